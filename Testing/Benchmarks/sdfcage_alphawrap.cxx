// SDFCage — Benchmarks: the peer, CGAL's 3D Alpha Wrapping, as a whole process on one file.
//
//   sdfcage_alphawrap INPUT -o WRAP.off [--alpha-ratio R] [--offset-ratio S]
//
// Reads INPUT (.off .obj .ply, with the tests' own readers), wraps it with CGAL::alpha_wrap_3
// (alpha = diagonal / R, offset = diagonal / S; defaults 20 and 600, the settings issue #13 compares
// against) and writes the wrap as OFF. Prints one line: the wrap's vertices and faces and the
// seconds spent reading, wrapping and writing. peer_benchmark.py times this program and sdfcage
// side by side, then judges both outputs with `sdfcage --check`. Benchmark only: CGAL stays a
// test dependency and no library links it.
#include "MeshIO.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace
{
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Wrap = CGAL::Surface_mesh<Point>;

double secondsSince(std::chrono::steady_clock::time_point t)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

int usage()
{
  std::cerr << "usage: sdfcage_alphawrap INPUT -o WRAP.off [--alpha-ratio R] [--offset-ratio S]\n";
  return 2;
}
} // namespace

int main(int argc, char** argv)
{
  std::string input, output;
  double alphaRatio = 20.0, offsetRatio = 600.0;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if ((a == "-o" || a == "--output") && hasValue)
      output = argv[++i];
    else if (a == "--alpha-ratio" && hasValue)
      alphaRatio = std::atof(argv[++i]);
    else if (a == "--offset-ratio" && hasValue)
      offsetRatio = std::atof(argv[++i]);
    else if (!a.empty() && a[0] != '-' && input.empty())
      input = a;
    else
      return usage();
  }
  if (input.empty() || output.empty() || !(alphaRatio > 0) || !(offsetRatio > 0))
    return usage();

  const auto t0 = std::chrono::steady_clock::now();
  sdfcage::PolygonMesh polygons;
  std::string error;
  if (!sdfcage::exact::readPolygonMesh(input, polygons, error))
  {
    std::cerr << "sdfcage_alphawrap: " << input << ": " << error << "\n";
    return 2;
  }
  sdfcage::TriangleMesh mesh;
  sdfcage::exact::fanTriangulate(polygons, mesh);
  if (mesh.Triangles.empty())
  {
    std::cerr << "sdfcage_alphawrap: " << input << ": no triangle\n";
    return 2;
  }
  std::vector<Point> points;
  points.reserve(mesh.Points.size());
  sdfcage::Vec3 lo = mesh.Points.front(), hi = lo;
  for (const sdfcage::Vec3& p : mesh.Points)
  {
    points.emplace_back(p.x(), p.y(), p.z());
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(mesh.Triangles.size());
  for (const sdfcage::Triangle& t : mesh.Triangles)
    faces.push_back({ static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
      static_cast<std::size_t>(t[2]) });
  const double readSeconds = secondsSince(t0);

  const double diagonal = (hi - lo).norm();
  const auto t1 = std::chrono::steady_clock::now();
  Wrap wrap;
  CGAL::alpha_wrap_3(points, faces, diagonal / alphaRatio, diagonal / offsetRatio, wrap);
  const double wrapSeconds = secondsSince(t1);

  const auto t2 = std::chrono::steady_clock::now();
  std::ofstream out(output);
  if (!out || !CGAL::IO::write_OFF(out, wrap, CGAL::parameters::stream_precision(17)))
  {
    std::cerr << "sdfcage_alphawrap: cannot write " << output << "\n";
    return 3;
  }
  out.close();
  std::printf("alpha_wrap_3 %s: alpha = diag/%g, offset = diag/%g: %zu vertices, %zu faces; "
              "read %.3f s, wrap %.3f s, write %.3f s\n",
    input.c_str(), alphaRatio, offsetRatio, static_cast<std::size_t>(wrap.number_of_vertices()),
    static_cast<std::size_t>(wrap.number_of_faces()), readSeconds, wrapSeconds, secondsSince(t2));
  return 0;
}
