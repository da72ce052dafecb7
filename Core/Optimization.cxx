#include "Optimization.h"

#include "Geometry.h"
#include "Normalization.h"
#include "Progress.h"
#include "TriangleTree.h"
#include "Validation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>

namespace sdfcage
{

const char* energyName(CageEnergy e)
{
  return e == CageEnergy::Spacing ? "Spacing" : "MIPS";
}

namespace
{

constexpr double Inf = std::numeric_limits<double>::infinity();
// Neighbouring cage triangles whose dihedral angle closes below ~18 degrees count as folded (the
// simplifier's threshold).
constexpr double FoldCosine = -0.95;
// Conservative advancement: each sub-step covers this fraction of the current gap.
constexpr double AdvanceFraction = 0.9;
constexpr int MaximumSubsteps = 16;
// Backtracking halvings of the line search.
constexpr int LineSearchTries = 8;
// The first trial step of the line search, relative to the mean edge length around the vertex.
constexpr double InitialStep = 0.25;
// The default clearance at the default isovalue (c / 4), for Clearance <= 0.
constexpr double DefaultClearance = 0.0025;

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// IPC barrier b(g, d̂) = -(g - d̂)^2 ln(g / d̂) for 0 < g < d̂ (eq. 7), and its derivative.
double barrier(double g, double dh)
{
  if (g >= dh)
    return 0.0;
  if (!(g > 0.0))
    return Inf;
  return -(g - dh) * (g - dh) * std::log(g / dh);
}
double barrierDerivative(double g, double dh)
{
  if (g >= dh || !(g > 0.0))
    return 0.0;
  return -2.0 * (g - dh) * std::log(g / dh) - (g - dh) * (g - dh) / g;
}

double triangleQuality(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const double area2 = (b - a).cross(c - a).norm();
  const double s = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return s > 0 ? 2.0 * std::sqrt(3.0) * area2 / s : 0.0;
}

/// MIPS with an equilateral reference, sum(l^2) / (2 sqrt(3) A), and its gradient with respect
/// to the first corner v (the triangle is (v, a, b), counter-clockwise).
double mips(const Vec3& v, const Vec3& a, const Vec3& b, Vec3* grad)
{
  const Vec3 n = (a - v).cross(b - v);
  const double a2 = n.norm(); // twice the area
  const double s = (a - v).squaredNorm() + (b - a).squaredNorm() + (v - b).squaredNorm();
  if (!(a2 > 0))
    return Inf;
  const double k = 1.0 / std::sqrt(3.0);
  const double e = k * s / a2;
  if (grad)
  {
    const Vec3 ds = 2.0 * (2.0 * v - a - b);
    const Vec3 da2 = (a - b).cross(n / a2);
    *grad = k * ds / a2 - k * s / (a2 * a2) * da2;
  }
  return e;
}

/// The 3-point degree-2 rule on a triangle: barycentric (2/3, 1/6, 1/6) and its rotations,
/// weight 1/3 each.
const double SpacingRule[3][3] = { { 2.0 / 3, 1.0 / 6, 1.0 / 6 }, { 1.0 / 6, 2.0 / 3, 1.0 / 6 },
  { 1.0 / 6, 1.0 / 6, 2.0 / 3 } };

/// Spacing energy of triangle (v, a, b): A * mean over the rule of (xi - h)^2, and its gradient
/// with respect to v (xi is 1-Lipschitz with gradient (x - y)/|x - y| outside the input).
double spacing(const Vec3& v, const Vec3& a, const Vec3& b, const TriangleTree& tree, double h, Vec3* grad)
{
  const Vec3 n = (a - v).cross(b - v);
  const double a2 = n.norm();
  const double area = 0.5 * a2;
  double mean = 0.0;
  Vec3 g = Vec3::Zero();
  for (const auto& w : SpacingRule)
  {
    const Vec3 x = w[0] * v + w[1] * a + w[2] * b;
    Vec3 y;
    int tri;
    double d;
    if (!tree.closestPoint(x, -1.0, y, tri, d))
      continue;
    mean += (d - h) * (d - h) / 3.0;
    if (grad && d > 0)
      g += (2.0 * (d - h) * w[0] / 3.0) * (x - y) / d;
  }
  if (grad)
  {
    const Vec3 dArea = a2 > 0 ? Vec3(0.5 * (a - b).cross(n / a2)) : Vec3(Vec3::Zero());
    *grad = dArea * mean + area * g;
  }
  return area * mean;
}

double triangleEnergy(const Vec3& a, const Vec3& b, const Vec3& c, const TriangleTree& tree, const OptimizeOptions& o)
{
  return o.Energy == CageEnergy::Spacing ? spacing(a, b, c, tree, o.TargetSpacing, nullptr) : mips(a, b, c, nullptr);
}

/// A bounding sphere of a triangle (centroid, farthest corner): distances between two
/// triangles are at least |c1 - c2| - r1 - r2.
struct Sphere
{
  Vec3 C;
  double R;
};
Sphere boundingSphere(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const Vec3 m = (a + b + c) / 3.0;
  return { m, std::sqrt(std::max({ (a - m).squaredNorm(), (b - m).squaredNorm(), (c - m).squaredNorm() })) };
}

std::uint64_t edgeKey(int a, int b)
{
  if (a > b)
    std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

/// The optimizer's working state: the cage with vertex-triangle adjacency and cached boxes.
class Optimizer
{
public:
  Optimizer(const TriangleMesh& cage, const TriangleMesh& input, const TriangleTree& tree, const OptimizeOptions& o,
    double clearance, double selfClearance, Progress* progress)
    : Input(input)
    , Tree(tree)
    , Opt(o)
    , Delta(clearance)
    , SelfDelta(selfClearance)
    , Prog(progress)
  {
    P = cage.Points;
    T = cage.Triangles;
    VT.assign(P.size(), {});
    for (std::size_t f = 0; f < T.size(); ++f)
      for (int v : T[f])
        VT[v].push_back(static_cast<int>(f));
    Lo.resize(T.size());
    Hi.resize(T.size());
    for (std::size_t f = 0; f < T.size(); ++f)
      updateBox(static_cast<int>(f));
  }

  TriangleMesh mesh() const
  {
    TriangleMesh m;
    m.Points = P;
    m.Triangles = T;
    return m;
  }

  /// One relocation pass over every vertex. Returns false when cancelled.
  bool relocationPass(OptimizeResult& r, double progressBegin, double progressEnd)
  {
    for (std::size_t v = 0; v < P.size(); ++v)
    {
      if (v % 32 == 0 && Prog &&
        Prog->update(progressBegin + (progressEnd - progressBegin) * double(v) / double(P.size())))
        return false;
      if (VT[v].empty())
        continue;
      for (int step = 0; step < std::max(1, Opt.DescentSteps); ++step)
      {
        const int outcome = descend(static_cast<int>(v));
        if (outcome > 0)
          ++r.Moves;
        else
        {
          if (outcome < 0)
            ++r.RejectedMoves;
          break;
        }
      }
    }
    return true;
  }

  /// One pass over the edges: flip where E_quality drops and every constraint holds.
  bool flipPass(OptimizeResult& r)
  {
    std::vector<std::uint64_t> edges;
    for (const Triangle& t : T)
      for (int k = 0; k < 3; ++k)
        if (t[k] < t[(k + 1) % 3])
          edges.push_back(edgeKey(t[k], t[(k + 1) % 3]));
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i < edges.size(); ++i)
    {
      if (i % 64 == 0 && progressCancelled(Prog))
        return false;
      const int a = static_cast<int>(edges[i] >> 32), b = static_cast<int>(edges[i] & 0xFFFFFFFFu);
      const int outcome = tryFlip(a, b);
      if (outcome > 0)
        ++r.Flips;
      else if (outcome < 0)
        ++r.RejectedFlips;
    }
    return true;
  }

  // ---- continuous collision detection (also used through collisionFreeFraction) ---------------

  /// Everything near vertex v that a move of length up to `reach` can involve.
  struct Local
  {
    int V = -1;
    Vec3 P0;
    std::vector<int> Ring;           ///< triangles around v
    std::vector<std::array<int, 3>> RingIds; ///< rotated so v comes first
    std::vector<int> InputTris;      ///< input triangles within δ + d̂ + reach of the ring
    std::vector<int> CageTris;       ///< other cage triangles within selfδ + d̂ + reach
    std::vector<Sphere> InputSpheres, CageSpheres;
    /// Lower bounds on the distance at P0 between ring triangle i and candidate j (exact where
    /// it could matter, index i * count + j); the cage one is infinite for pairs sharing a vertex.
    std::vector<double> InputD0, CageD0;
    std::vector<Sphere> BTriSpheres;
    // barrier primitives (cage ones share no vertex with the closed star of v)
    std::vector<std::array<Vec3, 3>> BTri; ///< vs the point v
    std::vector<double> BTriMargin;
    std::vector<std::array<Vec3, 2>> BEdge; ///< vs the edges (v, w)
    std::vector<double> BEdgeMargin;
    std::vector<Vec3> BPoint;         ///< vs the ring triangles
    std::vector<double> BPointMargin;
    double MeanEdge = 0.0;
  };

  void gather(int v, double reach, Local& L) const
  {
    L = Local();
    L.V = v;
    L.P0 = P[v];
    L.Ring = VT[v];
    std::vector<int> star{ v };
    double edgeSum = 0.0;
    for (int f : L.Ring)
    {
      const Triangle& t = T[f];
      int k = 0;
      while (t[k] != v)
        ++k;
      L.RingIds.push_back({ v, t[(k + 1) % 3], t[(k + 2) % 3] });
      star.push_back(t[(k + 1) % 3]);
      edgeSum += (P[t[(k + 1) % 3]] - P[v]).norm();
    }
    std::sort(star.begin(), star.end());
    star.erase(std::unique(star.begin(), star.end()), star.end());
    L.MeanEdge = edgeSum / std::max<std::size_t>(1, L.Ring.size());
    auto inStar = [&](int w) { return std::binary_search(star.begin(), star.end(), w); };

    const double dh = std::max(0.0, Opt.BarrierDistance);
    const double inputRadius = Delta + dh + reach;
    const double cageRadius = SelfDelta + dh + reach;
    Vec3 ringLo = Vec3::Constant(Inf), ringHi = -ringLo;
    for (const auto& ids : L.RingIds)
    {
      Vec3 pts[3] = { P[ids[0]], P[ids[1]], P[ids[2]] };
      Tree.trianglesWithin(pts, inputRadius, L.InputTris);
      for (const Vec3& q : pts)
      {
        ringLo = ringLo.cwiseMin(q);
        ringHi = ringHi.cwiseMax(q);
      }
    }
    std::sort(L.InputTris.begin(), L.InputTris.end());
    L.InputTris.erase(std::unique(L.InputTris.begin(), L.InputTris.end()), L.InputTris.end());
    const Vec3 lo = ringLo - Vec3::Constant(cageRadius), hi = ringHi + Vec3::Constant(cageRadius);
    const std::size_t nr = L.RingIds.size();
    std::vector<Sphere> ringSpheres(nr);
    for (std::size_t i = 0; i < nr; ++i)
      ringSpheres[i] = boundingSphere(P[L.RingIds[i][0]], P[L.RingIds[i][1]], P[L.RingIds[i][2]]);
    // the lower bound of a pair is made exact only when it could limit a move of `reach`
    auto lowerBound = [&](std::size_t i, const Vec3 q[3], const Sphere& sq, double margin) {
      const double lb = (sq.C - ringSpheres[i].C).norm() - sq.R - ringSpheres[i].R;
      if (lb - margin >= reach / AdvanceFraction + dh)
        return lb;
      const Vec3 rp[3] = { P[L.RingIds[i][0]], P[L.RingIds[i][1]], P[L.RingIds[i][2]] };
      return std::sqrt(triangleTriangleDistance2(rp, q));
    };
    std::vector<double> d0(nr);
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      if ((Lo[f].array() > hi.array()).any() || (Hi[f].array() < lo.array()).any())
        continue;
      const Triangle& t = T[f];
      if (t[0] == v || t[1] == v || t[2] == v)
        continue;
      const Vec3 pts[3] = { P[t[0]], P[t[1]], P[t[2]] };
      const Sphere sf = boundingSphere(pts[0], pts[1], pts[2]);
      bool near = false;
      for (std::size_t i = 0; i < nr; ++i)
      {
        const auto& ids = L.RingIds[i];
        const bool shares = t[0] == ids[1] || t[0] == ids[2] || t[1] == ids[1] || t[1] == ids[2] ||
          t[2] == ids[1] || t[2] == ids[2];
        d0[i] = lowerBound(i, pts, sf, SelfDelta);
        near = near || d0[i] < cageRadius;
        if (shares)
          d0[i] = Inf;
      }
      if (near)
      {
        L.CageTris.push_back(static_cast<int>(f));
        L.CageSpheres.push_back(sf);
        L.CageD0.insert(L.CageD0.end(), d0.begin(), d0.end());
      }
    }
    const std::size_t nc = L.CageTris.size();
    // CageD0 was filled candidate-major: transpose to ring-major
    std::vector<double> cd(nr * nc);
    for (std::size_t j = 0; j < nc; ++j)
      for (std::size_t i = 0; i < nr; ++i)
        cd[i * nc + j] = L.CageD0[j * nr + i];
    L.CageD0.swap(cd);
    const std::size_t ni = L.InputTris.size();
    L.InputD0.resize(nr * ni);
    for (std::size_t j = 0; j < ni; ++j)
    {
      const Triangle& t = Input.Triangles[L.InputTris[j]];
      const Vec3 q[3] = { Input.Points[t[0]], Input.Points[t[1]], Input.Points[t[2]] };
      L.InputSpheres.push_back(boundingSphere(q[0], q[1], q[2]));
      for (std::size_t i = 0; i < nr; ++i)
        L.InputD0[i * ni + j] = lowerBound(i, q, L.InputSpheres[j], Delta);
    }

    // barrier primitives, each counted once
    if (!(dh > 0))
      return;
    std::vector<std::pair<std::uint64_t, int>> edges; // key, 0 input / 1 cage
    std::vector<std::pair<int, int>> points;          // id, 0 input / 1 cage
    for (int f : L.InputTris)
    {
      const Triangle& t = Input.Triangles[f];
      L.BTri.push_back({ Input.Points[t[0]], Input.Points[t[1]], Input.Points[t[2]] });
      L.BTriMargin.push_back(Delta);
      L.BTriSpheres.push_back(boundingSphere(Input.Points[t[0]], Input.Points[t[1]], Input.Points[t[2]]));
      for (int k = 0; k < 3; ++k)
      {
        edges.push_back({ edgeKey(t[k], t[(k + 1) % 3]), 0 });
        points.push_back({ t[k], 0 });
      }
    }
    for (int f : L.CageTris)
    {
      const Triangle& t = T[f];
      if (inStar(t[0]) || inStar(t[1]) || inStar(t[2]))
        continue;
      L.BTri.push_back({ P[t[0]], P[t[1]], P[t[2]] });
      L.BTriMargin.push_back(SelfDelta);
      L.BTriSpheres.push_back(boundingSphere(P[t[0]], P[t[1]], P[t[2]]));
      for (int k = 0; k < 3; ++k)
      {
        edges.push_back({ edgeKey(t[k], t[(k + 1) % 3]), 1 });
        points.push_back({ t[k], 1 });
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());
    for (const auto& e : edges)
    {
      const int a = static_cast<int>(e.first >> 32), b = static_cast<int>(e.first & 0xFFFFFFFFu);
      const auto& pts = e.second == 0 ? Input.Points : P;
      L.BEdge.push_back({ pts[a], pts[b] });
      L.BEdgeMargin.push_back(e.second == 0 ? Delta : SelfDelta);
    }
    for (const auto& q : points)
    {
      L.BPoint.push_back(q.second == 0 ? Input.Points[q.first] : P[q.first]);
      L.BPointMargin.push_back(q.second == 0 ? Delta : SelfDelta);
    }
  }

  /// Smallest gap (distance minus the distance the pair must keep) between the ring at v = p and
  /// the gathered input and cage triangles (cage ones sharing no vertex with the ring triangle).
  /// Gaps at or above `enough` are not resolved exactly (the caller needs no more). A pair's
  /// distance at p is at least its distance at P0 minus |p - P0| (1-Lipschitz, see advance()).
  double minimumGap(const Local& L, const Vec3& p, double enough) const
  {
    double gap = enough;
    const double moved = (p - L.P0).norm();
    const std::size_t ni = L.InputTris.size(), nc = L.CageTris.size();
    for (std::size_t r = 0; r < L.RingIds.size(); ++r)
    {
      const auto& ids = L.RingIds[r];
      const Vec3 rp[3] = { p, P[ids[1]], P[ids[2]] };
      const Sphere sr = boundingSphere(rp[0], rp[1], rp[2]);
      for (std::size_t i = 0; i < ni; ++i)
      {
        if (L.InputD0[r * ni + i] - moved - Delta >= gap)
          continue;
        const Sphere& sq = L.InputSpheres[i];
        if ((sq.C - sr.C).norm() - sq.R - sr.R - Delta >= gap)
          continue;
        const Triangle& t = Input.Triangles[L.InputTris[i]];
        const Vec3 q[3] = { Input.Points[t[0]], Input.Points[t[1]], Input.Points[t[2]] };
        gap = std::min(gap, std::sqrt(triangleTriangleDistance2(rp, q)) - Delta);
      }
      for (std::size_t i = 0; i < nc; ++i)
      {
        if (L.CageD0[r * nc + i] - moved - SelfDelta >= gap) // also skips pairs sharing a vertex
          continue;
        const Sphere& sq = L.CageSpheres[i];
        if ((sq.C - sr.C).norm() - sq.R - sr.R - SelfDelta >= gap)
          continue;
        const Triangle& t = T[L.CageTris[i]];
        const Vec3 q[3] = { P[t[0]], P[t[1]], P[t[2]] };
        gap = std::min(gap, std::sqrt(triangleTriangleDistance2(rp, q)) - SelfDelta);
      }
    }
    return gap;
  }

  /// Conservative advancement. Every point of a ring triangle moves by its barycentric weight of
  /// v times the displacement of v, so by at most |move| t over a fraction t of the move: every
  /// pair distance is 1-Lipschitz in |move| t. From a position whose smallest gap is g > 0, a
  /// sub-step of length AdvanceFraction * g therefore keeps every gap >= (1 - AdvanceFraction) g
  /// > 0 along the whole sub-step; pairs not gathered start farther than their margin + reach and
  /// cannot close in. The result is the sum of the sub-steps (at most MaximumSubsteps).
  double advance(const Local& L, const Vec3& move) const
  {
    const double len = move.norm();
    if (!(len > 0))
      return 1.0;
    double t = 0.0;
    for (int k = 0; k < MaximumSubsteps; ++k)
    {
      // gaps beyond the rest of the move (with the sub-step factor) allow it whole
      const double rest = (1.0 - t) * len / AdvanceFraction;
      const double gap = minimumGap(L, L.P0 + t * move, rest * (1.0 + 1e-9) + 1e-300);
      if (!(gap > 0))
        return k == 0 ? 0.0 : t; // only at the start (a given cage that already violates a margin)
      const double s = AdvanceFraction * gap / len;
      if (t + s >= 1.0)
        return 1.0;
      t += s;
    }
    return t;
  }

  // ---- energy of one vertex -------------------------------------------------------------------

  double vertexEnergy(const Local& L, const Vec3& p, Vec3* grad) const
  {
    double e = 0.0;
    Vec3 g = Vec3::Zero();
    Vec3 gt;
    for (const auto& ids : L.RingIds)
    {
      const Vec3& a = P[ids[1]];
      const Vec3& b = P[ids[2]];
      e += Opt.Energy == CageEnergy::Spacing ? spacing(p, a, b, Tree, Opt.TargetSpacing, grad ? &gt : nullptr)
                                             : mips(p, a, b, grad ? &gt : nullptr);
      if (grad)
        g += gt;
    }
    const double dh = Opt.BarrierDistance;
    const double lambda = Opt.BarrierWeight;
    if (dh > 0 && lambda > 0)
    {
      double B = 0.0;
      Vec3 gb = Vec3::Zero();
      auto add = [&](double d, double margin, const Vec3& dddp) {
        const double gap = d - margin;
        if (gap >= dh)
          return;
        B += barrier(gap, dh);
        if (grad)
          gb += barrierDerivative(gap, dh) * dddp;
      };
      // point v vs triangles
      for (std::size_t i = 0; i < L.BTri.size(); ++i)
      {
        const auto& q = L.BTri[i];
        if ((p - L.BTriSpheres[i].C).norm() - L.BTriSpheres[i].R - L.BTriMargin[i] >= dh)
          continue;
        const Vec3 y = closestPointOnTriangle(p, q[0], q[1], q[2]);
        const double d = (p - y).norm();
        add(d, L.BTriMargin[i], d > 0 ? Vec3((p - y) / d) : Vec3(Vec3::Zero()));
      }
      // edges (v, w) vs edges
      for (const auto& ids : L.RingIds)
      {
        const Vec3& w = P[ids[1]]; // each edge (v, w) is the first edge of exactly one ring triangle
        const Vec3 mid = 0.5 * (p + w);
        const double half = 0.5 * (w - p).norm();
        for (std::size_t i = 0; i < L.BEdge.size(); ++i)
        {
          const Vec3 emid = 0.5 * (L.BEdge[i][0] + L.BEdge[i][1]);
          if ((emid - mid).norm() - half - 0.5 * (L.BEdge[i][1] - L.BEdge[i][0]).norm() - L.BEdgeMargin[i] >= dh)
            continue;
          double s, t;
          const double d = std::sqrt(segmentSegmentClosest(p, w, L.BEdge[i][0], L.BEdge[i][1], s, t));
          const Vec3 x = p + s * (w - p), y = L.BEdge[i][0] + t * (L.BEdge[i][1] - L.BEdge[i][0]);
          add(d, L.BEdgeMargin[i], d > 0 ? Vec3((1.0 - s) * (x - y) / d) : Vec3(Vec3::Zero()));
        }
      }
      // ring triangles vs points
      for (const auto& ids : L.RingIds)
      {
        const Vec3& a = P[ids[1]];
        const Vec3& b = P[ids[2]];
        const double full = (a - p).cross(b - p).norm();
        const Sphere sr = boundingSphere(p, a, b);
        for (std::size_t i = 0; i < L.BPoint.size(); ++i)
        {
          const Vec3& q = L.BPoint[i];
          if ((q - sr.C).norm() - sr.R - L.BPointMargin[i] >= dh)
            continue;
          const Vec3 x = closestPointOnTriangle(q, p, a, b);
          const double d = (x - q).norm();
          const double wv = full > 0 ? (a - x).cross(b - x).norm() / full : 1.0 / 3.0;
          add(d, L.BPointMargin[i], d > 0 ? Vec3(wv * (x - q) / d) : Vec3(Vec3::Zero()));
        }
      }
      e += lambda * B;
      g += lambda * gb;
    }
    if (grad)
      *grad = g;
    return e;
  }

  // ---- static acceptance test ---------------------------------------------------------------

  /// The ring of v at p: no needle or flip, clearance to the input (exact distances through the
  /// tree), no conflict with any other cage triangle (the simplifier's test).
  bool ringAcceptable(const Local& L, const Vec3& p) const
  {
    const int n = static_cast<int>(L.RingIds.size());
    std::vector<std::array<Vec3, 3>> pts(n);
    for (int i = 0; i < n; ++i)
    {
      const auto& ids = L.RingIds[i];
      pts[i] = { p, P[ids[1]], P[ids[2]] };
      const Vec3 before = (P[ids[1]] - L.P0).cross(P[ids[2]] - L.P0);
      const Vec3 after = (pts[i][1] - p).cross(pts[i][2] - p);
      if (!(after.dot(before) > 0))
        return false;
      const double q0 = triangleQuality(L.P0, P[ids[1]], P[ids[2]]);
      if (triangleQuality(p, P[ids[1]], P[ids[2]]) < std::min(Opt.MinimumTriangleQuality, q0))
        return false;
      if (Tree.anyCloserThan(pts[i].data(), Delta))
        return false;
    }
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        if (trianglesConflict(L.RingIds[i].data(), pts[i].data(), L.RingIds[j].data(), pts[j].data(), SelfDelta, FoldCosine))
          return false;
    for (int i = 0; i < n; ++i)
    {
      const Vec3 lo = pts[i][0].cwiseMin(pts[i][1]).cwiseMin(pts[i][2]) - Vec3::Constant(SelfDelta);
      const Vec3 hi = pts[i][0].cwiseMax(pts[i][1]).cwiseMax(pts[i][2]) + Vec3::Constant(SelfDelta);
      if (!othersClear(L.RingIds[i].data(), pts[i].data(), lo, hi, L.Ring.data(), L.Ring.size()))
        return false;
    }
    return true;
  }

  /// No cage triangle other than `skip` conflicts with the triangle (ids, pts) of box [lo, hi].
  bool othersClear(const int ids[3], const Vec3 pts[3], const Vec3& lo, const Vec3& hi, const int* skip,
    std::size_t skipCount) const
  {
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      if ((Lo[f].array() > hi.array()).any() || (Hi[f].array() < lo.array()).any())
        continue;
      if (std::find(skip, skip + skipCount, static_cast<int>(f)) != skip + skipCount)
        continue;
      const Triangle& t = T[f];
      const int tid[3] = { t[0], t[1], t[2] };
      const Vec3 tp[3] = { P[t[0]], P[t[1]], P[t[2]] };
      bool disjoint = true;
      for (int a : tid)
        disjoint = disjoint && a != ids[0] && a != ids[1] && a != ids[2];
      if (disjoint)
      {
        // disjoint triangles whose bounding spheres are farther apart than SelfDelta cannot conflict
        const Sphere s1 = boundingSphere(pts[0], pts[1], pts[2]), s2 = boundingSphere(tp[0], tp[1], tp[2]);
        if ((s1.C - s2.C).norm() - s1.R - s2.R >= SelfDelta)
          continue;
      }
      if (trianglesConflict(ids, pts, tid, tp, SelfDelta, FoldCosine))
        return false;
    }
    return true;
  }

