// Tests of cut_simulation.hpp against references written here: the swept ball's lowest point
// by dense sampling of ball positions along each move (refined by golden sections), closed
// forms on planes (the cusp of two parallel passes, a plunge), the visible surface by a
// dense triangle mesh, and the paper's plans against gouge.hpp's independent check.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "support/mesh_fixtures.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/verify_output.hpp"
#include "support/rational_patches.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------
// The reference: a move as a function of one parameter, sampled densely.
// ---------------------------------------------------------------------------------------

// The centre's position along the move at s in [0, 1], written from RS-274's definitions,
// not from toolpath.hpp's frames: G17 angles atan2(y, x) seen from +z, G18 atan2(x, z) seen
// from +y, G19 atan2(z, y) seen from +x; G3 turns counter-clockwise (increasing angle), the
// normal coordinate linear in the angle; start == end in the plane is a full circle.
struct ReferenceMove {
  SweptMove move;
  double r = 0.0, a0 = 0.0, sweep = 0.0;

  explicit ReferenceMove(const SweptMove& m) : move(m) {
    if (m.kind == MoveKind::line) return;
    const auto [s1, s2] = inPlane(m.start - m.center);
    const auto [e1, e2] = inPlane(m.end - m.center);
    r = std::hypot(s1, s2);
    a0 = std::atan2(s2, s1);
    double a1 = std::atan2(e2, e1);
    double turn = m.clockwise ? a0 - a1 : a1 - a0;
    while (turn <= 0.0) turn += 2.0 * kPi;
    while (turn > 2.0 * kPi) turn -= 2.0 * kPi;
    if (s1 == e1 && s2 == e2) turn = 2.0 * kPi;
    sweep = turn;
  }

  std::pair<double, double> inPlane(Vec3 d) const {
    switch (move.plane) {
      case ArcPlane::xy: return {d.x, d.y};
      case ArcPlane::zx: return {d.z, d.x};
      case ArcPlane::yz: return {d.y, d.z};
    }
    return {0.0, 0.0};
  }

  Vec3 at(double s) const {
    if (move.kind == MoveKind::line) return move.start + s * (move.end - move.start);
    const double angle = a0 + (move.clockwise ? -1.0 : 1.0) * s * sweep;
    const double c = r * std::cos(angle), d = r * std::sin(angle);
    const Vec3 o = move.center;
    switch (move.plane) {
      case ArcPlane::xy: return {o.x + c, o.y + d, move.start.z + s * (move.end.z - move.start.z)};
      case ArcPlane::zx: return {o.x + d, move.start.y + s * (move.end.y - move.start.y), o.z + c};
      case ArcPlane::yz: return {move.start.x + s * (move.end.x - move.start.x), o.y + c, o.z + d};
    }
    return o;
  }
};

double ballBottom(Vec3 c, double radius, double x, double y) {
  const double rho2 = (x - c.x) * (x - c.x) + (y - c.y) * (y - c.y);
  return rho2 > radius * radius ? kInf : c.z - std::sqrt(radius * radius - rho2);
}

struct ReferenceValue {
  double lowest = kInf;
  double nearest = kInf;  // the least horizontal distance from the samples to (x, y)
};

// Dense samples, then golden sections about the three best samples.
ReferenceValue referenceLowest(const SweptMove& move, double radius, double x, double y, int samples) {
  const ReferenceMove ref(move);
  ReferenceValue out;
  std::vector<std::pair<double, int>> values;
  for (int i = 0; i <= samples; ++i) {
    const Vec3 c = ref.at(static_cast<double>(i) / samples);
    out.nearest = std::min(out.nearest, std::hypot(x - c.x, y - c.y));
    values.push_back({ballBottom(c, radius, x, y), i});
  }
  std::partial_sort(values.begin(), values.begin() + std::min<std::ptrdiff_t>(3, std::ssize(values)), values.end());
  for (int k = 0; k < std::min(3, static_cast<int>(values.size())); ++k) {
    out.lowest = std::min(out.lowest, values[static_cast<std::size_t>(k)].first);
    if (!std::isfinite(values[static_cast<std::size_t>(k)].first)) continue;
    double lo = std::max(0.0, (values[static_cast<std::size_t>(k)].second - 1.0) / samples);
    double hi = std::min(1.0, (values[static_cast<std::size_t>(k)].second + 1.0) / samples);
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    auto f = [&](double s) { return ballBottom(ref.at(s), radius, x, y); };
    double a = hi - g * (hi - lo), b = lo + g * (hi - lo), fa = f(a), fb = f(b);
    for (int it = 0; it < 100; ++it) {
      if (fa < fb) {
        hi = b; b = a; fb = fa; a = hi - g * (hi - lo); fa = f(a);
      } else {
        lo = a; a = b; fa = fb; b = lo + g * (hi - lo); fb = f(b);
      }
      out.lowest = std::min({out.lowest, fa, fb});
    }
  }
  return out;
}

// Random moves of every kind, degenerate ones included.
SweptMove randomMove(std::mt19937_64& rng, double radius) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto point = [&] { return Vec3{4.0 * unit(rng), 4.0 * unit(rng), unit(rng)}; };
  SweptMove m;
  const int kind = static_cast<int>(rng() % 12);
  m.start = point();
  switch (kind) {
    case 0: case 1: case 2: m.end = point(); break;                                   // general line
    case 3: m.end = m.start; break;                                                   // zero length
    case 4: m.end = {m.start.x, m.start.y, unit(rng)}; break;                         // vertical plunge
    case 5: m.end = m.start + Vec3{1e-9 * unit(rng), -1e-9 * unit(rng), 0.5 * unit(rng) - 0.25}; break;  // nearly vertical
    case 6: m.end = m.start + Vec3{1e-7 * unit(rng), 1e-7, 0.0}; break;               // tiny
    case 7: m.end = {m.start.x + 2.0 * unit(rng) - 1.0, m.start.y, m.start.z}; break;  // horizontal
    default: {
      m.kind = MoveKind::arc;
      m.plane = static_cast<ArcPlane>(rng() % 3);
      m.clockwise = rng() % 2 == 0;
      const double r = kind == 8 ? 1e-6 + 1e-4 * unit(rng) : radius * 3.0 * unit(rng) + 1e-3;
      const double a0 = 2.0 * kPi * unit(rng);
      const double a1 = kind == 9 ? a0 : 2.0 * kPi * unit(rng);  // 9: full circle
      const double dn = kind == 11 ? unit(rng) - 0.5 : 0.0;        // 11: helix
      auto offset = [&](double a, double n) -> Vec3 {
        const double c = r * std::cos(a), d = r * std::sin(a);
        switch (m.plane) {
          case ArcPlane::xy: return {c, d, n};
          case ArcPlane::zx: return {d, n, c};
          case ArcPlane::yz: return {n, c, d};
        }
        return {};
      };
      m.center = m.start;
      m.start = m.center + offset(a0, 0.0);
      m.end = m.center + offset(a1, dn);
      // The centre shares the start's normal coordinate.
      if (m.plane == ArcPlane::xy) m.center.z = m.start.z;
      if (m.plane == ArcPlane::zx) m.center.y = m.start.y;
      if (m.plane == ArcPlane::yz) m.center.x = m.start.x;
    }
  }
  return m;
}

TEST(SweptBall, LowestPointMatchesDenseSamplingOnThousandsOfMoves) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int compared = 0, reached = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double radius = 0.05 + 0.95 * unit(rng);
    const SweptMove move = randomMove(rng, radius);
    for (int q = 0; q < 6; ++q) {
      // Points about the move: near its start, its centre, or anywhere nearby.
      const Vec3 base = q == 0 ? move.start : q == 1 ? move.end : move.kind == MoveKind::arc && q == 2 ? move.center
                                                                                                   : 0.5 * (move.start + move.end);
      const double x = base.x + (q == 2 ? 0.0 : (2.0 * unit(rng) - 1.0) * 1.5 * radius);
      const double y = base.y + (q == 2 ? 0.0 : (2.0 * unit(rng) - 1.0) * 1.5 * radius);
      const double got = sweptBallLowest(move, radius, x, y);
      const ReferenceValue want = referenceLowest(move, radius, x, y, 3000);
      // Grazing contacts at the ball's rim are where sampling cannot decide reach.
      if (std::abs(want.nearest - radius) < 1e-3 * radius) continue;
      ++compared;
      SCOPED_TRACE(testing::Message() << "trial " << trial << " kind " << static_cast<int>(move.kind) << " plane "
                                      << static_cast<int>(move.plane) << " at (" << x << ", " << y << ") R " << radius);
      if (!std::isfinite(want.lowest)) {
        EXPECT_EQ(got, kInf);
        continue;
      }
      ++reached;
      ASSERT_TRUE(std::isfinite(got));
      // Never above a genuine position (it finds the minimum) and never below the refined
      // minimum (no false gouge), up to rounding.
      const double tolerance = 1e-9 * (1.0 + radius);
      // A G18/G19 helix is bounded to its documented tolerance above the minimum.
      const bool verticalHelix = move.kind == MoveKind::arc && move.plane != ArcPlane::xy &&
                                 toArcPlane(move.plane, move.start).z != toArcPlane(move.plane, move.end).z;
      const double above = verticalHelix ? kHelixTolerance * (radius + norm(move.center) + norm(move.start - move.center))
                                         : tolerance;
      EXPECT_LE(got, want.lowest + above);
      EXPECT_GE(got, want.lowest - tolerance);
    }
  }
  EXPECT_GT(compared, 15000);
  EXPECT_GT(reached, 8000);
}

