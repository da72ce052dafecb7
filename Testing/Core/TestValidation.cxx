// SDFCage — Testing: every defect of Validation.h on hand-built meshes.
#include "Mesh/Mesh.h"
#include "Mesh/Shapes.h"
#include "Mesh/Validation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <vector>
#include <string>

using namespace sdfcage;

namespace
{

PolygonMesh unitBox()
{
  return PolygonMesh::fromTriangles(makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1)));
}

/// The unit cube as 6 quads, outward (corner i = x + 2y + 4z).
PolygonMesh quadCube()
{
  PolygonMesh m;
  for (int i = 0; i < 8; ++i)
  {
    m.Points.emplace_back(i & 1 ? 1.0 : 0.0, i & 2 ? 1.0 : 0.0, i & 4 ? 1.0 : 0.0);
  }
  m.addCell({ 0, 2, 3, 1 });
  m.addCell({ 4, 5, 7, 6 });
  m.addCell({ 0, 1, 5, 4 });
  m.addCell({ 2, 6, 7, 3 });
  m.addCell({ 0, 4, 6, 2 });
  m.addCell({ 1, 3, 7, 5 });
  return m;
}

/// Tetrahedron with outward faces.
void addTetrahedron(PolygonMesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, int shareA = -1)
{
  const std::int64_t base = static_cast<std::int64_t>(m.Points.size());
  std::int64_t ia = shareA;
  if (shareA < 0)
  {
    m.Points.push_back(a);
    ia = base;
  }
  const std::int64_t off = shareA < 0 ? 1 : 0;
  m.Points.push_back(b);
  m.Points.push_back(c);
  m.Points.push_back(d);
  const std::int64_t ib = base + off, ic = base + off + 1, id = base + off + 2;
  // a=(0,0,0) b=x c=y d=z style: outward for a right-handed (b-a, c-a, d-a)
  m.addCell({ ia, ic, ib });
  m.addCell({ ia, ib, id });
  m.addCell({ ia, id, ic });
  m.addCell({ ib, ic, id });
}

bool contains(const std::string& text, const std::string& what)
{
  return text.find(what) != std::string::npos;
}

} // namespace

TEST(Validation, ClosedBoxIsUsable)
{
  TriangleMesh out;
  const MeshDefects d = prepareMesh(unitBox(), out);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_TRUE(d.errorMessage().empty());
  EXPECT_EQ(out.Triangles.size(), 12u);
  EXPECT_EQ(out.Points.size(), 8u);
  EXPECT_EQ(d.Components, 1);
  EXPECT_EQ(d.Genus, 0);
  EXPECT_FALSE(d.FlippedOrientation);
  EXPECT_GT(signedVolume(out), 0.0);
  EXPECT_NEAR(signedVolume(out), 1.0, 1e-12);
}

TEST(Validation, EmptyMesh)
{
  TriangleMesh out;
  MeshDefects d = prepareMesh(PolygonMesh(), out);
  EXPECT_TRUE(d.Empty);
  EXPECT_FALSE(d.usable());
  EXPECT_FALSE(d.errorMessage().empty());
  EXPECT_TRUE(out.empty());

  // Only vertex and line cells: ignored, and nothing is left.
  PolygonMesh lines;
  lines.Points = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0) };
  lines.addCell({ 0 });
  lines.addCell({ 0, 1 });
  lines.addCell({ 1, 2 });
  d = prepareMesh(lines, out);
  EXPECT_TRUE(d.Empty);
  EXPECT_EQ(d.IgnoredCells, 3);
  EXPECT_FALSE(d.usable());
}

TEST(Validation, NonFiniteCoordinates)
{
  PolygonMesh m = unitBox();
  m.Points[3][1] = std::numeric_limits<double>::quiet_NaN();
  m.Points[5][2] = std::numeric_limits<double>::infinity();
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.NonFinitePoints, 2);
  EXPECT_FALSE(d.usable());
  EXPECT_FALSE(d.errorMessage().empty());

  // An unreferenced NaN point is no defect: it is dropped.
  PolygonMesh n = unitBox();
  n.Points.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  const MeshDefects e = prepareMesh(n, out);
  EXPECT_EQ(e.NonFinitePoints, 0);
  EXPECT_EQ(e.UnreferencedPoints, 1);
  EXPECT_TRUE(e.usable()) << e.errorMessage();
  EXPECT_EQ(out.Points.size(), 8u);
  for (const Vec3& p : out.Points)
  {
    EXPECT_TRUE(p.allFinite());
  }
}

