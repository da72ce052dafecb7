// SDFCage — Core: what every stage returns (a status) and the dense scalar image the envelope
// stage can hand out for display.
#pragma once

#include "Mesh/Mesh.h"

#include <array>
#include <vector>

namespace sdfcage
{

/// A dense sampled scalar field (point data on a regular grid, x fastest).
struct ScalarImage
{
  std::array<int, 3> Dimensions{ 0, 0, 0 };
  Vec3 Origin = Vec3::Zero();
  double Spacing = 1.0;
  std::vector<float> Values;
};

enum class Status
{
  Ok = 0,
  EmptyInput,
  InvalidInput,
  Cancelled,
  VerificationFailed,
  Failed,
  /// The envelope's genus or parts differ from the closed input's and the caller required them
  /// kept (EnvelopeOptions::RequireTopology): no cage.
  TopologyChanged
};

const char* statusName(Status s);

} // namespace sdfcage
