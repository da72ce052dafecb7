// SDFCage — Testing: "any mesh in". Open, cracked, overlapping, nested, inside-out, non-manifold,
// non-planar, single-triangle and sheet inputs get a cage with exactly the vertices asked for,
// each judged by the independent CGAL referee (exact predicates) against the input as given.
#include "CoreTestPrinters.h"
#include "ExactCheck.h"
#include "Envelope/SDFIsosurface.h"
#include "Mesh/Mesh.h"
#include "Mesh/Shapes.h"
#include "Mesh/Validation.h"
#include "Pipeline/CageGenerator.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleTree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace sdfcage;

namespace
{

TriangleMesh append(TriangleMesh a, const TriangleMesh& b)
{
  const int base = static_cast<int>(a.Points.size());
  a.Points.insert(a.Points.end(), b.Points.begin(), b.Points.end());
  for (Triangle t : b.Triangles)
  {
    a.Triangles.push_back({ t[0] + base, t[1] + base, t[2] + base });
  }
  return a;
}

TriangleMesh inverted(TriangleMesh m)
{
  reverseOrientation(m);
  return m;
}

/// A flat n x n grid of triangles over [0,1]^2 at height z (an open sheet).
TriangleMesh sheet(int n, double z = 0.0)
{
  TriangleMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.Points.emplace_back(double(i) / n, double(j) / n, z);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
    {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      m.Triangles.push_back({ a, b, d });
      m.Triangles.push_back({ a, d, c });
    }
  return m;
}

/// Every triangle with its own three points (an STL-like soup of a closed mesh).
TriangleMesh splitCorners(const TriangleMesh& m)
{
  TriangleMesh s;
  for (const Triangle& t : m.Triangles)
  {
    const int base = static_cast<int>(s.Points.size());
    for (int k = 0; k < 3; ++k)
      s.Points.push_back(m.Points[t[k]]);
    s.Triangles.push_back({ base, base + 1, base + 2 });
  }
  return s;
}

struct Case
{
  std::string Name;
  std::function<PolygonMesh()> Make;
  SignMode Expected; ///< the rule Auto must pick
  int Vertices;
};

std::vector<Case> cases()
{
  return {
    { "CubeWithOneFaceMissing",
      [] {
        TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
        box.Triangles.resize(10);
        return PolygonMesh::fromTriangles(box);
      },
      SignMode::WindingNumber, 100 },
    { "SphereWithASlit",
      [] {
        TriangleMesh s = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
        // a slit: the triangles of a band near the equator removed on one side
        TriangleMesh cracked;
        cracked.Points = s.Points;
        for (std::size_t f = 0; f < s.Triangles.size(); ++f)
        {
          const Vec3 c =
            (s.Points[s.Triangles[f][0]] + s.Points[s.Triangles[f][1]] + s.Points[s.Triangles[f][2]]) / 3.0;
          if (!(std::abs(c.z()) < 0.1 && c.x() > 0.3 && std::abs(c.y()) < 0.5))
            cracked.Triangles.push_back(s.Triangles[f]);
        }
        return PolygonMesh::fromTriangles(cracked);
      },
      SignMode::WindingNumber, 200 },
    { "SphereWithACrack",
      [] {
        // a crack along a half meridian: the points there are doubled, the copies (used by the
        // triangles on the y > 0 side) moved 0.004 apart, far more than the merge tolerance
        TriangleMesh s = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
        std::vector<int> copy(s.Points.size(), -1);
        for (std::size_t i = 0; i < s.Points.size(); ++i)
        {
          const Vec3& p = s.Points[i];
          if (std::abs(p.y()) < 1e-9 && p.x() > 1e-6 && std::abs(p.z()) < 0.99)
          {
            copy[i] = static_cast<int>(s.Points.size());
            s.Points.push_back(p + Vec3(0, 0.004, 0));
          }
        }
        for (Triangle& t : s.Triangles)
        {
          const Vec3 c = (s.Points[t[0]] + s.Points[t[1]] + s.Points[t[2]]) / 3.0;
          if (c.y() > 0)
            for (int& v : t)
              if (copy[v] >= 0)
                v = copy[v];
        }
        return PolygonMesh::fromTriangles(s);
      },
      SignMode::WindingNumber, 100 },
    { "TwoOverlappingSpheres",
      [] {
        return PolygonMesh::fromTriangles(
          append(makeSphere(Vec3(0, 0, 0), 1.0, 24, 12), makeSphere(Vec3(0.9, 0.2, 0), 0.8, 24, 12)));
      },
      SignMode::FloodFill, 100 }, // closed and consistently oriented (only self-intersecting)
    { "NestedShells",
      [] {
        return PolygonMesh::fromTriangles(
          append(makeSphere(Vec3(0, 0, 0), 1.0, 24, 12), makeSphere(Vec3(0.1, 0, 0), 0.5, 16, 8)));
      },
      SignMode::FloodFill, 100 },
    { "OneInsideOutPartOfAnOverlap",
      [] {
        return PolygonMesh::fromTriangles(
          append(makeSphere(Vec3(0, 0, 0), 1.0, 24, 12), inverted(makeSphere(Vec3(0.8, 0, 0), 0.6, 24, 12))));
      },
      SignMode::FloodFill, 100 },
    { "BowtieVertex",
      [] {
        // two boxes sharing one corner point: a non-manifold vertex
        TriangleMesh a = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
        const TriangleMesh b = makeBox(Vec3(1, 1, 1), Vec3(2, 2, 2));
        int ca = -1, cb = -1;
        for (std::size_t i = 0; i < a.Points.size(); ++i)
          if ((a.Points[i] - Vec3(1, 1, 1)).norm() == 0.0)
            ca = static_cast<int>(i);
        for (std::size_t i = 0; i < b.Points.size(); ++i)
          if ((b.Points[i] - Vec3(1, 1, 1)).norm() == 0.0)
            cb = static_cast<int>(i);
        std::vector<int> map(b.Points.size());
        for (std::size_t i = 0; i < b.Points.size(); ++i)
        {
          if (static_cast<int>(i) == cb)
            map[i] = ca;
          else
          {
            map[i] = static_cast<int>(a.Points.size());
            a.Points.push_back(b.Points[i]);
          }
        }
        for (const Triangle& t : b.Triangles)
          a.Triangles.push_back({ map[t[0]], map[t[1]], map[t[2]] });
        return PolygonMesh::fromTriangles(a);
      },
      SignMode::WindingNumber, 100 },
    { "SoupWithSplitCorners",
      [] { return PolygonMesh::fromTriangles(splitCorners(makeTorus(Vec3(0, 0, 0), 1.0, 0.35, 24, 12))); },
      SignMode::FloodFill, 100 }, // merged back into a closed torus
    { "NonPlanarQuads",
      [] {
        // a torus of quads with every other vertex pushed out: no quad is planar
        PolygonMesh m;
        const int nu = 24, nv = 12;
        for (int i = 0; i < nu; ++i)
          for (int j = 0; j < nv; ++j)
          {
            const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
            const double r = 0.35 * (((i + j) % 2) ? 1.15 : 0.9);
            m.Points.emplace_back(
              (1 + r * std::cos(v)) * std::cos(u), (1 + r * std::cos(v)) * std::sin(u), r * std::sin(v));
          }
        for (int i = 0; i < nu; ++i)
          for (int j = 0; j < nv; ++j)
          {
            auto id = [&](int a, int b) { return std::int64_t(((a + nu) % nu) * nv + (b + nv) % nv); };
            m.addCell({ id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1) });
          }
        return m;
      },
      SignMode::FloodFill, 100 },
    { "NonConvexPolygonPrism",
      [] {
        // an L-shaped prism: two non-convex hexagons and six quads
        PolygonMesh m;
        const double xy[6][2] = { { 0, 0 }, { 2, 0 }, { 2, 1 }, { 1, 1 }, { 1, 2 }, { 0, 2 } };
        for (int z = 0; z < 2; ++z)
          for (const auto& p : xy)
            m.Points.emplace_back(p[0], p[1], z);
        m.addCell({ 5, 4, 3, 2, 1, 0 });   // bottom, facing -z
        m.addCell({ 6, 7, 8, 9, 10, 11 }); // top
        for (int i = 0; i < 6; ++i)
          m.addCell({ i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i });
        return m;
      },
      SignMode::FloodFill, 60 },
    { "SingleTriangle",
      [] {
        PolygonMesh m;
        m.Points = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0) };
        m.addCell({ 0, 1, 2 });
        return m;
      },
      SignMode::WindingNumber, 30 },
    { "OpenPlaneSheet", [] { return PolygonMesh::fromTriangles(sheet(20)); }, SignMode::WindingNumber, 100 },
    { "SphereWithDebris",
      [] {
        // 80 tiny triangles (0.004 across) floating 0.016 above a sphere: their offsets fuse with
        // the sphere's into bumps, which the simplification flattens; without the swept-region
        // test a collapse jumps over a fragment and leaves it outside (no new triangle comes near)
        TriangleMesh m = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
        for (int i = 0; i < 80; ++i)
        {
          // a Fibonacci spiral of directions
          const double z = 1.0 - (i + 0.5) / 40.0, r = std::sqrt(1.0 - z * z), phi = 2.399963 * i;
          const Vec3 u(r * std::cos(phi), r * std::sin(phi), z);
          const Vec3 a = u.unitOrthogonal(), b = u.cross(a);
          const Vec3 c = 1.016 * u;
          const int base = static_cast<int>(m.Points.size());
          m.Points.push_back(c + 0.002 * a);
          m.Points.push_back(c - 0.001 * a + 0.0017 * b);
          m.Points.push_back(c - 0.001 * a - 0.0017 * b);
          m.Triangles.push_back({ base, base + 1, base + 2 });
        }
        return PolygonMesh::fromTriangles(m);
      },
      SignMode::WindingNumber, 100 },
  };
}

