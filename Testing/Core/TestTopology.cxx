// SDFCage — Testing: the envelope keeps the input's topology where parts nearly touch, also close
// to where they join (issue: the paper's r/l rule misses those). Generated closed shapes with
// gaps from 0.004 to 0.03 (unit-sphere units); each cage is judged by the CGAL referee.
#include "CoreTestPrinters.h"
#include "ExactCheck.h"
#include "MeshIO.h"
#include "Mesh/Mesh.h"
#include "Mesh/Normalization.h"
#include "Mesh/Shapes.h"
#include "Mesh/Validation.h"
#include "Envelope/ActivePointAnalysis.h"
#include "Envelope/ActivePoints.h"
#include "Envelope/Envelope.h"
#include "Pipeline/CageGenerator.h"
#include "Pipeline/Results.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <tuple>
#include <vector>

using namespace sdfcage;

namespace
{

const char* shapeName(GapShape s)
{
  switch (s)
  {
    case GapShape::Hook:
      return "hook";
    case GapShape::Cluster:
      return "cluster";
    case GapShape::Ring:
      return "ring";
    case GapShape::Comb:
      return "comb";
  }
  return "?";
}

} // namespace

TEST(GapShapes, ClosedGenusZeroSelfIntersectionFree)
{
  for (GapShape s : { GapShape::Hook, GapShape::Cluster, GapShape::Ring, GapShape::Comb })
    for (double gap : { 0.004, 0.01, 0.03 })
  {
    SCOPED_TRACE(gap);
    const TriangleMesh m = makeGapShape(s, gap);
    const MeshDefects d = checkTriangleMesh(m);
    EXPECT_TRUE(d.usable()) << shapeName(s);
    EXPECT_EQ(genus(m), 0) << shapeName(s);
    std::vector<int> comp;
    EXPECT_EQ(triangleComponents(m, comp), s == GapShape::Cluster ? 4 : s == GapShape::Ring ? 2 : 1) << shapeName(s);
    // the referee on the shape itself (as a "cage" around a far-away speck)
    const TriangleMesh speck = makeBox(Vec3(5, 5, 5), Vec3(5.001, 5.001, 5.001));
    const exact::ExactReport e = exact::exactCheck(speck, m, 0.0);
    EXPECT_EQ(e.SelfIntersections, 0) << shapeName(s);
    // the named gap, in unit-sphere units: the closest distance between its two sides is the
    // gap (the hook's tip and its straight part are one component: measured with the tip cut off)
    if (s == GapShape::Cluster)
    {
      const TriangleMesh unit = Normalization::fit(m).toUnit(m);
      TriangleMesh a, b;
      for (std::size_t k = 0; k < unit.Triangles.size(); ++k)
      {
        (comp[k] == comp[0] ? a : b).Triangles.push_back(unit.Triangles[k]);
      }
      a.Points = b.Points = unit.Points;
      const exact::ExactReport g = exact::exactCheck(a, b, 1.0);
      EXPECT_NEAR(g.MinimumClearance, gap, 1e-6);
    }
  }
}

