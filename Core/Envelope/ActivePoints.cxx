#include "Envelope/ActivePoints.h"
#include "Mesh/EdgeKey.h"

#include "Common/Progress.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

namespace sdfcage
{

namespace
{

/// Points bucketed in a hashed uniform grid (sorted by cell, open-addressing table of the
/// occupied cells), for fixed-radius queries. Memory is linear in the number of points whatever
/// the extent or the cell size.
class PointGrid
{
public:
  PointGrid(const std::vector<Vec3>& points, const std::vector<int>& ids, double cell)
    : Points(points)
    , Cell(std::max(cell, 1e-12))
  {
    std::vector<std::pair<std::uint64_t, int>> keyed(ids.size());
    for (std::size_t k = 0; k < ids.size(); ++k)
    {
      keyed[k] = { this->key(this->cellCoords(points[ids[k]])), ids[k] };
    }
    std::sort(keyed.begin(), keyed.end());
    this->Items.resize(ids.size());
    std::size_t cells = 0;
    for (std::size_t k = 0; k < keyed.size(); ++k)
    {
      this->Items[k] = keyed[k].second;
      cells += (k == 0 || keyed[k].first != keyed[k - 1].first);
    }
    std::size_t size = 16;
    while (size < 2 * cells)
    {
      size *= 2;
    }
    this->Mask = size - 1;
    this->Table.assign(size, Slot{});
    for (std::size_t k = 0; k < keyed.size();)
    {
      std::size_t e = k;
      while (e < keyed.size() && keyed[e].first == keyed[k].first)
      {
        ++e;
      }
      std::size_t h = this->hash(keyed[k].first) & this->Mask;
      while (this->Table[h].End != 0)
      {
        h = (h + 1) & this->Mask;
      }
      this->Table[h] = { keyed[k].first, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(e) };
      k = e;
    }
  }

  /// Calls f(id) for every point strictly closer than `radius` to p.
  template <typename F>
  void forEachWithin(const Vec3& p, double radius, F&& f) const
  {
    const double r2 = radius * radius;
    const int reach = static_cast<int>(std::ceil(radius / this->Cell));
    const std::array<std::int64_t, 3> c = this->cellCoords(p);
    for (std::int64_t k = c[2] - reach; k <= c[2] + reach; ++k)
      for (std::int64_t j = c[1] - reach; j <= c[1] + reach; ++j)
        for (std::int64_t i = c[0] - reach; i <= c[0] + reach; ++i)
        {
          const std::uint64_t cellKey = this->key({ i, j, k });
          std::size_t h = this->hash(cellKey) & this->Mask;
          while (this->Table[h].End != 0 && this->Table[h].Key != cellKey)
          {
            h = (h + 1) & this->Mask;
          }
          const Slot& slot = this->Table[h];
          for (std::uint32_t n = slot.Begin; n < slot.End; ++n)
          {
            const int id = this->Items[n];
            if ((this->Points[id] - p).squaredNorm() < r2)
            {
              f(id);
            }
          }
        }
  }

private:
  struct Slot
  {
    std::uint64_t Key = 0;
    std::uint32_t Begin = 0;
    std::uint32_t End = 0; // 0: empty slot (occupied slots hold at least one point)
  };
  std::array<std::int64_t, 3> cellCoords(const Vec3& p) const
  {
    return { static_cast<std::int64_t>(std::floor(p.x() / Cell)), static_cast<std::int64_t>(std::floor(p.y() / Cell)),
      static_cast<std::int64_t>(std::floor(p.z() / Cell)) };
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c)
  {
    // 21 bits per axis (two's complement, wrapped): collisions only between cells 2^21 apart,
    // which share a slot's key and are then filtered by the distance test
    const std::uint64_t m = (1u << 21) - 1;
    return (static_cast<std::uint64_t>(c[0]) & m) | ((static_cast<std::uint64_t>(c[1]) & m) << 21) |
      ((static_cast<std::uint64_t>(c[2]) & m) << 42);
  }
  static std::size_t hash(std::uint64_t k)
  {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return static_cast<std::size_t>(k);
  }

  const std::vector<Vec3>& Points;
  double Cell;
  std::uint64_t Mask = 0;
  std::vector<Slot> Table;
  std::vector<int> Items;
};

/// Undirected edge graph of a triangle mesh in CSR form, with edge lengths.
struct EdgeGraph
{
  std::vector<std::size_t> Start;
  std::vector<int> Neighbor;
  std::vector<double> Length;

