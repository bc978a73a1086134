// scallop::plan (plan.hpp) and its job control (job_control.hpp): the library call writes what
// the CLI writes, refuses bad options before any work, reports monotone progress, and stops
// with scallop::Cancelled soon after a cancel at any moment.

#include "scallop/jobs/plan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "support/cancel_moments.hpp"
#include "support/cli_fixture.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

using Clock = std::chrono::steady_clock;

// A coarse plan of paper-1 (0.004 in scallops): the same job as the CLI's
// `plan --example paper-1 --scallop-height 0.004`, a second or two.
PlanOptions coarsePlan() {
  PlanOptions options;
  options.source = "example paper-1";
  options.scallopHeight = 0.004;
  return options;
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class PlanCli : public test::CliFixture {};

TEST_F(PlanCli, TheLibraryCallWritesTheFilesTheCliWrites) {
  const test::RunResult run = this->run("plan --example paper-1 --scallop-height 0.004 --quiet --out out");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const Surface surface = exampleSurface("paper-1");
  const PlanResult result = plan(surface, coarsePlan());
  const std::vector<OutputFile> files = planFiles(surface, result);
  ASSERT_EQ(files.size(), 7u);
  std::size_t onDisk = 0;
  for (const auto& entry : std::filesystem::directory_iterator(workDir_ / "out")) {
    (void)entry;
    ++onDisk;
  }
  EXPECT_EQ(onDisk, files.size());
  for (const OutputFile& file : files) {
    SCOPED_TRACE(file.path);
    const std::string written = test::readFile(workDir_ / "out" / file.path);
    EXPECT_FALSE(written.empty());
    EXPECT_TRUE(written == file.content);
  }
}

TEST(Plan, RefusesBadOptionsBeforeAnyWork) {
  const Surface surface = exampleSurface("paper-1");
  const auto refused = [&](PlanOptions options, const std::string& part) {
    int calls = 0;
    JobControl control;
    control.progress = [&calls](double, const std::string&) { ++calls; };
    try {
      plan(surface, options, control);
      ADD_FAILURE() << "accepted; expected an error naming '" << part << "'";
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
    }
    EXPECT_EQ(calls, 0) << part;
  };
  PlanOptions options;
  options.toolRadius = -0.25;
  refused(options, "tool radius");
  options = {};
  options.toolRadius = std::nan("");
  refused(options, "tool radius");
  options = {};
  options.scallopHeight = 0.3;  // >= R = 0.25
  refused(options, "smaller than the tool radius");
  options = {};
  options.scallopHeight = 0.001;
  options.spacing = 0.01;
  refused(options, "at most one");
  options = {};
  options.spacing = 0.6;  // >= 2 R
  refused(options, "diameter");
  options = {};
  options.rapidRate = 0.0;
  refused(options, "rapid rate");
}

TEST(Plan, ProgressIsMonotoneEndsAtOneAndLeavesTheResultAlone) {
  const Surface surface = exampleSurface("paper-1");
  std::vector<std::pair<double, std::string>> events;
  const std::thread::id caller = std::this_thread::get_id();
  bool onOtherThread = false;
  JobControl control;
  control.progress = [&](double fraction, const std::string& stage) {
    events.emplace_back(fraction, stage);
    onOtherThread = onOtherThread || std::this_thread::get_id() != caller;
  };
  const PlanResult watched = plan(surface, coarsePlan(), control);
  const PlanResult plain = plan(surface, coarsePlan());
  EXPECT_FALSE(onOtherThread);
  ASSERT_GE(events.size(), 10u);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_GE(events[i].first, 0.0);
    EXPECT_LE(events[i].first, 1.0);
    EXPECT_FALSE(events[i].second.empty());
    if (i > 0) {
      EXPECT_GE(events[i].first, events[i - 1].first) << events[i].second;
    }
  }
  EXPECT_EQ(events.back().first, 1.0);
  // The stages the contract names, in order.
  std::vector<std::string> expected = {"computing the optimal slicing orientation", "cutting the surface",
                                       "ordering and linking", "checking the ball", "writing the G-code",
                                       "simulating the cut"};
  std::size_t next = 0;
  for (const auto& [fraction, stage] : events)
    if (next < expected.size() && stage.find(expected[next]) != std::string::npos) ++next;
  EXPECT_EQ(next, expected.size());
  // Progress between the stages too: no gap wider than a fifth of the whole.
  for (std::size_t i = 1; i < events.size(); ++i)
    EXPECT_LE(events[i].first - events[i - 1].first, 0.2) << events[i].second;
  const std::vector<OutputFile> a = planFiles(surface, watched), b = planFiles(surface, plain);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].content == b[i].content) << a[i].path;
}

TEST(Plan, ACancelFromTheProgressCallbackStopsTheCallWithoutAResult) {
  // Moments in every stage of both strategies (the orientation's certificate, the adaptive
  // offsets, sections, envelope, linking, gouge check, simulation): whatever code runs then
  // (some of it catches scallop::Error to try another way), the call ends in Cancelled itself.
  const Surface surface = exampleSurface("paper-1");
  const std::vector<std::pair<Strategy, std::vector<double>>> moments = {
      {Strategy::contour, {0.0, 0.003, 0.05, 0.3, 0.5, 0.6, 0.85}}, {Strategy::raster, {0.01, 0.3, 0.6}}};
  for (const auto& [strategy, fractions] : moments) {
    for (const double at : fractions) {
      SCOPED_TRACE(testing::Message() << strategyName(strategy) << " at " << at);
      PlanOptions options = coarsePlan();
      options.strategy = strategy;
      JobControl control;
      double last = -1.0;
      int callsAfterCancel = 0;
      control.progress = [&](double fraction, const std::string&) {
        if (control.cancel.cancelled()) ++callsAfterCancel;
        last = fraction;
        if (fraction >= at) control.cancel.cancel();
      };
      EXPECT_THROW(plan(surface, options, control), Cancelled);
      EXPECT_EQ(callsAfterCancel, 0);
      EXPECT_LT(last, 1.0);
    }
  }
}

