// SDFCage — Testing: strictly nested cages (paper §4, Fig. 9) from the built-in shape (a torus
// beside a sphere: genus 1, two parts). Every level has exactly its vertex count and is judged by
// the CGAL referee against the level inside it and against the input.
#include "CoreTestPrinters.h"
#include "ExactCheck.h"
#include "Common/Progress.h"
#include "Mesh/Mesh.h"
#include "Mesh/Shapes.h"
#include "Pipeline/NestedCages.h"
#include "Spatial/TriangleTree.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

using namespace sdfcage;

TEST(NestedCounts, SortedDescendingAndChecked)
{
  std::vector<int> c;
  EXPECT_EQ(parseNestedCounts("100, 2000,500", c), "");
  EXPECT_EQ(sortNestedCounts(c), "");
  EXPECT_EQ(c, (std::vector<int>{ 2000, 500, 100 }));

  EXPECT_EQ(parseNestedCounts("300", c), "");
  EXPECT_EQ(c, (std::vector<int>{ 300 }));

  for (const char* bad : { "", "12,", ",5", "1,,2", "12a", "1.5,3", "a,b" })
  {
    EXPECT_NE(parseNestedCounts(bad, c), "") << bad;
  }

  std::vector<int> dup{ 500, 100, 500 };
  const std::string why = sortNestedCounts(dup);
  EXPECT_NE(why.find("500"), std::string::npos) << why;
  EXPECT_NE(why.find("twice"), std::string::npos) << why;
  EXPECT_EQ(dup, (std::vector<int>{ 500, 100, 500 })); // unchanged on error

  std::vector<int> zero{ 500, 0 };
  EXPECT_NE(sortNestedCounts(zero).find("at least 1"), std::string::npos);
  std::vector<int> negative;
  EXPECT_EQ(parseNestedCounts("200,-3", negative), "");
  EXPECT_NE(sortNestedCounts(negative).find("at least 1"), std::string::npos);
  std::vector<int> none;
  EXPECT_NE(sortNestedCounts(none), "");
}

TEST(NestedCages, RejectsBadCountsWithoutRunning)
{
  const TriangleMesh shape = makeBuiltinShape();
  const NestedCageResult r = generateNestedCages(PolygonMesh::fromTriangles(shape), { 200, 200 }, CageOptions());
  EXPECT_EQ(r.State, Status::InvalidInput);
  EXPECT_NE(r.Message.find("twice"), std::string::npos) << r.Message;
  EXPECT_TRUE(r.Levels.empty());
}

