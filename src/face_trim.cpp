// A trimmed face's domain in its parameter plane (see face_trim.hpp).

#include "scallop/face_trim.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <limits>
#include <utility>

namespace scallop {

ParameterBox poleBox(const TrimArc& arc) {
  ParameterBox box{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const auto& p : arc) {
    const double u = p[0] / p[2], v = p[1] / p[2];
    box = {std::min(box.u0, u), std::max(box.u1, u), std::min(box.v0, v), std::max(box.v1, v)};
  }
  return box;
}

namespace {

// The two halves of an arc at t = 1/2 (de Casteljau on the homogeneous poles): the left
// half's poles are the first points of each level, the right half's the last (reversed).
std::pair<TrimArc, TrimArc> halves(TrimArc poles) {
  const std::size_t n = poles.size();
  TrimArc left(n), right(n);
  for (std::size_t level = 0; level < n; ++level) {
    left[level] = poles[0];
    right[n - 1 - level] = poles[n - 1 - level];
    for (std::size_t i = 0; i + 1 < n - level; ++i)
      for (std::size_t c = 0; c < 3; ++c) poles[i][c] = 0.5 * (poles[i][c] + poles[i + 1][c]);
  }
  return {std::move(left), std::move(right)};
}

}  // namespace

double sweptAngle(const TrimArc& arc, double u, double v) {
  double total = 0.0;
  std::vector<std::pair<TrimArc, int>> stack{{arc, 0}};
  while (!stack.empty()) {
    auto [poles, depth] = std::move(stack.back());
    stack.pop_back();
    // The poles as vectors from p, their angles measured from the first.
    const double ax = poles.front()[0] / poles.front()[2] - u, ay = poles.front()[1] / poles.front()[2] - v;
    bool wedge = ax != 0.0 || ay != 0.0;
    double least = 0.0, largest = 0.0, last = 0.0;
    for (std::size_t i = 1; wedge && i < poles.size(); ++i) {
      const double bx = poles[i][0] / poles[i][2] - u, by = poles[i][1] / poles[i][2] - v;
      if (bx == 0.0 && by == 0.0) {
        wedge = false;
        break;
      }
      last = std::atan2(ax * by - ay * bx, ax * bx + ay * by);
      least = std::min(least, last);
      largest = std::max(largest, last);
    }
    // A margin of 1e-9 rad keeps the rounding of the angles themselves out of the test.
    constexpr double kMargin = 1e-9;
    if (wedge && largest - least < std::numbers::pi - kMargin && least > -std::numbers::pi + kMargin &&
        largest < std::numbers::pi - kMargin) {
      total += last;
      continue;
    }
    if (depth >= kWindingDepth) return std::numeric_limits<double>::quiet_NaN();
    auto [left, right] = halves(std::move(poles));
    stack.push_back({std::move(left), depth + 1});
    stack.push_back({std::move(right), depth + 1});
  }
  return total;
}

CellPlace classifyPoint(const FaceTrim& trim, double u, double v) {
  double total = 0.0;
  for (const TrimArc& arc : trim.arcs) {
    const double angle = sweptAngle(arc, u, v);
    if (std::isnan(angle)) return CellPlace::boundary;
    total += angle;
  }
  const double turns = std::round(total / (2.0 * std::numbers::pi));
  if (!(std::abs(total - 2.0 * std::numbers::pi * turns) <= kWindingSlackRad)) return CellPlace::boundary;
  return std::fmod(std::abs(turns), 2.0) == 1.0 ? CellPlace::inside : CellPlace::outside;
}

CellPlace classifyBox(const FaceTrim& trim, const ParameterBox& box) {
  for (const TrimArc& arc : trim.arcs)
    if (mayMeet(arc, box)) return CellPlace::boundary;
  return classifyPoint(trim, 0.5 * (box.u0 + box.u1), 0.5 * (box.v0 + box.v1));
}

bool mayMeet(const TrimArc& arc, const ParameterBox& box) {
  const double smallU = (box.u1 - box.u0) / 8.0, smallV = (box.v1 - box.v0) / 8.0;
  std::vector<std::pair<TrimArc, int>> stack{{arc, 0}};
  while (!stack.empty()) {
    auto [poles, depth] = std::move(stack.back());
    stack.pop_back();
    const ParameterBox own = poleBox(poles);
    if (!own.meets(box)) continue;
    if ((own.u1 - own.u0 <= smallU && own.v1 - own.v0 <= smallV) || depth >= 40) return true;
    auto [left, right] = halves(std::move(poles));
    stack.push_back({std::move(left), depth + 1});
    stack.push_back({std::move(right), depth + 1});
  }
  return false;
}

}  // namespace scallop
