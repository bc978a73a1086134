#include "scallop/paths/raster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <fmt/format.h>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/parallel.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/paths/path_sampling.hpp"
#include "paths/alignment.hpp"
#include "paths/clearance.hpp"

namespace scallop {
namespace {

using detail::HeightBound;
using detail::segmentClears;

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

void requirePositive(const char* what, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(fmt::format("{} must be a positive number, got {}", what, value));
}

void requireNonNegative(const char* what, double value) {
  if (!(value >= 0.0) || !std::isfinite(value))
    throw Error(fmt::format("{} must be zero (the default) or a positive number, got {}", what,
                            value));
}

// The raster frame: feed d, plane normal e, z up; (d, e, z^) is right-handed (d x e = z^).
struct Frame {
  Vec3 d;
  Vec3 e;
  bool alongX = false;  // d = +-x exactly: arcs in the zx plane (G18)
  bool alongY = false;  // d = +-y exactly: arcs in the yz plane (G19)

  // P(s, z) = s d + w e + z z^. With d and e snapped to axes every product is exact, so
  // the coordinate normal to an arc's plane is w (or -w) bit for bit at every point.
  Vec3 at(double s, double w, double z) const { return s * d + w * e + Vec3{0.0, 0.0, z}; }
  Vec3 at(const Point2& p, double w) const { return at(p.x, w, p.z); }
};

Frame frameFor(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Frame f;
  if (std::abs(s) < 1e-12) {
    f.d = {c > 0.0 ? 1.0 : -1.0, 0.0, 0.0};
    f.alongX = true;
  } else if (std::abs(c) < 1e-12) {
    f.d = {0.0, s > 0.0 ? 1.0 : -1.0, 0.0};
    f.alongY = true;
  } else {
    f.d = {c, s, 0.0};
  }
  f.e = {0.0 - f.d.y, f.d.x, 0.0};  // 0 - 0 is +0: no "-0" in messages
  return f;
}

// ---------------------------------------------------------------------------------------
// Sections to chains
// ---------------------------------------------------------------------------------------

// One section curve as a chain in its plane, oriented so that s increases, with the
// section points (for naming places in errors).
struct OrientedCurve {
  std::size_t curve = 0;
  std::vector<Point2> points;       // (s, z)
  std::vector<SectionPoint> where;  // the same vertices, on the surface
};

[[noreturn]] void throwNotGraph(const Frame& f, double w, const std::string& what,
                                const SectionPoint& p) {
  throw Error(fmt::format(
      "the surface is not a graph over the raster direction d = ({:.6g}, {:.6g}, 0): in the "
      "plane e . r = {:.9g} (e = ({:.6g}, {:.6g}, 0)) {} at patch {} (u, v) = ({:.6g}, {:.6g}), "
      "point ({:.6g}, {:.6g}, {:.6g})",
      f.d.x, f.d.y, w, f.e.x, f.e.y, what, p.patch, p.u, p.v, p.point.x, p.point.y, p.point.z));
}

OrientedCurve orientCurve(const SectionCurve& curve, std::size_t index, const Frame& f, double w,
                          double tau) {
  OrientedCurve out;
  out.curve = index;
  out.where = curve.points;
  if (curve.closed) {
    // A closed section has a largest s where it turns back; name that point.
    const auto extreme = std::max_element(
        out.where.begin(), out.where.end(), [&](const SectionPoint& a, const SectionPoint& b) {
          return dot(f.d, a.point) < dot(f.d, b.point);
        });
    throwNotGraph(f, w, "the section is a closed loop; it turns back in s", *extreme);
  }
  if (dot(f.d, out.where.back().point) < dot(f.d, out.where.front().point))
    std::reverse(out.where.begin(), out.where.end());
  out.points.reserve(out.where.size());
  double highest = -kInf;
  std::size_t highestAt = 0;
  for (std::size_t i = 0; i < out.where.size(); ++i) {
    const Vec3& p = out.where[i].point;
    double s = dot(f.d, p);
    if (s < highest - tau)
      throwNotGraph(f, w,
                    fmt::format("the section reaches a largest s and turns back (by more "
                                "than the tolerance {:.3g})",
                                tau),
                    out.where[highestAt]);
    // Back-steps within tau are rounding on a vertical wall: flatten them so the chain is
    // monotone, as scallopHull requires.
    if (s <= highest) {
      s = highest;
    } else {
      highest = s;
      highestAt = i;
    }
    out.points.push_back({s, p.z});
  }
  return out;
}

// The chains of one plane: its curves sorted by s, checked to lie side by side, and those
// less than 2R apart merged through bridge vertices (see the contract).
std::vector<RasterChain> planeChains(const PlaneSection& section, const Frame& f, double w,
                                     double radius, double tau) {
  std::vector<OrientedCurve> curves;
  for (std::size_t i = 0; i < section.curves.size(); ++i)
    if (section.curves[i].points.size() >= 2)  // a lone point has nothing to follow
      curves.push_back(orientCurve(section.curves[i], i, f, w, tau));
  std::sort(curves.begin(), curves.end(), [](const OrientedCurve& a, const OrientedCurve& b) {
    return a.points.front().x < b.points.front().x;
  });
  std::vector<RasterChain> chains;
  double reach = -kInf;        // the largest s of the curves so far
  const OrientedCurve* reachCurve = nullptr;
  for (const OrientedCurve& c : curves) {
    const double begin = c.points.front().x;
    if (reachCurve != nullptr && begin < reach - tau) {
      // Two sheets over the same s: name the lower-s start that lies under/over the other.
      throwNotGraph(f, w,
                    fmt::format("two sheets of the surface lie over s in [{:.6g}, {:.6g}] "
                                "(section curves {} and {}); one begins",
                                begin, reach, reachCurve->curve, c.curve),
                    c.where.front());
    }
    if (chains.empty() || begin - reach >= 2.0 * radius) {
      chains.push_back({});
      chains.back().chain = c.points;
    } else {
      // A gap narrower than the ball: bridge it (the ball cannot reach the floor).
      Chain& chain = chains.back().chain;
      const Point2 a = chain.back();
      const double floor = std::min(a.z, c.points.front().z) - 2.0 * radius;
      chain.push_back({a.x, floor});
      for (std::size_t i = 0; i < c.points.size(); ++i) {
        const Point2 p{std::max(c.points[i].x, a.x), c.points[i].z};
        if (i == 0) chain.push_back({p.x, floor});
        chain.push_back(p);
      }
    }
    chains.back().curves.push_back(c.curve);
    if (c.points.back().x > reach) {
      reach = c.points.back().x;
      reachCurve = &c;
    }
  }
  return chains;
}

// The plane's chains when the surface is not a graph over the raster direction (a closed
// section, one that turns back, sheets over one another): what a ball from above can see of
// it, the upper envelope of its curves over s, as chains. The envelope is taken at every
// vertex's s (its crossings of two curves in between are cut a little low: the drop envelope
// lifts the path there, see the contract); curves whose s ranges overlap form one chain, and
// chains less than 2R apart are bridged as planeChains does.
std::vector<RasterChain> visibleChains(const PlaneSection& section, const Frame& f, double radius) {
  struct Piece {
    double lo, hi;
    std::vector<Point2> points;  // (s, z) along the curve, closed curves closed
    std::size_t curve;
  };
  std::vector<Piece> pieces;
  for (std::size_t i = 0; i < section.curves.size(); ++i) {
    const SectionCurve& curve = section.curves[i];
    if (curve.points.size() < 2) continue;
    Piece piece{kInf, -kInf, {}, i};
    for (const SectionPoint& p : curve.points) {
      piece.points.push_back({dot(f.d, p.point), p.point.z});
      piece.lo = std::min(piece.lo, piece.points.back().x);
      piece.hi = std::max(piece.hi, piece.points.back().x);
    }
    if (curve.closed) piece.points.push_back(piece.points.front());
    pieces.push_back(std::move(piece));
  }
  std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.lo < b.lo; });
  std::vector<RasterChain> chains;
  for (std::size_t first = 0; first < pieces.size();) {
    // A run of pieces whose s ranges overlap: one stretch of the envelope.
    std::size_t last = first;
    double reach = pieces[first].hi;
    while (last + 1 < pieces.size() && pieces[last + 1].lo <= reach) reach = std::max(reach, pieces[++last].hi);
    std::vector<double> stations;
    std::size_t work = 0;
    for (std::size_t k = first; k <= last; ++k) {
      for (const Point2& p : pieces[k].points) stations.push_back(p.x);
      work += pieces[k].points.size();
    }
    std::sort(stations.begin(), stations.end());
    stations.erase(std::unique(stations.begin(), stations.end()), stations.end());
    if (static_cast<double>(stations.size()) * static_cast<double>(work) > 5e7) {
      throw Error(fmt::format("the section at plane offset {} has {} vertices over one stretch: "
                              "too many for its upper envelope (use a coarser chordal tolerance)",
                              dot(f.e, section.curves[pieces[first].curve].points.front().point),
                              stations.size()));
    }
    Chain chain;
    for (const double station : stations) {
      double top = -kInf;
      for (std::size_t k = first; k <= last; ++k) {
        const std::vector<Point2>& pts = pieces[k].points;
        for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
          const Point2 a = pts[i], b = pts[i + 1];
          if (station < std::min(a.x, b.x) || station > std::max(a.x, b.x)) continue;
          if (a.x == b.x) {
            top = std::max({top, a.z, b.z});
          } else {
            const double t = (station - a.x) / (b.x - a.x);
            top = std::max(top, a.z + t * (b.z - a.z));
          }
        }
      }
      chain.push_back({station, top});
    }
    if (chain.size() >= 2) {
      if (!chains.empty() && chain.front().x - chains.back().chain.back().x < 2.0 * radius) {
        Chain& previous = chains.back().chain;
        const Point2 a = previous.back();
        const double floor = std::min(a.z, chain.front().z) - 2.0 * radius;
        previous.push_back({a.x, floor});
        previous.push_back({chain.front().x, floor});
        previous.insert(previous.end(), chain.begin(), chain.end());
      } else {
        chains.push_back({});
        chains.back().chain = std::move(chain);
      }
      for (std::size_t k = first; k <= last; ++k) chains.back().curves.push_back(pieces[k].curve);
    }
    first = last + 1;
  }
  return chains;
}

