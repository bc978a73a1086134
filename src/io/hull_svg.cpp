#include "scallop/io/hull_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "io/svg_format.hpp"

namespace scallop {
namespace {

using svg::lengthLabel;
using svg::px;
using svg::roundLength;

// Page layout, in SVG pixels.
constexpr double kMaxPlotWidth = 960.0;
constexpr double kMaxPlotHeight = 600.0;
constexpr double kMinPageWidth = 760.0;
constexpr double kMargin = 20.0;
constexpr double kHeaderHeight = 40.0;
constexpr double kFooterHeight = 70.0;
constexpr double kScaleBarTarget = 120.0;  // preferred scale bar length

// Space around the drawing and depth of the shaded material, as fractions of its extent.
constexpr double kPadding = 0.05;
constexpr double kMaterialDepth = 0.12;

// Colours (a colour-blind-safe palette) and stroke widths.
constexpr const char* kMaterialFill = "#eadfc8";
constexpr const char* kChainColour = "#333333";
constexpr const char* kLinkColour = "#1f77b4";
constexpr const char* kLidColour = "#ff7f0e";
constexpr const char* kPathColour = "#2ca02c";
constexpr const char* kToolColour = "#9467bd";

constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------
// Geometry of the drawing
// ---------------------------------------------------------------------------------------

double angleOf(const Point2& p, const Point2& centre) {
  return std::atan2(p.z - centre.z, p.x - centre.x);
}

// Angle swept turning counter-clockwise (x right, z up) from direction `from` to `to`,
// in [0, 2*pi).
double counterClockwiseSweep(double from, double to) {
  double sweep = to - from;
  while (sweep < 0.0) sweep += 2.0 * kPi;
  while (sweep >= 2.0 * kPi) sweep -= 2.0 * kPi;
  return sweep;
}

struct Bounds {
  double minX = std::numeric_limits<double>::infinity();
  double maxX = -std::numeric_limits<double>::infinity();
  double minZ = std::numeric_limits<double>::infinity();
  double maxZ = -std::numeric_limits<double>::infinity();

  void add(const Point2& p) {
    minX = std::min(minX, p.x);
    maxX = std::max(maxX, p.x);
    minZ = std::min(minZ, p.z);
    maxZ = std::max(maxZ, p.z);
  }
  void addCircle(const Point2& centre, double r) {
    add({centre.x - r, centre.z - r});
    add({centre.x + r, centre.z + r});
  }
  // The end points and every axis-extreme point (right, top, left, bottom) the clockwise
  // arc passes through.
  void addClockwiseArc(const PathElement& arc) {
    add(arc.start);
    add(arc.end);
    const double start = angleOf(arc.start, arc.center);
    double sweep = counterClockwiseSweep(angleOf(arc.end, arc.center), start);
    if (sweep > 1.5 * kPi) sweep = 0.0;  // at most a half turn: a tiny arc crossed by rounding
    for (int quarter = 0; quarter < 4; ++quarter) {
      const double angle = quarter * kPi / 2.0;
      if (counterClockwiseSweep(angle, start) <= sweep) {
        add({arc.center.x + arc.radius * std::cos(angle),
             arc.center.z + arc.radius * std::sin(angle)});
      }
    }
  }
};

// The centres where the tool's circle is drawn: at every lid (a corner of the tool path)
// and at the two ends of the path.
std::vector<Point2> toolCentres(const ScallopHull& result) {
  std::vector<Point2> centres;
  if (!std::isfinite(result.radius)) return centres;
  if (!result.toolpath.empty()) centres.push_back(result.toolpath.front().start);
  for (const HullElement& element : result.hull) {
    if (element.kind == HullElementKind::lid && !element.straight)
      centres.push_back(element.center);
  }
  if (!result.toolpath.empty()) centres.push_back(result.toolpath.back().end);
  return centres;
}

Bounds drawingBounds(std::span<const Point2> chain, const ScallopHull& result) {
  Bounds bounds;
  for (const Point2& p : chain) bounds.add(p);
  for (const HullElement& element : result.hull) {
    bounds.add(element.start);
    bounds.add(element.end);
  }
  for (const PathElement& element : result.toolpath) {
    if (element.kind == PathElementKind::arc) {
      bounds.addClockwiseArc(element);
    } else {
      bounds.add(element.start);
      bounds.add(element.end);
    }
  }
  for (const Point2& centre : toolCentres(result)) bounds.addCircle(centre, result.radius);
  return bounds;
}

// Maps the chain's plane (x right, z up) to the page (x right, y down).
struct View {
  double scale = 1.0;  // pixels per unit length
  double worldLeft = 0.0;
  double worldTop = 0.0;
  double worldBottom = 0.0;  // bottom of the shaded material
  double pageLeft = 0.0;
  double pageTop = 0.0;
  double plotWidth = 0.0;
  double plotHeight = 0.0;
  double pageWidth = 0.0;
  double pageHeight = 0.0;

