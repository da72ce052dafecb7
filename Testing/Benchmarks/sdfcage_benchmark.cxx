// Envelope-stage benchmark: per mesh, faces, time per stage, peak memory, envelope size,
// clearance and verdict. Each mesh runs in its own process so that peak memory is per mesh.
#include "Pipeline/CageGenerator.h"
#include "MeshIO.h"
#include "Mesh/Validation.h"
#include "Mesh/Shapes.h"
#include "Spatial/TriangleTree.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace sdfcage;

namespace
{

void usage()
{
  std::printf("usage: sdfcage_benchmark [--builtin] [--vertices N] [--iso C] [--voxel H] [--adaptivity A] "
              "[--no-active-points] [--active-radius R] "
              "[--threads N] [FILE|FOLDER ...]\n"
              "  default: every mesh of %s\n",
    SDFCAGE_DATA_DIR);
}

/// One-sided Hausdorff distance cage -> input, sampled: every cage triangle on a barycentric grid
/// with spacing about `step` (plus its corners), exact point-to-mesh distances.
double hausdorffCageToInput(const TriangleMesh& cage, const TriangleTree& input, double step)
{
  double worst = 0.0;
  for (const Triangle& t : cage.Triangles)
  {
    const Vec3 a = cage.Points[t[0]], b = cage.Points[t[1]], c = cage.Points[t[2]];
    const double longest = std::max({ (b - a).norm(), (c - b).norm(), (a - c).norm() });
    const int n = std::max(1, std::min(64, static_cast<int>(std::ceil(longest / step))));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
      {
        const double u = double(i) / n, v = double(j) / n;
        worst = std::max(worst, input.distance(a + u * (b - a) + v * (c - a)));
      }
  }
  return worst;
}

int runOne(const std::string& name, const std::string& path, const CageOptions& options)
{
  PolygonMesh input;
  double readSeconds = 0.0;
  if (path.empty())
  {
    input = PolygonMesh::fromTriangles(makeBuiltinShape());
  }
  else
  {
    std::string error;
    const auto t0 = std::chrono::steady_clock::now();
    if (!exact::readPolygonMesh(path, input, error))
    {
      std::printf("| %-24s | cannot read: %s |\n", name.c_str(), error.c_str());
      return 2;
    }
    readSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const CageResult r = generateCage(input, options);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double peakMB = ru.ru_maxrss / 1024.0;
  const double envelopeStage =
    r.ValidationSeconds + r.ActivePointSeconds + r.DistanceFieldSeconds + r.IsosurfaceSeconds + r.VerificationSeconds;
  if (r.State == Status::Ok)
  {
    // Hausdorff relative to the input's bounding-box diagonal, measured in input units
    TriangleMesh in;
    prepareMesh(input, in);
    const auto box = bounds(in);
    const double diagonal = (box[1] - box[0]).norm();
    const TriangleTree tree(in);
    const double hausdorff = r.Cage.empty() ? 0.0 : hausdorffCageToInput(r.Cage, tree, diagonal / 500.0) / diagonal;
    std::printf("| %-24s | %8zu | %5.2f | %6.3f | %zu (%zu) | %6.3f | %6.3f | %6.3f | %6.3f | **%6.3f** | %8zu | %6.3f "
                "| %6.3f | **%6.3f** | %5d | %7.5f | %7.5f | %d→%d→%d | %d | %7.0f | %s |\n",
      name.c_str(), input.numberOfCells(), readSeconds, r.ValidationSeconds, r.NumberOfActivePoints,
      r.NumberOfActiveSamples, r.ActivePointSeconds + r.AmplificationSeconds,
      r.DistanceFieldSeconds - r.AmplificationSeconds, r.IsosurfaceSeconds, r.VerificationSeconds, envelopeStage,
      r.Envelope.Triangles.size(), r.SimplificationSeconds, r.CageVerificationSeconds, r.TotalSeconds,
      r.VerticesReached, r.MinimumClearanceRelative, hausdorff, r.Defects.Genus, r.EnvelopeGenus, genus(r.Cage),
      r.RemovedPockets, peakMB, r.EnclosureVerified ? (r.TargetReached ? "yes" : "yes (target not reached)") : "NO");
  }
  else
  {
    std::string msg = r.Message.substr(0, 90);
    std::printf("| %-24s | %8zu | %5.2f | %6.3f | — | — | — | — | — | %6.3f | — | — | — | %6.3f | — | — | — | — | — | "
                "%7.0f | %s: %s |\n",
      name.c_str(), input.numberOfCells(), readSeconds, r.ValidationSeconds, envelopeStage, r.TotalSeconds, peakMB,
      statusName(r.State), msg.c_str());
  }
  std::fflush(stdout);
  return r.State == Status::Ok && r.EnclosureVerified ? 0 : 1;
}

} // namespace

int main(int argc, char** argv)
{
  CageOptions options;
  std::vector<std::pair<std::string, std::string>> meshes; // name, path ("" = built-in)
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&](double& v) {
      if (i + 1 >= argc)
      {
        usage();
        std::exit(2);
      }
      v = std::atof(argv[++i]);
    };
    if (a == "--builtin")
      meshes.emplace_back("builtin", "");
    else if (a == "--iso")
      value(options.Envelope.IsoValue);
    else if (a == "--voxel")
      value(options.Envelope.VoxelSize);
    else if (a == "--vertices" || a == "-n")
    {
      double t = 0;
      value(t);
      options.TargetNumberOfVertices = static_cast<int>(t);
    }
    else if (a == "--adaptivity")
      value(options.Envelope.Adaptivity);
    else if (a == "--no-active-points")
      options.Envelope.UseActivePoints = false;
    else if (a == "--active-radius")
      value(options.Envelope.ActivePoints.Radius);
    else if (a == "--threads")
    {
      double t = 0;
      value(t);
      options.NumberOfThreads = static_cast<int>(t);
    }
    else if (a == "-h" || a == "--help")
    {
      usage();
      return 0;
    }
    else
      inputs.push_back(a);
  }
  if (meshes.empty() && inputs.empty())
  {
    inputs.push_back(SDFCAGE_DATA_DIR);
  }
  for (const std::string& in : inputs)
  {
    std::error_code ec;
    if (fs::is_directory(in, ec))
    {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(in))
      {
        const std::string ext = e.path().extension().string();
        if (ext == ".off" || ext == ".obj" || ext == ".ply")
          files.push_back(e.path());
      }
      std::sort(files.begin(), files.end(),
        [](const fs::path& x, const fs::path& y) { return fs::file_size(x) < fs::file_size(y); });
      for (const auto& f : files)
        meshes.emplace_back(f.filename().string(), f.string());
    }
    else if (fs::exists(in, ec))
      meshes.emplace_back(fs::path(in).filename().string(), in);
    else
    {
      std::fprintf(stderr, "sdfcage_benchmark: no such file or folder: %s\n", in.c_str());
      return 2;
    }
  }
  std::printf(
    "c = %g, voxel = %g, adaptivity = %g, active points %s (r %g), target vertices = %d, threads = %d (0 = all)\n\n",
    options.Envelope.IsoValue, options.Envelope.voxelSize(), options.Envelope.Adaptivity,
    options.Envelope.UseActivePoints ? "on" : "off", options.Envelope.ActivePoints.Radius,
    options.TargetNumberOfVertices, options.NumberOfThreads);
  std::printf("| mesh | faces | read s | validate s | active pts (samples) | active + φξ s | SDF s | isosurface s | "
              "verify s | envelope stage s | "
              "envelope tris | simplify s | cage verify s | total s | cage verts | clearance (unit) | "
              "Hausdorff cage→input (/diag) | genus in→env→cage | pockets | peak MB | verified |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  int failures = 0;
  for (const auto& m : meshes)
  {
    const pid_t pid = fork();
    if (pid == 0)
    {
      std::_Exit(runOne(m.first, m.second, options));
    }
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status))
    {
      std::printf("| %-24s | crashed (signal %d) |\n", m.first.c_str(), WIFSIGNALED(status) ? WTERMSIG(status) : 0);
      ++failures;
    }
    else if (WEXITSTATUS(status) == 2)
      ++failures;
  }
  return failures ? 1 : 0;
}
