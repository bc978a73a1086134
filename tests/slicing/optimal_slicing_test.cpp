// Optimal slicing (Gauss map -> stereographic plane -> medial axis -> eq 13 -> N*) against
// an independent brute force written here: dense surface normals, thousands of candidate
// directions, local refinement of the best ones.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/slicing/gauss_map.hpp"
#include "scallop/slicing/medial_axis.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/slicing/stereographic.hpp"
#include "scallop/geometry/surface.hpp"
#include "support/corner_patches.hpp"
#include "support/gauss_references.hpp"

namespace {

using scallop::BezierPatch;
using scallop::Surface;
using scallop::Vec2;
using scallop::Vec3;

constexpr double kDeg = std::numbers::pi / 180.0;

using scallop::reference::sampledAlpha;
using scallop::reference::sampleNormals;
using scallop::SlicingMethod;
using scallop::slicingMethodName;

// The true alpha of a direction, independently of the library's own search: a fine grid
// per patch, then a local refinement of the grid's worst points by golden-section-like
// shrinking of a square around them. Accurate to ~1e-10 rad near smooth maxima.
double trueAlpha(const Surface& s, const Vec3& m) {
  constexpr int kGrid = 80;
  double worst = 0.0;
  for (const BezierPatch& p : s.patches) {
    auto f = [&](double u, double v) { return std::abs(scallop::dot(scallop::unitNormal(p, u, v), m)); };
    std::vector<std::pair<double, std::pair<double, double>>> grid;
    for (int i = 0; i <= kGrid; ++i) {
      for (int j = 0; j <= kGrid; ++j) {
        const double u = double(i) / kGrid, v = double(j) / kGrid;
        grid.push_back({f(u, v), {u, v}});
      }
    }
    std::partial_sort(grid.begin(), grid.begin() + 12, grid.end(), std::greater<>());
    for (int k = 0; k < 12; ++k) {
      auto [u, v] = grid[k].second;
      double best = grid[k].first;
      for (double h = 1.0 / kGrid; h > 1e-13; h *= 0.7) {
        for (int a = -2; a <= 2; ++a) {
          for (int b = -2; b <= 2; ++b) {
            const double uu = std::clamp(u + a * h / 2, 0.0, 1.0), vv = std::clamp(v + b * h / 2, 0.0, 1.0);
            const double g = f(uu, vv);
            if (g > best) best = g, u = uu, v = vv;
          }
        }
      }
      worst = std::max(worst, best);
    }
  }
  return std::acos(std::min(1.0, worst));
}

// Brute force: 3000 directions on the upper hemisphere (+-N slice alike), the 8 best
// refined by a pattern search on the sampled alpha, the best of those judged by trueAlpha.
Vec3 bruteForceDirection(const Surface& s) {
  const std::vector<Vec3> normals = sampleNormals(s, 60);
  std::vector<std::pair<double, Vec3>> scored;
  constexpr int kDirections = 3000;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kDirections; ++i) {
    const double z = 1.0 - (i + 0.5) / kDirections;
    const double r = std::sqrt(1.0 - z * z);
    const Vec3 m{r * std::cos(golden * i), r * std::sin(golden * i), z};
    scored.push_back({sampledAlpha(normals, m), m});
  }
  std::partial_sort(scored.begin(), scored.begin() + 8, scored.end(),
                    [](const auto& a, const auto& b) { return a.first > b.first; });
  Vec3 best = scored.front().second;
  double bestAlpha = -1.0;
  for (int k = 0; k < 8; ++k) {
    Vec3 m = scored[k].second;
    double a = scored[k].first;
    for (double step = 0.02; step > 1e-7; step *= 0.5) {
      for (bool moved = true; moved;) {
        moved = false;
        const Vec3 helper = std::abs(m.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        const Vec3 e1 = scallop::normalized(scallop::cross(m, helper));
        const Vec3 e2 = scallop::cross(m, e1);
        for (const Vec3& d : {e1, -e1, e2, -e2}) {
          const Vec3 c = scallop::normalized(m + step * d);
          const double ac = sampledAlpha(normals, c);
          if (ac > a) a = ac, m = c, moved = true;
        }
      }
    }
    const double t = trueAlpha(s, m);
    if (t > bestAlpha) bestAlpha = t, best = m;
  }
  return best;
}

// A random bicubic graph patch over a 3 x 3 footprint (like the paper's surfaces), heights
// in [0, amplitude].
Surface randomGraphSurface(std::mt19937_64& rng, double amplitude, scallop::Units units) {
  std::uniform_real_distribution<double> z(0.0, amplitude);
  BezierPatch p;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) p.control.push_back({double(k), double(j), z(rng)});
  }
  Surface s;
  s.units = units;
  s.patches.push_back(p);
  return s;
}

void expectAsGoodAsBruteForce(const Surface& s, double toleranceDeg) {
  scallop::OptimalSlicingOptions options;
  options.toleranceRad = toleranceDeg * kDeg;
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s, options);
  EXPECT_NEAR(scallop::norm(result.normal), 1.0, 1e-12);
  const double ours = trueAlpha(s, result.normal);
  // The reported alpha* is the true minimum angle at N* (the polish climbs to the true
  // maxima of |n . N*|): within the reference's own accuracy.
  EXPECT_NEAR(result.alphaRad, ours, 1e-7) << "reported alpha* vs independent alpha(N*)";
  const Vec3 brute = bruteForceDirection(s);
  const double best = trueAlpha(s, brute);
  // The criterion: alpha(N*) within 0.01 degree of the best brute force finds.
  EXPECT_GE(ours, best - 0.01 * kDeg) << "N* = (" << result.normal.x << ", " << result.normal.y
                                      << ", " << result.normal.z << "), alpha " << ours / kDeg
                                      << " deg; brute force (" << brute.x << ", " << brute.y
                                      << ", " << brute.z << "), alpha " << best / kDeg << " deg";
  EXPECT_TRUE(result.certified) << "certificate failed at " << result.certifiedAlphaRad / kDeg;
  // The certificate's claim, checked independently on samples.
  EXPECT_GE(sampledAlpha(sampleNormals(s, 60), result.normal), result.certifiedAlphaRad);
}

TEST(OptimalSlicing, PaperSurface1BeatsThePapersDirection) {
  const Surface s = scallop::exampleSurface("paper-1");
  expectAsGoodAsBruteForce(s, 0.5);
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
  // The paper's N* = (0.248, -0.969, 0.001) (eq 18) lies near the best horizontal direction;
  // ours is better by degrees (judge by alpha, as the issue says).
  const double paper = trueAlpha(s, scallop::normalized({0.248, -0.969, 0.001}));
  EXPECT_GT(result.alphaRad, paper + 1.0 * kDeg);
}

TEST(OptimalSlicing, PaperSurface2MatchesThePapersDirection) {
  const Surface s = scallop::exampleSurface("paper-2");
  expectAsGoodAsBruteForce(s, 0.5);
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
  // Eq (19): N* = (0.975, -0.221, -0.002), up to sign and the surface's symmetries (the
  // control net is symmetric under (x, y) -> (y, x) and under (x, y) -> (3 - x, 3 - y)).
  const Vec3 paper = scallop::normalized({0.975, -0.221, -0.002});
  double closest = 10.0;
  for (const Vec3& q : {paper, Vec3{paper.y, paper.x, paper.z}, Vec3{-paper.x, -paper.y, paper.z},
                        Vec3{-paper.y, -paper.x, paper.z}}) {
    closest = std::min(closest, std::acos(std::min(1.0, std::abs(scallop::dot(q, result.normal)))));
  }
  EXPECT_LT(closest, 0.5 * kDeg);
}

