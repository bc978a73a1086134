// The mesh drop-cutter (mesh_drop.hpp) against references written here, independently of
// the library's closed forms:
//   - the distance from a point to a triangle by minimising |p - q(u, v)|^2 over the simplex
//     (the 2 x 2 normal equations inside, each edge's clamped 1D minimum, the vertices);
//   - the drop height over one triangle by bisection on z of "the ball centred at (x, y, z)
//     is within R of the triangle" (the set of such z is an interval, the distance being
//     convex in z), bracketed by the triangle's point nearest the vertical line (found the
//     same way with z weighted 0) and its highest vertex + R;
//   - the distance from a segment to a triangle by ternary search over the segment (the
//     distance to a convex set is convex along a line), and to the mesh as the minimum.
// Cases (fixed seeds):
//   MeshDrop.RandomHeightfields      drops on 12 random heightfield triangulations, 4,000 points
//   MeshDrop.RandomSoups             random triangle soups with vertical and sliver triangles
//   MeshDrop.ClosedForms             flat square (plane + R), a spike (vertex sphere), a ridge
//                                    (horizontal edge: a circle across it), nothing within R
//   MeshDrop.SegmentDistance         segments near random meshes against the reference, the
//                                    cutoff, crossing segments at 0, segmentClear agreeing
//   MeshDrop.DropLine                every move sampled densely stays R - eps clear, every
//                                    vertex touches and is the reference drop; deterministic
//   MeshDrop.OpenCamLibParts         OpenCAMLib's STL parts (from a fetched mirror, not
//                                    committed: skipped when absent) on a grid against the
//                                    reference
//   MeshDrop.BadInput                R <= 0, NaN, an empty mesh, bad indices, bad line options

#include "scallop/paths/mesh_drop.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "support/mesh_fixtures.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/mesh.hpp"

namespace {

using scallop::DropLine;
using scallop::DropLineOptions;
using scallop::Mesh;
using scallop::MeshContact;
using scallop::MeshDropCutter;
using scallop::MeshFeature;
using scallop::Vec2;
using scallop::Vec3;

constexpr double kInf = std::numeric_limits<double>::infinity();

using Tri = std::array<Vec3, 3>;

Tri triangle(const Mesh& m, std::size_t t) {
  return {m.vertices[m.triangles[t][0]], m.vertices[m.triangles[t][1]], m.vertices[m.triangles[t][2]]};
}

// The point of the triangle minimising |W (q - p)|^2, W = diag(1, 1, wz): the simplex
// q = a + u (b - a) + v (c - a), u, v >= 0, u + v <= 1. A convex quadratic: its minimum is
// the interior stationary point when that is feasible, else on an edge (clamped 1D minimum).
Vec3 nearestPoint(Vec3 p, const Tri& t, double wz) {
  const auto w = [&](Vec3 d) { return Vec3{d.x, d.y, wz * d.z}; };
  const Vec3 e1 = w(t[1] - t[0]);
  const Vec3 e2 = w(t[2] - t[0]);
  const Vec3 r = w(p - t[0]);
  const double a11 = dot(e1, e1), a12 = dot(e1, e2), a22 = dot(e2, e2);
  const double b1 = dot(e1, r), b2 = dot(e2, r);
  const double det = a11 * a22 - a12 * a12;
  if (det > 1e-14 * a11 * a22) {
    const double u = (b1 * a22 - b2 * a12) / det;
    const double v = (a11 * b2 - a12 * b1) / det;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0) return t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
  }
  Vec3 best = t[0];
  double bestD = kInf;
  for (int i = 0; i < 3; ++i) {
    const Vec3 a = t[i];
    const Vec3 b = t[(i + 1) % 3];
    const Vec3 d = w(b - a);
    const double len2 = dot(d, d);
    const double s = len2 > 0.0 ? std::clamp(dot(w(p - a), d) / len2, 0.0, 1.0) : 0.0;
    const Vec3 q = a + s * (b - a);
    const Vec3 diff = w(p - q);
    const double dd = dot(diff, diff);
    if (dd < bestD) {
      bestD = dd;
      best = q;
    }
  }
  return best;
}

double pointTriangle(Vec3 p, const Tri& t) { return norm(p - nearestPoint(p, t, 1.0)); }

double pointMesh(Vec3 p, const Mesh& m) {
  double d = kInf;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) d = std::min(d, pointTriangle(p, triangle(m, t)));
  return d;
}

