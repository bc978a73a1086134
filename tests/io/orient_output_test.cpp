// Tests for orient_output.hpp: the JSON holds every documented key, in order, and every
// number bit for bit; the figures are well-formed, fixed-point only, deterministic, and put
// the optimal circle where the geometry says (recovered from the page coordinates, not from
// the code that wrote them); degenerate results (a plane, a curve) and non-finite input are
// handled. The library results are computed once, at a coarse tolerance (1 degree): the
// outputs, not the optimum, are under test here.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scallop/error.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/io/orient_output.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

using Json = nlohmann::json;
constexpr double kPi = std::numbers::pi;
constexpr double kToleranceDeg = 1.0;

const OptimalSlicing& exampleResult(const std::string& name) {
  static const OptimalSlicing paper1 = [] {
    OptimalSlicingOptions options;
    options.toleranceRad = kToleranceDeg * kPi / 180.0;
    return optimalSlicing(exampleSurface("paper-1"), options);
  }();
  static const OptimalSlicing paper2 = [] {
    OptimalSlicingOptions options;
    options.toleranceRad = kToleranceDeg * kPi / 180.0;
    return optimalSlicing(exampleSurface("paper-2"), options);
  }();
  return name == "paper-1" ? paper1 : paper2;
}

// A plane: Omega is {p, -p}, every direction orthogonal to p is optimal (alpha* = 90).
OptimalSlicing planeResult() {
  OptimalSlicing result;
  result.method = SlicingMethod::plane;
  result.gaussMap.kind = GaussMapKind::point;
  result.pole = result.gaussMap.pole = {0.0, 0.0, 1.0};
  result.normal = {1.0, 0.0, 0.0};
  result.alphaRad = kPi / 2.0;
  result.sphereCircle = {result.normal, result.alphaRad};
  return result;
}

// A cylinder-like Gauss image: an arc of normals through the pole (0, 0, 1), so that its
// stereographic image runs off to infinity.
OptimalSlicing curveResult() {
  OptimalSlicing result;
  result.method = SlicingMethod::curve;
  result.gaussMap.kind = GaussMapKind::curve;
  result.pole = result.gaussMap.pole = {0.0, 0.0, 1.0};
  std::vector<Vec3> arc;
  for (int k = 0; k <= 8; ++k) {
    const double t = kPi / 4.0 + kPi / 2.0 * k / 8.0;  // k = 4: t = pi/2, the pole
    arc.push_back({std::cos(t), 0.0, std::sin(t)});
  }
  result.gaussMap.sphereCurves = {arc};
  result.normal = {0.0, 1.0, 0.0};
  result.alphaRad = kPi / 2.0;
  result.sphereCircle = {result.normal, result.alphaRad};
  return result;
}

