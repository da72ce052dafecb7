// SDFCage — Core: judge any cage against the mesh it should enclose (distances, shape quality,
// topology and an exact-in-effect enclosure verdict). Works on broken cages too and says what is
// wrong instead of failing.
#pragma once

#include "Mesh/Mesh.h"

#include <string>
#include <vector>

namespace sdfcage
{

class Progress;

struct CageQualityOptions
{
  /// Two triangles closer than TouchingTolerance x D count as touching (D: the larger of the
  /// input's and the cage's bounding-box diagonals). The distance formulas of Geometry.h return
  /// 0 for triangles whose edges cross cleanly and are exact up to double rounding (about 1e-16
  /// x the coordinates) otherwise; but a crossing whose edge endpoint lies within 1e-10 (relative
  /// to the edge) of the other triangle's plane is left to those distances, which then come out
  /// as (at most about) that depth. 1e-10 therefore counts such crossings as touching and still
  /// separates touching from any real clearance: a cage with clearance 1e-6 x diagonal is judged
  /// by four orders of magnitude.
  double TouchingTolerance = 1e-10;
  /// The Hausdorff distances are certified by branch and bound to within this absolute gap
  /// (relative to the input's bounding-box diagonal) unless the evaluation budget runs out; the
  /// bounds actually reached are reported either way.
  double HausdorffTolerance = 1e-4;
  /// Maximum number of extra point-distance evaluations per Hausdorff direction.
  long long HausdorffBudget = 400000;
  /// Each cage triangle is split into 4^L sub-triangles whose centroids give the area-weighted
  /// mean distance (midpoint rule) and samples for the per-cell maximum: L is the smallest level
  /// that brings the sub-triangles' edges to MeanDistanceSpacing x diagonal, at least
  /// MinimumMeanDistanceLevel and at most 6 (4096 points per triangle).
  double MeanDistanceSpacing = 0.02;
  int MinimumMeanDistanceLevel = 2;
};

/// The phases of evaluateCage(), in the order they run (an evaluation may end after any of them:
/// empty meshes after SelfIntersections, a cancel after any).
enum class CageQualityPhase
{
  Topology,          ///< valid triangles, triangle shapes, cage defects and genus, the search trees
                     ///< (the input's topology runs beside all phases)
  SelfIntersections, ///< intersecting or touching non-adjacent cage triangle pairs
  PointDistances,    ///< exact distance of every point to the other surface, both ways
  Clearance,         ///< exact minimum distance between the surfaces (and touching pairs)
  InsideTest,        ///< input vertices strictly inside the cage (winding number)
  MeanDistance,      ///< area-weighted mean distance over the cage (quadrature)
  Hausdorff          ///< Hausdorff distances both ways (branch and bound)
};

/// Everything evaluateCage() measured. Lengths in the meshes' own units; "Relative" values are
/// divided by the input's bounding-box diagonal. Counts refer to the cage unless named otherwise.
///
/// **Encloses** means: the cage is non-empty, every cell has valid ids and finite points, it is a
/// closed 2-manifold (no boundary or non-manifold edge or vertex), consistently oriented, without
/// degenerate (zero-area) triangles; no two non-adjacent cage triangles intersect or touch
/// (SelfIntersections == 0); no cage triangle intersects or touches an input triangle
/// (InputIntersections == 0); and every input vertex is strictly inside the cage (its winding
/// number is odd, and it does not lie on the cage). Touching means a computed distance <=
/// TouchingTolerance x D (see CageQualityOptions). Then MinimumClearance > 0 is the exact distance between the
/// two surfaces. Orientation (inward or outward) is reported but not required.
struct CageQualityResult
{
  bool Encloses = false;
  /// Why the cage does not enclose (one sentence per reason), or what could not be evaluated.
  std::string Message;

