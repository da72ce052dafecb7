// SDFCage — tests of vtkSDFCageFilter: closed enclosing output, results, errors, empty input,
// abort, distance field, parameters, real meshes.
#include "SDFCageTestUtilities.h"

#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkOFFReader.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkActivePointFilter.h"
#include "vtkSDFCageFilter.h"
#include "vtkUnsignedCharArray.h"
#include "vtkSphereSource.h"
#include "vtkStringArray.h"
#include "vtkTriangleFilter.h"

#include "Pipeline/CageGenerator.h" // Core: the default options the filter must mirror
#include "Envelope/ActivePointAnalysis.h"
#include "Pipeline/Results.h" // Core: the results table every result must travel by
#include "vtkIdTypeArray.h"
#include "Mesh/Shapes.h" // Core: the built-in test shape

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

namespace sdfcage_test
{
namespace
{

vtkSmartPointer<vtkPolyData> FromTriangleMesh(const sdfcage::TriangleMesh& mesh)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (const sdfcage::Vec3& p : mesh.Points)
  {
    points->InsertNextPoint(p[0], p[1], p[2]);
  }
  vtkNew<vtkCellArray> polys;
  for (const sdfcage::Triangle& t : mesh.Triangles)
  {
    const vtkIdType ids[3] = { t[0], t[1], t[2] };
    polys->InsertNextCell(3, ids);
  }
  auto result = vtkSmartPointer<vtkPolyData>::New();
  result->SetPoints(points);
  result->SetPolys(polys);
  return result;
}

vtkSmartPointer<vtkPolyData> MakeCenteredSphere(const double center[3], double radius, int res)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(center[0], center[1], center[2]);
  sphere->SetRadius(radius);
  sphere->SetThetaResolution(res);
  sphere->SetPhiResolution(res);
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(sphere->GetOutputPort());
  triangles->Update();
  auto result = vtkSmartPointer<vtkPolyData>::New();
  result->ShallowCopy(triangles->GetOutput());
  return result;
}

std::string FieldString(vtkPolyData* data, const char* name)
{
  auto* array = vtkStringArray::SafeDownCast(data->GetFieldData()->GetAbstractArray(name));
  return array && array->GetNumberOfValues() > 0 ? array->GetValue(0) : std::string("<missing>");
}

double FieldNumber(vtkPolyData* data, const char* name)
{
  vtkDataArray* array = data->GetFieldData()->GetArray(name);
  return array && array->GetNumberOfTuples() > 0 ? array->GetTuple1(0) : vtkMath::Nan();
}

bool IsEmpty(vtkDataObject* data)
{
  if (auto* pd = vtkPolyData::SafeDownCast(data))
  {
    return pd->GetNumberOfPoints() == 0 && pd->GetNumberOfCells() == 0;
  }
  if (auto* image = vtkImageData::SafeDownCast(data))
  {
    return image->GetNumberOfPoints() == 0;
  }
  return data == nullptr;
}

/// Every result of Core's table is in the cage's field data, as an array of its kind, with the
/// value of the filter's getter by name, and the filter lists the table in its order: a result
/// added to the table cannot be forgotten on the way out. Holds whatever the outcome.
void CheckResultsTable(Checker& c, vtkSDFCageFilter* filter)
{
  vtkPolyData* cage = filter->GetOutput(0);
  vtkFieldData* fd = cage->GetFieldData();
  const sdfcage::ResultTable table = sdfcage::cageResults(sdfcage::CageResult());
  c.Check(filter->GetNumberOfResults() == static_cast<int>(table.size()),
    "the filter has every result of the table (" + Str(table.size()) + ")");
  int missing = 0;
  for (std::size_t i = 0; i < table.size(); ++i)
  {
    const sdfcage::ResultField& f = table[i];
    const char* name = f.Name.c_str();
    if (std::string(filter->GetResultName(static_cast<int>(i))) != f.Name)
    {
      c.Check(false,
        "result " + Str(i) + " is " + f.Name + ", the filter says " + filter->GetResultName(static_cast<int>(i)));
    }
    vtkAbstractArray* array = fd->GetAbstractArray(name);
    if (!array || array->GetNumberOfTuples() != 1)
    {
      ++missing;
      c.Check(false, std::string("field data has one value of ") + name);
      continue;
    }
    switch (f.Type)
    {
      case sdfcage::ResultField::Kind::Text:
        c.Check(
          vtkStringArray::SafeDownCast(array) != nullptr && FieldString(cage, name) == filter->GetResultText(name),
          std::string("field data ") + name + " is the text of GetResultText");
        break;
      case sdfcage::ResultField::Kind::Flag:
        c.Check(
          vtkIntArray::SafeDownCast(array) != nullptr && (FieldNumber(cage, name) == 0 || FieldNumber(cage, name) == 1),
          std::string("field data ") + name + " is an int flag");
        break;
      case sdfcage::ResultField::Kind::Integer:
        c.Check(
          vtkIdTypeArray::SafeDownCast(array) != nullptr, std::string("field data ") + name + " is a vtkIdTypeArray");
        break;
      case sdfcage::ResultField::Kind::Real:
        c.Check(
          vtkDoubleArray::SafeDownCast(array) != nullptr, std::string("field data ") + name + " is a vtkDoubleArray");
        break;
    }
    if (f.Type != sdfcage::ResultField::Kind::Text && FieldNumber(cage, name) != filter->GetResultNumber(name))
    {
      c.Check(false,
        std::string("field data ") + name + " = " + Str(FieldNumber(cage, name)) + ", GetResultNumber gives " +
          Str(filter->GetResultNumber(name)));
    }
  }
  c.Check(missing == 0, "every result of the table is in the field data");
  // the old getters read the same table
  c.Check(filter->GetMeasuredClearance() == filter->GetResultNumber("MeasuredClearance"),
    "GetMeasuredClearance = the table's");
  c.Check(
    filter->GetVerticesReached() == filter->GetResultNumber("VerticesReached"), "GetVerticesReached = the table's");
  c.Check(filter->GetEnclosureVerified() == (filter->GetResultNumber("EnclosureVerified") == 1),
    "GetEnclosureVerified = the table's");
  c.Check(filter->GetNumberOfActivePoints() == filter->GetResultNumber("NumberOfActivePoints"),
    "GetNumberOfActivePoints = the table's");
  c.Check(filter->GetTotalTime() == filter->GetResultNumber("TotalTime"), "GetTotalTime = the table's");
  c.Check(std::string(filter->GetStopReason()) == filter->GetResultText("StopReason"), "GetStopReason = the table's");
  c.Check(std::string(filter->GetResultName(-1)).empty() && filter->GetResultNumber("NoSuchResult") == 0 &&
      std::string(filter->GetResultText("NoSuchResult")).empty(),
    "unknown names and indices give nothing");
}

