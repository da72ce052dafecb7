#include "Quality/Verification.h"

#include "Common/Progress.h"
#include "Mesh/Validation.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleIndex.h"
#include "Spatial/TriangleTree.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <unordered_map>

namespace sdfcage
{

namespace
{

/// Step 3 of the checks: the surface never comes near the input, so each input component lies
/// entirely inside or entirely outside; one vertex per component is tested by winding number.
bool componentsInside(const TriangleMesh& input, const TriangleMesh& cage, std::string& why, Progress* progress)
{
  const std::vector<Vec3> probe = componentProbes(input);
  const int ncomp = static_cast<int>(probe.size());
  // one probe per component, in parallel (soups have many components)
  const int outside = tbb::parallel_reduce(
    tbb::blocked_range<int>(0, ncomp, 1), 0,
    [&](const tbb::blocked_range<int>& r, int count) {
      for (int c = r.begin(); c != r.end(); ++c)
      {
        count += windingNumber(cage, probe[c]) < 0.5;
      }
      return count;
    },
    [](int a, int b) { return a + b; });
  progressUpdate(progress, 1.0);
  if (outside > 0)
  {
    why = std::to_string(outside) + " input components are not inside the surface";
    return false;
  }
  return true;
}

/// Disjoint triangles closer than this (relative to the mesh size) count as touching.
double touchingTolerance(const TriangleMesh& mesh)
{
  const auto box = bounds(mesh);
  return 1e-12 * std::max(1.0, (box[1] - box[0]).norm());
}

/// Calls visit(g) for every triangle g != f of `mesh` (indexed by `index`) that conflicts with
/// triangle f (trianglesConflict, exact-intersection fold test) and that `consider(g)` admits;
/// consider runs before the exact test.
template <typename Consider, typename Visit>
void forEachConflict(const TriangleMesh& mesh, const TriangleIndex& index, std::size_t f, double touching,
  Consider&& consider, Visit&& visit)
{
  // exact-intersection fold test for edge-sharing pairs: only exactly opposite normals overlap
  const double foldCosine = -1.0 + 1e-12;
  const Triangle& t = mesh.Triangles[f];
  const int ia[3] = { t[0], t[1], t[2] };
  const Vec3 pa[3] = { mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]] };
  const Vec3 pad = Vec3::Constant(touching);
  const Vec3 lo = pa[0].cwiseMin(pa[1]).cwiseMin(pa[2]) - pad;
  const Vec3 hi = pa[0].cwiseMax(pa[1]).cwiseMax(pa[2]) + pad;
  index.forEachTriangleInBox(lo, hi, [&](int g) {
    if (static_cast<std::size_t>(g) == f || !consider(g))
      return;
    const Triangle& o = mesh.Triangles[g];
    const int ib[3] = { o[0], o[1], o[2] };
    const Vec3 pb[3] = { mesh.Points[o[0]], mesh.Points[o[1]], mesh.Points[o[2]] };
    if (trianglesConflict(ia, pa, ib, pb, touching, foldCosine))
      visit(g);
  });
}

/// A lower bound of triangle t's distance to the input from its corners' distances `dist`: the
/// distance changes by at most the distance travelled.
double cornerBound(const TriangleMesh& mesh, const Triangle& t, const std::vector<double>& dist)
{
  double lower = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i)
  {
    const Vec3& p = mesh.Points[t[i]];
    const double reach = std::max((mesh.Points[t[(i + 1) % 3]] - p).norm(), (mesh.Points[t[(i + 2) % 3]] - p).norm());
    lower = std::max(lower, dist[t[i]] - reach);
  }
  return lower;
}

} // namespace

long long countSelfIntersections(const TriangleMesh& mesh, Progress* progress, double touching)
{
  TriangleIndex index;
  index.build(mesh);
  if (!(touching >= 0.0))
  {
    touching = touchingTolerance(mesh);
  }
  return tbb::parallel_reduce(
    tbb::blocked_range<std::size_t>(0, mesh.Triangles.size(), 256), 0LL,
    [&](const tbb::blocked_range<std::size_t>& r, long long count) {
      if (progressCancelled(progress))
      {
        return count;
      }
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        // each pair once, from its smaller id
        forEachConflict(
          mesh, index, f, touching, [f](int g) { return static_cast<std::size_t>(g) > f; }, [&](int) { ++count; });
      }
      return count;
    },
    [](long long a, long long b) { return a + b; });
}

