#include "scallop/paths/envelope.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/parallel.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {

// Above every control point by R: every surface point is at least R below a ball centre
// there, so at least R away. A relative hair more for the rounding of the comparison.
double ballTopAbove(double highest, double radius) {
  return highest + radius * (1.0 + 1e-9) + 1e-9 * std::abs(highest);
}

double ballTop(const Surface& surface, double radius) { return ballTopAbove(controlPointTop(surface), radius); }

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Newton iterations of one local maximisation of the drop height, and the seeds tried (the
// proof's refuting point each time) before bisection takes over.
constexpr int kNewtonIterations = 30;
constexpr int kNewtonSeeds = 4;

// The lift recorded for a vertex inserted by halving (see the stretches below).
constexpr double kInserted = -std::numeric_limits<double>::infinity();

bool isFinite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// g(u, v) = z + sqrt(R^2 - d^2), d the horizontal distance from (x(u, v), y(u, v)) to (X, Y):
// the height at which the ball centred over (X, Y) touches r(u, v) from above; -infinity
// where d >= R. Returns g and, when wanted, its gradient and Hessian in (u, v):
//   A_u = dx x_u + dy y_u,  q = sqrt(R^2 - d^2),
//   g_u = z_u - A_u / q,
//   g_uu = z_uu - (x_u^2 + y_u^2 + dx x_uu + dy y_uu) / q - A_u^2 / q^3, likewise g_uv, g_vv.
struct DropValue {
  double g = -kInfinity;
  double gu = 0.0, gv = 0.0, guu = 0.0, guv = 0.0, gvv = 0.0;
};

DropValue dropValue(const BezierPatch& patch, double u, double v, double X, double Y, double R) {
  DropValue out;
  // A bicubic polynomial patch: its point first (de Casteljau, unrolled), the derivatives
  // only where the ball reaches it. Any other: point and derivatives from one pass of basis
  // sums (bezier.hpp), cheaper than de Casteljau's point alone at a high degree, and for a
  // rational patch the very pass its point() runs.
  const bool bicubic = !patch.rational() && patch.degreeU == 3 && patch.degreeV == 3;
  Vec3 r;
  PatchDerivatives d;
  if (bicubic) {
    r = point(patch, u, v);
  } else {
    d = derivativesToSecondOrder(patch, u, v, r);
  }
  const double dx = r.x - X, dy = r.y - Y;
  const double q2 = R * R - dx * dx - dy * dy;
  if (!(q2 > 0.0)) return out;
  const double q = std::sqrt(q2);
  out.g = r.z + q;
  if (bicubic) d = derivativesToSecondOrder(patch, u, v);
  const double au = dx * d.u.x + dy * d.u.y;
  const double av = dx * d.v.x + dy * d.v.y;
  out.gu = d.u.z - au / q;
  out.gv = d.v.z - av / q;
  const double q3 = q2 * q;
  out.guu = d.uu.z - (d.u.x * d.u.x + d.u.y * d.u.y + dx * d.uu.x + dy * d.uu.y) / q - au * au / q3;
  out.guv = d.uv.z - (d.u.x * d.v.x + d.u.y * d.v.y + dx * d.uv.x + dy * d.uv.y) / q - au * av / q3;
  out.gvv = d.vv.z - (d.v.x * d.v.x + d.v.y * d.v.y + dx * d.vv.x + dy * d.vv.y) / q - av * av / q3;
  return out;
}

// A local maximum of g on [0, 1]^2 from (u, v): projected Newton (the Hessian when negative
// definite, else a scaled gradient step), steps clamped to the square and halved until g
// increases. Its value is a lower bound of the drop envelope (a real contact) or -infinity.
double localDropHeight(const BezierPatch& patch, double& u, double& v, double X, double Y, double R) {
  DropValue at = dropValue(patch, u, v, X, Y, R);
  if (!std::isfinite(at.g)) return -kInfinity;
  for (int iteration = 0; iteration < kNewtonIterations; ++iteration) {
    const bool freeU = !((u <= 0.0 && at.gu < 0.0) || (u >= 1.0 && at.gu > 0.0));
    const bool freeV = !((v <= 0.0 && at.gv < 0.0) || (v >= 1.0 && at.gv > 0.0));
    double su = 0.0, sv = 0.0;
    const double det = at.guu * at.gvv - at.guv * at.guv;
    if (freeU && freeV && at.guu < 0.0 && det > 0.0) {
      su = -(at.gvv * at.gu - at.guv * at.gv) / det;
      sv = -(at.guu * at.gv - at.guv * at.gu) / det;
    } else if (freeU && !freeV && at.guu < 0.0) {
      su = -at.gu / at.guu;
    } else if (freeV && !freeU && at.gvv < 0.0) {
      sv = -at.gv / at.gvv;
    } else {
      // Not concave here: a gradient step of at most a tenth of the square.
      su = freeU ? at.gu : 0.0;
      sv = freeV ? at.gv : 0.0;
      const double length = std::hypot(su, sv);
      if (!(length > 0.0)) break;
      su *= 0.1 / length;
      sv *= 0.1 / length;
    }
    bool accepted = false;
    double nu = u, nv = v;
    for (double lambda = 1.0; lambda > 1e-8; lambda *= 0.5) {
      nu = std::clamp(u + lambda * su, 0.0, 1.0);
      nv = std::clamp(v + lambda * sv, 0.0, 1.0);
      const DropValue trial = dropValue(patch, nu, nv, X, Y, R);
      if (trial.g > at.g) {
        at = trial;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    const double moved = std::abs(nu - u) + std::abs(nv - v);
    u = nu;
    v = nv;
    if (moved <= 8.0 * std::numeric_limits<double>::epsilon()) break;
  }
  return at.g;
}

double bottomOf(const Surface& surface, double radius) {
  // Below every control point by R and a hair: a centre there is R from the whole surface.
  double bottom = kInfinity;
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& p : patch.control) bottom = std::min(bottom, p.z);
  return bottom - (radius * (1.0 + 1e-9) + 1e-9 * std::abs(bottom));
}

class Lifter {
 public:
  // `top`: ballTop(surface, R), above which every centre is clear.
  Lifter(const SurfaceDistance& distance, double radius, double eps, double top, std::size_t maxCells,
         std::size_t& proofs)
      : distance_(distance), radius_(radius), eps_(eps), maxCells_(maxCells), proofs_(proofs), top_(top) {}

  // Whether the ball and its shank over (x, y) from height z up are proven clear by
  // R - eps / 2; the refuting (or nearest) point is kept as a seed.
  bool verticalClear(double x, double y, double z) {
    if (z >= top_) return true;
    const SegmentClearance test =
        distance_.segmentClearance({x, y, z}, {x, y, top_}, radius_ - 0.5 * eps_, maxCells_);
    ++proofs_;
    if (test.verdict != Clearance::proven && std::isfinite(test.distance)) {
      seedPatch_ = test.patch, seedU_ = test.u, seedV_ = test.v, seeded_ = true;
    }
    return test.verdict == Clearance::proven;
  }

  // The lifted position of p (see the contract).
  Vec3 lift(Vec3 p) {
    // Along a path the contact moves little from one vertex to the next: first the local
    // maximum from the last contact, which settles most vertices with one proof.
    if (contactKnown_) {
      const BezierPatch& patch = distance_.surface().patches[contactPatch_];
      const Contact contact = localDropContact(patch, contactU_, contactV_, p.x, p.y);
      // A trimmed patch's contact outside its face is no contact.
      if (contact.z > p.z && surfaceKeepsPoint(distance_.surface(), contactPatch_, contact.u, contact.v) &&
          verticalClear(p.x, p.y, contact.z)) {
        contactU_ = contact.u, contactV_ = contact.v;
        return {p.x, p.y, contact.z};
      }
    }
    if (verticalClear(p.x, p.y, p.z)) return p;
    double low = p.z;  // not proven clear
    // Local maxima of the contact height from the refuting points: each a real contact, so
    // a lower bound of Z; the first one proven clear is Z itself.
    for (int seed = 0; seed < kNewtonSeeds && seeded_; ++seed) {
      seeded_ = false;
      const std::size_t patchIndex = seedPatch_;
      const BezierPatch& patch = distance_.surface().patches[patchIndex];
      const Contact contact = localDropContact(patch, seedU_, seedV_, p.x, p.y);
      if (!(contact.z > low) || !surfaceKeepsPoint(distance_.surface(), patchIndex, contact.u, contact.v)) break;
      low = contact.z;
      if (verticalClear(p.x, p.y, contact.z)) {
        contactKnown_ = true;
        contactPatch_ = patchIndex, contactU_ = contact.u, contactV_ = contact.v;
        return {p.x, p.y, contact.z};
      }
    }
    // Bisection on the monotone "clear from z up" between low (not proven) and the top.
    double high = top_;
    while (high - low > 0.25 * eps_) {
      const double middle = 0.5 * (low + high);
      if (verticalClear(p.x, p.y, middle)) {
        high = middle;
      } else {
        low = middle;
      }
    }
    return {p.x, p.y, high};
  }

  // Whether the straight move [a, b] is proven R - clearanceLoss clear.
  bool segmentClear(Vec3 a, Vec3 b, double clearanceLoss) {
    const SegmentClearance test = distance_.segmentClearance(a, b, radius_ - clearanceLoss, maxCells_);
    ++proofs_;
    if (test.verdict != Clearance::proven && std::isfinite(test.distance)) {
      seedPatch_ = test.patch, seedU_ = test.u, seedV_ = test.v, seeded_ = true;
    }
    return test.verdict == Clearance::proven;
  }

 private:
  const SurfaceDistance& distance_;
  double radius_;
  double eps_;
  std::size_t maxCells_;
  std::size_t& proofs_;
  double top_;
  struct Contact {
    double z = -kInfinity;
    double u = 0.0, v = 0.0;
  };
  Contact localDropContact(const BezierPatch& patch, double u, double v, double x, double y) const {
    Contact contact;
    contact.u = u, contact.v = v;
    contact.z = localDropHeight(patch, contact.u, contact.v, x, y, radius_);
    return contact;
  }

  bool seeded_ = false;
  std::size_t seedPatch_ = 0;
  double seedU_ = 0.0, seedV_ = 0.0;
  bool contactKnown_ = false;  // the last vertex's contact, proven the highest there
  std::size_t contactPatch_ = 0;
  double contactU_ = 0.0, contactV_ = 0.0;
};

// One pass's output: moves and, per output vertex, how far it was lifted.
struct PassBuilder {
  std::vector<ToolMove> moves;
  std::vector<double> lifts;  // of each move's end
  std::size_t maxMoves = 0;

  void add(const ToolMove& move, double lift) {
    if (moves.size() + 1 > maxMoves) {
      throw Error(fmt::format("lifting the path to the drop envelope: more than {} moves; the "
                              "depth tolerance is too fine for this path (raise it)",
                              maxMoves));
    }
    moves.push_back(move);
    lifts.push_back(lift);
  }
};

// One pass lifted (see the contract): its moves, per output vertex its lift (the start's
// first; kInserted for a halving's midpoint), per input move the output moves so far, and
// its counts.
struct PassLift {
  ToolPass pass;
  std::vector<double> lifts;
  std::vector<std::size_t> map;
  std::size_t movesIn = 0, arcsKept = 0, arcsReplaced = 0, proofs = 0, unprovenMoves = 0;
};

PassLift liftPass(const SurfaceDistance& distance, const ToolPass& pass, std::size_t passIndex,
                  double radius, double eps, double top, const EnvelopeOptions& options) {
  PassLift result;
  if (!isFinite(pass.start)) {
    throw Error(fmt::format("drop envelope: pass {}: the start is not finite", passIndex));
  }
  PassBuilder builder;
  builder.maxMoves = options.maxMoves;
  ToolPass& lifted = result.pass;
  lifted.retractBefore = pass.retractBefore;
  Lifter lifter(distance, radius, eps, top, options.maxCellsPerProof, result.proofs);
  // The pass's first and last vertices are lifted cold (a Lifter of their own, with no
  // contact carried over): a pass fed from the previous one's end then starts exactly where
  // that end was lifted to, whichever thread lifted which.
  const auto liftCold = [&](Vec3 p) {
    Lifter cold(distance, radius, eps, top, options.maxCellsPerProof, result.proofs);
    return cold.lift(p);
  };
  lifted.start = liftCold(pass.start);
  const double startLift = lifted.start.z - pass.start.z;

  // Straight moves from `from` (already lifted) to `to` (lifted): proven, or halved with
  // the midpoint lifted, depth first so the moves come out in order.
  const double bottom = bottomOf(distance.surface(), radius);
  const double sagLength = std::sqrt(8.0 * radius * options.sagTolerance);
  bool sagHere = false;  // the sag rule applies to the input move being refined
  auto refineLine = [&](auto&& self, Vec3 from, Vec3 to, double toLift, int halvings) -> void {
    if (lifter.segmentClear(from, to, eps)) {
      if (sagHere && halvings < kEnvelopeMaxHalvings &&
          std::hypot(to.x - from.x, to.y - from.y) > sagLength) {
        const Vec3 middle = 0.5 * (from + to);
        const Vec3 onEnvelope = lifter.lift({middle.x, middle.y, bottom});
        if (onEnvelope.z > bottom && onEnvelope.z < middle.z - options.sagTolerance) {
          self(self, from, onEnvelope, kInserted, halvings + 1);
          self(self, onEnvelope, to, toLift, halvings + 1);
          return;
        }
      }
      builder.add(ToolMove{MoveKind::line, to, {}, ArcPlane::xy, true}, toLift);
      return;
    }
    if (halvings >= kEnvelopeMaxHalvings || !(norm(to - from) > 0.25 * eps)) {
      ++result.unprovenMoves;
      builder.add(ToolMove{MoveKind::line, to, {}, ArcPlane::xy, true}, toLift);
      return;
    }
    const Vec3 middle = 0.5 * (from + to);
    const Vec3 raised = lifter.lift(middle);
    self(self, from, raised, kInserted, halvings + 1);
    self(self, raised, to, toLift, halvings + 1);
  };

  Vec3 at = pass.start;       // the input position
  Vec3 liftedAt = lifted.start;
  // The input moves the sag rule applies to (see EnvelopeOptions::sagMoves).
  std::size_t sagFirst = 0, sagLast = pass.moves.size();
  if (passIndex < options.sagMoves.size()) {
    sagFirst = std::min(options.sagMoves[passIndex].first, pass.moves.size());
    sagLast = std::min(options.sagMoves[passIndex].second, pass.moves.size());
  }
  for (std::size_t m = 0; m < pass.moves.size(); ++m) {
    checkCancelled();
    sagHere = options.sagTolerance > 0.0 && m >= sagFirst && m < sagLast;
    const ToolMove& move = pass.moves[m];
    if (!isFinite(move.end) || (move.kind == MoveKind::arc && !isFinite(move.center))) {
      throw Error(fmt::format("drop envelope: pass {}, move {}: not finite", passIndex, m));
    }
    ++result.movesIn;
    const Vec3 end = m + 1 == pass.moves.size() ? liftCold(move.end) : lifter.lift(move.end);
    const double endLift = end.z - move.end.z;
    if (move.kind == MoveKind::line) {
      refineLine(refineLine, liftedAt, end, endLift, 0);
    } else {
      const ArcGeometry arc = arcGeometry(at, move);
      // Chords of sagitta <= eps / 4: k = ceil(|sweep| / (2 acos(1 - s / r))).
      const double sagitta = 0.25 * eps;
      const double step = 2.0 * std::acos(std::max(-1.0, 1.0 - sagitta / std::max(arc.radius, sagitta)));
      const double pieces = std::ceil(std::abs(arc.sweep) / step);
      if (!(pieces <= 1e6)) {
        throw Error(fmt::format("drop envelope: pass {}, move {}: an arc of radius {} needs more "
                                "than a million chords at depth tolerance {}", passIndex, m, arc.radius, eps));
      }
      const auto count = static_cast<std::size_t>(std::max(1.0, pieces));
      bool keep = liftedAt == at && end == move.end;
      // Each chord's sagitta, exactly: r (1 - cos(sweep / 2k)).
      const double chordSagitta = arc.radius * (1.0 - std::cos(0.5 * std::abs(arc.sweep) / static_cast<double>(count)));
      for (std::size_t i = 0; keep && i < count; ++i) {
        const Vec3 a = i == 0 ? at : pointOnArc(arc, static_cast<double>(i) / static_cast<double>(count));
        const Vec3 b = i + 1 == count ? move.end : pointOnArc(arc, static_cast<double>(i + 1) / static_cast<double>(count));
        keep = lifter.segmentClear(a, b, eps - chordSagitta);
      }
      if (keep) {
        ++result.arcsKept;
        builder.add(move, 0.0);
      } else {
        ++result.arcsReplaced;
        // Points of the arc a chord apart, each lifted, then refined as lines.
        Vec3 from = liftedAt;
        for (std::size_t i = 1; i <= count; ++i) {
          const Vec3 onArc = i == count ? move.end : pointOnArc(arc, static_cast<double>(i) / static_cast<double>(count));
          const Vec3 raised = i == count ? end : lifter.lift(onArc);
          refineLine(refineLine, from, raised, i == count ? endLift : raised.z - onArc.z, 0);
          from = raised;
        }
      }
    }
    result.map.push_back(builder.moves.size());
    at = move.end;
    liftedAt = end;
  }
  lifted.moves = std::move(builder.moves);
  result.lifts.push_back(startLift);
  result.lifts.insert(result.lifts.end(), builder.lifts.begin(), builder.lifts.end());
  return result;
}

}  // namespace

ToolPath liftToDropEnvelope(const SurfaceDistance& distance, const ToolPath& path,
                            const EnvelopeOptions& options, EnvelopeReport& report,
                            std::vector<std::vector<std::size_t>>* moveMap) {
  const double radius = path.toolRadius;
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    throw Error(fmt::format("drop envelope: the tool radius must be positive and finite, got {}", radius));
  }
  if (path.units != distance.surface().units) {
    throw Error(fmt::format("drop envelope: the tool path is in {} but the surface in {}",
                            unitsName(path.units), unitsName(distance.surface().units)));
  }
  const double eps = options.depthTolerance > 0.0 ? options.depthTolerance
                                                  : 1e-6 * surfaceScale(distance.surface());
  if (!(eps > 0.0) || !std::isfinite(eps) || options.depthTolerance < 0.0) {
    throw Error(fmt::format("drop envelope: the depth tolerance must be positive and finite, got {}",
                            options.depthTolerance));
  }
  if (!(eps < radius)) {
    throw Error(fmt::format("drop envelope: the depth tolerance {} must be below the tool radius {}", eps, radius));
  }
  if (!(options.stretchThreshold >= 0.0) || !std::isfinite(options.stretchThreshold)) {
    throw Error(fmt::format("drop envelope: the stretch threshold must be finite and >= 0, got {}",
                            options.stretchThreshold));
  }
  if (options.maxMoves < 1 || options.maxCellsPerProof < 1) {
    throw Error("drop envelope: the budgets must be at least 1");
  }
  report = EnvelopeReport{};
  report.depthTolerance = eps;
  report.stretchThreshold = options.stretchThreshold > 0.0 ? options.stretchThreshold : 10.0 * eps;
  // The passes are independent (each lifts its own vertices with its own Lifter; the first
  // and last cold, see liftPass), so they are lifted on every core, and the result is the
  // same for any number of threads.
  const double top = ballTop(distance.surface(), radius);
  std::vector<PassLift> lifts(path.passes.size());
  // An error is the first pass's, whatever the timing.
  parallelForEach(path.passes.size(), threadCount(options.threads), [&](std::size_t i) {
    advanceStage(i, path.passes.size());  // reports on the calling thread only
    lifts[i] = liftPass(distance, path.passes[i], i, radius, eps, top, options);
  });

  ToolPath out;
  out.units = path.units;
  out.toolRadius = radius;
  if (moveMap) moveMap->assign(path.passes.size(), {});
  std::size_t total = 0;
  for (std::size_t passIndex = 0; passIndex < path.passes.size(); ++passIndex) {
    PassLift& lifted = lifts[passIndex];
    total += lifted.pass.moves.size();
    if (total > options.maxMoves) {
      throw Error(fmt::format("lifting the path to the drop envelope: more than {} moves; the "
                              "depth tolerance is too fine for this path (raise it)",
                              options.maxMoves));
    }
    report.movesIn += lifted.movesIn;
    report.movesOut += lifted.pass.moves.size();
    report.arcsKept += lifted.arcsKept;
    report.arcsReplaced += lifted.arcsReplaced;
    report.proofs += lifted.proofs;
    report.unprovenMoves += lifted.unprovenMoves;
    if (moveMap) (*moveMap)[passIndex] = lifted.map;

    // Lifted vertices and stretches.
    const double threshold = report.stretchThreshold;
    std::vector<double>& vertexLifts = lifted.lifts;
    // An inserted vertex (a halving's midpoint) has no input point below it: the lift of a
    // chord's midpoint is its sag, not the surface's doing. It counts as lifted as much as the
    // lesser of the input vertices around it.
    {
      double before = 0.0;
      std::vector<double> after(vertexLifts.size(), 0.0);
      double next = 0.0;
      for (std::size_t k = vertexLifts.size(); k-- > 0;) {
        if (vertexLifts[k] != kInserted) next = vertexLifts[k];
        after[k] = next;
      }
      for (std::size_t k = 0; k < vertexLifts.size(); ++k) {
        if (vertexLifts[k] != kInserted) {
          before = vertexLifts[k];
        } else {
          vertexLifts[k] = std::min(before, after[k]);
        }
      }
    }
    auto vertex = [&](std::size_t i) { return i == 0 ? lifted.pass.start : lifted.pass.moves[i - 1].end; };
    std::size_t i = 0;
    while (i < vertexLifts.size()) {
      report.maxLift = std::max(report.maxLift, vertexLifts[i]);
      if (vertexLifts[i] > eps) ++report.verticesLifted;
      if (!(vertexLifts[i] > threshold)) {
        ++i;
        continue;
      }
      LiftedStretch stretch;
      stretch.pass = passIndex;
      stretch.from = vertex(i);
      std::size_t j = i;
      while (j + 1 < vertexLifts.size() && vertexLifts[j + 1] > threshold) {
        ++j;
        stretch.length += norm(vertex(j) - vertex(j - 1));
        report.maxLift = std::max(report.maxLift, vertexLifts[j]);
        if (vertexLifts[j] > eps) ++report.verticesLifted;
      }
      for (std::size_t k = i; k <= j; ++k) stretch.maxLift = std::max(stretch.maxLift, vertexLifts[k]);
      stretch.to = vertex(j);
      report.liftedLength += stretch.length;
      report.stretches.push_back(stretch);
      i = j + 1;
    }
    out.passes.push_back(std::move(lifted.pass));
  }
  return out;
}

