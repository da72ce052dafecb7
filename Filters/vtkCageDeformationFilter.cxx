/*=========================================================================

  Program:   SDFCage
  Module:    vtkCageDeformationFilter.cxx

=========================================================================*/
#include "vtkCageDeformationFilter.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkCommunicator.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include "Deformation/CageCoordinates.h"
#include "SDFCageParallel.h"
#include "SDFCageVTKConversion.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <new>
#include <sstream>

vtkStandardNewMacro(vtkCageDeformationFilter);

using namespace sdfcage_vtk;

namespace
{
/// The cage's points and triangles. Returns "" or why it cannot be a cage (polygons that are not
/// triangles, strips); vertices and lines are ignored.
std::string ToCage(vtkPolyData* data, sdfcage::TriangleMesh& mesh)
{
  mesh = sdfcage::TriangleMesh();
  const vtkIdType np = data->GetNumberOfPoints();
  mesh.Points.resize(static_cast<std::size_t>(np));
  double p[3];
  for (vtkIdType i = 0; i < np; ++i)
  {
    data->GetPoint(i, p);
    mesh.Points[static_cast<std::size_t>(i)] = sdfcage::Vec3(p[0], p[1], p[2]);
  }
  if (data->GetNumberOfStrips() > 0)
  {
    return "it has triangle strips: convert them with vtkTriangleFilter (ParaView: Triangulate)";
  }
  vtkCellArray* polys = data->GetPolys();
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  vtkIdType nonTriangles = 0;
  for (polys->InitTraversal(); polys->GetNextCell(n, ids);)
  {
    if (n != 3)
    {
      ++nonTriangles;
      continue;
    }
    mesh.Triangles.push_back(
      { static_cast<int>(ids[0]), static_cast<int>(ids[1]), static_cast<int>(ids[2]) });
  }
  if (nonTriangles > 0)
  {
    std::ostringstream why;
    why << nonTriangles << " of its polygons are not triangles: triangulate it first (vtkTriangleFilter; "
        << "ParaView: Triangulate)";
    return why.str();
  }
  return {};
}

/// The same points (bit for bit) and the same polygons in the same order.
bool SameSurface(vtkPolyData* a, vtkPolyData* b)
{
  if (a->GetNumberOfPoints() != b->GetNumberOfPoints() || a->GetNumberOfPolys() != b->GetNumberOfPolys() ||
    a->GetNumberOfStrips() != b->GetNumberOfStrips())
  {
    return false;
  }
  double p[3];
  double q[3];
  for (vtkIdType i = 0; i < a->GetNumberOfPoints(); ++i)
  {
    a->GetPoint(i, p);
    b->GetPoint(i, q);
    if (p[0] != q[0] || p[1] != q[1] || p[2] != q[2])
    {
      return false;
    }
  }
  vtkCellArray* ca = a->GetPolys();
  vtkCellArray* cb = b->GetPolys();
  vtkIdType na = 0;
  vtkIdType nb = 0;
  const vtkIdType* ia = nullptr;
  const vtkIdType* ib = nullptr;
  ca->InitTraversal();
  cb->InitTraversal();
  while (ca->GetNextCell(na, ia))
  {
    if (!cb->GetNextCell(nb, ib) || na != nb || !std::equal(ia, ia + na, ib))
    {
      return false;
    }
  }
  return true;
}

double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
} // namespace

//------------------------------------------------------------------------------
struct vtkCageDeformationFilter::vtkInternals
{
  sdfcage::CageDeformer Deformer;
  sdfcage::TriangleMesh RestCage;
  // what the weights were computed for
  vtkDataObject* Input = nullptr;
  vtkMTimeType InputTime = 0;
  vtkDataObject* Rest = nullptr;
  vtkMTimeType RestTime = 0;
  int Coordinates = -1;
  bool Single = false;
  vtkSmartPointer<vtkPolyData> JoinedRest; ///< under MPI: the joined rest cage the weights are for
  sdfcage::CageBindingResult Binding;
};

//------------------------------------------------------------------------------
vtkCageDeformationFilter::vtkCageDeformationFilter()
  : Coordinates(MEAN_VALUE)
  , NumberOfThreads(0)
  , Internals(std::make_unique<vtkInternals>())
{
  this->SetNumberOfInputPorts(3);
  this->SetNumberOfOutputPorts(1);
  this->StatusString = "NotExecuted";
}

//------------------------------------------------------------------------------
vtkCageDeformationFilter::~vtkCageDeformationFilter() = default;

//------------------------------------------------------------------------------
void vtkCageDeformationFilter::SetRestCageConnection(vtkAlgorithmOutput* algOutput)
{
  this->SetInputConnection(1, algOutput);
}

void vtkCageDeformationFilter::SetRestCageData(vtkDataObject* cage)
{
  this->SetInputData(1, cage);
}