// ---------------------------------------------------------------------------------------
// Passes
// ---------------------------------------------------------------------------------------

// The hull's tool-centre path in 3D. Feeds along an axis keep the arcs; other feeds get the
// circumscribed polygon, which never passes inside the true path (path_sampling.hpp).
ToolPass passFromHull(const ScallopHull& hull, const Frame& f, double w, double arcTolerance) {
  ToolPass pass;
  const std::vector<PathElement>& path = hull.toolpath;
  if (f.alongX || f.alongY) {
    pass.start = f.at(path.front().start, w);
    // The hull's arcs turn clockwise in (s right, z up): a positive rotation about e, since
    // d x z^ = -e. Seen from the positive principal axis that is clockwise (G2) iff e points
    // the other way (see the contract).
    const ArcPlane plane = f.alongX ? ArcPlane::zx : ArcPlane::yz;
    const Vec3 axis = f.alongX ? Vec3{0.0, 1.0, 0.0} : Vec3{1.0, 0.0, 0.0};
    const bool clockwise = dot(f.e, axis) < 0.0;
    for (const PathElement& el : path) {
      if (el.start == el.end) continue;  // nothing to move (and no full-circle arcs)
      ToolMove move;
      move.end = f.at(el.end, w);
      if (el.kind == PathElementKind::arc) {
        move.kind = MoveKind::arc;
        move.center = f.at(el.center, w);
        move.plane = plane;
        move.clockwise = clockwise;
      }
      pass.moves.push_back(move);
    }
  } else {
    const std::vector<Point2> polyline = samplePath(path, arcTolerance);
    pass.start = f.at(polyline.front(), w);
    for (std::size_t i = 1; i < polyline.size(); ++i)
      pass.moves.push_back({MoveKind::line, f.at(polyline[i], w), {}, ArcPlane::xy, true});
  }
  return pass;
}


