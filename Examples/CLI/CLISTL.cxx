// SDFCage — CLI: the STL parser (see CLIParsers.h).
//
// Why our own and not vtkSTLReader: it trusts a binary file's triangle count, and it decides
// between ASCII and binary by looking at the first bytes only, so a file that starts with "solid"
// but holds binary bytes was read as binary with a count made of text (2.2 billion triangles:
// out of memory, found by fuzzing); the count had to be checked before VTK ran, with the checker
// guessing what VTK would decide. Reading STL is short: a binary file is 80 bytes of header, a
// 32-bit little-endian count and 50 bytes a triangle; an ASCII file is "solid", then "facet
// normal ... outer loop vertex x y z (x3) endloop endfacet" repeated, then "endsolid". Points
// with the same coordinates are merged exactly, as vtkSTLReader with merging does (STL stores
// every triangle's corners on their own), so that a closed STL arrives closed.
#include "CLIParsers.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <unordered_map>

namespace sdfcage_cli
{

namespace
{

/// Exact merging of equal points (-0 and +0 are one; NaN never equals anything, so each NaN
/// corner stays its own point and validation refuses it by name).
class PointMerger
{
public:
  explicit PointMerger(ParsedMesh& mesh)
    : Mesh(mesh)
  {
  }
  std::int64_t add(double x, double y, double z)
  {
    const double p[3] = { x == 0 ? 0.0 : x, y == 0 ? 0.0 : y, z == 0 ? 0.0 : z };
    const auto id = static_cast<std::int64_t>(Mesh.Points.size() / 3);
    if (std::isnan(x) || std::isnan(y) || std::isnan(z))
    {
      Mesh.Points.insert(Mesh.Points.end(), p, p + 3);
      return id;
    }
    Key key;
    std::memcpy(key.Bits, p, sizeof(p));
    const auto inserted = Ids.emplace(key, id);
    if (inserted.second)
    {
      Mesh.Points.insert(Mesh.Points.end(), p, p + 3);
    }
    return inserted.first->second;
  }

private:
  struct Key
  {
    std::uint64_t Bits[3];
    bool operator==(const Key& o) const
    {
      return Bits[0] == o.Bits[0] && Bits[1] == o.Bits[1] && Bits[2] == o.Bits[2];
    }
  };
  struct Hash
  {
    std::size_t operator()(const Key& k) const
    {
      std::uint64_t h = 1469598103934665603ull;
      for (std::uint64_t b : k.Bits)
      {
        h = (h ^ b) * 1099511628211ull;
        h ^= h >> 29;
      }
      return static_cast<std::size_t>(h);
    }
  };
  ParsedMesh& Mesh;
  std::unordered_map<Key, std::int64_t, Hash> Ids;
};

/// The triangle count a binary STL's header declares (32-bit little-endian at byte 80; the caller
/// has checked that there are 84 bytes).
std::uint64_t declaredCount(const unsigned char* data)
{
  return data[80] | (data[81] << 8) | (data[82] << 16) | (std::uint64_t(data[83]) << 24);
}

/// Whether a binary STL's triangle count fits its size (the count in `count`), or why not.
bool binaryCountFits(const unsigned char* data, std::size_t size, std::uint64_t& count, std::string& error)
{
  if (size < 84)
  {
    error = "a binary STL file needs at least 84 bytes (header and triangle count), this one has " +
      std::to_string(size);
    return false;
  }
  count = declaredCount(data);
  if (84 + 50 * count > size)
  {
    error = "the binary STL header declares " + std::to_string(count) + " triangles (" +
      std::to_string(84 + 50 * count) + " bytes), the file has " + std::to_string(size) + " bytes";
    return false;
  }
  return true;
}

bool parseBinarySTL(const unsigned char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled)
{
  std::uint64_t count = 0;
  if (!binaryCountFits(data, size, count, error))
  {
    return false;
  }
  // bytes after the declared triangles are ignored, as vtkSTLReader ignores them
  mesh.Points.reserve(3 * std::min<std::uint64_t>(3 * count, 1u << 20));
  mesh.Connectivity.reserve(3 * count);
  mesh.Offsets.reserve(count + 1);
  PointMerger merger(mesh);
  for (std::uint64_t t = 0; t < count; ++t)
  {
    if ((t & 16383) == 16383 && cancelled && cancelled())
    {
      error = "interrupted";
      return false;
    }
    const unsigned char* f = data + 84 + 50 * t + 12; // past the normal
    for (int corner = 0; corner < 3; ++corner)
    {
      double xyz[3];
      for (int k = 0; k < 3; ++k)
      {
        float v;
        std::memcpy(&v, f + 12 * corner + 4 * k, 4); // little-endian, as is this machine
        xyz[k] = v;
      }
      mesh.Connectivity.push_back(merger.add(xyz[0], xyz[1], xyz[2]));
    }
    mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
  }
  return true;
}

bool parseASCIISTL(const char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled)
{
  const char* p = data;
  const char* const end = data + size;
  std::string word;
  auto next = [&](bool lower) { return nextWord(p, end, word, lower); };
  auto fail = [&](const std::string& why) {
    error = "line " + std::to_string(1 + std::count(data, p, '\n')) + ": " + why;
    return false;
  };
  auto expect = [&](const char* keyword) {
    if (!next(true) || word != keyword)
    {
      return fail(std::string("'") + keyword + "' expected, not '" + word.substr(0, 40) + "'");
    }
    return true;
  };
  auto restOfLine = [&]() {
    const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
    p = nl ? static_cast<const char*>(nl) + 1 : end;
  };
  PointMerger merger(mesh);
  std::size_t facets = 0;
  bool inSolid = false;
  while (next(true))
  {
    if (word == "solid")
    {
      restOfLine(); // the solid's name
      inSolid = true;
      continue;
    }
    if (word == "endsolid")
    {
      restOfLine();
      inSolid = false;
      continue;
    }
    if (!inSolid || word != "facet")
    {
      return fail(std::string(inSolid ? "'facet' or 'endsolid'" : "'solid'") + " expected, not '" +
        word.substr(0, 40) + "'");
    }
    restOfLine(); // "normal nx ny nz": not needed (recomputed from the corners)
    if (!expect("outer") || !expect("loop"))
    {
      return false;
    }
    std::size_t corners = 0;
    while (next(true) && word == "vertex")
    {
      double xyz[3];
      for (double& c : xyz)
      {
        char* stop = nullptr;
        if (!next(false) || (c = std::strtod(word.c_str(), &stop), stop != word.c_str() + word.size()))
        {
          return fail("a vertex needs three numbers, not '" + word.substr(0, 40) + "'");
        }
      }
      mesh.Connectivity.push_back(merger.add(xyz[0], xyz[1], xyz[2]));
      ++corners;
    }
    if (word != "endloop")
    {
      return fail("'vertex' or 'endloop' expected, not '" + word.substr(0, 40) + "'");
    }
    if (!expect("endfacet"))
    {
      return false;
    }
    if (corners < 3)
    {
      mesh.Connectivity.resize(mesh.Connectivity.size() - corners);
      ++mesh.SkippedFaces;
    }
    else
    {
      mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
    }
    if ((++facets & 8191) == 0 && cancelled && cancelled())
    {
      error = "interrupted";
      return false;
    }
  }
  return true;
}

} // namespace

bool parseSTL(
  const char* data, std::size_t size, ParsedMesh& mesh, std::string& error, const std::function<bool()>& cancelled)
{
  mesh = ParsedMesh();
  mesh.Offsets.push_back(0);
  if (size == 0)
  {
    error = "the file is empty";
    return false;
  }
  const auto* bytes = reinterpret_cast<const unsigned char*>(data);
  // Binary when the size is exactly what the count says (some binary headers start with
  // "solid"); ASCII when it starts with "solid"; binary otherwise.
  std::size_t lead = 0;
  while (lead < size && std::isspace(bytes[lead]))
  {
    ++lead;
  }
  bool solid = size - lead >= 5;
  for (std::size_t k = 0; solid && k < 5; ++k)
  {
    solid = std::tolower(bytes[lead + k]) == "solid"[k];
  }
  const bool binaryBySize = size >= 84 && 84 + 50 * declaredCount(bytes) == size;
  const bool ascii = solid && !binaryBySize;
  bool ok =
    ascii ? parseASCIISTL(data, size, mesh, error, cancelled) : parseBinarySTL(bytes, size, mesh, error, cancelled);
  if (ok && mesh.Offsets.size() == 1)
  {
    error = "the file holds no triangles";
    ok = false;
  }
  if (!ok && ascii && error != "interrupted")
  {
    // Never read as binary then (a damaged ASCII file would give garbage triangles), but say
    // what a binary reading would have found: a text start with binary bytes after it.
    std::string binaryWhy;
    std::uint64_t count = 0;
    error = "not a valid ASCII STL (" + error + ")" +
      (binaryCountFits(bytes, size, count, binaryWhy) ? std::string() : ", nor a binary one (" + binaryWhy + ")");
  }
  if (!ok)
  {
    mesh = ParsedMesh();
  }
  return ok;
}

} // namespace sdfcage_cli
