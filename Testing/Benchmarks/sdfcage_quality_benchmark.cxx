// Benchmark of the cage quality judge (Core evaluateCage, the work of vtkCageQualityFilter):
//   sdfcage_quality_benchmark [INPUT CAGE] [--repeat N] [--vertices N]
// Reads INPUT and CAGE (.off .obj .ply) and times evaluateCage N times (default 3), printing
// the best and median wall time, the time per phase of the best run and the verdicts. Without
// files it uses SDFCAGE_DATA_DIR/armadillo_midsub4x.obj (346k faces) and first builds its cage
// with --vertices N (default 1000) vertices, as `sdfcage -n 1000` does (this takes a while).
#include "Pipeline/CageGenerator.h"
#include "Quality/CageQuality.h"
#include "MeshIO.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace sdfcage;
using sdfcage::exact::fanTriangulate;
using sdfcage::exact::readPolygonMesh;

namespace
{
bool load(const std::string& path, TriangleMesh& mesh)
{
  PolygonMesh polygons;
  std::string error;
  if (!readPolygonMesh(path, polygons, error))
  {
    std::fprintf(stderr, "cannot read %s: %s\n", path.c_str(), error.c_str());
    return false;
  }
  fanTriangulate(polygons, mesh);
  return true;
}
} // namespace

int main(int argc, char* argv[])
{
  std::vector<std::string> files;
  int repeat = 3, vertices = 1000;
  for (int i = 1; i < argc; ++i)
  {
    if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
    {
      repeat = std::max(1, std::atoi(argv[++i]));
    }
    else if (!std::strcmp(argv[i], "--vertices") && i + 1 < argc)
    {
      vertices = std::max(4, std::atoi(argv[++i]));
    }
    else if (argv[i][0] == '-')
    {
      std::printf("usage: sdfcage_quality_benchmark [INPUT CAGE] [--repeat N] [--vertices N]\n");
      return 2;
    }
    else
    {
      files.push_back(argv[i]);
    }
  }
  if (files.size() != 0 && files.size() != 2)
  {
    std::printf("usage: sdfcage_quality_benchmark [INPUT CAGE] [--repeat N] [--vertices N]\n");
    return 2;
  }
  TriangleMesh input, cage;
  if (files.empty())
  {
    const std::string path = std::string(SDFCAGE_DATA_DIR) + "/armadillo_midsub4x.obj";
    PolygonMesh polygons;
    std::string error;
    if (!readPolygonMesh(path, polygons, error))
    {
      std::printf("SKIPPED: cannot read %s (%s)\n", path.c_str(), error.c_str());
      return 0;
    }
    fanTriangulate(polygons, input);
    std::printf("building the %d-vertex cage of %s ...\n", vertices, path.c_str());
    std::fflush(stdout);
    CageOptions options;
    options.TargetNumberOfVertices = vertices;
    const CageResult made = generateCage(polygons, options);
    if (made.State != Status::Ok)
    {
      std::printf("cage generation failed: %s\n", made.Message.c_str());
      return 1;
    }
    cage = made.Cage;
    files = { path, "(generated)" };
  }
  else if (!load(files[0], input) || !load(files[1], cage))
  {
    return 2;
  }
  std::printf("input %s: %zu points, %zu triangles\ncage  %s: %zu points, %zu triangles\n", files[0].c_str(),
    input.Points.size(), input.Triangles.size(), files[1].c_str(), cage.Points.size(), cage.Triangles.size());

  std::vector<double> times;
  CageQualityResult best;
  for (int run = 0; run < repeat; ++run)
  {
    const auto start = std::chrono::steady_clock::now();
    CageQualityResult q = evaluateCage(input, cage);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    times.push_back(seconds);
    if (seconds <= *std::min_element(times.begin(), times.end()))
    {
      best = std::move(q);
    }
    std::printf("run %d: %.3f s\n", run + 1, seconds);
  }
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  std::printf(
    "evaluateCage: best %.3f s, median %.3f s over %d runs\n", sorted.front(), sorted[sorted.size() / 2], repeat);
  std::printf("phases of the best run:");
  for (int p = 0; p < 7; ++p)
  {
    std::printf(" %s %.3f s%s", CageQualityResult::PhaseNames[p], best.PhaseSeconds[p], p < 6 ? "," : "\n");
  }
  std::printf("encloses %s; clearance %.6g; Hausdorff cage->input %.6g (bound %.6g), input->cage %.6g (bound %.6g); "
              "mean %.6g; self-intersections %lld, input intersections %lld, input vertices outside %lld; genus cage "
              "%d input %d\n",
    best.Encloses ? "yes" : "NO", best.MinimumClearance, best.HausdorffCageToInput, best.HausdorffCageToInputBound,
    best.HausdorffInputToCage, best.HausdorffInputToCageBound, best.MeanDistanceCageToInput, best.SelfIntersections,
    best.InputIntersections, best.InputVerticesOutside, best.CageGenus, best.InputGenus);
  if (!best.Message.empty())
  {
    std::printf("message: %s\n", best.Message.c_str());
  }
  return 0;
}
