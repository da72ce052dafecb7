/*=========================================================================

  Program:   SDFCage
  Module:    vtkOFFWriter.cxx

=========================================================================*/
#include "vtkOFFWriter.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkErrorCode.h"
#include "vtkInformation.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtksys/FStream.hxx"

#include <cstdio>
#include <utility>

vtkStandardNewMacro(vtkOFFWriter);

//------------------------------------------------------------------------------
vtkOFFWriter::vtkOFFWriter() = default;

//------------------------------------------------------------------------------
vtkOFFWriter::~vtkOFFWriter()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------
vtkPolyData* vtkOFFWriter::GetInput()
{
  return vtkPolyData::SafeDownCast(this->Superclass::GetInput());
}

//------------------------------------------------------------------------------
int vtkOFFWriter::FillInputPortInformation(int vtkNotUsed(port), vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  return 1;
}

//------------------------------------------------------------------------------
void vtkOFFWriter::WriteData()
{
  vtkPolyData* input = this->GetInput();
  if (!input)
  {
    vtkErrorMacro("No input to write.");
    return;
  }
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("FileName is not set.");
    this->SetErrorCode(vtkErrorCode::NoFileNameError);
    return;
  }

  // Count the faces first: polygons, plus the non-degenerate triangles of the strips.
  vtkIdType numberOfFaces = input->GetNumberOfPolys();
  vtkCellArray* strips = input->GetStrips();
  if (strips && strips->GetNumberOfCells() > 0)
  {
    auto it = vtk::TakeSmartPointer(strips->NewIterator());
    vtkIdType npts = 0;
    const vtkIdType* pts = nullptr;
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
    {
      it->GetCurrentCell(npts, pts);
      for (vtkIdType i = 0; i + 2 < npts; ++i)
      {
        if (pts[i] != pts[i + 1] && pts[i + 1] != pts[i + 2] && pts[i] != pts[i + 2])
        {
          ++numberOfFaces;
        }
      }
    }
  }
  const vtkIdType skipped = input->GetNumberOfVerts() + input->GetNumberOfLines();
  if (skipped > 0)
  {
    vtkWarningMacro(<< skipped << " vertex and line cells are not written: OFF stores faces only.");
  }

  vtksys::ofstream out(this->FileName, std::ios::out | std::ios::binary);
  if (!out)
  {
    vtkErrorMacro("Cannot open " << this->FileName << " for writing.");
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
    return;
  }

  const vtkIdType numberOfPoints = input->GetNumberOfPoints();
  out << "OFF\n# written by SDFCage vtkOFFWriter\n" << numberOfPoints << " " << numberOfFaces << " 0\n";

  // %.17g round-trips every double; snprintf is several times faster than iostreams here.
  char buffer[128];
  double x[3];
  for (vtkIdType i = 0; i < numberOfPoints; ++i)
  {
    input->GetPoint(i, x);
    const int n = std::snprintf(buffer, sizeof(buffer), "%.17g %.17g %.17g\n", x[0], x[1], x[2]);
    out.write(buffer, n);
  }

  auto writeFace = [&out](vtkIdType npts, const vtkIdType* pts) {
    out << npts;
    for (vtkIdType k = 0; k < npts; ++k)
    {
      out << ' ' << pts[k];
    }
    out << '\n';
  };
  if (vtkCellArray* polys = input->GetPolys())
  {
    auto it = vtk::TakeSmartPointer(polys->NewIterator());
    vtkIdType npts = 0;
    const vtkIdType* pts = nullptr;
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
    {
      it->GetCurrentCell(npts, pts);
      writeFace(npts, pts);
    }
  }
  if (strips && strips->GetNumberOfCells() > 0)
  {
    auto it = vtk::TakeSmartPointer(strips->NewIterator());
    vtkIdType npts = 0;
    const vtkIdType* pts = nullptr;
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
    {
      it->GetCurrentCell(npts, pts);
      for (vtkIdType i = 0; i + 2 < npts; ++i)
      {
        vtkIdType tri[3] = { pts[i], pts[i + 1], pts[i + 2] };
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
        {
          continue;
        }
        if (i % 2 == 1)
        {
          std::swap(tri[0], tri[1]); // odd strip triangles are wound the other way
        }
        writeFace(3, tri);
      }
    }
  }

  out.flush();
  if (!out)
  {
    vtkErrorMacro("Writing " << this->FileName << " failed (disk full?).");
    this->SetErrorCode(vtkErrorCode::OutOfDiskSpaceError);
  }
}

//------------------------------------------------------------------------------
void vtkOFFWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}
