// SDFCage — Core: mean value and Green cage coordinates (see CageCoordinates.h for the formulas).
#include "Deformation/CageCoordinates.h"

#include "Common/Threads.h"
#include "Deformation/VectorMath.h"

#include <Eigen/Core>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <cmath>
#include <map>
#include <new>
#include <sstream>
#include <utility>

namespace sdfcage
{

namespace
{

constexpr double Pi = 3.14159265358979323846;
constexpr double InvFourPi = 1.0 / (4.0 * Pi);

using WeightMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using FloatWeightMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The rest cage with everything a weight row needs that depends on the cage only.
struct CageFrame
{
  TriangleMesh Mesh;
  std::vector<std::array<int, 2>> Edges;      // unique undirected edges
  std::vector<std::array<int, 3>> FaceEdges;  // edge of corners (k, k+1)
  std::vector<std::array<double, 3>> FaceEdgeSign; // +1 when edge (k, k+1) runs from Edges[e][0] to [1]
  std::vector<Vec3> EdgeTangent;              // unit, from Edges[e][0] to Edges[e][1]
  std::vector<Vec3> Normal;                   // unit outward normal per triangle
  std::vector<std::array<Vec3, 3>> Gradient;  // in-plane gradient of each corner's hat function
  std::vector<std::array<double, 3>> HatAt0;  // Gamma_k(0) = 1 - g_k . p_k
  std::vector<std::array<Vec3, 3>> EdgeNormal; // outward in-plane normal of edge (k, k+1)
  double Diagonal = 0.0;
  double Tiny = 0.0; // lengths below this count as zero (1e-12 x the diagonal)

  // The inside test's ray direction and a grid of the triangles projected along it (the plane
  // spanned by RayU, RayV): a ray from x meets only the triangles of x's cell.
  Vec3 Ray = Vec3(0.2357022603955158, 0.5491251384243406, 0.8017837257372732).normalized();
  Vec3 RayU, RayV;
  double GridLo[2] = { 0.0, 0.0 }, GridStep[2] = { 1.0, 1.0 };
  int GridSize = 1;
  std::vector<int> CellStart, CellTriangles; // compressed: cell c has CellTriangles[CellStart[c] .. CellStart[c+1])

