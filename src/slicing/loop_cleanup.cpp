// The Gauss map's loops made fit for the medial axis (see loop_cleanup.hpp).

#include "slicing/loop_cleanup.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace scallop::detail {

// The medial axis needs simple, disjoint loops (medial_axis.hpp). At fine tolerances the
// Gauss map's polygon union (Boost.Polygon, on an integer grid) can return a loop that runs
// back and forth along a nearly straight stretch, a zigzag a few grid steps wide whose
// segments cross or touch, and sliver holes of three or four points beside it (paper-1 at
// 0.005 degree: 17 such vertices among 57,804 segments; paper-2 at 0.0009 degree: 51 among
// 151,711, the zigzags up to 5e-8 wide in the plane, 0.3% of the tolerance there). Every
// vertex where the loop turns back within a triangle thinner than `widthRad` on the sphere
// (twice its area over its longest side, in the plane, where the projection stretches
// lengths by (1 + |p|^2) / 2) is removed, and a loop left with less than 3 points or an area
// below the square of that width dropped: the boundary moves by less than `widthRad`, below
// the polygon's own tolerance (and the polish works on the true surface anyway). O(n): a
// stack pass, then the junction of the loop's two ends.
std::vector<std::vector<Vec2>> withoutSpikes(const std::vector<std::vector<Vec2>>& loops, double widthRad) {
  auto width = [widthRad](const Vec2& q) { return widthRad * 0.5 * (1.0 + dot(q, q)); };
  auto spike = [&width](const Vec2& p, const Vec2& q, const Vec2& r) {
    const Vec2 a = q - p;
    const Vec2 b = r - q;
    const double longest = std::max({norm(a), norm(b), norm(a + b)});
    return dot(a, b) < 0.0 && std::abs(cross(a, b)) <= width(q) * longest;
  };
  std::vector<std::vector<Vec2>> out;
  for (const std::vector<Vec2>& loop : loops) {
    std::vector<Vec2> kept;
    for (const Vec2& p : loop) {
      if (!kept.empty() && kept.back() == p) continue;
      kept.push_back(p);
      while (kept.size() >= 3 && spike(kept[kept.size() - 3], kept[kept.size() - 2], kept.back())) {
        kept.erase(kept.end() - 2);
      }
    }
    // The last point and the first are neighbours too.
    std::size_t first = 0;
    for (bool changed = true; changed && kept.size() - first >= 3;) {
      changed = false;
      const std::size_t n = kept.size();
      if (kept[n - 1] == kept[first] || spike(kept[n - 2], kept[n - 1], kept[first])) {
        kept.pop_back(), changed = true;
      } else if (spike(kept[n - 1], kept[first], kept[first + 1])) {
        ++first, changed = true;
      }
    }
    kept.erase(kept.begin(), kept.begin() + static_cast<std::ptrdiff_t>(first));
    if (kept.size() < 3) continue;
    double area2 = 0.0;
    for (std::size_t i = 0; i < kept.size(); ++i) area2 += cross(kept[i] - kept[0], kept[(i + 1) % kept.size()] - kept[0]);
    const double w = width(kept[0]);
    if (0.5 * std::abs(area2) <= w * w) continue;
    out.push_back(std::move(kept));
  }
  return out;
}

}  // namespace scallop::detail
