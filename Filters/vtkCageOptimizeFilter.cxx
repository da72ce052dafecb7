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
#include "SDFCageVTKConversion.h"

#include <exception>
#include <new>
#include <sstream>

vtkStandardNewMacro(vtkCageOptimizeFilter);

using namespace sdfcage_vtk;

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
  this->MinimumClearance = defaults.Clearance;
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
  this->EnergyBefore = 0.0;
  this->EnergyAfter = 0.0;
  this->MinimumAngleBefore = 0.0;
  this->MinimumAngleAfter = 0.0;
  this->MeasuredClearance = 0.0;
  this->MeasuredClearanceRelative = 0.0;
  this->ClearanceUsed = 0.0;
  this->NumberOfMoves = 0;
  this->NumberOfFlips = 0;
  this->Reverted = false;
  this->OptimizationTime = 0.0;
  this->StatusString = "NotExecuted";
  this->LastErrorMessage.clear();
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
int vtkCageOptimizeFilter::RequestData(vtkInformation* vtkNotUsed(request),
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->ResetResults();
  vtkPolyData* cage = vtkPolyData::GetData(inputVector[0], 0);
  vtkPolyData* source = vtkPolyData::GetData(inputVector[1], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!output)
  {
    vtkErrorMacro("The output data object is missing or of the wrong type.");
    return 0;
  }
  output->Initialize();

  auto publish = [&]() {
    vtkFieldData* fd = output->GetFieldData();
    AddFieldValue<vtkDoubleArray>(fd, "EnergyBefore", this->EnergyBefore);
    AddFieldValue<vtkDoubleArray>(fd, "EnergyAfter", this->EnergyAfter);
    AddFieldValue<vtkDoubleArray>(fd, "MinimumAngleBefore", this->MinimumAngleBefore);
    AddFieldValue<vtkDoubleArray>(fd, "MinimumAngleAfter", this->MinimumAngleAfter);
    AddFieldValue<vtkDoubleArray>(fd, "MeasuredClearance", this->MeasuredClearance);
    AddFieldValue<vtkDoubleArray>(fd, "MeasuredClearanceRelative", this->MeasuredClearanceRelative);
    AddFieldValue<vtkDoubleArray>(fd, "ClearanceUsed", this->ClearanceUsed);
    AddFieldValue<vtkIntArray>(fd, "NumberOfMoves", this->NumberOfMoves);
    AddFieldValue<vtkIntArray>(fd, "NumberOfFlips", this->NumberOfFlips);
    AddFieldValue<vtkIntArray>(fd, "Reverted", this->Reverted ? 1 : 0);
    AddFieldValue<vtkDoubleArray>(fd, "OptimizationTime", this->OptimizationTime);
    AddFieldValue<vtkStringArray>(fd, "Status", this->StatusString);
    AddFieldValue<vtkStringArray>(fd, "LastErrorMessage", this->LastErrorMessage);
  };
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
      return fail(StatusIdentifier(sdfcage::Status::InvalidInput), "The cage (input 0) is not usable: " + dc.errorMessage());
    }
    const sdfcage::MeshDefects ds = sdfcage::prepareMesh(sourcePolygons, sourceMesh);
    if (!ds.usableAsInput()) // open and soup sources are fine, as for the cage filter
    {
      return fail(StatusIdentifier(sdfcage::Status::InvalidInput), "The source mesh (input 1) is not usable: " + ds.inputErrorMessage());
    }

    sdfcage::OptimizeOptions options;
    options.Energy = this->Energy == SPACING ? sdfcage::CageEnergy::Spacing : sdfcage::CageEnergy::MIPS;
    options.TargetSpacing = this->TargetSpacing;
    options.BarrierWeight = this->BarrierWeight;
    options.BarrierDistance = this->BarrierDistance;
    options.NumberOfIterations = this->NumberOfIterations;
    options.EdgeFlips = this->EdgeFlips != 0;
    options.Clearance = this->MinimumClearance;

    FilterProgress progress(this);
    this->UpdateProgress(0.0);
    const sdfcage::OptimizeResult r = sdfcage::optimizeCageInInputUnits(cageMesh, sourceMesh, options, &progress);
    const sdfcage::Normalization n = sdfcage::Normalization::fit(sourceMesh);

    this->EnergyBefore = r.EnergyBefore;
    this->EnergyAfter = r.EnergyAfter;
    this->MinimumAngleBefore = r.MinimumAngleBefore;
    this->MinimumAngleAfter = r.MinimumAngleAfter;
    this->MeasuredClearance = r.MinimumClearance;
    this->MeasuredClearanceRelative = n.lengthToUnit(r.MinimumClearance);
    this->ClearanceUsed = r.ClearanceUsed;
    this->NumberOfMoves = static_cast<int>(r.Moves);
    this->NumberOfFlips = static_cast<int>(r.Flips);
    this->Reverted = r.Reverted;
    this->OptimizationTime = r.Seconds;
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
        return fail(this->StatusString, "Cage optimization failed: " +
            (r.Message.empty() ? std::string("no reason given") : r.Message));
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
  os << indent << "MinimumClearance: " << this->MinimumClearance << "\n";
  os << indent << "Status: " << this->StatusString << "\n";
  os << indent << "LastErrorMessage: " << this->LastErrorMessage << "\n";
  os << indent << "EnergyBefore: " << this->EnergyBefore << "\n";
  os << indent << "EnergyAfter: " << this->EnergyAfter << "\n";
  os << indent << "MeasuredClearance: " << this->MeasuredClearance << "\n";
  os << indent << "OptimizationTime: " << this->OptimizationTime << "\n";
}
