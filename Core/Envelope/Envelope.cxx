#include "Envelope/Envelope.h"

#include "Envelope/SDFIsosurface.h"
#include "Spatial/Geometry.h"
#include "Common/Progress.h"
#include "Quality/Verification.h"
#include "Spatial/TriangleIndex.h"
#include "Spatial/PointGrid.h"
#include "Spatial/TriangleTree.h"
#include "Mesh/EdgeKey.h"
#include "Mesh/Validation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <queue>
#include <sstream>
#include <unordered_map>

namespace sdfcage
{

namespace
{

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Keeps the outer boundary: components with negative volume bound trapped air pockets (they face
/// into the pocket), and positive components nested inside another one are redundant.
TriangleMesh outerBoundary(const TriangleMesh& surface, int& removed)
{
  std::vector<int> comp;
  const int n = triangleComponents(surface, comp);
  std::vector<double> volume(n, 0.0);
  std::vector<int> someVertex(n, -1);
  for (std::size_t f = 0; f < surface.Triangles.size(); ++f)
  {
    const Triangle& t = surface.Triangles[f];
    volume[comp[f]] += surface.Points[t[0]].dot(surface.Points[t[1]].cross(surface.Points[t[2]])) / 6.0;
    someVertex[comp[f]] = t[0];
  }
  std::vector<char> keepComponent(n, 0);
  for (int c = 0; c < n; ++c)
  {
    keepComponent[c] = volume[c] > 0.0;
  }
  // nested positive components (a part inside a cavity of another part). Each component's
  // triangles are listed once and a component can only be inside another whose box holds its
  // probe vertex; the components are tested in parallel (soups give many).
  int positive = static_cast<int>(std::count(keepComponent.begin(), keepComponent.end(), 1));
  if (positive > 1)
  {
    std::vector<std::vector<int>> trianglesOf(n);
    std::vector<Vec3> lo(n, Vec3::Constant(std::numeric_limits<double>::infinity()));
    std::vector<Vec3> hi(n, Vec3::Constant(-std::numeric_limits<double>::infinity()));
    for (std::size_t f = 0; f < surface.Triangles.size(); ++f)
    {
      const int c = comp[f];
      trianglesOf[c].push_back(static_cast<int>(f));
      for (int i : surface.Triangles[f])
      {
        lo[c] = lo[c].cwiseMin(surface.Points[i]);
        hi[c] = hi[c].cwiseMax(surface.Points[i]);
      }
    }
    // the generalized winding number of component o at p (the same sum as windingNumber())
    auto windingOf = [&](int o, const Vec3& p) {
      double total = 0.0;
      for (int f : trianglesOf[o])
      {
        const Triangle& t = surface.Triangles[f];
        total += solidAngle(surface.Points[t[0]], surface.Points[t[1]], surface.Points[t[2]], p);
      }
      return total / (4.0 * M_PI);
    };
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& range) {
      for (int c = range.begin(); c != range.end(); ++c)
      {
        if (!keepComponent[c])
        {
          continue;
        }
        const Vec3& p = surface.Points[someVertex[c]];
        for (int o = 0; o < n; ++o)
        {
          if (o == c || volume[o] <= 0.0 || (p.array() < lo[o].array()).any() || (p.array() > hi[o].array()).any())
          {
            continue; // outside a closed component's box, its winding number is 0
          }
          if (windingOf(o, p) > 0.5)
          {
            keepComponent[c] = 0;
            break;
          }
        }
      }
    });
  }
  removed = 0;
  for (int c = 0; c < n; ++c)
  {
    removed += !keepComponent[c];
  }
  std::vector<char> keep(surface.Triangles.size(), 0);
  for (std::size_t f = 0; f < keep.size(); ++f)
  {
    keep[f] = keepComponent[comp[f]];
  }
  return submesh(surface, keep);
}

/// Flags every triangle of `surface` that crosses another one (beyond shared vertices/edges);
/// with `only`, just the triangles it selects are tested (against all the others).
void markSelfIntersecting(const TriangleMesh& surface, std::vector<char>& bad, const std::vector<char>* only = nullptr)
{
  const std::size_t nf = surface.Triangles.size();
  bad.resize(nf, 0);
  TriangleIndex index;
  index.build(surface);
  const double foldCosine = -1.0 + 1e-12;
  const auto box = bounds(surface);
  const double touching = 1e-12 * std::max(1.0, (box[1] - box[0]).norm());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f)
    {
      if (only && !(*only)[f])
      {
        continue;
      }
      const Triangle& t = surface.Triangles[f];
      const int ia[3] = { t[0], t[1], t[2] };
      const Vec3 pa[3] = { surface.Points[t[0]], surface.Points[t[1]], surface.Points[t[2]] };
      const Vec3 lo = pa[0].cwiseMin(pa[1]).cwiseMin(pa[2]);
      const Vec3 hi = pa[0].cwiseMax(pa[1]).cwiseMax(pa[2]);
      index.forEachTriangleInBox(lo, hi, [&](int g) {
        if (static_cast<std::size_t>(g) == f || bad[f])
        {
          return;
        }
        const Triangle& o = surface.Triangles[g];
        const int ib[3] = { o[0], o[1], o[2] };
        const Vec3 pb[3] = { surface.Points[o[0]], surface.Points[o[1]], surface.Points[o[2]] };
        if (trianglesConflict(ia, pa, ib, pb, touching, foldCosine))
        {
          bad[f] = 1; // each triangle only writes its own flag
        }
      });
    }
  });
}

/// markSelfIntersecting with `only` for a few selected triangles of a large surface: only the
/// triangles whose boxes meet a selected one's are indexed, found through a bitmap of coarse cells
/// (at most 128 along the surface's longest side, none smaller than the largest selected
/// triangle) that the selected boxes cover, not the whole surface. The lifting asks this up to 13
/// times per envelope for a few dozen to a few hundred lifted triangles of 10-25k: indexing the
/// whole surface each time was 60% of the lifting (decimated-knight 0.028 of 0.047 s).
void markSelfIntersectingNear(const TriangleMesh& surface, const std::vector<char>& only, std::vector<char>& bad)
{
  const std::size_t nf = surface.Triangles.size();
  bad.assign(nf, 0);
  std::vector<Vec3> lo(nf), hi(nf);
  Vec3 all[2] = { Vec3::Constant(std::numeric_limits<double>::max()),
    Vec3::Constant(-std::numeric_limits<double>::max()) };
  double largest = 0.0;
  for (std::size_t f = 0; f < nf; ++f)
  {
    const Triangle& t = surface.Triangles[f];
    const Vec3 &a = surface.Points[t[0]], &b = surface.Points[t[1]], &c = surface.Points[t[2]];
    lo[f] = a.cwiseMin(b).cwiseMin(c);
    hi[f] = a.cwiseMax(b).cwiseMax(c);
    all[0] = all[0].cwiseMin(lo[f]);
    all[1] = all[1].cwiseMax(hi[f]);
    if (only[f])
      largest = std::max(largest, (hi[f] - lo[f]).maxCoeff());
  }
  if (!(largest > 0.0))
    return; // nothing selected (or only degenerate points, which cross nothing)
  const double cell = std::max(largest, (all[1] - all[0]).maxCoeff() / 128.0);
  std::int64_t dims[3];
  for (int k = 0; k < 3; ++k)
    dims[k] = static_cast<std::int64_t>(std::floor((all[1][k] - all[0][k]) / cell)) + 1;
  std::vector<std::uint64_t> covered(static_cast<std::size_t>((dims[0] * dims[1] * dims[2] + 63) / 64), 0);
  // calls visit(cell index) for every cell the box of f covers, until it returns true
  const auto anyCell = [&](std::size_t f, auto&& visit) {
    std::int64_t a[3], b[3];
    for (int k = 0; k < 3; ++k)
    {
      a[k] = std::min(dims[k] - 1, static_cast<std::int64_t>(std::floor((lo[f][k] - all[0][k]) / cell)));
      b[k] = std::min(dims[k] - 1, static_cast<std::int64_t>(std::floor((hi[f][k] - all[0][k]) / cell)));
    }
    for (std::int64_t k = a[2]; k <= b[2]; ++k)
      for (std::int64_t j = a[1]; j <= b[1]; ++j)
        for (std::int64_t i = a[0]; i <= b[0]; ++i)
          if (visit(static_cast<std::size_t>((k * dims[1] + j) * dims[0] + i)))
            return true;
    return false;
  };
  for (std::size_t f = 0; f < nf; ++f)
    if (only[f])
      anyCell(f, [&](std::size_t c) {
        covered[c >> 6] |= std::uint64_t(1) << (c & 63);
        return false;
      });
  std::vector<char> keep(nf, 0);
  for (std::size_t f = 0; f < nf; ++f)
    keep[f] = only[f] || anyCell(f, [&](std::size_t c) { return ((covered[c >> 6] >> (c & 63)) & 1) != 0; });
  // (submesh keeps the kept triangles in order and numbers their points alike, so shared corners
  // are still shared for the conflict test)
  const TriangleMesh near = submesh(surface, keep);
  std::vector<char> nearOnly, nearBad;
  nearOnly.reserve(near.Triangles.size());
  for (std::size_t f = 0; f < nf; ++f)
    if (keep[f])
      nearOnly.push_back(only[f]);
  markSelfIntersecting(near, nearBad, &nearOnly);
  std::size_t g = 0;
  for (std::size_t f = 0; f < nf; ++f)
    if (keep[f])
      bad[f] = nearBad[g++];
}

/// Points on every flagged triangle of `surface`, about one voxel apart: where an adaptive
/// extraction is repeated without adaptivity.
std::vector<Vec3> pointsOnTriangles(const TriangleMesh& surface, const std::vector<char>& flagged, double voxel)
{
  std::vector<Vec3> points;
  for (std::size_t f = 0; f < surface.Triangles.size(); ++f)
  {
    if (!flagged[f])
    {
      continue;
    }
    const Triangle& t = surface.Triangles[f];
    const Vec3 &a = surface.Points[t[0]], &b = surface.Points[t[1]], &c = surface.Points[t[2]];
    const double longest = std::max({ (b - a).norm(), (c - b).norm(), (a - c).norm() });
    const int steps = std::max(1, static_cast<int>(std::ceil(longest / voxel)));
    for (int i = 0; i <= steps; ++i)
    {
      for (int j = 0; i + j <= steps; ++j)
      {
        const double u = static_cast<double>(i) / steps, v = static_cast<double>(j) / steps;
        points.push_back(a + u * (b - a) + v * (c - a));
      }
    }
  }
  return points;
}

