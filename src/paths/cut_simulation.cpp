#include "scallop/paths/cut_simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <limits>
#include <numbers>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/paths/mesh_raster.hpp"
#include "scallop/parallel.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

bool finite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// The lowest point of a ball centred at c above (x, y): +inf out of reach.
double ballLowest(Vec3 c, double radius2, double x, double y) {
  const double dx = x - c.x, dy = y - c.y;
  const double rho2 = dx * dx + dy * dy;
  if (rho2 > radius2) return kInf;
  return c.z - std::sqrt(radius2 - rho2);
}

// A line from a to b. g(t) = c_z(t) - sqrt(R^2 - rho(t)^2) is convex in t (rho is a convex
// distance, and -sqrt(R^2 - rho^2) convex and increasing in rho >= 0). With p at horizontal
// coordinates (s_p along the line's xy direction from a, e across it), rho^2 = e^2 +
// (s - s_p)^2 and g'(s) = 0 gives s - s_p = -dz k / L (k = sqrt(R^2 - e^2), L the 3D length,
// dz the rise): the stationary point, clamped to the segment, is the minimiser. Its centre,
// or nullopt when p lies more than R across the line (out of reach of every position).
std::optional<Vec3> lineMinimiser(Vec3 a, Vec3 b, double radius, double x, double y) {
  const double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
  const double h2 = dx * dx + dy * dy;
  if (h2 == 0.0) return dz > 0.0 ? a : b;  // vertical or a point: its lowest end
  const double h = std::sqrt(h2);
  const double wx = x - a.x, wy = y - a.y;
  const double along = (wx * dx + wy * dy) / h;
  const double across = (dx * wy - dy * wx) / h;
  if (std::abs(across) > radius) return std::nullopt;
  const double k = std::sqrt(radius * radius - across * across);
  const double s = along - dz * k / std::sqrt(h2 + dz * dz);
  if (s <= 0.0) return a;
  if (s >= h) return b;
  const double t = s / h;
  return Vec3{a.x + t * dx, a.y + t * dy, a.z + t * dz};
}

// The lowest point of the ball swept along the line above (x, y): +inf out of reach.
double lineLowest(Vec3 a, Vec3 b, double radius, double x, double y) {
  const std::optional<Vec3> centre = lineMinimiser(a, b, radius, x, y);
  return centre ? ballLowest(*centre, radius * radius, x, y) : kInf;
}

// The centre at which lineLowest's minimum is attained, or nullopt out of reach.
std::optional<Vec3> lineLowestCentre(Vec3 a, Vec3 b, double radius, double x, double y) {
  const std::optional<Vec3> centre = lineMinimiser(a, b, radius, x, y);
  if (!centre || ballLowest(*centre, radius * radius, x, y) == kInf) return std::nullopt;
  return centre;
}

// An arc in its plane's frame (toArcPlane): centre (c1, c2), radius r (the mean of the two
// ends' distances), angle theta = a0 + dir phi for phi in [0, sweep], normal coordinate
// n0 + dn phi / sweep.
struct Arc {
  ArcPlane plane = ArcPlane::xy;
  double c1 = 0.0, c2 = 0.0, r = 0.0, a0 = 0.0, dir = 1.0, sweep = kTwoPi, n0 = 0.0, dn = 0.0;

  explicit Arc(const SweptMove& move) : plane(move.plane) {
    const Vec3 s = toArcPlane(plane, move.start);
    const Vec3 e = toArcPlane(plane, move.end);
    const Vec3 c = toArcPlane(plane, move.center);
    c1 = c.x;
    c2 = c.y;
    r = 0.5 * (std::hypot(s.x - c1, s.y - c2) + std::hypot(e.x - c1, e.y - c2));
    a0 = std::atan2(s.y - c2, s.x - c1);
    dir = move.clockwise ? -1.0 : 1.0;
    const double a1 = std::atan2(e.y - c2, e.x - c1);
    sweep = std::fmod(dir * (a1 - a0), kTwoPi);
    if (sweep < 0.0) sweep += kTwoPi;
    if (sweep == 0.0) sweep = kTwoPi;  // the ends coincide: a full circle, as RS-274
    n0 = s.z;
    dn = e.z - s.z;
  }

  Vec3 at(double phi) const {
    const double theta = a0 + dir * phi;
    return fromArcPlane(plane, {c1 + r * std::cos(theta), c2 + r * std::sin(theta), n0 + dn * (phi / sweep)});
  }

  // phi of the angle theta when the arc passes there.
  std::optional<double> phiOf(double theta) const {
    double phi = std::fmod(dir * (theta - a0), kTwoPi);
    if (phi < 0.0) phi += kTwoPi;
    if (phi <= sweep) return phi;
    return std::nullopt;
  }
};

double flatArcLowest(const Arc& arc, double radius, double x, double y) {
  const double radius2 = radius * radius;
  double best = std::min(ballLowest(arc.at(0.0), radius2, x, y), ballLowest(arc.at(arc.sweep), radius2, x, y));
  auto candidate = [&](double theta) {
    if (const auto phi = arc.phiOf(theta)) best = std::min(best, ballLowest(arc.at(*phi), radius2, x, y));
  };
  if (arc.plane == ArcPlane::xy) {
    // z is constant: the lowest point is above the arc point nearest to (x, y).
    if (x != arc.c1 || y != arc.c2) candidate(std::atan2(y - arc.c2, x - arc.c1));
    return best;
  }
  // A vertical plane: h the horizontal in-plane axis (x for G18, y for G19).
  const Vec3 centre = fromArcPlane(arc.plane, {arc.c1, arc.c2, arc.n0});
  const bool zx = arc.plane == ArcPlane::zx;
  const double offset = zx ? y - centre.y : x - centre.x;
  const double k2 = radius2 - offset * offset;
  if (k2 < 0.0) return kInf;
  const double k = std::sqrt(k2);
  const double t = (zx ? x - centre.x : y - centre.y);
  for (const double sign : {1.0, -1.0}) {
    // The lowest point q = C + (r + sign k) u(psi) with q_h = p_h, the ball's offset
    // sign k u(psi) pointing down: sin(psi) <= 0 for the outer circle, >= 0 for the inner.
    const double den = arc.r + sign * k;
    if (den == 0.0 || std::abs(t) > std::abs(den)) continue;
    const double cosPsi = std::clamp(t / den, -1.0, 1.0);
    const double sinPsi = -sign * std::sqrt(std::max(0.0, 1.0 - cosPsi * cosPsi));
    const Vec3 u = zx ? Vec3{cosPsi, 0.0, sinPsi} : Vec3{0.0, cosPsi, sinPsi};
    const Vec3 f = toArcPlane(arc.plane, u);
    candidate(std::atan2(f.y, f.x));
  }
  return best;
}

