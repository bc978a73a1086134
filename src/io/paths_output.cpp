#include "scallop/io/paths_output.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "io/json_format.hpp"
#include "io/svg_format.hpp"

namespace scallop {
namespace {

using Json = nlohmann::ordered_json;

Json vec(const Vec3& p) { return Json::array({p.x, p.y, p.z}); }

const char* planeName(ArcPlane plane) {
  switch (plane) {
    case ArcPlane::xy: return "xy";
    case ArcPlane::zx: return "zx";
    case ArcPlane::yz: return "yz";
  }
  return "xy";
}

Json moveJson(const ToolMove& move) {
  Json json;
  if (move.kind == MoveKind::line) {
    json["line"] = vec(move.end);
  } else {
    Json arc;
    arc["end"] = vec(move.end);
    arc["center"] = vec(move.center);
    arc["plane"] = planeName(move.plane);
    arc["clockwise"] = move.clockwise;
    json["arc"] = arc;
  }
  return json;
}

// Points along an arc move from `from`, for drawing: counter-clockwise in (a, b) is positive
// angle; clockwise (G2) is negative.
void appendArc(const Vec3& from, const ToolMove& move, std::vector<Vec3>& out) {
  // The plane's in-plane axes, a x b its positive normal (toolpath.hpp).
  const Vec3 a = fromArcPlane(move.plane, {1.0, 0.0, 0.0});
  const Vec3 b = fromArcPlane(move.plane, {0.0, 1.0, 0.0});
  const Vec3 s = from - move.center;
  const ArcGeometry arc = arcGeometry(from, move);
  const double a0 = arc.startAngle;
  const double sweep = arc.sweep;
  const double radius = norm(s);
  const Vec3 normal = cross(a, b);
  const double level = dot(from, normal);
  const int steps = std::max(2, static_cast<int>(std::ceil(std::abs(sweep) / (5.0 * std::numbers::pi / 180.0))));
  for (int i = 1; i < steps; ++i) {
    const double t = a0 + sweep * i / steps;
    Vec3 p = move.center + radius * (std::cos(t) * a + std::sin(t) * b);
    p = p + (level - dot(p, normal)) * normal;
    out.push_back(p);
  }
  out.push_back(move.end);
}

std::vector<Vec3> passPoints(const ToolPass& pass) {
  std::vector<Vec3> points{pass.start};
  for (const ToolMove& move : pass.moves) {
    if (move.kind == MoveKind::line) {
      points.push_back(move.end);
    } else {
      appendArc(points.back(), move, points);
    }
  }
  return points;
}

// The title as SVG text: the five XML specials escaped.
std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

struct View {
  Vec3 right, up;
  Vec2 project(const Vec3& p) const { return {dot(p, right), -dot(p, up)}; }
};

}  // namespace

std::string pathsToJson(const PathsReport& report, const ToolPath& path) {
  Json document;
  document["strategy"] = report.strategy;
  document["source"] = report.source;
  document["units"] = std::string(unitsName(report.units));
  document["tool_radius"] = report.toolRadius;
  document["spacing"] = report.spacing;
  document["scallop_height"] = report.scallopHeight ? Json(*report.scallopHeight) : Json(nullptr);
  document["plane_normal"] = vec(report.planeNormal);
  document["alpha_deg"] = report.alphaRad * 180.0 / std::numbers::pi;
  if (report.feedAngleRad) document["feed_angle_deg"] = *report.feedAngleRad * 180.0 / std::numbers::pi;
  Json stats;
  stats["planes"] = report.stats.planes;
  stats["components"] = report.stats.components;
  stats["contact_length"] = report.stats.contactLength;
  stats["centre_length"] = report.stats.centreLength;
  stats["touch_points"] = report.stats.touchPoints;
  stats["passes"] = path.passes.size();
  if (report.linkLength) stats["link_length"] = *report.linkLength;
  if (report.unclearedEnds) stats["uncleared_ends"] = *report.unclearedEnds;
  document["stats"] = stats;
  if (report.scallop) {
    const ScallopReport& r = *report.scallop;
    // An infinite cusp (balls that do not meet) has no JSON number: null.
    const auto number = [](double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); };
    Json scallop;
    scallop["spacing_mode"] = r.adaptive ? "adaptive" : "constant";
    scallop["flat_spacing"] = r.flatSpacing;
    scallop["flat_planes"] = r.flatPlanes;
    scallop["planes"] = r.planes;
    scallop["min_spacing"] = r.minSpacing;
    scallop["max_spacing"] = r.maxSpacing;
    scallop["floor_steps"] = r.floorSteps;
    scallop["chordal_tolerance"] = r.chordalTolerance;
    Json cusp;
    cusp["max"] = number(r.cusp.max);
    cusp["p99"] = number(r.cusp.p99);
    cusp["mean"] = number(r.cusp.mean);
    cusp["samples"] = r.cusp.samples;
    cusp["pairs"] = r.cusp.pairs;
    cusp["too_tight"] = r.cusp.tooTight;
    scallop["cusp_estimate"] = cusp;
    document["scallop"] = scallop;
  }
  if (report.envelope) {
    const EnvelopeReport& e = *report.envelope;
    Json envelope;
    envelope["depth_tolerance"] = e.depthTolerance;
    envelope["vertices_lifted"] = e.verticesLifted;
    envelope["max_lift"] = e.maxLift;
    envelope["lifted_length"] = e.liftedLength;
    envelope["moves_in"] = e.movesIn;
    envelope["moves_out"] = e.movesOut;
    envelope["arcs_kept"] = e.arcsKept;
    envelope["arcs_replaced"] = e.arcsReplaced;
    envelope["proofs"] = e.proofs;
    envelope["unproven_moves"] = e.unprovenMoves;
    envelope["stretch_threshold"] = e.stretchThreshold;
    Json stretches = Json::array();
    for (const LiftedStretch& stretch : e.stretches) {
      Json item;
      item["pass"] = stretch.pass;
      item["from"] = vec(stretch.from);
      item["to"] = vec(stretch.to);
      item["length"] = stretch.length;
      item["max_lift"] = stretch.maxLift;
      stretches.push_back(std::move(item));
    }
    envelope["lifted_stretches"] = std::move(stretches);
    document["envelope"] = std::move(envelope);
  } else {
    document["envelope"] = nullptr;
  }
  if (report.verification) {
    const VerificationSummary& v = *report.verification;
    Json verification;
    verification["grid_spacing"] = v.gridSpacing;
    verification["height_error_bound"] = v.heightErrorBound;
    verification["stock_allowance"] = v.stockAllowance;
    verification["max_gouge"] = v.maxGouge;
    verification["max_gouge_at"] = v.maxGougeAt ? vec(*v.maxGougeAt) : Json(nullptr);
    verification["gouge_area"] = v.gougeArea;
    verification["gouge_tolerance"] = v.gougeTolerance;
    verification["cleared_gouge_points"] = v.clearedGougePoints;
    verification["max_cleared_gouge"] = v.maxClearedGouge;
    verification["max_scallop"] = v.maxScallop;
    verification["max_scallop_at"] = v.maxScallopAt ? vec(*v.maxScallopAt) : Json(nullptr);
    verification["scallop_p99"] = v.scallopP99;
    verification["mean_scallop"] = v.meanScallop;
    verification["uncut_area"] = v.uncutArea;
    verification["unreachable_area"] = v.unreachableArea;
    verification["unreachable_max_left"] = v.maxUnreachableLeft;
    verification["rapids_cutting"] = v.rapidsCutting;
    document["verification"] = std::move(verification);
  }
  if (report.tessellation) {
    const TessellationSummary& t = *report.tessellation;
    Json tessellation;
    tessellation["faces"] = t.faces;
    tessellation["triangles"] = t.triangles;
    tessellation["deflection"] = t.deflection;
    tessellation["deviation"] = t.deviation;
    tessellation["deviation_face"] = t.deviationFace;
    tessellation["clearance"] = t.clearance;
    tessellation["design"] = t.exactDesign ? "exact faces" : "mesh";
    document["tessellation"] = std::move(tessellation);
  }
  if (report.restFinishing) {
    Json rounds = Json::array();
    for (const RestRound& round : report.restRounds) {
      const RestReport& r = round.rest;
      Json item;
      item["max_scallop_before"] = round.maxScallopBefore;
      item["uncut_area_before"] = round.uncutAreaBefore;
      item["targets"] = r.targets;
      item["witnesses"] = r.witnesses;
      item["unreached"] = r.unreached;
      item["over_budget"] = r.overBudget;
      item["passes"] = r.passes;
      item["length"] = r.length;
      item["moves"] = r.envelope.movesOut;
      item["proofs"] = r.envelope.proofs;
      item["unproven_moves"] = r.envelope.unprovenMoves;
      rounds.push_back(std::move(item));
    }
    document["rest_finishing"] = std::move(rounds);
  } else {
    document["rest_finishing"] = nullptr;
  }
  if (report.gouge) {
    Json gouge;
    gouge["max_depth"] = report.gouge->maxDepth;
    gouge["signed_max_depth"] = report.gouge->signedMaxDepth;
    gouge["depth_bound"] = report.gouge->depthBound;
    gouge["sample_spacing"] = report.gougeSampleSpacing;
    gouge["samples"] = report.gouge->samples;
    gouge["where"] = vec(report.gouge->deepest.center);
    gouge["pass"] = report.gouge->deepest.pass;
    document["gouge"] = gouge;
  } else {
    document["gouge"] = nullptr;
  }
  if (report.orientation) {
    Json orientation;
    orientation["normal"] = vec(report.orientation->normal);
    orientation["alpha_deg"] = report.orientation->alphaRad * 180.0 / std::numbers::pi;
    orientation["certified"] = report.orientation->certified;
    orientation["boundary_segments"] = report.orientation->boundarySegments;
    document["orientation"] = orientation;
  } else {
    document["orientation"] = nullptr;
  }
  if (report.linking) {
    const LinkStats& l = *report.linking;
    Json linking;
    linking["units"] = l.units;
    linking["reversed_passes"] = l.reversedPasses;
    linking["rotated_loops"] = l.rotatedLoops;
    linking["direct_links"] = l.directLinks;
    linking["envelope_links"] = l.envelopeLinks;
    linking["local_retracts"] = l.localRetracts;
    linking["unproven_links"] = l.unprovenLinks;
    linking["strategy_links"] = l.strategyLinks;
    linking["first_plunge_shortened"] = l.firstPlungeShortened;
    linking["direct_link_length"] = l.directLinkLength;
    linking["gouge_allowance"] = l.gougeAllowance;
    linking["clearance"] = l.clearance;
    linking["plunge"] = l.plunge;
    linking["direct_link_max"] = l.directLinkMax;
    document["linking"] = linking;
  } else {
    document["linking"] = nullptr;
  }
  if (report.motion) {
    const GcodeMotion& m = *report.motion;
    Json motion;
    motion["feed_rate"] = report.feedRate;
    motion["plunge_feed_rate"] = report.plungeFeedRate;
    motion["rapid_rate"] = report.rapidRate;
    motion["feed_length"] = m.feedLength;
    motion["plunge_length"] = m.plungeLength;
    motion["rapid_length"] = m.rapidLength;
    motion["feed_minutes"] = m.feedMinutes;
    motion["plunge_minutes"] = m.plungeMinutes;
    motion["rapid_minutes"] = m.rapidMinutes;
    motion["non_cutting_minutes"] = m.plungeMinutes + m.rapidMinutes;
    motion["cycle_minutes"] = m.minutes;
    document["motion"] = motion;
  } else {
    document["motion"] = nullptr;
  }
  Json passes = Json::array();
  auto finite = [](const Vec3& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  };
  for (std::size_t i = 0; i < path.passes.size(); ++i) {
    const ToolPass& pass = path.passes[i];
    bool ok = finite(pass.start);
    for (const ToolMove& move : pass.moves) ok = ok && finite(move.end) && finite(move.center);
    if (!ok) throw Error(fmt::format("cannot write the tool path: pass {} has a position that is not finite", i));
  }
  for (std::size_t i = 0; i < path.passes.size(); ++i) {
    const ToolPass& pass = path.passes[i];
    Json p;
    p["retract_before"] = pass.retractBefore;
    if (i < report.linkMoves.size() && report.linkMoves[i] > 0) p["link_moves"] = report.linkMoves[i];
    if (pass.retract) p["retract"] = {{"height", pass.retract->height}, {"plunge", pass.retract->plunge}};
    p["start"] = vec(pass.start);
    Json moves = Json::array();
    for (const ToolMove& move : pass.moves) moves.push_back(moveJson(move));
    p["moves"] = moves;
    passes.push_back(p);
  }
  // Each pass on one line: "passes" is an array, which the layout keeps compact per element.
  document["passes"] = passes;
  return json::format(document);
}

