#include "scallop/slicing/stereographic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {
namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// v / |v| without overflow or underflow in the squares: scale by the largest component
// first. The caller guarantees v != 0 and finite.
Vec3 unitOf(Vec3 v) {
  const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  const Vec3 scaled = v / largest;
  return scaled / norm(scaled);
}

// rho^2 - R^2 as a product, free of cancellation when rho and R are close.
double differenceOfSquares(double rho, double radius) { return (rho - radius) * (rho + radius); }

}  // namespace

// ---------------------------------------------------------------------------------------
// Points
// ---------------------------------------------------------------------------------------

Vec2 stereographic(const Vec3& n) {
  if (n.z > 0.0) {
    // Eq (5) with 1 - n_z = (n_x^2 + n_y^2) / (1 + n_z) (|n| = 1): no cancellation near the
    // pole, where 1 - n_z would keep only the last bits of n_z. Dividing by r twice rather
    // than by r^2 keeps r^2 from underflowing.
    const double r = std::hypot(n.x, n.y);
    if (r == 0.0) {
      throw Error(fmt::format(
          "stereographic: the north pole ({}, {}, {}) has no finite image (it projects to "
          "infinity)",
          n.x, n.y, n.z));
    }
    const double scale = (1.0 + n.z) / r;
    return {n.x / r * scale, n.y / r * scale};
  }
  // Southern hemisphere: 1 - n_z lies in [1, 2], eq (5) as written.
  const double denominator = 1.0 - n.z;
  return {n.x / denominator, n.y / denominator};
}

Vec3 inverseStereographic(const Vec2& p) {
  const double r = std::hypot(p.x, p.y);
  if (r <= 1.0) {
    // Eq (6) as written: no overflow, and x^2 + y^2 + 1 lies in [1, 2].
    const double s = p.x * p.x + p.y * p.y;
    const double denominator = s + 1.0;
    return {2.0 * p.x / denominator, 2.0 * p.y / denominator, (s - 1.0) / denominator};
  }
  // Outside the unit circle: q = p / |p|^2 lies inside, and n(p) is n(q) mirrored in the
  // equator (substitute p = q / |q|^2 into eq (6)). Divide by r twice: r^2 may overflow.
  const Vec2 q{p.x / r / r, p.y / r / r};
  const double s = q.x * q.x + q.y * q.y;
  const double denominator = s + 1.0;
  return {2.0 * q.x / denominator, 2.0 * q.y / denominator, (1.0 - s) / denominator};
}

Vec2 antipodalImage(const Vec2& p) {
  // Eq (7): p' = -n_xy / (1 + n_z) with n from eq (6) simplifies to -p / |p|^2.
  const double r = std::hypot(p.x, p.y);
  if (r == 0.0) {
    throw Error(
        "antipodalImage: p = (0, 0) is the south pole, whose antipode (the north pole) has no "
        "finite image");
  }
  return {-(p.x / r / r), -(p.y / r / r)};
}

// ---------------------------------------------------------------------------------------
// Circles
// ---------------------------------------------------------------------------------------

PlaneCircle projectCircle(const SphereCircle& circle) {
  const double alpha = circle.alphaRad;
  if (!(alpha >= 0.0 && alpha <= std::numbers::pi / 2.0)) {
    throw Error(fmt::format(
        "projectCircle: angular radius {} rad outside [0, pi/2] (use the centre's antipode "
        "and pi - alpha)",
        alpha));
  }
  const Vec3& c = circle.center;
  // Co-latitude of the centre (its angle from the north pole), accurate to an ulp for any c.
  const double rc = std::hypot(c.x, c.y);
  const double theta = std::atan2(rc, c.z);
  const double gap = theta - alpha;  // the pole's angular distance from the circle
  if (std::abs(gap) <= 4.0 * kEpsilon * std::max(theta, alpha)) {
    throw Error(fmt::format(
        "projectCircle: the circle (centre ({}, {}, {}), alpha {} rad) passes through the "
        "north pole; its image is a line, not a circle",
        c.x, c.y, c.z, alpha));
  }
  // Eqs (9), (10) share the denominator cos(alpha) - c_z = cos(alpha) - cos(theta)
  // = 2 sin((theta + alpha)/2) sin((theta - alpha)/2): a product, so it keeps full relative
  // accuracy when the circle is small and near the pole, where the difference would cancel.
  const double denominator = 2.0 * std::sin(0.5 * (theta + alpha)) * std::sin(0.5 * gap);
  return {{c.x / denominator, c.y / denominator}, std::sin(alpha) / std::abs(denominator)};
}