  // ---- one descent step at v: 1 moved, 0 converged (no descent direction), -1 no acceptable step
  int descend(int v)
  {
    Local& L = Scratch;
    // the trial steps never exceed the first one, so gathering within it covers them all
    double edgeSum = 0.0;
    for (int f : VT[v])
      for (int w : T[f])
        edgeSum += (P[w] - P[v]).norm(); // each neighbour twice, v itself adds 0
    const double reach = InitialStep * edgeSum / (2.0 * std::max<std::size_t>(1, VT[v].size()));
    gather(v, reach, L);
    Vec3 g;
    const double e0 = vertexEnergy(L, L.P0, &g);
    const double gn = g.norm();
    if (!std::isfinite(e0) || !(gn > 0) || !std::isfinite(gn))
      return std::isfinite(e0) ? 0 : -1;
    const Vec3 dir = -g / gn;
    double step = reach;
    for (int k = 0; k < LineSearchTries; ++k, step *= 0.5)
    {
      const Vec3 move = step * dir;
      const double t = advance(L, move);
      if (!(t > 0))
        return -1;
      const Vec3 p = L.P0 + t * move;
      if (!(vertexEnergy(L, p, nullptr) < e0))
        continue;
      if (!ringAcceptable(L, p))
        continue;
      P[v] = p;
      for (int f : L.Ring)
        updateBox(f);
      return 1;
    }
    return -1;
  }

