#include "scallop/io/gcode.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/job_control.hpp"

namespace scallop {
namespace {

constexpr double kPi = std::numbers::pi;
// A line must stay shorter than grbl's 80-character line buffer (LINE_BUFFER_SIZE).
constexpr std::size_t kMaxLineLength = 79;
// How far an arc's end may be off its start's circle, or its end and centre off the start's
// plane, in quanta (see the header: the printed radii then stay within every controller's
// tolerance).
constexpr double kArcMismatchQuanta = 10.0;
// The largest honest difference between an arc's true sweep and the sweep read back from its
// rounded numbers is about 2 sqrt(2) q / r radians, at most 0.3 rad at the smallest radius
// written as an arc (10 q in inch); a larger difference means the rounded end fell on the
// other side of the start (see the header).
constexpr double kSweepSlack = 0.5;

// The printed number grid of the path's units.
struct NumberFormat {
  Units units = Units::inch;
  int decimals = 0;
  double scale = 1.0;    // 10^decimals
  double quantum = 1.0;  // 10^-decimals
  double minArcRadius = 0.0;
};

NumberFormat numberFormat(Units units) {
  switch (units) {
    case Units::inch:
      return {units, kGcodeDecimalsInch, 1e5, 1e-5, kGcodeMinArcRadiusInch};
    case Units::millimetre:
      return {units, kGcodeDecimalsMm, 1e4, 1e-4, kGcodeMinArcRadiusMm};
  }
  throw Error(fmt::format("gcode: unknown units ({})", static_cast<int>(units)));
}

using Point = std::array<double, 3>;
using Grid = std::array<std::int64_t, 3>;  // a point in quanta
using GridTarget = std::array<std::optional<std::int64_t>, 3>;

constexpr std::array<char, 3> kAxisWord = {'X', 'Y', 'Z'};
constexpr std::array<char, 3> kOffsetWord = {'I', 'J', 'K'};
constexpr std::array<std::string_view, 3> kAxisName = {"x", "y", "z"};

// The tip of the ball whose centre is `centre`.
Point tipOf(Vec3 centre, double radius) { return {centre.x, centre.y, centre.z - radius}; }

// The plane's two axes, in the order RS-274 pairs them with G2/G3 (the normal is
// first x second: x y -> z, z x -> y, y z -> x), its normal axis and its G-code.
struct PlaneAxes {
  int first = 0;
  int second = 1;
  int normal = 2;
  std::string_view code;
};

PlaneAxes planeAxes(ArcPlane plane, const std::string& where) {
  switch (plane) {
    case ArcPlane::xy:
      return {0, 1, 2, "G17"};
    case ArcPlane::zx:
      return {2, 0, 1, "G18"};
    case ArcPlane::yz:
      return {1, 2, 0, "G19"};
  }
  throw Error(fmt::format("gcode: {}: unknown arc plane ({})", where, static_cast<int>(plane)));
}

// The angle turned from direction a to direction b (in-plane coordinates), counter-clockwise
// about the plane's normal or clockwise, in (0, 2 pi]; parallel directions give 2 pi, a full
// turn, as a controller reads an arc whose end is its start.
double sweepAngle(double a1, double a2, double b1, double b2, bool clockwise) {
  double angle = std::atan2(a1 * b2 - a2 * b1, a1 * b1 + a2 * b2);  // [-pi, pi]
  if (clockwise) angle = -angle;
  if (angle <= 0.0) angle += 2.0 * kPi;
  return angle;
}

std::int64_t toGrid(double value, const NumberFormat& format) {
  return std::llround(value * format.scale);
}

// n quanta as fixed point with `decimals` decimals: exact, no exponent, no "-0".
std::string formatFixed(std::int64_t n, int decimals) {
  const auto width = static_cast<std::size_t>(decimals);
  std::string digits = std::to_string(n < 0 ? -n : n);
  if (digits.size() <= width) digits.insert(0, width + 1 - digits.size(), '0');
  std::string out = n < 0 ? "-" : "";
  out += std::string_view(digits).substr(0, digits.size() - width);
  if (width > 0) {
    out += '.';
    out += std::string_view(digits).substr(digits.size() - width);
  }
  return out;
}

// As formatFixed with trailing zeros (and a trailing point) dropped: rates, tolerances.
std::string formatTrimmed(std::int64_t n, int decimals) {
  std::string out = formatFixed(n, decimals);
  if (out.find('.') != std::string::npos) {
    while (out.back() == '0') out.pop_back();
    if (out.back() == '.') out.pop_back();
  }
  return out;
}

std::string sanitisedTitle(const std::string& title) {
  std::string out;
  out.reserve(title.size());
  for (const char c : title) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '(') {
      out += '[';
    } else if (c == ')') {
      out += ']';
    } else if (byte < 0x20 || byte == 0x7f) {
      out += ' ';
    } else if (byte >= 0x80) {
      out += '?';
    } else {
      out += c;
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------

void checkRate(std::string_view name, double value, const NumberFormat& format) {
  if (!(std::isfinite(value) && value >= format.quantum && value < kGcodeMaxCoordinate)) {
    throw Error(fmt::format("gcode: option {} = {}: must be a finite number in [{}, {}) ({} per "
                            "minute)",
                            name, value, format.quantum, kGcodeMaxCoordinate,
                            unitsName(format.units)));
  }
}

void validateOptions(const GcodeOptions& options, const NumberFormat& format) {
  if (options.dialect != GcodeDialect::linuxcnc && options.dialect != GcodeDialect::grbl) {
    throw Error(fmt::format("gcode: option dialect = {}: unknown dialect",
                            static_cast<int>(options.dialect)));
  }
  if (!(std::isfinite(options.safeHeight) &&
        std::fabs(options.safeHeight) < kGcodeMaxCoordinate)) {
    throw Error(fmt::format("gcode: option safeHeight = {}: must be a finite number with "
                            "|safeHeight| < {}",
                            options.safeHeight, kGcodeMaxCoordinate));
  }
  checkRate("feedRate", options.feedRate, format);
  checkRate("plungeFeedRate", options.plungeFeedRate, format);
  const double rpm = options.spindleRpm;
  if (!(rpm == 0.0 || (std::isfinite(rpm) && rpm >= 1.0 && rpm < kGcodeMaxCoordinate))) {
    throw Error(fmt::format("gcode: option spindleRpm = {}: must be 0 (no spindle words) or a "
                            "number in [1, {})",
                            rpm, kGcodeMaxCoordinate));
  }
  const double blend = options.blendTolerance;
  if (!(blend == 0.0 ||
        (std::isfinite(blend) && blend >= format.quantum && blend < kGcodeMaxCoordinate))) {
    throw Error(fmt::format("gcode: option blendTolerance = {}: must be 0 (exact path, G61) or "
                            "a number in [{}, {})",
                            blend, format.quantum, kGcodeMaxCoordinate));
  }
}

std::string moveWhere(std::size_t pass, std::size_t move) {
  return fmt::format("pass {}, move {}", pass, move);
}

void checkPoint(const Point& p, std::string_view what, const std::string& where) {
  for (std::size_t a = 0; a < 3; ++a) {
    if (!std::isfinite(p[a])) {
      throw Error(fmt::format("gcode: {}: {}.{} is not finite ({})", where, what, kAxisName[a],
                              p[a]));
    }
    if (!(std::fabs(p[a]) < kGcodeMaxCoordinate)) {
      throw Error(fmt::format("gcode: {}: {}.{} = {} is too large (|coordinate| must be < {})",
                              where, what, kAxisName[a], p[a], kGcodeMaxCoordinate));
    }
  }
}

// The highest tip z of an arc other than its ends: the top of its circle if it passes there.
std::optional<double> arcTop(const Point& start, const Point& centre, const PlaneAxes& axes,
                             double sweep, bool clockwise) {
  if (axes.normal == 2) return std::nullopt;  // G17: z is constant
  // +z in the plane's (first, second) coordinates: G18 first = z, G19 second = z.
  const double top1 = axes.first == 2 ? 1.0 : 0.0;
  const double top2 = axes.second == 2 ? 1.0 : 0.0;
  const double d1 = start[axes.first] - centre[axes.first];
  const double d2 = start[axes.second] - centre[axes.second];
  if (sweepAngle(d1, d2, top1, top2, clockwise) > sweep) return std::nullopt;
  return centre[2] + std::hypot(d1, d2);
}

struct HighestTip {
  double z = -std::numeric_limits<double>::infinity();
  std::string where = "no move";
};

// Checks every pass and move (finite, in range, arcs as the ToolPath contract states) and
// returns the highest tip z the path reaches.
HighestTip validatePath(const ToolPath& path, const NumberFormat& format) {
  if (!(std::isfinite(path.toolRadius) && path.toolRadius >= 0.0 &&
        path.toolRadius < kGcodeMaxCoordinate)) {
    throw Error(fmt::format("gcode: toolRadius = {}: must be a finite number in [0, {})",
                            path.toolRadius, kGcodeMaxCoordinate));
  }
  const double radius = path.toolRadius;
  const double mismatch = kArcMismatchQuanta * format.quantum;
  HighestTip highest;
  auto raise = [&highest](double z, std::string where) {
    if (z > highest.z) highest = {z, std::move(where)};
  };
  Point previousEnd = {0.0, 0.0, 0.0};
  for (std::size_t p = 0; p < path.passes.size(); ++p) {
    const ToolPass& pass = path.passes[p];
    Point current = tipOf(pass.start, radius);
    const std::string passWhere = fmt::format("pass {}, start", p);
    checkPoint(current, "start", passWhere);
    raise(current[2], passWhere);
    if (pass.retract) {
      const LocalRetract& r = *pass.retract;
      const std::string where = fmt::format("pass {}, retract", p);
      if (p > 0 && !pass.retractBefore) {
        throw Error(fmt::format("gcode: {}: a local retract on a pass without retractBefore",
                                where));
      }
      if (!(std::isfinite(r.height) && std::fabs(r.height) < kGcodeMaxCoordinate &&
            std::isfinite(r.plunge) && r.plunge >= 0.0 &&
            r.plunge <= r.height - pass.start.z + format.quantum)) {
        throw Error(fmt::format("gcode: {}: height h = {} and plunge d = {} must be finite with "
                                "0 <= d <= h - start z + q (start z = {}, q = {})",
                                where, r.height, r.plunge, pass.start.z, format.quantum));
      }
      if (p > 0) {
        if (!(r.height - radius >= previousEnd[2])) {
          throw Error(fmt::format("gcode: {}: height h = {} is below the previous pass's end "
                                  "(centre z {}): a retract only rises",
                                  where, r.height, previousEnd[2] + radius));
        }
        raise(r.height - radius, where + " height");
      } else {
        raise(current[2] + r.plunge, where + " plunge");
      }
    }
    for (std::size_t m = 0; m < pass.moves.size(); ++m) {
      const ToolMove& move = pass.moves[m];
      const std::string where = moveWhere(p, m);
      const Point end = tipOf(move.end, radius);
      checkPoint(end, "end", where);
      raise(end[2], where);
      if (move.kind == MoveKind::arc) {
        const Point centre = tipOf(move.center, radius);
        checkPoint(centre, "center", where);
        const PlaneAxes axes = planeAxes(move.plane, where);
        const double offEnd = std::fabs(end[axes.normal] - current[axes.normal]);
        const double offCentre = std::fabs(centre[axes.normal] - current[axes.normal]);
        if (!(offEnd <= mismatch && offCentre <= mismatch)) {
          throw Error(fmt::format(
              "gcode: {}: arc in the {} plane: its end and centre must share the start's {} "
              "(within {}); start {}, end {}, center {}",
              where, axes.code, kAxisName[static_cast<std::size_t>(axes.normal)], mismatch,
              current[axes.normal], end[axes.normal], centre[axes.normal]));
        }
        const double s1 = current[axes.first] - centre[axes.first];
        const double s2 = current[axes.second] - centre[axes.second];
        const double e1 = end[axes.first] - centre[axes.first];
        const double e2 = end[axes.second] - centre[axes.second];
        const double startRadius = std::hypot(s1, s2);
        const double endRadius = std::hypot(e1, e2);
        if (!(std::fabs(startRadius - endRadius) <= mismatch)) {
          throw Error(fmt::format("gcode: {}: arc radius to the start {} and to the end {} differ "
                                  "by more than {}",
                                  where, startRadius, endRadius, mismatch));
        }
        if (s1 == e1 && s2 == e2 && startRadius > 0.0) {
          throw Error(fmt::format("gcode: {}: arc ends where it starts (a full circle is not "
                                  "allowed)",
                                  where));
        }
        const double sweep = sweepAngle(s1, s2, e1, e2, move.clockwise);
        if (const auto top = arcTop(current, centre, axes, sweep, move.clockwise)) {
          raise(*top, where + " (top of the arc)");
        }
      }
      current = end;
    }
    previousEnd = current;
  }
  return highest;
}

// ---------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------

class ProgramWriter {
 public:
  ProgramWriter(const ToolPath& path, const GcodeOptions& options, const NumberFormat& format)
      : path_(path), options_(options), format_(format) {}

  std::string write() {
    writeHeader();
    const std::int64_t safe = toGrid(options_.safeHeight, format_);
    motion("G0", {std::nullopt, std::nullopt, safe}, std::nullopt);
    for (std::size_t p = 0; p < path_.passes.size(); ++p) writePass(p);
    motion("G0", {std::nullopt, std::nullopt, safe}, std::nullopt);
    if (options_.spindleRpm > 0.0) line("M5");
    line("M2");
    return std::move(out_);
  }

 private:
  void line(std::string_view text) {
    if (text.size() > kMaxLineLength) {
      // Cannot happen within the documented ranges; kept as a guard for grbl's buffer.
      throw Error(fmt::format("gcode: internal error: line longer than {} characters: {}",
                              kMaxLineLength, text));
    }
    out_ += text;
    out_ += '\n';
  }

  std::string number(std::int64_t n) const { return formatFixed(n, format_.decimals); }
  std::string rate(double value) const {
    return formatTrimmed(toGrid(value, format_), format_.decimals);
  }

  void writeHeader() {
    const bool inch = path_.units == Units::inch;
    std::string title = "(scallop tool path";
    if (!options_.title.empty()) {
      title += ": ";
      title += sanitisedTitle(options_.title);
    }
    if (title.size() > kMaxLineLength - 1) title.resize(kMaxLineLength - 1);
    title += ')';
    line(title);
    line(fmt::format("(units: {}; ball-end tool, radius {})", inch ? "inch" : "mm",
                     number(toGrid(path_.toolRadius, format_))));
    line("(positions are the ball tip = ball centre - radius along z)");
    line("(the tool length offset must be measured to the tip)");
    line(inch ? "G20" : "G21");
    line("G90 G94 G17 G40 G80");
    line("G91.1");
    if (options_.dialect == GcodeDialect::linuxcnc) {
      if (options_.blendTolerance > 0.0) {
        line(fmt::format("G64 P{}", rate(options_.blendTolerance)));
      } else {
        line("G61");
      }
    } else {
      line("(grbl rounds corners by its junction deviation setting $11)");
    }
    if (options_.spindleRpm > 0.0) line(fmt::format("S{} M3", rate(options_.spindleRpm)));
  }

  // Writes `code` to `target` (absent axes stay where they are), with the feed set first
  // when it changes. Axes whose printed value does not change are left out; a move that
  // changes none is not written.
  void motion(std::string_view code, const GridTarget& target, std::optional<double> feed) {
    std::string words;
    for (std::size_t a = 0; a < 3; ++a) {
      if (!target[a] || (known_[a] && position_[a] == *target[a])) continue;
      words += ' ';
      words += kAxisWord[a];
      words += number(*target[a]);
    }
    if (words.empty()) return;
    setFeed(feed);
    line(fmt::format("{}{}", code, words));
    for (std::size_t a = 0; a < 3; ++a) {
      if (!target[a]) continue;
      position_[a] = *target[a];
      known_[a] = true;
    }
  }

  void feedTo(const Point& target) {
    motion("G1", {toGrid(target[0], format_), toGrid(target[1], format_),
                  toGrid(target[2], format_)},
           options_.feedRate);
  }

  void setFeed(std::optional<double> feed) {
    if (!feed) return;
    const std::int64_t value = toGrid(*feed, format_);
    if (feed_ && *feed_ == value) return;
    line(fmt::format("F{}", formatTrimmed(value, format_.decimals)));
    feed_ = value;
  }

  void writePass(std::size_t p) {
    const ToolPass& pass = path_.passes[p];
    const double radius = path_.toolRadius;
    const Point start = tipOf(pass.start, radius);
    const Grid startGrid = {toGrid(start[0], format_), toGrid(start[1], format_),
                            toGrid(start[2], format_)};
    if (p == 0 || pass.retractBefore) {
      // Up (to the safe height, or to a local retract's height), across, rapid down to the
      // plunge's start when the retract is local, and down the rest at the plunge feed.
      const bool local = pass.retract.has_value();
      const std::int64_t top = toGrid(
          local && p > 0 ? pass.retract->height - radius : options_.safeHeight, format_);
      motion("G0", {std::nullopt, std::nullopt, top}, std::nullopt);
      motion("G0", {startGrid[0], startGrid[1], std::nullopt}, std::nullopt);
      if (local) {
        // Down to d above the start; on later passes never above the traverse (d may exceed
        // h - start z by a quantum of rounding).
        double from = start[2] + pass.retract->plunge;
        if (p > 0) from = std::min(from, pass.retract->height - radius);
        motion("G0", {std::nullopt, std::nullopt, toGrid(from, format_)}, std::nullopt);
      }
      motion("G1", {startGrid[0], startGrid[1], startGrid[2]}, options_.plungeFeedRate);
    } else {
      motion("G1", {startGrid[0], startGrid[1], startGrid[2]}, options_.feedRate);
    }
    Point current = start;
    for (const ToolMove& move : pass.moves) {
      if (++written_ % 1024 == 0) checkCancelled();  // a plan's cancel (job_control.hpp)
      const Point end = tipOf(move.end, radius);
      if (move.kind == MoveKind::arc) {
        writeArc(current, end, tipOf(move.center, radius), move.plane, move.clockwise);
      } else {
        feedTo(end);
      }
      current = end;
    }
  }

  // An arc from `start` (true values; the printed position is its rounding) to `end`.
  void writeArc(const Point& start, const Point& end, const Point& centre, ArcPlane plane,
                bool clockwise) {
    const PlaneAxes axes = planeAxes(plane, "arc");
    const auto f = static_cast<std::size_t>(axes.first);
    const auto s = static_cast<std::size_t>(axes.second);
    const auto n = static_cast<std::size_t>(axes.normal);
    const double s1 = start[f] - centre[f];
    const double s2 = start[s] - centre[s];
    const double e1 = end[f] - centre[f];
    const double e2 = end[s] - centre[s];
    const double radius = std::hypot(s1, s2);
    if (radius < format_.minArcRadius) {
      writeTinyArc(start, end, centre, axes, clockwise);
      return;
    }
    const double sweep = sweepAngle(s1, s2, e1, e2, clockwise);
    // Sagitta r (1 - cos(sweep / 2)) = 2 r sin^2(sweep / 4) <= q / 2: the chord is the arc
    // to the printed precision, and a G1 spares the controller a nearly flat arc.
    const double quarterSine = std::sin(0.25 * sweep);
    if (sweep <= kPi && 2.0 * radius * quarterSine * quarterSine <= 0.5 * format_.quantum) {
      feedTo(end);
      return;
    }
    const Grid endGrid = {toGrid(end[0], format_), toGrid(end[1], format_),
                          toGrid(end[2], format_)};
    const Grid centreGrid = {toGrid(centre[0], format_), toGrid(centre[1], format_),
                             toGrid(centre[2], format_)};
    // Differences of grid points are exact in double (|n| < 2^53).
    const auto q = [](std::int64_t a, std::int64_t b) { return static_cast<double>(a - b); };
    const bool sameInPlane = endGrid[f] == position_[f] && endGrid[s] == position_[s];
    const double readSweep =
        sweepAngle(q(position_[f], centreGrid[f]), q(position_[s], centreGrid[s]),
                   q(endGrid[f], centreGrid[f]), q(endGrid[s], centreGrid[s]), clockwise);
    if (sameInPlane || std::fabs(readSweep - sweep) > kSweepSlack) {
      if (sweep < kPi) {
        feedTo(end);  // a chord of a few quanta (or none: then nothing is written)
      } else {
        // Split at the midpoint: two half arcs of about pi each.
        const double half = 0.5 * (clockwise ? -sweep : sweep);
        const double c = std::cos(half);
        const double si = std::sin(half);
        Point middle = start;
        middle[f] = centre[f] + c * s1 - si * s2;
        middle[s] = centre[s] + si * s1 + c * s2;
        writeArc(start, middle, centre, plane, clockwise);
        writeArc(middle, end, centre, plane, clockwise);
      }
      return;
    }
    if (plane_ != plane) {
      line(axes.code);
      plane_ = plane;
    }
    std::string words = clockwise ? "G2" : "G3";
    for (std::size_t a = 0; a < 3; ++a) {
      if (a == n && endGrid[a] == position_[a]) continue;
      words += ' ';
      words += kAxisWord[a];
      words += number(endGrid[a]);
    }
    for (std::size_t a = 0; a < 3; ++a) {
      if (a == n) continue;
      words += ' ';
      words += kOffsetWord[a];
      words += number(centreGrid[a] - position_[a]);
    }
    setFeed(options_.feedRate);
    line(words);
    position_ = endGrid;
  }

  // An arc too small for the controllers' zero-radius check: its circumscribed polygon with
  // tolerance q, on the circle through the start (the end may be off it by <= 10 q).
  void writeTinyArc(const Point& start, const Point& end, const Point& centre,
                    const PlaneAxes& axes, bool clockwise) {
    const auto f = static_cast<std::size_t>(axes.first);
    const auto s = static_cast<std::size_t>(axes.second);
    const auto n = static_cast<std::size_t>(axes.normal);
    const double radius = std::hypot(start[f] - centre[f], start[s] - centre[s]);
    const double e1 = end[f] - centre[f];
    const double e2 = end[s] - centre[s];
    const double endRadius = std::hypot(e1, e2);
    if (radius == 0.0 || endRadius == 0.0) {
      feedTo(end);
      return;
    }
    Point planeCentre = centre;
    planeCentre[n] = start[n];
    Point onCircle = planeCentre;
    onCircle[f] += e1 * (radius / endRadius);
    onCircle[s] += e2 * (radius / endRadius);
    Point axis = {0.0, 0.0, 0.0};
    axis[n] = clockwise ? -1.0 : 1.0;
    const auto vec = [](const Point& p) { return Vec3{p[0], p[1], p[2]}; };
    const std::vector<Vec3> vertices = arcPolyline(vec(start), vec(onCircle), vec(planeCentre),
                                                   vec(axis), format_.quantum);
    for (std::size_t i = 1; i + 1 < vertices.size(); ++i) {
      feedTo({vertices[i].x, vertices[i].y, vertices[i].z});
    }
    feedTo(end);
  }

  const ToolPath& path_;
  const GcodeOptions& options_;
  NumberFormat format_;
  std::string out_;
  Grid position_ = {0, 0, 0};
  std::array<bool, 3> known_ = {false, false, false};
  std::optional<std::int64_t> feed_;
  ArcPlane plane_ = ArcPlane::xy;  // the header's G17
  std::size_t written_ = 0;        // moves written, for the cancel's polls
};

}  // namespace

std::string gcodeProgram(const ToolPath& path, const GcodeOptions& options) {
  const NumberFormat format = numberFormat(path.units);
  validateOptions(options, format);
  const HighestTip highest = validatePath(path, format);
  if (!(options.safeHeight > highest.z)) {
    throw Error(fmt::format("gcode: option safeHeight = {}: must be above the highest tool tip, "
                            "z = {} ({})",
                            options.safeHeight, highest.z, highest.where));
  }
  return ProgramWriter(path, options, format).write();
}

GcodeMotion gcodeMotion(const ToolPath& path, const GcodeOptions& options, double rapidRate) {
  const NumberFormat format = numberFormat(path.units);
  validateOptions(options, format);
  checkRate("rapidRate", rapidRate, format);
  const HighestTip highest = validatePath(path, format);
  if (!(options.safeHeight > highest.z)) {
    throw Error(fmt::format("gcode: option safeHeight = {}: must be above the highest tool tip, "
                            "z = {} ({})",
                            options.safeHeight, highest.z, highest.where));
  }
  const double radius = path.toolRadius;
  const double safe = options.safeHeight;
  GcodeMotion out;
  Point position = {0.0, 0.0, safe};
  for (std::size_t p = 0; p < path.passes.size(); ++p) {
    const ToolPass& pass = path.passes[p];
    const Point start = tipOf(pass.start, radius);
    if (p == 0 || pass.retractBefore) {
      const bool local = pass.retract.has_value();
      const double top = local && p > 0 ? pass.retract->height - radius : safe;
      out.rapidLength += top - position[2];  // straight up (validated: never down)
      // The first traverse starts from wherever the machine was: not counted.
      if (p > 0) out.rapidLength += std::hypot(start[0] - position[0], start[1] - position[1]);
      const double plungeFrom =
          local ? std::min(start[2] + pass.retract->plunge, p > 0 ? top : safe) : top;
      out.rapidLength += top - plungeFrom;
      out.plungeLength += plungeFrom - start[2];
    } else {
      out.feedLength += std::hypot(std::hypot(start[0] - position[0], start[1] - position[1]),
                                   start[2] - position[2]);
    }
    Point current = start;
    for (const ToolMove& move : pass.moves) {
      const Point end = tipOf(move.end, radius);
      if (move.kind == MoveKind::arc) {
        // r * sweep in the plane, and the change along its normal (a helix, within 10 q).
        const Point centre = tipOf(move.center, radius);
        const PlaneAxes axes = planeAxes(move.plane, "arc");
        const auto f = static_cast<std::size_t>(axes.first);
        const auto s = static_cast<std::size_t>(axes.second);
        const auto n = static_cast<std::size_t>(axes.normal);
        const double s1 = current[f] - centre[f], s2 = current[s] - centre[s];
        const double sweep =
            sweepAngle(s1, s2, end[f] - centre[f], end[s] - centre[s], move.clockwise);
        out.feedLength += std::hypot(std::hypot(s1, s2) * sweep, end[n] - current[n]);
      } else {
        out.feedLength += std::hypot(std::hypot(end[0] - current[0], end[1] - current[1]),
                                     end[2] - current[2]);
      }
      current = end;
    }
    position = current;
  }
  if (!path.passes.empty()) out.rapidLength += safe - position[2];  // the final retract
  out.feedMinutes = out.feedLength / options.feedRate;
  out.plungeMinutes = out.plungeLength / options.plungeFeedRate;
  out.rapidMinutes = out.rapidLength / rapidRate;
  out.minutes = out.feedMinutes + out.plungeMinutes + out.rapidMinutes;
  return out;
}

std::vector<Vec3> arcPolyline(Vec3 start, Vec3 end, Vec3 center, Vec3 axis, double tolerance) {
  const auto finite = [](Vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!(finite(start) && finite(end) && finite(center) && finite(axis))) {
    throw Error("arcPolyline: start, end, center and axis must be finite");
  }
  if (!(std::isfinite(tolerance) && tolerance > 0.0)) {
    throw Error(fmt::format("arcPolyline: tolerance = {}: must be a finite number > 0",
                            tolerance));
  }
  if (!(std::fabs(norm(axis) - 1.0) <= 1e-9)) {
    throw Error(fmt::format("arcPolyline: axis must be a unit vector, |axis| = {}", norm(axis)));
  }
  const Vec3 a = start - center;
  const Vec3 b = end - center;
  const double startOff = dot(a, axis);
  const double endOff = dot(b, axis);
  const Vec3 aIn = a - startOff * axis;
  const Vec3 bIn = b - endOff * axis;
  const double radius = norm(aIn);
  if (!(radius > 0.0 && std::isfinite(radius))) {
    throw Error("arcPolyline: start coincides with the center (radius 0)");
  }
  if (!(std::fabs(startOff) <= tolerance && std::fabs(endOff) <= tolerance &&
        std::fabs(norm(bIn) - radius) <= tolerance)) {
    throw Error(fmt::format("arcPolyline: the end must lie on the start's circle within the "
                            "tolerance {}: radius {} vs {}, off the plane by {} and {}",
                            tolerance, radius, norm(bIn), startOff, endOff));
  }
  const Vec3 u = aIn / radius;
  const Vec3 v = cross(axis, u);
  // end == start is the full circle (atan2 of the rounded (end - centre) . v could be a
  // tiny positive angle instead).
  double sweep = end == start ? 2.0 * kPi : std::atan2(dot(bIn, v), dot(bIn, u));
  if (sweep <= 0.0) sweep += 2.0 * kPi;
  // d_max = 2 acos(r / (r + tolerance)): then r / cos(d / 2) - r <= tolerance for d <= d_max.
  const double maxStep = 2.0 * std::acos(radius / (radius + tolerance));
  const double steps = std::ceil(sweep / maxStep);
  if (!(steps + 1.0 <= static_cast<double>(kArcPolylineMaxSegments))) {
    throw Error(fmt::format("arcPolyline: tolerance {} is too small for radius {}: more than {} "
                            "segments",
                            tolerance, radius, kArcPolylineMaxSegments));
  }
  const auto m = static_cast<int>(std::max(1.0, steps));
  const double step = sweep / m;
  const double vertexRadius = radius / std::cos(0.5 * step);
  std::vector<Vec3> vertices;
  vertices.reserve(static_cast<std::size_t>(m) + 2);
  vertices.push_back(start);
  for (int k = 1; k <= m; ++k) {
    const double angle = (k - 0.5) * step;
    vertices.push_back(center + vertexRadius * (std::cos(angle) * u + std::sin(angle) * v));
  }
  vertices.push_back(end);
  return vertices;
}

}  // namespace scallop