// ---------------------------------------------------------------------------------------
// Ways off the surface at a pass's ends
// ---------------------------------------------------------------------------------------

// A way off the surface from the ball centre c at one end of a pass: a horizontal move to
// `point`, then straight up to the clear height there, along which the ball never cuts
// deeper than max(its depth at c, 0) + slack (depth = R - dist(centre, surface)). Why: a pass ends R
// beyond its section's end at that end's height; where the surface's boundary is oblique to
// the feed, that centre lies beside neighbouring parts of the surface that stand higher,
// and rising straight from it the ball would cut into them. Moving away from the nearest
// surface point first lets it rise clear.
struct PassEndExit {
  Vec3 point;          // c itself when rising straight up clears
  bool proven = false;  // false: none of the candidates cleared; `point` is c
};

// Above the clear height of a point (x, y), clearHeight(x, y) = (a bound on the surface's
// height within horizontal distance R of it) + R, every centre is at least R from the surface,
// so the rise needs proof only below it.
template <class ClearHeight>
PassEndExit exitFrom(const SurfaceDistance& distance, Vec3 c, Vec3 outward, double radius,
                     const ClearHeight& clearHeight, double slack) {
  // Margins below slack / 64 mean the path creeps along its limit: give up there.
  const double minStep = slack / 64.0;
  // nearest.distance is an upper bound: the depth below is at most the true one, so
  // `allowed` never exceeds max(true depth, 0) + slack.
  const ClosestPoint nearest = distance.closest(c);
  const double allowed = std::max(radius - nearest.distance, 0.0) + slack;
  const double need = radius - allowed;
  const auto clears = [&](Vec3 from) {
    const double top = clearHeight(from.x, from.y);
    return top <= from.z ||
           segmentClears(distance, from, {from.x, from.y, top}, need, radius, minStep);
  };
  if (clears(c)) return {c, true};
  // Horizontal directions: away from the nearest surface point, along the feed out of the
  // pass, and between the two.
  std::vector<Vec3> directions;
  const auto add = [&](Vec3 v) {
    const double length = std::hypot(v.x, v.y);
    if (length > 1e-6 * norm(v)) directions.push_back({v.x / length, v.y / length, 0.0});
  };
  const Vec3 away = c - nearest.point;
  add(away);
  add(outward);
  if (directions.size() == 2) add(directions[0] + directions[1]);
  for (const double multiple : {0.125, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0}) {
    for (const Vec3& h : directions) {
      const Vec3 to = c + (multiple * radius) * h;
      if (segmentClears(distance, c, to, need, radius, minStep) && clears(to)) return {to, true};
    }
  }
  return {c, false};
}

