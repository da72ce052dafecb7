// SDFCage — Core: exact-in-effect distance primitives (double precision, robust formulas).
#pragma once

#include "Mesh/Mesh.h"

#include <cmath>
#include <vector>

namespace sdfcage
{

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Squared distance between segments [p0, p1] and [q0, q1].
double segmentSegmentDistance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);
/// The same, also giving the closest points p0 + s (p1 - p0) and q0 + t (q1 - q0), s, t in [0, 1].
double segmentSegmentClosest(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double& s, double& t);

/// Squared distance between two triangles (0 when they intersect).
double triangleTriangleDistance2(const Vec3 a[3], const Vec3 b[3]);

/// sqrt(triangleTriangleDistance2(a, b)) < delta, decided as soon as one of its parts is (a
/// corner near the other triangle, two edges near each other), else by the crossing tests: the
/// same answer at a fraction of the cost when the triangles are close.
bool trianglesCloserThan(const Vec3 a[3], const Vec3 b[3], double delta);

/// Two triangles sharing exactly vertex a, (a, b, c) and (a, d, e): do they meet anywhere
/// else? Nearly coplanar pairs whose corners overlap count as meeting (conservative).
bool meetBeyondSharedVertex(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e);

/// Do two triangles of one mesh (vertex ids ia/ib, points pa/pb) conflict? Triangles sharing no
/// vertex conflict when they intersect or come closer than `separation`; sharing one vertex, when
/// they meet anywhere else; sharing an edge, when their normals' cosine is below `foldCosine`
/// (folded onto each other; -1 + tiny for exact intersection only).
bool trianglesConflict(
  const int ia[3], const Vec3 pa[3], const int ib[3], const Vec3 pb[3], double separation, double foldCosine);

/// Signed solid angle of triangle (a, b, c) seen from p (Van Oosterom & Strackee, "The solid angle
/// of a plane triangle", 1983): positive when p lies behind the triangle (opposite its
/// counter-clockwise normal), in [-2 pi, 2 pi]. Summed over a closed mesh: 4 pi x the winding
/// number at p.
/// Every winding-number sum calls this one formula, so their results agree to the last bit.
inline double solidAngle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p)
{
  const Vec3 u = a - p, v = b - p, w = c - p;
  const double lu = u.norm(), lv = v.norm(), lw = w.norm();
  const double num = u.dot(v.cross(w));
  const double den = lu * lv * lw + u.dot(v) * lw + v.dot(w) * lu + w.dot(u) * lv;
  return 2.0 * std::atan2(num, den);
}

/// Generalized winding number of a closed triangle mesh at p (about 1 inside, 0 outside).
double windingNumber(const TriangleMesh& mesh, const Vec3& p);

/// The side of a closed, consistently oriented mesh a point is on, from its closest point: the
/// angle-weighted pseudo-normal of the closest feature (face, edge or vertex) points to the
/// outside (Baerentzen and Aanaes, "Signed distance computation using the angle weighted
/// pseudonormal", 2005). Written here: OpenVDB signs whole grids by flood fill, and a field
/// computed only near some points (the topology repair's local grid) has no closed band to fill
/// from. The mesh must outlive this.
class PseudoNormalSign
{
public:
  explicit PseudoNormalSign(const TriangleMesh& mesh);

  /// Triangle f's unit normal (zero when it is degenerate).
  const Vec3& faceNormal(int f) const { return Face[static_cast<std::size_t>(f)]; }

  /// x's closest point on the mesh is cp, on triangle f: is x outside?
  bool outside(const Vec3& x, int f, const Vec3& cp) const;

private:
  const TriangleMesh& M;
  std::vector<Vec3> Face, Vertex;
  std::vector<int> Across; ///< the triangle across edge k of f (3 f + k), -1 on a border
};

} // namespace sdfcage
