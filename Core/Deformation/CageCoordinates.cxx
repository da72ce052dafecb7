// SDFCage — Core: mean value and Green cage coordinates (see CageCoordinates.h for the formulas).
#include "Deformation/CageCoordinates.h"

#include "Common/Threads.h"

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

/// The rest cage with everything a weight row needs that depends on the cage only.
struct CageFrame
{
  TriangleMesh Mesh;
  std::vector<std::array<int, 2>> Edges;      // unique undirected edges
  std::vector<std::array<int, 3>> FaceEdges;  // edge of corners (k, k+1)
  std::vector<Vec3> EdgeTangent;              // unit, from Edges[e][0] to Edges[e][1]
  std::vector<Vec3> Normal;                   // unit outward normal per triangle
  std::vector<std::array<Vec3, 3>> Gradient;  // in-plane gradient of each corner's hat function
  std::vector<std::array<double, 3>> HatAt0;  // Gamma_k(0) = 1 - g_k . p_k
  std::vector<std::array<Vec3, 3>> EdgeNormal; // outward in-plane normal of edge (k, k+1)
  double Diagonal = 0.0;
  double Tiny = 0.0; // lengths below this count as zero (1e-12 x the diagonal)

  void build(const TriangleMesh& cage)
  {
    this->Mesh = cage;
    const auto& P = this->Mesh.Points;
    const std::size_t nf = this->Mesh.Triangles.size();
    std::map<std::pair<int, int>, int> edgeIds;
    this->FaceEdges.resize(nf);
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
  }
};

/// Per-thread scratch of one weight row.
struct RowScratch
{
  std::vector<Vec3> A;      // v_i - x
  std::vector<double> R;    // |v_i - x|
  std::vector<Vec3> U;      // unit vectors (MVC)
  std::vector<double> Theta, SinTheta, CosTheta; // per edge (MVC)
  std::vector<double> F;    // per edge line integral of 1/R (Green)
  void resize(std::size_t nv, std::size_t ne)
  {
    this->A.resize(nv);
    this->R.resize(nv);
    this->U.resize(nv);
    this->Theta.resize(ne);
    this->SinTheta.resize(ne);
    this->CosTheta.resize(ne);
    this->F.resize(ne);
  }
};

struct RowInfo
{
  bool OnCage = false;
  double Winding = 0.0;
};

