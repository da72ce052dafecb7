#include "Envelope/SDFIsosurface.h"

#include "Envelope/ActivePoints.h"
#include "Spatial/Geometry.h"
#include "Common/Progress.h"
#include "Spatial/TriangleTree.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <limits>
#include <mutex>
#include <cstdlib>
#include <condition_variable>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>

namespace sdfcage
{

namespace
{

/// OpenVDB interrupter backed by our Progress: one mechanism for both. Past `ExpansionPercent`
/// (meshToVolume's narrow-band expansion, which checks only between its iterations, each seconds
/// long on a large mesh) it arms `Expanding`: CancellableMeshAdapter cuts the work short from inside.
class VdbInterrupter : public openvdb::util::NullInterrupter
{
public:
  VdbInterrupter(Progress* p, double begin, double end, std::atomic<bool>* expanding = nullptr)
    : P(p)
    , Begin(begin)
    , End(end)
    , Expanding(expanding)
  {
  }
  /// meshToVolume's progress (OpenVDB 10) when the band expansion starts.
  static constexpr int ExpansionPercent = 54;

  bool wasInterrupted(int percent = -1) override
  {
    if (!P)
    {
      return false;
    }
    if (percent >= 0)
    {
      P->update(Begin + (End - Begin) * std::clamp(percent, 0, 100) / 100.0);
      if (Expanding && percent >= ExpansionPercent)
      {
        Expanding->store(true);
      }
    }
    return P->cancelled();
  }

private:
  Progress* P;
  double Begin, End;
  std::atomic<bool>* Expanding;
};

/// The triangles for meshToVolume (as openvdb::tools::QuadAndTriangleDataAdapter gives them),
/// with a cancel check in the one call every distance computation makes: once `expanding` is set
/// (OpenVDB's own checks cover the voxelization before it), every 1024th call on a thread checks
/// `progress`. From a cancel on, every triangle answers as if it were far away (1e15 index units):
/// no voxel is within the band any more, so the band expansion's current iteration makes no new
/// node and skips its second layer, ends, and OpenVDB's check before the next one returns. (It
/// used to throw instead, which stopped sooner but lost the nodes made so far in the iteration:
/// OpenVDB holds them by raw pointers in its parallel_reduce bodies until the iteration's end, a
/// few megabytes per cancel.) The grid is then wrong, and thrown away: the caller sees the cancel.
/// `scale` maps the points' index space to the grid's (0.5 for a grid twice as coarse).
class CancellableMeshAdapter
{
public:
  CancellableMeshAdapter(const std::vector<openvdb::Vec3s>& points, const std::vector<openvdb::Vec3I>& triangles,
    Progress* progress, const std::atomic<bool>* expanding, double scale = 1.0)
    : Points(points)
    , Triangles(triangles)
    , P(progress)
    , Expanding(expanding)
    , Scale(scale)
  {
  }
  std::size_t polygonCount() const { return Triangles.size(); }
  std::size_t pointCount() const { return Points.size(); }
  std::size_t vertexCount(std::size_t) const { return 3; }
  void getIndexSpacePoint(std::size_t n, std::size_t v, openvdb::Vec3d& pos) const
  {
    if (P && Expanding->load(std::memory_order_relaxed))
    {
      thread_local unsigned calls = 0;
      if (Stopped.load(std::memory_order_relaxed) || ((++calls & 1023u) == 0 && P->cancelled()))
      {
        Stopped.store(true, std::memory_order_relaxed);
        pos = openvdb::Vec3d(1e15, 1e15, 1e15);
        return;
      }
    }
    const openvdb::Vec3s& p = Points[Triangles[n][static_cast<int>(v)]];
    pos[0] = Scale * double(p[0]);
    pos[1] = Scale * double(p[1]);
    pos[2] = Scale * double(p[2]);
  }

private:
  const std::vector<openvdb::Vec3s>& Points;
  const std::vector<openvdb::Vec3I>& Triangles;
  Progress* P;
  const std::atomic<bool>* Expanding;
  const double Scale;
  mutable std::atomic<bool> Stopped{ false };
};

double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::once_flag vdbInit;

/// phi at world position x (unit-sphere units) given the closest triangle of amp.Surface.
double phiAt(const ActivePoints& amp, const Vec3& x, int triangle, double distance)
{
  const Triangle& t = amp.Surface.Triangles[triangle];
  const Vec3 closest =
    closestPointOnTriangle(x, amp.Surface.Points[t[0]], amp.Surface.Points[t[1]], amp.Surface.Points[t[2]]);
  return amp.amplificationAt(triangle, closest, distance);
}

/// Triangle ids sorted by the Morton code of their centroids in cells of two index units
/// (ties by id, so the order is deterministic).
std::vector<int> mortonOrder(const std::vector<openvdb::Vec3s>& points, const std::vector<Triangle>& triangles)
{
  const auto spread = [](std::uint64_t x) {
    x &= 0x1FFFFF; // 21 bits per axis
    x = (x | (x << 32)) & 0x1F00000000FFFFull;
    x = (x | (x << 16)) & 0x1F0000FF0000FFull;
    x = (x | (x << 8)) & 0x100F00F00F00F00Full;
    x = (x | (x << 4)) & 0x10C30C30C30C30C3ull;
    x = (x | (x << 2)) & 0x1249249249249249ull;
    return x;
  };
  openvdb::Vec3s lo(std::numeric_limits<float>::max());
  for (const auto& p : points)
  {
    lo = openvdb::math::minComponent(lo, p);
  }
  std::vector<std::pair<std::uint64_t, int>> keys(triangles.size());
  tbb::parallel_for(
    tbb::blocked_range<std::size_t>(0, triangles.size(), 8192), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = triangles[f];
        const openvdb::Vec3s c = (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0f - lo;
        std::uint64_t code = 0;
        for (int a = 0; a < 3; ++a)
        {
          const double cell = std::floor(std::max(0.0, static_cast<double>(c[a])) / 2.0);
          code |= spread(static_cast<std::uint64_t>(std::min(cell, 2097151.0))) << a;
        }
        keys[f] = { code, static_cast<int>(f) };
      }
    });
  std::sort(keys.begin(), keys.end());
  std::vector<int> order(keys.size());
  for (std::size_t f = 0; f < keys.size(); ++f)
  {
    order[f] = keys[f].second;
  }
  return order;
}

/// A vertex-clustered proxy of `mesh` for the distance field (vertex clustering, Rossignac and
/// Borrel 1993): the points snapped into cubic cells of `cell` (unit-sphere units), each cell's
/// points replaced by their mean, triangles whose corners fall into fewer than three cells
/// dropped. The proxy is the image of the surface under that map, so a closed input gives a
/// proxy without holes (it may be non-manifold: the flood fill does not mind). `points` are in
/// index space (voxel centres at integers, as meshToVolume reads them); `source` gives each kept
/// triangle's index in `mesh`. Written here: OpenVDB and VTK have no clustering that keeps the
/// triangles' origin.
void clusteredProxy(const TriangleMesh& mesh, double voxelSize, double cell, std::vector<openvdb::Vec3s>& points,
  std::vector<Triangle>& triangles, std::vector<int>& source)
{
  const std::size_t n = mesh.Points.size();
  std::vector<std::pair<std::uint64_t, int>> keys(n);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (const Vec3& p : mesh.Points)
    lo = lo.cwiseMin(p);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
    {
      const Vec3 q = (mesh.Points[i] - lo) / cell;
      std::uint64_t key = 0;
      for (int a = 0; a < 3; ++a)
        key = (key << 21) | static_cast<std::uint64_t>(std::min(2097151.0, std::max(0.0, std::floor(q[a]))));
      keys[i] = { key, static_cast<int>(i) };
    }
  });
  tbb::parallel_sort(keys.begin(), keys.end());
  std::vector<int> rep(n);
  std::vector<Vec3> sum;
  std::vector<int> count;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (i == 0 || keys[i].first != keys[i - 1].first)
    {
      sum.push_back(Vec3::Zero());
      count.push_back(0);
    }
    rep[keys[i].second] = static_cast<int>(sum.size()) - 1;
    sum.back() += mesh.Points[keys[i].second];
    ++count.back();
  }
  points.resize(sum.size());
  for (std::size_t k = 0; k < sum.size(); ++k)
  {
    const Vec3 p = sum[k] / (count[k] * voxelSize);
    points[k] = openvdb::Vec3s(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  triangles.clear();
  source.clear();
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    const int a = rep[t[0]], b = rep[t[1]], c = rep[t[2]];
    if (a == b || b == c || a == c)
      continue;
    triangles.push_back({ a, b, c });
    source.push_back(static_cast<int>(f));
  }
}