  /// A cancel (`progress`) stops the construction: the graph is then incomplete, for the caller
  /// to drop.
  explicit EdgeGraph(const TriangleMesh& mesh, Progress* progress = nullptr)
  {
    // Per point, in parallel: its neighbours (the other corners of its triangles) sorted and
    // unique, which is the order a global sort of the edges gave (2.6M edges of dragon_vrip:
    // 0.2 s serial before).
    const std::size_t n = mesh.Points.size();
    const PointTriangles incident(mesh);
    // a triangle listing a point twice lists it once here too
    auto neighbours = [&](std::size_t v, std::vector<int>& out) {
      out.clear();
      for (std::size_t i = incident.First[v]; i < incident.First[v + 1]; ++i)
      {
        for (int u : mesh.Triangles[incident.Triangles[i]])
        {
          if (u != static_cast<int>(v))
          {
            out.push_back(u);
          }
        }
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    };
    std::atomic<bool> stopped{ false };
    const tbb::blocked_range<std::size_t> all(0, n, 4096);
    Start.assign(n + 1, 0);
    tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& r) {
      if (stopped || progressCancelled(progress))
      {
        stopped = true;
        return;
      }
      std::vector<int> out;
      for (std::size_t v = r.begin(); v != r.end(); ++v)
      {
        neighbours(v, out);
        Start[v + 1] = out.size();
      }
    });
    if (stopped)
    {
      Start.assign(n + 1, 0);
      return; // incomplete: the caller drops it
    }
    for (std::size_t i = 0; i < n; ++i)
    {
      Start[i + 1] += Start[i];
    }
    Neighbor.resize(Start[n]);
    Length.resize(Start[n]);
    tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<int> out;
      for (std::size_t v = r.begin(); v != r.end(); ++v)
      {
        neighbours(v, out);
        std::size_t at = Start[v];
        for (int u : out)
        {
          // measured from the lower id, as for the edge itself: both ends read the same length
          const int a = std::min(u, static_cast<int>(v)), b = std::max(u, static_cast<int>(v));
          Neighbor[at] = u;
          Length[at++] = (mesh.Points[a] - mesh.Points[b]).norm();
        }
      }
    });
  }
};

/// Shortest paths along the edges of an EdgeGraph from one or more sources, out to a radius
/// (Dijkstra with a bound). The per-point state is reset in O(1) by a stamp, so one object serves
/// any number of searches: keep one per thread.
class BoundedDijkstra
{
public:
  explicit BoundedDijkstra(const EdgeGraph& graph)
    : Graph(&graph)
    , Dist(graph.Start.size() - 1, 0.0)
    , Seen(graph.Start.size() - 1, 0)
    , Settled(graph.Start.size() - 1, 0)
  {
  }

  /// Starts a new search: forgets every point reached before and every source.
  void restart()
  {
    if (++this->Now == 0)
    {
      std::fill(this->Seen.begin(), this->Seen.end(), 0);
      std::fill(this->Settled.begin(), this->Settled.end(), 0);
      this->Now = 1;
    }
    this->Heap.clear();
  }

  /// Adds a source (distance 0) to the current search.
  void addSource(int p)
  {
    this->Dist[p] = 0.0;
    this->Seen[p] = this->Now;
    this->push(0.0, p);
  }

  /// Settles points in increasing distance from the sources, up to `radius` (inclusive):
  /// visit(u, d) is called on each settled point u at distance d and returns false to end the
  /// search there.
  template <typename Visit>
  void run(double radius, Visit&& visit)
  {
    const EdgeGraph& graph = *this->Graph;
    const std::uint32_t now = this->Now;
    while (!this->Heap.empty())
    {
      const auto [d, u] = this->pop();
      if (this->Settled[u] == now || d > this->Dist[u])
      {
        continue;
      }
      this->Settled[u] = now;
      if (!visit(u, d))
      {
        return;
      }
      for (std::size_t e = graph.Start[u]; e < graph.Start[u + 1]; ++e)
      {
        const int v = graph.Neighbor[e];
        const double nd = d + graph.Length[e];
        if (nd > radius || this->Settled[v] == now)
        {
          continue;
        }
        if (this->Seen[v] != now || nd < this->Dist[v])
        {
          this->Seen[v] = now;
          this->Dist[v] = nd;
          this->push(nd, v);
        }
      }
    }
  }

