// SDFCage — Testing: cage optimization (paper §3.3). Every optimized cage is judged by the
// independent CGAL checker (exact predicates): closed 2-manifold, same vertex count and genus, no
// self-intersection, no cage/input intersection, every input vertex inside, clearance >= delta.
#include "Pipeline/CageGenerator.h"
#include "ExactCheck.h"
#include "Spatial/Geometry.h"
#include "Mesh/Normalization.h"
#include "Optimization/Optimization.h"
#include "Quality/CageQuality.h"
#include "Common/Progress.h"
#include "Mesh/Shapes.h"
#include "Spatial/TriangleTree.h"
#include "SpacingBand.h"

#include <gtest/gtest.h>

#include <mutex>

#include <algorithm>
#include <cmath>
#include <limits>
#include <iostream>

using namespace sdfcage;

namespace
{

CageResult makeCage(const TriangleMesh& input, int vertices)
{
  CageOptions o;
  o.TargetNumberOfVertices = vertices;
  return generateCage(PolygonMesh::fromTriangles(input), o);
}

void expectGuarantees(const TriangleMesh& input, const TriangleMesh& before, const OptimizeResult& r,
  double deltaInputUnits, const std::string& what)
{
  ASSERT_EQ(r.State, Status::Ok) << what << ": " << r.Message;
  EXPECT_FALSE(r.Reverted) << what << ": " << r.Message;
  EXPECT_EQ(r.Cage.Points.size(), before.Points.size()) << what;
  EXPECT_EQ(r.Cage.Triangles.size(), before.Triangles.size()) << what;
  const exact::ExactReport e = exact::exactCheck(input, r.Cage, 4 * deltaInputUnits);
  const exact::ExactReport e0 = exact::exactCheck(input, before, 4 * deltaInputUnits);
  std::cout << "[ optimize ] " << what << ": energy " << r.EnergyBefore << " -> " << r.EnergyAfter << ", min angle "
            << r.MinimumAngleBefore << " -> " << r.MinimumAngleAfter << " deg, moves " << r.Moves << " (rejected "
            << r.RejectedMoves << "), flips " << r.Flips << " (vetoed " << r.RejectedFlips << "), exact clearance "
            << e.MinimumClearance << " (delta " << deltaInputUnits << "), " << r.Seconds << " s (relocation "
            << r.RelocationSeconds << " s, flips " << r.FlipSeconds << " s)\n";
  EXPECT_TRUE(e.Closed2Manifold) << what;
  EXPECT_EQ(e.SelfIntersections, 0) << what;
  EXPECT_EQ(e.InputIntersections, 0) << what;
  EXPECT_EQ(e.InputVerticesOutside, 0) << what;
  EXPECT_TRUE(e.Encloses) << what;
  EXPECT_EQ(e.CageGenus, e0.CageGenus) << what;
  EXPECT_EQ(e.CageComponents, e0.CageComponents) << what;
  EXPECT_GE(e.MinimumClearance, deltaInputUnits * (1 - 1e-9)) << what;
  // the exact check measures clearances up to its cap (4 delta) and reports the cap beyond it
  const double cap = 4 * deltaInputUnits;
  if (e.MinimumClearance < cap * (1 - 1e-9))
    EXPECT_NEAR(r.MinimumClearance, e.MinimumClearance, 1e-6 * deltaInputUnits + 1e-12) << what;
  else
    EXPECT_GE(r.MinimumClearance, cap * (1 - 1e-6)) << what;
  ASSERT_EQ(r.DistanceToInput.size(), r.Cage.Points.size()) << what;
  EXPECT_TRUE(r.Moves > 0 || r.Flips > 0) << what << ": nothing changed";
}

/// Area-weighted mean and standard deviation of (distance to the input - h) over samples of the
/// cage (a barycentric grid of 15 points per triangle, corners included), unit-sphere units.
void spacingStatistics(const TriangleMesh& unitCage, const TriangleTree& tree, double h, double& mean, double& stddev)
{
  double w = 0.0, s1 = 0.0, s2 = 0.0;
  const int n = 4;
  for (const Triangle& t : unitCage.Triangles)
  {
    const Vec3& a = unitCage.Points[t[0]];
    const Vec3& b = unitCage.Points[t[1]];
    const Vec3& c = unitCage.Points[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
      {
        const Vec3 x = (double(i) * a + double(j) * b + double(n - i - j) * c) / n;
        const double e = tree.distance(x) - h;
        w += area;
        s1 += area * e;
        s2 += area * e * e;
      }
  }
  mean = s1 / w;
  stddev = std::sqrt(std::max(0.0, s2 / w - mean * mean));
}

} // namespace

TEST(Optimization, GuaranteesOnGeneratedShapes)
{
  struct Shape
  {
    const char* Name;
    TriangleMesh Mesh;
  };
  const Shape shapes[] = { { "builtin", makeBuiltinShape() }, { "torus", makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24) } };
  for (const Shape& s : shapes)
  {
    const CageResult cage = makeCage(s.Mesh, 300);
    ASSERT_EQ(cage.State, Status::Ok) << s.Name << ": " << cage.Message;
    const double delta = cage.Normalize.lengthToInput(CageOptions().Envelope.clearance());
    for (CageEnergy energy : { CageEnergy::MIPS, CageEnergy::Spacing })
    {
      OptimizeOptions o;
      o.Energy = energy;
      o.Clearance = CageOptions().Envelope.clearance();
      const OptimizeResult r = optimizeCageInInputUnits(cage.Cage, s.Mesh, o);
      expectGuarantees(s.Mesh, cage.Cage, r, delta, std::string(s.Name) + " " + energyName(energy));
      EXPECT_LT(r.EnergyAfter, r.EnergyBefore) << s.Name << " " << energyName(energy);
      if (energy == CageEnergy::MIPS)
        EXPECT_GT(r.MinimumAngleAfter, r.MinimumAngleBefore) << s.Name << ": the worst triangle improves";
    }
  }
}

