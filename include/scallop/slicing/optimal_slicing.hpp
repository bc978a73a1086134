#pragma once
// The optimal slicing orientation of a free-form surface (Smith, Farouki, al-Kandari,
// Pottmann, "Optimal slicing of free-form surfaces", CAGD 2002, Sections 3.2-3.4).
//
// Contract
// --------
// Input:  a surface of regular Bezier patches (surface.hpp) and an angular tolerance for the
//         Gauss map's polygonal boundary (radians).
// Output: the unit normal N* of parallel slicing planes N . r = k Delta that maximises, over
//         the whole surface, the minimum angle alpha between N and +-n (n the surface
//         normal), with alpha* itself; the maximal circle that realises it, in the
//         stereographic plane of the Gauss map's pole frame and on the sphere; and a
//         certificate: a Bernstein-form proof, patch by patch, that no surface normal lies
//         within alpha* - margin of +-N* (margin = 1e-7 rad, which keeps the subdivision
//         shallow; alpha* itself is exact to rounding, see Accuracy).
// Method: symmetrized Gauss map Omega (gauss_map.hpp) -> stereographic projection with a
//         surface normal as the pole (eqs 5-7) -> medial axis of the projected complement
//         of Omega (medial_axis.hpp; the map's loops first cleaned of zero-width zigzags,
//         see below; coarse to fine above 3,000 segments, see below) -> along every edge,
//         tan(alpha) = 2R / (rho^2 - R^2 + 1) (eq 12) at the edge's ends and at the roots
//         in (0, 1) of eq (13), built in Bernstein form with R^2 for R (degree 4 for linear
//         edges, 8 for parabolic ones) -> the best circle gives N* by eq (14), rotated back
//         from the pole frame -> the polish: from that circle and up to three rivals within
//         4 tolerances of it (more than a degree apart) (and, with latticeSeeds, from the
//         four best of a lattice of 2,000 directions; the medial axis's seeds win ties), the
//         minimax problem min_N max |n . N| is solved on the true surface by a trust-region
//         SQP method: the contacts (local maxima of |n . N| over each patch, interior, on
//         an edge or at a corner) by Newton's method from warm starts and a fixed 33 x 33
//         grid per patch; the step from a QP in 3 unknowns (the tangent step and the level
//         t) over the linearised contacts with the Lagrangian's curvature, solved exactly
//         by enumerating active sets; quadratic convergence where the optimum is a vertex
//         of three contacts or an edge of two (the derivation is in the source). The best
//         polished direction is N*.
// Coarse to fine (bestCircles): the loops F are simplified by Douglas-Peucker at a planar
//         delta (keeping ~10 sqrt(n) of their own vertices), and the search runs on a mixed
//         domain M, whose simplified segments near the near-optimal circles are replaced by
//         their fine chains, until M's answer is proven to be F's. M and F differ only within
//         delta of M's unrefined segments, and moving a circle's boundary by delta changes its
//         alpha by at most 2 delta (the projection's conformal factor 2 / (1 + |p|^2) <= 2);
//         so when every point of M's medial axis whose alpha is within 3 delta (plus the
//         rivals' window) of M's best lies farther than R + 2 delta from every unrefined
//         segment (dist - R is 2-Lipschitz along the edges), F's best circle and rivals touch
//         only refined, shared boundary and are M's. Otherwise the failing segments are
//         refined and M rebuilt (<= 10 rounds; delta halved where simplified loops cross; the
//         full domain as the last resort). The circles are F's to rounding, bit for bit in
//         practice (M's vertices are F's, on the same integer grid), to the medial axis's
//         tolerance when Boost's diagram of one of them needs a rotated rebuild.
// Accuracy: the circle is exact for the polygonal Omega, which lies within the tolerance of
//         the true boundary; N* and alpha* are then those of a local optimum of the true
//         problem, to rounding (|n . N*| to ~1e-16; N* to ~1e-8 where the optimum is an edge
//         of two contacts, along which max |n . N| grows only quadratically). The tolerance
//         only chooses the basin; alpha* is non-decreasing and N* constant once it is fine
//         enough (the paper's surfaces: from 1 degree on). The certificate states what is
//         proven.
// Zigzags: the Gauss map's polygon union can return a loop that runs back and forth over a
//         few grid steps, and sliver holes (seen at fine tolerances with the earlier
//         cell-union Gauss map); the medial axis rejects those, so vertices where a loop
//         turns back within a triangle thinner than 1% of the tolerance are removed, and
//         loops of negligible area dropped, before it (the boundary moves by less than that).
// Cost:   the paper's bicubic surfaces at 0.5 degree: ~13-14 ms of CPU on either, of which
//         the Gauss map 2.7 / 3.7 ms and the medial axis 5 / 4 ms. At ~100,000 boundary
//         segments (4e-7 degree on both): 0.8-1.0 s on either (a loaded machine), of which
//         the Gauss map 0.3-0.4 s and the medial-axis search ~0.55 s coarse to fine (one
//         refinement round; ~3,500 coarse segments, ~8,000 / ~7,200 searched; 92% of the
//         axis's edges rated by their bound alone), where the full-resolution medial axis
//         takes 4-5 s (Boost's Voronoi falls back to its multiprecision predicates on the
//         finely sampled, nearly collinear boundary).
// No complement: when the Gauss map's complement is empty within its tolerance, "no
//         direction exists" is said only with a proof (normal_coverage.hpp: the normals cover
//         the sphere; method "covered", alpha* = 0). Without one, the polish runs from the
//         lattice's seeds and the certificate proves what it can (method "lattice"), unless
//         OptimalSlicingOptions::noComplement says otherwise (method "open": alpha 0, nothing
//         searched; for a superset of normals, as a trimmed face's pieces, where nothing better
//         than 0 could be said of the face, and the search over thousands of pieces is long).
// Degenerate surfaces: a plane (Omega two points) gives alpha* = 90 degrees with N* any
//         direction orthogonal to the normal (one is returned, `method` "plane"); a surface
//         whose normals the Gauss map takes for a point (within the tolerance, or too close
//         for its grid) gets that direction polished against its true normals, alpha* just
//         under 90 degrees (a bilinear patch 10 km square twisted by 1 mm: 89.9999971
//         degrees), and the certificate as usual; for a surface whose Gauss
//         image is a curve (K = 0) the result is found by maximising the minimum angle over
//         the curve's sampled normals directly (flagged by `method`).

