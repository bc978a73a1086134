// The optimal slicing orientation: Gauss map -> stereographic plane -> medial axis ->
// maximisation of tan(alpha) along its edges (eq 13) -> N* (eq 14) -> certificate.
// See include/scallop/optimal_slicing.hpp for the contract.

#include "scallop/optimal_slicing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <fmt/format.h>

#include "scallop/bernstein.hpp"
#include "scallop/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/medial_axis.hpp"
#include "scallop/vector.hpp"

namespace scallop {
namespace {

// The certificate proves alpha* less this (1e-6 degree-ish): the polish finds the true
// local maxima of |n . N*| to about 1e-12, so a larger gap means a missed maximum.
constexpr double kCertificateMarginRad = 1e-7;

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

// A local maximum of |n . m| over the surface: where the slicing planes come nearest to
// tangency (the optimal circle's contacts with the Gauss map).
struct Contact {
  const BezierPatch* patch;
  double u;
  double v;
  double value;
};

// Climbs |n . m| from the contact's (u, v) by a pattern search in the parameter square
// (steps halving from `step` to 1e-12): the true local maximum, not a sample.
void climb(Contact& c, const Vec3& m, double step) {
  auto value = [&](double u, double v) { return std::abs(dot(unitNormal(*c.patch, u, v), m)); };
  c.value = value(c.u, c.v);
  for (; step > 1e-12; step *= 0.5) {
    for (bool moved = true; moved;) {
      moved = false;
      for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1},
                                   std::pair{0, -1}, std::pair{1, 1}, std::pair{-1, -1},
                                   std::pair{1, -1}, std::pair{-1, 1}}) {
        const double u = std::clamp(c.u + du * step, 0.0, 1.0);
        const double v = std::clamp(c.v + dv * step, 0.0, 1.0);
        const double g = value(u, v);
        if (g > c.value) c.value = g, c.u = u, c.v = v, moved = true;
      }
    }
  }
}

// All local maxima of |n . m| (n the unit normal): each patch is sampled on a grid, and
// every grid point that is a local maximum there is climbed. A maximum narrower than the
// grid step could be missed; the certificate (which subdivides in Bernstein form) would
// then fail and say so.
std::vector<Contact> findContacts(const Surface& surface, const Vec3& m) {
  constexpr int kGrid = 24;
  std::vector<Contact> contacts;
  for (const BezierPatch& patch : surface.patches) {
    std::array<std::array<double, kGrid + 1>, kGrid + 1> grid{};
    for (int i = 0; i <= kGrid; ++i) {
      for (int j = 0; j <= kGrid; ++j) {
        grid[i][j] = std::abs(dot(unitNormal(patch, double(i) / kGrid, double(j) / kGrid), m));
      }
    }
    for (int i = 0; i <= kGrid; ++i) {
      for (int j = 0; j <= kGrid; ++j) {
        bool peak = true;
        for (int di = -1; di <= 1 && peak; ++di) {
          for (int dj = -1; dj <= 1 && peak; ++dj) {
            const int a = i + di, b = j + dj;
            if (a < 0 || a > kGrid || b < 0 || b > kGrid || (di == 0 && dj == 0)) continue;
            if (grid[a][b] > grid[i][j]) peak = false;
          }
        }
        if (!peak) continue;
        contacts.push_back({&patch, double(i) / kGrid, double(j) / kGrid, grid[i][j]});
      }
    }
  }
  // Climb the highest peaks only: on a flat stretch (a direction orthogonal to a whole
  // family of normals) every sample is a peak, and only the top ones can matter.
  constexpr std::size_t kClimbed = 16;
  std::sort(contacts.begin(), contacts.end(),
            [](const Contact& a, const Contact& b) { return a.value > b.value; });
  if (contacts.size() > kClimbed) contacts.resize(kClimbed);
  for (Contact& c : contacts) climb(c, m, 1.0 / kGrid);
  return contacts;
}

double largest(const std::vector<Contact>& contacts) {
  double best = 0.0;
  for (const Contact& c : contacts) best = std::max(best, c.value);
  return best;
}

