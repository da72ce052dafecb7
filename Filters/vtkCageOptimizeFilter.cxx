/*=========================================================================

  Program:   SDFCage
  Module:    vtkCageOptimizeFilter.cxx

=========================================================================*/
#include "vtkCageOptimizeFilter.h"

#include "vtkAlgorithmOutput.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include "Mesh/Normalization.h"
#include "Optimization/Optimization.h"
#include "Mesh/Validation.h"
#include "SDFCageParallel.h"
#include "SDFCageVTKConversion.h"

#include <exception>
#include <new>
#include <sstream>

vtkStandardNewMacro(vtkCageOptimizeFilter);

using namespace sdfcage_vtk;

//------------------------------------------------------------------------------
struct vtkCageOptimizeFilter::vtkInternals
{
  sdfcage::ResultTable Results; // Core's table of the last execution
};

//------------------------------------------------------------------------------
vtkCageOptimizeFilter::vtkCageOptimizeFilter()
{
  // The defaults are Core's, so that the filter, the CLI and the plugin agree.
  const sdfcage::OptimizeOptions defaults;
  this->Energy = static_cast<int>(defaults.Energy);
  this->TargetSpacing = defaults.TargetSpacing;
  this->BarrierWeight = defaults.BarrierWeight;
  this->BarrierDistance = defaults.BarrierDistance;
  this->NumberOfIterations = defaults.NumberOfIterations;
  this->EdgeFlips = defaults.EdgeFlips ? 1 : 0;
  this->HausdorffFactor = defaults.HausdorffFactor;
  this->TargetMinimumAngle = defaults.TargetMinimumAngle;
  this->MaximumSweeps = defaults.MaximumSweeps;
  this->MinimumClearance = defaults.Clearance;
  this->Internals = std::make_unique<vtkInternals>();
  this->SetNumberOfInputPorts(2);
  this->SetNumberOfOutputPorts(1);
  this->ResetResults();
}

//------------------------------------------------------------------------------
vtkCageOptimizeFilter::~vtkCageOptimizeFilter() = default;

//------------------------------------------------------------------------------
void vtkCageOptimizeFilter::SetSourceConnection(vtkAlgorithmOutput* algOutput)
{
  this->SetInputConnection(1, algOutput);
}

//------------------------------------------------------------------------------
void vtkCageOptimizeFilter::SetSourceData(vtkDataObject* source)
{
  this->SetInputData(1, source);
}

//------------------------------------------------------------------------------
void vtkCageOptimizeFilter::ResetResults()
{
  this->Internals->Results = sdfcage::optimizeResults(sdfcage::OptimizeResult(), 0.0);
  this->StatusString = "NotExecuted";
  this->LastErrorMessage.clear();
}

//------------------------------------------------------------------------------
void vtkCageOptimizeFilter::PublishResults(vtkPolyData* output) const
{
  vtkFieldData* fd = output->GetFieldData();
  AddResultArrays(fd, this->Internals->Results);
  AddFieldValue<vtkStringArray>(fd, "Status", this->StatusString);
  AddFieldValue<vtkStringArray>(fd, "LastErrorMessage", this->LastErrorMessage);
}

//------------------------------------------------------------------------------
double vtkCageOptimizeFilter::GetResultNumber(const char* name) const
{
  return ResultNumber(this->Internals->Results, name);
}

const char* vtkCageOptimizeFilter::GetResultText(const char* name) const
{
  return ResultText(this->Internals->Results, name);
}

int vtkCageOptimizeFilter::GetNumberOfResults() const
{
  return static_cast<int>(this->Internals->Results.size());
}

const char* vtkCageOptimizeFilter::GetResultName(int index) const
{
  return ResultName(this->Internals->Results, index);
}

//------------------------------------------------------------------------------
int vtkCageOptimizeFilter::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  if (port == 1)
  {
    // a missing source gives an empty output, not a pipeline error
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkCageOptimizeFilter::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  RequestSamePieceWithoutGhosts(inputVector, this->GetNumberOfInputPorts(), outputVector, request);
  return 1;
}

//------------------------------------------------------------------------------
// On the whole inputs: directly in a serial run, on process 0 with the gathered pieces under MPI
// (the other processes adopt process 0's results).
int vtkCageOptimizeFilter::RequestData(
  vtkInformation* vtkNotUsed(request), vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  WholeSurfaceRun run;
  return RunOnWholeSurface(
    this, inputVector, outputVector, run,
    [this, outputVector](
      const std::vector<vtkPolyData*>& inputs) { return this->Execute(inputs[0], inputs[1], outputVector); },
    [this](vtkFieldData* fd) {
      this->ResetResults();
      ReadResultArrays(fd, this->Internals->Results);
      this->StatusString = FieldText(fd, "Status");
      this->LastErrorMessage = FieldText(fd, "LastErrorMessage");
    });
}

