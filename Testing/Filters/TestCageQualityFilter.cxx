// SDFCage — C++ tests of vtkCageQualityFilter: SDFCageQualityFilterTests <case> <scratch dir>
// A sphere judged against good and broken cages (quads, open, empty, missing mesh) and against
// the cage vtkSDFCageFilter makes.
#include "SDFCageTestUtilities.h"

#include "vtkCageQualityFilter.h"
#include "vtkSDFCageFilter.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCleanPolyData.h"
#include "vtkCubeSource.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"
#include "vtkStringArray.h"
#include "vtkStripper.h"
#include "vtkTriangleFilter.h"

#ifdef SDFCAGE_HAVE_EXACT
#include "ExactCheck.h" // the independent CGAL referee (test-only)
#endif

#include <cmath>
#include <functional>
#include <map>

namespace
{
using namespace sdfcage_test;

vtkSmartPointer<vtkPolyData> Sphere(double radius, int resolution)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(radius);
  sphere->SetThetaResolution(resolution);
  sphere->SetPhiResolution(resolution);
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(sphere->GetOutputPort());
  triangles->Update();
  auto result = vtkSmartPointer<vtkPolyData>::New();
  result->ShallowCopy(triangles->GetOutput());
  return result;
}

/// A cube of quads; `merge` shares the corner points (closed), otherwise every face has its own
/// four points (24 points: as a mesh, every edge is a boundary edge).
vtkSmartPointer<vtkPolyData> Cube(double side, bool merge)
{
  vtkNew<vtkCubeSource> cube;
  cube->SetXLength(side);
  cube->SetYLength(side);
  cube->SetZLength(side);
  cube->Update();
  auto result = vtkSmartPointer<vtkPolyData>::New();
  if (!merge)
  {
    result->ShallowCopy(cube->GetOutput());
    return result;
  }
  vtkNew<vtkCleanPolyData> clean;
  clean->SetInputConnection(cube->GetOutputPort());
  clean->Update();
  result->ShallowCopy(clean->GetOutput());
  result->GetPointData()->Initialize(); // normals and texture coordinates of the cube source
  return result;
}

double FieldValue(vtkPolyData* data, const char* name)
{
  vtkDataArray* a = data->GetFieldData()->GetArray(name);
  return a ? a->GetTuple1(0) : std::nan("");
}

std::string FieldText(vtkPolyData* data, const char* name)
{
  auto* a = vtkStringArray::SafeDownCast(data->GetFieldData()->GetAbstractArray(name));
  return a && a->GetNumberOfValues() > 0 ? a->GetValue(0) : std::string("<missing>");
}

