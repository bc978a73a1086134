#include "scallop/jobs/toolpath_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "scallop/paths/contour.hpp"
#include "scallop/paths/cusp.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/paths/raster.hpp"

namespace scallop {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The stages of toolpaths, as parts of its [0, 1] (by their share of paper-1's plan time).
constexpr double kOrientEnd = 0.02, kOffsetsEnd = 0.40, kPathsEnd = 0.85, kLinkEnd = 0.88;

std::vector<Vec3> curvePoints(const SectionCurve& curve) {
  std::vector<Vec3> points;
  points.reserve(curve.points.size());
  for (const SectionPoint& p : curve.points) points.push_back(p.point);
  return points;
}

// The ball against the whole surface, sampled every R / 10 along the path (the bound
// between samples adds R / 20): an independent measure beside the envelope's proof.
void checkGouge(const Surface& surface, const ToolpathOptions& options, ToolpathResult& result) {
  const double spacing = options.toolRadius / 10.0;
  const ProgressStage stage(kLinkEnd, 1.0,
                            fmt::format("checking the ball against the whole surface every {:.6g}", spacing));
  result.report.gouge = gougeCheck(surface, result.path, spacing);
  result.report.gougeSampleSpacing = spacing;
}

// The scallop height on the curved surface (cusp.hpp): with H, the sections are traced to
// H / 20 (a pass is a chord between exact offset points; where the surface is concave along
// the pass the chord lies above the true offset curve and leaves up to the chordal tolerance
// of extra material) and, unless --constant-spacing, the planes are adaptivePlaneOffsets'
// for the cusp H - H / 20.
struct ScallopPlanes {
  std::vector<double> offsets;  ///< empty: k Delta
  double chordalTolerance = 0.0;  ///< 0: the strategy's default
  std::size_t floorSteps = 0;
};

ScallopPlanes scallopPlanes(const Surface& surface, const ToolpathOptions& options, const Vec3& normal,
                            bool centrePlanes) {
  ScallopPlanes out;
  if (!options.scallopHeight || options.constantSpacing) return out;
  out.chordalTolerance =
      std::min(1e-4 * std::max(surfaceScale(surface), 1e-300), *options.scallopHeight / 20.0);
  CuspOptions cusp;
  cusp.toolRadius = options.toolRadius;
  // A pass is a chord between exact offset points: where the surface is concave along it,
  // the chord leaves up to the chordal tolerance above the true offset, on top of the cusp
  // (cusp.hpp), so the cusps are kept below H minus that.
  cusp.scallopHeight = *options.scallopHeight - out.chordalTolerance;
  cusp.chordalTolerance = out.chordalTolerance;
  cusp.centrePlanes = centrePlanes;
  const ProgressStage stage(kOrientEnd, kOffsetsEnd,
                            "choosing plane offsets that keep the cusp below the scallop height on the curved surface");
  AdaptiveOffsets adaptive = adaptivePlaneOffsets(surface, normal, cusp);
  out.offsets = std::move(adaptive.offsets);
  out.floorSteps = adaptive.floorSteps;
  return out;
}

ScallopReport scallopReport(const Surface& surface, const ToolpathOptions& options, const Vec3& normal,
                            double flatSpacing, const ScallopPlanes& planes,
                            const std::vector<PlaneContacts>& used, bool centrePlanes) {
  ScallopReport report;
  report.adaptive = !planes.offsets.empty();
  report.flatSpacing = flatSpacing;
  const auto [lo, hi] = sampledExtent(surface, normal);
  report.flatPlanes =
      static_cast<std::size_t>(std::max(0.0, std::floor(hi / flatSpacing) - std::ceil(lo / flatSpacing) + 1.0));
  report.planes = used.size();
  report.minSpacing = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < used.size(); ++k) {
    const double gap = used[k + 1].offset - used[k].offset;
    report.minSpacing = std::min(report.minSpacing, gap);
    report.maxSpacing = std::max(report.maxSpacing, gap);
  }
  if (used.size() < 2) report.minSpacing = 0.0;
  report.floorSteps = planes.floorSteps;
  report.chordalTolerance = planes.chordalTolerance > 0.0
                                ? planes.chordalTolerance
                                : 1e-4 * std::max(surfaceScale(surface), 1e-300);
  CuspOptions cusp;
  cusp.toolRadius = options.toolRadius;
  cusp.scallopHeight = options.scallopHeight.value_or(0.0);
  cusp.centrePlanes = centrePlanes;
  report.cusp = cuspStatistics(surface, normal, used, cusp);
  return report;
}

void runContour(const Surface& surface, const ToolpathOptions& options, ToolpathResult& result) {
  Vec3 normal;
  double alpha = 0.0;
  if (options.normal) {
    normal = normalized(*options.normal);
    const ProgressStage stage(0.0, kOrientEnd, "bounding the angle between the planes and the surface normals");
    alpha = minimumAngleBound(surface, normal);
  } else {
    if (!result.orientation) {
      const ProgressStage stage(0.0, kOrientEnd, "computing the optimal slicing orientation N*");
      result.orientation = optimalSlicing(surface);
    }
    normal = result.orientation->normal;
    // Machining from above: the planes' normal sign is free; prefer N . z >= 0.
    if (normal.z < 0.0) normal = -normal;
    alpha = result.orientation->certified ? result.orientation->certifiedAlphaRad
                                          : minimumAngleBound(surface, normal);
    // A closed surface (the teapot) has no direction free of its normals: every plane
    // orientation touches it tangentially, so no spacing bounds the scallop height.
    const SlicingMethod method = result.orientation->method;
    if (!options.spacing && (method == SlicingMethod::covered || method == SlicingMethod::lattice) && !(alpha > 0.0)) {
      throw Error(method == SlicingMethod::covered
                      ? "no slicing direction exists: the surface's normals cover the whole "
                        "sphere (proven), so every contour plane touches it tangentially and no "
                        "spacing bounds the scallop height; use --strategy raster, or give "
                        "--spacing"
                      : "no slicing direction free of the surface's normals was found (the "
                        "Gauss map covers the sphere within its tolerance): no spacing bounds "
                        "the scallop height; use --strategy raster, or give --spacing");
    }
  }
  ContourOptions contour;
  contour.normal = normal;
  contour.toolRadius = options.toolRadius;
  if (options.scallopHeight) contour.stretchThreshold = *options.scallopHeight;
  // Where the envelope sags between two lifted vertices, a straight move would leave its sag
  // on top of the cusp: split such moves down to a quarter of H.
  if (options.scallopHeight) contour.sagTolerance = *options.scallopHeight / 4.0;
  contour.dropEnvelope = options.dropEnvelope;
  contour.spacing = options.spacing ? *options.spacing
                                    : spacingForScallopHeight(options.toolRadius,
                                                              *options.scallopHeight, alpha);
  const ScallopPlanes planes = scallopPlanes(surface, options, normal, false);
  contour.planeOffsets = planes.offsets;
  contour.chordalTolerance = planes.chordalTolerance;
  std::optional<ProgressStage> stage;
  stage.emplace(kOffsetsEnd, kPathsEnd,
                planes.offsets.empty() ? fmt::format("cutting the surface with planes {:.6g} apart", contour.spacing)
                                       : fmt::format("cutting the surface with {} planes", planes.offsets.size()));
  ContourPaths paths = contourPaths(surface, contour);
  stage.reset();
  if (options.scallopHeight) {
    std::vector<PlaneContacts> used;
    for (const ContourSection& section : paths.sections) used.push_back({section.offset, &section.section});
    result.report.scallop = scallopReport(surface, options, paths.normal, contour.spacing, planes, used, false);
  }
  result.report.spacing = paths.spacing;
  result.report.planeNormal = paths.normal;
  result.report.alphaRad = alpha;
  result.report.stats = paths.stats;
  if (options.dropEnvelope) result.report.envelope = paths.envelope;
  for (const ContourSection& section : paths.sections)
    for (const SectionCurve& curve : section.section.curves)
      result.contactCurves.push_back(curvePoints(curve));
  result.path = std::move(paths.path);
}

void runRaster(const Surface& surface, const ToolpathOptions& options, ToolpathResult& result) {
  RasterOptions raster;
  raster.toolRadius = options.toolRadius;
  if (options.scallopHeight) raster.stretchThreshold = *options.scallopHeight;
  if (options.scallopHeight) raster.sagTolerance = *options.scallopHeight / 4.0;
  raster.dropEnvelope = options.dropEnvelope;
  const bool adaptive = options.scallopHeight && !options.constantSpacing;
  if (options.angleDeg) {
    raster.angleRad = *options.angleDeg * kDeg;
  } else if (adaptive) {
    // The planes' normal is needed before the paths: the same search rasterPaths would run.
    const ProgressStage stage(0.0, kOrientEnd, "searching the feed direction with the widest step-over");
    raster.angleRad = bestRasterAngle(surface);
  } else {
    raster.bestAngle = true;
  }
  if (options.spacing) raster.spacing = *options.spacing;
  if (options.scallopHeight) raster.scallopHeight = *options.scallopHeight;
  ScallopPlanes planes;
  if (adaptive) {
    const Vec3 e{-std::sin(raster.angleRad), std::cos(raster.angleRad), 0.0};
    planes = scallopPlanes(surface, options, e, true);
    raster.planeOffsets = planes.offsets;
    raster.chordalTolerance = planes.chordalTolerance;
  }
  std::optional<ProgressStage> stage;
  stage.emplace(kOffsetsEnd, kPathsEnd,
                raster.bestAngle ? "searching the feed direction with the widest step-over; cutting the surface with "
                                   "vertical planes; scallop hull of each section"
                                 : "cutting the surface with vertical planes; scallop hull of each section");
  RasterPaths paths = rasterPaths(surface, raster);
  stage.reset();
  if (options.scallopHeight) {
    std::vector<PlaneContacts> used;
    for (const RasterSection& section : paths.sections) used.push_back({section.offset, &section.section});
    result.report.scallop = scallopReport(surface, options, paths.planeNormal, paths.spacing, planes, used, true);
  }
  result.report.spacing = paths.spacing;
  result.report.planeNormal = paths.planeNormal;
  result.report.alphaRad = paths.alphaRad;
  result.report.feedAngleRad = paths.angleRad;
  result.report.stats = paths.stats;
  result.report.linkLength = paths.linkLength;
  result.report.unclearedEnds = paths.unclearedEnds;
  for (const RasterSection& section : paths.sections)
    for (const SectionCurve& curve : section.section.curves)
      result.contactCurves.push_back(curvePoints(curve));
  if (options.dropEnvelope) result.report.envelope = paths.envelope;
  result.path = std::move(paths.path);
}

// Linking (linking.hpp): the finished path's passes ordered, and needless retracts to the
// safe height replaced by proven direct feeds and local retracts; then the gouge check on the
// path as it will be cut, links included.
void linkAndCheck(const Surface& surface, const ToolpathOptions& options, ToolpathResult& result) {
  const std::string& source = options.source;
  result.path = result.unlinkedPath;
  if (options.link) {
    const ProgressStage stage(kPathsEnd, kLinkEnd, "ordering and linking the passes");
    try {
      // The links' margin and their plunges at feed must exceed the stock left above the
      // surface: the cusps, up to the scallop height H (more at the boundary), so at least 4 H.
      LinkOptions linking = options.linking;
      const double standard = surface.units == Units::inch ? 0.02 : 0.5;
      if (linking.clearance == 0.0 && options.scallopHeight)
        linking.clearance = std::max(standard, 4.0 * *options.scallopHeight);
      if (linking.plunge == 0.0 && options.scallopHeight)
        linking.plunge = std::max(standard, 4.0 * *options.scallopHeight);
      LinkedPath linked = linkToolPath(surface, result.path, linking);
      result.path = std::move(linked.path);
      result.report.linking = linked.stats;
      result.report.linkMoves = std::move(linked.linkMoves);
    } catch (const Cancelled&) {
      throw;
    } catch (const Error& error) {
      throw Error(fmt::format("{}: {}", source, error.what()));
    }
  }
  if (options.gougeCheck) checkGouge(surface, options, result);
}

}  // namespace

