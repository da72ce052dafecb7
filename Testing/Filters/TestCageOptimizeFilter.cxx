// SDFCage — tests of vtkCageOptimizeFilter (cage + source mesh -> optimized cage) and of the
// optimization step of vtkSDFCageFilter.
#include "SDFCageTestUtilities.h"

#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkCageOptimizeFilter.h"
#include "vtkSDFCageFilter.h"
#include "vtkStringArray.h"

#include "Optimization/Optimization.h" // Core: the default options the filter must mirror
#include "Spatial/TriangleTree.h"      // Core: distanceBetweenParts, to measure the parts' gap

#include "vtkAppendPolyData.h"
#include "vtkCellArray.h"
#include "vtkIdList.h"
#include "vtkSphereSource.h"
#include "vtkTriangleFilter.h"

#include <cmath>

namespace sdfcage_test
{

namespace
{
// The 150-vertex cage of a sphere that the tests below optimize, made by `cager` (the caller keeps
// it: TestOptimizeFilter runs it again with its own Optimize step).
bool BuildSphereCage(Checker& c, vtkSDFCageFilter* cager, vtkSmartPointer<vtkPolyData>& sphere)
{
  sphere = MakeSphere(1.0, 24);
  cager->SetInputData(sphere);
  cager->SetTargetNumberOfVertices(150);
  cager->Update();
  return c.Check(
    std::string(cager->GetStatusString()) == "Ok" && cager->GetOutput(0)->GetNumberOfPoints() == 150,
    "the cage to optimize was built");
}
} // namespace

int TestOptimizeFilter(const Context&)
{
  Checker c("OptimizeFilter");
  // a cage of a sphere from vtkSDFCageFilter, then optimized with both energies
  vtkSmartPointer<vtkPolyData> sphere;
  vtkNew<vtkSDFCageFilter> cager;
  if (!BuildSphereCage(c, cager, sphere))
  {
    return c.Result();
  }
  vtkPolyData* cage = cager->GetOutput(0);

  vtkNew<vtkCageOptimizeFilter> filter;
  const sdfcage::OptimizeOptions defaults;
  c.Check(filter->GetEnergy() == vtkCageOptimizeFilter::MIPS, "Energy default MIPS");
  c.Check(filter->GetTargetSpacing() == defaults.TargetSpacing, "TargetSpacing default is Core's");
  c.Check(filter->GetBarrierWeight() == defaults.BarrierWeight, "BarrierWeight default is Core's");
  c.Check(filter->GetBarrierDistance() == defaults.BarrierDistance, "BarrierDistance default is Core's");
  c.Check(filter->GetNumberOfIterations() == defaults.NumberOfIterations, "NumberOfIterations default");
  c.Check(filter->GetEdgeFlips() == 1, "EdgeFlips default on");
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive()); // its "returned failure" report of the error case
  filter->SetInputData(cage);
  filter->SetSourceData(sphere);
  for (int energy : { vtkCageOptimizeFilter::MIPS, vtkCageOptimizeFilter::SPACING })
  {
    const std::string name = energy == vtkCageOptimizeFilter::MIPS ? "MIPS" : "Spacing";
    filter->SetEnergy(energy);
    filter->SetTargetSpacing(0.03);
    filter->Update();
    vtkPolyData* out = filter->GetOutput();
    c.Check(std::string(filter->GetStatusString()) == "Ok",
      name + ": status Ok, got " + filter->GetStatusString() + " " + filter->GetLastErrorMessage());
    c.Check(
      out->GetNumberOfPoints() == cage->GetNumberOfPoints() && out->GetNumberOfPolys() == cage->GetNumberOfPolys(),
      name + ": same point and triangle counts");
    c.Check(CountOpenEdges(out) == 0, name + ": closed and manifold");
    c.Check(filter->GetEnergyAfter() < filter->GetEnergyBefore(),
      name + ": energy lowered " + Str(filter->GetEnergyBefore()) + " -> " + Str(filter->GetEnergyAfter()));
    c.Check(filter->GetNumberOfMoves() > 0, name + ": vertices moved");
    c.Check(!filter->GetReverted(), name + ": not reverted");
    c.Check(filter->GetMeasuredClearanceRelative() >= filter->GetClearanceUsed() * (1 - 1e-9),
      name + ": clearance kept " + Str(filter->GetMeasuredClearanceRelative()) +
        " >= " + Str(filter->GetClearanceUsed()));
    auto* distance = vtkDoubleArray::SafeDownCast(out->GetPointData()->GetArray("DistanceToInput"));
    if (c.Check(distance && distance->GetNumberOfTuples() == out->GetNumberOfPoints(), name + ": DistanceToInput"))
    {
      c.Check(distance->GetRange()[0] >= filter->GetMeasuredClearance() * (1 - 1e-9),
        name + ": DistanceToInput >= MeasuredClearance");
    }
    auto* status = vtkStringArray::SafeDownCast(out->GetFieldData()->GetAbstractArray("Status"));
    c.Check(status && status->GetValue(0) == "Ok", name + ": field data Status");
    c.Check(out->GetFieldData()->GetArray("EnergyAfter") != nullptr, name + ": field data EnergyAfter");
    // every result of the filter's table is in the field data, with the getter's value
    c.Check(filter->GetNumberOfResults() >= 11, name + ": the optimization table has its 11 results");
    for (int i = 0; i < filter->GetNumberOfResults(); ++i)
    {
      const std::string result = filter->GetResultName(i);
      vtkDataArray* a = out->GetFieldData()->GetArray(result.c_str());
      c.Check(a && a->GetNumberOfTuples() == 1 && a->GetTuple1(0) == filter->GetResultNumber(result.c_str()),
        name + ": field data " + result + " = the getter's");
    }
    c.Check(filter->GetEnergyAfter() == filter->GetResultNumber("EnergyAfter") &&
        filter->GetNumberOfMoves() == filter->GetResultNumber("NumberOfMoves"),
      name + ": the getters read the table");
    c.Check(filter->GetOptimizationTime() > 0, name + ": time measured");
  }
  c.Check(messages->Errors.empty(), "no errors");