  /// A new search from one source.
  template <typename Visit>
  void run(int source, double radius, Visit&& visit)
  {
    this->restart();
    this->addSource(source);
    this->run(radius, std::forward<Visit>(visit));
  }

  /// Was v settled by the current search (its distance known, and within the radius)?
  bool settled(int v) const { return this->Settled[v] == this->Now; }

private:
  using Entry = std::pair<double, int>;
  void push(double d, int v)
  {
    this->Heap.emplace_back(d, v);
    std::push_heap(this->Heap.begin(), this->Heap.end(), std::greater<Entry>());
  }
  Entry pop()
  {
    std::pop_heap(this->Heap.begin(), this->Heap.end(), std::greater<Entry>());
    const Entry e = this->Heap.back();
    this->Heap.pop_back();
    return e;
  }

  const EdgeGraph* Graph;
  std::vector<double> Dist;
  std::vector<std::uint32_t> Seen;    // Dist valid when Seen == Now
  std::vector<std::uint32_t> Settled; // settled when == Now
  std::vector<Entry> Heap;
  std::uint32_t Now = 0;
};

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Points referenced by a triangle (unreferenced input points take no part).
std::vector<char> referencedPoints(const TriangleMesh& mesh)
{
  std::vector<char> referenced(mesh.Points.size(), 0);
  for (const Triangle& t : mesh.Triangles)
  {
    referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
  }
  return referenced;
}

/// Sampling: greedy, in point order (deterministic): a referenced point not yet within
/// `separation` of a sample *along the surface* becomes one. (A Euclidean cover would let one
/// part's samples stand for a nearly touching other part, which then has no samples of its own.)
/// Stops (with some of the samples) once `progress` is cancelled.
std::vector<int> sampleSurface(
  const EdgeGraph& graph, const std::vector<char>& referenced, double separation, Progress* progress)
{
  std::vector<int> samples;
  std::vector<char> covered(referenced.size(), 0);
  BoundedDijkstra cover(graph);
  for (std::size_t i = 0; i < referenced.size(); ++i)
  {
    if (i % 8192 == 0 && progressCancelled(progress))
    {
      break;
    }
    if (!referenced[i] || covered[i])
    {
      continue;
    }
    samples.push_back(static_cast<int>(i));
    cover.run(static_cast<int>(i), separation, [&](int u, double) {
      covered[u] = 1;
      return true;
    });
  }
  return samples;
}

/// Centres of the certificate balls: a greedy cover, every sample within `reach` of a centre, the
/// centres farther than `reach` apart (samples in point order; a sample not yet covered becomes a
/// centre). A centre per occupied grid cell of side reach / sqrt(3) covered the same but needed
/// 3.2 times as many (dragon_vrip: 8,668 centres, 1.1 s of its 1.6 s of active points). Which
/// samples the balls certify does not change the active set, only how cheaply it is found.
std::vector<int> ballCentres(const std::vector<Vec3>& points, const std::vector<int>& samples, double reach)
{
  std::vector<int> centres;
  if (!(reach > 0) || samples.empty())
  {
    return centres;
  }
  const PointGrid grid(points, samples, reach);
  std::vector<char> covered(points.size(), 0);
  for (int p : samples)
  {
    if (covered[p])
    {
      continue;
    }
    centres.push_back(p);
    grid.forEachWithin(points[p], reach, [&](int q) { covered[q] = 1; });
    covered[p] = 1;
  }
  return centres;
}

/// The active samples (paper §3.1): a sample p is active when some other sample q closer than r
/// to p (a candidate) is farther than l from p along the surface. Each sample not settled
/// otherwise goes through the steps: candidate search within r, geodesic test against l,
/// marking (p and every candidate farther than l). A cheaper pass first certifies most samples
/// inactive (certifyInactiveByBalls). Threaded; every thread keeps its own search.
class ActiveSampleDetection
{
public:
  ActiveSampleDetection(const TriangleMesh& surface, const EdgeGraph& graph, const std::vector<int>& samples, double r,
    double l, Progress* progress)
    : Points(surface.Points)
    , Samples(samples)
    , R(r)
    , L(l)
    , SampleGrid(surface.Points, samples, r)
    , Active(new std::atomic<std::uint8_t>[surface.Points.size()])
    , Certified(new std::atomic<std::uint8_t>[surface.Points.size()])
    , Scratches([g = &graph]() { return Scratch(*g); })
    , Report(progress)
  {
    for (std::size_t i = 0; i < surface.Points.size(); ++i)
    {
      this->Active[i].store(0, std::memory_order_relaxed);
      this->Certified[i].store(0, std::memory_order_relaxed);
    }
  }