/// Where a failed surface is wrong: points on every triangle (sampled about one voxel apart)
/// that crosses another triangle or comes closer than `clearance` to the input.
std::vector<Vec3> defectLocations(const TriangleTree& tree, const TriangleMesh& surface, double clearance, double voxel)
{
  const std::size_t nf = surface.Triangles.size();
  std::vector<char> bad(nf, 0);
  markSelfIntersecting(surface, bad);
  // clearance
  {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        if (bad[f])
        {
          continue;
        }
        const Triangle& t = surface.Triangles[f];
        const Vec3 tri[3] = { surface.Points[t[0]], surface.Points[t[1]], surface.Points[t[2]] };
        if (tree.anyCloserThan(tri, clearance))
        {
          bad[f] = 1;
        }
      }
    });
  }
  return pointsOnTriangles(surface, bad, voxel);
}

/// Near active points the isosurface xi^ = c lies at xi = c / phi, closer to the input than the
/// grid resolves (a voxel is c/2, the offset there down to c/alpha): its chords cut corners.
/// There, the envelope is refined (edges split down to `maxEdge`) and every vertex where phi is
/// noticeably above 1 is moved along the distance gradient (away from its closest input point)
/// onto the exact solution of phi(g_A + d) d = c. Returns the number of vertices moved.
std::size_t projectOntoAmplifiedOffset(
  TriangleMesh& envelope, const ActivePoints& amp, const TriangleTree& tree, double c, double maxEdge)
{
  std::vector<char> amplified;
  std::vector<double> offset;                   // distance to the input after the projection
  std::vector<Vec3> original = envelope.Points; // where the grid put them (midpoints: of the chord)
  std::atomic<std::size_t> moved{ 0 };
  // phi - 1 <= 1e-3 (alpha - 1), below which nothing moves, once d^ >= sqrt(ln 1000) / beta. As
  // d^ = g_A(P(x)) + d(x), with g_A at a surface point at least its distance to the active
  // points less one edge of the refined surface, a vertex farther than that plus the longest
  // edge from every active point stays: a hashed grid of the active points answers it.
  double longestEdge = 0.0;
  for (const Triangle& t : amp.Surface.Triangles)
    for (int k = 0; k < 3; ++k)
      longestEdge = std::max(longestEdge, (amp.Surface.Points[t[k]] - amp.Surface.Points[t[(k + 1) % 3]]).norm());
  const double reach = std::sqrt(std::log(1000.0)) / amp.Beta + longestEdge;
  PointGrid activeGrid(reach);
  for (std::size_t i = 0; i < amp.Surface.Points.size() && i < amp.Active.size(); ++i)
    if (amp.Active[i])
      activeGrid.insert(amp.Surface.Points[i]);
  auto nearActive = [&](const Vec3& x) { return activeGrid.anyWithin(x); };
  auto project = [&](std::size_t begin) {
    amplified.resize(envelope.Points.size(), 0);
    offset.resize(envelope.Points.size(), 0.0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, envelope.Points.size(), 1024),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
        {
          Vec3& x = envelope.Points[i];
          if (!nearActive(x))
          {
            continue;
          }
          Vec3 cp;
          int t = -1;
          double d = 0.0;
          if (!tree.closestPoint(x, 2.0 * c, cp, t, d) || !(d > 0.0))
          {
            continue;
          }
          if (!(amp.amplificationAt(t, cp, d) > 1.0 + 1e-3 * (amp.Alpha - 1.0)))
          {
            continue;
          }
          // f(s) = phi(g + s) s - c is increasing on the relevant range: f(0) < 0 <= f(c)
          double lo = 0.0, hi = c;
          for (int k = 0; k < 40; ++k)
          {
            const double mid = 0.5 * (lo + hi);
            (amp.amplificationAt(t, cp, mid) * mid < c ? lo : hi) = mid;
          }
          original[i] = x;
          x = cp + (x - cp) * (hi / d);
          amplified[i] = 1;
          offset[i] = hi;
          ++moved;
        }
      });
  };
  project(0);
  const double m2 = maxEdge * maxEdge;
  // After the first round only edges with a new point are measured: an edge between points of
  // the round before has the same ends and the same answer (had it sagged, it would be split).
  std::size_t firstNew = 0;
  for (int round = 0; round < 3; ++round)
  {
    const std::size_t before = envelope.Points.size();
    // only chords that sag: where the offset surface curves (around rims and edges of the
    // input) its chords come closer to the input than their ends; flat parts are left alone
    // The candidate edges (both ends moved, longer than maxEdge) are measured once each, on all
    // threads, with the search bounded by what decides (the midpoint nearer than the bound);
    // splitEdges then looks the answers up.
    std::vector<std::uint64_t> candidates;
    for (const Triangle& t : envelope.Triangles)
      for (int k = 0; k < 3; ++k)
      {
        const int a = t[k], b = t[(k + 1) % 3];
        if (a < b && static_cast<std::size_t>(b) >= firstNew && amplified[a] && amplified[b] &&
          (envelope.Points[a] - envelope.Points[b]).squaredNorm() > m2)
          candidates.push_back(edgeKey(a, b));
      }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    std::vector<char> sags(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), 256),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
        {
          const int a = static_cast<int>(candidates[i] >> 32), b = static_cast<int>(candidates[i] & 0xFFFFFFFFu);
          const double bound = 0.9 * std::min(offset[a], offset[b]);
          Vec3 cp;
          int t = -1;
          double d = 0.0;
          sags[i] = bound > 0.0 &&
            tree.closestPoint(0.5 * (envelope.Points[a] + envelope.Points[b]), bound, cp, t, d) && d < bound;
        }
      });
    const std::size_t created = splitEdges(envelope, [&](int a, int b) {
      const std::uint64_t key = edgeKey(a, b);
      const auto it = std::lower_bound(candidates.begin(), candidates.end(), key);
      return it != candidates.end() && *it == key && sags[it - candidates.begin()] != 0;
    });
    if (created == 0)
    {
      break;
    }
    original.resize(envelope.Points.size());
    for (std::size_t i = before; i < envelope.Points.size(); ++i)
    {
      original[i] = envelope.Points[i];
    }
    project(before);
    firstNew = before;
  }
  // Moving vertices along diverging or converging normals can fold the surface in tight concave
  // places: there, the vertices go back to where the grid put them (verification decides whether
  // that is good enough).
  // After the first round, only the moved triangles that a restored vertex may have changed the
  // verdict of are tested again: those with a restored corner, and those whose box meets the box
  // of a triangle with one (every other pair is as the round before found it). The same
  // restorations as testing every moved triangle each round (dragon_quartet's repair round:
  // 0.12 s per round on its 155k-triangle envelope).
  std::vector<char> restoredPoint;
  for (int round = 0; round < 4; ++round)
  {
    // a fold the projection made involves a moved vertex: only triangles with one are tested
    const std::size_t nf = envelope.Triangles.size();
    std::vector<char> bad, moving(nf, 0);
    std::size_t movingCount = 0;
    for (std::size_t f = 0; f < nf; ++f)
    {
      const Triangle& t = envelope.Triangles[f];
      moving[f] = amplified[t[0]] || amplified[t[1]] || amplified[t[2]];
      movingCount += moving[f];
    }
    if (round > 0)
    {
      // the boxes of the triangles a restoration changed, in a grid of their own (a small mesh
      // of just their corners, renumbered)
      std::vector<char> changedTriangle(nf, 0);
      for (std::size_t f = 0; f < nf; ++f)
      {
        const Triangle& t = envelope.Triangles[f];
        changedTriangle[f] = restoredPoint[t[0]] || restoredPoint[t[1]] || restoredPoint[t[2]];
      }
      const TriangleMesh changed = submesh(envelope, changedTriangle);
      TriangleIndex near;
      near.build(changed);
      for (std::size_t f = 0; f < nf; ++f)
      {
        if (!moving[f])
          continue;
        const Triangle& t = envelope.Triangles[f];
        const Vec3 &a = envelope.Points[t[0]], &b = envelope.Points[t[1]], &c = envelope.Points[t[2]];
        bool meets = false;
        near.forEachTriangleInBox(a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c), [&](int) { meets = true; });
        moving[f] = meets;
        movingCount -= meets ? 0 : 1;
      }
    }
    if (movingCount == 0)
    {
      break;
    }
    markSelfIntersecting(envelope, bad, &moving);
    std::size_t restored = 0;
    restoredPoint.assign(envelope.Points.size(), 0);
    for (std::size_t f = 0; f < bad.size(); ++f)
    {
      if (!bad[f])
      {
        continue;
      }
      for (int k = 0; k < 3; ++k)
      {
        const int v = envelope.Triangles[f][k];
        if (amplified[v])
        {
          envelope.Points[v] = original[v];
          amplified[v] = 0;
          restoredPoint[v] = 1;
          ++restored;
        }
      }
    }
    if (restored == 0)
    {
      break;
    }
    moved -= restored;
  }
  return moved.load();
}

/// Sphere tracing from `x` along the unit direction `u`: how far to move `x` so that the input is
/// at least `c` away (up to `limit`), else how far to reach `low` first, else -1 (neither within
/// `limit`: a thin part or a fold the direction does not leave). `d` is the distance at `x`.
double traceOut(const TriangleTree& tree, const Vec3& x, const Vec3& u, double d, double c, double low, double limit)
{
  double t = 0.0, dt = d, reachedLow = -1.0;
  for (int step = 0; step < 24; ++step)
  {
    t += std::max(c - dt, 0.02 * c);
    if (t > limit)
      break;
    Vec3 q;
    int tq = -1;
    if (!tree.closestPoint(x + t * u, c, q, tq, dt) || !(dt < c))
      return t;
    if (reachedLow < 0.0 && dt >= low)
      reachedLow = t;
  }
  return reachedLow;
}

/// Whether `x` is outside the input (its winding number) and at least `low` away from it.
bool outsideAtLeast(const TriangleTree& tree, const Vec3& x, double low)
{
  Vec3 q;
  int t = -1;
  double d = 0.0;
  return !(tree.closestPoint(x, low, q, t, d) && d < low) && tree.windingNumber(x) < 0.5;
}

