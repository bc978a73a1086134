#pragma once
// Cancels spread over a job's run, from a second thread: the job runs `moments` times, each
// time cancelled after (k + 1/2) / moments of `whole` seconds. What the cancel tests of the
// library calls (plan, planMesh) judge.

#include <algorithm>
#include <chrono>
#include <functional>
#include <optional>
#include <thread>

#include "scallop/error.hpp"
#include "scallop/job_control.hpp"

namespace scallop::test {

struct CancelFigures {
  int cancelled = 0;     ///< runs that threw scallop::Cancelled
  double worst = 0.0;    ///< the longest from a cancel to the throw (seconds)
  double ranOn = 0.0;    ///< the longest a run went on after a cancel it did not throw for
};

inline CancelFigures cancelAtSpreadMoments(int moments, double whole,
                                           const std::function<void(const JobControl&)>& job) {
  using Clock = std::chrono::steady_clock;
  CancelFigures figures;
  for (int k = 0; k < moments; ++k) {
    const double delay = whole * (k + 0.5) / moments;
    JobControl control;
    std::optional<Clock::time_point> stopped;
    bool threwCancelled = false;
    std::thread worker([&] {
      try {
        job(control);
      } catch (const Cancelled&) {
        threwCancelled = true;
      }
      stopped = Clock::now();
    });
    std::this_thread::sleep_for(std::chrono::duration<double>(delay));
    const Clock::time_point asked = Clock::now();
    control.cancel.cancel();
    worker.join();
    if (threwCancelled) {
      ++figures.cancelled;
      figures.worst = std::max(figures.worst, std::chrono::duration<double>(*stopped - asked).count());
    } else if (*stopped > asked) {
      // Not stopped, though asked while it ran: it may only have been past its last poll, so
      // it must have ended within the same bound.
      figures.ranOn = std::max(figures.ranOn, std::chrono::duration<double>(*stopped - asked).count());
    }
  }
  return figures;
}

}  // namespace scallop::test