SphereCircle unprojectCircle(const PlaneCircle& circle) {
  const Vec2 x0 = circle.center;
  const double radius = circle.radius;
  if (!std::isfinite(x0.x) || !std::isfinite(x0.y) || !(radius >= 0.0) || !std::isfinite(radius)) {
    throw Error(fmt::format(
        "unprojectCircle: expected a finite centre and a finite radius >= 0, got centre "
        "({}, {}), radius {}",
        x0.x, x0.y, radius));
  }
  const double rho = std::hypot(x0.x, x0.y);
  // Substituting eq (6) into eq (8) and matching the coefficients with those of the plane
  // circle |p|^2 - 2 x0 . p + rho^2 - R^2 = 0 gives c proportional to
  // (2 x0, 2 y0, rho^2 - R^2 - 1) / (rho^2 - R^2 + 1) times cos(alpha), and
  // tan(alpha) = 2R / |rho^2 - R^2 + 1|: eqs (12), (14) for any direction of the centre.
  const double k = differenceOfSquares(rho, radius);
  const Vec3 direction = directionOfPlaneCircle(x0, radius);
  if (k + 1.0 < 0.0) {
    // The cap around `direction` is more than a hemisphere; describe the same circle by the
    // antipodal centre and the supplementary angle, atan2(2R, -(k + 1)) = pi - alpha.
    return {-direction, std::atan2(2.0 * radius, -(k + 1.0))};
  }
  return {direction, std::atan2(2.0 * radius, k + 1.0)};
}

double alphaOfPlaneCircleRad(double rho, double radius) {
  return std::atan2(2.0 * radius, differenceOfSquares(rho, radius) + 1.0);
}

double tanAlphaOfPlaneCircle(double rho, double radius) {
  return 2.0 * radius / (differenceOfSquares(rho, radius) + 1.0);
}

Vec3 directionOfPlaneCircle(Vec2 centre, double radius) {
  const double rho = std::hypot(centre.x, centre.y);
  // Eq (14). The vector is never 0: its length is also sqrt((rho^2 - R^2 + 1)^2 + 4 R^2).
  return unitOf({2.0 * centre.x, 2.0 * centre.y, differenceOfSquares(rho, radius) - 1.0});
}

// ---------------------------------------------------------------------------------------
// Rotations
// ---------------------------------------------------------------------------------------

Rotation3 rotationTaking(const Vec3& from, const Vec3& to) {
  const Vec3 k = cross(from, to);
  const double sine = norm(k);
  const double cosine = dot(from, to);
  const double length = std::hypot(sine, cosine);  // |from| |to|, 1 for unit vectors
  if (!(length > 0.0) || !std::isfinite(length)) {
    throw Error(
        fmt::format("rotationTaking: expected unit vectors, got ({}, {}, {}) and ({}, {}, {})",
                    from.x, from.y, from.z, to.x, to.y, to.z));
  }
  // The axis: from x to, re-orthogonalised against `from`. The cross product's rounding
  // (about eps in absolute terms) leaves a component along `from` that is negligible when
  // |from x to| is large but not when the vectors are nearly parallel or opposite; removing
  // it keeps a half turn about the axis taking `from` to -from exactly.
  Vec3 axis = k - dot(k, from) * from;
  double axisLength = norm(axis);
  if (!(axisLength > 1e-200)) {
    // from = +-to: no axis is defined by the pair. Any axis perpendicular to `from` works;
    // take it from the coordinate axis least aligned with `from`, for determinism.
    const double ax = std::abs(from.x);
    const double ay = std::abs(from.y);
    const double az = std::abs(from.z);
    const Vec3 e = (ax <= ay && ax <= az) ? Vec3{1.0, 0.0, 0.0}
                   : (ay <= az)           ? Vec3{0.0, 1.0, 0.0}
                                          : Vec3{0.0, 0.0, 1.0};
    axis = cross(from, e);
    axis = axis - dot(axis, from) / dot(from, from) * from;
    axisLength = norm(axis);
  }
  const Vec3 u = axis / axisLength;
  const double c = cosine / length;
  const double s = sine / length;
  const double t = 1.0 - c;
  // Rodrigues: R = c I + s [u]_x + (1 - c) u u^T.
  Rotation3 r;
  r.m[0][0] = c + t * u.x * u.x;
  r.m[0][1] = t * u.x * u.y - s * u.z;
  r.m[0][2] = t * u.x * u.z + s * u.y;
  r.m[1][0] = t * u.y * u.x + s * u.z;
  r.m[1][1] = c + t * u.y * u.y;
  r.m[1][2] = t * u.y * u.z - s * u.x;
  r.m[2][0] = t * u.z * u.x - s * u.y;
  r.m[2][1] = t * u.z * u.y + s * u.x;
  r.m[2][2] = c + t * u.z * u.z;
  return r;
}

Vec3 apply(const Rotation3& rotation, const Vec3& v) {
  const auto& m = rotation.m;
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
          m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Rotation3 transpose(const Rotation3& rotation) {
  Rotation3 result;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) result.m[i][j] = rotation.m[j][i];
  }
  return result;
}

}  // namespace scallop