TEST(Optimization, MIPSImprovesBadTriangles)
{
  // a UV sphere cage around a finer sphere: thin triangles at the poles
  const TriangleMesh input = makeSphere(Vec3(0, 0, 0), 1.0, 48, 24);
  const TriangleMesh cage = makeSphere(Vec3(0, 0, 0), 1.1, 24, 12);
  OptimizeOptions o;
  o.Energy = CageEnergy::MIPS;
  o.NumberOfIterations = 2;
  const OptimizeResult r = optimizeCageInInputUnits(cage, input, o);
  expectGuarantees(input, cage, r, 0.0025, "UV sphere MIPS");
  EXPECT_LT(r.EnergyAfter, r.EnergyBefore);
  EXPECT_GT(r.MinimumAngleAfter, r.MinimumAngleBefore + 1.0);
  EXPECT_GT(r.Flips, 0);
  // the energies reported are the cages' own
  const TriangleTree tree(input);
  EXPECT_NEAR(cageEnergy(r.Cage, tree, o), r.EnergyAfter, 1e-9 * r.EnergyAfter);
  EXPECT_NEAR(cageEnergy(cage, tree, o), r.EnergyBefore, 1e-9 * r.EnergyBefore);
}

TEST(Optimization, MIPSReachesFifteenDegreesAndStaysTight)
{
  // issue 15 part 3 at the defaults: no angle below 15 degrees, the one-sided Hausdorff distance
  // cage -> input (certified by the quality judge) at most 1.5 times the plain cage's, and every
  // guarantee (judged by the exact CGAL checker in expectGuarantees)
  struct Shape
  {
    const char* Name;
    TriangleMesh Mesh;
  };
  const Shape shapes[] = { { "builtin", makeBuiltinShape() }, { "torus", makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24) } };
  for (const Shape& s : shapes)
  {
    const CageResult cage = makeCage(s.Mesh, 500);
    ASSERT_EQ(cage.State, Status::Ok) << s.Name << ": " << cage.Message;
    OptimizeOptions o; // the defaults of --optimize mips
    ASSERT_EQ(o.Energy, CageEnergy::MIPS);
    ASSERT_EQ(o.NumberOfIterations, 1);
    o.Clearance = CageOptions().Envelope.clearance();
    const OptimizeResult r = optimizeCageInInputUnits(cage.Cage, s.Mesh, o);
    const double delta = cage.Normalize.lengthToInput(o.Clearance);
    expectGuarantees(s.Mesh, cage.Cage, r, delta, std::string(s.Name) + " MIPS at the defaults");
    const CageQualityResult q0 = evaluateCage(s.Mesh, cage.Cage);
    const CageQualityResult q1 = evaluateCage(s.Mesh, r.Cage);
    std::cout << "[ tight    ] " << s.Name << ": min angle " << minimumAngle(cage.Cage) << " -> " << r.MinimumAngleAfter
              << " deg, angles < 15: " << 100 * r.SmallAnglesBefore << "% -> " << 100 * r.SmallAnglesAfter
              << "%, Hausdorff cage->input " << q0.HausdorffCageToInputBound << " -> " << q1.HausdorffCageToInputBound
              << " (x" << q1.HausdorffCageToInputBound / q0.HausdorffCageToInputBound << "), " << r.Sweeps
              << " sweeps, " << r.Collapses << " collapse+split pairs, " << r.Seconds << " s\n";
    EXPECT_LT(r.MinimumAngleBefore, 15.0) << s.Name << ": the plain cage must have needles for this to test anything";
    EXPECT_GE(r.MinimumAngleAfter, 15.0) << s.Name;
    EXPECT_NEAR(r.MinimumAngleAfter, minimumAngle(r.Cage), 1e-9) << s.Name;
    EXPECT_EQ(r.SmallAnglesAfter, 0.0) << s.Name;
    EXPECT_LE(q1.HausdorffCageToInputBound, 1.5 * q0.HausdorffCageToInputBound) << s.Name;
    // the budget the optimizer enforced is the one it reports
    EXPECT_NEAR(r.HausdorffBudget, o.HausdorffFactor * r.HausdorffBefore, 1e-12) << s.Name;
  }
}