  void buildRayGrid()
  {
    this->RayU = this->Ray.unitOrthogonal();
    this->RayV = this->Ray.cross(this->RayU);
    const auto& P = this->Mesh.Points;
    double lo[2] = { 1e300, 1e300 }, hi[2] = { -1e300, -1e300 };
    for (const Vec3& p : P)
    {
      const double c[2] = { p.dot(this->RayU), p.dot(this->RayV) };
      for (int a = 0; a < 2; ++a)
      {
        lo[a] = std::min(lo[a], c[a]);
        hi[a] = std::max(hi[a], c[a]);
      }
    }
    const std::size_t nf = this->Mesh.Triangles.size();
    this->GridSize = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(nf))));
    for (int a = 0; a < 2; ++a)
    {
      const double pad = 1e-9 * (hi[a] - lo[a]) + 1e-300;
      this->GridLo[a] = lo[a] - pad;
      this->GridStep[a] = (hi[a] - lo[a] + 2.0 * pad) / this->GridSize;
    }
    const int g = this->GridSize;
    std::vector<std::array<int, 4>> ranges(nf);
    std::vector<int> count(static_cast<std::size_t>(g) * g + 1, 0);
    for (std::size_t j = 0; j < nf; ++j)
    {
      double tlo[2] = { 1e300, 1e300 }, thi[2] = { -1e300, -1e300 };
      for (int k = 0; k < 3; ++k)
      {
        const Vec3& p = P[this->Mesh.Triangles[j][k]];
        const double c[2] = { p.dot(this->RayU), p.dot(this->RayV) };
        for (int a = 0; a < 2; ++a)
        {
          tlo[a] = std::min(tlo[a], c[a]);
          thi[a] = std::max(thi[a], c[a]);
        }
      }
      // one cell of margin on each side: the inside test's tolerance never misses a triangle
      auto& r = ranges[j];
      r[0] = std::max(0, this->cellOf(tlo[0], 0) - 1);
      r[1] = std::min(g - 1, this->cellOf(thi[0], 0) + 1);
      r[2] = std::max(0, this->cellOf(tlo[1], 1) - 1);
      r[3] = std::min(g - 1, this->cellOf(thi[1], 1) + 1);
      for (int i = r[0]; i <= r[1]; ++i)
      {
        for (int k = r[2]; k <= r[3]; ++k)
        {
          ++count[static_cast<std::size_t>(i) * g + k + 1];
        }
      }
    }
    for (std::size_t c = 1; c < count.size(); ++c)
    {
      count[c] += count[c - 1];
    }
    this->CellStart = count;
    this->CellTriangles.assign(static_cast<std::size_t>(count.back()), 0);
    for (std::size_t j = 0; j < nf; ++j)
    {
      const auto& r = ranges[j];
      for (int i = r[0]; i <= r[1]; ++i)
      {
        for (int k = r[2]; k <= r[3]; ++k)
        {
          this->CellTriangles[static_cast<std::size_t>(count[static_cast<std::size_t>(i) * g + k]++)] = static_cast<int>(j);
        }
      }
    }
  }

  /// Grid cell index along axis a (may be outside [0, GridSize)).
  int cellOf(double c, int a) const
  {
    return static_cast<int>(std::floor((c - this->GridLo[a]) / this->GridStep[a]));
  }

  void build(const TriangleMesh& cage)
  {
    this->Mesh = cage;
    const auto& P = this->Mesh.Points;
    const std::size_t nf = this->Mesh.Triangles.size();
    std::map<std::pair<int, int>, int> edgeIds;
    this->FaceEdges.resize(nf);
    this->FaceEdgeSign.resize(nf);
    for (std::size_t j = 0; j < nf; ++j)
    {
      const Triangle& t = this->Mesh.Triangles[j];
      for (int k = 0; k < 3; ++k)
      {
        const int a = t[k], b = t[(k + 1) % 3];
        const auto key = std::make_pair(std::min(a, b), std::max(a, b));
        auto it = edgeIds.find(key);
        if (it == edgeIds.end())
        {
          it = edgeIds.emplace(key, static_cast<int>(this->Edges.size())).first;
          this->Edges.push_back({ key.first, key.second });
        }
        this->FaceEdges[j][k] = it->second;
        this->FaceEdgeSign[j][k] = a < b ? 1.0 : -1.0;
      }
    }
    this->EdgeTangent.resize(this->Edges.size());
    for (std::size_t e = 0; e < this->Edges.size(); ++e)
    {
      this->EdgeTangent[e] = (P[this->Edges[e][1]] - P[this->Edges[e][0]]).normalized();
    }
    this->Normal.resize(nf);
    this->Gradient.resize(nf);
    this->HatAt0.resize(nf);
    this->EdgeNormal.resize(nf);
    for (std::size_t j = 0; j < nf; ++j)
    {
      const Triangle& t = this->Mesh.Triangles[j];
      const Vec3 c = (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]);
      const double twiceArea = c.norm();
      const Vec3 n = c / twiceArea;
      this->Normal[j] = n;
      for (int k = 0; k < 3; ++k)
      {
        const Vec3& pk = P[t[k]];
        const Vec3& p1 = P[t[(k + 1) % 3]];
        const Vec3& p2 = P[t[(k + 2) % 3]];
        this->Gradient[j][k] = n.cross(p2 - p1) / twiceArea;
        this->HatAt0[j][k] = 1.0 - this->Gradient[j][k].dot(pk);
        this->EdgeNormal[j][k] = (p1 - pk).normalized().cross(n);
      }
    }
    const auto box = bounds(this->Mesh);
    this->Diagonal = (box[1] - box[0]).norm();
    this->Tiny = 1e-12 * this->Diagonal;
    this->buildRayGrid();
  }
};

/// Per-thread scratch of one weight row.
struct RowScratch
{
  std::vector<Vec3> A;      // v_i - x
  std::vector<double> R;    // |v_i - x|
  std::vector<double> InvR; // 1 / |v_i - x| (MVC)
  std::vector<Vec3> U;      // unit vectors (MVC)
  std::vector<double> Theta, SinHalf, CosHalf, InvSin; // per edge (MVC): angle at x, sin, cos of half, 1/sin
  std::vector<Vec3> EdgeNormal;                        // per edge (MVC): unit normal of the plane (x, edge)
  std::vector<double> F;    // per edge line integral of 1/R (Green)
  std::vector<double> In, Out; // arguments and values of the vector log / atan
  std::vector<double> Det, Den; // per triangle (Green): the solid angle's half-angle tangent
  std::vector<double> Row;      // one weight row in double precision (single-precision storage)
  void resize(std::size_t nv, std::size_t ne, std::size_t nf)
  {
    this->Row.resize(nv + nf);
    this->In.resize(std::max(ne, nf));
    this->Out.resize(std::max(ne, nf));
    this->Det.resize(nf);
    this->Den.resize(nf);
    this->A.resize(nv);
    this->R.resize(nv);
    this->InvR.resize(nv);
    this->U.resize(nv);
    this->Theta.resize(ne);
    this->SinHalf.resize(ne);
    this->CosHalf.resize(ne);
    this->InvSin.resize(ne);
    this->EdgeNormal.resize(ne);
    this->F.resize(ne);
  }
};

struct RowInfo
{
  bool OnCage = false;
  double Winding = 0.0;
};

/// 2 atan2(y, x) (a solid angle from Van Oosterom and Strackee's half-angle formula), in (-2 pi, 2 pi].
inline double twiceAtan2(double y, double x)
{
  if (x > 0.0)
  {
    return 2.0 * std::atan(y / x);
  }
  if (x < 0.0)
  {
    return 2.0 * (std::atan(y / x) + (y >= 0.0 ? Pi : -Pi));
  }
  return y > 0.0 ? Pi : (y < 0.0 ? -Pi : 0.0);
}

