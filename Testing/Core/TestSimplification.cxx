// SDFCage — Testing: constrained QEM simplification (paper §3.2). Every cage is judged by the
// independent CGAL checker (exact predicates): closed 2-manifold, genus kept, no self-
// intersection, no cage/input intersection, every input vertex inside, clearance >= delta.
#include "Pipeline/CageGenerator.h"
#include "Envelope/Envelope.h"
#include "ExactCheck.h"
#include "Mesh/Normalization.h"
#include "Common/Progress.h"
#include "Mesh/Shapes.h"
#include "Simplification/Simplification.h"
#include "Spatial/TriangleTree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <string>

using namespace sdfcage;

namespace
{

/// A comb: a base bar with thin teeth, gaps wider than 2c so the envelope keeps them apart.
/// Coarse cages of it must not cut through the teeth.
TriangleMesh makeComb()
{
  TriangleMesh m = makeBox(Vec3(0, 0, 0), Vec3(2.0, 0.25, 0.3));
  for (int i = 0; i < 5; ++i)
  {
    const double x = 0.1 + i * 0.4;
    appendMesh(m, makeBox(Vec3(x, 0.25, 0.0), Vec3(x + 0.12, 1.2, 0.3)));
  }
  return m;
}

struct Case
{
  std::string Name;
  std::function<TriangleMesh()> Make;
};

std::vector<Case> cases()
{
  return { { "builtin", [] { return makeBuiltinShape(); } },
    { "torus", [] { return makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24); } } };
}

void expectValidCage(const TriangleMesh& input, const CageResult& r, const std::string& what)
{
  ASSERT_EQ(r.State, Status::Ok) << what << ": " << r.Message;
  // the clearance promised: the automatic one, or lowered by the topology repair
  const double delta = r.Normalize.lengthToInput(
    r.ClearanceUsedRelative > 0 ? r.ClearanceUsedRelative : CageOptions().Envelope.clearance());
  const exact::ExactReport e = exact::exactCheck(input, r.Cage, 4 * delta);
  std::cout << "[ cage     ] " << what << ": " << r.Cage.Points.size() << " vertices, clearance " << e.MinimumClearance
            << " (delta " << delta << "), genus " << e.CageGenus << " (envelope " << r.EnvelopeGenus
            << "), simplification " << r.SimplificationSeconds << " s\n";
  EXPECT_TRUE(e.Closed2Manifold) << what;
  EXPECT_EQ(e.SelfIntersections, 0) << what;
  EXPECT_EQ(e.InputIntersections, 0) << what;
  EXPECT_EQ(e.InputVerticesOutside, 0) << what;
  EXPECT_TRUE(e.Encloses) << what;
  EXPECT_EQ(e.CageGenus, r.EnvelopeGenus) << what;
  EXPECT_EQ(e.CageComponents, r.EnvelopeComponents) << what;
  EXPECT_GE(e.MinimumClearance, delta * (1 - 1e-9)) << what;
  // our own measurement agrees with the referee's (both are exact distances)
  EXPECT_NEAR(r.MinimumClearance, e.MinimumClearance, 1e-6 * delta + 1e-12) << what;
  ASSERT_EQ(r.CageDistanceToInput.size(), r.Cage.Points.size());
  for (double d : r.CageDistanceToInput)
    EXPECT_GE(d, delta * (1 - 1e-9)) << what;
}

} // namespace

TEST(Simplification, ExactVertexCountsAndGuarantees)
{
  for (const Case& c : cases())
  {
    const TriangleMesh input = c.Make();
    for (int n : { 500, 200, 50 })
    {
      CageOptions o;
      o.TargetNumberOfVertices = n;
      const CageResult r = generateCage(PolygonMesh::fromTriangles(input), o);
      const std::string what = c.Name + " @" + std::to_string(n);
      expectValidCage(input, r, what);
      if (r.TargetReached)
      {
        EXPECT_EQ(static_cast<int>(r.Cage.Points.size()), n) << what;
        EXPECT_TRUE(r.StopReason.empty()) << what;
      }
      else
      {
        // allowed only with a stated reason, and never below the target
        EXPECT_GT(static_cast<int>(r.Cage.Points.size()), n) << what;
        EXPECT_FALSE(r.StopReason.empty()) << what;
      }
      EXPECT_EQ(r.VerticesReached, static_cast<int>(r.Cage.Points.size())) << what;
    }
  }
}

