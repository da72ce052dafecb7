#include "Simplification/Simplification.h"

#include "Spatial/Geometry.h"
#include "Common/Progress.h"
#include "Spatial/TriangleTree.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <unordered_map>
#include <unordered_set>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace sdfcage
{

namespace
{

// ---- Garland-Heckbert quadric: symmetric 4x4 stored as 10 coefficients ------------------------
struct Quadric
{
  double A[10] = { 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 }; // xx xy xz xw yy yz yw zz zw ww

  static Quadric plane(const Vec3& n, double d, double w)
  {
    Quadric q;
    const double a = n.x(), b = n.y(), c = n.z();
    q.A[0] = w * a * a;
    q.A[1] = w * a * b;
    q.A[2] = w * a * c;
    q.A[3] = w * a * d;
    q.A[4] = w * b * b;
    q.A[5] = w * b * c;
    q.A[6] = w * b * d;
    q.A[7] = w * c * c;
    q.A[8] = w * c * d;
    q.A[9] = w * d * d;
    return q;
  }
  Quadric& operator+=(const Quadric& o)
  {
    for (int i = 0; i < 10; ++i)
    {
      A[i] += o.A[i];
    }
    return *this;
  }
  double eval(const Vec3& v) const
  {
    const double x = v.x(), y = v.y(), z = v.z();
    return A[0] * x * x + 2 * A[1] * x * y + 2 * A[2] * x * z + 2 * A[3] * x + A[4] * y * y +
      2 * A[5] * y * z + 2 * A[6] * y + A[7] * z * z + 2 * A[8] * z + A[9];
  }
  bool optimum(Vec3& v) const
  {
    Eigen::Matrix3d m;
    m << A[0], A[1], A[2], A[1], A[4], A[5], A[2], A[5], A[7];
    const Eigen::Vector3d b(-A[3], -A[6], -A[8]);
    // accept only well-conditioned systems: flat or cylindrical regions have no unique optimum
    // (det is the product of the eigenvalues, trace^3/27 the cube of their mean)
    const double tr = m.trace();
    const double det = m.determinant();
    if (!(tr > 0) || !(det > 1e-9 * tr * tr * tr / 27.0))
    {
      return false;
    }
    v = m.inverse() * b;
    return v.allFinite();
  }
};

// ---- dynamic uniform hash grid over the cage's triangle boxes ---------------------------------
class CageGrid
{
public:
  void reset(double cellSize)
  {
    Cell = cellSize;
    Cells.clear();
  }
  double cellSize() const { return Cell; }
  template <typename F>
  void forCells(const Vec3& lo, const Vec3& hi, F&& f) const
  {
    const std::int64_t i0 = key1(lo.x()), i1 = key1(hi.x());
    const std::int64_t j0 = key1(lo.y()), j1 = key1(hi.y());
    const std::int64_t k0 = key1(lo.z()), k1 = key1(hi.z());
    for (std::int64_t k = k0; k <= k1; ++k)
      for (std::int64_t j = j0; j <= j1; ++j)
        for (std::int64_t i = i0; i <= i1; ++i)
          f(((k & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (i & 0x1FFFFF));
  }
  void insert(int t, const Vec3& lo, const Vec3& hi)
  {
    forCells(lo, hi, [&](std::int64_t key) { Cells[key].push_back(t); });
  }
  void remove(int t, const Vec3& lo, const Vec3& hi)
  {
    forCells(lo, hi, [&](std::int64_t key) {
      auto it = Cells.find(key);
      if (it == Cells.end())
        return;
      auto& v = it->second;
      auto pos = std::find(v.begin(), v.end(), t);
      if (pos != v.end())
      {
        *pos = v.back();
        v.pop_back();
      }
    });
  }
  template <typename F>
  void query(const Vec3& lo, const Vec3& hi, F&& f) const
  {
    forCells(lo, hi, [&](std::int64_t key) {
      auto it = Cells.find(key);
      if (it != Cells.end())
        for (int t : it->second)
          f(t);
    });
  }

private:
  std::int64_t key1(double x) const { return static_cast<std::int64_t>(std::floor(x / Cell)); }
  double Cell = 1.0;
  std::unordered_map<std::int64_t, std::vector<int>> Cells;
};

struct Entry
{
  double Cost;
  int V0, V1;
  unsigned Ver0, Ver1;
  Vec3 Pos;
  bool operator<(const Entry& o) const
  {
    // min-heap on cost; ties broken by vertex ids so the order is deterministic
    if (Cost != o.Cost)
      return Cost > o.Cost;
    if (V0 != o.V0)
      return V0 > o.V0;
    return V1 > o.V1;
  }
};

enum class Verdict
{
  Ok,
  Topology,
  Shape,
  Input,
  Self
};

std::uint64_t edgeKey(int a, int b)
{
  if (a > b)
    std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

double triangleQuality(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const double area2 = (b - a).cross(c - a).norm(); // twice the area
  const double s = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return s > 0 ? 2.0 * std::sqrt(3.0) * area2 / s : 0.0;
}

// Neighbouring cage triangles whose dihedral angle closes below ~18 degrees count as folded.
constexpr double FoldCosine = -0.95;

// Candidate collapses evaluated together. The batch is formed, evaluated and applied the same way
// whatever the number of threads, so the cage does not depend on it.
constexpr int BatchSize = 32;

struct Sample
{
  bool Near = false; // the input lies within the descent's target distance
  double D = 0, Xi = 0;
  Vec3 Dir = Vec3::Zero();
};

struct NewTri
{
  int Ids[3];
  Vec3 Pts[3];
  Vec3 N;
  Vec3 C;   // centroid
  double R; // bounding radius about C
};

struct Candidate
{
  int F;
  int Ids[3];
  Vec3 Pts[3];
  Vec3 Lo, Hi, C;
  double R;
};

// Per-thread scratch of the evaluation (per-triangle stamps and reusable buffers).
struct Scratch
{
  explicit Scratch(std::size_t triangles = 0)
    : Mark(triangles, 0)
    , Seen(triangles, 0)
  {
  }
  std::vector<unsigned> Mark, Seen; // triangle stamps: of the collapse; already a candidate
  unsigned MarkId = 0, QueryId = 0;
  std::vector<int> N0, N1;
  std::vector<NewTri> NewTris;
  std::vector<Candidate> Candidates;
  std::vector<std::pair<int, Sample>> SampleCache;
};

// One candidate collapse and everything its evaluation found and read. Evaluations only read the
// cage; what they learn is applied afterwards, in the batch's order, by one thread.
struct Eval
{
  Entry E;
  int C0 = -1, C1 = -1; // v0 survives, v1 goes
  std::vector<int> Removed, Changed;
  std::vector<int> Verts; // C0, C1 and their neighbours: the vertices the evaluation read
  bool Gathered = false, Feasible = false, Relocated = false;
  Vec3 Pos = Vec3::Zero();
  double Cost = 0;
  bool HasRead = false; // the cage triangles read lie within [ReadLo, ReadHi]
  Vec3 ReadLo = Vec3::Zero(), ReadHi = Vec3::Zero();
  std::vector<std::pair<int, double>> Dist; // vertex distances to the input measured
  Vec3 LastCheckPos = Vec3::Zero();
  double LastCheckDistance = -1;
  bool LastCheckExact = false; // check() measured the exact distance of LastCheckPos
  long long RejInput = 0, RejSelf = 0, RejShape = 0;
  Scratch* S = nullptr;
};

class Simplifier
{
public:
  Simplifier(const TriangleMesh& mesh, const TriangleTree& input, const SimplifyOptions& o, Progress* p,
    const std::vector<Vec3>* probes)
    : Input(input)
    , Opt(o)
    , Original(o)
    , Prog(p)
    , Scratches(Scratch(mesh.Triangles.size()))
  {
    P = mesh.Points;
    T = mesh.Triangles;
    VAlive.assign(P.size(), 1);
    TAlive.assign(T.size(), 1);
    VT.assign(P.size(), {});
    for (std::size_t f = 0; f < T.size(); ++f)
      for (int v : T[f])
        VT[v].push_back(static_cast<int>(f));
    Ver.assign(P.size(), 0);
    D.assign(P.size(), -1.0);
    VStamp.assign(P.size(), 0);
    BlockedAt.assign(P.size(), {});
    AliveVertices = static_cast<int>(P.size());
    AliveTriangles = static_cast<int>(T.size());
    Q.assign(P.size(), Quadric());
    for (const Triangle& t : T)
    {
      const Vec3 n = (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]);
      const double area = 0.5 * n.norm();
      if (!(area > 0))
        continue;
      const Vec3 u = n.normalized();
      const Quadric q = Quadric::plane(u, -u.dot(P[t[0]]), area);
      for (int v : t)
        Q[v] += q;
    }
    rebuildGrid();
    if (probes)
    {
      Probes = *probes;
      std::sort(Probes.begin(), Probes.end(), [](const Vec3& a, const Vec3& b) { return a.x() < b.x(); });
    }
  }

  SimplifyResult run()
  {
    SimplifyResult r;
    const auto t0 = std::chrono::steady_clock::now();
    const int start = AliveVertices;
    const int target = std::max(4, Opt.TargetNumberOfVertices);
    {
      // the edge of an equilateral triangle of the target's mean area (about 2 target triangles)
      double area = 0;
      for (const Triangle& t : T)
        area += 0.5 * (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]).norm();
      const double edge = std::sqrt(4.0 / std::sqrt(3.0) * area / (2.0 * target));
      PlacementReach = std::max(16.0 * Opt.Clearance, edge);
    }
    for (std::size_t v = 0; v < P.size(); ++v)
      for (int n : neighbours(static_cast<int>(v)))
        if (static_cast<int>(v) < n)
          pushEdge(static_cast<int>(v), n);
    // Pass 0 is the ordinary run. When the queue runs dry above the target, later passes retry
    // every blocked edge with a more thorough placement search (pass 1) and then with relaxed
    // shape bounds (pass 2, see relaxShape()); a pass that collapses something is repeated.
    // The clearance and self-intersection tests are the same exact tests in every pass.
    for (Pass = 0; Pass <= 2 && AliveVertices > target; ++Pass)
    {
      if (Pass > 0)
      {
        if (r.Cancelled || !requeueBlocked())
          continue;
        if (Pass == 2)
          relaxShape();
      }
      const long long before = Stats.Collapses;
      drain(target, start, r);

      // progress: try this pass again on what is now blocked (a bounded number of times: each
      // retry runs the thorough search on every blocked edge)
      if (Pass > 0 && Stats.Collapses > before && AliveVertices > target && ++Retries <= MaxRetries)
        --Pass;
    }
    const bool cancelled = r.Cancelled;
    r = Stats;
    r.Cancelled = cancelled || progressCancelled(Prog);
    r.VerticesReached = AliveVertices;
    r.TargetReached = AliveVertices <= target;
    if (!r.TargetReached)
      r.StopReason = r.Cancelled ? "cancelled"
                                 : "no remaining collapse keeps the clearance, self-intersection, "
                                   "topology, shape and placement-distance constraints";
    r.Cage = compact();
    r.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  }

  // Pops and collapses edges until the target or an empty queue, a batch at a time: the cheapest
  // valid entries whose neighbourhoods lie apart are evaluated side by side (in parallel), then
  // applied in queue order. An evaluation whose neighbourhood an earlier collapse of the batch
  // touched (shared vertices or overlapping boxes) is not applied but queued again, so every
  // applied decision is the one the sequential algorithm would take on the current cage.
  void drain(int target, int start, SimplifyResult& r)
  {
    std::vector<Eval> batch(BatchSize);
    std::vector<Entry> aside;
    std::vector<std::pair<Vec3, Vec3>> formBoxes, writeBoxes;
    const double margin = Opt.selfClearance();
    while (AliveVertices > target && !Heap.empty())
    {
      if (++BatchesSinceProgress >= 16)
      {
        BatchesSinceProgress = 0;
        if (Prog && Prog->update(double(start - AliveVertices) / std::max(1, start - target)))
        {
          r.Cancelled = true;
          break;
        }
      }
      // form: valid entries in queue order, skipping (for the next batch) those next to a member
      int n = 0;
      aside.clear();
      formBoxes.clear();
      while (n < BatchSize && !Heap.empty() && aside.size() < 2 * BatchSize)
      {
        const Entry e = Heap.top();
        Heap.pop();
        if (!VAlive[e.V0] || !VAlive[e.V1] || Ver[e.V0] != e.Ver0 || Ver[e.V1] != e.Ver1)
          continue;
        Vec3 lo = e.Pos, hi = e.Pos;
        for (int v : { e.V0, e.V1 })
          for (int f : VT[v])
            for (int w : T[f])
            {
              lo = lo.cwiseMin(P[w]);
              hi = hi.cwiseMax(P[w]);
            }
        lo -= Vec3::Constant(margin);
        hi += Vec3::Constant(margin);
        bool near = false;
        for (const auto& b : formBoxes)
          near = near || !((b.first.array() > hi.array()).any() || (b.second.array() < lo.array()).any());
        if (near)
        {
          aside.push_back(e);
          continue;
        }
        formBoxes.emplace_back(lo, hi);
        batch[n++].E = e;
      }
      for (const Entry& e : aside)
        Heap.push(e);
      if (n == 0)
        continue;

      // evaluate
      if (n > 1)
        tbb::parallel_for(0, n, [&](int i) { evaluate(batch[i], Scratches.local()); });
      else
        evaluate(batch[0], Scratches.local());

      // apply, in order
      ++BatchStamp;
      writeBoxes.clear();
      for (int i = 0; i < n && AliveVertices > target; ++i)
      {
        Eval& ev = batch[i];
        if (touched(ev, writeBoxes))
        {
          Heap.push(ev.E); // evaluated on a neighbourhood that has changed since: again later
          continue;
        }
        for (const auto& vd : ev.Dist)
          if (D[vd.first] < 0)
            D[vd.first] = vd.second;
        Stats.RejectedInput += ev.RejInput;
        Stats.RejectedSelf += ev.RejSelf;
        Stats.RejectedShape += ev.RejShape;
        if (!ev.Gathered)
        {
          ++Stats.RejectedTopology;
          block(ev.E.V0, ev.E.V1);
          continue;
        }
        if (!ev.Feasible)
        {
          block(ev.E.V0, ev.E.V1);
          continue;
        }
        if (ev.Relocated)
        {
          ++Stats.Relocated;
          if (!Heap.empty() && ev.Cost > Heap.top().Cost)
          {
            // no longer the cheapest: queue it with its feasible placement
            Heap.push({ ev.Cost, ev.C0, ev.C1, Ver[ev.C0], Ver[ev.C1], ev.Pos });
            continue;
          }
        }
        // what this collapse writes: its vertices and the box of its old and new triangles
        Vec3 lo = ev.Pos, hi = ev.Pos;
        for (int v : ev.Verts)
        {
          VStamp[v] = BatchStamp;
          lo = lo.cwiseMin(P[v]);
          hi = hi.cwiseMax(P[v]);
        }
        writeBoxes.emplace_back(lo, hi);
        collapse(ev);
        ++Stats.Collapses;
        if (AliveTriangles * 2 < GridTriangles)
          rebuildGrid();
      }
    }
  }

  // Did a collapse applied earlier in this batch change what `ev` read?
  bool touched(const Eval& ev, const std::vector<std::pair<Vec3, Vec3>>& writeBoxes) const
  {
    if (writeBoxes.empty())
      return false;
    for (int v : ev.Verts)
      if (VStamp[v] == BatchStamp)
        return true;
    if (ev.HasRead)
      for (const auto& b : writeBoxes)
        if (!((b.first.array() > ev.ReadHi.array()).any() || (b.second.array() < ev.ReadLo.array()).any()))
          return true;
    return false;
  }

  // Evaluates the collapse of ev.E on the current cage (reads only; any thread).
  void evaluate(Eval& ev, Scratch& s) const
  {
    ev.S = &s;
    ev.Gathered = ev.Feasible = ev.Relocated = false;
    ev.HasRead = false;
    ev.Dist.clear();
    ev.LastCheckExact = false;
    ev.RejInput = ev.RejSelf = ev.RejShape = 0;
    ev.Gathered = gather(ev);
    if (!ev.Gathered)
      return;
    Vec3 pos = ev.E.Pos;
    const Verdict v = check(pos, ev);
    if (v != Verdict::Ok)
    {
      countReject(v, ev);
      if (!place(pos, v, ev))
        return;
      ev.Relocated = true;
      ev.Cost = costAt(ev.C0, ev.C1, pos);
    }
    ev.Feasible = true;
    ev.Pos = pos;
  }

  // Queues every blocked edge again; false if there is none.
  bool requeueBlocked()
  {
    if (Blocked.empty())
      return false;
    std::vector<std::uint64_t> keys(Blocked.begin(), Blocked.end());
    std::sort(keys.begin(), keys.end()); // the set's order is not deterministic across builds
    Blocked.clear();
    for (auto& l : BlockedAt)
      l.clear();
    for (std::uint64_t k : keys)
    {
      const int a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xFFFFFFFFu);
      if (VAlive[a] && VAlive[b])
        pushEdge(a, b);
    }
    return true;
  }

  // Late, when nothing else collapses: the normal bound drops to 0 (a new triangle may turn up
  // to 90 degrees from the one it replaces, still no flip) and the needle bound to half. Folds,
  // crossings and clearances are checked exactly as before.
  void relaxShape()
  {
    Opt.MinimumNormalCosine = std::min(Opt.MinimumNormalCosine, 0.0);
    Opt.MinimumTriangleQuality = 0.5 * Original.MinimumTriangleQuality;
  }

  // The placement `pos` of the gathered collapse failed with verdict `first`. Looks for a
  // feasible one: the midpoint and the endpoints; the Psi descent from the placement (and, in the
  // thorough passes, from the other starts); in the thorough passes, an outward walk along the
  // one-ring's normal. Returns the cheapest found first in that order.
  bool place(Vec3& pos, Verdict first, Eval& ev) const
  {
    // the ordinary pass keeps to the Psi descent from the placement when the input is too
    // close: trying alternatives on every rejection of a dense envelope costs more than it gains
    if (Pass == 0)
    {
      if (first != Verdict::Input)
        return false;
      Vec3 p = pos;
      if (!relocate(p, ev))
        return false;
      pos = p;
      return true;
    }
    const int c0 = ev.C0, c1 = ev.C1;
    const Vec3 starts[4] = { pos, 0.5 * (P[c0] + P[c1]), P[c0], P[c1] };
    // the alternatives by increasing cost: the first feasible one is the cheapest
    int order[3] = { 1, 2, 3 };
    double cost[4];
    for (int i = 1; i < 4; ++i)
      cost[i] = costAt(c0, c1, starts[i]);
    std::sort(order, order + 3, [&](int a, int b) { return cost[a] < cost[b] || (cost[a] == cost[b] && a < b); });
    for (int i : order)
      if (check(starts[i], ev) == Verdict::Ok && withinReach(starts[i]))
      {
        pos = starts[i];
        return true;
      }
    for (int i = 0; i < 4; ++i)
    {
      Vec3 p = starts[i];
      if (relocate(p, ev) && withinReach(p))
      {
        pos = p;
        return true;
      }
    }
    // outward walk: the area-weighted normal of the current one-ring of the edge
    Vec3 n = Vec3::Zero();
    for (int f : ev.Changed)
      n += (P[T[f][1]] - P[T[f][0]]).cross(P[T[f][2]] - P[T[f][0]]);
    for (int f : ev.Removed)
      n += (P[T[f][1]] - P[T[f][0]]).cross(P[T[f][2]] - P[T[f][0]]);
    if (!(n.norm() > 0))
      return false;
    n.normalize();
    double reach = (P[c0] - P[c1]).norm();
    for (int f : ev.Changed)
      for (int v : T[f])
        reach = std::max(reach, (P[v] - P[c0]).norm());
    for (int i = 0; i < 4; ++i)
      for (double t = Opt.Clearance; t <= reach; t *= 2)
      {
        const Vec3 p = starts[i] + t * n;
        if (check(p, ev) == Verdict::Ok && withinReach(p))
        {
          pos = p;
          return true;
        }
      }
    return false;
  }

  // The thorough passes place a vertex no farther from the input than PlacementReach: without a
  // bound, repeated outward walks on a stubborn region (dragon_quartet at 200 vertices) inflated
  // the cage to 0.67 of the input's diagonal from it.
  bool withinReach(const Vec3& p) const
  {
    Vec3 c;
    int tri;
    double d;
    return Input.closestPoint(p, PlacementReach, c, tri, d);
  }

private:
  // distance from cage vertex v to the input (exact, or a lower bound when beyond a cap),
  // measured when first needed after v moved (kept in ev until the batch applies it)
  double vertexDistance(int v, Eval& ev) const
  {
    if (D[v] >= 0)
      return D[v];
    for (const auto& vd : ev.Dist)
      if (vd.first == v)
        return vd.second;
    // bounded query: beyond the cap, the cap itself is a valid lower bound and enough to clear
    // any triangle of the dense and middle stages
    const double cap = 16.0 * Opt.Clearance;
    Vec3 c;
    int tri;
    double d;
    const double value = Input.closestPoint(P[v], cap, c, tri, d) ? d : cap;
    ev.Dist.emplace_back(v, value);
    return value;
  }

  // ---- adjacency ----
  std::vector<int> neighbours(int v) const
  {
    std::vector<int> n;
    neighbours(v, n);
    return n;
  }
  void neighbours(int v, std::vector<int>& n) const
  {
    n.clear();
    for (int f : VT[v])
      for (int w : T[f])
        if (w != v)
          n.push_back(w);
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }

  double costAt(int a, int b, const Vec3& p) const
  {
    Quadric q = Q[a];
    q += Q[b];
    return std::max(0.0, q.eval(p));
  }

  void pushEdge(int a, int b)
  {
    Quadric q = Q[a];
    q += Q[b];
    const Vec3 mid = 0.5 * (P[a] + P[b]);
    Vec3 best = mid;
    double bestCost = q.eval(mid);
    Vec3 opt;
    if (q.optimum(opt) && (opt - mid).norm() <= 2.0 * (P[a] - P[b]).norm())
    {
      best = opt;
      bestCost = q.eval(opt);
    }
    else
    {
      for (const Vec3& c : { P[a], P[b] })
      {
        const double cc = q.eval(c);
        if (cc < bestCost)
        {
          bestCost = cc;
          best = c;
        }
      }
    }
    Heap.push({ std::max(0.0, bestCost), a, b, Ver[a], Ver[b], best });
  }

  // A blocked edge is retried when its neighbourhood changes: it is filed under both endpoints
  // and re-queued when a collapse lands next to either of them.
  void block(int a, int b)
  {
    if (Blocked.insert(edgeKey(a, b)).second)
    {
      BlockedAt[a].push_back(b);
      BlockedAt[b].push_back(a);
    }
  }

  bool gather(Eval& ev) const
  {
    Scratch& s = *ev.S;
    const int v0 = ev.E.V0, v1 = ev.E.V1;
    ev.C0 = v0;
    ev.C1 = v1;
    ev.Removed.clear();
    ev.Changed.clear();
    neighbours(v0, s.N0);
    neighbours(v1, s.N1);
    ev.Verts.assign(s.N0.begin(), s.N0.end());
    ev.Verts.insert(ev.Verts.end(), s.N1.begin(), s.N1.end());
    ev.Verts.push_back(v0);
    ev.Verts.push_back(v1);
    for (int f : VT[v0])
    {
      const Triangle& t = T[f];
      if (t[0] == v1 || t[1] == v1 || t[2] == v1)
        ev.Removed.push_back(f);
      else
        ev.Changed.push_back(f);
    }
    for (int f : VT[v1])
    {
      const Triangle& t = T[f];
      if (!(t[0] == v0 || t[1] == v0 || t[2] == v0))
        ev.Changed.push_back(f);
    }
    if (ev.Removed.size() != 2)
      return false;
    // link condition: the common neighbours of v0 and v1 are exactly the two opposite vertices
    std::size_t common = 0;
    for (std::size_t i = 0, j = 0; i < s.N0.size() && j < s.N1.size();)
    {
      if (s.N0[i] < s.N1[j])
        ++i;
      else if (s.N1[j] < s.N0[i])
        ++j;
      else
      {
        ++common;
        ++i;
        ++j;
      }
    }
    if (common != 2)
      return false;
    // keep at least a tetrahedron per component
    if (s.N0.size() + s.N1.size() <= 6 && AliveVertices <= 4)
      return false;
    ++s.MarkId;
    if (s.MarkId == 0)
    {
      std::fill(s.Mark.begin(), s.Mark.end(), 0);
      s.MarkId = 1;
    }
    for (int f : ev.Removed)
      s.Mark[f] = s.MarkId;
    for (int f : ev.Changed)
      s.Mark[f] = s.MarkId;
    return true;
  }

  // new vertex ids and positions of changed triangle f when the collapse puts v0 at p
  void newTriangle(const Eval& ev, int f, const Vec3& p, int ids[3], Vec3 pts[3]) const
  {
    for (int k = 0; k < 3; ++k)
    {
      int v = T[f][k];
      if (v == ev.C1)
        v = ev.C0;
      ids[k] = v;
      pts[k] = v == ev.C0 ? p : P[v];
    }
  }

  Verdict check(const Vec3& p, Eval& ev) const
  {
    Scratch& s = *ev.S;
    ev.LastCheckExact = false;
    const double delta = Opt.Clearance;
    const double selfDelta = Opt.selfClearance();
    auto& newTris = s.NewTris;
    newTris.resize(ev.Changed.size());
    // shape first (cheap): no needles, no flips
    for (std::size_t i = 0; i < ev.Changed.size(); ++i)
    {
      auto& nt = newTris[i];
      newTriangle(ev, ev.Changed[i], p, nt.Ids, nt.Pts);
      if (triangleQuality(nt.Pts[0], nt.Pts[1], nt.Pts[2]) < Opt.MinimumTriangleQuality)
        return Verdict::Shape;
      const Triangle& old = T[ev.Changed[i]];
      const Vec3 no = (P[old[1]] - P[old[0]]).cross(P[old[2]] - P[old[0]]);
      nt.N = (nt.Pts[1] - nt.Pts[0]).cross(nt.Pts[2] - nt.Pts[0]);
      nt.C = (nt.Pts[0] + nt.Pts[1] + nt.Pts[2]) / 3.0;
      nt.R = std::max({ (nt.Pts[0] - nt.C).norm(), (nt.Pts[1] - nt.C).norm(), (nt.Pts[2] - nt.C).norm() });
      if (no.dot(nt.N) <= Opt.MinimumNormalCosine * no.norm() * nt.N.norm())
        return Verdict::Shape;
    }
    // among the new triangles (they all share v0): no folds, no crossings
    for (std::size_t i = 0; i < newTris.size() && Opt.EnforceNoSelfIntersection; ++i)
      for (std::size_t j = i + 1; j < newTris.size(); ++j)
        if (trianglesConflict(newTris[i].Ids, newTris[i].Pts, newTris[j].Ids, newTris[j].Pts, selfDelta, FoldCosine))
          return Verdict::Self;
    // the input: clearance delta. Early-out (the distance to the input is 1-Lipschitz): every new
    // triangle lies within `reach` of p (its farthest point from p is a corner), so if no input
    // lies within delta + reach of p, all of them are clear. Otherwise exact triangle-triangle
    // distances through the tree.
    if (Opt.EnforceClearance)
    {
      // Early-outs from the distance being 1-Lipschitz. A point x of a triangle with barycentric
      // weights l_k satisfies sum_k l_k |x - v_k|^2 = sum_k l_k |v_k - o|^2 - |x - o|^2 for any o,
      // so with o the centroid, the average of |x - v_k| is at most R (the corners' largest
      // distance from the centroid) and d(x) >= sum_k l_k (D(v_k) - |x - v_k|) >= min_k D(v_k) - R.
      // D(p) comes from one query bounded by delta + max R (beyond it, that bound is all we need);
      // the other corners' distances are cached per vertex. Triangles the bound does not clear
      // get the exact triangle-input distance through the tree.
      double maxR = 0;
      for (const auto& nt : newTris)
        maxR = std::max(maxR, nt.R);
      const double limit = delta + maxR;
      Vec3 c;
      int tri;
      double dp;
      if (!Input.closestPoint(p, limit, c, tri, dp))
        dp = limit;
      else
      {
        ev.LastCheckPos = p;
        ev.LastCheckDistance = dp;
        ev.LastCheckExact = true;
      }
      for (const auto& nt : newTris)
      {
        double lo = dp;
        for (int k = 0; k < 3 && lo - nt.R > delta * (1 + 1e-9); ++k)
          if (nt.Ids[k] != ev.C0)
            lo = std::min(lo, vertexDistance(nt.Ids[k], ev));
        if (lo - nt.R > delta * (1 + 1e-9))
          continue;
        if (Input.anyCloserThan(nt.Pts, delta))
          return Verdict::Input;
      }
      if (sweepsProbe(p, ev))
        return Verdict::Input;
    }
    if (!Opt.EnforceNoSelfIntersection)
      return Verdict::Ok;
    // the rest of the cage: one grid query for the whole new one-ring, then per pair a box test,
    // a bounding-sphere test for disjoint triangles, and the exact conflict test
    Vec3 ringLo = Vec3::Constant(std::numeric_limits<double>::infinity()), ringHi = -ringLo;
    for (const auto& nt : newTris)
      for (const Vec3& q : nt.Pts)
      {
        ringLo = ringLo.cwiseMin(q);
        ringHi = ringHi.cwiseMax(q);
      }
    ringLo -= Vec3::Constant(selfDelta);
    ringHi += Vec3::Constant(selfDelta);
    if (ev.HasRead)
    {
      ev.ReadLo = ev.ReadLo.cwiseMin(ringLo);
      ev.ReadHi = ev.ReadHi.cwiseMax(ringHi);
    }
    else
    {
      ev.ReadLo = ringLo;
      ev.ReadHi = ringHi;
      ev.HasRead = true;
    }
    auto& candidates = s.Candidates;
    candidates.clear();
    ++s.QueryId;
    if (s.QueryId == 0)
    {
      std::fill(s.Seen.begin(), s.Seen.end(), 0);
      s.QueryId = 1;
    }
    Grid.query(ringLo, ringHi, [&](int f) {
      if (!TAlive[f] || s.Mark[f] == s.MarkId || s.Seen[f] == s.QueryId)
        return;
      s.Seen[f] = s.QueryId;
      Candidate c;
      c.F = f;
      for (int k = 0; k < 3; ++k)
      {
        c.Ids[k] = T[f][k];
        c.Pts[k] = P[T[f][k]];
      }
      c.Lo = c.Pts[0].cwiseMin(c.Pts[1]).cwiseMin(c.Pts[2]);
      c.Hi = c.Pts[0].cwiseMax(c.Pts[1]).cwiseMax(c.Pts[2]);
      if ((c.Lo.array() > ringHi.array()).any() || (c.Hi.array() < ringLo.array()).any())
        return;
      c.C = (c.Pts[0] + c.Pts[1] + c.Pts[2]) / 3.0;
      c.R = std::max({ (c.Pts[0] - c.C).norm(), (c.Pts[1] - c.C).norm(), (c.Pts[2] - c.C).norm() });
      candidates.push_back(c);
    });
    for (const auto& nt : newTris)
    {
      const Vec3 lo = nt.Pts[0].cwiseMin(nt.Pts[1]).cwiseMin(nt.Pts[2]) - Vec3::Constant(selfDelta);
      const Vec3 hi = nt.Pts[0].cwiseMax(nt.Pts[1]).cwiseMax(nt.Pts[2]) + Vec3::Constant(selfDelta);
      for (const Candidate& c : candidates)
      {
        if ((c.Lo.array() > hi.array()).any() || (c.Hi.array() < lo.array()).any())
          continue;
        int shared = 0, ka = -1, kb = -1;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (nt.Ids[i] == c.Ids[j])
            {
              ++shared;
              ka = i;
              kb = j;
            }
        const bool disjoint = shared == 0;
        // sharing one vertex: they cannot meet elsewhere when the other two corners of one lie
        // strictly on one side of the other's plane (by an angle far above rounding, so
        // meetBeyondSharedVertex's nearly-coplanar case cannot apply)
        if (shared == 1 &&
          (oneSide(nt.Pts[ka], nt.N, c.Pts[(kb + 1) % 3], c.Pts[(kb + 2) % 3]) ||
            oneSide(c.Pts[kb], (c.Pts[1] - c.Pts[0]).cross(c.Pts[2] - c.Pts[0]), nt.Pts[(ka + 1) % 3], nt.Pts[(ka + 2) % 3])))
          continue;
        // disjoint triangles whose bounding spheres are farther apart than selfDelta cannot conflict
        if (disjoint && (c.C - nt.C).norm() - c.R - nt.R >= selfDelta)
          continue;
        // nor those a separating axis keeps selfDelta apart: the centroids' line, the normals,
        // and (for the nearly coplanar neighbours of a flat region) the in-plane edge normals
        if (disjoint && separatedByAxes(nt, c, selfDelta))
          continue;
        if (trianglesConflict(nt.Ids, nt.Pts, c.Ids, c.Pts, selfDelta, FoldCosine))
          return Verdict::Self;
      }
    }
    return Verdict::Ok;
  }

  // Would the collapse sweep an input component out of the cage? The old one-ring (the changed
  // and removed triangles) and the new one (the changed triangles with v1 -> v0 at p) share
  // their boundary, so together (the new one reversed) they close the region the collapse sweeps
  // over; the cage's winding number changes by exactly that region's winding number there. The
  // clearance keeps every input component away from both rings, so a component is wholly in
  // the region or wholly out of it, and one probe point per component decides. Without this, a
  // component smaller than the cage's triangles (a fragment of a soup) can be jumped over
  // without any new triangle coming near it.
  bool sweepsProbe(const Vec3& p, const Eval& ev) const
  {
    if (Probes.empty())
      return false;
    Vec3 lo = p, hi = p;
    auto grow = [&](int f) {
      for (int v : T[f])
      {
        lo = lo.cwiseMin(P[v]);
        hi = hi.cwiseMax(P[v]);
      }
    };
    for (int f : ev.Changed)
      grow(f);
    for (int f : ev.Removed)
      grow(f);
    auto first = std::lower_bound(Probes.begin(), Probes.end(), lo.x(), [](const Vec3& a, double x) { return a.x() < x; });
    for (auto it = first; it != Probes.end() && it->x() <= hi.x(); ++it)
    {
      const Vec3& x = *it;
      if (x.y() < lo.y() || x.y() > hi.y() || x.z() < lo.z() || x.z() > hi.z())
        continue;
      double angle = 0.0;
      for (int f : ev.Changed)
      {
        const Triangle& t = T[f];
        angle += solidAngle(P[t[0]], P[t[1]], P[t[2]], x);
        int ids[3];
        Vec3 pts[3];
        newTriangle(ev, f, p, ids, pts);
        angle -= solidAngle(pts[0], pts[1], pts[2], x);
      }
      for (int f : ev.Removed)
      {
        const Triangle& t = T[f];
        angle += solidAngle(P[t[0]], P[t[1]], P[t[2]], x);
      }
      if (std::abs(angle) > 2.0 * M_PI) // |winding number| > 1/2
        return true;
    }
    return false;
  }

  // Do the projections of a and b on axis u leave a gap of at least `gap` (either order)? The
  // distance of two convex sets is at least the gap of their projections on any axis.
  static bool separated(const Vec3 a[3], const Vec3 b[3], const Vec3& u, double gap)
  {
    const double n = u.norm();
    if (!(n > 0))
      return false;
    const double a0 = u.dot(a[0]), a1 = u.dot(a[1]), a2 = u.dot(a[2]);
    const double b0 = u.dot(b[0]), b1 = u.dot(b[1]), b2 = u.dot(b[2]);
    const double g = gap * n * (1 + 1e-9);
    return std::min({ b0, b1, b2 }) - std::max({ a0, a1, a2 }) >= g ||
      std::min({ a0, a1, a2 }) - std::max({ b0, b1, b2 }) >= g;
  }
  // Do d and e lie strictly on one side of the plane through a with normal n, each at an angle
  // of at least 1e-6 radians from it as seen from a?
  static bool oneSide(const Vec3& a, const Vec3& n, const Vec3& d, const Vec3& e)
  {
    const Vec3 ad = d - a, ae = e - a;
    const double sd = n.dot(ad), se = n.dot(ae);
    const double nn = n.norm();
    const double td = 1e-6 * nn * ad.norm(), te = 1e-6 * nn * ae.norm();
    return (sd > td && se > te) || (sd < -td && se < -te);
  }
  template <typename A, typename B>
  static bool separatedByAxes(const A& a, const B& b, double gap)
  {
    if (separated(a.Pts, b.Pts, b.C - a.C, gap) || separated(a.Pts, b.Pts, a.N, gap))
      return true;
    const Vec3 nb = (b.Pts[1] - b.Pts[0]).cross(b.Pts[2] - b.Pts[0]);
    if (separated(a.Pts, b.Pts, nb, gap))
      return true;
    for (int k = 0; k < 3; ++k)
      if (separated(a.Pts, b.Pts, a.N.cross(a.Pts[(k + 1) % 3] - a.Pts[k]), gap) ||
        separated(a.Pts, b.Pts, nb.cross(b.Pts[(k + 1) % 3] - b.Pts[k]), gap))
        return true;
    return false;
  }

  // Gradient descent on Psi (eq. 5-6): move the placement so that the new one-ring moves away from
  // the input where it is closer than the target (2 delta), sampling each new triangle where p
  // weighs: at p, at the midpoints of its edges at p and at its centroid (weight = p's share).
  bool relocate(Vec3& p, Eval& ev) const
  {
    auto& sampleCache = ev.S->SampleCache;
    const double target = 2.0 * Opt.Clearance;
    for (int it = 0;; ++it)
    {
      Vec3 g = Vec3::Zero();
      double worst = target;
      double nearest = target; // unsigned: a sample nearer than delta dooms check()
      // the corner p and the midpoints of the edges at p are shared by neighbouring triangles:
      // each is measured once per step (key: -1 for p, the other end's id for a midpoint)
      sampleCache.clear();
      for (int f : ev.Changed)
      {
        int ids[3];
        Vec3 pts[3];
        newTriangle(ev, f, p, ids, pts);
        const double area = 0.5 * (pts[1] - pts[0]).cross(pts[2] - pts[0]).norm();
        int kp = 0;
        while (ids[kp] != ev.C0)
          ++kp;
        for (int s = 0; s < 4; ++s)
        {
          // s = 0: p (weight 1); 1, 2: midpoints towards the other corners (1/2); 3: centroid (1/3)
          const int other = s == 1 ? ids[(kp + 1) % 3] : s == 2 ? ids[(kp + 2) % 3] : -1;
          const double lp = s == 0 ? 1.0 : s == 3 ? 1.0 / 3.0 : 0.5;
          const int key = s == 0 ? -1 : other;
          Sample smp;
          bool cached = false;
          if (s < 3)
            for (const auto& kv : sampleCache)
              if (kv.first == key)
              {
                smp = kv.second;
                cached = true;
                break;
              }
          if (!cached)
          {
            const Vec3 x = s == 0 ? p
              : s == 3 ? Vec3((pts[0] + pts[1] + pts[2]) / 3.0)
                       : Vec3(0.5 * (p + pts[s == 1 ? (kp + 1) % 3 : (kp + 2) % 3]));
            Vec3 c;
            int tri;
            double d;
            smp.Near = Input.closestPoint(x, target, c, tri, d);
            if (smp.Near)
            {
              smp.D = d;
              smp.Dir = d > 0 ? Vec3((x - c) / d) : Input.normal(tri);
              smp.Xi = d;
              if (smp.Dir.dot(Input.normal(tri)) < 0) // inside the input: the gradient points outward
              {
                smp.Dir = -smp.Dir;
                smp.Xi = -d;
              }
            }
            if (s < 3)
              sampleCache.emplace_back(key, smp);
          }
          if (!smp.Near)
            continue; // comfortably clear
          nearest = std::min(nearest, smp.D);
          worst = std::min(worst, smp.Xi);
          g += area * lp * (target - smp.Xi) * smp.Dir;
        }
      }
      // the placement reached by the previous step: checked unless a sample already fails it
      if (it > 0 && nearest >= Opt.Clearance && check(p, ev) == Verdict::Ok)
        return true;
      if (it == Opt.PlacementIterations)
        return false;
      const double gn = g.norm();
      if (!(gn > 0))
        return false;
      p += (g / gn) * (target - worst);
    }
  }

  static void countReject(Verdict v, Eval& ev)
  {
    if (v == Verdict::Input)
      ++ev.RejInput;
    else if (v == Verdict::Self)
      ++ev.RejSelf;
    else if (v == Verdict::Shape)
      ++ev.RejShape;
  }

  void box(int f, Vec3& lo, Vec3& hi) const
  {
    lo = P[T[f][0]].cwiseMin(P[T[f][1]]).cwiseMin(P[T[f][2]]);
    hi = P[T[f][0]].cwiseMax(P[T[f][1]]).cwiseMax(P[T[f][2]]);
  }

  void collapse(const Eval& ev)
  {
    const int c0 = ev.C0, c1 = ev.C1;
    const Vec3& p = ev.Pos;
    Vec3 lo, hi;
    for (int f : ev.Removed)
    {
      box(f, lo, hi);
      Grid.remove(f, lo, hi);
      TAlive[f] = 0;
      --AliveTriangles;
      for (int v : T[f])
      {
        auto& l = VT[v];
        l.erase(std::remove(l.begin(), l.end(), f), l.end());
      }
    }
    for (int f : ev.Changed)
    {
      box(f, lo, hi);
      Grid.remove(f, lo, hi);
    }
    for (int f : VT[c1])
    {
      for (int& v : T[f])
        if (v == c1)
          v = c0;
      VT[c0].push_back(f);
    }
    VT[c1].clear();
    P[c0] = p;
    Q[c0] += Q[c1];
    VAlive[c1] = 0;
    --AliveVertices;
    ++Ver[c0];
    ++Ver[c1];
    for (int f : ev.Changed)
    {
      box(f, lo, hi);
      Grid.insert(f, lo, hi);
    }
    D[c0] = ev.LastCheckExact && ev.LastCheckPos == p ? ev.LastCheckDistance : -1.0;
    neighbours(c0, Ring);
    const std::vector<int>& ring = Ring;
    for (int v : { c0, c1 })
    {
      for (int n : BlockedAt[v])
        Blocked.erase(edgeKey(v, n));
      BlockedAt[v].clear();
    }
    for (int n : ring)
      pushEdge(std::min(c0, n), std::max(c0, n));
    // edges around the ring saw their neighbourhood change: retry the blocked ones (stale
    // partners, already collapsed or re-queued, are filtered when popped)
    for (int r : ring)
    {
      for (int n : BlockedAt[r])
        if (Blocked.erase(edgeKey(r, n)) && n != c0 && VAlive[n])
          pushEdge(std::min(r, n), std::max(r, n));
      BlockedAt[r].clear();
    }
  }

  void rebuildGrid()
  {
    double area = 0;
    for (std::size_t f = 0; f < T.size(); ++f)
      if (TAlive[f])
        area += 0.5 * (P[T[f][1]] - P[T[f][0]]).cross(P[T[f][2]] - P[T[f][0]]).norm();
    const double meanEdge = std::sqrt(4.0 * area / std::max(1, AliveTriangles) / std::sqrt(3.0));
    Grid.reset(std::max(2.0 * meanEdge, 1e-6));
    Vec3 lo, hi;
    for (std::size_t f = 0; f < T.size(); ++f)
      if (TAlive[f])
      {
        box(static_cast<int>(f), lo, hi);
        Grid.insert(static_cast<int>(f), lo, hi);
      }
    GridTriangles = AliveTriangles;
  }

  TriangleMesh compact() const
  {
    TriangleMesh m;
    std::vector<int> map(P.size(), -1);
    for (std::size_t v = 0; v < P.size(); ++v)
      if (VAlive[v] && !VT[v].empty())
      {
        map[v] = static_cast<int>(m.Points.size());
        m.Points.push_back(P[v]);
      }
    for (std::size_t f = 0; f < T.size(); ++f)
      if (TAlive[f])
        m.Triangles.push_back({ map[T[f][0]], map[T[f][1]], map[T[f][2]] });
    return m;
  }

  const TriangleTree& Input;
  std::vector<Vec3> Probes; ///< one input point per component, sorted by x (see sweepsProbe)
  SimplifyOptions Opt;
  const SimplifyOptions Original;
  Progress* Prog;
  tbb::enumerable_thread_specific<Scratch> Scratches;
  std::vector<Vec3> P;
  std::vector<Triangle> T;
  std::vector<char> VAlive, TAlive;
  std::vector<std::vector<int>> VT;
  std::vector<Quadric> Q;
  std::vector<double> D; // distance (or lower bound) to the input per vertex, < 0 = not known
  std::vector<unsigned> Ver;
  std::vector<unsigned> VStamp; // == BatchStamp: written by a collapse of the current batch
  unsigned BatchStamp = 0;
  int BatchesSinceProgress = 0;
  std::vector<int> Ring; // scratch of collapse()
  int AliveVertices = 0, AliveTriangles = 0, GridTriangles = 0;
  CageGrid Grid;
  std::priority_queue<Entry> Heap;
  std::vector<std::vector<int>> BlockedAt;
  std::unordered_set<std::uint64_t> Blocked;
  SimplifyResult Stats;
  int Pass = 0;
  int Retries = 0;
  double PlacementReach = std::numeric_limits<double>::infinity();
  static constexpr int MaxRetries = 16;
};

} // namespace

SimplifyResult simplifyEnvelope(const TriangleMesh& envelope, const TriangleTree& inputTree,
  const SimplifyOptions& options, Progress* progress, const std::vector<Vec3>* inputProbes)
{
  if (envelope.Triangles.empty())
  {
    SimplifyResult r;
    r.StopReason = "empty envelope";
    return r;
  }
  Simplifier s(envelope, inputTree, options, progress, inputProbes);
  return s.run();
}

} // namespace sdfcage
