// SDFCage — Filters (private): the filters under MPI (pvbatch or pvserver under mpiexec, any
// VTK program with a vtkMPIController as the global controller).
//
// There every process is handed its own piece of the input, but a cage, an active-point
// analysis, an optimization and a verdict are properties of the whole surface. So when the
// pieces are distributed the filters gather them on process 0, compute there, output the result
// on process 0 and empty pieces elsewhere, and broadcast what every process should report (the
// return code and the results in the field data). The one place where that happens is here.
//
// "Distributed" means: the global controller has more than one process and the input was asked
// for as many pieces as there are processes (what ParaView's data servers do). A pipeline that
// asks for the whole input (piece 0 of 1, e.g. a plain VTK Update() on one process of an MPI
// program, or each rank of a batch caging its own meshes) runs locally, without communication.
// Collective: when distributed, every process must execute the filter (as every ParaView data
// server does); the gather and broadcast would wait for a missing one.
#pragma once

#include "vtkSmartPointer.h"

#include "Pipeline/Results.h"

#include <functional>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkFieldData;
class vtkInformation;
class vtkInformationVector;
class vtkMultiProcessController;
class vtkPolyData;

namespace sdfcage_vtk
{

/// RequestUpdateExtent of the filters: every input gets the piece the output was asked for,
/// without ghost levels (ghost cells would only be dropped again when the pieces are joined).
void RequestSamePieceWithoutGhosts(vtkInformationVector** inputVector, int numberOfInputPorts,
  vtkInformationVector* outputVector, vtkInformation* request);

/// The global controller when the input of `inputVector` is distributed over its processes (see
/// above), nullptr otherwise.
vtkMultiProcessController* DistributingController(vtkInformationVector** inputVector);

/// Joins pieces of one surface into one vtkPolyData: cells flagged as duplicated ghost cells are
/// dropped; a point within 1e-12 of the bounding-box diagonal (in each coordinate) of a point of
/// an earlier piece becomes that point (pieces share their seam points, which processes may
/// compute with different rounding), points within a piece are never merged (a
/// serial input's coincident points stay apart, as in a serial run); point and cell arrays
/// present in every non-empty piece are kept, and the field data of the first non-empty piece.
/// Null pieces are skipped. Exposed for tests.
vtkSmartPointer<vtkPolyData> JoinPieces(const std::vector<vtkPolyData*>& pieces, vtkIdType* mergedPoints = nullptr);

/// The whole of a surface handed out in pieces, on process 0 (collective): every process's piece
/// gathered there and joined (JoinPieces); nullptr on the other processes. A null piece counts as
/// empty.
vtkSmartPointer<vtkPolyData> JoinOnProcessZero(vtkMultiProcessController* controller, vtkPolyData* piece);

/// The whole of a surface handed out in pieces, on every process (collective): the pieces are
/// gathered on process 0, joined (JoinPieces) and broadcast. A null piece counts as empty; the
/// result is empty (never null) when every piece is.
vtkSmartPointer<vtkPolyData> JoinOnEveryProcess(vtkMultiProcessController* controller, vtkPolyData* piece);

/// The body of a filter's RequestData, given its inputs (one vtkPolyData per input port,
/// connection 0, nullptr where there is none) and the filter's output vector.
using ExecuteFunction = std::function<int(const std::vector<vtkPolyData*>& inputs)>;
/// Called on processes other than 0 with the field data broadcast from process 0 (that of
/// output port `ResultsPort`), so that the filter's getters report what process 0 computed.
using AdoptFunction = std::function<void(vtkFieldData* results)>;

struct WholeSurfaceRun
{
  int ResultsPort = 0;         ///< output port whose field data carries the results
  std::vector<int> ImagePorts; ///< vtkImageData outputs: empty pieces with process 0's origin, spacing and arrays
};

/// Runs `execute` on the whole input: directly when the input is not distributed; otherwise
/// gathers every input port's pieces on process 0 (JoinPieces), executes there, leaves the other
/// processes' outputs empty (image outputs: no points, the same origin, spacing and array names
/// as process 0's), copies process 0's results field data to them and returns process 0's
/// return code on every process.
int RunOnWholeSurface(vtkAlgorithm* self, vtkInformationVector** inputVector, vtkInformationVector* outputVector,
  const WholeSurfaceRun& run, const ExecuteFunction& execute, const AdoptFunction& adopt);

/// Sets the values of `table` (whose names and kinds are known) from one-tuple field-data arrays
/// of the same names (the inverse of AddResultArrays); names absent from `fd` keep their value.
void ReadResultArrays(vtkFieldData* fd, sdfcage::ResultTable& table);

/// The first value of the string array `name` of `fd` ("" when absent).
std::string FieldText(vtkFieldData* fd, const char* name);

} // namespace sdfcage_vtk