int TestQualityGoodCube(const Context&)
{
  Checker c("QualityGoodCube");
  auto sphere = Sphere(1.0, 32);
  auto cube = Cube(3.0, true);
  vtkNew<vtkCageQualityFilter> quality;
  vtkNew<MessageRecorder> messages;
  messages->Watch(quality);
  quality->SetInputData(cube);
  quality->SetSourceData(sphere);
  quality->Update();
  vtkPolyData* out = quality->GetOutput();
  c.Check(messages->Errors.empty(), "no error");
  c.Check(
    quality->GetEncloses(), "a cube of side 3 encloses the unit sphere: " + std::string(quality->GetQualityMessage()));
  c.Check(FieldValue(out, "Encloses") == 1, "field data Encloses = 1");
  // every result of the filter's table is in the field data, with the getter's value
  c.Check(quality->GetNumberOfResults() >= 18, "the quality table has its 18 results");
  for (int i = 0; i < quality->GetNumberOfResults(); ++i)
  {
    const char* name = quality->GetResultName(i);
    vtkAbstractArray* a = out->GetFieldData()->GetAbstractArray(name);
    c.Check(a != nullptr && a->GetNumberOfTuples() == 1, std::string("field data has ") + name);
    if (vtkStringArray::SafeDownCast(a))
      c.Check(
        FieldText(out, name) == quality->GetResultText(name), std::string("field data ") + name + " = the getter's");
    else
      c.Check(
        FieldValue(out, name) == quality->GetResultNumber(name), std::string("field data ") + name + " = the getter's");
  }
  c.Check(quality->GetHausdorffCageToInput() == FieldValue(out, "HausdorffCageToInput"),
    "GetHausdorffCageToInput reads the table");
  c.Check(out->GetNumberOfCells() == 6 && out->GetNumberOfPoints() == 8, "output is the cage (6 quads, 8 points)");
  // vtkSphereSource puts no vertex on the x and y axes: the clearance is at least 0.5
  c.Check(quality->GetMinimumClearance() >= 0.5 && quality->GetMinimumClearance() < 0.52,
    "clearance in [0.5, 0.52): " + Str(quality->GetMinimumClearance()));
  c.Check(std::abs(FieldValue(out, "MinimumClearanceRelative") -
            quality->GetMinimumClearance() / sphere->GetLength()) <= 1e-12,
    "relative clearance = clearance / the sphere's bounding-box diagonal");
  c.Check(quality->GetSelfIntersections() == 0 && quality->GetInputIntersections() == 0 &&
      quality->GetInputVerticesOutside() == 0,
    "no intersections, no vertex outside");
  c.Check(quality->GetCageGenus() == 0 && quality->GetInputGenus() == 0, "genus 0 and 0");
  vtkDataArray* pd = out->GetPointData()->GetArray("DistanceToInput");
  c.Check(pd && pd->GetNumberOfTuples() == 8, "point DistanceToInput on 8 points");
  if (pd)
  {
    // corners (+-1.5)^3: distance to the sphere about 1.5 sqrt(3) - 1
    for (vtkIdType i = 0; i < 8; ++i)
    {
      c.Check(
        std::abs(pd->GetTuple1(i) - (1.5 * std::sqrt(3.0) - 1.0)) < 0.01, "corner distance " + Str(pd->GetTuple1(i)));
    }
  }
  for (const char* name : { "DistanceToInput", "MinimumAngle", "MIPSEnergy" })
  {
    vtkDataArray* a = out->GetCellData()->GetArray(name);
    c.Check(a && a->GetNumberOfTuples() == 6, std::string("cell array ") + name + " on 6 cells");
  }
  vtkDataArray* angle = out->GetCellData()->GetArray("MinimumAngle");
  if (angle)
  {
    c.Check(std::abs(angle->GetTuple1(0) - 45.0) < 1e-9, "a quad split in two: minimum angle 45");
  }
  vtkDataArray* cellDistance = out->GetCellData()->GetArray("DistanceToInput");
  if (cellDistance && pd)
  {
    c.Check(cellDistance->GetTuple1(0) >= pd->GetTuple1(0) - 1e-12, "cell distance >= its corners'");
  }
  c.Check(
    quality->GetHausdorffCageToInput() >= pd->GetRange()[1] - 1e-12, "Hausdorff cage->input >= max corner distance");
  c.Check(
    quality->GetHausdorffCageToInputBound() - quality->GetHausdorffCageToInput() <= 1e-4 * 2 * std::sqrt(3.0) + 1e-12,
    "Hausdorff certified to the tolerance");
  // input -> cage: the sphere point farthest from the faces is near (1,1,1)/sqrt3: 1.5 - 0.577
  c.Check(quality->GetHausdorffInputToCage() > 0.9 && quality->GetHausdorffInputToCage() < 0.95,
    "Hausdorff input->cage about 0.92: " + Str(quality->GetHausdorffInputToCage()));
  c.Check(quality->GetMeanDistanceCageToInput() > quality->GetMinimumClearance() &&
      quality->GetMeanDistanceCageToInput() < quality->GetHausdorffCageToInput(),
    "clearance < mean distance < Hausdorff");
  c.Check(FieldText(out, "QualityMessage").empty(), "empty QualityMessage");
  return c.Result();
}

