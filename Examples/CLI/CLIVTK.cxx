// SDFCage — CLI: the legacy VTK POLYDATA parser (see CLIParsers.h).
//
// Why our own and not vtkPolyDataReader: VTK's legacy reader trusts what a file declares. Fuzzing
// (Testing/Fuzz, CI's fuzz stage) made it crash three times in a row, each time through another
// door: a cell count running past its section, version-5 offsets cut short, and a FIELD block
// where it walked past its buffer in ReadMeshSimple; a header claiming a billion points made it
// allocate and loop for minutes. Checking the file before handing it to VTK meant re-parsing the
// format anyway, with the checker and VTK disagreeing on details (VTK matches keywords in any
// case, the checker did not). A cage needs the points and the polygons only, so this parser
// reads exactly those, bounds every count by the bytes left before anything is allocated, and
// returns a one-line reason on any defect. It has no VTK in it (the fuzz harness drives it).
#include "CLIParsers.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
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
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

/// Byte width of a legacy VTK data type in binary files (big-endian); 0 when unsupported.
/// vtkIdType is written as a 32-bit int by VTK's legacy writer; "long" is 64-bit on this
/// platform, as VTK reads it.
std::size_t typeWidth(const std::string& type)
{
  if (type == "char" || type == "unsigned_char")
  {
    return 1;
  }
  if (type == "short" || type == "unsigned_short")
  {
    return 2;
  }
  if (type == "int" || type == "unsigned_int" || type == "float" || type == "vtkidtype")
  {
    return 4;
  }
  if (type == "long" || type == "unsigned_long" || type == "double" || type == "vtktypeint64" ||
    type == "vtktypeuint64")
  {
    return 8;
  }
  return 0;
}

class LegacyParser
{
public:
  LegacyParser(const char* data, std::size_t size, const std::function<bool()>& cancelled)
    : Begin(data)
    , P(data)
    , End(data + size)
    , Cancelled(cancelled)
  {
  }

  bool parse(ParsedMesh& mesh, std::string& error);

private:
  const char* const Begin;
  const char* P;
  const char* const End;
  const std::function<bool()>& Cancelled;
  bool Binary = false;
  std::string Error;
  std::size_t Polled = 0;

  long long lineAt(const char* q) const
  {
    return 1 + static_cast<long long>(std::count(Begin, std::min(q, End), '\n'));
  }
  bool fail(const char* at, const std::string& why)
  {
    if (Error.empty())
    {
      Error = "line " + std::to_string(lineAt(at)) + ": " + why;
    }
    return false;
  }
  bool poll()
  {
    if ((++Polled & 65535) == 0 && Cancelled && Cancelled())
    {
      Error = "interrupted";
      return false;
    }
    return true;
  }
  std::size_t left() const { return static_cast<std::size_t>(End - P); }