TEST(Validation, InvalidPointIds)
{
  PolygonMesh m = unitBox();
  m.addCell({ 0, 1, 100 });
  m.addCell({ -1, 2, 3 });
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.InvalidPointIds, 2);
  EXPECT_FALSE(d.usable());
  EXPECT_FALSE(d.errorMessage().empty());
}

TEST(Validation, QuadsAreTriangulated)
{
  TriangleMesh out;
  const MeshDefects d = prepareMesh(quadCube(), out);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(d.TriangulatedPolygons, 6);
  EXPECT_EQ(d.UntriangulatedPolygons, 0);
  EXPECT_EQ(out.Triangles.size(), 12u);
  EXPECT_NEAR(signedVolume(out), 1.0, 1e-12);
  EXPECT_EQ(d.Genus, 0);
  EXPECT_FALSE(d.warnings().empty()); // the split is reported
}

TEST(Validation, NonPlanarPolygonIsSplit)
{
  // Raise one corner of the top face: the top quad is no longer planar (the side quads through
  // that corner stay planar). It is split by ear clipping in its best-fit plane, as VTK's
  // triangle filter would, and reported.
  PolygonMesh m = quadCube();
  m.Points[7][2] = 1.3;
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.UntriangulatedPolygons, 0);
  EXPECT_EQ(d.TriangulatedPolygons, 6);
  EXPECT_EQ(out.Triangles.size(), 12u);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
}

TEST(Validation, NonConvexPolygonIsSplitByEars)
{
  // An L-shaped prism: top and bottom are planar, non-convex hexagons.
  PolygonMesh m;
  const double xy[6][2] = { { 0, 0 }, { 2, 0 }, { 2, 1 }, { 1, 1 }, { 1, 2 }, { 0, 2 } };
  for (int z = 0; z < 2; ++z)
  {
    for (const auto& p : xy)
    {
      m.Points.emplace_back(p[0], p[1], z);
    }
  }
  m.addCell({ 0, 5, 4, 3, 2, 1 });   // bottom, facing -z
  m.addCell({ 6, 7, 8, 9, 10, 11 }); // top, facing +z
  for (int i = 0; i < 6; ++i)
  {
    const int j = (i + 1) % 6;
    m.addCell({ i, j, j + 6, i + 6 }); // convex side quads
  }
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.UntriangulatedPolygons, 0);
  EXPECT_EQ(d.TriangulatedPolygons, 8);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(out.Triangles.size(), 2u * 4u + 6u * 2u); // each hexagon in 4 ears, each quad in 2
  EXPECT_NEAR(signedVolume(out), 3.0, 1e-12);         // the L (area 3) times height 1: no overlap
}

TEST(Validation, BoundaryEdgesOfAnOpenBox)
{
  PolygonMesh m = PolygonMesh::fromTriangles([] {
    TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
    box.Triangles.resize(10); // remove the last face (two triangles): a square hole
    return box;
  }());
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.BoundaryEdges, 4);
  EXPECT_EQ(d.NonManifoldEdges, 0);
  EXPECT_FALSE(d.usable());
  const std::string message = d.errorMessage();
  EXPECT_TRUE(contains(message, "boundary edges")) << message;
  EXPECT_TRUE(contains(message, "4")) << message;

  const MeshDefects c = checkTriangleMesh(out);
  EXPECT_EQ(c.BoundaryEdges, 4);
}

TEST(Validation, NonManifoldEdge)
{
  // Three triangles on one edge: a closed box plus a fin on edge (0, 1).
  PolygonMesh m = unitBox();
  m.Points.emplace_back(0.5, -1.0, -1.0);
  m.addCell({ 0, 1, 8 });
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.NonManifoldEdges, 1);
  EXPECT_EQ(d.BoundaryEdges, 2);
  EXPECT_FALSE(d.usable());
  EXPECT_FALSE(d.errorMessage().empty());
}

TEST(Validation, NonManifoldVertex)
{
  // Two closed tetrahedra touching at one shared vertex: every edge has two triangles, but the
  // triangles around the shared vertex form two fans.
  PolygonMesh m;
  addTetrahedron(m, Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1));
  addTetrahedron(m, Vec3(0, 0, 0), Vec3(-1, 0, 0), Vec3(0, 0, -1), Vec3(0, -1, 0), 0);
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_EQ(d.NonManifoldVertices, 1);
  EXPECT_EQ(d.NonManifoldEdges, 0);
  EXPECT_EQ(d.BoundaryEdges, 0);
  EXPECT_EQ(d.InconsistentEdges, 0);
  EXPECT_FALSE(d.usable());
  EXPECT_FALSE(d.errorMessage().empty());
}

