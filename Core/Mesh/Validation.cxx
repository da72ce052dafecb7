#include "Mesh/Validation.h"

#include "Spatial/Geometry.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace sdfcage
{

bool MeshDefects::usable() const
{
  return !Empty && NonFinitePoints == 0 && InvalidPointIds == 0 && UntriangulatedPolygons == 0 &&
    BoundaryEdges == 0 && NonManifoldEdges == 0 && NonManifoldVertices == 0 &&
    DegenerateTriangles == 0 && InconsistentEdges == 0;
}

std::string MeshDefects::errorMessage() const
{
  std::ostringstream s;
  auto sep = [&]() {
    if (s.tellp() > 0)
    {
      s << "; ";
    }
  };
  if (Empty)
  {
    sep();
    s << "the mesh has no triangles";
  }
  if (NonFinitePoints)
  {
    sep();
    s << NonFinitePoints << " points have non-finite (NaN or infinite) coordinates: fix or remove them";
  }
  if (InvalidPointIds)
  {
    sep();
    s << InvalidPointIds << " cells reference points that do not exist: the file is corrupt";
  }
  if (UntriangulatedPolygons)
  {
    sep();
    s << UntriangulatedPolygons
      << " polygons are non-planar or non-convex and cannot be split safely: triangulate them first "
         "(e.g. vtkTriangleFilter / ParaView's Triangulate)";
  }
  if (BoundaryEdges)
  {
    sep();
    s << "the mesh has " << BoundaryEdges
      << " boundary edges: it must be closed (watertight); fill the holes first (e.g. "
         "vtkFillHolesFilter / ParaView's Fill Holes) or reconstruct a watertight surface";
  }
  if (NonManifoldEdges)
  {
    sep();
    s << NonManifoldEdges << " non-manifold edges (shared by more than two triangles)";
  }
  if (NonManifoldVertices)
  {
    sep();
    s << NonManifoldVertices
      << " non-manifold vertices (surface sheets touching at a single point)";
  }
  if (DegenerateTriangles)
  {
    sep();
    s << DegenerateTriangles
      << " degenerate (zero-area) triangles: remove them first (e.g. vtkCleanPolyData with point "
         "merging)";
  }
  if (InconsistentEdges)
  {
    sep();
    s << InconsistentEdges
      << " edges are used twice in the same direction: triangle orientation is inconsistent; "
         "orient the mesh consistently first (e.g. vtkPolyDataNormals with ConsistencyOn)";
  }
  std::string msg = s.str();
  if (!msg.empty())
  {
    msg = "Unusable input mesh: " + msg + ".";
  }
  return msg;
}

std::vector<std::string> MeshDefects::warnings() const
{
  std::vector<std::string> w;
  if (TriangulatedPolygons)
  {
    w.push_back(std::to_string(TriangulatedPolygons) + " polygons were split into triangles");
  }
  if (IgnoredCells)
  {
    w.push_back(std::to_string(IgnoredCells) + " vertex/line cells were ignored (not surfaces)");
  }
  if (UnreferencedPoints)
  {
    w.push_back(std::to_string(UnreferencedPoints) + " points used by no triangle were dropped");
  }
  if (FlippedOrientation)
  {
    w.push_back("the mesh was oriented inward; its triangles were flipped to face outward");
  }
  return w;
}

namespace
{

// Fan-triangulates polygon ids (n >= 4) when it is planar and strictly convex. Returns false when
// that is not safe (the split would depend on a choice the input does not determine).
bool triangulateConvex(const std::vector<Vec3>& pts, const std::int64_t* ids, std::int64_t n,
  std::vector<Triangle>& out)
{
  Vec3 normal = Vec3::Zero(); // Newell normal
  Vec3 centroid = Vec3::Zero();
  double diameter = 0.0;
  for (std::int64_t i = 0; i < n; ++i)
  {
    const Vec3& a = pts[ids[i]];
    const Vec3& b = pts[ids[(i + 1) % n]];
    normal += a.cross(b);
    centroid += a;
    diameter = std::max(diameter, (b - a).norm());
  }
  centroid /= static_cast<double>(n);
  const double len = normal.norm();
  if (!(len > 0.0) || !(diameter > 0.0))
  {
    return false;
  }
  normal /= len;
  // planar within 1e-3 of the polygon's edge length
  for (std::int64_t i = 0; i < n; ++i)
  {
    if (std::abs((pts[ids[i]] - centroid).dot(normal)) > 1e-3 * diameter)
    {
      return false;
    }
  }
  // strictly convex: every corner turns the same way as the normal
  for (std::int64_t i = 0; i < n; ++i)
  {
    const Vec3& a = pts[ids[(i + n - 1) % n]];
    const Vec3& b = pts[ids[i]];
    const Vec3& c = pts[ids[(i + 1) % n]];
    if ((b - a).cross(c - b).dot(normal) <= 0.0)
    {
      return false;
    }
  }
  for (std::int64_t i = 1; i + 1 < n; ++i)
  {
    out.push_back({ static_cast<int>(ids[0]), static_cast<int>(ids[i]), static_cast<int>(ids[i + 1]) });
  }
  return true;
}

struct HalfEdge
{
  std::uint64_t Key; // undirected (min << 32 | max)
  int Face;
  bool Forward; // a < b in the triangle's order
};

} // namespace

namespace
{
void checkTopology(const TriangleMesh& mesh, MeshDefects& d)
{
  const std::size_t nf = mesh.Triangles.size();
  std::vector<HalfEdge> he;
  he.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f)
  {
    const Triangle& t = mesh.Triangles[f];
    for (int k = 0; k < 3; ++k)
    {
      const std::uint32_t a = static_cast<std::uint32_t>(t[k]);
      const std::uint32_t b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
      const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
      he.push_back({ (static_cast<std::uint64_t>(lo) << 32) | hi, static_cast<int>(f), a < b });
    }
  }
  std::sort(he.begin(), he.end(), [](const HalfEdge& x, const HalfEdge& y) { return x.Key < y.Key; });
  for (std::size_t i = 0; i < he.size();)
  {
    std::size_t j = i;
    while (j < he.size() && he[j].Key == he[i].Key)
    {
      ++j;
    }
    const std::size_t count = j - i;
    if (count == 1)
    {
      ++d.BoundaryEdges;
    }
    else if (count > 2)
    {
      ++d.NonManifoldEdges;
    }
    else if (he[i].Forward == he[i + 1].Forward)
    {
      ++d.InconsistentEdges;
    }
    i = j;
  }

  // Vertex manifoldness: the triangles around a vertex, linked through shared edges, must form one
  // fan. Count fans per vertex with a small union-find over the vertex's incident triangles.
  const std::size_t nv = mesh.Points.size();
  std::vector<int> start(nv + 1, 0);
  for (const Triangle& t : mesh.Triangles)
  {
    for (int i : t)
    {
      ++start[i + 1];
    }
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int> incident(start[nv]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (std::size_t f = 0; f < nf; ++f)
  {
    for (int i : mesh.Triangles[f])
    {
      incident[fill[i]++] = static_cast<int>(f);
    }
  }
  std::vector<int> parent;
  std::vector<std::pair<int, int>> neighbourFace; // (other vertex, local triangle index)
  for (std::size_t v = 0; v < nv; ++v)
  {
    const int n = start[v + 1] - start[v];
    if (n == 0)
    {
      continue;
    }
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0);
    neighbourFace.clear();
    for (int k = 0; k < n; ++k)
    {
      const Triangle& t = mesh.Triangles[incident[start[v] + k]];
      for (int i : t)
      {
        if (i != static_cast<int>(v))
        {
          neighbourFace.emplace_back(i, k);
        }
      }
    }
    std::sort(neighbourFace.begin(), neighbourFace.end());
    auto root = [&](int x) {
      while (parent[x] != x)
      {
        parent[x] = parent[parent[x]];
        x = parent[x];
      }
      return x;
    };
    for (std::size_t i = 1; i < neighbourFace.size(); ++i)
    {
      if (neighbourFace[i].first == neighbourFace[i - 1].first)
      {
        parent[root(neighbourFace[i].second)] = root(neighbourFace[i - 1].second);
      }
    }
    int fans = 0;
    for (int k = 0; k < n; ++k)
    {
      fans += root(k) == k;
    }
    if (fans > 1)
    {
      ++d.NonManifoldVertices;
    }
  }
}
} // namespace

MeshDefects checkTriangleMesh(const TriangleMesh& mesh)
{
  MeshDefects d;
  d.Empty = mesh.Triangles.empty();
  for (const Triangle& t : mesh.Triangles)
  {
    const Vec3 n = (mesh.Points[t[1]] - mesh.Points[t[0]]).cross(mesh.Points[t[2]] - mesh.Points[t[0]]);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || n.squaredNorm() == 0.0)
    {
      ++d.DegenerateTriangles;
    }
  }
  checkTopology(mesh, d);
  std::vector<int> comp;
  d.Components = triangleComponents(mesh, comp);
  if (d.usable())
  {
    d.Genus = genus(mesh);
  }
  return d;
}

