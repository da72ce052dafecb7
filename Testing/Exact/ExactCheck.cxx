// SDFCage — Testing: exact-predicate cage check (CGAL, test-only).
#include "ExactCheck.h"

#include <CGAL/Box_intersection_d/Box_with_info_d.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>
#include <CGAL/squared_distance_3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <vector>

namespace sdfcage
{
namespace exact
{
namespace
{

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using P3 = K::Point_3;
using S3 = K::Segment_3;
using T3 = K::Triangle_3;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int, CGAL::Box_intersection_d::ID_EXPLICIT>;

/// box_intersection_d switches to brute-force scanning below this many boxes. CGAL's default is
/// 10; of 10, 100, 500 and 2000, 2000 used the least CPU on surface meshes of 10^5..10^6 small
/// triangles (armadillo checks with 132k..346k cage and 86k..346k input triangles: 2.0-2.8 s of
/// CPU for the whole check, against 5.3 s with the default).
constexpr std::ptrdiff_t kBoxCutoff = 2000;

/// A triangle as a point set: a proper triangle (Size 3), or, when degenerate, the segment
/// (Size 2) or point (Size 1) it collapses to. Size 0: unusable (bad id or non-finite point).
struct Primitive
{
  int Size = 0;
  std::array<P3, 3> P;
  CGAL::Bbox_3 Box;
  /// Unit normal and offset of the supporting plane (proper triangles only), for pruning.
  Vec3 Normal = Vec3::Zero();
  double Offset = 0.0;

