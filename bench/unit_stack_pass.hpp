#pragma once
// A measurement prototype, not library code: the scallop hull's stack pass reformulated on
// "units" instead of capsules, to measure what a rewrite of the pass could reach (README,
// Performance). It computes only the envelope c(x) of the ball centres (the stack of units
// and where each takes over), not the hull or the tool path.
//
// Contract
// --------
// Input:  a chain with x strictly increasing (no vertical edges, no repeated points), material
//         below; r > 0. Anything else returns false.
// Output: true and the stack: unit u (u = -1: the arc around v_0; u = e: the offset line of
//         edge e then the arc around v_{e+1}) takes over the envelope at (x, z). False when a
//         case outside the generic ones is met (the library's pass decides those).
// Decisions within `band` of a tie are taken by their sign and counted in `undecided`: a
//         library version would hand that edge to the present pass.
// Time:   O(n), one pass, each unit pushed and popped at most once.
//
// Why units: a capsule's top is arc - line - arc and the arc around a vertex belongs to two
// capsules, so the present pass must find which of up to 3 x 3 stretch pairs cross. A unit's
// top is one line and one arc, and every vertex arc is in exactly one unit. The top's start P
// is covered by the new unit U_k when P lies right of U_k's first point and within r of edge
// k (P is on the envelope, so above the capsule's lower boundary: inside = below the top). The
// crossing's pair is told by at most two side tests at the units' junctions, then one pair is
// solved in closed form (the paper's peak-peak, peak-slope and slope-slope, Figure 6).

#include <cmath>
#include <cstddef>
#include <vector>

#include "scallop/paths/chain.hpp"

namespace scallop_bench {

class UnitStackPass {
 public:
  struct Entry {
    long unit = -1;  // -1: the arc around v_0; e: edge e's offset line, then the arc around v_{e+1}
    double x = 0.0;  // where the unit takes over the envelope
    double z = 0.0;
    double nx = 0.0;  // edge e's upward unit normal
    double nz = 1.0;
  };

  UnitStackPass(double radius, double coordinateScale)
      : r_(radius), r2_(radius * radius), band_(64.0 * 2.220446049250313e-16 * (coordinateScale + radius)) {}

  bool run(const std::vector<scallop::Point2>& chain) {
    v_ = chain.data();
    const long n = static_cast<long>(chain.size());
    stack_.clear();
    undecided_ = 0;
    if (n < 2) return false;
    stack_.reserve(chain.size());
    stack_.push_back({-1, v_[0].x - r_, v_[0].z, 0.0, 1.0});
    for (long k = 0; k + 1 < n; ++k) {
      if (!addUnit(k)) return false;
    }
    return true;
  }

  [[nodiscard]] const std::vector<Entry>& stack() const { return stack_; }
  [[nodiscard]] long undecided() const { return undecided_; }

  /// The envelope at x (within the chain's reach), from the stack.
  [[nodiscard]] double height(double x) const {
    std::size_t lo = 0;
    std::size_t hi = stack_.size() - 1;
    while (lo < hi) {
      const std::size_t mid = (lo + hi + 1) / 2;
      if (stack_[mid].x <= x) lo = mid; else hi = mid - 1;
    }
    const Entry& e = stack_[lo];
    const scallop::Point2 c = v_[e.unit + 1];
    if (e.unit >= 0) {
      const scallop::Point2 a = v_[e.unit];
      const double s0 = a.x + r_ * e.nx;
      const double s1 = c.x + r_ * e.nx;
      if (x >= s0 && x <= s1) return a.z + r_ * e.nz + (x - s0) * (c.z - a.z) / (c.x - a.x);
    }
    const double d = x - c.x;
    return c.z + std::sqrt(std::max(0.0, r2_ - d * d));
  }

