// SDFCage — CLI: `sdfcage --check INPUT CAGE [--report FILE.json]`, the verdicts of
// vtkCageQualityFilter for any pair of mesh files.
#pragma once

#include <string>

namespace sdfcage_cli
{

class MessageCollector;

/// Reads both files, judges the cage, prints a summary (unless quiet) and writes the JSON report
/// (if `report` is not empty, also on failures). Returns the exit code: 0 the cage encloses the
/// input, 1 it does not, 2 a file cannot be used (missing, unknown format, no polygons),
/// 3 the report cannot be written or an internal error.
int runCheck(
  const std::string& input, const std::string& cage, const std::string& report, bool quiet, MessageCollector* messages);

} // namespace sdfcage_cli
