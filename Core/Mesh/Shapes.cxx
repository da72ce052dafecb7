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

namespace sdfcage
{

std::vector<Vec3> roundedPolyline(const std::vector<Vec3>& corners, double fillet, double step)
{
  std::vector<Vec3> out;
  if (corners.size() < 2 || !(step > 0))
  {
    return corners;
  }
  auto segment = [&](const Vec3& a, const Vec3& b) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 1; k <= n; ++k)
    {
      out.push_back(a + (b - a) * (static_cast<double>(k) / n));
    }
  };
  out.push_back(corners.front());
  Vec3 from = corners.front();
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
  {
    const Vec3 a = (corners[i] - corners[i - 1]).normalized(), b = (corners[i + 1] - corners[i]).normalized();
    const double turn = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    if (turn < 1e-9)
    {
      continue;
    }
    // tangent length of the arc, limited to half of each neighbouring segment
    double d = fillet * std::tan(0.5 * turn);
    d = std::min({ d, 0.5 * (corners[i] - corners[i - 1]).norm(), 0.5 * (corners[i + 1] - corners[i]).norm() });
    const double r = d / std::tan(0.5 * turn);
    const Vec3 start = corners[i] - a * d, end = corners[i] + b * d;
    segment(from, start);
    // the arc: centre on the inner side, the direction turns from a to b
    const Vec3 inward = (b - a * a.dot(b)).normalized();
    const Vec3 centre = start + inward * r;
    const int n = std::max(2, static_cast<int>(std::ceil(r * turn / step)));
    for (int k = 1; k <= n; ++k)
    {
      const double t = turn * k / n;
      out.push_back(centre + (-inward * std::cos(t) + a * std::sin(t)) * r);
    }
    from = end;
  }
  segment(from, corners.back());
  return out;
}

TriangleMesh makeTube(const std::vector<Vec3>& c, double radius, int sides, const Vec3& up)
{
  TriangleMesh m;
  const int n = static_cast<int>(c.size());
  if (n < 2 || sides < 3 || !(radius > 0))
  {
    return m;
  }
  // rings: start cap (pole side first), the body, end cap; each ring = centre, frame, radius
  struct Ring
  {
    Vec3 Centre, U, W;
    double R;
  };
  std::vector<Vec3> tangent(n), u(n);
  for (int i = 0; i < n; ++i)
  {
    tangent[i] = (c[std::min(i + 1, n - 1)] - c[std::max(i - 1, 0)]).normalized();
  }
  u[0] = (up - tangent[0] * tangent[0].dot(up)).normalized();
  for (int i = 1; i < n; ++i)
  {
    u[i] = (u[i - 1] - tangent[i] * tangent[i].dot(u[i - 1])).normalized(); // parallel transport
  }
  const int capRings = std::max(2, sides / 4);
  std::vector<Ring> rings;
  for (int k = 1; k < capRings; ++k)
  {
    const double a = 0.5 * M_PI * k / capRings;
    rings.push_back({ c[0] - tangent[0] * radius * std::cos(a), u[0], tangent[0].cross(u[0]), radius * std::sin(a) });
  }
  for (int i = 0; i < n; ++i)
  {
    rings.push_back({ c[i], u[i], tangent[i].cross(u[i]), radius });
  }
  for (int k = capRings - 1; k >= 1; --k)
  {
    const double a = 0.5 * M_PI * k / capRings;
    rings.push_back(
      { c[n - 1] + tangent[n - 1] * radius * std::cos(a), u[n - 1], tangent[n - 1].cross(u[n - 1]), radius * std::sin(a) });
  }
  m.Points.push_back(c[0] - tangent[0] * radius);
  for (const Ring& r : rings)
  {
    for (int j = 0; j < sides; ++j)
    {
      const double phi = 2.0 * M_PI * j / sides;
      m.Points.push_back(r.Centre + (r.U * std::cos(phi) + r.W * std::sin(phi)) * r.R);
    }
  }
  m.Points.push_back(c[n - 1] + tangent[n - 1] * radius);
  const int south = 0, north = static_cast<int>(m.Points.size()) - 1, nr = static_cast<int>(rings.size());
  auto id = [&](int ring, int j) { return 1 + ring * sides + (j % sides); };
  for (int j = 0; j < sides; ++j)
  {
    m.Triangles.push_back({ south, id(0, j + 1), id(0, j) });
    m.Triangles.push_back({ north, id(nr - 1, j), id(nr - 1, j + 1) });
    for (int i = 0; i + 1 < nr; ++i)
    {
      m.Triangles.push_back({ id(i, j), id(i, j + 1), id(i + 1, j + 1) });
      m.Triangles.push_back({ id(i, j), id(i + 1, j + 1), id(i + 1, j) });
    }
  }
  orientOutward(m);
  return m;
}

