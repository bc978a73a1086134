#pragma once
// Stereographic projection of the unit sphere onto the plane, and what it does to circles
// (Smith, Farouki, al-Kandari, Pottmann, "Optimal slicing of free-form surfaces", Section
// 3.2, eqs (5)-(14)); and the rotations that bring a chosen direction to the north pole
// before projecting.
//
// Contract
// --------
// Sphere: the unit sphere S centred at the origin; points of S are unit vectors n
//         (dimensionless). The projection is from the north pole (0, 0, 1) onto the plane
//         z = 0: the equator maps to the unit circle, the southern hemisphere to its inside
//         (the south pole to the origin), the northern hemisphere to its outside, and the
//         north pole to the point at infinity.
// Inputs: unit vectors are unit to rounding (|n| = 1 within a few ulps): the formulas use
//         |n| = 1 to avoid cancellation, so a vector far from unit length gives a wrong
//         answer, not an error. Plane points may be any finite size; plane circles need
//         centre and radius below about 1e150 (rho^2 - R^2 must not overflow).
// Circles: a circle on S is {n : c . n = cos(alpha)} (eq 8) with a unit centre c and an
//         angular radius alpha in [0, pi/2] (alpha = 0: a point, alpha = pi/2: a great
//         circle); (c, alpha) and (-c, pi - alpha) are the same circle, hence the range.
//         A circle through the north pole maps to a line, not a circle: projectCircle throws.
// Accuracy: every function is evaluated in a form free of avoidable cancellation (noted at
//         each), so results are correct to a few ulps relative to the size of the result,
//         except where the problem itself is ill-conditioned (a circle passing within
//         rounding of the north pole). Cost: O(1) each.
// Angles: radians throughout (names end in Rad where a number is an angle).

#include "scallop/geometry/vector.hpp"

