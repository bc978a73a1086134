// scallop::planMesh and meshToolpaths (mesh_plan.hpp) and scallop::tessellatePart
// (tessellate_part.hpp): the library calls give the bytes `scallop plan` writes for an STL mesh
// and for a tessellated STEP part (the CLI run as an independent route), refuse bad options
// before any work, report monotone progress on the calling thread only, and stop with
// scallop::Cancelled soon after a cancel from another thread.

#include "scallop/jobs/mesh_plan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "support/cancel_moments.hpp"
#include "support/cli_fixture.hpp"
#include "support/mesh_fixtures.hpp"
#include "support/message_checks.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/cad/tessellate_part.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/job_control.hpp"

namespace scallop {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const std::string kOcctSamples = "/usr/share/opencascade/data";

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// A height field z = 0.3 sin(2x) cos(3y) over [0, 2]^2 in, n x n cells cut along one
// diagonal (mesh_fixtures.hpp), as ASCII STL: coordinates written in their shortest
// round-trip form, so the CLI reads the very doubles the library is given.
std::string heightFieldStl(std::size_t n) {
  std::mt19937_64 rng(42);
  const Mesh mesh = test::heightFieldMesh(n, rng, 0.0, false);
  std::string stl = "solid field\n";
  for (const auto& t : mesh.triangles) {
    stl += "facet normal 0 0 0\nouter loop\n";
    for (const std::uint32_t v : t)
      stl += fmt::format("vertex {} {} {}\n", mesh.vertices[v].x, mesh.vertices[v].y, mesh.vertices[v].z);
    stl += "endloop\nendfacet\n";
  }
  return stl + "endsolid field\n";
}

// The mesh of `stl` as the CLI reads it (inches).
Mesh meshOf(const std::string& stl) { return parseStl(stl, "mesh.stl", {Units::inch, false}).mesh; }

// A quick plan of a height field: R 0.25 in, H 0.008 in (on the 8 x 8 field, one rest round
// and about a second).
MeshPlanOptions fieldPlan() {
  MeshPlanOptions options;
  options.source = "mesh.stl";
  options.toolRadius = 0.25;
  options.scallopHeight = 0.008;
  return options;
}

// A quicker one: a spacing of 0.1 in (no rest finishing; on the 12 x 12 field a quarter of a
// second).
MeshPlanOptions spacedPlan() {
  MeshPlanOptions options = fieldPlan();
  options.scallopHeight.reset();
  options.spacing = 0.1;
  return options;
}

class MeshPlanCli : public test::CliFixture {
 protected:
  // `scallop plan <arguments> --quiet --out out` wrote exactly `files`, byte for byte.
  void expectCliWrites(const std::string& arguments, const std::vector<OutputFile>& files) {
    fs::remove_all(workDir_ / "out");
    const test::RunResult run = this->run("plan " + arguments + " --quiet --out out");
    ASSERT_EQ(run.exitCode, 0) << arguments << ": " << run.err;
    // --quiet: the summary line alone.
    EXPECT_EQ(run.err.rfind("scallop plan: raster on ", 0), 0u) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    ASSERT_EQ(files.size(), 3u);
    std::size_t onDisk = 0;
    for (const auto& entry : fs::directory_iterator(workDir_ / "out")) {
      (void)entry;
      ++onDisk;
    }
    EXPECT_EQ(onDisk, files.size()) << arguments;
    for (const OutputFile& file : files) {
      SCOPED_TRACE(arguments + ": " + file.path);
      const std::string written = test::readFile(workDir_ / "out" / file.path);
      EXPECT_FALSE(written.empty());
      EXPECT_TRUE(written == file.content) << "differs";
    }
  }
};

TEST_F(MeshPlanCli, TheLibraryCallWritesTheBytesTheCliWritesOnAGeneratedMesh) {
  const std::string stl = heightFieldStl(8);
  write("mesh.stl", stl);
  const Mesh mesh = meshOf(stl);
  {
    const MeshPlanResult result = planMesh(mesh, fieldPlan());
    EXPECT_EQ(result.programName, "toolpath.ngc");
    EXPECT_FALSE(result.toolpaths.report.restRounds.empty());  // the rest passes are in the bytes too
    expectCliWrites("mesh.stl --units in --tool-radius 0.25 --scallop-height 0.008", meshPlanFiles(result));
  }
  MeshPlanOptions options = spacedPlan();
  options.dialect = GcodeDialect::grbl;
  options.rapidRate = 100.0;
  const MeshPlanResult result = planMesh(mesh, options);
  EXPECT_EQ(result.programName, "toolpath.gcode");
  expectCliWrites("mesh.stl --units in --tool-radius 0.25 --spacing 0.1 --dialect grbl --rapid-rate 100",
                  meshPlanFiles(result));
}

TEST_F(MeshPlanCli, TheLibraryCallWritesTheBytesTheCliWritesOnAnOcctStlPart) {
  // OCCT's sample shape.stl (494 triangles, a 90 mm part; Debian's occt-misc), coarsely.
  const std::string path = kOcctSamples + "/stl/shape.stl";
  const StlMesh stl = readStl(path, {Units::millimetre, false});
  MeshPlanOptions options;
  options.source = path;
  options.toolRadius = 6.0;
  options.spacing = 5.0;
  const MeshPlanResult result = planMesh(stl.mesh, options);
  expectCliWrites("'" + path + "' --tool-radius 6 --spacing 5", meshPlanFiles(result));
}

TEST_F(MeshPlanCli, ATessellatedPartGivesTheBytesTheCliWrites) {
  // OCCT's screw.step: 8 of its 10 faces are trimmed, so the CLI takes it through its
  // tessellation; the library the same way: tessellatePart, then planMesh on the part.
  const std::string path = kOcctSamples + "/step/screw.step";
  const CadPart part(path);
  MeshPlanOptions options;
  options.source = path;
  options.toolRadius = 6.0;
  options.spacing = 6.0;
  PartMeshOptions meshOptions;
  meshOptions.toolRadius = options.toolRadius;
  meshOptions.spacing = options.spacing;
  std::vector<std::pair<double, std::string>> events;
  JobControl control;
  control.progress = [&events](double fraction, const std::string& stage) { events.emplace_back(fraction, stage); };
  const TessellatedPart tessellated = tessellatePart(part, meshOptions, control);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().second.rfind("tessellating its 10 faces with deflection ", 0), 0u) << events.front().second;
  EXPECT_EQ(events.back(), (std::pair<double, std::string>{1.0, "done"}));
  EXPECT_TRUE(tessellated.warnings.empty());  // a spacing: no H to warn about
  EXPECT_EQ(tessellated.faces, 10u);
  EXPECT_GT(tessellated.deviation, 0.0);
  EXPECT_DOUBLE_EQ(tessellated.clearance, kDeviationMargin * tessellated.deviation);
  const MeshPlanResult result = planMesh(tessellated, options);
  ASSERT_TRUE(result.toolpaths.report.tessellation.has_value());
  EXPECT_TRUE(result.toolpaths.report.tessellation->exactDesign);
  expectCliWrites("'" + path + "' --tool-radius 6 --spacing 6", meshPlanFiles(result));
}