/// Winding number of the cage at x (relative vertex positions s.A) by the exact solid angles.
double windingBySolidAngles(const CageFrame& cage, const RowScratch& s)
{
  double sum = 0.0;
  for (const Triangle& t : cage.Mesh.Triangles)
  {
    const Vec3 &a0 = s.A[t[0]], &a1 = s.A[t[1]], &a2 = s.A[t[2]];
    const double r0 = s.R[t[0]], r1 = s.R[t[1]], r2 = s.R[t[2]];
    sum += twiceAtan2(a0.dot(a1.cross(a2)), r0 * r1 * r2 + a0.dot(a1) * r2 + a1.dot(a2) * r0 + a2.dot(a0) * r1);
  }
  return sum * InvFourPi;
}

/// Inside (winding 1) or outside (0) by the parity of a ray's crossings (Moeller-Trumbore); a
/// crossing within 1e-9 of a triangle's edge, or a ray grazing a plane, falls back to the exact
/// solid-angle sum. For the mean value mode's count of outside points (Green mode has the exact
/// winding number from its own solid angles).
double windingByRay(const CageFrame& cage, const RowScratch& s, const Vec3& x)
{
  const Vec3& d = cage.Ray;
  const int ci = cage.cellOf(x.dot(cage.RayU), 0), ck = cage.cellOf(x.dot(cage.RayV), 1);
  if (ci < 0 || ck < 0 || ci >= cage.GridSize || ck >= cage.GridSize)
  {
    return 0.0; // the ray misses the cage's shadow: outside
  }
  const std::size_t cell = static_cast<std::size_t>(ci) * cage.GridSize + ck;
  int crossings = 0;
  for (int c = cage.CellStart[cell]; c < cage.CellStart[cell + 1]; ++c)
  {
    const Triangle& t = cage.Mesh.Triangles[static_cast<std::size_t>(cage.CellTriangles[static_cast<std::size_t>(c)])];
    const Vec3& a0 = s.A[t[0]];
    const Vec3 e1 = s.A[t[1]] - a0, e2 = s.A[t[2]] - a0;
    const Vec3 pv = d.cross(e2);
    const double det = e1.dot(pv);
    const double scale = e1.squaredNorm() + e2.squaredNorm(); // >= |e1| |e2|, no square root
    const Vec3 tv = -a0;
    if (std::abs(det) <= 1e-12 * scale)
    {
      // the ray is parallel to the plane: no crossing unless it runs in the plane
      if (std::abs(tv.dot(e1.cross(e2))) <= 1e-12 * scale * tv.norm())
      {
        return windingBySolidAngles(cage, s);
      }
      continue;
    }
    const double inv = 1.0 / det;
    const double u = tv.dot(pv) * inv;
    if (u < -1e-9 || u > 1.0 + 1e-9)
    {
      continue;
    }
    const Vec3 qv = tv.cross(e1);
    const double v = d.dot(qv) * inv;
    if (v < -1e-9 || u + v > 1.0 + 1e-9)
    {
      continue;
    }
    const double along = e2.dot(qv) * inv;
    if (along <= 0.0)
    {
      continue;
    }
    if (u < 1e-9 || v < 1e-9 || u + v > 1.0 - 1e-9)
    {
      return windingBySolidAngles(cage, s); // through an edge or a vertex: decide exactly
    }
    ++crossings;
  }
  return (crossings % 2) ? 1.0 : 0.0;
}