/// Lifted points whose triangles now cross another triangle of the envelope (moving out of a
/// concave place can push a point through the surface beside it): first moved back towards the
/// input along the way from their closest input point (which keeps them outside) until they are
/// only `low` from it, and where that still crosses, put back where they were (`from`). `lifted[p]` flags the points still away from `from`;
/// `moved` lists every lifted point with its `from`, in increasing point order.
void uncrossLifted(TriangleMesh& envelope, const TriangleTree& tree, const std::vector<std::pair<int, Vec3>>& moved,
  std::vector<char>& lifted, double c, double low)
{
  if (moved.empty())
    return;
  // where a lifted point was: `moved` is in increasing point order (few points, many calls)
  const auto fromOf = [&moved](std::size_t q) -> const Vec3& {
    return std::lower_bound(moved.begin(), moved.end(), static_cast<int>(q), [](const std::pair<int, Vec3>& m, int p) {
      return m.first < p;
    })->second;
  };
  for (int pass = 0; pass < 2; ++pass)
  {
    std::vector<char> only(envelope.Triangles.size(), 0), crossing;
    bool any = false;
    for (std::size_t f = 0; f < envelope.Triangles.size(); ++f)
      for (int p : envelope.Triangles[f])
        if (lifted[static_cast<std::size_t>(p)])
          any = only[f] = 1;
    if (!any)
      return;
    markSelfIntersectingNear(envelope, only, crossing);
    std::size_t undone = 0;
    for (std::size_t f = 0; f < envelope.Triangles.size(); ++f)
    {
      if (!crossing[f])
        continue;
      for (int p : envelope.Triangles[f])
      {
        const std::size_t q = static_cast<std::size_t>(p);
        if (!lifted[q])
          continue;
        Vec3& x = envelope.Points[q];
        Vec3 cp;
        int tq = -1;
        double d = 0.0;
        if (pass == 0 && tree.closestPoint(x, 2.0 * c, cp, tq, d) && d > low)
        {
          x = cp + (x - cp) * (low / d);
        }
        else
        {
          x = fromOf(q);
          lifted[q] = 0;
        }
        ++undone;
      }
    }
    if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
      std::fprintf(stderr, "lift: %zu crossing points %s\n", undone, pass == 0 ? "lifted less" : "put back");
    if (!undone)
      return;
  }
}

/// Adaptive extraction (EnvelopeOptions::Adaptivity) merges the voxels of flat-looking regions
/// into large polygons whose corners lie on the isosurface; where the offset curves, their flat
/// interiors cut the corner and come closer to the input than the clearance, or even cross a thin
/// part. Re-extracting such places without adaptivity costs many uniform triangles (OpenVDB's
/// adaptivity mask works per leaf of 8^3 voxels) and a whole second extraction, lifting and
/// verification, so they are mended here first:
/// - the extraction's own points closer than `margin` (merged cells place some badly) are moved
///   out along the direction from their closest input point onto the offset {d = c};
/// - then, in up to `rounds` rounds, the longest edge of every triangle closer than `margin` to
///   the input is split, and each new midpoint closer than `c` is moved out the same way, where
///   the grid put the corners (flood-fill sign: there the envelope is that offset). A midpoint
///   whose closest-point direction is not the surface's outside (it lies inside a thin part the
///   chord crosses, or the input turns there) is traced along the surface's normal instead
///   (traceOut: onto the offset within 1.5 c, else 1.5 margin away);
/// - each step's moved points that make the surface cross itself are lifted less or put back
///   (uncrossLifted).
/// Splits are conforming (splitEdges), so the surface stays closed, manifold and oriented; only
/// triangles with a new point are measured again, and no point of the extraction moves after the
/// first measurement (the verification takes its unsplit triangles as measured: KnownClearTriangles).
/// Stops when no triangle is closer than `margin`, or at `maxTriangles`; verification judges the
/// result as before (folds of the extraction's own triangles: unfoldCrossings), and what it still
/// finds goes to the re-extraction. Measured at the defaults (session 50, with unfoldCrossings,
/// median of 5 whole runs; README, "Envelope speed"): armadillo, bunny, bunny_watertight, horse,
/// octopus-low and hand_fist pass on the first extraction (before: re-extracted once, hand_fist
/// twice; armadillo 1.24 -> 1.08 s, hand_fist 0.87 -> 0.59 s), anchor, decimated-knight,
/// decimated-max, fertility and armadillo_midsub4x are still re-extracted once. OpenVDB has no
/// such step; it is a few dozen lines on top of the mesh refinement the amplified projection
/// uses. Returns the number of points added.
std::size_t liftCutCorners(
  TriangleMesh& envelope, const TriangleTree& tree, double c, double margin, int rounds, std::size_t maxTriangles)
{
  std::size_t added = 0;
  std::atomic<std::size_t> skipped{ 0 };
  const auto tl = std::chrono::steady_clock::now();
  const double traceLimit = 1.5 * c, traceLow = 1.5 * margin, uncrossLow = 1.3 * margin;
  std::vector<char> lifted(envelope.Points.size(), 0);
  {
    // the extraction's points closer than margin
    std::vector<Vec3> normal(envelope.Points.size(), Vec3::Zero());
    for (const Triangle& t : envelope.Triangles)
    {
      const Vec3 a = areaNormal(envelope, t);
      for (int k = 0; k < 3; ++k)
        normal[static_cast<std::size_t>(t[k])] += a;
    }
    const std::vector<Vec3> from = envelope.Points;
    tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, envelope.Points.size(), 512), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
        {
          Vec3& x = envelope.Points[i];
          Vec3 cp;
          int t = -1;
          double d = 0.0;
          if (!tree.closestPoint(x, margin, cp, t, d) || !(d < margin) || !(d > 1e-9 * c))
            continue;
          const Vec3 dir = x - cp;
          if (dir.dot(normal[i]) > 0.5 * d * normal[i].norm())
          {
            x = cp + dir * (c / d);
            lifted[i] = 1;
          }
        }
      });
    std::vector<std::pair<int, Vec3>> moved;
    for (std::size_t i = 0; i < lifted.size(); ++i)
      if (lifted[i])
        moved.emplace_back(static_cast<int>(i), from[i]);
    uncrossLifted(envelope, tree, moved, lifted, c, uncrossLow);
    std::fill(lifted.begin(), lifted.end(), 0);
  }
  std::size_t firstNew = 0; // triangles with a point at or beyond it are measured
  for (int round = 0; round < rounds && envelope.Triangles.size() < maxTriangles; ++round)
  {
    const std::size_t nf = envelope.Triangles.size();
    std::vector<char> bad(nf, 0);
    const auto tm = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 512), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = envelope.Triangles[f];
        if (round > 0 && std::size_t(std::max({ t[0], t[1], t[2] })) < firstNew)
          continue;
        const Vec3 tri[3] = { envelope.Points[t[0]], envelope.Points[t[1]], envelope.Points[t[2]] };
        bad[f] = tree.anyCloserThan(tri, margin) ? 1 : 0;
      }
    });
    if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
      std::fprintf(stderr, "lift round %d: %zu triangles measured in %.4f s, %ld closer than %g\n", round, nf,
        seconds(tm), static_cast<long>(std::count(bad.begin(), bad.end(), 1)), margin);
    std::vector<std::uint64_t> keys;
    for (std::size_t f = 0; f < nf; ++f)
    {
      if (!bad[f])
        continue;
      const Triangle& t = envelope.Triangles[f];
      int longest = 0;
      double best = -1.0;
      for (int k = 0; k < 3; ++k)
      {
        const double l = (envelope.Points[t[k]] - envelope.Points[t[(k + 1) % 3]]).squaredNorm();
        if (l > best)
        {
          best = l;
          longest = k;
        }
      }
      keys.push_back(edgeKey(t[longest], t[(longest + 1) % 3]));
    }
    if (keys.empty())
      break;
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    // the ends of the edges to split: the passes below look up only edges between two of them
    // (up to six rounds of lookups for every edge of the surface; median of 5, both extractions:
    // octopus-low 0.041 -> 0.029 s, decimated-knight 0.048 -> 0.030 s, armadillo 0.044 -> 0.036 s)
    std::vector<char> end(envelope.Points.size(), 0);
    for (std::uint64_t key : keys)
    {
      end[static_cast<std::size_t>(key >> 32)] = 1;
      end[static_cast<std::size_t>(key & 0xFFFFFFFFu)] = 1;
    }
    // the edge a-b's index in keys, or -1 when it is not to be split
    const auto edgeIndex = [&](int a, int b) -> std::ptrdiff_t {
      if (!end[static_cast<std::size_t>(a)] || !end[static_cast<std::size_t>(b)])
        return -1;
      const std::uint64_t key = edgeKey(a, b);
      const auto it = std::lower_bound(keys.begin(), keys.end(), key);
      return it != keys.end() && *it == key ? it - keys.begin() : -1;
    };
    const auto marked = [&](int a, int b) { return edgeIndex(a, b) >= 0; };
    // the surface's normal along each edge to split (its two triangles' area-weighted normals)
    std::vector<Vec3> edgeNormal(keys.size(), Vec3::Zero());
    for (const Triangle& t : envelope.Triangles)
      for (int k = 0; k < 3; ++k)
      {
        const std::ptrdiff_t e = edgeIndex(t[k], t[(k + 1) % 3]);
        if (e >= 0)
          edgeNormal[static_cast<std::size_t>(e)] += areaNormal(envelope, t);
      }
    const std::size_t before = envelope.Points.size();
    std::vector<std::array<int, 2>> parents;
    splitEdges(envelope, marked, &parents);
    lifted.assign(envelope.Points.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(before, envelope.Points.size(), 256),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
        {
          Vec3& x = envelope.Points[i];
          Vec3 cp;
          int t = -1;
          double d = 0.0;
          if (tree.windingNumber(x) > 0.5)
          {
            // inside the input (the chord cuts through a part or across a sharp edge, as deep as
            // 0.01 on decimated-max): out through the closest input point, whose way from x is
            // the outside there, onto the offset
            if (tree.closestPoint(x, std::numeric_limits<double>::max(), cp, t, d) && d > 1e-9 * c)
            {
              const Vec3 y = cp + (cp - x) * (c / d);
              if (outsideAtLeast(tree, y, traceLow))
              {
                x = y;
                lifted[i] = 1;
                continue;
              }
            }
            skipped++;
            continue;
          }
          if (!tree.closestPoint(x, c, cp, t, d) || !(d < c))
            continue;
          const std::array<int, 2>& ab = parents[i - before];
          const Vec3 n = edgeNormal[static_cast<std::size_t>(edgeIndex(ab[0], ab[1]))];
          const Vec3 dir = x - cp;
          if (d > 1e-9 * c && dir.dot(n) > 0.5 * d * n.norm())
          {
            x = cp + dir * (c / d);
            lifted[i] = 1;
            continue;
          }
          // a midpoint whose way away from the input is not the surface's outside: along the normal
          // (the trace measures distance, not side: a way through a part is not taken)
          const double nl = n.norm();
          const double out = nl > 0.0 ? traceOut(tree, x, n / nl, d, c, traceLow, traceLimit) : -1.0;
          if (out > 0.0 && tree.windingNumber(x + out * (n / nl)) < 0.5)
          {
            x += out * (n / nl);
            lifted[i] = 1;
          }
          else
            skipped++;
        }
      });
    std::vector<std::pair<int, Vec3>> moved;
    for (std::size_t i = before; i < envelope.Points.size(); ++i)
      if (lifted[i])
      {
        const std::array<int, 2>& ab = parents[i - before];
        moved.emplace_back(static_cast<int>(i),
          0.5 * (envelope.Points[static_cast<std::size_t>(ab[0])] + envelope.Points[static_cast<std::size_t>(ab[1])]));
      }
    uncrossLifted(envelope, tree, moved, lifted, c, uncrossLow);
    added += envelope.Points.size() - before;
    firstNew = before;
  }
  if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
    std::fprintf(stderr, "lift: %zu points added, %zu not moved, %.4f s\n", added, skipped.load(), seconds(tl));
  return added;
}