std::uint64_t bitsOf(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

void expectSameDouble(const Json& value, double expected, const std::string& where) {
  ASSERT_TRUE(value.is_number()) << where << ": " << value.dump();
  EXPECT_EQ(bitsOf(value.get<double>()), bitsOf(expected))
      << where << ": " << value.dump() << " vs " << expected;
}

void expectSameVec3(const Json& value, const Vec3& expected, const std::string& where) {
  ASSERT_TRUE(value.is_array() && value.size() == 3) << where << ": " << value.dump();
  expectSameDouble(value[0], expected.x, where + "[0]");
  expectSameDouble(value[1], expected.y, where + "[1]");
  expectSameDouble(value[2], expected.z, where + "[2]");
}

// ---------------------------------------------------------------------------------------
// JSON
// ---------------------------------------------------------------------------------------

TEST(OrientJson, EveryKeyInOrderAndEveryNumberBitForBit) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const OptimalSlicing& result = exampleResult(name);
    const std::string text = orientationToJson(result, kToleranceDeg);

    const nlohmann::ordered_json ordered = nlohmann::ordered_json::parse(text);
    std::vector<std::string> keys;
    for (const auto& item : ordered.items()) keys.push_back(item.key());
    EXPECT_EQ(keys, (std::vector<std::string>{
                        "normal", "alpha_deg", "certified", "certified_alpha_deg",
                        "certificate_cells", "refuted_alpha_deg", "method", "circle",
                        "sphere_circle", "pole",
                        "tolerance_deg", "gauss_map", "medial_axis", "coverage"}));
    std::vector<std::string> medialKeys;
    for (const auto& item : ordered.at("medial_axis").items()) medialKeys.push_back(item.key());
    EXPECT_EQ(medialKeys, (std::vector<std::string>{"edges", "rebuilds", "segments", "refinements"}));

    const Json doc = Json::parse(text);
    expectSameVec3(doc.at("normal"), result.normal, "normal");
    expectSameDouble(doc.at("alpha_deg"), toDegrees(result.alphaRad), "alpha_deg");
    EXPECT_EQ(doc.at("certified").get<bool>(), result.certified);
    expectSameDouble(doc.at("certified_alpha_deg"), toDegrees(result.certifiedAlphaRad),
                     "certified_alpha_deg");
    EXPECT_EQ(doc.at("certificate_cells").get<std::size_t>(), result.certificateCells);
    EXPECT_EQ(doc.at("method").get<std::string>(), slicingMethodName(result.method));
    ASSERT_EQ(result.method, SlicingMethod::medialAxis);
    const Json& circle = doc.at("circle");
    ASSERT_TRUE(circle.at("center").is_array() && circle.at("center").size() == 2);
    expectSameDouble(circle.at("center")[0], result.circle.center.x, "circle.center[0]");
    expectSameDouble(circle.at("center")[1], result.circle.center.y, "circle.center[1]");
    expectSameDouble(circle.at("radius"), result.circle.radius, "circle.radius");
    expectSameVec3(doc.at("sphere_circle").at("center"), result.sphereCircle.center,
                   "sphere_circle.center");
    expectSameDouble(doc.at("sphere_circle").at("alpha_deg"),
                     toDegrees(result.sphereCircle.alphaRad), "sphere_circle.alpha_deg");
    expectSameVec3(doc.at("pole"), result.pole, "pole");
    expectSameDouble(doc.at("tolerance_deg"), kToleranceDeg, "tolerance_deg");
    const Json& gauss = doc.at("gauss_map");
    EXPECT_EQ(gauss.at("kind"), "region");
    EXPECT_EQ(gauss.at("loops").get<std::size_t>(), result.gaussMap.loops.size());
    EXPECT_EQ(gauss.at("boundary_segments").get<std::size_t>(),
              result.gaussMap.boundarySegments);
    EXPECT_EQ(gauss.at("parabolic_curves").get<std::size_t>(), result.gaussMap.parabolicCurves);
    EXPECT_EQ(gauss.at("traced_cells").get<std::size_t>(), result.gaussMap.tracedCells);
    EXPECT_EQ(gauss.at("fold_cells").get<std::size_t>(), result.gaussMap.foldCells);
    EXPECT_EQ(gauss.at("untraced_cells").get<std::size_t>(), result.gaussMap.untracedCells);
    EXPECT_EQ(gauss.at("candidate_pieces").get<std::size_t>(), result.gaussMap.candidatePieces);
    EXPECT_EQ(gauss.at("image_vertices").get<std::size_t>(), result.gaussMap.imageVertices);
    EXPECT_EQ(gauss.at("coarse_band").get<bool>(), result.gaussMap.coarseBandUsed);
    EXPECT_EQ(doc.at("medial_axis").at("edges").get<std::size_t>(), result.medialAxisEdges);
    EXPECT_EQ(doc.at("medial_axis").at("rebuilds").get<int>(), result.medialAxisRebuilds);
    EXPECT_EQ(doc.at("medial_axis").at("segments").get<std::size_t>(), result.medialAxisSegments);
    EXPECT_EQ(doc.at("medial_axis").at("refinements").get<int>(), result.medialAxisRefinements);
    EXPECT_GT(result.medialAxisSegments, 0u);
  }
}

