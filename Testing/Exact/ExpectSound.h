// SDFCage — Testing: the exact checker's verdict as gtest expectations, shared by the tests that
// judge an envelope or a cage the same way (closed, not self-intersecting, enclosing the input
// with the promised clearance, with the input's genus and parts).
#pragma once

#include "ExactCheck.h"

#include <gtest/gtest.h>

#include <iostream>
#include <string>

namespace sdfcage
{
namespace exact
{

/// Judges `cage` around `input` with exactCheck (distances measured up to twice `clearance`) and
/// expects it sound: a closed 2-manifold, no self-intersection, no input intersection, every input
/// vertex strictly inside, clearance at least `clearance` (up to the rounding between unit-sphere
/// and input coordinates), `genus` and `components`. `what` names it in the log and the failures.
inline ExactReport expectSoundCage(const TriangleMesh& input, const TriangleMesh& cage, double clearance, int genus,
  int components, const std::string& what)
{
  const ExactReport r = exactCheck(input, cage, 2.0 * clearance);
  std::cout << "[ exact    ] " << what << ": " << r.CageTriangles << " triangles, clearance " << r.MinimumClearance
            << " (promised " << clearance << "), genus " << r.CageGenus << ", components " << r.CageComponents << "\n";
  EXPECT_TRUE(r.Closed2Manifold) << what;
  EXPECT_EQ(r.SelfIntersections, 0) << what;
  EXPECT_EQ(r.InputIntersections, 0) << what;
  EXPECT_EQ(r.InputVerticesOutside, 0) << what;
  EXPECT_TRUE(r.Encloses) << what;
  EXPECT_GE(r.MinimumClearance, clearance * (1.0 - 1e-9)) << what;
  EXPECT_EQ(r.CageGenus, genus) << what;
  EXPECT_EQ(r.CageComponents, components) << what;
  return r;
}

} // namespace exact
} // namespace sdfcage