TEST(MeshPlan, ATessellatedPartsWarningIsReturnedNotPrinted) {
  // A coarse tessellation against a fine H: the exact faces stand farther from the mesh than
  // 3/4 of H leaves room for (the CLI prints it as "scallop plan: warning: ...").
  const CadPart part(kOcctSamples + "/step/screw.step");
  PartMeshOptions options;
  options.deflection = 0.2;
  options.toolRadius = 3.0;
  options.scallopHeight = 0.05;
  const TessellatedPart tessellated = tessellatePart(part, options);
  ASSERT_EQ(tessellated.warnings.size(), 1u);
  test::expectMessageContains(tessellated.warnings.front(),
                              {"the exact faces stand up to", "mm from the mesh (face ", "3/4 of H = 0.05",
                               "a smaller deflection (PartMeshOptions::deflection) helps"},
                              "warning");
  // A library caller has no --deflection flag: the warning names the option as it is told.
  EXPECT_EQ(tessellated.warnings.front().find("--deflection"), std::string::npos) << tessellated.warnings.front();
  options.deflectionOption = "--deflection";
  const TessellatedPart flagged = tessellatePart(part, options);
  ASSERT_EQ(flagged.warnings.size(), 1u);
  EXPECT_NE(flagged.warnings.front().find("(a smaller --deflection helps unless"), std::string::npos)
      << flagged.warnings.front();
  EXPECT_EQ(tessellated.deflection, 0.2);
  options.deflection.reset();  // H / 8: a fine mesh, and no warning... unless the model's own tolerance
  EXPECT_GT(tessellatePart(part, options).deflection, 0.0);
}