/// The input exactly as given (polygons fanned: a referee only needs the same surface).
TriangleMesh asGiven(const PolygonMesh& m)
{
  TriangleMesh t;
  t.Points = m.Points;
  for (std::size_t c = 0; c + 1 < m.Offsets.size(); ++c)
  {
    const std::int64_t b = m.Offsets[c], e = m.Offsets[c + 1];
    for (std::int64_t k = b + 1; k + 1 < e; ++k)
      t.Triangles.push_back({ int(m.Connectivity[b]), int(m.Connectivity[k]), int(m.Connectivity[k + 1]) });
  }
  return t;
}

void PrintTo(const Case& c, std::ostream* os)
{
  *os << c.Name;
}

class AnyMesh : public ::testing::TestWithParam<Case>
{
};

TEST_P(AnyMesh, GetsAVerifiedCageWithExactlyNVertices)
{
  const Case& c = GetParam();
  const PolygonMesh input = c.Make();
  CageOptions options;
  options.TargetNumberOfVertices = c.Vertices;
  const CageResult r = generateCage(input, options);
  ASSERT_EQ(r.State, Status::Ok) << statusName(r.State) << ": " << r.Message;
  EXPECT_EQ(r.SignUsed, c.Expected) << signModeName(r.SignUsed) << " (" << r.SignReason << ")";
  EXPECT_TRUE(r.EnclosureVerified);
  EXPECT_EQ(r.VerticesReached, c.Vertices) << r.StopReason;
  EXPECT_EQ(static_cast<int>(r.Cage.Points.size()), r.VerticesReached);
  if (!r.InputClosed)
  {
    EXPECT_EQ(r.InputGenus, -1); // undefined: no genus comparison, no topology warning
    EXPECT_TRUE(r.TopologyWarning.empty()) << r.TopologyWarning;
  }
  // the referee, on the input as given (not the repaired copy), non-convex polygons by ear
  // clipping would differ from a fan: judge against the repaired triangles there
  TriangleMesh judged = asGiven(input);
  if (c.Name == "NonConvexPolygonPrism")
  {
    prepareMesh(input, judged);
  }
  const exact::ExactReport e = exact::exactCheck(judged, r.Cage, 0.0);
  EXPECT_TRUE(e.Encloses) << exact::toJson(e);
  EXPECT_EQ(e.InputIntersections, 0);
  EXPECT_EQ(e.SelfIntersections, 0);
  EXPECT_EQ(e.InputVerticesOutside, 0);
  // the clearance the pipeline promises (relative to the unit sphere), measured exactly
  const double required = r.Normalize.lengthToInput(options.Envelope.clearance());
  EXPECT_GE(e.MinimumClearance, required * (1 - 1e-9)) << exact::toJson(e);
}

