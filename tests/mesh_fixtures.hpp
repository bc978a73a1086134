#pragma once
// Meshes the mesh tests share: random height fields over [0, 2]^2.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>

#include "scallop/mesh.hpp"

namespace scallop::test {

// z = 0.3 sin(2x) cos(3y) plus noise of up to `noise` on an n x n grid of [0, 2]^2 (inches),
// each cell split along a random diagonal when `randomDiagonals`, else along the same one.
inline Mesh heightFieldMesh(std::size_t n, std::mt19937_64& rng, double noise, bool randomDiagonals) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Mesh mesh;
  mesh.units = Units::inch;
  for (std::size_t j = 0; j <= n; ++j)
    for (std::size_t i = 0; i <= n; ++i) {
      const double x = 2.0 * static_cast<double>(i) / static_cast<double>(n);
      const double y = 2.0 * static_cast<double>(j) / static_cast<double>(n);
      mesh.vertices.push_back({x, y, 0.3 * std::sin(2.0 * x) * std::cos(3.0 * y) + noise * unit(rng)});
    }
  const auto at = [n](std::size_t i, std::size_t j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      if (!randomDiagonals || unit(rng) < 0.5) {
        mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      } else {
        mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        mesh.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  return mesh;
}

}  // namespace scallop::test