TEST(SweptBall, DegenerateMovesInClosedForm) {
  const double radius = 0.5;
  SweptMove plunge;
  plunge.start = {1.0, 1.0, 2.0};
  plunge.end = {1.0, 1.0, 0.5};
  // Straight down: the lower end's ball.
  EXPECT_DOUBLE_EQ(sweptBallLowest(plunge, radius, 1.0, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(sweptBallLowest(plunge, radius, 1.3, 1.0), 0.5 - 0.4);
  std::swap(plunge.start, plunge.end);  // straight up: the same
  EXPECT_DOUBLE_EQ(sweptBallLowest(plunge, radius, 1.3, 1.0), 0.5 - 0.4);
  EXPECT_EQ(sweptBallLowest(plunge, radius, 1.6, 1.0), kInf);
  SweptMove point;
  point.start = point.end = {0.0, 0.0, 1.0};
  EXPECT_DOUBLE_EQ(sweptBallLowest(point, radius, 0.0, 0.3), 1.0 - 0.4);
  // A horizontal line: a half cylinder, the same depth all along.
  SweptMove line;
  line.start = {0.0, 0.0, 1.0};
  line.end = {2.0, 0.0, 1.0};
  for (const double x : {0.0, 0.7, 2.0}) EXPECT_DOUBLE_EQ(sweptBallLowest(line, radius, x, 0.3), 0.6);
  // A ramp rising at 45 degrees, (x, y) on its axis: the ball's bottom lies below the axis
  // point R / cos 45 down (the cylinder's section is an ellipse), tip at (x, c_z(x) - R sqrt 2).
  line.end = {2.0, 0.0, 3.0};
  EXPECT_NEAR(sweptBallLowest(line, radius, 1.0, 0.0), 2.0 - radius * std::sqrt(2.0), 1e-15);
  // A G18 quarter circle of radius 1 about (0, 0, 0) from (0, 0, -1) (below) to (1, 0, 0):
  // above x in [0, 1] the ball touches the outer circle of radius 1 + R.
  SweptMove arc;
  arc.kind = MoveKind::arc;
  arc.plane = ArcPlane::zx;
  arc.center = {0.0, 0.0, 0.0};
  arc.start = {0.0, 0.0, -1.0};
  arc.end = {1.0, 0.0, 0.0};
  // Seen from +y (z right, x up) the short way from -z to +x turns clockwise: G2.
  arc.clockwise = true;
  EXPECT_NEAR(sweptBallLowest(arc, radius, 0.6, 0.0), -std::sqrt(1.5 * 1.5 - 0.36), 1e-15);
  // The other way round (G3) it passes through -x and over the top: lowest where the end
  // balls are.
  arc.clockwise = false;
  EXPECT_NEAR(sweptBallLowest(arc, radius, 0.0, 0.0), -1.5, 1e-15);
  EXPECT_NEAR(sweptBallLowest(arc, radius, 1.2, 0.0), -std::sqrt(0.25 - 0.04), 1e-15);
}

// ---------------------------------------------------------------------------------------
// The z-map on planes: closed forms.
// ---------------------------------------------------------------------------------------

Surface plane(double size, double z) {
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 1;
  patch.control = {{0.0, 0.0, z}, {size, 0.0, z}, {0.0, size, z}, {size, size, z}};
  return Surface{Units::inch, {patch}};
}

SweptMove lineMove(Vec3 a, Vec3 b) {
  SweptMove m;
  m.start = a;
  m.end = b;
  return m;
}

TEST(CutSimulation, TwoParallelPassesLeaveTheClosedFormCusp) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const double radius = 0.1 + 0.4 * unit(rng);
    const double height = radius * (0.001 + 0.02 * unit(rng));
    const double l = 2.0 * std::sqrt(2.0 * radius * height - height * height);  // cusp exactly H
    const double y0 = 1.5 + 0.5 * unit(rng);
    SimulationOptions options;
    options.toolRadius = radius;
    options.scallopHeight = height;
    options.margin = 0.0;
    options.stockTop = 0.5 * radius;
    // The uncut stock beside the passes is the whole plane: what is reachable is not this
    // test's subject (CutSimulationReach's), and classifying it costs most of the run.
    options.classifyReach = false;
    // Passes along x over the whole plane at tip height 0: centres at z = R.
    const std::vector<SweptMove> moves = {lineMove({-1.0, y0, radius}, {5.0, y0, radius}),
                                          lineMove({5.0, y0 + l, radius}, {-1.0, y0 + l, radius})};
    const Surface surface = plane(4.0, 0.0);
    const SimulationReport report = simulateCut(surface, moves, options);
    const HeightGrid& stock = report.stock;
    double sampledMax = 0.0;
    for (std::size_t j = 0; j < stock.rows; ++j) {
      for (std::size_t i = 0; i < stock.columns; ++i) {
        const Vec2 p = stock.point(i, j);
        const double dy = std::min(std::abs(p.y - y0), std::abs(p.y - y0 - l));
        const double want = dy > radius ? options.stockTop.value() : std::min(*options.stockTop, radius - std::sqrt(radius * radius - dy * dy));
        ASSERT_NEAR(stock.z[j * stock.columns + i], want, 1e-12) << "at " << p.x << ", " << p.y;
        if (p.y > y0 && p.y < y0 + l) sampledMax = std::max(sampledMax, stock.z[j * stock.columns + i]);
      }
    }
    // The ridge lies between grid rows: the sampled maximum misses it by at most the bound,
    // which is H / 4 at the default spacing.
    EXPECT_LE(sampledMax, height + 1e-12);
    EXPECT_GE(sampledMax, height - report.heightErrorBound - 1e-12);
    EXPECT_NEAR(report.heightErrorBound, 0.25 * height, 1e-12 * height);
    EXPECT_EQ(report.maxGouge, 0.0);
    EXPECT_EQ(report.gougePoints, 0u);
    EXPECT_NEAR(report.maxScallop, *options.stockTop, 1e-12);  // beyond the passes: uncut stock
  }
}

TEST(CutSimulation, APlungeBelowThePlaneIsAGougeOfItsDepth) {
  const double radius = 0.25, depth = 0.1;
  SimulationOptions options;
  options.toolRadius = radius;
  options.scallopHeight = 0.001;
  options.resolution = 0.01;
  options.margin = 0.0;
  SweptMove plunge = lineMove({2.0, 2.0, 2.0}, {2.0, 2.0, radius - depth});
  const SimulationReport report = simulateCut(plane(4.0, 0.0), {plunge}, options);
  EXPECT_NEAR(report.maxGouge, depth, 1e-12);
  ASSERT_TRUE(report.maxGougeAt.has_value());
  EXPECT_NEAR(report.maxGougeAt->x, 2.0, 1e-9);
  EXPECT_NEAR(report.maxGougeAt->y, 2.0, 1e-9);
  // The gouged points: the ball's bottom R - sqrt(R^2 - rho^2) - depth below 0 by more than
  // the tolerance, counted on the grid here.
  std::size_t want = 0;
  for (std::size_t j = 0; j < report.stock.rows; ++j) {
    for (std::size_t i = 0; i < report.stock.columns; ++i) {
      const Vec2 p = report.stock.point(i, j);
      const double rho2 = (p.x - 2.0) * (p.x - 2.0) + (p.y - 2.0) * (p.y - 2.0);
      if (rho2 < radius * radius && depth - (radius - std::sqrt(radius * radius - rho2)) > report.gougeTolerance) ++want;
    }
  }
  EXPECT_EQ(report.gougePoints, want);
  EXPECT_GT(want, 1000u);
  EXPECT_NEAR(report.gougeArea, static_cast<double>(want) * 1e-4, 1e-12);
  // The plunge started in the air above the stock (the plane's top): the stock elsewhere is
  // uncut, scallop = 0 exactly there as the stock top is the plane.
  EXPECT_EQ(report.maxScallop, 0.0);
}

TEST(CutSimulation, SweepEqualsTheLowestOfEveryMoveAtEveryPoint) {
  // The sweep's pruning (boxes, the stock already lower than the move can reach) loses
  // nothing: the z-map equals min(stock top, every move's lowest point) bit for bit.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const double radius = 0.1 + 0.5 * unit(rng);
    std::vector<SweptMove> moves;
    for (int k = 0; k < 40; ++k) {
      SweptMove m = randomMove(rng, radius);
      if (k % 10 == 0) {  // some far outside the grid
        m.start.x += 10.0;
        m.end.x += 10.0;
        m.center.x += 10.0;
      }
      m.rapid = k % 7 == 0;
      moves.push_back(m);
    }
    HeightGrid stock;
    stock.x0 = -0.3;
    stock.y0 = 0.2;
    stock.spacing = 0.075;
    stock.columns = 60;
    stock.rows = 50;
    stock.z.assign(stock.columns * stock.rows, 0.8);
    std::vector<double> lowered;
    sweepMoves(moves, radius, stock, &lowered);
    for (std::size_t j = 0; j < stock.rows; ++j) {
      for (std::size_t i = 0; i < stock.columns; ++i) {
        const Vec2 p = stock.point(i, j);
        double want = 0.8;
        for (const SweptMove& m : moves) want = std::min(want, sweptBallLowest(m, radius, p.x, p.y));
        ASSERT_EQ(stock.z[j * stock.columns + i], want) << "trial " << trial << " point " << i << ", " << j;
      }
    }
    for (std::size_t k = 0; k < moves.size(); k += 10) EXPECT_EQ(lowered[k], 0.0);  // outside
  }
}

// ---------------------------------------------------------------------------------------
// The design surface seen from above.
// ---------------------------------------------------------------------------------------

// The visible height by a triangle mesh of (n + 1)^2 samples: the highest triangle over
// each grid point, linearly interpolated.
struct MeshReference {
  std::vector<double> z;
};

MeshReference meshHeights(const Surface& surface, const HeightGrid& grid, int n) {
  MeshReference out;
  out.z.assign(grid.z.size(), -kInf);
  for (const BezierPatch& patch : surface.patches) {
    std::vector<Vec3> s;
    for (int a = 0; a <= n; ++a)
      for (int b = 0; b <= n; ++b) s.push_back(point(patch, static_cast<double>(a) / n, static_cast<double>(b) / n));
    auto at = [&](int a, int b) { return s[static_cast<std::size_t>(a * (n + 1) + b)]; };
    auto triangle = [&](Vec3 p, Vec3 q, Vec3 r) {
      const double x0 = std::min({p.x, q.x, r.x}), x1 = std::max({p.x, q.x, r.x});
      const double y0 = std::min({p.y, q.y, r.y}), y1 = std::max({p.y, q.y, r.y});
      const double det = (q.x - p.x) * (r.y - p.y) - (r.x - p.x) * (q.y - p.y);
      if (det == 0.0) return;
      for (long j = std::max(0L, static_cast<long>(std::ceil((y0 - grid.y0) / grid.spacing)));
           j <= std::min(static_cast<long>(grid.rows) - 1, static_cast<long>(std::floor((y1 - grid.y0) / grid.spacing))); ++j) {
        for (long i = std::max(0L, static_cast<long>(std::ceil((x0 - grid.x0) / grid.spacing)));
             i <= std::min(static_cast<long>(grid.columns) - 1, static_cast<long>(std::floor((x1 - grid.x0) / grid.spacing))); ++i) {
          const Vec2 g = grid.point(static_cast<std::size_t>(i), static_cast<std::size_t>(j));
          const double l1 = ((g.x - p.x) * (r.y - p.y) - (r.x - p.x) * (g.y - p.y)) / det;
          const double l2 = ((q.x - p.x) * (g.y - p.y) - (g.x - p.x) * (q.y - p.y)) / det;
          if (l1 < 0.0 || l2 < 0.0 || l1 + l2 > 1.0) continue;
          double& z = out.z[static_cast<std::size_t>(j) * grid.columns + static_cast<std::size_t>(i)];
          z = std::max(z, p.z + l1 * (q.z - p.z) + l2 * (r.z - p.z));
        }
      }
    };
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        triangle(at(a, b), at(a + 1, b), at(a + 1, b + 1));
        triangle(at(a, b), at(a + 1, b + 1), at(a, b + 1));
      }
    }
  }
  return out;
}

