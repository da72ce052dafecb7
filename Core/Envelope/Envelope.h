// SDFCage — Core: the verified SDF envelope (paper §3.1): distance field, active points and the
// amplified field, isosurface, trapped pockets removed, then verified (Quality/Verification.h).
#pragma once

#include "Common/MemoryBudget.h"
#include "Common/Status.h"
#include "Envelope/ActivePoints.h"
#include "Mesh/Mesh.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace sdfcage
{

class Progress;
class TriangleTree;

/// How the inside of the input, and so the sign of the distance field, is decided.
enum class SignMode
{
  /// FloodFill for a closed, consistently oriented 2-manifold input, WindingNumber otherwise.
  Auto = 0,
  /// OpenVDB's flood fill from outside (the first wave's path): needs a closed input.
  FloodFill,
  /// Inside where the generalized winding number of the input exceeds 1/2 in magnitude: holes,
  /// cracks, overlaps and flipped parts are bridged and the solid is caged; where there is no
  /// solid (an open sheet, |w| < 1/2 on both sides) this is the unsigned offset, wrapping the sheet
  /// on both sides.
  WindingNumber,
  /// No inside at all: the outer boundary of the unsigned offset {d <= c}; every sheet is wrapped
  /// on both sides, and holes wider than 2c let the envelope in.
  Unsigned
};

const char* signModeName(SignMode m);

/// All lengths in unit-sphere units (the input is normalized first).
struct EnvelopeOptions
{
  /// The inside rule (see SignMode). Auto decides from the input's topology.
  SignMode Sign = SignMode::Auto;
  /// Isovalue c of the envelope {xi = c} (paper default 0.01).
  double IsoValue = 0.01;
  /// Voxel size h of the SDF grid; 0 = automatic (IsoValue / 2, which keeps the genus of the
  /// shared test meshes and a clearance of about c/2).
  double VoxelSize = 0.0;
  /// Clearance delta that every envelope triangle must keep from every input triangle;
  /// 0 = automatic (IsoValue / 4).
  double MinimumClearance = 0.0;
  /// OpenVDB volumeToMesh adaptivity (0 = uniform triangles; up to 1 merges flat regions into
  /// larger polygons, giving a smaller envelope that is verified like any other). The default
  /// 0.3 gives 2-2.5x fewer triangles than 0.1 on the shared test meshes (armadillo: 56k against
  /// 133k), so extraction, verification and simplification are about twice as fast, and the
  /// 500-vertex cages are as tight or tighter (Hausdorff cage -> input 0.0188 against 0.0214 of
  /// the diagonal on armadillo). Merged polygons that break the clearance are re-extracted
  /// without adaptivity around the defect.
  double Adaptivity = 0.3;
  /// Mend the adaptive envelope's cut corners before verifying it: the extraction's points and
  /// triangles closer than 1.2 clearance to the input are lifted onto the offset (triangles split
  /// along their longest edge first), points whose lift makes the surface cross itself lifted
  /// less or put back (see liftCutCorners in Envelope.cxx), and a surface that then fails only by
  /// folds of its own triangles is mended in place and verified again (unfoldCrossings); what is
  /// left goes to the re-extraction without adaptivity around it. Not with active points (their
  /// amplified projection refines there).
  bool LiftCutCorners = true;
  /// If verification fails, retry up to this many times with half the voxel size.
  int MaximumRefinements = 2;
  /// Coarse grid first: with the automatic voxel size, a closed input (flood-fill sign) without
  /// active points is first tried on a grid twice as coarse (voxel = IsoValue: about 8x fewer
  /// voxels in the narrow band and 4x fewer isosurface cells). Its envelope is kept only when it
  /// is verified like any other and has the input's genus and parts; otherwise the requested
  /// grid (IsoValue / 2) follows as if the coarse one had not been tried. Refinements counts the
  /// grids finer than the requested one only. On by default since the adaptive envelope's cut
  /// corners are mended (LiftCutCorners): before that, the coarse grid's adaptive envelopes
  /// mostly failed verification and their re-extraction without adaptivity around the defects
  /// gave more triangles than the requested grid (hand_fist 78k against 46k), and the
  /// 500-vertex cage of the torus of core.Optimization.MIPSReachesFifteenDegreesAndStaysTight
  /// had a needle MIPS could not lift to 15 degrees (it passes now). Measured on the shared
  /// closed meshes at 500 vertices: 1.4-3x faster wherever the coarse envelope keeps the
  /// topology (README, "Time that follows the work"). Where it fuses parts (or holds too few
  /// points), a grid between follows (voxel 4/3 of the requested one, judged the same way), and
  /// then the requested grid as if no coarse one had been tried.
  bool CoarseFirst = true;
  /// The coarse grid's envelope is kept only with at least this many points (generateCage asks
  /// 4x its target: a coarse envelope of a small shape or a large isovalue could otherwise hold
  /// fewer points than the cage must have, or leave the simplifier few placements).
  std::size_t CoarseMinimumPoints = 0;
  /// Measure the envelope's exact minimum clearance (costly on a dense envelope) instead of
  /// certifying that it is at least the clearance (a certified lower bound is reported then).
  bool ExactEnvelopeClearance = false;
  /// Accept the extracted envelope without verifying it (VerificationDeferred in the result,
  /// EnclosureVerified false): for a caller that verifies it later, and only if it keeps it (the
  /// pipeline's envelopes that a wider one may replace, see CageOptions::DeferEnvelopeVerification).
  /// Outer boundary, pockets and parts as usual; no adaptive re-extraction (that needs the
  /// verification's findings).
  bool DeferVerification = false;
  /// Shape-aware envelope (paper §3.1): detect active points (parts of the surface that nearly
  /// touch other parts) and extract the envelope from the amplified field phi * xi, which lies
  /// closer to the input there (down to c / alpha) so that nearly touching parts stay separate.
  bool UseActivePoints = true;
  ActivePointOptions ActivePoints;
  /// Keep the sampled SDF as a dense image (for display).
  bool KeepDistanceField = false;
  /// Where the input's triangles are much smaller than the voxels, compute the distance field
  /// from a vertex-clustered proxy (cells of one voxel; points near active samples kept) when
  /// that drops at least a tenth of the triangles. The envelope is verified against the input
  /// itself either way. Off with KeepDistanceField (the displayed field stays exact).
  bool ClusteredField = true;
  /// When > 0: an extracted envelope whose parts and handles need more cage vertices than this
  /// (minimumCageVertices) is not verified; the result says TooComplex (the pipeline then tries a
  /// wider envelope, see CageOptions::MaximumEnvelopeWidenings). 0 = off.
  int VertexBudget = 0;

  /// Topology repair, for a closed input whose envelope's genus or number of parts differs from
  /// the input's (nearly touching parts fused): the envelope is built again, up to this many
  /// times, each round stronger than the last, and the first whose topology matches is kept
  /// (else the first one, with TopologyWarning):
  ///  1. the facing-gap rule joins the paper's (ActivePointOptions::GapRatio 3), the
  ///     amplification rises to the most the clearance allows (the envelope at 1.15 delta there),
  ///     and the voxel size halves;
  ///  2. the voxel size is a quarter of the requested one and, only when the clearance is
  ///     automatic, the clearance drops to 0.4 delta (a gap narrower than about twice the
  ///     clearance cannot stay open), the amplification rising with it.
  /// A round whose grid would hold more than MaximumRepairSurfaceVoxels voxels along the input's
  /// surface (its area / h^2) is not tried. Needs active points and the flood-fill rule. 0 = off.
  int MaximumTopologyRepairs = 2;
  double MaximumRepairSurfaceVoxels = 2.0e7;
  /// Set by the topology repair's first round (0 = off): its finer grid is exact only within
  /// this many coarse voxels of the gaps the grid twice as coarse may fuse (computeIsosurface's
  /// LocalExactField), elsewhere the coarse field interpolated. Needs active points and the
  /// flood-fill rule.
  int LocalExactDilation = 0;
  /// Fail (Status::TopologyChanged, no envelope) instead of accepting an envelope whose genus
  /// or number of parts differs from the closed input's after the repairs.
  bool RequireTopology = false;
  /// Memory budget in bytes: an envelope whose estimated need (estimateEnvelopeBytes) exceeds it
  /// is not built (Status::Failed, the message names the need and the limit), and a finer
  /// refinement grid over it is not tried. 0 = defaultMemoryLimit(), three quarters of the
  /// machine's physical memory.
  std::size_t MemoryLimit = 0;

  double voxelSize() const { return VoxelSize > 0 ? VoxelSize : IsoValue / 2; }
  std::size_t memoryLimit() const { return MemoryLimit > 0 ? MemoryLimit : defaultMemoryLimit(); }
  double clearance() const { return MinimumClearance > 0 ? MinimumClearance : IsoValue / 4; }
};

struct EnvelopeResult
{
  Status State = Status::Failed;
  SignMode SignUsed = SignMode::FloodFill; ///< the inside rule actually used (never Auto)
  std::string SignReason;                  ///< why that rule (Auto's choice or the request)
  bool InputClosed = false;                ///< the input is a closed, consistently oriented 2-manifold
  std::string Message;                     ///< what went wrong (empty when Ok)
  TriangleMesh Envelope;                   ///< outer envelope, outward oriented, unit-sphere units
  std::vector<double> DistanceToInput;     ///< per envelope point, unsigned, unit-sphere units
  double MinimumClearance =
    0.0; ///< exact min distance to the input (ExactEnvelopeClearance) or a certified lower bound >= delta, unit-sphere units
  bool EnclosureVerified = false;    ///< clearance >= delta, input inside, closed manifold
  bool VerificationDeferred = false; ///< accepted unverified (EnvelopeOptions::DeferVerification)
  int RemovedPockets = 0;            ///< trapped air pockets (inner components) removed
  int Components = 0;                ///< components of the kept envelope
  int Genus = 0;                     ///< genus of the kept envelope
  double VoxelSizeUsed = 0.0;        ///< after any refinement
  int Refinements = 0;               ///< finer grids needed (0: the requested voxel size)
  std::size_t ProjectedVertices = 0; ///< vertices moved onto the exact amplified offset
  int AdaptiveRepairs = 0;           ///< re-extractions with adaptivity switched off around defects
  std::size_t LiftedPoints = 0;      ///< points added where adaptive polygons cut corners (LiftCutCorners)
  double AdaptivityUsed = 0.0;       ///< adaptivity of the accepted envelope
  /// The amplification's alpha the accepted envelope used (0 without active points): the
  /// requested one, or lowered to c / (1.15 delta) where that one would put the envelope at the
  /// active points within the clearance delta.
  double AlphaUsed = 0.0;
  double DistanceFieldSeconds = 0.0;
  double IsosurfaceSeconds = 0.0;
  double VerificationSeconds = 0.0;
  ScalarImage DistanceField;             ///< filled when KeepDistanceField (unit-sphere units)
  ScalarImage ModifiedDistanceField;     ///< phi * xi, filled when KeepDistanceField and active points exist
  std::size_t NumberOfActivePoints = 0;  ///< input points flagged active
  std::size_t NumberOfActiveSamples = 0; ///< size of the active set A (samples)
  std::size_t AmplifiedVoxels = 0;       ///< voxels where phi > 1.001
  std::size_t ExactVoxels = 0;           ///< a repair round's voxels computed exactly (LocalExactDilation)
  std::size_t FieldTriangles = 0;        ///< triangles the kept envelope's field came from (ClusteredField)
  double ActivePointSeconds = 0.0;       ///< active points + g_A
  double AmplificationSeconds = 0.0;     ///< xi -> phi xi on the grid (included in DistanceFieldSeconds)
  double WindingSeconds = 0.0;           ///< winding-number sign (included in DistanceFieldSeconds)
  std::size_t WindingEvaluations = 0;    ///< voxels whose winding number was evaluated
  int InputGenus = 0;                    ///< -1 where undefined (the input is not closed)
  int InputComponents = 0;
  /// Non-empty when the envelope's genus or component count differs from the input's (parts
  /// closer than the parameters can separate were fused, or handles closed): the envelope is
  /// still verified, but the cage will not have the input's topology.
  std::string TopologyWarning;
  /// Topology repair rounds run (see EnvelopeOptions::MaximumTopologyRepairs) and what each did.
  int TopologyRepairs = 0;
  std::string TopologyRepairLog;
  /// The clearance the envelope was verified with: the requested one, or lowered by the
  /// topology repair (automatic clearance only). The later stages keep this one.
  double ClearanceUsed = 0.0;
  /// Where parts nearly touch across a gap (facing-gap samples, unit-sphere units), when the
  /// repair ran: the warning names the ones left.
  std::vector<Vec3> GapSites;
  /// Where the input's surface crosses itself joining parts far apart along it (filled when the
  /// envelope's topology differs and a repair would run): the solid is fused there, and when these
  /// places account for the difference no repair round is run (the warning says so).
  std::vector<Vec3> SelfFusedSites;
  /// The envelope needs more cage vertices than options.VertexBudget: not verified, State Failed.
  bool TooComplex = false;
  /// The bounding-volume tree of the unit input the verification used (built while the distance
  /// field is computed), for the later stages to reuse.
  std::shared_ptr<const TriangleTree> InputTree;
};

/// Builds and verifies the envelope of a validated, normalized mesh (unit-sphere units). The
/// input may be any triangle soup (open, non-manifold, self-intersecting, overlapping parts):
/// options.Sign says how its inside is decided. Active points (paper §3.1) are used with the
/// flood-fill rule only (their geodesic rule needs a closed surface); otherwise they are skipped
/// and the result says so.
/// Progress runs from 0.02 to `progressEnd` of the whole run.
/// `inputClosed`: 1 the input is a closed, consistently oriented 2-manifold, 0 it is not, -1
/// unknown (then it is checked here).
/// About the fewest vertices a cage of `components` parts and total genus `genus` can have: 4 per
/// part (a tetrahedron) and 8 per handle. The smallest triangulated torus has 7 vertices and a
/// genus-g surface at least (7 + sqrt(1 + 48 g)) / 2 (Heawood), but those are far too twisted to
/// keep clear of an input: a handle that does needs a ring of 3 or more vertices around it and 3
/// or more along it (500-vertex targets fail on envelopes of genus 100 or more).
int minimumCageVertices(int components, int genus);

EnvelopeResult buildEnvelope(const TriangleMesh& unitInput, const EnvelopeOptions& options,
  Progress* progress = nullptr, double progressEnd = 1.0, int inputClosed = -1);

} // namespace sdfcage
