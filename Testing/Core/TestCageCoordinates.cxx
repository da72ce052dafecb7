// SDFCage — Testing: mean value and Green cage coordinates (Core/Deformation).
#include "Deformation/CageCoordinates.h"
#include "GridBox.h"
#include "Mesh/Shapes.h"
#include "Spatial/Geometry.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <iostream>
#include <random>

using namespace sdfcage;
using sdfcage_test::bend;
using sdfcage_test::makeGridBox;

namespace
{

const CageCoordinateKind Kinds[] = { CageCoordinateKind::MeanValue, CageCoordinateKind::Green };

double diagonal(const TriangleMesh& m)
{
  const auto b = bounds(m);
  return (b[1] - b[0]).norm();
}

/// Random points strictly inside the torus tube (distance to the core circle < 0.8 minor radius).
std::vector<Vec3> pointsInTorus(double major, double minor, int count, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < count)
  {
    const double a = 2.0 * M_PI * u(rng), b = 2.0 * M_PI * u(rng), r = 0.8 * minor * u(rng);
    out.emplace_back((major + r * std::cos(b)) * std::cos(a), (major + r * std::cos(b)) * std::sin(a), r * std::sin(b));
  }
  return out;
}

/// A non-convex cage (a torus) and points in its tube, plus the vertices of an inner torus.
struct TorusCase
{
  TriangleMesh Cage = makeTorus(Vec3::Zero(), 1.0, 0.45, 24, 10);
  std::vector<Vec3> Points;
  TorusCase()
  {
    this->Points = pointsInTorus(1.0, 0.45 * std::cos(M_PI / 10), 300, 7);
    const TriangleMesh inner = makeTorus(Vec3::Zero(), 1.0, 0.25, 40, 16);
    this->Points.insert(this->Points.end(), inner.Points.begin(), inner.Points.end());
  }
};

double maxError(const std::vector<Vec3>& a, const std::vector<Vec3>& b)
{
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    worst = std::max(worst, (a[i] - b[i]).norm());
  }
  return worst;
}

std::vector<Vec3> mapped(const std::vector<Vec3>& points, const Eigen::Matrix3d& a, const Vec3& t)
{
  std::vector<Vec3> out;
  for (const Vec3& p : points)
  {
    out.push_back(a * p + t);
  }
  return out;
}

/// Mean absolute change of the triangle angles (degrees) between `before` and `after`; the largest
/// change into *largest (which must start at 0).
double angleDistortion(
  const std::vector<Triangle>& triangles, const std::vector<Vec3>& before, const std::vector<Vec3>& after, double* largest)
{
  auto angle = [](const Vec3& a, const Vec3& b, const Vec3& c) {
    return std::atan2((b - a).cross(c - a).norm(), (b - a).dot(c - a));
  };
  double sum = 0.0;
  for (const Triangle& t : triangles)
  {
    for (int k = 0; k < 3; ++k)
    {
      const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      const double change = std::abs(angle(after[a], after[b], after[c]) - angle(before[a], before[b], before[c]));
      sum += change;
      *largest = std::max(*largest, change * 180.0 / M_PI);
    }
  }
  return sum / (3.0 * triangles.size()) * 180.0 / M_PI;
}

} // namespace

TEST(CageCoordinates, GridBoxIsAValidCage)
{
  const TriangleMesh box = makeGridBox(Vec3(0, 0, 0), Vec3(4, 1, 1), { 8, 2, 2 });
  EXPECT_EQ(checkCage(box), "");
  EXPECT_NEAR(signedVolume(box), 4.0, 1e-12);
  EXPECT_EQ(checkCage(makeTorus(Vec3::Zero(), 1.0, 0.45, 24, 10)), "");
}