// The drop height over one triangle by bisection (see the file's comment); -inf when no
// point of it lies within R horizontally.
double referenceDropTriangle(double x, double y, const Tri& t, double r) {
  const Vec3 q = nearestPoint({x, y, 0.0}, t, 0.0);
  if (std::hypot(q.x - x, q.y - y) > r) return -kInf;
  double lo = q.z;  // the centre there is within R: inside the interval
  double hi = std::max({t[0].z, t[1].z, t[2].z}) + r + 1.0;
  for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (pointTriangle({x, y, mid}, t) <= r ? lo : hi) = mid;
  }
  return lo;
}

double referenceDrop(double x, double y, const Mesh& m, double r) {
  double z = -kInf;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) z = std::max(z, referenceDropTriangle(x, y, triangle(m, t), r));
  return z;
}

// The distance from [a, b] to one triangle by ternary search (convex along the segment).
double referenceSegmentTriangle(Vec3 a, Vec3 b, const Tri& t) {
  double lo = 0.0, hi = 1.0;
  const auto f = [&](double s) { return pointTriangle(a + s * (b - a), t); };
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    if (f(m1) <= f(m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  return std::min({f(0.0), f(1.0), f(0.5 * (lo + hi))});
}

double referenceSegmentMesh(Vec3 a, Vec3 b, const Mesh& m) {
  double d = kInf;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) d = std::min(d, referenceSegmentTriangle(a, b, triangle(m, t)));
  return d;
}

double meshSize(const Mesh& m) {
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  for (const Vec3& p : m.vertices) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  return norm(hi - lo);
}

// An n x n heightfield over [0, n]^2, random heights in [0, amp], each cell cut along a
// random diagonal.
Mesh heightfield(std::mt19937_64& rng, int n, double amp) {
  std::uniform_real_distribution<double> h(0.0, amp);
  return scallop::test::gridMesh(static_cast<std::size_t>(n), double(n), [&](double, double) { return h(rng); }, rng, true);
}

// A soup of n triangles in [0, 4]^2 x [0, 2]: general ones, vertical ones (the three
// vertices over one line in xy), slivers (the third vertex 1e-9 off the first edge) and
// some with both vertex orders.
Mesh soup(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Mesh m;
  const auto point = [&] { return Vec3{4.0 * u(rng), 4.0 * u(rng), 2.0 * u(rng)}; };
  for (int k = 0; k < n; ++k) {
    const Vec3 a = point();
    Vec3 b = point();
    Vec3 c = point();
    const int kind = k % 4;
    if (kind == 1) {  // vertical
      const double s = u(rng);
      c = {a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), 2.0 * u(rng)};
      if (std::fabs(c.z - (a.z + s * (b.z - a.z))) < 0.1) c.z += 0.5;
    } else if (kind == 2) {  // sliver
      const double s = u(rng);
      c = a + s * (b - a) + Vec3{1e-9, -1e-9, 1e-9};
    } else if (kind == 3) {
      std::swap(b, c);
    }
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {a, b, c});
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

struct Worst {
  double diff = 0.0;
  double x = 0.0, y = 0.0;
  void add(double d, double px, double py) {
    if (d > diff) *this = {d, px, py};
  }
};

// Drops at random points over the mesh's footprint grown by R against the reference.
Worst compareDrops(const Mesh& m, double r, int points, std::mt19937_64& rng, double tol) {
  const MeshDropCutter cutter(m, r);
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  for (const Vec3& p : m.vertices) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), 0.0};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), 0.0};
  }
  std::uniform_real_distribution<double> ux(lo.x - r, hi.x + r), uy(lo.y - r, hi.y + r);
  Worst worst;
  int failures = 0;
  for (int i = 0; i < points; ++i) {
    const double x = ux(rng), y = uy(rng);
    const MeshContact c = cutter.drop(x, y);
    const double ref = referenceDrop(x, y, m, r);
    if (ref == -kInf || c.z == -kInf) {
      if (ref != c.z && ++failures <= 5)
        ADD_FAILURE() << "at (" << x << ", " << y << "): drop " << c.z << ", reference " << ref;
      continue;
    }
    EXPECT_NE(c.feature, MeshFeature::none);
    const double d = std::fabs(c.z - ref);
    worst.add(d, x, y);
    if (d > tol && ++failures <= 5)
      ADD_FAILURE() << "at (" << x << ", " << y << "): drop " << c.z << ", reference " << ref
                    << ", difference " << d;
  }
  return worst;
}