bool verifyEnclosure(const TriangleMesh& input, const TriangleMesh& cage, double clearance, double& measuredClearance,
  std::string& why, std::vector<double>* pointDistances, Progress* progress, bool exactMinimum,
  const TriangleTree* inputTree)
{
  measuredClearance = 0.0;
  why.clear();
  const MeshDefects d = checkTriangleMesh(cage);
  if (!d.usable())
  {
    why = "the surface is not a closed 2-manifold: " + d.errorMessage();
    return false;
  }
  const long long selfIntersections = countSelfIntersections(cage, progress);
  if (selfIntersections > 0)
  {
    why = "the surface intersects itself (" + std::to_string(selfIntersections) + " triangle pairs)";
    return false;
  }
  std::unique_ptr<TriangleTree> ownTree;
  if (!inputTree)
  {
    ownTree = std::make_unique<TriangleTree>(input);
    inputTree = ownTree.get();
  }
  const TriangleTree& index = *inputTree;

  // 1. exact distance of every cage point to the input
  const std::size_t nv = cage.Points.size();
  std::vector<double> dist(nv, 0.0);
  std::atomic<std::size_t> done{ 0 };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    if (progressCancelled(progress))
    {
      return;
    }
    for (std::size_t i = r.begin(); i != r.end(); ++i)
    {
      dist[i] = index.distance(cage.Points[i]);
    }
    const std::size_t n = done.fetch_add(r.size()) + r.size();
    progressUpdate(progress, 0.6 * static_cast<double>(n) / static_cast<double>(std::max<std::size_t>(nv, 1)));
  });
  if (progressCancelled(progress))
  {
    why = "cancelled";
    return false;
  }
  double upper = std::numeric_limits<double>::infinity();
  for (double v : dist)
  {
    upper = std::min(upper, v);
  }

  // 2. per triangle, a Lipschitz lower bound from its corners: the distance to the input changes
  // by at most the distance travelled. Exact triangle-triangle distances only where the bound
  // does not already settle the question: for the exact minimum, every triangle whose bound is
  // below the best value so far; for certification, every triangle whose bound is below delta
  // (and then only up to delta, which the tree answers quickly).
  const double stopAt = exactMinimum ? upper : clearance;
  const std::size_t nf = cage.Triangles.size();
  std::vector<std::pair<double, int>> uncertain; // (lower bound, triangle)
  double certified = upper;
  for (std::size_t f = 0; f < nf; ++f)
  {
    const double lower = cornerBound(cage, cage.Triangles[f], dist);
    if (lower < stopAt)
    {
      uncertain.emplace_back(lower, static_cast<int>(f));
    }
    else
    {
      certified = std::min(certified, lower);
    }
  }
  std::sort(uncertain.begin(), uncertain.end());
  // process in increasing lower-bound order, in parallel chunks, stopping once the bound passes
  // the best exact value found so far
  std::atomic<double> best{ exactMinimum ? upper : clearance };
  const std::size_t chunk = 4096;
  std::atomic<double> certifiedUncertain{ std::numeric_limits<double>::infinity() };
  for (std::size_t b = 0; b < uncertain.size(); b += chunk)
  {
    if (exactMinimum && uncertain[b].first >= best.load())
    {
      break;
    }
    if (progressCancelled(progress))
    {
      why = "cancelled";
      return false;
    }
    const std::size_t e = std::min(uncertain.size(), b + chunk);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(b, e, 64), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k)
      {
        const double limit = exactMinimum ? best.load() : clearance;
        if (exactMinimum && uncertain[k].first >= limit)
        {
          continue;
        }
        const Triangle& t = cage.Triangles[uncertain[k].second];
        const Vec3 tri[3] = { cage.Points[t[0]], cage.Points[t[1]], cage.Points[t[2]] };
        const double dd = index.triangleDistance(tri, limit);
        double cur = best.load();
        while (dd < cur && !best.compare_exchange_weak(cur, dd))
        {
        }
        if (!exactMinimum)
        {
          // certified: at least max(its bound, delta) unless closer than delta
          const double value = dd < clearance ? dd : std::max(uncertain[k].first, clearance);
          double c2 = certifiedUncertain.load();
          while (value < c2 && !certifiedUncertain.compare_exchange_weak(c2, value))
          {
          }
        }
      }
    });
    progressUpdate(progress, 0.6 + 0.3 * static_cast<double>(e) / static_cast<double>(uncertain.size()));
  }
  if (!exactMinimum && best.load() >= clearance)
  {
    // nothing closer than delta: report the certified lower bound
    best.store(std::min(certified, certifiedUncertain.load()));
  }
  measuredClearance = best.load();
  if (pointDistances)
  {
    *pointDistances = std::move(dist);
  }
  if (!(measuredClearance >= clearance))
  {
    std::ostringstream s;
    s << "the surface comes within " << measuredClearance << " of the input (required clearance " << clearance << ")";
    why = s.str();
    return false;
  }

  // 3. enclosure: the surface never comes near the input, so each input component lies entirely
  // inside or entirely outside
  return componentsInside(input, cage, why, progress);
}