// Within `band` of the xy image of a patch's boundary (sampled).
bool nearBoundary(const Surface& surface, Vec2 p, double band) {
  for (const BezierPatch& patch : surface.patches) {
    for (int k = 0; k < 400; ++k) {
      const double t = k / 400.0, t1 = (k + 1) / 400.0;
      auto flat = [](Vec3 q) { return Vec2{q.x, q.y}; };
      const Vec2 edges[4][2] = {{flat(point(patch, t, 0.0)), flat(point(patch, t1, 0.0))},
                                {flat(point(patch, t, 1.0)), flat(point(patch, t1, 1.0))},
                                {flat(point(patch, 0.0, t)), flat(point(patch, 0.0, t1))},
                                {flat(point(patch, 1.0, t)), flat(point(patch, 1.0, t1))}};
      for (const auto& edge : edges)
        if (distanceToSegment(p, edge[0], edge[1]) < band) return true;
    }
  }
  return false;
}

void expectDesignMatchesMesh(const Surface& surface, double spacing, double tolerance, const std::string& name) {
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  options.resolution = spacing;
  HeightGrid grid = simulationGrid(surface, options);
  designHeights(surface, grid);
  const MeshReference mesh = meshHeights(surface, grid, 400);
  std::size_t inside = 0;
  for (std::size_t j = 0; j < grid.rows; ++j) {
    for (std::size_t i = 0; i < grid.columns; ++i) {
      const std::size_t k = j * grid.columns + i;
      const Vec2 p = grid.point(i, j);
      if (std::isfinite(mesh.z[k])) {
        ++inside;
        ASSERT_TRUE(std::isfinite(grid.z[k])) << name << ": no surface found at " << p.x << ", " << p.y;
        ASSERT_NEAR(grid.z[k], mesh.z[k], tolerance) << name << " at " << p.x << ", " << p.y;
      } else if (std::isfinite(grid.z[k])) {
        // Off the mesh: only where the true boundary bulges past the chords.
        ASSERT_TRUE(nearBoundary(surface, p, 1e-4)) << name << ": surface claimed at " << p.x << ", " << p.y;
      }
    }
  }
  EXPECT_GT(inside, grid.z.size() / 4) << name;
}

TEST(DesignHeights, RandomGraphPatchesAgainstADenseMesh) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 12; ++trial) {
    BezierPatch patch;
    patch.degreeU = 1 + static_cast<int>(rng() % 4);
    patch.degreeV = 1 + static_cast<int>(rng() % 4);
    for (int j = 0; j <= patch.degreeU; ++j) {
      for (int k = 0; k <= patch.degreeV; ++k) {
        // A perturbed (then rotated) grid: one-to-one over xy; heights up to 1.
        const double x = 2.0 * k / patch.degreeV + 0.15 * (unit(rng) - 0.5);
        const double y = 2.0 * j / patch.degreeU + 0.15 * (unit(rng) - 0.5);
        patch.control.push_back({0.8 * x - 0.6 * y, 0.6 * x + 0.8 * y, unit(rng)});
      }
    }
    const Surface surface{Units::inch, {patch}};
    validateSurface(surface);
    expectDesignMatchesMesh(surface, 0.02, 2e-4, "trial " + std::to_string(trial));
  }
}

// Rational patches (issue 14, item 2): random bumpy rational graphs against the dense mesh of
// their rational points, and the torus's upper quarters against the closed form
// z = sqrt(b^2 - (rho - a)^2), rho the distance from the axis, over their quarter annuli.
TEST(DesignHeights, RationalPatchesAgainstADenseMeshAndTheTorus) {
  std::mt19937_64 rng(1128);
  for (int trial = 0; trial < 6; ++trial) {
    const Surface surface{Units::inch, {scallop::test::randomRationalPatch(rng, 1 + trial % 3, 2 + trial % 2)}};
    validateSurface(surface);
    expectDesignMatchesMesh(surface, 0.02, 2e-4, "rational trial " + std::to_string(trial));
  }
  const double a = 3.0, b = 1.0;
  for (const bool outer : {true, false}) {
    const Surface surface{Units::inch, {scallop::test::torusPatch(a, b, outer)}};
    // (Not against the mesh: at the rims the tube is vertical, where chords lag the surface.)
    SimulationOptions options;
    options.toolRadius = 0.25;
    options.scallopHeight = 0.001;
    options.resolution = 0.0137;
    HeightGrid grid = simulationGrid(surface, options);
    designHeights(surface, grid);
    std::size_t checked = 0;
    for (std::size_t j = 0; j < grid.rows; ++j)
      for (std::size_t i = 0; i < grid.columns; ++i) {
        const Vec2 p = grid.point(i, j);
        const double rho = std::hypot(p.x, p.y), offset = rho - a;
        const bool over = p.x > 1e-3 && p.y > 1e-3 && (outer ? offset > 1e-3 && offset < b - 1e-3
                                                             : offset < -1e-3 && offset > -b + 1e-3);
        const bool off = p.x < -1e-3 || p.y < -1e-3 || (outer ? offset < -1e-3 || offset > b + 1e-3
                                                               : offset > 1e-3 || offset < -b - 1e-3);
        const double z = grid.z[j * grid.columns + i];
        if (over) {
          ASSERT_NEAR(z, std::sqrt(b * b - offset * offset), 1e-9) << p.x << ", " << p.y;
          ++checked;
        } else if (off) {
          ASSERT_EQ(z, -kInf) << p.x << ", " << p.y;
        }
      }
    EXPECT_GT(checked, 1000u);
  }
}

TEST(DesignHeights, AnOverhangShowsItsHighestSheet) {
  // A degree (1, 3) patch whose xz profile is an S: over x in its middle the vertical line
  // meets three sheets; a 3-axis mill sees the top one.
  BezierPatch patch;
  patch.degreeU = 1;
  patch.degreeV = 3;
  const std::vector<Vec2> profile = {{0.0, 0.0}, {3.0, 0.3}, {-1.0, 0.7}, {2.0, 1.0}};
  for (int j = 0; j <= 1; ++j)
    for (const Vec2& q : profile) patch.control.push_back({q.x, 2.0 * j, q.y});
  const Surface surface{Units::inch, {patch}};
  expectDesignMatchesMesh(surface, 0.02, 2e-3, "overhang");
}

