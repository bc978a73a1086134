#include "scallop/io/orient_output.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scallop/error.hpp"
#include "scallop/slicing/stereographic.hpp"
#include "io/json_format.hpp"
#include "io/svg_format.hpp"

namespace scallop {
namespace {

using svg::lengthLabel;
using svg::px;
using svg::roundLength;

constexpr double kPi = std::numbers::pi;

// =======================================================================================
// JSON
// =======================================================================================

// ordered_json keeps keys in the documented order instead of sorting them.
using Json = nlohmann::ordered_json;

Json vec2Json(const Vec2& v) { return Json::array({v.x, v.y}); }
Json vec3Json(const Vec3& v) { return Json::array({v.x, v.y, v.z}); }

const char* kindName(GaussMapKind kind) {
  switch (kind) {
    case GaussMapKind::region:
      return "region";
    case GaussMapKind::curve:
      return "curve";
    case GaussMapKind::point:
      return "point";
  }
  return "region";
}

Json documentJson(const OptimalSlicing& result, double toleranceDeg) {
  Json document;
  document["normal"] = vec3Json(result.normal);
  document["alpha_deg"] = toDegrees(result.alphaRad);
  document["certified"] = result.certified;
  document["certified_alpha_deg"] = toDegrees(result.certifiedAlphaRad);
  document["certificate_cells"] = result.certificateCells;
  // The polish's angle that the certificate refuted, when it did (alpha_deg is then proven).
  document["refuted_alpha_deg"] =
      result.uncertifiedAlphaRad > 0.0 ? Json(toDegrees(result.uncertifiedAlphaRad)) : Json(nullptr);
  document["method"] = slicingMethodName(result.method);
  if (result.method == SlicingMethod::medialAxis) {
    Json circle;
    circle["center"] = vec2Json(result.circle.center);
    circle["radius"] = result.circle.radius;
    document["circle"] = circle;
  } else {
    document["circle"] = nullptr;  // no medial axis, no circle in the plane
  }
  Json sphereCircle;
  sphereCircle["center"] = vec3Json(result.sphereCircle.center);
  sphereCircle["alpha_deg"] = toDegrees(result.sphereCircle.alphaRad);
  document["sphere_circle"] = sphereCircle;
  document["pole"] = vec3Json(result.pole);
  document["tolerance_deg"] = toleranceDeg;
  const GaussMap& map = result.gaussMap;
  Json gaussMap;
  gaussMap["kind"] = kindName(map.kind);
  gaussMap["loops"] = map.loops.size();
  gaussMap["boundary_segments"] = map.boundarySegments;
  gaussMap["parabolic_curves"] = map.parabolicCurves;
  gaussMap["traced_cells"] = map.tracedCells;
  gaussMap["fold_cells"] = map.foldCells;
  gaussMap["untraced_cells"] = map.untracedCells;
  gaussMap["candidate_pieces"] = map.candidatePieces;
  gaussMap["image_vertices"] = map.imageVertices;
  gaussMap["coarse_band"] = map.coarseBandUsed;
  document["gauss_map"] = gaussMap;
  Json medialAxis;
  medialAxis["edges"] = result.medialAxisEdges;
  medialAxis["rebuilds"] = result.medialAxisRebuilds;
  medialAxis["segments"] = result.medialAxisSegments;
  medialAxis["refinements"] = result.medialAxisRefinements;
  document["medial_axis"] = medialAxis;
  if (result.method == SlicingMethod::covered || result.method == SlicingMethod::lattice) {
    // The covering proof, tried because the complement came out empty.
    const NormalCoverage& coverage = result.coverage;
    Json proof;
    proof["proven"] = coverage.proven;
    proof["caps"] = coverage.caps;
    proof["cells"] = coverage.cells;
    proof["unproven_direction"] = coverage.proven ? Json(nullptr) : vec3Json(coverage.unprovenDirection);
    document["coverage"] = proof;
  } else {
    document["coverage"] = nullptr;
  }
  return document;
}

// =======================================================================================
// Figures: shared layout, labels and style
// =======================================================================================

// Page layout, in SVG pixels: a title block, then two square panels side by side, each with
// a caption above it, then a footer (scale bars and legend).
constexpr double kPanelSize = 440.0;
constexpr double kPanelGap = 40.0;
constexpr double kMargin = 20.0;
constexpr double kHeaderHeight = 80.0;   // title and two lines of subtitle
constexpr double kCaptionHeight = 26.0;  // above each panel
constexpr double kPageWidth = 2.0 * kPanelSize + kPanelGap + 2.0 * kMargin;
constexpr double kPanelTop = kHeaderHeight + kCaptionHeight;
constexpr double kLegendColumnWidth = (kPageWidth - 2.0 * kMargin) / 3.0;
constexpr double kLegendRowHeight = 22.0;

double panelLeft(int panel) { return kMargin + panel * (kPanelSize + kPanelGap); }

// Colours (colour-blind-safe: orange for the Gauss map, blue for the optimal circle) and
// stroke widths.
constexpr const char* kOmegaFill = "#f7d4b2";
constexpr const char* kOmegaEdge = "#c85200";
constexpr const char* kCircleColour = "#1a55b0";
constexpr const char* kMedialColour = "#3a9a3a";

std::string styleSheet() {
  return fmt::format(
      "<style>\n"
      "text {{ font-family: sans-serif; font-size: 13px; fill: #222222; }}\n"
      ".title {{ font-size: 15px; font-weight: bold; }}\n"
      ".subtitle {{ font-size: 13px; fill: #444444; }}\n"
      ".label {{ font-size: 12px; fill: #333333; }}\n"
      ".omega {{ fill: {0}; fill-rule: evenodd; stroke: none; }}\n"
      ".boundary {{ fill: none; stroke: {1}; stroke-width: 1.6; stroke-linejoin: round; }}\n"
      ".boundary.hidden {{ stroke-width: 1.1; stroke-opacity: 0.6; stroke-dasharray: 5 4; }}\n"
      ".circle {{ fill: none; stroke: {2}; stroke-width: 2.6; stroke-linejoin: round; }}\n"
      ".circle.hidden {{ stroke-width: 1.5; stroke-opacity: 0.65; stroke-dasharray: 7 5; }}\n"
      ".centre {{ fill: {2}; stroke: #ffffff; stroke-width: 1; }}\n"
      ".medial {{ fill: none; stroke: {3}; stroke-width: 0.7; stroke-opacity: 0.85; }}\n"
      ".unit {{ fill: none; stroke: #555555; stroke-width: 1.1; stroke-dasharray: 6 4; }}\n"
      ".axis {{ fill: none; stroke: #9a9a9a; stroke-width: 0.8; }}\n"
      ".axis.hidden {{ stroke-dasharray: 2 2; }}\n"
      ".sphere {{ fill: #fcfcfc; stroke: #444444; stroke-width: 1.3; }}\n"
      ".grid {{ fill: none; stroke: #c4c4c4; stroke-width: 0.7; }}\n"
      ".frame {{ fill: none; stroke: #888888; stroke-width: 0.8; }}\n"
      ".zoom {{ fill: none; stroke: #222222; stroke-width: 1.2; stroke-dasharray: 3 3; }}\n"
      ".mark {{ fill: none; stroke: #222222; stroke-width: 1.5; }}\n"
      ".scale line {{ stroke: #222222; stroke-width: 1.5; }}\n"
      "</style>\n",
      kOmegaFill, kOmegaEdge, kCircleColour, kMedialColour);
}

// An angle in degrees for a label: three decimals, fixed-point.
std::string degreesLabel(double radians) {
  const std::string text = fmt::format("{:.3f}\u00b0", toDegrees(radians));
  return text.rfind("-0.000", 0) == 0 ? text.substr(1) : text;
}

// A coordinate for a label: `decimals` places, fixed-point, with a true minus sign and no
// "-0".
std::string coordinateLabel(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.front() == '-') {
    const bool zero = text.find_first_not_of("-0.") == std::string::npos;
    text = zero ? text.substr(1) : std::string("\u2212").append(text, 1);
  }
  return text;
}

std::string vectorLabel(const Vec3& v, int decimals = 4) {
  return fmt::format("({}, {}, {})", coordinateLabel(v.x, decimals),
                     coordinateLabel(v.y, decimals), coordinateLabel(v.z, decimals));
}

std::string certificateLabel(const OptimalSlicing& result) {
  if (result.certified) {
    return fmt::format("Certified: no surface normal within {} of \u00b1N* ({} cells)",
                       degreesLabel(result.certifiedAlphaRad), result.certificateCells);
  }
  return result.certificateCells == 0 ? std::string("Certificate not run")
                                      : std::string("Not certified");
}

std::string pageStart(double pageHeight, const std::string& title) {
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\">\n",
      px(kPageWidth), px(pageHeight));
  svg += fmt::format("<title>{}</title>\n", title);
  svg += styleSheet();
  svg += fmt::format("<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>\n",
                     px(kPageWidth), px(pageHeight));
  return svg;
}