TEST(Validation, DegenerateTriangle)
{
  // Box with the midpoint m of edge (a, b) = (0, 1) inserted on one side: (a, b, c) becomes
  // (a, m, c) + (m, b, c), and the zero-area triangle (a, b, m) closes the gap. The mesh stays
  // closed, manifold and consistently oriented, with exactly one degenerate triangle.
  TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  const int a = 0, b = 1;
  int split = -1;
  for (std::size_t t = 0; t < box.Triangles.size() && split < 0; ++t)
  {
    for (int k = 0; k < 3; ++k)
    {
      if (box.Triangles[t][k] == a && box.Triangles[t][(k + 1) % 3] == b)
      {
        split = static_cast<int>(t);
      }
    }
  }
  ASSERT_GE(split, 0);
  Triangle tri = box.Triangles[split];
  while (tri[0] != a)
  {
    tri = { tri[1], tri[2], tri[0] };
  }
  const int c = tri[2];
  const int mid = static_cast<int>(box.Points.size());
  box.Points.push_back(0.5 * (box.Points[a] + box.Points[b]));
  box.Triangles[split] = { a, mid, c };
  box.Triangles.push_back({ mid, b, c });
  box.Triangles.push_back({ a, b, mid });
  TriangleMesh out;
  const MeshDefects d = prepareMesh(PolygonMesh::fromTriangles(box), out);
  // dropped and counted; the zero-width crack it closed is left as 3 boundary edges
  EXPECT_EQ(d.DroppedDegenerateTriangles, 1);
  EXPECT_EQ(d.DegenerateTriangles, 0);
  EXPECT_EQ(d.BoundaryEdges, 3);
  EXPECT_EQ(d.NonManifoldEdges, 0);
  EXPECT_EQ(d.InconsistentEdges, 0);
  EXPECT_FALSE(d.usable());
  EXPECT_TRUE(d.usableAsInput());
  EXPECT_EQ(out.Triangles.size(), 13u);
  EXPECT_FALSE(d.warnings().empty());

  // Repeated ids are degenerate too.
  TriangleMesh repeated = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  repeated.Triangles.push_back({ 2, 2, 5 });
  EXPECT_GE(checkTriangleMesh(repeated).DegenerateTriangles, 1);
}

TEST(Validation, DegenerateAreaTolerance)
{
  // A sliver of area 1e-9 (relative to the squared diagonal 3) passes with tolerance 0 and is
  // degenerate with tolerance 1e-6.
  // Built as in DegenerateTriangle, but the inserted point lies 2e-9 off the edge (0, 1).
  TriangleMesh sliver = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  int split = -1;
  for (std::size_t t = 0; t < sliver.Triangles.size() && split < 0; ++t)
  {
    for (int k = 0; k < 3; ++k)
    {
      if (sliver.Triangles[t][k] == 0 && sliver.Triangles[t][(k + 1) % 3] == 1)
      {
        split = static_cast<int>(t);
      }
    }
  }
  ASSERT_GE(split, 0);
  Triangle tri = sliver.Triangles[split];
  while (tri[0] != 0)
  {
    tri = { tri[1], tri[2], tri[0] };
  }
  const int c = tri[2];
  const int mid = static_cast<int>(sliver.Points.size());
  // Moved 2e-9 outward (away from c), so the sliver (0, 1, mid) has area 0.5 * 1 * 2e-9.
  const Vec3 away = (0.5 * (sliver.Points[0] + sliver.Points[1]) - sliver.Points[c]).normalized();
  sliver.Points.push_back(0.5 * (sliver.Points[0] + sliver.Points[1]) + 2e-9 * away);
  sliver.Triangles[split] = { 0, mid, c };
  sliver.Triangles.push_back({ mid, 1, c });
  sliver.Triangles.push_back({ 0, 1, mid });
  TriangleMesh out;
  const MeshDefects strict = prepareMesh(PolygonMesh::fromTriangles(sliver), out);
  EXPECT_EQ(strict.DegenerateTriangles, 0);
  EXPECT_TRUE(strict.usable()) << strict.errorMessage();
  ValidationOptions tolerant;
  tolerant.DegenerateAreaTolerance = 1e-6;
  EXPECT_EQ(prepareMesh(PolygonMesh::fromTriangles(sliver), out, tolerant).DroppedDegenerateTriangles, 1);
}

