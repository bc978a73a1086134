// The optimal slicing orientation: Gauss map -> stereographic plane -> medial axis ->
// maximisation of tan(alpha) along its edges (eq 13) -> N* (eq 14) -> certificate.
// See include/scallop/optimal_slicing.hpp for the contract.

#include "scallop/slicing/optimal_slicing.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/medial_axis.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {
namespace {

// The certificate proves alpha* less this (6e-6 degree). The polish's contacts are Newton
// accurate (|n . N*| to rounding), so the margin is not for their error but keeps the
// subdivision shallow: near a contact the certified polynomial's minimum is about
// margin sin(2 alpha*) |N|^2, which cells of side ~sqrt(margin) resolve. On the paper's
// surfaces depth 14 proves margins down to 1e-9 (77 / 165 cells at 1e-7, 101 / 213 at 1e-9,
// failing at 1e-10): 1e-7 leaves two decades of headroom for more curved surfaces, in under
// a millisecond.
constexpr double kCertificateMarginRad = 1e-7;
// Halvings of the certified angle when the claim fails (see optimalSlicing's certificate).
constexpr int kCertificateBisections = 48;

Bernstein1 constant(double c) { return Bernstein1{{c}}; }

// R(t)^2 along a medial-axis edge as a polynomial in Bernstein form: eq (15) squared for a
// line/line bisector, eq (16) squared for a point/point one, eq (17) squared (|r(t) - f|^2,
// a quartic) for a point/line parabola.
Bernstein1 radiusSquared(const MedialEdge& edge, const Bernstein1& x, const Bernstein1& y) {
  switch (edge.bisector) {
    case MedialEdge::Bisector::lineLine: {
      const Bernstein1 r{{edge.d0 * edge.sinPsi, edge.d1 * edge.sinPsi}};
      return multiply(r, r);
    }
    case MedialEdge::Bisector::pointPoint: {
      const Bernstein1 d{{edge.d0, edge.d1}};
      return add(multiply(d, d), constant(edge.halfGap * edge.halfGap));
    }
    case MedialEdge::Bisector::pointLine: {
      const Vec2 focus = edge.siteA.a;
      const Bernstein1 dx = subtract(x, constant(focus.x));
      const Bernstein1 dy = subtract(y, constant(focus.y));
      return add(multiply(dx, dx), multiply(dy, dy));
    }
  }
  return constant(0.0);
}

// The parameters in (0, 1) where d/dt tan(alpha) = 0 along the edge: eq (13),
//   (x^2 + y^2 + R^2 + 1) R' - 2 (x x' + y y') R = 0,
// multiplied by 2R and written with Q = R^2 (so R R' = Q'/2):
//   (x^2 + y^2 + Q + 1) Q' - 4 (x x' + y y') Q = 0,
// a polynomial (degree 4 on linear edges with quadratic Q, 7 on parabolic ones with quartic
// Q, as the paper counts after rationalising). Its extra roots (R = 0) are harmless: every
// candidate is evaluated.
std::vector<double> stationaryParameters(const MedialEdge& edge) {
  Bernstein1 x;
  Bernstein1 y;
  if (edge.kind == MedialEdge::Kind::linear) {
    x = Bernstein1{{edge.control[0].x, edge.control[1].x}};
    y = Bernstein1{{edge.control[0].y, edge.control[1].y}};
  } else {
    x = Bernstein1{{edge.control[0].x, edge.control[1].x, edge.control[2].x}};
    y = Bernstein1{{edge.control[0].y, edge.control[1].y, edge.control[2].y}};
  }
  const Bernstein1 q = radiusSquared(edge, x, y);
  const Bernstein1 rho2 = add(multiply(x, x), multiply(y, y));
  const Bernstein1 left = multiply(add(add(rho2, q), constant(1.0)), derivative(q));
  const Bernstein1 xdx = add(multiply(x, derivative(x)), multiply(y, derivative(y)));
  const Bernstein1 f = subtract(left, scale(multiply(xdx, q), 4.0));
  if (isZero(f)) return {};
  return realRoots(f);
}

// A unit vector orthogonal to n.
Vec3 orthogonal(const Vec3& n) {
  const Vec3 helper = std::abs(n.x) < 0.6 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  return normalized(cross(n, helper));
}

double minimumAngle(const std::vector<Vec3>& normals, const Vec3& n) {
  double best = std::numbers::pi / 2.0;
  for (const Vec3& m : normals) {
    best = std::min(best, std::acos(std::min(1.0, std::abs(dot(m, n)))));
  }
  return best;
}

// Gauss image of dimension 1: maximise the minimum angle to the sampled normals directly,
// over a Fibonacci sphere of directions, then by a shrinking pattern search.
Vec3 bestDirectionForCurve(const std::vector<Vec3>& normals) {
  Vec3 best{0.0, 0.0, 1.0};
  double bestAngle = -1.0;
  constexpr int kDirections = 800;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kDirections; ++i) {
    const double z = 1.0 - (i + 0.5) / kDirections;  // upper hemisphere: +-N slice alike
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 n{r * std::cos(golden * i), r * std::sin(golden * i), z};
    const double a = minimumAngle(normals, n);
    if (a > bestAngle) bestAngle = a, best = n;
  }
  for (double step = 0.05; step > 1e-9; step *= 0.5) {
    for (bool improved = true; improved;) {
      improved = false;
      const Vec3 e1 = orthogonal(best);
      const Vec3 e2 = cross(best, e1);
      for (const Vec3& d : {e1, -e1, e2, -e2}) {
        const Vec3 n = normalized(best + step * d);
        const double a = minimumAngle(normals, n);
        if (a > bestAngle) bestAngle = a, best = n, improved = true;
      }
    }
  }
  return best;
}

// ---------------------------------------------------------------------------------------
// The polish: N* on the true surface. The medial axis of the polygonal map puts N in the
// right basin; the polish removes the polygon's error by solving the minimax problem
//   minimise F(N) = max over the surface of |n(u, v) . N|,  |N| = 1
// (alpha = acos F) with a trust-region SQP method whose local model is built from the
// contacts: the local maxima of |n . N| over each patch, where the slicing planes come
// nearest to tangency (the optimal circle's contacts with the Gauss map).
//
// Model of one contact. Write f(w, N) = s n(w) . N, w = (u, v) in a patch's square and
// s = sign(n . N) at the contact, so that f = |n . N| nearby. A contact is a local maximum
// w_i(N) of f(., N); it moves with N (implicit function theorem on grad_w f = 0 over the
// parameters not held at a bound of the square; those held at a bound, with the gradient
// pointing out, stay there), and f_i(N) = f(w_i(N), N) is smooth. Differentiating
//   grad_N f_i = s n(w_i)                    (envelope theorem: grad_w f = 0 on the free
//                                              parameters, dw = 0 on the held ones)
//   d(grad_w f) = f_ww dw + B dN = 0,  B = d(grad_w f)/dN = s [n_u; n_v]  (free rows), so
//   hess_N f_i = B^T dw/dN = -B^T f_ww^-1 B   (positive semidefinite: f_ww < 0 at a strict
//                                              maximum; the contact slides along the
//                                              boundary of the Gauss image).
// On the sphere N(d) = (N + d1 e1 + d2 e2) / sqrt(1 + |d|^2) = N + d - |d|^2 N / 2 + O(|d|^3)
// (e1, e2 orthonormal, tangent at N), so
//   f_i(N(d)) = c_i + g_i . d + d^T H_i d / 2 + O(|d|^3),   c_i = f_i(N),
//   g_i = s (n_i . e1, n_i . e2),   H_i = E^T hess_N f_i E - c_i I   (E = [e1 e2]).
//
// Step. The QP in (d, t):  minimise t + d^T W d / 2  subject to  c_i + g_i . d <= t for the
// contacts near the top, |d1|, |d2| <= Delta (the trust region), with W = sum lambda_i H_i
// (lambda the QP's multipliers, sum lambda_i = 1: the Hessian of the Lagrangian). With the
// active set A of the optimum, its KKT conditions are Newton's equations for the minimax
// optimality system {f_i(N) = t (i in A), sum lambda_i grad f_i = 0, sum lambda_i = 1}:
//   - three active contacts (the generic optimum, the origin inside the triangle of their
//     gradients: a vertex): d solves the linearised level equations c_i + g_i . d = t,
//     W plays no part, and the iteration is Newton's method on f_1 = f_2 = f_3: quadratic;
//   - two active contacts (an edge: the optimum slides along the ridge f_1 = f_2 until the
//     ridge's curvature stops it, the two gradients opposite): W gives that curvature and the
//     step is Newton's on the KKT system, quadratic with exact multipliers (W is built from
//     the multipliers of a first solve at the same point, off by O(|d|): still quadratic).
// The QP has 3 unknowns and a handful of linear constraints. Its minimum is a KKT point of
// some set of at most 3 active constraints, so solving the equality-constrained KKT system of
// every such set and keeping the feasible point of least objective finds it exactly, even
// where W is indefinite (the -c_i I of the sphere): the box keeps the problem bounded.
// Acceptance by the true objective: rho = (F(N) - F(N(d))) / (F(N) - model(d)), F from a
// full contact search; accepted when rho > 0.01, Delta doubled when rho > 0.75 at the box's
// edge, halved to |d| / 2 when an accepted rho < 0.25, cut to |d| / 4 on a rejection. The
// Maratos effect: on a curved ridge the linearised constraints put N(d) O(|d|^2) off the
// ridge, where F grows at first order, so that a good step can look bad; when rho < 0.25 a
// second-order correction (Fletcher) re-solves the QP with each c_i replaced by
// f_i(N(d)) - g_i . d (the constraint's observed curvature), which lands on the ridge to
// O(|d|^3), and the better of the two steps is judged. Stop when the model promises less
// than the rounding of F, or after a step below 1e-10 rad.
// Measured (step lengths |d|, from the medial axis's circle): paper-1, a vertex of three
// contacts, 2.7e-4, 1.9e-8, done; paper-2, four contacts level by symmetry, 6.5e-3, 4.4e-5,
// 1.8e-9; an elliptic paraboloid (the test's), an edge of two contacts, 4.3e-3, 3.0e-7; random
// patches 2.7e-3, 2.4e-6, 1.7e-12. A handful of steps, each a contact search of ~20 Newton
// climbs: ~1 ms per rival on a bicubic patch.

