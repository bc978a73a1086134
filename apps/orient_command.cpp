// `scallop orient`: reads a surface of Bezier patches (a file, standard input or a built-in
// example), computes its optimal slicing orientation N* (the direction of parallel planes
// that meet the surface at the largest possible minimum angle alpha*), and writes JSON and/or
// two SVG figures. Every output is computed into memory first and the files are then written
// all or nothing, so a failed run leaves no output behind (not even the --svg-dir directory).

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "arguments.hpp"
#include "commands.hpp"
#include "output_directory.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/error.hpp"
#include "scallop/io/file_output.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/slicing/mesh_slicing.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/io/orient_output.hpp"
#include "scallop/geometry/surface.hpp"
#include "surface_options.hpp"

namespace scallop::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kStandardStream = "-";

// The Gauss-map tolerance must stay well inside the library's limit (0.1 rad, about 5.7
// degrees); beyond a few degrees the polygonal Gauss map is too coarse to mean much.
constexpr double kMaxToleranceDeg = 5.0;

constexpr const char* kSphereFigure = "gauss-map.svg";
constexpr const char* kPlaneFigure = "stereographic.svg";

struct OrientOptions {
  SurfaceSource surface;  // SURFACE ("-": standard input) or --example NAME, --patches
  std::string tolerance;  // --tolerance DEG, parsed by parseTolerance
  std::string jsonPath;   // --json OUT
  std::string svgDir;     // --svg-dir DIR
  bool noCertify = false;  // --no-certify
  bool latticeSeeds = false;  // --lattice-seeds
  std::string units;      // --units in|mm: an STL mesh's (STL has none)
  bool dropZeroArea = false;  // --drop-zero-area: an STL mesh's zero-area triangles
  bool tessellate = false;    // --tessellate: a STEP/IGES part oriented by its tessellation
  std::string deflection;     // --deflection D: that tessellation's
  std::string trimSpread;     // --trim-spread DEG: how closely pieces follow trimming curves
};

// The default of --trim-spread, degrees.
constexpr double kDefaultTrimSpreadDeg = 2.0;

// Where the JSON goes: --json, or standard output when no output is named at all.
std::string jsonDestination(const OrientOptions& options) {
  if (!options.jsonPath.empty()) return options.jsonPath;
  return options.svgDir.empty() ? std::string(kStandardStream) : std::string();
}

// The options of a Bezier surface's Gauss map, refused by name for a mesh's largest empty cap
// (`what`: "a mesh", "a tessellated part").
void rejectSurfaceOptions(const OrientOptions& options, const std::string& source, const char* what) {
  const auto reject = [&](bool given, const char* option, const char* why) {
    if (given) throw Error(fmt::format("{}: {} {}; not for {}", source, option, why, what));
  };
  reject(!options.surface.patches.empty(), "--patches", "selects Bezier patches");
  reject(!options.tolerance.empty(), "--tolerance", "is the polygonal Gauss map's (a mesh's is exact)");
  reject(!options.svgDir.empty(), "--svg-dir", "draws a surface's Gauss map");
  reject(options.noCertify || options.latticeSeeds, "--no-certify/--lattice-seeds", "apply to Bezier surfaces");
  reject(!options.trimSpread.empty(), "--trim-spread", "follows a trimmed face's curves with Bezier pieces");
}

