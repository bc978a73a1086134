// The polish of a slicing direction on the true surface (see direction_polish.hpp).

#include "slicing/direction_polish.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/job_control.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::detail {

Vec3 unitOrthogonal(const Vec3& n) {
  const Vec3 helper = std::abs(n.x) < 0.6 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  return normalized(cross(n, helper));
}

namespace {

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

}  // namespace

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
    // Peaks with one normal (to rounding) are one contact, and take one of the kClimbed
    // slots. On one patch they are a developable ridge: the patch keeps its normal along
    // each ruling, so its ridge of |n . m| is a line of grid peaks equal but for rounding (a
    // planar patch, all of it), climbed once. On other patches they are patches that repeat
    // one another (copies of a part side by side, a pattern) or meet with one tangent plane
    // at a shared edge (where the maximum may lie within a grid step inside either): climbed
    // too, up to kClimbed such repeats in all, outside the slots. Counted in the slots, the
    // repeats filled them all (17 copies of paper-1 filled all 16 with its highest contact,
    // the second was never climbed, and the polish settled 0.01 deg short of one copy's
    // optimum) and left the other contacts unclimbed.
    auto normalOf = [&](const Peak& q) {
      return grids_[q.patch][static_cast<std::size_t>(q.i * (kGrid + 1) + q.j)];
    };
    std::vector<Peak> chosen;
    std::size_t slots = 0, repeats = 0;
    for (const Peak& peak : peaks) {
      if (slots == kClimbed) break;
      const Vec3 n = normalOf(peak);
      bool onThisPatch = false, elsewhere = false;
      for (const Peak& q : chosen) {
        if (norm(normalOf(q) - n) >= 1e-12) continue;
        (q.patch == peak.patch ? onThisPatch : elsewhere) = true;
      }
      if (onThisPatch) continue;
      if (elsewhere) {
        if (repeats < kClimbed) ++repeats, chosen.push_back(peak);
        continue;
      }
      ++slots;
      chosen.push_back(peak);
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

namespace {

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
    const Vec3 e1 = unitOrthogonal(n);
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

}  // namespace

DirectionPolish::DirectionPolish(const Surface& surface) : finder_(std::make_unique<ContactFinder>(surface)) {}
DirectionPolish::~DirectionPolish() = default;

Vec3 DirectionPolish::polish(const Vec3& seed, double initialRadius, double& value) const {
  return polishDirection(*finder_, seed, initialRadius, value);
}

std::vector<Vec3> DirectionPolish::latticeSeeds(int directions, std::size_t count, double separationRad) const {
  return finder_->latticeSeeds(directions, count, separationRad);
}

}  // namespace scallop::detail
