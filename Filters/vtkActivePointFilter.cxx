/*=========================================================================

  Program:   SDFCage
  Module:    vtkActivePointFilter.cxx

=========================================================================*/
#include "vtkActivePointFilter.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include "Envelope/ActivePointAnalysis.h"
#include "SDFCageParallel.h"
#include "SDFCageVTKConversion.h"

#include <exception>
#include <new>

vtkStandardNewMacro(vtkActivePointFilter);

using namespace sdfcage_vtk;

//------------------------------------------------------------------------------
struct vtkActivePointFilter::vtkInternals
{
  sdfcage::ResultTable Results = sdfcage::activePointResults(sdfcage::ActivePointAnalysis());
};

//------------------------------------------------------------------------------
vtkActivePointFilter::vtkActivePointFilter()
{
  this->Internals = std::make_unique<vtkInternals>();
  const sdfcage::ActivePointOptions defaults;
  this->ActiveRadius = defaults.Radius;
  this->GeodesicThreshold = defaults.GeodesicThreshold;
  this->AmplificationAlpha = defaults.Alpha;
  this->AmplificationBeta = defaults.Beta;
  this->SetNumberOfOutputPorts(2);
}

//------------------------------------------------------------------------------
vtkActivePointFilter::~vtkActivePointFilter() = default;

//------------------------------------------------------------------------------
int vtkActivePointFilter::FillOutputPortInformation(int port, vtkInformation* info)
{
  if (port == 1)
  {
    info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkImageData");
    return 1;
  }
  return this->Superclass::FillOutputPortInformation(port, info);
}

//------------------------------------------------------------------------------
int vtkActivePointFilter::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  RequestSamePieceWithoutGhosts(inputVector, this->GetNumberOfInputPorts(), outputVector, request);
  return 1;
}

//------------------------------------------------------------------------------
// On the whole input: directly in a serial run, on process 0 with the gathered pieces under MPI
// (the other processes adopt process 0's results).
int vtkActivePointFilter::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  WholeSurfaceRun run;
  run.ResultsPort = 0;
  run.ImagePorts = { 1 };
  return RunOnWholeSurface(
    this, inputVector, outputVector, run,
    [this, outputVector](const std::vector<vtkPolyData*>& inputs) { return this->Execute(inputs[0], outputVector); },
    [this](vtkFieldData* fd) {
      this->Internals->Results = sdfcage::activePointResults(sdfcage::ActivePointAnalysis());
      ReadResultArrays(fd, this->Internals->Results);
      this->StatusString = FieldText(fd, "Status");
      this->LastErrorMessage = FieldText(fd, "LastErrorMessage");
    });
}

