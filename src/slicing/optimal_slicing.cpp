// The optimal slicing orientation: Gauss map -> stereographic plane -> medial axis ->
// maximisation of tan(alpha) along its edges (eq 13) -> N* (eq 14) -> polish -> certificate.
// See include/scallop/slicing/optimal_slicing.hpp for the contract. This file runs the
// stages; each lives in its own file:
//   gauss_map.cpp              the symmetrized Gauss map and its polygon on the plane
//   loop_cleanup.cpp           the polygon's zero-width zigzags removed for the medial axis
//   circle_search.cpp          bestCircles: eq (13) along the medial axis, coarse to fine
//   direction_polish.cpp       N* polished on the true surface (trust-region SQP)
//   clearance_certificate.cpp  the proof that no normal comes within alpha* of +-N*

#include "scallop/slicing/optimal_slicing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/medial_axis.hpp"
#include "scallop/geometry/vector.hpp"
#include "slicing/clearance_certificate.hpp"
#include "slicing/direction_polish.hpp"
#include "slicing/loop_cleanup.hpp"

namespace scallop {
namespace {

// The certificate proves alpha* less this (6e-6 degree). The polish's contacts are Newton
// accurate (|n . N*| to rounding), so the margin is not for their error but keeps the
// subdivision shallow: near a contact the certified polynomial's minimum is about
// margin sin(2 alpha*) |N|^2, which cells of side ~sqrt(margin) resolve. On the paper's
// surfaces depth 14 proves margins down to 1e-9 (77 / 165 cells at 1e-7, 101 / 213 at 1e-9,
// failing at 1e-10): 1e-7 leaves two decades of headroom for more curved surfaces, in under
// a millisecond.
constexpr double kCertificateMarginRad = 1e-7;
// Halvings of the certified angle when the claim fails (see optimalSlicing's certificate).
constexpr int kCertificateBisections = 48;

double minimumAngle(const std::vector<Vec3>& normals, const Vec3& n) {
  double best = std::numbers::pi / 2.0;
  for (const Vec3& m : normals) {
    best = std::min(best, std::acos(std::min(1.0, std::abs(dot(m, n)))));
  }
  return best;
}

// Gauss image of dimension 1: maximise the minimum angle to the sampled normals directly,
// over a Fibonacci sphere of directions, then by a shrinking pattern search.
Vec3 bestDirectionForCurve(const std::vector<Vec3>& normals) {
  Vec3 best{0.0, 0.0, 1.0};
  double bestAngle = -1.0;
  constexpr int kDirections = 800;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kDirections; ++i) {
    const double z = 1.0 - (i + 0.5) / kDirections;  // upper hemisphere: +-N slice alike
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 n{r * std::cos(golden * i), r * std::sin(golden * i), z};
    const double a = minimumAngle(normals, n);
    if (a > bestAngle) bestAngle = a, best = n;
  }
  for (double step = 0.05; step > 1e-9; step *= 0.5) {
    for (bool improved = true; improved;) {
      improved = false;
      const Vec3 e1 = detail::unitOrthogonal(best);
      const Vec3 e2 = cross(best, e1);
      for (const Vec3& d : {e1, -e1, e2, -e2}) {
        const Vec3 n = normalized(best + step * d);
        const double a = minimumAngle(normals, n);
        if (a > bestAngle) bestAngle = a, best = n, improved = true;
      }
    }
  }
  return best;
}

}  // namespace

const char* slicingMethodName(SlicingMethod method) {
  switch (method) {
    case SlicingMethod::medialAxis: return "medial-axis";
    case SlicingMethod::plane: return "plane";
    case SlicingMethod::curve: return "curve";
    case SlicingMethod::covered: return "covered";
    case SlicingMethod::lattice: return "lattice";
    case SlicingMethod::open: return "open";
  }
  return "unknown";
}

