/*=========================================================================

  Program:   SDFCage
  Module:    vtkSDFCageFilter.h

  SDFCage: cages from an SDF envelope, as VTK filters and a ParaView plugin.

=========================================================================*/
/**
 * @class   vtkSDFCageFilter
 * @brief   build a cage (a coarse closed mesh strictly enclosing the input) from an SDF envelope
 *
 * vtkSDFCageFilter implements the paper "High-quality Cage Generation Based on SDF".
 * Envelope stage (§3.1): the input surface is scaled into the
 * unit sphere, its signed distance field is sampled on a grid of size VoxelSize, and the
 * isosurface {SDF = IsoValue} is extracted. Trapped air pockets (inner components) are removed
 * and the result is verified: it must be a closed 2-manifold that keeps at least
 * MinimumClearance from every input triangle (exact triangle-triangle distances) and contain
 * every input component; if the check fails, the grid is refined and the envelope rebuilt.
 * Simplification stage (§3.2): constrained quadric-error edge collapses reduce the envelope to
 * TargetNumberOfVertices vertices; every collapse keeps the clearance, avoids self-intersections and
 * keeps the surface manifold, and the final cage is verified again independently.
 * Optional optimization stage (§3.3, Optimize off by default): vertex relocation and edge flips
 * lower a MIPS or cage-spacing energy while every guarantee is kept (see vtkCageOptimizeFilter).
 *
 * Any surface is accepted: polygons and triangle strips are triangulated, coincident points
 * merged, degenerate and duplicated triangles dropped, vertex and line cells ignored, a closed
 * inward-oriented mesh flipped (with a warning). A closed, consistently oriented 2-manifold keeps
 * the flood-fill inside; open, non-manifold or inconsistently oriented inputs are signed by their
 * winding number (see SignMode). Several components are allowed.
 *
 * Outputs:
 * - port 0 ("Cage"): the cage, with point array `DistanceToInput` (double, input units) and
 *   field data holding every result of the run (Core's results table, sdfcage::cageResults): one
 *   one-tuple array per result, named like its getter (flags as int 0/1, counts as vtkIdType,
 *   measures as double, texts as strings), plus the string arrays `Status` and
 *   `LastErrorMessage`. GetResultNumber / GetResultText read any result by name, and
 *   GetNumberOfResults / GetResultName list them.
 * - port 1 ("Envelope"): the verified dense envelope, with point array `DistanceToInput`.
 * - port 2 ("Distance Field"): a vtkImageData with the sampled signed distance as point array
 *   `SignedDistance` (input units; negative inside, positive outside) when GenerateDistanceField
 *   is on, an empty image otherwise. The field is exact only in a narrow band around the input
 *   (a few voxels, enough to contain the envelope); farther away the values keep their sign but
 *   saturate at the band's width.
 * - port 3 ("Nested Cages"): a vtkMultiBlockDataSet with one block per nested level when
 *   NestedVertexCounts are set (see SetNumberOfNestedLevels), empty otherwise.
 *
 * Every length parameter is relative: it is measured in units of the input scaled into the unit
 * sphere (the paper's convention, §4). Every output is in the input's own coordinates and units.
 *
 * The work is done by SDFCage::Core (sdfcage::generateCage) with TBB/OpenVDB threads; results do
 * not depend on the number of threads. Progress is reported from the thread that called
 * Update() only. GetAbortExecute() cancels the run at the next checkpoint, without an error and
 * with GetStatusString() "Cancelled": before the simplification the outputs are empty; during
 * it, the cage simplified so far (verified, valid, with more vertices than asked) and the
 * envelope are output. VTK 9.1 clears the abort flag when the next execution starts; the VTK
 * bundled with ParaView 5.11 keeps it set until SetAbortExecute(0).
 *
 * @warning An input without polygons, with non-finite points or invalid point ids is rejected
 * with an error that names the defect, and all outputs are empty. Self-intersecting inputs are not
 * detected. If the envelope or the cage
 * cannot be verified, that is an error too: the cage output stays empty and the envelope (if
 * any) is put on port 1 so the failure can be inspected. If the simplification cannot reach
 * TargetNumberOfVertices (no feasible collapse left), the cage it reached is output with a warning
 * that gives the reason (GetTargetReached() is false). Empty input is not an error: the outputs
 * are empty. The sampled grid's memory grows as 1/VoxelSize^2 (narrow band); GenerateDistanceField
 * stores a dense grid (1/VoxelSize^3 values).
 *
 * Under MPI (pvbatch or pvserver under mpiexec, or any program whose global controller has
 * several processes), when each process is given its piece of the input (as many pieces as
 * processes), the pieces are gathered on process 0 (seam points shared by pieces merged, ghost
 * cells dropped) and the cage is computed there: process 0 outputs what a serial run outputs, the
 * other processes empty outputs (an empty image with the same origin, spacing and arrays) with
 * the same results field data, and every process's getters report process 0's results. Every
 * process must execute the filter then (ParaView's data servers all do). A request for the whole
 * input (piece 0 of 1) runs on the calling process alone, without communication.
 *
 * @sa
 * vtkFillHolesFilter vtkTriangleFilter vtkCleanPolyData vtkQuadricDecimation vtkOFFReader
 * vtkOFFWriter vtkCageOptimizeFilter
 */

