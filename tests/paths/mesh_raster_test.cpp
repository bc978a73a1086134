// Raster finishing of triangle meshes (mesh_raster.hpp): judged by an independent brute-force
// point-to-mesh distance (every triangle, projection or nearest edge), and by the simulated cut
// on a mesh (cut_simulation.hpp) against the closed-form cusp of an inclined plane.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "support/mesh_fixtures.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/paths/mesh_raster.hpp"

namespace scallop {
namespace {

double segmentPointDistance(Vec3 p, Vec3 a, Vec3 b) {
  const Vec3 d = b - a;
  const double len2 = dot(d, d);
  const double s = len2 > 0.0 ? std::clamp(dot(p - a, d) / len2, 0.0, 1.0) : 0.0;
  return norm(p - (a + s * d));
}

// The distance from p to the triangle: to its plane where p projects inside (same-side tests
// on the three edges), else to the nearest of its edges.
double triangleDistance(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 n = cross(b - a, c - a);
  const double area2 = norm(n);
  if (area2 > 0.0) {
    const Vec3 unit = (1.0 / area2) * n;
    const Vec3 q = p - dot(p - a, unit) * unit;
    const bool inside = dot(cross(b - a, q - a), n) >= 0.0 && dot(cross(c - b, q - b), n) >= 0.0 &&
                        dot(cross(a - c, q - c), n) >= 0.0;
    if (inside) return std::abs(dot(p - a, unit));
  }
  return std::min({segmentPointDistance(p, a, b), segmentPointDistance(p, b, c), segmentPointDistance(p, c, a)});
}

double meshDistance(const Mesh& mesh, Vec3 p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles)
    best = std::min(best, triangleDistance(p, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
  return best;
}

// The largest scallop (along the normal) and vertical gouge over [0.3, 1.7]^2, away from the
// edges of a 2 x 2 part.
std::pair<double, double> innerFigures(const SimulationReport& report) {
  double scallop = 0.0, gouge = 0.0;
  for (std::size_t j = 0; j < report.stock.rows; ++j)
    for (std::size_t i = 0; i < report.stock.columns; ++i) {
      const Vec2 p = report.stock.point(i, j);
      if (p.x < 0.3 || p.x > 1.7 || p.y < 0.3 || p.y > 1.7) continue;
      const std::size_t k = j * report.stock.columns + i;
      scallop = std::max(scallop, (report.stock.z[k] - report.design.z[k]) * report.designNormalZ[k]);
      gouge = std::max(gouge, report.design.z[k] - report.stock.z[k]);
    }
  return {scallop, gouge};
}

// Every move sampled at its ends and three points between: no centre nearer than R - eps by
// the brute force; every vertex above the floor touches (within R + eps); the path is one
// continuous zigzag.
TEST(MeshRaster, RandomHeightFieldsAreCutGougeFreeByBruteForce) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    const Mesh mesh = test::heightFieldMesh(8 + 4 * static_cast<std::size_t>(trial), rng, 0.04, false);
    const double radius = 0.15 + 0.1 * trial;
    const MeshDropCutter cutter(mesh, radius);
    MeshRasterOptions options;
    options.spacing = 0.13;
    options.angleRad = 0.4 * trial;
    const MeshRasterPaths paths = meshRasterPaths(cutter, mesh, options);
    ASSERT_EQ(paths.path.passes.size(), 1u);
    EXPECT_EQ(paths.unprovenMoves, 0u);
    EXPECT_GT(paths.lines, 15u);
    const double eps = paths.eps;
    double deepest = -1.0, loosest = 0.0;
    std::size_t samples = 0;
    const ToolPass& pass = paths.path.passes[0];
    Vec3 at = pass.start;
    for (const ToolMove& move : pass.moves) {
      for (const double s : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        const double d = meshDistance(mesh, at + s * (move.end - at));
        deepest = std::max(deepest, radius - d);
        ++samples;
      }
      if (move.end.z > cutter.minZ() + radius + 1e-12) loosest = std::max(loosest, meshDistance(mesh, move.end) - radius);
      at = move.end;
    }
    std::printf("[          ] trial %d: %zu lines, %zu moves, %zu samples, deepest %.3g (eps %.3g), loosest vertex %.3g\n",
                trial, paths.lines, pass.moves.size(), samples, deepest, eps, loosest);
    EXPECT_LE(deepest, eps + 1e-12);
    EXPECT_LE(loosest, 1e-9);
  }
}

// The plane z = y / 2 over [0, 2]^2 as two triangles (inches).
Mesh inclinedPlane() {
  Mesh mesh;
  mesh.units = Units::inch;
  mesh.vertices = {{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {0.0, 2.0, 1.0}, {2.0, 2.0, 1.0}};
  mesh.triangles = {{0, 1, 3}, {0, 3, 2}};
  return mesh;
}

// An inclined plane z = y / 2 as two triangles, the feed along x: neighbouring lines' balls
// stand L = Delta / cos(phi) apart along the slope, so the cusp is R - sqrt(R^2 - L^2 / 4);
// the simulated cut reads it between the first and last lines within the grid's bound.
TEST(MeshRaster, AnInclinedPlaneLeavesTheClosedFormCusp) {
  const Mesh mesh = inclinedPlane();
  const double radius = 0.25, height = 0.002;
  const MeshDropCutter cutter(mesh, radius);
  MeshRasterOptions options;
  options.spacing = meshRasterSpacing(radius, height);
  const MeshRasterPaths paths = meshRasterPaths(cutter, mesh, options);
  SimulationOptions simulation;
  simulation.toolRadius = radius;
  simulation.scallopHeight = height;
  simulation.stockAllowance = 0.02;
  const SimulationReport report = simulateCut(mesh, sweptMoves(paths.path), simulation);
  const double cosPhi = 1.0 / std::sqrt(1.25);
  const double l = options.spacing / cosPhi;
  const double cusp = radius - std::sqrt(radius * radius - 0.25 * l * l);
  const auto [inner, innerGouge] = innerFigures(report);
  std::printf("[          ] spacing %.6f, cusp %.6f (flat %.6f), simulated %.6f, bound %.3g\n", options.spacing, cusp,
              height, inner, report.heightErrorBound);
  EXPECT_LE(inner, cusp + 1e-9);
  EXPECT_GE(inner, cusp - report.heightErrorBound / cosPhi);
  EXPECT_LE(innerGouge, paths.eps / cosPhi + 1e-12);
  EXPECT_GT(cusp, height);  // the slope widens the cusp: the plan measures it, never promises H
}

// The same plane with the cusp-adaptive steps for H: w = Delta sqrt(1 + s_e^2) = w_H on it,
// so the simulated cusp is H (within the grid's bound), never above.
TEST(MeshRaster, AdaptiveStepsHoldTheCuspOnASlopeToH) {
  const Mesh mesh = inclinedPlane();
  const double radius = 0.25, height = 0.002;
  const MeshDropCutter cutter(mesh, radius);
  MeshRasterOptions options;
  options.spacing = meshRasterSpacing(radius, height);
  options.scallopHeight = height;
  const MeshRasterPaths paths = meshRasterPaths(cutter, mesh, options);
  EXPECT_NEAR(paths.minSpacing, options.spacing / std::sqrt(1.25), 1e-12);
  EXPECT_EQ(paths.floorSteps, 0u);
  SimulationOptions simulation;
  simulation.toolRadius = radius;
  simulation.scallopHeight = height;
  simulation.stockAllowance = 0.02;
  const SimulationReport report = simulateCut(mesh, sweptMoves(paths.path), simulation);
  const double cosPhi = 1.0 / std::sqrt(1.25);
  const double inner = innerFigures(report).first;
  std::printf("[          ] %zu lines, step %.6f (flat %.6f), simulated cusp %.6f (H %.6f)\n", paths.lines,
              paths.minSpacing, options.spacing, inner, height);
  EXPECT_LE(inner, height + 1e-9);
  EXPECT_GE(inner, height - report.heightErrorBound / cosPhi);
  // A horizontal plane keeps the flat spacing.
  Mesh flat = inclinedPlane();
  for (Vec3& v : flat.vertices) v.z = 0.0;
  const MeshDropCutter flatCutter(flat, radius);
  EXPECT_NEAR(meshRasterPaths(flatCutter, flat, options).minSpacing, options.spacing, 1e-12);
}

// A square sheet tilted up along y: its three raised open edges get walls down to its lowest
// z (two triangles each; the edge lying on the bottom none); a ball beside the high edge and
// below it is clear of the sheet but not of the solid's side.
TEST(MeshRaster, TheSkirtWallsTheOpenEdgesOfASheet) {
  Mesh sheet;
  sheet.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 1.0}, {1.0, 1.0, 1.0}};
  sheet.triangles = {{0, 1, 3}, {0, 3, 2}};
  const Mesh solid = meshWithSkirt(sheet);
  EXPECT_EQ(solid.triangles.size(), 2u + 3u * 2u);
  for (std::size_t t = 2; t < solid.triangles.size(); ++t) {
    const auto& tri = solid.triangles[t];
    const Vec3 n = cross(solid.vertices[tri[1]] - solid.vertices[tri[0]], solid.vertices[tri[2]] - solid.vertices[tri[0]]);
    EXPECT_EQ(n.z, 0.0) << t;  // vertical
  }
  // Offset, every wall stands that far outside its edge, away from the sheet.
  const Mesh offset = meshWithSkirt(sheet, 0.01);
  ASSERT_EQ(offset.triangles.size(), solid.triangles.size());
  for (std::size_t v = sheet.vertices.size(); v < offset.vertices.size(); ++v) {
    const Vec3 p = offset.vertices[v];
    const bool outside = p.x < -0.009 || p.x > 1.009 || p.y > 1.009;  // the edge y = 0 lies on the bottom
    EXPECT_TRUE(outside) << p.x << ", " << p.y;
    EXPECT_TRUE(std::abs(p.x + 0.01) < 1e-12 || std::abs(p.x - 1.01) < 1e-12 || std::abs(p.y - 1.01) < 1e-12)
        << p.x << ", " << p.y;
  }
  EXPECT_THROW(meshWithSkirt(sheet, -1.0), Error);
  const double radius = 0.25;
  const Vec3 a{0.5, 1.2, 0.5}, b{0.6, 1.2, 0.5};  // 0.2 beside the edge y = 1 (at z = 1), half way down
  EXPECT_TRUE(MeshDropCutter(sheet, radius).segmentClear(a, b, radius - 1e-6));
  EXPECT_FALSE(MeshDropCutter(solid, radius).segmentClear(a, b, radius - 1e-6));
  // The drop heights are the same: a wall touches the ball only through its top edge.
  const MeshDropCutter open(sheet, radius), closed(solid, radius);
  for (double x = -0.3; x <= 1.3; x += 0.1)
    for (double y = -0.3; y <= 1.3; y += 0.1) {
      const double za = open.drop(x, y).z, zb = closed.drop(x, y).z;
      if (za == -std::numeric_limits<double>::infinity()) {
        EXPECT_LE(zb, radius) << x << ", " << y;  // the walls' bottom edges at z = 0
        continue;
      }
      EXPECT_NEAR(std::max(za, radius), std::max(zb, radius), 1e-12) << x << ", " << y;
    }
}