TEST(MeshPlan, ProgressIsMonotoneEndsAtOneOnTheCallingThreadAndLeavesTheResultAlone) {
  const Mesh mesh = meshOf(heightFieldStl(12));
  const MeshPlanResult quiet = planMesh(mesh, spacedPlan());
  std::vector<std::pair<double, std::string>> events;
  bool elsewhere = false;
  const std::thread::id caller = std::this_thread::get_id();
  JobControl control;
  control.progress = [&](double fraction, const std::string& stage) {
    elsewhere = elsewhere || std::this_thread::get_id() != caller;
    events.emplace_back(fraction, stage);
  };
  const MeshPlanResult reported = planMesh(mesh, spacedPlan(), control);
  EXPECT_FALSE(elsewhere);
  ASSERT_GE(events.size(), 4u);
  for (std::size_t i = 1; i < events.size(); ++i) {
    EXPECT_GE(events[i].first, events[i - 1].first) << i << ": " << events[i].second;
    EXPECT_LE(events[i].first, 1.0);
  }
  EXPECT_EQ(events.front().first, 0.0);
  EXPECT_EQ(events.back(), (std::pair<double, std::string>{1.0, "done"}));
  // The stages, in order, as the CLI prints them.
  std::vector<std::string> stages;
  for (const auto& [fraction, stage] : events)
    if (stages.empty() || stages.back() != stage) stages.push_back(stage);
  ASSERT_EQ(stages.size(), 4u);
  EXPECT_EQ(stages[0],
            "288 triangles; raster along x, lines at most 0.1 in apart, each the exact drop line of a 0.25 in ball");
  EXPECT_EQ(stages[1], "writing the G-code");
  EXPECT_EQ(stages[2], "simulating the cut of the program on the mesh (scallop verify)");
  // The raster advances within its stage (per line), not only at its start.
  EXPECT_GT(std::count_if(events.begin(), events.end(), [&](const auto& e) { return e.second == stages[0]; }), 3);
  EXPECT_TRUE(reported.program == quiet.program);
  EXPECT_EQ(meshPlanFiles(reported)[1].content, meshPlanFiles(quiet)[1].content);

  // meshToolpaths alone: the raster's stage, then 1; the same path as the plan's.
  events.clear();
  const MeshToolpathResult raster = meshToolpaths(mesh, spacedPlan(), control);
  EXPECT_EQ(events.front(), (std::pair<double, std::string>{0.0, stages[0]}));
  EXPECT_EQ(events.back(), (std::pair<double, std::string>{1.0, "done"}));
  EXPECT_EQ(raster.raster.path.passes.size(), 1u);
  EXPECT_TRUE(raster.raster.path.passes[0].moves.size() == quiet.toolpaths.raster.path.passes[0].moves.size());
  EXPECT_EQ(raster.report.gouge->maxDepth, quiet.toolpaths.report.gouge->maxDepth);
}

TEST(MeshPlan, RefusesBadOptionsBeforeAnyWork) {
  const Mesh mesh = meshOf(heightFieldStl(4));
  const auto refused = [](const Mesh& m, const MeshPlanOptions& options, const std::vector<std::string>& parts) {
    int calls = 0;
    JobControl control;
    control.progress = [&calls](double, const std::string&) { ++calls; };
    std::string message;
    try {
      planMesh(m, options, control);
    } catch (const Cancelled&) {
      message = "cancelled";
    } catch (const Error& error) {
      message = error.what();
    }
    test::expectMessageContains(message, parts, parts.front());
    EXPECT_EQ(calls, 0) << parts.front();
  };
  MeshPlanOptions options = fieldPlan();
  options.toolRadius = -1.0;
  refused(mesh, options, {"mesh.stl", "tool radius", "-1"});
  options.toolRadius = std::numeric_limits<double>::quiet_NaN();
  refused(mesh, options, {"mesh.stl", "tool radius", "nan"});
  options.toolRadius = 5000.0;  // the mesh spans 2 in
  refused(mesh, options, {"mesh.stl", "tool radius 5000", "1000 times", "--units"});
  options = fieldPlan();
  options.scallopHeight = 0.25;
  refused(mesh, options, {"scallop height 0.25", "smaller than the tool radius 0.25"});
  options.scallopHeight = 0.0;
  refused(mesh, options, {"mesh.stl", "scallop height", "positive"});
  options.spacing = 0.1;
  options.scallopHeight = 0.01;
  refused(mesh, options, {"at most one of a spacing and a scallop height"});
  options.scallopHeight.reset();
  options.spacing = 0.5;  // 2 R
  refused(mesh, options, {"spacing 0.5", "diameter 0.5"});
  options.spacing = -0.1;
  refused(mesh, options, {"mesh.stl", "spacing", "-0.1"});
  options = fieldPlan();
  options.rapidRate = 0.0;
  refused(mesh, options, {"rapid rate", "positive"});
  Mesh broken = mesh;
  broken.triangles.clear();
  refused(broken, fieldPlan(), {"mesh.stl", "no triangles"});
  broken = mesh;
  broken.triangles[7][1] = static_cast<std::uint32_t>(mesh.vertices.size());
  refused(broken, fieldPlan(), {"mesh.stl", "triangle 7", fmt::format("vertex {}", mesh.vertices.size())});
  broken = mesh;
  broken.vertices[3].z = std::numeric_limits<double>::infinity();
  refused(broken, fieldPlan(), {"mesh.stl", "vertex 3", "not finite"});
  // A tessellated part's clearance, and tessellatePart's own choices (before it tessellates).
  TessellatedPart part;
  part.mesh = mesh;
  part.clearance = -0.1;
  int calls = 0;
  JobControl control;
  control.progress = [&calls](double, const std::string&) { ++calls; };
  try {
    planMesh(part, fieldPlan(), control);
    ADD_FAILURE() << "a negative clearance accepted";
  } catch (const Error& error) {
    test::expectMessageContains(error.what(), {"mesh.stl", "clearance -0.1", ">= 0"}, "clearance");
  }
  const CadPart screw(kOcctSamples + "/step/screw.step");
  const auto refusedPart = [&](const PartMeshOptions& o, const std::vector<std::string>& parts) {
    try {
      tessellatePart(screw, o, control);
      ADD_FAILURE() << "accepted; expected " << parts.front();
    } catch (const Error& error) {
      test::expectMessageContains(error.what(), parts, parts.front());
    }
  };
  refusedPart({-1.0, {}, {}, {}}, {"deflection", "positive", "-1"});
  refusedPart({{}, {}, 0.01, 1.0}, {"at most one of a spacing and a scallop height"});
  refusedPart({{}, 3.0, {}, 6.0}, {"spacing 6", "diameter 6"});
  EXPECT_EQ(calls, 0);
}

