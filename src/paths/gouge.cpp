// Distance from a point to a surface of Bezier patches by branch and bound, and the gouge
// check of a tool path built on it. See include/scallop/gouge.hpp for the contract.

#include "scallop/paths/gouge.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/geometry/tolerances.hpp"
#include "scallop/job_control.hpp"
#include "scallop/parallel.hpp"

namespace scallop {

namespace detail {

struct Box {
  Vec3 lo;
  Vec3 hi;
};

// Where a piece lies in the surface's patch `original`: [u0, u0 + du] x [v0, v0 + dv] of its
// parameters, du and dv powers of 2 (so the map back is exact), made by `splits` halvings.
struct PieceOf {
  std::uint32_t original = 0;
  double u0 = 0.0, du = 1.0, v0 = 0.0, dv = 1.0;
  int splits = 0;
};

// One patch's sub-patches to `levels - 1` halvings in u and v. Level L holds 4^L cells; the
// cell (iu, iv), on [iu, iu + 1] x [iv, iv + 1] / 2^L, is at index iu 2^L + iv, its control
// net at nets[L][index * stride], its axis-aligned box at boxes[L][index].
// A rational patch's net (bezier.hpp's rational patches) holds its (m + 1)(n + 1) Euclidean
// control points p_jk, which bound the cell as a polynomial net does (the convex hull
// property holds for positive weights), followed by its weights as (w_jk, 0, 0): halving works
// on the homogeneous points w p and w, and divides back.
struct PatchTree {
  int degreeU = 0;
  int degreeV = 0;
  std::size_t points = 0;  // (m + 1)(n + 1) control points per net
  std::size_t stride = 0;  // points, or 2 points for a rational patch (its weights after them)
  bool rational = false;
  double weightRatio = 1.0;  // a rational patch's largest weight over its least
  int levels = 0;
  std::vector<std::vector<Vec3>> nets;
  std::vector<std::vector<Box>> boxes;
  double scale = 0.0;  // the largest |coordinate| of the patch's control points
  // A trimmed patch's cells' places in its face (CellPlace + 1; 0: not classified yet), level
  // after level (level L from placeOffset[L]), filled on first use by whichever thread gets
  // there: the place is a function of the cell alone, so every thread writes the same value.
  // Beside the cells' boxes, not in a hashed table: classifying costs a table lookup that
  // missed the cache on every cell (a quarter of a trimmed face's plan). Null: untrimmed.
  std::shared_ptr<std::atomic<std::uint8_t>[]> places;
  std::vector<std::size_t> placeOffset;
  // The piece of a surface's patch this tree covers (SurfaceDistance cuts long thin patches,
  // see the contract's Pieces), its net reparametrised to [0, 1]^2 (`patch`); `scale` and
  // `weightRatio` are the original patch's, and the rounding allowance counts piece.splits
  // as cell depth.
  BezierPatch patch;
  PieceOf piece;
};

// A piece's parameters in its original patch's.
double originalU(const PatchTree& tree, double s) { return tree.piece.u0 + s * tree.piece.du; }
double originalV(const PatchTree& tree, double t) { return tree.piece.v0 + t * tree.piece.dv; }

// A node of the hierarchy of the patches' root boxes: a leaf holds `count` patches
// (nodePatches_[first, first + count)), an inner node two children. Its rounding allowance
// bounds its patches' root cells' (cellAllowance at depth 0): coefficient (scale + query scale).
struct PatchNode {
  Box box;
  std::uint32_t first = 0;
  std::uint32_t count = 0;  // 0: an inner node
  std::uint32_t left = 0;
  std::uint32_t right = 0;
  double allowanceCoefficient = 0.0;
  double scale = 0.0;
};

}  // namespace detail

namespace {

using detail::Box;
using detail::PatchNode;
using detail::PatchTree;
using detail::PieceOf;

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kMaxTreeDepth = 6;

bool isFinite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }
double maxAbs(Vec3 a) { return std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)}); }

// The same with the count fixed at compile time and the six extremes in scalars (kept in
// registers across the unrolled loop; min and max are exact, so the same box).
template <std::size_t Count>
Box boxOfFixed(const Vec3* net) {
#if defined(__SSE2__)
  // x and y of each point as one pair, z alone: each coordinate's extremes taken in the same
  // order as below (_mm_min_pd(a, b) is a < b ? a : b, std::min(b, a)), so the same bits.
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is read as packed doubles");
  __m128d loXY = _mm_loadu_pd(&net[0].x);
  __m128d hiXY = loXY;
  double loZ = net[0].z, hiZ = loZ;
  for (std::size_t i = 1; i < Count; ++i) {
    const __m128d xy = _mm_loadu_pd(&net[i].x);
    loXY = _mm_min_pd(xy, loXY);
    hiXY = _mm_max_pd(xy, hiXY);
    loZ = std::min(loZ, net[i].z), hiZ = std::max(hiZ, net[i].z);
  }
  double lo[2], hi[2];
  _mm_storeu_pd(lo, loXY);
  _mm_storeu_pd(hi, hiXY);
  return {{lo[0], lo[1], loZ}, {hi[0], hi[1], hiZ}};
#else
  double loX = net[0].x, loY = net[0].y, loZ = net[0].z;
  double hiX = loX, hiY = loY, hiZ = loZ;
  for (std::size_t i = 1; i < Count; ++i) {
    loX = std::min(loX, net[i].x), loY = std::min(loY, net[i].y), loZ = std::min(loZ, net[i].z);
    hiX = std::max(hiX, net[i].x), hiY = std::max(hiY, net[i].y), hiZ = std::max(hiZ, net[i].z);
  }
  return {{loX, loY, loZ}, {hiX, hiY, hiZ}};
#endif
}

Box boxOf(const Vec3* net, std::size_t count) {
  if (count == 16) return boxOfFixed<16>(net);  // bicubic: unrolled (the search's hot loop)
  Box box{net[0], net[0]};
  for (std::size_t i = 1; i < count; ++i) {
    box.lo = {std::min(box.lo.x, net[i].x), std::min(box.lo.y, net[i].y),
              std::min(box.lo.z, net[i].z)};
    box.hi = {std::max(box.hi.x, net[i].x), std::max(box.hi.y, net[i].y),
              std::max(box.hi.z, net[i].z)};
  }
  return box;
}

// 2^-depth, exactly (depth <= kMaxCellDepth): the side of a cell in u and v. Built from the
// exponent bits, as std::ldexp would give it, without its library call in the hot loops.
double cellSide(int depth) {
  return std::bit_cast<double>(static_cast<std::uint64_t>(1023 - depth) << 52);
}

// How far 0 lies outside [lo, hi].
double gap(double lo, double hi) { return lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0); }

double boxDistance(const Box& box, Vec3 p) {
  const double dx = gap(box.lo.x - p.x, box.hi.x - p.x);
  const double dy = gap(box.lo.y - p.y, box.hi.y - p.y);
  const double dz = gap(box.lo.z - p.z, box.hi.z - p.z);
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// min_i (net[i] - origin) . w over `count` control points (net[i] . w without Shifted),
// each dot product rounded as dot() rounds it ((x wx + y wy) + z wz, after the
// subtraction). With SSE2 two points at a time (min is exact, so only the order of equal
// values can differ: the same minimum).
template <bool Shifted>
double leastAlong(const Vec3* net, int count, Vec3 origin, Vec3 w) {
  double least = kInfinity;
  int i = 0;
#if defined(__SSE2__)
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is read as packed doubles");
  const double* c = &net[0].x;
  const __m128d wx = _mm_set1_pd(w.x), wy = _mm_set1_pd(w.y), wz = _mm_set1_pd(w.z);
  const __m128d ox = _mm_set1_pd(origin.x), oy = _mm_set1_pd(origin.y), oz = _mm_set1_pd(origin.z);
  __m128d pair = _mm_set1_pd(kInfinity);
  for (; i + 1 < count; i += 2) {
    const double* q = c + 3 * i;  // x0 y0 | z0 x1 | y1 z1
    const __m128d a = _mm_loadu_pd(q);
    const __m128d b = _mm_loadu_pd(q + 2);
    const __m128d d = _mm_loadu_pd(q + 4);
    __m128d x = _mm_shuffle_pd(a, b, 0b10);
    __m128d y = _mm_shuffle_pd(a, d, 0b01);
    __m128d z = _mm_shuffle_pd(b, d, 0b10);
    if constexpr (Shifted) {
      x = _mm_sub_pd(x, ox);
      y = _mm_sub_pd(y, oy);
      z = _mm_sub_pd(z, oz);
    }
    const __m128d dots =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(x, wx), _mm_mul_pd(y, wy)), _mm_mul_pd(z, wz));
    pair = _mm_min_pd(dots, pair);  // dots < pair ? dots : pair, as std::min(pair, dots)
  }
  double lanes[2];
  _mm_storeu_pd(lanes, pair);
  least = std::min(lanes[0], lanes[1]);
#endif
  for (; i < count; ++i) least = std::min(least, dot(Shifted ? net[i] - origin : net[i], w));
  return least;
}

// A separating plane: with w the unit direction from p to the mean of the net's corners,
// every point of the convex hull, hence of the cell, is at least min_i (c_i - p) . w from
// p (see the contract: near the foot point w tends to the normal, along which the net is
// O(h^2) thin, so this bound is O(h^2) sharp there; the box in the lateral directions adds
// nothing, as p projects inside the cell's lateral extent). 0 when p is that mean.
double separatingPlaneDistance(const Vec3* net, int m, int n, Vec3 p) {
  const int stride = n + 1;
  const Vec3 toCell = 0.25 * (net[0] + net[n] + net[m * stride] + net[m * stride + n]) - p;
  const double length = norm(toCell);
  if (!(length > 0.0)) return 0.0;
  const Vec3 w = toCell / length;
  return std::max(0.0, leastAlong<true>(net, (m + 1) * stride, p, w));
}

// De Casteljau at 1/2 on b[0], b[s], .., b[n s] into left and right (n + 1 points each,
// the same stride; they may overwrite b). The same arithmetic as bezier.hpp's subdivideU /
// subdivideV at t = 1/2 (bit for bit: halving by 0.5 * (a + b) is exact scaling of one
// rounded sum either way), without its Bernstein2 temporaries, so that building the trees
// and the search loop do not allocate per cell.
// The same with the degree fixed at compile time (unrolled; the same operations in the same
// order, so the same bits).
template <int N>
void halveCurveFixed(const Vec3* b, std::ptrdiff_t s, Vec3* left, Vec3* right) {
  std::array<Vec3, N + 1> t;
  for (int i = 0; i <= N; ++i) t[static_cast<std::size_t>(i)] = b[i * s];
  left[0] = t[0];
  right[N * s] = t[static_cast<std::size_t>(N)];
  for (int r = 1; r <= N; ++r) {
    for (int i = 0; i <= N - r; ++i) {
      const auto k = static_cast<std::size_t>(i);
      t[k] = 0.5 * (t[k] + t[k + 1]);
    }
    left[r * s] = t[0];
    right[(N - r) * s] = t[static_cast<std::size_t>(N - r)];
  }
}

