// Plane sections against references written here: closed forms (a saddle z = xy cut through
// and beside its saddle point, a paraboloid cut through its vertex and in circles, tiny
// ones included), and, on random patches and the paper's surfaces, marching squares on a
// fine parameter grid (crossings on grid edges found by bisection, joined cell by cell).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <random>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/section.hpp"
#include "scallop/geometry/surface.hpp"
#include "support/rational_patches.hpp"

namespace {

using scallop::BezierPatch;
using scallop::PlaneSection;
using scallop::Surface;
using scallop::Vec3;

// z = x y on [-1, 1]^2: a bilinear patch (x along u, y along v).
Surface saddle() {
  Surface s;
  s.patches.push_back({1, 1, {{-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}, {1, 1, 1}}});
  return s;
}

// z = x^2 + y^2 on [-1, 1]^2: biquadratic, p_jk = (x_j, y_k, a_j + a_k) with x_j = -1, 0, 1
// and a = (1, -1, 1), the Bernstein coefficients of (2t - 1)^2.
Surface paraboloid() {
  Surface s;
  BezierPatch p{2, 2, {}};
  const double a[3] = {1, -1, 1};
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) p.control.push_back({j - 1.0, k - 1.0, a[j] + a[k]});
  s.patches.push_back(p);
  return s;
}

// The surface cut into a grid of pieces x pieces patches by restriction.
Surface split(const Surface& s, int pieces) {
  Surface out;
  out.units = s.units;
  for (const BezierPatch& p : s.patches)
    for (int i = 0; i < pieces; ++i)
      for (int j = 0; j < pieces; ++j)
        out.patches.push_back(scallop::restrictTo(p, double(i) / pieces, double(i + 1) / pieces,
                                                  double(j) / pieces, double(j + 1) / pieces));
  return out;
}

double totalLength(const PlaneSection& s) {
  double sum = 0.0;
  for (const auto& c : s.curves) sum += scallop::curveLength(c);
  return sum;
}

double distanceToSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = scallop::dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(scallop::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return scallop::norm(p - (a + t * ab));
}

double distanceToSection(const Vec3& p, const PlaneSection& s) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& c : s.curves)
    for (std::size_t i = 1; i < c.points.size(); ++i)
      best = std::min(best, distanceToSegment(p, c.points[i - 1].point, c.points[i].point));
  return best;
}

// Marching squares on a (g x g)-cell parameter grid per patch: crossings of f = n . r - d on
// grid edges by bisection, each cell's crossings joined in pairs (the saddle-cell choice by
// the value at the cell centre), pieces joined into components by shared crossings and, across
// patches, by coincident points.
struct Marching {
  std::vector<Vec3> crossings;
  double length = 0.0;
  std::size_t components = 0;
};

