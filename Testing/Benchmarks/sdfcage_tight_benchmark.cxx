// Tight-optimization benchmark (issue 15 part 3): for every closed mesh of the data folder (or
// the given files) at N vertices (default 500), the plain cage against the cage optimized at the
// defaults with --optimize mips, and the spacing energy at h = 0.03 and 0.05. Per mesh it prints
// the smallest angle, the fraction of angles below 15 degrees, the one-sided Hausdorff distance
// cage -> input before and after (certified by the quality judge, evaluateCage, relative to the
// input's bounding-box diagonal), the optimization time, whether the result encloses, and for
// the spacing energy the fraction of the cage's area whose distance to the input lies within
// h +- 20% (h in unit-sphere units, as --spacing), with the rest split into closer and farther
// (the optimizer's own SpacingCloserAfter / SpacingFartherAfter) on a line below.
//
//   sdfcage_tight_benchmark [--vertices N] [--cages DIR] [--no-spacing] [--no-mips] [--sweeps K]
//                           [--spacing-rounds K] [--threads N] [--verbose] [FILES...]
// --cages DIR: reuse DIR/<stem>_<N>.off as the plain cage when it exists, else generate it
// (generateCage at the defaults) and write it there; the generation is not timed. --no-mips and
// --no-spacing skip a part; --sweeps K sets MaximumSweeps of the MIPS run, --spacing-rounds K
// NumberOfIterations of the spacing runs (defaults otherwise); --verbose adds the MIPS counters.
#include "Mesh/Normalization.h"
#include "Mesh/Validation.h"
#include "MeshIO.h"
#include "Optimization/Optimization.h"
#include "Pipeline/CageGenerator.h"
#include "Quality/CageQuality.h"
#include "SpacingBand.h"
#include "Spatial/TriangleTree.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <vector>

using namespace sdfcage;

