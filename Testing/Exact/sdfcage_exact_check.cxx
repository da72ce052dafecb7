// SDFCage — Testing: command-line front end of the exact cage check.
//
//   sdfcage_exact_check INPUT CAGE [--clearance D]
//
// Reads two meshes (.off, .obj or .ply; polygons are fan-triangulated), runs exactCheck() and
// prints its report as one JSON object on stdout. D is the distance up to which the clearance is
// measured exactly, in the meshes' units (default: 2% of the input's bounding-box diagonal).
// Exit code: 0 when the cage encloses the input, 1 when it does not, 2 on bad arguments or
// unreadable files.
#include "ExactCheck.h"
#include "MeshIO.h"

#include <cstdlib>
#include <iostream>
#include <string>

namespace
{

int usage()
{
  std::cerr << "usage: sdfcage_exact_check INPUT CAGE [--clearance D]\n"
               "  INPUT, CAGE: .off, .obj or .ply meshes in the same coordinates\n"
               "  D: distance up to which the clearance is measured exactly (default 2% of the\n"
               "     input bounding-box diagonal)\n"
               "Prints a JSON report; exits 0 when CAGE strictly encloses INPUT, 1 when not, 2 on\n"
               "errors.\n";
  return 2;
}

bool load(const std::string& path, sdfcage::TriangleMesh& mesh)
{
  sdfcage::PolygonMesh polygons;
  std::string error;
  if (!sdfcage::exact::readPolygonMesh(path, polygons, error))
  {
    std::cerr << "sdfcage_exact_check: " << error << "\n";
    return false;
  }
  if (!sdfcage::exact::fanTriangulate(polygons, mesh))
  {
    std::cerr << "sdfcage_exact_check: warning: '" << path << "' has faces with invalid point ids (skipped)\n";
  }
  return true;
}

} // namespace

int main(int argc, char* argv[])
{
  std::string paths[2];
  int nPaths = 0;
  double clearance = 0.0;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--clearance" && i + 1 < argc)
    {
      char* end = nullptr;
      clearance = std::strtod(argv[++i], &end);
      if (!end || *end != '\0' || !(clearance > 0.0))
      {
        std::cerr << "sdfcage_exact_check: --clearance needs a positive number\n";
        return usage();
      }
    }
    else if (arg == "-h" || arg == "--help")
    {
      usage();
      return 0;
    }
    else if (!arg.empty() && arg[0] == '-')
    {
      std::cerr << "sdfcage_exact_check: unknown option '" << arg << "'\n";
      return usage();
    }
    else if (nPaths < 2)
    {
      paths[nPaths++] = arg;
    }
    else
    {
      return usage();
    }
  }
  if (nPaths != 2)
  {
    return usage();
  }
  sdfcage::TriangleMesh input, cage;
  if (!load(paths[0], input) || !load(paths[1], cage))
  {
    return 2;
  }
  const sdfcage::exact::ExactReport report = sdfcage::exact::exactCheck(input, cage, clearance);
  std::cout << sdfcage::exact::toJson(report) << std::endl;
  return report.Encloses ? 0 : 1;
}
