// SDFCage — CLI: see CLIMeshIO.h.
#include "CLIMeshIO.h"

#include "CLIMessages.h"

#include "Mesh/Shapes.h" // sdfcage::makeBuiltinShape (Core)

#include <vtkCellArray.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkOBJWriter.h>
#include <vtkOFFReader.h>
#include <vtkOFFWriter.h>
#include <vtkPLYReader.h>
#include <vtkPLYWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkSTLReader.h>
#include <vtkSTLWriter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

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

vtkSmartPointer<vtkPolyData> readMesh(const std::string& path, std::string& error)
{
  std::error_code ec;
  if (!fs::exists(path, ec))
  {
    error = "cannot read '" + path + "': no such file";
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

  clearMessages();
  const std::string ext = lowerExtension(path);
  vtkSmartPointer<vtkPolyData> mesh;
  unsigned long errorCode = 0;
  if (ext == ".off")
  {
    vtkNew<vtkOFFReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = reader->GetOutput();
  }
  else if (ext == ".obj")
  {
    vtkNew<vtkOBJReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = reader->GetOutput();
  }
  else if (ext == ".ply")
  {
    vtkNew<vtkPLYReader> reader;
    if (!reader->CanReadFile(path.c_str()))
    {
      error = "cannot read '" + path + "': not a PLY file";
      return nullptr;
    }
    reader->SetFileName(path.c_str());
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = reader->GetOutput();
  }
  else if (ext == ".stl")
  {
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(path.c_str());
    reader->MergingOn(); // STL stores triangle soup: merge coincident points to get a surface
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = reader->GetOutput();
  }
  else if (ext == ".vtp")
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    if (!reader->CanReadFile(path.c_str()))
    {
      error = "cannot read '" + path + "': not a VTK XML PolyData (.vtp) file";
      return nullptr;
    }
    reader->SetFileName(path.c_str());
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = reader->GetOutput();
  }
  else // ".vtk"
  {
    vtkNew<vtkPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    if (!reader->IsFilePolyData())
    {
      error = "cannot read '" + path +
        "': not a legacy VTK POLYDATA file (other dataset types are not surfaces; extract one "
        "first, e.g. with vtkGeometryFilter)";
      return nullptr;
    }
    reader->Update();
    errorCode = reader->GetErrorCode();
    mesh = reader->GetOutput();
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
