/*=========================================================================
  Program:   SDFCage
  Module:    vtkCageDeformationFilter.h
  SDFCage: cages from an SDF envelope, as VTK filters and a ParaView plugin.
=========================================================================*/
/**
 * @class   vtkCageDeformationFilter
 * @brief   deform any point set with a cage: mean value or Green coordinates
 *
 * Input 0 is the point set to deform (any vtkPointSet: a mesh, a point cloud, an unstructured
 * grid), input 1 the rest cage (a closed triangle mesh around it, e.g. vtkSDFCageFilter's
 * output), input 2 the deformed cage: the rest cage with moved points and the same
 * connectivity (any filter that moves points makes one: vtkTransformFilter, vtkWarpVector, a
 * Python calculator). The output is input 0 with its points moved:
 *
 * - mean value coordinates (Ju, Schaefer, Warren, "Mean Value Coordinates for Closed Triangular
 *   Meshes", SIGGRAPH 2005), SetCoordinatesToMeanValue(), the default: x' = sum_i w_i(x) v'_i.
 *   Smooth, reproduce every affine map of the cage exactly;
 * - Green coordinates (Lipman, Levin, Cohen-Or, "Green Coordinates", SIGGRAPH 2008),
 *   SetCoordinatesToGreen(): x' = sum_i phi_i(x) v'_i + sum_j psi_j(x) s_j n'_j, with the deformed
 *   triangles' normals n'_j and stretch factors s_j. Shape preserving (quasi-conformal: details
 *   rotate and scale instead of shearing), reproduce similarities exactly.
 *
 * The weights depend only on input 0's points and the rest cage. They are computed once (all
 * threads, see NumberOfThreads) and kept while neither changes (same data objects, same
 * modification times) and the coordinates stay the same; moving the deformed cage then only
 * re-applies them: one matrix product, milliseconds for tens of thousands of points. Memory:
 * 8 bytes per point and cage vertex (mean value), per point and cage vertex + triangle (Green):
 * 43k points and a 500-vertex cage take 173 MB (mean value) or 518 MB (Green); half with
 * SinglePrecisionWeights.
 *
 * Points outside the rest cage (generalized winding number below 1/2) and points on it are
 * counted (GetNumberOfPointsOutside(), GetNumberOfPointsOnCage()) and reported with a warning.
 * They are moved with mean value coordinates in both modes: those extend smoothly outside the
 * cage and follow it exactly for affine cage motions; for other motions they extrapolate,
 * increasingly so farther out. Green coordinates are not defined there. The point array
 * `CageLocation` (0 inside, 1 outside, 2 on the cage) marks them.
 *
 * Results (field data of the output as well): `CageCoordinates` ("MeanValue" or "Green"),
 * `PointsOutsideCage`, `PointsOnCage`, `WeightTime` (seconds of the last weight computation),
 * `ApplyTime`, `WeightsRecomputed` (1 when this execution computed them), `ReproductionError`
 * (the rest cage applied to the weights against the input points, relative to the cage's
 * diagonal: 1e-11 or better inside), `CageWasFlipped` (an inward rest cage is used reversed).
 *
 * @warning The cages must be closed, consistently oriented triangle meshes (triangulate
 * polygons first: vtkTriangleFilter); the deformed cage must have the rest cage's points and
 * triangles in the same order. Otherwise it is an error and the output is empty. Empty or
 * missing inputs are not errors: the output is then empty. Threaded with TBB; the results do
 * not depend on the number of threads.
 *
 * @sa
 * vtkSDFCageFilter vtkDeformPointSet
 */

#ifndef vtkCageDeformationFilter_h
#define vtkCageDeformationFilter_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <memory> // For the cached weights
#include <string> // For the status strings

class vtkMultiProcessController;

class SDFCAGEFILTERS_EXPORT vtkCageDeformationFilter : public vtkPointSetAlgorithm
{
public:
  vtkTypeMacro(vtkCageDeformationFilter, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  static vtkCageDeformationFilter* New();

  ///@{
  /**
   * The rest cage (input port 1) and the deformed cage (input port 2).
   * SetInputConnection(port, ...) and SetInputData(port, ...) work as well.
   */
  void SetRestCageConnection(vtkAlgorithmOutput* algOutput);
  void SetRestCageData(vtkDataObject* cage);
  void SetDeformedCageConnection(vtkAlgorithmOutput* algOutput);
  void SetDeformedCageData(vtkDataObject* cage);
  ///@}

  enum CoordinateType
  {
    MEAN_VALUE = 0,
    GREEN = 1
  };

  ///@{
  /**
   * Which coordinates: MeanValue (0, the default) or Green (1).
   */
  vtkSetClampMacro(Coordinates, int, MEAN_VALUE, GREEN);
  vtkGetMacro(Coordinates, int);
  void SetCoordinatesToMeanValue() { this->SetCoordinates(MEAN_VALUE); }
  void SetCoordinatesToGreen() { this->SetCoordinates(GREEN); }
  ///@}

  ///@{
  /**
   * Keep the weights in single precision: half the memory and about half the time to apply a
   * deformed cage. The rest cage still reproduces the input exactly (a per-point correction is
   * kept in double precision); a deformed cage is followed to about 1e-7 of its displacement
   * instead of 1e-9 of the size. Default off.
   */
  vtkSetMacro(SinglePrecisionWeights, vtkTypeBool);
  vtkGetMacro(SinglePrecisionWeights, vtkTypeBool);
  vtkBooleanMacro(SinglePrecisionWeights, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Worker threads for the weights and the product; 0 (the default) = all cores.
   */
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /**
   * Forgets the cached weights: the next execution computes them again.
   */
  void ClearWeights();

  ///@{
  /**
   * Results (only valid after the filter has executed): see the class description.
   */
  vtkIdType GetNumberOfPointsOutside() const { return this->PointsOutside; }
  vtkIdType GetNumberOfPointsOnCage() const { return this->PointsOnCage; }
  double GetWeightTime() const { return this->WeightTime; }
  double GetApplyTime() const { return this->ApplyTime; }
  bool GetWeightsRecomputed() const { return this->WeightsRecomputed; }
  double GetReproductionError() const { return this->ReproductionError; }
  bool GetCageWasFlipped() const { return this->CageWasFlipped; }
  ///@}

  /**
   * "Ok", "EmptyInput", "InvalidInput", "Cancelled" or "Failed" (only valid after execution).
   */
  const char* GetStatusString() const { return this->StatusString.c_str(); }
  /**
   * The error of the last execution; empty when all went well.
   */
  const char* GetLastErrorMessage() const { return this->LastErrorMessage.c_str(); }

protected:
  vtkCageDeformationFilter();
  ~vtkCageDeformationFilter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Coordinates;
  int NumberOfThreads;
  vtkTypeBool SinglePrecisionWeights = 0;

  // outcome of the last execution
  vtkIdType PointsOutside = 0;
  vtkIdType PointsOnCage = 0;
  double WeightTime = 0.0;
  double ApplyTime = 0.0;
  bool WeightsRecomputed = false;
  double ReproductionError = 0.0;
  bool CageWasFlipped = false;
  std::string StatusString;
  std::string LastErrorMessage;

private:
  vtkCageDeformationFilter(const vtkCageDeformationFilter&) = delete;
  void operator=(const vtkCageDeformationFilter&) = delete;

  // Under MPI: every process reports the whole run (counts summed, times the longest).
  void ShareResults(vtkMultiProcessController* controller, bool hasPoints);

  // the cached weights and what they were computed for
  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
