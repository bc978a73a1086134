// Trimmed surfaces (surface.hpp's trims, face_trim.hpp's PatchTrim): sections, distances and
// the simulated cut's design take only the face's part of a trimmed patch. The face here is
// paper-1's patch (x = 3 v, y = 3 u: a graph over the square [0, 3]^2) trimmed to a disk of
// its parameter square, or to the square minus a disk (a hole), the map to the face's
// parameters affine (scaled, shifted, u reversed), so every reference is in closed form or
// by dense sampling written here: the disk's membership of a point, the circle's parameters,
// brute-force distances over the disk and along its circle. A second face, an arch (a
// cylinder's rational quadratic arc, its weights not in standard form, trimmed in the face's
// (angle, height)), takes the half-angle map (face_trim.hpp's AxisMap): its references read
// the angle off each 3D point with atan2, not through the map.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/face_trim.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/paths/section.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

using scallop::CellPlace;
using scallop::FaceTrim;
using scallop::PatchTrim;
using scallop::Surface;
using scallop::TrimArc;
using scallop::Vec3;

constexpr double kInf = std::numeric_limits<double>::infinity();

// A circle of the face's parameter plane as four rational quadratic arcs.
std::vector<TrimArc> circleArcs(double cu, double cv, double radius, bool clockwise) {
  std::vector<TrimArc> arcs;
  const double w = std::sqrt(0.5);
  for (int q = 0; q < 4; ++q) {
    const double a = q * std::numbers::pi / 2.0, b = a + std::numbers::pi / 2.0;
    TrimArc arc{{cu + radius * std::cos(a), cv + radius * std::sin(a), 1.0},
                {w * (cu + radius * (std::cos(a) + std::cos(b))), w * (cv + radius * (std::sin(a) + std::sin(b))), w},
                {cu + radius * std::cos(b), cv + radius * std::sin(b), 1.0}};
    arcs.push_back(arc);
  }
  if (clockwise) {
    std::reverse(arcs.begin(), arcs.end());
    for (TrimArc& arc : arcs) std::reverse(arc.begin(), arc.end());
  }
  return arcs;
}

