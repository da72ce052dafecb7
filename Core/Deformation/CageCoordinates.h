// SDFCage — Core: cage coordinates and cage-based deformation (no VTK).
//
// A closed triangle cage C with vertices v_i and triangles t_j deforms every point x given as
//
//   mean value coordinates (Ju, Schaefer, Warren, "Mean Value Coordinates for Closed Triangular
//   Meshes", SIGGRAPH 2005):  x' = sum_i w_i(x) v'_i
//   Green coordinates (Lipman, Levin, Cohen-Or, "Green Coordinates", SIGGRAPH 2008):
//                             x' = sum_i phi_i(x) v'_i + sum_j psi_j(x) s_j n'_j
//
// with n'_j the unit normal of the deformed triangle t'_j and s_j its stretch factor (paper §4.2:
// s_j = sqrt(|u'|^2 |v|^2 - 2 (u'.v')(u.v) + |v'|^2 |u|^2) / (sqrt(8) area(t_j)), u, v the edge
// vectors of t_j from its first corner). The weights depend only on the points and the rest cage:
// CageDeformer computes them once (all threads), keeps them as a dense row-major matrix (one row
// per point: the vertex weights, then for Green one column per triangle) and applies a deformed
// cage as one matrix product.
//
// Mean value coordinates follow the paper's robust pseudo-code (points on a cage triangle or at a
// vertex get the linear interpolant of that triangle; triangles whose plane holds the point are
// skipped). They reproduce every affine map of the cage, inside and outside it.
//
// Green coordinates are evaluated in closed form (not with the paper's GCTriInt quadrature
// formula, which is equivalent): from Green's third identity for a harmonic u and x inside,
//   u(x) = sum_j  int_{t_j} u(y) dG/dn_y(x, y) - G(x, y) du/dn(y) dy,   G = -1 / (4 pi |x - y|),
// with u linear on each triangle (hat functions Gamma_i, in-plane gradient g_i), h = (x - y).n
// the height of x over the plane of t_j, omega the signed solid angle of t_j seen from x (sums to
// 4 pi inside), and for each edge k of t_j (outward in-plane normal m_k, from a_k) the line
// integral f_k = int_edge 1/|x - y| ds = ln((R_b + s_b) / (R_a + s_a)):
//   psi_j  = 1/(4 pi) [ sum_k ((a_k - x).m_k) f_k + h omega ]           (= -int G)
//   phi_i += 1/(4 pi) [ Gamma_i(x) omega + h g_i . sum_k m_k f_k ]       (= int Gamma_i dG/dn)
// (2D divergence theorem on the plane: int 1/R = sum_k d_k f_k - h^2 int 1/R^3 and
// int (y - x_p)/R^3 = -sum_k m_k f_k). They reproduce similarities (rotation, uniform scale,
// translation) exactly inside the cage.
//
// Points outside the rest cage (generalized winding number < 1/2) and points on it: Green
// coordinates are not defined there (the boundary integral of an outside point reproduces 0, not
// x). Those points get mean value coordinates in both modes: they follow the cage by MVC's smooth
// extension (exact for affine maps, an extrapolation otherwise), and are counted
// (PointsOutside, PointsOnCage) so callers can warn.
#pragma once

#include "Common/Progress.h"
#include "Common/Status.h"
#include "Mesh/Mesh.h"

#include <memory>
#include <string>
#include <vector>

namespace sdfcage
{

enum class CageCoordinateKind
{
  MeanValue = 0,
  Green = 1
};

const char* cageCoordinateKindName(CageCoordinateKind kind);

struct CageCoordinateOptions
{
  CageCoordinateKind Kind = CageCoordinateKind::MeanValue;
  /// Worker threads (0 = all cores); the weights do not depend on it.
  int NumberOfThreads = 0;
  /// Store the weights in single precision: half the memory and about half the apply time. The
  /// rest cage still gives the points back exactly (a per-point correction, x - W B_rest, is kept
  /// in double precision), but a deformed cage is followed only to about 1e-7 of its
  /// displacement (affine maps, similarities) instead of 1e-9 of the size.
  bool SinglePrecision = false;
};

/// What binding points to a cage did.
struct CageBindingResult
{
  Status State = Status::Ok;
  std::string Message;
  /// Points whose winding number with respect to the rest cage is below 1/2.
  long long PointsOutside = 0;
  /// Points on the rest cage (within 1e-12 of its bounding-box diagonal).
  long long PointsOnCage = 0;
  /// Points that use mean value rows in Green mode (outside, on the cage, or a non-finite row).
  long long MeanValueFallbacks = 0;
  /// The cage's triangles were inward (negative volume) and were used reversed.
  bool CageWasFlipped = false;
  /// max_x |x - (weights applied to the rest cage)| / cage diagonal, over the points (identity
  /// reproduction; ~1e-11 or better for points inside; with SinglePrecision: of the rounded weights
  /// before the correction, ~1e-7).
  double ReproductionError = 0.0;
  double WeightTime = 0.0;
  /// Bytes held by the weight matrix (8 or, with SinglePrecision, 4 per entry).
  double WeightBytes = 0.0;
};

/// Checks that `cage` can be used as a cage: at least 4 vertices, every index valid, no
/// degenerate triangle, every edge shared by exactly two triangles with opposite directions
/// (closed, consistently oriented 2-manifold). Returns an empty string or the reason.
std::string checkCage(const TriangleMesh& cage);

/// Weights of a fixed point set with respect to a fixed rest cage; applies deformed cages.
class CageDeformer
{
public:
  CageDeformer();
  ~CageDeformer();
  CageDeformer(const CageDeformer&) = delete;
  CageDeformer& operator=(const CageDeformer&) = delete;

  /// Computes the weights of `points` for `restCage` (closed, either orientation). On failure the
  /// deformer is empty (bound() false) and the result says why.
  CageBindingResult bind(const TriangleMesh& restCage, const std::vector<Vec3>& points,
    const CageCoordinateOptions& options, Progress* progress = nullptr);

  bool bound() const;
  void clear();
  CageCoordinateKind kind() const;
  std::size_t numberOfPoints() const;
  std::size_t numberOfCageVertices() const;
  std::size_t numberOfCageTriangles() const;

  /// The deformed points for a deformed cage with the rest cage's connectivity (only its points
  /// are given: `deformedCagePoints.size()` must equal the rest cage's vertex count). Returns
  /// false (and leaves `out` empty) when not bound or the count differs.
  bool apply(const std::vector<Vec3>& deformedCagePoints, std::vector<Vec3>& out, int numberOfThreads = 0) const;

  /// The weight row of point p: the vertex weights (numberOfCageVertices()), then for Green the
  /// triangle weights psi_j (numberOfCageTriangles()). For tests and inspection.
  std::vector<double> weights(std::size_t p) const;
  /// True when point p uses Green coordinates (false: mean value, see the header comment).
  bool usesGreen(std::size_t p) const;

  /// Where point p lies with respect to the rest cage.
  enum class Location : unsigned char
  {
    Inside = 0,
    Outside = 1,
    OnCage = 2
  };
  Location location(std::size_t p) const;

private:
  struct Data;
  std::unique_ptr<Data> D;
};

/// The Green stretch factors s_j and unit normals n'_j of `deformed` (points of the rest cage's
/// triangles `rest`): s_j n'_j is what multiplies psi_j.
std::vector<Vec3> greenScaledNormals(const TriangleMesh& rest, const std::vector<Vec3>& deformed);

} // namespace sdfcage
