#include "scallop/job_control.hpp"

#include <algorithm>

namespace scallop {
namespace {

// This thread's job: its control, whether it may call the progress callback, the range of the
// whole [0, 1] that the innermost stage maps its own [0, 1] into, and the last fraction
// reported (progress never goes back).
struct ThreadJob {
  const JobControl* control = nullptr;
  bool reportsProgress = false;
  double from = 0.0;
  double to = 1.0;
  double last = 0.0;
  const std::string* stage = nullptr;  ///< the innermost ProgressStage's name
};

thread_local ThreadJob threadJob;

// Reports `fraction` of the whole (clamped so that it never decreases) with `stage`.
void report(double fraction, const std::string& stage) {
  ThreadJob& job = threadJob;
  if (job.control == nullptr || !job.reportsProgress || !job.control->progress) return;
  job.last = std::clamp(fraction, job.last, 1.0);
  job.control->progress(job.last, stage);
}

}  // namespace

JobControlScope::JobControlScope(const JobControl* control, bool reportsProgress)
    : previousControl_(threadJob.control),
      previousReports_(threadJob.reportsProgress),
      previousFrom_(threadJob.from),
      previousTo_(threadJob.to),
      previousLast_(threadJob.last),
      previousStage_(threadJob.stage) {
  // The same control again (toolpaths inside plan): the caller's stage, scale and progress go
  // on, and nothing is restored at the end.
  if (control != nullptr && control == previousControl_ && reportsProgress == previousReports_) return;
  installed_ = true;
  threadJob = ThreadJob{control, reportsProgress, 0.0, 1.0, 0.0, nullptr};
}

JobControlScope::~JobControlScope() {
  if (installed_)
    threadJob = ThreadJob{previousControl_, previousReports_, previousFrom_, previousTo_, previousLast_, previousStage_};
}

const JobControl* currentJobControl() noexcept { return threadJob.control; }

void checkCancelled() {
  const JobControl* control = threadJob.control;
  if (control != nullptr && control->cancel.cancelled()) throw Cancelled();
}

ProgressStage::ProgressStage(double from, double to, const std::string& stage)
    : stage_(stage), outerFrom_(threadJob.from), outerTo_(threadJob.to), outerStage_(threadJob.stage) {
  checkCancelled();
  const double width = outerTo_ - outerFrom_;
  threadJob.from = outerFrom_ + std::clamp(from, 0.0, 1.0) * width;
  threadJob.to = outerFrom_ + std::clamp(std::max(from, to), 0.0, 1.0) * width;
  threadJob.stage = &stage_;
  report(threadJob.from, stage_);
}

ProgressStage::ProgressStage(double from, double to)
    : outerFrom_(threadJob.from), outerTo_(threadJob.to), outerStage_(threadJob.stage) {
  checkCancelled();
  const double width = outerTo_ - outerFrom_;
  threadJob.from = outerFrom_ + std::clamp(from, 0.0, 1.0) * width;
  threadJob.to = outerFrom_ + std::clamp(std::max(from, to), 0.0, 1.0) * width;
  if (outerStage_ != nullptr) {
    stage_ = *outerStage_;
    threadJob.stage = &stage_;
  }
}

ProgressStage::~ProgressStage() {
  threadJob.from = outerFrom_;
  threadJob.to = outerTo_;
  threadJob.stage = outerStage_;
}

void ProgressStage::advance(std::size_t done, std::size_t total) { advanceStage(done, total); }

void advanceStage(std::size_t done, std::size_t total) {
  checkCancelled();
  const ThreadJob& job = threadJob;
  if (total == 0 || job.stage == nullptr || !job.reportsProgress) return;
  const double part = static_cast<double>(std::min(done, total)) / static_cast<double>(total);
  const double fraction = job.from + part * (job.to - job.from);
  if (fraction >= job.last + 0.005) report(fraction, *job.stage);
}

}  // namespace scallop
