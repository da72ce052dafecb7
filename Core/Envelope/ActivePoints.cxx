#include "Envelope/ActivePoints.h"

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
#include <unordered_map>

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
    return { static_cast<std::int64_t>(std::floor(p.x() / Cell)),
      static_cast<std::int64_t>(std::floor(p.y() / Cell)), static_cast<std::int64_t>(std::floor(p.z() / Cell)) };
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

  explicit EdgeGraph(const TriangleMesh& mesh)
  {
    const std::size_t n = mesh.Points.size();
    std::vector<std::pair<int, int>> edges;
    edges.reserve(mesh.Triangles.size() * 3);
    for (const Triangle& t : mesh.Triangles)
    {
      for (int k = 0; k < 3; ++k)
      {
        const int a = t[k], b = t[(k + 1) % 3];
        if (a != b)
        {
          edges.emplace_back(std::min(a, b), std::max(a, b));
        }
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    Start.assign(n + 1, 0);
    for (const auto& e : edges)
    {
      ++Start[e.first + 1];
      ++Start[e.second + 1];
    }
    for (std::size_t i = 0; i < n; ++i)
    {
      Start[i + 1] += Start[i];
    }
    Neighbor.resize(Start[n]);
    Length.resize(Start[n]);
    std::vector<std::size_t> fill(Start.begin(), Start.end() - 1);
    for (const auto& e : edges)
    {
      const double len = (mesh.Points[e.first] - mesh.Points[e.second]).norm();
      Neighbor[fill[e.first]] = e.second;
      Length[fill[e.first]++] = len;
      Neighbor[fill[e.second]] = e.first;
      Length[fill[e.second]++] = len;
    }
  }
};

using HeapEntry = std::pair<double, int>;

/// Per-thread Dijkstra state, reset in O(1) by stamps.
struct Search
{
  std::vector<double> Dist;
  std::vector<std::uint32_t> Seen;    // Dist valid when Seen == Now
  std::vector<std::uint32_t> Settled; // settled when == Now
  std::vector<std::uint32_t> Target;  // a Euclidean neighbour of the source when == Now
  std::vector<HeapEntry> Heap;
  std::vector<int> Targets;
  std::uint32_t Now = 0;

  explicit Search(std::size_t n)
    : Dist(n, 0.0)
    , Seen(n, 0)
    , Settled(n, 0)
    , Target(n, 0)
  {
  }
};

void pushHeap(std::vector<HeapEntry>& h, double d, int v)
{
  h.emplace_back(d, v);
  std::push_heap(h.begin(), h.end(), std::greater<HeapEntry>());
}

HeapEntry popHeap(std::vector<HeapEntry>& h)
{
  std::pop_heap(h.begin(), h.end(), std::greater<HeapEntry>());
  HeapEntry e = h.back();
  h.pop_back();
  return e;
}

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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

std::size_t splitEdges(TriangleMesh& mesh, const std::function<bool(int, int)>& split,
  std::vector<std::array<int, 2>>* parents)
{
  std::unordered_map<std::uint64_t, int> midpoints;
  auto mid = [&](int a, int b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
      static_cast<std::uint32_t>(std::max(a, b));
    auto it = midpoints.find(key);
    if (it != midpoints.end())
    {
      return it->second;
    }
    const int id = static_cast<int>(mesh.Points.size());
    mesh.Points.push_back(0.5 * (mesh.Points[a] + mesh.Points[b]));
    if (parents)
    {
      parents->push_back({ a, b });
    }
    midpoints.emplace(key, id);
    return id;
  };
  // both triangles of an edge ask the same question, so the marking is conforming; the
  // predicate must be symmetric
  std::vector<Triangle> next;
  next.reserve(mesh.Triangles.size() + mesh.Triangles.size() / 2);
  for (const Triangle& t : mesh.Triangles)
  {
    bool marked[3];
    int count = 0;
    for (int k = 0; k < 3; ++k)
    {
      marked[k] = split(t[k], t[(k + 1) % 3]);
      count += marked[k];
    }
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
  return midpoints.size();
}

bool refineMesh(const TriangleMesh& mesh, double maxEdge, TriangleMesh& out, std::size_t maxTriangles)
{
  out = mesh;
  const double m2 = maxEdge * maxEdge;
  for (int round = 0; round < 64; ++round)
  {
    const std::size_t created = splitEdges(out, [&](int a, int b) {
      return (out.Points[a] - out.Points[b]).squaredNorm() > m2;
    });
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
  result.Cutoff = options.geodesicCutoff();
  result.NumberOfInputPoints = unitInput.Points.size();
  const double spacing = options.sampleSpacing();
  const double r = options.Radius;
  const double l = options.GeodesicThreshold;

  refineMesh(unitInput, spacing, result.Surface);
  const TriangleMesh& S = result.Surface;
  const std::size_t n = S.Points.size();
  result.Active.assign(n, 0);
  result.GeodesicToActive.assign(n, result.Cutoff);
  progressUpdate(progress, 0.05);
  if (unitInput.empty() || !options.validate().empty())
  {
    result.Seconds = seconds(t0);
    return result;
  }

  // Referenced points only (unreferenced input points take no part).
  std::vector<char> referenced(n, 0);
  for (const Triangle& t : S.Triangles)
  {
    referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
  }
  std::vector<int> all;
  all.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    if (referenced[i])
    {
      all.push_back(static_cast<int>(i));
    }
  }

  // Samples: greedy, in point order (deterministic): a point not yet within half a spacing of a
  // sample *along the surface* becomes one. (A Euclidean cover would let one part's samples
  // stand for a nearly touching other part, which then has no samples of its own.)
  const EdgeGraph graph(S);
  const double separation = 0.5 * spacing;
  std::vector<int> samples;
  {
    std::vector<char> covered(n, 0);
    Search cover(n);
    for (int id : all)
    {
      if (covered[id])
      {
        continue;
      }
      samples.push_back(id);
      const std::uint32_t now = ++cover.Now;
      cover.Heap.clear();
      cover.Dist[id] = 0.0;
      cover.Seen[id] = now;
      pushHeap(cover.Heap, 0.0, id);
      while (!cover.Heap.empty())
      {
        const auto [d, u] = popHeap(cover.Heap);
        if (cover.Settled[u] == now || d > cover.Dist[u])
        {
          continue;
        }
        cover.Settled[u] = now;
        covered[u] = 1;
        for (std::size_t e = graph.Start[u]; e < graph.Start[u + 1]; ++e)
        {
          const int v = graph.Neighbor[e];
          const double nd = d + graph.Length[e];
          if (nd <= separation && cover.Settled[v] != now && (cover.Seen[v] != now || nd < cover.Dist[v]))
          {
            cover.Seen[v] = now;
            cover.Dist[v] = nd;
            pushHeap(cover.Heap, nd, v);
          }
        }
      }
    }
  }
  result.NumberOfSamples = samples.size();
  progressUpdate(progress, 0.1);

  const PointGrid sampleGrid(S.Points, samples, r);
  std::unique_ptr<std::atomic<std::uint8_t>[]> active(new std::atomic<std::uint8_t>[n]);
  for (std::size_t i = 0; i < n; ++i)
  {
    active[i].store(0, std::memory_order_relaxed);
  }

  tbb::enumerable_thread_specific<Search> searches([n]() { return Search(n); });
  std::atomic<bool> cancelled{ false };
  auto nextStamp = [](Search& s) {
    if (++s.Now == 0)
    {
      std::fill(s.Seen.begin(), s.Seen.end(), 0);
      std::fill(s.Settled.begin(), s.Settled.end(), 0);
      std::fill(s.Target.begin(), s.Target.end(), 0);
      s.Now = 1;
    }
    return s.Now;
  };
  // Bounded Dijkstra from p; `visit(u, d)` is called on every settled point and returns false to
  // stop the search.
  auto dijkstra = [&](Search& s, int p, double limit, auto&& visit) {
    const std::uint32_t now = s.Now;
    s.Heap.clear();
    s.Dist[p] = 0.0;
    s.Seen[p] = now;
    pushHeap(s.Heap, 0.0, p);
    while (!s.Heap.empty())
    {
      const auto [d, u] = popHeap(s.Heap);
      if (s.Settled[u] == now || d > s.Dist[u])
      {
        continue;
      }
      s.Settled[u] = now;
      if (!visit(u, d))
      {
        return;
      }
      for (std::size_t e = graph.Start[u]; e < graph.Start[u + 1]; ++e)
      {
        const int v = graph.Neighbor[e];
        const double nd = d + graph.Length[e];
        if (nd > limit || s.Settled[v] == now)
        {
          continue;
        }
        if (s.Seen[v] != now || nd < s.Dist[v])
        {
          s.Seen[v] = now;
          s.Dist[v] = nd;
          pushHeap(s.Heap, nd, v);
        }
      }
    }
  };

  // Phase 1 (cheap certificates): one search of radius l/2 from a centre c settles a ball B; a
  // sample q in B all of whose Euclidean neighbours are in B is not active, since
  // g(q, w) <= g(q, c) + g(c, w) <= l for each neighbour w. Centres are spread so that these
  // balls cover the surface; most samples are settled here at a fraction of a search each.
  std::unique_ptr<std::atomic<std::uint8_t>[]> certified(new std::atomic<std::uint8_t>[n]);
  std::vector<char> isSample(n, 0);
  for (std::size_t i = 0; i < n; ++i)
  {
    certified[i].store(0, std::memory_order_relaxed);
  }
  for (int q : samples)
  {
    isSample[q] = 1;
  }
  const double half = 0.5 * l;
  const double reach = std::max(0.0, half - r);
  // centres: the first sample (in point order) of every occupied cell of side reach / sqrt(3),
  // so every sample lies within `reach` of the centre of its cell
  std::vector<int> centres;
  if (reach > 0)
  {
    const double cell = reach / std::sqrt(3.0);
    std::vector<std::pair<std::array<std::int64_t, 3>, int>> keyed(samples.size());
    for (std::size_t k = 0; k < samples.size(); ++k)
    {
      const Vec3& x = S.Points[samples[k]];
      keyed[k] = { { static_cast<std::int64_t>(std::floor(x.x() / cell)), static_cast<std::int64_t>(std::floor(x.y() / cell)),
                     static_cast<std::int64_t>(std::floor(x.z() / cell)) },
        samples[k] };
    }
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t k = 0; k < keyed.size(); ++k)
    {
      if (k == 0 || keyed[k].first != keyed[k - 1].first)
      {
        centres.push_back(keyed[k].second);
      }
    }
  }
  std::atomic<std::size_t> done{ 0 };
  const std::size_t work = centres.size() + samples.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, centres.size(), 16),
    [&](const tbb::blocked_range<std::size_t>& range) {
      if (cancelled.load(std::memory_order_relaxed))
      {
        return;
      }
      Search& s = searches.local();
      std::vector<int> unsettled, candidates;
      for (std::size_t k = range.begin(); k != range.end(); ++k)
      {
        const int c = centres[k];
        const std::uint32_t now = nextStamp(s);
        dijkstra(s, c, half, [](int, double) { return true; });
        // a sample within `reach` (Euclidean) of c has all its Euclidean neighbours within
        // reach + r of c: it is certified unless one of those is unsettled and near it
        unsettled.clear();
        candidates.clear();
        const Vec3& x = S.Points[c];
        const double reach2 = reach * reach;
        sampleGrid.forEachWithin(x, reach + r, [&](int w) {
          if (s.Settled[w] != now)
          {
            unsettled.push_back(w);
          }
          else if ((S.Points[w] - x).squaredNorm() <= reach2 && !certified[w].load(std::memory_order_relaxed))
          {
            candidates.push_back(w);
          }
        });
        const double r2 = r * r;
        for (int q : candidates)
        {
          bool ok = true;
          for (int u : unsettled)
          {
            if ((S.Points[u] - S.Points[q]).squaredNorm() < r2)
            {
              ok = false;
              break;
            }
          }
          if (ok)
          {
            certified[q].store(1, std::memory_order_relaxed);
          }
        }
      }
      const std::size_t total = done.fetch_add(range.size()) + range.size();
      if (progressUpdate(progress, 0.1 + 0.8 * static_cast<double>(total) / work))
      {
        cancelled.store(true);
      }
    });

  // Phase 2: every other sample p gets its own search, ended as soon as every Euclidean
  // neighbour is settled (p is not active) or when the radius l is exhausted (p is active, and
  // so is every neighbour not reached).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples.size(), 512),
    [&](const tbb::blocked_range<std::size_t>& range) {
      if (cancelled.load(std::memory_order_relaxed))
      {
        return;
      }
      Search& s = searches.local();
      for (std::size_t k = range.begin(); k != range.end(); ++k)
      {
        const int p = samples[k];
        if (active[p].load(std::memory_order_relaxed) || certified[p].load(std::memory_order_relaxed))
        {
          continue;
        }
        const std::uint32_t now = nextStamp(s);
        s.Targets.clear();
        sampleGrid.forEachWithin(S.Points[p], r, [&](int q) {
          if (q != p)
          {
            s.Targets.push_back(q);
            s.Target[q] = now;
          }
        });
        std::size_t remaining = s.Targets.size();
        if (remaining == 0)
        {
          continue;
        }
        dijkstra(s, p, l, [&](int u, double) { return !(s.Target[u] == now && --remaining == 0); });
        if (remaining > 0)
        {
          // some Euclidean neighbour is farther than l along the surface: both are active
          active[p].store(1, std::memory_order_relaxed);
          for (int q : s.Targets)
          {
            if (s.Settled[q] != now)
            {
              active[q].store(1, std::memory_order_relaxed);
            }
          }
        }
      }
      const std::size_t total = done.fetch_add(range.size()) + range.size();
      if (progressUpdate(progress, 0.1 + 0.8 * static_cast<double>(total) / work))
      {
        cancelled.store(true);
      }
    });
  if (cancelled.load() || progressCancelled(progress))
  {
    result.Cancelled = true;
    result.Seconds = seconds(t0);
    return result;
  }

  // g_A: multi-source Dijkstra from the active samples, up to the cutoff.
  std::vector<HeapEntry> heap;
  std::vector<char> settled(n, 0);
  std::vector<double>& g = result.GeodesicToActive;
  for (int p : samples)
  {
    if (active[p].load(std::memory_order_relaxed))
    {
      ++result.NumberOfActiveSamples;
      g[p] = 0.0;
      pushHeap(heap, 0.0, p);
    }
  }
  while (!heap.empty())
  {
    const auto [d, u] = popHeap(heap);
    if (settled[u] || d > g[u])
    {
      continue;
    }
    settled[u] = 1;
    for (std::size_t e = graph.Start[u]; e < graph.Start[u + 1]; ++e)
    {
      const int v = graph.Neighbor[e];
      const double nd = d + graph.Length[e];
      if (!settled[v] && nd < g[v])
      {
        g[v] = nd;
        pushHeap(heap, nd, v);
      }
    }
  }
  // A point is flagged active when it lies within half a spacing of an active sample (the
  // resolution of the sampling).
  for (std::size_t i = 0; i < n; ++i)
  {
    if (referenced[i] && g[i] <= separation)
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
