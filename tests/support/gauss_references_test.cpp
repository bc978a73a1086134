// Tests of the brute-force optimal slicing reference (gauss_references.hpp) on surfaces whose
// answer is known: planes (90 degrees, with and without a collapsed row), a paraboloid whose
// normals are known in closed form (one regular patch, and the same cap as four patches
// meeting at an apex), the paper's test surfaces (the values of its Section 4), a rotated
// copy, and the closed teapot (0).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <vector>

#include "support/gauss_references.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

using reference::bruteForceOptimalAlpha;
using reference::BruteForceSlicing;
using reference::sampleRegularNormals;

constexpr double kDegree = std::numbers::pi / 180.0;

double degrees(double radians) { return radians / kDegree; }

// The angle between two lines (directions up to sign), in degrees.
double lineAngleDeg(const Vec3& a, const Vec3& b) {
  return degrees(std::acos(std::min(1.0, std::abs(dot(normalized(a), normalized(b))))));
}

BezierPatch patchOf(int m, int n, const std::vector<Vec3>& points) {
  BezierPatch patch;
  patch.degreeU = m;
  patch.degreeV = n;
  patch.control = points;
  return patch;
}

// The paraboloid z = (x^2 + y^2) / 2 over the square [-a, a]^2 as one biquadratic patch (x
// along k, y along j). Its unit normals are (-x, -y, 1) / sqrt(1 + x^2 + y^2), so with the
// slicing normal N = (1, 0, 0), max |N . n| = a / sqrt(1 + a^2), at the edges x = +-a, y = 0,
// and alpha = 90 deg - atan(a); no other N does better (N tilted out of the plane z = 0 comes
// nearer one of the edges x = +-a; turned about z, it meets the corner normals, the gain
// being phi^2 / (2a) to second order in the angle phi).
BezierPatch paraboloidSquare(double a) {
  const double t[3] = {-a, 0.0, a};           // x (or y) at the Bernstein coefficients
  const double s[3] = {a * a, -a * a, a * a};  // x^2 in degree-2 Bernstein form on [-a, a]
  std::vector<Vec3> points;
  for (int j = 0; j <= 2; ++j) {
    for (int k = 0; k <= 2; ++k) points.push_back({t[k], t[j], 0.5 * (s[k] + s[j])});
  }
  return patchOf(2, 2, points);
}

// The same paraboloid over the triangle (0, 0), p, q, as the degenerate patch
// (x, y) = u ((1 - v) p + v q), z = u^2 g(v) / 2 with g(v) = |(1 - v) p + v q|^2, bidegree
// (2, 2): p_jk = ((j / 2) L_k, [j = 2] g_k / 2), L = (p, (p + q) / 2, q), g = (|p|^2, p . q,
// |q|^2). Its row p_0k is collapsed to the apex (0, 0, 0), where r_v = 0.
BezierPatch paraboloidTriangle(double px, double py, double qx, double qy) {
  const double lx[3] = {px, 0.5 * (px + qx), qx};
  const double ly[3] = {py, 0.5 * (py + qy), qy};
  const double g[3] = {px * px + py * py, px * qx + py * qy, qx * qx + qy * qy};
  std::vector<Vec3> points;
  for (int j = 0; j <= 2; ++j) {
    for (int k = 0; k <= 2; ++k) {
      points.push_back({0.5 * j * lx[k], 0.5 * j * ly[k], j == 2 ? 0.5 * g[k] : 0.0});
    }
  }
  return patchOf(2, 2, points);
}

TEST(BruteForceSlicing, PlaneGivesNinetyDegrees) {
  // A tilted bilinear plane patch: every normal is n = (1, 2, 3) / |.|.
  const Vec3 e1{1.0, 1.0, -1.0};
  const Vec3 e2{-1.0, 0.5, 0.0};
  const Surface plane{Units::inch,
                      {patchOf(1, 1, {{0.0, 0.0, 0.0}, e2, e1, e1 + e2})}};
  const BruteForceSlicing result = bruteForceOptimalAlpha(plane);
  EXPECT_NEAR(degrees(result.alphaRad), 90.0, 1e-6);
  EXPECT_NEAR(dot(result.direction, normalized(Vec3{1.0, 2.0, 3.0})), 0.0, 1e-8);
  EXPECT_NEAR(norm(result.direction), 1.0, 1e-12);
}

TEST(BruteForceSlicing, CollapsedRowIsSkipped) {
  // A flat triangle as a bilinear patch whose row p_0k is one point (the apex): r_v = 0 on
  // u = 0, where unitNormal would throw. The reference skips those samples.
  const Surface triangle{Units::inch,
                         {patchOf(1, 1, {{0.0, 0.0, 1.0}, {0.0, 0.0, 1.0},
                                         {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}})}};
  const std::vector<Vec3> normals = sampleRegularNormals(triangle, 8);
  // The 9 grid samples on u = 0 are left out, and of the 4 x 9 rays into the corners (at
  // 1e-6), the two along u = 0 itself.
  EXPECT_EQ(normals.size(), 9u * 8u + 4u * 9u - 2u);
  for (const Vec3& n : normals) EXPECT_NEAR(std::abs(dot(n, normalized(Vec3{1, 1, 1}))), 1.0, 1e-15);
  EXPECT_NEAR(degrees(bruteForceOptimalAlpha(triangle).alphaRad), 90.0, 1e-6);
}