/// A lifted adaptive envelope that failed verification only because some of its triangles cross
/// their neighbours (merged cells whose triangulation folds over itself: octopus-low and hand_fist
/// at the defaults, 4 triangles around 6 points each, none near the input) is mended in place
/// instead of extracted again: the points of the crossing triangles move to the mean of their
/// neighbours and out onto the offset {d = c} along the way from their closest input point. Kept
/// only when no triangle around a moved point then crosses another or comes closer than `margin`
/// to the input; otherwise every point goes back and false is returned (the re-extraction mends
/// it, as before). Also false when a defective triangle is closer than `clearance` to the input
/// (those need the re-extraction). The caller verifies the surface again. Saves the second
/// extraction, lifting and verification (session 50: octopus-low 0.022 + 0.022 + 0.015 s).
bool unfoldCrossings(TriangleMesh& envelope, const TriangleTree& tree, const std::vector<char>& defective, double c,
  double clearance, double margin)
{
  const std::size_t nf = envelope.Triangles.size();
  if (defective.size() != nf)
    return false;
  std::vector<char> point(envelope.Points.size(), 0);
  std::size_t count = 0;
  for (std::size_t f = 0; f < nf; ++f)
  {
    if (!defective[f])
      continue;
    const Triangle& t = envelope.Triangles[f];
    const Vec3 tri[3] = { envelope.Points[t[0]], envelope.Points[t[1]], envelope.Points[t[2]] };
    if (tree.anyCloserThan(tri, clearance) || ++count > 64)
      return false; // a clearance defect, or more than a few folds
    for (int p : t)
      point[static_cast<std::size_t>(p)] = 1;
  }
  if (!count)
    return false;
  std::vector<Vec3> sum(envelope.Points.size(), Vec3::Zero());
  std::vector<int> neighbours(envelope.Points.size(), 0);
  for (const Triangle& t : envelope.Triangles)
    for (int k = 0; k < 3; ++k)
    {
      const std::size_t p = static_cast<std::size_t>(t[k]);
      if (!point[p])
        continue;
      // (each neighbour is counted twice, once from each triangle of the edge: the mean is the same)
      sum[p] += envelope.Points[t[(k + 1) % 3]] + envelope.Points[t[(k + 2) % 3]];
      neighbours[p] += 2;
    }
  std::vector<std::pair<std::size_t, Vec3>> moved;
  for (std::size_t p = 0; p < point.size(); ++p)
  {
    if (!point[p] || !neighbours[p])
      continue;
    moved.emplace_back(p, envelope.Points[p]);
    Vec3 x = sum[p] / neighbours[p];
    Vec3 cp;
    int tq = -1;
    double d = 0.0;
    if (tree.closestPoint(x, c, cp, tq, d) && d > 1e-9 * c)
      x = cp + (x - cp) * (c / d);
    envelope.Points[p] = x;
  }
  std::vector<char> around(nf, 0), crossing;
  for (std::size_t f = 0; f < nf; ++f)
    for (int p : envelope.Triangles[f])
      if (point[static_cast<std::size_t>(p)])
        around[f] = 1;
  markSelfIntersectingNear(envelope, around, crossing);
  bool sound = std::find(crossing.begin(), crossing.end(), 1) == crossing.end();
  for (std::size_t f = 0; f < nf && sound; ++f)
  {
    if (!around[f])
      continue;
    const Triangle& t = envelope.Triangles[f];
    const Vec3 tri[3] = { envelope.Points[t[0]], envelope.Points[t[1]], envelope.Points[t[2]] };
    sound = !tree.anyCloserThan(tri, margin);
  }
  if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
    std::fprintf(stderr, "unfold: %zu crossing triangles, %zu points moved, %s\n", count, moved.size(),
      sound ? "kept" : "put back");
  if (!sound)
    for (const auto& m : moved)
      envelope.Points[m.first] = m.second;
  return sound;
}

} // namespace

const char* signModeName(SignMode m)
{
  switch (m)
  {
    case SignMode::Auto:
      return "auto";
    case SignMode::FloodFill:
      return "flood";
    case SignMode::WindingNumber:
      return "winding";
    case SignMode::Unsigned:
      return "unsigned";
  }
  return "unknown";
}

int minimumCageVertices(int components, int genus)
{
  return components <= 0 ? 0 : 4 * components + 8 * std::max(genus, 0);
}

namespace
{

/// The room the envelope keeps beyond the clearance: 15% (at the isovalue, and at an active
/// point with the amplification lowered to alphaKeepingClearance).
constexpr double ClearanceRoom = 1.15;

/// The weakest amplification a topology repair round is tried with.
constexpr double MinimumRepairAlpha = 1.5;

/// x > 0 rounded up or down to three significant digits (advice that holds as printed).
double roundToDigits(double x, bool up)
{
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 2);
  return (up ? std::ceil(x / unit * (1 - 1e-12)) : std::floor(x / unit * (1 + 1e-12))) * unit;
}

/// The topology repair rounds' room: their envelope at active points 1.2 times the clearance
/// away (not 1.15 as the first envelope's): round 1's grid exact only near the gaps missed the
/// clearance at 1.15 on dragon_quartet by 3e-6 (0.00249743 against 0.0025) however large the
/// exact region (1 to 8 coarse voxels), and round 2's uniform extraction (its merged one
/// crossed itself) by 1% on three stacked hooks 0.008 apart (0.000991 against 0.001); at 1.2
/// both are verified and keep the input's topology.
constexpr double RepairClearanceRoom = 1.2;

/// The largest alpha that keeps the envelope at an active point (about isoValue / alpha from
/// the input) 15% beyond the clearance; at least 1 (no amplification).

double alphaKeepingClearance(double isoValue, double clearance)
{
  return std::max(1.0, isoValue / (ClearanceRoom * clearance));
}

bool componentBoxesDisjoint(const TriangleMesh& m);

/// Did the envelope fuse what a repair round may separate? More handles than the closed input
/// (fused parts closing a loop), or fewer parts while the input's parts lie apart.
bool fusedApart(int genus, int parts, int inputGenus, int inputParts, const TriangleMesh& input)
{
  return genus > inputGenus || (parts < inputParts && parts >= 1 && componentBoxesDisjoint(input));
}