  /// The next white-space separated word (at most 256 characters), lower-cased when `lower`.
  bool word(std::string& out, bool lower = true) { return nextWord(P, End, out, lower); }
  /// Past the end of the current line (binary data starts after it).
  void skipLine()
  {
    const void* nl = std::memchr(P, '\n', left());
    P = nl ? static_cast<const char*>(nl) + 1 : End;
  }
  /// A count declared by a section header: a non-negative integer that `values` values of
  /// `width` bytes (binary) or of at least two bytes (ASCII: a digit and a separator) fit in
  /// what is left of the file. Read as a double so that 1e34 is refused by size, not wrapped.
  bool count(const std::string& what, std::size_t perItem, std::size_t width, std::size_t& n)
  {
    const char* at = P;
    std::string text;
    if (!word(text))
    {
      return fail(at, what + " needs a non-negative count (the file ends)");
    }
    char* stop = nullptr;
    const double v = std::strtod(text.c_str(), &stop);
    if (stop != text.c_str() + text.size() || !(v >= 0) || v != std::floor(v))
    {
      return fail(at, what + " needs a non-negative count, not '" + text.substr(0, 40) + "'");
    }
    // (a count of array components or tuples, perItem 0, is bounded by the file size as well:
    // their product is checked by the caller)
    const double bytesPer = std::max(1.0, static_cast<double>(perItem) * static_cast<double>(Binary ? width : 2));
    if (v * bytesPer > static_cast<double>(left()) + 1.0)
    {
      std::ostringstream m;
      m.precision(0);
      m << std::fixed << what << " declares " << v << ", more than a file of " << (End - Begin)
        << " bytes can hold";
      return fail(at, m.str());
    }
    n = static_cast<std::size_t>(v);
    return true;
  }
  /// Reads `n` values of `type` and hands each to `sink(value, index)` (false: stop, failed),
  /// or with `skip` only checks them (ASCII) or steps over them (binary).
  template <class Sink>
  bool eachValue(std::size_t n, const std::string& type, const std::string& what, bool skip, Sink&& sink)
  {
    const std::size_t width = typeWidth(type);
    if (width == 0)
    {
      return fail(P, what + ": data type '" + type.substr(0, 40) + "' is not read (numbers only)");
    }
    if (Binary)
    {
      skipLine();
      if (left() / width < n)
      {
        return fail(P, what + ": " + std::to_string(n) + " values declared, the file ends before");
      }
      const auto* b = reinterpret_cast<const unsigned char*>(P);
      P += n * width;
      if (skip)
      {
        return true;
      }
      const bool isFloat = type == "float" || type == "double";
      const bool isSigned = type.compare(0, 8, "unsigned") != 0 && type != "vtktypeuint64";
      for (std::size_t i = 0; i < n; ++i, b += width)
      {
        std::uint64_t bits = 0;
        for (std::size_t k = 0; k < width; ++k)
        {
          bits = (bits << 8) | b[k];
        }
        double value = 0;
        if (isFloat && width == 4)
        {
          const auto u = static_cast<std::uint32_t>(bits);
          float f;
          std::memcpy(&f, &u, 4);
          value = f;
        }
        else if (isFloat)
        {
          std::memcpy(&value, &bits, 8);
        }
        else if (isSigned)
        {
          const unsigned shift = static_cast<unsigned>(64 - 8 * width);
          value = static_cast<double>(static_cast<std::int64_t>(bits << shift) >> shift);
        }
        else
        {
          value = static_cast<double>(bits);
        }
        if (!sink(value, i) || !poll())
        {
          return false;
        }
      }
      return true;
    }
    std::string text;
    const bool isFloat = type == "float";
    for (std::size_t i = 0; i < n; ++i)
    {
      const char* at = P;
      if (!word(text, false))
      {
        return fail(at, what + ": " + std::to_string(n) + " values declared, the file ends after " +
            std::to_string(i));
      }
      char* stop = nullptr;
      double v = std::strtod(text.c_str(), &stop); // "nan", "inf" kept: validation names them
      if (stop != text.c_str() + text.size())
      {
        return fail(at, what + ": '" + text.substr(0, 40) + "' is not a number");
      }
      if (isFloat)
      {
        // what the file declares (and vtkPolyDataReader reads): a float; beyond its range, infinite
        v = std::fabs(v) > std::numeric_limits<float>::max() ? (v > 0 ? 1.0 : -1.0) * std::numeric_limits<double>::infinity()
                                                            : static_cast<double>(static_cast<float>(v));
      }
      if ((!skip && !sink(v, i)) || !poll())
      {
        return false;
      }
    }
    return true;
  }
  /// `n` numbers of `type` appended to `out` as doubles (out null: skipped).
  bool numbers(std::size_t n, const std::string& type, std::vector<double>* out, const std::string& what)
  {
    if (out)
    {
      out->reserve(out->size() + n);
    }
    return eachValue(n, type, what, out == nullptr, [&](double v, std::size_t) {
      out->push_back(v);
      return true;
    });
  }
  /// `n` integers (point counts, ids, offsets) of `type`, checked to be integers.
  bool integers(std::size_t n, const std::string& type, std::vector<long long>& out, const std::string& what)
  {
    if (type == "float" || type == "double")
    {
      return fail(P, what + ": integers needed, the type is " + type);
    }
    out.clear();
    out.reserve(n);
    return eachValue(n, type, what, false, [&](double v, std::size_t i) {
      if (!(std::fabs(v) < 9e15) || v != std::floor(v))
      {
        return fail(P, what + ": value " + std::to_string(i + 1) + " is not an integer");
      }
      out.push_back(static_cast<long long>(v));
      return true;
    });
  }
  /// "METADATA" blocks (after an array): lines up to the first empty one.
  void skipMetadata()
  {
    skipLine();
    while (P < End)
    {
      const char* lineStart = P;
      skipLine();
      const char* q = lineStart;
      while (q < P && isSpace(*q))
      {
        ++q;
      }
      if (q == P)
      {
        return; // an empty line ends the block
      }
    }
  }
  /// Peeks whether the next word is `keyword` (lower case); consumes it when it is.
  bool next(const char* keyword)
  {
    const char* save = P;
    std::string w;
    if (word(w) && w == keyword)
    {
      return true;
    }
    P = save;
    return false;
  }
  /// `n` strings of a string array: in ASCII a line each (VTK escapes what is not printable);
  /// in binary each is its length (1, 2, 4 or 8 big-endian bytes, the top two bits of the first
  /// saying which: 3, 2, 1, 0) and its bytes.
  bool skipStrings(std::size_t n, const std::string& what)
  {
    skipLine();
    for (std::size_t i = 0; i < n; ++i)
    {
      if (P >= End)
      {
        return fail(P, what + ": " + std::to_string(n) + " strings declared, the file ends after " + std::to_string(i));
      }
      if (!Binary)
      {
        skipLine();
        continue;
      }
      const auto* b = reinterpret_cast<const unsigned char*>(P);
      const std::size_t width = std::size_t(1) << (3 - (b[0] >> 6)); // 1, 2, 4, 8
      if (left() < width)
      {
        return fail(P, what + ": string " + std::to_string(i + 1) + " is cut short");
      }
      std::uint64_t length = b[0] & 0x3f;
      for (std::size_t k = 1; k < width; ++k)
      {
        length = (length << 8) | b[k];
      }
      P += width;
      if (length > left())
      {
        return fail(P, what + ": string " + std::to_string(i + 1) + " declares " + std::to_string(length) +
            " bytes, the file ends before");
      }
      P += length;
      if (!poll())
      {
        return false;
      }
    }
    return true;
  }
  bool fieldData();
  bool cells(const std::string& keyword, const char* headerAt, ParsedMesh& mesh);
};