Marching marchingSquares(const Surface& s, const Vec3& n, double d, int g) {
  Marching out;
  std::vector<std::pair<std::size_t, std::size_t>> links;
  for (const BezierPatch& patch : s.patches) {
    auto f = [&](double u, double v) { return scallop::dot(n, scallop::point(patch, u, v)) - d; };
    std::vector<double> value((g + 1) * (g + 1));
    for (int i = 0; i <= g; ++i)
      for (int j = 0; j <= g; ++j) value[i * (g + 1) + j] = f(double(i) / g, double(j) / g);
    // Crossing index per grid edge (horizontal: along u; vertical: along v).
    std::map<std::pair<int, int>, std::size_t> alongU, alongV;
    auto crossing = [&](double u0, double v0, double u1, double v1, double f0) {
      double lo = 0, hi = 1;
      for (int it = 0; it < 60; ++it) {
        const double t = 0.5 * (lo + hi);
        const double ft = f(u0 + t * (u1 - u0), v0 + t * (v1 - v0));
        if ((ft < 0) == (f0 < 0)) lo = t; else hi = t;
      }
      const double t = 0.5 * (lo + hi);
      out.crossings.push_back(scallop::point(patch, u0 + t * (u1 - u0), v0 + t * (v1 - v0)));
      return out.crossings.size() - 1;
    };
    for (int i = 0; i <= g; ++i)
      for (int j = 0; j <= g; ++j) {
        const double f0 = value[i * (g + 1) + j];
        if (i < g && (f0 < 0) != (value[(i + 1) * (g + 1) + j] < 0))
          alongU[{i, j}] = crossing(double(i) / g, double(j) / g, double(i + 1) / g, double(j) / g, f0);
        if (j < g && (f0 < 0) != (value[i * (g + 1) + j + 1] < 0))
          alongV[{i, j}] = crossing(double(i) / g, double(j) / g, double(i) / g, double(j + 1) / g, f0);
      }
    for (int i = 0; i < g; ++i)
      for (int j = 0; j < g; ++j) {
        std::vector<std::size_t> c;
        // Order around the cell: bottom (v = j), right (u = i + 1), top (v = j + 1), left (u = i).
        if (alongU.count({i, j})) c.push_back(alongU[{i, j}]);
        if (alongV.count({i + 1, j})) c.push_back(alongV[{i + 1, j}]);
        if (alongU.count({i, j + 1})) c.push_back(alongU[{i, j + 1}]);
        if (alongV.count({i, j})) c.push_back(alongV[{i, j}]);
        if (c.size() == 2) {
          links.push_back({c[0], c[1]});
        } else if (c.size() == 4) {
          const bool centreNegative = f((i + 0.5) / g, (j + 0.5) / g) < 0;
          const bool cornerNegative = value[i * (g + 1) + j] < 0;
          // Corner (i, j) sits between the bottom and left crossings.
          if (centreNegative == cornerNegative) {
            links.push_back({c[0], c[1]});
            links.push_back({c[2], c[3]});
          } else {
            links.push_back({c[3], c[0]});
            links.push_back({c[1], c[2]});
          }
        }
      }
  }
  std::vector<std::size_t> parent(out.crossings.size());
  std::iota(parent.begin(), parent.end(), 0);
  std::function<std::size_t(std::size_t)> find = [&](std::size_t i) {
    return parent[i] == i ? i : parent[i] = find(parent[i]);
  };
  for (auto [a, b] : links) {
    out.length += scallop::norm(out.crossings[a] - out.crossings[b]);
    parent[find(a)] = find(b);
  }
  // Across patch edges: crossings at the same point.
  const double eps = 1e-9;
  for (std::size_t a = 0; a < out.crossings.size(); ++a)
    for (std::size_t b = a + 1; b < out.crossings.size(); ++b)
      if (scallop::norm(out.crossings[a] - out.crossings[b]) < eps) parent[find(a)] = find(b);
  for (std::size_t i = 0; i < parent.size(); ++i)
    if (find(i) == i) ++out.components;
  return out;
}

TEST(Section, SaddleCutThroughItsSaddlePointIsOneCross) {
  const PlaneSection s = scallop::planeSection(saddle(), {0, 0, 1}, 0.0, 1e-6);
  EXPECT_EQ(s.components, 1u);
  // The two axes x = 0 and y = 0 across the square: four arms of length 1 meeting at 0.
  EXPECT_NEAR(totalLength(s), 4.0, 1e-5);
  // On the plane to rounding, but for the junction: the centre of a cell of width ~2^-18
  // around the saddle point, where z = x y is of the order of its width squared.
  for (const auto& c : s.curves)
    for (const auto& p : c.points)
      EXPECT_NEAR(p.point.z, 0.0, scallop::norm(p.point) < 1e-4 ? 1e-10 : 1e-14);
  for (double t = -1.0; t <= 1.0; t += 0.125) {
    EXPECT_LT(distanceToSection({t, 0, 0}, s), 1e-5);
    EXPECT_LT(distanceToSection({0, t, 0}, s), 1e-5);
  }
}

TEST(Section, SaddleCutBesideItsSaddlePointIsTwoHyperbolaBranches) {
  for (double c : {0.25, -0.25, 1e-3, -1e-6}) {
    const PlaneSection s = scallop::planeSection(saddle(), {0, 0, 1}, c, 1e-7);
    EXPECT_EQ(s.components, 2u) << c;
    ASSERT_EQ(s.curves.size(), 2u) << c;
    // Each branch of x y = c from x = |c| to 1: length by a fine midpoint rule in the test.
    double branch = 0.0;
    const int steps = 200000;
    const double a = std::abs(c);
    for (int i = 0; i < steps; ++i) {
      // Parametrise by the angle along the branch to stay accurate near the asymptotes:
      // x = sqrt(a) e^t, y = sqrt(a) e^-t, t in [ln sqrt(a), -ln sqrt(a)].
      const double t0 = std::log(std::sqrt(a));
      const double t = t0 + (-2.0 * t0) * (i + 0.5) / steps;
      branch += std::sqrt(a) * std::sqrt(std::exp(2 * t) + std::exp(-2 * t)) * (-2.0 * t0) / steps;
    }
    EXPECT_NEAR(totalLength(s), 2.0 * branch, 1e-5 * branch) << c;
    for (const auto& curve : s.curves) {
      EXPECT_FALSE(curve.closed);
      for (const auto& p : curve.points) EXPECT_NEAR(p.point.x * p.point.y, c, 1e-12);
    }
  }
}