#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include "scallop/slicing/gauss_map.hpp"
#include "scallop/slicing/medial_axis.hpp"
#include "scallop/slicing/normal_coverage.hpp"
#include "scallop/slicing/stereographic.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

struct OptimalSlicingOptions {
  /// Gauss-map polygon tolerance, in (0, 0.1) rad. 0.5 degree gives 120-160 boundary
  /// segments on the paper's surfaces (the paper used a few hundred); N* is polished on the
  /// true surface afterwards, so a finer tolerance changes it only when it moves the medial
  /// axis to another basin. ~4e-7 degree gives ~100,000 segments on either surface.
  double toleranceRad = 0.5 * std::numbers::pi / 180.0;
  bool certify = true;  ///< run the Bernstein-form certificate
  /// false (the default): the polish starts from the medial axis's circles alone, the
  /// paper's method. true: also from the four best directions of a fixed lattice of 2,000
  /// (rated on sampled normals), a safety net against a Gauss map that loses normals; the
  /// tests show it changes no answer on their surfaces (the teapot's included).
  bool latticeSeeds = false;
  /// true: the medial-axis search runs coarse-to-fine on large domains (bestCircles; the
  /// same circle, much faster); false: always on the full-resolution domain (for
  /// comparison and tests).
  bool coarseToFine = true;
  /// What to do when the Gauss map leaves no direction free within its tolerance:
  enum class NoComplement {
    proveThenSearch,  ///< prove the normals cover the sphere ("covered"), else polish the lattice's seeds ("lattice")
    prove,            ///< the proof alone; without it, method "open" (alpha 0, nothing searched)
    stop,             ///< neither: method "open" at once (alpha >= 0 is all that is said)
  };
  NoComplement noComplement = NoComplement::proveThenSearch;
};

/// How optimalSlicing found N* (OptimalSlicing::method).
enum class SlicingMethod {
  medialAxis,  ///< the paper's: the medial axis's best circle, polished and certified
  plane,       ///< a degenerate map: every normal one direction (or its antipode)
  curve,       ///< a degenerate map: the normals form a curve (K = 0), searched directly
  /// the Gauss map has no complement and a proof that the normals cover the sphere says
  /// alpha* = 0 exactly (any direction; OptimalSlicing::coverage)
  covered,
  /// no complement within the map's tolerance but no such proof either: N* is the best
  /// direction the lattice's seeds polish to, its alpha certified like any other (an honest
  /// lower bound, possibly 0)
  lattice,
  /// the same without the search (OptimalSlicingOptions::noComplement), alpha 0 at the pole
  open,
};

/// The method's name in JSON documents and messages: "medial-axis", "plane", "curve",
/// "covered", "lattice" or "open".
const char* slicingMethodName(SlicingMethod method);