/// Mean value coordinates of x (Ju, Schaefer, Warren 2005, the robust pseudo-code of §3.3) into
/// row[0 .. #V). Also whether x is inside the cage (Winding 1 or 0, see windingByRay).
/// The paper's per-triangle sines and cosines are taken from half angles: theta_e = 2 alpha_e with
/// sin(alpha_e) = |u_a - u_b| / 2, cos(alpha_e) = |u_a + u_b| / 2 per edge, and
/// h = alpha_0 + alpha_1 + alpha_2 by the addition theorems (one arctangent per edge, none per
/// triangle).
RowInfo meanValueRow(const CageFrame& cage, const Vec3& x, double* row, RowScratch& s)
{
  RowInfo info;
  const auto& P = cage.Mesh.Points;
  const std::size_t nv = P.size();
  std::fill(row, row + nv, 0.0);
  for (std::size_t i = 0; i < nv; ++i)
  {
    s.A[i] = P[i] - x;
    s.R[i] = s.A[i].norm();
    if (s.R[i] <= cage.Tiny)
    {
      row[i] = 1.0; // at a vertex: its own value
      info.OnCage = true;
      info.Winding = 0.5;
      return info;
    }
    s.InvR[i] = 1.0 / s.R[i];
    s.U[i] = s.A[i] * s.InvR[i];
  }
  for (std::size_t e = 0; e < cage.Edges.size(); ++e)
  {
    // l = |u_a - u_b| = 2 sin(alpha), m = |u_a + u_b| = 2 cos(alpha), l^2 + m^2 = 4: take the
    // smaller one from its own difference or sum, the other from 4 - x^2 (no cancellation)
    const Vec3& ua = s.U[cage.Edges[e][0]];
    const Vec3& ub = s.U[cage.Edges[e][1]];
    double l2 = (ua - ub).squaredNorm();
    double l, m;
    if (l2 <= 2.0)
    {
      l = std::sqrt(l2);
      m = std::sqrt(std::max(0.0, 4.0 - l2));
    }
    else
    {
      const double m2 = (ua + ub).squaredNorm();
      m = std::sqrt(m2);
      l = std::sqrt(std::max(0.0, 4.0 - m2));
    }
    s.In[e] = l <= m ? l / m : m / l; // alpha = atan(l / m), from an argument <= 1 (l^2 + m^2 = 4)
    s.SinHalf[e] = 0.5 * l;
    s.CosHalf[e] = 0.5 * m;
    const double sinTheta = 0.5 * l * m;
    s.InvSin[e] = sinTheta > 1e-12 ? 1.0 / sinTheta : 0.0; // 0: x on the line of the edge
    s.EdgeNormal[e] = ua.cross(ub) * s.InvSin[e];          // |u_a x u_b| = sin(theta)
  }
  vectorAtan(s.In.data(), s.Out.data(), static_cast<int>(cage.Edges.size()));
  for (std::size_t e = 0; e < cage.Edges.size(); ++e)
  {
    s.Theta[e] = 2.0 * (s.SinHalf[e] <= s.CosHalf[e] ? s.Out[e] : 0.5 * Pi - s.Out[e]);
  }
  for (std::size_t j = 0; j < cage.Mesh.Triangles.size(); ++j)
  {
    const Triangle& t = cage.Mesh.Triangles[j];
    // corner k sees the edge opposite it, (k+1, k+2)
    int e[3];
    for (int k = 0; k < 3; ++k)
    {
      e[k] = cage.FaceEdges[j][(k + 1) % 3];
    }
    // h = alpha_0 + alpha_1 + alpha_2 (half the sum of the angles)
    const double s01 = s.SinHalf[e[0]] * s.CosHalf[e[1]] + s.CosHalf[e[0]] * s.SinHalf[e[1]];
    const double c01 = s.CosHalf[e[0]] * s.CosHalf[e[1]] - s.SinHalf[e[0]] * s.SinHalf[e[1]];
    const double sinH = s01 * s.CosHalf[e[2]] + c01 * s.SinHalf[e[2]];
    const double cosH = c01 * s.CosHalf[e[2]] - s01 * s.SinHalf[e[2]];
    if (sinH < 1e-10 && cosH < 0.0)
    {
      // h = pi: x lies on this triangle: linear interpolation of its corners (2D barycentric)
      std::fill(row, row + nv, 0.0);
      double w[3], sum = 0.0;
      for (int k = 0; k < 3; ++k)
      {
        const double sinTheta = 2.0 * s.SinHalf[e[k]] * s.CosHalf[e[k]];
        w[k] = sinTheta * s.R[t[(k + 1) % 3]] * s.R[t[(k + 2) % 3]];
        sum += w[k];
      }
      for (int k = 0; k < 3; ++k)
      {
        row[t[k]] += w[k] / sum;
      }
      info.OnCage = true;
      info.Winding = 0.5;
      return info;
    }
    if (s.InvSin[e[0]] == 0.0 || s.InvSin[e[1]] == 0.0 || s.InvSin[e[2]] == 0.0)
    {
      continue; // x on the line of an edge, outside the triangle: its plane holds x
    }
    const double det = s.U[t[0]].dot(s.U[t[1]].cross(s.U[t[2]]));
    {
      // The paper's vector form (§3.2): with n_k the unit normal of the plane through x and the
      // edge opposite corner k (oriented as u_{k+1} x u_{k+2}) and the mean vector
      // m = sum_k theta_k / 2 n_k, w_k = (n_k . m) / (n_k . u_k) / d_k, where
      // n_k . u_k = det(u_0, u_1, u_2) / sin(theta_k). Used where x is clearly off the plane of
      // the triangle (sine of its elevation over the planes >= 1e-3); the robust angle form
      // below near the plane, where the vector form loses digits.
      const double sin0 = 2.0 * s.SinHalf[e[0]] * s.CosHalf[e[0]];
      const double sin1 = 2.0 * s.SinHalf[e[1]] * s.CosHalf[e[1]];
      const double sin2 = 2.0 * s.SinHalf[e[2]] * s.CosHalf[e[2]];
      const double largest = std::max(sin0, std::max(sin1, sin2));
      if (std::abs(det) >= 1e-3 * largest)
      {
        Vec3 n[3];
        for (int k = 0; k < 3; ++k)
        {
          n[k] = cage.FaceEdgeSign[j][(k + 1) % 3] * s.EdgeNormal[e[k]];
        }
        // (twice the paper's m: the robust form below is scaled so, and the two must agree)
        const Vec3 m = s.Theta[e[0]] * n[0] + s.Theta[e[1]] * n[1] + s.Theta[e[2]] * n[2];
        const double invDet = 1.0 / det;
        row[t[0]] += n[0].dot(m) * sin0 * invDet * s.InvR[t[0]];
        row[t[1]] += n[1].dot(m) * sin1 * invDet * s.InvR[t[1]];
        row[t[2]] += n[2].dot(m) * sin2 * invDet * s.InvR[t[2]];
        continue;
      }
    }
    const double sign = det < 0.0 ? -1.0 : 1.0;
    double c[3], sk[3];
    bool flat = false;
    for (int k = 0; k < 3; ++k)
    {
      const double sinTheta = 2.0 * s.SinHalf[e[k]] * s.CosHalf[e[k]];
      const double cosTheta = s.CosHalf[e[k]] * s.CosHalf[e[k]] - s.SinHalf[e[k]] * s.SinHalf[e[k]];
      c[k] = 2.0 * sinH * (sinH * cosTheta - cosH * sinTheta) * s.InvSin[e[(k + 1) % 3]] * s.InvSin[e[(k + 2) % 3]] - 1.0;
      sk[k] = sign * std::sqrt(std::max(0.0, (1.0 - c[k]) * (1.0 + c[k])));
      flat = flat || std::abs(sk[k]) <= 1e-10;
    }
    if (flat)
    {
      continue; // x on the plane of the triangle, outside it: no contribution
    }
    for (int k = 0; k < 3; ++k)
    {
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      const double th = s.Theta[e[k]], th1 = s.Theta[e[k1]], th2 = s.Theta[e[k2]];
      row[t[k]] += (th - c[k1] * th2 - c[k2] * th1) * s.InvR[t[k]] * s.InvSin[e[k1]] / sk[k2];
    }
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < nv; ++i)
  {
    sum += row[i];
  }
  const double inv = 1.0 / sum;
  for (std::size_t i = 0; i < nv; ++i)
  {
    row[i] *= inv;
  }
  info.Winding = windingByRay(cage, s, x);
  return info;
}

