// SDFCage — Testing: the exact checker against hand-built cases with known answers.
#include "ExactCheck.h"
#include "MeshIO.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <sys/wait.h>

using sdfcage::Triangle;
using sdfcage::TriangleMesh;
using sdfcage::Vec3;
using sdfcage::exact::exactCheck;
using sdfcage::exact::ExactReport;

namespace
{

/// Axis-aligned box [lo, hi] as 12 outward triangles (corner i = x + 2y + 4z).
TriangleMesh box(const Vec3& lo, const Vec3& hi)
{
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
  {
    m.Points.emplace_back(i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]);
  }
  const int quads[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 },
    { 1, 3, 7, 5 } };
  for (const auto& q : quads)
  {
    m.Triangles.push_back({ q[0], q[1], q[2] });
    m.Triangles.push_back({ q[0], q[2], q[3] });
  }
  return m;
}

TriangleMesh cube(double half)
{
  return box(Vec3::Constant(-half), Vec3::Constant(half));
}

void append(TriangleMesh& a, const TriangleMesh& b)
{
  const int offset = static_cast<int>(a.Points.size());
  a.Points.insert(a.Points.end(), b.Points.begin(), b.Points.end());
  for (const Triangle& t : b.Triangles)
  {
    a.Triangles.push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
  }
}

TriangleMesh torus(double major, double minor, int n, int m)
{
  TriangleMesh mesh;
  const double pi = std::acos(-1.0);
  for (int i = 0; i < n; ++i)
  {
    for (int j = 0; j < m; ++j)
    {
      const double u = 2 * pi * i / n, v = 2 * pi * j / m;
      mesh.Points.emplace_back(
        (major + minor * std::cos(v)) * std::cos(u), (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v));
    }
  }
  auto id = [&](int i, int j) { return (i % n) * m + (j % m); };
  for (int i = 0; i < n; ++i)
  {
    for (int j = 0; j < m; ++j)
    {
      mesh.Triangles.push_back({ id(i, j), id(i + 1, j), id(i + 1, j + 1) });
      mesh.Triangles.push_back({ id(i, j), id(i + 1, j + 1), id(i, j + 1) });
    }
  }
  return mesh;
}

TriangleMesh singleTriangle(const Vec3& a, const Vec3& b, const Vec3& c)
{
  TriangleMesh m;
  m.Points = { a, b, c };
  m.Triangles = { { 0, 1, 2 } };
  return m;
}

} // namespace

TEST(ExactCheck, NestedCubesEnclose)
{
  const ExactReport r = exactCheck(cube(1.0), cube(2.0), 5.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.BoundaryEdges, 0);
  EXPECT_EQ(r.NonManifoldEdges, 0);
  EXPECT_EQ(r.NonManifoldVertices, 0);
  EXPECT_EQ(r.InconsistentEdges, 0);
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_EQ(r.InputIntersections, 0);
  EXPECT_EQ(r.InputVerticesOutside, 0);
  EXPECT_EQ(r.CageGenus, 0);
  EXPECT_EQ(r.CageComponents, 1);
  EXPECT_NEAR(r.MinimumClearance, 1.0, 1e-12); // faces x = 1 and x = 2
  EXPECT_FALSE(r.ClearanceIsLowerBound);
  EXPECT_TRUE(r.Encloses);
}

TEST(ExactCheck, ClearanceBeyondLimitIsReportedAsLowerBound)
{
  const ExactReport r = exactCheck(cube(1.0), cube(2.0), 0.25);
  EXPECT_TRUE(r.Encloses);
  EXPECT_TRUE(r.ClearanceIsLowerBound);
  EXPECT_DOUBLE_EQ(r.MinimumClearance, 0.25);
  EXPECT_DOUBLE_EQ(r.ClearanceQueryLimit, 0.25);
}

TEST(ExactCheck, DefaultLimitIsTwoPercentOfInputDiagonal)
{
  const ExactReport r = exactCheck(cube(1.0), cube(2.0), 0.0);
  EXPECT_NEAR(r.ClearanceQueryLimit, 0.02 * std::sqrt(12.0), 1e-12);
  EXPECT_TRUE(r.ClearanceIsLowerBound);
}

