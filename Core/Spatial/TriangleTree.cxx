#include "Spatial/TriangleTree.h"

#include "Common/LargePages.h"
#include "Common/Progress.h"
#include "Spatial/Geometry.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

namespace sdfcage
{

namespace
{
// Nodes of the subtree over `count` triangles (leaves of at most 4, halves by count).
int subtreeNodes(int count, int depth)
{
  if (count <= 4 || depth > 60)
  {
    return 1;
  }
  const int half = count / 2;
  return 1 + subtreeNodes(half, depth + 1) + subtreeNodes(count - half, depth + 1);
}
} // namespace

// Long triangles entered as pieces (build's splitLong): no piece edge longer than 1/32 of the
// mesh's bounding-box diagonal, by longest-edge bisection. At most as many extra pieces as
// triangles or 2^19, whichever is more (the length doubles until they fit): 20,000 random slivers
// across the unit sphere become some 300,000 entries, 60 MB. No library offers this: it is the
// tree's own leaf layout.
namespace
{
constexpr double SplitFraction = 1.0 / 32.0;
constexpr int SplitDepth = 20;

template <typename Emit>
void splitTriangle(const Vec3& a, const Vec3& b, const Vec3& c, double length2, int depth, Emit& emit)
{
  const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(), ca = (a - c).squaredNorm();
  const double m = std::max({ ab, bc, ca });
  if (m <= length2 || depth >= SplitDepth)
  {
    emit(a, b, c);
    return;
  }
  // the halves keep the triangle's orientation
  if (m == ab)
  {
    const Vec3 h = 0.5 * (a + b);
    splitTriangle(a, h, c, length2, depth + 1, emit);
    splitTriangle(h, b, c, length2, depth + 1, emit);
  }
  else if (m == bc)
  {
    const Vec3 h = 0.5 * (b + c);
    splitTriangle(a, b, h, length2, depth + 1, emit);
    splitTriangle(a, h, c, length2, depth + 1, emit);
  }
  else
  {
    const Vec3 h = 0.5 * (c + a);
    splitTriangle(a, b, h, length2, depth + 1, emit);
    splitTriangle(h, b, c, length2, depth + 1, emit);
  }
}

std::size_t pieceCount(const Vec3& a, const Vec3& b, const Vec3& c, double length2)
{
  std::size_t count = 0;
  auto emit = [&count](const Vec3&, const Vec3&, const Vec3&) { ++count; };
  splitTriangle(a, b, c, length2, 0, emit);
  return count;
}
} // namespace

double TriangleTree::pieceLayout(const TriangleMesh& mesh, std::vector<std::size_t>& first)
{
  first.clear();
  const std::size_t n = mesh.Triangles.size();
  if (n == 0)
  {
    return 0.0;
  }
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Triangle& t : mesh.Triangles)
    for (int k = 0; k < 3; ++k)
    {
      lo = lo.cwiseMin(mesh.Points[t[k]]);
      hi = hi.cwiseMax(mesh.Points[t[k]]);
    }
  const double length = SplitFraction * (hi - lo).norm();
  double length2 = length * length;
  const std::size_t extraCap = std::max<std::size_t>(n, std::size_t(1) << 19);
  first.assign(n + 1, 0);
  for (int round = 0; round < 64 && length2 > 0 && std::isfinite(length2); ++round, length2 *= 4.0)
  {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = mesh.Triangles[f];
        first[f + 1] = pieceCount(mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]], length2);
      }
    });
    first[0] = 0;
    for (std::size_t f = 0; f < n; ++f)
      first[f + 1] += first[f];
    if (first[n] - n <= extraCap)
      break;
  }
  if (!(length2 > 0) || !std::isfinite(length2) || first[n] - n > extraCap || first[n] == n)
  {
    first.clear(); // nothing long (or nothing sensible): whole triangles
    return 0.0;
  }
  return length2;
}

std::size_t TriangleTree::pieceBytes(const TriangleMesh& mesh)
{
  std::vector<std::size_t> first;
  if (!(pieceLayout(mesh, first) > 0.0))
  {
    return 0;
  }
  const std::size_t extra = first.back() - mesh.Triangles.size();
  // per entry: the whole triangle, the piece, the build item; the node count grows with the entries
  return extra * (sizeof(Tri3) + sizeof(Piece) + sizeof(BuildItem) + sizeof(Node) / 2);
}

void TriangleTree::build(const TriangleMesh& mesh)
{
  this->build(mesh, nullptr);
}