namespace {


// Centres along a horizontal line dropped onto the envelope, each judged by the band of the
// surface point it touches (runOnPastEnd's and dropLineRuns' shared part).
class BandDropper {
 public:
  BandDropper(const SurfaceDistance& distance, double radius, const RunOnBand& band,
              const EnvelopeOptions& options, const char* what)
      : distance_(distance), band_(band) {
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw Error(fmt::format("{}: the tool radius must be positive and finite, got {}", what, radius));
    const Surface& surface = distance.surface();
    if (!(options.depthTolerance >= 0.0) || !std::isfinite(options.depthTolerance))
      throw Error(fmt::format("{}: the depth tolerance must be finite and >= 0, got {}", what, options.depthTolerance));
    const double eps = options.depthTolerance > 0.0 ? options.depthTolerance : 1e-6 * surfaceScale(surface);
    if (!(eps < radius))
      throw Error(fmt::format("{}: the depth tolerance {} must be below the tool radius {}", what, eps, radius));
    bottom_ = bottomOf(surface, radius);
    lifter_.emplace(distance, radius, eps, ballTop(surface, radius), options.maxCellsPerProof, proofs_);
  }

  enum class Verdict { clear, outside, inside };
  struct Dropped {
    Vec3 centre;
    Verdict verdict = Verdict::clear;
  };

