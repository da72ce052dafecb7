#include "Mesh/Normalization.h"

#include <algorithm>

namespace sdfcage
{

Normalization Normalization::fit(const TriangleMesh& mesh)
{
  Normalization n;
  if (mesh.Points.empty())
  {
    return n;
  }
  Vec3 lo = mesh.Points[0], hi = mesh.Points[0];
  for (const Vec3& p : mesh.Points)
  {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  n.Center = 0.5 * (lo + hi);
  double r2 = 0.0;
  for (const Vec3& p : mesh.Points)
  {
    r2 = std::max(r2, (p - n.Center).squaredNorm());
  }
  n.Scale = r2 > 0.0 ? 1.0 / std::sqrt(r2) : 1.0;
  return n;
}

TriangleMesh Normalization::toUnit(const TriangleMesh& mesh) const
{
  TriangleMesh out = mesh;
  for (Vec3& p : out.Points)
  {
    p = toUnit(p);
  }
  return out;
}

TriangleMesh Normalization::toInput(const TriangleMesh& mesh) const
{
  TriangleMesh out = mesh;
  for (Vec3& p : out.Points)
  {
    p = toInput(p);
  }
  return out;
}

} // namespace sdfcage
