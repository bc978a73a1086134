// The symmetrized Gauss map against dense samples of the surface normals, written here:
// every sampled normal and its antipode must lie in Omega (or within one tolerance of its
// boundary, as the contract says), and Omega's boundary must lie near the sampled image's edge.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/slicing/gauss_map.hpp"
#include "scallop/slicing/medial_axis.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/slicing/stereographic.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/surface_io.hpp"
#include "support/corner_patches.hpp"
#include "support/gauss_references.hpp"

namespace {

using scallop::BezierPatch;
using scallop::Surface;
using scallop::Vec2;
using scallop::Vec3;

constexpr double kDeg = std::numbers::pi / 180.0;

using scallop::reference::sampleNormals;
using scallop::SlicingMethod;
// The angle between a direction and the nearest of +-(the sampled normals).
const auto angleToSamples = scallop::reference::sampledAlpha;

struct Check {
  std::size_t normals = 0;        // directions tested (each sample and its antipode)
  double worstDepthRad = 0.0;     // deepest tested direction inside the complement
  std::size_t boundaryChecked = 0;
  double worstOverreachRad = 0.0; // deepest bound d - gap on a sampled normal near the boundary
};

// Checks map against the surface's dense normals (n x n per patch):
// - depth: a normal (or its antipode) inside the complement lies within tol of the
//   boundary (the clearance in the plane over the projection's scale (1 + |q|^2) / 2 is the
//   angle on the sphere, to first order);
// - boundary near the image's edge: from each boundary vertex, the point c 2 tol further
//   into the complement (across the loop) is, where the complement is that wide there (its
//   clearance d at least tol: checkable), at least d - 1.5 tol from every sampled normal
//   (no normal near the boundary lies more than 1.5 tol inside the complement). Where the
//   loop runs straight d is 2 tol and the bound tol / 2; at a corner of the loop c sits
//   nearer both edges (a 90 degree corner: d = 1.41 tol), and the bound with it, since a
//   boundary within tol of the true image's edge keeps only d - tol clear of it there.
Check checkAgainstSamples(const Surface& s, const scallop::GaussMap& map, double tol, int n) {
  Check check;
  scallop::PlanarDomain domain;
  domain.loops = map.loops;
  // Independent of bezier.hpp, and with rays into every corner (the arc of limits where
  // r_u x r_v vanishes at one).
  const std::vector<Vec3> normals = scallop::reference::sampleRegularNormals(s, n);
  auto depthOf = [&](const Vec3& m) {
    const Vec3 r = scallop::apply(map.toPoleFrame, m);
    if (r.z > 1.0 - 1e-12) return 0.0;  // the pole: a normal by construction
    const Vec2 q = scallop::stereographic(r);
    if (!scallop::insideDomain(domain, q)) return 0.0;
    return scallop::clearance(domain, q) / (0.5 * (1.0 + scallop::dot(q, q)));
  };
  std::size_t deep = 0;
  for (const Vec3& normal : normals) {
    for (double sign : {1.0, -1.0}) {
      const double depth = depthOf(sign * normal);
      ++check.normals;
      check.worstDepthRad = std::max(check.worstDepthRad, depth);
      deep += depth > tol ? 1 : 0;
    }
  }
  EXPECT_EQ(deep, 0u) << "of " << check.normals << " sampled normals lie more than one tolerance "
                      << "inside the complement of Omega, the deepest " << check.worstDepthRad / kDeg << " deg";
  std::size_t overreaching = 0;
  const scallop::Rotation3 back = scallop::transpose(map.toPoleFrame);
  for (const auto& loop : map.loops) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec3 b = scallop::apply(back, scallop::inverseStereographic(loop[i]));
      const Vec3 next = scallop::apply(back, scallop::inverseStereographic(loop[(i + 1) % loop.size()]));
      const Vec3 prev = scallop::apply(back, scallop::inverseStereographic(loop[(i + loop.size() - 1) % loop.size()]));
      const Vec3 side = scallop::cross(b, next - prev);
      if (!(scallop::norm(side) > 0.0)) continue;
      const Vec3 across = scallop::normalized(side);
      for (double sign : {1.0, -1.0}) {
        const Vec3 c = std::cos(2.0 * tol) * b + std::sin(2.0 * tol) * (sign * across);
        const double depth = depthOf(c);
        if (depth < tol) continue;  // not in the complement, or not clearly: unchecked
        ++check.boundaryChecked;
        // A normal within `gap` of c lies at least depth - gap inside the complement.
        const double gap = angleToSamples(normals, c);
        check.worstOverreachRad = std::max(check.worstOverreachRad, depth - gap);
        overreaching += depth - gap > 1.5 * tol ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(overreaching, 0u) << "of " << check.boundaryChecked << " boundary points checked lie "
                              << "near a sampled normal more than 1.5 tolerances inside the "
                              << "complement, the deepest " << check.worstOverreachRad / kDeg << " deg";
  return check;
}

// One patch from a 4 x 4 window of a control net.
BezierPatch window(const std::vector<std::vector<Vec3>>& net, int row, int column) {
  BezierPatch p;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) p.control.push_back(net[row + j][column + k]);
  }
  return p;
}