TEST(DesignHeights, AVerticalWallOnAGridLineEndsWithinItsBudget) {
  // A wall x = 0 (its xy image a segment on the grid column through x = 0, the Jacobian zero
  // everywhere) beside a floor z = 0.5: every cell over the wall is a fold cell; the
  // quadtree stops at 4 points a cell (in a fraction of a second), and the floor is seen
  // everywhere off the wall.
  BezierPatch wall;
  wall.degreeU = wall.degreeV = 1;
  wall.control = {{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {0.0, 2.0, 0.0}, {0.0, 2.0, 1.0}};
  const Surface surface{Units::inch, {wall, plane(2.0, 0.5).patches[0]}};
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  options.resolution = 1.0 / 256.0;
  HeightGrid grid = simulationGrid(surface, options);
  designHeights(surface, grid);
  std::size_t floor = 0;
  for (std::size_t j = 0; j < grid.rows; ++j) {
    for (std::size_t i = 0; i < grid.columns; ++i) {
      const Vec2 p = grid.point(i, j);
      if (p.x >= 0.0 && p.x <= 2.0 && p.y >= 0.0 && p.y <= 2.0) {
        const double z = grid.z[j * grid.columns + i];
        if (p.x == 0.0) {  // on the wall: the floor or a point of the wall (the contract)
          ASSERT_GE(z, 0.5);
          ASSERT_LE(z, 1.0);
        } else {
          ASSERT_EQ(z, 0.5) << p.x << ", " << p.y;
        }
        ++floor;
      }
    }
  }
  EXPECT_EQ(floor, 513u * 513u);
}

// A step: a top z = 1 over x in [-1, 0], a vertical wall x = 0 down to a floor z = 0 over
// x in [0, 1], y in [0, 2] throughout. The grid's column through x = 0 lies in the wall.
Surface stepWithAWall() {
  BezierPatch top, wall, floor;
  top.degreeU = top.degreeV = wall.degreeU = wall.degreeV = floor.degreeU = floor.degreeV = 1;
  top.control = {{-1.0, 0.0, 1.0}, {-1.0, 2.0, 1.0}, {0.0, 0.0, 1.0}, {0.0, 2.0, 1.0}};
  wall.control = {{0.0, 0.0, 1.0}, {0.0, 2.0, 1.0}, {0.0, 0.0, 0.0}, {0.0, 2.0, 0.0}};
  floor.control = {{0.0, 0.0, 0.0}, {0.0, 2.0, 0.0}, {1.0, 0.0, 0.0}, {1.0, 2.0, 0.0}};
  return Surface{Units::inch, {top, wall, floor}};
}

// Options for a surface's gouge checks with the tool and grid given: no margin, no reach
// classification (the tests below judge gouges only).
SimulationOptions gougeOnlyOptions(double radius, double resolution) {
  SimulationOptions options;
  options.toolRadius = radius;
  options.scallopHeight = 0.01;
  options.resolution = resolution;
  options.margin = 0.0;
  options.classifyReach = false;
  return options;
}

// The wall tests' gouges left after clearing, each under the ball that interferes (within R
// of its centre line): the pass into the wall at x = R - depth, y in [0.5, 1.5], or the ball
// buried at x = -0.5, y in [1, 1.2]. Counted per ball; a gouge under neither fails.
std::pair<std::size_t, std::size_t> gougesUnderTheWallTestsBalls(const SimulationReport& cut, double radius,
                                                                 double depth) {
  std::size_t nearInto = 0, nearBuried = 0;
  for (std::size_t j = 0; j < cut.design.rows; ++j)
    for (std::size_t i = 0; i < cut.design.columns; ++i) {
      const std::size_t k = j * cut.design.columns + i;
      const Vec2 p = cut.design.point(i, j);
      if (cut.design.z[k] - cut.stock.z[k] <= cut.gougeTolerance || cut.clearedGouge[k]) continue;
      const bool byInto = std::abs(p.x - (radius - depth)) <= radius && p.y >= 0.5 - radius && p.y <= 1.5 + radius;
      const bool byBuried = std::abs(p.x + 0.5) <= radius && p.y >= 1.0 - radius && p.y <= 1.2 + radius;
      EXPECT_TRUE(byInto || byBuried) << p.x << ", " << p.y;
      nearInto += byInto;
      nearBuried += byBuried;
    }
  return {nearInto, nearBuried};
}

// Vertical walls (the contract): a ball running along the floor tangent to the wall lowers
// the wall's grid column to its centre, a vertical "gouge" of the wall's height where the
// ball cut nothing (its distance to the step, in closed form below, is R); those points are
// cleared. A pass into the wall, and a ball buried under the top (clear of every face by more
// than R, but inside the part), are gouges; so is everything with clearVerticalGouges off.
TEST(CutSimulation, AVerticalWallGrazedByTheBallIsNoGougeButACutIntoItIs) {
  const Surface step = stepWithAWall();
  const double radius = 0.25, depth = 0.05;
  const SimulationOptions options = gougeOnlyOptions(radius, 1.0 / 64.0);
  // The distance from a centre to the step's faces (each a rectangle), in closed form.
  const auto stepDistance = [](Vec3 c) {
    const auto clamp = [](double t, double lo, double hi) { return std::clamp(t, lo, hi); };
    const double y = clamp(c.y, 0.0, 2.0);
    const double toTop = scallop::norm(c - Vec3{clamp(c.x, -1.0, 0.0), y, 1.0});
    const double toWall = scallop::norm(c - Vec3{0.0, y, clamp(c.z, 0.0, 1.0)});
    const double toFloor = scallop::norm(c - Vec3{clamp(c.x, 0.0, 1.0), y, 0.0});
    return std::min({toTop, toWall, toFloor});
  };
  const SweptMove grazing = lineMove({radius, -0.5, radius}, {radius, 2.5, radius});
  ASSERT_NEAR(stepDistance(grazing.start + Vec3{0.0, 1.0, 0.0}), radius, 1e-15);

  // The grazing pass alone: the wall's column is cleared, nothing else is deep.
  const SimulationReport grazed = simulateCut(step, {grazing}, options);
  std::size_t wallPoints = 0;
  for (std::size_t j = 0; j < grazed.design.rows; ++j)
    for (std::size_t i = 0; i < grazed.design.columns; ++i) {
      const std::size_t k = j * grazed.design.columns + i;
      const Vec2 p = grazed.design.point(i, j);
      const bool deep = grazed.design.z[k] - grazed.stock.z[k] > grazed.gougeTolerance;
      if (p.x == 0.0 && deep) ++wallPoints;
      EXPECT_EQ(grazed.clearedGouge[k] != 0, deep) << p.x << ", " << p.y;
      if (deep) {
        EXPECT_EQ(p.x, 0.0) << p.y;
      }
    }
  EXPECT_EQ(wallPoints, 129u);  // y = 0, 1/64, ..., 2: the design is the wall's top there
  EXPECT_EQ(grazed.clearedGougePoints, wallPoints);
  EXPECT_NEAR(grazed.maxClearedGouge, 1.0 - radius, 1e-12);
  EXPECT_EQ(grazed.gougePoints, 0u);
  EXPECT_EQ(grazed.maxGouge, 0.0);
  EXPECT_EQ(grazed.clearanceChecks, wallPoints);

  // Off: the old vertical measure.
  SimulationOptions unchecked = options;
  unchecked.clearVerticalGouges = false;
  const SimulationReport raw = simulateCut(step, {grazing}, unchecked);
  EXPECT_EQ(raw.gougePoints, wallPoints);
  EXPECT_EQ(raw.clearedGougePoints, 0u);
  EXPECT_NEAR(raw.maxGouge, 1.0 - radius, 1e-12);

  // A pass into the wall by `depth` and a ball buried under the top.
  const SweptMove into = lineMove({radius - depth, 0.5, radius}, {radius - depth, 1.5, radius});
  const SweptMove buried = lineMove({-0.5, 1.0, 0.3}, {-0.5, 1.2, 0.3});
  EXPECT_NEAR(stepDistance(into.start), radius - depth, 1e-15);
  EXPECT_GT(stepDistance(buried.start), radius);  // clear of every face, but inside the part
  const SimulationReport cut = simulateCut(step, {grazing, into, buried}, options);
  EXPECT_GT(cut.maxGouge, depth);
  const auto [nearInto, nearBuried] = gougesUnderTheWallTestsBalls(cut, radius, depth);
  EXPECT_GT(nearInto, 100u);
  EXPECT_GT(nearBuried, 100u);
  EXPECT_EQ(cut.gougePoints, nearInto + nearBuried);  // the two regions do not overlap
  // The wall's column away from the pass into it stays cleared.
  EXPECT_GT(cut.clearedGougePoints, 40u);
  EXPECT_LT(cut.clearedGougePoints, wallPoints);
}

// The same step as a mesh of six triangles, open at its rim (mesh_raster.hpp's skirt walls
// it for the proofs): the grazing ball's wall column is cleared as on the surface (all 129
// points, by a proof against the mesh as the top of a solid); the pass into the wall and the
// ball buried under the top are gouges, each under its own ball; a ball whose centre is
// below the mesh's lowest vertex is never cleared. Off, the raw vertical measure counts the wall.
TEST(CutSimulationMesh, AVerticalWallGrazedByTheBallIsNoGougeButACutIntoItIs) {
  Mesh step;
  step.units = Units::inch;
  step.vertices = {{-1.0, 0.0, 1.0}, {-1.0, 2.0, 1.0}, {0.0, 0.0, 1.0}, {0.0, 2.0, 1.0},
                   {0.0, 0.0, 0.0},  {0.0, 2.0, 0.0},  {1.0, 0.0, 0.0}, {1.0, 2.0, 0.0}};
  step.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}, {4, 6, 7}, {4, 7, 5}};
  const double radius = 0.25, depth = 0.05;
  const SimulationOptions options = gougeOnlyOptions(radius, 1.0 / 64.0);
  const SweptMove grazing = lineMove({radius, -0.5, radius}, {radius, 2.5, radius});
  const SimulationReport grazed = simulateCut(step, {grazing}, options);
  std::size_t wallPoints = 0;
  for (std::size_t j = 0; j < grazed.design.rows; ++j)
    for (std::size_t i = 0; i < grazed.design.columns; ++i) {
      const std::size_t k = j * grazed.design.columns + i;
      const bool deep = grazed.design.z[k] - grazed.stock.z[k] > grazed.gougeTolerance;
      if (!deep) continue;
      EXPECT_EQ(grazed.design.point(i, j).x, 0.0);
      EXPECT_NE(grazed.clearedGouge[k], 0);
      ++wallPoints;
    }
  EXPECT_EQ(wallPoints, 129u);  // y = 0, 1/64, ..., 2
  EXPECT_EQ(grazed.clearedGougePoints, wallPoints);
  EXPECT_NEAR(grazed.maxClearedGouge, 1.0 - radius, 1e-12);
  EXPECT_EQ(grazed.gougePoints, 0u);

  SimulationOptions unchecked = options;
  unchecked.clearVerticalGouges = false;
  const SimulationReport raw = simulateCut(step, {grazing}, unchecked);
  EXPECT_EQ(raw.gougePoints, wallPoints);
  EXPECT_EQ(raw.clearedGougePoints, 0u);

  const SweptMove into = lineMove({radius - depth, 0.5, radius}, {radius - depth, 1.5, radius});
  const SweptMove buried = lineMove({-0.5, 1.0, 0.3}, {-0.5, 1.2, 0.3});
  const SimulationReport cut = simulateCut(step, {grazing, into, buried}, options);
  EXPECT_GT(cut.maxGouge, depth);
  const auto [nearInto, nearBuried] = gougesUnderTheWallTestsBalls(cut, radius, depth);
  EXPECT_GT(nearInto, 100u);
  EXPECT_GT(nearBuried, 100u);
  EXPECT_EQ(cut.gougePoints, nearInto + nearBuried);
  EXPECT_GT(cut.clearedGougePoints, 40u);

  // Below the mesh's lowest vertex (z = 0): a ball R beside the floor's edge (its equator on
  // the edge's column, R from every triangle) is not cleared, and one nearer than R is a gouge.
  const SweptMove under = lineMove({1.0 + radius, 0.5, -0.1}, {1.0 + radius, 1.5, -0.1});
  const SweptMove reaching = lineMove({1.0 + 0.5 * radius, 0.5, -0.5 * radius}, {1.0 + 0.5 * radius, 1.5, -0.5 * radius});
  const SimulationReport low = simulateCut(step, {under, reaching}, options);
  EXPECT_GT(low.gougePoints, 0u);
  EXPECT_EQ(low.clearedGougePoints, 0u);
}

