// SDFCage — tests of the CLI's own legacy VTK and STL parsers (Examples/CLI/CLIVTK.cxx,
// CLISTL.cxx). Legacy VTK: on files written by VTK's own vtkPolyDataWriter (ASCII and binary, file
// versions 4.2 and 5.1, with FIELD data holding numbers and strings, point and cell data with
// METADATA, triangle strips, lines and vertices), it must read the same points and the same
// triangles as vtkPolyDataReader. STL: on what vtkSTLWriter writes (ASCII and binary), the same
// merged points and triangles as vtkSTLReader with merging. Both must refuse damaged files with a
// reason. OBJ: numbers bit for bit as strtod reads them, face corners as before.
#include "CLIParsers.h"
#include "CLIWriters.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPLYReader.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataNormals.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkSTLReader.h>
#include <vtkSTLWriter.h>
#include <vtkSphereSource.h>
#include <vtkStringArray.h>
#include <vtkStripper.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <array>
#include <string>
#include <vector>

namespace
{

using Triangle = std::array<long long, 3>;

/// A triangle with its smallest id first, the cyclic order (and so the orientation) kept.
Triangle canonical(long long a, long long b, long long c)
{
  if (b < a && b < c)
  {
    return { b, c, a };
  }
  if (c < a && c < b)
  {
    return { c, a, b };
  }
  return { a, b, c };
}

/// A sphere with a bit of everything a legacy POLYDATA file can hold.
vtkSmartPointer<vtkPolyData> everythingMesh(bool strips)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(13);
  sphere->SetPhiResolution(9);
  vtkNew<vtkPolyDataNormals> normals; // point normals: written with METADATA in 5.1
  normals->SetInputConnection(sphere->GetOutputPort());
  vtkSmartPointer<vtkPolyData> mesh = vtkSmartPointer<vtkPolyData>::New();
  if (strips)
  {
    vtkNew<vtkStripper> stripper;
    stripper->SetInputConnection(normals->GetOutputPort());
    stripper->Update();
    mesh->DeepCopy(stripper->GetOutput());
  }
  else
  {
    normals->Update();
    mesh->DeepCopy(normals->GetOutput());
  }
  // a line and two vertices (read past), a polygon of two points (dropped, counted)
  vtkNew<vtkCellArray> lines;
  const vtkIdType line[3] = { 0, 1, 2 };
  lines->InsertNextCell(3, line);
  mesh->SetLines(lines);
  vtkNew<vtkCellArray> verts;
  const vtkIdType vert[2] = { 3, 4 };
  verts->InsertNextCell(2, vert);
  mesh->SetVerts(verts);
  if (!strips)
  {
    const vtkIdType two[2] = { 5, 6 };
    mesh->GetPolys()->InsertNextCell(2, two);
  }
  // FIELD data with a string array (ASCII lines, binary length codes) and numbers
  vtkNew<vtkStringArray> names;
  names->SetName("names");
  names->InsertNextValue("a name with spaces");
  names->InsertNextValue(std::string(70, 'x')); // a 2-byte length in binary
  names->InsertNextValue("");
  mesh->GetFieldData()->AddArray(names);
  vtkNew<vtkDoubleArray> time;
  time->SetName("time");
  time->InsertNextValue(1.5);
  mesh->GetFieldData()->AddArray(time);
  vtkNew<vtkIntArray> ids;
  ids->SetName("ids");
  for (vtkIdType i = 0; i < mesh->GetNumberOfCells(); ++i)
  {
    ids->InsertNextValue(static_cast<int>(i));
  }
  mesh->GetCellData()->AddArray(ids);
  return mesh;
}

std::string written(vtkPolyData* mesh, bool binary, int version)
{
  vtkNew<vtkPolyDataWriter> writer;
  writer->SetInputData(mesh);
  writer->WriteToOutputStringOn();
  writer->SetFileVersion(version);
  if (binary)
  {
    writer->SetFileTypeToBinary();
  }
  writer->Write();
  return writer->GetOutputStdString();
}

