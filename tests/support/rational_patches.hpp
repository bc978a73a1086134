#pragma once
// Rational Bezier patches for the tests: a torus patch built from the textbook construction
// (independent of scallop's conversions) and random bumpy rational graphs.

#include <array>
#include <cmath>
#include <random>
#include <utility>

#include "scallop/geometry/bezier.hpp"

namespace scallop::test {

// A patch of the torus (sqrt(x^2 + y^2) - a)^2 + z^2 = b^2 as the tensor product of two
// rational quadratic quarter circles, built here from the surface of revolution's textbook
// construction (Piegl and Tiller, The NURBS Book, 8.5): the profile's control points
// (x_k, z_k) with weights v_k swept by the arc's (c_j, weights a_j): p_jk = (x_k c_j, z_k),
// w_jk = a_j v_k. `outer`: the profile's quarter from (a + b, 0) over the top to (a, b) (K >= 0);
// otherwise from (a - b, 0) to (a, b) (K <= 0).
inline BezierPatch torusPatch(double a, double b, bool outer) {
  const double s = std::sqrt(0.5);
  const std::array<std::pair<double, double>, 3> arc{{{1, 0}, {1, 1}, {0, 1}}};
  const std::array<double, 3> arcWeights{1, s, 1};
  const double x0 = outer ? a + b : a - b;
  const std::array<std::pair<double, double>, 3> profile{{{x0, 0}, {x0, b}, {a, b}}};
  BezierPatch patch;
  patch.degreeU = patch.degreeV = 2;
  for (int j = 0; j <= 2; ++j)
    for (int k = 0; k <= 2; ++k) {
      patch.control.push_back({profile[k].first * arc[j].first, profile[k].first * arc[j].second, profile[k].second});
      patch.weights.push_back(arcWeights[j] * arcWeights[k]);
    }
  return patch;
}

inline BezierPatch randomRationalPatch(std::mt19937_64& rng, int m, int n) {
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), weight(0.3, 3.0);
  BezierPatch patch;
  patch.degreeU = m;
  patch.degreeV = n;
  for (int j = 0; j <= m; ++j)
    for (int k = 0; k <= n; ++k) {
      // A bumpy graph over the unit square keeps the patch regular.
      patch.control.push_back({double(j) / m + 0.1 * coordinate(rng), double(k) / n + 0.1 * coordinate(rng),
                               0.5 * coordinate(rng)});
      patch.weights.push_back(weight(rng));
    }
  return patch;
}


}  // namespace scallop::test