  // errors: a "cage" inside the source is rejected with a clear message and an empty output
  messages->Clear();
  filter->SetInputData(MakeSphere(0.5, 12));
  filter->Update();
  c.Check(std::string(filter->GetStatusString()) == "InvalidInput", "a cage inside its source is invalid");
  c.Check(messages->ErrorContains("does not enclose"), "the error says the cage does not enclose the input");
  c.Check(filter->GetOutput()->GetNumberOfPoints() == 0, "empty output on error");

  // no source: not an error, empty output
  messages->Clear();
  vtkNew<vtkCageOptimizeFilter> lonely;
  messages->Watch(lonely);
  lonely->SetInputData(cage);
  lonely->Update();
  c.Check(std::string(lonely->GetStatusString()) == "EmptyInput", "no source gives EmptyInput");
  c.Check(lonely->GetOutput()->GetNumberOfPoints() == 0, "no source gives an empty output");
  c.Check(messages->Errors.empty(), "no source is not an error");

  // the optional step of vtkSDFCageFilter: off by default, on gives a verified, optimized cage
  c.Check(cager->GetOptimize() == 0, "vtkSDFCageFilter: Optimize off by default");
  cager->OptimizeOn();
  cager->SetEnergyToSpacing();
  cager->SetTargetSpacing(0.03);
  cager->Update();
  c.Check(
    std::string(cager->GetStatusString()) == "Ok", std::string("optimize step: status ") + cager->GetStatusString());
  c.Check(cager->GetEnclosureVerified(), "optimize step: enclosure verified");
  c.Check(cager->GetEnergyAfter() < cager->GetEnergyBefore(),
    "optimize step: energy lowered " + Str(cager->GetEnergyBefore()) + " -> " + Str(cager->GetEnergyAfter()));
  c.Check(cager->GetOutput(0)->GetNumberOfPoints() == 150, "optimize step keeps the vertex count");
  c.Check(cager->GetOptimizationTime() > 0, "optimize step: time measured");
  return c.Result();
}

