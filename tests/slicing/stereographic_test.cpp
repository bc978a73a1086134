// Tests for stereographic.hpp: point round trips, the antipode identity (eq 7), circles
// (eqs 9-14) checked against independent constructions (sampling points of a circle, the
// diametral points of eq 11), and the rotation helper.
//
// Tolerances. eps = 2^-52. Each library function is a handful of correctly rounded
// operations (+ - * / sqrt hypot: <= 1/2 ulp each; sin, cos, atan2: <= 1 ulp in glibc) on
// inputs that are themselves correct to a few ulps, so a result is correct to about
// 10 eps relative to its size when the problem is well conditioned; the tests allow 64 eps
// (a margin of 6) and, where the problem is ill-conditioned, multiply by its condition
// number, derived at each test.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "scallop/error.hpp"
#include "scallop/slicing/stereographic.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kTol = 64.0 * kEps;  // see the top of the file
constexpr double kPi = std::numbers::pi;

// A uniformly distributed unit vector (normalised Gaussian triple).
Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  while (true) {
    const Vec3 v{gauss(rng), gauss(rng), gauss(rng)};
    if (norm(v) > 1e-3) return normalized(v);
  }
}

// A unit vector near the north pole (or, with south = true, the south pole), at an angle
// from it that is log-uniform in [1e-12, 1e-1] radians.
Vec3 nearPole(std::mt19937_64& rng, bool south) {
  std::uniform_real_distribution<double> exponent(-12.0, -1.0);
  std::uniform_real_distribution<double> azimuth(0.0, 2.0 * kPi);
  const double angle = std::pow(10.0, exponent(rng));
  const double phi = azimuth(rng);
  const double z = std::cos(angle);
  return {std::sin(angle) * std::cos(phi), std::sin(angle) * std::sin(phi), south ? -z : z};
}

// Two unit vectors completing `c` to a right-handed orthonormal frame.
void frameAround(const Vec3& c, Vec3& e1, Vec3& e2) {
  const Vec3 helper = std::abs(c.x) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  e1 = normalized(cross(c, helper));
  e2 = cross(c, e1);
}

// The angle between two vectors, accurate for small and large angles alike.
double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(norm(cross(a, b)), dot(a, b));
}

double cot(double x) { return 1.0 / std::tan(x); }

// ---------------------------------------------------------------------------------------
// Points: eqs (5), (6)
// ---------------------------------------------------------------------------------------

TEST(Stereographic, KnownPoints) {
  EXPECT_EQ(stereographic({0.0, 0.0, -1.0}), (Vec2{0.0, 0.0}));  // south pole -> origin
  EXPECT_EQ(stereographic({1.0, 0.0, 0.0}), (Vec2{1.0, 0.0}));   // equator -> unit circle
  EXPECT_EQ(stereographic({0.0, -1.0, 0.0}), (Vec2{0.0, -1.0}));
  EXPECT_EQ(inverseStereographic({0.0, 0.0}), (Vec3{0.0, 0.0, -1.0}));
  EXPECT_EQ(inverseStereographic({0.0, 1.0}), (Vec3{0.0, 1.0, 0.0}));
  // (0.6, 0, 0.8) -> 0.6 / 0.2 = 3; n_z > 0, so via (1 + n_z) / r = 1.8 / 0.6.
  const Vec2 p = stereographic({0.6, 0.0, 0.8});
  EXPECT_NEAR(p.x, 3.0, 4.0 * kEps * 3.0);
  EXPECT_EQ(p.y, 0.0);
  const Vec3 n = inverseStereographic({3.0, 0.0});  // (6, 0, 8) / 10
  EXPECT_NEAR(n.x, 0.6, kTol);
  EXPECT_NEAR(n.z, 0.8, kTol);
}

TEST(Stereographic, NorthPoleHasNoImage) {
  EXPECT_THROW(stereographic({0.0, 0.0, 1.0}), Error);
  // Just off the pole the image is large but finite: |p| = cot(angle / 2) ~ 2 / angle.
  const Vec2 p = stereographic({1e-300, 0.0, 1.0});
  EXPECT_TRUE(std::isfinite(p.x));
  EXPECT_NEAR(p.x, 2e300, 2e300 * kTol);
  // The inverse of a huge point is the pole to rounding, never NaN.
  const Vec3 n = inverseStereographic({1e300, -1e300});
  EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
  EXPECT_EQ(n.z, 1.0);
  EXPECT_GT(n.x, 0.0);
  EXPECT_LT(n.y, 0.0);
}