std::string heading(const std::string& title, const std::array<std::string, 2>& subtitle) {
  return fmt::format(
      "<text class=\"title\" x=\"{0}\" y=\"24\">{1}</text>\n"
      "<text class=\"subtitle\" x=\"{0}\" y=\"46\">{2}</text>\n"
      "<text class=\"subtitle\" x=\"{0}\" y=\"64\">{3}</text>\n",
      px(kMargin), title, subtitle[0], subtitle[1]);
}

std::string caption(int panel, const std::string& text) {
  return fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", px(panelLeft(panel)),
                     px(kPanelTop - 9.0), text);
}

struct LegendEntry {
  std::string label;
  std::string swatch;  // drawn in a 28 x 12 box whose top-left is (0, 0)
};

// Rows of three entries, from `top`; returns the SVG and sets `bottom` below the last row.
std::string legend(const std::vector<LegendEntry>& entries, double top, double& bottom) {
  std::string out = "<g class=\"legend\">\n";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double x = kMargin + static_cast<double>(i % 3) * kLegendColumnWidth;
    const double y = top + static_cast<double>(i / 3) * kLegendRowHeight;
    out +=
        fmt::format("<g transform=\"translate({},{})\">{}<text x=\"36\" y=\"11\">{}</text></g>\n",
                    px(x), px(y), entries[i].swatch, entries[i].label);
  }
  bottom = top + static_cast<double>((entries.size() + 2) / 3) * kLegendRowHeight;
  return out + "</g>\n";
}

const char* kLineSwatch = "x1=\"0\" y1=\"6\" x2=\"28\" y2=\"6\"";

std::string lineSwatch(const char* cssClass) {
  return fmt::format("<line class=\"{}\" {}/>", cssClass, kLineSwatch);
}

std::string filledSwatch() {
  return "<rect class=\"omega\" x=\"0\" y=\"0\" width=\"28\" height=\"12\"/>"
         "<rect class=\"boundary\" x=\"0\" y=\"0\" width=\"28\" height=\"12\"/>";
}

std::string centreSwatch() { return "<circle class=\"centre\" cx=\"14\" cy=\"6\" r=\"4\"/>"; }

// Even-odd rule: whether `p` is inside an odd number of the closed polygons.
bool evenOddContains(const std::vector<std::vector<Vec2>>& polygons, const Vec2& p) {
  bool inside = false;
  for (const std::vector<Vec2>& polygon : polygons) {
    const std::size_t n = polygon.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
      const Vec2& a = polygon[i];
      const Vec2& b = polygon[j];
      if ((a.y > p.y) != (b.y > p.y) &&
          p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)) {
        inside = !inside;
      }
    }
  }
  return inside;
}

// Every number the figures draw comes from these; a non-finite one is an upstream bug.
void requireFinite(const OptimalSlicing& result) {
  auto finite3 = [](const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  auto finite2 = [](const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); };
  bool ok = finite3(result.normal) && std::isfinite(result.alphaRad) &&
            finite3(result.sphereCircle.center) && std::isfinite(result.sphereCircle.alphaRad) &&
            finite3(result.pole) && finite2(result.circle.center) &&
            std::isfinite(result.circle.radius) && norm(result.normal) > 0.0;
  for (const auto& loop : result.gaussMap.loops) {
    for (const Vec2& p : loop) ok = ok && finite2(p);
  }
  for (const auto& curve : result.gaussMap.sphereCurves) {
    for (const Vec3& p : curve) ok = ok && finite3(p);
  }
  for (const auto& curve : result.medialAxisCurves) {
    for (const Vec2& p : curve) ok = ok && finite2(p);
  }
  if (!ok) throw Error("cannot draw the slicing orientation: a coordinate is not finite");
}

// A unit vector orthogonal to the unit vector n.
Vec3 anyOrthogonal(const Vec3& n) {
  const Vec3 helper = std::abs(n.x) < 0.6 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  return normalized(cross(n, helper));
}

// The boundary loops of Omega carried back to the unit sphere (original frame), closed.
std::vector<std::vector<Vec3>> loopsOnSphere(const GaussMap& map) {
  const Rotation3 back = transpose(map.toPoleFrame);
  std::vector<std::vector<Vec3>> loops;
  for (const std::vector<Vec2>& loop : map.loops) {
    if (loop.size() < 3) continue;
    std::vector<Vec3> points;
    for (const Vec2& q : loop) points.push_back(apply(back, inverseStereographic(q)));
    points.push_back(points.front());
    loops.push_back(std::move(points));
  }
  return loops;
}