// A helix in G17: z = z0 + kappa phi over the circle. With psi = theta - theta_p (theta_p
// the angle of p about the centre, D its distance), rho^2 = D^2 + r^2 - 2 r D cos(psi), so
// g = z0 + kappa phi - sqrt(S), S = A + B cos(psi), A = R^2 - D^2 - r^2, B = 2 r D, and
// g' = 0 reads 2 kappa sqrt(S) = -B dir sin(psi); squared, a quadratic in c = cos(psi):
// B^2 c^2 + 4 kappa^2 B c + 4 kappa^2 A - B^2 = 0. Its roots (both signs of psi, those
// and the ends are the candidates.
double horizontalHelixLowest(const Arc& arc, double radius, double x, double y) {
  const double radius2 = radius * radius;
  double best = std::min(ballLowest(arc.at(0.0), radius2, x, y), ballLowest(arc.at(arc.sweep), radius2, x, y));
  const double px = x - arc.c1, py = y - arc.c2;
  const double d = std::hypot(px, py);
  const double b = 2.0 * arc.r * d;
  if (b == 0.0) return best;  // g is linear in phi
  const double kappa = arc.dn / arc.sweep;
  const double a = radius2 - d * d - arc.r * arc.r;
  const double qa = b * b, qb = 4.0 * kappa * kappa * b, qc = 4.0 * kappa * kappa * a - b * b;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return best;
  const double root = std::sqrt(disc);
  const double thetaP = std::atan2(py, px);
  for (const double c : {(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)}) {
    if (!(c >= -1.0 - 1e-12 && c <= 1.0 + 1e-12)) continue;
    const double psi = std::acos(std::clamp(c, -1.0, 1.0));
    for (const double signedPsi : {psi, -psi}) {
      // Both signs: the squaring's extra roots are genuine positions too, never too low.
      if (const auto phi = arc.phiOf(thetaP + signedPsi)) best = std::min(best, ballLowest(arc.at(*phi), radius2, x, y));
    }
  }
  return best;
}

// A helix in G18 / G19: branch and bound on phi (see the contract).
double helixLowest(const Arc& arc, double radius, double x, double y) {
  const double radius2 = radius * radius;
  struct Piece {
    double lower, a, b;
    bool operator>(const Piece& other) const { return lower > other.lower; }
  };
  const Vec3 centre = fromArcPlane(arc.plane, {arc.c1, arc.c2, arc.n0});
  const double tolerance = kHelixTolerance * (radius + norm(centre) + arc.r);
  double best = kInf;
  auto bound = [&](double a, double b) {
    const Vec3 pa = arc.at(a), pb = arc.at(b);
    const double sag = arc.r * (1.0 - std::cos(0.5 * (b - a)));
    // The piece lies in its chord's box grown by the sagitta along the in-plane axes.
    const Vec3 grow = fromArcPlane(arc.plane, {sag, sag, 0.0});
    const double xlo = std::min(pa.x, pb.x) - grow.x, xhi = std::max(pa.x, pb.x) + grow.x;
    const double ylo = std::min(pa.y, pb.y) - grow.y, yhi = std::max(pa.y, pb.y) + grow.y;
    const double zlo = std::min(pa.z, pb.z) - grow.z;
    const double dx = std::max({xlo - x, 0.0, x - xhi}), dy = std::max({ylo - y, 0.0, y - yhi});
    const double d2 = dx * dx + dy * dy;
    return d2 > radius2 ? kInf : zlo - std::sqrt(radius2 - d2);
  };
  std::priority_queue<Piece, std::vector<Piece>, std::greater<>> queue;
  const int first = std::max(1, static_cast<int>(std::ceil(arc.sweep / (0.5 * kPi))));
  for (int i = 0; i <= first; ++i) best = std::min(best, ballLowest(arc.at(arc.sweep * i / first), radius2, x, y));
  for (int i = 0; i < first; ++i) {
    const double a = arc.sweep * i / first, b = arc.sweep * (i + 1) / first;
    queue.push({bound(a, b), a, b});
  }
  for (int pieces = 0; !queue.empty() && pieces < kHelixMaxPieces; ++pieces) {
    const Piece piece = queue.top();
    queue.pop();
    if (piece.lower >= best - tolerance) break;
    // A piece shorter than the tolerance is only a grazing touch at the ball's rim.
    if ((piece.b - piece.a) * (arc.r + std::abs(arc.dn) / arc.sweep) <= tolerance) continue;
    const double mid = 0.5 * (piece.a + piece.b);
    best = std::min(best, ballLowest(arc.at(mid), radius2, x, y));
    queue.push({bound(piece.a, mid), piece.a, mid});
    queue.push({bound(mid, piece.b), mid, piece.b});
  }
  return best;
}

// One move prepared for many grid points.
class MoveShape {
 public:
  MoveShape(const SweptMove& move, double radius) : move_(move), radius_(radius), arc_(makeArc(move)) {
    if (move.kind == MoveKind::line) {
      lo_ = {std::min(move.start.x, move.end.x), std::min(move.start.y, move.end.y), std::min(move.start.z, move.end.z)};
      hi_ = {std::max(move.start.x, move.end.x), std::max(move.start.y, move.end.y), std::max(move.start.z, move.end.z)};
      return;
    }
    helix_ = arc_.dn != 0.0;
    // The circle's box in its plane, the normal coordinate's range across.
    const Vec3 clo = fromArcPlane(arc_.plane, {arc_.c1 - arc_.r, arc_.c2 - arc_.r, std::min(arc_.n0, arc_.n0 + arc_.dn)});
    const Vec3 chi = fromArcPlane(arc_.plane, {arc_.c1 + arc_.r, arc_.c2 + arc_.r, std::max(arc_.n0, arc_.n0 + arc_.dn)});
    lo_ = {std::min(clo.x, chi.x), std::min(clo.y, chi.y), std::min(clo.z, chi.z)};
    hi_ = {std::max(clo.x, chi.x), std::max(clo.y, chi.y), std::max(clo.z, chi.z)};
  }

  double lowest(double x, double y) const {
    if (move_.kind == MoveKind::line) return lineLowest(move_.start, move_.end, radius_, x, y);
    if (!helix_) return flatArcLowest(arc_, radius_, x, y);
    return arc_.plane == ArcPlane::xy ? horizontalHelixLowest(arc_, radius_, x, y) : helixLowest(arc_, radius_, x, y);
  }

  // The ball centre where lowest(x, y) is attained: lines only (nullopt for arcs and out of
  // reach).
  std::optional<Vec3> lowestCentre(double x, double y) const {
    if (move_.kind != MoveKind::line) return std::nullopt;
    return lineLowestCentre(move_.start, move_.end, radius_, x, y);
  }

  Vec3 lo() const { return lo_; }  // box of the centre's path
  Vec3 hi() const { return hi_; }

 private:
  static Arc makeArc(const SweptMove& move) {
    if (move.kind == MoveKind::arc) return Arc(move);
    SweptMove dummy;
    dummy.kind = MoveKind::arc;
    dummy.start = {1.0, 0.0, 0.0};
    dummy.end = {1.0, 0.0, 0.0};
    return Arc(dummy);
  }

