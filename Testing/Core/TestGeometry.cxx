// SDFCage — Testing: Normalization, distance primitives and the triangle index, against
// brute force and against the independent CGAL checker.
#include "ExactCheck.h"
#include "Spatial/Geometry.h"
#include "Mesh/Mesh.h"
#include "Mesh/Normalization.h"
#include "Mesh/Shapes.h"
#include "Spatial/TriangleIndex.h"
#include "Spatial/TriangleTree.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

using namespace sdfcage;

namespace
{

Vec3 randomPoint(std::mt19937& rng, double lo, double hi)
{
  std::uniform_real_distribution<double> u(lo, hi);
  return Vec3(u(rng), u(rng), u(rng));
}

/// Points on a barycentric grid of n subdivisions on triangle (a, b, c).
std::vector<Vec3> sampleTriangle(const Vec3& a, const Vec3& b, const Vec3& c, int n)
{
  std::vector<Vec3> s;
  for (int i = 0; i <= n; ++i)
  {
    for (int j = 0; i + j <= n; ++j)
    {
      s.push_back(a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a));
    }
  }
  return s;
}

double longestEdge(const Vec3& a, const Vec3& b, const Vec3& c)
{
  return std::max({ (a - b).norm(), (b - c).norm(), (c - a).norm() });
}

/// Is q in triangle (a, b, c) up to eps (relative barycentric coordinates)?
bool inTriangle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c, double eps)
{
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  if (std::abs((q - a).dot(n)) > eps * std::sqrt(area2) * longestEdge(a, b, c))
  {
    return false;
  }
  const double u = (c - b).cross(q - b).dot(n) / area2;
  const double v = (a - c).cross(q - c).dot(n) / area2;
  const double w = (b - a).cross(q - a).dot(n) / area2;
  return u >= -eps && v >= -eps && w >= -eps;
}

} // namespace

// --- Normalization --------------------------------------------------------------------------

