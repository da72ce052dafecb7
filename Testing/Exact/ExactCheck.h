// SDFCage — Testing: an independent, exact-predicate check of a cage against its input mesh.
//
// This is the referee of the test suite. It shares no code with Core (only the plain mesh
// structs of Mesh.h) and uses CGAL's Epick kernel, whose predicates (orientation, coplanarity,
// triangle/segment intersection, side of a closed mesh) are exact. CGAL is a test-only
// dependency: Core and Filters never link it.
#pragma once

#include "Mesh/Mesh.h"

#include <string>

namespace sdfcage
{
namespace exact
{

/// Everything exactCheck() measured. Counts refer to the cage unless named otherwise.
struct ExactReport
{
  // --- topology of the cage (by point index) ---
  long long BoundaryEdges = 0;       ///< undirected edges used by exactly one triangle
  long long NonManifoldEdges = 0;    ///< undirected edges used by more than two triangles
  long long NonManifoldVertices = 0; ///< vertices whose incident triangles form more than one fan
  /// Non-empty, every id valid, every point finite, no boundary or non-manifold edge/vertex.
  bool Closed2Manifold = false;

  // --- geometry (exact predicates) ---
  /// Pairs of cage triangles that intersect beyond what they share: disjoint-index pairs that
  /// touch at all, vertex-sharing pairs that meet anywhere but the shared vertex, edge-sharing
  /// pairs that overlap (coplanar, same side), duplicated triangles. Each degenerate (zero-area)
  /// cage triangle also counts once, as CGAL's PMP::self_intersections reports it.
  long long SelfIntersections = 0;
  /// Intersecting (touching counts) cage-triangle / input-triangle pairs.
  long long InputIntersections = 0;
  /// Referenced input vertices not strictly inside the cage by CGAL::Side_of_triangle_mesh
  /// (on the cage counts as outside). When the cage is not a closed manifold, or has degenerate
  /// triangles, inside/outside is unknown and every input vertex counts as outside.
  long long InputVerticesOutside = 0;
  /// Minimum distance between cage triangles and input triangles (0 when they intersect), in
  /// the meshes' own units. Exact up to the rounding of the distance formulas. When no pair is
  /// within the query limit this is the limit itself and ClearanceIsLowerBound is true.
  double MinimumClearance = 0.0;
  bool ClearanceIsLowerBound = false;

  // --- cage topology summary ---
  int CageGenus = 0;      ///< sum over components of (2 - chi_i) / 2 (meaningful when closed)
  int CageComponents = 0; ///< connected components over shared vertices

  /// Closed2Manifold && SelfIntersections == 0 && InputIntersections == 0 &&
  /// InputVerticesOutside == 0.
  bool Encloses = false;

  // --- extra diagnostics (not part of Encloses) ---
  long long DegenerateTriangles = 0; ///< cage triangles with repeated ids or collinear points
  long long InconsistentEdges = 0;   ///< cage edges used twice in the same direction
  long long InvalidTriangles = 0;    ///< cage triangles with out-of-range ids or non-finite points
  long long CageTriangles = 0;
  long long InputTriangles = 0;
  double ClearanceQueryLimit = 0.0; ///< the limit actually used
  double Seconds = 0.0;             ///< wall time of exactCheck
  /// Wall time of its phases: topology, self-intersections, cage/input pairs, inside test.
  double PhaseSeconds[4] = { 0.0, 0.0, 0.0, 0.0 };
};

/// Checks that `cage` strictly encloses `input` (both in the same coordinates). Distances up to
/// `clearanceQueryLimit` are measured exactly; a limit <= 0 (or not finite) means 2% of the input's
/// bounding-box diagonal. Never throws or crashes on broken cages (open, non-manifold, empty,
/// invalid ids, NaN points): it reports counts.
ExactReport exactCheck(const TriangleMesh& input, const TriangleMesh& cage, double clearanceQueryLimit);

/// The report as one JSON object (field names as in ExactReport).
std::string toJson(const ExactReport& report);

} // namespace exact
} // namespace sdfcage
