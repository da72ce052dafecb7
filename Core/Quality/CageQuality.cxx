#include "Quality/CageQuality.h"

#include "Quality/LocalChangeVeto.h"
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
std::vector<double> pointDistances(
  const TriangleMesh& mesh, const std::vector<char>& used, const TriangleTree& tree, std::vector<int>& nearest)
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
      const double far =
        std::max((piece.P[(j + 1) % 3] - piece.P[j]).norm(), (piece.P[(j + 2) % 3] - piece.P[j]).norm());
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
    tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, batch.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
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
  return mipsEnergy(a, b, c); // the optimizer's energy, one formula
}

namespace
{
/// One evaluation by evaluateCage(): the meshes, what the phases hand on to each other and the
/// result being filled. The phases run in the order of run(), each timed under its name
/// (CageQualityPhase); any of them may end the evaluation early.
class CageEvaluation
{
public:
  CageEvaluation(
    const TriangleMesh& inputMesh, const TriangleMesh& cageMesh, const CageQualityOptions& options, Progress* progress)
    : InputMesh(inputMesh)
    , CageMesh(cageMesh)
    , Options(options)
    , Report(progress)
  {
  }

  CageQualityResult run()
  {
    this->Start = std::chrono::steady_clock::now();
    // every phase returns false when the evaluation ends after it; a cancel ends it after any
    const std::pair<CageQualityPhase, bool (CageEvaluation::*)()> phases[] = {
      { CageQualityPhase::Topology, &CageEvaluation::checkTopologyAndShape },
      { CageQualityPhase::SelfIntersections, &CageEvaluation::countSelfIntersectingPairs },
      { CageQualityPhase::PointDistances, &CageEvaluation::measurePointDistances },
      { CageQualityPhase::Clearance, &CageEvaluation::measureClearance },
      { CageQualityPhase::InsideTest, &CageEvaluation::countInputVerticesOutside },
      { CageQualityPhase::MeanDistance, &CageEvaluation::measureMeanDistance },
      { CageQualityPhase::Hausdorff, &CageEvaluation::measureHausdorffDistances },
    };
    for (const auto& [phase, measure] : phases)
    {
      const auto begin = std::chrono::steady_clock::now();
      const bool more = (this->*measure)();
      this->R.PhaseSeconds[static_cast<int>(phase)] +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
      if (!more || this->cancelled())
      {
        return this->finish();
      }
    }
    this->R.Encloses = this->Reasons.empty() && this->R.SelfIntersections == 0 && this->R.InputIntersections == 0 &&
      this->R.InputVerticesOutside == 0 && this->R.MinimumClearance > 0.0;
    return this->finish();
  }

private:
  /// Valid triangles of both meshes; the shape of every cage triangle; the defects, genus and
  /// orientation of the cage (the input's topology runs beside all later phases); the two search
  /// trees; the scale of the touching tolerance; the defects that rule out enclosure.
  bool checkTopologyAndShape()
  {
    CageQualityResult& r = this->R;
    r.InputInvalidTriangles = sanitize(this->InputMesh, this->Input, this->InputKept);
    r.InvalidTriangles = sanitize(this->CageMesh, this->Cage, this->CageKept);
    const std::size_t ncells = this->CageMesh.Triangles.size();
    r.PointDistance.assign(this->CageMesh.Points.size(), kNaN);
    r.CellDistance.assign(ncells, kNaN);
    r.CellMinimumAngle.assign(ncells, kNaN);
    r.CellMIPSEnergy.assign(ncells, kNaN);
    const TriangleMesh &input = this->Input, &cage = this->Cage;

    for (std::size_t i = 0; i < cage.Triangles.size(); ++i)
    {
      const Triangle& t = cage.Triangles[i];
      const Vec3 &a = cage.Points[t[0]], &b = cage.Points[t[1]], &c = cage.Points[t[2]];
      r.CellMinimumAngle[this->CageKept[i]] = triangleMinimumAngle(a, b, c);
      r.CellMIPSEnergy[this->CageKept[i]] = triangleMIPSEnergy(a, b, c);
    }

    progressStage(this->Report, "topology", 0.0, 0.1);
    this->InputUsed = referencedMask(input);
    r.InputVertices = std::count(this->InputUsed.begin(), this->InputUsed.end(), 1);
    // the input's topology and the two search trees are independent: build them concurrently
    MeshDefects dc;
    if (!input.empty())
    {
      this->InputTopology.run([this]() {
        const MeshDefects di = checkTriangleMesh(this->Input);
        this->R.InputClosedManifold = di.BoundaryEdges == 0 && di.NonManifoldEdges == 0 && di.NonManifoldVertices == 0;
        this->R.InputGenus = !this->R.InputClosedManifold ? -1 : di.usable() ? di.Genus : genus(this->Input);
      });
    }
    tbb::parallel_invoke(
      [&]() {
        if (!input.empty() && !cage.empty())
        {
          this->InputTree.build(input);
        }
      },
      [&]() {
        if (!cage.empty())
        {
          dc = checkTriangleMesh(cage);
          this->CageTree.build(cage);
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
    this->Touching = this->Options.TouchingTolerance * scale;

    std::vector<std::string>& reasons = this->Reasons;
    if (cage.empty())
    {
      reasons.push_back(
        this->CageMesh.Triangles.empty() ? "the cage has no triangles" : "the cage has no valid triangles");
    }
    if (input.empty())
    {
      reasons.push_back(this->InputMesh.Triangles.empty() ? "the input mesh has no triangles"
                                                          : "the input mesh has no valid triangles");
    }
    if (r.InvalidTriangles > 0)
    {
      reasons.push_back("the cage has " + std::to_string(r.InvalidTriangles) +
        " triangles with invalid point ids or non-finite points");
    }
    if (!cage.empty() && !r.CageClosedManifold)
    {
      reasons.push_back("the cage is not a closed 2-manifold (" + std::to_string(r.BoundaryEdges) +
        " boundary edges, " + std::to_string(r.NonManifoldEdges) + " non-manifold edges, " +
        std::to_string(r.NonManifoldVertices) + " non-manifold vertices)");
    }
    if (r.InconsistentEdges > 0)
    {
      reasons.push_back("the cage is inconsistently oriented (" + std::to_string(r.InconsistentEdges) + " edges)");
    }
    if (r.DegenerateTriangles > 0)
    {
      reasons.push_back("the cage has " + std::to_string(r.DegenerateTriangles) + " degenerate triangles");
    }
    this->InsideDefined = !cage.empty() && r.InvalidTriangles == 0 && r.CageClosedManifold &&
      r.InconsistentEdges == 0 && r.DegenerateTriangles == 0;
    return true;
  }

  /// Intersecting or touching pairs of non-adjacent cage triangles (degenerate triangles count
  /// once each, as CGAL reports them). Ends the evaluation when either mesh is empty.
  bool countSelfIntersectingPairs()
  {
    CageQualityResult& r = this->R;
    progressStage(this->Report, "self-intersections", 0.1, 0.2);
    if (!this->Cage.empty())
    {
      r.SelfIntersections = countSelfIntersections(this->Cage, this->Report, this->Touching) + r.DegenerateTriangles;
      if (r.SelfIntersections > 0)
      {
        this->Reasons.push_back(
          "the cage intersects itself (" + std::to_string(r.SelfIntersections) + " triangle pairs)");
      }
    }
    if (this->Cage.empty() || this->Input.empty())
    {
      r.InputVerticesOutside = r.InputVertices;
      r.Encloses = false;
      return false;
    }
    return true;
  }

  /// Exact distance of every cage point to the input and of every input point to the cage (with
  /// the closest triangles, for the Hausdorff bounds); their smallest value bounds the clearance.
  bool measurePointDistances()
  {
    CageQualityResult& r = this->R;
    progressStage(this->Report, "distances", 0.2, 0.4);
    this->CageUsed = referencedMask(this->Cage);
    this->CageDistance = pointDistances(this->Cage, this->CageUsed, this->InputTree, this->CageNear);
    this->InputDistance = pointDistances(this->Input, this->InputUsed, this->CageTree, this->InputNear);
    // every finite cage point gets its distance (unreferenced ones too: they are displayed)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, this->CageMesh.Points.size(), 512),
      [&](const tbb::blocked_range<std::size_t>& rg) {
        for (std::size_t i = rg.begin(); i != rg.end(); ++i)
        {
          if (this->CageUsed[i])
          {
            r.PointDistance[i] = this->CageDistance[i];
          }
          else if (this->CageMesh.Points[i].allFinite())
          {
            r.PointDistance[i] = this->InputTree.distance(this->CageMesh.Points[i]);
          }
        }
      });
    double upper = kInf, sum = 0.0;
    long long counted = 0;
    for (std::size_t i = 0; i < this->CageDistance.size(); ++i)
    {
      if (this->CageUsed[i])
      {
        upper = std::min(upper, this->CageDistance[i]);
        r.MaximumPointDistance = std::max(r.MaximumPointDistance, this->CageDistance[i]);
        sum += this->CageDistance[i];
        ++counted;
      }
    }
    r.MeanPointDistance = counted ? sum / static_cast<double>(counted) : 0.0;
    for (std::size_t i = 0; i < this->InputDistance.size(); ++i)
    {
      if (this->InputUsed[i])
      {
        upper = std::min(upper, this->InputDistance[i]);
      }
    }
    this->ClearanceUpperBound = upper;
    return true;
  }

  /// Exact minimum clearance: cage triangles in increasing order of a Lipschitz lower bound, each
  /// measured exactly against the input only below the best value so far; when the surfaces
  /// touch, the intersecting or touching cage/input pairs are counted.
  bool measureClearance()
  {
    CageQualityResult& r = this->R;
    const TriangleMesh& cage = this->Cage;
    const TriangleTree& inputTree = this->InputTree;
    progressStage(this->Report, "clearance", 0.4, 0.6);
    const std::size_t nf = cage.Triangles.size();
    std::vector<double>& lowerBound = this->CellLowerBound;
    lowerBound.resize(nf);
    std::vector<int> order(nf);
    for (std::size_t f = 0; f < nf; ++f)
    {
      const Triangle& t = cage.Triangles[f];
      double lb = -kInf;
      for (int i = 0; i < 3; ++i)
      {
        const Vec3& p = cage.Points[t[i]];
        const double reach =
          std::max((cage.Points[t[(i + 1) % 3]] - p).norm(), (cage.Points[t[(i + 2) % 3]] - p).norm());
        lb = std::max(lb, this->CageDistance[t[i]] - reach);
      }
      lowerBound[f] = lb;
      order[f] = static_cast<int>(f);
    }
    std::sort(order.begin(), order.end(),
      [&](int a, int b) { return lowerBound[a] < lowerBound[b] || (lowerBound[a] == lowerBound[b] && a < b); });
    std::atomic<double> best{ this->ClearanceUpperBound };
    const std::size_t chunk = 256;
    for (std::size_t b = 0; b < nf; b += chunk)
    {
      if (lowerBound[order[b]] >= best.load() || this->cancelled())
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
    if (this->cancelled())
    {
      return false;
    }
    const double touching = this->Touching;
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
      this->Reasons.push_back("the cage intersects or touches the input (" + std::to_string(r.InputIntersections) +
        " cage/input triangle pairs)");
    }
    return true;
  }

  /// Input vertices not strictly inside the cage. The winding number is constant along every
  /// input edge that cannot reach the cage (d(u) + d(v) > |u - v|, the distance being
  /// 1-Lipschitz), so it is evaluated once per group of vertices connected by such edges, at the
  /// vertex farthest from the cage.
  bool countInputVerticesOutside()
  {
    CageQualityResult& r = this->R;
    const TriangleMesh& input = this->Input;
    const std::vector<double>& inputDistance = this->InputDistance;
    const double touching = this->Touching;
    progressStage(this->Report, "inside test", 0.6, 0.7);
    if (!this->InsideDefined)
    {
      r.InputVerticesOutside = r.InputVertices;
      this->Reasons.push_back("inside/outside is undefined for this cage: all " + std::to_string(r.InputVertices) +
        " input vertices count as outside");
      return true;
    }
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
      if (!this->InputUsed[i])
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
    tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, roots.size(), 1), [&](const tbb::blocked_range<std::size_t>& rg) {
        for (std::size_t k = rg.begin(); k != rg.end(); ++k)
        {
          const int rep = representative[roots[k]];
          if (inputDistance[rep] <= touching)
          {
            continue; // on the cage: not strictly inside
          }
          const long long w = std::llround(std::abs(windingNumber(this->Cage, input.Points[rep])));
          inside[roots[k]] = (w % 2) == 1;
        }
      });
    for (std::size_t i = 0; i < input.Points.size(); ++i)
    {
      if (this->InputUsed[i] && !(inside[groups.find(static_cast<int>(i))] && inputDistance[i] > touching))
      {
        ++r.InputVerticesOutside;
      }
    }
    if (r.InputVerticesOutside > 0)
    {
      this->Reasons.push_back(std::to_string(r.InputVerticesOutside) + " of " + std::to_string(r.InputVertices) +
        " input vertices are not strictly inside the cage");
    }
    return true;
  }