/// xi -> phi * xi on the active voxels outside the input (values in (0, maxValue]); returns the
/// number of voxels changed by more than 1e-3 relative.
/// `noAdapt` (a topology copy of grid's tree) keeps on only the voxels where phi > 1 + f (alpha - 1),
/// f = amp.AdaptivityOffFraction: 0.5 by default (phi 2 at alpha 3: there the envelope lies
/// within c / 2 of the input, its margin to the clearance (c/4 by default) a third of the
/// unamplified one or less; the first topology repair round keeps it and merges at adaptivity 1,
/// see buildEnvelope in Envelope.cxx). Merged polygons stay allowed where phi is smaller: the Gaussian of the
/// amplification reaches far (phi - 1 is still 1% of alpha - 1 at 0.27 from an active point at
/// beta 8), and with the first bound, phi > 1 + 0.01 (alpha - 1), nothing was left to merge on
/// inputs with active points all over. Measured, 500-vertex cages (whole runs, `sdfcage --check`
/// for the Hausdorff distance cage->input of the diagonal): f 0.01 -> 0.3, dragon_quartet (409
/// active points, repaired at voxel 0.0025) envelope 545,714 -> 320,176 triangles, 29.8 -> 22.7
/// s, H 0.0516 -> 0.0553; dragon_vrip (1,330) 133,344 -> 90,346 triangles, 9.6 -> 8.4 s, H 0.0451
/// -> 0.0394. f 0.3 -> 0.5 (2026-12-05, four runs each alternating): dragon_vrip 83,882
/// triangles, 8.9-10.3 -> 8.6-10.2 s (mean 9.66 -> 9.43 s), H 0.0394 -> 0.0325, input->cage
/// 0.0483 -> 0.0463; the built-in shape 44,066 -> 37,056 triangles, topology kept. The meshes
/// without active points take another path (unchanged). Every envelope is verified as before,
/// and one whose merged polygons fail gets adaptivity switched off around the defects
/// (computeIsosurface).
std::size_t amplify(openvdb::FloatGrid& grid, const openvdb::Int32Grid& index, const std::vector<int>& order,
  const ActivePoints& amp, double voxelSize, float maxValue, openvdb::BoolTree& noAdapt, Progress* progress)
{
  openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid.tree());
  std::atomic<std::size_t> changed{ 0 };
  const int triangles = static_cast<int>(amp.Surface.Triangles.size());
  const double noAdaptPhi = 1.0 + amp.AdaptivityOffFraction * (amp.Alpha - 1.0);
  tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange& range) {
    auto acc = index.getConstAccessor();
    std::size_t local = 0;
    for (auto leaf = range.begin(); leaf; ++leaf)
    {
      if (progressCancelled(progress))
      {
        return; // the caller reports the cancel
      }
      openvdb::BoolTree::LeafNodeType* maskLeaf = noAdapt.probeLeaf(leaf->origin());
      for (auto it = leaf->beginValueOn(); it; ++it)
      {
        const float v = *it;
        if (!(v > 0.0f) || v > maxValue)
        {
          if (maskLeaf)
          {
            maskLeaf->setValueOff(it.pos());
          }
          continue;
        }
        const openvdb::Coord ijk = it.getCoord();
        const int position = acc.getValue(ijk);
        if (position < 0 || position >= static_cast<int>(order.size()))
        {
          continue;
        }
        const int t = order[position];
        if (t < 0 || t >= triangles)
        {
          continue;
        }
        const Vec3 x(ijk.x() * voxelSize, ijk.y() * voxelSize, ijk.z() * voxelSize);
        const double phi = phiAt(amp, x, t, v);
        if (phi > 1.001)
        {
          ++local;
        }
        if (maskLeaf && !(phi > noAdaptPhi))
        {
          maskLeaf->setValueOff(it.pos());
        }
        it.setValue(static_cast<float>(phi * v));
      }
    }
    changed += local;
  });
  return changed.load();
}

/// OpenVDB's polygons as our triangles (unit-sphere units): quads split on the shorter diagonal,
/// counter-clockwise seen from outside.
TriangleMesh toTriangles(const openvdb::tools::VolumeToMesh& mesher)
{
  TriangleMesh s;
  s.Points.resize(mesher.pointListSize());
  const auto& pts = mesher.pointList();
  for (std::size_t i = 0; i < s.Points.size(); ++i)
  {
    s.Points[i] = Vec3(pts[i].x(), pts[i].y(), pts[i].z());
  }
  const openvdb::tools::PolygonPoolList& pools = mesher.polygonPoolList();
  for (std::size_t n = 0; n < mesher.polygonPoolListSize(); ++n)
  {
    const openvdb::tools::PolygonPool& pool = pools[n];
    // OpenVDB's polygons wind clockwise seen from outside; we store counter-clockwise.
    for (std::size_t i = 0; i < pool.numTriangles(); ++i)
    {
      const openvdb::Vec3I& t = pool.triangle(i);
      s.Triangles.push_back({ static_cast<int>(t[0]), static_cast<int>(t[2]), static_cast<int>(t[1]) });
    }
    for (std::size_t i = 0; i < pool.numQuads(); ++i)
    {
      const openvdb::Vec4I& q = pool.quad(i);
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
  return s;
}

/// The extractions still running after a cancel (see extract): the process waits for them at its
/// exit (this object's destructor runs before those of OpenVDB's and TBB's statics, which were
/// made before it), so that none is inside OpenVDB or TBB while they are torn down.
class AbandonedExtractions
{
public:
  static AbandonedExtractions& instance()
  {
    static AbandonedExtractions registry;
    return registry;
  }
  void started()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    ++this->Running;
  }
  void ended()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    --this->Running;
    this->Done.notify_all();
  }
  void abandoned() { this->Count.fetch_add(1); }
  long long count() const { return this->Count.load(); }
  ~AbandonedExtractions()
  {
    std::unique_lock<std::mutex> lock(this->Mutex);
    this->Done.wait(lock, [this]() { return this->Running == 0; });
  }

private:
  std::mutex Mutex;
  std::condition_variable Done;
  int Running = 0;
  std::atomic<long long> Count{ 0 }; // abandoned since the process started
};

/// One extraction: OpenVDB's VolumeToMesh (no interrupter in OpenVDB 10), on a thread of its own.
struct ExtractionJob
{
  openvdb::FloatGrid::ConstPtr Grid;
  openvdb::BoolTree::ConstPtr NoAdapt;
  double Iso = 0.0;
  double Adaptivity = 0.0;
  openvdb::tools::VolumeToMesh Mesher;
  std::string Error;
  std::mutex Mutex;
  std::condition_variable Changed;
  bool Finished = false;

