#include "SDFCageVTKConversion.h"

#include "Common/LargePages.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"

#include <algorithm>

namespace sdfcage_vtk
{
namespace
{

//------------------------------------------------------------------------------
// Appends the cells of `cells` to `mesh`. Polygons are copied as they are (Core triangulates
// them and reports what it could not split). Triangle strips are split here; the degenerate
// triangles a strip uses to turn (two equal ids) are an artifact of the encoding, not of the
// surface, and are skipped. Vertex and line cells are passed as 1- and 2-point cells so that
// Core counts them as ignored cells.
enum class CellKind
{
  Vertex,
  Line,
  Polygon,
  Strip
};

// Whether the offsets of `cells` describe its connectivity: they start at 0, never decrease and
// end at the connectivity's size. VTK's cell iterators trust them, and a reader given a damaged
// file (a fuzzed .vtp or version-5 .vtk, or a filter's bad output) can produce arrays that break
// this, which would make the iteration read outside the connectivity.
template <typename Offsets>
bool OffsetsAreSound(const Offsets* offsets, vtkIdType numberOfOffsets, vtkIdType numberOfIds)
{
  if (numberOfOffsets == 0)
  {
    return numberOfIds == 0;
  }
  if (offsets[0] != 0 || static_cast<vtkIdType>(offsets[numberOfOffsets - 1]) != numberOfIds)
  {
    return false;
  }
  for (vtkIdType i = 1; i < numberOfOffsets; ++i)
  {
    if (offsets[i] < offsets[i - 1])
    {
      return false;
    }
  }
  return true;
}

bool CellArrayIsSound(vtkCellArray* cells)
{
  const vtkIdType numberOfIds = cells->GetNumberOfConnectivityIds();
  if (cells->IsStorage64Bit())
  {
    vtkTypeInt64Array* offsets = cells->GetOffsetsArray64();
    return OffsetsAreSound(offsets->GetPointer(0), offsets->GetNumberOfValues(), numberOfIds);
  }
  vtkTypeInt32Array* offsets = cells->GetOffsetsArray32();
  return OffsetsAreSound(offsets->GetPointer(0), offsets->GetNumberOfValues(), numberOfIds);
}

void AppendCells(vtkCellArray* cells, CellKind kind, sdfcage::PolygonMesh& mesh)
{
  if (!cells || cells->GetNumberOfCells() == 0)
  {
    return;
  }
  if (!CellArrayIsSound(cells))
  {
    // Nothing in a damaged cell array can be trusted: one cell naming a point that does not
    // exist, so that Core refuses the input as invalid ("... refer to points that do not exist")
    // instead of caging a guess.
    mesh.addCell({ -1, -1, -1 });
    return;
  }
  auto it = vtk::TakeSmartPointer(cells->NewIterator());
  vtkIdType npts = 0;
  const vtkIdType* pts = nullptr;
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
  {
    it->GetCurrentCell(npts, pts);
    switch (kind)
    {
      case CellKind::Vertex:
        if (npts >= 1)
        {
          mesh.addCell({ pts[0] });
        }
        break;
      case CellKind::Line:
        if (npts >= 2)
        {
          mesh.addCell({ pts[0], pts[1] });
        }
        break;
      case CellKind::Polygon:
        mesh.Connectivity.insert(mesh.Connectivity.end(), pts, pts + npts);
        mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
        break;
      case CellKind::Strip:
        for (vtkIdType i = 0; i + 2 < npts; ++i)
        {
          vtkIdType a = pts[i], b = pts[i + 1];
          const vtkIdType c = pts[i + 2];
          if (a == b || b == c || a == c)
          {
            continue;
          }
          if (i % 2 == 1)
          {
            std::swap(a, b); // odd triangles of a strip are wound the other way
          }
          mesh.addCell({ a, b, c });
        }
        break;
    }
  }
}

} // namespace

void ToPolygonMesh(vtkPolyData* input, sdfcage::PolygonMesh& mesh)
{
  const vtkIdType numberOfPoints = input->GetNumberOfPoints();
  mesh.Points.clear();
  sdfcage::ReserveLarge(mesh.Points, static_cast<std::size_t>(numberOfPoints));
  mesh.Points.resize(static_cast<std::size_t>(numberOfPoints));
  double p[3];
  for (vtkIdType i = 0; i < numberOfPoints; ++i)
  {
    input->GetPoint(i, p);
    mesh.Points[static_cast<std::size_t>(i)] = sdfcage::Vec3(p[0], p[1], p[2]);
  }
  mesh.Offsets.assign(1, 0);
  mesh.Connectivity.clear();
  if (vtkCellArray* polys = input->GetPolys())
  {
    sdfcage::ReserveLarge(mesh.Connectivity, static_cast<std::size_t>(polys->GetNumberOfConnectivityIds()));
    sdfcage::ReserveLarge(mesh.Offsets, static_cast<std::size_t>(polys->GetNumberOfCells()) + 1);
  }
  AppendCells(input->GetPolys(), CellKind::Polygon, mesh);
  AppendCells(input->GetStrips(), CellKind::Strip, mesh);
  AppendCells(input->GetVerts(), CellKind::Vertex, mesh);
  AppendCells(input->GetLines(), CellKind::Line, mesh);
}

void ToPolyData(const sdfcage::TriangleMesh& mesh, const std::vector<double>& distance, vtkPolyData* output)
{
  const vtkIdType numberOfPoints = static_cast<vtkIdType>(mesh.numberOfPoints());
  const vtkIdType numberOfTriangles = static_cast<vtkIdType>(mesh.numberOfTriangles());

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(numberOfPoints);
  for (vtkIdType i = 0; i < numberOfPoints; ++i)
  {
    points->SetPoint(i, mesh.Points[static_cast<std::size_t>(i)].data());
  }

  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(numberOfTriangles + 1);
  connectivity->SetNumberOfValues(3 * numberOfTriangles);
  for (vtkIdType t = 0; t < numberOfTriangles; ++t)
  {
    const sdfcage::Triangle& tri = mesh.Triangles[static_cast<std::size_t>(t)];
    offsets->SetValue(t, 3 * t);
    connectivity->SetValue(3 * t, tri[0]);
    connectivity->SetValue(3 * t + 1, tri[1]);
    connectivity->SetValue(3 * t + 2, tri[2]);
  }
  offsets->SetValue(numberOfTriangles, 3 * numberOfTriangles);
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);