bool TriangleTree::build(const TriangleMesh& mesh, Progress* progress, bool splitLong)
{
  Nodes.clear();
  QueryNodes.clear();
  Root = { 0, 0 };
  Dipoles.clear();
  Tri.clear();
  Pieces.clear();
  SplitTriangles = 0;
  Normals.clear();
  const std::size_t n = mesh.Triangles.size();
  if (n == 0)
  {
    return !progressCancelled(progress);
  }
  // The large arrays are filled right after they are made: huge pages spare most of their page
  // faults (Common/LargePages.h). Tri3 entries are made once, in the tree's order, after the
  // build: the build itself reads the corners from the mesh (a whole copy of the triangles before
  // the build, then a second one in the tree's order, faulted 140 MB on an 871k-face scan).
  ReserveLarge(Normals, n);
  Normals.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    if (progressCancelled(progress))
      return;
    for (std::size_t f = r.begin(); f != r.end(); ++f)
    {
      const Triangle& t = mesh.Triangles[f];
      const Vec3 nrm = areaNormal(mesh, t);
      Normals[f] = nrm.norm() > 0 ? Vec3(nrm.normalized()) : Vec3(Vec3::Zero());
    }
  });
  auto wholeTriangle = [&mesh](std::size_t f) {
    Tri3 e;
    const Triangle& t = mesh.Triangles[f];
    for (int k = 0; k < 3; ++k)
    {
      e.P[k] = mesh.Points[t[k]];
    }
    e.Id = static_cast<int>(f);
    return e;
  };
  // the pieces of long triangles: counted first (the length grows until they fit), then made
  std::vector<std::size_t> first; // entries of triangle f: [first[f], first[f + 1])
  const double length2 = splitLong && !progressCancelled(progress) ? pieceLayout(mesh, first) : 0.0;
  const std::size_t m = first.empty() ? n : first[n];
  std::vector<Tri3> entries; // per entry when triangles are split (else the corners come from the mesh)
  std::vector<Piece> pieces;
  std::vector<BuildItem> items;
  ReserveLarge(items, m);
  items.resize(m);
  if (first.empty())
  {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = mesh.Triangles[f];
        items[f] = { (mesh.Points[t[0]] + mesh.Points[t[1]] + mesh.Points[t[2]]) / 3.0, static_cast<int>(f) };
      }
    });
  }
  else
  {
    entries.resize(m);
    pieces.resize(m);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
      if (progressCancelled(progress))
        return;
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Tri3 whole = wholeTriangle(f);
        const Vec3* P = whole.P;
        const double pad = 1e-9 * std::sqrt(std::max(
          { (P[1] - P[0]).squaredNorm(), (P[2] - P[1]).squaredNorm(), (P[0] - P[2]).squaredNorm() }));
        std::size_t e = first[f];
        auto emit = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
          entries[e] = whole;
          Piece& q = pieces[e];
          q.P[0] = a;
          q.P[1] = b;
          q.P[2] = c;
          q.Lo = a.cwiseMin(b).cwiseMin(c) - Vec3::Constant(pad);
          q.Hi = a.cwiseMax(b).cwiseMax(c) + Vec3::Constant(pad);
          items[e] = { (a + b + c) / 3.0, static_cast<int>(e) };
          ++e;
        };
        splitTriangle(P[0], P[1], P[2], length2, 0, emit);
      }
    });
    for (std::size_t f = 0; f < n; ++f)
    {
      SplitTriangles += first[f + 1] - first[f] > 1 ? 1 : 0;
    }
  }
  if (m > static_cast<std::size_t>(std::numeric_limits<int>::max() / 4))
  {
    Nodes.clear();
    Normals.clear();
    return false; // beyond the int indices (the memory budget stops inputs long before)
  }
  // The node layout is fixed in advance (pre-order, sizes known from the counts), so subtrees
  // are built in parallel into their own ranges and the tree does not depend on the threads.
  const std::size_t nodeCount = static_cast<std::size_t>(subtreeNodes(static_cast<int>(m), 0));
  ReserveLarge(Nodes, nodeCount);
  Nodes.resize(nodeCount);
  if (!progressCancelled(progress))
  {
    buildNode(0, 0, static_cast<int>(m), items, mesh, pieces, 0, progress);
  }
  if (progressCancelled(progress))
  {
    Nodes.clear(); // some subtrees were skipped: nothing of it may be used
    QueryNodes.clear();
    Normals.clear();
    SplitTriangles = 0;
    return false;
  }
  ReserveLarge(Tri, m);
  Tri.resize(m);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
    {
      const std::size_t id = static_cast<std::size_t>(items[i].Id);
      Tri[i] = entries.empty() ? wholeTriangle(id) : entries[id];
    }
  });
  if (!pieces.empty())
  {
    Pieces.resize(m);
    for (std::size_t i = 0; i < m; ++i)
    {
      Pieces[i] = pieces[items[i].Id];
    }
  }
  this->buildQueryNodes();
  return true;
}

