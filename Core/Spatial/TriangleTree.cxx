#include "Spatial/TriangleTree.h"

#include "Common/Progress.h"
#include "Spatial/Geometry.h"

#include <algorithm>
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

void TriangleTree::build(const TriangleMesh& mesh)
{
  this->build(mesh, nullptr);
}

bool TriangleTree::build(const TriangleMesh& mesh, Progress* progress)
{
  Nodes.clear();
  Dipoles.clear();
  Tri.clear();
  Normals.clear();
  const std::size_t n = mesh.Triangles.size();
  if (n == 0)
  {
    return !progressCancelled(progress);
  }
  std::vector<Tri3> tri(n);
  Normals.resize(n);
  std::vector<Vec3> centroids(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    if (progressCancelled(progress))
      return;
    for (std::size_t f = r.begin(); f != r.end(); ++f)
    {
      const Triangle& t = mesh.Triangles[f];
      for (int k = 0; k < 3; ++k)
      {
        tri[f].P[k] = mesh.Points[t[k]];
      }
      tri[f].Id = static_cast<int>(f);
      const Vec3 nrm = (tri[f].P[1] - tri[f].P[0]).cross(tri[f].P[2] - tri[f].P[0]);
      Normals[f] = nrm.norm() > 0 ? Vec3(nrm.normalized()) : Vec3(Vec3::Zero());
      centroids[f] = (tri[f].P[0] + tri[f].P[1] + tri[f].P[2]) / 3.0;
    }
  });
  // The node layout is fixed in advance (pre-order, sizes known from the counts), so subtrees
  // are built in parallel into their own ranges and the tree does not depend on the threads.
  Nodes.resize(static_cast<std::size_t>(subtreeNodes(static_cast<int>(n), 0)));
  std::vector<BuildItem> items(n);
  for (std::size_t f = 0; f < n; ++f)
  {
    items[f] = { centroids[f], static_cast<int>(f) };
  }
  if (!progressCancelled(progress))
  {
    buildNode(0, 0, static_cast<int>(n), items, tri, 0, progress);
  }
  if (progressCancelled(progress))
  {
    Nodes.clear(); // some subtrees were skipped: nothing of it may be used
    Normals.clear();
    return false;
  }
  Tri.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    Tri[i] = tri[items[i].Id];
  }
  return true;
}

