// SDFCage — CLI: see CLIMeshIO.h.
#include "CLIMeshIO.h"

#include "CLIMessages.h"
#include "CLIParsers.h"

#include "Mesh/Shapes.h" // sdfcage::makeBuiltinShape (Core)

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkDataArraySelection.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkOBJWriter.h>
#include <vtkOFFReader.h>
#include <vtkOFFWriter.h>
#include <vtkPLYWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkSTLReader.h>
#include <vtkSTLWriter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;

namespace sdfcage_cli
{

namespace
{

MessageCollector* collector()
{
  return MessageCollector::SafeDownCast(vtkOutputWindow::GetInstance());
}

void clearMessages()
{
  if (MessageCollector* c = collector())
  {
    c->clear();
  }
}

/// The first VTK error since clearMessages(), or "".
std::string firstVTKError()
{
  MessageCollector* c = collector();
  return (c && !c->errors().empty()) ? c->errors().front() : std::string();
}

/// The whole file in memory (the size was checked by the caller).
bool slurp(const std::string& path, std::string& bytes)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    return false;
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  bytes = buffer.str();
  return !in.bad();
}

vtkSmartPointer<vtkPolyData> toPolyData(const ParsedMesh& ply)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const vtkIdType n = static_cast<vtkIdType>(ply.Points.size() / 3);
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->SetPoint(i, ply.Points.data() + 3 * i);
  }
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(static_cast<vtkIdType>(ply.Offsets.size()));
  for (std::size_t i = 0; i < ply.Offsets.size(); ++i)
  {
    offsets->SetValue(static_cast<vtkIdType>(i), static_cast<vtkIdType>(ply.Offsets[i]));
  }
  connectivity->SetNumberOfValues(static_cast<vtkIdType>(ply.Connectivity.size()));
  for (std::size_t i = 0; i < ply.Connectivity.size(); ++i)
  {
    connectivity->SetValue(static_cast<vtkIdType>(i), static_cast<vtkIdType>(ply.Connectivity[i]));
  }
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);
  vtkSmartPointer<vtkPolyData> mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->SetPoints(points);
  mesh->SetPolys(polys);
  return mesh;
}

/// VTK XML PolyData: the arrays that are read (the points and the cell arrays; the data arrays
/// are not read, see readMesh) must declare the components they have: 3 for points, 1 for cell
/// connectivity and offsets. vtkXMLPolyDataReader allocates components x points before it reads
/// (a Points array declaring 1e9 components on 4 points allocated 8 GB and ran for minutes).
/// Only the XML before the appended data (binary) is scanned.
bool checkXMLComponents(const std::string& bytes, std::string& why)
{
  const std::size_t xmlEnd = std::min(bytes.find("<AppendedData"), bytes.size());
  struct Section
  {
    const char* Open;
    const char* Close;
    double Components;
  };
  const Section sections[] = { { "<Points", "</Points>", 3 }, { "<Verts", "</Verts>", 1 },
    { "<Lines", "</Lines>", 1 }, { "<Strips", "</Strips>", 1 }, { "<Polys", "</Polys>", 1 } };
  const std::string attribute = "NumberOfComponents=";
  for (const Section& section : sections)
  {
    std::size_t open = bytes.find(section.Open);
    while (open < xmlEnd)
    {
      const std::size_t close = std::min(bytes.find(section.Close, open), xmlEnd);
      for (std::size_t a = bytes.find(attribute, open); a < close; a = bytes.find(attribute, a + 1))
      {
        std::size_t v = a + attribute.size();
        if (v < bytes.size() && (bytes[v] == '"' || bytes[v] == '\''))
        {
          ++v;
        }
        const double components = std::strtod(bytes.c_str() + v, nullptr);
        if (components != section.Components)
        {
          std::ostringstream m;
          m << "an array of " << (section.Open + 1) << " declares " << bytes.substr(v, std::min<std::size_t>(20, bytes.find_first_of("\"'", v) - v))
            << " components, it must have " << section.Components;
          why = m.str();
          return false;
        }
      }
      open = bytes.find(section.Open, close);
    }
  }
  return true;
}

