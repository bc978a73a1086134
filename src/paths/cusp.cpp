#include "scallop/paths/cusp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Contacts where the plane is within this sine of tangency are skipped: at an isolated
// tangent point (a touch point, a saddle junction) the cross direction t is undefined.
constexpr double kTangentSine = 1e-6;

double sinc(double x) { return x == 0.0 ? 1.0 : std::sin(x) / x; }

// S(l) = sin(kappa l) / kappa and C(l) = (1 - cos(kappa l)) / kappa, without 1 / kappa.
double arcS(double l, double kappa) { return l * sinc(kappa * l); }
double arcC(double l, double kappa) {
  const double x = kappa * l;
  if (x == 0.0) return 0.0;
  const double s = std::sin(0.5 * x);
  return l * 2.0 * s * s / x;
}

struct Extent {
  double lo = kInf;
  double hi = -kInf;
  double leastSine = 1.0;  // least sin(angle(N, n)) on the grid
};

Extent sampleExtent(const Surface& surface, const Vec3& m) {
  constexpr int kGrid = 32;
  Extent e;
  for (std::size_t p = 0; p < surface.patches.size(); ++p)
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; j <= kGrid; ++j) {
        const double u = double(i) / kGrid, v = double(j) / kGrid;
        if (!surfaceKeepsPoint(surface, p, u, v)) continue;
        const double s = dot(m, point(surface.patches[p], u, v));
        e.lo = std::min(e.lo, s);
        e.hi = std::max(e.hi, s);
        const double c = dot(m, upwardNormal(surface, p, u, v));
        e.leastSine = std::min(e.leastSine, std::sqrt(std::max(0.0, 1.0 - c * c)));
      }
  return e;
}

std::vector<CrossGeometry> contactsOf(const Surface& surface, const PlaneSection& section,
                                      const Vec3& m, std::size_t budget) {
  std::size_t total = 0;
  for (const SectionCurve& curve : section.curves) total += curve.points.size();
  const std::size_t stride = std::max<std::size_t>(1, (total + budget - 1) / std::max<std::size_t>(budget, 1));
  std::vector<CrossGeometry> out;
  out.reserve(total / stride + 1);
  std::size_t index = 0;
  for (const SectionCurve& curve : section.curves)
    for (const SectionPoint& p : curve.points) {
      if (index++ % stride != 0) continue;
      const CrossGeometry g = crossGeometry(surface, p, m);
      if (g.a > kTangentSine) out.push_back(g);
    }
  return out;
}

// Per sample: the cusp toward the neighbour `delta` away (b flipped for the backward side),
// or a negative value for a tight concave sample (1 + R kappa <= 0).
// With centre planes (raster) the plane coordinate W of the centre c = p + R n moves along the
// offset circle, of radius rho + R: W(l) - W(0) = (1 + R kappa) (a S(l) - b C(l)), so the
// neighbour's contact is contactDistance(delta / (1 + R kappa)) away.
double sampleCusp(const CrossGeometry& g, double delta, double radius, bool backward,
                  bool* overCap, bool centrePlanes = false) {
  const double stretch = 1.0 + radius * g.kappa;
  if (stretch <= 0.0) return -1.0;
  CrossGeometry h = g;
  if (backward) h.b = -h.b;
  bool cap = false;
  const double l = contactDistance(centrePlanes ? delta / stretch : delta, h, &cap);
  if (overCap) *overCap = cap;
  // Centre planes in a concave sample whose neighbouring plane's centres never reach it
  // along its offset circle (the circle's W extent is below delta): no neighbour cusp to
  // speak of, the ball of its own plane and the drop envelope decide there. Counted as tight.
  if (centrePlanes && cap && g.kappa < 0.0) return -1.0;
  const double cusp = std::isfinite(l) ? cuspHeight(l, radius, g.kappa) : kInf;
  // In a concave circle of radius rho > R both balls' centres lie within rho - R of its
  // centre O, so every point of the circle is within 2 (rho - R) of each ball: the cusp never
  // exceeds that, however far apart the contacts (near-tight bowls, where the centre barely
  // moves while the contact sweeps: with centre planes l = delta / (a (1 + R kappa)) is large).
  return g.kappa < 0.0 ? std::min(cusp, 2.0 * stretch / -g.kappa) : cusp;
}