void TriangleTree::buildNode(int index, int start, int count, std::vector<BuildItem>& items,
  const std::vector<Tri3>& tri, int depth, Progress* progress)
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
      for (const Vec3& p : tri[items[i].Id].P)
      {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
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
  auto buildLeft = [&] { buildNode(left, start, half, items, tri, depth + 1, progress); };
  auto buildRight = [&] { buildNode(right, start + half, count - half, items, tri, depth + 1, progress); };
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
  // Each entry keeps its box distance, measured when its parent was opened: popped nodes are
  // tested against the current best without measuring again (the same nodes are visited, in the
  // same order, as when each box was measured on popping).
  struct Pending
  {
    int Node;
    double D2;
  };
  Pending stack[128];
  int top = 0;
  stack[top++] = { 0, boxPointDistance2(Nodes[0].Lo, Nodes[0].Hi, p) };
  while (top)
  {
    const Pending e = stack[--top];
    if (e.D2 > best2)
    {
      continue;
    }
    const Node& n = Nodes[e.Node];
    if (n.Left < 0)
    {
      for (int i = n.Start; i < n.Start + n.Count; ++i)
      {
        const Vec3* P = Tri[i].P;
        // the triangle's own box first: nothing in it is nearer than the box (the margin keeps
        // rounding in the closest point from ever making this skip a triangle it would take)
        const Vec3 lo = P[0].cwiseMin(P[1]).cwiseMin(P[2]), hi = P[0].cwiseMax(P[1]).cwiseMax(P[2]);
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
    const double dl = boxPointDistance2(Nodes[n.Left].Lo, Nodes[n.Left].Hi, p);
    const double dr = boxPointDistance2(Nodes[n.Right].Lo, Nodes[n.Right].Hi, p);
    if (dl < dr)
    {
      stack[top++] = { n.Right, dr };
      stack[top++] = { n.Left, dl };
    }
    else
    {
      stack[top++] = { n.Left, dl };
      stack[top++] = { n.Right, dr };
    }
  }
  if (triangle < 0)
  {
    return false;
  }
  distance = std::sqrt(best2);
  return true;
}

double TriangleTree::distance(const Vec3& p) const
{
  Vec3 q;
  int t;
  double d = std::numeric_limits<double>::infinity();
  this->closestPoint(p, -1.0, q, t, d);
  return d;
}

double TriangleTree::triangleQuery(const Vec3 t[3], double limit, bool stopAtFirst, std::vector<int>* within) const
{
  if (Nodes.empty())
  {
    return limit;
  }
  const Vec3 tlo = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
  const Vec3 thi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
  // plane of the query triangle: distance to the triangle >= distance to its plane
  Vec3 normal = (t[1] - t[0]).cross(t[2] - t[0]);
  const double nlen = normal.norm();
  const bool hasPlane = nlen > 0.0;
  if (hasPlane)
  {
    normal /= nlen;
  }
  const double offset = hasPlane ? normal.dot(t[0]) : 0.0;
  // the three side planes of the query triangle (through an edge, containing the normal, facing
  // out): the triangle lies on their inner side, so anything at least d beyond one of them is at
  // least d from the triangle
  Vec3 side[3];
  double sideOffset[3] = { 0.0, 0.0, 0.0 };
  if (hasPlane)
  {
    for (int i = 0; i < 3; ++i)
    {
      side[i] = (t[(i + 1) % 3] - t[i]).cross(normal);
      const double len = side[i].norm();
      side[i] = len > 0 ? Vec3(side[i] / len) : Vec3(Vec3::Zero());
      // the offset includes the query's own corners, so the triangle is on the inner side even
      // when its rounded normal is slightly off (slivers)
      sideOffset[i] = std::max({ side[i].dot(t[0]), side[i].dot(t[1]), side[i].dot(t[2]) });
    }
  }
  auto planeGap = [&](const Vec3& lo, const Vec3& hi) {
    if (!hasPlane)
    {
      return 0.0;
    }
    const Vec3 c = 0.5 * (lo + hi), e = 0.5 * (hi - lo);
    const double s = normal.dot(c) - offset;
    const double r = std::abs(normal.x()) * e.x() + std::abs(normal.y()) * e.y() + std::abs(normal.z()) * e.z();
    double gap = std::abs(s) - r;
    for (int i = 0; i < 3; ++i)
    {
      const Vec3& m = side[i];
      const double below = m.dot(c) - std::abs(m.x()) * e.x() - std::abs(m.y()) * e.y() - std::abs(m.z()) * e.z();
      gap = std::max(gap, below - sideOffset[i]);
    }
    return std::max(0.0, gap);
  };
  double best = limit;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top)
  {
    const Node& n = Nodes[stack[--top]];
    const double lb2 = boxBoxDistance2(n.Lo, n.Hi, tlo, thi);
    if (lb2 >= best * best || planeGap(n.Lo, n.Hi) >= best)
    {
      continue;
    }
    if (n.Left >= 0)
    {
      stack[top++] = n.Left;
      stack[top++] = n.Right;
      continue;
    }
    for (int i = n.Start; i < n.Start + n.Count; ++i)
    {
      const Tri3& o = Tri[i];
      if (hasPlane)
      {
        const double s0 = normal.dot(o.P[0]) - offset, s1 = normal.dot(o.P[1]) - offset,
                     s2 = normal.dot(o.P[2]) - offset;
        if (std::min({ s0, s1, s2 }) >= best || std::max({ s0, s1, s2 }) <= -best)
        {
          continue;
        }
        bool outside = false;
        for (int k = 0; k < 3 && !outside; ++k)
        {
          outside = std::min({ side[k].dot(o.P[0]), side[k].dot(o.P[1]), side[k].dot(o.P[2]) }) - sideOffset[k] >= best;
        }
        if (outside)
        {
          continue;
        }
      }
      const double d = std::sqrt(triangleTriangleDistance2(t, o.P));
      if (within)
      {
        // collect every triangle below the limit; the limit never shrinks
        if (d < best)
        {
          within->push_back(o.Id);
        }
        continue;
      }
      if (d < best)
      {
        best = d;
        if (stopAtFirst)
        {
          return best;
        }
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

long long TriangleTree::countWithin(const Vec3 t[3], double delta) const
{
  if (Nodes.empty())
  {
    return 0;
  }
  const Vec3 tlo = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
  const Vec3 thi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
  long long count = 0;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top)
  {
    const Node& n = Nodes[stack[--top]];
    if (boxBoxDistance2(n.Lo, n.Hi, tlo, thi) > delta * delta)
    {
      continue;
    }
    if (n.Left >= 0)
    {
      stack[top++] = n.Left;
      stack[top++] = n.Right;
      continue;
    }
    for (int i = n.Start; i < n.Start + n.Count; ++i)
    {
      const double d2 = triangleTriangleDistance2(t, Tri[i].P);
      count += (d2 == 0.0 || d2 <= delta * delta) ? 1 : 0;
    }
  }
  return count;
}

void TriangleTree::trianglesWithin(const Vec3 t[3], double radius, std::vector<int>& ids) const
{
  this->triangleQuery(t, radius, false, &ids);
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
          const Vec3* P = Tri[k].P;
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
          for (const Vec3& q : Tri[k].P)
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
        total += solidAngle(Tri[k].P[0], Tri[k].P[1], Tri[k].P[2], p); // exact
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
