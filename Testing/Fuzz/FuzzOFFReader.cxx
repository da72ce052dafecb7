// SDFCage — fuzz harness: vtkOFFReader (Filters) on any bytes, through a file as a user would.
// An accepted file must give cells whose indices are all inside the points; a refused one an
// error code.
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkErrorCode.h"
#include "vtkNew.h"
#include "vtkOFFReader.h"
#include "vtkObject.h"
#include "vtkPolyData.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  static const std::string path = "/dev/shm/sdfcage_fuzz_off_" + std::to_string(getpid()) + ".off";
  vtkObject::GlobalWarningDisplayOff();
  if (std::FILE* f = std::fopen(path.c_str(), "wb"))
  {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  vtkNew<vtkOFFReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkPolyData* out = reader->GetOutput();
  if (reader->GetErrorCode() == vtkErrorCode::NoError)
  {
    const vtkIdType n = out->GetNumberOfPoints();
    for (vtkCellArray* cells : { out->GetPolys(), out->GetLines(), out->GetVerts() })
    {
      auto it = vtk::TakeSmartPointer(cells->NewIterator());
      for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
      {
        vtkIdType count;
        const vtkIdType* ids;
        it->GetCurrentCell(count, ids);
        for (vtkIdType k = 0; k < count; ++k)
        {
          if (ids[k] < 0 || ids[k] >= n)
          {
            std::abort();
          }
        }
      }
    }
  }
  return 0;
}
