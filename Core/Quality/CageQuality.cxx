#include "Quality/CageQuality.h"

#include "Quality/Verification.h"

#include "Envelope/Envelope.h"
#include "Spatial/Geometry.h"
#include "Common/Progress.h"
#include "Spatial/TriangleIndex.h"
#include "Spatial/TriangleTree.h"
#include "Mesh/Validation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>

namespace sdfcage
{

namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Copies the triangles with valid ids and finite points; `kept[i]` is the original index of
/// triangle i of `clean`. Points are copied as they are (unreferenced ones included).
long long sanitize(const TriangleMesh& mesh, TriangleMesh& clean, std::vector<int>& kept)
{
  clean.Points = mesh.Points;
  clean.Triangles.clear();
  kept.clear();
  const long long np = static_cast<long long>(mesh.Points.size());
  long long invalid = 0;
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    bool ok = true;
    for (int k = 0; k < 3 && ok; ++k)
    {
      ok = t[k] >= 0 && t[k] < np && mesh.Points[t[k]].allFinite();
    }
    if (!ok)
    {
      ++invalid;
      continue;
    }
    clean.Triangles.push_back(t);
    kept.push_back(static_cast<int>(f));
  }
  return invalid;
}

std::vector<char> referencedMask(const TriangleMesh& mesh)
{
  std::vector<char> used(mesh.Points.size(), 0);
  for (const Triangle& t : mesh.Triangles)
  {
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  return used;
}

/// Distance of every referenced point of `mesh` to the surface in `tree` (NaN for the others),
/// and the closest triangle of the tree's mesh (-1 for the others).
std::vector<double> pointDistances(const TriangleMesh& mesh, const std::vector<char>& used, const TriangleTree& tree,
  std::vector<int>& nearest)
{
  std::vector<double> d(mesh.Points.size(), kNaN);
  nearest.assign(mesh.Points.size(), -1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, d.size(), 512), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
    {
      if (used[i])
      {
        Vec3 q;
        tree.closestPoint(mesh.Points[i], -1.0, q, nearest[i], d[i]);
      }
    }
  });
  return d;
}

struct UnionFind
{
  std::vector<int> Parent;
  explicit UnionFind(std::size_t n)
    : Parent(n)
  {
    std::iota(Parent.begin(), Parent.end(), 0);
  }
  int find(int x)
  {
    while (Parent[x] != x)
    {
      Parent[x] = Parent[Parent[x]];
      x = Parent[x];
    }
    return x;
  }
  void unite(int a, int b)
  {
    a = find(a);
    b = find(b);
    if (a != b)
    {
      Parent[std::max(a, b)] = std::min(a, b);
    }
  }
};

// ---- Hausdorff distance by branch and bound ----------------------------------------------------
// Upper bounds of the distance d to the target surface over a piece (a triangle of the source
// surface or a part of one):
//  - Lipschitz: d is 1-Lipschitz, so d <= d(v_j) + (farthest corner from v_j), and
//    d <= d(c) + max_j |v_j - c| with c the centroid;
//  - convex: d <= dist(., T) for any target triangle T, and dist(., T) is convex, so its maximum
//    over the piece is at a corner: d <= max_j dist(v_j, T). With T the triangle closest to a
//    corner or to the centroid this is tight where the piece faces one target triangle (e.g.
//    parallel to it), where the Lipschitz bounds would need tiny pieces.
// Pieces whose bound could exceed the best value found (plus the tolerance) are refined,
// largest bound first: centroid first, then a split into four.
struct Piece
{
  Vec3 P[3];
  double D[3];
  int Near[3];
  double Upper;
  int Cell;
  bool Refined;
};

struct Target
{
  const TriangleTree& Tree;
  const TriangleMesh& Mesh;

