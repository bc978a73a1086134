// Optimal slicing (Gauss map -> stereographic plane -> medial axis -> eq 13 -> N*) against
// an independent brute force written here: dense surface normals, thousands of candidate
// directions, local refinement of the best ones.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "scallop/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/gauss_map.hpp"
#include "scallop/medial_axis.hpp"
#include "scallop/optimal_slicing.hpp"
#include "scallop/stereographic.hpp"
#include "scallop/surface.hpp"

namespace {

using scallop::BezierPatch;
using scallop::Surface;
using scallop::Vec2;
using scallop::Vec3;

constexpr double kDeg = std::numbers::pi / 180.0;

// Unit normals on an (n+1) x (n+1) grid of every patch.
std::vector<Vec3> sampleNormals(const Surface& s, int n) {
  std::vector<Vec3> out;
  for (const BezierPatch& p : s.patches) {
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) out.push_back(scallop::unitNormal(p, double(i) / n, double(j) / n));
    }
  }
  return out;
}

// The minimum angle between direction m and +-(the sampled normals).
double sampledAlpha(const std::vector<Vec3>& normals, const Vec3& m) {
  double worst = 0.0;
  for (const Vec3& n : normals) worst = std::max(worst, std::abs(scallop::dot(n, m)));
  return std::acos(std::min(1.0, worst));
}

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

TEST(OptimalSlicing, RandomGeneralPatches) {
  // Control nets that are not grids over the plane: every point moved in x, y and z.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.35, 0.35);
  std::uniform_real_distribution<double> height(0.0, 1.5);
  int tested = 0;
  while (tested < 3) {
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) p.control.push_back({k + jitter(rng), j + jitter(rng), height(rng)});
    }
    Surface s;
    s.patches.push_back(p);
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

TEST(OptimalSlicing, TwoPatchSurface) {
  // Two bicubic patches side by side, sharing their common boundary row (C0): the Gauss map
  // is the union of both patches' images.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> height(0.0, 1.2);
  double z[4][7];
  for (auto& row : z) {
    for (double& h : row) h = height(rng);
  }
  Surface s;
  for (int part = 0; part < 2; ++part) {
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) p.control.push_back({double(3 * part + k), double(j), z[j][3 * part + k]});
    }
    s.patches.push_back(p);
  }
  expectAsGoodAsBruteForce(s, 0.5);
}

