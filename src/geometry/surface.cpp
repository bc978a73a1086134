#include "support/examples.hpp"
#include "geometry/teapot.hpp"
#include "support/json_input.hpp"
#include "support/text_input.hpp"
#include "scallop/geometry/surface.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/tolerances.hpp"

namespace scallop {
namespace {

using detail::displayName;

using Json = nlohmann::json;

// ---------------------------------------------------------------------------------------
// Messages
// ---------------------------------------------------------------------------------------

// Error messages quote the offending JSON value; a huge one is cut.
std::string quoted(const Json& value) { return detail::clipped(value.dump()); }



// "patches[1]", "patches[1].degree", "patches[1].control_points[2][0]".
std::string patchPath(std::size_t patch) { return fmt::format("patches[{}]", patch); }

// Shortest decimal that reads back as the same double (std::to_chars, correctly rounded
// both ways), as "%g"-like text. A negative zero is written "-0.0": "-0" would be read as
// the integer 0 by JSON parsers and lose its sign.
std::string shortest(double value) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  std::string text(buffer.data(), result.ptr);
  if (text == "-0") text = "-0.0";
  return text;
}

// ---------------------------------------------------------------------------------------
// Regularity: f = |r_u x r_v|^2 in Bernstein form, quadtree
// ---------------------------------------------------------------------------------------


// Rounding allowances of the two certificates after `depth` quadtree levels, from the error
// bounds documented in bernstein.hpp (u = unit roundoff; P-bar = the same combination of
// absolute values, "the scale of every error"; gamma_k ~ k u):
//   N = r_u x r_v, bidegree (m_N, n_N): each component is a difference of two products of
//     hodograph coordinates, so P-bar <= 2 S_u S_v; the products are within
//     gamma_{min(m_N, n_N) + 5} of P-bar, and each level halves in u and then in v (de
//     Casteljau at 1/2), adding gamma_{3 m_N} + gamma_{3 n_N}; d . N (|d| = 1) adds 3 u.
//     Total: (min + 8 + 3 (m_N + n_N) depth) u 2 S_u S_v.
//   f = |N|^2, bidegree (m_f, n_f): P-bar <= 3 (2 S_u S_v)^2 = 12 G (G = (S_u S_v)^2); the
//     errors of N, doubled by squaring, plus the products' and the sum's own, plus the
//     halvings: (2 min + 13 + 3 (m_f + n_f) depth) u 12 G.
// Each is multiplied by a safety factor of 4, so that a proof is never an artefact of
// rounding. For a bicubic patch at depth 16: 4.4e-13 S_u S_v and 5.2e-12 G.
constexpr double kSlackSafety = 4.0;

double slackDirectional(const Bernstein2& normalComponent, int depth, double boundProduct) {
  const int low = std::min(normalComponent.degreeU, normalComponent.degreeV);
  const int sum = normalComponent.degreeU + normalComponent.degreeV;
  return kSlackSafety * (low + 8 + 3.0 * sum * depth) * kUnitRoundoff * 2.0 * boundProduct;
}

double slackSquared(const Bernstein2& f, const Bernstein2& normalComponent, int depth,
                    double boundProduct) {
  const int low = std::min(normalComponent.degreeU, normalComponent.degreeV);
  const int sum = f.degreeU + f.degreeV;
  return kSlackSafety * (2.0 * low + 13 + 3.0 * sum * depth) * kUnitRoundoff * 12.0 * boundProduct *
         boundProduct;
}

double patchScale(const BezierPatch& patch) {
  double scale = 0.0;
  for (const Vec3& p : patch.control) {
    scale = std::max({scale, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  }
  return scale;
}

// S_u S_v with S_u = m max|p_{j+1,k} - p_jk|, S_v = n max|p_{j,k+1} - p_jk|: bounds of
// |r_u| and |r_v| over the patch (the hodographs' control points are m (p_{j+1,k} - p_jk)
// and n (p_{j,k+1} - p_jk), and a Bezier function lies in the convex hull of its control
// points), the same bounds bezier.hpp's unitNormal uses.
double derivativeBoundProduct(const BezierPatch& patch) {
  const int m = patch.degreeU;
  const int n = patch.degreeV;
  if (patch.rational()) {
    // N = w X_u x X_v - w_v X_u x X - w_u X x X_v (bezier.hpp): each term's factors bounded
    // by their nets (hodographs m dX, m dw; X and w themselves), summed.
    double x = 0.0, w = 0.0, dxu = 0.0, dxv = 0.0, dwu = 0.0, dwv = 0.0;
    for (int j = 0; j <= m; ++j) {
      for (int k = 0; k <= n; ++k) {
        const Vec3 h = patch.weight(j, k) * patch.at(j, k);
        x = std::max(x, norm(h));
        w = std::max(w, patch.weight(j, k));
        if (j < m) {
          dxu = std::max(dxu, norm(patch.weight(j + 1, k) * patch.at(j + 1, k) - h));
          dwu = std::max(dwu, std::abs(patch.weight(j + 1, k) - patch.weight(j, k)));
        }
        if (k < n) {
          dxv = std::max(dxv, norm(patch.weight(j, k + 1) * patch.at(j, k + 1) - h));
          dwv = std::max(dwv, std::abs(patch.weight(j, k + 1) - patch.weight(j, k)));
        }
      }
    }
    return w * (m * dxu) * (n * dxv) + (n * dwv) * (m * dxu) * x + (m * dwu) * x * (n * dxv);
  }
  double du = 0.0;
  double dv = 0.0;
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k <= n; ++k) {
      if (j < m) du = std::max(du, norm(patch.at(j + 1, k) - patch.at(j, k)));
      if (k < n) dv = std::max(dv, norm(patch.at(j, k + 1) - patch.at(j, k)));
    }
  }
  return m * du * n * dv;
}

// The polynomials of one quadtree cell [u0, u1] x [v0, v1], each in Bernstein form on the
// cell (mapped to [0, 1]^2): f = |N|^2 and the components of N = r_u x r_v.
struct Cell {
  Bernstein2 f;
  std::array<Bernstein2, 3> normal;
  double u0 = 0.0;
  double u1 = 1.0;
  double v0 = 0.0;
  double v1 = 1.0;
};

// The four quarters of p, in the order (low u, low v), (low u, high v), (high u, low v),
// (high u, high v): halve in u, then each half in v (exact halving points).
std::array<Bernstein2, 4> quartersOf(const Bernstein2& p) {
  auto [low, high] = subdivideU(p, 0.5);
  auto [lowLow, lowHigh] = subdivideV(low, 0.5);
  auto [highLow, highHigh] = subdivideV(high, 0.5);
  return {std::move(lowLow), std::move(lowHigh), std::move(highLow), std::move(highHigh)};
}

std::array<Cell, 4> quarters(const Cell& cell) {
  const double um = 0.5 * (cell.u0 + cell.u1);
  const double vm = 0.5 * (cell.v0 + cell.v1);
  std::array<Cell, 4> result;
  result[0].u0 = cell.u0, result[0].u1 = um, result[0].v0 = cell.v0, result[0].v1 = vm;
  result[1].u0 = cell.u0, result[1].u1 = um, result[1].v0 = vm, result[1].v1 = cell.v1;
  result[2].u0 = um, result[2].u1 = cell.u1, result[2].v0 = cell.v0, result[2].v1 = vm;
  result[3].u0 = um, result[3].u1 = cell.u1, result[3].v0 = vm, result[3].v1 = cell.v1;
  std::array<Bernstein2, 4> f = quartersOf(cell.f);
  for (std::size_t q = 0; q < 4; ++q) result[q].f = std::move(f[q]);
  for (std::size_t c = 0; c < 3; ++c) {
    std::array<Bernstein2, 4> component = quartersOf(cell.normal[c]);
    for (std::size_t q = 0; q < 4; ++q) result[q].normal[c] = std::move(component[q]);
  }
  return result;
}

// The directional certificate: with d the unit normal at the cell's centre, the smallest
// Bernstein coefficient of d . N on the cell, a lower bound of d . N <= |N| there.
double directionalLowerBound(const Cell& cell) {
  const Vec3 d{evaluate(cell.normal[0], 0.5, 0.5), evaluate(cell.normal[1], 0.5, 0.5),
               evaluate(cell.normal[2], 0.5, 0.5)};
  const double length = norm(d);
  if (!(length > 0.0)) return -std::numeric_limits<double>::infinity();
  const Vec3 unit = d / length;
  double lowest = std::numeric_limits<double>::infinity();
  const std::vector<double>& nx = cell.normal[0].coefficients;
  const std::vector<double>& ny = cell.normal[1].coefficients;
  const std::vector<double>& nz = cell.normal[2].coefficients;
  for (std::size_t i = 0; i < nx.size(); ++i) {
    lowest = std::min(lowest, unit.x * nx[i] + unit.y * ny[i] + unit.z * nz[i]);
  }
  return lowest;
}

double normalLengthAt(const BezierPatch& patch, double u, double v) {
  return norm(normalVector(patch, u, v));
}

}  // namespace