  /// Finds the active samples; false when cancelled.
  bool run()
  {
    const double reach = std::max(0.0, 0.5 * this->L - this->R);
    const std::vector<int> centres = ballCentres(this->Points, this->Samples, reach);
    this->Work = centres.size() + this->Samples.size();
    this->certifyInactiveByBalls(centres, reach);
    this->testSamples();
    return !this->Cancelled.load();
  }

  bool isActive(int p) const { return this->Active[p].load(std::memory_order_relaxed) != 0; }

  /// The facing-gap rule (ActivePointOptions::GapRatio) on every sample the paper's rule left
  /// inactive: the candidates within r whose normals face p's across the gap, and a search from
  /// p ended when each is settled or beyond ratio |p - q| + slack. Returns the samples it made
  /// active; false in `ok` when cancelled.
  std::size_t findFacingGaps(
    const std::vector<Vec3>& normals, double ratio, double slack, bool& ok, std::vector<int>& madeActive)
  {
    std::vector<char> before(this->Samples.size());
    for (std::size_t k = 0; k < this->Samples.size(); ++k)
    {
      before[k] = this->isActive(this->Samples[k]);
    }
    tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, this->Samples.size(), 512), [&](const tbb::blocked_range<std::size_t>& range) {
        if (this->Cancelled.load(std::memory_order_relaxed))
        {
          return;
        }
        Scratch& s = this->Scratches.local();
        for (std::size_t k = range.begin(); k != range.end(); ++k)
        {
          const int p = this->Samples[k];
          if (before[k])
          {
            continue;
          }
          const Vec3& x = this->Points[p];
          const Vec3& np = normals[p];
          s.Candidates.clear();
          double reach = 0.0;
          this->SampleGrid.forEachWithin(x, this->R, [&](int q) {
            if (q == p)
            {
              return;
            }
            const Vec3 d = this->Points[q] - x;
            const double len = d.norm();
            if (len > 0 && d.dot(np) >= 0.5 * len && -d.dot(normals[q]) >= 0.5 * len)
            {
              s.Candidates.push_back(q);
              s.IsCandidate[q] = 1;
              reach = std::max(reach, ratio * len + slack);
            }
          });
          if (s.Candidates.empty())
          {
            continue;
          }
          // a candidate is close along the surface when settled within ratio |p - q| + slack
          std::size_t remaining = s.Candidates.size();
          s.Search.run(p, reach, [&](int u, double d) {
            if (s.IsCandidate[u])
            {
              s.IsCandidate[u] = 2;
              s.AlongOf.emplace_back(u, d);
              return --remaining != 0;
            }
            return true;
          });
          bool gap = false;
          for (int q : s.Candidates)
          {
            double along = -1.0;
            for (const auto& [u, d] : s.AlongOf)
            {
              if (u == q)
              {
                along = d;
                break;
              }
            }
            const double len = (this->Points[q] - x).norm();
            if (along < 0 || along > ratio * len + slack)
            {
              gap = true;
              this->Active[q].store(1, std::memory_order_relaxed);
            }
          }
          if (gap)
          {
            this->Active[p].store(1, std::memory_order_relaxed);
          }
          for (int q : s.Candidates)
          {
            s.IsCandidate[q] = 0;
          }
          s.AlongOf.clear();
        }
      });
    ok = !this->Cancelled.load();
    std::size_t made = 0;
    for (std::size_t k = 0; k < this->Samples.size(); ++k)
    {
      if (!before[k] && this->isActive(this->Samples[k]))
      {
        ++made;
        madeActive.push_back(this->Samples[k]);
      }
    }
    return made;
  }