  ExtractionJob(openvdb::FloatGrid::ConstPtr grid, openvdb::BoolTree::ConstPtr noAdapt, double iso, double adaptivity)
    : Grid(std::move(grid))
    , NoAdapt(std::move(noAdapt))
    , Iso(iso)
    , Adaptivity(adaptivity)
    , Mesher(iso, adaptivity, true)
  {
    if (this->NoAdapt && adaptivity > 0.0)
    {
      this->Mesher.setAdaptivityMask(this->NoAdapt);
    }
  }
  void run()
  {
    try
    {
      this->Mesher(*this->Grid);
    }
    catch (const std::exception& e)
    {
      this->Error = e.what();
    }
    catch (...)
    {
      this->Error = "unknown error";
    }
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Finished = true;
    this->Changed.notify_all();
  }
};

/// The isosurface {value = iso} of `grid` (unit-sphere units), quads split on the shorter
/// diagonal, counter-clockwise seen from outside; no adaptivity inside `noAdapt`.
///
/// OpenVDB's VolumeToMesh has no interrupter, and one extraction takes 0.4-1.0 s on
/// armadillo_midsub4x (2 loaded cores). So it runs on a thread of its own while this one checks
/// `progress` every 20 ms: a cancel returns at once (`cancelled` set, empty mesh) and abandons the
/// extraction, which ends on its own (it owns what it reads: the grid and the mask are shared) and
/// frees its memory; the process waits for it at exit (AbandonedExtractions). Same mesh as a plain
/// call: the same OpenVDB code on the same data. Throws what the extraction threw (as
/// std::runtime_error).
TriangleMesh extract(const openvdb::FloatGrid::ConstPtr& grid, double iso, double adaptivity,
  const openvdb::BoolTree::ConstPtr& noAdapt, Progress* progress, bool& cancelled)
{
  cancelled = false;
  auto job = std::make_shared<ExtractionJob>(grid, noAdapt, iso, adaptivity);
  if (!progress)
  {
    job->run(); // nothing can cancel: no thread
  }
  else
  {
    AbandonedExtractions& abandoned = AbandonedExtractions::instance();
    abandoned.started();
    try
    {
      std::thread([job, &abandoned]() mutable {
        job->run();
        job.reset(); // frees the mesh of an abandoned extraction before the exit may go on
        abandoned.ended();
      }).detach();
    }
    catch (const std::system_error&)
    {
      abandoned.ended();
      job->run(); // no thread to be had: uninterruptible, as OpenVDB is
    }
    std::unique_lock<std::mutex> lock(job->Mutex);
    while (!job->Finished)
    {
      if (job->Changed.wait_for(lock, std::chrono::milliseconds(20), [&job]() { return job->Finished; }))
      {
        break;
      }
      lock.unlock();
      const bool stop = progress->cancelled(); // may fire the filter's progress event: unlocked
      lock.lock();
      if (stop && !job->Finished)
      {
        cancelled = true;
        AbandonedExtractions::instance().abandoned();
        return TriangleMesh();
      }
    }
  }
  if (!job->Error.empty())
  {
    throw std::runtime_error(job->Error);
  }
  return toTriangles(job->Mesher);
}

/// Marks the voxels within `radius` voxels of each point (unit-sphere units).
/// Returns how many voxels were not marked before.
std::size_t markAround(const std::vector<Vec3>& points, double voxelSize, int radius, openvdb::BoolTree& mask)
{
  openvdb::tree::ValueAccessor<openvdb::BoolTree> acc(mask);
  std::size_t added = 0;
  for (const Vec3& p : points)
  {
    const openvdb::Coord c(static_cast<int>(std::lround(p.x() / voxelSize)),
      static_cast<int>(std::lround(p.y() / voxelSize)), static_cast<int>(std::lround(p.z() / voxelSize)));
    for (int k = -radius; k <= radius; ++k)
      for (int j = -radius; j <= radius; ++j)
        for (int i = -radius; i <= radius; ++i)
        {
          const openvdb::Coord ijk = c.offsetBy(i, j, k);
          if (!acc.isValueOn(ijk))
          {
            acc.setValueOn(ijk, true);
            ++added;
          }
        }
  }
  return added;
}