TEST(Simplification, CoarseTargetsAreReached)
{
  // Coarse cages need vertices far outside the envelope (a 50-vertex torus cage sags by tens of
  // clearances between its vertices): the placement search must find them. The count must be
  // exact and the cage valid for the independent checker.
  const std::vector<std::pair<Case, int>> coarse = {
    { { "sphere", [] { return makeSphere(Vec3(0, 0, 0), 1.0, 24, 12); } }, 50 },
    { { "torus", [] { return makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24); } }, 50 },
    { { "torus", [] { return makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24); } }, 16 },
  };
  for (const auto& c : coarse)
  {
    const TriangleMesh input = c.first.Make();
    CageOptions o;
    o.TargetNumberOfVertices = c.second;
    const CageResult r = generateCage(PolygonMesh::fromTriangles(input), o);
    const std::string what = c.first.Name + " @" + std::to_string(c.second);
    expectValidCage(input, r, what);
    EXPECT_TRUE(r.TargetReached) << what << ": " << r.StopReason;
    EXPECT_EQ(static_cast<int>(r.Cage.Points.size()), c.second) << what;
  }
}

TEST(Simplification, PlainQEMFailsWhereConstrainedPasses)
{
  // (the comb of makeComb() shows the same, but its envelope needs the dense non-adaptive grid,
  // which makes the test slow; the built-in shape is enough to show it)
  for (const auto& shape : { std::make_pair(std::string("builtin"), makeBuiltinShape()) })
  {
    const TriangleMesh& input = shape.second;
    const Normalization n = Normalization::fit(input);
    const TriangleMesh unit = n.toUnit(input);
    const EnvelopeOptions eo;
    const EnvelopeResult env = buildEnvelope(unit, eo);
    ASSERT_EQ(env.State, Status::Ok) << env.Message;
    const TriangleTree tree(unit);
    SimplifyOptions so;
    so.TargetNumberOfVertices = 40;
    so.Clearance = eo.clearance();
    SimplifyOptions plain = so;
    plain.EnforceClearance = false;
    plain.EnforceNoSelfIntersection = false;
    const SimplifyResult ours = simplifyEnvelope(env.Envelope, tree, so);
    const SimplifyResult qem = simplifyEnvelope(env.Envelope, tree, plain);
    const exact::ExactReport eOurs = exact::exactCheck(unit, ours.Cage, 4 * so.Clearance);
    const exact::ExactReport eQem = exact::exactCheck(unit, qem.Cage, 4 * so.Clearance);
    std::cout << "[ qem      ] " << shape.first << ": plain QEM " << qem.VerticesReached << " vertices, encloses "
              << eQem.Encloses << ", input intersections " << eQem.InputIntersections << ", outside "
              << eQem.InputVerticesOutside << "; constrained " << ours.VerticesReached << " vertices, encloses "
              << eOurs.Encloses << ", clearance " << eOurs.MinimumClearance << "\n";
    EXPECT_FALSE(eQem.Encloses && eQem.MinimumClearance >= so.Clearance) << shape.first;
    EXPECT_TRUE(eOurs.Encloses) << shape.first;
    EXPECT_GE(eOurs.MinimumClearance, so.Clearance * (1 - 1e-9)) << shape.first;
    EXPECT_EQ(eOurs.CageGenus, env.Genus) << shape.first;
  }
}