// Unit steps in the tangent plane at m (basis e1, e2) that lower the largest of the
// linearised active contacts f_i(m + d) ~ c_i + g_i . d, with g_i = sign(n_i . m) (n_i . e1,
// n_i . e2) (the contact point's own motion is second order: it is a local maximum). For
// each contact alone, its steepest descent; for each pair, the two directions along which
// the pair stays level (d . (g_i - g_j) = 0) pointing downhill; for each triple, the
// direction towards the point where all three are level. Only those that lower the
// linearised maximum are kept.
std::vector<Vec3> minimaxDirections(const std::vector<Contact>& contacts, const Vec3& m,
                                    const Vec3& e1, const Vec3& e2, double top) {
  struct Linear {
    double c;
    Vec2 g;
  };
  std::vector<Linear> lin;
  for (const Contact& contact : contacts) {
    const Vec3 n = unitNormal(*contact.patch, contact.u, contact.v);
    const double sign = dot(n, m) >= 0.0 ? 1.0 : -1.0;
    if (contact.value >= top - 1e-6) lin.push_back({contact.value, {sign * dot(n, e1), sign * dot(n, e2)}});
  }
  std::vector<Vec2> candidates;
  for (std::size_t i = 0; i < lin.size(); ++i) {
    if (norm(lin[i].g) > 0.0) candidates.push_back(-(1.0 / norm(lin[i].g)) * lin[i].g);
    for (std::size_t j = i + 1; j < lin.size(); ++j) {
      const Vec2 diff = lin[i].g - lin[j].g;
      if (norm(diff) == 0.0) continue;
      const Vec2 along{-diff.y / norm(diff), diff.x / norm(diff)};
      candidates.push_back(along);
      candidates.push_back(-along);
      for (std::size_t k = j + 1; k < lin.size(); ++k) {
        // g_i . d + c_i = g_j . d + c_j = g_k . d + c_k: two linear equations in d.
        const Vec2 a = lin[i].g - lin[j].g;
        const Vec2 b = lin[i].g - lin[k].g;
        const double det = cross(a, b);
        if (det == 0.0) continue;
        const double ra = lin[j].c - lin[i].c;
        const double rb = lin[k].c - lin[i].c;
        const Vec2 d{(ra * b.y - rb * a.y) / det, (a.x * rb - b.x * ra) / det};
        if (norm(d) > 0.0) candidates.push_back((1.0 / norm(d)) * d);
      }
    }
  }
  std::vector<Vec3> out;
  for (const Vec2& d : candidates) {
    double worst = -1.0;
    for (const Linear& l : lin) worst = std::max(worst, l.c + 1e-3 * dot(l.g, d));
    double now = -1.0;
    for (const Linear& l : lin) now = std::max(now, l.c);
    if (worst < now) out.push_back(d.x * e1 + d.y * e2);
  }
  return out;
}

// Polishes a direction found on the polygonal Gauss map against the true surface: a
// pattern search on the sphere minimising the largest |n . m| (maximising the minimum angle
// alpha), from steps of the Gauss-map tolerance down to 1e-10 rad. The medial axis has put
// m in the right basin; this removes the polygon's error, so that alpha* no longer depends
// on the tolerance. While m moves, only the contacts that matter are re-climbed (from where
// they were, with small steps); a full search at the end checks that no other maximum has
// overtaken them, and polishing resumes if one has.
Vec3 polishDirection(const Surface& surface, Vec3 m, double initialStep, double& value) {
  constexpr double finalStep = 1e-10;
  for (int pass = 0; pass < 8; ++pass) {
    std::vector<Contact> all = findContacts(surface, m);
    const double top = largest(all);
    // Contacts within a few steps' worth of the top may become the top as m moves.
    std::vector<Contact> active;
    for (const Contact& c : all) {
      if (c.value >= top - 4.0 * initialStep) active.push_back(c);
    }
    auto evaluate = [&](const Vec3& candidate, std::vector<Contact>& cs) {
      for (Contact& c : cs) climb(c, candidate, 1e-3);
      return largest(cs);
    };
    value = top;
    for (double step = initialStep; step > finalStep; step *= 0.5) {
      for (int rounds = 0; rounds < 64; ++rounds) {
        const Vec3 e1 = orthogonal(m);
        const Vec3 e2 = cross(m, e1);
        bool moved = false;
        // Trial steps: the minimax steps of the linearised active contacts (below), then
        // eight fixed directions. At a point where two or three contacts are level, the
        // descent cone can be narrower than the fixed directions' spacing: the minimax steps
        // find it.
        std::vector<Vec3> directions = minimaxDirections(active, m, e1, e2, value);
        for (const Vec3& d : {e1, -e1, e2, -e2, normalized(e1 + e2), normalized(e1 - e2),
                              normalized(-e1 + e2), normalized(-e1 - e2)}) {
          directions.push_back(d);
        }
        for (const Vec3& d : directions) {
          const Vec3 candidate = normalized(m + step * d);
          std::vector<Contact> trial = active;
          const double f = evaluate(candidate, trial);
          if (f < value) {
            value = f;
            m = candidate;
            active = std::move(trial);
            moved = true;
            break;
          }
        }
        if (!moved) break;
      }
    }
    const double check = largest(findContacts(surface, m));
    if (check <= value * (1.0 + 1e-14) + 1e-15) return m;
    value = check;  // another maximum overtook the active ones: polish again
  }
  return m;
}

// Proves P = cos^2(bound) |N|^2 - (N . m)^2 > 0 on the cell (P given in Bernstein form on
// it): then |n . m| < cos(bound), no normal within `bound` of +-m.
bool provePositive(const Bernstein2& p, int depth, int maxDepth, std::size_t& cells) {
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

}  // namespace

