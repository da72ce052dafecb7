// SDFCage — Core: a static bounding-volume hierarchy over a triangle mesh for exact distance
// queries between points or triangles and the mesh (used for the input during simplification
// and verification, where query triangles can be far larger than the mesh's triangles).
#pragma once

#include "Mesh/Mesh.h"

#include <algorithm>
#include <vector>

namespace sdfcage
{

class Progress;

/// The smallest distance between two parts of `mesh` when it is below `limit` (exact triangle
/// distances), else `limit` (also for a mesh of one part).
double distanceBetweenParts(const TriangleMesh& mesh, double limit);
/// The same with the parts known: `component` per triangle and their number (triangleComponents).
double distanceBetweenParts(const TriangleMesh& mesh, double limit, const std::vector<int>& component, int parts);

class TriangleTree
{
public:
  TriangleTree() = default;
  explicit TriangleTree(const TriangleMesh& mesh, bool splitLong = false) { this->build(mesh, nullptr, splitLong); }
  void build(const TriangleMesh& mesh);
  /// The same with cancel checks (about every 8,000 triangles): false, and an empty tree, once
  /// `progress` is cancelled. `splitLong`: triangles longer than 1/32 of the mesh's diagonal are
  /// entered as pieces (see SplitLength in the .cxx): a soup of long slivers, whose boxes all
  /// overlap, then gets boxes that prune. Every query's answer is the same up to ties (distances
  /// are still measured to the whole triangles; winding numbers sum the pieces).
  bool build(const TriangleMesh& mesh, Progress* progress, bool splitLong = false);

  /// Closest point on the mesh to p within maxDistance (<0: unlimited). False when none.
  bool closestPoint(const Vec3& p, double maxDistance, Vec3& closest, int& triangle, double& distance) const;
  double distance(const Vec3& p) const;

  /// Exact distance between the triangle t and the mesh, or `limit` when it is not below limit.
  double triangleDistance(const Vec3 t[3], double limit) const;
  /// True when some mesh triangle comes closer than `delta` to triangle t (stops at the first).
  bool anyCloserThan(const Vec3 t[3], double delta) const;
  /// Is some triangle closer than delta to one of the `count` triangles tris[i] (each three
  /// corners)? The same answer as anyCloserThan on each in turn, from one walk of the tree for
  /// all of them: the changed triangles of a local change lie together, and share the walk down
  /// to where they are. At most 32 triangles in one call.
  bool anyCloserThanAny(const Vec3* const* tris, int count, double delta) const;
  /// Number of mesh triangles at distance <= delta from triangle t (0 counts: intersecting or
  /// touching). Used to count intersecting pairs.
  long long countWithin(const Vec3 t[3], double delta) const;
  /// Appends to `ids` the mesh triangles closer than `radius` to triangle t (exact distances).
  void trianglesWithin(const Vec3 t[3], double radius, std::vector<int>& ids) const;

  /// Unit normal of mesh triangle `id` (zero for degenerate triangles).
  const Vec3& normal(int id) const { return Normals[id]; }

  /// Generalized winding number of the mesh at p (Jacobson et al. 2013, "Robust inside-outside
  /// segmentation using generalized winding numbers"): about 1 inside a closed outward mesh, 0
  /// outside, and a smooth, robust inside measure for soups, holes, cracks and overlaps (about
  /// +-1/2 beside an open sheet). Evaluated hierarchically as in Barill et al. 2018, "Fast
  /// winding numbers for soups and clouds": a node farther than `beta` times its radius counts
  /// as one dipole (its area-weighted normal at its area centroid), others are summed exactly.
  /// prepareWindingNumbers() must have been called (once, after build).
  double windingNumber(const Vec3& p, double beta = 2.0) const;
  /// Computes the per-node dipoles windingNumber() needs (linear in the triangles, threaded).
  void prepareWindingNumbers();
  bool windingNumbersReady() const { return !Dipoles.empty() || Nodes.empty(); }

