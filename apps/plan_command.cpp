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
#include <filesystem>
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
#include "scallop/cad_tessellation.hpp"
#include "scallop/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/gcode.hpp"
#include "scallop/gcode_reader.hpp"
#include "scallop/optimal_slicing.hpp"
#include "scallop/mesh_raster.hpp"
#include "scallop/mesh_drop.hpp"
#include "scallop/orient_output.hpp"
#include "scallop/paths_output.hpp"
#include "scallop/rest_finishing.hpp"
#include "scallop/verify_output.hpp"
#include "scallop/surface.hpp"
#include "surface_options.hpp"
#include "linking_options.hpp"
#include "toolpath_job.hpp"

namespace scallop::cli {
namespace {

namespace fs = std::filesystem;

struct PlanOptions {
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

// What a mesh plan cuts: an STL mesh, or the tessellation of a STEP or IGES part whose faces
// the exact importer refuses (trimmed, rational).
struct MeshJob {
  Mesh mesh;
  std::string description;        // the progress line's "4,608 triangles (binary STL)"
  double clearance = 0.0;         // added to R in every proof: the tessellation's margin
  double deviation = 0.0;         // the exact faces' sampled distance from the mesh
  const CadPart* part = nullptr;  // the exact faces: the simulated cut's design
  std::optional<TessellationSummary> tessellation;
};

// The simulated cut's budget of vertical lines through a CAD part's exact faces: past it the
// cut is judged on the mesh instead, and the report says so.
constexpr std::size_t kExactDesignRays = 1'000'000;
// The clearance a tessellated part's proofs add to R: this times the sampled deviation
// (cad_tessellation.hpp: sampled, so a margin).
constexpr double kDeviationMargin = 1.5;

// Rounds of rest finishing at most (each a simulation of the whole program more).
constexpr int kRestRounds = 2;

// The cusp between balls of radius R on neighbouring passes `spacing` apart on a flat surface:
// the scallop height a plan given --spacing is simulated against. Refused from 2 R up, where
// the balls do not meet and nothing bounds what is left between passes.
double flatCusp(double radius, double spacing) {
  if (!(spacing < 2.0 * radius))
    throw Error(fmt::format("the spacing {} is not below the ball's diameter {}: neighbouring passes would leave "
                            "uncut ridges of any height (give a spacing below 2 R, or --scallop-height)",
                            spacing, 2.0 * radius));
  return radius - std::sqrt(radius * radius - 0.25 * spacing * spacing);
}

// The largest |coordinate| of a mesh's vertices (as surfaceScale is a surface's).
double meshScale(const Mesh& mesh) {
  double scale = 0.0;
  for (const Vec3& v : mesh.vertices) scale = std::max({scale, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  return scale;
}

// report.json's `verification`: the simulated cut of the program in short.
VerificationSummary verificationSummary(const SimulationReport& simulated, double stockAllowance) {
  return VerificationSummary{simulated.design.spacing, simulated.heightErrorBound, stockAllowance,
                             simulated.maxGouge, simulated.maxGougeAt, simulated.gougeArea,
                             simulated.gougeTolerance, simulated.maxScallop, simulated.maxScallopAt,
                             simulated.scallopP99, simulated.meanScallop, simulated.uncutArea,
                             simulated.unreachableArea, simulated.maxUnreachableScallop,
                             simulated.rapidsCutting, simulated.seconds};
}

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
void rejectMeshOptions(const PlanOptions& options, const char* what) {
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
  reject(options.noRestFinishing, "--no-rest-finishing", "switches off what a mesh plan does not do yet");
}

// `plan` on an STL mesh: raster passes of exact drop lines (mesh_raster.hpp), every move proven
// within eps; the program written and its cut simulated on the mesh itself.
void runPlanMesh(const PlanOptions& options, MeshJob job) {
  const std::string path = sourceName(options.surface);  // "<stdin>" for "-"
  const char* const what = job.part ? "a tessellated part" : "a mesh";
  rejectMeshOptions(options, what);
  auto progress = [&](const std::string& line) {
    if (!options.quiet) fmt::print(stderr, "scallop plan: {}...\n", line);
  };
  const auto start = std::chrono::steady_clock::now();
  const Mesh& mesh = job.mesh;
  const bool inch = mesh.units == Units::inch;
  const double radius = options.toolRadius.empty()
                            ? (inch ? 0.25 : 6.0)
                            : parsePositive(options.toolRadius, "tool radius", "a positive length");
  // A ball a thousand times the size of the part is a typo, not a tool (as for surfaces).
  if (radius > 1e3 * std::max(meshScale(mesh), 1e-300))
    throw Error(fmt::format("{}: the tool radius {} is more than 1000 times the mesh's size (largest |coordinate| {} "
                            "{}); check the units (--units)",
                            path, radius, meshScale(mesh), unitsName(mesh.units)));
  std::optional<double> height;
  double spacing = 0.0;
  if (!options.spacing.empty()) {
    spacing = parsePositive(options.spacing, "spacing", "a positive length");
    flatCusp(radius, spacing);  // refused early from 2 R up
  } else {
    height = options.scallopHeight.empty() ? (inch ? 0.001 : 0.025)
                                           : parsePositive(options.scallopHeight, "scallop height", "a positive length");
    if (!(*height < radius))
      throw Error(fmt::format("the scallop height {} must be smaller than the tool radius {}", *height, radius));
    // A tessellated part's passes stand the clearance off the mesh, which stands up to the
    // deviation off the exact faces: the cusps aim at what is left of H (at least H / 4).
    spacing = meshRasterSpacing(radius, std::max(*height - job.clearance - job.deviation, 0.25 * *height));
  }
  const double rapidRate = options.rapidRate.empty()
                               ? defaultRapidRate(mesh.units)
                               : parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  progress(fmt::format("{}; raster along x, lines at most {:.6g} {} apart, each the exact drop line of a {} {} ball{}",
                       job.description, spacing, unitsName(mesh.units), radius, unitsName(mesh.units),
                       job.clearance > 0.0 ? fmt::format(" kept {:.3g} {} farther from the mesh", job.clearance,
                                                         unitsName(mesh.units))
                                           : std::string()));
  // The proofs see the mesh as the top of a solid (its open edges walled down to its bottom).
  // The walls stand 4 eps outside the edges (eps: the drop lines' 1e-6 of the mesh's size).
  double diagonal = 0.0;
  {
    Vec3 lo = mesh.vertices.front(), hi = lo;
    for (const Vec3& v : mesh.vertices) {
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
    diagonal = norm(hi - lo);
  }
  const Mesh solid = meshWithSkirt(mesh, 4e-6 * diagonal);
  // A tessellated part's proofs use the ball grown by the clearance: a centre R + c from the
  // mesh is at least R from every exact face within c of the mesh.
  const double proofRadius = radius + job.clearance;
  const MeshDropCutter cutter(solid, proofRadius);
  MeshRasterOptions raster;
  raster.spacing = spacing;
  // A chord of the drop line leaves at most its sag of material: a quarter of H, as the
  // surfaces' sag rule (envelope.hpp).
  const std::optional<double> cuspHeight =
      height ? std::optional<double>(std::max(*height - job.clearance - job.deviation, 0.25 * *height)) : std::nullopt;
  if (cuspHeight) raster.sagTolerance = *cuspHeight / 4.0;
  // With H, the steps between lines adapt to the facets' slopes (mesh_raster.hpp).
  if (cuspHeight) raster.scallopHeight = *cuspHeight;
  // Off the part the ball runs R above the lowest point seen from above (the simulation's
  // design, exact at its grid points), never beside the part below what it shows.
  SimulationOptions simulation;
  simulation.toolRadius = radius;
  simulation.scallopHeight = height ? *height : flatCusp(radius, spacing);
  simulation.stockAllowance = std::max(inch ? 0.01 : 0.25, 2.0 * simulation.scallopHeight);
  double top = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : mesh.vertices) top = std::max(top, v.z);
  // The finishing stock is the surface raised by the allowance everywhere: a flat top at the
  // part's highest point would clip it there (a flat part would show no scallop at all).
  simulation.stockTop = top + *simulation.stockAllowance;
  {
    HeightGrid visible = simulationGrid(mesh, simulation);
    designHeights(mesh, visible);
    double lowest = std::numeric_limits<double>::infinity();
    for (const double z : visible.z)
      if (z != -std::numeric_limits<double>::infinity()) lowest = std::min(lowest, z);
    if (std::isfinite(lowest)) raster.floor = lowest + proofRadius;
  }
  MeshRasterPaths paths = [&] {
    try {
      return meshRasterPaths(cutter, solid, raster);
    } catch (const Error& e) {
      throw Error(fmt::format("{}: {}", path, e.what()));
    }
  }();
  paths.path.toolRadius = radius;  // the centres were proven for R + clearance; the tool is R
  // The deepest the ball comes, exactly: every move's distance to the mesh.
  double least = std::numeric_limits<double>::infinity();
  Vec3 deepestAt;
  for (const ToolPass& pass : paths.path.passes) {
    Vec3 at = pass.start;
    for (const ToolMove& move : pass.moves) {
      const double d = cutter.segmentDistance(at, move.end, least);
      if (d < least) {
        least = d;
        deepestAt = move.end;
      }
      at = move.end;
    }
  }

  PathsReport report;
  report.strategy = "raster";
  report.source = path;
  report.units = mesh.units;
  report.toolRadius = radius;
  report.spacing = spacing;
  report.scallopHeight = height;
  report.planeNormal = {0.0, 1.0, 0.0};
  report.alphaRad = std::numbers::pi / 2.0;  // vertical planes: the flat-surface formula's sin(alpha) = 1
  report.feedAngleRad = 0.0;
  report.stats.planes = paths.lines;
  report.stats.components = paths.lines;
  report.stats.centreLength = paths.centreLength;
  GougeReport gouge;
  gouge.samples = 0;
  gouge.signedMaxDepth = proofRadius - least;  // against the mesh, the ball grown by the clearance
  gouge.maxDepth = std::max(0.0, proofRadius - least);
  gouge.depthBound = gouge.maxDepth;  // exact distances, not samples
  gouge.deepest.center = deepestAt;
  report.gouge = gouge;
  report.tessellation = job.tessellation;

  progress("writing the G-code");
  const GcodeDialect dialect = gcodeDialect(options.dialect);
  const std::string title = fmt::format("scallop plan raster {}", path);
  const std::string programName = dialect == GcodeDialect::grbl ? "toolpath.gcode" : "toolpath.ngc";
  const GcodeOptions gcodeOptions = defaultGcodeOptions(mesh.units, top, paths.path, dialect, title);
  const std::string program = gcodeProgram(paths.path, gcodeOptions);
  report.motion = gcodeMotion(paths.path, gcodeOptions, rapidRate);
  report.feedRate = gcodeOptions.feedRate;
  report.plungeFeedRate = gcodeOptions.plungeFeedRate;
  report.rapidRate = rapidRate;
  const GcodeProgram written = parseGcodeProgram(program, programName);
  const SimulationReport simulated = [&] {
    if (job.part) {
      HeightGrid grid = simulationGrid(mesh, simulation);
      if (grid.z.size() <= kExactDesignRays) {
        progress(fmt::format("simulating the cut of the program on the part's exact faces ({} x {} vertical lines)",
                             grid.columns, grid.rows));
        report.tessellation->exactDesign = true;
        const CadPart& part = *job.part;
        return verifyProgram(
            mesh.units, std::move(grid), top,
            [&part](HeightGrid& g, std::vector<double>& normalZ) { part.designHeights(g, &normalZ); }, written,
            simulation, &mesh);
      }
      progress(fmt::format("the simulation's {} x {} grid exceeds the budget of {} lines through the exact faces: "
                           "simulating the cut on the mesh",
                           grid.columns, grid.rows, kExactDesignRays));
    } else {
      progress("simulating the cut of the program on the mesh (scallop verify)");
    }
    return verifyProgram(mesh, written, simulation);
  }();
  report.verification = verificationSummary(simulated, *simulation.stockAllowance);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress("writing the report");
  const fs::path dir = options.out;
  writeOutputs({{(dir / programName).string(), program},
                {(dir / "report.json").string(), pathsToJson(report, paths.path)},
                {(dir / "verify.svg").string(), verifySvg(simulated, {path, programName, 0, 0.0})}},
               options.out);
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
             gouge.maxDepth, units, cycleSummary(report, mesh.units), simulated.maxGouge, simulated.maxScallop,
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

// A STEP or IGES part's tessellation as a mesh job (cad_tessellation.hpp). The deflection
// asked of the mesher is H / 8 unless given: what the mesh's error adds to the scallops is then
// small beside H (measured, the deviation is often 1.5-3 times the deflection).
MeshJob tessellatedJob(const PlanOptions& options, const CadPart& part, const std::optional<CadImport>& exact) {
  const bool inch = part.units() == Units::inch;
  const auto progress = [&](const std::string& line) {
    if (!options.quiet) fmt::print(stderr, "scallop plan: {}...\n", line);
  };
  if (exact) {
    std::size_t trimmed = 0, rational = 0;
    for (const SkippedFace& face : exact->skipped) {
      trimmed += face.issue == CadFaceIssue::trimmed ? 1 : 0;
      rational += face.issue == CadFaceIssue::rational ? 1 : 0;
    }
    progress(fmt::format("{} of {} faces cannot be machined exactly yet ({} trimmed, {} rational, {} other; the first: "
                         "{}): cutting the part through its tessellation",
                         exact->skipped.size(), part.faces(), trimmed, rational,
                         exact->skipped.size() - trimmed - rational, exact->skipped.front().reason));
  }
  double deflection = 0.0;
  if (!options.deflection.empty()) {
    deflection = parsePositive(options.deflection, "deflection", "a positive length");
  } else {
    double height = inch ? 0.001 : 0.025;
    if (!options.scallopHeight.empty()) {
      height = parsePositive(options.scallopHeight, "scallop height", "a positive length");
    } else if (!options.spacing.empty()) {
      const double radius = options.toolRadius.empty()
                                ? (inch ? 0.25 : 6.0)
                                : parsePositive(options.toolRadius, "tool radius", "a positive length");
      height = flatCusp(radius, parsePositive(options.spacing, "spacing", "a positive length"));
    }
    deflection = height / 8.0;
  }
  TessellationOptions tessellation;
  tessellation.deflection = deflection;
  progress(fmt::format("tessellating its {} faces with deflection {:.3g} {}", part.faces(), deflection,
                       unitsName(part.units())));
  CadTessellation mesh = part.tessellate(tessellation);
  MeshJob job;
  job.clearance = kDeviationMargin * mesh.deviation;
  job.description = fmt::format("{} triangles from {} faces ({}), the exact faces at most {:.3g} {} from them (sampled "
                                "at {} points)",
                                mesh.mesh.triangles.size(), part.faces(), cadFormatName(part.format()), mesh.deviation,
                                unitsName(part.units()), mesh.deviationSamples);
  // The clearance is material left on the part: beside H it shows in the scallops. Often it is
  // not the mesh but the model: faces whose edges stand off their surfaces by the model's
  // tolerance (OCCT's bearing.iges: 0.0012 mm).
  const double height = options.scallopHeight.empty() ? (inch ? 0.001 : 0.025)
                                                      : parsePositive(options.scallopHeight, "scallop height",
                                                                      "a positive length");
  job.deviation = mesh.deviation;
  if (options.spacing.empty() && job.clearance + job.deviation > 0.75 * height && !options.quiet)
    fmt::print(stderr,
               "scallop plan: warning: the exact faces stand up to {:.3g} {} from the mesh (face {}, near ({:.6g}, "
               "{:.6g}, {:.6g})), and the passes keep 1.5 times that farther: that leaves more than 3/4 of H = {}, "
               "so the scallops will exceed H (a smaller --deflection helps unless the model's own tolerance is the "
               "cause)\n",
               mesh.deviation, unitsName(part.units()), mesh.deviationFace, mesh.deviationAt.x, mesh.deviationAt.y,
               mesh.deviationAt.z, height);
  job.tessellation = TessellationSummary{part.faces(), mesh.mesh.triangles.size(), deflection, mesh.deviation,
                                         mesh.deviationFace, job.clearance, false};
  job.mesh = std::move(mesh.mesh);
  return job;
}

void runPlan(const PlanOptions& options) {
  if (!options.spacing.empty() && !options.scallopHeight.empty())
    throw CLI::ValidationError("plan", "give at most one of --spacing and --scallop-height");
  if (isStlSource(options.surface.input)) {
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
  const bool cad = !options.surface.input.empty() && options.surface.input != "-" &&
                   cadFormatOf(options.surface.input).has_value();
  if (!cad && (options.tessellate || !options.deflection.empty()))
    throw Error("--tessellate and --deflection are for STEP and IGES parts (.step, .stp, .iges, .igs)");
  if (cad && options.surface.skipFaces && options.tessellate)
    throw Error(fmt::format("{}: --skip-faces plans only the faces imported exactly, --tessellate all of them "
                            "through the mesh: give one",
                            options.surface.input));
  if (cad && !options.surface.skipFaces) {
    // Every face exact: the surface route below. Otherwise (or asked) the tessellation.
    const CadPart part(options.surface.input);
    std::optional<CadImport> exact;
    if (!options.tessellate) exact = part.exactFaces();
    if (options.tessellate || !exact->skipped.empty()) {
      rejectMeshOptions(options, "a tessellated part");
      MeshJob job = tessellatedJob(options, part, exact);
      job.part = &part;
      return runPlanMesh(options, std::move(job));
    }
  }
  if (!options.deflection.empty())
    throw Error(fmt::format("{}: --deflection is for a tessellated part (--tessellate, or faces that cannot be "
                            "machined exactly); this one is cut on its exact faces",
                            sourceName(options.surface)));
  SurfaceSource from = options.surface;
  if (from.input.empty() && from.example.empty()) from.example = "paper-1";  // the main job
  const Surface surface = loadSurface(from, !options.quiet);
  const std::string source = sourceName(from);
  const bool inch = surface.units == Units::inch;
  auto progress = [&](const std::string& line) {
    if (!options.quiet) fmt::print(stderr, "scallop plan: {}...\n", line);
  };

  JobOptions job;
  job.strategy = options.strategy.empty() ? "contour" : options.strategy;
  // Defaults: a 1/2 inch (12 mm) ball-end mill and a finishing scallop of 0.001 in (0.025 mm).
  job.toolRadius = options.toolRadius.empty()
                       ? (inch ? 0.25 : 6.0)
                       : parsePositive(options.toolRadius, "tool radius", "a positive length");
  if (!options.spacing.empty()) {
    job.spacing = parsePositive(options.spacing, "spacing", "a positive length");
    flatCusp(job.toolRadius, *job.spacing);  // refused early from 2 R up
  } else {
    job.scallopHeight = options.scallopHeight.empty()
                            ? (inch ? 0.001 : 0.025)
                            : parsePositive(options.scallopHeight, "scallop height", "a positive length");
  }
  job.link = !options.noLinking;
  job.dropEnvelope = !options.noDropEnvelope;
  job.constantSpacing = options.constantSpacing;
  job.linking.direction = options.oneWay ? PassDirection::keep : PassDirection::zigzag;
  const double rapidRate = options.rapidRate.empty()
                               ? defaultRapidRate(surface.units)
                               : parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  progress("computing the optimal slicing orientation N* (Gauss map, medial axis, certificate)");
  OptimalSlicing orientation = optimalSlicing(surface);
  JobResult result = runToolpathJob(surface, source, job, orientation, progress);
  PathsReport& report = result.report;
  report.orientation = OrientationSummary{orientation.normal, orientation.alphaRad,
                                          orientation.certified,
                                          orientation.gaussMap.boundarySegments, orientation.seconds};

  const GcodeDialect dialect = gcodeDialect(options.dialect);
  const std::string title = fmt::format("scallop plan {} {}", job.strategy, source);
  const std::string programName = dialect == GcodeDialect::grbl ? "toolpath.gcode" : "toolpath.ngc";
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
  double top = -std::numeric_limits<double>::infinity();
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& c : patch.control) top = std::max(top, c.z);
  simulation.stockTop = top + *simulation.stockAllowance;
  GcodeOptions gcodeOptions;
  std::string program;
  const auto writeAndSimulate = [&] {
    gcodeOptions = defaultGcodeOptions(surface, result.path, dialect, title);
    program = gcodeProgram(result.path, gcodeOptions);
    progress("simulating the cut of the program (scallop verify)");
    return verifyProgram(surface, parseGcodeProgram(program, programName), simulation);
  };
  progress("writing the G-code");
  SimulationReport simulated = writeAndSimulate();
  // Rest finishing (rest_finishing.hpp): where the simulated cut leaves more than H on points
  // the ball can reach (corners whose ball stands outside the footprint, rims of pockets
  // tighter than the ball), passes through the balls that touch them, linked in with the
  // others; the program is simulated again. Only when H was asked and the spacing is ours.
  report.restFinishing = job.scallopHeight && !job.constantSpacing && !options.noRestFinishing;
  for (int round = 0; report.restFinishing && round < kRestRounds; ++round) {
    // The first round also serves what the grid may straddle beside the pockets
    // (restTargets); a second one only what the grid still reads above H.
    if (round > 0 ? simulated.uncutPoints == 0 : restTargets(simulated, *job.scallopHeight).empty()) break;
    RestOptions rest;
    rest.toolRadius = job.toolRadius;
    rest.scallopHeight = *job.scallopHeight;
    rest.sagTolerance = *job.scallopHeight / 4.0;
    if (report.envelope) rest.depthTolerance = report.envelope->depthTolerance;
    progress(fmt::format("rest finishing: {} grid points left above H", simulated.uncutPoints));
    RestRound summary{simulated.maxScallop, simulated.uncutArea, {}};
    RestPasses passes = restPasses(surface, simulated, rest);
    summary.rest = passes.report;
    report.restRounds.push_back(summary);
    if (passes.path.passes.empty()) break;
    addPasses(surface, source, job, passes.path, result, progress);
    simulated = writeAndSimulate();
  }

  progress("writing the report and figures");
  const fs::path dir = options.out;
  const std::string figureTitle = fmt::format(
      "scallop plan: {} strategy on {}, R = {} {}, spacing {:.5g}, {} passes", job.strategy,
      source, job.toolRadius, unitsName(surface.units), report.spacing, result.path.passes.size());
  report.motion = gcodeMotion(result.path, gcodeOptions, rapidRate);
  report.feedRate = gcodeOptions.feedRate;
  report.plungeFeedRate = gcodeOptions.plungeFeedRate;
  report.rapidRate = rapidRate;
  report.verification = verificationSummary(simulated, *simulation.stockAllowance);
  std::vector<OutputFile> outputs{
      {(dir / programName).string(), program},
      {(dir / "report.json").string(), pathsToJson(report, result.path)},
      {(dir / "verify.svg").string(), verifySvg(simulated, {source, programName, 0, 0.0})},
      {(dir / "paths.svg").string(), pathsSvg(surface, result.contactCurves, result.path, figureTitle, false)},
      {(dir / "paths-plan.svg").string(), pathsSvg(surface, result.contactCurves, result.path, figureTitle, true)},
      {(dir / "gauss-map.svg").string(), gaussMapSphereSvg(orientation)},
      {(dir / "stereographic.svg").string(), stereographicSvg(orientation)},
  };
  writeOutputs(outputs, options.out);
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
             job.strategy, source, orientation.normal.x, orientation.normal.y,
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
  auto options = std::make_shared<PlanOptions>();
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
  plan->add_flag("--tessellate", options->tessellate,
                 "STEP/IGES: cut the part through its tessellation (raster on the mesh, proofs kept 1.5 times the "
                 "measured deviation farther, the cut simulated on the exact faces) even when every face could be "
                 "imported exactly; parts with trimmed or rational faces are cut so without it");
  plan->add_option("--deflection", options->deflection,
                   "STEP/IGES tessellation: OCCT mesher's linear deflection (default H/8)")
      ->type_name("D");
  plan->add_option("--out", options->out, "output folder (default scallop-out)")->type_name("DIR");
  plan->add_flag("--quiet", options->quiet, "no progress lines");
  plan->callback([options] { runPlan(*options); });
}

}  // namespace scallop::cli