void expectSameAsVTK(const std::string& bytes, bool expectSkipped)
{
  vtkNew<vtkPolyDataReader> reader;
  reader->ReadFromInputStringOn();
  reader->SetInputString(bytes);
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(reader->GetOutputPort());
  triangles->PassLinesOff();
  triangles->PassVertsOff();
  triangles->Update();
  vtkPolyData* reference = triangles->GetOutput();

  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  ASSERT_TRUE(sdfcage_cli::parseLegacyVTK(bytes.data(), bytes.size(), mesh, error)) << error;
  ASSERT_EQ(mesh.Points.size(), 3 * static_cast<std::size_t>(reference->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < reference->GetNumberOfPoints(); ++i)
  {
    double p[3];
    reference->GetPoint(i, p);
    for (int k = 0; k < 3; ++k)
    {
      ASSERT_EQ(mesh.Points[3 * i + k], p[k]) << "point " << i;
    }
  }
  std::vector<Triangle> ours, theirs;
  for (std::size_t f = 0; f + 1 < mesh.Offsets.size(); ++f)
  {
    ASSERT_EQ(mesh.Offsets[f + 1] - mesh.Offsets[f], 3); // a sphere's polygons are triangles
    const auto* c = mesh.Connectivity.data() + mesh.Offsets[f];
    ours.push_back(canonical(c[0], c[1], c[2]));
  }
  for (vtkIdType t = 0; t < reference->GetNumberOfCells(); ++t)
  {
    const vtkIdType* c = nullptr;
    vtkIdType n = 0;
    reference->GetCellPoints(t, n, c);
    if (n == 3)
    {
      theirs.push_back(canonical(c[0], c[1], c[2]));
    }
  }
  std::sort(ours.begin(), ours.end());
  std::sort(theirs.begin(), theirs.end());
  EXPECT_GT(ours.size(), 100u);
  EXPECT_EQ(ours, theirs); // the same triangles, the same orientations
  EXPECT_EQ(mesh.SkippedFaces, expectSkipped ? 1 : 0);
}

} // namespace

TEST(LegacyVTKParser, ReadsWhatVTKWritesLikeVTKReadsIt)
{
  for (const bool strips : { false, true })
  {
    vtkSmartPointer<vtkPolyData> mesh = everythingMesh(strips);
    if (strips)
    {
      ASSERT_GT(mesh->GetNumberOfStrips(), 0);
    }
    for (const bool binary : { false, true })
    {
      for (const int version : { 42, 51 })
      {
        SCOPED_TRACE(std::string(strips ? "strips, " : "polygons, ") + (binary ? "binary, " : "ascii, ") +
          "version " + std::to_string(version));
        const std::string bytes = written(mesh, binary, version);
        ASSERT_NE(bytes.find("FIELD"), std::string::npos);
        expectSameAsVTK(bytes, !strips);
      }
    }
  }
}

TEST(LegacyVTKParser, KeywordsInAnyCaseAsVTKReadsThem)
{
  const std::string text = "# vtk DataFile Version 3.0\nt\nascii\ndataset polydata\npoints 3 float\n"
                           "0 0 0 1 0 0 0 1 0\npolygons 1 4\n3 0 1 2\n";
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  ASSERT_TRUE(sdfcage_cli::parseLegacyVTK(text.data(), text.size(), mesh, error)) << error;
  EXPECT_EQ(mesh.Points.size(), 9u);
  EXPECT_EQ(mesh.Connectivity, (std::vector<std::int64_t>{ 0, 1, 2 }));
}

TEST(LegacyVTKParser, RefusesDamagedFilesWithAReason)
{
  const std::string head = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n";
  const std::string points = "POINTS 3 float\n0 0 0 1 0 0 0 1 0\n";
  struct Case
  {
    std::string bytes;
    std::string reason;
  };
  const std::vector<Case> cases = {
    { "", "empty" },
    { "hello\n", "not a legacy VTK file" },
    { "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n", "not a legacy VTK POLYDATA" },
    { "# vtk DataFile Version 3.0\nt\nTEXT\n", "ASCII or BINARY" },
    { head + "points 1000000000 float\n0 0 0\n", "more than a file of" },
    { head + "POINTS 1e34 float\n0 0 0\n", "more than a file of" },
    { head + "POINTS -3 float\n", "non-negative" },
    { head + "POINTS 3 float\n0 0 0 1 0 0 0 1\n", "the file ends after 8" },
    { head + "POINTS 3 float\n0 0 0 1 0 0 0 1 zz\n", "not a number" },
    { head + "POINTS 3 bit\n0 0 0 0 0 0 0 0 0\n", "is not read" },
    { head + points + "POLYGONS 1 4\n7 0 1 2\n", "lists 7 points" },
    { head + points + "POLYGONS 2 4\n3 0 1 2\n", "values end after 1" },
    { head + points + "POLYGONS 1 4\n3 0 1 5\n", "do not exist" },
    { head + points + "POLYGONS 1 4\n3 0 -1 2\n", "do not exist" },
    { head + points + "POLYGONS 1 4\n3 0 1.5 2\n", "not an integer" },
    { head + points + "POLYGONS 2 3\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n0 1 2\n",
      "offsets end at 4" },
    { head + points + "POLYGONS 2 3\nOFFSETS vtktypeint64\n1 3\nCONNECTIVITY vtktypeint64\n0 1 2\n",
      "start at 0" },
    { head + points + "POLYGONS 3 3\nOFFSETS vtktypeint64\n0 3 2\nCONNECTIVITY vtktypeint64\n0 1 2\n",
      "smaller than the one before" },
    { head + points + "POLYGONS 2 3\nOFFSETS vtktypeint64\n0 3\nTHE_REST vtktypeint64\n0 1 2\n",
      "CONNECTIVITY expected" },
    { head + "FIELD f 1000000000\n", "more than a file of" },
    { head + "FIELD f 1\nnames 1 5 string\na\nb\n", "strings declared, the file ends" },
    { head + "FIELD f 1\nvalues 100000 100000 float\n1 2\n", "more than" },
    { head + points + "COLOURS 3\n", "unknown section" },
    { head + points + points, "a second POINTS" },
  };
  for (const Case& c : cases)
  {
    sdfcage_cli::ParsedMesh mesh;
    std::string error;
    EXPECT_FALSE(sdfcage_cli::parseLegacyVTK(c.bytes.data(), c.bytes.size(), mesh, error)) << c.bytes;
    EXPECT_NE(error.find(c.reason), std::string::npos) << "'" << error << "' for:\n" << c.bytes;
    EXPECT_TRUE(mesh.Points.empty());
  }
}

