// Contour paths: Table 1 of Smith, Farouki, al-Kandari, Pottmann (the paper's own figures are
// the reference), the scallop-height spacing against a brute-force cusp on an inclined plane,
// the proven minimum angle against dense normals, the plane range against dense sampling.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

using scallop::BezierPatch;
using scallop::ContourOptions;
using scallop::Surface;
using scallop::Vec3;

constexpr double kDeg = std::numbers::pi / 180.0;

struct TableRow {
  const char* surface;
  double spacing;
  Vec3 normal;
  double paperLength;      // inches, the paper's Table 1
  std::size_t paperComponents;
};

// Table 1 of the paper (tool radius 0.25 in). Our lengths are the tool-centre paths, our
// components the connected pieces of each section, summed over the planes.
TEST(Contour, ReproducesTable1) {
  const TableRow rows[] = {
      {"paper-1", 0.0051, {0, 0, 1}, 369.41, 211},
      {"paper-1", 0.025, {0.248, -0.969, 0.001}, 369.95, 146},
      {"paper-2", 0.01, {0, 0, 1}, 359.51, 358},
      {"paper-2", 0.0267, {0.975, -0.221, -0.002}, 359.23, 134},
  };
  for (const TableRow& row : rows) {
    ContourOptions options;
    options.normal = row.normal;
    options.spacing = row.spacing;
    options.toolRadius = 0.25;
    options.dropEnvelope = false;  // the paper's paths: r + R n, unlifted
    const auto result = scallop::contourPaths(scallop::exampleSurface(row.surface), options);
    EXPECT_NEAR(result.stats.centreLength, row.paperLength, 0.01 * row.paperLength) << row.surface;
    EXPECT_LE(std::abs(double(result.stats.components) - double(row.paperComponents)), 3.0)
        << row.surface << " " << result.stats.components;
    EXPECT_EQ(result.path.passes.size(), result.stats.components) << row.surface;
  }
}

// The tool centres sit at R along the upward normal from their contact points, and every
// plane that dense sampling shows crossing the surface is among the planes that cut.
TEST(Contour, CentresAndPlanes) {
  const Surface s = scallop::exampleSurface("paper-1");
  ContourOptions options;
  options.normal = {0.3, -0.9, 0.2};
  options.spacing = 0.05;
  options.toolRadius = 0.25;
  options.dropEnvelope = false;  // the centres r + R n themselves (lifting: envelope_test.cpp)
  const auto result = scallop::contourPaths(s, options);
  const Vec3 n = scallop::normalized(options.normal);
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 200; ++j) {
      const double h = scallop::dot(n, scallop::point(s.patches[0], i / 200.0, j / 200.0));
      lo = std::min(lo, h), hi = std::max(hi, h);
    }
  std::size_t expected = 0;
  for (double k = std::ceil(lo / options.spacing); k * options.spacing < hi; k += 1.0) ++expected;
  EXPECT_EQ(result.stats.planes, expected);
  ASSERT_EQ(result.sections.size(), expected);
  std::size_t passIndex = 0;
  for (const auto& plane : result.sections) {
    for (const auto& curve : plane.section.curves) {
      const auto& pass = result.path.passes.at(passIndex++);
      ASSERT_EQ(pass.moves.size() + 1, curve.points.size());
      for (std::size_t i = 0; i < curve.points.size(); ++i) {
        const auto& p = curve.points[i];
        const Vec3 centre = i == 0 ? pass.start : pass.moves[i - 1].end;
        const Vec3 normal = scallop::unitNormal(s.patches[p.patch], p.u, p.v);
        EXPECT_NEAR(scallop::norm(centre - p.point), 0.25, 1e-12);
        // Along +-n, and above the surface (the graph's normal points up).
        EXPECT_NEAR(std::abs(scallop::dot(centre - p.point, normal)), 0.25, 1e-12);
        EXPECT_GT(centre.z, p.point.z);
      }
    }
  }
}