int TestQualityBrokenCages(const Context&)
{
  Checker c("QualityBrokenCages");
  auto sphere = Sphere(1.0, 32);

  // too small: cuts the sphere
  vtkNew<vtkCageQualityFilter> quality;
  vtkNew<MessageRecorder> messages;
  messages->Watch(quality);
  messages->Watch(quality->GetExecutive());
  quality->SetInputData(Cube(1.6, true));
  quality->SetSourceData(sphere);
  quality->Update();
  c.Check(messages->Errors.empty(), "a cutting cage is not an error");
  c.Check(!quality->GetEncloses(), "a cube of side 1.6 does not enclose the unit sphere");
  c.Check(quality->GetInputIntersections() > 0 && quality->GetInputVerticesOutside() > 0,
    "intersections and vertices outside are counted");
  c.Check(FieldValue(quality->GetOutput(), "Encloses") == 0, "field data Encloses = 0");
  c.Check(FieldText(quality->GetOutput(), "QualityMessage").find("intersects") != std::string::npos,
    "QualityMessage says it intersects: " + FieldText(quality->GetOutput(), "QualityMessage"));

  // open: the cube source's faces do not share points
  quality->SetInputData(Cube(3.0, false));
  quality->Update();
  c.Check(messages->Errors.empty(), "an open cage is not an error");
  c.Check(!quality->GetEncloses(), "an open cage does not enclose");
  c.Check(std::string(quality->GetQualityMessage()).find("not a closed 2-manifold") != std::string::npos,
    std::string("the message says it is open: ") + quality->GetQualityMessage());
  c.Check(quality->GetCageGenus() == -1, "no genus for an open cage");
  c.Check(quality->GetOutput()->GetNumberOfCells() == 6, "the open cage is still output, with its arrays");

  // empty cage: empty output, no error
  vtkNew<vtkPolyData> empty;
  quality->SetInputData(empty);
  quality->Update();
  c.Check(messages->Errors.empty(), "an empty cage is not an error");
  c.Check(quality->GetOutput()->GetNumberOfPoints() == 0 && !quality->GetEncloses(), "empty output");

  // missing mesh: a clear error
  vtkNew<vtkCageQualityFilter> lonely;
  vtkNew<MessageRecorder> lonelyMessages;
  lonelyMessages->Watch(lonely);
  lonelyMessages->Watch(lonely->GetExecutive());
  lonely->SetInputData(Cube(3.0, true));
  lonely->Update();
  c.Check(!lonelyMessages->Errors.empty(), "a missing mesh is an error");
  c.Check(lonely->GetOutput()->GetNumberOfPoints() == 0, "empty output without a mesh");
  return c.Result();
}

int TestQualityOfSDFCage(const Context&)
{
  Checker c("QualityOfSDFCage");
  auto sphere = Sphere(2.0, 32);
  vtkNew<vtkSDFCageFilter> cage;
  cage->SetInputData(sphere);
  cage->SetIsoValue(0.04);
  cage->SetTargetNumberOfVertices(100);
  vtkNew<vtkCageQualityFilter> quality;
  quality->SetInputConnection(cage->GetOutputPort(0));
  quality->SetSourceData(sphere);
  quality->Update();
  c.Check(cage->GetEnclosureVerified(), "the SDF cage is verified");
  c.Check(quality->GetEncloses(), std::string("the quality filter agrees: ") + quality->GetQualityMessage());
  c.Check(
    std::abs(quality->GetMinimumClearance() - cage->GetMeasuredClearance()) <= 1e-9 * cage->GetMeasuredClearance(),
    "the same exact clearance: " + Str(quality->GetMinimumClearance()) + " vs " + Str(cage->GetMeasuredClearance()));
  vtkDataArray* ours = quality->GetOutput()->GetPointData()->GetArray("DistanceToInput");
  vtkDataArray* theirs = cage->GetOutput(0)->GetPointData()->GetArray("DistanceToInput");
  c.Check(ours && theirs && ours->GetNumberOfTuples() == theirs->GetNumberOfTuples(), "both have DistanceToInput");
  if (ours && theirs)
  {
    double worst = 0.0;
    for (vtkIdType i = 0; i < ours->GetNumberOfTuples(); ++i)
    {
      worst = std::max(worst, std::abs(ours->GetTuple1(i) - theirs->GetTuple1(i)));
    }
    c.Check(worst <= 1e-12 * 4.0, "point distances agree (worst " + Str(worst) + ")");
  }
  c.Check(quality->GetCageGenus() == 0, "cage genus 0");
  c.Check(FieldValue(quality->GetOutput(), "QualityTime") >= 0, "QualityTime published");
  return c.Result();
}