TEST(LegacyVTKParser, BinaryStringLengthsThatLieAreRefused)
{
  std::string bytes = "# vtk DataFile Version 5.1\nt\nBINARY\nDATASET POLYDATA\nFIELD f 1\nnames 1 1 string\n";
  bytes += static_cast<char>(0xff); // a one-byte length (top bits 11): 63 bytes, only 4 follow
  bytes += "abc\n";
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  EXPECT_FALSE(sdfcage_cli::parseLegacyVTK(bytes.data(), bytes.size(), mesh, error));
  EXPECT_NE(error.find("declares 63 bytes"), std::string::npos) << error;
}

TEST(LegacyVTKParser, PointDataIsNotReadAndCannotHurt)
{
  // SCALARS with a billion components on 3 points: not read (made vtkPolyDataReader allocate GBs)
  const std::string text = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n"
                           "0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 2\nPOINT_DATA 3\n"
                           "SCALARS s float 1000000000\nLOOKUP_TABLE default\n0 1 2\n";
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  ASSERT_TRUE(sdfcage_cli::parseLegacyVTK(text.data(), text.size(), mesh, error)) << error;
  EXPECT_EQ(mesh.Offsets.size(), 2u);
}

namespace
{

using CornerTriangle = std::array<std::array<double, 3>, 3>;

/// The triangles as corner coordinates, each rotated to start at its smallest corner, sorted.
std::vector<CornerTriangle> cornerTriangles(const std::vector<double>& points, const std::vector<std::int64_t>& ids)
{
  std::vector<CornerTriangle> out;
  for (std::size_t t = 0; t + 2 < ids.size(); t += 3)
  {
    CornerTriangle tri;
    for (int c = 0; c < 3; ++c)
    {
      for (int k = 0; k < 3; ++k)
      {
        tri[c][k] = points[3 * static_cast<std::size_t>(ids[t + c]) + k];
      }
    }
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string fileBytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

} // namespace

// An element without properties takes no bytes whatever its count, so the count is not bounded
// by the file's size: nothing may be reserved for it (a 'face' element of 948 million such made
// the parser reserve 7.6 GB; found by fuzz_mesh_parsers, kept as its regression input).
TEST(PLYParser, AnElementWithoutPropertiesReservesNothing)
{
  const std::string text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 100000000\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  ASSERT_TRUE(sdfcage_cli::parsePLY(text.data(), text.size(), mesh, error)) << error;
  EXPECT_EQ(mesh.Points.size(), 9u);
  EXPECT_EQ(mesh.Offsets.size(), 1u); // no face read
  EXPECT_LT(mesh.Offsets.capacity(), 1000u);
  EXPECT_LT(mesh.Connectivity.capacity(), 1000u);
}

TEST(STLParser, ReadsWhatVTKWritesLikeVTKReadsIt)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(13);
  sphere->SetPhiResolution(9);
  for (const bool binary : { false, true })
  {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const std::string path = std::string("sdfcage_parser_test_") + (binary ? "binary" : "ascii") + ".stl";
    vtkNew<vtkSTLWriter> writer;
    writer->SetInputConnection(sphere->GetOutputPort());
    writer->SetFileName(path.c_str());
    if (binary)
    {
      writer->SetFileTypeToBinary();
    }
    else
    {
      writer->SetFileTypeToASCII();
    }
    writer->Write();
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(path.c_str());
    reader->MergingOn();
    reader->Update();
    vtkPolyData* reference = reader->GetOutput();

    const std::string bytes = fileBytes(path);
    std::remove(path.c_str());
    sdfcage_cli::ParsedMesh mesh;
    std::string error;
    ASSERT_TRUE(sdfcage_cli::parseSTL(bytes.data(), bytes.size(), mesh, error)) << error;
    ASSERT_EQ(mesh.Points.size(), 3 * static_cast<std::size_t>(reference->GetNumberOfPoints()));
    ASSERT_EQ(mesh.Offsets.size() - 1, static_cast<std::size_t>(reference->GetNumberOfPolys()));
    std::vector<double> theirPoints(3 * reference->GetNumberOfPoints());
    for (vtkIdType i = 0; i < reference->GetNumberOfPoints(); ++i)
    {
      reference->GetPoint(i, theirPoints.data() + 3 * i);
    }
    std::vector<std::int64_t> theirIds;
    for (vtkIdType t = 0; t < reference->GetNumberOfPolys(); ++t)
    {
      const vtkIdType* c = nullptr;
      vtkIdType n = 0;
      reference->GetCellPoints(t, n, c);
      ASSERT_EQ(n, 3);
      theirIds.insert(theirIds.end(), c, c + 3);
    }
    EXPECT_EQ(mesh.Connectivity.size(), theirIds.size());
    EXPECT_EQ(cornerTriangles(mesh.Points, mesh.Connectivity), cornerTriangles(theirPoints, theirIds));
    EXPECT_EQ(mesh.Points.size() / 3, 93u); // a closed 13 x 9 sphere: 13 * 7 + 2 points, merged
  }
}

TEST(STLParser, BinaryAndASCIIEdgeCases)
{
  // a binary file whose header starts with "solid" (as some exporters write): read as binary,
  // since its size is what its count says
  std::string binary(80, ' ');
  binary.replace(0, 9, "solid abc");
  const std::uint32_t one = 1;
  binary.append(reinterpret_cast<const char*>(&one), 4);
  const float corners[12] = { 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0 }; // normal, then 3 corners
  binary.append(reinterpret_cast<const char*>(corners), sizeof(corners));
  binary.append(2, '\0');
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  ASSERT_TRUE(sdfcage_cli::parseSTL(binary.data(), binary.size(), mesh, error)) << error;
  EXPECT_EQ(mesh.Points, (std::vector<double>{ 0, 0, 0, 1, 0, 0, 0, 1, 0 }));

  // ASCII in any case, two solids, a facet of two corners skipped, shared corners merged
  const std::string text = "SOLID one\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
                           "   vertex 0 1 0\n  endloop\n endfacet\nendsolid one\nsolid two\nFacet Normal 0 0 1\n"
                           "Outer Loop\nVertex 1 0 0\nVertex 1 1 0\nVertex 0 1 0\nEndLoop\nEndFacet\n"
                           "facet normal 0 0 1\nouter loop\nvertex 5 5 5\nvertex 6 6 6\nendloop\nendfacet\nendsolid\n";
  ASSERT_TRUE(sdfcage_cli::parseSTL(text.data(), text.size(), mesh, error)) << error;
  EXPECT_EQ(mesh.Points.size(), 3u * 6u); // 4 used, 2 of the facet dropped (kept, as other readers keep them)
  EXPECT_EQ(mesh.Offsets.size(), 3u);
  EXPECT_EQ(mesh.SkippedFaces, 1);

  struct Case
  {
    std::string bytes;
    std::string reason;
  };
  std::string truncated = binary.substr(0, binary.size() - 10);
  std::string noTriangles = binary.substr(0, 80) + std::string(4, '\0');
  const std::vector<Case> cases = {
    { "", "empty" },
    { "solid x\nendsolid x\n", "no triangles" },
    { noTriangles, "no triangles" },
    { truncated, "declares 1 triangles" },
    { "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zz\n", "three numbers" },
    { "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nendfacet\n", "'vertex' or 'endloop'" },
    { "solid c\n" + std::string(200, '\x83'), "nor a binary one" },
    { "garbage", "at least 84 bytes" },
  };
  for (const Case& c : cases)
  {
    EXPECT_FALSE(sdfcage_cli::parseSTL(c.bytes.data(), c.bytes.size(), mesh, error)) << c.bytes;
    EXPECT_NE(error.find(c.reason), std::string::npos) << "'" << error << "'";
    EXPECT_TRUE(mesh.Points.empty());
  }
}

// ---------------------------------------------------------------------------------------------
// VTK XML with appended data moved inline (Examples/CLI/CLIVTP.cxx): on what vtkXMLPolyDataWriter
// writes in appended mode (raw and base64, compressed in small blocks and not, UInt32 and UInt64
// headers, both byte orders), the inlined file must have no appended data left and must read
// back, from a string, to the same points, triangles and point and field data as the writer was
// given. With the expat of an up-to-date Debian 12, VTK 9.1 cannot read the appended original.

namespace
{

vtkSmartPointer<vtkPolyData> readXMLString(const std::string& text)
{
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->ReadFromInputStringOn();
  reader->SetInputString(text);
  reader->Update();
  return reader->GetOutput();
}

std::string appendedSphere(vtkPolyData* mesh, bool raw, bool compressed, bool uint64, bool bigEndian)
{
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(mesh);
  writer->WriteToOutputStringOn();
  writer->SetDataModeToAppended();
  writer->SetEncodeAppendedData(!raw);
  if (compressed)
  {
    writer->SetCompressorTypeToZLib();
    writer->SetBlockSize(512); // several blocks per array
  }
  else
  {
    writer->SetCompressorTypeToNone();
  }
  if (uint64)
  {
    writer->SetHeaderTypeToUInt64();
  }
  else
  {
    writer->SetHeaderTypeToUInt32();
  }
  if (bigEndian)
  {
    writer->SetByteOrderToBigEndian();
  }
  else
  {
    writer->SetByteOrderToLittleEndian();
  }
  writer->Write();
  return writer->GetOutputString();
}

/// Every cell of `mesh` (polygons, lines, vertices) as its point ids, in order.
std::vector<std::vector<vtkIdType>> cells(vtkPolyData* mesh)
{
  std::vector<std::vector<vtkIdType>> out;
  for (vtkIdType c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    const vtkIdType* ids = nullptr;
    vtkIdType n = 0;
    mesh->GetCellPoints(c, n, ids);
    out.emplace_back(ids, ids + n);
  }
  return out;
}

} // namespace

TEST(AppendedXML, InlinedReadsBackToWhatWasWritten)
{
  const vtkSmartPointer<vtkPolyData> mesh = everythingMesh(false);
  for (int c = 0; c < 16; ++c)
  {
    const bool raw = c & 1, compressed = c & 2, uint64 = c & 4, bigEndian = c & 8;
    SCOPED_TRACE(::testing::Message() << "raw " << raw << " compressed " << compressed << " UInt64 " << uint64
                                      << " big-endian " << bigEndian);
    const std::string appended = appendedSphere(mesh, raw, compressed, uint64, bigEndian);
    ASSERT_NE(appended.find("<AppendedData"), std::string::npos);
    std::string inlined;
    std::string error;
    ASSERT_TRUE(sdfcage_cli::inlineAppendedXML(appended, inlined, error)) << error;
    EXPECT_EQ(inlined.find("<AppendedData"), std::string::npos);
    EXPECT_EQ(inlined.find("format=\"appended\""), std::string::npos);
    const vtkSmartPointer<vtkPolyData> back = readXMLString(inlined);
    ASSERT_EQ(back->GetNumberOfPoints(), mesh->GetNumberOfPoints());
    ASSERT_EQ(back->GetNumberOfPolys(), mesh->GetNumberOfPolys());
    for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
    {
      double a[3], b[3];
      mesh->GetPoint(i, a);
      back->GetPoint(i, b);
      ASSERT_EQ(a[0], b[0]);
      ASSERT_EQ(a[1], b[1]);
      ASSERT_EQ(a[2], b[2]);
    }
    EXPECT_EQ(cells(back), cells(mesh));
    for (vtkIdType i : { vtkIdType(0), mesh->GetNumberOfCells() - 1 })
    {
      EXPECT_EQ(back->GetCellData()->GetArray("ids")->GetTuple1(i), static_cast<double>(i));
    }
    vtkDataArray* normals = back->GetPointData()->GetArray("Normals");
    ASSERT_NE(normals, nullptr);
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_EQ(normals->GetTuple3(7)[k], mesh->GetPointData()->GetArray("Normals")->GetTuple3(7)[k]);
    }
    auto* names = vtkStringArray::SafeDownCast(back->GetFieldData()->GetAbstractArray("names"));
    ASSERT_NE(names, nullptr);
    ASSERT_EQ(names->GetNumberOfValues(), 3);
    EXPECT_EQ(names->GetValue(1), std::string(70, 'x'));
    vtkDataArray* time = back->GetFieldData()->GetArray("time");
    ASSERT_NE(time, nullptr);
    EXPECT_EQ(time->GetTuple1(0), 1.5);
  }
}