// n -> p -> n. The round trip is the identity up to rounding: eq (5) in the chosen form is
// correct to a few ulps relative to |p|, and eq (6) maps a relative error delta of p to an
// error of at most delta in n (the projection is conformal with scale 2 / (1 + |p|^2), so
// |dn| = 2 |dp| / (1 + |p|^2) <= delta |p| * 2 / (1 + |p|^2) <= delta), plus its own few
// ulps; and the input is unit only to about eps. Hence |n' - n| <= 64 eps.
TEST(Stereographic, NormalRoundTrip) {
  std::mt19937_64 rng(42);
  std::vector<Vec3> normals;
  for (int i = 0; i < 5000; ++i) normals.push_back(randomUnit(rng));
  for (int i = 0; i < 1000; ++i) normals.push_back(nearPole(rng, false));
  for (int i = 0; i < 1000; ++i) normals.push_back(nearPole(rng, true));
  for (const Vec3& n : normals) {
    const Vec3 back = inverseStereographic(stereographic(n));
    EXPECT_LE(norm(back - n), kTol) << n.x << " " << n.y << " " << n.z;
    EXPECT_NEAR(norm(back), 1.0, 4.0 * kEps);
  }
}

// p -> n -> p, with |p| log-uniform over 16 decades. Relative error: eq (6) gives n_x, n_y
// to a few ulps relative to themselves (no cancellation in either branch) and n_z to a few
// ulps absolutely; eq (5) then uses n_x, n_y and (1 + n_z) or (1 - n_z), whichever lies in
// [1, 2], so it adds only a few ulps: |p' - p| <= 64 eps |p|.
TEST(Stereographic, PlanePointRoundTrip) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> exponent(-8.0, 8.0);
  std::uniform_real_distribution<double> azimuth(0.0, 2.0 * kPi);
  for (int i = 0; i < 10000; ++i) {
    const double r = std::pow(10.0, exponent(rng));
    const double phi = azimuth(rng);
    const Vec2 p{r * std::cos(phi), r * std::sin(phi)};
    const Vec2 back = stereographic(inverseStereographic(p));
    EXPECT_LE(norm(back - p), kTol * norm(p)) << p.x << " " << p.y;
  }
  EXPECT_EQ(stereographic(inverseStereographic({0.0, 0.0})), (Vec2{0.0, 0.0}));
}

// ---------------------------------------------------------------------------------------
// Antipodes: eq (7)
// ---------------------------------------------------------------------------------------

// antipodalImage(p) against stereographic(-n) computed directly, and the complex identity
// conj(p) p' = -1. Both sides are correct to a few ulps relative to |p'|, so 64 eps |p'|.
TEST(Stereographic, AntipodeIsInversionThroughTheOrigin) {
  std::mt19937_64 rng(42);
  std::vector<Vec3> normals;
  for (int i = 0; i < 5000; ++i) normals.push_back(randomUnit(rng));
  for (int i = 0; i < 500; ++i) normals.push_back(nearPole(rng, false));
  for (int i = 0; i < 500; ++i) normals.push_back(nearPole(rng, true));
  for (const Vec3& n : normals) {
    const Vec2 p = stereographic(n);
    const Vec2 image = antipodalImage(p);
    const Vec2 direct = stereographic(-n);
    EXPECT_LE(norm(image - direct), kTol * norm(direct)) << n.x << " " << n.y << " " << n.z;
    // conj(p) p' = (x x' + y y') + i (x y' - y x'); |p||p'| = 1, so errors are absolute.
    EXPECT_NEAR(dot(p, image), -1.0, kTol);
    EXPECT_NEAR(cross(p, image), 0.0, kTol);
  }
  EXPECT_THROW(antipodalImage({0.0, 0.0}), Error);
  EXPECT_EQ(antipodalImage({2.0, 0.0}), (Vec2{-0.5, -0.0}));
}

// ---------------------------------------------------------------------------------------
// Circles: eqs (8)-(14)
// ---------------------------------------------------------------------------------------

