// SDFCage — Testing: the whole pipeline gives the same cage on 1 and 2 threads, on one real mesh.
//
//   SDFCageDeterminismTests --mesh=FILE [--optimize] [gtest flags]
//   SDFCageDeterminismTests --data-dir=DIR        (no mesh: reports SKIPPED, naming the folder)
//
// generateCage runs twice with the default options (CageOptions; with --optimize the MIPS
// optimization too), NumberOfThreads 1 and 2. Everything a user gets must be bit for bit the
// same: the envelope, the cage (points and triangles, in order), the per-vertex distances, the
// clearance, the vertex count reached and the stop reason. On a difference the test names the
// first output that differs and where.
#include "Pipeline/CageGenerator.h"
#include "MeshIO.h"
#include "DataTestSupport.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

using namespace sdfcage;

namespace
{

datatest::Arguments gArgs;

/// "" when a and b are the same bit for bit, else where they first differ.
std::string compareMeshes(const TriangleMesh& a, const TriangleMesh& b)
{
  std::ostringstream s;
  if (a.Points.size() != b.Points.size() || a.Triangles.size() != b.Triangles.size())
  {
    s << a.Points.size() << " points and " << a.Triangles.size() << " triangles against " << b.Points.size()
      << " and " << b.Triangles.size();
    return s.str();
  }
  for (std::size_t i = 0; i < a.Points.size(); ++i)
  {
    if (std::memcmp(a.Points[i].data(), b.Points[i].data(), 3 * sizeof(double)) != 0)
    {
      s.precision(17);
      s << "point " << i << ": (" << a.Points[i].transpose() << ") against (" << b.Points[i].transpose() << ")";
      return s.str();
    }
  }
  for (std::size_t t = 0; t < a.Triangles.size(); ++t)
  {
    if (a.Triangles[t] != b.Triangles[t])
    {
      s << "triangle " << t << ": " << a.Triangles[t][0] << " " << a.Triangles[t][1] << " " << a.Triangles[t][2]
        << " against " << b.Triangles[t][0] << " " << b.Triangles[t][1] << " " << b.Triangles[t][2];
      return s.str();
    }
  }
  return "";
}

std::string compareValues(const std::vector<double>& a, const std::vector<double>& b)
{
  if (a.size() != b.size())
    return std::to_string(a.size()) + " values against " + std::to_string(b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0)
    {
      std::ostringstream s;
      s.precision(17);
      s << "value " << i << ": " << a[i] << " against " << b[i];
      return s.str();
    }
  return "";
}

} // namespace

TEST(Determinism, SameCageOnOneAndTwoThreads)
{
  SDFCAGE_SKIP_WITHOUT_MESH(gArgs.Mesh, gArgs.DataDir);
  PolygonMesh polygons;
  std::string error;
  ASSERT_TRUE(exact::readPolygonMesh(gArgs.Mesh, polygons, error)) << error;

  CageResult results[2];
  for (int k = 0; k < 2; ++k)
  {
    CageOptions options;
    options.NumberOfThreads = k + 1;
    options.Optimize = gArgs.has("optimize");
    results[k] = generateCage(polygons, options);
    std::cout << "[ threads  ] " << (k + 1) << ": " << statusName(results[k].State) << ", envelope "
              << results[k].Envelope.Points.size() << " points, cage " << results[k].Cage.Points.size()
              << " points, " << results[k].TotalSeconds << " s\n";
  }
  const CageResult& a = results[0];
  const CageResult& b = results[1];
  // the run must have produced something to compare
  ASSERT_EQ(a.State, Status::Ok) << a.Message;
  ASSERT_FALSE(a.Cage.Triangles.empty());

  EXPECT_EQ(b.State, a.State) << b.Message;
  EXPECT_EQ(b.Message, a.Message);
  EXPECT_EQ(compareMeshes(a.Envelope, b.Envelope), "") << "the envelopes differ";
  EXPECT_EQ(compareValues(a.EnvelopeDistanceToInput, b.EnvelopeDistanceToInput), "")
    << "the envelopes' distances differ";
  EXPECT_EQ(compareMeshes(a.Cage, b.Cage), "") << "the cages differ";
  EXPECT_EQ(compareValues(a.CageDistanceToInput, b.CageDistanceToInput), "") << "the cages' distances differ";
  EXPECT_EQ(compareValues({ a.MinimumClearance }, { b.MinimumClearance }), "");
  EXPECT_EQ(b.VerticesReached, a.VerticesReached);
  EXPECT_EQ(b.TargetReached, a.TargetReached);
  EXPECT_EQ(b.StopReason, a.StopReason);
  EXPECT_EQ(b.EnvelopeWidenings, a.EnvelopeWidenings);
  EXPECT_EQ(b.TopologyRepairs, a.TopologyRepairs);
  EXPECT_EQ(b.NumberOfActivePoints, a.NumberOfActivePoints);
  EXPECT_EQ(b.Optimized, a.Optimized);
}

int main(int argc, char** argv)
{
  if (!datatest::parseArguments(argc, argv, "SDFCageDeterminismTests", { "optimize" }, {}, gArgs))
    return 2;
  return RUN_ALL_TESTS();
}