TEST(MeshDrop, RandomHeightfields) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> radius(0.1, 2.0), amp(0.1, 3.0);
  Worst worst;
  for (int k = 0; k < 12; ++k) {
    const Mesh m = heightfield(rng, 4 + k % 5, amp(rng));
    const double size = meshSize(m);
    const Worst w = compareDrops(m, radius(rng), 350, rng, 1e-12 * size);
    worst.add(w.diff / size, w.x, w.y);
  }
  std::printf("heightfields: worst |drop - reference| = %.3g of the mesh size\n", worst.diff);
}

TEST(MeshDrop, RandomSoups) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> radius(0.05, 1.5);
  Worst worst;
  for (int k = 0; k < 8; ++k) {
    const Mesh m = soup(rng, 12 + 6 * k);
    const double size = meshSize(m);
    const Worst w = compareDrops(m, radius(rng), 400, rng, 1e-11 * size);
    worst.add(w.diff / size, w.x, w.y);
  }
  std::printf("soups: worst |drop - reference| = %.3g of the mesh size\n", worst.diff);
}

TEST(MeshDrop, ClosedForms) {
  // A flat square at z = 1: plane + R everywhere over it, R n_z = R.
  Mesh flat;
  flat.vertices = {{0, 0, 1}, {4, 0, 1}, {4, 4, 1}, {0, 4, 1}};
  flat.triangles = {{0, 1, 2}, {0, 2, 3}};
  const MeshDropCutter square(flat, 0.5);
  for (double x : {0.5, 1.0, 2.0, 3.5})
    for (double y : {0.5, 1.7, 3.5}) {
      const MeshContact c = square.drop(x, y);
      EXPECT_DOUBLE_EQ(c.z, 1.5);
      EXPECT_EQ(c.feature, MeshFeature::facet);
    }
  // Beyond the corner by d in both axes: the vertex, 1 + sqrt(R^2 - 2 d^2).
  EXPECT_NEAR(square.drop(4.2, 4.2).z, 1.0 + std::sqrt(0.25 - 0.08), 1e-14);
  EXPECT_EQ(square.drop(4.2, 4.2).feature, MeshFeature::vertex);
  // Beyond an edge by d: 1 + sqrt(R^2 - d^2) (the edge's circle).
  EXPECT_NEAR(square.drop(2.0, 4.3).z, 1.0 + std::sqrt(0.25 - 0.09), 1e-14);
  EXPECT_EQ(square.drop(2.0, 4.3).feature, MeshFeature::edge);
  EXPECT_EQ(square.drop(5.0, 2.0).z, -kInf);
  EXPECT_EQ(square.drop(5.0, 2.0).feature, MeshFeature::none);

  // A spike: apex (0, 0, 10) over a base of radius 0.1 at z = 0. Its sides are within 0.6
  // degrees of vertical: a ball of R = 1 rests on the apex while d <= 0.9.
  Mesh spike;
  spike.vertices.push_back({0, 0, 10});
  for (int k = 0; k < 6; ++k)
    spike.vertices.push_back({0.1 * std::cos(k * M_PI / 3), 0.1 * std::sin(k * M_PI / 3), 0});
  for (std::uint32_t k = 0; k < 6; ++k) spike.triangles.push_back({0, 1 + k, 1 + (k + 1) % 6});
  const MeshDropCutter needle(spike, 1.0);
  for (double d : {0.0, 0.2, 0.5, 0.9}) {
    const MeshContact c = needle.drop(d * 0.6, d * 0.8);
    EXPECT_NEAR(c.z, 10.0 + std::sqrt(1.0 - d * d), 1e-14) << d;
    EXPECT_EQ(c.feature, MeshFeature::vertex);
    EXPECT_EQ(c.vertices[0], 0u);
  }

  // A ridge along x at y = 0, z = 5, falling to z = 0 at y = +-0.05: the ball R = 1 rests on
  // the ridge line, its section a circle: z = 5 + sqrt(1 - y^2).
  Mesh ridge;
  ridge.vertices = {{-10, 0, 5}, {10, 0, 5}, {-10, 0.05, 0}, {10, 0.05, 0}, {-10, -0.05, 0}, {10, -0.05, 0}};
  ridge.triangles = {{0, 1, 3}, {0, 3, 2}, {0, 5, 1}, {0, 4, 5}};
  const MeshDropCutter tent(ridge, 1.0);
  for (double y : {-0.9, -0.3, 0.0, 0.4, 0.95})
    for (double x : {-8.0, 0.0, 3.3}) {
      const MeshContact c = tent.drop(x, y);
      EXPECT_NEAR(c.z, 5.0 + std::sqrt(1.0 - y * y), 1e-14) << x << ", " << y;
      EXPECT_EQ(c.feature, MeshFeature::edge);
    }
  // A sloped edge alone (a vertical triangle under it): its ellipse, z = z(t) + r / cos.
  Mesh slope;
  slope.vertices = {{0, 0, 0}, {10, 0, 5}, {5, 0, -20}};
  slope.triangles = {{0, 1, 2}};
  const MeshDropCutter ramp(slope, 1.0);
  const double secTheta = std::hypot(10.0, 5.0) / 10.0;
  for (double y : {0.0, 0.5}) {
    const double x = 5.0;
    EXPECT_NEAR(ramp.drop(x, y).z, 0.5 * x + std::sqrt(1.0 - y * y) * secTheta, 1e-13);
    EXPECT_EQ(ramp.drop(x, y).feature, MeshFeature::edge);
  }
}