TEST(Validation, InconsistentOrientation)
{
  TriangleMesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  std::swap(box.Triangles[5][1], box.Triangles[5][2]);
  TriangleMesh out;
  const MeshDefects d = prepareMesh(PolygonMesh::fromTriangles(box), out);
  EXPECT_EQ(d.InconsistentEdges, 3);
  EXPECT_EQ(d.BoundaryEdges, 0);
  EXPECT_FALSE(d.usable());
  EXPECT_FALSE(d.errorMessage().empty());
  EXPECT_EQ(checkTriangleMesh(box).InconsistentEdges, 3);
}

TEST(Validation, InwardMeshIsFlipped)
{
  TriangleMesh sphere = makeSphere(Vec3(1, 2, 3), 2.0, 24, 12);
  const double outwardVolume = signedVolume(sphere);
  ASSERT_GT(outwardVolume, 0.0);
  reverseOrientation(sphere);
  ASSERT_LT(signedVolume(sphere), 0.0);
  TriangleMesh out;
  const MeshDefects d = prepareMesh(PolygonMesh::fromTriangles(sphere), out);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_TRUE(d.FlippedOrientation);
  EXPECT_NEAR(signedVolume(out), outwardVolume, 1e-9 * outwardVolume);
  EXPECT_EQ(checkTriangleMesh(out).InconsistentEdges, 0);
  bool warned = false;
  for (const std::string& w : d.warnings())
  {
    warned = warned || contains(w, "flip") || contains(w, "inward");
  }
  EXPECT_TRUE(warned);

  // checkTriangleMesh reports, but never flips.
  const MeshDefects c = checkTriangleMesh(sphere);
  EXPECT_FALSE(c.FlippedOrientation);
  EXPECT_TRUE(c.usable());
}

TEST(Validation, SeveralComponentsAreFine)
{
  TriangleMesh m = makeBox(Vec3(0, 0, 0), Vec3(1, 1, 1));
  appendMesh(m, makeBox(Vec3(2, 0, 0), Vec3(3, 1, 1)));
  appendMesh(m, makeSphere(Vec3(5, 0, 0), 0.5, 16, 8));
  TriangleMesh out;
  const MeshDefects d = prepareMesh(PolygonMesh::fromTriangles(m), out);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(d.Components, 3);
  EXPECT_EQ(d.Genus, 0);
  EXPECT_FALSE(d.FlippedOrientation);
}

TEST(Validation, TorusHasGenusOne)
{
  const TriangleMesh torus = makeTorus(Vec3(0, 0, 0), 1.0, 0.3, 32, 12);
  TriangleMesh out;
  const MeshDefects d = prepareMesh(PolygonMesh::fromTriangles(torus), out);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(d.Genus, 1);
  EXPECT_EQ(d.Components, 1);
  EXPECT_EQ(genus(torus), 1);
  EXPECT_EQ(eulerCharacteristic(torus), 0);

  // Two tori and a sphere: total genus 2, three components.
  TriangleMesh more = torus;
  appendMesh(more, makeTorus(Vec3(5, 0, 0), 1.0, 0.3, 32, 12));
  appendMesh(more, makeSphere(Vec3(0, 5, 0), 1.0, 16, 8));
  const MeshDefects e = prepareMesh(PolygonMesh::fromTriangles(more), out);
  EXPECT_TRUE(e.usable()) << e.errorMessage();
  EXPECT_EQ(e.Genus, 2);
  EXPECT_EQ(e.Components, 3);

  // checkTriangleMesh counts the edges of a closed mesh as 3F/2: the same genus as genus(), with
  // points no triangle uses left in, and with the built-in shape (a torus beside a sphere) added
  more.Points.push_back(Vec3(9, 9, 9));
  const MeshDefects f = checkTriangleMesh(more);
  EXPECT_TRUE(f.usable()) << f.errorMessage();
  EXPECT_EQ(f.Genus, 2);
  EXPECT_EQ(f.Components, 3);
  EXPECT_EQ(genus(more), 2);
  appendMesh(more, makeBuiltinShape());
  EXPECT_TRUE(checkTriangleMesh(more).usable());
  EXPECT_EQ(checkTriangleMesh(more).Genus, 3);
  EXPECT_EQ(genus(more), 3);
  EXPECT_EQ(checkTriangleMesh(torus).Genus, 1);
}