private:
  struct Scratch
  {
    explicit Scratch(const EdgeGraph& graph)
      : Search(graph)
      , IsCandidate(graph.Start.size() - 1, 0)
    {
    }
    BoundedDijkstra Search;
    std::vector<char> IsCandidate;           // 0 outside testSample()
    std::vector<int> Candidates;             // of the sample being tested
    std::vector<int> Unsettled, Certifiable; // near the ball being certified
    std::vector<std::pair<int, double>> AlongOf; // facing-gap rule: candidates settled, distance
  };

  /// Cheap certificates: one search of radius l/2 from a centre c settles a ball B; a sample q in
  /// B all of whose candidates are in B is not active, since g(q, w) <= g(q, c) + g(c, w) <= l
  /// for each candidate w. The centres are spread so that these balls cover the surface; most
  /// samples are settled here at a fraction of a search each.
  void certifyInactiveByBalls(const std::vector<int>& centres, double reach)
  {
    const double half = 0.5 * this->L, r = this->R;
    tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, centres.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
        if (this->Cancelled.load(std::memory_order_relaxed))
        {
          return;
        }
        Scratch& s = this->Scratches.local();
        for (std::size_t k = range.begin(); k != range.end(); ++k)
        {
          const int c = centres[k];
          s.Search.run(c, half, [](int, double) { return true; });
          // a sample within `reach` (Euclidean) of c has all its candidates within reach + r of c:
          // it is certified unless one of those is unsettled and near it
          s.Unsettled.clear();
          s.Certifiable.clear();
          const Vec3& x = this->Points[c];
          const double reach2 = reach * reach;
          this->SampleGrid.forEachWithin(x, reach + r, [&](int w) {
            if (!s.Search.settled(w))
            {
              s.Unsettled.push_back(w);
            }
            else if ((this->Points[w] - x).squaredNorm() <= reach2 &&
              !this->Certified[w].load(std::memory_order_relaxed))
            {
              s.Certifiable.push_back(w);
            }
          });
          const double r2 = r * r;
          for (int q : s.Certifiable)
          {
            bool ok = true;
            for (int u : s.Unsettled)
            {
              if ((this->Points[u] - this->Points[q]).squaredNorm() < r2)
              {
                ok = false;
                break;
              }
            }
            if (ok)
            {
              this->Certified[q].store(1, std::memory_order_relaxed);
            }
          }
        }
        this->advance(range.size());
      });
  }

  /// Every sample neither certified nor already found active goes through the three steps.
  void testSamples()
  {
    tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, this->Samples.size(), 512), [&](const tbb::blocked_range<std::size_t>& range) {
        if (this->Cancelled.load(std::memory_order_relaxed))
        {
          return;
        }
        Scratch& s = this->Scratches.local();
        for (std::size_t k = range.begin(); k != range.end(); ++k)
        {
          const int p = this->Samples[k];
          if (this->isActive(p) || this->Certified[p].load(std::memory_order_relaxed))
          {
            continue;
          }
          this->findCandidates(p, s);
          if (!s.Candidates.empty() && !this->geodesicTest(p, s))
          {
            this->markActive(p, s);
          }
          for (int q : s.Candidates)
          {
            s.IsCandidate[q] = 0;
          }
        }
        this->advance(range.size());
      });
  }

  /// Candidate search within r: the other samples closer than r to p (Euclidean).
  void findCandidates(int p, Scratch& s) const
  {
    s.Candidates.clear();
    this->SampleGrid.forEachWithin(this->Points[p], this->R, [&](int q) {
      if (q != p)
      {
        s.Candidates.push_back(q);
        s.IsCandidate[q] = 1;
      }
    });
  }

  /// Geodesic test against l: a search from p bounded by l, ended as soon as every candidate is
  /// settled. True when every candidate is within l of p along the surface.
  bool geodesicTest(int p, Scratch& s) const
  {
    std::size_t remaining = s.Candidates.size();
    s.Search.run(p, this->L, [&](int u, double) { return !(s.IsCandidate[u] && --remaining == 0); });
    return remaining == 0;
  }

  /// Marking: some candidate is farther than l along the surface (not reached by the test's
  /// search): p is active, and so is every candidate not reached.
  void markActive(int p, const Scratch& s)
  {
    this->Active[p].store(1, std::memory_order_relaxed);
    for (int q : s.Candidates)
    {
      if (!s.Search.settled(q))
      {
        this->Active[q].store(1, std::memory_order_relaxed);
      }
    }
  }

  void advance(std::size_t steps)
  {
    const std::size_t total = this->Done.fetch_add(steps) + steps;
    if (progressUpdate(this->Report, 0.1 + 0.8 * static_cast<double>(total) / this->Work))
    {
      this->Cancelled.store(true);
    }
  }

  const std::vector<Vec3>& Points;
  const std::vector<int>& Samples;
  const double R, L;
  const PointGrid SampleGrid;
  std::unique_ptr<std::atomic<std::uint8_t>[]> Active, Certified;
  tbb::enumerable_thread_specific<Scratch> Scratches;
  Progress* Report;
  std::size_t Work = 0;
  std::atomic<std::size_t> Done{ 0 };
  std::atomic<bool> Cancelled{ false };
};

