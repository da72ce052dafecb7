#include "Mesh/Validation.h"
#include "Mesh/EdgeKey.h"

#include "Common/CancellableSort.h"
#include "Common/LargePages.h"
#include "Common/Progress.h"
#include "Spatial/Geometry.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace sdfcage
{

bool MeshDefects::usable() const
{
  return !Empty && NonFinitePoints == 0 && InvalidPointIds == 0 && UntriangulatedPolygons == 0 && BoundaryEdges == 0 &&
    NonManifoldEdges == 0 && NonManifoldVertices == 0 && DegenerateTriangles == 0 && InconsistentEdges == 0;
}

std::string MeshDefects::errorMessage() const
{
  std::ostringstream s;
  auto sep = [&]() {
    if (s.tellp() > 0)
    {
      s << "; ";
    }
  };
  if (Empty)
  {
    sep();
    s << "the mesh has no triangles";
  }
  if (NonFinitePoints)
  {
    sep();
    s << NonFinitePoints << " points have non-finite (NaN or infinite) coordinates: fix or remove them";
  }
  if (InvalidPointIds)
  {
    sep();
    s << InvalidPointIds << " cells reference points that do not exist: the file is corrupt";
  }
  if (UntriangulatedPolygons)
  {
    sep();
    s << UntriangulatedPolygons
      << " polygons are non-planar or non-convex and cannot be split safely: triangulate them first "
         "(e.g. vtkTriangleFilter / ParaView's Triangulate)";
  }
  if (BoundaryEdges)
  {
    sep();
    s << "the mesh has " << BoundaryEdges << " boundary edges (it is not closed)";
  }
  if (NonManifoldEdges)
  {
    sep();
    s << NonManifoldEdges << " non-manifold edges (shared by more than two triangles)";
  }
  if (NonManifoldVertices)
  {
    sep();
    s << NonManifoldVertices << " non-manifold vertices (surface sheets touching at a single point)";
  }
  if (DegenerateTriangles)
  {
    sep();
    s << DegenerateTriangles << " degenerate (zero-area) triangles";
  }
  if (InconsistentEdges)
  {
    sep();
    s << InconsistentEdges << " edges are used twice in the same direction (inconsistent orientation)";
  }
  std::string msg = s.str();
  if (!msg.empty())
  {
    msg = "Unusable mesh: " + msg + ".";
  }
  return msg;
}

std::string MeshDefects::inputErrorMessage() const
{
  std::string msg;
  auto add = [&](const std::string& part) { msg += (msg.empty() ? "" : "; ") + part; };
  if (NonFinitePoints)
  {
    add(std::to_string(NonFinitePoints) + " points have non-finite (NaN or infinite) coordinates: fix or remove them");
  }
  if (InvalidPointIds)
  {
    add(std::to_string(InvalidPointIds) + " cells reference points that do not exist: the file is corrupt");
  }
  if (Empty && msg.empty())
  {
    add(DroppedDegenerateTriangles > 0 ? "the mesh has no triangles with a non-zero area (" +
          std::to_string(DroppedDegenerateTriangles) + " degenerate ones)"
                                       : std::string("the mesh has no polygons (points or lines only, or nothing)"));
  }
  return msg.empty() ? msg : "Unusable input mesh: " + msg + ".";
}

std::vector<std::string> MeshDefects::warnings() const
{
  std::vector<std::string> w;
  if (MergedPoints)
  {
    w.push_back(std::to_string(MergedPoints) + " coincident points were merged (split seams or duplicated positions)");
  }
  if (TriangulatedPolygons)
  {
    w.push_back(std::to_string(TriangulatedPolygons) + " polygons were split into triangles");
  }
  if (DroppedDegenerateTriangles)
  {
    w.push_back(std::to_string(DroppedDegenerateTriangles) + " degenerate (zero-area) triangles were dropped");
  }
  if (DroppedDuplicateTriangles)
  {
    w.push_back(std::to_string(DroppedDuplicateTriangles) + " duplicated triangles were dropped");
  }
  if (BoundaryEdges || NonManifoldEdges || NonManifoldVertices || InconsistentEdges)
  {
    w.push_back("the mesh is not a closed, consistently oriented 2-manifold (" + std::to_string(BoundaryEdges) +
      " boundary edges, " + std::to_string(NonManifoldEdges) + " non-manifold edges, " +
      std::to_string(NonManifoldVertices) + " non-manifold vertices, " + std::to_string(InconsistentEdges) +
      " inconsistently oriented edges): it is caged all the same; SignMode says how its inside was decided");
  }
  if (IgnoredCells)
  {
    w.push_back(std::to_string(IgnoredCells) + " vertex/line cells were ignored (not surfaces)");
  }
  if (UnreferencedPoints)
  {
    w.push_back(std::to_string(UnreferencedPoints) + " points used by no triangle were dropped");
  }
  if (FlippedOrientation)
  {
    w.push_back("the mesh was oriented inward; its triangles were flipped to face outward");
  }
  return w;
}

namespace
{

// Fan-triangulates polygon ids (n >= 4) when it is planar and strictly convex. Returns false when
// that is not safe (the split would depend on a choice the input does not determine).
bool triangulateConvex(
  const std::vector<Vec3>& pts, const std::int64_t* ids, std::int64_t n, std::vector<Triangle>& out)
{
  Vec3 normal = Vec3::Zero(); // Newell normal
  Vec3 centroid = Vec3::Zero();
  double diameter = 0.0;
  for (std::int64_t i = 0; i < n; ++i)
  {
    const Vec3& a = pts[ids[i]];
    const Vec3& b = pts[ids[(i + 1) % n]];
    normal += a.cross(b);
    centroid += a;
    diameter = std::max(diameter, (b - a).norm());
  }
  centroid /= static_cast<double>(n);
  const double len = normal.norm();
  if (!(len > 0.0) || !(diameter > 0.0))
  {
    return false;
  }
  normal /= len;
  // planar within 1e-3 of the polygon's edge length
  for (std::int64_t i = 0; i < n; ++i)
  {
    if (std::abs((pts[ids[i]] - centroid).dot(normal)) > 1e-3 * diameter)
    {
      return false;
    }
  }
  // strictly convex: every corner turns the same way as the normal
  for (std::int64_t i = 0; i < n; ++i)
  {
    const Vec3& a = pts[ids[(i + n - 1) % n]];
    const Vec3& b = pts[ids[i]];
    const Vec3& c = pts[ids[(i + 1) % n]];
    if ((b - a).cross(c - b).dot(normal) <= 0.0)
    {
      return false;
    }
  }
  for (std::int64_t i = 1; i + 1 < n; ++i)
  {
    out.push_back({ static_cast<int>(ids[0]), static_cast<int>(ids[i]), static_cast<int>(ids[i + 1]) });
  }
  return true;
}

// Ear clipping of polygon ids (n >= 4) in the plane of its Newell normal; false when the
// polygon has no area or no ear can be found (self-overlapping outline).
bool triangulateEars(const std::vector<Vec3>& pts, const std::int64_t* ids, std::int64_t n, std::vector<Triangle>& out)
{
  Vec3 normal = Vec3::Zero();
  for (std::int64_t i = 0; i < n; ++i)
  {
    normal += pts[ids[i]].cross(pts[ids[(i + 1) % n]]);
  }
  if (!(normal.norm() > 0.0))
  {
    return false;
  }
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double orient = normal[axis] > 0 ? 1.0 : -1.0;
  std::vector<std::array<double, 2>> q(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i)
  {
    q[i] = { pts[ids[i]][u], pts[ids[i]][v] };
  }
  auto cross = [&](int a, int b, int c) {
    return orient * ((q[b][0] - q[a][0]) * (q[c][1] - q[a][1]) - (q[b][1] - q[a][1]) * (q[c][0] - q[a][0]));
  };
  std::vector<int> next(n), prev(n);
  for (int i = 0; i < n; ++i)
  {
    next[i] = static_cast<int>((i + 1) % n);
    prev[i] = static_cast<int>((i + n - 1) % n);
  }
  std::vector<Triangle> tris;
  int remaining = static_cast<int>(n);
  int i = 1; // the first ear tried is (0, 1, 2): a quad gets the same split as a fan

  int sinceLastEar = 0;
  while (remaining > 3)
  {
    const int a = prev[i], b = i, c = next[i];
    bool ear = cross(a, b, c) > 0.0;
    for (int k = next[c]; ear && k != a; k = next[k])
    {
      // a point of the outline inside (or on) the candidate ear blocks it
      ear = !(cross(a, b, k) >= 0.0 && cross(b, c, k) >= 0.0 && cross(c, a, k) >= 0.0);
    }
    if (ear)
    {
      tris.push_back({ static_cast<int>(ids[a]), static_cast<int>(ids[b]), static_cast<int>(ids[c]) });
      next[a] = c;
      prev[c] = a;
      --remaining;
      i = a;
      sinceLastEar = 0;
    }
    else
    {
      i = c;
      if (++sinceLastEar > remaining)
      {
        return false;
      }
    }
  }
  tris.push_back({ static_cast<int>(ids[prev[i]]), static_cast<int>(ids[i]), static_cast<int>(ids[next[i]]) });
  out.insert(out.end(), tris.begin(), tris.end());
  return true;
}

// Maps referenced points to the first earlier referenced point within `tol` (per coordinate),
// where at least one of the two is on a boundary edge (two points inside closed surfaces are never
// merged), on hashed grids of cells of size tol; returns the number of merged points.
std::int64_t mergeCoincidentPoints(const std::vector<Vec3>& pts, const std::vector<char>& referenced,
  const std::vector<char>& onBoundary, const Vec3& origin, double tol, std::vector<std::int64_t>& representative,
  Progress* progress)
{
  const std::size_t np = pts.size();
  representative.resize(np);
  std::iota(representative.begin(), representative.end(), 0);
  if (!(tol > 0.0))
  {
    return 0;
  }
  // cells counted from the box corner: at most diagonal / tol = 1e9 per axis, no overflow
  auto cell = [&](double x) { return static_cast<std::int64_t>(std::floor(x / tol)); };
  auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (static_cast<std::uint64_t>(x) * 73856093ULL) ^ (static_cast<std::uint64_t>(y) * 19349663ULL) ^
      (static_cast<std::uint64_t>(z) * 83492791ULL);
  };
  // Two grids of cells (all representatives, and those of them on a boundary edge): an
  // open-addressing table of cell keys, each cell a list in insertion order through `next`. A hash
  // map of vectors did the same with an allocation per cell (dragon_vrip's 437k points: 0.5 s).
  struct Grid
  {
    std::vector<std::uint64_t> Keys;
    std::vector<std::int64_t> Head, Tail, Next;
    std::uint64_t Mask = 0;
    Grid(std::size_t points, std::size_t capacity)
      : Next(points, -1)
    {
      std::size_t size = 16;
      while (size < 2 * capacity)
        size *= 2;
      ReserveLarge(Keys, size);
      Keys.assign(size, 0);
      ReserveLarge(Head, size);
      Head.assign(size, -1);
      ReserveLarge(Tail, size);
      Tail.assign(size, -1);
      Mask = size - 1;
    }
    std::size_t slot(std::uint64_t k) const
    {
      std::size_t h = static_cast<std::size_t>((k ^ (k >> 29)) * 0x9E3779B97F4A7C15ULL) & Mask;
      while (Head[h] >= 0 && Keys[h] != k)
        h = (h + 1) & Mask;
      return h;
    }
    std::int64_t first(std::uint64_t k) const { return Head[slot(k)]; }
    void add(std::uint64_t k, std::int64_t i)
    {
      const std::size_t h = slot(k);
      if (Head[h] < 0)
      {
        Keys[h] = k;
        Head[h] = i;
      }
      else
        Next[Tail[h]] = i;
      Tail[h] = i;
    }
  };
  std::size_t referencedCount = 0, boundaryCount = 0;
  for (std::size_t i = 0; i < np; ++i)
  {
    referencedCount += referenced[i] ? 1 : 0;
    boundaryCount += referenced[i] && onBoundary[i] ? 1 : 0;
  }
  Grid all(np, referencedCount), boundary(np, boundaryCount);
  auto search = [&](const Grid& grid, const Vec3& p, std::int64_t cx, std::int64_t cy, std::int64_t cz) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          for (std::int64_t j = grid.first(key(cx + dx, cy + dy, cz + dz)); j >= 0; j = grid.Next[j])
            if ((pts[j] - p).cwiseAbs().maxCoeff() <= tol)
              return j;
    return std::int64_t(-1);
  };
  std::int64_t merged = 0;
  for (std::size_t i = 0; i < np; ++i)
  {
    if ((i + 1) % (std::size_t(1) << 16) == 0 && progressCancelled(progress))
    {
      return merged; // the caller sees the cancel
    }
    if (!referenced[i])
    {
      continue;
    }
    const Vec3& p = pts[i];
    const Vec3 rel = p - origin;
    const std::int64_t cx = cell(rel.x()), cy = cell(rel.y()), cz = cell(rel.z());
    const std::int64_t found = search(onBoundary[i] ? all : boundary, p, cx, cy, cz);
    if (found >= 0)
    {
      representative[i] = found;
      ++merged;
      continue;
    }
    all.add(key(cx, cy, cz), static_cast<std::int64_t>(i));
    if (onBoundary[i])
    {
      boundary.add(key(cx, cy, cz), static_cast<std::int64_t>(i));
    }
  }
  return merged;
}

