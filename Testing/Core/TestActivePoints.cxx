// SDFCage — Testing: active points, g_A, the amplified field and the shape-aware envelope
// (paper §3.1), with the envelopes judged by the independent CGAL checker.
#include "Envelope/ActivePointAnalysis.h"
#include "Envelope/ActivePoints.h"
#include "CoreTestPrinters.h"
#include "Envelope/Envelope.h"
#include "ExpectSound.h"
#include "Spatial/Geometry.h"
#include "Mesh/Mesh.h"
#include "Mesh/Normalization.h"
#include "Mesh/Shapes.h"
#include "Mesh/Validation.h"

#include <tbb/global_control.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <set>

using namespace sdfcage;

namespace
{

double distanceToMesh(const TriangleMesh& mesh, const Vec3& p)
{
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : mesh.Triangles)
  {
    best =
      std::min(best, (p - closestPointOnTriangle(p, mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]])).norm());
  }
  return best;
}

double totalArea(const TriangleMesh& m)
{
  double a = 0.0;
  for (const Triangle& t : m.Triangles)
  {
    a += 0.5 * (m.Points[t[1]] - m.Points[t[0]]).cross(m.Points[t[2]] - m.Points[t[0]]).norm();
  }
  return a;
}

/// Two slabs 0.012 apart in unit-sphere units (less than 2c) (thickness 0.4 each, far more than r): only the
/// facing sides have points closer than r to the other part.
struct Plates
{
  TriangleMesh Unit;
  TriangleMesh Left, Right; // the two parts, in unit units
  double Gap = 0.0;
};

Plates makePlates()
{
  TriangleMesh m = makeBox(Vec3(-1.0, -1.0, -1.0), Vec3(-0.0105, 1.0, 1.0));
  const std::size_t leftTriangles = m.Triangles.size();
  appendMesh(m, makeBox(Vec3(0.0105, -1.0, -1.0), Vec3(1.0, 1.0, 1.0)));
  Plates p;
  const Normalization n = Normalization::fit(m);
  p.Unit = n.toUnit(m);
  p.Left.Points = p.Unit.Points;
  p.Right.Points = p.Unit.Points;
  for (std::size_t f = 0; f < p.Unit.Triangles.size(); ++f)
  {
    (f < leftTriangles ? p.Left : p.Right).Triangles.push_back(p.Unit.Triangles[f]);
  }
  p.Gap = n.lengthToUnit(0.021);
  return p;
}

} // namespace

TEST(RefineMesh, SplitsLongEdgesKeepingShapeAndOrientation)
{
  const TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 2, 3));
  TriangleMesh fine;
  ASSERT_TRUE(refineMesh(box, 0.1, fine));
  ASSERT_GT(fine.Triangles.size(), box.Triangles.size() * 50);
  for (std::size_t i = 0; i < box.Points.size(); ++i)
  {
    EXPECT_EQ(fine.Points[i], box.Points[i]) << "the input's points keep their indices";
  }
  for (const Triangle& t : fine.Triangles)
  {
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_LE((fine.Points[t[k]] - fine.Points[t[(k + 1) % 3]]).norm(), 0.1 + 1e-12);
    }
  }
  EXPECT_NEAR(totalArea(fine), totalArea(box), 1e-9);
  EXPECT_NEAR(signedVolume(fine), signedVolume(box), 1e-9);
  const MeshDefects d = checkTriangleMesh(fine);
  EXPECT_TRUE(d.usable()) << d.errorMessage(); // closed, manifold, consistently oriented
  EXPECT_EQ(genus(fine), 0);
}