TEST(Simplification, DebrisIsNeverSweptOut)
{
  // A sphere with 200 tiny triangles (0.004 across) floating 0.016 above it: their offsets fuse
  // with the sphere's into bumps that the simplification flattens. Without the input's component
  // probes a collapse can jump over a fragment (no new triangle comes near it) and leave it
  // outside; with them, the cage keeps every fragment inside.
  TriangleMesh input = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
  for (int i = 0; i < 200; ++i)
  {
    const double z = 1.0 - (i + 0.5) / 100.0, r = std::sqrt(1.0 - z * z), phi = 2.399963 * i;
    const Vec3 u(r * std::cos(phi), r * std::sin(phi), z);
    const Vec3 a = u.unitOrthogonal(), b = u.cross(a), c = 1.016 * u;
    const int base = static_cast<int>(input.Points.size());
    input.Points.push_back(c + 0.002 * a);
    input.Points.push_back(c - 0.001 * a + 0.0017 * b);
    input.Points.push_back(c - 0.001 * a - 0.0017 * b);
    input.Triangles.push_back({ base, base + 1, base + 2 });
  }
  const Normalization n = Normalization::fit(input);
  const TriangleMesh unit = n.toUnit(input);
  EnvelopeOptions eo;
  eo.Sign = SignMode::WindingNumber;
  const EnvelopeResult env = buildEnvelope(unit, eo);
  ASSERT_EQ(env.State, Status::Ok) << env.Message;
  const TriangleTree tree(unit);
  SimplifyOptions so;
  so.TargetNumberOfVertices = 300;
  so.Clearance = eo.clearance();
  const std::vector<Vec3> probes = componentProbes(unit);
  ASSERT_EQ(probes.size(), 201u);
  const SimplifyResult with = simplifyEnvelope(env.Envelope, tree, so, nullptr, &probes);
  const SimplifyResult without = simplifyEnvelope(env.Envelope, tree, so);
  const exact::ExactReport eWith = exact::exactCheck(unit, with.Cage, 4 * so.Clearance);
  const exact::ExactReport eWithout = exact::exactCheck(unit, without.Cage, 4 * so.Clearance);
  std::cout << "[ debris   ] with probes " << with.VerticesReached << " vertices, encloses " << eWith.Encloses
            << ", input vertices outside " << eWith.InputVerticesOutside << "; without " << without.VerticesReached
            << " vertices, encloses " << eWithout.Encloses << ", outside " << eWithout.InputVerticesOutside << "\n";
  EXPECT_TRUE(eWith.Encloses);
  EXPECT_EQ(eWith.InputVerticesOutside, 0);
  EXPECT_EQ(eWith.InputIntersections, 0);
  EXPECT_GE(eWith.MinimumClearance, so.Clearance * (1 - 1e-9));
  EXPECT_FALSE(eWithout.Encloses) << "the case no longer shows the jump over a fragment";
}

TEST(Simplification, DeterministicAcrossThreadCounts)
{
  // the built-in shape: its adaptive envelope verifies, which keeps this test quick
  const TriangleMesh input = makeBuiltinShape();
  CageOptions a, b;
  a.TargetNumberOfVertices = b.TargetNumberOfVertices = 400;
  a.NumberOfThreads = 1;
  b.NumberOfThreads = 2;
  const CageResult ra = generateCage(PolygonMesh::fromTriangles(input), a);
  const CageResult rb = generateCage(PolygonMesh::fromTriangles(input), b);
  ASSERT_EQ(ra.State, Status::Ok);
  ASSERT_EQ(rb.State, Status::Ok);
  ASSERT_EQ(ra.Cage.Points.size(), rb.Cage.Points.size());
  ASSERT_EQ(ra.Cage.Triangles.size(), rb.Cage.Triangles.size());
  for (std::size_t i = 0; i < ra.Cage.Points.size(); ++i)
    EXPECT_EQ(ra.Cage.Points[i], rb.Cage.Points[i]) << i;
  EXPECT_EQ(ra.Cage.Triangles, rb.Cage.Triangles);
}

TEST(Simplification, CancelGivesAValidCoarserCage)
{
  class CancelMidway : public Progress
  {
  protected:
    void report(double overall, const std::string& stage) override
    {
      // late in the simplification ([0.45, 0.95] of the run): a cage cut short is output only
      // when it is verified within 0.15 s of the cancel (GracePeriod), which a cage cut at 0.6
      // (some 14,000 vertices) missed on a loaded machine
      if (stage == "simplifying" && overall > 0.9)
        this->cancel();
    }
  };
  const TriangleMesh input = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24);
  CancelMidway p;
  CageOptions o;
  o.TargetNumberOfVertices = 50;
  const CageResult r = generateCage(PolygonMesh::fromTriangles(input), o, &p);
  EXPECT_EQ(r.State, Status::Cancelled);
#if defined(__SANITIZE_ADDRESS__)
  if (r.Cage.empty()) // ten times slower: the verification may not end within the grace
    GTEST_SKIP() << "sanitized build: the cage so far was not verified within the grace";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  if (r.Cage.empty())
    GTEST_SKIP() << "sanitized build: the cage so far was not verified within the grace";
