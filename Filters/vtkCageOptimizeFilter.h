/*=========================================================================

  Program:   SDFCage
  Module:    vtkCageOptimizeFilter.h

  SDFCage: cages from an SDF envelope, as VTK filters and a ParaView plugin.

=========================================================================*/
/**
 * @class   vtkCageOptimizeFilter
 * @brief   improve a cage (MIPS or spacing energy) while it keeps enclosing its input
 *
 * vtkCageOptimizeFilter implements the optimization of "High-quality Cage Generation Based on
 * SDF" (§3.3). Input 0 is a cage, input 1 (SetSourceConnection) the
 * mesh it encloses. Each vertex of the cage is relocated by gradient descent on
 * E_quality + BarrierWeight * B, B the IPC barrier (eq. 7) over the point-triangle and edge-edge
 * pairs between the vertex's one-ring and the input and the rest of the cage; the line search
 * accepts a step only if it lowers the energy, if a collision-free step test (the whole
 * move if it is clear, else a bisection on the move fraction) shows that no pair comes closer than the clearance along the way, and if the
 * new one-ring passes the static tests (exact distances to the input, no self-intersection, no
 * flipped or needle triangle). Then edges are flipped where that lowers E_quality and keeps every
 * constraint (and the manifold). The energy is MIPS (eq. 8, equilateral reference: well-shaped
 * triangles) or cage spacing (eq. 9: the cage at distance TargetSpacing from the input).
 *
 * The result is verified independently (closed 2-manifold, no self-intersection, every input
 * part inside, every triangle at least the clearance from the input, exact distances); should
 * that ever fail, the given cage is output unchanged with a warning (GetReverted()).
 *
 * The output is the optimized cage (same vertices and triangle count) with point array
 * `DistanceToInput` (input units), plus the results as one-tuple field-data arrays named like
 * the getters and the string arrays `Status` and `LastErrorMessage`.
 *
 * Lengths are relative: in units of the input mesh scaled into the unit sphere (the paper's
 * convention, §4), like vtkSDFCageFilter's. The output is in the input's coordinates.
 * Sequential and deterministic.
 *
 * @warning The given cage must already enclose the input without self-intersection, with at
 * least MinimumClearance (automatic: the smaller of 0.0025 and the cage's own clearance);
 * otherwise it is an error ("InvalidInput") and the output is empty. Both inputs must be closed,
 * manifold surfaces. Vertices whose neighbourhood already violates a margin do not move. A missing
 * or empty input is not an error: the output is empty.
 *
 * Under MPI, when each process is given its piece of the cage and of the source, both are
 * gathered on process 0 and optimized there (see vtkSDFCageFilter): process 0 outputs the serial
 * result, the others an empty cage with the same results field data.
 *
 * @sa
 * vtkSDFCageFilter
 */

#ifndef vtkCageOptimizeFilter_h
#define vtkCageOptimizeFilter_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <memory> // For the results table
#include <string> // For the status strings