// A steep plane, z = 2 y over x in [0, 2], y in [0, 1], cut as a raster pass down its slope
// ends: the ball runs down the slope `interference` nearer than R along the normal, on to R
// beside the edge y = 0 at the height where it touches the edge, then plunges beside the
// edge to z = 0, `beside` nearer than R to the edge line. Vertically the slope is gouged
// sqrt(5) times the interference and the edge sqrt(2 R beside) (2.2e-3 for 1e-5); along the
// normal, the closed-form distance below, no more than the interference. Within the
// tolerance both are cleared, whatever the points checked before them (the strip that found
// this: a drop envelope seeded by the slope's contact stood 2e-3 above the plunge beside the
// edge and refused it); beyond it the slope is a gouge of at least the interference.
TEST(CutSimulation, ASteepPatchsEdgeGrazedWithinTheToleranceIsClearedAndACutBeyondItIsNot) {
  BezierPatch slope;
  slope.degreeU = slope.degreeV = 1;
  slope.control = {{0.0, 0.0, 0.0}, {0.0, 1.0, 2.0}, {2.0, 0.0, 0.0}, {2.0, 1.0, 2.0}};
  const Surface steep{Units::inch, {slope}};
  const double radius = 0.25, root5 = std::sqrt(5.0);
  const Vec3 normal{0.0, -2.0 / root5, 1.0 / root5};  // upward unit normal
  const auto planeDistance = [](Vec3 c) {
    // The nearest point (c.x in [0, 2] here) at y in [0, 1] on z = 2 y.
    const double y = std::clamp((c.y + 2.0 * c.z) / 5.0, 0.0, 1.0);
    return std::hypot(c.y - y, c.z - 2.0 * y);
  };
  const SimulationOptions options = gougeOnlyOptions(radius, 1.0 / 128.0);
  const auto program = [&](double interference, double beside) {
    std::vector<SweptMove> moves;
    for (const double x : {0.5, 1.0, 1.5}) {
      const Vec3 top = Vec3{x, 0.6, 1.2} + (radius - interference) * normal;
      const Vec3 foot = Vec3{x, 0.0, 0.0} + (radius - interference) * normal;
      const Vec3 edge{x, -(radius - beside), 0.0};
      moves.push_back(lineMove(top, foot));
      moves.push_back(lineMove(foot, Vec3{x, foot.y, radius / root5}));
      moves.push_back(lineMove(Vec3{x, foot.y, radius / root5}, Vec3{edge.x, edge.y, radius / root5}));
      moves.push_back(lineMove(Vec3{edge.x, edge.y, radius / root5}, edge));
      moves.push_back(lineMove(edge, Vec3{edge.x, edge.y, 1.0}));
      EXPECT_NEAR(planeDistance(top), radius - interference, 1e-12);
      EXPECT_NEAR(planeDistance(edge), radius - beside, 1e-12);
    }
    return moves;
  };

  const SimulationReport grazed = simulateCut(steep, program(6e-5, 1e-5), options);
  EXPECT_GT(grazed.clearedGougePoints, 100u);  // the slope and the edge beside each plunge
  EXPECT_GT(grazed.maxClearedGouge, 2e-3);     // the edge, vertically
  EXPECT_EQ(grazed.gougePoints, 0u);
  EXPECT_LE(grazed.maxGouge, grazed.gougeTolerance);

  const SimulationReport cut = simulateCut(steep, program(3e-4, 1e-5), options);
  EXPECT_GE(cut.maxGouge, 3e-4);
  EXPECT_LE(cut.maxGouge, root5 * 3e-4 + 1e-9);
  EXPECT_GT(cut.gougePoints, 100u);
  EXPECT_GT(cut.clearedGougePoints, 0u);  // the edge beside the plunges
}

TEST(DesignHeights, ThePaperSurfacesAgainstADenseMesh) {
  for (const std::string name : {"paper-1", "paper-2"}) expectDesignMatchesMesh(exampleSurface(name), 0.02, 1e-4, name);
}

// ---------------------------------------------------------------------------------------
// Programs, tool paths and the paper's plans.
// ---------------------------------------------------------------------------------------

GcodeOptions programOptions() {
  GcodeOptions options;
  options.safeHeight = 2.0;
  options.feedRate = 40.0;
  options.plungeFeedRate = 15.0;
  options.spindleRpm = 10000.0;
  return options;
}

TEST(CutSimulation, AProgramCutsAsItsToolPathUpToTheGcodeRounding) {
  // A raster along x writes exact G18 arcs. Every ball centre of the program lies within
  // delta of one of the path's (rounding to q / 2 per axis, q = 0.00001 in, of the ends and
  // the arcs' centres; arcs of tiny sagitta as lines, polygons within q), so the balls of
  // radius R - delta about the path's centres lie inside the program's swept balls, and
  // those lie inside the balls of radius R + delta: the z-maps nest point by point. (The
  // program's plunges and retracts run straight down to and up from the passes' ends.)
  const Surface surface = exampleSurface("paper-1");
  RasterOptions raster;
  raster.angleRad = 0.0;
  raster.toolRadius = 0.25;
  raster.scallopHeight = 0.002;
  raster.dropEnvelope = false;  // the hull's exact G18 arcs (lifting replaces them)
  const RasterPaths paths = rasterPaths(surface, raster);
  const GcodeProgram program = parseGcodeProgram(gcodeProgram(paths.path, programOptions()), "raster.ngc");
  std::size_t arcs = 0;
  for (const ProgramMove& m : program.moves) arcs += m.kind == ProgramMoveKind::arc;
  EXPECT_GT(arcs, 100u);
  const double delta = 3e-5;
  SimulationOptions options;
  options.scallopHeight = 0.002;
  options.toolRadius = 0.25;
  options.resolution = 0.008;  // the same grid for the three radii
  const SimulationReport fromProgram = verifyProgram(surface, program, options);
  options.toolRadius = 0.25 + delta;
  const SimulationReport outer = verifyToolPath(surface, paths.path, options);
  options.toolRadius = 0.25 - delta;
  const SimulationReport inner = verifyToolPath(surface, paths.path, options);
  ASSERT_EQ(outer.stock.z.size(), fromProgram.stock.z.size());
  std::size_t outside = 0, close = 0;
  for (std::size_t k = 0; k < outer.stock.z.size(); ++k) {
    if (!(outer.stock.z[k] <= fromProgram.stock.z[k] + 1e-12 && fromProgram.stock.z[k] <= inner.stock.z[k] + 1e-12))
      ++outside;
    if (std::abs(outer.stock.z[k] - inner.stock.z[k]) < 1e-4) ++close;
  }
  EXPECT_EQ(outside, 0u);
  // Not vacuous: the bounds are within 1e-4 of each other on 98.9 % of the points (all but
  // those under the steep rims of the balls, where 2 delta of radius moves the height most).
  EXPECT_GT(close, outer.stock.z.size() * 95 / 100) << close << " of " << outer.stock.z.size();
  EXPECT_EQ(fromProgram.rapidsCutting, 0u);
}

TEST(CutSimulation, FindsTheRasterPlansGougeOnPaper1) {
  // gouge.hpp measures the ball's interference delta = R - distance to the surface; the
  // vertical gouge above the nearest surface point is at least delta (cut_simulation.hpp),
  // so the z-map must show at least delta, less what a grid point beside the deepest one
  // can miss (the gouge's slope, at most ~2 here, times d).
  const Surface surface = exampleSurface("paper-1");
  RasterOptions raster;
  raster.bestAngle = true;
  raster.toolRadius = 0.25;
  raster.scallopHeight = 0.001;
  raster.dropEnvelope = false;  // the in-plane hull's paths, which gouge (issue 13)
  const RasterPaths paths = rasterPaths(surface, raster);
  const GougeReport check = gougeCheck(surface, paths.path, raster.toolRadius / 10.0);
  ASSERT_GT(check.maxDepth, 0.15);
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  const SimulationReport report =
      verifyProgram(surface, parseGcodeProgram(gcodeProgram(paths.path, programOptions()), "p1.ngc"), options);
  EXPECT_GE(report.maxGouge, check.maxDepth - 2.0 * report.design.spacing);
  EXPECT_GT(report.gougePoints, 1000u);
  // Where the check found its deepest interference, the z-map shows a gouge too.
  const Vec3 contact = check.deepest.contact.point;
  const auto i = static_cast<std::size_t>(std::lround((contact.x - report.design.x0) / report.design.spacing));
  const auto j = static_cast<std::size_t>(std::lround((contact.y - report.design.y0) / report.design.spacing));
  double nearby = 0.0;
  for (std::size_t b = j - 2; b <= j + 2; ++b)
    for (std::size_t a = i - 2; a <= i + 2; ++a)
      if (a < report.design.columns && b < report.design.rows)
        nearby = std::max(nearby, report.design.z[b * report.design.columns + a] - report.stock.z[b * report.design.columns + a]);
  EXPECT_GE(nearby, check.maxDepth - 4.0 * report.design.spacing);
}

TEST(CutSimulation, FindsTheContourPlansGougeOnPaper2WithALargeBall) {
  const Surface surface = exampleSurface("paper-2");
  const OptimalSlicing orientation = optimalSlicing(surface);
  ContourOptions contour;
  contour.normal = orientation.normal;
  contour.toolRadius = 1.0;
  contour.spacing = spacingForScallopHeight(1.0, 0.001, orientation.certifiedAlphaRad);
  contour.dropEnvelope = false;  // the centres r + R n, which cut in (issue 13: about 0.2 in)
  const ContourPaths paths = contourPaths(surface, contour);
  const GougeReport check = gougeCheck(surface, paths.path, contour.toolRadius / 10.0);
  ASSERT_GT(check.maxDepth, 0.1);
  SimulationOptions options;
  options.toolRadius = 1.0;
  options.scallopHeight = 0.001;
  const SimulationReport report = verifyToolPath(surface, paths.path, options);
  EXPECT_GE(report.maxGouge, check.maxDepth - 2.0 * report.design.spacing);
}