TEST(Optimization, AngleRelocationRaisesTheSmallestAngles)
{
  // the angle-targeted relocation (OptimizeOptions::AngleRelocation) on its own: one sweep with
  // one descent step per vertex and no flips leaves needles on the builtin shape's 500-vertex
  // cage; the corners of those needles moving to raise their ring's smallest angle must leave
  // fewer angles below the target and a larger smallest angle than the same sweep without it,
  // every guarantee kept (the exact CGAL checker) and within the Hausdorff budget
  const TriangleMesh input = makeBuiltinShape();
  const CageResult cage = makeCage(input, 500);
  ASSERT_EQ(cage.State, Status::Ok) << cage.Message;
  OptimizeOptions o;
  o.Clearance = CageOptions().Envelope.clearance();
  o.MaximumSweeps = 1;
  o.DescentSteps = 1;
  o.EdgeFlips = false;
  o.AngleRelocation = false;
  const OptimizeResult off = optimizeCageInInputUnits(cage.Cage, input, o);
  o.AngleRelocation = true;
  const OptimizeResult on = optimizeCageInInputUnits(cage.Cage, input, o);
  const double delta = cage.Normalize.lengthToInput(o.Clearance);
  expectGuarantees(input, cage.Cage, on, delta, "builtin, one sweep with the angle relocation");
  std::cout << "[ angles   ] one sweep without / with the angle relocation: min angle " << off.MinimumAngleAfter
            << " / " << on.MinimumAngleAfter << " deg, angles < 15: " << 100 * off.SmallAnglesAfter << "% / "
            << 100 * on.SmallAnglesAfter << "%, angle moves " << off.AngleMoves << " / " << on.AngleMoves << "\n";
  ASSERT_EQ(off.State, Status::Ok) << off.Message;
  EXPECT_EQ(off.AngleMoves, 0);
  EXPECT_GT(on.AngleMoves, 0);
  EXPECT_LT(off.MinimumAngleAfter, o.TargetMinimumAngle) << "without it the sweep must leave needles";
  EXPECT_GT(on.MinimumAngleAfter, off.MinimumAngleAfter + 1.0);
  EXPECT_LT(on.SmallAnglesAfter, off.SmallAnglesAfter);
  EXPECT_LE(on.HausdorffAfter, on.HausdorffBudget * (1 + 1.0 / 16));
}

