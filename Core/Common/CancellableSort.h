// SDFCage — Core: std::sort with cancel checks, for the sorts of a million elements and more
// (edges, half-edges, triangles) that would otherwise run a whole second between two checks on a
// loaded machine.
#pragma once

#include "Common/Progress.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sdfcage
{

/// Sorts `v` by `less` like std::sort (the same order, but for equivalent elements), in chunks of
/// `chunk` elements merged pairwise, with a cancel check before every chunk and every merge.
/// Returns false, `v` then in no particular order, once `progress` is cancelled. Without
/// `progress`, or for a short vector, it is std::sort.
template <typename T, typename Less>
bool cancellableSort(std::vector<T>& v, Less less, Progress* progress, std::size_t chunk = std::size_t(1) << 16)
{
  const std::size_t n = v.size();
  if (!progress || n <= chunk)
  {
    std::sort(v.begin(), v.end(), less);
    return !progressCancelled(progress);
  }
  using Diff = typename std::vector<T>::difference_type;
  const auto at = [&v](std::size_t i) { return v.begin() + static_cast<Diff>(i); };
  for (std::size_t b = 0; b < n; b += chunk)
  {
    if (progress->cancelled())
      return false;
    std::sort(at(b), at(std::min(n, b + chunk)), less);
  }
  for (std::size_t width = chunk; width < n; width *= 2)
  {
    for (std::size_t b = 0; b + width < n; b += 2 * width)
    {
      if (progress->cancelled())
        return false;
      std::inplace_merge(at(b), at(b + width), at(std::min(n, b + 2 * width)), less);
    }
  }
  return !progress->cancelled();
}

template <typename T>
bool cancellableSort(std::vector<T>& v, Progress* progress, std::size_t chunk = std::size_t(1) << 16)
{
  return cancellableSort(v, [](const T& a, const T& b) { return a < b; }, progress, chunk);
}

} // namespace sdfcage