TEST(Validation, UnreferencedPointsAndIgnoredCellsAreDropped)
{
  PolygonMesh m = unitBox();
  m.Points.insert(m.Points.begin(), Vec3(9, 9, 9)); // shift every id by one
  for (auto& id : m.Connectivity)
  {
    ++id;
  }
  m.addCell({ 0 });
  m.addCell({ 0, 1 });
  TriangleMesh out;
  const MeshDefects d = prepareMesh(m, out);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(d.UnreferencedPoints, 1);
  EXPECT_EQ(d.IgnoredCells, 2);
  EXPECT_EQ(out.Points.size(), 8u);
  for (const Vec3& p : out.Points)
  {
    EXPECT_LE(p.maxCoeff(), 1.0);
  }
  EXPECT_NEAR(signedVolume(out), 1.0, 1e-12);
}

namespace
{
/// A small deterministic generator for the randomized tests: next(m) is in [0, m).
struct RandomBelow
{
  explicit RandomBelow(unsigned seed)
    : Seed(seed)
  {
  }
  unsigned operator()(unsigned m)
  {
    Seed = Seed * 1664525u + 1013904223u;
    return (Seed >> 8) % m;
  }
  unsigned Seed;
};
} // namespace

// checkTriangleMesh classifies each undirected edge around its lower vertex (Validation.cxx): on
// meshes damaged at random (triangles removed, flipped, duplicated, extra triangles on existing
// edges, repeated corners) its counts must equal a brute-force count over all edges (a map from
// each undirected edge to the directions of its triangles) and, for the vertices, the number of
// fans found by walking each vertex's triangles through shared edges.
TEST(Validation, EdgeAndVertexCountsEqualABruteForceCount)
{
  RandomBelow next(7u);
  for (int trial = 0; trial < 60; ++trial)
  {
    SCOPED_TRACE(trial);
    TriangleMesh m = makeSphere(Vec3(0, 0, 0), 1.0, 5 + static_cast<int>(next(6)), 4 + static_cast<int>(next(5)));
    const int nv = static_cast<int>(m.Points.size());
    const int damage = static_cast<int>(next(6));
    for (int k = 0; k < damage; ++k)
    {
      const std::size_t f = next(static_cast<unsigned>(m.Triangles.size()));
      switch (next(5))
      {
        case 0: // removed
          m.Triangles.erase(m.Triangles.begin() + static_cast<std::ptrdiff_t>(f));
          break;
        case 1: // flipped
          std::swap(m.Triangles[f][1], m.Triangles[f][2]);
          break;
        case 2: // duplicated
          m.Triangles.push_back(m.Triangles[f]);
          break;
        case 3: // a third triangle on one of its edges, to a random point
          m.Triangles.push_back({ m.Triangles[f][0], m.Triangles[f][1], static_cast<int>(next(nv)) });
          break;
        default: // a repeated corner (only in some trials: they take the general path)
          if (trial % 3 == 0)
            m.Triangles[f][2] = m.Triangles[f][0];
          break;
      }
    }
    // brute force: edges
    std::map<std::pair<int, int>, std::vector<bool>> edges; // (lo, hi) -> runs lo -> hi?
    for (const Triangle& t : m.Triangles)
      for (int i = 0; i < 3; ++i)
      {
        const int a = t[i], b = t[(i + 1) % 3];
        edges[{ std::min(a, b), std::max(a, b) }].push_back(a < b);
      }
    std::int64_t boundary = 0, nonManifold = 0, inconsistent = 0;
    for (const auto& e : edges)
    {
      if (e.second.size() == 1)
        ++boundary;
      else if (e.second.size() > 2)
        ++nonManifold;
      else if (e.second[0] == e.second[1])
        ++inconsistent;
    }
    // brute force: fans, by a walk over the triangles at v linked by a shared neighbour of v
    std::int64_t nonManifoldVertices = 0;
    for (int v = 0; v < nv; ++v)
    {
      std::vector<int> at;
      for (std::size_t f = 0; f < m.Triangles.size(); ++f)
        for (int i = 0; i < 3; ++i)
          if (m.Triangles[f][i] == v)
            at.push_back(static_cast<int>(f));
      if (at.empty())
        continue;
      auto others = [&](int f) {
        std::set<int> o;
        for (int w : m.Triangles[f])
          if (w != v)
            o.insert(w);
        return o;
      };
      std::vector<char> seen(at.size(), 0);
      int fans = 0;
      for (std::size_t s = 0; s < at.size(); ++s)
      {
        if (seen[s])
          continue;
        ++fans;
        std::vector<std::size_t> stack{ s };
        seen[s] = 1;
        while (!stack.empty())
        {
          const std::size_t a = stack.back();
          stack.pop_back();
          const std::set<int> oa = others(at[a]);
          for (std::size_t b = 0; b < at.size(); ++b)
          {
            if (seen[b])
              continue;
            const std::set<int> ob = others(at[b]);
            bool shared = false;
            for (int w : ob)
              shared = shared || oa.count(w) > 0;
            if (shared)
            {
              seen[b] = 1;
              stack.push_back(b);
            }
          }
        }
      }
      nonManifoldVertices += fans > 1 ? 1 : 0;
    }
    const MeshDefects d = checkTriangleMesh(m);
    EXPECT_EQ(d.BoundaryEdges, boundary);
    EXPECT_EQ(d.NonManifoldEdges, nonManifold);
    EXPECT_EQ(d.InconsistentEdges, inconsistent);
    EXPECT_EQ(d.NonManifoldVertices, nonManifoldVertices);
  }
}

