// SDFCage — tests of the CLI's legacy VTK parser (Examples/CLI/CLIVTK.cxx): on files written by
// VTK's own vtkPolyDataWriter (ASCII and binary, file versions 4.2 and 5.1, with FIELD data
// holding numbers and strings, point and cell data with METADATA, triangle strips, lines and
// vertices), it must read the same points and the same triangles as vtkPolyDataReader; and it
// must refuse damaged files with a reason.
#include "CLIParsers.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataNormals.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkSphereSource.h>
#include <vtkStringArray.h>
#include <vtkStripper.h>
#include <vtkTriangleFilter.h>

#include <gtest/gtest.h>

#include <algorithm>
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
