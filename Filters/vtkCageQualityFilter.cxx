/*=========================================================================

  Program:   SDFCage
  Module:    vtkCageQualityFilter.cxx

=========================================================================*/
#include "vtkCageQualityFilter.h"

#include "vtkAlgorithmOutput.h"
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkCompositeDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include "Quality/CageQuality.h"
#include "Common/Progress.h"
#include "SDFCageParallel.h"
#include "SDFCageVTKConversion.h"

#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <thread>
#include <vector>

vtkStandardNewMacro(vtkCageQualityFilter);

namespace
{
//------------------------------------------------------------------------------
// Forwards Core's progress to the filter and the filter's abort flag to Core; VTK objects are
// only touched from the thread that runs RequestData.
class QualityProgress final : public sdfcage::Progress
{
public:
  explicit QualityProgress(vtkCageQualityFilter* filter)
    : Filter(filter)
    , Owner(std::this_thread::get_id())
  {
  }

protected:
  void report(double overall, const std::string& stage) override
  {
    if (std::this_thread::get_id() != this->Owner || stage == this->LastStage)
    {
      return; // phase boundaries only: a few updates per run
    }
    this->LastStage = stage;
    this->Filter->SetProgressText(stage.c_str());
    this->Filter->UpdateProgress(overall);
  }
  bool pollCancel() override
  {
    return std::this_thread::get_id() == this->Owner && this->Filter->GetAbortExecute() != 0;
  }

private:
  vtkCageQualityFilter* Filter;
  std::thread::id Owner;
  std::string LastStage;
};

//------------------------------------------------------------------------------
// Fan-triangulates the polygons and strips of `data`; `cellOfTriangle[i]` is the id (in the
// polydata's cell numbering: verts, lines, polys, strips) of the cell triangle i came from.
// Ids are copied unchecked: Core reports out-of-range ids as invalid triangles.
void ToTriangles(vtkPolyData* data, sdfcage::TriangleMesh& mesh, std::vector<vtkIdType>& cellOfTriangle)
{
  const vtkIdType np = data->GetNumberOfPoints();
  mesh.Points.resize(static_cast<std::size_t>(np));
  double p[3];
  for (vtkIdType i = 0; i < np; ++i)
  {
    data->GetPoint(i, p);
    mesh.Points[static_cast<std::size_t>(i)] = sdfcage::Vec3(p[0], p[1], p[2]);
  }
  auto toInt = [](vtkIdType id) { return id < 0 || id > std::numeric_limits<int>::max() ? -1 : static_cast<int>(id); };
  vtkIdType cellId = data->GetNumberOfVerts() + data->GetNumberOfLines();
  vtkIdType npts = 0;
  const vtkIdType* pts = nullptr;
  if (vtkCellArray* polys = data->GetPolys())
  {
    auto it = vtk::TakeSmartPointer(polys->NewIterator());
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell(), ++cellId)
    {
      it->GetCurrentCell(npts, pts);
      for (vtkIdType k = 1; k + 1 < npts; ++k)
      {
        mesh.Triangles.push_back({ toInt(pts[0]), toInt(pts[k]), toInt(pts[k + 1]) });
        cellOfTriangle.push_back(cellId);
      }
    }
  }
  if (vtkCellArray* strips = data->GetStrips())
  {
    auto it = vtk::TakeSmartPointer(strips->NewIterator());
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell(), ++cellId)
    {
      it->GetCurrentCell(npts, pts);
      for (vtkIdType k = 0; k + 2 < npts; ++k)
      {
        vtkIdType a = pts[k], b = pts[k + 1];
        const vtkIdType c = pts[k + 2];
        if (a == b || b == c || a == c)
        {
          continue; // the turn of a strip, not a surface triangle
        }
        if (k % 2 == 1)
        {
          std::swap(a, b);
        }
        mesh.Triangles.push_back({ toInt(a), toInt(b), toInt(c) });
        cellOfTriangle.push_back(cellId);
      }
    }
  }
}

vtkSmartPointer<vtkDoubleArray> NewArray(const char* name, vtkIdType n)
{
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  array->SetNumberOfTuples(n);
  array->Fill(std::numeric_limits<double>::quiet_NaN());
  return array;
}
} // namespace

//------------------------------------------------------------------------------
struct vtkCageQualityFilter::vtkInternals
{
  sdfcage::ResultTable Results; // Core's table of the last execution
};

