// Envelope-stage benchmark: per mesh, faces, time per stage, peak memory, envelope size,
// clearance and verdict. Each mesh runs in its own process so that peak memory is per mesh.
#include "CageGenerator.h"
#include "MeshIO.h"
#include "Shapes.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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
  std::printf("usage: sdfcage_benchmark [--builtin] [--iso C] [--voxel H] [--adaptivity A] "
              "[--threads N] [FILE|FOLDER ...]\n"
              "  default: every mesh of %s\n",
    SDFCAGE_DATA_DIR);
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
    if (!readPolygonMesh(path, input, error))
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
  const double envelopeStage = r.ValidationSeconds + r.DistanceFieldSeconds + r.IsosurfaceSeconds + r.VerificationSeconds;
  if (r.State == Status::Ok)
  {
    std::printf("| %-24s | %8zu | %5.2f | %6.3f | %6.3f | %6.3f | %6.3f | %6.3f | %8zu | %7.5f | %d→%d | %d | %7.0f | %s |\n",
      name.c_str(), input.numberOfCells(), readSeconds, r.ValidationSeconds, r.DistanceFieldSeconds,
      r.IsosurfaceSeconds, r.VerificationSeconds, envelopeStage, r.Envelope.Triangles.size(),
      r.MinimumClearanceRelative, r.Defects.Genus, r.EnvelopeGenus, r.RemovedPockets, peakMB,
      r.EnclosureVerified ? "yes" : "NO");
  }
  else
  {
    std::string msg = r.Message.substr(0, 90);
    std::printf("| %-24s | %8zu | %5.2f | %6.3f | — | — | — | %6.3f | — | — | — | — | %7.0f | %s: %s |\n",
      name.c_str(), input.numberOfCells(), readSeconds, r.ValidationSeconds, envelopeStage, peakMB,
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
    else if (a == "--adaptivity")
      value(options.Envelope.Adaptivity);
    else if (a == "--threads")
    {
      double t = 0;
      value(t);
      options.Envelope.NumberOfThreads = static_cast<int>(t);
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
      std::sort(files.begin(), files.end(), [](const fs::path& x, const fs::path& y) {
        return fs::file_size(x) < fs::file_size(y);
      });
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
  std::printf("c = %g, voxel = %g, adaptivity = %g, threads = %d (0 = all)\n\n", options.Envelope.IsoValue,
    options.Envelope.voxelSize(), options.Envelope.Adaptivity, options.Envelope.NumberOfThreads);
  std::printf("| mesh | faces | read s | validate s | SDF s | isosurface s | verify s | envelope stage s | "
              "envelope tris | clearance (unit) | genus in→env | pockets | peak MB | verified |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
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