// Patch parameter grid of the contact search: the unit normals at its (kGrid + 1)^2 points
// are computed once, and each search only takes their dot products with N.
constexpr int kGrid = 32;
// The highest grid peaks climbed by each search (a flat stretch of |n . N|, N orthogonal to
// a whole family of normals, makes every sample a peak; only the top ones can matter).
constexpr std::size_t kClimbed = 16;
// Contacts within this of the top always enter the QP (level with it up to rounding),
// however small the trust region.
constexpr double kActiveMargin = 1e-9;
// At most this many contacts (the highest) enter the QP: its enumeration is cubic in them,
// and a lower one that overtakes the top within the step shows in the true objective.
constexpr std::size_t kModelContacts = 10;
// Model decreases below this are rounding noise of F (a few ulps of values <= 1).
constexpr double kNoiseF = 1e-15;

// Symmetric 2 x 2 matrix [[xx, xy], [xy, yy]].
struct Sym2 {
  double xx = 0.0;
  double xy = 0.0;
  double yy = 0.0;
};

// The Bernstein basis of degree n at t, b_k^n(t) = C(n, k) (1 - t)^(n - k) t^k, with its
// first and second derivatives: d/dt b_k^n = n (b_{k-1}^{n-1} - b_k^{n-1}), and again.
struct BasisJet {
  std::vector<double> b;
  std::vector<double> db;
  std::vector<double> ddb;
  std::vector<double> lower1;  // degree n - 1
  std::vector<double> lower2;  // degree n - 2
};

void basisAt(int n, double t, BasisJet& out) {
  const auto size = static_cast<std::size_t>(n + 1);
  out.b.assign(size, 0.0);
  out.db.assign(size, 0.0);
  out.ddb.assign(size, 0.0);
  out.lower1.assign(size, 0.0);
  out.lower2.assign(size, 0.0);
  const double s = 1.0 - t;
  std::vector<double>& b = out.b;
  b[0] = 1.0;
  // Degree d from degree d - 1 (the de Casteljau triangle), in place from the top index.
  for (int d = 1; d <= n; ++d) {
    if (d - 1 == n - 2) out.lower2 = b;
    if (d - 1 == n - 1) out.lower1 = b;
    const auto du = static_cast<std::size_t>(d);
    b[du] = t * b[du - 1];
    for (std::size_t k = du - 1; k >= 1; --k) b[k] = s * b[k] + t * b[k - 1];
    b[0] = s * b[0];
  }
  if (n == 0) return;
  const double dn = n;
  auto at = [](const std::vector<double>& v, long k, long top) { return k < 0 || k > top ? 0.0 : v[static_cast<std::size_t>(k)]; };
  for (long k = 0; k <= n; ++k) {
    out.db[static_cast<std::size_t>(k)] = dn * (at(out.lower1, k - 1, n - 1) - at(out.lower1, k, n - 1));
    if (n >= 2) {
      out.ddb[static_cast<std::size_t>(k)] =
          dn * (dn - 1.0) *
          (at(out.lower2, k - 2, n - 2) - 2.0 * at(out.lower2, k - 1, n - 2) + at(out.lower2, k, n - 2));
    }
  }
}

// P = r_u x r_v (not normalised) and its partial derivatives up to the second order.
struct NormalJet {
  Vec3 p, pu, pv, puu, puv, pvv;
};

// N = r_u x r_v of one patch in Bernstein form (normalPolynomials), evaluated with its
// derivatives from the basis jets: sum_ij c_ij b_i^(a)(u) b_j^(b)(v), rows first.
class NormalField {
 public:
  // The direction field (collapsed edges factored out): its limits on an apex row are the
  // normals there, and Newton's method may step onto that row.
  explicit NormalField(const BezierPatch& patch)
      : poly_(normalDirectionPolynomials(patch).polynomials) {}

  NormalJet jet(double u, double v) const {
    const int m = poly_[0].degreeU;
    const int n = poly_[0].degreeV;
    basisAt(m, u, bu_);
    basisAt(n, v, bv_);
    NormalJet out;
    std::array<Vec3*, 6> targets{&out.p, &out.pu, &out.pv, &out.puu, &out.puv, &out.pvv};
    for (int c = 0; c < 3; ++c) {
      const std::vector<double>& coef = poly_[static_cast<std::size_t>(c)].coefficients;
      std::array<double, 6> sums{};
      for (int i = 0; i <= m; ++i) {
        double r0 = 0.0, r1 = 0.0, r2 = 0.0;  // the row in v: value, d/dv, d2/dv2
        const std::size_t row = static_cast<std::size_t>(i) * static_cast<std::size_t>(n + 1);
        for (int j = 0; j <= n; ++j) {
          const double cij = coef[row + static_cast<std::size_t>(j)];
          const auto ju = static_cast<std::size_t>(j);
          r0 += cij * bv_.b[ju];
          r1 += cij * bv_.db[ju];
          r2 += cij * bv_.ddb[ju];
        }
        const auto iu = static_cast<std::size_t>(i);
        sums[0] += bu_.b[iu] * r0;
        sums[1] += bu_.db[iu] * r0;
        sums[2] += bu_.b[iu] * r1;
        sums[3] += bu_.ddb[iu] * r0;
        sums[4] += bu_.db[iu] * r1;
        sums[5] += bu_.b[iu] * r2;
      }
      for (std::size_t k = 0; k < 6; ++k) {
        Vec3& target = *targets[k];
        (c == 0 ? target.x : c == 1 ? target.y : target.z) = sums[k];
      }
    }
    return out;
  }

 private:
  std::array<Bernstein2, 3> poly_;
  mutable BasisJet bu_;  // scratch, reused between calls
  mutable BasisJet bv_;
};

// f = s n . m with its parameter derivatives up to the second order, and the unit normal's
// first derivatives (for B above). With a = P . m and q = P . P, f = s a q^(-1/2):
//   f_k  = s (a_k q^(-1/2) - a q_k q^(-3/2) / 2)
//   f_kl = s (a_kl q^(-1/2) - (a_k q_l + a_l q_k + a q_kl) q^(-3/2) / 2 + 3 a q_k q_l q^(-5/2) / 4)
//   n_k  = P_k q^(-1/2) - P q_k q^(-3/2) / 2
// (a_k = P_k . m, q_k = 2 P . P_k, q_kl = 2 (P_k . P_l + P . P_kl)).
struct Height {
  double f = 0.0;
  double fu = 0.0, fv = 0.0, fuu = 0.0, fuv = 0.0, fvv = 0.0;
  Vec3 n, nu, nv;
};

Height heightOf(const NormalJet& j, const Vec3& m, double s) {
  const double q = dot(j.p, j.p);
  const double r1 = 1.0 / std::sqrt(q);
  const double r3 = r1 / q;
  const double r5 = r3 / q;
  const double a = dot(j.p, m), au = dot(j.pu, m), av = dot(j.pv, m);
  const double auu = dot(j.puu, m), auv = dot(j.puv, m), avv = dot(j.pvv, m);
  const double qu = 2.0 * dot(j.p, j.pu), qv = 2.0 * dot(j.p, j.pv);
  const double quu = 2.0 * (dot(j.pu, j.pu) + dot(j.p, j.puu));
  const double quv = 2.0 * (dot(j.pu, j.pv) + dot(j.p, j.puv));
  const double qvv = 2.0 * (dot(j.pv, j.pv) + dot(j.p, j.pvv));
  Height h;
  h.f = s * a * r1;
  h.fu = s * (au * r1 - 0.5 * a * qu * r3);
  h.fv = s * (av * r1 - 0.5 * a * qv * r3);
  h.fuu = s * (auu * r1 - (au * qu + 0.5 * a * quu) * r3 + 0.75 * a * qu * qu * r5);
  h.fuv = s * (auv * r1 - 0.5 * (au * qv + av * qu + a * quv) * r3 + 0.75 * a * qu * qv * r5);
  h.fvv = s * (avv * r1 - (av * qv + 0.5 * a * qvv) * r3 + 0.75 * a * qv * qv * r5);
  h.n = r1 * j.p;
  h.nu = r1 * j.pu - (0.5 * qu * r3) * j.p;
  h.nv = r1 * j.pv - (0.5 * qv * r3) * j.p;
  return h;
}

// A local maximum of |n . m| over one patch.
struct Contact {
  std::size_t patch = 0;
  double u = 0.0;
  double v = 0.0;
  double value = 0.0;  ///< |n . m| there
  double sign = 1.0;   ///< sign of n . m
  bool freeU = true;   ///< u not held at 0 or 1 (the gradient pointing out)
  bool freeV = true;
  Height height;       ///< f, its derivatives and n's at (u, v)
};

// The contacts of a surface with a direction m: every local maximum of |n . m| that can
// matter, found from warm starts and the peaks of a fixed parameter grid, each climbed by
// Newton's method.
class ContactFinder {
 public:
  explicit ContactFinder(const Surface& surface) {
    for (const BezierPatch& patch : surface.patches) {
      fields_.emplace_back(patch);
      std::vector<Vec3> grid;
      grid.reserve((kGrid + 1) * (kGrid + 1));
      for (int i = 0; i <= kGrid; ++i) {
        for (int j = 0; j <= kGrid; ++j) {
          grid.push_back(normalized(fields_.back().jet(double(i) / kGrid, double(j) / kGrid).p));
        }
      }
      grids_.push_back(std::move(grid));
    }
  }