  SweptMove move_;
  double radius_;
  Arc arc_;
  bool helix_ = false;
  Vec3 lo_, hi_;
};

void requireMoveFinite(const SweptMove& move, std::size_t index) {
  if (finite(move.start) && finite(move.end) && (move.kind == MoveKind::line || finite(move.center))) return;
  throw Error(move.line > 0 ? fmt::format("line {}: a move with a coordinate that is not finite", move.line)
                            : fmt::format("move {}: a coordinate is not finite", index));
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Newton's method on (x, y)(u, v) = (px, py), projected onto the cell.
struct SurfaceHit {
  double z = 0.0;
  double normalZ = 0.0;  // |n_z| of the unit normal there
  double u = 0.0, v = 0.0;
};

std::optional<SurfaceHit> solveHeight(const BezierPatch& patch, double u0, double u1, double v0, double v1,
                                      double u, double v, double px, double py, double tolerance) {
  for (int iteration = 0; iteration < 40; ++iteration) {
    const Vec3 r = point(patch, u, v);
    const double fx = r.x - px, fy = r.y - py;
    const Vec3 ru = derivativeU(patch, u, v), rv = derivativeV(patch, u, v);
    if (std::hypot(fx, fy) <= tolerance) {
      const Vec3 n = cross(ru, rv);
      const double length = norm(n);
      return SurfaceHit{r.z, length > 0.0 ? std::abs(n.z) / length : 0.0, u, v};
    }
    const double det = ru.x * rv.y - rv.x * ru.y;
    if (det == 0.0 || !std::isfinite(det)) return std::nullopt;
    const double du = (rv.y * fx - rv.x * fy) / det;
    const double dv = (-ru.y * fx + ru.x * fy) / det;
    const double nu = std::clamp(u - du, u0, u1), nv = std::clamp(v - dv, v0, v1);
    if (nu == u && nv == v) return std::nullopt;  // stuck on the cell's edge: p is outside
    u = nu;
    v = nv;
  }
  return std::nullopt;
}

struct IndexRange {
  std::size_t lo = 1, hi = 0;  // inclusive; empty when lo > hi
  bool empty() const { return lo > hi; }
};

IndexRange indexRange(double lo, double hi, double origin, double spacing, std::size_t count) {
  const double a = std::ceil((lo - origin) / spacing), b = std::floor((hi - origin) / spacing);
  if (!(a <= b) || b < 0.0 || a > static_cast<double>(count) - 1.0) return {};
  return {static_cast<std::size_t>(std::max(a, 0.0)), static_cast<std::size_t>(std::min(b, static_cast<double>(count) - 1.0))};
}

// Sub-patches: split while a cell covers more than kCellPoints grid points, or while the
// Jacobian det d(x, y) / d(u, v) is not of one strict sign on it (where the surface may fold
// over a vertical tangent), to depth kDesignMaxDepth.
constexpr std::size_t kCellPoints = 256;
constexpr std::size_t kFoldCellPoints = 4;
constexpr int kDesignMaxDepth = 10;

struct DesignPatch {
  const BezierPatch& patch;
  Bernstein2 jacobian;  // x_u y_v - x_v y_u
  double tolerance;
  const PatchTrim* trim = nullptr;  // a trimmed patch's: only its face's points are design
};

void designCell(const DesignPatch& design, double u0, double u1, double v0, double v1, int depth, HeightGrid& grid,
                std::vector<double>* normalZ) {
  checkCancelled();
  const BezierPatch& patch = design.patch;
  // A trimmed patch's cell outside its face holds no design; inside it, no hit needs a test.
  DesignPatch inner = design;
  if (design.trim != nullptr) {
    const CellPlace place = classifyCell(*design.trim, ParameterCell{u0, u1, v0, v1});
    if (place == CellPlace::outside) return;
    if (place == CellPlace::inside) inner.trim = nullptr;
  }
  const double tolerance = design.tolerance;
  const BezierPatch piece = restrictTo(patch, u0, u1, v0, v1);
  double xlo = kInf, xhi = -kInf, ylo = kInf, yhi = -kInf;
  for (const Vec3& c : piece.control) {
    xlo = std::min(xlo, c.x);
    xhi = std::max(xhi, c.x);
    ylo = std::min(ylo, c.y);
    yhi = std::max(yhi, c.y);
  }
  const double slack = tolerance;
  const IndexRange is = indexRange(xlo - slack, xhi + slack, grid.x0, grid.spacing, grid.columns);
  const IndexRange js = indexRange(ylo - slack, yhi + slack, grid.y0, grid.spacing, grid.rows);
  if (is.empty() || js.empty()) return;
  const std::size_t count = (is.hi - is.lo + 1) * (js.hi - js.lo + 1);
  const Bounds jacobian = bounds(restrictTo(design.jacobian, u0, u1, v0, v1));
  const bool oneSheet = jacobian.lo > 0.0 || jacobian.hi < 0.0;
  // A fold cell over a few points is left to the multi-start Newton below: the work stays
  // proportional to the grid points even where a vertical wall projects onto a grid line.
  if ((count > kCellPoints || (!oneSheet && count > kFoldCellPoints)) && depth < kDesignMaxDepth) {
    const double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    designCell(inner, u0, um, v0, vm, depth + 1, grid, normalZ);
    designCell(inner, um, u1, v0, vm, depth + 1, grid, normalZ);
    designCell(inner, u0, um, vm, v1, depth + 1, grid, normalZ);
    designCell(inner, um, u1, vm, v1, depth + 1, grid, normalZ);
    return;
  }
  // On a fold cell (left at the depth limit) Newton also starts from the four corners'
  // quarter points, so that each sheet has a start near it.
  std::vector<Vec2> starts = {{0.5, 0.5}};
  if (!oneSheet) starts.insert(starts.end(), {{0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}, {0.75, 0.75}});
  for (std::size_t j = js.lo; j <= js.hi; ++j) {
    for (std::size_t i = is.lo; i <= is.hi; ++i) {
      const Vec2 p = grid.point(i, j);
      for (const Vec2 start : starts) {
        const auto hit = solveHeight(patch, u0, u1, v0, v1, u0 + start.x * (u1 - u0), v0 + start.y * (v1 - v0), p.x,
                                     p.y, tolerance);
        if (!hit) continue;
        if (inner.trim != nullptr && !keepsPoint(*inner.trim, hit->u, hit->v)) continue;
        const std::size_t index = j * grid.columns + i;
        if (hit->z > grid.z[index]) {
          grid.z[index] = hit->z;
          if (normalZ) (*normalZ)[index] = hit->normalZ;
        }
      }
    }
  }
}

double defaultGougeTolerance(Units units) { return units == Units::inch ? 1e-4 : 2.5e-3; }

void validateOptions(const SimulationOptions& options) {
  const double radius = options.toolRadius, height = options.scallopHeight;
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw Error(fmt::format("invalid tool radius {}: must be positive and finite", radius));
  if (!(height > 0.0) || !(height < radius))
    throw Error(fmt::format("invalid scallop height {}: must be positive and smaller than the tool radius {}", height, radius));
  if (!(options.resolution >= 0.0) || !std::isfinite(options.resolution))
    throw Error(fmt::format("invalid resolution {}: must be a positive length (or 0: from the scallop height)", options.resolution));
  if (!std::isnan(options.margin) && (!(options.margin >= 0.0) || !std::isfinite(options.margin)))
    throw Error(fmt::format("invalid margin {}: must be a length >= 0", options.margin));
  if (options.stockAllowance && !(*options.stockAllowance >= 0.0 && std::isfinite(*options.stockAllowance)))
    throw Error(fmt::format("invalid stock allowance {}: must be finite and >= 0", *options.stockAllowance));
  if (options.stockTop && !std::isfinite(*options.stockTop))
    throw Error(fmt::format("invalid stock top {}: must be finite", *options.stockTop));
  if (!std::isnan(options.gougeTolerance) && (!(options.gougeTolerance >= 0.0) || !std::isfinite(options.gougeTolerance)))
    throw Error(fmt::format("invalid gouge tolerance {}: must be a length >= 0", options.gougeTolerance));
}

double flankSlope(double radius, double height) {
  return std::sqrt(2.0 * radius * height - height * height) / (radius - height);
}

}  // namespace