// `orient` on an STL mesh (mesh_slicing.hpp): the largest empty cap of the +-facet normals.
void runOrientMesh(const OrientOptions& options) {
  const std::string& path = options.surface.input;
  rejectSurfaceOptions(options, path, "a mesh");
  const auto start = std::chrono::steady_clock::now();
  const StlMesh mesh = loadStlMesh(path, options.units, options.dropZeroArea);
  const MeshSlicing result = optimalMeshSlicing(mesh.mesh);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string jsonPath = jsonDestination(options);
  writeOutputs({{jsonPath, meshOrientationToJson(result, mesh, path)}}, "");
  if (jsonPath != kStandardStream) {
    fmt::print(stderr,
               "scallop: {}: {} triangles ({} STL{}), {} distinct normals: N* = ({:.6f}, {:.6f}, {:.6f}), alpha* = "
               "{:.4f} deg{}; {:.3f} s -> {}\n",
               path, result.triangles, mesh.format == StlFormat::binary ? "binary" : "ASCII",
               mesh.zeroAreaDropped > 0 ? fmt::format(", {} of zero area dropped", mesh.zeroAreaDropped) : std::string(),
               result.distinctNormals, result.normal.x, result.normal.y, result.normal.z, toDegrees(result.alphaRad),
               result.greatCircle ? " (every normal on one great circle: its pole)" : "", seconds, jsonPath);
  }
}

// `orient` on a STEP or IGES part with faces the exact importer refuses (or trimmed faces
// past the budget of pieces), or with --tessellate: the largest empty cap of the +-exact normals sampled at its
// tessellation's nodes and inside its triangles: an upper bound of the part's alpha*, not
// certified.
void runOrientTessellated(const OrientOptions& options, const CadPart& part, const std::optional<CadImport>& exact) {
  const std::string source = sourceName(options.surface);
  rejectSurfaceOptions(options, source, "a tessellated part");
  const auto start = std::chrono::steady_clock::now();
  const std::string jsonPath = jsonDestination(options);
  const bool talk = jsonPath != kStandardStream;
  if (exact && talk)
    fmt::print(stderr,
               "scallop: {}: {} of {} faces cannot be imported as exact Bezier patches yet (the first: {}): oriented "
               "by its tessellation\n",
               source, exact->skipped.size(), part.faces(), exact->skipped.front().reason);
  TessellationOptions tessellation;
  // The normals matter here: a finer angular deflection than the plan's, and a deflection of
  // 1e-3 of the part's size unless given.
  tessellation.angularDeflection = 0.1;
  tessellation.deflection = options.deflection.empty()
                                ? 1e-3 * norm(part.boxHigh() - part.boxLow())
                                : parsePositive(options.deflection, "deflection", "a positive length");
  const CadTessellation mesh = part.tessellate(tessellation);
  if (mesh.sampledNormals.empty())
    throw Error(fmt::format("{}: no exact normal could be sampled on its faces", source));
  const MeshSlicing result = optimalNormalSlicing(mesh.sampledNormals);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const TessellationFacts facts{part.units(), part.faces(), tessellation.deflection, mesh.deviation,
                                mesh.normalDeviationRad, mesh.sampledNormals.size()};
  writeOutputs({{jsonPath, tessellationOrientationToJson(result, facts, source)}}, "");
  if (talk) {
    fmt::print(stderr,
               "scallop: {}: {} exact normals sampled on its {} faces (at the nodes and inside the triangles of its "
               "tessellation): N* = ({:.6f}, {:.6f}, {:.6f}), alpha* <= {:.4f} deg (theirs: normals between the "
               "samples can only lower it), not certified; {:.3f} s -> {}\n",
               source, result.normalsGiven, part.faces(), result.normal.x, result.normal.y, result.normal.z,
               toDegrees(result.alphaRad), seconds, jsonPath);
  }
}

// Checks the combination of options, which CLI11 cannot express.
void checkOptions(const OrientOptions& options) {
  requireOneSurfaceSource(options.surface, "orient");
  if (options.svgDir == kStandardStream) {
    throw CLI::ValidationError("orient", "--svg-dir needs a directory, not standard output");
  }
}

// The library's default tolerance in degrees, rounded to drop the conversion's last-bit noise
// (0.5 deg -> rad -> deg may not come back as exactly 0.5).
double defaultToleranceDeg() {
  return std::round(toDegrees(OptimalSlicingOptions{}.toleranceRad) * 1e9) / 1e9;
}

