#include "scallop/paths/path_sampling.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {
namespace {

// A bound on the points one arc may produce: a tolerance so small against the radius that
// it would need more is a caller's mistake, reported instead of exhausting memory.
constexpr double kMaxPiecesPerArc = 1 << 24;

void checkTolerance(double tolerance) {
  if (!std::isfinite(tolerance) || !(tolerance > 0.0)) {
    throw Error(
        fmt::format("path sampling tolerance must be a positive finite number, got {}", tolerance));
  }
}

void appendDistinct(std::vector<Point2>& polyline, const Point2& p) {
  if (polyline.empty() || !(polyline.back() == p)) polyline.push_back(p);
}

// Clockwise sweep from the start to the end direction, in [0, 2*pi): scallopHull's arcs
// turn clockwise (x right, z up).
double clockwiseSweep(const PathElement& arc) {
  const double startAngle = std::atan2(arc.start.z - arc.center.z, arc.start.x - arc.center.x);
  const double endAngle = std::atan2(arc.end.z - arc.center.z, arc.end.x - arc.center.x);
  double sweep = startAngle - endAngle;
  if (sweep < 0.0) sweep += 2.0 * std::numbers::pi;
  return sweep;
}

// The largest angle one polygon edge pair may cover: a tangent polygon with vertices at
// angle phi apart reaches r / cos(phi / 2) = r + t at its corners. Written as
// tan(phi / 2) = sqrt(t (2r + t)) / r, which keeps its accuracy when t << r (the acos form
// of the same relation cancels).
double maxPieceAngle(double radius, double tolerance) {
  return 2.0 * std::atan(std::sqrt(tolerance * (2.0 * radius + tolerance)) / radius);
}

std::size_t pieceCount(double sweep, double radius, double tolerance) {
  const double pieces = std::ceil(sweep / maxPieceAngle(radius, tolerance));
  if (!(pieces <= kMaxPiecesPerArc)) {
    throw Error(fmt::format(
        "path sampling tolerance {} is too small for an arc of radius {}: it would need more "
        "than {} points",
        tolerance, radius, kMaxPiecesPerArc));
  }
  return std::max<std::size_t>(1, static_cast<std::size_t>(pieces));
}

// True for an arc like scallopHull's: clockwise over the top of its circle from left to
// right (both ends on or, by rounding, just below the centre's height), so that x never
// decreases along it.
bool isUpperArcMovingRight(const PathElement& arc, double sweep) {
  const double slack = 1e-9 * arc.radius;
  return arc.start.x <= arc.end.x && sweep <= std::numbers::pi + 1e-9 &&
         arc.start.z >= arc.center.z - slack && arc.end.z >= arc.center.z - slack;
}

// Appends the corners of the circumscribed polygon of `arc` (not its end points): the
// tangent lines at the start, at every piece boundary and at the end meet at the pieces'
// mid-angles, at distance r / cos(half a piece) from the centre.
void appendArcCorners(std::vector<Point2>& polyline, const PathElement& arc, double tolerance) {
  const double sweep = clockwiseSweep(arc);
  if (sweep == 0.0) return;  // a degenerate arc: start and end in one direction
  const double r = arc.radius;
  const std::size_t pieces = pieceCount(sweep, r, tolerance);
  const double piece = sweep / static_cast<double>(pieces);
  const double cornerRadius = r / std::cos(0.5 * piece);
  const double startAngle = std::atan2(arc.start.z - arc.center.z, arc.start.x - arc.center.x);
  // Along an upper arc x must not decrease; rounding in cos() could push a corner next to
  // a vertical tangent (at the arc's leftmost or rightmost point) one ulp past its
  // neighbour, so corners are clamped into the arc's x range in order.
  const bool movingRight = isUpperArcMovingRight(arc, sweep);
  for (std::size_t k = 0; k < pieces; ++k) {
    const double angle = startAngle - (static_cast<double>(k) + 0.5) * piece;
    Point2 corner{arc.center.x + cornerRadius * std::cos(angle),
                  arc.center.z + cornerRadius * std::sin(angle)};
    if (movingRight) corner.x = std::clamp(corner.x, polyline.back().x, arc.end.x);
    appendDistinct(polyline, corner);
  }
}

}  // namespace

std::vector<Point2> samplePath(std::span<const PathElement> toolpath, double tolerance) {
  checkTolerance(tolerance);
  std::vector<Point2> polyline;
  for (const PathElement& element : toolpath) {
    appendDistinct(polyline, element.start);
    if (element.kind == PathElementKind::arc) appendArcCorners(polyline, element, tolerance);
    appendDistinct(polyline, element.end);
  }
  return polyline;
}

}  // namespace scallop