TEST(Optimization, SpacingConcentratesAroundTarget)
{
  const TriangleMesh input = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24);
  const CageResult cage = makeCage(input, 300);
  ASSERT_EQ(cage.State, Status::Ok) << cage.Message;
  const double h = 0.05;
  OptimizeOptions o;
  o.Energy = CageEnergy::Spacing;
  o.TargetSpacing = h;
  o.NumberOfIterations = 3;
  const OptimizeResult r = optimizeCageInInputUnits(cage.Cage, input, o);
  const double delta = cage.Normalize.lengthToInput(0.0025);
  expectGuarantees(input, cage.Cage, r, delta, "torus spacing h=0.05");
  const Normalization n = Normalization::fit(input);
  const TriangleTree tree(n.toUnit(input));
  double m0, s0, m1, s1;
  spacingStatistics(n.toUnit(cage.Cage), tree, h, m0, s0);
  spacingStatistics(n.toUnit(r.Cage), tree, h, m1, s1);
  std::cout << "[ spacing  ] distance - h over cage samples (h = " << h << ", unit-sphere units): before mean " << m0
            << " stddev " << s0 << " rms " << std::hypot(m0, s0) << "; after mean " << m1 << " stddev " << s1 << " rms "
            << std::hypot(m1, s1) << "\n";
  EXPECT_LT(std::abs(m1), 0.5 * std::abs(m0));
  EXPECT_LT(std::hypot(m1, s1), 0.5 * std::hypot(m0, s0));
  // the reported area within h +- 20% agrees with the test's own measure (256 pieces a triangle)
  const double b0 = bandFraction(n.toUnit(cage.Cage), tree, 0.8 * h, 1.2 * h);
  const double b1 = bandFraction(n.toUnit(r.Cage), tree, 0.8 * h, 1.2 * h);
  std::cout << "[ spacing  ] area within h +- 20%: reported " << r.SpacingBandBefore << " -> " << r.SpacingBandAfter
            << ", measured here " << b0 << " -> " << b1 << "\n";
  EXPECT_NEAR(r.SpacingBandBefore, b0, 0.03);
  EXPECT_NEAR(r.SpacingBandAfter, b1, 0.03);
  EXPECT_GT(r.SpacingBandAfter, r.SpacingBandBefore + 0.2);
  // the rest of the area split into closer than 0.8 h and farther than 1.2 h, each as measured here
  const double closer = bandFraction(n.toUnit(r.Cage), tree, 0.0, 0.8 * h);
  std::cout << "[ spacing  ] after: closer " << r.SpacingCloserAfter << " (measured here " << closer << "), farther "
            << r.SpacingFartherAfter << " (" << 1.0 - b1 - closer << ")\n";
  EXPECT_NEAR(r.SpacingCloserAfter, closer, 0.03);
  EXPECT_NEAR(r.SpacingFartherAfter, 1.0 - b1 - closer, 0.03);
  EXPECT_NEAR(r.SpacingBandAfter + r.SpacingCloserAfter + r.SpacingFartherAfter, 1.0, 1e-9);
  // the plain cage lies about the isovalue (0.01) from the input: below the band almost wholly
  const OptimizeOptions none = [&] {
    OptimizeOptions z = o;
    z.NumberOfIterations = 0;
    return z;
  }();
  const OptimizeResult plain = optimizeCageInInputUnits(cage.Cage, input, none);
  ASSERT_EQ(plain.State, Status::Ok) << plain.Message;
  EXPECT_GT(plain.SpacingCloserAfter, 0.9) << "the plain cage at about 0.01 from the input, h = " << h;
  EXPECT_LT(plain.SpacingFartherAfter, 0.05);
}

