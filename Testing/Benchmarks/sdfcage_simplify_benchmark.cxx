// SDFCage — benchmark of the constrained simplification alone (paper §3.2): builds the verified
// envelope of each mesh once, then simplifies it to N vertices `--repeat` times and prints the
// best time, the time per collapse and the simplifier's statistics. Repeating on one envelope
// makes before/after comparisons on a shared, noisy machine meaningful (take the best).
//
//   sdfcage_simplify_benchmark [--vertices N] [--repeat K] [--builtin] [MESH ...]
//   (default: armadillo.obj, octopus-low_surface.obj and anchor.off of SDFCAGE_DATA_DIR, N = 500,
//   K = 3)
#include "Pipeline/CageGenerator.h"
#include "Envelope/Envelope.h"
#include "MeshIO.h"
#include "Mesh/Shapes.h"
#include "Simplification/Simplification.h"
#include "Spatial/TriangleTree.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

using namespace sdfcage;

namespace
{

int run(const std::string& name, const PolygonMesh& polygons, int vertices, int repeat)
{
  // the pipeline's own envelope (validated, normalized input): generateCage without simplifying
  CageOptions options;
  options.TargetNumberOfVertices = 0;
  const CageResult full = generateCage(polygons, options);
  if (full.State != Status::Ok)
  {
    std::printf("%-28s %s: %s\n", name.c_str(), statusName(full.State), full.Message.c_str());
    return 1;
  }
  TriangleMesh input;
  if (!exact::fanTriangulate(polygons, input))
  {
    std::printf("%-28s cannot triangulate\n", name.c_str());
    return 1;
  }
  const Normalization& n = full.Normalize;
  const TriangleMesh unit = n.toUnit(input);
  const TriangleMesh envelope = n.toUnit(full.Envelope);
  const TriangleTree tree(unit);
  SimplifyOptions so = options.Simplify;
  so.TargetNumberOfVertices = vertices;
  so.Clearance = options.Envelope.clearance();
  double best = 1e300;
  SimplifyResult r;
  for (int i = 0; i < repeat; ++i)
  {
    r = simplifyEnvelope(envelope, tree, so);
    best = std::min(best, r.Seconds);
  }
  std::printf("%-28s envelope %7zu triangles -> %5d vertices (target %d%s): best of %d %.3f s, "
              "%.1f us/collapse; collapses %lld, rejected input %lld self %lld topology %lld shape "
              "%lld, relocated %lld\n",
    name.c_str(), envelope.Triangles.size(), r.VerticesReached, vertices, r.TargetReached ? "" : ", not reached",
    repeat, best, 1e6 * best / std::max(1LL, r.Collapses), r.Collapses, r.RejectedInput, r.RejectedSelf,
    r.RejectedTopology, r.RejectedShape, r.Relocated);
  std::fflush(stdout);
  return 0;
}

} // namespace

int main(int argc, char** argv)
{
  int vertices = 500, repeat = 3;
  bool builtin = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--vertices" && i + 1 < argc)
      vertices = std::stoi(argv[++i]);
    else if (a == "--repeat" && i + 1 < argc)
      repeat = std::max(1, std::stoi(argv[++i]));
    else if (a == "--builtin")
      builtin = true;
    else
      files.push_back(a);
  }
  if (files.empty() && !builtin)
    for (const char* f : { "armadillo.obj", "octopus-low_surface.obj", "anchor.off" })
      files.push_back(std::string(SDFCAGE_DATA_DIR) + "/" + f);
  int failures = 0;
  if (builtin)
    failures += run("builtin", PolygonMesh::fromTriangles(makeBuiltinShape()), vertices, repeat);
  for (const std::string& f : files)
  {
    PolygonMesh polygons;
    std::string error;
    if (!exact::readPolygonMesh(f, polygons, error))
    {
      std::printf("%s: %s\n", f.c_str(), error.c_str());
      ++failures;
      continue;
    }
    const std::size_t slash = f.find_last_of('/');
    failures += run(slash == std::string::npos ? f : f.substr(slash + 1), polygons, vertices, repeat);
  }
  return failures == 0 ? 0 : 1;
}