/// Legacy VTK cell lists before file version 5 ("POLYGONS n size" followed by `size` values,
/// each cell its point count and then its points): vtkPolyDataReader reads the `size` values and
/// then walks them cell by cell trusting every count, so a count larger than what is left of the
/// section made it read past its buffer (a fuzzed file crashed it). Walk the section here first:
/// every cell must fit in it. `start` is where the values begin (the line after the header);
/// sections VTK cannot read at all (too short, not numbers) are left for VTK to refuse. Files of
/// version 5 and later (an OFFSETS line follows): checkLegacyCellsV5.
/// Version 5 and later ("POLYGONS n size", then "OFFSETS type" with n offsets and "CONNECTIVITY
/// type" with `size` point ids): vtkPolyDataReader trusts the offsets, so a damaged list (a
/// fuzzed file: offsets cut short by bytes that are no numbers) made it read past its buffer.
/// Both lists must be there in full, the offsets start at 0, never decrease and end at `size`.
bool checkLegacyCellsV5(const std::string& bytes, std::size_t at, bool binary, double declaredOffsets,
  double declaredValues, const std::string& keyword, int lineNumber, std::string& why)
{
  const auto n = static_cast<std::size_t>(declaredOffsets); // both fit: checked against the file size
  const auto values = static_cast<std::size_t>(declaredValues);
  auto refuse = [&](const std::string& what) {
    why = "line " + std::to_string(lineNumber) + ": " + keyword + " " + what + " (the file is damaged)";
    return false;
  };
  // "WORD type" at `at`: the type's size in binary files, and `at` past the line
  auto header = [&](const char* word, std::size_t& width) {
    const std::size_t length = std::strlen(word);
    at = bytes.find_first_not_of(" \t\r\n", at);
    if (at == std::string::npos || bytes.compare(at, length, word) != 0)
    {
      return false;
    }
    const std::size_t eol = bytes.find('\n', at);
    if (eol == std::string::npos)
    {
      return false;
    }
    const std::string type = bytes.substr(at + length, eol - at - length);
    width = type.find("64") != std::string::npos ? 8 : 4;
    at = eol + 1;
    return true;
  };
  // `count` integers from `at` (big-endian of `width` bytes in binary files)
  auto read = [&](std::size_t count, std::size_t width, std::vector<long long>* out) {
    if (binary)
    {
      if (at > bytes.size() || (bytes.size() - at) / width < count)
      {
        return false;
      }
      if (out)
      {
        const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
        for (std::size_t i = 0; i < count; ++i)
        {
          std::uint64_t v = 0;
          for (std::size_t k = 0; k < width; ++k)
          {
            v = (v << 8) | b[i * width + k];
          }
          out->push_back(width == 8 ? static_cast<long long>(v) : static_cast<std::int32_t>(v));
        }
      }
      at += count * width;
      return true;
    }
    const char* cursor = bytes.c_str() + std::min(at, bytes.size());
    for (std::size_t i = 0; i < count; ++i)
    {
      char* end = nullptr;
      errno = 0;
      const long long v = std::strtoll(cursor, &end, 10);
      if (end == cursor || errno != 0)
      {
        return false;
      }
      cursor = end;
      if (out)
      {
        out->push_back(v);
      }
    }
    at = static_cast<std::size_t>(cursor - bytes.c_str());
    return true;
  };
  std::size_t width = 4;
  std::vector<long long> offsets;
  offsets.reserve(n);
  if (!header("OFFSETS", width) || !read(n, width, &offsets))
  {
    return refuse("declares " + std::to_string(n) + " offsets, but fewer are there");
  }
  if (!offsets.empty() && offsets.front() != 0)
  {
    return refuse("offsets must start at 0");
  }
  for (std::size_t i = 1; i < offsets.size(); ++i)
  {
    if (offsets[i] < offsets[i - 1])
    {
      return refuse("offset " + std::to_string(i + 1) + " is smaller than the one before");
    }
  }
  if (!offsets.empty() && static_cast<unsigned long long>(offsets.back()) != values)
  {
    return refuse("offsets end at " + std::to_string(offsets.back()) + ", not at the " + std::to_string(values) +
      " point ids declared");
  }
  if (!header("CONNECTIVITY", width) || !read(values, width, nullptr))
  {
    return refuse("declares " + std::to_string(values) + " point ids, but fewer are there");
  }
  return true;
}