TEST(AppendedXML, InlineFilesAreCopiedAndDamagedOnesRefusedWithAReason)
{
  const vtkSmartPointer<vtkPolyData> mesh = everythingMesh(false);
  {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(mesh);
    writer->WriteToOutputStringOn();
    writer->SetDataModeToBinary();
    writer->Write();
    std::string out, error;
    ASSERT_TRUE(sdfcage_cli::inlineAppendedXML(writer->GetOutputString(), out, error));
    EXPECT_EQ(out, writer->GetOutputString());
  }
  const std::string raw = appendedSphere(mesh, true, true, true, false);
  const std::string base64 = appendedSphere(mesh, false, false, false, false);
  auto cut = [](const std::string& s, std::size_t keep) {
    // the appended data shortened to `keep` bytes after '_', the closing tags kept
    const std::size_t u = s.find('_', s.find("<AppendedData"));
    return s.substr(0, u + 1 + keep) + "\n  </AppendedData>\n</VTKFile>\n";
  };
  auto replaced = [](std::string s, const std::string& from, const std::string& to) {
    const std::size_t at = s.find(from);
    if (at != std::string::npos)
    {
      s.replace(at, from.size(), to);
    }
    return s;
  };
  struct Case
  {
    std::string bytes;
    std::string reason;
  };
  const std::vector<Case> cases = {
    { cut(raw, raw.rfind("</AppendedData>") - raw.find('_', raw.find("<AppendedData")) - 21),
      "runs past the appended data" },
    { cut(raw, 5), "beyond the appended data" },
    { cut(base64, 0), "beyond the appended data" },
    { replaced(raw, "offset=\"0\"", "offset=\"99999999999\""), "beyond the appended data" },
    { replaced(raw, "offset=\"0\"", "offset=\"-1\""), "no offset" },
    { replaced(raw, "encoding=\"raw\"", "encoding=\"hex\""), "unknown encoding 'hex'" },
    { replaced(raw, "header_type=\"UInt64\"", "header_type=\"Int8\""), "'Int8' is not UInt32" },
    { replaced(raw, "</AppendedData>", "</Appended>"), "no </AppendedData>" },
    { replaced(raw, "<VTKFile", "<VTK_File"), "no <VTKFile>" },
  };
  for (const Case& c : cases)
  {
    std::string out, error;
    EXPECT_FALSE(sdfcage_cli::inlineAppendedXML(c.bytes, out, error)) << c.reason;
    EXPECT_NE(error.find(c.reason), std::string::npos) << "'" << error << "' for '" << c.reason << "'";
  }
  // a compressed header whose block count is huge: refused before anything is allocated
  std::string huge = raw;
  const std::size_t u = huge.find('_', huge.find("<AppendedData"));
  for (int b = 0; b < 8; ++b)
  {
    huge[u + 1 + b] = static_cast<char>(0x7f);
  }
  std::string out, error;
  EXPECT_FALSE(sdfcage_cli::inlineAppendedXML(huge, out, error));
  EXPECT_NE(error.find("more blocks"), std::string::npos) << error;
  // an uncompressed array whose byte count is huge
  std::string big = appendedSphere(mesh, true, false, false, false);
  const std::size_t v = big.find('_', big.find("<AppendedData"));
  for (int b = 0; b < 4; ++b)
  {
    big[v + 1 + b] = static_cast<char>(0x7f);
  }
  EXPECT_FALSE(sdfcage_cli::inlineAppendedXML(big, out, error));
  EXPECT_NE(error.find("size runs past"), std::string::npos) << error;
}