// One round of splitEdges with a symmetric marking that mixes 1-2, 1-3 and 1-4 splits: one
// midpoint per marked edge (at its middle, its edge in `parents`), a triangle more per marked edge
// of each triangle, the surface closed, oriented and of the same area; nothing marked, nothing done.
TEST(RefineMesh, SplitEdgesMakesOneMidpointPerMarkedEdge)
{
  TriangleMesh mesh = makeSphere(Vec3(0, 0, 0), 1.0, 24, 12);
  const TriangleMesh before = mesh;
  const auto marked = [](int a, int b) { return (a + b) % 3 == 0 || (a * b) % 7 == 1; };
  std::set<std::pair<int, int>> edges;
  std::size_t incidences = 0;
  for (const Triangle& t : before.Triangles)
  {
    for (int k = 0; k < 3; ++k)
    {
      const int a = t[k], b = t[(k + 1) % 3];
      if (marked(a, b))
      {
        edges.insert({ std::min(a, b), std::max(a, b) });
        ++incidences;
      }
    }
  }
  ASSERT_GT(edges.size(), 100u);
  std::vector<std::array<int, 2>> parents;
  const std::size_t made = splitEdges(mesh, marked, &parents);
  EXPECT_EQ(made, edges.size());
  ASSERT_EQ(mesh.Points.size(), before.Points.size() + edges.size());
  ASSERT_EQ(parents.size(), edges.size());
  EXPECT_EQ(mesh.Triangles.size(), before.Triangles.size() + incidences);
  std::set<std::pair<int, int>> split;
  for (std::size_t i = 0; i < parents.size(); ++i)
  {
    const int a = parents[i][0], b = parents[i][1];
    split.insert({ std::min(a, b), std::max(a, b) });
    EXPECT_EQ(mesh.Points[before.Points.size() + i], 0.5 * (before.Points[a] + before.Points[b]));
  }
  EXPECT_EQ(split, edges);
  EXPECT_NEAR(totalArea(mesh), totalArea(before), 1e-12);
  EXPECT_NEAR(signedVolume(mesh), signedVolume(before), 1e-12);
  const MeshDefects d = checkTriangleMesh(mesh);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  // nothing marked
  TriangleMesh same = before;
  EXPECT_EQ(splitEdges(same, [](int, int) { return false; }), 0u);
  EXPECT_EQ(same.Points, before.Points);
  EXPECT_EQ(same.Triangles, before.Triangles);
}

TEST(ActivePoints, SphereHasNone)
{
  const TriangleMesh sphere = makeSphere(Vec3(1, 2, 3), 4.0, 40, 20);
  const TriangleMesh unit = Normalization::fit(sphere).toUnit(sphere);
  const ActivePoints a = computeActivePoints(unit, ActivePointOptions());
  EXPECT_GT(a.NumberOfSamples, 1000u);
  EXPECT_EQ(a.NumberOfActiveSamples, 0u);
  EXPECT_EQ(a.NumberOfActivePoints, 0u);
  EXPECT_TRUE(a.empty());
  // no active point: phi = 1 + (alpha - 1) exp(-beta^2 cutoff^2) ~ 1 everywhere
  EXPECT_NEAR(a.amplificationAt(0, unit.Points[unit.Triangles[0][0]], 0.0), 1.0, 1e-6);
}

TEST(ActivePoints, ParallelPlatesOnlyOnTheFacingSides)
{
  const Plates plates = makePlates();
  ASSERT_LT(plates.Gap, 0.025);
  const ActivePointOptions options;
  const ActivePoints a = computeActivePoints(plates.Unit, options);
  ASSERT_GT(a.NumberOfActiveSamples, 0u);
  const double r = options.Radius;
  std::size_t facingActive = 0, facingInner = 0;
  for (std::size_t i = 0; i < a.Surface.Points.size(); ++i)
  {
    const Vec3& p = a.Surface.Points[i];
    const bool left = p.x() < 0.0;
    const double toOther = distanceToMesh(left ? plates.Right : plates.Left, p);
    if (a.Active[i])
    {
      // an active point has the other part within r (up to the sampling resolution)
      EXPECT_LT(toOther, r + options.sampleSpacing()) << "point " << p.transpose();
    }
    // points of the facing sides, away from their rims, must all be active
    const bool facing = std::abs(std::abs(p.x()) - plates.Gap / 2) < 1e-9;
    if (facing && std::abs(p.y()) < 0.3 && std::abs(p.z()) < 0.3)
    {
      ++facingInner;
      facingActive += a.Active[i];
    }
    // the far sides (0.4 from the other part) never are
    if (std::abs(std::abs(p.x()) - plates.Gap / 2) > 0.1 && toOther > 0.1)
    {
      EXPECT_EQ(a.Active[i], 0) << "far point " << p.transpose();
    }
  }
  ASSERT_GT(facingInner, 20u);
  EXPECT_EQ(facingActive, facingInner);
  // g_A is 0 on the facing sides and grows along the surface away from them
  for (std::size_t i = 0; i < a.Surface.Points.size(); ++i)
  {
    EXPECT_GE(a.GeodesicToActive[i], 0.0);
    EXPECT_LE(a.GeodesicToActive[i], a.Cutoff + 1e-12);
  }
  // phi: alpha at an active point on the surface, ~1 far away (eq. 3)
  EXPECT_NEAR(a.phi(0.0), options.Alpha, 1e-12);
  EXPECT_NEAR(a.phi(1.0), 1.0, 1e-12);
}