struct HalfEdge
{
  std::uint64_t Key; // undirected (min << 32 | max)
  int Face;
  bool Forward; // a < b in the triangle's order
};

} // namespace

namespace
{
/// Cells, triangles or vertices between two cancel checks of a loop over a whole mesh.
constexpr std::size_t CheckEvery = std::size_t(1) << 16;

/// One undirected edge by the triangles along it: one is a boundary, more than two make it
/// non-manifold, two that run it the same way make it inconsistent (`sameWay`: the first two).
void countEdge(
  std::size_t count, bool sameWay, std::int64_t& boundary, std::int64_t& nonManifold, std::int64_t& inconsistent)
{
  if (count == 1)
    ++boundary;
  else if (count > 2)
    ++nonManifold;
  else if (sameWay)
    ++inconsistent;
}

/// Edge classes by a sort of all half-edges: the general path (triangles with a repeated corner
/// included). False when `progress` was cancelled.
bool classifyEdgesBySort(const TriangleMesh& mesh, MeshDefects& d, Progress* progress)
{
  const std::size_t nf = mesh.Triangles.size();
  std::vector<HalfEdge> he;
  ReserveLarge(he, 3 * nf);
  for (std::size_t f = 0; f < nf; ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    for (int k = 0; k < 3; ++k)
    {
      const std::uint32_t a = static_cast<std::uint32_t>(t[k]);
      const std::uint32_t b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
      he.push_back({ edgeKey(t[k], t[(k + 1) % 3]), static_cast<int>(f), a < b });
    }
  }
  if (!cancellableSort(he, [](const HalfEdge& x, const HalfEdge& y) { return x.Key < y.Key; }, progress))
    return false;
  for (std::size_t i = 0; i < he.size();)
  {
    std::size_t j = i;
    while (j < he.size() && he[j].Key == he[i].Key)
    {
      ++j;
    }
    countEdge(j - i, j - i == 2 && he[i].Forward == he[i + 1].Forward, d.BoundaryEdges, d.NonManifoldEdges,
      d.InconsistentEdges);
    i = j;
  }
  return true;
}

/// Returns false when `progress` was cancelled (the counts are then incomplete).
///
/// Edges and vertices in one parallel pass over the vertices: each undirected edge (v, w), v < w,
/// is classified at v from the triangles around v (1 of them: boundary, more than 2: non-manifold,
/// 2 traversing it the same way: inconsistent), the fans around v counted from the same list. A
/// global sort of the 3F half-edges did the edges before (armadillo_midsub4x, 346k triangles:
/// checkTopology 0.13 -> 0.05 s). A mesh with a triangle that repeats a corner takes the sort.
bool checkTopology(const TriangleMesh& mesh, MeshDefects& d, Progress* progress = nullptr)
{
  const std::size_t nv = mesh.Points.size();
  bool repeated = false;
  for (const Triangle& t : mesh.Triangles)
    repeated = repeated || t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
  if (repeated && !classifyEdgesBySort(mesh, d, progress))
    return false;
  const bool edgesHere = !repeated;

  // Vertex manifoldness: the triangles around a vertex, linked through shared edges, must form one
  // fan. Count fans per vertex with a small union-find over the vertex's incident triangles.
  const PointTriangles incident(mesh);
  struct Counts
  {
    std::int64_t Boundary = 0, NonManifold = 0, Inconsistent = 0, NonManifoldVertices = 0;
    Counts operator+(const Counts& o) const
    {
      return { Boundary + o.Boundary, NonManifold + o.NonManifold, Inconsistent + o.Inconsistent,
        NonManifoldVertices + o.NonManifoldVertices };
    }
  };
  struct Around
  {
    int W;    // the other end of the edge
    int K;    // the triangle, by its index around v
    bool Out; // the triangle runs v -> W (else W -> v)
    bool operator<(const Around& o) const { return W != o.W ? W < o.W : K != o.K ? K < o.K : Out < o.Out; }
  };
  // the vertices in parallel ranges, each with its own scratch (the counts are sums)
  std::atomic<bool> stopped{ false };
  const Counts counts = tbb::parallel_reduce(
    tbb::blocked_range<std::size_t>(0, nv, 4096), Counts(),
    [&](const tbb::blocked_range<std::size_t>& r, Counts c) {
      if (stopped || progressCancelled(progress))
      {
        stopped = true;
        return c;
      }
      std::vector<int> parent;
      std::vector<Around> around;
      for (std::size_t v = r.begin(); v != r.end(); ++v)
      {
        const int n = static_cast<int>(incident.count(v));
        if (n == 0)
        {
          continue;
        }
        parent.resize(n);
        std::iota(parent.begin(), parent.end(), 0);
        around.clear();
        for (int k = 0; k < n; ++k)
        {
          const Triangle& t = mesh.Triangles[incident.Triangles[incident.First[v] + k]];
          for (int i = 0; i < 3; ++i)
          {
            // (a repeated corner's edge from v to itself links nothing)
            if (t[i] == static_cast<int>(v) && t[(i + 1) % 3] != static_cast<int>(v))
              around.push_back({ t[(i + 1) % 3], k, true });
            if (t[i] == static_cast<int>(v) && t[(i + 2) % 3] != static_cast<int>(v))
              around.push_back({ t[(i + 2) % 3], k, false });
          }
        }
        std::sort(around.begin(), around.end());
        auto root = [&](int x) {
          while (parent[x] != x)
          {
            parent[x] = parent[parent[x]];
            x = parent[x];
          }
          return x;
        };
        for (std::size_t i = 0; i < around.size();)
        {
          std::size_t j = i + 1;
          while (j < around.size() && around[j].W == around[i].W)
          {
            parent[root(around[j].K)] = root(around[i].K);
            ++j;
          }
          if (edgesHere && around[i].W > static_cast<int>(v))
            countEdge(
              j - i, j - i == 2 && around[i].Out == around[i + 1].Out, c.Boundary, c.NonManifold, c.Inconsistent);
          i = j;
        }
        int fans = 0;
        for (int k = 0; k < n; ++k)
        {
          fans += root(k) == k;
        }
        c.NonManifoldVertices += fans > 1 ? 1 : 0;
      }
      return c;
    },
    [](const Counts& a, const Counts& b) { return a + b; });
  d.BoundaryEdges += counts.Boundary;
  d.NonManifoldEdges += counts.NonManifold;
  d.InconsistentEdges += counts.Inconsistent;
  d.NonManifoldVertices += counts.NonManifoldVertices;
  return !stopped;
}
} // namespace