const char* strategyName(Strategy strategy) { return strategy == Strategy::raster ? "raster" : "contour"; }

Strategy parseStrategy(const std::string& text) {
  if (text == "contour") return Strategy::contour;
  if (text == "raster") return Strategy::raster;
  throw Error(fmt::format("unknown strategy '{}': expected contour or raster", text));
}

void validateToolpathOptions(const Surface& surface, const ToolpathOptions& options) {
  const std::string& source = options.source;
  if (!(options.toolRadius > 0.0) || !std::isfinite(options.toolRadius))
    throw Error(fmt::format("the tool radius must be positive, got {}", options.toolRadius));
  // A ball a thousand times the size of the part is a typo (mm for inches, a missing
  // decimal point), not a tool; beyond it the path and the gouge check lose their meaning.
  const double size = std::max(surfaceScale(surface), 1e-300);
  if (options.toolRadius > 1e3 * size)
    throw Error(fmt::format("{}: the tool radius {} is more than 1000 times the surface's size "
                            "(largest |coordinate| {} {}); check the units",
                            source, options.toolRadius, size, unitsName(surface.units)));
  if (options.spacing.has_value() == options.scallopHeight.has_value())
    throw Error("give exactly one of --spacing and --scallop-height");
  if (options.spacing && (!(*options.spacing > 0.0) || !std::isfinite(*options.spacing)))
    throw Error(fmt::format("the spacing must be positive, got {}", *options.spacing));
  if (options.scallopHeight && (!(*options.scallopHeight > 0.0) || !std::isfinite(*options.scallopHeight)))
    throw Error(fmt::format("the scallop height must be positive, got {}", *options.scallopHeight));
  if (options.scallopHeight && !(*options.scallopHeight < options.toolRadius))
    throw Error(fmt::format("the scallop height {} must be smaller than the tool radius {}",
                            *options.scallopHeight, options.toolRadius));
}