TEST(Plan, AnExceptionFromTheProgressCallbackPropagatesAsItself) {
  struct Stop : std::exception {};
  const Surface surface = exampleSurface("paper-1");
  JobControl control;
  control.progress = [](double fraction, const std::string&) {
    if (fraction > 0.5) throw Stop();
  };
  EXPECT_THROW(plan(surface, coarsePlan(), control), Stop);
}

TEST(Plan, ACancelFromAnotherThreadAtAnyMomentStopsItSoon) {
  const Surface surface = exampleSurface("paper-1");
  const Clock::time_point start = Clock::now();
  plan(surface, coarsePlan());
  const double whole = secondsSince(start);
  // Cancels spread over the whole run, from a second thread, while the plan runs on every core.
  constexpr int kMoments = 8;
  const scallop::test::CancelFigures figures = scallop::test::cancelAtSpreadMoments(
      kMoments, whole, [&](const JobControl& control) { plan(surface, coarsePlan(), control); });
  const auto [cancelled, worst, ranOn] = figures;
  // Runs vary with the machine's load (the plan runs on every core), so a later run may end
  // before its cancel; most cancels still come while it runs, and each of those stops it.
  EXPECT_GE(cancelled, kMoments / 2);
  EXPECT_LT(ranOn, 1.0);
  // The contract says 0.1 s; the bound here is wide because this machine is shared and the
  // suite runs two tests at a time (the README gives the figures measured alone).
  EXPECT_LT(worst, 1.0);
  RecordProperty("worst_cancel_latency_ms", static_cast<int>(worst * 1000.0));
  std::printf("plan of %.2f s: %d of %d cancels stopped it, the slowest in %.1f ms\n", whole, cancelled, kMoments,
              worst * 1000.0);
}

TEST(JobControl, ATokenIsSharedByItsCopiesAndNothingIsInstalledOutsideACall) {
  const CancelToken token;
  const CancelToken copy = token;
  EXPECT_FALSE(copy.cancelled());
  token.cancel();
  EXPECT_TRUE(copy.cancelled());
  EXPECT_EQ(currentJobControl(), nullptr);
  EXPECT_NO_THROW(checkCancelled());
  JobControl control;
  control.cancel = copy;
  {
    const JobControlScope scope(&control);
    EXPECT_EQ(currentJobControl(), &control);
    EXPECT_THROW(checkCancelled(), Cancelled);
    EXPECT_THROW(ProgressStage(0.0, 1.0, "stage"), Cancelled);
  }
  EXPECT_EQ(currentJobControl(), nullptr);
  EXPECT_NO_THROW(checkCancelled());
}

TEST(JobControl, NestedStagesMapIntoTheirCallersRange) {
  std::vector<std::pair<double, std::string>> events;
  JobControl control;
  control.progress = [&](double fraction, const std::string& stage) { events.emplace_back(fraction, stage); };
  const JobControlScope scope(&control);
  {
    const ProgressStage outer(0.5, 1.0, "outer");
    {
      const ProgressStage inner(0.5, 1.0, "inner");  // [0.75, 1] of the whole
      advanceStage(1, 2);                            // 0.875
      const ProgressStage part(0.0, 0.5);             // [0.75, 0.875], still "inner"
      advanceStage(1, 1);                            // 0.875 again: not reported twice
    }
    advanceStage(0, 4);  // 0.5 < 0.875: progress does not go back, and is not reported
  }
  const std::vector<std::pair<double, std::string>> expected = {{0.5, "outer"}, {0.75, "inner"}, {0.875, "inner"}};
  EXPECT_EQ(events, expected);
  // The same control installed again (a call nested in another): the caller's scale and
  // progress go on, and survive the nested scope (progress never goes back after it).
  {
    std::vector<std::pair<double, std::string>> nestedEvents;
    JobControl outerControl;
    outerControl.progress = [&](double fraction, const std::string& stage) { nestedEvents.emplace_back(fraction, stage); };
    const JobControlScope outerScope(&outerControl);
    const ProgressStage first(0.0, 0.5, "first half");
    {
      const JobControlScope nested(&outerControl);
      const ProgressStage inner(0.5, 1.0, "nested");  // [0.25, 0.5] of the whole
      advanceStage(1, 1);                             // 0.5
    }
    advanceStage(1, 2);  // 0.25 < 0.5: not reported
    const std::vector<std::pair<double, std::string>> expectedNested = {
        {0.0, "first half"}, {0.25, "nested"}, {0.5, "nested"}};
    EXPECT_EQ(nestedEvents, expectedNested);
  }
  // A worker thread polls but never reports.
  std::thread worker([&] {
    const JobControlScope workerScope(&control, false);
    const ProgressStage stage(0.0, 1.0, "worker");
    advanceStage(1, 1);
  });
  worker.join();
  EXPECT_EQ(events.size(), expected.size());
}

}  // namespace
}  // namespace scallop