std::vector<SweptMove> sweptMoves(const GcodeProgram& program, double toolRadius) {
  if (!(toolRadius > 0.0) || !std::isfinite(toolRadius))
    throw Error(fmt::format("invalid tool radius {}: must be positive and finite", toolRadius));
  const Vec3 up{0.0, 0.0, toolRadius};
  std::vector<SweptMove> moves;
  moves.reserve(program.moves.size());
  for (const ProgramMove& m : program.moves) {
    SweptMove s;
    s.kind = m.kind == ProgramMoveKind::arc ? MoveKind::arc : MoveKind::line;
    s.rapid = m.kind == ProgramMoveKind::rapid;
    s.start = m.start + up;
    s.end = m.end + up;
    s.center = m.center + up;
    s.plane = m.plane;
    s.clockwise = m.clockwise;
    s.line = m.line;
    moves.push_back(s);
  }
  return moves;
}

std::vector<SweptMove> sweptMoves(const ToolPath& path) {
  std::vector<SweptMove> moves;
  std::optional<Vec3> previous;
  for (const ToolPass& pass : path.passes) {
    if (!pass.retractBefore && previous) {
      SweptMove link;
      link.start = *previous;
      link.end = pass.start;
      moves.push_back(link);
    }
    Vec3 at = pass.start;
    for (const ToolMove& move : pass.moves) {
      SweptMove s;
      s.kind = move.kind;
      s.start = at;
      s.end = move.end;
      s.center = move.center;
      s.plane = move.plane;
      s.clockwise = move.clockwise;
      moves.push_back(s);
      at = move.end;
    }
    previous = at;
  }
  return moves;
}

double sweptBallLowest(const SweptMove& move, double toolRadius, double x, double y) {
  return MoveShape(move, toolRadius).lowest(x, y);
}

namespace {

// The xy box of some points.
struct XyBox {
  double xlo = kInf, xhi = -kInf, ylo = kInf, yhi = -kInf;
  void add(const Vec3& p) {
    xlo = std::min(xlo, p.x);
    xhi = std::max(xhi, p.x);
    ylo = std::min(ylo, p.y);
    yhi = std::max(yhi, p.y);
  }
};

// The contract's grid over the xy box (options validated).
HeightGrid gridOver(const XyBox& box, const SimulationOptions& options) {
  const auto [xlo, xhi, ylo, yhi] = box;
  const double radius = options.toolRadius, height = options.scallopHeight;
  const double spacing = options.resolution > 0.0 ? options.resolution
                                                  : height / (2.0 * flankSlope(radius, height));
  const double margin = std::isnan(options.margin) ? 2.0 * spacing : options.margin;
  HeightGrid grid;
  grid.spacing = spacing;
  grid.x0 = xlo - margin;
  grid.y0 = ylo - margin;
  const double columns = std::floor((xhi + margin - grid.x0) / spacing) + 1.0;
  const double rows = std::floor((yhi + margin - grid.y0) / spacing) + 1.0;
  const double points = columns * rows;
  if (!(points <= static_cast<double>(options.maxPoints)))
    throw Error(fmt::format("the grid at resolution {} over {} x {} would have {:.0f} x {:.0f} = {:.0f} points, more than "
                            "the budget of {}: give a coarser resolution (or a larger scallop height)",
                            spacing, xhi - xlo + 2.0 * margin, yhi - ylo + 2.0 * margin, columns, rows, points,
                            options.maxPoints));
  grid.columns = static_cast<std::size_t>(columns);
  grid.rows = static_cast<std::size_t>(rows);
  grid.z.assign(grid.columns * grid.rows, -kInf);
  return grid;
}

}  // namespace

HeightGrid simulationGrid(const Surface& surface, const SimulationOptions& options) {
  validateOptions(options);
  if (surface.patches.empty()) throw Error("the surface has no patches");
  XyBox box;
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& c : patch.control) box.add(c);
  return gridOver(box, options);
}

HeightGrid simulationGrid(const Mesh& mesh, const SimulationOptions& options) {
  validateOptions(options);
  if (mesh.triangles.empty()) throw Error("the mesh has no triangles");
  XyBox box;
  for (const Vec3& v : mesh.vertices) box.add(v);
  return gridOver(box, options);
}

HeightGrid simulationGrid(Vec2 low, Vec2 high, const SimulationOptions& options) {
  validateOptions(options);
  if (!(std::isfinite(low.x + low.y + high.x + high.y) && low.x <= high.x && low.y <= high.y))
    throw Error(fmt::format("the simulation's box ({}, {}) to ({}, {}) is empty or not finite", low.x, low.y, high.x,
                            high.y));
  XyBox box;
  box.add({low.x, low.y, 0.0});
  box.add({high.x, high.y, 0.0});
  return gridOver(box, options);
}

