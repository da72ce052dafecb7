// SDFCage — Core: active points of a mesh in its own coordinates (what vtkActivePointFilter
// shows): validation, normalization, detection, g_A, and optionally the sampled fields.
#pragma once

#include "Envelope/ActivePoints.h"
#include "Common/Status.h"
#include "Mesh/Normalization.h"
#include "Mesh/Validation.h"

namespace sdfcage
{

struct ActivePointAnalysisOptions
{
  ActivePointOptions ActivePoints;
  ValidationOptions Validation;
  /// Sample xi and phi * xi on a regular grid (at most ~256 per axis) for display.
  bool GenerateFields = false;
  /// Isovalue c, only to size the display grid's margin (unit-sphere units).
  double IsoValue = 0.01;
  /// Worker threads (0 = all cores), as CageOptions::NumberOfThreads.
  int NumberOfThreads = 0;
};

struct ActivePointAnalysis
{
  Status State = Status::Failed;
  std::string Message;
  MeshDefects Defects;
  TriangleMesh Mesh;                     ///< the validated input, input coordinates
  std::vector<std::uint8_t> Active;      ///< per Mesh point
  /// Per Mesh point, the rule that made it active: 0 not active, 1 the paper's (closer than r in
  /// space, farther than l along the surface), 2 the facing-gap rule (ActivePointOptions::
  /// GapRatio, what a topology repair round adds): within half a sample spacing (in space) of a
  /// sample only that rule found.
  std::vector<std::uint8_t> ActiveRule;
  std::vector<double> GeodesicToActive;  ///< g_A per Mesh point, input units (clamped at the cutoff)
  std::vector<double> Amplification;     ///< phi on the surface: phi(g_A)
  std::size_t NumberOfActivePoints = 0;  ///< Mesh points flagged active
  std::size_t NumberOfActiveSamples = 0; ///< size of the active set on the surface sampling
  std::size_t NumberOfSamples = 0;
  std::size_t NumberOfGapSamples = 0;    ///< of the active samples, those only the facing-gap rule found
  std::size_t NumberOfGapRulePoints = 0; ///< Mesh points with ActiveRule 2
  ScalarImage SignedDistance;         ///< xi, input coordinates and units (GenerateFields)
  ScalarImage ModifiedSignedDistance; ///< phi * xi, same grid
  double Seconds = 0.0;
};

ActivePointAnalysis analyzeActivePoints(
  const PolygonMesh& input, const ActivePointAnalysisOptions& options, Progress* progress = nullptr);

} // namespace sdfcage