namespace {

// The patch scaled by a power of two (exact, barring underflow of coordinates far below the
// largest) so that its largest |coordinate| lies in [0.5, 1): the squares and fourth powers
// of the regularity check can then neither overflow nor underflow, and its verdicts are
// invariant under scaling by powers of two.
BezierPatch scaledToUnit(const BezierPatch& original) {
  int exponent = 0;
  std::frexp(patchScale(original), &exponent);
  BezierPatch patch = original;
  for (Vec3& p : patch.control) {
    p = {std::ldexp(p.x, -exponent), std::ldexp(p.y, -exponent), std::ldexp(p.z, -exponent)};
  }
  // A rational patch's weights likewise, largest in [0.5, 1) (the surface is unchanged:
  // weights matter only up to a common factor), so that its N = w^3 r_u x r_v is of the
  // polynomial case's size.
  if (patch.rational()) {
    int weightExponent = 0;
    std::frexp(*std::max_element(patch.weights.begin(), patch.weights.end()), &weightExponent);
    for (double& w : patch.weights) w = std::ldexp(w, -weightExponent);
  }
  return patch;
}

// Degrees >= 1 and (m + 1)(n + 1) finite control points, or scallop::Error from `what`.
void requireWellFormed(const BezierPatch& patch, const char* what) {
  const bool shaped = patch.degreeU >= 1 && patch.degreeV >= 1 &&
                      patch.control.size() == static_cast<std::size_t>(patch.degreeU + 1) *
                                                  static_cast<std::size_t>(patch.degreeV + 1);
  const bool finite = std::all_of(
      patch.control.begin(), patch.control.end(),
      [](const Vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); });
  if (!shaped || !finite) {
    throw Error(fmt::format(
        "{}: expected degrees >= 1, (m + 1)(n + 1) finite control points; got degree [{}, {}] "
        "with {} points{}",
        what, patch.degreeU, patch.degreeV, patch.control.size(), finite ? "" : ", not all finite"));
  }
}

