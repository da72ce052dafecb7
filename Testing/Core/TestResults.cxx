// The results table (Core/Pipeline/Results): every way out (field data, getters, CLI summary and
// JSON) iterates it, so its names must be unique and well-formed, and its values must be the
// run's.
#include "Envelope/ActivePointAnalysis.h"
#include "Mesh/Shapes.h"
#include "Optimization/Optimization.h"
#include "Pipeline/CageGenerator.h"
#include "Pipeline/Results.h"
#include "Quality/CageQuality.h"

#include <gtest/gtest.h>

#include <cctype>
#include <set>
#include <string>

using namespace sdfcage;

namespace
{
void expectWellFormed(const ResultTable& table, const char* what)
{
  ASSERT_FALSE(table.empty()) << what;
  std::set<std::string> names;
  for (const ResultField& f : table)
  {
    EXPECT_TRUE(names.insert(f.Name).second) << what << ": the name " << f.Name << " is used twice";
    ASSERT_FALSE(f.Name.empty()) << what;
    EXPECT_TRUE(std::isupper(static_cast<unsigned char>(f.Name[0]))) << what << ": " << f.Name << " is not CamelCase";
    for (const char c : f.Name)
    {
      EXPECT_TRUE(std::isalnum(static_cast<unsigned char>(c)))
        << what << ": " << f.Name << " is not a plain identifier";
    }
    EXPECT_FALSE(f.Description.empty()) << what << ": " << f.Name << " has no description";
    if (f.Type == ResultField::Kind::Text || f.Type == ResultField::Kind::Flag)
    {
      EXPECT_TRUE(f.Unit.empty()) << what << ": " << f.Name << " is text or a flag, with a unit";
    }
    if (f.Type == ResultField::Kind::Flag)
    {
      EXPECT_TRUE(f.Integer == 0 || f.Integer == 1) << what << ": " << f.Name;
    }
  }
}

double number(const ResultTable& table, const char* name)
{
  const ResultField* f = findResult(table, name);
  EXPECT_NE(f, nullptr) << name;
  return f ? f->number() : -12345.0;
}

std::string text(const ResultTable& table, const char* name)
{
  const ResultField* f = findResult(table, name);
  EXPECT_NE(f, nullptr) << name;
  return f ? f->Text : std::string("<missing>");
}
} // namespace

TEST(Results, NamesAreUniqueAndDescribed)
{
  expectWellFormed(cageResults(CageResult()), "cageResults");
  expectWellFormed(optimizeResults(OptimizeResult(), 0.0), "optimizeResults");
  expectWellFormed(qualityResults(CageQualityResult()), "qualityResults");
  expectWellFormed(activePointResults(ActivePointAnalysis()), "activePointResults");
  // the same table whatever the run: names and kinds do not depend on the values
  CageResult other;
  other.EnclosureVerified = true;
  other.SignReason = "requested";
  const ResultTable a = cageResults(CageResult()), b = cageResults(other);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    EXPECT_EQ(a[i].Name, b[i].Name);
    EXPECT_EQ(a[i].Type, b[i].Type) << a[i].Name;
  }
}

