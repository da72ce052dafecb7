// SDFCage — Core (internal): the OpenVDB part of the pipeline, kept in one translation unit
// because OpenVDB's mesh tools are slow to compile.
#pragma once

#include "Envelope.h"
#include "Mesh.h"

#include <string>
#include <vector>

namespace sdfcage
{

class Progress;

struct IsosurfaceOutput
{
  /// the isosurface {xi = iso} for each requested adaptivity, triangles (quads split), unit units
  std::vector<TriangleMesh> Surfaces;
  ScalarImage Field;      ///< for display: xi on a coarser grid (<= 256 per axis), interior filled
  bool Cancelled = false;
  std::string Error;
  double DistanceFieldSeconds = 0.0;
  double IsosurfaceSeconds = 0.0;
  std::size_t ActiveVoxels = 0;
};

/// Narrow-band SDF of a closed (possibly self-intersecting) mesh with OpenVDB (sign by flood
/// fill), wide enough outside for `iso`, then marching-cubes-style extraction at `iso`.
/// Progress: fractions 0..0.6 for the SDF, 0.6..1 for the surface of the current stage.
IsosurfaceOutput computeIsosurface(const TriangleMesh& unitInput, double voxelSize, double iso,
  bool keepField, Progress* progress, const std::vector<double>& adaptivities = { 0.0 });

} // namespace sdfcage