/// FIELD name arrays, each "name components tuples type" and its values: skipped (not needed).
bool LegacyParser::fieldData()
{
  std::string name;
  word(name, false);
  std::size_t arrays = 0;
  if (!count("FIELD " + name.substr(0, 40), 4, 1, arrays)) // an array takes at least 4 words
  {
    return false;
  }
  for (std::size_t a = 0; a < arrays; ++a)
  {
    const char* at = P;
    std::string arrayName, type;
    if (!word(arrayName, false))
    {
      return fail(at, "FIELD " + name.substr(0, 40) + " declares " + std::to_string(arrays) +
          " arrays, the file ends after " + std::to_string(a));
    }
    if (arrayName == "NULL_ARRAY")
    {
      continue;
    }
    std::size_t components = 0, tuples = 0;
    const std::string what = "FIELD array " + arrayName.substr(0, 40);
    if (!count(what + " components", 0, 1, components) || !count(what + " tuples", 0, 1, tuples) ||
      !word(type))
    {
      return fail(at, what + " needs 'name components tuples type'");
    }
    const bool strings = type == "string" || type == "utf8_string";
    const double values = static_cast<double>(components) * static_cast<double>(tuples);
    // at least a byte a string (its line end, or its length), two bytes an ASCII number
    const double perValue = strings ? 1.0 : Binary ? static_cast<double>(std::max<std::size_t>(typeWidth(type), 1)) : 2.0;
    if (values * perValue > static_cast<double>(left()) + 1.0)
    {
      return fail(at, what + " declares " + std::to_string(components) + " x " + std::to_string(tuples) +
          " values, more than the file can hold");
    }
    if (strings ? !skipStrings(components * tuples, what) : !numbers(components * tuples, type, nullptr, what))
    {
      return false;
    }
    if (next("metadata"))
    {
      skipMetadata();
    }
  }
  return true;
}