namespace
{
// float bounds of a double coordinate: never above (down) or below (up) it
float roundDown(double v)
{
  float f = static_cast<float>(v);
  if (static_cast<double>(f) > v)
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float roundUp(double v)
{
  float f = static_cast<float>(v);
  if (static_cast<double>(f) < v)
    f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}
} // namespace

// Asks the memory for a child's data as soon as it is pushed, so that the miss overlaps the work
// on the entries above it (the tree of a large scan does not fit in the caches, and the queries
// of the simplification come in no spatial order).
inline void TriangleTree::prefetch(const Ref& r) const
{
#if defined(__GNUC__)
  if (r.Count == 0)
  {
    const char* node = reinterpret_cast<const char*>(&QueryNodes[static_cast<std::size_t>(r.Child)]);
    __builtin_prefetch(node);
    __builtin_prefetch(node + 64);
  }
  else
  {
    const char* first = reinterpret_cast<const char*>(&Tri[static_cast<std::size_t>(r.Child)]);
    const std::size_t bytes = sizeof(Tri3) * static_cast<std::size_t>(std::min(r.Count, 4));
    for (std::size_t b = 0; b < bytes; b += 64)
      __builtin_prefetch(first + b);
  }
#else
  (void)r;
#endif
}

void TriangleTree::buildQueryNodes()
{
  QueryNodes.clear();
  // Nodes are in pre-order: numbering the internal ones in index order keeps it (a node's left
  // child, when internal, is the next query node)
  std::vector<int> queryIndex(Nodes.size(), -1);
  int internal = 0;
  for (std::size_t i = 0; i < Nodes.size(); ++i)
    if (Nodes[i].Left >= 0)
      queryIndex[i] = internal++;
  ReserveLarge(QueryNodes, static_cast<std::size_t>(internal));
  QueryNodes.resize(static_cast<std::size_t>(internal));
  auto ref = [&](int node) {
    const Node& n = Nodes[node];
    return n.Left >= 0 ? Ref{ queryIndex[node], 0 } : Ref{ n.Start, n.Count };
  };
  Root = Nodes.empty() ? Ref{ 0, 0 } : ref(0);
  // each node's entries in Tri (pre-order: a subtree's leaves are one range, children after
  // their parent), for the slabs
  std::vector<int> first(Nodes.size()), count(Nodes.size());
  double scale = 0.0;
  for (std::size_t i = Nodes.size(); i-- > 0;)
  {
    const Node& n = Nodes[i];
    first[i] = n.Left >= 0 ? first[static_cast<std::size_t>(n.Left)] : n.Start;
    count[i] =
      n.Left >= 0 ? count[static_cast<std::size_t>(n.Left)] + count[static_cast<std::size_t>(n.Right)] : n.Count;
  }
  if (!Nodes.empty())
  {
    scale = Nodes[0].Lo.cwiseAbs().cwiseMax(Nodes[0].Hi.cwiseAbs()).maxCoeff();
  }
  // a dot product of a direction of norm <= 1 with coordinates up to `scale` rounds by less than
  // 3 ulp of `scale` (in doubles); the margin is far above that
  SlabMargin = 1e-13 * scale;
  // Slabs for subtrees of at most this many entries: larger ones span curved surface, where the
  // slab is no thinner than the box (and making them would visit each entry at every level).
  constexpr int SlabEntries = 4096;
  auto makeSlab = [&](int node, QueryNode& q, int c) {
    const float inf = std::numeric_limits<float>::infinity();
    q.Normal[c][0] = q.Normal[c][1] = q.Normal[c][2] = 0.0f;
    q.SlabLo[c] = -inf;
    q.SlabHi[c] = inf;
    const int n = count[static_cast<std::size_t>(node)];
    if (n > SlabEntries)
      return;
    const int begin = first[static_cast<std::size_t>(node)];
    Vec3 sum = Vec3::Zero();
    for (int i = begin; i < begin + n; ++i)
    {
      const Vec3* P = Tri[static_cast<std::size_t>(i)].P;
      sum += (P[1] - P[0]).cross(P[2] - P[0]);
    }
    const double len = sum.norm();
    if (!(len > 0.0) || !std::isfinite(len))
      return;
    // shortened a little so that the float direction's norm stays below 1: a range gap along it
    // is then a lower bound of the distance
    const Vec3 m = sum * ((1.0 - 1e-6) / len);
    for (int a = 0; a < 3; ++a)
      q.Normal[c][a] = static_cast<float>(m[a]);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int i = begin; i < begin + n; ++i)
      for (const Vec3& p : Tri[static_cast<std::size_t>(i)].P)
      {
        const double v = along(q, c, p);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    q.SlabLo[c] = roundDown(lo);
    q.SlabHi[c] = roundUp(hi);
  };
  tbb::parallel_for(
    tbb::blocked_range<std::size_t>(0, Nodes.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
      {
        const Node& n = Nodes[i];
        if (n.Left < 0)
          continue;
        QueryNode& q = QueryNodes[static_cast<std::size_t>(queryIndex[i])];
        const int children[2] = { n.Left, n.Right };
        for (int c = 0; c < 2; ++c)
        {
          const Node& child = Nodes[children[c]];
          for (int a = 0; a < 3; ++a)
          {
            q.Lo[c][a] = roundDown(child.Lo[a]);
            q.Hi[c][a] = roundUp(child.Hi[a]);
          }
          const Ref r2 = ref(children[c]);
          q.Child[c] = r2.Child;
          q.Count[c] = r2.Count;
          makeSlab(children[c], q, c);
        }
      }
    });
}

void TriangleTree::buildNode(int index, int start, int count, std::vector<BuildItem>& items, const TriangleMesh& mesh,
  const std::vector<Piece>& pieces, int depth, Progress* progress)
{
  if (count > 8192 && progressCancelled(progress))
  {
    return; // build() clears the tree
  }
  Node& node = Nodes[index];
  if (count <= 4 || depth > 60)
  {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int i = start; i < start + count; ++i)
    {
      if (!pieces.empty())
      {
        lo = lo.cwiseMin(pieces[items[i].Id].Lo);
        hi = hi.cwiseMax(pieces[items[i].Id].Hi);
        continue;
      }
      for (const int corner : mesh.Triangles[static_cast<std::size_t>(items[i].Id)])
      {
        lo = lo.cwiseMin(mesh.Points[static_cast<std::size_t>(corner)]);
        hi = hi.cwiseMax(mesh.Points[static_cast<std::size_t>(corner)]);
      }
    }
    node.Lo = lo;
    node.Hi = hi;
    node.Start = start;
    node.Count = count;
    return;
  }
  Vec3 clo = Vec3::Constant(std::numeric_limits<double>::infinity()), chi = -clo;
  for (int i = start; i < start + count; ++i)
  {
    clo = clo.cwiseMin(items[i].C);
    chi = chi.cwiseMax(items[i].C);
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int half = count / 2;
  // median split by the centroid coordinate (ties by id, so the split is deterministic)
  std::nth_element(items.begin() + start, items.begin() + start + half, items.begin() + start + count,
    [axis](const BuildItem& a, const BuildItem& b) {
      const double ca = a.C[axis], cb = b.C[axis];
      return ca < cb || (ca == cb && a.Id < b.Id);
    });
  const int left = index + 1;
  const int right = left + subtreeNodes(half, depth + 1);
  node.Left = left;
  node.Right = right;
  auto buildLeft = [&] { buildNode(left, start, half, items, mesh, pieces, depth + 1, progress); };
  auto buildRight = [&] { buildNode(right, start + half, count - half, items, mesh, pieces, depth + 1, progress); };
  if (count > 8192)
  {
    tbb::parallel_invoke(buildLeft, buildRight);
  }
  else
  {
    buildLeft();
    buildRight();
  }
  // the box from the children's
  Nodes[index].Lo = Nodes[left].Lo.cwiseMin(Nodes[right].Lo);
  Nodes[index].Hi = Nodes[left].Hi.cwiseMax(Nodes[right].Hi);
}

namespace
{
double boxPointDistance2(const Vec3& lo, const Vec3& hi, const Vec3& p)
{
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
}
double boxBoxDistance2(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi)
{
  return (alo - bhi).cwiseMax(blo - ahi).cwiseMax(0.0).squaredNorm();
}
} // namespace

bool TriangleTree::closestPoint(const Vec3& p, double maxDistance, Vec3& closest, int& triangle, double& distance) const
{
  triangle = -1;
  if (Nodes.empty())
  {
    return false;
  }
  double best2 = maxDistance < 0 ? std::numeric_limits<double>::infinity() : maxDistance * maxDistance;
  const double margin = this->slabMargin(p.cwiseAbs().maxCoeff());
  // Each entry keeps its box distance, measured when its parent was opened: popped nodes are
  // tested against the current best without measuring again.
  struct Pending
  {
    Ref R;
    double D2;
  };
  Pending stack[128];
  int top = 0;
  stack[top++] = { Root, boxPointDistance2(Nodes[0].Lo, Nodes[0].Hi, p) };
  while (top)
  {
    const Pending e = stack[--top];
    if (e.D2 > best2)
    {
      continue;
    }
    if (e.R.Count > 0)
    {
      for (int i = e.R.Child; i < e.R.Child + e.R.Count; ++i)
      {
        const Vec3* P = Tri[i].P;
        // the triangle's own box first: nothing in it is nearer than the box (the margin keeps
        // rounding in the closest point from ever making this skip a triangle it would take). A
        // piece's box: the piece holding the triangle's closest point is not skipped.
        const bool piece = !Pieces.empty();
        const Vec3 lo = piece ? Pieces[i].Lo : Vec3(P[0].cwiseMin(P[1]).cwiseMin(P[2]));
        const Vec3 hi = piece ? Pieces[i].Hi : Vec3(P[0].cwiseMax(P[1]).cwiseMax(P[2]));
        if (boxPointDistance2(lo, hi, p) > best2 * (1.0 + 1e-9))
        {
          continue;
        }
        const Vec3 q = closestPointOnTriangle(p, P[0], P[1], P[2]);
        const double d2 = (q - p).squaredNorm();
        if (d2 < best2 || (triangle < 0 && d2 <= best2))
        {
          best2 = d2;
          closest = q;
          triangle = Tri[i].Id;
        }
      }
      continue;
    }
    // visit the nearer child first (pushed last)
    const QueryNode& n = QueryNodes[static_cast<std::size_t>(e.R.Child)];
    const double dl = boxPointDistance2(childLo(n, 0), childHi(n, 0), p);
    const double dr = boxPointDistance2(childLo(n, 1), childHi(n, 1), p);
    // the order is the boxes' (as without slabs, so that ties between equally near triangles
    // resolve the same); a slab only prunes
    auto slab2 = [&](int c) {
      const double a = along(n, c, p);
      const double g = slabGap(n, c, a, a, margin);
      return g > 0 ? g * g : 0.0;
    };
    const Pending left{ { n.Child[0], n.Count[0] }, std::max(dl, slab2(0)) },
      right{ { n.Child[1], n.Count[1] }, std::max(dr, slab2(1)) };
    for (const Pending& q : { dl < dr ? right : left, dl < dr ? left : right })
      if (q.D2 <= best2)
      {
        this->prefetch(q.R);
        stack[top++] = q;
      }
  }
  if (triangle < 0)
  {
    return false;
  }
  distance = std::sqrt(best2);
  return true;
}

double distanceBetweenParts(const TriangleMesh& mesh, double limit)
{
  std::vector<int> component;
  const int parts = triangleComponents(mesh, component);
  return distanceBetweenParts(mesh, limit, component, parts);
}

double distanceBetweenParts(const TriangleMesh& mesh, double limit, const std::vector<int>& component, int parts)
{
  double gap = limit;
  for (int c = 0; c + 1 < parts; ++c)
  {
    // the triangles of part c against those of the later parts
    TriangleMesh others;
    others.Points = mesh.Points;
    for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
      if (component[f] > c)
        others.Triangles.push_back(mesh.Triangles[f]);
    const TriangleTree tree(others);
    std::vector<int> near;
    for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
    {
      if (component[f] != c)
        continue;
      const Triangle& t = mesh.Triangles[f];
      const Vec3 a[3] = { mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]] };
      near.clear();
      tree.trianglesWithin(a, gap, near);
      for (int g : near)
      {
        const Triangle& u = others.Triangles[g];
        const Vec3 b[3] = { mesh.Points[u[0]], mesh.Points[u[1]], mesh.Points[u[2]] };
        gap = std::min(gap, std::sqrt(triangleTriangleDistance2(a, b)));
      }
    }
  }
  return gap;
}