TEST(Normalization, FitsIntoTheUnitSphereAndRoundTrips)
{
  const TriangleMesh box = makeBox(Vec3(1, 2, -1), Vec3(3, 6, 1));
  const Normalization n = Normalization::fit(box);
  EXPECT_NEAR((n.Center - Vec3(2, 4, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(n.Scale, 1.0 / std::sqrt(6.0), 1e-15);

  const TriangleMesh unit = n.toUnit(box);
  ASSERT_EQ(unit.Triangles, box.Triangles);
  double largest = 0.0;
  for (const Vec3& p : unit.Points)
  {
    largest = std::max(largest, p.norm());
  }
  EXPECT_NEAR(largest, 1.0, 1e-14);

  const TriangleMesh back = n.toInput(unit);
  for (std::size_t i = 0; i < box.Points.size(); ++i)
  {
    EXPECT_NEAR((back.Points[i] - box.Points[i]).norm(), 0.0, 1e-14);
  }
  std::mt19937 rng(7);
  for (int i = 0; i < 100; ++i)
  {
    const Vec3 p = randomPoint(rng, -50, 50);
    EXPECT_NEAR((n.toInput(n.toUnit(p)) - p).norm(), 0.0, 1e-12);
    const double length = std::abs(p[0]);
    EXPECT_NEAR(n.lengthToInput(n.lengthToUnit(length)), length, 1e-12);
  }
  // Lengths scale like distances between mapped points.
  const Vec3 p(1, 1, 1), q(2, 3, 5);
  EXPECT_NEAR((n.toUnit(p) - n.toUnit(q)).norm(), n.lengthToUnit((p - q).norm()), 1e-14);
}

// --- closest point, segment and triangle distances ---------------------------------------------

TEST(Geometry, ClosestPointOnTriangleMatchesBruteForce)
{
  std::mt19937 rng(11);
  const int n = 60;
  for (int trial = 0; trial < 200; ++trial)
  {
    const Vec3 a = randomPoint(rng, -1, 1), b = randomPoint(rng, -1, 1), c = randomPoint(rng, -1, 1);
    const Vec3 p = randomPoint(rng, -2, 2);
    const Vec3 q = closestPointOnTriangle(p, a, b, c);
    EXPECT_TRUE(inTriangle(q, a, b, c, 1e-9)) << "trial " << trial;
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& s : sampleTriangle(a, b, c, n))
    {
      best = std::min(best, (p - s).norm());
    }
    // q is at least as close as every sample, and no sample is farther than h from the optimum.
    EXPECT_LE((p - q).norm(), best + 1e-12) << "trial " << trial;
    EXPECT_GE((p - q).norm(), best - longestEdge(a, b, c) / n) << "trial " << trial;
  }
  // Vertex, edge and face regions of a right triangle, exactly.
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_EQ(closestPointOnTriangle(Vec3(-1, -1, 3), a, b, c), a);
  EXPECT_EQ(closestPointOnTriangle(Vec3(2, -1, 0), a, b, c), b);
  EXPECT_NEAR((closestPointOnTriangle(Vec3(0.5, -2, 1), a, b, c) - Vec3(0.5, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((closestPointOnTriangle(Vec3(0.2, 0.3, -4), a, b, c) - Vec3(0.2, 0.3, 0)).norm(), 0, 1e-15);
}

TEST(Geometry, SegmentSegmentDistanceMatchesBruteForce)
{
  std::mt19937 rng(13);
  const int n = 400;
  for (int trial = 0; trial < 200; ++trial)
  {
    const Vec3 p0 = randomPoint(rng, -1, 1), p1 = randomPoint(rng, -1, 1);
    const Vec3 q0 = randomPoint(rng, -1, 1), q1 = randomPoint(rng, -1, 1);
    const double d = std::sqrt(segmentSegmentDistance2(p0, p1, q0, q1));
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= n; ++i)
    {
      const Vec3 x = p0 + (double(i) / n) * (p1 - p0);
      for (int j = 0; j <= n; ++j)
      {
        best = std::min(best, (x - (q0 + (double(j) / n) * (q1 - q0))).norm());
      }
    }
    const double h = ((p1 - p0).norm() + (q1 - q0).norm()) / n;
    EXPECT_LE(d, best + 1e-12) << "trial " << trial;
    EXPECT_GE(d, best - h) << "trial " << trial;
  }
  // Parallel, collinear-overlapping, crossing and point-like segments.
  EXPECT_NEAR(segmentSegmentDistance2(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 2, 0), Vec3(3, 2, 0)), 4.0, 1e-14);
  EXPECT_NEAR(segmentSegmentDistance2(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0), Vec3(3, 0, 0)), 0.0, 1e-14);
  EXPECT_NEAR(segmentSegmentDistance2(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 1, 0)), 0.0, 1e-14);
  EXPECT_NEAR(segmentSegmentDistance2(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, 4, 0), Vec3(3, 4, 0)), 4.0 + 16.0, 1e-12);
  EXPECT_NEAR(segmentSegmentDistance2(Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 4), Vec3(1, 1, 4)), 9.0, 1e-12);
}

TEST(Geometry, TriangleDistanceMatchesSamplingAndCgal)
{
  std::mt19937 rng(17);
  const int n = 40;
  for (int trial = 0; trial < 60; ++trial)
  {
    Vec3 a[3], b[3];
    const Vec3 shift(0.6 + trial * 0.02, 0.0, 0.0); // from overlapping to well apart
    for (int k = 0; k < 3; ++k)
    {
      a[k] = randomPoint(rng, -1, 1);
      b[k] = randomPoint(rng, -1, 1) + shift;
    }
    const double d = std::sqrt(triangleTriangleDistance2(a, b));

    // The CGAL checker on two one-triangle meshes measures the same distance independently.
    TriangleMesh ta, tb;
    ta.Points = { a[0], a[1], a[2] };
    ta.Triangles = { { 0, 1, 2 } };
    tb.Points = { b[0], b[1], b[2] };
    tb.Triangles = { { 0, 1, 2 } };
    const exact::ExactReport r = exact::exactCheck(ta, tb, 10.0);
    EXPECT_NEAR(d, r.MinimumClearance, 1e-12) << "trial " << trial;
    if (r.InputIntersections > 0)
    {
      EXPECT_EQ(d, 0.0) << "trial " << trial << ": the triangles intersect (exact predicate)";
    }

    double best = std::numeric_limits<double>::infinity();
    const std::vector<Vec3> sa = sampleTriangle(a[0], a[1], a[2], n);
    for (const Vec3& q : sampleTriangle(b[0], b[1], b[2], n))
    {
      for (const Vec3& p : sa)
      {
        best = std::min(best, (p - q).norm());
      }
    }
    const double h = (longestEdge(a[0], a[1], a[2]) + longestEdge(b[0], b[1], b[2])) / n;
    EXPECT_LE(d, best + 1e-12) << "trial " << trial;
    EXPECT_GE(d, best - h) << "trial " << trial;
  }
}