// On the inclined plane z = x tan(beta), planes z = k Delta meet the surface in lines
// Delta / sin(beta) apart along it; balls of radius R on neighbouring lines leave a cusp.
// Its height is measured here by brute force (the lowest point of the union of the two balls'
// lower hemispheres above the surface, sampled densely) and must equal H.
TEST(Contour, ScallopHeightSpacingOnAnInclinedPlane) {
  for (double beta : {10.0 * kDeg, 35.0 * kDeg, 80.0 * kDeg}) {
    for (double H : {1e-4, 1e-3, 0.02}) {
      const double R = 0.25;
      const double delta = scallop::spacingForScallopHeight(R, H, beta);
      // In the surface's own frame (s along the slope, h above it) the contacts are
      // l = Delta / sin(beta) apart and the balls' centres at height R.
      // Contact lines at x_k = k Delta / tan(beta); along the slope 1 / cos(beta) times that.
      const double l = (delta / std::tan(beta)) / std::cos(beta);
      double cusp = 0.0;
      for (int i = 0; i <= 100000; ++i) {
        const double s = l * i / 100000.0;
        // The lowest material point left at s: the lower of the two balls' bottoms.
        const double a = R - std::sqrt(std::max(0.0, R * R - s * s));
        const double b = R - std::sqrt(std::max(0.0, R * R - (l - s) * (l - s)));
        cusp = std::max(cusp, std::min(a, b));
      }
      EXPECT_NEAR(cusp, H, 1e-9) << beta << " " << H;
    }
  }
  EXPECT_THROW(scallop::spacingForScallopHeight(0.25, 0.25, 1.0), scallop::Error);
  EXPECT_THROW(scallop::spacingForScallopHeight(0.25, 0.0, 1.0), scallop::Error);
  EXPECT_THROW(scallop::spacingForScallopHeight(-1.0, 0.1, 1.0), scallop::Error);
  EXPECT_THROW(scallop::spacingForScallopHeight(0.25, 0.01, 0.0), scallop::Error);
}

TEST(Contour, MinimumAngleBoundAgainstDenseNormals) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = scallop::exampleSurface(name);
    std::vector<Vec3> normals;
    for (int i = 0; i <= 300; ++i)
      for (int j = 0; j <= 300; ++j)
        normals.push_back(scallop::unitNormal(s.patches[0], i / 300.0, j / 300.0));
    for (int trial = 0; trial < 8; ++trial) {
      const Vec3 m = scallop::normalized({gauss(rng), gauss(rng), gauss(rng)});
      double worst = 0.0;
      std::size_t at = 0;
      for (std::size_t i = 0; i < normals.size(); ++i)
        if (std::abs(scallop::dot(normals[i], m)) > worst)
          worst = std::abs(scallop::dot(normals[i], m)), at = i;
      double sampled = std::acos(std::min(1.0, worst));
      // Refine the best sample by a shrinking pattern search: where m is itself a surface
      // normal (inside the Gauss map) the grid shows only its spacing, the truth is 0.
      double u = double(at / 301) / 300, v = double(at % 301) / 300;
      for (double step = 1.0 / 300; step > 1e-13; step *= 0.5)
        for (bool moved = true; moved;) {
          moved = false;
          for (auto [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
            const double a = std::clamp(u + du * step, 0.0, 1.0), b = std::clamp(v + dv * step, 0.0, 1.0);
            const double c = std::abs(scallop::dot(scallop::unitNormal(s.patches[0], a, b), m));
            if (c > worst) worst = c, u = a, v = b, moved = true;
          }
        }
      sampled = std::min(sampled, std::acos(std::min(1.0, worst)));
      const double bound = scallop::minimumAngleBound(s, m);
      EXPECT_LE(bound, sampled + 1e-12) << name;
      EXPECT_GT(bound, sampled - 0.01 * kDeg) << name << " sampled " << sampled;
    }
  }
}

TEST(Contour, BadOptionsAreErrors) {
  const Surface s = scallop::exampleSurface("paper-1");
  auto run = [&](Vec3 n, double spacing, double radius) {
    ContourOptions o;
    o.normal = n;
    o.spacing = spacing;
    o.toolRadius = radius;
    return scallop::contourPaths(s, o);
  };
  EXPECT_THROW(run({0, 0, 0}, 0.1, 0.25), scallop::Error);
  EXPECT_THROW(run({0, std::nan(""), 1}, 0.1, 0.25), scallop::Error);
  EXPECT_THROW(run({0, 0, 1}, 0.0, 0.25), scallop::Error);
  EXPECT_THROW(run({0, 0, 1}, -0.1, 0.25), scallop::Error);
  EXPECT_THROW(run({0, 0, 1}, 0.1, 0.0), scallop::Error);
  EXPECT_THROW(run({0, 0, 1}, 0.1, std::nan("")), scallop::Error);
  // Spacing so wide that no plane k Delta cuts the surface (z in [0.45, 1.1] or so).
  try {
    run({0, 0, 1}, 50.0, 0.25);
    FAIL() << "expected an error";
  } catch (const scallop::Error& e) {
    EXPECT_NE(std::string(e.what()).find("cuts the surface"), std::string::npos) << e.what();
  }
}

}  // namespace
