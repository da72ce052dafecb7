// SDFCage — Core: the memory budget of a run (no VTK).
//
// The largest allocations of the pipeline are the envelope's: OpenVDB's narrow-band distance
// grid (with its closest-triangle index grid), the isosurface and its verification structures,
// all growing as the input's area over the voxel size squared (halving the voxel size takes four
// times the memory). buildEnvelope() estimates them before each grid it builds and refuses, with a
// message naming the need, a grid over EnvelopeOptions::MemoryLimit, instead of letting the
// kernel's out-of-memory killer end the process.
#pragma once

#include "Mesh/Mesh.h"

#include <cstddef>
#include <string>

namespace sdfcage
{

/// The machine's physical memory in bytes (0 when unknown).
std::size_t physicalMemoryBytes();

/// The default budget: three quarters of the physical memory (8 GiB when it is unknown).
std::size_t defaultMemoryLimit();

/// Estimated peak bytes of one envelope of `unitInput` (scaled into the unit sphere) at voxel
/// size `voxel` and isovalue `iso`: the band voxels (area / voxel^2 times the band's layers:
/// ceil(iso / voxel) + 1 outside, 1 inside, as many inside as outside for the winding-number
/// and unsigned rules) at a measured cost per voxel, plus a measured cost per input triangle,
/// plus the dense display images when `denseField`. Calibrated by peak resident size on the
/// shared meshes (see Testing/Core/TestMemoryBudget.cxx); an estimate, on the high side.
std::size_t estimateEnvelopeBytes(
  const TriangleMesh& unitInput, double voxel, double iso, bool signedByFloodFill, bool denseField);

/// "1.5 GiB", "300 MiB".
std::string formatBytes(std::size_t bytes);

} // namespace sdfcage
