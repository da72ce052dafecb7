// SDFCage — Testing: evaluateCage (Core/CageQuality) on hand-made good and broken cages, every
// verdict cross-checked with the independent CGAL checker (Testing/Exact), distances checked
// against brute force.
#include "Quality/CageQuality.h"
#include "ExactCheck.h"
#include "MeshIO.h"
#include "Spatial/Geometry.h"
#include "Mesh/Mesh.h"
#include "Common/Progress.h"
#include "Mesh/Shapes.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace sdfcage;

namespace
{

TriangleMesh unitSphere()
{
  // slices divisible by 4 and an even number of stacks: vertices at (+-1, 0, 0), (0, +-1, 0),
  // (0, 0, +-1), so a box of half-size 1 touches it exactly there
  return makeSphere(Vec3::Zero(), 1.0, 32, 16);
}

TriangleMesh cube(double half)
{
  return makeBox(Vec3::Constant(-half), Vec3::Constant(half));
}

double diagonal(const TriangleMesh& m)
{
  const auto b = bounds(m);
  return (b[1] - b[0]).norm();
}

/// Brute-force area-weighted mean distance from `from` to `to`: midpoint rule on k x k
/// sub-triangles of each triangle.
double bruteMeanDistance(const TriangleMesh& from, const TriangleMesh& to, int k)
{
  double sum = 0.0, area = 0.0;
  for (const Triangle& t : from.Triangles)
  {
    const Vec3 &a = from.Points[t[0]], &b = from.Points[t[1]], &c = from.Points[t[2]];
    const double ar = 0.5 * (b - a).cross(c - a).norm();
    auto dist = [&](double u, double v) {
      const Vec3 p = a + (b - a) * (u / k) + (c - a) * (v / k);
      double d = std::numeric_limits<double>::infinity();
      for (const Triangle& o : to.Triangles)
      {
        d = std::min(d, (p - closestPointOnTriangle(p, to.Points[o[0]], to.Points[o[1]], to.Points[o[2]])).norm());
      }
      return d;
    };
    double s = 0.0;
    for (int i = 0; i < k; ++i)
    {
      for (int j = 0; i + j < k; ++j)
      {
        s += dist(i + 1.0 / 3.0, j + 1.0 / 3.0);
        if (i + j < k - 1)
        {
          s += dist(i + 2.0 / 3.0, j + 2.0 / 3.0);
        }
      }
    }
    sum += ar * s / (k * k);
    area += ar;
  }
  return sum / area;
}

/// Brute-force max over dense samples of `from` (each triangle split k x k) of the distance to
/// every triangle of `to`.
double bruteMaxDistance(const TriangleMesh& from, const TriangleMesh& to, int k, double* mean = nullptr)
{
  double best = 0.0, sum = 0.0, area = 0.0;
  for (const Triangle& t : from.Triangles)
  {
    const Vec3 &a = from.Points[t[0]], &b = from.Points[t[1]], &c = from.Points[t[2]];
    const double ar = 0.5 * (b - a).cross(c - a).norm();
    double s = 0.0;
    int cnt = 0;
    for (int i = 0; i <= k; ++i)
    {
      for (int j = 0; i + j <= k; ++j)
      {
        const Vec3 p = a + (b - a) * (double(i) / k) + (c - a) * (double(j) / k);
        double d = std::numeric_limits<double>::infinity();
        for (const Triangle& o : to.Triangles)
        {
          d = std::min(d, (p - closestPointOnTriangle(p, to.Points[o[0]], to.Points[o[1]], to.Points[o[2]])).norm());
        }
        best = std::max(best, d);
        s += d;
        ++cnt;
      }
    }
    sum += ar * s / cnt;
    area += ar;
  }
  if (mean)
  {
    *mean = sum / area;
  }
  return best;
}

/// The verdicts of evaluateCage must agree with CGAL's exact predicates.
void expectAgreesWithExact(const TriangleMesh& input, const TriangleMesh& cage, const CageQualityResult& q)
{
  const exact::ExactReport e = exact::exactCheck(input, cage, 0.0);
  EXPECT_EQ(q.Encloses, e.Encloses) << q.Message << "\nexact: " << exact::toJson(e);
  EXPECT_EQ(q.SelfIntersections > 0, e.SelfIntersections > 0) << q.SelfIntersections << " vs " << e.SelfIntersections;
  EXPECT_EQ(q.InputIntersections > 0, e.InputIntersections > 0)
    << q.InputIntersections << " vs " << e.InputIntersections;
  EXPECT_EQ(q.InputVerticesOutside, e.InputVerticesOutside);
  EXPECT_EQ(q.CageClosedManifold, e.Closed2Manifold);
  if (e.Closed2Manifold)
  {
    EXPECT_EQ(q.CageGenus, e.CageGenus);
  }
  if (!e.ClearanceIsLowerBound)
  {
    EXPECT_NEAR(q.MinimumClearance, e.MinimumClearance, 1e-12 * q.Diagonal + 1e-9 * e.MinimumClearance);
  }
}

} // namespace