// The rectangle [u0, u1] x [v0, v1] as four straight arcs anticlockwise, then a clockwise
// circular hole in it.
std::vector<TrimArc> squareWithHole(double u0, double v0, double u1, double v1, double cu, double cv, double radius) {
  const double corners[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  std::vector<TrimArc> arcs;
  for (int i = 0; i < 4; ++i)
    arcs.push_back(TrimArc{{corners[i][0], corners[i][1], 1.0}, {corners[(i + 1) % 4][0], corners[(i + 1) % 4][1], 1.0}});
  for (const TrimArc& arc : circleArcs(cu, cv, radius, true)) arcs.push_back(arc);
  return arcs;
}

// The face: in the patch's own parameters (s, t), the disk |(s, t) - (0.5, 0.45)| <= 0.3
// (`hole` false) or the square minus that disk (`hole` true). The face's parameters are
// u = 10 - 4 s (reversed) and v = 2 + 4 t, where the circle is centred at (8, 3.8) with
// radius 1.2.
struct TrimmedPaper {
  Surface surface;
  bool hole = false;
  static constexpr double kCentreS = 0.5, kCentreT = 0.45, kRadius = 0.3;

  explicit TrimmedPaper(bool withHole) : hole(withHole) {
    surface = scallop::exampleSurface("paper-1");
    auto face = std::make_shared<FaceTrim>();
    // The circle in face parameters: s = (10 - u) / 4, t = (v - 2) / 4.
    const double cu = 10.0 - 4.0 * kCentreS, cv = 2.0 + 4.0 * kCentreT, r = 4.0 * kRadius;
    // The square's boundary (u from 10 down to 6, v from 2 to 6), then the hole; or the disk.
    face->arcs = hole ? squareWithHole(6, 2, 10, 6, cu, cv, r) : circleArcs(cu, cv, r, false);
    PatchTrim trim;
    trim.face = face;
    trim.u = scallop::AxisMap::affine(10.0, 6.0), trim.v = scallop::AxisMap::affine(2.0, 6.0);
    trim.margin = 1e-12;
    surface.trims = {trim};
  }

  // The closed-form membership in the patch's parameters, with a band left undecided.
  double signedDistance(double s, double t) const {  // > 0 inside the face
    const double d = kRadius - std::hypot(s - kCentreS, t - kCentreT);
    return hole ? -d : d;
  }

  // The circle's point at angle a, pulled into the face by `inward` (patch parameters).
  std::pair<double, double> boundary(double a, double inward) const {
    const double r = kRadius + (hole ? inward : -inward);
    return {kCentreS + r * std::cos(a), kCentreT + r * std::sin(a)};
  }
  // Where the section planes pass and the query points lie.
  Vec3 middle() const { return {1.5, 1.35, 0.6}; }
  Vec3 randomPoint(std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> across(-0.5, 3.5), up(-1.0, 2.5);
    return {across(rng), across(rng), up(rng)};
  }
  double queryReach() const { return 3.5; }  // the query points' largest coordinate
  int circleSamples() const { return 20000; }
};

// The arch: a cylinder of radius 2 about the y axis, r(s, t) = (2 cos a, 3 t, 2 sin a) for
// the angle a from 40 to 140 degrees, s along the arc as a rational quadratic with weights
// (1, 1.7 cos 50 deg, 1.7^2) (a Moebius reparametrisation of the standard form, so s is
// neither the angle nor its standard half-angle parameter). The face's parameters are
// (u, v) = (a, y); its trim is the disk |(u, v) - (pi / 2, 1.5)| <= 0.6, or the rectangle
// minus it (`hole` true).
struct TrimmedArch {
  Surface surface;
  bool hole = false;
  static constexpr double kRadius = 0.6, kCentreV = 1.5, kRho = 2.0, kWeightScale = 1.7;
  static constexpr double kStart = 40.0 * std::numbers::pi / 180.0, kEnd = 140.0 * std::numbers::pi / 180.0;
  static constexpr double kCentreU = std::numbers::pi / 2.0;

  explicit TrimmedArch(bool withHole) : hole(withHole) {
    scallop::BezierPatch patch;
    patch.degreeU = 2, patch.degreeV = 1;
    const double half = 0.5 * (kEnd - kStart), middle = 0.5 * (kStart + kEnd);
    const Vec3 rim[3] = {{kRho * std::cos(kStart), 0.0, kRho * std::sin(kStart)},
                         {kRho / std::cos(half) * std::cos(middle), 0.0, kRho / std::cos(half) * std::sin(middle)},
                         {kRho * std::cos(kEnd), 0.0, kRho * std::sin(kEnd)}};
    const double weights[3] = {1.0, kWeightScale * std::cos(half), kWeightScale * kWeightScale};
    for (int a = 0; a <= 2; ++a)
      for (int b = 0; b <= 1; ++b) {
        patch.control.push_back(rim[a] + Vec3{0.0, 3.0 * b, 0.0});
        patch.weights.push_back(weights[a]);
      }
    surface.units = scallop::Units::millimetre;
    surface.patches = {patch};
    auto face = std::make_shared<FaceTrim>();
    face->arcs = hole ? squareWithHole(kStart, 0, kEnd, 3, kCentreU, kCentreV, kRadius)
                      : circleArcs(kCentreU, kCentreV, kRadius, false);
    PatchTrim trim;
    trim.face = face;
    // The map through the angles of the patch's points at s = 0, 1/2, 1, read off with atan2
    // (as cad_import.cpp reads OCCT's parameters of them).
    trim.u = scallop::AxisMap::halfAngle(angleAt(0.0), angleAt(0.5), angleAt(1.0));
    trim.v = scallop::AxisMap::affine(0.0, 3.0);
    trim.margin = 1e-12;
    surface.trims = {trim};
  }

  // The angle of the patch's point at s (any t), from the point itself.
  double angleAt(double s) const {
    const Vec3 p = scallop::point(surface.patches[0], s, 0.5);
    return std::atan2(p.z, p.x);
  }
  double signedDistance(double s, double t) const {  // > 0 inside the face
    const Vec3 p = scallop::point(surface.patches[0], s, t);
    const double d = kRadius - std::hypot(std::atan2(p.z, p.x) - kCentreU, p.y - kCentreV);
    return hole ? -d : d;
  }
  // The circle's point at angle a, pulled into the face by `inward` (face parameters): s by
  // bisection on the angle of the patch's points (it increases with s).
  std::pair<double, double> boundary(double a, double inward) const {
    const double r = kRadius + (hole ? inward : -inward);
    const double u = kCentreU + r * std::cos(a), v = kCentreV + r * std::sin(a);
    double lo = 0.0, hi = 1.0;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      (angleAt(mid) < u ? lo : hi) = mid;
    }
    return {0.5 * (lo + hi), v / 3.0};
  }
  Vec3 middle() const { return {0.0, 1.5, 1.9}; }
  Vec3 randomPoint(std::mt19937_64& rng) const {
    // Most near the disk's part of the arch, so that the trim matters to many of them.
    std::uniform_real_distribution<double> across(-2.0, 2.0), along(0.3, 2.7), up(0.3, 3.2);
    return {across(rng), along(rng), up(rng)};
  }
  double queryReach() const { return 3.5; }
  int circleSamples() const { return 20000; }
};

