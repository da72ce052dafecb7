// SDFCage — CLI: the PLY parser (see CLIParsers.h).
#include "CLIParsers.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <charconv>
#include <cstring>
#include <limits>
#include <sstream>

namespace sdfcage_cli
{

namespace
{

enum class Format
{
  Ascii,
  BinaryLittleEndian,
  BinaryBigEndian
};

enum class Type
{
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Float32,
  Float64
};

bool typeFromName(const std::string& name, Type& type)
{
  static const struct
  {
    const char* Name;
    Type T;
  } names[] = { { "char", Type::Int8 }, { "int8", Type::Int8 }, { "uchar", Type::UInt8 }, { "uint8", Type::UInt8 },
    { "short", Type::Int16 }, { "int16", Type::Int16 }, { "ushort", Type::UInt16 }, { "uint16", Type::UInt16 },
    { "int", Type::Int32 }, { "int32", Type::Int32 }, { "uint", Type::UInt32 }, { "uint32", Type::UInt32 },
    { "float", Type::Float32 }, { "float32", Type::Float32 }, { "double", Type::Float64 },
    { "float64", Type::Float64 } };
  for (const auto& n : names)
  {
    if (name == n.Name)
    {
      type = n.T;
      return true;
    }
  }
  return false;
}

std::size_t typeSize(Type t)
{
  switch (t)
  {
    case Type::Int8:
    case Type::UInt8:
      return 1;
    case Type::Int16:
    case Type::UInt16:
      return 2;
    case Type::Int32:
    case Type::UInt32:
    case Type::Float32:
      return 4;
    case Type::Float64:
      return 8;
  }
  return 8;
}

struct Property
{
  std::string Name;
  bool IsList = false;
  Type CountType = Type::UInt8; ///< lists only
  Type ValueType = Type::Float32;
};

struct Element
{
  std::string Name;
  std::int64_t Count = 0;
  std::vector<Property> Properties;
};

std::vector<std::string> splitWords(const std::string& line)
{
  std::vector<std::string> words;
  std::istringstream in(line);
  std::string w;
  while (in >> w)
  {
    words.push_back(w);
  }
  return words;
}

/// Sequential reader of the body, ASCII (whitespace-separated tokens) or binary.
class Body
{
public:
  Body(const char* data, std::size_t size, Format format)
    : Data(data)
    , Size(size)
    , Fmt(format)
  {
  }

  std::size_t remaining() const { return this->Size - this->Pos; }

  /// Anything but white space left (a final line feed after binary data is tolerated).
  bool trailingData() const
  {
    for (std::size_t i = this->Pos; i < this->Size; ++i)
    {
      if (!std::strchr(" \t\r\n\v\f", this->Data[i]) || this->Data[i] == '\0')
      {
        return true;
      }
    }
    return false;
  }

  /// The fewest bytes a value of `t` takes: its size in binary; in ASCII one character and a
  /// separator (the last value of the file may lack the separator: callers allow one byte).
  std::size_t minimumBytes(Type t) const { return this->Fmt == Format::Ascii ? 2 : typeSize(t); }

  /// Reads one value as a double. False at the end of the data or on a malformed number.
  bool read(Type t, double& value)
  {
    return this->Fmt == Format::Ascii ? this->readAscii(value) : this->readBinary(t, value);
  }

private:
  static bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

  bool readAscii(double& value)
  {
    while (this->Pos < this->Size && isBlank(this->Data[this->Pos]))
    {
      ++this->Pos;
    }
    const std::size_t start = this->Pos;
    while (this->Pos < this->Size && this->Data[this->Pos] != '\0' && !isBlank(this->Data[this->Pos]))
    {
      ++this->Pos;
    }
    const std::size_t length = this->Pos - start;
    if (length == 0 || length >= 80)
    {
      return false;
    }
    // std::from_chars first (a few times faster than strtod: no locale, no copy; both round
    // correctly, so the value is the same); strtod for what it does not take ("+1", hex,
    // out-of-range values, which strtod turns into inf or 0 as before)
    const char* first = this->Data + start;
    const std::from_chars_result r = std::from_chars(first, first + length, value);
    if (r.ec == std::errc() && r.ptr == first + length)
    {
      return true;
    }
    char token[80];
    std::memcpy(token, first, length);
    token[length] = '\0';
    char* end = nullptr;
    value = std::strtod(token, &end);
    return end == token + length;
  }

