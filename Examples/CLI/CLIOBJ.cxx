// SDFCage — CLI: the OBJ parser (see CLIParsers.h).
#include "CLIParsers.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>

namespace sdfcage_cli
{

namespace
{

bool isSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/// The next white-space separated token of [p, end), copied (at most 255 characters).
bool nextToken(const char*& p, const char* end, std::string& token)
{
  while (p < end && isSpace(*p))
  {
    ++p;
  }
  const char* start = p;
  while (p < end && !isSpace(*p))
  {
    ++p;
  }
  token.assign(start, p);
  return !token.empty();
}

bool parseNumber(const std::string& token, double& value)
{
  if (token.empty() || token.size() > 255)
  {
    return false;
  }
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end); // "nan", "inf" and overflows (inf) are kept for validation
  return end == token.c_str() + token.size();
}

bool parseIndex(const std::string& text, long long& value)
{
  if (text.empty() || text.size() > 20)
  {
    return false;
  }
  char* end = nullptr;
  errno = 0;
  value = std::strtoll(text.c_str(), &end, 10);
  return end == text.c_str() + text.size() && errno != ERANGE;
}

} // namespace

bool parseOBJ(
  const char* data, std::size_t size, ParsedMesh& mesh, std::string& error, const std::function<bool()>& cancelled)
{
  mesh = ParsedMesh();
  mesh.Offsets.push_back(0);
  long long lineNumber = 0;
  auto fail = [&](const std::string& why) {
    error = "line " + std::to_string(lineNumber) + ": " + why;
    mesh = ParsedMesh();
    return false;
  };
  if (size == 0)
  {
    error = "the file is empty";
    return false;
  }
  // Face indices are kept 0-based as read (relative ones resolved against the vertices read so
  // far) and checked against the final vertex count at the end (forward references are legal).
  std::vector<long long> faceLines; // the line of each face, for the message
  const char* p = data;
  const char* const fileEnd = data + size;
  std::string keyword, token;
  while (p < fileEnd)
  {
    const char* lineEnd = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(fileEnd - p)));
    if (!lineEnd)
    {
      lineEnd = fileEnd;
    }
    ++lineNumber;
    if ((lineNumber & 8191) == 0 && cancelled && cancelled())
    {
      error = "interrupted";
      mesh = ParsedMesh();
      return false;
    }
    const char* q = p;
    p = lineEnd + 1;
    if (std::memchr(q, '\0', static_cast<std::size_t>(lineEnd - q)))
    {
      return fail("a NUL byte: not a text OBJ file");
    }
    if (!nextToken(q, lineEnd, keyword) || keyword[0] == '#')
    {
      continue;
    }
    if (keyword == "v")
    {
      double xyz[3];
      for (double& c : xyz)
      {
        if (!nextToken(q, lineEnd, token) || !parseNumber(token, c))
        {
          return fail("a vertex needs three numbers ('v x y z')");
        }
      }
      mesh.Points.insert(mesh.Points.end(), xyz, xyz + 3);
    }
    else if (keyword == "f")
    {
      const long long vertices = static_cast<long long>(mesh.Points.size() / 3);
      std::size_t count = 0;
      while (nextToken(q, lineEnd, token))
      {
        long long index = 0;
        if (!parseIndex(token.substr(0, token.find('/')), index) || index == 0)
        {
          return fail("'" + token.substr(0, 40) + "' is not a vertex index (1-based, negative = relative)");
        }
        if (index < 0)
        {
          index += vertices; // -1: the last vertex read
          if (index < 0)
          {
            return fail("relative index " + token.substr(0, 40) + " reaches before the first vertex");
          }
        }
        else
        {
          index -= 1;
        }
        mesh.Connectivity.push_back(index);
        ++count;
      }
      if (count < 3)
      {
        mesh.Connectivity.resize(mesh.Connectivity.size() - count);
        ++mesh.SkippedFaces;
      }
      else
      {
        mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
        faceLines.push_back(lineNumber);
      }
    }
    // anything else (vt vn g o s usemtl mtllib l p ...) is not needed for a cage
  }
  const long long vertices = static_cast<long long>(mesh.Points.size() / 3);
  for (std::size_t f = 0; f + 1 < mesh.Offsets.size(); ++f)
  {
    for (std::int64_t k = mesh.Offsets[f]; k < mesh.Offsets[f + 1]; ++k)
    {
      if (mesh.Connectivity[static_cast<std::size_t>(k)] >= vertices)
      {
        lineNumber = faceLines[f];
        return fail("face uses vertex " + std::to_string(mesh.Connectivity[static_cast<std::size_t>(k)] + 1) +
          ", outside [1, " + std::to_string(vertices) + "]");
      }
    }
  }
  return true;
}

} // namespace sdfcage_cli