namespace
{

bool exists(const std::string& p)
{
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

std::string stem(const std::string& path)
{
  std::string b = path.substr(path.find_last_of('/') + 1);
  return b.substr(0, b.find_last_of('.'));
}

/// Fraction of angles below `angle` degrees.
double smallAngles(const TriangleMesh& m, double angle)
{
  long long n = 0;
  for (const Triangle& t : m.Triangles)
    for (int k = 0; k < 3; ++k)
    {
      const Vec3 u = m.Points[t[(k + 1) % 3]] - m.Points[t[k]];
      const Vec3 w = m.Points[t[(k + 2) % 3]] - m.Points[t[k]];
      n += std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / M_PI < angle;
    }
  return m.Triangles.empty() ? 0.0 : double(n) / double(3 * m.Triangles.size());
}

} // namespace

int main(int argc, char** argv)
{
  int vertices = 500;
  int threads = 0;
  bool spacing = true;
  bool verbose = false;
  bool mips = true;
  int spacingRounds = -1; // < 0: the default
  int sweeps = -1;        // < 0: the default
  std::string cages;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i)
  {
    if (!std::strcmp(argv[i], "--vertices") && i + 1 < argc)
      vertices = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--cages") && i + 1 < argc)
      cages = argv[++i];
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--spacing-rounds") && i + 1 < argc)
      spacingRounds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--sweeps") && i + 1 < argc)
      sweeps = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-mips"))
      mips = false;
    else if (!std::strcmp(argv[i], "--verbose"))
      verbose = true;
    else if (!std::strcmp(argv[i], "--no-spacing"))
      spacing = false;
    else if (argv[i][0] == '-')
    {
      std::printf("usage: sdfcage_tight_benchmark [--vertices N] [--cages DIR] [--no-spacing] [--no-mips] "
                  "[--sweeps K] [--spacing-rounds K] [--threads N] [--verbose] [FILES...]\n");
      return 2;
    }
    else
      files.push_back(argv[i]);
  }
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  if (files.empty())
  {
    const std::string dir = SDFCAGE_DATA_DIR;
    if (DIR* d = opendir(dir.c_str()))
    {
      while (dirent* e = readdir(d))
      {
        const std::string name = e->d_name;
        const auto dot = name.find_last_of('.');
        if (dot == std::string::npos)
          continue;
        const std::string ext = name.substr(dot + 1);
        if (ext == "off" || ext == "obj" || ext == "ply" || ext == "stl")
          files.push_back(dir + "/" + name);
      }
      closedir(d);
    }
    std::sort(files.begin(), files.end());
    if (files.empty())
    {
      std::printf("SKIPPED: no meshes in %s\n", dir.c_str());
      return 0;
    }
  }
  std::printf("N = %d; H = one-sided Hausdorff cage->input / bbox diagonal (certified); band = area "
              "fraction within h +- 20%%\n",
    vertices);
  std::printf("%-22s | %-16s | %-13s | %-21s | %6s | %6s | %-8s | %-14s | %-14s\n", "mesh", "min angle",
    "% < 15 deg", "H plain -> mips", "ratio", "mips s", "encloses", "band h=0.03", "band h=0.05");
  int status = 0;
  for (const std::string& path : files)
  {
    PolygonMesh polygons;
    std::string error;
    if (!exact::readPolygonMesh(path, polygons, error))
    {
      std::printf("%-22s | cannot read: %s\n", stem(path).c_str(), error.c_str());
      continue;
    }
    TriangleMesh input;
    const MeshDefects defects = prepareMesh(polygons, input);
    // closed meshes only (an inward one is flipped): a file that needed repairs (split seams,
    // degenerate or duplicate faces: a raw scan) is not one
    if (!defects.usable() || defects.Components > 1 || defects.MergedPoints > 0 ||
      defects.DroppedDegenerateTriangles > 0 || defects.DroppedDuplicateTriangles > 0 || defects.TriangulatedPolygons > 0)
    {
      std::printf("%-22s | skipped: not a clean closed mesh\n", stem(path).c_str());
      continue;
    }
    TriangleMesh cage;
    const std::string cached = cages.empty() ? std::string() : cages + "/" + stem(path) + "_" +
        std::to_string(vertices) + ".off";
    if (!cached.empty() && exists(cached))
    {
      PolygonMesh cp;
      if (!exact::readPolygonMesh(cached, cp, error) || !prepareMesh(cp, cage).usable())
      {
        std::printf("%-22s | cannot use the cage %s %s\n", stem(path).c_str(), cached.c_str(), error.c_str());
        status = 1;
        continue;
      }
    }
    else
    {
      CageOptions co;
      co.TargetNumberOfVertices = vertices;
      const CageResult c = generateCage(PolygonMesh::fromTriangles(input), co);
      if (c.State != Status::Ok)
      {
        std::printf("%-22s | cage generation failed: %s\n", stem(path).c_str(), c.Message.c_str());
        status = 1;
        continue;
      }
      cage = c.Cage;
      if (!cached.empty())
        exact::writeOFF(cached, cage);
    }
    const Normalization nz = Normalization::fit(input);
    const TriangleMesh unitInput = nz.toUnit(input);
    const TriangleMesh unitCage = nz.toUnit(cage);
    const TriangleTree tree(unitInput);

    OptimizeOptions o; // the defaults of --optimize mips
    o.NumberOfIterations = mips ? o.NumberOfIterations : 0;
    if (sweeps > 0)
      o.MaximumSweeps = sweeps;
    const OptimizeResult r = optimizeCage(unitCage, unitInput, tree, o);
    const CageQualityResult q0 = evaluateCage(unitInput, unitCage);
    const CageQualityResult q1 = evaluateCage(unitInput, r.Cage);
    const double h0 = q0.HausdorffCageToInputBound / q0.Diagonal, h1 = q1.HausdorffCageToInputBound / q1.Diagonal;
    const bool ok = r.State == Status::Ok && !r.Reverted && q1.Encloses;
    if (!ok)
      status = 1;
    char angles[64], small[64], hd[64], band[2][64], split[2][96];
    std::snprintf(angles, sizeof angles, "%5.2f -> %5.2f", minimumAngle(unitCage), minimumAngle(r.Cage));
    std::snprintf(small, sizeof small, "%4.1f -> %4.1f", 100 * smallAngles(unitCage, 15), 100 * smallAngles(r.Cage, 15));
    std::snprintf(hd, sizeof hd, "%.4f -> %.4f", h0, h1);
    for (int k = 0; k < 2; ++k)
    {
      std::snprintf(band[k], sizeof band[k], "-");
      split[k][0] = '\0';
      if (!spacing)
        continue;
      const double h = k == 0 ? 0.03 : 0.05;
      OptimizeOptions so;
      so.Energy = CageEnergy::Spacing;
      so.TargetSpacing = h;
      if (spacingRounds >= 0)
        so.NumberOfIterations = spacingRounds;
      const OptimizeResult s = optimizeCage(unitCage, unitInput, tree, so);
      if (s.State != Status::Ok || s.Reverted)
      {
        std::snprintf(band[k], sizeof band[k], "failed");
        status = 1;
        continue;
      }
      std::snprintf(band[k], sizeof band[k], "%4.1f%% -> %4.1f%%", 100 * bandFraction(unitCage, tree, 0.8 * h, 1.2 * h),
        100 * bandFraction(s.Cage, tree, 0.8 * h, 1.2 * h));
      std::snprintf(split[k], sizeof split[k], "h=%.2f: closer than 0.8h %.1f%%, farther than 1.2h %.1f%%", h,
        100 * s.SpacingCloserAfter, 100 * s.SpacingFartherAfter);
    }
    std::printf("%-22s | %-16s | %-13s | %-21s | %6.2f | %6.1f | %-8s | %-14s | %-14s\n", stem(path).c_str(), angles,
      small, hd, h0 > 0 ? h1 / h0 : 0.0, r.Seconds, ok ? "yes" : "NO", band[0], band[1]);
    if (spacing)
      std::printf("    spacing, the rest of the area: %s; %s\n", split[0], split[1]);
    if (verbose)
      std::printf("    mips: %d sweeps, moves %lld (rejected %lld: energy %lld, collision %lld, shape %lld, self %lld, "
                  "fidelity %lld), flips %lld (vetoed %lld), collapses+splits %lld (vetoed %lld), angle moves %lld, "
                  "sampled H %.5f -> "
                  "%.5f (budget %.5f, unit sphere); seconds: relocation %.2f, flips+repair %.2f, verification %.2f\n",
        r.Sweeps, r.Moves, r.RejectedMoves, r.MovesWithoutDescent, r.MovesCutByCollision, r.MovesVetoedByShape,
        r.MovesVetoedBySelfIntersection, r.MovesVetoedByFidelity, r.Flips, r.RejectedFlips, r.Collapses,
        r.RejectedCollapses, r.AngleMoves, r.HausdorffBefore, r.HausdorffAfter, r.HausdorffBudget, r.RelocationSeconds,
        r.FlipSeconds, r.VerificationSeconds);
    std::fflush(stdout);
  }
  return status;
}