/// VERTICES / LINES / POLYGONS / TRIANGLE_STRIPS n size, in the format before version 5 (each
/// cell its point count then its ids; `size` values in all) or from version 5 on (OFFSETS with
/// n values from 0 to `size`, never decreasing, then CONNECTIVITY with `size` ids). Polygons are
/// kept (fewer than 3 points: counted as skipped), strips split into triangles, the rest read
/// past.
bool LegacyParser::cells(const std::string& keyword, const char* headerAt, ParsedMesh& mesh)
{
  std::string upper = keyword;
  std::transform(upper.begin(), upper.end(), upper.begin(),
    [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  std::size_t n = 0, size = 0;
  if (!count(upper + " cells", 1, 1, n) || !count(upper + " values", 1, 4, size))
  {
    return false;
  }
  // version 5: the line after the header is "OFFSETS type"
  const char* afterCounts = P;
  skipLine();
  const bool v5 = next("offsets");
  if (!v5)
  {
    P = afterCounts;
  }
  std::vector<long long> offsets, ids;
  if (v5)
  {
    std::string type;
    word(type);
    if (!integers(n, type, offsets, upper + " OFFSETS"))
    {
      return false;
    }
    if (!next("connectivity"))
    {
      return fail(P, upper + ": CONNECTIVITY expected after the offsets");
    }
    word(type);
    if (!integers(size, type, ids, upper + " CONNECTIVITY"))
    {
      return false;
    }
    if (!offsets.empty() && offsets.front() != 0)
    {
      return fail(headerAt, upper + " offsets must start at 0 (the file is damaged)");
    }
    for (std::size_t i = 1; i < offsets.size(); ++i)
    {
      if (offsets[i] < offsets[i - 1])
      {
        return fail(headerAt, upper + " offset " + std::to_string(i + 1) +
            " is smaller than the one before (the file is damaged)");
      }
    }
    if (offsets.empty() ? size != 0 : static_cast<unsigned long long>(offsets.back()) != size)
    {
      return fail(headerAt, upper + " offsets end at " +
          std::to_string(offsets.empty() ? 0 : offsets.back()) + ", not at the " + std::to_string(size) +
          " point ids declared (the file is damaged)");
    }
  }
  else
  {
    std::vector<long long> values;
    if (!integers(size, "int", values, upper))
    {
      return false;
    }
    // each cell: its point count, then its ids; every cell must fit in the section
    offsets.reserve(n + 1);
    offsets.push_back(0);
    std::size_t at = 0;
    for (std::size_t cell = 0; cell < n; ++cell)
    {
      if (at >= values.size())
      {
        return fail(headerAt, upper + " declares " + std::to_string(n) + " cells, its " + std::to_string(size) +
            " values end after " + std::to_string(cell) + " (the file is damaged)");
      }
      const long long points = values[at];
      if (points < 0 || static_cast<unsigned long long>(points) > values.size() - at - 1)
      {
        return fail(headerAt, upper + " cell " + std::to_string(cell + 1) + " lists " + std::to_string(points) +
            " points, but only " + std::to_string(values.size() - at - 1) + " of the section's " +
            std::to_string(size) + " values are left for them (the file is damaged)");
      }
      ids.insert(ids.end(), values.begin() + static_cast<std::ptrdiff_t>(at + 1),
        values.begin() + static_cast<std::ptrdiff_t>(at + 1 + static_cast<std::size_t>(points)));
      offsets.push_back(static_cast<long long>(ids.size()));
      at += 1 + static_cast<std::size_t>(points);
    }
    if (at != values.size())
    {
      return fail(headerAt, upper + " declares " + std::to_string(size) + " values, its " + std::to_string(n) +
          " cells use " + std::to_string(at) + " (the file is damaged)");
    }
  }
  if (keyword != "polygons" && keyword != "triangle_strips")
  {
    return true; // vertices and lines are not part of a surface
  }
  for (std::size_t c = 0; c + 1 < offsets.size(); ++c)
  {
    const auto first = static_cast<std::size_t>(offsets[c]);
    const auto count = static_cast<std::size_t>(offsets[c + 1] - offsets[c]);
    if (count < 3)
    {
      ++mesh.SkippedFaces;
      continue;
    }
    if (keyword == "polygons")
    {
      mesh.Connectivity.insert(mesh.Connectivity.end(), ids.begin() + static_cast<std::ptrdiff_t>(first),
        ids.begin() + static_cast<std::ptrdiff_t>(first + count));
      mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
      continue;
    }
    // a strip of k points is k - 2 triangles, every other one turned to keep the orientation
    for (std::size_t k = 0; k + 2 < count; ++k)
    {
      const long long a = ids[first + k], b = ids[first + k + 1], t = ids[first + k + 2];
      if (k % 2 == 0)
      {
        mesh.Connectivity.insert(mesh.Connectivity.end(), { a, b, t });
      }
      else
      {
        mesh.Connectivity.insert(mesh.Connectivity.end(), { b, a, t });
      }
      mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
    }
  }
  return true;
}

bool LegacyParser::parse(ParsedMesh& mesh, std::string& error)
{
  mesh = ParsedMesh();
  mesh.Offsets.push_back(0);
  auto refuse = [&]() {
    error = Error;
    mesh = ParsedMesh();
    return false;
  };
  if (P == End)
  {
    Error = "the file is empty";
    return refuse();
  }
  static const char magic[] = "# vtk datafile";
  std::string first(P, std::min<std::size_t>(left(), sizeof(magic) - 1));
  std::transform(first.begin(), first.end(), first.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (first != magic)
  {
    fail(P, "not a legacy VTK file (the first line must be '# vtk DataFile Version x.y')");
    return refuse();
  }
  skipLine(); // version
  skipLine(); // title
  std::string w;
  const char* at = P;
  if (!word(w))
  {
    fail(at, "the file ends after the header (ASCII or BINARY expected)");
    return refuse();
  }
  if (w.compare(0, 5, "ascii") == 0)
  {
    Binary = false;
  }
  else if (w.compare(0, 6, "binary") == 0)
  {
    Binary = true;
  }
  else
  {
    fail(at, "ASCII or BINARY expected, not '" + w.substr(0, 40) + "'");
    return refuse();
  }
  at = P;
  if (!word(w) || w != "dataset")
  {
    fail(at, "DATASET POLYDATA expected");
    return refuse();
  }
  at = P;
  word(w);
  if (w != "polydata")
  {
    fail(at, "not a legacy VTK POLYDATA file (it holds '" + w.substr(0, 40) +
        "'; other dataset types are not surfaces: extract one first, e.g. with vtkGeometryFilter)");
    return refuse();
  }
  bool havePoints = false;
  while (true)
  {
    at = P;
    if (!word(w))
    {
      break;
    }
    if (w == "point_data" || w == "cell_data")
    {
      break; // the data arrays are not needed for a cage: not read
    }
    if (w == "field")
    {
      if (!fieldData())
      {
        return refuse();
      }
    }
    else if (w == "points")
    {
      if (havePoints)
      {
        fail(at, "a second POINTS section");
        return refuse();
      }
      havePoints = true;
      std::size_t n = 0;
      std::string type;
      if (!count("POINTS", 3, 4, n))
      {
        return refuse();
      }
      if (!word(type) || !numbers(3 * n, type, &mesh.Points, "POINTS"))
      {
        fail(at, "POINTS needs a data type");
        return refuse();
      }
    }
    else if (w == "metadata")
    {
      skipMetadata();
    }
    else if (w == "vertices" || w == "lines" || w == "polygons" || w == "triangle_strips")
    {
      if (!cells(w, at, mesh))
      {
        return refuse();
      }
    }
    else
    {
      fail(at, "unknown section '" + w.substr(0, 40) +
          "' (a POLYDATA file has FIELD, POINTS, VERTICES, LINES, POLYGONS, TRIANGLE_STRIPS, POINT_DATA, CELL_DATA)");
      return refuse();
    }
  }
  const auto points = static_cast<long long>(mesh.Points.size() / 3);
  for (std::int64_t id : mesh.Connectivity)
  {
    if (id < 0 || id >= points)
    {
      Error = "cells refer to points that do not exist (point " + std::to_string(id) + "; the file has " +
        std::to_string(points) + " points, numbered from 0)";
      return refuse();
    }
  }
  return true;
}

} // namespace

bool nextWord(const char*& p, const char* end, std::string& out, bool lower)
{
  while (p < end && isSpace(*p))
  {
    ++p;
  }
  const char* start = p;
  while (p < end && !isSpace(*p) && p - start <= 256)
  {
    ++p;
  }
  out.assign(start, p);
  if (lower)
  {
    std::transform(out.begin(), out.end(), out.begin(),
      [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  return !out.empty();
}

bool parseLegacyVTK(
  const char* data, std::size_t size, ParsedMesh& mesh, std::string& error, const std::function<bool()>& cancelled)
{
  LegacyParser parser(data, size, cancelled);
  return parser.parse(mesh, error);
}

} // namespace sdfcage_cli