//------------------------------------------------------------------------------
vtkCageQualityFilter::vtkCageQualityFilter()
{
  this->Internals = std::make_unique<vtkInternals>();
  this->ResetResults();
  this->HausdorffTolerance = sdfcage::CageQualityOptions().HausdorffTolerance;
  this->SetNumberOfInputPorts(2);
  this->SetNumberOfOutputPorts(1);
}

//------------------------------------------------------------------------------
vtkCageQualityFilter::~vtkCageQualityFilter() = default;

//------------------------------------------------------------------------------
void vtkCageQualityFilter::SetSourceConnection(vtkAlgorithmOutput* algOutput)
{
  this->SetInputConnection(1, algOutput);
}

void vtkCageQualityFilter::SetSourceData(vtkPolyData* source)
{
  this->SetInputData(1, source);
}

vtkPolyData* vtkCageQualityFilter::GetSource()
{
  if (this->GetNumberOfInputConnections(1) < 1)
  {
    return nullptr;
  }
  return vtkPolyData::SafeDownCast(this->GetExecutive()->GetInputData(1, 0));
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  if (port == 0)
  {
    info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet"); // nested levels
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::FillOutputPortInformation(int, vtkInformation* info)
{
  // a vtkPolyData for a cage, a vtkMultiBlockDataSet for nested levels (RequestDataObject)
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkDataObject");
  return 1;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkCageQualityFilter::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT()))
  {
    return this->RequestDataObject(request, inputVector, outputVector);
  }
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (!outInfo)
  {
    return 0;
  }
  vtkDataObject* input = vtkDataObject::GetData(inputVector[0], 0);
  vtkDataObject* output = outInfo->Get(vtkDataObject::DATA_OBJECT());
  if (vtkMultiBlockDataSet::SafeDownCast(input))
  {
    if (!vtkMultiBlockDataSet::SafeDownCast(output))
    {
      vtkNew<vtkMultiBlockDataSet> levels;
      outInfo->Set(vtkDataObject::DATA_OBJECT(), levels);
    }
  }
  else if (!vtkPolyData::SafeDownCast(output))
  {
    vtkNew<vtkPolyData> cage;
    outInfo->Set(vtkDataObject::DATA_OBJECT(), cage);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkCageQualityFilter::ResetResults()
{
  this->Internals->Results = sdfcage::qualityResults(sdfcage::CageQualityResult());
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  sdfcage_vtk::RequestSamePieceWithoutGhosts(inputVector, this->GetNumberOfInputPorts(), outputVector, request);
  return 1;
}

//------------------------------------------------------------------------------
// On the whole inputs: directly in a serial run, on process 0 with the gathered pieces under MPI
// (the other processes adopt process 0's results).
int vtkCageQualityFilter::RequestData(
  vtkInformation* vtkNotUsed(request), vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (auto* levels = vtkMultiBlockDataSet::GetData(inputVector[0], 0))
  {
    this->ResetResults();
    auto* output = vtkMultiBlockDataSet::GetData(outputVector, 0);
    if (!output)
    {
      vtkErrorMacro("The output data object is missing or of the wrong type.");
      return 0;
    }
    vtkPolyData* mesh = vtkPolyData::GetData(inputVector[1], 0);
    vtkMultiProcessController* controller = sdfcage_vtk::DistributingController(inputVector);
    if (!controller)
    {
      return this->ExecuteLevels(levels, mesh, output);
    }
    return this->ExecuteLevelsDistributed(controller, levels, mesh, output);
  }
  sdfcage_vtk::WholeSurfaceRun run;
  return sdfcage_vtk::RunOnWholeSurface(
    this, inputVector, outputVector, run,
    [this, outputVector](
      const std::vector<vtkPolyData*>& inputs) { return this->Execute(inputs[0], inputs[1], outputVector); },
    [this](vtkFieldData* fd) {
      this->ResetResults();
      sdfcage_vtk::ReadResultArrays(fd, this->Internals->Results);
    });
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::Execute(vtkPolyData* cage, vtkPolyData* mesh, vtkInformationVector* outputVector)
{
  this->ResetResults();
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!output)
  {
    vtkErrorMacro("The output data object is missing or of the wrong type.");
    return 0;
  }
  return this->Judge(cage, mesh, output);
}

//------------------------------------------------------------------------------
// Nested levels under MPI: the mesh's pieces and every level's pieces are joined on process 0,
// judged there; the other processes output the same blocks, empty, and adopt process 0's return
// code and results (collective: every process has the same number of blocks, as vtkSDFCageFilter
// gives them).
int vtkCageQualityFilter::ExecuteLevelsDistributed(
  vtkMultiProcessController* controller, vtkMultiBlockDataSet* levels, vtkPolyData* mesh, vtkMultiBlockDataSet* output)
{
  const bool root = controller->GetLocalProcessId() == 0;
  vtkSmartPointer<vtkPolyData> wholeMesh = sdfcage_vtk::JoinOnProcessZero(controller, mesh);
  const unsigned int n = levels->GetNumberOfBlocks();
  vtkNew<vtkMultiBlockDataSet> wholeLevels;
  wholeLevels->SetNumberOfBlocks(n);
  for (unsigned int i = 0; i < n; ++i)
  {
    vtkSmartPointer<vtkPolyData> level =
      sdfcage_vtk::JoinOnProcessZero(controller, vtkPolyData::SafeDownCast(levels->GetBlock(i)));
    wholeLevels->SetBlock(i, level);
    if (levels->HasMetaData(i))
    {
      wholeLevels->GetMetaData(i)->Copy(levels->GetMetaData(i));
    }
  }
  int rc = 1;
  if (root)
  {
    rc = this->ExecuteLevels(wholeLevels, mesh ? wholeMesh.Get() : nullptr, output);
  }
  else
  {
    output->Initialize();
    output->SetNumberOfBlocks(n);
    for (unsigned int i = 0; i < n; ++i)
    {
      vtkNew<vtkPolyData> empty;
      output->SetBlock(i, empty);
      if (levels->HasMetaData(i))
      {
        output->GetMetaData(i)->Copy(levels->GetMetaData(i));
      }
    }
  }
  controller->Broadcast(&rc, 1, 0);
  vtkNew<vtkPolyData> carrier; // process 0's results, for every process's getters
  if (root)
  {
    sdfcage_vtk::AddResultArrays(carrier->GetFieldData(), this->Internals->Results);
  }
  controller->Broadcast(carrier, 0);
  if (!root)
  {
    this->ResetResults();
    sdfcage_vtk::ReadResultArrays(carrier->GetFieldData(), this->Internals->Results);
  }
  return rc;
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::ExecuteLevels(vtkMultiBlockDataSet* levels, vtkPolyData* mesh, vtkMultiBlockDataSet* output)
{
  output->Initialize();
  const unsigned int n = levels->GetNumberOfBlocks();
  for (unsigned int i = 0; i < n; ++i)
  {
    vtkDataObject* block = levels->GetBlock(i);
    if (block && !vtkPolyData::SafeDownCast(block))
    {
      vtkErrorMacro("Nested levels: block " << i << " is a " << block->GetClassName()
                                            << ", not a vtkPolyData (a cage level).");
      return 0;
    }
  }
  output->SetNumberOfBlocks(n);
  vtkPolyData* inner = mesh;
  std::string innerName = "input";
  sdfcage::ResultTable chosen = this->Internals->Results; // the filter's results: see the header
  bool failed = false;
  for (unsigned int i = 0; i < n; ++i)
  {
    std::string name = "block_" + std::to_string(i);
    if (levels->HasMetaData(i) && levels->GetMetaData(i)->Has(vtkCompositeDataSet::NAME()))
    {
      name = levels->GetMetaData(i)->Get(vtkCompositeDataSet::NAME());
    }
    output->GetMetaData(i)->Set(vtkCompositeDataSet::NAME(), name.c_str());
    auto* level = vtkPolyData::SafeDownCast(levels->GetBlock(i));
    vtkNew<vtkPolyData> judged;
    this->ResetResults();
    if (level && level->GetNumberOfCells() > 0)
    {
      if (!this->Judge(level, inner, judged))
      {
        output->Initialize();
        this->ResetResults();
        return 0;
      }
      if (this->GetAbortExecute())
      {
        output->Initialize();
        this->ResetResults();
        return 1;
      }
      vtkNew<vtkStringArray> against;
      against->SetName("JudgedAgainst");
      against->InsertNextValue(innerName);
      judged->GetFieldData()->AddArray(against);
      if (!failed)
      {
        chosen = this->Internals->Results;
        failed = this->GetResultNumber("Encloses") == 0;
      }
      inner = level;
      innerName = name;
    }
    output->SetBlock(i, judged);
  }
  this->Internals->Results = chosen;
  return 1;
}

//------------------------------------------------------------------------------
int vtkCageQualityFilter::Judge(vtkPolyData* cage, vtkPolyData* mesh, vtkPolyData* output)
{
  output->Initialize();
  if (!cage || cage->GetNumberOfCells() == 0)
  {
    return 1; // empty cage: empty output, not an error
  }
  if (!mesh)
  {
    vtkErrorMacro("No input mesh: connect the mesh the cage should enclose with SetSourceConnection "
                  "(input port 1).");
    return 0;
  }
  output->ShallowCopy(cage);

  auto publish = [&]() { sdfcage_vtk::AddResultArrays(output->GetFieldData(), this->Internals->Results); };

  try
  {
    sdfcage::TriangleMesh cageMesh, inputMesh;
    std::vector<vtkIdType> cellOfTriangle, unused;
    ToTriangles(cage, cageMesh, cellOfTriangle);
    ToTriangles(mesh, inputMesh, unused);

    sdfcage::CageQualityOptions options;
    options.HausdorffTolerance = this->HausdorffTolerance;
    QualityProgress progress(this);
    this->UpdateProgress(0.0);
    const sdfcage::CageQualityResult q = sdfcage::evaluateCage(inputMesh, cageMesh, options, &progress);
    if (q.Message == "cancelled")
    {
      output->Initialize();
      return 1;
    }

    // point and cell arrays
    const vtkIdType np = cage->GetNumberOfPoints(), nc = cage->GetNumberOfCells();
    auto pointDistance = NewArray("DistanceToInput", np);
    for (vtkIdType i = 0; i < np; ++i)
    {
      pointDistance->SetValue(i, q.PointDistance[static_cast<std::size_t>(i)]);
    }
    output->GetPointData()->AddArray(pointDistance);
    auto cellDistance = NewArray("DistanceToInput", nc);
    auto minimumAngle = NewArray("MinimumAngle", nc);
    auto mips = NewArray("MIPSEnergy", nc);
    for (std::size_t t = 0; t < cellOfTriangle.size(); ++t)
    {
      const vtkIdType c = cellOfTriangle[t];
      auto merge = [c](vtkDoubleArray* a, double v, bool takeMax) {
        const double old = a->GetValue(c);
        if (std::isnan(old) || (!std::isnan(v) && (takeMax ? v > old : v < old)))
        {
          a->SetValue(c, v);
        }
      };
      merge(cellDistance, q.CellDistance[t], true);
      merge(minimumAngle, q.CellMinimumAngle[t], false);
      merge(mips, q.CellMIPSEnergy[t], true);
    }
    output->GetCellData()->AddArray(cellDistance);
    output->GetCellData()->AddArray(minimumAngle);
    output->GetCellData()->AddArray(mips);
    output->GetPointData()->SetActiveScalars("DistanceToInput");

    this->Internals->Results = sdfcage::qualityResults(q);
    publish();
    this->UpdateProgress(1.0);
    return 1;
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro("Out of memory while evaluating the cage.");
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("Internal error while evaluating the cage: " << e.what());
  }
  catch (...)
  {
    vtkErrorMacro("Unknown internal error while evaluating the cage.");
  }
  output->Initialize();
  return 0;
}

//------------------------------------------------------------------------------
void vtkCageQualityFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "HausdorffTolerance: " << this->HausdorffTolerance << "\n";
  for (const sdfcage::ResultField& f : this->Internals->Results)
  {
    os << indent << f.Name << ": " << f.toString() << "\n";
  }
}

//------------------------------------------------------------------------------
double vtkCageQualityFilter::GetResultNumber(const char* name) const
{
  return sdfcage_vtk::ResultNumber(this->Internals->Results, name);
}

const char* vtkCageQualityFilter::GetResultText(const char* name) const
{
  return sdfcage_vtk::ResultText(this->Internals->Results, name);
}

int vtkCageQualityFilter::GetNumberOfResults() const
{
  return static_cast<int>(this->Internals->Results.size());
}

const char* vtkCageQualityFilter::GetResultName(int index) const
{
  return sdfcage_vtk::ResultName(this->Internals->Results, index);
}