  /// Area-weighted mean distance over the cage (midpoint rule on 4^level sub-triangles per
  /// triangle, the level chosen per triangle from its size); the largest sample of each triangle
  /// starts its CellDistance and the Hausdorff search.
  bool measureMeanDistance()
  {
    CageQualityResult& r = this->R;
    const TriangleMesh& cage = this->Cage;
    progressStage(this->Report, "mean distance", 0.7, 0.8);
    const double spacing = std::max(this->Options.MeanDistanceSpacing, 1e-6) * r.Diagonal;
    const int minimumLevel = std::clamp(this->Options.MinimumMeanDistanceLevel, 0, 6);
    const std::size_t nf = cage.Triangles.size();
    std::vector<double> cellArea(nf), cellMean(nf);
    std::vector<double>& cellMax = this->CellMaximum;
    cellMax.assign(nf, 0.0);
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
        double m = std::max({ this->CageDistance[t[0]], this->CageDistance[t[1]], this->CageDistance[t[2]] });
        double s = 0.0;
        auto at = [&](double u, double v) {
          const double d = this->InputTree.distance(a + (b - a) * (u / n) + (c - a) * (v / n));
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
    this->SampledMaximum = sampledMax;
    r.MeanDistanceCageToInput = area > 0 ? weighted / area : r.MeanPointDistance;
    return true;
  }

  /// Hausdorff distances both ways by branch and bound, with the certified bounds reached; the
  /// cage-to-input search also completes CellDistance.
  bool measureHausdorffDistances()
  {
    CageQualityResult& r = this->R;
    const double tol = this->Options.HausdorffTolerance * r.Diagonal;
    progressStage(this->Report, "Hausdorff cage to input", 0.8, 0.9);
    const HausdorffBounds hc =
      hausdorff(this->Cage, this->CageDistance, this->CageNear, Target{ this->InputTree, this->Input },
        this->SampledMaximum, tol, this->Options.HausdorffBudget, &this->CellMaximum, this->Report);
    r.HausdorffCageToInput = hc.Value;
    r.HausdorffCageToInputBound = hc.Bound;
    for (std::size_t f = 0; f < this->CellMaximum.size(); ++f)
    {
      r.CellDistance[this->CageKept[f]] = this->CellMaximum[f];
    }
    progressStage(this->Report, "Hausdorff input to cage", 0.9, 1.0);
    const HausdorffBounds hi = hausdorff(this->Input, this->InputDistance, this->InputNear,
      Target{ this->CageTree, this->Cage }, 0.0, tol, this->Options.HausdorffBudget, nullptr, this->Report);
    r.HausdorffInputToCage = hi.Value;
    r.HausdorffInputToCageBound = hi.Bound;
    return true;
  }

  bool cancelled()
  {
    if (progressCancelled(this->Report))
    {
      this->R.Encloses = false;
      this->Reasons.assign(1, "cancelled");
      return true;
    }
    return false;
  }

  CageQualityResult finish()
  {
    this->InputTopology.wait();
    std::string msg;
    for (const std::string& s : this->Reasons)
    {
      msg += (msg.empty() ? "" : "; ") + s;
    }
    this->R.Message = msg;
    this->R.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - this->Start).count();
    return std::move(this->R);
  }

