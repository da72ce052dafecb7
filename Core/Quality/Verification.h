// SDFCage — Core: the independent acceptance check of any envelope or cage against its input
// (closed 2-manifold, no self-intersection, exact clearance, every input component inside), used
// by the envelope, the simplification's final check and the optimization.
#pragma once

#include "Mesh/Mesh.h"

#include <memory>
#include <string>
#include <vector>

namespace sdfcage
{

class Progress;
class TriangleTree;
struct MeshDefects;

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

/// What a verification learned about one surface, for the verification of the next surface
/// when that one keeps most of its triangles: an adaptive envelope that failed is extracted again
/// with adaptivity off around its defects only, and 90-96% of its triangles come back with the
/// same corners (octopus-low, armadillo at the defaults). Create one per sequence of surfaces of
/// the same input, clearance and grid.
struct VerificationMemo
{
  /// Of the surface last checked, one flag per triangle: 1 where it conflicts with another
  /// triangle (as countSelfIntersections counts) or comes closer than the clearance to the input.
  /// Every triangle is judged: the check does not stop at the first failure.
  std::vector<char> Defective;
  /// Triangles that the next check takes from this memo instead of testing them.
  std::size_t Reused = 0;
  struct Store;
  std::shared_ptr<Store> Known; ///< what the next surface may reuse (internal)
};

/// What the caller knows of a surface's clearance before its check: no input triangle comes
/// closer than `Distance` to a triangle whose three corners all have ids below `Below` (the
/// adaptive envelope's lifting measured every triangle of the extraction, whose points come
/// first, and split every one it found closer).
struct KnownClearTriangles
{
  std::size_t Below = 0;
  double Distance = 0.0;
};

/// verifyEnclosure with `exactMinimum` false (the same answer, `why` and certified clearance), for
/// a surface that shares triangles with the one `memo` last saw: a triangle whose three corners
/// are the same points (the same doubles, the same orientation) as a sound triangle of that
/// surface, and whose corners are not duplicated in this one, keeps what was found for it: no
/// conflict with the other such triangles (they share corners exactly as before, so the pair's
/// test is the same) and its certified distance to the input; point distances are reused by
/// position. Every pair involving a new triangle, every new triangle's clearance, the 2-manifold
/// test and the winding numbers are checked as usual. Fills memo.Defective and replaces what the
/// memo keeps with this surface's findings. `checked`, if given, is checkTriangleMesh(surface)
/// (saves computing it again). `clear`, if given and its Distance is at least the clearance,
/// spares the exact clearance test of the triangles it covers (with the same result: the test
/// would find nothing closer than the clearance).
bool verifyEnclosureWithMemo(const TriangleMesh& input, const TriangleMesh& surface, double clearance,
  double& measuredClearance, std::string& why, std::vector<double>* pointDistances, Progress* progress,
  const TriangleTree& inputTree, VerificationMemo& memo, const MeshDefects* checked = nullptr,
  const KnownClearTriangles* clear = nullptr);

} // namespace sdfcage
