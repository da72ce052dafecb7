// SDFCage — Core: strictly nested cages (paper §4, Fig. 9): a list of vertex counts gives one
// cage per count, each enclosing the next finer one (and so the input) with the clearance.
#pragma once

#include "Pipeline/CageGenerator.h"
#include "Pipeline/Results.h"

#include <string>
#include <vector>

namespace sdfcage
{

/// One level of a nested hierarchy.
struct NestedLevel
{
  int TargetNumberOfVertices = 0;
  /// The run that built this level. Level 0's input is the input mesh; level k's is level k-1's
  /// cage, so its Envelope, CageDistanceToInput, InputGenus, ... refer to that cage (the level
  /// inside). Its Cage is in the input's coordinates.
  CageResult Result;
  /// Verification (Quality/Verification.h verifyEnclosure, exact minimum distances): level 0 by
  /// the pipeline's own final check against the input; level k >= 1 re-verified in the input's
  /// coordinates against the level inside it (with its clearance) and against the input (with
  /// level 0's clearance).
  bool VerifiedAgainstInside = false;
  double ClearanceToInside = 0.0; ///< measured exact minimum distance, input units
  bool VerifiedAgainstInput = false;
  double ClearanceToInput = 0.0;   ///< measured exact minimum distance, input units
  std::string VerificationMessage; ///< why a re-verification failed (empty when both passed)
  int CageGenus = 0;               ///< of this cage (sum over its parts)
  int CageComponents = 0;
  /// Genus and parts equal to the input's (closed input; always false for an input without a
  /// defined topology).
  bool TopologyKept = false;
  double Seconds = 0.0; ///< this level's run and re-verification
};

struct NestedCageResult
{
  /// Ok when every level was built and verified; otherwise the state of the level that stopped
  /// the run (its predecessors are kept in Levels, each valid and verified).
  Status State = Status::Failed;
  std::string Message;
  std::vector<int> Counts;         ///< the counts used, finest first (sorted descending)
  std::vector<NestedLevel> Levels; ///< finest first; Levels.size() <= Counts.size()
  double TotalSeconds = 0.0;
};

/// Sorts `counts` descending (finest level first). Returns "" when they can be used, otherwise
/// the reason (empty list, a count below 1, a count given twice), with `counts` unchanged.
std::string sortNestedCounts(std::vector<int>& counts);

/// Parses "2000,500,100" (commas, optional spaces) into counts; "" on success, else the reason.
/// The counts are not sorted or checked beyond being integers in [1, INT_MAX].
std::string parseNestedCounts(const std::string& text, std::vector<int>& counts);

/// Builds the levels finest first. Level 0 is generateCage(input, options) at the largest count;
/// level k reruns the whole method on level k-1's cage (the paper's procedure, §4): its envelope
/// is the verified offset of that cage and its simplification keeps the clearance from it, so it
/// encloses every finer level and the input (a surface outside a closed surface that contains
/// the input is at least as far from the input as from that surface). Each level is then
/// re-verified in the input's coordinates against the level inside it and against the input.
/// Levels k >= 1 use options as given, except: their inside is decided by flood fill (a cage is
/// a closed 2-manifold), no distance field is kept, and active points are used only when level 0
/// found some (the input has nearly touching parts that the cages must keep apart). Progress is split evenly over the levels.
NestedCageResult generateNestedCages(
  const PolygonMesh& input, std::vector<int> counts, const CageOptions& options, Progress* progress = nullptr);

/// The nested results of one level (Level, TargetNumberOfVertices, VerifiedAgainstInside,
/// ClearanceToInside, VerifiedAgainstInput, ClearanceToInput, CageGenus, CageComponents,
/// TopologyKept, LevelTime) for field data and reports; `index` is the level's position, 0 the
/// finest.
ResultTable nestedLevelResults(const NestedLevel& level, int index);

} // namespace sdfcage