/// Everything a successful run must satisfy: a closed cage and envelope around the input, with
/// DistanceToInput no smaller than the measured clearance, and consistent results.
void CheckSuccessfulRun(Checker& c, vtkSDFCageFilter* filter, vtkPolyData* input)
{
  c.Check(std::string(filter->GetStatusString()) == "Ok",
    std::string("status Ok, got ") + filter->GetStatusString() + ": " + filter->GetLastErrorMessage());
  c.Check(filter->GetEnclosureVerified(), "EnclosureVerified");
  c.Check(filter->GetMeasuredClearance() > 0, "MeasuredClearance > 0");
  c.Check(filter->GetMeasuredClearanceRelative() > 0, "MeasuredClearanceRelative > 0");
  const double delta = filter->GetMinimumClearance() > 0 ? filter->GetMinimumClearance() : filter->GetIsoValue() / 4;
  c.Check(filter->GetMeasuredClearanceRelative() >= delta * (1 - 1e-9),
    "relative clearance " + Str(filter->GetMeasuredClearanceRelative()) + " >= delta " + Str(delta));
  c.Check(filter->GetVoxelSizeUsed() > 0, "VoxelSizeUsed > 0");
  c.Check(filter->GetTotalTime() > 0, "TotalTime > 0");
  c.Check(filter->GetTotalTime() + 1e-9 >= filter->GetDistanceFieldTime(), "TotalTime >= DistanceFieldTime");
  c.Check(std::string(filter->GetLastErrorMessage()).empty(), "no error message");

  double inBounds[6];
  input->GetBounds(inBounds);
  for (int port = 0; port < 2; ++port)
  {
    const std::string name = port == 0 ? "cage" : "envelope";
    vtkPolyData* out = filter->GetOutput(port);
    if (!c.Check(out && out->GetNumberOfPoints() > 0 && out->GetNumberOfPolys() > 0, name + " is not empty"))
    {
      continue;
    }
    c.Check(CountOpenEdges(out) == 0,
      name +
        " is closed and manifold (no boundary or "
        "non-manifold edges)");
    double outBounds[6];
    out->GetBounds(outBounds);
    for (int a = 0; a < 3; ++a)
    {
      c.Check(outBounds[2 * a] < inBounds[2 * a] && outBounds[2 * a + 1] > inBounds[2 * a + 1],
        name + " bounds strictly contain the input's on axis " + Str(a));
    }
    auto* distance = vtkDoubleArray::SafeDownCast(out->GetPointData()->GetArray("DistanceToInput"));
    if (c.Check(distance != nullptr, name + " has a double array DistanceToInput") &&
      c.Check(
        distance->GetNumberOfTuples() == out->GetNumberOfPoints(), name + " DistanceToInput has one value per point"))
    {
      double range[2];
      distance->GetRange(range);
      // MeasuredClearance is the cage's; the envelope only promises delta (in input units:
      // delta x MeasuredClearance / MeasuredClearanceRelative).
      const double bound = port == 0 ? filter->GetMeasuredClearance()
                                     : delta * filter->GetMeasuredClearance() / filter->GetMeasuredClearanceRelative();
      c.Check(range[0] >= bound * (1 - 1e-9), name + " min DistanceToInput " + Str(range[0]) + " >= " + Str(bound));
    }
  }
  vtkPolyData* cageOut = filter->GetOutput(0);
  c.Check(filter->GetVerticesReached() == cageOut->GetNumberOfPoints(),
    "VerticesReached = cage points (" + Str(filter->GetVerticesReached()) + ")");
  if (filter->GetTargetNumberOfVertices() > 0)
  {
    c.Check(filter->GetTargetReached() == (cageOut->GetNumberOfPoints() == filter->GetTargetNumberOfVertices()),
      "TargetReached agrees with the cage's vertex count");
    c.Check(cageOut->GetNumberOfPoints() >= filter->GetTargetNumberOfVertices(),
      "the cage has at least TargetNumberOfVertices vertices");
    c.Check(filter->GetTargetReached() == std::string(filter->GetStopReason()).empty(),
      "a StopReason is given exactly when the target was missed");
  }

  vtkPolyData* cage = filter->GetOutput(0);
  c.Check(FieldString(cage, "Status") == "Ok", "field data Status = Ok");
  c.Check(FieldNumber(cage, "EnclosureVerified") == 1, "field data EnclosureVerified = 1");
  c.Check(FieldNumber(cage, "MeasuredClearance") == filter->GetMeasuredClearance(),
    "field data MeasuredClearance equals the getter");
  c.Check(
    FieldNumber(cage, "EnvelopeGenus") == filter->GetEnvelopeGenus(), "field data EnvelopeGenus equals the getter");
  for (const char* name : { "ValidationTime", "DistanceFieldTime", "IsosurfaceTime", "VerificationTime",
         "SimplificationTime", "CageVerificationTime", "TotalTime", "VerticesReached", "TargetReached",
         "MeasuredClearanceRelative", "RemovedPockets", "EnvelopeComponents", "VoxelSizeUsed", "InputWasFlipped" })
  {
    c.Check(!std::isnan(FieldNumber(cage, name)), std::string("field data has ") + name);
  }
  if (!filter->GetGenerateDistanceField())
  {
    c.Check(IsEmpty(filter->GetOutputDataObject(2)), "no distance field unless requested");
  }
  CheckResultsTable(c, filter);
}

void PrintResults(vtkSDFCageFilter* filter)
{
  vtkPolyData* cage = filter->GetOutput(0);
  std::cout << "  status " << filter->GetStatusString() << ", cage " << cage->GetNumberOfPoints() << " points / "
            << cage->GetNumberOfPolys() << " triangles (target " << filter->GetTargetNumberOfVertices()
            << (filter->GetTargetReached() ? " reached" : " missed: ") << filter->GetStopReason() << "), envelope "
            << filter->GetOutput(1)->GetNumberOfPoints() << " points, genus " << filter->GetEnvelopeGenus()
            << ", pockets removed " << filter->GetRemovedPockets() << ", clearance " << filter->GetMeasuredClearance()
            << " (relative " << filter->GetMeasuredClearanceRelative() << "), voxel " << filter->GetVoxelSizeUsed()
            << ", time " << filter->GetTotalTime() << " s (simplify " << filter->GetSimplificationTime() << " s)\n";
}

} // namespace