  // The centre over (x, y) on the envelope, and whether it touches nothing (clear), a point
  // outside the band or one inside.
  Dropped drop(double x, double y) {
    Dropped out;
    out.centre = lifter_->lift({x, y, bottom_});
    if (!(out.centre.z > bottom_)) return out;  // nothing within R of the vertical line
    const ClosestPoint contact = distance_.closest(out.centre);
    Vec3 n = unitNormal(distance_.surface().patches[contact.patch], contact.u, contact.v);
    if (n.z < 0.0) n = -n;
    const double w = dot(band_.normal, contact.point + band_.offset * n);
    out.verdict = w >= band_.lo && w <= band_.hi ? Verdict::inside : Verdict::outside;
    return out;
  }

 private:
  const SurfaceDistance& distance_;
  RunOnBand band_;
  double bottom_ = 0.0;
  std::size_t proofs_ = 0;
  std::optional<Lifter> lifter_;
};

void checkLine(Vec3 origin, Vec3 direction, double step, double length, const char* what) {
  if (!(step > 0.0) || !std::isfinite(step) || !(length >= 0.0) || !std::isfinite(length))
    throw Error(fmt::format("{}: the step ({}) must be positive and the length ({}) finite and >= 0",
                            what, step, length));
  if (!isFinite(origin) || !isFinite(direction))
    throw Error(fmt::format("{}: the points and the direction must be finite", what));
  if (length / step > 1e7)
    throw Error(fmt::format("{}: {} steps of {} over {}; more than 10 million", what, length / step, step, length));
}

}  // namespace