 private:
  // (distance^2 - r^2) times |b - a|^2 from p to segment a-b, and the half-width of its
  // undecided band (the band in distance, times 2r |b - a|^2).
  double excess(double px0, double pz0, const scallop::Point2& a, double dx, double dz, double len2) const {
    const double px = px0 - a.x;
    const double pz = pz0 - a.z;
    const double dot = px * dx + pz * dz;
    if (dot <= 0.0) return (px * px + pz * pz - r2_) * len2;
    if (dot >= len2) {
      const double qx = px - dx;
      const double qz = pz - dz;
      return (qx * qx + qz * qz - r2_) * len2;
    }
    const double cross = px * dz - pz * dx;
    return cross * cross - r2_ * len2;
  }

  bool addUnit(long k) {
    const scallop::Point2 a = v_[k];
    const scallop::Point2 b = v_[k + 1];
    const double dx = b.x - a.x;
    const double dz = b.z - a.z;
    if (!(dx > 0.0)) return false;
    const double len2 = dx * dx + dz * dz;
    const double inverseLength = 1.0 / std::sqrt(len2);
    const double nx = -dz * inverseLength;
    const double nz = dx * inverseLength;
    const double s0 = a.x + r_ * nx;  // the unit's offset line runs over [s0, s1]
    const double s1 = b.x + r_ * nx;
    const double threshold = 2.0 * r_ * band_ * len2;

    // Backward exclusion: pop the units whose start the new one covers.
    bool popped = false;
    double pieceEnd = 0.0;  // where the top unit's piece ends: the last popped start
    while (true) {
      const Entry& top = stack_.back();
      if (top.x < s0) break;
      const double e = excess(top.x, top.z, a, dx, dz, len2);
      if (e > threshold) break;
      if (e > -threshold) ++undecided_;
      pieceEnd = top.x;
      popped = true;
      stack_.pop_back();
      if (stack_.empty()) return false;
    }
    const Entry top = stack_.back();
    double qx = 0.0;
    double qz = 0.0;
    if (!popped) {
      // The top is U_{k-1}, whose arc around v_k = a ends the envelope so far.
      if (top.unit != k - 1) return false;
      const bool convex = k == 0 || (a.x - v_[k - 1].x) * dz - (a.z - v_[k - 1].z) * dx <= 0.0;
      if (convex) {
        // The new line leaves the arc around a at its tangent point.
        if (!(s0 > top.x)) return false;
        stack_.push_back({k, s0, a.z + r_ * nz, nx, nz});
        return true;
      }
      // Concave (slope-slope, Figure 6a): the offset lines meet at a + r (n + n') / (1 + n.n').
      const double denominator = 1.0 + top.nx * nx + top.nz * nz;
      if (denominator > 1e-8) {
        qx = a.x + r_ * (top.nx + nx) / denominator;
        qz = a.z + r_ * (top.nz + nz) / denominator;
        const double topS0 = v_[k - 1].x + r_ * top.nx;
        const double topS1 = a.x + r_ * top.nx;
        if (qx > top.x && qx > topS0 && qx < topS1 && qx > s0 && qx < s1) {
          stack_.push_back({k, qx, qz, nx, nz});
          return true;
        }
      }
      pieceEnd = a.x + r_;  // otherwise the general case over the top's whole piece
    }
    // The crossing of U_k with the top unit U_j on its piece [top.x, pieceEnd].
    const long j = top.unit;
    const scallop::Point2 c = v_[j + 1];  // the top's arc centre
    const scallop::Point2 cPrevious = j >= 0 ? v_[j] : c;
    const double topS1 = j >= 0 ? c.x + r_ * top.nx : -INFINITY;
    bool topOnLine = j >= 0 && top.x < topS1;
    if (topOnLine && topS1 < pieceEnd) {
      // The top's junction (line to arc) is on the envelope: inside capsule k, the crossing
      // is before it, on the top's line.
      const double e = excess(topS1, c.z + r_ * top.nz, a, dx, dz, len2);
      if (std::abs(e) <= threshold) ++undecided_;
      topOnLine = topS1 >= s0 && e < 0.0;
    }
    // The new unit's stretch: its line if the crossing is left of s1 (U_k above the top's
    // stretch there), else its arc around b.
    bool newOnLine = true;
    if (s1 <= top.x) {
      newOnLine = false;
    } else if (s1 < pieceEnd) {
      const double jx = s1;
      const double jz = b.z + r_ * nz;
      double side;
      double sideBand;
      if (topOnLine) {
        const double tdx = c.x - cPrevious.x;
        const double tdz = c.z - cPrevious.z;
        side = (jz - (c.z + r_ * top.nz)) * tdx - (jx - topS1) * tdz;
        sideBand = 4.0 * band_ * (std::abs(tdx) + std::abs(tdz));
      } else {
        const double ux = jx - c.x;
        const double uz = jz - c.z;
        side = std::abs(ux) > r_ ? 1.0 : ux * ux + uz * uz - r2_;
        sideBand = 4.0 * r_ * band_;
      }
      if (std::abs(side) <= sideBand) ++undecided_;
      newOnLine = side > 0.0;
    }
    if (!topOnLine && !newOnLine) {
      // peak-peak (Figure 6b): the upper meeting point of two circles of radius r.
      const double wx = b.x - c.x;
      const double wz = b.z - c.z;
      const double d2 = wx * wx + wz * wz;
      if (!(d2 < 4.0 * r2_) || !(d2 > 0.0)) return false;
      const double h = std::sqrt(r2_ / d2 - 0.25);  // height over the midpoint, over |w|
      qx = 0.5 * (c.x + b.x) - h * wz;
      qz = 0.5 * (c.z + b.z) + h * wx;
    } else if (topOnLine && newOnLine) {
      // slope-slope (Figure 6a) between edges that are not adjacent.
      const double tdx = c.x - cPrevious.x;
      const double tdz = c.z - cPrevious.z;
      const double px = a.x + r_ * nx - (cPrevious.x + r_ * top.nx);
      const double pz = a.z + r_ * nz - (cPrevious.z + r_ * top.nz);
      const double denominator = tdx * dz - tdz * dx;
      if (denominator == 0.0) return false;
      const double s = (px * dz - pz * dx) / denominator;
      qx = cPrevious.x + r_ * top.nx + s * tdx;
      qz = cPrevious.z + r_ * top.nz + s * tdz;
    } else {
      // peak-slope (Figure 6c): a line p + s u meets the circle of radius r around centre m.
      double px, pz, ux, uz, mx, mz;
      if (topOnLine) {
        const double tdx = c.x - cPrevious.x;
        const double tdz = c.z - cPrevious.z;
        const double inverse = 1.0 / std::sqrt(tdx * tdx + tdz * tdz);
        px = cPrevious.x + r_ * top.nx;
        pz = cPrevious.z + r_ * top.nz;
        ux = tdx * inverse;
        uz = tdz * inverse;
        mx = b.x;
        mz = b.z;
      } else {
        px = a.x + r_ * nx;
        pz = a.z + r_ * nz;
        ux = dx * inverseLength;
        uz = dz * inverseLength;
        mx = c.x;
        mz = c.z;
      }
      const double wx = px - mx;
      const double wz = pz - mz;
      const double half = wx * ux + wz * uz;
      const double constant = wx * wx + wz * wz - r2_;
      const double discriminant = half * half - constant;
      if (!(discriminant > 1e-9 * r2_)) return false;
      // The top's line enters the new arc at the first root; the new line rises out of the
      // top's arc at the second.
      const double s = topOnLine ? -half - std::sqrt(discriminant) : -half + std::sqrt(discriminant);
      qx = px + s * ux;
      qz = pz + s * uz;
      if (qz < mz) return false;
    }
    // The crossing must lie on both stretches and in the top's piece.
    const double margin = 32.0 * 2.220446049250313e-16 * (r_ + std::abs(qx));
    if (!(qx > top.x + margin && qx < pieceEnd - margin)) ++undecided_;
    if (newOnLine ? !(qx > s0 + margin && qx < s1 - margin) : !(qx > s1 + margin)) return false;
    if (topOnLine ? !(qx < topS1 - margin) : !(qx > topS1 + margin)) return false;
    stack_.push_back({k, qx, qz, nx, nz});
    return true;
  }

  double r_;
  double r2_;
  double band_;
  const scallop::Point2* v_ = nullptr;
  std::vector<Entry> stack_;
  long undecided_ = 0;
};

}  // namespace scallop_bench