namespace
{

/// At the defaults: the cage keeps the input's genus and parts, and the referee accepts it.
void expectTopologyKept(GapShape s, double gap)
{
  const TriangleMesh m = makeGapShape(s, gap);
  CageOptions o;
  const CageResult r = generateCage(PolygonMesh::fromTriangles(m), o);
  std::printf("%-8s gap %.3f: input genus %d, %d part(s); envelope %d, %d; cage %d vertices; %zu active "
              "points; %d repair round(s); clearance %.4g; %.2f s\n  %s\n",
    shapeName(s), gap, r.InputGenus, r.InputComponents, r.EnvelopeGenus, r.EnvelopeComponents, r.VerticesReached,
    r.NumberOfActivePoints, r.TopologyRepairs, r.ClearanceUsedRelative, r.TotalSeconds, r.TopologyRepairLog.c_str());
  ASSERT_EQ(r.State, Status::Ok) << r.Message;
  // below about twice the default clearance the repair lowers the clearance to 0.001, and three
  // parts 0.004 apart then stall the simplification above the target (651 of 500 vertices):
  // topology and the guarantees are asserted there, the count within 1.5 times the target
  if (gap >= 0.008)
  {
    EXPECT_TRUE(r.TargetReached) << r.VerticesReached;
  }
  else
  {
    EXPECT_LE(r.VerticesReached, 750);
  }
  EXPECT_EQ(r.EnvelopeGenus, r.InputGenus);
  EXPECT_EQ(r.EnvelopeComponents, r.InputComponents);
  EXPECT_TRUE(r.TopologyWarning.empty()) << r.TopologyWarning;
  // the log gives every round's time
  std::size_t timed = 0;
  for (std::size_t at = r.TopologyRepairLog.find(" s)"); at != std::string::npos;
       at = r.TopologyRepairLog.find(" s)", at + 1))
    ++timed;
  EXPECT_EQ(static_cast<int>(timed), r.TopologyRepairs) << r.TopologyRepairLog;
  const exact::ExactReport e = exact::exactCheck(m, r.Cage, 0.0);
  EXPECT_TRUE(e.Closed2Manifold);
  EXPECT_EQ(e.SelfIntersections, 0);
  EXPECT_EQ(e.InputIntersections, 0);
  EXPECT_EQ(e.InputVerticesOutside, 0);
  EXPECT_EQ(e.CageGenus, r.InputGenus);
  EXPECT_EQ(e.CageComponents, r.InputComponents);
}

} // namespace

class GapTopology : public ::testing::TestWithParam<std::tuple<GapShape, double>>
{
};

TEST_P(GapTopology, KeptAtDefaults)
{
  expectTopologyKept(std::get<0>(GetParam()), std::get<1>(GetParam()));
}

INSTANTIATE_TEST_SUITE_P(Gaps, GapTopology,
  ::testing::Combine(::testing::Values(GapShape::Hook, GapShape::Cluster, GapShape::Ring, GapShape::Comb),
    ::testing::Values(0.004, 0.008, 0.015, 0.03)),
  [](const ::testing::TestParamInfo<std::tuple<GapShape, double>>& info) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%03d", shapeName(std::get<0>(info.param)),
      static_cast<int>(std::get<1>(info.param) * 1000 + 0.5));
    return std::string(name);
  });

// A repair round's finer grid merges polygons wherever its few amplified samples leave room
// (adaptivity 1, uniform triangles only where phi > 1 + 0.5 (alpha - 1)): the hook whose tip is
// 0.015 from its straight part takes one round, and that round's merged envelope is the one kept.
// It is verified like any other: the referee checks it encloses the input with the clearance, and
// it keeps the input's topology. With adaptivity off everywhere the same round gives more
// triangles.
// A clearance or an alpha that would put the envelope at the active points (about c / alpha
// from the input) within the clearance used to fail verification on every finer grid (the
// built-in shape at clearance 0.0035: 63 s, 2.1 GB, no cage; alpha 6: 59 s, no cage). The
// alpha is lowered to c / (1.15 delta) and reported; the gap stays open.
TEST(ActivePointAlpha, LoweredWhereItWouldPutTheEnvelopeWithinTheClearance)
{
  const TriangleMesh m = makeBuiltinShape();
  struct Case
  {
    double Clearance, Alpha;
  };
  for (const Case k : { Case{ 0.0035, 3.0 }, Case{ 0.0, 6.0 }, Case{ 0.0, 3.0 } })
  {
    CageOptions o;
    o.Envelope.MinimumClearance = k.Clearance;
    o.Envelope.ActivePoints.Alpha = k.Alpha;
    o.TargetNumberOfVertices = 300;
    const CageResult r = generateCage(PolygonMesh::fromTriangles(m), o);
    ASSERT_EQ(r.State, Status::Ok) << "clearance " << k.Clearance << ", alpha " << k.Alpha << ": " << r.Message;
    const double room = o.Envelope.IsoValue / (1.15 * o.Envelope.clearance());
    EXPECT_NEAR(r.AlphaUsed, std::min(k.Alpha, room), 1e-9) << "clearance " << k.Clearance << ", alpha " << k.Alpha;
    EXPECT_GE(r.MinimumClearanceRelative, o.Envelope.clearance() * (1 - 1e-9));
    EXPECT_EQ(static_cast<int>(r.Cage.Points.size()), 300);
    const ResultTable table = cageResults(r);
    const ResultField* reported = findResult(table, "AmplificationAlphaUsed");
    ASSERT_NE(reported, nullptr);
    EXPECT_DOUBLE_EQ(reported->number(), r.AlphaUsed);
    // the referee: enclosed, no crossing, the two parts kept apart
    const exact::ExactReport e = exact::exactCheck(m, r.Cage, 0.0);
    EXPECT_TRUE(e.Encloses);
    EXPECT_EQ(e.CageComponents, 2);
    EXPECT_EQ(e.CageGenus, 1);
    EXPECT_GE(e.MinimumClearance, r.MinimumClearance * (1 - 1e-6));
  }
}

