#pragma once
// The work shared by `scallop paths` and `scallop plan`: from a surface and the user's
// choices (strategy, tool radius, spacing or scallop height, plane normal or feed angle) to
// the tool path, its report, the G-code and the figures. Errors propagate as scallop::Error.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scallop/gcode.hpp"
#include "scallop/linking.hpp"
#include "scallop/optimal_slicing.hpp"
#include "scallop/paths_output.hpp"
#include "scallop/surface.hpp"
#include "scallop/toolpath.hpp"

namespace scallop {

struct JobOptions {
  std::string strategy = "contour";     ///< "contour" or "raster"
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

struct JobResult {
  PathsReport report;
  ToolPath path;
  /// The strategy's passes before linking (the same as `path` without linking): what
  /// addPasses links again with more passes.
  ToolPath unlinkedPath;
  std::vector<std::vector<Vec3>> contactCurves;  ///< the sections, for the figures
  std::optional<OptimalSlicing> orientation;     ///< when N* was computed
};

/// Progress lines for long steps ("orienting", "sections", ...); may be empty.
using Progress = std::function<void(const std::string&)>;

/// Computes the tool path (see JobOptions); `orientation`, when given, is reused as N*.
JobResult runToolpathJob(const Surface& surface, const std::string& source,
                         const JobOptions& options, std::optional<OptimalSlicing> orientation,
                         const Progress& progress);

/// `extra` passes (rest finishing: same units and radius) added to the job's unlinked
/// passes, and the whole linked and gouge-checked again as runToolpathJob does.
void addPasses(const Surface& surface, const std::string& source, const JobOptions& options,
               const ToolPath& extra, JobResult& result, const Progress& progress);

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