TEST(CageQuality, ShapeMeasuresOfOneTriangle)
{
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0.5, std::sqrt(3.0) / 2, 0);
  EXPECT_NEAR(triangleMIPSEnergy(a, b, c), 2.0, 1e-12);
  EXPECT_NEAR(triangleMinimumAngle(a, b, c), 60.0, 1e-9);
  const Vec3 d(0, 1, 0);
  EXPECT_NEAR(triangleMIPSEnergy(a, b, d), 4.0 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(triangleMinimumAngle(a, b, d), 45.0, 1e-9);
  EXPECT_EQ(triangleMinimumAngle(a, b, Vec3(2, 0, 0)), 0.0);
  EXPECT_TRUE(std::isinf(triangleMIPSEnergy(a, b, Vec3(2, 0, 0))));
}

TEST(CageQuality, GoodBoxAroundSphere)
{
  const TriangleMesh sphere = unitSphere(), box = cube(1.5);
  const CageQualityResult q = evaluateCage(sphere, box);
  EXPECT_TRUE(q.Encloses) << q.Message;
  EXPECT_TRUE(q.Message.empty()) << q.Message;
  // the sphere's vertices (+-1,0,0) etc. are the closest points to the faces
  EXPECT_NEAR(q.MinimumClearance, 0.5, 1e-12);
  EXPECT_EQ(q.SelfIntersections, 0);
  EXPECT_EQ(q.InputIntersections, 0);
  EXPECT_EQ(q.InputVerticesOutside, 0);
  EXPECT_EQ(q.InputVertices, static_cast<long long>(sphere.Points.size()));
  EXPECT_EQ(q.CageGenus, 0);
  EXPECT_EQ(q.InputGenus, 0);
  EXPECT_TRUE(q.CageClosedManifold);
  EXPECT_FALSE(q.CageInwardOriented);
  ASSERT_EQ(q.PointDistance.size(), box.Points.size());
  ASSERT_EQ(q.CellDistance.size(), box.Triangles.size());
  for (std::size_t i = 0; i < box.Points.size(); ++i)
  {
    double d = std::numeric_limits<double>::infinity();
    for (const Triangle& o : sphere.Triangles)
    {
      d = std::min(d,
        (box.Points[i] -
          closestPointOnTriangle(box.Points[i], sphere.Points[o[0]], sphere.Points[o[1]], sphere.Points[o[2]]))
          .norm());
    }
    EXPECT_NEAR(q.PointDistance[i], d, 1e-12);
  }
  for (std::size_t f = 0; f < box.Triangles.size(); ++f)
  {
    EXPECT_NEAR(q.CellMinimumAngle[f], 45.0, 1e-9);
    EXPECT_NEAR(q.CellMIPSEnergy[f], 4.0 / std::sqrt(3.0), 1e-9);
    EXPECT_GE(q.CellDistance[f], 0.5);
  }
  // Hausdorff both ways and the mean against brute force
  const double tol = CageQualityOptions().HausdorffTolerance * q.Diagonal;
  const double cageToInput = bruteMaxDistance(box, sphere, 40);
  const double bruteMean = bruteMeanDistance(box, sphere, 48);
  EXPECT_LE(q.HausdorffCageToInput, q.HausdorffCageToInputBound);
  EXPECT_GE(q.HausdorffCageToInputBound, cageToInput - 1e-12);
  EXPECT_GE(q.HausdorffCageToInput, cageToInput - tol);
  EXPECT_LE(q.HausdorffCageToInputBound - q.HausdorffCageToInput, tol * 1.0001);
  EXPECT_NEAR(q.MeanDistanceCageToInput, bruteMean, 0.002 * bruteMean);
  const double inputToCage = bruteMaxDistance(sphere, box, 8);
  EXPECT_GE(q.HausdorffInputToCageBound, inputToCage - 1e-12);
  EXPECT_GE(q.HausdorffInputToCage, inputToCage - tol);
  EXPECT_LE(q.HausdorffInputToCageBound - q.HausdorffInputToCage, tol * 1.0001);
  expectAgreesWithExact(sphere, box, q);
}