TEST(ExactCheck, InnerCageLeavesAllInputVerticesOutside)
{
  const ExactReport r = exactCheck(cube(2.0), cube(1.0), 5.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.InputVerticesOutside, 8);
  EXPECT_EQ(r.InputIntersections, 0);
  EXPECT_NEAR(r.MinimumClearance, 1.0, 1e-12);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, InputComponentOutsideCountsAllItsVertices)
{
  // No cage/input contact: one inside query per input component decides for all its vertices.
  TriangleMesh input = cube(1.0);
  append(input, box(Vec3(5, 5, 5), Vec3(6, 6, 6)));
  append(input, box(Vec3(-0.5, -0.5, 1.5), Vec3(0.5, 0.5, 1.9)));
  const ExactReport r = exactCheck(input, cube(2.0), 5.0);
  EXPECT_EQ(r.InputIntersections, 0);
  EXPECT_EQ(r.InputVerticesOutside, 8);
  EXPECT_NEAR(r.MinimumClearance, 0.1, 1e-12); // z = 1.9 vs the cage face z = 2
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, TouchingFaceIsAnIntersection)
{
  // Input box [-1, 2] x [-1, 1]^2 touches the cage face x = 2.
  const ExactReport r = exactCheck(box(Vec3(-1, -1, -1), Vec3(2, 1, 1)), cube(2.0), 5.0);
  EXPECT_GT(r.InputIntersections, 0);
  EXPECT_EQ(r.MinimumClearance, 0.0);
  EXPECT_EQ(r.InputVerticesOutside, 4); // the four on x = 2 lie on the cage: not strictly inside
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, CrossingInputIsAnIntersection)
{
  const ExactReport r = exactCheck(box(Vec3(-1, -1, -1), Vec3(3, 1, 1)), cube(2.0), 5.0);
  EXPECT_GT(r.InputIntersections, 0);
  EXPECT_EQ(r.InputVerticesOutside, 4);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, OpenCageReportsBoundaryAndNoInsideTest)
{
  TriangleMesh cage = cube(2.0);
  cage.Triangles.pop_back();
  const ExactReport r = exactCheck(cube(1.0), cage, 5.0);
  EXPECT_EQ(r.BoundaryEdges, 3);
  EXPECT_FALSE(r.Closed2Manifold);
  EXPECT_EQ(r.InputVerticesOutside, 8); // unknown: all count as outside
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, EmptyCage)
{
  const ExactReport r = exactCheck(cube(1.0), TriangleMesh(), 5.0);
  EXPECT_FALSE(r.Closed2Manifold);
  EXPECT_EQ(r.CageComponents, 0);
  EXPECT_EQ(r.InputVerticesOutside, 8);
  EXPECT_TRUE(r.ClearanceIsLowerBound);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, EmptyInputInsideAnyClosedCage)
{
  const ExactReport r = exactCheck(TriangleMesh(), cube(1.0), 1.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.InputVerticesOutside, 0);
  EXPECT_TRUE(r.Encloses);
}

TEST(ExactCheck, NonManifoldEdge)
{
  TriangleMesh cage = cube(2.0);
  // A fin on edge (0, 1) pointing outward (-y, -z): third triangle on that edge.
  cage.Points.emplace_back(0.0, -3.0, -3.0);
  cage.Triangles.push_back({ 0, 1, 8 });
  const ExactReport r = exactCheck(cube(1.0), cage, 5.0);
  EXPECT_EQ(r.NonManifoldEdges, 1);
  EXPECT_EQ(r.BoundaryEdges, 2);
  EXPECT_FALSE(r.Closed2Manifold);
  EXPECT_EQ(r.SelfIntersections, 0); // the fin meets the box only along the shared edge
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, NonManifoldVertexWithoutSelfIntersection)
{
  // Two cubes touching at one corner that they share by index.
  TriangleMesh cage = box(Vec3(0, 0, 0), Vec3(1, 1, 1));
  TriangleMesh other = box(Vec3(1, 1, 1), Vec3(2, 2, 2));
  append(cage, other);
  for (Triangle& t : cage.Triangles)
  {
    for (int& v : t)
    {
      v = (v == 8) ? 7 : v; // corner 0 of the second cube is corner 7 of the first
    }
  }
  const ExactReport r = exactCheck(TriangleMesh(), cage, 1.0);
  EXPECT_EQ(r.NonManifoldVertices, 1);
  EXPECT_EQ(r.NonManifoldEdges, 0);
  EXPECT_EQ(r.BoundaryEdges, 0);
  EXPECT_EQ(r.CageComponents, 1);
  EXPECT_FALSE(r.Closed2Manifold);
  EXPECT_EQ(r.SelfIntersections, 0); // they meet only at the shared vertex
}

