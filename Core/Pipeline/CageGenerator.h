// SDFCage — Core: the whole pipeline, mesh in input coordinates -> cage in input coordinates.
#pragma once

#include "Envelope/Envelope.h"
#include "Mesh/Normalization.h"
#include "Optimization/Optimization.h"
#include "Simplification/Simplification.h"
#include "Mesh/Validation.h"

namespace sdfcage
{

struct CageOptions
{
  /// Worker threads of every stage (0 = all cores). The cage does not depend on it.
  int NumberOfThreads = 0;
  EnvelopeOptions Envelope;
  ValidationOptions Validation;
  /// Target vertex count of the cage; 0 keeps the dense verified envelope as the cage.
  int TargetNumberOfVertices = 500;
  /// Simplification knobs (Clearance is taken from Envelope.clearance()).
  SimplifyOptions Simplify;
  /// Optional optimization of the simplified cage (paper §3.3); off by default. Its Clearance is
  /// taken from Envelope.clearance(). Not applied when TargetNumberOfVertices is 0.
  bool Optimize = false;
  OptimizeOptions Optimization;
  /// Inputs without a defined topology (open, soups, non-manifold: not a closed, consistently
  /// oriented 2-manifold) have no genus to keep, and their envelope can have more parts and
  /// handles than the target's vertices can carry (debris beside a body, gaps between the parts
  /// of a model). When the target is not reached for such an input, the envelope is built again
  /// with twice the isovalue (the automatic voxel size and clearance follow it), which fuses
  /// parts and closes handles narrower than about twice the new isovalue, up to this many
  /// times (2, 4, 8 times the isovalue); the cage that reaches the target (or gets closest) is kept and IsoValueUsed /
  /// EnvelopeWidenings say what was done. An envelope that a wider one may still replace is not
  /// simplified past its ordinary pass when that ends above WideningGiveUpAbove(target)
  /// vertices (the thorough passes that follow rescue a few percent at most and cost most of
  /// the time of a cage that ends short). Closed inputs are never widened (their topology is
  /// kept). 0 = off.
  int MaximumEnvelopeWidenings = 3;
  /// With widening on, the automatic voxel size and an input of more parts than the target can
  /// carry apart (4 vertices each: its envelope reaches the target only where the isovalue
  /// fuses them), the isovalue is chosen before any envelope is built on the requested grid, by
  /// probes on grids twice as coarse (voxel = the isovalue; distance field, sign and isosurface,
  /// neither verified nor simplified): from the widest isovalue below the last one down, each
  /// probe whose envelope's parts and handles may fit the target (minimumCageVertices) lowers
  /// the choice, and the first that cannot stops the probing. The envelope is then built on the
  /// requested grid at the chosen isovalue and widened from there as before. The probe's count
  /// is an estimate (the coarse grid fuses narrow gaps, and can open handles in slabs thinner
  /// than its voxel); it only decides which envelopes are not built. Closed inputs are never
  /// probed.
  bool ChooseIsoValueFirst = true;
  /// With widening on, an input without a defined topology: an envelope that a wider one may
  /// still replace is simplified before it is verified (EnvelopeOptions::DeferVerification), and
  /// verified only once its cage reaches the target (or is kept after the widenings): the
  /// envelopes that are thrown away are never verified (on the 100k-face soup of
  /// Testing/Benchmarks/anymesh_benchmark.py that is a 0.5 s verification of the 0.04 envelope
  /// whose cage stops at 657 vertices). Nothing unverified is ever output: an envelope that fails
  /// the late verification is built again the ordinary way (verified first, adaptivity repaired),
  /// and every cage is verified as before. The cages are the same either way.
  bool DeferEnvelopeVerification = true;
  /// Relaxation of a stalled simplification: when the ordinary pass ends more than
  /// max(64, target / 4) vertices above the target (a region of needles and slivers where every
  /// collapse would fold, cross or crowd a neighbour), the cage so far gets one sweep of MIPS
  /// relaxation (tangential moves and edge flips, with the optimizer's guarantees and its
  /// Hausdorff budget of 1.4 times the stalled cage's distance; no needle repair) and is
  /// simplified again, up to this many times while a round removes at least a sixteenth of the
  /// vertices above the target; the thorough passes run on what is left. A pass that ends closer
  /// to the target runs the thorough passes first, and is relaxed only if they end above it.
  /// 0 = off (the thorough passes only, as before). Cages that reach the target in their
  /// ordinary pass are not touched.
  int MaximumRelaxations = 4;
};

struct CageResult
{
  Status State = Status::Failed;
  std::string Message; ///< error or cancellation reason (empty when Ok)
  /// Validation report of the input; Empty until the input is validated (a run that did not
  /// happen has no input: not closed, genus undefined).
  MeshDefects Defects = [] {
    MeshDefects none;
    none.Empty = true;
    return none;
  }();
  TriangleMesh Cage;                           ///< input coordinates
  std::vector<double> CageDistanceToInput;     ///< per cage point, input units
  TriangleMesh Envelope;                       ///< input coordinates
  std::vector<double> EnvelopeDistanceToInput; ///< per envelope point, input units
  double MinimumClearance = 0.0;               ///< measured, input units
  double MinimumClearanceRelative = 0.0;       ///< measured, unit-sphere units
  bool EnclosureVerified = false;
  int RemovedPockets = 0;
  int EnvelopeGenus = 0;
  int EnvelopeComponents = 0;
  double VoxelSizeUsed = 0.0; ///< unit-sphere units
  /// adaptivity of the kept envelope's extraction (a topology repair round's 1, a failed one's fallback)
  double AdaptivityUsed = 0.0;
  /// the amplification's alpha of the kept envelope (0 without active points): the requested one,
  /// or lowered to IsoValue / (1.15 clearance) where that one would put the envelope within the
  /// clearance at the active points (EnvelopeResult::AlphaUsed)
  double AlphaUsed = 0.0;
  int InputGenus = 0;         ///< -1 where undefined (the input is not closed)
  int InputComponents = 0;
  bool InputClosed = false;                ///< closed, consistently oriented 2-manifold (after repair)
  SignMode SignUsed = SignMode::FloodFill; ///< how the inside was decided (never Auto)
  std::string SignReason;                  ///< why
  double WindingSeconds = 0.0;             ///< winding-number sign, part of DistanceFieldSeconds
  std::size_t NumberOfActivePoints = 0;    ///< input points flagged active (0 when off)
  std::size_t NumberOfActiveSamples = 0;   ///< the active set A on the surface sampling
  double ActivePointSeconds = 0.0;
  double AmplificationSeconds = 0.0; ///< phi xi on the grid, part of DistanceFieldSeconds
  /// Non-empty when the envelope (and so the cage) does not have the input's genus and
  /// component count: parts closer than the parameters can separate were fused.
  std::string TopologyWarning;
  /// Envelopes rebuilt to keep the input's topology (EnvelopeOptions::MaximumTopologyRepairs)
  /// and what each round did.
  int TopologyRepairs = 0;
  std::string TopologyRepairLog;
  /// The clearance every cage triangle keeps (unit-sphere units): the requested or automatic
  /// one, lowered by the topology repair only when automatic.
  double ClearanceUsedRelative = 0.0;
  double ValidationSeconds = 0.0;
  double DistanceFieldSeconds = 0.0;
  double IsosurfaceSeconds = 0.0;
  double VerificationSeconds = 0.0;
  int VerticesReached = 0;       ///< cage vertex count
  bool TargetReached = false;    ///< VerticesReached == TargetNumberOfVertices (or target 0)
  std::string StopReason;        ///< why simplification stopped early (empty otherwise)
  SimplifyResult Simplification; ///< statistics of the simplification (all its rounds)
  double SimplificationSeconds = 0.0; ///< relaxation rounds included
  int Relaxations = 0;                ///< relaxation rounds run (CageOptions::MaximumRelaxations)
  int VerticesBeforeRelaxation =
    0; ///< where the simplification stalled before relaxing (0: it did not, or no relaxation)
  double RelaxationSeconds = 0.0;     ///< the relaxation sweeps (part of SimplificationSeconds)
  double CageVerificationSeconds = 0.0;
  OptimizeResult Optimization; ///< statistics of the optional optimization (its Cage is cleared)
  bool Optimized = false;      ///< the optimization ran and its result is the cage
  double OptimizationSeconds = 0.0;
  double TotalSeconds = 0.0;
  double IsoValueUsed = 0.0; ///< unit-sphere units: the requested one, or widened (see MaximumEnvelopeWidenings)
  /// Doublings of the isovalue to reach the target: IsoValueUsed = IsoValue x 2^EnvelopeWidenings
  /// (the isovalues the probes ruled out included, see CageOptions::ChooseIsoValueFirst).
  int EnvelopeWidenings = 0;
  /// This run's envelope has more parts and handles than the target's vertices can carry, and
  /// was not simplified because a wider one is tried next (see MaximumEnvelopeWidenings).
  bool EnvelopeTooComplex = false;
  /// One entry per envelope built when widening: isovalue, parts, genus, vertices reached, time
  /// (probes first, see CageOptions::ChooseIsoValueFirst).
  std::string WideningLog;
  int EnvelopeProbes = 0;     ///< coarse-grid probes run to choose the isovalue
  int IsoValuesSkipped = 0;   ///< isovalues the probes ruled out (included in EnvelopeWidenings)
  double ProbeSeconds = 0.0;  ///< time of the probes
  int EnvelopeAttempts = 0;   ///< envelopes built on the requested grid (each one full run)
  /// Triangles the envelope's distance field was computed from: fewer than the input's when it
  /// came from a clustered proxy (EnvelopeOptions::ClusteredField).
  long long FieldTriangles = 0;
  /// A provisional result (CageOptions::DeferEnvelopeVerification): its envelope is not verified
  /// yet, nor its cage; never returned by generateCage.
  bool VerificationDeferred = false;
  ScalarImage DistanceField;         ///< input coordinates and units, when requested
  ScalarImage ModifiedDistanceField; ///< phi * xi, input units, when requested and active points exist
  Normalization Normalize;
};

/// A field sampled in unit-sphere units, mapped back to input coordinates and lengths.
ScalarImage imageToInput(ScalarImage image, const Normalization& n);

/// The simplification of an envelope that a wider one may replace stops after its ordinary pass
/// when that ends above this many vertices (SimplifyOptions::GiveUpAbove): target + max(8,
/// target / 5).
int WideningGiveUpAbove(int target);

CageResult generateCage(const PolygonMesh& input, const CageOptions& options, Progress* progress = nullptr);

} // namespace sdfcage
