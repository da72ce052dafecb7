// SDFCage — Testing: the local-change veto (Core/Quality/LocalChangeVeto) that the simplifier,
// the optimizer's moves and its flips share: each named check gives its verdict on a hand-made
// change; the optimizer's relaxed margin; the pair test's early-outs only skip pairs the exact
// test finds clear; the cage grid finds every triangle whose box meets a query box.
#include "Mesh/Shapes.h"
#include "Quality/LocalChangeVeto.h"
#include "Spatial/CageGrid.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleTree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>
#include <set>

using namespace sdfcage;

namespace
{

/// A cage (box A = [0,1]^3, optionally box B = [0,1]^2 x [1 + gap, 2 + gap] above it) around the
/// input [0.3, 0.7]^3, with a grid, and the change "move vertex 7 of A (the corner (1,1,1))".
struct BoxCages
{
  TriangleMesh Input = makeBox(Vec3::Constant(0.3), Vec3::Constant(0.7));
  TriangleTree Tree{ Input };
  std::vector<Vec3> P;
  std::vector<Triangle> T;
  CageGrid Grid;
  LocalChangeScratch S;

  explicit BoxCages(double gap = -1)
  {
    TriangleMesh cage = makeBox(Vec3::Zero(), Vec3::Ones());
    if (gap >= 0)
      appendMesh(cage, makeBox(Vec3(0, 0, 1 + gap), Vec3(1, 1, 2 + gap)));
    P = cage.Points;
    T = cage.Triangles;
    Grid.reset(0.5);
    for (std::size_t f = 0; f < T.size(); ++f)
      Grid.insert(static_cast<int>(f), P[T[f][0]].cwiseMin(P[T[f][1]]).cwiseMin(P[T[f][2]]),
        P[T[f][0]].cwiseMax(P[T[f][1]]).cwiseMax(P[T[f][2]]));
  }
  CageView view() const { return CageView{ &P, &T, nullptr, nullptr, nullptr, &Grid }; }

  /// Fills S with the ring of vertex v moved to p (as the optimizer does).
  void move(int v, const Vec3& p)
  {
    S.Tris.clear();
    S.Replaced.begin(T.size());
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      const Triangle& t = T[f];
      if (t[0] != v && t[1] != v && t[2] != v)
        continue;
      S.Replaced.insert(static_cast<int>(f));
      ChangedTriangle c;
      for (int k = 0; k < 3; ++k)
      {
        c.Ids[k] = t[k];
        c.Before[k] = P[t[k]];
        c.Pts[k] = t[k] == v ? p : P[t[k]];
      }
      c.Reference = (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]);
      c.QualityBefore = triangleQuality(P[t[0]], P[t[1]], P[t[2]]);
      S.Tris.push_back(c);
    }
  }
  LocalChangeVerdict check(const LocalChangePolicy& policy)
  {
    const LocalChangeVeto veto(policy, Tree, view());
    return veto.check(S);
  }
};

LocalChangePolicy basePolicy()
{
  LocalChangePolicy p;
  p.Clearance = 0.1;
  p.SelfClearance = 0.05;
  p.MinimumNormalCosine = 0.2;
  return p;
}

} // namespace