std::string pathsSvg(const Surface& surface, const std::vector<std::vector<Vec3>>& contactCurves,
                     const ToolPath& path, const std::string& title, bool planView) {
  using svg::px;
  View view;
  if (planView) {
    view = {{1, 0, 0}, {0, 1, 0}};
  } else {
    // Looking from the front left and above (azimuth -60 degrees, elevation 30 degrees).
    const double az = -60.0 * std::numbers::pi / 180.0, el = 30.0 * std::numbers::pi / 180.0;
    const Vec3 eye{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    const Vec3 right = normalized(cross(Vec3{0, 0, 1}, eye));
    view = {right, cross(eye, right)};
  }
  // Surface iso-parameter lines, 11 each way per patch.
  std::vector<std::vector<Vec3>> iso;
  for (const BezierPatch& patch : surface.patches) {
    for (int i = 0; i <= 10; ++i) {
      std::vector<Vec3> a, b;
      for (int j = 0; j <= 40; ++j) {
        a.push_back(point(patch, i / 10.0, j / 40.0));
        b.push_back(point(patch, j / 40.0, i / 10.0));
      }
      iso.push_back(std::move(a));
      iso.push_back(std::move(b));
    }
  }
  std::vector<std::vector<Vec3>> passes;
  for (const ToolPass& pass : path.passes) passes.push_back(passPoints(pass));
  // Page frame from everything drawn.
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  using Lines = std::vector<std::vector<Vec3>>;
  for (const Lines* group : {static_cast<const Lines*>(&iso), &contactCurves, static_cast<const Lines*>(&passes)})
    for (const auto& line : *group)
      for (const Vec3& p : line) {
        const Vec2 q = view.project(p);
        x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
      }
  if (!(x1 > x0) || !(y1 > y0)) throw Error("cannot draw the tool path: nothing to draw");
  constexpr double kWidth = 900.0, kMargin = 20.0, kTop = 60.0;
  const double scale = (kWidth - 2 * kMargin) / std::max(x1 - x0, (y1 - y0) * 1.2);
  const double height = kTop + (y1 - y0) * scale + 2 * kMargin;
  auto polyline = [&](const std::vector<Vec3>& line, const char* cls) {
    std::string s = fmt::format("<polyline class=\"{}\" points=\"", cls);
    for (std::size_t i = 0; i < line.size(); ++i) {
      const Vec2 q = view.project(line[i]);
      s += fmt::format("{}{},{}", i ? " " : "", px(kMargin + (q.x - x0) * scale),
                       px(kTop + (q.y - y0) * scale));
    }
    return s + "\"/>\n";
  };
  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n"
      "<style>\n"
      "text {{ font-family: sans-serif; font-size: 13px; fill: #222222; }}\n"
      ".title {{ font-size: 15px; font-weight: bold; }}\n"
      "polyline {{ fill: none; stroke-linejoin: round; }}\n"
      ".iso {{ stroke: #b8b8b8; stroke-width: 0.6; }}\n"
      ".contact {{ stroke: #1f5fbf; stroke-width: 0.8; }}\n"
      ".centre {{ stroke: #c0392b; stroke-width: 0.8; }}\n"
      ".rapid {{ stroke: #666666; stroke-width: 0.5; stroke-dasharray: 3 3; }}\n"
      "</style>\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      px(kWidth), px(height));
  out += fmt::format("<text class=\"title\" x=\"{}\" y=\"22\">{}</text>\n", px(kMargin), escaped(title));
  out += fmt::format(
      "<text x=\"{}\" y=\"42\">{}: grey surface iso-lines, blue contact curves (sections), red "
      "tool-centre passes, dashed rapid moves</text>\n",
      px(kMargin), planView ? "plan view" : "axonometric view");
  for (const auto& line : iso) out += polyline(line, "iso");
  for (const auto& line : contactCurves) out += polyline(line, "contact");
  for (std::size_t i = 0; i < passes.size(); ++i) {
    const ToolPass& pass = path.passes[i];
    if (i > 0) {
      const Vec3 from = passes[i - 1].back();
      const Vec3 to = passes[i].front();
      if (pass.retractBefore && pass.retract) {
        // A local retract (linking.hpp): up, across at its height, down.
        const double h = pass.retract->height;
        out += polyline({from, {from.x, from.y, h}, {to.x, to.y, h}, to}, "rapid");
      } else if (pass.retractBefore) {
        out += polyline({from, to}, "rapid");
      } else if (!(from == to)) {
        out += polyline({from, to}, "centre");  // a direct feed
      }
    }
    out += polyline(passes[i], "centre");
  }
  out += "</svg>\n";
  return out;
}

}  // namespace scallop
