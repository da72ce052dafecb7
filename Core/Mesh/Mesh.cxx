#include "Mesh/Mesh.h"
#include "Mesh/EdgeKey.h"

#include "Common/LargePages.h"

#include <algorithm>
#include <numeric>
#include <unordered_map>

namespace sdfcage
{

PolygonMesh PolygonMesh::fromTriangles(const TriangleMesh& mesh)
{
  PolygonMesh out;
  out.Points = mesh.Points;
  out.Offsets.reserve(mesh.Triangles.size() + 1);
  out.Connectivity.reserve(3 * mesh.Triangles.size());
  for (const Triangle& t : mesh.Triangles)
  {
    out.addCell({ t[0], t[1], t[2] });
  }
  return out;
}

double signedVolume(const TriangleMesh& mesh)
{
  double v = 0.0;
  for (const Triangle& t : mesh.Triangles)
  {
    v += mesh.Points[t[0]].dot(mesh.Points[t[1]].cross(mesh.Points[t[2]]));
  }
  return v / 6.0;
}

void reverseOrientation(TriangleMesh& mesh)
{
  for (Triangle& t : mesh.Triangles)
  {
    std::swap(t[1], t[2]);
  }
}

bool orientOutward(TriangleMesh& mesh)
{
  if (!(signedVolume(mesh) < 0.0))
  {
    return false;
  }
  reverseOrientation(mesh);
  return true;
}

namespace
{
int findRoot(std::vector<int>& parent, int i)
{
  while (parent[i] != i)
  {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}
} // namespace

PointTriangles::PointTriangles(const TriangleMesh& mesh)
  : First(mesh.Points.size() + 1, 0)
{
  for (const Triangle& t : mesh.Triangles)
    for (int v : t)
      ++First[v + 1];
  std::partial_sum(First.begin(), First.end(), First.begin());
  ReserveLarge(Triangles, First.back());
  Triangles.resize(First.back());
  std::vector<std::size_t> fill(First.begin(), First.end() - 1);
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
    for (int v : mesh.Triangles[f])
      Triangles[fill[v]++] = static_cast<int>(f);
}

int triangleComponents(const TriangleMesh& mesh, std::vector<int>& componentOfTriangle)
{
  std::vector<int> parent(mesh.Points.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const Triangle& t : mesh.Triangles)
  {
    const int r0 = findRoot(parent, t[0]);
    for (int k = 1; k < 3; ++k)
    {
      const int rk = findRoot(parent, t[k]);
      if (rk != r0)
      {
        parent[rk] = r0;
      }
    }
  }
  std::vector<int> label(mesh.Points.size(), -1);
  int count = 0;
  componentOfTriangle.assign(mesh.Triangles.size(), -1);
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    const int r = findRoot(parent, mesh.Triangles[f][0]);
    if (label[r] < 0)
    {
      label[r] = count++;
    }
    componentOfTriangle[f] = label[r];
  }
  return count;
}

std::vector<Vec3> componentProbes(const TriangleMesh& mesh)
{
  std::vector<int> comp;
  const int n = triangleComponents(mesh, comp);
  std::vector<Vec3> probes;
  probes.reserve(n);
  std::vector<char> seen(n, 0);
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    if (!seen[comp[f]])
    {
      seen[comp[f]] = 1;
      probes.push_back(mesh.Points[mesh.Triangles[f][0]]);
    }
  }
  return probes;
}

