// SDFCage — Testing: active points and the shape-aware envelope on real meshes (paper §3.1),
// judged by the CGAL checker. Skips (gtest SKIPPED) when the data folder is absent.
//
//   SDFCageActivePointDataTests --data-dir=DIR [gtest flags]
//
// hand_fist.off and octopus-low_surface.obj: their nearly touching parts (fingers on the palm,
// tentacles) are 0.06 and 0.05 apart in unit-sphere units at the closest (measured: the smallest
// Euclidean distance between surface points more than l = 0.15 apart along the surface), so with
// the default r = 0.025 they have no active point, and a plain offset at c = 0.01 already keeps
// their topology. The tests therefore use r = 0.08, which makes those parts active, and check
// that the amplified envelope still has the input's genus and components and encloses exactly.
#include "../Core/CoreTestPrinters.h"
#include "Envelope/ActivePoints.h"
#include "Envelope/Envelope.h"
#include "ExpectSound.h"
#include "MeshIO.h"
#include "Mesh/Normalization.h"
#include "Mesh/Validation.h"

#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <iostream>
#include <string>

using namespace sdfcage;

namespace
{

std::string gDataDir;

// A data mesh's test: SetUp loads the data folder's mesh named by the parameter, prepared and
// fitted to the unit sphere, with its parts and genus, or skips the test when it is absent.
class DataMeshTest : public ::testing::TestWithParam<std::string>
{
protected:
  void SetUp() override
  {
    const std::string path = gDataDir + "/" + GetParam();
    if (gDataDir.empty() || !std::ifstream(path).good())
    {
      GTEST_SKIP() << "mesh '" << path << "' is absent (data folder '" << gDataDir << "')";
    }
    PolygonMesh raw;
    std::string error;
    ASSERT_TRUE(exact::readPolygonMesh(path, raw, error)) << error;
    TriangleMesh mesh;
    const MeshDefects d = prepareMesh(raw, mesh, ValidationOptions());
    ASSERT_TRUE(d.usable()) << d.errorMessage();
    unit = Normalization::fit(mesh).toUnit(mesh);
    std::vector<int> comp;
    components = triangleComponents(unit, comp);
    inputGenus = genus(unit);
  }

  TriangleMesh unit;
  int components = 0;
  int inputGenus = 0;
};

// a test name from a mesh file name: its stem, other characters than letters and digits as '_'
std::string meshTestName(const ::testing::TestParamInfo<std::string>& info)
{
  std::string n = info.param.substr(0, info.param.find('.'));
  for (char& ch : n)
  {
    ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  }
  return n;
}

class ActivePointData : public DataMeshTest
{
};

} // namespace

TEST_P(ActivePointData, ShapeAwareEnvelopeKeepsTopology)
{
  // the defaults find nothing on these meshes (see above): reported, not asserted
  const ActivePoints defaults = computeActivePoints(unit, ActivePointOptions());
  std::cout << "[ active   ] " << GetParam() << " defaults (r 0.025): " << defaults.NumberOfActiveSamples
            << " active samples of " << defaults.NumberOfSamples << ", " << defaults.Seconds << " s\n";

  EnvelopeOptions options;
  options.ActivePoints.Radius = 0.08;
  const ActivePoints wide = computeActivePoints(unit, options.ActivePoints);
  std::cout << "[ active   ] " << GetParam() << " r 0.08: " << wide.NumberOfActiveSamples << " active samples, "
            << wide.NumberOfActiveInputPoints << " input points, " << wide.Seconds << " s\n";
  EXPECT_GT(wide.NumberOfActiveSamples, 0u) << "the nearly touching parts are active at r = 0.08";
  EXPECT_LT(wide.NumberOfActiveSamples, wide.NumberOfSamples / 2) << "but not the whole surface";

  const EnvelopeResult env = buildEnvelope(unit, options);
  ASSERT_EQ(env.State, Status::Ok) << env.Message;
  std::cout << "[ envelope ] " << env.Envelope.Triangles.size() << " triangles, genus " << env.Genus << ", components "
            << env.Components << ", amplified voxels " << env.AmplifiedVoxels << ", projected vertices "
            << env.ProjectedVertices << ", clearance >= " << env.MinimumClearance << "\n";
  EXPECT_GT(env.NumberOfActiveSamples, 0u);
  EXPECT_GT(env.AmplifiedVoxels, 0u);
  EXPECT_EQ(env.Genus, inputGenus);
  EXPECT_EQ(env.Components, components);
  EXPECT_TRUE(env.TopologyWarning.empty()) << env.TopologyWarning;

  exact::expectSoundCage(unit, env.Envelope, options.clearance(), inputGenus, components, GetParam());
}

INSTANTIATE_TEST_SUITE_P(Meshes, ActivePointData,
  ::testing::Values(std::string("hand_fist.off"), std::string("octopus-low_surface.obj")), meshTestName);

// The adaptive envelope's cut corners mended on real meshes (liftCutCorners in Envelope.cxx): at
// the defaults the first extraction's badly placed points are lifted, its midpoints traced out
// where their closest-point way is not the outside, midpoints inside the input (chords through a
// part or across a sharp edge) taken out through their closest input point, and lifted points
// that make the surface cross itself lifted less or put back; on most meshes that leaves nothing
// for verification to find; on octopus-low and hand_fist it finds a fold of the extraction's own
// triangles, mended in place (unfoldCrossings) and verified again. So each envelope is accepted
// without a second, partly uniform extraction (before session 50 each needed one: clearance
// defects at unmoved midpoints, crossings at lifted ones and the folds; anchor, decimated-knight
// and decimated-max until session 51: midpoints inside the input, traced or lifted further in).
// Judged again by the CGAL checker.
class FirstExtractionData : public DataMeshTest
{
};

TEST_P(FirstExtractionData, LiftedEnvelopePassesWithoutReExtraction)
{
  const EnvelopeOptions options;
  const EnvelopeResult env = buildEnvelope(unit, options);
  ASSERT_EQ(env.State, Status::Ok) << env.Message;
  std::cout << "[ lift     ] " << GetParam() << ": " << env.Envelope.Triangles.size() << " triangles, "
            << env.LiftedPoints << " points added, " << env.AdaptiveRepairs << " re-extractions\n";
  EXPECT_GT(env.LiftedPoints, 0u) << "nothing lifted: the test does not test the lifting";
  EXPECT_EQ(env.AdaptiveRepairs, 0) << "the lifted first extraction failed verification";
  EXPECT_EQ(env.Genus, inputGenus);
  EXPECT_EQ(env.Components, components);

  exact::expectSoundCage(unit, env.Envelope, options.clearance(), inputGenus, components, GetParam());
}

INSTANTIATE_TEST_SUITE_P(Meshes, FirstExtractionData,
  ::testing::Values(std::string("armadillo.obj"), std::string("bunny.off"), std::string("bunny_watertight.obj"),
    std::string("horse.ply"), std::string("octopus-low_surface.obj"), std::string("hand_fist.off"),
    std::string("anchor.off"), std::string("decimated-knight.off"), std::string("decimated-max.obj")),
  meshTestName);

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a.rfind("--data-dir=", 0) == 0)
    {
      gDataDir = a.substr(11);
    }
  }
  return RUN_ALL_TESTS();
}
