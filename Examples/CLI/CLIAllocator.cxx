// SDFCage — the sdfcage program: how the C library's allocator serves this one-shot process.
//
// Why: on the virtual machines this runs on, every first touch of a 4 KB page is a page fault
// that costs microseconds, and glibc's defaults make a run fault again and again: it returns
// freed memory at the top of its heap to the system (M_TRIM_THRESHOLD 128 KB, raised only
// dynamically), serves blocks above the mmap threshold with fresh mappings that are unmapped on
// free, and gives every worker thread an arena of its own. The pipeline builds and frees many
// buffers of a few MB (distance grids, isosurfaces, trees, the simplifier's queues): octopus-low
// faulted 11,000 times, armadillo 19,600. glibc's tunables
// (GLIBC_TUNABLES=glibc.malloc.hugetlb=1 with larger trim/top-pad/mmap thresholds) cut that to
// about 2,000 and the runs by 10-13%, but they are read only when a process starts, and
// re-executing the program to set them costs its start-up again. So the program does the
// equivalent itself, first thing in main(), with mallopt() and madvise():
//   - freed memory stays in the heap (trim threshold 1 GB), the heap grows by 64 MB at a time,
//     and blocks up to 32 MB come from the heap instead of mappings of their own;
//   - on machines with at most 4 hardware threads, one arena for all threads (so that what
//     follows covers every thread's blocks; the lock is rarely contended with 2-4 threads);
//   - the heap is grown once by up to 512 MB and its 64-MB pad (virtual address space only:
//     nothing is touched and the resident memory is unchanged) and that range is advised for transparent huge
//     pages, so that its first touches fault once per 2 MB instead of once per 4 KB.
// Measured (whole processes, 7 runs each alternately, median, `sdfcage MESH -n 500`):
// octopus-low 0.55 -> 0.49 s, anchor 0.60 -> 0.53 s, armadillo 1.21 -> 1.10 s; page faults
// 11,002 -> 2,002 and 19,630 -> 2,656; peak resident memory the same (91 and 122 MB).
// This is the program's business only: the library, the ParaView plugin and the Python module
// leave their host's allocator alone. A user who tunes glibc's allocator through the
// environment (GLIBC_TUNABLES or MALLOC_*_) keeps those settings: nothing here is done then.
#include "CLIAllocator.h"

#if defined(__GLIBC__) && defined(__linux__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <thread>

extern char** environ;
#endif

namespace sdfcage_cli
{

std::vector<std::string> allocatorEnvironment()
{
  std::vector<std::string> names;
#if defined(__GLIBC__) && defined(__linux__)
  for (char** e = environ; e && *e; ++e)
    if (std::strncmp(*e, "GLIBC_TUNABLES=", 15) == 0 || std::strncmp(*e, "MALLOC_", 7) == 0)
      names.emplace_back(*e, std::strchr(*e, '=') - *e);
#endif
  return names;
}

AllocatorTuning tuneAllocator()
{
  AllocatorTuning t;
#if defined(__GLIBC__) && defined(__linux__)
  if (!allocatorEnvironment().empty())
  {
    t.Skipped = true; // the user's own settings
    return t;
  }
  constexpr std::size_t MB = std::size_t(1) << 20;
  t.Tuned = mallopt(M_MMAP_THRESHOLD, static_cast<int>(32 * MB)) == 1 &&
    mallopt(M_TRIM_THRESHOLD, static_cast<int>(1024 * MB)) == 1 && mallopt(M_TOP_PAD, static_cast<int>(64 * MB)) == 1;
  if (!t.Tuned)
    return t;
  const unsigned threads = std::thread::hardware_concurrency();
  if (threads > 0 && threads <= 4)
    t.SingleArena = mallopt(M_ARENA_MAX, 1) == 1;

  // The reservation: at most an eighth of the physical memory, at most 512 MB.
  std::size_t reserve = 512 * MB;
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
  if (pages > 0 && pageSize > 0)
    reserve = std::min(reserve, static_cast<std::size_t>(pages) * static_cast<std::size_t>(pageSize) / 8);
  constexpr std::size_t block = 30 * MB; // below the mmap threshold: from the heap
  constexpr int maxBlocks = 32;
  void* blocks[maxBlocks];
  int n = 0;
  const auto before = reinterpret_cast<std::uintptr_t>(sbrk(0));
  for (std::size_t got = 0; got + block <= reserve && n < maxBlocks; got += block)
  {
    blocks[n] = std::malloc(block);
    if (!blocks[n])
      break;
    ++n;
  }
  const auto after = reinterpret_cast<std::uintptr_t>(sbrk(0));
  for (int i = 0; i < n; ++i)
    std::free(blocks[i]); // (kept in the heap: the trim threshold is above what they hold)
  // (the heap did not grow when sbrk is unavailable and glibc mapped the blocks instead: nothing
  // to advise then)
  constexpr std::uintptr_t huge = 2 * MB;
  const std::uintptr_t lo = (before + huge - 1) & ~(huge - 1);
  if (before != static_cast<std::uintptr_t>(-1) && after > lo + huge)
  {
    t.AdvisedBytes = after - lo;
    if (madvise(reinterpret_cast<void*>(lo), t.AdvisedBytes, MADV_HUGEPAGE) != 0)
      t.AdvisedBytes = 0; // (a kernel without transparent huge pages: the rest still holds)
  }
#endif
  return t;
}

} // namespace sdfcage_cli
