// SDFCage — Testing: the test-side mesh readers (OFF, OBJ, PLY ascii/binary).
#include "MeshIO.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

using sdfcage::PolygonMesh;
using sdfcage::TriangleMesh;
using sdfcage::Vec3;
namespace io = sdfcage::exact;

namespace
{

std::string tempPath(const std::string& name)
{
  return ::testing::TempDir() + "sdfcage_meshio_" + name;
}

void writeText(const std::string& path, const std::string& text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// The reference: a unit square pyramid (4 base points as one quad, 4 side triangles).
const std::vector<Vec3> kPoints = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(0.5, 0.5, 0.75) };
const std::vector<std::vector<std::int64_t>> kCells = { { 0, 3, 2, 1 }, { 0, 1, 4 }, { 1, 2, 4 }, { 2, 3, 4 },
  { 3, 0, 4 } };

void expectPyramid(const PolygonMesh& mesh)
{
  ASSERT_EQ(mesh.Points.size(), kPoints.size());
  for (std::size_t i = 0; i < kPoints.size(); ++i)
  {
    EXPECT_NEAR((mesh.Points[i] - kPoints[i]).norm(), 0.0, 1e-7) << "point " << i;
  }
  ASSERT_EQ(mesh.numberOfCells(), kCells.size());
  for (std::size_t c = 0; c < kCells.size(); ++c)
  {
    const std::vector<std::int64_t> cell(
      mesh.Connectivity.begin() + mesh.Offsets[c], mesh.Connectivity.begin() + mesh.Offsets[c + 1]);
    EXPECT_EQ(cell, kCells[c]) << "cell " << c;
  }
}

template <typename T>
void putBinary(std::string& out, T value, bool bigEndian)
{
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t one = 1;
  const bool hostLittle = *reinterpret_cast<const char*>(&one) == 1;
  if (bigEndian == hostLittle)
  {
    std::reverse(bytes, bytes + sizeof(T));
  }
  out.append(bytes, sizeof(T));
}

} // namespace