  bool readBinary(Type t, double& value)
  {
    const std::size_t n = typeSize(t);
    if (this->remaining() < n)
    {
      return false;
    }
    unsigned char bytes[8];
    std::memcpy(bytes, this->Data + this->Pos, n);
    this->Pos += n;
    const bool little = this->Fmt == Format::BinaryLittleEndian;
    const std::uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    const bool hostLittle = first == 1;
    if (little != hostLittle)
    {
      for (std::size_t i = 0; i < n / 2; ++i)
      {
        const unsigned char tmp = bytes[i];
        bytes[i] = bytes[n - 1 - i];
        bytes[n - 1 - i] = tmp;
      }
    }
    switch (t)
    {
      case Type::Int8:
      {
        std::int8_t v;
        std::memcpy(&v, bytes, 1);
        value = v;
        break;
      }
      case Type::UInt8:
        value = bytes[0];
        break;
      case Type::Int16:
      {
        std::int16_t v;
        std::memcpy(&v, bytes, 2);
        value = v;
        break;
      }
      case Type::UInt16:
      {
        std::uint16_t v;
        std::memcpy(&v, bytes, 2);
        value = v;
        break;
      }
      case Type::Int32:
      {
        std::int32_t v;
        std::memcpy(&v, bytes, 4);
        value = v;
        break;
      }
      case Type::UInt32:
      {
        std::uint32_t v;
        std::memcpy(&v, bytes, 4);
        value = v;
        break;
      }
      case Type::Float32:
      {
        float v;
        std::memcpy(&v, bytes, 4);
        value = v;
        break;
      }
      case Type::Float64:
        std::memcpy(&value, bytes, 8);
        break;
    }
    return true;
  }