TEST(OptimalSlicing, RandomGraphPatchesInchesAndMillimetres) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 4; ++i) {
    Surface s = randomGraphSurface(rng, 1.5, scallop::Units::inch);
    if (i % 2 == 1) {  // the same shape in millimetres: alpha is scale free
      s.units = scallop::Units::millimetre;
      for (auto& p : s.patches[0].control) p = 25.4 * p;
    }
    SCOPED_TRACE("random surface " + std::to_string(i));
    expectAsGoodAsBruteForce(s, 0.5);
  }
}

// A bicubic control net that is not a grid over the plane: the grid over [x0, x0 + 3] x
// [0, 3] with every point moved in x and y by up to 0.35, heights in [0, 1.5].
BezierPatch randomGeneralPatch(std::mt19937_64& rng, double x0) {
  std::uniform_real_distribution<double> jitter(-0.35, 0.35);
  std::uniform_real_distribution<double> height(0.0, 1.5);
  BezierPatch p;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) p.control.push_back({x0 + k + jitter(rng), j + jitter(rng), height(rng)});
  }
  return p;
}

TEST(OptimalSlicing, RandomGeneralPatches) {
  std::mt19937_64 rng(7);
  int tested = 0;
  while (tested < 3) {
    Surface s;
    s.patches.push_back(randomGeneralPatch(rng, 0.0));
    try {
      scallop::validateSurface(s);
    } catch (const scallop::Error&) {
      continue;  // a net folding over itself: not a regular patch
    }
    SCOPED_TRACE("general patch " + std::to_string(tested));
    expectAsGoodAsBruteForce(s, 0.5);
    ++tested;
  }
}

TEST(OptimalSlicing, RandomMultiPatchSurfacesAtAFineTolerance) {
  // One to three general patches side by side (apart), at 1e-5 degree (~20,000-45,000
  // boundary segments: the coarse band, the polygon union and the coarse-to-fine circle
  // search all at work), against the brute force as above.
  std::mt19937_64 rng(99);
  int tested = 0;
  while (tested < 3) {
    Surface s;
    for (int q = 0; q <= tested; ++q) s.patches.push_back(randomGeneralPatch(rng, 4.0 * q));
    try {
      scallop::validateSurface(s);
    } catch (const scallop::Error&) {
      continue;
    }
    SCOPED_TRACE(std::to_string(tested + 1) + " patches");
    expectAsGoodAsBruteForce(s, 1e-5);
    ++tested;
  }
}

TEST(OptimalSlicing, TwoPatchSurface) {
  // Two bicubic patches side by side, sharing their common boundary row (C0): the Gauss map
  // is the union of both patches' images.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> height(0.0, 1.2);
  double z[4][7];
  for (auto& row : z) {
    for (double& h : row) h = height(rng);
  }
  expectAsGoodAsBruteForce(scallop::reference::twoPatchSurface(z), 0.5);
}

TEST(OptimalSlicing, TwoPatchSurfaceWhoseGaussMapMissesNormals) {
  // A random two-patch surface (C0 along x = 3) on which the Gauss map at 0.5 degree once
  // missed a region of normals near the corner (u, v) = (0, 1) of the second patch (2,640 of
  // 40,803 sampled normals lay more than two tolerances inside the complement; each patch
  // alone was right): the medial axis's best circle claimed 63.0 degrees, the true optimum
  // is 57.82 at about (0.526, 0.849, 0.055), which the lattice seeds of the polish found
  // then. The map was mended since (gauss_map_test.cpp checks it); the medial axis alone, with
  // the lattice seeds off (the default), finds the optimum, and its circle must be honest.
  const Surface s = scallop::reference::twoPatchRegressionSurface();
  expectAsGoodAsBruteForce(s, 0.5);
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
  ASSERT_FALSE(scallop::OptimalSlicingOptions{}.latticeSeeds);
  EXPECT_GT(result.alphaRad, 57.8 * kDeg);
  // The medial axis's circle claims no more than the surface allows at its centre, up to
  // Omega's tolerance (and the samples' spacing, which can only raise the sampled alpha).
  const double circleAlpha =
      scallop::alphaOfPlaneCircleRad(scallop::norm(result.circle.center), result.circle.radius);
  const Vec3 centre = scallop::apply(scallop::transpose(result.gaussMap.toPoleFrame),
                                     scallop::directionOfPlaneCircle(result.circle.center, result.circle.radius));
  EXPECT_LE(circleAlpha, sampledAlpha(sampleNormals(s, 100), centre) + 0.5 * kDeg);
}

TEST(OptimalSlicing, EllipticParaboloidEdgeOptimumIsExact) {
  // z = a x^2 + b y^2 over [-1, 1]^2 with a < b: the Gauss image is a cap elongated along y;
  // the best direction is N* = (1, 0, 0), touching the image at the two normals of (+-1, 0)
  // only (an optimum on an edge of the minimax problem: two contacts, stopped by the
  // curvature of the boundary images; the polish's Newton steps need the second-order
  // model there). alpha* = atan(1 / (2a)) exactly.
  constexpr double a = 0.3, b = 0.6;
  const double c[4] = {1.0, -1.0 / 3.0, -1.0 / 3.0, 1.0};  // (2u - 1)^2 in the cubic Bernstein basis
  BezierPatch p;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) p.control.push_back({-1.0 + 2.0 * j / 3.0, -1.0 + 2.0 * k / 3.0, a * c[j] + b * c[k]});
  }
  Surface s;
  s.patches.push_back(p);
  expectAsGoodAsBruteForce(s, 0.5);
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
  EXPECT_NEAR(result.alphaRad, std::atan(1.0 / (2.0 * a)), 1e-13);
  // Along the ridge F grows quadratically, so N* is determined to ~sqrt(rounding).
  EXPECT_NEAR(std::abs(result.normal.x), 1.0, 1e-12);
  EXPECT_LT(std::hypot(result.normal.y, result.normal.z), 1e-7);
}

