// SDFCage — Testing: small mesh readers (OFF, OBJ, PLY) into sdfcage::PolygonMesh.
#include "MeshIO.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string_view>
#include <vector>

namespace sdfcage
{
namespace exact
{
namespace
{

bool readFile(const std::string& path, std::string& data, std::string& error)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    error = "cannot open '" + path + "'";
    return false;
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0)
  {
    error = "cannot read '" + path + "'";
    return false;
  }
  data.resize(static_cast<std::size_t>(size));
  in.seekg(0, std::ios::beg);
  in.read(data.data(), size);
  if (!in)
  {
    error = "cannot read '" + path + "'";
    return false;
  }
  return true;
}

std::string lowerExtension(const std::string& path)
{
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of("/\\");
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
  {
    return std::string();
  }
  std::string ext = path.substr(dot + 1);
  std::transform(
    ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// Cursor over a text buffer, line by line or token by token.
class TextCursor
{
public:
  TextCursor(const char* begin, const char* end)
    : P(begin)
    , End(end)
  {
  }

  bool atEnd() const { return P >= End; }

  /// Next line with '#' comments removed that contains something other than blanks.
  bool nextLine(std::string_view& line)
  {
    while (P < End)
    {
      const char* e = static_cast<const char*>(std::memchr(P, '\n', static_cast<std::size_t>(End - P)));
      if (!e)
      {
        e = End;
      }
      const char* b = P;
      P = (e < End) ? e + 1 : End;
      const char* hash = static_cast<const char*>(std::memchr(b, '#', static_cast<std::size_t>(e - b)));
      const char* stop = hash ? hash : e;
      const char* s = b;
      while (s < stop && std::isspace(static_cast<unsigned char>(*s)))
      {
        ++s;
      }
      if (s < stop)
      {
        line = std::string_view(s, static_cast<std::size_t>(stop - s));
        return true;
      }
    }
    return false;
  }

  const char* position() const { return P; }
  const char* end() const { return End; }

private:
  const char* P;
  const char* End;
};

void skipSpace(const char*& p, const char* end)
{
  while (p < end && std::isspace(static_cast<unsigned char>(*p)))
  {
    ++p;
  }
}

bool parseDouble(const char*& p, const char* end, double& v)
{
  skipSpace(p, end);
  if (p < end && *p == '+')
  {
    ++p;
  }
  const auto r = std::from_chars(p, end, v);
  if (r.ec != std::errc())
  {
    // from_chars does not accept "nan"/"inf" in every spelling; try the common ones.
    std::string_view rest(p, static_cast<std::size_t>(end - p));
    auto startsWith = [&](const char* w) {
      const std::size_t n = std::strlen(w);
      if (rest.size() < n)
      {
        return false;
      }
      for (std::size_t i = 0; i < n; ++i)
      {
        if (std::tolower(static_cast<unsigned char>(rest[i])) != w[i])
        {
          return false;
        }
      }
      return true;
    };
    bool negative = false;
    if (startsWith("-"))
    {
      negative = true;
      rest.remove_prefix(1);
    }
    if (startsWith("nan"))
    {
      v = std::numeric_limits<double>::quiet_NaN();
    }
    else if (startsWith("inf"))
    {
      v = negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    }
    else
    {
      return false;
    }
    p = rest.data();
    while (p < end && !std::isspace(static_cast<unsigned char>(*p)))
    {
      ++p;
    }
    return true;
  }
  p = r.ptr;
  return true;
}

bool parseInt(const char*& p, const char* end, std::int64_t& v)
{
  skipSpace(p, end);
  if (p < end && *p == '+')
  {
    ++p;
  }
  const auto r = std::from_chars(p, end, v);
  if (r.ec != std::errc())
  {
    return false;
  }
  p = r.ptr;
  return true;
}

bool endsWithOFF(std::string_view w)
{
  return w.size() >= 3 && w.substr(w.size() - 3) == "OFF";
}

} // namespace

bool readOFF(const std::string& path, PolygonMesh& mesh, std::string& error)
{
  std::string data;
  if (!readFile(path, data, error))
  {
    return false;
  }
  mesh = PolygonMesh();
  TextCursor cursor(data.data(), data.data() + data.size());
  std::string_view line;
  if (!cursor.nextLine(line))
  {
    error = "'" + path + "' is empty";
    return false;
  }
  // Header: "OFF" (also COFF, NOFF, ...), optionally followed by the counts on the same line.
  const char* p = line.data();
  const char* e = line.data() + line.size();
  const char* w = p;
  while (w < e && !std::isspace(static_cast<unsigned char>(*w)))
  {
    ++w;
  }
  if (!endsWithOFF(std::string_view(p, static_cast<std::size_t>(w - p))))
  {
    error = "'" + path + "' has no OFF header";
    return false;
  }
  p = w;
  skipSpace(p, e);
  if (p >= e)
  {
    if (!cursor.nextLine(line))
    {
      error = "'" + path + "': missing counts";
      return false;
    }
    p = line.data();
    e = line.data() + line.size();
  }
  std::int64_t nv = 0, nf = 0;
  if (!parseInt(p, e, nv) || !parseInt(p, e, nf) || nv < 0 || nf < 0)
  {
    error = "'" + path + "': bad counts line";
    return false;
  }
  mesh.Points.reserve(static_cast<std::size_t>(nv));
  for (std::int64_t i = 0; i < nv; ++i)
  {
    Vec3 x;
    if (!cursor.nextLine(line))
    {
      error = "'" + path + "': truncated vertex list";
      return false;
    }
    p = line.data();
    e = line.data() + line.size();
    if (!parseDouble(p, e, x[0]) || !parseDouble(p, e, x[1]) || !parseDouble(p, e, x[2]))
    {
      error = "'" + path + "': bad vertex line " + std::string(line);
      return false;
    }
    mesh.Points.push_back(x);
  }
  mesh.Offsets.reserve(static_cast<std::size_t>(nf) + 1);
  mesh.Connectivity.reserve(static_cast<std::size_t>(nf) * 3);
  for (std::int64_t f = 0; f < nf; ++f)
  {
    if (!cursor.nextLine(line))
    {
      error = "'" + path + "': truncated face list";
      return false;
    }
    p = line.data();
    e = line.data() + line.size();
    std::int64_t n = 0;
    if (!parseInt(p, e, n) || n < 0)
    {
      error = "'" + path + "': bad face line " + std::string(line);
      return false;
    }
    for (std::int64_t k = 0; k < n; ++k)
    {
      std::int64_t id = 0;
      if (!parseInt(p, e, id))
      {
        error = "'" + path + "': bad face line " + std::string(line);
        return false;
      }
      mesh.Connectivity.push_back(id);
    }
    mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
  }
  return true;
}

bool readOBJ(const std::string& path, PolygonMesh& mesh, std::string& error)
{
  std::string data;
  if (!readFile(path, data, error))
  {
    return false;
  }
  mesh = PolygonMesh();
  TextCursor cursor(data.data(), data.data() + data.size());
  std::string_view line;
  std::size_t lineCount = 0;
  while (cursor.nextLine(line))
  {
    ++lineCount;
    if (line.size() < 2 || !std::isspace(static_cast<unsigned char>(line[1])))
    {
      continue; // vn, vt, usemtl, ... : not geometry we need
    }
    const char* p = line.data() + 1;
    const char* e = line.data() + line.size();
    if (line[0] == 'v')
    {
      Vec3 x;
      if (!parseDouble(p, e, x[0]) || !parseDouble(p, e, x[1]) || !parseDouble(p, e, x[2]))
      {
        error = "'" + path + "': bad vertex line " + std::string(line);
        return false;
      }
      mesh.Points.push_back(x);
    }
    else if (line[0] == 'f')
    {
      const std::int64_t nPoints = static_cast<std::int64_t>(mesh.Points.size());
      for (;;)
      {
        skipSpace(p, e);
        if (p >= e)
        {
          break;
        }
        std::int64_t id = 0;
        if (!parseInt(p, e, id) || id == 0)
        {
          error = "'" + path + "': bad face line " + std::string(line);
          return false;
        }
        // 1-based; negative indices count back from the last vertex read so far.
        mesh.Connectivity.push_back(id > 0 ? id - 1 : nPoints + id);
        while (p < e && !std::isspace(static_cast<unsigned char>(*p)))
        {
          ++p; // skip "/vt/vn"
        }
      }
      mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
    }
  }
  if (lineCount == 0)
  {
    error = "'" + path + "' is empty";
    return false;
  }
  return true;
}

namespace
{

enum class PlyType
{
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Float32,
  Float64,
  Invalid
};

PlyType plyType(const std::string& name)
{
  if (name == "char" || name == "int8")
    return PlyType::Int8;
  if (name == "uchar" || name == "uint8")
    return PlyType::UInt8;
  if (name == "short" || name == "int16")
    return PlyType::Int16;
  if (name == "ushort" || name == "uint16")
    return PlyType::UInt16;
  if (name == "int" || name == "int32")
    return PlyType::Int32;
  if (name == "uint" || name == "uint32")
    return PlyType::UInt32;
  if (name == "float" || name == "float32")
    return PlyType::Float32;
  if (name == "double" || name == "float64")
    return PlyType::Float64;
  return PlyType::Invalid;
}

int plySize(PlyType t)
{
  switch (t)
  {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
    default:
      return 0;
  }
}

struct PlyProperty
{
  std::string Name;
  bool IsList = false;
  PlyType CountType = PlyType::Invalid;
  PlyType Type = PlyType::Invalid;
};

struct PlyElement
{
  std::string Name;
  std::int64_t Count = 0;
  std::vector<PlyProperty> Properties;
};

/// Reads one binary scalar at p (which must have plySize(t) bytes) as double.
double readBinary(const char* p, PlyType t, bool swap)
{
  unsigned char b[8];
  const int n = plySize(t);
  std::memcpy(b, p, static_cast<std::size_t>(n));
  if (swap)
  {
    std::reverse(b, b + n);
  }
  switch (t)
  {
    case PlyType::Int8:
    {
      std::int8_t v;
      std::memcpy(&v, b, 1);
      return v;
    }
    case PlyType::UInt8:
      return b[0];
    case PlyType::Int16:
    {
      std::int16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case PlyType::UInt16:
    {
      std::uint16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case PlyType::Int32:
    {
      std::int32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case PlyType::UInt32:
    {
      std::uint32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case PlyType::Float32:
    {
      float v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case PlyType::Float64:
    {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
    default:
      return 0.0;
  }
}

bool hostIsLittleEndian()
{
  const std::uint16_t one = 1;
  unsigned char c;
  std::memcpy(&c, &one, 1);
  return c == 1;
}

} // namespace

bool readPLY(const std::string& path, PolygonMesh& mesh, std::string& error)
{
  std::string data;
  if (!readFile(path, data, error))
  {
    return false;
  }
  mesh = PolygonMesh();
  const char* const begin = data.data();
  const char* const end = data.data() + data.size();

  // --- header (line based; each header line ends with \n, possibly preceded by \r) ---
  const char* p = begin;
  auto headerLine = [&](std::string& out) {
    if (p >= end)
    {
      return false;
    }
    const char* e = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    if (!e)
    {
      return false;
    }
    out.assign(p, e);
    if (!out.empty() && out.back() == '\r')
    {
      out.pop_back();
    }
    p = e + 1;
    return true;
  };
  std::string line;
  if (!headerLine(line) || line != "ply")
  {
    error = "'" + path + "' has no PLY header";
    return false;
  }
  enum class Format
  {
    Ascii,
    BinaryLE,
    BinaryBE,
    Unknown
  } format = Format::Unknown;
  std::vector<PlyElement> elements;
  bool headerDone = false;
  while (headerLine(line))
  {
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "format")
    {
      std::string f;
      words >> f;
      format = f == "ascii"           ? Format::Ascii
        : f == "binary_little_endian" ? Format::BinaryLE
        : f == "binary_big_endian"    ? Format::BinaryBE
                                      : Format::Unknown;
    }
    else if (key == "element")
    {
      PlyElement el;
      words >> el.Name >> el.Count;
      if (!words || el.Count < 0)
      {
        error = "'" + path + "': bad element line '" + line + "'";
        return false;
      }
      elements.push_back(el);
    }
    else if (key == "property")
    {
      if (elements.empty())
      {
        error = "'" + path + "': property before any element";
        return false;
      }
      PlyProperty prop;
      std::string t;
      words >> t;
      if (t == "list")
      {
        std::string ct, vt;
        words >> ct >> vt >> prop.Name;
        prop.IsList = true;
        prop.CountType = plyType(ct);
        prop.Type = plyType(vt);
        if (prop.CountType == PlyType::Invalid || prop.Type == PlyType::Invalid)
        {
          error = "'" + path + "': unknown list type in '" + line + "'";
          return false;
        }
      }
      else
      {
        prop.Type = plyType(t);
        words >> prop.Name;
        if (prop.Type == PlyType::Invalid)
        {
          error = "'" + path + "': unknown property type in '" + line + "'";
          return false;
        }
      }
      elements.back().Properties.push_back(prop);
    }
    else if (key == "end_header")
    {
      headerDone = true;
      break;
    }
    // comment, obj_info: ignored
  }
  if (!headerDone || format == Format::Unknown)
  {
    error = "'" + path + "': incomplete header or unknown format";
    return false;
  }

  const bool swap = (format == Format::BinaryLE) != hostIsLittleEndian();
  const char* q = p; // body cursor
  const std::string truncated = "'" + path + "': file is truncated or malformed";

  // Reads one scalar of type t from the body (ascii or binary).
  auto readScalar = [&](PlyType t, double& v) {
    if (format == Format::Ascii)
    {
      return parseDouble(q, end, v);
    }
    const int n = plySize(t);
    if (end - q < n)
    {
      return false;
    }
    v = readBinary(q, t, swap);
    q += n;
    return true;
  };

  for (const PlyElement& el : elements)
  {
    const bool isVertex = el.Name == "vertex";
    const bool isFace = el.Name == "face";
    int ix = -1, iy = -1, iz = -1, iface = -1;
    for (std::size_t k = 0; k < el.Properties.size(); ++k)
    {
      const std::string& n = el.Properties[k].Name;
      if (isVertex && !el.Properties[k].IsList)
      {
        ix = n == "x" ? static_cast<int>(k) : ix;
        iy = n == "y" ? static_cast<int>(k) : iy;
        iz = n == "z" ? static_cast<int>(k) : iz;
      }
      if (isFace && el.Properties[k].IsList && (n == "vertex_indices" || n == "vertex_index"))
      {
        iface = static_cast<int>(k);
      }
    }
    if (isVertex && (ix < 0 || iy < 0 || iz < 0))
    {
      error = "'" + path + "': vertex element without x, y, z";
      return false;
    }
    if (isVertex)
    {
      mesh.Points.reserve(static_cast<std::size_t>(el.Count));
    }
    if (isFace)
    {
      mesh.Offsets.reserve(static_cast<std::size_t>(el.Count) + 1);
      mesh.Connectivity.reserve(static_cast<std::size_t>(el.Count) * 3);
    }
    for (std::int64_t i = 0; i < el.Count; ++i)
    {
      Vec3 x = Vec3::Zero();
      for (std::size_t k = 0; k < el.Properties.size(); ++k)
      {
        const PlyProperty& prop = el.Properties[k];
        double v = 0.0;
        if (!prop.IsList)
        {
          if (!readScalar(prop.Type, v))
          {
            error = truncated;
            return false;
          }
          if (static_cast<int>(k) == ix)
            x[0] = v;
          else if (static_cast<int>(k) == iy)
            x[1] = v;
          else if (static_cast<int>(k) == iz)
            x[2] = v;
          continue;
        }
        double count = 0.0;
        if (!readScalar(prop.CountType, count) || count < 0)
        {
          error = truncated;
          return false;
        }
        const std::int64_t n = static_cast<std::int64_t>(count);
        for (std::int64_t j = 0; j < n; ++j)
        {
          if (!readScalar(prop.Type, v))
          {
            error = truncated;
            return false;
          }
          if (static_cast<int>(k) == iface)
          {
            mesh.Connectivity.push_back(static_cast<std::int64_t>(v));
          }
        }
        if (static_cast<int>(k) == iface)
        {
          mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
        }
      }
      if (isVertex)
      {
        mesh.Points.push_back(x);
      }
    }
  }
  return true;
}

bool readPolygonMesh(const std::string& path, PolygonMesh& mesh, std::string& error)
{
  const std::string ext = lowerExtension(path);
  if (ext == "off")
  {
    return readOFF(path, mesh, error);
  }
  if (ext == "obj")
  {
    return readOBJ(path, mesh, error);
  }
  if (ext == "ply")
  {
    return readPLY(path, mesh, error);
  }
  error = "'" + path + "': unsupported extension (use .off, .obj or .ply)";
  return false;
}

bool fanTriangulate(const PolygonMesh& mesh, TriangleMesh& out)
{
  out = TriangleMesh();
  out.Points = mesh.Points;
  const std::int64_t nPoints = static_cast<std::int64_t>(mesh.Points.size());
  bool allValid = true;
  for (std::size_t c = 0; c < mesh.numberOfCells(); ++c)
  {
    const std::int64_t b = mesh.Offsets[c];
    const std::int64_t e = mesh.Offsets[c + 1];
    if (e - b < 3)
    {
      continue;
    }
    bool valid = true;
    for (std::int64_t k = b; k < e; ++k)
    {
      valid = valid && mesh.Connectivity[k] >= 0 && mesh.Connectivity[k] < nPoints;
    }
    if (!valid)
    {
      allValid = false;
      continue;
    }
    for (std::int64_t k = b + 1; k + 1 < e; ++k)
    {
      out.Triangles.push_back({ static_cast<int>(mesh.Connectivity[b]), static_cast<int>(mesh.Connectivity[k]),
        static_cast<int>(mesh.Connectivity[k + 1]) });
    }
  }
  return allValid;
}

bool writeOFF(const std::string& path, const TriangleMesh& mesh)
{
  std::ofstream out(path);
  if (!out)
  {
    return false;
  }
  out.precision(17);
  out << "OFF\n" << mesh.Points.size() << ' ' << mesh.Triangles.size() << " 0\n";
  for (const Vec3& x : mesh.Points)
  {
    out << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
  }
  for (const Triangle& t : mesh.Triangles)
  {
    out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  }
  return static_cast<bool>(out);
}

} // namespace exact
} // namespace sdfcage