// The regularity check proper (the contract's quadtree), on a patch whose corners are not
// singular, or that is itself a corner piece.
PatchRegularity checkPieceRegularity(const BezierPatch& original) {
  const BezierPatch patch = scaledToUnit(original);
  const double scale = patchScale(patch);
  PatchRegularity result;
  result.threshold = kRelativeNormalTolerance;
  const double tau = kRelativeNormalTolerance * scale * scale;
  // N's direction field, collapsed edges (apex rows) factored out: the patch is regular when
  // q is nowhere zero on the closed patch, its unit normal then continuous up to those edges
  // (their limits). Each division by u, say, multiplies coefficients by up to the degree, so
  // the rounding slacks below take S_u S_v times that factor per division.
  const NormalDirection direction = normalDirectionPolynomials(patch);
  const EdgePowers& powers = direction.powers;
  const double bound = derivativeBoundProduct(patch) *
                       std::pow(std::max(patch.degreeU, patch.degreeV),
                                powers.u0 + powers.u1 + powers.v0 + powers.v1);

  double least = std::numeric_limits<double>::infinity();
  // Evaluates |q| (|r_u x r_v| without collapsed edges) at (u, v); returns true if it is
  // small enough to prove the patch singular there. Keeps the least value seen as the
  // location of an undecided verdict.
  auto probe = [&](double u, double v) {
    const double length =
        powers.any() ? norm(Vec3{evaluate(direction.polynomials[0], u, v),
                                 evaluate(direction.polynomials[1], u, v),
                                 evaluate(direction.polynomials[2], u, v)})
                     : normalLengthAt(patch, u, v);
    if (length < least) {
      least = length;
      result.u = u;
      result.v = v;
      result.relativeNormalLength = scale > 0.0 ? length / (scale * scale) : 0.0;
    }
    return length <= tau;
  };

  // Breadth first, one level at a time, so that the cell budget is spent evenly.
  std::vector<Cell> level(1);
  const std::array<Bernstein2, 3>& q = direction.polynomials;
  level[0].f = add(add(multiply(q[0], q[0]), multiply(q[1], q[1])), multiply(q[2], q[2]));
  level[0].normal = q;
  for (int depth = 0; !level.empty(); ++depth) {
    // A cell is proven regular (|N| > tau on it, beyond rounding) when f's coefficients all
    // exceed proofSquared, or the coefficients of d . N all exceed proofDirectional.
    const Bernstein2& sample = level.front().normal[0];
    const double proofSquared = tau * tau + slackSquared(level.front().f, sample, depth, bound);
    const double proofDirectional = tau + slackDirectional(sample, depth, bound);
    std::vector<Cell> unresolved;
    for (Cell& cell : level) {
      ++result.cells;
      if (bounds(cell.f).lo > proofSquared) continue;                // all of f's > 0
      if (directionalLowerBound(cell) > proofDirectional) continue;  // N within a half-space
      const double um = 0.5 * (cell.u0 + cell.u1);
      const double vm = 0.5 * (cell.v0 + cell.v1);
      const bool singular = probe(um, vm) || probe(cell.u0, cell.v0) || probe(cell.u1, cell.v0) ||
                            probe(cell.u0, cell.v1) || probe(cell.u1, cell.v1);
      if (singular) {
        result.verdict = RegularityVerdict::singular;
        return result;
      }
      unresolved.push_back(std::move(cell));
    }
    if (unresolved.empty()) break;
    const std::size_t next = result.cells + 4 * unresolved.size();
    if (depth == kRegularityMaxDepth || next > kRegularityMaxCells) {
      result.verdict = RegularityVerdict::undecided;
      return result;
    }
    level.clear();
    for (const Cell& cell : unresolved) {
      for (Cell& quarter : quarters(cell)) level.push_back(std::move(quarter));
    }
  }
  result.verdict = RegularityVerdict::regular;
  result.u = 0.0;
  result.v = 0.0;
  result.relativeNormalLength = 0.0;
  return result;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Singular corners: pieces whose normals have limits
// ---------------------------------------------------------------------------------------

namespace {

// Corner c of [0, 1]^2: bit 0 set for u = 1, bit 1 set for v = 1.
double cornerU(int corner) { return (corner & 1) ? 1.0 : 0.0; }
double cornerV(int corner) { return (corner & 2) ? 1.0 : 0.0; }

// The corners where q (N with collapsed edges' factors divided out) is within tau =
// kRelativeNormalTolerance scale^2 of 0, as bits 1 << corner. Decided on the patch scaled by
// a power of two (exact), as the regularity check: no overflow, the same verdict.
unsigned singularCorners(const BezierPatch& original) {
  const BezierPatch patch = scaledToUnit(original);
  const double scale = patchScale(patch);
  const double tau = kRelativeNormalTolerance * scale * scale;
  const std::array<Bernstein2, 3>& q = normalDirectionPolynomials(patch).polynomials;
  auto length = [&](int i, int j) { return norm(Vec3{q[0].at(i, j), q[1].at(i, j), q[2].at(i, j)}); };
  unsigned corners = 0;
  for (int corner = 0; corner < 4; ++corner) {
    // A Bernstein form's corner coefficient is its value there, exactly; its neighbours
    // along the two edges are that value plus q_u / m', q_v / n': above tau when the zero is
    // of first order along the edges (a row nearly collapsed, q within tau along it, is
    // left to the quadtree, which rejects it).
    if (q[0].degreeU < 1 || q[0].degreeV < 1) break;  // q constant along an edge: no such zero
    const int i = (corner & 1) ? q[0].degreeU : 0;
    const int j = (corner & 2) ? q[0].degreeV : 0;
    const int inwardI = (corner & 1) ? i - 1 : i + 1;
    const int inwardJ = (corner & 2) ? j - 1 : j + 1;
    if (length(i, j) <= tau && length(inwardI, j) > tau && length(i, inwardJ) > tau) {
      corners |= 1u << corner;
    }
  }
  return corners;
}

Bernstein2 transposed(const Bernstein2& p) {
  Bernstein2 t{p.degreeV, p.degreeU, std::vector<double>(p.coefficients.size())};
  for (int i = 0; i <= p.degreeU; ++i) {
    for (int j = 0; j <= p.degreeV; ++j) t.coefficients[j * (p.degreeU + 1) + i] = p.at(i, j);
  }
  return t;
}

// p(a, phi(a, t)) for p of bidegree (m, n) and phi of bidegree (1, 1): bidegree (m + n, n) in
// (a, t). De Casteljau in v, its weights 1 - phi and phi being polynomials in (a, t): each
// of the n levels raises the bidegree by (1, 1); the rows are then summed with b_j^m(a).
Bernstein2 composedInV(const Bernstein2& p, const Bernstein2& phi) {
  const int m = p.degreeU;
  const int n = p.degreeV;
  const Bernstein2 one{0, 0, {1.0}};
  const Bernstein2 complement = subtract(one, phi);
  Bernstein2 result{m + n, n, std::vector<double>(static_cast<std::size_t>((m + n + 1) * (n + 1)), 0.0)};
  for (int j = 0; j <= m; ++j) {
    std::vector<Bernstein2> level;
    for (int k = 0; k <= n; ++k) level.push_back(Bernstein2{0, 0, {p.at(j, k)}});
    for (int r = 1; r <= n; ++r) {
      for (int k = 0; k + r <= n; ++k) {
        level[k] = add(multiply(complement, level[k]), multiply(phi, level[k + 1]));
      }
    }
    Bernstein2 basis{m, 0, std::vector<double>(static_cast<std::size_t>(m + 1), 0.0)};
    basis.coefficients[j] = 1.0;
    result = add(result, multiply(basis, level[0]));
  }
  return result;
}

// The bilinear phi(a, t) = e + (1 - 2e) |a - c| tau(t), tau(t) = t for e = 0 and 1 - t for
// e = 1: on [0, 1]^2 its Bernstein coefficients are its corner values.
Bernstein2 fanParameter(double c, double e) {
  Bernstein2 phi{1, 1, std::vector<double>(4)};
  for (int i = 0; i <= 1; ++i) {
    for (int j = 0; j <= 1; ++j) {
      const double tau = e == 0.0 ? j : 1.0 - j;
      phi.coefficients[i * 2 + j] = e + (1.0 - 2.0 * e) * std::abs(i - c) * tau;
    }
  }
  return phi;
}

BezierPatch patchOf(const std::array<Bernstein2, 3>& xyz) {
  BezierPatch patch;
  patch.degreeU = xyz[0].degreeU;
  patch.degreeV = xyz[0].degreeV;
  patch.control.resize(xyz[0].coefficients.size());
  for (std::size_t i = 0; i < patch.control.size(); ++i) {
    patch.control[i] = {xyz[0].coefficients[i], xyz[1].coefficients[i], xyz[2].coefficients[i]};
  }
  return patch;
}

// The two fans of `rectangle` (a whole patch or a quarter, its pieces' u0..v1 already set)
// about its corner `corner` (see PatchPiece).
std::array<PatchPiece, 2> fansAbout(const BezierPatch& rectangle, const PatchPiece& frame, int corner) {
  const double cu = cornerU(corner), cv = cornerV(corner);
  const std::array<Bernstein2, 3> xyz = coordinatePolynomials(rectangle);
  std::array<Bernstein2, 3> besideU, besideV;
  const Bernstein2 phi = fanParameter(cu, cv);  // v as a function of (a, t)
  const Bernstein2 psi = fanParameter(cv, cu);  // u as a function of (b, s)
  for (std::size_t c = 0; c < 3; ++c) {
    besideU[c] = composedInV(xyz[c], phi);
    besideV[c] = transposed(composedInV(transposed(xyz[c]), psi));
  }
  std::array<PatchPiece, 2> fans{frame, frame};
  fans[0].patch = patchOf(besideU);
  fans[1].patch = patchOf(besideV);
  fans[0].corner = fans[1].corner = corner;
  fans[0].besideUEdge = true;
  fans[1].besideUEdge = false;
  // The collapsed edges (a = cu, b = cv) are the corner point exactly, and the diagonal the
  // two fans share has bit-equal control points (seams are recognised so): the same curve
  // of degree m + n, its parameter a = b when cu == cv, else reversed.
  const Vec3 apex = rectangle.at(cu == 0.0 ? 0 : rectangle.degreeU, cv == 0.0 ? 0 : rectangle.degreeV);
  BezierPatch& a = fans[0].patch;
  BezierPatch& b = fans[1].patch;
  const int rowA = cu == 0.0 ? 0 : a.degreeU;
  for (int k = 0; k <= a.degreeV; ++k) a.control[rowA * (a.degreeV + 1) + k] = apex;
  const int columnB = cv == 0.0 ? 0 : b.degreeV;
  for (int j = 0; j <= b.degreeU; ++j) b.control[j * (b.degreeV + 1) + columnB] = apex;
  const int diagonalA = cv == 0.0 ? a.degreeV : 0;  // tau(t) = 1
  const int diagonalB = cu == 0.0 ? b.degreeU : 0;  // sigma(s) = 1
  const int d = a.degreeU;                           // == b.degreeV == m + n
  for (int i = 0; i <= d; ++i) {
    const int k = cu == cv ? i : d - i;
    b.control[diagonalB * (b.degreeV + 1) + k] = a.control[i * (a.degreeV + 1) + diagonalA];
  }
  return fans;
}

}  // namespace

Vec2 PatchPiece::sourceParameters(double s, double t) const {
  double x = s, y = t;  // in the rectangle, [0, 1]^2
  if (corner >= 0) {
    const double cu = cornerU(corner), cv = cornerV(corner);
    if (besideUEdge) {
      const double tau = cv == 0.0 ? t : 1.0 - t;
      x = s;
      y = cv + (1.0 - 2.0 * cv) * std::abs(s - cu) * tau;
    } else {
      const double sigma = cu == 0.0 ? s : 1.0 - s;
      x = cu + (1.0 - 2.0 * cu) * std::abs(t - cv) * sigma;
      y = t;
    }
  }
  return {u0 + (u1 - u0) * x, v0 + (v1 - v0) * y};
}

std::vector<PatchPiece> cornerPieces(const BezierPatch& patch, std::size_t source) {
  requireWellFormed(patch, "cornerPieces");
  PatchPiece whole;
  whole.patch = patch;
  whole.source = source;
  const unsigned corners = singularCorners(patch);
  if (corners == 0) return {whole};
  if (patch.degreeU + patch.degreeV > kMaxPatchDegree) {
    throw Error(fmt::format(
        "r_u x r_v vanishes at the corner (u, v) = ({}, {}); resolving such a corner needs the "
        "degree sum m + n <= {}, got {} + {}",
        cornerU(std::countr_zero(corners)), cornerV(std::countr_zero(corners)), kMaxPatchDegree,
        patch.degreeU, patch.degreeV));
  }
  std::vector<PatchPiece> pieces;
  if (std::popcount(corners) == 1) {
    for (PatchPiece& fan : fansAbout(patch, whole, std::countr_zero(corners))) pieces.push_back(std::move(fan));
    return pieces;
  }
  // Several: the quarters (halved in u, then each half in v, so that shared edges are bit
  // for bit equal), each with at most one of the patch's corners, fanned about it.
  auto [low, high] = subdivideU(patch, 0.5);
  for (int half = 0; half < 2; ++half) {
    auto [lower, upper] = subdivideV(half == 0 ? low : high, 0.5);
    for (int part = 0; part < 2; ++part) {
      PatchPiece quarter = whole;
      quarter.patch = part == 0 ? std::move(lower) : std::move(upper);
      quarter.u0 = 0.5 * half, quarter.u1 = 0.5 * (half + 1);
      quarter.v0 = 0.5 * part, quarter.v1 = 0.5 * (part + 1);
      const int corner = half | (part << 1);  // the patch's corner inside this quarter
      if (corners & (1u << corner)) {
        for (PatchPiece& fan : fansAbout(quarter.patch, quarter, corner)) pieces.push_back(std::move(fan));
      } else {
        pieces.push_back(std::move(quarter));
      }
    }
  }
  return pieces;
}

Surface cornerResolved(const Surface& surface, std::vector<std::size_t>* sources) {
  Surface resolved;
  resolved.units = surface.units;
  if (sources) sources->clear();
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    for (PatchPiece& piece : cornerPieces(surface.patches[i], i)) {
      resolved.patches.push_back(std::move(piece.patch));
      if (sources) sources->push_back(i);
    }
  }
  return resolved;
}