// The sign of d(x, y) / d(u, v) as a polynomial: x_u y_v - x_v y_u itself on a polynomial
// patch; on a rational one, with H = (X, Y, w) its homogeneous coordinates (x = X / w,
// y = Y / w), the identity d(x, y) / d(u, v) = det(H, H_u, H_v) / w^3 gives the determinant,
// expanded along H: X (Y_u w_v - w_u Y_v) - Y (X_u w_v - w_u X_v) + w (X_u Y_v - Y_u X_v),
// bidegree (3m - 1, 3n - 1), of the same sign (w > 0).
Bernstein2 jacobianSign(const BezierPatch& patch) {
  if (!patch.rational()) {
    const std::array<Bernstein2, 3> r = coordinatePolynomials(patch);
    return subtract(multiply(derivativeU(r[0]), derivativeV(r[1])), multiply(derivativeV(r[0]), derivativeU(r[1])));
  }
  const std::array<Bernstein2, 4> h = homogeneousPolynomials(patch);
  const Bernstein2 &x = h[0], &y = h[1], &w = h[3];
  const Bernstein2 xu = derivativeU(x), xv = derivativeV(x), yu = derivativeU(y), yv = derivativeV(y);
  const Bernstein2 wu = derivativeU(w), wv = derivativeV(w);
  const auto minor = [](const Bernstein2& au, const Bernstein2& av, const Bernstein2& bu, const Bernstein2& bv) {
    return subtract(multiply(au, bv), multiply(bu, av));  // a_u b_v - b_u a_v
  };
  return add(subtract(multiply(x, minor(yu, yv, wu, wv)), multiply(y, minor(xu, xv, wu, wv))),
             multiply(w, minor(xu, xv, yu, yv)));
}

void designHeights(const Surface& surface, HeightGrid& grid, std::vector<double>* normalZ) {
  std::fill(grid.z.begin(), grid.z.end(), -kInf);
  if (normalZ) normalZ->assign(grid.z.size(), 0.0);
  const double tolerance = 1e-12 * std::max(surfaceScale(surface), 1e-300);
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    advanceStage(i, 3 * surface.patches.size());  // the design: about a third of a simulation
    designCell(DesignPatch{surface.patches[i], jacobianSign(surface.patches[i]), tolerance, patchTrim(surface, i)}, 0.0,
               1.0, 0.0, 1.0, 0, grid, normalZ);
  }
}

namespace {

constexpr std::uint32_t kNoTriangle = kNoDesignTriangle;

// designHeights on a mesh, with the winning triangle per point (kNoTriangle where none) when
// `triangles` is given.
void meshDesign(const Mesh& mesh, HeightGrid& grid, std::vector<double>* normalZ,
                std::vector<std::uint32_t>* triangles) {
  std::fill(grid.z.begin(), grid.z.end(), -kInf);
  if (normalZ) normalZ->assign(grid.z.size(), 0.0);
  if (triangles) triangles->assign(grid.z.size(), kNoTriangle);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (t % 256 == 0) checkCancelled();
    const auto& tri = mesh.triangles[t];
    const Vec3 a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
    const Vec3 n = cross(b - a, c - a);
    // A vertical triangle shows from above only along its top edge, which its neighbours
    // share; twice its projected area is n_z, so one of no area adds no grid point.
    if (n.z == 0.0) continue;
    const double nz = std::abs(n.z) / norm(n);
    const auto [is, js] = std::pair{
        indexRange(std::min({a.x, b.x, c.x}), std::max({a.x, b.x, c.x}), grid.x0, grid.spacing, grid.columns),
        indexRange(std::min({a.y, b.y, c.y}), std::max({a.y, b.y, c.y}), grid.y0, grid.spacing, grid.rows)};
    if (is.empty() || js.empty()) continue;
    for (std::size_t j = js.lo; j <= js.hi; ++j) {
      for (std::size_t i = is.lo; i <= is.hi; ++i) {
        const Vec2 p = grid.point(i, j);
        // Barycentric coordinates in the xy projection. A point on an edge belongs to both
        // triangles, and to the footprint where the edge is its boundary: the coordinates'
        // rounding (a few ulps) must not drop it, so they may fall 1e-12 below 0 (the height
        // is then extrapolated by at most 1e-12 of the triangle's rise).
        const double wa = ((b.x - p.x) * (c.y - p.y) - (b.y - p.y) * (c.x - p.x)) / n.z;
        const double wb = ((c.x - p.x) * (a.y - p.y) - (c.y - p.y) * (a.x - p.x)) / n.z;
        const double wc = 1.0 - wa - wb;
        constexpr double kEdgeSlack = -1e-12;
        if (wa < kEdgeSlack || wb < kEdgeSlack || wc < kEdgeSlack) continue;
        const double z = wa * a.z + wb * b.z + wc * c.z;
        double& top = grid.z[j * grid.columns + i];
        if (z > top) {
          top = z;
          if (normalZ) (*normalZ)[j * grid.columns + i] = nz;
          if (triangles) (*triangles)[j * grid.columns + i] = static_cast<std::uint32_t>(t);
        }
      }
    }
  }
}

}  // namespace

void designHeights(const Mesh& mesh, HeightGrid& grid, std::vector<double>* normalZ) {
  meshDesign(mesh, grid, normalZ, nullptr);
}

std::vector<std::uint32_t> designTriangles(const Mesh& mesh, const HeightGrid& grid) {
  HeightGrid copy = grid;
  std::vector<std::uint32_t> triangles;
  meshDesign(mesh, copy, nullptr, &triangles);
  return triangles;
}

// The grid points within R (horizontally) of a move's box: the only ones it can lower.
std::pair<IndexRange, IndexRange> pointsNear(const MoveShape& shape, double toolRadius, const HeightGrid& stock) {
  return {indexRange(shape.lo().x - toolRadius, shape.hi().x + toolRadius, stock.x0, stock.spacing, stock.columns),
          indexRange(shape.lo().y - toolRadius, shape.hi().y + toolRadius, stock.y0, stock.spacing, stock.rows)};
}

double sweepEvaluations(const std::vector<SweptMove>& moves, double toolRadius, const HeightGrid& stock) {
  double total = 0.0;
  for (std::size_t m = 0; m < moves.size(); ++m) {
    requireMoveFinite(moves[m], m);
    const MoveShape shape(moves[m], toolRadius);
    const auto [is, js] = pointsNear(shape, toolRadius, stock);
    if (is.empty() || js.empty()) continue;
    total += static_cast<double>(is.hi - is.lo + 1) * static_cast<double>(js.hi - js.lo + 1);
  }
  return total;
}

std::size_t sweepMoves(const std::vector<SweptMove>& moves, double toolRadius, HeightGrid& stock,
                       std::vector<double>* lowered) {
  return sweepMoves(moves, toolRadius, stock, lowered, nullptr);
}