TEST(Optimization, CCDCutsAMoveThroughATriangleShort)
{
  // input: the box [-1, 1]^3; cage: the box [-2, 2]^3. Vertex 7 of the cage box is (2, 2, 2):
  // moving it to (-1.5, -1.5, -1.5) drives its triangles through the input's corner triangles.
  const TriangleMesh input = makeBox(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  const TriangleMesh cage = makeBox(Vec3(-2, -2, -2), Vec3(2, 2, 2));
  int v = -1;
  for (std::size_t i = 0; i < cage.Points.size(); ++i)
    if ((cage.Points[i] - Vec3(2, 2, 2)).norm() < 1e-12)
      v = static_cast<int>(i);
  ASSERT_GE(v, 0);
  const TriangleTree tree(input);
  const double delta = 0.01, selfDelta = 0.0025;
  const Vec3 move = Vec3(-1.5, -1.5, -1.5) - cage.Points[v];

  // the reference: sample the path finely; the first fraction at which a triangle around v comes
  // closer than delta to the input (or the vertex reaches the input at all)
  auto ringDistance = [&](double t) {
    const Vec3 p = cage.Points[v] + t * move;
    double best = std::numeric_limits<double>::infinity();
    for (const Triangle& tri : cage.Triangles)
    {
      if (tri[0] != v && tri[1] != v && tri[2] != v)
        continue;
      Vec3 pts[3];
      for (int k = 0; k < 3; ++k)
        pts[k] = tri[k] == v ? p : cage.Points[tri[k]];
      best = std::min(best, tree.triangleDistance(pts, 1e9));
    }
    return best;
  };
  double contact = 1.0;
  for (int i = 0; i <= 20000; ++i)
    if (ringDistance(i / 20000.0) < delta)
    {
      contact = i / 20000.0;
      break;
    }
  ASSERT_LT(contact, 1.0) << "the hand-built move must hit the input";
  EXPECT_EQ(ringDistance(2.0 / 3.5), 0.0) << "on the way, the vertex passes the input's centre";

  const double t = collisionFreeFraction(cage, v, move, input, tree, delta, selfDelta);
  std::cout << "[ ccd      ] allowed fraction " << t << ", first sampled contact at " << contact << "\n";
  EXPECT_GT(t, 0.0);
  EXPECT_LE(t, contact);
  EXPECT_GT(t, 0.5 * contact) << "conservative, but not uselessly so";
  // along the allowed part of the path, every sampled position keeps the clearance
  for (int i = 0; i <= 1000; ++i)
    EXPECT_GE(ringDistance(t * i / 1000.0), delta * (1 - 1e-12));

  // a move that stays clear is allowed whole
  EXPECT_EQ(collisionFreeFraction(cage, v, Vec3(0.3, 0.2, 0.1), input, tree, delta, selfDelta), 1.0);
  // a cage/cage collision: push the vertex through the opposite face of the cage itself
  const TriangleMesh empty = makeBox(Vec3(-0.01, -0.01, -0.01), Vec3(0.01, 0.01, 0.01));
  const TriangleTree emptyTree(empty);
  const Vec3 through = Vec3(1.5, 1.5, -2.5) - cage.Points[v];
  const double ts = collisionFreeFraction(cage, v, through, empty, emptyTree, delta, selfDelta);
  EXPECT_LT(ts, 1.0);
  const Vec3 p = cage.Points[v] + ts * through;
  EXPECT_GT(p.z(), -2.0) << "stopped before the bottom face z = -2";
}

TEST(Optimization, RejectsCagesThatDoNotEnclose)
{
  const TriangleMesh input = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
  const TriangleMesh small = makeSphere(Vec3(0, 0, 0), 0.5, 16, 8);
  const OptimizeResult r = optimizeCageInInputUnits(small, input, OptimizeOptions());
  EXPECT_EQ(r.State, Status::InvalidInput);
  EXPECT_NE(r.Message.find("does not enclose"), std::string::npos) << r.Message;
  EXPECT_EQ(r.Cage.Points.size(), small.Points.size());

  const OptimizeResult e = optimizeCageInInputUnits(TriangleMesh(), input, OptimizeOptions());
  EXPECT_EQ(e.State, Status::EmptyInput);

  // a requested clearance larger than the cage has
  OptimizeOptions o;
  o.Clearance = 0.5;
  const OptimizeResult c = optimizeCageInInputUnits(makeSphere(Vec3(0, 0, 0), 1.1, 24, 12), input, o);
  EXPECT_EQ(c.State, Status::InvalidInput);
  EXPECT_NE(c.Message.find("closer than the clearance"), std::string::npos) << c.Message;
}

namespace
{
// Numbers in [0, 1) from a fixed seed (a linear congruential generator): the same random queries
// on every machine for the brute-force comparisons below.
struct UnitRandom
{
  unsigned Seed;
  double operator()()
  {
    Seed = Seed * 1664525u + 1013904223u;
    return (Seed >> 8) / double(1u << 24);
  }
};
} // namespace

TEST(Optimization, TreeTriangleQueriesMatchBruteForce)
{
  // the tree's pruning (bounding boxes, the query's and each input triangle's plane and side
  // planes) must not change the answers: distances, "any closer" and "all within" against a brute-force loop
  const TriangleMesh mesh = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 48, 16);
  const TriangleTree tree(mesh);
  UnitRandom uniform{ 12345u };
  int within = 0;
  for (int trial = 0; trial < 300; ++trial)
  {
    const Vec3 c(2.6 * uniform() - 1.3, 2.6 * uniform() - 1.3, 0.8 * uniform() - 0.4);
    const double size = trial % 3 == 0 ? 0.02 : (trial % 3 == 1 ? 0.2 : 0.8);
    Vec3 t[3];
    for (Vec3& p : t)
      p = c + size * Vec3(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
    const double radius = 0.005 + 0.1 * uniform();
    double brute = std::numeric_limits<double>::infinity();
    std::vector<int> expected;
    for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
    {
      const Vec3 q[3] = { mesh.Points[mesh.Triangles[f][0]], mesh.Points[mesh.Triangles[f][1]],
        mesh.Points[mesh.Triangles[f][2]] };
      const double d = std::sqrt(triangleTriangleDistance2(t, q));
      brute = std::min(brute, d);
      if (d < radius)
        expected.push_back(static_cast<int>(f));
    }
    EXPECT_DOUBLE_EQ(tree.triangleDistance(t, 1e9), brute) << trial;
    EXPECT_EQ(tree.anyCloserThan(t, radius), brute < radius) << trial;
    std::vector<int> got;
    tree.trianglesWithin(t, radius, got);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << trial;
    within += expected.empty() ? 0 : 1;
  }
  EXPECT_GT(within, 30) << "the random queries must exercise non-empty answers";
}

TEST(Optimization, TreeClosestPointMatchesBruteForce)
{
  // closestPoint's pruning (node boxes kept on the stack, each triangle's box before its closest
  // point) must not change the answer: the nearest distance, bounded and unbounded, and whether
  // anything lies within the bound, against a brute-force loop
  const TriangleMesh mesh = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 48, 16);
  const TriangleTree tree(mesh);
  UnitRandom uniform{ 4242u };
  int inside = 0, outside = 0;
  for (int trial = 0; trial < 500; ++trial)
  {
    const Vec3 p(3.0 * uniform() - 1.5, 3.0 * uniform() - 1.5, 1.0 * uniform() - 0.5);
    double brute = std::numeric_limits<double>::infinity();
    for (const Triangle& t : mesh.Triangles)
    {
      const Vec3 q = closestPointOnTriangle(p, mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]]);
      brute = std::min(brute, (q - p).norm());
    }
    EXPECT_DOUBLE_EQ(tree.distance(p), brute) << trial;
    const double bound = 0.2 * uniform();
    Vec3 c;
    int tri = -1;
    double d = -1;
    const bool found = tree.closestPoint(p, bound, c, tri, d);
    EXPECT_EQ(found, brute <= bound) << trial;
    if (found)
    {
      ++inside;
      EXPECT_DOUBLE_EQ(d, brute) << trial;
      EXPECT_NEAR((c - p).norm(), d, 1e-12) << trial;
      ASSERT_GE(tri, 0);
      const Triangle& t = mesh.Triangles[tri];
      const Vec3 q = closestPointOnTriangle(p, mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]]);
      EXPECT_DOUBLE_EQ((q - p).norm(), brute) << trial;
    }
    else
    {
      ++outside;
    }
  }
  EXPECT_GT(inside, 30) << "the random queries must find points within the bound";
  EXPECT_GT(outside, 30) << "and miss it";
}