  // Climbs f = s n . m (s fixed by the start) from (u, v) to a local maximum over the
  // patch's square: projected Newton, the parameters at a bound with the gradient pointing
  // out held there, a trust radius in the square (gradient steps where f_ww is not negative
  // definite), every step increasing f. Newton converges quadratically at the contacts:
  // an interior maximum of n . m lies on a parabolic line (where the Gauss map folds) and
  // f_ww is still definite there generically; on the boundary only one parameter moves.
  Contact climb(std::size_t patch, double u, double v, const Vec3& m) const {
    const NormalField& field = fields_[patch];
    NormalJet jet = field.jet(u, v);
    const double s = dot(jet.p, m) >= 0.0 ? 1.0 : -1.0;
    Height h = heightOf(jet, m, s);
    double radius = 1.0 / kGrid;
    for (int iteration = 0; iteration < 100; ++iteration) {
      const bool holdU = (u <= 0.0 && h.fu <= 0.0) || (u >= 1.0 && h.fu >= 0.0);
      const bool holdV = (v <= 0.0 && h.fv <= 0.0) || (v >= 1.0 && h.fv >= 0.0);
      double du = 0.0;
      double dv = 0.0;
      bool newton = true;
      if (!holdU && !holdV) {
        const double det = h.fuu * h.fvv - h.fuv * h.fuv;
        if (h.fuu < 0.0 && det > 0.0) {
          du = -(h.fvv * h.fu - h.fuv * h.fv) / det;
          dv = -(h.fuu * h.fv - h.fuv * h.fu) / det;
        } else {
          du = h.fu, dv = h.fv, newton = false;
        }
      } else if (!holdU) {
        if (h.fuu < 0.0) du = -h.fu / h.fuu; else du = h.fu, newton = false;
      } else if (!holdV) {
        if (h.fvv < 0.0) dv = -h.fv / h.fvv; else dv = h.fv, newton = false;
      }
      const double length = std::hypot(du, dv);
      if (length == 0.0) break;  // a corner, or a stationary point
      if (!newton || length > radius) du *= radius / length, dv *= radius / length;
      const double nu = std::clamp(u + du, 0.0, 1.0);
      const double nv = std::clamp(v + dv, 0.0, 1.0);
      const double moved = std::max(std::abs(nu - u), std::abs(nv - v));
      if (moved < 1e-15) break;
      const NormalJet trialJet = field.jet(nu, nv);
      const Height trial = heightOf(trialJet, m, s);
      if (trial.f > h.f || (newton && trial.f == h.f)) {
        u = nu, v = nv, h = trial;
        if (newton && moved < 1e-12) break;  // quadratic convergence: the next is ~1e-24
        if (moved >= 0.9 * radius) radius = std::min(0.5, 2.0 * radius);
      } else {
        if (moved < 1e-11) break;  // f flat to rounding here
        radius = 0.25 * moved;
      }
    }
    Contact c;
    c.patch = patch;
    c.u = u;
    c.v = v;
    c.sign = s;
    c.value = h.f;
    c.freeU = !((u <= 0.0 && h.fu <= 0.0) || (u >= 1.0 && h.fu >= 0.0));
    c.freeV = !((v <= 0.0 && h.fv <= 0.0) || (v >= 1.0 && h.fv >= 0.0));
    c.height = h;
    return c;
  }

  // Every local maximum of |n . m| that can matter, highest first: the warm starts (the
  // previous contacts, which Newton's method brings back in a step or two) and the highest
  // peaks of the grid, each climbed; a peak next to a climbed contact at least as high is
  // that contact's. A maximum narrower than the grid step could be missed; the certificate
  // (which subdivides in Bernstein form) would then fail and say so.
  std::vector<Contact> search(const Vec3& m, const std::vector<Contact>& warm) const {
    std::vector<Contact> found;
    found.reserve(warm.size() + kClimbed);
    for (const Contact& c : warm) found.push_back(climb(c.patch, c.u, c.v, m));
    struct Peak {
      double value;
      std::size_t patch;
      int i;
      int j;
    };
    std::vector<Peak> peaks;
    std::vector<double> values((kGrid + 1) * (kGrid + 1));
    for (std::size_t p = 0; p < grids_.size(); ++p) {
      for (std::size_t k = 0; k < values.size(); ++k) values[k] = std::abs(dot(grids_[p][k], m));
      auto at = [&](int i, int j) { return values[static_cast<std::size_t>(i * (kGrid + 1) + j)]; };
      for (int i = 0; i <= kGrid; ++i) {
        for (int j = 0; j <= kGrid; ++j) {
          const double g = at(i, j);
          bool peak = true;
          for (int di = -1; di <= 1 && peak; ++di) {
            for (int dj = -1; dj <= 1 && peak; ++dj) {
              const int a = i + di, b = j + dj;
              if (a < 0 || a > kGrid || b < 0 || b > kGrid || (di == 0 && dj == 0)) continue;
              peak = at(a, b) <= g;
            }
          }
          if (peak) peaks.push_back({g, p, i, j});
        }
      }
    }
    std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.value > b.value; });
    // Peaks with one normal (to rounding) on one patch are one contact: a developable patch
    // keeps its normal along each ruling, so its ridge of |n . m| is a line of grid peaks
    // equal but for rounding (a planar patch, all of it), which would otherwise fill every
    // slot and leave the other patches' contacts unclimbed.
    auto normalOf = [&](const Peak& q) {
      return grids_[q.patch][static_cast<std::size_t>(q.i * (kGrid + 1) + q.j)];
    };
    std::vector<Peak> chosen;
    for (const Peak& peak : peaks) {
      if (chosen.size() == kClimbed) break;
      const Vec3 n = normalOf(peak);
      bool repeated = false;
      for (const Peak& q : chosen) {
        repeated = repeated || (q.patch == peak.patch && norm(normalOf(q) - n) < 1e-12);
      }
      if (!repeated) chosen.push_back(peak);
    }
    peaks = std::move(chosen);
    const std::size_t warmCount = found.size();
    for (const Peak& peak : peaks) {
      const double u = double(peak.i) / kGrid, v = double(peak.j) / kGrid;
      bool known = false;
      for (std::size_t k = 0; k < warmCount && !known; ++k) {
        const Contact& c = found[k];
        known = c.patch == peak.patch && c.value >= peak.value &&
                std::max(std::abs(c.u - u), std::abs(c.v - v)) <= 1.5 / kGrid;
      }
      if (!known) found.push_back(climb(peak.patch, u, v, m));
    }
    // Highest first; duplicates (two seeds climbing to one maximum, or one normal on the
    // shared boundary of two patches) kept once.
    std::sort(found.begin(), found.end(), [](const Contact& a, const Contact& b) { return a.value > b.value; });
    std::vector<Contact> out;
    for (const Contact& c : found) {
      bool duplicate = false;
      for (const Contact& k : out) {
        duplicate = duplicate || norm(c.sign * c.height.n - k.sign * k.height.n) < 1e-9;
      }
      if (!duplicate) out.push_back(c);
    }
    return out;
  }

  // Seeds independent of the Gauss map: the `count` best directions of a Fibonacci lattice
  // of `directions` on the upper hemisphere (+-N slice alike, so it covers every axis),
  // ranked by the grid's max |n . N| and more than `separation` apart. The medial axis
  // finds the basin when the Gauss map is right; these catch a map that missed normals (its
  // circle then claims more clearance than the surface has, e.g. 63.0 against a true
  // optimum of 57.8 degrees on a random two-patch surface, before the map's union was
  // fixed) or covers a basin. O(directions
  // x grid points): a few milliseconds per patch.
  std::vector<Vec3> latticeSeeds(int directions, std::size_t count, double separation) const {
    std::vector<std::pair<double, Vec3>> scored;
    scored.reserve(static_cast<std::size_t>(directions));
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < directions; ++k) {
      const double z = 1.0 - (k + 0.5) / directions;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const Vec3 m{r * std::cos(golden * k), r * std::sin(golden * k), z};
      double worst = 0.0;
      for (const std::vector<Vec3>& grid : grids_) {
        for (const Vec3& n : grid) worst = std::max(worst, std::abs(dot(n, m)));
      }
      scored.push_back({worst, m});
    }
    std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Vec3> seeds;
    for (const auto& [worst, m] : scored) {
      if (seeds.size() == count) break;
      bool distinct = true;
      for (const Vec3& q : seeds) distinct = distinct && std::acos(std::min(1.0, std::abs(dot(q, m)))) > separation;
      if (distinct) seeds.push_back(m);
    }
    return seeds;
  }

 private:
  std::vector<NormalField> fields_;
  std::vector<std::vector<Vec3>> grids_;
};

// One contact in the tangent frame (e1, e2) at N: f_i(N(d)) ~ c + g . d + d^T h d / 2.
struct ModelContact {
  double c = 0.0;
  Vec2 g;
  Sym2 h;
};