void halveCurve(const Vec3* b, int n, std::ptrdiff_t s, Vec3* left, Vec3* right) {
  switch (n) {  // the common degrees unrolled
    case 1: return halveCurveFixed<1>(b, s, left, right);
    case 2: return halveCurveFixed<2>(b, s, left, right);
    case 3: return halveCurveFixed<3>(b, s, left, right);
    default: break;
  }
  std::array<Vec3, kMaxPatchDegree + 1> t;
  for (int i = 0; i <= n; ++i) t[static_cast<std::size_t>(i)] = b[i * s];
  left[0] = t[0];
  right[n * s] = t[static_cast<std::size_t>(n)];
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i <= n - r; ++i) {
      const auto k = static_cast<std::size_t>(i);
      t[k] = 0.5 * (t[k] + t[k + 1]);
    }
    left[r * s] = t[0];
    right[(n - r) * s] = t[static_cast<std::size_t>(n - r)];
  }
}

// The four quarters of a net, in the order (u half, v half) = (0,0), (0,1), (1,0), (1,1),
// written at out, out + size, .. (size = (m + 1)(n + 1); out must not overlap net).
template <int M, int N>
void halveNetFixed(const Vec3* net, Vec3* out) {
  constexpr int stride = N + 1;
  constexpr std::ptrdiff_t size = (M + 1) * stride;
  Vec3* const lowU = out;
  Vec3* const highU = out + 2 * size;
  for (int k = 0; k <= N; ++k) halveCurveFixed<M>(net + k, stride, lowU + k, highU + k);
  for (Vec3* half : {lowU, highU}) {
    for (int j = 0; j <= M; ++j) {
      Vec3* row = half + j * stride;
      halveCurveFixed<N>(row, 1, row, row + size);
    }
  }
}

void halveNet(const Vec3* net, int m, int n, Vec3* out) {
  if (m == 3 && n == 3) return halveNetFixed<3, 3>(net, out);  // bicubic, the usual patch
  const int stride = n + 1;
  const std::ptrdiff_t size = (m + 1) * stride;
  Vec3* const lowU = out;
  Vec3* const highU = out + 2 * size;
  for (int k = 0; k <= n; ++k) halveCurve(net + k, m, stride, lowU + k, highU + k);  // in u
  for (Vec3* half : {lowU, highU}) {  // then each half in v, row by row, in place
    for (int j = 0; j <= m; ++j) {
      Vec3* row = half + j * stride;
      halveCurve(row, n, 1, row, row + size);
    }
  }
}

// A tree's net halved into its four quarters (out: 4 strides): halveNet on a polynomial net;
// on a rational one the homogeneous points w p and the weights are halved alike (de
// Casteljau is linear) and each quarter's points divided back.
void halveTreeNet(const PatchTree& tree, const Vec3* net, Vec3* out) {
  if (!tree.rational) {
    halveNet(net, tree.degreeU, tree.degreeV, out);
    return;
  }
  const std::size_t count = tree.points;
  // Per-thread scratch: this runs for every halving of a rational cell.
  thread_local std::vector<Vec3> homogeneous, weights, halvedPoints, halvedWeights;
  homogeneous.resize(count);
  weights.resize(count);
  halvedPoints.resize(4 * count);
  halvedWeights.resize(4 * count);
  for (std::size_t i = 0; i < count; ++i) {
    homogeneous[i] = net[count + i].x * net[i];
    weights[i] = net[count + i];
  }
  halveNet(homogeneous.data(), tree.degreeU, tree.degreeV, halvedPoints.data());
  halveNet(weights.data(), tree.degreeU, tree.degreeV, halvedWeights.data());
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t i = 0; i < count; ++i) {
      out[k * tree.stride + i] = halvedPoints[k * count + i] / halvedWeights[k * count + i].x;
      out[k * tree.stride + count + i] = halvedWeights[k * count + i];
    }
}

struct CurveJet {
  Vec3 d0, d1, d2;
};

// Value, first and second derivative of the degree-N curve b[0 .. N] at t (b is consumed):
// de Casteljau down to three points q0, q1, q2; then r = the quadratic's value,
// r' = N (e1 - e0) from the last level but one, r'' = N (N - 1) (q2 - 2 q1 + q0). Inlined
// by force into jetAt's seven calls (GCC 12 kept them calls: 2.5 % of the raster plan's
// instructions).
template <int N>
[[gnu::always_inline]] inline CurveJet curveJetFixed(Vec3* b, double t) {
  static_assert(N >= 2);
  const double s = 1.0 - t;
  for (int count = N + 1; count > 3; --count) {
    for (int i = 0; i + 1 < count; ++i) b[i] = s * b[i] + t * b[i + 1];
  }
  const Vec3 e0 = s * b[0] + t * b[1];
  const Vec3 e1 = s * b[1] + t * b[2];
  const double nn = N;
  return {s * e0 + t * e1, nn * (e1 - e0), (nn * (nn - 1.0)) * (b[2] - 2.0 * b[1] + b[0])};
}

// r and its partial derivatives to second order at (u, v).
struct Jet {
  Vec3 r, ru, rv, ruu, ruv, rvv;
};
Jet jetAt(const BezierPatch& patch, double u, double v) {
  if (patch.rational() || patch.degreeU != 3 || patch.degreeV != 3) {
    // One pass of basis sums (bezier.hpp): O(m^2 + n^2 + mn), where de Casteljau down each
    // row is O(m n^2) (BM_PatchJet: 3 times the time at degree 20). A rational patch by the
    // quotient rule.
    Vec3 r;
    const PatchDerivatives d = derivativesToSecondOrder(patch, u, v, r);
    return {r, d.u, d.v, d.uu, d.uv, d.vv};
  }
  // Bicubic, the usual patch: de Casteljau along each row, then across, unrolled.
  std::array<Vec3, 4> row, value, dv, dvv;
  for (int j = 0; j <= 3; ++j) {
    std::copy_n(patch.control.begin() + j * 4, 4, row.begin());
    const CurveJet c = curveJetFixed<3>(row.data(), v);
    const auto k = static_cast<std::size_t>(j);
    value[k] = c.d0;
    dv[k] = c.d1;
    dvv[k] = c.d2;
  }
  const CurveJet a = curveJetFixed<3>(value.data(), u);
  const CurveJet b = curveJetFixed<3>(dv.data(), u);
  const CurveJet c = curveJetFixed<3>(dvv.data(), u);
  return {a.d0, a.d1, b.d0, a.d2, b.d1, c.d0};
}

struct Candidate {
  double distance = kInfinity;
  std::size_t patch = 0;
  double u = 0.0;
  double v = 0.0;
  Vec3 point;
};