INSTANTIATE_TEST_SUITE_P(Inputs, AnyMesh, ::testing::ValuesIn(cases()),
  [](const ::testing::TestParamInfo<Case>& info) { return info.param.Name; });

TEST(AnyMeshWidening, OffKeepsTheIsovalueOnReportsTheWiderEnvelope)
{
  // the sphere with floating debris (the AnyMesh case): at the requested isovalue its envelope
  // has the debris' bumps and handles and stops short of 100 vertices; widened, it reaches them
  PolygonMesh input;
  for (const Case& c : cases())
    if (c.Name == "SphereWithDebris")
      input = c.Make();
  ASSERT_FALSE(input.Points.empty());
  CageOptions options;
  options.TargetNumberOfVertices = 100;
  options.MaximumEnvelopeWidenings = 0;
  const CageResult off = generateCage(input, options);
  ASSERT_EQ(off.State, Status::Ok) << off.Message;
  EXPECT_EQ(off.EnvelopeWidenings, 0);
  EXPECT_EQ(off.IsoValueUsed, options.Envelope.IsoValue);
  EXPECT_FALSE(off.TargetReached);
  EXPECT_FALSE(off.StopReason.empty());
  EXPECT_TRUE(off.WideningLog.empty());
  options.MaximumEnvelopeWidenings = 3;
  options.ChooseIsoValueFirst = false; // the plain widening: every isovalue built from the requested one
  const CageResult on = generateCage(input, options);
  ASSERT_EQ(on.State, Status::Ok) << on.Message;
  EXPECT_TRUE(on.TargetReached) << on.StopReason;
  EXPECT_GE(on.EnvelopeWidenings, 1);
  EXPECT_EQ(on.IsoValueUsed, options.Envelope.IsoValue * (1 << on.EnvelopeWidenings));
  EXPECT_NE(on.WideningLog.find("isovalue 0.01:"), std::string::npos) << on.WideningLog;
  EXPECT_TRUE(on.EnclosureVerified);
  EXPECT_EQ(on.EnvelopeProbes, 0);
  EXPECT_EQ(on.EnvelopeAttempts, on.EnvelopeWidenings + 1);
  // (the default, probes first, on this input: the AnyMesh case SphereWithDebris)
  // a closed input is never widened, whatever its target
  CageOptions closed;
  closed.TargetNumberOfVertices = 5; // a torus cannot have 5 vertices
  const CageResult torus = generateCage(PolygonMesh::fromTriangles(makeTorus(Vec3(0, 0, 0), 1.0, 0.4, 24, 12)), closed);
  ASSERT_EQ(torus.State, Status::Ok) << torus.Message;
  EXPECT_TRUE(torus.InputClosed);
  EXPECT_FALSE(torus.TargetReached);
  EXPECT_EQ(torus.EnvelopeWidenings, 0);
  EXPECT_TRUE(torus.WideningLog.empty());
}

