/*=========================================================================

  Program:   SDFCage
  Module:    vtkSDFCageFilter.cxx

=========================================================================*/
#include "vtkSDFCageFilter.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"

#include "Pipeline/CageGenerator.h"
#include "Pipeline/NestedCages.h"
#include "Pipeline/Results.h"
#include "SDFCageParallel.h"
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
struct vtkSDFCageFilter::vtkInternals
{
  sdfcage::ResultTable Results; // Core's table of the last execution
};

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
  this->MaximumEnvelopeWidenings = cageDefaults.MaximumEnvelopeWidenings;
  this->MaximumRelaxations = cageDefaults.MaximumRelaxations;
  this->ChooseIsoValueFirst = cageDefaults.ChooseIsoValueFirst ? 1 : 0;
  this->MaximumTopologyRepairs = defaults.MaximumTopologyRepairs;
  this->RequireTopology = defaults.RequireTopology ? 1 : 0;
  this->CoarseFirst = defaults.CoarseFirst ? 1 : 0;
  this->GenerateDistanceField = defaults.KeepDistanceField ? 1 : 0;
  this->UseActivePoints = defaults.UseActivePoints ? 1 : 0;
  this->ActiveRadius = defaults.ActivePoints.Radius;
  this->GeodesicThreshold = defaults.ActivePoints.GeodesicThreshold;
  this->AmplificationAlpha = defaults.ActivePoints.Alpha;
  this->AmplificationBeta = defaults.ActivePoints.Beta;
  this->NumberOfThreads = cageDefaults.NumberOfThreads;
  this->Optimize = cageDefaults.Optimize ? 1 : 0;
  this->Energy = static_cast<int>(cageDefaults.Optimization.Energy);
  this->TargetSpacing = cageDefaults.Optimization.TargetSpacing;
  this->BarrierWeight = cageDefaults.Optimization.BarrierWeight;
  this->BarrierDistance = cageDefaults.Optimization.BarrierDistance;
  this->NumberOfIterations = cageDefaults.Optimization.NumberOfIterations;
  this->EdgeFlips = cageDefaults.Optimization.EdgeFlips ? 1 : 0;
  this->HausdorffFactor = cageDefaults.Optimization.HausdorffFactor;
  this->TargetMinimumAngle = cageDefaults.Optimization.TargetMinimumAngle;
  this->MaximumSweeps = cageDefaults.Optimization.MaximumSweeps;

  this->Internals = std::make_unique<vtkInternals>();
  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(4);
  this->ResetResults();
}

//------------------------------------------------------------------------------
vtkSDFCageFilter::~vtkSDFCageFilter() = default;