// A local minimum of f = |r(u, v) - p|^2 / 2 on [0, 1]^2 near (u, v), by a projected Newton
// iteration: a parameter at its bound whose gradient points outwards is held there (the
// active set); the Newton step uses the Hessian
//   [r_u.r_u + d.r_uu, r_u.r_v + d.r_uv; .., r_v.r_v + d.r_vv], d = r - p,
// when it is positive definite, else the Gauss-Newton matrix [r_u.r_u, r_u.r_v; .., r_v.r_v];
// steps are clamped to [0, 1]^2 and halved until f decreases. Only ever an upper bound for
// the search (every point it returns is a surface point), so it need not be globally right.
Candidate newton(const BezierPatch& patch, std::size_t index, Vec3 p, double u, double v,
                 const Jet& start) {
  Jet jet = start;
  Vec3 d = jet.r - p;
  double f = dot(d, d);
  for (int iteration = 0; iteration < 20; ++iteration) {
    const double gu = dot(d, jet.ru);
    const double gv = dot(d, jet.rv);
    const double guu = dot(jet.ru, jet.ru);
    const double guv = dot(jet.ru, jet.rv);
    const double gvv = dot(jet.rv, jet.rv);
    double huu = guu + dot(d, jet.ruu);
    double huv = guv + dot(d, jet.ruv);
    double hvv = gvv + dot(d, jet.rvv);
    const bool freeU = !((u <= 0.0 && gu > 0.0) || (u >= 1.0 && gu < 0.0));
    const bool freeV = !((v <= 0.0 && gv > 0.0) || (v >= 1.0 && gv < 0.0));
    double su = 0.0;
    double sv = 0.0;
    if (freeU && freeV) {
      if (!(huu > 0.0 && huu * hvv - huv * huv > 0.0)) {
        huu = guu;
        huv = guv;
        hvv = gvv;
      }
      const double det = huu * hvv - huv * huv;
      if (!(det > 0.0)) break;
      su = -(hvv * gu - huv * gv) / det;
      sv = -(huu * gv - huv * gu) / det;
    } else if (freeU) {
      const double h = huu > 0.0 ? huu : guu;
      if (!(h > 0.0)) break;
      su = -gu / h;
    } else if (freeV) {
      const double h = hvv > 0.0 ? hvv : gvv;
      if (!(h > 0.0)) break;
      sv = -gv / h;
    } else {
      break;  // a corner where f increases into the square: a constrained minimum
    }
    bool accepted = false;
    double nu = u;
    double nv = v;
    for (double lambda = 1.0; lambda > 1e-6; lambda *= 0.5) {
      nu = std::clamp(u + lambda * su, 0.0, 1.0);
      nv = std::clamp(v + lambda * sv, 0.0, 1.0);
      const Jet trial = jetAt(patch, nu, nv);
      const Vec3 dt = trial.r - p;
      const double ft = dot(dt, dt);
      if (ft < f) {
        jet = trial;
        d = dt;
        f = ft;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    const double moved = std::abs(nu - u) + std::abs(nv - v);
    u = nu;
    v = nv;
    if (moved <= 4.0 * std::numeric_limits<double>::epsilon()) break;
  }
  return {std::sqrt(f), index, u, v, jet.r};
}

// Interval arithmetic on boxes, for the convexity certificate below. Not outward rounded:
// the certificate takes a relative margin instead (see convexLowerBound).
struct Interval {
  double lo = 0.0;
  double hi = 0.0;
};
Interval product(double alo, double ahi, double blo, double bhi) {
  const double p[4] = {alo * blo, alo * bhi, ahi * blo, ahi * bhi};
  return {std::min({p[0], p[1], p[2], p[3]}), std::max({p[0], p[1], p[2], p[3]})};
}
Interval dotRange(const Box& a, const Box& b) {
  const Interval x = product(a.lo.x, a.hi.x, b.lo.x, b.hi.x);
  const Interval y = product(a.lo.y, a.hi.y, b.lo.y, b.hi.y);
  const Interval z = product(a.lo.z, a.hi.z, b.lo.z, b.hi.z);
  return {x.lo + y.lo + z.lo, x.hi + y.hi + z.hi};
}
double squaredNormLow(const Box& a) {  // min |x|^2 over the box: its distance to 0, squared
  const double x = gap(a.lo.x, a.hi.x);
  const double y = gap(a.lo.y, a.hi.y);
  const double z = gap(a.lo.z, a.hi.z);
  return x * x + y * y + z * z;
}

// The box of the control points of the (du, dv) partial derivative of the net's patch
// (du + dv <= 2): m!/(m-du)! n!/(n-dv)! times the du-th difference along s and the dv-th
// along t. Zero where the degree is too low.
Box derivativeBox(const Vec3* net, int m, int n, int du, int dv) {
  if (du > m || dv > n) return {};
  const int stride = n + 1;
  const double weights[3][3] = {{1.0, 0.0, 0.0}, {-1.0, 1.0, 0.0}, {1.0, -2.0, 1.0}};
  const double factor = (du == 0 ? 1.0 : (du == 1 ? m : m * (m - 1.0))) *
                        (dv == 0 ? 1.0 : (dv == 1 ? n : n * (n - 1.0)));
  Box box{{kInfinity, kInfinity, kInfinity}, {-kInfinity, -kInfinity, -kInfinity}};
  for (int j = 0; j + du <= m; ++j) {
    for (int k = 0; k + dv <= n; ++k) {
      Vec3 c;
      for (int a = 0; a <= du; ++a) {
        for (int b = 0; b <= dv; ++b) {
          c = c + (weights[du][a] * weights[dv][b]) * net[(j + a) * stride + k + b];
        }
      }
      c = factor * c;
      box.lo = {std::min(box.lo.x, c.x), std::min(box.lo.y, c.y), std::min(box.lo.z, c.z)};
      box.hi = {std::max(box.hi.x, c.x), std::max(box.hi.y, c.y), std::max(box.hi.z, c.z)};
    }
  }
  return box;
}

// A lower bound on the distance from p to the cell (net on [u0, u0 + h] x [v0, v0 + h] of
// `patch`) when f = |R(s, t) - p|^2 / 2, R the cell in its own parameters (s, t) in [0, 1]^2,
// is provably strongly convex there; 0 otherwise. Why: near the foot point the box bounds
// lag the distance by O(h^2), which for a tolerance t costs about log4(1/t) levels of
// cells; a convex f is settled at once, from one point x0 of the cell:
//   f(x) >= f(x0) + g . (x - x0) + lambda/2 |x - x0|^2  for x in the cell,
// lambda a lower bound of the Hessian's eigenvalues over the cell,
//   H = [R_s.R_s + d.R_ss, R_s.R_t + d.R_st; .., R_t.R_t + d.R_tt], d = R - p,
// from interval products of the boxes of the derivative nets (convex hull property); for a
// symmetric 2x2 matrix lambda_min grows with the diagonal and falls with |off-diagonal|,
// so the intervals' ends give it. The quadratic's minimum over [0, 1]^2 is separable. x0 is
// the best point so far clamped into the cell (there g ~ 0 for the cell holding the foot
// point, and points away from it for its neighbours), else the centre.
double convexLowerBound(const Vec3* net, const BezierPatch& patch, std::size_t patchIndex,
                        double u0, double v0, double h, const Candidate& best, Vec3 p) {
  // A rational cell's derivatives are quotients, not differences of its net: bounds 1 and 2
  // carry its search alone (some more levels of cells near the foot point).
  if (patch.rational()) return 0.0;
  const int m = patch.degreeU;
  const int n = patch.degreeV;
  const auto count = static_cast<std::size_t>((m + 1) * (n + 1));
  Box d = boxOf(net, count);
  d = {d.lo - p, d.hi - p};
  const Box rs = derivativeBox(net, m, n, 1, 0);
  const Box rt = derivativeBox(net, m, n, 0, 1);
  const Interval dss = dotRange(d, derivativeBox(net, m, n, 2, 0));
  const Interval dst = dotRange(d, derivativeBox(net, m, n, 1, 1));
  const Interval dtt = dotRange(d, derivativeBox(net, m, n, 0, 2));
  const Interval st = dotRange(rs, rt);
  const double ss = squaredNormLow(rs);
  const double tt = squaredNormLow(rt);
  const double a = ss + dss.lo;
  const double c = tt + dtt.lo;
  const double b = std::max(std::abs(st.lo + dst.lo), std::abs(st.hi + dst.hi));
  if (!(a > 0.0 && c > 0.0 && a * c > b * b)) return 0.0;
  // lambda_min = (a c - b^2) / ((a + c)/2 + sqrt(((a - c)/2)^2 + b^2)), without cancellation;
  // less a margin for the rounding of the interval products (1e-12 of their magnitudes, far
  // above their few-ulp errors).
  const double margin = 1e-12 * (ss + tt + std::abs(dss.lo) + std::abs(dtt.lo) + 2.0 * b);
  const double lambda = (a * c - b * b) / (0.5 * (a + c) + std::hypot(0.5 * (a - c), b)) - margin;
  if (!(lambda > 0.0)) return 0.0;
  double s0 = 0.5;
  double t0 = 0.5;
  if (best.patch == patchIndex && std::isfinite(best.distance)) {
    s0 = std::clamp((best.u - u0) / h, 0.0, 1.0);
    t0 = std::clamp((best.v - v0) / h, 0.0, 1.0);
  }
  const Jet jet = jetAt(patch, u0 + h * s0, v0 + h * t0);
  const Vec3 r = jet.r - p;
  const double gs = h * dot(r, jet.ru);
  const double gt = h * dot(r, jet.rv);
  // min over delta in [lo, hi] of g delta + lambda/2 delta^2.
  const auto least = [lambda](double g, double lo, double hi) {
    const double delta = std::clamp(-g / lambda, lo, hi);
    return delta * (g + 0.5 * lambda * delta);
  };
  const double f = 0.5 * dot(r, r) + least(gs, -s0, 1.0 - s0) + least(gt, -t0, 1.0 - t0);
  return std::sqrt(2.0 * std::max(0.0, f));
}

// A cell of the search: a sub-patch of `patch` on [u0, u0 + h] x [v0, v0 + h], h = 2^-depth.
// Its net is in the patch's tree (inTree, at `net` = node index) or in the thread's cell
// store (at `net` = offset into its nets, its box at `box`).
struct Cell {
  double lower = 0.0;
  std::uint32_t patch = 0;
  int depth = 0;
  bool inTree = false;
  std::uint32_t box = 0;
  std::size_t net = 0;
  double u0 = 0.0;
  double v0 = 0.0;
  bool inFace = false;  // a trimmed patch's cell known to lie in its face (no more classifying)
};

struct ByLowerBound {
  bool operator()(const Cell& a, const Cell& b) const { return a.lower > b.lower; }  // min-heap
};

// Queues `cell` with bound `lower` on the min-heap: std::push_heap's sift-up with ByLowerBound
// (the same comparisons and moves, so the same heap, and ties pop in the same order), with the
// bound written into the cell's final slot last. std::push_heap copies a cell whose bound was
// just stored with 16-byte loads: a store-forwarding stall on every queued cell. Likewise the
// offers take their cell by reference: a cell passed by value is copied to the argument area
// with 16-byte loads right after its fields were stored one by one (perf: 29% of
// segmentSearch's own time sat on that copy).
void pushCell(std::vector<Cell>& heap, const Cell& cell, double lower) {
  heap.push_back(cell);
  std::size_t hole = heap.size() - 1;
  while (hole > 0) {
    const std::size_t parent = (hole - 1) / 2;
    if (!(heap[parent].lower > lower)) break;
    heap[hole] = heap[parent];
    hole = parent;
  }
  if (hole + 1 != heap.size()) heap[hole] = cell;
  heap[hole].lower = lower;
}

// The cells below the patches' trees, halved on demand, kept per thread across queries:
// consecutive queries along a path (the drop envelope's proofs along a pass) search the same
// small region, so they would halve the same cells again. Keyed by the split cell (patch,
// depth, iu, iv), each entry holds its four quarters' nets and boxes, computed exactly as
// halveNet and boxOf compute them, so a query gives the same bits whatever the store holds.
// Bounded: emptied at the start of a query once it holds its limit of splits (or cells of
// another SurfaceDistance, told apart by its id); within a query it grows with the cells
// split (past the limit they are kept but no longer indexed). The limit is kStoreEntries,
// kTrimmedStoreEntries for a trimmed surface. 1024 splits of bicubic cells are 1.7 MB; on
// paper-1's raster plan 256 kept 1 % more instructions, 4096 and 16384 no fewer (the drop
// envelope's proofs along a pass reuse only recent cells), and on paper-2's raster paths
// 4096 took 1.04x the time (the nets no longer stay in the cache). A trimmed surface's
// queries split the same cells along its trimming curves, 18 levels deep, again and again:
// there 4096 took the screw's exact-trims paths 111 -> 93 s (32,768: no better), the disk's
// 0.94x.
constexpr std::size_t kStoreEntries = 1024;
constexpr std::size_t kTrimmedStoreEntries = 4096;
constexpr std::size_t kStoreSlots = 4 * kTrimmedStoreEntries;  // a power of 2; at most 1/4 full

// A cell's key (position iu, iv at its depth, in its patch) mixed into 64 bits.
std::uint64_t mixCellKey(std::uint64_t iu, std::uint64_t iv, std::uint32_t patch, int depth) {
  std::uint64_t k = iu * 0x9E3779B97F4A7C15ULL ^ (iv + 0x632BE59BD9B4E019ULL) * 0xC2B2AE3D27D4EB4FULL;
  k ^= (static_cast<std::uint64_t>(patch) << 8 | static_cast<std::uint64_t>(depth)) * 0x165667B19E3779F9ULL;
  return k ^ (k >> 29);
}

struct CellStore {
  struct Slot {
    std::uint64_t iu = 0;
    std::uint64_t iv = 0;
    std::uint32_t patch = 0;
    int depth = -1;  // -1: empty
    std::size_t net = 0;
    std::uint32_t box = 0;
  };
  std::uint64_t owner = 0;  // SurfaceDistance::id_ of the cells held; 0: none
  std::vector<Vec3> nets;   // [0, netsUsed) in use; never shrunk, so never re-zeroed
  std::size_t netsUsed = 0;
  std::vector<Box> boxes;
  std::vector<std::uint8_t> places;  // beside boxes: a trimmed cell's place + 1 (0: not classified)
  std::size_t boxesUsed = 0;
  std::vector<Slot> slots = std::vector<Slot>(kStoreSlots);
  std::size_t entries = 0;
  std::size_t limit = kStoreEntries;  // splits indexed; the slots in use are [0, 4 limit)

  // Before a query of the SurfaceDistance `id`, of a trimmed surface or not.
  void prepare(std::uint64_t id, bool trimmed) {
    const std::size_t wanted = trimmed ? kTrimmedStoreEntries : kStoreEntries;
    if (owner == id && limit == wanted && entries < limit && boxesUsed <= 4 * limit) return;
    owner = id;
    netsUsed = 0;
    boxesUsed = 0;
    if (entries > 0) std::fill(slots.begin(), slots.begin() + static_cast<std::ptrdiff_t>(4 * limit), Slot{});
    entries = 0;
    limit = wanted;
  }

  [[nodiscard]] std::size_t mask() const { return 4 * limit - 1; }  // 4 limit: a power of 2

  [[nodiscard]] std::size_t hash(std::uint64_t iu, std::uint64_t iv, std::uint32_t patch, int depth) const {
    return static_cast<std::size_t>(mixCellKey(iu, iv, patch, depth)) & mask();
  }

  // The quarters of the cell (patch, depth, iu, iv) with the net `parent` (m, n its
  // degrees): where its nets (4 (m + 1)(n + 1) points from the offset returned in `net`) and
  // boxes (4 from `box`) are, halved now unless held.
  void quarters(std::uint32_t patch, int depth, std::uint64_t iu, std::uint64_t iv, const Vec3* parent,
                const PatchTree& tree, std::size_t& net, std::uint32_t& box) {
    std::size_t slot = hash(iu, iv, patch, depth);
    for (;; slot = (slot + 1) & mask()) {
      const Slot& s = slots[slot];
      if (s.depth < 0) break;
      if (s.iu == iu && s.iv == iv && s.patch == patch && s.depth == depth) {
        net = s.net;
        box = s.box;
        return;
      }
    }
    const std::size_t stride = tree.stride;
    net = netsUsed;
    netsUsed += 4 * stride;
    if (netsUsed > nets.size()) {
      // Growing moves the nets: copy the parent first if it lives here.
      std::vector<Vec3> copy(parent, parent + stride);
      nets.resize(std::max(netsUsed, 2 * nets.size()));
      halveTreeNet(tree, copy.data(), nets.data() + net);
    } else {
      halveTreeNet(tree, parent, nets.data() + net);
    }
    box = static_cast<std::uint32_t>(boxesUsed);
    boxesUsed += 4;
    if (boxesUsed > boxes.size()) {
      boxes.resize(std::max(boxesUsed, 2 * boxes.size()));
      places.resize(boxes.size());
    }
    std::fill_n(places.begin() + box, 4, std::uint8_t{0});
    for (std::size_t k = 0; k < 4; ++k) boxes[box + k] = boxOf(nets.data() + net + k * stride, tree.points);
    if (entries < limit) {
      slots[slot] = {iu, iv, patch, depth, net, box};
      ++entries;
    }
  }
};

// What both searches (closest point, segment clearance) do with a cell before their own
// bounds: the rounding allowance of the contract for a cell `depth` halvings deep and queries
// of magnitude `queryScale`; the cell's control net (in the tree, or in the cell store);
// its corners not seen before (`fresh`, a bit per corner), surface points, offered to
// `consider`; and its axis-aligned box.
double allowanceCoefficient(const PatchTree& tree, int depth) {
  // A rational net's points are quotients X / w of halved homogeneous points and weights:
  // their errors, each of the polynomial net's order relative to w_max |p|_max and w_max,
  // are divided by w >= w_min, so at most 2 w_max / w_min times the polynomial allowance.
  const double quotient = tree.rational ? 2.0 * tree.weightRatio + 1.0 : 1.0;
  return quotient * (3.0 * (tree.degreeU + tree.degreeV) * (depth + tree.piece.splits + 1) + 16.0) * kUnitRoundoff;
}

double cellAllowance(const PatchTree& tree, int depth, double queryScale) {
  return allowanceCoefficient(tree, depth) * (tree.scale + queryScale);
}

const Vec3* cellNet(const PatchTree& tree, const Cell& cell, const CellStore& store) {
  return cell.inTree ? tree.nets[static_cast<std::size_t>(cell.depth)].data() + cell.net * tree.stride
                     : store.nets.data() + cell.net;
}

// Inlined by force: it runs for every cell, and GCC 12 left it a call that copied the box
// out (4 % of the raster plan's instructions).
template <class Consider>
[[gnu::always_inline]] inline Box cornersAndBox(const PatchTree& tree, const Cell& cell,
                                                const Vec3* net, unsigned fresh,
                                                const CellStore& store, Consider&& consider) {
  const int m = tree.degreeU;
  const int n = tree.degreeV;
  const double h = cellSide(cell.depth);
  // A cell known to lie in its face (or of an untrimmed patch) needs no test of its corners.
  if (fresh & 1u) consider(net[0], cell.patch, cell.u0, cell.v0, cell.inFace);
  if (fresh & 2u) consider(net[n], cell.patch, cell.u0, cell.v0 + h, cell.inFace);
  if (fresh & 4u) consider(net[m * (n + 1)], cell.patch, cell.u0 + h, cell.v0, cell.inFace);
  if (fresh & 8u) consider(net[m * (n + 1) + n], cell.patch, cell.u0 + h, cell.v0 + h, cell.inFace);
  return cell.inTree ? tree.boxes[static_cast<std::size_t>(cell.depth)][cell.net] : store.boxes[cell.box];
}

// A node of the patches' hierarchy waiting in a search, by the lower bound of its box.
struct NodeEntry {
  double lower = 0.0;
  std::uint32_t node = 0;
};

struct NodeByLowerBound {
  bool operator()(const NodeEntry& a, const NodeEntry& b) const { return a.lower > b.lower; }  // min-heap
};

struct Scratch {
  std::vector<Cell> heap;
  std::vector<NodeEntry> nodes;
  CellStore store;
};

// The hierarchy's walk shared by both searches. A surface of one leaf offers its patches'
// root cells at once, in order (the search before the hierarchy, bit for bit); otherwise
// nodes wait in their own heap and are opened while their lower bound is at most the
// least of the queued cells', so cells and nodes are taken in the order of their bounds.
// `lowerOf` bounds a node's box; `drop(lower)` is told of nodes that cannot matter.
template <typename LowerOf, typename Keep, typename Drop, typename Offer>
class NodeWalk {
 public:
  NodeWalk(const std::vector<PatchNode>& nodes, const std::vector<std::uint32_t>& patches, std::vector<NodeEntry>& heap,
           const std::vector<Cell>& cells, LowerOf lowerOf, Keep keep, Drop drop, Offer offer)
      : nodes_(nodes), patches_(patches), heap_(heap), cells_(cells), lowerOf_(lowerOf), keep_(keep), drop_(drop),
        offer_(offer) {
    heap_.clear();
    if (nodes_.size() == 1) {
      openLeaf(nodes_.front());
    } else {
      heap_.push_back({lowerOf_(nodes_.front()), 0});
    }
  }

  // Opens the nodes that come before the least queued cell.
  void advance() {
    while (!heap_.empty()) {
      if (!cells_.empty() && heap_.front().lower > cells_.front().lower) return;
      std::pop_heap(heap_.begin(), heap_.end(), NodeByLowerBound{});
      const NodeEntry entry = heap_.back();
      heap_.pop_back();
      if (!keep_(entry.lower)) {
        drop_(entry.lower);
        continue;
      }
      const PatchNode& node = nodes_[entry.node];
      if (node.count > 0) {
        openLeaf(node);
        continue;
      }
      for (const std::uint32_t child : {node.left, node.right}) {
        const double lower = lowerOf_(nodes_[child]);
        if (!keep_(lower)) {
          drop_(lower);
          continue;
        }
        heap_.push_back({lower, child});
        std::push_heap(heap_.begin(), heap_.end(), NodeByLowerBound{});
      }
    }
  }

  // The least bound of the nodes not opened (infinity when none is left).
  double waiting() const { return heap_.empty() ? kInfinity : heap_.front().lower; }

 private:
  void openLeaf(const PatchNode& node) {
    for (std::uint32_t k = 0; k < node.count; ++k)
      offer_(Cell{0.0, patches_[node.first + k], 0, true, 0, 0, 0.0, 0.0}, 0b1111u);
  }

  const std::vector<PatchNode>& nodes_;
  const std::vector<std::uint32_t>& patches_;
  std::vector<NodeEntry>& heap_;
  const std::vector<Cell>& cells_;
  LowerOf lowerOf_;
  Keep keep_;
  Drop drop_;
  Offer offer_;
};

// The hierarchy over the patches' root boxes (see the contract): median splits of the box
// centres along the longest axis of their spread, leaves of at most kPatchesPerLeaf patches
// in index order. Iterative (a stack of ranges), deterministic.
void buildHierarchy(const std::vector<PatchTree>& trees, std::vector<PatchNode>& nodes,
                    std::vector<std::uint32_t>& patches) {
  patches.resize(trees.size());
  for (std::size_t i = 0; i < trees.size(); ++i) patches[i] = static_cast<std::uint32_t>(i);
  const auto centre = [&](std::uint32_t i) {
    const Box& b = trees[i].boxes[0][0];
    return 0.5 * (b.lo + b.hi);
  };
  struct Range {
    std::size_t node, begin, end;
  };
  nodes.clear();
  nodes.emplace_back();
  std::vector<Range> stack{{0, 0, patches.size()}};
  while (!stack.empty()) {
    const Range range = stack.back();
    stack.pop_back();
    PatchNode node;
    node.box = trees[patches[range.begin]].boxes[0][0];
    Vec3 low = centre(patches[range.begin]), high = low;
    for (std::size_t k = range.begin; k < range.end; ++k) {
      const PatchTree& tree = trees[patches[k]];
      const Box& b = tree.boxes[0][0];
      node.box.lo = {std::min(node.box.lo.x, b.lo.x), std::min(node.box.lo.y, b.lo.y), std::min(node.box.lo.z, b.lo.z)};
      node.box.hi = {std::max(node.box.hi.x, b.hi.x), std::max(node.box.hi.y, b.hi.y), std::max(node.box.hi.z, b.hi.z)};
      node.scale = std::max(node.scale, tree.scale);
      node.allowanceCoefficient = std::max(node.allowanceCoefficient, allowanceCoefficient(tree, 0));
      const Vec3 c = centre(patches[k]);
      low = {std::min(low.x, c.x), std::min(low.y, c.y), std::min(low.z, c.z)};
      high = {std::max(high.x, c.x), std::max(high.y, c.y), std::max(high.z, c.z)};
    }
    if (range.end - range.begin <= kPatchesPerLeaf) {
      std::sort(patches.begin() + static_cast<std::ptrdiff_t>(range.begin),
                patches.begin() + static_cast<std::ptrdiff_t>(range.end));
      node.first = static_cast<std::uint32_t>(range.begin);
      node.count = static_cast<std::uint32_t>(range.end - range.begin);
      nodes[range.node] = node;
      continue;
    }
    const Vec3 spread = high - low;
    const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
    const auto key = [&](std::uint32_t i) {
      const Vec3 c = centre(i);
      return axis == 0 ? c.x : (axis == 1 ? c.y : c.z);
    };
    const std::size_t middle = range.begin + (range.end - range.begin) / 2;
    std::nth_element(patches.begin() + static_cast<std::ptrdiff_t>(range.begin),
                     patches.begin() + static_cast<std::ptrdiff_t>(middle),
                     patches.begin() + static_cast<std::ptrdiff_t>(range.end),
                     [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b) || (key(a) == key(b) && a < b); });
    node.left = static_cast<std::uint32_t>(nodes.size());
    node.right = node.left + 1;
    nodes[range.node] = node;
    nodes.emplace_back();
    nodes.emplace_back();
    stack.push_back({node.right, middle, range.end});
    stack.push_back({node.left, range.begin, middle});
  }
}

// Offers the four quarters of `cell` (subdivided at 1/2 in u and v): from the patch's tree
// while it goes that deep, else from the cell store. Each quarter comes with the corners it
// does not share with `cell` or an earlier quarter (the same points, bit for bit: de
// Casteljau copies the ends), so that each surface point is considered once, in the order
// the quarters' corners would first show it: `consider` keeps the first of equal distances.
template <typename Offer>
void offerQuarters(const Cell& cell, const PatchTree& tree, CellStore& store, const Offer& offer) {
  constexpr unsigned kFresh[2][2] = {{0b1110u, 0b1000u}, {0b1000u, 0b0000u}};
  const double half = cellSide(cell.depth + 1);
  if (cell.inTree && cell.depth + 1 < tree.levels) {
    const auto side = std::size_t{1} << cell.depth;
    const std::size_t iu = cell.net / side;
    const std::size_t iv = cell.net % side;
    for (std::size_t a = 0; a < 2; ++a) {
      for (std::size_t b = 0; b < 2; ++b) {
        offer(Cell{0.0, cell.patch, cell.depth + 1, true, 0, (2 * iu + a) * (2 * side) + (2 * iv + b),
                   cell.u0 + static_cast<double>(a) * half, cell.v0 + static_cast<double>(b) * half, cell.inFace},
              kFresh[a][b]);
      }
    }
    return;
  }
  // The cell's integer position at its depth (u0, v0 are exact multiples of its side).
  const double cells = cellSide(-cell.depth);
  const auto iu = static_cast<std::uint64_t>(cell.u0 * cells);
  const auto iv = static_cast<std::uint64_t>(cell.v0 * cells);
  std::size_t first = 0;
  std::uint32_t box = 0;
  store.quarters(cell.patch, cell.depth, iu, iv, cellNet(tree, cell, store), tree, first, box);
  for (std::size_t a = 0; a < 2; ++a) {
    for (std::size_t b = 0; b < 2; ++b) {
      const std::size_t k = 2 * a + b;
      offer(Cell{0.0, cell.patch, cell.depth + 1, false, box + static_cast<std::uint32_t>(k),
                 first + k * tree.stride, cell.u0 + static_cast<double>(a) * half,
                 cell.v0 + static_cast<double>(b) * half, cell.inFace},
            kFresh[a][b]);
    }
  }
}

void checkSurface(const Surface& surface) {
  if (surface.patches.empty()) throw Error("surface distance: the surface has no patches");
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    const BezierPatch& patch = surface.patches[i];
    if (patch.degreeU < 1 || patch.degreeV < 1 || patch.degreeU > kMaxPatchDegree ||
        patch.degreeV > kMaxPatchDegree) {
      throw Error(
          fmt::format("surface distance: patches[{}]: degrees must be 1 .. {}, got ({}, {})", i,
                      kMaxPatchDegree, patch.degreeU, patch.degreeV));
    }
    const auto expected = static_cast<std::size_t>((patch.degreeU + 1) * (patch.degreeV + 1));
    if (patch.control.size() != expected) {
      throw Error(
          fmt::format("surface distance: patches[{}]: bidegree ({}, {}) needs {} control "
                      "points, got {}",
                      i, patch.degreeU, patch.degreeV, expected, patch.control.size()));
    }
    for (std::size_t c = 0; c < patch.control.size(); ++c) {
      if (!isFinite(patch.control[c])) {
        throw Error(
            fmt::format("surface distance: patches[{}]: control point {} is not finite", i, c));
      }
    }
    if (patch.rational()) {
      if (patch.weights.size() != expected)
        throw Error(fmt::format("surface distance: patches[{}]: {} weights for {} control points", i,
                                patch.weights.size(), expected));
      const double largest = *std::max_element(patch.weights.begin(), patch.weights.end());
      for (std::size_t c = 0; c < patch.weights.size(); ++c)
        if (!(patch.weights[c] > 0.0) || !std::isfinite(patch.weights[c]) ||
            !(patch.weights[c] * kMaxWeightRatio >= largest))
          throw Error(fmt::format("surface distance: patches[{}]: weight {} is {}: weights must be positive, finite "
                                  "and within a ratio of {:g}",
                                  i, c, patch.weights[c], kMaxWeightRatio));
    }
  }
}