TEST(ExactCheck, TouchingAtDuplicatedPointIsSelfIntersection)
{
  // The same two cubes, but the touching corner exists twice (two ids at one position).
  TriangleMesh cage = box(Vec3(0, 0, 0), Vec3(1, 1, 1));
  append(cage, box(Vec3(1, 1, 1), Vec3(2, 2, 2)));
  const ExactReport r = exactCheck(TriangleMesh(), cage, 1.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.CageComponents, 2);
  EXPECT_GT(r.SelfIntersections, 0);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, OverlappingComponentsSelfIntersect)
{
  TriangleMesh cage = cube(2.0);
  append(cage, box(Vec3(1, 1, 1), Vec3(3, 3, 3)));
  const ExactReport r = exactCheck(cube(0.5), cage, 5.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.CageComponents, 2);
  EXPECT_GT(r.SelfIntersections, 0);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, SeparateComponentsEncloseSeparateInputs)
{
  TriangleMesh input = box(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  append(input, box(Vec3(5, -1, -1), Vec3(7, 1, 1)));
  TriangleMesh cage = box(Vec3(-1.5, -1.5, -1.5), Vec3(1.5, 1.5, 1.5));
  append(cage, box(Vec3(4.75, -1.25, -1.25), Vec3(7.25, 1.25, 1.25)));
  const ExactReport r = exactCheck(input, cage, 1.0);
  EXPECT_EQ(r.CageComponents, 2);
  EXPECT_EQ(r.CageGenus, 0);
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_NEAR(r.MinimumClearance, 0.25, 1e-12);
  EXPECT_TRUE(r.Encloses);
}

TEST(ExactCheck, TorusGenusAndNestedTori)
{
  const TriangleMesh outer = torus(2.0, 0.8, 48, 24);
  const TriangleMesh inner = torus(2.0, 0.3, 48, 24);
  const ExactReport r = exactCheck(inner, outer, 1.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.CageGenus, 1);
  EXPECT_EQ(r.CageComponents, 1);
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_TRUE(r.Encloses);
  // Polygonal tori: the gap lies between the smooth radii' difference (0.5) and that minus the
  // sagitta of the outer tessellation.
  EXPECT_LT(r.MinimumClearance, 0.5 + 1e-9);
  EXPECT_GT(r.MinimumClearance, 0.4);
}

TEST(ExactCheck, InconsistentOrientationStillManifold)
{
  TriangleMesh cage = cube(2.0);
  std::swap(cage.Triangles[3][1], cage.Triangles[3][2]);
  const ExactReport r = exactCheck(cube(1.0), cage, 5.0);
  EXPECT_EQ(r.InconsistentEdges, 3);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.InputVerticesOutside, 0); // inside/outside is orientation-free
}

TEST(ExactCheck, VertexSharingTriangles)
{
  TriangleMesh crossing;
  crossing.Points = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1) };
  crossing.Triangles = { { 0, 1, 2 }, { 0, 3, 4 } }; // second one pierces the first
  EXPECT_EQ(exactCheck(TriangleMesh(), crossing, 1.0).SelfIntersections, 1);

  TriangleMesh apart = crossing;
  apart.Points[3] = Vec3(-0.2, -0.2, -1);
  apart.Points[4] = Vec3(-0.2, -0.1, 1);
  EXPECT_EQ(exactCheck(TriangleMesh(), apart, 1.0).SelfIntersections, 0);

  TriangleMesh coplanarOverlap = crossing;
  coplanarOverlap.Points[3] = Vec3(0.5, 0.2, 0);
  coplanarOverlap.Points[4] = Vec3(0.2, 0.5, 0);
  EXPECT_EQ(exactCheck(TriangleMesh(), coplanarOverlap, 1.0).SelfIntersections, 1);

  TriangleMesh coplanarApart = crossing;
  coplanarApart.Points[3] = Vec3(-0.5, -0.2, 0);
  coplanarApart.Points[4] = Vec3(-0.2, -0.5, 0);
  EXPECT_EQ(exactCheck(TriangleMesh(), coplanarApart, 1.0).SelfIntersections, 0);
}

