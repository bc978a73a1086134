#pragma once
// What the Gauss map and optimal slicing tests share: dense surface normals for their
// brute-force references, and a surface that once broke the Gauss map.

#include <algorithm>
#include <cmath>
#include <vector>

#include "scallop/bezier.hpp"
#include "scallop/surface.hpp"
#include "scallop/vector.hpp"

namespace scallop::reference {

// Unit normals on an (n+1) x (n+1) parameter grid of every patch.
inline std::vector<Vec3> sampleNormals(const Surface& s, int n) {
  std::vector<Vec3> out;
  for (const BezierPatch& p : s.patches) {
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) out.push_back(unitNormal(p, double(i) / n, double(j) / n));
    }
  }
  return out;
}

// The least angle between direction m and +-(the sampled normals): alpha of m over the
// samples, and the angle from m to the sampled symmetrized Gauss image.
inline double sampledAlpha(const std::vector<Vec3>& normals, const Vec3& m) {
  double worst = 0.0;
  for (const Vec3& n : normals) worst = std::max(worst, std::abs(dot(n, m)));
  return std::acos(std::min(1.0, worst));
}

// Two bicubic graph patches over [0, 3] x [0, 3] and [3, 6] x [0, 3] with heights z[j][k] at
// (x, y) = (k, j), sharing the column k = 3 (C0).
inline Surface twoPatchSurface(const double (&z)[4][7]) {
  Surface s;
  for (int part = 0; part < 2; ++part) {
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) p.control.push_back({double(3 * part + k), double(j), z[j][3 * part + k]});
    }
    s.patches.push_back(p);
  }
  return s;
}

// Two random bicubic patches, C0 along x = 3, on which the Gauss map's union once lost the
// normals near the corner (u, v) = (0, 1) of the second patch (2,640 of 40,803 normals sampled
// at 101 x 101 lay more than two tolerances inside the complement, 34 degrees deep at worst).
inline Surface twoPatchRegressionSurface() {
  const double z[4][7] = {{0.6753, 1.1909, 1.2780, 0.7642, 0.6671, 0.9258, 1.0888},
                          {0.3085, 1.3275, 1.3722, 0.5354, 0.0021, 1.1797, 0.2465},
                          {0.5283, 1.0242, 0.4930, 0.2316, 1.0166, 0.2580, 0.6747},
                          {0.8372, 0.5874, 1.4148, 0.6583, 1.4150, 1.4974, 1.2883}};
  return twoPatchSurface(z);
}

}  // namespace scallop::reference