int closedManifoldGenus(const TriangleMesh& mesh, int components)
{
  // a closed 2-manifold has E = 3F/2: no sort of the edges is needed
  const long long f = static_cast<long long>(mesh.Triangles.size());
  const long long chi = usedVertexCount(mesh) - 3 * f / 2 + f;
  return static_cast<int>((2LL * components - chi) / 2);
}

MeshDefects checkTriangleMesh(const TriangleMesh& mesh)
{
  MeshDefects d;
  d.Empty = mesh.Triangles.empty();
  for (const Triangle& t : mesh.Triangles)
  {
    const Vec3 n = areaNormal(mesh, t);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || n.squaredNorm() == 0.0)
    {
      ++d.DegenerateTriangles;
    }
  }
  checkTopology(mesh, d);
  std::vector<int> comp;
  d.Components = triangleComponents(mesh, comp);
  if (d.usable())
  {
    // a closed 2-manifold: every edge has exactly two triangles, so E = 3F/2 and
    // chi = V - 3F/2 + F = 2 parts - 2 genus (genus() would sort the edges once more)
    const long long f = static_cast<long long>(mesh.Triangles.size());
    const long long chi = usedVertexCount(mesh) - f / 2;
    d.Genus = static_cast<int>((2LL * d.Components - chi) / 2);
  }
  return d;
}

