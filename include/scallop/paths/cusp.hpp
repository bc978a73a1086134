#pragma once
// Scallop (cusp) height between neighbouring passes on a curved surface, and plane offsets
// chosen one after another so that it stays below a given H (adaptive spacing).
//
// Smith, Farouki, al-Kandari, Pottmann, "Optimal slicing of free-form surfaces" (CAGD 19,
// 2002), Section 4, space the planes by the flat-surface formula: neighbouring contact
// curves l = Delta / sin(angle(N, n)) apart leave a cusp h = R - sqrt(R^2 - l^2 / 4), so
// Delta = 2 sqrt(2 R H - H^2) sin(alpha) (contour.hpp's spacingForScallopHeight). On a
// convex part the cusp is higher (about (1 + R / rho) times), on a concave one lower.
//
// Contract
// --------
// Input:  a valid surface (surface.hpp) cut from above; a unit plane normal N (contour: any;
//         raster: the horizontal e of the vertical planes e . r = w); a ball radius R > 0;
//         for the adaptive offsets a scallop height 0 < H < R.
// Model (per contact point p of plane w, unit upward normal n, the ball's centre at
//         p + R n as contour.hpp places it):
//         t = (N - (N . n) n) / |...| is the surface direction across the passes (t is
//         perpendicular to the contact curve, whose tangent is N x n, and N . t =
//         sin(angle(N, n)) =: a > 0); b = N . n; kappa = -II(t, t) / I(t, t) the normal
//         curvature along t, positive where the surface bends away from the ball (convex),
//         negative where it bends towards it (concave). In the normal section (t, n) the
//         surface is the osculating circle of radius rho = 1 / kappa:
//             p(l) = p + S(l) t - C(l) n,  S = sin(kappa l) / kappa,  C = (1 - cos(kappa l)) / kappa.
//         Contact distance: the neighbouring plane w + Delta meets that circle at the
//         smallest l > 0 with N . (p(l) - p) = a S(l) - b C(l) = Delta (a safeguarded
//         Newton solve; as kappa -> 0, l = Delta / a, the paper's l = Delta / sin). If the
//         circle's extreme point in direction N (at l_top, where a cos(kappa l) =
//         b sin(kappa l)) stays below the plane, the plane passes over a cap: the cusp is
//         then the one across the cap, between the contact and its mirror image on the far
//         side, l = 2 l_top.
//         Cusp: the two balls' centres lie on the circle of radius rho + R about the centre
//         of curvature O (convex; |rho| - R for concave, on the same side as the ball), an
//         angle theta = kappa l apart. Their spheres (radius R) meet in the normal section
//         on the bisector at distance (rho + R) cos(theta / 2) - sqrt(R^2 - (rho + R)^2
//         sin^2(theta / 2)) from O (the intersection nearer O, i.e. toward the material;
//         with signed rho the same expression covers the concave case), so the cusp's
//         height above the surface, along the surface normal at the section's midpoint, is
//             h(l, R, kappa) = (rho + R) cos(theta / 2) - rho
//                              - sqrt(R^2 - (rho + R)^2 sin^2(theta / 2)),
//         written without 1 / kappa (cuspHeight):
//             h = -2 R sin^2(x / 4) - l (2 sin^2(x / 4) / x) + m^2 / (R + sqrt(R^2 - m^2)),
//             x = kappa l,  m = (1 + R kappa) (l / 2) sinc(x / 2).
//         As kappa -> 0, m -> l / 2 and h -> R - sqrt(R^2 - l^2 / 4): the paper's formula.
//         h is +infinity when m > R (the balls do not meet: a strip is left uncut). Where
//         1 + R kappa <= 0 the concave radius is at most R: the ball cannot follow the
//         surface (the drop envelope lifts it there), no cusp is defined and the sample is
//         counted in `tooTight`, not in the distribution.
//         Both directions are evaluated for each neighbouring pair (w_k, w_{k+1}): from the
//         contacts of plane k toward +Delta and from those of plane k+1 toward -Delta (N
//         flipped: b -> -b); the pair's worst cusp is the larger.
// What is an estimate: the surface is replaced by its osculating circle across the passes
//         (exact on spheres and cylinders cut along their axis; second order elsewhere, and
//         the curvature varies over l); the contacts are the section curves' vertices
//         (subsampled); raster passes are placed by the scallop hull in their plane and
//         lifted in 3D by the drop envelope (envelope.hpp), so their balls do not sit
//         exactly at p + R n, and the final raster cusp differs from this in-plane model;
//         contour passes lifted by the drop envelope (concave radius < R, creases) likewise;
//         a pass is a chord between exact offset points, and where the surface is concave
//         along the pass the chord lies above the true offset curve, adding up to the
//         chordal tolerance (the CLI traces sections to H / 20 for this); at an edge oblique
//         to the passes the material between two passes' ends is higher than their cusp
//         (an end effect the model does not see).
//         The tests judge the contour cusp independently by the lower envelope of the swept
//         balls over dense surface samples.
// Adaptive offsets (adaptivePlaneOffsets): the surface's extent [s_lo, s_hi] of N . r is
//         sampled (a grid per patch); w_0 = s_lo + firstStep / 2 (firstStep: the paper's
//         flat spacing with the sampled least sin(angle(N, n)), at least the floor). Then
//         w_{k+1} = w_k + Delta_k, Delta_k the largest step in [floor, ceiling] whose
//         pair's worst cusp is <= H: ceiling = maxStepFactor * l_H (l_H = 2 sqrt(2RH -
//         H^2), the flat step-over), accepted at once if it passes; otherwise bisection
//         with `bisectionSteps` sections. floor = floorFraction * l_H: where even the floor
//         fails (near tangency: a tends to 0 and l = Delta / a grows without bound; at a
//         touch point; where the balls cannot meet), the step is the floor and `floorSteps`
//         counts it, so the offsets never stall. Stops when w_{k+1} > s_hi; then, if s_hi - w_k >
//         firstStep / 2, one more plane at w_k + max(s_hi - w_k - firstStep / 2, min(floor,
//         s_hi - w_k)), so the last plane lies as near s_hi as the first lies to s_lo. A part of the
//         surface that lies between two planes and that neither plane's section reaches is
//         not seen by the estimate (as with a constant spacing).
// Centre planes (CuspOptions::centrePlanes, raster): a raster ball's centre c lies in its
//         plane, and it touches the surface at p = c - R n, off the plane by R (N . n) where
//         the surface slopes across it; the contacts of plane w are the points with
//         W(p) = N . (p + R n(p)) = w, not the section. Along the cross direction the centre
//         moves on the offset circle (radius rho + R): W(l) - W(0) = (1 + R kappa)
//         (a S(l) - b C(l)), so the neighbour's contact lies contactDistance(delta /
//         (1 + R kappa)) away, and the cusp is cuspHeight of that l. The surface is sampled
//         on a grid per patch (about two samples per flat step-over across its control box,
//         16 to 128 per side), each sample with its W; a pair (w, w + delta) is judged by the
//         worst cusp, both directions, of the samples with W in [w, w + delta] (each taken as
//         if it were the contact: the strip's worst local geometry). The extent is that of
//         W over the samples, so the outermost planes lie beyond the surface's own extent
//         where it slopes across them (raster drops balls from such planes onto the surface,
//         raster.hpp). cuspStatistics judges its pairs the same way (sections unused).
// Tolerance: cuspHeight is exact up to rounding (relative ~1e-15 of R, no cancellation of
//         R - sqrt); the contact distance to 1e-14 relative; the adaptive step is within
//         (ceiling - floor) / 2^bisectionSteps of the largest accepted one (bisection does
//         not require the worst cusp to grow with Delta; it returns a step that passed).
// Complexity: cuspStatistics: O(samples) contact evaluations (second derivatives) plus
//         a few Newton steps each. adaptivePlaneOffsets: per plane at most bisectionSteps + 2
//         planeSections and as many passes over <= samplesPerPlane contacts; throws
//         scallop::Error beyond kMaxPlanes planes.