ModelContact modelOf(const Contact& contact, const Vec3& e1, const Vec3& e2) {
  const Height& h = contact.height;
  const double s = contact.sign;
  ModelContact out;
  out.c = contact.value;
  out.g = {s * dot(h.n, e1), s * dot(h.n, e2)};
  // -B^T f_ww^-1 B over the free parameters, B's rows s (n_u . e), s (n_v . e).
  const Vec2 ju{s * dot(h.nu, e1), s * dot(h.nu, e2)};
  const Vec2 jv{s * dot(h.nv, e1), s * dot(h.nv, e2)};
  double iuu = 0.0, iuv = 0.0, ivv = 0.0;  // -f_ww^-1 (positive definite at a strict maximum)
  if (contact.freeU && contact.freeV) {
    const double det = h.fuu * h.fvv - h.fuv * h.fuv;
    if (h.fuu < 0.0 && det > 0.0) iuu = -h.fvv / det, iuv = h.fuv / det, ivv = -h.fuu / det;
  } else if (contact.freeU) {
    if (h.fuu < 0.0) iuu = -1.0 / h.fuu;
  } else if (contact.freeV) {
    if (h.fvv < 0.0) ivv = -1.0 / h.fvv;
  }
  out.h.xx = iuu * ju.x * ju.x + 2.0 * iuv * ju.x * jv.x + ivv * jv.x * jv.x - out.c;
  out.h.xy = iuu * ju.x * ju.y + iuv * (ju.x * jv.y + jv.x * ju.y) + ivv * jv.x * jv.y;
  out.h.yy = iuu * ju.y * ju.y + 2.0 * iuv * ju.y * jv.y + ivv * jv.y * jv.y - out.c;
  return out;
}

// Solves the n x n system a x = rhs (n <= 6; rhs in column n) by Gaussian elimination with
// partial pivoting; false when a pivot is negligible (a singular active set).
bool solveSmall(std::array<std::array<double, 7>, 6>& a, int n, std::array<double, 6>& x) {
  const auto un = static_cast<std::size_t>(n);
  for (std::size_t col = 0; col < un; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < un; ++r) {
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    }
    if (std::abs(a[pivot][col]) < 1e-13) return false;
    std::swap(a[pivot], a[col]);
    for (std::size_t r = col + 1; r < un; ++r) {
      const double factor = a[r][col] / a[col][col];
      for (std::size_t k = col; k <= un; ++k) a[r][k] -= factor * a[col][k];
    }
  }
  for (std::size_t r = un; r-- > 0;) {
    double sum = a[r][un];
    for (std::size_t k = r + 1; k < un; ++k) sum -= a[r][k] * x[k];
    x[r] = sum / a[r][r];
  }
  return true;
}

struct StepQp {
  Vec2 d;                       ///< the step in the tangent frame
  double model = 0.0;           ///< t + d^T W d / 2 at the minimum
  std::vector<double> weights;  ///< the contacts' multipliers (sum 1)
  bool ok = false;
};

// The QP above, by enumeration of the active sets of at most three constraints among the
// contacts' c_i + g_i . d - t <= 0 and the box's +-d_k <= delta (see the derivation).
StepQp solveStepQp(const std::vector<ModelContact>& contacts, const Sym2& w, double delta) {
  const int m = static_cast<int>(contacts.size());
  const int total = m + 4;
  struct Row {
    std::array<double, 3> a;
    double b;
  };
  std::vector<Row> rows;
  for (const ModelContact& c : contacts) rows.push_back({{c.g.x, c.g.y, -1.0}, -c.c});
  rows.push_back({{1.0, 0.0, 0.0}, delta});
  rows.push_back({{-1.0, 0.0, 0.0}, delta});
  rows.push_back({{0.0, 1.0, 0.0}, delta});
  rows.push_back({{0.0, -1.0, 0.0}, delta});
  StepQp best;
  double bestModel = std::numeric_limits<double>::infinity();
  std::array<int, 3> set{};
  auto tryActive = [&](int count) {
    // KKT: [W 0; 0 0] x + sum mu_s a_s = -(0, 0, 1), a_s . x = b_s (s in the set).
    const int n = 3 + count;
    std::array<std::array<double, 7>, 6> k{};
    k[0][0] = w.xx, k[0][1] = w.xy, k[1][0] = w.xy, k[1][1] = w.yy;
    k[2][static_cast<std::size_t>(n)] = -1.0;
    for (int s = 0; s < count; ++s) {
      const Row& r = rows[static_cast<std::size_t>(set[static_cast<std::size_t>(s)])];
      const auto col = static_cast<std::size_t>(3 + s);
      for (std::size_t i = 0; i < 3; ++i) k[i][col] = r.a[i], k[col][i] = r.a[i];
      k[col][static_cast<std::size_t>(n)] = r.b;
    }
    std::array<double, 6> x{};
    if (!solveSmall(k, n, x)) return;
    for (const Row& r : rows) {
      if (r.a[0] * x[0] + r.a[1] * x[1] + r.a[2] * x[2] > r.b + 1e-13) return;
    }
    const double model = x[2] + 0.5 * (w.xx * x[0] * x[0] + 2.0 * w.xy * x[0] * x[1] + w.yy * x[1] * x[1]);
    if (!(model < bestModel)) return;
    bestModel = model;
    best.ok = true;
    best.d = {x[0], x[1]};
    best.model = model;
    best.weights.assign(static_cast<std::size_t>(m), 0.0);
    for (int s = 0; s < count; ++s) {
      if (set[static_cast<std::size_t>(s)] < m) {
        best.weights[static_cast<std::size_t>(set[static_cast<std::size_t>(s)])] = x[static_cast<std::size_t>(3 + s)];
      }
    }
  };
  // The box's opposite faces are never active together.
  auto compatible = [&](int a, int b) { return !(a >= m && b >= m && (a - m) / 2 == (b - m) / 2); };
  for (int i = 0; i < m; ++i) {
    set = {i, 0, 0};
    tryActive(1);
    for (int j = i + 1; j < total; ++j) {
      set = {i, j, 0};
      tryActive(2);
      for (int l = j + 1; l < total; ++l) {
        if (!compatible(j, l)) continue;
        set = {i, j, l};
        tryActive(3);
      }
    }
  }
  return best;
}

// W = sum lambda_i H_i with the multipliers clamped at 0 and renormalised (an indefinite W
// can leave a slightly negative one at a degenerate point).
Sym2 lagrangianHessian(const std::vector<ModelContact>& contacts, const std::vector<double>& weights) {
  double sum = 0.0;
  for (double l : weights) sum += std::max(0.0, l);
  Sym2 w;
  if (!(sum > 0.0)) return contacts.front().h;
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const double l = std::max(0.0, weights[i]) / sum;
    w.xx += l * contacts[i].h.xx, w.xy += l * contacts[i].h.xy, w.yy += l * contacts[i].h.yy;
  }
  return w;
}

double largest(const std::vector<Contact>& contacts) {
  return contacts.empty() ? 0.0 : contacts.front().value;
}

// The polish from `seed` (see the derivation above): returns N with F(N) in `value`.
Vec3 polishDirection(const ContactFinder& finder, Vec3 n, double initialRadius, double& value) {
  std::vector<Contact> contacts = finder.search(n, {});
  double f = largest(contacts);
  value = f;
  if (contacts.empty()) return n;
  double radius = initialRadius;
  for (int iteration = 0; iteration < 200 && radius > 1e-12; ++iteration) {
    checkCancelled();
    const Vec3 e1 = orthogonal(n);
    const Vec3 e2 = cross(n, e1);
    // Contacts the step can make the top: a contact falls at most |g| |d| <= sqrt(2) radius
    // behind the top within the box, up to second order.
    std::vector<Contact> active;
    std::vector<ModelContact> models;
    for (const Contact& c : contacts) {
      if (c.value < f - 3.0 * radius - kActiveMargin || active.size() == kModelContacts) break;
      active.push_back(c);
      models.push_back(modelOf(c, e1, e2));
    }
    // Two solves: the first with the top contact's curvature gives the multipliers, the
    // second uses the Lagrangian's Hessian built from them.
    StepQp qp = solveStepQp(models, models.front().h, radius);
    if (!qp.ok) break;
    const Sym2 w = lagrangianHessian(models, qp.weights);
    qp = solveStepQp(models, w, radius);
    if (!qp.ok) break;
    const double predicted = f - qp.model;
    if (!(predicted > kNoiseF)) break;  // no descent left in the model: converged
    auto stepTo = [&](const Vec2& d) { return normalized(n + d.x * e1 + d.y * e2); };
    Vec2 step = qp.d;
    Vec3 trial = stepTo(step);
    std::vector<Contact> trialContacts = finder.search(trial, contacts);
    double ratio = (f - largest(trialContacts)) / predicted;
    if (ratio < 0.25) {
      // Second-order correction: the active contacts' observed values at the trial point.
      std::vector<ModelContact> corrected = models;
      for (std::size_t i = 0; i < active.size(); ++i) {
        const Contact there = finder.climb(active[i].patch, active[i].u, active[i].v, trial);
        corrected[i].c = there.value - (corrected[i].g.x * step.x + corrected[i].g.y * step.y);
      }
      const StepQp soc = solveStepQp(corrected, w, radius);
      if (soc.ok) {
        const Vec3 socTrial = stepTo(soc.d);
        std::vector<Contact> socContacts = finder.search(socTrial, contacts);
        const double socRatio = (f - largest(socContacts)) / predicted;
        if (socRatio > ratio) {
          ratio = socRatio, step = soc.d, trial = socTrial, trialContacts = std::move(socContacts);
        }
      }
    }
    const double length = std::max(std::abs(step.x), std::abs(step.y));
    if (ratio > 0.01) {
      n = trial;
      contacts = std::move(trialContacts);
      f = largest(contacts);
      if (ratio > 0.75 && length >= 0.9 * radius) radius = std::min(0.2, 2.0 * radius);
      if (ratio < 0.25) radius = 0.5 * length;
      if (length < 1e-10) break;  // converged: the next step is below the rounding of N
    } else {
      radius = 0.25 * length;
    }
  }
  value = f;
  return n;
}

