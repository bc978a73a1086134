#pragma once
// How many threads scallop's parallel loops use.
//
// Contract
// --------
// Every parallel part of scallop (the contour and raster planes: section, passes, run-on and
// ways off; lifting passes to the drop envelope; the gouge check's sample blocks; the cut
// simulation's clearance and reach checks; the exact heights of a CAD part) takes its thread
// count from its options' `threads` field where it has one (0 there means threadCount()
// below), else threadCount(). Each of them writes only its own slots and combines them in a fixed
// order, so results are the same, bit for bit, for every thread count (tests/cli/cli_test.cpp
// compares the files every command writes at 1 and 2 threads).
//
// threadCount(): the process-wide default, set by setThreadCount (the CLI's `--threads N`);
// 0 (the initial setting) means every core: std::thread::hardware_concurrency(), or 1 when
// that is unknown. Thread-safe (an atomic); meant to be set once, before the work starts.
//
// parallelForEach (below) is the one pool every parallel part runs on.
//
// Why the standard library and not TBB: the parallel parts are a handful of loops over
// independent items whose cost is known up front (passes, sample blocks, grid rows); a pool
// of std::jthreads pulling indices from an atomic counter balances them, keeps the result
// independent of the schedule, and adds no dependency to the core library (Debian's TBB is
// in the tree only because OpenCASCADE's CMake files name it).

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

#include "scallop/job_control.hpp"

namespace scallop {

namespace detail {
inline std::atomic<std::size_t> threadCountSetting{0};
}  // namespace detail

/// Sets the default thread count of every parallel part (0: every core).
inline void setThreadCount(std::size_t threads) { detail::threadCountSetting.store(threads); }

/// The default thread count: setThreadCount's value, or every core when that is 0 (>= 1).
inline std::size_t threadCount() {
  const std::size_t set = detail::threadCountSetting.load();
  if (set > 0) return set;
  return std::max<std::size_t>(1, std::thread::hardware_concurrency());
}

/// `requested` (an option's `threads` field) when positive, else threadCount().
inline std::size_t threadCount(std::size_t requested) { return requested > 0 ? requested : threadCount(); }

/// Runs work(i) for every i in [0, count) on min(threads, count) threads, the calling thread
/// among them; items are handed out in increasing order from a shared counter, so uneven
/// items balance. The calling thread's job control (job_control.hpp) is installed on every
/// worker: work polls cancellation, and progress is reported on the calling thread only.
/// work(i) must write only its own slots (results independent of the schedule). An exception
/// from work(i) stops no other item; once all have run, the one of the lowest i is rethrown,
/// whatever the timing.
template <typename Work>
void parallelForEach(std::size_t count, std::size_t threads, const Work& work) {
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  const auto run = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        work(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    const JobControl* const control = currentJobControl();
    for (std::size_t t = 1; t < std::min(threads, count); ++t)
      pool.emplace_back([&run, control] {
        const JobControlScope scope(control, false);
        run();
      });
    run();
  }
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
}

}  // namespace scallop
