// SDFCage — tests of vtkOFFReader and vtkOFFWriter: exact round trip, format variants, and
// malformed files (clear error, empty output, no crash).
#include "SDFCageTestUtilities.h"

#include "vtkCellArray.h"
#include "vtkExecutive.h"
#include "vtkOFFReader.h"
#include "vtkOFFWriter.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"

#include <algorithm>
#include <cmath>
#include <fstream>

namespace sdfcage_test
{
namespace
{
void WriteText(const std::string& path, const std::string& text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
}

struct ReadResult
{
  vtkSmartPointer<vtkPolyData> Data;
  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
};

ReadResult Read(const std::string& path)
{
  vtkNew<vtkOFFReader> reader;
  vtkNew<MessageRecorder> messages;
  messages->Watch(reader);
  messages->Watch(reader->GetExecutive());
  reader->SetFileName(path.c_str());
  reader->Update();
  ReadResult result;
  result.Data = reader->GetOutput();
  result.Errors = messages->Errors;
  result.Warnings = messages->Warnings;
  return result;
}
} // namespace

//------------------------------------------------------------------------------
int TestOFFRoundTrip(const Context& context)
{
  Checker c("OFFRoundTrip");
  // Irregular coordinates (a sphere, shifted by a non-representable amount) and quads + triangles
  // (vtkSphereSource makes triangles only; add a quad by hand).
  vtkNew<vtkSphereSource> source;
  source->SetCenter(0.1, 1.0 / 3.0, -2.0 / 7.0);
  source->SetRadius(1e-3 * std::acos(-1.0));
  source->SetThetaResolution(13);
  source->SetPhiResolution(7);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  source->Update();
  vtkNew<vtkPolyData> mesh;
  mesh->DeepCopy(source->GetOutput());
  const vtkIdType quad[4] = { 0, 1, 2, 3 };
  mesh->GetPolys()->InsertNextCell(4, quad);

  const std::string path = context.Scratch + "/roundtrip.off";
  vtkNew<vtkOFFWriter> writer;
  vtkNew<MessageRecorder> writerMessages;
  writerMessages->Watch(writer);
  writer->SetInputData(mesh);
  writer->SetFileName(path.c_str());
  c.Check(writer->Write() == 1, "Write() succeeds");
  c.Check(writerMessages->Errors.empty(), "no writer errors");

  c.Check(vtkOFFReader::CanReadFile(path.c_str()) == 1, "CanReadFile accepts the written file");
  ReadResult read = Read(path);
  c.Check(read.Errors.empty(), "no reader errors");
  vtkPolyData* back = read.Data;
  if (!c.Check(back->GetNumberOfPoints() == mesh->GetNumberOfPoints(), "same number of points") ||
    !c.Check(back->GetNumberOfPolys() == mesh->GetNumberOfPolys(), "same number of polygons"))
  {
    return c.Result();
  }
  bool exact = true;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    double p[3], q[3];
    mesh->GetPoint(i, p);
    back->GetPoint(i, q);
    exact = exact && p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
  }
  c.Check(exact, "points read back bit-identical (17 significant digits)");
  bool sameCells = true;
  for (vtkIdType cell = 0; cell < mesh->GetNumberOfPolys(); ++cell)
  {
    vtkIdType n1 = 0, n2 = 0;
    const vtkIdType *p1 = nullptr, *p2 = nullptr;
    mesh->GetPolys()->GetCellAtId(cell, n1, p1);
    back->GetPolys()->GetCellAtId(cell, n2, p2);
    sameCells = sameCells && n1 == n2 && std::equal(p1, p1 + n1, p2);
  }
  c.Check(sameCells, "identical polygons, in order, including the quad");