TEST(Geometry, CoplanarTriangleDistance)
{
  // Dense envelopes are full of coplanar triangles (grid-aligned marching-cubes facets), so
  // disjoint coplanar pairs must get their true distance, not 0.
  auto check = [](const Vec3 a[3], const Vec3 b[3], const char* what) {
    TriangleMesh ta, tb;
    ta.Points = { a[0], a[1], a[2] };
    ta.Triangles = { { 0, 1, 2 } };
    tb.Points = { b[0], b[1], b[2] };
    tb.Triangles = { { 0, 1, 2 } };
    const exact::ExactReport r = exact::exactCheck(ta, tb, 10.0);
    const double d = std::sqrt(triangleTriangleDistance2(a, b));
    EXPECT_NEAR(d, r.MinimumClearance, 1e-12) << what;
    return r.MinimumClearance;
  };
  const Vec3 a[3] = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0) };
  const Vec3 apart[3] = { Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(2, 1, 0) };
  EXPECT_NEAR(check(a, apart, "z = 0, one apart"), 1.0, 1e-12);
  const Vec3 overlapping[3] = { Vec3(0.2, 0.2, 0), Vec3(2, 0.2, 0), Vec3(0.2, 2, 0) };
  EXPECT_EQ(check(a, overlapping, "z = 0, overlapping"), 0.0);
  const Vec3 touching[3] = { Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0) };
  EXPECT_EQ(check(a, touching, "z = 0, touching at a corner"), 0.0);

  // The same pairs in a tilted plane.
  const Eigen::Matrix3d rotation =
    (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) * Eigen::AngleAxisd(0.3, Vec3::UnitX())).toRotationMatrix();
  Vec3 ra[3], rb[3];
  for (int k = 0; k < 3; ++k)
  {
    ra[k] = rotation * a[k] + Vec3(0.5, -2, 7);
    rb[k] = rotation * apart[k] + Vec3(0.5, -2, 7);
  }
  EXPECT_NEAR(check(ra, rb, "tilted, one apart"), 1.0, 1e-12);

  // A pair from a marching-cubes envelope of a torus (coordinates as produced), 0.0037 apart.
  const Vec3 ea[3] = { Vec3(-0.9837767481803894, -0.072499997913837433, -0.10249999910593033),
    Vec3(-0.98170572519302368, -0.072499997913837433, -0.10750000178813934),
    Vec3(-0.98353111743927002, -0.077500000596046448, -0.10249999910593033) };
  const Vec3 eb[3] = { Vec3(-0.98328548669815063, -0.082500003278255463, -0.10249999910593033),
    Vec3(-0.9814600944519043, -0.077500000596046448, -0.10750000178813934),
    Vec3(-0.98121446371078491, -0.082500003278255463, -0.10750000178813934) };
  EXPECT_GT(check(ea, eb, "envelope facets"), 0.003);
}