  double x(double worldX) const { return pageLeft + (worldX - worldLeft) * scale; }
  double y(double worldZ) const { return pageTop + (worldTop - worldZ) * scale; }
  std::string point(const Point2& p) const { return px(x(p.x)) + "," + px(y(p.z)); }
};

View makeView(const Bounds& bounds) {
  const double width = bounds.maxX - bounds.minX;
  const double height = bounds.maxZ - bounds.minZ;
  double extent = std::max(width, height);
  if (!std::isfinite(extent)) {
    throw Error("cannot draw the scallop hull: the coordinates span more than a double can hold");
  }
  // All points equal (and no tool circle): draw a neighbourhood of the point as large as
  // its coordinates, so that padding a point at 1e9 is not lost in rounding; at the origin,
  // a neighbourhood of size 1.
  if (extent == 0.0) extent = std::max(std::abs(bounds.minX), std::abs(bounds.minZ));
  if (extent == 0.0) extent = 1.0;

  View view;
  view.worldLeft = bounds.minX - kPadding * extent;
  view.worldTop = bounds.maxZ + kPadding * extent;
  view.worldBottom = bounds.minZ - kMaterialDepth * extent;
  const double worldWidth = bounds.maxX + kPadding * extent - view.worldLeft;
  const double worldHeight = view.worldTop - view.worldBottom;
  if (!std::isfinite(worldWidth) || !std::isfinite(worldHeight)) {
    throw Error("cannot draw the scallop hull: the coordinates span more than a double can hold");
  }
  view.scale = std::min(kMaxPlotWidth / worldWidth, kMaxPlotHeight / worldHeight);
  view.plotWidth = worldWidth * view.scale;
  view.plotHeight = worldHeight * view.scale;
  view.pageWidth = std::max(view.plotWidth + 2.0 * kMargin, kMinPageWidth);
  view.pageHeight = kHeaderHeight + view.plotHeight + kFooterHeight;
  view.pageLeft = 0.5 * (view.pageWidth - view.plotWidth);
  view.pageTop = kHeaderHeight;
  return view;
}

// ---------------------------------------------------------------------------------------
// Drawing
// ---------------------------------------------------------------------------------------

std::string materialPolygon(std::span<const Point2> chain, const View& view) {
  std::string points;
  for (const Point2& p : chain) {
    points += view.point(p);
    points += ' ';
  }
  points += view.point({chain.back().x, view.worldBottom});
  points += ' ';
  points += view.point({chain.front().x, view.worldBottom});
  return fmt::format("<polygon class=\"material\" points=\"{}\"/>\n", points);
}

std::string chainPolyline(std::span<const Point2> chain, const View& view) {
  std::string points;
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (i > 0) points += ' ';
    points += view.point(chain[i]);
  }
  return fmt::format("<polyline class=\"chain\" points=\"{}\"/>\n", points);
}

std::string lineElement(const char* cssClass, const Point2& a, const Point2& b, const View& view) {
  return fmt::format("<line class=\"{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", cssClass,
                     px(view.x(a.x)), px(view.y(a.z)), px(view.x(b.x)), px(view.y(b.z)));
}

// SVG arc command to `end`. The picture shows the plane as it is (z up), so a turn that
// looks counter-clockwise in the plane looks counter-clockwise on the page too; but SVG's
// sweep flag 1 means "angle increasing" in page coordinates, whose y axis points down:
// a clockwise-looking turn. Hence counter-clockwise = flag 0, clockwise = flag 1.
// The large-arc flag is always 0: every arc scallop draws is at most a half circle (a lid
// is part of the lower semicircle, since only the lower half of the circle can touch a
// monotone chain from above; a path arc turns between the normals of two edges at a convex
// vertex, at most pi). Deriving the flag from rounded angles instead would turn a tiny arc
// whose ends cross by rounding into a full circle.
std::string arcCommand(const Point2& end, double radius, bool counterClockwise, const View& view) {
  const int sweepFlag = counterClockwise ? 0 : 1;
  return fmt::format("A {} {} 0 0 {} {}", px(radius * view.scale), px(radius * view.scale),
                     sweepFlag, view.point(end));
}

// A lid is the lower arc of its circle, from its left contact point down and around to its
// right one: counter-clockwise in the plane (x right, z up).
std::string lidElement(const HullElement& lid, double radius, const View& view) {
  if (lid.straight || !std::isfinite(radius))
    return lineElement("lid straight", lid.start, lid.end, view);
  return fmt::format("<path class=\"lid\" d=\"M {} {}\"/>\n", view.point(lid.start),
                     arcCommand(lid.end, radius, true, view));
}

std::string hullElements(const ScallopHull& result, const View& view) {
  std::string out = "<g class=\"hull\">\n";
  for (const HullElement& element : result.hull) {
    if (element.start == element.end) continue;  // nothing to draw
    out += element.kind == HullElementKind::link
               ? lineElement("link", element.start, element.end, view)
               : lidElement(element, result.radius, view);
  }
  return out + "</g>\n";
}

// The tool-centre path as one SVG path: lines, and arcs (clockwise in the plane).
std::string toolPathElement(const ScallopHull& result, const View& view) {
  if (result.toolpath.empty()) return {};
  std::string d;
  const Point2* previousEnd = nullptr;
  for (const PathElement& element : result.toolpath) {
    // The path is contiguous by contract; a gap is drawn as a gap, not bridged.
    if (previousEnd == nullptr || !(*previousEnd == element.start)) {
      d += d.empty() ? "M " : " M ";
      d += view.point(element.start);
    }
    if (element.kind == PathElementKind::arc && !(element.start == element.end)) {
      d += ' ';
      d += arcCommand(element.end, element.radius, !element.clockwise, view);
    } else {
      d += " L ";
      d += view.point(element.end);
    }
    previousEnd = &element.end;
  }
  return fmt::format("<path class=\"toolpath\" d=\"{}\"/>\n", d);
}

std::string toolCircles(const ScallopHull& result, const View& view) {
  const std::vector<Point2> centres = toolCentres(result);
  if (centres.empty()) return {};
  std::string out = "<g class=\"tool\">\n";
  for (const Point2& centre : centres) {
    out += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", px(view.x(centre.x)),
                       px(view.y(centre.z)), px(result.radius * view.scale));
  }
  out += "</g>\n<g class=\"centre\">\n";
  for (const Point2& centre : centres) {
    out += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"2.5\"/>\n", px(view.x(centre.x)),
                       px(view.y(centre.z)));
  }
  return out + "</g>\n";
}