// A curved patch with a developable one beside it whose normals lie just beside the curved
// patch's best slicing direction (5 degrees from it): a plane, or a cylinder-like patch
// bent along one tangent (its normals sweep an arc of a great circle through `normal`).
// Those normals must keep the slicing direction away as any other: the Gauss map has to
// hold them (Omega is what the medial axis sees; it once left them out, and the circle
// claimed 67.1 degrees within 6 of them), and the polish has to see them (the cylinder's
// ridge of |n . N|, a line of grid peaks equal to rounding along a ruling, once took every
// slot of the contact search: alpha* 47.83 degrees claimed, 47.75 true, not certified).
TEST(OptimalSlicing, CurvedPatchWithDevelopablePatch) {
  std::mt19937_64 rng(5);
  const Surface curved = randomGraphSurface(rng, 1.2, scallop::Units::inch);
  Vec3 best = bruteForceDirection(curved);
  if (best.z < 0.0) best = -best;
  const double curvedAlpha = trueAlpha(curved, best);
  const Vec3 side = scallop::normalized(scallop::cross(best, {0.0, 0.0, 1.0}));
  const Vec3 normal = std::cos(5.0 * kDeg) * best + std::sin(5.0 * kDeg) * side;
  const Vec3 along = scallop::normalized(scallop::cross(normal, {0.3, 0.2, 0.9}));
  const Vec3 across = scallop::cross(normal, along);
  const double bend[4] = {0.0, 0.8, -0.3, 0.6};
  for (bool cylinder : {false, true}) {
    SCOPED_TRACE(cylinder ? "cylinder-like patch" : "planar patch");
    BezierPatch developable;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) {
        developable.control.push_back(Vec3{5.0, 5.0, 0.0} + (k / 3.0) * along + (j / 3.0) * across +
                                      (cylinder ? bend[k] : 0.0) * normal);
      }
    }
    Surface s = curved;
    s.patches.push_back(developable);
    expectAsGoodAsBruteForce(s, 0.5);
    const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
    // alpha* is the surface's own: not above the alpha of N* over dense normals of both
    // patches (sampling can only overestimate alpha).
    const std::vector<Vec3> dense = sampleNormals(s, 100);
    EXPECT_LE(result.alphaRad, sampledAlpha(dense, result.normal) + 1e-12);
    // The developable patch matters: the curved patch alone allowed more.
    EXPECT_LT(result.alphaRad, curvedAlpha - 1.0 * kDeg);
    // The medial axis's circle, found on Omega before any polish, already keeps off the
    // developable patch's normals (up to Omega's tolerance and strip width, two tolerances).
    const double circleAlpha =
        scallop::alphaOfPlaneCircleRad(scallop::norm(result.circle.center), result.circle.radius);
    const Vec3 centre = scallop::apply(scallop::transpose(result.gaussMap.toPoleFrame),
                                       scallop::directionOfPlaneCircle(result.circle.center, result.circle.radius));
    Surface alone;
    alone.patches = {developable};
    EXPECT_LE(circleAlpha, sampledAlpha(sampleNormals(alone, 100), centre) + 2.0 * 0.5 * kDeg);
    EXPECT_LE(circleAlpha, sampledAlpha(dense, centre) + 2.0 * 0.5 * kDeg);
  }
}

// The angle between two slicing normals (+-N slice alike), and for paper-2 the least over
// the images of `b` under the surface's symmetries ((x, y) -> (y, x), (x, y) -> (3 - x, 3 - y)
// on the control net: normals (nx, ny, nz) -> (ny, nx, nz), (-nx, -ny, nz)), which tie exactly.
double axisAngle(const Vec3& a, const Vec3& b, bool paper2Symmetry) {
  double best = std::acos(std::min(1.0, std::abs(scallop::dot(a, b))));
  if (paper2Symmetry) {
    for (const Vec3& q : {Vec3{b.y, b.x, b.z}, Vec3{-b.x, -b.y, b.z}, Vec3{-b.y, -b.x, b.z}}) {
      best = std::min(best, std::acos(std::min(1.0, std::abs(scallop::dot(a, q)))));
    }
  }
  return best;
}

TEST(OptimalSlicing, ConvergesAsTheToleranceShrinks) {
  // Issue item 7: as the Gauss map's tolerance shrinks (down to 1e-4 degree: some 7,000
  // boundary segments on either surface, about half a second each; the benchmark runs
  // 100,000, at 4e-7 degree),
  // alpha* never decreases beyond rounding and converges to the brute force's value, and N*
  // converges (successive N* closer and closer).
  struct Case {
    const char* name;
    std::vector<double> tolerancesDeg;
    bool symmetric;
  };
  for (const Case& c : {Case{"paper-1", {1.0, 0.5, 0.1, 0.01, 0.001, 0.0001}, false},
                        Case{"paper-2", {1.0, 0.5, 0.1, 0.01, 0.001, 0.0001}, true}}) {
    SCOPED_TRACE(c.name);
    const Surface s = scallop::exampleSurface(c.name);
    const double brute = trueAlpha(s, bruteForceDirection(s));
    double previousAlpha = -1.0;
    Vec3 previousNormal;
    double previousMove = 10.0;
    std::size_t previousSegments = 0;
    for (double toleranceDeg : c.tolerancesDeg) {
      SCOPED_TRACE("tolerance " + std::to_string(toleranceDeg) + " deg");
      scallop::OptimalSlicingOptions options;
      options.toleranceRad = toleranceDeg * kDeg;
      const scallop::OptimalSlicing result = scallop::optimalSlicing(s, options);
      EXPECT_TRUE(result.certified);
      EXPECT_GT(result.gaussMap.boundarySegments, previousSegments);
      previousSegments = result.gaussMap.boundarySegments;
      if (previousAlpha >= 0.0) {
        EXPECT_GE(result.alphaRad, previousAlpha - 1e-12);
        const double move = axisAngle(previousNormal, result.normal, c.symmetric);
        EXPECT_LE(move, previousMove + 1e-9);
        previousMove = move;
      }
      previousAlpha = result.alphaRad;
      previousNormal = result.normal;
    }
    EXPECT_GT(previousSegments, 5000u);
    // The true alpha at N*, at least the brute force's (which, sampling, can fall short).
    EXPECT_NEAR(previousAlpha, trueAlpha(s, previousNormal), 1e-7);
    EXPECT_GE(previousAlpha, brute - 0.01 * kDeg);
    EXPECT_LT(previousMove, 1e-7);
  }
}

TEST(OptimalSlicing, PlaneAndCylinder) {
  // A plane: alpha* = 90 degrees, N* in the plane.
  Surface plane;
  BezierPatch p;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) p.control.push_back({double(k), double(j), 0.2 * k + 0.1 * j});
  }
  plane.patches.push_back(p);
  const scallop::OptimalSlicing flat = scallop::optimalSlicing(plane);
  EXPECT_EQ(flat.method, SlicingMethod::plane);
  EXPECT_NEAR(flat.alphaRad, std::numbers::pi / 2, 1e-9);
  EXPECT_NEAR(trueAlpha(plane, flat.normal), std::numbers::pi / 2, 1e-9);
  // A cylinder-like patch z = f(x) only: normals lie on a great circle; the axis (y) is at
  // 90 degrees from all of them.
  Surface cylinder;
  BezierPatch c;
  const double heights[4] = {0.0, 1.2, -0.4, 0.3};
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) c.control.push_back({double(k), double(j), heights[k]});
  }
  cylinder.patches.push_back(c);
  const scallop::OptimalSlicing axis = scallop::optimalSlicing(cylinder);
  EXPECT_NEAR(trueAlpha(cylinder, axis.normal) / kDeg, 90.0, 1e-3);
}

TEST(OptimalSlicing, NearlyFlatSurfaceAtFineTolerances) {
  // A bilinear patch 10 km square (in millimetres) twisted by 1 mm: its normals lie within
  // ~1e-7 rad of +z, a Gauss map far below its integer grid's resolution about the origin
  // (see gauss_map.hpp), at tolerances on either side of that spread. It was once an error
  // ("no usable circle", or an empty union). Reported as a point, alpha* is measured on the
  // surface: below 90 degrees by at most the spread, as the brute force finds, and certified.
  Surface s;
  s.units = scallop::Units::millimetre;
  s.patches.push_back(BezierPatch{1, 1, {{0, 0, 0}, {0, 1e7, 0}, {1e7, 0, 0}, {1e7, 1e7, 1}}});
  for (double toleranceDeg : {1e-3, 1e-5, 1e-6, 4e-7, 1e-7}) {
    SCOPED_TRACE("tolerance " + std::to_string(toleranceDeg) + " deg");
    scallop::OptimalSlicingOptions options;
    options.toleranceRad = toleranceDeg * kDeg;
    const scallop::OptimalSlicing result = scallop::optimalSlicing(s, options);
    EXPECT_EQ(result.gaussMap.kind, scallop::GaussMapKind::point);
    EXPECT_EQ(result.method, SlicingMethod::plane);
    EXPECT_TRUE(result.certified);
    EXPECT_LT(result.alphaRad, std::numbers::pi / 2);
    EXPECT_GT(result.alphaRad, std::numbers::pi / 2 - 2e-7);
    EXPECT_NEAR(trueAlpha(s, result.normal), result.alphaRad, 1e-9);
  }
  expectAsGoodAsBruteForce(s, 1e-6);
}