// The tree of a piece (`patch`) of the surface's patch `original` (the same patch when it is
// whole), whose scale and weight ratio set the rounding allowance.
PatchTree buildTree(const BezierPatch& patch, const BezierPatch& original, const PieceOf& piece, int depth) {
  PatchTree tree;
  tree.piece = piece;
  tree.degreeU = patch.degreeU;
  tree.degreeV = patch.degreeV;
  tree.points = patch.control.size();
  tree.rational = patch.rational();
  tree.stride = tree.rational ? 2 * tree.points : tree.points;
  tree.levels = depth + 1;
  for (const Vec3& c : original.control) tree.scale = std::max(tree.scale, maxAbs(c));
  tree.nets.resize(static_cast<std::size_t>(tree.levels));
  tree.boxes.resize(static_cast<std::size_t>(tree.levels));
  tree.nets[0] = patch.control;
  if (tree.rational) {
    const auto [least, largest] = std::minmax_element(original.weights.begin(), original.weights.end());
    tree.weightRatio = *largest / *least;
    for (const double w : patch.weights) tree.nets[0].push_back({w, 0.0, 0.0});
  }
  for (int level = 0; level < tree.levels; ++level) {
    const auto side = std::size_t{1} << level;
    const auto L = static_cast<std::size_t>(level);
    std::vector<Box>& boxes = tree.boxes[L];
    boxes.resize(side * side);
    for (std::size_t i = 0; i < side * side; ++i) {
      boxes[i] = boxOf(tree.nets[L].data() + i * tree.stride, tree.points);
    }
    if (level + 1 == tree.levels) break;
    std::vector<Vec3>& children = tree.nets[L + 1];
    children.resize(4 * side * side * tree.stride);
    std::vector<Vec3> quarters(4 * tree.stride);
    for (std::size_t iu = 0; iu < side; ++iu) {
      for (std::size_t iv = 0; iv < side; ++iv) {
        halveTreeNet(tree, tree.nets[L].data() + (iu * side + iv) * tree.stride, quarters.data());
        for (std::size_t a = 0; a < 2; ++a) {
          for (std::size_t b = 0; b < 2; ++b) {
            const std::size_t child = (2 * iu + a) * (2 * side) + (2 * iv + b);
            std::copy_n(quarters.begin() + static_cast<std::ptrdiff_t>((2 * a + b) * tree.stride),
                        tree.stride,
                        children.begin() + static_cast<std::ptrdiff_t>(child * tree.stride));
          }
        }
      }
    }
  }
  return tree;
}

