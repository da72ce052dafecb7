// SDFCage — Core: cage optimization (paper §3.3). Vertex relocation by gradient descent on
// E_quality + λ·B (IPC barrier, eq. 7) with a collision-free line search, then edge flips that
// lower E_quality; with MIPS, tangential steps first, a Hausdorff budget on every change and a
// repair of needles (flips, collapses paired with edge splits), in sweeps until no angle is below
// the target. Every accepted change keeps the clearance to the input, freedom from
// self-intersection, manifoldness and the vertex count, and the result is verified again at the
// end.
#pragma once

#include "Common/Status.h"
#include "Mesh/Mesh.h"

#include <string>
#include <vector>

namespace sdfcage
{

class Progress;
class TriangleTree;

/// The cage quality measure E_quality.
enum class CageEnergy
{
  /// MIPS energy (eq. 8) against equilateral reference triangles: per triangle
  /// sum(l_i^2) / (2 sqrt(3) A), which is 2 for an equilateral triangle and grows without bound
  /// as it degenerates.
  MIPS = 0,
  /// Cage spacing (eq. 9): integral over the cage of (xi(x) - h)^2 dA, xi the exact distance to
  /// the input (the cage is outside, so it is the SDF), by a 3-point degree-2 rule per triangle.
  Spacing = 1
};

const char* energyName(CageEnergy e);

/// Lengths in unit-sphere units (the input scaled into the unit sphere, paper §4).
struct OptimizeOptions
{
  CageEnergy Energy = CageEnergy::MIPS;
  /// Target distance h of the spacing energy.
  double TargetSpacing = 0.05;
  /// λ, the weight of the barrier.
  double BarrierWeight = 0.1;
  /// d̂: the barrier acts on the gap g = d - δ_pair between a pair's distance d and the distance
  /// the pair must keep (δ for cage/input pairs, the self clearance for cage/cage pairs), and is
  /// b(g) = -(g - d̂)^2 ln(g / d̂) for g < d̂, 0 beyond. It starts repelling at d = δ + d̂ and is
  /// infinite at d = δ. Default 0.0025 (= δ at the default isovalue).
  double BarrierDistance = 0.0025;
  /// Rounds of sweeps (see MaximumSweeps).
  int NumberOfIterations = 1;
  /// Gradient steps per vertex in one relocation pass.
  int DescentSteps = 2;
  bool EdgeFlips = true;
  /// δ: every cage triangle keeps at least this distance from every input triangle. <= 0 means
  /// automatic: min(0.0025, the measured clearance of the given cage), so a valid cage made with
  /// a smaller clearance can still be optimized without getting any closer.
  double Clearance = 0.0;
  /// Distance kept between cage triangles that share no vertex; 0 = δ / 4 (as the simplifier).
  double SelfClearance = 0.0;
  /// The parts (connected components) of the cage never come closer to each other than in the
  /// given cage (measured up to MaximumPartRoom): the room the nested cages' next level passes
  /// through (SimplifyOptions::PartClearance). The pipeline sets it when the simplifier kept
  /// room. Up to 16 parts.
  bool KeepPartsApart = false;
  /// KeepPartsApart: parts farther apart than this (unit-sphere units) only keep this distance.
  double MaximumPartRoom = 0.1;
  /// A changed triangle's quality 4 sqrt(3) A / sum(l^2) (1 equilateral) must stay at least
  /// min(this, its quality before the change).
  double MinimumTriangleQuality = 0.02;