#endif
#endif
  ASSERT_FALSE(r.Cage.empty());
  EXPECT_GT(r.Cage.Points.size(), 50u);
  EXPECT_LT(r.Cage.Points.size(), r.Envelope.Points.size());
  const double delta = r.Normalize.lengthToInput(o.Envelope.clearance());
  const exact::ExactReport e = exact::exactCheck(input, r.Cage, 4 * delta);
  EXPECT_TRUE(e.Encloses);
  EXPECT_GE(e.MinimumClearance, delta * (1 - 1e-9));
}

TEST(Simplification, ZeroTargetKeepsTheEnvelope)
{
  CageOptions o;
  o.TargetNumberOfVertices = 0;
  const CageResult r = generateCage(PolygonMesh::fromTriangles(makeSphere(Vec3(0, 0, 0), 1.0, 24, 12)), o);
  ASSERT_EQ(r.State, Status::Ok);
  EXPECT_EQ(r.Cage.Points.size(), r.Envelope.Points.size());
  EXPECT_EQ(r.Cage.Triangles, r.Envelope.Triangles);
}

// A simplification that stalls above the target (every remaining collapse would fold a sliver or
// crowd a neighbour) is relaxed (one MIPS sweep, every guarantee kept) and goes on
// (CageOptions::MaximumRelaxations). Without it, these stop above the target: the torus at 13
// of 12 vertices, the three hooks 0.004 apart (four parts) at 97 of 80. (The hooks 0.008 apart
// stalled at 136 of 100 until their shape stopped crossing itself: now they reach 100.)
TEST(Simplification, StalledCagesAreRelaxedAndReachTheTarget)
{
  const std::vector<std::pair<Case, int>> stalled = {
    { { "torus", [] { return makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24); } }, 12 },
    { { "cluster 0.004", [] { return makeGapShape(GapShape::Cluster, 0.004); } }, 80 },
  };
  for (const auto& c : stalled)
  {
    const TriangleMesh input = c.first.Make();
    const std::string what = c.first.Name + " @" + std::to_string(c.second);
    CageOptions o;
    o.TargetNumberOfVertices = c.second;
    o.MaximumRelaxations = 0;
    const CageResult plain = generateCage(PolygonMesh::fromTriangles(input), o);
    ASSERT_EQ(plain.State, Status::Ok) << what << ": " << plain.Message;
    EXPECT_EQ(plain.Relaxations, 0) << what;
    EXPECT_EQ(plain.VerticesBeforeRelaxation, 0) << what;
    std::cout << "[ relax    ] " << what << " without relaxation: " << plain.VerticesReached << " vertices ("
              << plain.StopReason << ")\n";
    EXPECT_GT(plain.VerticesReached, c.second) << what << ": the case no longer stalls; it tests nothing";

    o.MaximumRelaxations = CageOptions().MaximumRelaxations;
    const CageResult r = generateCage(PolygonMesh::fromTriangles(input), o);
    std::cout << "[ relax    ] " << what << ": stalled at " << r.VerticesBeforeRelaxation << ", " << r.Relaxations
              << " relaxation(s) (" << r.RelaxationSeconds << " s), " << r.VerticesReached << " vertices\n";
    expectValidCage(input, r, what);
    EXPECT_TRUE(r.TargetReached) << what << ": " << r.StopReason;
    EXPECT_EQ(static_cast<int>(r.Cage.Points.size()), c.second) << what;
    EXPECT_GE(r.Relaxations, 1) << what;
    EXPECT_GT(r.VerticesBeforeRelaxation, c.second) << what;
    EXPECT_GT(r.RelaxationSeconds, 0.0) << what;
    EXPECT_LE(r.RelaxationSeconds, r.SimplificationSeconds) << what;
    // the genus and parts are the input's (the cluster keeps its four parts apart)
    const exact::ExactReport e = exact::exactCheck(input, r.Cage, 0.0);
    EXPECT_EQ(e.CageComponents, plain.EnvelopeComponents) << what;
    EXPECT_EQ(e.CageGenus, plain.EnvelopeGenus) << what;
  }
}
