/*=========================================================================

  Program:   SDFCage
  Module:    vtkSDFCageFilter.cxx

=========================================================================*/
#include "vtkSDFCageFilter.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"

#include "Pipeline/CageGenerator.h"
#include "Pipeline/Results.h"
#include "SDFCageVTKConversion.h"
#include "Common/Progress.h"

#include <algorithm>
#include <exception>
#include <new>
#include <sstream>
#include <thread>
#include <utility>

vtkStandardNewMacro(vtkSDFCageFilter);


using namespace sdfcage_vtk;

//------------------------------------------------------------------------------
vtkSDFCageFilter::vtkSDFCageFilter()
{
  // The defaults are Core's, so that the filter, the CLI and the plugin agree.
  const sdfcage::CageOptions cageDefaults;
  const sdfcage::EnvelopeOptions& defaults = cageDefaults.Envelope;
  this->TargetNumberOfVertices = cageDefaults.TargetNumberOfVertices;
  this->IsoValue = defaults.IsoValue;
  this->VoxelSize = defaults.VoxelSize;
  this->MinimumClearance = defaults.MinimumClearance;
  this->Adaptivity = defaults.Adaptivity;
  this->MaximumRefinements = defaults.MaximumRefinements;
  this->GenerateDistanceField = defaults.KeepDistanceField ? 1 : 0;
  this->UseActivePoints = defaults.UseActivePoints ? 1 : 0;
  this->ActiveRadius = defaults.ActivePoints.Radius;
  this->GeodesicThreshold = defaults.ActivePoints.GeodesicThreshold;
  this->AmplificationAlpha = defaults.ActivePoints.Alpha;
  this->AmplificationBeta = defaults.ActivePoints.Beta;
  this->NumberOfThreads = defaults.NumberOfThreads;
  this->Optimize = cageDefaults.Optimize ? 1 : 0;
  this->Energy = static_cast<int>(cageDefaults.Optimization.Energy);
  this->TargetSpacing = cageDefaults.Optimization.TargetSpacing;
  this->BarrierWeight = cageDefaults.Optimization.BarrierWeight;
  this->BarrierDistance = cageDefaults.Optimization.BarrierDistance;
  this->NumberOfIterations = cageDefaults.Optimization.NumberOfIterations;
  this->EdgeFlips = cageDefaults.Optimization.EdgeFlips ? 1 : 0;

  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(3);
  this->ResetResults();
}

//------------------------------------------------------------------------------
vtkSDFCageFilter::~vtkSDFCageFilter() = default;