/// g_A: the geodesic distance to the nearest active sample, from one search with all of them as
/// sources, up to the cutoff (points beyond keep it). Returns the number of active samples.
/// Reports progress in (0.9, 1) and checks for a cancel every 1024 settled points: `cancelled`
/// is set when it stopped (g then incomplete).
std::size_t geodesicToActive(const EdgeGraph& graph, const std::vector<int>& samples,
  const ActiveSampleDetection& detection, double cutoff, std::vector<double>& g, Progress* progress, bool& cancelled)
{
  cancelled = false;
  BoundedDijkstra spread(graph);
  spread.restart();
  std::size_t sources = 0;
  for (int p : samples)
  {
    if (detection.isActive(p))
    {
      spread.addSource(p);
      ++sources;
    }
  }
  const double points = static_cast<double>(std::max<std::size_t>(1, g.size()));
  std::size_t settled = 0;
  spread.run(cutoff, [&](int u, double d) {
    g[u] = d;
    if ((++settled & 1023u) == 0 && progressUpdate(progress, 0.9 + 0.1 * std::min(0.999, settled / points)))
    {
      cancelled = true;
      return false;
    }
    return true;
  });
  return sources;
}

} // namespace

std::string ActivePointOptions::validate() const
{
  std::ostringstream s;
  if (!(Radius > 0) || !std::isfinite(Radius))
  {
    s << "ActiveRadius must be > 0 (got " << Radius << "). ";
  }
  if (!(GeodesicThreshold > 0) || !std::isfinite(GeodesicThreshold))
  {
    s << "GeodesicThreshold must be > 0 (got " << GeodesicThreshold << "). ";
  }
  else if (GeodesicThreshold < Radius)
  {
    s << "GeodesicThreshold (" << GeodesicThreshold << ") must be at least ActiveRadius (" << Radius
      << "): otherwise every point is active. ";
  }
  if (!(Alpha >= 1) || !std::isfinite(Alpha))
  {
    s << "AmplificationAlpha must be >= 1 (got " << Alpha << "). ";
  }
  if (!(Beta > 0) || !std::isfinite(Beta))
  {
    s << "AmplificationBeta must be > 0 (got " << Beta << "). ";
  }
  if (SampleSpacing < 0 || !std::isfinite(SampleSpacing))
  {
    s << "SampleSpacing must be >= 0. ";
  }
  if (!(GapRatio >= 0) || !std::isfinite(GapRatio))
  {
    s << "GapRatio must be >= 0 (got " << GapRatio << "). ";
  }
  if (!(AdaptivityOffFraction >= 0 && AdaptivityOffFraction <= 1))
  {
    s << "AdaptivityOffFraction must be in [0, 1] (got " << AdaptivityOffFraction << "). ";
  }
  std::string r = s.str();
  if (!r.empty())
  {
    r.pop_back();
  }
  return r;
}

double ActivePoints::phi(double dHat) const
{
  return (this->Alpha - 1.0) * std::exp(-this->Beta * this->Beta * dHat * dHat) + 1.0;
}

double ActivePoints::geodesicAt(int t, const Vec3& w) const
{
  const Triangle& tri = this->Surface.Triangles[t];
  return w[0] * this->GeodesicToActive[tri[0]] + w[1] * this->GeodesicToActive[tri[1]] +
    w[2] * this->GeodesicToActive[tri[2]];
}

double ActivePoints::amplificationAt(int t, const Vec3& closest, double distance) const
{
  if (this->NumberOfActiveSamples == 0 || t < 0 || t >= static_cast<int>(this->Surface.Triangles.size()))
  {
    return 1.0;
  }
  const Triangle& tri = this->Surface.Triangles[t];
  const Vec3& a = this->Surface.Points[tri[0]];
  const Vec3& b = this->Surface.Points[tri[1]];
  const Vec3& c = this->Surface.Points[tri[2]];
  // barycentric weights of the closest point (on the triangle), robust to slivers
  const Vec3 v0 = b - a, v1 = c - a, v2 = closest - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const double d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  Vec3 w(1.0 / 3, 1.0 / 3, 1.0 / 3);
  if (den > 1e-30)
  {
    const double v = std::clamp((d11 * d20 - d01 * d21) / den, 0.0, 1.0);
    const double u = std::clamp((d00 * d21 - d01 * d20) / den, 0.0, 1.0);
    const double s = v + u;
    w = s > 1.0 ? Vec3(0.0, v / s, u / s) : Vec3(1.0 - s, v, u);
  }
  return this->phi(this->geodesicAt(t, w) + distance);
}