TEST(CageCoordinates, RestCageReproducesPoints)
{
  const TorusCase c;
  const double diag = diagonal(c.Cage);
  for (CageCoordinateKind kind : Kinds)
  {
    CageDeformer deformer;
    CageCoordinateOptions o;
    o.Kind = kind;
    const CageBindingResult r = deformer.bind(c.Cage, c.Points, o);
    ASSERT_EQ(r.State, Status::Ok) << r.Message;
    EXPECT_EQ(r.PointsOutside, 0);
    EXPECT_EQ(r.PointsOnCage, 0);
    EXPECT_EQ(r.MeanValueFallbacks, 0);
    EXPECT_LT(r.ReproductionError, 1e-9) << cageCoordinateKindName(kind);
    std::vector<Vec3> out;
    ASSERT_TRUE(deformer.apply(c.Cage.Points, out));
    EXPECT_LT(maxError(out, c.Points), 1e-9 * diag) << cageCoordinateKindName(kind);
    if (kind == CageCoordinateKind::Green)
    {
      EXPECT_TRUE(deformer.usesGreen(0));
      // partition of unity of phi inside; psi sums to the (positive) single-layer potential
      const std::vector<double> w = deformer.weights(0);
      ASSERT_EQ(w.size(), c.Cage.Points.size() + c.Cage.Triangles.size());
      double sum = 0.0;
      for (std::size_t i = 0; i < c.Cage.Points.size(); ++i)
      {
        sum += w[i];
      }
      EXPECT_NEAR(sum, 1.0, 1e-12);
    }
    else
    {
      // mean value coordinates are positive inside a cage... only for convex cages; they sum to 1
      const std::vector<double> w = deformer.weights(5);
      double sum = 0.0;
      for (double x : w)
      {
        sum += x;
      }
      EXPECT_NEAR(sum, 1.0, 1e-12);
    }
  }
}

TEST(CageCoordinates, MeanValueReproducesAffineMaps)
{
  const TorusCase c;
  std::vector<Vec3> points = c.Points;
  // mean value coordinates extend outside the cage and reproduce affine maps there too
  points.emplace_back(0.0, 0.0, 0.0);
  points.emplace_back(3.0, -2.0, 1.0);
  CageDeformer deformer;
  const CageBindingResult r = deformer.bind(c.Cage, points, {});
  ASSERT_EQ(r.State, Status::Ok) << r.Message;
  EXPECT_EQ(r.PointsOutside, 2);
  Eigen::Matrix3d a;
  a << 1.3, 0.4, -0.2, 0.1, 0.7, 0.5, -0.3, 0.2, 1.6; // shear and non-uniform scale
  const Vec3 t(0.5, -1.0, 2.0);
  std::vector<Vec3> out;
  ASSERT_TRUE(deformer.apply(mapped(c.Cage.Points, a, t), out));
  const std::vector<Vec3> expected = mapped(points, a, t);
  EXPECT_LT(maxError(out, expected), 1e-9 * diagonal(c.Cage));
}

TEST(CageCoordinates, GreenReproducesSimilaritiesButNotShears)
{
  const TorusCase c;
  CageDeformer deformer;
  CageCoordinateOptions o;
  o.Kind = CageCoordinateKind::Green;
  const CageBindingResult r = deformer.bind(c.Cage, c.Points, o);
  ASSERT_EQ(r.State, Status::Ok) << r.Message;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, -1).normalized()).toRotationMatrix();
  const Eigen::Matrix3d similarity = 1.7 * rotation;
  const Vec3 t(-2.0, 0.3, 1.1);
  std::vector<Vec3> out;
  ASSERT_TRUE(deformer.apply(mapped(c.Cage.Points, similarity, t), out));
  const double diag = diagonal(c.Cage);
  EXPECT_LT(maxError(out, mapped(c.Points, similarity, t)), 1e-9 * diag);

  // a shear is not reproduced: Green coordinates do not follow the cage's affine maps, they keep
  // the shape (quasi-conformal) — the difference must be clearly above rounding
  Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
  shear(0, 2) = 0.8;
  ASSERT_TRUE(deformer.apply(mapped(c.Cage.Points, shear, Vec3::Zero()), out));
  EXPECT_GT(maxError(out, mapped(c.Points, shear, Vec3::Zero())), 1e-3 * diag);
}