// Whether the unit vector `direction` lies in Omega: in the pole frame's plane, the
// complement is the even-odd interior of the loops; the pole itself (a surface normal) maps
// to infinity and is in Omega.
bool inOmega(const GaussMap& map, const Vec3& direction) {
  const Vec3 q = apply(map.toPoleFrame, direction);
  if (q.x == 0.0 && q.y == 0.0 && q.z > 0.0) return true;
  const Vec2 p = stereographic(q);
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return true;
  return !evenOddContains(map.loops, p);
}

// =======================================================================================
// The sphere (Figs 3, 5, 10, 12)
// =======================================================================================

constexpr double kSphereRadius = 200.0;          // pixels
constexpr double kMaxStepRad = kPi / 180.0;      // curves resampled to 1 degree
constexpr double kTiltRad = kPi / 4.0;           // views tilted 45 degrees from N*

// An orthographic view of the unit sphere: the viewer looks along -toViewer; `right` and
// `up` span the picture plane (right x up = toViewer).
struct SphereView {
  Vec3 toViewer;
  Vec3 right;
  Vec3 up;
  double cx = 0.0;  // page position of the sphere's centre
  double cy = 0.0;

  double depth(const Vec3& v) const { return dot(v, toViewer); }
  Vec2 page(const Vec3& v) const {
    return {cx + kSphereRadius * dot(v, right), cy - kSphereRadius * dot(v, up)};
  }
  // A hidden point pushed radially onto the sphere's outline (its direction on the page).
  Vec2 onOutline(const Vec3& v) const {
    const double a = dot(v, right);
    const double b = dot(v, up);
    const double length = std::hypot(a, b);
    if (length == 0.0) return {cx + kSphereRadius, cy};  // straight behind: any outline point
    return {cx + kSphereRadius * a / length, cy - kSphereRadius * b / length};
  }
};

// The two views: both have N* in front, tilted by kTiltRad towards the pole p (a surface
// normal) and towards -p respectively, so that each shows the circle against one side of
// Omega. Both share the `right` axis: the second is the first turned about it.
std::array<SphereView, 2> sphereViews(const OptimalSlicing& result) {
  const Vec3 n = normalized(result.normal);
  Vec3 towardPole = result.pole - dot(result.pole, n) * n;
  towardPole = norm(towardPole) > 1e-9 ? normalized(towardPole) : anyOrthogonal(n);
  const double c = std::cos(kTiltRad);
  const double s = std::sin(kTiltRad);
  std::array<SphereView, 2> views;
  for (int i = 0; i < 2; ++i) {
    const double sign = i == 0 ? 1.0 : -1.0;
    SphereView& view = views[static_cast<std::size_t>(i)];
    view.toViewer = normalized(c * n + sign * s * towardPole);
    view.up = normalized(c * towardPole - sign * s * n);
    view.right = cross(view.up, view.toViewer);
    view.cx = panelLeft(i) + 0.5 * kPanelSize;
    view.cy = kPanelTop + 0.5 * kPanelSize;
  }
  return views;
}

// Points along the great-circle arcs between consecutive points, at most kMaxStepRad apart
// (so that visibility changes are found to a degree, and chords stay close to the sphere).
std::vector<Vec3> resampled(const std::vector<Vec3>& curve) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const Vec3 b = normalized(curve[i]);
    if (i > 0) {
      const Vec3 a = out.back();
      const double angle = std::atan2(norm(cross(a, b)), dot(a, b));
      const int steps = std::min(720, static_cast<int>(std::ceil(angle / kMaxStepRad)));
      for (int k = 1; k < steps && angle < kPi - 1e-6; ++k) {
        const double t = static_cast<double>(k) / steps;
        out.push_back(normalized((1.0 - t) * a + t * b));
      }
    }
    out.push_back(b);
  }
  return out;
}

struct SphereRun {
  bool visible = true;
  std::vector<Vec3> points;
};

// `curve` cut where it crosses the outline (depth 0) into visible and hidden runs; the
// crossing point ends one run and starts the next.
std::vector<SphereRun> splitAtOutline(const std::vector<Vec3>& curve, const SphereView& view) {
  const std::vector<Vec3> points = resampled(curve);
  std::vector<SphereRun> runs;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const bool visible = view.depth(points[i]) >= 0.0;
    if (runs.empty()) {
      runs.push_back({visible, {points[i]}});
    } else if (visible == runs.back().visible) {
      runs.back().points.push_back(points[i]);
    } else {
      const Vec3& a = points[i - 1];
      const double da = view.depth(a);
      const double db = view.depth(points[i]);
      const Vec3 crossing = normalized(a + (da / (da - db)) * (points[i] - a));
      runs.back().points.push_back(crossing);
      runs.push_back({visible, {crossing, points[i]}});
    }
  }
  return runs;
}

std::string pathData(const std::vector<Vec2>& points, bool closed) {
  std::string d;
  for (std::size_t i = 0; i < points.size(); ++i) {
    d += i == 0 ? "M " : i == 1 ? " L " : " ";
    d += px(points[i].x);
    d += ',';
    d += px(points[i].y);
  }
  if (closed && !d.empty()) d += " Z";
  return d;
}

// The runs of `curves` of the given visibility, as one path element (empty if none).
std::string curvesElement(const std::vector<std::vector<Vec3>>& curves, const SphereView& view,
                          bool visible, const char* cssClass) {
  std::string d;
  for (const std::vector<Vec3>& curve : curves) {
    for (const SphereRun& run : splitAtOutline(curve, view)) {
      if (run.visible != visible || run.points.size() < 2) continue;
      std::vector<Vec2> page;
      for (const Vec3& p : run.points) page.push_back(view.page(p));
      if (!d.empty()) d += ' ';
      d += pathData(page, false);
    }
  }
  if (d.empty()) return {};
  return fmt::format("<path class=\"{}\" d=\"{}\"/>\n", cssClass, d);
}

// A hidden run pushed onto the outline, following the outline between consecutive points
// (near the point straight behind, one step on the sphere may turn far around it; the
// shorter way round is taken) so that no chord cuts across the disk.
void appendAlongOutline(const std::vector<Vec3>& run, const SphereView& view,
                        std::vector<Vec2>& polygon) {
  constexpr double kOutlineStepRad = 2.0 * kPi / 180.0;
  double previous = 0.0;
  bool started = false;
  for (const Vec3& v : run) {
    const double a = dot(v, view.right);
    const double b = dot(v, view.up);
    if (a == 0.0 && b == 0.0) continue;  // straight behind: no direction
    const double angle = std::atan2(b, a);
    if (started) {
      const double turn = std::remainder(angle - previous, 2.0 * kPi);
      const int steps = static_cast<int>(std::ceil(std::abs(turn) / kOutlineStepRad));
      for (int k = 1; k < steps; ++k) {
        const double t = previous + turn * k / steps;
        polygon.push_back({view.cx + kSphereRadius * std::cos(t),
                           view.cy - kSphereRadius * std::sin(t)});
      }
    }
    polygon.push_back(view.onOutline(v));
    previous = angle;
    started = true;
  }
}