  T3 triangle() const { return T3(P[0], P[1], P[2]); }
  S3 segment() const { return S3(P[0], P[1]); }
  int edgeCount() const { return Size == 3 ? 3 : (Size == 2 ? 1 : 0); }
  S3 edge(int e) const { return S3(P[e], P[(e + 1) % Size]); }
};

/// Builds the primitive of triangle t; Size 0 when an id is out of range or a point not finite.
Primitive makePrimitive(const TriangleMesh& mesh, const Triangle& t)
{
  Primitive prim;
  const int n = static_cast<int>(mesh.Points.size());
  for (int k = 0; k < 3; ++k)
  {
    if (t[k] < 0 || t[k] >= n || !mesh.Points[t[k]].allFinite())
    {
      return prim;
    }
  }
  const Vec3& a = mesh.Points[t[0]];
  const Vec3& b = mesh.Points[t[1]];
  const Vec3& c = mesh.Points[t[2]];
  const P3 p(a[0], a[1], a[2]), q(b[0], b[1], b[2]), r(c[0], c[1], c[2]);
  prim.Box = p.bbox() + q.bbox() + r.bbox();
  if (!CGAL::collinear(p, q, r))
  {
    prim.Size = 3;
    prim.P = { p, q, r };
    const Vec3 n = (b - a).cross(c - a);
    if (n.norm() > 0.0)
    {
      prim.Normal = n.normalized();
      prim.Offset = prim.Normal.dot(a);
    }
    return prim;
  }
  // Collinear (exact): the point set is the segment between the two outermost points.
  P3 s0 = p, s1 = r;
  if (CGAL::collinear_are_ordered_along_line(q, p, r))
  {
    s0 = q; // p lies between q and r
  }
  else if (CGAL::collinear_are_ordered_along_line(p, r, q))
  {
    s1 = q; // r lies between p and q
  }
  prim.P = { s0, s1, s1 };
  prim.Size = (s0 == s1) ? 1 : 2;
  return prim;
}

/// Exact: do the two point sets share a point?
bool intersects(const Primitive& a0, const Primitive& b0)
{
  const Primitive& a = a0.Size >= b0.Size ? a0 : b0;
  const Primitive& b = a0.Size >= b0.Size ? b0 : a0;
  switch (a.Size * 4 + b.Size)
  {
    case 3 * 4 + 3:
      return CGAL::do_intersect(a.triangle(), b.triangle());
    case 3 * 4 + 2:
      return CGAL::do_intersect(a.triangle(), b.segment());
    case 3 * 4 + 1:
      return CGAL::do_intersect(a.triangle(), b.P[0]);
    case 2 * 4 + 2:
      return CGAL::do_intersect(a.segment(), b.segment());
    case 2 * 4 + 1:
      return CGAL::do_intersect(a.segment(), b.P[0]);
    case 1 * 4 + 1:
      return a.P[0] == b.P[0];
    default:
      return false;
  }
}

double squaredDistance(const P3& p, const Primitive& b)
{
  switch (b.Size)
  {
    case 3:
      return CGAL::to_double(CGAL::squared_distance(p, b.triangle()));
    case 2:
      return CGAL::to_double(CGAL::squared_distance(p, b.segment()));
    default:
      return CGAL::to_double(CGAL::squared_distance(p, b.P[0]));
  }
}

/// Squared distance of two primitives known not to intersect: for two triangles the minimum of
/// the 6 vertex/triangle and 9 edge/edge squared distances (the closest pair of two disjoint
/// triangles is always one of these).
double squaredDistanceDisjoint(const Primitive& a, const Primitive& b)
{
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < a.Size; ++i)
  {
    best = std::min(best, squaredDistance(a.P[i], b));
  }
  for (int j = 0; j < b.Size; ++j)
  {
    best = std::min(best, squaredDistance(b.P[j], a));
  }
  for (int i = 0; i < a.edgeCount(); ++i)
  {
    for (int j = 0; j < b.edgeCount(); ++j)
    {
      best = std::min(best, CGAL::to_double(CGAL::squared_distance(a.edge(i), b.edge(j))));
    }
  }
  return best;
}

/// Squared distance between two boxes (a lower bound of the distance of their contents).
double boxDistance2(const CGAL::Bbox_3& a, const CGAL::Bbox_3& b)
{
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k)
  {
    const double gap = std::max({ 0.0, a.min(k) - b.max(k), b.min(k) - a.max(k) });
    d2 += gap * gap;
  }
  return d2;
}

/// A lower bound of the distance between a and b from a's supporting plane: when all of b lies on
/// one side of it, b is at least as far from a as b's nearest point is from the plane. Reduced by
/// a rounding allowance of 1e-12 of the coordinates' magnitude (it only prunes candidates).
double planeBound(const Primitive& a, const Primitive& b)
{
  if (a.Size != 3 || a.Normal.squaredNorm() == 0.0)
  {
    return 0.0;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, magnitude = std::abs(a.Offset);
  for (int i = 0; i < b.Size; ++i)
  {
    const Vec3 x(b.P[i].x(), b.P[i].y(), b.P[i].z());
    const double d = a.Normal.dot(x) - a.Offset;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
    magnitude = std::max(magnitude, x.cwiseAbs().maxCoeff());
  }
  const double bound = lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
  return std::max(0.0, bound - 1e-12 * (1.0 + magnitude));
}

/// Do two non-degenerate cage triangles sharing ids intersect beyond what they share?
/// `shared` = number of common ids (1 or 2; 3 is a duplicated triangle and always counts).
bool adjacentIntersect(const Triangle& ta, const Triangle& tb, const Primitive& a, const Primitive& b, int shared)
{
  if (shared >= 3)
  {
    return true;
  }
  auto indexIn = [](const Triangle& t, int id) {
    for (int k = 0; k < 3; ++k)
    {
      if (t[k] == id)
      {
        return k;
      }
    }
    return -1;
  };
  if (shared == 1)
  {
    // Shared vertex v = a.P[i] = b.P[j]. A ray from v inside a triangle leaves it through the
    // opposite edge, so the triangles meet beyond v exactly when one triangle's opposite edge
    // touches the other triangle.
    int i = 0, j = -1;
    for (; i < 3; ++i)
    {
      j = indexIn(tb, ta[i]);
      if (j >= 0)
      {
        break;
      }
    }
    const S3 oppositeA(a.P[(i + 1) % 3], a.P[(i + 2) % 3]);
    const S3 oppositeB(b.P[(j + 1) % 3], b.P[(j + 2) % 3]);
    return CGAL::do_intersect(oppositeA, b.triangle()) || CGAL::do_intersect(oppositeB, a.triangle());
  }
  // Shared edge (p, q), apexes r (of a) and s (of b): the triangles meet beyond the edge exactly
  // when they are coplanar and r, s lie on the same side of line pq.
  int ra = 0, sb = 0;
  for (int k = 0; k < 3; ++k)
  {
    if (indexIn(tb, ta[k]) < 0)
    {
      ra = k;
    }
    if (indexIn(ta, tb[k]) < 0)
    {
      sb = k;
    }
  }
  const P3& p = a.P[(ra + 1) % 3];
  const P3& q = a.P[(ra + 2) % 3];
  const P3& r = a.P[ra];
  const P3& s = b.P[sb];
  return CGAL::coplanar(p, q, r, s) && CGAL::coplanar_orientation(p, q, r, s) == CGAL::POSITIVE;
}

int sharedIds(const Triangle& a, const Triangle& b)
{
  int n = 0;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      n += (a[i] == b[j]) ? 1 : 0;
    }
  }
  return n;
}