// Random multi-patch surfaces of four layouts: a row of patches sharing boundary rows (C0)
// or apart, over a grid footprint (graph-like) or with every control point moved in x and y
// too (general); heights in [0, 1.2]. Returns false when a patch is not regular.
bool randomSurface(std::mt19937_64& rng, int patches, bool joined, bool general, Surface& s) {
  std::uniform_real_distribution<double> height(0.0, 1.2);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  s = Surface{};
  if (joined) {
    std::vector<std::vector<Vec3>> net(4, std::vector<Vec3>(static_cast<std::size_t>(3 * patches + 1)));
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3 * patches; ++k) {
        const double dx = general ? jitter(rng) : 0.0, dy = general ? jitter(rng) : 0.0;
        net[j][static_cast<std::size_t>(k)] = {k + dx, j + dy, height(rng)};
      }
    }
    for (int p = 0; p < patches; ++p) s.patches.push_back(window(net, 0, 3 * p));
  } else {
    for (int p = 0; p < patches; ++p) {
      std::vector<std::vector<Vec3>> net(4, std::vector<Vec3>(4));
      for (int j = 0; j <= 3; ++j) {
        for (int k = 0; k <= 3; ++k) {
          const double dx = general ? jitter(rng) : 0.0, dy = general ? jitter(rng) : 0.0;
          net[j][k] = {4.0 * p + k + dx, j + dy, height(rng)};
        }
      }
      s.patches.push_back(window(net, 0, 0));
    }
  }
  try {
    scallop::validateSurface(s);
  } catch (const scallop::Error&) {
    return false;
  }
  return true;
}

const auto twoPatchSurface = scallop::reference::twoPatchRegressionSurface;

scallop::GaussMap mapAt(const Surface& s, double tol) {
  scallop::GaussMapOptions options;
  options.toleranceRad = tol;
  return scallop::symmetrizedGaussMap(s, options);
}

TEST(GaussMap, SampledNormalsAreInsideOmegaAndBoundaryIsNearThem) {
  for (const char* name : {"paper-1", "paper-2"}) {
    SCOPED_TRACE(name);
    const Surface s = scallop::exampleSurface(name);
    const double tol = 0.5 * kDeg;
    const scallop::GaussMap map = mapAt(s, tol);
    ASSERT_EQ(map.kind, scallop::GaussMapKind::region);
    ASSERT_FALSE(map.loops.empty());
    const Check check = checkAgainstSamples(s, map, tol, 60);
    EXPECT_GT(check.boundaryChecked, 100u);
    // Membership agrees with the samples: every sampled normal is a member.
    const std::vector<Vec3> normals = sampleNormals(s, 40);
    for (std::size_t i = 0; i < normals.size(); i += 97) {
      EXPECT_TRUE(scallop::isSymmetrizedNormal(s, normals[i]));
      EXPECT_TRUE(scallop::isSymmetrizedNormal(s, -normals[i]));
    }
    // Every boundary vertex lies within a few tolerances of a sampled normal (the samples
    // are ~1.5 degrees apart at worst on these surfaces: that spacing plus the tolerance).
    const std::vector<Vec3> fine = sampleNormals(s, 120);
    for (const auto& curve : map.sphereCurves) {
      for (std::size_t i = 0; i < curve.size(); i += 7) {
        EXPECT_LE(angleToSamples(fine, curve[i]), 1.5 * kDeg + tol);
      }
    }
  }
}