  bool empty() const { return Nodes.empty(); }
  /// Entries in the tree: the triangles, or more when long ones were entered as pieces.
  std::size_t size() const { return Tri.size(); }
  /// Triangles entered as more than one piece (build's `splitLong`).
  std::size_t splitTriangles() const { return SplitTriangles; }
  /// Memory the pieces of build(mesh, ..., true) take beyond a tree of whole triangles (0 when no
  /// triangle is long), for the memory budget before the tree is built.
  static std::size_t pieceBytes(const TriangleMesh& mesh);

private:
  struct Node
  {
    Vec3 Lo, Hi;
    int Left = -1; // child index, or -1 for a leaf
    int Right = -1;
    int Start = 0; // leaf: range into Tri
    int Count = 0;
  };
  struct Tri3
  {
    Vec3 P[3]; // the whole triangle (every distance is measured to it)
    int Id;
  };
  struct Piece
  {
    Vec3 P[3];      // the piece of the triangle this entry stands for (winding numbers)
    Vec3 Lo, Hi;    // its box, padded so that the pieces' boxes cover the whole triangle
  };
  struct BuildItem
  {
    Vec3 C; // centroid
    int Id;
  };
  // Leaf boxes: the pieces' when triangles are split, else the mesh's triangles by id.
  void buildNode(int index, int start, int count, std::vector<BuildItem>& items, const TriangleMesh& mesh,
    const std::vector<Piece>& pieces, int depth, Progress* progress);
  // Entries per triangle (first[f] .. first[f + 1]) and the squared piece length; 0 and no
  // entries when no triangle is split.
  static double pieceLayout(const TriangleMesh& mesh, std::vector<std::size_t>& first);
  const Vec3* windingCorners(int entry) const { return Pieces.empty() ? Tri[entry].P : Pieces[entry].P; }
  // The distance from t to the input if below `limit`, else `limit`; with stopAtFirst, a value
  // below `limit` as soon as one triangle is closer than it (not the distance); with `within`,
  // every triangle closer than `limit` is listed and `limit` returned.
  double triangleQuery(const Vec3 t[3], double limit, bool stopAtFirst, std::vector<int>* within = nullptr) const;
  // A query triangle's box, plane and side planes, and the bounds the triangle walks take from them
  // (TriangleTree.cxx).
  struct QueryTriangle;
  struct Dipole
  {
    Vec3 Center = Vec3::Zero();     // area centroid of the node's triangles
    Vec3 AreaNormal = Vec3::Zero(); // sum of area-weighted normals
    double Area = 0.0;
    double Radius = 0.0; // farthest triangle corner from Center
  };
  // The layout the distance queries walk (built from Nodes after the build): each internal node
  // holds both children's boxes, in floats rounded outward, so that choosing and pruning children
  // reads one 64-byte line instead of three nodes of Nodes, and a pushed child is prefetched. The
  // same nodes are visited in the same order as with Nodes (rounding outward only prunes less).
  // Measured with sdfcage_simplify_benchmark (best of 4) on dragon_vrip.ply, whose 871k-face tree
  // outgrows the caches: the simplification 4.63 -> 4.23 s. A child is an internal node (Count 0:
  // Child is its index here) or a leaf (Child its first entry in Tri, Count its entries).
  //
  // Each child also has a slab: a unit direction (its triangles' mean normal) and the range its
  // triangles' corners span along it. Nothing in the child is nearer to a point or triangle than
  // the gap between their ranges along it. Where the surface is smooth, the slab is much thinner
  // than the box, and a query that passes above the surface (the cage's triangles, at the
  // isovalue from the input) is cleared high in the tree instead of at the leaves. Measured on
  // armadillo's cage (session 48): the clearance queries opened 37 nodes each instead of 55 and
  // tested 13 triangles instead of 28; the simplification went 0.51 -> 0.45 s, whole runs of
  // armadillo_midsub4x 2.18 -> 1.84 s and dragon_vrip 10.1 -> 8.9 s, with the same cages.
  struct alignas(64) QueryNode
  {
    float Lo[2][3];
    float Hi[2][3];
    int Child[2];
    int Count[2];
    float Normal[2][3]; // |Normal| <= 1; zero (and the range infinite) where no slab was made
    float SlabLo[2];
    float SlabHi[2];
  };
  struct Ref
  {
    int Child;
    int Count;
  };
  void buildQueryNodes();
  void prefetch(const Ref& r) const;
  Vec3 childLo(const QueryNode& q, int c) const { return Vec3(q.Lo[c][0], q.Lo[c][1], q.Lo[c][2]); }
  Vec3 childHi(const QueryNode& q, int c) const { return Vec3(q.Hi[c][0], q.Hi[c][1], q.Hi[c][2]); }
  // Lower bound of the distance from some points (their range along the child's slab direction
  // being [lo, hi]) to the child's triangles; <= 0 when the slab does not separate them. The
  // margin covers the rounding of the dot products: slabMargin(the points' largest coordinate).
  double slabGap(const QueryNode& q, int c, double lo, double hi, double margin) const
  {
    return std::max(static_cast<double>(q.SlabLo[c]) - hi, lo - static_cast<double>(q.SlabHi[c])) - margin;
  }
  double slabMargin(double queryScale) const { return SlabMargin + 1e-13 * queryScale; }
  double along(const QueryNode& q, int c, const Vec3& p) const
  {
    return static_cast<double>(q.Normal[c][0]) * p.x() + static_cast<double>(q.Normal[c][1]) * p.y() +
      static_cast<double>(q.Normal[c][2]) * p.z();
  }
  std::vector<Node> Nodes;
  std::vector<QueryNode> QueryNodes;
  double SlabMargin = 0.0; // rounding of the dot products along a slab direction (the tree's coordinates)
  Ref Root{ 0, 0 }; // the root as a child reference (a leaf when the tree has one node)
  std::vector<Dipole> Dipoles;
  std::vector<Tri3> Tri;
  std::vector<Piece> Pieces; // parallel to Tri when some triangle was split, else empty
  std::size_t SplitTriangles = 0;
  std::vector<Vec3> Normals;
};

} // namespace sdfcage