// The visible part of Omega, shaded. Each boundary loop becomes a closed page polygon: its
// visible runs as they are, its hidden runs pushed onto the outline. Inside the sphere's
// disk, the even-odd parity of these polygons differs from membership in Omega by a
// constant (a path between two visible points crosses the same visible boundary pieces in
// both), found at the disk's centre; when it is 1 the outline is added as one more
// polygon, which flips the parity everywhere inside.
std::string omegaFill(const OptimalSlicing& result, const SphereView& view,
                      const std::string& clipId) {
  std::vector<std::vector<Vec2>> polygons;
  for (const std::vector<Vec3>& loop : loopsOnSphere(result.gaussMap)) {
    std::vector<Vec2> polygon;
    for (const SphereRun& run : splitAtOutline(loop, view)) {
      if (run.visible) {
        for (const Vec3& p : run.points) polygon.push_back(view.page(p));
      } else {
        appendAlongOutline(run.points, view, polygon);
      }
    }
    polygons.push_back(std::move(polygon));
  }
  // No loops: Omega has no complement left within its tolerance (methods covered and
  // lattice), so the whole visible hemisphere is Omega.
  if (polygons.empty() && !inOmega(result.gaussMap, view.toViewer)) return {};
  std::string d;
  for (const std::vector<Vec2>& polygon : polygons) d += pathData(polygon, true) + " ";
  const bool parity = evenOddContains(polygons, {view.cx, view.cy});
  if (parity != inOmega(result.gaussMap, view.toViewer)) {
    d += fmt::format("M {0},{1} A {2} {2} 0 1 0 {3},{1} A {2} {2} 0 1 0 {0},{1} Z",
                     px(view.cx - kSphereRadius), px(view.cy), px(kSphereRadius),
                     px(view.cx + kSphereRadius));
  }
  return fmt::format("<path class=\"omega\" clip-path=\"url(#{})\" fill-opacity=\"0.8\" d=\"{}\"/>\n",
                     clipId, d);
}

// The equator and six meridians of the original frame (z up), visible parts only.
std::string graticule(const SphereView& view) {
  std::vector<std::vector<Vec3>> circles;
  std::vector<Vec3> equator;
  for (int k = 0; k <= 180; ++k) {
    const double t = 2.0 * kPi * k / 180.0;
    equator.push_back({std::cos(t), std::sin(t), 0.0});
  }
  circles.push_back(std::move(equator));
  for (int m = 0; m < 6; ++m) {
    const double longitude = kPi * m / 6.0;
    std::vector<Vec3> meridian;
    for (int k = 0; k <= 180; ++k) {
      const double t = 2.0 * kPi * k / 180.0;
      meridian.push_back({std::cos(longitude) * std::sin(t), std::sin(longitude) * std::sin(t),
                          std::cos(t)});
    }
    circles.push_back(std::move(meridian));
  }
  return curvesElement(circles, view, true, "grid");
}

// The optimal circle {m : c . m = cos(alpha)}, sampled every degree.
std::vector<Vec3> circleOnSphere(const SphereCircle& circle) {
  const Vec3 c = normalized(circle.center);
  const Vec3 e1 = anyOrthogonal(c);
  const Vec3 e2 = cross(c, e1);
  std::vector<Vec3> points;
  for (int k = 0; k <= 360; ++k) {
    const double t = 2.0 * kPi * k / 360.0;
    points.push_back(std::cos(circle.alphaRad) * c +
                     std::sin(circle.alphaRad) * (std::cos(t) * e1 + std::sin(t) * e2));
  }
  return points;
}

// A labelled point on the sphere: filled dot in front, nothing behind.
std::string sphereMark(const SphereView& view, const Vec3& v, const std::string& label,
                       bool strong) {
  if (view.depth(v) < 0.0) return {};
  const Vec2 p = view.page(v);
  std::string out =
      strong ? fmt::format("<circle class=\"centre\" cx=\"{}\" cy=\"{}\" r=\"4.5\"/>\n", px(p.x),
                           px(p.y))
             : fmt::format("<path class=\"mark\" d=\"M {} {} L {} {} M {} {} L {} {}\"/>\n",
                           px(p.x - 4.0), px(p.y - 4.0), px(p.x + 4.0), px(p.y + 4.0),
                           px(p.x - 4.0), px(p.y + 4.0), px(p.x + 4.0), px(p.y - 4.0));
  out += fmt::format("<text class=\"label\" x=\"{}\" y=\"{}\"{}>{}</text>\n", px(p.x + 7.0),
                     px(p.y - 6.0), strong ? " font-weight=\"bold\"" : "", label);
  return out;
}

// The directions of the original x, y, z axes, in the panel's bottom-left corner (dashed
// when pointing away from the viewer).
std::string axisTriad(const SphereView& view, int panel) {
  const double ox = panelLeft(panel) + 30.0;
  const double oy = kPanelTop + kPanelSize - 30.0;
  std::string out;
  const std::array<std::pair<Vec3, const char*>, 3> axes = {
      {{{1.0, 0.0, 0.0}, "x"}, {{0.0, 1.0, 0.0}, "y"}, {{0.0, 0.0, 1.0}, "z"}}};
  std::vector<Vec2> labels;
  for (const auto& [axis, name] : axes) {
    const double a = dot(axis, view.right);
    const double b = dot(axis, view.up);
    out += fmt::format("<line class=\"axis{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n",
                       view.depth(axis) < 0.0 ? " hidden" : "", px(ox), px(oy),
                       px(ox + 22.0 * a), px(oy - 22.0 * b));
    // Beyond the tip; an axis seen nearly end-on puts its label beside the origin, moved
    // along until it clears the labels already placed.
    Vec2 label{ox + 30.0 * a, oy - 30.0 * b};
    for (int tries = 0; tries < 4; ++tries) {
      const bool clear = std::none_of(labels.begin(), labels.end(), [&](const Vec2& other) {
        return norm(other - label) < 11.0;
      });
      if (clear) break;
      label.x += 11.0;
    }
    labels.push_back(label);
    out += fmt::format(
        "<text class=\"label\" x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
        px(label.x), px(label.y + 4.0), name);
  }
  return out;
}