TEST(CageCoordinates, GreenPreservesAnglesBetterThanMeanValueOnABend)
{
  // a coarse bar cage (2 x 2 cells across, like a real cage) bent by a quarter turn; the mesh
  // inside is a finer bar of right isosceles triangles. Measured: mean angle change mean value
  // 3.07 deg, Green 2.12 deg (the exact bend of the inner bar itself: 2.30 deg); largest 10.9 vs
  // 6.6 deg. Green's deformations are quasi-conformal, mean value coordinates shear the bar.
  const TriangleMesh cage = makeGridBox(Vec3(0, -0.5, -0.5), Vec3(4, 0.5, 0.5), { 4, 2, 2 });
  const TriangleMesh inner = makeGridBox(Vec3(0.1, -0.4, -0.4), Vec3(3.9, 0.4, 0.4), { 30, 6, 6 });
  const double radius = 4.0 / (0.5 * M_PI);
  std::vector<Vec3> bent;
  for (const Vec3& p : cage.Points)
  {
    bent.push_back(bend(p, radius));
  }
  double mean[2], worst[2] = { 0.0, 0.0 };
  for (CageCoordinateKind kind : Kinds)
  {
    CageDeformer deformer;
    CageCoordinateOptions o;
    o.Kind = kind;
    const CageBindingResult r = deformer.bind(cage, inner.Points, o);
    ASSERT_EQ(r.State, Status::Ok) << r.Message;
    EXPECT_EQ(r.PointsOutside, 0);
    std::vector<Vec3> out;
    ASSERT_TRUE(deformer.apply(bent, out));
    for (const Vec3& p : out)
    {
      ASSERT_TRUE(p.allFinite());
    }
    mean[static_cast<int>(kind)] = angleDistortion(inner.Triangles, inner.Points, out, &worst[static_cast<int>(kind)]);
  }
  std::cout << "angle change on the bend (mean, largest): mean value " << mean[0] << ", " << worst[0]
            << " deg; Green " << mean[1] << ", " << worst[1] << " deg\n";
  EXPECT_LT(mean[1], 0.8 * mean[0]);
  EXPECT_LT(worst[1], 0.8 * worst[0]);
}

TEST(CageCoordinates, GreenClosedFormsMatchQuadrature)
{
  // phi_i = 1/(4 pi) int Gamma_i (y - x).n / |y - x|^3, psi_j = 1/(4 pi) int 1 / |y - x|, by a
  // midpoint rule on 300^2 sub-triangles per cage triangle
  const TriangleMesh cage = makeGridBox(Vec3(0, -0.5, -0.5), Vec3(4, 0.5, 0.5), { 4, 1, 1 });
  const Vec3 x(1.3, 0.1, -0.2);
  CageDeformer deformer;
  CageCoordinateOptions o;
  o.Kind = CageCoordinateKind::Green;
  ASSERT_EQ(deformer.bind(cage, { x }, o).State, Status::Ok);
  const std::vector<double> w = deformer.weights(0);
  const std::size_t nv = cage.Points.size(), nf = cage.Triangles.size();
  std::vector<double> phi(nv, 0.0), psi(nf, 0.0);
  const int n = 300;
  for (std::size_t j = 0; j < nf; ++j)
  {
    const Triangle& t = cage.Triangles[j];
    const Vec3 &p0 = cage.Points[t[0]], &p1 = cage.Points[t[1]], &p2 = cage.Points[t[2]];
    const Vec3 c = (p1 - p0).cross(p2 - p0);
    const Vec3 normal = c.normalized();
    const double dA = 0.5 * c.norm() / (n * n);
    for (int a = 0; a < n; ++a)
    {
      for (int b = 0; a + b < n; ++b)
      {
        for (int up = 0; up < 2 && (up == 0 || a + b + 1 < n); ++up)
        {
          const double l1 = (a + (up ? 2.0 : 1.0) / 3.0) / n, l2 = (b + (up ? 2.0 : 1.0) / 3.0) / n;
          const double l0 = 1.0 - l1 - l2;
          const Vec3 y = l0 * p0 + l1 * p1 + l2 * p2;
          const double r = (y - x).norm();
          psi[j] += dA / r / (4.0 * M_PI);
          const double k = dA * (y - x).dot(normal) / (r * r * r) / (4.0 * M_PI);
          phi[t[0]] += l0 * k;
          phi[t[1]] += l1 * k;
          phi[t[2]] += l2 * k;
        }
      }
    }
  }
  for (std::size_t i = 0; i < nv; ++i)
  {
    EXPECT_NEAR(w[i], phi[i], 1e-6) << "phi " << i;
  }
  for (std::size_t j = 0; j < nf; ++j)
  {
    EXPECT_NEAR(w[nv + j], psi[j], 1e-6) << "psi " << j;
  }
}

