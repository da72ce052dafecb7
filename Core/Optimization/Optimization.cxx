#include "Optimization/Optimization.h"

#include "Common/GracePeriod.h"
#include "Common/Progress.h"
#include "Mesh/EdgeKey.h"
#include "Mesh/Normalization.h"
#include "Mesh/Validation.h"
#include "Quality/LocalChangeVeto.h"
#include "Quality/Verification.h"
#include "Spatial/CageGrid.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleTree.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdint>
#include <iterator>
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
// Bisection steps of the continuous collision detection when a whole move is not clear.
constexpr int BisectionSteps = 10;
// Sufficient-decrease fraction of the line search (Armijo condition).
constexpr double ArmijoFraction = 0.1;
// Vertices relocated together at most (a batch of non-overlapping regions).
constexpr std::size_t MaximumBatch = 256;
// Backtracking halvings of the line search.
constexpr int LineSearchTries = 8;
// The first trial step of the line search, relative to the mean edge length around the vertex.
constexpr double InitialStep = 0.25;
// MIPS sweeps stop when the smallest angle has not grown for this many.
constexpr int StallSweeps = 4;
/// MIPS sweeps after a round's first relocate only the vertices within this many rings of a
/// triangle with an angle below the target (the rest of the cage has had its full pass; this
/// keeps a 500-vertex cage's later sweeps a fraction of the first one's cost).
constexpr int ActiveRings = 2;
// The angle-targeted relocation (Optimizer::anglePass): tangent directions tried, their tilt
// toward the normal (degrees, each direction also tilted up and down), step lengths (halving
// from AngleReach times the ring's mean edge), the smallest gain of the ring's smallest angle
// (degrees) a candidate must promise, and the candidates checked at most per vertex.
constexpr int AngleDirections = 16;
constexpr double AngleTilt = 30.0;
constexpr int AngleSteps = 5;
constexpr double AngleReach = 1.0;
constexpr double AngleGain = 0.01;
constexpr std::size_t AngleTries = 40;
// The spacing energy's sweeps stop when one lowers it by less than this fraction.
constexpr double SpacingConvergence = 0.002;
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

/// The angle at corner a of triangle (a, b, c), degrees.
double cornerAngle(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const Vec3 u = b - a, w = c - a;
  return std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / M_PI;
}
double minimumAngleOf(const Vec3& a, const Vec3& b, const Vec3& c)
{
  return std::min({ cornerAngle(a, b, c), cornerAngle(b, c, a), cornerAngle(c, a, b) });
}

// Subdivision depth of the fidelity test and of the Hausdorff bound (a triangle splits into
// 4^depth at most): at the finest level a cell's centroid stands for it.
constexpr int FidelityDepth = 5;

/// Is the distance to the input at most `limit` everywhere on triangle (a, b, c)? The distance is
/// 1-Lipschitz, so a cell whose centroid is at distance d and whose corners lie within R of it
/// is within d + R: cells are split in four until that settles it; at depth 0 the centroid
/// decides (the answer may then be off by the cell's R, 1/32 of the triangle's).
bool triangleWithin(const TriangleTree& tree, const Vec3& a, const Vec3& b, const Vec3& c, double limit, int depth)
{
  const Vec3 m = (a + b + c) / 3.0;
  const double R = std::sqrt(std::max({ (a - m).squaredNorm(), (b - m).squaredNorm(), (c - m).squaredNorm() }));
  Vec3 y;
  int t;
  double d;
  if (!tree.closestPoint(m, limit, y, t, d) || d > limit)
    return false;
  if (d + R <= limit || depth == 0)
    return true;
  const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  return triangleWithin(tree, a, ab, ca, limit, depth - 1) && triangleWithin(tree, ab, b, bc, limit, depth - 1) &&
    triangleWithin(tree, ca, bc, c, limit, depth - 1) && triangleWithin(tree, ab, bc, ca, limit, depth - 1);
}

/// Branch and bound for the largest distance to the input on triangle (a, b, c): raises `lower`
/// (a value reached) and `upper` (a bound of the triangle's maximum, to the finest cells' R).
void triangleFarthest(const TriangleTree& tree, const Vec3& a, const Vec3& b, const Vec3& c, int depth, double& lower,
  double& upper)
{
  const Vec3 m = (a + b + c) / 3.0;
  const double R = std::sqrt(std::max({ (a - m).squaredNorm(), (b - m).squaredNorm(), (c - m).squaredNorm() }));
  const double d = tree.distance(m);
  lower = std::max(lower, d);
  if (d + R <= lower)
    return;
  if (depth == 0)
  {
    upper = std::max(upper, d + R);
    return;
  }
  const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  triangleFarthest(tree, a, ab, ca, depth - 1, lower, upper);
  triangleFarthest(tree, ab, b, bc, depth - 1, lower, upper);
  triangleFarthest(tree, ca, bc, c, depth - 1, lower, upper);
  triangleFarthest(tree, ab, bc, ca, depth - 1, lower, upper);
}

/// MIPS with an equilateral reference, sum(l^2) / (2 sqrt(3) A), and its gradient with respect
/// to the first corner v (the triangle is (v, a, b), counter-clockwise).
double mips(const Vec3& v, const Vec3& a, const Vec3& b, Vec3* grad)
{
  return mipsEnergy(v, a, b, grad);
}

/// The spacing energy's quadrature: the triangle cut into SpacingCuts^2 equal sub-triangles, the
/// 3-point degree-2 rule on each (barycentric (2/3, 1/6, 1/6) and its rotations), equal weights.
/// With the 3-point rule on the whole triangle (SpacingCuts 1) the relocation could not see how
/// the distance varies across a cage triangle: at 500 vertices, 80-89.5% of the area ended within
/// h +- 20% of the input at h = 0.03 on 5 of 13 closed meshes; with 4 sub-triangles (12 points)
/// 89.6-98% (sdfcage_tight_benchmark), for 2.6 times the optimization time (armadillo 3.1 ->
/// 8.2 s); 9 sub-triangles gained another 0.3-0.6% for twice that time again.
constexpr int SpacingCuts = 2;
std::vector<std::array<double, 3>> makeSpacingRule()
{
  const int n = SpacingCuts;
  std::vector<std::array<double, 3>> rule;
  auto corner = [n](int i, int j) {
    return std::array<double, 3>{ 1.0 - double(i + j) / n, double(i) / n, double(j) / n };
  };
  auto add = [&rule](const std::array<double, 3>& p, const std::array<double, 3>& q, const std::array<double, 3>& r) {
    const double w[3][3] = { { 2.0 / 3, 1.0 / 6, 1.0 / 6 }, { 1.0 / 6, 2.0 / 3, 1.0 / 6 },
      { 1.0 / 6, 1.0 / 6, 2.0 / 3 } };
    for (const auto& k : w)
      rule.push_back({ k[0] * p[0] + k[1] * q[0] + k[2] * r[0], k[0] * p[1] + k[1] * q[1] + k[2] * r[1],
        k[0] * p[2] + k[1] * q[2] + k[2] * r[2] });
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j)
    {
      add(corner(i, j), corner(i + 1, j), corner(i, j + 1));
      if (i + j + 1 < n)
        add(corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1));
    }
  return rule;
}
const std::vector<std::array<double, 3>> SpacingRule = makeSpacingRule();