std::string spherePanel(const OptimalSlicing& result, const SphereView& view, int panel) {
  const GaussMap& map = result.gaussMap;
  const std::string clipId = fmt::format("sphere{}", panel);
  std::string out = fmt::format(
      "<defs><clipPath id=\"{}\"><circle cx=\"{}\" cy=\"{}\" r=\"{}\"/></clipPath></defs>\n",
      clipId, px(view.cx), px(view.cy), px(kSphereRadius));
  out += fmt::format("<circle class=\"sphere\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", px(view.cx),
                     px(view.cy), px(kSphereRadius));
  const std::vector<std::vector<Vec3>> circle = {circleOnSphere(result.sphereCircle)};
  // Far side first, then Omega's visible part shaded over it, then the near side.
  out += curvesElement(map.sphereCurves, view, false, "boundary hidden");
  out += curvesElement(circle, view, false, "circle hidden");
  if (map.kind == GaussMapKind::region) out += omegaFill(result, view, clipId);
  out += graticule(view);
  // The boundary over the (wider) circle, so that where they touch both show.
  out += curvesElement(circle, view, true, "circle");
  out += curvesElement(map.sphereCurves, view, true, "boundary");
  out += sphereMark(view, result.pole, "p", false);
  out += sphereMark(view, -result.pole, "\u2212p", false);
  out += sphereMark(view, normalized(result.normal), "N*", true);
  out += axisTriad(view, panel);
  return out;
}

// =======================================================================================
// The stereographic plane (Figs 4, 11)
// =======================================================================================

constexpr double kPlanePadding = 0.06;    // around the drawing, fraction of its extent
constexpr double kClipMargin = 0.25;      // geometry kept this far beyond the panel
constexpr double kZoomPadding = 1.15;     // zoom half-width / innermost loop's extent
constexpr double kMaxZoom = 1000.0;       // second panel's scale / first panel's, at most
constexpr double kScaleBarTarget = 120.0;  // preferred scale bar length, pixels

struct Box {
  double minX = std::numeric_limits<double>::infinity();
  double maxX = -std::numeric_limits<double>::infinity();
  double minY = std::numeric_limits<double>::infinity();
  double maxY = -std::numeric_limits<double>::infinity();

  void add(const Vec2& p) {
    minX = std::min(minX, p.x);
    maxX = std::max(maxX, p.x);
    minY = std::min(minY, p.y);
    maxY = std::max(maxY, p.y);
  }
  void addCircle(const Vec2& c, double r) {
    add({c.x - r, c.y - r});
    add({c.x + r, c.y + r});
  }
};

// A square window of the plane (x right, y up) drawn in a panel (page y down).
struct PlaneView {
  Vec2 centre;
  double halfWidth = 1.0;
  double left = 0.0;  // page position of the panel's top-left corner
  double top = 0.0;

  double scale() const { return kPanelSize / (2.0 * halfWidth); }
  double x(double worldX) const { return left + (worldX - centre.x + halfWidth) * scale(); }
  double y(double worldY) const { return top + (centre.y + halfWidth - worldY) * scale(); }
  Vec2 page(const Vec2& p) const { return {x(p.x), y(p.y)}; }
  // Geometry is clipped to this box before it is written, so that a loop a thousand times
  // larger than a zoomed panel costs no more than one that fits.
  Box clipBox() const {
    const double h = (1.0 + kClipMargin) * halfWidth;
    return {centre.x - h, centre.x + h, centre.y - h, centre.y + h};
  }
};

// The signed distances of p from the four sides of `box` (>= 0 inside).
double sideDistance(const Box& box, int side, const Vec2& p) {
  switch (side) {
    case 0:
      return p.x - box.minX;
    case 1:
      return box.maxX - p.x;
    case 2:
      return p.y - box.minY;
    default:
      return box.maxY - p.y;
  }
}

Vec2 sideCrossing(const Box& box, int side, const Vec2& a, const Vec2& b) {
  const double da = sideDistance(box, side, a);
  const double db = sideDistance(box, side, b);
  return a + (da / (da - db)) * (b - a);
}

// Sutherland-Hodgman: the closed polygon clipped to the box. For a non-convex polygon the
// result may run along the box's sides, outside the panel; the area it encloses inside the
// box (even-odd) is exact.
std::vector<Vec2> clipPolygon(std::vector<Vec2> polygon, const Box& box) {
  for (int side = 0; side < 4 && !polygon.empty(); ++side) {
    std::vector<Vec2> kept;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const Vec2& current = polygon[i];
      const Vec2& previous = polygon[(i + polygon.size() - 1) % polygon.size()];
      const bool currentIn = sideDistance(box, side, current) >= 0.0;
      const bool previousIn = sideDistance(box, side, previous) >= 0.0;
      if (currentIn != previousIn) kept.push_back(sideCrossing(box, side, previous, current));
      if (currentIn) kept.push_back(current);
    }
    polygon = std::move(kept);
  }
  return polygon;
}

// The open polyline clipped to the box, as the pieces that remain.
std::vector<std::vector<Vec2>> clipPolyline(const std::vector<Vec2>& polyline, const Box& box) {
  std::vector<std::vector<Vec2>> pieces;
  for (std::size_t i = 1; i < polyline.size(); ++i) {
    Vec2 a = polyline[i - 1];
    Vec2 b = polyline[i];
    bool inside = true;
    for (int side = 0; side < 4 && inside; ++side) {
      const bool aIn = sideDistance(box, side, a) >= 0.0;
      const bool bIn = sideDistance(box, side, b) >= 0.0;
      if (!aIn && !bIn) {
        inside = false;
      } else if (!aIn) {
        a = sideCrossing(box, side, a, b);
      } else if (!bIn) {
        b = sideCrossing(box, side, a, b);
      }
    }
    if (!inside) continue;
    if (pieces.empty() || !(pieces.back().back() == a)) pieces.push_back({a});
    pieces.back().push_back(b);
  }
  return pieces;
}

double largestRadius(const std::vector<Vec2>& loop) {
  double r = 0.0;
  for (const Vec2& p : loop) r = std::max(r, norm(p));
  return r;
}

// What the plane picture draws as Omega's boundary: the loops, or, for a Gauss image of
// dimension < 2, its curves carried into the pole frame (broken where they reach the pole,
// whose image is at infinity).
struct PlaneGeometry {
  std::vector<std::vector<Vec2>> loops;   // closed
  std::vector<std::vector<Vec2>> curves;  // open
};

PlaneGeometry planeGeometry(const GaussMap& map) {
  PlaneGeometry geometry;
  if (map.kind == GaussMapKind::region) {
    for (const std::vector<Vec2>& loop : map.loops) {
      if (loop.size() >= 3) geometry.loops.push_back(loop);
    }
    return geometry;
  }
  for (const std::vector<Vec3>& curve : map.sphereCurves) {
    std::vector<Vec2> piece;
    for (const Vec3& v : curve) {
      const Vec3 q = normalized(apply(map.toPoleFrame, v));
      if (q.z > 1.0 - 1e-12) {
        if (piece.size() >= 2) geometry.curves.push_back(piece);
        piece.clear();
        continue;
      }
      piece.push_back(stereographic(q));
    }
    if (piece.size() >= 2) geometry.curves.push_back(piece);
  }
  return geometry;
}

