#include "Spatial/Geometry.h"
#include "Mesh/EdgeKey.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>

namespace sdfcage
{

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)
{
  // Voronoi-region walk (Ericson §5.1.5), written from the region definitions.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0)
  {
    return a;
  }
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3)
  {
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
  {
    return a + ab * (d1 / (d1 - d3));
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6)
  {
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
  {
    return a + ac * (d2 / (d2 - d6));
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
  {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denom = va + vb + vc;
  if (!(denom > 0.0))
  {
    // degenerate triangle: best of its edges
    Vec3 best = a;
    double bd = (p - a).squaredNorm();
    const Vec3 e[3][2] = { { a, b }, { b, c }, { c, a } };
    for (const auto& s : e)
    {
      const Vec3 d = s[1] - s[0];
      const double l2 = d.squaredNorm();
      const double t = l2 > 0 ? std::clamp((p - s[0]).dot(d) / l2, 0.0, 1.0) : 0.0;
      const Vec3 q = s[0] + t * d;
      if ((p - q).squaredNorm() < bd)
      {
        bd = (p - q).squaredNorm();
        best = q;
      }
    }
    return best;
  }
  const double v = vb / denom, w = vc / denom;
  return a + ab * v + ac * w;
}

double segmentSegmentDistance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1)
{
  double s, t;
  return segmentSegmentClosest(p0, p1, q0, q1, s, t);
}

double segmentSegmentClosest(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double& s, double& t)
{
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  s = 0.0;
  t = 0.0;
  if (a <= 0.0 && e <= 0.0)
  {
    return r.squaredNorm();
  }
  if (a <= 0.0)
  {
    t = std::clamp(f / e, 0.0, 1.0);
  }
  else
  {
    const double c = d1.dot(r);
    if (e <= 0.0)
    {
      s = std::clamp(-c / a, 0.0, 1.0);
    }
    else
    {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0)
      {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      }
      else if (t > 1.0)
      {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + d1 * s) - (q0 + d2 * t)).squaredNorm();
}

namespace
{
// Does segment [p, q] cross triangle (a, b, c)? Orientation-sign test; touching counts.
bool segmentTriangleIntersect(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c)
{
  auto orient = [](const Vec3& x, const Vec3& y, const Vec3& z, const Vec3& w) {
    return (y - x).cross(z - x).dot(w - x);
  };
  const double sp = orient(a, b, c, p), sq = orient(a, b, c, q);
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0))
  {
    return false;
  }
  // An endpoint on (or within rounding of) the plane makes the crossing test ill-conditioned; the
  // point-triangle and edge-edge distances of the caller decide those cases exactly enough.
  const double scale = (b - a).cross(c - a).norm() * (q - p).norm();
  if (std::abs(sp) <= 1e-10 * scale || std::abs(sq) <= 1e-10 * scale)
  {
    return false;
  }
  const double s1 = orient(p, q, a, b), s2 = orient(p, q, b, c), s3 = orient(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}
} // namespace

double triangleTriangleDistance2(const Vec3 a[3], const Vec3 b[3])
{
  for (int i = 0; i < 3; ++i)
  {
    if (segmentTriangleIntersect(a[i], a[(i + 1) % 3], b[0], b[1], b[2]) ||
      segmentTriangleIntersect(b[i], b[(i + 1) % 3], a[0], a[1], a[2]))
    {
      return 0.0;
    }
  }
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i)
  {
    best = std::min(best, (a[i] - closestPointOnTriangle(a[i], b[0], b[1], b[2])).squaredNorm());
    best = std::min(best, (b[i] - closestPointOnTriangle(b[i], a[0], a[1], a[2])).squaredNorm());
    for (int j = 0; j < 3; ++j)
    {
      best = std::min(best, segmentSegmentDistance2(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
    }
  }
  return best;
}

bool trianglesCloserThan(const Vec3 a[3], const Vec3 b[3], double delta)
{
  // the parts of the distance in triangleTriangleDistance2's terms, each compared as the whole
  // would be (sqrt(min) < delta exactly when some part's sqrt is), the cheapest first
  for (int i = 0; i < 3; ++i)
  {
    if (std::sqrt((a[i] - closestPointOnTriangle(a[i], b[0], b[1], b[2])).squaredNorm()) < delta ||
      std::sqrt((b[i] - closestPointOnTriangle(b[i], a[0], a[1], a[2])).squaredNorm()) < delta)
    {
      return true;
    }
  }
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      if (std::sqrt(segmentSegmentDistance2(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) < delta)
      {
        return true;
      }
    }
  }
  for (int i = 0; i < 3; ++i)
  {
    if (segmentTriangleIntersect(a[i], a[(i + 1) % 3], b[0], b[1], b[2]) ||
      segmentTriangleIntersect(b[i], b[(i + 1) % 3], a[0], a[1], a[2]))
    {
      return delta > 0.0;
    }
  }
  return false;
}

namespace
{
// Is direction u inside the (closed) corner angle spanned by e1, e2 (normal n = e1 x e2)?
bool inCorner(const Vec3& u, const Vec3& e1, const Vec3& e2, const Vec3& n)
{
  return e1.cross(u).dot(n) >= 0 && u.cross(e2).dot(n) >= 0;
}
} // namespace

bool meetBeyondSharedVertex(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e)
{
  const Vec3 n1 = (b - a).cross(c - a), n2 = (d - a).cross(e - a);
  const Vec3 u = n1.cross(n2);
  const double scale = n1.norm() * n2.norm();
  if (!(scale > 0))
  {
    return true;
  }
  if (u.norm() <= 1e-9 * scale)
  {
    // (nearly) coplanar: they overlap beyond a when the corner angles overlap
    const Vec3 n = n1.normalized();
    return inCorner(d - a, b - a, c - a, n) || inCorner(e - a, b - a, c - a, n) || inCorner(b - a, d - a, e - a, n) ||
      inCorner(c - a, d - a, e - a, n);
  }
  // the planes meet in the line a + s u; both triangles contain a piece of it on the same side
  return (inCorner(u, b - a, c - a, n1) && inCorner(u, d - a, e - a, n2)) ||
    (inCorner(-u, b - a, c - a, n1) && inCorner(-u, d - a, e - a, n2));
}

bool trianglesConflict(
  const int ia[3], const Vec3 pa[3], const int ib[3], const Vec3 pb[3], double separation, double foldCosine)
{
  int sa[3], sb[3], shared = 0;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      if (ia[i] == ib[j])
      {
        sa[shared] = i;
        sb[shared] = j;
        ++shared;
      }
    }
  }
  if (shared == 0)
  {
    const double d2 = triangleTriangleDistance2(pa, pb);
    return d2 == 0.0 || d2 < separation * separation;
  }
  if (shared == 1)
  {
    const int i = sa[0], j = sb[0];
    return meetBeyondSharedVertex(pa[i], pa[(i + 1) % 3], pa[(i + 2) % 3], pb[(j + 1) % 3], pb[(j + 2) % 3]);
  }
  if (shared == 2)
  {
    const Vec3 na = (pa[1] - pa[0]).cross(pa[2] - pa[0]), nb = (pb[1] - pb[0]).cross(pb[2] - pb[0]);
    return na.dot(nb) < foldCosine * na.norm() * nb.norm();
  }
  return true; // the same three vertices twice
}

