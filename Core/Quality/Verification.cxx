#include "Quality/Verification.h"

#include "Common/Progress.h"
#include "Mesh/Validation.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleIndex.h"
#include "Spatial/TriangleTree.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>
#include <sstream>

namespace sdfcage
{

long long countSelfIntersections(const TriangleMesh& mesh, Progress* progress, double touching)
{
  TriangleIndex index;
  index.build(mesh);
  // exact-intersection fold test for edge-sharing pairs: only exactly opposite normals overlap
  const double foldCosine = -1.0 + 1e-12;
  if (!(touching >= 0.0))
  {
    // disjoint triangles closer than this (relative to the mesh size) count as touching
    const auto box = bounds(mesh);
    touching = 1e-12 * std::max(1.0, (box[1] - box[0]).norm());
  }
  const Vec3 pad = Vec3::Constant(touching);
  return tbb::parallel_reduce(
    tbb::blocked_range<std::size_t>(0, mesh.Triangles.size(), 256), 0LL,
    [&](const tbb::blocked_range<std::size_t>& r, long long count) {
      if (progressCancelled(progress))
      {
        return count;
      }
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = mesh.Triangles[f];
        const int ia[3] = { t[0], t[1], t[2] };
        const Vec3 pa[3] = { mesh.Points[t[0]], mesh.Points[t[1]], mesh.Points[t[2]] };
        const Vec3 lo = pa[0].cwiseMin(pa[1]).cwiseMin(pa[2]) - pad;
        const Vec3 hi = pa[0].cwiseMax(pa[1]).cwiseMax(pa[2]) + pad;
        index.forEachTriangleInBox(lo, hi, [&](int g) {
          if (static_cast<std::size_t>(g) <= f)
          {
            return;
          }
          const Triangle& o = mesh.Triangles[g];
          const int ib[3] = { o[0], o[1], o[2] };
          const Vec3 pb[3] = { mesh.Points[o[0]], mesh.Points[o[1]], mesh.Points[o[2]] };
          count += trianglesConflict(ia, pa, ib, pb, touching, foldCosine) ? 1 : 0;
        });
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
    const Triangle& t = cage.Triangles[f];
    double lower = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i)
    {
      const Vec3& p = cage.Points[t[i]];
      const double reach = std::max((cage.Points[t[(i + 1) % 3]] - p).norm(), (cage.Points[t[(i + 2) % 3]] - p).norm());
      lower = std::max(lower, dist[t[i]] - reach);
    }
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
  // inside or entirely outside; test one vertex per component by winding number.
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

} // namespace sdfcage
