// SDFCage — Testing: generateCage on one real mesh, judged by the CGAL checker.
//
//   SDFCageDataTests --mesh=FILE --expect=cage|invalid [--inward] [gtest flags]
//   SDFCageDataTests --data-dir=DIR        (no mesh: reports SKIPPED, naming the folder)
//
// --expect=cage: the mesh is closed; the run must end Ok with a verified envelope, and the exact
// check must find a closed 2-manifold cage without self-intersections that strictly encloses the
// input at the promised clearance. --expect=invalid: the mesh is not watertight; the run must end
// with InvalidInput and a message naming the boundary edges. --inward: the mesh faces inward and
// validation must flip it.
#include "CageGenerator.h"
#include "ExactCheck.h"
#include "MeshIO.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <string>

using namespace sdfcage;

namespace
{

std::string gMesh;
std::string gDataDir;
std::string gExpect = "cage";
bool gInward = false;

double since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string baseName(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

} // namespace

TEST(DataMesh, GenerateCage)
{
  if (gMesh.empty())
  {
    GTEST_SKIP() << "no test meshes: the data folder '" << gDataDir
                 << "' is absent or empty (set SDFCAGE_DATA_DIR)";
  }
  if (!std::ifstream(gMesh).good())
  {
    GTEST_SKIP() << "mesh '" << gMesh << "' is absent (re-run CMake after changing the data folder)";
  }
  const std::string name = baseName(gMesh);

  auto t0 = std::chrono::steady_clock::now();
  PolygonMesh polygons;
  std::string error;
  ASSERT_TRUE(exact::readPolygonMesh(gMesh, polygons, error)) << error;
  const double readSeconds = since(t0);
  std::cout << "[ data     ] " << name << ": " << polygons.Points.size() << " points, "
            << polygons.numberOfCells() << " cells, read in " << readSeconds << " s\n";
  ASSERT_GT(polygons.numberOfCells(), 0u);

  CageOptions options;
  t0 = std::chrono::steady_clock::now();
  const CageResult result = generateCage(polygons, options);
  const double cageSeconds = since(t0);
  std::cout << "[ data     ] " << name << ": " << statusName(result.State) << " in " << cageSeconds
            << " s (validation " << result.ValidationSeconds << ", SDF " << result.DistanceFieldSeconds
            << ", isosurface " << result.IsosurfaceSeconds << ", verification "
            << result.VerificationSeconds << ")\n";
  RecordProperty("GenerateCageSeconds", std::to_string(cageSeconds));

  if (gExpect == "invalid")
  {
    EXPECT_EQ(result.State, Status::InvalidInput) << statusName(result.State) << ": " << result.Message;
    EXPECT_GT(result.Defects.BoundaryEdges, 0);
    EXPECT_NE(result.Message.find("boundary edges"), std::string::npos) << result.Message;
    EXPECT_TRUE(result.Cage.empty());
    std::cout << "[ data     ] " << name << ": " << result.Message << "\n";
    return;
  }

  ASSERT_EQ(result.State, Status::Ok) << statusName(result.State) << ": " << result.Message;
  EXPECT_TRUE(result.EnclosureVerified);
  EXPECT_EQ(result.Defects.FlippedOrientation, gInward)
    << (gInward ? "this mesh faces inward and must be flipped" : "this mesh faces outward");
  ASSERT_FALSE(result.Cage.empty());

  // The checker reads the input itself (fan-triangulated file contents, not Core's validated
  // copy); orientation does not matter to it.
  TriangleMesh input;
  EXPECT_TRUE(exact::fanTriangulate(polygons, input));
  const Normalization& n = result.Normalize;
  const double delta = n.lengthToInput(options.Envelope.clearance());
  const double limit = n.lengthToInput(2.0 * options.Envelope.IsoValue);
  const exact::ExactReport r = exact::exactCheck(input, result.Cage, limit);
  std::cout << "[ data     ] " << name << ": cage " << result.Cage.Triangles.size()
            << " triangles, voxel " << result.VoxelSizeUsed << ", removed pockets "
            << result.RemovedPockets << "\n"
            << "[ data     ] " << name << ": exact " << exact::toJson(r) << "\n"
            << "[ data     ] " << name << ": clearance " << n.lengthToUnit(r.MinimumClearance)
            << " unit-sphere units (promised " << options.Envelope.clearance() << ", Core measured "
            << result.MinimumClearanceRelative << ")\n"
            << "[ data     ] " << name << ": input genus " << result.Defects.Genus << ", components "
            << result.Defects.Components << "; cage genus " << r.CageGenus << ", components "
            << r.CageComponents << (r.CageGenus == result.Defects.Genus &&
                                       r.CageComponents == result.Defects.Components
                                     ? " (topology kept)\n"
                                     : " (topology NOT kept)\n");
  RecordProperty("ExactCheckSeconds", std::to_string(r.Seconds));
  RecordProperty("ClearanceUnit", std::to_string(n.lengthToUnit(r.MinimumClearance)));
  RecordProperty("CageTriangles", std::to_string(result.Cage.Triangles.size()));

  EXPECT_TRUE(r.Closed2Manifold) << "boundary edges " << r.BoundaryEdges << ", non-manifold edges "
                                 << r.NonManifoldEdges << ", vertices " << r.NonManifoldVertices;
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_EQ(r.InputIntersections, 0);
  EXPECT_EQ(r.InputVerticesOutside, 0);
  EXPECT_TRUE(r.Encloses);
  EXPECT_GE(r.MinimumClearance, delta * (1.0 - 1e-9));
  EXPECT_NEAR(result.MinimumClearance, r.MinimumClearance, 1e-6 * r.MinimumClearance);
  EXPECT_EQ(result.EnvelopeGenus, r.CageGenus);
  EXPECT_EQ(result.EnvelopeComponents, r.CageComponents);
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg.rfind("--mesh=", 0) == 0)
    {
      gMesh = arg.substr(7);
    }
    else if (arg.rfind("--data-dir=", 0) == 0)
    {
      gDataDir = arg.substr(11);
    }
    else if (arg.rfind("--expect=", 0) == 0)
    {
      gExpect = arg.substr(9);
    }
    else if (arg == "--inward")
    {
      gInward = true;
    }
    else
    {
      std::cerr << "SDFCageDataTests: unknown argument '" << arg << "'\n";
      return 2;
    }
  }
  if (gExpect != "cage" && gExpect != "invalid")
  {
    std::cerr << "SDFCageDataTests: --expect must be cage or invalid\n";
    return 2;
  }
  return RUN_ALL_TESTS();
}
