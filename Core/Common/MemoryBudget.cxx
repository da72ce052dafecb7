// SDFCage — Core: see MemoryBudget.h.
#include "Common/MemoryBudget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <unistd.h>

namespace sdfcage
{

namespace
{
// Measured: peak resident size of `sdfcage` above its 88 MB of libraries (default parameters,
// /usr/bin/time -f %M): bunny (7k triangles, area 5.3 in the unit sphere) 70 MB at isovalue
// 0.01 and 200 MB at 0.005 (4.25 M band voxels: 47 bytes each), fertility 192 MB at 0.005
// (4.15 M voxels: 46 bytes each), armadillo (86k triangles) 88 MB at 0.01, of which about 50 MB
// (580 bytes a triangle) beyond its voxels. Rounded up:
constexpr double BytesPerBandVoxel = 64.0;
constexpr double BytesPerInputTriangle = 1024.0;
} // namespace

std::size_t physicalMemoryBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || pageSize <= 0)
  {
    return 0;
  }
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(pageSize);
}

std::size_t defaultMemoryLimit()
{
  const std::size_t physical = physicalMemoryBytes();
  return physical > 0 ? physical / 4 * 3 : std::size_t(8) << 30;
}

std::size_t estimateEnvelopeBytes(
  const TriangleMesh& unitInput, double voxel, double iso, bool signedByFloodFill, bool denseField)
{
  if (!(voxel > 0.0) || !(iso > 0.0))
  {
    return 0;
  }
  double area = 0.0;
  for (const Triangle& t : unitInput.Triangles)
  {
    const Vec3& a = unitInput.Points[static_cast<std::size_t>(t[0])];
    const Vec3& b = unitInput.Points[static_cast<std::size_t>(t[1])];
    const Vec3& c = unitInput.Points[static_cast<std::size_t>(t[2])];
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double outside = std::ceil(iso / voxel) + 1.0;
  const double inside = signedByFloodFill ? 1.0 : outside;
  const double voxels = area / (voxel * voxel) * (outside + inside + 1.0);
  double bytes = voxels * BytesPerBandVoxel + static_cast<double>(unitInput.Triangles.size()) * BytesPerInputTriangle;
  if (denseField)
  {
    // two float images over the unit sphere's box
    const double side = 2.0 / voxel + 1.0;
    bytes += 2.0 * 4.0 * side * side * side;
  }
  const double largest = static_cast<double>(static_cast<std::size_t>(-1) / 2);
  return static_cast<std::size_t>(std::min(bytes, largest));
}

std::string formatBytes(std::size_t bytes)
{
  char text[32];
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024.0 * 1024.0)
    std::snprintf(text, sizeof(text), "%.1f GiB", b / (1024.0 * 1024.0 * 1024.0));
  else
    std::snprintf(text, sizeof(text), "%.0f MiB", b / (1024.0 * 1024.0));
  return text;
}

} // namespace sdfcage