TEST(Geometry, WindingNumberInsideOutside)
{
  const TriangleMesh sphere = makeSphere(Vec3(0.5, -0.25, 2.0), 1.5, 32, 16);
  std::mt19937 rng(19);
  int inside = 0, outside = 0;
  for (int i = 0; i < 300; ++i)
  {
    const Vec3 p = Vec3(0.5, -0.25, 2.0) + randomPoint(rng, -2.5, 2.5);
    const double r = (p - Vec3(0.5, -0.25, 2.0)).norm();
    if (std::abs(r - 1.5) < 0.05)
    {
      continue; // too close to the faceted surface to know the answer from the smooth sphere
    }
    const double w = windingNumber(sphere, p);
    if (r < 1.5)
    {
      EXPECT_NEAR(w, 1.0, 0.01) << "at radius " << r;
      ++inside;
    }
    else
    {
      EXPECT_NEAR(w, 0.0, 0.01) << "at radius " << r;
      ++outside;
    }
  }
  EXPECT_GT(inside, 10);
  EXPECT_GT(outside, 10);

  // A flipped mesh gives about -1 inside; a torus's hole is outside.
  TriangleMesh flipped = sphere;
  reverseOrientation(flipped);
  EXPECT_NEAR(windingNumber(flipped, Vec3(0.5, -0.25, 2.0)), -1.0, 0.01);
  const TriangleMesh torus = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 48, 16);
  EXPECT_NEAR(windingNumber(torus, Vec3(0, 0, 0)), 0.0, 0.01);
  EXPECT_NEAR(windingNumber(torus, Vec3(1, 0, 0)), 1.0, 0.01);
  EXPECT_NEAR(windingNumber(torus, Vec3(0, 0, 1)), 0.0, 0.01);
}

// --- TriangleIndex --------------------------------------------------------------------------

namespace
{

TriangleMesh indexTestMesh()
{
  TriangleMesh m = makeSphere(Vec3(0, 0, 0), 1.0, 40, 20);
  appendMesh(m, makeTorus(Vec3(2.5, 0, 0), 0.8, 0.2, 48, 12));
  appendMesh(m, makeBox(Vec3(-3, -1, -1), Vec3(-2, 2, 0.5)));
  return m;
}

/// Brute force: the distance from p to the mesh and the nearest triangle.
double bruteDistance(const TriangleMesh& m, const Vec3& p, int& triangle)
{
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < m.Triangles.size(); ++t)
  {
    const Triangle& tri = m.Triangles[t];
    const double d = (p - closestPointOnTriangle(p, m.Points[tri[0]], m.Points[tri[1]], m.Points[tri[2]])).norm();
    if (d < best)
    {
      best = d;
      triangle = static_cast<int>(t);
    }
  }
  return best;
}

} // namespace

TEST(TriangleIndex, ClosestPointMatchesBruteForce)
{
  const TriangleMesh mesh = indexTestMesh();
  for (const double cellSize : { 0.0, 0.05, 0.7 })
  {
    TriangleIndex index;
    index.build(mesh, cellSize);
    std::mt19937 rng(23);
    for (int i = 0; i < 300; ++i)
    {
      // Mostly near the surfaces, some far outside the grid.
      const Vec3 p = i % 10 == 0 ? randomPoint(rng, -12, 12) : randomPoint(rng, -3.5, 3.5);
      int bruteTriangle = -1;
      const double expected = bruteDistance(mesh, p, bruteTriangle);
      Vec3 closest;
      int triangle = -1;
      double distance = -1;
      ASSERT_TRUE(index.closestPoint(p, -1.0, closest, triangle, distance)) << "cell " << cellSize;
      EXPECT_NEAR(distance, expected, 1e-12) << "cell " << cellSize << " point " << i;
      EXPECT_NEAR((p - closest).norm(), distance, 1e-12);
      ASSERT_GE(triangle, 0);
      ASSERT_LT(triangle, static_cast<int>(mesh.Triangles.size()));
      const Triangle& tri = mesh.Triangles[triangle];
      EXPECT_TRUE(inTriangle(closest, mesh.Points[tri[0]], mesh.Points[tri[1]], mesh.Points[tri[2]], 1e-9));
      EXPECT_NEAR(index.distance(p), expected, 1e-12);

      // A search radius below the distance finds nothing; above it finds the same point.
      Vec3 c2;
      int t2;
      double d2;
      if (expected > 1e-3)
      {
        EXPECT_FALSE(index.closestPoint(p, 0.5 * expected, c2, t2, d2));
      }
      ASSERT_TRUE(index.closestPoint(p, 1.01 * expected + 1e-9, c2, t2, d2));
      EXPECT_NEAR(d2, expected, 1e-12);
    }
  }
}