TEST(CageQuality, BoxThatCutsTheSphere)
{
  const TriangleMesh sphere = unitSphere(), box = cube(0.8);
  const CageQualityResult q = evaluateCage(sphere, box);
  EXPECT_FALSE(q.Encloses);
  EXPECT_EQ(q.MinimumClearance, 0.0);
  EXPECT_GT(q.InputIntersections, 0);
  EXPECT_GT(q.InputVerticesOutside, 0);
  EXPECT_LT(q.InputVerticesOutside, q.InputVertices);
  EXPECT_NE(q.Message.find("intersects or touches the input"), std::string::npos) << q.Message;
  // brute-force count of input vertices outside the box
  long long outside = 0;
  for (const Vec3& p : sphere.Points)
  {
    outside += p.cwiseAbs().maxCoeff() >= 0.8;
  }
  EXPECT_EQ(q.InputVerticesOutside, outside);
  expectAgreesWithExact(sphere, box, q);
}

TEST(CageQuality, OpenCage)
{
  const TriangleMesh sphere = unitSphere();
  TriangleMesh box = cube(1.5);
  box.Triangles.pop_back();
  const CageQualityResult q = evaluateCage(sphere, box);
  EXPECT_FALSE(q.Encloses);
  EXPECT_FALSE(q.CageClosedManifold);
  EXPECT_EQ(q.BoundaryEdges, 3);
  EXPECT_EQ(q.CageGenus, -1);
  EXPECT_EQ(q.InputVerticesOutside, q.InputVertices);
  EXPECT_NE(q.Message.find("not a closed 2-manifold"), std::string::npos) << q.Message;
  // distances are still measured
  EXPECT_NEAR(q.MinimumClearance, 0.5, 1e-12);
  expectAgreesWithExact(sphere, box, q);
}

TEST(CageQuality, SelfIntersectingCage)
{
  const TriangleMesh sphere = unitSphere();
  TriangleMesh cage = cube(1.5);
  TriangleMesh second = makeBox(Vec3(-1.3, -1.6, -1.6), Vec3(1.8, 1.4, 1.4));
  appendMesh(cage, second);
  const CageQualityResult q = evaluateCage(sphere, cage);
  EXPECT_FALSE(q.Encloses);
  EXPECT_TRUE(q.CageClosedManifold);
  EXPECT_GT(q.SelfIntersections, 0);
  EXPECT_EQ(q.InputIntersections, 0);
  EXPECT_EQ(q.CageComponents, 2);
  // inside both boxes the winding number is 2: by parity (as a ray test) outside
  EXPECT_EQ(q.InputVerticesOutside, q.InputVertices);
  expectAgreesWithExact(sphere, cage, q);
}

