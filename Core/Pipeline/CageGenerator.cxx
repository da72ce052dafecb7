#include "Pipeline/CageGenerator.h"

#include "Common/GracePeriod.h"
#include "Common/Progress.h"
#include "Common/Threads.h"
#include "Quality/Verification.h"
#include "Spatial/TriangleTree.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <memory>

namespace sdfcage
{

namespace
{
/// Probes (CageOptions::ChooseIsoValueFirst) use grids this many times as coarse as the
/// automatic voxel size of their isovalue.
constexpr double ProbeVoxelFactor = 2.0;

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
} // namespace

ScalarImage imageToInput(ScalarImage image, const Normalization& n)
{
  image.Origin = n.toInput(image.Origin);
  image.Spacing = n.lengthToInput(image.Spacing);
  for (float& v : image.Values)
  {
    v = static_cast<float>(n.lengthToInput(v));
  }
  return image;
}

namespace
{
/// The input, validated, repaired and normalized once for every run of generateCage.
struct PreparedInput
{
  MeshDefects Defects;
  double ValidationSeconds = 0.0;
  Normalization Normalize;
  TriangleMesh Unit; ///< the repaired input in unit-sphere units
};

/// Validation and normalization (steps 1 and 2 of every run). False (with `failed` filled) when
/// the input cannot be used or the run was cancelled.
bool prepareInput(const PolygonMesh& input, const CageOptions& options, Progress* progress, PreparedInput& prepared,
  CageResult& failed)
{
  const auto start = std::chrono::steady_clock::now();
  // 1. validation
  progressStage(progress, "validating input", 0.0, 0.02);
  TriangleMesh mesh;
  prepared.Defects = prepareMesh(input, mesh, options.Validation, progress);
  prepared.ValidationSeconds = seconds(start);
  failed.IsoValueUsed = options.Envelope.IsoValue;
  failed.Defects = prepared.Defects;
  failed.ValidationSeconds = prepared.ValidationSeconds;
  failed.TotalSeconds = seconds(start);
  if (progressCancelled(progress))
  {
    failed.State = Status::Cancelled;
    failed.Message = "cancelled";
    return false;
  }
  if (!prepared.Defects.usableAsInput())
  {
    const bool nothing = prepared.Defects.Empty && prepared.Defects.NonFinitePoints == 0 &&
      prepared.Defects.InvalidPointIds == 0;
    failed.State = nothing ? Status::EmptyInput : Status::InvalidInput;
    failed.Message = prepared.Defects.inputErrorMessage();
    return false;
  }
  // 2. normalization into the unit sphere: every length parameter is relative to it
  prepared.Normalize = Normalization::fit(mesh);
  prepared.Unit = prepared.Normalize.toUnit(mesh);
  return true;
}

/// The constrained simplification with relaxation rounds (CageOptions::MaximumRelaxations). A
/// simplification that stalls above the target has reached a cage whose remaining edges all sit
/// among needles and slivers: every collapse would fold a sliver, cross a neighbour or come
/// within the self clearance, and the thorough passes (placement search, relaxed shape bounds)
/// rescue few of them at a high cost. One sweep of the optimizer's MIPS relaxation (tangential
/// moves and flips, every guarantee checked as in any optimization, within its Hausdorff budget)
/// turns those regions into ordinary triangles, and the simplification goes on. Measured on
/// dragon_quartet.obj (its topology repair's 545k-triangle envelope, 500 vertices asked): the
/// ordinary pass stalls at 2,055 vertices; before, the thorough passes took 11 s more and ended
/// at 1,432; two relaxation sweeps (3.1 s in all) and the simplifications after them reach 500.
/// options.GiveUpAbove > 0 (widening): a wider envelope follows when the ordinary pass ends
/// above it (the result then says GaveUp, as without relaxation).
SimplifyResult simplifyRelaxing(const TriangleMesh& envelope, const TriangleMesh& unit, const TriangleTree& tree,
  const SimplifyOptions& options, int maximumRelaxations, Progress* progress, const std::vector<Vec3>& probes,
  CageResult& result)
{
  const int target = options.TargetNumberOfVertices;
  progressStage(progress, "simplifying", 0.45, 0.95);
  if (maximumRelaxations <= 0)
    return simplifyEnvelope(envelope, tree, options, progress, &probes);
  // A pass that stalls close to the target goes on with the thorough passes as before (cheap on
  // a few dozen blocked edges: the comb at 30 vertices stalls at 50 and its thorough passes
  // take 0.1 s, three relaxations 0.9 s); one that stalls farther (more than max(64, target / 4)
  // above it) is relaxed first. With widening the envelope's own limit (GiveUpAbove) is the
  // lower one: above it a wider envelope follows, as without relaxation.
  const int closeTo = target + std::max(64, target / 4);
  const int stallAbove = options.GiveUpAbove > 0 ? std::min(options.GiveUpAbove, closeTo) : closeTo;
  SimplifyOptions ordinary = options;
  ordinary.GiveUpAbove = stallAbove;
  SimplifyResult r = simplifyEnvelope(envelope, tree, ordinary, progress, &probes);
  if (r.TargetReached || r.Cancelled ||
    (r.GaveUp && options.GiveUpAbove > 0 && r.VerticesReached > options.GiveUpAbove))
    return r; // reached, cancelled, or a wider envelope follows (its own GaveUp)
  result.VerticesBeforeRelaxation = r.VerticesReached;
  auto add = [](SimplifyResult& total, SimplifyResult&& more) {
    more.Collapses += total.Collapses;
    more.RejectedInput += total.RejectedInput;
    more.RejectedSelf += total.RejectedSelf;
    more.RejectedTopology += total.RejectedTopology;
    more.RejectedShape += total.RejectedShape;
    more.Relocated += total.Relocated;
    more.Seconds += total.Seconds;
    if (total.PartClearanceUsed > 0)
      more.PartClearanceUsed = std::min(more.PartClearanceUsed, total.PartClearanceUsed);
    total = std::move(more);
  };
  // The room kept between parts so far (nested levels), not more: a simplification measures it
  // again on the cage it is given.
  auto simplifyAgain = [&](SimplifyOptions o) {
    if (r.PartClearanceUsed > 0)
      o.PartClearance = r.PartClearanceUsed;
    add(r, simplifyEnvelope(r.Cage, tree, o, progress, &probes));
  };
  OptimizeOptions relax;
  relax.Energy = CageEnergy::MIPS;
  relax.NumberOfIterations = 1;
  relax.MaximumSweeps = 1;
  relax.TargetMinimumAngle = 0.0; // no needle repair: the simplification removes them
  // One descent per vertex, not the optimizer's two: the sweep only has to unblock the stalled
  // regions, the simplification after it moves the vertices again. On the eight stalled runs
  // measured (README, "Exactly N vertices"): relaxation 15-50% faster (dragon_quartet at 500
  // 3.3-3.6 -> 1.8 s), the same targets reached, Hausdorff and mean distance 5% lower on average.
  relax.DescentSteps = 1;
  relax.Clearance = options.Clearance;
  relax.SelfClearance = options.selfClearance();
  SimplifyOptions again = options;
  again.GiveUpAbove = closeTo;
  // (the rounds and the thorough passes report at the end of the ordinary pass's span, where a
  // stalled pass leaves the progress; cancels are checked as everywhere)
  for (int round = 0; round < maximumRelaxations && !r.TargetReached; ++round)
  {
    relax.KeepPartsApart = r.PartClearanceUsed > 0;
    const auto t0 = std::chrono::steady_clock::now();
    OptimizeResult o = optimizeCage(r.Cage, unit, tree, relax, progress, 0.95, 0.95);
    result.RelaxationSeconds += seconds(t0);
    r.Seconds += seconds(t0);
    if (o.State == Status::Cancelled || progressCancelled(progress))
    {
      r.Cancelled = true; // the cage so far (verified by the caller) stays
      return r;
    }
    if (o.State != Status::Ok || o.Reverted || o.Cage.Triangles.empty())
      break;
    ++result.Relaxations;
    r.Cage = std::move(o.Cage);
    progressStage(progress, "simplifying", 0.95, 0.95);
    const int before = r.VerticesReached;
    simplifyAgain(again);
    if (r.Cancelled || 16 * (before - r.VerticesReached) < before - target)
      break;
  }
  if (!r.TargetReached && !r.Cancelled && r.GaveUp)
  {
    // the last simplification stopped after its ordinary pass: the thorough passes on what is left
    SimplifyOptions last = options;
    last.GiveUpAbove = 0;
    progressStage(progress, "simplifying", 0.95, 0.95);
    simplifyAgain(last);
  }
  r.GaveUp = false;
  return r;
}

/// One run of the pipeline on the prepared input. `mayWiden`: a wider envelope will be tried if
/// this one cannot carry the target, so an envelope whose topology needs more vertices than the
/// target is not simplified (it could not reach the target; the time is better spent on the
/// wider one), nor is a simplification pursued past its ordinary pass when that ends well above
/// the target (SimplifyOptions::GiveUpAbove).
/// `allowDefer`: the envelope's verification may wait until its cage is known to be kept
/// (CageOptions::DeferEnvelopeVerification); a result that stops short of the target is then
/// returned provisional (VerificationDeferred: neither envelope nor cage verified).
CageResult generateOnce(const PreparedInput& prepared, const CageOptions& options, Progress* progress,
  bool mayWiden, bool allowDefer = true)
{
  CageResult result;
  result.IsoValueUsed = options.Envelope.IsoValue;
  result.EnvelopeAttempts = 1;
  const auto start = std::chrono::steady_clock::now();
  result.Defects = prepared.Defects;
  result.ValidationSeconds = prepared.ValidationSeconds;
  result.Normalize = prepared.Normalize;
  const Normalization& n = result.Normalize;
  const TriangleMesh& unit = prepared.Unit;

  // 3. the verified envelope
  // when the dense envelope is itself the cage, its exact clearance is the one to report
  EnvelopeOptions envelopeOptions = options.Envelope;
  envelopeOptions.ExactEnvelopeClearance =
    envelopeOptions.ExactEnvelopeClearance || options.TargetNumberOfVertices <= 0;
  // the coarse grid first only for a cage simplified from it, with room for the target (the
  // dense envelope as the cage comes from the grid asked for)
  envelopeOptions.CoarseFirst = envelopeOptions.CoarseFirst && options.TargetNumberOfVertices > 0;
  envelopeOptions.CoarseMinimumPoints = std::max<std::size_t>(
    envelopeOptions.CoarseMinimumPoints, 4 * static_cast<std::size_t>(std::max(0, options.TargetNumberOfVertices)));
  if (mayWiden && !result.Defects.usable() && options.TargetNumberOfVertices > 0)
  {
    envelopeOptions.VertexBudget = options.TargetNumberOfVertices; // too complex: not even verified
    envelopeOptions.DeferVerification = allowDefer && options.DeferEnvelopeVerification;
  }
  EnvelopeResult env = buildEnvelope(
    unit, envelopeOptions, progress, options.TargetNumberOfVertices > 0 ? 0.45 : 1.0, result.Defects.usable() ? 1 : 0);
  result.SignUsed = env.SignUsed;
  result.SignReason = env.SignReason;
  result.InputClosed = env.InputClosed;
  result.WindingSeconds = env.WindingSeconds;
  result.DistanceFieldSeconds = env.DistanceFieldSeconds;
  result.IsosurfaceSeconds = env.IsosurfaceSeconds;
  result.VerificationSeconds = env.VerificationSeconds;
  result.VoxelSizeUsed = env.VoxelSizeUsed;
  result.AdaptivityUsed = env.AdaptivityUsed;
  result.AlphaUsed = env.AlphaUsed;
  result.RemovedPockets = env.RemovedPockets;
  result.InputGenus = env.InputGenus;
  result.InputComponents = env.InputComponents;
  result.NumberOfActivePoints = env.NumberOfActivePoints;
  result.NumberOfActiveSamples = env.NumberOfActiveSamples;
  result.ActivePointSeconds = env.ActivePointSeconds;
  result.AmplificationSeconds = env.AmplificationSeconds;
  result.TopologyWarning = env.TopologyWarning;
  result.TopologyRepairs = env.TopologyRepairs;
  result.TopologyRepairLog = env.TopologyRepairLog;
  result.FieldTriangles = static_cast<long long>(env.FieldTriangles);
  result.ClearanceUsedRelative = env.ClearanceUsed;
  result.TotalSeconds = seconds(start);
  if (env.TooComplex)
  {
    result.State = Status::Failed;
    result.EnvelopeTooComplex = true;
    result.EnvelopeComponents = env.Components;
    result.EnvelopeGenus = env.Genus;
    result.VerticesReached = static_cast<int>(env.Envelope.Points.size());
    result.Message = result.StopReason = env.Message;
    return result;
  }
  if (env.State != Status::Ok)
  {
    result.State = env.State;
    result.Message = env.Message;
    return result;
  }
  result.EnclosureVerified = env.EnclosureVerified;
  result.MinimumClearanceRelative = env.MinimumClearance;
  result.MinimumClearance = n.lengthToInput(env.MinimumClearance);
  result.EnvelopeGenus = env.Genus;
  result.EnvelopeComponents = env.Components;
  result.Envelope = n.toInput(env.Envelope);
  result.EnvelopeDistanceToInput.resize(env.DistanceToInput.size());
  for (std::size_t i = 0; i < env.DistanceToInput.size(); ++i)
  {
    result.EnvelopeDistanceToInput[i] = n.lengthToInput(env.DistanceToInput[i]);
  }
  if (options.Envelope.KeepDistanceField)
  {
    result.DistanceField = imageToInput(env.DistanceField, n);
    result.ModifiedDistanceField = imageToInput(env.ModifiedDistanceField, n);
  }

  // 4. the cage: constrained simplification of the verified envelope, verified again
  const int needed = minimumCageVertices(env.Components, env.Genus);
  if (mayWiden && !env.InputClosed && options.TargetNumberOfVertices > 0 && needed > options.TargetNumberOfVertices)
  {
    result.State = Status::Failed;
    result.EnvelopeTooComplex = true;
    result.VerticesReached = static_cast<int>(env.Envelope.Points.size());
    result.EnvelopeComponents = env.Components;
    result.EnvelopeGenus = env.Genus;
    result.TargetReached = false;
    result.Message = result.StopReason = "the envelope has " + std::to_string(env.Components) + " parts and genus " +
      std::to_string(env.Genus) + ": a cage like it needs about " + std::to_string(needed) + " vertices or more";
    result.TotalSeconds = seconds(start);
    return result;
  }
  if (options.TargetNumberOfVertices <= 0)
  {
    result.Cage = result.Envelope;
    result.CageDistanceToInput = result.EnvelopeDistanceToInput;
    result.VerticesReached = static_cast<int>(result.Cage.Points.size());
    result.TargetReached = true;
    if (options.Optimize)
      result.Optimization.Message = "the optimization needs a simplified cage (a target number of vertices > 0)";
  }
  else
  {
    const std::shared_ptr<const TriangleTree> ownTree = env.InputTree ? nullptr : std::make_shared<TriangleTree>(unit);
    const TriangleTree& tree = env.InputTree ? *env.InputTree : *ownTree;
    SimplifyOptions so = options.Simplify;
    so.TargetNumberOfVertices = options.TargetNumberOfVertices;
    so.Clearance = env.ClearanceUsed > 0 ? env.ClearanceUsed : options.Envelope.clearance();
    if (mayWiden && !env.InputClosed)
    {
      // the thorough passes rescue a few percent at most (soup: 657 -> 509, truck: 1,673 ->
      // 1,274 for a target of 500) and take most of the time of a cage that ends short
      so.GiveUpAbove = WideningGiveUpAbove(options.TargetNumberOfVertices);
    }
    const std::vector<Vec3> probes = componentProbes(unit);
    const int relaxations = needed <= options.TargetNumberOfVertices ? options.MaximumRelaxations : 0;
    result.Simplification = simplifyRelaxing(env.Envelope, unit, tree, so, relaxations, progress, probes, result);
    result.SimplificationSeconds = result.Simplification.Seconds;
    result.VerticesReached = result.Simplification.VerticesReached;
    result.TargetReached = result.Simplification.TargetReached;
    result.StopReason = result.Simplification.StopReason;
    if (env.VerificationDeferred)
    {
      // a cancel here leaves nothing verified, and does not wait for a verification: no cage
      auto cancelledWithoutCage = [&](const char* message) {
        CageResult cancelled;
        cancelled.Defects = prepared.Defects;
        cancelled.State = Status::Cancelled;
        cancelled.Message = message;
        cancelled.TotalSeconds = seconds(start);
        return cancelled;
      };
      if (result.Simplification.Cancelled || progressCancelled(progress))
      {
        return cancelledWithoutCage("cancelled while an envelope was simplified: no cage");
      }
      if (!result.TargetReached)
      {
        // a wider envelope follows; this one is verified only if it is kept (generateCage)
        result.VerificationDeferred = true;
        result.State = Status::Ok;
        result.TotalSeconds = seconds(start);
        return result;
      }
      // kept: the envelope's verification now, as buildEnvelope would have run it
      progressStage(progress, "verifying enclosure", 0.95, 0.96);
      const auto t0 = std::chrono::steady_clock::now();
      std::vector<double> distances;
      std::string why;
      double clearance = 0.0;
      const bool envelopeOk = verifyEnclosure(unit, env.Envelope, so.Clearance, clearance, why, &distances, progress,
        envelopeOptions.ExactEnvelopeClearance, &tree);
      result.VerificationSeconds += seconds(t0);
      if (!envelopeOk)
      {
        if (progressCancelled(progress))
        {
          return cancelledWithoutCage("cancelled while the envelope was verified: no cage");
        }
        // the ordinary way: verified first (and its adaptive merges repaired where they fail)
        CageResult again = generateOnce(prepared, options, progress, mayWiden, false);
        again.TotalSeconds += seconds(start);
        return again;
      }
      result.EnclosureVerified = true;
      result.MinimumClearanceRelative = clearance;
      result.MinimumClearance = n.lengthToInput(clearance);
      result.EnvelopeDistanceToInput.resize(distances.size());
      for (std::size_t i = 0; i < distances.size(); ++i)
      {
        result.EnvelopeDistanceToInput[i] = n.lengthToInput(distances[i]);
      }
    }
    // independent re-verification of the final cage (exact distances, winding numbers). It runs
    // even after a cancel: the partial cage is valid and usable. But a cancel must answer at
    // once, and a cage cut short early is large (15,000 vertices and more take a second or two
    // on a loaded machine): after a cancel, during the simplification or this verification, it
    // gets VerificationGrace seconds, and no cage is output if it runs out.
    progressStage(progress, "verifying cage", 0.95, options.Optimize ? 0.96 : 1.0);
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<double> dist;
    std::string why;
    double clearance = 0.0;
    GracePeriod grace(progress, VerificationGrace);
    const bool ok = verifyEnclosure(unit, result.Simplification.Cage, so.Clearance, clearance, why, &dist,
      progress ? &grace : nullptr, true, &tree);
    result.CageVerificationSeconds = seconds(t1);
    if (!ok && grace.expired())
    {
      result.State = Status::Cancelled;
      result.Message = result.Simplification.Cancelled
        ? "cancelled during simplification; the cage so far could not be verified in time: no cage"
        : "cancelled while the cage was verified: no cage";
      result.TotalSeconds = seconds(start);
      return result;
    }
    if (!ok)
    {
      result.State = Status::VerificationFailed;
      result.Message = "the simplified cage failed verification: " + why;
      result.EnclosureVerified = false;
      result.TotalSeconds = seconds(start);
      return result;
    }
    // 5. optional optimization (§3.3): it verifies its own result, and keeps the simplified cage
    // if that ever fails
    if (options.Optimize && !result.Simplification.Cancelled && !progressCancelled(progress))
    {
      OptimizeOptions oo = options.Optimization;
      oo.KeepPartsApart = result.Simplification.PartClearanceUsed > 0; // the nested levels' room
      oo.Clearance = so.Clearance;
      result.Optimization = optimizeCage(result.Simplification.Cage, unit, tree, oo, progress, 0.96, 1.0);
      result.OptimizationSeconds = result.Optimization.Seconds;
      const Status os = result.Optimization.State;
      // (a cancel while the optimization verified the given cage leaves it no cage: ours stays)
      if ((os == Status::Ok || os == Status::Cancelled) && !result.Optimization.Reverted &&
        !result.Optimization.Cage.Triangles.empty())
      {
        result.Optimized = true;
        result.Simplification.Cage = std::move(result.Optimization.Cage);
        dist = std::move(result.Optimization.DistanceToInput);
        clearance = result.Optimization.MinimumClearance;
      }
      result.Optimization.Cage = TriangleMesh();
      result.Optimization.DistanceToInput.clear();
    }
    result.Cage = n.toInput(result.Simplification.Cage);
    result.CageDistanceToInput.resize(dist.size());
    for (std::size_t i = 0; i < dist.size(); ++i)
      result.CageDistanceToInput[i] = n.lengthToInput(dist[i]);
    result.MinimumClearanceRelative = clearance;
    result.MinimumClearance = n.lengthToInput(clearance);
    result.Simplification.Cage = TriangleMesh(); // the result keeps the input-unit copy only
    // a cancel after the simplification (while its cage was verified) skips the optimization
    if (result.Simplification.Cancelled || result.Optimization.State == Status::Cancelled ||
      progressCancelled(progress))
    {
      result.State = Status::Cancelled;
      if (result.Simplification.Cancelled)
        result.Message = "cancelled during simplification; the cage so far is valid";
      else if (result.Optimization.State == Status::Cancelled)
        result.Message = "cancelled during optimization; the cage so far is valid";
      else
        result.Message = "cancelled after the simplification; its cage is valid";
      result.TotalSeconds = seconds(start);
      return result;
    }
  }
  result.State = Status::Ok;
  result.TotalSeconds = seconds(start);
  progressUpdate(progress, 1.0);
  return result;
}

/// Should the envelope be widened (see CageOptions::MaximumEnvelopeWidenings)? `left`: the
/// widenings still allowed.
bool wantsWidening(const CageResult& r, const CageOptions& options, int left, Progress* progress)
{
  return left > 0 && options.TargetNumberOfVertices > 0 &&
    ((r.State == Status::Ok && !r.TargetReached) || r.EnvelopeTooComplex) && !r.InputClosed &&
    !progressCancelled(progress);
}

/// One coarse-grid probe (CageOptions::ChooseIsoValueFirst): the envelope at `isoValue` on a
/// grid of voxel ProbeVoxelFactor x `isoValue` / 2, extracted but neither verified nor
/// simplified (a vertex budget of 1 stops every extraction at its parts and genus).
struct Probe
{
  bool Ran = false; ///< false: cancelled or failed (the probing stops, nothing is skipped)
  int Components = 0;
  int Genus = 0;
  double Seconds = 0.0;
};

Probe probeEnvelope(const TriangleMesh& unit, const EnvelopeOptions& requested, double isoValue, Progress* progress)
{
  const auto t0 = std::chrono::steady_clock::now();
  EnvelopeOptions o = requested;
  o.IsoValue = isoValue;
  o.VoxelSize = ProbeVoxelFactor * o.voxelSize();
  o.MinimumClearance = requested.MinimumClearance > 0 ? requested.MinimumClearance : isoValue / 4;
  o.VertexBudget = 1;
  o.MaximumRefinements = 0;
  o.KeepDistanceField = false;
  o.ExactEnvelopeClearance = false;
  o.CoarseFirst = false;
  o.MaximumTopologyRepairs = 0;
  Probe p;
  const EnvelopeResult env = buildEnvelope(unit, o, progress, 1.0, 0);
  p.Seconds = seconds(t0);
  if (env.TooComplex && !progressCancelled(progress))
  {
    p.Ran = true;
    p.Components = env.Components;
    p.Genus = env.Genus;
  }
  return p;
}
} // namespace

int WideningGiveUpAbove(int target)
{
  return target + std::max(8, target / 5);
}

CageResult generateCage(const PolygonMesh& input, const CageOptions& options, Progress* progress)
{
  const auto start = std::chrono::steady_clock::now();
  const ThreadLimit threads(options.NumberOfThreads);
  PreparedInput prepared;
  {
    CageResult failed;
    if (!prepareInput(input, options, progress, prepared, failed))
    {
      return failed;
    }
  }
  std::string log;
  // The isovalue chosen first (CageOptions::ChooseIsoValueFirst), on coarse grids, for an input
  // of more parts than the target can carry apart (4 vertices each): its envelope reaches the
  // target only where the isovalue fuses them. From the widest isovalue below the last one
  // down, each probe that can carry the target lowers the choice; the first that cannot stops
  // the probing (a narrower envelope keeps even more apart). The widest allowed isovalue is
  // never probed: the widening ends there anyway.
  CageOptions first = options;
  int skipped = 0;
  int probes = 0;
  double probeSeconds = 0.0;
  const int maxWidenings = options.MaximumEnvelopeWidenings;
  if (options.ChooseIsoValueFirst && maxWidenings > 0 && options.TargetNumberOfVertices > 0 &&
    !prepared.Defects.usable() && !(options.Envelope.VoxelSize > 0) && options.Envelope.Sign != SignMode::FloodFill &&
    minimumCageVertices(static_cast<int>(prepared.Defects.Components), 0) > options.TargetNumberOfVertices)
  {
    progressStage(progress, "choosing the isovalue on coarse grids", 0.0, 1.0);
    skipped = maxWidenings; // the widest isovalue unless a probe can carry the target
    for (int k = maxWidenings - 1; k >= 0 && !progressCancelled(progress); --k)
    {
      const double iso = options.Envelope.IsoValue * static_cast<double>(1 << k);
      const Probe p = probeEnvelope(prepared.Unit, options.Envelope, iso, progress);
      ++probes;
      probeSeconds += p.Seconds;
      if (!p.Ran)
      {
        skipped = k; // failed (not cancelled): from here, as without probes
        break;
      }
      const int needed = minimumCageVertices(p.Components, p.Genus);
      const bool carries = needed <= options.TargetNumberOfVertices;
      std::ostringstream s;
      s << (log.empty() ? "" : "; ") << "isovalue " << iso << " probed on a grid of voxel "
        << ProbeVoxelFactor * iso / 2 << ": envelope of " << p.Components << " part(s), genus " << p.Genus
        << ", needs about " << needed << " vertices" << (carries ? "" : ": not built") << " (" << std::setprecision(3)
        << p.Seconds << " s)";
      log += s.str();
      if (!carries)
      {
        break;
      }
      skipped = k;
    }
    first.Envelope.IsoValue = options.Envelope.IsoValue * static_cast<double>(1 << skipped);
  }
  if (progressCancelled(progress))
  {
    CageResult cancelled;
    cancelled.State = Status::Cancelled;
    cancelled.Message = "cancelled";
    cancelled.Defects = prepared.Defects;
    cancelled.ValidationSeconds = prepared.ValidationSeconds;
    cancelled.WideningLog = log;
    cancelled.TotalSeconds = seconds(start);
    return cancelled;
  }
  const int allowed = options.MaximumEnvelopeWidenings - skipped; // fine-grid widenings left
  CageResult best = generateOnce(prepared, first, progress, allowed > 0);
  int attempts = 1;
  // A cage simplified from the coarse grid's envelope (EnvelopeOptions::CoarseFirst) that misses
  // its target (small targets: the coarse envelope's merged polygons leave the simplifier fewer
  // placements) is made again from the requested grid's envelope; the one with fewer vertices
  // is kept. (The grid requested is that of the isovalue built, which the probes may have
  // widened: its c/2 grid is no coarse grid.)
  if (best.State == Status::Ok && !best.TargetReached && options.TargetNumberOfVertices > 0 &&
    options.Envelope.CoarseFirst && best.VoxelSizeUsed > first.Envelope.voxelSize() * (1.0 + 1e-9) &&
    !progressCancelled(progress))
  {
    CageOptions requested = first;
    requested.Envelope.CoarseFirst = false;
    progressStage(progress, "the envelope on the requested grid, to reach the target", 0.0, 1.0);
    CageResult next = generateOnce(prepared, requested, progress, options.MaximumEnvelopeWidenings > 0);
    ++attempts;
    if (next.State == Status::Cancelled || (next.State == Status::Ok && next.VerticesReached < best.VerticesReached))
    {
      best = std::move(next);
    }
  }
  if (skipped > 0 && best.State != Status::Cancelled)
  {
    best.EnvelopeWidenings = skipped;
  }
  CageOptions wider = first;
  int tried = 0;
  auto note = [&log](const CageResult& r) {
    std::ostringstream s;
    s << (log.empty() ? "" : "; ") << "isovalue " << r.IsoValueUsed << ": envelope of " << r.EnvelopeComponents
      << " part(s), genus " << r.EnvelopeGenus << ", "
      << (r.EnvelopeTooComplex ? std::string("not simplified") : std::to_string(r.VerticesReached) + " vertices")
      << (r.Simplification.GaveUp ? " after the ordinary pass" : "") << " (" << std::setprecision(3)
      << r.TotalSeconds << " s: field " << r.DistanceFieldSeconds << " of which sign " << r.WindingSeconds
      << ", isosurface " << r.IsosurfaceSeconds << ", verification " << r.VerificationSeconds
      << ", simplification " << r.SimplificationSeconds << ")";
    log += s.str();
  };
  if (skipped > 0)
  {
    note(best);
  }
  for (int k = 0; wantsWidening(best, options, allowed - k, progress); ++k)
  {
    if (k == 0 && skipped == 0)
      note(best);
    tried = k + 1;
    wider.Envelope.IsoValue *= 2.0;
    progressStage(progress, "widening the envelope to reach the target", 0.0, 1.0);
    CageResult next = generateOnce(prepared, wider, progress, k + 1 < allowed);
    ++attempts;
    note(next);
    // keep the cage that reaches the target, or the one closest to it (on a tie, the tighter first one)
    if ((next.State == Status::Ok || next.EnvelopeTooComplex) &&
      (best.EnvelopeTooComplex || next.VerticesReached < best.VerticesReached))
    {
      next.EnvelopeWidenings = skipped + k + 1;
      next.StopReason = next.TargetReached ? std::string() : next.StopReason;
      best = std::move(next);
    }
    else if (next.State == Status::Cancelled)
    {
      break;
    }
  }
  if (best.VerificationDeferred && !progressCancelled(progress))
  {
    // no envelope reached the target and this one, the closest, is kept: built again the
    // ordinary way (verified first, then its cage), with everything else as it was
    CageOptions kept = first;
    kept.Envelope.IsoValue = best.IsoValueUsed;
    const int widenings = best.EnvelopeWidenings;
    // (a result is deferred only where a wider envelope could follow it)
    CageResult verified = generateOnce(prepared, kept, progress, true, false);
    ++attempts;
    verified.EnvelopeWidenings = widenings;
    best = std::move(verified);
  }
  else if (best.VerificationDeferred)
  {
    best = CageResult();
    best.Defects = prepared.Defects;
    best.State = Status::Cancelled;
    best.Message = "cancelled";
  }
  if ((tried > 0 || skipped > 0) && !best.TargetReached && best.State == Status::Ok)
  {
    best.StopReason += "; the envelope was widened " + std::to_string(tried + skipped) +
      " time(s), the cage with the fewest vertices is kept";
  }
  best.WideningLog = log;
  best.EnvelopeProbes = probes;
  best.IsoValuesSkipped = skipped;
  best.ProbeSeconds = probeSeconds;
  best.EnvelopeAttempts = attempts;
  best.TotalSeconds = seconds(start);
  return best;
}

} // namespace sdfcage
