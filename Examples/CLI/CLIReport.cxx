// SDFCage — CLI: see CLIReport.h.
#include "CLIReport.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace sdfcage_cli
{

std::string jsonString(const std::string& s)
{
  std::string out = "\"";
  for (const char ch : s)
  {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (c)
    {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20)
        {
          char buffer[8];
          std::snprintf(buffer, sizeof(buffer), "\\u%04x", c);
          out += buffer;
        }
        else
        {
          out += ch;
        }
    }
  }
  return out + "\"";
}

std::string jsonNumber(double v)
{
  if (!std::isfinite(v))
  {
    return "null"; // JSON has no NaN/Inf
  }
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.10g", v);
  return buffer;
}

namespace
{

std::string seconds(double s)
{
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f s", s);
  return buffer;
}

std::string number(double v)
{
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", v);
  return buffer;
}

} // namespace

double RunReport::number(const char* name) const
{
  const sdfcage::ResultField* f = sdfcage::findResult(Results, name);
  return f ? f->number() : 0.0;
}

std::string RunReport::text(const char* name) const
{
  const sdfcage::ResultField* f = sdfcage::findResult(Results, name);
  return f && f->Type == sdfcage::ResultField::Kind::Text ? f->Text : std::string();
}

void writeJsonResults(std::ostream& os, const sdfcage::ResultTable& results, bool& first)
{
  for (const sdfcage::ResultField& f : results)
  {
    os << (first ? "\n" : ",\n") << "  " << jsonString(f.Name) << ": ";
    first = false;
    switch (f.Type)
    {
      case sdfcage::ResultField::Kind::Flag:
        os << (f.Integer ? "true" : "false");
        break;
      case sdfcage::ResultField::Kind::Integer:
        os << f.Integer;
        break;
      case sdfcage::ResultField::Kind::Real:
        os << jsonNumber(f.Real);
        break;
      case sdfcage::ResultField::Kind::Text:
        os << jsonString(f.Text);
        break;
    }
  }
}

std::string toJson(const RunReport& r)
{
  std::ostringstream os;
  bool first = true;
  auto key = [&](const char* name) -> std::ostream& {
    os << (first ? "\n" : ",\n") << "  " << jsonString(name) << ": ";
    first = false;
    return os;
  };
  os << "{";
  // the run
  key("InputFile") << jsonString(r.InputFile);
  key("OutputFile") << jsonString(r.OutputFile);
  key("ScreenshotFile") << jsonString(r.ScreenshotFile);
  key("Status") << jsonString(r.Status);
  key("ErrorMessage") << jsonString(r.ErrorMessage);
  key("ExitCode") << r.ExitCode;
  // what was asked
  key("IsoValue") << jsonNumber(r.IsoValue);
  key("VoxelSize") << jsonNumber(r.VoxelSize);
  key("MinimumClearance") << jsonNumber(r.MinimumClearance);
  key("MinimumClearanceUsed") << jsonNumber(r.MinimumClearanceUsed);
  key("TargetNumberOfVertices") << r.TargetNumberOfVertices;
  key("Adaptivity") << jsonNumber(r.Adaptivity);
  key("MaximumRefinements") << r.MaximumRefinements;
  key("CoarseFirst") << (r.CoarseFirst ? "true" : "false");
  key("ChooseIsoValueFirst") << (r.ChooseIsoValueFirst ? "true" : "false");
  key("Optimize") << jsonString(r.Optimize);
  key("TargetSpacing") << jsonNumber(r.TargetSpacing);
  key("NumberOfIterations") << r.NumberOfIterations;
  key("HausdorffFactor") << jsonNumber(r.HausdorffFactor);
  key("TargetMinimumAngle") << jsonNumber(r.TargetMinimumAngle);
  key("MaximumSweeps") << r.MaximumSweeps;
  key("NumberOfThreads") << r.NumberOfThreads;
  key("UseActivePoints") << (r.UseActivePoints ? "true" : "false");
  key("ActiveRadius") << jsonNumber(r.ActiveRadius);
  key("GeodesicThreshold") << jsonNumber(r.GeodesicThreshold);
  key("AmplificationAlpha") << jsonNumber(r.AmplificationAlpha);
  key("AmplificationBeta") << jsonNumber(r.AmplificationBeta);
  key("RequestedSignMode") << jsonString(r.Sign);
  // the meshes, reading and writing
  key("InputPoints") << r.InputPoints;
  key("InputCells") << r.InputCells;
  key("InputTriangles") << r.InputTriangles;
  key("EnvelopePoints") << r.EnvelopePoints;
  key("EnvelopeTriangles") << r.EnvelopeTriangles;
  key("CagePoints") << r.CagePoints;
  key("CageTriangles") << r.CageTriangles;
  key("ReadTime") << jsonNumber(r.ReadTime);
  key("WriteTime") << jsonNumber(r.WriteTime);
  if (!r.NestedCounts.empty())
  {
    std::ostringstream counts;
    for (std::size_t i = 0; i < r.NestedCounts.size(); ++i)
      counts << (i ? ", " : "") << r.NestedCounts[i];
    key("NestedVertexCounts") << "[" << counts.str() << "]";
    key("NestedLevels") << "[";
    for (std::size_t k = 0; k < r.Levels.size(); ++k)
    {
      const LevelReport& l = r.Levels[k];
      os << (k ? ",\n    {" : "\n    {") << "\n      \"Name\": " << jsonString(l.Name)
         << ",\n      \"File\": " << jsonString(l.File) << ",\n      \"Status\": " << jsonString(l.Status)
         << ",\n      \"Points\": " << l.Points << ",\n      \"Triangles\": " << l.Triangles;
      bool firstField = false;
      std::ostringstream fields;
      writeJsonResults(fields, l.Results, firstField);
      // writeJsonResults indents by two: one level deeper here
      std::string text = fields.str();
      for (std::size_t at = text.find("\n  "); at != std::string::npos; at = text.find("\n  ", at + 7))
        text.replace(at, 3, "\n      ");
      os << text << "\n    }";
    }
    os << (r.Levels.empty() ? "]" : "\n  ]");
  }
  // every result of the filter
  writeJsonResults(os, r.Results, first);
  os << "\n}\n";
  return os.str();
}

