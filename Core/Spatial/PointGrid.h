// SDFCage — Core: points hashed into cubic cells of a fixed radius, answering "is any of them
// closer than the radius to x?" by the 27 cells around x (the active points' neighbourhoods: the
// amplified projection's reach, the Active Points filter's facing-gap rule per point). Written
// here: the question is this narrow, and a tree would cost more to build than it saves.
#pragma once

#include "Mesh/Mesh.h"

#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace sdfcage
{

class PointGrid
{
public:
  explicit PointGrid(double radius)
    : R(radius)
  {
  }
  void insert(const Vec3& p) { Cells[key(cell(p.x()), cell(p.y()), cell(p.z()))].push_back(p); }
  /// Whether some inserted point lies closer than the radius to x.
  bool anyWithin(const Vec3& x) const
  {
    const std::int64_t ci = cell(x.x()), cj = cell(x.y()), ck = cell(x.z());
    for (std::int64_t k = ck - 1; k <= ck + 1; ++k)
      for (std::int64_t j = cj - 1; j <= cj + 1; ++j)
        for (std::int64_t i = ci - 1; i <= ci + 1; ++i)
        {
          const auto it = Cells.find(key(i, j, k));
          if (it == Cells.end())
            continue;
          for (const Vec3& a : it->second)
            if ((a - x).squaredNorm() < R * R)
              return true;
        }
    return false;
  }

private:
  std::int64_t cell(double v) const { return static_cast<std::int64_t>(std::floor(v / R)); }
  static std::int64_t key(std::int64_t i, std::int64_t j, std::int64_t k)
  {
    return ((k & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (i & 0x1FFFFF);
  }
  double R;
  std::unordered_map<std::int64_t, std::vector<Vec3>> Cells;
};

} // namespace sdfcage