  // Triangle strips are written as triangles with the strip's orientation.
  vtkNew<vtkPolyData> strip;
  strip->SetPoints(mesh->GetPoints());
  vtkNew<vtkCellArray> strips;
  const vtkIdType s[5] = { 0, 1, 2, 3, 4 };
  strips->InsertNextCell(5, s);
  strip->SetStrips(strips);
  const std::string stripPath = context.Scratch + "/strip.off";
  writer->SetInputData(strip);
  writer->SetFileName(stripPath.c_str());
  writer->Write();
  ReadResult stripRead = Read(stripPath);
  c.Check(stripRead.Data->GetNumberOfPolys() == 3, "a 5-point strip becomes 3 triangles");
  if (stripRead.Data->GetNumberOfPolys() == 3)
  {
    vtkIdType n = 0;
    const vtkIdType* p = nullptr;
    stripRead.Data->GetPolys()->GetCellAtId(1, n, p);
    c.Check(n == 3 && p[0] == 2 && p[1] == 1 && p[2] == 3, "the odd strip triangle is re-wound");
  }

  // Unwritable destination: an error, no crash.
  vtkNew<MessageRecorder> failMessages;
  vtkNew<vtkOFFWriter> failing;
  failMessages->Watch(failing);
  failMessages->Watch(failing->GetExecutive());
  failing->SetInputData(mesh);
  failing->SetFileName((context.Scratch + "/no/such/folder/x.off").c_str());
  failing->Write();
  c.Check(!failMessages->Errors.empty(), "writing into a missing folder reports an error");
  return c.Result();
}