PatchRegularity checkPatchRegularity(const BezierPatch& patch) {
  requireWellFormed(patch, "checkPatchRegularity");
  if (singularCorners(patch) == 0) return checkPieceRegularity(patch);
  // A corner where q vanishes: the patch is regular when each fan is (its normals then have a
  // limit along every ray into the corner, the fan's collapsed edge).
  PatchRegularity combined;
  for (const PatchPiece& piece : cornerPieces(patch, 0)) {
    PatchRegularity part = checkPieceRegularity(piece.patch);
    combined.cells += part.cells;
    if (part.verdict != RegularityVerdict::regular) {
      const Vec2 at = piece.sourceParameters(part.u, part.v);
      part.u = at.x, part.v = at.y, part.cells = combined.cells;
      return part;
    }
  }
  return combined;
}

namespace {

// ---------------------------------------------------------------------------------------
// Validation of a patch in memory (degrees, sizes, finiteness, regularity)
// ---------------------------------------------------------------------------------------

void validatePatch(const BezierPatch& patch, std::size_t index, bool regularity = true) {
  const std::string where = patchPath(index);
  for (const auto& [degree, direction] :
       {std::pair{patch.degreeU, "u (the first)"}, std::pair{patch.degreeV, "v (the second)"}}) {
    if (degree < 1) {
      throw Error(
          fmt::format("{}.degree: degree {} in {} leaves the patch without a normal (r_{} vanishes "
                      "identically); each degree must be at least 1",
                      where, degree, direction, direction[0]));
    }
    if (degree > kMaxPatchDegree) {
      throw Error(fmt::format("{}.degree: degree {} in {} exceeds the supported maximum {}", where,
                              degree, direction, kMaxPatchDegree));
    }
  }
  const std::size_t expected =
      static_cast<std::size_t>(patch.degreeU + 1) * static_cast<std::size_t>(patch.degreeV + 1);
  if (patch.control.size() != expected) {
    throw Error(fmt::format("{}: degree [{}, {}] needs {} x {} = {} control points, got {}", where,
                            patch.degreeU, patch.degreeV, patch.degreeU + 1, patch.degreeV + 1,
                            expected, patch.control.size()));
  }
  for (int j = 0; j <= patch.degreeU; ++j) {
    for (int k = 0; k <= patch.degreeV; ++k) {
      const Vec3& p = patch.at(j, k);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw Error(
            fmt::format("{}.control_points[{}][{}]: coordinates must be finite, got [{}, {}, {}]",
                        where, j, k, p.x, p.y, p.z));
      }
    }
  }
  if (patch.rational()) {
    if (patch.weights.size() != expected)
      throw Error(fmt::format("{}.weights: degree [{}, {}] needs {} weights, got {}", where, patch.degreeU,
                              patch.degreeV, expected, patch.weights.size()));
    double least = std::numeric_limits<double>::infinity(), largest = 0.0;
    for (int j = 0; j <= patch.degreeU; ++j) {
      for (int k = 0; k <= patch.degreeV; ++k) {
        const double w = patch.weight(j, k);
        if (!(w > 0.0) || !std::isfinite(w))
          throw Error(fmt::format("{}.weights[{}][{}]: a weight must be positive and finite, got {}", where, j, k, w));
        least = std::min(least, w);
        largest = std::max(largest, w);
      }
    }
    // The rational polynomials multiply up to ten weights: a spread beyond this would lose
    // the small ones to rounding (CAD's conics have sqrt(2)/2 to 1).
    if (largest > kMaxWeightRatio * least)
      throw Error(fmt::format("{}.weights: they range from {:g} to {:g}, a ratio above {:g}", where, least, largest,
                              kMaxWeightRatio));
  }
  const double scale = patchScale(patch);
  if (scale > kMaxPatchScale || (scale > 0.0 && scale < kMinPatchScale)) {
    throw Error(fmt::format("{}: the largest |coordinate| is {:g}, outside [{:g}, {:g}] where the "
                            "curvature polynomials neither overflow nor underflow (check the units)",
                            where, scale, kMinPatchScale, kMaxPatchScale));
  }
  if (!regularity) return;  // a trimmed patch: regular where its face is (surface.hpp's trims)
  PatchRegularity verdict;
  try {
    verdict = checkPatchRegularity(patch);
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", where, error.what()));
  }
  switch (verdict.verdict) {
    case RegularityVerdict::regular:
      return;
    case RegularityVerdict::singular:
      throw Error(fmt::format(
          "{}: degenerate patch: r_u x r_v vanishes at (u, v) = ({}, {}) (|r_u x r_v| / scale^2 = "
          "{:g} <= {:g}, scale = largest |coordinate| = {:g}), so the unit normal is undefined "
          "there{}",
          where, verdict.u, verdict.v, verdict.relativeNormalLength, verdict.threshold,
          patchScale(patch),
          (verdict.u == 0.0 || verdict.u == 1.0) && (verdict.v == 0.0 || verdict.v == 1.0)
              ? " (at a corner it may vanish only to first order, its direction having a limit "
                "along every ray into the patch)"
              : ""));
    case RegularityVerdict::undecided:
      throw Error(fmt::format(
          "{}: degenerate patch: could not prove r_u x r_v != 0 near (u, v) = ({}, {}) "
          "(|r_u x r_v| / scale^2 = {:g} there, after {} quadtree cells); the unit normal is "
          "unreliable or undefined nearby",
          where, verdict.u, verdict.v, verdict.relativeNormalLength, verdict.cells));
  }
}

