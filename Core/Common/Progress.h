// SDFCage — Core: one progress/cancel mechanism shared by Core, OpenVDB (see
// VdbInterrupter in the OpenVDB translation units), the VTK filters and the CLI.
#pragma once

#include <atomic>
#include <string>

namespace sdfcage
{

/// Progress sink and cancel flag, shaped like OpenVDB's util::NullInterrupter.
///
/// Algorithms report a fraction of the current *stage*; the stage maps it onto [begin, end] of
/// the whole run. update() and cancelled() are thread-safe and cheap (atomics); report() is called
/// with the overall fraction from whichever thread called update(): overrides that touch a GUI or
/// VTK must forward only from their own thread. Cancel by calling cancel() from any thread, or by
/// overriding pollCancel() (e.g. to read vtkAlgorithm::GetAbortExecute()).
class Progress
{
public:
  virtual ~Progress() = default;

  /// Starts a stage that covers [begin, end] of the whole run (fractions in [0, 1]).
  void beginStage(const char* name, double begin, double end);
  /// Reports progress inside the current stage (0..1). Returns true when cancelled.
  bool update(double stageFraction);
  /// True once cancel() was called or pollCancel() returned true. Thread-safe.
  bool cancelled();
  /// Requests cancellation (any thread).
  void cancel() { this->Cancelled.store(true); }

  const std::string& stageName() const { return this->Stage; }
  double overall() const { return this->Overall.load(); }

protected:
  /// Called with the overall fraction (0..1) and the stage name; may be called from any thread.
  virtual void report(double /*overall*/, const std::string& /*stage*/) {}
  /// Extra cancel source, polled by cancelled(); may be called from any thread.
  virtual bool pollCancel() { return false; }

private:
  std::atomic<bool> Cancelled{ false };
  std::atomic<double> Overall{ 0.0 };
  std::string Stage;
  double Begin = 0.0;
  double End = 1.0;
};

/// Null-safe helpers.
inline bool progressCancelled(Progress* p)
{
  return p && p->cancelled();
}
inline bool progressUpdate(Progress* p, double f)
{
  return p && p->update(f);
}
inline void progressStage(Progress* p, const char* name, double b, double e)
{
  if (p)
  {
    p->beginStage(name, b, e);
  }
}

} // namespace sdfcage