struct UnionFind
{
  std::vector<int> Parent;
  explicit UnionFind(std::size_t n)
    : Parent(n)
  {
    std::iota(Parent.begin(), Parent.end(), 0);
  }
  int find(int x)
  {
    while (Parent[x] != x)
    {
      Parent[x] = Parent[Parent[x]];
      x = Parent[x];
    }
    return x;
  }
  void unite(int a, int b)
  {
    a = find(a);
    b = find(b);
    if (a != b)
    {
      Parent[std::max(a, b)] = std::min(a, b);
    }
  }
};

/// Topology by ids over the triangles with valid ids (`valid[t]`).
void checkTopology(const TriangleMesh& cage, const std::vector<char>& valid, ExactReport& report)
{
  const std::size_t nPoints = cage.Points.size();
  struct HalfEdge
  {
    std::uint64_t Key; // (min id << 32) | max id
    bool Forward;      // stored as (min, max) in the triangle's direction
  };
  std::vector<HalfEdge> edges;
  edges.reserve(cage.Triangles.size() * 3);
  for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
  {
    if (!valid[t])
    {
      continue;
    }
    const Triangle& tri = cage.Triangles[t];
    for (int k = 0; k < 3; ++k)
    {
      const std::uint32_t a = static_cast<std::uint32_t>(tri[k]);
      const std::uint32_t b = static_cast<std::uint32_t>(tri[(k + 1) % 3]);
      if (a != b)
      {
        const std::uint64_t lo = std::min(a, b), hi = std::max(a, b);
        edges.push_back({ (lo << 32) | hi, a < b });
      }
    }
  }
  std::sort(edges.begin(), edges.end(), [](const HalfEdge& x, const HalfEdge& y) { return x.Key < y.Key; });

  // Components over shared vertices; count V, E, F per component for the genus.
  UnionFind uf(nPoints);
  std::vector<char> referenced(nPoints, 0);
  for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
  {
    if (!valid[t])
    {
      continue;
    }
    const Triangle& tri = cage.Triangles[t];
    for (int k = 0; k < 3; ++k)
    {
      referenced[tri[k]] = 1;
    }
    uf.unite(tri[0], tri[1]);
    uf.unite(tri[1], tri[2]);
  }

  std::vector<long long> chi(nPoints, 0);
  for (std::size_t b = 0; b < edges.size();)
  {
    std::size_t e = b;
    int forward = 0;
    while (e < edges.size() && edges[e].Key == edges[b].Key)
    {
      forward += edges[e].Forward ? 1 : 0;
      ++e;
    }
    const std::size_t n = e - b;
    if (n == 1)
    {
      ++report.BoundaryEdges;
    }
    else if (n > 2)
    {
      ++report.NonManifoldEdges;
    }
    else if (forward != 1)
    {
      ++report.InconsistentEdges;
    }
    const int v = static_cast<int>(edges[b].Key >> 32);
    chi[uf.find(v)] -= 1;
    b = e;
  }
  for (std::size_t v = 0; v < nPoints; ++v)
  {
    if (referenced[v])
    {
      chi[uf.find(static_cast<int>(v))] += 1;
    }
  }
  for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
  {
    if (valid[t])
    {
      chi[uf.find(cage.Triangles[t][0])] += 1;
    }
  }
  report.CageComponents = 0;
  long long genus2 = 0;
  for (std::size_t v = 0; v < nPoints; ++v)
  {
    if (referenced[v] && uf.find(static_cast<int>(v)) == static_cast<int>(v))
    {
      ++report.CageComponents;
      genus2 += 2 - chi[v];
    }
  }
  report.CageGenus = static_cast<int>(genus2 / 2);

  // Non-manifold vertices: the triangles around a vertex, linked through the edges they share at
  // that vertex, must form a single fan.
  std::vector<std::int64_t> start(nPoints + 1, 0);
  for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
  {
    if (valid[t])
    {
      for (int k = 0; k < 3; ++k)
      {
        ++start[cage.Triangles[t][k] + 1];
      }
    }
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int> around(static_cast<std::size_t>(start[nPoints]));
  std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
  {
    if (valid[t])
    {
      for (int k = 0; k < 3; ++k)
      {
        around[fill[cage.Triangles[t][k]]++] = static_cast<int>(t);
      }
    }
  }
  std::vector<int> parent;
  std::vector<std::pair<int, int>> firstUse; // (other vertex, local triangle)
  for (std::size_t v = 0; v < nPoints; ++v)
  {
    const std::int64_t b = start[v], e = start[v + 1];
    if (e - b < 2)
    {
      continue;
    }
    const int n = static_cast<int>(e - b);
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
      while (parent[x] != x)
      {
        x = parent[x] = parent[parent[x]];
      }
      return x;
    };
    firstUse.clear();
    for (int i = 0; i < n; ++i)
    {
      const Triangle& tri = cage.Triangles[around[b + i]];
      for (int k = 0; k < 3; ++k)
      {
        const int w = tri[k];
        if (w == static_cast<int>(v))
        {
          continue;
        }
        auto it =
          std::find_if(firstUse.begin(), firstUse.end(), [w](const std::pair<int, int>& u) { return u.first == w; });
        if (it == firstUse.end())
        {
          firstUse.emplace_back(w, i);
        }
        else
        {
          const int x = find(i), y = find(it->second);
          parent[std::max(x, y)] = std::min(x, y);
        }
      }
    }
    int fans = 0;
    for (int i = 0; i < n; ++i)
    {
      fans += (find(i) == i) ? 1 : 0;
    }
    if (fans > 1)
    {
      ++report.NonManifoldVertices;
    }
  }
}