TEST(MeshRaster, RejectsBadOptions) {
  Mesh mesh;
  mesh.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  mesh.triangles = {{0, 1, 2}};
  const MeshDropCutter cutter(mesh, 0.1);
  MeshRasterOptions options;
  EXPECT_THROW(meshRasterPaths(cutter, mesh, options), Error);  // no spacing
  options.spacing = 0.01;
  options.angleRad = std::nan("");
  EXPECT_THROW(meshRasterPaths(cutter, mesh, options), Error);
  options.angleRad = 0.0;
  options.spacing = 1e-9;
  EXPECT_THROW(meshRasterPaths(cutter, mesh, options), Error);  // over the line budget
  options.spacing = 0.01;
  options.scallopHeight = 0.5;  // not below R
  EXPECT_THROW(meshRasterPaths(cutter, mesh, options), Error);
  options.scallopHeight = -1.0;
  EXPECT_THROW(meshRasterPaths(cutter, mesh, options), Error);
  EXPECT_THROW(meshRasterSpacing(0.1, 0.2), Error);
  EXPECT_THROW(meshRasterSpacing(0.1, 0.0), Error);
  EXPECT_NEAR(meshRasterSpacing(0.25, 0.001), 2.0 * std::sqrt(2.0 * 0.25 * 0.001 - 1e-6), 1e-15);
}

}  // namespace
}  // namespace scallop