namespace
{

/// The envelope of the hook whose tip is `gap` from its straight part (unit-sphere units, in
/// `unit`) at the defaults, after `rounds` repair rounds: genus 0, one part, verified, and judged
/// by the referee (enclosing, no crossing, at least `clearance` from the input).
EnvelopeResult repairedHook(double gap, int rounds, double clearance, TriangleMesh& unit)
{
  const TriangleMesh world = makeGapShape(GapShape::Hook, gap);
  unit = Normalization::fit(world).toUnit(world);
  const EnvelopeResult r = buildEnvelope(unit, EnvelopeOptions());
  EXPECT_EQ(r.State, Status::Ok) << r.Message;
  EXPECT_EQ(r.TopologyRepairs, rounds) << r.TopologyRepairLog;
  EXPECT_EQ(r.Genus, 0);
  EXPECT_EQ(r.Components, 1);
  EXPECT_TRUE(r.EnclosureVerified);
  const exact::ExactReport e = exact::exactCheck(unit, r.Envelope, 0.0);
  EXPECT_TRUE(e.Encloses);
  EXPECT_EQ(e.SelfIntersections, 0);
  EXPECT_GE(e.MinimumClearance, clearance * (1.0 - 1e-9));
  EXPECT_EQ(e.CageGenus, 0);
  EXPECT_EQ(e.CageComponents, 1);
  return r;
}

} // namespace

TEST(TopologyRepair, FirstRoundMergesPolygonsAwayFromTheGap)
{
  EnvelopeOptions o;
  TriangleMesh unit;
  const EnvelopeResult merged = repairedHook(0.015, 1, o.clearance(), unit);
  ASSERT_EQ(merged.State, Status::Ok);
  EXPECT_DOUBLE_EQ(merged.AdaptivityUsed, 1.0);
  EXPECT_DOUBLE_EQ(merged.VoxelSizeUsed, 0.5 * o.voxelSize());
  // the round's grid exact only near the gap (EnvelopeOptions::LocalExactDilation), and that
  // envelope kept: not run again on the whole exact grid
  EXPECT_GT(merged.ExactVoxels, 0u);
  EXPECT_NE(merged.TopologyRepairLog.find("with the grid exact near the gaps only ("), std::string::npos)
    << merged.TopologyRepairLog;
  EXPECT_EQ(merged.TopologyRepairLog.find("on the exact grid"), std::string::npos) << merged.TopologyRepairLog;

  o.Adaptivity = 0.0;
  const EnvelopeResult uniform = buildEnvelope(unit, o);
  ASSERT_EQ(uniform.State, Status::Ok) << uniform.Message;
  EXPECT_EQ(uniform.TopologyRepairs, 1) << uniform.TopologyRepairLog;
  EXPECT_EQ(uniform.Genus, 0);
  EXPECT_LT(2 * merged.Envelope.Triangles.size(), uniform.Envelope.Triangles.size());

  // the run reports the kept envelope's adaptivity (the CLI summary and the field data show it)
  const CageResult cage = generateCage(PolygonMesh::fromTriangles(makeGapShape(GapShape::Hook, 0.015)), CageOptions());
  ASSERT_EQ(cage.State, Status::Ok) << cage.Message;
  EXPECT_EQ(cage.TopologyRepairs, 1);
  EXPECT_DOUBLE_EQ(cage.AdaptivityUsed, 1.0);
  const ResultTable table = cageResults(cage);
  const ResultField* used = findResult(table, "AdaptivityUsed");
  ASSERT_NE(used, nullptr);
  EXPECT_DOUBLE_EQ(used->number(), 1.0);
}