  // ---- edge flip of (a, b): 1 flipped, 0 not worth it / not allowed topologically, -1 vetoed
  int tryFlip(int a, int b)
  {
    int f1 = -1, f2 = -1, c = -1, d = -1;
    for (int f : VT[a])
    {
      const Triangle& t = T[f];
      for (int k = 0; k < 3; ++k)
      {
        if (t[k] == a && t[(k + 1) % 3] == b)
        {
          f1 = f;
          c = t[(k + 2) % 3];
        }
        if (t[k] == b && t[(k + 1) % 3] == a)
        {
          f2 = f;
          d = t[(k + 2) % 3];
        }
      }
    }
    if (f1 < 0 || f2 < 0 || c == d || VT[a].size() <= 3 || VT[b].size() <= 3)
      return 0;
    for (int f : VT[c]) // the new edge must not exist already (manifold)
      for (int w : T[f])
        if (w == d)
          return 0;
    const Triangle n1{ c, a, d }, n2{ d, b, c };
    const double before = triangleEnergy(P[a], P[b], P[c], Tree, Opt) + triangleEnergy(P[b], P[a], P[d], Tree, Opt);
    const double after = triangleEnergy(P[c], P[a], P[d], Tree, Opt) + triangleEnergy(P[d], P[b], P[c], Tree, Opt);
    if (!(after < before - 1e-12 * std::abs(before)))
      return 0;
    const double qmin = std::min({ Opt.MinimumTriangleQuality, triangleQuality(P[a], P[b], P[c]),
      triangleQuality(P[b], P[a], P[d]) });
    const Vec3 nOld = (P[b] - P[a]).cross(P[c] - P[a]).normalized() + (P[a] - P[b]).cross(P[d] - P[b]).normalized();
    const int ids1[3] = { c, a, d }, ids2[3] = { d, b, c };
    const Vec3 p1[3] = { P[c], P[a], P[d] }, p2[3] = { P[d], P[b], P[c] };
    for (const Vec3* p : { p1, p2 })
    {
      if (triangleQuality(p[0], p[1], p[2]) < qmin)
        return -1;
      if (!((p[1] - p[0]).cross(p[2] - p[0]).dot(nOld) > 0))
        return -1;
      if (Tree.anyCloserThan(p, Delta))
        return -1;
    }
    if (trianglesConflict(ids1, p1, ids2, p2, SelfDelta, FoldCosine))
      return -1;
    const int skip[2] = { f1, f2 };
    for (int i = 0; i < 2; ++i)
    {
      const int* ids = i == 0 ? ids1 : ids2;
      const Vec3* p = i == 0 ? p1 : p2;
      const Vec3 lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]) - Vec3::Constant(SelfDelta);
      const Vec3 hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]) + Vec3::Constant(SelfDelta);
      if (!othersClear(ids, p, lo, hi, skip, 2))
        return -1;
    }
    T[f1] = n1;
    T[f2] = n2;
    auto drop = [&](int v, int f) {
      auto& l = VT[v];
      l.erase(std::remove(l.begin(), l.end(), f), l.end());
    };
    drop(a, f2);
    drop(b, f1);
    VT[c].push_back(f2);
    VT[d].push_back(f1);
    updateBox(f1);
    updateBox(f2);
    return 1;
  }

  void updateBox(int f)
  {
    const Triangle& t = T[f];
    Lo[f] = P[t[0]].cwiseMin(P[t[1]]).cwiseMin(P[t[2]]);
    Hi[f] = P[t[0]].cwiseMax(P[t[1]]).cwiseMax(P[t[2]]);
  }