/// One envelope with the given options (no topology repair). `skipWhenFused` (buildEnvelope's
/// first envelope when a repair round may follow): an envelope on the requested grid whose genus
/// exceeds the closed input's, or with fewer parts while the input's parts lie apart, is accepted
/// as extracted, neither projected onto the amplified offset nor verified (VerificationDeferred):
/// the repair round replaces it, and buildEnvelope builds it again the ordinary way should it be
/// kept after all. dragon_quartet's first envelope failed its verification, was re-extracted and
/// verified again before the round that replaced it.
EnvelopeResult buildEnvelopeOnce(const TriangleMesh& unitInput, const EnvelopeOptions& options, Progress* progress,
  double progressEnd, int inputClosed, bool skipWhenFused = false)
{
  EnvelopeResult result;
  if (unitInput.empty())
  {
    result.State = Status::EmptyInput;
    result.Message = "the input has no triangles";
    return result;
  }
  const double c = options.IsoValue;
  double h = options.voxelSize();
  const double delta = options.clearance();
  result.ClearanceUsed = delta;
  if (!(c > 0.0) || !(h > 0.0) || !(delta > 0.0) || delta >= c)
  {
    result.State = Status::InvalidInput;
    result.Message = "invalid parameters: need IsoValue > 0, VoxelSize > 0 and 0 < MinimumClearance < IsoValue";
    return result;
  }
  // The envelope lies at about c from the input (c / alpha at active points) and is verified
  // to keep the clearance: a clearance within 15% of c leaves the isosurface's error no room
  // on any affordable grid and no amplification at all (built-in shape, c 0.01: clearance
  // 0.0095 ran more than 200 s through ever finer grids), so it is refused at once.
  if (delta * ClearanceRoom > c)
  {
    std::ostringstream m;
    m << "the minimum clearance " << delta << " is too close to the isovalue " << c
      << " (unit-sphere units): the envelope lies about the isovalue from the input and needs at least "
      << static_cast<int>(std::lround(100 * (ClearanceRoom - 1))) << "% more than the clearance to be verified; "
      << "use an isovalue of at least " << roundToDigits(ClearanceRoom * delta, true) << " or a clearance of at most "
      << roundToDigits(c / ClearanceRoom, false);
    result.State = Status::InvalidInput;
    result.Message = m.str();
    return result;
  }
  // The inside rule: flood fill for a closed, consistently oriented 2-manifold, the winding
  // number for anything else, unless the caller forces one.
  result.InputClosed = inputClosed >= 0 ? inputClosed == 1 : checkTriangleMesh(unitInput).usable();
  if (options.Sign == SignMode::Auto)
  {
    result.SignUsed = result.InputClosed ? SignMode::FloodFill : SignMode::WindingNumber;
    result.SignReason = result.InputClosed
      ? "auto: the input is a closed, consistently oriented 2-manifold"
      : "auto: the input is not a closed, consistently oriented 2-manifold (open, non-manifold, or "
        "inconsistently oriented)";
  }
  else
  {
    result.SignUsed = options.Sign;
    result.SignReason = "requested";
  }
  const bool flood = result.SignUsed == SignMode::FloodFill;
  const bool useActivePoints = options.UseActivePoints && flood;
  // The input's tree for the verification is built meanwhile (on another thread when there is
  // one): the active points and the distance field come first. The winding-number rule needs
  // its dipoles too.
  auto inputTree = std::make_shared<TriangleTree>();
  tbb::task_group treeTask;
  const bool winding = result.SignUsed == SignMode::WindingNumber;
  // A cancel cuts the build short (every return path waits for it); tree() then builds it
  // again in full, should anything still ask for it.
  std::atomic<bool> treeComplete{ false };
  // Inputs without a defined topology (soups) enter their long triangles as pieces: a soup of
  // long slivers otherwise has every box overlap every query (20,000 random slivers: 74 s, most of
  // it in the simplifier's and the winding number's queries). Closed inputs keep whole triangles
  // and so exactly today's cages (pieces change which of two equidistant triangles a query names).
  // Their memory counts in the budget (the grids' checks below add it); pieces that would take more
  // than a quarter of it are not made (whole triangles: slower, never wrong).
  std::size_t pieceBytes = flood ? 0 : TriangleTree::pieceBytes(unitInput);
  if (pieceBytes > options.memoryLimit() / 4)
  {
    pieceBytes = 0;
  }
  const bool splitLong = !flood && pieceBytes > 0;
  // The lifting of an adaptive surface's cut corners tells inside from outside by the winding
  // number too: prepared here, beside the distance field, rather than at the lifting, on the
  // critical path (0.04 s on armadillo_midsub4x). Wasted only when active points amplify the
  // offset (the lifting is then not run): a small part of the tree's build.
  const bool windingWanted = winding || (options.Adaptivity > 0.0 && options.LiftCutCorners);
  treeTask.run([&unitInput, inputTree, windingWanted, splitLong, progress, &treeComplete] {
    if (!inputTree->build(unitInput, progress, splitLong))
    {
      return;
    }
    if (windingWanted)
    {
      inputTree->prepareWindingNumbers();
    }
    treeComplete.store(true);
  });
  struct WaitFor
  {
    tbb::task_group& Group;
    ~WaitFor()
    {
      try
      {
        Group.wait();
      }
      catch (...) // out of memory in the build: nothing to do on the way out
      {
      }
    }
  } waitForTree{ treeTask }; // every return path waits for it
  bool treeReady = false;
  auto tree = [&]() -> const TriangleTree& {
    if (!treeReady)
    {
      treeTask.wait();
      if (!treeComplete.load())
      {
        inputTree->build(unitInput, nullptr, splitLong);
        if (windingWanted)
        {
          inputTree->prepareWindingNumbers();
        }
      }
      treeReady = true;
    }
    return *inputTree;
  };
  {
    std::vector<int> comp;
    result.InputComponents = triangleComponents(unitInput, comp);
    result.InputGenus = result.InputClosed ? closedManifoldGenus(unitInput, result.InputComponents) : -1;
  }
  if (progressCancelled(progress))
  {
    result.State = Status::Cancelled;
    result.Message = "cancelled";
    return result;
  }
  ActivePoints active;
  const ActivePoints* amplification = nullptr;
  std::unique_ptr<TriangleTree> surfaceTree;
  if (useActivePoints)
  {
    const std::string bad = options.ActivePoints.validate();
    if (!bad.empty())
    {
      result.State = Status::InvalidInput;
      result.Message = "invalid active-point parameters: " + bad;
      return result;
    }
    progressStage(progress, "active points", 0.02, 0.12 * progressEnd);
    // The envelope at an active point lies at about c / alpha from the input: an alpha that
    // puts it within the clearance (a clearance above c / (1.15 alpha): 0.0029 at the default
    // c and alpha) fails verification on every grid (the built-in shape at clearance 0.0035:
    // 8 ever finer grids, 63 s, 2.1 GB, then no cage). Such an alpha is lowered to keep the
    // envelope 15% beyond the clearance, as the topology repair rounds do, and reported.
    ActivePointOptions activeOptions = options.ActivePoints;
    activeOptions.Alpha = std::min(activeOptions.Alpha, alphaKeepingClearance(options.IsoValue, options.clearance()));
    result.AlphaUsed = activeOptions.Alpha;
    active = computeActivePoints(unitInput, activeOptions, progress);
    result.ActivePointSeconds = active.Seconds;
    if (active.Cancelled || progressCancelled(progress))
    {
      result.State = Status::Cancelled;
      result.Message = "cancelled";
      return result;
    }
    result.NumberOfActivePoints = active.NumberOfActiveInputPoints;
    result.NumberOfActiveSamples = active.NumberOfActiveSamples;
    for (int id : active.GapSamples)
    {
      result.GapSites.push_back(active.Surface.Points[id]);
    }
    amplification = &active;
    // the refined surface's own tree, unless the refinement split nothing: the surface is then
    // the input itself (the same points and triangles in the same order), whose tree is being
    // built anyway (dragon_vrip: one 871k-triangle build fewer)
    if (!active.empty() &&
      !(active.Surface.Points.size() == unitInput.Points.size() &&
        active.Surface.Triangles.size() == unitInput.Triangles.size()))
    {
      surfaceTree = std::make_unique<TriangleTree>(active.Surface);
    }
  }
  // A repair round's finer grid, exact only near the gaps (EnvelopeOptions::LocalExactDilation)
  LocalExactField local;
  if (options.LocalExactDilation > 0 && amplification && !amplification->empty() && flood)
  {
    local.Dilation = options.LocalExactDilation;
    local.Tree = surfaceTree ? surfaceTree.get() : &tree();
  }
  const double fieldBegin = useActivePoints ? 0.12 * progressEnd : 0.02;
  // Attempts: the requested grid, first with the requested adaptivity and, if that envelope fails
  // verification (merged polygons can cut corners or cross), without it from the same field; then
  // finer grids without adaptivity.
  int attempt = 0;
  // A coarse grid first (EnvelopeOptions::CoarseFirst): nothing below the isovalue needs
  // resolving when no point is active, and a closed input's topology tells whether the coarse
  // envelope fused anything. Levels -2 and -1 are the coarse grids; level 0 the requested one.
  const bool coarseFirst = options.CoarseFirst && !(options.VoxelSize > 0) && flood &&
    (!amplification || amplification->empty()) && result.InputClosed;
  const int levels = 1 + std::max(0, options.MaximumRefinements);
  // The grids in turn: with CoarseFirst voxel 2h (level -2), then 4h/3 (level -1) when that one
  // fused parts or held too few points, then the requested h (level 0) and its refinements h/2,
  // h/4. The grid between keeps apart what the coarsest fuses at about half the requested grid's
  // cost: armadillo (an arm fused with the body at voxel 2h) 2.46 -> 1.70 s for its cage at
  // 4h/3 alone, H 0.0174 -> 0.0181 of the diagonal (at 3h/2: 1.74 s, H 0.0194).
  const double requestedVoxel = h;
  const auto voxelAt = [requestedVoxel](int level) {
    return level == -2 ? 2.0 * requestedVoxel
      : level == -1    ? requestedVoxel * 4.0 / 3.0
                       : std::ldexp(requestedVoxel, -level);
  };
  for (int level = coarseFirst ? -2 : 0; level < levels; ++level)
  {
    h = voxelAt(level);
    const bool coarseLevel = level < 0;
    bool coarseRejected = false;
    // the memory budget, before the grid is built (MemoryBudget.h)
    const std::size_t need = estimateEnvelopeBytes(unitInput, h, c, flood, options.KeepDistanceField) + pieceBytes;
    if (need > options.memoryLimit() && coarseLevel)
    {
      continue; // the requested grid, finer, is over it too: its check names the need
    }
    if (need > options.memoryLimit())
    {
      std::ostringstream m;
      m << "the envelope at voxel size " << h << " needs about " << formatBytes(need)
        << " of memory (distance grid, isosurface and verification, estimated), more than the memory limit of "
        << formatBytes(options.memoryLimit());
      if (level == 0)
      {
        result.State = Status::Failed;
        result.Message = m.str() + ": use a larger VoxelSize or IsoValue, or raise MemoryLimit";
        return result;
      }
      result.Message += " (no finer grid tried: " + m.str() + ")";
      break;
    }
    std::vector<double> adaptivities{ 0.0 };
    if (level <= 0 && options.Adaptivity > 0)
    {
      adaptivities = { options.Adaptivity, 0.0 };
      if (options.Adaptivity > 0.3)
      {
        // a high adaptivity (the repair rounds') that fails even after the local repairs tries
        // the default before the uniform triangles (3M of them at voxel 0.0025 on dragon_quartet)
        adaptivities = { options.Adaptivity, 0.3, 0.0 };
      }
    }
    progressStage(progress, "distance field and isosurface", fieldBegin, 0.7 * progressEnd);
    // Each extracted surface is judged here: outer boundary, then the full verification. A
    // failing adaptive surface is re-extracted with adaptivity off around its defects.
    bool accepted = false;
    // An adaptive surface's verification flags every defect (not only the first) and remembers
    // the sound triangles: the surface re-extracted around the defects keeps 90-96% of them, and
    // its verification tests only the rest (verification stage: octopus-low 0.113 -> 0.078 s,
    // armadillo 0.18 -> 0.095 s, hand_fist 0.185 -> 0.105 s; same envelopes).
    VerificationMemo memo;
    const SurfaceJudge judge = [&](const TriangleMesh& surface, double adaptivity, std::vector<Vec3>& repairNear) {
      auto t0 = std::chrono::steady_clock::now();
      int pockets = 0;
      TriangleMesh envelope = outerBoundary(surface, pockets);
      if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
        std::fprintf(stderr, "judge: outer boundary %.4f s\n", seconds(t0));
      if (progressCancelled(progress))
      {
        return false; // computeIsosurface reports the cancel
      }
      // the envelope's parts and genus, computed once when first needed
      int parts = -1, g = 0;
      bool usable = false;
      const auto topology = [&]() {
        if (parts < 0)
        {
          const MeshDefects d = checkTriangleMesh(envelope);
          parts = d.Components;
          usable = d.usable();
          g = usable ? d.Genus : 0;
        }
      };
      if (coarseLevel && result.InputClosed)
      {
        // fused on the coarse grid, or too few points for the target (judged before the costly
        // mending and verification; the accepted envelope is checked again below): the
        // requested grid decides
        if (envelope.Points.size() >= options.CoarseMinimumPoints)
          topology();
        if (envelope.Points.size() < options.CoarseMinimumPoints ||
          (usable && (parts != result.InputComponents || g != result.InputGenus)))
        {
          if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
            std::fprintf(stderr, "coarse grid rejected: %zu points, %d parts, genus %d (input %d, %d)\n",
              envelope.Points.size(), parts, g, result.InputComponents, result.InputGenus);
          coarseRejected = true;
          return true; // stops the extraction
        }
      }
      if (options.VertexBudget > 0)
      {
        // too many parts and handles for the target: not worth verifying (a wider one follows)
        topology();
        if (minimumCageVertices(parts, g) > options.VertexBudget && coarseLevel)
        {
          coarseRejected = true; // the requested grid may separate what the coarse one fused
          return true;           // stops the extraction
        }
        if (minimumCageVertices(parts, g) > options.VertexBudget)
        {
          result.TooComplex = true;
          result.Components = parts;
          result.Genus = g;
          result.Envelope = std::move(envelope);
          result.IsosurfaceSeconds += seconds(t0);
          return true; // stops the extraction; buildEnvelope reports TooComplex
        }
      }
      if (skipWhenFused && !coarseLevel && flood && result.InputClosed && !options.DeferVerification)
      {
        topology();
        if (usable && fusedApart(g, parts, result.InputGenus, result.InputComponents, unitInput))
        {
          result.Components = parts;
          result.Genus = g;
          result.Envelope = std::move(envelope);
          result.RemovedPockets = pockets;
          result.VoxelSizeUsed = h;
          result.AdaptivityUsed = adaptivity;
          result.Refinements = std::max(0, level);
          result.VerificationDeferred = true;
          result.IsosurfaceSeconds += seconds(t0);
          accepted = true;
          return true; // stops the extraction
        }
      }
      KnownClearTriangles lifted;
      if (adaptivity > 0.0 && options.LiftCutCorners && !(amplification && !amplification->empty()))
      {
        // (the extraction's points keep their ids and positions: its triangles the lifting left
        // unsplit were measured clear of the input by 1.2 delta)
        lifted.Below = envelope.Points.size();
        lifted.Distance = 1.2 * delta;
        // the lifting tells inside from outside by the input's winding number (prepared with
        // the tree: windingWanted)
        result.LiftedPoints +=
          liftCutCorners(envelope, tree(), c, lifted.Distance, 6, 4 * envelope.Triangles.size() + 1024);
      }
      if (amplification && !amplification->empty())
      {
        result.ProjectedVertices =
          projectOntoAmplifiedOffset(envelope, *amplification, surfaceTree ? *surfaceTree : tree(), c, 0.5 * h);
      }
      result.IsosurfaceSeconds += seconds(t0);
      if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
        std::fprintf(stderr, "judge: boundary, lift and projection %.4f s\n", seconds(t0));
      progressStage(progress, "verifying enclosure", 0.7 * progressEnd, progressEnd);
      auto t1 = std::chrono::steady_clock::now();
      std::string why;
      double clearance = 0.0;
      std::vector<double> distances;
      // (deferred: accepted as extracted, the caller verifies it if it keeps it)
      const bool withMemo = adaptivity > 0.0 && !options.ExactEnvelopeClearance && !options.DeferVerification;
      // (the manifold check, parts and genus of the surface as verified: the verification's
      // first step, and the accepted envelope's parts and genus below)
      const MeshDefects checked = withMemo ? checkTriangleMesh(envelope) : MeshDefects();
      bool ok = options.DeferVerification ||
        (withMemo ? verifyEnclosureWithMemo(
                      unitInput, envelope, delta, clearance, why, &distances, progress, tree(), memo, &checked, &lifted)
                  : verifyEnclosure(unitInput, envelope, delta, clearance, why, &distances, progress,
                      options.ExactEnvelopeClearance, &tree()));
      // folds of the lifted surface mended in place, then verified again (the memo spares the
      // triangles that did not move; the moved points are extraction points, so no triangle is
      // taken as known clear; the connectivity, hence `checked`, is unchanged)
      if (!ok && withMemo && lifted.Below > 0 && !progressCancelled(progress) &&
        unfoldCrossings(envelope, tree(), memo.Defective, c, delta, lifted.Distance))
      {
        distances.clear();
        ok = verifyEnclosureWithMemo(
          unitInput, envelope, delta, clearance, why, &distances, progress, tree(), memo, &checked, nullptr);
      }
      result.VerificationDeferred = options.DeferVerification;
      ++attempt;
      if (ok && withMemo)
      {
        result.Components = checked.Components;
        result.Genus = checked.usable() ? checked.Genus : genus(envelope);
      }
      if (ok)
      {
        result.Envelope = std::move(envelope);
        result.DistanceToInput = std::move(distances);
        result.MinimumClearance = clearance;
        result.RemovedPockets = pockets;
        result.VoxelSizeUsed = h;
        result.AdaptivityUsed = adaptivity;
        result.Refinements = std::max(0, level);
        accepted = true;
      }
      else if (!progressCancelled(progress))
      {
        std::ostringstream m;
        m << "envelope at voxel size " << h << " (adaptivity " << adaptivity << ") failed verification: " << why;
        result.Message = m.str();
        if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
        {
          std::fprintf(stderr, "%s\n", result.Message.c_str());
        }
        if (adaptivity > 0.0)
        {
          repairNear =
            withMemo ? pointsOnTriangles(envelope, memo.Defective, h) : defectLocations(tree(), envelope, delta, h);
        }
      }
      result.VerificationSeconds += seconds(t1);
      if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
        std::fprintf(stderr, "judge: verification %.4f s (%s)\n", seconds(t1), ok ? "passed" : "failed");
      if (ok && !withMemo)
      {
        // (the accepted envelope's parts and genus: not part of the verification's time, which
        // is none for a deferred envelope)
        const MeshDefects d = checkTriangleMesh(result.Envelope);
        result.Components = d.Components;
        result.Genus = d.usable() ? d.Genus : genus(result.Envelope);
      }
      return ok;
    };
    IsosurfaceOutput iso = computeIsosurface(unitInput, h, c, options.KeepDistanceField, progress, adaptivities,
      amplification, &judge, 4, result.SignUsed, flood ? nullptr : &tree(),
      options.ClusteredField && !std::getenv("SDFCAGE_EXACT_FIELD"), local.Dilation > 0 ? &local : nullptr);
    result.ExactVoxels = iso.ExactVoxels;
    result.WindingSeconds += iso.WindingSeconds;
    result.WindingEvaluations += iso.WindingEvaluations;
    result.AmplifiedVoxels = iso.AmplifiedVoxels;
    if (accepted)
      result.FieldTriangles = iso.FieldTriangles;
    result.AmplificationSeconds += iso.AmplificationSeconds;
    result.AdaptiveRepairs = iso.Repairs;
    result.DistanceFieldSeconds += iso.DistanceFieldSeconds;
    result.IsosurfaceSeconds += iso.IsosurfaceSeconds;
    if (iso.Cancelled || progressCancelled(progress))
    {
      result.State = Status::Cancelled;
      result.Message = "cancelled";
      return result;
    }
    if (!iso.Error.empty())
    {
      result.State = Status::Failed;
      result.Message = iso.Error;
      return result;
    }
    if (coarseRejected)
    {
      continue;
    }
    if (accepted && coarseLevel)
    {
      if (result.Components != result.InputComponents || result.Genus != result.InputGenus)
      {
        accepted = false; // fused on the coarse grid: the requested grid decides
        result.Envelope = TriangleMesh();
        result.DistanceToInput.clear();
        continue;
      }
    }
    result.DistanceField = std::move(iso.Field);
    result.ModifiedDistanceField = std::move(iso.ModifiedField);
    if (result.TooComplex)
    {
      result.State = Status::Failed;
      result.Message = "the envelope has " + std::to_string(result.Components) + " part(s) and genus " +
        std::to_string(result.Genus) + ": a cage like it needs about " +
        std::to_string(minimumCageVertices(result.Components, result.Genus)) + " vertices or more";
      tree();
      result.InputTree = inputTree;
      return result;
    }
    if (accepted)
    {
      // (result.Components and result.Genus: the accepted envelope's, set by the judge)
      // the input's genus is defined for a closed input only
      if (result.InputClosed && (result.Genus != result.InputGenus || result.Components != result.InputComponents))
      {
        std::ostringstream w;
        w << "the envelope has genus " << result.Genus << " and " << result.Components
          << " component(s), the input genus " << result.InputGenus << " and " << result.InputComponents
          << ": parts of the input closer than the parameters can "
          << "separate were fused";
        if (!useActivePoints)
        {
          w << " (active points are off: turn them on)";
        }
        else
        {
          w << " (try a smaller IsoValue and VoxelSize, or a larger ActiveRadius / AmplificationAlpha)";
        }
        result.TopologyWarning = w.str();
      }
      result.EnclosureVerified = !result.VerificationDeferred;
      result.State = Status::Ok;
      result.Message.clear();
      tree();
      result.InputTree = inputTree;
      return result;
    }
  }
  result.State = Status::VerificationFailed;
  result.EnclosureVerified = false;
  result.Message +=
    " (after " + std::to_string(attempt) + " attempts with finer grids; try a larger IsoValue or a smaller VoxelSize)";
  return result;
}

} // namespace