TEST(CageQuality, TouchingCageDoesNotEnclose)
{
  const TriangleMesh sphere = unitSphere(), box = cube(1.0);
  const CageQualityResult q = evaluateCage(sphere, box);
  EXPECT_FALSE(q.Encloses);
  EXPECT_EQ(q.MinimumClearance, 0.0);
  EXPECT_GT(q.InputIntersections, 0);
  // the six axis vertices lie on the faces: not strictly inside
  EXPECT_EQ(q.InputVerticesOutside, 6);
  expectAgreesWithExact(sphere, box, q);
}

TEST(CageQuality, CageWithTinyClearanceEncloses)
{
  const TriangleMesh sphere = unitSphere();
  const double gap = 1e-6 * diagonal(sphere);
  const TriangleMesh box = cube(1.0 + gap);
  const CageQualityResult q = evaluateCage(sphere, box);
  EXPECT_TRUE(q.Encloses) << q.Message;
  EXPECT_NEAR(q.MinimumClearance, gap, 1e-15);
  EXPECT_EQ(q.InputVerticesOutside, 0);
  expectAgreesWithExact(sphere, box, q);
}

TEST(CageQuality, InwardOrientedCageEnclosesAndIsReported)
{
  const TriangleMesh sphere = unitSphere();
  TriangleMesh box = cube(1.5);
  reverseOrientation(box);
  const CageQualityResult q = evaluateCage(sphere, box);
  EXPECT_TRUE(q.Encloses) << q.Message;
  EXPECT_TRUE(q.CageInwardOriented);
  expectAgreesWithExact(sphere, box, q);
}

TEST(CageQuality, TorusGenusAndCageAroundIt)
{
  const TriangleMesh torus = makeTorus(Vec3::Zero(), 1.0, 0.3, 48, 16);
  const TriangleMesh box = makeBox(Vec3(-1.5, -1.5, -0.5), Vec3(1.5, 1.5, 0.5));
  const CageQualityResult q = evaluateCage(torus, box);
  EXPECT_EQ(q.InputGenus, 1);
  EXPECT_EQ(q.CageGenus, 0);
  EXPECT_TRUE(q.Encloses) << q.Message;
  expectAgreesWithExact(torus, box, q);
  // a box through the hole of the torus cuts it
  const TriangleMesh thin = makeBox(Vec3(-0.5, -0.5, -2), Vec3(0.5, 0.5, 2));
  const CageQualityResult q2 = evaluateCage(torus, thin);
  EXPECT_FALSE(q2.Encloses);
  expectAgreesWithExact(torus, thin, q2);
}

TEST(CageQuality, EmptyAndInvalidMeshesAreReportedNotFatal)
{
  const TriangleMesh sphere = unitSphere();
  const CageQualityResult empty = evaluateCage(sphere, TriangleMesh());
  EXPECT_FALSE(empty.Encloses);
  EXPECT_NE(empty.Message.find("no triangles"), std::string::npos) << empty.Message;
  EXPECT_EQ(empty.InputVerticesOutside, empty.InputVertices);

  const CageQualityResult noInput = evaluateCage(TriangleMesh(), cube(1.5));
  EXPECT_FALSE(noInput.Encloses);
  EXPECT_NE(noInput.Message.find("input mesh has no triangles"), std::string::npos) << noInput.Message;
  EXPECT_EQ(noInput.CellMinimumAngle.size(), 12u);

  TriangleMesh bad = cube(1.5);
  bad.Triangles.push_back({ 0, 1, 99 });
  bad.Points.push_back(Vec3(std::nan(""), 0, 0));
  bad.Triangles.push_back({ 0, 1, 8 });
  const CageQualityResult q = evaluateCage(sphere, bad);
  EXPECT_FALSE(q.Encloses);
  EXPECT_EQ(q.InvalidTriangles, 2);
  EXPECT_EQ(q.CellDistance.size(), bad.Triangles.size());
  EXPECT_TRUE(std::isnan(q.CellDistance[12]));
  EXPECT_FALSE(std::isnan(q.CellDistance[0]));

  // non-manifold: the same box twice sharing its points
  TriangleMesh doubled = cube(1.5);
  const auto tris = doubled.Triangles;
  doubled.Triangles.insert(doubled.Triangles.end(), tris.begin(), tris.end());
  const CageQualityResult nm = evaluateCage(sphere, doubled);
  EXPECT_FALSE(nm.Encloses);
  EXPECT_GT(nm.NonManifoldEdges, 0);
  EXPECT_GT(nm.SelfIntersections, 0);
}