void vtkCageDeformationFilter::SetDeformedCageConnection(vtkAlgorithmOutput* algOutput)
{
  this->SetInputConnection(2, algOutput);
}

void vtkCageDeformationFilter::SetDeformedCageData(vtkDataObject* cage)
{
  this->SetInputData(2, cage);
}

//------------------------------------------------------------------------------
void vtkCageDeformationFilter::ClearWeights()
{
  this->Internals = std::make_unique<vtkInternals>();
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkCageDeformationFilter::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
    return 1;
  }
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  // a missing cage gives an empty output, not a pipeline error
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkCageDeformationFilter::RequestData(
  vtkInformation* vtkNotUsed(request), vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->StatusString = StatusIdentifier(sdfcage::Status::Ok);
  this->LastErrorMessage.clear();
  this->WeightsRecomputed = false;
  this->ApplyTime = 0.0;
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  vtkPolyData* rest = vtkPolyData::GetData(inputVector[1], 0);
  vtkPolyData* deformed = vtkPolyData::GetData(inputVector[2], 0);
  vtkPointSet* output = vtkPointSet::GetData(outputVector, 0);

  // Under MPI (the points handed out in pieces, as ParaView's data servers do) each process moves
  // its own piece of the points: a point's motion depends on the cages only. So the cages (on
  // process 0 when they come from SDF Cage, or in pieces from a reader) are joined on every
  // process, and the points are never gathered. The joined rest cage is a new object each time:
  // the one the weights were computed for is kept while its points and triangles stay the same,
  // so that moving the cage re-applies without computing the weights again.
  vtkMultiProcessController* controller = DistributingController(inputVector);
  vtkSmartPointer<vtkPolyData> restWhole;
  vtkSmartPointer<vtkPolyData> deformedWhole;
  if (controller)
  {
    restWhole = JoinOnEveryProcess(controller, rest);
    deformedWhole = JoinOnEveryProcess(controller, deformed);
    if (this->Internals->JoinedRest && SameSurface(this->Internals->JoinedRest, restWhole))
    {
      restWhole = this->Internals->JoinedRest;
    }
    this->Internals->JoinedRest = restWhole;
    rest = restWhole->GetNumberOfPoints() > 0 ? restWhole.Get() : nullptr;
    deformed = deformedWhole->GetNumberOfPoints() > 0 ? deformedWhole.Get() : nullptr;
  }
  if (!output)
  {
    vtkErrorMacro("The output data object is missing or of the wrong type.");
    return 0;
  }
  auto publish = [&]() {
    vtkFieldData* fd = output->GetFieldData();
    AddFieldValue<vtkStringArray>(fd, "CageCoordinates",
      this->Coordinates == GREEN ? std::string("Green") : std::string("MeanValue"));
    AddFieldValue<vtkIdTypeArray>(fd, "PointsOutsideCage", this->PointsOutside);
    AddFieldValue<vtkIdTypeArray>(fd, "PointsOnCage", this->PointsOnCage);
    AddFieldValue<vtkDoubleArray>(fd, "WeightTime", this->WeightTime);
    AddFieldValue<vtkDoubleArray>(fd, "ApplyTime", this->ApplyTime);
    AddFieldValue<vtkIntArray>(fd, "WeightsRecomputed", this->WeightsRecomputed ? 1 : 0);
    AddFieldValue<vtkDoubleArray>(fd, "ReproductionError", this->ReproductionError);
    AddFieldValue<vtkIntArray>(fd, "CageWasFlipped", this->CageWasFlipped ? 1 : 0);
    AddFieldValue<vtkStringArray>(fd, "Status", this->StatusString);
    AddFieldValue<vtkStringArray>(fd, "LastErrorMessage", this->LastErrorMessage);
  };
  auto fail = [&](sdfcage::Status status, const std::string& message) {
    output->Initialize();
    this->StatusString = StatusIdentifier(status);
    this->LastErrorMessage = message;
    vtkErrorMacro(<< message);
    publish();
    return 1; // a valid (empty) output; the error is reported
  };

  // the weights and the moved points on this process's points (a lambda: under MPI the results are
  // shared after it, whatever path it returns by)
  auto deformLocally = [&]() -> int {
    try
    {
      if (!input || !rest || !deformed || input->GetNumberOfPoints() == 0 || rest->GetNumberOfPoints() == 0)
      {
        output->Initialize();
        this->StatusString = StatusIdentifier(sdfcage::Status::EmptyInput);
        publish();
        return 1;
      }

      // the weights: computed again only when the points, the rest cage or the coordinates changed
      vtkInternals& in = *this->Internals;
      const bool current = in.Deformer.bound() && in.Input == input && in.InputTime == input->GetMTime() &&
        in.Rest == rest && in.RestTime == rest->GetMTime() && in.Coordinates == this->Coordinates &&
        in.Single == (this->SinglePrecisionWeights != 0);
      if (!current)
      {
        in.Deformer.clear();
        in.Input = nullptr;
        const std::string problem = ToCage(rest, in.RestCage);
        if (!problem.empty())
        {
          return fail(sdfcage::Status::InvalidInput, "The rest cage (input 1) cannot be used: " + problem + ".");
        }
        std::vector<sdfcage::Vec3> points(static_cast<std::size_t>(input->GetNumberOfPoints()));
        double p[3];
        for (vtkIdType i = 0; i < input->GetNumberOfPoints(); ++i)
        {
          input->GetPoint(i, p);
          points[static_cast<std::size_t>(i)] = sdfcage::Vec3(p[0], p[1], p[2]);
        }
        sdfcage::CageCoordinateOptions options;
        options.Kind = this->Coordinates == GREEN ? sdfcage::CageCoordinateKind::Green : sdfcage::CageCoordinateKind::MeanValue;
        options.NumberOfThreads = this->NumberOfThreads;
        options.SinglePrecision = this->SinglePrecisionWeights != 0;
        FilterProgress progress(this);
        this->UpdateProgress(0.0);
        in.Binding = in.Deformer.bind(in.RestCage, points, options, &progress);
        if (in.Binding.State != sdfcage::Status::Ok)
        {
          const sdfcage::Status state = in.Binding.State;
          const std::string message = in.Binding.Message;
          in.Deformer.clear();
          if (state == sdfcage::Status::Cancelled)
          {
            output->Initialize();
            this->StatusString = StatusIdentifier(state);
            this->LastErrorMessage = "cancelled";
            publish();
            return 1;
          }
          return fail(state,
            (state == sdfcage::Status::InvalidInput ? "The rest cage (input 1) cannot be used: " : "Cage coordinates failed: ") +
              message + ".");
        }
        in.Input = input;
        in.InputTime = input->GetMTime();
        in.Rest = rest;
        in.RestTime = rest->GetMTime();
        in.Coordinates = this->Coordinates;
        in.Single = options.SinglePrecision;
        this->WeightsRecomputed = true;
        this->PointsOutside = static_cast<vtkIdType>(in.Binding.PointsOutside);
        this->PointsOnCage = static_cast<vtkIdType>(in.Binding.PointsOnCage);
        this->WeightTime = in.Binding.WeightTime;
        this->ReproductionError = in.Binding.ReproductionError;
        this->CageWasFlipped = in.Binding.CageWasFlipped;
        if (in.Binding.PointsOutside > 0 || in.Binding.PointsOnCage > 0)
        {
          vtkWarningMacro(<< in.Binding.PointsOutside << " of " << input->GetNumberOfPoints()
                          << " points are outside the rest cage (winding number below 1/2) and "
                          << in.Binding.PointsOnCage
                          << " on it: they are moved with mean value coordinates extended outside the cage "
                             "(exact for affine cage motions, an extrapolation otherwise"
                          << (this->Coordinates == GREEN ? "; Green coordinates are defined inside only" : "")
                          << "). Point array CageLocation marks them (1 outside, 2 on the cage). A cage from "
                             "vtkSDFCageFilter encloses every point of its input.");
        }
      }

      // the deformed cage must be the rest cage moved
      sdfcage::TriangleMesh moved;
      const std::string problem = ToCage(deformed, moved);
      if (!problem.empty())
      {
        return fail(sdfcage::Status::InvalidInput, "The deformed cage (input 2) cannot be used: " + problem + ".");
      }
      if (moved.Points.size() != in.RestCage.Points.size() || moved.Triangles != in.RestCage.Triangles)
      {
        std::ostringstream why;
        why << "The deformed cage (input 2) must be the rest cage (input 1) with moved points: same points and "
               "triangles in the same order; it has "
            << moved.Points.size() << " points and " << moved.Triangles.size() << " triangles, the rest cage "
            << in.RestCage.Points.size() << " and " << in.RestCage.Triangles.size()
            << (moved.Points.size() == in.RestCage.Points.size() && moved.Triangles.size() == in.RestCage.Triangles.size()
                   ? " but other triangles"
                   : "")
            << ".";
        return fail(sdfcage::Status::InvalidInput, why.str());
      }
      for (const sdfcage::Vec3& p : moved.Points)
      {
        if (!p.allFinite())
        {
          return fail(sdfcage::Status::InvalidInput, "The deformed cage (input 2) has NaN or infinite coordinates.");
        }
      }

      const auto start = std::chrono::steady_clock::now();
      std::vector<sdfcage::Vec3> result;
      if (!in.Deformer.apply(moved.Points, result, this->NumberOfThreads))
      {
        return fail(sdfcage::Status::Failed, "Cage deformation failed: the weights do not match the cages.");
      }
      this->ApplyTime = SecondsSince(start);

      output->CopyStructure(input);
      output->GetPointData()->PassData(input->GetPointData());
      output->GetCellData()->PassData(input->GetCellData());
      output->GetFieldData()->PassData(input->GetFieldData());
      vtkNew<vtkPoints> points;
      points->SetDataType(input->GetPoints()->GetDataType());
      points->SetNumberOfPoints(input->GetNumberOfPoints());
      for (vtkIdType i = 0; i < input->GetNumberOfPoints(); ++i)
      {
        const sdfcage::Vec3& q = result[static_cast<std::size_t>(i)];
        points->SetPoint(i, q.x(), q.y(), q.z());
      }
      output->SetPoints(points);
      vtkNew<vtkUnsignedCharArray> where;
      where->SetName("CageLocation");
      where->SetNumberOfTuples(input->GetNumberOfPoints());
      for (vtkIdType i = 0; i < input->GetNumberOfPoints(); ++i)
      {
        where->SetValue(i, static_cast<unsigned char>(in.Deformer.location(static_cast<std::size_t>(i))));
      }
      output->GetPointData()->AddArray(where);
      publish();
      this->UpdateProgress(1.0);
      return 1;
    }
    catch (const std::bad_alloc&)
    {
      this->Internals = std::make_unique<vtkInternals>();
      return fail(sdfcage::Status::Failed, "Out of memory for the cage coordinates.");
    }
    catch (const std::exception& e)
    {
      this->Internals = std::make_unique<vtkInternals>();
      return fail(sdfcage::Status::Failed, std::string("Cage deformation failed: ") + e.what());
    }
    catch (...)
    {
      this->Internals = std::make_unique<vtkInternals>();
      return fail(sdfcage::Status::Failed, "Cage deformation failed with an unknown exception.");
    }
  };
  const int rc = deformLocally();
  if (controller)
  {
    this->ShareResults(controller, input && input->GetNumberOfPoints() > 0);
    publish();
  }
  return rc;
}