TEST(GaussMap, TwoPatchSurfaceKeepsEveryNormal) {
  const Surface s = twoPatchSurface();
  for (double tolDeg : {1.0, 0.5, 0.2}) {
    SCOPED_TRACE("tolerance " + std::to_string(tolDeg) + " deg");
    const scallop::GaussMap map = mapAt(s, tolDeg * kDeg);
    ASSERT_EQ(map.kind, scallop::GaussMapKind::region);
    const Check check = checkAgainstSamples(s, map, tolDeg * kDeg, 100);
    // The polygon is within one tolerance of the true boundary; the samples add nothing.
    EXPECT_LE(check.worstDepthRad, tolDeg * kDeg);
    std::cout << "two-patch surface at " << tolDeg << " deg: " << check.normals
              << " normals, worst depth " << check.worstDepthRad / kDeg << " deg; "
              << check.boundaryChecked << " boundary points checked\n";
  }
}

TEST(GaussMap, RandomMultiPatchSurfacesKeepEveryNormal) {
  // 2 to 4 patches, C0-joined or apart, graph-like or general; fixed seed.
  std::mt19937_64 rng(2024);
  const double tol = 0.5 * kDeg;
  int surfaces = 0;
  std::size_t normals = 0, boundary = 0;
  double worst = 0.0;
  for (int attempt = 0; surfaces < 16 && attempt < 200; ++attempt) {
    const int patches = 2 + surfaces % 3;
    const bool joined = (surfaces / 2) % 2 == 0;
    const bool general = surfaces % 2 == 1;
    Surface s;
    if (!randomSurface(rng, patches, joined, general, s)) continue;  // a net folding over
    SCOPED_TRACE("surface " + std::to_string(surfaces) + ": " + std::to_string(patches) +
                 " patches, " + (joined ? "C0-joined" : "apart") + ", " + (general ? "general" : "graph"));
    const scallop::GaussMap map = mapAt(s, tol);
    ASSERT_EQ(map.kind, scallop::GaussMapKind::region);
    const Check check = checkAgainstSamples(s, map, tol, 40);
    normals += check.normals;
    boundary += check.boundaryChecked;
    worst = std::max(worst, check.worstDepthRad);
    ++surfaces;
  }
  EXPECT_EQ(surfaces, 16);
  std::cout << surfaces << " random surfaces: " << normals << " normals, worst depth "
            << worst / kDeg << " deg; " << boundary << " boundary points checked\n";
}

// Random patches with singular corners (tests/support/corner_patches.hpp), alone and three side by
// side: the arcs of the normal's limits at the corners (rays sampled 1e-6 inside) and every
// other sampled normal lie in Omega, and membership says yes to them.
TEST(GaussMap, SingularCornerPatchesKeepEveryNormal) {
  std::mt19937_64 rng(11);
  const double tol = 0.5 * kDeg;
  int surfaces = 0;
  std::size_t normals = 0;
  double worst = 0.0;
  for (int attempt = 0; surfaces < 40 && attempt < 200; ++attempt) {
    Surface s;
    for (int i = 0; i < (surfaces % 4 == 3 ? 3 : 1); ++i) {
      BezierPatch patch = scallop::test::randomCorneredPatch(rng).patch;
      for (Vec3& p : patch.control) p.x += 5.0 * i;
      s.patches.push_back(std::move(patch));
    }
    try {
      scallop::validateSurface(s);
    } catch (const scallop::Error&) {
      continue;  // folds inside
    }
    SCOPED_TRACE("surface " + std::to_string(surfaces));
    const scallop::GaussMap map = mapAt(s, tol);
    ASSERT_EQ(map.kind, scallop::GaussMapKind::region);
    const Check check = checkAgainstSamples(s, map, tol, 40);
    normals += check.normals;
    worst = std::max(worst, check.worstDepthRad);
    // Membership at interior points (on an edge, a sample's own rounding can put it a hair
    // outside the patch's normals) and on rays 1e-6 into each corner.
    std::uniform_real_distribution<double> inside(1e-3, 1.0 - 1e-3), angle(0.01, 0.5 * std::numbers::pi - 0.01);
    for (const BezierPatch& patch : s.patches) {
      for (int i = 0; i < 8; ++i) {
        const int corner = i % 4;
        const double u0 = (corner & 1) ? 1.0 : 0.0, v0 = (corner & 2) ? 1.0 : 0.0, theta = angle(rng);
        const double u = i < 4 ? inside(rng) : u0 + (1.0 - 2.0 * u0) * 1e-6 * std::cos(theta);
        const double v = i < 4 ? inside(rng) : v0 + (1.0 - 2.0 * v0) * 1e-6 * std::sin(theta);
        const Vec3 normal = scallop::normalized(scallop::cross(scallop::derivativeU(patch, u, v), scallop::derivativeV(patch, u, v)));
        EXPECT_TRUE(scallop::isSymmetrizedNormal(s, normal)) << "(" << u << ", " << v << ")";
        EXPECT_TRUE(scallop::isSymmetrizedNormal(s, -normal)) << "(" << u << ", " << v << ")";
      }
    }
    ++surfaces;
  }
  EXPECT_EQ(surfaces, 40);
  std::cout << surfaces << " surfaces with singular corners: " << normals << " normals, worst depth "
            << worst / kDeg << " deg\n";
}