// The OBJ parser reads numbers with std::from_chars and falls back to strtod for what only strtod
// accepts: every coordinate must be the very double strtod gives (bit for bit), including a
// leading '+', hex floats, overflow to inf, "nan", denormals and many digits; and face corners
// (a, a/t, a//n, a/t/n, signed, relative) as strtoll read them before.
TEST(OBJParser, NumbersAreWhatStrtodReadsAndIndicesWhatStrtollReads)
{
  std::vector<std::string> words = { "0", "-0", "+1.5", "1e400", "-1e400", "nan", "inf", "-inf", "0x1.8p1", "1e-320",
    "2.2250738585072014e-308", "0.1", ".5", "5.", "-.25e+2", "123456789012345678901234567890",
    "0.333333333333333314829616256247390992939472198486328125", "1E5", "+.0e-0" };
  // and many random values printed the ways exporters print them
  unsigned seed = 12345u;
  auto next = [&seed]() {
    seed = seed * 1664525u + 1013904223u;
    return seed;
  };
  for (int i = 0; i < 600; ++i)
  {
    const double v =
      (static_cast<double>(next()) / 4294967296.0 - 0.5) * std::pow(10.0, static_cast<int>(next() % 13) - 6);
    char buffer[64];
    const char* formats[] = { "%.17g", "%.6f", "%e", "%.9g", "%.3e" };
    std::snprintf(buffer, sizeof buffer, formats[i % 5], v);
    words.push_back(buffer);
  }
  while (words.size() % 3 != 0)
    words.push_back("7");
  std::string text = "# comment\nmtllib a.mtl\no part\n";
  for (std::size_t i = 0; i < words.size(); i += 3)
    text += "v " + words[i] + "\t" + words[i + 1] + "  " + words[i + 2] + " 1.0\r\n";
  text += "vt 0.5 0.5\nvn 0 0 1\ns off\n";
  text += "f 1 2 3\nf 1/1 2/1 3/1\nf 1//1 2//1 3//1\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -3 -2 -1\nf +1 +2 +3\nf 1 2\n";
  sdfcage_cli::ParsedMesh mesh;
  std::string error;
  ASSERT_TRUE(sdfcage_cli::parseOBJ(text.data(), text.size(), mesh, error)) << error;
  ASSERT_EQ(mesh.Points.size(), words.size());
  for (std::size_t i = 0; i < words.size(); ++i)
  {
    const double expected = std::strtod(words[i].c_str(), nullptr);
    const double got = mesh.Points[i];
    if (std::isnan(expected))
      EXPECT_TRUE(std::isnan(got)) << words[i];
    else
      EXPECT_EQ(std::memcmp(&expected, &got, sizeof got), 0) << words[i] << ": " << got << " against " << expected;
  }
  const std::int64_t n = static_cast<std::int64_t>(words.size() / 3);
  const std::vector<std::int64_t> offsets = { 0, 3, 6, 9, 13, 16, 19 };
  const std::vector<std::int64_t> connectivity = { 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 3, n - 3, n - 2, n - 1, 0, 1,
    2 };
  EXPECT_EQ(mesh.Offsets, offsets);
  EXPECT_EQ(mesh.Connectivity, connectivity);
  EXPECT_EQ(mesh.SkippedFaces, 1);

  // refused, each with a reason naming the line
  for (const char* bad : { "v 1 2\n", "v 1 2 x\n", "v 1 2 3e\n", "v 1 2 --3\n", "v 1 2 ++3\n", "v 1 2 3\nf 1a 1 1\n",
         "v 1 2 3\nf ++1 1 1\n", "v 1 2 3\nf 0 1 1\n", "v 1 2 3\nf 1 1 2\n", "v 1 2 3\nf -2 1 1\n",
         "v 1 2 3\nf 99999999999999999999999 1 1\n", "v 1 2 3\nf /1 1 1\n", "v 1 2 3\nf - 1 1\n" })
  {
    const std::string b(bad);
    error.clear();
    EXPECT_FALSE(sdfcage_cli::parseOBJ(b.data(), b.size(), mesh, error)) << b;
    EXPECT_NE(error.find("line "), std::string::npos) << b << ": " << error;
  }
}