TEST(OptimalSlicing, CertificateRejectsAnOverclaim) {
  const Surface s = scallop::exampleSurface("paper-2");
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
  std::size_t cells = 0;
  // Claiming one degree more than the true alpha must fail; one degree less must pass.
  EXPECT_FALSE(scallop::certifyClearance(s, result.normal, result.alphaRad + 1.0 * kDeg, cells));
  EXPECT_TRUE(scallop::certifyClearance(s, result.normal, result.alphaRad - 1.0 * kDeg, cells));
}

// Many patches (copies of one, translated: the same normals) unite their Gauss-map pieces in a
// tree of unions past 512 pieces instead of one sweep: the same map, the same alpha* as a few
// copies (one sweep) and as one alone, certified; and the cost grows about linearly (600
// copies: about 1.5 s, where one sweep took minutes at 400). 17 copies and more once settled
// 0.01 deg short of one copy's alpha* (78.0376 against 78.0475 deg): the polish's contact
// search filled its 16 slots with the copies of one contact.
TEST(OptimalSlicing, ManyPatchesUniteAsAFewDo) {
  const scallop::BezierPatch patch = scallop::exampleSurface("paper-1").patches[0];
  const auto copies = [&](int count) {
    Surface s;
    for (int i = 0; i < count; ++i) {
      scallop::BezierPatch copy = patch;
      for (Vec3& c : copy.control) c = c + Vec3{3.5 * (i % 50), 3.5 * (i / 50), 0.0};
      s.patches.push_back(copy);
    }
    return s;
  };
  const scallop::OptimalSlicing one = scallop::optimalSlicing(copies(1));
  const scallop::OptimalSlicing few = scallop::optimalSlicing(copies(20));
  const scallop::OptimalSlicing many = scallop::optimalSlicing(copies(600));
  ASSERT_TRUE(one.certified);
  ASSERT_TRUE(few.certified);
  ASSERT_TRUE(many.certified);
  EXPECT_GT(many.gaussMap.candidatePieces, 512u);
  EXPECT_NEAR(few.alphaRad, one.alphaRad, 1e-9);
  EXPECT_NEAR(many.alphaRad, one.alphaRad, 1e-9);
  EXPECT_NEAR(many.certifiedAlphaRad, one.certifiedAlphaRad, 1e-9);
  for (const int count : {16, 17}) {
    const scallop::OptimalSlicing some = scallop::optimalSlicing(copies(count));
    EXPECT_NEAR(some.certifiedAlphaRad, one.certifiedAlphaRad, 1e-9) << count << " copies";
  }
  EXPECT_EQ(many.gaussMap.loops.size(), few.gaussMap.loops.size());
  const std::vector<Vec3> normals = scallop::reference::sampleNormals(copies(1), 64);
  EXPECT_GE(scallop::reference::sampledAlpha(normals, many.normal), many.certifiedAlphaRad - 1e-12);
}

TEST(OptimalSlicing, RejectsBadTolerance) {
  const Surface s = scallop::exampleSurface("paper-1");
  for (double bad : {0.0, -1.0, std::nan(""), 10.0}) {
    scallop::OptimalSlicingOptions options;
    options.toleranceRad = bad * kDeg;
    EXPECT_THROW(scallop::optimalSlicing(s, options), scallop::Error);
  }
}

// ---------------------------------------------------------------------------------------
// The coarse-to-fine medial-axis search (bestCircles) against the full-resolution one.

// A smooth star-shaped loop about `centre`: r(theta) = radius (1 + sum of five harmonics of
// total amplitude <= `wobble`), n vertices at even steps of theta.
std::vector<Vec2> starLoop(std::mt19937_64& rng, Vec2 centre, double radius, double wobble, int n) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::array<double, 5> amplitude{};
  std::array<double, 5> phase{};
  double total = 0.0;
  for (std::size_t k = 0; k < amplitude.size(); ++k) {
    amplitude[k] = unit(rng) / double(k + 1);
    phase[k] = 2.0 * std::numbers::pi * unit(rng);
    total += amplitude[k];
  }
  std::vector<Vec2> loop;
  for (int i = 0; i < n; ++i) {
    const double theta = 2.0 * std::numbers::pi * i / n;
    double r = 1.0;
    for (std::size_t k = 0; k < amplitude.size(); ++k) {
      r += wobble / total * amplitude[k] * std::cos(double(k + 2) * theta + phase[k]);
    }
    loop.push_back(centre + radius * r * Vec2{std::cos(theta), std::sin(theta)});
  }
  return loop;
}

// Like the Gauss map's projected complement: an outer blob about the origin with a hole
// round the origin (the south pole lies in Omega) and sometimes a second, off-centre hole;
// `total` vertices in all.
scallop::PlanarDomain randomBlobDomain(std::mt19937_64& rng, int total) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto jitter = [&](double size) { return Vec2{size * (2.0 * unit(rng) - 1.0), size * (2.0 * unit(rng) - 1.0)}; };
  const bool secondHole = unit(rng) < 0.5;
  scallop::PlanarDomain domain;
  // Outer radius in [0.75, 1.25] about a centre within 0.1 * sqrt(2) of the origin; the
  // hole's in [0.2, 0.3] about a centre within 0.05 * sqrt(2) (so it holds the origin); the
  // second hole's in [0.064, 0.096], 0.5 from the origin: all disjoint (0.5 - 0.071 > 0.3 +
  // 0.096, 0.5 + 0.142 + 0.096 < 0.75).
  domain.loops.push_back(starLoop(rng, jitter(0.1), 1.0, 0.25, total * 3 / 5));
  domain.loops.push_back(starLoop(rng, jitter(0.05), 0.25, 0.2, total / 4));
  if (secondHole) {
    const double angle = 2.0 * std::numbers::pi * unit(rng);
    domain.loops.push_back(starLoop(rng, 0.5 * Vec2{std::cos(angle), std::sin(angle)}, 0.08, 0.2, total * 3 / 20));
  }
  return domain;
}

std::size_t segmentsOf(const scallop::PlanarDomain& domain) {
  std::size_t n = 0;
  for (const auto& loop : domain.loops) n += loop.size();
  return n;
}

double diagonalOf(const scallop::PlanarDomain& domain) {
  Vec2 low{1e300, 1e300}, high{-1e300, -1e300};
  for (const auto& loop : domain.loops) {
    for (const Vec2& p : loop) {
      low = {std::min(low.x, p.x), std::min(low.y, p.y)};
      high = {std::max(high.x, p.x), std::max(high.y, p.y)};
    }
  }
  return scallop::norm(high - low);
}