// The angle from m to the nearest point of the polylines `curves` (on the sphere; chords
// for angles, equal to 1e-8 relative at these sizes), brute force.
double angleToCurves(const std::vector<std::vector<Vec3>>& curves, const Vec3& m) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& curve : curves) {
    for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
      best = std::min(best, scallop::distanceToSegment(m, curve[i], curve[i + 1]));
    }
  }
  return best;
}

TEST(GaussMap, CoarseBandKeepsTheFineMap) {
  // At a tolerance fine enough for the band (3e-4 degree), the map with curves deep inside
  // Omega sampled coarsely against the map sampled to the tolerance everywhere: the same
  // boundary (each within the tolerance of the true one: within 2 tolerances of each
  // other; every third vertex checked) and the sampled normals all inside. Single patches
  // (the paper's, a random one) and multi-patch surfaces with seams (C0-joined) and without.
  const double tol = 3e-4 * kDeg;
  std::vector<std::pair<std::string, Surface>> cases{
      {"paper-1", scallop::exampleSurface("paper-1")},
      {"paper-2", scallop::exampleSurface("paper-2")},
      {"two-patch", twoPatchSurface()}};
  std::mt19937_64 rng(77);
  for (int attempt = 0; cases.size() < 7 && attempt < 100; ++attempt) {
    const int layout = static_cast<int>(cases.size()) - 3;  // 0 .. 3
    Surface s;
    const int patches = layout == 0 ? 1 : 2 + layout % 2;
    if (!randomSurface(rng, patches, layout >= 2, layout % 2 == 1, s)) continue;
    cases.emplace_back("random " + std::to_string(patches) + " patches, layout " + std::to_string(layout), s);
  }
  ASSERT_EQ(cases.size(), 7u);
  for (const auto& [name, s] : cases) {
    SCOPED_TRACE(name);
    scallop::GaussMapOptions options;
    options.toleranceRad = tol;
    const scallop::GaussMap banded = scallop::symmetrizedGaussMap(s, options);
    options.coarseBand = false;
    const scallop::GaussMap full = scallop::symmetrizedGaussMap(s, options);
    ASSERT_EQ(banded.kind, scallop::GaussMapKind::region);
    ASSERT_EQ(full.kind, scallop::GaussMapKind::region);
    EXPECT_TRUE(banded.coarseBandUsed);
    EXPECT_FALSE(full.coarseBandUsed);
    EXPECT_EQ(banded.loops.size(), full.loops.size());
    double worst = 0.0;
    for (const auto& [from, to] : {std::pair{&banded, &full}, std::pair{&full, &banded}}) {
      for (const auto& curve : from->sphereCurves) {
        for (std::size_t i = 0; i < curve.size(); i += 3) worst = std::max(worst, angleToCurves(to->sphereCurves, curve[i]));
      }
    }
    EXPECT_LE(worst, 2.0 * tol);
    checkAgainstSamples(s, banded, tol, 30);
    std::cout << name << ": " << banded.boundarySegments << " / " << full.boundarySegments
              << " boundary segments (band / full), " << banded.imageVertices << " / "
              << full.imageVertices << " image vertices, boundaries "
              << worst / tol << " tolerances apart\n";
  }
}

// A random curved graph patch over [0, 3]^2 and a developable patch beside it with unit
// normal `normal` at its middle: a plane, or a cylinder-like patch bent along one tangent,
// whose normals sweep an arc of a great circle through `normal` (about +-65 degrees).
Surface curvedWithDevelopable(bool cylinder, const Vec3& normal) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> height(0.0, 1.2);
  BezierPatch curved;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) curved.control.push_back({double(k), double(j), height(rng)});
  }
  const Vec3 along = scallop::normalized(scallop::cross(normal, {0.3, 0.2, 0.9}));
  const Vec3 across = scallop::cross(normal, along);
  const double bend[4] = {0.0, 0.8, -0.3, 0.6};
  BezierPatch developable;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) {
      developable.control.push_back(Vec3{5.0, 5.0, 0.0} + (k / 3.0) * along + (j / 3.0) * across +
                                    (cylinder ? bend[k] : 0.0) * normal);
    }
  }
  Surface s;
  s.patches = {curved, developable};
  return s;
}