bool certifyClearance(const Surface& surface, const Vec3& n, double lowerBoundRad,
                      std::size_t& cells, int maxDepth) {
  if (!(lowerBoundRad > 0.0)) return true;
  const Vec3 m = normalized(n);
  const double c = std::cos(lowerBoundRad);
  for (const BezierPatch& patch : surface.patches) {
    const std::array<Bernstein2, 3> normal = normalPolynomials(patch);
    Bernstein2 dotM = scale(normal[0], m.x);
    dotM = add(dotM, scale(normal[1], m.y));
    dotM = add(dotM, scale(normal[2], m.z));
    const Bernstein2 p =
        subtract(scale(normalLengthSquared(patch), c * c), multiply(dotM, dotM));
    if (!provePositive(p, 0, maxDepth, cells)) return false;
  }
  return true;
}

OptimalSlicing optimalSlicing(const Surface& surface, const OptimalSlicingOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const double tol = options.toleranceRad;
  if (!(tol > 0.0) || !(tol < 0.1) || !std::isfinite(tol)) {
    throw Error(fmt::format("the tolerance must be an angle in (0, {} deg), got {} deg",
                            0.1 * 180.0 / std::numbers::pi, tol * 180.0 / std::numbers::pi));
  }
  validateSurface(surface);
  OptimalSlicing result;
  GaussMapOptions gaussOptions;
  gaussOptions.toleranceRad = tol;
  result.gaussMap = symmetrizedGaussMap(surface, gaussOptions);
  const GaussMap& map = result.gaussMap;
  result.pole = map.pole;
  const Rotation3 back = transpose(map.toPoleFrame);
  std::vector<Vec3> rivals;  // medial-axis directions to polish (the best first)

  if (map.kind == GaussMapKind::point) {
    // A plane: every direction in the plane of the surface is at 90 degrees.
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
  } else {
    if (map.loops.empty()) throw Error("the complement of the Gauss map is empty: no slicing direction avoids every surface normal");
    PlanarDomain domain;
    domain.loops = map.loops;
    const MedialAxis axis = medialAxis(domain);
    result.medialAxisEdges = axis.edges.size();
    result.medialAxisRebuilds = axis.rebuilds;
    double bestAlpha = -1.0;
    std::vector<std::pair<double, PlaneCircle>> circles;  // every candidate, for rival basins
    for (const MedialEdge& edge : axis.edges) {
      std::vector<Vec2> curve;
      const int samples = edge.kind == MedialEdge::Kind::linear ? 1 : 8;
      for (int i = 0; i <= samples; ++i) curve.push_back(pointAt(edge, static_cast<double>(i) / samples));
      result.medialAxisCurves.push_back(std::move(curve));
      std::vector<double> ts = stationaryParameters(edge);
      ts.push_back(0.0);
      ts.push_back(1.0);
      for (double t : ts) {
        const Vec2 c = pointAt(edge, t);
        const double r = radiusAt(edge, t);
        const double rho = norm(c);
        // Circles that hold the origin (the south pole, a surface normal's antipode) are not
        // in the complement; the medial axis never yields them but rounding might.
        if (!(r > 0.0) || rho <= r) continue;
        const double alpha = alphaOfPlaneCircleRad(rho, r);  // eq (12)
        circles.push_back({alpha, {c, r}});
        if (alpha > bestAlpha) bestAlpha = alpha, result.circle = {c, r};
      }
    }
    if (bestAlpha < 0.0) throw Error("the medial axis of the Gauss map's complement has no usable circle");
    result.alphaRad = alphaOfPlaneCircleRad(norm(result.circle.center), result.circle.radius);
    result.normal = apply(back, directionOfPlaneCircle(result.circle.center, result.circle.radius));
    result.sphereCircle = {result.normal, result.alphaRad};
    // Rival basins: the polygon is within tol of Omega, so a circle within a few tol of the
    // best may be the true optimum's. Keep up to four such, in distinct directions (more
    // than a degree apart), to be polished below.
    std::sort(circles.begin(), circles.end(),
              [](const auto& a, const auto& b) { return a.first > b.first; });
    for (const auto& [alpha, circle] : circles) {
      if (alpha < bestAlpha - 4.0 * tol || rivals.size() >= 4) break;
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
  if (result.method == "medial-axis") {
    // Every rival is polished to the end: the pattern search crawls along the ridges where
    // contacts are level, so a ranking after a coarse polish is not reliable.
    double bestValue = 2.0;
    for (const Vec3& seed : rivals) {
      double value = 0.0;
      const Vec3 polished = polishDirection(surface, seed, tol, value);
      if (value < bestValue) bestValue = value, result.normal = polished;
    }
    result.alphaRad = std::acos(std::min(1.0, bestValue));
    result.sphereCircle = {result.normal, result.alphaRad};
  }
  // Certificate: prove that no normal comes within alpha* less a small margin (what the
  // sampled-and-climbed maxima could have missed) of +-N*.
  if (options.certify) {
    result.certifiedAlphaRad = std::max(0.0, result.alphaRad - kCertificateMarginRad);
    result.certified = certifyClearance(surface, result.normal, result.certifiedAlphaRad,
                                        result.certificateCells);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scallop