TEST(MeshDrop, SegmentDistance) {
  std::mt19937_64 rng(11);
  double worst = 0.0;
  int cases = 0;
  for (int k = 0; k < 6; ++k) {
    const Mesh m = k % 2 == 0 ? heightfield(rng, 4, 2.0) : soup(rng, 16);
    const double r = 0.5;
    const MeshDropCutter cutter(m, r);
    std::uniform_real_distribution<double> ux(-0.5, 4.5), uz(-0.5, 3.5), len(0.0, 2.0);
    std::normal_distribution<double> dir(0.0, 1.0);
    for (int i = 0; i < 60; ++i) {
      const Vec3 a{ux(rng), ux(rng), uz(rng)};
      const Vec3 d{dir(rng), dir(rng), dir(rng)};
      const Vec3 b = i % 10 == 0 ? a : a + (len(rng) / norm(d)) * d;
      const double got = cutter.segmentDistance(a, b);
      const double ref = referenceSegmentMesh(a, b, m);
      const double diff = std::fabs(got - ref);
      worst = std::max(worst, diff);
      EXPECT_LE(diff, 1e-9) << "segment " << i << " of mesh " << k << ": " << got << " vs " << ref;
      // The cutoff: exact below it, the cutoff above.
      const double cut = 0.3;
      EXPECT_EQ(cutter.segmentDistance(a, b, cut), ref < cut - 1e-9 ? got : cut) << i;
      // segmentClear agrees away from the threshold.
      if (ref > 0.3 + 1e-9) {
        EXPECT_TRUE(cutter.segmentClear(a, b, 0.3));
      }
      if (ref < 0.3 - 1e-9) {
        EXPECT_FALSE(cutter.segmentClear(a, b, 0.3));
      }
      ++cases;
    }
  }
  // A segment through a facet's interior: 0.
  Mesh flat;
  flat.vertices = {{0, 0, 1}, {4, 0, 1}, {4, 4, 1}};
  flat.triangles = {{0, 1, 2}};
  const MeshDropCutter one(flat, 1.0);
  EXPECT_EQ(one.segmentDistance({3, 1, 0}, {3, 1.5, 2}), 0.0);
  EXPECT_NEAR(one.segmentDistance({3, 1, 1.5}, {3.5, 1, 3}), 0.5, 1e-15);
  std::printf("segment distance: %d segments, worst |distance - reference| = %.3g\n", cases, worst);
}

