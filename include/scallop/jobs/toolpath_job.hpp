#pragma once
// The tool paths of a surface as `scallop paths` makes them (and `scallop plan`, plan.hpp,
// before its G-code and simulated cut).
//
// Contract
// --------
// toolpaths(surface, options, control): from the user's choices (strategy, tool radius,
// spacing or scallop height, plane normal or feed angle) to the finished tool path: passes by
// the contour strategy on the optimal planes N* (or given ones) or the raster strategy, lifted
// to the drop envelope, ordered and linked, and the ball checked against the whole surface.
// The report (paths_output.hpp's PathsReport) holds every figure the CLI writes.
// Errors: scallop::Error naming `options.source` (bad options are refused before any work);
// scallop::Cancelled when `control`'s token is set (job_control.hpp), which also carries the
// progress. Deterministic: the same input gives the same result for any thread count.

#include <optional>
#include <string>
#include <vector>

#include "scallop/io/gcode.hpp"
#include "scallop/job_control.hpp"
#include "scallop/paths/linking.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"

namespace scallop {

enum class Strategy {
  contour,  ///< sections by parallel planes N . x = k Delta (the optimal N* unless given)
  raster,   ///< vertical planes along a feed direction, each section's scallop hull
};

/// "contour" or "raster".
const char* strategyName(Strategy strategy);
/// The inverse of strategyName; scallop::Error naming the text otherwise.
Strategy parseStrategy(const std::string& text);

struct ToolpathOptions {
  std::string source = "surface";       ///< the surface's name in errors and the report
  Strategy strategy = Strategy::contour;
  double toolRadius = 0.0;              ///< R > 0
  std::optional<double> spacing;        ///< Delta, or
  std::optional<double> scallopHeight;  ///< H (0 < H < R): planes from H (cusp.hpp)
  /// With H: the paper's constant Delta from H and alpha (flat-surface formula) instead of
  /// the adaptive offsets that keep the estimated cusp <= H on the curved surface.
  bool constantSpacing = false;
  std::optional<Vec3> normal;           ///< contour: N; none = the optimal N* (orient)
  std::optional<double> angleDeg;       ///< raster: feed angle; none = the best angle
  bool gougeCheck = true;               ///< measure the ball's interference (gouge.hpp)
  bool link = true;                     ///< order and link the passes (linking.hpp)
  bool dropEnvelope = true;             ///< lift to the drop envelope (envelope.hpp)
  LinkOptions linking;
};

struct ToolpathResult {
  PathsReport report;
  ToolPath path;
  /// The strategy's passes before linking (the same as `path` without linking): what
  /// addPasses links again with more passes.
  ToolPath unlinkedPath;
  std::vector<std::vector<Vec3>> contactCurves;  ///< the sections, for the figures
  std::optional<OptimalSlicing> orientation;     ///< when N* was computed
};

/// The checks toolpaths makes before any work: a positive finite tool radius at most 1000 times
/// the surface's size, exactly one of spacing and scallop height, positive and finite, H < R.
/// scallop::Error.
void validateToolpathOptions(const Surface& surface, const ToolpathOptions& options);

/// Computes the tool path (see the contract); `orientation`, when given, is reused as N*.
ToolpathResult toolpaths(const Surface& surface, const ToolpathOptions& options,
                         std::optional<OptimalSlicing> orientation = std::nullopt,
                         const JobControl& control = {});

/// `extra` passes (rest finishing: same units and radius) added to the result's unlinked
/// passes, and the whole linked and gouge-checked again as toolpaths does. Runs under the
/// job control installed on this thread (plan's).
void addPasses(const Surface& surface, const ToolpathOptions& options, const ToolPath& extra,
               ToolpathResult& result);

/// G-code options that suit the surface's units: feeds 40 / 15 in/min or 1000 / 400
/// mm/min, 10,000 rpm, and a safe height 0.2 in (5 mm) above the highest of the surface's
/// control points and of the path's tool tips.
GcodeOptions defaultGcodeOptions(const Surface& surface, const ToolPath& path,
                                 GcodeDialect dialect, const std::string& title);
/// The same for a part whose highest point is `partTop` (a mesh's highest vertex).
GcodeOptions defaultGcodeOptions(Units units, double partTop, const ToolPath& path, GcodeDialect dialect,
                                 const std::string& title);

/// The rapid rate assumed for the cycle time when none is given: 200 in/min or 5000 mm/min.
double defaultRapidRate(Units units);

}  // namespace scallop