TEST(CutSimulation, ScallopOfAContourPlanOnAPlaneIsTheClosedForm) {
  // Horizontal planes z = k Delta cut an inclined plane in parallel lines; balls on them
  // leave cusps of the flat-surface height: max scallop within the grid's bound of
  // R - sqrt(R^2 - l^2 / 4), l the lines' distance, and no gouge.
  const double radius = 0.25, height = 0.002;
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 1;
  patch.control = {{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {0.0, 2.0, 1.0}, {2.0, 2.0, 1.0}};
  const Surface surface{Units::inch, {patch}};
  // The angle theta between z and the plane's normal (0, -1/2, 1) / sqrt(1.25).
  const double sinAlpha = 0.5 / std::sqrt(1.25), cosAlpha = 1.0 / std::sqrt(1.25);
  ContourOptions contour;
  contour.normal = {0.0, 0.0, 1.0};
  contour.toolRadius = radius;
  contour.spacing = spacingForScallopHeight(radius, height, std::asin(sinAlpha));
  // The centres r + R n as they are (no run-on past the edges, where a ball beside the edge
  // within the envelope's eps shows a vertical gouge of up to sqrt(2 R eps)).
  contour.dropEnvelope = false;
  const ContourPaths paths = contourPaths(surface, contour);
  SimulationOptions options;
  options.toolRadius = radius;
  options.scallopHeight = height;
  const SimulationReport report = verifyToolPath(surface, paths.path, options);
  EXPECT_LE(report.maxGouge, 1e-12);
  // Between the first and last lines (away from the edges, where stock is left).
  double inner = 0.0;
  for (std::size_t j = 0; j < report.stock.rows; ++j) {
    for (std::size_t i = 0; i < report.stock.columns; ++i) {
      const Vec2 p = report.stock.point(i, j);
      if (p.x < 0.3 || p.x > 1.7 || p.y < 0.3 || p.y > 1.7) continue;
      const std::size_t k = j * report.stock.columns + i;
      // The scallop along the normal: the vertical difference times n_z.
      inner = std::max(inner, (report.stock.z[k] - report.design.z[k]) * cosAlpha);
      ASSERT_NEAR(report.designNormalZ[k], cosAlpha, 1e-12);
    }
  }
  const double l = contour.spacing / sinAlpha;
  const double cusp = radius - std::sqrt(radius * radius - 0.25 * l * l);
  EXPECT_NEAR(cusp, height, 1e-9);
  EXPECT_LE(inner, cusp + 1e-9);
  // A ridge across the slope lies within d / (2 cos theta) of a grid point along the surface.
  EXPECT_GE(inner, cusp - report.heightErrorBound / cosAlpha);
}

TEST(CutSimulation, TranslatingSurfaceAndMovesTogetherChangesNothing) {
  // Moved by a vector whose components are multiples of the grid spacing (powers of two, so
  // every coordinate moves exactly), the grid moves with the surface's box and each point's
  // stock and design move by dz: gouges and scallops stay the same up to rounding.
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 3;
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) patch.control.push_back({k + 0.1 * unit(rng), j + 0.1 * unit(rng), 0.3 * unit(rng)});
  const Surface surface{Units::inch, {patch}};
  std::vector<SweptMove> moves;
  for (int k = 0; k < 200; ++k) {
    SweptMove m = randomMove(rng, 0.25);
    m.start.z -= 0.3;
    m.end.z -= 0.3;
    m.center.z -= 0.3;
    moves.push_back(m);
  }
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  options.resolution = 1.0 / 64.0;
  const SimulationReport before = simulateCut(surface, moves, options);
  const Vec3 shift{2.0, -1.5, 0.75};
  Surface moved = surface;
  for (Vec3& c : moved.patches[0].control) c = c + shift;
  std::vector<SweptMove> movedMoves = moves;
  for (SweptMove& m : movedMoves) {
    m.start = m.start + shift;
    m.end = m.end + shift;
    m.center = m.center + shift;
  }
  const SimulationReport after = simulateCut(moved, movedMoves, options);
  ASSERT_EQ(before.design.columns, after.design.columns);
  ASSERT_EQ(before.design.rows, after.design.rows);
  EXPECT_GT(before.maxGouge, 0.01);  // the moves dip into the surface
  EXPECT_NEAR(before.maxGouge, after.maxGouge, 1e-9);
  EXPECT_NEAR(before.maxScallop, after.maxScallop, 1e-9);
  EXPECT_NEAR(before.scallopP99, after.scallopP99, 1e-9);
  EXPECT_EQ(before.surfacePoints, after.surfacePoints);
  // Counts at thresholds may flip only for values within rounding of the threshold.
  EXPECT_NEAR(static_cast<double>(before.gougePoints), static_cast<double>(after.gougePoints), 2.0);
}

TEST(CutSimulation, OptionsAndBudgetsAreCheckedWithClearErrors) {
  const Surface surface = plane(4.0, 0.0);
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  options.resolution = 1e-4;  // 40,000 x 40,000 points
  try {
    simulateCut(surface, {}, options);
    FAIL() << "accepted a grid over the budget";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("more than the budget of 4000000"), std::string::npos) << error.what();
  }
  options.resolution = 0.0;
  options.scallopHeight = 0.3;
  EXPECT_THROW(simulateCut(surface, {}, options), Error);
  options.scallopHeight = 0.001;
  options.toolRadius = -1.0;
  EXPECT_THROW(simulateCut(surface, {}, options), Error);
  options.toolRadius = 0.25;
  SweptMove bad = lineMove({0.0, 0.0, 0.0}, {std::nan(""), 0.0, 0.0});
  bad.line = 17;
  try {
    simulateCut(surface, {bad}, options);
    FAIL() << "accepted a NaN move";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("line 17"), std::string::npos) << error.what();
  }
  // The sweep's budget is counted before sweeping.
  std::vector<SweptMove> many(2000, lineMove({-1.0, -1.0, 0.3}, {5.0, 5.0, 0.3}));
  options.maxEvaluations = 1e8;
  try {
    simulateCut(surface, many, options);
    FAIL() << "accepted a sweep over the budget";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("more than the budget of 1e+08"), std::string::npos) << error.what();
  }
  options.maxEvaluations = 4e9;
  // An empty program: the stock stays at the surface's top; nothing is gouged.
  const SimulationReport report = simulateCut(surface, {}, options);
  EXPECT_EQ(report.maxGouge, 0.0);
  EXPECT_EQ(report.uncutPoints, 0u);  // the plane's top is its bounding box's top
}