bool checkLegacyCells(const std::string& bytes, std::size_t start, bool binary, double declaredCells,
  double declaredValues, const std::string& keyword, int lineNumber, std::string& why)
{
  std::size_t first = bytes.find_first_not_of(" \t\r\n", start);
  if (first != std::string::npos && bytes.compare(first, 7, "OFFSETS") == 0)
  {
    return checkLegacyCellsV5(bytes, start, binary, declaredCells, declaredValues, keyword, lineNumber, why);
  }
  const auto values = static_cast<std::size_t>(declaredValues); // fits: checked against the file size
  auto refuse = [&](std::size_t cell, long long points, std::size_t at) {
    std::ostringstream m;
    m << "line " << lineNumber << ": " << keyword << " cell " << cell + 1 << " lists " << points
      << " points, but only " << (values - at - 1) << " of the section's " << values
      << " values are left for them (the file is damaged)";
    why = m.str();
    return false;
  };
  std::size_t cell = 0;
  std::size_t at = 0; // index of the value being read
  if (binary)
  {
    // big-endian 32-bit integers, right after the header line
    if (start > bytes.size() || bytes.size() - start < 4 * values)
    {
      return true; // VTK refuses a short section itself
    }
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + start);
    while (at < values)
    {
      const std::int32_t count = static_cast<std::int32_t>((std::uint32_t(b[4 * at]) << 24) |
        (std::uint32_t(b[4 * at + 1]) << 16) | (std::uint32_t(b[4 * at + 2]) << 8) | std::uint32_t(b[4 * at + 3]));
      if (count < 0 || static_cast<std::size_t>(count) > values - at - 1)
      {
        return refuse(cell, count, at);
      }
      at += 1 + static_cast<std::size_t>(count);
      ++cell;
    }
    return true;
  }
  const char* cursor = bytes.c_str() + std::min(start, bytes.size());
  std::size_t skip = 0; // values of the current cell still to pass over
  while (at < values)
  {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(cursor, &end, 10);
    if (end == cursor || errno != 0)
    {
      return true; // not a number: VTK refuses the section itself
    }
    cursor = end;
    if (skip > 0)
    {
      --skip;
    }
    else
    {
      if (v < 0 || static_cast<unsigned long long>(v) > values - at - 1)
      {
        return refuse(cell, v, at);
      }
      skip = static_cast<std::size_t>(v);
      ++cell;
    }
    ++at;
  }
  return true;
}