//------------------------------------------------------------------------------
int TestSphere(const Context&)
{
  Checker c("Sphere");
  // Off-origin and not unit-sized, so that the mapping back to input coordinates is exercised.
  const double center[3] = { 10.0, -3.0, 2.0 };
  const double radius = 2.5;
  vtkSmartPointer<vtkPolyData> input = MakeCenteredSphere(center, radius, 32);

  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetInputData(input);
  filter->Update();
  PrintResults(filter);

  c.Check(
    messages->Errors.empty(), "no errors" + (messages->Errors.empty() ? std::string() : ": " + messages->Errors[0]));
  c.Check(messages->Warnings.empty(), "no warnings for a clean triangle sphere");
  CheckSuccessfulRun(c, filter, input);
  c.Check(!filter->GetInputWasFlipped(), "an outward sphere is not flipped");
  c.Check(filter->GetEnvelopeGenus() == 0, "the envelope of a sphere has genus 0");

  // The normalization maps the sphere onto the unit sphere: input lengths are radius x relative.
  c.Check(std::abs(filter->GetMeasuredClearance() - filter->GetMeasuredClearanceRelative() * radius) <=
      1e-6 * filter->GetMeasuredClearance(),
    "MeasuredClearance = MeasuredClearanceRelative x radius");

  // DistanceToInput is in input units: for a faceted sphere it is close to |p - center| - R.
  vtkPolyData* cage = filter->GetOutput(0);
  auto* distance = vtkDoubleArray::SafeDownCast(cage->GetPointData()->GetArray("DistanceToInput"));
  if (distance)
  {
    double worst = 0;
    for (vtkIdType i = 0; i < cage->GetNumberOfPoints(); ++i)
    {
      double p[3];
      cage->GetPoint(i, p);
      const double expected = std::sqrt(vtkMath::Distance2BetweenPoints(p, center)) - radius;
      worst = std::max(worst, std::abs(distance->GetValue(i) - expected));
    }
    // facets deviate from the true sphere by < 1% of R at this resolution
    c.Check(worst < 0.01 * radius, "DistanceToInput matches |p - center| - R within facet error, worst " + Str(worst));
  }
  auto* envelopeDistance =
    vtkDoubleArray::SafeDownCast(filter->GetOutput(1)->GetPointData()->GetArray("DistanceToInput"));
  if (envelopeDistance)
  {
    double range[2];
    envelopeDistance->GetRange(range);
    c.Check(range[1] < 0.05 * radius, "the envelope hugs the sphere (max distance " + Str(range[1]) + " < 5% of R)");
  }

  // Same input, second update without changes: no re-execution, same result.
  const vtkIdType points = cage->GetNumberOfPoints();
  filter->Update();
  c.Check(filter->GetOutput(0)->GetNumberOfPoints() == points, "stable on re-update");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestBuiltinShape(const Context&)
{
  Checker c("BuiltinShape");
  vtkSmartPointer<vtkPolyData> input = FromTriangleMesh(sdfcage::makeBuiltinShape());
  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetInputData(input);
  filter->Update();
  PrintResults(filter);
  c.Check(
    messages->Errors.empty(), "no errors" + (messages->Errors.empty() ? std::string() : ": " + messages->Errors[0]));
  CheckSuccessfulRun(c, filter, input);
  // A torus beside a sphere: the torus hole is far wider than the offset, so genus >= 1.
  c.Check(filter->GetEnvelopeGenus() >= 1, "the torus' hole survives (genus >= 1)");

  // MaximumRelaxations (default = Core's): at 17 vertices the simplification stalls (at 82) and
  // is relaxed and goes on, to fewer vertices than without relaxation; the field data says so
  c.Check(filter->GetMaximumRelaxations() == sdfcage::CageOptions().MaximumRelaxations,
    "MaximumRelaxations default = Core's");
  vtkIdType reached[2] = { 0, 0 };
  for (const int relaxations : { 4, 0 })
  {
    vtkNew<vtkSDFCageFilter> coarse;
    coarse->SetInputData(input);
    coarse->SetTargetNumberOfVertices(17);
    coarse->SetMaximumRelaxations(relaxations);
    coarse->Update();
    vtkPolyData* cage = coarse->GetOutput(0);
    reached[relaxations ? 0 : 1] = cage->GetNumberOfPoints();
    const double rounds = FieldNumber(cage, "Relaxations");
    const double stalled = FieldNumber(cage, "VerticesBeforeRelaxation");
    std::cout << "  MaximumRelaxations " << relaxations << ": " << cage->GetNumberOfPoints() << " vertices, " << rounds
              << " relaxation(s), stalled at " << stalled << "\n";
    c.Check(FieldNumber(cage, "EnclosureVerified") == 1, "17 vertices: the cage is verified");
    if (relaxations)
    {
      c.Check(rounds >= 1 && stalled > 17, "17 vertices: relaxed after the simplification stalled");
      c.Check(FieldNumber(cage, "RelaxationTime") > 0, "17 vertices: RelaxationTime in the field data");
    }
    else
      c.Check(rounds == 0 && stalled == 0, "MaximumRelaxations 0: no relaxation");
  }
  c.Check(reached[0] < reached[1], "the relaxed cage is closer to the target than the one without relaxation");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestOpenInput(const Context&)
{
  Checker c("OpenInput");

  // A sphere with one triangle removed: 3 boundary edges.
  vtkSmartPointer<vtkPolyData> sphere = MakeSphere(1.0, 16);
  vtkNew<vtkCellArray> polys;
  {
    vtkCellArray* all = sphere->GetPolys();
    vtkIdType npts = 0;
    const vtkIdType* pts = nullptr;
    for (vtkIdType cell = 1; cell < all->GetNumberOfCells(); ++cell) // skip cell 0
    {
      all->GetCellAtId(cell, npts, pts);
      polys->InsertNextCell(npts, pts);
    }
  }
  vtkNew<vtkPolyData> holed;
  holed->SetPoints(sphere->GetPoints());
  holed->SetPolys(polys);

  // Once refused, now caged: the inside comes from the winding number, the hole is reported.
  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetTargetNumberOfVertices(80);
  filter->SetInputData(holed);
  filter->Update();
  bool warned = false;
  for (const std::string& w : messages->Warnings)
  {
    std::cout << "  warning: " << w << "\n";
    warned = warned || w.find("not a closed") != std::string::npos;
  }
  c.Check(messages->Errors.empty(), "no error for an open sphere");
  c.Check(warned, "a warning says the input is not closed");
  c.Check(std::string(filter->GetStatusString()) == "Ok", "status Ok");
  c.Check(filter->GetEnclosureVerified(), "enclosure verified");
  c.Check(filter->GetOutput(0)->GetNumberOfPoints() == 80, "exactly 80 cage vertices");
  c.Check(std::string(filter->GetResultText("SignMode")) == "winding", "SignMode winding");
  c.Check(filter->GetResultNumber("InputBoundaryEdges") == 3, "3 boundary edges reported");
  c.Check(filter->GetResultNumber("InputClosed") == 0, "InputClosed 0");
  c.Check(FieldString(filter->GetOutput(0), "SignMode") == "winding", "field data SignMode = winding");
  c.Check(CountOpenEdges(filter->GetOutput(0)) == 0, "the cage is closed");

  // A single triangle: caged too (wrapped on both sides).
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(0, 0, 0);
  points->InsertNextPoint(1, 0, 0);
  points->InsertNextPoint(0, 1, 0);
  vtkNew<vtkCellArray> one;
  const vtkIdType tri[3] = { 0, 1, 2 };
  one->InsertNextCell(3, tri);
  vtkNew<vtkPolyData> triangle;
  triangle->SetPoints(points);
  triangle->SetPolys(one);
  messages->Clear();
  filter->SetTargetNumberOfVertices(30);
  filter->SetInputData(triangle);
  filter->Update();
  c.Check(messages->Errors.empty(), "no error for a single triangle");
  c.Check(filter->GetEnclosureVerified(), "a single triangle gets a verified cage");
  c.Check(filter->GetOutput(0)->GetNumberOfPoints() == 30, "of exactly 30 vertices");

  // Forced flood fill on the open sphere: the user's choice is honoured and reported.
  messages->Clear();
  filter->SetSignModeToUnsigned();
  filter->SetTargetNumberOfVertices(80);
  filter->SetInputData(holed);
  filter->Update();
  c.Check(std::string(filter->GetResultText("SignMode")) == "unsigned", "forced unsigned is used");
  c.Check(std::string(filter->GetResultText("SignReason")) == "requested", "and reported as requested");
  c.Check(filter->GetEnclosureVerified(), "unsigned: enclosure verified");
  filter->SetSignModeToAuto();

  // The filter recovers: a closed input afterwards succeeds without errors.
  messages->Clear();
  vtkSmartPointer<vtkPolyData> closed = MakeSphere(1.0, 16);
  filter->SetInputData(closed);
  filter->SetIsoValue(0.04); // coarse and fast: only recovery is tested here
  filter->Update();
  c.Check(messages->Errors.empty(), "no error after fixing the input");
  c.Check(std::string(filter->GetStatusString()) == "Ok", "status Ok after fixing the input");
  c.Check(filter->GetOutput(0)->GetNumberOfPoints() > 0, "non-empty cage after fixing the input");
  return c.Result();
}

//------------------------------------------------------------------------------
// ChooseIsoValueFirst reaches Core: 8 open cubes (8 parts, more than a 20-vertex target can carry
// apart) with IsoValue 0.04 and one widening. On (the default, Core's), the isovalue 0.04 is
// probed on a coarse grid and not built: one envelope, at 0.08. Off, 0.04 and then 0.08 are built.
int TestChooseIsoValueFirst(const Context&)
{
  Checker c("ChooseIsoValueFirst");
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> polys;
  // the cube [0, 0.8]^3 without its top face, outward triangles
  const double corner[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 },
    { 1, 1, 1 }, { 0, 1, 1 } };
  const vtkIdType sides[10][3] = { { 0, 2, 1 }, { 0, 3, 2 }, { 0, 1, 5 }, { 0, 5, 4 }, { 2, 3, 7 }, { 2, 7, 6 },
    { 1, 2, 6 }, { 1, 6, 5 }, { 3, 0, 4 }, { 3, 4, 7 } };
  for (int cell = 0; cell < 8; ++cell)
  {
    const vtkIdType first = points->GetNumberOfPoints();
    for (const auto& p : corner)
    {
      points->InsertNextPoint((cell & 1) + 0.8 * p[0], ((cell >> 1) & 1) + 0.8 * p[1], (cell >> 2) + 0.8 * p[2]);
    }
    for (const auto& t : sides)
    {
      const vtkIdType ids[3] = { first + t[0], first + t[1], first + t[2] };
      polys->InsertNextCell(3, ids);
    }
  }
  vtkNew<vtkPolyData> cubes;
  cubes->SetPoints(points);
  cubes->SetPolys(polys);

  const sdfcage::CageOptions core;
  double isoValueUsed[2] = { 0, 0 };
  for (const int on : { 1, 0 })
  {
    vtkNew<vtkSDFCageFilter> filter;
    if (on)
    {
      c.Check((filter->GetChooseIsoValueFirst() != 0) == core.ChooseIsoValueFirst, "ChooseIsoValueFirst default = Core's");
      c.Check(filter->GetChooseIsoValueFirst() != 0, "ChooseIsoValueFirst on by default");
    }
    else
    {
      filter->ChooseIsoValueFirstOff();
    }
    filter->SetInputData(cubes);
    filter->SetTargetNumberOfVertices(20);
    filter->SetIsoValue(0.04);
    filter->SetMaximumEnvelopeWidenings(1);
    filter->Update();
    const std::string label = on ? "on: " : "off: ";
    std::cout << "  " << label << filter->GetResultText("WideningLog") << "\n";
    c.Check(std::string(filter->GetStatusString()) == "Ok", label + "status Ok");
    c.Check(filter->GetEnclosureVerified(), label + "enclosure verified");
    c.Check(filter->GetResultNumber("InputComponents") == 8, label + "8 input parts");
    c.Check(filter->GetResultNumber("EnvelopeProbes") == (on ? 1 : 0),
      label + "EnvelopeProbes " + Str(filter->GetResultNumber("EnvelopeProbes")));
    c.Check(filter->GetResultNumber("IsoValuesSkipped") == (on ? 1 : 0),
      label + "IsoValuesSkipped " + Str(filter->GetResultNumber("IsoValuesSkipped")));
    c.Check(filter->GetResultNumber("EnvelopeAttempts") == (on ? 1 : 2),
      label + "EnvelopeAttempts " + Str(filter->GetResultNumber("EnvelopeAttempts")));
    c.Check((std::string(filter->GetResultText("WideningLog")).find("probed") != std::string::npos) == (on != 0),
      label + "the widening log lists a probe only when on");
    c.Check(FieldNumber(filter->GetOutput(0), "EnvelopeProbes") == (on ? 1 : 0), label + "field data EnvelopeProbes");
    isoValueUsed[on] = filter->GetResultNumber("IsoValueUsed");
  }
  c.Check(std::abs(isoValueUsed[0] - 0.08) < 1e-12 && std::abs(isoValueUsed[1] - 0.08) < 1e-12,
    "both cages come from the isovalue 0.08 (" + Str(isoValueUsed[1]) + ", " + Str(isoValueUsed[0]) + ")");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestNoSurface(const Context&)
{
  Checker c("NoSurface");
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> verts;
  for (int i = 0; i < 10; ++i)
  {
    const vtkIdType id = points->InsertNextPoint(i, 0.5 * i, 0);
    verts->InsertNextCell(1, &id);
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);
  cloud->SetVerts(verts);

  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetInputData(cloud);
  filter->Update();
  std::cout << "  error: " << (messages->Errors.empty() ? "(none)" : messages->Errors[0]) << "\n";
  c.Check(messages->ErrorContains("no polygons"), "a point cloud is rejected (no polygons)");
  c.Check(IsEmpty(filter->GetOutput(0)), "empty cage");
  c.Check(FieldString(filter->GetOutput(0), "Status") == "InvalidInput", "field data Status InvalidInput");
  CheckResultsTable(c, filter);

  // A cell array whose offsets do not fit its connectivity (a damaged file read by a reader that
  // does not check them): refused as corrupt, never iterated past the connectivity's end.
  vtkNew<vtkPoints> tetPoints;
  tetPoints->InsertNextPoint(0, 0, 0);
  tetPoints->InsertNextPoint(1, 0, 0);
  tetPoints->InsertNextPoint(0, 1, 0);
  tetPoints->InsertNextPoint(0, 0, 1);
  vtkNew<vtkIdTypeArray> offsets;
  for (vtkIdType o : { 0, 3, 900, 9, 12 })
  {
    offsets->InsertNextValue(o);
  }
  vtkNew<vtkIdTypeArray> connectivity;
  for (vtkIdType id : { 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3 })
  {
    connectivity->InsertNextValue(id);
  }
  vtkNew<vtkCellArray> damaged;
  damaged->SetData(offsets, connectivity);
  vtkNew<vtkPolyData> tetrahedron;
  tetrahedron->SetPoints(tetPoints);
  tetrahedron->SetPolys(damaged);
  messages->Errors.clear();
  filter->SetInputData(tetrahedron);
  filter->Update();
  std::cout << "  error: " << (messages->Errors.empty() ? "(none)" : messages->Errors[0]) << "\n";
  c.Check(messages->ErrorContains("do not exist"), "damaged offsets are refused as a corrupt input");
  c.Check(IsEmpty(filter->GetOutput(0)), "empty cage for damaged offsets");
  c.Check(std::string(filter->GetStatusString()) == "InvalidInput", "status InvalidInput for damaged offsets");

  // The same tetrahedron with sound offsets is caged (the check refuses only what is damaged).
  offsets->SetValue(2, 6);
  offsets->Modified();
  tetrahedron->Modified();
  messages->Errors.clear();
  filter->SetTargetNumberOfVertices(20);
  filter->Update();
  c.Check(messages->Errors.empty(), "sound offsets: no error");
  c.Check(filter->GetOutput(0)->GetNumberOfPoints() == 20, "sound offsets: a 20-vertex cage");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestEmptyInput(const Context&)
{
  Checker c("EmptyInput");
  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());

  vtkNew<vtkPolyData> empty;
  filter->SetInputData(empty);
  filter->Update();
  c.Check(messages->Errors.empty() && messages->Warnings.empty(), "no error or warning");
  c.Check(std::string(filter->GetStatusString()) == "EmptyInput", "status EmptyInput");
  CheckResultsTable(c, filter); // a run that did not happen still publishes every result
  c.Check(std::string(filter->GetResultText("SignMode")).empty(), "no inside rule decided");
  for (int port = 0; port < 3; ++port)
  {
    c.Check(IsEmpty(filter->GetOutputDataObject(port)), "output " + Str(port) + " is empty");
  }

  // Points but no cells is empty too.
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(0, 0, 0);
  vtkNew<vtkPolyData> pointsOnly;
  pointsOnly->SetPoints(points);
  filter->SetInputData(pointsOnly);
  filter->Update();
  c.Check(messages->Errors.empty(), "no error for points without cells");
  c.Check(IsEmpty(filter->GetOutput(0)), "empty cage for points without cells");
  return c.Result();
}

//------------------------------------------------------------------------------
namespace
{
/// Aborts the filter once its progress reaches `Threshold`.
class AbortAt : public vtkCommand
{
public:
  static AbortAt* New() { return new AbortAt; }
  void Execute(vtkObject* caller, unsigned long, void* callData) override
  {
    const double progress = callData ? *static_cast<double*>(callData) : 0.0;
    ++this->Events;
    if (progress >= this->Threshold && !this->Fired)
    {
      this->Fired = true;
      this->FiredAt = std::chrono::steady_clock::now();
      vtkAlgorithm::SafeDownCast(caller)->SetAbortExecute(1);
    }
  }
  double Threshold = 0.0;
  bool Fired = false;
  int Events = 0;
  std::chrono::steady_clock::time_point FiredAt;
};
} // namespace

int TestAbort(const Context&)
{
  Checker c("Abort");
  // Dense enough that a run takes a while.
  vtkSmartPointer<vtkPolyData> input = MakeSphere(1.0, 160);
  using Clock = std::chrono::steady_clock;

  // Reference run.
  double fullSeconds = 0;
  {
    vtkNew<vtkSDFCageFilter> filter;
    vtkNew<AbortAt> progress; // never fires
    progress->Threshold = 2.0;
    filter->AddObserver(vtkCommand::ProgressEvent, progress);
    filter->SetInputData(input);
    const auto t0 = Clock::now();
    filter->Update();
    fullSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    std::cout << "  full run " << fullSeconds << " s, " << progress->Events << " progress events\n";
    c.Check(std::string(filter->GetStatusString()) == "Ok", "reference run succeeds");
    c.Check(progress->Events >= 3, "progress is reported during the run");
    // throttled: one per stage, per 1% and per 50 ms (so that an abort set by an observer answers
    // at once) at the most
    c.Check(
      progress->Events < 300 + fullSeconds / 0.05, "progress events are throttled (" + Str(progress->Events) + ")");
  }

  for (double threshold : { 0.0, 0.3, 0.6 })
  {
    vtkNew<vtkSDFCageFilter> filter;
    vtkNew<MessageRecorder> messages;
    messages->Watch(filter);
    messages->Watch(filter->GetExecutive());
    vtkNew<AbortAt> progress;
    progress->Threshold = threshold;
    filter->AddObserver(vtkCommand::ProgressEvent, progress);
    filter->SetInputData(input);
    filter->Update();
    const auto t1 = Clock::now();
    const std::string tag = "abort at " + Str(threshold) + ": ";
    if (!progress->Fired)
    {
      std::cout << "  " << tag << "progress never reached the threshold\n";
      continue;
    }
    const double afterAbort = std::chrono::duration<double>(t1 - progress->FiredAt).count();
    std::cout << "  " << tag << "status " << filter->GetStatusString() << ", returned " << afterAbort
              << " s after the abort request\n";
    c.Check(messages->Errors.empty(), tag + "no error");
    const std::string status = filter->GetStatusString();
    c.Check(status == "Cancelled" || status == "Ok", tag + "status Cancelled (or Ok)");
    vtkPolyData* cage = filter->GetOutput(0);
    if (IsEmpty(cage))
    {
      c.Check(status == "Cancelled", tag + "an empty cage only when cancelled");
      c.Check(IsEmpty(filter->GetOutput(1)), tag + "empty envelope with the empty cage");
    }
    else
    {
      // finished anyway, or cancelled during the simplification: a valid, verified cage
      std::cout << "  " << tag << "cage of " << cage->GetNumberOfPoints() << " points\n";
      c.Check(CountOpenEdges(cage) == 0, tag + "the cage output is closed");
      c.Check(filter->GetEnclosureVerified(), tag + "the cage output is verified");
      c.Check(cage->GetNumberOfPoints() >= filter->GetTargetNumberOfVertices(), tag + "no fewer vertices than asked");
    }
    // "Promptly": well before a full run would have finished.
    c.Check(afterAbort < 0.5 * fullSeconds + 0.25,
      tag + "returns promptly (" + Str(afterAbort) + " s vs full " + Str(fullSeconds) + " s)");

    // A cancelled filter runs normally next time (coarse grid: only the recovery matters).
    // VTK 9.1 clears the abort flag when the next execution starts; ParaView 5.11's VTK keeps it
    // set until it is cleared, so clear it explicitly (right for both).
    filter->RemoveObservers(vtkCommand::ProgressEvent);
    filter->SetAbortExecute(0);
    filter->SetIsoValue(0.04);
    filter->Update();
    c.Check(std::string(filter->GetStatusString()) == "Ok" && filter->GetOutput(0)->GetNumberOfPoints() > 0,
      tag + "the next update after a cancel succeeds");
    c.Check(messages->Errors.empty(), tag + "no error in the next update");
  }
  return c.Result();
}

//------------------------------------------------------------------------------
int TestDistanceField(const Context&)
{
  Checker c("DistanceField");
  const double center[3] = { 0.0, 0.0, 0.0 };
  const double radius = 2.0;
  vtkSmartPointer<vtkPolyData> input = MakeCenteredSphere(center, radius, 32);
  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetInputData(input);
  // A coarse grid keeps the dense image small (about 100^3 values instead of 400^3).
  filter->SetIsoValue(0.04);
  filter->GenerateDistanceFieldOn();
  filter->Update();
  c.Check(messages->Errors.empty(), "no errors");
  CheckSuccessfulRun(c, filter, input);

  c.Check(std::string(filter->GetOutputDataObject(2)->GetClassName()) == "vtkImageData", "output 2 is a vtkImageData");
  vtkImageData* image = vtkImageData::SafeDownCast(filter->GetOutputDataObject(2));
  if (!c.Check(image && image->GetNumberOfPoints() > 0, "the distance field is not empty"))
  {
    return c.Result();
  }
  int dims[3];
  image->GetDimensions(dims);
  double spacing[3], bounds[6];
  image->GetSpacing(spacing);
  image->GetBounds(bounds);
  std::cout << "  image " << dims[0] << "x" << dims[1] << "x" << dims[2] << ", spacing " << spacing[0] << ", bounds ["
            << bounds[0] << ", " << bounds[1] << "]\n";
  vtkDataArray* sd = image->GetPointData()->GetArray("SignedDistance");
  if (!c.Check(sd != nullptr, "point array SignedDistance"))
  {
    return c.Result();
  }
  // The grid covers the input (and the envelope).
  for (int a = 0; a < 3; ++a)
  {
    c.Check(bounds[2 * a] < -radius && bounds[2 * a + 1] > radius, "the grid covers the input on axis " + Str(a));
  }
  auto valueAt = [&](double x, double y, double z) {
    const double p[3] = { x, y, z };
    const vtkIdType id = image->FindPoint(const_cast<double*>(p));
    return id < 0 ? vtkMath::Nan() : sd->GetTuple1(id);
  };
  const double inside = valueAt(0, 0, 0);
  const double outside = valueAt(bounds[1], bounds[3], bounds[5]);
  std::cout << "  SignedDistance at the center " << inside << ", at the grid corner " << outside << "\n";
  c.Check(inside < 0, "negative inside (at the center)");
  c.Check(outside > 0, "positive outside (at the grid corner)");
  // Near the surface the values are distances in input units: 0.02 R outside the sphere. The
  // nearest grid point is up to sqrt(3)/2 spacing away, and the facets are within 0.5% of R.
  const double probe = valueAt(radius * 1.02, 0, 0);
  const double tolerance = spacing[0] + 0.01 * radius;
  c.Check(std::abs(probe - 0.02 * radius) < tolerance,
    "value near the surface in input units: " + Str(probe) + " vs " + Str(0.02 * radius) + " (tolerance " +
      Str(tolerance) + ")");
  const double probeIn = valueAt(radius * 0.97, 0, 0);
  c.Check(probeIn < 0, "negative just inside the surface (" + Str(probeIn) + ")");

  // Turned off again: the image output is emptied.
  filter->GenerateDistanceFieldOff();
  filter->Update();
  c.Check(IsEmpty(filter->GetOutputDataObject(2)), "image empty once GenerateDistanceField is off");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestParameters(const Context&)
{
  Checker c("Parameters");
  vtkNew<vtkSDFCageFilter> filter;
  const sdfcage::EnvelopeOptions core;
  c.Check(filter->GetIsoValue() == core.IsoValue, "IsoValue default = Core's");
  c.Check(filter->GetVoxelSize() == core.VoxelSize, "VoxelSize default = Core's");
  c.Check(filter->GetMinimumClearance() == core.MinimumClearance, "MinimumClearance default = Core's");
  c.Check(filter->GetAdaptivity() == core.Adaptivity, "Adaptivity default = Core's");
  c.Check(filter->GetMaximumRefinements() == core.MaximumRefinements, "MaximumRefinements default = Core's");
  c.Check(
    (filter->GetGenerateDistanceField() != 0) == core.KeepDistanceField, "GenerateDistanceField default = Core's");
  c.Check(filter->GetNumberOfThreads() == sdfcage::CageOptions().NumberOfThreads, "NumberOfThreads default = Core's");
  c.Check(filter->GetIsoValue() == 0.01, "IsoValue default is the paper's 0.01");
  c.Check(filter->GetTargetNumberOfVertices() == sdfcage::CageOptions().TargetNumberOfVertices,
    "TargetNumberOfVertices default = Core's");

  filter->SetIsoValue(-1.0);
  c.Check(filter->GetIsoValue() > 0, "IsoValue is clamped to a positive value");
  filter->SetVoxelSize(-1.0);
  c.Check(filter->GetVoxelSize() == 0, "VoxelSize is clamped to >= 0");
  filter->SetNumberOfThreads(-3);
  c.Check(filter->GetNumberOfThreads() == 0, "NumberOfThreads is clamped to >= 0");

  c.Check(filter->GetNumberOfOutputPorts() == 4, "four output ports");
  c.Check(std::string(filter->GetOutputPortInformation(3)->Get(vtkDataObject::DATA_TYPE_NAME())) ==
      "vtkMultiBlockDataSet",
    "output port 3 (nested levels) is declared as vtkMultiBlockDataSet");
  c.Check(std::string(filter->GetOutputPortInformation(2)->Get(vtkDataObject::DATA_TYPE_NAME())) == "vtkImageData",
    "output port 2 is declared as vtkImageData");
  c.Check(std::string(filter->GetOutputPortInformation(0)->Get(vtkDataObject::DATA_TYPE_NAME())) == "vtkPolyData",
    "output port 0 is declared as vtkPolyData");
  std::ostringstream print;
  filter->Print(print);
  c.Check(print.str().find("IsoValue") != std::string::npos, "PrintSelf lists the parameters");

  // Explicit (non-automatic) values are honoured: a coarser grid and an explicit clearance.
  vtkSmartPointer<vtkPolyData> input = MakeSphere(1.0, 24);
  vtkNew<vtkSDFCageFilter> explicitFilter;
  explicitFilter->SetInputData(input);
  explicitFilter->SetIsoValue(0.04);
  explicitFilter->SetVoxelSize(0.02);
  explicitFilter->SetMinimumClearance(0.005);
  explicitFilter->SetNumberOfThreads(1);
  explicitFilter->Update();
  PrintResults(explicitFilter);
  CheckSuccessfulRun(c, explicitFilter, input);
  c.Check(explicitFilter->GetVoxelSizeUsed() <= 0.02 + 1e-12, "VoxelSizeUsed <= VoxelSize");

  // CoarseFirst (default = Core's): on, the closed sphere without active points keeps the envelope
  // of the grid of c (voxel = IsoValue); off, the automatic grid c/2 is sampled directly
  c.Check((filter->GetCoarseFirst() != 0) == core.CoarseFirst, "CoarseFirst default = Core's");
  for (const int coarseFirst : { 1, 0 })
  {
    vtkNew<vtkSDFCageFilter> grid;
    grid->SetInputData(input);
    grid->SetTargetNumberOfVertices(50);
    grid->SetCoarseFirst(coarseFirst);
    grid->Update();
    CheckSuccessfulRun(c, grid, input);
    const double expected = coarseFirst ? core.IsoValue : core.IsoValue / 2;
    c.Check(std::abs(grid->GetVoxelSizeUsed() - expected) < 1e-12,
      coarseFirst ? "CoarseFirst on: the sphere keeps the grid of c" : "CoarseFirst off: the grid of c/2");
  }

  // Thread count does not change the result.
  vtkNew<vtkSDFCageFilter> allThreads;
  allThreads->SetInputData(input);
  allThreads->SetIsoValue(0.04);
  allThreads->SetVoxelSize(0.02);
  allThreads->SetMinimumClearance(0.005);
  allThreads->SetNumberOfThreads(0);
  allThreads->Update();
  vtkPolyData* a = explicitFilter->GetOutput(0);
  vtkPolyData* b = allThreads->GetOutput(0);
  bool same = a->GetNumberOfPoints() == b->GetNumberOfPoints() && a->GetNumberOfPolys() == b->GetNumberOfPolys();
  for (vtkIdType i = 0; same && i < a->GetNumberOfPoints(); ++i)
  {
    double p[3], q[3];
    a->GetPoint(i, p);
    b->GetPoint(i, q);
    same = p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
  }
  c.Check(same, "identical cages with 1 thread and all threads");

  // TargetNumberOfVertices: an explicit target is met exactly; 0 makes the cage the envelope.
  explicitFilter->SetTargetNumberOfVertices(120);
  explicitFilter->Update();
  PrintResults(explicitFilter);
  CheckSuccessfulRun(c, explicitFilter, input);
  c.Check(explicitFilter->GetOutput(0)->GetNumberOfPoints() == 120, "a 120-vertex cage");
  explicitFilter->SetTargetNumberOfVertices(0);
  explicitFilter->Update();
  CheckSuccessfulRun(c, explicitFilter, input);
  c.Check(explicitFilter->GetOutput(0)->GetNumberOfPoints() == explicitFilter->GetOutput(1)->GetNumberOfPoints(),
    "TargetNumberOfVertices 0: the cage is the envelope");
  return c.Result();
}

//------------------------------------------------------------------------------
namespace
{
int RunOnDataFile(const Context& context, const char* name, const char* file)
{
  Checker c(name);
  const std::string path = context.DataDir + "/" + file;
  if (context.DataDir.empty() || !std::ifstream(path).good())
  {
    std::cout << "skipped: " << path << " not found (data folder absent)\n";
    return Skipped;
  }
  vtkNew<vtkOFFReader> reader;
  reader->SetFileName(path.c_str());
  vtkNew<vtkSDFCageFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(reader);
  filter->SetInputConnection(reader->GetOutputPort());
  filter->Update();
  PrintResults(filter);
  c.Check(
    messages->Errors.empty(), "no errors" + (messages->Errors.empty() ? std::string() : ": " + messages->Errors[0]));
  vtkPolyData* input = reader->GetOutput();
  c.Check(input->GetNumberOfPolys() > 0, "the reader produced polygons");
  CheckSuccessfulRun(c, filter, input);
  return c.Result();
}
} // namespace

int TestDataKnight(const Context& context)
{
  return RunOnDataFile(context, "DataKnight", "decimated-knight.off");
}

int TestDataBunnyOFF(const Context& context)
{
  return RunOnDataFile(context, "DataBunnyOFF", "bunny.off");
}

//------------------------------------------------------------------------------
// vtkActivePointFilter on the built-in shape (a torus 0.012 from a sphere, unit-sphere units):
// the arrays, the counts, the optional fields; and the cage filter's UseActivePoints, which is
// what keeps the two parts apart.
int TestActivePointsBuiltin(const Context&)
{
  Checker c("ActivePointsBuiltin");
  vtkSmartPointer<vtkPolyData> input = FromTriangleMesh(sdfcage::makeBuiltinShape());
  vtkNew<vtkActivePointFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetInputData(input);
  filter->GenerateDistanceFieldsOn();
  filter->Update();
  c.Check(messages->Errors.empty(), "no errors");
  c.Check(std::string(filter->GetStatusString()) == "Ok", "status Ok");
  vtkPolyData* out = filter->GetOutput(0);
  c.Check(out->GetNumberOfPoints() == input->GetNumberOfPoints(), "the mesh keeps its points");
  c.Check(out->GetNumberOfCells() == input->GetNumberOfCells(), "the mesh keeps its triangles");
  auto* active = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("ActivePoint"));
  auto* g = vtkDoubleArray::SafeDownCast(out->GetPointData()->GetArray("GeodesicDistanceToActive"));
  auto* phi = vtkDoubleArray::SafeDownCast(out->GetPointData()->GetArray("Amplification"));
  if (!c.Check(active && g && phi, "arrays ActivePoint, GeodesicDistanceToActive, Amplification"))
  {
    return c.Result();
  }
  vtkIdType count = 0;
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    const int a = active->GetValue(i);
    c.Check(a == 0 || a == 1, "ActivePoint is 0/1");
    count += a;
    c.Check(phi->GetValue(i) >= 1.0 && phi->GetValue(i) <= filter->GetAmplificationAlpha() + 1e-12,
      "1 <= Amplification <= alpha");
    c.Check(g->GetValue(i) >= 0.0, "g_A >= 0");
    if (a)
    {
      c.Check(phi->GetValue(i) > 1.5, "active points are amplified");
    }
  }
  std::cout << "  active points: " << count << " of " << out->GetNumberOfPoints() << ", samples "
            << filter->GetNumberOfActiveSamples() << " of " << filter->GetNumberOfSamples() << ", "
            << filter->GetExecutionTime() << " s\n";
  c.Check(count > 0, "the built-in shape has active points (its parts nearly touch)");
  c.Check(count == filter->GetNumberOfActivePoints(), "GetNumberOfActivePoints counts them");
  c.Check(count < out->GetNumberOfPoints() / 2, "most points are not active");
  c.Check(FieldNumber(out, "NumberOfActivePoints") == static_cast<double>(count), "field data NumberOfActivePoints");
  // which rule: the paper's for every active point while GapRatio is 0 (the default)
  auto* rule = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("ActiveRule"));
  if (c.Check(rule != nullptr, "array ActiveRule"))
  {
    for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
    {
      c.Check(rule->GetValue(i) == active->GetValue(i), "ActiveRule is 1 where active, 0 elsewhere (GapRatio 0)");
    }
  }
  c.Check(filter->GetGapRatio() == 0.0 && FieldNumber(out, "NumberOfGapRulePoints") == 0.0,
    "GapRatio 0 by default: no point active by the facing-gap rule");
  {
    // a hook whose tip nearly touches its own straight part: the paper's rule misses it, the
    // facing-gap rule (GapRatio 3, what a topology repair round uses) finds it
    vtkNew<vtkActivePointFilter> hook;
    hook->SetInputData(FromTriangleMesh(sdfcage::makeGapShape(sdfcage::GapShape::Hook, 0.008)));
    hook->SetGapRatio(3.0);
    hook->Update();
    vtkPolyData* h = hook->GetOutput(0);
    auto* hookRule = vtkUnsignedCharArray::SafeDownCast(h->GetPointData()->GetArray("ActiveRule"));
    vtkIdType byGap = 0;
    for (vtkIdType i = 0; hookRule && i < h->GetNumberOfPoints(); ++i)
      byGap += hookRule->GetValue(i) == 2 ? 1 : 0;
    std::cout << "  hook with GapRatio 3: " << byGap << " points active by the facing-gap rule, "
              << FieldNumber(h, "NumberOfGapSamples") << " gap samples\n";
    c.Check(byGap > 0 && FieldNumber(h, "NumberOfGapRulePoints") == static_cast<double>(byGap),
      "GapRatio 3: the hook's tip is active by the facing-gap rule (ActiveRule 2), counted in the field data");
  }
  const sdfcage::ResultTable table = sdfcage::activePointResults(sdfcage::ActivePointAnalysis());
  c.Check(filter->GetNumberOfResults() == static_cast<int>(table.size()), "the filter has Core's active-point table");
  for (const sdfcage::ResultField& f : table)
  {
    c.Check(FieldNumber(out, f.Name.c_str()) == filter->GetResultNumber(f.Name.c_str()),
      "field data " + f.Name + " = GetResultNumber");
  }
  c.Check(filter->GetExecutionTime() == FieldNumber(out, "ActivePointTime") && filter->GetActivePointTime() > 0,
    "GetExecutionTime (old name) = GetActivePointTime = field data ActivePointTime");
  auto* fields = vtkImageData::SafeDownCast(filter->GetOutputDataObject(1));
  c.Check(fields && fields->GetNumberOfPoints() > 1000, "output 1 holds the fields");
  if (fields)
  {
    auto* xi = fields->GetPointData()->GetArray("SignedDistance");
    auto* mod = fields->GetPointData()->GetArray("ModifiedSignedDistance");
    c.Check(xi && mod, "SignedDistance and ModifiedSignedDistance");
    if (xi && mod)
    {
      vtkIdType amplified = 0;
      for (vtkIdType k = 0; k < xi->GetNumberOfTuples(); ++k)
      {
        amplified += xi->GetTuple1(k) > 0 && mod->GetTuple1(k) > 1.5 * xi->GetTuple1(k);
      }
      c.Check(amplified > 0, "the modified field is amplified somewhere");
    }
  }

  // Off by default: no fields.
  filter->GenerateDistanceFieldsOff();
  filter->Update();
  c.Check(IsEmpty(filter->GetOutputDataObject(1)), "no fields unless asked");

  // The cage filter: with active points the envelope keeps two components, without it fuses them.
  vtkNew<vtkSDFCageFilter> cage;
  vtkNew<MessageRecorder> cageMessages;
  cageMessages->Watch(cage);
  cage->SetInputData(input);
  cage->SetTargetNumberOfVertices(0); // the envelope is what is tested
  c.Check(cage->GetUseActivePoints() != 0, "UseActivePoints is on by default");
  cage->Update();
  c.Check(std::string(cage->GetStatusString()) == "Ok", "cage with active points: Ok");
  c.Check(cage->GetEnvelopeComponents() == 2,
    "with active points the envelope keeps 2 components (got " + Str(cage->GetEnvelopeComponents()) + ")");
  c.Check(cage->GetEnvelopeGenus() == 1, "and genus 1");
  c.Check(cage->GetNumberOfActivePoints() > 0, "NumberOfActivePoints > 0");
  c.Check(std::string(cage->GetTopologyWarning()).empty(), "no topology warning");
  cage->UseActivePointsOff();
  cageMessages->Clear();
  cage->Update();
  c.Check(std::string(cage->GetStatusString()) == "Ok", "cage without active points: Ok");
  c.Check(cage->GetEnvelopeComponents() == 1, "without them the parts fuse (1 component)");
  c.Check(cage->GetNumberOfActivePoints() == 0, "no active points when off");
  c.Check(!std::string(cage->GetTopologyWarning()).empty(), "a topology warning says so");
  bool warned = false;
  for (const std::string& w : cageMessages->Warnings)
  {
    warned = warned || w.find("fused") != std::string::npos;
  }
  c.Check(warned, "the warning reaches the user as a VTK warning");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestActivePointsErrors(const Context&)
{
  Checker c("ActivePointsErrors");
  vtkNew<vtkActivePointFilter> filter;
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  // a sphere: no active points
  filter->SetInputData(MakeSphere(2.0, 48));
  filter->Update();
  c.Check(std::string(filter->GetStatusString()) == "Ok", "sphere: Ok");
  c.Check(filter->GetNumberOfActivePoints() == 0, "a sphere has no active points");
  c.Check(messages->Errors.empty(), "no errors on a sphere");

  // an open sphere: an error naming the defect, empty outputs
  vtkSmartPointer<vtkPolyData> sphere = MakeSphere(1.0, 16);
  vtkNew<vtkCellArray> polys;
  vtkIdType npts = 0;
  const vtkIdType* pts = nullptr;
  for (vtkIdType cell = 1; cell < sphere->GetPolys()->GetNumberOfCells(); ++cell)
  {
    sphere->GetPolys()->GetCellAtId(cell, npts, pts);
    polys->InsertNextCell(npts, pts);
  }
  vtkNew<vtkPolyData> holed;
  holed->SetPoints(sphere->GetPoints());
  holed->SetPolys(polys);
  filter->SetInputData(holed);
  filter->Update();
  c.Check(messages->ErrorContains("boundary"), "open input: the error names the boundary edges");
  c.Check(std::string(filter->GetStatusString()) == "InvalidInput", "status InvalidInput");
  c.Check(IsEmpty(filter->GetOutput(0)), "empty output on error");

  // empty input: no error, empty output
  messages->Clear();
  vtkNew<vtkPolyData> empty;
  filter->SetInputData(empty);
  filter->Update();
  c.Check(messages->Errors.empty(), "empty input is not an error");
  c.Check(std::string(filter->GetStatusString()) == "EmptyInput", "status EmptyInput");

  // bad parameters: l < r is named
  messages->Clear();
  filter->SetInputData(MakeSphere(1.0, 16));
  filter->SetGeodesicThreshold(0.01);
  filter->Update();
  c.Check(messages->ErrorContains("GeodesicThreshold"), "l < r is rejected, naming the parameter");
  c.Check(IsEmpty(filter->GetOutput(0)), "empty output on bad parameters");
  return c.Result();
}

} // namespace sdfcage_test