#include <cstddef>
#include <vector>

#include "scallop/paths/section.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// h(l, R, kappa) of the contract: the cusp between balls of radius R whose contacts lie a
/// surface distance l >= 0 apart on a normal section of curvature kappa (convex > 0,
/// concave < 0). +infinity when the balls do not meet; requires 1 + R kappa > 0 and
/// |kappa l| <= 2 pi (throws scallop::Error otherwise, or for R <= 0, l < 0, non-finite input).
double cuspHeight(double l, double toolRadius, double kappa);

/// The cusp between balls of radius R on neighbouring passes `spacing` apart on a flat surface:
/// the scallop height a plan given --spacing is simulated against. Refused from 2 R up, where
/// the balls do not meet and nothing bounds what is left between passes.
double flatCusp(double radius, double spacing);

/// The contact geometry of the model at one point: a = N . t = sin(angle(N, n)) >= 0,
/// b = N . n, kappa along t.
struct CrossGeometry {
  double a = 0.0;
  double b = 0.0;
  double kappa = 0.0;
};

/// The geometry at a section point, n the upward normal (contour.hpp's upwardNormal).
CrossGeometry crossGeometry(const Surface& surface, const SectionPoint& point,
                            const Vec3& unitNormal);

/// The surface distance l to the neighbouring plane `delta` > 0 away along t on the
/// osculating circle (the contract): the smallest l > 0 with a S(l) - b C(l) = delta, or
/// 2 l_top when the plane passes over the cap (`overCap` set). +infinity when a = 0 and
/// kappa = 0 (the plane is parallel to the surface).
double contactDistance(double delta, const CrossGeometry& g, bool* overCap = nullptr);