// The coarse-to-fine search against the full-resolution one (the reference: the direct
// search, the medial axis of the whole domain, itself checked against a brute-force
// clearance: its best circle is a maximal empty disc). Returns the coarse-to-fine result.
//  - Both medial axes accepted at the same rotation (the usual case): the domains share
//    their integer grid, so the best circle must agree to 1e-12 in alpha (relative) and
//    1e-9 of the domain's size, and so must every rival within the window; where circles
//    tie with the best (within 1e-12 in alpha), the circle found must be one of the ties.
//  - Boost's diagram of one domain failed validation and was rebuilt rotated (medial_axis.hpp):
//    the two integer domains differ by rounding (0.71 grid steps q), so alpha agrees to a few
//    q (the conformal factor is <= 2) and the circle found is an empty disc of the full
//    domain to the medial axis's tolerance. `sameGrid` counts the first kind.
scallop::BestCircles expectSameBestCircle(const scallop::PlanarDomain& domain, double windowRad,
                                          std::size_t minSegments, int& sameGrid) {
  scallop::BestCirclesOptions fineOptions;
  fineOptions.windowRad = windowRad;
  fineOptions.coarseToFine = false;
  scallop::BestCirclesOptions coarseOptions = fineOptions;
  coarseOptions.coarseToFine = true;
  coarseOptions.coarseToFineMinSegments = minSegments;
  const scallop::BestCircles full = scallop::bestCircles(domain, fineOptions);
  const scallop::BestCircles fast = scallop::bestCircles(domain, coarseOptions);
  const double size = diagonalOf(domain);
  const scallop::PlaneCircle& c = full.best.circle;
  EXPECT_TRUE(scallop::insideDomain(domain, c.center));
  EXPECT_NEAR(scallop::clearance(domain, c.center), c.radius, 2.0 * full.axis.tolerance);
  if (fast.axis.rotationRad != full.axis.rotationRad) {
    const double q = std::max(full.axis.tolerance, fast.axis.tolerance);
    EXPECT_NEAR(fast.best.alphaRad, full.best.alphaRad, 8.0 * q);
    EXPECT_GE(scallop::clearance(domain, fast.best.circle.center), fast.best.circle.radius - 4.0 * q);
    EXPECT_TRUE(scallop::insideDomain(domain, fast.best.circle.center));
    return fast;
  }
  ++sameGrid;
  EXPECT_NEAR(fast.best.alphaRad, full.best.alphaRad, 1e-12 * full.best.alphaRad);
  auto sameCircle = [size](const scallop::PlaneCircle& a, const scallop::PlaneCircle& b) {
    return scallop::norm(a.center - b.center) <= 1e-9 * size && std::abs(a.radius - b.radius) <= 1e-9 * size;
  };
  auto tiesWithBest = [&full](const scallop::RatedCircle& r) {
    return r.alphaRad >= full.best.alphaRad * (1.0 - 1e-12);
  };
  bool tied = false;
  for (const scallop::RatedCircle& r : full.rivals) tied = tied || (tiesWithBest(r) && !sameCircle(r.circle, c));
  if (!tied) {
    EXPECT_TRUE(sameCircle(fast.best.circle, c))
        << "centre (" << fast.best.circle.center.x << ", " << fast.best.circle.center.y << ") r "
        << fast.best.circle.radius << " vs (" << c.center.x << ", " << c.center.y << ") r " << c.radius;
  } else {
    bool found = false;
    for (const scallop::RatedCircle& r : full.rivals) found = found || (tiesWithBest(r) && sameCircle(r.circle, fast.best.circle));
    EXPECT_TRUE(found) << "not one of the full search's tied circles";
  }
  // Each rival within the window is one of the full search's, and vice versa.
  auto among = [&](const scallop::RatedCircle& r, const std::vector<scallop::RatedCircle>& list) {
    for (const scallop::RatedCircle& q : list) {
      if (std::abs(q.alphaRad - r.alphaRad) <= 1e-12 * full.best.alphaRad && sameCircle(q.circle, r.circle)) return true;
    }
    return false;
  };
  for (const scallop::RatedCircle& r : fast.rivals) EXPECT_TRUE(among(r, full.rivals)) << "extra rival, alpha " << r.alphaRad;
  for (const scallop::RatedCircle& r : full.rivals) EXPECT_TRUE(among(r, fast.rivals)) << "missed rival, alpha " << r.alphaRad;
  return fast;
}

TEST(BestCircles, CoarseToFineMatchesFullResolutionOnRandomBlobs) {
  // Six domains of 3,000-6,000 vertices, with the scheme's threshold lowered to 1,000
  // segments so that it runs (the full reference costs ~0.05 s per 1,000 segments).
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int sameGrid = 0;
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const scallop::PlanarDomain domain = randomBlobDomain(rng, 3000 + static_cast<int>(3000.0 * unit(rng)));
    const scallop::BestCircles fast = expectSameBestCircle(domain, 1e-4, 1000, sameGrid);
    // The scheme did run coarse and verified (no fallback to the full domain).
    EXPECT_GT(fast.simplificationTolerance, 0.0);
    EXPECT_LT(fast.segments, segmentsOf(domain) / 2);
  }
  EXPECT_GE(sameGrid, 4);  // all 6 when written
}

TEST(BestCircles, CoarseToFineMatchesFullResolutionAtPipelineSize) {
  // One domain of 20,000-30,000 vertices, at the pipeline's threshold (3,000 segments).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const scallop::PlanarDomain domain = randomBlobDomain(rng, 20000 + static_cast<int>(10000.0 * unit(rng)));
  int sameGrid = 0;
  const scallop::BestCircles fast = expectSameBestCircle(domain, 1e-4, 3000, sameGrid);
  EXPECT_GT(fast.simplificationTolerance, 0.0);
  EXPECT_LT(fast.segments, segmentsOf(domain) / 5);
  EXPECT_EQ(sameGrid, 1);
}

TEST(BestCircles, CoarseToFineMatchesFullResolutionOnDegenerateDomains) {
  // 3,000 + 2,000 vertices per domain; the scheme's threshold lowered to 1,000 segments.
  auto circle = [](Vec2 centre, double radius, int n, double wobble) {
    std::vector<Vec2> loop;
    for (int i = 0; i < n; ++i) {
      const double t = 2.0 * std::numbers::pi * i / n;
      loop.push_back(centre + radius * (1.0 + wobble * std::cos(3.0 * t)) * Vec2{std::cos(t), std::sin(t)});
    }
    return loop;
  };
  constexpr int kOuter = 3000;
  constexpr int kInner = 2000;
  int sameGrid = 0;
  {
    // Every point of the medial axis (the circle of radius 0.65) ties: the whole domain is
    // refined, and the result is the full search's.
    SCOPED_TRACE("concentric annulus about the origin");
    scallop::PlanarDomain domain;
    domain.loops = {circle({0.0, 0.0}, 1.0, kOuter, 0.0), circle({0.0, 0.0}, 0.3, kInner, 0.0)};
    expectSameBestCircle(domain, 0.0, 1000, sameGrid);
  }
  {
    SCOPED_TRACE("nearly circular: a flat landscape with one optimum");
    scallop::PlanarDomain domain;
    domain.loops = {circle({0.01, 0.0}, 1.0, kOuter, 1e-7), circle({0.0, 0.0}, 0.3, kInner, 0.0)};
    const scallop::BestCircles fast = expectSameBestCircle(domain, 0.0, 1000, sameGrid);
    EXPECT_GT(fast.simplificationTolerance, 0.0);
  }
  {
    // A hole that comes within 3e-6 of the outer loop, against a delta of ~5e-5 (where the
    // simplified outer loop crosses the hole and the search simplifies again at delta / 2,
    // delta / 4).
    SCOPED_TRACE("a neck narrower than delta");
    const double offset = 0.5 - 3e-6;
    scallop::PlanarDomain domain;
    domain.loops = {circle({0.0, 0.0}, 1.0, kOuter, 0.0),
                    circle({offset * std::cos(0.7), offset * std::sin(0.7)}, 0.5, kInner, 0.0)};
    expectSameBestCircle(domain, 0.0, 1000, sameGrid);
  }
  {
    // A ring 1e-6 wide: every simplification crosses the other loop, so the search falls
    // back to the full domain.
    SCOPED_TRACE("a ring thinner than delta");
    scallop::PlanarDomain domain;
    domain.loops = {circle({0.0, 0.0}, 1.0, kOuter, 0.0), circle({0.0, 0.0}, 1.0 - 1e-6, kOuter, 0.0)};
    const scallop::BestCircles fast = expectSameBestCircle(domain, 0.0, 1000, sameGrid);
    EXPECT_EQ(fast.simplificationTolerance, 0.0);
    EXPECT_EQ(fast.segments, segmentsOf(domain));
  }
  EXPECT_EQ(sameGrid, 4);
}

