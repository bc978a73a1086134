#include "scallop/paths/toolpath.hpp"

#include <cmath>
#include <numbers>

namespace scallop {

ArcGeometry arcGeometry(Vec3 start, const ToolMove& arc) {
  ArcGeometry out;
  out.plane = arc.plane;
  out.center = arc.center;
  const Vec3 a = toArcPlane(arc.plane, start - arc.center);
  const Vec3 b = toArcPlane(arc.plane, arc.end - arc.center);
  out.radius = 0.5 * (std::hypot(a.x, a.y) + std::hypot(b.x, b.y));
  out.startAngle = std::atan2(a.y, a.x);
  double sweep = std::atan2(b.y, b.x) - out.startAngle;
  const double turn = 2.0 * std::numbers::pi;
  if (arc.clockwise) {
    while (sweep >= 0.0) sweep -= turn;
  } else {
    while (sweep <= 0.0) sweep += turn;
  }
  out.sweep = sweep;
  out.startLevel = a.z;
  out.endLevel = b.z;
  return out;
}

Vec3 pointOnArc(const ArcGeometry& arc, double t) {
  const double angle = arc.startAngle + t * arc.sweep;
  const Vec3 local{arc.radius * std::cos(angle), arc.radius * std::sin(angle),
                   arc.startLevel + t * (arc.endLevel - arc.startLevel)};
  return arc.center + fromArcPlane(arc.plane, local);
}

double moveLength(Vec3 start, const ToolMove& move) {
  if (move.kind == MoveKind::line) return norm(move.end - start);
  const ArcGeometry arc = arcGeometry(start, move);
  return std::hypot(arc.radius * arc.sweep, arc.endLevel - arc.startLevel);
}

Vec3 passEnd(const ToolPass& pass) { return pass.moves.empty() ? pass.start : pass.moves.back().end; }

ToolPass reversedPass(const ToolPass& pass) {
  ToolPass out;
  out.retractBefore = pass.retractBefore;
  out.start = passEnd(pass);
  for (std::size_t i = pass.moves.size(); i-- > 0;) {
    ToolMove move = pass.moves[i];
    move.end = i == 0 ? pass.start : pass.moves[i - 1].end;
    if (move.kind == MoveKind::arc) move.clockwise = !move.clockwise;
    out.moves.push_back(move);
  }
  return out;
}

}  // namespace scallop