std::size_t sweepMoves(const std::vector<SweptMove>& moves, double toolRadius, HeightGrid& stock,
                       std::vector<double>* lowered, std::vector<std::uint32_t>* lowestMove) {
  if (lowered) lowered->assign(moves.size(), 0.0);
  if (lowestMove) lowestMove->assign(stock.z.size(), kNoMove);
  // The grid's rows in bands, one per thread; each band takes every move in order over its
  // own rows. A point's height is the same sequence of minima as in one pass over the moves,
  // and a move's deepest cut the maximum over the bands: the same result, bit for bit, for
  // any number of threads.
  for (std::size_t m = 0; m < moves.size(); ++m) requireMoveFinite(moves[m], m);  // once, not per band
  const std::size_t bands = std::clamp<std::size_t>(threadCount(), 1, std::max<std::size_t>(1, stock.rows / 16));
  std::vector<std::vector<double>> bandLowered(bands, std::vector<double>(lowered ? moves.size() : 0, 0.0));
  std::vector<std::size_t> bandVisits(bands, 0);
  parallelForEach(bands, bands, [&](std::size_t band) {
    const std::size_t rowLo = stock.rows * band / bands, rowHi = stock.rows * (band + 1) / bands;
    std::size_t visits = 0;
    for (std::size_t m = 0; m < moves.size(); ++m) {
      advanceStage(moves.size() + 2 * m, 3 * moves.size());  // the sweep: the rest of a simulation
      const MoveShape shape(moves[m], toolRadius);
      const auto [is, js] = pointsNear(shape, toolRadius, stock);
      if (is.empty() || js.empty() || js.hi < rowLo || js.lo >= rowHi) continue;
      const double floor = shape.lo().z - toolRadius;  // no point of the swept ball is lower
      double most = 0.0;
      for (std::size_t j = std::max(js.lo, rowLo); j <= js.hi && j < rowHi; ++j) {
        for (std::size_t i = is.lo; i <= is.hi; ++i) {
          double& z = stock.z[j * stock.columns + i];
          if (z <= floor) continue;
          const Vec2 p = stock.point(i, j);
          const double low = shape.lowest(p.x, p.y);
          ++visits;
          if (low < z) {
            most = std::max(most, z - low);
            z = low;
            if (lowestMove) (*lowestMove)[j * stock.columns + i] = static_cast<std::uint32_t>(m);
          }
        }
      }
      if (lowered) bandLowered[band][m] = most;
    }
    bandVisits[band] = visits;
  });
  std::size_t visits = 0;
  for (std::size_t band = 0; band < bands; ++band) {
    visits += bandVisits[band];
    if (lowered)
      for (std::size_t m = 0; m < moves.size(); ++m) (*lowered)[m] = std::max((*lowered)[m], bandLowered[band][m]);
  }
  return visits;
}

namespace {

// Whether the ball cannot reach a surface point q left above H (see the contract's Reach).
using ReachTest = std::function<bool(Vec3)>;
// Called once, only when some point is left above H (its engine is built then, off the path
// of the simulations that leave none): makes a ReachTest per thread. None: no classification.
using ReachPreparation = std::function<std::function<ReachTest()>()>;

// Whether a ball centred at c is proven clear of the surface within the gouge tolerance and
// above it (see the contract's Vertical walls). Prepared as ReachPreparation is, when some
// point's vertical gouge exceeds the tolerance; none: no point is cleared.
using ClearanceTest = std::function<bool(Vec3)>;
using ClearancePreparation = std::function<std::function<ClearanceTest()>()>;

// Runs work(from, to) over [0, count) on up to every core, in blocks of kCoreBlock (the last
// one shorter) whatever the number of threads, so that work which carries a state from one
// item to the next within a block (a drop cutter's seed) gives the same results on any
// number of threads; the job's control installed on every thread (work polls it); an error
// (Cancelled among them) is rethrown on the calling thread, the first block's first.
constexpr std::size_t kCoreBlock = 256;
void onEveryCore(std::size_t count, const std::function<void(std::size_t, std::size_t)>& work) {
  const std::size_t blocks = (count + kCoreBlock - 1) / kCoreBlock;
  parallelForEach(blocks, threadCount(), [&](std::size_t block) {
    work(block * kCoreBlock, std::min(count, (block + 1) * kCoreBlock));
  });
}

// The contract's Reach on a mesh: q's upward normal is that of the triangle that holds q over
// its grid point (`triangles`, from meshDesign on `grid`), the drop envelope is the exact one
// of MeshDropCutter (built when first needed, shared by the threads: its queries are const).
ReachPreparation meshReach(const Mesh& mesh, const HeightGrid& grid,
                           std::shared_ptr<const std::vector<std::uint32_t>> triangles, double radius, double height) {
  return [&mesh, &grid, triangles, radius, height]() -> std::function<ReachTest()> {
    const auto cutter = std::make_shared<const MeshDropCutter>(mesh, radius);
    return [&mesh, &grid, triangles, cutter, radius, height]() -> ReachTest {
      return [&mesh, &grid, triangles, cutter, radius, height](Vec3 q) {
        const auto i = static_cast<std::size_t>(std::llround((q.x - grid.x0) / grid.spacing));
        const auto j = static_cast<std::size_t>(std::llround((q.y - grid.y0) / grid.spacing));
        const std::uint32_t t = (*triangles)[j * grid.columns + i];
        if (t == kNoTriangle) return false;
        Vec3 n = triangleNormal(mesh, t);
        if (n.z < 0.0) n = -n;
        const Vec3 c = q + radius * n;
        const double z = cutter->drop(c.x, c.y).z;
        if (!std::isfinite(z)) return false;
        const double lift = std::max(0.0, z - c.z);
        return reachGap(radius, lift, n.z) > height;
      };
    };
  };
}

// A report's figures before the design: units, tool, grid, tolerances, the stock's top.
SimulationReport reportFor(Units units, HeightGrid grid, double highest, const SimulationOptions& options) {
  SimulationReport report;
  report.units = units;
  report.toolRadius = options.toolRadius;
  report.scallopHeight = options.scallopHeight;
  report.design = std::move(grid);
  report.gougeTolerance = std::isnan(options.gougeTolerance) ? defaultGougeTolerance(units) : options.gougeTolerance;
  report.heightErrorBound = 0.5 * flankSlope(options.toolRadius, options.scallopHeight) * report.design.spacing;
  report.stockTop = options.stockTop.value_or(highest);
  return report;
}

// The sweep and the comparison on a report whose design grid, normals, stock top and
// tolerances are set.
void sweepAndCompare(SimulationReport& report, const std::vector<SweptMove>& moves, const SimulationOptions& options,
                     const ReachPreparation& prepareReach, std::chrono::steady_clock::time_point start,
                     const ClearancePreparation& prepareClearance = {});

}  // namespace

SimulationReport simulateCut(const Surface& surface, const std::vector<SweptMove>& moves,
                             const SimulationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SimulationReport report =
      reportFor(surface.units, simulationGrid(surface, options), controlPointTop(surface), options);
  designHeights(surface, report.design, &report.designNormalZ);
  report.designSeconds = secondsSince(start);
  const double radius = options.toolRadius, height = options.scallopHeight;
  // One distance engine for both checks, built when first needed.
  std::shared_ptr<const SurfaceDistance> engine;
  const auto sharedDistance = [&] {
    if (!engine) engine = std::make_shared<const SurfaceDistance>(surface);
    return engine;
  };
  const double slack = report.gougeTolerance;
  sweepAndCompare(
      report, moves, options,
      [&]() -> std::function<ReachTest()> {
        return [distance = sharedDistance(), radius, height]() -> ReachTest {
          auto cutter = std::make_shared<DropCutter>(*distance, radius);
          return [distance, cutter, radius, height](Vec3 q) {
            const ReachWitness witness = reachWitness(*distance, *cutter, q, radius);
            return witness.centre && witness.gap > height;
          };
        };
      },
      start,
      [&]() -> std::function<ClearanceTest()> {
        // The segment from c up to above the whole surface, proven R - gougeTolerance clear.
        const double top = ballTop(surface, radius);
        return [distance = sharedDistance(), clearance = radius - slack, top]() -> ClearanceTest {
          return [distance, clearance, top](Vec3 c) {
            if (c.z >= top) return true;
            // A tolerance of R or more proves nothing of where the ball stands.
            if (!(clearance > 0.0)) return false;
            return distance->segmentClearance(c, {c.x, c.y, top}, clearance).verdict == Clearance::proven;
          };
        };
      });
  return report;
}

