// SDFCage — Core: turn a user's polygon mesh into a usable closed triangle mesh, or say why not.
#pragma once

#include "Mesh/Mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace sdfcage
{

/// Counts of everything validation found. A mesh is usable when none of the fatal counts is
/// non-zero (see usable()).
struct MeshDefects
{
  // fatal
  bool Empty = false;                     ///< no triangles after conversion
  std::int64_t NonFinitePoints = 0;       ///< referenced points with NaN/Inf coordinates
  std::int64_t InvalidPointIds = 0;       ///< cell references outside the point list
  std::int64_t UntriangulatedPolygons = 0; ///< polygons that could not be split safely
  std::int64_t BoundaryEdges = 0;         ///< edges with one incident triangle (not closed)
  std::int64_t NonManifoldEdges = 0;      ///< edges with more than two incident triangles
  std::int64_t NonManifoldVertices = 0;   ///< vertices whose triangle fan is not one disk
  std::int64_t DegenerateTriangles = 0;   ///< zero-area triangles (repeated or collinear points)
  std::int64_t InconsistentEdges = 0;     ///< edges used twice in the same direction
  // informative
  std::int64_t TriangulatedPolygons = 0;  ///< quads/polygons split into triangles
  std::int64_t IgnoredCells = 0;          ///< vertex and line cells (not surfaces)
  std::int64_t UnreferencedPoints = 0;    ///< points no triangle uses (dropped)
  int Components = 0;                     ///< connected components (several are allowed)
  int Genus = 0;                          ///< total genus (valid when usable)
  bool FlippedOrientation = false;        ///< the closed mesh was inward and was flipped

  bool usable() const;
  /// One actionable sentence per fatal defect, e.g. "the mesh has 12 boundary edges: it must be
  /// closed (watertight); fill holes first, e.g. with vtkFillHolesFilter".
  std::string errorMessage() const;
  /// Non-fatal notes (triangulation, flipped orientation, ignored cells).
  std::vector<std::string> warnings() const;
};

struct ValidationOptions
{
  /// Relative area threshold (to the squared bounding-box diagonal) under which a triangle counts
  /// as degenerate. 0 means exactly zero area only.
  double DegenerateAreaTolerance = 0.0;
};

/// Validates and converts: triangulates polygons where safe (convex, planar within tolerance),
/// ignores vertex/line cells, drops unreferenced points, checks closedness, manifoldness,
/// degeneracy and orientation consistency, and flips an inward-oriented mesh.
/// `output` is valid only when the returned defects are usable().
MeshDefects prepareMesh(const PolygonMesh& input, TriangleMesh& output,
  const ValidationOptions& options = ValidationOptions());

/// The same checks on a triangle mesh, without conversion or flipping (used to check envelopes
/// and cages). Orientation is reported through InconsistentEdges only.
MeshDefects checkTriangleMesh(const TriangleMesh& mesh);

} // namespace sdfcage