TEST(Section, ParaboloidTouchedAtItsVertexHasNoCurve) {
  const PlaneSection s = scallop::planeSection(paraboloid(), {0, 0, 1}, 0.0, 1e-6);
  EXPECT_TRUE(s.curves.empty());
  ASSERT_FALSE(s.touchPoints.empty());
  for (const auto& p : s.touchPoints) EXPECT_LT(scallop::norm(p.point), 1e-5);
  // Below the vertex: nothing at all.
  EXPECT_TRUE(scallop::planeSection(paraboloid(), {0, 0, 1}, -1e-3, 1e-6).curves.empty());
}

TEST(Section, ParaboloidCirclesAreClosedLoops) {
  for (double z : {0.5, 1e-2, 1e-8}) {
    const double radius = std::sqrt(z);
    const double tolerance = 1e-4 * radius;
    for (const Surface& surface : {paraboloid(), split(paraboloid(), 2), split(paraboloid(), 3)}) {
      const PlaneSection s = scallop::planeSection(surface, {0, 0, 1}, z, tolerance);
      EXPECT_EQ(s.components, 1u) << z;
      ASSERT_EQ(s.curves.size(), 1u) << z;
      EXPECT_TRUE(s.curves[0].closed) << z;
      // A polygon inscribed in the circle with sagitta <= tolerance: length within
      // 2 pi r (1 - ...) and 2 pi r.
      const double length = totalLength(s);
      EXPECT_LE(length, 2 * std::numbers::pi * radius * (1 + 1e-12)) << z;
      EXPECT_GE(length, 2 * std::numbers::pi * radius * (1 - 2 * tolerance / radius)) << z;
      for (const auto& p : s.curves[0].points)
        EXPECT_NEAR(std::hypot(p.point.x, p.point.y), radius, 1e-9 + 1e-12 / radius) << z;
    }
  }
}

TEST(Section, PlaneThroughAPatchCornerAndAlongAnEdge) {
  // z = x y is zero along x = 0 and y = 0; the bilinear patch on [0, 1]^2 has the plane
  // z = 0 along two of its boundary edges.
  Surface s;
  s.patches.push_back({1, 1, {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 1}}});
  const PlaneSection section = scallop::planeSection(s, {0, 0, 1}, 0.0, 1e-6);
  for (const auto& c : section.curves)
    for (const auto& p : c.points) EXPECT_NEAR(p.point.z, 0.0, 1e-14);
  // The two boundary edges x = 0 and y = 0, joined at the origin into one curve.
  EXPECT_EQ(section.components, 1u);
  ASSERT_EQ(section.curves.size(), 1u);
  EXPECT_NEAR(totalLength(section), 2.0, 1e-12);
  // The corner (1, 1, 1) lies in the plane z = 1: a single point of the surface.
  const PlaneSection corner = scallop::planeSection(s, {0, 0, 1}, 1.0, 1e-6);
  EXPECT_LT(totalLength(corner), 1e-6);
}

// Random bicubic graph patches and the paper's surfaces, random planes: every crossing that
// marching squares finds lies on our curves (within the chordal tolerance), our vertices lie
// on the plane, the lengths agree to the grid's accuracy and the components agree.
TEST(Section, AgreesWithMarchingSquares) {
  std::mt19937_64 rng(20261121);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Surface> surfaces{scallop::exampleSurface("paper-1"), scallop::exampleSurface("paper-2"),
                                split(scallop::exampleSurface("paper-1"), 2)};
  for (int i = 0; i < 4; ++i) {
    Surface s;
    BezierPatch p{3, 3, {}};
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) p.control.push_back({double(k), double(j), 2.0 * unit(rng)});
    s.patches.push_back(p);
    surfaces.push_back(s);
  }
  int cases = 0;
  for (const Surface& s : surfaces) {
    for (int trial = 0; trial < 6; ++trial) {
      const double theta = std::acos(2 * unit(rng) - 1), phi = 2 * std::numbers::pi * unit(rng);
      Vec3 n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      // An offset through a random point of the surface.
      const Vec3 at = scallop::point(s.patches[0], unit(rng), unit(rng));
      const double d = scallop::dot(n, at);
      const double tolerance = 1e-4;
      const PlaneSection ours = scallop::planeSection(s, n, d, tolerance);
      const Marching reference = marchingSquares(s, n, d, 400);
      for (const auto& c : ours.curves)
        for (const auto& p : c.points) EXPECT_NEAR(scallop::dot(n, p.point), d, 1e-12);
      double worst = 0.0;
      for (const Vec3& x : reference.crossings) worst = std::max(worst, distanceToSection(x, ours));
      EXPECT_LT(worst, 2 * tolerance) << "surface " << &s - &surfaces[0] << " trial " << trial;
      EXPECT_NEAR(totalLength(ours), reference.length, 2e-3 * reference.length + 1e-9);
      EXPECT_EQ(ours.components, reference.components)
          << "surface " << &s - &surfaces[0] << " trial " << trial;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 42);
}