/// Green coordinates of x in closed form into row[0 .. #V) (phi) and row[#V .. #V + #F) (psi).
/// OnCage when x is on a vertex, an edge or a triangle (the integrals are singular there).
RowInfo greenRow(const CageFrame& cage, const Vec3& x, double* row, RowScratch& s)
{
  RowInfo info;
  const auto& P = cage.Mesh.Points;
  const std::size_t nv = P.size(), nf = cage.Mesh.Triangles.size();
  std::fill(row, row + nv + nf, 0.0);
  for (std::size_t i = 0; i < nv; ++i)
  {
    s.A[i] = P[i] - x;
    s.R[i] = s.A[i].norm();
    if (s.R[i] <= cage.Tiny)
    {
      info.OnCage = true;
      return info;
    }
  }
  for (std::size_t e = 0; e < cage.Edges.size(); ++e)
  {
    // f = int_a^b ds / sqrt(s^2 + D^2) = asinh(s_b / D) - asinh(s_a / D), written without
    // cancellation: R + s for s >= 0, D^2 / (R - s) for s < 0.
    const int a = cage.Edges[e][0], b = cage.Edges[e][1];
    const Vec3& tangent = cage.EdgeTangent[e];
    const double sa = s.A[a].dot(tangent), sb = s.A[b].dot(tangent);
    const double d2 = s.A[a].cross(tangent).squaredNorm();
    // (sb - sa = the edge length > 0)
    if (sa >= 0.0)
    {
      s.In[e] = (s.R[b] + sb) / (s.R[a] + sa);
    }
    else if (sb <= 0.0)
    {
      s.In[e] = (s.R[a] - sa) / (s.R[b] - sb);
    }
    else if (d2 > cage.Tiny * cage.Tiny)
    {
      s.In[e] = (s.R[b] + sb) * (s.R[a] - sa) / d2;
    }
    else
    {
      info.OnCage = true; // x on the edge
      return info;
    }
  }
  vectorLog(s.In.data(), s.F.data(), static_cast<int>(cage.Edges.size()));
  // the solid angles omega = 2 atan2(det, den) (Van Oosterom and Strackee), arctangents at once
  for (std::size_t j = 0; j < nf; ++j)
  {
    const Triangle& t = cage.Mesh.Triangles[j];
    const Vec3& a0 = s.A[t[0]];
    const Vec3& a1 = s.A[t[1]];
    const Vec3& a2 = s.A[t[2]];
    const double r0 = s.R[t[0]], r1 = s.R[t[1]], r2 = s.R[t[2]];
    const double det = a0.dot(a1.cross(a2));
    const double den = r0 * r1 * r2 + a0.dot(a1) * r2 + a1.dot(a2) * r0 + a2.dot(a0) * r1;
    const double h = -cage.Normal[j].dot(a0); // height of x over the plane
    if (std::abs(h) <= cage.Tiny && den <= 0.0)
    {
      info.OnCage = true; // x on the triangle
      return info;
    }
    s.Det[j] = det;
    s.Den[j] = den;
    s.In[j] = den != 0.0 ? det / den : 0.0;
  }
  vectorAtan(s.In.data(), s.Out.data(), static_cast<int>(nf));
  double windingSum = 0.0;
  double* phi = row;
  double* psi = row + nv;
  for (std::size_t j = 0; j < nf; ++j)
  {
    const Triangle& t = cage.Mesh.Triangles[j];
    const Vec3& a0 = s.A[t[0]];
    const double det = s.Det[j], den = s.Den[j];
    // > 0 seen from behind the triangle; in (-2 pi, 2 pi]
    const double omega = den > 0.0 ? 2.0 * s.Out[j]
      : den < 0.0                  ? 2.0 * s.Out[j] + (det >= 0.0 ? 2.0 * Pi : -2.0 * Pi)
                                   : (det > 0.0 ? Pi : (det < 0.0 ? -Pi : 0.0));
    const double h = -cage.Normal[j].dot(a0);
    windingSum += omega;
    Vec3 m = Vec3::Zero();
    double dSum = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      const double f = s.F[cage.FaceEdges[j][k]];
      const Vec3& mk = cage.EdgeNormal[j][k];
      m += f * mk;
      dSum += f * s.A[t[k]].dot(mk);
    }
    psi[j] = InvFourPi * (dSum + h * omega);
    for (int k = 0; k < 3; ++k)
    {
      const Vec3& g = cage.Gradient[j][k];
      const double hat = cage.HatAt0[j][k] + g.dot(x);
      phi[t[k]] += InvFourPi * (hat * omega + h * g.dot(m));
    }
  }
  info.Winding = windingSum * InvFourPi;
  return info;
}

