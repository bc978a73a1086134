// Tests for the outputs: hull_json.hpp (every double survives the round trip bit for bit,
// every documented key is there), hull_svg.hpp (well-formed, fixed-point numbers only,
// arcs bending the right way, degenerate and extreme extents) and file_output.hpp (all or
// nothing). References are computed here from the in-memory results, never taken from the
// program's output.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <random>
#include <regex>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scallop/paths/chain.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/error.hpp"
#include "scallop/io/file_output.hpp"
#include "scallop/io/hull_json.hpp"
#include "scallop/io/hull_svg.hpp"
#include "scallop/paths/scallop_hull.hpp"

namespace scallop {
namespace {

using Json = nlohmann::json;
constexpr double kPi = std::numbers::pi;

std::uint64_t bitsOf(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// ---------------------------------------------------------------------------------------
// JSON
// ---------------------------------------------------------------------------------------

void expectSameDouble(const Json& value, double expected, const std::string& where) {
  ASSERT_TRUE(value.is_number()) << where << ": " << value.dump();
  EXPECT_EQ(bitsOf(value.get<double>()), bitsOf(expected))
      << where << ": " << value.dump() << " vs " << expected;
}

void expectSamePoint(const Json& value, const Point2& expected, const std::string& where) {
  ASSERT_TRUE(value.is_array() && value.size() == 2) << where << ": " << value.dump();
  expectSameDouble(value[0], expected.x, where + ".x");
  expectSameDouble(value[1], expected.z, where + ".z");
}

void expectHullElement(const Json& json, const HullElement& element, const std::string& where) {
  expectSamePoint(json.at("start"), element.start, where + ".start");
  expectSamePoint(json.at("end"), element.end, where + ".end");
  if (element.kind == HullElementKind::link) {
    EXPECT_EQ(json.at("kind"), "link") << where;
    EXPECT_EQ(json.at("edge").get<std::size_t>(), element.edge) << where;
    EXPECT_FALSE(json.contains("center")) << where;
  } else {
    EXPECT_EQ(json.at("kind"), "lid") << where;
    EXPECT_FALSE(json.contains("edge")) << where;
    if (element.straight) {
      EXPECT_FALSE(json.contains("center")) << where;
    } else {
      expectSamePoint(json.at("center"), element.center, where + ".center");
    }
  }
}

void expectPathElement(const Json& json, const PathElement& element, const std::string& where) {
  expectSamePoint(json.at("start"), element.start, where + ".start");
  expectSamePoint(json.at("end"), element.end, where + ".end");
  if (element.kind == PathElementKind::arc) {
    EXPECT_EQ(json.at("kind"), "arc") << where;
    expectSamePoint(json.at("center"), element.center, where + ".center");
    expectSameDouble(json.at("radius"), element.radius, where + ".radius");
    EXPECT_EQ(json.at("clockwise").get<bool>(), element.clockwise) << where;
  } else {
    EXPECT_EQ(json.at("kind"), "line") << where;
    EXPECT_FALSE(json.contains("center")) << where;
    EXPECT_FALSE(json.contains("radius")) << where;
  }
}

// Checks `text` (hullToJson's output) against the in-memory result, value by value.
void expectJsonMatches(const std::string& text, const ScallopHull& result, std::size_t vertices) {
  const Json doc = Json::parse(text);
  if (std::isfinite(result.radius)) {
    expectSameDouble(doc.at("radius"), result.radius, "radius");
  } else {
    EXPECT_TRUE(doc.at("radius").is_null());
  }
  ASSERT_EQ(doc.at("hull").size(), result.hull.size());
  for (std::size_t i = 0; i < result.hull.size(); ++i) {
    expectHullElement(doc["hull"][i], result.hull[i], "hull[" + std::to_string(i) + "]");
  }
  ASSERT_EQ(doc.at("toolpath").size(), result.toolpath.size());
  for (std::size_t i = 0; i < result.toolpath.size(); ++i) {
    expectPathElement(doc["toolpath"][i], result.toolpath[i],
                      "toolpath[" + std::to_string(i) + "]");
  }
  expectSameDouble(doc.at("toolpath_length"), pathLength(result.toolpath), "toolpath_length");

  const std::size_t links = static_cast<std::size_t>(
      std::count_if(result.hull.begin(), result.hull.end(),
                    [](const HullElement& e) { return e.kind == HullElementKind::link; }));
  const Json& stats = doc.at("stats");
  EXPECT_EQ(stats.at("vertices").get<std::size_t>(), vertices);
  EXPECT_EQ(stats.at("links").get<std::size_t>(), links);
  EXPECT_EQ(stats.at("lids").get<std::size_t>(), result.hull.size() - links);
  EXPECT_FALSE(stats.contains("seconds"));  // no wall time: the same hull, the same bytes
  EXPECT_EQ(stats.at("stack_pushes").get<std::uint64_t>(), result.stats.pushes);
  EXPECT_EQ(stats.at("stack_pops").get<std::uint64_t>(), result.stats.pops);
}

// Finite doubles of every magnitude: random bit patterns (subnormals, huge, tiny), plus the
// classic troublemakers for shortest round-trip printing.
class AwkwardDoubles {
 public:
  explicit AwkwardDoubles(std::uint64_t seed) : rng_(seed) {}
  double next() {
    static constexpr double kSpecial[] = {0.1,
                                          1.0 / 3.0,
                                          5e-324,
                                          2.2250738585072014e-308,
                                          1e-300,
                                          1e300,
                                          1.7976931348623157e308,
                                          -0.0,
                                          0.0,
                                          9007199254740993.0,
                                          123456789.12345679,
                                          2.5};
    if (index_ < std::size(kSpecial)) return kSpecial[index_++];
    while (true) {
      const std::uint64_t bits = rng_();
      double value = 0.0;
      std::memcpy(&value, &bits, sizeof value);
      if (std::isfinite(value)) return value;
    }
  }
  Point2 point() { return {next(), next()}; }

 private:
  std::mt19937_64 rng_;
  std::size_t index_ = 0;
};

ScallopHull syntheticHull(double radius) {
  AwkwardDoubles values(42);
  std::mt19937_64 rng(42);
  ScallopHull result;
  result.radius = radius;
  for (int i = 0; i < 60; ++i) {
    HullElement element;
    element.kind = i % 3 == 0 ? HullElementKind::lid : HullElementKind::link;
    element.start = values.point();
    element.end = values.point();
    element.center = values.point();
    element.edge = static_cast<std::size_t>(rng() % 100000);
    element.straight = element.kind == HullElementKind::lid && !std::isfinite(radius);
    result.hull.push_back(element);
  }
  for (int i = 0; i < 60; ++i) {
    PathElement element;
    element.kind = i % 2 == 0 ? PathElementKind::arc : PathElementKind::line;
    element.start = values.point();
    element.end = values.point();
    if (element.kind == PathElementKind::arc) {
      element.center = values.point();
      element.radius = values.next();
    }
    result.toolpath.push_back(element);
  }
  result.stats = {rng(), rng(), rng()};
  return result;
}

TEST(HullOutputJson, SyntheticValuesRoundTripBitForBit) {
  // Small magnitudes only for the path, so that its length stays finite (JSON has no inf).
  ScallopHull result = syntheticHull(0.7);
  for (PathElement& element : result.toolpath) {
    for (Point2* p : {&element.start, &element.end, &element.center}) {
      p->x = std::fmod(p->x, 1e100);
      p->z = std::fmod(p->z, 1e100);
    }
    element.radius = std::abs(std::fmod(element.radius, 1e100));
  }
  expectJsonMatches(hullToJson(result, 12345), result, 12345);
}

TEST(HullOutputJson, InfiniteRadiusIsNullAndStraightLidsHaveNoCentre) {
  ScallopHull result = syntheticHull(kInfiniteRadius);
  result.toolpath.clear();
  const std::string text = hullToJson(result, 7);
  expectJsonMatches(text, result, 7);
  EXPECT_TRUE(Json::parse(text).at("toolpath").empty());
}

TEST(HullOutputJson, HasEveryDocumentedKey) {
  const Chain chain = exampleChain("figure2");
  const ScallopHull result = scallopHull(chain, 1.0);
  const Json doc = Json::parse(hullToJson(result, chain.size()));
  for (const char* key : {"radius", "hull", "toolpath", "toolpath_length", "stats"}) {
    EXPECT_TRUE(doc.contains(key)) << key;
  }
  EXPECT_FALSE(doc.contains("polyline"));
  for (const char* key : {"vertices", "links", "lids", "stack_pushes", "stack_pops"}) {
    EXPECT_TRUE(doc.at("stats").contains(key)) << key;
  }
}

TEST(HullOutputJson, PolylineOverloadWritesPointsExactly) {
  const ScallopHull result = syntheticHull(2.0);
  AwkwardDoubles values(7);
  std::vector<Point2> polyline;
  for (int i = 0; i < 100; ++i) polyline.push_back(values.point());
  const std::string withPolyline = hullToJson(result, 3, polyline);
  const Json doc = Json::parse(withPolyline);
  ASSERT_EQ(doc.at("polyline").size(), polyline.size());
  for (std::size_t i = 0; i < polyline.size(); ++i) {
    expectSamePoint(doc["polyline"][i], polyline[i], "polyline[" + std::to_string(i) + "]");
  }
  expectJsonMatches(withPolyline, result, 3);
}

TEST(HullOutputJson, RealHullsRoundTrip) {
  for (const std::string& name : exampleChainNames()) {
    const Chain chain = exampleChain(name);
    for (const double radius : {0.3, 1.0, 2.5, kInfiniteRadius}) {
      SCOPED_TRACE(name + " r=" + std::to_string(radius));
      const ScallopHull result = scallopHull(chain, radius);
      expectJsonMatches(hullToJson(result, chain.size()), result, chain.size());
    }
  }
}

// ---------------------------------------------------------------------------------------
// SVG
// ---------------------------------------------------------------------------------------

// Tags nest and close, attribute quotes pair up, the root is <svg>. Returns "" if so.
std::string tagProblems(const std::string& svg) {
  if (svg.rfind("<svg", 0) != 0) return "does not start with <svg";
  std::vector<std::string> open;
  std::size_t position = 0;
  bool sawRoot = false;
  while ((position = svg.find('<', position)) != std::string::npos) {
    const std::size_t close = svg.find('>', position);
    if (close == std::string::npos) return "unterminated tag";
    const std::string tag = svg.substr(position + 1, close - position - 1);
    position = close + 1;
    if (std::count(tag.begin(), tag.end(), '"') % 2 != 0) return "unpaired quote in <" + tag + ">";
    if (tag.find('<') != std::string::npos) return "'<' inside <" + tag + ">";
    if (tag.empty()) return "empty tag";
    if (tag.front() == '/') {
      if (open.empty() || open.back() != tag.substr(1))
        return "mismatched </" + tag.substr(1) + ">";
      open.pop_back();
      continue;
    }
    const std::string name = tag.substr(0, tag.find_first_of(" /"));
    if (open.empty() && sawRoot) return "content after the root element";
    sawRoot = true;
    if (tag.back() != '/') open.push_back(name);
  }
  if (!open.empty()) return "unclosed <" + open.back() + ">";
  if (svg.find('&') != std::string::npos) return "unescaped '&'";
  return "";
}

void expectCleanSvg(const std::string& svg) {
  EXPECT_EQ(tagProblems(svg), "");
  std::string lower = svg;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  EXPECT_EQ(lower.find("nan"), std::string::npos);
  EXPECT_EQ(lower.find("inf"), std::string::npos);
  // No exponent notation anywhere (e+, e-, or a bare exponent like 1e5).
  EXPECT_FALSE(std::regex_search(svg, std::regex("[0-9.][eE][-+]?[0-9]")));
  EXPECT_EQ(svg.find("e+"), std::string::npos);
}

struct PagePoint {
  double x = 0.0;
  double y = 0.0;
};

// World (x, z) to page, recovered from where the chain polyline puts the chain's first and
// last vertex (the chain must span some x).
struct PageTransform {
  double scale = 0.0;
  PagePoint origin;  // page position of world (0, 0)
  PagePoint map(const Point2& p) const { return {origin.x + p.x * scale, origin.y - p.z * scale}; }
};

std::vector<PagePoint> parsePointList(const std::string& text) {
  std::vector<PagePoint> points;
  std::istringstream in(text);
  std::string pair;
  while (in >> pair) {
    const std::size_t comma = pair.find(',');
    points.push_back({std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1))});
  }
  return points;
}

PageTransform recoverTransform(const std::string& svg, std::span<const Point2> chain) {
  std::smatch match;
  EXPECT_TRUE(std::regex_search(svg, match, std::regex("class=\"chain\" points=\"([^\"]*)\"")));
  const std::vector<PagePoint> page = parsePointList(match[1]);
  EXPECT_EQ(page.size(), chain.size());
  PageTransform transform;
  transform.scale = (page.back().x - page.front().x) / (chain.back().x - chain.front().x);
  transform.origin = {page.front().x - chain.front().x * transform.scale,
                      page.front().y + chain.front().z * transform.scale};
  return transform;
}

// The middle of an SVG arc given in endpoint form (SVG 1.1, appendix F.6.5, with rx = ry
// and no rotation), computed independently of the writer.
PagePoint svgArcMidpoint(PagePoint from, double radius, int largeArc, int sweep, PagePoint to) {
  const double hx = 0.5 * (from.x - to.x);
  const double hy = 0.5 * (from.y - to.y);
  const double halfChord2 = hx * hx + hy * hy;
  if (halfChord2 == 0.0) return from;  // the arc is omitted (F.6.2)
  double r = radius;
  double factor = 0.0;
  if (r * r >= halfChord2) {
    factor = std::sqrt((r * r - halfChord2) / halfChord2) * (largeArc == sweep ? -1.0 : 1.0);
  } else {
    r = std::sqrt(halfChord2);  // radii scaled up to just reach (F.6.6)
  }
  const PagePoint centre{factor * hy + 0.5 * (from.x + to.x), -factor * hx + 0.5 * (from.y + to.y)};
  const double theta1 = std::atan2(from.y - centre.y, from.x - centre.x);
  double delta = std::atan2(to.y - centre.y, to.x - centre.x) - theta1;
  if (sweep == 0 && delta > 0) delta -= 2 * kPi;
  if (sweep == 1 && delta < 0) delta += 2 * kPi;
  return {centre.x + r * std::cos(theta1 + 0.5 * delta),
          centre.y + r * std::sin(theta1 + 0.5 * delta)};
}

// The middle of a world arc around `centre` from `start` to `end`, turning counter-clockwise
// (lids: the lower arc) or clockwise (tool path arcs), x right and z up. Both kinds span at
// most a half circle, so a larger sweep can only be a tiny arc whose ends crossed by
// rounding: it is taken the short way.
Point2 worldArcMidpoint(Point2 centre, double radius, Point2 start, Point2 end, bool clockwise) {
  const double a = std::atan2(start.z - centre.z, start.x - centre.x);
  const double b = std::atan2(end.z - centre.z, end.x - centre.x);
  double sweep = clockwise ? a - b : b - a;
  while (sweep < 0) sweep += 2 * kPi;
  if (sweep > 1.5 * kPi) sweep -= 2 * kPi;
  const double middle = clockwise ? a - 0.5 * sweep : a + 0.5 * sweep;
  return {centre.x + radius * std::cos(middle), centre.z + radius * std::sin(middle)};
}

double pageDistance(PagePoint a, PagePoint b) { return std::hypot(a.x - b.x, a.y - b.y); }

struct SvgArc {
  PagePoint from;
  double radius = 0.0;
  int largeArc = 0;
  int sweep = 0;
  PagePoint to;
};

PagePoint parsePagePoint(const std::string& text) { return parsePointList(text).front(); }

// The arcs of an SVG path's "d" (commands M, L, A as hullToSvg writes them).
std::vector<SvgArc> arcsOfPath(const std::string& d) {
  std::istringstream in(d);
  std::vector<SvgArc> arcs;
  std::string command;
  PagePoint current;
  while (in >> command) {
    if (command == "M" || command == "L") {
      std::string p;
      in >> p;
      current = parsePagePoint(p);
    } else if (command == "A") {
      SvgArc arc;
      double ry = 0.0;
      double rotation = 0.0;
      std::string p;
      in >> arc.radius >> ry >> rotation >> arc.largeArc >> arc.sweep >> p;
      arc.from = current;
      arc.to = parsePagePoint(p);
      current = arc.to;
      arcs.push_back(arc);
    } else {
      ADD_FAILURE() << "unexpected path command " << command << " in: " << d;
      break;
    }
  }
  return arcs;
}

// Lids must sag (lower arcs) and tool path arcs bulge (clockwise over convex vertices):
// compare each drawn arc's middle with the middle of the true arc.
void expectArcsBendCorrectly(const std::string& svg, std::span<const Point2> chain,
                             const ScallopHull& result) {
  const PageTransform transform = recoverTransform(svg, chain);
  const std::string drawing = svg.substr(0, svg.find("<g class=\"legend\">"));
  constexpr double kPixelTolerance = 1.0;

  std::vector<SvgArc> lidArcs;
  const std::regex lidPattern("<path class=\"lid\" d=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(drawing.begin(), drawing.end(), lidPattern);
       it != std::sregex_iterator(); ++it) {
    for (const SvgArc& arc : arcsOfPath((*it)[1])) lidArcs.push_back(arc);
  }
  std::size_t lid = 0;
  for (const HullElement& element : result.hull) {
    if (element.kind != HullElementKind::lid || element.straight || element.start == element.end) {
      continue;
    }
    ASSERT_LT(lid, lidArcs.size());
    const SvgArc& arc = lidArcs[lid++];
    EXPECT_LT(pageDistance(arc.from, transform.map(element.start)), 0.01);
    EXPECT_LT(pageDistance(arc.to, transform.map(element.end)), 0.01);
    const PagePoint drawn = svgArcMidpoint(arc.from, arc.radius, arc.largeArc, arc.sweep, arc.to);
    const PagePoint truth = transform.map(
        worldArcMidpoint(element.center, result.radius, element.start, element.end, false));
    EXPECT_LT(pageDistance(drawn, truth), kPixelTolerance) << "lid " << lid - 1;
  }
  EXPECT_EQ(lid, lidArcs.size());

  std::smatch match;
  if (result.toolpath.empty()) {
    EXPECT_FALSE(std::regex_search(svg, match, std::regex("class=\"toolpath\" d=")));
    return;
  }
  ASSERT_TRUE(std::regex_search(svg, match, std::regex("<path class=\"toolpath\" d=\"([^\"]*)\"")));
  const std::vector<SvgArc> pathArcs = arcsOfPath(match[1]);
  std::size_t index = 0;
  for (const PathElement& element : result.toolpath) {
    if (element.kind != PathElementKind::arc || element.start == element.end) continue;
    ASSERT_LT(index, pathArcs.size());
    const SvgArc& arc = pathArcs[index++];
    const PagePoint drawn = svgArcMidpoint(arc.from, arc.radius, arc.largeArc, arc.sweep, arc.to);
    const PagePoint truth = transform.map(
        worldArcMidpoint(element.center, element.radius, element.start, element.end, true));
    EXPECT_LT(pageDistance(drawn, truth), kPixelTolerance) << "path arc " << index - 1;
  }
  EXPECT_EQ(index, pathArcs.size());
}

TEST(HullOutputSvg, ExamplesAreCleanAndArcsBendCorrectly) {
  for (const std::string& name : exampleChainNames()) {
    const Chain chain = exampleChain(name);
    for (const double radius : {0.3, 1.0, 2.5, kInfiniteRadius}) {
      SCOPED_TRACE(name + " r=" + std::to_string(radius));
      const ScallopHull result = scallopHull(chain, radius);
      const std::string svg = hullToSvg(chain, result);
      expectCleanSvg(svg);
      expectArcsBendCorrectly(svg, chain, result);
    }
  }
}

TEST(HullOutputSvg, TitleNamesVertexCountAndRadius) {
  const Chain chain = exampleChain("steps");
  const std::string svg = hullToSvg(chain, scallopHull(chain, 0.5));
  EXPECT_NE(svg.find("n = " + std::to_string(chain.size())), std::string::npos);
  EXPECT_NE(svg.find("r = 0.5"), std::string::npos);
  const std::string straight = hullToSvg(chain, scallopHull(chain, kInfiniteRadius));
  EXPECT_NE(straight.find("r = \u221e"), std::string::npos);
  EXPECT_EQ(straight.find("class=\"toolpath\" d="), std::string::npos);
}

// The picture is drawn to fit the page, so scaling every length of the input by a power
// of two (exact in floating point) must give the same drawing byte for byte; only the
// length labels (title, scale bar) may differ.
std::string withoutLabels(const std::string& svg) {
  std::string out = std::regex_replace(svg, std::regex("<title>[^<]*</title>"), "<title/>");
  out = std::regex_replace(out, std::regex(">[^<]*</text>"), "></text>");
  return std::regex_replace(out, std::regex("<g class=\"scale\">[\\s\\S]*?</g>"), "<g/>");
}

ScallopHull scaledHull(ScallopHull result, double factor) {
  auto scale = [factor](Point2& p) { p = {p.x * factor, p.z * factor}; };
  result.radius *= factor;
  for (HullElement& element : result.hull) {
    scale(element.start);
    scale(element.end);
    scale(element.center);
  }
  for (PathElement& element : result.toolpath) {
    scale(element.start);
    scale(element.end);
    scale(element.center);
    element.radius *= factor;
  }
  return result;
}

TEST(HullOutputSvg, ScaleInvariantAndDeterministic) {
  const Chain chain = exampleChain("figure2");
  const ScallopHull result = scallopHull(chain, 1.0);
  const std::string reference = hullToSvg(chain, result);
  EXPECT_EQ(hullToSvg(chain, result), reference);
  for (const double factor : {0.25, 1024.0}) {
    Chain scaled = chain;
    for (Point2& p : scaled) p = {p.x * factor, p.z * factor};
    EXPECT_EQ(withoutLabels(hullToSvg(scaled, scaledHull(result, factor))),
              withoutLabels(reference))
        << "factor " << factor;
  }
}

TEST(HullOutputSvg, ExtremeAndDegenerateExtents) {
  std::vector<Chain> chains = {
      {{0.0, 0.0}, {0.0, 0.0}},                 // all points equal
      {{3.0, -2.0}, {3.0, -2.0}, {3.0, -2.0}},  // all equal, away from the origin
      {{0.0, 1.0}, {5.0, 1.0}},                 // zero height
      {{2.0, 0.0}, {2.0, 4.0}},                 // zero width
  };
  // Tiny, huge and far-from-origin versions of figure2.
  for (const double scale : {1e-9, 1e9}) {
    Chain scaled = exampleChain("figure2");
    for (Point2& p : scaled) p = {p.x * scale, p.z * scale};
    chains.push_back(scaled);
  }
  Chain shifted = exampleChain("figure2");
  for (Point2& p : shifted) p = {p.x + 1e6, p.z - 1e6};
  chains.push_back(shifted);

  for (const Chain& chain : chains) {
    const double extent = coordinateScale(chain) > 0.0 ? coordinateScale(chain) : 1.0;
    for (const double radius : {1e-3 * extent, 0.5 * extent, kInfiniteRadius}) {
      SCOPED_TRACE("chain of " + std::to_string(chain.size()) + " at scale " +
                   std::to_string(extent) + ", r = " + std::to_string(radius));
      const ScallopHull result = scallopHull(chain, radius);
      expectCleanSvg(hullToSvg(chain, result));
    }
  }
}

// ---------------------------------------------------------------------------------------
// Writing files
// ---------------------------------------------------------------------------------------

class HullOutputFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "scallop-out-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    directory_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string path(const std::string& name) const { return (directory_ / name).string(); }

