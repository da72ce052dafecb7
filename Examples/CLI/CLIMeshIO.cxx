// SDFCage — CLI: see CLIMeshIO.h.
#include "CLIMeshIO.h"

#include "CLIMessages.h"
#include "CLIParsers.h"
#include "CLIWriters.h"

#include "Common/LargePages.h" // sdfcage::ReserveLarge (Core)
#include "Mesh/Shapes.h"       // sdfcage::makeBuiltinShape (Core)

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkDataArraySelection.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkOFFReader.h>
#include <vtkOFFWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

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
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in)
  {
    return false;
  }
  // sized once and read in one call: a stream buffer grown while reading copied a 34 MB scan
  // three times and faulted its pages as often
  const std::streamoff size = in.tellg();
  if (size < 0 || !in.seekg(0))
  {
    std::ifstream stream(path, std::ios::binary); // not seekable (a pipe): read as it comes
    if (!stream)
    {
      return false;
    }
    std::ostringstream buffer;
    buffer << stream.rdbuf();
    bytes = buffer.str();
    return !stream.bad();
  }
  bytes.clear();
  sdfcage::ReserveLarge(bytes, static_cast<std::size_t>(size));
  bytes.resize(static_cast<std::size_t>(size));
  in.read(bytes.data(), size);
  return in.gcount() == size;
}

vtkSmartPointer<vtkPolyData> toPolyData(const ParsedMesh& ply)
{
  // the arrays are written through their pointers, right after they are made (huge pages: see
  // Core/Common/LargePages.h)
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(static_cast<vtkIdType>(ply.Points.size() / 3));
  sdfcage::AdviseLargePages(coordinates->GetPointer(0), ply.Points.size() * sizeof(double));
  std::copy(ply.Points.begin(), ply.Points.begin() + static_cast<std::ptrdiff_t>(ply.Points.size() / 3 * 3),
    coordinates->GetPointer(0));
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(static_cast<vtkIdType>(ply.Offsets.size()));
  sdfcage::AdviseLargePages(offsets->GetPointer(0), ply.Offsets.size() * sizeof(vtkIdType));
  std::transform(ply.Offsets.begin(), ply.Offsets.end(), offsets->GetPointer(0),
    [](std::int64_t v) { return static_cast<vtkIdType>(v); });
  connectivity->SetNumberOfValues(static_cast<vtkIdType>(ply.Connectivity.size()));
  sdfcage::AdviseLargePages(connectivity->GetPointer(0), ply.Connectivity.size() * sizeof(vtkIdType));
  std::transform(ply.Connectivity.begin(), ply.Connectivity.end(), connectivity->GetPointer(0),
    [](std::int64_t v) { return static_cast<vtkIdType>(v); });
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);
  vtkSmartPointer<vtkPolyData> mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->SetPoints(points);
  mesh->SetPolys(polys);
  return mesh;
}