TEST(AnyMeshWidening, DeferredVerificationGivesTheSameVerifiedCage)
{
  // CageOptions::DeferEnvelopeVerification: the envelopes a wider one may replace are simplified
  // unverified and verified only if kept: the same verified cage and envelope as without
  // deferral. An open torus (two faces missing: widened like any soup) cannot be caged with 12
  // vertices at any isovalue without relaxing its stalled simplifications (with them the 0.08
  // envelope reaches 12), so with relaxation off every envelope is simplified and misses the
  // target; the widest one allowed is simplified in full and never deferred.
  TriangleMesh torus = makeTorus(Vec3(0, 0, 0), 0.7, 0.25, 48, 24);
  torus.Triangles.resize(torus.Triangles.size() - 2);
  const PolygonMesh input = PolygonMesh::fromTriangles(torus);
  for (int widenings : { 1, 2 })
  {
    CageOptions options;
    options.Envelope.IsoValue = 0.04; // small envelopes: a quick test
    options.TargetNumberOfVertices = 12;
    options.MaximumEnvelopeWidenings = widenings;
    options.ChooseIsoValueFirst = false;
    options.MaximumRelaxations = 0;
    options.DeferEnvelopeVerification = false;
    const CageResult plain = generateCage(input, options);
    options.DeferEnvelopeVerification = true;
    const CageResult deferred = generateCage(input, options);
    const std::string what = deferred.WideningLog;
    ASSERT_EQ(plain.State, Status::Ok) << what << ": " << plain.Message;
    ASSERT_EQ(deferred.State, Status::Ok) << what << ": " << deferred.Message;
    EXPECT_FALSE(deferred.TargetReached) << what;
    std::cout << "[ deferred ] widenings " << widenings << ": kept isovalue " << deferred.IsoValueUsed << ", "
              << deferred.VerticesReached << " vertices, " << deferred.EnvelopeAttempts << " attempts (plain "
              << plain.EnvelopeAttempts << "): " << what << "\n";
    EXPECT_FALSE(deferred.VerificationDeferred) << what;
    EXPECT_TRUE(deferred.EnclosureVerified) << what;
    EXPECT_EQ(deferred.IsoValueUsed, plain.IsoValueUsed) << what;
    EXPECT_EQ(deferred.EnvelopeWidenings, plain.EnvelopeWidenings) << what;
    // one more attempt when the kept envelope was a deferred one (built again, verified)
    EXPECT_EQ(deferred.EnvelopeAttempts,
      plain.EnvelopeAttempts + (deferred.IsoValueUsed < options.Envelope.IsoValue * (1 << widenings) ? 1 : 0))
      << what;
    EXPECT_EQ(deferred.Cage.Points, plain.Cage.Points) << what;
    EXPECT_EQ(deferred.Cage.Triangles, plain.Cage.Triangles) << what;
    EXPECT_EQ(deferred.Envelope.Points, plain.Envelope.Points) << what;
    ASSERT_EQ(deferred.EnvelopeDistanceToInput.size(), deferred.Envelope.Points.size()) << what;
    EXPECT_EQ(deferred.EnvelopeDistanceToInput, plain.EnvelopeDistanceToInput) << what;
    EXPECT_EQ(deferred.MinimumClearance, plain.MinimumClearance) << what;
    // the first envelope was simplified without a verification: its log entry's verification
    // time is the bare timer's (below a microsecond here, about 0.2 ms or more when verified)
    auto firstVerification = [](const std::string& log) {
      const std::size_t at = log.find("verification ");
      return at == std::string::npos ? -1.0 : std::stod(log.substr(at + 13));
    };
    EXPECT_GE(firstVerification(what), 0.0) << what;
    EXPECT_LT(firstVerification(what), 1e-4) << what;
    EXPECT_GT(firstVerification(plain.WideningLog), 1e-4) << plain.WideningLog;
    const exact::ExactReport e = exact::exactCheck(asGiven(input), deferred.Cage, 0.0);
    EXPECT_TRUE(e.Encloses) << exact::toJson(e);
    EXPECT_EQ(e.InputIntersections, 0) << what;
    EXPECT_EQ(e.SelfIntersections, 0) << what;
  }
}