/// computeIsosurface's field with a LocalExactField: the amplified field of the grid twice as
/// coarse (OpenVDB's, from `coarse` and its closest triangles `coarseClosest`, positions in
/// `order`), interpolated onto the grid of `voxelSize`, and computed exactly (a query of
/// local.Tree per voxel, signed by the pseudo-normal) within local.Dilation coarse voxels of a
/// facing gap.
/// `noAdapt` gets the voxels the amplification keeps uniform (as amplify marks them). Returns
/// the grid (nullptr when cancelled); `exact` counts the voxels computed exactly.
openvdb::FloatGrid::Ptr localExactField(const openvdb::FloatGrid& coarse, const openvdb::BoolTree& coarseMask,
  const openvdb::Int32Grid& coarseClosest, const std::vector<int>& order, const ActivePoints& amp,
  const LocalExactField& local, double voxelSize, double iso, float background, openvdb::BoolTree& noAdapt,
  std::size_t& exact, std::size_t& amplified, Progress* progress)
{
  using LeafT = openvdb::FloatTree::LeafNodeType;
  // the fine leaves under the coarse ones: each coarse leaf of 8^3 voxels covers 2^3 fine leaves
  std::vector<const openvdb::FloatTree::LeafNodeType*> coarseLeaves;
  coarse.tree().getNodes(coarseLeaves);
  std::vector<std::unique_ptr<LeafT>> fine(8 * coarseLeaves.size());
  std::vector<std::unique_ptr<openvdb::BoolTree::LeafNodeType>> fineMask(fine.size());
  const PseudoNormalSign sign(amp.Surface);
  // The gaps the coarse grid may fuse: neighbouring coarse voxels whose closest points lie on
  // surfaces facing each other across the space between them (each one's normal points at the
  // other's closest point; inside a thin part they point away from each other). Every voxel
  // within `Dilation` coarse voxels of one is exact.
  openvdb::BoolTree gaps(false);
  {
    using CoarseLeaf = openvdb::FloatTree::LeafNodeType;
    tbb::enumerable_thread_specific<std::vector<openvdb::Coord>> found;
    const int triangles = static_cast<int>(amp.Surface.Triangles.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, coarseLeaves.size(), 8),
      [&](const tbb::blocked_range<std::size_t>& r) {
        auto idx = coarseClosest.getConstAccessor();
        auto values = coarse.getConstAccessor();
        auto& mine = found.local();
        // a voxel's closest point and the normal of its triangle (false where it has none)
        const auto closestAt = [&](const openvdb::Coord& ijk, Vec3& cp, Vec3& n) {
          const int position = idx.getValue(ijk);
          if (position < 0 || position >= static_cast<int>(order.size()))
            return false;
          const int t = order[static_cast<std::size_t>(position)];
          if (t < 0 || t >= triangles)
            return false;
          const Triangle& tri = amp.Surface.Triangles[static_cast<std::size_t>(t)];
          const Vec3 x(ijk.x() * 2.0 * voxelSize, ijk.y() * 2.0 * voxelSize, ijk.z() * 2.0 * voxelSize);
          cp = closestPointOnTriangle(x, amp.Surface.Points[tri[0]], amp.Surface.Points[tri[1]], amp.Surface.Points[tri[2]]);
          n = sign.faceNormal(t);
          return true;
        };
        // each voxel's, computed once for its leaf (a neighbour across the leaf's +x, +y or +z
        // face is computed again)
        std::vector<Vec3> cps(CoarseLeaf::SIZE), normals(CoarseLeaf::SIZE);
        std::vector<char> has(CoarseLeaf::SIZE);
        for (std::size_t l = r.begin(); l != r.end(); ++l)
        {
          const CoarseLeaf& cl = *coarseLeaves[l];
          std::fill(has.begin(), has.end(), 0);
          for (auto it = cl.cbeginValueOn(); it; ++it)
            has[it.pos()] = closestAt(it.getCoord(), cps[it.pos()], normals[it.pos()]) ? 1 : 0;
          for (auto it = cl.cbeginValueOn(); it; ++it)
          {
            if (!has[it.pos()])
              continue;
            const openvdb::Coord ijk = it.getCoord();
            const Vec3 &cp = cps[it.pos()], &n = normals[it.pos()];
            const openvdb::Coord within = ijk - cl.origin();
            for (int axis = 0; axis < 3; ++axis)
            {
              openvdb::Coord next = ijk;
              next[axis] += 1;
              Vec3 cq, m;
              if (within[axis] + 1 < static_cast<int>(CoarseLeaf::DIM))
              {
                const openvdb::Index o = CoarseLeaf::coordToOffset(next);
                if (!cl.isValueOn(o) || !has[o])
                  continue;
                cq = cps[o];
                m = normals[o];
              }
              else if (!values.isValueOn(next) || !closestAt(next, cq, m))
                continue;
              if (n.dot(m) < 0 && (cq - cp).dot(n) > 0 && (cp - cq).dot(m) > 0)
              {
                mine.push_back(ijk);
                mine.push_back(next);
              }
            }
          }
        }
      });
    for (const auto& list : found)
      for (const openvdb::Coord& c : list)
        gaps.setValueOn(c, true);
    if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
      std::fprintf(stderr, "local exact field: %zu coarse voxels at facing gaps\n", std::size_t(gaps.activeVoxelCount()));
    if (!gaps.empty())
      openvdb::tools::dilateActiveValues(gaps, local.Dilation, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
  }
  const double noAdaptPhi = 1.0 + amp.AdaptivityOffFraction * (amp.Alpha - 1.0);
  const float maxAmplified = static_cast<float>(iso + 2.0 * voxelSize);
  const double limit = static_cast<double>(background); // the band's width: beyond it, the background
  std::atomic<std::size_t> exactCount{ 0 }, amplifiedCount{ 0 };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, coarseLeaves.size(), 8),
    [&](const tbb::blocked_range<std::size_t>& r) {
      auto acc = coarse.getConstAccessor();
      openvdb::tree::ValueAccessor<const openvdb::BoolTree> maskAcc(coarseMask);
      openvdb::tree::ValueAccessor<const openvdb::BoolTree> gapAcc(gaps);
      std::size_t e = 0, a = 0;
      for (std::size_t l = r.begin(); l != r.end(); ++l)
      {
        if (progressCancelled(progress))
          return;
        const LeafT& cl = *coarseLeaves[l];
        const openvdb::Coord co = cl.origin();
        for (int s = 0; s < 8; ++s)
        {
          const openvdb::Coord fo(2 * co.x() + 8 * (s & 1), 2 * co.y() + 8 * ((s >> 1) & 1), 2 * co.z() + 8 * (s >> 2));
          auto leaf = std::make_unique<LeafT>(fo, background, false);
          auto mask = std::make_unique<openvdb::BoolTree::LeafNodeType>(fo, false, false);
          bool any = false;
          for (openvdb::Index n = 0; n < LeafT::SIZE; ++n)
          {
            const openvdb::Coord ijk = LeafT::offsetToLocalCoord(n) + fo;
            const openvdb::Coord parent(ijk.x() >> 1, ijk.y() >> 1, ijk.z() >> 1);
            const Vec3 x(ijk.x() * voxelSize, ijk.y() * voxelSize, ijk.z() * voxelSize);
            // near a gap every voxel is exact, also where the coarse grid's band has none (the
            // inside of a gap the coarse grid fused: a crossing next to an inactive voxel would
            // leave the extraction a crack)
            const bool exactHere = gapAcc.isValueOn(parent);
            if (!exactHere && !cl.isValueOn(parent))
            {
              // off: its sign for the flood fill, from the coarse grid
              leaf->setValueOnly(n, cl.getValue(parent) < 0 ? -background : background);
              continue;
            }
            any = true;
            float v = static_cast<float>(openvdb::tools::BoxSampler::sample(
              acc, openvdb::Vec3R(0.5 * ijk.x(), 0.5 * ijk.y(), 0.5 * ijk.z())));
            bool keepUniform = maskAcc.isValueOn(parent);
            if (exactHere)
            {
              ++e;
              Vec3 cp;
              int t = -1;
              double d = 0.0;
              if (!local.Tree->closestPoint(x, limit, cp, t, d))
                v = v < 0 ? -background : background;
              else
              {
                double signedD = sign.outside(x, t, cp) ? d : -d;
                keepUniform = false;
                if (signedD > 0 && signedD <= maxAmplified)
                {
                  const double phi = amp.amplificationAt(t, cp, d);
                  a += phi > 1.001 ? 1 : 0;
                  keepUniform = phi > noAdaptPhi;
                  signedD *= phi;
                }
                v = static_cast<float>(std::max(-limit, std::min(limit, signedD)));
              }
            }
            leaf->setValueOn(n, v);
            if (keepUniform)
              mask->setValueOn(n, true);
          }
          if (any)
          {
            fine[8 * l + static_cast<std::size_t>(s)] = std::move(leaf);
            fineMask[8 * l + static_cast<std::size_t>(s)] = std::move(mask);
          }
        }
      }
      exactCount += e;
      amplifiedCount += a;
    });
  if (progressCancelled(progress))
    return nullptr;
  auto grid = openvdb::FloatGrid::create(background);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  for (std::size_t i = 0; i < fine.size(); ++i)
    if (fine[i])
    {
      grid->tree().addLeaf(fine[i].release());
      noAdapt.addLeaf(fineMask[i].release());
    }
  // the inside beyond the band (tiles and untouched leaves' voxels) negative, as meshToVolume's
  openvdb::tools::signedFloodFill(grid->tree());
  exact = exactCount.load();
  amplified = amplifiedCount.load();
  return grid;
}

} // namespace

long long abandonedExtractionCount()
{
  return AbandonedExtractions::instance().count();
}