TEST(ActivePoints, SameResultForOneAndTwoThreads)
{
  const TriangleMesh input = makeBuiltinShape();
  const TriangleMesh unit = Normalization::fit(input).toUnit(input);
  ActivePoints one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = computeActivePoints(unit, ActivePointOptions());
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = computeActivePoints(unit, ActivePointOptions());
  }
  ASSERT_GT(one.NumberOfActiveSamples, 0u);
  EXPECT_EQ(one.Active, two.Active);
  EXPECT_EQ(one.GeodesicToActive, two.GeodesicToActive);
}

TEST(ActivePoints, InvalidParametersAreNamed)
{
  ActivePointOptions o;
  o.GeodesicThreshold = 0.01; // below r
  EXPECT_NE(o.validate().find("GeodesicThreshold"), std::string::npos);
  o = ActivePointOptions();
  o.Alpha = 0.5;
  EXPECT_NE(o.validate().find("AmplificationAlpha"), std::string::npos);
  EXPECT_TRUE(ActivePointOptions().validate().empty());
  o.AdaptivityOffFraction = 1.5;
  EXPECT_NE(o.validate().find("AdaptivityOffFraction"), std::string::npos);
  o.AdaptivityOffFraction = -0.1;
  EXPECT_NE(o.validate().find("AdaptivityOffFraction"), std::string::npos);

  const TriangleMesh input = makeBuiltinShape();
  const TriangleMesh unit = Normalization::fit(input).toUnit(input);
  EnvelopeOptions e;
  e.ActivePoints.Radius = -1.0;
  const EnvelopeResult r = buildEnvelope(unit, e);
  EXPECT_EQ(r.State, Status::InvalidInput);
  EXPECT_NE(r.Message.find("ActiveRadius"), std::string::npos) << r.Message;
}

// The feature under test: the built-in shape's two parts are 0.012 apart (unit-sphere units), less
// than 2c: the plain offset fuses them, the amplified field keeps them apart.
TEST(ShapeAwareEnvelope, BuiltinKeepsItsTopologyOnlyWithActivePoints)
{
  const TriangleMesh input = makeBuiltinShape();
  const TriangleMesh unit = Normalization::fit(input).toUnit(input);
  std::vector<int> comp;
  const int inputComponents = triangleComponents(unit, comp);
  const int inputGenus = genus(unit);
  ASSERT_EQ(inputComponents, 2);
  ASSERT_EQ(inputGenus, 1);

  EnvelopeOptions off;
  off.UseActivePoints = false;
  const EnvelopeResult plain = buildEnvelope(unit, off);
  ASSERT_EQ(plain.State, Status::Ok) << plain.Message;
  EXPECT_NE(plain.Components, inputComponents) << "the plain offset was expected to fuse the parts";
  EXPECT_FALSE(plain.TopologyWarning.empty());
  EXPECT_NE(plain.TopologyWarning.find("active points are off"), std::string::npos) << plain.TopologyWarning;

  EnvelopeOptions on; // the default
  ASSERT_TRUE(on.UseActivePoints);
  const EnvelopeResult aware = buildEnvelope(unit, on);
  ASSERT_EQ(aware.State, Status::Ok) << aware.Message;
  EXPECT_GT(aware.NumberOfActiveSamples, 0u);
  EXPECT_GT(aware.NumberOfActivePoints, 0u);
  EXPECT_GT(aware.AmplifiedVoxels, 0u);
  EXPECT_EQ(aware.Components, inputComponents);
  EXPECT_EQ(aware.Genus, inputGenus);
  EXPECT_TRUE(aware.TopologyWarning.empty()) << aware.TopologyWarning;

  exact::expectSoundCage(
    unit, aware.Envelope, on.clearance(), inputGenus, inputComponents, "builtin shape-aware envelope");
}

