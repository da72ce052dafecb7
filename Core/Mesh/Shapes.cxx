#include "Mesh/Shapes.h"

#include "Mesh/Normalization.h"

#include <cmath>

namespace sdfcage
{

void appendMesh(TriangleMesh& a, const TriangleMesh& b)
{
  const int offset = static_cast<int>(a.Points.size());
  a.Points.insert(a.Points.end(), b.Points.begin(), b.Points.end());
  for (const Triangle& t : b.Triangles)
  {
    a.Triangles.push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
  }
}

TriangleMesh makeSphere(const Vec3& center, double radius, int slices, int stacks)
{
  // poles on the -x and +x axis, so a vertex sits exactly at the point nearest to -x
  TriangleMesh m;
  m.Points.push_back(center + Vec3(-radius, 0, 0));
  for (int i = 1; i < stacks; ++i)
  {
    const double theta = M_PI * i / stacks; // from -x pole
    for (int j = 0; j < slices; ++j)
    {
      const double phi = 2.0 * M_PI * j / slices;
      m.Points.push_back(
        center + radius * Vec3(-std::cos(theta), std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi)));
    }
  }
  m.Points.push_back(center + Vec3(radius, 0, 0));
  const int south = 0, north = static_cast<int>(m.Points.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * slices + ((j % slices) + slices) % slices; };
  for (int j = 0; j < slices; ++j)
  {
    m.Triangles.push_back({ south, ring(1, j + 1), ring(1, j) });
    m.Triangles.push_back({ north, ring(stacks - 1, j), ring(stacks - 1, j + 1) });
  }
  for (int i = 1; i + 1 < stacks; ++i)
  {
    for (int j = 0; j < slices; ++j)
    {
      m.Triangles.push_back({ ring(i, j), ring(i, j + 1), ring(i + 1, j + 1) });
      m.Triangles.push_back({ ring(i, j), ring(i + 1, j + 1), ring(i + 1, j) });
    }
  }
  return m;
}

TriangleMesh makeTorus(const Vec3& center, double R, double r, int nu, int nv)
{
  // in the xy plane; u = 0 points along +x, v = 0 is the outer equator
  TriangleMesh m;
  for (int i = 0; i < nu; ++i)
  {
    const double u = 2.0 * M_PI * i / nu;
    for (int j = 0; j < nv; ++j)
    {
      const double v = 2.0 * M_PI * j / nv;
      m.Points.push_back(
        center + Vec3((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)));
    }
  }
  auto id = [&](int i, int j) { return ((i + nu) % nu) * nv + (j + nv) % nv; };
  for (int i = 0; i < nu; ++i)
  {
    for (int j = 0; j < nv; ++j)
    {
      m.Triangles.push_back({ id(i, j), id(i + 1, j), id(i + 1, j + 1) });
      m.Triangles.push_back({ id(i, j), id(i + 1, j + 1), id(i, j + 1) });
    }
  }
  return m;
}

TriangleMesh makeBox(const Vec3& lo, const Vec3& hi)
{
  TriangleMesh m;
  for (int k = 0; k < 8; ++k)
  {
    m.Points.push_back(Vec3((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z()));
  }
  const int quads[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 },
    { 1, 3, 7, 5 } };
  for (const auto& q : quads)
  {
    m.Triangles.push_back({ q[0], q[1], q[2] });
    m.Triangles.push_back({ q[0], q[2], q[3] });
  }
  return m;
}

TriangleMesh makeBuiltinShape(double gap, int resolution)
{
  const int s = std::max(1, resolution);
  // Torus (genus 1) around the origin and a sphere on the +x side. The torus's outer equator
  // vertex (u = 0, v = 0) at x = R + r and the sphere's -x pole face each other on the x axis,
  // so the nearest points of the two parts are exactly those two vertices.
  const double R = 0.42, r = 0.16, rs = 0.3;
  // Work in the final unit-sphere frame: the bounding-box centre and radius depend on the gap,
  // so solve for the world gap that becomes `gap` after normalization (fixed point; converges in
  // a few steps because the scale changes little with the gap).
  double g = gap;
  TriangleMesh m;
  for (int iter = 0; iter < 20; ++iter)
  {
    m = makeTorus(Vec3::Zero(), R, r, 64 * s, 24 * s);
    appendMesh(m, makeSphere(Vec3(R + r + g + rs, 0, 0), rs, 48 * s, 24 * s));
    const Normalization n = Normalization::fit(m);
    const double unitGap = g * n.Scale;
    if (std::abs(unitGap - gap) < 1e-9)
    {
      break;
    }
    g *= gap / unitGap;
  }
  return m;
}

} // namespace sdfcage
