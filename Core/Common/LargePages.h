// SDFCage — Core: large buffers backed by transparent huge pages where the system allows it.
#pragma once

#include <cstddef>

namespace sdfcage
{

/// Asks the system to back [data, data + bytes) with transparent huge pages (2 MB) when it is
/// touched for the first time. Only the 2 MB-aligned part of a buffer of at least 4 MB is
/// advised; smaller buffers and other systems are left alone (a no-op).
///
/// Why: every first touch of a 4 KB page is a page fault, and on the virtual machines this runs
/// on one costs microseconds. dragon_vrip (871k triangles) faulted 225,000 times in one run, more
/// than half of it in the triangle trees and the reading of the file; with huge pages the same
/// buffers fault 512 times less often. Debian leaves huge pages to each program's advice
/// (`/sys/kernel/mm/transparent_hugepage/enabled` is `madvise`), so nothing happens unless the
/// program asks. glibc asks for all its allocations only when told so at start-up
/// (GLIBC_TUNABLES=glibc.malloc.hugetlb=1, which a library cannot set for its host), and TBB's
/// scalable allocator only uses huge pages that the system reserves or makes always on: hence this
/// advice, given for the few large arrays that are filled right after they are made.
void AdviseLargePages(void* data, std::size_t bytes);

/// `v.reserve(n)`, then the advice above on the reserved storage (before it is first touched, so
/// call it on a vector or string that is about to be filled).
template <class Container>
void ReserveLarge(Container& v, std::size_t n)
{
  v.reserve(n);
  AdviseLargePages(v.data(), v.capacity() * sizeof(typename Container::value_type));
}

} // namespace sdfcage