/// Legacy VTK files: every count a section header declares (POINTS n, POLYGONS n size, ...,
/// POINT_DATA n, field arrays "name components tuples type") must fit in the file (at least
/// two bytes a value in ASCII, one in binary) before vtkPolyDataReader allocates for it: a
/// header claiming a billion points made it allocate and loop for minutes.
bool checkLegacyCounts(const std::string& bytes, std::string& why)
{
  const double size = static_cast<double>(bytes.size());
  bool binary = false;
  std::size_t pos = 0;
  int lineNumber = 0;
  double tuples = 0; // of the current POINT_DATA / CELL_DATA section
  while (pos < bytes.size())
  {
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos)
    {
      end = bytes.size();
    }
    const std::string line = bytes.substr(pos, std::min<std::size_t>(end - pos, 256));
    pos = end + 1;
    ++lineNumber;
    if (lineNumber == 3)
    {
      binary = line.compare(0, 6, "BINARY") == 0;
    }
    std::istringstream in(line);
    std::string keyword;
    in >> keyword;
    const double perValue = binary ? 1.0 : 2.0;
    // a declared count as text (no conversion to an integer type: a header may declare 1e34)
    auto count = [](double v) {
      std::ostringstream c;
      c << std::fixed << std::setprecision(0) << v;
      return c.str();
    };
    auto tooLarge = [&](double values, const std::string& what) {
      if (values * perValue <= size + 1.0)
      {
        return false;
      }
      std::ostringstream m;
      m << "line " << lineNumber << " declares " << what << ", more than a file of " << bytes.size()
        << " bytes can hold";
      why = m.str();
      return true;
    };
    if (keyword == "POINTS" || keyword == "POINT_DATA" || keyword == "CELL_DATA")
    {
      double n = -1;
      if (!(in >> n) || n < 0)
      {
        why = "line " + std::to_string(lineNumber) + ": " + keyword + " needs a non-negative count";
        return false;
      }
      if (tooLarge(keyword == "POINTS" ? 3 * n : n, count(n) + " " +
              (keyword == "POINTS" ? "points" : "data tuples")))
      {
        return false;
      }
      if (keyword != "POINTS")
      {
        tuples = n;
      }
    }
    else if (keyword == "SCALARS" || keyword == "COLOR_SCALARS" || keyword == "LOOKUP_TABLE")
    {
      // values per tuple (SCALARS name type [components], COLOR_SCALARS name components) times
      // the tuples of the data section, or a lookup table's 4 values per entry (LOOKUP_TABLE
      // name size): VTK allocates for them before reading (SCALARS with 1e8 components on 4
      // points allocated 7 GB)
      std::string name, type;
      double components = 1;
      double values = -1;
      if (keyword == "SCALARS")
      {
        if ((in >> name >> type) && (in >> components))
        {
          values = components * tuples;
        }
        else
        {
          values = tuples;
        }
      }
      else if (keyword == "COLOR_SCALARS")
      {
        if (in >> name >> components)
        {
          values = components * tuples;
        }
      }
      else if ((in >> name >> components))
      {
        values = 4 * components; // LOOKUP_TABLE name size ("LOOKUP_TABLE default" has none)
      }
      if (components < 0)
      {
        why = "line " + std::to_string(lineNumber) + ": " + keyword + " needs a non-negative count";
        return false;
      }
      if (values >= 0 && tooLarge(values, keyword + " " + name + " of " + count(values) + " values"))
      {
        return false;
      }
    }
    else if (keyword == "VERTICES" || keyword == "LINES" || keyword == "POLYGONS" || keyword == "TRIANGLE_STRIPS")
    {
      double n = -1, values = -1;
      if (!(in >> n >> values) || n < 0 || values < 0)
      {
        why = "line " + std::to_string(lineNumber) + ": " + keyword + " needs two non-negative counts";
        return false;
      }
      if (tooLarge(std::max(n, values), count(n) + " cells of " +
              count(values) + " values"))
      {
        return false;
      }
      if (!checkLegacyCells(bytes, pos, binary, n, values, keyword, lineNumber, why))
      {
        return false;
      }
    }
    else if (!keyword.empty())
    {
      // a field array: "name components tuples type"
      double components = -1, tuples = -1;
      std::string type, extra;
      if ((in >> components >> tuples >> type) && !(in >> extra) && components >= 0 && tuples >= 0 &&
        (type == "float" || type == "double" || type == "int" || type == "vtkIdType" || type == "char" ||
          type == "unsigned_char" || type == "short" || type == "unsigned_short" || type == "unsigned_int" ||
          type == "long" || type == "unsigned_long" || type == "vtktypeint64" || type == "vtktypeuint64" ||
          type == "bit" || type == "string"))
      {
        if (tooLarge(components * tuples, "an array of " + count(tuples) +
                " tuples"))
        {
          return false;
        }
      }
    }
  }
  return true;
}