// The rating skips the roots of eq (13) on edges whose alpha bound falls short of the best
// end less the window (BestCircles::boundedEdges). Against the same search with a window of
// 10 rad (which bounds out nothing, so every root is rated): on 50 random domains and three
// windows, the same best circle bit for bit, and the same rivals in the same order.
TEST(BestCircles, EdgesRatedByTheirBoundLoseNoCandidate) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> size(150, 600);
  std::size_t bounded = 0, edges = 0, rivals = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const scallop::PlanarDomain domain = randomBlobDomain(rng, size(rng));
    scallop::BestCirclesOptions everything;
    everything.windowRad = 10.0;
    everything.coarseToFine = false;
    const scallop::BestCircles reference = scallop::bestCircles(domain, everything);
    ASSERT_EQ(reference.boundedEdges, 0u);
    for (double window : {0.0, 1e-4, 1e-2}) {
      SCOPED_TRACE("trial " + std::to_string(trial) + ", window " + std::to_string(window));
      scallop::BestCirclesOptions options = everything;
      options.windowRad = window;
      const scallop::BestCircles found = scallop::bestCircles(domain, options);
      bounded += found.boundedEdges;
      edges += found.axis.edges.size();
      EXPECT_EQ(found.best.alphaRad, reference.best.alphaRad);
      EXPECT_EQ(found.best.circle.center.x, reference.best.circle.center.x);
      EXPECT_EQ(found.best.circle.center.y, reference.best.circle.center.y);
      EXPECT_EQ(found.best.circle.radius, reference.best.circle.radius);
      std::vector<scallop::RatedCircle> expected;
      for (const scallop::RatedCircle& r : reference.rivals) {
        if (r.alphaRad >= reference.best.alphaRad - window) expected.push_back(r);
      }
      ASSERT_EQ(found.rivals.size(), expected.size());
      rivals += expected.size();
      for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(found.rivals[i].alphaRad, expected[i].alphaRad);
        EXPECT_EQ(found.rivals[i].circle.center.x, expected[i].circle.center.x);
        EXPECT_EQ(found.rivals[i].circle.center.y, expected[i].circle.center.y);
        EXPECT_EQ(found.rivals[i].circle.radius, expected[i].circle.radius);
      }
    }
  }
  // Not vacuous: most edges were bounded out.
  EXPECT_GT(bounded, edges / 2);
  std::printf("[          ] 150 searches: %zu of %zu edges rated by their bound, %zu rivals compared\n",
              bounded, edges, rivals);
}

// On the paper's surfaces at ~10,000 boundary segments (5e-5 degree), optimalSlicing finds
// the same circle with and without the coarse-to-fine search.
TEST(OptimalSlicing, CoarseToFineGivesTheFullResolutionCircle) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const Surface s = scallop::exampleSurface(name);
    scallop::OptimalSlicingOptions options;
    options.toleranceRad = 5e-5 * kDeg;
    options.certify = false;
    const scallop::OptimalSlicing fast = scallop::optimalSlicing(s, options);
    options.coarseToFine = false;
    const scallop::OptimalSlicing full = scallop::optimalSlicing(s, options);
    EXPECT_GT(full.gaussMap.boundarySegments, 8000u);
    // The full search takes the whole map (less the few zigzag vertices removed before it).
    EXPECT_GT(full.medialAxisSegments, full.gaussMap.boundarySegments * 99 / 100);
    EXPECT_LT(fast.medialAxisSegments, full.medialAxisSegments / 2);
    const double scale = std::max(1.0, scallop::norm(full.circle.center));
    EXPECT_NEAR(fast.circle.center.x, full.circle.center.x, 1e-12 * scale);
    EXPECT_NEAR(fast.circle.center.y, full.circle.center.y, 1e-12 * scale);
    EXPECT_NEAR(fast.circle.radius, full.circle.radius, 1e-12 * full.circle.radius);
    EXPECT_NEAR(fast.alphaRad, full.alphaRad, 1e-12 * full.alphaRad);
    EXPECT_NEAR(scallop::dot(fast.normal, full.normal), 1.0, 1e-15);
  }
}

}  // namespace

namespace {

// Six families of patches that real parts are made of, 1,800 in all (fixed seed): quarter
// surfaces of revolution (plain, with an apex row, with a perturbed profile), a cylindrical
// strip with one curved column (K = 0 on most of it), nearly developable patches (z within
// 1e-3 of a parabolic cylinder: a Gauss image a thin strip), and random graphs with a
// collapsed column. Each must give a certified answer, no error, and no more than dense
// samples allow at N*. (Before this work 500 of them were rejected and 55 more failed.)
TEST(OptimalSlicing, RealisticPatchFamiliesAlwaysGiveCertifiedAnswers) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double k = 0.5522847498307936;
  const double cx[4] = {1, 1, k, 0}, cy[4] = {0, k, 1, 1};
  int answered = 0;
  for (int trial = 0; trial < 1800; ++trial) {
    const int family = trial % 6;
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int c = 0; c <= 3; ++c) {
        Vec3 q;
        if (family <= 2) {
          const double r = 0.5 + 0.4 * j + (family == 2 ? 0.3 * unit(rng) : 0.0);
          q = {r * cx[c], r * cy[c], 0.5 * std::sin(j) + (family != 0 ? 0.2 * unit(rng) : 0.0)};
          if (family == 1 && j == 0) q = {0.0, 0.0, 0.7};  // an apex row
        } else if (family == 3) {
          q = {double(c), std::cos(j * 0.5), std::sin(j * 0.5) + (c == 3 ? 0.3 * unit(rng) : 0.0)};
        } else if (family == 4) {
          q = {double(c), double(j), 1e-3 * unit(rng) + 0.1 * c * c};
        } else {
          q = {double(c), double(j), 0.8 * unit(rng)};
          if (c == 3) q = {3.0, 1.5, 0.2};  // a collapsed column
        }
        p.control.push_back(q);
      }
    }
    const Surface s{scallop::Units::inch, {p}};
    SCOPED_TRACE("trial " + std::to_string(trial) + ", family " + std::to_string(family));
    ASSERT_NO_THROW(scallop::validateSurface(s));
    scallop::OptimalSlicing result;
    ASSERT_NO_THROW(result = scallop::optimalSlicing(s));
    EXPECT_TRUE(result.certified);
    EXPECT_LE(result.certifiedAlphaRad,
              sampledAlpha(scallop::reference::sampleRegularNormals(s, 40), result.normal) + 1e-12);
    ++answered;
  }
  EXPECT_EQ(answered, 1800);
}

}  // namespace