TEST(Optimization, DeterministicAcrossThreadCounts)
{
  // the relocation runs batches of non-overlapping vertex regions in parallel: the result must
  // not depend on the number of threads (here through generateCage's optimization step)
  const TriangleMesh input = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24);
  CageOptions a;
  a.TargetNumberOfVertices = 300;
  a.Optimize = true;
  a.Optimization.Energy = CageEnergy::Spacing;
  a.Optimization.TargetSpacing = 0.03;
  CageOptions b = a;
  a.NumberOfThreads = 1;
  b.NumberOfThreads = 2;
  const CageResult ra = generateCage(PolygonMesh::fromTriangles(input), a);
  const CageResult rb = generateCage(PolygonMesh::fromTriangles(input), b);
  ASSERT_EQ(ra.State, Status::Ok) << ra.Message;
  ASSERT_EQ(rb.State, Status::Ok) << rb.Message;
  ASSERT_TRUE(ra.Optimized && rb.Optimized) << ra.Optimization.Message << rb.Optimization.Message;
  EXPECT_GT(ra.Optimization.Moves, 0);
  EXPECT_LT(ra.Optimization.EnergyAfter, ra.Optimization.EnergyBefore);
  ASSERT_EQ(ra.Cage.Points.size(), rb.Cage.Points.size());
  for (std::size_t i = 0; i < ra.Cage.Points.size(); ++i)
    EXPECT_EQ(ra.Cage.Points[i], rb.Cage.Points[i]) << i;
  EXPECT_EQ(ra.Cage.Triangles, rb.Cage.Triangles);
  EXPECT_EQ(ra.Optimization.EnergyAfter, rb.Optimization.EnergyAfter);
}

