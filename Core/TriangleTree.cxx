#include "TriangleTree.h"

#include "Geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace sdfcage
{

void TriangleTree::build(const TriangleMesh& mesh)
{
  Nodes.clear();
  Tri.clear();
  Normals.clear();
  const std::size_t n = mesh.Triangles.size();
  if (n == 0)
  {
    return;
  }
  Tri.resize(n);
  Normals.resize(n);
  std::vector<Vec3> centroids(n);
  for (std::size_t f = 0; f < n; ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    for (int k = 0; k < 3; ++k)
    {
      Tri[f].P[k] = mesh.Points[t[k]];
    }
    Tri[f].Id = static_cast<int>(f);
    const Vec3 nrm = (Tri[f].P[1] - Tri[f].P[0]).cross(Tri[f].P[2] - Tri[f].P[0]);
    Normals[f] = nrm.norm() > 0 ? Vec3(nrm.normalized()) : Vec3(Vec3::Zero());
    centroids[f] = (Tri[f].P[0] + Tri[f].P[1] + Tri[f].P[2]) / 3.0;
  }
  Nodes.reserve(2 * n / 2 + 1);
  buildNode(0, static_cast<int>(n), centroids, 0);
}

int TriangleTree::buildNode(int start, int count, std::vector<Vec3>& centroids, int depth)
{
  const int index = static_cast<int>(Nodes.size());
  Nodes.emplace_back();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Vec3 clo = lo, chi = hi;
  for (int i = start; i < start + count; ++i)
  {
    for (const Vec3& p : Tri[i].P)
    {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    clo = clo.cwiseMin(centroids[i]);
    chi = chi.cwiseMax(centroids[i]);
  }
  Nodes[index].Lo = lo;
  Nodes[index].Hi = hi;
  if (count <= 4 || depth > 60)
  {
    Nodes[index].Start = start;
    Nodes[index].Count = count;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int mid = start + count / 2;
  // partial sort of triangles and centroids together by the centroid coordinate
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::nth_element(order.begin(), order.begin() + (mid - start), order.end(),
    [&](int a, int b) { return centroids[start + a][axis] < centroids[start + b][axis]; });
  std::vector<Tri3> tri(count);
  std::vector<Vec3> cen(count);
  for (int i = 0; i < count; ++i)
  {
    tri[i] = Tri[start + order[i]];
    cen[i] = centroids[start + order[i]];
  }
  std::copy(tri.begin(), tri.end(), Tri.begin() + start);
  std::copy(cen.begin(), cen.end(), centroids.begin() + start);
  const int left = buildNode(start, mid - start, centroids, depth + 1);
  const int right = buildNode(mid, start + count - mid, centroids, depth + 1);
  Nodes[index].Left = left;
  Nodes[index].Right = right;
  return index;
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
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top)
  {
    const Node& n = Nodes[stack[--top]];
    if (boxPointDistance2(n.Lo, n.Hi, p) > best2)
    {
      continue;
    }
    if (n.Left < 0)
    {
      for (int i = n.Start; i < n.Start + n.Count; ++i)
      {
        const Vec3 q = closestPointOnTriangle(p, Tri[i].P[0], Tri[i].P[1], Tri[i].P[2]);
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
      stack[top++] = n.Right;
      stack[top++] = n.Left;
    }
    else
    {
      stack[top++] = n.Left;
      stack[top++] = n.Right;
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
        const double s0 = normal.dot(o.P[0]) - offset, s1 = normal.dot(o.P[1]) - offset, s2 = normal.dot(o.P[2]) - offset;
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

} // namespace sdfcage