/// Mean value coordinates of x (Ju, Schaefer, Warren 2005, the robust pseudo-code of §3.3) into
/// row[0 .. #V). Also the winding number of the cage at x.
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
    s.U[i] = s.A[i] / s.R[i];
  }
  for (std::size_t e = 0; e < cage.Edges.size(); ++e)
  {
    // theta = 2 asin(l / 2) with l = |u_a - u_b|, written as 2 atan2(l, m) with m = |u_a + u_b|
    // (l^2 + m^2 = 4): well conditioned up to theta = pi, where asin loses half the digits
    const double l = (s.U[cage.Edges[e][0]] - s.U[cage.Edges[e][1]]).norm();
    const double m = (s.U[cage.Edges[e][0]] + s.U[cage.Edges[e][1]]).norm();
    s.Theta[e] = 2.0 * std::atan2(l, m);
    s.SinTheta[e] = 0.5 * l * m;
    s.CosTheta[e] = 0.25 * (m * m - l * l);
  }
  double windingSum = 0.0;
  for (std::size_t j = 0; j < cage.Mesh.Triangles.size(); ++j)
  {
    const Triangle& t = cage.Mesh.Triangles[j];
    // theta[k]: the angle at x of the edge opposite corner k = edge (k+1, k+2)
    double th[3], sn[3], cs[3];
    for (int k = 0; k < 3; ++k)
    {
      const int e = cage.FaceEdges[j][(k + 1) % 3];
      th[k] = s.Theta[e];
      sn[k] = s.SinTheta[e];
      cs[k] = s.CosTheta[e];
    }
    const double det = s.U[t[0]].dot(s.U[t[1]].cross(s.U[t[2]]));
    windingSum += 2.0 * std::atan2(det, 1.0 + cs[0] + cs[1] + cs[2]);
    const double h = 0.5 * (th[0] + th[1] + th[2]);
    if (Pi - h < 1e-10)
    {
      // x lies on this triangle: linear interpolation of its corners (2D barycentric weights)
      std::fill(row, row + nv, 0.0);
      double sum = 0.0;
      double w[3];
      for (int k = 0; k < 3; ++k)
      {
        w[k] = sn[k] * s.R[t[(k + 1) % 3]] * s.R[t[(k + 2) % 3]];
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
    if (sn[0] < 1e-12 || sn[1] < 1e-12 || sn[2] < 1e-12)
    {
      continue; // x on the line of an edge, outside the triangle: its plane holds x
    }
    const double sinH = std::sin(h), cosH = std::cos(h);
    const double sign = det < 0.0 ? -1.0 : 1.0;
    double c[3], sk[3];
    bool flat = false;
    for (int k = 0; k < 3; ++k)
    {
      const double sinHMinusTheta = sinH * cs[k] - cosH * sn[k];
      c[k] = 2.0 * sinH * sinHMinusTheta / (sn[(k + 1) % 3] * sn[(k + 2) % 3]) - 1.0;
      sk[k] = sign * std::sqrt(std::max(0.0, 1.0 - c[k] * c[k]));
      flat = flat || std::abs(sk[k]) <= 1e-10;
    }
    if (flat)
    {
      continue; // x on the plane of the triangle, outside it: no contribution
    }
    for (int k = 0; k < 3; ++k)
    {
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      row[t[k]] += (th[k] - c[k1] * th[k2] - c[k2] * th[k1]) / (s.R[t[k]] * sn[k1] * sk[k2]);
    }
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < nv; ++i)
  {
    sum += row[i];
  }
  for (std::size_t i = 0; i < nv; ++i)
  {
    row[i] /= sum;
  }
  info.Winding = windingSum * InvFourPi;
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
      s.F[e] = std::log((s.R[b] + sb) / (s.R[a] + sa));
    }
    else if (sb <= 0.0)
    {
      s.F[e] = std::log((s.R[a] - sa) / (s.R[b] - sb));
    }
    else if (d2 > cage.Tiny * cage.Tiny)
    {
      s.F[e] = std::log((s.R[b] + sb) * (s.R[a] - sa) / d2);
    }
    else
    {
      info.OnCage = true; // x on the edge
      return info;
    }
  }
  double windingSum = 0.0;
  double* phi = row;
  double* psi = row + nv;
  for (std::size_t j = 0; j < nf; ++j)
  {
    const Triangle& t = cage.Mesh.Triangles[j];
    const Vec3& a0 = s.A[t[0]];
    const Vec3& a1 = s.A[t[1]];
    const Vec3& a2 = s.A[t[2]];
    const double r0 = s.R[t[0]], r1 = s.R[t[1]], r2 = s.R[t[2]];
    const double det = a0.dot(a1.cross(a2));
    const double den = r0 * r1 * r2 + a0.dot(a1) * r2 + a1.dot(a2) * r0 + a2.dot(a0) * r1;
    const double omega = 2.0 * std::atan2(det, den); // > 0 seen from behind the triangle
    const double h = -cage.Normal[j].dot(a0);         // height of x over the plane
    if (std::abs(h) <= cage.Tiny && den <= 0.0)
    {
      info.OnCage = true; // x on the triangle
      return info;
    }
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
  WeightMatrix Weights;
  std::vector<char> Green;
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
  return static_cast<std::size_t>(this->D->Weights.rows());
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
  if (signedVolume(cage) < 0.0)
  {
    for (Triangle& t : cage.Triangles)
    {
      std::swap(t[1], t[2]);
    }
    result.CageWasFlipped = true;
  }
  Data& d = *this->D;
  d.Kind = options.Kind;
  d.Cage.build(cage);
  const std::size_t n = points.size();
  const std::size_t nv = cage.Points.size(), nf = cage.Triangles.size();
  const std::size_t columns = options.Kind == CageCoordinateKind::Green ? nv + nf : nv;
  result.WeightBytes = 8.0 * static_cast<double>(n) * static_cast<double>(columns);
  try
  {
    d.Weights.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(columns));
    d.Green.assign(n, 0);
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
      scratch.resize(nv, d.Cage.Edges.size());
      for (std::size_t p = range.begin(); p != range.end(); ++p)
      {
        double* row = d.Weights.row(static_cast<Eigen::Index>(p)).data();
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
        d.Green[p] = useGreen ? 1 : 0;
        if (info.OnCage)
        {
          ++onCage;
        }
        else if (info.Winding < 0.5)
        {
          ++outside;
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

  // identity reproduction: the weights applied to the rest cage give the points back
  std::vector<Vec3> again;
  this->apply(cage.Points, again, options.NumberOfThreads);
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
  const Eigen::Index n = d.Weights.rows();
  out.resize(static_cast<std::size_t>(n));
  ThreadLimit limit(numberOfThreads);
  // Row blocks of the product on every thread (each block one small GEMM).
  const Eigen::Index block = 256;
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, (n + block - 1) / block), [&](const tbb::blocked_range<Eigen::Index>& r) {
    for (Eigen::Index blk = r.begin(); blk != r.end(); ++blk)
    {
      const Eigen::Index first = blk * block;
      const Eigen::Index count = std::min(block, n - first);
      const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> y = d.Weights.middleRows(first, count) * b;
      for (Eigen::Index i = 0; i < count; ++i)
      {
        out[static_cast<std::size_t>(first + i)] = y.row(i).transpose();
      }
    }
  });
  return true;
}

std::vector<double> CageDeformer::weights(std::size_t p) const
{
  const auto row = this->D->Weights.row(static_cast<Eigen::Index>(p));
  return std::vector<double>(row.data(), row.data() + row.size());
}

bool CageDeformer::usesGreen(std::size_t p) const
{
  return this->D->Green[p] != 0;
}

} // namespace sdfcage
