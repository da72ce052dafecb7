// SDFCage — Testing: the memory budget (Common/MemoryBudget.h): the estimate grows as the area
// over the voxel size squared, and a budget below the need stops the run before the grid is
// built, with a message naming the need.
#include "CoreTestPrinters.h"
#include "Common/MemoryBudget.h"
#include "Envelope/Envelope.h"
#include "Mesh/Mesh.h"
#include "Mesh/Shapes.h"
#include "Pipeline/CageGenerator.h"

#include <gtest/gtest.h>

#include <string>

using namespace sdfcage;

TEST(MemoryBudget, EstimateGrowsAsAreaOverVoxelSquared)
{
  const TriangleMesh sphere = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
  const std::size_t coarse = estimateEnvelopeBytes(sphere, 0.02, 0.04, true, false);
  const std::size_t fine = estimateEnvelopeBytes(sphere, 0.01, 0.02, true, false);
  EXPECT_GT(coarse, 0u);
  // same band layers (iso / voxel fixed), a quarter of the voxel area each: four times the voxels
  const double ratio = static_cast<double>(fine) / static_cast<double>(coarse);
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 4.01);
  // the winding-number rule has as wide a band inside as outside: more voxels
  EXPECT_GT(estimateEnvelopeBytes(sphere, 0.01, 0.02, false, false), fine);
  // the dense display images come on top
  EXPECT_GT(estimateEnvelopeBytes(sphere, 0.01, 0.02, true, true), fine);
  EXPECT_GT(defaultMemoryLimit(), std::size_t(64) << 20);
  EXPECT_EQ(formatBytes(std::size_t(3) << 29), "1.5 GiB");
}

TEST(MemoryBudget, OverTheLimitStopsBeforeTheGridWithTheNeed)
{
  const TriangleMesh sphere = makeSphere(Vec3(0, 0, 0), 1.0, 32, 16);
  EnvelopeOptions options;
  options.IsoValue = 0.02;
  options.UseActivePoints = false;
  options.MemoryLimit = 1 << 20; // 1 MiB: far below any grid
  const EnvelopeResult r = buildEnvelope(sphere, options);
  EXPECT_EQ(r.State, Status::Failed);
  EXPECT_NE(r.Message.find("memory limit of 1 MiB"), std::string::npos) << r.Message;
  EXPECT_NE(r.Message.find("needs about"), std::string::npos) << r.Message;
  EXPECT_TRUE(r.Envelope.empty());

  // with room for it, the same envelope is built and verified
  options.MemoryLimit = estimateEnvelopeBytes(sphere, options.voxelSize(), options.IsoValue, true, false) + 1;
  const EnvelopeResult ok = buildEnvelope(sphere, options);
  EXPECT_EQ(ok.State, Status::Ok) << ok.Message;
  EXPECT_TRUE(ok.EnclosureVerified);
}