MeshDefects prepareMesh(const PolygonMesh& input, TriangleMesh& output, const ValidationOptions& options)
{
  MeshDefects d;
  output = TriangleMesh();
  const std::int64_t np = static_cast<std::int64_t>(input.Points.size());
  const std::size_t nc = input.numberOfCells();

  // 1. cells -> triangles
  output.Triangles.reserve(nc);
  std::vector<char> referenced(np, 0);
  for (std::size_t c = 0; c < nc; ++c)
  {
    const std::int64_t b = input.Offsets[c], e = input.Offsets[c + 1];
    const std::int64_t n = e - b;
    if (n < 3)
    {
      ++d.IgnoredCells;
      continue;
    }
    bool valid = true;
    for (std::int64_t k = b; k < e; ++k)
    {
      const std::int64_t id = input.Connectivity[k];
      if (id < 0 || id >= np)
      {
        valid = false;
      }
    }
    if (!valid)
    {
      ++d.InvalidPointIds;
      continue;
    }
    for (std::int64_t k = b; k < e; ++k)
    {
      referenced[input.Connectivity[k]] = 1;
    }
    if (n == 3)
    {
      output.Triangles.push_back({ static_cast<int>(input.Connectivity[b]),
        static_cast<int>(input.Connectivity[b + 1]), static_cast<int>(input.Connectivity[b + 2]) });
    }
    else if (triangulateConvex(input.Points, &input.Connectivity[b], n, output.Triangles))
    {
      ++d.TriangulatedPolygons;
    }
    else
    {
      ++d.UntriangulatedPolygons;
    }
  }
  for (std::int64_t i = 0; i < np; ++i)
  {
    if (referenced[i] && !input.Points[i].allFinite())
    {
      ++d.NonFinitePoints;
    }
    if (!referenced[i])
    {
      ++d.UnreferencedPoints;
    }
  }
  d.Empty = output.Triangles.empty();
  if (d.Empty || d.NonFinitePoints || d.InvalidPointIds)
  {
    return d; // geometry cannot be trusted further
  }
  output.Points = input.Points;
  removeUnreferencedPoints(output);

  // 2. degenerate triangles (area relative to the squared bounding-box diagonal)
  const auto box = bounds(output);
  const double diag2 = (box[1] - box[0]).squaredNorm();
  const double tol = options.DegenerateAreaTolerance * diag2;
  for (const Triangle& t : output.Triangles)
  {
    const Vec3 n = (output.Points[t[1]] - output.Points[t[0]]).cross(output.Points[t[2]] - output.Points[t[0]]);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || 0.5 * n.norm() <= tol)
    {
      ++d.DegenerateTriangles;
    }
  }

  // 3. topology
  checkTopology(output, d);
  std::vector<int> comp;
  d.Components = triangleComponents(output, comp);
  if (!d.usable())
  {
    return d;
  }

  // 4. orientation per component: a component with negative volume faces inward, unless it is a
  // cavity inside another component (then inward is right).
  std::vector<double> volume(d.Components, 0.0);
  for (std::size_t f = 0; f < output.Triangles.size(); ++f)
  {
    const Triangle& t = output.Triangles[f];
    volume[comp[f]] += output.Points[t[0]].dot(output.Points[t[1]].cross(output.Points[t[2]])) / 6.0;
  }
  std::vector<char> flip(d.Components, 0);
  for (int c = 0; c < d.Components; ++c)
  {
    if (volume[c] >= 0.0)
    {
      continue;
    }
    bool nested = false;
    if (d.Components > 1)
    {
      // a point of component c, tested against each other component
      int someVertex = -1;
      for (std::size_t f = 0; f < output.Triangles.size() && someVertex < 0; ++f)
      {
        if (comp[f] == c)
        {
          someVertex = output.Triangles[f][0];
        }
      }
      for (int o = 0; o < d.Components && !nested; ++o)
      {
        if (o == c)
        {
          continue;
        }
        TriangleMesh other;
        other.Points = output.Points;
        for (std::size_t f = 0; f < output.Triangles.size(); ++f)
        {
          if (comp[f] == o)
          {
            other.Triangles.push_back(output.Triangles[f]);
          }
        }
        nested = std::abs(windingNumber(other, output.Points[someVertex])) > 0.5;
      }
    }
    if (!nested)
    {
      flip[c] = 1;
      d.FlippedOrientation = true;
    }
  }
  if (d.FlippedOrientation)
  {
    for (std::size_t f = 0; f < output.Triangles.size(); ++f)
    {
      if (flip[comp[f]])
      {
        std::swap(output.Triangles[f][1], output.Triangles[f][2]);
      }
    }
  }
  d.Genus = genus(output);
  return d;
}

} // namespace sdfcage