TEST(CageCoordinates, FiniteEverywhereAndOutsideCounted)
{
  const TriangleMesh cage = makeGridBox(Vec3(0, 0, 0), Vec3(2, 1, 1), { 4, 2, 2 });
  const Triangle& t0 = cage.Triangles[0];
  std::vector<Vec3> points = {
    Vec3(1.0, 0.5, 0.5),                                                      // inside
    Vec3(1.0, 0.5, 1e-7),                                                     // just inside, near a face
    cage.Points[3],                                                           // a cage vertex
    0.5 * (cage.Points[t0[0]] + cage.Points[t0[1]]),                          // a cage edge
    (cage.Points[t0[0]] + cage.Points[t0[1]] + cage.Points[t0[2]]) / 3.0,     // a cage triangle
    Vec3(1.0, 0.5, 1.2),                                                      // outside, near
    Vec3(50.0, -30.0, 20.0),                                                  // outside, far
    Vec3(2.0, 1.0, 3.0),                                                      // on the line of an edge
  };
  for (CageCoordinateKind kind : Kinds)
  {
    CageDeformer deformer;
    CageCoordinateOptions o;
    o.Kind = kind;
    const CageBindingResult r = deformer.bind(cage, points, o);
    ASSERT_EQ(r.State, Status::Ok) << r.Message;
    EXPECT_EQ(r.PointsOnCage, 3) << cageCoordinateKindName(kind);
    EXPECT_EQ(r.PointsOutside, 3) << cageCoordinateKindName(kind);
    EXPECT_EQ(r.MeanValueFallbacks, kind == CageCoordinateKind::Green ? 6 : 0);
    std::vector<Vec3> bent, out;
    for (const Vec3& p : cage.Points)
    {
      bent.push_back(bend(p, 1.5));
    }
    ASSERT_TRUE(deformer.apply(bent, out));
    for (const Vec3& p : out)
    {
      EXPECT_TRUE(p.allFinite()) << cageCoordinateKindName(kind);
    }
    // points on the cage follow it: a vertex exactly, an edge and a triangle linearly
    EXPECT_LT((out[2] - bent[3]).norm(), 1e-12);
    EXPECT_LT((out[3] - 0.5 * (bent[t0[0]] + bent[t0[1]])).norm(), 1e-9);
    EXPECT_LT((out[4] - (bent[t0[0]] + bent[t0[1]] + bent[t0[2]]) / 3.0).norm(), 1e-9);
    // identity everywhere, outside too (mean value rows there)
    ASSERT_TRUE(deformer.apply(cage.Points, out));
    // (far outside, 30 cage sizes away, the unit vectors to the cage are nearly parallel and mean
    // value coordinates lose digits: 5e-9 relative measured there)
    for (std::size_t i = 0; i < points.size(); ++i)
    {
      EXPECT_LT((out[i] - points[i]).norm(), (i == 6 ? 1e-7 : 1e-9) * std::max(1.0, points[i].norm())) << i;
    }
  }
}

