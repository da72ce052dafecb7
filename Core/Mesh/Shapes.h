// SDFCage — Core: the built-in procedural shape for the main job and the tests.
#pragma once

#include "Mesh/Mesh.h"

#include <vector>

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
/// A closed tube of `radius` along a polyline (points at most a few radii apart; corners
/// should be rounded by the caller), with hemispherical caps, `sides` points per ring (a
/// multiple of 4 puts points exactly at +-radius along the first frame's axes). The frame is
/// parallel-transported from `up` (perpendicular to the first segment). Outward oriented.
TriangleMesh makeTube(const std::vector<Vec3>& centerline, double radius, int sides, const Vec3& up);

/// A polyline through `corners` whose corners are rounded by circular arcs of radius `fillet`
/// (smaller where a segment is too short), sampled at most `step` apart.
std::vector<Vec3> roundedPolyline(const std::vector<Vec3>& corners, double fillet, double step);

/// Test shapes for topology (issue: parts that nearly touch where they join). Each is closed,
/// genus 0, and its named gap is exactly `gap` in unit-sphere units after normalization:
///  Hook    one tube that bends up, back and down, its tip `gap` above its own straight part
///          (the tip is close along the surface too: the paper's r/l rule misses it);
///  Cluster three short hooks side by side, `gap` apart, and a separate straight tube (four
///          components);
///  Ring    a ring (tube along a circle) nearly closed on itself, its two caps `gap` apart,
///          and a separate straight tube;
///  Comb    one tube meandering in four parallel runs `gap` apart (a comb's teeth).
enum class GapShape
{
  Hook,
  Cluster,
  Ring,
  Comb
};
TriangleMesh makeGapShape(GapShape kind, double gap);

/// Appends b to a (offsets indices).
void appendMesh(TriangleMesh& a, const TriangleMesh& b);

} // namespace sdfcage
