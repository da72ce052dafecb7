// SDFCage — Core: the built-in procedural shape for the main job and the tests.
#pragma once

#include "Mesh/Mesh.h"

namespace sdfcage
{

/// Torus (genus 1) beside a sphere, two closed components whose nearest points are `gap` apart
/// in unit-sphere units after normalization (default 0.012: narrower than 2c so a plain offset
/// at c = 0.01 fuses them, wider than c/2). `resolution` scales the tessellation.
TriangleMesh makeBuiltinShape(double gap = 0.012, int resolution = 1);

/// UV sphere (closed, outward) and torus, for tests.
TriangleMesh makeSphere(const Vec3& center, double radius, int slices, int stacks);
TriangleMesh makeTorus(
  const Vec3& center, double majorRadius, double minorRadius, int majorSegments, int minorSegments);
/// Axis-aligned box split into 12 triangles, outward.
TriangleMesh makeBox(const Vec3& lo, const Vec3& hi);
/// Appends b to a (offsets indices).
void appendMesh(TriangleMesh& a, const TriangleMesh& b);

} // namespace sdfcage