TEST(BruteForceSlicing, ParaboloidWithKnownNormals) {
  // The samples miss normals, so the sampled optimum can only be larger than the true one,
  // here by turning N about z a little: the grid's normals nearest the edge's (y = 0) then
  // lie on the grid line y = 2a / 128, not at the true maximiser y* ~ phi (1 + a^2) / a. The
  // gain is second order in the grid step: 3.5e-5 deg (a = 0.5) to 2.2e-3 deg (a = 2), at
  // phi up to 0.4 deg.
  for (const double a : {0.5, 1.0, 2.0}) {
    const double expected = 90.0 - degrees(std::atan(a));
    const double slack = 3e-3;
    auto nearAxis = [](const Vec3& direction) {
      return std::min(lineAngleDeg(direction, {1, 0, 0}), lineAngleDeg(direction, {0, 1, 0}));
    };
    // One regular patch.
    const Surface square{Units::inch, {paraboloidSquare(a)}};
    const BruteForceSlicing one = bruteForceOptimalAlpha(square);
    EXPECT_GE(degrees(one.alphaRad), expected - 1e-9) << "a = " << a;
    EXPECT_LE(degrees(one.alphaRad), expected + slack) << "a = " << a;
    EXPECT_LT(nearAxis(one.direction), 0.5) << "a = " << a;
    // The same cap as four triangles meeting at the apex (0, 0, 0), each with a collapsed
    // row there, as the teapot's knob and bottom meet at theirs.
    const Surface fan{Units::inch,
                      {paraboloidTriangle(a, -a, a, a), paraboloidTriangle(a, a, -a, a),
                       paraboloidTriangle(-a, a, -a, -a), paraboloidTriangle(-a, -a, a, -a)}};
    const BruteForceSlicing four = bruteForceOptimalAlpha(fan);
    EXPECT_GE(degrees(four.alphaRad), expected - 1e-9) << "a = " << a;
    EXPECT_LE(degrees(four.alphaRad), expected + slack) << "a = " << a;
    EXPECT_LT(nearAxis(four.direction), 0.5) << "a = " << a;
  }
}

TEST(BruteForceSlicing, PaperSurfaces) {
  // Section 4 of the paper and the certified values of optimal_slicing (README): surface 1,
  // alpha* = 78.048 deg, N* = (0.248, -0.969, 0.001) printed, (0.2388, -0.9691, -0.0625)
  // computed; surface 2, 45.932 deg, N* = (0.975, -0.221, -0.002), or its mirror image under
  // the surface's symmetry x <-> y. Sampling misses the extreme normals by up to ~(1/128)^2,
  // so the sampled alpha is a little larger.
  const BruteForceSlicing one = bruteForceOptimalAlpha(exampleSurface("paper-1"));
  EXPECT_NEAR(degrees(one.alphaRad), 78.0475, 5e-4);
  EXPECT_LT(lineAngleDeg(one.direction, {0.2388, -0.9691, -0.0625}), 0.02);
  const BruteForceSlicing two = bruteForceOptimalAlpha(exampleSurface("paper-2"));
  EXPECT_NEAR(degrees(two.alphaRad), 45.932, 1e-3);
  EXPECT_LT(std::min(lineAngleDeg(two.direction, {0.975, -0.221, -0.002}),
                     lineAngleDeg(two.direction, {-0.221, 0.975, -0.002})),
            0.2);
}

TEST(BruteForceSlicing, RotatedSurfaceGivesTheSameAngleAndARotatedDirection) {
  // A rotation about the axis (1, 2, 2) / 3 by 50 degrees (Rodrigues), applied to paper-1's
  // control points: the normals turn with it, the screen's grid does not.
  const Vec3 axis = normalized(Vec3{1.0, 2.0, 2.0});
  const double c = std::cos(50.0 * kDegree);
  const double s = std::sin(50.0 * kDegree);
  auto rotate = [&](const Vec3& p) {
    return c * p + s * cross(axis, p) + (1.0 - c) * dot(axis, p) * axis;
  };
  const Surface original = exampleSurface("paper-1");
  Surface turned = original;
  for (Vec3& p : turned.patches[0].control) p = rotate(p);
  const BruteForceSlicing before = bruteForceOptimalAlpha(original);
  const BruteForceSlicing after = bruteForceOptimalAlpha(turned);
  EXPECT_NEAR(degrees(after.alphaRad), degrees(before.alphaRad), 1e-6);
  EXPECT_LT(lineAngleDeg(after.direction, rotate(before.direction)), 1e-3);
}

TEST(BruteForceSlicing, IsDeterministic) {
  const Surface lid = exampleSurface("teapot-lid");
  const BruteForceSlicing a = bruteForceOptimalAlpha(lid);
  const BruteForceSlicing b = bruteForceOptimalAlpha(lid);
  EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0);
}

TEST(BruteForceSlicing, ClosedTeapotLeavesNoDirection) {
  // The teapot is closed but for the seams of the handle and spout with the body: its normals
  // cover the sphere, alpha* = 0; the samples leave gaps under a degree.
  EXPECT_LT(degrees(bruteForceOptimalAlpha(exampleSurface("teapot")).alphaRad), 1.0);
}

}  // namespace
}  // namespace scallop