TEST(CageCoordinates, InwardCageIsUsedReversed)
{
  const TorusCase c;
  TriangleMesh inward = c.Cage;
  reverseOrientation(inward);
  Eigen::Matrix3d a = 1.2 * Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix();
  for (CageCoordinateKind kind : Kinds)
  {
    CageDeformer outward, reversed;
    CageCoordinateOptions o;
    o.Kind = kind;
    ASSERT_EQ(outward.bind(c.Cage, c.Points, o).State, Status::Ok);
    const CageBindingResult r = reversed.bind(inward, c.Points, o);
    ASSERT_EQ(r.State, Status::Ok);
    EXPECT_TRUE(r.CageWasFlipped);
    std::vector<Vec3> a1, a2;
    const std::vector<Vec3> target = mapped(c.Cage.Points, a, Vec3(0, 0, 1));
    ASSERT_TRUE(outward.apply(target, a1));
    ASSERT_TRUE(reversed.apply(target, a2));
    EXPECT_LT(maxError(a1, a2), 1e-12);
  }
}

TEST(CageCoordinates, ThreadCountDoesNotChangeResults)
{
  const TorusCase c;
  for (CageCoordinateKind kind : Kinds)
  {
    CageDeformer one, two;
    CageCoordinateOptions o;
    o.Kind = kind;
    o.NumberOfThreads = 1;
    ASSERT_EQ(one.bind(c.Cage, c.Points, o).State, Status::Ok);
    o.NumberOfThreads = 2;
    ASSERT_EQ(two.bind(c.Cage, c.Points, o).State, Status::Ok);
    std::vector<Vec3> bent, a1, a2;
    for (const Vec3& p : c.Cage.Points)
    {
      bent.push_back(bend(p, 2.0));
    }
    ASSERT_TRUE(one.apply(bent, a1, 1));
    ASSERT_TRUE(two.apply(bent, a2, 2));
    EXPECT_EQ(maxError(a1, a2), 0.0);
  }
}

TEST(CageCoordinates, BadCagesAreRefused)
{
  TriangleMesh open = makeGridBox(Vec3(0, 0, 0), Vec3(1, 1, 1), { 2, 2, 2 });
  open.Triangles.pop_back();
  CageDeformer deformer;
  CageBindingResult r = deformer.bind(open, { Vec3(0.5, 0.5, 0.5) }, {});
  EXPECT_EQ(r.State, Status::InvalidInput);
  EXPECT_NE(r.Message.find("boundary edge"), std::string::npos) << r.Message;
  EXPECT_FALSE(deformer.bound());
  std::vector<Vec3> out;
  EXPECT_FALSE(deformer.apply(open.Points, out));

  TriangleMesh tiny;
  tiny.Points = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0) };
  tiny.Triangles = { { 0, 1, 2 } };
  EXPECT_EQ(deformer.bind(tiny, {}, {}).State, Status::InvalidInput);

  // the deformed cage must have the rest cage's vertex count
  const TriangleMesh box = makeGridBox(Vec3(0, 0, 0), Vec3(1, 1, 1), { 2, 2, 2 });
  ASSERT_EQ(deformer.bind(box, { Vec3(0.5, 0.5, 0.5) }, {}).State, Status::Ok);
  std::vector<Vec3> fewer(box.Points.begin(), box.Points.end() - 1);
  EXPECT_FALSE(deformer.apply(fewer, out));
  EXPECT_TRUE(out.empty());

  // NaN points
  EXPECT_EQ(deformer.bind(box, { Vec3(NAN, 0, 0) }, {}).State, Status::InvalidInput);
}

TEST(CageCoordinates, GreenStretchFactor)
{
  const TriangleMesh box = makeGridBox(Vec3(0, 0, 0), Vec3(1, 1, 1), { 1, 1, 1 });
  std::vector<Vec3> scaled;
  for (const Vec3& p : box.Points)
  {
    scaled.push_back(2.5 * p);
  }
  const std::vector<Vec3> same = greenScaledNormals(box, box.Points);
  const std::vector<Vec3> big = greenScaledNormals(box, scaled);
  for (std::size_t j = 0; j < box.Triangles.size(); ++j)
  {
    EXPECT_NEAR(same[j].norm(), 1.0, 1e-14);
    EXPECT_NEAR(big[j].norm(), 2.5, 1e-14);
  }
}

