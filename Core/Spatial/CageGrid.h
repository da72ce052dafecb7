// SDFCage — Core: a dynamic uniform hash grid over the boxes of a changing mesh's triangles (the
// cage while the simplifier collapses edges and the optimizer moves vertices and flips edges).
// A triangle is filed in every cell its box touches; a query visits the triangles of every cell a
// box touches (a triangle once per cell: callers deduplicate, and test boxes themselves).
#pragma once

#include "Mesh/Mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace sdfcage
{

class CageGrid
{
public:
  void reset(double cellSize)
  {
    Cell = cellSize;
    Cells.clear();
  }
  double cellSize() const { return Cell; }
  /// Calls f(key) for every cell touched by the box [lo, hi].
  template <typename F>
  void forCells(const Vec3& lo, const Vec3& hi, F&& f) const
  {
    const std::int64_t i0 = key1(lo.x()), i1 = key1(hi.x());
    const std::int64_t j0 = key1(lo.y()), j1 = key1(hi.y());
    const std::int64_t k0 = key1(lo.z()), k1 = key1(hi.z());
    for (std::int64_t k = k0; k <= k1; ++k)
      for (std::int64_t j = j0; j <= j1; ++j)
        for (std::int64_t i = i0; i <= i1; ++i)
          f(((k & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (i & 0x1FFFFF));
  }
  void insert(int t, const Vec3& lo, const Vec3& hi)
  {
    forCells(lo, hi, [&](std::int64_t key) { Cells[key].push_back(t); });
  }
  /// Removes t from the cells of [lo, hi], the box it was inserted with.
  void remove(int t, const Vec3& lo, const Vec3& hi)
  {
    forCells(lo, hi, [&](std::int64_t key) {
      auto it = Cells.find(key);
      if (it == Cells.end())
        return;
      auto& v = it->second;
      auto pos = std::find(v.begin(), v.end(), t);
      if (pos != v.end())
      {
        *pos = v.back();
        v.pop_back();
      }
    });
  }
  /// Calls f(t) for every triangle filed in a cell the box [lo, hi] touches (possibly repeated,
  /// possibly a triangle whose box misses [lo, hi]). Read-only: safe from several threads while
  /// nothing inserts or removes.
  template <typename F>
  void query(const Vec3& lo, const Vec3& hi, F&& f) const
  {
    forCells(lo, hi, [&](std::int64_t key) {
      auto it = Cells.find(key);
      if (it != Cells.end())
        for (int t : it->second)
          f(t);
    });
  }

private:
  std::int64_t key1(double x) const { return static_cast<std::int64_t>(std::floor(x / Cell)); }
  double Cell = 1.0;
  std::unordered_map<std::int64_t, std::vector<int>> Cells;
};

/// Per-triangle stamps: a set of triangle ids emptied in O(1) (one per thread, reused).
class TriangleStamps
{
public:
  /// Empties the set (and sizes it for `triangles` triangles).
  void begin(std::size_t triangles)
  {
    if (Stamp.size() < triangles)
      Stamp.resize(triangles, 0);
    if (++Id == 0)
    {
      std::fill(Stamp.begin(), Stamp.end(), 0);
      Id = 1;
    }
  }
  /// Adds f; false if it was there already.
  bool insert(int f)
  {
    if (Stamp[f] == Id)
      return false;
    Stamp[f] = Id;
    return true;
  }
  bool contains(int f) const { return Stamp[f] == Id; }

private:
  std::vector<unsigned> Stamp;
  unsigned Id = 0;
};

} // namespace sdfcage
