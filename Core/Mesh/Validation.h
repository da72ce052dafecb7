// SDFCage — Core: turn a user's polygon mesh into a triangle mesh the pipeline can cage (repairing
// what can be repaired and counting it), or say why not.
#pragma once

#include "Mesh/Mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace sdfcage
{
class Progress;

/// Counts of everything validation found and repaired.
///
/// Any input with at least one usable triangle gets through prepareMesh (usableAsInput()):
/// coincident points are merged, every polygon is triangulated, degenerate and duplicated
/// triangles are dropped, all of it counted. What is left decides how the inside is chosen
/// (see SignMode in Envelope/Envelope.h): a closed, consistently oriented 2-manifold
/// (closedManifold()) keeps the flood-fill path; anything else (boundary edges, non-manifold
/// edges or vertices, inconsistent orientation) goes through the generalized winding number.
struct MeshDefects
{
  // fatal for an input (the file cannot be trusted), and for a cage
  bool Empty = false;               ///< no triangles after conversion and repair
  std::int64_t NonFinitePoints = 0; ///< referenced points with NaN/Inf coordinates
  std::int64_t InvalidPointIds = 0; ///< cell references outside the point list
  // fatal for a cage (usable()), reported and handled for an input
  std::int64_t UntriangulatedPolygons = 0; ///< polygons that could not be split (always 0 from prepareMesh)
  std::int64_t BoundaryEdges = 0;          ///< edges with one incident triangle (not closed)
  std::int64_t NonManifoldEdges = 0;       ///< edges with more than two incident triangles
  std::int64_t NonManifoldVertices = 0;    ///< vertices whose triangle fan is not one disk
  std::int64_t DegenerateTriangles = 0;    ///< zero-area triangles left (prepareMesh drops them: 0)
  std::int64_t InconsistentEdges = 0;      ///< edges used twice in the same direction
  // repairs of an input (informative)
  std::int64_t MergedPoints = 0;               ///< points merged into a coincident one (split seams)
  double MergeTolerance = 0.0;                 ///< the merge distance used (input units)
  std::int64_t TriangulatedPolygons = 0;       ///< quads/polygons split into triangles
  std::int64_t DroppedDegenerateTriangles = 0; ///< zero-area triangles dropped
  std::int64_t DroppedDuplicateTriangles = 0;  ///< repeated triangles (same three points) dropped
  std::int64_t IgnoredCells = 0;               ///< vertex and line cells (not surfaces)
  std::int64_t UnreferencedPoints = 0;         ///< points no triangle uses (dropped)
  int Components = 0;                          ///< connected components (several are allowed)
  int Genus = 0;                               ///< total genus (valid when closedManifold())
  bool FlippedOrientation = false;             ///< the closed mesh was inward and was flipped

  /// Strict: a closed, consistently oriented 2-manifold without degenerate triangles (what an
  /// envelope and a cage must be, and the input of the flood-fill path).
  bool usable() const;
  bool closedManifold() const { return usable(); }
  /// An input that can be caged: at least one triangle, finite points, valid ids.
  bool usableAsInput() const { return !Empty && NonFinitePoints == 0 && InvalidPointIds == 0; }
  /// One actionable sentence per defect that usable() rejects, e.g. "the mesh has 12 boundary
  /// edges (it is not closed)".
  std::string errorMessage() const;
  /// The same for what usableAsInput() rejects (empty when it accepts).
  std::string inputErrorMessage() const;
  /// Notes on what was repaired or found (merged points, triangulation, dropped triangles,
  /// ignored cells, flipped orientation, boundary and non-manifold edges).
  std::vector<std::string> warnings() const;
};

struct ValidationOptions
{
  /// Relative area threshold (to the squared bounding-box diagonal) under which a triangle counts
  /// as degenerate. 0 means exactly zero area only.
  double DegenerateAreaTolerance = 0.0;
  /// Points closer than this, at least one of them on a boundary edge, (relative to the bounding-box diagonal, per
  /// coordinate) are merged: far below any voxel size (1e-9 against 0.005 of the unit sphere), it
  /// only joins positions that are the same up to rounding, such as the split seams of a textured
  /// OBJ, an STL's separate facet corners or a scan's duplicated points. Points inside a closed
  /// surface are never merged (that would make non-manifold vertices). Negative: no merging.
  double MergeTolerance = 1e-9;
};

/// Validates, converts and repairs: merges coincident points, triangulates every polygon
/// (convex planar ones by a fan as before, others by ear clipping in their best-fit plane),
/// drops degenerate and duplicated triangles and unreferenced points, ignores vertex/line cells,
/// measures closedness, manifoldness and orientation consistency, and flips a closed
/// inward-oriented mesh. `output` is valid when the returned defects are usableAsInput().
/// With `progress`, cancel checks between its steps and inside them (every 65,536 cells,
/// triangles or vertices of a loop, every chunk of a sort: CancellableSort.h): once cancelled it
/// returns at the next one with `output` empty (the caller tells a cancel by
/// progress->cancelled(), not by the defects).
MeshDefects prepareMesh(const PolygonMesh& input, TriangleMesh& output,
  const ValidationOptions& options = ValidationOptions(), Progress* progress = nullptr);

/// Genus of a closed 2-manifold triangle mesh (MeshDefects::closedManifold()) of `components`
/// connected parts: every edge has two triangles, so E = 3F/2 and no edge list is sorted (the
/// same value as Mesh.h's genus(), which works on any mesh, in a fraction of its time).
int closedManifoldGenus(const TriangleMesh& mesh, int components);

/// The same checks on a triangle mesh, without conversion or flipping (used to check envelopes
/// and cages). Orientation is reported through InconsistentEdges only.
MeshDefects checkTriangleMesh(const TriangleMesh& mesh);

} // namespace sdfcage