// ---------------------------------------------------------------------------------------
// JSON parsing
// ---------------------------------------------------------------------------------------

[[noreturn]] void fail(const std::string& source, const std::string& where,
                       const std::string& what) {
  throw Error(fmt::format("{}: {}: {}", source, where, what));
}

void rejectUnknownKeys(const Json& object, std::initializer_list<std::string_view> known,
                       const std::string& source, const std::string& where) {
  for (const auto& item : object.items()) {
    if (std::find(known.begin(), known.end(), item.key()) != known.end()) continue;
    std::string expected;
    for (const std::string_view key : known) {
      expected += expected.empty() ? "" : ", ";
      expected += fmt::format("\"{}\"", key);
    }
    fail(source, where, fmt::format("unknown key \"{}\" (expected {})", item.key(), expected));
  }
}

Units parseUnits(const Json& document, const std::string& source) {
  if (!document.contains("units")) {
    throw Error(fmt::format("{}: missing \"units\" (\"in\" or \"mm\")", source));
  }
  const Json& units = document["units"];
  if (units.is_string()) {
    const std::string& name = units.get_ref<const std::string&>();
    if (name == "in") return Units::inch;
    if (name == "mm") return Units::millimetre;
  }
  fail(source, "units", fmt::format("expected \"in\" or \"mm\", got {}", quoted(units)));
}