double TriangleTree::distance(const Vec3& p) const
{
  Vec3 q;
  int t;
  double d = std::numeric_limits<double>::infinity();
  this->closestPoint(p, -1.0, q, t, d);
  return d;
}

namespace
{
/// Is triangle `t` at least `gap` from triangle `o` by o's plane or one of o's three side planes
/// (through an edge, containing o's normal, facing out)? A sufficient test, cheap next to the
/// exact triangle-triangle distance.
bool separatedFromTriangle(const Vec3 o[3], const Vec3 t[3], double gap)
{
  const Vec3 n = (o[1] - o[0]).cross(o[2] - o[0]);
  const double len = n.norm();
  if (!(len > 0))
  {
    return false;
  }
  const Vec3 u = n / len;
  const double p0 = u.dot(o[0]);
  const double s0 = u.dot(t[0]) - p0, s1 = u.dot(t[1]) - p0, s2 = u.dot(t[2]) - p0;
  if (std::min({ s0, s1, s2 }) >= gap || std::max({ s0, s1, s2 }) <= -gap)
  {
    return true;
  }
  for (int k = 0; k < 3; ++k)
  {
    const Vec3 m = (o[(k + 1) % 3] - o[k]).cross(u);
    const double ml = m.norm();
    if (!(ml > 0))
    {
      continue;
    }
    // the offset includes o's own corners (rounding on slivers), as for the query's side planes
    const double off = std::max({ m.dot(o[0]), m.dot(o[1]), m.dot(o[2]) });
    if (std::min({ m.dot(t[0]), m.dot(t[1]), m.dot(t[2]) }) - off >= gap * ml)
    {
      return true;
    }
  }
  return false;
}
} // namespace

