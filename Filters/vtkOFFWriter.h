/*=========================================================================

  Program:   SDFCage
  Module:    vtkOFFWriter.h

  SDFCage: cages from an SDF envelope, as VTK filters and a ParaView plugin.

=========================================================================*/
/**
 * @class   vtkOFFWriter
 * @brief   write polygon meshes in the ASCII Object File Format (OFF)
 *
 * vtkOFFWriter writes the points and the polygons of a vtkPolyData as an ASCII OFF file (the
 * format of Geomview, read by libigl, CGAL, MeshLab and vtkOFFReader), e.g. to hand a cage made
 * by vtkSDFCageFilter (see "High-quality Cage Generation Based on SDF") to other tools.
 * Coordinates are written with 17 significant digits, so a double-precision mesh reads back
 * bit-identical. Triangle strips are written as triangles.
 *
 * @warning Vertex and line cells, point and cell data are not written (OFF has no place for
 * them; a warning names the number of skipped cells). All points are written, referenced or
 * not, so that point ids are kept.
 *
 * @sa
 * vtkOFFReader vtkSDFCageFilter vtkPLYWriter
 */

#ifndef vtkOFFWriter_h
#define vtkOFFWriter_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkWriter.h"

class vtkPolyData;

class SDFCAGEFILTERS_EXPORT vtkOFFWriter : public vtkWriter
{
public:
  vtkTypeMacro(vtkOFFWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  static vtkOFFWriter* New();

  ///@{
  /**
   * Name of the file to write.
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  /**
   * The input of this writer.
   */
  vtkPolyData* GetInput();

protected:
  vtkOFFWriter();
  ~vtkOFFWriter() override;

  void WriteData() override;
  int FillInputPortInformation(int port, vtkInformation* info) override;

  char* FileName = nullptr;

private:
  vtkOFFWriter(const vtkOFFWriter&) = delete;
  void operator=(const vtkOFFWriter&) = delete;
};

#endif