private:
  const TriangleMesh& Input;
  const TriangleTree& Tree;
  OptimizeOptions Opt;
  double Delta;
  double SelfDelta;
  Progress* Prog;
  std::vector<Vec3> P;
  std::vector<Triangle> T;
  std::vector<std::vector<int>> VT;
  std::vector<Vec3> Lo, Hi;
  Local Scratch;
};

} // namespace

double cageEnergy(const TriangleMesh& cage, const TriangleTree& inputTree, const OptimizeOptions& options)
{
  double e = 0.0;
  for (const Triangle& t : cage.Triangles)
    e += triangleEnergy(cage.Points[t[0]], cage.Points[t[1]], cage.Points[t[2]], inputTree, options);
  return e;
}

double minimumAngle(const TriangleMesh& cage)
{
  double best = 180.0;
  for (const Triangle& t : cage.Triangles)
    for (int k = 0; k < 3; ++k)
    {
      const Vec3 u = cage.Points[t[(k + 1) % 3]] - cage.Points[t[k]];
      const Vec3 w = cage.Points[t[(k + 2) % 3]] - cage.Points[t[k]];
      best = std::min(best, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / M_PI);
    }
  return cage.Triangles.empty() ? 0.0 : best;
}

double collisionFreeFraction(const TriangleMesh& cage, int v, const Vec3& move, const TriangleMesh& input,
  const TriangleTree& inputTree, double clearance, double selfClearance)
{
  if (v < 0 || v >= static_cast<int>(cage.Points.size()))
    return 0.0;
  OptimizeOptions o;
  o.BarrierDistance = 0.0; // no barrier primitives needed
  Optimizer opt(cage, input, inputTree, o, clearance, selfClearance, nullptr);
  Optimizer::Local L;
  opt.gather(v, move.norm(), L);
  return opt.advance(L, move);
}