// Degrees in [the Gauss map's least tolerance, kMaxToleranceDeg).
double parseTolerance(const std::string& text) {
  const double degrees =
      parsePositive(text, "tolerance", "a positive angle in degrees, below 5");
  if (!(degrees < kMaxToleranceDeg)) {
    throw Error(fmt::format("invalid tolerance '{}': must be below {} degrees", text,
                            kMaxToleranceDeg));
  }
  const double leastDeg = toDegrees(kMinGaussMapToleranceRad);
  if (degrees < leastDeg) {
    throw Error(fmt::format("invalid tolerance '{}': must be at least {:.2g} degrees (finer than "
                            "the Gauss map's integer grid resolves)", text, leastDeg));
  }
  return degrees;
}


std::string certificateSummary(const OptimalSlicing& result, bool certify) {
  if (!certify) return "not certified (--no-certify)";
  if (result.certified) {
    return fmt::format("certified alpha >= {:.4f} deg ({} cells)",
                       toDegrees(result.certifiedAlphaRad), result.certificateCells);
  }
  return fmt::format("NOT certified ({} cells)", result.certificateCells);
}

void printSummary(const std::string& source, const OptimalSlicing& result, bool certify,
                  const std::vector<OutputFile>& outputs) {
  std::string written;
  for (const OutputFile& output : outputs) {
    written += (written.empty() ? "" : ", ") + output.path;
  }
  if (result.method == SlicingMethod::covered) {
    fmt::print(stderr,
               "scallop: {}: no slicing direction exists: the surface's normals cover the whole "
               "sphere (proven, {} caps), alpha* = 0; {:.3f} s -> {}\n",
               source, result.coverage.caps, result.seconds, written);
    return;
  }
  if (result.method == SlicingMethod::lattice) {
    fmt::print(stderr,
               "scallop: {}: the Gauss map leaves no direction free within its tolerance, but no "
               "proof covers every direction (none found near ({:.4f}, {:.4f}, {:.4f})); best "
               "direction found N = ({:.6f}, {:.6f}, {:.6f}), alpha = {:.4f} deg, {}; {:.3f} s -> {}\n",
               source, result.coverage.unprovenDirection.x, result.coverage.unprovenDirection.y,
               result.coverage.unprovenDirection.z, result.normal.x, result.normal.y,
               result.normal.z, toDegrees(result.alphaRad), certificateSummary(result, certify),
               result.seconds, written);
    return;
  }
  fmt::print(stderr,
             "scallop: {}: N* = ({:.6f}, {:.6f}, {:.6f}), alpha* = {:.4f} deg, {}, {} boundary "
             "segments, {:.3f} s -> {}\n",
             source, result.normal.x, result.normal.y, result.normal.z,
             toDegrees(result.alphaRad), certificateSummary(result, certify),
             result.gaussMap.boundarySegments, result.seconds, written);
}

// A part with trimmed faces: alpha* between the certified lower bound (all pieces) and the
// optimum of the inside pieces (see orient_output.hpp's trimmedOrientationToJson).
void printTrimmedSummary(const std::string& source, const OptimalSlicing& result, const TrimmedFacts& facts,
                         bool certify, const std::vector<OutputFile>& outputs) {
  std::string written;
  for (const OutputFile& output : outputs) written += (written.empty() ? "" : ", ") + output.path;
  const std::string lower =
      result.method == SlicingMethod::open
          ? std::string("alpha* >= 0 (the pieces, boundary pieces included, leave no direction free)")
      : certify && result.certified
          ? fmt::format("alpha* >= {:.4f} deg (certified over the faces and their boundary pieces)",
                        toDegrees(result.certifiedAlphaRad))
          : fmt::format("alpha* >= {:.4f} deg ({})", toDegrees(result.alphaRad), certificateSummary(result, certify));
  std::string upper = "no upper bound (no piece lies wholly inside a face)";
  if (facts.inside != nullptr) {
    if (facts.inside->method == SlicingMethod::covered) {
      upper = "alpha* = 0: the normals inside the faces alone cover the sphere (proven): no slicing direction exists";
    } else if (facts.inside->method == SlicingMethod::open || facts.inside->method == SlicingMethod::lattice) {
      upper = "no upper bound: the pieces inside the faces leave no direction free within the Gauss map's tolerance, "
              "unproven";
    } else {
      upper = fmt::format("<= {:.4f} deg (the optimum of the pieces inside the faces)", toDegrees(facts.inside->alphaRad));
    }
  }
  fmt::print(stderr,
             "scallop: {}: {} trimmed faces followed by {} pieces inside and {} on their trimming curves (normals "
             "within {:.4g} deg): N* = ({:.6f}, {:.6f}, {:.6f}), {}, {}; {:.3f} s -> {}\n",
             source, facts.faces, facts.insidePieces, facts.boundaryPieces, toDegrees(facts.largestSpreadRad),
             result.normal.x, result.normal.y, result.normal.z, lower, upper,
             result.seconds + (facts.inside != nullptr ? facts.inside->seconds : 0.0), written);
}

