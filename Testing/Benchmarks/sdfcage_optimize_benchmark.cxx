// Optimization benchmark (paper §3.3): the time of one relocation pass + one flip pass on an
// N-vertex cage (default: 500 vertices of armadillo.obj from the data folder), for each energy,
// with the energies, angles, moves and flips. The cage is made by generateCage first (not timed).
//
//   sdfcage_optimize_benchmark [--builtin] [--vertices N] [--iterations K] [--energy mips|spacing]
//                              [--save-cage OUT.off] [--cage CAGE.off] [--threads N] [FILE]
// --save-cage writes the generated cage (input coordinates); --cage reuses one instead of
// generating it (it must enclose FILE).
#include "Pipeline/CageGenerator.h"
#include "MeshIO.h"
#include "Mesh/Normalization.h"
#include "Optimization/Optimization.h"
#include "Mesh/Shapes.h"
#include "Spatial/TriangleTree.h"
#include "Mesh/Validation.h"

#include <tbb/global_control.h>

#include <chrono>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

using namespace sdfcage;

int main(int argc, char** argv)
{
  std::string path = std::string(SDFCAGE_DATA_DIR) + "/armadillo.obj";
  bool builtin = false;
  int vertices = 500;
  int iterations = 1;
  std::string saveCage, loadCage, only;
  int threads = 0;
  for (int i = 1; i < argc; ++i)
  {
    if (!std::strcmp(argv[i], "--builtin"))
      builtin = true;
    else if (!std::strcmp(argv[i], "--vertices") && i + 1 < argc)
      vertices = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--iterations") && i + 1 < argc)
      iterations = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--save-cage") && i + 1 < argc)
      saveCage = argv[++i];
    else if (!std::strcmp(argv[i], "--cage") && i + 1 < argc)
      loadCage = argv[++i];
    else if (!std::strcmp(argv[i], "--energy") && i + 1 < argc)
      only = argv[++i];
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (argv[i][0] == '-')
    {
      std::printf("usage: sdfcage_optimize_benchmark [--builtin] [--vertices N] [--iterations K] [FILE]\n");
      return 2;
    }
    else
      path = argv[i];
  }
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  PolygonMesh polygons;
  if (builtin)
  {
    polygons = PolygonMesh::fromTriangles(makeBuiltinShape());
    path = "builtin";
  }
  else
  {
    std::string error;
    if (!exact::readPolygonMesh(path, polygons, error))
    {
      std::printf("SKIPPED: cannot read %s: %s\n", path.c_str(), error.c_str());
      return 0;
    }
  }
  TriangleMesh input;
  const MeshDefects defects = prepareMesh(polygons, input);
  if (!defects.usable())
  {
    std::printf("%s: unusable input: %s\n", path.c_str(), defects.errorMessage().c_str());
    return 1;
  }
  CageOptions co;
  co.TargetNumberOfVertices = vertices;
  const auto t0 = std::chrono::steady_clock::now();
  TriangleMesh cageMesh;
  if (!loadCage.empty())
  {
    PolygonMesh cp;
    std::string error;
    if (!exact::readPolygonMesh(loadCage, cp, error) || !prepareMesh(cp, cageMesh).usable())
    {
      std::printf("cannot use the cage %s %s\n", loadCage.c_str(), error.c_str());
      return 1;
    }
  }
  else
  {
    const CageResult cage = generateCage(PolygonMesh::fromTriangles(input), co);
    if (cage.State != Status::Ok)
    {
      std::printf("%s: cage generation failed: %s\n", path.c_str(), cage.Message.c_str());
      return 1;
    }
    cageMesh = cage.Cage;
    if (!saveCage.empty())
      exact::writeOFF(saveCage, cageMesh);
  }
  const double cageSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Normalization n = Normalization::fit(input);
  const TriangleMesh unitInput = n.toUnit(input);
  const TriangleMesh unitCage = n.toUnit(cageMesh);
  const TriangleTree tree(unitInput);
  std::printf("%s: %zu input triangles, cage %zu vertices / %zu triangles (generated in %.2f s)\n", path.c_str(),
    input.Triangles.size(), unitCage.Points.size(), unitCage.Triangles.size(), cageSeconds);
  std::printf("%-8s | %9s | %9s | %10s | %10s | %8s | %8s | %12s | %12s | %10s | %6s | %s\n", "energy", "reloc s",
    "flips s", "reloc+flip", "(cpu s)", "verify s", "total s", "E before", "E after", "min angle", "moves", "flips");
  int status = 0;
  for (CageEnergy energy : { CageEnergy::MIPS, CageEnergy::Spacing })
  {
    if (!only.empty() && only != (energy == CageEnergy::MIPS ? "mips" : "spacing"))
      continue;
    OptimizeOptions o;
    o.Energy = energy;
    o.NumberOfIterations = iterations;
    o.Clearance = co.Envelope.clearance();
    const OptimizeResult r = optimizeCage(unitCage, unitInput, tree, o);
    if (r.State != Status::Ok || r.Reverted)
    {
      std::printf("%-8s | failed: %s\n", energyName(energy), r.Message.c_str());
      status = 1;
      continue;
    }
    std::printf(
      "%-8s | %9.3f | %9.3f | %10.3f | %10.3f | %8.3f | %8.3f | %12.6g | %12.6g | %4.1f->%4.1f | %6lld | %lld\n",
      energyName(energy), r.RelocationSeconds, r.FlipSeconds, r.RelocationSeconds + r.FlipSeconds,
      r.RelocationAndFlipCpuSeconds, r.VerificationSeconds, r.Seconds, r.EnergyBefore, r.EnergyAfter,
      r.MinimumAngleBefore, r.MinimumAngleAfter, r.Moves, r.Flips);
    std::printf("%-8s   %lld relocation batches (mean %.1f vertices each)\n", "", r.Batches,
      double(unitCage.Points.size() * std::max(1, iterations)) / double(std::max(1LL, r.Batches)));
  }
  return status;
}