/// Binary STL: 80 bytes of header, the triangle count, 50 bytes a triangle. Whether the file is
/// binary is decided as vtkSTLReader decides it (vtksys' DetectFileType on the first bytes, also
/// for a file that starts with "solid"), so that the count it would trust is checked.
bool checkBinarySTL(const std::string& path, std::uintmax_t size, std::string& why)
{
  if (vtksys::SystemTools::DetectFileType(path.c_str()) == vtksys::SystemTools::FileTypeText)
  {
    return true; // read as ASCII by VTK
  }
  std::ifstream in(path, std::ios::binary);
  char head[84] = {};
  in.read(head, sizeof(head));
  const std::streamsize got = in.gcount();
  if (got < 84)
  {
    why = "a binary STL file needs at least 84 bytes (header and triangle count), this one has " +
      std::to_string(size);
    return false;
  }
  const auto* b = reinterpret_cast<const unsigned char*>(head + 80);
  const std::uint64_t count = b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint64_t>(b[3]) << 24);
  if (84 + 50 * count > size)
  {
    why = "the binary STL header declares " + std::to_string(count) + " triangles (" +
      std::to_string(84 + 50 * count) + " bytes), the file has " + std::to_string(size) + " bytes";
    return false;
  }
  return true;
}

} // namespace

const char* supportedExtensions()
{
  return ".off .obj .ply .stl .vtp .vtk";
}