// ---------------------------------------------------------------------------------------
// The best feed angle
// ---------------------------------------------------------------------------------------

// alpha(a) = acos(max |e(a) . n|) over the surface, two ways: `estimate` from normals
// sampled once on a grid (a few flops per sample and angle: the scan), `refined` with the
// largest grid samples of each patch climbed to their local maxima by a shrinking pattern
// search (the golden-section stage, where the grid's error would otherwise decide).
class AngleObjective {
 public:
  explicit AngleObjective(const Surface& surface) : surface_(surface) {
    for (std::size_t p = 0; p < surface.patches.size(); ++p) {
      first_.push_back(samples_.size());
      for (int i = 0; i <= kAngleGrid; ++i)
        for (int j = 0; j <= kAngleGrid; ++j) {
          const double u = double(i) / kAngleGrid, v = double(j) / kAngleGrid;
          if (!surfaceKeepsPoint(surface, p, u, v)) continue;
          const Vec3 n = unitNormal(surface.patches[p], u, v);
          samples_.push_back({n.x, n.y, u, v});
        }
    }
    first_.push_back(samples_.size());
  }

  static Vec2 normalOf(double a) { return {-std::sin(a), std::cos(a)}; }

  double estimate(double a) const {
    const Vec2 e = normalOf(a);
    double largest = 0.0;
    for (const Sample& s : samples_) largest = std::max(largest, std::abs(e.x * s.nx + e.y * s.ny));
    return std::acos(std::min(1.0, largest));
  }

  double refined(double a) const {
    constexpr std::size_t kSeeds = 4;
    const Vec2 e2 = normalOf(a);
    const Vec3 e{e2.x, e2.y, 0.0};
    double largest = 0.0;
    for (std::size_t p = 0; p + 1 < first_.size(); ++p) {
      const BezierPatch& patch = surface_.patches[p];
      struct Seed {
        double value, u, v;
      };
      std::vector<Seed> seeds;
      for (std::size_t i = first_[p]; i < first_[p + 1]; ++i) {
        const Sample& s = samples_[i];
        seeds.push_back({std::abs(e.x * s.nx + e.y * s.ny), s.u, s.v});
      }
      const std::size_t count = std::min(kSeeds, seeds.size());
      std::partial_sort(seeds.begin(), seeds.begin() + static_cast<std::ptrdiff_t>(count),
                        seeds.end(), [](const Seed& x, const Seed& y) { return x.value > y.value; });
      for (std::size_t k = 0; k < count; ++k) {
        const Seed& seed = seeds[k];
        const detail::AlignmentPeak c =
            detail::climbAlignment(patch, e, {seed.value, seed.u, seed.v}, 1.0 / kAngleGrid, 1e-10);
        largest = std::max(largest, c.value);
      }
    }
    return std::acos(std::min(1.0, largest));
  }

 private:
  struct Sample {
    double nx, ny, u, v;
  };
  const Surface& surface_;
  std::vector<Sample> samples_;
  std::vector<std::size_t> first_;  // patch p's samples: [first_[p], first_[p + 1])
};