OptimizeResult optimizeCage(const TriangleMesh& cage, const TriangleMesh& input, const TriangleTree& inputTree,
  const OptimizeOptions& options, Progress* progress)
{
  OptimizeResult r;
  const auto start = std::chrono::steady_clock::now();
  r.Cage = cage;
  if (cage.Triangles.empty() || input.Triangles.empty())
  {
    r.State = Status::EmptyInput;
    r.Message = cage.Triangles.empty() ? "the cage has no triangles" : "the input mesh has no triangles";
    return r;
  }
  if (!(options.TargetSpacing >= 0) || !(options.BarrierWeight >= 0) || !(options.BarrierDistance >= 0) ||
    !std::isfinite(options.TargetSpacing + options.BarrierWeight + options.BarrierDistance))
  {
    r.State = Status::InvalidInput;
    r.Message = "TargetSpacing, BarrierWeight and BarrierDistance must be finite and >= 0";
    return r;
  }
  // the given cage must already satisfy the guarantees; measure its clearance
  progressStage(progress, "verifying the given cage", 0.0, 0.05);
  std::string why;
  double measured = 0.0;
  const auto tv = std::chrono::steady_clock::now();
  if (!verifyEnclosure(input, cage, std::numeric_limits<double>::min(), measured, why, nullptr, nullptr, true))
  {
    r.State = Status::InvalidInput;
    r.Message = "the given cage does not enclose the input without self-intersection: " + why;
    return r;
  }
  double delta = options.Clearance;
  if (!(delta > 0))
    delta = std::min(DefaultClearance, measured);
  else if (measured < delta)
  {
    r.State = Status::InvalidInput;
    r.Message = "the given cage is " + std::to_string(measured) + " from the input, closer than the clearance " +
      std::to_string(delta) + " to keep (unit-sphere units): lower MinimumClearance or use 0 (automatic)";
    return r;
  }
  const double selfDelta = options.SelfClearance > 0 ? options.SelfClearance : delta / 4;
  r.ClearanceUsed = delta;
  r.EnergyBefore = cageEnergy(cage, inputTree, options);
  r.MinimumAngleBefore = minimumAngle(cage);
  r.VerificationSeconds = seconds(tv);

  Optimizer opt(cage, input, inputTree, options, delta, selfDelta, progress);
  bool cancelled = false;
  const int rounds = std::max(0, options.NumberOfIterations);
  for (int it = 0; it < rounds && !cancelled; ++it)
  {
    progressStage(progress, "relocating cage vertices", 0.05 + 0.85 * it / rounds, 0.05 + 0.85 * (it + 0.8) / rounds);
    const auto t0 = std::chrono::steady_clock::now();
    cancelled = !opt.relocationPass(r, 0.0, 1.0);
    r.RelocationSeconds += seconds(t0);
    if (!cancelled && options.EdgeFlips)
    {
      progressStage(progress, "flipping cage edges", 0.05 + 0.85 * (it + 0.8) / rounds, 0.05 + 0.85 * (it + 1.0) / rounds);
      const auto t1 = std::chrono::steady_clock::now();
      cancelled = !opt.flipPass(r);
      r.FlipSeconds += seconds(t1);
    }
  }

  // independent verification of the result (also after a cancel: the partial result is valid)
  progressStage(progress, "verifying the optimized cage", 0.9, 1.0);
  const auto t2 = std::chrono::steady_clock::now();
  TriangleMesh result = opt.mesh();
  double clearance = 0.0;
  std::vector<double> dist;
  if (verifyEnclosure(input, result, delta, clearance, why, &dist, nullptr, true))
  {
    r.Cage = std::move(result);
    r.MinimumClearance = clearance;
    r.DistanceToInput = std::move(dist);
  }
  else
  {
    // should not happen: every change was checked. Keep the given (verified) cage.
    r.Reverted = true;
    r.Message = "the optimized cage failed verification (" + why + "); the given cage is returned unchanged";
    r.Cage = cage;
    verifyEnclosure(input, cage, std::numeric_limits<double>::min(), clearance, why, &dist, nullptr, true);
    r.MinimumClearance = clearance;
    r.DistanceToInput = std::move(dist);
  }
  r.VerificationSeconds += seconds(t2);
  r.EnergyAfter = cageEnergy(r.Cage, inputTree, options);
  r.MinimumAngleAfter = minimumAngle(r.Cage);
  r.State = cancelled ? Status::Cancelled : Status::Ok;
  if (cancelled && r.Message.empty())
    r.Message = "cancelled during optimization; the cage so far is valid";
  r.Seconds = seconds(start);
  progressUpdate(progress, 1.0);
  return r;
}

