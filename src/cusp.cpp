#include "scallop/cusp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "scallop/bezier.hpp"
#include "scallop/contour.hpp"
#include "scallop/error.hpp"

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
double sampleCusp(const CrossGeometry& g, double delta, double radius, bool backward,
                  bool* overCap) {
  if (1.0 + radius * g.kappa <= 0.0) return -1.0;
  CrossGeometry h = g;
  if (backward) h.b = -h.b;
  const double l = contactDistance(delta, h, overCap);
  return std::isfinite(l) ? cuspHeight(l, radius, g.kappa) : kInf;
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
  std::vector<std::vector<CrossGeometry>> contacts;
  contacts.reserve(planes.size());
  for (const PlaneContacts& plane : planes) {
    if (plane.section == nullptr) throw Error("cuspStatistics: a plane without its section");
    contacts.push_back(contactsOf(surface, *plane.section, unitNormal, options.samplesPerPlane));
  }
  for (std::size_t k = 0; k + 1 < planes.size(); ++k) {
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
  const Extent extent = sampleExtent(surface, unitNormal);
  out.extentLo = extent.lo;
  out.extentHi = extent.hi;
  if ((extent.hi - extent.lo) / out.floor >= kMaxPlanes)
    throw Error(fmt::format("the scallop height {} allows steps down to {}, up to {:.0f} planes "
                            "across the surface; more than 100,000 is not a tool path (check "
                            "the units)",
                            height, out.floor, (extent.hi - extent.lo) / out.floor));

  const auto sectionAt = [&](double w) {
    ++out.sections;
    return planeSection(surface, unitNormal, w, tolerance);
  };
  // The pair (w, w + delta)'s worst cusp; the contacts of w + delta are returned for reuse.
  const auto worst = [&](const std::vector<CrossGeometry>& here, double w, double delta,
                         std::vector<CrossGeometry>& next) {
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
  std::vector<CrossGeometry> here =
      contactsOf(surface, sectionAt(w), unitNormal, options.samplesPerPlane);
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
        if (accepted.empty() && w + out.floor <= extent.hi)
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
  return out;
}

}  // namespace scallop