TEST(OrientJson, NormalIsUnitAndAlphaInRange) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const Json doc = Json::parse(orientationToJson(exampleResult(name), kToleranceDeg));
    const Json& n = doc.at("normal");
    const double length = std::sqrt(n[0].get<double>() * n[0].get<double>() +
                                    n[1].get<double>() * n[1].get<double>() +
                                    n[2].get<double>() * n[2].get<double>());
    EXPECT_NEAR(length, 1.0, 1e-12);
    EXPECT_GT(doc.at("alpha_deg").get<double>(), 0.0);
    EXPECT_LE(doc.at("alpha_deg").get<double>(), 90.0);
    EXPECT_LE(doc.at("certified_alpha_deg").get<double>(), doc.at("alpha_deg").get<double>());
  }
}

TEST(OrientJson, DegenerateGaussImagesHaveNoPlaneCircle) {
  for (const OptimalSlicing& result : {planeResult(), curveResult()}) {
    SCOPED_TRACE(slicingMethodName(result.method));
    const Json doc = Json::parse(orientationToJson(result, 0.25));
    EXPECT_TRUE(doc.at("circle").is_null());
    EXPECT_EQ(doc.at("method"), slicingMethodName(result.method));
    EXPECT_EQ(doc.at("gauss_map").at("kind"), result.method == SlicingMethod::plane ? "point" : "curve");
    EXPECT_EQ(doc.at("alpha_deg").get<double>(), 90.0);
  }
}

// ---------------------------------------------------------------------------------------
// SVG: well-formed, fixed-point
// ---------------------------------------------------------------------------------------