/// 125 small open boxes (two triangles missing each) on a 5 x 5 x 5 lattice, 0.1 apart (about
/// 0.1 in unit-sphere units too): a soup whose envelope keeps the boxes apart (125 parts: 500
/// vertices or more) until the isovalue bridges the gaps (0.08).
PolygonMesh boxLattice()
{
  TriangleMesh soup;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k)
      {
        const Vec3 lo(0.25 * i, 0.25 * j, 0.25 * k);
        TriangleMesh box = makeBox(lo, lo + Vec3(0.15, 0.15, 0.15));
        box.Triangles.resize(10);
        soup = append(soup, box);
      }
  return PolygonMesh::fromTriangles(soup);
}

TEST(AnyMeshWidening, ProbesSkipTheFineRunsOfEnvelopesThatCannotCarryTheTarget)
{
  const PolygonMesh input = boxLattice();
  CageOptions options;
  options.TargetNumberOfVertices = 100;
  options.Envelope.IsoValue = 0.02; // then 0.04 and 0.08 (a quick test: coarser grids)
  options.MaximumEnvelopeWidenings = 2;
  options.ChooseIsoValueFirst = false;
  const CageResult plain = generateCage(input, options);
  ASSERT_EQ(plain.State, Status::Ok) << plain.Message;
  ASSERT_TRUE(plain.TargetReached) << plain.StopReason;
  EXPECT_EQ(plain.EnvelopeProbes, 0);
  EXPECT_EQ(plain.EnvelopeWidenings, 2) << plain.WideningLog; // 125 parts at 0.02 and 0.04
  EXPECT_EQ(plain.EnvelopeAttempts, plain.EnvelopeWidenings + 1) << plain.WideningLog;

  options.ChooseIsoValueFirst = true;
  const CageResult probed = generateCage(input, options);
  ASSERT_EQ(probed.State, Status::Ok) << probed.Message;
  EXPECT_TRUE(probed.TargetReached) << probed.StopReason;
  EXPECT_GE(probed.EnvelopeProbes, 1);
  EXPECT_GE(probed.IsoValuesSkipped, 1);
  EXPECT_NE(probed.WideningLog.find("not built"), std::string::npos) << probed.WideningLog;
  EXPECT_LT(probed.EnvelopeAttempts, plain.EnvelopeAttempts) << probed.WideningLog << "\n" << plain.WideningLog;
  // the same isovalue as the plain widening, so the same cage (the run at the widest isovalue
  // is the last one allowed either way)
  EXPECT_EQ(probed.IsoValueUsed, plain.IsoValueUsed);
  EXPECT_EQ(probed.EnvelopeWidenings, plain.EnvelopeWidenings);
  EXPECT_EQ(probed.IsoValueUsed, options.Envelope.IsoValue * (1 << probed.EnvelopeWidenings));
  ASSERT_EQ(probed.Cage.Points.size(), plain.Cage.Points.size());
  EXPECT_EQ(probed.Cage.Points, plain.Cage.Points);
  EXPECT_EQ(static_cast<int>(probed.Cage.Points.size()), options.TargetNumberOfVertices);
  const exact::ExactReport e = exact::exactCheck(asGiven(input), probed.Cage, 0.0);
  EXPECT_TRUE(e.Encloses) << exact::toJson(e);
  EXPECT_EQ(e.InputIntersections, 0);
  EXPECT_EQ(e.SelfIntersections, 0);
  EXPECT_EQ(e.InputVerticesOutside, 0);

  // few parts (the target can carry them apart): no probe, the plain path
  options.TargetNumberOfVertices = 600;
  options.MaximumEnvelopeWidenings = 1;
  const CageResult many = generateCage(input, options);
  EXPECT_EQ(many.EnvelopeProbes, 0) << many.WideningLog;
}

