// SDFCage — Testing: the procedural shapes, checked with Validation and the CGAL checker.
#include "ExactCheck.h"
#include "Mesh/Mesh.h"
#include "Mesh/Normalization.h"
#include "Mesh/Shapes.h"
#include "Mesh/Validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace sdfcage;

namespace
{

/// The triangles of component c as their own mesh (points are shared, unreferenced ones stay).
TriangleMesh component(const TriangleMesh& mesh, const std::vector<int>& comp, int c)
{
  TriangleMesh out;
  out.Points = mesh.Points;
  for (std::size_t t = 0; t < mesh.Triangles.size(); ++t)
  {
    if (comp[t] == c)
    {
      out.Triangles.push_back(mesh.Triangles[t]);
    }
  }
  removeUnreferencedPoints(out);
  return out;
}

/// Exact minimum distance between the two components of a two-component mesh.
double componentGap(const TriangleMesh& mesh)
{
  std::vector<int> comp;
  EXPECT_EQ(triangleComponents(mesh, comp), 2);
  const exact::ExactReport r = exact::exactCheck(component(mesh, comp, 0), component(mesh, comp, 1), 1.0);
  EXPECT_EQ(r.InputIntersections, 0);
  EXPECT_FALSE(r.ClearanceIsLowerBound);
  return r.MinimumClearance;
}

void expectCleanClosedSurface(const TriangleMesh& mesh, int components, int expectedGenus)
{
  const MeshDefects d = checkTriangleMesh(mesh);
  EXPECT_TRUE(d.usable()) << d.errorMessage();
  EXPECT_EQ(d.Components, components);
  EXPECT_EQ(genus(mesh), expectedGenus);
  const exact::ExactReport r = exact::exactCheck(TriangleMesh(), mesh, 1.0);
  EXPECT_TRUE(r.Closed2Manifold);
  EXPECT_EQ(r.SelfIntersections, 0);
  EXPECT_EQ(r.InconsistentEdges, 0);
  EXPECT_EQ(r.CageGenus, expectedGenus);
  EXPECT_EQ(r.CageComponents, components);
  EXPECT_GT(signedVolume(mesh), 0.0); // outward
}

} // namespace

TEST(Shapes, BuiltinShapeIsClosedTwoComponentsGenusOne)
{
  const TriangleMesh shape = makeBuiltinShape();
  expectCleanClosedSurface(shape, 2, 1);
  std::vector<int> comp;
  ASSERT_EQ(triangleComponents(shape, comp), 2);
  // Each component is outward on its own (no nesting).
  EXPECT_GT(signedVolume(component(shape, comp, 0)), 0.0);
  EXPECT_GT(signedVolume(component(shape, comp, 1)), 0.0);
}

TEST(Shapes, BuiltinShapeGapInUnitSphereUnits)
{
  const TriangleMesh shape = makeBuiltinShape();
  const Normalization n = Normalization::fit(shape);
  const double gap = componentGap(n.toUnit(shape));
  EXPECT_GT(gap, 0.005);
  EXPECT_LT(gap, 0.02);
  EXPECT_NEAR(gap, 0.012, 0.02 * 0.012) << "the documented default gap";
}

TEST(Shapes, BuiltinShapeHonoursGapAndResolution)
{
  for (const double requested : { 0.006, 0.015, 0.05 })
  {
    const TriangleMesh shape = makeBuiltinShape(requested);
    const double gap = componentGap(Normalization::fit(shape).toUnit(shape));
    EXPECT_NEAR(gap, requested, 0.02 * requested) << "requested " << requested;
  }
  const TriangleMesh coarse = makeBuiltinShape(0.012, 1);
  const TriangleMesh fine = makeBuiltinShape(0.012, 2);
  EXPECT_GT(fine.Triangles.size(), 2 * coarse.Triangles.size());
  expectCleanClosedSurface(fine, 2, 1);
  EXPECT_NEAR(componentGap(Normalization::fit(fine).toUnit(fine)), 0.012, 0.02 * 0.012);
}

TEST(Shapes, SphereTorusBox)
{
  const double pi = std::acos(-1.0);
  const TriangleMesh sphere = makeSphere(Vec3(1, 2, 3), 2.0, 64, 32);
  expectCleanClosedSurface(sphere, 1, 0);
  EXPECT_NEAR(signedVolume(sphere), 4.0 / 3.0 * pi * 8.0, 0.02 * 4.0 / 3.0 * pi * 8.0);

  const TriangleMesh torus = makeTorus(Vec3(-1, 0, 0), 1.5, 0.5, 64, 32);
  expectCleanClosedSurface(torus, 1, 1);
  EXPECT_NEAR(signedVolume(torus), 2 * pi * pi * 1.5 * 0.25, 0.02 * 2 * pi * pi * 1.5 * 0.25);

  const TriangleMesh box = makeBox(Vec3(-1, 0, 2), Vec3(1, 3, 2.5));
  expectCleanClosedSurface(box, 1, 0);
  EXPECT_NEAR(signedVolume(box), 2.0 * 3.0 * 0.5, 1e-12);
  const auto b = bounds(box);
  EXPECT_EQ(b[0], Vec3(-1, 0, 2));
  EXPECT_EQ(b[1], Vec3(1, 3, 2.5));

  TriangleMesh both = sphere;
  appendMesh(both, makeBox(Vec3(10, 0, 0), Vec3(11, 1, 1)));
  EXPECT_EQ(both.Points.size(), sphere.Points.size() + 8);
  expectCleanClosedSurface(both, 2, 0);
}
