#include "Simplification/Simplification.h"

#include "Common/Progress.h"
#include "Mesh/EdgeKey.h"
#include "Quality/LocalChangeVeto.h"
#include "Spatial/CageGrid.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleTree.h"

#include <algorithm>
#include <iterator>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <unordered_set>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

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
    return A[0] * x * x + 2 * A[1] * x * y + 2 * A[2] * x * z + 2 * A[3] * x + A[4] * y * y + 2 * A[5] * y * z +
      2 * A[6] * y + A[7] * z * z + 2 * A[8] * z + A[9];
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

// Candidate collapses evaluated together. The batch is formed, evaluated and applied the same way
// whatever the number of threads, so the cage does not depend on it.
constexpr int BatchSize = 32;

struct Sample
{
  bool Near = false; // the input lies within the descent's target distance
  double D = 0, Xi = 0;
  Vec3 Dir = Vec3::Zero();
};

// Per-thread scratch of the evaluation.
struct Scratch
{
  std::vector<int> N0, N1;
  LocalChangeScratch Veto; // the new triangles of the collapse, the triangles it replaces
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
    , Veto(policy(o), input, CageView{ &P, &T, &TAlive, nullptr, nullptr, &Grid, &Part })
  {
    P = mesh.Points;
    T = mesh.Triangles;
    if (o.PartClearance > o.selfClearance())
    {
      // room between parts: as asked, but no more than the envelope's parts have (measured part
      // against the later parts, a tree each: up to 16 parts)
      std::vector<int> component;
      const int parts = triangleComponents(mesh, component);
      if (parts > 1 && parts <= 16)
      {
        const double room =
          std::min(o.PartClearance, 0.95 * distanceBetweenParts(mesh, o.PartClearance / 0.95, component, parts));
        if (room > o.selfClearance())
        {
          Part.assign(P.size(), 0);
          for (std::size_t f = 0; f < T.size(); ++f)
            for (int v : T[f])
              Part[v] = component[f];
          LocalChangePolicy p = Veto.policy();
          p.PartClearance = room;
          Veto.setPolicy(p);
          PartRoom = room;
        }
      }
    }
    VAlive.assign(P.size(), 1);
    TAlive.assign(T.size(), 1);
    VT.assign(P.size(), {});
    for (std::size_t f = 0; f < T.size(); ++f)
      for (int v : T[f])
        VT[v].push_back(static_cast<int>(f));
    Ver.assign(P.size(), 0);
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
    {
      if (v % 4096 == 0 && progressCancelled(Prog))
      {
        r.Cancelled = true; // drain() stops at once
        break;
      }
      for (int n : neighbours(static_cast<int>(v)))
        if (static_cast<int>(v) < n)
          pushEdge(static_cast<int>(v), n);
    }
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
      const int excess = AliveVertices - target;
      drain(target, start, r);
      if (Pass == 0 && Opt.GiveUpAbove > 0 && AliveVertices > Opt.GiveUpAbove && !r.Cancelled)
      {
        GaveUp = true; // the caller has a better option than the thorough passes
        break;
      }

      // progress: try this pass again on what is now blocked (a bounded number of times: each
      // retry runs the thorough search on every blocked edge). Only while a pass removes a fair
      // share of what is left (1/16 of the vertices above the target): a pass that frees a few
      // collapses on a stalled cage thousands above the target costs a thorough search of every
      // blocked edge each time (minutes on a fused cluster) for nothing.
      const long long made = Stats.Collapses - before;
      if (Pass > 0 && made > 0 && made * 16 >= excess && AliveVertices > target && ++Retries <= MaxRetries)
        --Pass;
    }
    const bool cancelled = r.Cancelled;
    r = Stats;
    r.Cancelled = cancelled || progressCancelled(Prog);
    r.GaveUp = GaveUp;
    r.VerticesReached = AliveVertices;
    r.TargetReached = AliveVertices <= target;
    r.PartClearanceUsed = PartRoom;
    if (!r.TargetReached)
      r.StopReason = r.Cancelled ? "cancelled"
        : GaveUp ? "the ordinary pass ended above " + std::to_string(Opt.GiveUpAbove) +
            " vertices: the thorough passes were skipped (a wider envelope follows)"
                 : "no remaining collapse keeps the clearance, self-intersection, "
                   "topology, shape and placement-distance constraints";
    r.Cage = compact();
    r.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  }

  // An entry with the box of its neighbourhood (the triangles around both ends, the placement,
  // the margin), as of the batch Stamp: valid while no later batch wrote either end (a collapse
  // that changes a triangle around V0 or V1, or moves one of their neighbours, has them in its
  // Verts and stamps them; VStamp only grows).
  struct Candidate
  {
    Entry E;
    Vec3 Lo = Vec3::Zero(), Hi = Vec3::Zero();
    unsigned Stamp = 0;
    bool Stale = false; // found stale (for good) when popped ahead
  };

  bool staleEntry(const Entry& e) const
  {
    return !VAlive[e.V0] || !VAlive[e.V1] || Ver[e.V0] != e.Ver0 || Ver[e.V1] != e.Ver1;
  }

  void boxOf(Candidate& c, double margin) const
  {
    const Entry& e = c.E;
    Vec3 lo = e.Pos, hi = e.Pos;
    for (int v : { e.V0, e.V1 })
      for (int f : VT[v])
        for (int w : T[f])
        {
          lo = lo.cwiseMin(P[w]);
          hi = hi.cwiseMax(P[w]);
        }
    c.Lo = lo - Vec3::Constant(margin);
    c.Hi = hi + Vec3::Constant(margin);
    c.Stamp = BatchStamp;
  }

  // Pops and collapses edges until the target or an empty queue, a batch at a time: the cheapest
  // valid entries whose neighbourhoods lie apart are evaluated side by side (in parallel), then
  // applied in queue order. An evaluation whose neighbourhood an earlier collapse of the batch
  // touched (shared vertices or overlapping boxes) is not applied but queued again, so every
  // applied decision is the one the sequential algorithm would take on the current cage.
  //
  // While a batch is evaluated, the queue's front is popped ahead into `ahead` with the boxes of
  // its valid entries (its stale ones marked: an entry once stale stays so). The next batch is
  // formed after the application exactly as from the queue itself: from the first of `held`,
  // `ahead` and the queue (which the application pushed to), a box taken again only where the
  // application stamped an end. The batches, hence the cages, are the ones the forming from the
  // queue alone gives (byte for byte on the 21 data meshes); the pops and most boxes are taken
  // beside the evaluation instead of between the batches. Session 57, best of 3 of
  // `sdfcage_simplify_benchmark --repeat 3`, three rounds: armadillo 0.79-0.89 -> 0.67-0.73 s,
  // octopus-low 0.38 -> 0.30-0.33 s, anchor the same (0.28-0.31 s).
  void drain(int target, int start, SimplifyResult& r)
  {
    std::vector<Eval> batch(BatchSize);
    // held: the entries the last forming skipped (next to a member), in queue order; merged: the
    // next `held`, a buffer kept across batches
    std::vector<Candidate> aside, held, merged, ahead;
    std::size_t aheadAt = 0;    // ahead[aheadAt..]: the queue's front, in queue order
    std::size_t aheadValid = 0; // ... of which not stale
    std::vector<std::pair<Vec3, Vec3>> formBoxes, writeBoxes;
    const double margin = std::max(Opt.selfClearance(), PartRoom);
    // (enough for most formings: a batch takes BatchSize members and skips up to 2 x BatchSize)
    const std::size_t aheadWanted = 4 * BatchSize;
    auto popAhead = [&]() {
      if (aheadAt > 0 && aheadAt * 2 >= ahead.size())
      {
        ahead.erase(ahead.begin(), ahead.begin() + static_cast<std::ptrdiff_t>(aheadAt));
        aheadAt = 0;
      }
      const std::size_t had = ahead.size();
      while (aheadValid < aheadWanted && !Heap.empty())
      {
        // (a stale entry stays in `ahead`, marked: the queue's cheapest, which a relocated
        // collapse is compared with, is taken over stale entries as from the heap)
        Candidate c;
        c.E = Heap.top();
        Heap.pop();
        c.Stale = staleEntry(c.E);
        if (!c.Stale)
        {
          boxOf(c, margin);
          ++aheadValid;
        }
        ahead.push_back(c);
      }
      // the application pushed entries that may rank before what was popped ahead earlier
      std::inplace_merge(ahead.begin() + static_cast<std::ptrdiff_t>(aheadAt),
        ahead.begin() + static_cast<std::ptrdiff_t>(had), ahead.end(),
        [](const Candidate& x, const Candidate& y) { return y.E < x.E; });
    };
    // the queue's front entry (the first of `ahead` and the heap's top) outranks `e`
    auto queueOutranks = [&](const Entry& e) {
      return (aheadAt < ahead.size() && e < ahead[aheadAt].E) || (!Heap.empty() && e < Heap.top());
    };
    auto queueEmpty = [&]() { return aheadAt == ahead.size() && Heap.empty(); };
    while (AliveVertices > target && (!queueEmpty() || !held.empty()))
    {
      // progress every 16 batches; a cancel check every batch (a batch is some 10 ms, 16 of them
      // made a cancel wait up to 0.3 s on a loaded machine)
      if (++BatchesSinceProgress >= 16)
      {
        BatchesSinceProgress = 0;
        if (Prog && Prog->update(double(start - AliveVertices) / std::max(1, start - target)))
        {
          r.Cancelled = true;
          break;
        }
      }
      else if (progressCancelled(Prog))
      {
        r.Cancelled = true;
        break;
      }
      // form: valid entries in queue order, skipping (for the next batch) those next to a member.
      // The entries skipped by the previous batch (`held`, in queue order) are merged with the
      // queue rather than pushed back into it: the same order, without a push and a pop per
      // skipped entry (where the cheapest edges lie together, e.g. the equal-cost edges of a
      // uniform envelope's flat faces, most batches skip 2 x BatchSize of them)
      int n = 0;
      aside.clear();
      formBoxes.clear();
      std::size_t nextHeld = 0;
      while (n < BatchSize && (nextHeld < held.size() || !queueEmpty()) && aside.size() < 2 * BatchSize)
      {
        Candidate c;
        bool known = true; // c's box was taken (as of c.Stamp)
        if (nextHeld < held.size() && !queueOutranks(held[nextHeld].E))
          c = held[nextHeld++];
        else if (aheadAt < ahead.size() && (Heap.empty() || !(ahead[aheadAt].E < Heap.top())))
        {
          c = ahead[aheadAt++];
          if (c.Stale)
            continue;
          --aheadValid;
        }
        else
        {
          c.E = Heap.top();
          Heap.pop();
          known = false;
        }
        if (!known || VStamp[c.E.V0] > c.Stamp || VStamp[c.E.V1] > c.Stamp)
        {
          if (staleEntry(c.E))
            continue;
          boxOf(c, margin);
        }
        const Vec3& lo = c.Lo;
        const Vec3& hi = c.Hi;
        bool near = false;
        for (const auto& b : formBoxes)
          near = near || !((b.first.array() > hi.array()).any() || (b.second.array() < lo.array()).any());
        if (near)
        {
          aside.push_back(c);
          continue;
        }
        formBoxes.emplace_back(lo, hi);
        batch[n++].E = c.E;
      }
      // what this batch skipped comes first next time, then what the previous one skipped and
      // this one did not reach (both in queue order, and none after the other: merged)
      merged.clear();
      std::merge(aside.begin(), aside.end(), held.begin() + static_cast<std::ptrdiff_t>(nextHeld), held.end(),
        std::back_inserter(merged), [](const Candidate& a, const Candidate& b) { return b.E < a.E; });
      held.swap(merged);
      if (n == 0)
        continue;

      // evaluate (reads the cage), and pop the queue's front ahead meanwhile (reads the queue
      // and the cage)
      auto evaluateAll = [&]() {
        if (n > 1)
          tbb::parallel_for(0, n, [&](int i) { evaluate(batch[i], Scratches.local()); });
        else
          evaluate(batch[0], Scratches.local());
      };
      if (!Heap.empty() && aheadValid < aheadWanted)
        tbb::parallel_invoke(evaluateAll, popAhead);
      else
        evaluateAll();

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
          // (the queue's cheapest: its front or the first entry held back)
          double cheapest = std::numeric_limits<double>::infinity();
          if (!Heap.empty())
            cheapest = Heap.top().Cost;
          if (aheadAt < ahead.size())
            cheapest = std::min(cheapest, ahead[aheadAt].E.Cost);
          if (!held.empty())
            cheapest = std::min(cheapest, held.front().E.Cost);
          if (ev.Cost > cheapest)
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
    // (a later pass or drain finds them in the queue, as before)
    for (std::size_t i = aheadAt; i < ahead.size(); ++i)
      if (!ahead[i].Stale)
        Heap.push(ahead[i].E);
    for (const Candidate& c : held)
      Heap.push(c.E);
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
    ev.RejInput = ev.RejSelf = ev.RejShape = 0;
    ev.Gathered = gather(ev);
    if (!ev.Gathered)
      return;
    Vec3 pos = ev.E.Pos;
    const LocalChangeVerdict v = check(pos, ev);
    if (v != LocalChangeVerdict::Accepted)
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
    LocalChangePolicy p = policy(Opt);
    p.PartClearance = PartRoom;
    Veto.setPolicy(p);
  }

  // The placement `pos` of the gathered collapse failed with verdict `first`. Looks for a
  // feasible one: the midpoint and the endpoints; the Psi descent from the placement (and, in the
  // thorough passes, from the other starts); in the thorough passes, an outward walk along the
  // one-ring's normal. Returns the cheapest found first in that order.
  bool place(Vec3& pos, LocalChangeVerdict first, Eval& ev) const
  {
    // the ordinary pass keeps to the Psi descent from the placement when the input is too
    // close: trying alternatives on every rejection of a dense envelope costs more than it gains
    if (Pass == 0)
    {
      if (first != LocalChangeVerdict::InputClearance)
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
      if (check(starts[i], ev) == LocalChangeVerdict::Accepted && withinReach(starts[i]))
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
        if (check(p, ev) == LocalChangeVerdict::Accepted && withinReach(p))
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
    s.Veto.Replaced.begin(T.size());
    for (int f : ev.Removed)
      s.Veto.Replaced.insert(f);
    for (int f : ev.Changed)
      s.Veto.Replaced.insert(f);
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

  // The veto (Quality/LocalChangeVeto.h) on the collapse gathered in ev with v0 placed at p:
  // shape, fold, input clearance (bounded by the cached vertex distances), self-intersection.
  LocalChangeVerdict check(const Vec3& p, Eval& ev) const
  {
    LocalChangeScratch& s = ev.S->Veto;
    s.Tris.resize(ev.Changed.size());
    for (std::size_t i = 0; i < ev.Changed.size(); ++i)
    {
      ChangedTriangle& nt = s.Tris[i];
      newTriangle(ev, ev.Changed[i], p, nt.Ids, nt.Pts);
      const Triangle& old = T[ev.Changed[i]];
      nt.Reference = (P[old[1]] - P[old[0]]).cross(P[old[2]] - P[old[0]]);
    }
    LocalChangeFindings found;
    const LocalChangeVerdict v = Veto.check(s, &found);
    if (found.Read)
    {
      if (ev.HasRead)
      {
        ev.ReadLo = ev.ReadLo.cwiseMin(found.ReadLo);
        ev.ReadHi = ev.ReadHi.cwiseMax(found.ReadHi);
      }
      else
      {
        ev.ReadLo = found.ReadLo;
        ev.ReadHi = found.ReadHi;
        ev.HasRead = true;
      }
    }
    // and no input component swept out of the cage (see sweepsProbe)
    if (v == LocalChangeVerdict::Accepted && Opt.EnforceClearance && sweepsProbe(p, ev))
      return LocalChangeVerdict::InputClearance;
    return v;
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
    auto first =
      std::lower_bound(Probes.begin(), Probes.end(), lo.x(), [](const Vec3& a, double x) { return a.x() < x; });
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

  static LocalChangePolicy policy(const SimplifyOptions& o)
  {
    LocalChangePolicy p;
    p.MinimumTriangleQuality = o.MinimumTriangleQuality;
    p.MinimumNormalCosine = o.MinimumNormalCosine;
    p.Clearance = o.Clearance;
    // Every new triangle goes to the input's tree (one walk for all). A 1-Lipschitz bound from
    // cached vertex distances used to clear some first, but it cleared only about 4% of them
    // (the new triangles are larger than the room between the envelope and the clearance) and
    // cost a distance query per check: without it the cages are the same byte for byte and
    // `sdfcage_simplify_benchmark` runs faster (session 57, best of 3, three alternating rounds:
    // armadillo 0.69-0.78 -> 0.54-0.64 s, octopus-low 0.29-0.34 -> 0.26-0.32 s, anchor
    // 0.26-0.30 -> 0.25-0.27 s; best of 1, two rounds: dragon_vrip 2.03-2.34 -> 2.01-2.08 s,
    // armadillo_midsub4x 0.76-0.83 -> 0.62-0.72 s).
    p.Input = o.EnforceClearance ? LocalChangePolicy::InputTest::Exact : LocalChangePolicy::InputTest::None;
    p.CheckSelfIntersection = o.EnforceNoSelfIntersection;
    p.SelfClearance = o.selfClearance();
    return p;
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
              : s == 3            ? Vec3((pts[0] + pts[1] + pts[2]) / 3.0)
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
      // the placement reached by the previous step: checked unless a sample already fails it. A
      // verdict other than the input's clearance ends the descent: it moves p away from the input
      // only, and a needle, fold or crossing it meets stays (dragon_vrip at 500 vertices: of 1,578
      // descents whose first check found one, 3 ended accepted)
      if (it > 0 && nearest >= Opt.Clearance)
      {
        const LocalChangeVerdict v = check(p, ev);
        if (v == LocalChangeVerdict::Accepted)
          return true;
        if (v != LocalChangeVerdict::InputClearance)
          return false;
      }
      if (it == Opt.PlacementIterations)
        return false;
      const double gn = g.norm();
      if (!(gn > 0))
        return false;
      p += (g / gn) * (target - worst);
    }
  }

  static void countReject(LocalChangeVerdict v, Eval& ev)
  {
    if (v == LocalChangeVerdict::InputClearance)
      ++ev.RejInput;
    else if (v == LocalChangeVerdict::Fold || v == LocalChangeVerdict::SelfIntersection)
      ++ev.RejSelf;
    else if (v == LocalChangeVerdict::Shape)
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
  bool GaveUp = false; ///< stopped after pass 0 (SimplifyOptions::GiveUpAbove)
  double PlacementReach = std::numeric_limits<double>::infinity();
  static constexpr int MaxRetries = 16;
  std::vector<int> Part; // per vertex: its part, when room is kept between parts (else empty)
  double PartRoom = 0.0; // SimplifyOptions::PartClearance as used (0: off)
  LocalChangeVeto Veto;  // reads P, T, TAlive, Grid and Part
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