//------------------------------------------------------------------------------
void vtkSDFCageFilter::SetNumberOfNestedLevels(int number)
{
  const std::size_t n = static_cast<std::size_t>(std::max(0, number));
  if (n != this->NestedVertexCounts.size())
  {
    this->NestedVertexCounts.resize(n, 0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::GetNumberOfNestedLevels() const
{
  return static_cast<int>(this->NestedVertexCounts.size());
}

//------------------------------------------------------------------------------
// Like vtkContourFilter::SetValue: an index past the end grows the list (new entries 0, which
// the execution rejects until they are set).
void vtkSDFCageFilter::SetNestedVertexCount(int level, int count)
{
  if (level < 0)
  {
    vtkErrorMacro("SetNestedVertexCount: the level index must be >= 0, got " << level);
    return;
  }
  const std::size_t i = static_cast<std::size_t>(level);
  if (i >= this->NestedVertexCounts.size())
  {
    this->NestedVertexCounts.resize(i + 1, 0);
  }
  else if (this->NestedVertexCounts[i] == count)
  {
    return;
  }
  this->NestedVertexCounts[i] = count;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::GetNestedVertexCount(int level) const
{
  return level >= 0 && static_cast<std::size_t>(level) < this->NestedVertexCounts.size()
    ? this->NestedVertexCounts[static_cast<std::size_t>(level)]
    : 0;
}

//------------------------------------------------------------------------------
void vtkSDFCageFilter::ResetResults()
{
  // the table of a run that did not happen: every result present, with its "nothing" value
  this->Internals->Results = sdfcage::cageResults(sdfcage::CageResult());
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
  if (port == 3)
  {
    info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkMultiBlockDataSet");
    return 1;
  }
  return this->Superclass::FillOutputPortInformation(port, info);
}

namespace
{
//------------------------------------------------------------------------------
// The filter's parameters as Core's options.
sdfcage::CageOptions CageOptionsOf(vtkSDFCageFilter* f)
{
  sdfcage::CageOptions options;
  options.TargetNumberOfVertices = f->GetTargetNumberOfVertices();
  options.NumberOfThreads = f->GetNumberOfThreads();
  options.Envelope.IsoValue = f->GetIsoValue();
  options.Envelope.VoxelSize = f->GetVoxelSize();
  options.Envelope.MinimumClearance = f->GetMinimumClearance();
  options.Envelope.Adaptivity = f->GetAdaptivity();
  options.Envelope.MaximumRefinements = f->GetMaximumRefinements();
  options.MaximumEnvelopeWidenings = f->GetMaximumEnvelopeWidenings();
  options.MaximumRelaxations = f->GetMaximumRelaxations();
  options.ChooseIsoValueFirst = f->GetChooseIsoValueFirst() != 0;
  options.Envelope.MaximumTopologyRepairs = f->GetMaximumTopologyRepairs();
  options.Envelope.RequireTopology = f->GetRequireTopology() != 0;
  options.Envelope.CoarseFirst = f->GetCoarseFirst() != 0;
  options.Envelope.MemoryLimit = static_cast<std::size_t>(f->GetMemoryLimit() * 1048576.0);
  options.Envelope.KeepDistanceField = f->GetGenerateDistanceField() != 0;
  options.Envelope.UseActivePoints = f->GetUseActivePoints() != 0;
  options.Envelope.ActivePoints.Radius = f->GetActiveRadius();
  options.Envelope.ActivePoints.GeodesicThreshold = f->GetGeodesicThreshold();
  options.Envelope.ActivePoints.Alpha = f->GetAmplificationAlpha();
  options.Envelope.ActivePoints.Beta = f->GetAmplificationBeta();
  options.Envelope.Sign = static_cast<sdfcage::SignMode>(f->GetSignMode());
  options.Optimize = f->GetOptimize() != 0;
  options.Optimization.Energy = f->GetEnergy() == 1 ? sdfcage::CageEnergy::Spacing : sdfcage::CageEnergy::MIPS;
  options.Optimization.TargetSpacing = f->GetTargetSpacing();
  options.Optimization.BarrierWeight = f->GetBarrierWeight();
  options.Optimization.BarrierDistance = f->GetBarrierDistance();
  options.Optimization.NumberOfIterations = f->GetNumberOfIterations();
  options.Optimization.EdgeFlips = f->GetEdgeFlips() != 0;
  options.Optimization.HausdorffFactor = f->GetHausdorffFactor();
  options.Optimization.TargetMinimumAngle = f->GetTargetMinimumAngle();
  options.Optimization.MaximumSweeps = f->GetMaximumSweeps();
  return options;
}

std::string OrNoReason(const std::string& message)
{
  return message.empty() ? std::string("no reason given") : message;
}
} // namespace

//------------------------------------------------------------------------------
int vtkSDFCageFilter::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  RequestSamePieceWithoutGhosts(inputVector, this->GetNumberOfInputPorts(), outputVector, request);
  return 1;
}

//------------------------------------------------------------------------------
// On the whole input: directly in a serial run, on process 0 with the gathered pieces under MPI.
int vtkSDFCageFilter::RequestData(
  vtkInformation* vtkNotUsed(request), vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  WholeSurfaceRun run;
  run.ResultsPort = 0;
  run.ImagePorts = { 2 };
  return RunOnWholeSurface(
    this, inputVector, outputVector, run,
    [this, outputVector](const std::vector<vtkPolyData*>& inputs) { return this->Execute(inputs[0], outputVector); },
    [this, outputVector](vtkFieldData* fd) {
      this->AdoptResults(fd);
      // the same block structure as process 0's, every block empty
      this->MakeEmptyLevels(vtkMultiBlockDataSet::GetData(outputVector, 3));
    });
}

//------------------------------------------------------------------------------
// Process 0's results on the other processes of an MPI run.
void vtkSDFCageFilter::AdoptResults(vtkFieldData* fd)
{
  this->ResetResults();
  ReadResultArrays(fd, this->Internals->Results);
  this->StatusString = FieldText(fd, "Status");
  this->LastErrorMessage = FieldText(fd, "LastErrorMessage");
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::Execute(vtkPolyData* input, vtkInformationVector* outputVector)
{
  this->ResetResults();

  vtkPolyData* cageOutput = vtkPolyData::GetData(outputVector, 0);
  vtkPolyData* envelopeOutput = vtkPolyData::GetData(outputVector, 1);
  vtkImageData* fieldOutput = vtkImageData::GetData(outputVector, 2);
  vtkMultiBlockDataSet* levelsOutput = vtkMultiBlockDataSet::GetData(outputVector, 3);
  if (!cageOutput || !envelopeOutput || !fieldOutput || !levelsOutput)
  {
    vtkErrorMacro("Output data objects are missing or of the wrong type.");
    return 0;
  }
  cageOutput->Initialize();
  envelopeOutput->Initialize();
  fieldOutput->Initialize();
  levelsOutput->Initialize();
  if (!this->NestedVertexCounts.empty())
  {
    std::vector<int> counts = this->NestedVertexCounts;
    const std::string bad = sdfcage::sortNestedCounts(counts);
    if (!bad.empty())
    {
      std::ostringstream msg;
      msg << "NestedVertexCounts (";
      for (std::size_t i = 0; i < this->NestedVertexCounts.size(); ++i)
        msg << (i ? "," : "") << this->NestedVertexCounts[i];
      msg << "): " << bad << ".";
      return this->Fail(StatusIdentifier(sdfcage::Status::InvalidInput), msg.str(), cageOutput);
    }
    this->MakeEmptyLevels(levelsOutput);
  }

  if (!input || input->GetNumberOfPoints() == 0 || input->GetNumberOfCells() == 0 ||
    input->GetNumberOfPolys() + input->GetNumberOfStrips() == 0)
  {
    return this->RejectInput(input, cageOutput);
  }
  try
  {
    // read -> options -> run -> results -> outputs
    sdfcage::PolygonMesh mesh;
    ToPolygonMesh(input, mesh);
    if (!this->NestedVertexCounts.empty())
    {
      return this->ExecuteNested(mesh, cageOutput, envelopeOutput, fieldOutput, levelsOutput);
    }
    const sdfcage::CageOptions options = CageOptionsOf(this);
    FilterProgress progress(this);
    this->UpdateProgress(0.0);
    const sdfcage::CageResult result = sdfcage::generateCage(mesh, options, &progress);
    this->Internals->Results = sdfcage::cageResults(result);
    this->StatusString = StatusIdentifier(result.State);
    this->LastErrorMessage = result.Message;
    return this->DeliverOutputs(result, cageOutput, envelopeOutput, fieldOutput);
  }
  catch (const std::bad_alloc&)
  {
    envelopeOutput->Initialize();
    fieldOutput->Initialize();
    this->MakeEmptyLevels(levelsOutput);
    return this->Fail(StatusIdentifier(sdfcage::Status::Failed),
      "Out of memory. Use a larger VoxelSize (or IsoValue), or turn GenerateDistanceField off.", cageOutput);
  }
  catch (const std::exception& e)
  {
    envelopeOutput->Initialize();
    fieldOutput->Initialize();
    this->MakeEmptyLevels(levelsOutput);
    return this->Fail(
      StatusIdentifier(sdfcage::Status::Failed), std::string("Cage generation failed: ") + e.what(), cageOutput);
  }
  catch (...)
  {
    envelopeOutput->Initialize();
    fieldOutput->Initialize();
    this->MakeEmptyLevels(levelsOutput);
    return this->Fail(
      StatusIdentifier(sdfcage::Status::Failed), "Cage generation failed with an unknown exception.", cageOutput);
  }
}

//------------------------------------------------------------------------------
// One empty block per nested level (sorted finest first), named like the level, Status
// "NotBuilt": the structure of port 3 depends on the parameters only, so every process of an MPI
// run and every outcome has the same blocks.
void vtkSDFCageFilter::MakeEmptyLevels(vtkMultiBlockDataSet* levels) const
{
  if (!levels)
  {
    return;
  }
  levels->Initialize();
  std::vector<int> counts = this->NestedVertexCounts;
  if (counts.empty() || !sdfcage::sortNestedCounts(counts).empty())
  {
    return;
  }
  levels->SetNumberOfBlocks(static_cast<unsigned int>(counts.size()));
  for (std::size_t k = 0; k < counts.size(); ++k)
  {
    vtkNew<vtkPolyData> block;
    AddFieldValue<vtkStringArray>(block->GetFieldData(), "Status", std::string("NotBuilt"));
    const unsigned int b = static_cast<unsigned int>(k);
    levels->SetBlock(b, block);
    levels->GetMetaData(b)->Set(vtkCompositeDataSet::NAME(), ("cage_" + std::to_string(counts[k])).c_str());
  }
}

//------------------------------------------------------------------------------
// Nested cages: the levels on port 3, the finest level's run on ports 0-2 and in the getters.
int vtkSDFCageFilter::ExecuteNested(const sdfcage::PolygonMesh& mesh, vtkPolyData* cage, vtkPolyData* envelope,
  vtkImageData* field, vtkMultiBlockDataSet* levels)
{
  const sdfcage::CageOptions options = CageOptionsOf(this);
  FilterProgress progress(this);
  this->UpdateProgress(0.0);
  const sdfcage::NestedCageResult nested =
    sdfcage::generateNestedCages(mesh, this->NestedVertexCounts, options, &progress);
  if (!nested.Levels.empty())
  {
    this->Internals->Results = sdfcage::cageResults(nested.Levels[0].Result);
  }
  this->StatusString = StatusIdentifier(nested.State);
  this->LastErrorMessage = nested.Message;

  // the levels that were built, each with its results
  for (std::size_t k = 0; k < nested.Levels.size(); ++k)
  {
    const sdfcage::NestedLevel& level = nested.Levels[k];
    if (level.Result.Cage.empty())
    {
      continue; // level 0's failure: its block stays "NotBuilt"
    }
    vtkPolyData* block = vtkPolyData::SafeDownCast(levels->GetBlock(static_cast<unsigned int>(k)));
    ToPolyData(level.Result.Cage, level.Result.CageDistanceToInput, block);
    vtkFieldData* fd = block->GetFieldData();
    fd->Initialize();
    AddResultArrays(fd, sdfcage::cageResults(level.Result));
    AddResultArrays(fd, sdfcage::nestedLevelResults(level, static_cast<int>(k)));
    AddFieldValue<vtkStringArray>(fd, "Status", StatusIdentifier(level.Result.State));
    std::ostringstream prefix;
    prefix << "nested level " << k << " (" << level.TargetNumberOfVertices << " vertices): ";
    this->WarnAbout(level.Result, level.TargetNumberOfVertices, prefix.str());
  }

  const bool finestBuilt = !nested.Levels.empty() && !nested.Levels[0].Result.Cage.empty();
  if (finestBuilt)
  {
    const sdfcage::CageResult& r0 = nested.Levels[0].Result;
    ToPolyData(r0.Cage, r0.CageDistanceToInput, cage);
    ToPolyData(r0.Envelope, r0.EnvelopeDistanceToInput, envelope);
    if (this->GenerateDistanceField)
    {
      ToImageData(r0.DistanceField, field, "SignedDistance");
      ToImageData(r0.ModifiedDistanceField, field, "ModifiedSignedDistance");
    }
  }
  switch (nested.State)
  {
    case sdfcage::Status::Ok:
      this->PublishResults(cage);
      this->UpdateProgress(1.0);
      return 1;
    case sdfcage::Status::EmptyInput:
    case sdfcage::Status::Cancelled:
      // not errors; a cancel keeps the finished levels (each verified)
      this->PublishResults(cage);
      return 1;
    default:
      break;
  }
  if (!finestBuilt)
  {
    // the input itself could not be caged: exactly what a single run reports
    if (!nested.Levels.empty() && nested.Levels[0].Result.State == sdfcage::Status::VerificationFailed)
    {
      const sdfcage::CageResult& r0 = nested.Levels[0].Result;
      ToPolyData(r0.Envelope, r0.EnvelopeDistanceToInput, envelope);
    }
    return this->Fail(this->StatusString, "Cage generation failed: " + OrNoReason(nested.Message), cage);
  }
  // a coarser level failed: the finer ones are kept on the outputs, and the error says which
  vtkErrorMacro(<< "Nested cages: " << OrNoReason(nested.Message));
  this->PublishResults(cage);
  return 0;
}

//------------------------------------------------------------------------------
// No input, or nothing that could be a surface: empty input is not an error, points and lines
// without polygons are.
int vtkSDFCageFilter::RejectInput(vtkPolyData* input, vtkPolyData* cage)
{
  if (!input || input->GetNumberOfPoints() == 0 || input->GetNumberOfCells() == 0)
  {
    this->StatusString = StatusIdentifier(sdfcage::Status::EmptyInput);
    this->PublishResults(cage);
    return 1;
  }
  std::ostringstream msg;
  msg << "The input has " << input->GetNumberOfVerts() << " vertex and " << input->GetNumberOfLines()
      << " line cells but no polygons: a surface mesh is required (for a point cloud, "
         "reconstruct a surface first, e.g. with vtkSurfaceReconstructionFilter or ParaView's "
         "Delaunay 3D + Extract Surface).";
  return this->Fail(StatusIdentifier(sdfcage::Status::InvalidInput), msg.str(), cage);
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::Fail(const std::string& status, const std::string& message, vtkPolyData* cage)
{
  cage->Initialize();
  this->StatusString = status;
  this->LastErrorMessage = message;
  vtkErrorMacro(<< message);
  this->PublishResults(cage);
  return 0;
}

//------------------------------------------------------------------------------
// The outputs for each outcome of Core's run; the results are already stored.
int vtkSDFCageFilter::DeliverOutputs(
  const sdfcage::CageResult& result, vtkPolyData* cage, vtkPolyData* envelope, vtkImageData* field)
{
  switch (result.State)
  {
    case sdfcage::Status::Ok:
      break;
    case sdfcage::Status::EmptyInput:
      // e.g. every polygon was a vertex or line cell: nothing to enclose, not an error.
      this->PublishResults(cage);
      return 1;
    case sdfcage::Status::Cancelled:
      // Aborted by the user, no error. A cancel during the simplification leaves a verified,
      // valid cage (with more vertices than asked): output it; before that there is none.
      vtkDebugMacro("Execution cancelled: " << result.Message);
      if (!result.Cage.empty())
      {
        ToPolyData(result.Cage, result.CageDistanceToInput, cage);
        ToPolyData(result.Envelope, result.EnvelopeDistanceToInput, envelope);
      }
      this->PublishResults(cage);
      return 1;
    case sdfcage::Status::InvalidInput:
      return this->Fail(
        this->StatusString, result.Message.empty() ? result.Defects.errorMessage() : result.Message, cage);
    case sdfcage::Status::VerificationFailed:
      // Keep the unverified envelope for inspection; the cage stays empty.
      ToPolyData(result.Envelope, result.EnvelopeDistanceToInput, envelope);
      return this->Fail(this->StatusString, "The envelope could not be verified: " + OrNoReason(result.Message), cage);
    case sdfcage::Status::Failed:
    default:
      return this->Fail(this->StatusString, "Cage generation failed: " + OrNoReason(result.Message), cage);
  }

  this->WarnAbout(result, this->TargetNumberOfVertices);
  ToPolyData(result.Cage, result.CageDistanceToInput, cage);
  ToPolyData(result.Envelope, result.EnvelopeDistanceToInput, envelope);
  if (this->GenerateDistanceField)
  {
    ToImageData(result.DistanceField, field, "SignedDistance");
    ToImageData(result.ModifiedDistanceField, field, "ModifiedSignedDistance");
  }
  this->PublishResults(cage);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
// One warning for everything a successful run should tell: repairs of the input, an optimization
// that did not happen, a target not reached, fused parts.
void vtkSDFCageFilter::WarnAbout(const sdfcage::CageResult& result, int target, const std::string& prefix)
{
  std::vector<std::string> warnings = result.Defects.warnings();
  if (this->Optimize && !result.Optimized && result.State == sdfcage::Status::Ok)
  {
    warnings.push_back("the cage was not optimized: " + OrNoReason(result.Optimization.Message));
  }
  if (!result.TargetReached)
  {
    std::ostringstream msg;
    msg << "the cage has " << result.VerticesReached << " vertices, not the " << target
        << " asked for: " << OrNoReason(result.StopReason);
    warnings.push_back(msg.str());
  }
  if (!result.TopologyWarning.empty())
  {
    warnings.push_back(result.TopologyWarning);
  }
  if (!warnings.empty())
  {
    std::ostringstream msg;
    msg << prefix;
    for (std::size_t i = 0; i < warnings.size(); ++i)
    {
      msg << (i ? "; " : "") << warnings[i];
    }
    vtkWarningMacro(<< msg.str());
  }
}

//------------------------------------------------------------------------------
// The results as field data of the cage (for ParaView's Information panel and pvpython's Fetch),
// whatever the outcome.
void vtkSDFCageFilter::PublishResults(vtkPolyData* cage) const
{
  vtkFieldData* fd = cage->GetFieldData();
  AddResultArrays(fd, this->Internals->Results);
  AddFieldValue<vtkStringArray>(fd, "Status", this->StatusString);
  AddFieldValue<vtkStringArray>(fd, "LastErrorMessage", this->LastErrorMessage);
}

//------------------------------------------------------------------------------
void vtkSDFCageFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TargetNumberOfVertices: " << this->TargetNumberOfVertices << "\n";
  os << indent << "NestedVertexCounts:";
  for (int n : this->NestedVertexCounts)
  {
    os << " " << n;
  }
  os << (this->NestedVertexCounts.empty() ? " (none)\n" : "\n");
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "VoxelSize: " << this->VoxelSize << "\n";
  os << indent << "MinimumClearance: " << this->MinimumClearance << "\n";
  os << indent << "Adaptivity: " << this->Adaptivity << "\n";
  os << indent << "MaximumRefinements: " << this->MaximumRefinements << "\n";
  os << indent << "MaximumEnvelopeWidenings: " << this->MaximumEnvelopeWidenings << "\n";
  os << indent << "MaximumRelaxations: " << this->MaximumRelaxations << "\n";
  os << indent << "ChooseIsoValueFirst: " << (this->ChooseIsoValueFirst ? "On" : "Off") << "\n";
  os << indent << "MaximumTopologyRepairs: " << this->MaximumTopologyRepairs << "\n";
  os << indent << "RequireTopology: " << this->RequireTopology << "\n";
  os << indent << "CoarseFirst: " << this->CoarseFirst << "\n";
  os << indent << "MemoryLimit: " << this->MemoryLimit << " MiB (0 = automatic)\n";
  os << indent << "UseActivePoints: " << (this->UseActivePoints ? "On" : "Off") << "\n";
  os << indent << "ActiveRadius: " << this->ActiveRadius << "\n";
  os << indent << "GeodesicThreshold: " << this->GeodesicThreshold << "\n";
  os << indent << "AmplificationAlpha: " << this->AmplificationAlpha << "\n";
  os << indent << "AmplificationBeta: " << this->AmplificationBeta << "\n";
  os << indent << "SignMode: " << this->SignMode << "\n";
  os << indent << "GenerateDistanceField: " << (this->GenerateDistanceField ? "On" : "Off") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Optimize: " << (this->Optimize ? "On" : "Off") << "\n";
  os << indent << "Energy: " << (this->Energy == 1 ? "Spacing" : "MIPS") << "\n";
  os << indent << "TargetSpacing: " << this->TargetSpacing << "\n";
  os << indent << "BarrierWeight: " << this->BarrierWeight << "\n";
  os << indent << "BarrierDistance: " << this->BarrierDistance << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "EdgeFlips: " << (this->EdgeFlips ? "On" : "Off") << "\n";
  os << indent << "HausdorffFactor: " << this->HausdorffFactor << "\n";
  os << indent << "TargetMinimumAngle: " << this->TargetMinimumAngle << "\n";
  os << indent << "MaximumSweeps: " << this->MaximumSweeps << "\n";
  os << indent << "Status: " << this->StatusString << "\n";
  os << indent << "LastErrorMessage: " << this->LastErrorMessage << "\n";
  for (const sdfcage::ResultField& f : this->Internals->Results)
  {
    os << indent << f.Name << ": " << f.toString() << "\n";
  }
}

//------------------------------------------------------------------------------
double vtkSDFCageFilter::GetResultNumber(const char* name) const
{
  return ResultNumber(this->Internals->Results, name);
}

//------------------------------------------------------------------------------
long long vtkSDFCageFilter::ResultInteger(const char* name) const
{
  const sdfcage::ResultField* f = name ? sdfcage::findResult(this->Internals->Results, name) : nullptr;
  return f ? f->Integer : 0;
}

//------------------------------------------------------------------------------
const char* vtkSDFCageFilter::GetResultText(const char* name) const
{
  return ResultText(this->Internals->Results, name);
}

//------------------------------------------------------------------------------
int vtkSDFCageFilter::GetNumberOfResults() const
{
  return static_cast<int>(this->Internals->Results.size());
}

//------------------------------------------------------------------------------
const char* vtkSDFCageFilter::GetResultName(int index) const
{
  return ResultName(this->Internals->Results, index);
}
