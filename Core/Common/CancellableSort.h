// SDFCage — Core: std::sort with cancel checks, for the sorts of a million elements and more
// (edges, half-edges, triangles) that would otherwise run a whole second between two checks on a
// loaded machine.
#pragma once

#include "Common/Progress.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sdfcage
{

/// Sorts `v` by `less` like std::sort (the same order, but for equivalent elements), in chunks of
/// `chunk` elements merged pairwise, with a cancel check before every chunk and every merge. The
/// chunks, and the merges of one width, run in parallel (TBB): the order is the same for any
/// number of threads. Returns false, `v` then in no particular order, once `progress` is
/// cancelled. A vector of at most `chunk` elements is std::sort.
template <typename T, typename Less>
bool cancellableSort(std::vector<T>& v, Less less, Progress* progress, std::size_t chunk = std::size_t(1) << 16)
{
  const std::size_t n = v.size();
  if (n <= chunk)
  {
    std::sort(v.begin(), v.end(), less);
    return !progressCancelled(progress);
  }
  using Diff = typename std::vector<T>::difference_type;
  const auto at = [&v](std::size_t i) { return v.begin() + static_cast<Diff>(i); };
  const std::size_t chunks = (n + chunk - 1) / chunk;
  tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
    if (progressCancelled(progress))
      return;
    std::sort(at(c * chunk), at(std::min(n, (c + 1) * chunk)), less);
  });
  for (std::size_t width = chunk; width < n; width *= 2)
  {
    if (progressCancelled(progress))
      return false;
    const std::size_t pairs = (n - width + 2 * width - 1) / (2 * width); // b = 2 k width with b + width < n
    tbb::parallel_for(std::size_t(0), pairs, [&](std::size_t k) {
      const std::size_t b = 2 * k * width;
      if (progressCancelled(progress))
        return;
      std::inplace_merge(at(b), at(b + width), at(std::min(n, b + 2 * width)), less);
    });
  }
  return !progressCancelled(progress);
}

template <typename T>
bool cancellableSort(std::vector<T>& v, Progress* progress, std::size_t chunk = std::size_t(1) << 16)
{
  return cancellableSort(v, [](const T& a, const T& b) { return a < b; }, progress, chunk);
}

} // namespace sdfcage
