// SDFCage — Testing: generateCage on one real mesh, judged by the CGAL checker.
//
//   SDFCageDataTests --mesh=FILE [--any] [--inward] [--vertices=N] [gtest flags]
//   SDFCageDataTests --data-dir=DIR        (no mesh: reports SKIPPED, naming the folder)
//
// --expect=cage: the mesh is closed; the run must end Ok with a verified envelope, and the exact
// check must find the envelope and the cage closed 2-manifolds without self-intersections that
// strictly enclose the input at the promised clearance; the cage must have the requested vertex
// count or a stop reason. --any: the mesh need not be a clean closed 2-manifold ("any mesh
// in": open, soup, quads, self-intersecting): the same checks, its orientation not asserted.
// --inward: the mesh faces inward and validation must flip it. --vertices=N: the cage's vertex count (default: CageOptions' 500).
#include "../Core/CoreTestPrinters.h"
#include "Pipeline/CageGenerator.h"
#include "ExactCheck.h"
#include "MeshIO.h"
#include "DataTestSupport.h"
#include "Optimization/Optimization.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <fstream>
#include <iostream>
#include <string>

using namespace sdfcage;

namespace
{

datatest::Arguments gArgs;
std::string gMesh;
bool gAny = false;
bool gInward = false;
int gVertices = -1; // < 0: the default of CageOptions

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
  SDFCAGE_SKIP_WITHOUT_MESH(gMesh, gArgs.DataDir);
  const std::string name = baseName(gMesh);

  auto t0 = std::chrono::steady_clock::now();
  PolygonMesh polygons;
  std::string error;
  ASSERT_TRUE(exact::readPolygonMesh(gMesh, polygons, error)) << error;
  const double readSeconds = since(t0);
  std::cout << "[ data     ] " << name << ": " << polygons.Points.size() << " points, " << polygons.numberOfCells()
            << " cells, read in " << readSeconds << " s\n";
  ASSERT_GT(polygons.numberOfCells(), 0u);

  CageOptions options;
  if (gVertices >= 0)
  {
    options.TargetNumberOfVertices = gVertices;
  }
  t0 = std::chrono::steady_clock::now();
  const CageResult result = generateCage(polygons, options);
  const double cageSeconds = since(t0);
  std::cout << "[ data     ] " << name << ": " << statusName(result.State) << " in " << cageSeconds << " s (validation "
            << result.ValidationSeconds << ", SDF " << result.DistanceFieldSeconds << ", isosurface "
            << result.IsosurfaceSeconds << ", verification " << result.VerificationSeconds << ")\n";
  RecordProperty("GenerateCageSeconds", std::to_string(cageSeconds));

  const MeshDefects& d = result.Defects;
  std::cout << "[ data     ] " << name << ": repairs: " << d.MergedPoints << " points merged, "
            << d.TriangulatedPolygons << " polygons triangulated, " << d.DroppedDegenerateTriangles
            << " degenerate and " << d.DroppedDuplicateTriangles << " duplicated triangles dropped; " << d.BoundaryEdges
            << " boundary edges, " << d.NonManifoldEdges << " non-manifold edges, " << d.NonManifoldVertices
            << " non-manifold vertices, " << d.InconsistentEdges << " inconsistent edges, " << d.Components
            << " components; inside rule " << signModeName(result.SignUsed) << " (" << result.SignReason << ")\n";

  ASSERT_EQ(result.State, Status::Ok) << statusName(result.State) << ": " << result.Message;
  EXPECT_TRUE(result.EnclosureVerified);
  if (!gAny)
  {
    EXPECT_TRUE(result.InputClosed) << "this mesh is listed as closed";
    EXPECT_EQ(result.SignUsed, SignMode::FloodFill);
    EXPECT_EQ(result.Defects.FlippedOrientation, gInward)
      << (gInward ? "this mesh faces inward and must be flipped" : "this mesh faces outward");
  }
  ASSERT_FALSE(result.Cage.empty());

  // The checker reads the input itself (fan-triangulated file contents, not Core's validated
  // copy); orientation does not matter to it.
  TriangleMesh input;
  EXPECT_TRUE(exact::fanTriangulate(polygons, input));
  const Normalization& n = result.Normalize;
  // the clearance kept: the automatic one, or lowered by the topology repair
  const double promised = result.ClearanceUsedRelative > 0 ? result.ClearanceUsedRelative : options.Envelope.clearance();
  const double delta = n.lengthToInput(promised);
  std::cout << "[ data     ] " << name << ": envelope " << result.Envelope.Triangles.size() << " triangles (voxel "
            << result.VoxelSizeUsed << ", removed pockets " << result.RemovedPockets << "); cage "
            << result.VerticesReached << " vertices, " << result.Cage.Triangles.size() << " triangles (simplification "
            << result.SimplificationSeconds << " s, cage verification " << result.CageVerificationSeconds << " s)\n";
  RecordProperty("EnvelopeTriangles", std::to_string(result.Envelope.Triangles.size()));
  RecordProperty("CageVertices", std::to_string(result.VerticesReached));

