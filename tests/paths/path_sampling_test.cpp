// Tests for path_sampling.hpp: the circumscribed polyline never enters an arc's circle,
// stays within the tolerance outside it, keeps lines and end points exactly, and on real
// tool paths keeps its distance to the chain within [r, r + t].

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "scallop/paths/chain.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/path_sampling.hpp"
#include "scallop/paths/scallop_hull.hpp"

namespace scallop {
namespace {

constexpr double kPi = std::numbers::pi;

double distance(Point2 a, Point2 b) { return std::hypot(a.x - b.x, a.z - b.z); }

double pointSegmentDistance(Point2 p, Point2 a, Point2 b) {
  const double dx = b.x - a.x;
  const double dz = b.z - a.z;
  const double length2 = dx * dx + dz * dz;
  double t = length2 > 0.0 ? ((p.x - a.x) * dx + (p.z - a.z) * dz) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return distance(p, {a.x + t * dx, a.z + t * dz});
}

double cross(Point2 o, Point2 a, Point2 b) {
  return (a.x - o.x) * (b.z - o.z) - (a.z - o.z) * (b.x - o.x);
}

// Distance between two segments: 0 if they cross, else the least end-point distance.
double segmentDistance(Point2 a, Point2 b, Point2 c, Point2 d) {
  const double d1 = cross(a, b, c);
  const double d2 = cross(a, b, d);
  const double d3 = cross(c, d, a);
  const double d4 = cross(c, d, b);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
    return 0.0;
  }
  return std::min({pointSegmentDistance(a, c, d), pointSegmentDistance(b, c, d),
                   pointSegmentDistance(c, a, b), pointSegmentDistance(d, a, b)});
}

PathElement upperArc(Point2 centre, double r, double startAngle, double endAngle) {
  PathElement arc;
  arc.kind = PathElementKind::arc;
  arc.center = centre;
  arc.radius = r;
  arc.clockwise = true;
  arc.start = {centre.x + r * std::cos(startAngle), centre.z + r * std::sin(startAngle)};
  arc.end = {centre.x + r * std::cos(endAngle), centre.z + r * std::sin(endAngle)};
  return arc;
}

TEST(PathSampling, RejectsToleranceThatIsNotPositiveAndFinite) {
  const std::vector<PathElement> path = {upperArc({0, 0}, 1.0, kPi, 0.0)};
  for (const double bad : {0.0, -0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(samplePath(path, bad), Error) << bad;
  }
  // Even for an empty path: the tolerance is checked first.
  EXPECT_THROW(samplePath({}, 0.0), Error);
  EXPECT_TRUE(samplePath({}, 0.1).empty());
}

TEST(PathSampling, KeepsLinesExactly) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> step(0.0, 3.0);
  std::uniform_real_distribution<double> height(-5.0, 5.0);
  std::vector<PathElement> path;
  std::vector<Point2> expected = {{-1.0, 0.3}};
  for (int i = 0; i < 50; ++i) {
    PathElement line;
    line.start = expected.back();
    // Every fifth line is vertical, as where the ball slides down a vertical edge.
    line.end = {line.start.x + (i % 5 == 0 ? 0.0 : step(rng)), height(rng)};
    path.push_back(line);
    expected.push_back(line.end);
  }
  const std::vector<Point2> polyline = samplePath(path, 1e-3);
  ASSERT_EQ(polyline.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(polyline[i], expected[i]) << i;
  }
}

// The property the header promises, for random upper arcs (clockwise over the top, from
// angle a to angle b <= a, both in [0, pi]) of every size, at every tolerance.
TEST(PathSampling, RandomArcsAreCircumscribedWithinTolerance) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 3000; ++trial) {
    const Point2 centre{200.0 * unit(rng) - 100.0, 200.0 * unit(rng) - 100.0};
    const double r = std::pow(10.0, 6.0 * unit(rng) - 3.0);
    double startAngle = kPi * unit(rng);
    double endAngle = startAngle * unit(rng);
    // The tool path's own shapes: end quarter-arcs and a half turn over a needle.
    if (trial % 10 == 0) {
      startAngle = kPi;
      endAngle = 0.5 * kPi;
    }
    if (trial % 10 == 1) {
      startAngle = 0.5 * kPi;
      endAngle = 0.0;
    }
    if (trial % 10 == 2) {
      startAngle = kPi;
      endAngle = 0.0;
    }
    const double tolerance = r * std::pow(10.0, 8.0 * unit(rng) - 8.0);
    const PathElement arc = upperArc(centre, r, startAngle, endAngle);
    SCOPED_TRACE("trial " + std::to_string(trial));

    const std::vector<Point2> polyline = samplePath(std::span(&arc, 1), tolerance);
    ASSERT_GE(polyline.size(), 2u);
    EXPECT_EQ(polyline.front(), arc.start);
    EXPECT_EQ(polyline.back(), arc.end);

    const double eps = 1e-12 * std::max({r, std::abs(centre.x), std::abs(centre.z)});
    for (std::size_t i = 0; i < polyline.size(); ++i) {
      EXPECT_LE(distance(polyline[i], centre), r + tolerance + eps) << "vertex " << i;
      if (i == 0) continue;
      EXPECT_FALSE(polyline[i] == polyline[i - 1]) << "repeated vertex " << i;
      EXPECT_GE(polyline[i].x, polyline[i - 1].x) << "x decreases at vertex " << i;
      EXPECT_GE(pointSegmentDistance(centre, polyline[i - 1], polyline[i]), r - eps)
          << "segment " << i << " enters the circle";
    }
    // No more corners than the tolerance requires: a tangent polygon edge pair may span
    // phi = 2 acos(r / (r + t)); one extra for rounding at the boundary.
    const double phi = 2.0 * std::acos(r / (r + tolerance));
    if (phi > 1e-6) {
      const double corners = static_cast<double>(polyline.size()) - 2.0;
      EXPECT_LE(corners, std::ceil((startAngle - endAngle) / phi) + 1.0);
    }
  }
}

