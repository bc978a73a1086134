// The raster of a triangle mesh for `scallop plan` and `scallop paths` (see mesh_job.hpp).

#include "mesh_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "arguments.hpp"
#include "scallop/paths/cusp.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/mesh_drop.hpp"

namespace scallop::cli {
namespace {

// The largest |coordinate| of a mesh's vertices (as surfaceScale is a surface's).
double meshScale(const Mesh& mesh) {
  double scale = 0.0;
  for (const Vec3& v : mesh.vertices) scale = std::max({scale, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  return scale;
}

}  // namespace

MeshRasterResult runMeshRaster(const MeshJob& job, const MeshRasterRequest& request) {
  MeshRasterResult result;
  result.start = std::chrono::steady_clock::now();
  const std::string& path = request.source;
  const auto progress = [&](const std::string& line) {
    if (!request.quiet) fmt::print(stderr, "scallop {}: {}...\n", request.command, line);
  };
  const Mesh& mesh = job.mesh;
  const bool inch = mesh.units == Units::inch;
  const double radius = request.toolRadius.empty()
                            ? (inch ? 0.25 : 6.0)
                            : parsePositive(request.toolRadius, "tool radius", "a positive length");
  // A ball a thousand times the size of the part is a typo, not a tool (as for surfaces).
  if (radius > 1e3 * std::max(meshScale(mesh), 1e-300))
    throw Error(fmt::format("{}: the tool radius {} is more than 1000 times the mesh's size (largest |coordinate| {} "
                            "{}); check the units (--units)",
                            path, radius, meshScale(mesh), unitsName(mesh.units)));
  std::optional<double> height;
  double spacing = 0.0;
  if (!request.spacing.empty()) {
    spacing = parsePositive(request.spacing, "spacing", "a positive length");
    flatCusp(radius, spacing);  // refused early from 2 R up
  } else {
    height = request.scallopHeight.empty() ? (inch ? 0.001 : 0.025)
                                           : parsePositive(request.scallopHeight, "scallop height", "a positive length");
    if (!(*height < radius))
      throw Error(fmt::format("the scallop height {} must be smaller than the tool radius {}", *height, radius));
    // A tessellated part's passes stand the clearance off the mesh, which stands up to the
    // deviation off the exact faces: the cusps aim at what is left of H (at least H / 4).
    spacing = meshRasterSpacing(radius, std::max(*height - job.clearance - job.deviation, 0.25 * *height));
  }
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
  const auto solidMesh = std::make_shared<const Mesh>(meshWithSkirt(mesh, 4e-6 * diagonal));
  const Mesh& solid = *solidMesh;
  // A tessellated part's proofs use the ball grown by the clearance: a centre R + c from the
  // mesh is at least R from every exact face within c of the mesh.
  const double proofRadius = radius + job.clearance;
  const auto cutterShared = std::make_shared<const MeshDropCutter>(solid, proofRadius);
  const MeshDropCutter& cutter = *cutterShared;
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
  result.top = top;
  result.simulation = simulation;
  result.solid = solidMesh;
  result.cutter = cutterShared;
  result.dropLine.eps = paths.eps;
  result.dropLine.sagTolerance = raster.sagTolerance;
  result.dropLine.floor = raster.floor;
  result.report = std::move(report);
  result.paths = std::move(paths);
  return result;
}

// A STEP or IGES part's tessellation as a mesh job (cad_tessellation.hpp). The deflection
// asked of the mesher is H / 8 unless given: what the mesh's error adds to the scallops is then
// small beside H (measured, the deviation is often 1.5-3 times the deflection).
MeshJob tessellatedJob(const CadPart& part, const std::optional<CadImport>& exact, const MeshRasterRequest& options,
                       const std::string& deflectionText) {
  const bool inch = part.units() == Units::inch;
  const auto progress = [&](const std::string& line) {
    if (!options.quiet) fmt::print(stderr, "scallop {}: {}...\n", options.command, line);
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
  if (!deflectionText.empty()) {
    deflection = parsePositive(deflectionText, "deflection", "a positive length");
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
               "scallop {}: warning: the exact faces stand up to {:.3g} {} from the mesh (face {}, near ({:.6g}, "
               "{:.6g}, {:.6g})), and the passes keep 1.5 times that farther: that leaves more than 3/4 of H = {}, "
               "so the scallops may exceed H (a smaller --deflection helps unless the model's own tolerance is the "
               "cause)\n",
               options.command, mesh.deviation, unitsName(part.units()), mesh.deviationFace, mesh.deviationAt.x, mesh.deviationAt.y,
               mesh.deviationAt.z, height);
  job.tessellation = TessellationSummary{part.faces(), mesh.mesh.triangles.size(), deflection, mesh.deviation,
                                         mesh.deviationFace, job.clearance, false};
  job.mesh = std::move(mesh.mesh);
  return job;
}

}  // namespace scallop::cli
