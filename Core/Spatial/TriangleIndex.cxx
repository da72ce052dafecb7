#include "Spatial/TriangleIndex.h"

#include "Spatial/Geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sdfcage
{

void TriangleIndex::build(const TriangleMesh& mesh, double cellSize)
{
  this->Mesh = &mesh;
  const auto box = bounds(mesh);
  const std::size_t nf = mesh.Triangles.size();
  if (nf == 0)
  {
    this->Dims = { 1, 1, 1 };
    this->CellStart.assign(2, 0);
    this->CellTriangles.clear();
    this->MinCell.clear();
    return;
  }
  if (!(cellSize > 0.0))
  {
    // about two mean triangle extents per cell, but at most ~4 cells per triangle overall
    double extent = 0.0;
    for (const Triangle& t : mesh.Triangles)
    {
      const Vec3 lo = mesh.Points[t[0]].cwiseMin(mesh.Points[t[1]]).cwiseMin(mesh.Points[t[2]]);
      const Vec3 hi = mesh.Points[t[0]].cwiseMax(mesh.Points[t[1]]).cwiseMax(mesh.Points[t[2]]);
      extent += (hi - lo).maxCoeff();
    }
    cellSize = 2.0 * extent / static_cast<double>(nf);
    const Vec3 size = box[1] - box[0];
    const double volume = std::max(size.x(), 1e-12) * std::max(size.y(), 1e-12) * std::max(size.z(), 1e-12);
    cellSize = std::max(cellSize, std::cbrt(volume / (4.0 * static_cast<double>(nf))));
    if (!(cellSize > 0.0))
    {
      cellSize = 1.0;
    }
  }
  this->CellSize = cellSize;
  this->Origin = box[0] - Vec3::Constant(0.5 * cellSize);
  for (int a = 0; a < 3; ++a)
  {
    this->Dims[a] = std::max(1, static_cast<int>(std::ceil((box[1][a] - this->Origin[a]) / cellSize + 0.5)));
  }
  const std::int64_t ncells = static_cast<std::int64_t>(Dims[0]) * Dims[1] * Dims[2];
  this->CellStart.assign(ncells + 1, 0);
  this->MinCell.resize(nf);
  // two passes: count, then fill
  for (int pass = 0; pass < 2; ++pass)
  {
    std::vector<std::int64_t> fill;
    if (pass == 1)
    {
      for (std::int64_t c = 0; c < ncells; ++c)
      {
        this->CellStart[c + 1] += this->CellStart[c];
      }
      this->CellTriangles.resize(this->CellStart[ncells]);
      fill.assign(this->CellStart.begin(), this->CellStart.end() - 1);
    }
    for (std::size_t f = 0; f < nf; ++f)
    {
      const Triangle& t = mesh.Triangles[f];
      const Vec3 lo = mesh.Points[t[0]].cwiseMin(mesh.Points[t[1]]).cwiseMin(mesh.Points[t[2]]);
      const Vec3 hi = mesh.Points[t[0]].cwiseMax(mesh.Points[t[1]]).cwiseMax(mesh.Points[t[2]]);
      std::array<int, 3> a, b;
      this->cellRange(lo, hi, a, b);
      if (pass == 0)
        this->MinCell[f] = a;
      for (int k = a[2]; k <= b[2]; ++k)
        for (int j = a[1]; j <= b[1]; ++j)
          for (int i = a[0]; i <= b[0]; ++i)
          {
            const std::int64_t c = (static_cast<std::int64_t>(k) * Dims[1] + j) * Dims[0] + i;
            if (pass == 0)
            {
              ++this->CellStart[c + 1];
            }
            else
            {
              this->CellTriangles[fill[c]++] = static_cast<int>(f);
            }
          }
    }
  }
}

void TriangleIndex::cellRange(const Vec3& lo, const Vec3& hi, std::array<int, 3>& a, std::array<int, 3>& b) const
{
  for (int d = 0; d < 3; ++d)
  {
    const double l = std::floor((lo[d] - Origin[d]) / CellSize);
    const double h = std::floor((hi[d] - Origin[d]) / CellSize);
    a[d] = static_cast<int>(std::clamp(l, 0.0, static_cast<double>(Dims[d] - 1)));
    b[d] = static_cast<int>(std::clamp(h, 0.0, static_cast<double>(Dims[d] - 1)));
  }
}

bool TriangleIndex::closestPoint(
  const Vec3& p, double maxDistance, Vec3& closest, int& triangle, double& distance) const
{
  triangle = -1;
  if (!Mesh || Mesh->Triangles.empty())
  {
    return false;
  }
  const double limit = maxDistance < 0 ? std::numeric_limits<double>::infinity() : maxDistance;
  double best2 = limit * limit;
  std::array<int, 3> c, unused;
  this->cellRange(p, p, c, unused);
  const int maxRing = std::max({ Dims[0], Dims[1], Dims[2] });
  for (int r = 0; r <= maxRing; ++r)
  {
    // every cell of ring r is at least (r - 1) cells away along some axis
    const double ringLower = (r - 1) * CellSize;
    if (r > 0 && ringLower > 0 && ringLower * ringLower >= best2)
    {
      break;
    }
    for (int k = c[2] - r; k <= c[2] + r; ++k)
    {
      if (k < 0 || k >= Dims[2])
        continue;
      for (int j = c[1] - r; j <= c[1] + r; ++j)
      {
        if (j < 0 || j >= Dims[1])
          continue;
        const bool shellJK = std::abs(k - c[2]) == r || std::abs(j - c[1]) == r;
        for (int i = c[0] - r; i <= c[0] + r; i += (shellJK || r == 0) ? 1 : 2 * r)
        {
          if (i < 0 || i >= Dims[0])
            continue;
          // distance from p to the cell box: skip cells that cannot improve
          Vec3 lo = Origin + Vec3(i, j, k) * CellSize;
          Vec3 d = (lo - p).cwiseMax(p - (lo + Vec3::Constant(CellSize))).cwiseMax(0.0);
          if (d.squaredNorm() >= best2)
            continue;
          const std::int64_t cell = (static_cast<std::int64_t>(k) * Dims[1] + j) * Dims[0] + i;
          for (std::int64_t s = CellStart[cell]; s < CellStart[cell + 1]; ++s)
          {
            const int f = CellTriangles[s];
            const Triangle& t = Mesh->Triangles[f];
            {
              // cheap box test first: skip triangles whose box is farther than the best so far
              const Vec3& a = Mesh->Points[t[0]];
              const Vec3& b = Mesh->Points[t[1]];
              const Vec3& cc = Mesh->Points[t[2]];
              const Vec3 tlo = a.cwiseMin(b).cwiseMin(cc), thi = a.cwiseMax(b).cwiseMax(cc);
              const Vec3 bd = (tlo - p).cwiseMax(p - thi).cwiseMax(0.0);
              if (bd.squaredNorm() > best2)
                continue;
            }
            const Vec3 q = closestPointOnTriangle(p, Mesh->Points[t[0]], Mesh->Points[t[1]], Mesh->Points[t[2]]);
            const double d2 = (q - p).squaredNorm();
            if (d2 < best2 || (triangle < 0 && d2 <= best2))
            {
              best2 = d2;
              closest = q;
              triangle = f;
            }
          }
        }
      }
    }
  }
  if (triangle < 0)
  {
    return false;
  }
  distance = std::sqrt(best2);
  return true;
}

double TriangleIndex::distance(const Vec3& p) const
{
  Vec3 q;
  int t;
  double d = std::numeric_limits<double>::infinity();
  this->closestPoint(p, -1.0, q, t, d);
  return d;
}

double TriangleIndex::triangleDistance(const Vec3 t[3], double limit) const
{
  const Vec3 lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]) - Vec3::Constant(limit);
  const Vec3 hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]) + Vec3::Constant(limit);
  double best2 = limit * limit;
  this->forEachTriangleInBox(lo, hi, [&](int f) {
    const Triangle& tri = Mesh->Triangles[f];
    const Vec3 o[3] = { Mesh->Points[tri[0]], Mesh->Points[tri[1]], Mesh->Points[tri[2]] };
    best2 = std::min(best2, triangleTriangleDistance2(t, o));
  });
  return std::sqrt(best2);
}

} // namespace sdfcage