struct RandomCircle {
  SphereCircle circle;
  double gap = 0.0;  // |co-latitude of the centre - alpha|: the pole's distance from the circle
};

// A random sphere circle (uniform centre, uniform alpha in [0, pi/2]) whose angular distance
// `gap` from the north pole is at least 1e-3, so that its image stays of moderate size
// (eq 10's denominator is 2 sin((theta + alpha)/2) sin(gap/2)).
RandomCircle randomCircle(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  while (true) {
    RandomCircle result;
    result.circle.center = randomUnit(rng);
    result.circle.alphaRad = unit(rng) * kPi / 2.0;
    const Vec3& c = result.circle.center;
    result.gap = std::abs(std::atan2(std::hypot(c.x, c.y), c.z) - result.circle.alphaRad);
    if (result.gap >= 1e-3) return result;
  }
}

// Points on the sphere circle, projected one by one with eq (5), lie on projectCircle's
// circle. Error budget: a sampled point n = cos(a) c + sin(a) (cos(t) e1 + sin(t) e2) is on
// the circle to about 4 eps (angle); the projection magnifies angles by (1 + |p|^2) / 2, so
// the image is off by 4 eps (1 + |p|^2) / 2, plus eq (5)'s own relative error 4 eps |p|.
// The circle's centre and radius: eq (9), (10) with the product form of the denominator are
// correct to a few ulps given c and alpha, but c itself is unit only to eps, which moves the
// pole's distance `gap` by eps, i.e. the denominator by a relative eps / gap: an error of
// eps (|c_0| + R) / gap. Total with margin: 64 eps [(1 + |p|^2) + |p| + (|c_0| + R)(1 + 1/gap)].
TEST(Stereographic, ProjectedCirclePassesThroughProjectedPoints) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> azimuth(0.0, 2.0 * kPi);
  for (int i = 0; i < 3000; ++i) {
    const RandomCircle random = randomCircle(rng);
    const SphereCircle& circle = random.circle;
    const PlaneCircle image = projectCircle(circle);
    Vec3 e1;
    Vec3 e2;
    frameAround(circle.center, e1, e2);
    const double ca = std::cos(circle.alphaRad);
    const double sa = std::sin(circle.alphaRad);
    for (int k = 0; k < 8; ++k) {
      const double t = azimuth(rng);
      const Vec3 n = ca * circle.center + sa * (std::cos(t) * e1 + std::sin(t) * e2);
      const Vec2 p = stereographic(n);
      const double pp = norm(p);
      const double scale =
          (1.0 + pp * pp) + pp + (norm(image.center) + image.radius) * (1.0 + 1.0 / random.gap);
      EXPECT_NEAR(norm(p - image.center), image.radius, kTol * scale)
          << "circle " << i << " point " << k;
    }
  }
}

// Eq (11) run backwards: a sphere circle with centre at co-latitude theta and longitude phi
// has the diametral points at co-latitudes theta -+ alpha on the same meridian (signed, so
// that a negative co-latitude is across the pole), whose images are at signed distances
// x = cot(co-latitude / 2) along (cos phi, sin phi). So the image circle has centre
// (x_1 + x_2) / 2 and radius |x_2 - x_1| / 2. Here c is built from exact (theta, phi), so
// only the rounding of c (eps, magnified by 1/gap as above) and of cot (a few ulps of x_1,
// x_2, each of size <= |c_0| + R) enter: 64 eps (|c_0| + R)(1 + 1/gap).
TEST(Stereographic, ProjectedCircleMatchesDiametralPoints) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int i = 0; i < 5000; ++i) {
    const double theta = unit(rng) * kPi;
    const double phi = unit(rng) * 2.0 * kPi;
    const double alpha = unit(rng) * kPi / 2.0;
    const double gap = std::abs(theta - alpha);
    if (gap < 1e-6) continue;
    const Vec3 c{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
    const PlaneCircle image = projectCircle({c, alpha});
    const double x1 = cot(0.5 * (theta - alpha));
    const double x2 = cot(0.5 * (theta + alpha));
    const Vec2 direction{std::cos(phi), std::sin(phi)};
    const Vec2 expectedCentre = (0.5 * (x1 + x2)) * direction;
    const double expectedRadius = 0.5 * std::abs(x1 - x2);
    const double scale = (norm(expectedCentre) + expectedRadius + 1.0) * (1.0 + 1.0 / gap);
    EXPECT_LE(norm(image.center - expectedCentre), kTol * scale) << theta << " " << alpha;
    EXPECT_NEAR(image.radius, expectedRadius, kTol * scale) << theta << " " << alpha;
    ++checked;
  }
  EXPECT_GT(checked, 4900);
}