TEST(TriangleIndex, BoxQueryReportsEachOverlappingTriangleOnce)
{
  const TriangleMesh mesh = indexTestMesh();
  TriangleIndex index;
  index.build(mesh, 0.1);
  std::mt19937 rng(29);
  for (int q = 0; q < 50; ++q)
  {
    const Vec3 c = randomPoint(rng, -3.5, 3.5);
    const Vec3 half = randomPoint(rng, 0.0, 0.6);
    const Vec3 lo = c - half, hi = c + half;
    std::multiset<int> reported;
    index.forEachTriangleInBox(lo, hi, [&](int t) { reported.insert(t); });
    std::set<int> expected;
    for (std::size_t t = 0; t < mesh.Triangles.size(); ++t)
    {
      const Triangle& tri = mesh.Triangles[t];
      const Vec3 tlo = mesh.Points[tri[0]].cwiseMin(mesh.Points[tri[1]]).cwiseMin(mesh.Points[tri[2]]);
      const Vec3 thi = mesh.Points[tri[0]].cwiseMax(mesh.Points[tri[1]]).cwiseMax(mesh.Points[tri[2]]);
      if (!((tlo.array() > hi.array()).any() || (thi.array() < lo.array()).any()))
      {
        expected.insert(static_cast<int>(t));
      }
    }
    EXPECT_EQ(std::set<int>(reported.begin(), reported.end()), expected) << "query " << q;
    EXPECT_EQ(reported.size(), expected.size()) << "query " << q << ": a triangle was repeated";
  }
}

TEST(TriangleIndex, TriangleDistanceMatchesBruteForce)
{
  const TriangleMesh mesh = indexTestMesh();
  TriangleIndex index;
  index.build(mesh);
  std::mt19937 rng(31);
  for (int q = 0; q < 60; ++q)
  {
    Vec3 t[3];
    const Vec3 c = randomPoint(rng, -3.5, 3.5);
    for (int k = 0; k < 3; ++k)
    {
      t[k] = c + randomPoint(rng, -0.2, 0.2);
    }
    double expected = std::numeric_limits<double>::infinity();
    for (const Triangle& tri : mesh.Triangles)
    {
      const Vec3 m[3] = { mesh.Points[tri[0]], mesh.Points[tri[1]], mesh.Points[tri[2]] };
      expected = std::min(expected, std::sqrt(triangleTriangleDistance2(t, m)));
    }
    const double limit = 0.5;
    const double d = index.triangleDistance(t, limit);
    if (expected < limit)
    {
      EXPECT_NEAR(d, expected, 1e-12) << "query " << q;
    }
    else
    {
      EXPECT_EQ(d, limit) << "query " << q;
    }
  }
}