namespace
{

/// The shape for a world gap g (its unit-sphere gap is g times the normalization scale).
TriangleMesh gapShapeWorld(GapShape kind, double g)
{
  const double rho = 0.012, step = 0.008, fillet = 0.02;
  const int sides = 16;
  auto hook = [&](double z, double length) {
    // a straight part along -x, up, back, and down to `g` above the straight part; tall enough
    // that the last bend's arc (roundedPolyline shortens it to half the last segment) keeps a
    // radius above the tube's: a tighter bend folds the tube's inner side through itself (at
    // H = 0.055 every gap above 0.0064 did: 20 crossing pairs at 0.01)
    const double W = 0.045, H = std::max(0.055, 2 * rho + g + 2.2 * rho);
    const std::vector<Vec3> corners{ { -length, 0, z }, { 0, 0, z }, { 0, H, z }, { -W, H, z },
      { -W, 2 * rho + g, z } };
    return makeTube(roundedPolyline(corners, fillet, step), rho, sides, Vec3(0, 1, 0));
  };
  // a separate straight tube far from the rest: it sets the extent (about 2 across, so that
  // world and unit-sphere units nearly agree)
  auto ruler = [&]() {
    return makeTube(roundedPolyline({ { -1.8, -0.4, 0 }, { 0.1, -0.4, 0 } }, fillet, step), rho, sides, Vec3(0, 1, 0));
  };
  TriangleMesh m;
  switch (kind)
  {
    case GapShape::Hook:
      // the long straight part sets the extent itself
      m = hook(0.0, 1.9);
      break;
    case GapShape::Cluster:
      for (int k = 0; k < 3; ++k)
      {
        appendMesh(m, hook(k * (2 * rho + g), 0.25));
      }
      appendMesh(m, ruler());
      break;
    case GapShape::Ring:
    {
      // the caps' poles, at angles +-theta0 on a circle of radius R, are g apart
      const double R = 0.1;
      double lo = 0.0, hi = 0.5 * M_PI;
      for (int it = 0; it < 100; ++it)
      {
        const double mid = 0.5 * (lo + hi);
        (2.0 * (R * std::sin(mid) - rho * std::cos(mid)) < g ? lo : hi) = mid;
      }
      const double t0 = 0.5 * (lo + hi);
      std::vector<Vec3> arc;
      const int n = static_cast<int>(std::ceil(2.0 * M_PI * R / step));
      for (int k = 0; k <= n; ++k)
      {
        const double t = t0 + (2.0 * M_PI - 2.0 * t0) * k / n;
        arc.push_back(Vec3(R * std::cos(t), R * std::sin(t), 0));
      }
      m = makeTube(arc, rho, sides, Vec3(0, 0, 1));
      appendMesh(m, ruler());
      break;
    }
    case GapShape::Comb:
    {
      // four runs along x, `g` apart, joined by U-turns at alternate ends, then the long tail
      const double L = 0.3, pitch = 2 * rho + g;
      std::vector<Vec3> c;
      for (int k = 0; k < 4; ++k)
      {
        const double y = k * pitch;
        const bool forward = (k % 2) == 0;
        const double x0 = forward ? 0.0 : L, x1 = forward ? L : 0.0;
        if (k > 0)
        {
          // U-turn: half circle of radius pitch / 2 from the previous run's end
          const double cx = x0, cy = y - 0.5 * pitch, s = forward ? -1.0 : 1.0;
          for (int j = 1; j < 12; ++j)
          {
            const double a = M_PI * j / 12;
            c.push_back(Vec3(cx + s * 0.5 * pitch * std::sin(a), cy - 0.5 * pitch * std::cos(a), 0));
          }
        }
        const int n = static_cast<int>(std::ceil(L / step));
        for (int j = 0; j <= n; ++j)
        {
          if (k == 0 && j == 0)
          {
            // the tail: a long straight lead-in along -x
            for (int t = 0; t < 200; ++t)
            {
              c.push_back(Vec3(-1.6 + 1.6 * t / 200.0, 0, 0));
            }
          }
          c.push_back(Vec3(x0 + (x1 - x0) * j / n, y, 0));
        }
      }
      m = makeTube(c, rho, sides, Vec3(0, 0, 1));
      break;
    }
  }
  return m;
}

} // namespace

TriangleMesh makeGapShape(GapShape kind, double gap)
{
  // like makeBuiltinShape: solve for the world gap that becomes `gap` after normalization
  double g = gap;
  TriangleMesh m;
  for (int iter = 0; iter < 20; ++iter)
  {
    m = gapShapeWorld(kind, g);
    const double unitGap = g * Normalization::fit(m).Scale;
    if (std::abs(unitGap - gap) < 1e-10)
    {
      break;
    }
    g *= gap / unitGap;
  }
  return m;
}

} // namespace sdfcage