struct OptimalSlicing {
  Vec3 normal;             ///< N*, unit (its sign is arbitrary: +-N* slice alike)
  double alphaRad = 0.0;   ///< alpha*: the minimum angle between N* and +-n, radians
  PlaneCircle circle;      ///< the maximal circle in the pole frame's stereographic plane
  SphereCircle sphereCircle;  ///< the same circle on the unit sphere (original frame)
  Vec3 pole;               ///< the surface normal used as the pole
  bool certified = false;  ///< proven: no normal within certifiedAlphaRad of +-N*
  double certifiedAlphaRad = 0.0;  ///< the angle the certificate proves (alpha* - 1e-7 rad)
  /// When the certificate refuted the polish's alpha (a normal nearer to N* than its contacts
  /// showed), that refuted value; alphaRad is then the largest angle the certificate proves
  /// at N* (by bisection), so an uncertified angle is never the answer. 0 otherwise.
  double uncertifiedAlphaRad = 0.0;
  std::size_t certificateCells = 0;  ///< quadtree cells the certificate examined
  /// How N* was found (SlicingMethod).
  SlicingMethod method = SlicingMethod::medialAxis;
  NormalCoverage coverage;  ///< the covering proof, tried when the complement is empty
  GaussMap gaussMap;
  /// The interior medial axis of the projected complement (pole frame), each edge sampled
  /// as a polyline, for figures. Coarse to fine, that of the final mixed domain: the full
  /// domain's near the best circles, a simplified one's elsewhere.
  std::vector<std::vector<Vec2>> medialAxisCurves;
  std::size_t medialAxisEdges = 0;
  int medialAxisRebuilds = 0;
  /// Boundary segments of the final domain handed to the medial axis (the coarse-to-fine
  /// search's mixed domain, or the whole projected complement).
  std::size_t medialAxisSegments = 0;
  int medialAxisRefinements = 0;  ///< refinement rounds of the coarse-to-fine search
  double seconds = 0.0;    ///< wall time of the whole computation
};

/// A circle of the stereographic plane and the angular radius of its cap on the sphere
/// (eq 12), the quantity the medial-axis search maximises.
struct RatedCircle {
  double alphaRad = 0.0;
  PlaneCircle circle;
};

struct BestCirclesOptions {
  /// Also return every candidate circle within this angle (radians, >= 0) of the best: the
  /// rival basins that optimalSlicing polishes (it uses 4 tolerances).
  double windowRad = 0.0;
  /// true: domains with more than coarseToFineMinSegments segments are searched coarse to
  /// fine (see bestCircles); false: always the full-resolution medial axis.
  bool coarseToFine = true;
  std::size_t coarseToFineMinSegments = 3000;
};

/// What bestCircles found.
struct BestCircles {
  RatedCircle best;  ///< the greatest alpha (the first such in the axis's edge order)
  /// Every candidate (edge end or root of eq 13) within windowRad of the best, best first
  /// (ties in the axis's edge order); the best circle is among them.
  std::vector<RatedCircle> rivals;
  MedialAxis axis;               ///< the medial axis of the final domain searched
  std::size_t segments = 0;      ///< boundary segments of that domain
  int refinements = 0;           ///< refinement rounds of the coarse-to-fine search
  /// Douglas-Peucker tolerance of the verified coarse domain (the domain's units); 0: the
  /// full-resolution domain was searched (small domain, coarseToFine off, or a fallback).
  double simplificationTolerance = 0.0;
  /// Edges of `axis` rated at their ends alone: an upper bound of alpha over the edge (from
  /// its control points, see circle_search.cpp) fell short of the best end less the
  /// window, so no root of eq (13) on it could be the best or a rival.
  std::size_t boundedEdges = 0;
};

/// The maximal circle of greatest alpha (eq 12) in a planar domain of the stereographic
/// plane (the projected complement of the Gauss map, which never holds the origin): the
/// medial axis's edges are rated at their ends and at the roots of eq (13) (on the edges
/// whose bound can reach within the window of the best end). Coarse to fine
/// above options.coarseToFineMinSegments (see the contract): the same best circle and rivals
/// as the full-resolution search, to rounding. Deterministic. Throws scallop::Error when
/// the medial axis of the full domain does, or when no circle is usable.
BestCircles bestCircles(const PlanarDomain& domain, const BestCirclesOptions& options = {});

/// The optimal slicing orientation of `surface`; throws scallop::Error on bad options.
OptimalSlicing optimalSlicing(const Surface& surface, const OptimalSlicingOptions& options = {});

/// The minimum angle (radians) between direction `n` (any length) and +-(surface normals),
/// proven at least `lowerBoundRad` when the return is true: the Bernstein-form certificate
/// (see the contract), subdividing each patch while needed, up to `maxDepth`. `cells`
/// counts the cells examined.
constexpr int kCertificateMaxDepth = 14;
bool certifyClearance(const Surface& surface, const Vec3& n, double lowerBoundRad,
                      std::size_t& cells, int maxDepth = kCertificateMaxDepth);

}  // namespace scallop
