// scallop-bench, the whole plan by stage: where the time of `scallop plan` goes, and how each
// stage scales with threads, so that the speed on more cores can be projected from measured
// figures (README, "Threads").
//   BM_PlanStages/<surface>/<strategy>/<threads>
//     scallop::plan (jobs/plan.hpp: N* or the feed angle, passes, drop envelope, links, gouge
//     check, G-code, simulated cut, rest passes) on paper-1 (1) or paper-2 (2), contour (0) or
//     raster (1), on 1 or 2 threads. Counters: the wall seconds of each stage, told apart by
//     the progress callback's stage names (a stage runs from its first report to the next
//     stage's), named s1..s9 in the order of first report; the label lists the names.
//     Run at 1 and 2 threads in the same run: a stage's speed-up S = t1 / t2 gives its
//     parallel fraction p = 2 (1 - 1 / S) (Amdahl), and its time on N cores
//     t1 ((1 - p) + p / N), an estimate that assumes the parallel loops keep scaling.

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/jobs/plan.hpp"
#include "scallop/jobs/toolpath_job.hpp"
#include "scallop/parallel.hpp"

namespace {

// Wall time per stage, in the order the stages first report.
class StageClock {
 public:
  void report(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    if (!names_.empty() && stage == names_[current_]) return;
    if (!names_.empty()) seconds_[current_] += std::chrono::duration<double>(now - since_).count();
    since_ = now;
    for (current_ = 0; current_ < names_.size() && names_[current_] != stage; ++current_) {
    }
    if (current_ == names_.size()) {
      names_.push_back(stage);
      seconds_.push_back(0.0);
    }
  }
  [[nodiscard]] const std::vector<std::string>& names() const { return names_; }
  [[nodiscard]] const std::vector<double>& seconds() const { return seconds_; }

 private:
  std::vector<std::string> names_;
  std::vector<double> seconds_;
  std::size_t current_ = 0;
  std::chrono::steady_clock::time_point since_;
};

void BM_PlanStages(benchmark::State& state) {
  const char* surfaceName = state.range(0) == 1 ? "paper-1" : "paper-2";
  const scallop::Surface surface = scallop::exampleSurface(surfaceName);
  scallop::PlanOptions options;
  options.source = surfaceName;
  options.strategy = state.range(1) == 0 ? scallop::Strategy::contour : scallop::Strategy::raster;
  scallop::setThreadCount(static_cast<std::size_t>(state.range(2)));
  StageClock clock;
  scallop::JobControl control;
  control.progress = [&clock](double, const std::string& stage) { clock.report(stage); };
  for (auto _ : state) {
    const scallop::PlanResult result = scallop::plan(surface, options, control);
    benchmark::DoNotOptimize(result.program.data());
  }
  scallop::setThreadCount(0);
  std::string label = fmt::format("{} {}:", surfaceName, scallop::strategyName(options.strategy));
  for (std::size_t i = 0; i < clock.names().size(); ++i) {
    state.counters[fmt::format("s{}", i + 1)] =
        benchmark::Counter(clock.seconds()[i], benchmark::Counter::kAvgIterations);
    label += fmt::format(" s{}={}", i + 1, clock.names()[i]);
  }
  state.SetLabel(label);
}

}  // namespace

BENCHMARK(BM_PlanStages)
    ->ArgsProduct({{1, 2}, {0, 1}, {1, 2}})
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