// Proves P = cos^2(bound) |N|^2 - (N . m)^2 > 0 on the cell (P given in Bernstein form on
// it): then |n . m| < cos(bound), no normal within `bound` of +-m.
bool provePositive(const Bernstein2& p, int depth, int maxDepth, std::size_t& cells) {
  if (cells % 64 == 0) checkCancelled();
  ++cells;
  const Bounds b = bounds(p);
  if (b.lo > 0.0) return true;
  if (b.hi < 0.0 || evaluate(p, 0.5, 0.5) < 0.0 || depth >= maxDepth) return false;
  auto [left, right] = subdivideU(p, 0.5);
  for (const Bernstein2* half : {&left, &right}) {
    auto [a, c] = subdivideV(*half, 0.5);
    if (!provePositive(a, depth + 1, maxDepth, cells)) return false;
    if (!provePositive(c, depth + 1, maxDepth, cells)) return false;
  }
  return true;
}

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

// ---------------------------------------------------------------------------------------
// The medial-axis search (bestCircles), coarse to fine.

// The coarse domain's target size, in segments: this times the square root of the fine
// count. The search costs about two medial axes of the mixed domain, whose segments are the
// coarse ones plus the fine chains of the few dozen coarse segments near the best circles
// (each standing for fine / coarse fine segments): the sum is least near sqrt(dozens x fine).
// On the paper's surfaces at ~100,000 segments: ~3,000 coarse ones, ~6,000-9,000 searched.
constexpr double kCoarseSegmentsPerRootFine = 10.0;
// Refinement rounds before the search gives up and takes the full-resolution domain.
constexpr int kMaxRefinementRounds = 10;
// Simplifications tried (delta halved each time) when the simplified loops cross (where the
// domain is thinner than delta) before the full-resolution domain is taken.
constexpr int kSimplificationAttempts = 3;

// Every candidate circle of a medial axis, in edge order: each edge's ends and the roots of
// eq (13) on it, where alpha along the edge has its extrema, so that edgeBestAlpha also
// bounds alpha over the whole edge.
struct AxisCandidates {
  std::vector<RatedCircle> circles;
  std::vector<double> edgeBestAlpha;  // per edge; -1: no usable circle on it
  std::size_t best = 0;               // index into circles of the first greatest alpha
  std::size_t boundedEdges = 0;       // edges rated at their ends alone (see rateCandidates)
};

// An upper bound of alpha over the edge's circles (pi when they may reach the origin).
// By eq (12), tan alpha = 2R / (rho^2 - R^2 + 1) with rho = |c|: while rho > R it grows with
// R and falls with rho. The centre stays in the hull of the edge's control points (a
// segment, or the parabola's control triangle), which bounds rho from below. R is convex in
// the centre's position (the distance to a point; to a line, affine, on a line/line
// bisector), so its largest value on that hull is at a control point: the ends' radii, and
// on a parabola the control points' distances to the focus (eq 17). A relative 1e-9 covers
// the rounding of either side.
double alphaBound(const MedialEdge& edge) {
  const Vec2 origin{0.0, 0.0};
  double rMax = std::max(radiusAt(edge, 0.0), radiusAt(edge, 1.0));
  double rhoMin = 0.0;
  if (edge.kind == MedialEdge::Kind::linear) {
    rhoMin = distanceToSegment(origin, edge.control[0], edge.control[1]);
  } else {
    const std::array<Vec2, 3>& p = edge.control;
    for (const Vec2& q : p) rMax = std::max(rMax, norm(q - edge.siteA.a));
    const double s0 = cross(p[1] - p[0], origin - p[0]);
    const double s1 = cross(p[2] - p[1], origin - p[1]);
    const double s2 = cross(p[0] - p[2], origin - p[2]);
    const bool inside = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
    if (!inside) {
      rhoMin = std::min({distanceToSegment(origin, p[0], p[1]), distanceToSegment(origin, p[1], p[2]),
                         distanceToSegment(origin, p[2], p[0])});
    }
  }
  const double d = rhoMin * rhoMin - rMax * rMax + 1.0;
  if (!(d > 0.0) || !std::isfinite(rMax)) return std::numbers::pi;
  return std::atan2(2.0 * rMax, d) * (1.0 + 1e-9) + 1e-15;
}

// The candidates of `axis` (see AxisCandidates). The interior roots of eq (13) matter only
// on edges that can hold a circle within `windowRad` of the best: every edge's ends are rated
// first, and an edge whose alphaBound is below the best of them less the window keeps its
// ends alone, with the bound as its edgeBestAlpha (still an upper bound, which is all the
// coarse-to-fine test asks of it). The best circle and the rivals come out as if every root
// had been rated, in the same order: a bypassed root's alpha is below every rival's.
AxisCandidates rateCandidates(const MedialAxis& axis, double windowRad) {
  double bestEnd = -1.0;
  for (const MedialEdge& edge : axis.edges) {
    for (double t : {0.0, 1.0}) {
      const double r = radiusAt(edge, t);
      const double rho = norm(pointAt(edge, t));
      if (r > 0.0 && rho > r) bestEnd = std::max(bestEnd, alphaOfPlaneCircleRad(rho, r));
    }
  }
  AxisCandidates out;
  out.edgeBestAlpha.assign(axis.edges.size(), -1.0);
  for (std::size_t e = 0; e < axis.edges.size(); ++e) {
    if (e % 256 == 0) checkCancelled();
    const MedialEdge& edge = axis.edges[e];
    std::vector<double> ts;
    const double bound = bestEnd >= 0.0 ? alphaBound(edge) : std::numbers::pi;
    const bool bypassed = bound < bestEnd - windowRad;
    if (!bypassed) ts = stationaryParameters(edge);
    ts.push_back(0.0);
    ts.push_back(1.0);
    for (double t : ts) {
      const Vec2 c = pointAt(edge, t);
      const double r = radiusAt(edge, t);
      const double rho = norm(c);
      // Circles that hold the origin (the south pole, a surface normal's antipode) are not
      // in the complement; the medial axis never yields them but rounding might.
      if (!(r > 0.0) || rho <= r) {
        // Rated as the best possible for the coarse-to-fine test, which then examines it.
        if (r > 0.0) out.edgeBestAlpha[e] = std::numbers::pi;
        continue;
      }
      const double alpha = alphaOfPlaneCircleRad(rho, r);  // eq (12)
      if (out.circles.empty() || alpha > out.circles[out.best].alphaRad) out.best = out.circles.size();
      out.circles.push_back({alpha, {c, r}});
      out.edgeBestAlpha[e] = std::max(out.edgeBestAlpha[e], alpha);
    }
    if (bypassed) {
      out.edgeBestAlpha[e] = std::max(out.edgeBestAlpha[e], bound);
      ++out.boundedEdges;
    }
  }
  return out;
}

BestCircles searchResult(MedialAxis axis, const AxisCandidates& candidates, double windowRad) {
  if (candidates.circles.empty()) throw Error("the medial axis of the Gauss map's complement has no usable circle");
  BestCircles out;
  out.best = candidates.circles[candidates.best];
  for (const RatedCircle& c : candidates.circles) {
    if (c.alphaRad >= out.best.alphaRad - windowRad) out.rivals.push_back(c);
  }
  std::stable_sort(out.rivals.begin(), out.rivals.end(),
                   [](const RatedCircle& a, const RatedCircle& b) { return a.alphaRad > b.alphaRad; });
  out.axis = std::move(axis);
  out.boundedEdges = candidates.boundedEdges;
  return out;
}

std::size_t segmentCount(const PlanarDomain& domain) {
  std::size_t n = 0;
  for (const auto& loop : domain.loops) n += loop.size();
  return n;
}

// Douglas-Peucker on a closed loop: the indices (increasing, starting with 0) of the
// vertices kept so that every vertex between two consecutive kept ones lies within `delta`
// of the segment joining them. Vertex 0 and the loop's extreme vertices in x and y are
// always kept, so that the simplified domain has the same bounding box, hence the same
// integer grid in medialAxis (medial_axis.hpp), as the full one: the vertices they share are
// quantised alike and the circles they define come out bit for bit. Iterative (explicit
// stack); O(n log n) on smooth loops, where the farthest vertex splits a chain near its
// middle.
std::vector<std::uint32_t> douglasPeucker(const std::vector<Vec2>& loop, double delta) {
  const std::size_t n = loop.size();
  if (n < 3) {
    std::vector<std::uint32_t> all(n);
    std::iota(all.begin(), all.end(), 0U);
    return all;
  }
  std::vector<char> keep(n, 0);
  std::array<std::size_t, 5> anchors{0, 0, 0, 0, 0};
  for (std::size_t i = 1; i < n; ++i) {
    if (loop[i].x < loop[anchors[1]].x) anchors[1] = i;
    if (loop[i].x > loop[anchors[2]].x) anchors[2] = i;
    if (loop[i].y < loop[anchors[3]].y) anchors[3] = i;
    if (loop[i].y > loop[anchors[4]].y) anchors[4] = i;
  }
  for (std::size_t a : anchors) keep[a] = 1;
  std::vector<std::size_t> sorted(anchors.begin(), anchors.end());
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  // Chains [first, last] in unrolled indices (last may be n, i.e. vertex 0 again).
  std::vector<std::pair<std::size_t, std::size_t>> stack;
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    stack.push_back({sorted[k], k + 1 < sorted.size() ? sorted[k + 1] : n});
  }
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    if (last - first < 2) continue;
    const Vec2 a = loop[first];
    const Vec2 b = loop[last % n];
    double farthest = -1.0;
    std::size_t split = first;
    for (std::size_t i = first + 1; i < last; ++i) {
      const double d = distanceToSegment(loop[i], a, b);
      if (d > farthest) farthest = d, split = i;
    }
    if (farthest <= delta) continue;
    keep[split] = 1;
    stack.push_back({first, split});
    stack.push_back({split, last});
  }
  std::vector<std::uint32_t> kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