OptimizeResult optimizeCageInInputUnits(const TriangleMesh& cage, const TriangleMesh& input,
  const OptimizeOptions& options, Progress* progress)
{
  OptimizeResult r;
  r.Cage = cage;
  TriangleMesh in, cg;
  const MeshDefects di = prepareMesh(PolygonMesh::fromTriangles(input), in);
  if (!di.usable())
  {
    r.State = di.Empty ? Status::EmptyInput : Status::InvalidInput;
    r.Message = "input mesh: " + (di.Empty ? std::string("it has no triangles") : di.errorMessage());
    return r;
  }
  const MeshDefects dc = prepareMesh(PolygonMesh::fromTriangles(cage), cg);
  if (!dc.usable())
  {
    r.State = dc.Empty ? Status::EmptyInput : Status::InvalidInput;
    r.Message = "cage: " + (dc.Empty ? std::string("it has no triangles") : dc.errorMessage());
    return r;
  }
  const Normalization n = Normalization::fit(in);
  const TriangleMesh unitInput = n.toUnit(in);
  const TriangleTree tree(unitInput);
  OptimizeResult u = optimizeCage(n.toUnit(cg), unitInput, tree, options, progress);
  u.Cage = n.toInput(u.Cage);
  for (double& d : u.DistanceToInput)
    d = n.lengthToInput(d);
  u.MinimumClearance = n.lengthToInput(u.MinimumClearance);
  return u;
}

} // namespace sdfcage