TEST(Optimization, CancelGivesAValidPartialCage)
{
  class CancelDuringRelocation : public Progress
  {
  protected:
    void report(double overall, const std::string& stage) override
    {
      if (stage == "relocating cage vertices" && overall > 0.2)
        this->cancel();
    }
  };
  const TriangleMesh input = makeSphere(Vec3(0, 0, 0), 1.0, 48, 24);
  const TriangleMesh cage = makeSphere(Vec3(0, 0, 0), 1.1, 24, 12);
  OptimizeOptions o;
  o.NumberOfIterations = 5;
  CancelDuringRelocation progress;
  const TriangleTree tree(input);
  const OptimizeResult r = optimizeCage(cage, input, tree, o, &progress);
  EXPECT_EQ(r.State, Status::Cancelled) << r.Message;
  EXPECT_FALSE(r.Reverted);
  EXPECT_EQ(r.Cage.Points.size(), cage.Points.size());
  // the partial result was verified like a finished one
  const exact::ExactReport e = exact::exactCheck(input, r.Cage, 0.01);
  EXPECT_TRUE(e.Encloses);
  EXPECT_GE(e.MinimumClearance, r.ClearanceUsed * (1 - 1e-9));
  EXPECT_LE(r.EnergyAfter, r.EnergyBefore);
}

TEST(Optimization, CancelInsideGenerateCage)
{
  // generateCage's optimization step reports progress and honours a cancel: the cage so far is
  // verified and output with Cancelled
  class CancelDuringOptimization : public Progress
  {
  protected:
    // report() may be called from any worker thread (Progress's contract): guard the list
    void report(double, const std::string& stage) override
    {
      std::lock_guard<std::mutex> guard(Lock);
      Stages.push_back(stage);
      if (stage == "relocating cage vertices")
        this->cancel();
    }

  public:
    std::mutex Lock;
    std::vector<std::string> Stages;
  };
  const TriangleMesh input = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 64, 24);
  CageOptions o;
  o.TargetNumberOfVertices = 300;
  o.Optimize = true;
  o.Optimization.NumberOfIterations = 3;
  CancelDuringOptimization progress;
  const CageResult r = generateCage(PolygonMesh::fromTriangles(input), o, &progress);
  EXPECT_EQ(r.State, Status::Cancelled) << r.Message;
  EXPECT_NE(r.Message.find("optimization"), std::string::npos) << r.Message;
  EXPECT_NE(
    std::find(progress.Stages.begin(), progress.Stages.end(), "relocating cage vertices"), progress.Stages.end());
  ASSERT_EQ(r.Cage.Points.size(), 300u);
  const exact::ExactReport e = exact::exactCheck(input, r.Cage, r.Normalize.lengthToInput(0.01));
  EXPECT_TRUE(e.Encloses);
  EXPECT_GE(e.MinimumClearance, r.Normalize.lengthToInput(0.0025) * (1 - 1e-9));
}
