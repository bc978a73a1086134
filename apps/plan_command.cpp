// `scallop plan`: the main job. A surface (the paper's test surface 1 unless given), a ball
// radius and a scallop height become a tool path by the contour strategy on the optimal
// planes (or the raster strategy), written with its report and figures into one folder:
//   toolpath.ngc        G-code (LinuxCNC; --dialect grbl for grbl)
//   report.json         parameters, statistics, the optimal orientation, the passes
//   paths.svg           the surface, its sections and the tool-centre paths (axonometric)
//   paths-plan.svg      the same seen from above
//   gauss-map.svg       the symmetrized Gauss map and the optimal circle on the sphere
//   stereographic.svg   the stereographic plane with the medial axis and the optimal circle
// Everything is computed first; the folder is written all or nothing.

#include <algorithm>
#include <chrono>
#include <limits>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "arguments.hpp"
#include "commands.hpp"
#include "output_directory.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/mesh_raster.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/io/orient_output.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/paths/rest_finishing.hpp"
#include "scallop/io/verify_output.hpp"
#include "scallop/geometry/surface.hpp"
#include "surface_options.hpp"
#include "linking_options.hpp"
#include "mesh_job.hpp"
#include "scallop/jobs/plan.hpp"

namespace scallop::cli {
namespace {

// Every file `plan` writes into its --out directory (the mesh route writes the first four).
const OwnedNames kPlanOutputs = {"toolpath.ngc", "toolpath.gcode", "report.json",   "verify.svg",
                                 "paths.svg",    "paths-plan.svg", "gauss-map.svg", "stereographic.svg"};

struct PlanArguments {
  SurfaceSource surface;
  std::string strategy;  // empty: contour for a surface, raster for a mesh
  std::string toolRadius;
  std::string scallopHeight;
  std::string spacing;
  std::string dialect = "linuxcnc";
  std::string out = "scallop-out";
  std::string rapidRate;
  bool noLinking = false;
  bool noDropEnvelope = false;
  bool oneWay = false;
  bool constantSpacing = false;
  bool noRestFinishing = false;
  bool quiet = false;
  std::string units;          // --units in|mm: an STL mesh's
  bool dropZeroArea = false;  // --drop-zero-area: an STL mesh's
  bool tessellate = false;    // --tessellate: a STEP/IGES part cut through its tessellation
  std::string deflection;     // --deflection D: that tessellation's
};

// Rounds of rest finishing at most (each a simulation of the whole program more).
constexpr int kRestRounds = 2;

// "; rest finishing: ..." when rest passes were added (what the strategies left, what it took).
std::string restSummary(const PathsReport& report, Units units) {
  std::size_t passes = 0, targets = 0;
  double length = 0.0;
  for (const RestRound& round : report.restRounds) {
    passes += round.rest.passes;
    targets += round.rest.targets;
    length += round.rest.length;
  }
  if (report.restRounds.empty()) return {};
  const RestRound& first = report.restRounds.front();
  if (first.rest.overBudget)
    return fmt::format("; rest finishing skipped: {} points to finish exceed its budget", first.rest.targets);
  return fmt::format("; rest finishing: {} passes, {:.3f} {}, for {} grid points (scallop max {:.6f} before)", passes,
                     length, unitsName(units), targets, first.maxScallopBefore);
}

// The options a mesh plan (an STL mesh, a tessellated part: `what`) cannot honour, refused
// by name before any work.
void rejectMeshOptions(const PlanArguments& options, const char* what) {
  const std::string path = sourceName(options.surface);
  const auto reject = [&](bool given, const char* option, const char* why) {
    if (given) throw Error(fmt::format("{}: {} {}; not for {}", path, option, why, what));
  };
  reject(!options.surface.patches.empty() || options.surface.skipFaces, "--patches/--skip-faces",
         "select a surface's patches or faces");
  reject(options.strategy == "contour", "--strategy contour",
         "needs the surface's normal along its sections (a mesh's jumps at every edge): meshes are cut by raster");
  reject(options.noDropEnvelope, "--no-drop-envelope", "keeps a surface strategy's own centres (a mesh's passes are drop lines)");
  reject(options.constantSpacing, "--constant-spacing", "is the optimal planes' flat-surface spacing");
  reject(options.noLinking || options.oneWay, "--no-linking/--one-way", "order a surface plan's passes (a mesh's raster is one zigzag)");
}

// What plan asks of a mesh raster.
MeshRasterRequest meshRequest(const PlanArguments& options) {
  return {sourceName(options.surface), "plan", options.toolRadius, options.scallopHeight, options.spacing,
          options.quiet};
}

// `plan` on an STL mesh: raster passes of exact drop lines (mesh_raster.hpp), every move proven
// within eps; the program written and its cut simulated on the mesh itself.
void runPlanMesh(const PlanArguments& options, MeshJob job) {
  const std::string path = sourceName(options.surface);  // "<stdin>" for "-"
  const char* const what = job.part ? "a tessellated part" : "a mesh";
  rejectMeshOptions(options, what);
  auto progress = [&](const std::string& line) {
    if (!options.quiet) fmt::print(stderr, "scallop plan: {}...\n", line);
  };
  MeshRasterResult raster = runMeshRaster(job, meshRequest(options));
  const Mesh& mesh = job.mesh;
  const std::optional<double> height = raster.report.scallopHeight;
  const double spacing = raster.report.spacing;
  const double top = raster.top;
  SimulationOptions& simulation = raster.simulation;
  MeshRasterPaths& paths = raster.paths;
  PathsReport& report = raster.report;
  const auto start = raster.start;
  const double rapidRate = options.rapidRate.empty()
                               ? defaultRapidRate(mesh.units)
                               : parsePositive(options.rapidRate, "rapid rate", "a positive rate");

  progress("writing the G-code");
  const GcodeDialect dialect = gcodeDialect(options.dialect);
  const std::string title = fmt::format("scallop plan raster {}", path);
  const std::string programName = dialect == GcodeDialect::grbl ? "toolpath.gcode" : "toolpath.ngc";
  // A tessellated part's exact design is computed once, for every simulation of the program.
  std::optional<std::pair<HeightGrid, std::vector<double>>> exactDesign;
  GcodeOptions gcodeOptions;
  std::string program;
  const auto writeAndSimulate = [&]() -> SimulationReport {
    gcodeOptions = defaultGcodeOptions(mesh.units, top, paths.path, dialect, title);
    program = gcodeProgram(paths.path, gcodeOptions);
    const GcodeProgram written = parseGcodeProgram(program, programName);
    if (job.part) {
      HeightGrid grid = simulationGrid(mesh, simulation);
      if (grid.z.size() <= kExactDesignRays) {
        if (!exactDesign) {
          progress(fmt::format("the part's exact heights on {} x {} vertical lines", grid.columns, grid.rows));
          HeightGrid heights = grid;
          std::vector<double> normalZ;
          job.part->designHeights(heights, &normalZ);
          exactDesign.emplace(std::move(heights), std::move(normalZ));
        }
        progress("simulating the cut of the program on the part's exact faces");
        report.tessellation->exactDesign = true;
        return verifyProgram(
            mesh.units, std::move(grid), top,
            [&exactDesign](HeightGrid& g, std::vector<double>& normalZ) {
              g.z = exactDesign->first.z;
              normalZ = exactDesign->second;
            },
            written, simulation, &mesh);
      }
      progress(fmt::format("the simulation's {} x {} grid exceeds the budget of {} lines through the exact faces: "
                           "simulating the cut on the mesh",
                           grid.columns, grid.rows, kExactDesignRays));
    } else {
      progress("simulating the cut of the program on the mesh (scallop verify)");
    }
    return verifyProgram(mesh, written, simulation);
  };
  SimulationReport simulated = writeAndSimulate();
  // Rest finishing (rest_finishing.hpp): where the simulated cut leaves more than H on points
  // the ball can reach, passes through the balls that touch them, every step an exact drop
  // line; the program is simulated again. Only when H was asked.
  // A tessellated part whose clearance and deviation take half of H or more is left alone: the
  // balls stand that far off the exact faces wherever they go, so what exceeds H there is the
  // clearance's, which no rest pass removes (bearing.iges: 298 passes for nothing).
  report.restFinishing =
      height.has_value() && !options.noRestFinishing && job.clearance + job.deviation < 0.5 * *height;
  const std::size_t rasterPasses = paths.path.passes.size();
  for (int round = 0; report.restFinishing && round < kRestRounds; ++round) {
    if (round > 0 ? simulated.uncutPoints == 0 : restTargets(simulated, *height).empty()) break;
    // A second round only when the first took at least a tenth of what was above H.
    if (round > 0 && simulated.uncutArea > 0.9 * report.restRounds.back().uncutAreaBefore) break;
    RestOptions rest;
    rest.toolRadius = report.toolRadius;
    rest.scallopHeight = *height;
    progress(fmt::format("rest finishing: {} grid points left above H", simulated.uncutPoints));
    RestRound summary{simulated.maxScallop, simulated.uncutArea, {}};
    RestPasses passes = meshRestPasses(*raster.solid, *raster.cutter, simulated, rest, raster.dropLine);
    summary.rest = passes.report;
    report.restRounds.push_back(summary);
    if (passes.path.passes.empty()) break;
    for (ToolPass& pass : passes.path.passes) paths.path.passes.push_back(std::move(pass));
    simulated = writeAndSimulate();
  }
  if (!report.restRounds.empty()) {
    // The deepest the ball comes, over the rest passes too (exact distances to the mesh; the
    // raster's own least distance is already in the report).
    GougeReport& deepest = *report.gouge;
    double least = raster.cutter->radius() - deepest.signedMaxDepth;
    for (std::size_t p = rasterPasses; p < paths.path.passes.size(); ++p) {
      const ToolPass& pass = paths.path.passes[p];
      Vec3 at = pass.start;
      for (const ToolMove& move : pass.moves) {
        const double d = raster.cutter->segmentDistance(at, move.end, least);
        if (d < least) {
          least = d;
          deepest.deepest.center = move.end;
        }
        at = move.end;
      }
    }
    deepest.signedMaxDepth = raster.cutter->radius() - least;
    deepest.maxDepth = std::max(0.0, deepest.signedMaxDepth);
    deepest.depthBound = deepest.maxDepth;
  }
  report.motion = gcodeMotion(paths.path, gcodeOptions, rapidRate);
  report.feedRate = gcodeOptions.feedRate;
  report.plungeFeedRate = gcodeOptions.plungeFeedRate;
  report.rapidRate = rapidRate;
  report.verification = verificationSummary(simulated, *simulation.stockAllowance);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress("writing the report");
  replaceDirectory(options.out,
                   {{programName, program},
                    {"report.json", pathsToJson(report, paths.path)},
                    {"verify.svg", verifySvg(simulated, {path, programName, 0, 0.0})}},
                   kPlanOutputs);
  const std::string units(unitsName(mesh.units));
  fmt::print(stderr,
             "scallop plan: raster on {}{}: {} triangles, {} lines {:.5g} to {:.5g} {} apart, tool-centre length {:.4f} {}, "
             "{} moves proven within eps {:.2g} ({} unproven), deepest ball interference {:.6f} {} (exact); {}; "
             "simulated: gouge {:.6f}, scallop max {:.6f} / 99% {:.6f} {}{}{}; {:.2f} s -> {}/\n",
             path,
             job.tessellation
                 ? fmt::format(" (tessellated: deviation {:.3g} {}, clearance {:.3g}; simulated on the {})",
                               report.tessellation->deviation, unitsName(mesh.units), job.clearance,
                               report.tessellation->exactDesign ? "exact faces" : "mesh")
                 : std::string(),
             mesh.triangles.size(), paths.lines, paths.minSpacing, spacing, units, paths.centreLength, units,
             paths.path.passes.empty() ? 0 : paths.path.passes[0].moves.size(), paths.eps, paths.unprovenMoves,
             report.gouge->maxDepth, units, cycleSummary(report, mesh.units) + restSummary(report, mesh.units),
             simulated.maxGouge, simulated.maxScallop,
             simulated.scallopP99, units,
             height && simulated.maxScallop > *height
                 ? fmt::format(" (above H = {} on {:.4g} {}^2: the facets' cusps are modelled, not the edges between "
                               "them)",
                               *height, simulated.uncutArea, units)
                 : std::string(),
             simulated.unreachablePoints > 0
                 ? fmt::format(", {:.4g} {}^2 beyond the ball's reach (up to {:.4g} {} left)", simulated.unreachableArea,
                               units, simulated.maxUnreachableScallop, units)
                 : std::string(),
             report.seconds, options.out);
}

void runPlan(const PlanArguments& options) {
  if (!options.spacing.empty() && !options.scallopHeight.empty())
    throw CLI::ValidationError("plan", "give at most one of --spacing and --scallop-height");
  checkReplaceableDirectory(options.out, kPlanOutputs);  // before the work, not after it
  if (isStlSource(options.surface.input)) {
    if (options.surface.exactTrims)
      throw Error(fmt::format("{}: --exact-trims is for STEP and IGES parts; an STL file is a mesh",
                              options.surface.input));
    if (options.tessellate || !options.deflection.empty())
      throw Error(fmt::format("{}: --tessellate and --deflection are for STEP and IGES parts; an STL file is a mesh "
                              "already",
                              options.surface.input));
    const StlMesh stl = loadStlMesh(options.surface.input, options.units, options.dropZeroArea);
    MeshJob job;
    job.description = fmt::format("{} triangles ({})", stl.mesh.triangles.size(),
                                  stl.format == StlFormat::binary ? "binary STL" : "ASCII STL");
    job.mesh = stl.mesh;
    return runPlanMesh(options, std::move(job));
  }
  if (!options.units.empty() || options.dropZeroArea)
    throw Error("--units and --drop-zero-area are for STL meshes (a .stl file); a surface's units are in its file");
  // Every face exact: the surface route below. Otherwise (or asked) the tessellation.
  const CadRoute route = cadRoute(options.surface, options.tessellate, options.deflection, exactRationalFaces(options.surface));
  if (route.tessellate) {
    rejectMeshOptions(options, "a tessellated part");
    MeshJob job = tessellatedJob(*route.part, route.exact, meshRequest(options), options.deflection);
    job.part = &*route.part;
    return runPlanMesh(options, std::move(job));
  }
  SurfaceSource from = options.surface;
  if (from.input.empty() && from.example.empty()) from.example = "paper-1";  // the main job
  const Surface surface = loadSurface(from, !options.quiet, route.exact ? &*route.exact : nullptr);
  scallop::PlanOptions job;
  job.source = sourceName(from);
  job.strategy = parseStrategy(options.strategy.empty() ? "contour" : options.strategy);
  if (!options.toolRadius.empty())
    job.toolRadius = parsePositive(options.toolRadius, "tool radius", "a positive length");
  if (!options.spacing.empty()) {
    job.spacing = parsePositive(options.spacing, "spacing", "a positive length");
  } else if (!options.scallopHeight.empty()) {
    job.scallopHeight = parsePositive(options.scallopHeight, "scallop height", "a positive length");
  }
  job.link = !options.noLinking;
  job.dropEnvelope = !options.noDropEnvelope;
  job.constantSpacing = options.constantSpacing;
  job.oneWay = options.oneWay;
  job.restFinishing = !options.noRestFinishing;
  job.dialect = gcodeDialect(options.dialect);
  if (!options.rapidRate.empty())
    job.rapidRate = parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  JobControl control;
  if (!options.quiet)
    control.progress = [last = std::string()](double, const std::string& stage) mutable {
      if (stage == last || stage == "done") return;  // a stage's advances; the end
      last = stage;
      fmt::print(stderr, "scallop plan: {}...\n", stage);
    };
  const PlanResult planned = plan(surface, job, control);
  const PathsReport& report = planned.toolpaths.report;
  const OptimalSlicing& orientation = planned.orientation;
  const SimulationReport& simulated = planned.simulated;
  const std::string& source = job.source;
  if (!options.quiet) fmt::print(stderr, "scallop plan: writing the report and figures...\n");
  replaceDirectory(options.out, planFiles(surface, planned), kPlanOutputs);
  const PathStats& s = report.stats;
  std::string gouge;
  if (report.envelope && report.envelope->verticesLifted > 0)
    gouge += fmt::format(", lifted to the drop envelope (eps {:.2g}) by up to {:.6f} {} over {} "
                         "stretches", report.envelope->depthTolerance, report.envelope->maxLift,
                         unitsName(surface.units), report.envelope->stretches.size());
  if (report.gouge)
    gouge += fmt::format(", deepest ball interference {:.6f} {} (bound {:.6f})", report.gouge->maxDepth,
                        unitsName(surface.units), report.gouge->depthBound);
  fmt::print(stderr,
             "scallop plan: {} on {}: N* = ({:.4f}, {:.4f}, {:.4f}), alpha* = {:.3f} deg; spacing "
             "{:.5g}, {} planes, {} components, tool-centre length {:.4f} {}{}; {}; {:.2f} s -> "
             "{}/\n",
             report.strategy, source, orientation.normal.x, orientation.normal.y,
             orientation.normal.z, orientation.alphaRad * 180.0 / std::numbers::pi, report.spacing,
             s.planes, s.components, s.centreLength, unitsName(surface.units), gouge,
             cycleSummary(report, surface.units) +
                 fmt::format("; simulated: gouge {:.6f}, scallop max {:.6f} / 99% {:.6f} {}{}",
                             simulated.maxGouge, simulated.maxScallop, simulated.scallopP99,
                             unitsName(surface.units),
                             simulated.unreachablePoints > 0
                                 ? fmt::format(", {:.4f} {}^2 beyond the ball's reach", simulated.unreachableArea,
                                               unitsName(surface.units))
                                 : std::string()) +
                 restSummary(report, surface.units),
             report.seconds + orientation.seconds,
             options.out);
}

}  // namespace

void addPlanCommand(CLI::App& app) {
  auto options = std::make_shared<PlanArguments>();
  CLI::App* plan = app.add_subcommand(
      "plan", "The main job: surface -> optimal orientation -> tool paths -> G-code, report, figures");
  plan->footer(
      "With no arguments: the paper's test surface 1 (inches), a 0.25 in ball, a 0.001 in "
      "scallop height, the contour strategy on the optimal planes N*; writes toolpath.ngc, "
      "report.json (with the simulated cut of the program), verify.svg (its heat map), "
      "paths.svg, paths-plan.svg, gauss-map.svg and stereographic.svg into "
      "scallop-out/ (or --out DIR), all or nothing.");
  addSurfaceSourceOptions(*plan, options->surface, "surface file (JSON or .bpt; .step/.stp or .iges/.igs; .stl: a triangle mesh, cut by raster); - reads standard input",
                          "a built-in example (default paper-1)");
  addStrategyOption(*plan, options->strategy);
  plan->add_option("--tool-radius", options->toolRadius, "ball radius R (default 0.25 in or 6 mm)")
      ->type_name("R");
  plan->add_option("--scallop-height", options->scallopHeight,
                   "largest scallop height H (default 0.001 in or 0.025 mm)")
      ->type_name("H");
  plan->add_option("--spacing", options->spacing, "plane spacing Delta instead of a scallop height")
      ->type_name("D");
  addDialectOption(*plan, options->dialect);
  addLinkingOptions(*plan, options->noLinking, options->oneWay, options->rapidRate);
  plan->add_flag("--no-drop-envelope", options->noDropEnvelope,
                 "keep the strategy's own centres (contour: r + R n; raster: the in-plane scallop hull) "
                 "instead of lifting them to the proven gouge-free drop envelope; they cut into the "
                 "surface where the report's gouge check says");
  plan->add_flag("--constant-spacing", options->constantSpacing,
                  "with --scallop-height: the paper's constant plane spacing (flat-surface formula) "
                  "instead of adaptive offsets that keep the estimated cusp <= H on curved parts");
  plan->add_flag("--no-rest-finishing", options->noRestFinishing,
                 "no rest passes where the simulated cut leaves more than H on points the ball can "
                 "reach (by default, with a scallop height and adaptive spacing, up to two rounds of "
                 "them, each simulated again)");
  addStlOptions(*plan, options->units, options->dropZeroArea);
  addExactTrimsOption(*plan, options->surface);
  plan->add_flag("--tessellate", options->tessellate,
                 "STEP/IGES: cut the part through its tessellation (raster on the mesh, proofs kept 1.5 times the "
                 "measured deviation farther, the cut simulated on the exact faces) even when every face could be "
                 "imported exactly; parts with trimmed faces are cut so without it");
  plan->add_option("--deflection", options->deflection,
                   "STEP/IGES tessellation: OCCT mesher's linear deflection (default H/8)")
      ->type_name("D");
  plan->add_option("--out", options->out, "output folder (default scallop-out)")->type_name("DIR");
  plan->add_flag("--quiet", options->quiet, "no progress lines");
  plan->callback([options] { runPlan(*options); });
}

}  // namespace scallop::cli
