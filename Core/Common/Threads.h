// SDFCage — Core: the one thread-count option of every entry point (generateCage,
// analyzeActivePoints): while a ThreadLimit lives, TBB (and so OpenVDB) runs every stage on at most
// that many threads. Results never depend on the thread count.
#pragma once

#include <memory>

namespace sdfcage
{

class ThreadLimit
{
public:
  /// `numberOfThreads` <= 0: no limit (all cores).
  explicit ThreadLimit(int numberOfThreads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

private:
  struct Control;
  std::unique_ptr<Control> Limit;
};

} // namespace sdfcage
