// SDFCage — Core: the key of an undirected edge (a, b) of a mesh, the same for (b, a).
#pragma once

#include <cstdint>
#include <utility>

namespace sdfcage
{

inline std::uint64_t edgeKey(int a, int b)
{
  if (a > b)
    std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

} // namespace sdfcage