// Every move of a drop line sampled at `samples` points keeps the reference distance
// >= R - eps; every vertex touches (reference distance <= R) unless on the floor, and its
// height is the reference drop: within 1e-11 of the size, or, where the ball touches at its
// equator (a contact at horizontal distance R, where Z is vertical), within the rounding bound
// of the contract there, sqrt(16 u S R): one unit of rounding in d moves sqrt(R^2 - d^2) by that.
void checkDropLine(const Mesh& m, const MeshDropCutter& cutter, const DropLine& line, int samples) {
  const double r = cutter.radius();
  const double tiny = 1e-12 * cutter.meshSize();
  double worstDepth = 0.0, worstVertex = 0.0;
  double scale = 0.0;
  for (const Vec3& p : m.vertices) scale = std::max({scale, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  const double equator = std::sqrt(16.0 * 0x1p-53 * (scale + 10.0) * r);
  int atEquator = 0;
  EXPECT_EQ(line.unprovenMoves, 0u);
  for (std::size_t i = 0; i < line.vertices.size(); ++i) {
    const auto& v = line.vertices[i];
    const double ref = std::max(referenceDrop(v.centre.x, v.centre.y, m, r), cutter.minZ() + r);
    worstVertex = std::max(worstVertex, std::fabs(ref - v.centre.z));
    if (std::fabs(v.centre.z - ref) > 1e-11 * cutter.meshSize()) {
      ++atEquator;
      EXPECT_NEAR(v.centre.z, ref, equator) << "vertex " << i;
    }
    if (i == 0) continue;
    const Vec3 a = line.vertices[i - 1].centre, b = v.centre;
    for (int s = 0; s <= samples; ++s) {
      const double d = pointMesh(a + (double(s) / samples) * (b - a), m);
      worstDepth = std::max(worstDepth, r - d);
      if (d < r - line.eps - tiny) {
        ADD_FAILURE() << "move " << i << " at " << s << "/" << samples << ": distance " << d;
        return;
      }
    }
  }
  std::printf("drop line: %zu vertices, %zu drops, %zu proofs; deepest %.3g (eps %.3g), worst "
              "vertex %.3g (%d beyond 1e-11 of the size: at the equator)\n",
              line.vertices.size(), line.drops, line.proofs, worstDepth, line.eps, worstVertex, atEquator);
}

TEST(MeshDrop, DropLine) {
  std::mt19937_64 rng(5);
  for (int k = 0; k < 3; ++k) {
    const Mesh m = heightfield(rng, 5, 1.5);
    const MeshDropCutter cutter(m, 0.4 + 0.2 * k);
    DropLineOptions options;
    options.eps = 1e-4 * cutter.meshSize();
    const Vec2 dir = k == 1 ? Vec2{0.6, 0.8} : Vec2{1.0, 0.0};
    const DropLine line = cutter.dropLine({-0.5, 0.3 + 1.7 * k}, dir, 0.0, 6.0, options);
    ASSERT_GT(line.vertices.size(), 2u);
    EXPECT_EQ(line.vertices.front().t, 0.0);
    EXPECT_EQ(line.vertices.back().t, 6.0);
    for (std::size_t i = 1; i < line.vertices.size(); ++i)
      EXPECT_LT(line.vertices[i - 1].t, line.vertices[i].t);
    checkDropLine(m, cutter, line, 24);
    // Deterministic: the same line again, vertex for vertex.
    const DropLine again = cutter.dropLine({-0.5, 0.3 + 1.7 * k}, dir, 0.0, 6.0, options);
    ASSERT_EQ(again.vertices.size(), line.vertices.size());
    for (std::size_t i = 0; i < line.vertices.size(); ++i)
      EXPECT_EQ(again.vertices[i].centre, line.vertices[i].centre);
  }
  // The default eps (1e-6 of the size) on a soup with vertical and sliver triangles.
  const Mesh m = soup(rng, 24);
  const MeshDropCutter cutter(m, 0.3);
  const DropLine line = cutter.dropLine({-0.5, 2.0}, {1.0, 0.0}, 0.0, 5.0);
  checkDropLine(m, cutter, line, 8);
}

// OpenCAMLib's test parts, read from a fetched mirror of its repository (LGPL: never
// committed here). SCALLOP_OCL_MIRROR names the git directory; the default is where the
// search tool's fetch puts it.
std::string oclPart(const std::string& name) {
  const char* env = std::getenv("SCALLOP_OCL_MIRROR");
  const std::string dir = env != nullptr ? env : "/work/.mirror/aewallin+opencamlib/repo";
  const std::string probe = dir + "/HEAD";
  if (std::FILE* f = std::fopen(probe.c_str(), "rb")) {
    std::fclose(f);
  } else {
    return {};
  }
  const std::string command = "git --git-dir='" + dir + "' show HEAD:stl/" + name + " 2>/dev/null";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {};
  std::string bytes;
  char buffer[65536];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) bytes.append(buffer, got);
  pclose(pipe);
  return bytes;
}

TEST(MeshDrop, OpenCamLibParts) {
  int parts = 0;
  for (const char* name : {"sphere.stl", "ktoolcav.stl", "mount_rush.stl", "cone_on_side.stl"}) {
    const std::string bytes = oclPart(name);
    if (bytes.empty()) continue;
    scallop::StlOptions stl;
    stl.dropZeroArea = true;
    const Mesh m = scallop::parseStl(bytes, name, stl).mesh;
    const double size = meshSize(m);
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    for (const Vec3& p : m.vertices) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), 0.0};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), 0.0};
    }
    const double r = 0.02 * size;
    const MeshDropCutter cutter(m, r);
    constexpr int kGrid = 24;
    double worst = 0.0;
    int failures = 0;
    for (int j = 0; j <= kGrid; ++j)
      for (int i = 0; i <= kGrid; ++i) {
        // A grid slightly off the mesh's round coordinates, over the footprint grown by R.
        const double x = lo.x - r + (hi.x - lo.x + 2 * r) * (i + 0.3183) / (kGrid + 1);
        const double y = lo.y - r + (hi.y - lo.y + 2 * r) * (j + 0.2718) / (kGrid + 1);
        const double got = cutter.drop(x, y).z;
        const double ref = referenceDrop(x, y, m, r);
        if (ref == -kInf || got == -kInf) {
          EXPECT_EQ(got, ref);
          continue;
        }
        worst = std::max(worst, std::fabs(got - ref));
        if (std::fabs(got - ref) > 1e-12 * size && ++failures <= 5)
          ADD_FAILURE() << name << " at (" << x << ", " << y << "): " << got << " vs " << ref;
      }
    std::printf("%s: %zu triangles, R = %.4g, %d points, worst |drop - reference| = %.3g of the "
                "size\n", name, m.triangles.size(), r, (kGrid + 1) * (kGrid + 1), worst / size);
    ++parts;
  }
  if (parts == 0) GTEST_SKIP() << "OpenCAMLib's mirror is absent (fetch github:aewallin/opencamlib, or set SCALLOP_OCL_MIRROR)";
}