// Centre planes (raster, CuspOptions::centrePlanes): the surface sampled on a grid per patch,
// each sample with the plane coordinate W = N . (p + R n) of the centre that touches it, sorted
// by W. A pair of planes (w, w + delta) is judged by every sample in its strip.
struct CentreSample {
  double w = 0.0;
  CrossGeometry g;
};

struct CentreSamples {
  std::vector<CentreSample> samples;  // by w
  double leastSine = 1.0;

  // The worst cusp over the samples with W in [w, w + delta], both directions; negative
  // (none) when the strip holds no sample.
  double worst(double w, double delta, double radius) const {
    const auto first = std::lower_bound(samples.begin(), samples.end(), w,
                                        [](const CentreSample& s, double x) { return s.w < x; });
    double h = -1.0;
    for (auto it = first; it != samples.end() && it->w <= w + delta; ++it)
      for (const bool backward : {false, true}) h = std::max(h, sampleCusp(it->g, delta, radius, backward, nullptr, true));
    return h;
  }
};

// With centre planes the cross direction T lies on the offset surface c = r + R n, and the
// cusp is that of two balls on its osculating circle along T: of curvature kappa_o(T) =
// T . S (Id + R S)^-1 T, S the shape operator (dn = S dr, n upward: positive where the
// surface bends away from the ball), since dc = (Id + R S) dr and dn = S (Id + R S)^-1 dc.
// The model's circle is the surface's with radius rho = 1 / kappa_o - R, so the effective
// curvature is kappa_o / (1 - R kappa_o) (its offset circle then has curvature kappa_o).
// Along a principal direction this is the surface's own normal curvature; elsewhere it differs
// (paper-1 with R = 1 in: 0.19 against the offset's, and a cusp estimate of 0.93 H where the
// balls leave 1.23 H). NaN where Id + R S is not positive definite (a concave radius <= R).
double effectiveCurvature(const BezierPatch& patch, double u, double v, const Vec3& t, const Vec3& n,
                          double radius) {
  const PatchDerivatives d = derivativesToSecondOrder(patch, u, v);
  const double e = dot(d.u, d.u), f = dot(d.u, d.v), g = dot(d.v, d.v);
  const double det = e * g - f * f;
  if (!(det > 1e-20 * e * g && det > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // T = alpha r_u + beta r_v.
  const double tu = dot(t, d.u), tv = dot(t, d.v);
  const double alpha = (g * tu - f * tv) / det, beta = (e * tv - f * tu) / det;
  // S = -I^-1 II in (u, v) coordinates, II = [[L, M], [M, N]] with n.
  const double l = dot(d.uu, n), m = dot(d.uv, n), nn = dot(d.vv, n);
  const double s11 = -(g * l - f * m) / det, s12 = -(g * m - f * nn) / det;
  const double s21 = -(e * m - f * l) / det, s22 = -(e * nn - f * m) / det;
  // A = Id + R S and its inverse.
  const double a11 = 1.0 + radius * s11, a12 = radius * s12, a21 = radius * s21, a22 = 1.0 + radius * s22;
  const double adet = a11 * a22 - a12 * a21;
  // Id + R S has the eigenvalues 1 + R k_i: both positive iff det > 0 and trace > 0.
  if (!(adet > 0.0) || !(a11 + a22 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // x = S A^-1 (alpha, beta).
  const double y1 = (a22 * alpha - a12 * beta) / adet, y2 = (-a21 * alpha + a11 * beta) / adet;
  const double x1 = s11 * y1 + s12 * y2, x2 = s21 * y1 + s22 * y2;
  // kappa_o = T . (x1 r_u + x2 r_v) = (alpha, beta) I (x1, x2).
  const double kappaOffset = alpha * (e * x1 + f * x2) + beta * (f * x1 + g * x2);
  return kappaOffset / (1.0 - radius * kappaOffset);
}

CentreSamples centreSamples(const Surface& surface, const Vec3& m, double radius, double flatStep) {
  CentreSamples out;
  for (std::size_t p = 0; p < surface.patches.size(); ++p) {
    const BezierPatch& patch = surface.patches[p];
    // About two samples per flat step-over across the patch's control box, 16 to 128.
    Vec3 lo = patch.control.front(), hi = lo;
    for (const Vec3& c : patch.control) {
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
    }
    const double size = norm(hi - lo);
    const int grid = static_cast<int>(std::clamp(std::ceil(2.0 * size / flatStep), 16.0, 128.0));
    for (int i = 0; i <= grid; ++i) {
      checkCancelled();
      for (int j = 0; j <= grid; ++j) {
        const double u = double(i) / grid, v = double(j) / grid;
        if (!surfaceKeepsPoint(surface, p, u, v)) continue;
        const Vec3 q = point(patch, u, v);
        const Vec3 n = upwardNormal(surface, p, u, v);
        CrossGeometry g = crossGeometry(surface, SectionPoint{q, p, u, v}, m);
        out.leastSine = std::min(out.leastSine, g.a);
        if (!(g.a > kTangentSine)) continue;
        const Vec3 t = (m - g.b * n) / g.a;
        const double kappa = effectiveCurvature(patch, u, v, t, n, radius);
        // Tight (a concave radius <= R): the drop envelope lifts the ball there; the sample
        // is counted as such (1 + R kappa <= 0).
        g.kappa = std::isfinite(kappa) ? kappa : -2.0 / radius;
        out.samples.push_back({dot(m, q + radius * n), g});
      }
    }
  }
  std::sort(out.samples.begin(), out.samples.end(),
            [](const CentreSample& a, const CentreSample& b) { return a.w < b.w; });
  return out;
}

void requirePositive(const char* what, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(fmt::format("{} must be a positive number, got {}", what, value));
}

double chordalTolerance(const Surface& surface, const CuspOptions& options) {
  return options.chordalTolerance > 0.0 ? options.chordalTolerance
                                        : 1e-4 * std::max(surfaceScale(surface), 1e-300);
}

}  // namespace

double cuspHeight(double l, double toolRadius, double kappa) {
  if (!(toolRadius > 0.0) || !std::isfinite(toolRadius) || !(l >= 0.0) || !std::isfinite(l) ||
      !std::isfinite(kappa))
    throw Error(fmt::format("cuspHeight: needs R > 0, l >= 0 and a finite curvature, got R = {}, "
                            "l = {}, kappa = {}",
                            toolRadius, l, kappa));
  if (!(1.0 + toolRadius * kappa > 0.0))
    throw Error(fmt::format("cuspHeight: the concave radius {} is not larger than the tool "
                            "radius {}: the ball cannot follow the surface",
                            -1.0 / kappa, toolRadius));
  const double x = kappa * l;
  if (std::abs(x) > 2.0 * std::numbers::pi + 1e-12)
    throw Error(fmt::format("cuspHeight: kappa l = {} goes more than once around the circle", x));
  const double r = toolRadius;
  // theta = x; (rho + R) sin(theta / 2) = (1 + R kappa) (l / 2) sinc(x / 2).
  const double m = (1.0 + r * kappa) * 0.5 * l * sinc(0.5 * x);
  if (m > r) return kInf;
  const double s4 = std::sin(0.25 * x);
  // (rho + R) cos(theta / 2) - rho = R cos(theta / 2) - 2 sin^2(theta / 4) / kappa
  //                                = R - 2 R sin^2(x / 4) - l 2 sin^2(x / 4) / x.
  const double q = x == 0.0 ? 0.0 : l * 2.0 * s4 * s4 / x;
  // R - sqrt(R^2 - m^2) = m^2 / (R + sqrt(R^2 - m^2)): no cancellation.
  return m * m / (r + std::sqrt(r * r - m * m)) - 2.0 * r * s4 * s4 - q;
}

CrossGeometry crossGeometry(const Surface& surface, const SectionPoint& point,
                            const Vec3& unitNormal) {
  const BezierPatch& patch = surface.patches.at(point.patch);
  double u = point.u, v = point.v;
  const Vec3 n = upwardNormal(surface, point.patch, u, v);
  CrossGeometry g;
  g.b = dot(unitNormal, n);
  const Vec3 across = unitNormal - g.b * n;
  const double length = norm(across);
  g.a = length;
  if (!(length > 0.0)) return g;
  const Vec3 t = across / length;
  // On a collapsed edge (an apex row) r_u or r_v vanishes and t has no (alpha, beta); the
  // curvature is taken a little inside the patch.
  for (int attempt = 0; attempt < 2; ++attempt) {
    const PatchDerivatives d = derivativesToSecondOrder(patch, u, v);
    const double e = dot(d.u, d.u), f = dot(d.u, d.v), gg = dot(d.v, d.v);
    const double det = e * gg - f * f;
    if (det > 1e-20 * e * gg && det > 0.0) {
      const double tu = dot(t, d.u), tv = dot(t, d.v);
      const double alpha = (gg * tu - f * tv) / det;
      const double beta = (e * tv - f * tu) / det;
      const double first = e * alpha * alpha + 2.0 * f * alpha * beta + gg * beta * beta;
      const double second =
          dot(d.uu, n) * alpha * alpha + 2.0 * dot(d.uv, n) * alpha * beta + dot(d.vv, n) * beta * beta;
      g.kappa = first > 0.0 ? -second / first : 0.0;
      return g;
    }
    u = 0.5 + (u - 0.5) * (1.0 - 1e-4);
    v = 0.5 + (v - 0.5) * (1.0 - 1e-4);
  }
  return g;
}

double contactDistance(double delta, const CrossGeometry& g, bool* overCap) {
  if (overCap) *overCap = false;
  const double a = g.a, b = g.b, kappa = g.kappa;
  if (kappa == 0.0) return a > 0.0 ? delta / a : kInf;
  // The circle's extreme point in direction N: a cos(kappa l) = b sin(kappa l).
  const double theta = kappa > 0.0 ? std::atan2(a, b) : std::atan2(a, -b);
  const double top = theta / std::abs(kappa);
  const auto rise = [&](double l) { return a * arcS(l, kappa) - b * arcC(l, kappa); };
  if (rise(top) <= delta) {
    if (overCap) *overCap = true;
    return 2.0 * top;
  }
  // rise is increasing on [0, top] (its derivative a cos(kappa l) - b sin(kappa l) > 0).
  double lo = 0.0, hi = top;
  double l = a > 0.0 ? std::min(delta / a, 0.5 * top) : 0.5 * top;
  for (int i = 0; i < 100; ++i) {
    const double f = rise(l) - delta;
    if (f > 0.0) hi = l; else lo = l;
    const double slope = a * std::cos(kappa * l) - b * std::sin(kappa * l);
    double next = slope > 0.0 ? l - f / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - l) <= 1e-15 * l || hi - lo <= 1e-15 * hi) return next;
    l = next;
  }
  return l;
}

std::pair<double, double> sampledExtent(const Surface& surface, const Vec3& unitNormal) {
  const Extent e = sampleExtent(surface, unitNormal);
  return {e.lo, e.hi};
}

CuspStatistics cuspStatistics(const Surface& surface, const Vec3& unitNormal,
                              const std::vector<PlaneContacts>& planes,
                              const CuspOptions& options) {
  requirePositive("the tool radius", options.toolRadius);
  CuspStatistics out;
  std::vector<double> heights;
  if (options.centrePlanes) {
    const double r = options.toolRadius, h = options.scallopHeight;
    const double flatStep = h > 0.0 && h < r ? 2.0 * std::sqrt(2.0 * r * h - h * h) : r / 4.0;
    const CentreSamples samples = centreSamples(surface, unitNormal, r, flatStep);
    for (std::size_t k = 0; k + 1 < planes.size(); ++k) {
      const double w = planes[k].offset, delta = planes[k + 1].offset - w;
      if (!(delta > 0.0))
        throw Error(fmt::format("cuspStatistics: plane offsets must increase, got {} then {}", w,
                                planes[k + 1].offset));
      ++out.pairs;
      const auto first = std::lower_bound(samples.samples.begin(), samples.samples.end(), w,
                                          [](const CentreSample& s, double x) { return s.w < x; });
      for (auto it = first; it != samples.samples.end() && it->w <= w + delta; ++it)
        for (const bool backward : {false, true}) {
          bool cap = false;
          const double cusp = sampleCusp(it->g, delta, options.toolRadius, backward, &cap, true);
          if (cusp < 0.0) {
            ++out.tooTight;
            continue;
          }
          out.overCap += cap ? 1 : 0;
          heights.push_back(cusp);
        }
    }
  }
  std::vector<std::vector<CrossGeometry>> contacts;
  contacts.reserve(planes.size());
  for (const PlaneContacts& plane : options.centrePlanes ? std::vector<PlaneContacts>{} : planes) {
    if (plane.section == nullptr) throw Error("cuspStatistics: a plane without its section");
    contacts.push_back(contactsOf(surface, *plane.section, unitNormal, options.samplesPerPlane));
  }
  for (std::size_t k = 0; k + 1 < contacts.size(); ++k) {
    const double delta = planes[k + 1].offset - planes[k].offset;
    if (!(delta > 0.0))
      throw Error(fmt::format("cuspStatistics: plane offsets must increase, got {} then {}",
                              planes[k].offset, planes[k + 1].offset));
    ++out.pairs;
    for (int side = 0; side < 2; ++side)
      for (const CrossGeometry& g : contacts[k + static_cast<std::size_t>(side)]) {
        bool cap = false;
        const double h = sampleCusp(g, delta, options.toolRadius, side == 1, &cap);
        if (h < 0.0) {
          ++out.tooTight;
          continue;
        }
        out.overCap += cap ? 1 : 0;
        heights.push_back(h);
      }
  }
  out.samples = heights.size();
  if (heights.empty()) return out;
  std::sort(heights.begin(), heights.end());
  out.max = heights.back();
  const std::size_t rank =
      static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(heights.size())));
  out.p99 = heights[std::max<std::size_t>(rank, 1) - 1];
  double sum = 0.0;
  std::size_t finite = 0;
  for (double h : heights)
    if (std::isfinite(h)) sum += h, ++finite;
  out.mean = finite > 0 ? sum / static_cast<double>(finite) : kInf;
  return out;
}