// "" if every tag is closed in order, there is one root and no stray '&'; else the problem.
std::string tagProblems(const std::string& svg) {
  if (svg.rfind("<svg", 0) != 0) return "does not start with <svg";
  std::vector<std::string> open;
  bool sawRoot = false;
  std::size_t pos = 0;
  while ((pos = svg.find('<', pos)) != std::string::npos) {
    const std::size_t end = svg.find('>', pos);
    if (end == std::string::npos) return "unterminated tag";
    const std::string tag = svg.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty()) return "empty tag";
    if (tag.front() == '/') {
      if (open.empty() || open.back() != tag.substr(1)) return "mismatched </" + tag.substr(1) + ">";
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
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  std::string lower = svg;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  EXPECT_FALSE(std::regex_search(lower, std::regex("\\bnan\\b|\\binf(inity)?\\b")));
  EXPECT_FALSE(std::regex_search(svg, std::regex("[0-9.][eE][-+]?[0-9]")));
  EXPECT_EQ(svg.find("e+"), std::string::npos);
}

TEST(OrientSvg, FiguresAreWellFormedFixedPointAndDeterministic) {
  std::vector<std::pair<std::string, OptimalSlicing>> cases = {
      {"paper-1", exampleResult("paper-1")},
      {"paper-2", exampleResult("paper-2")},
      {"plane", planeResult()},
      {"curve", curveResult()}};
  for (const auto& [name, result] : cases) {
    SCOPED_TRACE(name);
    const std::string sphere = gaussMapSphereSvg(result);
    const std::string plane = stereographicSvg(result);
    expectCleanSvg(sphere);
    expectCleanSvg(plane);
    EXPECT_EQ(gaussMapSphereSvg(result), sphere);
    EXPECT_EQ(stereographicSvg(result), plane);
    // The optimal circle is drawn on the sphere (at least its near half) and N* marked.
    EXPECT_NE(sphere.find("<path class=\"circle\""), std::string::npos);
    EXPECT_NE(sphere.find("<circle class=\"centre\""), std::string::npos);
    EXPECT_NE(plane.find("<circle class=\"unit\""), std::string::npos);
    if (result.method == SlicingMethod::medialAxis) {
      EXPECT_NE(plane.find("<circle class=\"circle\""), std::string::npos);
      EXPECT_NE(plane.find("<path class=\"medial\""), std::string::npos);
      EXPECT_NE(plane.find("<path class=\"omega\""), std::string::npos);
    }
  }
}

// printf-style formatting of one number.
std::string formatted(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

TEST(OrientSvg, TitlesGiveNStarAndAlphaStar) {
  const OptimalSlicing& result = exampleResult("paper-2");
  const std::string sphere = gaussMapSphereSvg(result);
  const std::string alpha = formatted("%.3f", toDegrees(result.alphaRad)) + "\u00b0";
  EXPECT_NE(sphere.find("\u03b1* = " + alpha), std::string::npos);
  // N* to four decimals, with true minus signs.
  const std::string x = formatted("%.4f", result.normal.x);
  const std::string shown = x.front() == '-' ? std::string("\u2212").append(x, 1) : x;
  EXPECT_NE(sphere.find("N* = (" + shown + ", "), std::string::npos) << shown;
  EXPECT_NE(stereographicSvg(result).find(alpha), std::string::npos);
}

// A surface whose normals cover the sphere (the whole teapot, proven): the figures say so,
// shade the whole sphere (Omega has no boundary: one shaded disk per view), and draw no
// boundary; the JSON carries the proof.
TEST(OrientSvg, CoveredSphereSaysSoAndIsShadedWhole) {
  const OptimalSlicing result = scallop::optimalSlicing(scallop::exampleSurface("teapot"));
  ASSERT_EQ(result.method, SlicingMethod::covered);
  const std::string sphere = gaussMapSphereSvg(result);
  EXPECT_NE(sphere.find("it covers the whole sphere, so no slicing direction exists"), std::string::npos);
  std::size_t shaded = 0;
  const std::string fill = "<path class=\"omega\" clip-path";  // a panel's shading
  for (std::size_t at = sphere.find(fill); at != std::string::npos; at = sphere.find(fill, at + 1)) {
    ++shaded;
  }
  EXPECT_EQ(shaded, 2u);
  EXPECT_NE(stereographicSvg(result).find("covers the whole plane (proven)"), std::string::npos);
  const Json doc = Json::parse(orientationToJson(result, 0.5));
  EXPECT_EQ(doc.at("method"), "covered");
  EXPECT_TRUE(doc.at("coverage").at("proven").get<bool>());
  EXPECT_EQ(doc.at("alpha_deg").get<double>(), 0.0);
}

TEST(OrientSvg, NonFiniteInputIsAnErrorNotAPicture) {
  OptimalSlicing result = exampleResult("paper-2");
  result.normal.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(gaussMapSphereSvg(result), Error);
  EXPECT_THROW(stereographicSvg(result), Error);
  result = exampleResult("paper-2");
  ASSERT_FALSE(result.gaussMap.loops.empty());
  result.gaussMap.loops.front().front().x = std::numeric_limits<double>::infinity();
  EXPECT_THROW(stereographicSvg(result), Error);
}

// ---------------------------------------------------------------------------------------
// SVG: the circle is where the geometry says
// ---------------------------------------------------------------------------------------

struct PageCircle {
  double cx = 0.0;
  double cy = 0.0;
  double r = 0.0;
};

std::vector<PageCircle> circlesOfClass(const std::string& svg, const std::string& cssClass) {
  std::vector<PageCircle> circles;
  const std::regex pattern("<circle class=\"" + cssClass +
                           "\" cx=\"([-0-9.]+)\" cy=\"([-0-9.]+)\" r=\"([-0-9.]+)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), pattern);
       it != std::sregex_iterator(); ++it) {
    circles.push_back({std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3])});
  }
  return circles;
}

std::vector<std::pair<double, double>> pathPoints(const std::string& svg, const std::string& cssClass) {
  std::vector<std::pair<double, double>> points;
  const std::regex pattern("<path class=\"" + cssClass + "\" d=\"([^\"]*)\"");
  std::smatch match;
  if (!std::regex_search(svg, match, pattern)) return points;
  const std::string d = match[1];
  const std::regex pair("([-0-9.]+),([-0-9.]+)");
  for (auto it = std::sregex_iterator(d.begin(), d.end(), pair); it != std::sregex_iterator();
       ++it) {
    points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  }
  return points;
}