SimulationReport simulateCut(const Mesh& mesh, const std::vector<SweptMove>& moves, const SimulationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  double top = -kInf, lowest = kInf;
  for (const Vec3& v : mesh.vertices) {
    top = std::max(top, v.z);
    lowest = std::min(lowest, v.z);
  }
  SimulationReport report = reportFor(mesh.units, simulationGrid(mesh, options), top, options);
  auto triangles = std::make_shared<std::vector<std::uint32_t>>();
  meshDesign(mesh, report.design, &report.designNormalZ, triangles.get());
  report.designSeconds = secondsSince(start);
  const double radius = options.toolRadius;
  sweepAndCompare(report, moves, options,
                  meshReach(mesh, report.design, triangles, options.toolRadius, options.scallopHeight), start,
                  [&]() -> std::function<ClearanceTest()> {
                    // The mesh as the top of a solid: walls under its open edges, down to its
                    // lowest vertex, at the edges themselves (meshWithSkirt). A centre at or
                    // above that lowest z whose vertical segment up to R above the whole mesh
                    // is proven R - gougeTolerance clear of the solid's boundary is outside it
                    // (inside, or under the sheet, the segment meets the top) and its ball
                    // reaches into a column of the z-map only across the walls (at the
                    // centre's height, the ball's widest slice) or above the top: so it cut
                    // no deeper than the tolerance, as on a surface (the contract).
                    const auto cutter = std::make_shared<const MeshDropCutter>(meshWithSkirt(mesh, 0.0), radius);
                    return [cutter, clearance = radius - report.gougeTolerance, top = ballTopAbove(top, radius),
                            lowest]() -> ClearanceTest {
                      return [cutter, clearance, top, lowest](Vec3 c) {
                        if (c.z >= top) return true;
                        if (!(clearance > 0.0) || c.z < lowest) return false;
                        return cutter->segmentClear(c, {c.x, c.y, top}, clearance);
                      };
                    };
                  });
  return report;
}

SimulationReport simulateCut(Units units, HeightGrid grid, double highest, const DesignHeightsFunction& design,
                             const std::vector<SweptMove>& moves, const SimulationOptions& options,
                             const Mesh* reachMesh) {
  const auto start = std::chrono::steady_clock::now();
  validateOptions(options);
  SimulationReport report = reportFor(units, std::move(grid), highest, options);
  std::fill(report.design.z.begin(), report.design.z.end(), -kInf);
  report.designNormalZ.assign(report.design.z.size(), 0.0);
  design(report.design, report.designNormalZ);
  if (report.designNormalZ.size() != report.design.z.size())
    throw Error("the design's normals do not match its grid");  // a caller's bug, not the input's
  report.designSeconds = secondsSince(start);
  ReachPreparation reach;
  if (reachMesh) {
    // The triangles over the grid's points: q's normal and the drop come from the mesh.
    auto triangles = std::make_shared<std::vector<std::uint32_t>>();
    HeightGrid meshGrid = report.design;
    meshDesign(*reachMesh, meshGrid, nullptr, triangles.get());
    reach = meshReach(*reachMesh, report.design, triangles, options.toolRadius, options.scallopHeight);
  }
  sweepAndCompare(report, moves, options, reach, start);
  return report;
}

