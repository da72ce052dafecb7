// SDFCage — Core: exact-in-effect distance primitives (double precision, robust formulas).
#pragma once

#include "Mesh.h"

namespace sdfcage
{

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Squared distance between segments [p0, p1] and [q0, q1].
double segmentSegmentDistance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

/// Squared distance between two triangles (0 when they intersect).
double triangleTriangleDistance2(const Vec3 a[3], const Vec3 b[3]);

/// Generalized winding number of a closed triangle mesh at p (about 1 inside, 0 outside).
double windingNumber(const TriangleMesh& mesh, const Vec3& p);

} // namespace sdfcage