// Every level lies at least the clearance outside the one inside it, so a gap between parts
// narrows by twice the clearance (and the envelope's offset) per level: the default built-in
// shape's gap (0.012) closes at the second level. Here the gap leaves room for three levels.
TEST(NestedCages, BuiltinShapeLevelsAreExactAndStrictlyNested)
{
  const TriangleMesh shape = makeBuiltinShape(0.08);
  // unsorted on purpose: the levels come out finest first
  const NestedCageResult r = generateNestedCages(PolygonMesh::fromTriangles(shape), { 60, 400, 150 }, CageOptions());
  ASSERT_EQ(r.State, Status::Ok) << r.Message;
  ASSERT_EQ(r.Levels.size(), 3u);
  EXPECT_EQ(r.Counts, (std::vector<int>{ 400, 150, 60 }));
  for (std::size_t k = 0; k < r.Levels.size(); ++k)
  {
    const NestedLevel& level = r.Levels[k];
    const TriangleMesh& cage = level.Result.Cage;
    const TriangleMesh& inside = k == 0 ? shape : r.Levels[k - 1].Result.Cage;
    std::printf("level %zu: %d vertices (asked %d), genus %d, %d parts, clearance to inside %.4g, to input %.4g, "
                "%.2f s\n",
      k, level.Result.VerticesReached, level.TargetNumberOfVertices, level.CageGenus, level.CageComponents,
      level.ClearanceToInside, level.ClearanceToInput, level.Seconds);
    std::printf("  repairs %d: %s\n", level.Result.TopologyRepairs, level.Result.TopologyRepairLog.c_str());
    EXPECT_EQ(level.TargetNumberOfVertices, r.Counts[k]);
    EXPECT_TRUE(level.Result.TargetReached) << level.Result.StopReason;
    EXPECT_EQ(static_cast<int>(cage.Points.size()), r.Counts[k]);
    EXPECT_TRUE(level.VerifiedAgainstInside) << level.VerificationMessage;
    EXPECT_TRUE(level.VerifiedAgainstInput) << level.VerificationMessage;
    EXPECT_TRUE(level.TopologyKept);
    EXPECT_EQ(level.CageGenus, 1);
    EXPECT_EQ(level.CageComponents, 2);

    // the referee, against the level inside and against the input
    const exact::ExactReport in = exact::exactCheck(inside, cage, 0.0);
    EXPECT_TRUE(in.Encloses) << "level " << k << " vs inside: " << exact::toJson(in);
    EXPECT_EQ(in.CageGenus, 1);
    EXPECT_EQ(in.CageComponents, 2);
    const double clearance = level.Result.Normalize.lengthToInput(level.Result.ClearanceUsedRelative);
    EXPECT_GE(in.MinimumClearance, 0.999 * clearance) << "level " << k;
    EXPECT_NEAR(in.MinimumClearance, level.ClearanceToInside, 1e-9 + 1e-6 * clearance) << "level " << k;
    const exact::ExactReport out = exact::exactCheck(shape, cage, 0.0);
    EXPECT_TRUE(out.Encloses) << "level " << k << " vs input: " << exact::toJson(out);
    EXPECT_GE(out.MinimumClearance, in.MinimumClearance * (1.0 - 1e-9)) << "level " << k;
    // each coarser level lies farther out than the finer one
    if (k > 0)
    {
      EXPECT_GT(level.ClearanceToInput, r.Levels[k - 1].ClearanceToInput);
    }
    const ResultTable t = nestedLevelResults(level, static_cast<int>(k));
    ASSERT_NE(findResult(t, "Level"), nullptr);
    EXPECT_EQ(findResult(t, "Level")->Integer, static_cast<long long>(k));
    EXPECT_EQ(findResult(t, "VerifiedAgainstInside")->Integer, 1);
  }
}

namespace
{
/// Cancels as soon as the second level starts.
class CancelAtLevelTwo : public Progress
{
protected:
  void report(double, const std::string& stage) override
  {
    if (stage.rfind("level 2", 0) == 0)
      this->cancel();
  }
};
} // namespace

// Room between parts (SimplifyOptions::PartClearance): two spheres 0.08 apart keep two parts
// through three levels, each level's parts keep the room it reports (measured by the referee),
// and the counts are reached. Without the room the 40-vertex level fused (measured: 96 vertices,
// one part).
namespace
{
TriangleMesh twoSpheres(double gap)
{
  TriangleMesh shape = makeSphere(Vec3(-0.5 - gap / 2, 0, 0), 0.5, 64, 32);
  const TriangleMesh other = makeSphere(Vec3(0.5 + gap / 2, 0, 0), 0.5, 64, 32);
  const int offset = static_cast<int>(shape.Points.size());
  shape.Points.insert(shape.Points.end(), other.Points.begin(), other.Points.end());
  for (Triangle t : other.Triangles)
  {
    for (int& v : t)
      v += offset;
    shape.Triangles.push_back(t);
  }
  return shape;
}

// Each level encloses the one inside it without self-intersection, has two parts, and (all but
// the last) keeps its reported room between them, all measured by the referee.
void expectLevelsApart(const TriangleMesh& shape, const NestedCageResult& r, bool optimized)
{
  for (std::size_t k = 0; k < r.Levels.size(); ++k)
  {
    const NestedLevel& level = r.Levels[k];
    const TriangleMesh& cage = level.Result.Cage;
    const TriangleMesh& inside = k == 0 ? shape : r.Levels[k - 1].Result.Cage;
    const double room = level.Result.Normalize.lengthToInput(level.Result.Simplification.PartClearanceUsed);
    std::printf("level %zu: %d vertices, %d parts, room %.4g (input units), optimized %d\n", k,
      level.Result.VerticesReached, level.CageComponents, room, level.Result.Optimized ? 1 : 0);
    EXPECT_TRUE(level.Result.TargetReached) << level.Result.StopReason;
    EXPECT_EQ(level.CageComponents, 2) << "level " << k;
    if (optimized)
    {
      EXPECT_TRUE(level.Result.Optimized) << "level " << k << ": " << level.Result.Optimization.Message;
      EXPECT_GT(level.Result.Optimization.Moves, 0) << "level " << k;
      // the optimizer's room: what the simplified cage kept, at least the simplifier's
      EXPECT_GE(level.Result.Optimization.PartClearanceUsed, level.Result.Simplification.PartClearanceUsed);
    }
    const exact::ExactReport in = exact::exactCheck(inside, cage, 0.0);
    EXPECT_TRUE(in.Encloses) << "level " << k << ": " << exact::toJson(in);
    EXPECT_EQ(in.SelfIntersections, 0);
    // the room: asked of every level but the last, and kept between its two parts
    if (k + 1 < r.Levels.size())
    {
      EXPECT_GT(room, 0.0) << "level " << k;
    }
    else
    {
      EXPECT_EQ(room, 0.0);
    }
    std::vector<int> part;
    ASSERT_EQ(triangleComponents(cage, part), 2);
    TriangleMesh a, b;
    a.Points = b.Points = cage.Points;
    for (std::size_t f = 0; f < cage.Triangles.size(); ++f)
      (part[f] == part[0] ? a : b).Triangles.push_back(cage.Triangles[f]);
    const exact::ExactReport apart = exact::exactCheck(a, b, 1.0);
    std::printf("  parts %.4g apart\n", apart.MinimumClearance);
    EXPECT_GE(apart.MinimumClearance, 0.999 * room) << "level " << k;
  }
}
} // namespace