struct DropCutter::State {
  State(const SurfaceDistance& distance, double radius, double eps, std::size_t maxCells)
      : bottom(bottomOf(distance.surface(), radius)),
        lifter(distance, radius, eps, ballTop(distance.surface(), radius), maxCells, proofs) {}
  double bottom;
  std::size_t proofs = 0;
  Lifter lifter;
};

DropCutter::DropCutter(const SurfaceDistance& distance, double radius, const EnvelopeOptions& options) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw Error(fmt::format("drop cutter: the tool radius must be positive and finite, got {}", radius));
  if (!(options.depthTolerance >= 0.0) || !std::isfinite(options.depthTolerance))
    throw Error(fmt::format("drop cutter: the depth tolerance must be finite and >= 0, got {}", options.depthTolerance));
  const double eps = options.depthTolerance > 0.0 ? options.depthTolerance : 1e-6 * surfaceScale(distance.surface());
  if (!(eps < radius))
    throw Error(fmt::format("drop cutter: the depth tolerance {} must be below the tool radius {}", eps, radius));
  state_ = std::make_unique<State>(distance, radius, eps, options.maxCellsPerProof);
}

DropCutter::~DropCutter() = default;

double DropCutter::height(double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y))
    throw Error(fmt::format("drop cutter: the point ({}, {}) is not finite", x, y));
  const Vec3 c = state_->lifter.lift({x, y, state_->bottom});
  return c.z > state_->bottom ? c.z : -kInfinity;
}