int TestQualityMixedCells(const Context&)
{
  Checker c("QualityMixedCells");
  // the closed cube of quads plus a vertex cell and a line cell (ignored, NaN cell values), and
  // the same cube as triangle strips: the verdict and the per-cell values follow the cells
  auto cube = Cube(3.0, true);
  vtkNew<vtkCellArray> verts, lines;
  const vtkIdType v0 = 0, l01[2] = { 0, 1 };
  verts->InsertNextCell(1, &v0);
  lines->InsertNextCell(2, l01);
  cube->SetVerts(verts);
  cube->SetLines(lines);
  vtkNew<vtkCageQualityFilter> quality;
  quality->SetInputData(cube);
  quality->SetSourceData(Sphere(1.0, 32));
  quality->Update();
  vtkPolyData* out = quality->GetOutput();
  c.Check(
    quality->GetEncloses(), std::string("quads + vertex + line cells still enclose: ") + quality->GetQualityMessage());
  c.Check(out->GetNumberOfCells() == 8, "8 cells (1 vertex, 1 line, 6 quads): " + Str(out->GetNumberOfCells()));
  vtkDataArray* angle = out->GetCellData()->GetArray("MinimumAngle");
  vtkDataArray* distance = out->GetCellData()->GetArray("DistanceToInput");
  c.Check(angle && angle->GetNumberOfTuples() == 8 && distance && distance->GetNumberOfTuples() == 8, "8 cell values");
  if (angle && distance)
  {
    c.Check(std::isnan(angle->GetTuple1(0)) && std::isnan(angle->GetTuple1(1)), "vertex and line cells: NaN");
    bool quadsOk = true;
    for (vtkIdType i = 2; i < 8; ++i)
    {
      quadsOk = quadsOk && std::abs(angle->GetTuple1(i) - 45.0) < 1e-9 && distance->GetTuple1(i) > 0.5;
    }
    c.Check(quadsOk, "every quad: minimum angle 45, distance > 0.5");
  }

  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputData(Cube(3.0, true));
  vtkNew<vtkStripper> stripper;
  stripper->SetInputConnection(triangles->GetOutputPort());
  stripper->Update();
  vtkPolyData* strips = stripper->GetOutput();
  c.Check(strips->GetNumberOfStrips() > 0 && strips->GetNumberOfPolys() == 0, "the cube as triangle strips");
  quality->SetInputData(strips);
  quality->Update();
  c.Check(quality->GetEncloses(), std::string("the strips enclose too: ") + quality->GetQualityMessage());
  c.Check(quality->GetCageGenus() == 0, "genus 0 from strips");
  vtkDataArray* stripAngle = quality->GetOutput()->GetCellData()->GetArray("MinimumAngle");
  c.Check(stripAngle && stripAngle->GetNumberOfTuples() == strips->GetNumberOfCells() &&
      std::abs(stripAngle->GetRange()[0] - 45.0) < 1e-9,
    "one value per strip, 45 degrees");
  return c.Result();
}

/// A sphere and its nested cages (150 and 60 vertices) from vtkSDFCageFilter's port 3.
struct NestedSetup
{
  vtkSmartPointer<vtkPolyData> Input = Sphere(2.0, 32);
  vtkNew<vtkSDFCageFilter> Cager;
  NestedSetup()
  {
    this->Cager->SetInputData(this->Input);
    this->Cager->SetNumberOfNestedLevels(2);
    this->Cager->SetNestedVertexCount(0, 60); // the order does not matter: finest first
    this->Cager->SetNestedVertexCount(1, 150);
    this->Cager->Update();
  }
  vtkMultiBlockDataSet* Levels() { return vtkMultiBlockDataSet::SafeDownCast(this->Cager->GetOutputDataObject(3)); }
};

std::string BlockName(vtkMultiBlockDataSet* levels, unsigned int i)
{
  return levels && i < levels->GetNumberOfBlocks() && levels->HasMetaData(i) &&
      levels->GetMetaData(i)->Has(vtkCompositeDataSet::NAME())
    ? levels->GetMetaData(i)->Get(vtkCompositeDataSet::NAME())
    : std::string();
}

#ifdef SDFCAGE_HAVE_EXACT
sdfcage::TriangleMesh ToMesh(vtkPolyData* data)
{
  sdfcage::TriangleMesh mesh;
  double p[3];
  for (vtkIdType i = 0; i < data->GetNumberOfPoints(); ++i)
  {
    data->GetPoint(i, p);
    mesh.Points.emplace_back(p[0], p[1], p[2]);
  }
  vtkIdType npts = 0;
  const vtkIdType* pts = nullptr;
  vtkCellArray* polys = data->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
  {
    for (vtkIdType k = 1; k + 1 < npts; ++k)
    {
      mesh.Triangles.push_back({ static_cast<int>(pts[0]), static_cast<int>(pts[k]), static_cast<int>(pts[k + 1]) });
    }
  }
  return mesh;
}
#endif