//------------------------------------------------------------------------------
// Under MPI every process moved its own piece of the points: each reports the whole run, the
// counts of points outside and on the cage summed over the processes, the times the longest. A
// process whose piece has no points reports Ok when another piece was deformed.
void vtkCageDeformationFilter::ShareResults(vtkMultiProcessController* controller, bool hasPoints)
{
  const vtkInternals& in = *this->Internals;
  const bool bound = in.Deformer.bound();
  long long counts[2] = { bound ? static_cast<long long>(in.Binding.PointsOutside) : 0,
    bound ? static_cast<long long>(in.Binding.PointsOnCage) : 0 };
  long long sums[2] = { 0, 0 };
  controller->AllReduce(counts, sums, 2, vtkCommunicator::SUM_OP);
  double values[3] = { bound ? in.Binding.WeightTime : 0.0, this->ApplyTime,
    bound ? in.Binding.ReproductionError : 0.0 };
  double largest[3] = { 0.0, 0.0, 0.0 };
  controller->AllReduce(values, largest, 3, vtkCommunicator::MAX_OP);
  const std::string ok = StatusIdentifier(sdfcage::Status::Ok);
  int flags[2] = { this->WeightsRecomputed ? 1 : 0, this->StatusString == ok ? 1 : 0 };
  int any[2] = { 0, 0 };
  controller->AllReduce(flags, any, 2, vtkCommunicator::MAX_OP);
  this->PointsOutside = static_cast<vtkIdType>(sums[0]);
  this->PointsOnCage = static_cast<vtkIdType>(sums[1]);
  this->WeightTime = largest[0];
  this->ApplyTime = largest[1];
  this->ReproductionError = largest[2];
  this->WeightsRecomputed = any[0] != 0;
  if (!hasPoints && any[1] && this->StatusString == StatusIdentifier(sdfcage::Status::EmptyInput))
  {
    this->StatusString = ok;
  }
}

//------------------------------------------------------------------------------
void vtkCageDeformationFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Coordinates: " << (this->Coordinates == GREEN ? "Green" : "MeanValue") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "SinglePrecisionWeights: " << (this->SinglePrecisionWeights ? "On" : "Off") << "\n";
  os << indent << "PointsOutside: " << this->PointsOutside << "\n";
  os << indent << "PointsOnCage: " << this->PointsOnCage << "\n";
  os << indent << "WeightTime: " << this->WeightTime << "\n";
  os << indent << "ApplyTime: " << this->ApplyTime << "\n";
  os << indent << "Status: " << this->StatusString << "\n";
  os << indent << "LastErrorMessage: " << this->LastErrorMessage << "\n";
}