// The program's own OBJ, PLY and STL writers (CLIWriters.h): what they write reads back, with our
// parsers and with VTK's readers, to the same points (bit for bit for OBJ and PLY, which keep
// doubles, except through vtkPLYReader, which keeps floats; as 32-bit floats for STL) and the
// same faces (a quad fanned into two triangles in STL).
TEST(Writers, WhatIsWrittenReadsBackWithOurParsersAndVTKs)
{
  sdfcage_cli::ParsedMesh mesh;
  unsigned seed = 3u;
  for (int i = 0; i < 42; ++i)
  {
    seed = seed * 1664525u + 1013904223u;
    mesh.Points.push_back((static_cast<double>(seed) / 4294967296.0 - 0.5) * std::pow(10.0, i % 7 - 3));
  }
  mesh.Points.insert(mesh.Points.end(), { 0.1, 1e-300, -0.0, 1.0 / 3.0, 2.0 / 3.0, 123456.789 });
  const std::int64_t n = static_cast<std::int64_t>(mesh.Points.size() / 3);
  mesh.Offsets = { 0 };
  for (std::int64_t f = 0; f + 2 < n; ++f)
  {
    mesh.Connectivity.insert(mesh.Connectivity.end(), { f, f + 1, f + 2 });
    mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));
  }
  mesh.Connectivity.insert(mesh.Connectivity.end(), { 0, 1, 2, 3 }); // a quad
  mesh.Offsets.push_back(static_cast<std::int64_t>(mesh.Connectivity.size()));

  for (const std::string ext : { ".obj", ".ply", ".stl" })
  {
    SCOPED_TRACE(ext);
    const std::string path = "sdfcage_writer_test" + ext;
    std::string error;
    const bool written = ext == ".obj" ? sdfcage_cli::writeOBJ(mesh, path, error)
      : ext == ".ply"                  ? sdfcage_cli::writePLY(mesh, path, error)
                                       : sdfcage_cli::writeSTL(mesh, path, error);
    ASSERT_TRUE(written) << error;
    const std::string bytes = fileBytes(path);
    sdfcage_cli::ParsedMesh back;
    const bool parsed = ext == ".obj" ? sdfcage_cli::parseOBJ(bytes.data(), bytes.size(), back, error)
      : ext == ".ply"                 ? sdfcage_cli::parsePLY(bytes.data(), bytes.size(), back, error)
                                      : sdfcage_cli::parseSTL(bytes.data(), bytes.size(), back, error);
    ASSERT_TRUE(parsed) << error;
    vtkSmartPointer<vtkPolyData> theirs;
    if (ext == ".obj")
    {
      vtkNew<vtkOBJReader> reader;
      reader->SetFileName(path.c_str());
      reader->Update();
      theirs = reader->GetOutput();
    }
    else if (ext == ".ply")
    {
      vtkNew<vtkPLYReader> reader;
      reader->SetFileName(path.c_str());
      reader->Update();
      theirs = reader->GetOutput();
    }
    else
    {
      vtkNew<vtkSTLReader> reader;
      reader->SetFileName(path.c_str());
      reader->MergingOff();
      reader->Update();
      theirs = reader->GetOutput();
    }
    if (ext != ".stl")
    {
      // the same points (bit for bit) and faces, read by us and by VTK
      EXPECT_EQ(back.Points, mesh.Points);
      EXPECT_EQ(back.Offsets, mesh.Offsets);
      EXPECT_EQ(back.Connectivity, mesh.Connectivity);
      ASSERT_EQ(theirs->GetNumberOfPoints(), n);
      ASSERT_EQ(theirs->GetNumberOfPolys(), static_cast<vtkIdType>(mesh.Offsets.size() - 1));
      for (vtkIdType i = 0; i < n; ++i)
      {
        double p[3];
        theirs->GetPoint(i, p);
        for (int k = 0; k < 3; ++k)
        {
          const double expected = mesh.Points[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(k)];
          // (vtkPLYReader keeps floats whatever the file holds)
          EXPECT_EQ(p[k], ext == ".ply" ? static_cast<double>(static_cast<float>(expected)) : expected) << i;
        }
      }
    }
    else
    {
      // each face fanned into triangles, every corner a 32-bit float of the point
      const std::size_t triangles = mesh.Offsets.size() - 2 + 2;
      ASSERT_EQ(back.Offsets.size(), triangles + 1);
      ASSERT_EQ(theirs->GetNumberOfPolys(), static_cast<vtkIdType>(triangles));
      std::size_t t = 0;
      for (std::size_t f = 0; f + 1 < mesh.Offsets.size(); ++f)
        for (std::int64_t k = mesh.Offsets[f] + 1; k + 1 < mesh.Offsets[f + 1]; ++k, ++t)
        {
          const std::int64_t corners[3] = { mesh.Connectivity[static_cast<std::size_t>(mesh.Offsets[f])],
            mesh.Connectivity[static_cast<std::size_t>(k)], mesh.Connectivity[static_cast<std::size_t>(k + 1)] };
          vtkIdType npts = 0;
          const vtkIdType* ids = nullptr;
          theirs->GetPolys()->GetCellAtId(static_cast<vtkIdType>(t), npts, ids);
          ASSERT_EQ(npts, 3);
          for (int c = 0; c < 3; ++c)
          {
            double p[3];
            theirs->GetPoint(ids[c], p);
            const double* q =
              &back.Points[3 * static_cast<std::size_t>(back.Connectivity[3 * t + static_cast<std::size_t>(c)])];
            for (int a = 0; a < 3; ++a)
            {
              const float expected =
                static_cast<float>(mesh.Points[3 * static_cast<std::size_t>(corners[c]) + static_cast<std::size_t>(a)]);
              EXPECT_EQ(p[a], static_cast<double>(expected));
              EXPECT_EQ(q[a], static_cast<double>(expected));
            }
          }
        }
    }
  }
  // an unwritable path: false with a reason naming it, no crash
  std::string error;
  EXPECT_FALSE(sdfcage_cli::writeOBJ(mesh, "no/such/folder/x.obj", error));
  EXPECT_NE(error.find("no/such/folder/x.obj"), std::string::npos) << error;
  EXPECT_FALSE(sdfcage_cli::writePLY(mesh, "no/such/folder/x.ply", error));
  EXPECT_FALSE(sdfcage_cli::writeSTL(mesh, "no/such/folder/x.stl", error));
}