TEST(TriangleTree, SlabsPruneOnlyWhatIsNotNearer)
{
  // The tree's slabs (each subtree's triangles between two planes along their mean normal) prune
  // where a query passes just above a smooth surface, the case the cage's clearance checks are.
  // Queries there, at distances on both sides of the limit, must get exactly the brute-force
  // answers: distances, "any closer", the triangles within, the closest point.
  TriangleMesh m = makeSphere(Vec3(0, 0, 0), 1.0, 160, 80);
  appendMesh(m, makeTorus(Vec3(0, 0, 0), 1.6, 0.25, 96, 24));
  // a gently curved sheet far from both, with some long slivers across it
  const int n = 40;
  const int base = static_cast<int>(m.Points.size());
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
    {
      const double x = 3.0 + 2.0 * i / n, y = -1.0 + 2.0 * j / n;
      m.Points.emplace_back(x, y, 0.05 * std::sin(2.0 * x) * std::cos(3.0 * y));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
    {
      const int a = base + i * (n + 1) + j;
      m.Triangles.push_back({ a, a + n + 1, a + 1 });
      m.Triangles.push_back({ a + 1, a + n + 1, a + n + 2 });
    }
  for (int k = 0; k < 10; ++k)
    m.Triangles.push_back({ base + k, base + n * (n + 1) + 3 * k, base + k + 1 });
  TriangleTree whole(m), pieces;
  ASSERT_TRUE(pieces.build(m, nullptr, true));
  ASSERT_GT(pieces.splitTriangles(), 0u);

  std::mt19937 rng(37);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int nearer = 0, farther = 0;
  std::vector<std::array<Vec3, 3>> queries;
  for (int q = 0; q < 400; ++q)
  {
    // a point on one of the surfaces and its outward normal (numerically, from the tree)
    Vec3 on, normal;
    const int which = q % 3;
    const double a = 2.0 * M_PI * u(rng), b = M_PI * (u(rng) - 0.5);
    if (which == 0)
    {
      on = Vec3(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b));
      normal = on;
    }
    else if (which == 1)
    {
      const Vec3 ring(1.6 * std::cos(a), 1.6 * std::sin(a), 0.0);
      normal = Vec3(std::cos(a) * std::cos(2 * b), std::sin(a) * std::cos(2 * b), std::sin(2 * b));
      on = ring + 0.25 * normal;
    }
    else
    {
      on = Vec3(3.2 + 1.6 * u(rng), -0.8 + 1.6 * u(rng), 0.0);
      on.z() = 0.05 * std::sin(2.0 * on.x()) * std::cos(3.0 * on.y());
      normal = Vec3(0, 0, 1);
    }
    const double limit = 0.004 + 0.02 * u(rng);
    const double height = limit * (0.3 + 1.4 * u(rng)); // half below the limit, half above
    const Vec3 c = on + height * normal;
    // a triangle about the surface's tangent plane, from small to wide
    const Vec3 e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
    const double size = 0.01 + 0.15 * u(rng);
    Vec3 t[3];
    for (int k = 0; k < 3; ++k)
    {
      const double phi = a + 2.1 * k + 0.3 * u(rng);
      t[k] = c + size * (std::cos(phi) * e1 + std::sin(phi) * e2) + 0.1 * size * (u(rng) - 0.5) * normal;
    }
    queries.push_back({ t[0], t[1], t[2] });
    double brute = std::numeric_limits<double>::infinity();
    std::vector<int> within;
    for (std::size_t f = 0; f < m.Triangles.size(); ++f)
    {
      const Triangle& tri = m.Triangles[f];
      const Vec3 o[3] = { m.Points[tri[0]], m.Points[tri[1]], m.Points[tri[2]] };
      const double d = std::sqrt(triangleTriangleDistance2(t, o));
      brute = std::min(brute, d);
      if (d < limit)
        within.push_back(static_cast<int>(f));
    }
    (brute < limit ? nearer : farther) += 1;
    for (const TriangleTree* tree : { &whole, &pieces })
    {
      EXPECT_EQ(tree->triangleDistance(t, limit), std::min(brute, limit)) << "query " << q;
      EXPECT_EQ(tree->anyCloserThan(t, limit), brute < limit) << "query " << q;
      std::vector<int> got;
      tree->trianglesWithin(t, limit, got);
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, within) << "query " << q;
      // a point query from each corner
      for (const Vec3& p : t)
      {
        int bruteTriangle = -1;
        const double expected = bruteDistance(m, p, bruteTriangle);
        Vec3 closest;
        int triangle = -1;
        double d = -1;
        const bool found = tree->closestPoint(p, limit, closest, triangle, d);
        EXPECT_EQ(found, expected <= limit) << "query " << q;
        if (found)
        {
          EXPECT_EQ(d, expected) << "query " << q;
        }
        EXPECT_EQ(tree->distance(p), expected) << "query " << q;
      }
    }
  }
  // both sides of the limit are exercised
  EXPECT_GT(nearer, 60);
  EXPECT_GT(farther, 60);

  // Several triangles in one walk (anyCloserThanAny, for a local change's triangles): the same
  // answer as each on its own, for groups of one to 40 (over 32: in parts), where all are clear
  // and where only one is not (the last, the first, or in the middle).
  const double delta = 0.012;
  std::vector<char> single(queries.size());
  std::vector<std::size_t> clear, notClear;
  for (std::size_t k = 0; k < queries.size(); ++k)
  {
    single[k] = whole.anyCloserThan(queries[k].data(), delta);
    (single[k] ? notClear : clear).push_back(k);
  }
  ASSERT_GT(clear.size(), 80u);
  ASSERT_GT(notClear.size(), 40u);
  int groups = 0, groupsNotClear = 0;
  for (int size : { 1, 2, 7, 32, 33, 40 })
    for (int trial = 0; trial < 30; ++trial)
    {
      std::vector<std::size_t> members;
      for (int i = 0; i < size; ++i)
        members.push_back(
          clear[(static_cast<std::size_t>(trial) * 7 + static_cast<std::size_t>(i) * 3) % clear.size()]);
      if (trial % 3 != 0)
      {
        // one not clear, at the end, the start or the middle
        const std::size_t at = trial % 3 == 1 ? members.size() - 1 : (trial % 2 ? 0 : members.size() / 2);
        members[at] = notClear[static_cast<std::size_t>(trial) % notClear.size()];
      }
      std::vector<const Vec3*> group;
      bool expected = false;
      for (std::size_t k : members)
      {
        group.push_back(queries[k].data());
        expected = expected || single[k];
      }
      for (const TriangleTree* tree : { &whole, &pieces })
        EXPECT_EQ(tree->anyCloserThanAny(group.data(), static_cast<int>(group.size()), delta), expected)
          << "group of " << size << ", trial " << trial;
      ++groups;
      groupsNotClear += expected ? 1 : 0;
    }
  EXPECT_GT(groupsNotClear, 60);
  EXPECT_LT(groupsNotClear, groups);
}

