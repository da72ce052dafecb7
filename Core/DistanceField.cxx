#include "DistanceField.h"

#include "Progress.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <cstdlib>

namespace sdfcage
{

namespace
{

/// OpenVDB interrupter backed by our Progress: one mechanism for both.
class VdbInterrupter : public openvdb::util::NullInterrupter
{
public:
  VdbInterrupter(Progress* p, double begin, double end)
    : P(p)
    , Begin(begin)
    , End(end)
  {
  }
  bool wasInterrupted(int percent = -1) override
  {
    if (!P)
    {
      return false;
    }
    if (percent >= 0)
    {
      P->update(Begin + (End - Begin) * std::clamp(percent, 0, 100) / 100.0);
    }
    return P->cancelled();
  }

private:
  Progress* P;
  double Begin, End;
};

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::once_flag vdbInit;

} // namespace

IsosurfaceOutput computeIsosurface(const TriangleMesh& unitInput, double voxelSize, double iso,
  bool keepField, Progress* progress, const std::vector<double>& adaptivities)
{
  std::call_once(vdbInit, []() { openvdb::initialize(); });
  IsosurfaceOutput out;
  auto t0 = std::chrono::steady_clock::now();

  // mesh in index space (voxel centres at integer coordinates)
  std::vector<openvdb::Vec3s> points(unitInput.Points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    const Vec3 p = unitInput.Points[i] / voxelSize;
    points[i] = openvdb::Vec3s(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  std::vector<openvdb::Vec3I> tris(unitInput.Triangles.size());
  for (std::size_t f = 0; f < tris.size(); ++f)
  {
    const Triangle& t = unitInput.Triangles[f];
    tris[f] = openvdb::Vec3I(t[0], t[1], t[2]);
  }
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(points, tris);
  auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);

  // The isosurface at `iso` needs values up to iso plus one voxel. Corners beyond the band read the
  // background (band width), which is still > iso: the crossing can only move outward (the safe
  // side), and the envelope is verified anyway. Inside, one voxel is enough: the flood fill gives
  // the interior its sign. Narrow bands are most of the speed of this stage.
  const float exteriorBand = static_cast<float>(std::ceil(iso / voxelSize) + 1.0);
  const float interiorBand = 1.0f;
  VdbInterrupter sdfInterrupter(progress, 0.0, 0.6);
  openvdb::FloatGrid::Ptr grid;
  try
  {
    grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      sdfInterrupter, adapter, *transform, exteriorBand, interiorBand, 0);
  }
  catch (const std::exception& e)
  {
    out.Error = std::string("OpenVDB could not compute the distance field: ") + e.what();
    return out;
  }
  out.DistanceFieldSeconds = seconds(t0);
  if (progressCancelled(progress) || !grid)
  {
    out.Cancelled = true;
    return out;
  }
  out.ActiveVoxels = grid->activeVoxelCount();

  auto t1 = std::chrono::steady_clock::now();
  for (const double adaptivity : adaptivities)
  {
    std::vector<openvdb::Vec3s> meshPoints;
    std::vector<openvdb::Vec3I> meshTris;
    std::vector<openvdb::Vec4I> meshQuads;
    try
    {
      openvdb::tools::volumeToMesh(*grid, meshPoints, meshTris, meshQuads, iso, adaptivity, true);
    }
    catch (const std::exception& e)
    {
      out.Error = std::string("OpenVDB could not extract the isosurface: ") + e.what();
      return out;
    }
    out.Surfaces.emplace_back();
    TriangleMesh& s = out.Surfaces.back();
    s.Points.resize(meshPoints.size());
    for (std::size_t i = 0; i < meshPoints.size(); ++i)
    {
      s.Points[i] = Vec3(meshPoints[i].x(), meshPoints[i].y(), meshPoints[i].z());
    }
    s.Triangles.reserve(meshTris.size() + 2 * meshQuads.size());
    // OpenVDB's polygons wind clockwise seen from outside; we store counter-clockwise.
    for (const auto& t : meshTris)
    {
      s.Triangles.push_back({ static_cast<int>(t[0]), static_cast<int>(t[2]), static_cast<int>(t[1]) });
    }
    for (const auto& q : meshQuads)
    {
      const int a = q[0], b = q[1], c = q[2], d = q[3];
      // split along the shorter diagonal (better-shaped triangles)
      if ((s.Points[a] - s.Points[c]).squaredNorm() <= (s.Points[b] - s.Points[d]).squaredNorm())
      {
        s.Triangles.push_back({ a, c, b });
        s.Triangles.push_back({ a, d, c });
      }
      else
      {
        s.Triangles.push_back({ a, d, b });
        s.Triangles.push_back({ b, d, c });
      }
    }
  }
  progressUpdate(progress, 0.9);

  if (keepField)
  {
    // For display: a separate, coarser field (at most 256 samples per axis) over the whole box
    // with the interior filled and a wide exterior band, so slices and contours show the real
    // distances rather than the narrow band the envelope needs.
    const auto box = bounds(unitInput);
    const double extent = (box[1] - box[0]).maxCoeff() + 4.0 * iso;
    const double spacing = std::max(voxelSize, extent / 255.0);
    std::vector<openvdb::Vec3s> coarsePoints(unitInput.Points.size());
    for (std::size_t i = 0; i < coarsePoints.size(); ++i)
    {
      const Vec3 p = unitInput.Points[i] / spacing;
      coarsePoints[i] = openvdb::Vec3s(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
    openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> coarseAdapter(coarsePoints, tris);
    auto coarseTransform = openvdb::math::Transform::createLinearTransform(spacing);
    const float band = static_cast<float>(std::ceil(2.0 * iso / spacing) + 8.0);
    openvdb::FloatGrid::Ptr field;
    try
    {
      field = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        coarseAdapter, *coarseTransform, band, std::numeric_limits<float>::max(), 0);
    }
    catch (const std::exception& e)
    {
      out.Error = std::string("OpenVDB could not compute the display field: ") + e.what();
      return out;
    }
    ScalarImage& img = out.Field;
    img.Spacing = spacing;
    const Vec3 lo = box[0] - Vec3::Constant(2.0 * iso + 2.0 * spacing);
    const Vec3 hi = box[1] + Vec3::Constant(2.0 * iso + 2.0 * spacing);
    img.Origin = lo;
    for (int a = 0; a < 3; ++a)
    {
      img.Dimensions[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / spacing)) + 1;
    }
    img.Values.resize(static_cast<std::size_t>(img.Dimensions[0]) * img.Dimensions[1] * img.Dimensions[2]);
    openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*field);
    std::size_t n = 0;
    for (int k = 0; k < img.Dimensions[2]; ++k)
      for (int j = 0; j < img.Dimensions[1]; ++j)
        for (int i = 0; i < img.Dimensions[0]; ++i)
        {
          img.Values[n++] = sampler.wsSample(openvdb::Vec3d(lo.x() + i * spacing, lo.y() + j * spacing, lo.z() + k * spacing));
        }
  }
  out.IsosurfaceSeconds = seconds(t1);
  progressUpdate(progress, 1.0);
  return out;
}

} // namespace sdfcage
