/*=========================================================================

  Program:   SDFCage
  Module:    vtkActivePointFilter.h

=========================================================================*/
/**
 * @class   vtkActivePointFilter
 * @brief   find the parts of a closed triangle mesh that nearly touch other parts
 *
 * A surface point p is *active* (paper §3.1) when some surface point q is closer than
 * ActiveRadius to p in space but farther than GeodesicThreshold from p along the surface, or on
 * another component: fingers of a closed fist, the legs of a scorpion, two parts a narrow gap
 * apart. vtkSDFCageFilter amplifies the signed distance field near these points so that the cage
 * keeps such parts separate; this filter shows what it sees.
 *
 * Output 0 is the validated input (triangulated, inward components flipped, unreferenced points
 * dropped) with point arrays `ActivePoint` (1 = active; the surface is sampled with samples ActiveRadius/2 apart,
 * so a point within ActiveRadius/2 of an active sample along the surface counts as active), `ActiveRule` (0 not active,
 * 1 the paper's rule, 2 the facing-gap rule of GapRatio), `GeodesicDistanceToActive` (g_A,
 * the distance along the surface to the nearest active point, in input units, clamped at
 * 4 / AmplificationBeta in unit-sphere units) and `Amplification` (phi on the surface,
 * phi = (alpha - 1) exp(-beta^2 g_A^2) + 1). Output 1, when GenerateDistanceFields is on, is a
 * vtkImageData (at most ~256 samples per axis) with point arrays `SignedDistance` (xi) and
 * `ModifiedSignedDistance` (phi * xi, where phi uses d^ = g_A(closest point) + |xi|), for slicing
 * and contouring in ParaView.
 *
 * Lengths (ActiveRadius, GeodesicThreshold) and AmplificationBeta are relative to the input
 * scaled into the unit sphere, as in vtkSDFCageFilter, whose defaults these are.
 *
 * @warning The input must be a closed triangle (or polygon) mesh: an open or non-manifold input
 * is rejected with an error naming the defect, and the outputs are empty. Empty input gives
 * empty outputs without an error. Abort (SetAbortExecute) stops the search promptly with empty
 * outputs.
 *
 * Under MPI, when each process is given its piece of the input, the pieces are gathered on
 * process 0 and analysed there (see vtkSDFCageFilter): process 0 outputs the serial result, the
 * others empty outputs with the same results field data.
 *
 * @sa vtkSDFCageFilter
 */

#ifndef vtkActivePointFilter_h
#define vtkActivePointFilter_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <memory> // For the results table
#include <string> // For the status strings

class SDFCAGEFILTERS_EXPORT vtkActivePointFilter : public vtkPolyDataAlgorithm
{
public:
  static vtkActivePointFilter* New();
  vtkTypeMacro(vtkActivePointFilter, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * r: the Euclidean radius (unit-sphere units, default 0.025) and l: the geodesic threshold
   * (default 0.15) of the definition above. l must be at least r.
   */
  vtkSetClampMacro(ActiveRadius, double, 1e-6, 1.0);
  vtkGetMacro(ActiveRadius, double);
  vtkSetClampMacro(GeodesicThreshold, double, 1e-6, 10.0);
  vtkGetMacro(GeodesicThreshold, double);
  ///@}

  ///@{
  /**
   * The facing-gap rule beside the paper's (0, the default, = off): a point is also active when
   * a point closer than ActiveRadius faces it across air and is farther from it along the
   * surface than GapRatio times their distance plus the sample spacing. It finds parts that
   * nearly touch close to where they join (a leg beside the body, a finger near its base), which
   * the paper's rule misses. vtkSDFCageFilter's topology repair rounds use 3: set 3 here to see
   * where a repair round amplifies (point array `ActiveRule` = 2).
   */
  vtkSetClampMacro(GapRatio, double, 0.0, 100.0);
  vtkGetMacro(GapRatio, double);
  ///@}

  ///@{
  /**
   * alpha (> 1, default 3) and beta (default 8, per unit-sphere length) of the amplification
   * phi = (alpha - 1) exp(-beta^2 d^2) + 1 (paper eq. 3).
   */
  vtkSetClampMacro(AmplificationAlpha, double, 1.0, 100.0);
  vtkGetMacro(AmplificationAlpha, double);
  vtkSetClampMacro(AmplificationBeta, double, 1e-3, 1000.0);
  vtkGetMacro(AmplificationBeta, double);
  ///@}

  ///@{
  /**
   * If on, output 1 receives the sampled `SignedDistance` and `ModifiedSignedDistance`. Off by
   * default.
   */
  vtkSetMacro(GenerateDistanceFields, vtkTypeBool);
  vtkGetMacro(GenerateDistanceFields, vtkTypeBool);
  vtkBooleanMacro(GenerateDistanceFields, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Number of worker threads; 0 (the default) uses all cores. Results do not depend on it.
   */
  vtkSetClampMacro(NumberOfThreads, int, 0, 4096);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /**
   * Results of the last execution (also in output 0's field data): the number of output points
   * flagged active, the size of the active set on the surface sampling, the number of samples,
   * the time in seconds, the status ("Ok", "EmptyInput", "InvalidInput", "Cancelled", "Failed")
   * and the last error message.
   */
  vtkIdType GetNumberOfActivePoints() const
  {
    return static_cast<vtkIdType>(this->GetResultNumber("NumberOfActivePoints"));
  }
  vtkIdType GetNumberOfActiveSamples() const
  {
    return static_cast<vtkIdType>(this->GetResultNumber("NumberOfActiveSamples"));
  }
  vtkIdType GetNumberOfSamples() const { return static_cast<vtkIdType>(this->GetResultNumber("NumberOfSamples")); }
  double GetActivePointTime() const { return this->GetResultNumber("ActivePointTime"); }
  double GetExecutionTime() const { return this->GetActivePointTime(); } ///< the old name of GetActivePointTime
  const char* GetStatusString() const { return this->StatusString.c_str(); }
  const char* GetLastErrorMessage() const { return this->LastErrorMessage.c_str(); }
  ///@}

  ///@{
  /**
   * The same results by name, as in output 0's field data (Core's sdfcage::activePointResults
   * table, in its order); 0 for unknown names.
   */
  double GetResultNumber(const char* name) const;
  int GetNumberOfResults() const;
  const char* GetResultName(int index) const; ///< "" out of range
  ///@}

protected:
  vtkActivePointFilter();
  ~vtkActivePointFilter() override;

  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double ActiveRadius;
  double GeodesicThreshold;
  double AmplificationAlpha;
  double AmplificationBeta;
  double GapRatio = 0.0;
  vtkTypeBool GenerateDistanceFields = 0;
  int NumberOfThreads = 0;

  // outcome of the last execution (the results are in Internals' table)
  std::string StatusString;
  std::string LastErrorMessage;

private:
  vtkActivePointFilter(const vtkActivePointFilter&) = delete;
  void operator=(const vtkActivePointFilter&) = delete;

  int Execute(vtkPolyData* input, vtkInformationVector* outputVector); // on the whole input

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
