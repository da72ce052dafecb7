// SDFCage — Testing: the optimization keeps the cage tight on real meshes (issue 15, part 3).
//
//   SDFCageTightDataTests --mesh=FILE [gtest flags]
//
// Tight.MIPS: the 500-vertex cage optimized at the defaults of --optimize mips has no angle below
// 15 degrees, a one-sided Hausdorff distance cage -> input (certified by the quality judge) at
// most 1.5 times the plain cage's, the same vertex count, and the exact CGAL checker finds it a
// closed 2-manifold of the same genus, without self-intersections, strictly enclosing the input
// at the clearance. Tight.Spacing: --optimize spacing --spacing 0.05 puts 90% of the cage's area
// within h +- 20% of the input, with the same guarantees. A missing mesh reports SKIPPED.
#include "../Core/CoreTestPrinters.h"
#include "ExactCheck.h"
#include "MeshIO.h"
#include "DataTestSupport.h"
#include "Mesh/Normalization.h"
#include "Mesh/Validation.h"
#include "Optimization/Optimization.h"
#include "Pipeline/CageGenerator.h"
#include "Quality/CageQuality.h"
#include "SpacingBand.h"
#include "Spatial/TriangleTree.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

using namespace sdfcage;

namespace
{

datatest::Arguments gArgs;

struct Prepared
{
  TriangleMesh Input; ///< input units
  CageResult Cage;
};

/// Reads the mesh and builds its 500-vertex cage; false (with a failure) when it cannot.
bool prepare(Prepared& p)
{
  PolygonMesh polygons;
  std::string error;
  EXPECT_TRUE(exact::readPolygonMesh(gArgs.Mesh, polygons, error)) << error;
  EXPECT_TRUE(prepareMesh(polygons, p.Input).usable()) << gArgs.Mesh << " is not a closed mesh";
  CageOptions o;
  o.TargetNumberOfVertices = 500;
  p.Cage = generateCage(PolygonMesh::fromTriangles(p.Input), o);
  EXPECT_EQ(p.Cage.State, Status::Ok) << p.Cage.Message;
  return p.Cage.State == Status::Ok && !p.Input.Triangles.empty();
}

void expectGuarantees(const Prepared& p, const OptimizeResult& r, const char* what)
{
  ASSERT_EQ(r.State, Status::Ok) << what << ": " << r.Message;
  EXPECT_FALSE(r.Reverted) << what << ": " << r.Message;
  EXPECT_EQ(r.Cage.Points.size(), p.Cage.Cage.Points.size()) << what;
  EXPECT_EQ(r.Cage.Triangles.size(), p.Cage.Cage.Triangles.size()) << what;
  const double delta = p.Cage.Normalize.lengthToInput(CageOptions().Envelope.clearance());
  const exact::ExactReport e = exact::exactCheck(p.Input, r.Cage, 4 * delta);
  const exact::ExactReport e0 = exact::exactCheck(p.Input, p.Cage.Cage, 4 * delta);
  EXPECT_TRUE(e.Closed2Manifold) << what;
  EXPECT_EQ(e.SelfIntersections, 0) << what;
  EXPECT_EQ(e.InputIntersections, 0) << what;
  EXPECT_EQ(e.InputVerticesOutside, 0) << what;
  EXPECT_TRUE(e.Encloses) << what;
  EXPECT_EQ(e.CageGenus, e0.CageGenus) << what;
  EXPECT_EQ(e.CageComponents, e0.CageComponents) << what;
  EXPECT_GE(e.MinimumClearance, delta * (1 - 1e-9)) << what;
}

} // namespace

TEST(Tight, MIPS)
{
  SDFCAGE_SKIP_WITHOUT_MESH(gArgs.Mesh, gArgs.DataDir);
  Prepared p;
  if (!prepare(p))
    return;
  OptimizeOptions o; // the defaults of --optimize mips
  o.Clearance = CageOptions().Envelope.clearance();
  const OptimizeResult r = optimizeCageInInputUnits(p.Cage.Cage, p.Input, o);
  expectGuarantees(p, r, "mips");
  const CageQualityResult q0 = evaluateCage(p.Input, p.Cage.Cage);
  const CageQualityResult q1 = evaluateCage(p.Input, r.Cage);
  const double ratio = q1.HausdorffCageToInputBound / q0.HausdorffCageToInputBound;
  std::cout << "[ tight    ] " << gArgs.Mesh << ": min angle " << r.MinimumAngleBefore << " -> " << r.MinimumAngleAfter
            << " deg, angles < 15: " << 100 * r.SmallAnglesBefore << "% -> " << 100 * r.SmallAnglesAfter
            << "%, Hausdorff cage->input / diagonal " << q0.HausdorffCageToInputBound / q0.Diagonal << " -> "
            << q1.HausdorffCageToInputBound / q1.Diagonal << " (x" << ratio << "), " << r.Sweeps << " sweeps, "
            << r.Collapses << " collapse+split pairs, " << r.Seconds << " s\n";
  EXPECT_GE(r.MinimumAngleAfter, 15.0);
  EXPECT_LE(ratio, 1.5);
}

TEST(Tight, Spacing)
{
  SDFCAGE_SKIP_WITHOUT_MESH(gArgs.Mesh, gArgs.DataDir);
  Prepared p;
  if (!prepare(p))
    return;
  const Normalization& n = p.Cage.Normalize;
  const TriangleTree tree(n.toUnit(p.Input));
  for (const double h : { 0.05, 0.03 })
  {
    OptimizeOptions o;
    o.Energy = CageEnergy::Spacing;
    o.TargetSpacing = h;
    o.Clearance = CageOptions().Envelope.clearance();
    const OptimizeResult r = optimizeCageInInputUnits(p.Cage.Cage, p.Input, o);
    expectGuarantees(p, r, "spacing");
    // the area fraction within h +- 20% (unit-sphere units)
    const double fraction = bandFraction(n.toUnit(r.Cage), tree, 0.8 * h, 1.2 * h);
    std::cout << "[ spacing  ] " << gArgs.Mesh << ": " << 100 * fraction << "% of the area within h +- 20% (h = " << h
              << "), " << r.Sweeps << " sweeps, " << r.Seconds << " s\n";
    EXPECT_GE(fraction, 0.9) << "h = " << h;
    EXPECT_NEAR(r.SpacingBandAfter, fraction, 0.03) << "the reported area within the band, h = " << h;
  }
}

int main(int argc, char** argv)
{
  if (!datatest::parseArguments(argc, argv, "SDFCageTightDataTests", {}, {}, gArgs))
    return 2;
  return RUN_ALL_TESTS();
}