double windingNumber(const TriangleMesh& mesh, const Vec3& p)
{
  // Sum of signed solid angles, divided by 4 pi.
  double total = 0.0;
  for (const Triangle& t : mesh.Triangles)
  {
    total += solidAngle(mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]], p);
  }
  return total / (4.0 * M_PI);
}

PseudoNormalSign::PseudoNormalSign(const TriangleMesh& mesh)
  : M(mesh)
  , Face(mesh.Triangles.size(), Vec3::Zero())
  , Vertex(mesh.Points.size(), Vec3::Zero())
  , Across(3 * mesh.Triangles.size(), -1)
{
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * mesh.Triangles.size());
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    const Vec3 n = areaNormal(mesh, t);
    const double len = n.norm();
    Face[f] = len > 0 ? Vec3(n / len) : Vec3::Zero();
    for (int k = 0; k < 3; ++k)
    {
      const Vec3& p = mesh.Points[t[k]];
      const Vec3 u = mesh.Points[t[(k + 1) % 3]] - p, w = mesh.Points[t[(k + 2) % 3]] - p;
      Vertex[t[k]] += std::atan2(u.cross(w).norm(), u.dot(w)) * Face[f];
      edges.emplace_back(edgeKey(t[k], t[(k + 1) % 3]), static_cast<int>(3 * f + k));
    }
  }
  tbb::parallel_sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i + 1 < edges.size(); ++i)
    if (edges[i].first == edges[i + 1].first)
    {
      Across[static_cast<std::size_t>(edges[i].second)] = edges[i + 1].second / 3;
      Across[static_cast<std::size_t>(edges[i + 1].second)] = edges[i].second / 3;
    }
}

bool PseudoNormalSign::outside(const Vec3& x, int f, const Vec3& cp) const
{
  const Triangle& t = M.Triangles[static_cast<std::size_t>(f)];
  const Vec3 &a = M.Points[t[0]], &b = M.Points[t[1]], &c = M.Points[t[2]];
  const double area = areaNormal(M, t).norm();
  Vec3 n = Face[static_cast<std::size_t>(f)];
  if (area > 0)
  {
    // barycentric weights of cp: a weight near 0 puts it on the opposite edge
    const double w[3] = { (b - cp).cross(c - cp).norm() / area, (c - cp).cross(a - cp).norm() / area,
      (a - cp).cross(b - cp).norm() / area };
    const double eps = 1e-7;
    int zeros = 0, zero = -1, nonzero = -1;
    for (int k = 0; k < 3; ++k)
      if (w[k] < eps)
      {
        ++zeros;
        zero = k;
      }
      else
        nonzero = k;
    if (zeros >= 2)
      n = Vertex[static_cast<std::size_t>(t[nonzero])]; // at a corner
    else if (zeros == 1)
    {
      // on the edge opposite corner `zero`: edge k runs from corner k to k + 1
      const int across = Across[3 * static_cast<std::size_t>(f) + static_cast<std::size_t>((zero + 1) % 3)];
      if (across >= 0)
        n = Face[static_cast<std::size_t>(f)] + Face[static_cast<std::size_t>(across)];
    }
  }
  return (x - cp).dot(n) > 0;
}

} // namespace sdfcage