/// Items grouped by point, for the per-point work of prepareMesh (written here: a counting sort
/// is a few lines, and it keeps the items' order within a group, which the duplicate rule needs).
/// `visitAll(emit)` calls emit(point, item) for every item, the same way each time (it is called
/// twice: count, then place). Then `each(point, begin, end)` runs on every point's group, the
/// points in parallel ranges; false when `progress` was cancelled.
template <typename T, typename VisitAll, typename Each>
bool forEachPointGroup(std::size_t points, const VisitAll& visitAll, Progress* progress, const Each& each)
{
  std::vector<std::size_t> first(points + 1, 0);
  visitAll([&](std::size_t point, const T&) { ++first[point + 1]; });
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<T> items(first.back());
  {
    std::vector<std::size_t> fill(first.begin(), first.end() - 1);
    visitAll([&](std::size_t point, const T& item) { items[fill[point]++] = item; });
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    if (progressCancelled(progress))
      return;
    for (std::size_t v = r.begin(); v != r.end(); ++v)
      each(v, items.begin() + static_cast<std::ptrdiff_t>(first[v]),
        items.begin() + static_cast<std::ptrdiff_t>(first[v + 1]));
  });
  return !progressCancelled(progress);
}

MeshDefects prepareMesh(
  const PolygonMesh& input, TriangleMesh& output, const ValidationOptions& options, Progress* progress)
{
  MeshDefects d;
  output = TriangleMesh();
  // a cancel answers between the steps (each a fraction of a second on a million triangles)
  const auto cancelled = [&]() {
    if (!progressCancelled(progress))
      return false;
    output = TriangleMesh();
    return true;
  };
  const std::int64_t np = static_cast<std::int64_t>(input.Points.size());
  const std::size_t nc = input.numberOfCells();

  // 1. which points the surface cells use; cells with invalid ids are counted (fatal)
  std::vector<char> referenced(np, 0);
  std::vector<char> cellValid(nc, 0);
  for (std::size_t c = 0; c < nc; ++c)
  {
    const std::int64_t b = input.Offsets[c], e = input.Offsets[c + 1];
    if (e - b < 3)
    {
      ++d.IgnoredCells;
      continue;
    }
    bool valid = true;
    for (std::int64_t k = b; k < e; ++k)
    {
      const std::int64_t id = input.Connectivity[k];
      valid = valid && id >= 0 && id < np;
    }
    if (!valid)
    {
      ++d.InvalidPointIds;
      continue;
    }
    cellValid[c] = 1;
    for (std::int64_t k = b; k < e; ++k)
    {
      referenced[input.Connectivity[k]] = 1;
    }
  }
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::int64_t i = 0; i < np; ++i)
  {
    if (!referenced[i])
    {
      ++d.UnreferencedPoints;
    }
    else if (!input.Points[i].allFinite())
    {
      ++d.NonFinitePoints;
    }
    else
    {
      lo = lo.cwiseMin(input.Points[i]);
      hi = hi.cwiseMax(input.Points[i]);
    }
  }
  if (d.NonFinitePoints || d.InvalidPointIds)
  {
    d.Empty = true;
    return d; // geometry cannot be trusted further
  }

  if (cancelled())
    return d;
  // 2. coincident points merged (split seams, STL facet corners, duplicated scan points) where
  // one of them is on a boundary edge of the cells as given: a split seam is closed again, while
  // two distinct points of a closed surface that happen to coincide stay apart (merging them
  // would make a non-manifold vertex). A mesh without boundary edges or zero-area triangles skips
  // this.
  std::vector<std::int64_t> rep;
  const double diagonal = (hi - lo).allFinite() ? (hi - lo).norm() : 0.0;
  d.MergeTolerance = options.MergeTolerance >= 0.0 ? options.MergeTolerance * diagonal : -1.0;
  {
    std::vector<char> onBoundary(np, 0);
    bool any = false;
    // the corners of zero-area triangles count too: a sliver between two coincident points hides
    // the seam it closes (dragon_vrip.ply has such)
    for (std::size_t c = 0; c < nc; ++c)
    {
      const std::int64_t b = input.Offsets[c];
      if (!cellValid[c] || input.Offsets[c + 1] - b != 3)
        continue;
      const Vec3& p0 = input.Points[input.Connectivity[b]];
      const Vec3& p1 = input.Points[input.Connectivity[b + 1]];
      const Vec3& p2 = input.Points[input.Connectivity[b + 2]];
      if ((p1 - p0).cross(p2 - p0).squaredNorm() == 0.0)
      {
        for (int k = 0; k < 3; ++k)
          onBoundary[input.Connectivity[b + k]] = 1;
        any = true;
      }
    }
    // Each cell edge at both ends: a point is on the boundary when one of its edges is there
    // once (a counting sort by point, then each point's few edges compared, in parallel, each
    // point writing only its own flag; a sort of all edges before: armadillo_midsub4x 0.075 s)
    const auto forEachEdgeEnd = [&](const auto& emit) {
      for (std::size_t c = 0; c < nc; ++c)
      {
        if (!cellValid[c])
          continue;
        const std::int64_t b = input.Offsets[c], e = input.Offsets[c + 1];
        for (std::int64_t k = b; k < e; ++k)
        {
          const std::int64_t u = input.Connectivity[k];
          const std::int64_t v = input.Connectivity[k + 1 < e ? k + 1 : b];
          if (u != v)
          {
            emit(static_cast<std::size_t>(u), v);
            emit(static_cast<std::size_t>(v), u);
          }
        }
      }
    };
    std::atomic<bool> anyEdge{ false };
    forEachPointGroup<std::int64_t>(
      static_cast<std::size_t>(np), forEachEdgeEnd, progress, [&](std::size_t v, auto b, auto e) {
        std::sort(b, e);
        for (auto i = b; i != e;)
        {
          auto j = i + 1;
          while (j != e && *j == *i)
            ++j;
          if (j - i == 1)
          {
            onBoundary[v] = 1;
            anyEdge.store(true, std::memory_order_relaxed);
            return;
          }
          i = j;
        }
      });
    any = any || anyEdge.load();
    if (cancelled())
      return d;
    d.MergedPoints =
      mergeCoincidentPoints(input.Points, referenced, onBoundary, lo, any ? d.MergeTolerance : -1.0, rep, progress);
  }
  if (cancelled())
    return d;
  auto id = [&](std::int64_t k) { return static_cast<int>(rep[input.Connectivity[k]]); };

  // 3. cells -> triangles: convex planar polygons by a fan (as before), others by ear clipping
  // in their plane, a fan when even that fails (a self-overlapping outline)
  ReserveLarge(output.Triangles, nc);
  std::vector<std::int64_t> ring;
  for (std::size_t c = 0; c < nc; ++c)
  {
    if (c % CheckEvery == 0 && cancelled())
      return d;
    if (!cellValid[c])
    {
      continue;
    }
    const std::int64_t b = input.Offsets[c], e = input.Offsets[c + 1];
    const std::int64_t n = e - b;
    if (n == 3)
    {
      output.Triangles.push_back({ id(b), id(b + 1), id(b + 2) });
      continue;
    }
    ring.clear();
    for (std::int64_t k = b; k < e; ++k)
    {
      if (ring.empty() || rep[input.Connectivity[k]] != ring.back())
      {
        ring.push_back(rep[input.Connectivity[k]]);
      }
    }
    while (ring.size() > 1 && ring.front() == ring.back())
    {
      ring.pop_back();
    }
    const std::int64_t m = static_cast<std::int64_t>(ring.size());
    ++d.TriangulatedPolygons;
    if (m < 3)
    {
      ++d.DroppedDegenerateTriangles;
      continue;
    }
    if (m == 3)
    {
      output.Triangles.push_back({ static_cast<int>(ring[0]), static_cast<int>(ring[1]), static_cast<int>(ring[2]) });
    }
    else if (!triangulateConvex(input.Points, ring.data(), m, output.Triangles) &&
      !triangulateEars(input.Points, ring.data(), m, output.Triangles))
    {
      for (std::int64_t k = 1; k + 1 < m; ++k)
      {
        output.Triangles.push_back(
          { static_cast<int>(ring[0]), static_cast<int>(ring[k]), static_cast<int>(ring[k + 1]) });
      }
    }
  }

  if (cancelled())
    return d;
  // 4. degenerate (area relative to the squared bounding-box diagonal) and duplicated triangles
  // dropped
  {
    const double tol = options.DegenerateAreaTolerance * diagonal * diagonal;
    std::vector<Triangle> kept;
    kept.reserve(output.Triangles.size());
    for (const Triangle& t : output.Triangles)
    {
      const Vec3 n = (input.Points[t[1]] - input.Points[t[0]]).cross(input.Points[t[2]] - input.Points[t[0]]);
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || 0.5 * n.norm() <= tol)
      {
        ++d.DroppedDegenerateTriangles;
      }
      else
      {
        kept.push_back(t);
      }
    }
    // duplicates: the same three points in any order (the first one is kept), grouped by their
    // smallest point (a counting sort) and compared within each group, in parallel (a sort of
    // all triangles before: armadillo_midsub4x 0.048 s)
    std::vector<std::array<int, 3>> corners(kept.size());
    for (std::size_t f = 0; f < kept.size(); ++f)
    {
      corners[f] = kept[f];
      std::sort(corners[f].begin(), corners[f].end());
    }
    std::vector<char> duplicate(kept.size(), 0);
    forEachPointGroup<int>(
      static_cast<std::size_t>(np),
      [&](const auto& emit) {
        for (std::size_t f = 0; f < kept.size(); ++f)
          emit(static_cast<std::size_t>(corners[f][0]), static_cast<int>(f));
      },
      progress,
      [&](std::size_t, auto b, auto e) {
        if (e - b < 2)
          return;
        std::sort(b, e, [&](int x, int y) { return corners[x] != corners[y] ? corners[x] < corners[y] : x < y; });
        for (auto i = b + 1; i < e; ++i)
          if (corners[*i] == corners[*(i - 1)])
            duplicate[*i] = 1;
      });
    if (cancelled())
      return d;
    for (const char dup : duplicate)
      d.DroppedDuplicateTriangles += dup ? 1 : 0;
    output.Triangles.clear();
    for (std::size_t f = 0; f < kept.size(); ++f)
    {
      if (!duplicate[f])
      {
        output.Triangles.push_back(kept[f]);
      }
    }
  }
  if (cancelled())
    return d;
  d.Empty = output.Triangles.empty();
  if (d.Empty)
  {
    return d;
  }
  output.Points = input.Points;
  removeUnreferencedPoints(output);
  d.UnreferencedPoints = static_cast<std::int64_t>(input.Points.size() - output.Points.size()) - d.MergedPoints;

  if (cancelled())
    return d;
  // 3. topology
  checkTopology(output, d, progress);
  if (cancelled())
    return d;
  std::vector<int> comp;
  d.Components = triangleComponents(output, comp);
  if (!d.closedManifold())
  {
    return d; // no orientation to fix, no genus: the winding number decides the inside
  }

  if (cancelled())
    return d;
  // 4. orientation per component: a component with negative volume faces inward, unless it is a
  // cavity inside another component (then inward is right).
  std::vector<double> volume(d.Components, 0.0);
  for (std::size_t f = 0; f < output.Triangles.size(); ++f)
  {
    const Triangle& t = output.Triangles[f];
    volume[comp[f]] += output.Points[t[0]].dot(output.Points[t[1]].cross(output.Points[t[2]])) / 6.0;
  }
  std::vector<char> flip(d.Components, 0);
  for (int c = 0; c < d.Components; ++c)
  {
    if (volume[c] >= 0.0)
    {
      continue;
    }
    if (cancelled())
      return d;
    bool nested = false;
    if (d.Components > 1)
    {
      // a point of component c, tested against each other component
      int someVertex = -1;
      for (std::size_t f = 0; f < output.Triangles.size() && someVertex < 0; ++f)
      {
        if (comp[f] == c)
        {
          someVertex = output.Triangles[f][0];
        }
      }
      for (int o = 0; o < d.Components && !nested; ++o)
      {
        if (o == c)
        {
          continue;
        }
        TriangleMesh other;
        other.Points = output.Points;
        for (std::size_t f = 0; f < output.Triangles.size(); ++f)
        {
          if (comp[f] == o)
          {
            other.Triangles.push_back(output.Triangles[f]);
          }
        }
        nested = std::abs(windingNumber(other, output.Points[someVertex])) > 0.5;
      }
    }
    if (!nested)
    {
      flip[c] = 1;
      d.FlippedOrientation = true;
    }
  }
  if (d.FlippedOrientation)
  {
    for (std::size_t f = 0; f < output.Triangles.size(); ++f)
    {
      if (flip[comp[f]])
      {
        std::swap(output.Triangles[f][1], output.Triangles[f][2]);
      }
    }
  }
  if (cancelled())
    return d;
  d.Genus = closedManifoldGenus(output, d.Components);
  return d;
}

} // namespace sdfcage