int parseDegree(const Json& value, const char* direction, const std::string& source,
                const std::string& where, const Json& degree) {
  if (!value.is_number_integer()) {
    fail(source, where,
         fmt::format("expected [m, n], two integers, got {} (the degree in {} is not an integer)",
                     quoted(degree), direction));
  }
  const std::int64_t d = value.is_number_unsigned()
                             ? static_cast<std::int64_t>(std::min<std::uint64_t>(
                                   value.get<std::uint64_t>(), std::uint64_t{1} << 62))
                             : value.get<std::int64_t>();
  if (d < 1) {
    fail(source, where,
         fmt::format("degree {} in {} (got {}): each degree must be at least 1, or r_{} vanishes "
                     "identically and the patch has no normal",
                     d, direction, quoted(degree), direction[0]));
  }
  if (d > kMaxPatchDegree) {
    fail(source, where,
         fmt::format("degree {} in {} (got {}) exceeds the supported maximum {}", d, direction,
                     quoted(degree), kMaxPatchDegree));
  }
  return static_cast<int>(d);
}

Vec3 parsePoint(const Json& value, const std::string& source, const std::string& where) {
  const bool shaped = value.is_array() && value.size() == 3 && value[0].is_number() &&
                      value[1].is_number() && value[2].is_number();
  if (!shaped)
    fail(source, where, fmt::format("expected [x, y, z], three numbers, got {}", quoted(value)));
  const Vec3 p{value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
  // JSON has no NaN or infinity (and nlohmann rejects literals that overflow); kept as a
  // guard so that the invariant never rests on the JSON library's behaviour.
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    fail(source, where, fmt::format("coordinates must be finite numbers, got {}", quoted(value)));
  }
  return p;
}