TEST(Geometry, CloserThanAgreesWithTheDistance)
{
  // trianglesCloserThan answers "sqrt(triangleTriangleDistance2) < delta" part by part with early
  // exits: on crossing, touching, coplanar, edge-near and distant pairs it must give exactly the
  // distance's answer, at deltas on both sides of it and at the distance itself.
  std::mt19937 rng(29);
  int closer = 0, crossing = 0, apart = 0;
  for (int trial = 0; trial < 4000; ++trial)
  {
    Vec3 a[3], b[3];
    for (int k = 0; k < 3; ++k)
    {
      a[k] = randomPoint(rng, -1.0, 1.0);
      b[k] = randomPoint(rng, -1.0, 1.0) + Vec3(0.0, 0.0, trial % 4 == 0 ? 0.0 : 0.6 * (trial % 3));
    }
    if (trial % 5 == 0)
    {
      b[0] = a[1]; // touching at a corner
    }
    if (trial % 7 == 0)
    {
      for (Vec3& p : b)
        p.z() = a[0].z() = a[1].z() = a[2].z() = 0.25; // coplanar
    }
    const double d = std::sqrt(triangleTriangleDistance2(a, b));
    for (double delta : { 0.0, 1e-3, 0.05, 0.2, 0.5, 1.5, d, std::nextafter(d, 10.0), 0.5 * d })
    {
      const bool got = trianglesCloserThan(a, b, delta), want = d < delta;
      EXPECT_EQ(got, want) << "trial " << trial << " distance " << d << " delta " << delta;
      closer += got ? 1 : 0;
    }
    crossing += d == 0.0 ? 1 : 0;
    apart += d > 0.2 ? 1 : 0;
  }
  // the pairs must exercise each case
  EXPECT_GT(crossing, 200);
  EXPECT_GT(apart, 200);
  EXPECT_GT(closer, 4000);
}

namespace
{

/// The prism over a polygon of the xy plane star-shaped from its first corner (its caps fanned
/// from there), from z = 0 to z = height, oriented outward.
TriangleMesh extrudedPolygon(const std::vector<Vec3>& polygon, double height)
{
  TriangleMesh m;
  const int n = static_cast<int>(polygon.size());
  for (const Vec3& p : polygon)
    m.Points.push_back(p);
  for (const Vec3& p : polygon)
    m.Points.push_back(p + Vec3(0, 0, height));
  for (int k = 1; k + 1 < n; ++k)
  {
    m.Triangles.push_back({ 0, k + 1, k });
    m.Triangles.push_back({ n, n + k, n + k + 1 });
  }
  for (int k = 0; k < n; ++k)
  {
    const int a = k, b = (k + 1) % n;
    m.Triangles.push_back({ a, b, n + b });
    m.Triangles.push_back({ a, n + b, n + a });
  }
  orientOutward(m);
  return m;
}

} // namespace