// The maximiser of f on [lo, hi] by golden-section search: robust for a unimodal f with
// kinks (alpha is a minimum over the surface, so its maxima are often where two normals
// tie), where derivative-based steps would stall.
template <class F>
std::pair<double, double> goldenMaximum(const F& f, double lo, double hi, double tolerance) {
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  while (hi - lo > tolerance) {
    checkCancelled();
    if (f1 >= f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - ratio * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + ratio * (hi - lo), f2 = f(x2);
    }
  }
  return f1 >= f2 ? std::pair{x1, f1} : std::pair{x2, f2};
}

}  // namespace

double bestRasterAngle(const Surface& surface) {
  validateSurface(surface);
  const AngleObjective objective(surface);
  // alpha is pi-periodic in a (e and -e make the same planes): scan [0, pi) and keep the
  // best few local maxima of the estimate, cyclically.
  std::vector<double> scan(kAngleScan);
  const double step = kPi / kAngleScan;
  for (int i = 0; i < kAngleScan; ++i) {
    checkCancelled();
    scan[static_cast<std::size_t>(i)] = objective.estimate(i * step);
  }
  std::vector<std::pair<double, int>> peaks;
  for (int i = 0; i < kAngleScan; ++i) {
    const double here = scan[static_cast<std::size_t>(i)];
    const double before = scan[static_cast<std::size_t>((i + kAngleScan - 1) % kAngleScan)];
    const double after = scan[static_cast<std::size_t>((i + 1) % kAngleScan)];
    if (here >= before && here >= after) peaks.push_back({here, i});
  }
  std::sort(peaks.begin(), peaks.end(), std::greater<>());
  constexpr std::size_t kCandidates = 3;
  double bestAngle = 0.0;
  double bestAlpha = -1.0;
  for (std::size_t c = 0; c < std::min(kCandidates, peaks.size()); ++c) {
    const double centre = peaks[c].second * step;
    const auto [a, alpha] = goldenMaximum([&](double x) { return objective.refined(x); },
                                          centre - step, centre + step, 1e-9);
    if (alpha > bestAlpha) bestAlpha = alpha, bestAngle = a;
  }
  bestAngle = std::fmod(bestAngle, kPi);
  if (bestAngle < 0.0) bestAngle += kPi;
  return bestAngle >= kPi ? 0.0 : bestAngle;
}

namespace {

// The passes lifted to the drop envelope; the move counts of RasterPass and the lengths
// recomputed on the lifted moves.
void liftRasterPaths(const SurfaceDistance& distance, const RasterOptions& options, RasterPaths& out) {
  EnvelopeOptions envelope;
  envelope.depthTolerance = options.depthTolerance;
  envelope.stretchThreshold = options.stretchThreshold;
  envelope.sagTolerance = options.sagTolerance;
  // The sag rule on the cutting moves only: after the link and the entry, before the exit.
  for (std::size_t p = 0; p < out.passes.size(); ++p) {
    const RasterPass& info = out.passes[p];
    envelope.sagMoves.emplace_back(info.linkMoves + info.entryMoves, out.path.passes[p].moves.size() - info.exitMoves);
  }
  std::vector<std::vector<std::size_t>> moveMap;
  out.path = liftToDropEnvelope(distance, out.path, envelope, out.envelope, &moveMap);
  out.stats.centreLength = 0.0;
  out.linkLength = 0.0;
  for (std::size_t p = 0; p < out.path.passes.size(); ++p) {
    RasterPass& info = out.passes[p];
    const std::vector<std::size_t>& map = moveMap[p];
    const ToolPass& pass = out.path.passes[p];
    // Output moves [0, cutFirst) are the link and entry, [cutFirst, cutLast) the cut.
    const std::size_t inputMoves = map.size();
    const std::size_t linkEnd = info.linkMoves == 0 ? 0 : map[info.linkMoves - 1];
    const std::size_t entryIn = info.linkMoves + info.entryMoves;
    const std::size_t cutFirst = entryIn == 0 ? 0 : map[entryIn - 1];
    const std::size_t cutLast = info.exitMoves == 0 ? pass.moves.size() : map[inputMoves - 2];
    info.linkMoves = linkEnd;
    info.entryMoves = cutFirst - linkEnd;
    info.exitMoves = pass.moves.size() - cutLast;
    Vec3 at = pass.start;
    for (std::size_t m = 0; m < pass.moves.size(); ++m) {
      const double length = moveLength(at, pass.moves[m]);
      (m >= cutFirst && m < cutLast ? out.stats.centreLength : out.linkLength) += length;
      at = pass.moves[m].end;
    }
  }
}

}  // namespace

