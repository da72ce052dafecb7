// SDFCage — Testing: a closed, outward box surface split into a grid of n[0] x n[1] x n[2] cells
// (two triangles per surface cell), and the bend used by the deformation tests.
#pragma once

#include "Mesh/Mesh.h"

#include <array>
#include <cmath>
#include <map>

namespace sdfcage_test
{

inline sdfcage::TriangleMesh makeGridBox(const sdfcage::Vec3& lo, const sdfcage::Vec3& hi, std::array<int, 3> n)
{
  using sdfcage::Vec3;
  sdfcage::TriangleMesh mesh;
  std::map<std::array<int, 3>, int> ids;
  auto point = [&](std::array<int, 3> ijk) {
    auto it = ids.find(ijk);
    if (it != ids.end())
    {
      return it->second;
    }
    Vec3 p;
    for (int a = 0; a < 3; ++a)
    {
      p[a] = lo[a] + (hi[a] - lo[a]) * ijk[a] / n[a];
    }
    mesh.Points.push_back(p);
    ids.emplace(ijk, static_cast<int>(mesh.Points.size()) - 1);
    return static_cast<int>(mesh.Points.size()) - 1;
  };
  for (int axis = 0; axis < 3; ++axis)
  {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3; // (u, v, axis) is right-handed
    for (int side = 0; side < 2; ++side)
    {
      for (int i = 0; i < n[u]; ++i)
      {
        for (int j = 0; j < n[v]; ++j)
        {
          std::array<int, 4> q;
          const int corners[4][2] = { { i, j }, { i + 1, j }, { i + 1, j + 1 }, { i, j + 1 } };
          for (int c = 0; c < 4; ++c)
          {
            std::array<int, 3> ijk;
            ijk[axis] = side * n[axis];
            ijk[u] = corners[c][0];
            ijk[v] = corners[c][1];
            q[c] = point(ijk);
          }
          // counter-clockwise in (u, v) faces +axis: keep it on the high side, reverse on the low
          if (side == 1)
          {
            mesh.Triangles.push_back({ q[0], q[1], q[2] });
            mesh.Triangles.push_back({ q[0], q[2], q[3] });
          }
          else
          {
            mesh.Triangles.push_back({ q[0], q[2], q[1] });
            mesh.Triangles.push_back({ q[0], q[3], q[2] });
          }
        }
      }
    }
  }
  return mesh;
}

/// Bends the x axis around a circle of radius `radius` (the plane z = const keeps its shape):
/// (x, y, z) -> (0, -radius) + (radius + y) (sin(x / radius), cos(x / radius)), z.
inline sdfcage::Vec3 bend(const sdfcage::Vec3& p, double radius)
{
  const double t = p.x() / radius;
  return { (radius + p.y()) * std::sin(t), -radius + (radius + p.y()) * std::cos(t), p.z() };
}

} // namespace sdfcage_test