TEST(CageQuality, CancelReturnsEarly)
{
  Progress progress;
  progress.cancel();
  const CageQualityResult q = evaluateCage(unitSphere(), cube(1.5), CageQualityOptions(), &progress);
  EXPECT_FALSE(q.Encloses);
  EXPECT_EQ(q.Message, "cancelled");
}

namespace
{
/// A tetrahedron (closed, outward) with corners a, b, c, d (d above the plane of a, b, c).
TriangleMesh tetrahedron(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
{
  TriangleMesh m;
  m.Points = { a, b, c, d };
  m.Triangles = { { 0, 2, 1 }, { 0, 1, 3 }, { 1, 2, 3 }, { 2, 0, 3 } };
  orientOutward(m);
  return m;
}
} // namespace

TEST(CageQuality, VertexExactlyOnAnInputEdgeTouches)
{
  // input: a tetrahedron; (0.5, 1, 1.5) lies exactly (in binary too) on its edge (0,0,0)-(1,2,3)
  const TriangleMesh input = tetrahedron(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(1, 2, 3));
  const Vec3 m(0.5, 1.0, 1.5);
  // away from the edge, perpendicular to it, away from the input's centroid
  const Vec3 d = Vec3(1, 2, 3).normalized();
  Vec3 u = m - Vec3(0.75, 1.0, 0.75);
  u = (u - u.dot(d) * d).normalized();
  auto cageWithApex = [&](const Vec3& apex) {
    return tetrahedron(
      apex, apex + 3.0 * u + Vec3(0.3, 0, 0), apex + 3.0 * u + Vec3(0, 0.3, 0), apex + 3.0 * u + Vec3(0, 0, 0.3));
  };
  // touching: not enclosing, clearance 0, the touching pairs counted; CGAL agrees
  const TriangleMesh touching = cageWithApex(m);
  const CageQualityResult q = evaluateCage(input, touching);
  EXPECT_EQ(q.MinimumClearance, 0.0);
  EXPECT_GT(q.InputIntersections, 0);
  const exact::ExactReport e = exact::exactCheck(input, touching, 0.0);
  EXPECT_GT(e.InputIntersections, 0);
  EXPECT_FALSE(q.Encloses);
  EXPECT_FALSE(e.Encloses);

  // 1e-6 of the diagonal away: no intersection, clearance about that gap (CGAL agrees)
  const double gap = 1e-6 * diagonal(input);
  const TriangleMesh near = cageWithApex(m + gap * u);
  const CageQualityResult qn = evaluateCage(input, near);
  EXPECT_EQ(qn.InputIntersections, 0);
  EXPECT_GT(qn.MinimumClearance, 0.5 * gap);
  EXPECT_LE(qn.MinimumClearance, gap * (1 + 1e-6));
  const exact::ExactReport en = exact::exactCheck(input, near, 0.0);
  EXPECT_EQ(en.InputIntersections, 0);
  EXPECT_NEAR(qn.MinimumClearance, en.MinimumClearance, 1e-12 * qn.Diagonal);
}

TEST(CageQuality, RealMeshScaledCopiesAgreeWithExact)
{
  const std::string path = std::string(SDFCAGE_DATA_DIR) + "/bunny.off";
  PolygonMesh polygons;
  std::string error;
  if (!exact::readPolygonMesh(path, polygons, error))
  {
    GTEST_SKIP() << "no data: " << error;
  }
  TriangleMesh bunny;
  exact::fanTriangulate(polygons, bunny);
  const auto box = bounds(bunny);
  const Vec3 centre = 0.5 * (box[0] + box[1]);
  // scaled copies about the box centre: the bunny is not star-shaped, so the larger copies may
  // or may not enclose it; whatever the verdict, CGAL's exact predicates must agree
  for (double scale : { 0.97, 1.0, 1.03, 1.2 })
  {
    TriangleMesh cage = bunny;
    // (scale 1 keeps the points bit for bit: centre + (p - centre) may move them by an ulp, and
    // an ulp is "touching" for evaluateCage (1e-10 of the diagonal) but not for CGAL)
    for (Vec3& p : cage.Points)
    {
      p = scale == 1.0 ? p : Vec3(centre + scale * (p - centre));
    }
    const CageQualityResult q = evaluateCage(bunny, cage);
    SCOPED_TRACE("scale " + std::to_string(scale) + ": " + q.Message);
    if (scale <= 1.0)
    {
      EXPECT_FALSE(q.Encloses);
    }
    if (scale == 1.0)
    {
      EXPECT_EQ(q.MinimumClearance, 0.0); // the same surface: touches everywhere
      EXPECT_EQ(q.InputVerticesOutside, q.InputVertices);
    }
    EXPECT_EQ(q.CageGenus, q.InputGenus);
    expectAgreesWithExact(bunny, cage, q);
  }
}

TEST(CageQuality, SameResultsWithOneThread)
{
  const TriangleMesh torus = makeTorus(Vec3::Zero(), 1.0, 0.3, 64, 24);
  TriangleMesh cage = makeSphere(Vec3(0.1, 0.0, 0.05), 1.45, 12, 8);
  const CageQualityResult many = evaluateCage(torus, cage);
  CageQualityResult one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = evaluateCage(torus, cage);
  }
  EXPECT_EQ(many.Encloses, one.Encloses);
  EXPECT_EQ(many.MinimumClearance, one.MinimumClearance);
  EXPECT_EQ(many.HausdorffCageToInput, one.HausdorffCageToInput);
  EXPECT_EQ(many.HausdorffCageToInputBound, one.HausdorffCageToInputBound);
  EXPECT_EQ(many.HausdorffInputToCage, one.HausdorffInputToCage);
  EXPECT_EQ(many.HausdorffInputToCageBound, one.HausdorffInputToCageBound);
  EXPECT_EQ(many.MeanDistanceCageToInput, one.MeanDistanceCageToInput);
  EXPECT_EQ(many.InputVerticesOutside, one.InputVerticesOutside);
  EXPECT_EQ(many.InputIntersections, one.InputIntersections);
  EXPECT_EQ(many.CellDistance, one.CellDistance);
  EXPECT_EQ(many.PointDistance, one.PointDistance);
}

TEST(CageQuality, ShallowCrossingCountsAsTouching)
{
  // The input's top face lies in z = 0; the cage's apex pokes 1e-11 below it (inside the input):
  // a crossing too shallow for the orientation test, which the distances then report as ~1e-11.
  // It must count as an intersection (CGAL: it crosses).
  const TriangleMesh input = tetrahedron(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(0.5, 0.5, -1));
  const Vec3 apex(0.5, 0.5, -1e-11);
  const TriangleMesh cage = tetrahedron(apex, Vec3(0, 0, 3), Vec3(1, 0, 3), Vec3(0, 1, 3));
  const CageQualityResult q = evaluateCage(input, cage);
  EXPECT_EQ(q.MinimumClearance, 0.0);
  EXPECT_GT(q.InputIntersections, 0);
  const exact::ExactReport e = exact::exactCheck(input, cage, 0.0);
  EXPECT_GT(e.InputIntersections, 0);
}
