// SDFCage — Core: triangle and polygon mesh types (no VTK).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <vector>

namespace sdfcage
{

using Vec3 = Eigen::Vector3d;
using Triangle = std::array<int, 3>;

/// A triangle mesh: #V points and #F triangles (indices into Points, counter-clockwise seen from
/// outside for a closed, outward-oriented mesh).
struct TriangleMesh
{
  std::vector<Vec3> Points;
  std::vector<Triangle> Triangles;

  std::size_t numberOfPoints() const { return Points.size(); }
  std::size_t numberOfTriangles() const { return Triangles.size(); }
  bool empty() const { return Triangles.empty(); }
};

/// A polygon mesh as readers deliver it: cells of any size in compressed form (cell c uses
/// Connectivity[Offsets[c] .. Offsets[c+1])). Offsets has #cells + 1 entries.
/// Cells with fewer than 3 points (vertices, lines) are counted and ignored by validation.
struct PolygonMesh
{
  std::vector<Vec3> Points;
  std::vector<std::int64_t> Offsets{ 0 };
  std::vector<std::int64_t> Connectivity;

  std::size_t numberOfCells() const { return Offsets.empty() ? 0 : Offsets.size() - 1; }
  void addCell(std::initializer_list<std::int64_t> ids)
  {
    Connectivity.insert(Connectivity.end(), ids.begin(), ids.end());
    Offsets.push_back(static_cast<std::int64_t>(Connectivity.size()));
  }
  static PolygonMesh fromTriangles(const TriangleMesh& mesh);
};

/// Triangle t's normal scaled by twice its area (the cross product of its edges from t[0]):
/// outward on an outward-oriented mesh; summed over a point's or an edge's triangles it gives the
/// area-weighted normal there.
inline Vec3 areaNormal(const std::vector<Vec3>& points, const Triangle& t)
{
  const Vec3& a = points[static_cast<std::size_t>(t[0])];
  return (points[static_cast<std::size_t>(t[1])] - a).cross(points[static_cast<std::size_t>(t[2])] - a);
}
inline Vec3 areaNormal(const TriangleMesh& mesh, const Triangle& t)
{
  return areaNormal(mesh.Points, t);
}

/// Signed volume enclosed by a closed mesh (positive when outward oriented).
double signedVolume(const TriangleMesh& mesh);

/// Reverses every triangle (swaps its last two corners): outward becomes inward and back.
void reverseOrientation(TriangleMesh& mesh);

/// Reverses every triangle of a closed mesh whose signed volume is negative (inward oriented),
/// which orients it outward; returns whether it did.
bool orientOutward(TriangleMesh& mesh);

/// Connected components over shared vertices: returns the component id per triangle and the
/// number of components.
int triangleComponents(const TriangleMesh& mesh, std::vector<int>& componentOfTriangle);

/// The triangles at each point, as a CSR: those of point v are Triangles[First[v] .. First[v + 1]),
/// in increasing order (a triangle naming v twice is listed twice).
struct PointTriangles
{
  std::vector<std::size_t> First;
  std::vector<int> Triangles;
  explicit PointTriangles(const TriangleMesh& mesh);
  std::size_t count(std::size_t v) const { return First[v + 1] - First[v]; }
};

/// One input point per connected component (the first corner of its first triangle): a surface
/// that keeps away from the input has each component wholly inside or wholly outside, so these
/// points decide enclosure (verification) and must never be swept across (simplification).
std::vector<Vec3> componentProbes(const TriangleMesh& mesh);

/// Number of distinct points referenced by at least one triangle.
long long usedVertexCount(const TriangleMesh& mesh);

/// Euler characteristic V - E + F counted over referenced vertices and unique undirected edges.
long long eulerCharacteristic(const TriangleMesh& mesh);

/// Total genus of a closed 2-manifold mesh: sum over components of (2 - chi_i) / 2.
int genus(const TriangleMesh& mesh);

/// Axis-aligned bounds {min, max}.
std::array<Vec3, 2> bounds(const TriangleMesh& mesh);

/// Removes points no triangle references; keeps the order of the others.
void removeUnreferencedPoints(TriangleMesh& mesh);

/// The triangles f with keep[f] (in their order) and only the points they use (in the mesh's
/// order), without copying the rest of the mesh.
TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<char>& keep);

} // namespace sdfcage