// Rational patches (bezier.hpp): random bumpy ones against marching squares (which evaluates
// the rational points), and torus patches against the closed form: z = c cuts the outer quarter
// in a quarter circle of radius a + sqrt(b^2 - c^2).
TEST(Section, RationalPatchesAgreeWithMarchingSquaresAndTheTorus) {
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int cases = 0;
  for (int i = 0; i < 6; ++i) {
    const Surface s{scallop::Units::inch, {scallop::test::randomRationalPatch(rng, 1 + i % 3, 2 + i % 2)}};
    for (int trial = 0; trial < 4; ++trial) {
      const double theta = std::acos(2 * unit(rng) - 1), phi = 2 * std::numbers::pi * unit(rng);
      const Vec3 n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      const double d = scallop::dot(n, scallop::point(s.patches[0], unit(rng), unit(rng)));
      const double tolerance = 1e-4;
      const PlaneSection ours = scallop::planeSection(s, n, d, tolerance);
      const Marching reference = marchingSquares(s, n, d, 400);
      for (const auto& c : ours.curves)
        for (const auto& p : c.points) {
          EXPECT_NEAR(scallop::dot(n, p.point), d, 1e-12);
          EXPECT_LE(scallop::norm(p.point - scallop::point(s.patches[0], p.u, p.v)), 1e-14);
        }
      double worst = 0.0;
      for (const Vec3& x : reference.crossings) worst = std::max(worst, distanceToSection(x, ours));
      EXPECT_LT(worst, 2 * tolerance) << "patch " << i << " trial " << trial;
      EXPECT_NEAR(totalLength(ours), reference.length, 2e-3 * reference.length + 1e-9);
      EXPECT_EQ(ours.components, reference.components) << "patch " << i << " trial " << trial;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 24);
  const double a = 3.0, b = 1.0;
  const Surface torus{scallop::Units::inch, {scallop::test::torusPatch(a, b, true)}};
  for (const double c : {0.1, 0.5, 0.9}) {
    const PlaneSection ours = scallop::planeSection(torus, {0, 0, 1}, c, 1e-6);
    ASSERT_EQ(ours.curves.size(), 1u) << c;
    const double radius = a + std::sqrt(b * b - c * c);
    for (const auto& p : ours.curves[0].points) EXPECT_NEAR(std::hypot(p.point.x, p.point.y), radius, 1e-12);
    // The polyline is inscribed: shorter than the arc by at most its chords' sag.
    const double arc = 0.5 * std::numbers::pi * radius;
    EXPECT_LE(totalLength(ours), arc + 1e-12) << c;
    EXPECT_GE(totalLength(ours), arc * (1.0 - 1e-5)) << c;
  }
}

// Ten heights across the surface's range (sampled on a 101 x 101 grid), off the round ones.
std::vector<double> heightsAcross(const Surface& surface) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const BezierPatch& patch : surface.patches)
    for (int i = 0; i <= 100; ++i)
      for (int j = 0; j <= 100; ++j) {
        const double z = scallop::point(patch, i / 100.0, j / 100.0).z;
        low = std::min(low, z), high = std::max(high, z);
      }
  std::vector<double> heights;
  for (int k = 0; k < 10; ++k) heights.push_back(low + (high - low) * (k + 0.37) / 10);
  return heights;
}