  const TriangleMesh& InputMesh;
  const TriangleMesh& CageMesh;
  const CageQualityOptions& Options;
  Progress* Report;
  std::chrono::steady_clock::time_point Start;
  CageQualityResult R;
  std::vector<std::string> Reasons; ///< why the cage does not enclose, in the order found
  /// the input's topology is needed only for the report: it runs beside all other phases and is
  /// waited for at the end
  tbb::task_group InputTopology;

  // checkTopologyAndShape
  TriangleMesh Input, Cage;             ///< the valid triangles (points copied as they are)
  std::vector<int> InputKept, CageKept; ///< original index of each valid triangle
  std::vector<char> InputUsed;          ///< input points referenced by a valid triangle
  TriangleTree InputTree, CageTree;
  double Touching = 0.0;      ///< distances up to this count as touching
  bool InsideDefined = false; ///< the cage is closed, consistently oriented, not degenerate
  // measurePointDistances
  std::vector<char> CageUsed;
  std::vector<double> CageDistance, InputDistance; ///< per referenced point, to the other surface
  std::vector<int> CageNear, InputNear;            ///< the closest triangle of the other surface
  double ClearanceUpperBound = kInf;
  // measureClearance
  std::vector<double> CellLowerBound; ///< per valid cage triangle, of its distance to the input
  // measureMeanDistance
  std::vector<double> CellMaximum; ///< per valid cage triangle, the largest distance sampled
  double SampledMaximum = 0.0;
};
} // namespace

CageQualityResult evaluateCage(
  const TriangleMesh& inputMesh, const TriangleMesh& cageMesh, const CageQualityOptions& options, Progress* progress)
{
  return CageEvaluation(inputMesh, cageMesh, options, progress).run();
}

} // namespace sdfcage