// The half-angle map against the angle read off the patch's points; the patch's membership
// (keepsPoint) against the closed form, beyond a band of 1e-9.
TEST(TrimmedSurface, AHalfAngleMapIsTheAngleOfTheArcsPoints) {
  const TrimmedArch arch(false);
  const PatchTrim& trim = arch.surface.trims[0];
  double worst = 0.0;
  for (int i = 0; i <= 10000; ++i) {
    const double s = i / 10000.0;
    worst = std::max(worst, std::abs(trim.u.at(s) - arch.angleAt(s)));
  }
  EXPECT_LE(worst, 1e-13);
  // Not the affine map through the ends: the weights make s far from the angle's fraction.
  EXPECT_GT(std::abs(trim.u.at(0.5) - 0.5 * (TrimmedArch::kStart + TrimmedArch::kEnd)), 0.1);
  for (const bool hole : {false, true}) {
    const TrimmedArch trimmed(hole);
    int inside = 0, outside = 0;
    for (int a = 0; a <= 400; ++a)
      for (int b = 0; b <= 400; ++b) {
        const double s = (a + 0.3) / 400.7, t = (b + 0.6) / 400.7;
        const double margin = trimmed.signedDistance(s, t);
        if (std::abs(margin) < 1e-9) continue;
        EXPECT_EQ(scallop::keepsPoint(trimmed.surface.trims[0], s, t), margin > 0.0) << s << ", " << t;
        (margin > 0.0 ? inside : outside) += 1;
      }
    EXPECT_GT(inside, 20000) << hole;
    EXPECT_GT(outside, 20000) << hole;
  }
}

// The paper surface's point over (x, y) = (3 t, 3 s): on paper-1, r(s, t) = (3 t, 3 s, z(s, t)).
template <typename Case>
void checkSectionsStopAtTheTrimmingCurve(const Case& trimmed) {
  const bool hole = trimmed.hole;
  {
    Surface untrimmed = trimmed.surface;
    untrimmed.trims.clear();
    int ends = 0, samples = 0;
    for (int k = 0; k < 24; ++k) {
      // Planes of several directions through the surface.
      const double angle = 0.3 + 0.25 * k;
      const Vec3 normal{std::cos(angle), std::sin(angle), k % 3 == 0 ? 0.0 : 0.4};
      const double offset = dot(normal, trimmed.middle()) + 0.05 * (k % 5 - 2);
      const scallop::PlaneSection cut = scallop::planeSection(trimmed.surface, normal, offset, 1e-5);
      const scallop::PlaneSection whole = scallop::planeSection(untrimmed, normal, offset, 1e-5);
      // Every vertex in the face (the curves' ends on the circle, within 1e-9).
      for (const scallop::SectionCurve& curve : cut.curves) {
        for (std::size_t i = 0; i < curve.points.size(); ++i) {
          const scallop::SectionPoint& p = curve.points[i];
          const double inside = trimmed.signedDistance(p.u, p.v);
          EXPECT_GE(inside, -1e-9) << "hole " << hole << " plane " << k;
          EXPECT_NEAR(dot(normal, p.point) / norm(normal), offset / norm(normal), 1e-12);
          const bool end = !curve.closed && (i == 0 || i + 1 == curve.points.size());
          // An end inside the square is on the circle (else on the patch's own edge).
          const bool onSquareEdge = p.u == 0.0 || p.u == 1.0 || p.v == 0.0 || p.v == 1.0;
          if (end && !onSquareEdge) {
            EXPECT_NEAR(inside, 0.0, 1e-9) << "hole " << hole << " plane " << k;
            ++ends;
          }
        }
      }
      // Every point of the untrimmed section inside the face (by 1e-6) is on the trimmed one:
      // within the chordal tolerance of some edge.
      for (const scallop::SectionCurve& curve : whole.curves)
        for (const scallop::SectionPoint& p : curve.points) {
          if (trimmed.signedDistance(p.u, p.v) < 1e-6) continue;
          ++samples;
          double nearest = kInf;
          for (const scallop::SectionCurve& other : cut.curves)
            for (std::size_t i = 0; i + 1 < other.points.size(); ++i) {
              const Vec3 a = other.points[i].point, b = other.points[i + 1].point;
              const double t = std::clamp(dot(p.point - a, b - a) / std::max(dot(b - a, b - a), 1e-300), 0.0, 1.0);
              nearest = std::min(nearest, norm(a + t * (b - a) - p.point));
            }
          EXPECT_LE(nearest, 2e-5) << "hole " << hole << " plane " << k;
        }
    }
    EXPECT_GT(ends, 20) << hole;
    EXPECT_GT(samples, 500) << hole;
  }
}

