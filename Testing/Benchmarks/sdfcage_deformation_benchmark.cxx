// Benchmark of cage-based deformation (Core CageDeformer, the work of vtkCageDeformationFilter):
//   sdfcage_deformation_benchmark [INPUT CAGE] [--repeat N] [--vertices N] [--threads N] [--kind mvc|green] [--single]
// Reads INPUT (the points to deform: every vertex) and CAGE (.off .obj .ply), or without files
// uses SDFCAGE_DATA_DIR/armadillo.obj and first builds its cage with --vertices N (default 500)
// vertices, as `sdfcage -n 500` does. For mean value and Green coordinates it times computing
// the weights (best and median of N runs, default 3) and applying a deformed cage (a bend; best
// and median of 20 applications), and prints the identity reproduction error and the weights'
// memory (--single: weights in single precision); for the weights also the processor time of all threads (on a busy machine, half of it
// is what 2 free cores would take). Figures, not a test: the targets (issue 15) are weights <= 2 s and apply <= 50 ms
// for armadillo (43k points) with a 500-vertex cage on 2 cores.
#include "Deformation/CageCoordinates.h"
#include "MeshIO.h"
#include "Pipeline/CageGenerator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

using namespace sdfcage;
using sdfcage::exact::fanTriangulate;
using sdfcage::exact::readPolygonMesh;

namespace
{
bool load(const std::string& path, PolygonMesh& polygons, TriangleMesh& mesh)
{
  std::string error;
  if (!readPolygonMesh(path, polygons, error))
  {
    std::fprintf(stderr, "cannot read %s: %s\n", path.c_str(), error.c_str());
    return false;
  }
  fanTriangulate(polygons, mesh);
  return true;
}

double seconds(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void summary(std::vector<double> t, double& best, double& median)
{
  std::sort(t.begin(), t.end());
  best = t.front();
  median = t[t.size() / 2];
}

int usage()
{
  std::printf("usage: sdfcage_deformation_benchmark [INPUT CAGE] [--repeat N] [--vertices N] [--threads N] [--kind mvc|green] [--single]\n");
  return 2;
}
} // namespace

int main(int argc, char* argv[])
{
  std::vector<std::string> files;
  int repeat = 3, vertices = 500, threads = 0;
  bool single = false;
  std::vector<CageCoordinateKind> kinds = { CageCoordinateKind::MeanValue, CageCoordinateKind::Green };
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
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
    {
      threads = std::atoi(argv[++i]);
    }
    else if (!std::strcmp(argv[i], "--single"))
    {
      single = true;
    }
    else if (!std::strcmp(argv[i], "--kind") && i + 1 < argc)
    {
      const std::string k = argv[++i];
      kinds = { k == "green" ? CageCoordinateKind::Green : CageCoordinateKind::MeanValue };
    }
    else if (argv[i][0] == '-')
    {
      return usage();
    }
    else
    {
      files.push_back(argv[i]);
    }
  }
  if (files.size() != 0 && files.size() != 2)
  {
    return usage();
  }
  PolygonMesh polygons, cagePolygons;
  TriangleMesh input, cage;
  if (files.empty())
  {
    const std::string path = std::string(SDFCAGE_DATA_DIR) + "/armadillo.obj";
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
  else if (!load(files[0], polygons, input) || !load(files[1], cagePolygons, cage))
  {
    return 2;
  }
  std::printf("points %s: %zu\ncage   %s: %zu points, %zu triangles\nthreads: %s\n", files[0].c_str(),
    input.Points.size(), files[1].c_str(), cage.Points.size(), cage.Triangles.size(),
    threads > 0 ? std::to_string(threads).c_str() : "all cores");

  // the deformed cage: the longest axis bent by a quarter turn around the middle one
  const auto box = bounds(cage);
  const Vec3 size = box[1] - box[0];
  int along = 0;
  for (int a = 1; a < 3; ++a)
  {
    if (size[a] > size[along])
    {
      along = a;
    }
  }
  const int across = (along + 1) % 3;
  const double radius = size[along] / (0.5 * M_PI);
  std::vector<Vec3> bent;
  for (const Vec3& p : cage.Points)
  {
    Vec3 q = p;
    const double t = (p[along] - box[0][along]) / radius;
    const double r = radius + (p[across] - box[0][across]);
    q[along] = box[0][along] + r * std::sin(t);
    q[across] = box[0][across] - radius + r * std::cos(t);
    bent.push_back(q);
  }

  for (CageCoordinateKind kind : kinds)
  {
    CageCoordinateOptions options;
    options.Kind = kind;
    options.NumberOfThreads = threads;
    options.SinglePrecision = single;
    std::vector<double> bindTimes, applyTimes, bindCpu;
    CageDeformer deformer;
    CageBindingResult result;
    for (int run = 0; run < repeat; ++run)
    {
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpuStart = std::clock();
      result = deformer.bind(cage, input.Points, options);
      bindTimes.push_back(seconds(start));
      bindCpu.push_back(static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC);
      if (result.State != Status::Ok)
      {
        std::printf("%s: binding failed: %s\n", cageCoordinateKindName(kind), result.Message.c_str());
        return 1;
      }
    }
    std::vector<Vec3> out;
    bool finite = true;
    for (int run = 0; run < 20; ++run)
    {
      const auto start = std::chrono::steady_clock::now();
      deformer.apply(bent, out, threads);
      applyTimes.push_back(seconds(start));
    }
    for (const Vec3& p : out)
    {
      finite = finite && p.allFinite();
    }
    double bindBest, bindMedian, applyBest, applyMedian, cpuBest, cpuMedian;
    summary(bindTimes, bindBest, bindMedian);
    summary(bindCpu, cpuBest, cpuMedian);
    summary(applyTimes, applyBest, applyMedian);
    std::printf("%-9s | weights best %.3f s, median %.3f s (%d runs; processor time best %.3f s) | apply best %.1f ms, median %.1f ms (20 runs) | "
                "%.0f MB | identity error %.2g of the cage diagonal | outside %lld, on cage %lld | bent output %s\n",
      cageCoordinateKindName(kind), bindBest, bindMedian, repeat, cpuBest, 1e3 * applyBest, 1e3 * applyMedian,
      result.WeightBytes / 1e6, result.ReproductionError, result.PointsOutside, result.PointsOnCage,
      finite ? "finite" : "NOT FINITE");
  }
  return 0;
}