ToolpathResult toolpaths(const Surface& surface, const ToolpathOptions& options,
                         std::optional<OptimalSlicing> orientation, const JobControl& control) {
  const JobControlScope scope(&control);
  const std::string& source = options.source;
  const auto start = std::chrono::steady_clock::now();
  validateToolpathOptions(surface, options);
  ToolpathResult result;
  result.orientation = std::move(orientation);
  result.report.strategy = strategyName(options.strategy);
  result.report.source = source;
  result.report.units = surface.units;
  result.report.toolRadius = options.toolRadius;
  result.report.scallopHeight = options.scallopHeight;
  // What goes wrong from here on is about the surface (or the planes against it): say which.
  try {
    if (options.strategy == Strategy::contour) {
      runContour(surface, options, result);
    } else {
      runRaster(surface, options, result);
    }
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", source, error.what()));
  }
  result.unlinkedPath = result.path;
  linkAndCheck(surface, options, result);
  result.report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void addPasses(const Surface& surface, const ToolpathOptions& options, const ToolPath& extra,
               ToolpathResult& result) {
  if (extra.units != result.unlinkedPath.units || extra.toolRadius != result.unlinkedPath.toolRadius)
    throw Error("addPasses: the extra passes' units or tool radius differ from the job's");
  result.unlinkedPath.passes.insert(result.unlinkedPath.passes.end(), extra.passes.begin(), extra.passes.end());
  linkAndCheck(surface, options, result);
}

GcodeOptions defaultGcodeOptions(const Surface& surface, const ToolPath& path,
                                 GcodeDialect dialect, const std::string& title) {
  // The surface's control points bound it from above, so rapids at the safe height clear it.
  return defaultGcodeOptions(surface.units, controlPointTop(surface), path, dialect, title);
}

GcodeOptions defaultGcodeOptions(Units units, double partTop, const ToolPath& path, GcodeDialect dialect,
                                 const std::string& title) {
  const bool inch = units == Units::inch;
  GcodeOptions options;
  options.dialect = dialect;
  options.feedRate = inch ? 40.0 : 1000.0;
  options.plungeFeedRate = inch ? 15.0 : 400.0;
  options.spindleRpm = 10000.0;
  options.title = title;
  // The highest tip (centre - R) of the path: line ends, and the top of every arc, which
  // lies at most its radius above its centre; and the part's top.
  double top = partTop;
  for (const ToolPass& pass : path.passes) {
    top = std::max(top, pass.start.z - path.toolRadius);
    for (const ToolMove& move : pass.moves) {
      top = std::max(top, move.end.z - path.toolRadius);
      if (move.kind == MoveKind::arc)
        top = std::max(top, move.center.z + norm(move.end - move.center) - path.toolRadius);
    }
  }
  options.safeHeight = top + (inch ? 0.2 : 5.0);
  return options;
}

double defaultRapidRate(Units units) { return units == Units::inch ? 200.0 : 5000.0; }

}  // namespace scallop
