// SDFCage — Core (internal): the OpenVDB part of the pipeline, kept in one translation unit
// because OpenVDB's mesh tools are slow to compile.
#pragma once

#include "Envelope/Envelope.h"
#include "Mesh/Mesh.h"

#include <functional>
#include <string>
#include <vector>

namespace sdfcage
{

class Progress;
class TriangleTree;
struct ActivePoints;

struct IsosurfaceOutput
{
  /// the isosurface {xi = iso} for each requested adaptivity, triangles (quads split), unit units
  std::vector<TriangleMesh> Surfaces;
  ScalarImage Field;         ///< for display: xi on a coarser grid (<= 256 per axis), interior filled
  ScalarImage ModifiedField; ///< with amplification and keepField: phi * xi on the same grid
  bool Cancelled = false;
  std::string Error;
  double DistanceFieldSeconds = 0.0;
  double IsosurfaceSeconds = 0.0; ///< the extractions and the display field (not the judge's time)
  std::size_t ActiveVoxels = 0;
  std::size_t AmplifiedVoxels = 0;    ///< voxels whose value phi changed by more than 1e-3
  std::size_t ExactVoxels = 0;        ///< with a LocalExactField: the voxels computed exactly near its sites
  double AmplificationSeconds = 0.0;  ///< xi -> phi xi on the grid (part of DistanceFieldSeconds)
  double WindingSeconds = 0.0;        ///< the winding-number sign (part of DistanceFieldSeconds)
  std::size_t WindingEvaluations = 0; ///< voxels whose winding number was evaluated
  std::size_t InsideVoxels = 0;       ///< of those, the ones found inside
  double AcceptedAdaptivity = 0.0;    ///< with a judge: the adaptivity of the accepted surface
  int Repairs = 0;                    ///< with a judge: re-extractions with a larger no-adaptivity region
  std::size_t FieldTriangles = 0;     ///< the triangles the distance field was computed from
};

/// Judges an extracted surface: true accepts it. Otherwise `repairNear` may receive points (unit-
/// sphere units) where the surface is wrong: the same adaptivity is tried again with adaptivity
/// switched off around them (merged polygons are what goes wrong), else the next adaptivity.
using SurfaceJudge = std::function<bool(const TriangleMesh& surface, double adaptivity, std::vector<Vec3>& repairNear)>;

/// Narrow-band SDF of a closed (possibly self-intersecting) mesh with OpenVDB (sign by flood
/// fill), wide enough outside for `iso`, then marching-cubes-style extraction at `iso`.
/// Progress: fractions 0..0.6 for the SDF, 0.6..1 for the surface of the current stage.
/// With `amplification`, the field is the amplified xi^ = phi * xi of paper eq. 2–3 (outside the
/// input; inside, xi is kept: its sign is all the isosurface at iso > 0 needs) and the distance
/// field is computed on amplification->Surface (the refined input, same shape), whose triangles
/// the closest-triangle ids refer to; `unitInput` is then unused. Adaptivity is switched off
/// near active points.
/// Without `judge`, Surfaces holds one surface per adaptivity. With it, the adaptivities are tried
/// in order (each up to 1 + maxRepairs times, see SurfaceJudge) and Surfaces holds the first
/// accepted surface only (empty if none).
/// `sign` other than FloodFill computes the unsigned distance: from `windingTree` when given (the
/// input's tree; exact distances, one query per voxel near the input, see unsignedBandField in
/// the .cxx), else with OpenVDB's meshToVolume (which overestimates some of the band's far
/// voxels: up to 0.03 at voxel 0.04 on the benchmark's soup); with WindingNumber, the
/// voxels whose sign matters for the isosurface at `iso` (value >= iso) are made negative where
/// `windingTree` (the input's tree, prepareWindingNumbers() done) gives |w| > 1/2. The deep inside
/// beyond the band reads as outside then and yields inward-facing pockets, which the envelope
/// removes with the others.
///
/// `local` (with amplification and the flood-fill sign only): the field is exact only near the
/// gaps the grid twice as coarse may fuse: neighbouring coarse voxels whose closest points lie
/// on surfaces facing each other across the space between them, dilated by local->Dilation
/// coarse voxels. There every voxel is a query of local->Tree (over amplification->Surface),
/// signed by the angle-weighted pseudo-normal of its closest feature. Elsewhere the field is the
/// amplified field of the coarse grid, trilinearly interpolated: the finer grid only resolves
/// the same surface more finely there (the envelope's points are projected onto the exact
/// amplified offset and the envelope is verified, as always).
struct LocalExactField
{
  int Dilation = 0; ///< exact within this many coarse voxels of a facing gap
  const TriangleTree* Tree = nullptr;
};
IsosurfaceOutput computeIsosurface(const TriangleMesh& unitInput, double voxelSize, double iso, bool keepField,
  Progress* progress, const std::vector<double>& adaptivities = { 0.0 }, const ActivePoints* amplification = nullptr,
  const SurfaceJudge* judge = nullptr, int maxRepairs = 3, SignMode sign = SignMode::FloodFill,
  const TriangleTree* windingTree = nullptr, bool clusteredField = false, const LocalExactField* local = nullptr);

/// How many isosurface extractions a cancel has abandoned since the process started (each ends
/// on its own thread and frees its memory; the process waits for them at exit). For tests and
/// diagnostics: it tells a cancel answered from inside an extraction from one answered after it.
long long abandonedExtractionCount();

/// For display: xi sampled on a regular grid over the mesh's box plus a margin (spacing at least
/// `minSpacing`, at most ~256 samples per axis), interior filled, exterior band wide enough to
/// show the amplification. With `amplification` (non-empty) and `modified`, also phi * xi on the
/// same grid (amplification->Surface is then the mesh). False with `error` on failure.
bool computeDisplayFields(const TriangleMesh& unitMesh, double iso, double minSpacing,
  const ActivePoints* amplification, ScalarImage& field, ScalarImage* modified, std::string& error);

} // namespace sdfcage