TEST(AnyMeshWidening, GiveUpStopsTheSimplificationAfterItsOrdinaryPass)
{
  EXPECT_EQ(WideningGiveUpAbove(500), 600);
  EXPECT_EQ(WideningGiveUpAbove(20), 28);
  // a torus cannot have 4 vertices: the ordinary pass ends above 6
  const TriangleMesh torus = makeTorus(Vec3(0, 0, 0), 0.7, 0.25, 48, 24);
  EnvelopeOptions eo;
  eo.UseActivePoints = false;
  eo.IsoValue = 0.04; // a small envelope: a quick test
  const EnvelopeResult env = buildEnvelope(torus, eo);
  ASSERT_EQ(env.State, Status::Ok) << env.Message;
  const TriangleTree tree(torus);
  SimplifyOptions so;
  so.TargetNumberOfVertices = 4;
  so.Clearance = eo.clearance();
  const SimplifyResult full = simplifyEnvelope(env.Envelope, tree, so);
  so.GiveUpAbove = 6;
  const SimplifyResult early = simplifyEnvelope(env.Envelope, tree, so);
  EXPECT_FALSE(full.GaveUp);
  EXPECT_FALSE(full.TargetReached);
  EXPECT_TRUE(early.GaveUp);
  EXPECT_FALSE(early.TargetReached);
  EXPECT_GT(early.VerticesReached, 6);
  EXPECT_GE(early.VerticesReached, full.VerticesReached);
  EXPECT_NE(early.StopReason.find("ordinary pass"), std::string::npos) << early.StopReason;
  EXPECT_EQ(static_cast<int>(early.Cage.Points.size()), early.VerticesReached);
  // a generous bound changes nothing
  so.GiveUpAbove = static_cast<int>(env.Envelope.Points.size());
  const SimplifyResult same = simplifyEnvelope(env.Envelope, tree, so);
  EXPECT_FALSE(same.GaveUp);
  EXPECT_EQ(same.VerticesReached, full.VerticesReached);
  EXPECT_EQ(same.Cage.Points, full.Cage.Points);
}

TEST(AnyMeshRepairs, AreCounted)
{
  // the split-corner torus: every point but one per position merged, nothing dropped
  const TriangleMesh torus = makeTorus(Vec3(0, 0, 0), 1.0, 0.35, 24, 12);
  TriangleMesh out;
  MeshDefects d = prepareMesh(PolygonMesh::fromTriangles(splitCorners(torus)), out);
  EXPECT_EQ(d.MergedPoints, static_cast<long long>(3 * torus.Triangles.size() - torus.Points.size()));
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(d.Genus, 1);
  EXPECT_EQ(out.Points.size(), torus.Points.size());

  // duplicated and degenerate triangles dropped, counted: what is left is the closed box
  const TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  PolygonMesh m = PolygonMesh::fromTriangles(box);
  const Triangle t0 = box.Triangles[0];
  m.addCell({ t0[1], t0[2], t0[0] }); // the first triangle again (rotated)
  m.addCell({ 0, 0, 1 });             // a repeated point
  m.Points.push_back(0.5 * (box.Points[0] + box.Points[1]));
  m.addCell({ 0, 1, std::int64_t(m.Points.size() - 1) }); // three collinear points
  d = prepareMesh(m, out);
  EXPECT_EQ(d.DroppedDuplicateTriangles, 1);
  EXPECT_EQ(d.DroppedDegenerateTriangles, 2);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(out.Triangles.size(), 12u);
  EXPECT_EQ(out.Points.size(), 8u);

  // a polygon of 1000 sides (a circle) is triangulated, not refused
  PolygonMesh disk;
  std::vector<std::int64_t> ids;
  for (int i = 0; i < 1000; ++i)
  {
    const double a = 2 * M_PI * i / 1000;
    disk.Points.emplace_back(std::cos(a), std::sin(a) * (i % 2 ? 0.9 : 1.0), 0.0);
    ids.push_back(i);
  }
  disk.Connectivity = ids;
  disk.Offsets = { 0, 1000 };
  d = prepareMesh(disk, out);
  EXPECT_EQ(d.TriangulatedPolygons, 1);
  EXPECT_EQ(out.Triangles.size(), 998u);
  EXPECT_EQ(d.BoundaryEdges, 1000);
}