/// Spacing energy of triangle (v, a, b): A * mean over the rule of (xi - h)^2, and its gradient
/// with respect to v (xi is 1-Lipschitz with gradient (x - y)/|x - y| outside the input).
double spacing(const Vec3& v, const Vec3& a, const Vec3& b, const TriangleTree& tree, double h, Vec3* grad)
{
  const Vec3 n = (a - v).cross(b - v);
  const double a2 = n.norm();
  const double area = 0.5 * a2;
  double mean = 0.0;
  Vec3 g = Vec3::Zero();
  const double weight = 1.0 / static_cast<double>(SpacingRule.size());
  for (const auto& w : SpacingRule)
  {
    const Vec3 x = w[0] * v + w[1] * a + w[2] * b;
    Vec3 y;
    int tri;
    double d;
    if (!tree.closestPoint(x, -1.0, y, tri, d))
      continue;
    mean += (d - h) * (d - h) * weight;
    if (grad && d > 0)
      g += (2.0 * (d - h) * w[0] * weight) * (x - y) / d;
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

/// The veto's rules for the optimizer's changes (a vertex move, an edge flip): no triangle worse
/// than min(the quality floor, what it replaces), no flip, and pairs that were already closer than
/// the self clearance may keep half their distance (moves only: a flip makes new pairs).
LocalChangePolicy changePolicy(const OptimizeOptions& o, double clearance, double selfClearance, bool move)
{
  LocalChangePolicy p;
  p.MinimumTriangleQuality = o.MinimumTriangleQuality;
  p.KeepQualityBefore = true;
  p.MinimumNormalCosine = 0.0;
  // FoldCosine: the default, the simplifier's
  p.Clearance = clearance;
  // a move's input clearance is established by the collision-free sweep (sweepClear)
  p.Input = move ? LocalChangePolicy::InputTest::None : LocalChangePolicy::InputTest::Exact;
  p.SelfClearance = selfClearance;
  p.RelaxCloserPairs = move;
  return p;
}

/// The optimizer's working state: the cage with vertex-triangle adjacency, cached boxes and a
/// grid of them.
class Optimizer
{
public:
  Optimizer(const TriangleMesh& cage, const TriangleMesh& input, const TriangleTree& tree, const OptimizeOptions& o,
    double clearance, double selfClearance, Progress* progress, double partRoom = 0.0,
    const std::vector<int>* cageComponent = nullptr)
    : Input(input)
    , Tree(tree)
    , Opt(o)
    , Delta(clearance)
    , SelfDelta(selfClearance)
    , Prog(progress)
    , MoveVeto(
        changePolicy(o, clearance, selfClearance, true), tree, CageView{ &P, &T, nullptr, &Lo, &Hi, &Grid, &Part })
    , FlipVeto(
        changePolicy(o, clearance, selfClearance, false), tree, CageView{ &P, &T, nullptr, &Lo, &Hi, &Grid, &Part })
  {
    P = cage.Points;
    T = cage.Triangles;
    if (partRoom > selfClearance && cageComponent)
    {
      // room between the parts (OptimizeOptions::KeepPartsApart; `cageComponent` per triangle): every
      // move and flip keeps it through the veto, which then reads that far around a change
      // (ReadDelta)
      Part.assign(P.size(), 0);
      for (std::size_t f = 0; f < T.size(); ++f)
        for (int v : T[f])
          Part[v] = (*cageComponent)[f];
      for (LocalChangeVeto* veto : { &MoveVeto, &FlipVeto })
      {
        LocalChangePolicy p = veto->policy();
        p.PartClearance = partRoom;
        veto->setPolicy(p);
      }
      ReadDelta = partRoom;
    }
    VT.assign(P.size(), {});
    for (std::size_t f = 0; f < T.size(); ++f)
      for (int v : T[f])
        VT[v].push_back(static_cast<int>(f));
    Lo.resize(T.size());
    Hi.resize(T.size());
    std::vector<int> component;
    const int components = triangleComponents(input, component);
    std::vector<char> seen(static_cast<std::size_t>(std::max(0, components)), 0);
    for (std::size_t f = 0; f < input.Triangles.size(); ++f)
      if (!seen[component[f]])
      {
        seen[component[f]] = 1;
        Representatives.push_back(input.Points[input.Triangles[f][0]]);
      }
    double area = 0.0;
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      const Triangle& t = T[f];
      Lo[f] = P[t[0]].cwiseMin(P[t[1]]).cwiseMin(P[t[2]]);
      Hi[f] = P[t[0]].cwiseMax(P[t[1]]).cwiseMax(P[t[2]]);
      area += 0.5 * areaNormal(P, t).norm();
    }
    // cells of about two mean edges (the edge of an equilateral triangle of the mean area)
    const double meanEdge = std::sqrt(4.0 * area / std::max<std::size_t>(1, T.size()) / std::sqrt(3.0));
    Grid.reset(std::max(2.0 * meanEdge, 1e-6));
    for (std::size_t f = 0; f < T.size(); ++f)
      Grid.insert(static_cast<int>(f), Lo[f], Hi[f]);
  }

  TriangleMesh mesh() const
  {
    TriangleMesh m;
    m.Points = P;
    m.Triangles = T;
    return m;
  }

  /// One relocation pass over every vertex. Returns false when cancelled.
  ///
  /// Vertices are relocated in batches whose regions do not overlap, the batches in parallel. The
  /// region of a vertex is the box of its one-ring grown by everything its descent steps can touch
  /// or read: its whole motion (DescentSteps trial steps of at most `reach`), the radius within
  /// which cage triangles are gathered, and the self clearance. A vertex of a batch therefore
  /// never reads a position another vertex of the batch writes (cage triangle boxes are updated
  /// between batches), so a batch gives the same result in any order and on any number of threads.
  /// Batches take the pending vertices in index order, deferring those that overlap.
  /// `only` (optional, one flag per vertex): relocate just the flagged vertices.
  bool relocationPass(
    OptimizeResult& r, double progressBegin, double progressEnd, const std::vector<char>* only = nullptr)
  {
    const int steps = std::max(1, Opt.DescentSteps);
    const double dh = std::max(0.0, Opt.BarrierDistance);
    std::vector<int> pending, next, batch;
    for (std::size_t v = 0; v < P.size(); ++v)
      if (!VT[v].empty() && (!only || (*only)[v]))
        pending.push_back(static_cast<int>(v));
    const std::size_t total = pending.size();
    std::vector<double> reach(P.size(), 0.0);
    std::vector<Vec3> boxLo, boxHi;
    std::vector<int> outcomeMoves, outcomeRejected;
    std::size_t done = 0;
    while (!pending.empty())
    {
      if (Prog &&
        Prog->update(
          progressBegin + (progressEnd - progressBegin) * double(done) / double(std::max<std::size_t>(1, total))))
        return false;
      batch.clear();
      next.clear();
      boxLo.clear();
      boxHi.clear();
      for (int v : pending)
      {
        Vec3 lo = Vec3::Constant(Inf), hi = -lo;
        double edgeSum = 0.0;
        for (int f : VT[v])
          for (int w : T[f])
          {
            lo = lo.cwiseMin(P[w]);
            hi = hi.cwiseMax(P[w]);
            edgeSum += (P[w] - P[v]).norm(); // each neighbour twice, v itself adds 0
          }
        reach[v] = InitialStep * edgeSum / (2.0 * double(VT[v].size()));
        const double grow = steps * reach[v] + ReadDelta + dh + reach[v] + ReadDelta;
        lo -= Vec3::Constant(grow);
        hi += Vec3::Constant(grow);
        bool overlaps = batch.size() >= MaximumBatch;
        for (std::size_t i = 0; i < batch.size() && !overlaps; ++i)
          overlaps = !((boxLo[i].array() > hi.array()).any() || (boxHi[i].array() < lo.array()).any());
        if (overlaps)
        {
          next.push_back(v);
          continue;
        }
        batch.push_back(v);
        boxLo.push_back(lo);
        boxHi.push_back(hi);
      }
      outcomeMoves.assign(batch.size(), 0);
      outcomeRejected.assign(batch.size(), 0);
      tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, batch.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t i = range.begin(); i != range.end(); ++i)
          {
            // after a cancel, the rest of the batch stays where it is (every move made was
            // checked: the cage is valid); the next update() ends the pass
            if (progressCancelled(Prog))
              break;
            const int v = batch[i];
            for (int step = 0; step < steps; ++step)
            {
              const int outcome = descend(v, reach[v]);
              if (outcome > 0)
                ++outcomeMoves[i];
              else
              {
                if (outcome < 0)
                  ++outcomeRejected[i];
                break;
              }
            }
          }
        });
      for (std::size_t i = 0; i < batch.size(); ++i)
      {
        r.Moves += outcomeMoves[i];
        r.RejectedMoves += outcomeRejected[i];
        if (outcomeMoves[i] > 0)
          for (int f : VT[batch[i]])
            updateBox(f);
      }
      done += batch.size();
      ++r.Batches;
      pending.swap(next);
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

  /// Barrier primitives, each counted once: triangles (vs the point v), edges (vs the edges
  /// (v, w)) and points (vs the ring triangles), each with the distance its pair must keep.
  struct Primitives
  {
    std::vector<std::array<Vec3, 3>> Tri;
    std::vector<Sphere> TriSpheres;
    std::vector<double> TriMargin;
    std::vector<std::array<Vec3, 2>> Edge;
    std::vector<double> EdgeMargin;
    std::vector<Vec3> Point;
    std::vector<double> PointMargin;
    void clear()
    {
      Tri.clear();
      TriSpheres.clear();
      TriMargin.clear();
      Edge.clear();
      EdgeMargin.clear();
      Point.clear();
      PointMargin.clear();
    }
  };

  /// Everything near vertex v that a move of length up to `reach` can involve. The input is not
  /// gathered: its distances come from the tree at each position.
  struct Local
  {
    int V = -1;
    Vec3 P0;
    std::vector<int> Ring;                   ///< triangles around v
    std::vector<std::array<int, 3>> RingIds; ///< rotated so v comes first
    std::vector<int> CageTris;               ///< other cage triangles within selfδ + d̂ + reach
    std::vector<Sphere> CageSpheres;
    /// Lower bounds on the distance at P0 between ring triangle i and cage candidate j (exact
    /// where it could matter, index i * count + j); infinite for pairs sharing a vertex.
    std::vector<double> CageD0;
    /// Per ring triangle, a lower bound on its distance to the input at P0 (δ + d̂ or 0): the
    /// input is clear of the ring at q when this minus |q - P0| is large enough.
    std::vector<double> InputD0;
    /// Cage barrier primitives: those of candidates sharing no vertex with the closed star of v.
    Primitives CageBarrier;
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
    const double cageRadius = SelfDelta + dh + reach;
    Vec3 ringLo = Vec3::Constant(Inf), ringHi = -ringLo;
    for (const auto& ids : L.RingIds)
    {
      const Vec3 pts[3] = { P[ids[0]], P[ids[1]], P[ids[2]] };
      for (const Vec3& q : pts)
      {
        ringLo = ringLo.cwiseMin(q);
        ringHi = ringHi.cwiseMax(q);
      }
    }
    const Vec3 lo = ringLo - Vec3::Constant(cageRadius), hi = ringHi + Vec3::Constant(cageRadius);
    const std::size_t nr = L.RingIds.size();
    std::vector<Sphere> ringSpheres(nr);
    for (std::size_t i = 0; i < nr; ++i)
      ringSpheres[i] = boundingSphere(P[L.RingIds[i][0]], P[L.RingIds[i][1]], P[L.RingIds[i][2]]);
    // the lower bound of a pair is made exact only when it could limit a move of `reach`
    auto lowerBound = [&](std::size_t i, const Vec3 q[3], const Sphere& sq, double margin) {
      const double lb = (sq.C - ringSpheres[i].C).norm() - sq.R - ringSpheres[i].R;
      if (lb - margin >= reach + dh)
        return lb;
      const Vec3 rp[3] = { P[L.RingIds[i][0]], P[L.RingIds[i][1]], P[L.RingIds[i][2]] };
      return std::sqrt(triangleTriangleDistance2(rp, q));
    };
    std::vector<double> d0(nr);
    // the cage triangles whose boxes meet [lo, hi], in index order
    Work& w = work();
    std::vector<int>& nearby = w.Nearby;
    nearby.clear();
    w.Change.Seen.begin(T.size());
    Grid.query(lo, hi, [&](int f) {
      if (w.Change.Seen.insert(f) && !((Lo[f].array() > hi.array()).any() || (Hi[f].array() < lo.array()).any()))
        nearby.push_back(f);
    });
    std::sort(nearby.begin(), nearby.end());
    for (int f : nearby)
    {
      const Triangle& t = T[f];
      if (t[0] == v || t[1] == v || t[2] == v)
        continue;
      const Vec3 pts[3] = { P[t[0]], P[t[1]], P[t[2]] };
      const Sphere sf = boundingSphere(pts[0], pts[1], pts[2]);
      bool near = false;
      for (std::size_t i = 0; i < nr; ++i)
      {
        const auto& ids = L.RingIds[i];
        const bool shares =
          t[0] == ids[1] || t[0] == ids[2] || t[1] == ids[1] || t[1] == ids[2] || t[2] == ids[1] || t[2] == ids[2];
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
    for (std::size_t i = 0; i < nr; ++i)
    {
      const Vec3 rp[3] = { P[L.RingIds[i][0]], P[L.RingIds[i][1]], P[L.RingIds[i][2]] };
      // a cheap certificate (the query stops at the first triangle closer than the limit)
      const double limit = Delta + dh;
      L.InputD0.push_back(Tree.anyCloserThan(rp, limit) ? 0.0 : limit);
    }
    // cage barrier primitives
    if (!(dh > 0))
      return;
    std::vector<int> far;
    for (int f : L.CageTris)
    {
      const Triangle& t = T[f];
      if (!inStar(t[0]) && !inStar(t[1]) && !inStar(t[2]))
        far.push_back(f);
    }
    primitives(far, T, P, SelfDelta, L.CageBarrier);
    // pairs already closer than the self clearance keep half their distance (see relaxed())
    Primitives& b = L.CageBarrier;
    for (std::size_t i = 0; i < b.Tri.size(); ++i)
      b.TriMargin[i] = relaxed((L.P0 - closestPointOnTriangle(L.P0, b.Tri[i][0], b.Tri[i][1], b.Tri[i][2])).norm());
    for (std::size_t i = 0; i < b.Edge.size(); ++i)
    {
      double d = Inf, s, t;
      for (const auto& ids : L.RingIds)
        d = std::min(d, std::sqrt(segmentSegmentClosest(L.P0, P[ids[1]], b.Edge[i][0], b.Edge[i][1], s, t)));
      b.EdgeMargin[i] = relaxed(d);
    }
    for (std::size_t i = 0; i < b.Point.size(); ++i)
    {
      double d = Inf;
      for (const auto& ids : L.RingIds)
        d = std::min(d, (b.Point[i] - closestPointOnTriangle(b.Point[i], L.P0, P[ids[1]], P[ids[2]])).norm());
      b.PointMargin[i] = relaxed(d);
    }
  }

  /// Barrier primitives of the triangles `tris` of a mesh (triangles, points): every triangle,
  /// every edge and every point once.
  void primitives(const std::vector<int>& tris, const std::vector<Triangle>& triangles, const std::vector<Vec3>& points,
    double margin, Primitives& out) const
  {
    out.clear();
    Work& w = work();
    std::vector<std::uint64_t>& edges = w.Edges;
    std::vector<int>& ids = w.Points;
    edges.clear();
    ids.clear();
    for (int f : tris)
    {
      const Triangle& t = triangles[f];
      out.Tri.push_back({ points[t[0]], points[t[1]], points[t[2]] });
      out.TriSpheres.push_back(boundingSphere(points[t[0]], points[t[1]], points[t[2]]));
      out.TriMargin.push_back(margin);
      for (int k = 0; k < 3; ++k)
      {
        edges.push_back(edgeKey(t[k], t[(k + 1) % 3]));
        ids.push_back(t[k]);
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (std::uint64_t e : edges)
    {
      out.Edge.push_back({ points[static_cast<int>(e >> 32)], points[static_cast<int>(e & 0xFFFFFFFFu)] });
      out.EdgeMargin.push_back(margin);
    }
    for (int q : ids)
    {
      out.Point.push_back(points[q]);
      out.PointMargin.push_back(margin);
    }
  }

  /// The distance a pair of vertex-disjoint cage triangles must keep: the self clearance, or half
  /// their distance before the move when they were already closer (a given cage, or the dense
  /// envelope's leftovers, may have such pairs; they may move, but never touch).
  double relaxed(double before) const { return MoveVeto.policy().relaxed(before); }

  /// Is the straight move of v from P0 to q collision-free? The ring triangle (v, a, b) sweeps
  /// exactly the tetrahedron conv(P0, q, a, b) (a point of it is (P0 + s (q - P0)) weighted with
  /// a and b). So no pair comes closer than its margin during the move iff no input triangle and
  /// no cage triangle sharing no vertex with (v, a, b) comes closer than its margin to the
  /// tetrahedron: that is, to one of its faces (the face (P0, a, b) is the starting triangle,
  /// already clear), or lies wholly inside it (then its component's representative point, or for
  /// the cage its corners, are inside). Exact-in-effect distances (the same double-precision
  /// triangle-triangle distances as everywhere else).
  bool sweepClear(const Local& L, const Vec3& q) const
  {
    const double moved = (q - L.P0).norm();
    const std::size_t nc = L.CageTris.size();
    for (std::size_t r = 0; r < L.RingIds.size(); ++r)
    {
      const auto& ids = L.RingIds[r];
      const Vec3& a = P[ids[1]];
      const Vec3& b = P[ids[2]];
      const Vec3 faces[3][3] = { { q, a, b }, { L.P0, q, a }, { L.P0, b, q } };
      // the tetrahedron lies within `moved` of the starting triangle: if that is far enough from
      // the input, neither a face nor a whole component can come closer than Delta
      const bool inputFar = L.InputD0[r] - moved >= Delta;
      for (const auto& f : faces)
        if (!inputFar && Tree.anyCloserThan(f, Delta))
          return false;
      const double volume = (q - L.P0).dot((a - L.P0).cross(b - L.P0));
      const bool solid =
        std::abs(volume) > 1e-14 * std::pow(std::max({ moved, (a - L.P0).norm(), (b - L.P0).norm() }), 3);
      auto inside = [&](const Vec3& x) {
        if (!solid)
          return false;
        const double s0 = (a - x).dot((b - x).cross(q - x));    // opposite P0
        const double s1 = (L.P0 - x).dot((b - x).cross(a - x)); // opposite q
        const double s2 = (L.P0 - x).dot((q - x).cross(b - x)); // opposite a
        const double s3 = (L.P0 - x).dot((a - x).cross(q - x)); // opposite b
        return (s0 >= 0 && s1 >= 0 && s2 >= 0 && s3 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0 && s3 <= 0);
      };
      for (const Vec3& x : Representatives)
        if (!inputFar && inside(x))
          return false;
      for (std::size_t i = 0; i < nc; ++i)
      {
        // the tetrahedron lies within `moved` of the starting triangle; also skips pairs
        // sharing a vertex (infinite bound)
        const double d0 = L.CageD0[r * nc + i];
        const double margin = relaxed(d0);
        if (d0 - moved - margin >= 0)
          continue;
        const Triangle& t = T[L.CageTris[i]];
        const Vec3 c[3] = { P[t[0]], P[t[1]], P[t[2]] };
        for (const auto& f : faces)
          if (triangleTriangleDistance2(f, c) < margin * margin)
            return false;
        for (const Vec3& x : c)
          if (inside(x))
            return false;
      }
    }
    return true;
  }

  /// The largest fraction t of the move (to 1/1024) for which the move to P0 + t move is
  /// collision-free: the whole move if it is, else a bisection (a fraction is clear iff its
  /// tetrahedra are, and they grow with t, so clear fractions form an interval [0, t*]).
  double advance(const Local& L, const Vec3& move) const
  {
    if (!(move.norm() > 0) || sweepClear(L, L.P0 + move))
      return 1.0;
    double lo = 0.0, hi = 1.0;
    for (int k = 0; k < BisectionSteps; ++k)
    {
      const double mid = 0.5 * (lo + hi);
      if (sweepClear(L, L.P0 + mid * move))
        lo = mid;
      else
        hi = mid;
    }
    return lo;
  }

  /// Adds the barrier of the pairs between the primitives and the ring of v at p to B (and its
  /// gradient with respect to p to gb).
  void barrierTerms(
    const Local& L, const Primitives& prims, const Vec3& p, double dh, bool withGradient, double& B, Vec3& gb) const
  {
    auto add = [&](double d, double margin, const Vec3& dddp) {
      const double gap = d - margin;
      if (gap >= dh)
        return;
      B += barrier(gap, dh);
      if (withGradient)
        gb += barrierDerivative(gap, dh) * dddp;
    };
    // point v vs triangles
    for (std::size_t i = 0; i < prims.Tri.size(); ++i)
    {
      const auto& q = prims.Tri[i];
      if ((p - prims.TriSpheres[i].C).norm() - prims.TriSpheres[i].R - prims.TriMargin[i] >= dh)
        continue;
      const Vec3 y = closestPointOnTriangle(p, q[0], q[1], q[2]);
      const double d = (p - y).norm();
      add(d, prims.TriMargin[i], d > 0 ? Vec3((p - y) / d) : Vec3(Vec3::Zero()));
    }
    // edges (v, w) vs edges; each edge (v, w) is the first edge of exactly one ring triangle
    for (const auto& ids : L.RingIds)
    {
      const Vec3& w = P[ids[1]];
      const Vec3 mid = 0.5 * (p + w);
      const double half = 0.5 * (w - p).norm();
      for (std::size_t i = 0; i < prims.Edge.size(); ++i)
      {
        const auto& e = prims.Edge[i];
        if ((0.5 * (e[0] + e[1]) - mid).norm() - half - 0.5 * (e[1] - e[0]).norm() - prims.EdgeMargin[i] >= dh)
          continue;
        double s, t;
        const double d = std::sqrt(segmentSegmentClosest(p, w, e[0], e[1], s, t));
        const Vec3 x = p + s * (w - p), y = e[0] + t * (e[1] - e[0]);
        add(d, prims.EdgeMargin[i], d > 0 ? Vec3((1.0 - s) * (x - y) / d) : Vec3(Vec3::Zero()));
      }
    }
    // ring triangles vs points
    for (const auto& ids : L.RingIds)
    {
      const Vec3& a = P[ids[1]];
      const Vec3& b = P[ids[2]];
      const double full = (a - p).cross(b - p).norm();
      const Sphere sr = boundingSphere(p, a, b);
      for (std::size_t i = 0; i < prims.Point.size(); ++i)
      {
        const Vec3& q = prims.Point[i];
        if ((q - sr.C).norm() - sr.R - prims.PointMargin[i] >= dh)
          continue;
        const Vec3 x = closestPointOnTriangle(q, p, a, b);
        const double d = (x - q).norm();
        const double wv = full > 0 ? (a - x).cross(b - x).norm() / full : 1.0 / 3.0;
        add(d, prims.PointMargin[i], d > 0 ? Vec3(wv * (x - q) / d) : Vec3(Vec3::Zero()));
      }
    }
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
      barrierTerms(L, L.CageBarrier, p, dh, grad != nullptr, B, gb);
      // the input: only triangles within δ + d̂ of the ring at p can give a non-zero term
      Work& w = work();
      std::vector<int>& InputScratch = w.InputIds;
      InputScratch.clear();
      const double moved = (p - L.P0).norm();
      for (std::size_t r = 0; r < L.RingIds.size(); ++r)
      {
        if (L.InputD0[r] - moved >= Delta + dh) // no input within the barrier's reach
          continue;
        const Vec3 rp[3] = { p, P[L.RingIds[r][1]], P[L.RingIds[r][2]] };
        Tree.trianglesWithin(rp, Delta + dh, InputScratch);
      }
      if (!InputScratch.empty())
      {
        std::sort(InputScratch.begin(), InputScratch.end());
        InputScratch.erase(std::unique(InputScratch.begin(), InputScratch.end()), InputScratch.end());
        primitives(InputScratch, Input.Triangles, Input.Points, Delta, w.InputBarrier);
        barrierTerms(L, w.InputBarrier, p, dh, grad != nullptr, B, gb);
      }
      e += lambda * B;
      g += lambda * gb;
    }
    if (grad)
      *grad = g;
    return e;
  }

  // ---- static acceptance test ---------------------------------------------------------------

  /// The veto (Quality/LocalChangeVeto.h) on the ring of v moved to p: no needle or flip, no
  /// fold, no conflict with any other cage triangle. The input clearance of the ring at p is not
  /// tested again: sweepClear() established it (its tetrahedra have the ring at p as a face,
  /// tested with the same anyCloserThan). Sets the work's LastVeto.
  bool ringAcceptable(const Local& L, const Vec3& p) const
  {
    Work& w = work();
    LocalChangeScratch& s = w.Change;
    const std::size_t n = L.RingIds.size();
    s.Tris.resize(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      const auto& ids = L.RingIds[i];
      ChangedTriangle& t = s.Tris[i];
      for (int k = 0; k < 3; ++k)
        t.Ids[k] = ids[k];
      t.Pts[0] = p;
      t.Pts[1] = P[ids[1]];
      t.Pts[2] = P[ids[2]];
      t.Before[0] = L.P0;
      t.Before[1] = P[ids[1]];
      t.Before[2] = P[ids[2]];
      t.Reference = (P[ids[1]] - L.P0).cross(P[ids[2]] - L.P0);
      t.QualityBefore = triangleQuality(L.P0, P[ids[1]], P[ids[2]]);
    }
    s.Replaced.begin(T.size());
    for (int f : L.Ring)
      s.Replaced.insert(f);
    const LocalChangeVerdict v = MoveVeto.check(s);
    w.LastVeto = v == LocalChangeVerdict::Shape ? Veto::Shape : Veto::Self;
    return v == LocalChangeVerdict::Accepted;
  }

  /// Why descent steps failed (the reason of their last trial): energy not lowered, collision
  /// (CCD), shape (flip or needle), self-intersection (static test), fidelity (a ring sample
  /// beyond the Hausdorff budget).
  enum class Veto
  {
    Energy = 0,
    Collision,
    Shape,
    Self,
    Fidelity
  };

  // ---- one descent step at v: 1 moved, 0 converged (no descent direction), -1 no acceptable step
  /// `reach`: the first trial step (the later ones are shorter, so gathering within it covers
  /// them all). The caller updates the boxes of the ring's triangles after a move.
  int descend(int v, double reach)
  {
    Work& w = work();
    Local& L = w.L;
    gather(v, reach, L);
    Vec3 g;
    const double e0 = vertexEnergy(L, L.P0, &g);
    if (!std::isfinite(e0))
      return -1;
    Veto worst = Veto::Energy; // the last reason a trial step failed
    bool tried = false;
    if (Opt.Energy == CageEnergy::MIPS && Opt.TangentialRelaxation)
    {
      // tangential relaxation first: the gradient without its component along the area-weighted
      // vertex normal (still a descent direction of the whole energy), so the vertex slides
      // along the cage; where that finds no acceptable step (a crease of a tight cage), the
      // whole gradient below, the Hausdorff budget bounding how far it may lift the cage
      Vec3 n = Vec3::Zero();
      for (const auto& ids : L.RingIds)
        n += (P[ids[1]] - L.P0).cross(P[ids[2]] - L.P0);
      const double nn = n.norm();
      if (nn > 0)
      {
        n /= nn;
        const Vec3 gt = g - g.dot(n) * n;
        const int outcome = lineSearch(L, e0, gt, reach, worst);
        if (outcome > 0)
          return 1;
        tried = tried || outcome < 0;
      }
    }
    const int outcome = lineSearch(L, e0, g, reach, worst);
    if (outcome > 0)
      return 1;
    if (outcome == 0 && !tried)
      return 0;
    ++w.Counts[static_cast<int>(worst)];
    return -1;
  }

  /// Backtracking line search of descend() along -g from the vertex of L: 1 moved, 0 no
  /// descent direction, -1 no acceptable step (the reason of the last trial in `worst`).
  int lineSearch(Local& L, double e0, const Vec3& g, double reach, Veto& worst)
  {
    Work& w = work();
    const double gn = g.norm();
    if (!(gn > 0) || !std::isfinite(gn))
      return 0;
    const Vec3 dir = -g / gn;
    double step = reach;
    for (int k = 0; k < LineSearchTries; ++k, step *= 0.5)
    {
      // energy first (cheaper than the collision test), then the collision-free fraction
      const Vec3 move = step * dir;
      Vec3 p = L.P0 + move;
      // sufficient decrease (Armijo): at least a fraction of what the slope promises
      const double wanted = e0 - ArmijoFraction * step * gn;
      if (!(vertexEnergy(L, p, nullptr) <= wanted))
      {
        worst = Veto::Energy;
        continue;
      }
      const double t = advance(L, move);
      if (!(t > 0))
      {
        worst = Veto::Collision;
        return -1;
      }
      if (t < 1.0)
      {
        p = L.P0 + t * move;
        if (!(vertexEnergy(L, p, nullptr) <= e0 - ArmijoFraction * t * step * gn))
        {
          worst = Veto::Collision;
          continue;
        }
      }
      if (!ringAcceptable(L, p))
      {
        worst = w.LastVeto;
        continue;
      }
      if (!ringWithinBudget(L, p))
      {
        worst = Veto::Fidelity;
        continue;
      }
      P[L.V] = p;
      return 1;
    }
    return -1;
  }

  /// Per-thread scratch of the relocation (the const queries write only here).
  struct Work
  {
    Local L;
    std::vector<int> InputIds;
    Primitives InputBarrier;
    std::vector<std::uint64_t> Edges;
    std::vector<int> Points;
    Veto LastVeto = Veto::Shape;
    long long Counts[5] = { 0, 0, 0, 0, 0 };
    LocalChangeScratch Change; ///< the veto's scratch
    std::vector<int> Nearby;   ///< gather()'s cage triangles
  };
  Work& work() const { return Works.local(); }
  /// The veto counts summed over the threads.
  void counts(long long out[5]) const
  {
    for (int k = 0; k < 5; ++k)
      out[k] = 0;
    for (const Work& w : Works)
      for (int k = 0; k < 5; ++k)
        out[k] += w.Counts[k];
  }

  /// The triangles on edge (a, b): f1 = (a, b, c) and f2 = (b, a, d) (-1 where there is none).
  void edgeTriangles(int a, int b, int& f1, int& f2, int& c, int& d) const
  {
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
  }

  // ---- edge flip of (a, b): 1 flipped, 0 not worth it / not allowed topologically, -1 vetoed
  /// `byAngle`: the flip must raise the smaller of the pair's smallest angles instead of
  /// lowering E_quality (the repair of caps).
  int tryFlip(int a, int b, bool byAngle = false)
  {
    int f1 = -1, f2 = -1, c = -1, d = -1;
    edgeTriangles(a, b, f1, f2, c, d);
    if (f1 < 0 || f2 < 0 || c == d || VT[a].size() <= 3 || VT[b].size() <= 3)
      return 0;
    for (int f : VT[c]) // the new edge must not exist already (manifold)
      for (int w : T[f])
        if (w == d)
          return 0;
    const Triangle n1{ c, a, d }, n2{ d, b, c };
    if (byAngle)
    {
      const double before = std::min(minimumAngleOf(P[a], P[b], P[c]), minimumAngleOf(P[b], P[a], P[d]));
      const double after = std::min(minimumAngleOf(P[c], P[a], P[d]), minimumAngleOf(P[d], P[b], P[c]));
      if (!(after > before + 1e-9))
        return 0;
    }
    else
    {
      const double before =
        triangleEnergy(P[a], P[b], P[c], Tree, Opt) + triangleEnergy(P[b], P[a], P[d], Tree, Opt);
      const double after =
        triangleEnergy(P[c], P[a], P[d], Tree, Opt) + triangleEnergy(P[d], P[b], P[c], Tree, Opt);
      if (!(after < before - 1e-12 * std::abs(before)))
        return 0;
    }
    // the veto: both new triangles at least min(the floor, the worse old one), not flipped
    // against the old pair's mean normal, clear of the input and of the rest of the cage
    const double qBefore = std::min(triangleQuality(P[a], P[b], P[c]), triangleQuality(P[b], P[a], P[d]));
    const Vec3 nOld = (P[b] - P[a]).cross(P[c] - P[a]).normalized() + (P[a] - P[b]).cross(P[d] - P[b]).normalized();
    LocalChangeScratch& s = work().Change;
    s.Tris.resize(2);
    for (int i = 0; i < 2; ++i)
    {
      const Triangle& n = i == 0 ? n1 : n2;
      ChangedTriangle& t = s.Tris[i];
      for (int k = 0; k < 3; ++k)
      {
        t.Ids[k] = n[k];
        t.Pts[k] = P[n[k]];
      }
      t.Reference = nOld;
      t.QualityBefore = qBefore;
    }
    s.Replaced.begin(T.size());
    s.Replaced.insert(f1);
    s.Replaced.insert(f2);
    if (!changeAccepted(s))
      return -1;
    // the flip sweeps the tetrahedron (a, b, c, d): an input component wholly inside it (its
    // representative inside; none comes near the four faces) would end up outside the cage
    {
      const Vec3 lo = P[a].cwiseMin(P[b]).cwiseMin(P[c]).cwiseMin(P[d]);
      const Vec3 hi = P[a].cwiseMax(P[b]).cwiseMax(P[c]).cwiseMax(P[d]);
      const Vec3 t[4] = { P[a], P[b], P[c], P[d] };
      for (const Vec3& x : Representatives)
      {
        if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any())
          continue;
        const double s0 = (t[1] - x).dot((t[2] - x).cross(t[3] - x));
        const double s1 = (t[0] - x).dot((t[3] - x).cross(t[2] - x));
        const double s2 = (t[0] - x).dot((t[1] - x).cross(t[3] - x));
        const double s3 = (t[0] - x).dot((t[2] - x).cross(t[1] - x));
        if ((s0 >= 0 && s1 >= 0 && s2 >= 0 && s3 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0 && s3 <= 0))
          return -1;
      }
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

  // ---- fidelity: the Hausdorff budget ----------------------------------------------------------

  /// Budget (unit-sphere units) every sample of a changed triangle must stay within; 0 = none.
  void setBudget(double b) { Budget = b; }

  /// Are all samples of triangle (a, b, c) within the budget of the input?
  bool withinBudget(const Vec3& a, const Vec3& b, const Vec3& c) const
  {
    return !(Budget > 0) || triangleWithin(Tree, a, b, c, Budget, FidelityDepth);
  }

  /// A flip's or a collapse's new triangles (s.Tris, replacing s.Replaced): the veto (shape,
  /// fold, exact input clearance, self-intersection), then the Hausdorff budget.
  bool changeAccepted(LocalChangeScratch& s) const
  {
    if (FlipVeto.check(s) != LocalChangeVerdict::Accepted)
      return false;
    for (const ChangedTriangle& nt : s.Tris)
      if (!withinBudget(nt.Pts[0], nt.Pts[1], nt.Pts[2]))
        return false;
    return true;
  }

  /// The ring of v at p within the budget.
  bool ringWithinBudget(const Local& L, const Vec3& p) const
  {
    for (const auto& ids : L.RingIds)
      if (!withinBudget(p, P[ids[1]], P[ids[2]]))
        return false;
    return true;
  }

  // ---- repair of needles and caps (MIPS) ------------------------------------------------------

  double triangleMinimumAngle(int f) const
  {
    const Triangle& t = T[f];
    return minimumAngleOf(P[t[0]], P[t[1]], P[t[2]]);
  }

  /// Flags the vertices within `rings` rings of a triangle with an angle below `target`
  /// (degrees); returns how many.
  std::size_t markNearSmallAngles(double target, int rings, std::vector<char>& flags) const
  {
    flags.assign(P.size(), 0);
    std::vector<int> front;
    for (std::size_t f = 0; f < T.size(); ++f)
      if (triangleMinimumAngle(static_cast<int>(f)) < target)
        for (int v : T[f])
          if (!flags[v])
          {
            flags[v] = 1;
            front.push_back(v);
          }
    std::size_t count = front.size();
    std::vector<int> grown;
    for (int ring = 0; ring < rings && !front.empty(); ++ring)
    {
      grown.clear();
      for (int v : front)
        for (int f : VT[v])
          for (int w : T[f])
            if (!flags[w])
            {
              flags[w] = 1;
              grown.push_back(w);
            }
      count += grown.size();
      front.swap(grown);
    }
    return count;
  }

  /// One pass over the triangles with an angle below the target, worst first: a flip of one of
  /// its edges that raises the pair's smallest angle (the longest edge first); else the shortest
  /// edge is collapsed
  /// if every constraint allows it, and the longest edge of the cage is split at its midpoint in
  /// exchange (the vertex count stays exact). Returns false when cancelled.
  bool repairPass(OptimizeResult& r, long long& changes)
  {
    const double target = Opt.TargetMinimumAngle;
    std::vector<std::pair<double, int>> bad;
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      const double a = triangleMinimumAngle(static_cast<int>(f));
      if (a < target)
        bad.emplace_back(a, static_cast<int>(f));
    }
    std::sort(bad.begin(), bad.end());
    // at most a tenth of the vertices change places per pass (the split vertices need relocation)
    long long collapsesLeft = std::max<long long>(1, static_cast<long long>(P.size()) / 10);
    for (std::size_t i = 0; i < bad.size(); ++i)
    {
      if (i % 16 == 0 && progressCancelled(Prog))
        return false;
      const int f = bad[i].second;
      if (triangleMinimumAngle(f) >= target)
        continue; // mended by an earlier change (or its slot reused)
      const Triangle t = T[f];
      double ang[3];
      for (int k = 0; k < 3; ++k)
        ang[k] = cornerAngle(P[t[k]], P[t[(k + 1) % 3]], P[t[(k + 2) % 3]]);
      const int kMin = static_cast<int>(std::min_element(ang, ang + 3) - ang);
      const int kMax = static_cast<int>(std::max_element(ang, ang + 3) - ang);
      // the flips that raise the pair's smallest angle: the longest edge first (a cap's remedy),
      // then the others (a needle's neighbour may take its short edge)
      bool flipped = false;
      for (int e = 0; e < 3 && !flipped; ++e)
      {
        const int k = (kMax + e) % 3;
        const int outcome = tryFlip(t[(k + 1) % 3], t[(k + 2) % 3], true);
        if (outcome > 0)
        {
          ++r.Flips;
          ++changes;
          flipped = true;
        }
        else if (outcome < 0)
          ++r.RejectedFlips;
      }
      if (flipped)
        continue;
      if (collapsesLeft <= 0)
        continue;
      const int outcome = tryCollapse(t[(kMin + 1) % 3], t[(kMin + 2) % 3]);
      if (outcome > 0)
      {
        ++r.Collapses;
        ++changes;
        --collapsesLeft;
        continue;
      }
      if (outcome < 0)
        ++r.RejectedCollapses;
      // a cap (an obtuse corner) that neither a flip nor a collapse mends
      if (ang[kMax] > 90.0 && tryCapToFoot(f, t[kMax]) > 0)
      {
        ++r.Collapses;
        ++changes;
        --collapsesLeft;
      }
    }
    return true;
  }

  /// Smallest angle (degrees) of the ring of L's vertex placed at p.
  double ringMinimumAngle(const Local& L, const Vec3& p) const
  {
    double m = 180.0;
    for (const auto& ids : L.RingIds)
      m = std::min(m, minimumAngleOf(p, P[ids[1]], P[ids[2]]));
    return m;
  }

  /// Angle-targeted relocation of the corners of the triangles still below the target (MIPS
  /// with a target), worst first. The descent lowers the ring's summed MIPS energy, which can
  /// settle with one needle left in the ring (widening it would cost its neighbours more); here
  /// a corner instead tries positions that raise the smallest angle of its ring (max-min):
  /// AngleDirections directions in the tangent plane of the ring (area-weighted normal), each
  /// also tilted by ±AngleTilt toward the normal, at reach, reach / 2, ... (AngleSteps lengths,
  /// reach AngleReach times the ring's mean edge). Candidates are taken in descending order of
  /// the ring's smallest angle (the first AngleTries of them), and the first that every check of
  /// a descent step accepts is kept: the collision-free sweep (clearance to the input and to
  /// the rest of the cage, cut short where it must be and then judged again), the veto on the
  /// ring (shape, fold, self-intersection) and the Hausdorff budget. Returns false when cancelled; `changes` counts the moves.
  bool anglePass(OptimizeResult& r, long long& changes)
  {
    const double target = Opt.TargetMinimumAngle;
    std::vector<std::pair<double, int>> bad;
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      const double a = triangleMinimumAngle(static_cast<int>(f));
      if (a < target)
        bad.emplace_back(a, static_cast<int>(f));
    }
    std::sort(bad.begin(), bad.end());
    Local& L = work().L;
    std::vector<std::pair<double, Vec3>> candidates;
    for (std::size_t i = 0; i < bad.size(); ++i)
    {
      if (i % 16 == 0 && progressCancelled(Prog))
        return false;
      const int f = bad[i].second;
      for (int k = 0; k < 3; ++k)
      {
        if (triangleMinimumAngle(f) >= target)
          break; // mended
        const int v = T[f][k];
        double edgeSum = 0.0;
        for (int g : VT[v])
          for (int w : T[g])
            edgeSum += (P[w] - P[v]).norm(); // each neighbour twice
        const double reach = AngleReach * edgeSum / (2.0 * double(VT[v].size()));
        if (!(reach > 0))
          continue;
        gather(v, reach, L);
        const double before = ringMinimumAngle(L, L.P0);
        Vec3 n = Vec3::Zero();
        for (const auto& ids : L.RingIds)
          n += (P[ids[1]] - L.P0).cross(P[ids[2]] - L.P0);
        if (!(n.norm() > 0))
          continue;
        n.normalize();
        const Vec3 e1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
        const Vec3 e2 = n.cross(e1);
        candidates.clear();
        for (int d = 0; d < AngleDirections; ++d)
        {
          const double phi = 2.0 * M_PI * d / AngleDirections;
          const Vec3 tangent = std::cos(phi) * e1 + std::sin(phi) * e2;
          for (int tilt = -1; tilt <= 1; ++tilt)
          {
            const double psi = tilt * AngleTilt * M_PI / 180.0;
            const Vec3 dir = std::cos(psi) * tangent + std::sin(psi) * n;
            double step = reach;
            for (int s = 0; s < AngleSteps; ++s, step *= 0.5)
            {
              const Vec3 move = step * dir;
              const double a = ringMinimumAngle(L, L.P0 + move);
              if (a > before + AngleGain)
                candidates.emplace_back(a, move);
            }
          }
        }
        // the best first; ties (equal angles) keep the generation order (deterministic)
        std::stable_sort(candidates.begin(), candidates.end(),
          [](const std::pair<double, Vec3>& x, const std::pair<double, Vec3>& y) { return x.first > y.first; });
        const std::size_t tries = std::min<std::size_t>(candidates.size(), AngleTries);
        for (std::size_t c = 0; c < tries; ++c)
        {
          const Vec3& move = candidates[c].second;
          const double t = advance(L, move);
          if (!(t > 0))
            continue;
          const Vec3 p = L.P0 + t * move;
          if (t < 1.0 && !(ringMinimumAngle(L, p) > before + AngleGain))
            continue;
          if (!ringAcceptable(L, p) || !ringWithinBudget(L, p))
            continue;
          P[v] = p;
          for (int g : VT[v])
            updateBox(g);
          ++r.AngleMoves;
          ++changes;
          break;
        }
      }
    }
    return true;
  }

  /// Sorted neighbours of v.
  void neighbours(int v, std::vector<int>& out) const
  {
    out.clear();
    for (int f : VT[v])
      for (int w : T[f])
        if (w != v)
          out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  /// Collapses edge (a, b) (b merged into a, placed at the midpoint, at a or at b, lifted along
  /// the region's normal by 0, 0.1, ..., 0.5, 0.75 or 1 times the edge's length: the lowest
  /// that every check accepts and that raises the smallest angle of the region), then splits the
  /// longest edge of the cage with b's index and the two freed triangles. 1 done, 0 not allowed
  /// topologically or no improvement, -1 vetoed. The checks: the link condition; the veto on the
  /// new triangles (shape, fold, exact input clearance, self-intersection); the Hausdorff budget;
  /// and no input component swept out of the cage (the winding number of the region between the
  /// old and the new triangles at one point per component, as the simplifier does).
  int tryCollapse(int a, int b)
  {
    int f1 = -1, f2 = -1, c = -1, d = -1;
    edgeTriangles(a, b, f1, f2, c, d);
    if (f1 < 0 || f2 < 0 || c == d || VT[c].size() <= 3 || VT[d].size() <= 3)
      return 0;
    std::vector<int> na, nb;
    neighbours(a, na);
    neighbours(b, nb);
    if (na.size() + nb.size() <= 6)
      return 0;
    std::vector<int> common;
    std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
    if (common.size() != 2) // link condition: only c and d
      return 0;
    std::vector<int> changed;
    for (int v : { a, b })
      for (int f : VT[v])
        if (f != f1 && f != f2)
          changed.push_back(f);
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    double oldMin = std::min(triangleMinimumAngle(f1), triangleMinimumAngle(f2));
    for (int f : changed)
      oldMin = std::min(oldMin, triangleMinimumAngle(f));
    // where the merged vertex may go: the midpoint, a, b, and (a tight cage on a convex part
    // would otherwise cut into the clearance) the midpoint lifted along the region's normal
    Vec3 normal = Vec3::Zero();
    for (int f : changed)
      normal += areaNormal(P, T[f]);
    if (normal.norm() > 0)
      normal.normalize();
    const double len = (P[b] - P[a]).norm();
    const Vec3 mid = 0.5 * (P[a] + P[b]);
    const Vec3 bases[3] = { mid, P[a], P[b] };
    const double lifts[8] = { 0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.75, 1.0 };
    bool vetoed = false;
    LocalChangeScratch& s = work().Change;
    for (int candidate = 0; candidate < 24; ++candidate)
    {
      const Vec3 p = bases[candidate % 3] + lifts[candidate / 3] * len * normal;
      s.Tris.resize(changed.size());
      double newMin = 180.0;
      for (std::size_t i = 0; i < changed.size(); ++i)
      {
        const Triangle& old = T[changed[i]];
        Triangle ids = old;
        std::replace(ids.begin(), ids.end(), b, a);
        ChangedTriangle& nt = s.Tris[i];
        fillChanged(nt, ids, a, p, old);
        newMin = std::min(newMin, minimumAngleOf(nt.Pts[0], nt.Pts[1], nt.Pts[2]));
      }
      if (!(newMin > oldMin + 1e-9))
        continue;
      if (!regionChangeAccepted(s, changed, f1, f2))
      {
        vetoed = true;
        continue;
      }
      // commit the collapse: b merges into a at p
      for (int f : changed)
        for (int k = 0; k < 3; ++k)
          if (T[f][k] == b)
            T[f][k] = a;
      P[a] = p;
      VT[a] = changed;
      VT[b].clear();
      auto drop = [&](int v, int f) {
        auto& l = VT[v];
        l.erase(std::remove(l.begin(), l.end(), f), l.end());
      };
      drop(c, f1);
      drop(d, f2);
      Grid.remove(f1, Lo[f1], Hi[f1]);
      Grid.remove(f2, Lo[f2], Hi[f2]);
      for (int f : changed)
        updateBox(f);
      split(b, f1, f2);
      return 1;
    }
    return vetoed ? -1 : 0;
  }

  /// The remedy for a cap (triangle `cap` with its obtuse corner at `apex`) whose long edge (u, w)
  /// may not flip and whose short edges may not collapse (each leaves the Hausdorff budget or
  /// the clearance: anchor_dense's 500-vertex cage kept a 141-degree cap at 14.65 degrees): the
  /// long edge is split at the apex's foot and the apex collapsed into the split point, i.e. the
  /// apex moves onto the long edge and the cap and the triangle across (w, u, q) become
  /// (w, apex, q) and (apex, u, q), in the plane of the one across. The vertex count stays. The
  /// foot is tried first, then the points at 0.5, 0.35 and 0.65 of the edge. Same checks as a
  /// collapse (link condition, veto, budget, no component swept) and the smallest angle of the
  /// region must grow. 1 done, 0 not allowed or no improvement, -1 vetoed.
  int tryCapToFoot(int cap, int apex)
  {
    const Triangle t = T[cap];
    int k = 0;
    while (t[k] != apex)
      ++k;
    const int u = t[(k + 1) % 3], w = t[(k + 2) % 3];
    int f1 = -1, f2 = -1, c = -1, q = -1;
    edgeTriangles(u, w, f1, f2, c, q); // f1 = cap (u, w, apex), f2 = (w, u, q)
    if (f1 != cap || f2 < 0 || c != apex || q == apex || VT[u].size() <= 3 || VT[w].size() <= 3)
      return 0;
    for (int f : VT[apex]) // the new edge (apex, q) must not exist already
      for (int v : T[f])
        if (v == q)
          return 0;
    std::vector<int> changed;
    for (int f : VT[apex])
      if (f != cap)
        changed.push_back(f);
    double oldMin = std::min(triangleMinimumAngle(cap), triangleMinimumAngle(f2));
    for (int f : changed)
      oldMin = std::min(oldMin, triangleMinimumAngle(f));
    const Vec3 e = P[w] - P[u];
    const double foot = e.dot(P[apex] - P[u]) / e.squaredNorm();
    const double spots[4] = { std::min(0.8, std::max(0.2, foot)), 0.5, 0.35, 0.65 };
    const Triangle n1{ w, apex, q }, n2{ apex, u, q };
    const Vec3 across = areaNormal(P, Triangle{ w, u, q });
    const double qAcross = std::min(triangleQuality(P[u], P[w], P[apex]), triangleQuality(P[w], P[u], P[q]));
    bool vetoed = false;
    LocalChangeScratch& s = work().Change;
    for (const double spot : spots)
    {
      const Vec3 p = P[u] + spot * e;
      s.Tris.resize(changed.size() + 2);
      double newMin = 180.0;
      for (std::size_t i = 0; i < changed.size(); ++i)
        fillChanged(s.Tris[i], T[changed[i]], apex, p, T[changed[i]]);
      fillChanged(s.Tris[changed.size()], n1, apex, p, across, qAcross);
      fillChanged(s.Tris[changed.size() + 1], n2, apex, p, across, qAcross);
      for (const ChangedTriangle& nt : s.Tris)
        newMin = std::min(newMin, minimumAngleOf(nt.Pts[0], nt.Pts[1], nt.Pts[2]));
      if (!(newMin > oldMin + 1e-9))
        continue;
      if (!regionChangeAccepted(s, changed, cap, f2))
      {
        vetoed = true;
        continue;
      }
      T[cap] = n1;
      T[f2] = n2;
      P[apex] = p;
      auto drop = [&](int v, int f) {
        auto& l = VT[v];
        l.erase(std::remove(l.begin(), l.end(), f), l.end());
      };
      drop(u, cap); // u keeps f2 (now (apex, u, q)), w keeps cap (now (w, apex, q))
      drop(w, f2);
      VT[apex].push_back(f2);
      VT[q].push_back(cap);
      updateBox(cap);
      updateBox(f2);
      for (int f : changed)
        updateBox(f);
      return 1;
    }
    return vetoed ? -1 : 0;
  }

  /// nt: the triangle `ids` with vertex `moved` at p, judged against the normal `reference` and
  /// the quality `qualityBefore` of what it replaces (a collapse's and a cap remedy's new region).
  void fillChanged(ChangedTriangle& nt, const Triangle& ids, int moved, const Vec3& p, const Vec3& reference,
    double qualityBefore) const
  {
    for (int k = 0; k < 3; ++k)
    {
      nt.Ids[k] = ids[k];
      nt.Pts[k] = ids[k] == moved ? p : P[ids[k]];
    }
    nt.Reference = reference;
    nt.QualityBefore = qualityBefore;
  }
  /// The same, judged against the old triangle `old` it replaces.
  void fillChanged(ChangedTriangle& nt, const Triangle& ids, int moved, const Vec3& p, const Triangle& old) const
  {
    fillChanged(nt, ids, moved, p, areaNormal(P, old), triangleQuality(P[old[0]], P[old[1]], P[old[2]]));
  }

  /// The new triangles s.Tris in place of the old ones (changed, f1, f2) of a collapse or a cap's
  /// move onto its long edge: the veto and the budget (changeAccepted), and no input component
  /// swept out of the cage (sweepsComponent).
  bool regionChangeAccepted(LocalChangeScratch& s, const std::vector<int>& changed, int f1, int f2) const
  {
    s.Replaced.begin(T.size());
    s.Replaced.insert(f1);
    s.Replaced.insert(f2);
    for (int f : changed)
      s.Replaced.insert(f);
    return changeAccepted(s) && !sweepsComponent(s.Tris, changed, f1, f2);
  }

  /// Would replacing the old triangles (changed, f1, f2) by the new ones s sweep an input
  /// component out of the cage? Both close the swept region; its winding number at a
  /// component's representative point (the clearance keeps components off both) decides.
  bool sweepsComponent(const std::vector<ChangedTriangle>& tris, const std::vector<int>& changed, int f1, int f2) const
  {
    Vec3 lo = Vec3::Constant(Inf), hi = -lo;
    auto grow = [&](int f) {
      for (int v : T[f])
      {
        lo = lo.cwiseMin(P[v]);
        hi = hi.cwiseMax(P[v]);
      }
    };
    for (int f : changed)
      grow(f);
    grow(f1);
    grow(f2);
    for (const ChangedTriangle& nt : tris)
      for (const Vec3& q : nt.Pts)
      {
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
    for (const Vec3& x : Representatives)
    {
      if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any())
        continue;
      double angle = 0.0;
      for (int f : changed)
        angle += solidAngle(P[T[f][0]], P[T[f][1]], P[T[f][2]], x);
      angle += solidAngle(P[T[f1][0]], P[T[f1][1]], P[T[f1][2]], x);
      angle += solidAngle(P[T[f2][0]], P[T[f2][1]], P[T[f2][2]], x);
      for (const ChangedTriangle& nt : tris)
        angle -= solidAngle(nt.Pts[0], nt.Pts[1], nt.Pts[2], x);
      if (std::abs(angle) > 2.0 * M_PI) // |winding number| > 1/2
        return true;
    }
    return false;
  }

  /// Splits the longest edge of the cage at its midpoint, with the free vertex index m and the
  /// free triangle slots g3, g4 (those of a collapse). The surface does not change, so every
  /// constraint still holds.
  void split(int m, int g3, int g4)
  {
    double best = -1.0;
    int u = -1, w = -1;
    for (std::size_t f = 0; f < T.size(); ++f)
    {
      if (static_cast<int>(f) == g3 || static_cast<int>(f) == g4)
        continue;
      const Triangle& t = T[f];
      for (int k = 0; k < 3; ++k)
      {
        const double l = (P[t[(k + 1) % 3]] - P[t[k]]).squaredNorm();
        if (l > best) // first longest in triangle order: deterministic
        {
          best = l;
          u = t[k];
          w = t[(k + 1) % 3];
        }
      }
    }
    int g1 = -1, g2 = -1, e = -1, q = -1;
    for (int f : VT[u])
    {
      const Triangle& t = T[f];
      for (int k = 0; k < 3; ++k)
      {
        if (t[k] == u && t[(k + 1) % 3] == w)
        {
          g1 = f;
          e = t[(k + 2) % 3];
        }
        if (t[k] == w && t[(k + 1) % 3] == u)
        {
          g2 = f;
          q = t[(k + 2) % 3];
        }
      }
    }
    P[m] = 0.5 * (P[u] + P[w]);
    if (!Part.empty())
      Part[m] = Part[u]; // the free vertex may have come from another part
    T[g1] = { u, m, e };
    T[g3] = { m, w, e };
    T[g2] = { m, u, q };
    T[g4] = { w, m, q };
    auto drop = [&](int v, int f) {
      auto& l = VT[v];
      l.erase(std::remove(l.begin(), l.end(), f), l.end());
    };
    drop(w, g1);
    drop(w, g2);
    VT[w].push_back(g3);
    VT[w].push_back(g4);
    VT[e].push_back(g3);
    VT[q].push_back(g4);
    VT[m] = { g1, g3, g2, g4 };
    updateBox(g1);
    updateBox(g2);
    for (int f : { g3, g4 })
    {
      const Triangle& t = T[f];
      Lo[f] = P[t[0]].cwiseMin(P[t[1]]).cwiseMin(P[t[2]]);
      Hi[f] = P[t[0]].cwiseMax(P[t[1]]).cwiseMax(P[t[2]]);
      Grid.insert(f, Lo[f], Hi[f]);
    }
  }

  /// Refiles triangle f (moved or flipped) in the grid with its new box.
  void updateBox(int f)
  {
    const Triangle& t = T[f];
    Grid.remove(f, Lo[f], Hi[f]);
    Lo[f] = P[t[0]].cwiseMin(P[t[1]]).cwiseMin(P[t[2]]);
    Hi[f] = P[t[0]].cwiseMax(P[t[1]]).cwiseMax(P[t[2]]);
    Grid.insert(f, Lo[f], Hi[f]);
  }

private:
  const TriangleMesh& Input;
  const TriangleTree& Tree;
  OptimizeOptions Opt;
  double Delta;
  double SelfDelta;
  double ReadDelta = SelfDelta; ///< how far the veto reads around a change: SelfDelta or the part room
  Progress* Prog;
  std::vector<Vec3> P;
  std::vector<Triangle> T;
  std::vector<std::vector<int>> VT;
  std::vector<Vec3> Lo, Hi;          ///< triangle boxes, as filed in the grid
  CageGrid Grid;                     ///< updated between relocation batches and after each flip
  std::vector<Vec3> Representatives; ///< one input point per input component
  mutable tbb::enumerable_thread_specific<Work> Works;
  std::vector<int> Part;              ///< per vertex: its part, when room is kept between parts (else empty)
  LocalChangeVeto MoveVeto, FlipVeto; ///< read P, T, Lo, Hi, Grid and Part
  double Budget = 0.0;                ///< the Hausdorff budget (0: none)
};

/// One-sided Hausdorff distance cage -> input by branch and bound (the largest value reached;
/// the bound is at most 1/32 of the largest triangle's size above it), and the fraction of
/// triangle angles below `angle` degrees.
/// Once `progress` is cancelled it stops, with a lower bound of the distance.
double sampledHausdorff(const TriangleMesh& cage, const TriangleTree& tree, Progress* progress = nullptr)
{
  double lower = 0.0, upper = 0.0;
  for (const Triangle& t : cage.Triangles)
    for (int v : t)
      lower = std::max(lower, tree.distance(cage.Points[v]));
  for (std::size_t f = 0; f < cage.Triangles.size(); ++f)
  {
    if (f % 16 == 0 && progressCancelled(progress))
      break;
    const Triangle& t = cage.Triangles[f];
    triangleFarthest(tree, cage.Points[t[0]], cage.Points[t[1]], cage.Points[t[2]], FidelityDepth, lower, upper);
  }
  return lower;
}
/// Area fractions of a cage by its distance to the input: closer than lo, within [lo, hi],
/// farther than hi.
struct BandAreas
{
  double Closer = 0.0;
  double Within = 0.0;
  double Farther = 0.0;
};

/// The cage's BandAreas: every triangle cut into 4^3 = 64 by three rounds of midpoint
/// subdivision, each piece judged at its centroid (exact distances through the input's tree);
/// per triangle in parallel, summed in order.
BandAreas bandAreas(const TriangleMesh& cage, const TriangleTree& tree, double lo, double hi)
{
  const std::size_t n = cage.Triangles.size();
  std::vector<double> inside(n, 0.0), closer(n, 0.0), area(n, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<std::array<Vec3, 3>> pieces, next;
    for (std::size_t f = range.begin(); f != range.end(); ++f)
    {
      const Triangle& t = cage.Triangles[f];
      pieces.assign(1, { cage.Points[t[0]], cage.Points[t[1]], cage.Points[t[2]] });
      for (int round = 0; round < 3; ++round)
      {
        next.clear();
        for (const auto& q : pieces)
        {
          const Vec3 ab = 0.5 * (q[0] + q[1]), bc = 0.5 * (q[1] + q[2]), ca = 0.5 * (q[2] + q[0]);
          next.push_back({ q[0], ab, ca });
          next.push_back({ ab, q[1], bc });
          next.push_back({ ca, bc, q[2] });
          next.push_back({ ab, bc, ca });
        }
        pieces.swap(next);
      }
      for (const auto& q : pieces)
      {
        const double a = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
        const double d = tree.distance((q[0] + q[1] + q[2]) / 3.0);
        area[f] += a;
        if (d >= lo && d <= hi)
          inside[f] += a;
        else if (d < lo)
          closer[f] += a;
      }
    }
  });
  double in = 0.0, near = 0.0, all = 0.0;
  for (std::size_t f = 0; f < n; ++f)
  {
    in += inside[f];
    near += closer[f];
    all += area[f];
  }
  BandAreas b;
  if (all > 0.0)
  {
    b.Within = in / all;
    b.Closer = near / all;
    b.Farther = std::max(0.0, 1.0 - b.Within - b.Closer);
  }
  return b;
}

double smallAngleFraction(const TriangleMesh& cage, double angle)
{
  long long n = 0;
  for (const Triangle& t : cage.Triangles)
    for (int k = 0; k < 3; ++k)
      n += cornerAngle(cage.Points[t[k]], cage.Points[t[(k + 1) % 3]], cage.Points[t[(k + 2) % 3]]) < angle;
  return cage.Triangles.empty() ? 0.0 : double(n) / double(3 * cage.Triangles.size());
}

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
  const OptimizeOptions& options, Progress* progress, double progressBegin, double progressEnd)
{
  // stages over [progressBegin, progressEnd] of the whole run
  const auto stage = [&](const char* name, double b, double e) {
    progressStage(progress, name, progressBegin + (progressEnd - progressBegin) * b,
      progressBegin + (progressEnd - progressBegin) * e);
  };
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
  if (!(options.HausdorffFactor == 0 || (options.HausdorffFactor >= 1 && std::isfinite(options.HausdorffFactor))) ||
    !(options.TargetMinimumAngle >= 0 && options.TargetMinimumAngle < 60))
  {
    r.State = Status::InvalidInput;
    r.Message = "HausdorffFactor must be 0 (off) or >= 1, TargetMinimumAngle in [0, 60)";
    return r;
  }
  // the given cage must already satisfy the guarantees; measure its clearance
  stage("verifying the given cage", 0.0, 0.05);
  std::string why;
  double measured = 0.0;
  const auto tv = std::chrono::steady_clock::now();
  const bool givenOk =
    verifyEnclosure(input, cage, std::numeric_limits<double>::min(), measured, why, nullptr, progress, true, &inputTree);
  if (progressCancelled(progress))
  {
    // the given cage is not known to be valid: no cage (the pipeline keeps its own, verified)
    r.State = Status::Cancelled;
    r.Message = "cancelled while the given cage was verified: no cage";
    r.Cage = TriangleMesh();
    r.Seconds = seconds(start);
    return r;
  }
  if (!givenOk)
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
  const bool mipsMode = options.Energy == CageEnergy::MIPS;
  r.SmallAnglesBefore = smallAngleFraction(cage, options.TargetMinimumAngle);
  r.HausdorffBefore = sampledHausdorff(cage, inputTree, progress);
  if (!mipsMode)
    r.SpacingBandBefore = bandAreas(cage, inputTree, 0.8 * options.TargetSpacing, 1.2 * options.TargetSpacing).Within;
  if (progressCancelled(progress))
  {
    // the given cage, verified above (its distances are not measured again)
    r.State = Status::Cancelled;
    r.Reverted = true;
    r.Message = "cancelled before the optimization: the given cage is returned unchanged";
    r.MinimumClearance = measured;
    r.Seconds = seconds(start);
    return r;
  }
  r.VerificationSeconds = seconds(tv);

  // The room between the parts: as the given cage has it (at most 16 parts: a tree each). With
  // the simplifier's room (2.2 c) only, the spacing energy pushed two spheres' cages (0.08 apart)
  // onto it and the next nested level fused them; MIPS took a 100-vertex level from 0.028 to
  // 0.025 apart and the 40-vertex level after it fused.
  double partRoom = 0.0;
  std::vector<int> component; // per cage triangle, when the room is measured
  if (options.KeepPartsApart && options.MaximumPartRoom > selfDelta)
  {
    const int parts = triangleComponents(cage, component);
    if (parts > 1 && parts <= 16)
      partRoom = distanceBetweenParts(cage, options.MaximumPartRoom, component, parts);
    if (!(partRoom > selfDelta))
      partRoom = 0.0;
  }
  r.PartClearanceUsed = partRoom;
  Optimizer opt(cage, input, inputTree, options, delta, selfDelta, progress, partRoom, &component);
  if (mipsMode && options.HausdorffFactor > 0)
  {
    r.HausdorffBudget = options.HausdorffFactor * r.HausdorffBefore;
    opt.setBudget(r.HausdorffBudget);
  }
  bool cancelled = false;
  const auto copyCounts = [&]() {
    long long c[5];
    opt.counts(c);
    r.MovesVetoedByFidelity = c[4];
    r.MovesWithoutDescent = c[0];
    r.MovesCutByCollision = c[1];
    r.MovesVetoedByShape = c[2];
    r.MovesVetoedBySelfIntersection = c[3];
  };
  const int rounds = std::max(0, options.NumberOfIterations);
  // up to MaximumSweeps sweeps per round
  const int sweeps = std::max(1, options.MaximumSweeps);
  double energy = r.EnergyBefore;
  double bestAngle = r.MinimumAngleBefore;
  int stalled = 0;
  TriangleMesh best; // MIPS: the cage after the sweep with the largest smallest angle
  const bool repair = mipsMode && options.TargetMinimumAngle > 0;
  std::vector<char> active; // the vertices a narrowed sweep relocates
  const std::clock_t cpu0 = std::clock();
  for (int it = 0; it < rounds && !cancelled; ++it)
  {
    for (int sw = 0; sw < sweeps && !cancelled; ++sw)
    {
      const double b = 0.05 + 0.85 * (it + double(sw) / sweeps) / rounds;
      const double e = 0.05 + 0.85 * (it + double(sw + 1) / sweeps) / rounds;
      const long long movesBefore = r.Moves, flipsBefore = r.Flips;
      long long repairs = 0;
      stage("relocating cage vertices", b, b + 0.8 * (e - b));
      const auto t0 = std::chrono::steady_clock::now();
      // MIPS with a target: after the round's first sweep, only around the small angles
      const bool narrow = repair && sw > 0;
      if (narrow)
        opt.markNearSmallAngles(options.TargetMinimumAngle, ActiveRings, active);
      cancelled = !opt.relocationPass(r, 0.0, 1.0, narrow ? &active : nullptr);
      r.RelocationSeconds += seconds(t0);
      if (!cancelled && options.EdgeFlips)
      {
        stage("flipping cage edges", b + 0.8 * (e - b), b + 0.9 * (e - b));
        const auto t1 = std::chrono::steady_clock::now();
        cancelled = !opt.flipPass(r);
        r.FlipSeconds += seconds(t1);
      }
      if (!cancelled && repair)
      {
        stage("repairing needles", b + 0.9 * (e - b), e);
        const auto t1 = std::chrono::steady_clock::now();
        cancelled = !opt.repairPass(r, repairs);
        if (!cancelled && options.AngleRelocation)
          cancelled = !opt.anglePass(r, repairs);
        r.FlipSeconds += seconds(t1);
      }
      ++r.Sweeps;
      if (!mipsMode)
      {
        // the spacing energy: done when a sweep lowers it by less than SpacingConvergence
        const double e = cageEnergy(opt.mesh(), inputTree, options);
        const bool converged = !(energy - e > SpacingConvergence * energy);
        energy = e;
        if (converged)
          break;
        continue;
      }
      // done when no angle is below the target, when the sweep changed nothing, or when the
      // smallest angle has not grown for StallSweeps sweeps (a needle no change may mend)
      TriangleMesh now = opt.mesh();
      const double angle = minimumAngle(now);
      if (angle > bestAngle + 0.01)
      {
        stalled = 0;
      }
      else
        ++stalled;
      if (angle > bestAngle)
      {
        // the best cage so far (every state is valid: each change was checked)
        bestAngle = angle;
        best = std::move(now);
      }
      if (angle >= options.TargetMinimumAngle || (r.Moves == movesBefore && r.Flips == flipsBefore && repairs == 0) ||
        stalled >= StallSweeps)
        break;
    }
  }

  r.RelocationAndFlipCpuSeconds = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  copyCounts();
  // independent verification of the result (also after a cancel: the partial result is valid)
  stage("verifying the optimized cage", 0.9, 1.0);
  const auto t2 = std::chrono::steady_clock::now();
  TriangleMesh result = opt.mesh();
  // MIPS: the sweeps' smallest angle is not monotone (relocation lowers the sum of the energy);
  // keep the best cage seen after a sweep
  if (mipsMode && !best.Triangles.empty() && minimumAngle(result) < bestAngle)
    result = std::move(best);
  double clearance = 0.0;
  std::vector<double> dist;
  // after a cancel (before or during it) it gets VerificationGrace seconds
  GracePeriod grace(progress, VerificationGrace);
  // the parts' room: every change kept it; checked here like the enclosure
  bool roomKept = true;
  if (partRoom > 0)
  {
    const double apart = distanceBetweenParts(result, partRoom);
    roomKept = apart >= partRoom * (1.0 - 1e-9);
    if (!roomKept)
      why = "its parts are " + std::to_string(apart) + " apart, less than the room " + std::to_string(partRoom);
  }
  if (roomKept &&
    verifyEnclosure(input, result, delta, clearance, why, &dist, progress ? &grace : nullptr, true, &inputTree))
  {
    r.Cage = std::move(result);
    r.MinimumClearance = clearance;
    r.DistanceToInput = std::move(dist);
  }
  else if (grace.expired())
  {
    // cancelled, and the optimized cage could not be verified in time: the given cage (verified
    // above; its distances are not measured again)
    cancelled = true;
    r.Reverted = true;
    r.Message = "cancelled during optimization; the optimized cage could not be verified in time: the given cage "
                "is returned unchanged";
    r.Cage = cage;
    r.MinimumClearance = measured;
  }
  else
  {
    // should not happen: every change was checked. Keep the given (verified) cage.
    r.Reverted = true;
    r.Message = "the optimized cage failed verification (" + why + "); the given cage is returned unchanged";
    r.Cage = cage;
    verifyEnclosure(input, cage, std::numeric_limits<double>::min(), clearance, why, &dist, nullptr, true, &inputTree);
    r.MinimumClearance = clearance;
    r.DistanceToInput = std::move(dist);
  }
  r.VerificationSeconds += seconds(t2);
  r.EnergyAfter = cageEnergy(r.Cage, inputTree, options);
  r.MinimumAngleAfter = minimumAngle(r.Cage);
  r.SmallAnglesAfter = smallAngleFraction(r.Cage, options.TargetMinimumAngle);
  // after a cancel, bounded by the verification's grace (then a lower bound)
  r.HausdorffAfter = sampledHausdorff(r.Cage, inputTree, progress ? &grace : nullptr);
  if (!mipsMode)
  {
    const BandAreas after = bandAreas(r.Cage, inputTree, 0.8 * options.TargetSpacing, 1.2 * options.TargetSpacing);
    r.SpacingBandAfter = after.Within;
    r.SpacingCloserAfter = after.Closer;
    r.SpacingFartherAfter = after.Farther;
  }
  if (progress && grace.expired() && r.Message.find("lower bound") == std::string::npos)
    r.Message += std::string(r.Message.empty() ? "" : "; ") + "HausdorffAfter is a lower bound (cut short by the cancel)";
  r.State = cancelled ? Status::Cancelled : Status::Ok;
  if (cancelled && r.Message.empty())
    r.Message = "cancelled during optimization; the cage so far is valid";
  r.Seconds = seconds(start);
  progressUpdate(progress, 1.0);
  return r;
}

OptimizeResult optimizeCageInInputUnits(
  const TriangleMesh& cage, const TriangleMesh& input, const OptimizeOptions& options, Progress* progress)
{
  OptimizeResult r;
  r.Cage = cage;
  TriangleMesh in, cg;
  const MeshDefects di = prepareMesh(PolygonMesh::fromTriangles(input), in);
  if (!di.usableAsInput()) // any surface (open, soup) can be the input; the cage must be closed
  {
    r.State =
      di.Empty && di.NonFinitePoints == 0 && di.InvalidPointIds == 0 ? Status::EmptyInput : Status::InvalidInput;
    r.Message = "input mesh: " + di.inputErrorMessage();
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