namespace
{

bool topologyDiffers(const EnvelopeResult& r)
{
  return r.State == Status::Ok && r.InputClosed && (r.Genus != r.InputGenus || r.Components != r.InputComponents);
}

/// Are the bounding boxes of the input's components pairwise disjoint? (Then fewer envelope
/// parts than input parts means parts fused. Nested or overlapping parts share a box: their
/// envelope has fewer parts whatever the resolution, and no repair can change that.)
bool componentBoxesDisjoint(const TriangleMesh& m)
{
  std::vector<int> comp;
  const int n = triangleComponents(m, comp);
  if (n < 2 || n > 4096)
  {
    return n < 2;
  }
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Vec3> lo(n, Vec3::Constant(inf)), hi(n, Vec3::Constant(-inf));
  for (std::size_t t = 0; t < m.Triangles.size(); ++t)
  {
    for (int k = 0; k < 3; ++k)
    {
      lo[comp[t]] = lo[comp[t]].cwiseMin(m.Points[m.Triangles[t][k]]);
      hi[comp[t]] = hi[comp[t]].cwiseMax(m.Points[m.Triangles[t][k]]);
    }
  }
  for (int i = 0; i < n; ++i)
  {
    for (int j = i + 1; j < n; ++j)
    {
      if ((lo[i].array() <= hi[j].array()).all() && (lo[j].array() <= hi[i].array()).all())
      {
        return false;
      }
    }
  }
  return true;
}

/// Can a repair help? When the envelope has more handles than the input (fused parts closing a
/// loop), or fewer parts while the input's parts lie apart.
bool repairMayHelp(const EnvelopeResult& r, const TriangleMesh& input)
{
  return topologyDiffers(r) && fusedApart(r.Genus, r.Components, r.InputGenus, r.InputComponents, input);
}

/// Surface area of the input (unit-sphere units): the narrow-band grid holds about area / h^2
/// voxels along it.
double surfaceArea(const TriangleMesh& m)
{
  double a = 0.0;
  for (const Triangle& t : m.Triangles)
  {
    a += 0.5 * areaNormal(m, t).norm();
  }
  return a;
}

/// Where the input's own surface crosses itself and joins parts that lie farther than `apart`
/// from each other along it (a tail pushed into a body, a horn through a head): there the solid
/// the flood fill sees is fused already, so its genus or number of parts is not the surface's,
/// and no envelope, however fine, can separate what the input itself joins. One site (a point
/// of the crossing) per such place; crossings that are folds within `apart` along the surface
/// (a local overlap, no new handle) are left out.
std::vector<Vec3> selfFusedSites(const TriangleMesh& m, double apart)
{
  const std::size_t nf = m.Triangles.size();
  TriangleIndex index;
  index.build(m);
  const auto box = bounds(m);
  const double touching = 1e-12 * std::max(1.0, (box[1] - box[0]).norm());
  std::vector<std::pair<int, int>> pairs;
  std::mutex pairsMutex;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::pair<int, int>> local;
    for (std::size_t f = r.begin(); f != r.end(); ++f)
    {
      const Triangle& t = m.Triangles[f];
      const int ia[3] = { t[0], t[1], t[2] };
      const Vec3 pa[3] = { m.Points[t[0]], m.Points[t[1]], m.Points[t[2]] };
      const Vec3 lo = pa[0].cwiseMin(pa[1]).cwiseMin(pa[2]);
      const Vec3 hi = pa[0].cwiseMax(pa[1]).cwiseMax(pa[2]);
      index.forEachTriangleInBox(lo, hi, [&](int g) {
        if (static_cast<std::size_t>(g) <= f)
        {
          return;
        }
        const Triangle& o = m.Triangles[g];
        const int ib[3] = { o[0], o[1], o[2] };
        const Vec3 pb[3] = { m.Points[o[0]], m.Points[o[1]], m.Points[o[2]] };
        if (trianglesConflict(ia, pa, ib, pb, touching, -1.0 + 1e-12))
        {
          local.emplace_back(static_cast<int>(f), g);
        }
      });
    }
    if (!local.empty())
    {
      std::lock_guard<std::mutex> lock(pairsMutex);
      pairs.insert(pairs.end(), local.begin(), local.end());
    }
  });
  if (pairs.empty())
  {
    return {};
  }
  std::sort(pairs.begin(), pairs.end()); // the same sites whatever the thread schedule
  // places: crossing triangles joined by a crossing or a shared vertex
  std::vector<int> parent(nf);
  for (std::size_t f = 0; f < nf; ++f)
  {
    parent[f] = static_cast<int>(f);
  }
  auto root = [&](int x) {
    while (parent[x] != x)
    {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  auto join = [&](int a, int b) { parent[root(a)] = root(b); };
  std::unordered_map<int, int> crossingAtVertex;
  auto touchVertices = [&](int f) {
    for (int v : m.Triangles[f])
    {
      const auto it = crossingAtVertex.emplace(v, f);
      if (!it.second)
      {
        join(f, it.first->second);
      }
    }
  };
  for (const auto& p : pairs)
  {
    join(p.first, p.second);
    touchVertices(p.first);
    touchVertices(p.second);
  }
  // is g farther than `apart` from f along the surface (edge paths from f's corners)?
  std::vector<std::vector<std::pair<int, double>>> edges(m.Points.size());
  for (const Triangle& t : m.Triangles)
  {
    for (int k = 0; k < 3; ++k)
    {
      const int a = t[k], b = t[(k + 1) % 3];
      const double l = (m.Points[a] - m.Points[b]).norm();
      edges[a].emplace_back(b, l);
      edges[b].emplace_back(a, l);
    }
  }
  std::vector<double> dist(m.Points.size(), std::numeric_limits<double>::infinity());
  std::vector<int> touched;
  auto farApart = [&](int f, int g) {
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    for (int v : m.Triangles[f])
    {
      dist[v] = 0.0;
      touched.push_back(v);
      queue.emplace(0.0, v);
    }
    const Triangle& target = m.Triangles[g];
    bool reached = false;
    while (!queue.empty() && !reached)
    {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > dist[v])
      {
        continue;
      }
      reached = v == target[0] || v == target[1] || v == target[2];
      for (const auto& [w, l] : edges[v])
      {
        const double dw = d + l;
        if (dw < dist[w] && dw <= apart)
        {
          if (std::isinf(dist[w]))
          {
            touched.push_back(w);
          }
          dist[w] = dw;
          queue.emplace(dw, w);
        }
      }
    }
    for (int v : touched)
    {
      dist[v] = std::numeric_limits<double>::infinity();
    }
    touched.clear();
    return !reached;
  };
  std::vector<Vec3> sites;
  std::unordered_map<int, char> placeDone; // place root -> decided far
  int searches = 0;
  for (const auto& p : pairs)
  {
    const int place = root(p.first);
    if (placeDone.count(place) || searches >= 4096)
    {
      continue;
    }
    ++searches;
    if (farApart(p.first, p.second))
    {
      placeDone[place] = 1;
      const Triangle& t = m.Triangles[p.first];
      sites.push_back((m.Points[t[0]] + m.Points[t[1]] + m.Points[t[2]]) / 3.0);
    }
  }
  return sites;
}