namespace {

void sweepAndCompare(SimulationReport& report, const std::vector<SweptMove>& moves, const SimulationOptions& options,
                     const ReachPreparation& prepareReach, std::chrono::steady_clock::time_point start,
                     const ClearancePreparation& prepareClearance) {
  const auto sweepStart = std::chrono::steady_clock::now();
  report.stock = report.design;
  const double evaluations = sweepEvaluations(moves, options.toolRadius, report.stock);
  if (evaluations > options.maxEvaluations)
    throw Error(fmt::format("the {} moves would take {:.3g} envelope evaluations on the grid of {} x {} points "
                            "(spacing {}), more than the budget of {:.3g}: give a coarser resolution",
                            moves.size(), evaluations, report.stock.columns, report.stock.rows, report.stock.spacing,
                            options.maxEvaluations));
  std::fill(report.stock.z.begin(), report.stock.z.end(), report.stockTop);
  if (options.stockAllowance) {
    for (std::size_t i = 0; i < report.stock.z.size(); ++i) {
      report.stock.z[i] = std::min(report.stockTop, report.design.z[i] + *options.stockAllowance);
    }
  }
  std::vector<double> lowered;
  std::vector<std::uint32_t> lowestMove;
  const bool clearing = prepareClearance && options.clearVerticalGouges && moves.size() < kNoMove;
  report.sweptPointVisits =
      sweepMoves(moves, options.toolRadius, report.stock, &lowered, clearing ? &lowestMove : nullptr);
  report.sweepSeconds = secondsSince(sweepStart);
  report.moves = moves.size();
  for (std::size_t m = 0; m < moves.size(); ++m) {
    if (moves[m].kind == MoveKind::arc) ++report.arcs;
    if (!moves[m].rapid) continue;
    ++report.rapids;
    if (lowered[m] > report.gougeTolerance) {
      if (report.rapidsCutting == 0) report.firstRapidCutLine = moves[m].line;
      ++report.rapidsCutting;
    }
  }

  // The comparison.
  const HeightGrid& design = report.design;
  const HeightGrid& stock = report.stock;
  // Vertical gouges beyond the tolerance cut by a ball proven clear (the contract's Vertical
  // walls).
  report.clearedGouge.assign(design.z.size(), 0);
  if (clearing) {
    std::vector<std::size_t> deep;
    for (std::size_t index = 0; index < design.z.size(); ++index)
      if (design.z[index] != -kInf && design.z[index] - stock.z[index] > report.gougeTolerance &&
          lowestMove[index] != kNoMove)
        deep.push_back(index);
    if (!deep.empty()) {
      const std::function<ClearanceTest()> clearanceTest = prepareClearance();
      const std::size_t checks = std::min(deep.size(), options.maxClearanceChecks);
      report.clearanceChecks = checks;
      report.clearanceBudgetExhausted = checks < deep.size();
      onEveryCore(checks, [&](std::size_t from, std::size_t to) {
        const ClearanceTest clear = clearanceTest();
        for (std::size_t k = from; k < to; ++k) {
          checkCancelled();
          const std::size_t index = deep[k];
          const Vec2 p = design.point(index % design.columns, index / design.columns);
          const std::optional<Vec3> centre =
              MoveShape(moves[lowestMove[index]], options.toolRadius).lowestCentre(p.x, p.y);
          if (centre && clear(*centre)) report.clearedGouge[index] = 1;
        }
      });
    }
  }
  std::vector<double> scallopAt(design.z.size(), -1.0);  // -1: no surface
  std::vector<std::size_t> uncut;
  for (std::size_t j = 0; j < design.rows; ++j) {
    for (std::size_t i = 0; i < design.columns; ++i) {
      const std::size_t index = j * design.columns + i;
      const double d = design.z[index];
      if (d == -kInf) continue;
      const double s = stock.z[index];
      const Vec2 p = design.point(i, j);
      if (report.clearedGouge[index]) {
        ++report.clearedGougePoints;
        report.maxClearedGouge = std::max(report.maxClearedGouge, d - s);
      } else {
        if (d - s > report.maxGouge) {
          report.maxGouge = d - s;
          report.maxGougeAt = Vec3{p.x, p.y, d};
        }
        if (d - s > report.gougeTolerance) ++report.gougePoints;
      }
      scallopAt[index] = std::max(0.0, s - d) * report.designNormalZ[index];
      if (scallopAt[index] > options.scallopHeight) uncut.push_back(index);
    }
  }
  // Which of the points left above H the ball can reach at all (see the contract).
  report.unreachable.assign(design.z.size(), 0);
  if (options.classifyReach && prepareReach && !uncut.empty()) {
    const auto reachStart = std::chrono::steady_clock::now();
    const std::function<ReachTest()> reachTest = prepareReach();
    const std::size_t checks = std::min(uncut.size(), options.maxReachChecks);
    report.reachChecks = checks;
    report.reachBudgetExhausted = checks < uncut.size();
    onEveryCore(checks, [&](std::size_t from, std::size_t to) {
      const ReachTest beyondReach = reachTest();
      for (std::size_t k = from; k < to; ++k) {
        checkCancelled();
        const std::size_t index = uncut[k];
        const Vec2 p = design.point(index % design.columns, index / design.columns);
        if (beyondReach(Vec3{p.x, p.y, design.z[index]})) report.unreachable[index] = 1;
      }
    });
    report.reachSeconds = secondsSince(reachStart);
  }
  std::vector<double> scallops;
  scallops.reserve(design.z.size());
  double sum = 0.0;
  for (std::size_t j = 0; j < design.rows; ++j) {
    for (std::size_t i = 0; i < design.columns; ++i) {
      const std::size_t index = j * design.columns + i;
      const double scallop = scallopAt[index];
      if (scallop < 0.0) continue;
      const Vec2 p = design.point(i, j);
      if (report.unreachable[index]) {
        ++report.unreachablePoints;
        if (scallop > report.maxUnreachableScallop) {
          report.maxUnreachableScallop = scallop;
          report.maxUnreachableAt = Vec3{p.x, p.y, design.z[index]};
        }
        continue;
      }
      if (scallop > report.maxScallop || !report.maxScallopAt) {
        report.maxScallop = scallop;
        report.maxScallopAt = Vec3{p.x, p.y, design.z[index]};
      }
      if (scallop > options.scallopHeight) ++report.uncutPoints;
      scallops.push_back(scallop);
      sum += scallop;
    }
  }
  report.surfacePoints = scallops.size();
  if (!scallops.empty()) {
    // The smallest value that at least 99 % of the points do not exceed.
    const auto rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(scallops.size()))) - 1;
    std::nth_element(scallops.begin(), scallops.begin() + static_cast<std::ptrdiff_t>(rank), scallops.end());
    report.scallopP99 = scallops[rank];
    report.meanScallop = sum / static_cast<double>(scallops.size());
  }
  const double cellArea = design.spacing * design.spacing;
  report.gougeArea = static_cast<double>(report.gougePoints) * cellArea;
  report.uncutArea = static_cast<double>(report.uncutPoints) * cellArea;
  report.unreachableArea = static_cast<double>(report.unreachablePoints) * cellArea;
  report.seconds = secondsSince(start);
}

}  // namespace

ReachWitness reachWitness(const SurfaceDistance& distance, DropCutter& cutter, Vec3 q, double radius) {
  const ClosestPoint foot = distance.closest(q);
  Vec3 n = unitNormal(distance.surface().patches[foot.patch], foot.u, foot.v);
  if (n.z < 0.0) n = -n;
  const Vec3 c = q + radius * n;
  const double z = cutter.height(c.x, c.y);
  ReachWitness out;
  if (!std::isfinite(z)) return out;
  const double lift = std::max(0.0, z - c.z);
  out.centre = Vec3{c.x, c.y, c.z + lift};
  // |c + lift z - q| - R: how near to q the ball comes from where it would touch it.
  out.gap = reachGap(radius, lift, n.z);
  return out;
}

double reachGap(double radius, double lift, double normalZ) {
  return std::sqrt(radius * radius + 2.0 * radius * lift * normalZ + lift * lift) - radius;
}

namespace {

void requireUnits(const GcodeProgram& program, Units units, const char* what) {
  if (program.units != units)
    throw Error(fmt::format("{}: the program is in {} ({}) but the {} in {}", program.sourceName,
                            program.units == Units::inch ? "inches" : "millimetres",
                            program.units == Units::inch ? "G20" : "G21", what,
                            units == Units::inch ? "inches" : "millimetres"));
}

}  // namespace

SimulationReport verifyProgram(const Surface& surface, const GcodeProgram& program,
                               const SimulationOptions& options) {
  requireUnits(program, surface.units, "surface");
  validateOptions(options);
  return simulateCut(surface, sweptMoves(program, options.toolRadius), options);
}

SimulationReport verifyProgram(const Mesh& mesh, const GcodeProgram& program, const SimulationOptions& options) {
  requireUnits(program, mesh.units, "mesh");
  validateOptions(options);
  return simulateCut(mesh, sweptMoves(program, options.toolRadius), options);
}

SimulationReport verifyProgram(Units units, HeightGrid grid, double highest, const DesignHeightsFunction& design,
                               const GcodeProgram& program, const SimulationOptions& options, const Mesh* reachMesh) {
  requireUnits(program, units, "part");
  validateOptions(options);
  return simulateCut(units, std::move(grid), highest, design, sweptMoves(program, options.toolRadius), options,
                     reachMesh);
}

SimulationReport verifyToolPath(const Surface& surface, const ToolPath& path, SimulationOptions options) {
  if (options.toolRadius == 0.0) options.toolRadius = path.toolRadius;
  if (path.units != surface.units) throw Error("the tool path's units are not the surface's");
  return simulateCut(surface, sweptMoves(path), options);
}

}  // namespace scallop