void runOrient(const OrientOptions& options) {
  checkOptions(options);
  if (isStlSource(options.surface.input)) {
    runOrientMesh(options);
    return;
  }
  if (!options.units.empty() || options.dropZeroArea)
    throw Error("--units and --drop-zero-area are for STL meshes (a .stl file); a surface's units are in its file");
  // The Gauss map takes rational patches (bezier.hpp), and trimmed faces as pieces that follow
  // their trimming curves (trimmed_patch.hpp): only faces of other kinds need the tessellation.
  CadImportOptions exactOptions;
  exactOptions.acceptRational = true;
  exactOptions.acceptTrimmed = true;
  double trimSpreadDeg = kDefaultTrimSpreadDeg;
  if (!options.trimSpread.empty()) {
    trimSpreadDeg = parsePositive(options.trimSpread, "trim spread", "a positive angle in degrees, below 10");
    if (!(trimSpreadDeg < 10.0))
      throw Error(fmt::format("invalid trim spread '{}': must be below 10 degrees", options.trimSpread));
  }
  exactOptions.trimSplit.normalSpreadRad = trimSpreadDeg * (std::numbers::pi / 180.0);
  const CadRoute route = cadRoute(options.surface, options.tessellate, options.deflection, exactOptions);
  // An asked spread that some face cannot be taken at (past the budget of pieces, say) is
  // refused with that face's reason, not silently traded for the tessellation.
  if (!options.trimSpread.empty() && route.exact && !route.exact->skipped.empty())
    throw Error(fmt::format("{}: --trim-spread {}: {}", sourceName(options.surface), options.trimSpread,
                            route.exact->skipped.front().reason));
  if (!options.trimSpread.empty() && !(route.exact && route.exact->trimmedFaces > 0))
    throw Error(fmt::format("{}: --trim-spread is for STEP and IGES parts with trimmed faces, taken exactly",
                            sourceName(options.surface)));
  if (route.tessellate) return runOrientTessellated(options, *route.part, route.exact);
  OptimalSlicingOptions slicingOptions;  // the library's default tolerance unless given
  double toleranceDeg = defaultToleranceDeg();
  if (!options.tolerance.empty()) {
    toleranceDeg = parseTolerance(options.tolerance);
    slicingOptions.toleranceRad = toleranceDeg * (std::numbers::pi / 180.0);
  }
  slicingOptions.certify = !options.noCertify;
  slicingOptions.latticeSeeds = options.latticeSeeds;

  SurfaceSource source = options.surface;
  source.acceptRational = true;  // the Gauss map takes rational patches (bezier.hpp)
  const bool trimmed = route.exact && route.exact->trimmedFaces > 0;
  if (trimmed && !options.surface.patches.empty())
    throw Error(fmt::format("{}: --patches selects patches, and its trimmed faces are pieces: not with --patches",
                            options.surface.input));
  const Surface surface = loadSurface(source, true, route.exact ? &*route.exact : nullptr);
  // A trimmed part's pieces hold more normals than its faces: when they leave no direction
  // free, a proof that they cover the sphere says nothing of the faces, and alpha >= 0 is all
  // the lower bound can say (the search over thousands of pieces would be long for it).
  OptimalSlicingOptions allOptions = slicingOptions;
  if (trimmed) allOptions.noComplement = OptimalSlicingOptions::NoComplement::stop;
  const OptimalSlicing result = optimalSlicing(surface, allOptions);
  // A trimmed part: the pieces inside their faces alone bound alpha* from above (their normals
  // are the part's), as the slicing of all of them bounds it from below.
  std::optional<OptimalSlicing> inside;
  TrimmedFacts facts;
  if (trimmed) {
    const CadImport& part = *route.exact;
    Surface insidePieces{surface.units, {}};
    for (std::size_t p = 0; p < surface.patches.size(); ++p)
      if (part.patchRoles[p] == PieceRole::inside) insidePieces.patches.push_back(surface.patches[p]);
    facts.faces = part.trimmedFaces;
    facts.insidePieces = insidePieces.patches.size();
    facts.boundaryPieces = surface.patches.size() - insidePieces.patches.size();
    facts.spreadRad = exactOptions.trimSplit.normalSpreadRad;
    facts.largestSpreadRad = part.largestSpreadRad;
    if (!insidePieces.patches.empty()) {
      OptimalSlicingOptions upperOptions = slicingOptions;
      upperOptions.certify = false;  // it bounds alpha* from above: a lower bound of its own says nothing
      // No complement: a proof that these normals cover the sphere proves alpha* = 0; the
      // lattice's best would bound nothing from above.
      upperOptions.noComplement = OptimalSlicingOptions::NoComplement::prove;
      inside = optimalSlicing(insidePieces, upperOptions);
      facts.inside = &*inside;
    }
  }

  std::vector<OutputFile> outputs;
  const std::string jsonPath = jsonDestination(options);
  if (!jsonPath.empty())
    outputs.push_back({jsonPath, trimmed ? trimmedOrientationToJson(result, toleranceDeg, facts)
                                         : orientationToJson(result, toleranceDeg)});
  if (!options.svgDir.empty()) {
    const fs::path dir = options.svgDir;
    outputs.push_back({(dir / kSphereFigure).string(), gaussMapSphereSvg(result)});
    outputs.push_back({(dir / kPlaneFigure).string(), stereographicSvg(result)});
  }
  writeOutputs(outputs, options.svgDir);

  // The summary goes to stderr, but stays quiet when the JSON is piped on standard output.
  if (jsonPath != kStandardStream) {
    if (trimmed) {
      printTrimmedSummary(sourceName(options.surface), result, facts, slicingOptions.certify, outputs);
    } else {
      printSummary(sourceName(options.surface), result, slicingOptions.certify, outputs);
    }
  }
}

}  // namespace