//------------------------------------------------------------------------------
int TestOFFVariants(const Context& context)
{
  Checker c("OFFVariants");
  struct Variant
  {
    const char* Name;
    const char* Text;
    vtkIdType Points, Polys, Lines, Verts;
  };
  const Variant variants[] = {
    { "comments and blank lines",
      "# a tetrahedron\nOFF # header\n\n4 4 6 # counts\n0 0 0\n1 0 0 # v1\n0 1 0\n0 0 1\n"
      "# faces\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
      4, 4, 0, 0 },
    { "counts on the header line, no edge count", "OFF 4 1\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", 4, 1, 0, 0 },
    { "no header keyword", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 3, 1, 0, 0 },
    { "COFF with vertex and face colours",
      "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2 0.5 0.5 0.5 1\n", 3, 1, 0, 0 },
    { "NOFF with normals", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n", 3, 1, 0, 0 },
    { "STCNOFF",
      "STCNOFF\n3 1 0\n0 0 0 0 0 1 1 1 1 1 0 0\n1 0 0 0 0 1 1 1 1 1 1 0\n"
      "0 1 0 0 0 1 1 1 1 1 0 1\n3 0 1 2\n",
      3, 1, 0, 0 },
    { "pentagon, segment and point faces",
      "OFF\n5 3 0\n0 0 0\n1 0 0\n1.5 1 0\n0.5 1.5 0\n-0.5 1 0\n5 0 1 2 3 4\n2 0 2\n1 4\n", 5, 1, 1, 1 },
    { "windows line endings and scientific notation",
      "OFF\r\n3 1 0\r\n0 0 0\r\n1e0 0 0\r\n0 1.0E+00 -0e-3\r\n3 0 1 2\r\n", 3, 1, 0, 0 },
    { "no faces", "OFF\n2 0 0\n0 0 0\n1 1 1\n", 2, 0, 0, 0 },
  };
  int index = 0;
  for (const Variant& v : variants)
  {
    const std::string path = context.Scratch + "/variant" + Str(index++) + ".off";
    WriteText(path, v.Text);
    ReadResult r = Read(path);
    const std::string tag = std::string(v.Name) + ": ";
    c.Check(r.Errors.empty(), tag + "no error" + (r.Errors.empty() ? "" : " (" + r.Errors[0] + ")"));
    c.Check(r.Data->GetNumberOfPoints() == v.Points, tag + "points " + Str(r.Data->GetNumberOfPoints()));
    c.Check(r.Data->GetNumberOfPolys() == v.Polys, tag + "polygons " + Str(r.Data->GetNumberOfPolys()));
    c.Check(r.Data->GetNumberOfLines() == v.Lines, tag + "lines " + Str(r.Data->GetNumberOfLines()));
    c.Check(r.Data->GetNumberOfVerts() == v.Verts, tag + "verts " + Str(r.Data->GetNumberOfVerts()));
    c.Check(vtkOFFReader::CanReadFile(path.c_str()) == 1, tag + "CanReadFile");
  }
  // Coordinates of the COFF file are the first three numbers, not the colours.
  ReadResult coff = Read(context.Scratch + "/variant3.off");
  if (coff.Data->GetNumberOfPoints() == 3)
  {
    double p[3];
    coff.Data->GetPoint(1, p);
    c.Check(p[0] == 1 && p[1] == 0 && p[2] == 0, "COFF vertex 1 is (1, 0, 0)");
  }
  return c.Result();
}

//------------------------------------------------------------------------------
int TestOFFMalformed(const Context& context)
{
  Checker c("OFFMalformed");
  struct Case
  {
    const char* Name;
    const char* Text;
    const char* Expect; // a word the error must contain
  };
  const Case cases[] = {
    { "empty file", "", "empty" },
    { "only comments", "# nothing here\n\n", "empty" },
    { "not an OFF file", "ply\nformat ascii 1.0\n", "not an OFF header" },
    { "4D OFF", "4OFF\n1 0 0\n0 0 0 1\n", "not supported" },
    { "binary OFF", "OFF BINARY\n", "binary" },
    { "header without counts", "OFF\n", "counts" },
    { "non-numeric counts", "OFF\nthree one zero\n", "counts" },
    { "negative counts", "OFF\n-3 1 0\n", "negative" },
    { "huge counts", "OFF\n2000000000 2000000000 0\n0 0 0\n", "more than" },
    { "missing vertices", "OFF\n4 1 0\n0 0 0\n1 0 0\n", "vertices" },
    { "short vertex", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "vertex 1" },
    { "non-numeric coordinate", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", "vertex 1" },
    { "missing faces", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "faces" },
    { "index out of range", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "outside" },
    { "negative index", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "outside" },
    { "too few indices", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "face 0" },
    { "fractional index", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "face 0" },
    { "absurd face size", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n99999999999 0 1 2\n", "face 0" },
  };
  int index = 0;
  for (const Case& m : cases)
  {
    const std::string path = context.Scratch + "/malformed" + Str(index++) + ".off";
    WriteText(path, m.Text);
    ReadResult r = Read(path);
    const std::string tag = std::string(m.Name) + ": ";
    std::cout << "  " << tag << (r.Errors.empty() ? "(no error)" : r.Errors[0]) << "\n";
    c.Check(!r.Errors.empty(), tag + "an error is reported");
    bool mentions = false;
    for (const std::string& e : r.Errors)
    {
      mentions = mentions || e.find(m.Expect) != std::string::npos;
    }
    c.Check(mentions, tag + "the error mentions '" + m.Expect + "'");
    c.Check(r.Data->GetNumberOfPoints() == 0 && r.Data->GetNumberOfCells() == 0, tag + "the output is empty");
  }

  // Missing file and unset file name.
  ReadResult missing = Read(context.Scratch + "/does-not-exist.off");
  c.Check(!missing.Errors.empty() && missing.Data->GetNumberOfPoints() == 0,
    "a missing file is an error with an empty output");
  c.Check(vtkOFFReader::CanReadFile((context.Scratch + "/does-not-exist.off").c_str()) == 0,
    "CanReadFile rejects a missing file");
  c.Check(
    vtkOFFReader::CanReadFile((context.Scratch + "/malformed2.off").c_str()) == 0, "CanReadFile rejects a PLY file");
  {
    vtkNew<vtkOFFReader> reader;
    vtkNew<MessageRecorder> messages;
    messages->Watch(reader);
    messages->Watch(reader->GetExecutive());
    reader->Update();
    c.Check(messages->ErrorContains("FileName"), "no file name: the error says so");
  }
  return c.Result();
}

} // namespace sdfcage_test
