// A program outside the scallop tree, built against the installed package by
// tests/packaging_test.cmake, once with find_package(scallop) and once with
// `pkg-config --cflags --libs scallop`. It reaches into scallop::io (a chain parsed from
// text, a hull written as JSON) and scallop::core and the libraries core links (the scallop
// hull; Qhull through the optimal slicing of a set of normals; Clipper through a Gauss map),
// runs the whole plan through scallop::jobs with progress and cancel, prints the tool path's
// length and exits 0 when every figure is as expected.
// With SCALLOP_CONSUMER_CAD it also calls scallop::cad (OpenCASCADE) on a missing file.

#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <string>

#include "scallop/io/chain_io.hpp"
#include "scallop/error.hpp"
#include "scallop/slicing/gauss_map.hpp"
#include "scallop/io/hull_json.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/mesh_slicing.hpp"
#include "scallop/jobs/plan.hpp"
#include "scallop/paths/scallop_hull.hpp"
#include "scallop/geometry/surface.hpp"
#ifdef SCALLOP_CONSUMER_CAD
#include "scallop/cad/cad_import.hpp"
#endif

namespace {

int failures = 0;

void check(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "scallop-consumer: failed: %s\n", what);
  ++failures;
}

}  // namespace

int main() {
  try {
    // A flat chain 2 long under a ball of radius 0.5: the tool-centre path is a quarter arc,
    // a line and a quarter arc, 2 + pi/2 long.
    const scallop::Chain chain = scallop::parseChain("x,z\n0 0\n2 0\n", "consumer");
    const scallop::ScallopHull hull = scallop::scallopHull(chain, 0.5);
    const double length = scallop::pathLength(hull.toolpath);
    std::printf("tool path length %.12f\n", length);
    check(std::abs(length - (2.0 + std::numbers::pi / 2.0)) < 1e-12, "tool path length 2 + pi/2");
    const std::string json = scallop::hullToJson(hull, chain.size());
    check(!json.empty() && json.front() == '{', "hull JSON");

    // A cube's normals: the largest empty cap is centred on a diagonal, acos(1/sqrt(3)) from
    // the axes (Qhull's hull of the six points +-x, +-y, +-z).
    const scallop::MeshSlicing slicing = scallop::optimalNormalSlicing({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
    check(std::abs(slicing.alphaRad - std::acos(1.0 / std::sqrt(3.0))) < 1e-9, "cube normals' slicing angle");

    // The symmetrized Gauss map of a built-in surface (Clipper's polygon union).
    const scallop::GaussMap gaussMap = scallop::symmetrizedGaussMap(scallop::exampleSurface("paper-1"));
    check(gaussMap.kind == scallop::GaussMapKind::region && !gaussMap.loops.empty(), "Gauss map loops");

    // The whole plan through scallop::jobs, with progress and a cancel: paper-1 at 0.01 in
    // scallops; the progress never goes back and ends at 1; the program holds G-code; a second
    // plan cancelled from its progress callback half way throws scallop::Cancelled.
    const scallop::Surface paper1 = scallop::exampleSurface("paper-1");
    scallop::PlanOptions planOptions;
    planOptions.scallopHeight = 0.01;
    scallop::JobControl control;
    double last = 0.0;
    int reports = 0;
    bool monotone = true;
    control.progress = [&](double fraction, const std::string&) {
      monotone = monotone && fraction >= last;
      last = fraction;
      ++reports;
    };
    const scallop::PlanResult planned = scallop::plan(paper1, planOptions, control);
    std::printf("plan: %d progress reports, %zu passes, %zu bytes of G-code\n", reports,
                planned.toolpaths.path.passes.size(), planned.program.size());
    check(monotone && last == 1.0 && reports > 5, "plan progress monotone, ending at 1");
    check(planned.program.find("G1") != std::string::npos && planned.simulated.maxGouge < 1e-3, "plan program");
    check(scallop::planFiles(paper1, planned).size() == 7, "plan files");
    scallop::JobControl halfway;
    halfway.progress = [&halfway](double fraction, const std::string&) {
      if (fraction > 0.5) halfway.cancel.cancel();
    };
    bool cancelled = false;
    try {
      (void)scallop::plan(paper1, planOptions, halfway);
    } catch (const scallop::Cancelled&) {
      cancelled = true;
    }
    check(cancelled, "a plan cancelled half way throws scallop::Cancelled");

#ifdef SCALLOP_CONSUMER_CAD
    bool refused = false;
    try {
      (void)scallop::importCad("scallop-consumer-no-such-file.step");
    } catch (const scallop::Error&) {
      refused = true;
    }
    check(refused, "a missing STEP file refused with scallop::Error");
#endif
  } catch (const std::exception& error) {
    std::fprintf(stderr, "scallop-consumer: %s\n", error.what());
    return 1;
  }
  return failures == 0 ? 0 : 1;
}