// The Douglas-Peucker tolerance delta that leaves about kCoarseSegmentsPerRootFine x
// sqrt(fine) coarse segments: one trial at 1e-6 of the bounding box's diagonal, then the
// count's law on smooth curves (a chord of sagitta delta spans a length proportional to
// sqrt(delta), so the count goes as delta^-1/2), within a factor 100 of the trial.
double simplificationTolerance(const PlanarDomain& domain) {
  Vec2 low{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 high = -low;
  std::size_t fine = 0;
  for (const auto& loop : domain.loops) {
    fine += loop.size();
    for (const Vec2& p : loop) {
      low = {std::min(low.x, p.x), std::min(low.y, p.y)};
      high = {std::max(high.x, p.x), std::max(high.y, p.y)};
    }
  }
  const double trial = 1e-6 * norm(high - low);
  if (!std::isfinite(trial) || !(trial > 0.0)) return 0.0;
  std::size_t coarse = 0;
  for (const auto& loop : domain.loops) {
    if (loop.size() >= 3) coarse += douglasPeucker(loop, trial).size();
  }
  const double target = kCoarseSegmentsPerRootFine * std::sqrt(static_cast<double>(fine));
  const double ratio = static_cast<double>(std::max<std::size_t>(coarse, 1)) / target;
  return trial * std::clamp(ratio * ratio, 1e-2, 1e2);
}

// A uniform grid over segments for the verification's query: the segments that may lie
// within distance `outer` of a point, skipping the cells wholly within distance `inner`
// (inside an empty maximal disc, where no boundary lies). Cells are registered by each
// segment's bounding box. A query costs O(rows + cells along the annulus).
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<std::array<Vec2, 2>>& segments, Vec2 low, Vec2 high) {
    origin_ = low;
    const double extent = std::max({high.x - low.x, high.y - low.y, 1e-300});
    // About two cells per segment: the segments lie along curves, so most cells stay
    // empty and an occupied one holds a few.
    const double side = std::clamp(std::ceil(std::sqrt(2.0 * static_cast<double>(segments.size()))), 1.0, 2048.0);
    cell_ = extent / side;
    columns_ = static_cast<int>(std::ceil((high.x - low.x) / cell_)) + 1;
    rows_ = static_cast<int>(std::ceil((high.y - low.y) / cell_)) + 1;
    start_.assign(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_) + 1, 0);
    auto forCells = [this](const std::array<Vec2, 2>& s, auto&& f) {
      const int i0 = column(std::min(s[0].x, s[1].x)), i1 = column(std::max(s[0].x, s[1].x));
      const int j0 = row(std::min(s[0].y, s[1].y)), j1 = row(std::max(s[0].y, s[1].y));
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) f(index(i, j));
    };
    for (const auto& s : segments) forCells(s, [this](std::size_t c) { ++start_[c + 1]; });
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(start_.back());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t k = 0; k < segments.size(); ++k) {
      forCells(segments[k], [&](std::size_t c) { items_[fill[c]++] = static_cast<std::uint32_t>(k); });
    }
  }

  template <typename Visit>
  void forEachNear(Vec2 p, double inner, double outer, Visit&& visit) const {
    const int j0 = row(p.y - outer), j1 = row(p.y + outer);
    for (int j = j0; j <= j1; ++j) {
      const double ya = origin_.y + j * cell_, yb = ya + cell_;
      const double dyMin = std::max({ya - p.y, 0.0, p.y - yb});
      if (dyMin > outer) continue;
      const double dyMax = std::max(std::abs(p.y - ya), std::abs(p.y - yb));
      const double half = std::sqrt(outer * outer - dyMin * dyMin);
      const int i0 = column(p.x - half), i1 = column(p.x + half);
      // Columns [skip0, skip1] lie wholly within `inner` of p on this row.
      int skip0 = i1 + 1, skip1 = i1;
      if (inner > dyMax) {
        const double w = std::sqrt(inner * inner - dyMax * dyMax);
        skip0 = static_cast<int>(std::clamp(std::floor((p.x - w - origin_.x) / cell_) + 1.0, -1.0, double(columns_)));
        skip1 = static_cast<int>(std::clamp(std::ceil((p.x + w - origin_.x) / cell_) - 2.0, -2.0, double(columns_)));
      }
      for (int i = i0; i <= i1; ++i) {
        if (i >= skip0 && i <= skip1) {
          i = skip1;
          continue;
        }
        const std::size_t c = index(i, j);
        for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) visit(items_[k]);
      }
    }
  }

 private:
  int column(double x) const {
    return static_cast<int>(std::clamp(std::floor((x - origin_.x) / cell_), 0.0, double(columns_ - 1)));
  }
  int row(double y) const {
    return static_cast<int>(std::clamp(std::floor((y - origin_.y) / cell_), 0.0, double(rows_ - 1)));
  }
  std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(i);
  }

  Vec2 origin_;
  double cell_ = 1.0;
  int columns_ = 1;
  int rows_ = 1;
  std::vector<std::uint32_t> start_;  // CSR: cell c holds items_[start_[c], start_[c + 1])
  std::vector<std::uint32_t> items_;
};

// The domain of the coarse-to-fine search: every loop simplified by Douglas-Peucker at
// `delta`, each coarse segment standing for the fine chain between its two kept vertices,
// and the "mixed" domain M in which the refined coarse segments are replaced by their
// chains.
//
// Why M's optimum is the full domain F's (the test in violations()). Every fine vertex of a
// chain lies within delta of its coarse segment, hence so does the whole chain, and every
// point of the segment lies within delta of the chain (the chain's projection onto the
// segment covers it), so M and F differ only inside the delta-neighbourhoods of the
// unrefined coarse segments. The stereographic projection's conformal factor is
// 2 / (1 + |p|^2) <= 2: moving a circle's boundary by delta in the plane changes its cap's
// angular radius alpha by at most 2 delta (and alpha <= 2R). Let C* be an optimal (or
// rival) circle of F, with alpha* > 4 delta, so its centre is not within delta of an
// unrefined coarse segment and lies in M. C* shrunk by delta avoids M's boundary, so lies in
// M, hence in a maximal disc D of M, centred on M's medial axis, with
// alpha(D) >= alpha(C*) - 2 delta. The test: every point of M's axis whose circle has
// alpha >= alpha_M - window - 3 delta (2 delta, and delta for rounding) is farther than
// R + 2 delta from every unrefined coarse segment. Along each edge, alpha is monotone between
// the roots of eq (13), so the parts above that threshold are intervals (found by
// bisection); on them g(t) = dist(c(t), unrefined) - R(t), 2-Lipschitz in arc length, is
// sampled from one end to the other, each sample covering the arc length
// (g - 2 delta - rounding) / 2 ahead of it; a sample that covers less than h / 2 (h = delta)
// fails, and the coarse segments within R + 2 delta + h of it are refined. If no sample
// fails, C* (within delta of D) stays more than delta from every unrefined segment, so it
// touches only refined parts (common to M and F) and is a maximal disc of M:
// alpha_M >= alpha*. Conversely M's best circle and rivals pass the test, so they are empty
// maximal discs of F touching the same sites (and alpha* >= alpha_M > 5 delta, as assumed).
// Hence alpha_M = alpha*, and the circles within the window of it are the same in M and F,
// up to the rounding of the roots of eq (13) on edges of different extent: bit for bit in
// practice, as M's refined vertices are F's, on the same integer grid (see douglasPeucker),
// unless Boost's diagram of one of them fails validation and is rebuilt rotated (then the
// two agree to the medial axis's tolerance).
class CoarseToFineDomain {
 public:
  CoarseToFineDomain(const PlanarDomain& fine, double delta) : fine_(fine), delta_(delta) {
    for (std::size_t l = 0; l < fine.loops.size(); ++l) {
      const std::vector<Vec2>& loop = fine.loops[l];
      if (loop.empty()) continue;
      std::vector<std::uint32_t> kept = douglasPeucker(loop, delta);
      // A loop that simplifies below a triangle is thinner than 2 delta: kept whole (and a
      // degenerate one left for medialAxis to explain).
      const bool whole = kept.size() < 3;
      for (std::size_t k = 0; k < kept.size(); ++k) {
        const std::uint32_t last = k + 1 < kept.size() ? kept[k + 1] : static_cast<std::uint32_t>(loop.size());
        segments_.push_back({static_cast<std::uint32_t>(l), kept[k], last, whole});
      }
    }
  }

  double delta() const { return delta_; }

  // M: each loop's coarse segments, the refined ones replaced by their fine chains.
  PlanarDomain mixed() const {
    PlanarDomain out;
    out.loops.resize(fine_.loops.size());
    for (const Segment& s : segments_) {
      const std::vector<Vec2>& loop = fine_.loops[s.loop];
      std::vector<Vec2>& into = out.loops[s.loop];
      into.push_back(loop[s.first]);
      if (s.refined) into.insert(into.end(), loop.begin() + s.first + 1, loop.begin() + s.last);
    }
    return out;
  }