TEST(Section, SplitSurfaceGivesTheSameSection) {
  const Surface whole = scallop::exampleSurface("paper-2");
  const Surface pieces = split(whole, 3);
  for (const double z : heightsAcross(whole)) {
    ASSERT_FALSE(scallop::planeSection(whole, {0, 0, 1}, z, 1e-5).curves.empty()) << z;
    const PlaneSection a = scallop::planeSection(whole, {0, 0, 1}, z, 1e-5);
    const PlaneSection b = scallop::planeSection(pieces, {0, 0, 1}, z, 1e-5);
    EXPECT_EQ(a.components, b.components) << z;
    EXPECT_EQ(a.curves.size(), b.curves.size()) << z;
    EXPECT_NEAR(totalLength(a), totalLength(b), 1e-4) << z;
  }
}

// A CAD model's faces meet only to the model's tolerance: paper-2 split into 3 x 3 patches,
// each moved by g / 2 in a random direction (so neighbours stand up to g apart), is the judge's
// model of such faces. With each patch's seam tolerance g, its sections are those of the whole
// surface (the same curves, closed where those are); without it, or with a chordal tolerance
// below the gaps, they break at the seams; a tolerance a hundredth of the gaps joins fewer.
TEST(Section, SeamsOfACadModelJoinWithinTheirTolerance) {
  const Surface whole = scallop::exampleSurface("paper-2");
  const double gap = 1e-6;  // paper-2 spans about 1 inch
  Surface apart = split(whole, 3);
  std::mt19937 random(20261128);
  std::normal_distribution<double> normal;
  for (BezierPatch& patch : apart.patches) {
    Vec3 shift{normal(random), normal(random), normal(random)};
    shift = shift * (0.5 * gap / scallop::norm(shift));
    for (Vec3& point : patch.control) point = point + shift;
  }
  const Surface together = split(whole, 3);
  std::size_t seamPlanes = 0, fewerJoins = 0;
  for (const double z : heightsAcross(whole)) {
    const PlaneSection reference = scallop::planeSection(whole, {0, 0, 1}, z, 1e-5);
    ASSERT_FALSE(reference.curves.empty()) << z;
    // Whether the section crosses a seam: a curve of the unmoved pieces on two patches.
    bool crossesSeam = false;
    for (const auto& curve : scallop::planeSection(together, {0, 0, 1}, z, 1e-5).curves)
      for (const auto& point : curve.points) crossesSeam |= point.patch != curve.points.front().patch;
    const auto closedCount = [](const PlaneSection& s) {
      return std::count_if(s.curves.begin(), s.curves.end(), [](const auto& c) { return c.closed; });
    };
    apart.seamTolerances.assign(apart.patches.size(), gap);
    const PlaneSection joined = scallop::planeSection(apart, {0, 0, 1}, z, 1e-5);
    EXPECT_EQ(joined.components, reference.components) << z;
    EXPECT_EQ(joined.curves.size(), reference.curves.size()) << z;
    EXPECT_EQ(closedCount(joined), closedCount(reference)) << z;
    EXPECT_NEAR(totalLength(joined), totalLength(reference), 1e-4) << z;

    apart.seamTolerances.clear();
    const PlaneSection broken = scallop::planeSection(apart, {0, 0, 1}, z, 1e-5);
    apart.seamTolerances.assign(apart.patches.size(), gap);
    const PlaneSection capped = scallop::planeSection(apart, {0, 0, 1}, z, 1e-8);
    apart.seamTolerances.assign(apart.patches.size(), gap / 100);
    const PlaneSection tight = scallop::planeSection(apart, {0, 0, 1}, z, 1e-5);
    if (!crossesSeam) continue;
    ++seamPlanes;
    EXPECT_GT(broken.curves.size(), reference.curves.size()) << z;
    EXPECT_GT(capped.curves.size(), reference.curves.size()) << z;
    if (tight.curves.size() > reference.curves.size()) ++fewerJoins;
  }
  EXPECT_GE(seamPlanes, 4u);
  EXPECT_GE(fewerJoins, seamPlanes / 2);
}

TEST(Section, BadPlanesAreErrors) {
  const Surface s = saddle();
  EXPECT_THROW(scallop::planeSection(s, {0, 0, 0}, 0.0, 1e-3), scallop::Error);
  EXPECT_THROW(scallop::planeSection(s, {std::nan(""), 0, 1}, 0.0, 1e-3), scallop::Error);
  EXPECT_THROW(scallop::planeSection(s, {0, 0, 1}, std::nan(""), 1e-3), scallop::Error);
  EXPECT_THROW(scallop::planeSection(s, {0, 0, 1}, 0.0, 0.0), scallop::Error);
  EXPECT_THROW(scallop::planeSection(s, {0, 0, 1}, 0.0, -1.0), scallop::Error);
}

}  // namespace