// Small circles close to the north pole, where cos(alpha) - c_z of eq (9) cancels entirely
// in double precision (both are 1 to rounding): the product form keeps full relative
// accuracy. Centre at co-latitude 2e-9, alpha = 1e-9: diametral points at 1e-9 and 3e-9,
// images at cot(0.5e-9) = 2e9 and cot(1.5e-9) = 6.67e8 (eq 11). Relative error of a few ulps.
TEST(Stereographic, SmallCircleNearThePoleKeepsRelativeAccuracy) {
  for (const double scale : {1e-3, 1e-6, 1e-9, 1e-12}) {
    const double theta = 2.0 * scale;
    const double alpha = scale;
    const Vec3 c{std::sin(theta), 0.0, std::cos(theta)};
    const PlaneCircle image = projectCircle({c, alpha});
    const double x1 = cot(0.5 * (theta - alpha));
    const double x2 = cot(0.5 * (theta + alpha));
    EXPECT_NEAR(image.center.x, 0.5 * (x1 + x2), kTol * (x1 + x2)) << scale;
    EXPECT_EQ(image.center.y, 0.0);
    EXPECT_NEAR(image.radius, 0.5 * (x1 - x2), kTol * (x1 + x2)) << scale;
    // And back: the inverse recovers the centre's direction and alpha to relative accuracy.
    const SphereCircle back = unprojectCircle(image);
    EXPECT_NEAR(back.alphaRad, alpha, kTol * alpha) << scale;
    EXPECT_NEAR(angleBetween(back.center, c), 0.0, kTol * theta) << scale;
  }
}

TEST(Stereographic, CircleThroughThePoleIsRejected) {
  // Co-latitude of the centre equals alpha: the pole is on the circle.
  EXPECT_THROW(projectCircle({{1.0, 0.0, 0.0}, kPi / 2.0}), Error);  // a meridian great circle
  EXPECT_THROW(projectCircle({{0.0, 0.0, 1.0}, 0.0}), Error);        // the pole as a point circle
  const double theta = 0.7;
  EXPECT_THROW(projectCircle({{std::sin(theta), 0.0, std::cos(theta)}, theta}), Error);
  EXPECT_THROW(projectCircle({{0.0, 0.0, 1.0}, -0.1}), Error);  // alpha outside [0, pi/2]
  EXPECT_THROW(projectCircle({{0.0, 0.0, 1.0}, 1.6}), Error);
  // The equator (centre at the south pole, alpha = pi/2) maps to the unit circle.
  const PlaneCircle equator = projectCircle({{0.0, 0.0, -1.0}, kPi / 2.0});
  EXPECT_NEAR(equator.radius, 1.0, kTol);
  EXPECT_NEAR(norm(equator.center), 0.0, kTol);
  // A point circle maps to the image of its centre with radius 0.
  const Vec3 c = normalized(Vec3{0.3, -0.4, 0.5});
  const PlaneCircle point = projectCircle({c, 0.0});
  EXPECT_EQ(point.radius, 0.0);
  EXPECT_LE(norm(point.center - stereographic(c)), kTol * norm(point.center));
}

// unprojectCircle(projectCircle(c)) == c. Condition: the plane circle carries the relative
// error eps / gap of the previous tests; unprojecting is well conditioned in angle (eq 12,
// 14 evaluated without cancellation except rho^2 - R^2 + 1 near alpha = pi/2, where atan2
// is flat), so the centre direction and alpha come back within 64 eps (1 + 1/gap) radians.
TEST(Stereographic, UnprojectInvertsProject) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 5000; ++i) {
    const RandomCircle random = randomCircle(rng);
    const SphereCircle& circle = random.circle;
    const SphereCircle back = unprojectCircle(projectCircle(circle));
    const double tolerance = kTol * (1.0 + 1.0 / random.gap);
    EXPECT_NEAR(back.alphaRad, circle.alphaRad, tolerance) << i;
    EXPECT_LE(back.alphaRad, kPi / 2.0);
    // Near alpha = pi/2 the pair (c, alpha) and (-c, pi - alpha) are nearly the same
    // description; the normalisation may pick either side within rounding.
    const double angle = angleBetween(back.center, circle.center);
    if (std::abs(circle.alphaRad - kPi / 2.0) > 1e-9) {
      EXPECT_LE(angle, tolerance) << i;
    } else {
      EXPECT_TRUE(angle <= tolerance || kPi - angle <= tolerance) << i;
    }
  }
}