  // The unrefined coarse segments that fail the test above for M's axis and its candidates.
  std::vector<std::size_t> violations(const MedialAxis& axis, const AxisCandidates& candidates,
                                      double windowRad) const {
    std::vector<std::size_t> ids;
    std::vector<std::array<Vec2, 2>> coarse;
    Vec2 low{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    Vec2 high = -low;
    for (std::size_t k = 0; k < segments_.size(); ++k) {
      const Segment& s = segments_[k];
      if (s.refined) continue;
      const std::vector<Vec2>& loop = fine_.loops[s.loop];
      const std::array<Vec2, 2> ab{loop[s.first], loop[s.last % loop.size()]};
      for (const Vec2& p : ab) {
        low = {std::min(low.x, p.x), std::min(low.y, p.y)};
        high = {std::max(high.x, p.x), std::max(high.y, p.y)};
      }
      ids.push_back(k);
      coarse.push_back(ab);
    }
    if (coarse.empty()) return {};
    const SegmentGrid grid(coarse, low, high);
    const double h = delta_;
    // The axis is exact for the integer-rounded domain; its radii to within its tolerance.
    const double clearance = 2.0 * delta_ + 4.0 * axis.tolerance;
    const double threshold = candidates.circles[candidates.best].alphaRad - windowRad - 3.0 * delta_;
    std::vector<char> violated(coarse.size(), 0);
    // The test at one point of the axis: the arc length ahead of it in which g = dist - R
    // stays above `clearance` (g is 2-Lipschitz), or, when that is below h/2, a failure: the
    // segments closer than R + clearance + h are marked (which lets the march go on h/2).
    auto clearAhead = [&](Vec2 c, double r) {
      const double reach = std::max(h, std::min(0.25 * r, 64.0 * h));  // the longest stride sought
      double nearest = r + clearance + 2.0 * reach;
      grid.forEachNear(c, r - delta_, nearest, [&](std::uint32_t k) {
        if (!violated[k]) nearest = std::min(nearest, distanceToSegment(c, coarse[k][0], coarse[k][1]));
      });
      const double ahead = 0.5 * (nearest - r - clearance);
      if (ahead >= 0.5 * h) return ahead;
      const double limit = r + clearance + h;
      grid.forEachNear(c, r - delta_, limit, [&](std::uint32_t k) {
        if (distanceToSegment(c, coarse[k][0], coarse[k][1]) <= limit) violated[k] = 1;
      });
      return 0.5 * h;
    };
    auto alphaAt = [](const MedialEdge& edge, double t) {
      return alphaOfPlaneCircleRad(norm(pointAt(edge, t)), radiusAt(edge, t));
    };
    for (std::size_t e = 0; e < axis.edges.size(); ++e) {
      if (candidates.edgeBestAlpha[e] < threshold) continue;
      const MedialEdge& edge = axis.edges[e];
      // |c'(t)| bounds the arc length per unit t: the control polygon's longest leg, doubled
      // on a quadratic.
      const auto& p = edge.control;
      const double speed = edge.kind == MedialEdge::Kind::linear
                               ? norm(p[1] - p[0])
                               : 2.0 * std::max(norm(p[1] - p[0]), norm(p[2] - p[1]));
      // alpha is monotone between consecutive roots of eq (13) (its derivative has the sign
      // of that polynomial over R > 0), so {alpha >= threshold} is a union of intervals whose
      // ends bisection finds; each is marched with the test above.
      std::vector<double> ts = stationaryParameters(edge);
      ts.push_back(0.0);
      ts.push_back(1.0);
      for (double& t : ts) t = std::clamp(t, 0.0, 1.0);
      std::sort(ts.begin(), ts.end());
      for (std::size_t k = 0; k + 1 < ts.size(); ++k) {
        double lo = ts[k], hi = ts[k + 1];
        const double alphaLo = alphaAt(edge, lo), alphaHi = alphaAt(edge, hi);
        if (std::max(alphaLo, alphaHi) < threshold) continue;
        if (std::min(alphaLo, alphaHi) < threshold) {
          // Keep the bracket's end below the threshold: the interval only grows.
          const bool rising = alphaLo < alphaHi;
          double below = rising ? lo : hi, above = rising ? hi : lo;
          for (int i = 0; i < 60 && std::abs(above - below) * speed > 0.25 * h; ++i) {
            const double mid = 0.5 * (below + above);
            (alphaAt(edge, mid) < threshold ? below : above) = mid;
          }
          (rising ? lo : hi) = below;
        }
        for (double t = lo;;) {
          const double ahead = clearAhead(pointAt(edge, t), radiusAt(edge, t));
          if (t >= hi || !(speed > 0.0)) break;
          t = std::min(hi, t + ahead / speed);
        }
      }
    }
    std::vector<std::size_t> out;
    for (std::size_t k = 0; k < coarse.size(); ++k) {
      if (violated[k]) out.push_back(ids[k]);
    }
    return out;
  }

  // Replaces the given coarse segments, and their neighbours in their loops, by their fine
  // chains. The neighbours: the circles move a little when their contacts are refined, and
  // would otherwise often call for one more round (one medial axis of the whole mixed
  // domain) for a segment or two.
  void refine(const std::vector<std::size_t>& ids) {
    for (std::size_t k : ids) {
      segments_[k].refined = true;
      const Segment& s = segments_[k];
      if (k > 0 && segments_[k - 1].loop == s.loop) segments_[k - 1].refined = true;
      if (k + 1 < segments_.size() && segments_[k + 1].loop == s.loop) segments_[k + 1].refined = true;
    }
  }

 private:
  struct Segment {
    std::uint32_t loop = 0;
    std::uint32_t first = 0;  // kept vertex where the segment starts
    std::uint32_t last = 0;   // the next kept vertex (the loop's size for vertex 0)
    bool refined = false;     // replaced by the fine chain first..last in M
  };

  const PlanarDomain& fine_;
  double delta_;
  std::vector<Segment> segments_;
};

}  // namespace

namespace {

// certifyClearance on a surface whose corners are resolved already (cornerPieces): the
// optimal slicing's bisection calls it up to kCertificateBisections times on the same pieces.
bool certifyPieces(const Surface& pieces, const Vec3& n, double lowerBoundRad, std::size_t& cells,
                   int maxDepth) {
  if (!(lowerBoundRad > 0.0)) return true;
  const Vec3 m = normalized(n);
  const double c = std::cos(lowerBoundRad);
  for (const BezierPatch& patch : pieces.patches) {
    // q, N's direction field (collapsed edges factored out), for N: the same directions, and
    // on an apex row their limits, which the certificate must cover too.
    const std::array<Bernstein2, 3> normal = normalDirectionPolynomials(patch).polynomials;
    Bernstein2 dotM = scale(normal[0], m.x);
    dotM = add(dotM, scale(normal[1], m.y));
    dotM = add(dotM, scale(normal[2], m.z));
    const Bernstein2 lengthSquared =
        add(add(multiply(normal[0], normal[0]), multiply(normal[1], normal[1])),
            multiply(normal[2], normal[2]));
    const Bernstein2 p = subtract(scale(lengthSquared, c * c), multiply(dotM, dotM));
    if (!provePositive(p, 0, maxDepth, cells)) return false;
  }
  return true;
}

}  // namespace

bool certifyClearance(const Surface& surface, const Vec3& n, double lowerBoundRad,
                      std::size_t& cells, int maxDepth) {
  return certifyPieces(cornerResolved(surface), n, lowerBoundRad, cells, maxDepth);
}

BestCircles bestCircles(const PlanarDomain& domain, const BestCirclesOptions& options) {
  if (!(options.windowRad >= 0.0) || !std::isfinite(options.windowRad)) {
    throw Error(fmt::format("bestCircles: the window must be a finite angle >= 0, got {} rad", options.windowRad));
  }
  const std::size_t fineSegments = segmentCount(domain);
  auto searchWhole = [&](int refinements) {
    MedialAxis axis = medialAxis(domain);
    const AxisCandidates candidates = rateCandidates(axis, options.windowRad);
    BestCircles out = searchResult(std::move(axis), candidates, options.windowRad);
    out.segments = fineSegments;
    out.refinements = refinements;
    return out;
  };
  if (!options.coarseToFine || fineSegments <= options.coarseToFineMinSegments) return searchWhole(0);
  const double delta = simplificationTolerance(domain);
  if (!(delta > 0.0)) return searchWhole(0);  // degenerate input: medialAxis explains
  int refinements = 0;
  for (int attempt = 0; attempt < kSimplificationAttempts; ++attempt) {
    CoarseToFineDomain coarse(domain, std::ldexp(delta, -attempt));
    for (int round = 0;; ++round) {
      const PlanarDomain mixed = coarse.mixed();
      MedialAxis axis;
      try {
        axis = medialAxis(mixed);
      } catch (const Cancelled&) {
        throw;
      } catch (const Error&) {
        break;  // the simplified loops cross where the domain is thinner than delta
      }
      const AxisCandidates candidates = rateCandidates(axis, options.windowRad);
      // The proof needs alpha* > 4 delta (see CoarseToFineDomain); below that delta is as
      // large as the circles, and the full domain is cheaper than refining everything.
      if (candidates.circles.empty() || !(candidates.circles[candidates.best].alphaRad > 5.0 * coarse.delta())) {
        return searchWhole(refinements);
      }
      const std::vector<std::size_t> violations = coarse.violations(axis, candidates, options.windowRad);
      if (violations.empty()) {
        BestCircles out = searchResult(std::move(axis), candidates, options.windowRad);
        out.segments = segmentCount(mixed);
        out.refinements = refinements;
        out.simplificationTolerance = coarse.delta();
        return out;
      }
      if (round + 1 >= kMaxRefinementRounds) return searchWhole(refinements);
      coarse.refine(violations);
      ++refinements;
    }
  }
  return searchWhole(refinements);
}