TEST(Results, NamesUsersScriptAgainstArePresent)
{
  // field-data arrays, getters and JSON keys of the first waves: renaming one breaks scripts
  const ResultTable cage = cageResults(CageResult());
  for (const char* name :
    { "ValidationTime", "DistanceFieldTime", "IsosurfaceTime", "VerificationTime", "SimplificationTime",
      "CageVerificationTime", "TotalTime", "EnergyBefore", "EnergyAfter", "OptimizationTime", "VerticesReached",
      "TargetReached", "StopReason", "MeasuredClearance", "MeasuredClearanceRelative", "EnclosureVerified",
      "RemovedPockets", "EnvelopeGenus", "EnvelopeComponents", "VoxelSizeUsed", "InputWasFlipped",
      "NumberOfActivePoints", "ActivePointTime", "TopologyWarning", "MergedPoints", "MergeTolerance",
      "TriangulatedPolygons", "DroppedDegenerateTriangles", "DroppedDuplicateTriangles", "IgnoredCells",
      "InputBoundaryEdges", "InputNonManifoldEdges", "InputNonManifoldVertices", "InputInconsistentEdges",
      "InputComponents", "InputClosed", "InputGenus", "SignMode", "SignReason", "WindingTime" })
  {
    EXPECT_NE(findResult(cage, name), nullptr) << "cageResults has no " << name;
  }
  const ResultTable optimize = optimizeResults(OptimizeResult(), 0.0);
  for (const char* name :
    { "EnergyBefore", "EnergyAfter", "MinimumAngleBefore", "MinimumAngleAfter", "MeasuredClearance",
      "MeasuredClearanceRelative", "ClearanceUsed", "NumberOfMoves", "NumberOfFlips", "Reverted", "OptimizationTime" })
  {
    EXPECT_NE(findResult(optimize, name), nullptr) << "optimizeResults has no " << name;
  }
  const ResultTable quality = qualityResults(CageQualityResult());
  for (const char* name : { "Encloses", "MinimumClearance", "MinimumClearanceRelative", "HausdorffCageToInput",
         "HausdorffCageToInputRelative", "HausdorffCageToInputBound", "HausdorffInputToCage",
         "HausdorffInputToCageRelative", "HausdorffInputToCageBound", "MeanDistanceCageToInput",
         "MeanDistanceCageToInputRelative", "SelfIntersections", "InputIntersections", "InputVerticesOutside",
         "CageGenus", "InputGenus", "QualityTime", "QualityMessage" })
  {
    EXPECT_NE(findResult(quality, name), nullptr) << "qualityResults has no " << name;
  }
}

TEST(Results, ARunThatDidNotHappen)
{
  const ResultTable t = cageResults(CageResult());
  EXPECT_EQ(number(t, "EnclosureVerified"), 0.0);
  EXPECT_EQ(number(t, "InputGenus"), -1.0) << "undefined for an input that was never validated";
  EXPECT_EQ(text(t, "SignMode"), "") << "no inside rule was decided";
  EXPECT_EQ(findResult(t, "NoSuchResult"), nullptr);
}

TEST(Results, CarryTheValuesOfARun)
{
  CageOptions options;
  options.TargetNumberOfVertices = 80;
  options.Envelope.IsoValue = 0.04;
  const CageResult r = generateCage(PolygonMesh::fromTriangles(makeSphere(Vec3(0, 0, 0), 1.0, 24, 12)), options);
  ASSERT_EQ(r.State, Status::Ok) << r.Message;
  const ResultTable t = cageResults(r);
  EXPECT_EQ(number(t, "EnclosureVerified"), 1.0);
  EXPECT_EQ(number(t, "VerticesReached"), r.VerticesReached);
  EXPECT_EQ(number(t, "VerticesReached"), 80.0);
  EXPECT_EQ(number(t, "TargetReached"), 1.0);
  EXPECT_EQ(number(t, "MeasuredClearance"), r.MinimumClearance);
  EXPECT_GT(number(t, "MeasuredClearance"), 0.0);
  EXPECT_EQ(number(t, "MeasuredClearanceRelative"), r.MinimumClearanceRelative);
  EXPECT_EQ(number(t, "EnvelopeGenus"), 0.0);
  EXPECT_EQ(number(t, "EnvelopeComponents"), 1.0);
  EXPECT_EQ(number(t, "Collapses"), static_cast<double>(r.Simplification.Collapses));
  EXPECT_GT(number(t, "Collapses"), 0.0);
  EXPECT_EQ(number(t, "TotalTime"), r.TotalSeconds);
  EXPECT_EQ(number(t, "InputGenus"), 0.0);
  EXPECT_EQ(number(t, "InputClosed"), 1.0);
  EXPECT_EQ(text(t, "SignMode"), "flood");
  EXPECT_EQ(text(t, "SignReason"), r.SignReason);
  EXPECT_EQ(text(t, "StopReason"), "");
  EXPECT_EQ(number(t, "Optimized"), 0.0);

  // the kinds survive the way through numbers (the VTK getters): setNumber is number's inverse
  for (ResultField f : t)
  {
    if (f.Type == ResultField::Kind::Text)
      continue;
    const double v = f.number();
    ResultField g = f;
    g.Integer = 0;
    g.Real = 0.0;
    g.setNumber(v);
    EXPECT_EQ(g.number(), v) << f.Name;
  }
}
