// A trimmed face's domain in its parameter plane (see face_trim.hpp).

#include "scallop/face_trim.hpp"

#include <algorithm>
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

bool mayMeet(const TrimArc& arc, const ParameterBox& box) {
  const double smallU = (box.u1 - box.u0) / 8.0, smallV = (box.v1 - box.v0) / 8.0;
  std::vector<std::pair<TrimArc, int>> stack{{arc, 0}};
  while (!stack.empty()) {
    auto [poles, depth] = std::move(stack.back());
    stack.pop_back();
    const ParameterBox own = poleBox(poles);
    if (!own.meets(box)) continue;
    if ((own.u1 - own.u0 <= smallU && own.v1 - own.v0 <= smallV) || depth >= 40) return true;
    // Halve: the left half's poles are the first points of each de Casteljau level, the
    // right half's the last (reversed).
    const std::size_t n = poles.size();
    TrimArc left(n), right(n);
    for (std::size_t level = 0; level < n; ++level) {
      left[level] = poles[0];
      right[n - 1 - level] = poles[n - 1 - level];
      for (std::size_t i = 0; i + 1 < n - level; ++i)
        for (std::size_t c = 0; c < 3; ++c) poles[i][c] = 0.5 * (poles[i][c] + poles[i + 1][c]);
    }
    stack.push_back({std::move(left), depth + 1});
    stack.push_back({std::move(right), depth + 1});
  }
  return false;
}

}  // namespace scallop