  double convexBound(const Vec3 p[3], int triangle) const
  {
    if (triangle < 0)
    {
      return kInf;
    }
    const Triangle& t = Mesh.Triangles[triangle];
    const Vec3 &a = Mesh.Points[t[0]], &b = Mesh.Points[t[1]], &c = Mesh.Points[t[2]];
    double m = 0.0;
    for (int j = 0; j < 3; ++j)
    {
      m = std::max(m, (p[j] - closestPointOnTriangle(p[j], a, b, c)).norm());
    }
    return m;
  }
  /// Lipschitz bound from the corners and convex bounds from the corners' closest triangles.
  double bound(const Piece& piece) const
  {
    double u = kInf;
    for (int j = 0; j < 3; ++j)
    {
      const double far = std::max((piece.P[(j + 1) % 3] - piece.P[j]).norm(), (piece.P[(j + 2) % 3] - piece.P[j]).norm());
      u = std::min(u, piece.D[j] + far);
    }
    for (int j = 0; j < 3; ++j)
    {
      if (j == 0 || piece.Near[j] != piece.Near[j - 1])
      {
        u = std::min(u, this->convexBound(piece.P, piece.Near[j]));
      }
    }
    return u;
  }
  double closest(const Vec3& p, int& triangle) const
  {
    Vec3 q;
    double d = kInf;
    triangle = -1;
    Tree.closestPoint(p, -1.0, q, triangle, d);
    return d;
  }
};

struct PieceOrder
{
  bool operator()(const Piece& a, const Piece& b) const
  {
    if (a.Upper != b.Upper)
    {
      return a.Upper < b.Upper;
    }
    return a.Cell > b.Cell;
  }
};

struct HausdorffBounds
{
  double Value = 0.0;
  double Bound = 0.0;
};

HausdorffBounds hausdorff(const TriangleMesh& from, const std::vector<double>& vertexDistance,
  const std::vector<int>& vertexNear, const Target& to, double lowerStart, double tolerance, long long budget,
  std::vector<double>* cellMax, Progress* progress)
{
  double lower = lowerStart;
  for (const Triangle& t : from.Triangles)
  {
    for (int k = 0; k < 3; ++k)
    {
      lower = std::max(lower, vertexDistance[t[k]]);
    }
  }
  // initial pieces: every source triangle, bounded in parallel; only those that could beat the
  // best value found are kept
  const std::size_t nf = from.Triangles.size();
  auto makePiece = [&](std::size_t f) {
    const Triangle& t = from.Triangles[f];
    Piece piece;
    for (int k = 0; k < 3; ++k)
    {
      piece.P[k] = from.Points[t[k]];
      piece.D[k] = vertexDistance[t[k]];
      piece.Near[k] = vertexNear[t[k]];
    }
    piece.Cell = static_cast<int>(f);
    piece.Refined = false;
    piece.Upper = to.bound(piece);
    return piece;
  };
  std::vector<double> initialUpper(nf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f)
    {
      initialUpper[f] = makePiece(f).Upper;
    }
  });
  double discarded = lower; // largest bound of a piece dropped because it could not beat `lower`
  std::priority_queue<Piece, std::vector<Piece>, PieceOrder> heap;
  for (std::size_t f = 0; f < nf; ++f)
  {
    if (initialUpper[f] > lower + tolerance)
    {
      heap.push(makePiece(f));
    }
    else
    {
      discarded = std::max(discarded, initialUpper[f]);
    }
  }

  const std::size_t batchSize = 256;
  std::vector<Piece> batch;
  std::vector<std::vector<Piece>> children;
  std::vector<std::vector<double>> samples; // new point distances per batch entry
  while (!heap.empty() && heap.top().Upper > lower + tolerance && budget > 0)
  {
    if (progressCancelled(progress))
    {
      break;
    }
    batch.clear();
    while (!heap.empty() && batch.size() < batchSize && heap.top().Upper > lower + tolerance)
    {
      batch.push_back(heap.top());
      heap.pop();
    }
    children.assign(batch.size(), {});
    samples.assign(batch.size(), {});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, batch.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t b = r.begin(); b != r.end(); ++b)
      {
        const Piece& piece = batch[b];
        if (!piece.Refined)
        {
          const Vec3 c = (piece.P[0] + piece.P[1] + piece.P[2]) / 3.0;
          int nc = -1;
          const double dc = to.closest(c, nc);
          double reach = 0.0;
          for (const Vec3& p : piece.P)
          {
            reach = std::max(reach, (p - c).norm());
          }
          Piece refined = piece;
          refined.Upper = std::min({ piece.Upper, dc + reach, to.convexBound(piece.P, nc) });
          refined.Refined = true;
          children[b].push_back(refined);
          samples[b].push_back(dc);
          continue;
        }
        Vec3 m[3];
        double dm[3];
        int nm[3];
        for (int k = 0; k < 3; ++k)
        {
          m[k] = 0.5 * (piece.P[k] + piece.P[(k + 1) % 3]);
          dm[k] = to.closest(m[k], nm[k]);
          samples[b].push_back(dm[k]);
        }
        // corners: 0, m0, m2 | m0, 1, m1 | m2, m1, 2 | m0, m1, m2
        const Vec3* sub[4][3] = { { &piece.P[0], &m[0], &m[2] }, { &m[0], &piece.P[1], &m[1] },
          { &m[2], &m[1], &piece.P[2] }, { &m[0], &m[1], &m[2] } };
        const double subD[4][3] = { { piece.D[0], dm[0], dm[2] }, { dm[0], piece.D[1], dm[1] },
          { dm[2], dm[1], piece.D[2] }, { dm[0], dm[1], dm[2] } };
        const int subN[4][3] = { { piece.Near[0], nm[0], nm[2] }, { nm[0], piece.Near[1], nm[1] },
          { nm[2], nm[1], piece.Near[2] }, { nm[0], nm[1], nm[2] } };
        for (int s = 0; s < 4; ++s)
        {
          Piece child;
          for (int k = 0; k < 3; ++k)
          {
            child.P[k] = *sub[s][k];
            child.D[k] = subD[s][k];
            child.Near[k] = subN[s][k];
          }
          child.Cell = piece.Cell;
          child.Refined = false;
          child.Upper = std::min(piece.Upper, to.bound(child));
          children[b].push_back(child);
        }
      }
    });
    // merge in batch order (deterministic whatever the thread count)
    for (std::size_t b = 0; b < batch.size(); ++b)
    {
      budget -= static_cast<long long>(samples[b].size());
      for (double s : samples[b])
      {
        lower = std::max(lower, s);
        if (cellMax)
        {
          (*cellMax)[batch[b].Cell] = std::max((*cellMax)[batch[b].Cell], s);
        }
      }
    }
    for (std::size_t b = 0; b < batch.size(); ++b)
    {
      for (const Piece& child : children[b])
      {
        if (child.Upper > lower + tolerance)
        {
          heap.push(child);
        }
        else
        {
          discarded = std::max(discarded, child.Upper);
        }
      }
    }
  }
  HausdorffBounds h;
  h.Value = lower;
  h.Bound = std::max(lower, discarded);
  if (!heap.empty())
  {
    h.Bound = std::max(h.Bound, heap.top().Upper);
  }
  return h;
}
} // namespace