std::vector<Vec3> runOnPastEnd(const SurfaceDistance& distance, Vec3 end, Vec3 direction,
                               double radius, const RunOnBand& band, double step, double length,
                               const EnvelopeOptions& options) {
  const char* what = "running a pass on";
  checkLine(end, direction, step, length, what);
  BandDropper dropper(distance, radius, band, options, what);
  const double horizontal = std::hypot(direction.x, direction.y);
  if (!(horizontal > 0.0)) return {};
  const Vec3 h{direction.x / horizontal, direction.y / horizontal, 0.0};
  std::vector<Vec3> out;
  std::size_t keep = 0;  // up to the last vertex inside the band
  const auto steps = static_cast<std::size_t>(std::floor(length / step));
  for (std::size_t k = 1; k <= steps; ++k) {
    checkCancelled();
    const double along = static_cast<double>(k) * step;
    const BandDropper::Dropped c = dropper.drop(end.x + along * h.x, end.y + along * h.y);
    if (c.verdict == BandDropper::Verdict::clear) break;
    out.push_back(c.centre);
    if (c.verdict == BandDropper::Verdict::inside) keep = out.size();
  }
  out.resize(keep);
  return out;
}

void runPassOn(const SurfaceDistance& distance, ToolPass& pass, Vec3 backward, Vec3 forward, double radius,
               const RunOnBand& band, double step) {
  const auto line = [](Vec3 end) { return ToolMove{MoveKind::line, end, {}, ArcPlane::xy, true}; };
  for (const Vec3& c : runOnPastEnd(distance, passEnd(pass), forward, radius, band, step, kRunOnLength * radius))
    pass.moves.push_back(line(c));
  const std::vector<Vec3> before = runOnPastEnd(distance, pass.start, backward, radius, band, step, kRunOnLength * radius);
  if (before.empty()) return;
  // The pass now starts at the farthest vertex and comes back through the others.
  std::vector<ToolMove> prefix;
  prefix.reserve(before.size());
  for (std::size_t i = before.size() - 1; i-- > 0;) prefix.push_back(line(before[i]));
  prefix.push_back(line(pass.start));
  pass.moves.insert(pass.moves.begin(), prefix.begin(), prefix.end());
  pass.start = before.back();
}