AdaptiveOffsets adaptivePlaneOffsets(const Surface& surface, const Vec3& unitNormal,
                                     const CuspOptions& options) {
  validateSurface(surface);
  const double radius = options.toolRadius, height = options.scallopHeight;
  requirePositive("the tool radius", radius);
  requirePositive("the scallop height", height);
  if (height >= radius)
    throw Error(fmt::format("the scallop height {} must be smaller than the tool radius {}",
                            height, radius));
  requirePositive("the floor fraction", options.floorFraction);
  requirePositive("the largest step factor", options.maxStepFactor);
  if (options.maxStepFactor < options.floorFraction)
    throw Error("the largest step factor must not be below the floor fraction");
  if (options.bisectionSteps < 0 || options.bisectionSteps > 60)
    throw Error(fmt::format("the bisection budget must be in [0, 60], got {}", options.bisectionSteps));
  if (options.samplesPerPlane == 0) throw Error("samplesPerPlane must be at least 1");
  const double tolerance = chordalTolerance(surface, options);
  requirePositive("the chordal tolerance", tolerance);

  AdaptiveOffsets out;
  out.flatStepOver = 2.0 * std::sqrt(2.0 * radius * height - height * height);
  out.floor = options.floorFraction * out.flatStepOver;
  const double ceiling = options.maxStepFactor * out.flatStepOver;
  Extent extent;
  CentreSamples centres;
  if (options.centrePlanes) {
    centres = centreSamples(surface, unitNormal, radius, out.flatStepOver);
    if (centres.samples.empty()) throw Error("adaptive plane offsets: every sampled normal is parallel to the planes' normal");
    extent.lo = centres.samples.front().w;
    extent.hi = centres.samples.back().w;
    extent.leastSine = centres.leastSine;
  } else {
    extent = sampleExtent(surface, unitNormal);
  }
  out.extentLo = extent.lo;
  out.extentHi = extent.hi;
  if ((extent.hi - extent.lo) / out.floor >= kMaxPlanes)
    throw Error(fmt::format("the scallop height {} allows steps down to {}, up to {:.0f} planes "
                            "across the surface; more than 100,000 is not a tool path (check "
                            "the units)",
                            height, out.floor, (extent.hi - extent.lo) / out.floor));

  const auto sectionAt = [&](double w) {
    // Progress by the plane's place across the surface (polls the job's cancellation too).
    advanceStage(static_cast<std::size_t>(std::clamp((w - extent.lo) / (extent.hi - extent.lo), 0.0, 1.0) * 1000.0),
                 1000);
    ++out.sections;
    return planeSection(surface, unitNormal, w, tolerance);
  };
  // The pair (w, w + delta)'s worst cusp; the contacts of w + delta are returned for reuse.
  const auto worst = [&](const std::vector<CrossGeometry>& here, double w, double delta,
                         std::vector<CrossGeometry>& next) {
    checkCancelled();
    if (options.centrePlanes) return std::max(0.0, centres.worst(w, delta, radius));
    double h = 0.0;
    for (const CrossGeometry& g : here) h = std::max(h, sampleCusp(g, delta, radius, false, nullptr));
    next.clear();
    if (h > height) return h;  // no need for the section
    next = contactsOf(surface, sectionAt(w + delta), unitNormal, options.samplesPerPlane);
    for (const CrossGeometry& g : next) h = std::max(h, sampleCusp(g, delta, radius, true, nullptr));
    return h;
  };

  const double first = std::max(out.flatStepOver * extent.leastSine, out.floor);
  double w = extent.lo + 0.5 * first;
  std::vector<CrossGeometry> here;
  if (!options.centrePlanes) here = contactsOf(surface, sectionAt(w), unitNormal, options.samplesPerPlane);
  std::vector<CrossGeometry> trial, accepted;
  for (;;) {
    out.offsets.push_back(w);
    if (out.offsets.size() > static_cast<std::size_t>(kMaxPlanes))
      throw Error("the adaptive spacing gives more than 100,000 planes; not a tool path");
    if (w + out.floor > extent.hi) break;
    double step = ceiling;
    double cusp = worst(here, w, ceiling, accepted);
    if (!(cusp <= height)) {
      double lo = out.floor, hi = ceiling;
      bool found = false;
      for (int i = 0; i < options.bisectionSteps; ++i) {
        const double mid = 0.5 * (lo + hi);
        const double h = worst(here, w, mid, trial);
        if (h <= height) {
          lo = mid, found = true, cusp = h;
          accepted.swap(trial);
        } else {
          hi = mid;
        }
      }
      if (!found) {
        cusp = worst(here, w, out.floor, accepted);
        if (!(cusp <= height)) ++out.floorSteps;
        if (!options.centrePlanes && accepted.empty() && w + out.floor <= extent.hi)
          accepted = contactsOf(surface, sectionAt(w + out.floor), unitNormal,
                                options.samplesPerPlane);
        lo = out.floor;
      }
      step = lo;
    }
    if (w + step > extent.hi) break;
    out.worstCusp.push_back(cusp);
    w += step;
    here.swap(accepted);
  }
  // The last plane as near the far end as the first is to the near one: a last step that
  // overshoots s_hi would otherwise leave up to a whole step beyond the last plane.
  const double rest = extent.hi - w;
  if (rest > 0.5 * first) {
    const double step = std::max(rest - 0.5 * first, std::min(out.floor, rest));
    std::vector<CrossGeometry> last;
    out.worstCusp.push_back(worst(here, w, step, last));
    out.offsets.push_back(w + step);
  }
  return out;
}

double flatCusp(double radius, double spacing) {
  if (!(spacing < 2.0 * radius))
    throw Error(fmt::format("the spacing {} is not below the ball's diameter {}: neighbouring passes would leave "
                            "uncut ridges of any height (give a spacing below 2 R, or --scallop-height)",
                            spacing, 2.0 * radius));
  return radius - std::sqrt(radius * radius - 0.25 * spacing * spacing);
}

}  // namespace scallop
