// SDFCage — Core: the local-change veto. Every change the simplifier (paper §3.2, an edge
// collapse) and the optimizer (§3.3, a vertex move or an edge flip) makes to the cage replaces a
// few triangles by a few new ones; before it is made, this one test says whether it may be, in
// the sense of CGAL's edge-collapse filter policy or libigl's pre_collapse callback. Its named
// checks, in the order they run (cheap first):
//   Shape             no needle (quality floor) and no flip (normal against the replaced one);
//   Fold              the new triangles do not fold onto or cross each other;
//   InputClearance    every new triangle keeps the clearance to the input;
//   SelfIntersection  no new triangle conflicts with the rest of the cage (a grid query).
// The first check that fails names the verdict. A small policy holds the rules that genuinely
// differ between the callers (see LocalChangePolicy).
#pragma once

#include "Mesh/Mesh.h"
#include "Spatial/CageGrid.h"

#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

namespace sdfcage
{

class TriangleTree;

/// Shape quality 4 sqrt(3) A / (sum of squared edges): 1 for equilateral, 0 for degenerate.
inline double triangleQuality(const Vec3& a, const Vec3& b, const Vec3& c)
{
  const double area2 = (b - a).cross(c - a).norm(); // twice the area
  const double s = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return s > 0 ? 2.0 * std::sqrt(3.0) * area2 / s : 0.0;
}

/// MIPS energy of triangle (v, a, b): ||J||_F^2 / det J of the affine map from an equilateral
/// triangle, (sum of squared edges) / (2 sqrt(3) area); 2 for equilateral, infinite for
/// degenerate. With `grad`, its gradient with respect to v. The optimizer's energy and the
/// quality judge's per-triangle value.
inline double mipsEnergy(const Vec3& v, const Vec3& a, const Vec3& b, Vec3* grad = nullptr)
{
  const Vec3 n = (a - v).cross(b - v);
  const double a2 = n.norm(); // twice the area
  const double s = (a - v).squaredNorm() + (b - a).squaredNorm() + (v - b).squaredNorm();
  if (!(a2 > 0))
    return std::numeric_limits<double>::infinity();
  const double k = 1.0 / std::sqrt(3.0);
  const double e = k * s / a2;
  if (grad)
  {
    const Vec3 ds = 2.0 * (2.0 * v - a - b);
    const Vec3 da2 = (a - b).cross(n / a2);
    *grad = k * ds / a2 - k * s / (a2 * a2) * da2;
  }
  return e;
}

/// What the veto says about a local change: accepted, or the first named check that failed.
enum class LocalChangeVerdict
{
  Accepted,
  Shape,
  Fold,
  InputClearance,
  SelfIntersection
};
const char* verdictName(LocalChangeVerdict v);

/// The rules that differ between the simplifier, the optimizer's moves and its flips.
struct LocalChangePolicy
{
  /// Shape: a new triangle's quality (triangleQuality) must be at least this...
  double MinimumTriangleQuality = 0.02;
  /// ... or, when set, at least min(MinimumTriangleQuality, its QualityBefore): the optimizer
  /// never makes a triangle worse than a needle, nor a needle worse than it was.
  bool KeepQualityBefore = false;
  /// Shape: the cosine between a new triangle's normal and its Reference must exceed this.
  double MinimumNormalCosine = 0.0;
  /// Fold (and the SelfIntersection test of triangles sharing an edge): neighbours whose
  /// normals' cosine is below this have folded onto each other (about 18 degrees).
  double FoldCosine = -0.95;
  /// InputClearance: distance every new triangle keeps from the input.
  double Clearance = 0.0025;
  enum class InputTest
  {
    None,  ///< not tested (off, or already established by the caller)
    Exact, ///< every new triangle through the tree
  };
  InputTest Input = InputTest::Exact;
  /// Fold and SelfIntersection are tested (the simplifier's unconstrained mode turns them off).
  bool CheckSelfIntersection = true;
  /// SelfIntersection: distance kept between cage triangles that share no vertex.
  double SelfClearance = 0.0025 / 4;
  /// SelfIntersection: distance kept between triangles of different parts (CageView::Part), when
  /// larger than SelfClearance: room between parts (the nested cages' next level must pass
  /// between them).
  double PartClearance = 0.0;
  /// SelfIntersection: a pair that shares no vertex and was already closer than SelfClearance
  /// before the change (ChangedTriangle::Before) may stay closer: it must keep half its distance
  /// before, and not touch (the optimizer: a given cage may have such pairs).
  bool RelaxCloserPairs = false;

