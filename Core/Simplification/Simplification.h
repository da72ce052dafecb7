// SDFCage — Core: constrained QEM simplification (paper §3.2): collapse edges of the verified
// envelope down to exactly N vertices while every step keeps the cage strictly outside the input
// and free of self-intersections.
#pragma once

#include "Mesh/Mesh.h"

#include <string>

namespace sdfcage
{

class Progress;
class TriangleTree;

/// Lengths in unit-sphere units.
struct SimplifyOptions
{
  /// Stop at exactly this many vertices (>= 4 per component).
  int TargetNumberOfVertices = 500;
  /// Every cage triangle keeps at least this distance from every input triangle.
  double Clearance = 0.0025;
  /// Every new cage triangle keeps at least this distance from every cage triangle that shares
  /// no vertex with it; triangles sharing a vertex or an edge must not intersect or fold.
  /// 0 = Clearance / 4 (the dense envelope's own 2-ring neighbours are closer than Clearance).
  double SelfClearance = 0.0;
  /// When larger than the self clearance: every new cage triangle keeps at least this distance
  /// from the triangles of the cage's other parts (connected components), up to 0.95 of the
  /// distance the envelope's parts have to begin with (a cage cannot keep more room than the
  /// envelope gives). Room between parts for what is built on the cage: a nested cage's next
  /// level must enclose each part with its clearance and keep them apart (NestedCages.cxx).
  /// Envelopes of more than 16 parts keep none (measuring the room costs a tree per part).
  /// 0 = off.
  double PartClearance = 0.0;
  /// Needle bound: a new triangle's quality 4*sqrt(3)*area / (sum of squared edges), 1 for
  /// equilateral, must be at least this (0.02 is a minimum angle of roughly 0.7 degrees).
  double MinimumTriangleQuality = 0.02;
  /// A new triangle's normal must stay within this angle of the triangle it replaces: cos = 0.2
  /// (about 78 degrees) forbids flips and near-flips. When no collapse is left above the target,
  /// a last pass relaxes this bound to min(this, 0) and the needle bound to half (folds,
  /// crossings and clearances stay checked exactly). Those late passes place a vertex no
  /// farther from the input than max(16 Clearance, the edge of an equilateral triangle of the
  /// target's mean area), so a stubborn region cannot inflate the cage.
  double MinimumNormalCosine = 0.2;
  /// Gradient steps on Psi (eq. 5-6) to move an infeasible placement into the feasible region.
  /// An infeasible placement is first replaced by the edge's midpoint or an endpoint when one of
  /// them is feasible; when the queue runs dry above the target, the blocked edges are retried
  /// with the descent started from all of these and an outward walk along the one-ring normal.
  int PlacementIterations = 8;
  /// When > 0: if the ordinary pass (every collapse the first queue allows) ends above this many
  /// vertices, the thorough passes that follow (a fuller placement search, then relaxed shape
  /// bounds: most of the time of a cage that ends short) are skipped and the result says
  /// GaveUp. For a caller with a better option than a long tail of rescued collapses (the
  /// pipeline's wider envelope, CageOptions::MaximumEnvelopeWidenings). 0 = off.
  int GiveUpAbove = 0;
  /// For comparisons only: turning these off gives plain (unconstrained) QEM, which does not
  /// keep the guarantees. Link condition, flip and needle checks stay on.
  bool EnforceClearance = true;
  bool EnforceNoSelfIntersection = true;

  double selfClearance() const { return SelfClearance > 0 ? SelfClearance : Clearance / 4; }
};

struct SimplifyResult
{
  TriangleMesh Cage; ///< unit-sphere units
  int VerticesReached = 0;
  bool TargetReached = false;
  /// The room kept between parts (SimplifyOptions::PartClearance as capped by the envelope's
  /// parts; 0 when not asked or the envelope has one part).
  double PartClearanceUsed = 0.0;
  bool Cancelled = false;
  bool GaveUp = false; ///< stopped after the ordinary pass (SimplifyOptions::GiveUpAbove)
  std::string StopReason; ///< why it stopped before the target (empty when reached)
  long long Collapses = 0;
  long long RejectedInput = 0;    ///< candidate collapses vetoed by the input clearance
  long long RejectedSelf = 0;     ///< ... by self-intersection / self clearance
  long long RejectedTopology = 0; ///< ... by the link condition
  long long RejectedShape = 0;    ///< ... by flips or needles
  long long Relocated = 0;        ///< infeasible placements replaced by a feasible one
  double Seconds = 0.0;
};

/// Simplifies `envelope` (closed, outward, unit units, at least `Clearance` from the input) down
/// to options.TargetNumberOfVertices vertices. `inputTree` indexes the normalized input. Candidate
/// collapses are evaluated in batches of well-separated edges on all threads and applied in queue
/// order; an evaluation whose neighbourhood an earlier collapse changed is repeated later.
/// Deterministic: the batches do not depend on the thread count, nor does the cage.
/// `inputProbes` (componentProbes() of the normalized input): no collapse may sweep one of
/// them out of the cage. Needed whenever the input has components smaller than the cage's
/// triangles (soups, scans with debris); the pipeline always passes them.
SimplifyResult simplifyEnvelope(const TriangleMesh& envelope, const TriangleTree& inputTree,
  const SimplifyOptions& options, Progress* progress = nullptr, const std::vector<Vec3>* inputProbes = nullptr);

} // namespace sdfcage
