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

#include <algorithm>
#include <chrono>
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
//
// A progress event fires at every new stage, every 1% and, whatever the progress, at least every
// EventInterval seconds while Core runs (from its progress reports or its cancel checks): ParaView's
// Cancel and the sdfcage program's Ctrl-C set AbortExecute from a ProgressEvent observer, so a
// stage that reports little progress would otherwise not be cancelled before it ends.
class FilterProgress final : public sdfcage::Progress
{
public:
  explicit FilterProgress(vtkAlgorithm* filter)
    : Filter(filter)
    , Owner(std::this_thread::get_id())
    , LastEvent(std::chrono::steady_clock::now())
  {
  }

  /// Seconds between progress events at the most, while Core reports or checks for a cancel.
  static constexpr double EventInterval = 0.05;

protected:
  void report(double overall, const std::string& stage) override
  {
    if (std::this_thread::get_id() != this->Owner)
    {
      return;
    }
    // Throttle: a new stage always shows; inside a stage, report every 1% at most (each
    // UpdateProgress fires observers, which in ParaView repaint a progress bar), or when the
    // last event is EventInterval old.
    const bool newStage = stage != this->LastStage;
    if (!newStage && overall < this->LastReported + 0.01 && !this->eventDue())
    {
      return;
    }
    if (newStage)
    {
      this->LastStage = stage;
      this->Filter->SetProgressText(stage.c_str());
    }
    this->LastReported = overall;
    this->fire(overall);
  }

  bool pollCancel() override
  {
    if (std::this_thread::get_id() != this->Owner)
    {
      return false;
    }
    if (this->eventDue())
    {
      this->fire(std::max(this->LastReported, this->overall()));
    }
    return this->Filter->GetAbortExecute() != 0;
  }

private:
  bool eventDue() const
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - this->LastEvent).count() >=
      EventInterval;
  }
  void fire(double overall)
  {
    this->LastEvent = std::chrono::steady_clock::now();
    this->Filter->UpdateProgress(std::min(1.0, std::max(0.0, overall)));
  }

  vtkAlgorithm* Filter;
  std::thread::id Owner;
  std::string LastStage;
  double LastReported = -1.0;
  std::chrono::steady_clock::time_point LastEvent;
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