namespace
{

using Corners = std::array<double, 9>;
using Position = std::array<double, 3>;

struct BitsHash
{
  template <std::size_t N>
  std::size_t operator()(const std::array<double, N>& a) const
  {
    std::uint64_t h = 1469598103934665603ull;
    for (double v : a)
    {
      std::uint64_t bits;
      v = v == 0.0 ? 0.0 : v; // -0 and +0 compare equal: one key
      std::memcpy(&bits, &v, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
      h ^= h >> 29;
    }
    return static_cast<std::size_t>(h);
  }
};

Position positionKey(const Vec3& p)
{
  return { p.x(), p.y(), p.z() };
}

/// The triangle's corners from its lexicographically smallest one on, in its own order (a
/// rotation keeps the orientation; the flipped triangle is another key).
Corners cornersKey(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const Position p[3] = { positionKey(a), positionKey(b), positionKey(c) };
  int first = 0;
  for (int i = 1; i < 3; ++i)
    if (p[i] < p[first])
      first = i;
  Corners k;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      k[3 * i + j] = p[(first + i) % 3][j];
  return k;
}

} // namespace

struct VerificationMemo::Store
{
  const TriangleMesh* Input = nullptr;
  double Clearance = 0.0, Touching = 0.0;
  std::unordered_map<Corners, double, BitsHash> Sound; // -> certified distance to the input
  std::unordered_map<Position, double, BitsHash> Distance;
};

bool verifyEnclosureWithMemo(const TriangleMesh& input, const TriangleMesh& surface, double clearance,
  double& measuredClearance, std::string& why, std::vector<double>* pointDistances, Progress* progress,
  const TriangleTree& inputTree, VerificationMemo& memo, const MeshDefects* checked, const KnownClearTriangles* clear)
{
  measuredClearance = 0.0;
  why.clear();
  const std::size_t nv = surface.Points.size(), nf = surface.Triangles.size();
  const double touching = touchingTolerance(surface);
  // what the memo may give: same input and clearance, a tolerance for touching at least ours
  std::shared_ptr<const VerificationMemo::Store> known = memo.Known;
  if (known && (known->Input != &input || known->Clearance != clearance || known->Touching < touching))
    known.reset();
  // triangles known sound: their corners as before and not duplicated here (a corner repeated
  // under two ids would share differently with its neighbours than before)
  std::vector<double> knownBound(nf, -1.0); // >= 0: certified distance of a known triangle
  std::vector<Corners> keys(nf);
  {
    std::unordered_map<Position, int, BitsHash> first;
    first.reserve(2 * nv);
    std::vector<char> duplicated(nv, 0);
    for (std::size_t i = 0; i < nv; ++i)
    {
      const auto ins = first.emplace(positionKey(surface.Points[i]), static_cast<int>(i));
      if (!ins.second)
        duplicated[i] = duplicated[ins.first->second] = 1;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = surface.Triangles[f];
        keys[f] = cornersKey(surface.Points[t[0]], surface.Points[t[1]], surface.Points[t[2]]);
        if (!known || duplicated[t[0]] || duplicated[t[1]] || duplicated[t[2]])
          continue;
        const auto it = known->Sound.find(keys[f]);
        if (it != known->Sound.end())
          knownBound[f] = it->second;
      }
    });
  }
  memo.Reused =
    static_cast<std::size_t>(std::count_if(knownBound.begin(), knownBound.end(), [](double b) { return b >= 0.0; }));
  memo.Defective.assign(nf, 0);
  std::vector<char>& defective = memo.Defective;

  // 0. closed 2-manifold (judged whole: it is cheap)
  const MeshDefects d = checked ? *checked : checkTriangleMesh(surface);
  std::string manifoldWhy;
  if (!d.usable())
    manifoldWhy = "the surface is not a closed 2-manifold: " + d.errorMessage();

  // 1. conflicting pairs with at least one new triangle, each tested and counted once: from its
  // new triangle of smaller id, or from its only new one (the test is symmetric; both sides
  // tested each pair before: this stage on octopus-low's first envelope 0.030-0.033 -> 0.024-0.026
  // s, session 57); both triangles flagged
  long long conflicts = 0;
  {
    TriangleIndex index;
    index.build(surface);
    tbb::enumerable_thread_specific<std::vector<int>> partners;
    conflicts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nf, 256), 0LL,
      [&](const tbb::blocked_range<std::size_t>& r, long long count) {
        if (progressCancelled(progress))
          return count;
        std::vector<int>& mine = partners.local();
        for (std::size_t f = r.begin(); f != r.end(); ++f)
        {
          if (knownBound[f] >= 0.0)
            continue;
          forEachConflict(
            surface, index, f, touching, [&](int g) { return knownBound[g] >= 0.0 || static_cast<std::size_t>(g) > f; },
            [&](int g) {
              defective[f] = 1; // each new triangle writes only its own flag here, its partner's after
              mine.push_back(g);
              ++count;
            });
        }
        return count;
      },
      [](long long a, long long b) { return a + b; });
    for (const auto& list : partners)
      for (int g : list)
        defective[g] = 1;
  }
  if (progressCancelled(progress))
  {
    why = "cancelled";
    return false;
  }
  progressUpdate(progress, 0.3);

  // 2. point distances (reused by position), then per new triangle the Lipschitz bound from its
  // corners and, below the clearance, the exact test up to it (as verifyEnclosure certifies)
  std::vector<double> dist(nv, -1.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    if (progressCancelled(progress))
      return;
    for (std::size_t i = r.begin(); i != r.end(); ++i)
    {
      if (known)
      {
        const auto it = known->Distance.find(positionKey(surface.Points[i]));
        if (it != known->Distance.end())
        {
          dist[i] = it->second;
          continue;
        }
      }
      dist[i] = inputTree.distance(surface.Points[i]);
    }
  });
  if (progressCancelled(progress))
  {
    why = "cancelled";
    return false;
  }
  progressUpdate(progress, 0.6);
  std::vector<double> bound(nf, 0.0);
  // Triangles the caller knows clear skip the exact test (VerificationTime, median of 5:
  // octopus-low 0.059 -> 0.050 s, armadillo 0.067 -> 0.055 s, decimated-knight 0.067 -> 0.056 s)
  const std::size_t clearBelow = clear && clear->Distance >= clearance ? clear->Below : 0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 64), [&](const tbb::blocked_range<std::size_t>& r) {
    if (progressCancelled(progress))
      return;
    for (std::size_t f = r.begin(); f != r.end(); ++f)
    {
      if (knownBound[f] >= 0.0)
      {
        bound[f] = knownBound[f];
        continue;
      }
      const Triangle& t = surface.Triangles[f];
      const double lower = cornerBound(surface, t, dist);
      if (lower >= clearance)
      {
        bound[f] = lower;
        continue;
      }
      if (clearBelow > static_cast<std::size_t>(std::max({ t[0], t[1], t[2] })))
      {
        bound[f] = std::max(lower, clearance); // what the exact test below would give
        continue;
      }
      const Vec3 tri[3] = { surface.Points[t[0]], surface.Points[t[1]], surface.Points[t[2]] };
      const double dd = inputTree.triangleDistance(tri, clearance);
      if (dd < clearance)
      {
        bound[f] = dd;
        defective[f] = 1;
      }
      else
        bound[f] = std::max(lower, clearance);
    }
  });
  if (progressCancelled(progress))
  {
    why = "cancelled";
    return false;
  }
  progressUpdate(progress, 0.9);
  double lowest = std::numeric_limits<double>::infinity();
  for (double v : dist)
    lowest = std::min(lowest, v);
  for (double v : bound)
    lowest = std::min(lowest, v);

  // the verdict, in verifyEnclosure's order
  bool ok = true;
  if (!manifoldWhy.empty())
  {
    why = manifoldWhy;
    ok = false;
  }
  else if (conflicts > 0)
  {
    why = "the surface intersects itself (" + std::to_string(conflicts) + " triangle pairs)";
    ok = false;
  }
  else if (!(lowest >= clearance))
  {
    std::ostringstream s;
    s << "the surface comes within " << lowest << " of the input (required clearance " << clearance << ")";
    why = s.str();
    ok = false;
  }
  else
  {
    ok = componentsInside(input, surface, why, progress);
  }
  measuredClearance = ok || conflicts == 0 ? lowest : 0.0;
  if (ok)
  {
    memo.Known.reset(); // a sound surface ends the sequence
  }
  else
  {
    // what the next surface may reuse: this one's sound triangles and its point distances
    auto next = std::make_shared<VerificationMemo::Store>();
    next->Input = &input;
    next->Clearance = clearance;
    next->Touching = touching;
    next->Sound.reserve(nf);
    for (std::size_t f = 0; f < nf; ++f)
      if (!defective[f])
        next->Sound.emplace(keys[f], bound[f]);
    next->Distance.reserve(nv);
    for (std::size_t i = 0; i < nv; ++i)
      next->Distance.emplace(positionKey(surface.Points[i]), dist[i]);
    memo.Known = std::move(next);
  }
  if (pointDistances && (ok || conflicts == 0))
    *pointDistances = std::move(dist);
  return ok;
}

} // namespace sdfcage
