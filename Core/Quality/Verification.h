// SDFCage — Core: the independent acceptance check of any envelope or cage against its input
// (closed 2-manifold, no self-intersection, exact clearance, every input component inside), used
// by the envelope, the simplification's final check and the optimization.
#pragma once

#include "Mesh/Mesh.h"

#include <string>
#include <vector>

namespace sdfcage
{

class Progress;
class TriangleTree;

/// Pairs of triangles of `mesh` that conflict (Spatial/Geometry.h trianglesConflict): sharing no
/// vertex and closer than `touching` (or crossing), sharing one vertex and meeting elsewhere,
/// sharing an edge and folded exactly onto each other, or repeating the same three vertices.
/// `touching` < 0: 1e-12 of the mesh size. Threaded. The one count of the envelope and cage
/// checks and of the quality judge (Quality/CageQuality.h).
long long countSelfIntersections(const TriangleMesh& mesh, Progress* progress = nullptr, double touching = -1.0);

/// Independent check used by buildEnvelope and by tests: closed 2-manifold without
/// self-intersections, every triangle of
/// `cage` at least `clearance` from `input` (exact distances), and one point of every input
/// component inside (winding number). Returns the measured exact minimum clearance in
/// `measuredClearance` (with exactMinimum; otherwise a certified lower bound >= clearance, much
/// cheaper on dense surfaces) and per-cage-point exact distances in `pointDistances` (if non-null).
/// `inputTree`, if given, must index `input` (saves building it).
bool verifyEnclosure(const TriangleMesh& input, const TriangleMesh& cage, double clearance, double& measuredClearance,
  std::string& why, std::vector<double>* pointDistances = nullptr, Progress* progress = nullptr,
  bool exactMinimum = true, const TriangleTree* inputTree = nullptr);

} // namespace sdfcage