/// The right-hand side of the product: deformed vertices, then (Green) s_j n'_j.
WeightMatrix rightHandSide(const CageFrame& cage, CageCoordinateKind kind, const std::vector<Vec3>& deformed)
{
  const std::size_t nv = cage.Mesh.Points.size(), nf = cage.Mesh.Triangles.size();
  WeightMatrix b(static_cast<Eigen::Index>(kind == CageCoordinateKind::Green ? nv + nf : nv), 3);
  for (std::size_t i = 0; i < nv; ++i)
  {
    b.row(static_cast<Eigen::Index>(i)) = deformed[i].transpose();
  }
  if (kind == CageCoordinateKind::Green)
  {
    const std::vector<Vec3> sn = greenScaledNormals(cage.Mesh, deformed);
    for (std::size_t j = 0; j < nf; ++j)
    {
      b.row(static_cast<Eigen::Index>(nv + j)) = sn[j].transpose();
    }
  }
  return b;
}

double secondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

const char* cageCoordinateKindName(CageCoordinateKind kind)
{
  return kind == CageCoordinateKind::Green ? "Green" : "MeanValue";
}

std::string checkCage(const TriangleMesh& cage)
{
  std::ostringstream why;
  const std::size_t nv = cage.Points.size();
  if (nv < 4 || cage.Triangles.size() < 4)
  {
    why << "the cage has " << nv << " points and " << cage.Triangles.size()
        << " triangles: a closed cage needs at least 4 of each";
    return why.str();
  }
  for (const Vec3& p : cage.Points)
  {
    if (!p.allFinite())
    {
      return "the cage has NaN or infinite coordinates";
    }
  }
  std::map<std::pair<int, int>, int> directed;
  long long degenerate = 0;
  for (const Triangle& t : cage.Triangles)
  {
    for (int k = 0; k < 3; ++k)
    {
      if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= nv)
      {
        why << "a cage triangle has the point index " << t[k] << " (the cage has " << nv << " points)";
        return why.str();
      }
    }
    const Vec3 c = (cage.Points[t[1]] - cage.Points[t[0]]).cross(cage.Points[t[2]] - cage.Points[t[0]]);
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || !(c.norm() > 0.0))
    {
      ++degenerate;
      continue;
    }
    for (int k = 0; k < 3; ++k)
    {
      ++directed[{ t[k], t[(k + 1) % 3] }];
    }
  }
  if (degenerate > 0)
  {
    why << "the cage has " << degenerate << " degenerate (zero-area) triangle(s)";
    return why.str();
  }
  long long open = 0, nonManifold = 0, inconsistent = 0;
  for (const auto& [edge, count] : directed)
  {
    const auto back = directed.find({ edge.second, edge.first });
    const int reverse = back == directed.end() ? 0 : back->second;
    if (count > 1)
    {
      ++inconsistent;
    }
    if (reverse == 0)
    {
      ++open;
    }
    else if (count + reverse > 2)
    {
      ++nonManifold;
    }
  }
  if (open > 0 || nonManifold > 0 || inconsistent > 0)
  {
    why << "the cage must be a closed, consistently oriented triangle mesh: " << open
        << " boundary edge(s), " << nonManifold << " non-manifold edge(s), " << inconsistent
        << " inconsistently oriented edge(s)";
    return why.str();
  }
  return {};
}