double triangleMinimumAngle(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const Vec3 p[3] = { a, b, c };
  double best = 180.0;
  for (int k = 0; k < 3; ++k)
  {
    const Vec3 u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
    const double s = u.cross(v).norm(), co = u.dot(v);
    if (!(s > 0.0))
    {
      return 0.0;
    }
    best = std::min(best, std::atan2(s, co) * 180.0 / M_PI);
  }
  return best;
}

double triangleMIPSEnergy(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const double area2 = (b - a).cross(c - a).norm(); // twice the area
  const double sum = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  if (!(area2 > 0.0))
  {
    return kInf;
  }
  // ||J||_F^2 / det J of the affine map from an equilateral triangle: (a^2+b^2+c^2) / (2 sqrt3 A)
  return sum / (std::sqrt(3.0) * area2);
}

CageQualityResult evaluateCage(const TriangleMesh& inputMesh, const TriangleMesh& cageMesh,
  const CageQualityOptions& options, Progress* progress)
{
  const auto start = std::chrono::steady_clock::now();
  CageQualityResult r;
  auto lapStart = start;
  auto lap = [&](int phase) {
    const auto now = std::chrono::steady_clock::now();
    r.PhaseSeconds[phase] += std::chrono::duration<double>(now - lapStart).count();
    lapStart = now;
  };
  std::vector<std::string> reasons;
  // the input's topology (closedness, genus) is needed only for the report: it runs beside
  // everything else and is waited for at the end
  tbb::task_group inputTopology;
  auto finish = [&]() {
    inputTopology.wait();
    std::string msg;
    for (const std::string& s : reasons)
    {
      msg += (msg.empty() ? "" : "; ") + s;
    }
    r.Message = msg;
    r.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  };
  auto cancelled = [&]() {
    if (progressCancelled(progress))
    {
      r.Encloses = false;
      reasons.assign(1, "cancelled");
      return true;
    }
    return false;
  };

  TriangleMesh input, cage;
  std::vector<int> inputKept, cageKept;
  r.InputInvalidTriangles = sanitize(inputMesh, input, inputKept);
  r.InvalidTriangles = sanitize(cageMesh, cage, cageKept);
  const std::size_t ncells = cageMesh.Triangles.size();
  r.PointDistance.assign(cageMesh.Points.size(), kNaN);
  r.CellDistance.assign(ncells, kNaN);
  r.CellMinimumAngle.assign(ncells, kNaN);
  r.CellMIPSEnergy.assign(ncells, kNaN);

  // --- shape of the cage triangles ---
  for (std::size_t i = 0; i < cage.Triangles.size(); ++i)
  {
    const Triangle& t = cage.Triangles[i];
    const Vec3 &a = cage.Points[t[0]], &b = cage.Points[t[1]], &c = cage.Points[t[2]];
    r.CellMinimumAngle[cageKept[i]] = triangleMinimumAngle(a, b, c);
    r.CellMIPSEnergy[cageKept[i]] = triangleMIPSEnergy(a, b, c);
  }

  // --- topology ---
  progressStage(progress, "topology", 0.0, 0.1);
  const std::vector<char> inputUsed = referencedMask(input);
  r.InputVertices = std::count(inputUsed.begin(), inputUsed.end(), 1);
  // the input's topology and the two search trees are independent: build them concurrently
  TriangleTree inputTree, cageTree;
  MeshDefects dc;
  if (!input.empty())
  {
    inputTopology.run([&]() {
      const MeshDefects di = checkTriangleMesh(input);
      r.InputClosedManifold = di.BoundaryEdges == 0 && di.NonManifoldEdges == 0 && di.NonManifoldVertices == 0;
      r.InputGenus = !r.InputClosedManifold ? -1 : di.usable() ? di.Genus : genus(input);
    });
  }
  tbb::parallel_invoke(
    [&]() {
      if (!input.empty() && !cage.empty())
      {
        inputTree.build(input);
      }
    },
    [&]() {
      if (!cage.empty())
      {
        dc = checkTriangleMesh(cage);
        cageTree.build(cage);
      }
    });
  if (!cage.empty())
  {
    r.BoundaryEdges = dc.BoundaryEdges;
    r.NonManifoldEdges = dc.NonManifoldEdges;
    r.NonManifoldVertices = dc.NonManifoldVertices;
    r.DegenerateTriangles = dc.DegenerateTriangles;
    r.InconsistentEdges = dc.InconsistentEdges;
    r.CageComponents = dc.Components;
    r.CageClosedManifold = dc.BoundaryEdges == 0 && dc.NonManifoldEdges == 0 && dc.NonManifoldVertices == 0;
    r.CageGenus = !r.CageClosedManifold ? -1 : dc.usable() ? dc.Genus : genus(cage);
    r.CageInwardOriented = r.CageClosedManifold && r.InconsistentEdges == 0 && signedVolume(cage) < 0;
  }

  // the scale: the input's bounding box, or the cage's when there is no input
  const TriangleMesh& scaleMesh = input.empty() ? cage : input;
  if (!scaleMesh.empty())
  {
    const auto box = bounds(scaleMesh);
    r.Diagonal = (box[1] - box[0]).norm();
  }
  double scale = r.Diagonal;
  if (!cage.empty())
  {
    const auto box = bounds(cage);
    scale = std::max(scale, (box[1] - box[0]).norm());
  }
  const double touching = options.TouchingTolerance * scale;

  if (cage.empty())
  {
    reasons.push_back(cageMesh.Triangles.empty() ? "the cage has no triangles" : "the cage has no valid triangles");
  }
  if (input.empty())
  {
    reasons.push_back(inputMesh.Triangles.empty() ? "the input mesh has no triangles" : "the input mesh has no valid triangles");
  }
  if (r.InvalidTriangles > 0)
  {
    reasons.push_back("the cage has " + std::to_string(r.InvalidTriangles) + " triangles with invalid point ids or non-finite points");
  }
  if (!cage.empty() && !r.CageClosedManifold)
  {
    reasons.push_back("the cage is not a closed 2-manifold (" + std::to_string(r.BoundaryEdges) + " boundary edges, " +
      std::to_string(r.NonManifoldEdges) + " non-manifold edges, " + std::to_string(r.NonManifoldVertices) +
      " non-manifold vertices)");
  }
  if (r.InconsistentEdges > 0)
  {
    reasons.push_back("the cage is inconsistently oriented (" + std::to_string(r.InconsistentEdges) + " edges)");
  }
  if (r.DegenerateTriangles > 0)
  {
    reasons.push_back("the cage has " + std::to_string(r.DegenerateTriangles) + " degenerate triangles");
  }
  const bool insideDefined = !cage.empty() && r.InvalidTriangles == 0 && r.CageClosedManifold &&
    r.InconsistentEdges == 0 && r.DegenerateTriangles == 0;
  if (cancelled())
  {
    return finish();
  }

  lap(0);
  // --- self-intersections (degenerate triangles count once each, as CGAL reports them) ---
  progressStage(progress, "self-intersections", 0.1, 0.2);
  if (!cage.empty())
  {
    r.SelfIntersections = countSelfIntersections(cage, progress, touching) + r.DegenerateTriangles;
    if (r.SelfIntersections > 0)
    {
      reasons.push_back("the cage intersects itself (" + std::to_string(r.SelfIntersections) + " triangle pairs)");
    }
  }
  if (cage.empty() || input.empty())
  {
    r.InputVerticesOutside = r.InputVertices;
    r.Encloses = false;
    return finish();
  }
  if (cancelled())
  {
    return finish();
  }

  lap(1);
  // --- point distances both ways ---
  progressStage(progress, "distances", 0.2, 0.4);
  const std::vector<char> cageUsed = referencedMask(cage);
  std::vector<int> cageNear, inputNear;
  const std::vector<double> cageDistance = pointDistances(cage, cageUsed, inputTree, cageNear);
  const std::vector<double> inputDistance = pointDistances(input, inputUsed, cageTree, inputNear);
  // every finite cage point gets its distance (unreferenced ones too: they are displayed)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cageMesh.Points.size(), 512), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t i = rg.begin(); i != rg.end(); ++i)
    {
      if (cageUsed[i])
      {
        r.PointDistance[i] = cageDistance[i];
      }
      else if (cageMesh.Points[i].allFinite())
      {
        r.PointDistance[i] = inputTree.distance(cageMesh.Points[i]);
      }
    }
  });
  double upper = kInf, sum = 0.0;
  long long counted = 0;
  for (std::size_t i = 0; i < cageDistance.size(); ++i)
  {
    if (cageUsed[i])
    {
      upper = std::min(upper, cageDistance[i]);
      r.MaximumPointDistance = std::max(r.MaximumPointDistance, cageDistance[i]);
      sum += cageDistance[i];
      ++counted;
    }
  }
  r.MeanPointDistance = counted ? sum / static_cast<double>(counted) : 0.0;
  for (std::size_t i = 0; i < inputDistance.size(); ++i)
  {
    if (inputUsed[i])
    {
      upper = std::min(upper, inputDistance[i]);
    }
  }
  if (cancelled())
  {
    return finish();
  }

  lap(2);
  // --- exact minimum clearance: cage triangles in increasing order of a Lipschitz lower bound,
  // each measured exactly against the input only below the best value so far ---
  progressStage(progress, "clearance", 0.4, 0.6);
  const std::size_t nf = cage.Triangles.size();
  std::vector<double> lowerBound(nf);
  std::vector<int> order(nf);
  for (std::size_t f = 0; f < nf; ++f)
  {
    const Triangle& t = cage.Triangles[f];
    double lb = -kInf;
    for (int i = 0; i < 3; ++i)
    {
      const Vec3& p = cage.Points[t[i]];
      const double reach = std::max((cage.Points[t[(i + 1) % 3]] - p).norm(), (cage.Points[t[(i + 2) % 3]] - p).norm());
      lb = std::max(lb, cageDistance[t[i]] - reach);
    }
    lowerBound[f] = lb;
    order[f] = static_cast<int>(f);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return lowerBound[a] < lowerBound[b] || (lowerBound[a] == lowerBound[b] && a < b); });
  std::atomic<double> best{ upper };
  const std::size_t chunk = 256;
  for (std::size_t b = 0; b < nf; b += chunk)
  {
    if (lowerBound[order[b]] >= best.load() || cancelled())
    {
      break;
    }
    const std::size_t e = std::min(nf, b + chunk);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(b, e, 4), [&](const tbb::blocked_range<std::size_t>& rg) {
      for (std::size_t k = rg.begin(); k != rg.end(); ++k)
      {
        const int f = order[k];
        double current = best.load();
        if (lowerBound[f] >= current)
        {
          continue;
        }
        const Triangle& t = cage.Triangles[f];
        const Vec3 tri[3] = { cage.Points[t[0]], cage.Points[t[1]], cage.Points[t[2]] };
        const double d = inputTree.triangleDistance(tri, current);
        while (d < current && !best.compare_exchange_weak(current, d))
        {
        }
      }
    });
  }
  if (cancelled())
  {
    return finish();
  }
  r.MinimumClearance = best.load() <= touching ? 0.0 : best.load();
  if (r.MinimumClearance == 0.0)
  {
    // count the intersecting or touching pairs (only triangles that can reach the input)
    r.InputIntersections = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nf, 16), 0LL,
      [&](const tbb::blocked_range<std::size_t>& rg, long long count) {
        for (std::size_t f = rg.begin(); f != rg.end(); ++f)
        {
          if (lowerBound[f] > touching)
          {
            continue;
          }
          const Triangle& t = cage.Triangles[f];
          const Vec3 tri[3] = { cage.Points[t[0]], cage.Points[t[1]], cage.Points[t[2]] };
          count += inputTree.countWithin(tri, touching);
        }
        return count;
      },
      [](long long a, long long b) { return a + b; });
    reasons.push_back("the cage intersects or touches the input (" + std::to_string(r.InputIntersections) +
      " cage/input triangle pairs)");
  }

  lap(3);
  // --- input vertices inside: the winding number is constant along every input edge that cannot
  // reach the cage (d(u) + d(v) > |u - v|, the distance being 1-Lipschitz), so it is evaluated
  // once per group of vertices connected by such edges, at the vertex farthest from the cage ---
  progressStage(progress, "inside test", 0.6, 0.7);
  if (!insideDefined)
  {
    r.InputVerticesOutside = r.InputVertices;
    reasons.push_back("inside/outside is undefined for this cage: all " + std::to_string(r.InputVertices) +
      " input vertices count as outside");
  }
  else
  {
    UnionFind groups(input.Points.size());
    for (const Triangle& t : input.Triangles)
    {
      for (int k = 0; k < 3; ++k)
      {
        const int u = t[k], v = t[(k + 1) % 3];
        if (inputDistance[u] > touching && inputDistance[v] > touching &&
          inputDistance[u] + inputDistance[v] > (input.Points[u] - input.Points[v]).norm())
        {
          groups.unite(u, v);
        }
      }
    }
    std::vector<int> representative(input.Points.size(), -1);
    std::vector<int> roots;
    for (std::size_t i = 0; i < input.Points.size(); ++i)
    {
      if (!inputUsed[i])
      {
        continue;
      }
      const int g = groups.find(static_cast<int>(i));
      if (representative[g] < 0)
      {
        roots.push_back(g);
        representative[g] = static_cast<int>(i);
      }
      else if (inputDistance[i] > inputDistance[representative[g]])
      {
        representative[g] = static_cast<int>(i);
      }
    }
    std::vector<char> inside(input.Points.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, roots.size(), 1), [&](const tbb::blocked_range<std::size_t>& rg) {
      for (std::size_t k = rg.begin(); k != rg.end(); ++k)
      {
        const int rep = representative[roots[k]];
        if (inputDistance[rep] <= touching)
        {
          continue; // on the cage: not strictly inside
        }
        const long long w = std::llround(std::abs(windingNumber(cage, input.Points[rep])));
        inside[roots[k]] = (w % 2) == 1;
      }
    });
    for (std::size_t i = 0; i < input.Points.size(); ++i)
    {
      if (inputUsed[i] && !(inside[groups.find(static_cast<int>(i))] && inputDistance[i] > touching))
      {
        ++r.InputVerticesOutside;
      }
    }
    if (r.InputVerticesOutside > 0)
    {
      reasons.push_back(std::to_string(r.InputVerticesOutside) + " of " + std::to_string(r.InputVertices) +
        " input vertices are not strictly inside the cage");
    }
  }
  if (cancelled())
  {
    return finish();
  }

  lap(4);
  // --- mean distance over the cage (midpoint rule on 4^level sub-triangles per triangle, the level
  // chosen per triangle from its size) ---
  progressStage(progress, "mean distance", 0.7, 0.8);
  const double spacing = std::max(options.MeanDistanceSpacing, 1e-6) * r.Diagonal;
  const int minimumLevel = std::clamp(options.MinimumMeanDistanceLevel, 0, 6);
  std::vector<double> cellArea(nf), cellMean(nf), cellMax(nf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 4), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t f = rg.begin(); f != rg.end(); ++f)
    {
      const Triangle& t = cage.Triangles[f];
      const Vec3 &a = cage.Points[t[0]], &b = cage.Points[t[1]], &c = cage.Points[t[2]];
      const double edge = std::max({ (b - a).norm(), (c - b).norm(), (a - c).norm() });
      int level = minimumLevel;
      while (level < 6 && edge > spacing * static_cast<double>(1 << level))
      {
        ++level;
      }
      const int n = 1 << level;
      double m = std::max({ cageDistance[t[0]], cageDistance[t[1]], cageDistance[t[2]] });
      double s = 0.0;
      auto at = [&](double u, double v) {
        const double d = inputTree.distance(a + (b - a) * (u / n) + (c - a) * (v / n));
        m = std::max(m, d);
        s += d;
      };
      for (int i = 0; i < n; ++i)
      {
        for (int j = 0; i + j < n; ++j)
        {
          at(i + 1.0 / 3.0, j + 1.0 / 3.0);
          if (i + j < n - 1)
          {
            at(i + 2.0 / 3.0, j + 2.0 / 3.0);
          }
        }
      }
      cellArea[f] = 0.5 * (b - a).cross(c - a).norm();
      cellMean[f] = s / static_cast<double>(n * n);
      cellMax[f] = m;
    }
  });
  double area = 0.0, weighted = 0.0, sampledMax = 0.0;
  for (std::size_t f = 0; f < nf; ++f)
  {
    area += cellArea[f];
    weighted += cellArea[f] * cellMean[f];
    sampledMax = std::max(sampledMax, cellMax[f]);
  }
  r.MeanDistanceCageToInput = area > 0 ? weighted / area : r.MeanPointDistance;
  if (cancelled())
  {
    return finish();
  }

  lap(5);
  // --- Hausdorff distances (branch and bound) ---
  progressStage(progress, "Hausdorff cage to input", 0.8, 0.9);
  const double tol = options.HausdorffTolerance * r.Diagonal;
  const HausdorffBounds hc = hausdorff(cage, cageDistance, cageNear, Target{ inputTree, input }, sampledMax, tol, options.HausdorffBudget, &cellMax, progress);
  r.HausdorffCageToInput = hc.Value;
  r.HausdorffCageToInputBound = hc.Bound;
  for (std::size_t f = 0; f < nf; ++f)
  {
    r.CellDistance[cageKept[f]] = cellMax[f];
  }
  progressStage(progress, "Hausdorff input to cage", 0.9, 1.0);
  const HausdorffBounds hi = hausdorff(input, inputDistance, inputNear, Target{ cageTree, cage }, 0.0, tol, options.HausdorffBudget, nullptr, progress);
  r.HausdorffInputToCage = hi.Value;
  r.HausdorffInputToCageBound = hi.Bound;
  if (cancelled())
  {
    return finish();
  }

  lap(6);
  r.Encloses = reasons.empty() && r.SelfIntersections == 0 && r.InputIntersections == 0 && r.InputVerticesOutside == 0 &&
    r.MinimumClearance > 0.0;
  return finish();
}

} // namespace sdfcage