bool computeDisplayFields(const TriangleMesh& unitMesh, double iso, double minSpacing,
  const ActivePoints* amplification, ScalarImage& field, ScalarImage* modified, std::string& error)
{
  std::call_once(vdbInit, []() { openvdb::initialize(); });
  if (amplification && amplification->empty())
  {
    amplification = nullptr;
  }
  const double voxelSize = minSpacing;
  std::vector<openvdb::Vec3I> tris(unitMesh.Triangles.size());
  for (std::size_t f = 0; f < tris.size(); ++f)
  {
    const Triangle& t = unitMesh.Triangles[f];
    tris[f] = openvdb::Vec3I(t[0], t[1], t[2]);
  }

  // For display: a separate, coarser field (at most 256 samples per axis) over the whole box
  // with the interior filled and a wide exterior band, so slices and contours show the real
  // distances rather than the narrow band the envelope needs.
  const auto box = bounds(unitMesh);
  const double extent = (box[1] - box[0]).maxCoeff() + 4.0 * iso;
  const double spacing = std::max(voxelSize, extent / 255.0);
  std::vector<openvdb::Vec3s> coarsePoints(unitMesh.Points.size());
  for (std::size_t i = 0; i < coarsePoints.size(); ++i)
  {
    const Vec3 p = unitMesh.Points[i] / spacing;
    coarsePoints[i] = openvdb::Vec3s(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> coarseAdapter(coarsePoints, tris);
  auto coarseTransform = openvdb::math::Transform::createLinearTransform(spacing);
  // With amplification the exterior band also covers where phi differs from 1 noticeably
  // (phi - 1 < 2e-4 (alpha - 1) beyond 0.36 at beta = 8), and closest triangles are kept.
  double bandWorld = 2.0 * iso + 8.0 * spacing;
  openvdb::Int32Grid::Ptr displayTriangle;
  if (amplification)
  {
    bandWorld = std::max(bandWorld, std::min(amplification->Cutoff, 3.0 / amplification->Beta));
    displayTriangle = openvdb::Int32Grid::create(-1);
  }
  const float band = static_cast<float>(std::ceil(bandWorld / spacing) + 1.0);
  openvdb::FloatGrid::Ptr grid;
  try
  {
    openvdb::util::NullInterrupter none;
    grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      none, coarseAdapter, *coarseTransform, band, std::numeric_limits<float>::max(), 0, displayTriangle.get());
  }
  catch (const std::exception& e)
  {
    error = std::string("OpenVDB could not compute the display field: ") + e.what();
    return false;
  }
  ScalarImage& img = field;
  img.Spacing = spacing;
  // samples on the voxel centres of the display grid (no interpolation)
  openvdb::Coord first, last;
  for (int a = 0; a < 3; ++a)
  {
    first[a] = static_cast<int>(std::floor((box[0][a] - 2.0 * iso) / spacing)) - 2;
    last[a] = static_cast<int>(std::ceil((box[1][a] + 2.0 * iso) / spacing)) + 2;
    img.Dimensions[a] = last[a] - first[a] + 1;
  }
  img.Origin = Vec3(first.x(), first.y(), first.z()) * spacing;
  const std::size_t count = static_cast<std::size_t>(img.Dimensions[0]) * img.Dimensions[1] * img.Dimensions[2];
  img.Values.resize(count);
  if (modified)
  {
    *modified = img;
    modified->Values.resize(count);
  }
  const int nx = img.Dimensions[0], ny = img.Dimensions[1];
  const int triangles = static_cast<int>(unitMesh.Triangles.size());
  tbb::parallel_for(0, img.Dimensions[2], [&](int k) {
    auto acc = grid->getConstAccessor();
    std::unique_ptr<openvdb::Int32Grid::ConstAccessor> tri;
    if (displayTriangle)
    {
      tri = std::make_unique<openvdb::Int32Grid::ConstAccessor>(displayTriangle->getConstAccessor());
    }
    std::size_t n = static_cast<std::size_t>(k) * nx * ny;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, ++n)
      {
        const openvdb::Coord ijk(first.x() + i, first.y() + j, first.z() + k);
        const float v = acc.getValue(ijk);
        img.Values[n] = v;
        if (tri && modified)
        {
          const int t = tri->getValue(ijk);
          double phi = 1.0;
          if (t >= 0 && t < triangles)
          {
            phi = phiAt(*amplification, Vec3(ijk.x(), ijk.y(), ijk.z()) * spacing, t, std::abs(v));
          }
          modified->Values[n] = static_cast<float>(phi * v);
        }
      }
  });
  return true;
}

/// The unsigned narrow band (what meshToVolume gives with UNSIGNED_DISTANCE_FIELD: world-space
/// distances below `band` voxels active, background band x voxelSize elsewhere), computed per
/// voxel from the input's tree instead of per triangle. Written here because OpenVDB's
/// voxelization visits the whole band around every triangle: for inputs whose triangles are
/// smaller than a voxel (a 100k-face scan or soup on the coarse grids of probes and widened
/// envelopes) that is (2 band + 1)^3 closest-point evaluations per triangle, 90% of them for
/// voxels other triangles are nearer to. Here the voxels near the input are found first (each
/// triangle marks the voxels of its box, large ones split until their pieces span two voxels or
/// less; the mask is then dilated by the band, a superset of the voxels within the band), and
/// each gets one exact query: the work follows the band's voxels, not the triangles.
/// Null when cancelled.
openvdb::FloatGrid::Ptr unsignedBandField(const TriangleMesh& mesh, const TriangleTree& tree, double voxelSize,
  int band, Progress* progress)
{
  using MaskTree = openvdb::MaskTree;
  tbb::enumerable_thread_specific<MaskTree> masks;
  std::atomic<bool> stop{ false };
  const double inv = 1.0 / voxelSize;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.Triangles.size(), 4096),
    [&](const tbb::blocked_range<std::size_t>& r) {
      if (stop.load() || progressCancelled(progress))
      {
        stop.store(true);
        return;
      }
      MaskTree& mask = masks.local();
      openvdb::tree::ValueAccessor<MaskTree> acc(mask);
      struct Piece
      {
        Vec3 A, B, C;
      };
      std::vector<Piece> pending;
      for (std::size_t f = r.begin(); f != r.end(); ++f)
      {
        const Triangle& t = mesh.Triangles[f];
        pending.push_back({ mesh.Points[t[0]] * inv, mesh.Points[t[1]] * inv, mesh.Points[t[2]] * inv });
        while (!pending.empty())
        {
          const Piece q = pending.back();
          pending.pop_back();
          const Vec3 lo = q.A.cwiseMin(q.B).cwiseMin(q.C), hi = q.A.cwiseMax(q.B).cwiseMax(q.C);
          if ((hi - lo).maxCoeff() > 2.0)
          {
            // halved across its longest edge: a sliver makes about length / h pieces, not
            // (length / h)^2 (see bandPieces)
            const double ab = (q.B - q.A).squaredNorm(), bc = (q.C - q.B).squaredNorm(),
                         ca = (q.A - q.C).squaredNorm();
            if (ab >= bc && ab >= ca)
            {
              const Vec3 m = 0.5 * (q.A + q.B);
              pending.push_back({ q.A, m, q.C });
              pending.push_back({ m, q.B, q.C });
            }
            else if (bc >= ca)
            {
              const Vec3 m = 0.5 * (q.B + q.C);
              pending.push_back({ q.A, q.B, m });
              pending.push_back({ q.A, m, q.C });
            }
            else
            {
              const Vec3 m = 0.5 * (q.C + q.A);
              pending.push_back({ q.A, q.B, m });
              pending.push_back({ m, q.B, q.C });
            }
            continue;
          }
          const openvdb::Coord c0(static_cast<int>(std::floor(lo.x())), static_cast<int>(std::floor(lo.y())),
            static_cast<int>(std::floor(lo.z())));
          const openvdb::Coord c1(static_cast<int>(std::ceil(hi.x())), static_cast<int>(std::ceil(hi.y())),
            static_cast<int>(std::ceil(hi.z())));
          for (int i = c0.x(); i <= c1.x(); ++i)
            for (int j = c0.y(); j <= c1.y(); ++j)
              for (int k = c0.z(); k <= c1.z(); ++k)
                acc.setValueOn(openvdb::Coord(i, j, k));
        }
      }
    });
  if (stop.load() || progressCancelled(progress))
  {
    return nullptr;
  }
  MaskTree mask;
  for (MaskTree& m : masks)
  {
    mask.topologyUnion(m);
  }
  openvdb::tools::dilateActiveValues(mask, band, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
  const float background = static_cast<float>(band * voxelSize);
  auto grid = openvdb::FloatGrid::create(background);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  grid->setTree(openvdb::FloatTree::Ptr(new openvdb::FloatTree(mask, background, background, openvdb::TopologyCopy())));
  openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid->tree());
  const double limit = band * voxelSize;
  tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange& r) {
    for (auto leaf = r.begin(); leaf; ++leaf)
    {
      if (stop.load() || progressCancelled(progress))
      {
        stop.store(true);
        return;
      }
      for (auto v = leaf->beginValueOn(); v; ++v)
      {
        const openvdb::Coord ijk = v.getCoord();
        const Vec3 x(ijk.x() * voxelSize, ijk.y() * voxelSize, ijk.z() * voxelSize);
        Vec3 closest;
        int triangle = -1;
        double d = limit;
        if (tree.closestPoint(x, limit, closest, triangle, d) && d < limit)
        {
          v.setValue(static_cast<float>(d));
        }
        else
        {
          v.setValue(background);
          v.setValueOff();
        }
      }
    }
  });
  if (stop.load() || progressCancelled(progress))
  {
    return nullptr;
  }
  openvdb::tools::pruneInactive(grid->tree());
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