/// Counts the referenced input vertices that are not strictly inside the closed cage
/// (non-finite ones count as outside). `cageUsable`: the cage is a closed manifold without
/// degenerate triangles (otherwise inside is unknown and every vertex counts as outside).
/// `oneQueryPerComponent`: no cage triangle touches any input triangle, so each connected input
/// component lies in a single cell of the cage's complement and one exact query per component
/// decides for all of its vertices.
long long countOutside(const TriangleMesh& input, const TriangleMesh& cage, const std::vector<char>& cageValid,
  bool cageUsable, bool consistentOrientation, bool oneQueryPerComponent)
{
  const int nInput = static_cast<int>(input.Points.size());
  std::vector<char> referenced(input.Points.size(), 0);
  UnionFind components(input.Points.size());
  long long total = 0;
  for (const Triangle& tri : input.Triangles)
  {
    bool valid = true;
    for (int k = 0; k < 3; ++k)
    {
      const int v = tri[k];
      if (v < 0 || v >= nInput)
      {
        valid = false;
        continue;
      }
      valid = valid && input.Points[v].allFinite(); // only geometric triangles connect vertices
      if (!referenced[v])
      {
        referenced[v] = 1;
        ++total;
      }
    }
    if (valid)
    {
      components.unite(tri[0], tri[1]);
      components.unite(tri[1], tri[2]);
    }
  }
  if (!cageUsable)
  {
    return total;
  }

  using Mesh = CGAL::Surface_mesh<P3>;
  namespace PMP = CGAL::Polygon_mesh_processing;
  Mesh mesh;
  if (consistentOrientation)
  {
    // A closed, consistently oriented manifold (checked by id): add it face by face.
    mesh.reserve(static_cast<Mesh::size_type>(cage.Points.size()),
      static_cast<Mesh::size_type>(cage.Triangles.size() * 3 / 2), static_cast<Mesh::size_type>(cage.Triangles.size()));
    for (const Vec3& x : cage.Points)
    {
      mesh.add_vertex(P3(x[0], x[1], x[2]));
    }
    for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
    {
      const Triangle& tri = cage.Triangles[t];
      if (cageValid[t] &&
        mesh.add_face(Mesh::Vertex_index(tri[0]), Mesh::Vertex_index(tri[1]), Mesh::Vertex_index(tri[2])) ==
          Mesh::null_face())
      {
        return total;
      }
    }
  }
  else
  {
    // Side_of_triangle_mesh counts ray crossings, so orientation does not matter, but a halfedge
    // mesh needs a consistent one: orient the soup (fails for a non-orientable cage).
    std::vector<P3> points;
    points.reserve(cage.Points.size());
    for (const Vec3& x : cage.Points)
    {
      points.emplace_back(x[0], x[1], x[2]);
    }
    std::vector<std::array<std::size_t, 3>> polygons;
    for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
    {
      if (cageValid[t])
      {
        const Triangle& tri = cage.Triangles[t];
        polygons.push_back(
          { static_cast<std::size_t>(tri[0]), static_cast<std::size_t>(tri[1]), static_cast<std::size_t>(tri[2]) });
      }
    }
    PMP::orient_polygon_soup(points, polygons);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
    {
      return total;
    }
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  }
  if (mesh.number_of_faces() == 0 || !CGAL::is_closed(mesh) || !CGAL::is_triangle_mesh(mesh))
  {
    return total;
  }

  CGAL::Side_of_triangle_mesh<Mesh, K> side(mesh);
  auto outsideOf = [&](int v) {
    const Vec3& x = input.Points[v];
    return !x.allFinite() || side(P3(x[0], x[1], x[2])) != CGAL::ON_BOUNDED_SIDE;
  };
  long long outside = 0;
  if (!oneQueryPerComponent)
  {
    for (int v = 0; v < nInput; ++v)
    {
      outside += (referenced[v] && outsideOf(v)) ? 1 : 0;
    }
    return outside;
  }
  // Query one finite vertex per component; non-finite vertices always count.
  std::vector<signed char> verdict(input.Points.size(), -1); // per component root
  for (int v = 0; v < nInput; ++v)
  {
    if (!referenced[v])
    {
      continue;
    }
    if (!input.Points[v].allFinite())
    {
      ++outside;
      continue;
    }
    signed char& c = verdict[components.find(v)];
    if (c < 0)
    {
      c = outsideOf(v) ? 1 : 0;
    }
    outside += c;
  }
  return outside;
}