// The other direction: a random plane circle (any centre, any radius, the origin inside or
// not) unprojects to a sphere circle that projects back onto it. When the disk is the image
// of a cap larger than a hemisphere (R^2 > rho^2 + 1) the inverse is normalised to the
// antipodal centre, pi - alpha: the same circle. Relative error in the plane: the round
// trip is as conditioned as the previous one with gap = the returned circle's distance
// from the pole; compare relative to rho + R, and skip gap < 1e-3.
TEST(Stereographic, ProjectInvertsUnproject) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> exponent(-3.0, 3.0);
  std::uniform_real_distribution<double> azimuth(0.0, 2.0 * kPi);
  int checked = 0;
  int largerThanHemisphere = 0;
  for (int i = 0; i < 5000; ++i) {
    const double rho = std::pow(10.0, exponent(rng));
    const double phi = azimuth(rng);
    const PlaneCircle circle{{rho * std::cos(phi), rho * std::sin(phi)},
                             std::pow(10.0, exponent(rng))};
    const SphereCircle sphere = unprojectCircle(circle);
    ASSERT_GE(sphere.alphaRad, 0.0);
    ASSERT_LE(sphere.alphaRad, kPi / 2.0);
    const Vec3& c = sphere.center;
    const double gap = std::abs(std::atan2(std::hypot(c.x, c.y), c.z) - sphere.alphaRad);
    if (gap < 1e-3) continue;
    largerThanHemisphere += circle.radius * circle.radius > rho * rho + 1.0 ? 1 : 0;
    const PlaneCircle back = projectCircle(sphere);
    const double tolerance = kTol * (rho + circle.radius) * (1.0 + 1.0 / gap);
    EXPECT_LE(norm(back.center - circle.center), tolerance) << i;
    EXPECT_NEAR(back.radius, circle.radius, tolerance) << i;
    ++checked;
  }
  EXPECT_GT(checked, 4500);
  EXPECT_GT(largerThanHemisphere, 500);
}

// Eq (12) and eq (14) against the definition of a sphere circle: points of the plane circle,
// lifted by eq (6), are at angle alpha from N. Each lifted point is correct to a few ulps
// (absolute, unit vectors), N likewise, and the angle is computed with atan2 of |N x n|
// and N . n, so |angle - alpha| <= 64 eps. tanAlphaOfPlaneCircle is tan(alpha) to a few ulps
// relative (compared where alpha is not within 1e-6 of pi/2, where tan blows up).
TEST(Stereographic, AlphaAndDirectionMatchTheSphereCircle) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> exponent(-3.0, 3.0);
  std::uniform_real_distribution<double> azimuth(0.0, 2.0 * kPi);
  for (int i = 0; i < 3000; ++i) {
    const double r = std::pow(10.0, exponent(rng));
    const double phi = azimuth(rng);
    const Vec2 centre{r * std::cos(phi), r * std::sin(phi)};
    // rho as the library computes it from the centre: the rounded centre is at distance
    // r (1 +- eps) from the origin, and alpha is sensitive to rho when the circle passes
    // near the origin (d alpha / d rho = -4 rho R / ((K + 1)^2 + 4 R^2), up to about 1).
    const double rho = std::hypot(centre.x, centre.y);
    const double radius = std::pow(10.0, exponent(rng));
    const Vec3 direction = directionOfPlaneCircle(centre, radius);
    const double alpha = alphaOfPlaneCircleRad(rho, radius);
    EXPECT_NEAR(norm(direction), 1.0, 4.0 * kEps);
    for (int k = 0; k < 8; ++k) {
      const double t = azimuth(rng);
      const Vec2 p = centre + radius * Vec2{std::cos(t), std::sin(t)};
      // p is rounded to eps |p| <= eps (rho + R); lifted, that moves n by
      // 2 eps (rho + R) / (1 + |p|^2), at most eps (rho + R) / |p|... bounded by the extra
      // term below for points near the origin of a large circle.
      const double pp = norm(p);
      const double lifted = 2.0 * (rho + radius) / (1.0 + pp * pp);
      EXPECT_NEAR(angleBetween(direction, inverseStereographic(p)), alpha, kTol * (1.0 + lifted))
          << i << " " << k;
    }
    if (std::abs(alpha - kPi / 2.0) > 1e-6) {
      const double expected = std::tan(alpha);
      // tan magnifies an error d(alpha) by (1 + tan^2): compare with that factor.
      EXPECT_NEAR(tanAlphaOfPlaneCircle(rho, radius), expected,
                  kTol * (std::abs(expected) + 1.0 + expected * expected))
          << i;
    }
  }
  // The planar image of a great circle (alpha = pi/2): rho^2 - R^2 + 1 = 0.
  EXPECT_EQ(alphaOfPlaneCircleRad(0.0, 1.0), kPi / 2.0);
  EXPECT_EQ(tanAlphaOfPlaneCircle(0.0, 1.0), std::numeric_limits<double>::infinity());
}