std::string titleText(std::span<const Point2> chain, const ScallopHull& result) {
  std::size_t links = 0;
  for (const HullElement& element : result.hull) {
    links += element.kind == HullElementKind::link ? 1 : 0;
  }
  const std::size_t lids = result.hull.size() - links;
  const bool finite = std::isfinite(result.radius);
  return fmt::format("Scallop hull: n = {} vertices, r = {} ({} links, {} lids{})", chain.size(),
                     finite ? lengthLabel(result.radius) : std::string("\u221e"), links, lids,
                     finite ? "" : "; upper convex hull, no tool path");
}

std::string scaleBar(const View& view) {
  const double length = roundLength(kScaleBarTarget / view.scale);
  const double left = kMargin;
  const double right = left + length * view.scale;
  const double y = view.pageTop + view.plotHeight + 24.0;
  return fmt::format(
      "<g class=\"scale\">\n"
      "<line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\"/>\n"
      "<line x1=\"{0}\" y1=\"{3}\" x2=\"{0}\" y2=\"{4}\"/>\n"
      "<line x1=\"{1}\" y1=\"{3}\" x2=\"{1}\" y2=\"{4}\"/>\n"
      "<text x=\"{5}\" y=\"{6}\" text-anchor=\"middle\">{7}</text>\n"
      "</g>\n",
      px(left), px(right), px(y), px(y - 5.0), px(y + 5.0), px(0.5 * (left + right)), px(y + 22.0),
      lengthLabel(length));
}