namespace
{
std::vector<std::uint64_t> uniqueEdgeKeys(const TriangleMesh& mesh, const std::vector<int>* subset)
{
  std::vector<std::uint64_t> keys;
  auto add = [&](const Triangle& t) {
    for (int k = 0; k < 3; ++k)
    {
      keys.push_back(edgeKey(t[k], t[(k + 1) % 3]));
    }
  };
  if (subset)
  {
    keys.reserve(3 * subset->size());
    for (int f : *subset)
    {
      add(mesh.Triangles[f]);
    }
  }
  else
  {
    keys.reserve(3 * mesh.Triangles.size());
    for (const Triangle& t : mesh.Triangles)
    {
      add(t);
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}
} // namespace

long long usedVertexCount(const TriangleMesh& mesh)
{
  std::vector<char> used(mesh.Points.size(), 0);
  long long v = 0;
  for (const Triangle& t : mesh.Triangles)
  {
    for (int i : t)
    {
      if (!used[i])
      {
        used[i] = 1;
        ++v;
      }
    }
  }
  return v;
}

long long eulerCharacteristic(const TriangleMesh& mesh)
{
  const long long v = usedVertexCount(mesh);
  const long long e = static_cast<long long>(uniqueEdgeKeys(mesh, nullptr).size());
  return v - e + static_cast<long long>(mesh.Triangles.size());
}

int genus(const TriangleMesh& mesh)
{
  std::vector<int> comp;
  const int n = triangleComponents(mesh, comp);
  // chi summed over components = 2n - 2g
  const long long chi = eulerCharacteristic(mesh);
  return static_cast<int>((2LL * n - chi) / 2);
}

std::array<Vec3, 2> bounds(const TriangleMesh& mesh)
{
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Triangle& t : mesh.Triangles)
  {
    for (int i : t)
    {
      lo = lo.cwiseMin(mesh.Points[i]);
      hi = hi.cwiseMax(mesh.Points[i]);
    }
  }
  return { lo, hi };
}

namespace
{
// New numbers of the points the triangles f with keep(f) use, in the mesh's order (-1 for the
// others), and how many they are.
template <typename Keep>
std::vector<int> usedPointNumbers(const TriangleMesh& mesh, Keep keep, std::size_t& used)
{
  std::vector<int> map(mesh.Points.size(), -1);
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    if (keep(f))
    {
      for (int i : mesh.Triangles[f])
        map[static_cast<std::size_t>(i)] = 0;
    }
  }
  used = 0;
  for (int& m : map)
  {
    if (m == 0)
      m = static_cast<int>(used++);
  }
  return map;
}

// to[map[i]] = from[i] for every used point i. from and to may be the same vector: a point's new
// number is never above its old one, so in place each point is read before it is overwritten
void gatherPoints(const std::vector<int>& map, const std::vector<Vec3>& from, std::vector<Vec3>& to)
{
  for (std::size_t i = 0; i < map.size(); ++i)
  {
    if (map[i] >= 0)
      to[static_cast<std::size_t>(map[i])] = from[i];
  }
}

Triangle renumbered(const Triangle& t, const std::vector<int>& map)
{
  return { map[static_cast<std::size_t>(t[0])], map[static_cast<std::size_t>(t[1])],
    map[static_cast<std::size_t>(t[2])] };
}
} // namespace

void removeUnreferencedPoints(TriangleMesh& mesh)
{
  std::size_t used = 0;
  const std::vector<int> map = usedPointNumbers(
    mesh, [](std::size_t) { return true; }, used);
  gatherPoints(map, mesh.Points, mesh.Points);
  mesh.Points.resize(used);
  for (Triangle& t : mesh.Triangles)
    t = renumbered(t, map);
}

TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<char>& keep)
{
  TriangleMesh out;
  std::size_t used = 0;
  const std::vector<int> map = usedPointNumbers(
    mesh, [&keep](std::size_t f) { return keep[f] != 0; }, used);
  out.Points.resize(used);
  gatherPoints(map, mesh.Points, out.Points);
  out.Triangles.reserve(
    static_cast<std::size_t>(std::count_if(keep.begin(), keep.end(), [](char k) { return k != 0; })));
  for (std::size_t f = 0; f < mesh.Triangles.size(); ++f)
  {
    if (keep[f])
      out.Triangles.push_back(renumbered(mesh.Triangles[f], map));
  }
  return out;
}

} // namespace sdfcage
