/*=========================================================================

  Program:   SDFCage
  Module:    vtkSDFCageInternals.h

=========================================================================*/
// Private helpers shared by the SDFCage filters (not wrapped, not installed): Core progress
// forwarding, vtkPolyData <-> Core mesh conversion, status identifiers, one-value field arrays.
#ifndef vtkSDFCageInternals_h
#define vtkSDFCageInternals_h

#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include "Envelope.h"
#include "Mesh.h"
#include "Progress.h"

#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace sdfcage_vtk
{
//------------------------------------------------------------------------------
// Forwards Core's progress to the filter, and the filter's abort flag to Core.
// Core may call report()/pollCancel() from worker threads; VTK objects are only touched from the
// thread that runs RequestData (the one that constructed this object). Cancellation still reaches
// the workers: Progress latches the flag in an atomic once pollCancel() has returned true.
class FilterProgress final : public sdfcage::Progress
{
public:
  explicit FilterProgress(vtkAlgorithm* filter)
    : Filter(filter)
    , Owner(std::this_thread::get_id())
  {
  }

protected:
  void report(double overall, const std::string& stage) override
  {
    if (std::this_thread::get_id() != this->Owner)
    {
      return;
    }
    // Throttle: a new stage always shows; inside a stage, report every 1% at most (each
    // UpdateProgress fires observers, which in ParaView repaint a progress bar).
    const bool newStage = stage != this->LastStage;
    if (!newStage && overall < this->LastReported + 0.01)
    {
      return;
    }
    if (newStage)
    {
      this->LastStage = stage;
      this->Filter->SetProgressText(stage.c_str());
    }
    this->LastReported = overall;
    this->Filter->UpdateProgress(overall);
  }

  bool pollCancel() override
  {
    return std::this_thread::get_id() == this->Owner && this->Filter->GetAbortExecute() != 0;
  }

private:
  vtkAlgorithm* Filter;
  std::thread::id Owner;
  std::string LastStage;
  double LastReported = -1.0;
};

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

inline void AppendCells(vtkCellArray* cells, CellKind kind, sdfcage::PolygonMesh& mesh)
{
  if (!cells || cells->GetNumberOfCells() == 0)
  {
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

inline void ToPolygonMesh(vtkPolyData* input, sdfcage::PolygonMesh& mesh)
{
  const vtkIdType numberOfPoints = input->GetNumberOfPoints();
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
    mesh.Connectivity.reserve(static_cast<std::size_t>(polys->GetNumberOfConnectivityIds()));
    mesh.Offsets.reserve(static_cast<std::size_t>(polys->GetNumberOfCells()) + 1);
  }
  AppendCells(input->GetPolys(), CellKind::Polygon, mesh);
  AppendCells(input->GetStrips(), CellKind::Strip, mesh);
  AppendCells(input->GetVerts(), CellKind::Vertex, mesh);
  AppendCells(input->GetLines(), CellKind::Line, mesh);
}

inline void ToPolyData(
  const sdfcage::TriangleMesh& mesh, const std::vector<double>& distance, vtkPolyData* output)
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

// Machine-readable status identifiers (Core's statusName() is for humans).
inline const char* StatusIdentifier(sdfcage::Status status)
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
    case sdfcage::Status::Failed:
    default:
      return "Failed";
  }
}

template <typename ArrayT, typename ValueT>
void AddFieldValue(vtkFieldData* fd, const char* name, ValueT value)
{
  vtkNew<ArrayT> array;
  array->SetName(name);
  array->SetNumberOfTuples(1);
  array->SetValue(0, value);
  fd->AddArray(array);
}
} // namespace sdfcage_vtk

#endif