TEST(TrimmedSurface, SectionsStopAtTheTrimmingCurve) {
  for (const bool hole : {false, true}) checkSectionsStopAtTheTrimmingCurve(TrimmedPaper(hole));
}

TEST(TrimmedSurface, SectionsOfAHalfAngleTrimStopAtItsCurve) {
  for (const bool hole : {false, true}) checkSectionsStopAtTheTrimmingCurve(TrimmedArch(hole));
}

// The distance to the trimmed face against brute force over it: a 300 x 300 grid of the
// square kept where the disk test passes, plus 20,000 points of the circle, the best refined
// by a pattern search that stays in the face (a step leaving it is refused).
template <typename Case>
double referenceDistance(const Case& trimmed, const std::vector<std::pair<double, double>>& circle, Vec3 p) {
  const scallop::BezierPatch& patch = trimmed.surface.patches[0];
  struct Start {
    double d, s, t;
  };
  std::vector<Start> starts;
  const auto consider = [&](double s, double t) {
    if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0 || trimmed.signedDistance(s, t) < 0.0) return;
    starts.push_back({norm(scallop::point(patch, s, t) - p), s, t});
  };
  for (int i = 0; i <= 300; ++i)
    for (int k = 0; k <= 300; ++k) consider(i / 300.0, k / 300.0);
  for (const auto& [s, t] : circle) consider(s, t);
  std::partial_sort(starts.begin(), starts.begin() + 6, starts.end(),
                    [](const Start& a, const Start& b) { return a.d < b.d; });
  double best = starts.front().d;
  for (int k = 0; k < 6; ++k) {
    Start at = starts[static_cast<std::size_t>(k)];
    for (double h = 1.0 / 300.0; h > 1e-12; h *= 0.5) {
      for (bool moved = true; moved;) {
        moved = false;
        for (const auto& [ds, dt] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1}}) {
          const double s = at.s + ds * h, t = at.t + dt * h;
          if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0 || trimmed.signedDistance(s, t) < 0.0) continue;
          const double d = norm(scallop::point(patch, s, t) - p);
          if (d < at.d) at = {d, s, t}, moved = true;
        }
      }
    }
    best = std::min(best, at.d);
  }
  return best;
}