RasterPaths rasterPaths(const Surface& surface, const RasterOptions& options) {
  validateSurface(surface);
  requirePositive("the tool radius", options.toolRadius);
  if (!options.bestAngle && !std::isfinite(options.angleRad))
    throw Error(fmt::format("the feed angle must be a finite number of radians, got {}",
                            options.angleRad));
  validatePlaneOffsets(options.planeOffsets, "the plane offsets");
  const bool explicitOffsets = !options.planeOffsets.empty();
  if (explicitOffsets && options.spacing == 0.0 && options.scallopHeight == 0.0) {
    // The offsets alone: no spacing to report.
  } else if (options.scallopHeight != 0.0) {
    if (options.spacing != 0.0)
      throw Error(fmt::format("give the step-over ({}) or the scallop height ({}), not both",
                              options.spacing, options.scallopHeight));
    requirePositive("the scallop height", options.scallopHeight);
  } else {
    requirePositive("the step-over (plane spacing)", options.spacing);
  }
  requireNonNegative("the chordal tolerance", options.chordalTolerance);
  requireNonNegative("the arc tolerance", options.arcTolerance);
  requireNonNegative("the depth tolerance", options.depthTolerance);
  const double scale = std::max(surfaceScale(surface), 1e-300);
  const double tolerance =
      options.chordalTolerance > 0.0 ? options.chordalTolerance : 1e-4 * scale;
  requirePositive("the chordal tolerance", tolerance);  // 1e-4 scale may underflow
  const double arcTolerance = options.arcTolerance > 0.0 ? options.arcTolerance : tolerance;
  const double radius = options.toolRadius;
  const double tau = kRasterTurnTolerance * scale;

  RasterPaths out;
  out.angleRad = options.bestAngle ? bestRasterAngle(surface) : options.angleRad;
  const Frame frame = frameFor(out.angleRad);
  out.feedDirection = frame.d;
  out.planeNormal = frame.e;
  out.alphaRad = minimumAngleBound(surface, frame.e);
  out.spacing = options.spacing > 0.0 ? options.spacing
                : options.scallopHeight > 0.0
                    ? spacingForScallopHeight(radius, options.scallopHeight, out.alphaRad)
                    : 0.0;
  out.path.units = surface.units;
  out.path.toolRadius = radius;

  const PlaneRange range =
      explicitOffsets ? PlaneRange{options.planeOffsets.front(), options.planeOffsets.back(), 0.0,
                                   static_cast<double>(options.planeOffsets.size() - 1)}
                      : planeRange(surface, frame.e, out.spacing, "the step-over");

  const HeightBound heights(surface, tolerance, 1e-12 * scale);
  // The ways off (see the contract): limits `slack` above the pass end's depth, proven with
  // lower bounds good to slack / 8 (tighter ones cost cells and buy nothing).
  const double slack = std::max(tolerance, radius / 256.0);
  DistanceOptions loose;
  loose.tolerance = slack / 8.0;
  const SurfaceDistance distance(surface, loose);
  const auto clearHeight = [&](double x, double y) {
    return heights.above({x, y}, {x, y}, radius) + radius;
  };
  const auto line = [](Vec3 end) { return ToolMove{MoveKind::line, end, {}, ArcPlane::xy, true}; };
  const auto offsetAt = [&](double kk) {
    return explicitOffsets ? options.planeOffsets[static_cast<std::size_t>(kk)] : kk * out.spacing;
  };
  // The footprint's extent along d (control points), for the drop lines.
  double footLo = kInf, footHi = -kInf;
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& p : patch.control) footLo = std::min(footLo, dot(frame.d, p)), footHi = std::max(footHi, dot(frame.d, p));

  // One plane's passes, in increasing s, not yet reversed, run on past their ends (with the
  // drop envelope): from the scallop hulls of its chains, or, where its section gives none
  // and `dropLine`, from the drop envelope along the line (envelope.hpp, dropLineRuns).
  // Built independently of every other plane (planes are built in parallel); the path is
  // assembled from them in order (appendPlane).
  struct PlaneBuild {
    RasterSection plane;
    std::vector<ToolPass> passes;
    // Per pass, the ways off at its two ends as built: from its start backwards (-d) and
    // from its end onwards (+d). A reversed pass's entry is its end's, its exit its start's
    // (reversedPass keeps the end points bit for bit).
    std::vector<std::pair<PassEndExit, PassEndExit>> ends;
    std::size_t components = 0;
    std::size_t touchPoints = 0;
    double contactLength = 0.0;
    bool visible = false;
  };
  const auto buildPlane = [&](double w, long long k, const RunOnBand& band, double step, bool dropLine) {
    checkCancelled();
    PlaneBuild b;
    PlaneSection section = planeSection(surface, frame.e, w, tolerance);
    b.touchPoints = section.touchPoints.size();
    b.plane.offset = w;
    b.plane.k = k;
    if (options.dropEnvelope) {
      // Not a graph here: the part a ball from above sees (the error names where otherwise).
      try {
        b.plane.chains = planeChains(section, frame, w, radius, tau);
      } catch (const Cancelled&) {
        throw;
      } catch (const Error&) {
        b.plane.chains = visibleChains(section, frame, radius);
        b.visible = true;
      }
    } else {
      b.plane.chains = planeChains(section, frame, w, radius, tau);
    }
    b.components = section.components;
    for (const SectionCurve& curve : section.curves) b.contactLength += curveLength(curve);
    for (RasterChain& chain : b.plane.chains) {
      chain.hull = scallopHull(chain.chain, radius);
      ToolPass pass = passFromHull(chain.hull, frame, w, arcTolerance);
      // The pass runs on past both ends while its ball still finishes its own band of the
      // surface (envelope.hpp, runOnPastEnd).
      if (options.dropEnvelope) runPassOn(distance, pass, -frame.d, frame.d, radius, band, step);
      b.passes.push_back(std::move(pass));
    }
    if (b.plane.chains.empty() && dropLine && options.dropEnvelope) {
      b.plane.dropLine = true;
      for (std::vector<Vec3>& run : dropLineRuns(distance, w * frame.e, frame.d, footLo - radius, footHi + radius,
                                                 radius, band, step)) {
        ToolPass pass;
        pass.start = run.front();
        for (std::size_t v = 1; v < run.size(); ++v) pass.moves.push_back(line(run[v]));
        b.passes.push_back(std::move(pass));
      }
    }
    b.plane.section = std::move(section);
    for (const ToolPass& pass : b.passes) {
      b.ends.emplace_back(exitFrom(distance, pass.start, -frame.d, radius, clearHeight, slack),
                          exitFrom(distance, passEnd(pass), frame.d, radius, clearHeight, slack));
    }
    return b;
  };

  // With the drop envelope, planes beyond the outermost ones, at the outermost gap, while
  // their balls still finish points of the surface that no given plane's ball does: a raster
  // ball's contacts are shifted across its plane by R (e . n) where the surface slopes across
  // it, so the points near the surface's extreme in e are reached only from planes beyond
  // (the simulated cut of paper-1 found an untouched corner at 9.6 H). At most R / gap + 2
  // each side.
  std::vector<PlaneBuild> below, above;
  const std::size_t planeCount = static_cast<std::size_t>(range.last - range.first + 1.0);
  if (options.dropEnvelope) {
    const double fallbackGap = out.spacing > 0.0 ? out.spacing : radius / 4.0;
    const double gapLo = planeCount >= 2 ? offsetAt(range.first + 1.0) - offsetAt(range.first) : fallbackGap;
    const double gapHi = planeCount >= 2 ? offsetAt(range.last) - offsetAt(range.last - 1.0) : fallbackGap;
    for (const int side : {-1, 1}) {
      const double gap = side < 0 ? gapLo : gapHi;
      const double edge = offsetAt(side < 0 ? range.first : range.last);
      const long long edgeK = static_cast<long long>(side < 0 ? range.first : range.last);
      const auto count = static_cast<long long>(std::ceil(radius / gap)) + 2;
      for (long long j = 1; j <= count; ++j) {
        const double w = edge + static_cast<double>(side * j) * gap;
        RunOnBand band{frame.e, radius};
        (side < 0 ? band.hi : band.lo) = w - 0.5 * side * gap;
        PlaneBuild b = buildPlane(w, edgeK + side * j, band, runOnStep(gap, radius), true);
        out.stats.touchPoints += b.touchPoints;
        if (b.passes.empty()) break;
        (side < 0 ? below : above).push_back(std::move(b));
      }
    }
  }
  std::vector<double> allOffsets;  // every plane's w, in increasing order
  for (auto b = below.rbegin(); b != below.rend(); ++b) allOffsets.push_back(b->plane.offset);
  for (double kk = range.first; kk <= range.last; kk += 1.0) allOffsets.push_back(offsetAt(kk));
  for (const PlaneBuild& b : above) allOffsets.push_back(b.plane.offset);

  // A plane's passes into the path: zigzag, ways on and off, links from the previous plane.
  const auto appendPlane = [&](PlaneBuild&& b) {
    RasterSection& plane = b.plane;
    if (b.passes.empty()) return;
    plane.reversed = out.sections.size() % 2 == 1;
    ++out.stats.planes;
    out.visibleFromAbovePlanes += b.visible ? 1 : 0;
    out.stats.components += b.components;
    out.stats.contactLength += b.contactLength;
    const std::size_t index = out.sections.size();
    const std::size_t n = b.passes.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t c = plane.reversed ? n - 1 - i : i;
      ToolPass pass = std::move(b.passes[c]);
      if (!plane.dropLine) out.stats.centreLength += pathLength(plane.chains[c].hull.toolpath);
      if (plane.reversed) pass = reversedPass(pass);
      RasterPass info{index, c, plane.reversed, 0, 0.0, 0, 0};
      // Ways on and off: the entry is an exit run backwards.
      const Vec3 cutEnd = passEnd(pass);
      const auto& [fromStart, fromEnd] = b.ends[c];
      const PassEndExit& entry = plane.reversed ? fromEnd : fromStart;
      const PassEndExit& exit = plane.reversed ? fromStart : fromEnd;
      out.unclearedEnds += (entry.proven ? 0 : 1) + (exit.proven ? 0 : 1);
      if (!(entry.point == pass.start)) {
        out.linkLength += norm(pass.start - entry.point);
        pass.moves.insert(pass.moves.begin(), line(pass.start));
        pass.start = entry.point;
        info.entryMoves = 1;
      }
      if (!(exit.point == cutEnd)) {
        out.linkLength += norm(exit.point - cutEnd);
        pass.moves.push_back(line(exit.point));
        info.exitMoves = 1;
      }
      // The first pass of a plane after the first is linked from the previous pass's end
      // (which lies at the same end of the surface: zigzag); the rest are retracted.
      if (i == 0 && !out.path.passes.empty()) {
        const Vec3 from = passEnd(out.path.passes.back());
        const Vec3 to = pass.start;
        const double surfaceTop = heights.above({from.x, from.y}, {to.x, to.y}, radius);
        const double height = std::max({from.z, to.z, surfaceTop + radius});
        std::vector<ToolMove> link;
        Vec3 at = from;
        for (const Vec3 next : {Vec3{from.x, from.y, height}, Vec3{to.x, to.y, height}, to}) {
          if (next == at) continue;
          out.linkLength += norm(next - at);
          link.push_back(line(next));
          at = next;
        }
        info.linkMoves = link.size();
        info.linkHeight = height;
        pass.moves.insert(pass.moves.begin(), link.begin(), link.end());
        pass.start = from;
        pass.retractBefore = false;
      } else {
        pass.retractBefore = true;
      }
      if (!plane.dropLine) plane.chains[c].pass = out.path.passes.size();
      out.path.passes.push_back(std::move(pass));
      out.passes.push_back(info);
    }
    out.sections.push_back(std::move(plane));
  };

  // The given planes, each on its own (on every core), then the path from them in order.
  std::vector<PlaneBuild> planes(planeCount);
  parallelForEach(planeCount, threadCount(), [&](std::size_t i) {
    const std::size_t at = below.size() + i;
    advanceStage(at, allOffsets.size());  // reports on the calling thread only
    const double w = allOffsets[at];
    RunOnBand band{frame.e, radius};
    double gap = 4.0 * radius;
    if (at > 0) band.lo = 0.5 * (allOffsets[at - 1] + w), gap = std::min(gap, w - allOffsets[at - 1]);
    if (at + 1 < allOffsets.size()) band.hi = 0.5 * (w + allOffsets[at + 1]), gap = std::min(gap, allOffsets[at + 1] - w);
    planes[i] = buildPlane(w, static_cast<long long>(range.first + static_cast<double>(i)), band,
                           runOnStep(gap, radius), true);
  });
  for (const PlaneBuild& b : planes) out.stats.touchPoints += b.touchPoints;
  for (auto b = below.rbegin(); b != below.rend(); ++b) appendPlane(std::move(*b));
  for (PlaneBuild& b : planes) appendPlane(std::move(b));
  for (PlaneBuild& b : above) appendPlane(std::move(b));
  if (out.sections.empty())
    throw Error(fmt::format(
        "no plane e . r = k * {} with e = ({}, {}, 0) cuts the surface (e . r spans [{}, {}])",
        out.spacing, frame.e.x, frame.e.y, range.lo, range.hi));
  if (options.dropEnvelope) liftRasterPaths(distance, options, out);
  return out;
}

}  // namespace scallop
