// SDFCage — Testing: every defect of Validation.h on hand-built meshes.
#include "Mesh/Mesh.h"
#include "Mesh/Shapes.h"
#include "Mesh/Validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
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
  for (Triangle& t : sphere.Triangles)
  {
    std::swap(t[1], t[2]);
  }
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
