#pragma once
// What `scallop paths` and `scallop plan` write besides G-code: the JSON report of a tool
// path (strategy, parameters, statistics, the gouge check, the passes themselves) and
// pictures of it in the spirit of the paper's Figs 2, 6, 9 and 13 (the surface with its
// sections and the tool-centre paths, in an axonometric view, and the plan view).
//
// Contract
// --------
// JSON: one object, keys in the documented order, every number shortest-round-trip (full
//       double precision); positions are ball centres in the surface's units. Moves:
//       {"line": [x, y, z]} or {"arc": {"end": [..], "center": [..], "plane": "xy"|"zx"|"yz",
//       "clockwise": bool}} (clockwise as G2: seen from the plane normal's positive end).
//       No wall times (the `seconds` fields below are for callers; the CLI prints them on
//       stderr): the same input gives the same bytes.
// SVG:  fixed-point coordinates only (never an exponent, nan or inf); deterministic.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "scallop/paths/contour.hpp"
#include "scallop/paths/cusp.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/paths/linking.hpp"
#include "scallop/paths/rest_finishing.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// The optimal slicing orientation, when the job computed it (optimal_slicing.hpp).
struct OrientationSummary {
  Vec3 normal;
  double alphaRad = 0.0;
  bool certified = false;
  std::size_t boundarySegments = 0;
  double seconds = 0.0;
};

/// `scallop plan`'s simulation of its own program (cut_simulation.hpp), in short.
struct VerificationSummary {
  double gridSpacing = 0.0;
  double heightErrorBound = 0.0;  ///< how much a scallop ridge can hide between grid points
  double stockAllowance = 0.0;    ///< the finishing stock: the surface raised by this
  double maxGouge = 0.0;          ///< vertical, at grid points
  std::optional<Vec3> maxGougeAt;
  double gougeArea = 0.0;         ///< beyond the gouge tolerance
  double gougeTolerance = 0.0;
  double maxScallop = 0.0;
  std::optional<Vec3> maxScallopAt;
  double scallopP99 = 0.0;
  double meanScallop = 0.0;
  double uncutArea = 0.0;         ///< scallop above H where the ball reaches
  double unreachableArea = 0.0;   ///< left above H beyond the ball's reach (a smaller tool's)
  double maxUnreachableLeft = 0.0;
  std::size_t rapidsCutting = 0;
  double seconds = 0.0;
  /// Grid points over a vertical wall the ball only grazed (cut_simulation.hpp's Vertical
  /// walls): out of the gouge figures; their vertical measure at most.
  std::size_t clearedGougePoints = 0;
  double maxClearedGouge = 0.0;
};

/// One round of `scallop plan`'s rest finishing: what the simulated cut left before it, and
/// the rest passes added.
struct RestRound {
  double maxScallopBefore = 0.0;  ///< the simulated max scallop over reachable points, before
  double uncutAreaBefore = 0.0;   ///< the area above H before
  RestReport rest;
};

/// The scallop height on the curved surface (cusp.hpp), when the spacing came from H: the
/// plane offsets used (adaptive, or the paper's constant Delta) beside the paper's flat-surface
/// spacing, and the distribution of the estimated cusp heights between neighbouring passes.
struct ScallopReport {
  bool adaptive = false;        ///< offsets from adaptivePlaneOffsets (else k Delta_flat)
  double flatSpacing = 0.0;     ///< the paper's Delta = 2 sqrt(2RH - H^2) sin(alpha)
  std::size_t flatPlanes = 0;   ///< planes k Delta_flat within the surface's sampled extent
  std::size_t planes = 0;       ///< planes used that cut the surface
  double minSpacing = 0.0;      ///< least and largest gap between neighbouring planes used
  double maxSpacing = 0.0;
  std::size_t floorSteps = 0;   ///< adaptive steps that fell to the floor (cusp.hpp)
  double chordalTolerance = 0.0;  ///< the sections' (and so the passes' chords') tolerance
  CuspStatistics cusp;          ///< estimated cusp heights (an estimate: see cusp.hpp)
};

/// A STEP or IGES part cut through its tessellation (cad_tessellation.hpp): how far the mesh
/// stands from the exact faces, and what the plan did about it.
struct TessellationSummary {
  std::size_t faces = 0;
  std::size_t triangles = 0;
  double deflection = 0.0;     ///< D asked of OCCT's mesher
  double deviation = 0.0;      ///< sampled max distance from the exact faces to their triangles
  std::size_t deviationFace = 0;
  double clearance = 0.0;      ///< added to R in every proof against the mesh
  bool exactDesign = false;    ///< the simulated cut judged against the exact faces (else the mesh)
};

struct PathsReport {
  std::string strategy;            ///< "contour" or "raster"
  std::string source;              ///< the surface's file or example name
  Units units = Units::inch;
  double toolRadius = 0.0;
  double spacing = 0.0;            ///< Delta between planes
  std::optional<double> scallopHeight;  ///< H when Delta was derived from it
  Vec3 planeNormal;                ///< N of the cutting planes (unit)
  double alphaRad = 0.0;           ///< proven least angle between N and +-n
  std::optional<double> feedAngleRad;   ///< raster: the feed direction's angle from +x
  /// Raster: the links, entries and exits (RasterPaths::linkLength) and the pass ends with
  /// no proven way off (RasterPaths::unclearedEnds).
  std::optional<double> linkLength;
  std::optional<std::size_t> unclearedEnds;
  PathStats stats;
  std::optional<ScallopReport> scallop;  ///< with a scallop height H (cusp.hpp)
  /// The drop envelope's lifting (envelope.hpp), when the strategy lifted its passes.
  std::optional<EnvelopeReport> envelope;
  std::optional<GougeReport> gouge;  ///< the ball against the whole surface, sampled
  double gougeSampleSpacing = 0.0;   ///< the spacing the gouge check sampled at
  std::optional<OrientationSummary> orientation;
  std::optional<LinkStats> linking;   ///< when the passes were linked (linking.hpp)
  /// Per pass of the written path, the leading moves that are the linker's feed over the drop
  /// envelope from the previous pass's end (LinkedPath::linkMoves; empty: none).
  std::vector<std::size_t> linkMoves;
  /// The simulated cut of the written program (`scallop plan`; none for `paths`).
  std::optional<VerificationSummary> verification;
  /// `scallop plan`'s rest finishing (rest_finishing.hpp): one report per round of rest
  /// passes added after a simulated cut, with the simulated figures before the round (the
  /// `verification` above is of the final program). Empty: none was run or needed.
  std::vector<RestRound> restRounds;
  /// A STEP or IGES part cut through its tessellation; none for exact surfaces and STL.
  std::optional<TessellationSummary> tessellation;
  bool restFinishing = false;  ///< rest finishing was on (the rounds may still be none)
  /// The G-code program's motion and estimated cycle time (gcode.hpp's gcodeMotion), with
  /// the rates it assumed (units per minute).
  std::optional<GcodeMotion> motion;
  double feedRate = 0.0;
  double plungeFeedRate = 0.0;
  double rapidRate = 0.0;
  double seconds = 0.0;
};

/// The report and the passes as JSON (see the contract).
std::string pathsToJson(const PathsReport& report, const ToolPath& path);

/// An axonometric picture of the surface (iso-parameter lines), the contact curves (the
/// sections) and the tool-centre passes, with rapid moves dashed: as the paper's figures of
/// the slicing planes on the test surfaces. `planView` looks straight down instead.
std::string pathsSvg(const Surface& surface, const std::vector<std::vector<Vec3>>& contactCurves,
                     const ToolPath& path, const std::string& title, bool planView);

}  // namespace scallop
