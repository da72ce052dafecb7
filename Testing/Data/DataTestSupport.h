// SDFCage — Testing: what the data tests (one real mesh from ../shared/data per test) share: their
// command line and the skip when the mesh or the data folder is absent.
//
//   --mesh=FILE      the mesh (empty when CMake found no data folder: the test reports SKIPPED)
//   --data-dir=DIR   the data folder, named in the skip message
//   --NAME / --NAME=VALUE   the test program's own flags, declared by the caller
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <string>

namespace sdfcage
{
namespace datatest
{

struct Arguments
{
  std::string Mesh;
  std::string DataDir;
  std::set<std::string> Flags;                 ///< the declared flags given ("inward")
  std::map<std::string, std::string> Values;   ///< the declared valued options given ("vertices" -> "200")

  bool has(const std::string& flag) const { return Flags.count(flag) != 0; }
  std::string value(const std::string& name, const std::string& fallback = "") const
  {
    const auto it = Values.find(name);
    return it == Values.end() ? fallback : it->second;
  }
};

/// Initializes GoogleTest and parses the rest; false (after a message naming the program) on an
/// argument that is neither --mesh, --data-dir nor one of `flags` / `valued`.
inline bool parseArguments(int& argc, char** argv, const char* program, const std::set<std::string>& flags,
  const std::set<std::string>& valued, Arguments& out)
{
  ::testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    const std::size_t eq = arg.find('=');
    const std::string name = arg.rfind("--", 0) == 0 ? arg.substr(2, eq == std::string::npos ? eq : eq - 2) : "";
    const std::string value = eq == std::string::npos ? "" : arg.substr(eq + 1);
    if (name == "mesh" && eq != std::string::npos)
      out.Mesh = value;
    else if (name == "data-dir" && eq != std::string::npos)
      out.DataDir = value;
    else if (eq == std::string::npos && flags.count(name))
      out.Flags.insert(name);
    else if (eq != std::string::npos && valued.count(name))
      out.Values[name] = value;
    else
    {
      std::cerr << program << ": unknown argument '" << arg << "'\n";
      return false;
    }
  }
  return true;
}

/// Why a data test cannot run ("" when the mesh is there): the data folder is absent or empty
/// (CMake passed no mesh), or the mesh file is gone since CMake listed it.
inline std::string missingMeshReason(const std::string& mesh, const std::string& dataDir)
{
  if (mesh.empty())
    return "no test meshes: the data folder '" + dataDir + "' is absent or empty (set SDFCAGE_DATA_DIR)";
  if (!std::ifstream(mesh).good())
    return "mesh '" + mesh + "' is absent (re-run CMake after changing the data folder)";
  return "";
}

} // namespace datatest
} // namespace sdfcage

/// In a test body: reports SKIPPED, with the reason, when the data mesh cannot be read.
#define SDFCAGE_SKIP_WITHOUT_MESH(mesh, dataDir)                                                              \
  do                                                                                                          \
  {                                                                                                           \
    const std::string sdfcageSkipReason = ::sdfcage::datatest::missingMeshReason(mesh, dataDir);              \
    if (!sdfcageSkipReason.empty())                                                                           \
      GTEST_SKIP() << sdfcageSkipReason;                                                                      \
  } while (false)