// The pseudo-normal sign (the topology repair's local grid) against the winding number, on
// closed meshes free of self-intersection (the cluster at 0.004: see GapShapes) with convex, concave and sharp corners and edges:
// points near every vertex (whose closest feature is then mostly a vertex or an edge, where a
// face's own normal can give the wrong side) and near random surface points. The face normal
// alone must get some of them wrong, else the points would not test the edge and vertex rules.
TEST(PseudoNormalSign, AgreesWithTheWindingNumberNearCornersAndEdges)
{
  // an L (a concave edge) and a sliver of 10 degrees (convex edges sharper than a right angle)
  const TriangleMesh ell = extrudedPolygon(
    { Vec3(0, 0, 0), Vec3(0.8, 0, 0), Vec3(0.8, 0.3, 0), Vec3(0.3, 0.3, 0), Vec3(0.3, 0.8, 0), Vec3(0, 0.8, 0) }, 0.4);
  const TriangleMesh sliver =
    extrudedPolygon({ Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(std::cos(0.1745), std::sin(0.1745), 0) }, 0.3);
  const std::vector<std::pair<const char*, TriangleMesh>> meshes = { { "box",
                                                                       makeBox(Vec3(-0.5, -0.3, -0.2), Vec3(0.4, 0.3, 0.2)) },
    { "ell", ell }, { "sliver", sliver }, { "comb", makeGapShape(GapShape::Comb, 0.01) },
    { "cluster", makeGapShape(GapShape::Cluster, 0.004) } };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int faceWrong = 0;
  for (const auto& [name, mesh] : meshes)
  {
    SCOPED_TRACE(name);
    const TriangleTree tree(mesh);
    const PseudoNormalSign sign(mesh);
    std::vector<Vec3> points;
    // (at most about 300 vertices: the winding numbers are brute-force sums)
    const std::size_t every = 1 + mesh.Points.size() / 300;
    for (std::size_t i = 0; i < mesh.Points.size(); i += every)
      for (double eps : { 1e-4, 3e-3 })
        for (int k = 0; k < 4; ++k)
          points.push_back(mesh.Points[i] + eps * Vec3(u(rng), u(rng), u(rng)));
    for (int k = 0; k < 600; ++k)
    {
      const Triangle& t = mesh.Triangles[static_cast<std::size_t>(k) % mesh.Triangles.size()];
      const double a = 0.5 * (u(rng) + 1.0), b = 0.5 * (u(rng) + 1.0) * (1.0 - a);
      const Vec3 on = mesh.Points[t[0]] + a * (mesh.Points[t[1]] - mesh.Points[t[0]]) +
        b * (mesh.Points[t[2]] - mesh.Points[t[0]]);
      points.push_back(on + 0.01 * Vec3(u(rng), u(rng), u(rng)));
    }
    int wrong = 0, decided = 0;
    for (const Vec3& x : points)
    {
      Vec3 cp;
      int f = -1;
      double d = 0.0;
      ASSERT_TRUE(tree.closestPoint(x, -1.0, cp, f, d));
      const double w = windingNumber(mesh, x);
      if (d < 1e-9 || std::abs(w - 0.5) < 0.25)
        continue; // on the surface, or not clearly on one side
      ++decided;
      const bool out = w < 0.5;
      wrong += sign.outside(x, f, cp) != out ? 1 : 0;
      faceWrong += ((x - cp).dot(sign.faceNormal(f)) > 0) != out ? 1 : 0;
    }
    EXPECT_GT(decided, static_cast<int>(points.size()) / 2);
    EXPECT_EQ(wrong, 0) << "of " << decided;
  }
  EXPECT_GT(faceWrong, 0);
  std::printf("the face normal alone: %d wrong\n", faceWrong);
}