TEST(PathSampling, DegenerateArcAddsNoPoints) {
  PathElement arc = upperArc({1.0, 1.0}, 2.0, 1.0, 1.0);
  arc.end = arc.start;
  const std::vector<Point2> polyline = samplePath(std::span(&arc, 1), 0.01);
  ASSERT_EQ(polyline.size(), 1u);
  EXPECT_EQ(polyline.front(), arc.start);
}

TEST(PathSampling, ToleranceTooSmallForTheRadiusIsAnError) {
  const PathElement arc = upperArc({0.0, 0.0}, 1.0, kPi, 0.0);
  EXPECT_THROW(samplePath(std::span(&arc, 1), 1e-300), Error);
}

// On real tool paths: the polyline starts and ends with the path, contains every line's
// end points in order, and its distance to the chain stays within [r - eps, r + t + eps]
// (the path is at distance r everywhere; the polyline lies outside it, within t).
TEST(PathSampling, RealPathsKeepClearanceFromTheChain) {
  for (const std::string& name : exampleChainNames()) {
    const Chain chain = exampleChain(name);
    for (const double r : {0.3, 1.0, 2.5}) {
      for (const double tolerance : {1e-4, 0.05}) {
        SCOPED_TRACE(name + " r=" + std::to_string(r) + " t=" + std::to_string(tolerance));
        const ScallopHull result = scallopHull(chain, r);
        ASSERT_FALSE(result.toolpath.empty());
        const std::vector<Point2> polyline = samplePath(result.toolpath, tolerance);
        EXPECT_EQ(polyline.front(), result.toolpath.front().start);
        EXPECT_EQ(polyline.back(), result.toolpath.back().end);

        std::size_t cursor = 0;
        for (const PathElement& element : result.toolpath) {
          if (element.kind != PathElementKind::line) continue;
          const auto found = std::find(polyline.begin() + static_cast<std::ptrdiff_t>(cursor),
                                       polyline.end(), element.end);
          ASSERT_NE(found, polyline.end()) << "line end missing from the polyline";
          cursor = static_cast<std::size_t>(found - polyline.begin());
        }

        const double eps = 1e-11 * std::max(r, coordinateScale(chain));
        for (std::size_t i = 0; i < polyline.size(); ++i) {
          double nearest = std::numeric_limits<double>::infinity();
          double nearestSegment = std::numeric_limits<double>::infinity();
          for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
            nearest = std::min(nearest, pointSegmentDistance(polyline[i], chain[k], chain[k + 1]));
            if (i > 0) {
              nearestSegment =
                  std::min(nearestSegment,
                           segmentDistance(polyline[i - 1], polyline[i], chain[k], chain[k + 1]));
            }
          }
          EXPECT_LE(nearest, r + tolerance + eps) << "vertex " << i;
          if (i > 0) {
            EXPECT_GE(nearestSegment, r - eps) << "segment " << i;
            EXPECT_FALSE(polyline[i] == polyline[i - 1]) << "repeated vertex " << i;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace scallop