//------------------------------------------------------------------------------
int vtkActivePointFilter::Execute(vtkPolyData* input, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  vtkImageData* fields = vtkImageData::GetData(outputVector, 1);
  this->Internals->Results = sdfcage::activePointResults(sdfcage::ActivePointAnalysis());
  this->LastErrorMessage.clear();
  if (!output || !fields)
  {
    vtkErrorMacro(<< "Missing output.");
    return 0;
  }
  output->Initialize();
  fields->Initialize();

  auto publish = [&]() {
    vtkFieldData* fd = output->GetFieldData();
    AddResultArrays(fd, this->Internals->Results);
    AddFieldValue<vtkStringArray>(fd, "Status", this->StatusString);
    AddFieldValue<vtkStringArray>(fd, "LastErrorMessage", this->LastErrorMessage);
  };
  auto fail = [&](sdfcage::Status status, const std::string& message) {
    output->Initialize();
    fields->Initialize();
    this->StatusString = StatusIdentifier(status);
    this->LastErrorMessage = message;
    vtkErrorMacro(<< message);
    publish();
    return 0;
  };

  if (!input || input->GetNumberOfPoints() == 0 || input->GetNumberOfCells() == 0)
  {
    this->StatusString = StatusIdentifier(sdfcage::Status::EmptyInput);
    publish();
    return 1;
  }

  try
  {
    sdfcage::PolygonMesh mesh;
    ToPolygonMesh(input, mesh);
    sdfcage::ActivePointAnalysisOptions options;
    options.ActivePoints.Radius = this->ActiveRadius;
    options.ActivePoints.GeodesicThreshold = this->GeodesicThreshold;
    options.ActivePoints.Alpha = this->AmplificationAlpha;
    options.ActivePoints.Beta = this->AmplificationBeta;
    options.ActivePoints.GapRatio = this->GapRatio;
    options.GenerateFields = this->GenerateDistanceFields != 0;
    options.NumberOfThreads = this->NumberOfThreads;
    FilterProgress progress(this);
    const sdfcage::ActivePointAnalysis result = sdfcage::analyzeActivePoints(mesh, options, &progress);
    this->StatusString = StatusIdentifier(result.State);
    sdfcage::ActivePointAnalysis timeOnly; // the counts are published for a complete analysis only
    timeOnly.Seconds = result.Seconds;
    this->Internals->Results = sdfcage::activePointResults(result.State == sdfcage::Status::Ok ? result : timeOnly);
    switch (result.State)
    {
      case sdfcage::Status::Ok:
        break;
      case sdfcage::Status::EmptyInput:
      case sdfcage::Status::Cancelled:
        publish();
        return 1;
      default:
        return fail(result.State, result.Message.empty() ? std::string("active points failed") : result.Message);
    }
    for (const std::string& w : result.Defects.warnings())
    {
      vtkWarningMacro(<< w);
    }
    ToPolyData(result.Mesh, {}, output);
    const vtkIdType n = output->GetNumberOfPoints();
    vtkNew<vtkUnsignedCharArray> active;
    active->SetName("ActivePoint");
    active->SetNumberOfValues(n);
    vtkNew<vtkUnsignedCharArray> rule;
    rule->SetName("ActiveRule");
    rule->SetNumberOfValues(n);
    vtkNew<vtkDoubleArray> geodesic;
    geodesic->SetName("GeodesicDistanceToActive");
    geodesic->SetNumberOfValues(n);
    vtkNew<vtkDoubleArray> phi;
    phi->SetName("Amplification");
    phi->SetNumberOfValues(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      const std::size_t k = static_cast<std::size_t>(i);
      active->SetValue(i, result.Active[k]);
      rule->SetValue(i, result.ActiveRule[k]);
      geodesic->SetValue(i, result.GeodesicToActive[k]);
      phi->SetValue(i, result.Amplification[k]);
    }
    output->GetPointData()->SetScalars(active);
    output->GetPointData()->AddArray(rule);
    output->GetPointData()->AddArray(geodesic);
    output->GetPointData()->AddArray(phi);
    if (this->GenerateDistanceFields)
    {
      ToImageData(result.SignedDistance, fields, "SignedDistance");
      ToImageData(result.ModifiedSignedDistance, fields, "ModifiedSignedDistance");
    }
    publish();
    return 1;
  }
  catch (const std::bad_alloc&)
  {
    return fail(sdfcage::Status::Failed, "Out of memory while computing active points.");
  }
  catch (const std::exception& e)
  {
    return fail(sdfcage::Status::Failed, std::string("Active points failed: ") + e.what());
  }
  catch (...)
  {
    return fail(sdfcage::Status::Failed, "Active points failed with an unknown exception.");
  }
}

//------------------------------------------------------------------------------
void vtkActivePointFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ActiveRadius: " << this->ActiveRadius << "\n";
  os << indent << "GeodesicThreshold: " << this->GeodesicThreshold << "\n";
  os << indent << "AmplificationAlpha: " << this->AmplificationAlpha << "\n";
  os << indent << "AmplificationBeta: " << this->AmplificationBeta << "\n";
  os << indent << "GapRatio: " << this->GapRatio << "\n";
  os << indent << "GenerateDistanceFields: " << (this->GenerateDistanceFields ? "On" : "Off") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Status: " << this->StatusString << "\n";
  for (const sdfcage::ResultField& f : this->Internals->Results)
  {
    os << indent << f.Name << ": " << f.toString() << "\n";
  }
}

//------------------------------------------------------------------------------
double vtkActivePointFilter::GetResultNumber(const char* name) const
{
  return ResultNumber(this->Internals->Results, name);
}

int vtkActivePointFilter::GetNumberOfResults() const
{
  return static_cast<int>(this->Internals->Results.size());
}

const char* vtkActivePointFilter::GetResultName(int index) const
{
  return ResultName(this->Internals->Results, index);
}
