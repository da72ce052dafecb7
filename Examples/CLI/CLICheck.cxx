// SDFCage — CLI: see CLICheck.h.
#include "CLICheck.h"

#include "CLIMeshIO.h"
#include "CLIMessages.h"
#include "CLIReport.h"

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
  bool Judged = false;
  bool Encloses = false;
  double MinimumClearance = 0, MinimumClearanceRelative = 0;
  double HausdorffCageToInput = 0, HausdorffCageToInputRelative = 0, HausdorffCageToInputBound = 0;
  double HausdorffInputToCage = 0, HausdorffInputToCageRelative = 0, HausdorffInputToCageBound = 0;
  double MeanDistanceCageToInput = 0, MeanDistanceCageToInputRelative = 0;
  long long SelfIntersections = 0, InputIntersections = 0, InputVerticesOutside = 0;
  int CageGenus = -1, InputGenus = -1;
  double QualityTime = 0.0;
  std::string QualityMessage;
  std::string Status = "NotRun";
  std::string ErrorMessage;
  int ExitCode = 0;
};

std::string toJson(const CheckReport& r)
{
  std::ostringstream o;
  auto b = [](bool v) { return v ? "true" : "false"; };
  o << "{\n"
    << "  \"Mode\": \"check\",\n"
    << "  \"InputFile\": " << jsonString(r.InputFile) << ",\n"
    << "  \"CageFile\": " << jsonString(r.CageFile) << ",\n"
    << "  \"InputPoints\": " << r.InputPoints << ",\n"
    << "  \"InputTriangles\": " << r.InputTriangles << ",\n"
    << "  \"CagePoints\": " << r.CagePoints << ",\n"
    << "  \"CageTriangles\": " << r.CageTriangles << ",\n"
    << "  \"Encloses\": " << b(r.Encloses) << ",\n"
    << "  \"MinimumClearance\": " << jsonNumber(r.MinimumClearance) << ",\n"
    << "  \"MinimumClearanceRelative\": " << jsonNumber(r.MinimumClearanceRelative) << ",\n"
    << "  \"HausdorffCageToInput\": " << jsonNumber(r.HausdorffCageToInput) << ",\n"
    << "  \"HausdorffCageToInputRelative\": " << jsonNumber(r.HausdorffCageToInputRelative) << ",\n"
    << "  \"HausdorffCageToInputBound\": " << jsonNumber(r.HausdorffCageToInputBound) << ",\n"
    << "  \"HausdorffInputToCage\": " << jsonNumber(r.HausdorffInputToCage) << ",\n"
    << "  \"HausdorffInputToCageRelative\": " << jsonNumber(r.HausdorffInputToCageRelative) << ",\n"
    << "  \"HausdorffInputToCageBound\": " << jsonNumber(r.HausdorffInputToCageBound) << ",\n"
    << "  \"MeanDistanceCageToInput\": " << jsonNumber(r.MeanDistanceCageToInput) << ",\n"
    << "  \"MeanDistanceCageToInputRelative\": " << jsonNumber(r.MeanDistanceCageToInputRelative) << ",\n"
    << "  \"SelfIntersections\": " << r.SelfIntersections << ",\n"
    << "  \"InputIntersections\": " << r.InputIntersections << ",\n"
    << "  \"InputVerticesOutside\": " << r.InputVerticesOutside << ",\n"
    << "  \"CageGenus\": " << r.CageGenus << ",\n"
    << "  \"InputGenus\": " << r.InputGenus << ",\n"
    << "  \"QualityMessage\": " << jsonString(r.QualityMessage) << ",\n"
    << "  \"ReadTime\": " << jsonNumber(r.ReadTime) << ",\n"
    << "  \"QualityTime\": " << jsonNumber(r.QualityTime) << ",\n"
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
  r.Judged = true;
  r.Status = "Ok";
  r.Encloses = quality->GetEncloses();
  r.MinimumClearance = quality->GetMinimumClearance();
  r.MinimumClearanceRelative = quality->GetMinimumClearanceRelative();
  r.HausdorffCageToInput = quality->GetHausdorffCageToInput();
  r.HausdorffCageToInputRelative = quality->GetHausdorffCageToInputRelative();
  r.HausdorffCageToInputBound = quality->GetHausdorffCageToInputBound();
  r.HausdorffInputToCage = quality->GetHausdorffInputToCage();
  r.HausdorffInputToCageRelative = quality->GetHausdorffInputToCageRelative();
  r.HausdorffInputToCageBound = quality->GetHausdorffInputToCageBound();
  r.MeanDistanceCageToInput = quality->GetMeanDistanceCageToInput();
  r.MeanDistanceCageToInputRelative = quality->GetMeanDistanceCageToInputRelative();
  r.SelfIntersections = quality->GetSelfIntersections();
  r.InputIntersections = quality->GetInputIntersections();
  r.InputVerticesOutside = quality->GetInputVerticesOutside();
  r.CageGenus = quality->GetCageGenus();
  r.InputGenus = quality->GetInputGenus();
  r.QualityTime = quality->GetQualityTime();
  r.QualityMessage = quality->GetQualityMessage();

  if (!quiet)
  {
    auto genus = [](int v) { return v < 0 ? std::string("n/a (not a closed 2-manifold)") : std::to_string(v); };
    std::cout << "input       : " << inputPath << ", " << r.InputPoints << " points, " << r.InputTriangles
              << " triangles, genus " << genus(r.InputGenus) << "\n"
              << "cage        : " << cagePath << ", " << r.CagePoints << " points, " << r.CageTriangles
              << " triangles, genus " << genus(r.CageGenus) << "\n"
              << "clearance   : " << g(r.MinimumClearance) << " (input units) = " << g(r.MinimumClearanceRelative)
              << " of the input's diagonal\n"
              << "Hausdorff   : cage->input " << g(r.HausdorffCageToInput) << " (" << g(r.HausdorffCageToInputRelative)
              << " rel.), input->cage " << g(r.HausdorffInputToCage) << " (" << g(r.HausdorffInputToCageRelative)
              << " rel.)\n"
              << "mean dist.  : cage->input " << g(r.MeanDistanceCageToInput) << " ("
              << g(r.MeanDistanceCageToInputRelative) << " rel.)\n"
              << "counts      : " << r.SelfIntersections << " self-intersecting pairs, " << r.InputIntersections
              << " cage/input intersecting pairs, " << r.InputVerticesOutside << " input vertices outside\n"
              << "time        : " << g(r.QualityTime) << " s\n"
              << "encloses    : " << (r.Encloses ? std::string("yes") : "NO: " + r.QualityMessage) << "\n";
  }
  return finishCheck(r, report, r.Encloses ? 0 : 1);
}

} // namespace sdfcage_cli