TEST(NestedCages, RoomBetweenPartsKeepsThemApartLevelAfterLevel)
{
  const TriangleMesh shape = twoSpheres(0.08);
  const NestedCageResult r = generateNestedCages(PolygonMesh::fromTriangles(shape), { 400, 100, 40 }, CageOptions());
  ASSERT_EQ(r.State, Status::Ok) << r.Message;
  ASSERT_EQ(r.Levels.size(), 3u);
  expectLevelsApart(shape, r, false);
}

// The optimizer keeps the parts as far apart as the simplified cage had them
// (OptimizeOptions::KeepPartsApart). Without it, the spacing energy pushed the 400-vertex level's
// parts to 0.00065 apart and the next level fused them (measured); with the simplifier's room
// alone (2.2 c) the 40-vertex level fused with both energies.

TEST(NestedCages, OptimizedLevelsKeepTheRoomBetweenParts)
{
  const TriangleMesh shape = twoSpheres(0.08);
  for (const CageEnergy energy : { CageEnergy::MIPS, CageEnergy::Spacing })
  {
    SCOPED_TRACE(energyName(energy));
    CageOptions options;
    options.Optimize = true;
    options.Optimization.Energy = energy;
    const NestedCageResult r = generateNestedCages(PolygonMesh::fromTriangles(shape), { 400, 100, 40 }, options);
    ASSERT_EQ(r.State, Status::Ok) << r.Message;
    ASSERT_EQ(r.Levels.size(), 3u);
    expectLevelsApart(shape, r, true);
  }
}

TEST(NestedCages, CancelKeepsTheFinishedLevels)
{
  const TriangleMesh shape = makeBuiltinShape();
  CancelAtLevelTwo progress;
  const NestedCageResult r =
    generateNestedCages(PolygonMesh::fromTriangles(shape), { 300, 100 }, CageOptions(), &progress);
  EXPECT_EQ(r.State, Status::Cancelled) << r.Message;
  ASSERT_EQ(r.Levels.size(), 1u);
  EXPECT_EQ(r.Levels[0].Result.VerticesReached, 300);
  EXPECT_TRUE(r.Levels[0].VerifiedAgainstInput);
}

// The level's results share a block's field data with the level's run (cageResults): the names
// must not clash, and each is a described CamelCase identifier.
TEST(NestedCages, LevelResultsAreDescribedAndApartFromTheRunResults)
{
  const ResultTable level = nestedLevelResults(NestedLevel(), 0);
  const ResultTable run = cageResults(CageResult());
  ASSERT_FALSE(level.empty());
  for (const ResultField& f : level)
  {
    EXPECT_FALSE(f.Name.empty());
    EXPECT_FALSE(f.Description.empty()) << f.Name;
    EXPECT_EQ(findResult(run, f.Name), nullptr) << f.Name << " is also a result of the run";
    EXPECT_EQ(&*findResult(level, f.Name), &f) << f.Name << " is used twice";
    if (f.Type == ResultField::Kind::Flag)
    {
      EXPECT_TRUE(f.Unit.empty()) << f.Name;
    }
  }
}