TEST(MeshIO, OffWithCommentsColorsAndQuad)
{
  std::string text = "OFF\n# a comment line\n\n5 5 0\n";
  for (const Vec3& p : kPoints)
  {
    text += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "  # trailing comment\n";
  }
  for (const auto& cell : kCells)
  {
    text += std::to_string(cell.size());
    for (auto id : cell)
    {
      text += " " + std::to_string(id);
    }
    text += " 255 0 0\n"; // a face colour, ignored
  }
  const std::string path = tempPath("pyramid.off");
  writeText(path, text);
  PolygonMesh mesh;
  std::string error;
  ASSERT_TRUE(io::readPolygonMesh(path, mesh, error)) << error;
  expectPyramid(mesh);

  // Counts on the header line, upper-case extension.
  writeText(tempPath("tri.OFF"), "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  ASSERT_TRUE(io::readPolygonMesh(tempPath("tri.OFF"), mesh, error)) << error;
  EXPECT_EQ(mesh.Points.size(), 3u);
  EXPECT_EQ(mesh.numberOfCells(), 1u);
}

TEST(MeshIO, ObjWithSlashesAndNegativeIndices)
{
  std::string text = "# pyramid\nmtllib none.mtl\n";
  for (const Vec3& p : kPoints)
  {
    text += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  }
  text += "vt 0 0\nvn 0 0 1\n";
  text += "f 1/1/1 4/1/1 3/1/1 2/1/1\n"; // quad
  text += "f -5//1 -4//1 -1//1\n";       // 0 1 4, relative
  text += "f 2 3 5\nf 3 4 5\nf 4 1 5\n";
  const std::string path = tempPath("pyramid.obj");
  writeText(path, text);
  PolygonMesh mesh;
  std::string error;
  ASSERT_TRUE(io::readPolygonMesh(path, mesh, error)) << error;
  expectPyramid(mesh);
}

TEST(MeshIO, PlyAscii)
{
  std::string text = "ply\nformat ascii 1.0\ncomment test\nelement vertex 5\n"
                     "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
                     "element face 5\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& p : kPoints)
  {
    text += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + " 7\n";
  }
  for (const auto& cell : kCells)
  {
    text += std::to_string(cell.size());
    for (auto id : cell)
    {
      text += " " + std::to_string(id);
    }
    text += "\n";
  }
  const std::string path = tempPath("pyramid_ascii.ply");
  writeText(path, text);
  PolygonMesh mesh;
  std::string error;
  ASSERT_TRUE(io::readPolygonMesh(path, mesh, error)) << error;
  expectPyramid(mesh);
}

TEST(MeshIO, PlyBinaryBothEndiannesses)
{
  for (const bool big : { false, true })
  {
    // float xyz + normals, a face list with uchar count and int ids, a trailing extra property,
    // and an extra element after the faces: everything but x, y, z and the ids is skipped.
    std::string data = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
      " 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "element face 5\nproperty list uchar int vertex_indices\nproperty ushort flags\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
    for (const Vec3& p : kPoints)
    {
      for (int k = 0; k < 3; ++k)
      {
        putBinary<float>(data, static_cast<float>(p[k]), big);
      }
      for (int k = 0; k < 3; ++k)
      {
        putBinary<float>(data, 0.5f, big);
      }
    }
    for (const auto& cell : kCells)
    {
      putBinary<std::uint8_t>(data, static_cast<std::uint8_t>(cell.size()), big);
      for (auto id : cell)
      {
        putBinary<std::int32_t>(data, static_cast<std::int32_t>(id), big);
      }
      putBinary<std::uint16_t>(data, 0xBEEF, big);
    }
    putBinary<std::int32_t>(data, 0, big);
    putBinary<std::int32_t>(data, 1, big);
    const std::string path = tempPath(big ? "pyramid_be.ply" : "pyramid_le.ply");
    writeText(path, data);
    PolygonMesh mesh;
    std::string error;
    ASSERT_TRUE(io::readPolygonMesh(path, mesh, error)) << error;
    expectPyramid(mesh);

    // Truncated body: an error, not a crash.
    writeText(path, data.substr(0, data.size() - 20));
    EXPECT_FALSE(io::readPolygonMesh(path, mesh, error));
    EXPECT_NE(error.find("truncated"), std::string::npos) << error;
  }
}

TEST(MeshIO, PlyDoubleCoordinatesAndUIntIds)
{
  std::string data = "ply\nformat binary_little_endian 1.0\nelement vertex 5\n"
                     "property double x\nproperty double y\nproperty double z\n"
                     "element face 5\nproperty list uint8 uint32 vertex_index\nend_header\n";
  for (const Vec3& p : kPoints)
  {
    for (int k = 0; k < 3; ++k)
    {
      putBinary<double>(data, p[k], false);
    }
  }
  for (const auto& cell : kCells)
  {
    putBinary<std::uint8_t>(data, static_cast<std::uint8_t>(cell.size()), false);
    for (auto id : cell)
    {
      putBinary<std::uint32_t>(data, static_cast<std::uint32_t>(id), false);
    }
  }
  const std::string path = tempPath("pyramid_double.ply");
  writeText(path, data);
  PolygonMesh mesh;
  std::string error;
  ASSERT_TRUE(io::readPolygonMesh(path, mesh, error)) << error;
  expectPyramid(mesh);
}

TEST(MeshIO, ErrorsAreReported)
{
  PolygonMesh mesh;
  std::string error;
  EXPECT_FALSE(io::readPolygonMesh(tempPath("does_not_exist.off"), mesh, error));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;

  writeText(tempPath("bad.off"), "NOTOFF\n1 2 3\n");
  EXPECT_FALSE(io::readPolygonMesh(tempPath("bad.off"), mesh, error));

  writeText(tempPath("short.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n");
  EXPECT_FALSE(io::readPolygonMesh(tempPath("short.off"), mesh, error));
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;

  writeText(tempPath("mesh.stl"), "solid x\n");
  EXPECT_FALSE(io::readPolygonMesh(tempPath("mesh.stl"), mesh, error));
  EXPECT_NE(error.find("unsupported"), std::string::npos) << error;

  writeText(tempPath("noformat.ply"), "ply\nelement vertex 0\nend_header\n");
  EXPECT_FALSE(io::readPolygonMesh(tempPath("noformat.ply"), mesh, error));
}

TEST(MeshIO, FanTriangulationAndWriteRoundTrip)
{
  PolygonMesh poly;
  poly.Points = kPoints;
  for (const auto& cell : kCells)
  {
    poly.Connectivity.insert(poly.Connectivity.end(), cell.begin(), cell.end());
    poly.Offsets.push_back(static_cast<std::int64_t>(poly.Connectivity.size()));
  }
  poly.addCell({ 0, 1 }); // a line: ignored
  TriangleMesh tri;
  EXPECT_TRUE(io::fanTriangulate(poly, tri));
  EXPECT_EQ(tri.Triangles.size(), 6u); // quad -> 2, plus 4
  EXPECT_EQ(tri.Points.size(), kPoints.size());

  const std::string path = tempPath("roundtrip.off");
  ASSERT_TRUE(io::writeOFF(path, tri));
  PolygonMesh back;
  std::string error;
  ASSERT_TRUE(io::readPolygonMesh(path, back, error)) << error;
  TriangleMesh again;
  EXPECT_TRUE(io::fanTriangulate(back, again));
  EXPECT_EQ(again.Triangles, tri.Triangles);
  ASSERT_EQ(again.Points.size(), tri.Points.size());
  for (std::size_t i = 0; i < tri.Points.size(); ++i)
  {
    EXPECT_EQ(again.Points[i], tri.Points[i]); // 17 significant digits: exact
  }

  poly.addCell({ 0, 1, 42 }); // invalid id: skipped and reported
  EXPECT_FALSE(io::fanTriangulate(poly, tri));
  EXPECT_EQ(tri.Triangles.size(), 6u);
}