// prepareMesh finds boundary edges (which decide where coincident points merge) and duplicated
// triangles by grouping at each point (Validation.cxx): on a split-corner torus (every triangle
// with its own three points, as in an STL file) with random triangles repeated in any corner
// order, the merge must join every position, and exactly the repeats must be dropped (counted
// by brute force over position triples), the first of each kept, leaving the closed torus.
TEST(Validation, MergesAndDuplicatesEqualABruteForceCount)
{
  RandomBelow next(11u);
  for (int trial = 0; trial < 20; ++trial)
  {
    SCOPED_TRACE(trial);
    const TriangleMesh torus =
      makeTorus(Vec3(0, 0, 0), 1.0, 0.35, 8 + static_cast<int>(next(12)), 5 + static_cast<int>(next(8)));
    PolygonMesh m;
    for (const Triangle& t : torus.Triangles)
    {
      const std::int64_t base = static_cast<std::int64_t>(m.Points.size());
      for (int v : t)
        m.Points.push_back(torus.Points[v]);
      m.addCell({ base, base + 1, base + 2 });
    }
    const std::size_t original = m.numberOfCells();
    const int repeats = static_cast<int>(next(40));
    for (int k = 0; k < repeats; ++k)
    {
      const std::size_t c = next(static_cast<unsigned>(original));
      // with points of its own, as in an STL file (repeats sharing their points would leave those
      // points off the boundary, where coincident points are kept apart on purpose)
      const std::int64_t b = m.Offsets[c];
      const std::int64_t base = static_cast<std::int64_t>(m.Points.size());
      for (int k = 0; k < 3; ++k)
        m.Points.push_back(Vec3(m.Points[m.Connectivity[b + k]]));
      std::int64_t ids[3] = { base, base + 1, base + 2 };
      if (next(2))
        std::swap(ids[1], ids[2]);              // reversed
      std::rotate(ids, ids + next(3), ids + 3); // and rotated
      m.addCell({ ids[0], ids[1], ids[2] });
    }
    // brute force: distinct position triples among the cells
    std::set<std::array<std::array<double, 3>, 3>> distinct;
    for (std::size_t c = 0; c < m.numberOfCells(); ++c)
    {
      std::array<std::array<double, 3>, 3> key;
      for (int k = 0; k < 3; ++k)
      {
        const Vec3& p = m.Points[m.Connectivity[m.Offsets[c] + k]];
        key[k] = { p.x(), p.y(), p.z() };
      }
      std::sort(key.begin(), key.end());
      distinct.insert(key);
    }
    TriangleMesh out;
    const MeshDefects d = prepareMesh(m, out);
    EXPECT_EQ(d.DroppedDuplicateTriangles, static_cast<std::int64_t>(m.numberOfCells() - distinct.size()));
    EXPECT_EQ(out.Triangles.size(), distinct.size());
    EXPECT_EQ(out.Points.size(), torus.Points.size());
    EXPECT_EQ(d.BoundaryEdges, 0);
    EXPECT_EQ(d.NonManifoldEdges, 0);
    EXPECT_TRUE(d.usable()) << d.errorMessage();
    EXPECT_EQ(d.Genus, 1);
    // the first of each repeated triple is the one kept: the torus' own triangles, in order
    ASSERT_GE(out.Triangles.size(), torus.Triangles.size());
    for (std::size_t f = 0; f < torus.Triangles.size(); ++f)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(out.Points[out.Triangles[f][k]], torus.Points[torus.Triangles[f][k]]);
  }
}