TEST(GaussMap, DevelopablePatchAmongCurvedOnesIsInOmega) {
  for (bool cylinder : {false, true}) {
    SCOPED_TRACE(cylinder ? "cylinder-like patch" : "planar patch");
    // A nearly horizontal normal: the curved patch's normals are within ~55 degrees of the
    // vertical.
    const Surface s = curvedWithDevelopable(cylinder, scallop::normalized({0.05, -1.0, 0.1}));
    for (double tolDeg : {0.5, 0.1}) {
      const double tol = tolDeg * kDeg;
      const scallop::GaussMap map = mapAt(s, tol);
      ASSERT_EQ(map.kind, scallop::GaussMapKind::region);
      // The developable patch's normals stick out of the curved patch's image...
      Surface curvedOnly;
      curvedOnly.patches = {s.patches[0]};
      const std::vector<Vec3> curvedNormals = sampleNormals(curvedOnly, 60);
      EXPECT_GT(angleToSamples(curvedNormals, scallop::unitNormal(s.patches[1], 0.5, 0.5)), 10.0 * kDeg);
      // ...and are in Omega all the same, with the curved patch's.
      const Check check = checkAgainstSamples(s, map, tol, 60);
      EXPECT_LE(check.worstDepthRad, tol);
      EXPECT_GT(check.boundaryChecked, 50u);
      std::cout << (cylinder ? "cylinder-like" : "planar") << " patch among curved, " << tolDeg
                << " deg: " << check.normals << " normals, worst depth "
                << check.worstDepthRad / kDeg << " deg\n";
    }
  }
}

TEST(GaussMap, RejectsBadInput) {
  const Surface s = scallop::exampleSurface("paper-1");
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity(),
                     0.5 * scallop::kMinGaussMapToleranceRad}) {
    scallop::GaussMapOptions options;
    options.toleranceRad = bad;
    EXPECT_THROW(scallop::symmetrizedGaussMap(s, options), scallop::Error);
  }
  EXPECT_THROW(scallop::symmetrizedGaussMap(Surface{}), scallop::Error);
  for (int bad : {0, -3, 41}) {
    scallop::GaussMapOptions options;
    options.maxCellDepth = bad;
    try {
      scallop::symmetrizedGaussMap(s, options);
      ADD_FAILURE() << "no error for maxCellDepth " << bad;
    } catch (const scallop::Error& e) {
      EXPECT_NE(std::string(e.what()).find("got " + std::to_string(bad)), std::string::npos) << e.what();
    }
  }
}

}  // namespace

namespace {

// The Utah teapot (its example file): every patch and the open groups, the map that orient
// uses (retried with the pole off its cell's centre when the first came out empty), against
// dense normals. Surfaces of revolution, parabolic lines along edges and iso-lines, apexes.
TEST(GaussMap, TeapotMapsKeepEveryNormal) {
  const Surface whole =
      scallop::readSurface(std::string(SCALLOP_EXAMPLES_DIR) + "/surfaces/teapot.json");
  const double tol = 0.5 * kDeg;
  std::size_t normals = 0;
  double worst = 0.0;
  auto check = [&](const Surface& s, const std::string& name) {
    SCOPED_TRACE(name);
    const scallop::OptimalSlicing result = scallop::optimalSlicing(s);
    ASSERT_EQ(result.method, SlicingMethod::medialAxis);
    const Check c = checkAgainstSamples(s, result.gaussMap, tol, 60);
    normals += c.normals;
    worst = std::max(worst, c.worstDepthRad);
  };
  for (std::size_t i = 0; i < whole.patches.size(); ++i) {
    check(Surface{whole.units, {whole.patches[i]}}, "patch " + std::to_string(i));
  }
  Surface body{whole.units, {}}, handle{whole.units, {}};
  for (std::size_t i = 4; i < 12; ++i) body.patches.push_back(whole.patches[i]);
  for (std::size_t i = 12; i < 16; ++i) handle.patches.push_back(whole.patches[i]);
  check(body, "body");
  check(handle, "handle");
  std::cout << "teapot: " << normals << " normals, worst depth " << worst / kDeg << " deg\n";
}

}  // namespace