std::vector<std::vector<Vec3>> dropLineRuns(const SurfaceDistance& distance, Vec3 origin,
                                            Vec3 direction, double from, double to, double radius,
                                            const RunOnBand& band, double step,
                                            const EnvelopeOptions& options) {
  const char* what = "dropping a line onto the envelope";
  checkLine(origin, direction, step, to - from, what);
  BandDropper dropper(distance, radius, band, options, what);
  const double horizontal = std::hypot(direction.x, direction.y);
  if (!(horizontal > 0.0)) throw Error(fmt::format("{}: the direction is vertical", what));
  const Vec3 h{direction.x / horizontal, direction.y / horizontal, 0.0};
  std::vector<std::vector<Vec3>> runs;
  std::vector<Vec3> run;
  const auto steps = static_cast<std::size_t>(std::floor((to - from) / step));
  for (std::size_t k = 0; k <= steps; ++k) {
    checkCancelled();
    const double t = from + static_cast<double>(k) * step;
    const BandDropper::Dropped c = dropper.drop(origin.x + t * h.x, origin.y + t * h.y);
    if (c.verdict == BandDropper::Verdict::inside) {
      run.push_back(c.centre);
      continue;
    }
    if (run.size() >= 2) runs.push_back(std::move(run));
    run.clear();
  }
  if (run.size() >= 2) runs.push_back(std::move(run));
  return runs;
}

}  // namespace scallop
