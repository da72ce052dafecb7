// SDFCage — Core: a cancel that lets a verification outlive the user's cancel a little.
#pragma once

#include "Common/Progress.h"

#include <atomic>
#include <chrono>

namespace sdfcage
{

/// Cancelled `grace` seconds after `user` is first seen cancelled (at once when `user` already is
/// at construction). Given to the verification of a cage that may be output after a cancel: one
/// whose verification ends within the grace is output, one whose verification runs out of it is
/// not (a cancel must answer at once, and an unverified cage is never output). Polls `user`
/// (which fires the filter's progress events) from any thread; `user` may be null (never
/// cancelled then).
class GracePeriod final : public Progress
{
public:
  GracePeriod(Progress* user, double grace)
    : User(user)
    , Grace(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(grace)))
  {
    if (progressCancelled(user))
    {
      this->Seen.store(now());
    }
  }
  /// True once the grace after the user's cancel ran out.
  bool expired() { return this->cancelled(); }

protected:
  bool pollCancel() override
  {
    Clock::rep seen = this->Seen.load();
    if (seen == 0)
    {
      if (!progressCancelled(this->User))
      {
        return false;
      }
      Clock::rep none = 0;
      this->Seen.compare_exchange_strong(none, now());
      seen = this->Seen.load();
    }
    return now() - seen >= this->Grace.count();
  }

private:
  using Clock = std::chrono::steady_clock;
  static Clock::rep now() { return Clock::now().time_since_epoch().count(); }

  Progress* User;
  Clock::duration Grace;
  std::atomic<Clock::rep> Seen{ 0 }; ///< when `user` was first seen cancelled (0: not yet)
};

/// Seconds a verification may go on after a cancel (see GracePeriod): well inside the 0.5 s a
/// cancel may take to answer, on a loaded machine too.
constexpr double VerificationGrace = 0.15;

} // namespace sdfcage