OptimalSlicing optimalSlicing(const Surface& surface, const OptimalSlicingOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const double tol = options.toleranceRad;
  if (!(tol > 0.0) || !(tol < 0.1) || !std::isfinite(tol)) {
    throw Error(fmt::format("the tolerance must be an angle in (0, {} deg), got {} deg",
                            0.1 * 180.0 / std::numbers::pi, tol * 180.0 / std::numbers::pi));
  }
  validateSurface(surface);
  // Trimmed faces: their pieces' normals hold the faces' (a certified lower bound of alpha*).
  if (surface.trimmed()) return optimalSlicing(trimmedPieces(surface), options);
  // The polish and the certificate work on pieces without corners where q vanishes (the
  // polish's heights divide by |q|); the Gauss map and the coverage proof resolve them
  // themselves, naming the source patches in their errors.
  const Surface working = cornerResolved(surface);
  OptimalSlicing result;
  GaussMapOptions gaussOptions;
  gaussOptions.toleranceRad = tol;
  BestCirclesOptions searchOptions;
  // Rival basins: the polygon is within tol of Omega, so a circle within a few tol of the
  // best may be the true optimum's.
  searchOptions.windowRad = 4.0 * tol;
  searchOptions.coarseToFine = options.coarseToFine;
  // The map and its medial axis, and once more with the pole off its cell's centre when the
  // complement comes out empty (the pole on a cell edge's image, see gauss_map.hpp, Pole)
  // or the medial axis refuses it (loops that touch on its integer grid, a Voronoi diagram
  // that fails validation in every rotation): another pole projects another plane.
  // Each map's loops go to the medial axis as they are (Clipper's output is simple), and
  // only if it refuses them without their zero-width zigzags (withoutSpikes: removing a
  // vertex can make its chord cross a slit's other side, as on nearly developable patches).
  std::optional<BestCircles> found;
  for (int attempt = 0; attempt < 2 && !found; ++attempt) {
    gaussOptions.offsetPole = attempt == 1;
    result.gaussMap = symmetrizedGaussMap(surface, gaussOptions);
    if (result.gaussMap.kind != GaussMapKind::region) break;
    PlanarDomain domain{result.gaussMap.loops};
    if (domain.loops.empty()) continue;
    for (int cleaned = 0; cleaned < 2 && !found; ++cleaned) {
      if (cleaned == 1) domain.loops = withoutSpikes(result.gaussMap.loops, 1e-2 * tol);
      if (domain.loops.empty()) break;
      try {
        found = bestCircles(domain, searchOptions);
      } catch (const Cancelled&) {
        throw;
      } catch (const Error&) {
        if (attempt == 1 && cleaned == 1) throw;
      }
    }
  }
  const GaussMap& map = result.gaussMap;
  result.pole = map.pole;
  const Rotation3 back = transpose(map.toPoleFrame);
  std::vector<Vec3> rivals;  // medial-axis directions to polish (the best first)

  if (map.kind == GaussMapKind::point) {
    // A plane, or a surface whose normals all lie within the tolerance (or too close for
    // the Gauss map's grid, see gauss_map.hpp): a direction orthogonal to the pole, polished
    // against the true normals (below). A plane keeps 90 degrees.
    result.method = "plane";
    result.normal = orthogonal(map.pole);
    result.alphaRad = std::numbers::pi / 2.0;
    result.sphereCircle = {result.normal, result.alphaRad};
  } else if (map.kind == GaussMapKind::curve) {
    result.method = "curve";
    // The curves come in antipodal pairs (n, -n), alike for |n . N|: keep one of each.
    std::vector<Vec3> normals;
    for (std::size_t i = 0; i < map.sphereCurves.size(); i += 2) {
      normals.insert(normals.end(), map.sphereCurves[i].begin(), map.sphereCurves[i].end());
    }
    result.normal = bestDirectionForCurve(normals);
    result.alphaRad = minimumAngle(normals, result.normal);
    result.sphereCircle = {result.normal, result.alphaRad};
  } else if (!found) {
    // No complement within the map's tolerance. "No direction exists" only with a proof
    // that the normals cover the sphere (normal_coverage.hpp); otherwise the best direction
    // that the lattice's seeds polish to, certified below like any other.
    using NoComplement = OptimalSlicingOptions::NoComplement;
    if (options.noComplement != NoComplement::stop) result.coverage = proveNormalsCoverSphere(surface);
    if (!result.coverage.proven && options.noComplement != NoComplement::proveThenSearch) {
      // Asked not to search: alpha >= 0 holds at every direction, and nothing more is said.
      result.method = "open";
      result.normal = map.pole;
      result.alphaRad = 0.0;
      result.sphereCircle = {result.normal, 0.0};
      result.certified = true;
      result.certifiedAlphaRad = 0.0;
      result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    if (result.coverage.proven) {
      result.method = "covered";
      result.normal = map.pole;
      result.alphaRad = 0.0;
      result.sphereCircle = {result.normal, 0.0};
      result.certified = true;  // alpha = 0 at every direction: proven by the covering
      result.certifiedAlphaRad = 0.0;
      result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    result.method = "lattice";
    result.normal = map.pole;
    result.alphaRad = 0.0;
    result.sphereCircle = {result.normal, 0.0};
  } else {
    const BestCircles& search = *found;
    result.medialAxisEdges = search.axis.edges.size();
    result.medialAxisRebuilds = search.axis.rebuilds;
    result.medialAxisSegments = search.segments;
    result.medialAxisRefinements = search.refinements;
    for (const MedialEdge& edge : search.axis.edges) {
      std::vector<Vec2> curve;
      const int samples = edge.kind == MedialEdge::Kind::linear ? 1 : 8;
      for (int i = 0; i <= samples; ++i) curve.push_back(pointAt(edge, static_cast<double>(i) / samples));
      result.medialAxisCurves.push_back(std::move(curve));
    }
    result.circle = search.best.circle;
    result.alphaRad = alphaOfPlaneCircleRad(norm(result.circle.center), result.circle.radius);
    result.normal = apply(back, directionOfPlaneCircle(result.circle.center, result.circle.radius));
    result.sphereCircle = {result.normal, result.alphaRad};
    // Keep up to four rivals, in distinct directions (more than a degree apart), to be
    // polished below.
    for (const auto& [alpha, circle] : search.rivals) {
      if (rivals.size() >= 4) break;
      const Vec3 n = apply(back, directionOfPlaneCircle(circle.center, circle.radius));
      bool distinct = true;
      for (const Vec3& q : rivals) {
        distinct = distinct && std::acos(std::min(1.0, std::abs(dot(q, n)))) > std::numbers::pi / 180.0;
      }
      if (distinct) rivals.push_back(n);
    }
  }
  // Polish against the true surface (see polishDirection); the circle found on the
  // polygonal map stays as the medial-axis result.
  // (A curve-like image was searched on its own exact samples; its |n . N| landscape is flat
  // along the family of normals, where the pattern search only wanders.)
  if (result.method == "medial-axis" || result.method == "lattice") {
    // Every rival is polished: the polygonal map can rank close rival optima wrongly by a
    // few tolerances, and each polish is cheap (a few Newton steps). With the option, then
    // the lattice's seeds (see latticeSeeds); the medial axis's rivals come first and win
    // ties.
    const ContactFinder finder(working);
    if (options.latticeSeeds || result.method == "lattice") {
      for (const Vec3& seed : finder.latticeSeeds(2000, 4, 2.0 * std::numbers::pi / 180.0)) rivals.push_back(seed);
    }
    double bestValue = 2.0;
    for (const Vec3& seed : rivals) {
      double value = 0.0;
      const Vec3 polished = polishDirection(finder, seed, tol, value);
      if (value < bestValue) bestValue = value, result.normal = polished;
    }
    result.alphaRad = std::acos(std::min(1.0, bestValue));
    result.sphereCircle = {result.normal, result.alphaRad};
  } else if (result.method == "plane") {
    double value = 0.0;
    const Vec3 polished = polishDirection(ContactFinder(working), result.normal, tol, value);
    if (value > 0.0) {
      result.normal = polished;
      result.alphaRad = std::acos(std::min(1.0, value));
      result.sphereCircle = {result.normal, result.alphaRad};
    }
  } else if (result.method == "curve") {
    // The curves' own optimum, polished on the true surface where that is better (a nearly
    // flat curved patch among developable ones has normals off its boundary's curve, within
    // the tolerance, that the curve search does not see).
    double value = 0.0;
    const Vec3 polished = polishDirection(ContactFinder(working), result.normal, tol, value);
    const double polishedAlpha = std::acos(std::min(1.0, value));
    if (value > 0.0 && polishedAlpha > result.alphaRad) {
      result.normal = polished;
      result.alphaRad = polishedAlpha;
      result.sphereCircle = {result.normal, result.alphaRad};
    }
  }
  // Certificate: prove that no normal comes within alpha* less a small margin (what the
  // sampled-and-climbed maxima could have missed) of +-N*.
  if (options.certify) {
    result.certifiedAlphaRad = std::max(0.0, result.alphaRad - kCertificateMarginRad);
    result.certified = certifyPieces(working, result.normal, result.certifiedAlphaRad,
                                     result.certificateCells, kCertificateMaxDepth);
    if (!result.certified) {
      // The polish's contacts missed a normal nearer to N* (a fold where the normal turns
      // fast, say): the claim falls, and what is proven at N* becomes the answer, found by
      // bisection on the certificate (the claim is an upper end; 0 holds trivially).
      // At most kCertificateBisections halvings, stopping at 1e-12 rad: a bounded cost (each
      // certificate subdivides only about the contacts it cannot yet prove).
      result.uncertifiedAlphaRad = result.alphaRad;
      double proven = 0.0, refuted = result.certifiedAlphaRad;
      for (int step = 0; step < kCertificateBisections && refuted - proven > 1e-12; ++step) {
        const double middle = 0.5 * (proven + refuted);
        if (certifyPieces(working, result.normal, middle, result.certificateCells, kCertificateMaxDepth)) {
          proven = middle;
        } else {
          refuted = middle;
        }
      }
      result.certifiedAlphaRad = proven;
      result.alphaRad = proven;
      result.sphereCircle.alphaRad = proven;
      result.certified = true;  // alpha >= proven at N* (trivially so for 0)
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scallop
