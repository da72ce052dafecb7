#include "Common/Threads.h"

#include <tbb/global_control.h>

namespace sdfcage
{

struct ThreadLimit::Control
{
  explicit Control(int n)
    : Value(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(n))
  {
  }
  tbb::global_control Value;
};

ThreadLimit::ThreadLimit(int numberOfThreads)
{
  if (numberOfThreads > 0)
  {
    Limit = std::make_unique<Control>(numberOfThreads);
  }
}

ThreadLimit::~ThreadLimit() = default;

} // namespace sdfcage