// The query triangle's bounds that both triangle walks test: its box, its plane and its three
// side planes (through an edge, containing the normal, facing out). The triangle lies on the inner
// side of each, so anything at least d beyond one of them is at least d from the triangle.
struct TriangleTree::QueryTriangle
{
  const Vec3* T = nullptr;
  Vec3 Lo, Hi, Normal, Side[3];
  double Offset = 0.0, SideOffset[3] = { 0.0, 0.0, 0.0 }, Margin = 0.0;
  bool HasPlane = false;

  QueryTriangle() = default;
  QueryTriangle(const Vec3 t[3], const TriangleTree& tree) { this->set(t, tree); }
  void set(const Vec3 t[3], const TriangleTree& tree)
  {
    T = t;
    Lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
    Hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    Normal = (t[1] - t[0]).cross(t[2] - t[0]);
    Margin = tree.slabMargin(Lo.cwiseAbs().cwiseMax(Hi.cwiseAbs()).maxCoeff());
    Offset = 0.0;
    const double nlen = Normal.norm();
    HasPlane = nlen > 0.0;
    if (!HasPlane)
    {
      return;
    }
    Normal /= nlen;
    Offset = Normal.dot(t[0]);
    for (int k = 0; k < 3; ++k)
    {
      Side[k] = (t[(k + 1) % 3] - t[k]).cross(Normal);
      const double len = Side[k].norm();
      Side[k] = len > 0 ? Vec3(Side[k] / len) : Vec3(Vec3::Zero());
      // the offset includes the query's own corners, so the triangle is on the inner side even
      // when its rounded normal is slightly off (slivers)
      SideOffset[k] = std::max({ Side[k].dot(t[0]), Side[k].dot(t[1]), Side[k].dot(t[2]) });
    }
  }
  double box2(const Vec3& lo, const Vec3& hi) const { return boxBoxDistance2(lo, hi, Lo, Hi); }
  // lower bound of the distance to the box [lo, hi] by the plane and the side planes (>= 0)
  double planeGap(const Vec3& lo, const Vec3& hi) const
  {
    if (!HasPlane)
    {
      return 0.0;
    }
    const Vec3 c = 0.5 * (lo + hi), e = 0.5 * (hi - lo);
    const double s = Normal.dot(c) - Offset;
    const double r = std::abs(Normal.x()) * e.x() + std::abs(Normal.y()) * e.y() + std::abs(Normal.z()) * e.z();
    double gap = std::abs(s) - r;
    for (int k = 0; k < 3; ++k)
    {
      const Vec3& m = Side[k];
      const double below = m.dot(c) - std::abs(m.x()) * e.x() - std::abs(m.y()) * e.y() - std::abs(m.z()) * e.z();
      gap = std::max(gap, below - SideOffset[k]);
    }
    return std::max(0.0, gap);
  }
  // lower bound of the distance to child c of node n by its slab
  double slabGap(const TriangleTree& tree, const QueryNode& n, int c) const
  {
    const double a0 = tree.along(n, c, T[0]), a1 = tree.along(n, c, T[1]), a2 = tree.along(n, c, T[2]);
    return tree.slabGap(n, c, std::min({ a0, a1, a2 }), std::max({ a0, a1, a2 }), Margin);
  }
  // is triangle o at least d beyond the plane (either side) or beyond one of the side planes?
  bool separates(const Vec3 o[3], double d) const
  {
    if (!HasPlane)
    {
      return false;
    }
    const double s0 = Normal.dot(o[0]) - Offset, s1 = Normal.dot(o[1]) - Offset, s2 = Normal.dot(o[2]) - Offset;
    if (std::min({ s0, s1, s2 }) >= d || std::max({ s0, s1, s2 }) <= -d)
    {
      return true;
    }
    for (int k = 0; k < 3; ++k)
    {
      if (std::min({ Side[k].dot(o[0]), Side[k].dot(o[1]), Side[k].dot(o[2]) }) - SideOffset[k] >= d)
      {
        return true;
      }
    }
    return false;
  }
  // may the exact test of o find it closer than d? (o's piece box, the query's planes, o's planes)
  bool leafMayBeCloser(const TriangleTree& tree, int entry, double d) const
  {
    // a piece whose box is beyond d: the triangle's nearest point lies in another piece
    if (!tree.Pieces.empty() && box2(tree.Pieces[entry].Lo, tree.Pieces[entry].Hi) >= d * d)
    {
      return false;
    }
    const Vec3* o = tree.Tri[entry].P;
    // the same two tests from the other side: the query beyond the input triangle's plane or
    // beyond one of its side planes by d (about 40% of the exact distances dragon_quartet's
    // queries computed end there)
    return !separates(o, d) && !separatedFromTriangle(o, T, d);
  }
};