// Long thin patches cut into pieces (see the contract's Pieces).
struct CutPiece {
  BezierPatch patch;
  PieceOf of;
};

// The longest of a net's control polygons along u (alongU) or v: a bound on the length of
// the patch's parameter lines that way.
double longestPolygon(const BezierPatch& patch, bool alongU) {
  const int m = patch.degreeU, n = patch.degreeV;
  double longest = 0.0;
  for (int line = 0; line <= (alongU ? n : m); ++line) {
    double length = 0.0;
    for (int i = 0; i < (alongU ? m : n); ++i)
      length += alongU ? norm(patch.at(i + 1, line) - patch.at(i, line)) : norm(patch.at(line, i + 1) - patch.at(line, i));
    longest = std::max(longest, length);
  }
  return longest;
}

std::vector<CutPiece> cutLongPatches(const Surface& surface, bool cut) {
  // Halvings wanted per patch in u and v: the longer way halved until it is at most twice the
  // other (an aspect of 2^kMaxPieceHalvings at most is evened out).
  std::vector<std::pair<int, int>> wanted;
  wanted.reserve(surface.patches.size());
  for (const BezierPatch& patch : surface.patches) {
    double lu = longestPolygon(patch, true), lv = longestPolygon(patch, false);
    int ku = 0, kv = 0;
    for (; cut && ku < kMaxPieceHalvings && lu > 2.0 * lv; ++ku) lu *= 0.5;
    for (; cut && kv < kMaxPieceHalvings && lv > 2.0 * lu; ++kv) lv *= 0.5;
    wanted.emplace_back(ku, kv);
  }
  // Within kPiecesBudget: every patch's halvings capped alike, the cap lowered until it fits.
  int cap = kMaxPieceHalvings;
  const auto piecesAt = [&](int c) {
    std::size_t count = 0;
    for (const auto& [ku, kv] : wanted) count += std::size_t{1} << (std::min(ku, c) + std::min(kv, c));
    return count;
  };
  while (cap > 0 && piecesAt(cap) > std::max(kPiecesBudget, surface.patches.size())) --cap;
  std::vector<CutPiece> pieces;
  pieces.reserve(piecesAt(cap));
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    const int ku = std::min(wanted[i].first, cap), kv = std::min(wanted[i].second, cap);
    const std::size_t first = pieces.size();
    pieces.push_back({surface.patches[i], PieceOf{static_cast<std::uint32_t>(i)}});
    // Halved at 1/2 (de Casteljau, as the cells are), u first: the pieces in u-major order.
    for (int level = 0; level < ku + kv; ++level) {
      const bool inU = level < ku;
      const std::size_t end = pieces.size();
      std::vector<CutPiece> halves;
      halves.reserve(2 * (end - first));
      for (std::size_t k = first; k < end; ++k) {
        auto [low, high] = inU ? subdivideU(pieces[k].patch, 0.5) : subdivideV(pieces[k].patch, 0.5);
        PieceOf a = pieces[k].of;
        ++a.splits;
        (inU ? a.du : a.dv) *= 0.5;
        PieceOf b = a;
        (inU ? b.u0 : b.v0) += inU ? a.du : a.dv;
        halves.push_back({std::move(low), a});
        halves.push_back({std::move(high), b});
      }
      pieces.resize(first);
      for (CutPiece& half : halves) pieces.push_back(std::move(half));
    }
  }
  return pieces;
}

// Cells of trimmed patches classified, kept per thread across queries (keyed by the
// SurfaceDistance's id, patch, depth and position): consecutive queries classify the same
// cells, and classifying one clips the face's arcs down to its size. A direct-mapped table
// (a slot per hash, overwritten on collision: a lost entry is classified again, to the same
// place), no allocation per cell.
struct TrimCellCache {
  static constexpr std::size_t kSlots = std::size_t{1} << 18;
  struct Slot {
    std::uint64_t id = 0, iu = 0, iv = 0;  // id 0: empty (SurfaceDistance ids start at 1)
    std::uint32_t patch = 0;
    int depth = 0;
    CellPlace place = CellPlace::boundary;
  };
  std::vector<Slot> slots = std::vector<Slot>(kSlots);
  // The last point whose place was asked (placeOfCell): the four quarters of a split share it.
  struct Point {
    std::uint64_t id = 0;  // 0: none
    std::size_t patch = 0;
    double s = 0.0, t = 0.0;
    CellPlace place = CellPlace::boundary;
  } lastPoint;
};

