#include "Common/Progress.h"

#include <algorithm>

namespace sdfcage
{

void Progress::beginStage(const char* name, double begin, double end)
{
  this->Stage = name ? name : "";
  this->Begin = begin;
  this->End = end;
  this->update(0.0);
}

bool Progress::update(double stageFraction)
{
  const double f = this->Begin + std::clamp(stageFraction, 0.0, 1.0) * (this->End - this->Begin);
  // monotonic overall value (several threads may report slightly out of order)
  double prev = this->Overall.load();
  while (f > prev && !this->Overall.compare_exchange_weak(prev, f))
  {
  }
  this->report(this->Overall.load(), this->Stage);
  return this->cancelled();
}

bool Progress::cancelled()
{
  if (!this->Cancelled.load() && this->pollCancel())
  {
    this->Cancelled.store(true);
  }
  return this->Cancelled.load();
}

} // namespace sdfcage
