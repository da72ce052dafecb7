// SDFCage — Testing: the spacing measure of issue #15 (the area fraction of a cage whose distance
// to the input lies within a band), shared by the data tests and the tight-optimization benchmark.
#pragma once

#include "Mesh/Mesh.h"
#include "Spatial/TriangleTree.h"

namespace sdfcage
{

/// Fraction of the cage's area (unit-sphere units) whose distance to the input lies within
/// [lo, hi]: each triangle split into 4^4 = 256 sub-triangles, judged at their centroids.
inline double bandFraction(const TriangleMesh& cage, const TriangleTree& tree, double lo, double hi)
{
  const int n = 16;
  double in = 0.0, all = 0.0;
  for (const Triangle& t : cage.Triangles)
  {
    const Vec3& a = cage.Points[t[0]];
    const Vec3& b = cage.Points[t[1]];
    const Vec3& c = cage.Points[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm() / (n * n);
    // the n^2 sub-triangles of the uniform grid: upright (i, j) and inverted ones
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j)
        for (int up = 0; up < 2; ++up)
        {
          if (up == 1 && i + j + 1 >= n)
            continue;
          const double bi = i + (up ? 2.0 : 1.0) / 3, bj = j + (up ? 2.0 : 1.0) / 3;
          const double d = tree.distance(a + (bi / n) * (b - a) + (bj / n) * (c - a));
          all += area;
          if (d >= lo && d <= hi)
            in += area;
        }
  }
  return all > 0 ? in / all : 0.0;
}

} // namespace sdfcage