bool writeJsonReport(const RunReport& r, const std::string& path, std::string& error)
{
  std::ofstream file(path, std::ios::out | std::ios::trunc);
  if (!file)
  {
    error = "cannot write the report '" + path + "': check that the folder exists and is writable";
    return false;
  }
  file << toJson(r);
  file.close();
  if (!file)
  {
    error = "cannot write the report '" + path + "': write error";
    return false;
  }
  return true;
}

void printSummary(std::ostream& os, const RunReport& r)
{
  os << "input       : " << (r.InputFile == "builtin" ? "built-in shape" : r.InputFile) << ", " << r.InputPoints
     << " points, " << r.InputTriangles << " triangles";
  if (r.InputCells != r.InputTriangles)
  {
    os << " (from " << r.InputCells << " polygons)";
  }
  if (r.flag("InputWasFlipped"))
  {
    os << ", inward-oriented (flipped)";
  }
  os << "\n";
  if (!r.FilterRan)
  {
    return;
  }
  os << "repairs     : " << r.integer("MergedPoints") << " points merged, " << r.integer("TriangulatedPolygons")
     << " polygons triangulated, " << r.integer("DroppedDegenerateTriangles") << " degenerate and "
     << r.integer("DroppedDuplicateTriangles") << " duplicated triangles dropped\n";
  os << "inside rule : " << r.text("SignMode") << " (" << r.text("SignReason") << "); " << r.integer("InputComponents")
     << " component(s), " << r.integer("InputBoundaryEdges") << " boundary edges, "
     << r.integer("InputNonManifoldEdges") << " non-manifold edges, " << r.integer("InputNonManifoldVertices")
     << " non-manifold vertices";
  if (r.integer("InputClosed"))
    os << ", genus " << r.integer("InputGenus");
  os << "\n";
  const std::string sign = r.text("SignMode");
  if (r.UseActivePoints && sign != "flood" && !sign.empty())
  {
    os << "active pts  : skipped (they need a closed input and the flood-fill rule)\n";
  }
  else if (r.UseActivePoints)
  {
    os << "active pts  : " << r.integer("NumberOfActivePoints") << " input points (r " << number(r.ActiveRadius)
       << ", l " << number(r.GeodesicThreshold) << ", alpha " << number(r.AmplificationAlpha);
    // lowered where the requested alpha would put the envelope within the clearance (or raised by
    // a topology repair round): the kept envelope's
    const double alphaUsed =
      sdfcage::findResult(r.Results, "AmplificationAlphaUsed") ? r.number("AmplificationAlphaUsed") : 0.0;
    if (alphaUsed > 0 && std::abs(alphaUsed - r.AmplificationAlpha) > 1e-9)
    {
      os << " (the kept envelope's: " << number(alphaUsed) << ")";
    }
    os << ", beta " << number(r.AmplificationBeta) << "), " << seconds(r.number("ActivePointTime")) << "\n";
  }
  else
  {
    os << "active pts  : off (plain offset)\n";
  }
  os << "envelope    : " << r.EnvelopePoints << " points, " << r.EnvelopeTriangles << " triangles, "
     << r.integer("EnvelopeComponents") << " component(s), genus " << r.integer("EnvelopeGenus") << ", "
     << r.integer("RemovedPockets") << " trapped pocket(s) removed\n";
  os << "cage        : " << r.CagePoints << " points, " << r.CageTriangles << " triangles";
  if (r.TargetNumberOfVertices > 0)
  {
    const bool reached = r.flag("TargetReached");
    const std::string stop = r.text("StopReason");
    os << (reached ? " (target " : " (target NOT reached: ") << r.TargetNumberOfVertices
       << (reached           ? std::string(" reached")
              : stop.empty() ? std::string()
                             : std::string("; ") + stop)
       << ")";
  }
  else
  {
    os << " (not simplified)";
  }
  if (r.integer("Relaxations") > 0)
  {
    os << "; the simplification stalled at " << r.integer("VerticesBeforeRelaxation") << " vertices and went on after "
       << r.integer("Relaxations") << " relaxation sweep(s) (" << seconds(r.number("RelaxationTime")) << ")";
  }
  if (!r.OutputFile.empty())
  {
    os << " -> " << r.OutputFile;
  }
  os << "\n";
  os << "voxel size  : " << number(r.number("VoxelSizeUsed")) << " (relative: the input scaled into the "
     << "unit sphere), isovalue " << number(r.IsoValue) << ", adaptivity " << number(r.Adaptivity);
  // the kept envelope's, where it differs (a topology repair round merges at 1; a failed
  // adaptive extraction falls back to 0.3, then 0)
  if (sdfcage::findResult(r.Results, "AdaptivityUsed") && r.number("VoxelSizeUsed") > 0 &&
    std::abs(r.number("AdaptivityUsed") - r.Adaptivity) > 1e-12)
  {
    os << " (the kept envelope's: " << number(r.number("AdaptivityUsed")) << ")";
  }
  os << "\n";
  if (r.integer("EnvelopeProbes") > 0)
  {
    os << "probes      : " << r.integer("EnvelopeProbes") << " coarse-grid probe(s) chose the isovalue in "
       << seconds(r.number("ProbeTime")) << ", " << r.integer("IsoValuesSkipped")
       << " isovalue(s) ruled out and not built (--no-choose-iso-first: every widening built)\n";
  }
  if (r.integer("EnvelopeWidenings") > 0)
  {
    os << "widened     : " << r.integer("EnvelopeWidenings") << " time(s), to isovalue "
       << number(r.number("IsoValueUsed")) << " (the input has no defined topology and the target "
       << "needed it): " << r.text("WideningLog") << "\n";
  }
  os << "timings     : validation " << seconds(r.number("ValidationTime")) << ", distance field "
     << seconds(r.number("DistanceFieldTime")) << ", active points " << seconds(r.number("ActivePointTime"))
     << ", isosurface " << seconds(r.number("IsosurfaceTime")) << ", verification "
     << seconds(r.number("VerificationTime")) << ",\n              simplification "
     << seconds(r.number("SimplificationTime")) << ", cage verification " << seconds(r.number("CageVerificationTime"))
     << ", total " << seconds(r.number("TotalTime")) << "\n";
  if (r.Optimize != "none")
  {
    os << "optimization: " << r.Optimize << " energy " << number(r.number("EnergyBefore")) << " -> "
       << number(r.number("EnergyAfter")) << ", " << r.NumberOfIterations << " iteration(s), "
       << r.integer("NumberOfSweeps") << " sweep(s), "
       << seconds(r.number("OptimizationTime")) << "\n"
       << "              min angle " << number(r.number("MinimumAngleBefore")) << " -> "
       << number(r.number("MinimumAngleAfter")) << " deg, Hausdorff cage->input " << number(r.number("HausdorffBefore"))
       << " -> " << number(r.number("HausdorffAfter")) << " relative\n";
    if (r.Optimize == "spacing")
    {
      const double closer = r.number("SpacingCloserAfter"), farther = r.number("SpacingFartherAfter");
      os << "              area within spacing " << number(r.TargetSpacing)
         << " +- 20%: " << number(r.number("SpacingBandBefore")) << "% -> " << number(r.number("SpacingBandAfter"))
         << "% (closer " << number(closer) << "%, farther " << number(farther) << "%)\n";
      // much of the cage off the band after an optimization: its vertices are too few to follow
      // the input's detail at that distance, over small features (closer) and into concavities
      // (farther), or the rounds ended early (dragon_quartet at h 0.03: 55% within the band at
      // 500 vertices, 24% closer, 21% farther; 56% with 4 rounds; 90% at 2,000 vertices)
      if (r.number("SpacingBandAfter") < 80.0 && r.integer("NumberOfSweeps") > 0)
        os << "              (more vertices, -n, or more rounds, --iterations, let the cage follow the input "
              "more closely at that distance)\n";
    }
  }
  os << "clearance   : " << number(r.number("MeasuredClearance"))
     << " (input units) = " << number(r.number("MeasuredClearanceRelative"))
     << " relative, required >= "
     << number(r.number("ClearanceUsed") > 0 ? r.number("ClearanceUsed") : r.MinimumClearanceUsed) << " relative\n";
  os << "enclosure verified: " << (r.flag("EnclosureVerified") ? "yes" : "no") << "\n";
  if (!r.NestedCounts.empty())
  {
    os << "nested levels (each re-verified against the level inside it and against the input):\n";
    for (const LevelReport& l : r.Levels)
    {
      auto value = [&l](const char* name) {
        const sdfcage::ResultField* f = sdfcage::findResult(l.Results, name);
        return f ? f->number() : 0.0;
      };
      os << "  " << l.Name << std::string(l.Name.size() < 11 ? 11 - l.Name.size() : 0, ' ') << ": ";
      if (l.Status == "NotBuilt")
      {
        os << "not built\n";
        continue;
      }
      os << l.Points << " points" << (value("TargetReached") != 0 ? "" : " (target NOT reached)") << ", clearance to inside "
         << number(value("ClearanceToInside")) << ", to input " << number(value("ClearanceToInput")) << ", genus "
         << static_cast<long long>(value("CageGenus")) << ", " << static_cast<long long>(value("CageComponents"))
         << " part(s), verified "
         << (value("VerifiedAgainstInside") != 0 && value("VerifiedAgainstInput") != 0 ? "yes" : "NO") << ", "
         << seconds(value("LevelTime"));
      if (!l.File.empty())
        os << " -> " << l.File;
      os << "\n";
    }
  }
}

sdfcage::ResultTable levelResultFields()
{
  sdfcage::ResultTable t = sdfcage::nestedLevelResults(sdfcage::NestedLevel(), 0);
  const sdfcage::ResultTable run = sdfcage::cageResults(sdfcage::CageResult());
  for (const char* name :
    { "VerticesReached", "TargetReached", "MeasuredClearance", "StopReason", "TopologyWarning", "TotalTime" })
  {
    if (const sdfcage::ResultField* f = sdfcage::findResult(run, name))
      t.push_back(*f);
  }
  return t;
}

void printResults(std::ostream& os, const sdfcage::ResultTable& results)
{
  std::size_t width = 0;
  for (const sdfcage::ResultField& f : results)
  {
    width = std::max(width, f.Name.size());
  }
  os << "results:\n";
  for (const sdfcage::ResultField& f : results)
  {
    std::string value = f.toString();
    if (!f.Unit.empty() && f.Unit != "count")
    {
      value += " " + f.Unit;
    }
    os << "  " << f.Name << std::string(width - f.Name.size(), ' ') << " = " << value << "  (" << f.Description
       << ")\n";
  }
}

} // namespace sdfcage_cli