std::string legend(const ScallopHull& result, const View& view) {
  struct Entry {
    const char* label;
    std::string swatch;  // drawn in a 28 x 12 box whose top-left is (0, 0)
  };
  const bool finite = std::isfinite(result.radius);
  std::vector<Entry> entries = {
      {"material", "<rect class=\"material\" x=\"0\" y=\"0\" width=\"28\" height=\"12\"/>"},
      {"chain", "<line class=\"chain\" x1=\"0\" y1=\"6\" x2=\"28\" y2=\"6\"/>"},
      {"link", "<line class=\"link\" x1=\"2\" y1=\"6\" x2=\"26\" y2=\"6\"/>"},
      {"lid", finite ? "<path class=\"lid\" d=\"M 2,2 A 14 14 0 0 0 26,2\"/>"
                     : "<line class=\"lid straight\" x1=\"2\" y1=\"6\" x2=\"26\" y2=\"6\"/>"},
  };
  if (finite) {
    entries.push_back(
        {"tool-centre path", "<line class=\"toolpath\" x1=\"0\" y1=\"6\" x2=\"28\" y2=\"6\"/>"});
    entries.push_back(
        {"tool at lid centres", "<g class=\"tool\"><circle cx=\"14\" cy=\"6\" r=\"6\"/></g>"});
  }
  // Two rows of three, right-aligned in the footer.
  constexpr double kColumnWidth = 185.0;
  constexpr std::size_t kColumns = 3;
  const double left = view.pageWidth - kMargin - kColumns * kColumnWidth;
  const double top = view.pageTop + view.plotHeight + 12.0;
  std::string out = "<g class=\"legend\">\n";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double x = left + static_cast<double>(i % kColumns) * kColumnWidth;
    const double y = top + static_cast<double>(i / kColumns) * 24.0;
    out +=
        fmt::format("<g transform=\"translate({},{})\">{}<text x=\"36\" y=\"11\">{}</text></g>\n",
                    px(x), px(y), entries[i].swatch, entries[i].label);
  }
  return out + "</g>\n";
}

std::string styleSheet() {
  return fmt::format(
      "<style>\n"
      "text {{ font-family: sans-serif; font-size: 13px; fill: #222222; }}\n"
      ".title {{ font-size: 15px; }}\n"
      ".material {{ fill: {0}; stroke: none; }}\n"
      ".chain {{ fill: none; stroke: {1}; stroke-width: 1.2; stroke-linejoin: round; }}\n"
      ".link {{ stroke: {2}; stroke-width: 5; stroke-opacity: 0.7; stroke-linecap: round; }}\n"
      ".lid {{ fill: none; stroke: {3}; stroke-width: 5; stroke-opacity: 0.8; "
      "stroke-linecap: round; }}\n"
      ".straight {{ stroke-dasharray: 8 4; }}\n"
      ".toolpath {{ fill: none; stroke: {4}; stroke-width: 2; stroke-linejoin: round; }}\n"
      ".tool circle {{ fill: none; stroke: {5}; stroke-width: 0.8; stroke-opacity: 0.8; }}\n"
      ".centre circle {{ fill: {5}; stroke: none; }}\n"
      ".scale line {{ stroke: #222222; stroke-width: 1.5; }}\n"
      "</style>\n",
      kMaterialFill, kChainColour, kLinkColour, kLidColour, kPathColour, kToolColour);
}

}  // namespace

std::string hullToSvg(std::span<const Point2> chain, const ScallopHull& result) {
  if (chain.empty()) throw Error("cannot draw the scallop hull of an empty chain");
  const View view = makeView(drawingBounds(chain, result));
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\">\n",
      px(view.pageWidth), px(view.pageHeight));
  const std::string title = titleText(chain, result);
  svg += fmt::format("<title>{}</title>\n", title);
  svg += styleSheet();
  svg += fmt::format("<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>\n",
                     px(view.pageWidth), px(view.pageHeight));
  svg += fmt::format("<text class=\"title\" x=\"{}\" y=\"26\">{}</text>\n", px(kMargin), title);
  svg += materialPolygon(chain, view);
  svg += toolCircles(result, view);
  svg += chainPolyline(chain, view);
  svg += hullElements(result, view);
  svg += toolPathElement(result, view);
  svg += scaleBar(view);
  svg += legend(result, view);
  svg += "</svg>\n";
  return svg;
}

}  // namespace scallop