std::vector<Vec3> greenScaledNormals(const TriangleMesh& rest, const std::vector<Vec3>& deformed)
{
  std::vector<Vec3> out(rest.Triangles.size(), Vec3::Zero());
  for (std::size_t j = 0; j < rest.Triangles.size(); ++j)
  {
    const Triangle& t = rest.Triangles[j];
    const Vec3 u = rest.Points[t[1]] - rest.Points[t[0]];
    const Vec3 v = rest.Points[t[2]] - rest.Points[t[0]];
    const Vec3 ud = deformed[t[1]] - deformed[t[0]];
    const Vec3 vd = deformed[t[2]] - deformed[t[0]];
    const double area = 0.5 * u.cross(v).norm();
    const double num = ud.squaredNorm() * v.squaredNorm() - 2.0 * ud.dot(vd) * u.dot(v) + vd.squaredNorm() * u.squaredNorm();
    const double stretch = std::sqrt(std::max(0.0, num)) / (std::sqrt(8.0) * area);
    const Vec3 c = ud.cross(vd);
    const double cn = c.norm();
    if (cn > 0.0 && std::isfinite(stretch))
    {
      out[j] = stretch * c / cn; // a collapsed deformed triangle has no normal: no term
    }
  }
  return out;
}

struct CageDeformer::Data
{
  CageCoordinateKind Kind = CageCoordinateKind::MeanValue;
  CageFrame Cage;
  WeightMatrix Weights;         // double precision (the default)
  FloatWeightMatrix WeightsF;   // or single precision
  bool Single = false;
  std::vector<Vec3> Residual;   // single precision: x - W_float B_rest per point
  std::vector<char> Green;
  std::vector<CageDeformer::Location> Where;
  bool Bound = false;
};

CageDeformer::CageDeformer()
  : D(std::make_unique<Data>())
{
}

CageDeformer::~CageDeformer() = default;

bool CageDeformer::bound() const
{
  return this->D->Bound;
}

void CageDeformer::clear()
{
  this->D = std::make_unique<Data>();
}

CageCoordinateKind CageDeformer::kind() const
{
  return this->D->Kind;
}

std::size_t CageDeformer::numberOfPoints() const
{
  return this->D->Single ? static_cast<std::size_t>(this->D->WeightsF.rows())
                         : static_cast<std::size_t>(this->D->Weights.rows());
}

std::size_t CageDeformer::numberOfCageVertices() const
{
  return this->D->Cage.Mesh.Points.size();
}

std::size_t CageDeformer::numberOfCageTriangles() const
{
  return this->D->Cage.Mesh.Triangles.size();
}

CageBindingResult CageDeformer::bind(const TriangleMesh& restCage, const std::vector<Vec3>& points,
  const CageCoordinateOptions& options, Progress* progress)
{
  CageBindingResult result;
  this->clear();
  const auto start = std::chrono::steady_clock::now();
  const std::string problem = checkCage(restCage);
  if (!problem.empty())
  {
    result.State = Status::InvalidInput;
    result.Message = problem;
    return result;
  }
  for (const Vec3& p : points)
  {
    if (!p.allFinite())
    {
      result.State = Status::InvalidInput;
      result.Message = "the points to deform have NaN or infinite coordinates";
      return result;
    }
  }
  TriangleMesh cage = restCage;
  if (orientOutward(cage))
  {
    result.CageWasFlipped = true;
  }
  Data& d = *this->D;
  d.Kind = options.Kind;
  d.Cage.build(cage);
  const std::size_t n = points.size();
  const std::size_t nv = cage.Points.size(), nf = cage.Triangles.size();
  const std::size_t columns = options.Kind == CageCoordinateKind::Green ? nv + nf : nv;
  d.Single = options.SinglePrecision;
  result.WeightBytes = (d.Single ? 4.0 : 8.0) * static_cast<double>(n) * static_cast<double>(columns);
  try
  {
    if (d.Single)
    {
      d.WeightsF.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(columns));
    }
    else
    {
      d.Weights.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(columns));
    }
    d.Green.assign(n, 0);
    d.Where.assign(n, Location::Inside);
  }
  catch (const std::bad_alloc&)
  {
    this->clear();
    std::ostringstream why;
    why << "not enough memory for the weights: " << n << " points x " << columns << " columns = "
        << result.WeightBytes / 1e9 << " GB";
    result.State = Status::Failed;
    result.Message = why.str();
    return result;
  }

  progressStage(progress, "cage coordinates", 0.0, 1.0);
  std::atomic<long long> outside{ 0 }, onCage{ 0 }, fallbacks{ 0 }, done{ 0 };
  std::atomic<bool> cancelled{ false };
  {
    ThreadLimit limit(options.NumberOfThreads);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& range) {
      if (cancelled.load() || progressCancelled(progress))
      {
        cancelled.store(true);
        return;
      }
      RowScratch scratch;
      scratch.resize(nv, d.Cage.Edges.size(), nf);
      for (std::size_t p = range.begin(); p != range.end(); ++p)
      {
        double* row = d.Single ? scratch.Row.data() : d.Weights.row(static_cast<Eigen::Index>(p)).data();
        RowInfo info;
        bool useGreen = false;
        if (options.Kind == CageCoordinateKind::Green)
        {
          info = greenRow(d.Cage, points[p], row, scratch);
          useGreen = !info.OnCage && info.Winding > 0.5;
          for (std::size_t c = 0; useGreen && c < columns; ++c)
          {
            useGreen = std::isfinite(row[c]);
          }
          if (!useGreen)
          {
            std::fill(row, row + columns, 0.0);
            ++fallbacks;
          }
        }
        if (!useGreen)
        {
          const bool greenOnCage = info.OnCage;
          info = meanValueRow(d.Cage, points[p], row, scratch);
          info.OnCage = info.OnCage || greenOnCage;
        }
        if (d.Single)
        {
          float* stored = d.WeightsF.row(static_cast<Eigen::Index>(p)).data();
          for (std::size_t c = 0; c < columns; ++c)
          {
            stored[c] = static_cast<float>(row[c]);
          }
        }
        d.Green[p] = useGreen ? 1 : 0;
        if (info.OnCage)
        {
          ++onCage;
          d.Where[p] = Location::OnCage;
        }
        else if (info.Winding < 0.5)
        {
          ++outside;
          d.Where[p] = Location::Outside;
        }
      }
      const long long finished = done.fetch_add(static_cast<long long>(range.size())) + static_cast<long long>(range.size());
      progressUpdate(progress, static_cast<double>(finished) / static_cast<double>(n));
    });
  }
  if (cancelled.load() || progressCancelled(progress))
  {
    this->clear();
    result.State = Status::Cancelled;
    result.Message = "cancelled";
    return result;
  }
  result.PointsOutside = outside.load();
  result.PointsOnCage = onCage.load();
  result.MeanValueFallbacks = fallbacks.load();
  d.Bound = true;

  // identity reproduction: the weights applied to the rest cage give the points back (single
  // precision: before the per-point correction, which then makes it exact)
  std::vector<Vec3> again;
  this->apply(cage.Points, again, options.NumberOfThreads);
  if (d.Single)
  {
    d.Residual.resize(n);
    for (std::size_t p = 0; p < n; ++p)
    {
      d.Residual[p] = points[p] - again[p];
    }
  }
  double worst = 0.0;
  for (std::size_t p = 0; p < n; ++p)
  {
    const double e = (again[p] - points[p]).norm();
    worst = std::isfinite(e) ? std::max(worst, e) : std::numeric_limits<double>::infinity();
  }
  result.ReproductionError = d.Cage.Diagonal > 0.0 ? worst / d.Cage.Diagonal : worst;
  result.WeightTime = secondsSince(start);
  return result;
}

