/*=========================================================================

  Program:   SDFCage
  Module:    vtkCageQualityFilter.h

  SDFCage: cages from an SDF envelope, as VTK filters and a ParaView plugin.

=========================================================================*/
/**
 * @class   vtkCageQualityFilter
 * @brief   judge a cage against the mesh it should enclose: distances, shape, enclosure verdict
 *
 * Input 0 is a cage (any surface mesh: made by vtkSDFCageFilter or by another program, and
 * possibly broken), input 1 (SetSourceConnection / SetSourceData) is the mesh it should
 * enclose. The output is the cage with
 * - point array `DistanceToInput`: exact distance of each cage point to the input;
 * - cell arrays `DistanceToInput` (the largest distance to the input found on the cell: its
 *   corners, at least 16 quadrature points and the Hausdorff search samples), `MinimumAngle`
 *   (degrees) and `MIPSEnergy` (the MIPS energy of "High-quality Cage Generation Based on SDF",
 *   eq. 8, against an equilateral reference: 2 for an equilateral triangle, +inf degenerate);
 * - field data (one-tuple arrays, named like the getters): `Encloses` (0/1), `MinimumClearance`,
 *   `HausdorffCageToInput`, `HausdorffInputToCage`, `MeanDistanceCageToInput` (each also as
 *   `...Relative`, divided by the input's bounding-box diagonal), the certified upper bounds
 *   `HausdorffCageToInputBound`, `HausdorffInputToCageBound`, the counts `SelfIntersections`,
 *   `InputIntersections`, `InputVerticesOutside`, `CageGenus`, `InputGenus` (-1 when not a
 *   closed 2-manifold), `QualityTime` (seconds) and the string array `QualityMessage` (why the
 *   cage does not enclose, empty when it does).
 *
 * Encloses is exact in effect, never sampled: the cage is a closed, consistently oriented
 * 2-manifold without degenerate triangles, no two non-adjacent cage triangles intersect or touch,
 * no cage triangle intersects or touches an input triangle, and every input vertex is strictly
 * inside (odd winding number). Touching means a computed triangle–triangle distance below 1e-10 of
 * the larger bounding-box diagonal (what the double-precision predicates of Core cannot tell
 * from contact), so a cage that keeps 1e-6 of the diagonal is judged enclosing and one that
 * touches is not. The
 * Hausdorff distances are found by branch and bound over the surfaces (the distance is
 * 1-Lipschitz) to within 1e-4 of the diagonal; the mean distance is a midpoint-rule quadrature
 * (at least 16 points per cage triangle, sub-triangles of at most 2% of the diagonal).
 *
 * The work is done by SDFCage::Core (sdfcage::evaluateCage) with TBB threads; results do not
 * depend on the number of threads. GetAbortExecute() stops at the next phase with an empty
 * output.
 *
 * @warning Polygons and triangle strips of either mesh are fan-triangulated; a cell's values are
 * then aggregated over its triangles (max distance, min angle, max MIPS energy). Vertex and line
 * cells are ignored (their cell values are NaN). A broken cage (open, non-manifold,
 * self-intersecting, invalid ids) is not an error: it is judged, Encloses is 0 and
 * QualityMessage says why. An empty cage gives an empty output; an empty input mesh gives the
 * cage with Encloses 0.
 *
 * Nested cages: input 0 may also be a vtkMultiBlockDataSet of cage levels, innermost (finest)
 * first, as vtkSDFCageFilter's "Nested Cages" port (3) gives them (blocks "cage_2000",
 * "cage_500", ...). Then the output is a vtkMultiBlockDataSet with the same blocks and names
 * (GetOutput() returns null: use GetOutputDataObject(0)), each block the level judged as above
 * against the next level in: the first block against the mesh of input 1, every other block
 * against the last non-empty block before it. Each block carries its own arrays and results
 * field data, plus the string array `JudgedAgainst` ("input" or the inner block's name). The
 * filter's results (the getters) are those of the first level that does not enclose the one
 * inside it, else of the outermost level, so GetEncloses() is true only when every level
 * encloses the next one in. An empty block (a level that was not reached) gives an empty block
 * and is skipped as an inner level; a block that is not a vtkPolyData is an error (empty
 * output).
 *
 * Under MPI, when each process is given its piece of the cage and of the mesh, both are gathered
 * on process 0 and judged there (see vtkSDFCageFilter): process 0 outputs the serial result, the
 * others an empty output with the same results field data. Nested levels the same way: every
 * level's pieces and the mesh's are joined on process 0 and judged there; the other processes
 * output the same blocks, empty, and report process 0's results.
 *
 * @sa
 * vtkSDFCageFilter vtkDistancePolyDataFilter vtkMeshQuality
 */