// A trimmed cell's place (face_trim.hpp's classifyCell, but for the point it asks): boundary
// when an arc may meet it, else the place of its corner at its parent's centre. A cell no arc
// meets lies wholly on one side of the trim, so any of its points tells (placeOfPoint); that
// corner is its three siblings' too, so the four quarters of a split cost one winding
// computation, not four. A pure function of the cell, like the cache that keeps it: the same for any order of
// queries and any thread.
CellPlace placeOfCell(const std::vector<PatchTrim>& trims, std::uint64_t id, const PatchTree& tree, const Cell& cell,
                      std::uint64_t iu, std::uint64_t iv, TrimCellCache& cache) {
  const std::size_t patch = tree.piece.original;
  const PatchTrim& trim = trims[patch];
  const double h = cellSide(cell.depth);
  const ParameterCell image{originalU(tree, cell.u0), originalU(tree, cell.u0 + h), originalV(tree, cell.v0),
                            originalV(tree, cell.v0 + h)};
  if (cellMayMeetTrim(trim, image)) return CellPlace::boundary;
  // The parent's centre: a cell at an even position has it at its far corner (a root cell,
  // at 0, at (1, 1)). cell.u0 + h is computed as its sibling's u0 was (parent u0 + half),
  // so the siblings ask the very same point.
  const double s = (iu & 1) != 0 ? image.u0 : image.u1;
  const double t = (iv & 1) != 0 ? image.v0 : image.v1;
  TrimCellCache::Point& last = cache.lastPoint;
  if (last.id != id || last.patch != patch || last.s != s || last.t != t) {
    last = {id, patch, s, t, placeOfPoint(trim, s, t)};
  }
  return last.place;
}

// A trimmed patch's cell (trims non-null and the patch trimmed, the cell not known inside):
// false when it lies outside the face (dropped), else marks it when it lies inside. The place
// is remembered beside the cell (its tree's places, or the cell store's), and the per-thread
// table is asked only the first time: it outlives the store's cells.
bool classifyForTrim(const std::vector<PatchTrim>* trims, std::uint64_t id, const PatchTree& tree,
                     CellStore& store, Cell& cell) {
  if (cell.inFace) return true;
  if (trims == nullptr || !(*trims)[tree.piece.original].trimmed()) {
    cell.inFace = true;  // all of an untrimmed patch is surface
    return true;
  }
  std::atomic<std::uint8_t>* treePlace = nullptr;
  std::uint8_t* storePlace = nullptr;
  std::uint8_t known = 0;
  if (cell.inTree && tree.places) {
    treePlace = &tree.places[tree.placeOffset[static_cast<std::size_t>(cell.depth)] + cell.net];
    known = treePlace->load(std::memory_order_relaxed);
  } else if (!cell.inTree) {
    storePlace = &store.places[cell.box];
    known = *storePlace;
  }
  CellPlace place;
  if (known != 0) {
    place = static_cast<CellPlace>(known - 1);
  } else {
    thread_local TrimCellCache cache;
    const double cells = cellSide(-cell.depth);
    const auto iu = static_cast<std::uint64_t>(cell.u0 * cells), iv = static_cast<std::uint64_t>(cell.v0 * cells);
    // Cells classified one after another lie side by side (a cell's quarters, the next
    // query's cells beside the last's), so an 8 x 8 block of cells shares a run of 64 slots:
    // the table is read a few cache lines at a time, not at random (perf: a random slot's
    // cache miss was a quarter of the screw's exact-trims paths).
    const auto block = static_cast<std::size_t>(mixCellKey(iu >> 3, iv >> 3, cell.patch, cell.depth) ^
                                                (id * 0xD6E8FEB86659FD93ULL));
    TrimCellCache::Slot& slot =
        cache.slots[(block << 6 | static_cast<std::size_t>((iu & 7) << 3 | (iv & 7))) & (TrimCellCache::kSlots - 1)];
    if (slot.id != id || slot.iu != iu || slot.iv != iv || slot.patch != cell.patch || slot.depth != cell.depth) {
      slot = {id, iu, iv, cell.patch, cell.depth,
              placeOfCell(*trims, id, tree, cell, iu, iv, cache)};
    }
    place = slot.place;
    const auto code = static_cast<std::uint8_t>(static_cast<std::uint8_t>(place) + 1);
    if (treePlace != nullptr) treePlace->store(code, std::memory_order_relaxed);
    if (storePlace != nullptr) *storePlace = code;
  }
  if (place == CellPlace::outside) return false;
  cell.inFace = place == CellPlace::inside;
  return true;
}

// Whether a surface point of the piece counts (a trimmed patch's points outside its face do not).
bool inFace(const std::vector<PatchTrim>* trims, const PatchTree& tree, double u, double v) {
  return trims == nullptr || keepsPoint((*trims)[tree.piece.original], originalU(tree, u), originalV(tree, v));
}

// The branch and bound of the contract (`scale`: the surface's, surfaceScale).
ClosestPoint search(const Surface& surface, double scale, const std::vector<PatchTree>& trees,
                    const std::vector<PatchNode>& nodes, const std::vector<std::uint32_t>& nodePatches,
                    std::uint64_t id, double tolerance, std::size_t maxCells, Vec3 p, double cutoff) {
  if (!isFinite(p)) {
    throw Error(
        fmt::format("surface distance: the query point ({}, {}, {}) is not finite", p.x, p.y, p.z));
  }
  if (std::isnan(cutoff)) throw Error("surface distance: the cutoff is NaN");
  thread_local Scratch scratch;
  std::vector<Cell>& heap = scratch.heap;
  CellStore& store = scratch.store;
  heap.clear();
  store.prepare(id, surface.trimmed());

  Candidate best;
  double setAside = kInfinity;  // the least lower bound of the cells dropped
  std::size_t cells = 0;
  const double pScale = maxAbs(p);
  const auto level = [&] { return std::min(best.distance - tolerance, cutoff); };
  const std::vector<PatchTrim>* trims = surface.trimmed() ? &surface.trims : nullptr;
  bool trimResolved = false;  // a cell on a trimming curve was left at kTrimCellDepth
  // Points of cells on a trimming curve are not offered as corners (`known` false there): the
  // inside cells beside them, as fine, offer theirs; centres and Newton points are tested.
  const auto consider = [&](Vec3 q, std::size_t patch, double u, double v, bool known) {
    const double d = norm(q - p);
    if (d < best.distance && known) best = {d, patch, u, v, q};
  };
  // Bounds a new cell: its corners are surface points (upper bounds); then its lower bound,
  // the axis-aligned box first (cheap, precomputed in the tree) and the separating plane
  // only if the cell survives that; then queued or set aside.
  const auto offer = [&](Cell&& cell, unsigned fresh) {
    ++cells;
    if (!classifyForTrim(trims, id, trees[cell.patch], store, cell)) return;
    const PatchTree& tree = trees[cell.patch];
    const Vec3* net = cellNet(tree, cell, store);
    const Box box = cornersAndBox(tree, cell, net, fresh, store, consider);
    const double allowance = cellAllowance(tree, cell.depth, pScale);
    const int m = tree.degreeU;
    const int n = tree.degreeV;
    double lower = boxDistance(box, p);
    if (lower - allowance < level()) lower = std::max(lower, separatingPlaneDistance(net, m, n, p));
    lower = std::max(0.0, lower - allowance);
    if (lower >= level()) {
      setAside = std::min(setAside, lower);
      return;
    }
    pushCell(heap, cell, lower);
  };

  NodeWalk walk(
      nodes, nodePatches, scratch.nodes, heap,
      [&](const PatchNode& node) {
        return std::max(0.0, boxDistance(node.box, p) - node.allowanceCoefficient * (node.scale + pScale));
      },
      [&](double lower) { return lower < level(); }, [&](double lower) { setAside = std::min(setAside, lower); },
      offer);
  double lowerBound = kInfinity;  // of the cells still queued when the search stops
  for (;;) {
    walk.advance();
    if (heap.empty()) break;
    std::pop_heap(heap.begin(), heap.end(), ByLowerBound{});
    const Cell cell = heap.back();
    heap.pop_back();
    if (cell.lower >= level()) {  // the least lower bound left: nothing better remains
      lowerBound = cell.lower;
      break;
    }
    const BezierPatch& patch = trees[cell.patch].patch;
    const double h = cellSide(cell.depth);
    const double uc = cell.u0 + 0.5 * h;
    const double vc = cell.v0 + 0.5 * h;
    const Jet jet = jetAt(patch, uc, vc);
    if (norm(jet.r - p) < best.distance) {
      const Candidate polished = newton(patch, cell.patch, p, uc, vc, jet);
      consider(jet.r, cell.patch, uc, vc, cell.inFace || inFace(trims, trees[cell.patch], uc, vc));
      // Newton may leave the cell: its point is always tested.
      // A point of a cell known inside the face is in it (no winding to count).
      const bool inCell = polished.u >= cell.u0 && polished.u <= cell.u0 + h && polished.v >= cell.v0 &&
                          polished.v <= cell.v0 + h;
      consider(polished.point, cell.patch, polished.u, polished.v,
               (cell.inFace && inCell) || inFace(trims, trees[cell.patch], polished.u, polished.v));
    }
    if (cell.lower >= level()) {
      setAside = std::min(setAside, cell.lower);
      continue;
    }
    const PatchTree& tree = trees[cell.patch];
    const double convex =
        convexLowerBound(cellNet(tree, cell, store), patch, cell.patch, cell.u0, cell.v0, h, best, p) -
        cellAllowance(tree, cell.depth, pScale);
    if (convex >= level()) {
      setAside = std::min(setAside, std::max(cell.lower, convex));
      continue;
    }
    if (cell.depth >= kMaxCellDepth) {  // cannot be split: its bound stays what it is
      setAside = std::min(setAside, cell.lower);
      continue;
    }
    if (cell.depth >= kTrimCellDepth && !cell.inFace) {
      // On a trimming curve (cells of untrimmed patches are all inFace) and as fine as the
      // trim is followed: its bound stands.
      setAside = std::min(setAside, cell.lower);
      trimResolved = true;
      continue;
    }
    if (cells >= maxCells) {
      lowerBound = cell.lower;
      break;
    }
    offerQuarters(cell, tree, store, offer);
  }

  ClosestPoint result;
  result.distance = best.distance;
  if (std::isfinite(best.distance)) {
    const PatchTree& tree = trees[best.patch];
    result.patch = tree.piece.original;
    result.u = originalU(tree, best.u);
    result.v = originalV(tree, best.v);
  }
  result.point = best.point;
  result.lowerBound = std::max(0.0, std::min({lowerBound, walk.waiting(), setAside, best.distance}));
  // Beside a trimming curve the bound is as fine as the cells there (see the contract).
  const double reach = trimResolved ? tolerance + kTrimCellReach * (scale + pScale) : tolerance;
  result.converged = best.distance - result.lowerBound <= reach || result.lowerBound >= cutoff;
  result.cells = cells;
  return result;
}

// ---------------------------------------------------------------------------------------
// Segment clearance
// ---------------------------------------------------------------------------------------