BezierPatch parsePatch(const Json& value, std::size_t index, const std::string& source) {
  const std::string where = patchPath(index);
  if (!value.is_object()) {
    fail(source, where,
         fmt::format("expected an object {{\"degree\": [m, n], \"control_points\": [...]}}, got {}",
                     quoted(value)));
  }
  rejectUnknownKeys(value, {"degree", "control_points", "weights"}, source, where);
  if (!value.contains("degree")) fail(source, where, "missing \"degree\": [m, n]");
  if (!value.contains("control_points")) fail(source, where, "missing \"control_points\"");

  const Json& degree = value["degree"];
  const std::string degreeWhere = where + ".degree";
  if (!degree.is_array() || degree.size() != 2) {
    fail(source, degreeWhere, fmt::format("expected [m, n], two integers, got {}", quoted(degree)));
  }
  BezierPatch patch;
  patch.degreeU = parseDegree(degree[0], "u (the first)", source, degreeWhere, degree);
  patch.degreeV = parseDegree(degree[1], "v (the second)", source, degreeWhere, degree);
  const std::size_t rows = static_cast<std::size_t>(patch.degreeU) + 1;
  const std::size_t columns = static_cast<std::size_t>(patch.degreeV) + 1;

  const Json& points = value["control_points"];
  const std::string pointsWhere = where + ".control_points";
  if (!points.is_array()) {
    fail(source, pointsWhere,
         fmt::format("expected an array of {} rows of {} points, got {}", rows, columns,
                     quoted(points)));
  }
  if (points.size() != rows) {
    fail(source, pointsWhere,
         fmt::format("degree [{}, {}] needs m + 1 = {} rows, got {}", patch.degreeU, patch.degreeV,
                     rows, points.size()));
  }
  patch.control.reserve(rows * columns);
  for (std::size_t j = 0; j < rows; ++j) {
    const Json& row = points[j];
    const std::string rowWhere = fmt::format("{}[{}]", pointsWhere, j);
    if (!row.is_array()) {
      fail(source, rowWhere,
           fmt::format("expected a row of {} points, got {}", columns, quoted(row)));
    }
    if (row.size() != columns) {
      fail(source, rowWhere,
           fmt::format("degree [{}, {}] needs n + 1 = {} points per row, got {}", patch.degreeU,
                       patch.degreeV, columns, row.size()));
    }
    for (std::size_t k = 0; k < columns; ++k) {
      patch.control.push_back(parsePoint(row[k], source, fmt::format("{}[{}]", rowWhere, k)));
    }
  }
  // Optional: a rational patch's weights, rows of numbers as the control points' (bezier.hpp).
  if (value.contains("weights")) {
    const Json& weights = value["weights"];
    const std::string weightsWhere = where + ".weights";
    if (!weights.is_array() || weights.size() != rows)
      fail(source, weightsWhere,
           fmt::format("degree [{}, {}] needs m + 1 = {} rows of {} weights, got {}", patch.degreeU, patch.degreeV,
                       rows, columns, quoted(weights)));
    patch.weights.reserve(rows * columns);
    for (std::size_t j = 0; j < rows; ++j) {
      const Json& row = weights[j];
      const std::string rowWhere = fmt::format("{}[{}]", weightsWhere, j);
      if (!row.is_array() || row.size() != columns)
        fail(source, rowWhere, fmt::format("expected a row of {} weights, got {}", columns, quoted(row)));
      for (std::size_t k = 0; k < columns; ++k) {
        if (!row[k].is_number())
          fail(source, fmt::format("{}[{}]", rowWhere, k), fmt::format("expected a number, got {}", quoted(row[k])));
        const double w = row[k].get<double>();
        if (!(w > 0.0) || !std::isfinite(w))
          fail(source, fmt::format("{}[{}]", rowWhere, k), fmt::format("a weight must be positive, got {}", w));
        patch.weights.push_back(w);
      }
    }
  }
  return patch;
}

Surface parseDocument(const Json& document, const std::string& source) {
  if (!document.is_object()) {
    throw Error(fmt::format(
        "{}: expected a JSON object {{\"units\": \"in\" or \"mm\", \"patches\": [...]}}, got {}",
        source, quoted(document)));
  }
  rejectUnknownKeys(document, {"units", "patches"}, source, "top level");
  Surface surface;
  surface.units = parseUnits(document, source);
  if (!document.contains("patches")) {
    throw Error(fmt::format("{}: missing \"patches\" (an array of at least one patch)", source));
  }
  const Json& patches = document["patches"];
  if (!patches.is_array()) {
    fail(source, "patches", fmt::format("expected an array of patches, got {}", quoted(patches)));
  }
  if (patches.empty()) fail(source, "patches", "no patches; a surface needs at least one");
  for (std::size_t i = 0; i < patches.size(); ++i) {
    surface.patches.push_back(parsePatch(patches[i], i, source));
  }
  return surface;
}

// ---------------------------------------------------------------------------------------
// Built-in examples: the paper's Section 4
// ---------------------------------------------------------------------------------------

// A bicubic patch over the 3 x 3 grid p_jk = (k, j, z[j][k]), as both test surfaces are
// printed: p_01 = (1, 0, .), p_10 = (0, 1, .), so k runs along x and j along y.
// (With u along y and v along x, r_u x r_v points to -z where the surface is flat-ish; the
// symmetrized Gauss map does not depend on the orientation.)
BezierPatch gridBicubic(const double (&z)[4][4]) {
  BezierPatch patch;
  patch.degreeU = 3;
  patch.degreeV = 3;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) {
      patch.control.push_back({static_cast<double>(k), static_cast<double>(j), z[j][k]});
    }
  }
  return patch;
}

// Test surface #1, Section 4.1 (Fig. 1). Row j lists z of p_j0 .. p_j3 as printed.
Surface paper1() {
  constexpr double z[4][4] = {
      {0.48, 1.00, 0.80, 0.40},  // p_00 .. p_03
      {0.90, 1.41, 0.60, 0.60},  // p_10 .. p_13
      {1.00, 0.88, 0.00, 0.72},  // p_20 .. p_23
      {0.80, 0.60, 0.40, 0.80},  // p_30 .. p_33
  };
  return {Units::inch, {gridBicubic(z)}};
}

// Test surface #2, Section 4.2 (Fig. 8): symmetric under p_jk <-> p_kj (x <-> y).
Surface paper2() {
  constexpr double z[4][4] = {
      {1.65, 3.05, 3.05, 2.05},  // p_00 .. p_03
      {3.05, 0.00, 4.10, 3.05},  // p_10 .. p_13
      {3.05, 4.10, 0.00, 3.05},  // p_20 .. p_23
      {2.05, 3.05, 3.05, 1.65},  // p_30 .. p_33
  };
  return {Units::inch, {gridBicubic(z)}};
}

// The Utah teapot's patches first to last - 1 (teapot.hpp), built like the paper's surfaces
// (valid: the knob's and the bottom's apexes have their normals' limits; tested).
template <std::size_t first, std::size_t last>
Surface teapot() {
  static_assert(first < last && last <= detail::kTeapotPatchCount);
  Surface surface{Units::inch, {}};
  for (std::size_t i = first; i < last; ++i) surface.patches.push_back(detail::teapotPatch(i));
  return surface;
}

constexpr detail::Example<Surface> kExamples[] = {
    {"paper-1", paper1},
    {"paper-2", paper2},
    {"teapot", teapot<0, 32>},
    {"teapot-rim", teapot<0, 4>},
    {"teapot-body", teapot<4, 12>},
    {"teapot-handle", teapot<12, 16>},
    {"teapot-spout", teapot<16, 20>},
    {"teapot-lid", teapot<20, 28>},
    {"teapot-bottom", teapot<28, 32>},
};

}  // namespace

