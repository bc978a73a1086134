// The plan of a triangle mesh (see mesh_plan.hpp).

#include "scallop/jobs/mesh_plan.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/io/verify_output.hpp"
#include "scallop/jobs/plan.hpp"
#include "scallop/jobs/toolpath_job.hpp"
#include "scallop/paths/cusp.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/paths/rest_finishing.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Rounds of rest finishing at most (each a simulation of the whole program more).
constexpr int kRestRounds = 2;

// The stages of planMesh, as parts of its [0, 1] (about their share of the paper-1 mesh's
// plan time), and the raster's own: the skirt, the cutter and the floor; the lines; the
// exact distances of the moves.
constexpr double kRasterEnd = 0.5, kGcodeEnd = 0.51, kSimulationEnd = 0.85;
constexpr double kSetupEnd = 0.05, kLinesEnd = 0.9;

// The largest |coordinate| of a mesh's vertices (as surfaceScale is a surface's).
double meshScale(const Mesh& mesh) {
  double scale = 0.0;
  for (const Vec3& v : mesh.vertices) scale = std::max({scale, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  return scale;
}

// The choices of a plan, checked and with their defaults (the mesh's units).
struct Settings {
  double radius = 0.0;
  std::optional<double> height;  ///< H; none with a spacing
  double spacing = 0.0;          ///< the lines' spacing at most
  double rapidRate = 0.0;
  double clearance = 0.0;        ///< c: a tessellated part's, 0 for a mesh
  double deviation = 0.0;
};

// The checks before any work (see the contract's Errors), in the order the CLI made them.
Settings settings(const Mesh& mesh, const TessellatedPart* part, const MeshPlanOptions& options) {
  const std::string& source = options.source;
  if (mesh.triangles.empty()) throw Error(fmt::format("{}: the mesh has no triangles", source));
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3 p = mesh.vertices[v];
    if (!std::isfinite(p.x + p.y + p.z))
      throw Error(fmt::format("{}: vertex {} ({}, {}, {}) is not finite", source, v, p.x, p.y, p.z));
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t index : mesh.triangles[t])
      if (index >= mesh.vertices.size())
        throw Error(fmt::format("{}: triangle {} names vertex {}, and the mesh has {} vertices", source, t, index,
                                mesh.vertices.size()));
  Settings out;
  if (part) {
    if (!(part->clearance >= 0.0 && std::isfinite(part->clearance)) ||
        !(part->deviation >= 0.0 && std::isfinite(part->deviation)))
      throw Error(fmt::format("{}: the tessellation's clearance {} and deviation {} must be >= 0 and finite", source,
                              part->clearance, part->deviation));
    out.clearance = part->clearance;
    out.deviation = part->deviation;
  }
  const bool inch = mesh.units == Units::inch;
  out.radius = options.toolRadius.value_or(inch ? 0.25 : 6.0);
  if (!(out.radius > 0.0) || !std::isfinite(out.radius))
    throw Error(fmt::format("{}: the tool radius must be positive and finite, got {}", source, out.radius));
  // A ball a thousand times the size of the part is a typo, not a tool (as for surfaces).
  if (out.radius > 1e3 * std::max(meshScale(mesh), 1e-300))
    throw Error(fmt::format("{}: the tool radius {} is more than 1000 times the mesh's size (largest |coordinate| {} "
                            "{}); check the units (--units)",
                            source, out.radius, meshScale(mesh), unitsName(mesh.units)));
  if (options.spacing && options.scallopHeight) throw Error("give at most one of a spacing and a scallop height");
  if (options.spacing) {
    out.spacing = *options.spacing;
    if (!(out.spacing > 0.0) || !std::isfinite(out.spacing))
      throw Error(fmt::format("{}: the spacing must be positive and finite, got {}", source, out.spacing));
    flatCusp(out.radius, out.spacing);  // refused early from 2 R up
  } else {
    const double height = options.scallopHeight.value_or(inch ? 0.001 : 0.025);
    if (!(height > 0.0) || !std::isfinite(height))
      throw Error(fmt::format("{}: the scallop height must be positive and finite, got {}", source, height));
    if (!(height < out.radius))
      throw Error(fmt::format("the scallop height {} must be smaller than the tool radius {}", height, out.radius));
    out.height = height;
    // A tessellated part's passes stand the clearance off the mesh, which stands up to the
    // deviation off the exact faces: the cusps aim at what is left of H (at least H / 4).
    out.spacing = meshRasterSpacing(out.radius, std::max(height - out.clearance - out.deviation, 0.25 * height));
  }
  out.rapidRate = options.rapidRate.value_or(defaultRapidRate(mesh.units));
  if (!(out.rapidRate > 0.0) || !std::isfinite(out.rapidRate))
    throw Error(fmt::format("the rapid rate must be positive, got {}", out.rapidRate));
  return out;
}

// The raster and what it was proven against, for more passes (rest finishing): the mesh
// walled down as a solid, its cutter (R plus the clearance) and the drop lines' options;
// and the simulation's options (R, H or the spacing's flat cusp, allowance, stock top).
struct Raster {
  MeshToolpathResult result;
  SimulationOptions simulation;
  std::unique_ptr<const Mesh> solid;
  std::unique_ptr<const MeshDropCutter> cutter;
  DropLineOptions dropLine;
};

// The raster of the contract's steps 1-3, under one stage spanning the caller's [0, 1].
Raster raster(const Mesh& mesh, const TessellatedPart* part, const MeshPlanOptions& options, const Settings& s) {
  const std::string& source = options.source;
  const std::string units(unitsName(mesh.units));
  const bool inch = mesh.units == Units::inch;
  const std::string description = !options.description.empty() ? options.description
                                  : part != nullptr            ? part->description
                                                               : fmt::format("{} triangles", mesh.triangles.size());
  const ProgressStage stage(
      0.0, 1.0,
      fmt::format("{}; raster along x, lines at most {:.6g} {} apart, each the exact drop line of a {} {} ball{}",
                  description, s.spacing, units, s.radius, units,
                  s.clearance > 0.0 ? fmt::format(" kept {:.3g} {} farther from the mesh", s.clearance, units)
                                    : std::string()));
  Raster out;
  MeshRasterOptions rasterOptions;
  // A tessellated part's proofs use the ball grown by the clearance: a centre R + c from the
  // mesh is at least R from every exact face within c of the mesh.
  const double proofRadius = s.radius + s.clearance;
  double top = -kInf;
  {
    const ProgressStage setup(0.0, kSetupEnd);
    // The proofs see the mesh as the top of a solid (its open edges walled down to its
    // bottom). The walls stand 4 eps outside the edges (eps: the drop lines' 1e-6 of the
    // mesh's size).
    Vec3 lo = mesh.vertices.front(), hi = lo;
    for (const Vec3& v : mesh.vertices) {
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
    out.solid = std::make_unique<const Mesh>(meshWithSkirt(mesh, 4e-6 * norm(hi - lo)));
    out.cutter = std::make_unique<const MeshDropCutter>(*out.solid, proofRadius);
    rasterOptions.spacing = s.spacing;
    // A chord of the drop line leaves at most its sag of material: a quarter of H, as the
    // surfaces' sag rule (envelope.hpp).
    if (s.height) {
      const double cuspHeight = std::max(*s.height - s.clearance - s.deviation, 0.25 * *s.height);
      rasterOptions.sagTolerance = cuspHeight / 4.0;
      // With H, the steps between lines adapt to the facets' slopes (mesh_raster.hpp).
      rasterOptions.scallopHeight = cuspHeight;
    }
    // Off the part the ball runs R above the lowest point seen from above (the simulation's
    // design, exact at its grid points), never beside the part below what it shows.
    SimulationOptions& simulation = out.simulation;
    simulation.toolRadius = s.radius;
    simulation.scallopHeight = s.height ? *s.height : flatCusp(s.radius, s.spacing);
    simulation.stockAllowance = std::max(inch ? 0.01 : 0.25, 2.0 * simulation.scallopHeight);
    for (const Vec3& v : mesh.vertices) top = std::max(top, v.z);
    // The finishing stock is the surface raised by the allowance everywhere: a flat top at
    // the part's highest point would clip it there (a flat part would show no scallop at all).
    simulation.stockTop = top + *simulation.stockAllowance;
    HeightGrid visible = simulationGrid(mesh, simulation);
    designHeights(mesh, visible);
    double lowest = kInf;
    for (const double z : visible.z)
      if (z != -kInf) lowest = std::min(lowest, z);
    if (std::isfinite(lowest)) rasterOptions.floor = lowest + proofRadius;
  }
  MeshRasterPaths& paths = out.result.raster;
  {
    const ProgressStage lines(kSetupEnd, kLinesEnd);
    try {
      paths = meshRasterPaths(*out.cutter, *out.solid, rasterOptions);
    } catch (const Cancelled&) {
      throw;
    } catch (const Error& e) {
      throw Error(fmt::format("{}: {}", source, e.what()));
    }
  }
  paths.path.toolRadius = s.radius;  // the centres were proven for R + clearance; the tool is R
  // The deepest the ball comes, exactly: every move's distance to the mesh.
  double least = kInf;
  Vec3 deepestAt;
  {
    const ProgressStage distances(kLinesEnd, 1.0);
    std::size_t moves = 0, total = 0;
    for (const ToolPass& pass : paths.path.passes) total += pass.moves.size();
    for (const ToolPass& pass : paths.path.passes) {
      Vec3 at = pass.start;
      for (const ToolMove& move : pass.moves) {
        if (++moves % 256 == 0) advanceStage(moves, total);
        const double d = out.cutter->segmentDistance(at, move.end, least);
        if (d < least) {
          least = d;
          deepestAt = move.end;
        }
        at = move.end;
      }
    }
  }

  PathsReport& report = out.result.report;
  report.strategy = "raster";
  report.source = source;
  report.units = mesh.units;
  report.toolRadius = s.radius;
  report.spacing = s.spacing;
  report.scallopHeight = s.height;
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
  if (part != nullptr)
    report.tessellation = TessellationSummary{part->faces, mesh.triangles.size(), part->deflection, part->deviation,
                                              part->deviationFace, part->clearance, false};
  out.result.partTop = top;
  out.dropLine.eps = paths.eps;
  out.dropLine.sagTolerance = rasterOptions.sagTolerance;
  out.dropLine.floor = rasterOptions.floor;
  return out;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

MeshToolpathResult toolpathsOf(const Mesh& mesh, const TessellatedPart* part, const MeshPlanOptions& options,
                               const JobControl& control) {
  const auto start = std::chrono::steady_clock::now();
  const JobControlScope scope(&control);
  const Settings s = settings(mesh, part, options);
  Raster out = raster(mesh, part, options, s);
  out.result.report.seconds = secondsSince(start);
  const ProgressStage done(1.0, 1.0, "done");
  return std::move(out.result);
}

MeshPlanResult planOf(const Mesh& mesh, const TessellatedPart* part, const MeshPlanOptions& options,
                      const JobControl& control) {
  const auto start = std::chrono::steady_clock::now();
  const JobControlScope scope(&control);
  const Settings s = settings(mesh, part, options);
  Raster r;
  {
    const ProgressStage stage(0.0, kRasterEnd);  // the raster names its own stage
    r = raster(mesh, part, options, s);
  }
  MeshPlanResult out;
  out.toolpaths = std::move(r.result);
  PathsReport& report = out.toolpaths.report;
  ToolPath& path = out.toolpaths.raster.path;
  const double top = out.toolpaths.partTop;
  out.programName = options.dialect == GcodeDialect::grbl ? "toolpath.gcode" : "toolpath.ngc";
  const std::string title = fmt::format("scallop plan raster {}", options.source);
  const auto write = [&] {
    out.gcode = defaultGcodeOptions(mesh.units, top, path, options.dialect, title);
    out.program = gcodeProgram(path, out.gcode);
  };
  // A tessellated part's exact design is computed once, for every simulation of the program.
  std::optional<std::pair<HeightGrid, std::vector<double>>> exactDesign;
  // The program as written, read back and cut in simulation, in [from, to] of the whole.
  const auto simulate = [&](double from, double to) -> SimulationReport {
    const GcodeProgram written = parseGcodeProgram(out.program, out.programName);
    if (part != nullptr && part->exactHeights) {
      HeightGrid grid = simulationGrid(mesh, r.simulation);
      if (grid.z.size() <= part->maxExactRays) {
        double at = from;
        if (!exactDesign) {
          // Vertical lines through exact faces cost far more than the sweep: most of the span.
          at = from + 0.7 * (to - from);
          const ProgressStage stage(
              from, at, fmt::format("the part's exact heights on {} x {} vertical lines", grid.columns, grid.rows));
          HeightGrid heights = grid;
          std::vector<double> normalZ;
          part->exactHeights(heights, normalZ);
          exactDesign.emplace(std::move(heights), std::move(normalZ));
        }
        const ProgressStage stage(at, to, "simulating the cut of the program on the part's exact faces");
        report.tessellation->exactDesign = true;
        return verifyProgram(
            mesh.units, std::move(grid), top,
            [&exactDesign](HeightGrid& g, std::vector<double>& normalZ) {
              g.z = exactDesign->first.z;
              normalZ = exactDesign->second;
            },
            written, r.simulation, &mesh);
      }
      const ProgressStage stage(from, to,
                                fmt::format("the simulation's {} x {} grid exceeds the budget of {} lines through the "
                                            "exact faces: simulating the cut on the mesh",
                                            grid.columns, grid.rows, part->maxExactRays));
      return verifyProgram(mesh, written, r.simulation);
    }
    const ProgressStage stage(from, to, "simulating the cut of the program on the mesh (scallop verify)");
    return verifyProgram(mesh, written, r.simulation);
  };
  {
    const ProgressStage stage(kRasterEnd, kGcodeEnd, "writing the G-code");
    write();
  }
  out.simulated = simulate(kGcodeEnd, kSimulationEnd);
  SimulationReport& simulated = out.simulated;
  // Rest finishing (rest_finishing.hpp): where the simulated cut leaves more than H on points
  // the ball can reach, passes through the balls that touch them, every step an exact drop
  // line; the program is simulated again. Only when H was asked.
  // A tessellated part whose clearance and deviation take half of H or more is left alone: the
  // balls stand that far off the exact faces wherever they go, so what exceeds H there is the
  // clearance's, which no rest pass removes (bearing.iges: 298 passes for nothing).
  report.restFinishing = s.height.has_value() && options.restFinishing && s.clearance + s.deviation < 0.5 * *s.height;
  const std::size_t rasterPasses = path.passes.size();
  for (int round = 0; report.restFinishing && round < kRestRounds; ++round) {
    if (round > 0 ? simulated.uncutPoints == 0 : restTargets(simulated, *s.height).empty()) break;
    // A second round only when the first took at least a tenth of what was above H.
    if (round > 0 && simulated.uncutArea > 0.9 * report.restRounds.back().uncutAreaBefore) break;
    const double from = kSimulationEnd + (1.0 - kSimulationEnd) * round / kRestRounds;
    const double to = kSimulationEnd + (1.0 - kSimulationEnd) * (round + 1) / kRestRounds;
    RestOptions rest;
    rest.toolRadius = report.toolRadius;
    rest.scallopHeight = *s.height;
    RestRound summary{simulated.maxScallop, simulated.uncutArea, {}};
    {
      const ProgressStage stage(from, (from + to) / 2.0,
                                fmt::format("rest finishing: {} grid points left above H", simulated.uncutPoints));
      RestPasses passes = meshRestPasses(*r.solid, *r.cutter, simulated, rest, r.dropLine);
      summary.rest = passes.report;
      report.restRounds.push_back(summary);
      if (passes.path.passes.empty()) break;
      for (ToolPass& pass : passes.path.passes) path.passes.push_back(std::move(pass));
      write();
    }
    simulated = simulate((from + to) / 2.0, to);
  }
  if (!report.restRounds.empty()) {
    // The deepest the ball comes, over the rest passes too (exact distances to the mesh; the
    // raster's own least distance is already in the report).
    GougeReport& deepest = *report.gouge;
    double least = r.cutter->radius() - deepest.signedMaxDepth;
    std::size_t moves = 0;
    for (std::size_t p = rasterPasses; p < path.passes.size(); ++p) {
      const ToolPass& pass = path.passes[p];
      Vec3 at = pass.start;
      for (const ToolMove& move : pass.moves) {
        if (++moves % 256 == 0) checkCancelled();
        const double d = r.cutter->segmentDistance(at, move.end, least);
        if (d < least) {
          least = d;
          deepest.deepest.center = move.end;
        }
        at = move.end;
      }
    }
    deepest.signedMaxDepth = r.cutter->radius() - least;
    deepest.maxDepth = std::max(0.0, deepest.signedMaxDepth);
    deepest.depthBound = deepest.maxDepth;
  }
  report.motion = gcodeMotion(path, out.gcode, s.rapidRate);
  report.feedRate = out.gcode.feedRate;
  report.plungeFeedRate = out.gcode.plungeFeedRate;
  report.rapidRate = s.rapidRate;
  report.verification = verificationSummary(simulated, *r.simulation.stockAllowance);
  report.seconds = secondsSince(start);
  const ProgressStage done(1.0, 1.0, "done");
  return out;
}

}  // namespace

MeshToolpathResult meshToolpaths(const Mesh& mesh, const MeshPlanOptions& options, const JobControl& control) {
  return toolpathsOf(mesh, nullptr, options, control);
}

MeshToolpathResult meshToolpaths(const TessellatedPart& part, const MeshPlanOptions& options,
                                 const JobControl& control) {
  return toolpathsOf(part.mesh, &part, options, control);
}

MeshPlanResult planMesh(const Mesh& mesh, const MeshPlanOptions& options, const JobControl& control) {
  return planOf(mesh, nullptr, options, control);
}

MeshPlanResult planMesh(const TessellatedPart& part, const MeshPlanOptions& options, const JobControl& control) {
  return planOf(part.mesh, &part, options, control);
}

std::vector<OutputFile> meshPlanFiles(const MeshPlanResult& result) {
  const PathsReport& report = result.toolpaths.report;
  return {
      {result.programName, result.program},
      {"report.json", pathsToJson(report, result.toolpaths.raster.path)},
      {"verify.svg", verifySvg(result.simulated, {report.source, result.programName, 0, 0.0})},
  };
}

}  // namespace scallop