TEST(LocalChangeVeto, EachNamedCheckGivesItsVerdict)
{
  BoxCages s;
  const Vec3 corner(1, 1, 1);
  // a small outward move is fine
  s.move(7, corner + Vec3(0.01, 0.01, 0.01));
  ASSERT_EQ(s.S.Tris.size(), 6u);
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::Accepted);
  EXPECT_STREQ(verdictName(LocalChangeVerdict::Accepted), "accepted");

  // Shape: the box's right isosceles triangles (quality 0.866) under a floor of 0.99 ...
  LocalChangePolicy needle = basePolicy();
  needle.MinimumTriangleQuality = 0.99;
  EXPECT_EQ(s.check(needle), LocalChangeVerdict::Shape);
  // ... unless the floor is min(floor, the quality before) and the change keeps the quality
  s.move(7, corner);
  needle.KeepQualityBefore = true;
  EXPECT_EQ(s.check(needle), LocalChangeVerdict::Accepted);
  // Shape: a new triangle turned against the one it replaces
  s.move(7, corner + Vec3(0.01, 0.01, 0.01));
  s.S.Tris[2].Reference = -s.S.Tris[2].Reference;
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::Shape);

  // InputClearance: the corner pushed in to 0.087 from the input, clearance 0.1
  s.move(7, Vec3(0.75, 0.75, 0.75));
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::InputClearance);
  LocalChangePolicy noInput = basePolicy();
  noInput.Input = LocalChangePolicy::InputTest::None;
  EXPECT_EQ(s.check(noInput), LocalChangeVerdict::Accepted);
  noInput.Clearance = 0.05; // the exact test passes at a smaller clearance
  noInput.Input = LocalChangePolicy::InputTest::Exact;
  EXPECT_EQ(s.check(noInput), LocalChangeVerdict::Accepted);

  // Fold: two new triangles across an edge, the second folded back onto the first
  s.S.Tris.clear();
  s.S.Replaced.begin(s.T.size());
  const Vec3 q[4] = { Vec3(2, 2, 2), Vec3(3, 2, 2), Vec3(2.5, 3, 2), Vec3(2.5, 2.9, 2.05) };
  const int ids[2][3] = { { 100, 101, 102 }, { 101, 100, 103 } };
  for (int i = 0; i < 2; ++i)
  {
    ChangedTriangle c;
    for (int k = 0; k < 3; ++k)
    {
      c.Ids[k] = ids[i][k];
      c.Pts[k] = q[ids[i][k] - 100];
    }
    c.Reference = (c.Pts[1] - c.Pts[0]).cross(c.Pts[2] - c.Pts[0]); // shape alone would pass
    s.S.Tris.push_back(c);
  }
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::Fold);
  LocalChangePolicy unconstrained = basePolicy();
  unconstrained.CheckSelfIntersection = false;
  EXPECT_EQ(s.check(unconstrained), LocalChangeVerdict::Accepted);
}

TEST(LocalChangeVeto, SelfIntersectionWithTheRestOfTheCage)
{
  // box B 0.1 above box A: raising A's corner by 0.08 leaves 0.02 < the self clearance 0.05
  BoxCages s(0.1);
  s.move(7, Vec3(1, 1, 1.04));
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::Accepted);
  s.move(7, Vec3(1, 1, 1.08));
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::SelfIntersection);
  LocalChangeFindings found;
  const LocalChangeVeto veto(basePolicy(), s.Tree, s.view());
  EXPECT_EQ(veto.check(s.S, &found), LocalChangeVerdict::SelfIntersection);
  EXPECT_TRUE(found.Read);
  EXPECT_NEAR(found.ReadHi.z(), 1.08 + 0.05, 1e-12);
  // through B: also caught (intersection, not only closeness)
  s.move(7, Vec3(1, 1, 1.3));
  EXPECT_EQ(s.check(basePolicy()), LocalChangeVerdict::SelfIntersection);
}

TEST(LocalChangeVeto, RelaxedMarginForPairsAlreadyCloser)
{
  // B only 0.03 above A (closer than the self clearance 0.05 already): under RelaxCloserPairs a
  // move may bring the pair to half its distance before (0.015), not closer
  BoxCages s(0.03);
  LocalChangePolicy strict = basePolicy(), relaxed = basePolicy();
  relaxed.RelaxCloserPairs = true;
  EXPECT_DOUBLE_EQ(relaxed.relaxed(0.03), 0.015);
  EXPECT_DOUBLE_EQ(relaxed.relaxed(0.08), 0.05);
  s.move(7, Vec3(1, 1, 1.01)); // 0.02 from B
  EXPECT_EQ(s.check(strict), LocalChangeVerdict::SelfIntersection);
  EXPECT_EQ(s.check(relaxed), LocalChangeVerdict::Accepted);
  s.move(7, Vec3(1, 1, 1.02)); // 0.01 from B
  EXPECT_EQ(s.check(relaxed), LocalChangeVerdict::SelfIntersection);
}