// The window of the first panel: everything but the (distant) images of open curves.
PlaneView wholeView(const OptimalSlicing& result, const PlaneGeometry& geometry) {
  Box box;
  box.addCircle({0.0, 0.0}, 1.0);  // the unit circle
  for (const auto& loop : geometry.loops) {
    for (const Vec2& p : loop) box.add(p);
  }
  for (const auto& curve : geometry.curves) {
    for (const Vec2& p : curve) {
      if (norm(p) < 4.0) box.add(p);
    }
  }
  if (result.method == SlicingMethod::medialAxis) box.addCircle(result.circle.center, result.circle.radius);
  PlaneView view;
  view.centre = {0.5 * (box.minX + box.maxX), 0.5 * (box.minY + box.maxY)};
  view.halfWidth = 0.5 * std::max(box.maxX - box.minX, box.maxY - box.minY) * (1.0 + 2.0 * kPlanePadding);
  view.left = panelLeft(0);
  view.top = kPanelTop;
  return view;
}

// The window of the second panel: centred on the origin (the image of -p), fitted to the
// innermost loop around it (the boundary of the part of Omega around -p); without one, to
// the nearest loop point; without loops, to the unit circle. At most kMaxZoom times the
// first panel's scale.
PlaneView zoomView(const PlaneGeometry& geometry, const PlaneView& whole) {
  double extent = std::numeric_limits<double>::infinity();
  for (const std::vector<Vec2>& loop : geometry.loops) {
    if (evenOddContains({loop}, {0.0, 0.0})) extent = std::min(extent, largestRadius(loop));
  }
  if (!std::isfinite(extent)) {
    for (const std::vector<Vec2>& loop : geometry.loops) {
      for (const Vec2& p : loop) extent = std::min(extent, norm(p));
    }
  }
  if (!std::isfinite(extent)) extent = 1.0;
  PlaneView view;
  view.halfWidth = std::max(kZoomPadding * extent, whole.halfWidth / kMaxZoom);
  view.left = panelLeft(1);
  view.top = kPanelTop;
  return view;
}

std::string pathOfPieces(const std::vector<std::vector<Vec2>>& pieces, const PlaneView& view,
                         bool closed) {
  std::string d;
  for (const std::vector<Vec2>& piece : pieces) {
    if (piece.size() < 2) continue;
    std::vector<Vec2> page;
    for (const Vec2& p : piece) page.push_back(view.page(p));
    if (!d.empty()) d += ' ';
    d += pathData(page, closed);
  }
  return d;
}

std::string planePanel(const OptimalSlicing& result, const PlaneGeometry& geometry,
                       const PlaneView& view, int panel, const PlaneView* zoom) {
  const std::string clipId = fmt::format("plane{}", panel);
  const Box clip = view.clipBox();
  std::string out = fmt::format(
      "<defs><clipPath id=\"{}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>"
      "</clipPath></defs>\n<g clip-path=\"url(#{})\">\n",
      clipId, px(view.left), px(view.top), px(kPanelSize), px(kPanelSize), clipId);

  // Omega shaded: the clip box plus every loop, even-odd, fills exactly the points inside
  // an even number of loops (the complement is the odd interior).
  std::vector<std::vector<Vec2>> loops;
  for (const std::vector<Vec2>& loop : geometry.loops) {
    std::vector<Vec2> clipped = clipPolygon(loop, clip);
    if (clipped.size() >= 3) loops.push_back(std::move(clipped));
  }
  if (result.gaussMap.kind == GaussMapKind::region) {
    const std::vector<std::vector<Vec2>> frame = {{{clip.minX, clip.minY},
                                                   {clip.maxX, clip.minY},
                                                   {clip.maxX, clip.maxY},
                                                   {clip.minX, clip.maxY}}};
    std::string d = pathOfPieces(frame, view, true);
    if (!loops.empty()) {
      d += ' ';
      d += pathOfPieces(loops, view, true);
    }
    out += fmt::format("<path class=\"omega\" d=\"{}\"/>\n", d);
  }

  // Axes through the origin.
  out += fmt::format(
      "<path class=\"axis\" d=\"M {} {} L {} {} M {} {} L {} {}\"/>\n", px(view.x(clip.minX)),
      px(view.y(0.0)), px(view.x(clip.maxX)), px(view.y(0.0)), px(view.x(0.0)),
      px(view.y(clip.minY)), px(view.x(0.0)), px(view.y(clip.maxY)));

  // Medial axis, thin, under the boundary.
  std::vector<std::vector<Vec2>> medial;
  for (const std::vector<Vec2>& curve : result.medialAxisCurves) {
    for (std::vector<Vec2>& piece : clipPolyline(curve, clip)) medial.push_back(std::move(piece));
  }
  if (!medial.empty()) {
    out += fmt::format("<path class=\"medial\" d=\"{}\"/>\n", pathOfPieces(medial, view, false));
  }

  if (!loops.empty()) {
    out += fmt::format("<path class=\"boundary\" d=\"{}\"/>\n", pathOfPieces(loops, view, true));
  }
  std::vector<std::vector<Vec2>> curves;
  for (const std::vector<Vec2>& curve : geometry.curves) {
    for (std::vector<Vec2>& piece : clipPolyline(curve, clip)) curves.push_back(std::move(piece));
  }
  if (!curves.empty()) {
    out += fmt::format("<path class=\"boundary\" d=\"{}\"/>\n", pathOfPieces(curves, view, false));
  }

  out += fmt::format("<circle class=\"unit\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", px(view.x(0.0)),
                     px(view.y(0.0)), px(view.scale()));
  if (result.method == SlicingMethod::medialAxis) {
    const Vec2 c = view.page(result.circle.center);
    out += fmt::format("<circle class=\"circle\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", px(c.x),
                       px(c.y), px(result.circle.radius * view.scale()));
    out += fmt::format("<circle class=\"centre\" cx=\"{}\" cy=\"{}\" r=\"4\"/>\n", px(c.x),
                       px(c.y));
  }
  // The origin: the image of -p.
  const double ox = view.x(0.0);
  const double oy = view.y(0.0);
  out += fmt::format("<path class=\"mark\" d=\"M {} {} L {} {} M {} {} L {} {}\"/>\n",
                     px(ox - 4.0), px(oy - 4.0), px(ox + 4.0), px(oy + 4.0), px(ox - 4.0),
                     px(oy + 4.0), px(ox + 4.0), px(oy - 4.0));
  out += fmt::format("<text class=\"label\" x=\"{}\" y=\"{}\">0</text>\n", px(ox + 5.0),
                     px(oy + 15.0));
  if (zoom != nullptr) {
    // The second panel's window, at least a few pixels wide so that it can be found.
    const double half = std::max(zoom->halfWidth * view.scale(), 4.0);
    out += fmt::format("<rect class=\"zoom\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n",
                       px(ox - half), px(oy - half), px(2.0 * half), px(2.0 * half));
  }
  out += "</g>\n";

  out += fmt::format("<rect class=\"frame\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n",
                     px(view.left), px(view.top), px(kPanelSize), px(kPanelSize));
  // Axis names at the panel's edges, where the axes leave it.
  const double right = view.left + kPanelSize;
  const double bottom = view.top + kPanelSize;
  if (oy > view.top + 12.0 && oy < bottom - 4.0) {
    out += fmt::format("<text class=\"label\" x=\"{}\" y=\"{}\" text-anchor=\"end\">x</text>\n",
                       px(right - 5.0), px(oy - 5.0));
  }
  if (ox > view.left + 4.0 && ox < right - 12.0) {
    out += fmt::format("<text class=\"label\" x=\"{}\" y=\"{}\">y</text>\n", px(ox + 5.0),
                       px(view.top + 14.0));
  }
  return out;
}