// In each panel, the unit circle fixes the page transform (its centre is the origin, its
// radius one plane unit); the optimal circle must then have the result's centre and radius.
TEST(OrientSvg, PlaneCircleMatchesTheResultInBothPanels) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const OptimalSlicing& result = exampleResult(name);
    const std::string svg = stereographicSvg(result);
    const std::vector<PageCircle> units = circlesOfClass(svg, "unit");
    const std::vector<PageCircle> circles = circlesOfClass(svg, "circle");
    ASSERT_EQ(units.size(), 2u);
    ASSERT_EQ(circles.size(), 2u);
    for (std::size_t panel = 0; panel < 2; ++panel) {
      const double scale = units[panel].r;
      const double slack = 2e-3 * (1.0 + std::abs(result.circle.center.x) +
                                   std::abs(result.circle.center.y) + result.circle.radius);
      EXPECT_NEAR(circles[panel].cx, units[panel].cx + scale * result.circle.center.x, slack);
      EXPECT_NEAR(circles[panel].cy, units[panel].cy - scale * result.circle.center.y, slack);
      EXPECT_NEAR(circles[panel].r, scale * result.circle.radius, slack);
    }
    // The second panel magnifies.
    EXPECT_GT(units[1].r, units[0].r);
  }
}

// Visible points of the sphere figure, lifted back to the sphere in the view's frame
// (orthographic: depth = sqrt(1 - a^2 - b^2)), must lie at angle alpha* from N* for the
// circle, and no closer than alpha* less the Gauss map's tolerance to +-N* for the
// boundary of Omega.
TEST(OrientSvg, SphereCircleLiesAtAlphaStarFromNStar) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const OptimalSlicing& result = exampleResult(name);
    const std::string svg = gaussMapSphereSvg(result);
    const std::vector<PageCircle> spheres = circlesOfClass(svg, "sphere");
    const std::vector<PageCircle> centres = circlesOfClass(svg, "centre");
    ASSERT_EQ(spheres.size(), 2u);
    ASSERT_GE(centres.size(), 2u);  // N* in each panel (then the legend's swatch)
    // Only the first panel's paths are checked: cut the document at the second sphere.
    const std::string firstPanel = svg.substr(0, svg.find("<circle class=\"sphere\"",
                                                          svg.find("<circle class=\"sphere\"") + 1));
    const PageCircle& sphere = spheres[0];
    auto lift = [&](double x, double y) {
      const double a = (x - sphere.cx) / sphere.r;
      const double b = (sphere.cy - y) / sphere.r;
      return Vec3{a, b, std::sqrt(std::max(0.0, 1.0 - a * a - b * b))};
    };
    const Vec3 nStar = lift(centres[0].cx, centres[0].cy);
    // Both views are tilted 45 degrees from N*.
    EXPECT_NEAR(std::acos(nStar.z), kPi / 4.0, 1e-4);

    const std::vector<std::pair<double, double>> circle = pathPoints(firstPanel, "circle");
    ASSERT_GT(circle.size(), 90u);
    std::size_t checked = 0;
    for (const auto& [x, y] : circle) {
      const Vec3 v = lift(x, y);
      if (v.z < 0.3) continue;  // near the outline the lift is ill-conditioned
      EXPECT_NEAR(std::acos(std::clamp(dot(v, nStar), -1.0, 1.0)), result.alphaRad, 2e-4);
      ++checked;
    }
    EXPECT_GT(checked, 30u);

    const std::vector<std::pair<double, double>> boundary = pathPoints(firstPanel, "boundary");
    ASSERT_FALSE(boundary.empty());
    const double margin = (kToleranceDeg + 0.5) * kPi / 180.0;
    for (const auto& [x, y] : boundary) {
      const Vec3 v = lift(x, y);
      if (v.z < 0.3) continue;
      EXPECT_GE(std::acos(std::min(1.0, std::abs(dot(v, nStar)))), result.alphaRad - margin);
    }
  }
}

}  // namespace
}  // namespace scallop