// The segment [a, b] of a clearance query, with what every cell's bounds take from it
// (computed once per query, the same values as per cell).
struct QuerySegment {
  Vec3 a, b;
  Vec3 ab;         // b - a
  double length2;  // dot(ab, ab)
  Vec3 lo, hi;     // its box
  explicit QuerySegment(Vec3 a_, Vec3 b_)
      : a(a_), b(b_), ab(b_ - a_), length2(dot(ab, ab)),
        lo{std::min(a_.x, b_.x), std::min(a_.y, b_.y), std::min(a_.z, b_.z)},
        hi{std::max(a_.x, b_.x), std::max(a_.y, b_.y), std::max(a_.z, b_.z)} {}
};

// The point of the segment nearest to p.
Vec3 nearestOnSegment(const QuerySegment& s, Vec3 p) {
  if (!(s.length2 > 0.0)) return s.a;
  return s.a + std::clamp(dot(p - s.a, s.ab) / s.length2, 0.0, 1.0) * s.ab;
}

// A lower bound of the distance between a box and the segment: the gap between the box and
// the segment's own box (exact for an axis-parallel segment, loose for a diagonal one; the
// separating plane below takes over there).
double boxSegmentDistance(const Box& box, const QuerySegment& s) {
  const double dx = std::max({0.0, box.lo.x - s.hi.x, s.lo.x - box.hi.x});
  const double dy = std::max({0.0, box.lo.y - s.hi.y, s.lo.y - box.hi.y});
  const double dz = std::max({0.0, box.lo.z - s.hi.z, s.lo.z - box.hi.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// A separating plane between the cell and the segment: w the unit direction from the
// segment's point nearest to the mean of the net's corners to that mean; every point of the
// cell's convex hull lies at least min_i c_i . w along w, every point of the segment at most
// max(a . w, b . w) (a linear function's maximum is at an end), so their distance is at
// least the difference. Near a contact w tends to the common normal, along which the net is
// O(h^2) thin and a segment tangent to the offset surface O(length^2) thick.
double separatingPlaneSegmentDistance(const Vec3* net, int m, int n, const QuerySegment& s) {
  const int stride = n + 1;
  const Vec3 mean = 0.25 * (net[0] + net[n] + net[m * stride] + net[m * stride + n]);
  const Vec3 toCell = mean - nearestOnSegment(s, mean);
  const double length = norm(toCell);
  if (!(length > 0.0)) return 0.0;
  const Vec3 w = toCell / length;
  const double least = leastAlong<false>(net, (m + 1) * stride, {}, w);
  return std::max(0.0, least - std::max(dot(s.a, w), dot(s.b, w)));
}

SegmentClearance segmentSearch(const std::vector<PatchTree>& trees, const std::vector<PatchNode>& nodes,
                               const std::vector<std::uint32_t>& nodePatches, const std::vector<PatchTrim>* trims,
                               std::uint64_t id, Vec3 a, Vec3 b, double clearance, std::size_t maxCells) {
  if (!isFinite(a) || !isFinite(b)) {
    throw Error(fmt::format("segment clearance: the segment ({}, {}, {}) - ({}, {}, {}) is not "
                            "finite", a.x, a.y, a.z, b.x, b.y, b.z));
  }
  if (!std::isfinite(clearance)) throw Error("segment clearance: the clearance is not finite");
  thread_local Scratch scratch;
  std::vector<Cell>& heap = scratch.heap;
  CellStore& store = scratch.store;
  heap.clear();
  store.prepare(id, trims != nullptr);
  SegmentClearance result;
  // The nearest point's piece and parameters as the surface's patch and its parameters.
  const auto inOriginalPatch = [&trees](SegmentClearance found) {
    if (std::isfinite(found.distance)) {
      const PatchTree& tree = trees[found.patch];
      found.patch = tree.piece.original;
      found.u = originalU(tree, found.u);
      found.v = originalV(tree, found.v);
    }
    return found;
  };
  const QuerySegment segment(a, b);
  const double pScale = std::max(maxAbs(a), maxAbs(b));
  bool trimUnresolved = false;  // a cell on a trimming curve left at kTrimCellDepth within the clearance
  // A surface point nearer than the clearance refutes it; the nearest seen is kept.
  bool violated = false;
  // Corners of cells on a trimming curve are not tested (`known` false): the inside cells
  // beside them, as fine, offer theirs.
  const auto consider = [&](Vec3 q, std::uint32_t patch, double u, double v, bool known) {
    if (!known) return;
    const double d = norm(q - nearestOnSegment(segment, q));
    if (d < result.distance) {
      result.distance = d;
      result.patch = patch;
      result.u = u;
      result.v = v;
      result.point = q;
    }
    if (d < clearance) violated = true;
  };
  const auto offer = [&](Cell&& cell, unsigned fresh) {
    ++result.cells;
    if (!classifyForTrim(trims, id, trees[cell.patch], store, cell)) return;
    const PatchTree& tree = trees[cell.patch];
    const Vec3* net = cellNet(tree, cell, store);
    const Box box = cornersAndBox(tree, cell, net, fresh, store, consider);
    const double allowance = cellAllowance(tree, cell.depth, pScale);
    const int m = tree.degreeU;
    const int n = tree.degreeV;
    double lower = boxSegmentDistance(box, segment);
    if (lower - allowance < clearance) {
      lower = std::max(lower, separatingPlaneSegmentDistance(net, m, n, segment));
    }
    lower -= allowance;
    if (lower >= clearance) return;  // proven clear
    pushCell(heap, cell, lower);
  };
  // A surface of one leaf offers its root cells in order, stopping at the first violation.
  const auto offerUnlessViolated = [&](Cell&& cell, unsigned fresh) {
    if (!violated) offer(std::move(cell), fresh);
  };
  NodeWalk walk(
      nodes, nodePatches, scratch.nodes, heap,
      [&](const PatchNode& node) {
        return boxSegmentDistance(node.box, segment) - node.allowanceCoefficient * (node.scale + pScale);
      },
      [&](double lower) { return lower < clearance; }, [](double) {}, offerUnlessViolated);
  for (;;) {
    if (violated) break;
    walk.advance();
    if (heap.empty() || violated) break;
    std::pop_heap(heap.begin(), heap.end(), ByLowerBound{});
    const Cell cell = heap.back();
    heap.pop_back();
    const PatchTree& tree = trees[cell.patch];
    if (cell.depth >= kMaxCellDepth || result.cells >= maxCells) {
      result.verdict = Clearance::undecided;
      return inOriginalPatch(result);
    }
    if (cell.depth >= kTrimCellDepth && !cell.inFace) {  // on a trimming curve (see search)
      trimUnresolved = true;  // on a trimming curve, as fine as the trim is followed: not proven
      continue;
    }
    offerQuarters(cell, tree, store, offer);
  }
  result.verdict = violated ? Clearance::violated : trimUnresolved ? Clearance::undecided : Clearance::proven;
  return inOriginalPatch(result);
}

// ---------------------------------------------------------------------------------------
// Tool-path sampling
// ---------------------------------------------------------------------------------------

// One stretch of the path to sample: a line or an arc from `from` to `to`.
struct Segment {
  std::size_t pass = 0;
  std::size_t move = 0;
  bool onLink = false;
  bool sampleStart = false;  // the first centre of a retracted pass
  MoveKind kind = MoveKind::line;
  Vec3 from;
  Vec3 to;
  // Arcs, in plane coordinates: the centre, start angle, signed sweep, radii, heights.
  ArcPlane plane = ArcPlane::xy;
  Vec3 center;
  double angle0 = 0.0;
  double sweep = 0.0;
  double radius0 = 0.0;
  double radius1 = 0.0;
  double height0 = 0.0;
  double height1 = 0.0;
  double length = 0.0;    // an upper bound on the arc length
  std::size_t steps = 0;  // intervals between samples
};

Vec3 positionOn(const Segment& s, std::size_t i) {
  if (i == 0) return s.from;
  if (i == s.steps) return s.to;  // vertices exactly
  const double t = static_cast<double>(i) / static_cast<double>(s.steps);
  if (s.kind == MoveKind::line) return s.from + t * (s.to - s.from);
  const double angle = s.angle0 + t * s.sweep;
  const double radius = s.radius0 + t * (s.radius1 - s.radius0);
  return fromArcPlane(s.plane,
                   {s.center.x + radius * std::cos(angle), s.center.y + radius * std::sin(angle),
                    s.height0 + t * (s.height1 - s.height0)});
}

std::string where(std::size_t pass, std::size_t move, bool onLink) {
  return onLink ? fmt::format("passes[{}] (link)", pass)
                : fmt::format("passes[{}].moves[{}]", pass, move);
}

void requireFinite(Vec3 a, const std::string& what) {
  if (!isFinite(a)) {
    throw Error(fmt::format("gougeCheck: {} is not finite: ({}, {}, {})", what, a.x, a.y, a.z));
  }
}

Segment arcSegment(Segment s, const ToolMove& move) {
  const std::string name = where(s.pass, s.move, false);
  requireFinite(move.center, name + ".center");
  s.plane = move.plane;
  const Vec3 a = toArcPlane(move.plane, s.from);
  const Vec3 b = toArcPlane(move.plane, s.to);
  s.center = toArcPlane(move.plane, move.center);
  s.radius0 = std::hypot(a.x - s.center.x, a.y - s.center.y);
  s.radius1 = std::hypot(b.x - s.center.x, b.y - s.center.y);
  const double radius = std::max(s.radius0, s.radius1);
  if (!(s.radius0 > 0.0) || !(s.radius1 > 0.0)) {
    throw Error(
        fmt::format("gougeCheck: {}: arc end at its centre (radius {} at the start, {} at "
                    "the end)",
                    name, s.radius0, s.radius1));
  }
  if (s.from == s.to) {
    throw Error(
        fmt::format("gougeCheck: {}: arc starts where it ends (a full circle is not "
                    "allowed)",
                    name));
  }
  const double slack = 1e-6 * radius;  // "the same distance, within rounding" (toolpath.hpp)
  if (std::abs(s.radius0 - s.radius1) > slack) {
    throw Error(
        fmt::format("gougeCheck: {}: arc ends at different distances from the centre: "
                    "{} and {}",
                    name, s.radius0, s.radius1));
  }
  if (std::abs(a.z - s.center.z) > slack || std::abs(b.z - s.center.z) > slack) {
    throw Error(
        fmt::format("gougeCheck: {}: arc ends and centre are not in one plane normal to "
                    "its axis ({}, {} and {} along it)",
                    name, a.z, b.z, s.center.z));
  }
  s.height0 = a.z;
  s.height1 = b.z;
  s.angle0 = std::atan2(a.y - s.center.y, a.x - s.center.x);
  const double angle1 = std::atan2(b.y - s.center.y, b.x - s.center.x);
  // Counter-clockwise turns through increasing angle; the sweep is in (0, 2 pi].
  double sweep = move.clockwise ? s.angle0 - angle1 : angle1 - s.angle0;
  if (sweep <= 0.0) sweep += 2.0 * std::numbers::pi;
  s.sweep = move.clockwise ? -sweep : sweep;
  // |d/dt (r cos, r sin, z)| <= sqrt((r_max sweep)^2 + dr^2 + dz^2) pointwise.
  s.length = std::sqrt(radius * sweep * radius * sweep +
                       (s.radius1 - s.radius0) * (s.radius1 - s.radius0) +
                       (s.height1 - s.height0) * (s.height1 - s.height0));
  return s;
}

std::vector<Segment> segmentsOf(const ToolPath& path) {
  std::vector<Segment> segments;
  Vec3 previousEnd;
  for (std::size_t i = 0; i < path.passes.size(); ++i) {
    const ToolPass& pass = path.passes[i];
    requireFinite(pass.start, fmt::format("passes[{}].start", i));
    const bool linked = i > 0 && !pass.retractBefore;
    Segment first;
    first.pass = i;
    if (linked) {
      first.onLink = true;
      first.from = previousEnd;
      first.to = pass.start;
      first.length = norm(pass.start - previousEnd);
      segments.push_back(first);
    } else {  // the pass's first centre, alone: a zero-length line sampled at its start
      first.sampleStart = true;
      first.from = pass.start;
      first.to = pass.start;
      segments.push_back(first);
    }
    Vec3 at = pass.start;
    for (std::size_t k = 0; k < pass.moves.size(); ++k) {
      const ToolMove& move = pass.moves[k];
      requireFinite(move.end, where(i, k, false) + ".end");
      Segment s;
      s.pass = i;
      s.move = k;
      s.kind = move.kind;
      s.from = at;
      s.to = move.end;
      if (move.kind == MoveKind::arc) {
        s = arcSegment(s, move);
      } else {
        s.length = norm(move.end - at);
      }
      segments.push_back(s);
      at = move.end;
    }
    previousEnd = at;
  }
  return segments;
}

}  // namespace

SurfaceDistance::SurfaceDistance(const Surface& surface, const DistanceOptions& options)
    : surface_(surface), options_(options) {
  checkSurface(surface_);
  if (!(options.tolerance >= 0.0) || !std::isfinite(options.tolerance)) {
    throw Error(fmt::format("surface distance: the tolerance must be finite and >= 0, got {}",
                            options.tolerance));
  }
  if (options.treeDepth < 0 || options.treeDepth > kMaxTreeDepth) {
    throw Error(fmt::format("surface distance: treeDepth must be 0 .. {}, got {}", kMaxTreeDepth,
                            options.treeDepth));
  }
  if (options.maxCells < 1) throw Error("surface distance: maxCells must be >= 1");
  // Ids from 1 (0 marks an empty cell store); copies share theirs with the cells they hold.
  static std::atomic<std::uint64_t> lastId{0};
  id_ = lastId.fetch_add(1, std::memory_order_relaxed) + 1;
  scale_ = surfaceScale(surface_);
  tolerance_ = options.tolerance > 0.0 ? options.tolerance : 1e-9 * scale_;
  // A surface collapsed to the origin has scale 0; any positive tolerance will do there.
  if (!(tolerance_ > 0.0)) tolerance_ = std::numeric_limits<double>::min();
  std::vector<CutPiece> pieces = cutLongPatches(surface_, options.cutLongPatches);
  // The trees' depth, lowered for all patches alike to keep within kTreePointsBudget: deeper
  // cells are halved on demand as the same bits (the contract), so only speed depends on it.
  int depth = options.treeDepth;
  const auto pointsAt = [&](int levels) {
    std::size_t points = 0;
    const std::size_t cells = ((std::size_t{1} << (2 * (levels + 1))) - 1) / 3;
    for (const CutPiece& piece : pieces)
      points += cells * piece.patch.control.size() * (piece.patch.rational() ? 2 : 1);
    return points;
  };
  while (depth > 0 && pointsAt(depth) > kTreePointsBudget) --depth;
  trees_.reserve(pieces.size());
  for (CutPiece& piece : pieces) {
    trees_.push_back(buildTree(piece.patch, surface_.patches[piece.of.original], piece.of, depth));
    PatchTree& tree = trees_.back();
    tree.patch = std::move(piece.patch);
    if (surface_.trimmed() && surface_.trims[piece.of.original].trimmed()) {
      std::size_t cells = 0;
      for (int level = 0; level < tree.levels; ++level) {
        tree.placeOffset.push_back(cells);
        cells += std::size_t{1} << (2 * level);
      }
      tree.places = std::shared_ptr<std::atomic<std::uint8_t>[]>(new std::atomic<std::uint8_t>[cells]());  // all 0
    }
  }
  buildHierarchy(trees_, nodes_, nodePatches_);
}

SurfaceDistance::~SurfaceDistance() = default;
SurfaceDistance::SurfaceDistance(const SurfaceDistance&) = default;
SurfaceDistance::SurfaceDistance(SurfaceDistance&&) noexcept = default;
SurfaceDistance& SurfaceDistance::operator=(const SurfaceDistance&) = default;
SurfaceDistance& SurfaceDistance::operator=(SurfaceDistance&&) noexcept = default;

ClosestPoint SurfaceDistance::closest(Vec3 p) const { return closest(p, kInfinity); }

ClosestPoint SurfaceDistance::closest(Vec3 p, double cutoff) const {
  return search(surface_, scale_, trees_, nodes_, nodePatches_, id_, tolerance_, options_.maxCells, p, cutoff);
}

SegmentClearance SurfaceDistance::segmentClearance(Vec3 a, Vec3 b, double clearance,
                                                   std::size_t maxCells) const {
  if (maxCells < 1) throw Error("segment clearance: maxCells must be >= 1");
  return segmentSearch(trees_, nodes_, nodePatches_, surface_.trimmed() ? &surface_.trims : nullptr, id_, a, b,
                       clearance, maxCells);
}

double distanceToSurface(const Surface& surface, Vec3 p, const DistanceOptions& options) {
  return closestPointOnSurface(surface, p, options).distance;
}

ClosestPoint closestPointOnSurface(const Surface& surface, Vec3 p, const DistanceOptions& options) {
  return SurfaceDistance(surface, options).closest(p);
}

GougeReport gougeCheck(const Surface& surface, const ToolPath& path, double sampleSpacing,
                       const GougeOptions& options) {
  return gougeCheck(SurfaceDistance(surface, options.distance), path, sampleSpacing, options);
}

GougeReport gougeCheck(const SurfaceDistance& distance, const ToolPath& path, double sampleSpacing,
                       const GougeOptions& options) {
  if (!(sampleSpacing > 0.0) || !std::isfinite(sampleSpacing)) {
    throw Error(fmt::format(
        "gougeCheck: the sample spacing must be a positive finite length, got {}", sampleSpacing));
  }
  const double radius = path.toolRadius;
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw Error(
        fmt::format("gougeCheck: the tool radius must be positive and finite, got {}", radius));
  }
  if (path.units != distance.surface().units) {
    throw Error(fmt::format("gougeCheck: the tool path is in {} but the surface in {}",
                            unitsName(path.units), unitsName(distance.surface().units)));
  }
  if (std::isnan(options.depthThreshold)) throw Error("gougeCheck: the depth threshold is NaN");

  std::vector<Segment> segments = segmentsOf(path);
  // Count before sampling: a tiny spacing on a long path must fail fast, not run for hours.
  double total = 0.0;
  double length = 0.0;
  double maxGap = 0.0;
  for (Segment& s : segments) {
    const double steps = std::ceil(s.length / sampleSpacing);
    total += steps + (s.sampleStart ? 1.0 : 0.0);
    length += s.length;
    if (total > static_cast<double>(options.maxSamples)) {
      throw Error(
          fmt::format("gougeCheck: a sample spacing of {} needs more than {} samples on "
                      "this path (more than {} of path length so far); use a larger spacing "
                      "or raise maxSamples",
                      sampleSpacing, options.maxSamples, length));
    }
    s.steps = static_cast<std::size_t>(steps);
    if (s.steps > 0) maxGap = std::max(maxGap, s.length / static_cast<double>(s.steps));
  }

  // Blocks of consecutive segments of about kGougeSamplesPerBlock samples (see the contract).
  std::vector<std::size_t> blockStarts{0};
  std::size_t inBlock = 0;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    if (inBlock >= kGougeSamplesPerBlock) {
      blockStarts.push_back(k);
      inBlock = 0;
    }
    inBlock += segments[k].steps + 1;
  }
  blockStarts.push_back(segments.size());
  const double countBelow = radius - options.depthThreshold;
  struct Block {
    double least = kInfinity;        // the least distance found
    double leastProven = kInfinity;  // the least lower bound of any sample's distance
    std::size_t samples = 0, deeper = 0, startsBelow = 0;
    GougeLocation deepest;
  };
  std::vector<Block> blocks(blockStarts.size() - 1);
  const auto sampleBlock = [&](std::size_t b) {
    Block& block = blocks[b];
    for (std::size_t k = blockStarts[b]; k < blockStarts[b + 1]; ++k) {
      const Segment& s = segments[k];
      checkCancelled();
      for (std::size_t i = s.sampleStart ? 0 : 1; i <= s.steps; ++i) {
        const Vec3 center = positionOn(s, i);
        // A sample farther than both the least distance so far and R - threshold changes
        // nothing in the block's report: let the search drop it early. A retracted pass's
        // first centre is found in full, for the test of its side.
        const double cutoff = s.sampleStart ? kInfinity : std::max(block.least, countBelow);
        const ClosestPoint contact = distance.closest(center, cutoff);
        ++block.samples;
        block.leastProven = std::min(block.leastProven, contact.lowerBound);
        if (contact.distance < countBelow) ++block.deeper;
        if (contact.distance < block.least) {
          block.least = contact.distance;
          block.deepest = {s.pass, s.move, s.onLink, center, contact};
        }
        if (s.sampleStart && contact.distance > distance.tolerance()) {
          // Material side: opposite the upward normal at the closest point (see the contract);
          // unitNormal's limit on an apex row, where r_u x r_v itself vanishes.
          Vec3 up = unitNormal(distance.surface().patches[contact.patch], contact.u, contact.v);
          if (up.z < 0.0) up = -up;
          if (up.z > 0.0 && dot(center - contact.point, up) < 0.0) ++block.startsBelow;
        }
      }
    }
  };
  // Each block writes only its own slot; an error is the first block's, whatever the timing.
  parallelForEach(blocks.size(), threadCount(options.threads), [&](std::size_t b) {
    advanceStage(b, blocks.size());  // reports on the calling thread only
    sampleBlock(b);
  });

  GougeReport report;
  report.depthThreshold = options.depthThreshold;
  report.maxSampleGap = maxGap;
  report.tolerance = distance.tolerance();
  double least = kInfinity;
  double leastProven = kInfinity;
  for (const Block& block : blocks) {
    report.samples += block.samples;
    report.samplesDeeperThanThreshold += block.deeper;
    report.passStartsBelowSurface += block.startsBelow;
    leastProven = std::min(leastProven, block.leastProven);
    if (block.least < least) {
      least = block.least;
      report.deepest = block.deepest;
    }
  }
  if (report.samples > 0) {
    report.signedMaxDepth = radius - least;
    report.maxDepth = std::max(0.0, report.signedMaxDepth);
    report.depthBound = radius - leastProven + 0.5 * maxGap;
  }
  return report;
}

}  // namespace scallop