// vtkSDFCageFilter's "Nested Cages" port: one block per level, finest first, named by its count,
// with exactly that many vertices, each strictly enclosing the level inside it and the input
// (judged by the exact CGAL referee when it is built).
int TestNestedCagesPort(const Context&)
{
  Checker c("NestedCagesPort");
  NestedSetup s;
  vtkMultiBlockDataSet* levels = s.Levels();
  if (!c.Check(levels != nullptr, "port 3 is a vtkMultiBlockDataSet"))
  {
    return c.Result();
  }
  c.Check(std::string(s.Cager->GetStatusString()) == "Ok", std::string("status ") + s.Cager->GetStatusString());
  c.Check(levels->GetNumberOfBlocks() == 2, "two blocks, got " + Str(levels->GetNumberOfBlocks()));
  const int counts[2] = { 150, 60 };
  vtkPolyData* inner = s.Input;
  for (unsigned int i = 0; i < levels->GetNumberOfBlocks() && i < 2; ++i)
  {
    const std::string expected = "cage_" + std::to_string(counts[i]);
    c.Check(BlockName(levels, i) == expected, "block " + Str(i) + " named " + expected + ", got " + BlockName(levels, i));
    auto* level = vtkPolyData::SafeDownCast(levels->GetBlock(i));
    if (!c.Check(level != nullptr, "block " + Str(i) + " is a vtkPolyData"))
    {
      continue;
    }
    c.Check(level->GetNumberOfPoints() == counts[i],
      expected + ": " + Str(level->GetNumberOfPoints()) + " vertices, asked " + Str(counts[i]));
    c.Check(level->GetPointData()->GetArray("DistanceToInput") != nullptr, expected + ": DistanceToInput");
#ifdef SDFCAGE_HAVE_EXACT
    const sdfcage::TriangleMesh cage = ToMesh(level);
    for (vtkPolyData* inside : { inner, static_cast<vtkPolyData*>(s.Input) })
    {
      const sdfcage::exact::ExactReport r = sdfcage::exact::exactCheck(ToMesh(inside), cage, 0.0);
      c.Check(r.Encloses && r.MinimumClearance > 0,
        expected + " strictly encloses " + (inside == s.Input ? std::string("the input") : BlockName(levels, i - 1)) +
          " (exact referee, clearance " + Str(r.MinimumClearance) + ")");
    }
#endif
    inner = level;
  }
  // the single-cage port holds the finest level
  c.Check(s.Cager->GetOutput(0)->GetNumberOfPoints() == 150, "port 0 is the finest level");
  return c.Result();
}