  // Both the dense envelope (near distance c: 2c measures it exactly) and the cage (possibly
  // farther: a quarter of the unit radius) must enclose the input at the promised clearance.
  struct Checked
  {
    const char* What;
    const TriangleMesh* Mesh;
    double Limit;
  };
  // (the isovalue used: inputs without a defined topology may have had their envelope widened)
  const Checked checks[2] = { { "envelope", &result.Envelope, n.lengthToInput(2.0 * result.IsoValueUsed) },
    { "cage", &result.Cage, n.lengthToInput(0.25) } };
  exact::ExactReport reports[2];
  for (int k = 0; k < 2; ++k)
  {
    const exact::ExactReport& r = reports[k] = exact::exactCheck(input, *checks[k].Mesh, checks[k].Limit);
    const std::string what = name + " " + checks[k].What;
    std::cout << "[ data     ] " << what << ": exact " << exact::toJson(r) << "\n"
              << "[ data     ] " << what << ": clearance " << n.lengthToUnit(r.MinimumClearance)
              << " unit-sphere units (promised " << promised << ")\n"
              << "[ data     ] " << what << ": input genus " << result.Defects.Genus << ", components "
              << result.Defects.Components << "; " << checks[k].What << " genus " << r.CageGenus << ", components "
              << r.CageComponents
              << (r.CageGenus == result.Defects.Genus && r.CageComponents == result.Defects.Components
                     ? " (topology kept)\n"
                     : " (topology NOT kept)\n");
    RecordProperty(std::string(checks[k].What) + "ExactCheckSeconds", std::to_string(r.Seconds));
    RecordProperty(std::string(checks[k].What) + "ClearanceUnit", std::to_string(n.lengthToUnit(r.MinimumClearance)));
    EXPECT_TRUE(r.Closed2Manifold) << what << ": boundary edges " << r.BoundaryEdges << ", non-manifold edges "
                                   << r.NonManifoldEdges << ", vertices " << r.NonManifoldVertices;
    EXPECT_EQ(r.SelfIntersections, 0) << what;
    EXPECT_EQ(r.InputIntersections, 0) << what;
    EXPECT_EQ(r.InputVerticesOutside, 0) << what;
    EXPECT_TRUE(r.Encloses) << what;
    EXPECT_GE(r.MinimumClearance, delta * (1.0 - 1e-9)) << what;
    EXPECT_FALSE(r.ClearanceIsLowerBound) << what;
  }
  EXPECT_EQ(result.EnvelopeGenus, reports[0].CageGenus);
  EXPECT_EQ(result.EnvelopeComponents, reports[0].CageComponents);
  EXPECT_NEAR(result.MinimumClearance, reports[1].MinimumClearance, 1e-6 * reports[1].MinimumClearance);
  // The cage has the requested vertex count, or says why not.
  EXPECT_EQ(static_cast<std::size_t>(result.VerticesReached), result.Cage.Points.size());
  if (result.TargetReached)
  {
    EXPECT_EQ(result.Cage.Points.size(), static_cast<std::size_t>(options.TargetNumberOfVertices));
  }
  else
  {
    EXPECT_FALSE(result.StopReason.empty());
    std::cout << "[ data     ] " << name << ": target not reached: " << result.StopReason << "\n";
  }

  // The cage stays near the input: no vertex farther than 0.2 of the bounding-box diagonal from
  // it (the largest seen on these meshes is about 0.1, dragon_quartet at 200; unbounded outward
  // placements once reached 0.67). Measured independently, by brute force, as the distance to the
  // nearest input vertex (an upper bound of the distance to the surface).
  {
    Vec3 lo = input.Points[0], hi = input.Points[0];
    for (const Vec3& p : input.Points)
    {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const double diagonal = (hi - lo).norm();
    double farthest = 0.0;
    for (const Vec3& v : result.Cage.Points)
    {
      double nearest2 = std::numeric_limits<double>::infinity();
      for (const Vec3& p : input.Points)
        nearest2 = std::min(nearest2, (p - v).squaredNorm());
      farthest = std::max(farthest, std::sqrt(nearest2));
    }
    std::cout << "[ data     ] " << name << ": farthest cage vertex " << farthest / diagonal
              << " of the diagonal from the input's vertices\n";
    EXPECT_LE(farthest, 0.2 * diagonal) << name;
  }

  // The optimization (paper §3.3, MIPS, one round) of this cage keeps every guarantee and lowers
  // its energy; judged by the same referee.
  OptimizeOptions oo;
  oo.Clearance = promised;
  const OptimizeResult opt = optimizeCageInInputUnits(result.Cage, input, oo);
  ASSERT_EQ(opt.State, Status::Ok) << opt.Message;
  EXPECT_FALSE(opt.Reverted) << opt.Message;
  const exact::ExactReport r = exact::exactCheck(input, opt.Cage, n.lengthToInput(0.25));
  std::cout << "[ data     ] " << name << " optimized: MIPS " << opt.EnergyBefore << " -> " << opt.EnergyAfter
            << ", min angle " << opt.MinimumAngleBefore << " -> " << opt.MinimumAngleAfter << " deg, " << opt.Moves
            << " moves, " << opt.Flips << " flips, relocation + flips " << opt.RelocationSeconds + opt.FlipSeconds
            << " s; exact " << exact::toJson(r) << "\n";
  RecordProperty("OptimizationSeconds", std::to_string(opt.Seconds));
  EXPECT_LT(opt.EnergyAfter, opt.EnergyBefore);
  EXPECT_EQ(opt.Cage.Points.size(), result.Cage.Points.size());
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_EQ(r.InputIntersections, 0);
  EXPECT_EQ(r.InputVerticesOutside, 0);
  EXPECT_TRUE(r.Encloses);
  EXPECT_EQ(r.CageGenus, reports[1].CageGenus);
  EXPECT_GE(r.MinimumClearance, delta * (1.0 - 1e-9));
}

int main(int argc, char** argv)
{
  if (!datatest::parseArguments(argc, argv, "SDFCageDataTests", { "any", "inward" }, { "vertices" }, gArgs))
    return 2;
  gMesh = gArgs.Mesh;
  gAny = gArgs.has("any");
  gInward = gArgs.has("inward");
  gVertices = std::stoi(gArgs.value("vertices", "-1"));
  return RUN_ALL_TESTS();
}