  /// The margin a pair at distance `before` must keep under RelaxCloserPairs.
  double relaxed(double before) const { return before >= SelfClearance ? SelfClearance : 0.5 * before; }
};

/// A new triangle of a local change, as the caller describes it.
struct ChangedTriangle
{
  int Ids[3];
  Vec3 Pts[3];
  /// A normal (any length) of what it replaces, for the flip test.
  Vec3 Reference;
  /// For KeepQualityBefore: the quality of what it replaces.
  double QualityBefore = std::numeric_limits<double>::infinity();
  /// For RelaxCloserPairs: the triangle before the change.
  Vec3 Before[3];
  // Filled by the Shape check: normal (twice the area), centroid, bounding radius about it.
  Vec3 N, C;
  double R = 0;
};

/// What the veto learnt besides the verdict.
struct LocalChangeFindings
{
  /// The SelfIntersection check ran: the cage triangles it read lie within [ReadLo, ReadHi].
  bool Read = false;
  Vec3 ReadLo = Vec3::Zero(), ReadHi = Vec3::Zero();
};

/// Per-thread scratch of the veto: the change (filled by the caller) and reusable buffers.
struct LocalChangeScratch
{
  /// The new triangles of the change (the caller fills Ids, Pts, Reference and, as the policy
  /// needs them, QualityBefore and Before).
  std::vector<ChangedTriangle> Tris;
  /// The cage triangles the change replaces (the caller: Replaced.begin(...), insert(f)).
  TriangleStamps Replaced;

  struct Candidate
  {
    int F;
    int Ids[3];
    Vec3 Pts[3];
    Vec3 Lo, Hi, C;
    double R; // < 0 until the bounding sphere (C, R) is computed
  };
  std::vector<Candidate> Candidates;
  TriangleStamps Seen;
};

/// The cage as the veto reads it: points, triangles, which are alive, their boxes and a grid.
struct CageView
{
  const std::vector<Vec3>* Points = nullptr;
  const std::vector<Triangle>* Triangles = nullptr;
  /// Null: every triangle is alive.
  const std::vector<char>* Alive = nullptr;
  /// Cached triangle boxes (those the grid filed them with); null: from the points.
  const std::vector<Vec3>* BoxLo = nullptr;
  const std::vector<Vec3>* BoxHi = nullptr;
  const CageGrid* Grid = nullptr;
  /// Per point: its part (connected component), for LocalChangePolicy::PartClearance; null or
  /// empty: no part rule.
  const std::vector<int>* Part = nullptr;
};

/// The veto. Const and thread-safe: everything a check writes is in the scratch (one per thread)
/// and the findings. The cage must not change during a check.
class LocalChangeVeto
{
public:
  LocalChangeVeto(const LocalChangePolicy& policy, const TriangleTree& input, const CageView& cage)
    : Policy(policy)
    , Input(input)
    , Cage(cage)
  {
  }
  const LocalChangePolicy& policy() const { return Policy; }
  /// Between checks only (the simplifier relaxes its shape bounds in a late pass).
  void setPolicy(const LocalChangePolicy& p) { Policy = p; }

  /// Runs the named checks on the change in s (Tris, Replaced) in order; the first that fails is
  /// the verdict. The findings, if given, are reset and filled.
  LocalChangeVerdict check(LocalChangeScratch& s, LocalChangeFindings* findings = nullptr) const;

  // ---- the named checks (check() runs them in this order) ----
  /// No needle, no flip; fills N, C and R of the triangles.
  bool shapeOk(std::vector<ChangedTriangle>& tris) const;
  /// No two new triangles conflict (fold onto each other across a shared edge, cross, or come
  /// closer than the self clearance).
  bool foldFree(const std::vector<ChangedTriangle>& tris) const;
  /// Every new triangle keeps the clearance to the input.
  bool inputClear(const std::vector<ChangedTriangle>& tris) const;
  /// No new triangle conflicts with a cage triangle that is alive and not replaced.
  bool selfIntersectionFree(LocalChangeScratch& s, LocalChangeFindings* findings) const;

  // ---- conservative early-outs of the pair test, shared by everyone who pairs cage triangles ----
  // Each only skips pairs trianglesConflict (Spatial/Geometry.h) cannot report as conflicting.
  /// Do the projections of a and b on axis u leave a gap of at least `gap` (either order)? The
  /// distance of two convex sets is at least the gap of their projections on any axis.
  static bool separated(const Vec3 a[3], const Vec3 b[3], const Vec3& u, double gap);
  /// Do d and e lie strictly on one side of the plane through a with normal n, each at an angle
  /// of at least 1e-6 radians from it as seen from a?
  static bool oneSide(const Vec3& a, const Vec3& n, const Vec3& d, const Vec3& e);
  /// A separating axis keeping a and b (normal a.N, centroids a.C, b.C) `gap` apart: the
  /// centroids' line, the normals, and (for the nearly coplanar neighbours of a flat region)
  /// the in-plane edge normals.
  static bool separatedByAxes(const ChangedTriangle& a, const LocalChangeScratch::Candidate& b, double gap);

private:
  LocalChangePolicy Policy;
  const TriangleTree& Input;
  CageView Cage;
};

} // namespace sdfcage