/// An upper bound of the cage/input clearance: the smallest distance from a cage vertex to an
/// input vertex (kd-tree). Any point pair bounds the minimum from above, and on fine meshes this
/// one is close to it, so the candidate search can use it instead of the (larger) query limit.
/// Only vertices of usable triangles count. Returns +infinity when either side has none.
double vertexDistanceUpperBound(const TriangleMesh& input, const std::vector<Primitive>& inputPrims,
  const TriangleMesh& cage, const std::vector<Primitive>& cagePrims)
{
  auto usedPoints = [](const TriangleMesh& mesh, const std::vector<Primitive>& prims) {
    std::vector<char> used(mesh.Points.size(), 0);
    std::vector<P3> points;
    for (std::size_t t = 0; t < prims.size(); ++t)
    {
      if (prims[t].Size == 0)
      {
        continue;
      }
      for (const int v : mesh.Triangles[t])
      {
        if (!used[v])
        {
          used[v] = 1;
          const Vec3& x = mesh.Points[v];
          points.emplace_back(x[0], x[1], x[2]);
        }
      }
    }
    return points;
  };
  const std::vector<P3> inputPoints = usedPoints(input, inputPrims);
  const std::vector<P3> cagePoints = usedPoints(cage, cagePrims);
  if (inputPoints.empty() || cagePoints.empty())
  {
    return std::numeric_limits<double>::infinity();
  }
  using Search = CGAL::Orthogonal_k_neighbor_search<CGAL::Search_traits_3<K>>;
  Search::Tree tree(inputPoints.begin(), inputPoints.end());
  double best2 = std::numeric_limits<double>::infinity();
  for (const P3& q : cagePoints)
  {
    Search search(tree, q, 1);
    best2 = std::min(best2, CGAL::to_double(search.begin()->second));
    if (best2 == 0.0)
    {
      break;
    }
  }
  return std::sqrt(best2);
}

} // namespace

