// SDFCage — fuzz harness: Core's validation and whole pipeline (Pipeline/CageGenerator.h) on tiny
// meshes made from the bytes: up to 12 points on a coarse lattice (so that coincident points,
// degenerate, duplicated and overlapping cells are common) and up to 16 cells of 3 to 6 indices
// (some out of range). A coarse grid (isovalue 0.1, voxel 0.05) keeps a run in milliseconds.
// Any outcome is fine except a crash, a hang, or a result that says verified without a closed
// cage of points at finite coordinates.
#include "Mesh/Mesh.h"
#include "Pipeline/CageGenerator.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  std::size_t at = 0;
  auto next = [&]() -> int { return at < size ? data[at++] : 0; };
  sdfcage::PolygonMesh mesh;
  const int points = 3 + next() % 10;
  for (int i = 0; i < points; ++i)
  {
    const int a = next(), b = next(), c = next();
    mesh.Points.emplace_back((a % 9) * 0.125, (b % 9) * 0.125, (c % 9) * 0.125);
  }
  const int cells = 1 + next() % 16;
  for (int c = 0; c < cells && at < size; ++c)
  {
    const int n = 3 + next() % 4;
    for (int k = 0; k < n; ++k)
    {
      const int v = next();
      mesh.Connectivity.push_back(v == 255 ? -1 : v % (points + 1)); // -1 and `points`: out of range
    }
    mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
  }
  sdfcage::CageOptions options;
  options.NumberOfThreads = 1;
  options.TargetNumberOfVertices = 8 + (next() % 3) * 8;
  options.Envelope.IsoValue = 0.1;
  options.Envelope.VoxelSize = 0.05;
  options.Envelope.MaximumRefinements = 0;
  options.Envelope.UseActivePoints = (next() & 1) != 0;
  options.MaximumEnvelopeWidenings = next() % 2;
  const sdfcage::CageResult r = sdfcage::generateCage(mesh, options);
  if (r.EnclosureVerified)
  {
    if (r.Cage.Triangles.empty())
    {
      std::abort();
    }
    for (const sdfcage::Vec3& p : r.Cage.Points)
    {
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      {
        std::abort();
      }
    }
  }
  return 0;
}