//------------------------------------------------------------------------------
int vtkCageOptimizeFilter::Execute(vtkPolyData* cage, vtkPolyData* source, vtkInformationVector* outputVector)
{
  this->ResetResults();
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!output)
  {
    vtkErrorMacro("The output data object is missing or of the wrong type.");
    return 0;
  }
  output->Initialize();

  auto publish = [&]() { this->PublishResults(output); };
  auto fail = [&](const std::string& status, const std::string& message) {
    output->Initialize();
    this->StatusString = status;
    this->LastErrorMessage = message;
    vtkErrorMacro(<< message);
    publish();
    return 0;
  };

  if (!cage || !source || cage->GetNumberOfCells() == 0 || source->GetNumberOfCells() == 0)
  {
    // nothing to optimize (or nothing to enclose): not an error
    this->StatusString = StatusIdentifier(sdfcage::Status::EmptyInput);
    publish();
    return 1;
  }

  try
  {
    sdfcage::PolygonMesh cagePolygons, sourcePolygons;
    ToPolygonMesh(cage, cagePolygons);
    ToPolygonMesh(source, sourcePolygons);
    sdfcage::TriangleMesh cageMesh, sourceMesh;
    const sdfcage::MeshDefects dc = sdfcage::prepareMesh(cagePolygons, cageMesh);
    if (!dc.usable())
    {
      return fail(
        StatusIdentifier(sdfcage::Status::InvalidInput), "The cage (input 0) is not usable: " + dc.errorMessage());
    }
    const sdfcage::MeshDefects ds = sdfcage::prepareMesh(sourcePolygons, sourceMesh);
    if (!ds.usableAsInput()) // open and soup sources are fine, as for the cage filter
    {
      return fail(StatusIdentifier(sdfcage::Status::InvalidInput),
        "The source mesh (input 1) is not usable: " + ds.inputErrorMessage());
    }

    sdfcage::OptimizeOptions options;
    options.Energy = this->Energy == SPACING ? sdfcage::CageEnergy::Spacing : sdfcage::CageEnergy::MIPS;
    options.TargetSpacing = this->TargetSpacing;
    options.BarrierWeight = this->BarrierWeight;
    options.BarrierDistance = this->BarrierDistance;
    options.NumberOfIterations = this->NumberOfIterations;
    options.EdgeFlips = this->EdgeFlips != 0;
    options.HausdorffFactor = this->HausdorffFactor;
    options.TargetMinimumAngle = this->TargetMinimumAngle;
    options.MaximumSweeps = this->MaximumSweeps;
    options.Clearance = this->MinimumClearance;
    options.KeepPartsApart = this->KeepPartsApart != 0;

    FilterProgress progress(this);
    this->UpdateProgress(0.0);
    const sdfcage::OptimizeResult r = sdfcage::optimizeCageInInputUnits(cageMesh, sourceMesh, options, &progress);
    const sdfcage::Normalization n = sdfcage::Normalization::fit(sourceMesh);

    this->Internals->Results = sdfcage::optimizeResults(r, n.lengthToUnit(r.MinimumClearance));
    this->StatusString = StatusIdentifier(r.State);
    this->LastErrorMessage = r.Message;

    switch (r.State)
    {
      case sdfcage::Status::Ok:
      case sdfcage::Status::Cancelled: // the cage so far is verified and valid
        break;
      case sdfcage::Status::EmptyInput:
        publish();
        return 1;
      default:
        return fail(this->StatusString,
          "Cage optimization failed: " + (r.Message.empty() ? std::string("no reason given") : r.Message));
    }
    if (r.Reverted)
    {
      vtkWarningMacro(<< r.Message);
    }
    ToPolyData(r.Cage, r.DistanceToInput, output);
    publish();
    this->UpdateProgress(1.0);
    return 1;
  }
  catch (const std::bad_alloc&)
  {
    return fail(StatusIdentifier(sdfcage::Status::Failed), "Out of memory during cage optimization.");
  }
  catch (const std::exception& e)
  {
    return fail(StatusIdentifier(sdfcage::Status::Failed), std::string("Cage optimization failed: ") + e.what());
  }
  catch (...)
  {
    return fail(StatusIdentifier(sdfcage::Status::Failed), "Cage optimization failed with an unknown exception.");
  }
}

//------------------------------------------------------------------------------
void vtkCageOptimizeFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Energy: " << (this->Energy == SPACING ? "Spacing" : "MIPS") << "\n";
  os << indent << "TargetSpacing: " << this->TargetSpacing << "\n";
  os << indent << "BarrierWeight: " << this->BarrierWeight << "\n";
  os << indent << "BarrierDistance: " << this->BarrierDistance << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "EdgeFlips: " << (this->EdgeFlips ? "On" : "Off") << "\n";
  os << indent << "HausdorffFactor: " << this->HausdorffFactor << "\n";
  os << indent << "TargetMinimumAngle: " << this->TargetMinimumAngle << "\n";
  os << indent << "MaximumSweeps: " << this->MaximumSweeps << "\n";
  os << indent << "MinimumClearance: " << this->MinimumClearance << "\n";
  os << indent << "KeepPartsApart: " << (this->KeepPartsApart ? "On" : "Off") << "\n";
  os << indent << "Status: " << this->StatusString << "\n";
  os << indent << "LastErrorMessage: " << this->LastErrorMessage << "\n";
  for (const sdfcage::ResultField& f : this->Internals->Results)
  {
    os << indent << f.Name << ": " << f.toString() << "\n";
  }
}