  static std::string contents(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(directory_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  std::filesystem::path directory_;
};

TEST_F(HullOutputFiles, WritesAndReplacesLeavingNoTemporary) {
  std::string content = "first";
  content.push_back('\0');  // binary-safe
  content += "\nline";
  writeFileAtomically(path("a.json"), content);
  EXPECT_EQ(contents(path("a.json")), content);
  writeFileAtomically(path("a.json"), "second");
  EXPECT_EQ(contents(path("a.json")), "second");
  writeFileAtomically(path("empty"), "");
  EXPECT_EQ(contents(path("empty")), "");
  EXPECT_EQ(listing(), (std::vector<std::string>{"a.json", "empty"}));
}

TEST_F(HullOutputFiles, FailureNamesPathAndReasonAndLeavesNothing) {
  const std::string target = path("no-such-dir/out.svg");
  try {
    writeFileAtomically(target, "x");
    FAIL() << "wrote into a missing directory";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(target), std::string::npos) << message;
    EXPECT_NE(message.find(std::strerror(ENOENT)), std::string::npos) << message;
  }
  EXPECT_TRUE(listing().empty());
  // A directory in the way: the rename fails, the temporary must go.
  std::filesystem::create_directory(path("taken"));
  std::filesystem::create_directory(path("taken/inside"));
  EXPECT_THROW(writeFileAtomically(path("taken"), "x"), Error);
  EXPECT_EQ(listing(), (std::vector<std::string>{"taken"}));
}

TEST_F(HullOutputFiles, SeveralFilesAllOrNothing) {
  writeFileAtomically(path("a.json"), "old");
  const std::vector<OutputFile> outputs = {{path("a.json"), "new"}, {path("missing/b.svg"), "svg"}};
  EXPECT_THROW(writeFilesAtomically(outputs), Error);
  // The first target still holds its previous content: it was never replaced.
  EXPECT_EQ(contents(path("a.json")), "old");
  EXPECT_EQ(listing(), (std::vector<std::string>{"a.json"}));

  const std::vector<OutputFile> good = {{path("a.json"), "new"}, {path("b.svg"), "svg"}};
  writeFilesAtomically(good);
  EXPECT_EQ(contents(path("a.json")), "new");
  EXPECT_EQ(contents(path("b.svg")), "svg");
  EXPECT_EQ(listing(), (std::vector<std::string>{"a.json", "b.svg"}));
}

TEST_F(HullOutputFiles, SamePathTwiceIsAnError) {
  const std::vector<OutputFile> outputs = {{path("a"), "1"}, {path("a"), "2"}};
  EXPECT_THROW(writeFilesAtomically(outputs), Error);
  const std::vector<OutputFile> spelledTwoWays = {{path("a"), "1"}, {path("./a"), "2"}};
  EXPECT_THROW(writeFilesAtomically(spelledTwoWays), Error);
  EXPECT_TRUE(listing().empty());
}

}  // namespace
}  // namespace scallop