double TriangleTree::triangleQuery(const Vec3 t[3], double limit, bool stopAtFirst, std::vector<int>* within) const
{
  if (Nodes.empty())
  {
    return limit;
  }
  const QueryTriangle q(t, *this);
  double best = limit;
  // Each entry keeps its two lower bounds (box distance squared, plane gap), measured when its
  // parent was opened and tested again when popped, as `best` may have shrunk meanwhile.
  struct Pending
  {
    Ref R;
    double Box2;
    double Gap;
  };
  auto far = [&best](double box2, double gap) { return box2 >= best * best || gap >= best; };
  Pending stack[128];
  int top = 0;
  stack[top++] = { Root, q.box2(Nodes[0].Lo, Nodes[0].Hi), q.planeGap(Nodes[0].Lo, Nodes[0].Hi) };
  while (top)
  {
    const Pending e = stack[--top];
    if (far(e.Box2, e.Gap))
    {
      continue;
    }
    if (e.R.Count == 0)
    {
      const QueryNode& n = QueryNodes[static_cast<std::size_t>(e.R.Child)];
      for (int c = 0; c < 2; ++c)
      {
        const Vec3 lo = childLo(n, c), hi = childHi(n, c);
        const double box2 = q.box2(lo, hi);
        if (box2 >= best * best)
          continue;
        double gap = q.planeGap(lo, hi);
        if (gap < best)
        {
          gap = std::max(gap, q.slabGap(*this, n, c));
        }
        if (gap < best)
        {
          stack[top++] = { { n.Child[c], n.Count[c] }, box2, gap };
          this->prefetch(stack[top - 1].R);
        }
      }
      continue;
    }
    for (int i = e.R.Child; i < e.R.Child + e.R.Count; ++i)
    {
      if (!q.leafMayBeCloser(*this, i, best))
      {
        continue;
      }
      const Tri3& o = Tri[i];
      if (within || stopAtFirst)
      {
        // only "closer than the limit?" is asked (the limit never shrinks): answered without the
        // exact distance; `within` collects every such triangle, stopAtFirst ends at the first
        if (trianglesCloserThan(t, o.P, best))
        {
          if (!within)
          {
            return 0.0;
          }
          within->push_back(o.Id);
        }
        continue;
      }
      const double d = std::sqrt(triangleTriangleDistance2(t, o.P));
      if (d < best)
      {
        best = d;
      }
    }
  }
  return best;
}

