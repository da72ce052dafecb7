// SDFCage — CLI: see CLIReport.h.
#include "CLIReport.h"

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
  key("InputFile") << jsonString(r.InputFile);
  key("OutputFile") << jsonString(r.OutputFile);
  key("ScreenshotFile") << jsonString(r.ScreenshotFile);
  key("Status") << jsonString(r.Status);
  key("ErrorMessage") << jsonString(r.ErrorMessage);
  key("ExitCode") << r.ExitCode;
  key("IsoValue") << jsonNumber(r.IsoValue);
  key("VoxelSize") << jsonNumber(r.VoxelSize);
  key("MinimumClearance") << jsonNumber(r.MinimumClearance);
  key("MinimumClearanceUsed") << jsonNumber(r.MinimumClearanceUsed);
  key("TargetNumberOfVertices") << r.TargetNumberOfVertices;
  key("Adaptivity") << jsonNumber(r.Adaptivity);
  key("MaximumRefinements") << r.MaximumRefinements;
  key("Optimize") << jsonString(r.Optimize);
  key("TargetSpacing") << jsonNumber(r.TargetSpacing);
  key("NumberOfIterations") << r.NumberOfIterations;
  key("NumberOfThreads") << r.NumberOfThreads;
  key("UseActivePoints") << (r.UseActivePoints ? "true" : "false");
  key("ActiveRadius") << jsonNumber(r.ActiveRadius);
  key("GeodesicThreshold") << jsonNumber(r.GeodesicThreshold);
  key("AmplificationAlpha") << jsonNumber(r.AmplificationAlpha);
  key("AmplificationBeta") << jsonNumber(r.AmplificationBeta);
  key("InputPoints") << r.InputPoints;
  key("InputCells") << r.InputCells;
  key("InputTriangles") << r.InputTriangles;
  key("EnvelopePoints") << r.EnvelopePoints;
  key("EnvelopeTriangles") << r.EnvelopeTriangles;
  key("CagePoints") << r.CagePoints;
  key("CageTriangles") << r.CageTriangles;
  key("ReadTime") << jsonNumber(r.ReadTime);
  key("ValidationTime") << jsonNumber(r.ValidationTime);
  key("DistanceFieldTime") << jsonNumber(r.DistanceFieldTime);
  key("IsosurfaceTime") << jsonNumber(r.IsosurfaceTime);
  key("VerificationTime") << jsonNumber(r.VerificationTime);
  key("SimplificationTime") << jsonNumber(r.SimplificationTime);
  key("CageVerificationTime") << jsonNumber(r.CageVerificationTime);
  key("OptimizationTime") << jsonNumber(r.OptimizationTime);
  key("EnergyBefore") << jsonNumber(r.EnergyBefore);
  key("EnergyAfter") << jsonNumber(r.EnergyAfter);
  key("TotalTime") << jsonNumber(r.TotalTime);
  key("WriteTime") << jsonNumber(r.WriteTime);
  key("MeasuredClearance") << jsonNumber(r.MeasuredClearance);
  key("MeasuredClearanceRelative") << jsonNumber(r.MeasuredClearanceRelative);
  key("EnclosureVerified") << (r.EnclosureVerified ? "true" : "false");
  key("RemovedPockets") << r.RemovedPockets;
  key("EnvelopeGenus") << r.EnvelopeGenus;
  key("EnvelopeComponents") << r.EnvelopeComponents;
  key("VerticesReached") << r.VerticesReached;
  key("TargetReached") << (r.TargetReached ? "true" : "false");
  key("StopReason") << jsonString(r.StopReason);
  key("VoxelSizeUsed") << jsonNumber(r.VoxelSizeUsed);
  key("InputWasFlipped") << (r.InputWasFlipped ? "true" : "false");
  key("NumberOfActivePoints") << r.NumberOfActivePoints;
  key("ActivePointTime") << jsonNumber(r.ActivePointTime);
  key("TopologyWarning") << jsonString(r.TopologyWarning);
  key("RequestedSignMode") << jsonString(r.Sign);
  for (const sdfcage::ResultField& f : r.InputResults)
  {
    if (f.Type == sdfcage::ResultField::Kind::Text)
      key(f.Name.c_str()) << jsonString(f.Text);
    else if (f.Type == sdfcage::ResultField::Kind::Real)
      key(f.Name.c_str()) << jsonNumber(f.Real);
    else
      key(f.Name.c_str()) << f.Integer;
  }
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
  os << "input       : " << (r.InputFile == "builtin" ? "built-in shape" : r.InputFile) << ", "
     << r.InputPoints << " points, " << r.InputTriangles << " triangles";
  if (r.InputCells != r.InputTriangles)
  {
    os << " (from " << r.InputCells << " polygons)";
  }
  if (r.InputWasFlipped)
  {
    os << ", inward-oriented (flipped)";
  }
  os << "\n";
  if (!r.FilterRan)
  {
    return;
  }
  auto field = [&](const char* name) -> const sdfcage::ResultField* {
    for (const sdfcage::ResultField& f : r.InputResults)
      if (f.Name == name)
        return &f;
    return nullptr;
  };
  auto count = [&](const char* name) { const auto* f = field(name); return f ? f->Integer : 0LL; };
  auto text = [&](const char* name) { const auto* f = field(name); return f ? f->Text : std::string(); };
  if (!r.InputResults.empty())
  {
    os << "repairs     : " << count("MergedPoints") << " points merged, " << count("TriangulatedPolygons")
       << " polygons triangulated, " << count("DroppedDegenerateTriangles") << " degenerate and "
       << count("DroppedDuplicateTriangles") << " duplicated triangles dropped\n";
    os << "inside rule : " << text("SignMode") << " (" << text("SignReason") << "); " << count("InputComponents")
       << " component(s), " << count("InputBoundaryEdges") << " boundary edges, " << count("InputNonManifoldEdges")
       << " non-manifold edges, " << count("InputNonManifoldVertices") << " non-manifold vertices";
    if (count("InputClosed"))
      os << ", genus " << count("InputGenus");
    os << "\n";
  }
  if (r.UseActivePoints && text("SignMode") != "flood" && !text("SignMode").empty())
  {
    os << "active pts  : skipped (they need a closed input and the flood-fill rule)\n";
  }
  else if (r.UseActivePoints)
  {
    os << "active pts  : " << r.NumberOfActivePoints << " input points (r " << number(r.ActiveRadius)
       << ", l " << number(r.GeodesicThreshold) << ", alpha " << number(r.AmplificationAlpha)
       << ", beta " << number(r.AmplificationBeta) << "), " << seconds(r.ActivePointTime) << "\n";
  }
  else
  {
    os << "active pts  : off (plain offset)\n";
  }
  os << "envelope    : " << r.EnvelopePoints << " points, " << r.EnvelopeTriangles
     << " triangles, " << r.EnvelopeComponents << " component(s), genus " << r.EnvelopeGenus
     << ", " << r.RemovedPockets << " trapped pocket(s) removed\n";
  os << "cage        : " << r.CagePoints << " points, " << r.CageTriangles << " triangles";
  if (r.TargetNumberOfVertices > 0)
  {
    os << (r.TargetReached ? " (target " : " (target NOT reached: ") << r.TargetNumberOfVertices
       << (r.TargetReached ? std::string(" reached")
            : r.StopReason.empty() ? std::string()
                                   : std::string("; ") + r.StopReason)
       << ")";
  }
  else
  {
    os << " (not simplified)";
  }
  if (!r.OutputFile.empty())
  {
    os << " -> " << r.OutputFile;
  }
  os << "\n";
  os << "voxel size  : " << number(r.VoxelSizeUsed) << " (relative: the input scaled into the "
     << "unit sphere), isovalue " << number(r.IsoValue) << ", adaptivity "
     << number(r.Adaptivity) << "\n";
  os << "timings     : validation " << seconds(r.ValidationTime) << ", distance field "
     << seconds(r.DistanceFieldTime) << ", active points " << seconds(r.ActivePointTime) << ", isosurface " << seconds(r.IsosurfaceTime)
     << ", verification " << seconds(r.VerificationTime) << ",\n              simplification "
     << seconds(r.SimplificationTime) << ", cage verification "
     << seconds(r.CageVerificationTime) << ", total " << seconds(r.TotalTime) << "\n";
  if (r.Optimize != "none")
  {
    os << "optimization: " << r.Optimize << " energy " << number(r.EnergyBefore) << " -> "
       << number(r.EnergyAfter) << ", " << r.NumberOfIterations << " iteration(s), "
       << seconds(r.OptimizationTime) << "\n";
  }
  os << "clearance   : " << number(r.MeasuredClearance) << " (input units) = "
     << number(r.MeasuredClearanceRelative) << " relative, required >= "
     << number(r.MinimumClearanceUsed) << " relative\n";
  os << "enclosure verified: " << (r.EnclosureVerified ? "yes" : "no") << "\n";
}

} // namespace sdfcage_cli
