// `scallop paths`: tool paths for a surface with a ball-end cutter, by the contour strategy
// (planes N . r = k Delta, N the optimal N* or given) or the raster strategy (vertical planes,
// each section's tool path from the scallop hull's offset), as JSON, G-code and/or a figure.
// Every output is computed first and the files are written all or nothing.

#include <cstdio>
#include <memory>
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
#include "scallop/io/paths_output.hpp"
#include "scallop/geometry/surface.hpp"
#include "surface_options.hpp"
#include "linking_options.hpp"
#include "mesh_job.hpp"
#include "scallop/jobs/mesh_plan.hpp"
#include "scallop/jobs/toolpath_job.hpp"

namespace scallop::cli {
namespace {

constexpr const char* kStandardStream = "-";

struct PathsOptions {
  SurfaceSource surface;
  std::string toolRadius;
  std::string spacing;
  std::string scallopHeight;
  std::string strategy;  // empty: contour for a surface, raster for a mesh
  std::string normal = "auto";
  std::string angle;
  std::string dialect = "linuxcnc";
  std::string jsonPath;
  std::string gcodePath;
  std::string svgPath;
  bool noGougeCheck = false;
  std::string rapidRate;
  bool noLinking = false;
  bool noDropEnvelope = false;
  bool oneWay = false;
  bool constantSpacing = false;
  std::string units;          // --units in|mm: an STL mesh's
  bool dropZeroArea = false;  // --drop-zero-area: an STL mesh's
  bool tessellate = false;    // --tessellate: a STEP/IGES part cut through its tessellation
  std::string deflection;     // --deflection D: that tessellation's
};

// What paths asks of a mesh raster, parsed (the strings' errors name the option).
MeshPlanOptions meshPathsOptions(const PathsOptions& options) {
  MeshPlanOptions job;
  job.source = sourceName(options.surface);
  job.toolRadius = parsePositive(options.toolRadius, "tool radius", "a positive length");
  if (!options.spacing.empty()) {
    job.spacing = parsePositive(options.spacing, "spacing", "a positive length");
  } else {
    job.scallopHeight = parsePositive(options.scallopHeight, "scallop height", "a positive length");
  }
  return job;
}

// `paths` on a triangle mesh (an STL file, or a STEP/IGES part's tessellation: `part`): the
// library's raster of exact drop lines (mesh_plan.hpp's meshToolpaths), every move proven, as
// JSON and G-code.
void runPathsMesh(const PathsOptions& options, const Mesh& mesh, const TessellatedPart* part) {
  const std::string source = sourceName(options.surface);
  const char* const what = part != nullptr ? "a tessellated part" : "a mesh";
  const auto reject = [&](bool given, const char* option, const char* why) {
    if (given) throw Error(fmt::format("{}: {} {}; not for {}", source, option, why, what));
  };
  reject(options.strategy == "contour", "--strategy contour",
         "needs the surface's normal along its sections (a mesh's jumps at every edge): meshes are cut by raster");
  reject(!options.surface.patches.empty(), "--patches", "selects a surface's patches");
  reject(options.normal != "auto", "--normal", "is the contour strategy's");
  reject(!options.angle.empty(), "--angle", "turns a surface's raster (a mesh's runs along x)");
  reject(options.noDropEnvelope, "--no-drop-envelope", "keeps a surface strategy's own centres (a mesh's passes are drop lines)");
  reject(options.constantSpacing, "--constant-spacing", "is the optimal planes' flat-surface spacing");
  reject(options.noLinking || options.oneWay, "--no-linking/--one-way", "order a surface plan's passes (a mesh's raster is one zigzag)");
  reject(options.noGougeCheck, "--no-gouge-check", "skips a surface's sampled check (a mesh's moves are all proven exactly)");
  reject(!options.svgPath.empty(), "--svg", "draws a surface's sections (scallop plan draws a mesh's simulated cut)");
  const MeshPlanOptions job = meshPathsOptions(options);
  const Units units = mesh.units;
  const double rapidRate = options.rapidRate.empty()
                               ? defaultRapidRate(units)
                               : parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  MeshToolpathResult raster = part != nullptr ? meshToolpaths(*part, job) : meshToolpaths(mesh, job);
  const GcodeDialect dialect = gcodeDialect(options.dialect);
  const GcodeOptions gcodeOptions = defaultGcodeOptions(units, raster.partTop, raster.raster.path, dialect,
                                                        fmt::format("scallop paths raster {}", source));
  PathsReport& report = raster.report;
  report.motion = gcodeMotion(raster.raster.path, gcodeOptions, rapidRate);
  report.feedRate = gcodeOptions.feedRate;
  report.plungeFeedRate = gcodeOptions.plungeFeedRate;
  report.rapidRate = rapidRate;
  std::vector<OutputFile> outputs;
  const bool anyOutput = !options.jsonPath.empty() || !options.gcodePath.empty();
  const std::string jsonPath = anyOutput ? options.jsonPath : std::string(kStandardStream);
  if (!jsonPath.empty()) outputs.push_back({jsonPath, pathsToJson(report, raster.raster.path)});
  if (!options.gcodePath.empty())
    outputs.push_back({options.gcodePath, gcodeProgram(raster.raster.path, gcodeOptions)});
  writeOutputs(outputs, "");
  if (jsonPath != kStandardStream) {
    fmt::print(stderr,
               "scallop: {}: raster paths on {} triangles, {} lines {:.6g} to {:.6g} apart, tool-centre length {:.6g} "
               "{}, every move proven (deepest ball interference {:.3g}, exact); {}; {:.3f} s\n",
               source, mesh.triangles.size(), raster.raster.lines, raster.raster.minSpacing, report.spacing,
               raster.raster.centreLength, unitsName(units), report.gouge->maxDepth, cycleSummary(report, units),
               report.seconds);
  }
}

void runPaths(const PathsOptions& options) {
  requireOneSurfaceSource(options.surface, "paths");
  if (options.spacing.empty() == options.scallopHeight.empty())
    throw CLI::ValidationError("paths", "give exactly one of --spacing and --scallop-height");
  if (options.strategy == "raster" && options.normal != "auto")
    throw CLI::ValidationError("paths", "--normal is for --strategy contour");
  if (isStlSource(options.surface.input)) {
    if (options.surface.exactTrims)
      throw Error(fmt::format("{}: --exact-trims is for STEP and IGES parts; an STL file is a mesh",
                              options.surface.input));
    if (options.tessellate || !options.deflection.empty())
      throw Error(fmt::format("{}: --tessellate and --deflection are for STEP and IGES parts; an STL file is a mesh "
                              "already",
                              sourceName(options.surface)));
    const Mesh mesh = loadStlMesh(options.surface.input, options.units, options.dropZeroArea).mesh;
    return runPathsMesh(options, mesh, nullptr);
  }
  if (!options.units.empty() || options.dropZeroArea)
    throw Error("--units and --drop-zero-area are for STL meshes (a .stl file); a surface's units are in its file");
  const CadRoute route = cadRoute(options.surface, options.tessellate, options.deflection, exactRationalFaces(options.surface));
  if (route.tessellate) {
    const bool quiet = options.jsonPath.empty() && options.gcodePath.empty();  // JSON on stdout: stderr quiet too
    announceTessellation(*route.part, route.exact, "paths", quiet);
    const TessellatedPart part =
        tessellatedJob(*route.part, meshPathsOptions(options), options.deflection, "paths", quiet);
    return runPathsMesh(options, part.mesh, &part);
  }
  const std::string strategy = options.strategy.empty() ? "contour" : options.strategy;
  if (strategy == "contour" && !options.angle.empty())
    throw CLI::ValidationError("paths", "--angle is for --strategy raster");
  ToolpathOptions job;
  job.strategy = parseStrategy(strategy);
  job.toolRadius = parsePositive(options.toolRadius, "tool radius", "a positive length");
  if (!options.spacing.empty())
    job.spacing = parsePositive(options.spacing, "spacing", "a positive length");
  if (!options.scallopHeight.empty())
    job.scallopHeight = parsePositive(options.scallopHeight, "scallop height", "a positive length");
  if (options.normal != "auto") job.normal = parseNormal(options.normal);
  if (!options.angle.empty()) job.angleDeg = parseFinite(options.angle, "angle", "degrees");
  job.gougeCheck = !options.noGougeCheck;
  job.link = !options.noLinking;
  job.dropEnvelope = !options.noDropEnvelope;
  job.constantSpacing = options.constantSpacing;
  job.linking.direction = options.oneWay ? PassDirection::keep : PassDirection::zigzag;

  const Surface surface = loadSurface(options.surface, true, route.exact ? &*route.exact : nullptr);
  const std::string source = sourceName(options.surface);
  job.source = source;
  const double rapidRate = options.rapidRate.empty()
                               ? defaultRapidRate(surface.units)
                               : parsePositive(options.rapidRate, "rapid rate", "a positive rate");
  ToolpathResult result = toolpaths(surface, job);
  const GcodeDialect dialect = gcodeDialect(options.dialect);
  const std::string title = fmt::format("scallop paths {} {}", strategy, source);
  const GcodeOptions gcodeOptions = defaultGcodeOptions(surface, result.path, dialect, title);
  result.report.motion = gcodeMotion(result.path, gcodeOptions, rapidRate);
  result.report.feedRate = gcodeOptions.feedRate;
  result.report.plungeFeedRate = gcodeOptions.plungeFeedRate;
  result.report.rapidRate = rapidRate;

  std::vector<OutputFile> outputs;
  const bool anyOutput = !options.jsonPath.empty() || !options.gcodePath.empty() || !options.svgPath.empty();
  const std::string jsonPath = anyOutput ? options.jsonPath : std::string(kStandardStream);
  if (!jsonPath.empty()) outputs.push_back({jsonPath, pathsToJson(result.report, result.path)});
  if (!options.gcodePath.empty()) outputs.push_back({options.gcodePath, gcodeProgram(result.path, gcodeOptions)});
  if (!options.svgPath.empty()) {
    outputs.push_back({options.svgPath,
                       pathsSvg(surface, result.contactCurves, result.path,
                                fmt::format("scallop paths: {} strategy, {}", strategy, source),
                                /*planView=*/false)});
  }
  writeOutputs(outputs, "");
  if (jsonPath != kStandardStream) {
    const PathStats& s = result.report.stats;
    fmt::print(stderr,
               "scallop: {}: {} paths, spacing {:.6g}, {} planes, {} components, tool-centre "
               "length {:.6g} {}; {}; {:.3f} s\n",
               source, strategy, result.report.spacing, s.planes, s.components,
               s.centreLength, unitsName(surface.units), cycleSummary(result.report, surface.units),
               result.report.seconds);
  }
}

}  // namespace

void addPathsCommand(CLI::App& app) {
  auto options = std::make_shared<PathsOptions>();
  CLI::App* paths = app.add_subcommand(
      "paths", "Tool paths for a ball-end cutter over a surface: contour or raster, as JSON, G-code, SVG");
  paths->footer(
      "Contour (default): planes N . r = k Delta, N the optimal slicing normal N* (--normal "
      "auto) or given as X,Y,Z; the ball's centre follows r + R n along each section. Raster: "
      "vertical planes along a feed direction (--angle DEG from +x, or the best one), each "
      "section's tool path from its scallop hull (Chou et al. 1994), passes linked zigzag; the "
      "ball is then checked against the whole surface and the deepest interference reported. "
      "Delta is --spacing, or derived from --scallop-height H and the least angle alpha between "
      "the planes and the surface: Delta = 2 sqrt(2 R H - H^2) sin(alpha).\n"
      "Example: scallop paths --example paper-1 --tool-radius 0.25 --scallop-height 0.001 "
      "--gcode out.ngc --svg out.svg");
  addSurfaceSourceOptions(*paths, options->surface, "surface file (JSON or .bpt; .step/.stp or .iges/.igs; .stl: a triangle mesh, cut by raster); - reads standard input",
                          "use a built-in example surface");
  paths->add_option("--tool-radius", options->toolRadius, "ball radius R, in the surface's units")
      ->required()
      ->type_name("R");
  paths->add_option("--spacing", options->spacing, "distance Delta between the planes")->type_name("D");
  paths->add_option("--scallop-height", options->scallopHeight, "largest scallop height H (< R)")
      ->type_name("H");
  addStrategyOption(*paths, options->strategy);
  paths->add_option("--normal", options->normal, "contour: auto (the optimal N*, default) or X,Y,Z")
      ->type_name("auto|X,Y,Z");
  paths->add_option("--angle", options->angle, "raster: feed direction in degrees from +x (default: the best)")
      ->type_name("DEG");
  addDialectOption(*paths, options->dialect);
  addLinkingOptions(*paths, options->noLinking, options->oneWay, options->rapidRate);
  paths->add_flag("--no-drop-envelope", options->noDropEnvelope,
                 "keep the strategy's own centres (contour: r + R n; raster: the in-plane scallop hull) "
                 "instead of lifting them to the proven gouge-free drop envelope; they cut into the "
                 "surface where the report's gouge check says");
  paths->add_flag("--constant-spacing", options->constantSpacing,
                  "with --scallop-height: the paper's constant plane spacing (flat-surface formula) "
                  "instead of adaptive offsets that keep the estimated cusp <= H on curved parts");
  paths->add_option("--json", options->jsonPath, "write the report and the passes as JSON (- = standard output)")
      ->type_name("OUT");
  paths->add_option("--gcode", options->gcodePath, "write the G-code program")->type_name("OUT");
  paths->add_option("--svg", options->svgPath, "write a picture of the surface, the sections and the paths")
      ->type_name("OUT");
  addStlOptions(*paths, options->units, options->dropZeroArea);
  addExactTrimsOption(*paths, options->surface);
  paths->add_flag("--tessellate", options->tessellate,
                  "STEP/IGES: raster on the part's tessellation, the proofs kept 1.5 times the measured deviation "
                  "farther (parts with trimmed faces are cut so without it)");
  paths->add_option("--deflection", options->deflection, "STEP/IGES tessellation: OCCT mesher's linear deflection (default H/8)")
      ->type_name("D");
  paths->add_flag("--no-gouge-check", options->noGougeCheck, "skip the sampled ball-against-surface check (the drop envelope's proof stays)");
  paths->callback([options] { runPaths(*options); });
}

}  // namespace scallop::cli