  output->SetPoints(points);
  output->SetPolys(polys);

  if (static_cast<vtkIdType>(distance.size()) == numberOfPoints)
  {
    vtkNew<vtkDoubleArray> array;
    array->SetName("DistanceToInput");
    array->SetNumberOfValues(numberOfPoints);
    for (vtkIdType i = 0; i < numberOfPoints; ++i)
    {
      array->SetValue(i, distance[static_cast<std::size_t>(i)]);
    }
    output->GetPointData()->SetScalars(array);
  }
}

void ToImageData(const sdfcage::ScalarImage& field, vtkImageData* output, const char* name)
{
  const auto& dims = field.Dimensions;
  const std::size_t count = static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) * dims[2];
  if (dims[0] <= 0 || dims[1] <= 0 || dims[2] <= 0 || field.Values.size() != count)
  {
    return;
  }
  output->SetDimensions(dims[0], dims[1], dims[2]);
  output->SetOrigin(field.Origin[0], field.Origin[1], field.Origin[2]);
  output->SetSpacing(field.Spacing, field.Spacing, field.Spacing);
  vtkNew<vtkFloatArray> values;
  values->SetName(name);
  values->SetNumberOfValues(static_cast<vtkIdType>(count));
  std::copy(field.Values.begin(), field.Values.end(), values->GetPointer(0));
  if (output->GetPointData()->GetScalars())
  {
    output->GetPointData()->AddArray(values);
  }
  else
  {
    output->GetPointData()->SetScalars(values);
  }
}

const char* StatusIdentifier(sdfcage::Status status)
{
  switch (status)
  {
    case sdfcage::Status::Ok:
      return "Ok";
    case sdfcage::Status::EmptyInput:
      return "EmptyInput";
    case sdfcage::Status::InvalidInput:
      return "InvalidInput";
    case sdfcage::Status::Cancelled:
      return "Cancelled";
    case sdfcage::Status::VerificationFailed:
      return "VerificationFailed";
    case sdfcage::Status::TopologyChanged:
      return "TopologyChanged";
    case sdfcage::Status::Failed:
    default:
      return "Failed";
  }
}

void AddResultArrays(vtkFieldData* fd, const sdfcage::ResultTable& results)
{
  for (const sdfcage::ResultField& f : results)
  {
    switch (f.Type)
    {
      case sdfcage::ResultField::Kind::Flag:
        AddFieldValue<vtkIntArray>(fd, f.Name.c_str(), static_cast<int>(f.Integer));
        break;
      case sdfcage::ResultField::Kind::Integer:
        AddFieldValue<vtkIdTypeArray>(fd, f.Name.c_str(), static_cast<vtkIdType>(f.Integer));
        break;
      case sdfcage::ResultField::Kind::Real:
        AddFieldValue<vtkDoubleArray>(fd, f.Name.c_str(), f.Real);
        break;
      case sdfcage::ResultField::Kind::Text:
        AddFieldValue<vtkStringArray>(fd, f.Name.c_str(), f.Text);
        break;
    }
  }
}

double ResultNumber(const sdfcage::ResultTable& results, const char* name)
{
  const sdfcage::ResultField* f = name ? sdfcage::findResult(results, name) : nullptr;
  return f ? f->number() : 0.0;
}

const char* ResultText(const sdfcage::ResultTable& results, const char* name)
{
  const sdfcage::ResultField* f = name ? sdfcage::findResult(results, name) : nullptr;
  return f && f->Type == sdfcage::ResultField::Kind::Text ? f->Text.c_str() : "";
}

const char* ResultName(const sdfcage::ResultTable& results, int index)
{
  return index >= 0 && static_cast<std::size_t>(index) < results.size()
    ? results[static_cast<std::size_t>(index)].Name.c_str()
    : "";
}

} // namespace sdfcage_vtk