IsosurfaceOutput computeIsosurface(const TriangleMesh& unitInput, double voxelSize, double iso, bool keepField,
  Progress* progress, const std::vector<double>& adaptivities, const ActivePoints* amplification,
  const SurfaceJudge* judge, int maxRepairs, SignMode sign, const TriangleTree* windingTree, bool clusteredField,
  const LocalExactField* local)
{
  std::call_once(vdbInit, []() { openvdb::initialize(); });
  if (amplification && amplification->empty())
  {
    amplification = nullptr; // no active point: phi = 1 everywhere
  }
  const TriangleMesh& unitMesh = amplification ? amplification->Surface : unitInput;
  IsosurfaceOutput out;
  auto t0 = std::chrono::steady_clock::now();

  std::atomic<bool> expanding{ false };

  // The isosurface at `iso` needs values up to iso plus one voxel. Corners beyond the band read the
  // background (band width), which is still > iso: the crossing can only move outward (the safe
  // side), and the envelope is verified anyway. Inside, one voxel is enough: the flood fill gives
  // the interior its sign. Narrow bands are most of the speed of this stage.
  const float exteriorBand = static_cast<float>(std::ceil(iso / voxelSize) + 1.0);
  const bool unsignedField = sign != SignMode::FloodFill;
  const float interiorBand = unsignedField ? exteriorBand : 1.0f;
  VdbInterrupter sdfInterrupter(progress, 0.0, 0.6, &expanding);
  openvdb::FloatGrid::Ptr grid;
  openvdb::Int32Grid::Ptr closestTriangle;
  if (amplification)
  {
    closestTriangle = openvdb::Int32Grid::create(-1);
  }
  // The unsigned band from the input's tree (unsignedBandField) where the triangles are smaller
  // than the voxels: more triangles than the surface has voxel faces (area / h^2). OpenVDB's
  // voxelization costs about (2 band + 1)^3 point-triangle distances per triangle, ours one tree
  // query per band voxel (about (2 band + 1) area / h^2 of them, each some 30 such distances):
  // about even where triangles = area / h^2. Measured: the benchmark's 100k-face soup at voxels
  // 0.02 and 0.04 (13 and 3 triangles per voxel face) 0.09-0.13 s against 0.23-0.30 s; face.obj
  // at 0.005 (0.4 per voxel face) 1.14 s against 0.74 s. SDFCAGE_VDB_UNSIGNED=1 keeps OpenVDB's
  // everywhere (for comparisons).
  bool ownBand = unsignedField && windingTree && !amplification && !std::getenv("SDFCAGE_VDB_UNSIGNED");
  // Its marking splits large triangles into pieces two voxels across: about (1 + length / h)
  // (1 + width / h) per triangle; a hostile input of many long slivers would make that huge, and
  // gets OpenVDB's (whose cost is bounded by its band around each triangle).
  if (ownBand)
  {
    double area = 0.0, pieces = 0.0;
    std::size_t small = 0;
    for (const Triangle& t : unitMesh.Triangles)
    {
      const Vec3 &a = unitMesh.Points[t[0]], &b = unitMesh.Points[t[1]], &c = unitMesh.Points[t[2]];
      const double twice = (b - a).cross(c - a).norm();
      const double length = std::max({ (b - a).norm(), (c - b).norm(), (a - c).norm() });
      area += 0.5 * twice;
      pieces += (1.0 + length / voxelSize) * (1.0 + (length > 0 ? twice / length : 0.0) / voxelSize);
      small += length <= voxelSize ? 1 : 0;
    }
    // and 90% of the triangles no longer than a voxel: long slivers (area but no width) make the
    // tree's boxes overlap and its queries slow (2,000 random slivers across the unit sphere:
    // 2.2 s against OpenVDB's 1.2 s on a grid of 0.02)
    const std::size_t n = unitMesh.Triangles.size();
    ownBand = static_cast<double>(n) * voxelSize * voxelSize > area && 10 * small >= 9 * n && pieces < 5.0e7;
  }
  // OpenVDB's input (not needed by the band from the tree): the mesh in index space (voxel centres
  // at integer coordinates), its triangles in Morton order of their centroids (cells of two voxels):
  // OpenVDB's voxelization gives each thread scratch trees that spatially coherent triangles keep
  // small and its accessors' caches hit (armadillo_midsub4x: 4.2 -> 2.4 s, armadillo 1.39 -> 1.19 s).
  // The closest-triangle grid then holds positions in this order: `order` maps them back.
  std::vector<openvdb::Vec3s> points;
  std::vector<int> order;
  std::vector<openvdb::Vec3I> tris;
  if (!ownBand)
  {
    // Where the triangles are much smaller than the voxels, the field comes from a vertex-
    // clustered proxy with cells of one voxel (clusteredProxy): OpenVDB's voxelization costs
    // per triangle, the proxy moves the surface by a fraction of a voxel along its curvature
    // (the extraction's own error is of that order), and every envelope is verified against the
    // input itself. Only when it drops at least a tenth of the triangles (coarser inputs keep
    // the exact field and their envelopes), and not with amplification: its projection onto the
    // exact amplified offset (projectOntoAmplifiedOffset) then disagrees with the extracted
    // surface (dragon_vrip with cells of 0.7-1.5 voxels: 32 crossing pairs at every adaptivity,
    // the envelope falls to the next grid, 110 s instead of 10 s). Measured: armadillo_midsub4x
    // (346k triangles, 105k in the proxy of the 0.01 grid) 4.7 -> 2.4 s for its whole run.
    std::vector<Triangle> proxy;
    std::vector<int> source; // proxy triangle -> unitMesh triangle
    const std::vector<Triangle>* fieldTriangles = &unitMesh.Triangles;
    if (clusteredField && !keepField && !amplification)
    {
      clusteredProxy(unitMesh, voxelSize, voxelSize, points, proxy, source);
      if (10 * proxy.size() <= 9 * unitMesh.Triangles.size())
        fieldTriangles = &proxy;
      else
        source.clear();
    }
    if (fieldTriangles == &unitMesh.Triangles)
    {
      points.resize(unitMesh.Points.size());
      for (std::size_t i = 0; i < points.size(); ++i)
      {
        const Vec3 p = unitMesh.Points[i] / voxelSize;
        points[i] = openvdb::Vec3s(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
      }
    }
    out.FieldTriangles = fieldTriangles->size();
    order = mortonOrder(points, *fieldTriangles);
    tris.resize(order.size());
    for (std::size_t f = 0; f < tris.size(); ++f)
    {
      const Triangle& t = (*fieldTriangles)[order[f]];
      tris[f] = openvdb::Vec3I(t[0], t[1], t[2]);
      if (!source.empty())
        order[f] = source[order[f]];
    }
  }
  // OpenVDB's field on the grid of voxel h (voxelSize or a multiple of it), its band out to the
  // isovalue plus a voxel
  const auto vdbField = [&](double h, float interior, int flags) {
    const CancellableMeshAdapter adapter(points, tris, progress, &expanding, voxelSize / h);
    const auto transform = openvdb::math::Transform::createLinearTransform(h);
    const float exterior = static_cast<float>(std::ceil(iso / h) + 1.0);
    return openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      sdfInterrupter, adapter, *transform, exterior, interior, flags, closestTriangle.get());
  };
  const bool localField = local && amplification && !unsignedField && !ownBand && local->Tree &&
    local->Dilation > 0;
  openvdb::BoolTree::Ptr localMask;
  try
  {
    if (localField)
    {
      // the grid twice as coarse, amplified on its own voxels
      const double coarseVoxel = 2.0 * voxelSize;
      openvdb::FloatGrid::Ptr coarse = vdbField(coarseVoxel, 1.0f, 0);
      if (coarse && !progressCancelled(progress))
      {
        openvdb::BoolTree coarseMask(coarse->tree(), false, openvdb::TopologyCopy());
        amplify(*coarse, *closestTriangle, order, *amplification, coarseVoxel,
          static_cast<float>(iso + 2.0 * coarseVoxel), coarseMask, progress);
        localMask.reset(new openvdb::BoolTree(false));
        grid = localExactField(*coarse, coarseMask, *closestTriangle, order, *amplification, *local, voxelSize, iso,
          static_cast<float>(exteriorBand * voxelSize), *localMask, out.ExactVoxels, out.AmplifiedVoxels, progress);
      }
      closestTriangle.reset();
      if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
        std::fprintf(stderr, "local exact field: %zu of %zu voxels exact, %.4f s\n", out.ExactVoxels,
          grid ? std::size_t(grid->activeVoxelCount()) : 0, seconds(t0));
    }
    else if (ownBand)
    {
      out.FieldTriangles = unitMesh.Triangles.size();
      grid = unsignedBandField(unitMesh, *windingTree, voxelSize, static_cast<int>(exteriorBand), progress);
    }
    else
    {
      grid = vdbField(voxelSize, interiorBand, unsignedField ? openvdb::tools::UNSIGNED_DISTANCE_FIELD : 0);
    }
  }
  catch (const std::exception& e)
  {
    out.Error = std::string("OpenVDB could not compute the distance field: ") + e.what();
    return out;
  }
  if (progressCancelled(progress) || !grid)
  {
    out.Cancelled = true;
    return out;
  }
  if (unsignedField)
  {
    // OpenVDB's volumeToMesh inverts the polygons of grids not classed as level sets, and the
    // unsigned distance is not; ours is read like one (inside = below the isovalue).
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
  }
  if (sign == SignMode::WindingNumber && windingTree)
  {
    // Only voxels at or beyond the isovalue can change the isosurface by their sign (below it,
    // both signs are inside {xi < iso}); those inside by winding number become negative.
    const auto tw = std::chrono::steady_clock::now();
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid->tree());
    std::atomic<std::size_t> evaluated{ 0 }, inside{ 0 };
    const float isoF = static_cast<float>(iso);
    // By blocks of 2x2x2 voxels: one evaluation at the block's centre decides all of the block's
    // voxels at or beyond the isovalue when it is clearly on one side (|w| < 1/4 or > 3/4). Such a
    // voxel is at least 2 voxels from the input and at most 0.87 from the centre, so the segment
    // between them stays 1.13 voxels away and w changes along it by about 0.12 per open border
    // nearby (w = angle / 2 pi beside a border); blocks nearer 1/2 are evaluated voxel by voxel.
    // (4-8x fewer evaluations, the cost of the winding-number sign.)
    tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange& r) {
      std::size_t e = 0, in = 0;
      using LeafT = openvdb::FloatTree::LeafNodeType;
      for (auto leaf = r.begin(); leaf; ++leaf)
      {
        if (progressCancelled(progress))
        {
          return;
        }
        const openvdb::Coord origin = leaf->origin();
        for (int bx = 0; bx < 8; bx += 2)
          for (int by = 0; by < 8; by += 2)
            for (int bz = 0; bz < 8; bz += 2)
            {
              openvdb::Index far[8];
              int nfar = 0;
              for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j)
                  for (int k = 0; k < 2; ++k)
                  {
                    const openvdb::Index o = LeafT::coordToOffset(origin.offsetBy(bx + i, by + j, bz + k));
                    if (leaf->isValueOn(o) && leaf->getValue(o) >= isoF)
                      far[nfar++] = o;
                  }
              if (nfar == 0)
                continue;
              int decided = -1; // 1 inside, 0 outside, -1 voxel by voxel
              if (nfar > 1)
              {
                const Vec3 c((origin.x() + bx + 0.5) * voxelSize, (origin.y() + by + 0.5) * voxelSize,
                  (origin.z() + bz + 0.5) * voxelSize);
                const double w = std::abs(windingTree->windingNumber(c));
                ++e;
                decided = w < 0.25 ? 0 : w > 0.75 ? 1 : -1;
              }
              for (int q = 0; q < nfar; ++q)
              {
                bool in1 = decided == 1;
                if (decided < 0)
                {
                  const openvdb::Coord ijk = LeafT::offsetToLocalCoord(far[q]) + origin;
                  const Vec3 x(ijk.x() * voxelSize, ijk.y() * voxelSize, ijk.z() * voxelSize);
                  ++e;
                  in1 = std::abs(windingTree->windingNumber(x)) > 0.5;
                }
                if (in1)
                {
                  leaf->setValueOnly(far[q], -leaf->getValue(far[q]));
                  ++in;
                }
              }
            }
      }
      evaluated += e;
      inside += in;
    });
    // The deep inside: beyond the band the grid holds only its background, read as outside.
    // (a) The voxels of band leaves beyond the band take the winding number's side, by blocks of
    // 2x2x2 voxels (w is smooth that far from the surface); inside ones become active -background.
    const float background = grid->background();
    using LeafT = openvdb::FloatTree::LeafNodeType;
    std::vector<char> filledLeaf(leaves.leafCount(), 0);
    auto leafIndex = [&](const openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange::Iterator& it) {
      return it.pos();
    };
    tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange& r) {
      std::size_t e = 0;
      for (auto leaf = r.begin(); leaf; ++leaf)
      {
        if (progressCancelled(progress))
        {
          return;
        }
        const openvdb::Coord origin = leaf->origin();
        for (int bx = 0; bx < 8; bx += 2)
          for (int by = 0; by < 8; by += 2)
            for (int bz = 0; bz < 8; bz += 2)
            {
              openvdb::Index offsets[8];
              int off = 0;
              for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j)
                  for (int k = 0; k < 2; ++k)
                  {
                    const openvdb::Index o = LeafT::coordToOffset(origin.offsetBy(bx + i, by + j, bz + k));
                    if (!leaf->isValueOn(o))
                      offsets[off++] = o;
                  }
              if (off == 0)
                continue;
              const Vec3 x((origin.x() + bx + 0.5) * voxelSize, (origin.y() + by + 0.5) * voxelSize,
                (origin.z() + bz + 0.5) * voxelSize);
              ++e;
              if (std::abs(windingTree->windingNumber(x)) > 0.5)
              {
                for (int q = 0; q < off; ++q)
                  leaf->setValueOn(offsets[q], -background);
                filledLeaf[leafIndex(leaf)] = 1;
              }
            }
      }
      evaluated += e;
    });
    // (b) Leaf-sized blocks of the input's box without band voxels: -background where inside.
    {
      Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      for (const Vec3& p : unitMesh.Points)
      {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      const int b0[3] = { static_cast<int>(std::floor(lo.x() / voxelSize)) & ~7,
        static_cast<int>(std::floor(lo.y() / voxelSize)) & ~7, static_cast<int>(std::floor(lo.z() / voxelSize)) & ~7 };
      const int b1[3] = { static_cast<int>(std::ceil(hi.x() / voxelSize)),
        static_cast<int>(std::ceil(hi.y() / voxelSize)), static_cast<int>(std::ceil(hi.z() / voxelSize)) };
      std::vector<openvdb::Coord> blocks;
      for (int x = b0[0]; x <= b1[0]; x += 8)
        for (int y = b0[1]; y <= b1[1]; y += 8)
          for (int z = b0[2]; z <= b1[2]; z += 8)
            if (!grid->tree().probeConstLeaf(openvdb::Coord(x, y, z)))
              blocks.emplace_back(x, y, z);
      std::vector<char> insideBlock(blocks.size(), 0);
      tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, blocks.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i)
          {
            const openvdb::Coord& c = blocks[i];
            const Vec3 x((c.x() + 3.5) * voxelSize, (c.y() + 3.5) * voxelSize, (c.z() + 3.5) * voxelSize);
            insideBlock[i] = std::abs(windingTree->windingNumber(x)) > 0.5;
          }
        });
      evaluated += blocks.size();
      // as leaves of active voxels, not as tiles: the extraction leaves cracks at tile borders and
      // between inactive voxels
      for (std::size_t i = 0; i < blocks.size(); ++i)
      {
        if (insideBlock[i])
        {
          grid->tree().touchLeaf(blocks[i])->fill(-background, true);
        }
      }
      // a leaf with inside values next to a block without a leaf: that one gets an outside leaf, so
      // that the crossing lies between two leaves (the extraction leaves cracks at a missing
      // neighbour)
      std::vector<openvdb::Coord> filled;
      for (std::size_t i = 0; i < blocks.size(); ++i)
        if (insideBlock[i])
          filled.push_back(blocks[i]);
      for (std::size_t i = 0; i < filledLeaf.size(); ++i)
        if (filledLeaf[i])
          filled.push_back(leaves.leaf(i).origin());
      for (const openvdb::Coord& origin : filled)
        for (int dx = -8; dx <= 8; dx += 8)
          for (int dy = -8; dy <= 8; dy += 8)
            for (int dz = -8; dz <= 8; dz += 8)
            {
              const openvdb::Coord n = origin.offsetBy(dx, dy, dz);
              if (!grid->tree().probeConstLeaf(n))
                grid->tree().touchLeaf(n)->fill(background, true);
            }
    }
    out.WindingEvaluations = evaluated.load();
    out.InsideVoxels = inside.load();
    out.WindingSeconds = seconds(tw);
    if (progressCancelled(progress))
    {
      out.Cancelled = true;
      return out;
    }
  }
  out.DistanceFieldSeconds = seconds(t0);
  out.ActiveVoxels = grid->activeVoxelCount();
  // Voxels where adaptivity is switched off: near active points (the amplified envelope lies
  // close to the input there, merged polygons would cut into the clearance) and, after a failed
  // judgement, around the triangles the judge points at.
  openvdb::BoolTree::Ptr noAdapt(new openvdb::BoolTree(false));
  if (localMask)
  {
    noAdapt = localMask; // amplified by localExactField
    openvdb::tools::dilateActiveValues(*noAdapt, 1);
  }
  else if (amplification)
  {
    // xi^ = phi xi (eq. 2–3) wherever the isosurface xi^ = iso can lie or be interpolated from:
    // phi >= 1, so only where xi <= iso (plus a voxel for the interpolation).
    const auto ta = std::chrono::steady_clock::now();
    noAdapt.reset(new openvdb::BoolTree(grid->tree(), false, openvdb::TopologyCopy()));
    out.AmplifiedVoxels = amplify(*grid, *closestTriangle, order, *amplification, voxelSize,
      static_cast<float>(iso + 2.0 * voxelSize), *noAdapt, progress);
    openvdb::tools::dilateActiveValues(*noAdapt, 1);
    closestTriangle.reset();
    out.AmplificationSeconds = seconds(ta);
    out.DistanceFieldSeconds += out.AmplificationSeconds;
  }
  if (progressCancelled(progress))
  {
    out.Cancelled = true;
    return out;
  }

  progressUpdate(progress, 0.6); // the field is done, the surface part begins
  // the extractions and the display field only: the judge's time is its caller's to count
  double extractionSeconds = 0.0;
  for (std::size_t k = 0; k < adaptivities.size(); ++k)
  {
    const double adaptivity = adaptivities[k];
    const int rounds = (judge && adaptivity > 0.0) ? 1 + std::max(0, maxRepairs) : 1;
    for (int round = 0; round < rounds; ++round)
    {
      TriangleMesh surface;
      const auto te = std::chrono::steady_clock::now();
      try
      {
        bool stopped = false;
        // OpenVDB's mesher reads the mask by leaf (MergeVoxelRegions: probeConstLeaf at each
        // leaf's origin) and merges freely under an active tile, and the dilation prunes whole
        // leaves of the mask into tiles: voxelized, a mask that is on everywhere near the active
        // points keeps their triangles uniform
        if (adaptivity > 0.0 && !noAdapt->empty())
          noAdapt->voxelizeActiveTiles();
        surface = extract(grid, iso, adaptivity, noAdapt->empty() ? nullptr : noAdapt, progress, stopped);
        extractionSeconds += seconds(te);
        if (std::getenv("SDFCAGE_DEBUG_ENVELOPE"))
          std::fprintf(stderr, "extraction (adaptivity %g, round %d): %zu triangles, %.4f s\n", adaptivity, round,
            surface.Triangles.size(), seconds(te));
        if (stopped)
        {
          out.Cancelled = true;
          return out;
        }
      }
      catch (const std::exception& e)
      {
        out.Error = std::string("OpenVDB could not extract the isosurface: ") + e.what();
        return out;
      }
      if (progressCancelled(progress))
      {
        out.Cancelled = true;
        return out;
      }
      if (!judge)
      {
        out.Surfaces.push_back(std::move(surface));
        break;
      }
      std::vector<Vec3> repairNear;
      const bool accepted = (*judge)(surface, adaptivity, repairNear);
      if (progressCancelled(progress))
      {
        out.Cancelled = true;
        return out;
      }
      if (accepted)
      {
        out.Surfaces.push_back(std::move(surface));
        out.AcceptedAdaptivity = adaptivity;
        out.Repairs = round;
        break;
      }
      if (repairNear.empty() || adaptivity <= 0.0)
      {
        break;
      }
      // Nothing newly marked: the next extraction would be this one again, and fail alike (the
      // defect lies where the triangles are uniform already: the amplified offset itself within
      // the clearance, not merged polygons). dragon_quartet with its repair rounds on grids where
      // the amplification fails: four identical extractions and verifications per adaptivity.
      if (markAround(repairNear, voxelSize, 2, *noAdapt) == 0)
      {
        break;
      }
    }
    if (!out.Surfaces.empty() && judge)
    {
      break;
    }
  }
  progressUpdate(progress, 0.9);

  const auto tf = std::chrono::steady_clock::now();
  if (keepField &&
    !computeDisplayFields(
      unitMesh, iso, voxelSize, amplification, out.Field, amplification ? &out.ModifiedField : nullptr, out.Error))
  {
    return out;
  }
  out.IsosurfaceSeconds = extractionSeconds + seconds(tf);
  progressUpdate(progress, 1.0);
  return out;
}

} // namespace sdfcage