/// The cusp heights over every neighbouring pair of a list of planes (consecutive entries).
struct PlaneContacts {
  double offset = 0.0;                   ///< w: the plane N . r = w
  const PlaneSection* section = nullptr; ///< its section (contact curves)
};

struct CuspStatistics {
  double max = 0.0;         ///< the largest finite or infinite cusp sampled
  double p99 = 0.0;         ///< 99th percentile (nearest rank)
  double mean = 0.0;        ///< mean over finite samples
  std::size_t samples = 0;  ///< cusp samples in the distribution
  std::size_t pairs = 0;    ///< neighbouring pairs of planes
  std::size_t tooTight = 0; ///< samples with concave radius <= R (no cusp defined)
  std::size_t overCap = 0;  ///< samples whose neighbouring plane passes over a cap
};

struct CuspOptions {
  double toolRadius = 0.0;        ///< R > 0
  double scallopHeight = 0.0;     ///< H, 0 < H < R (adaptive offsets only)
  double chordalTolerance = 0.0;  ///< sections; 0 means 1e-4 surfaceScale (as contour/raster)
  std::size_t samplesPerPlane = 2000;  ///< contacts per plane (section vertices, strided)
  int bisectionSteps = 14;        ///< sections per step at most (plus two)
  double floorFraction = 0.02;    ///< floor = floorFraction * l_H
  double maxStepFactor = 4.0;     ///< ceiling = maxStepFactor * l_H
  /// The planes hold the balls' centres, not their contacts (raster: the scallop hull and the
  /// drop envelope place the centre in the plane; see "Centre planes" in the contract).
  bool centrePlanes = false;
};

/// Cusp heights between consecutive planes of `planes` (increasing offsets), sampled at
/// every contact (strided to samplesPerPlane per plane) in both directions.
CuspStatistics cuspStatistics(const Surface& surface, const Vec3& unitNormal,
                              const std::vector<PlaneContacts>& planes,
                              const CuspOptions& options);

struct AdaptiveOffsets {
  std::vector<double> offsets;   ///< increasing; planes N . r = offsets[k]
  std::vector<double> worstCusp; ///< per step k -> k + 1 (offsets.size() - 1 entries)
  double extentLo = 0.0;         ///< sampled extent of N . r over the surface
  double extentHi = 0.0;
  double flatStepOver = 0.0;     ///< l_H = 2 sqrt(2 R H - H^2)
  double floor = 0.0;            ///< the smallest step allowed
  std::size_t floorSteps = 0;    ///< steps that fell to the floor
  std::size_t sections = 0;      ///< planeSections computed
};

/// Offsets w_0 < w_1 < ... chosen so that every neighbouring pair's estimated worst cusp
/// stays <= H (see the contract). Throws scallop::Error on bad options or beyond kMaxPlanes.
AdaptiveOffsets adaptivePlaneOffsets(const Surface& surface, const Vec3& unitNormal,
                                     const CuspOptions& options);

/// Sampled extent [lo, hi] of N . r over the surface (a 33 x 33 grid per patch).
std::pair<double, double> sampledExtent(const Surface& surface, const Vec3& unitNormal);

}  // namespace scallop