namespace {

// Random surfaces of 1 to 4 patches of degrees 1 to 5 side by side (fixed seed), mixing graph
// patches, apex rows, nearly flat near-cylinders (z within 1e-4 of a sine) and jittered nets.
// Two failures were found this way and are kept below as regressions: a nearly flat patch
// chosen as the pole cell (its polygon need not wind around its own centre normal, and the
// whole map became Omega: 6 of 600 surfaces), and a plane beside a nearly flat patch (no
// regular cell: an error). Every answer must be certified and claim no more than dense
// samples allow at N*.
Surface mixedSurface(std::mt19937_64& rng, int trial) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> degree(1, 5), count(1, 4);
  Surface s;
  const int patches = count(rng);
  for (int q = 0; q < patches; ++q) {
    BezierPatch p;
    p.degreeU = degree(rng);
    p.degreeV = degree(rng);
    const int family = (trial + q) % 4;
    for (int j = 0; j <= p.degreeU; ++j) {
      for (int k = 0; k <= p.degreeV; ++k) {
        double x = 3.0 * j / p.degreeU + 3.0 * q, y = 3.0 * k / p.degreeV, z = 0.7 * unit(rng);
        if (family == 1 && j == 0) x = 3.0 * q, y = 1.5, z = 0.3;                  // apex row
        if (family == 2) z = 0.3 * std::sin(2.0 * j / p.degreeU) + 1e-4 * unit(rng);  // nearly flat
        if (family == 3) x += 0.5 * unit(rng), y += 0.5 * unit(rng);                 // jittered
        p.control.push_back({x, y, z});
      }
    }
    s.patches.push_back(p);
  }
  return s;
}

TEST(OptimalSlicing, MixedMultiPatchSurfacesAlwaysGiveCertifiedAnswers) {
  std::mt19937_64 rng(2);
  int answered = 0, skipped = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Surface s = mixedSurface(rng, trial);
    try {
      scallop::validateSurface(s);
    } catch (const scallop::Error&) {
      ++skipped;  // a random net that folds (r_u x r_v = 0 inside): not a regular surface
      continue;
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    scallop::OptimalSlicing result;
    ASSERT_NO_THROW(result = scallop::optimalSlicing(s));
    EXPECT_TRUE(result.certified);
    EXPECT_LE(result.certifiedAlphaRad,
              sampledAlpha(scallop::reference::sampleRegularNormals(s, 40), result.normal) + 1e-12);
    // A free direction exists on all of these (open patches side by side): the map must
    // find it, not call the complement empty.
    EXPECT_NE(result.method, SlicingMethod::lattice);
    EXPECT_NE(result.method, SlicingMethod::covered);
    if (trial % 16 == 0) {
      // Every 16th against the brute force's best direction on the continuous surface.
      const scallop::reference::BruteForceSlicing bruteForce = scallop::reference::bruteForceOptimalAlpha(s);
      EXPECT_LE(scallop::reference::nearestNormalAngle(s, bruteForce.direction), result.alphaRad + 0.01 * kDeg)
          << slicingMethodName(result.method);
    }
    ++answered;
  }
  EXPECT_GT(answered, 380);
  std::printf("[          ] %d mixed surfaces answered, %d random nets rejected\n", answered, skipped);
}

// The two regressions against the brute force, judged on the continuous surface.
TEST(OptimalSlicing, NearlyFlatPatchBesideOthersMatchesBruteForce) {
  // A curved ruled patch (degree (5, 1)) beside a nearly flat one: the pole cell was the flat
  // patch's whole domain.
  Surface curved;
  {
    BezierPatch p{5, 1, {}};
    const double z0[6] = {0.3, -0.2037, 0.4319, 0.4261, -0.4595, 0.3394};
    const double z1[6] = {0.3, 0.6192, 0.2595, -0.5202, 0.1031, 0.1767};
    for (int j = 0; j <= 5; ++j) {
      p.control.push_back(j == 0 ? Vec3{0, 1.5, 0.3} : Vec3{0.6 * j, 0, z0[j]});
      p.control.push_back(j == 0 ? Vec3{0, 1.5, 0.3} : Vec3{0.6 * j, 3, z1[j]});
    }
    BezierPatch flat{1, 3, {}};
    const double noise[8] = {2e-5, -7e-5, 4e-5, 1e-5, -3e-5, 6e-5, -1e-5, 5e-5};
    for (int j = 0; j <= 1; ++j) {
      for (int k = 0; k <= 3; ++k) {
        flat.control.push_back({3.0 + 3.0 * j, double(k), 0.3 * std::sin(2.0 * j) + noise[4 * j + k]});
      }
    }
    curved.patches = {p, flat};
  }
  // A plane (a flat triangle with an apex row) beside a nearly flat patch: no regular cell.
  Surface flats;
  {
    BezierPatch triangle{1, 1, {{0, 1.5, 0.3}, {0, 1.5, 0.3}, {3, 0, 0.1462}, {3, 3, -0.4548}}};
    BezierPatch flat{1, 4, {}};
    const double z0[5] = {2.8e-5, 8.9e-5, 6.8e-6, 6.6e-5, 2.4e-6};
    const double z1[5] = {0.27270, 0.27284, 0.27281, 0.27284, 0.27277};
    for (int k = 0; k <= 4; ++k) flat.control.push_back({3.0, 0.75 * k, z0[k]});
    for (int k = 0; k <= 4; ++k) flat.control.push_back({6.0, 0.75 * k, z1[k]});
    flats.patches = {triangle, flat};
  }
  for (const Surface* s : {&curved, &flats}) {
    ASSERT_NO_THROW(scallop::validateSurface(*s));
    const scallop::OptimalSlicing result = scallop::optimalSlicing(*s);
    EXPECT_TRUE(result.certified);
    // The brute force's best direction, measured on the continuous surface (its samples
    // overestimate alpha there by their gap), is no better than scallop's answer, and
    // scallop's answer is what the surface allows at N*, both within 0.01 degree.
    const scallop::reference::BruteForceSlicing bruteForce = scallop::reference::bruteForceOptimalAlpha(*s);
    EXPECT_LE(scallop::reference::nearestNormalAngle(*s, bruteForce.direction), result.alphaRad + 0.01 * kDeg)
        << slicingMethodName(result.method);
    EXPECT_GE(result.alphaRad, scallop::reference::nearestNormalAngle(*s, result.normal) - 0.01 * kDeg);
    EXPECT_LE(result.certifiedAlphaRad,
              sampledAlpha(scallop::reference::sampleRegularNormals(*s, 200), result.normal) + 1e-12);
  }
}

}  // namespace

