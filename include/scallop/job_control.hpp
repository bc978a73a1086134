#pragma once
// Progress and cancellation of long library calls (scallop::plan, scallop::toolpaths, ...).
//
// Contract
// --------
// A JobControl holds a progress callback (may be empty) and a CancelToken. A long call takes
// one and installs it (JobControlScope) on its own thread for its duration; each parallel part
// installs the same control on the worker threads it starts. Without one, nothing is reported
// and nothing can be cancelled, at the cost of one thread-local read per poll. Any other
// library call (optimalSlicing, verifyProgram, ...) polls the same way: a caller who installs
// a JobControlScope around it can cancel it too.
//
// Cancellation: CancelToken::cancel() is thread-safe and may be called at any moment from any
// thread, the progress callback included. The work polls the token (checkCancelled) in every
// loop whose iterations are short: per plane, per traced section step, per envelope vertex,
// per gouge sample block, per simulated grid row, per run-on search step, per Gauss-map cell.
// Once a poll sees the flag it throws scallop::Cancelled, which unwinds the call: it returns
// no result, and whatever files the caller writes at the end are not written.
// tests/jobs/plan_test.cpp cancels plans at spread moments and measures how long they take
// to stop; the README gives the figures.
//
// Progress: the callback receives (fraction, stage) on the thread that called, never on a
// worker: fraction in [0, 1], never decreasing within a call, ending at 1; stage a short
// phrase naming what runs ("cutting the surface with 87 planes"). Stages nest: a stage that
// spans [from, to] of its caller's range maps its own [0, 1] into it (ProgressStage), so a
// call inside another (toolpaths inside plan) reports in its caller's scale. An exception the
// callback throws propagates out of the call.

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "scallop/error.hpp"

namespace scallop {

/// Thrown by checkCancelled() once the job's CancelToken is set.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

/// A shared flag: copies share it, so the caller keeps one copy and gives the job another.
class CancelToken {
 public:
  CancelToken() : flag_(std::make_shared<std::atomic<bool>>(false)) {}
  /// Asks the job to stop; thread-safe, idempotent.
  void cancel() const noexcept { flag_->store(true, std::memory_order_relaxed); }
  bool cancelled() const noexcept { return flag_->load(std::memory_order_relaxed); }

 private:
  std::shared_ptr<std::atomic<bool>> flag_;
};

/// (fraction in [0, 1], stage name): see the contract.
using ProgressCallback = std::function<void(double fraction, const std::string& stage)>;

struct JobControl {
  ProgressCallback progress;  ///< empty: no progress
  CancelToken cancel;
};

/// Installs `control` (may be null: none) on this thread until destroyed, restoring what was
/// there before. Installing the control already there (a call nested in another with the
/// caller's control) keeps the caller's stage, so progress goes on in its scale. `reportsProgress` false: a worker thread, which polls the token but never
/// calls the progress callback.
class JobControlScope {
 public:
  explicit JobControlScope(const JobControl* control, bool reportsProgress = true);
  ~JobControlScope();
  JobControlScope(const JobControlScope&) = delete;
  JobControlScope& operator=(const JobControlScope&) = delete;

 private:
  const JobControl* previousControl_;
  bool previousReports_;
  double previousFrom_, previousTo_, previousLast_;
  const std::string* previousStage_;
  bool installed_ = false;  ///< false: the control was there already (see above)
};

/// The control installed on this thread (null: none): what a parallel part hands its workers.
const JobControl* currentJobControl() noexcept;

/// Throws Cancelled when this thread's control has been cancelled; otherwise nothing.
void checkCancelled();

/// A stage of the current call: reports (from, stage) in the enclosing range now, and maps
/// [0, 1] of its own into [from, to] of the enclosing range for the stages and advances nested
/// in it, until destroyed. Also polls the token. On a thread without a progress callback it
/// only polls.
class ProgressStage {
 public:
  ProgressStage(double from, double to, const std::string& stage);
  /// A part [from, to] of the enclosing stage under the enclosing stage's name: maps the
  /// advances inside it, reports no new stage.
  ProgressStage(double from, double to);
  ~ProgressStage();
  ProgressStage(const ProgressStage&) = delete;
  ProgressStage& operator=(const ProgressStage&) = delete;
  /// `done` of `total` items of this stage are finished: reports the fraction (at most every
  /// half per cent of the whole) and polls the token.
  void advance(std::size_t done, std::size_t total);

 private:
  std::string stage_;
  double outerFrom_, outerTo_;
  const std::string* outerStage_;
};

/// ProgressStage::advance for the innermost stage of this thread, from code that does not hold
/// it (a loop inside the stage's call): polls the token everywhere, reports only on the
/// calling thread (a worker's call only polls).
void advanceStage(std::size_t done, std::size_t total);

}  // namespace scallop
