/*=========================================================================

  Program:   SDFCage
  Module:    vtkOFFReader.h

  SDFCage: cages from an SDF envelope, as VTK filters and a ParaView plugin.

=========================================================================*/
/**
 * @class   vtkOFFReader
 * @brief   read Object File Format (OFF) polygon meshes
 *
 * vtkOFFReader reads the ASCII Object File Format of Geomview, the format most test meshes of
 * the cage-generation literature ship in (the data sets of "High-quality Cage Generation Based
 * on SDF" and of libigl/CGAL). It accepts:
 * - an optional header keyword `OFF`, with the prefixes `C` (vertex colours), `N` (normals) and
 *   `ST` (texture coordinates), e.g. `COFF`, `NOFF`, `STCNOFF`; the counts may follow the
 *   keyword on the same line or on the next one; a file may also start directly with the counts;
 * - `#` comments anywhere (to the end of the line) and blank lines;
 * - one vertex per line: the first three numbers are the position, anything after them
 *   (colours, normals, texture coordinates) is ignored;
 * - one face per line: `n i_1 ... i_n` with 0-based indices, polygons of any size; anything after
 *   the indices (a face colour) is ignored. Faces of one or two points become vertex or line
 *   cells.
 *
 * The output is a vtkPolyData with double-precision points and polygon cells (not
 * triangulated).
 *
 * @warning Binary OFF (`OFF BINARY`) and the 4D/n-dimensional variants (`4OFF`, `nOFF`) are not
 * supported. A vertex or face split over several lines is not supported. Malformed files
 * (missing counts, too few vertices or faces, indices out of range, non-numeric values) are
 * reported with vtkErrorMacro naming the line, and the output is empty.
 *
 * @sa
 * vtkOFFWriter vtkSDFCageFilter vtkPLYReader vtkOBJReader
 */

#ifndef vtkOFFReader_h
#define vtkOFFReader_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class SDFCAGEFILTERS_EXPORT vtkOFFReader : public vtkPolyDataAlgorithm
{
public:
  vtkTypeMacro(vtkOFFReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  static vtkOFFReader* New();

  ///@{
  /**
   * Name of the file to read.
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  /**
   * Returns 1 if the file exists and its first meaningful line looks like an OFF header (a
   * supported keyword, or a line of two or three counts), 0 otherwise.
   */
  static int CanReadFile(const char* fileName);

protected:
  vtkOFFReader();
  ~vtkOFFReader() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName = nullptr;

private:
  vtkOFFReader(const vtkOFFReader&) = delete;
  void operator=(const vtkOFFReader&) = delete;
};

#endif