TEST(MeshDrop, BadInput) {
  Mesh flat;
  flat.vertices = {{0, 0, 1}, {4, 0, 1}, {4, 4, 1}};
  flat.triangles = {{0, 1, 2}};
  const auto expectError = [](auto&& f, const std::string& mention) {
    try {
      f();
      ADD_FAILURE() << "no error; expected one mentioning " << mention;
    } catch (const scallop::Error& e) {
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  };
  expectError([&] { MeshDropCutter(flat, 0.0); }, "radius");
  expectError([&] { MeshDropCutter(flat, -1.0); }, "radius");
  expectError([&] { MeshDropCutter(flat, std::nan("")); }, "radius");
  expectError([&] { MeshDropCutter(Mesh{}, 1.0); }, "no triangle");
  Mesh badIndex = flat;
  badIndex.triangles[0][2] = 7;
  expectError([&] { MeshDropCutter(badIndex, 1.0); }, "vertex 7");
  Mesh nanVertex = flat;
  nanVertex.vertices[1].y = std::nan("");
  expectError([&] { MeshDropCutter(nanVertex, 1.0); }, "not finite");
  const MeshDropCutter cutter(flat, 1.0);
  expectError([&] { cutter.drop(std::nan(""), 0.0); }, "not finite");
  expectError([&] { cutter.drop(0.0, kInf); }, "not finite");
  expectError([&] { cutter.segmentDistance({0, 0, std::nan("")}, {1, 1, 1}); }, "not finite");
  expectError([&] { cutter.segmentDistance({0, 0, 0}, {1, 1, 1}, -1.0); }, "cutoff");
  expectError([&] { cutter.dropLine({0, 0}, {1, 1}, 0.0, 1.0); }, "unit");
  expectError([&] { cutter.dropLine({0, 0}, {1, 0}, 1.0, 0.0); }, "interval");
  expectError([&] { cutter.dropLine({std::nan(""), 0}, {1, 0}, 0.0, 1.0); }, "origin");
  DropLineOptions negative;
  negative.eps = -1.0;
  expectError([&] { cutter.dropLine({0, 0}, {1, 0}, 0.0, 1.0, negative); }, "eps");
  DropLineOptions tight;
  tight.step = 1e-3;
  tight.maxVertices = 10;
  expectError([&] { cutter.dropLine({0, 0}, {1, 0}, 0.0, 1.0, tight); }, "budget");
}

}  // namespace