TEST(ExactCheck, EdgeSharingTriangles)
{
  TriangleMesh m;
  m.Points = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.5, 0.5, 0) };
  m.Triangles = { { 0, 1, 2 }, { 1, 0, 3 } }; // coplanar, apexes on the same side: folded over
  EXPECT_EQ(exactCheck(TriangleMesh(), m, 1.0).SelfIntersections, 1);
  m.Points[3] = Vec3(0.5, -0.5, 0); // coplanar, opposite sides: a flat pair
  EXPECT_EQ(exactCheck(TriangleMesh(), m, 1.0).SelfIntersections, 0);
  m.Points[3] = Vec3(0.5, 0.5, 1e-12); // a dihedral angle of almost zero is still fine
  EXPECT_EQ(exactCheck(TriangleMesh(), m, 1.0).SelfIntersections, 0);
  m.Triangles.push_back({ 2, 1, 0 }); // a duplicated triangle
  EXPECT_GE(exactCheck(TriangleMesh(), m, 1.0).SelfIntersections, 1);
}

TEST(ExactCheck, SelfIntersectionsAgreeWithCgalPmp)
{
  // A torus with folds (some vertices pushed far through the surface) and a second, crossing
  // torus: hundreds of intersecting pairs, adjacent and not. CGAL's
  // Polygon_mesh_processing::self_intersections must count the same pairs.
  TriangleMesh mesh = torus(2.0, 0.6, 40, 16);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t v = 0; v < mesh.Points.size(); v += 7)
  {
    mesh.Points[v] += 0.5 * Vec3(u(rng), u(rng), u(rng));
  }
  TriangleMesh crossing = torus(1.0, 0.4, 24, 12);
  for (Vec3& p : crossing.Points)
  {
    p = Vec3(p[0] + 2.0, p[2], p[1]); // in the xz plane, through the first torus's tube
  }
  append(mesh, crossing);

  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  Mesh sm;
  std::vector<Mesh::Vertex_index> vertices;
  for (const Vec3& p : mesh.Points)
  {
    vertices.push_back(sm.add_vertex(K::Point_3(p[0], p[1], p[2])));
  }
  for (const Triangle& t : mesh.Triangles)
  {
    ASSERT_NE(sm.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]), Mesh::null_face());
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));

  const ExactReport r = exactCheck(TriangleMesh(), mesh, 1.0);
  EXPECT_GT(pairs.size(), 100u);
  EXPECT_EQ(r.SelfIntersections, static_cast<long long>(pairs.size()));
  EXPECT_EQ(r.CageComponents, 2);
  EXPECT_TRUE(r.Closed2Manifold);
}

TEST(ExactCheck, DegenerateAndInvalidTrianglesDoNotCrash)
{
  TriangleMesh cage = cube(2.0);
  cage.Points.emplace_back(2.0, 2.0, 0.0); // on edge (3, 7): collinear with it
  cage.Triangles.push_back({ 3, 7, 8 });
  ExactReport r = exactCheck(cube(1.0), cage, 5.0);
  EXPECT_EQ(r.DegenerateTriangles, 1);
  EXPECT_GE(r.SelfIntersections, 1);
  EXPECT_FALSE(r.Encloses);

  cage = cube(2.0);
  cage.Triangles.push_back({ 0, 0, 1 });  // repeated id
  cage.Triangles.push_back({ 0, 1, 99 }); // id out of range
  cage.Triangles.push_back({ -4, 1, 2 }); // negative id
  r = exactCheck(cube(1.0), cage, 5.0);
  EXPECT_EQ(r.InvalidTriangles, 2);
  EXPECT_EQ(r.DegenerateTriangles, 1);
  EXPECT_FALSE(r.Closed2Manifold);
  EXPECT_FALSE(r.Encloses);

  cage = cube(2.0);
  cage.Points[0][1] = std::numeric_limits<double>::quiet_NaN();
  r = exactCheck(cube(1.0), cage, 5.0);
  EXPECT_EQ(r.InvalidTriangles, 6); // every triangle using corner 0
  EXPECT_FALSE(r.Closed2Manifold);
  EXPECT_FALSE(r.Encloses);
}

