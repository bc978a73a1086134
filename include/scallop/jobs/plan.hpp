#pragma once
// The main job as one library call: a surface to its tool path, G-code program, simulated cut
// and figures, as `scallop plan` makes them (the CLI is a shell over this call).
//
// Contract
// --------
// plan(surface, options, control):
//   1. the optimal slicing orientation N* of the surface (optimal_slicing.hpp);
//   2. the tool path (toolpath_job.hpp): contour on N* (or raster), lifted to the proven
//      gouge-free drop envelope, linked, and the ball checked against the whole surface;
//   3. the G-code program (gcode.hpp) with feeds and a safe height that suit the units;
//   4. the program read back and its cut simulated (cut_simulation.hpp, `scallop verify`)
//      on a finishing stock of the surface raised by half the links' clearance (at least 2 H);
//   5. with a scallop height and adaptive spacing: up to two rounds of rest finishing
//      (rest_finishing.hpp) where the simulated cut leaves more than H on points the ball can
//      reach, each linked in and simulated again.
// Defaults suit the surface's units: a 0.25 in (6 mm) ball, H = 0.001 in (0.025 mm).
// Errors: scallop::Error, naming options.source, before any work for bad options;
// scallop::Cancelled when control.cancel is set (job_control.hpp), which also carries the
// progress (fraction, stage) on the calling thread. Threads: parallel.hpp's threadCount();
// the result is the same, byte for byte, for every thread count and run.
// Cost: paper-1 with the defaults takes about 3 s on one core of the reference machine; the
// README gives the figures of the examples and of real parts.
//
// planFiles(surface, result): the seven files `scallop plan` writes (G-code, report.json,
// verify.svg, paths.svg, paths-plan.svg, gauss-map.svg, stereographic.svg), in that order,
// as (name, contents); nothing is written to disk.

#include <optional>
#include <string>
#include <vector>

#include "scallop/paths/cut_simulation.hpp"
#include "scallop/io/file_output.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/jobs/toolpath_job.hpp"

namespace scallop {

struct PlanOptions {
  std::string source = "surface";             ///< the surface's name in errors, report, G-code title
  Strategy strategy = Strategy::contour;
  std::optional<double> toolRadius;           ///< R; none: 0.25 in or 6 mm
  std::optional<double> scallopHeight;        ///< H < R; none (and no spacing): 0.001 in or 0.025 mm
  std::optional<double> spacing;              ///< Delta instead of H (no rest finishing)
  bool constantSpacing = false;               ///< with H: the paper's flat-surface Delta
  bool link = true;                           ///< order and link the passes (linking.hpp)
  bool oneWay = false;                        ///< linked passes keep their direction (no zigzag)
  bool dropEnvelope = true;                   ///< lift to the proven gouge-free drop envelope
  bool restFinishing = true;                  ///< rest passes where the cut leaves more than H
  GcodeDialect dialect = GcodeDialect::linuxcnc;
  std::optional<double> rapidRate;            ///< for the cycle time; none: 200 in/min or 5000 mm/min
};

struct PlanResult {
  ToolpathResult toolpaths;       ///< the path, its report (with every figure below) and sections
  OptimalSlicing orientation;     ///< N*, alpha*, the Gauss map and medial axis (the figures')
  GcodeOptions gcode;             ///< feeds, spindle, safe height of the program
  std::string programName;        ///< toolpath.ngc (LinuxCNC) or toolpath.gcode (grbl)
  std::string program;            ///< the G-code program
  SimulationReport simulated;     ///< the program's simulated cut (the last one, after rest passes)
};

/// The main job (see the contract).
PlanResult plan(const Surface& surface, const PlanOptions& options = {}, const JobControl& control = {});

/// report.json's `verification`: the simulated cut in short (`stockAllowance`: the
/// finishing stock's, above the surface).
VerificationSummary verificationSummary(const SimulationReport& simulated, double stockAllowance);

/// The files `scallop plan` writes, as (name, contents), from plan's result on `surface`.
std::vector<OutputFile> planFiles(const Surface& surface, const PlanResult& result);

}  // namespace scallop