TEST(AnyMeshRepairs, WindingNumberOfTheTreeMatchesTheExactSum)
{
  const TriangleMesh sphere = makeSphere(Vec3(0, 0, 0), 1.0, 48, 24);
  TriangleTree tree(sphere);
  tree.prepareWindingNumbers();
  for (const Vec3& p : { Vec3(0, 0, 0), Vec3(0.5, 0.3, 0.1), Vec3(0.95, 0, 0), Vec3(1.05, 0, 0), Vec3(3, 1, 0) })
  {
    const double exact = sdfcage::windingNumber(sphere, p);
    EXPECT_NEAR(tree.windingNumber(p), exact, 0.05) << p.transpose(); // first-order dipoles, beta 2
  }
  // an open sheet (normal +z): about -1/2 just above it (the side it faces), +1/2 below, less
  // than 1/2 in magnitude farther away
  const TriangleMesh s = sheet(20);
  TriangleTree st(s);
  st.prepareWindingNumbers();
  EXPECT_NEAR(st.windingNumber(Vec3(0.5, 0.5, 0.01)), -0.5, 0.05);
  EXPECT_NEAR(st.windingNumber(Vec3(0.5, 0.5, -0.01)), 0.5, 0.05);
  EXPECT_LT(std::abs(st.windingNumber(Vec3(0.5, 0.5, 0.3))), 0.5);
}

TEST(AnyMeshRepairs, LongTrianglesEnteredAsPiecesAnswerAsWholeTriangles)
{
  // 300 random slivers across the unit ball (each as long as the ball is wide) and a small sphere:
  // the tree with pieces answers every query as the tree of whole triangles and as brute force
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto inBall = [&]() {
    for (;;)
    {
      const Vec3 p(u(rng), u(rng), u(rng));
      if (p.squaredNorm() <= 1.0)
        return p;
    }
  };
  TriangleMesh m = makeSphere(Vec3(0.2, 0.1, 0), 0.2, 12, 6);
  for (int i = 0; i < 300; ++i)
  {
    const Vec3 a = inBall(), b = inBall();
    const Vec3 c = 0.5 * (a + b) + 1e-3 * Vec3(u(rng), u(rng), u(rng));
    const int base = static_cast<int>(m.Points.size());
    m.Points.insert(m.Points.end(), { a, b, c });
    m.Triangles.push_back({ base, base + 1, base + 2 });
  }
  TriangleTree whole(m), pieces;
  ASSERT_TRUE(pieces.build(m, nullptr, true));
  EXPECT_EQ(whole.size(), m.Triangles.size());
  EXPECT_EQ(whole.splitTriangles(), 0u);
  EXPECT_GT(pieces.splitTriangles(), 250u);
  EXPECT_GT(pieces.size(), 4 * m.Triangles.size());
  // the budget's figure: the extra entries' memory, none for a mesh without long triangles
  EXPECT_GE(TriangleTree::pieceBytes(m), (pieces.size() - m.Triangles.size()) * 100);
  EXPECT_LE(TriangleTree::pieceBytes(m), (pieces.size() - m.Triangles.size()) * 1000);
  EXPECT_EQ(TriangleTree::pieceBytes(makeSphere(Vec3(0, 0, 0), 1.0, 128, 64)), 0u); // edges below 1/32 of 3.46
  EXPECT_GT(TriangleTree::pieceBytes(makeSphere(Vec3(0, 0, 0), 1.0, 24, 12)), 0u);   // edges of 0.26
  whole.prepareWindingNumbers();
  pieces.prepareWindingNumbers();
  for (int q = 0; q < 300; ++q)
  {
    const Vec3 p = 1.2 * inBall();
    double brute = std::numeric_limits<double>::infinity();
    for (const Triangle& t : m.Triangles)
      brute = std::min(brute, (closestPointOnTriangle(p, m.Points[t[0]], m.Points[t[1]], m.Points[t[2]]) - p).norm());
    Vec3 c;
    int tri = -1;
    double d = -1;
    ASSERT_TRUE(pieces.closestPoint(p, -1.0, c, tri, d));
    EXPECT_EQ(d, whole.distance(p)) << p.transpose();
    EXPECT_EQ(d, brute) << p.transpose();
    EXPECT_NEAR((closestPointOnTriangle(p, m.Points[m.Triangles[tri][0]], m.Points[m.Triangles[tri][1]],
                   m.Points[m.Triangles[tri][2]]) - p).norm(), d, 1e-15);
    // bounded: none within a tenth of the distance
    EXPECT_FALSE(pieces.closestPoint(p, 0.1 * d, c, tri, d));
    // winding numbers: the pieces' dipoles and exact sums against the exact sum over the triangles
    const double exact = sdfcage::windingNumber(m, p);
    EXPECT_NEAR(pieces.windingNumber(p), exact, 0.05) << p.transpose();
    // triangle queries
    const Vec3 t[3] = { p, p + 0.3 * Vec3(u(rng), u(rng), u(rng)), p + 0.3 * Vec3(u(rng), u(rng), u(rng)) };
    for (double limit : { 0.01, 0.05, 0.2 })
    {
      EXPECT_EQ(pieces.triangleDistance(t, limit), whole.triangleDistance(t, limit));
      EXPECT_EQ(pieces.anyCloserThan(t, limit), whole.anyCloserThan(t, limit));
      EXPECT_EQ(pieces.countWithin(t, limit), whole.countWithin(t, limit));
      std::vector<int> a{ -7 }, b{ -7 }; // appended after what is there
      pieces.trianglesWithin(t, limit, a);
      whole.trianglesWithin(t, limit, b);
      std::sort(b.begin() + 1, b.end());
      EXPECT_EQ(a, b);
    }
  }
}