void addOrientCommand(CLI::App& app) {
  // Owned by the callback, which outlives this function (CLI11's pattern for subcommands
  // defined in their own file).
  auto options = std::make_shared<OrientOptions>();
  CLI::App* orient = app.add_subcommand(
      "orient", "Optimal slicing orientation of a free-form surface, as JSON and/or SVG figures");
  orient->footer(
      "Computes the direction N* of parallel slicing planes N* . r = k Delta that maximises the "
      "least angle alpha* between the planes' normal and the surface normals +-n (Smith, "
      "Farouki, al-Kandari, Pottmann 2002): symmetrized Gauss map, stereographic projection, "
      "medial axis, eqs (12)-(14), then a Bernstein-form certificate that no surface normal "
      "comes within alpha* of +-N*. Writes JSON (to standard output if neither --json nor "
      "--svg-dir is given) and/or two figures, DIR/gauss-map.svg (the Gauss map and the optimal "
      "circle on the sphere) and DIR/stereographic.svg (the stereographic plane with the medial "
      "axis); outputs are written all or nothing.\n"
      "Input: JSON {\"units\": \"in\"|\"mm\", \"patches\": [{\"degree\": [m, n], "
      "\"control_points\": [[[x, y, z], ... n + 1], ... m + 1 rows]}, ...]}, or .bpt text (the "
      "patch count, then per patch a line 'm n' and (m + 1)(n + 1) lines 'x y z', in inches); "
      "every patch must be regular (r_u x r_v != 0, except on a boundary row or column "
      "collapsed to one point, an apex, and at a corner where it vanishes to first order: there "
      "the normal's limits are taken).\n"
      "When the Gauss map leaves no direction free, 'no slicing direction exists' is said only "
      "with a proof that the normals cover the sphere; otherwise the best direction found, "
      "certified.\n"
      "A STEP (.step, .stp) or IGES (.iges, .igs) file is read through OpenCASCADE: every face "
      "becomes Bezier patches exactly, in the file's units (inches or millimetres); rational faces "
      "as rational patches; trimmed faces become pieces that follow their trimming curves: alpha* is then given between a certified "
      "lower bound (all pieces) and the optimum of the pieces inside the faces.\n"
      "A .stl file (binary or ASCII) is a triangle mesh: N* is then the centre of the largest "
      "spherical cap free of its +-facet normals (their convex hull's facet nearest the origin), "
      "alpha* the least angle to them; JSON only.\n"
      "Example: scallop orient --example teapot-body --json out.json --svg-dir figs");

  addSurfaceSourceOptions(*orient, options->surface,
                          "surface file (JSON or .bpt, Bezier patches; .step/.stp or .iges/.igs: CAD faces; .stl: a triangle mesh); - reads standard input",
                          "use a built-in example surface instead");
  orient
      ->add_option("--tolerance", options->tolerance,
                   fmt::format("angular tolerance of the Gauss map's polygonal boundary, in "
                               "degrees, in (0, {}); default {}. Smaller is more accurate and "
                               "slower",
                               kMaxToleranceDeg, defaultToleranceDeg()))
      ->type_name("DEG");
  orient
      ->add_option("--json", options->jsonPath,
                   "write N*, alpha*, the certificate and statistics as JSON to OUT (- = "
                   "standard output)")
      ->type_name("OUT");
  orient
      ->add_option("--svg-dir", options->svgDir,
                   "write the figures gauss-map.svg and stereographic.svg into DIR (created "
                   "if missing)")
      ->type_name("DIR");
  orient->add_flag("--no-certify", options->noCertify,
                   "skip the Bernstein-form certificate (faster; \"certified\" is then false)");
  orient->add_flag("--lattice-seeds", options->latticeSeeds,
                   "also polish from the best directions of a fixed lattice of 2,000 (a "
                   "safety net beside the medial axis; off: the paper's method alone)");
  addStlOptions(*orient, options->units, options->dropZeroArea);
  orient->add_flag("--tessellate", options->tessellate,
                   "STEP/IGES: orient the part by its tessellation's sampled normals (an upper bound, not certified) "
                   "even when every face could be taken exactly; parts with faces that cannot (or with trimmed "
                   "faces past the budget of pieces) are oriented so without it");
  orient->add_option("--trim-spread", options->trimSpread,
                     fmt::format("STEP/IGES trimmed faces: split the pieces crossing a trimming curve until their "
                                 "normals spread by at most DEG degrees (default {}); alpha* is then bounded within "
                                 "about that",
                                 kDefaultTrimSpreadDeg))
      ->type_name("DEG");
  orient->add_option("--deflection", options->deflection,
                     "STEP/IGES tessellation: OCCT mesher's linear deflection (default 1e-3 of the part's size)")
      ->type_name("D");
  orient->callback([options] { runOrient(*options); });
}

}  // namespace scallop::cli