namespace scallop {

// ---------------------------------------------------------------------------------------
// Points
// ---------------------------------------------------------------------------------------

/// Eq (5): the image p = (n_x, n_y) / (1 - n_z) of the unit vector n. Evaluated as
/// (n_x, n_y) (1 + n_z) / (n_x^2 + n_y^2) on the northern hemisphere (n_z > 0), where
/// 1 - n_z would cancel; equal for unit n.
/// At the north pole itself (n_x = n_y = 0, n_z > 0) the image is the point at infinity:
/// throws scallop::Error. Within about 1e-308 of the pole (n_x, n_y subnormal) the
/// components may overflow to +-infinity.
Vec2 stereographic(const Vec3& unitNormal);

/// Eq (6): the unit vector n whose image is p:
///   n = (2x, 2y, x^2 + y^2 - 1) / (x^2 + y^2 + 1).
/// For |p| > 1 it is evaluated through q = p / |p|^2 (then n(p) is n(q) mirrored in the
/// equator), so that large |p| neither overflows nor loses n_x, n_y. Never throws for finite p.
Vec3 inverseStereographic(const Vec2& p);

/// Eq (7): the image p' of the antipode -n, given the image p of n: conj(p) p' = -1 in complex
/// notation, i.e. p' = -p / |p|^2 (inversion in the unit circle and reflection through the
/// origin). p = 0 (the south pole) has the north pole as antipode, whose image is at
/// infinity: throws scallop::Error.
Vec2 antipodalImage(const Vec2& p);

// ---------------------------------------------------------------------------------------
// Circles
// ---------------------------------------------------------------------------------------

/// A circle on the unit sphere: {n : center . n = cos(alphaRad)} (eq 8).
/// Invariant: |center| = 1, 0 <= alphaRad <= pi/2.
struct SphereCircle {
  Vec3 center{0.0, 0.0, -1.0};
  double alphaRad = 0.0;  ///< angular radius, radians
};

/// A circle in the plane of projection. Invariant: radius >= 0, finite.
struct PlaneCircle {
  Vec2 center;
  double radius = 0.0;
};

/// Eqs (9), (10): the image of a circle on the sphere,
///   centre c_0 = (c_x, c_y) / (cos(alpha) - c_z),   R = |sin(alpha) / (cos(alpha) - c_z)|.
/// The denominator is evaluated as 2 sin((theta + alpha)/2) sin((theta - alpha)/2), with
/// theta = atan2(|(c_x, c_y)|, c_z) the co-latitude of c, which is exact to rounding even
/// for small circles near the pole. It vanishes when the circle passes through the north
/// pole (theta = alpha); throws scallop::Error when |theta - alpha| <= 4 ulps of
/// max(theta, alpha), i.e. when the pole lies on the circle within the rounding of its data.
/// Which side maps to the disk: if theta > alpha (the cap {c . n >= cos(alpha)} does not
/// contain the north pole) the cap maps onto the disk; otherwise onto the disk's outside.
/// For alpha = 0 the result is the point stereographic(c) with radius 0.
PlaneCircle projectCircle(const SphereCircle& circle);

/// The general inverse of projectCircle: the circle on the sphere whose image is `circle`,
/// whatever the direction of its centre (eqs (11), (12), (14), rotated about z):
///   N = (2 x_0, 2 y_0, rho^2 - R^2 - 1) / sqrt(4 rho^2 + (rho^2 - R^2 - 1)^2),
///   alpha = atan2(2R, rho^2 - R^2 + 1)  in [0, pi),
/// where the disk's inside is the image of the cap of angular radius alpha around N. When
/// R^2 > rho^2 + 1 (that cap is more than a hemisphere, alpha > pi/2) the result is
/// normalised to (-N, pi - alpha) so that alphaRad <= pi/2; the disk is then the image of
/// the complement of the returned cap. rho^2 - R^2 is evaluated as
/// (rho - R)(rho + R). Never throws for a finite circle.
SphereCircle unprojectCircle(const PlaneCircle& circle);

/// Eq (12): the angular radius of the cap (around directionOfPlaneCircle) whose image is the
/// disk of radius `radius` with centre at distance `rho` from the origin:
///   alpha = atan2(2R, rho^2 - R^2 + 1), in [0, pi) (> pi/2 when R^2 > rho^2 + 1).
/// This is the quantity the optimal slicing orientation maximises (Section 3.4).
double alphaOfPlaneCircleRad(double rho, double radius);

/// tan(alpha) = 2R / (rho^2 - R^2 + 1) (Section 3.4, the function whose stationary points
/// along medial-axis edges are the roots of eq (13)). Monotone in alpha on [0, pi/2);
/// +infinity at alpha = pi/2 (denominator 0), negative beyond.
double tanAlphaOfPlaneCircle(double rho, double radius);

/// Eq (14): the unit centre N of the cap whose image is the disk (centre, radius):
///   N = (2x, 2y, rho^2 - R^2 - 1) / sqrt(4 rho^2 + (rho^2 - R^2 - 1)^2).
/// The denominator equals sqrt((rho^2 - R^2 + 1)^2 + 4R^2) too, so it never vanishes (at
/// rho = 0 it is R^2 + 1): this never throws. The cap's angular radius is
/// alphaOfPlaneCircleRad(rho, R).
Vec3 directionOfPlaneCircle(Vec2 centre, double radius);

// ---------------------------------------------------------------------------------------
// Rotations
// ---------------------------------------------------------------------------------------

/// A rotation of space as a 3x3 matrix acting on column vectors: apply(R, v) = R v.
/// Invariant: orthonormal with determinant +1 (to rounding).
struct Rotation3 {
  double m[3][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
};

/// The rotation taking the unit vector `from` to the unit vector `to`: the smallest one,
/// about the axis from x to, by the angle atan2(|from x to|, from . to). Robust when the two
/// are (nearly) opposite: the axis is re-orthogonalised against `from`, and when from = -to
/// exactly (no axis defined) the half turn is about an axis perpendicular to `from` chosen
/// from the coordinate axis least aligned with it. Deterministic.
Rotation3 rotationTaking(const Vec3& from, const Vec3& to);

/// R v.
Vec3 apply(const Rotation3& rotation, const Vec3& v);

/// The transpose, which is the inverse rotation.
Rotation3 transpose(const Rotation3& rotation);

}  // namespace scallop
