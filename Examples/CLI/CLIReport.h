// SDFCage — CLI: what one run did, as a text summary and as a JSON report.
#pragma once

#include "Pipeline/CageGenerator.h"
#include "Pipeline/NestedCages.h"
#include "Pipeline/Results.h"

#include <ostream>
#include <string>
#include <vector>

namespace sdfcage_cli
{

/// One level of a nested run (-n 2000,500,100).
struct LevelReport
{
  int Count = 0;         ///< vertex count asked
  std::string Name;      ///< "cage_<count>"
  std::string File;      ///< file written ("" when none; the .vtm/.vtpc when all levels share one)
  std::string Status;    ///< the level's status ("NotBuilt" when the run stopped before it)
  long long Points = 0;
  long long Triangles = 0;
  /// nestedLevelResults' fields and a few of the level's run (VerticesReached, TargetReached,
  /// MeasuredClearance, StopReason, TopologyWarning, TotalTime), read from the level's block.
  sdfcage::ResultTable Results;
};

/// The fields of LevelReport::Results, with their "nothing" values.
sdfcage::ResultTable levelResultFields();

/// Everything the program reports. Result fields are named like vtkSDFCageFilter's getters and
/// the JSON keys are exactly these names.
struct RunReport
{
  /// A result of the table by name: its number (flags 0/1, 0 when absent) or its text.
  double number(const char* name) const;
  long long integer(const char* name) const { return static_cast<long long>(number(name)); }
  bool flag(const char* name) const { return number(name) != 0.0; }
  std::string text(const char* name) const;

  // what was asked
  std::string InputFile;  ///< path, or "builtin" for the built-in shape
  std::string OutputFile; ///< path written, "" when nothing was written
  std::string ReportFile;
  std::string ScreenshotFile; ///< "" when none was written
  double IsoValue = 0.0;
  double VoxelSize = 0.0;
  double MinimumClearance = 0.0;
  double MinimumClearanceUsed = 0.0; ///< after "0 = automatic"
  double Adaptivity = 0.0;
  int TargetNumberOfVertices = 0; ///< the target (0 = no simplification)
  int MaximumRefinements = 0;
  std::string Optimize = "none"; ///< none, mips or spacing
  std::string Sign = "auto";     ///< the inside rule asked for (SignMode has the one used)
  double TargetSpacing = 0.0;
  int NumberOfIterations = 0;
  double HausdorffFactor = 0.0;
  double TargetMinimumAngle = 0.0;
  int MaximumSweeps = 0;
  int NumberOfThreads = 0;
  bool UseActivePoints = true;
  bool CoarseFirst = true;
  bool ChooseIsoValueFirst = true;
  double ActiveRadius = 0.0;
  double GeodesicThreshold = 0.0;
  double AmplificationAlpha = 0.0;
  double AmplificationBeta = 0.0;

  /// Nested levels asked with -n N1,N2,... (sorted, finest first); empty for one cage.
  std::vector<int> NestedCounts;
  std::vector<LevelReport> Levels; ///< one per count when nested

  // counts
  long long InputPoints = 0;
  long long InputCells = 0;
  long long InputTriangles = 0;
  long long EnvelopePoints = 0;
  long long EnvelopeTriangles = 0;
  long long CagePoints = 0;
  long long CageTriangles = 0;

  double ReadTime = 0.0;
  double WriteTime = 0.0;
  /// Every result of the cage filter (Core's cageResults table, read back from the filter by
  /// name): JSON keys and summary values come from it.
  sdfcage::ResultTable Results = sdfcage::cageResults(sdfcage::CageResult());
  bool FilterRan = false; ///< false when the run stopped before the filter (e.g. unreadable)

  // outcome
  std::string Status = "NotRun"; ///< the filter's status string, or a CLI-level one
  std::string ErrorMessage;
  int ExitCode = 0;
};

/// The human-readable summary (several lines).
void printSummary(std::ostream& os, const RunReport& r);

/// Every result of the table, one per line: name, value, unit and description (--verbose).
void printResults(std::ostream& os, const sdfcage::ResultTable& results);

/// A table's results as JSON members (`"Name": value`, flags as true/false), for the reports.
void writeJsonResults(std::ostream& os, const sdfcage::ResultTable& results, bool& first);

/// Writes the JSON report. Returns false with a reason.
bool writeJsonReport(const RunReport& r, const std::string& path, std::string& error);

/// JSON literals: a quoted, escaped string; a number ("null" when not finite).
std::string jsonString(const std::string& s);
std::string jsonNumber(double v);

/// The report as a JSON object (also used by the tests through the file).
std::string toJson(const RunReport& r);

} // namespace sdfcage_cli