std::string lowerExtension(const std::string& path)
{
  std::string ext = fs::path(path).extension().string();
  std::transform(
    ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool isSupportedExtension(const std::string& path)
{
  const std::string ext = lowerExtension(path);
  return ext == ".off" || ext == ".obj" || ext == ".ply" || ext == ".stl" || ext == ".vtp" || ext == ".vtk";
}

vtkSmartPointer<vtkPolyData> readMesh(
  const std::string& path, std::string& error, const std::function<bool()>& cancelled)
{
  std::error_code ec;
  if (!fs::exists(path, ec))
  {
    error = "cannot read '" + path + "': no such file";
    return nullptr;
  }
  if (fs::is_directory(path, ec))
  {
    error = "cannot read '" + path + "': it is a folder, not a mesh file";
    return nullptr;
  }
  if (!fs::is_regular_file(path, ec))
  {
    error = "cannot read '" + path + "': not a regular file";
    return nullptr;
  }
  if (!std::ifstream(path).good())
  {
    error = "cannot read '" + path + "': permission denied or unreadable";
    return nullptr;
  }
  if (!isSupportedExtension(path))
  {
    error = "cannot read '" + path + "': unknown extension '" + lowerExtension(path) +
      "' (supported: " + supportedExtensions() + ")";
    return nullptr;
  }
  const std::uintmax_t fileSize = fs::file_size(path, ec);
  if (ec || fileSize == 0)
  {
    error = "cannot read '" + path + "': the file is empty";
    return nullptr;
  }

  clearMessages();
  const std::string ext = lowerExtension(path);
  vtkSmartPointer<vtkPolyData> mesh;
  unsigned long errorCode = 0;
  // VTK's readers that poll AbortExecute stop early on Ctrl-C (the caller checks afterwards).
  vtkNew<vtkCallbackCommand> abortOnCancel;
  abortOnCancel->SetClientData(const_cast<std::function<bool()>*>(&cancelled));
  abortOnCancel->SetCallback([](vtkObject* caller, unsigned long, void* clientData, void*) {
    const auto* cancel = static_cast<const std::function<bool()>*>(clientData);
    if (*cancel && (*cancel)())
    {
      static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
    }
  });
  auto run = [&](vtkAlgorithm* reader) {
    reader->AddObserver(vtkCommand::ProgressEvent, abortOnCancel);
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = vtkPolyData::SafeDownCast(reader->GetOutputDataObject(0));
  };
  if (ext == ".off")
  {
    vtkNew<vtkOFFReader> reader;
    reader->SetFileName(path.c_str());
    run(reader);
  }
  else if (ext == ".obj" || ext == ".ply")
  {
    // our own parsers: vtkPLYReader trusts the header's counts, vtkOBJReader reads bad numbers
    // as other numbers (see CLIParsers.h)
    std::string bytes;
    if (!slurp(path, bytes))
    {
      error = "cannot read '" + path + "': read error";
      return nullptr;
    }
    ParsedMesh parsed;
    std::string why;
    const bool ok = ext == ".ply" ? parsePLY(bytes.data(), bytes.size(), parsed, why, cancelled)
                                  : parseOBJ(bytes.data(), bytes.size(), parsed, why, cancelled);
    if (!ok)
    {
      error = why == "interrupted" ? why : "cannot read '" + path + "': " + why;
      return nullptr;
    }
    bytes = std::string();
    mesh = toPolyData(parsed);
  }
  else if (ext == ".stl")
  {
    std::string why;
    if (!checkBinarySTL(path, fileSize, why))
    {
      error = "cannot read '" + path + "': " + why;
      return nullptr;
    }
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(path.c_str());
    reader->MergingOn(); // STL stores triangle soup: merge coincident points to get a surface
    run(reader);
  }
  else if (ext == ".vtp")
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    if (!reader->CanReadFile(path.c_str()))
    {
      error = "cannot read '" + path + "': not a VTK XML PolyData (.vtp) file";
      return nullptr;
    }
    {
      std::string bytes;
      std::string why;
      if (!slurp(path, bytes))
      {
        error = "cannot read '" + path + "': read error";
        return nullptr;
      }
      if (!checkXMLComponents(bytes, why))
      {
        error = "cannot read '" + path + "': " + why;
        return nullptr;
      }
    }
    reader->SetFileName(path.c_str());
    // Only the points and cells make the cage: the point and cell data arrays are not read.
    // Their sizes are not checked by the reader before it allocates (a PointData array declaring
    // 1e9 components on 4 points allocated 8 GB and ran for minutes).
    reader->UpdateInformation();
    reader->GetPointDataArraySelection()->DisableAllArrays();
    reader->GetCellDataArraySelection()->DisableAllArrays();
    run(reader);
  }
  else // ".vtk"
  {
    std::string bytes;
    std::string why;
    if (!slurp(path, bytes))
    {
      error = "cannot read '" + path + "': read error";
      return nullptr;
    }
    if (!checkLegacyCounts(bytes, why))
    {
      error = "cannot read '" + path + "': " + why;
      return nullptr;
    }
    bytes = std::string();
    vtkNew<vtkPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    if (!reader->IsFilePolyData())
    {
      error = "cannot read '" + path +
        "': not a legacy VTK POLYDATA file (other dataset types are not surfaces; extract one "
        "first, e.g. with vtkGeometryFilter)";
      return nullptr;
    }
    run(reader);
  }
  if (cancelled && cancelled())
  {
    error = "interrupted";
    return nullptr;
  }

  const std::string vtkError = firstVTKError();
  if (errorCode != 0 || !vtkError.empty() || !mesh)
  {
    error = "cannot read '" + path + "'" + (vtkError.empty() ? std::string() : ": " + vtkError);
    return nullptr;
  }
  if (mesh->GetNumberOfPolys() + mesh->GetNumberOfStrips() == 0)
  {
    error = "'" + path + "' contains no polygons (" + std::to_string(mesh->GetNumberOfPoints()) +
      " points): a surface mesh is needed (for a point cloud, reconstruct a surface first)";
    return nullptr;
  }
  // Keep our own copy, detached from the reader.
  vtkSmartPointer<vtkPolyData> copy = vtkSmartPointer<vtkPolyData>::New();
  copy->ShallowCopy(mesh);
  return copy;
}

bool checkWritable(const std::string& path, std::string& error)
{
  std::error_code ec;
  const fs::path p(path);
  if (fs::is_directory(p, ec))
  {
    error = "cannot write '" + path + "': it is a folder";
    return false;
  }
  const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::exists(parent, ec))
  {
    error = "cannot write '" + path + "': the folder '" + parent.string() + "' does not exist";
    return false;
  }
  if (!fs::is_directory(parent, ec))
  {
    error = "cannot write '" + path + "': '" + parent.string() + "' is not a folder";
    return false;
  }
  // The only true test is to open it: an existing file for appending (nothing changes), a new
  // one created and removed again.
  const bool existed = fs::exists(p, ec);
  std::FILE* f = std::fopen(path.c_str(), "ab");
  if (!f)
  {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    return false;
  }
  std::fclose(f);
  if (!existed)
  {
    fs::remove(p, ec);
  }
  return true;
}