// The MIPS options that keep the cage tight (HausdorffFactor, TargetMinimumAngle, MaximumSweeps)
// reach Core through both filters: their defaults are Core's and each changes what Core reports.
int TestOptimizeTightOptions(const Context&)
{
  Checker c("OptimizeTightOptions");
  vtkSmartPointer<vtkPolyData> sphere;
  vtkNew<vtkSDFCageFilter> cager;
  if (!BuildSphereCage(c, cager, sphere))
  {
    return c.Result();
  }
  vtkPolyData* cage = cager->GetOutput(0);
  const sdfcage::OptimizeOptions defaults;
  vtkNew<vtkCageOptimizeFilter> filter;
  c.Check(filter->GetHausdorffFactor() == defaults.HausdorffFactor, "HausdorffFactor default is Core's");
  c.Check(filter->GetTargetMinimumAngle() == defaults.TargetMinimumAngle, "TargetMinimumAngle default is Core's");
  c.Check(filter->GetMaximumSweeps() == defaults.MaximumSweeps, "MaximumSweeps default is Core's");
  c.Check(cager->GetHausdorffFactor() == defaults.HausdorffFactor &&
      cager->GetTargetMinimumAngle() == defaults.TargetMinimumAngle &&
      cager->GetMaximumSweeps() == defaults.MaximumSweeps,
    "vtkSDFCageFilter: the same defaults");
  vtkNew<MessageRecorder> messages;
  messages->Watch(filter);
  messages->Watch(filter->GetExecutive());
  filter->SetInputData(cage);
  filter->SetSourceData(sphere);

  // TargetMinimumAngle: the share of small angles is measured against it
  filter->SetMaximumSweeps(1);
  filter->SetTargetMinimumAngle(15);
  filter->Update();
  const double small15 = filter->GetResultNumber("SmallAnglesBefore");
  c.Check(std::string(filter->GetStatusString()) == "Ok", std::string("target 15: ") + filter->GetStatusString());
  c.Check(filter->GetResultNumber("NumberOfSweeps") == 1,
    "MaximumSweeps 1: one sweep, got " + Str(filter->GetResultNumber("NumberOfSweeps")));
  filter->SetTargetMinimumAngle(45);
  filter->Update();
  const double small45 = filter->GetResultNumber("SmallAnglesBefore");
  c.Check(small45 > small15 && small45 > 0,
    "TargetMinimumAngle reaches Core: angles below 45 deg " + Str(small45) + "% > below 15 deg " + Str(small15) + "%");
  // MaximumSweeps: 45 deg is out of reach, so the round runs every sweep allowed
  filter->SetMaximumSweeps(2);
  filter->Update();
  c.Check(filter->GetResultNumber("NumberOfSweeps") == 2,
    "MaximumSweeps 2: two sweeps, got " + Str(filter->GetResultNumber("NumberOfSweeps")));
  c.Check(filter->GetOutput()->GetNumberOfPoints() == 150 && !filter->GetReverted(), "the vertex count is kept");
  // HausdorffFactor: Core rejects a factor in (0, 1), with a clear error and an empty output
  messages->Clear();
  filter->SetHausdorffFactor(0.5);
  filter->Update();
  c.Check(std::string(filter->GetStatusString()) == "InvalidInput",
    std::string("HausdorffFactor 0.5 reaches Core: ") + filter->GetStatusString());
  c.Check(messages->ErrorContains("HausdorffFactor"), "the error names HausdorffFactor");
  c.Check(filter->GetOutput()->GetNumberOfPoints() == 0, "empty output on error");
  filter->SetHausdorffFactor(0);
  filter->Update();
  c.Check(std::string(filter->GetStatusString()) == "Ok", "HausdorffFactor 0 (no bound) is accepted");

  // the optimization step of vtkSDFCageFilter passes them too
  cager->OptimizeOn();
  cager->SetEnergyToMIPS();
  cager->SetMaximumSweeps(1);
  cager->SetTargetMinimumAngle(45);
  cager->Update();
  c.Check(std::string(cager->GetStatusString()) == "Ok", std::string("SDF cage + MIPS: ") + cager->GetStatusString());
  c.Check(cager->GetResultNumber("NumberOfSweeps") == 1 && cager->GetResultNumber("SmallAnglesBefore") > small15,
    "vtkSDFCageFilter: MaximumSweeps and TargetMinimumAngle reach Core (sweeps " +
      Str(cager->GetResultNumber("NumberOfSweeps")) + ", below 45 deg " +
      Str(cager->GetResultNumber("SmallAnglesBefore")) + "%)");
  return c.Result();
}

