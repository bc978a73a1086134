#pragma once
// Meshes the mesh tests share: triangulated grids (height fields).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>

#include "scallop/geometry/mesh.hpp"

namespace scallop::test {

// The (n + 1)^2 points (side i / n, side j / n, height(x, y)) in row order, each of the n^2
// cells cut into two triangles along a diagonal chosen by a fair coin from `rng` when
// `randomDiagonals` (after every height has been taken), else always the same one.
template <typename Height>
Mesh gridMesh(std::size_t n, double side, Height&& height, std::mt19937_64& rng, bool randomDiagonals) {
  Mesh mesh;
  for (std::size_t j = 0; j <= n; ++j)
    for (std::size_t i = 0; i <= n; ++i) {
      const double x = side * static_cast<double>(i) / static_cast<double>(n);
      const double y = side * static_cast<double>(j) / static_cast<double>(n);
      mesh.vertices.push_back({x, y, height(x, y)});
    }
  std::bernoulli_distribution coin(0.5);
  const auto at = [n](std::size_t i, std::size_t j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      if (!randomDiagonals || coin(rng)) {
        mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      } else {
        mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        mesh.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  return mesh;
}

// z = 0.3 sin(2x) cos(3y) plus noise of up to `noise` over [0, 2]^2, in inches.
inline Mesh heightFieldMesh(std::size_t n, std::mt19937_64& rng, double noise, bool randomDiagonals) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Mesh mesh = gridMesh(
      n, 2.0, [&](double x, double y) { return 0.3 * std::sin(2.0 * x) * std::cos(3.0 * y) + noise * unit(rng); },
      rng, randomDiagonals);
  mesh.units = Units::inch;
  return mesh;
}

}  // namespace scallop::test