TEST(MeshPlan, ACancelFromTheProgressCallbackStopsItInTheExactHeights) {
  // Cancelled where the exact judge runs (CadPart::designHeights on every core): it polls per
  // vertical line.
  const CadPart screw(kOcctSamples + "/step/screw.step");
  PartMeshOptions meshOptions;
  meshOptions.toolRadius = 6.0;
  meshOptions.spacing = 6.0;
  const TessellatedPart part = tessellatePart(screw, meshOptions);
  MeshPlanOptions options;
  options.source = "screw.step";
  options.toolRadius = 6.0;
  options.spacing = 6.0;
  JobControl control;
  std::optional<Clock::time_point> asked;
  std::string last;
  control.progress = [&](double, const std::string& stage) {
    last = stage;
    if (!asked && stage.rfind("the part's exact heights", 0) == 0) {
      asked = Clock::now();
      control.cancel.cancel();
    }
  };
  EXPECT_THROW(planMesh(part, options, control), Cancelled);
  ASSERT_TRUE(asked.has_value());
  EXPECT_LT(secondsSince(*asked), 1.0);
  EXPECT_EQ(last.rfind("the part's exact heights", 0), 0u) << last;  // stopped there, nothing after
}

TEST(MeshPlan, ACancelFromAnotherThreadAtAnyMomentStopsItSoon) {
  const Mesh mesh = meshOf(heightFieldStl(12));
  // The run's length, warm (the first run of a process is the slowest): the cancels below
  // are spread over it.
  double whole = std::numeric_limits<double>::infinity();
  for (int run = 0; run < 2; ++run) {
    const Clock::time_point start = Clock::now();
    planMesh(mesh, spacedPlan());
    whole = std::min(whole, secondsSince(start));
  }
  // Cancels spread over the whole run, from a second thread, while the plan runs on every core.
  constexpr int kMoments = 6;
  const scallop::test::CancelFigures figures = scallop::test::cancelAtSpreadMoments(
      kMoments, whole, [&](const JobControl& control) { planMesh(mesh, spacedPlan(), control); });
  const auto [cancelled, worst, ranOn] = figures;
  // Runs vary with the machine's load, so a later run may end before its cancel; most cancels
  // still come while it runs, and each of those stops it.
  EXPECT_GE(cancelled, kMoments / 2);
  EXPECT_LT(ranOn, 1.0);
  // Wide: this machine is shared and the suite runs two tests at a time.
  EXPECT_LT(worst, 1.0);
  RecordProperty("worst_cancel_latency_ms", static_cast<int>(worst * 1000.0));
  std::printf("mesh plan of %.2f s: %d of %d cancels stopped it, the slowest in %.1f ms\n", whole, cancelled, kMoments,
              worst * 1000.0);
}

}  // namespace
}  // namespace scallop