  // --- per cage point / cell (sizes: cage points, cage triangles) ---
  std::vector<double> PointDistance; ///< exact distance of each cage point to the input
  /// Per cage triangle: the largest distance to the input found on it (corners, quadrature
  /// points and branch-and-bound samples): a lower bound of the maximum over the triangle.
  std::vector<double> CellDistance;
  std::vector<double> CellMinimumAngle; ///< degrees; 0 for degenerate triangles
  /// MIPS energy against an equilateral reference (paper eq. 8, per triangle):
  /// (a^2 + b^2 + c^2) / (2 sqrt(3) area); 2 for an equilateral triangle, +inf when degenerate.
  std::vector<double> CellMIPSEnergy;

  // --- distances ---
  double Diagonal = 0.0;                  ///< input bounding-box diagonal
  double MinimumClearance = 0.0;          ///< exact min distance between the surfaces (0 if they touch)
  double HausdorffCageToInput = 0.0;      ///< max over the cage surface of the distance to the input (value reached)
  double HausdorffCageToInputBound = 0.0; ///< certified upper bound of it
  double HausdorffInputToCage = 0.0;      ///< max over the input surface of the distance to the cage (value reached)
  double HausdorffInputToCageBound = 0.0; ///< certified upper bound of it
  double MeanDistanceCageToInput = 0.0;   ///< area-weighted mean over the cage surface (quadrature)
  double MaximumPointDistance = 0.0;      ///< max of PointDistance
  double MeanPointDistance = 0.0;         ///< mean of PointDistance

  // --- counts ---
  long long SelfIntersections = 0;  ///< intersecting non-adjacent cage triangle pairs (+1 per degenerate triangle)
  long long InputIntersections = 0; ///< intersecting or touching cage/input triangle pairs
  /// Input vertices not strictly inside the cage. When inside/outside is undefined (the cage is
  /// not a closed 2-manifold, is inconsistently oriented or has degenerate triangles) every input
  /// vertex counts as outside.
  long long InputVerticesOutside = 0;
  long long InputVertices = 0; ///< referenced input vertices

  // --- cage defects (Validation.h terms) ---
  long long InvalidTriangles = 0; ///< ids out of range or non-finite points (ignored otherwise)
  long long BoundaryEdges = 0;
  long long NonManifoldEdges = 0;
  long long NonManifoldVertices = 0;
  long long DegenerateTriangles = 0;
  long long InconsistentEdges = 0;
  bool CageClosedManifold = false;
  bool CageInwardOriented = false;
  int CageComponents = 0;
  int CageGenus = -1;  ///< -1 when the cage is not a closed 2-manifold
  int InputGenus = -1; ///< -1 when the input is not a closed 2-manifold
  bool InputClosedManifold = false;
  long long InputInvalidTriangles = 0;

  double Seconds = 0.0;
  /// Wall time of each phase, indexed by CageQualityPhase (phaseSeconds()); named by PhaseNames.
  double PhaseSeconds[7] = { 0, 0, 0, 0, 0, 0, 0 };
  static constexpr const char* PhaseNames[7] = { "topology", "self-intersections", "point distances", "clearance",
    "inside test", "mean distance", "Hausdorff" };
  double phaseSeconds(CageQualityPhase phase) const { return PhaseSeconds[static_cast<int>(phase)]; }
};

/// Judges `cage` against `input` (same coordinates). Never throws on bad meshes: an empty or
/// broken cage or input gives Encloses false and a Message. Threaded with TBB; results do not
/// depend on the thread count. Cancelling (through `progress`) returns early with Encloses false
/// and Message "cancelled".
CageQualityResult evaluateCage(const TriangleMesh& input, const TriangleMesh& cage,
  const CageQualityOptions& options = CageQualityOptions(), Progress* progress = nullptr);

/// Minimum angle (degrees) and MIPS energy of one triangle.
double triangleMinimumAngle(const Vec3& a, const Vec3& b, const Vec3& c);
double triangleMIPSEnergy(const Vec3& a, const Vec3& b, const Vec3& c);

} // namespace sdfcage