/// The points and the polygons of `mesh` for the writers of CLIWriters.h (triangle strips as
/// triangles, alternately turned so that they keep the strip's orientation).
ParsedMesh fromPolyData(vtkPolyData* mesh)
{
  ParsedMesh out;
  out.Offsets.push_back(0);
  const vtkIdType np = mesh->GetNumberOfPoints();
  out.Points.resize(3 * static_cast<std::size_t>(np));
  for (vtkIdType i = 0; i < np; ++i)
    mesh->GetPoint(i, &out.Points[3 * static_cast<std::size_t>(i)]);
  const auto add = [&out](std::initializer_list<vtkIdType> ids) {
    for (vtkIdType id : ids)
      out.Connectivity.push_back(static_cast<std::int64_t>(id));
    out.Offsets.push_back(static_cast<std::int64_t>(out.Connectivity.size()));
  };
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  if (vtkCellArray* polys = mesh->GetPolys())
  {
    for (polys->InitTraversal(); polys->GetNextCell(n, ids);)
    {
      for (vtkIdType k = 0; k < n; ++k)
        out.Connectivity.push_back(static_cast<std::int64_t>(ids[k]));
      out.Offsets.push_back(static_cast<std::int64_t>(out.Connectivity.size()));
    }
  }
  if (vtkCellArray* strips = mesh->GetStrips())
  {
    for (strips->InitTraversal(); strips->GetNextCell(n, ids);)
      for (vtkIdType k = 0; k + 2 < n; ++k)
        k % 2 == 0 ? add({ ids[k], ids[k + 1], ids[k + 2] }) : add({ ids[k + 1], ids[k], ids[k + 2] });
  }
  return out;
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
  // the whole file in memory, then one of our parsers (same contract: CLIParsers.h)
  using Parser = bool (*)(const char*, std::size_t, ParsedMesh&, std::string&, const std::function<bool()>&);
  auto parseOwn = [&](Parser parse) {
    std::string bytes;
    if (!slurp(path, bytes))
    {
      error = "cannot read '" + path + "': read error";
      return false;
    }
    ParsedMesh parsed;
    std::string why;
    if (!parse(bytes.data(), bytes.size(), parsed, why, cancelled))
    {
      error = why == "interrupted" ? why : "cannot read '" + path + "': " + why;
      return false;
    }
    bytes = std::string();
    mesh = toPolyData(parsed);
    return true;
  };
  if (ext == ".off")
  {
    vtkNew<vtkOFFReader> reader;
    reader->SetFileName(path.c_str());
    run(reader);
  }
  else if (ext == ".obj" || ext == ".ply" || ext == ".stl")
  {
    // our own parsers (CLIParsers.h, and each file's head says why not VTK's reader): vtkPLYReader
    // and vtkSTLReader trust the counts of the file, vtkOBJReader reads bad numbers as other numbers
    if (!parseOwn(ext == ".ply" ? parsePLY : ext == ".obj" ? parseOBJ : parseSTL))
    {
      return nullptr;
    }
  }
  else if (ext == ".vtp")
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    if (!reader->CanReadFile(path.c_str()))
    {
      error = "cannot read '" + path + "': not a VTK XML PolyData (.vtp) file";
      return nullptr;
    }
    std::string inlined;
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
      // appended data moved inline: VTK 9.1 cannot read it with an up-to-date Debian 12's
      // expat (CLIVTP.cxx)
      if (bytes.find("<AppendedData") != std::string::npos && !sdfcage_cli::inlineAppendedXML(bytes, inlined, why))
      {
        error = "cannot read '" + path + "': " + why;
        return nullptr;
      }
    }
    if (inlined.empty())
    {
      reader->SetFileName(path.c_str());
    }
    else
    {
      reader->ReadFromInputStringOn();
      reader->SetInputString(inlined);
    }
    // Only the points and cells make the cage: the point and cell data arrays are not read.
    // Their sizes are not checked by the reader before it allocates (a PointData array declaring
    // 1e9 components on 4 points allocated 8 GB and ran for minutes).
    reader->UpdateInformation();
    reader->GetPointDataArraySelection()->DisableAllArrays();
    reader->GetCellDataArraySelection()->DisableAllArrays();
    run(reader);
  }
  else if (!parseOwn(parseLegacyVTK)) // ".vtk": our own parser (CLIVTK.cxx says why not vtkPolyDataReader)
  {
    return nullptr;
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
  else if (ext == ".obj" || ext == ".ply" || ext == ".stl")
  {
    // our own writers (CLIWriters.h says why not VTK's)
    const ParsedMesh m = fromPolyData(mesh);
    return ext == ".obj" ? writeOBJ(m, path, error)
      : ext == ".ply"    ? writePLY(m, path, error)
                         : writeSTL(m, path, error);
  }
  else if (ext == ".vtp")
  {
    vtkNew<vtkXMLPolyDataWriter> writer;
    // inline, not appended: VTK 9.1 cannot read appended data with an up-to-date Debian 12's
    // expat (CLIVTP.cxx)
    writer->SetDataModeToBinary();
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