bool CageDeformer::apply(const std::vector<Vec3>& deformedCagePoints, std::vector<Vec3>& out, int numberOfThreads) const
{
  out.clear();
  const Data& d = *this->D;
  if (!d.Bound || deformedCagePoints.size() != d.Cage.Mesh.Points.size())
  {
    return false;
  }
  const WeightMatrix b = rightHandSide(d.Cage, d.Kind, deformedCagePoints);
  const Eigen::Index n = static_cast<Eigen::Index>(this->numberOfPoints());
  out.resize(static_cast<std::size_t>(n));
  const bool corrected = d.Single && d.Residual.size() == static_cast<std::size_t>(n);
  ThreadLimit limit(numberOfThreads);
  // One pass over the weights, row by row: the three dot products of a row in one vectorized
  // loop (VectorMath), the columns of b contiguous. Memory bound: the weights are read once per
  // apply.
  const Eigen::Matrix<double, Eigen::Dynamic, 3> columns = b; // column-major copy
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 512), [&](const tbb::blocked_range<Eigen::Index>& r) {
    for (Eigen::Index i = r.begin(); i != r.end(); ++i)
    {
      Vec3& y = out[static_cast<std::size_t>(i)];
      if (d.Single)
      {
        double v[3];
        floatRowTimes3(d.WeightsF.row(i).data(), columns.col(0).data(), columns.col(1).data(), columns.col(2).data(),
          static_cast<int>(columns.rows()), v);
        y = Vec3(v[0], v[1], v[2]);
        if (corrected)
        {
          y += d.Residual[static_cast<std::size_t>(i)];
        }
      }
      else
      {
        double v[3];
        rowTimes3(d.Weights.row(i).data(), columns.col(0).data(), columns.col(1).data(), columns.col(2).data(),
          static_cast<int>(columns.rows()), v);
        y = Vec3(v[0], v[1], v[2]);
      }
    }
  });
  return true;
}

std::vector<double> CageDeformer::weights(std::size_t p) const
{
  if (this->D->Single)
  {
    const auto row = this->D->WeightsF.row(static_cast<Eigen::Index>(p));
    return std::vector<double>(row.data(), row.data() + row.size());
  }
  const auto row = this->D->Weights.row(static_cast<Eigen::Index>(p));
  return std::vector<double>(row.data(), row.data() + row.size());
}

bool CageDeformer::usesGreen(std::size_t p) const
{
  return this->D->Green[p] != 0;
}

CageDeformer::Location CageDeformer::location(std::size_t p) const
{
  return this->D->Where[p];
}

} // namespace sdfcage