TEST(VerifyOutput, JsonHasNoNanAndTheSvgStaysSmall) {
  const Surface surface = exampleSurface("paper-1");
  RasterOptions raster;
  raster.bestAngle = true;
  raster.toolRadius = 0.25;
  raster.scallopHeight = 0.001;
  raster.dropEnvelope = false;  // a path that gouges, for the report's gouge fields
  const RasterPaths paths = rasterPaths(surface, raster);
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  const SimulationReport report = verifyToolPath(surface, paths.path, options);
  const std::string json = verifyToJson(report, {"example paper-1", "p.ngc", 0, 0.0});
  EXPECT_EQ(json.find("nan"), std::string::npos);
  EXPECT_EQ(json.find("inf"), std::string::npos);
  EXPECT_NE(json.find("\"over_tolerance\": true"), std::string::npos);
  const std::string svg = verifySvg(report, {"example <paper-1>", "p.ngc", 0, 0.0});
  EXPECT_LT(svg.size(), 1'500'000u);
  EXPECT_NE(svg.find("example &lt;paper-1&gt;"), std::string::npos);
  EXPECT_NE(svg.find("deepest gouge"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  // Deterministic.
  EXPECT_EQ(svg, verifySvg(report, {"example <paper-1>", "p.ngc", 0, 0.0}));
}


// ---------------------------------------------------------------------------------------
// Reach: the points left above H that the ball cannot reach from above.
// ---------------------------------------------------------------------------------------

// The valley z = k (x - 1)^2 over [0, 2]^2, exactly, as a biquadratic patch: x = 2u, y = 2v,
// and (2u - 1)^2 has the Bernstein coefficients 1, -1, 1 (its blossom). Its bottom's radius
// of curvature is 1 / (2k).
Surface valley(double k) {
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 2;
  const double c[3] = {1.0, -1.0, 1.0};
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) patch.control.push_back({double(j), double(i), k * c[j]});
  return Surface{Units::inch, {patch}};
}

// The brute-force judge of reach on the valley, written from its profile alone. Away from the
// ends y = 0 and y = 2 (by more than R + H) every surface point is (s, t, k (s - 1)^2), so
// the drop envelope over (x, y) with y inside is the profile's
//     Z(x) = max { k (s - 1)^2 + sqrt(R^2 - (s - x)^2) : s in [0, 2], |s - x| <= R },
// taken here by 400 samples of s refined by golden sections about the best two, and the
// ball at (x, y', Z(x)) is nearest a point q = (q_x, q_y, q_z) with y' = q_y: the smallest
// gap |c - q| - R over the centres that can touch q is
//     min over x in [q_x - R - H, q_x + R + H] of sqrt((x - q_x)^2 + (Z(x) - q_z)^2) - R,
// taken over Z on a grid of x (spacing `step`, every value a genuine centre's: never below
// the true minimum) and at the centre q + R n itself (exactly where the library looks).
struct ValleyReach {
  double k, R, step, x0;
  std::vector<double> z;  // Z at x0 + i step

  double profile(double x) const {
    const double lo = std::max(0.0, x - R), hi = std::min(2.0, x + R);
    if (lo > hi) return -kInf;
    const auto g = [&](double s) {
      const double d2 = (s - x) * (s - x);
      return k * (s - 1.0) * (s - 1.0) + std::sqrt(std::max(0.0, R * R - d2));
    };
    constexpr int n = 400;
    std::vector<std::pair<double, int>> samples;
    for (int i = 0; i <= n; ++i) samples.push_back({g(lo + (hi - lo) * i / n), i});
    std::partial_sort(samples.begin(), samples.begin() + 2, samples.end(), std::greater<>());
    double best = samples[0].first;
    for (int b = 0; b < 2; ++b) {
      double a = lo + (hi - lo) * std::max(0, samples[b].second - 1) / n;
      double c = lo + (hi - lo) * std::min(n, samples[b].second + 1) / n;
      const double r = (std::sqrt(5.0) - 1.0) / 2.0;
      for (int it = 0; it < 80; ++it) {
        const double x1 = c - r * (c - a), x2 = a + r * (c - a);
        const double g1 = g(x1), g2 = g(x2);
        best = std::max({best, g1, g2});
        if (g1 > g2) c = x2; else a = x1;
      }
    }
    return best;
  }

  ValleyReach(double k_, double R_, double h, double step_) : k(k_), R(R_), step(step_), x0(-R_ - h - 0.05) {
    for (double x = x0; x <= 2.0 + R + h + 0.05; x += step) z.push_back(profile(x));
  }

  // The least gap for the surface point over (qx, *), and the gap at q + R n alone.
  std::pair<double, double> gap(double qx, double h) const {
    const double qz = k * (qx - 1.0) * (qx - 1.0);
    const auto at = [&](double x, double zx) { return std::hypot(x - qx, zx - qz) - R; };
    double best = kInf;
    const auto first = static_cast<std::size_t>(std::max(0.0, std::floor((qx - R - h - x0) / step)));
    for (std::size_t i = first; i < z.size() && x0 + double(i) * step <= qx + R + h; ++i)
      best = std::min(best, at(x0 + double(i) * step, z[i]));
    const double slope = 2.0 * k * (qx - 1.0);
    const double nx = -slope / std::hypot(slope, 1.0);
    const double cx = qx + R * nx;
    const double own = at(cx, profile(cx));
    return {std::min(best, own), own};
  }
};

// The report's figures follow from its own grids and flags.
void expectReachBookkeeping(const SimulationReport& report, double height, const std::string& what) {
  std::size_t above = 0, flagged = 0, uncut = 0;
  double maxFlagged = 0.0, maxOther = 0.0;
  const double cell = report.design.spacing * report.design.spacing;
  for (std::size_t i = 0; i < report.design.z.size(); ++i) {
    if (report.design.z[i] == -kInf) {
      EXPECT_EQ(report.unreachable[i], 0) << what << " point " << i << ": no surface";
      continue;
    }
    const double scallop = std::max(0.0, report.stock.z[i] - report.design.z[i]) * report.designNormalZ[i];
    if (scallop > height) ++above;
    if (report.unreachable[i]) {
      EXPECT_GT(scallop, height) << what << " point " << i << ": classified, yet not above H";
      ++flagged;
      maxFlagged = std::max(maxFlagged, scallop);
    } else {
      uncut += scallop > height;
      maxOther = std::max(maxOther, scallop);
    }
  }
  EXPECT_EQ(report.unreachablePoints, flagged) << what;
  EXPECT_NEAR(report.unreachableArea, double(flagged) * cell, 1e-12) << what;
  EXPECT_NEAR(report.maxUnreachableScallop, maxFlagged, 1e-12) << what;
  EXPECT_EQ(report.uncutPoints, uncut) << what;
  EXPECT_NEAR(report.uncutArea, double(uncut) * cell, 1e-12) << what;
  EXPECT_NEAR(report.maxScallop, maxOther, 1e-12) << what;
  EXPECT_EQ(report.reachChecks, std::min(above, std::size_t{400'000})) << what;
}

// The valley z = 2 (x - 1)^2 (bottom radius 0.25 in) under a ball of R = 0.5 in, H = 0.002 in:
// the ball wedges between the walls, touching them at t0 = sqrt(4 k^2 R^2 - 1) / (2k) either
// side of the bottom (t = x - 1), and cannot finish what lies between. Passes along y over the
// left wall (vertices every 0.05 in below the surface, lifted onto the envelope) cut part of
// it; elsewhere the finishing stock a = 0.05 in stays (a |n_z| > H everywhere below the flat
// top). Every point the report classifies, away from the ends y = 0 and 2 (where the judge's
// symmetry holds), against ValleyReach's least gap over all centres:
//   - classified reachable: the ball at q + R n touched within H by the library's envelope,
//     which lies below the true one by at most the height that loses eps / 2 of clearance,
//     eps / (2 n_z) <= 2.1 eps on these walls (n_z >= 1 / sqrt(17)): least gap <= H + 2.1 eps;
//   - classified unreachable: least gap > H, except in the band next to the wedge contacts
//     where the heuristic cannot see the wedged ball: the wedged ball is tangent to the wall at
//     t0, and at arc length sigma from there the gap between them is sigma^2 (1/R - kappa) / 2
//     to leading order (kappa = 2k / (1 + 4k^2 t0^2)^(3/2) the profile's curvature there), so
//     the wedged ball comes within H of the points with |t| > t0 - Delta_H, Delta_H =
//     sqrt(2H / ((1/R - kappa)(1 + 4k^2 t0^2))), while their own centres q + R n stand on the
//     envelope's steep branch beside the wedge, lifted more than H. The contract says so ("a
//     centre beside c may come nearer"); the band is checked to be where the misses are
//     (within 1.5 Delta_H: the next term is O(sigma^3)) and the figures printed.
TEST(CutSimulationReach, ValleyTighterThanTheBallAgainstABruteForceJudge) {
  const double k = 2.0, R = 0.5, H = 0.002;
  const Surface surface = valley(k);
  ToolPath path;
  path.toolRadius = R;
  for (double x = 0.5; x <= 0.95; x += 0.03) {
    ToolPass pass{{x, 0.0, -1.0}, {}, true};
    for (int j = 1; j <= 40; ++j) pass.moves.push_back({MoveKind::line, {x, 0.05 * j, -1.0}, {}, ArcPlane::xy, true});
    path.passes.push_back(pass);
  }
  EnvelopeReport lift;
  path = liftToDropEnvelope(SurfaceDistance(surface), path, {}, lift);
  ASSERT_EQ(lift.unprovenMoves, 0u);
  SimulationOptions options;
  options.toolRadius = R;
  options.scallopHeight = H;
  options.resolution = 0.02;
  options.stockAllowance = 0.05;
  options.stockTop = 3.0;
  const SimulationReport report = verifyToolPath(surface, path, options);
  expectReachBookkeeping(report, H, "valley");
  EXPECT_FALSE(report.reachBudgetExhausted);
  const ValleyReach judge(k, R, H, 1e-4);
  const double eps = 1e-6 * surfaceScale(surface);
  const double t0 = std::sqrt(4.0 * k * k * R * R - 1.0) / (2.0 * k);
  const double kappa = 2.0 * k / std::pow(1.0 + 4.0 * k * k * t0 * t0, 1.5);
  const double band = std::sqrt(2.0 * H / ((1.0 / R - kappa) * (1.0 + 4.0 * k * k * t0 * t0)));
  std::size_t unreachable = 0, reachable = 0, missed = 0, cut = 0;
  double leastUnreachable = kInf, mostReachable = -kInf, leastMissed = kInf, widestMiss = 0.0;
  for (std::size_t j = 0; j < report.design.rows; ++j) {
    for (std::size_t i = 0; i < report.design.columns; ++i) {
      const std::size_t index = j * report.design.columns + i;
      const Vec2 p = report.design.point(i, j);
      if (report.design.z[index] == -kInf || p.y < R + H + 0.01 || p.y > 2.0 - R - H - 0.01) continue;
      const double scallop = std::max(0.0, report.stock.z[index] - report.design.z[index]) * report.designNormalZ[index];
      if (scallop <= H) {
        ++cut;
        continue;
      }
      const double least = judge.gap(p.x, H).first;
      const auto where = [&] { return ::testing::Message() << "(" << p.x << ", " << p.y << ")"; };
      if (!report.unreachable[index]) {
        ++reachable;
        mostReachable = std::max(mostReachable, least);
        EXPECT_LE(least, H + 2.1 * eps) << where() << ": classified reachable, the ball comes no nearer than " << least;
        continue;
      }
      ++unreachable;
      if (least > H) {
        leastUnreachable = std::min(leastUnreachable, least);
        continue;
      }
      ++missed;
      leastMissed = std::min(leastMissed, least);
      const double inside = t0 - std::abs(p.x - 1.0);  // how far inside the wedge's contact
      widestMiss = std::max(widestMiss, inside);
      EXPECT_GT(inside, 0.0) << where();
      EXPECT_LT(inside, 1.5 * band) << where() << ": classified unreachable, the ball comes within " << least;
    }
  }
  std::printf("[          ] valley k %g, R %g, H %g (judged away from the ends): %zu cut to H, %zu classified "
              "reachable (largest least gap %.3g), %zu unreachable (%zu of them within H of the wedged ball: least "
              "gap %.3g, at most %.3g inside its contact, band %.3g; the others' least gap >= %.3g); in all %zu "
              "unreachable points (area %.4g), %zu uncut\n",
              k, R, H, cut, reachable, mostReachable, unreachable, missed, leastMissed, widestMiss, band,
              leastUnreachable, report.unreachablePoints, report.unreachableArea, report.uncutPoints);
  EXPECT_GT(reachable, 100u);
  EXPECT_GT(unreachable, 300u);
  EXPECT_GT(cut, 100u);
  EXPECT_LE(missed, unreachable / 10);
}

// The option and the budget, on the valley with nothing cut (the finishing stock everywhere,
// every point above H): classifyReach = false classifies nothing and counts every point in
// the scallop figures; maxReachChecks = 10 classifies 10 points, says the budget ran out,
// and agrees with the full classification on the points it flags; the figures add up.
TEST(CutSimulationReach, TheOptionAndTheBudget) {
  const Surface surface = valley(2.0);
  SimulationOptions options;
  options.toolRadius = 0.5;
  options.scallopHeight = 0.002;
  options.resolution = 0.04;
  options.stockAllowance = 0.05;
  options.stockTop = 3.0;
  const SimulationReport full = simulateCut(surface, {}, options);
  expectReachBookkeeping(full, options.scallopHeight, "full");
  EXPECT_EQ(full.reachChecks, full.surfacePoints + full.unreachablePoints);  // every point above H
  EXPECT_GT(full.unreachablePoints, 100u);
  EXPECT_FALSE(full.reachBudgetExhausted);

  options.classifyReach = false;
  const SimulationReport off = simulateCut(surface, {}, options);
  EXPECT_EQ(off.reachChecks, 0u);
  EXPECT_EQ(off.unreachablePoints, 0u);
  EXPECT_EQ(off.unreachableArea, 0.0);
  EXPECT_EQ(off.maxUnreachableScallop, 0.0);
  EXPECT_FALSE(off.maxUnreachableAt.has_value());
  EXPECT_FALSE(off.reachBudgetExhausted);
  EXPECT_EQ(std::count(off.unreachable.begin(), off.unreachable.end(), 1), 0);
  EXPECT_EQ(off.uncutPoints, full.uncutPoints + full.unreachablePoints);
  EXPECT_GE(off.maxScallop, full.maxScallop);
  EXPECT_NEAR(off.maxScallop, std::max(full.maxScallop, full.maxUnreachableScallop), 1e-15);

  options.classifyReach = true;
  options.maxReachChecks = 10;
  const SimulationReport budget = simulateCut(surface, {}, options);
  EXPECT_EQ(budget.reachChecks, 10u);
  EXPECT_TRUE(budget.reachBudgetExhausted);
  EXPECT_LE(budget.unreachablePoints, 10u);
  EXPECT_EQ(budget.uncutPoints + budget.unreachablePoints, off.uncutPoints);
  for (std::size_t i = 0; i < budget.unreachable.size(); ++i) {
    if (budget.unreachable[i]) {
      EXPECT_EQ(full.unreachable[i], 1) << i;
    }
  }
  options.maxReachChecks = 0;
  const SimulationReport none = simulateCut(surface, {}, options);
  EXPECT_EQ(none.reachChecks, 0u);
  EXPECT_TRUE(none.reachBudgetExhausted);
  EXPECT_EQ(none.unreachablePoints, 0u);
}

// Where the ball touches every point from its own centre q + R n (a plane, tilted; a dome,
// convex: it lies below each tangent plane, so the ball above the plane at q clears it),
// nothing is unreachable, though every point is left above H and classified.
TEST(CutSimulationReach, NothingIsUnreachableOnAPlaneOrAConvexDome) {
  BezierPatch tilted;
  tilted.degreeU = tilted.degreeV = 1;
  tilted.control = {{0.0, 0.0, 0.0}, {0.0, 2.0, 0.3}, {2.0, 0.0, 1.2}, {2.0, 2.0, 1.5}};
  BezierPatch dome;
  dome.degreeU = dome.degreeV = 2;
  const double c[3] = {1.0, -1.0, 1.0};  // (2u - 1)^2
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) dome.control.push_back({double(j), double(i), 2.0 - 0.8 * (c[j] + c[i])});
  for (const auto& [patch, name] : {std::pair{tilted, "plane"}, std::pair{dome, "dome"}}) {
    for (const double R : {0.1, 0.5, 1.5}) {
      SimulationOptions options;
      options.toolRadius = R;
      options.scallopHeight = 0.002;
      options.resolution = 0.04;
      options.stockAllowance = 0.05;
      options.stockTop = 5.0;
      const SimulationReport report = simulateCut(Surface{Units::inch, {patch}}, {}, options);
      expectReachBookkeeping(report, options.scallopHeight, name);
      EXPECT_GT(report.reachChecks, 1000u) << name << " R " << R;
      EXPECT_EQ(report.unreachablePoints, 0u) << name << " R " << R;
      EXPECT_EQ(report.maxUnreachableScallop, 0.0) << name << " R " << R;
    }
  }
}

}  // namespace
}  // namespace scallop

// ---------------------------------------------------------------------------------------
// Meshes (the contract's Meshes)
// ---------------------------------------------------------------------------------------

namespace scallop {
namespace {

// The highest triangle over (x, y) by solving a + s (b - a) + t (c - a) = (x, y) in xy with
// Cramer's rule (s, t >= 0, s + t <= 1, a hair of slack for points on an edge): -inf if none.
double referenceMeshHeight(const Mesh& mesh, double x, double y) {
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& tri : mesh.triangles) {
    const Vec3 a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
    const double e1x = b.x - a.x, e1y = b.y - a.y, e2x = c.x - a.x, e2y = c.y - a.y;
    const double det = e1x * e2y - e1y * e2x;
    if (det == 0.0) continue;
    const double s = ((x - a.x) * e2y - (y - a.y) * e2x) / det;
    const double t = (e1x * (y - a.y) - e1y * (x - a.x)) / det;
    const double slack = 1e-12;
    if (s < -slack || t < -slack || s + t > 1.0 + slack) continue;
    best = std::max(best, a.z + s * (b.z - a.z) + t * (c.z - a.z));
  }
  return best;
}

TEST(CutSimulationMesh, DesignHeightsAreTheHighestTriangleAgainstAReference) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 6; ++trial) {
    const Mesh mesh = test::heightFieldMesh(6 + 3 * static_cast<std::size_t>(trial), rng, 0.05, true);
    SimulationOptions options;
    options.toolRadius = 0.25;
    options.scallopHeight = 0.001;
    options.resolution = 0.0173;
    HeightGrid grid = simulationGrid(mesh, options);
    std::vector<double> normalZ;
    designHeights(mesh, grid, &normalZ);
    std::size_t inside = 0;
    for (std::size_t j = 0; j < grid.rows; ++j)
      for (std::size_t i = 0; i < grid.columns; ++i) {
        const Vec2 p = grid.point(i, j);
        const double expected = referenceMeshHeight(mesh, p.x, p.y);
        const double got = grid.z[j * grid.columns + i];
        if (expected == -std::numeric_limits<double>::infinity()) {
          // Off the footprint, or within a hair of its edge (the reference's slack).
          if (got != expected) {
            EXPECT_TRUE(p.x > -1e-9 && p.x < 2.0 + 1e-9 && p.y > -1e-9 && p.y < 2.0 + 1e-9);
          }
          continue;
        }
        ++inside;
        ASSERT_NEAR(got, expected, 1e-12) << "trial " << trial << " at " << p.x << ", " << p.y;
        EXPECT_GT(normalZ[j * grid.columns + i], 0.0);
        EXPECT_LE(normalZ[j * grid.columns + i], 1.0);
      }
    EXPECT_GT(inside, 10000u);
  }
}