#ifndef vtkCageQualityFilter_h
#define vtkCageQualityFilter_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <memory> // For the results table

class vtkMultiBlockDataSet;
class vtkMultiProcessController;
#include <string> // For the message

class SDFCAGEFILTERS_EXPORT vtkCageQualityFilter : public vtkPolyDataAlgorithm
{
public:
  vtkTypeMacro(vtkCageQualityFilter, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  static vtkCageQualityFilter* New();

  ///@{
  /**
   * The mesh the cage should enclose (input port 1).
   */
  void SetSourceConnection(vtkAlgorithmOutput* algOutput);
  void SetSourceData(vtkPolyData* source);
  vtkPolyData* GetSource();
  ///@}

  ///@{
  /**
   * Accuracy of the Hausdorff distances, relative to the input's bounding-box diagonal
   * (default 1e-4): the reported value and its certified bound differ by at most this much
   * unless the evaluation budget runs out.
   */
  vtkSetClampMacro(HausdorffTolerance, double, 1e-8, 0.1);
  vtkGetMacro(HausdorffTolerance, double);
  ///@}

  ///@{
  /**
   * Results, valid after the filter has executed (also in the output's field data).
   */
  bool GetEncloses() const { return this->GetResultNumber("Encloses") != 0; }
  double GetMinimumClearance() const { return this->GetResultNumber("MinimumClearance"); }
  double GetMinimumClearanceRelative() const { return this->GetResultNumber("MinimumClearanceRelative"); }
  double GetHausdorffCageToInput() const { return this->GetResultNumber("HausdorffCageToInput"); }
  double GetHausdorffCageToInputRelative() const { return this->GetResultNumber("HausdorffCageToInputRelative"); }
  double GetHausdorffCageToInputBound() const { return this->GetResultNumber("HausdorffCageToInputBound"); }
  double GetHausdorffInputToCage() const { return this->GetResultNumber("HausdorffInputToCage"); }
  double GetHausdorffInputToCageRelative() const { return this->GetResultNumber("HausdorffInputToCageRelative"); }
  double GetHausdorffInputToCageBound() const { return this->GetResultNumber("HausdorffInputToCageBound"); }
  double GetMeanDistanceCageToInput() const { return this->GetResultNumber("MeanDistanceCageToInput"); }
  double GetMeanDistanceCageToInputRelative() const { return this->GetResultNumber("MeanDistanceCageToInputRelative"); }
  vtkIdType GetSelfIntersections() const { return static_cast<vtkIdType>(this->GetResultNumber("SelfIntersections")); }
  vtkIdType GetInputIntersections() const
  {
    return static_cast<vtkIdType>(this->GetResultNumber("InputIntersections"));
  }
  vtkIdType GetInputVerticesOutside() const
  {
    return static_cast<vtkIdType>(this->GetResultNumber("InputVerticesOutside"));
  }
  int GetCageGenus() const { return static_cast<int>(this->GetResultNumber("CageGenus")); }
  int GetInputGenus() const { return static_cast<int>(this->GetResultNumber("InputGenus")); }
  double GetQualityTime() const { return this->GetResultNumber("QualityTime"); }
  const char* GetQualityMessage() const { return this->GetResultText("QualityMessage"); }
  ///@}

  ///@{
  /**
   * The same results by name, as in the output's field data (Core's sdfcage::qualityResults
   * table, in its order); GetResultNumber gives flags as 0/1 and 0 for unknown names.
   */
  double GetResultNumber(const char* name) const;
  const char* GetResultText(const char* name) const;
  int GetNumberOfResults() const;
  const char* GetResultName(int index) const; ///< "" out of range
  ///@}

protected:
  vtkCageQualityFilter();
  ~vtkCageQualityFilter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*);
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double HausdorffTolerance;

private:
  int Execute(vtkPolyData* cage, vtkPolyData* mesh, vtkInformationVector* outputVector); // on the whole inputs
  // judges `cage` against `mesh` into `output` (the results into Internals); 0 on an error
  int Judge(vtkPolyData* cage, vtkPolyData* mesh, vtkPolyData* output);
  // nested levels: each block against the one inside it, the first against `mesh`
  int ExecuteLevels(vtkMultiBlockDataSet* levels, vtkPolyData* mesh, vtkMultiBlockDataSet* output);
  int ExecuteLevelsDistributed(vtkMultiProcessController* controller, vtkMultiBlockDataSet* levels, vtkPolyData* mesh,
    vtkMultiBlockDataSet* output);
  void ResetResults();
  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;

  vtkCageQualityFilter(const vtkCageQualityFilter&) = delete;
  void operator=(const vtkCageQualityFilter&) = delete;
};

#endif
