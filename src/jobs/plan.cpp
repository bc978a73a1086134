#include "scallop/jobs/plan.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "scallop/paths/cusp.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/io/orient_output.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/paths/rest_finishing.hpp"
#include "scallop/io/verify_output.hpp"

namespace scallop {
namespace {

// Rounds of rest finishing at most (each a simulation of the whole program more).
constexpr int kRestRounds = 2;

// The stages of plan, as parts of its [0, 1] (about their share of paper-1's plan time).
constexpr double kOrientEnd = 0.01, kPathsEnd = 0.50, kGcodeEnd = 0.51, kSimulationEnd = 0.90;

}  // namespace

VerificationSummary verificationSummary(const SimulationReport& simulated, double stockAllowance) {
  return VerificationSummary{simulated.design.spacing, simulated.heightErrorBound, stockAllowance,
                             simulated.maxGouge, simulated.maxGougeAt, simulated.gougeArea,
                             simulated.gougeTolerance, simulated.maxScallop, simulated.maxScallopAt,
                             simulated.scallopP99, simulated.meanScallop, simulated.uncutArea,
                             simulated.unreachableArea, simulated.maxUnreachableScallop,
                             simulated.rapidsCutting, simulated.seconds, simulated.clearedGougePoints,
                             simulated.maxClearedGouge};
}

PlanResult plan(const Surface& surface, const PlanOptions& options, const JobControl& control) {
  const JobControlScope scope(&control);
  const bool inch = surface.units == Units::inch;
  ToolpathOptions job;
  job.source = options.source;
  job.strategy = options.strategy;
  // Defaults: a 1/2 inch (12 mm) ball-end mill and a finishing scallop of 0.001 in (0.025 mm).
  job.toolRadius = options.toolRadius.value_or(inch ? 0.25 : 6.0);
  if (options.spacing && options.scallopHeight)
    throw Error("give at most one of a spacing and a scallop height");
  if (options.spacing) {
    job.spacing = *options.spacing;
  } else {
    job.scallopHeight = options.scallopHeight.value_or(inch ? 0.001 : 0.025);
  }
  validateToolpathOptions(surface, job);
  if (job.spacing) flatCusp(job.toolRadius, *job.spacing);  // refused early from 2 R up
  job.link = options.link;
  job.dropEnvelope = options.dropEnvelope;
  job.constantSpacing = options.constantSpacing;
  job.linking.direction = options.oneWay ? PassDirection::keep : PassDirection::zigzag;
  const double rapidRate = options.rapidRate.value_or(defaultRapidRate(surface.units));
  if (!(rapidRate > 0.0) || !std::isfinite(rapidRate))
    throw Error(fmt::format("the rapid rate must be positive, got {}", rapidRate));

  PlanResult out;
  {
    const ProgressStage stage(0.0, kOrientEnd,
                              "computing the optimal slicing orientation N* (Gauss map, medial axis, certificate)");
    out.orientation = optimalSlicing(surface);
  }
  const OptimalSlicing& orientation = out.orientation;
  {
    const ProgressStage stage(kOrientEnd, kPathsEnd);  // its stages are toolpaths' own
    out.toolpaths = toolpaths(surface, job, orientation, control);
  }
  ToolpathResult& result = out.toolpaths;
  PathsReport& report = result.report;
  report.orientation = OrientationSummary{orientation.normal, orientation.alphaRad, orientation.certified,
                                          orientation.gaussMap.boundarySegments, orientation.seconds};

  out.programName = options.dialect == GcodeDialect::grbl ? "toolpath.gcode" : "toolpath.ngc";
  const std::string title = fmt::format("scallop plan {} {}", strategyName(job.strategy), job.source);
  // The program as written, read back and cut in simulation (scallop verify): the finishing
  // stock is the surface raised by half the links' clearance (what they assume roughing
  // left; at least 2 H, so scallops up to 2 H show), the scallop height the one asked (or the
  // flat-surface one of the spacing given).
  SimulationOptions simulation;
  simulation.toolRadius = job.toolRadius;
  simulation.scallopHeight = job.scallopHeight ? *job.scallopHeight : flatCusp(job.toolRadius, report.spacing);
  simulation.stockAllowance = std::max(report.linking ? 0.5 * report.linking->clearance : (inch ? 0.01 : 0.25),
                                       2.0 * simulation.scallopHeight);
  // The finishing stock is the surface raised by the allowance everywhere: a flat top at the
  // part's highest point would clip it there (a flat part would show no scallop at all).
  simulation.stockTop = controlPointTop(surface) + *simulation.stockAllowance;
  const auto writeAndSimulate = [&](double from, double to) {
    {
      const ProgressStage stage(from, from + 0.025 * (to - from), "writing the G-code");
      out.gcode = defaultGcodeOptions(surface, result.path, options.dialect, title);
      out.program = gcodeProgram(result.path, out.gcode);
    }
    const ProgressStage stage(from + 0.025 * (to - from), to, "simulating the cut of the program (scallop verify)");
    return verifyProgram(surface, parseGcodeProgram(out.program, out.programName), simulation);
  };
  out.simulated = writeAndSimulate(kPathsEnd, kSimulationEnd);
  SimulationReport& simulated = out.simulated;
  // Rest finishing (rest_finishing.hpp): where the simulated cut leaves more than H on points
  // the ball can reach (corners whose ball stands outside the footprint, rims of pockets
  // tighter than the ball), passes through the balls that touch them, linked in with the
  // others; the program is simulated again. Only when H was asked and the spacing is ours.
  report.restFinishing = job.scallopHeight && !job.constantSpacing && options.restFinishing;
  for (int round = 0; report.restFinishing && round < kRestRounds; ++round) {
    // The first round also serves what the grid may straddle beside the pockets
    // (restTargets); a second one only what the grid still reads above H.
    if (round > 0 ? simulated.uncutPoints == 0 : restTargets(simulated, *job.scallopHeight).empty()) break;
    const double from = kSimulationEnd + (1.0 - kSimulationEnd) * round / kRestRounds;
    const double to = kSimulationEnd + (1.0 - kSimulationEnd) * (round + 1) / kRestRounds;
    RestOptions rest;
    rest.toolRadius = job.toolRadius;
    rest.scallopHeight = *job.scallopHeight;
    rest.sagTolerance = *job.scallopHeight / 4.0;
    if (report.envelope) rest.depthTolerance = report.envelope->depthTolerance;
    RestRound summary{simulated.maxScallop, simulated.uncutArea, {}};
    {
      const ProgressStage stage(from, (from + to) / 2.0,
                                fmt::format("rest finishing: {} grid points left above H", simulated.uncutPoints));
      RestPasses passes = restPasses(surface, simulated, rest);
      summary.rest = passes.report;
      report.restRounds.push_back(summary);
      if (passes.path.passes.empty()) break;
      addPasses(surface, job, passes.path, result);
    }
    simulated = writeAndSimulate((from + to) / 2.0, to);
  }
  report.motion = gcodeMotion(result.path, out.gcode, rapidRate);
  report.feedRate = out.gcode.feedRate;
  report.plungeFeedRate = out.gcode.plungeFeedRate;
  report.rapidRate = rapidRate;
  report.verification = verificationSummary(simulated, *simulation.stockAllowance);
  const ProgressStage done(1.0, 1.0, "done");
  return out;
}

std::vector<OutputFile> planFiles(const Surface& surface, const PlanResult& result) {
  const ToolpathResult& paths = result.toolpaths;
  const PathsReport& report = paths.report;
  const std::string figureTitle =
      fmt::format("scallop plan: {} strategy on {}, R = {} {}, spacing {:.5g}, {} passes", report.strategy,
                  report.source, report.toolRadius, unitsName(surface.units), report.spacing, paths.path.passes.size());
  return {
      {result.programName, result.program},
      {"report.json", pathsToJson(report, paths.path)},
      {"verify.svg", verifySvg(result.simulated, {report.source, result.programName, 0, 0.0})},
      {"paths.svg", pathsSvg(surface, paths.contactCurves, paths.path, figureTitle, false)},
      {"paths-plan.svg", pathsSvg(surface, paths.contactCurves, paths.path, figureTitle, true)},
      {"gauss-map.svg", gaussMapSphereSvg(result.orientation)},
      {"stereographic.svg", stereographicSvg(result.orientation)},
  };
}

}  // namespace scallop
