// SDFCage — Core: active points, geodesic distance to them and the amplification of the SDF
// (paper §3.1, eq. 2–3). No VTK, no OpenVDB.
#pragma once

#include "Mesh/Mesh.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sdfcage
{

class Progress;

/// All lengths in unit-sphere units (the input is normalized first).
struct ActivePointOptions
{
  /// r: a surface point p is active when some surface point q with |p - q| < r is farther than
  /// l from p along the surface (or on another component).
  double Radius = 0.025;
  /// l: the geodesic threshold.
  double GeodesicThreshold = 0.15;
  /// alpha > 1: the amplification at the active points (the envelope there lies at c / alpha).
  double Alpha = 3.0;
  /// beta: how fast the amplification decays with the distance d^ (eq. 3).
  double Beta = 8.0;
  /// Spacing of the surface sampling; 0 = automatic (Radius). The input is refined (edge
  /// splits, the shape is unchanged) until no edge is longer than this, so coarse inputs are
  /// sampled as densely as fine ones; detection runs on samples at least half of it apart.
  double SampleSpacing = 0.0;
  /// The facing-gap rule (beyond the paper's; 0 = off, the paper's rule only): a surface point p
  /// is also active when some point q closer than r faces it across air (the outward normal of
  /// each points at the other, within 60 degrees) and is farther from p along the surface than
  /// GapRatio |p - q| + the sample spacing. It finds parts that nearly touch close to where they
  /// join (a leg beside the body, a claw near the head, a finger near its base), where the
  /// geodesic distance stays below l, while flat and convex regions and open concave creases
  /// (along-surface / straight-line distance below GapRatio) stay inactive. The envelope's
  /// topology repair turns it on (3) when the envelope's genus or parts differ from the input's.
  double GapRatio = 0.0;
  /// Adaptivity (merged polygons) is switched off in the isosurface where the amplification phi
  /// exceeds 1 + AdaptivityOffFraction (alpha - 1): there the envelope lies closest to the input
  /// (see amplify in SDFIsosurface.cxx).
  double AdaptivityOffFraction = 0.5;

  double sampleSpacing() const { return SampleSpacing > 0 ? SampleSpacing : Radius; }
  /// Beyond this geodesic distance phi - 1 < (alpha - 1) * 1e-7: g_A is clamped there.
  double geodesicCutoff() const { return 4.0 / Beta; }
  /// Empty when valid, otherwise what is wrong.
  std::string validate() const;
};

/// The result: a refined copy of the surface (the input's points first, in the same order, then
/// the points inserted on split edges; the same shape) with per-point values.
struct ActivePoints
{
  TriangleMesh Surface;                ///< refined input, unit-sphere units
  std::size_t NumberOfInputPoints = 0; ///< Surface.Points[0, n) are the input's points
  std::vector<std::uint8_t>
    Active; ///< per Surface point: 1 = active (sample or within half a spacing of an active sample)
  std::vector<double> GeodesicToActive;      ///< g_A per Surface point, clamped to the cutoff
  std::size_t NumberOfSamples = 0;           ///< points tested
  std::size_t NumberOfActiveSamples = 0;     ///< samples found active (the active set A)
  std::size_t NumberOfActivePoints = 0;      ///< Surface points flagged in Active
  std::size_t NumberOfActiveInputPoints = 0; ///< of those, input points
  std::size_t NumberOfGapSamples = 0;        ///< of the active samples, those found by the facing-gap rule only
  std::vector<int> GapSamples;               ///< those samples (Surface point ids)
  double Alpha = 3.0;
  double Beta = 8.0;
  double AdaptivityOffFraction = 0.5; ///< see ActivePointOptions
  double Cutoff = 0.5;
  double Seconds = 0.0;
  bool Cancelled = false;

  bool empty() const { return NumberOfActiveSamples == 0; }
  /// phi(d^) = (alpha - 1) exp(-beta^2 d^2) + 1 (eq. 3).
  double phi(double dHat) const;
  /// g_A at a point of Surface triangle t given by barycentric weights (linear interpolation).
  double geodesicAt(int t, const Vec3& barycentric) const;
  /// phi at a point x whose closest surface point lies on Surface triangle t at `closest`, at
  /// unsigned distance `distance` from the surface: d^ = g_A(P_M(x)) + d_M(x) (eq. 2).
  double amplificationAt(int t, const Vec3& closest, double distance) const;
};

/// Detects the active points of a closed, normalized mesh and the geodesic distance to them.
/// Geodesic distances are shortest paths along the edges of the refined surface (a slight
/// overestimate of the true geodesic distance), each search ending as soon as every Euclidean
/// neighbour is reached. Threaded and deterministic.
ActivePoints computeActivePoints(
  const TriangleMesh& unitInput, const ActivePointOptions& options, Progress* progress = nullptr);

/// One round of conforming red-green refinement: every edge for which split(a, b) (symmetric)
/// holds gets its midpoint, appended to mesh.Points (with its edge in `parents`); triangles are
/// split 1-2, 1-3 or 1-4 keeping their orientation. Returns the number of midpoints added.
std::size_t splitEdges(
  TriangleMesh& mesh, const std::function<bool(int, int)>& split, std::vector<std::array<int, 2>>* parents = nullptr);

/// Splits edges (conforming red-green refinement) until none is longer than `maxEdge`; the
/// points of `mesh` keep their indices. Stops after `maxTriangles` triangles (returns false).
bool refineMesh(const TriangleMesh& mesh, double maxEdge, TriangleMesh& refined, std::size_t maxTriangles = 20000000);

} // namespace sdfcage