template <typename Case>
void checkDistancesAreToTheFaceAlone(const Case& trimmed, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const bool hole = trimmed.hole;
  // Points of the circle (20,000, or as many as the case asks), just inside the face (pulled
  // in by 1e-13): a start on the circle cannot slide along it, so their spacing bounds the
  // reference's error where the face's nearest point is on the circle.
  std::vector<std::pair<double, double>> circle;
  const int samples = trimmed.circleSamples();
  for (int i = 0; i < samples; ++i) circle.push_back(trimmed.boundary(2.0 * std::numbers::pi * i / samples, 1e-13));
  {
    const scallop::SurfaceDistance engine(trimmed.surface);
    Surface untrimmed = trimmed.surface;
    untrimmed.trims.clear();
    const scallop::SurfaceDistance whole(untrimmed);
    int fartherThanUntrimmed = 0;
    for (int i = 0; i < 120; ++i) {
      const Vec3 p = trimmed.randomPoint(rng);
      const scallop::ClosestPoint found = engine.closest(p);
      ASSERT_TRUE(found.converged) << i;
      const double reference = referenceDistance(trimmed, circle, p);
      // The reference is a point of the face: an upper bound; its refinement reaches 1e-9.
      // Beside a trimming curve the search resolves the face to kTrimCellReach of its scale.
      const double reach = engine.tolerance() + scallop::kTrimCellReach * (scallop::surfaceScale(trimmed.surface) + trimmed.queryReach());
      EXPECT_LE(found.distance, reference + reach) << "hole " << hole << " point " << i << " excess "
                                                   << found.distance - reference;
      EXPECT_GE(found.distance, reference - 1e-7) << "hole " << hole << " point " << i;
      EXPECT_GE(trimmed.signedDistance(found.u, found.v), -1e-9) << "hole " << hole << " point " << i;
      EXPECT_GE(found.distance, whole.closest(p).distance - engine.tolerance());  // both within it of their minima
      if (found.distance > whole.closest(p).distance + 1e-3) ++fartherThanUntrimmed;
      // A segment from p halfway to the face's point: violated beyond half the distance (by
      // more than the trim's resolution), never at less.
      const Vec3 b = p + 0.5 * (found.point - p);
      EXPECT_EQ(engine.segmentClearance(p, b, 0.5 * found.distance + 2.0 * reach).verdict, scallop::Clearance::violated);
      EXPECT_NE(engine.segmentClearance(p, b, 0.5 * found.distance - 1e-6).verdict, scallop::Clearance::violated);
    }
    EXPECT_GT(fartherThanUntrimmed, 10) << hole;  // the trim matters to many of the points
  }
}

TEST(TrimmedSurface, DistancesAreToTheFaceAlone) {
  for (const bool hole : {false, true}) checkDistancesAreToTheFaceAlone(TrimmedPaper(hole), 1414);
}

// The same face on paper-1's patch stretched 20 times along x: SurfaceDistance searches it in
// 16 pieces (gouge.hpp's Pieces), classified against the original patch's trim.
struct TrimmedStrip : TrimmedPaper {
  static constexpr double kStretch = 20.0;
  explicit TrimmedStrip(bool withHole) : TrimmedPaper(withHole) {
    for (Vec3& c : surface.patches[0].control) c.x *= kStretch;
  }
  Vec3 randomPoint(std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> alongX(-0.5 * kStretch, 3.5 * kStretch), across(-0.5, 3.5), up(-1.0, 2.5);
    return {alongX(rng), across(rng), up(rng)};
  }
  double queryReach() const { return 3.5 * kStretch; }
  // The circle is an ellipse 20 times as long: 10 times the samples keep their spacing within 2.
  int circleSamples() const { return 200000; }
};

TEST(TrimmedSurface, DistancesOnALongThinTrimmedPatchAreToTheFaceAlone) {
  for (const bool hole : {false, true}) checkDistancesAreToTheFaceAlone(TrimmedStrip(hole), 1416);
}

TEST(TrimmedSurface, DistancesToAHalfAngleTrimAreToTheFaceAlone) {
  for (const bool hole : {false, true}) checkDistancesAreToTheFaceAlone(TrimmedArch(hole), 1415);
}

// The design's heights on `grid` against a closed form: reference(x, y) gives the point's
// signed distance into the face (-infinity off the patch's square) and, inside, the surface's
// height there. Outside by 1e-9: no surface; inside by 1e-9: the height within 1e-9.
struct DesignReference {
  double margin, z;
};
void checkDesignIsTheFaceAlone(const Surface& surface, scallop::HeightGrid grid,
                               const std::function<DesignReference(double, double)>& reference,
                               int atLeast) {
  grid.z.assign(grid.columns * grid.rows, -kInf);
  scallop::designHeights(surface, grid, nullptr);
  int inside = 0, outside = 0;
  for (std::size_t j = 0; j < grid.rows; ++j)
    for (std::size_t i = 0; i < grid.columns; ++i) {
      const scallop::Vec2 at = grid.point(i, j);
      const double z = grid.z[j * grid.columns + i];
      const DesignReference expected = reference(at.x, at.y);
      if (expected.margin < -1e-9) {
        EXPECT_EQ(z, -kInf) << at.x << ", " << at.y;
        ++outside;
      } else if (expected.margin > 1e-9) {
        EXPECT_NEAR(z, expected.z, 1e-9) << at.x << ", " << at.y;
        ++inside;
      }
    }
  EXPECT_GT(inside, atLeast);
  EXPECT_GT(outside, atLeast);
}

