// SDFCage — CLI: see CLICheck.h.
#include "CLICheck.h"

#include "CLIMeshIO.h"
#include "CLIMessages.h"
#include "CLIReport.h"

#include "Quality/CageQuality.h"

#include <vtkCageQualityFilter.h>

#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

namespace sdfcage_cli
{

namespace
{

struct CheckReport
{
  std::string InputFile, CageFile;
  long long InputPoints = 0, InputTriangles = 0, CagePoints = 0, CageTriangles = 0;
  double ReadTime = 0.0;
  /// The judge's results (Core's qualityResults table, read back from the filter by name).
  sdfcage::ResultTable Results = sdfcage::qualityResults(sdfcage::CageQualityResult());
  std::string Status = "NotRun";
  std::string ErrorMessage;
  int ExitCode = 0;

  double number(const char* name) const
  {
    const sdfcage::ResultField* f = sdfcage::findResult(Results, name);
    return f ? f->number() : 0.0;
  }
  std::string text(const char* name) const
  {
    const sdfcage::ResultField* f = sdfcage::findResult(Results, name);
    return f ? f->Text : std::string();
  }
};

std::string toJson(const CheckReport& r)
{
  std::ostringstream o;
  o << "{\n"
    << "  \"Mode\": \"check\",\n"
    << "  \"InputFile\": " << jsonString(r.InputFile) << ",\n"
    << "  \"CageFile\": " << jsonString(r.CageFile) << ",\n"
    << "  \"InputPoints\": " << r.InputPoints << ",\n"
    << "  \"InputTriangles\": " << r.InputTriangles << ",\n"
    << "  \"CagePoints\": " << r.CagePoints << ",\n"
    << "  \"CageTriangles\": " << r.CageTriangles;
  bool first = false;
  writeJsonResults(o, r.Results, first);
  o << ",\n"
    << "  \"ReadTime\": " << jsonNumber(r.ReadTime) << ",\n"
    << "  \"Status\": " << jsonString(r.Status) << ",\n"
    << "  \"ErrorMessage\": " << jsonString(r.ErrorMessage) << ",\n"
    << "  \"ExitCode\": " << r.ExitCode << "\n"
    << "}\n";
  return o.str();
}

int finishCheck(CheckReport& r, const std::string& report, int code)
{
  r.ExitCode = code;
  if (report.empty())
  {
    return code;
  }
  std::ofstream out(report);
  out << toJson(r);
  out.close();
  if (!out)
  {
    std::cerr << "sdfcage: error: cannot write the report '" << report << "'\n";
    return code == 0 ? 3 : code;
  }
  return code;
}

std::string g(double v)
{
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}
} // namespace

int runCheck(const std::string& inputPath, const std::string& cagePath, const std::string& report, bool quiet,
  MessageCollector* messages)
{
  CheckReport r;
  r.InputFile = inputPath;
  r.CageFile = cagePath;
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  vtkSmartPointer<vtkPolyData> input = readMesh(inputPath, error);
  vtkSmartPointer<vtkPolyData> cage;
  if (input)
  {
    cage = readMesh(cagePath, error);
  }
  messages->clear();
  if (!input || !cage)
  {
    std::cerr << "sdfcage: error: " << error << "\n";
    r.Status = "UnreadableInput";
    r.ErrorMessage = error;
    return finishCheck(r, report, 2);
  }
  r.ReadTime = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.InputPoints = input->GetNumberOfPoints();
  r.InputTriangles = triangleCount(input);
  r.CagePoints = cage->GetNumberOfPoints();
  r.CageTriangles = triangleCount(cage);
  for (const auto& item : { std::make_pair(&r.InputTriangles, inputPath), std::make_pair(&r.CageTriangles, cagePath) })
  {
    if (*item.first == 0)
    {
      r.Status = "UnreadableInput";
      r.ErrorMessage = "'" + item.second + "' has no polygons: a surface mesh is needed";
      std::cerr << "sdfcage: error: " << r.ErrorMessage << "\n";
      return finishCheck(r, report, 2);
    }
  }

  vtkNew<vtkCageQualityFilter> quality;
  quality->SetInputData(cage);
  quality->SetSourceData(input);
  quality->Update();
  if (!messages->errors().empty())
  {
    r.Status = "Failed";
    r.ErrorMessage = messages->errors().front();
    std::cerr << "sdfcage: error: " << r.ErrorMessage << "\n";
    messages->clear();
    return finishCheck(r, report, 3);
  }
  messages->clear();
  r.Status = "Ok";
  for (sdfcage::ResultField& f : r.Results)
  {
    if (f.Type == sdfcage::ResultField::Kind::Text)
      f.Text = quality->GetResultText(f.Name.c_str());
    else
      f.setNumber(quality->GetResultNumber(f.Name.c_str()));
  }

  const bool encloses = r.number("Encloses") != 0;
  if (!quiet)
  {
    auto genus = [](double v) {
      return v < 0 ? std::string("n/a (not a closed 2-manifold)") : std::to_string(static_cast<int>(v));
    };
    auto count = [&](const char* name) { return static_cast<long long>(r.number(name)); };
    std::cout << "input       : " << inputPath << ", " << r.InputPoints << " points, " << r.InputTriangles
              << " triangles, genus " << genus(r.number("InputGenus")) << "\n"
              << "cage        : " << cagePath << ", " << r.CagePoints << " points, " << r.CageTriangles
              << " triangles, genus " << genus(r.number("CageGenus")) << "\n"
              << "clearance   : " << g(r.number("MinimumClearance"))
              << " (input units) = " << g(r.number("MinimumClearanceRelative")) << " of the input's diagonal\n"
              << "Hausdorff   : cage->input " << g(r.number("HausdorffCageToInput")) << " ("
              << g(r.number("HausdorffCageToInputRelative")) << " rel.), input->cage "
              << g(r.number("HausdorffInputToCage")) << " (" << g(r.number("HausdorffInputToCageRelative"))
              << " rel.)\n"
              << "mean dist.  : cage->input " << g(r.number("MeanDistanceCageToInput")) << " ("
              << g(r.number("MeanDistanceCageToInputRelative")) << " rel.)\n"
              << "counts      : " << count("SelfIntersections") << " self-intersecting pairs, "
              << count("InputIntersections") << " cage/input intersecting pairs, " << count("InputVerticesOutside")
              << " input vertices outside\n"
              << "time        : " << g(r.number("QualityTime")) << " s\n"
              << "encloses    : " << (encloses ? std::string("yes") : "NO: " + r.text("QualityMessage")) << "\n";
  }
  return finishCheck(r, report, encloses ? 0 : 1);
}

} // namespace sdfcage_cli