//------------------------------------------------------------------------------
void vtkSDFCageFilter::ResetResults()
{
  this->ValidationTime = 0.0;
  this->DistanceFieldTime = 0.0;
  this->IsosurfaceTime = 0.0;
  this->VerificationTime = 0.0;
  this->SimplificationTime = 0.0;
  this->CageVerificationTime = 0.0;
  this->TotalTime = 0.0;
  this->EnergyBefore = 0.0;
  this->EnergyAfter = 0.0;
  this->OptimizationTime = 0.0;
  this->VerticesReached = 0;
  this->TargetReached = false;
  this->StopReason.clear();
  this->MeasuredClearance = 0.0;
  this->MeasuredClearanceRelative = 0.0;
  this->EnclosureVerified = false;
  this->RemovedPockets = 0;
  this->EnvelopeGenus = 0;
  this->EnvelopeComponents = 0;
  this->VoxelSizeUsed = 0.0;
  this->InputWasFlipped = false;
  this->NumberOfActivePoints = 0;
  this->ActivePointTime = 0.0;
  this->TopologyWarning.clear();
  this->ResultNumbers.clear();
  this->ResultTexts.clear();
  this->StatusString = "NotExecuted";
  this->LastErrorMessage.clear();
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::FillOutputPortInformation(int port, vtkInformation* info)
{
  if (port == 2)
  {
    info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkImageData");
    return 1;
  }
  return this->Superclass::FillOutputPortInformation(port, info);
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::RequestData(vtkInformation* vtkNotUsed(request),
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->ResetResults();

  vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
  vtkPolyData* cageOutput = vtkPolyData::GetData(outputVector, 0);
  vtkPolyData* envelopeOutput = vtkPolyData::GetData(outputVector, 1);
  vtkImageData* fieldOutput = vtkImageData::GetData(outputVector, 2);
  if (!cageOutput || !envelopeOutput || !fieldOutput)
  {
    vtkErrorMacro("Output data objects are missing or of the wrong type.");
    return 0;
  }
  cageOutput->Initialize();
  envelopeOutput->Initialize();
  fieldOutput->Initialize();

  // Publishes the results as field data on the cage (for ParaView's Information panel and
  // pvpython's Fetch), whatever the outcome.
  auto publish = [&]() {
    vtkFieldData* fd = cageOutput->GetFieldData();
    AddFieldValue<vtkDoubleArray>(fd, "ValidationTime", this->ValidationTime);
    AddFieldValue<vtkDoubleArray>(fd, "DistanceFieldTime", this->DistanceFieldTime);
    AddFieldValue<vtkDoubleArray>(fd, "IsosurfaceTime", this->IsosurfaceTime);
    AddFieldValue<vtkDoubleArray>(fd, "VerificationTime", this->VerificationTime);
    AddFieldValue<vtkDoubleArray>(fd, "SimplificationTime", this->SimplificationTime);
    AddFieldValue<vtkDoubleArray>(fd, "CageVerificationTime", this->CageVerificationTime);
    AddFieldValue<vtkDoubleArray>(fd, "TotalTime", this->TotalTime);
    if (this->Optimize)
    {
      AddFieldValue<vtkDoubleArray>(fd, "EnergyBefore", this->EnergyBefore);
      AddFieldValue<vtkDoubleArray>(fd, "EnergyAfter", this->EnergyAfter);
      AddFieldValue<vtkDoubleArray>(fd, "OptimizationTime", this->OptimizationTime);
    }
    AddFieldValue<vtkIntArray>(fd, "VerticesReached", this->VerticesReached);
    AddFieldValue<vtkIntArray>(fd, "TargetReached", this->TargetReached ? 1 : 0);
    AddFieldValue<vtkStringArray>(fd, "StopReason", this->StopReason);
    AddFieldValue<vtkDoubleArray>(fd, "MeasuredClearance", this->MeasuredClearance);
    AddFieldValue<vtkDoubleArray>(
      fd, "MeasuredClearanceRelative", this->MeasuredClearanceRelative);
    AddFieldValue<vtkIntArray>(fd, "EnclosureVerified", this->EnclosureVerified ? 1 : 0);
    AddFieldValue<vtkIntArray>(fd, "RemovedPockets", this->RemovedPockets);
    AddFieldValue<vtkIntArray>(fd, "EnvelopeGenus", this->EnvelopeGenus);
    AddFieldValue<vtkIntArray>(fd, "EnvelopeComponents", this->EnvelopeComponents);
    AddFieldValue<vtkDoubleArray>(fd, "VoxelSizeUsed", this->VoxelSizeUsed);
    AddFieldValue<vtkIntArray>(fd, "InputWasFlipped", this->InputWasFlipped ? 1 : 0);
    AddFieldValue<vtkIdTypeArray>(fd, "NumberOfActivePoints", this->NumberOfActivePoints);
    AddFieldValue<vtkDoubleArray>(fd, "ActivePointTime", this->ActivePointTime);
    AddFieldValue<vtkStringArray>(fd, "TopologyWarning", this->TopologyWarning);
    for (const auto& kv : this->ResultNumbers)
    {
      AddFieldValue<vtkDoubleArray>(fd, kv.first.c_str(), kv.second);
    }
    for (const auto& kv : this->ResultTexts)
    {
      AddFieldValue<vtkStringArray>(fd, kv.first.c_str(), kv.second);
    }
    AddFieldValue<vtkStringArray>(fd, "Status", this->StatusString);
    AddFieldValue<vtkStringArray>(fd, "LastErrorMessage", this->LastErrorMessage);
  };
  auto fail = [&](const std::string& status, const std::string& message) {
    this->StatusString = status;
    this->LastErrorMessage = message;
    vtkErrorMacro(<< message);
    publish();
    return 0;
  };

  // Empty input is not an error.
  if (!input || input->GetNumberOfPoints() == 0 || input->GetNumberOfCells() == 0)
  {
    this->StatusString = StatusIdentifier(sdfcage::Status::EmptyInput);
    publish();
    return 1;
  }
  if (input->GetNumberOfPolys() + input->GetNumberOfStrips() == 0)
  {
    std::ostringstream msg;
    msg << "The input has " << input->GetNumberOfVerts() << " vertex and "
        << input->GetNumberOfLines()
        << " line cells but no polygons: a surface mesh is required (for a point cloud, "
           "reconstruct a surface first, e.g. with vtkSurfaceReconstructionFilter or ParaView's "
           "Delaunay 3D + Extract Surface).";
    return fail(StatusIdentifier(sdfcage::Status::InvalidInput), msg.str());
  }

  try
  {
    sdfcage::PolygonMesh mesh;
    ToPolygonMesh(input, mesh);

    sdfcage::CageOptions options;
    options.TargetNumberOfVertices = this->TargetNumberOfVertices;
    options.Envelope.IsoValue = this->IsoValue;
    options.Envelope.VoxelSize = this->VoxelSize;
    options.Envelope.MinimumClearance = this->MinimumClearance;
    options.Envelope.Adaptivity = this->Adaptivity;
    options.Envelope.MaximumRefinements = this->MaximumRefinements;
    options.Envelope.KeepDistanceField = this->GenerateDistanceField != 0;
    options.Envelope.UseActivePoints = this->UseActivePoints != 0;
    options.Envelope.ActivePoints.Radius = this->ActiveRadius;
    options.Envelope.ActivePoints.GeodesicThreshold = this->GeodesicThreshold;
    options.Envelope.ActivePoints.Alpha = this->AmplificationAlpha;
    options.Envelope.ActivePoints.Beta = this->AmplificationBeta;
    options.Envelope.NumberOfThreads = this->NumberOfThreads;
    options.Envelope.Sign = static_cast<sdfcage::SignMode>(this->SignMode);
    options.Optimize = this->Optimize != 0;
    options.Optimization.Energy = this->Energy == 1 ? sdfcage::CageEnergy::Spacing : sdfcage::CageEnergy::MIPS;
    options.Optimization.TargetSpacing = this->TargetSpacing;
    options.Optimization.BarrierWeight = this->BarrierWeight;
    options.Optimization.BarrierDistance = this->BarrierDistance;
    options.Optimization.NumberOfIterations = this->NumberOfIterations;
    options.Optimization.EdgeFlips = this->EdgeFlips != 0;

    FilterProgress progress(this);
    this->UpdateProgress(0.0);
    const sdfcage::CageResult result = sdfcage::generateCage(mesh, options, &progress);

    this->ValidationTime = result.ValidationSeconds;
    this->DistanceFieldTime = result.DistanceFieldSeconds;
    this->IsosurfaceTime = result.IsosurfaceSeconds;
    this->VerificationTime = result.VerificationSeconds;
    this->SimplificationTime = result.SimplificationSeconds;
    this->CageVerificationTime = result.CageVerificationSeconds;
    this->TotalTime = result.TotalSeconds;
    this->EnergyBefore = result.Optimization.EnergyBefore;
    this->EnergyAfter = result.Optimization.EnergyAfter;
    this->OptimizationTime = result.OptimizationSeconds;
    this->VerticesReached = result.VerticesReached;
    this->TargetReached = result.TargetReached;
    this->StopReason = result.StopReason;
    this->MeasuredClearance = result.MinimumClearance;
    this->MeasuredClearanceRelative = result.MinimumClearanceRelative;
    this->EnclosureVerified = result.EnclosureVerified;
    this->RemovedPockets = result.RemovedPockets;
    this->EnvelopeGenus = result.EnvelopeGenus;
    this->EnvelopeComponents = result.EnvelopeComponents;
    this->VoxelSizeUsed = result.VoxelSizeUsed;
    this->InputWasFlipped = result.Defects.FlippedOrientation;
    this->NumberOfActivePoints = static_cast<vtkIdType>(result.NumberOfActivePoints);
    this->ActivePointTime = result.ActivePointSeconds;
    this->TopologyWarning = result.TopologyWarning;
    for (const sdfcage::ResultField& f : sdfcage::inputResults(result))
    {
      if (f.Type == sdfcage::ResultField::Kind::Text)
        this->ResultTexts[f.Name] = f.Text;
      else
        this->ResultNumbers[f.Name] = f.number();
    }
    this->StatusString = StatusIdentifier(result.State);
    this->LastErrorMessage = result.Message;

    switch (result.State)
    {
      case sdfcage::Status::Ok:
        break;
      case sdfcage::Status::EmptyInput:
        // e.g. every polygon was a vertex or line cell: nothing to enclose, not an error.
        publish();
        return 1;
      case sdfcage::Status::Cancelled:
        // Aborted by the user, no error. A cancel during the simplification leaves a verified,
        // valid cage (with more vertices than asked): output it; before that there is none.
        vtkDebugMacro("Execution cancelled: " << result.Message);
        if (!result.Cage.empty())
        {
          ToPolyData(result.Cage, result.CageDistanceToInput, cageOutput);
          ToPolyData(result.Envelope, result.EnvelopeDistanceToInput, envelopeOutput);
        }
        publish();
        return 1;
      case sdfcage::Status::InvalidInput:
      {
        std::string message = result.Message;
        if (message.empty())
        {
          message = result.Defects.errorMessage();
        }
        return fail(this->StatusString, message);
      }
      case sdfcage::Status::VerificationFailed:
        // Keep the unverified envelope for inspection; the cage stays empty.
        ToPolyData(result.Envelope, result.EnvelopeDistanceToInput, envelopeOutput);
        return fail(this->StatusString,
          "The envelope could not be verified: " +
            (result.Message.empty() ? std::string("no reason given") : result.Message));
      case sdfcage::Status::Failed:
      default:
        return fail(this->StatusString,
          "Cage generation failed: " +
            (result.Message.empty() ? std::string("no reason given") : result.Message));
    }

    std::vector<std::string> warnings = result.Defects.warnings();
    if (this->Optimize && !result.Optimized && result.State == sdfcage::Status::Ok)
    {
      warnings.push_back("the cage was not optimized: " +
        (result.Optimization.Message.empty() ? std::string("no reason given") : result.Optimization.Message));
    }
    if (!result.TargetReached)
    {
      std::ostringstream msg;
      msg << "the cage has " << result.VerticesReached << " vertices, not the " << this->TargetNumberOfVertices
          << " asked for: " << (result.StopReason.empty() ? "no reason given" : result.StopReason);
      warnings.push_back(msg.str());
    }
    if (!result.TopologyWarning.empty())
    {
      warnings.push_back(result.TopologyWarning);
    }
    if (!warnings.empty())
    {
      std::ostringstream msg;
      for (std::size_t i = 0; i < warnings.size(); ++i)
      {
        msg << (i ? "; " : "") << warnings[i];
      }
      vtkWarningMacro(<< msg.str());
    }

    ToPolyData(result.Cage, result.CageDistanceToInput, cageOutput);
    ToPolyData(result.Envelope, result.EnvelopeDistanceToInput, envelopeOutput);
    if (this->GenerateDistanceField)
    {
      ToImageData(result.DistanceField, fieldOutput, "SignedDistance");
      ToImageData(result.ModifiedDistanceField, fieldOutput, "ModifiedSignedDistance");
    }
    publish();
    this->UpdateProgress(1.0);
    return 1;
  }
  catch (const std::bad_alloc&)
  {
    cageOutput->Initialize();
    envelopeOutput->Initialize();
    fieldOutput->Initialize();
    return fail(StatusIdentifier(sdfcage::Status::Failed),
      "Out of memory. Use a larger VoxelSize (or IsoValue), or turn GenerateDistanceField off.");
  }
  catch (const std::exception& e)
  {
    cageOutput->Initialize();
    envelopeOutput->Initialize();
    fieldOutput->Initialize();
    return fail(StatusIdentifier(sdfcage::Status::Failed), std::string("Cage generation failed: ") + e.what());
  }
  catch (...)
  {
    cageOutput->Initialize();
    envelopeOutput->Initialize();
    fieldOutput->Initialize();
    return fail(StatusIdentifier(sdfcage::Status::Failed), "Cage generation failed with an unknown exception.");
  }
}

//------------------------------------------------------------------------------
void vtkSDFCageFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TargetNumberOfVertices: " << this->TargetNumberOfVertices << "\n";
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "VoxelSize: " << this->VoxelSize << "\n";
  os << indent << "MinimumClearance: " << this->MinimumClearance << "\n";
  os << indent << "Adaptivity: " << this->Adaptivity << "\n";
  os << indent << "MaximumRefinements: " << this->MaximumRefinements << "\n";
  os << indent << "UseActivePoints: " << (this->UseActivePoints ? "On" : "Off") << "\n";
  os << indent << "ActiveRadius: " << this->ActiveRadius << "\n";
  os << indent << "GeodesicThreshold: " << this->GeodesicThreshold << "\n";
  os << indent << "AmplificationAlpha: " << this->AmplificationAlpha << "\n";
  os << indent << "AmplificationBeta: " << this->AmplificationBeta << "\n";
  os << indent << "NumberOfActivePoints: " << this->NumberOfActivePoints << "\n";
  os << indent << "TopologyWarning: " << this->TopologyWarning << "\n";
  os << indent << "SignMode: " << this->SignMode << "\n";
  os << indent << "GenerateDistanceField: " << (this->GenerateDistanceField ? "On" : "Off")
     << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Optimize: " << (this->Optimize ? "On" : "Off") << "\n";
  os << indent << "Energy: " << (this->Energy == 1 ? "Spacing" : "MIPS") << "\n";
  os << indent << "TargetSpacing: " << this->TargetSpacing << "\n";
  os << indent << "BarrierWeight: " << this->BarrierWeight << "\n";
  os << indent << "BarrierDistance: " << this->BarrierDistance << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "EdgeFlips: " << (this->EdgeFlips ? "On" : "Off") << "\n";
  os << indent << "Status: " << this->StatusString << "\n";
  os << indent << "LastErrorMessage: " << this->LastErrorMessage << "\n";
  os << indent << "ValidationTime: " << this->ValidationTime << "\n";
  os << indent << "DistanceFieldTime: " << this->DistanceFieldTime << "\n";
  os << indent << "IsosurfaceTime: " << this->IsosurfaceTime << "\n";
  os << indent << "VerificationTime: " << this->VerificationTime << "\n";
  os << indent << "SimplificationTime: " << this->SimplificationTime << "\n";
  os << indent << "CageVerificationTime: " << this->CageVerificationTime << "\n";
  os << indent << "TotalTime: " << this->TotalTime << "\n";
  os << indent << "VerticesReached: " << this->VerticesReached << "\n";
  os << indent << "TargetReached: " << this->TargetReached << "\n";
  os << indent << "StopReason: " << this->StopReason << "\n";
  os << indent << "MeasuredClearance: " << this->MeasuredClearance << "\n";
  os << indent << "MeasuredClearanceRelative: " << this->MeasuredClearanceRelative << "\n";
  os << indent << "EnclosureVerified: " << this->EnclosureVerified << "\n";
  os << indent << "RemovedPockets: " << this->RemovedPockets << "\n";
  os << indent << "EnvelopeGenus: " << this->EnvelopeGenus << "\n";
  os << indent << "EnvelopeComponents: " << this->EnvelopeComponents << "\n";
  os << indent << "VoxelSizeUsed: " << this->VoxelSizeUsed << "\n";
  os << indent << "InputWasFlipped: " << this->InputWasFlipped << "\n";
}

//------------------------------------------------------------------------------
double vtkSDFCageFilter::GetResultNumber(const char* name) const
{
  const auto it = name ? this->ResultNumbers.find(name) : this->ResultNumbers.end();
  return it == this->ResultNumbers.end() ? 0.0 : it->second;
}

//------------------------------------------------------------------------------
const char* vtkSDFCageFilter::GetResultText(const char* name) const
{
  const auto it = name ? this->ResultTexts.find(name) : this->ResultTexts.end();
  return it == this->ResultTexts.end() ? "" : it->second.c_str();
}