ExactReport exactCheck(const TriangleMesh& input, const TriangleMesh& cage, double clearanceQueryLimit)
{
  const auto start = std::chrono::steady_clock::now();
  ExactReport report;
  report.CageTriangles = static_cast<long long>(cage.Triangles.size());
  report.InputTriangles = static_cast<long long>(input.Triangles.size());

  // --- primitives ---
  std::vector<Primitive> cagePrims(cage.Triangles.size());
  std::vector<char> cageValid(cage.Triangles.size(), 0);
  for (std::size_t t = 0; t < cage.Triangles.size(); ++t)
  {
    const Triangle& tri = cage.Triangles[t];
    cagePrims[t] = makePrimitive(cage, tri);
    if (cagePrims[t].Size == 0)
    {
      ++report.InvalidTriangles;
      // ids may still be valid (non-finite point): topology uses ids only when in range
      const int n = static_cast<int>(cage.Points.size());
      cageValid[t] = (tri[0] >= 0 && tri[0] < n && tri[1] >= 0 && tri[1] < n && tri[2] >= 0 && tri[2] < n) ? 1 : 0;
      continue;
    }
    cageValid[t] = 1;
    if (cagePrims[t].Size < 3)
    {
      ++report.DegenerateTriangles;
    }
  }
  std::vector<Primitive> inputPrims(input.Triangles.size());
  CGAL::Bbox_3 inputBox;
  for (std::size_t t = 0; t < input.Triangles.size(); ++t)
  {
    inputPrims[t] = makePrimitive(input, input.Triangles[t]);
    if (inputPrims[t].Size > 0)
    {
      inputBox += inputPrims[t].Box;
    }
  }

  auto lap = [last = start]() mutable {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last).count();
    last = now;
    return s;
  };

  // --- topology ---
  checkTopology(cage, cageValid, report);
  report.Closed2Manifold = !cage.Triangles.empty() && report.InvalidTriangles == 0 && report.BoundaryEdges == 0 &&
    report.NonManifoldEdges == 0 && report.NonManifoldVertices == 0;

  report.PhaseSeconds[0] = lap();

  // --- self-intersections ---
  report.SelfIntersections = report.DegenerateTriangles;
  {
    std::vector<Box> boxes;
    boxes.reserve(cagePrims.size());
    for (std::size_t t = 0; t < cagePrims.size(); ++t)
    {
      if (cagePrims[t].Size == 3)
      {
        boxes.emplace_back(cagePrims[t].Box, static_cast<int>(t));
      }
    }
    long long count = 0;
    CGAL::box_self_intersection_d(
      boxes.begin(), boxes.end(),
      [&](const Box& x, const Box& y) {
        const Triangle& ta = cage.Triangles[x.info()];
        const Triangle& tb = cage.Triangles[y.info()];
        const Primitive& a = cagePrims[x.info()];
        const Primitive& b = cagePrims[y.info()];
        const int shared = sharedIds(ta, tb);
        const bool hit =
          shared == 0 ? CGAL::do_intersect(a.triangle(), b.triangle()) : adjacentIntersect(ta, tb, a, b, shared);
        count += hit ? 1 : 0;
      },
      CGAL::Box_intersection_d::Box_traits_d<Box>(), kBoxCutoff);
    report.SelfIntersections += count;
  }

  report.PhaseSeconds[1] = lap();

  // --- cage/input intersections and clearance ---
  double limit = clearanceQueryLimit;
  if (!(limit > 0.0) || !std::isfinite(limit))
  {
    const double diagonal = std::sqrt(std::pow(inputBox.xmax() - inputBox.xmin(), 2) +
      std::pow(inputBox.ymax() - inputBox.ymin(), 2) + std::pow(inputBox.zmax() - inputBox.zmin(), 2));
    limit = (std::isfinite(diagonal) && diagonal > 0) ? 0.02 * diagonal : 1.0;
  }
  report.ClearanceQueryLimit = limit;
  {
    // Pairs farther apart than the smaller of the limit and a vertex-pair distance cannot hold
    // the minimum. Cage boxes grow by that (and a relative hair, so rounding cannot lose a pair).
    const double reach = std::min(limit, vertexDistanceUpperBound(input, inputPrims, cage, cagePrims));
    const double grow = reach * (1.0 + 1e-9);
    std::vector<Box> cageBoxes, inputBoxes;
    cageBoxes.reserve(cagePrims.size());
    for (std::size_t t = 0; t < cagePrims.size(); ++t)
    {
      if (cagePrims[t].Size > 0)
      {
        const CGAL::Bbox_3& b = cagePrims[t].Box;
        cageBoxes.emplace_back(CGAL::Bbox_3(b.xmin() - grow, b.ymin() - grow, b.zmin() - grow, b.xmax() + grow,
                                 b.ymax() + grow, b.zmax() + grow),
          static_cast<int>(t));
      }
    }
    inputBoxes.reserve(inputPrims.size());
    for (std::size_t t = 0; t < inputPrims.size(); ++t)
    {
      if (inputPrims[t].Size > 0)
      {
        inputBoxes.emplace_back(inputPrims[t].Box, static_cast<int>(t));
      }
    }
    const double limit2 = limit * limit;
    double best2 = grow * grow;
    bool found = false;
    long long hits = 0;
    CGAL::box_intersection_d(
      cageBoxes.begin(), cageBoxes.end(), inputBoxes.begin(), inputBoxes.end(),
      [&](const Box& x, const Box& y) {
        const Primitive& a = cagePrims[x.info()];
        const Primitive& b = inputPrims[y.info()];
        if (CGAL::do_overlap(a.Box, b.Box) && intersects(a, b))
        {
          ++hits;
          best2 = 0.0;
          found = true;
          return;
        }
        // Prune with lower bounds: the box distance (the factor absorbs its rounding) and the
        // two separating-plane distances.
        if (best2 == 0.0 || boxDistance2(a.Box, b.Box) * (1.0 - 1e-12) > best2)
        {
          return;
        }
        const double plane = std::max(planeBound(a, b), planeBound(b, a));
        if (plane * plane > best2)
        {
          return;
        }
        const double d2 = squaredDistanceDisjoint(a, b);
        if (d2 <= best2)
        {
          best2 = d2;
          found = true;
        }
      },
      CGAL::Box_intersection_d::Box_traits_d<Box>(), kBoxCutoff);
    report.InputIntersections = hits;
    found = found && best2 <= limit2;
    report.ClearanceIsLowerBound = !found;
    report.MinimumClearance = found ? std::sqrt(best2) : limit;
  }

  report.PhaseSeconds[2] = lap();

  // --- input vertices strictly inside ---
  report.InputVerticesOutside =
    countOutside(input, cage, cageValid, report.Closed2Manifold && report.DegenerateTriangles == 0,
      report.InconsistentEdges == 0, report.InputIntersections == 0);

  report.PhaseSeconds[3] = lap();

  report.Encloses = report.Closed2Manifold && report.SelfIntersections == 0 && report.InputIntersections == 0 &&
    report.InputVerticesOutside == 0;
  report.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

