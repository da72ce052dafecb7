// SDFCage — Core: scale into the unit sphere (paper §4) and back.
#pragma once

#include "Mesh/Mesh.h"

namespace sdfcage
{

/// x_unit = (x - Center) * Scale. Every length parameter of the method is in unit-sphere units;
/// every output is mapped back with toInput().
struct Normalization
{
  Vec3 Center = Vec3::Zero();
  double Scale = 1.0;

  /// Center of the bounding box; Scale = 1 / (largest distance of a point from it).
  static Normalization fit(const TriangleMesh& mesh);

  Vec3 toUnit(const Vec3& p) const { return (p - Center) * Scale; }
  Vec3 toInput(const Vec3& p) const { return p / Scale + Center; }
  double lengthToInput(double unitLength) const { return unitLength / Scale; }
  double lengthToUnit(double inputLength) const { return inputLength * Scale; }

  TriangleMesh toUnit(const TriangleMesh& mesh) const;
  TriangleMesh toInput(const TriangleMesh& mesh) const;
};

} // namespace sdfcage