std::string planeScaleBar(const PlaneView& view) {
  const double length = roundLength(kScaleBarTarget / view.scale());
  const double left = view.left;
  const double right = left + length * view.scale();
  const double y = view.top + kPanelSize + 20.0;
  return fmt::format(
      "<g class=\"scale\">\n"
      "<line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\"/>\n"
      "<line x1=\"{0}\" y1=\"{3}\" x2=\"{0}\" y2=\"{4}\"/>\n"
      "<line x1=\"{1}\" y1=\"{3}\" x2=\"{1}\" y2=\"{4}\"/>\n"
      "<text x=\"{5}\" y=\"{6}\">{7}</text>\n"
      "</g>\n",
      px(left), px(right), px(y), px(y - 5.0), px(y + 5.0), px(right + 8.0), px(y + 4.5),
      lengthLabel(length));
}

}  // namespace

// =======================================================================================
// Front doors
// =======================================================================================

std::string orientationToJson(const OptimalSlicing& result, double toleranceDeg) {
  return json::format(documentJson(result, toleranceDeg));
}

std::string trimmedOrientationToJson(const OptimalSlicing& result, double toleranceDeg, const TrimmedFacts& facts) {
  Json document = documentJson(result, toleranceDeg);
  Json trimmed;
  trimmed["faces"] = facts.faces;
  trimmed["inside_pieces"] = facts.insidePieces;
  trimmed["boundary_pieces"] = facts.boundaryPieces;
  trimmed["spread_deg"] = toDegrees(facts.spreadRad);
  trimmed["largest_spread_deg"] = toDegrees(facts.largestSpreadRad);
  trimmed["alpha_lower_deg"] = toDegrees(result.certified ? result.certifiedAlphaRad : result.alphaRad);
  if (facts.inside != nullptr) {
    // Without a complement and without a covering proof the inside pieces bound nothing.
    const bool bounds = facts.inside->method != SlicingMethod::open && facts.inside->method != SlicingMethod::lattice;
    trimmed["alpha_upper_deg"] = bounds ? Json(toDegrees(facts.inside->alphaRad)) : Json(nullptr);
    trimmed["upper_method"] = slicingMethodName(facts.inside->method);
    trimmed["upper_normal"] = {facts.inside->normal.x, facts.inside->normal.y, facts.inside->normal.z};
  } else {
    trimmed["alpha_upper_deg"] = nullptr;
    trimmed["upper_method"] = nullptr;
    trimmed["upper_normal"] = nullptr;
  }
  document["trimmed"] = std::move(trimmed);
  return json::format(document);
}

std::string gaussMapSphereSvg(const OptimalSlicing& result) {
  requireFinite(result);
  const std::array<SphereView, 2> views = sphereViews(result);
  const bool region = result.gaussMap.kind == GaussMapKind::region;

  std::vector<LegendEntry> entries;
  if (region) {
    entries.push_back({"\u03a9: normals \u00b1n of the surface", filledSwatch()});
  }
  entries.push_back({region ? "\u2202\u03a9, near side" : "\u03a9 (Gauss image), near side",
                     lineSwatch("boundary")});
  entries.push_back({region ? "\u2202\u03a9, far side" : "\u03a9 (Gauss image), far side",
                     lineSwatch("boundary hidden")});
  entries.push_back({fmt::format("optimal circle, radius \u03b1* = {}", degreesLabel(result.alphaRad)),
                     lineSwatch("circle")});
  entries.push_back({"optimal circle, far side", lineSwatch("circle hidden")});
  entries.push_back({"N*: centre of the circle", centreSwatch()});
  entries.push_back({"p, \u2212p: pole of the plane figure",
                     "<path class=\"mark\" d=\"M 10 2 L 18 10 M 10 10 L 18 2\"/>"});
  entries.push_back({"equator and meridians (z up)", lineSwatch("grid")});

  const double legendTop = kPanelTop + kPanelSize + 14.0;
  double legendBottom = 0.0;
  const std::string legendSvg = legend(entries, legendTop, legendBottom);
  const double pageHeight = legendBottom + 8.0;

  std::string title =
      fmt::format("Symmetrized Gauss map \u03a9 and the optimal slicing circle: N* = {}, "
                  "\u03b1* = {}",
                  vectorLabel(result.normal), degreesLabel(result.alphaRad));
  std::array<std::string, 2> subtitle = {
      std::string("Every surface normal \u00b1n is at least \u03b1* from N*: the circle of "
                  "angular radius \u03b1* around N* touches \u03a9 without entering it."),
      fmt::format("{}. Pole p = {}: a surface normal.", certificateLabel(result),
                  vectorLabel(result.pole, 3))};
  if (result.method == SlicingMethod::covered) {
    title = "Symmetrized Gauss map \u03a9: it covers the whole sphere, so no slicing direction "
            "exists (\u03b1* = 0)";
    subtitle = {fmt::format("Proven: every direction or its opposite is a surface normal ({} "
                            "caps of directions, each inside the image of patch rectangles).",
                            result.coverage.caps),
                fmt::format("Pole p = {}: a surface normal.", vectorLabel(result.pole, 3))};
  } else if (result.method == SlicingMethod::lattice) {
    title = fmt::format("Symmetrized Gauss map \u03a9: no direction free within the tolerance; "
                        "best found N = {}, \u03b1 = {}",
                        vectorLabel(result.normal), degreesLabel(result.alphaRad));
    subtitle = {fmt::format("No proof that \u03a9 covers the sphere (none found near {}): N is "
                            "the best direction found, its \u03b1 certified.",
                            vectorLabel(result.coverage.unprovenDirection, 3)),
                fmt::format("{}. Pole p = {}: a surface normal.", certificateLabel(result),
                            vectorLabel(result.pole, 3))};
  }

  std::string svg = pageStart(pageHeight, title);
  svg += heading(title, subtitle);
  for (int panel = 0; panel < 2; ++panel) {
    const SphereView& view = views[static_cast<std::size_t>(panel)];
    svg += caption(panel, fmt::format("Seen from {}: N* and {} in front",
                                      vectorLabel(view.toViewer, 2), panel == 0 ? "p" : "\u2212p"));
    svg += spherePanel(result, view, panel);
  }
  svg += legendSvg;
  svg += "</svg>\n";
  return svg;
}