// Eq (12) derived through eq (11): for 0 < R < rho, theta_1 = 2 atan(1 / (rho - R)),
// theta_2 = 2 atan(1 / (rho + R)), alpha = (theta_1 - theta_2) / 2 and the centre's
// co-latitude theta = (theta_1 + theta_2) / 2 = atan2(2 rho, rho^2 - R^2 - 1). The halved
// difference loses up to eps * theta_1 <= eps * pi absolutely, so compare within 64 eps.
TEST(Stereographic, EquationTwelveAgreesWithEquationEleven) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> exponent(-3.0, 3.0);
  std::uniform_real_distribution<double> fraction(0.001, 0.999);
  for (int i = 0; i < 5000; ++i) {
    const double rho = std::pow(10.0, exponent(rng));
    const double radius = fraction(rng) * rho;
    const double theta1 = 2.0 * std::atan(1.0 / (rho - radius));
    const double theta2 = 2.0 * std::atan(1.0 / (rho + radius));
    const double alpha = 0.5 * (theta1 - theta2);
    const double theta = 0.5 * (theta1 + theta2);
    EXPECT_NEAR(alphaOfPlaneCircleRad(rho, radius), alpha, kTol) << rho << " " << radius;
    // eq (12)'s theta, as the paper writes it (atan2 puts it in (0, pi)).
    const double rr = (rho - radius) * (rho + radius);
    EXPECT_NEAR(std::atan2(2.0 * rho, rr - 1.0), theta, kTol) << rho << " " << radius;
    // ... and as the co-latitude of eq (14)'s N for a centre on the positive x axis.
    const Vec3 n = directionOfPlaneCircle({rho, 0.0}, radius);
    EXPECT_NEAR(std::atan2(std::hypot(n.x, n.y), n.z), theta, kTol) << rho << " " << radius;
    EXPECT_GT(n.x, 0.0);
    EXPECT_EQ(n.y, 0.0);
    // 0 < R < rho gives 0 < alpha < pi/2 (the paper's assumption).
    EXPECT_GT(alphaOfPlaneCircleRad(rho, radius), 0.0);
    EXPECT_LT(alphaOfPlaneCircleRad(rho, radius), kPi / 2.0);
  }
}

// A disk containing the origin's far side: R^2 > rho^2 + 1 means the cap around N is more
// than a hemisphere, and unprojectCircle reports the antipodal description. The disk
// |p| < 2 around the origin is the image of the cap around the south pole of angular radius
// atan2(4, -3) (n_z = 3/5 on its rim): as a circle, centre (0, 0, 1), alpha = atan2(4, 3).
TEST(Stereographic, LargeDiskIsNormalisedToTheAntipodalCap) {
  EXPECT_NEAR(alphaOfPlaneCircleRad(0.0, 2.0), std::atan2(4.0, -3.0), kTol);
  const Vec3 n = directionOfPlaneCircle({0.0, 0.0}, 2.0);
  EXPECT_EQ(n, (Vec3{0.0, 0.0, -1.0}));
  const SphereCircle circle = unprojectCircle({{0.0, 0.0}, 2.0});
  EXPECT_EQ(circle.center, (Vec3{-0.0, -0.0, 1.0}));
  EXPECT_NEAR(circle.alphaRad, std::atan2(4.0, 3.0), kTol);
  EXPECT_THROW(unprojectCircle({{0.0, 0.0}, -1.0}), Error);
  EXPECT_THROW(unprojectCircle({{std::nan(""), 0.0}, 1.0}), Error);
}

