// SDFCage — fuzz harness: the program's mesh reading (Examples/CLI/CLIMeshIO.h readMesh) of
// every format it accepts. The first byte picks the extension (.off .obj .ply .stl .vtp .vtk),
// the rest is the file. Reading must end with a mesh or a one-line reason, never a crash, a
// hang or a huge allocation (libFuzzer's -rss_limit_mb and -timeout watch those).
#include "CLIMeshIO.h"
#include "CLIMessages.h"

#include <vtkObject.h>
#include <vtkPolyData.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  static const char* const extensions[] = { ".off", ".obj", ".ply", ".stl", ".vtp", ".vtk" };
  static bool installed = [] {
    sdfcage_cli::MessageCollector::install();
    return true;
  }();
  (void)installed;
  if (size == 0)
  {
    return 0;
  }
  const std::string path =
    "/dev/shm/sdfcage_fuzz_read_" + std::to_string(getpid()) + extensions[data[0] % 6];
  if (std::FILE* f = std::fopen(path.c_str(), "wb"))
  {
    std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
  }
  std::string error;
  vtkSmartPointer<vtkPolyData> mesh = sdfcage_cli::readMesh(path, error);
  if (!mesh && error.empty())
  {
    std::abort(); // a refusal always says why
  }
  if (mesh && mesh->GetNumberOfPolys() + mesh->GetNumberOfStrips() == 0)
  {
    std::abort(); // readMesh promises polygons
  }
  std::remove(path.c_str());
  return 0;
}