std::string stereographicSvg(const OptimalSlicing& result) {
  requireFinite(result);
  const PlaneGeometry geometry = planeGeometry(result.gaussMap);
  const PlaneView whole = wholeView(result, geometry);
  const PlaneView zoom = zoomView(geometry, whole);
  const bool medial = result.method == SlicingMethod::medialAxis;
  const bool region = result.gaussMap.kind == GaussMapKind::region;

  std::vector<LegendEntry> entries;
  if (region) entries.push_back({"\u03a9 (shaded) and its boundary loops", filledSwatch()});
  if (!region) entries.push_back({"\u03a9 (Gauss image)", lineSwatch("boundary")});
  if (medial) entries.push_back({"medial axis of the complement", lineSwatch("medial")});
  if (medial) {
    entries.push_back({"optimal circle and its centre",
                       "<line class=\"circle\" x1=\"0\" y1=\"6\" x2=\"18\" y2=\"6\"/>"
                       "<circle class=\"centre\" cx=\"23\" cy=\"6\" r=\"4\"/>"});
  }
  entries.push_back({"unit circle: image of the equator", lineSwatch("unit")});
  entries.push_back({"origin: image of \u2212p",
                     "<path class=\"mark\" d=\"M 10 2 L 18 10 M 10 10 L 18 2\"/>"});
  entries.push_back({"window of the zoomed panel",
                     "<rect class=\"zoom\" x=\"4\" y=\"0\" width=\"20\" height=\"12\"/>"});

  const double legendTop = kPanelTop + kPanelSize + 40.0;
  double legendBottom = 0.0;
  const std::string legendSvg = legend(entries, legendTop, legendBottom);
  const double pageHeight = legendBottom + 8.0;

  const std::string title = fmt::format(
      "Stereographic projection of \u03a9 from the pole p = {} (a surface normal)",
      vectorLabel(result.pole, 4));
  std::array<std::string, 2> subtitle;
  if (medial) {
    subtitle[0] = fmt::format(
        "Optimal circle: centre ({}, {}), R = {}; \u03b1 = {} on the polygonal \u03a9 (eq 12), "
        "\u03b1* = {} on the surface.",
        coordinateLabel(result.circle.center.x, 4), coordinateLabel(result.circle.center.y, 4),
        coordinateLabel(result.circle.radius, 4),
        degreesLabel(alphaOfPlaneCircleRad(norm(result.circle.center), result.circle.radius)),
        degreesLabel(result.alphaRad));
    subtitle[1] = fmt::format(
        "It maximises \u03b1 = atan(2R / (\u03c1\u00b2 \u2212 R\u00b2 + 1)), not R. {} boundary "
        "loops ({} segments), {} medial-axis edges.",
        result.gaussMap.loops.size(), result.gaussMap.boundarySegments, result.medialAxisEdges);
  } else if (result.method == SlicingMethod::covered || result.method == SlicingMethod::lattice) {
    subtitle[0] = result.method == SlicingMethod::covered
                      ? std::string("\u03a9 covers the whole plane (proven): no complement, no "
                                    "medial axis, no slicing direction (\u03b1* = 0).")
                      : std::string("\u03a9 leaves no complement within its tolerance: no medial "
                                    "axis; no proof that it covers the sphere either.");
    subtitle[1] = "Only \u03a9 (all of the plane), the unit circle and the origin are drawn.";
  } else {
    subtitle[0] = fmt::format("The Gauss image has no interior (method: {}): no medial axis; "
                              "\u03b1* = {} found on the sphere.",
                              slicingMethodName(result.method), degreesLabel(result.alphaRad));
    subtitle[1] = "Only the image of the Gauss curves, the unit circle and the origin are drawn.";
  }

  std::string svg = pageStart(pageHeight, title);
  svg += heading(title, subtitle);
  svg += caption(0, "The whole complement of \u03a9");
  svg += caption(1, fmt::format("Near the origin (dashed square at left), \u00d7{} magnified",
                                lengthLabel(std::round(whole.halfWidth / zoom.halfWidth * 10.0) / 10.0)));
  svg += planePanel(result, geometry, whole, 0, &zoom);
  svg += planePanel(result, geometry, zoom, 1, nullptr);
  svg += planeScaleBar(whole);
  svg += planeScaleBar(zoom);
  svg += legendSvg;
  svg += "</svg>\n";
  return svg;
}

namespace {

// The largest empty cap's figures, which a mesh's and a tessellation's documents share.
void addEmptyCap(nlohmann::ordered_json& document, const MeshSlicing& result) {
  document["distinct_normals"] = result.distinctNormals;
  document["hull_facets"] = result.hullFacets;
  document["great_circle"] = result.greatCircle;
  document["normal"] = {result.normal.x, result.normal.y, result.normal.z};
  document["alpha_deg"] = toDegrees(result.alphaRad);
}

}  // namespace

std::string meshOrientationToJson(const MeshSlicing& result, const StlMesh& mesh, const std::string& source) {
  nlohmann::ordered_json document;
  document["input"] = "mesh";
  document["source"] = source;
  document["format"] = mesh.format == StlFormat::binary ? "binary" : "ascii";
  document["units"] = std::string(unitsName(mesh.mesh.units));
  document["triangles_read"] = mesh.trianglesRead;
  document["zero_area_dropped"] = mesh.zeroAreaDropped;
  document["triangles"] = result.triangles;
  addEmptyCap(document, result);
  return json::format(document);
}

std::string tessellationOrientationToJson(const MeshSlicing& result, const TessellationFacts& facts,
                                          const std::string& source) {
  nlohmann::ordered_json document;
  document["input"] = "tessellation";
  document["source"] = source;
  document["units"] = std::string(unitsName(facts.units));
  document["faces"] = facts.faces;
  document["deflection"] = facts.deflection;
  document["deviation"] = facts.deviation;
  document["facet_normal_angle_deg"] = toDegrees(facts.normalAngleRad);
  document["normals_sampled"] = facts.normalsSampled;
  addEmptyCap(document, result);
  document["alpha_is"] = "upper bound";
  document["certified"] = false;
  return json::format(document);
}

}  // namespace scallop