  // ---- keeping the MIPS-optimized cage tight (ignored by the spacing energy) ----
  /// MIPS: vertices move in their tangent plane only (the MIPS gradient with its component along
  /// the area-weighted vertex normal removed), so relaxation slides triangles along the cage
  /// instead of inflating it; the barrier and the line search are unchanged.
  bool TangentialRelaxation = true;
  /// MIPS fidelity: no change (move, flip, collapse) may put a point of a changed triangle
  /// farther from the input than this times the given cage's one-sided Hausdorff distance
  /// cage -> input. Both by branch and bound on the 1-Lipschitz distance (cells split to 1/32 of
  /// the triangle; the finest cells judged at their centroids, so the result may exceed the
  /// budget by about that much). 0 = off, else >= 1.
  double HausdorffFactor = 1.4;
  /// MIPS: the smallest angle (degrees) the sweeps aim at. Triangles with a smaller angle are
  /// repaired when relocation and flips leave them: the shortest edge of a needle is collapsed
  /// (checked like any change) and, to keep the vertex count, the longest edge of the cage is
  /// split at its midpoint (the surface does not change). 0 = no repair.
  double TargetMinimumAngle = 15.0;
  /// MIPS with a target: after each repair pass, the corners of the triangles still below
  /// TargetMinimumAngle try moves that raise the smallest angle of their ring (max-min angle
  /// instead of the summed MIPS energy), checked like every move (collision-free sweep, veto,
  /// Hausdorff budget).
  bool AngleRelocation = true;
  /// Sweeps per round (one relocation pass, one flip pass and, MIPS, one repair pass each). A
  /// MIPS round ends early once no angle is below TargetMinimumAngle, a sweep changes nothing or
  /// the smallest angle has not grown for 4 sweeps;
  /// a spacing round once a sweep lowers the energy by less than 0.2%.
  int MaximumSweeps = 12;
};

struct OptimizeResult
{
  Status State = Status::Failed;
  std::string Message;                         ///< error, cancellation or revert reason (empty when all went well)
  TriangleMesh Cage;                           ///< unit-sphere units (the given cage when reverted or invalid)
  std::vector<double> DistanceToInput;         ///< per cage point, exact, unit-sphere units
  double EnergyBefore = 0.0;                   ///< E_quality of the given cage (no barrier)
  double EnergyAfter = 0.0;                    ///< E_quality of the result
  double MinimumClearance = 0.0;               ///< measured exact minimum distance to the input
  double ClearanceUsed = 0.0;                  ///< δ actually enforced
  double PartClearanceUsed = 0.0;              ///< room kept between the cage's parts (0: none)
  double MinimumAngleBefore = 0.0;             ///< degrees
  double MinimumAngleAfter = 0.0;              ///< degrees
  long long Moves = 0;                         ///< accepted descent steps
  long long RejectedMoves = 0;                 ///< descent steps with no acceptable step size, by the reason
  long long MovesWithoutDescent = 0;           ///< ... of their last trial: the energy did not drop,
  long long MovesCutByCollision = 0;           ///< the CCD allowed nothing (or too little to lower it),
  long long MovesVetoedByShape = 0;            ///< a ring triangle would flip or become a needle,
  long long MovesVetoedBySelfIntersection = 0; ///< the static self-intersection test failed
  long long MovesVetoedByFidelity = 0;         ///< a ring sample went beyond the Hausdorff budget
  long long AngleMoves = 0;                    ///< moves of the angle-targeted relocation (AngleRelocation)
  long long Collapses = 0;                     ///< needle collapses (each paired with one edge split)
  long long RejectedCollapses = 0;             ///< needle collapses that broke a constraint
  int Sweeps = 0;                              ///< sweeps run (over all rounds)
  /// One-sided Hausdorff distance cage -> input (the largest value the branch and bound
  /// reached), unit-sphere units, of the given cage and of the result, and the budget
  /// HausdorffFactor x before (MIPS; 0: off).
  double HausdorffBefore = 0.0;
  double HausdorffAfter = 0.0;
  /// Spacing energy: the area fraction of the cage whose distance to the input lies within
  /// TargetSpacing +- 20% (each triangle judged at the centroids of its 64 midpoint pieces).
  double SpacingBandBefore = 0.0;
  double SpacingBandAfter = 0.0;
  /// ... and the rest of the result's area, split: closer than 0.8 TargetSpacing to the input
  /// (where the cage cannot follow the input at that distance with its vertices, or a narrow gap
  /// keeps it close), farther than 1.2 TargetSpacing (concavities the cage spans).
  double SpacingCloserAfter = 0.0;
  double SpacingFartherAfter = 0.0;
  double HausdorffBudget = 0.0;
  double SmallAnglesBefore = 0.0; ///< fraction of triangle angles below TargetMinimumAngle (MIPS)
  double SmallAnglesAfter = 0.0;
  long long Batches = 0;                       ///< relocation batches (vertices relocated in parallel)
  long long Flips = 0;
  long long RejectedFlips = 0; ///< flips that would lower the energy but break a constraint
  bool Reverted = false;       ///< the final verification failed: the given cage is returned
  double Seconds = 0.0;
  double RelocationSeconds = 0.0;
  double FlipSeconds = 0.0;
  double RelocationAndFlipCpuSeconds =
    0.0; ///< processor time of the passes (relocation runs parallel batches, one pass after the other)
  double VerificationSeconds = 0.0;
};

/// Optimizes `cage` (closed, outward, enclosing `input` with clearance) in unit-sphere units.
/// `inputTree` indexes `input`. Deterministic: relocation runs batches of vertices with
/// separate neighbourhoods in parallel, with results independent of the thread count. The given cage is verified first
/// (InvalidInput if it fails); the result is verified with verifyEnclosure and, should that ever
/// fail, the given cage is returned unchanged with Reverted and a message. Progress stages cover
/// [progressBegin, progressEnd] of the whole run; a cancel returns the (verified) cage so far with
/// State Cancelled.
OptimizeResult optimizeCage(const TriangleMesh& cage, const TriangleMesh& input, const TriangleTree& inputTree,
  const OptimizeOptions& options, Progress* progress = nullptr, double progressBegin = 0.0, double progressEnd = 1.0);

/// The same for meshes in the input's own coordinates: normalizes both by the input (as
/// generateCage does), optimizes, and maps the cage, DistanceToInput and MinimumClearance back to
/// input units (energies and ClearanceUsed stay in unit-sphere units). Validates both meshes
/// (closed, manifold, consistently oriented; an inward one is flipped).
OptimizeResult optimizeCageInInputUnits(
  const TriangleMesh& cage, const TriangleMesh& input, const OptimizeOptions& options, Progress* progress = nullptr);

/// E_quality of a whole cage (unit-sphere units).
double cageEnergy(const TriangleMesh& cage, const TriangleTree& inputTree, const OptimizeOptions& options);

/// Smallest interior angle of the cage's triangles, in degrees.
double minimumAngle(const TriangleMesh& cage);

/// Continuous collision detection: the largest fraction t in [0, 1] (to 1/1024, never above the
/// true one) of the move P[v] -> P[v] + move such that, along the whole straight path to
/// P[v] + t move, no triangle around v comes closer than `clearance` to the input or closer than
/// `selfClearance` to a cage triangle it shares no vertex with. A triangle (v, a, b) sweeps exactly
/// the tetrahedron (P[v], P[v] + t move, a, b), which is tested with exact-in-effect distances.
/// Exposed for tests; the optimizer uses the same code.
double collisionFreeFraction(const TriangleMesh& cage, int v, const Vec3& move, const TriangleMesh& input,
  const TriangleTree& inputTree, double clearance, double selfClearance);

} // namespace sdfcage