// vtkCageQualityFilter on the nested levels: each judged against the next one in, the innermost
// against the input; a level judged against a level outside it is caught.
int TestQualityNestedLevels(const Context&)
{
  Checker c("QualityNestedLevels");
  NestedSetup s;
  vtkMultiBlockDataSet* levels = s.Levels();
  if (!c.Check(levels && levels->GetNumberOfBlocks() == 2, "two nested levels built"))
  {
    return c.Result();
  }
  vtkNew<vtkCageQualityFilter> quality;
  vtkNew<MessageRecorder> messages;
  messages->Watch(quality);
  quality->SetInputConnection(s.Cager->GetOutputPort(3));
  quality->SetSourceData(s.Input);
  quality->Update();
  auto* judged = vtkMultiBlockDataSet::SafeDownCast(quality->GetOutputDataObject(0));
  c.Check(quality->GetOutput() == nullptr, "GetOutput() is null for levels (a multiblock)");
  if (!c.Check(judged && judged->GetNumberOfBlocks() == 2, "the output has the two levels"))
  {
    return c.Result();
  }
  c.Check(quality->GetEncloses(), std::string("every level encloses the next one in: ") + quality->GetQualityMessage());
  double clearanceToInner[2] = { 0, 0 };
  for (unsigned int i = 0; i < 2; ++i)
  {
    auto* block = vtkPolyData::SafeDownCast(judged->GetBlock(i));
    const std::string name = BlockName(judged, i);
    c.Check(name == BlockName(levels, i), "block " + Str(i) + " keeps its name " + name);
    auto* original = vtkPolyData::SafeDownCast(levels->GetBlock(i));
    if (!c.Check(block && original && block->GetNumberOfPoints() == original->GetNumberOfPoints(),
          name + ": the level with its points"))
    {
      continue;
    }
    auto* against = vtkStringArray::SafeDownCast(block->GetFieldData()->GetAbstractArray("JudgedAgainst"));
    const std::string expected = i == 0 ? "input" : BlockName(levels, 0);
    c.Check(against && against->GetValue(0) == expected, name + ": judged against " + expected);
    c.Check(FieldValue(block, "Encloses") == 1, name + ": encloses the level inside it");
    c.Check(block->GetPointData()->GetArray("DistanceToInput") != nullptr &&
        block->GetCellData()->GetArray("MinimumAngle") != nullptr,
      name + ": per-point and per-cell arrays");
    clearanceToInner[i] = FieldValue(block, "MinimumClearance");
  }
  // the coarse level judged against the fine one, not the input: its clearance is the gap to
  // the fine level, smaller than its gap to the input
  vtkNew<vtkCageQualityFilter> single;
  single->SetInputData(levels->GetBlock(1));
  single->SetSourceData(s.Input);
  single->Update();
  c.Check(single->GetEncloses() && clearanceToInner[1] > 0 && clearanceToInner[1] < single->GetMinimumClearance(),
    "the outer level's clearance is to the inner level (" + Str(clearanceToInner[1]) + " < " +
      Str(single->GetMinimumClearance()) + " to the input)");
  c.Check(std::abs(quality->GetMinimumClearance() - clearanceToInner[1]) <= 1e-12 * clearanceToInner[1],
    "the filter's results are the outermost level's");
  c.Check(messages->Errors.empty(), "no errors");

  // the order reversed (coarse first): the fine level does not enclose the coarse one
  vtkNew<vtkMultiBlockDataSet> reversed;
  reversed->SetNumberOfBlocks(2);
  reversed->SetBlock(0, levels->GetBlock(1));
  reversed->SetBlock(1, levels->GetBlock(0));
  quality->SetInputData(reversed);
  quality->Update();
  c.Check(!quality->GetEncloses(), "reversed levels: the fine level does not enclose the coarse one");
  judged = vtkMultiBlockDataSet::SafeDownCast(quality->GetOutputDataObject(0));
  c.Check(judged && BlockName(judged, 1) == "block_1", "unnamed blocks get block_<i>");

  // a single level still gives a vtkPolyData
  quality->SetInputData(levels->GetBlock(0));
  quality->Update();
  c.Check(quality->GetOutput() != nullptr && quality->GetOutput()->GetNumberOfPoints() == 150 &&
      quality->GetEncloses(),
    "a single level: a vtkPolyData judged against the input");

  // a block that is not a surface: an error, empty output
  vtkNew<vtkMultiBlockDataSet> bad;
  bad->SetNumberOfBlocks(2);
  bad->SetBlock(0, levels->GetBlock(0));
  vtkNew<vtkMultiBlockDataSet> nestedBlock;
  bad->SetBlock(1, nestedBlock);
  quality->SetInputData(bad);
  messages->Watch(quality->GetExecutive());
  quality->Update();
  judged = vtkMultiBlockDataSet::SafeDownCast(quality->GetOutputDataObject(0));
  c.Check(messages->ErrorContains("not a vtkPolyData"), "a non-surface block is a clear error");
  c.Check(judged && judged->GetNumberOfBlocks() == 0 && !quality->GetEncloses(), "empty output on error");
  return c.Result();
}

int TestQualityAbort(const Context&)
{
  Checker c("QualityAbort");
  vtkNew<vtkCageQualityFilter> quality;
  quality->SetInputData(Cube(3.0, true));
  quality->SetSourceData(Sphere(1.0, 32));
  // abort from the first progress event (VTK 9.1 clears a flag set before Update)
  vtkNew<vtkCallbackCommand> abort;
  abort->SetCallback(
    [](vtkObject* caller, unsigned long, void*, void*) { static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1); });
  quality->AddObserver(vtkCommand::ProgressEvent, abort);
  quality->Update();
  quality->SetAbortExecute(0);
  c.Check(quality->GetOutput()->GetNumberOfPoints() == 0, "aborted: empty output");
  c.Check(!quality->GetEncloses(), "aborted: no verdict");
  return c.Result();
}
} // namespace

int main(int argc, char* argv[])
{
  const std::map<std::string, std::function<int(const Context&)>> cases = {
    { "QualityGoodCube", TestQualityGoodCube },
    { "QualityBrokenCages", TestQualityBrokenCages },
    { "QualityOfSDFCage", TestQualityOfSDFCage },
    { "QualityAbort", TestQualityAbort },
    { "QualityMixedCells", TestQualityMixedCells },
    { "NestedCagesPort", TestNestedCagesPort },
    { "QualityNestedLevels", TestQualityNestedLevels },
  };
  if (argc < 2 || cases.find(argv[1]) == cases.end())
  {
    std::cerr << "usage: " << argv[0] << " <case> [scratch dir]\n";
    return 2;
  }
  Context context;
  context.Scratch = argc > 2 ? argv[2] : ".";
  return cases.at(argv[1])(context);
}