TEST(OptimalSlicing, TwoPatchSurfaceWhoseGaussMapMissesNormals) {
  // A random two-patch surface (C0 along x = 3) on which the Gauss map at 0.5 degree misses
  // a region of normals near the corner (u, v) = (0, 1) of the second patch (2,640 of 40,803
  // sampled normals lie more than two tolerances inside the complement; each patch alone is
  // right): the medial axis's best circle claims 63.0 degrees, the true optimum is 57.82 at
  // about (0.526, 0.849, 0.055). The lattice seeds of the polish find it.
  const double z[4][7] = {{0.6753, 1.1909, 1.2780, 0.7642, 0.6671, 0.9258, 1.0888},
                          {0.3085, 1.3275, 1.3722, 0.5354, 0.0021, 1.1797, 0.2465},
                          {0.5283, 1.0242, 0.4930, 0.2316, 1.0166, 0.2580, 0.6747},
                          {0.8372, 0.5874, 1.4148, 0.6583, 1.4150, 1.4974, 1.2883}};
  Surface s;
  for (int part = 0; part < 2; ++part) {
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) p.control.push_back({double(3 * part + k), double(j), z[j][3 * part + k]});
    }
    s.patches.push_back(p);
  }
  expectAsGoodAsBruteForce(s, 0.5);
  EXPECT_GT(scallop::optimalSlicing(s).alphaRad, 57.8 * kDeg);
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
  // Issue item 7: as the Gauss map's tolerance shrinks (paper-1 down to 57,804 boundary
  // segments at 0.005 degree, where the map's polygon union leaves a zigzag that the
  // medial axis would reject; paper-2 to 3,490 at 0.02 degree, its Gauss map being slower;
  // the benchmark runs 100,000),
  // alpha* never decreases beyond rounding and converges to the brute force's value, and N*
  // converges (successive N* closer and closer).
  struct Case {
    const char* name;
    std::vector<double> tolerancesDeg;
    bool symmetric;
  };
  for (const Case& c : {Case{"paper-1", {1.0, 0.5, 0.2, 0.05, 0.005}, false},
                        Case{"paper-2", {1.0, 0.5, 0.2, 0.05, 0.02}, true}}) {
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
    EXPECT_GT(previousSegments, c.symmetric ? 3000u : 50000u);
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
  EXPECT_EQ(flat.method, "plane");
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

TEST(GaussMap, SampledNormalsAreInsideOmegaAndBoundaryIsNearThem) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const Surface s = scallop::exampleSurface(name);
    scallop::GaussMapOptions options;
    options.toleranceRad = 0.5 * kDeg;
    const scallop::GaussMap map = scallop::symmetrizedGaussMap(s, options);
    ASSERT_EQ(map.kind, scallop::GaussMapKind::region);
    ASSERT_FALSE(map.loops.empty());
    scallop::PlanarDomain domain;
    domain.loops = map.loops;
    // Every sampled normal (and its antipode) lies in Omega: not in the complement beyond
    // the polygon's tolerance (tol on the sphere is tol (1 + |p|^2) / 2 in the plane).
    const std::vector<Vec3> normals = sampleNormals(s, 40);
    for (const Vec3& n : normals) {
      for (double sign : {1.0, -1.0}) {
        const Vec3 r = scallop::apply(map.toPoleFrame, sign * n);
        if (r.z > 1.0 - 1e-12) continue;  // the pole itself (a surface normal by construction)
        const Vec2 q = scallop::stereographic(r);
        if (scallop::insideDomain(domain, q)) {
          EXPECT_LE(scallop::clearance(domain, q), 2.0 * options.toleranceRad * (1.0 + scallop::dot(q, q)) / 2.0)
              << "a surface normal lies in the complement";
        }
      }
    }
    // Membership agrees with the samples: every sampled normal is a member.
    for (std::size_t i = 0; i < normals.size(); i += 97) {
      EXPECT_TRUE(scallop::isSymmetrizedNormal(s, normals[i]));
      EXPECT_TRUE(scallop::isSymmetrizedNormal(s, -normals[i]));
    }
    // The boundary lies near the image: every boundary vertex is within a few tolerances
    // of a sampled normal (the samples are ~1.5 degrees apart at worst on these surfaces,
    // so the allowance is that spacing plus the tolerance).
    const std::vector<Vec3> fine = sampleNormals(s, 120);
    for (const auto& curve : map.sphereCurves) {
      for (std::size_t i = 0; i < curve.size(); i += 7) {
        double nearest = 10.0;
        for (const Vec3& n : fine) {
          nearest = std::min(nearest, std::acos(std::min(1.0, std::abs(scallop::dot(n, curve[i])))));
        }
        EXPECT_LE(nearest, 1.5 * kDeg + options.toleranceRad);
      }
    }
  }
}

TEST(OptimalSlicing, CertificateRejectsAnOverclaim) {
  const Surface s = scallop::exampleSurface("paper-2");
  const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
  std::size_t cells = 0;
  // Claiming one degree more than the true alpha must fail; one degree less must pass.
  EXPECT_FALSE(scallop::certifyClearance(s, result.normal, result.alphaRad + 1.0 * kDeg, cells));
  EXPECT_TRUE(scallop::certifyClearance(s, result.normal, result.alphaRad - 1.0 * kDeg, cells));
}

TEST(OptimalSlicing, RejectsBadTolerance) {
  const Surface s = scallop::exampleSurface("paper-1");
  for (double bad : {0.0, -1.0, std::nan(""), 10.0}) {
    scallop::OptimalSlicingOptions options;
    options.toleranceRad = bad * kDeg;
    EXPECT_THROW(scallop::optimalSlicing(s, options), scallop::Error);
  }
}

}  // namespace