OptimalSlicing optimalSlicing(const Surface& surface, const OptimalSlicingOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const double tol = options.toleranceRad;
  if (!(tol > 0.0) || !(tol < 0.1) || !std::isfinite(tol)) {
    throw Error(fmt::format("the tolerance must be an angle in (0, {} deg), got {} deg",
                            0.1 * 180.0 / std::numbers::pi, tol * 180.0 / std::numbers::pi));
  }
  validateSurface(surface);
  // Trimmed faces: their pieces' normals hold the faces' (a certified lower bound of alpha*).
  if (surface.trimmed()) return optimalSlicing(trimmedPieces(surface), options);
  // The polish and the certificate work on pieces without corners where q vanishes (the
  // polish's heights divide by |q|); the Gauss map and the coverage proof resolve them
  // themselves, naming the source patches in their errors.
  const Surface working = cornerResolved(surface);
  OptimalSlicing result;
  GaussMapOptions gaussOptions;
  gaussOptions.toleranceRad = tol;
  BestCirclesOptions searchOptions;
  // Rival basins: the polygon is within tol of Omega, so a circle within a few tol of the
  // best may be the true optimum's.
  searchOptions.windowRad = 4.0 * tol;
  searchOptions.coarseToFine = options.coarseToFine;
  // The map and its medial axis, and once more with the pole off its cell's centre when the
  // complement comes out empty (the pole on a cell edge's image, see gauss_map.hpp, Pole)
  // or the medial axis refuses it (loops that touch on its integer grid, a Voronoi diagram
  // that fails validation in every rotation): another pole projects another plane.
  // Each map's loops go to the medial axis as they are (Clipper's output is simple), and
  // only if it refuses them without their zero-width zigzags (withoutSpikes: removing a
  // vertex can make its chord cross a slit's other side, as on nearly developable patches).
  std::optional<BestCircles> found;
  for (int attempt = 0; attempt < 2 && !found; ++attempt) {
    gaussOptions.offsetPole = attempt == 1;
    result.gaussMap = symmetrizedGaussMap(surface, gaussOptions);
    if (result.gaussMap.kind != GaussMapKind::region) break;
    PlanarDomain domain{result.gaussMap.loops};
    if (domain.loops.empty()) continue;
    for (int cleaned = 0; cleaned < 2 && !found; ++cleaned) {
      if (cleaned == 1) domain.loops = detail::withoutSpikes(result.gaussMap.loops, 1e-2 * tol);
      if (domain.loops.empty()) break;
      try {
        found = bestCircles(domain, searchOptions);
      } catch (const Cancelled&) {
        throw;
      } catch (const Error&) {
        if (attempt == 1 && cleaned == 1) throw;
      }
    }
  }
  const GaussMap& map = result.gaussMap;
  result.pole = map.pole;
  const Rotation3 back = transpose(map.toPoleFrame);
  std::vector<Vec3> rivals;  // medial-axis directions to polish (the best first)

  if (map.kind == GaussMapKind::point) {
    // A plane, or a surface whose normals all lie within the tolerance (or too close for
    // the Gauss map's grid, see gauss_map.hpp): a direction orthogonal to the pole, polished
    // against the true normals (below). A plane keeps 90 degrees.
    result.method = SlicingMethod::plane;
    result.normal = detail::unitOrthogonal(map.pole);
    result.alphaRad = std::numbers::pi / 2.0;
    result.sphereCircle = {result.normal, result.alphaRad};
  } else if (map.kind == GaussMapKind::curve) {
    result.method = SlicingMethod::curve;
    // The curves come in antipodal pairs (n, -n), alike for |n . N|: keep one of each.
    std::vector<Vec3> normals;
    for (std::size_t i = 0; i < map.sphereCurves.size(); i += 2) {
      normals.insert(normals.end(), map.sphereCurves[i].begin(), map.sphereCurves[i].end());
    }
    result.normal = bestDirectionForCurve(normals);
    result.alphaRad = minimumAngle(normals, result.normal);
    result.sphereCircle = {result.normal, result.alphaRad};
  } else if (!found) {
    // No complement within the map's tolerance. "No direction exists" only with a proof
    // that the normals cover the sphere (normal_coverage.hpp); otherwise the best direction
    // that the lattice's seeds polish to, certified below like any other.
    using NoComplement = OptimalSlicingOptions::NoComplement;
    if (options.noComplement != NoComplement::stop) result.coverage = proveNormalsCoverSphere(surface);
    if (!result.coverage.proven && options.noComplement != NoComplement::proveThenSearch) {
      // Asked not to search: alpha >= 0 holds at every direction, and nothing more is said.
      result.method = SlicingMethod::open;
      result.normal = map.pole;
      result.alphaRad = 0.0;
      result.sphereCircle = {result.normal, 0.0};
      result.certified = true;
      result.certifiedAlphaRad = 0.0;
      result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    if (result.coverage.proven) {
      result.method = SlicingMethod::covered;
      result.normal = map.pole;
      result.alphaRad = 0.0;
      result.sphereCircle = {result.normal, 0.0};
      result.certified = true;  // alpha = 0 at every direction: proven by the covering
      result.certifiedAlphaRad = 0.0;
      result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    result.method = SlicingMethod::lattice;
    result.normal = map.pole;
    result.alphaRad = 0.0;
    result.sphereCircle = {result.normal, 0.0};
  } else {
    const BestCircles& search = *found;
    result.medialAxisEdges = search.axis.edges.size();
    result.medialAxisRebuilds = search.axis.rebuilds;
    result.medialAxisSegments = search.segments;
    result.medialAxisRefinements = search.refinements;
    for (const MedialEdge& edge : search.axis.edges) {
      std::vector<Vec2> curve;
      const int samples = edge.kind == MedialEdge::Kind::linear ? 1 : 8;
      for (int i = 0; i <= samples; ++i) curve.push_back(pointAt(edge, static_cast<double>(i) / samples));
      result.medialAxisCurves.push_back(std::move(curve));
    }
    result.circle = search.best.circle;
    result.alphaRad = alphaOfPlaneCircleRad(norm(result.circle.center), result.circle.radius);
    result.normal = apply(back, directionOfPlaneCircle(result.circle.center, result.circle.radius));
    result.sphereCircle = {result.normal, result.alphaRad};
    // Keep up to four rivals, in distinct directions (more than a degree apart), to be
    // polished below.
    for (const auto& [alpha, circle] : search.rivals) {
      if (rivals.size() >= 4) break;
      const Vec3 n = apply(back, directionOfPlaneCircle(circle.center, circle.radius));
      bool distinct = true;
      for (const Vec3& q : rivals) {
        distinct = distinct && std::acos(std::min(1.0, std::abs(dot(q, n)))) > std::numbers::pi / 180.0;
      }
      if (distinct) rivals.push_back(n);
    }
  }
  // Polish against the true surface (see direction_polish.hpp); the circle found on the
  // polygonal map stays as the medial-axis result.
  // (A curve-like image was searched on its own exact samples; its |n . N| landscape is flat
  // along the family of normals, where the pattern search only wanders.)
  if (result.method == SlicingMethod::medialAxis || result.method == SlicingMethod::lattice) {
    // Every rival is polished: the polygonal map can rank close rival optima wrongly by a
    // few tolerances, and each polish is cheap (a few Newton steps). With the option, then
    // the lattice's seeds (see latticeSeeds); the medial axis's rivals come first and win
    // ties.
    const detail::DirectionPolish polisher(working);
    if (options.latticeSeeds || result.method == SlicingMethod::lattice) {
      for (const Vec3& seed : polisher.latticeSeeds(2000, 4, 2.0 * std::numbers::pi / 180.0)) rivals.push_back(seed);
    }
    double bestValue = 2.0;
    for (const Vec3& seed : rivals) {
      double value = 0.0;
      const Vec3 polished = polisher.polish(seed, tol, value);
      if (value < bestValue) bestValue = value, result.normal = polished;
    }
    result.alphaRad = std::acos(std::min(1.0, bestValue));
    result.sphereCircle = {result.normal, result.alphaRad};
  } else if (result.method == SlicingMethod::plane) {
    double value = 0.0;
    const Vec3 polished = detail::DirectionPolish(working).polish(result.normal, tol, value);
    if (value > 0.0) {
      result.normal = polished;
      result.alphaRad = std::acos(std::min(1.0, value));
      result.sphereCircle = {result.normal, result.alphaRad};
    }
  } else if (result.method == SlicingMethod::curve) {
    // The curves' own optimum, polished on the true surface where that is better (a nearly
    // flat curved patch among developable ones has normals off its boundary's curve, within
    // the tolerance, that the curve search does not see).
    double value = 0.0;
    const Vec3 polished = detail::DirectionPolish(working).polish(result.normal, tol, value);
    const double polishedAlpha = std::acos(std::min(1.0, value));
    if (value > 0.0 && polishedAlpha > result.alphaRad) {
      result.normal = polished;
      result.alphaRad = polishedAlpha;
      result.sphereCircle = {result.normal, result.alphaRad};
    }
  }
  // Certificate: prove that no normal comes within alpha* less a small margin (what the
  // sampled-and-climbed maxima could have missed) of +-N*.
  if (options.certify) {
    result.certifiedAlphaRad = std::max(0.0, result.alphaRad - kCertificateMarginRad);
    result.certified = detail::certifyPieces(working, result.normal, result.certifiedAlphaRad,
                                     result.certificateCells, kCertificateMaxDepth);
    if (!result.certified) {
      // The polish's contacts missed a normal nearer to N* (a fold where the normal turns
      // fast, say): the claim falls, and what is proven at N* becomes the answer, found by
      // bisection on the certificate (the claim is an upper end; 0 holds trivially).
      // At most kCertificateBisections halvings, stopping at 1e-12 rad: a bounded cost (each
      // certificate subdivides only about the contacts it cannot yet prove).
      result.uncertifiedAlphaRad = result.alphaRad;
      double proven = 0.0, refuted = result.certifiedAlphaRad;
      for (int step = 0; step < kCertificateBisections && refuted - proven > 1e-12; ++step) {
        const double middle = 0.5 * (proven + refuted);
        if (detail::certifyPieces(working, result.normal, middle, result.certificateCells, kCertificateMaxDepth)) {
          proven = middle;
        } else {
          refuted = middle;
        }
      }
      result.certifiedAlphaRad = proven;
      result.alphaRad = proven;
      result.sphereCircle.alphaRad = proven;
      result.certified = true;  // alpha >= proven at N* (trivially so for 0)
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scallop