TEST(LocalChangeVeto, EarlyOutsOnlySkipPairsThatCannotConflict)
{
  // random nearby triangle pairs, sharing no vertex or one: whenever an early-out of the pair
  // test skips a pair, the exact test finds it clear
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double gap = 0.05;
  int skippedSphere = 0, skippedAxes = 0, skippedOneSide = 0, conflicts = 0;
  for (int i = 0; i < 20000; ++i)
  {
    const double scale = i % 2 ? 0.1 : 0.4;
    ChangedTriangle a;
    LocalChangeScratch::Candidate b;
    for (int k = 0; k < 3; ++k)
    {
      a.Ids[k] = k;
      a.Pts[k] = Vec3(u(rng), u(rng), u(rng)) * scale;
      b.Ids[k] = 3 + k;
      b.Pts[k] = Vec3(0.15 + u(rng) * scale, u(rng) * scale, u(rng) * scale);
    }
    const bool shareOne = i % 3 == 0;
    if (shareOne)
    {
      b.Ids[0] = a.Ids[1];
      b.Pts[0] = a.Pts[1];
    }
    a.N = (a.Pts[1] - a.Pts[0]).cross(a.Pts[2] - a.Pts[0]);
    a.C = (a.Pts[0] + a.Pts[1] + a.Pts[2]) / 3.0;
    a.R = std::max({ (a.Pts[0] - a.C).norm(), (a.Pts[1] - a.C).norm(), (a.Pts[2] - a.C).norm() });
    b.C = (b.Pts[0] + b.Pts[1] + b.Pts[2]) / 3.0;
    b.R = std::max({ (b.Pts[0] - b.C).norm(), (b.Pts[1] - b.C).norm(), (b.Pts[2] - b.C).norm() });
    const bool conflict = trianglesConflict(a.Ids, a.Pts, b.Ids, b.Pts, gap, -0.95);
    conflicts += conflict ? 1 : 0;
    if (shareOne)
    {
      const Vec3 nb = (b.Pts[1] - b.Pts[0]).cross(b.Pts[2] - b.Pts[0]);
      if (LocalChangeVeto::oneSide(a.Pts[1], a.N, b.Pts[1], b.Pts[2]) ||
        LocalChangeVeto::oneSide(b.Pts[0], nb, a.Pts[2], a.Pts[0]))
      {
        ++skippedOneSide;
        EXPECT_FALSE(conflict) << "one-side early-out skipped a conflicting pair (" << i << ")";
      }
      continue;
    }
    if ((b.C - a.C).norm() - a.R - b.R >= gap)
    {
      ++skippedSphere;
      EXPECT_FALSE(conflict) << "sphere early-out skipped a conflicting pair (" << i << ")";
    }
    else if (LocalChangeVeto::separatedByAxes(a, b, gap))
    {
      ++skippedAxes;
      EXPECT_FALSE(conflict) << "separating-axis early-out skipped a conflicting pair (" << i << ")";
    }
  }
  std::cout << "[ pairs    ] " << conflicts << " conflicting; skipped by spheres " << skippedSphere << ", axes "
            << skippedAxes << ", one side " << skippedOneSide << "\n";
  EXPECT_GT(skippedSphere, 100);
  EXPECT_GT(skippedAxes, 100);
  EXPECT_GT(skippedOneSide, 100);
  EXPECT_GT(conflicts, 1000);
}

TEST(CageGrid, QueriesFindEveryTriangleWhoseBoxMeetsTheBox)
{
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), len(0.0, 0.3);
  std::vector<Vec3> lo(500), hi(500);
  CageGrid grid;
  grid.reset(0.2);
  for (int t = 0; t < 500; ++t)
  {
    lo[t] = Vec3(u(rng), u(rng), u(rng));
    hi[t] = lo[t] + Vec3(len(rng), len(rng), len(rng));
    grid.insert(t, lo[t], hi[t]);
  }
  // refile half of them elsewhere, as the optimizer does after a move
  for (int t = 0; t < 500; t += 2)
  {
    grid.remove(t, lo[t], hi[t]);
    lo[t] = Vec3(u(rng), u(rng), u(rng));
    hi[t] = lo[t] + Vec3(len(rng), len(rng), len(rng));
    grid.insert(t, lo[t], hi[t]);
  }
  for (int q = 0; q < 200; ++q)
  {
    const Vec3 a(u(rng), u(rng), u(rng)), b = a + Vec3(len(rng), len(rng), len(rng));
    std::set<int> found, expected;
    grid.query(a, b, [&](int t) {
      if (!((lo[t].array() > b.array()).any() || (hi[t].array() < a.array()).any()))
        found.insert(t);
    });
    for (int t = 0; t < 500; ++t)
      if (!((lo[t].array() > b.array()).any() || (hi[t].array() < a.array()).any()))
        expected.insert(t);
    EXPECT_EQ(found, expected);
  }
}