double TriangleTree::triangleDistance(const Vec3 t[3], double limit) const
{
  return this->triangleQuery(t, limit, false);
}

bool TriangleTree::anyCloserThan(const Vec3 t[3], double delta) const
{
  return this->triangleQuery(t, delta, true) < delta;
}

bool TriangleTree::anyCloserThanAny(const Vec3* const* tris, int count, double delta) const
{
  if (count <= 0 || Nodes.empty())
  {
    return false;
  }
  if (count > 32)
  {
    return this->anyCloserThanAny(tris, 32, delta) || this->anyCloserThanAny(tris + 32, count - 32, delta);
  }
  // per query triangle what triangleQuery measures
  QueryTriangle q[32];
  for (int i = 0; i < count; ++i)
  {
    q[i].set(tris[i], *this);
  }
  const double delta2 = delta * delta;
  // may query i's walk enter the box [lo, hi] (child c of node n, or the root)? As triangleQuery
  // with limit delta: the box distance, the plane gap, the slab gap
  auto enters = [&](const QueryTriangle& Q, const Vec3& lo, const Vec3& hi, const QueryNode* n, int c) {
    return Q.box2(lo, hi) < delta2 && Q.planeGap(lo, hi) < delta && (!n || Q.slabGap(*this, *n, c) < delta);
  };
  struct Pending
  {
    Ref R;
    std::uint32_t Mask;
  };
  Pending stack[128];
  int top = 0;
  std::uint32_t rootMask = 0;
  for (int i = 0; i < count; ++i)
    if (enters(q[i], Nodes[0].Lo, Nodes[0].Hi, nullptr, 0))
      rootMask |= std::uint32_t(1) << i;
  if (rootMask)
    stack[top++] = { Root, rootMask };
  while (top)
  {
    const Pending e = stack[--top];
    if (e.R.Count == 0)
    {
      const QueryNode& n = QueryNodes[static_cast<std::size_t>(e.R.Child)];
      for (int c = 0; c < 2; ++c)
      {
        const Vec3 lo = childLo(n, c), hi = childHi(n, c);
        std::uint32_t mask = 0;
        for (std::uint32_t m = e.Mask; m; m &= m - 1)
        {
          const int i = __builtin_ctz(m);
          if (enters(q[i], lo, hi, &n, c))
            mask |= std::uint32_t(1) << i;
        }
        if (mask)
        {
          stack[top++] = { { n.Child[c], n.Count[c] }, mask };
          this->prefetch(stack[top - 1].R);
        }
      }
      continue;
    }
    for (int j = e.R.Child; j < e.R.Child + e.R.Count; ++j)
    {
      for (std::uint32_t m = e.Mask; m; m &= m - 1)
      {
        const int i = __builtin_ctz(m);
        if (q[i].leafMayBeCloser(*this, j, delta) && trianglesCloserThan(tris[i], Tri[j].P, delta))
          return true;
      }
    }
  }
  return false;
}