  const char* Data;
  std::size_t Size;
  std::size_t Pos = 0;
  Format Fmt;
};

/// The fewest bytes one element takes (lists counted empty).
std::size_t minimumElementBytes(const Element& e, const Body& body)
{
  std::size_t bytes = 0;
  for (const Property& p : e.Properties)
  {
    bytes += body.minimumBytes(p.IsList ? p.CountType : p.ValueType);
  }
  return bytes;
}

std::string lineOf(const char* data, std::size_t size, std::size_t& pos)
{
  const std::size_t start = pos;
  while (pos < size && data[pos] != '\n')
  {
    ++pos;
  }
  std::string line(data + start, pos - start);
  if (pos < size)
  {
    ++pos; // the '\n'
  }
  if (!line.empty() && line.back() == '\r')
  {
    line.pop_back();
  }
  return line;
}

} // namespace

bool parsePLY(const char* data, std::size_t size, ParsedMesh& mesh, std::string& error,
  const std::function<bool()>& cancelled)
{
  mesh = ParsedMesh();
  auto fail = [&error, &mesh](const std::string& why) {
    error = why;
    mesh = ParsedMesh();
    return false;
  };
  if (size == 0)
  {
    return fail("the file is empty");
  }

  // --- header ----------------------------------------------------------------------------
  std::size_t pos = 0;
  if (lineOf(data, size, pos) != "ply")
  {
    return fail("not a PLY file (the first line is not 'ply')");
  }
  Format format = Format::Ascii;
  bool haveFormat = false;
  bool ended = false;
  std::vector<Element> elements;
  int headerLine = 1;
  while (pos < size && !ended)
  {
    const std::string line = lineOf(data, size, pos);
    ++headerLine;
    const std::vector<std::string> w = splitWords(line);
    const std::string where = "header line " + std::to_string(headerLine) + ": ";
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info")
    {
      continue;
    }
    if (w[0] == "end_header")
    {
      ended = true;
    }
    else if (w[0] == "format")
    {
      if (w.size() < 2)
        return fail(where + "'format' needs ascii, binary_little_endian or binary_big_endian");
      if (w[1] == "ascii")
        format = Format::Ascii;
      else if (w[1] == "binary_little_endian")
        format = Format::BinaryLittleEndian;
      else if (w[1] == "binary_big_endian")
        format = Format::BinaryBigEndian;
      else
        return fail(where + "unknown format '" + w[1] + "'");
      haveFormat = true;
    }
    else if (w[0] == "element")
    {
      if (w.size() != 3)
        return fail(where + "expected 'element NAME COUNT'");
      Element e;
      e.Name = w[1];
      char* end = nullptr;
      errno = 0;
      const long long count = std::strtoll(w[2].c_str(), &end, 10);
      if (*end != '\0' || errno == ERANGE)
        return fail(where + "the count of element '" + e.Name + "' is not an integer: '" + w[2] + "'");
      if (count < 0)
        return fail(where + "negative count " + w[2] + " for element '" + e.Name + "'");
      e.Count = count;
      elements.push_back(e);
    }
    else if (w[0] == "property")
    {
      if (elements.empty())
        return fail(where + "a property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list")
      {
        p.IsList = true;
        if (!typeFromName(w[2], p.CountType) || !typeFromName(w[3], p.ValueType))
          return fail(where + "unknown list type '" + w[2] + " " + w[3] + "'");
        if (p.CountType == Type::Float32 || p.CountType == Type::Float64)
          return fail(where + "a list count must be an integer type");
        p.Name = w[4];
      }
      else if (w.size() == 3)
      {
        if (!typeFromName(w[1], p.ValueType))
          return fail(where + "unknown property type '" + w[1] + "'");
        p.Name = w[2];
      }
      else
      {
        return fail(where + "expected 'property TYPE NAME' or 'property list COUNTTYPE TYPE NAME'");
      }
      elements.back().Properties.push_back(p);
    }
    else
    {
      return fail(where + "unknown header keyword '" + w[0] + "'");
    }
  }
  if (!ended)
    return fail("the header has no 'end_header' line (truncated file?)");
  if (!haveFormat)
    return fail("the header has no 'format' line");

  // --- what to take: vertex x y z, face vertex_indices --------------------------------------
  const Element* vertices = nullptr;
  for (const Element& e : elements)
  {
    if (e.Name == "vertex" && !vertices)
      vertices = &e;
  }
  if (!vertices)
    return fail("no 'vertex' element");
  int xyz[3] = { -1, -1, -1 };
  for (std::size_t i = 0; i < vertices->Properties.size(); ++i)
  {
    const Property& p = vertices->Properties[i];
    for (int k = 0; k < 3; ++k)
    {
      if (!p.IsList && p.Name == std::string(1, static_cast<char>('x' + k)))
        xyz[k] = static_cast<int>(i);
    }
  }
  if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
    return fail("the 'vertex' element lacks one of the properties x, y, z");
  const std::int64_t numberOfVertices = vertices->Count;

  // --- every count against the bytes left -------------------------------------------------
  Body body(data + pos, size - pos, format);
  {
    std::size_t left = body.remaining() + 1; // + 1: the last ASCII value may end the file
    for (const Element& e : elements)
    {
      const std::size_t perElement = minimumElementBytes(e, body);
      if (perElement == 0)
        continue;
      if (static_cast<std::uint64_t>(e.Count) > left / perElement)
      {
        std::ostringstream m;
        m << "the header declares " << e.Count << " '" << e.Name << "' elements (at least " << perElement
          << " bytes each), more than the " << body.remaining() << " bytes after the header can hold";
        return fail(m.str());
      }
      left -= static_cast<std::size_t>(e.Count) * perElement;
    }
  }

  // --- body -------------------------------------------------------------------------------
  mesh.Points.reserve(static_cast<std::size_t>(numberOfVertices) * 3);
  for (const Element& e : elements)
  {
    // the counts fit in the bytes (checked above) when the element has properties; one without
    // takes no bytes, whatever its count (a 'face' element of 948 million such: 7.6 GB reserved
    // before, found by fuzz_mesh_parsers), and is skipped below
    if (e.Name == "face" && !e.Properties.empty()) // triangles are the usual
    {
      mesh.Offsets.reserve(static_cast<std::size_t>(e.Count) + 1);
      mesh.Connectivity.reserve(static_cast<std::size_t>(e.Count) * 3);
    }
  }
  mesh.Offsets.push_back(0);
  for (const Element& e : elements)
  {
    if (e.Properties.empty())
      continue;
    const bool isVertex = &e == vertices;
    const bool isFace = e.Name == "face";
    int faceList = -1;
    if (isFace)
    {
      for (std::size_t i = 0; i < e.Properties.size(); ++i)
      {
        const Property& p = e.Properties[i];
        if (p.IsList && (p.Name == "vertex_indices" || p.Name == "vertex_index") && faceList < 0)
          faceList = static_cast<int>(i);
      }
    }
    for (std::int64_t n = 0; n < e.Count; ++n)
    {
      if ((n & 4095) == 4095 && cancelled && cancelled())
        return fail("interrupted");
      double point[3] = { 0.0, 0.0, 0.0 };
      for (std::size_t i = 0; i < e.Properties.size(); ++i)
      {
        const Property& p = e.Properties[i];
        auto truncated = [&]() {
          std::ostringstream m;
          m << "the file ends (or a value is malformed) in '" << e.Name << "' element " << n << " of " << e.Count
            << ", property '" << p.Name << "'";
          return fail(m.str());
        };
        if (!p.IsList)
        {
          double v = 0.0;
          if (!body.read(p.ValueType, v))
            return truncated();
          if (isVertex)
          {
            for (int k = 0; k < 3; ++k)
              if (xyz[k] == static_cast<int>(i))
                point[k] = v;
          }
          continue;
        }
        double countValue = 0.0;
        if (!body.read(p.CountType, countValue))
          return truncated();
        const std::size_t itemBytes = body.minimumBytes(p.ValueType);
        if (!(countValue >= 0.0) || countValue != std::floor(countValue) ||
          countValue > static_cast<double>((body.remaining() + 1) / itemBytes))
        {
          std::ostringstream m;
          m << "'" << e.Name << "' element " << n << ": list '" << p.Name << "' claims " << countValue
            << " items, more than the rest of the file holds (or not a count)";
          return fail(m.str());
        }
        const auto count = static_cast<std::size_t>(countValue);
        const bool take = static_cast<int>(i) == faceList;
        for (std::size_t k = 0; k < count; ++k)
        {
          double v = 0.0;
          if (!body.read(p.ValueType, v))
            return truncated();
          if (take)
          {
            if (!(v >= 0.0) || v != std::floor(v) || v >= static_cast<double>(numberOfVertices))
            {
              std::ostringstream m;
              m << "face " << n << " uses vertex index " << v << ", outside [0, " << numberOfVertices << ")";
              return fail(m.str());
            }
            mesh.Connectivity.push_back(static_cast<std::int64_t>(v));
          }
        }
        if (take)
        {
          if (count < 3)
          {
            mesh.Connectivity.resize(mesh.Connectivity.size() - count);
            ++mesh.SkippedFaces;
          }
          else
          {
            mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
          }
        }
      }
      if (isVertex)
      {
        mesh.Points.insert(mesh.Points.end(), point, point + 3);
      }
    }
  }
  // what the header declared must be all there is: bytes left mean it claims less than the
  // file holds (trailing white space is fine)
  if (body.trailingData())
  {
    std::ostringstream m;
    m << body.remaining() << " bytes are left after the elements the header declares: the header does not match "
      << "the data";
    return fail(m.str());
  }
  return true;
}

} // namespace sdfcage_cli
