// Trimmed surfaces (surface.hpp's trims, face_trim.hpp's PatchTrim): sections, distances and
// the simulated cut's design take only the face's part of a trimmed patch. The face here is
// paper-1's patch (x = 3 v, y = 3 u: a graph over the square [0, 3]^2) trimmed to a disk of
// its parameter square, or to the square minus a disk (a hole), the map to the face's
// parameters affine (scaled, shifted, u reversed), so every reference is in closed form or
// by dense sampling written here: the disk's membership of a point, the circle's parameters,
// brute-force distances over the disk and along its circle.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "scallop/bezier.hpp"
#include "scallop/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/face_trim.hpp"
#include "scallop/gouge.hpp"
#include "scallop/section.hpp"
#include "scallop/surface.hpp"

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
    if (hole) {
      // The square's boundary (u from 10 down to 6, v from 2 to 6), then the hole.
      const double corners[4][2] = {{6, 2}, {10, 2}, {10, 6}, {6, 6}};
      for (int i = 0; i < 4; ++i)
        face->arcs.push_back(
            TrimArc{{corners[i][0], corners[i][1], 1.0}, {corners[(i + 1) % 4][0], corners[(i + 1) % 4][1], 1.0}});
      for (const TrimArc& arc : circleArcs(cu, cv, r, true)) face->arcs.push_back(arc);
    } else {
      face->arcs = circleArcs(cu, cv, r, false);
    }
    PatchTrim trim;
    trim.face = face;
    trim.u0 = 10.0, trim.u1 = 6.0, trim.v0 = 2.0, trim.v1 = 6.0;
    trim.margin = 1e-12;
    surface.trims = {trim};
  }

  // The closed-form membership in the patch's parameters, with a band left undecided.
  double signedDistance(double s, double t) const {  // > 0 inside the face
    const double d = kRadius - std::hypot(s - kCentreS, t - kCentreT);
    return hole ? -d : d;
  }
};

// The paper surface's point over (x, y) = (3 t, 3 s): on paper-1, r(s, t) = (3 t, 3 s, z(s, t)).
TEST(TrimmedSurface, SectionsStopAtTheTrimmingCurve) {
  for (const bool hole : {false, true}) {
    const TrimmedPaper trimmed(hole);
    Surface untrimmed = trimmed.surface;
    untrimmed.trims.clear();
    int ends = 0, samples = 0;
    for (int k = 0; k < 24; ++k) {
      // Planes of several directions through the surface.
      const double angle = 0.3 + 0.25 * k;
      const Vec3 normal{std::cos(angle), std::sin(angle), k % 3 == 0 ? 0.0 : 0.4};
      const double offset = dot(normal, Vec3{1.5, 1.35, 0.6}) + 0.05 * (k % 5 - 2);
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

// The distance to the trimmed face against brute force over it: a 300 x 300 grid of the
// square kept where the disk test passes, plus 20,000 points of the circle, the best refined
// by a pattern search that stays in the face (a step leaving it is refused).
double referenceDistance(const TrimmedPaper& trimmed, Vec3 p) {
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
  for (int i = 0; i < 20000; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 20000.0;
    // Just inside the face: on the circle, pulled in by 1e-13.
    const double r = TrimmedPaper::kRadius + (trimmed.hole ? 1e-13 : -1e-13);
    consider(TrimmedPaper::kCentreS + r * std::cos(a), TrimmedPaper::kCentreT + r * std::sin(a));
  }
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

TEST(TrimmedSurface, DistancesAreToTheFaceAlone) {
  std::mt19937_64 rng(1414);
  std::uniform_real_distribution<double> across(-0.5, 3.5), up(-1.0, 2.5);
  for (const bool hole : {false, true}) {
    const TrimmedPaper trimmed(hole);
    const scallop::SurfaceDistance engine(trimmed.surface);
    Surface untrimmed = trimmed.surface;
    untrimmed.trims.clear();
    const scallop::SurfaceDistance whole(untrimmed);
    int fartherThanUntrimmed = 0;
    for (int i = 0; i < 120; ++i) {
      const Vec3 p{across(rng), across(rng), up(rng)};
      const scallop::ClosestPoint found = engine.closest(p);
      ASSERT_TRUE(found.converged) << i;
      const double reference = referenceDistance(trimmed, p);
      // The reference is a point of the face: an upper bound; its refinement reaches 1e-9.
      // Beside a trimming curve the search resolves the face to kTrimCellReach of its scale.
      const double reach = engine.tolerance() + scallop::kTrimCellReach * (scallop::surfaceScale(trimmed.surface) + 3.5);
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

// The simulated cut's design: over (x, y) = (3 t, 3 s) the surface's height where the face
// is, nothing elsewhere.
TEST(TrimmedSurface, TheDesignIsTheFaceAlone) {
  for (const bool hole : {false, true}) {
    const TrimmedPaper trimmed(hole);
    scallop::HeightGrid grid;
    grid.x0 = -0.05, grid.y0 = -0.05, grid.spacing = 0.02, grid.columns = 156, grid.rows = 156;
    grid.z.assign(grid.columns * grid.rows, -kInf);
    scallop::designHeights(trimmed.surface, grid, nullptr);
    int inside = 0, outside = 0;
    for (std::size_t j = 0; j < grid.rows; ++j)
      for (std::size_t i = 0; i < grid.columns; ++i) {
        const scallop::Vec2 at = grid.point(i, j);
        const double x = at.x, y = at.y;
        const double s = y / 3.0, t = x / 3.0;
        const double z = grid.z[j * grid.columns + i];
        const bool inSquare = s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0;
        const double margin = trimmed.signedDistance(s, t);
        if (!inSquare || margin < -1e-9) {
          EXPECT_EQ(z, -kInf) << x << ", " << y;
          ++outside;
        } else if (margin > 1e-9) {
          EXPECT_NEAR(z, scallop::point(trimmed.surface.patches[0], s, t).z, 1e-9) << x << ", " << y;
          ++inside;
        }
      }
    EXPECT_GT(inside, 1000) << hole;
    EXPECT_GT(outside, 1000) << hole;
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
  flat.trims[0].v1 = flat.trims[0].v0;  // maps the square onto a segment
  EXPECT_NE(message([&] { scallop::validateSurface(flat); }).find("not a rectangle"), std::string::npos);
}

}  // namespace