// The simulated cut's design: over (x, y) = (3 t, 3 s) the surface's height where the face
// is, nothing elsewhere.
TEST(TrimmedSurface, TheDesignIsTheFaceAlone) {
  for (const bool hole : {false, true}) {
    SCOPED_TRACE(hole);
    const TrimmedPaper trimmed(hole);
    scallop::HeightGrid grid;
    grid.x0 = -0.05, grid.y0 = -0.05, grid.spacing = 0.02, grid.columns = 156, grid.rows = 156;
    checkDesignIsTheFaceAlone(
        trimmed.surface, grid,
        [&](double x, double y) {
          const double s = y / 3.0, t = x / 3.0;
          if (s < 0.0 || s > 1.0 || t < 0.0 || t > 1.0) return DesignReference{-kInf, 0.0};
          return DesignReference{trimmed.signedDistance(s, t), scallop::point(trimmed.surface.patches[0], s, t).z};
        },
        1000);
  }
}

// The arch's design over (x, y): the cylinder's height sqrt(4 - x^2) where the angle
// acos(x / 2) and y put the point in the face, nothing elsewhere (the arch's ends, where the
// height is steep, left out by 1e-9 in x).
TEST(TrimmedSurface, TheDesignOfAHalfAngleTrimIsTheFaceAlone) {
  for (const bool hole : {false, true}) {
    SCOPED_TRACE(hole);
    const TrimmedArch trimmed(hole);
    scallop::HeightGrid grid;
    grid.x0 = -1.8, grid.y0 = -0.1, grid.spacing = 0.02, grid.columns = 181, grid.rows = 161;
    checkDesignIsTheFaceAlone(
        trimmed.surface, grid,
        [&](double x, double y) {
          const double angle = std::acos(std::clamp(x / TrimmedArch::kRho, -1.0, 1.0));
          if (angle < TrimmedArch::kStart || angle > TrimmedArch::kEnd || y < 0.0 || y > 3.0)
            return DesignReference{-kInf, 0.0};
          double margin = TrimmedArch::kRadius - std::hypot(angle - TrimmedArch::kCentreU, y - TrimmedArch::kCentreV);
          if (hole) margin = -margin;
          // Inside, only where the arch is not near-vertical (its ends: the height's slope unbounded).
          if (margin > 0.0 && !(std::abs(x) < TrimmedArch::kRho * std::cos(TrimmedArch::kStart) - 1e-9))
            margin = 0.0;
          return DesignReference{margin, std::sqrt(TrimmedArch::kRho * TrimmedArch::kRho - x * x)};
        },
        3000);
  }
}

// What a trimmed surface must be, and what it cannot be written as.
TEST(TrimmedSurface, TrimsAreCheckedAndHaveNoJsonForm) {
  TrimmedPaper trimmed(false);
  EXPECT_NO_THROW(scallop::validateSurface(trimmed.surface));
  const auto message = [](const std::function<void()>& call) {
    try {
      call();
    } catch (const scallop::Error& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_NE(message([&] { (void)scallop::surfaceToJson(trimmed.surface); }).find("no JSON form"), std::string::npos);
  Surface two = trimmed.surface;
  two.patches.push_back(two.patches[0]);  // two patches, one trim
  EXPECT_NE(message([&] { scallop::validateSurface(two); }).find("trims: 1 for 2 patches"), std::string::npos);
  Surface flat = trimmed.surface;
  flat.trims[0].v.to = flat.trims[0].v.from;  // maps the square onto a segment
  EXPECT_NE(message([&] { scallop::validateSurface(flat); }).find("patches[0]: its trim's v: maps [0, 1] onto [2, 2]"),
            std::string::npos);
  TrimmedArch arch(false);
  EXPECT_NO_THROW(scallop::validateSurface(arch.surface));
  Surface pole = arch.surface;
  pole.trims[0].u.offset = -0.25 * pole.trims[0].u.slope;  // the denominator vanishes at s = 1/4
  EXPECT_NE(message([&] { scallop::validateSurface(pole); }).find("its trim's u: maps [0, 1] onto"), std::string::npos);
  // Angles that are not a monotone arc of less than a turn have no half-angle map.
  EXPECT_NE(message([] { (void)scallop::AxisMap::halfAngle(0.0, 1.0, 0.5); }).find("not a monotone arc"),
            std::string::npos);
  EXPECT_NE(message([] { (void)scallop::AxisMap::halfAngle(0.0, 3.5, 7.0); }).find("not a monotone arc"),
            std::string::npos);
}

}  // namespace
