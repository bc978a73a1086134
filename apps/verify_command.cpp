// `scallop verify`: simulate a G-code program's cut on a z-map of the stock and compare it
// with the design surface (cut_simulation.hpp): gouges, scallops left, uncut area, as a
// summary line, JSON and a heat map. Everything is computed first; the files are written all
// or nothing. Exit status: 0, also when the program gouges, unless --fail-on-gouge is given
// and the deepest gouge exceeds the tolerance: then 2 (after writing the outputs). Errors 1.

#include <algorithm>
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
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/verify_output.hpp"
#include "surface_options.hpp"

namespace scallop::cli {
namespace {

constexpr const char* kStandardStream = "-";

struct VerifyOptions {
  std::vector<std::string> files;  // [SURFACE] PROGRAM
  std::string example;
  std::string patches;
  std::string radius;
  std::string scallopHeight;
  std::string resolution;
  std::string gougeTolerance;
  std::string stockTop;
  std::string stockAllowance;
  std::string jsonPath;
  std::string svgPath;
  bool failOnGouge = false;
  bool skipFaces = false;  // --skip-faces: a STEP or IGES file's unsupported faces
  bool exactTrims = false;  // --exact-trims: trimmed B-spline faces exactly
  std::string units;          // --units in|mm: an STL mesh's (STL has none)
  bool dropZeroArea = false;  // --drop-zero-area: an STL mesh's zero-area triangles
};

int runVerify(const VerifyOptions& options) {
  SurfaceSource source;
  source.example = options.example;
  source.patches = options.patches;
  const std::size_t expected = options.example.empty() ? 2 : 1;
  if (options.files.size() != expected)
    throw CLI::ValidationError("verify", options.example.empty()
                                             ? "give SURFACE and PROGRAM (or --example NAME and PROGRAM)"
                                             : "with --example give only PROGRAM");
  if (expected == 2) source.input = options.files[0];
  source.skipFaces = options.skipFaces;
  source.exactTrims = options.exactTrims;
  const std::string programPath = options.files.back();

  SimulationOptions simulation;
  simulation.toolRadius = parsePositive(options.radius, "tool radius", "a positive length");
  // The design: a triangle mesh (.stl) or a surface of Bezier patches.
  const bool mesh = expected == 2 && isStlSource(source.input);
  if (mesh && options.exactTrims)
    throw Error(fmt::format("{}: --exact-trims is for STEP and IGES parts; an STL file is a mesh", source.input));
  if (mesh && (!options.patches.empty() || options.skipFaces))
    throw Error(fmt::format("{}: --patches and --skip-faces select a surface's patches or faces; not for a mesh",
                            source.input));
  if (!mesh && (!options.units.empty() || options.dropZeroArea))
    throw Error("--units and --drop-zero-area are for STL meshes (a .stl file); a surface's units are in its file");
  std::optional<StlMesh> stl;
  std::optional<Surface> surface;
  // A STEP or IGES part with faces the exact importer refuses (trimmed faces) is judged
  // on its exact faces through OCCT (cad_tessellation.hpp), unless --skip-faces asks for the
  // exact faces alone.
  std::optional<CadRoute> route;
  const CadPart* part = nullptr;
  if (mesh) {
    stl = loadStlMesh(source.input, options.units, options.dropZeroArea);
  } else {
    route = cadRoute(source, false, "", exactRationalFaces(source));
    if (route->tessellate) {
      part = &*route->part;
      if (!options.patches.empty())
        throw Error(fmt::format("{}: --patches selects Bezier patches; give --skip-faces to judge only the faces "
                                "imported exactly",
                                source.input));
      if (options.jsonPath != kStandardStream)
        fmt::print(stderr,
                   "scallop: {}: {} of {} faces cannot be imported as exact Bezier patches yet (the first: {}): the "
                   "program is judged on the exact faces through OpenCASCADE (vertical lines through each grid "
                   "point)\n",
                   source.input, route->exact->skipped.size(), part->faces(), route->exact->skipped.front().reason);
    } else {
      surface = loadSurface(source, true, route->exact ? &*route->exact : nullptr);
    }
  }
  const Units designUnits = mesh ? stl->mesh.units : part ? part->units() : surface->units;
  const bool inch = designUnits == Units::inch;
  simulation.scallopHeight = options.scallopHeight.empty()
                                 ? (inch ? 0.001 : 0.025)
                                 : parsePositive(options.scallopHeight, "scallop height", "a positive length");
  if (!(simulation.scallopHeight < simulation.toolRadius))
    throw Error(fmt::format("invalid scallop height '{}': must be smaller than the tool radius {}",
                            options.scallopHeight.empty() ? fmt::format("{}", simulation.scallopHeight) : options.scallopHeight,
                            simulation.toolRadius));
  if (!options.resolution.empty())
    simulation.resolution = parsePositive(options.resolution, "resolution", "a positive length");
  if (!options.gougeTolerance.empty())
    simulation.gougeTolerance = parsePositive(options.gougeTolerance, "gouge tolerance", "a positive length");
  if (!options.stockTop.empty()) simulation.stockTop = parseFinite(options.stockTop, "stock top", "a height");
  if (!options.stockAllowance.empty())
    simulation.stockAllowance = parseFinite(options.stockAllowance, "stock allowance", "a length >= 0");

  const GcodeProgram program = readGcodeProgram(programPath);
  const SimulationReport report = [&] {
    if (mesh) return verifyProgram(stl->mesh, program, simulation);
    if (!part) return verifyProgram(*surface, program, simulation);
    const Vec3 low = part->boxLow(), high = part->boxHigh();
    const CadPart& exact = *part;
    // Reach is classified on a tessellation (the normal and the drop envelope from its
    // triangles, as on an STL mesh): at H / 8, no finer than 1e-5 of the part's size.
    TessellationOptions tessellation;
    tessellation.deflection = std::max(simulation.scallopHeight / 8.0, 1e-5 * norm(high - low));
    const Mesh facets = exact.tessellate(tessellation).mesh;
    return verifyProgram(
        exact.units(), simulationGrid(Vec2{low.x, low.y}, Vec2{high.x, high.y}, simulation), high.z,
        [&exact](HeightGrid& grid, std::vector<double>& normalZ) { exact.designHeights(grid, &normalZ); }, program,
        simulation, &facets);
  }();
  const VerifySources sources{sourceName(source), program.sourceName == "-" ? "<stdin>" : program.sourceName,
                              program.unknownStartMoves, program.maxArcRadiusMismatch};

  std::vector<OutputFile> outputs;
  if (!options.jsonPath.empty()) outputs.push_back({options.jsonPath, verifyToJson(report, sources)});
  if (!options.svgPath.empty()) outputs.push_back({options.svgPath, verifySvg(report, sources)});
  writeOutputs(outputs, "");
  const std::string units(unitsName(designUnits));
  const bool gouges = report.maxGouge > report.gougeTolerance;
  if (options.jsonPath != kStandardStream) {
    fmt::print(stderr,
               "scallop: {}: {} moves on {} x {} points (spacing {:.6g} {}): deepest gouge {:.6g} {} (vertical){}, "
               "scallop max {:.6g} / 99% {:.6g} / mean {:.6g} {}, above H = {:.6g} on {:.6g} {}^2; {:.3f} s\n",
               sources.program, report.moves, report.design.columns, report.design.rows, report.design.spacing, units,
               report.maxGouge, units,
               gouges && report.maxGougeAt
                   ? fmt::format(" at ({:.4f}, {:.4f}) ({} points beyond {:.6g})", report.maxGougeAt->x,
                                 report.maxGougeAt->y, report.gougePoints, report.gougeTolerance)
                   : std::string(),
               report.maxScallop, report.scallopP99, report.meanScallop, units, report.scallopHeight, report.uncutArea,
               units, report.seconds);
    if (report.unreachablePoints > 0)
      fmt::print(stderr, "scallop: {}: {:.6g} {}^2 left above H beyond the ball's reach (up to {:.6g} {}): a smaller "
                 "tool's work, not in the scallop figures\n", sources.program, report.unreachableArea, units,
                 report.maxUnreachableScallop, units);
    if (report.clearedGougePoints > 0)
      fmt::print(stderr, "scallop: {}: {} points over vertical walls measure up to {:.6g} {} below the wall's top, "
                 "where the ball that cut them lowest is proven clear of the part: grazed, not gouged\n",
                 sources.program, report.clearedGougePoints, report.maxClearedGouge, units);
    if (report.rapidsCutting > 0)
      fmt::print(stderr, "scallop: {}: {} rapid moves cut material, the first on line {}\n", sources.program,
                 report.rapidsCutting, report.firstRapidCutLine);
  }
  return options.failOnGouge && gouges ? 2 : 0;
}

}  // namespace

void addVerifyCommand(CLI::App& app, int& exitStatus) {
  auto options = std::make_shared<VerifyOptions>();
  CLI::App* verify = app.add_subcommand(
      "verify", "Simulate a G-code program's cut on a z-map and compare it with the surface: gouges and scallops");
  verify->footer(
      "Reads the program (G0-G3 in G17/G18/G19, G20/G21, G90, G91.1, positions the ball's tip), "
      "sweeps a ball of radius R along every move through a height map of the stock over the "
      "surface's footprint (exact at each grid point), and compares it with the highest point of the "
      "surface above each grid point: gouge = surface - stock (vertical), scallop = stock - surface "
      "(along the surface normal). The grid "
      "spacing follows the scallop height H (a scallop ridge between points is missed by at most H/4) "
      "unless --resolution is given. Exit status 0 (also with gouges), 1 on error, 2 with "
      "--fail-on-gouge when the deepest gouge exceeds the tolerance.\n"
      "Example: scallop plan --out out && scallop verify --example paper-1 out/toolpath.ngc --radius 0.25 "
      "--svg verify.svg");
  verify->add_option("FILES", options->files, "[SURFACE] PROGRAM: the surface (JSON, .bpt, STEP or IGES; .stl: a triangle mesh; not with --example) and the G-code")
      ->required()
      ->expected(1, 2)
      ->type_name("");
  verify->add_option("--example", options->example, "use a built-in example surface")
      ->check(CLI::IsMember(exampleSurfaceNames()))
      ->type_name("NAME");
  verify->add_option("--patches", options->patches, "keep only these patches of the surface, e.g. 4 or 4-7,12")
      ->type_name("LIST");
  verify->add_flag("--exact-trims", options->exactTrims,
                   "STEP/IGES: judge trimmed faces of B-spline and Bezier surfaces (and planes) on the exact Bezier "
                   "patches with their trimming curves, instead of through OpenCASCADE");
  verify->add_flag("--skip-faces", options->skipFaces,
                   "STEP/IGES: leave out the faces that cannot be imported exactly, as plan --skip-faces");
  verify->add_option("--radius", options->radius, "ball radius R, in the surface's units")->required()->type_name("R");
  verify->add_option("--scallop-height", options->scallopHeight,
                     "scallop height H aimed at (default 0.001 in / 0.025 mm): grid spacing and uncut area")
      ->type_name("H");
  verify->add_option("--resolution", options->resolution, "grid spacing (default from H)")->type_name("D");
  verify->add_option("--gouge-tolerance", options->gougeTolerance,
                     "a gouge deeper than this counts (default 0.0001 in / 0.0025 mm)")
      ->type_name("T");
  verify->add_option("--stock-allowance", options->stockAllowance,
                     "finishing: the stock is the design surface raised by this (what roughing left), "
                     "capped by --stock-top, instead of a flat block");
  verify->add_option("--stock-top", options->stockTop, "the stock's flat top before the cut (default: the top of the surface's bounding box)")
      ->type_name("Z");
  verify->add_option("--json", options->jsonPath, "write the figures as JSON (- = standard output)")->type_name("OUT");
  verify->add_option("--svg", options->svgPath, "write the heat map of scallops and gouges")->type_name("OUT");
  addStlOptions(*verify, options->units, options->dropZeroArea);
  verify->add_flag("--fail-on-gouge", options->failOnGouge,
                   "exit with status 2 when the deepest gouge exceeds the tolerance (outputs are still written)");
  verify->callback([options, &exitStatus] { exitStatus = runVerify(*options); });
}

}  // namespace scallop::cli
