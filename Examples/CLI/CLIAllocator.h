// SDFCage — CLI: the C library's allocator tuned for this one-shot program (fewer page faults;
// CLIAllocator.cxx says why and what was measured).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace sdfcage_cli
{

struct AllocatorTuning
{
  bool Skipped = false;         ///< the environment tunes the allocator (GLIBC_TUNABLES, MALLOC_*_)
  bool Tuned = false;           ///< the thresholds were set
  bool SingleArena = false;     ///< one arena for all threads
  std::size_t AdvisedBytes = 0; ///< heap advised for transparent huge pages
};

/// Call first thing in main(), before any thread starts. A no-op off glibc/Linux.
AllocatorTuning tuneAllocator();

/// The environment variables by which the user tunes the allocator (GLIBC_TUNABLES, MALLOC_*),
/// by name: tuneAllocator() does nothing when there is one. Empty off glibc/Linux.
std::vector<std::string> allocatorEnvironment();

} // namespace sdfcage_cli