TEST(AnyMeshRepairs, ForcedRulesAreHonoured)
{
  TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  box.Triangles.resize(10);
  for (SignMode m : { SignMode::Unsigned, SignMode::WindingNumber })
  {
    CageOptions options;
    options.TargetNumberOfVertices = 80;
    options.Envelope.Sign = m;
    const CageResult r = generateCage(PolygonMesh::fromTriangles(box), options);
    ASSERT_EQ(r.State, Status::Ok) << signModeName(m) << ": " << r.Message;
    EXPECT_EQ(r.SignUsed, m);
    EXPECT_EQ(r.SignReason, "requested");
    EXPECT_FALSE(r.InputClosed);
    const exact::ExactReport e = exact::exactCheck(box, r.Cage, 0.0);
    EXPECT_TRUE(e.Encloses) << signModeName(m) << " " << exact::toJson(e);
  }
}

} // namespace

TEST(AnyMeshField, TheUnsignedBandIsExactWhereTrianglesAreSmallerThanVoxels)
{
  // The unsigned narrow band from the input's tree (computeIsosurface with the tree: one exact
  // query per voxel near the input) on a sheet of 80,000 triangles eight times smaller than the
  // voxel: over the sheet's flat middle the distance is |z|, linear, so the isosurface at `iso`
  // interpolated from exact values lies exactly at distance iso (to float rounding).
  const TriangleMesh flat = sheet(200); // [0,1]^2, z = 0
  TriangleMesh m = flat;
  for (Vec3& p : m.Points)
    p = 0.5 * p; // [0,0.5]^2: triangles 0.0025 across
  const TriangleTree tree(m);
  const double h = 0.02, iso = 0.04;
  const IsosurfaceOutput own =
    computeIsosurface(m, h, iso, false, nullptr, { 0.0 }, nullptr, nullptr, 3, SignMode::Unsigned, &tree);
  ASSERT_TRUE(own.Error.empty()) << own.Error;
  ASSERT_EQ(own.Surfaces.size(), 1u);
  const IsosurfaceOutput vdb =
    computeIsosurface(m, h, iso, false, nullptr, { 0.0 }, nullptr, nullptr, 3, SignMode::Unsigned, nullptr);
  ASSERT_EQ(vdb.Surfaces.size(), 1u);
  auto worst = [&](const TriangleMesh& s, std::size_t& middle) {
    double e = 0.0;
    middle = 0;
    for (const Vec3& p : s.Points)
    {
      if (p.x() < 0.1 || p.x() > 0.4 || p.y() < 0.1 || p.y() > 0.4)
        continue;
      ++middle;
      e = std::max(e, std::abs(tree.distance(p) - iso));
    }
    return e;
  };
  std::size_t middleOwn = 0, middleVdb = 0;
  const double eOwn = worst(own.Surfaces[0], middleOwn), eVdb = worst(vdb.Surfaces[0], middleVdb);
  std::cout << "[ band     ] isosurface over the sheet's middle: |d - iso| at most " << eOwn << " (own band, "
            << own.DistanceFieldSeconds << " s), " << eVdb << " (OpenVDB's meshToVolume, " << vdb.DistanceFieldSeconds
            << " s)\n";
  EXPECT_GT(middleOwn, 100u); // both sides of the middle
  EXPECT_LT(eOwn, 1e-5 * iso);
}