#ifndef vtkSDFCageFilter_h
#define vtkSDFCageFilter_h

#include "SDFCageFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <memory> // For the results table
#include <string> // For the status strings
#include <vector> // For the nested vertex counts

namespace sdfcage
{
struct CageResult;
struct PolygonMesh;
}

class vtkFieldData;
class vtkImageData;
class vtkMultiBlockDataSet;

class SDFCAGEFILTERS_EXPORT vtkSDFCageFilter : public vtkPolyDataAlgorithm
{
public:
  vtkTypeMacro(vtkSDFCageFilter, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  static vtkSDFCageFilter* New();

  ///@{
  /**
   * Number of vertices of the cage (the simplification stops there). 0 skips the
   * simplification: the cage is then the dense verified envelope. Default 500 (Core's).
   */
  vtkSetClampMacro(TargetNumberOfVertices, int, 0, VTK_INT_MAX);
  vtkGetMacro(TargetNumberOfVertices, int);
  ///@}

  ///@{
  /**
   * When the simplification stalls above the target (every remaining collapse would fold a
   * sliver or crowd a neighbour; far above it at once, close to it after the thorough passes),
   * the cage so far gets one sweep of MIPS relaxation (moves and
   * flips with every guarantee kept, within 1.4 times its distance to the input) and is simplified
   * again, up to this many times (results Relaxations, VerticesBeforeRelaxation,
   * RelaxationTime). 0 = off. Default 4 (Core's).
   */
  vtkSetClampMacro(MaximumRelaxations, int, 0, 16);
  vtkGetMacro(MaximumRelaxations, int);
  ///@}

  ///@{
  /**
   * Nested cages (paper §4, Fig. 9): a list of vertex counts, one cage per count, each strictly
   * enclosing the next finer one (and so the input) with the clearance. Empty (the default): one
   * cage of TargetNumberOfVertices, as before. Set like vtkContourFilter's values:
   * SetNumberOfNestedLevels(3), SetNestedVertexCount(0, 2000), (1, 500), (2, 100); the order does
   * not matter (the levels are sorted finest first); a count below 1 or given twice is an error
   * (status InvalidInput, every output empty). TargetNumberOfVertices is then not used.
   *
   * The finest level is the usual run on the input; each coarser one reruns the whole method on
   * the cage of the level inside it (the paper's procedure), and is re-verified in the input's
   * coordinates against that level and against the input (sdfcage::generateNestedCages). Ports
   * 0-2 then hold the finest level's cage, envelope and field, and the getters its results.
   * Port 3 holds every level, finest first, as blocks named "cage_<count>" (vtkCompositeDataSet
   * NAME()), each with the point array `DistanceToInput` (distance to the level inside it) and
   * field data: that level's results (the same names as port 0's), Level, VerifiedAgainstInside,
   * ClearanceToInside, VerifiedAgainstInput, ClearanceToInput, CageGenus, CageComponents,
   * TopologyKept, LevelTime, and the string Status. A level that was not built (an error or a
   * cancel stopped the run earlier) is an empty block with Status "NotBuilt".
   *
   * Why a fourth output port and not a separate filter: every parameter of a nested run is this
   * filter's, ports 0-2 stay what existing pipelines and state files expect (a vtkPolyData cage
   * on port 0), and ParaView shows named output ports as separate pipeline items, as it already
   * does for the envelope and the field. Every gap between parts of the input narrows by at
   * least twice the clearance per level, so parts that nearly touch fuse at some level: the
   * level's TopologyWarning and TopologyKept say so.
   */
  void SetNumberOfNestedLevels(int number);
  int GetNumberOfNestedLevels() const;
  void SetNestedVertexCount(int level, int count);
  int GetNestedVertexCount(int level) const; ///< 0 out of range
  ///@}

  ///@{
  /**
   * Isovalue c of the envelope {SDF = c}, relative to the input scaled into the unit sphere.
   * The paper's default is 0.01. The envelope lies about c outside the input.
   */
  vtkSetClampMacro(IsoValue, double, 0.0001, 0.5);
  vtkGetMacro(IsoValue, double);
  ///@}

  ///@{
  /**
   * Voxel size h of the distance grid, relative to the input scaled into the unit sphere.
   * 0 (the default) chooses IsoValue / 2, which keeps the genus of typical inputs. A coarser grid
   * is faster but may fuse nearly-touching parts.
   */
  vtkSetClampMacro(VoxelSize, double, 0.0, 0.5);
  vtkGetMacro(VoxelSize, double);
  ///@}

  ///@{
  /**
   * Clearance delta that every envelope triangle must keep from every input triangle, relative
   * to the input scaled into the unit sphere. 0 (the default) chooses IsoValue / 4. It must be
   * at most IsoValue / 1.15 (the envelope lies about IsoValue from the input and needs 15% room
   * to be verified): a larger one fails at once with the values that work in the error.
   */
  vtkSetClampMacro(MinimumClearance, double, 0.0, 0.5);
  vtkGetMacro(MinimumClearance, double);
  ///@}

  ///@{
  /**
   * Adaptivity of the isosurface extraction (OpenVDB volumeToMesh), in [0, 1]: 0 gives uniform
   * triangles, larger values merge flat regions into larger triangles (a smaller envelope,
   * verified like any other). Default 0.3 (Core's): 2-2.5x fewer triangles than 0.1 on the shared
   * test meshes, cages as tight or tighter.
   */
  vtkSetClampMacro(Adaptivity, double, 0.0, 1.0);
  vtkGetMacro(Adaptivity, double);
  ///@}

  ///@{
  /**
   * How the inside of the input is decided. Auto (0, default): a closed, consistently oriented
   * 2-manifold input keeps the flood-fill path (FloodFill, 1); any other input (open scans,
   * soups of overlapping parts, non-manifold or inconsistently oriented meshes) is signed by its
   * generalized winding number (WindingNumber, 2): holes and cracks are bridged and the solid is
   * caged, an open sheet is wrapped on both sides. Unsigned (3) has no inside at all: the cage
   * wraps every sheet on both sides. Active points are used with FloodFill only. The rule used
   * and why: GetResultText("SignMode"), GetResultText("SignReason").
   */
  vtkSetClampMacro(SignMode, int, 0, 3);
  vtkGetMacro(SignMode, int);
  void SetSignModeToAuto() { this->SetSignMode(0); }
  void SetSignModeToFloodFill() { this->SetSignMode(1); }
  void SetSignModeToWindingNumber() { this->SetSignMode(2); }
  void SetSignModeToUnsigned() { this->SetSignMode(3); }
  ///@}

  ///@{
  /**
   * Every result of the last execution by name, as in the field data of the cage (Core's
   * results table, sdfcage::cageResults, in its order): the verdict (EnclosureVerified,
   * MeasuredClearance, VerticesReached, TargetReached, StopReason), the envelope, the
   * simplification's and the optimization's statistics, the timings, what was done to the input
   * (MergedPoints, MergeTolerance, TriangulatedPolygons, DroppedDegenerateTriangles,
   * DroppedDuplicateTriangles, IgnoredCells), what it is (InputBoundaryEdges,
   * InputNonManifoldEdges, InputNonManifoldVertices, InputInconsistentEdges, InputComponents,
   * InputClosed, InputGenus: -1 when undefined) and how its inside was decided (SignMode,
   * SignReason, WindingTime). The getters below read the same table. GetResultNumber gives flags
   * as 0/1, 0 for texts and unknown names; GetResultText gives "" for numbers and unknown names.
   */
  double GetResultNumber(const char* name) const;
  const char* GetResultText(const char* name) const;
  int GetNumberOfResults() const;
  const char* GetResultName(int index) const; ///< "" out of range
  ///@}

  ///@{
  /**
   * How often the grid may be refined (voxel size halved) when the envelope fails the
   * verification. Default 2.
   */
  vtkSetClampMacro(MaximumRefinements, int, 0, 5);
  vtkGetMacro(MaximumRefinements, int);
  ///@}

  ///@{
  /**
   * Inputs without a defined topology (open, non-manifold, soups) whose target is not reached get
   * their envelope rebuilt at twice the isovalue, up to this many times; the cage that reaches
   * the target, or gets closest, is kept (results IsoValueUsed, EnvelopeWidenings, WideningLog).
   * Closed inputs are never widened. 0 = off. Default 3.
   */
  vtkSetClampMacro(MaximumEnvelopeWidenings, int, 0, 6);
  vtkGetMacro(MaximumEnvelopeWidenings, int);
  ///@}

  ///@{
  /**
   * With widening on (MaximumEnvelopeWidenings > 0) and the automatic voxel size, an input of
   * more parts than the target can carry apart (4 vertices each) has its isovalue chosen first
   * by probes on grids twice as coarse (parts and genus of the envelope, neither verified nor
   * simplified), so that the envelopes that cannot reach the target are not built on the
   * requested grid. Results EnvelopeProbes, IsoValuesSkipped, ProbeTime, WideningLog. Off: every
   * widening is built in turn. Closed inputs are never probed. Default on (Core's
   * CageOptions::ChooseIsoValueFirst).
   */
  vtkSetMacro(ChooseIsoValueFirst, vtkTypeBool);
  vtkGetMacro(ChooseIsoValueFirst, vtkTypeBool);
  vtkBooleanMacro(ChooseIsoValueFirst, vtkTypeBool);
  ///@}

  ///@{
  /**
   * A closed input whose envelope has another genus or number of parts (nearly touching parts
   * fused) gets its envelope rebuilt up to this many times, each round stronger: the facing-gap
   * rule beside the paper's active points, the most amplification the clearance allows, a finer
   * grid, and (automatic clearance only) a lower clearance. Results TopologyRepairs,
   * TopologyRepairLog, ClearanceUsed. 0 = off. Default 2.
   */
  vtkSetClampMacro(MaximumTopologyRepairs, int, 0, 2);
  vtkGetMacro(MaximumTopologyRepairs, int);
  ///@}

  ///@{
  /**
   * Fail (status TopologyChanged, no cage) instead of producing a cage whose genus or number of
   * parts differs from the closed input's. Default off: the cage is produced with a warning
   * (TopologyWarning) naming where the gaps are.
   */
  vtkSetMacro(RequireTopology, vtkTypeBool);
  vtkGetMacro(RequireTopology, vtkTypeBool);
  vtkBooleanMacro(RequireTopology, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Coarse grid first: with the automatic voxel size, a closed input without active points is
   * first sampled on a grid twice as coarse (voxel = IsoValue); its envelope is kept only when it
   * is verified and has the input's genus and parts, otherwise a grid between (voxel 2/3 of the
   * IsoValue, judged the same way) and then the automatic grid (IsoValue / 2) follow. VoxelSizeUsed in the field data says which grid was kept. Default on (Core's).
   */
  vtkSetMacro(CoarseFirst, vtkTypeBool);
  vtkGetMacro(CoarseFirst, vtkTypeBool);
  vtkBooleanMacro(CoarseFirst, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Memory budget of the envelope in MiB (its distance grid, isosurface and verification, as
   * estimated before each grid is built): a grid whose need exceeds it is not built; the run
   * stops with an error naming the need (status Failed), and a finer refinement grid over it is
   * not tried. 0 (default) = three quarters of the machine's physical memory.
   */
  vtkSetClampMacro(MemoryLimit, double, 0.0, 1.0e12);
  vtkGetMacro(MemoryLimit, double);
  ///@}

  ///@{
  /**
   * Shape-aware envelope (paper §3.1), on by default: points of the input that have another
   * surface point closer than ActiveRadius but farther than GeodesicThreshold along the surface
   * (nearly touching parts: fingers, legs, separate components) are "active", and the SDF is
   * amplified near them, phi = (AmplificationAlpha - 1) exp(-AmplificationBeta^2 d^2) + 1, so the
   * envelope lies closer to the input there (down to IsoValue / AmplificationAlpha) and keeps
   * the parts separate. Off: the plain offset {SDF = IsoValue}, which may fuse them. Lengths are
   * relative to the input scaled into the unit sphere (defaults r 0.025, l 0.15, alpha 3,
   * beta 8). An AmplificationAlpha above IsoValue / (1.15 clearance) would put the envelope
   * within the clearance at the active points: it is lowered to that bound for the run (result
   * AmplificationAlphaUsed). If the envelope still does not have the input's genus and component
   * count, a warning says so (GetTopologyWarning()).
   */
  vtkSetMacro(UseActivePoints, vtkTypeBool);
  vtkGetMacro(UseActivePoints, vtkTypeBool);
  vtkBooleanMacro(UseActivePoints, vtkTypeBool);
  vtkSetClampMacro(ActiveRadius, double, 1e-6, 1.0);
  vtkGetMacro(ActiveRadius, double);
  vtkSetClampMacro(GeodesicThreshold, double, 1e-6, 10.0);
  vtkGetMacro(GeodesicThreshold, double);
  vtkSetClampMacro(AmplificationAlpha, double, 1.0, 100.0);
  vtkGetMacro(AmplificationAlpha, double);
  vtkSetClampMacro(AmplificationBeta, double, 1e-3, 1000.0);
  vtkGetMacro(AmplificationBeta, double);
  ///@}

  ///@{
  /**
   * Results of the active-point stage of the last execution: the number of input points flagged
   * active, its time in seconds, and a warning (empty when the envelope has the input's genus
   * and component count).
   */
  vtkIdType GetNumberOfActivePoints() const { return this->ResultInteger("NumberOfActivePoints"); }
  double GetActivePointTime() const { return this->GetResultNumber("ActivePointTime"); }
  const char* GetTopologyWarning() const { return this->GetResultText("TopologyWarning"); }
  ///@}

  ///@{
  /**
   * If on, output port 2 receives the sampled signed distance field as a dense vtkImageData
   * (point array `SignedDistance`, and `ModifiedSignedDistance` = phi * SDF when active points
   * were found). Off by default: the dense grid can be large.
   */
  vtkSetMacro(GenerateDistanceField, vtkTypeBool);
  vtkGetMacro(GenerateDistanceField, vtkTypeBool);
  vtkBooleanMacro(GenerateDistanceField, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Number of worker threads; 0 (the default) uses all cores. Results are identical for every
   * thread count.
   */
  vtkSetClampMacro(NumberOfThreads, int, 0, 4096);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /**
   * Optional last step (paper §3.3, off by default): optimize the simplified cage as
   * vtkCageOptimizeFilter does, with the parameters below (same meaning and defaults there). The
   * optimized cage is verified like any other; if the optimization cannot improve or verify it,
   * the simplified cage is output with a warning.
   */
  vtkSetMacro(Optimize, vtkTypeBool);
  vtkGetMacro(Optimize, vtkTypeBool);
  vtkBooleanMacro(Optimize, vtkTypeBool);
  vtkSetClampMacro(Energy, int, 0, 1);
  vtkGetMacro(Energy, int);
  void SetEnergyToMIPS() { this->SetEnergy(0); }
  void SetEnergyToSpacing() { this->SetEnergy(1); }
  vtkSetClampMacro(TargetSpacing, double, 0.0, 1.0);
  vtkGetMacro(TargetSpacing, double);
  vtkSetClampMacro(BarrierWeight, double, 0.0, 1.0e6);
  vtkGetMacro(BarrierWeight, double);
  vtkSetClampMacro(BarrierDistance, double, 0.0, 0.5);
  vtkGetMacro(BarrierDistance, double);
  vtkSetClampMacro(NumberOfIterations, int, 0, 1000);
  vtkGetMacro(NumberOfIterations, int);
  vtkSetMacro(EdgeFlips, vtkTypeBool);
  vtkGetMacro(EdgeFlips, vtkTypeBool);
  vtkBooleanMacro(EdgeFlips, vtkTypeBool);
  vtkSetClampMacro(HausdorffFactor, double, 0.0, 1000.0);
  vtkGetMacro(HausdorffFactor, double);
  vtkSetClampMacro(TargetMinimumAngle, double, 0.0, 59.0);
  vtkGetMacro(TargetMinimumAngle, double);
  vtkSetClampMacro(MaximumSweeps, int, 1, 1000);
  vtkGetMacro(MaximumSweeps, int);
  ///@}

  ///@{
  /**
   * Optimization results (only valid after the filter has executed with Optimize on): E_quality
   * before and after (see vtkCageOptimizeFilter) and the time in seconds.
   */
  double GetEnergyBefore() const { return this->GetResultNumber("EnergyBefore"); }
  double GetEnergyAfter() const { return this->GetResultNumber("EnergyAfter"); }
  double GetOptimizationTime() const { return this->GetResultNumber("OptimizationTime"); }
  ///@}

  ///@{
  /**
   * Timings of the last execution, in seconds (only valid after the filter has executed):
   * input validation, distance field, isosurface, envelope verification, simplification, final
   * cage verification, and the whole run.
   */
  double GetValidationTime() const { return this->GetResultNumber("ValidationTime"); }
  double GetDistanceFieldTime() const { return this->GetResultNumber("DistanceFieldTime"); }
  double GetIsosurfaceTime() const { return this->GetResultNumber("IsosurfaceTime"); }
  double GetVerificationTime() const { return this->GetResultNumber("VerificationTime"); }
  double GetSimplificationTime() const { return this->GetResultNumber("SimplificationTime"); }
  double GetCageVerificationTime() const { return this->GetResultNumber("CageVerificationTime"); }
  double GetTotalTime() const { return this->GetResultNumber("TotalTime"); }
  ///@}

  ///@{
  /**
   * Simplification outcome (only valid after the filter has executed): the number of cage
   * vertices reached, whether it equals TargetNumberOfVertices, and why the simplification stopped
   * early (empty when the target was reached).
   */
  int GetVerticesReached() const { return static_cast<int>(this->ResultInteger("VerticesReached")); }
  bool GetTargetReached() const { return this->ResultInteger("TargetReached") != 0; }
  const char* GetStopReason() const { return this->GetResultText("StopReason"); }
  ///@}

  ///@{
  /**
   * Measured minimum distance between the cage and the input (exact triangle-triangle
   * distance), in input units and relative to the unit sphere (only valid after the filter has
   * executed).
   */
  double GetMeasuredClearance() const { return this->GetResultNumber("MeasuredClearance"); }
  double GetMeasuredClearanceRelative() const { return this->GetResultNumber("MeasuredClearanceRelative"); }
  ///@}

  ///@{
  /**
   * Verdicts and counts of the last execution (only valid after the filter has executed):
   * whether enclosure was verified, how many trapped air pockets were removed, the genus and the
   * number of components of the envelope, the voxel size actually used (relative, after
   * refinements), and whether the input was inward-oriented and had to be flipped.
   */
  bool GetEnclosureVerified() const { return this->ResultInteger("EnclosureVerified") != 0; }
  int GetRemovedPockets() const { return static_cast<int>(this->ResultInteger("RemovedPockets")); }
  int GetEnvelopeGenus() const { return static_cast<int>(this->ResultInteger("EnvelopeGenus")); }
  int GetEnvelopeComponents() const { return static_cast<int>(this->ResultInteger("EnvelopeComponents")); }
  double GetVoxelSizeUsed() const { return this->GetResultNumber("VoxelSizeUsed"); }
  bool GetInputWasFlipped() const { return this->ResultInteger("InputWasFlipped") != 0; }
  ///@}

  /**
   * Outcome of the last execution: "Ok", "EmptyInput", "InvalidInput", "Cancelled",
   * "VerificationFailed" or "Failed" (only valid after the filter has executed).
   */
  const char* GetStatusString() const { return this->StatusString.c_str(); }

  /**
   * The error (or cancellation reason) of the last execution; empty when it succeeded.
   */
  const char* GetLastErrorMessage() const { return this->LastErrorMessage.c_str(); }

protected:
  vtkSDFCageFilter();
  ~vtkSDFCageFilter() override;

  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  // parameters
  int TargetNumberOfVertices;
  double IsoValue;
  double VoxelSize;
  double MinimumClearance;
  double Adaptivity;
  int MaximumRefinements;
  int MaximumEnvelopeWidenings;
  int MaximumRelaxations;
  vtkTypeBool ChooseIsoValueFirst;
  int MaximumTopologyRepairs;
  vtkTypeBool RequireTopology;
  vtkTypeBool CoarseFirst;
  double MemoryLimit = 0.0;
  vtkTypeBool GenerateDistanceField;
  int NumberOfThreads;
  vtkTypeBool UseActivePoints;
  double ActiveRadius;
  double GeodesicThreshold;
  double AmplificationAlpha;
  double AmplificationBeta;
  vtkTypeBool Optimize;
  int Energy;
  double TargetSpacing;
  double BarrierWeight;
  double BarrierDistance;
  int NumberOfIterations;
  vtkTypeBool EdgeFlips;
  double HausdorffFactor;
  double TargetMinimumAngle;
  int MaximumSweeps;
  int SignMode = 0;
  std::vector<int> NestedVertexCounts;

  // outcome of the last execution (the results are in Internals' table)
  std::string StatusString;
  std::string LastErrorMessage;

private:
  vtkSDFCageFilter(const vtkSDFCageFilter&) = delete;
  void operator=(const vtkSDFCageFilter&) = delete;

  // the phases of RequestData (Execute: on the whole input, see SDFCageParallel.h)
  int Execute(vtkPolyData* input, vtkInformationVector* outputVector);
  int ExecuteNested(const sdfcage::PolygonMesh& mesh, vtkPolyData* cage, vtkPolyData* envelope, vtkImageData* field,
    vtkMultiBlockDataSet* levels);
  void MakeEmptyLevels(vtkMultiBlockDataSet* levels) const;
  void AdoptResults(vtkFieldData* fd);
  void ResetResults();
  int RejectInput(vtkPolyData* input, vtkPolyData* cage);
  int Fail(const std::string& status, const std::string& message, vtkPolyData* cage);
  int DeliverOutputs(const sdfcage::CageResult& result, vtkPolyData* cage, vtkPolyData* envelope, vtkImageData* field);
  void WarnAbout(const sdfcage::CageResult& result, int target, const std::string& prefix = std::string());
  void PublishResults(vtkPolyData* cage) const;
  long long ResultInteger(const char* name) const;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