TEST(CageCoordinates, InsideTestsAgree)
{
  // mean value mode decides inside/outside by a ray's crossings over a projected grid, Green mode
  // by the exact solid-angle sum: they must agree point by point (random points around a torus
  // cage, and points on the grid box's lattice, where rays graze edges)
  const TorusCase c;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.7, 1.7), w(-0.7, 0.7);
  std::vector<Vec3> points;
  for (int i = 0; i < 3000; ++i)
  {
    points.emplace_back(u(rng), u(rng), w(rng));
  }
  CageDeformer mvc, green;
  CageCoordinateOptions o;
  ASSERT_EQ(mvc.bind(c.Cage, points, o).State, Status::Ok);
  o.Kind = CageCoordinateKind::Green;
  ASSERT_EQ(green.bind(c.Cage, points, o).State, Status::Ok);
  int outside = 0, inside = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    ASSERT_EQ(mvc.location(i), green.location(i)) << i;
    const double wn = windingNumber(c.Cage, points[i]);
    EXPECT_EQ(mvc.location(i) == CageDeformer::Location::Inside, wn > 0.5) << i;
    (wn > 0.5 ? inside : outside)++;
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(outside, 300);

  const TriangleMesh box = makeGridBox(Vec3(0, 0, 0), Vec3(4, 2, 2), { 4, 2, 2 });
  std::vector<Vec3> lattice;
  for (int i = -1; i <= 9; ++i)
  {
    for (int j = -1; j <= 5; ++j)
    {
      for (int k = -1; k <= 5; ++k)
      {
        const Vec3 p(0.5 * i + 0.25, 0.5 * j + 0.25, 0.5 * k + 0.25);
        lattice.push_back(p);
      }
    }
  }
  CageDeformer onLattice;
  const CageBindingResult r = onLattice.bind(box, lattice, {});
  ASSERT_EQ(r.State, Status::Ok);
  long long expectedOutside = 0;
  for (std::size_t i = 0; i < lattice.size(); ++i)
  {
    const Vec3& p = lattice[i];
    const bool in = p.x() > 0 && p.x() < 4 && p.y() > 0 && p.y() < 2 && p.z() > 0 && p.z() < 2;
    expectedOutside += in ? 0 : 1;
    EXPECT_EQ(onLattice.location(i) == CageDeformer::Location::Inside, in) << p.transpose();
  }
  EXPECT_EQ(r.PointsOutside, expectedOutside);
}

TEST(CageCoordinates, SinglePrecisionWeights)
{
  const TorusCase c;
  const double diag = diagonal(c.Cage);
  const Eigen::Matrix3d similarity = 1.3 * Eigen::AngleAxisd(0.5, Vec3(0, 1, 1).normalized()).toRotationMatrix();
  const Vec3 t(0.2, 0.4, -1.0);
  for (CageCoordinateKind kind : Kinds)
  {
    CageDeformer single, full;
    CageCoordinateOptions o;
    o.Kind = kind;
    ASSERT_EQ(full.bind(c.Cage, c.Points, o).State, Status::Ok);
    o.SinglePrecision = true;
    const CageBindingResult r = single.bind(c.Cage, c.Points, o);
    ASSERT_EQ(r.State, Status::Ok);
    EXPECT_GT(r.ReproductionError, 0.0); // the rounded weights alone miss the points ...
    EXPECT_LT(r.ReproductionError, 1e-5);
    std::vector<Vec3> out, ref;
    ASSERT_TRUE(single.apply(c.Cage.Points, out));
    EXPECT_LT(maxError(out, c.Points), 1e-12 * diag); // ... the correction makes the identity exact
    ASSERT_TRUE(single.apply(mapped(c.Cage.Points, similarity, t), out));
    ASSERT_TRUE(full.apply(mapped(c.Cage.Points, similarity, t), ref));
    const double e = maxError(out, ref);
    EXPECT_LT(e, 1e-5 * diag) << cageCoordinateKindName(kind);
    EXPECT_GT(e, 0.0) << cageCoordinateKindName(kind);
    EXPECT_EQ(single.weights(3).size(), full.weights(3).size());
  }
}
