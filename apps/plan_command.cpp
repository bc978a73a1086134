// `scallop plan`: the main job. A surface (the paper's test surface 1 unless given), a ball
// radius and a scallop height become a tool path by the contour strategy on the optimal
// planes (or the raster strategy), written with its report and figures into one folder:
//   toolpath.ngc        G-code (LinuxCNC; --dialect grbl for grbl)
//   report.json         parameters, statistics, the optimal orientation, the passes
//   paths.svg           the surface, its sections and the tool-centre paths (axonometric)
//   paths-plan.svg      the same seen from above
//   gauss-map.svg       the symmetrized Gauss map and the optimal circle on the sphere
//   stereographic.svg   the stereographic plane with the medial axis and the optimal circle
// Everything is computed first (plan.hpp's scallop::plan); the folder is written all or
// nothing. A triangle mesh (an STL file, or a STEP/IGES part through its tessellation) is
// planned by mesh_plan.hpp's scallop::planMesh, which writes the G-code, report.json and
// verify.svg.

#include <algorithm>
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
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/io/orient_output.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/geometry/surface.hpp"
#include "surface_options.hpp"
#include "linking_options.hpp"
#include "mesh_job.hpp"
#include "scallop/jobs/mesh_plan.hpp"
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

// The ball and the step between passes, as both plans take them (a spacing, or else H; unset
// ones keep the job's defaults). The strings' errors name the option.
template <typename Job>
void parseToolAndStep(const PlanArguments& options, Job& job) {
  if (!options.toolRadius.empty())
    job.toolRadius = parsePositive(options.toolRadius, "tool radius", "a positive length");
  if (!options.spacing.empty()) {
    job.spacing = parsePositive(options.spacing, "spacing", "a positive length");
  } else if (!options.scallopHeight.empty()) {
    job.scallopHeight = parsePositive(options.scallopHeight, "scallop height", "a positive length");
  }
}

// What plan asks of a mesh plan, parsed (the strings' errors name the option).
MeshPlanOptions meshPlanOptions(const PlanArguments& options) {
  MeshPlanOptions job;
  job.source = sourceName(options.surface);  // "<stdin>" for "-"
  parseToolAndStep(options, job);
  job.restFinishing = !options.noRestFinishing;
  job.dialect = gcodeDialect(options.dialect);
  if (!options.rapidRate.empty()) job.rapidRate = parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  return job;
}

// `plan` on a mesh (an STL mesh, or a tessellated part: `part`): the library's mesh plan
// (mesh_plan.hpp), its files written and summed up in one line.
void runPlanMesh(const PlanArguments& options, const Mesh& mesh, const TessellatedPart* part,
                 const MeshPlanOptions& job) {
  const std::string& path = job.source;
  const MeshPlanResult planned = part != nullptr ? planMesh(*part, job, stageLines("plan", options.quiet))
                                                 : planMesh(mesh, job, stageLines("plan", options.quiet));
  const PathsReport& report = planned.toolpaths.report;
  const MeshRasterPaths& paths = planned.toolpaths.raster;
  const SimulationReport& simulated = planned.simulated;
  const std::optional<double> height = report.scallopHeight;
  if (!options.quiet) fmt::print(stderr, "scallop plan: writing the report...\n");
  replaceDirectory(options.out, meshPlanFiles(planned), kPlanOutputs);
  const std::string units(unitsName(mesh.units));
  fmt::print(stderr,
             "scallop plan: raster on {}{}: {} triangles, {} lines {:.5g} to {:.5g} {} apart, tool-centre length {:.4f} {}, "
             "{} moves proven within eps {:.2g} ({} unproven), deepest ball interference {:.6f} {} (exact); {}; "
             "simulated: gouge {:.6f}, scallop max {:.6f} / 99% {:.6f} {}{}{}; {:.2f} s -> {}/\n",
             path,
             report.tessellation
                 ? fmt::format(" (tessellated: deviation {:.3g} {}, clearance {:.3g}; simulated on the {})",
                               report.tessellation->deviation, unitsName(mesh.units), report.tessellation->clearance,
                               report.tessellation->exactDesign ? "exact faces" : "mesh")
                 : std::string(),
             mesh.triangles.size(), paths.lines, paths.minSpacing, report.spacing, units, paths.centreLength, units,
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
    rejectMeshOptions(options, "a mesh");
    MeshPlanOptions job = meshPlanOptions(options);
    job.description = fmt::format("{} triangles ({})", stl.mesh.triangles.size(),
                                  stl.format == StlFormat::binary ? "binary STL" : "ASCII STL");
    return runPlanMesh(options, stl.mesh, nullptr, job);
  }
  if (!options.units.empty() || options.dropZeroArea)
    throw Error("--units and --drop-zero-area are for STL meshes (a .stl file); a surface's units are in its file");
  // Every face exact: the surface route below. Otherwise (or asked) the tessellation.
  const CadRoute route = cadRoute(options.surface, options.tessellate, options.deflection, exactRationalFaces(options.surface));
  if (route.tessellate) {
    rejectMeshOptions(options, "a tessellated part");
    announceTessellation(*route.part, route.exact, "plan", options.quiet);
    const MeshPlanOptions job = meshPlanOptions(options);
    const TessellatedPart part = tessellatedJob(*route.part, job, options.deflection, "plan", options.quiet);
    return runPlanMesh(options, part.mesh, &part, job);
  }
  SurfaceSource from = options.surface;
  if (from.input.empty() && from.example.empty()) from.example = "paper-1";  // the main job
  const Surface surface = loadSurface(from, !options.quiet, route.exact ? &*route.exact : nullptr);
  scallop::PlanOptions job;
  job.source = sourceName(from);
  job.strategy = parseStrategy(options.strategy.empty() ? "contour" : options.strategy);
  parseToolAndStep(options, job);
  job.link = !options.noLinking;
  job.dropEnvelope = !options.noDropEnvelope;
  job.constantSpacing = options.constantSpacing;
  job.oneWay = options.oneWay;
  job.restFinishing = !options.noRestFinishing;
  job.dialect = gcodeDialect(options.dialect);
  if (!options.rapidRate.empty())
    job.rapidRate = parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  const PlanResult planned = plan(surface, job, stageLines("plan", options.quiet));
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