TEST(ShapeAwareEnvelope, PlatesStaySeparateAndEnclosed)
{
  const Plates plates = makePlates();
  EnvelopeOptions off;
  off.UseActivePoints = false;
  const EnvelopeResult plain = buildEnvelope(plates.Unit, off);
  ASSERT_EQ(plain.State, Status::Ok) << plain.Message;
  EXPECT_EQ(plain.Components, 1) << "a gap of " << plates.Gap << " < 2c fuses without active points";

  const EnvelopeOptions on;
  const EnvelopeResult aware = buildEnvelope(plates.Unit, on);
  ASSERT_EQ(aware.State, Status::Ok) << aware.Message;
  EXPECT_EQ(aware.Components, 2);
  exact::expectSoundCage(plates.Unit, aware.Envelope, on.clearance(), 0, 2, "plates' shape-aware envelope");
}

TEST(ActivePointAnalysis, InputCoordinatesAndFields)
{
  // the built-in shape scaled and moved: results come back in its own units
  TriangleMesh input = makeBuiltinShape();
  for (Vec3& p : input.Points)
  {
    p = 50.0 * p + Vec3(100, -20, 7);
  }
  ActivePointAnalysisOptions options;
  options.GenerateFields = true;
  const ActivePointAnalysis a = analyzeActivePoints(PolygonMesh::fromTriangles(input), options);
  ASSERT_EQ(a.State, Status::Ok) << a.Message;
  ASSERT_EQ(a.Active.size(), a.Mesh.Points.size());
  EXPECT_GT(a.NumberOfActivePoints, 0u);
  const Normalization n = Normalization::fit(input);
  double maxG = 0.0;
  for (std::size_t i = 0; i < a.Mesh.Points.size(); ++i)
  {
    EXPECT_GE(a.Amplification[i], 1.0);
    EXPECT_LE(a.Amplification[i], options.ActivePoints.Alpha + 1e-12);
    if (a.Active[i])
    {
      EXPECT_LE(a.GeodesicToActive[i], n.lengthToInput(options.ActivePoints.sampleSpacing()));
      EXPECT_GT(a.Amplification[i], 1.5);
    }
    maxG = std::max(maxG, a.GeodesicToActive[i]);
  }
  EXPECT_NEAR(maxG, n.lengthToInput(options.ActivePoints.geodesicCutoff()), 1e-9 * maxG);
  // fields: same grid, phi * xi >= xi outside, <= xi inside, equal far away
  const ScalarImage& xi = a.SignedDistance;
  const ScalarImage& mod = a.ModifiedSignedDistance;
  ASSERT_FALSE(xi.Values.empty());
  ASSERT_EQ(xi.Values.size(), mod.Values.size());
  EXPECT_EQ(xi.Dimensions, mod.Dimensions);
  std::size_t amplified = 0;
  for (std::size_t k = 0; k < xi.Values.size(); ++k)
  {
    const float v = xi.Values[k], m = mod.Values[k];
    if (v > 0)
    {
      EXPECT_GE(m, v * (1 - 1e-6f));
      EXPECT_LE(m, v * options.ActivePoints.Alpha * (1 + 1e-6));
    }
    else
    {
      EXPECT_LE(m, v * (1 - 1e-6f) + 1e-9f);
    }
    amplified += m > v * 1.5f && v > 0;
  }
  EXPECT_GT(amplified, 0u);
  // the grid is in input coordinates: it covers the scaled, moved shape
  const auto b = bounds(input);
  for (int k = 0; k < 3; ++k)
  {
    EXPECT_LE(xi.Origin[k], b[0][k]);
    EXPECT_GE(xi.Origin[k] + xi.Spacing * (xi.Dimensions[k] - 1), b[1][k]);
  }
}

TEST(ActivePointAnalysis, OpenInputIsRejected)
{
  TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  box.Triangles.pop_back();
  const ActivePointAnalysis a = analyzeActivePoints(PolygonMesh::fromTriangles(box), ActivePointAnalysisOptions());
  EXPECT_EQ(a.State, Status::InvalidInput);
  EXPECT_NE(a.Message.find("boundary"), std::string::npos) << a.Message;
  EXPECT_TRUE(a.Mesh.empty());
  const ActivePointAnalysis e = analyzeActivePoints(PolygonMesh(), ActivePointAnalysisOptions());
  EXPECT_EQ(e.State, Status::EmptyInput);
}