TEST(ExactCheck, TriangleDistanceMatchesDenseSampling)
{
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 40; // samples per edge
  for (int trial = 0; trial < 25; ++trial)
  {
    Vec3 a[3], b[3];
    for (int k = 0; k < 3; ++k)
    {
      a[k] = Vec3(u(rng), u(rng), u(rng));
      b[k] = Vec3(u(rng), u(rng), u(rng)) + Vec3(1.5, 0.3 * trial / 25.0, 0.0);
    }
    const ExactReport r = exactCheck(singleTriangle(a[0], a[1], a[2]), singleTriangle(b[0], b[1], b[2]), 100.0);
    double sampled = std::numeric_limits<double>::infinity();
    std::vector<Vec3> sa, sb;
    for (int i = 0; i <= n; ++i)
    {
      for (int j = 0; i + j <= n; ++j)
      {
        const double s = double(i) / n, t = double(j) / n;
        sa.push_back(a[0] + s * (a[1] - a[0]) + t * (a[2] - a[0]));
        sb.push_back(b[0] + s * (b[1] - b[0]) + t * (b[2] - b[0]));
      }
    }
    for (const Vec3& p : sa)
    {
      for (const Vec3& q : sb)
      {
        sampled = std::min(sampled, (p - q).norm());
      }
    }
    double longest = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      longest = std::max({ longest, (a[k] - a[(k + 1) % 3]).norm(), (b[k] - b[(k + 1) % 3]).norm() });
    }
    // The samples are within longest/n of any point of their triangle.
    EXPECT_LE(r.MinimumClearance, sampled + 1e-12) << "trial " << trial;
    EXPECT_GE(r.MinimumClearance, sampled - 2.0 * longest / n) << "trial " << trial;
    EXPECT_EQ(r.InputIntersections > 0, r.MinimumClearance == 0.0) << "trial " << trial;
  }
}

namespace
{

/// Runs the CLI; returns its exit status and stdout.
int runChecker(const std::string& args, std::string& output)
{
  const std::string out = ::testing::TempDir() + "sdfcage_exact_check_stdout.txt";
  const std::string command =
    std::string("\"") + SDFCAGE_EXACT_CHECK_EXE + "\" " + args + " > \"" + out + "\" 2>/dev/null";
  const int status = std::system(command.c_str());
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  output = text.str();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// The number after "key": in a flat JSON object (NaN when absent).
double jsonNumber(const std::string& json, const std::string& key)
{
  const std::size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos)
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

} // namespace

TEST(ExactCheckTool, ExitCodesAndJson)
{
  const std::string dir = ::testing::TempDir();
  const std::string inner = dir + "exact_inner.off", outer = dir + "exact_outer.off";
  ASSERT_TRUE(sdfcage::exact::writeOFF(inner, cube(1.0)));
  ASSERT_TRUE(sdfcage::exact::writeOFF(outer, cube(2.0)));
  // An OBJ cage, to exercise the other reader through the tool.
  const std::string outerObj = dir + "exact_outer.obj";
  {
    std::ofstream obj(outerObj);
    const TriangleMesh c = cube(2.0);
    for (const Vec3& p : c.Points)
    {
      obj << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    }
    for (const Triangle& t : c.Triangles)
    {
      obj << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }
  }
  std::string json;
  EXPECT_EQ(runChecker("\"" + inner + "\" \"" + outer + "\" --clearance 5", json), 0);
  EXPECT_NE(json.find("\"Encloses\": true"), std::string::npos) << json;
  EXPECT_NEAR(jsonNumber(json, "MinimumClearance"), 1.0, 1e-12) << json;

  EXPECT_EQ(runChecker("\"" + inner + "\" \"" + outerObj + "\"", json), 0);
  EXPECT_NE(json.find("\"Encloses\": true"), std::string::npos) << json;

  EXPECT_EQ(runChecker("\"" + outer + "\" \"" + inner + "\"", json), 1);
  EXPECT_NE(json.find("\"Encloses\": false"), std::string::npos) << json;
  EXPECT_EQ(jsonNumber(json, "InputVerticesOutside"), 8.0) << json;

  EXPECT_EQ(runChecker("\"" + inner + "\" \"" + dir + "does_not_exist.off\"", json), 2);
  EXPECT_EQ(runChecker("\"" + inner + "\"", json), 2);
  EXPECT_EQ(runChecker("\"" + inner + "\" \"" + outer + "\" --clearance -1", json), 2);
}