std::size_t splitEdges(
  TriangleMesh& mesh, const std::function<bool(int, int)>& split, std::vector<std::array<int, 2>>* parents)
{
  // The midpoints made so far, by edge: an open-addressing table (linear probing, never erased)
  // sized for every edge being split, as in the refinement's last rounds. std::unordered_map
  // allocated a node per midpoint. ActivePointTime, median of 7, of anchor.off (its 1,050
  // triangles refined into 144,000) 0.071 -> 0.067 s, octopus-low 0.018 -> 0.014 s; the same
  // refined meshes. The marking comes first, to size it: both triangles of an edge ask the
  // same question, so the marking is conforming (the predicate must be symmetric).
  std::vector<std::uint8_t> marks(mesh.Triangles.size(), 0);
  std::size_t marking = 0; // edges marked, counted once per triangle: at least the midpoints
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    for (int k = 0; k < 3; ++k)
    {
      if (split(t[k], t[(k + 1) % 3]))
      {
        marks[f] |= static_cast<std::uint8_t>(1u << k);
        ++marking;
      }
    }
  }
  if (marking == 0)
  {
    return 0;
  }
  constexpr std::uint64_t emptyKey = ~std::uint64_t(0);
  std::size_t capacity = 64;
  while (capacity < 2 * marking)
    capacity *= 2;
  std::vector<std::uint64_t> keys(capacity, emptyKey);
  std::vector<int> ids(capacity);
  int shift = 64;
  for (std::size_t c = capacity; c > 1; c /= 2)
    --shift;
  std::size_t made = 0;
  auto mid = [&](int a, int b) {
    const std::uint64_t key = edgeKey(a, b);
    const std::size_t mask = capacity - 1;
    std::size_t i = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift);
    for (; keys[i] != emptyKey; i = (i + 1) & mask)
    {
      if (keys[i] == key)
      {
        return ids[i];
      }
    }
    const int id = static_cast<int>(mesh.Points.size());
    mesh.Points.push_back(0.5 * (mesh.Points[a] + mesh.Points[b]));
    if (parents)
    {
      parents->push_back({ a, b });
    }
    keys[i] = key;
    ids[i] = id;
    ++made;
    return id;
  };
  // the points grow by push_back (geometrically over refineMesh's rounds); the triangles are a
  // new list each round, reserved for what the marks make
  std::vector<Triangle> next;
  next.reserve(mesh.Triangles.size() + 2 * marking);
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    const Triangle t = mesh.Triangles[f];
    const bool marked[3] = { (marks[f] & 1u) != 0, (marks[f] & 2u) != 0, (marks[f] & 4u) != 0 };
    const int count = marked[0] + marked[1] + marked[2];
    if (count == 0)
    {
      next.push_back(t);
    }
    else if (count == 1)
    {
      const int k = marked[0] ? 0 : (marked[1] ? 1 : 2);
      const int a = t[k], b = t[(k + 1) % 3], o = t[(k + 2) % 3];
      const int m = mid(a, b);
      next.push_back({ a, m, o });
      next.push_back({ m, b, o });
    }
    else if (count == 2)
    {
      const int j = !marked[0] ? 0 : (!marked[1] ? 1 : 2); // the unmarked edge (a, b)
      const int a = t[j], b = t[(j + 1) % 3], c = t[(j + 2) % 3];
      const int m1 = mid(b, c), m2 = mid(c, a);
      next.push_back({ m1, c, m2 });
      if ((mesh.Points[a] - mesh.Points[m1]).squaredNorm() <= (mesh.Points[b] - mesh.Points[m2]).squaredNorm())
      {
        next.push_back({ a, b, m1 });
        next.push_back({ a, m1, m2 });
      }
      else
      {
        next.push_back({ a, b, m2 });
        next.push_back({ b, m1, m2 });
      }
    }
    else
    {
      const int m01 = mid(t[0], t[1]), m12 = mid(t[1], t[2]), m20 = mid(t[2], t[0]);
      next.push_back({ t[0], m01, m20 });
      next.push_back({ m01, t[1], m12 });
      next.push_back({ m20, m12, t[2] });
      next.push_back({ m01, m12, m20 });
    }
  }
  mesh.Triangles.swap(next);
  return made;
}