class SDFCAGEFILTERS_EXPORT vtkCageOptimizeFilter : public vtkPolyDataAlgorithm
{
public:
  vtkTypeMacro(vtkCageOptimizeFilter, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  static vtkCageOptimizeFilter* New();

  /**
   * The mesh the cage encloses (input port 1).
   */
  void SetSourceConnection(vtkAlgorithmOutput* algOutput);
  void SetSourceData(vtkDataObject* source);

  enum EnergyType
  {
    MIPS = 0,
    SPACING = 1
  };

  ///@{
  /**
   * The quality measure: MIPS (0, the default: well-shaped triangles) or Spacing (1: distance
   * TargetSpacing from the input).
   */
  vtkSetClampMacro(Energy, int, MIPS, SPACING);
  vtkGetMacro(Energy, int);
  void SetEnergyToMIPS() { this->SetEnergy(MIPS); }
  void SetEnergyToSpacing() { this->SetEnergy(SPACING); }
  ///@}

  ///@{
  /**
   * Target distance h of the spacing energy, relative to the unit sphere. Default 0.05.
   */
  vtkSetClampMacro(TargetSpacing, double, 0.0, 1.0);
  vtkGetMacro(TargetSpacing, double);
  ///@}

  ///@{
  /**
   * Weight λ of the IPC barrier. Default 0.1 (the paper's).
   */
  vtkSetClampMacro(BarrierWeight, double, 0.0, 1.0e6);
  vtkGetMacro(BarrierWeight, double);
  ///@}

  ///@{
  /**
   * d̂ of the barrier, relative to the unit sphere: it acts on the gap between a pair's distance
   * and the distance the pair must keep (MinimumClearance for cage/input pairs), starting at
   * d̂ and growing without bound as the gap closes. Default 0.0025; 0 turns the barrier off (the
   * constraints are still enforced by the line search).
   */
  vtkSetClampMacro(BarrierDistance, double, 0.0, 0.5);
  vtkGetMacro(BarrierDistance, double);
  ///@}

  ///@{
  /**
   * Rounds of up to MaximumSweeps sweeps (a relocation pass, a flip pass and, MIPS, a needle
   * repair pass). Default 1.
   */
  vtkSetClampMacro(NumberOfIterations, int, 0, 1000);
  vtkGetMacro(NumberOfIterations, int);
  ///@}

  ///@{
  /**
   * Flip edges after each relocation pass. Default on.
   */
  vtkSetMacro(EdgeFlips, vtkTypeBool);
  vtkGetMacro(EdgeFlips, vtkTypeBool);
  vtkBooleanMacro(EdgeFlips, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Keeping the MIPS-optimized cage tight (ignored by the spacing energy). HausdorffFactor: no
   * move, flip or collapse may put a point of a changed triangle farther from the input than
   * this times the given cage's one-sided Hausdorff distance cage -> input; 0 = no bound, else
   * at least 1 (a value in (0, 1) is an InvalidInput error). Default 1.4. TargetMinimumAngle:
   * the smallest triangle angle (degrees) the sweeps aim at; triangles below it are repaired
   * (flips, needle collapses paired with an edge split, so the vertex count stays exact); 0 = no
   * repair. Default 15. MaximumSweeps: sweeps (relocation, flips, repair) per round; a round
   * stops earlier once no angle is below the target or the smallest angle stalls. Default 12.
   */
  vtkSetClampMacro(HausdorffFactor, double, 0.0, 1000.0);
  vtkGetMacro(HausdorffFactor, double);
  vtkSetClampMacro(TargetMinimumAngle, double, 0.0, 59.0);
  vtkGetMacro(TargetMinimumAngle, double);
  vtkSetClampMacro(MaximumSweeps, int, 1, 1000);
  vtkGetMacro(MaximumSweeps, int);
  ///@}

  ///@{
  /**
   * Clearance every cage triangle keeps from every input triangle, relative to the unit sphere.
   * 0 (the default) = automatic: the smaller of 0.0025 (vtkSDFCageFilter's default) and the given
   * cage's own clearance.
   */
  vtkSetClampMacro(MinimumClearance, double, 0.0, 0.5);
  vtkGetMacro(MinimumClearance, double);
  ///@}

  ///@{
  /**
   * Keep the cage's parts (connected components) at least as far apart as in the given cage
   * (measured up to 0.1, relative to the unit sphere): on for a level of a nested hierarchy, whose
   * next level must pass between its parts. Off by default (the parts may come as close as the
   * self clearance). The room kept is the result `OptimizationPartRoom`.
   */
  vtkSetMacro(KeepPartsApart, vtkTypeBool);
  vtkGetMacro(KeepPartsApart, vtkTypeBool);
  vtkBooleanMacro(KeepPartsApart, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Results (only valid after the filter has executed): E_quality before and after (MIPS: the
   * sum over triangles, 2 per equilateral triangle; Spacing: the integral, unit-sphere units),
   * the smallest triangle angle before and after (degrees), the measured minimum distance to
   * the input (input units and relative), the clearance enforced (relative), the accepted
   * vertex moves and flips, whether the result was reverted, and the time in seconds.
   */
  double GetEnergyBefore() const { return this->GetResultNumber("EnergyBefore"); }
  double GetEnergyAfter() const { return this->GetResultNumber("EnergyAfter"); }
  double GetMinimumAngleBefore() const { return this->GetResultNumber("MinimumAngleBefore"); }
  double GetMinimumAngleAfter() const { return this->GetResultNumber("MinimumAngleAfter"); }
  double GetMeasuredClearance() const { return this->GetResultNumber("MeasuredClearance"); }
  double GetMeasuredClearanceRelative() const { return this->GetResultNumber("MeasuredClearanceRelative"); }
  double GetClearanceUsed() const { return this->GetResultNumber("ClearanceUsed"); }
  int GetNumberOfMoves() const { return static_cast<int>(this->GetResultNumber("NumberOfMoves")); }
  int GetNumberOfFlips() const { return static_cast<int>(this->GetResultNumber("NumberOfFlips")); }
  bool GetReverted() const { return this->GetResultNumber("Reverted") != 0; }
  double GetOptimizationTime() const { return this->GetResultNumber("OptimizationTime"); }
  ///@}

  ///@{
  /**
   * The same results by name, as in the output's field data (Core's sdfcage::optimizeResults
   * table, in its order); GetResultNumber gives flags as 0/1 and 0 for unknown names.
   */
  double GetResultNumber(const char* name) const;
  const char* GetResultText(const char* name) const;
  int GetNumberOfResults() const;
  const char* GetResultName(int index) const; ///< "" out of range
  ///@}

  /**
   * "Ok", "EmptyInput", "InvalidInput", "Cancelled" or "Failed" (only valid after execution).
   */
  const char* GetStatusString() const { return this->StatusString.c_str(); }
  /**
   * The error, cancellation or revert reason of the last execution; empty when all went well.
   */
  const char* GetLastErrorMessage() const { return this->LastErrorMessage.c_str(); }

protected:
  vtkCageOptimizeFilter();
  ~vtkCageOptimizeFilter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Energy;
  double TargetSpacing;
  double BarrierWeight;
  double BarrierDistance;
  int NumberOfIterations;
  vtkTypeBool EdgeFlips;
  double HausdorffFactor;
  double TargetMinimumAngle;
  int MaximumSweeps;
  double MinimumClearance;
  vtkTypeBool KeepPartsApart = 0;

  // outcome of the last execution (the results are in Internals' table)
  std::string StatusString;
  std::string LastErrorMessage;

private:
  vtkCageOptimizeFilter(const vtkCageOptimizeFilter&) = delete;
  void operator=(const vtkCageOptimizeFilter&) = delete;

  int Execute(vtkPolyData* cage, vtkPolyData* source, vtkInformationVector* outputVector); // on the whole inputs
  void ResetResults();
  void PublishResults(vtkPolyData* output) const;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