// The second round keeps the requested adaptivity, and its merged envelope is the one kept: near
// the active points the adaptivity mask keeps the triangles uniform. OpenVDB's mesher reads that
// mask by leaf and merged freely under the active tiles the mask's dilation made, so the merged
// envelope came within the clearance there (0.00025 against 0.001), the round fell back to
// uniform triangles (454k instead of 51k) and the whole run took 10.9 s instead of 2.2 s.
TEST(TopologyRepair, SecondRoundKeepsItsMergedPolygons)
{
  const EnvelopeOptions o;
  TriangleMesh unit;
  const EnvelopeResult r = repairedHook(0.008, 2, 0.4 * o.clearance(), unit);
  ASSERT_EQ(r.State, Status::Ok);
  EXPECT_DOUBLE_EQ(r.VoxelSizeUsed, 0.25 * o.voxelSize());
  EXPECT_DOUBLE_EQ(r.AdaptivityUsed, o.Adaptivity);
  EXPECT_LT(r.Envelope.Triangles.size(), 150000u);
}

// The strict option: with the repair off, a hook whose tip is 0.004 from its own straight part
// fuses (a handle appears) and RequireTopology gives no cage; the default keeps a warned cage.
TEST(GapTopologyStrict, RequireTopologyGivesNoCage)
{
  const TriangleMesh m = makeGapShape(GapShape::Hook, 0.004);
  CageOptions o;
  o.Envelope.MaximumTopologyRepairs = 0;
  const CageResult warned = generateCage(PolygonMesh::fromTriangles(m), o);
  ASSERT_EQ(warned.State, Status::Ok) << warned.Message;
  EXPECT_NE(warned.EnvelopeGenus, 0);
  EXPECT_FALSE(warned.TopologyWarning.empty());
  EXPECT_FALSE(warned.Cage.empty());
  o.Envelope.RequireTopology = true;
  const CageResult strict = generateCage(PolygonMesh::fromTriangles(m), o);
  EXPECT_EQ(strict.State, Status::TopologyChanged);
  EXPECT_TRUE(strict.Cage.empty());
  EXPECT_FALSE(strict.Message.empty());
}

// The facing-gap rule finds the hook's tip and the part below it, which the paper's r/l rule
// misses (they are close along the surface), and leaves a plain tube inactive.
TEST(GapRule, FindsTheHookTipOnly)
{
  const TriangleMesh world = makeGapShape(GapShape::Hook, 0.008);
  const Normalization n = Normalization::fit(world);
  const TriangleMesh hook = n.toUnit(world);
  ActivePointOptions paper;
  const ActivePoints a = computeActivePoints(hook, paper);
  ActivePointOptions gap = paper;
  gap.GapRatio = 3.0;
  const ActivePoints b = computeActivePoints(hook, gap);
  EXPECT_GT(b.NumberOfGapSamples, 0u);
  EXPECT_GT(b.NumberOfActiveSamples, a.NumberOfActiveSamples);
  // every gap sample lies near the tip or the part below it (in the shape's own coordinates the
  // hook's bend spans x in [-0.06, 0.02], y in [-0.02, 0.07]; the straight part runs to x = -1.9)
  for (int id : b.GapSamples)
  {
    const Vec3 p = n.toInput(b.Surface.Points[id]);
    EXPECT_LT(p.y(), 0.08) << p.transpose();
    EXPECT_GT(p.x(), -0.15) << p.transpose();
  }
  std::vector<Vec3> line{ Vec3(-0.9, 0, 0), Vec3(0.9, 0, 0) };
  const TriangleMesh tube = makeTube(roundedPolyline(line, 0.02, 0.008), 0.012, 16, Vec3(0, 1, 0));
  const ActivePoints c = computeActivePoints(tube, gap);
  EXPECT_EQ(c.NumberOfActiveSamples, 0u);
}

