// SDFCage — fuzz harness: the CLI's PLY, OBJ, STL and legacy VTK parsers (Examples/CLI/CLIParsers.h) on any bytes.
// Whatever they accept must be a consistent mesh: three coordinates a point, offsets rising
// from 0 to the connectivity's end, every index inside [0, points).
#include "CLIParsers.h"

#include <cstdint>
#include <cstdlib>
#include <string>

namespace
{
void checkConsistent(const sdfcage_cli::ParsedMesh& m)
{
  if (m.Points.size() % 3 != 0 || m.Offsets.empty() || m.Offsets.front() != 0 ||
    m.Offsets.back() != static_cast<std::int64_t>(m.Connectivity.size()))
  {
    std::abort();
  }
  for (std::size_t i = 1; i < m.Offsets.size(); ++i)
  {
    if (m.Offsets[i] - m.Offsets[i - 1] < 3)
    {
      std::abort();
    }
  }
  const auto n = static_cast<std::int64_t>(m.Points.size() / 3);
  for (std::int64_t id : m.Connectivity)
  {
    if (id < 0 || id >= n)
    {
      std::abort();
    }
  }
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const char* text = reinterpret_cast<const char*>(data);
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  if (sdfcage_cli::parsePLY(text, size, mesh, error))
  {
    checkConsistent(mesh);
  }
  else if (error.empty())
  {
    std::abort(); // a refusal always says why
  }
  error.clear();
  if (sdfcage_cli::parseOBJ(text, size, mesh, error))
  {
    checkConsistent(mesh);
  }
  else if (error.empty())
  {
    std::abort();
  }
  error.clear();
  if (sdfcage_cli::parseSTL(text, size, mesh, error))
  {
    checkConsistent(mesh);
  }
  else if (error.empty())
  {
    std::abort();
  }
  error.clear();
  if (sdfcage_cli::parseLegacyVTK(text, size, mesh, error))
  {
    checkConsistent(mesh);
  }
  else if (error.empty())
  {
    std::abort();
  }
  return 0;
}