/// Up to `count` sites, each at least `apart` from the ones before (the first ones in order).
std::vector<Vec3> spreadSites(const std::vector<Vec3>& sites, std::size_t count, double apart)
{
  std::vector<Vec3> out;
  for (const Vec3& p : sites)
  {
    bool near = false;
    for (const Vec3& q : out)
    {
      near = near || (p - q).norm() < apart;
    }
    if (!near)
    {
      out.push_back(p);
      if (out.size() == count)
      {
        break;
      }
    }
  }
  return out;
}

/// Adds the stage times of an envelope built and not kept (a repair round, a first envelope
/// built again verified) to those of the one kept: the timings count every build.
void addStageSeconds(EnvelopeResult& to, const EnvelopeResult& from)
{
  to.DistanceFieldSeconds += from.DistanceFieldSeconds;
  to.IsosurfaceSeconds += from.IsosurfaceSeconds;
  to.VerificationSeconds += from.VerificationSeconds;
  to.ActivePointSeconds += from.ActivePointSeconds;
}

} // namespace

EnvelopeResult buildEnvelope(const TriangleMesh& unitInput, const EnvelopeOptions& options, Progress* progress,
  double progressEnd, int inputClosed)
{
  const bool mayRepair = options.UseActivePoints && options.MaximumTopologyRepairs > 0;
  EnvelopeResult first = buildEnvelopeOnce(unitInput, options, progress, progressEnd, inputClosed, mayRepair);
  // The first envelope, when it was accepted unverified for a repair round (skipWhenFused) and
  // is kept after all: built again the ordinary way (deterministic: the same envelope, verified,
  // or re-extracted and refined as verification demands), the time spent on it counted.
  const auto verifiedFirst = [&](EnvelopeResult& r) {
    if (!r.VerificationDeferred || options.DeferVerification || r.State != Status::Ok)
    {
      return;
    }
    EnvelopeResult again = buildEnvelopeOnce(unitInput, options, progress, progressEnd, inputClosed);
    addStageSeconds(again, r);
    again.GapSites = std::move(r.GapSites);
    r = std::move(again);
  };
  const bool repairable = first.SignUsed == SignMode::FloodFill && mayRepair && !first.TooComplex;
  if (!repairable || !repairMayHelp(first, unitInput))
  {
    verifiedFirst(first);
    if (topologyDiffers(first) && options.RequireTopology)
    {
      first.State = Status::TopologyChanged;
      first.Message = first.TopologyWarning;
      first.Envelope = TriangleMesh();
      first.EnclosureVerified = false;
    }
    return first;
  }
  const double c = options.IsoValue, h0 = options.voxelSize(), delta0 = options.clearance();
  // Where the input crosses itself and joins parts far apart along its surface, the solid is
  // fused already: when such places can account for every extra handle and lost part, the
  // envelope has the solid's topology, and the repair rounds (up to 16x the voxels each, most
  // of the time on such inputs: 5k-face cow 105 s) could not change it.
  {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<Vec3> fused = selfFusedSites(unitInput, options.ActivePoints.GeodesicThreshold);
    first.VerificationSeconds += seconds(t0);
    const int excess = std::max(0, first.Genus - first.InputGenus) + std::max(0, first.InputComponents - first.Components);
    if (!fused.empty() && excess <= static_cast<int>(fused.size()))
    {
      verifiedFirst(first);
      if (first.State != Status::Ok)
      {
        return first; // cancelled, or no grid verified it (as without the skip)
      }
      std::ostringstream where;
      where << "the input intersects itself in " << fused.size()
            << " place(s) joining parts far apart along its surface, near (unit-sphere units):";
      for (const Vec3& p : spreadSites(fused, 5, 4.0 * c))
      {
        where << " (" << p.x() << ", " << p.y() << ", " << p.z() << ")";
      }
      where << "; there its solid is fused already, so the envelope follows the solid's topology, not the "
               "surface's";
      first.SelfFusedSites = fused;
      first.TopologyRepairLog = "envelope genus " + std::to_string(first.Genus) + ", " +
        std::to_string(first.Components) + " part(s) (input " + std::to_string(first.InputGenus) + ", " +
        std::to_string(first.InputComponents) + "); no repair round: " + where.str();
      first.TopologyWarning = "the envelope has genus " + std::to_string(first.Genus) + " and " +
        std::to_string(first.Components) + " component(s), the input's surface genus " +
        std::to_string(first.InputGenus) + " and " + std::to_string(first.InputComponents) + ": " + where.str();
      if (options.RequireTopology)
      {
        first.State = Status::TopologyChanged;
        first.Message = first.TopologyWarning;
        first.Envelope = TriangleMesh();
        first.EnclosureVerified = false;
      }
      return first;
    }
  }
  // The repair rounds (see EnvelopeOptions::MaximumTopologyRepairs): each is a whole new
  // envelope with the facing-gap rule, a stronger amplification and a finer grid.
  const bool automaticClearance = !(options.MinimumClearance > 0);
  const double area = surfaceArea(unitInput);
  std::ostringstream log;
  log << "envelope genus " << first.Genus << ", " << first.Components << " part(s) (input " << first.InputGenus << ", "
      << first.InputComponents << ")";
  EnvelopeResult best = std::move(first);
  int rounds = 0;
  const int maxRounds = std::min(options.MaximumTopologyRepairs, 2);
  // each round's grid, clearance and amplification: the envelope at an active point lies at
  // about c / alpha, kept 20% beyond the clearance (RepairClearanceRoom; buildEnvelopeOnce would
  // lower a larger alpha to 15%)
  const auto roundVoxel = [&](int round) { return round == 1 ? 0.5 * h0 : 0.25 * h0; };
  const auto roundClearance = [&](int round) { return round == 2 && automaticClearance ? 0.4 * delta0 : delta0; };
  const auto roundAlpha = [&](int round) { return std::max(1.0, c / (RepairClearanceRoom * roundClearance(round))); };
  const auto roundVoxels = [&](int round) { return area / (roundVoxel(round) * roundVoxel(round)); };
  // (is round 2 tried: allowed, with room to amplify and within the surface voxels' limit?)
  const bool secondRoundTried = maxRounds >= 2 && roundAlpha(2) >= MinimumRepairAlpha &&
    roundVoxels(2) <= options.MaximumRepairSurfaceVoxels;
  for (int round = 1; round <= maxRounds; ++round)
  {
    EnvelopeOptions o = options;
    o.MaximumTopologyRepairs = 0;
    o.RequireTopology = false;
    // A round's envelope that fails verification on the round's grid is not refined further:
    // round 1's grid refined is round 2's, and a finer one than round 2's costs 4 and 16 times
    // its surface voxels for an amplification that already failed there (dragon_quartet with
    // round 1 forced to voxel 0.0035: round 2 refined to 0.000625 and took 350 s and 11.8 GB,
    // still not verified).
    o.MaximumRefinements = 0;
    o.ActivePoints.GapRatio = options.ActivePoints.GapRatio > 0 ? options.ActivePoints.GapRatio : 3.0;
    o.VoxelSize = roundVoxel(round);
    const double delta = roundClearance(round);
    o.MinimumClearance = delta;
    o.ActivePoints.Alpha = roundAlpha(round);
    // The first round's finer grid, with merged polygons wherever the amplification leaves room:
    // OpenVDB merges any unambiguous, manifold block at adaptivity 1 (no normal test), and the
    // samples the round amplifies keep uniform triangles where phi > 1 + 0.5 (alpha - 1) (the
    // default bound, see amplify in SDFIsosurface.cxx: the envelope within 0.45 c of the input,
    // 0.2 c beyond the clearance at alpha 3.48). Every envelope is verified; merged polygons that
    // fail are re-extracted without adaptivity around the defects (then at 0.3, then uniform).
    // dragon_quartet (one round, 18 samples, voxel 0.0025; whole runs): envelope 320,176 ->
    // 166,378 triangles, 24.8 / 25.9 -> 19.1 / 19.4 s, about 450 -> 427 MB, Hausdorff cage->input
    // 0.0553 -> 0.0495 of the diagonal. (Adaptivity 0.3 with the bound 0.6: 262,296
    // triangles; adaptivity 1 with the bound 0.6: 150,714 and 18.3-19.4 s, but its cage's MIPS
    // optimization stalls at 12.9 degrees, 15.04 with the bound 0.5; adaptivity 0.9 or 0.99:
    // 190-193k, OpenVDB's normal test merges far less than none.) The second round keeps the
    // requested adaptivity: its clearance is 0.4 times the first's, and there adaptivity 1 costs a
    // failed extraction (three parts 0.004 apart: 8.5 -> 9.7 s).
    if (round == 1 && options.Adaptivity > 0.0)
    {
      o.Adaptivity = 1.0;
    }
    const double voxels = roundVoxels(round);
    log << "; round " << round << ": voxel " << o.VoxelSize << ", alpha " << o.ActivePoints.Alpha << ", clearance "
        << delta;
    // A clearance close to the isovalue leaves the round almost no amplification: it would
    // separate only parts between 2c / alpha and 2c apart, at 4 and 16 times the first envelope's
    // cost (built-in shape, clearance 0.86 c: alpha 1.01, rounds of 6.6 and 24.6 s, nothing
    // separated).
    if (o.ActivePoints.Alpha < MinimumRepairAlpha)
    {
      log << ": not tried (the clearance leaves room for an amplification of " << o.ActivePoints.Alpha
          << " only, less than " << MinimumRepairAlpha << ": a larger IsoValue or a smaller clearance lets it amplify)";
      if (automaticClearance && round == 1)
      {
        continue; // round 2 lowers an automatic clearance, which leaves more room
      }
      break;
    }
    if (voxels > options.MaximumRepairSurfaceVoxels)
    {
      log << ": not tried (about " << static_cast<long long>(voxels) << " surface voxels, more than "
          << static_cast<long long>(options.MaximumRepairSurfaceVoxels) << ")";
      break;
    }
    const std::string stage = "repairing topology (round " + std::to_string(round) + ")";
    progressStage(progress, stage.c_str(), 0.02, progressEnd);
    const auto roundStart = std::chrono::steady_clock::now();
    // The round's finer grid is needed where nearly touching parts must stay apart: exact
    // within 4 coarse voxels of the gaps the grid twice as coarse may fuse, the coarse field
    // interpolated elsewhere (EnvelopeOptions::LocalExactDilation). Measured on dragon_quartet
    // (its repair round, whole runs): round 4.4 s instead of 9.8 s, total 12.5 s instead of
    // 15.2-15.9 s, 353 MB instead of 378 MB; 0.84 M of 8.1 M voxels exact at 2 voxels, 2.4 M of
    // 9.1 M at 4 (the gaps: 7,042 coarse voxels). A round that fails so (not verified, or the
    // topology still differs) is run again on the whole exact grid, unless it was verified
    // and round 2 follows: that round's grid is exact and finer, and the exact grid of this
    // round kept the local one's extra handles on every generated gap shape that needed round
    // 2 (hook 0.004 and 0.008: genus 1 and 1; cluster 0.004: 3 and 3, 0.008: 14 and 13; ring
    // 0.004: 1 and 1), 0.45-1 s for nothing.
    EnvelopeOptions localOptions = o;
    if (round == 1)
    {
      localOptions.LocalExactDilation = 4;
    }
    EnvelopeResult r = buildEnvelopeOnce(
      unitInput, localOptions.LocalExactDilation > 0 ? localOptions : o, progress, progressEnd, inputClosed ? 1 : 0);
    if (localOptions.LocalExactDilation > 0 && r.State != Status::Cancelled && !progressCancelled(progress) &&
      (r.State != Status::Ok || (topologyDiffers(r) && !secondRoundTried)))
    {
      log << ": with the grid exact near the gaps only (" << r.ExactVoxels << " voxels), "
          << (r.State != Status::Ok ? std::string("not verified") : "genus " + std::to_string(r.Genus))
          << "; on the exact grid";
      EnvelopeResult exact = buildEnvelopeOnce(unitInput, o, progress, progressEnd, inputClosed ? 1 : 0);
      addStageSeconds(exact, r);
      r = std::move(exact);
    }
    else if (localOptions.LocalExactDilation > 0)
      log << ": with the grid exact near the gaps only (" << r.ExactVoxels << " voxels)";
    const double roundSeconds = seconds(roundStart);
    ++rounds;
    if (r.State == Status::Cancelled || progressCancelled(progress))
    {
      r.State = Status::Cancelled;
      r.Message = "cancelled";
      return r;
    }
    // each round's time (a round costs about 4, then 16 times the first envelope)
    char took[32];
    std::snprintf(took, sizeof took, " (%.2f s)", roundSeconds);
    log << ": " << r.NumberOfActiveSamples << " active samples (" << r.GapSites.size() << " by the gap rule), ";
    // (a round's stages count in the timings whether or not its envelope is kept)
    if (r.State != Status::Ok)
    {
      log << "not verified" << took;
      addStageSeconds(best, r);
      continue;
    }
    log << "genus " << r.Genus << ", " << r.Components << " part(s)" << took;
    const bool better = !topologyDiffers(r);
    if (better)
    {
      addStageSeconds(r, best);
      best = std::move(r);
      break;
    }
    // keep the first envelope, but remember where the gaps are
    if (best.GapSites.empty())
    {
      best.GapSites = r.GapSites;
    }
    addStageSeconds(best, r);
  }
  if (best.VerificationDeferred && !options.DeferVerification)
  {
    // no round was better: the first envelope is kept, verified now
    verifiedFirst(best);
    if (best.State == Status::Cancelled)
    {
      return best;
    }
    log << "; the first envelope kept";
  }
  best.TopologyRepairs = rounds;
  best.TopologyRepairLog = log.str();
  if (topologyDiffers(best))
  {
    std::ostringstream w;
    w << best.TopologyWarning << "; " << rounds << " repair round(s) did not separate them";
    const std::vector<Vec3> sites = spreadSites(best.GapSites, 5, 4.0 * c);
    if (!sites.empty())
    {
      w << "; narrow gaps near (unit-sphere units):";
      for (const Vec3& p : sites)
      {
        w << " (" << p.x() << ", " << p.y() << ", " << p.z() << ")";
      }
    }
    best.TopologyWarning = w.str();
    if (options.RequireTopology)
    {
      best.State = Status::TopologyChanged;
      best.Message = best.TopologyWarning;
      best.Envelope = TriangleMesh();
      best.EnclosureVerified = false;
    }
  }
  else
  {
    best.TopologyWarning.clear();
  }
  return best;
}

} // namespace sdfcage