// ---------------------------------------------------------------------------------------
// Rotations
// ---------------------------------------------------------------------------------------

double determinant(const Rotation3& r) {
  const auto& m = r.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// R is built by Rodrigues' formula from an axis that is unit to a few ulps and from
// cos, sin that satisfy c^2 + s^2 = 1 to a few ulps; each entry is a sum of at most three
// products, so R^T R - I and det R - 1 are a few tens of ulps: 64 eps. R from = to within
// 64 eps (|from| = 1), and the transpose takes it back.
void expectProperRotation(const Vec3& from, const Vec3& to) {
  const Rotation3 r = rotationTaking(from, to);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double product = 0.0;
      for (int k = 0; k < 3; ++k) product += r.m[k][i] * r.m[k][j];
      EXPECT_NEAR(product, i == j ? 1.0 : 0.0, kTol) << i << j;
    }
  }
  EXPECT_NEAR(determinant(r), 1.0, kTol);
  EXPECT_LE(norm(apply(r, from) - to), kTol)
      << from.x << " " << from.y << " " << from.z << " -> " << to.x << " " << to.y << " " << to.z;
  EXPECT_LE(norm(apply(transpose(r), to) - from), kTol);
}

TEST(Stereographic, RotationTakingRandomPairs) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 5000; ++i) expectProperRotation(randomUnit(rng), randomUnit(rng));
}

TEST(Stereographic, RotationTakingAntipodalAndEqualPairs) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> exponent(-16.0, -2.0);
  const std::vector<Vec3> axes = {{1.0, 0.0, 0.0},  {0.0, 1.0, 0.0},  {0.0, 0.0, 1.0},
                                  {-1.0, 0.0, 0.0}, {0.0, -1.0, 0.0}, {0.0, 0.0, -1.0}};
  for (const Vec3& a : axes) {
    expectProperRotation(a, -a);
    expectProperRotation(a, a);
  }
  for (int i = 0; i < 3000; ++i) {
    const Vec3 from = randomUnit(rng);
    expectProperRotation(from, -from);  // exactly opposite
    expectProperRotation(from, from);   // equal: the identity
    // Nearly opposite and nearly equal, perpendicular offsets from 1e-16 to 1e-2.
    Vec3 e1;
    Vec3 e2;
    frameAround(from, e1, e2);
    const double offset = std::pow(10.0, exponent(rng));
    expectProperRotation(from, normalized(-from + offset * e1));
    expectProperRotation(from, normalized(from + offset * e2));
  }
  // The identity is exact for equal vectors.
  const Rotation3 identity = rotationTaking({0.0, 0.0, 1.0}, {0.0, 0.0, 1.0});
  EXPECT_EQ(apply(identity, Vec3{0.3, -0.2, 0.7}), (Vec3{0.3, -0.2, 0.7}));
  EXPECT_THROW(rotationTaking({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}), Error);
}

// The pipeline's use: rotate the sphere so that a chosen normal becomes the north pole; the
// rotation preserves angles, so circles stay circles with the same alpha.
TEST(Stereographic, RotatingAChosenNormalToTheNorthPole) {
  std::mt19937_64 rng(42);
  const Vec3 north{0.0, 0.0, 1.0};
  for (int i = 0; i < 1000; ++i) {
    const Vec3 chosen = randomUnit(rng);
    const Rotation3 r = rotationTaking(chosen, north);
    EXPECT_LE(norm(apply(r, chosen) - north), kTol);
    const Vec3 other = randomUnit(rng);
    EXPECT_NEAR(angleBetween(apply(r, other), north), angleBetween(other, chosen), kTol);
  }
}

}  // namespace
}  // namespace scallop