// The same inclined plane as a bilinear patch and as two triangles, cut by the same lines:
// the two simulations agree point by point (the design is the same plane), so the mesh path
// inherits the surface path's closed-form check (ScallopOfAContourPlanOnAPlaneIsTheClosedForm).
TEST(CutSimulationMesh, APlaneAsTrianglesIsCutAsThePlanePatchIs) {
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 1;
  patch.control = {{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {0.0, 2.0, 1.0}, {2.0, 2.0, 1.0}};
  const Surface surface{Units::inch, {patch}};
  Mesh mesh;
  mesh.units = Units::inch;
  mesh.vertices = {{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {0.0, 2.0, 1.0}, {2.0, 2.0, 1.0}};
  mesh.triangles = {{0, 1, 3}, {0, 3, 2}};
  const double radius = 0.25;
  std::vector<SweptMove> moves;
  for (int k = 0; k <= 20; ++k) {
    const double y = 0.1 * k;
    SweptMove move;
    // Centres R along the plane's unit normal (0, -1/2, 1) / sqrt(1.25) from the line.
    const Vec3 offset = radius / std::sqrt(1.25) * Vec3{0.0, -0.5, 1.0};
    move.start = Vec3{0.0, y, 0.5 * y} + offset;
    move.end = Vec3{2.0, y, 0.5 * y} + offset;
    moves.push_back(move);
  }
  SimulationOptions options;
  options.toolRadius = radius;
  options.scallopHeight = 0.002;
  options.classifyReach = false;
  const SimulationReport onPatch = simulateCut(surface, moves, options);
  const SimulationReport onMesh = simulateCut(mesh, moves, options);
  ASSERT_EQ(onMesh.design.z.size(), onPatch.design.z.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < onMesh.design.z.size(); ++k) {
    if (onPatch.design.z[k] == -std::numeric_limits<double>::infinity()) continue;
    if (onMesh.design.z[k] == -std::numeric_limits<double>::infinity()) continue;  // the edges' rounding
    worst = std::max(worst, std::abs(onMesh.design.z[k] - onPatch.design.z[k]));
    ASSERT_NEAR(onMesh.designNormalZ[k], onPatch.designNormalZ[k], 1e-12);
  }
  EXPECT_LE(worst, 1e-12);
  EXPECT_NEAR(onMesh.maxScallop, onPatch.maxScallop, 1e-12);
  EXPECT_NEAR(onMesh.maxGouge, onPatch.maxGouge, 1e-12);
  EXPECT_EQ(onMesh.uncutPoints, onPatch.uncutPoints);
  EXPECT_GT(onMesh.maxScallop, 0.0);
}

// Reach on a mesh: a plate z = 0 over [0, 4] x [0, 2] in with a slot 0.4 in wide and 0.5 deep
// along y (floor z = -0.5 over 1.8 < x < 2.2, vertical walls), finishing stock 0.05 in, no
// move: every point stays 0.05 > H above the design. In closed form a ball of R = 0.5 cannot
// enter the slot: over its middle its centre stops on both rims at sqrt(R^2 - 0.2^2) =
// 0.458 in, so it stays 0.458 - 0.5 + 0.5 = 0.458 in above the floor, and nearer the walls
// more (the rim it rests on is nearer): every floor point is beyond reach, by far. On the
// plate the ball sits on the plate: every plate point is reachable.
TEST(CutSimulationMesh, ASlotNarrowerThanTheBallIsBeyondReachThePlateIsNot) {
  Mesh mesh;
  mesh.units = Units::inch;
  const auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    const auto at = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {a, b, c, d});
    mesh.triangles.push_back({at, at + 1, at + 2});
    mesh.triangles.push_back({at, at + 2, at + 3});
  };
  quad({0, 0, 0}, {1.8, 0, 0}, {1.8, 2, 0}, {0, 2, 0});                  // plate, left
  quad({2.2, 0, 0}, {4, 0, 0}, {4, 2, 0}, {2.2, 2, 0});                  // plate, right
  quad({1.8, 0, -0.5}, {2.2, 0, -0.5}, {2.2, 2, -0.5}, {1.8, 2, -0.5});  // floor
  quad({1.8, 0, 0}, {1.8, 0, -0.5}, {1.8, 2, -0.5}, {1.8, 2, 0});        // walls
  quad({2.2, 0, -0.5}, {2.2, 0, 0}, {2.2, 2, 0}, {2.2, 2, -0.5});
  SimulationOptions options;
  options.toolRadius = 0.5;
  options.scallopHeight = 0.01;
  options.resolution = 0.0237;
  options.stockAllowance = 0.05;
  options.stockTop = 1.0;  // above the plate's allowance (the default, the mesh's top, would clip it)
  const SimulationReport report = simulateCut(mesh, {}, options);
  expectReachBookkeeping(report, options.scallopHeight, "slot");
  std::size_t floor = 0, plate = 0;
  for (std::size_t j = 0; j < report.design.rows; ++j)
    for (std::size_t i = 0; i < report.design.columns; ++i) {
      const std::size_t index = j * report.design.columns + i;
      const Vec2 p = report.design.point(i, j);
      if (report.design.z[index] == -kInf) continue;
      if (std::abs(p.x - 1.8) < 1e-9 || std::abs(p.x - 2.2) < 1e-9) continue;  // the rims: either answer
      const bool inSlot = p.x > 1.8 && p.x < 2.2;
      EXPECT_EQ(report.unreachable[index], inSlot ? 1 : 0) << "(" << p.x << ", " << p.y << ")";
      (inSlot ? floor : plate) += 1;
    }
  EXPECT_GT(floor, 1000u);
  EXPECT_GT(plate, 10000u);
  EXPECT_NEAR(report.maxUnreachableScallop, 0.05, 1e-12);
  EXPECT_EQ(report.uncutPoints, plate);  // the plate, reachable, still carries its 0.05
}

TEST(CutSimulationMesh, BadInput) {
  SimulationOptions options;
  options.toolRadius = 0.25;
  options.scallopHeight = 0.001;
  EXPECT_THROW(simulateCut(Mesh{}, {}, options), Error);
  GcodeProgram program;
  program.units = Units::millimetre;
  Mesh inches;
  inches.units = Units::inch;
  inches.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  inches.triangles = {{0, 1, 2}};
  EXPECT_THROW(verifyProgram(inches, program, options), Error);
}

}  // namespace
}  // namespace scallop