std::string toJson(const ExactReport& r)
{
  char buffer[2048];
  std::snprintf(buffer, sizeof(buffer),
    "{\"BoundaryEdges\": %lld, \"NonManifoldEdges\": %lld, \"NonManifoldVertices\": %lld, "
    "\"Closed2Manifold\": %s, \"SelfIntersections\": %lld, \"InputIntersections\": %lld, "
    "\"InputVerticesOutside\": %lld, \"MinimumClearance\": %.17g, "
    "\"ClearanceIsLowerBound\": %s, \"CageGenus\": %d, \"CageComponents\": %d, "
    "\"Encloses\": %s, \"DegenerateTriangles\": %lld, \"InconsistentEdges\": %lld, "
    "\"InvalidTriangles\": %lld, \"CageTriangles\": %lld, \"InputTriangles\": %lld, "
    "\"ClearanceQueryLimit\": %.17g, \"Seconds\": %.6f, \"PhaseSeconds\": [%.6f, %.6f, %.6f, %.6f]}",
    r.BoundaryEdges, r.NonManifoldEdges, r.NonManifoldVertices, r.Closed2Manifold ? "true" : "false",
    r.SelfIntersections, r.InputIntersections, r.InputVerticesOutside, r.MinimumClearance,
    r.ClearanceIsLowerBound ? "true" : "false", r.CageGenus, r.CageComponents, r.Encloses ? "true" : "false",
    r.DegenerateTriangles, r.InconsistentEdges, r.InvalidTriangles, r.CageTriangles, r.InputTriangles,
    r.ClearanceQueryLimit, r.Seconds, r.PhaseSeconds[0], r.PhaseSeconds[1], r.PhaseSeconds[2], r.PhaseSeconds[3]);
  return buffer;
}

} // namespace exact
} // namespace sdfcage
