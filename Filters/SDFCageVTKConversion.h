// SDFCage — Filters (private): conversions between VTK data and Core's types, shared by the
// filters of this module, and the adapter from Core's Progress to a VTK algorithm.
#pragma once

#include "vtkAlgorithm.h"
#include "vtkFieldData.h"
#include "vtkNew.h"

#include "Envelope/Envelope.h"
#include "Mesh/Mesh.h"
#include "Common/Progress.h"
#include "Pipeline/Results.h"

#include <string>
#include <thread>
#include <vector>

class vtkImageData;
class vtkPolyData;

namespace sdfcage_vtk
{
//------------------------------------------------------------------------------
// Forwards Core's progress to the filter, and the filter's abort flag to Core.
// Core may call report()/pollCancel() from worker threads; VTK objects are only touched from the
// thread that runs RequestData (the one that constructed this object). Cancellation still reaches
// the workers: Progress latches the flag in an atomic once pollCancel() has returned true.
class FilterProgress final : public sdfcage::Progress
{
public:
  explicit FilterProgress(vtkAlgorithm* filter)
    : Filter(filter)
    , Owner(std::this_thread::get_id())
  {
  }

protected:
  void report(double overall, const std::string& stage) override
  {
    if (std::this_thread::get_id() != this->Owner)
    {
      return;
    }
    // Throttle: a new stage always shows; inside a stage, report every 1% at most (each
    // UpdateProgress fires observers, which in ParaView repaint a progress bar).
    const bool newStage = stage != this->LastStage;
    if (!newStage && overall < this->LastReported + 0.01)
    {
      return;
    }
    if (newStage)
    {
      this->LastStage = stage;
      this->Filter->SetProgressText(stage.c_str());
    }
    this->LastReported = overall;
    this->Filter->UpdateProgress(overall);
  }

  bool pollCancel() override
  {
    return std::this_thread::get_id() == this->Owner && this->Filter->GetAbortExecute() != 0;
  }

private:
  vtkAlgorithm* Filter;
  std::thread::id Owner;
  std::string LastStage;
  double LastReported = -1.0;
};

/// The cells of a vtkPolyData as Core's polygon mesh (strips split, verts/lines kept as 1-/2-
/// point cells for Core to count and ignore).
void ToPolygonMesh(vtkPolyData* input, sdfcage::PolygonMesh& mesh);

/// A triangle mesh as vtkPolyData, with point scalars "DistanceToInput" when `distance` has one
/// value per point.
void ToPolyData(const sdfcage::TriangleMesh& mesh, const std::vector<double>& distance, vtkPolyData* output);

/// A sampled field as point data `name` of an image (the first array becomes the scalars).
void ToImageData(const sdfcage::ScalarImage& field, vtkImageData* output, const char* name);

/// Machine-readable status identifiers (Core's statusName() is for humans).
const char* StatusIdentifier(sdfcage::Status status);

template <typename ArrayT, typename ValueT>
void AddFieldValue(vtkFieldData* fd, const char* name, ValueT value)
{
  vtkNew<ArrayT> array;
  array->SetName(name);
  array->SetNumberOfTuples(1);
  array->SetValue(0, value);
  fd->AddArray(array);
}

/// One one-tuple array per result of Core's table, named like the result: flags as vtkIntArray
/// (0/1), counts as vtkIdTypeArray, measures as vtkDoubleArray, texts as vtkStringArray.
void AddResultArrays(vtkFieldData* fd, const sdfcage::ResultTable& results);

/// A result by name for the filters' generic getters: flags as 0/1; 0 (or "") for texts, numbers
/// and unknown names as the other kind.
double ResultNumber(const sdfcage::ResultTable& results, const char* name);
const char* ResultText(const sdfcage::ResultTable& results, const char* name);
/// The name of result `index` ("" out of range).
const char* ResultName(const sdfcage::ResultTable& results, int index);

} // namespace sdfcage_vtk