bool writeMesh(vtkPolyData* mesh, const std::string& path, std::string& error)
{
  const std::string ext = lowerExtension(path);
  if (!isSupportedExtension(path))
  {
    error = "cannot write '" + path + "': unknown extension '" + ext + "' (supported: " + supportedExtensions() + ")";
    return false;
  }
  clearMessages();
  int ok = 0;
  unsigned long errorCode = 0;
  if (ext == ".off")
  {
    vtkNew<vtkOFFWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetInputData(mesh);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  else if (ext == ".obj")
  {
    vtkNew<vtkOBJWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetInputData(mesh);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  else if (ext == ".ply")
  {
    vtkNew<vtkPLYWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetFileTypeToBinary();
    writer->SetInputData(mesh);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  else if (ext == ".stl")
  {
    vtkNew<vtkSTLWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetFileTypeToBinary();
    writer->SetInputData(mesh);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  else if (ext == ".vtp")
  {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetInputData(mesh);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  else // ".vtk"
  {
    vtkNew<vtkPolyDataWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetFileTypeToBinary();
    writer->SetInputData(mesh);
    ok = writer->Write();
    errorCode = writer->GetErrorCode();
  }
  const std::string vtkError = firstVTKError();
  std::error_code ec;
  if (!ok || errorCode != 0 || !vtkError.empty() || !fs::exists(path, ec))
  {
    error = "cannot write '" + path + "'" +
      (vtkError.empty() ? std::string(": check that the folder exists and is writable") : ": " + vtkError);
    return false;
  }
  return true;
}

vtkSmartPointer<vtkPolyData> builtinShape()
{
  const sdfcage::TriangleMesh shape = sdfcage::makeBuiltinShape();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(shape.Points.size()));
  for (std::size_t i = 0; i < shape.Points.size(); ++i)
  {
    const sdfcage::Vec3& p = shape.Points[i];
    points->SetPoint(static_cast<vtkIdType>(i), p.x(), p.y(), p.z());
  }
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(static_cast<vtkIdType>(shape.Triangles.size()) + 1);
  connectivity->SetNumberOfValues(3 * static_cast<vtkIdType>(shape.Triangles.size()));
  for (std::size_t t = 0; t < shape.Triangles.size(); ++t)
  {
    offsets->SetValue(static_cast<vtkIdType>(t), 3 * static_cast<vtkIdType>(t));
    for (int k = 0; k < 3; ++k)
    {
      connectivity->SetValue(3 * static_cast<vtkIdType>(t) + k, shape.Triangles[t][k]);
    }
  }
  offsets->SetValue(static_cast<vtkIdType>(shape.Triangles.size()), 3 * static_cast<vtkIdType>(shape.Triangles.size()));
  vtkNew<vtkCellArray> triangles;
  triangles->SetData(offsets, connectivity);

  vtkSmartPointer<vtkPolyData> mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->SetPoints(points);
  mesh->SetPolys(triangles);
  return mesh;
}

long long triangleCount(vtkPolyData* mesh)
{
  long long count = 0;
  for (vtkCellArray* cells : { mesh->GetPolys(), mesh->GetStrips() })
  {
    if (!cells)
    {
      continue;
    }
    const vtkIdType n = cells->GetNumberOfCells();
    for (vtkIdType c = 0; c < n; ++c)
    {
      const vtkIdType size = cells->GetCellSize(c);
      count += size >= 3 ? size - 2 : 0;
    }
  }
  return count;
}

} // namespace sdfcage_cli