// Random patches with one to four corners where r_u x r_v vanishes (the normal's limits along
// the rays into such a corner form an arc, which the Gauss map takes from cornerPieces'
// fans), and two- and three-patch surfaces of them: the paper's method alone, certified,
// never more than the normals allow at N* (dense samples with rays into every corner), and
// the brute force's best direction no better on the continuous surface. The brute force
// screens on 32 x 32 normals here: with 16 it missed the optimum by up to 18 degrees on
// patches folded tightly near a corner.
TEST(OptimalSlicing, SingularCornersMatchBruteForce) {
  std::mt19937_64 rng(1125);
  int tested = 0, agreeing = 0;
  double worstGap = 0.0;
  for (int trial = 0; tested < 150 && trial < 400; ++trial) {
    Surface s;
    const int patches = trial % 5 == 4 ? 1 + trial % 3 : 1;
    for (int i = 0; i < patches; ++i) {
      BezierPatch patch = scallop::test::randomCorneredPatch(rng).patch;
      for (Vec3& p : patch.control) p.x += 5.0 * i;
      s.patches.push_back(std::move(patch));
    }
    try {
      scallop::validateSurface(s);
    } catch (const scallop::Error&) {
      continue;  // a random net that folds inside: not a regular surface
    }
    ++tested;
    SCOPED_TRACE("trial " + std::to_string(trial));
    scallop::OptimalSlicingOptions options;
    ASSERT_FALSE(options.latticeSeeds);
    scallop::OptimalSlicing result;
    ASSERT_NO_THROW(result = scallop::optimalSlicing(s, options));
    EXPECT_EQ(result.method, SlicingMethod::medialAxis);
    EXPECT_TRUE(result.certified);
    const std::vector<Vec3> dense = scallop::reference::sampleRegularNormals(s, 100);
    EXPECT_GE(sampledAlpha(dense, result.normal), result.certifiedAlphaRad - 1e-12);
    const double nearest = scallop::reference::nearestNormalAngle(s, result.normal);
    EXPECT_GE(nearest, result.certifiedAlphaRad - 1e-12);
    // The polished alpha* itself is within the certificate's margin (1e-7 rad: what the
    // polish's climbed contacts may miss; measured up to 7e-9 here) of the nearest normal.
    EXPECT_GE(nearest, result.alphaRad - 1e-7) << (result.alphaRad - nearest);
    scallop::reference::BruteForceOptions bruteOptions;
    bruteOptions.screenSamples = 32;
    bruteOptions.finalists = 16;
    const scallop::reference::BruteForceSlicing bruteForce = scallop::reference::bruteForceOptimalAlpha(s, bruteOptions);
    const double gap = scallop::reference::nearestNormalAngle(s, bruteForce.direction) - result.alphaRad;
    EXPECT_LE(gap, 0.01 * kDeg);
    worstGap = std::max(worstGap, gap);
    agreeing += std::abs(bruteForce.alphaRad - result.alphaRad) <= 0.01 * kDeg;
  }
  EXPECT_EQ(tested, 150);
  std::printf("[          ] %d surfaces with singular corners; the brute force's samples agree within "
              "0.01 deg on %d (elsewhere their gap overestimates); its best direction is at most "
              "%.5f deg better on the continuous surface\n",
              tested, agreeing, worstGap / kDeg);
}

// --- rational patches (bezier.hpp's Rational patches; issue 14, item 2) -------------------

namespace {

// The surface of revolution's textbook construction (Piegl and Tiller, The NURBS Book, 8.5):
// a rational quadratic profile (x_k, z_k; weights 1, sqrt(2)/2, 1) swept by a quarter
// circle: p_jk = (x_k c_j, z_k), w_jk = a_j v_k.
Surface quarterRevolution(const std::array<std::pair<double, double>, 3>& profile) {
  const double s = std::sqrt(0.5);
  const std::array<std::pair<double, double>, 3> arc{{{1, 0}, {1, 1}, {0, 1}}};
  const std::array<double, 3> weights{1, s, 1};
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 2;
  patch.control.clear();
  for (int j = 0; j <= 2; ++j)
    for (int k = 0; k <= 2; ++k) {
      patch.control.push_back({profile[k].first * arc[j].first, profile[k].first * arc[j].second, profile[k].second});
      patch.weights.push_back(weights[j] * weights[k]);
    }
  return Surface{scallop::Units::millimetre, {patch}};
}

}  // namespace

// Closed forms: a sphere's octant (its pole row collapsed), the outer and the inner quarter
// of a torus's quarter: each patch's normals fill one octant of the sphere (and, symmetrized,
// its antipode), whose farthest direction stands 45 deg from both: alpha* = 45 deg exactly,
// certified, and the brute force agrees.
TEST(OptimalSlicingRational, SphereOctantAndTorusQuartersGiveFortyFiveDegrees) {
  const std::array<std::array<std::pair<double, double>, 3>, 3> profiles{{
      {{{2, 0}, {2, 2}, {0, 2}}},  // sphere of radius 2: equator to pole
      {{{4, 0}, {4, 1}, {3, 1}}},  // torus (3, 1), outer quarter
      {{{2, 0}, {2, 1}, {3, 1}}},  // torus (3, 1), inner quarter
  }};
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    SCOPED_TRACE("profile " + std::to_string(i));
    const Surface surface = quarterRevolution(profiles[i]);
    scallop::validateSurface(surface);
    const scallop::OptimalSlicing result = scallop::optimalSlicing(surface);
    EXPECT_NEAR(result.alphaRad / kDeg, 45.0, 1e-9);
    EXPECT_TRUE(result.certified);
    EXPECT_GE(result.certifiedAlphaRad / kDeg, 45.0 - 1e-3);
    EXPECT_LE(result.certifiedAlphaRad, result.alphaRad + 1e-15);
    EXPECT_NEAR(std::abs(result.normal.z), std::sqrt(0.5), 1e-6);
    expectAsGoodAsBruteForce(surface, 0.5);
  }
}

// Random rational graph patches (bicubic nets over a 3 x 3 footprint as the paper's, weights
// in [0.4, 2.5]): N* as good as the brute force over the same rational normals, certified,
// and the certificate's claim true on dense samples.
TEST(OptimalSlicingRational, RandomRationalGraphPatchesAgainstBruteForce) {
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> weight(0.4, 2.5);
  int tested = 0;
  while (tested < 6) {
    Surface s = randomGraphSurface(rng, tested % 2 == 0 ? 1.5 : 0.6, scallop::Units::inch);
    for (std::size_t k = 0; k < s.patches[0].control.size(); ++k) s.patches[0].weights.push_back(weight(rng));
    try {
      scallop::validateSurface(s);
    } catch (const scallop::Error&) {
      continue;
    }
    SCOPED_TRACE("rational patch " + std::to_string(tested));
    expectAsGoodAsBruteForce(s, 0.5);
    ++tested;
  }
}

// Equal weights are the polynomial patch: the same answer to rounding.
TEST(OptimalSlicingRational, EqualWeightsGiveThePolynomialAnswer) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    Surface polynomial = randomGraphSurface(rng, 1.5, scallop::Units::inch);
    Surface rational = polynomial;
    rational.patches[0].weights.assign(rational.patches[0].control.size(), 0.75);
    const scallop::OptimalSlicing a = scallop::optimalSlicing(polynomial), b = scallop::optimalSlicing(rational);
    EXPECT_NEAR(a.alphaRad, b.alphaRad, 1e-9);
    EXPECT_NEAR(std::abs(scallop::dot(a.normal, b.normal)), 1.0, 1e-9);
    EXPECT_EQ(a.certified, b.certified);
  }
}