long long TriangleTree::countWithin(const Vec3 t[3], double delta) const
{
  if (Nodes.empty())
  {
    return 0;
  }
  const Vec3 tlo = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
  const Vec3 thi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
  long long count = 0;
  std::vector<int> ids; // with pieces: a triangle counts once
  Ref stack[128];
  int top = 0;
  if (!(boxBoxDistance2(Nodes[0].Lo, Nodes[0].Hi, tlo, thi) > delta * delta))
  {
    stack[top++] = Root;
  }
  while (top)
  {
    const Ref r = stack[--top];
    if (r.Count == 0)
    {
      const QueryNode& n = QueryNodes[static_cast<std::size_t>(r.Child)];
      for (int c = 0; c < 2; ++c)
        if (!(boxBoxDistance2(childLo(n, c), childHi(n, c), tlo, thi) > delta * delta))
          stack[top++] = { n.Child[c], n.Count[c] };
      continue;
    }
    for (int i = r.Child; i < r.Child + r.Count; ++i)
    {
      if (!Pieces.empty() && boxBoxDistance2(Pieces[i].Lo, Pieces[i].Hi, tlo, thi) > delta * delta)
      {
        continue;
      }
      const double d2 = triangleTriangleDistance2(t, Tri[i].P);
      if (d2 == 0.0 || d2 <= delta * delta)
      {
        ++count;
        if (!Pieces.empty())
        {
          ids.push_back(Tri[i].Id);
        }
      }
    }
  }
  if (!Pieces.empty())
  {
    std::sort(ids.begin(), ids.end());
    count = static_cast<long long>(std::unique(ids.begin(), ids.end()) - ids.begin());
  }
  return count;
}

void TriangleTree::trianglesWithin(const Vec3 t[3], double radius, std::vector<int>& ids) const
{
  const std::size_t before = ids.size();
  this->triangleQuery(t, radius, false, &ids);
  if (!Pieces.empty())
  {
    // a triangle found through several of its pieces is listed once
    const auto begin = ids.begin() + static_cast<std::ptrdiff_t>(before);
    std::sort(begin, ids.end());
    ids.erase(std::unique(begin, ids.end()), ids.end());
  }
}

void TriangleTree::prepareWindingNumbers()
{
  Dipoles.assign(Nodes.size(), Dipole());
  // Nodes are in pre-order (children after their parent): leaves first, then parents from the
  // back. Leaves are independent and computed in parallel.
  tbb::parallel_for(
    tbb::blocked_range<std::size_t>(0, Nodes.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
      {
        const Node& node = Nodes[i];
        if (node.Left >= 0)
        {
          continue;
        }
        Dipole& d = Dipoles[i];
        Vec3 weighted = Vec3::Zero();
        Vec3 mean = Vec3::Zero();
        for (int k = node.Start; k < node.Start + node.Count; ++k)
        {
          const Vec3* P = this->windingCorners(k);
          const Vec3 an = 0.5 * (P[1] - P[0]).cross(P[2] - P[0]);
          const double a = an.norm();
          d.AreaNormal += an;
          d.Area += a;
          weighted += a * (P[0] + P[1] + P[2]) / 3.0;
          mean += (P[0] + P[1] + P[2]) / 3.0;
        }
        d.Center = d.Area > 0 ? Vec3(weighted / d.Area) : Vec3(mean / std::max(1, node.Count));
        for (int k = node.Start; k < node.Start + node.Count; ++k)
        {
          const Vec3* Q = this->windingCorners(k);
          for (const Vec3& q : { Q[0], Q[1], Q[2] })
          {
            d.Radius = std::max(d.Radius, (q - d.Center).norm());
          }
        }
      }
    });
  for (std::size_t i = Nodes.size(); i-- > 0;)
  {
    const Node& node = Nodes[i];
    if (node.Left < 0)
    {
      continue;
    }
    const Dipole& l = Dipoles[node.Left];
    const Dipole& r = Dipoles[node.Right];
    Dipole& d = Dipoles[i];
    d.Area = l.Area + r.Area;
    d.AreaNormal = l.AreaNormal + r.AreaNormal;
    d.Center = d.Area > 0 ? Vec3((l.Area * l.Center + r.Area * r.Center) / d.Area) : Vec3(0.5 * (l.Center + r.Center));
    d.Radius = std::max((l.Center - d.Center).norm() + l.Radius, (r.Center - d.Center).norm() + r.Radius);
  }
}

double TriangleTree::windingNumber(const Vec3& p, double beta) const
{
  if (Nodes.empty() || Dipoles.size() != Nodes.size())
  {
    return 0.0;
  }
  double total = 0.0; // sum of solid angles
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0)
  {
    const int i = stack[--top];
    const Node& node = Nodes[i];
    const Dipole& d = Dipoles[i];
    const Vec3 r = d.Center - p;
    const double dist = r.norm();
    if (dist > beta * d.Radius && dist > 0.0)
    {
      total += d.AreaNormal.dot(r) / (dist * dist * dist); // far: one dipole
      continue;
    }
    if (node.Left < 0)
    {
      for (int k = node.Start; k < node.Start + node.Count; ++k)
      {
        const Vec3* P = this->windingCorners(k);
        total += solidAngle(P[0], P[1], P[2], p); // exact
      }
      continue;
    }
    if (top + 2 > 128)
    {
      total += d.AreaNormal.dot(r) / std::max(dist * dist * dist, 1e-300); // depth cap (never reached: depth <= 61)
      continue;
    }
    stack[top++] = node.Left;
    stack[top++] = node.Right;
  }
  return total / (4.0 * M_PI);
}

} // namespace sdfcage