// ---------------------------------------------------------------------------------------
// Public functions
// ---------------------------------------------------------------------------------------

std::string_view unitsName(Units units) { return units == Units::inch ? "in" : "mm"; }

void validateSurface(const Surface& surface, const std::string& sourceName) {
  try {
    validateSurface(surface);
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", sourceName, error.what()));
  }
}

void validateSurface(const Surface& surface) {
  if (surface.patches.empty()) throw Error("patches: no patches; a surface needs at least one");
  if (surface.trimmed() && surface.trims.size() != surface.patches.size())
    throw Error(fmt::format("trims: {} for {} patches; one per patch or none", surface.trims.size(),
                            surface.patches.size()));
  if (!surface.seamTolerances.empty() && surface.seamTolerances.size() != surface.patches.size())
    throw Error(fmt::format("seam tolerances: {} for {} patches; one per patch or none",
                            surface.seamTolerances.size(), surface.patches.size()));
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    if (!surface.seamTolerances.empty() &&
        !(surface.seamTolerances[i] >= 0.0 && std::isfinite(surface.seamTolerances[i])))
      throw Error(fmt::format("{}: its seam tolerance {} is not a finite non-negative number", patchPath(i),
                              surface.seamTolerances[i]));
    const PatchTrim* const trimmed = patchTrim(surface, i);
    if (trimmed) {
      const PatchTrim& trim = *trimmed;
      const std::string what = patchPath(i);
      validateAxisMap(trim.u, (what + ": its trim's u").c_str());
      validateAxisMap(trim.v, (what + ": its trim's v").c_str());
      if (!(trim.margin >= 0.0) || !std::isfinite(trim.margin))
        throw Error(fmt::format("{}: its trim's margin {} is not a finite non-negative number", what, trim.margin));
    }
    validatePatch(surface.patches[i], i, trimmed == nullptr);
  }
}

Surface parseSurface(std::string_view json, const std::string& sourceName, SurfaceCheck check) {
  const std::string source = displayName(sourceName);
  // A UTF-8 byte order mark, as some editors write, is not content.
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (json.substr(0, kByteOrderMark.size()) == kByteOrderMark) {
    json.remove_prefix(kByteOrderMark.size());
  }
  const Json document = detail::parseJsonDocument(json, source);
  Surface surface = parseDocument(document, source);
  if (check == SurfaceCheck::full) validateSurface(surface, source);
  return surface;
}

std::string surfaceToJson(const Surface& surface) {
  if (surface.trimmed())
    throw Error("surfaceToJson: a trimmed surface's trims (STEP/IGES trimming curves) have no JSON form");
  std::string out =
      fmt::format("{{\n  \"units\": \"{}\",\n  \"patches\": [", unitsName(surface.units));
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    const BezierPatch& patch = surface.patches[i];
    // Only what the text needs: the shape (to index the rows) and finiteness (JSON has no
    // NaN or infinity). Regularity is not checked: any such surface can be written.
    const bool shaped = patch.degreeU >= 0 && patch.degreeV >= 0 &&
                        patch.control.size() == static_cast<std::size_t>(patch.degreeU + 1) *
                                                    static_cast<std::size_t>(patch.degreeV + 1);
    const bool finite = std::all_of(patch.control.begin(), patch.control.end(), [](const Vec3& p) {
      return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    });
    if (!shaped || !finite) {
      throw Error(fmt::format(
          "surfaceToJson: {}: degree [{}, {}] with {} control points{} cannot be written",
          patchPath(i), patch.degreeU, patch.degreeV, patch.control.size(),
          finite ? "" : " (not all finite)"));
    }
    out += i == 0 ? "\n" : ",\n";
    out += fmt::format("    {{\n      \"degree\": [{}, {}],\n      \"control_points\": [",
                       patch.degreeU, patch.degreeV);
    for (int j = 0; j <= patch.degreeU; ++j) {
      out += j == 0 ? "\n        [" : ",\n        [";
      for (int k = 0; k <= patch.degreeV; ++k) {
        const Vec3& p = patch.at(j, k);
        out += fmt::format("{}[{}, {}, {}]", k == 0 ? "" : ", ", shortest(p.x), shortest(p.y),
                           shortest(p.z));
      }
      out += "]";
    }
    out += "\n      ]";
    if (patch.rational()) {
      if (patch.weights.size() != patch.control.size() ||
          !std::all_of(patch.weights.begin(), patch.weights.end(), [](double w) { return std::isfinite(w); }))
        throw Error(fmt::format("surfaceToJson: {}: {} weights for {} control points{} cannot be written",
                                patchPath(i), patch.weights.size(), patch.control.size(), " (or not all finite)"));
      out += ",\n      \"weights\": [";
      for (int j = 0; j <= patch.degreeU; ++j) {
        out += j == 0 ? "\n        [" : ",\n        [";
        for (int k = 0; k <= patch.degreeV; ++k) out += fmt::format("{}{}", k == 0 ? "" : ", ", shortest(patch.weight(j, k)));
        out += "]";
      }
      out += "\n      ]";
    }
    out += "\n    }";
  }
  out += surface.patches.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return out;
}

double surfaceScale(const Surface& surface) {
  double scale = 0.0;
  for (const BezierPatch& patch : surface.patches) scale = std::max(scale, patchScale(patch));
  return scale;
}

double controlPointTop(const Surface& surface) {
  double top = -std::numeric_limits<double>::infinity();
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& p : patch.control) top = std::max(top, p.z);
  return top;
}

std::vector<std::string> exampleSurfaceNames() {
  return detail::exampleNames<Surface>(kExamples);
}

Surface exampleSurface(const std::string& name) {
  return detail::makeExample<Surface>(kExamples, name, "surface");
}

}  // namespace scallop