bool refineMesh(const TriangleMesh& mesh, double maxEdge, TriangleMesh& out, std::size_t maxTriangles)
{
  out = mesh;
  const double m2 = maxEdge * maxEdge;
  for (int round = 0; round < 64; ++round)
  {
    const std::size_t created =
      splitEdges(out, [&](int a, int b) { return (out.Points[a] - out.Points[b]).squaredNorm() > m2; });
    if (created == 0)
    {
      return true;
    }
    if (out.Triangles.size() > maxTriangles)
    {
      return false;
    }
  }
  return false;
}

ActivePoints computeActivePoints(const TriangleMesh& unitInput, const ActivePointOptions& options, Progress* progress)
{
  const auto t0 = std::chrono::steady_clock::now();
  ActivePoints result;
  result.Alpha = options.Alpha;
  result.Beta = options.Beta;
  result.AdaptivityOffFraction = options.AdaptivityOffFraction;
  result.Cutoff = options.geodesicCutoff();
  result.NumberOfInputPoints = unitInput.Points.size();
  const double spacing = options.sampleSpacing();

  refineMesh(unitInput, spacing, result.Surface);
  const TriangleMesh& S = result.Surface;
  const std::size_t n = S.Points.size();
  result.Active.assign(n, 0);
  result.GeodesicToActive.assign(n, result.Cutoff);
  const bool cancelled = progressUpdate(progress, 0.05);
  if (unitInput.empty() || !options.validate().empty() || cancelled)
  {
    result.Cancelled = cancelled;
    result.Seconds = seconds(t0);
    return result;
  }

  // sampling: samples half a spacing apart along the surface
  const EdgeGraph graph(S, progress);
  if (progressCancelled(progress))
  {
    result.Cancelled = true;
    result.Seconds = seconds(t0);
    return result;
  }
  const double separation = 0.5 * spacing;
  const std::vector<char> referenced = referencedPoints(S);
  const std::vector<int> samples = sampleSurface(graph, referenced, separation, progress);
  result.NumberOfSamples = samples.size();
  if (progressUpdate(progress, 0.1))
  {
    result.Cancelled = true;
    result.Seconds = seconds(t0);
    return result;
  }

  // candidate search within r, geodesic test against l, marking of the active samples
  ActiveSampleDetection detection(S, graph, samples, options.Radius, options.GeodesicThreshold, progress);
  if (!detection.run() || progressCancelled(progress))
  {
    result.Cancelled = true;
    result.Seconds = seconds(t0);
    return result;
  }

  if (options.GapRatio > 0)
  {
    // the facing-gap rule, with area-weighted vertex normals of the refined surface
    std::vector<Vec3> normals(n, Vec3::Zero());
    for (const Triangle& t : S.Triangles)
    {
      const Vec3 a = (S.Points[t[1]] - S.Points[t[0]]).cross(S.Points[t[2]] - S.Points[t[0]]);
      for (int k = 0; k < 3; ++k)
      {
        normals[t[k]] += a;
      }
    }
    for (Vec3& v : normals)
    {
      const double len = v.norm();
      v = len > 0 ? Vec3(v / len) : Vec3::Zero();
    }
    bool ok = true;
    result.NumberOfGapSamples = detection.findFacingGaps(normals, options.GapRatio, spacing, ok, result.GapSamples);
    if (!ok || progressCancelled(progress))
    {
      result.Cancelled = true;
      result.Seconds = seconds(t0);
      return result;
    }
  }

  // g_A, and the points flagged active: those within half a spacing of an active sample (the
  // resolution of the sampling)
  bool stopped = false;
  result.NumberOfActiveSamples =
    geodesicToActive(graph, samples, detection, result.Cutoff, result.GeodesicToActive, progress, stopped);
  if (stopped)
  {
    result.Cancelled = true;
    result.Seconds = seconds(t0);
    return result;
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    if (referenced[i] && result.GeodesicToActive[i] <= separation)
    {
      result.Active[i] = 1;
      ++result.NumberOfActivePoints;
      if (i < result.NumberOfInputPoints)
      {
        ++result.NumberOfActiveInputPoints;
      }
    }
  }
  progressUpdate(progress, 1.0);
  result.Seconds = seconds(t0);
  return result;
}

} // namespace sdfcage