// KeepPartsApart: the spacing energy pushes the cages of two spheres 0.08 apart towards each
// other; with it on the parts stay at least as far apart as in the given cage (measured with
// Core's exact distanceBetweenParts), with it off they come closer.
int TestOptimizeKeepsPartsApart(const Context&)
{
  Checker c("OptimizeKeepsPartsApart");
  vtkNew<vtkAppendPolyData> both;
  for (const double x : { -0.54, 0.54 })
  {
    vtkNew<vtkSphereSource> sphere;
    sphere->SetCenter(x, 0, 0);
    sphere->SetRadius(0.5);
    sphere->SetThetaResolution(48);
    sphere->SetPhiResolution(24);
    both->AddInputConnection(sphere->GetOutputPort());
  }
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(both->GetOutputPort());
  triangles->Update();
  vtkPolyData* spheres = triangles->GetOutput();
  vtkNew<vtkSDFCageFilter> cager;
  cager->SetInputData(spheres);
  cager->SetTargetNumberOfVertices(400);
  cager->Update();
  vtkPolyData* cage = cager->GetOutput(0);
  if (!c.Check(std::string(cager->GetStatusString()) == "Ok" && cage->GetNumberOfPoints() == 400,
        "the two spheres' cage was built"))
  {
    return c.Result();
  }
  auto gap = [](vtkPolyData* pd) {
    sdfcage::TriangleMesh m;
    for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i)
    {
      double p[3];
      pd->GetPoint(i, p);
      m.Points.emplace_back(p[0], p[1], p[2]);
    }
    vtkNew<vtkIdList> ids;
    for (vtkIdType f = 0; f < pd->GetNumberOfCells(); ++f)
    {
      pd->GetCellPoints(f, ids);
      if (ids->GetNumberOfIds() == 3)
        m.Triangles.push_back(
          { static_cast<int>(ids->GetId(0)), static_cast<int>(ids->GetId(1)), static_cast<int>(ids->GetId(2)) });
    }
    return sdfcage::distanceBetweenParts(m, 1.0);
  };
  const double given = gap(cage);
  vtkNew<vtkCageOptimizeFilter> filter;
  c.Check(filter->GetKeepPartsApart() == 0, "KeepPartsApart is off by default");
  filter->SetInputData(cage);
  filter->SetSourceData(spheres);
  filter->SetEnergy(vtkCageOptimizeFilter::SPACING);
  filter->Update();
  const double off = gap(filter->GetOutput());
  c.Check(std::string(filter->GetStatusString()) == "Ok" && !filter->GetReverted(), "spacing, parts free: Ok");
  c.Check(filter->GetResultNumber("OptimizationPartRoom") == 0, "no room kept when off");
  filter->KeepPartsApartOn();
  filter->Update();
  const double on = gap(filter->GetOutput());
  std::cout << "  parts apart: given " << given << ", optimized " << off << " (free) and " << on
            << " (KeepPartsApart), room " << filter->GetResultNumber("OptimizationPartRoom") << " relative\n";
  c.Check(std::string(filter->GetStatusString()) == "Ok" && !filter->GetReverted(), "spacing, parts kept apart: Ok");
  c.Check(filter->GetOutput()->GetNumberOfPoints() == 400, "the vertex count is kept");
  c.Check(filter->GetResultNumber("NumberOfMoves") > 0, "the optimization moved vertices");
  c.Check(off < given, "free, the spacing energy brings the parts closer");
  c.Check(on >= given * (1.0 - 1e-9), "KeepPartsApart: the parts are at least as far apart as given");
  c.Check(filter->GetResultNumber("OptimizationPartRoom") > 0, "OptimizationPartRoom reports the room");
  return c.Result();
}

} // namespace sdfcage_test