// What the Active Points filter shows (analyzeActivePoints, in the shape's own coordinates): with
// the gap rule on, the hook's tip and the part below it are active by that rule (ActiveRule 2),
// every other active point by the paper's (1); with it off no point has rule 2.
TEST(GapRule, TheAnalysisTellsWhichRuleMadeAPointActive)
{
  const TriangleMesh hook = makeGapShape(GapShape::Hook, 0.008);
  ActivePointAnalysisOptions options;
  const ActivePointAnalysis paper = analyzeActivePoints(PolygonMesh::fromTriangles(hook), options);
  ASSERT_EQ(paper.State, Status::Ok) << paper.Message;
  options.ActivePoints.GapRatio = 3.0;
  const ActivePointAnalysis gap = analyzeActivePoints(PolygonMesh::fromTriangles(hook), options);
  ASSERT_EQ(gap.State, Status::Ok) << gap.Message;
  EXPECT_EQ(paper.NumberOfGapSamples, 0u);
  EXPECT_EQ(paper.NumberOfGapRulePoints, 0u);
  EXPECT_GT(gap.NumberOfGapSamples, 0u);
  EXPECT_GT(gap.NumberOfGapRulePoints, 0u);
  for (const ActivePointAnalysis* a : { &paper, &gap })
  {
    ASSERT_EQ(a->ActiveRule.size(), a->Mesh.Points.size());
    std::size_t byGap = 0;
    for (std::size_t i = 0; i < a->Mesh.Points.size(); ++i)
    {
      EXPECT_EQ(a->ActiveRule[i] != 0, a->Active[i] != 0) << i;
      EXPECT_LE(a->ActiveRule[i], 2);
      if (a->ActiveRule[i] == 2)
      {
        ++byGap;
        // near the tip or the part below it (the bend spans x in [-0.06, 0.02], y in [-0.02, 0.07])
        const Vec3& p = a->Mesh.Points[i];
        EXPECT_LT(p.y(), 0.09) << p.transpose();
        EXPECT_GT(p.x(), -0.17) << p.transpose();
      }
    }
    EXPECT_EQ(byGap, a->NumberOfGapRulePoints);
  }
  // the gap rule adds active points where the paper's finds none
  EXPECT_GT(gap.NumberOfActivePoints, paper.NumberOfActivePoints);
}

// Writes the shapes for manual runs (a tool, not a test: disabled): SDFCAGE_WRITE_GAP_SHAPES=folder
// SDFCageCoreTests --gtest_also_run_disabled_tests --gtest_filter=GapShapes.DISABLED_Write*
TEST(GapShapes, DISABLED_WriteForManualRuns)
{
  const char* dir = std::getenv("SDFCAGE_WRITE_GAP_SHAPES");
  if (!dir)
  {
    GTEST_SKIP() << "set SDFCAGE_WRITE_GAP_SHAPES=folder to write the shapes";
  }
  for (GapShape s : { GapShape::Hook, GapShape::Cluster, GapShape::Ring, GapShape::Comb })
  {
    for (double gap : { 0.004, 0.008, 0.015, 0.03 })
    {
      char name[256];
      std::snprintf(name, sizeof name, "%s/%s_%.3f.off", dir, shapeName(s), gap);
      EXPECT_TRUE(exact::writeOFF(name, makeGapShape(s, gap)));
    }
  }
}
