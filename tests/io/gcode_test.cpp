// Tests for gcode.hpp. The writer's programs are checked by LinuxCNC's own interpreter: each
// program is run through `rs274` (package linuxcnc-uspace), which must accept it without an
// error, and the path is rebuilt from the canonical machining commands it prints
// (STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED, ...) and compared with the ToolPath. The
// references are the interpreter and computations made here from the ToolPath (tips,
// sweeps, rotation axes by Rodrigues' formula), never the writer's own output. arcPolyline
// is checked on thousands of random arcs against its contract.
//
// rs274 quirks this relies on (LinuxCNC 2.9, Debian 12):
//   - `rs274 -t tools.tbl -v params.var -g prog.ngc` runs headless: no ini file, realtime
//     or X display needed. It prints "executing" on stderr, one canonical call per line on
//     stdout, and on an error its message and the offending block on stderr, exit status 1.
//     It maps $HOME/.tool.mmap (see runRs274: each run gets its own HOME).
//   - Canonical values are in the program's units (after USE_LENGTH_UNITS(CANON_UNITS_INCHES)
//     they are inches), printed with 4 decimals: a point read back is within q/2 (the
//     program's rounding) + 0.00005 (the canonical printing) of the true one.
//   - ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, a,
//     b, c): (first, second) are (x, y) in XY, (z, x) in XZ and (y, z) in YZ, so that
//     first x second is the plane's normal (+z, +y, +x); rotation > 0 turns
//     counter-clockwise about that normal, < 0 clockwise (|rotation| - 1 more full turns),
//     and an end equal to the start is a full turn.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "support/rs274.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/paths/linking.hpp"
#include "scallop/paths/toolpath.hpp"

#ifndef SCALLOP_RS274_PATH
#define SCALLOP_RS274_PATH ""
#endif

namespace scallop {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------
// Geometry, computed here independently of the writer
// ---------------------------------------------------------------------------------------

// The plane's normal as toolpath.hpp states it: G17 +z, G18 +y, G19 +x.
Vec3 planeNormal(ArcPlane plane) {
  switch (plane) {
    case ArcPlane::xy:
      return {0, 0, 1};
    case ArcPlane::zx:
      return {0, 1, 0};
    case ArcPlane::yz:
      return {1, 0, 0};
  }
  return {};
}

// Rotation of v by angle about the unit axis w (Rodrigues).
Vec3 rotate(Vec3 v, Vec3 w, double angle) {
  return std::cos(angle) * v + std::sin(angle) * cross(w, v) +
         (dot(w, v) * (1.0 - std::cos(angle))) * w;
}

// Angle turned counter-clockwise about w from a to b, in (0, 2 pi]; parallel gives 2 pi.
double sweepAbout(Vec3 a, Vec3 b, Vec3 w) {
  double angle = std::atan2(dot(w, cross(a, b)), dot(a, b));
  if (angle <= 0.0) angle += 2.0 * kPi;
  return angle;
}

Vec3 tipOf(Vec3 centre, double radius) { return {centre.x, centre.y, centre.z - radius}; }

double quantum(Units units) { return units == Units::inch ? 1e-5 : 1e-4; }

// Distance within which a point read back from rs274's canonical output lies from the true
// one: the program's rounding (q / 2) plus the canonical printing (0.00005), per axis.
double readBackTolerance(Units units) { return 0.5 * quantum(units) + 0.5e-4 + 1e-9; }

// ---------------------------------------------------------------------------------------
// Building tool paths
// ---------------------------------------------------------------------------------------

ToolMove lineTo(Vec3 end) {
  ToolMove move;
  move.kind = MoveKind::line;
  move.end = end;
  return move;
}

// The arc from `from` about `centre` (same normal coordinate), sweeping `sweep` radians
// clockwise or not as seen from the plane's positive normal.
ToolMove arcFrom(Vec3 from, Vec3 centre, ArcPlane plane, bool clockwise, double sweep) {
  const Vec3 w = (clockwise ? -1.0 : 1.0) * planeNormal(plane);
  ToolMove move;
  move.kind = MoveKind::arc;
  move.center = centre;
  move.plane = plane;
  move.clockwise = clockwise;
  move.end = centre + rotate(from - centre, w, sweep);
  return move;
}

// A safe height (for tips) above everything the path reaches: every arc's whole circle.
double safeHeightFor(const ToolPath& path, double margin) {
  double top = -kInf;
  for (const ToolPass& pass : path.passes) {
    top = std::max(top, pass.start.z);
    Vec3 current = pass.start;
    for (const ToolMove& move : pass.moves) {
      top = std::max(top, move.end.z);
      if (move.kind == MoveKind::arc) {
        top = std::max(top, move.center.z + norm(current - move.center));
      }
      current = move.end;
    }
    if (pass.retract) top = std::max(top, pass.retract->height);
  }
  return top - path.toolRadius + margin;
}

GcodeOptions optionsFor(const ToolPath& path, GcodeDialect dialect) {
  const double unit = path.units == Units::inch ? 1.0 : 25.4;
  GcodeOptions options;
  options.dialect = dialect;
  options.safeHeight = safeHeightFor(path, 0.5 * unit);
  options.feedRate = 40.0 * unit;
  options.plungeFeedRate = 12.5 * unit;
  options.spindleRpm = 18000.0;
  options.title = "gcode_test";
  return options;
}

ToolPath scaled(ToolPath path, double factor, Units units) {
  path.units = units;
  path.toolRadius *= factor;
  for (ToolPass& pass : path.passes) {
    pass.start = factor * pass.start;
    if (pass.retract) pass.retract = LocalRetract{factor * pass.retract->height, factor * pass.retract->plunge};
    for (ToolMove& move : pass.moves) {
      move.end = factor * move.end;
      move.center = factor * move.center;
    }
  }
  return path;
}

// Lines only: three raster passes, retracting between them.
ToolPath linesPath() {
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.125;
  for (int i = 0; i < 3; ++i) {
    ToolPass pass;
    const double y = 0.1 * i;
    pass.start = {0.0, y, 0.5};
    pass.moves = {lineTo({0.3, y, 0.45}), lineTo({0.6, y, 0.47}), lineTo({1.0, y + 0.01, 0.5})};
    pass.retractBefore = true;
    path.passes.push_back(pass);
  }
  return path;
}

// Arcs in all three planes, both directions, quarter turns to 3/4 turns, with both kinds of
// links.
ToolPath arcsPath() {
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.25;
  const std::array<ArcPlane, 3> planes = {ArcPlane::xy, ArcPlane::zx, ArcPlane::yz};
  Vec3 current = {1.0, 1.0, 1.0};
  int index = 0;
  for (const ArcPlane plane : planes) {
    for (const bool clockwise : {true, false}) {
      ToolPass pass;
      pass.start = current;
      pass.retractBefore = index % 2 == 0;
      const Vec3 n = planeNormal(plane);
      // A centre 0.4 away in the plane, in a direction that varies with the pass.
      Vec3 inPlane = cross(n, Vec3{0.3, 0.5, 0.7});
      inPlane = (0.4 / norm(inPlane)) * inPlane;
      Vec3 position = pass.start;
      for (const double sweep : {0.5 * kPi, 1.2, 1.5 * kPi}) {
        const ToolMove arc = arcFrom(position, position + inPlane, plane, clockwise, sweep);
        pass.moves.push_back(arc);
        position = arc.end;
        pass.moves.push_back(lineTo(position + Vec3{0.05, -0.03, 0.02}));
        position = pass.moves.back().end;
        inPlane = rotate(inPlane, n, 0.7);
      }
      current = position + Vec3{0.1, 0.1, -0.05};
      path.passes.push_back(pass);
      ++index;
    }
  }
  return path;
}

// The same path with local retracts (toolpath.hpp) on its retracted passes: a random
// height above both ends of the link and a random plunge distance, some of them the whole
// descent (d = h - start z) and some none (d = 0); the first pass gets a plunge only.
ToolPath withLocalRetracts(ToolPath path, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t p = 0; p < path.passes.size(); ++p) {
    ToolPass& pass = path.passes[p];
    if (!pass.retractBefore && p > 0) continue;
    const double below = p == 0 ? pass.start.z
                                : std::max(pass.start.z, (path.passes[p - 1].moves.empty()
                                                              ? path.passes[p - 1].start
                                                              : path.passes[p - 1].moves.back().end)
                                                             .z);
    const double height = below + 0.3 * unit(rng);
    const double choice = unit(rng);
    const double span = height - pass.start.z;
    const double plunge = choice < 0.2 ? 0.0 : choice < 0.4 ? span : span * unit(rng);
    pass.retract = LocalRetract{height, plunge};
  }
  return path;
}

// A large random path: lines and arcs in every plane and direction, random links.
ToolPath randomPath(std::uint64_t seed, int passes, int movesPerPass) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.0625;
  Vec3 position = {0.0, 0.0, 0.0};
  const std::array<ArcPlane, 3> planes = {ArcPlane::xy, ArcPlane::zx, ArcPlane::yz};
  for (int p = 0; p < passes; ++p) {
    ToolPass pass;
    pass.retractBefore = unit(rng) < 0.5;
    pass.start = position + Vec3{uniform(-0.5, 0.5), uniform(-0.5, 0.5), uniform(-0.5, 0.5)};
    position = pass.start;
    for (int m = 0; m < movesPerPass; ++m) {
      // Drift back towards the origin so that the path stays in a box of about +-10.
      const Vec3 pull = -0.02 * position;
      if (unit(rng) < 0.5) {
        position = position + pull +
                   Vec3{uniform(-0.4, 0.4), uniform(-0.4, 0.4), uniform(-0.2, 0.2)};
        pass.moves.push_back(lineTo(position));
      } else {
        const ArcPlane plane = planes[static_cast<std::size_t>(rng() % 3)];
        const Vec3 n = planeNormal(plane);
        const double radius = uniform(0.02, 1.5);
        const Vec3 direction = rotate(cross(n, Vec3{0.6, 0.7, 0.8}), n, uniform(0.0, 2.0 * kPi));
        const Vec3 centre = position + (radius / norm(direction)) * direction;
        const bool clockwise = unit(rng) < 0.5;  // one draw per statement: a fixed order
        const double sweep = uniform(0.02, 2.0 * kPi - 0.02);
        const ToolMove arc = arcFrom(position, centre, plane, clockwise, sweep);
        pass.moves.push_back(arc);
        position = arc.end;
      }
    }
    path.passes.push_back(pass);
  }
  return path;
}

// ---------------------------------------------------------------------------------------
// Running LinuxCNC's interpreter
// ---------------------------------------------------------------------------------------

using scallop::test::findRs274;
using scallop::test::Rs274Run;
using scallop::test::runRs274;

struct CanonCall {
  std::string name;
  std::vector<std::string> args;
  std::string text;
};

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

double number(const std::string& text) {
  std::size_t used = 0;
  const double value = std::stod(text, &used);
  if (used != text.size()) throw std::runtime_error("not a number: " + text);
  return value;
}

// Parses rs274's canonical output; any other line is reported in `unexpected`.
std::vector<CanonCall> parseCanon(const std::string& out, std::vector<std::string>& unexpected) {
  std::vector<CanonCall> calls;
  for (const std::string& line : lines(out)) {
    const std::optional<test::CanonLine> call = test::parseCanonLine(line);
    if (!call) {
      if (!line.empty()) unexpected.push_back(line);
      continue;
    }
    CanonCall c;
    c.name = call->name;
    c.text = line;
    std::stringstream args(call->arguments);
    std::string arg;
    while (std::getline(args, arg, ',')) {
      const auto first = arg.find_first_not_of(' ');
      c.args.push_back(first == std::string::npos ? "" : arg.substr(first));
    }
    calls.push_back(c);
  }
  return calls;
}

// One motion, as rebuilt from the canonical calls or as expected from the ToolPath.
struct Motion {
  enum class Kind { traverse, feed, arc } kind = Kind::feed;
  Vec3 start;
  Vec3 end;
  Vec3 centre;      // arc only
  Vec3 axis;        // arc only: the unit rotation axis (counter-clockwise about it)
  double sweep = 0; // arc only
  double feedRate = 0;
  std::string text; // the canonical call, for messages
};

struct Canon {
  std::optional<std::string> units;  // the last USE_LENGTH_UNITS before the first motion
  std::vector<Motion> motions;
  std::vector<std::string> controlModes;  // SET_MOTION_CONTROL_MODE arguments
  std::optional<double> spindleSpeed;
  bool spindleOnBeforeFirstCut = false;
  bool spindleStoppedAfterLastCut = false;
  bool programEnd = false;
};

// Replays the canonical calls: positions start at the origin, as rs274's do.
Canon rebuild(const std::vector<CanonCall>& calls) {
  Canon canon;
  Vec3 position = {0, 0, 0};
  std::string plane = "CANON_PLANE_XY";
  double feedRate = 0.0;
  bool spindleOn = false;
  bool anyCut = false;
  for (const CanonCall& c : calls) {
    const auto arg = [&c](std::size_t i) { return number(c.args.at(i)); };
    if (c.name == "USE_LENGTH_UNITS") {
      if (canon.motions.empty()) canon.units = c.args.at(0);
    } else if (c.name == "SELECT_PLANE") {
      plane = c.args.at(0);
    } else if (c.name == "SET_FEED_RATE") {
      feedRate = arg(0);
    } else if (c.name == "SET_SPINDLE_SPEED") {
      canon.spindleSpeed = arg(1);
    } else if (c.name == "START_SPINDLE_CLOCKWISE") {
      spindleOn = true;
    } else if (c.name == "STOP_SPINDLE_TURNING") {
      if (anyCut && spindleOn) canon.spindleStoppedAfterLastCut = true;
      spindleOn = false;
    } else if (c.name == "SET_MOTION_CONTROL_MODE") {
      std::string mode = c.args.at(0);
      if (c.args.size() > 1) mode += " " + c.args.at(1);
      canon.controlModes.push_back(mode);
    } else if (c.name == "PROGRAM_END") {
      canon.programEnd = true;
    } else if (c.name == "STRAIGHT_TRAVERSE" || c.name == "STRAIGHT_FEED") {
      Motion m;
      m.kind = c.name == "STRAIGHT_FEED" ? Motion::Kind::feed : Motion::Kind::traverse;
      m.start = position;
      m.end = {arg(0), arg(1), arg(2)};
      m.feedRate = feedRate;
      m.text = c.text;
      if (m.kind == Motion::Kind::feed) {
        if (!anyCut) canon.spindleOnBeforeFirstCut = spindleOn;
        anyCut = true;
        canon.spindleStoppedAfterLastCut = false;
      }
      position = m.end;
      canon.motions.push_back(m);
    } else if (c.name == "ARC_FEED") {
      // (first, second, normal) axes of the canonical plane, normal = first x second.
      std::array<int, 3> axes = {0, 1, 2};
      if (plane == "CANON_PLANE_XZ") axes = {2, 0, 1};
      if (plane == "CANON_PLANE_YZ") axes = {1, 2, 0};
      std::array<double, 3> end = {position.x, position.y, position.z};
      std::array<double, 3> centre = end;
      end[static_cast<std::size_t>(axes[0])] = arg(0);
      end[static_cast<std::size_t>(axes[1])] = arg(1);
      end[static_cast<std::size_t>(axes[2])] = arg(5);
      centre[static_cast<std::size_t>(axes[0])] = arg(2);
      centre[static_cast<std::size_t>(axes[1])] = arg(3);
      const int rotation = std::stoi(c.args.at(4));
      std::array<double, 3> normal = {0, 0, 0};
      normal[static_cast<std::size_t>(axes[2])] = rotation > 0 ? 1.0 : -1.0;
      Motion m;
      m.kind = Motion::Kind::arc;
      m.start = position;
      m.end = {end[0], end[1], end[2]};
      m.centre = {centre[0], centre[1], centre[2]};
      m.axis = {normal[0], normal[1], normal[2]};
      const Vec3 along = m.axis;
      const auto inPlane = [&along](Vec3 v) { return v - dot(v, along) * along; };
      m.sweep = sweepAbout(inPlane(m.start - m.centre), inPlane(m.end - m.centre), m.axis) +
                2.0 * kPi * (std::abs(rotation) - 1);
      m.feedRate = feedRate;
      m.text = c.text;
      if (!anyCut) canon.spindleOnBeforeFirstCut = spindleOn;
      anyCut = true;
      canon.spindleStoppedAfterLastCut = false;
      position = m.end;
      canon.motions.push_back(m);
    }
  }
  return canon;
}

// The cutting motions the program must make, from the ToolPath and the documented links:
// the plunge from the safe height above a pass start after a retract (at the plunge feed),
// or a feed from the previous pass's end; then every move, on the tips.
std::vector<Motion> expectedCuts(const ToolPath& path, const GcodeOptions& options) {
  std::vector<Motion> cuts;
  const double r = path.toolRadius;
  Vec3 previous;
  for (std::size_t p = 0; p < path.passes.size(); ++p) {
    const ToolPass& pass = path.passes[p];
    const Vec3 start = tipOf(pass.start, r);
    Motion link;
    link.kind = Motion::Kind::feed;
    link.end = start;
    if (p == 0 || pass.retractBefore) {
      // From the safe height, or from d above the start after a local retract.
      link.start = {start.x, start.y,
                    pass.retract ? start.z + pass.retract->plunge : options.safeHeight};
      link.feedRate = options.plungeFeedRate;
      // A plunge that rounds to nothing (d < q / 2) is left out, as every zero-length move.
      const double scale = path.units == Units::inch ? 1e5 : 1e4;  // 1 / q, as the writer's
      if (std::llround(link.start.z * scale) == std::llround(start.z * scale)) {
        link.kind = Motion::Kind::traverse;
      }
    } else {
      link.start = previous;
      link.feedRate = options.feedRate;
      // A feed that rounds to nothing (a pass starting where the last ended) is left out.
      const double scale = path.units == Units::inch ? 1e5 : 1e4;
      const auto same = [&](double a, double b) { return std::llround(a * scale) == std::llround(b * scale); };
      if (same(link.start.x, start.x) && same(link.start.y, start.y) && same(link.start.z, start.z))
        link.kind = Motion::Kind::traverse;
    }
    if (link.kind == Motion::Kind::feed) cuts.push_back(link);
    Vec3 current = start;
    for (const ToolMove& move : pass.moves) {
      Motion m;
      m.start = current;
      m.end = tipOf(move.end, r);
      m.feedRate = options.feedRate;
      if (move.kind == MoveKind::arc) {
        m.kind = Motion::Kind::arc;
        m.centre = tipOf(move.center, r);
        m.axis = (move.clockwise ? -1.0 : 1.0) * planeNormal(move.plane);
        m.sweep = sweepAbout(m.start - m.centre, m.end - m.centre, m.axis);
        // As documented: an arc of at most a half turn whose sagitta is within half a
        // quantum of its chord is written as a line.
        const double sagitta = norm(m.start - m.centre) * (1.0 - std::cos(0.5 * m.sweep));
        if (m.sweep <= kPi && sagitta <= 0.5 * quantum(path.units)) m.kind = Motion::Kind::feed;
      }
      cuts.push_back(m);
      current = m.end;
    }
    previous = current;
  }
  return cuts;
}

std::string describe(Vec3 v) {
  std::ostringstream out;
  out.precision(8);
  out << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return out.str();
}

double distance(Vec3 a, Vec3 b) {
  return std::max({std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)});
}

// Runs the program through rs274 and returns its canonical calls, failing the test on any
// error the interpreter reports.
std::vector<CanonCall> interpret(const std::string& program) {
  const std::string rs274 = findRs274();
  if (rs274.empty()) {
    ADD_FAILURE() << "LinuxCNC's rs274 interpreter was not found (neither at the configured "
                     "path '" SCALLOP_RS274_PATH "' nor on PATH): install it with "
                     "`apt-get install --no-install-recommends linuxcnc-uspace` (tools/setup.sh "
                     "test does)";
    return {};
  }
  const Rs274Run run = runRs274(rs274, program);
  EXPECT_EQ(run.exitCode, 0) << "rs274 failed:\n" << run.err << "\nprogram:\n" << program;
  for (const std::string& line : lines(run.err)) {
    EXPECT_TRUE(line.empty() || line == "executing") << "rs274 reported: " << run.err;
  }
  std::vector<std::string> unexpected;
  std::vector<CanonCall> calls = parseCanon(run.out, unexpected);
  EXPECT_TRUE(unexpected.empty()) << "rs274 printed: " << unexpected.front();
  return calls;
}

// Checks the program against LinuxCNC: accepted; units; spindle; the cutting motions one to
// one with the ToolPath within the read-back tolerance; rapid moves only straight up (to the
// safe height or a local retract's height), across at one of those heights, or straight down
// to where a plunge starts (d above a pass start after a local retract); the program ending
// at the safe height.
void expectInterpretedAs(const std::string& program, const ToolPath& path,
                         const GcodeOptions& options) {
  const std::vector<CanonCall> calls = interpret(program);
  ASSERT_FALSE(calls.empty());
  const Canon canon = rebuild(calls);
  EXPECT_EQ(canon.units, path.units == Units::inch ? "CANON_UNITS_INCHES" : "CANON_UNITS_MM");
  EXPECT_TRUE(canon.programEnd);
  if (options.spindleRpm > 0.0) {
    ASSERT_TRUE(canon.spindleSpeed.has_value());
    EXPECT_NEAR(*canon.spindleSpeed, options.spindleRpm, 1e-4);
    EXPECT_TRUE(canon.spindleOnBeforeFirstCut);
    EXPECT_TRUE(canon.spindleStoppedAfterLastCut);
  } else {
    EXPECT_FALSE(canon.spindleOnBeforeFirstCut);
  }
  if (options.dialect == GcodeDialect::linuxcnc) {
    ASSERT_FALSE(canon.controlModes.empty());
    if (options.blendTolerance > 0.0) {
      const std::string mode = canon.controlModes.front();
      EXPECT_EQ(mode.rfind("CANON_CONTINUOUS ", 0), 0u) << mode;
      EXPECT_NEAR(number(mode.substr(17)), options.blendTolerance, 1e-6);
    } else {
      EXPECT_EQ(canon.controlModes.front(), "CANON_EXACT_PATH");
    }
  } else {
    EXPECT_TRUE(canon.controlModes.empty());
  }

  const double tol = readBackTolerance(path.units);
  const double safe = options.safeHeight;
  // Tip heights a rapid may rise to and cross at, and points a rapid may descend to.
  std::vector<double> levels{safe};
  std::vector<Vec3> plungeStarts;
  for (std::size_t p = 0; p < path.passes.size(); ++p) {
    const ToolPass& pass = path.passes[p];
    if (!pass.retract || !(p == 0 || pass.retractBefore)) continue;
    if (p > 0) levels.push_back(pass.retract->height - path.toolRadius);
    const Vec3 tip = tipOf(pass.start, path.toolRadius);
    plungeStarts.push_back({tip.x, tip.y, tip.z + pass.retract->plunge});
  }
  const auto isLevel = [&](double z) {
    return std::any_of(levels.begin(), levels.end(),
                       [&](double level) { return std::fabs(z - level) <= tol; });
  };
  std::vector<Motion> cuts;
  bool firstTraverse = true;
  for (const Motion& m : canon.motions) {
    if (m.kind != Motion::Kind::traverse) {
      cuts.push_back(m);
      continue;
    }
    // The first rapid starts from rs274's arbitrary initial position (the origin).
    const bool fromKnownPosition = !firstTraverse;
    firstTraverse = false;
    const bool vertical = distance(Vec3{m.start.x, m.start.y, 0}, Vec3{m.end.x, m.end.y, 0}) <= tol;
    if (!fromKnownPosition) {
      EXPECT_NEAR(m.end.z, safe, tol) << m.text;
      continue;
    }
    if (!vertical) {
      EXPECT_TRUE(std::fabs(m.start.z - m.end.z) <= tol && isLevel(m.start.z))
          << "rapid across, not at the safe height or a retract's: " << m.text;
    } else if (m.end.z < m.start.z - tol) {
      EXPECT_TRUE(std::any_of(plungeStarts.begin(), plungeStarts.end(),
                              [&](Vec3 p) { return distance(p, m.end) <= tol; }))
          << "rapid downwards, not to a plunge's start: " << m.text;
    } else {
      EXPECT_TRUE(isLevel(m.end.z)) << "rapid up, not to the safe height or a retract's: "
                                    << m.text;
    }
  }
  ASSERT_FALSE(canon.motions.empty());
  EXPECT_EQ(canon.motions.back().kind, Motion::Kind::traverse);
  EXPECT_NEAR(canon.motions.back().end.z, safe, tol);

  const std::vector<Motion> expected = expectedCuts(path, options);
  ASSERT_EQ(cuts.size(), expected.size());
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    const Motion& got = cuts[i];
    const Motion& want = expected[i];
    const std::string where = "cut " + std::to_string(i) + ": " + got.text;
    ASSERT_EQ(got.kind, want.kind) << where;
    EXPECT_LE(distance(got.start, want.start), tol)
        << where << " starts at " << describe(got.start) << ", expected " << describe(want.start);
    EXPECT_LE(distance(got.end, want.end), tol)
        << where << " ends at " << describe(got.end) << ", expected " << describe(want.end);
    EXPECT_NEAR(got.feedRate, want.feedRate, 1e-4 + quantum(path.units)) << where;
    if (want.kind == Motion::Kind::arc) {
      EXPECT_LE(distance(got.centre, want.centre), tol)
          << where << " centre " << describe(got.centre) << ", expected " << describe(want.centre);
      EXPECT_EQ(got.axis, want.axis)
          << where << " turns about " << describe(got.axis) << ", expected " << describe(want.axis);
      const double radius = norm(want.start - want.centre);
      EXPECT_NEAR(got.sweep, want.sweep, 6.0 * tol / radius + 1e-9) << where;
      // The arc's midpoint, by Rodrigues about the expected axis: the direction check that
      // does not depend on how sweeps are measured.
      const Vec3 gotMiddle = got.centre + rotate(got.start - got.centre, got.axis, 0.5 * got.sweep);
      const Vec3 wantMiddle =
          want.centre + rotate(want.start - want.centre, want.axis, 0.5 * want.sweep);
      EXPECT_LE(distance(gotMiddle, wantMiddle), 6.0 * tol) << where;
    }
  }

  // The cycle time's lengths (gcodeMotion) against the interpreter's own motions: every
  // traverse but the first two (from rs274's arbitrary start up to the safe height, and across
  // to the first pass), the feeds at the plunge rate, and the other feeds (arcs as r x sweep
  // with the change along the axis). Each printed point is within q / 2 per axis of the true
  // one, so each length within 2 q of its true value; tiny arcs written as polygons and flat
  // ones as chords differ from the arc by less than that.
  double rapid = 0.0, plunge = 0.0, feed = 0.0;
  std::size_t traverses = 0;
  for (const Motion& m : canon.motions) {
    if (m.kind == Motion::Kind::traverse) {
      if (++traverses > 2) rapid += norm(m.end - m.start);
      continue;
    }
    double length = norm(m.end - m.start);
    if (m.kind == Motion::Kind::arc) {
      const Vec3 s = m.start - m.centre;
      const double radius = norm(s - dot(s, m.axis) * m.axis);
      length = std::hypot(radius * m.sweep, dot(m.end - m.start, m.axis));
    }
    (std::fabs(m.feedRate - options.plungeFeedRate) < 1e-9 ? plunge : feed) += length;
  }
  const GcodeMotion motion = gcodeMotion(path, options, 100.0);
  const double slack = 2.0 * quantum(path.units) * static_cast<double>(canon.motions.size()) + 1e-9;
  EXPECT_NEAR(motion.rapidLength, rapid, slack);
  EXPECT_NEAR(motion.plungeLength, plunge, slack);
  EXPECT_NEAR(motion.feedLength, feed, slack);
}

// ---------------------------------------------------------------------------------------
// The program text
// ---------------------------------------------------------------------------------------

struct Word {
  char letter = 0;
  std::string value;
};

// The words of a block, its comment removed; fails the test on a malformed block.
std::vector<Word> words(const std::string& block) {
  std::string code;
  int depth = 0;
  for (const char c : block) {
    if (c == '(') {
      EXPECT_EQ(depth, 0) << "nested comment: " << block;
      ++depth;
    } else if (c == ')') {
      --depth;
    } else if (depth == 0) {
      code += c;
    }
  }
  EXPECT_EQ(depth, 0) << block;
  static const std::regex word(R"(([A-Z])(-?[0-9]+(\.[0-9]+)?))");
  std::vector<Word> out;
  std::stringstream in(code);
  std::string token;
  while (in >> token) {
    std::smatch match;
    if (!std::regex_match(token, match, word)) {
      ADD_FAILURE() << "malformed word '" << token << "' in: " << block;
      continue;
    }
    out.push_back({match[1].str()[0], match[2].str()});
  }
  return out;
}

void expectWellFormed(const std::string& program, Units units, GcodeDialect dialect) {
  const int decimals = units == Units::inch ? 5 : 4;
  const std::regex coordinate("-?(0|[1-9][0-9]*)\\.[0-9]{" + std::to_string(decimals) + "}");
  const std::regex rate(R"((0|[1-9][0-9]*)(\.[0-9]*[1-9])?)");
  // grbl 1.1's G- and M-codes (gcode.c); these programs need only the plain ones.
  const std::set<std::string> grblG = {"0",  "1",  "2",  "3",  "4",  "10", "17", "18", "19",
                                       "20", "21", "28", "30", "40", "43.1", "49", "53", "54",
                                       "55", "56", "57", "58", "59", "61", "80", "90", "91",
                                       "91.1", "92", "93", "94"};
  const std::set<std::string> grblM = {"0", "1", "2", "3", "4", "5", "7", "8", "9", "30"};
  EXPECT_FALSE(program.empty());
  EXPECT_EQ(program.back(), '\n');
  EXPECT_EQ(program.find('%'), std::string::npos);
  EXPECT_EQ(program.find('\r'), std::string::npos);
  for (const std::string& block : lines(program)) {
    EXPECT_LT(block.size(), 80u) << block;
    for (const char c : block) {
      EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "byte " << static_cast<int>(c) << " in " << block;
    }
    for (const Word& w : words(block)) {
      const std::string text = std::string(1, w.letter) + w.value;
      EXPECT_EQ(w.value.find_first_of("eE"), std::string::npos) << text;
      EXPECT_NE(w.letter, 'O') << block;
      EXPECT_NE(w.letter, 'N') << block;
      if (std::string("XYZIJK").find(w.letter) != std::string::npos) {
        EXPECT_TRUE(std::regex_match(w.value, coordinate)) << text << " in " << block;
        EXPECT_FALSE(w.value[0] == '-' && w.value.find_first_not_of("-0.") == std::string::npos)
            << "negative zero: " << block;
      } else if (w.letter == 'F' || w.letter == 'S' || w.letter == 'P') {
        EXPECT_TRUE(std::regex_match(w.value, rate)) << text << " in " << block;
        EXPECT_GT(number(w.value), 0.0) << block;
      } else if (w.letter == 'G' || w.letter == 'M') {
        if (dialect == GcodeDialect::grbl) {
          EXPECT_TRUE((w.letter == 'G' ? grblG : grblM).count(w.value)) << text << ": not grbl";
        }
      } else {
        ADD_FAILURE() << "unexpected word " << text << " in " << block;
      }
      if (dialect == GcodeDialect::grbl) {
        EXPECT_FALSE(w.letter == 'G' && (w.value == "64" || w.value == "61")) << block;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Writer unit tests
// ---------------------------------------------------------------------------------------

TEST(GcodeFormat, WellFormedInBothUnitsAndDialects) {
  for (const Units units : {Units::inch, Units::millimetre}) {
    for (const GcodeDialect dialect : {GcodeDialect::linuxcnc, GcodeDialect::grbl}) {
      const ToolPath path = units == Units::inch ? arcsPath() : scaled(arcsPath(), 25.4, units);
      const std::string program = gcodeProgram(path, optionsFor(path, dialect));
      SCOPED_TRACE(program);
      expectWellFormed(program, units, dialect);
    }
  }
}

TEST(GcodeFormat, HeaderStatesTitleUnitsRadiusAndTip) {
  ToolPath path = linesPath();
  GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  options.title = "hull (figure 2)\nsecond line";
  const std::string inch = gcodeProgram(path, options);
  const std::vector<std::string> blocks = lines(inch);
  ASSERT_GE(blocks.size(), 5u);
  EXPECT_EQ(blocks[0], "(scallop tool path: hull [figure 2] second line)");
  EXPECT_NE(inch.find("inch"), std::string::npos);
  EXPECT_NE(inch.find("radius 0.12500"), std::string::npos);
  EXPECT_NE(inch.find("ball tip"), std::string::npos);
  EXPECT_NE(std::find(blocks.begin(), blocks.end(), "G20"), blocks.end());
  EXPECT_EQ(std::find(blocks.begin(), blocks.end(), "G21"), blocks.end());
  EXPECT_NE(std::find(blocks.begin(), blocks.end(), "G61"), blocks.end());

  const ToolPath mmPath = scaled(path, 25.4, Units::millimetre);
  GcodeOptions mmOptions = optionsFor(mmPath, GcodeDialect::linuxcnc);
  mmOptions.blendTolerance = 0.01;
  const std::string mm = gcodeProgram(mmPath, mmOptions);
  const std::vector<std::string> mmBlocks = lines(mm);
  EXPECT_NE(mm.find("radius 3.1750"), std::string::npos);
  EXPECT_NE(std::find(mmBlocks.begin(), mmBlocks.end(), "G21"), mmBlocks.end());
  EXPECT_NE(std::find(mmBlocks.begin(), mmBlocks.end(), "G64 P0.01"), mmBlocks.end());

  // A long title is cut to fit the line; no parenthesis or control character survives.
  options.title = std::string(200, 'x') + "(MSG, hi)\t\x01\xc3\xa9";
  const std::string longTitle = gcodeProgram(path, options);
  EXPECT_LT(lines(longTitle)[0].size(), 80u);
  options.title = "(MSG, hi)\t\x01\xc3\xa9";
  EXPECT_EQ(lines(gcodeProgram(path, options))[0], "(scallop tool path: [MSG, hi]  ?\?)");
}

TEST(GcodeFormat, NoSpindleWordsWhenRpmIsZero) {
  const ToolPath path = linesPath();
  GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  options.spindleRpm = 0.0;
  const std::string program = gcodeProgram(path, options);
  for (const std::string& block : lines(program)) {
    for (const Word& w : words(block)) {
      EXPECT_FALSE(w.letter == 'S') << block;
      EXPECT_FALSE(w.letter == 'M' && (w.value == "3" || w.value == "5")) << block;
    }
  }
  expectInterpretedAs(program, path, options);
}

TEST(GcodeFormat, Deterministic) {
  const ToolPath path = randomPath(7, 5, 40);
  const GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  EXPECT_EQ(gcodeProgram(path, options), gcodeProgram(path, options));
}

TEST(GcodeFormat, RoundsToTheGridWithoutNegativeZero) {
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.0;
  ToolPass pass;
  pass.start = {-1e-9, -4e-6, 0.0};
  pass.moves = {lineTo({1.5, -2.25, -6e-6}), lineTo({0.0, 2.0 / 3.0, 0.0})};
  path.passes.push_back(pass);
  GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  options.safeHeight = 1.0;
  const std::string program = gcodeProgram(path, options);
  EXPECT_EQ(program.find("-0.00000"), std::string::npos) << program;
  EXPECT_NE(program.find("G0 X0.00000 Y0.00000"), std::string::npos) << program;
  EXPECT_NE(program.find("G1 X1.50000 Y-2.25000 Z-0.00001"), std::string::npos) << program;
  EXPECT_NE(program.find("Y0.66667"), std::string::npos) << program;
  expectWellFormed(program, Units::inch, GcodeDialect::linuxcnc);
}

TEST(GcodeFormat, ZeroLengthMovesAreLeftOut) {
  ToolPath path;
  path.units = Units::millimetre;
  path.toolRadius = 1.0;
  ToolPass pass;
  pass.start = {0, 0, 0};
  pass.moves = {lineTo({0, 0, 0}), lineTo({1, 0, 0}), lineTo({1 + 1e-6, 0, 0}),
                lineTo({2, 0, 0})};
  path.passes.push_back(pass);
  ToolPass direct;  // starts where the previous pass ended: no link move
  direct.retractBefore = false;
  direct.start = {2, 0, 0};
  direct.moves = {lineTo({3, 0, 0})};
  path.passes.push_back(direct);
  const GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  const std::string program = gcodeProgram(path, options);
  int feeds = 0;
  for (const std::string& block : lines(program)) feeds += block.rfind("G1", 0) == 0 ? 1 : 0;
  EXPECT_EQ(feeds, 4) << program;  // plunge, x = 1, x = 2, x = 3
  const std::vector<CanonCall> calls = interpret(program);
  const Canon canon = rebuild(calls);
  int canonFeeds = 0;
  for (const Motion& m : canon.motions) canonFeeds += m.kind == Motion::Kind::feed ? 1 : 0;
  EXPECT_EQ(canonFeeds, 4);
}

// ---------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------

void expectError(const ToolPath& path, const GcodeOptions& options,
                 const std::vector<std::string>& fragments) {
  try {
    (void)gcodeProgram(path, options);
    ADD_FAILURE() << "no error; expected one mentioning " << fragments.front();
  } catch (const Error& e) {
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
          << "'" << e.what() << "' does not mention '" << fragment << "'";
    }
  }
}

TEST(GcodeValidation, BadOptionsNameTheOptionAndValue) {
  const ToolPath path = linesPath();
  const GcodeOptions good = optionsFor(path, GcodeDialect::linuxcnc);
  EXPECT_NO_THROW((void)gcodeProgram(path, good));
  auto with = [&good](auto change) {
    GcodeOptions options = good;
    change(options);
    return options;
  };
  expectError(path, with([](GcodeOptions& o) { o.feedRate = 0.0; }), {"feedRate", "0"});
  expectError(path, with([](GcodeOptions& o) { o.feedRate = -5.0; }), {"feedRate", "-5"});
  expectError(path, with([](GcodeOptions& o) { o.feedRate = kNaN; }), {"feedRate", "nan"});
  expectError(path, with([](GcodeOptions& o) { o.plungeFeedRate = kInf; }),
              {"plungeFeedRate", "inf"});
  expectError(path, with([](GcodeOptions& o) { o.plungeFeedRate = 1e-9; }),
              {"plungeFeedRate", "1e-09"});
  expectError(path, with([](GcodeOptions& o) { o.spindleRpm = -100.0; }),
              {"spindleRpm", "-100"});
  expectError(path, with([](GcodeOptions& o) { o.spindleRpm = kNaN; }), {"spindleRpm", "nan"});
  expectError(path, with([](GcodeOptions& o) { o.safeHeight = kNaN; }), {"safeHeight", "nan"});
  expectError(path, with([](GcodeOptions& o) { o.blendTolerance = -0.001; }),
              {"blendTolerance", "-0.001"});
  expectError(path, with([](GcodeOptions& o) { o.dialect = static_cast<GcodeDialect>(7); }),
              {"dialect", "7"});
  // The highest tip of linesPath is 0.5 - 0.125 at pass 0's start.
  expectError(path, with([](GcodeOptions& o) { o.safeHeight = 0.375; }),
              {"safeHeight", "0.375", "highest tool tip", "pass 0"});
  EXPECT_NO_THROW((void)gcodeProgram(path, with([](GcodeOptions& o) { o.safeHeight = 0.376; })));
  // Defaults must be set.
  expectError(path, GcodeOptions{}, {"safeHeight", "nan"});
}

TEST(GcodeValidation, LocalRetractsMustRiseAndStayBelowTheSafeHeight) {
  // linesPath: passes at y = 0, 0.1, 0.2, each from z = 0.5 to 0.5 (centres), R = 0.125.
  ToolPath path = linesPath();
  path.passes[1].retract = LocalRetract{0.6, 0.05};
  const GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  EXPECT_NO_THROW((void)gcodeProgram(path, options));
  ToolPath low = path;
  low.passes[1].retract = LocalRetract{0.49, 0.0};  // below the previous end (and the start)
  expectError(low, options, {"pass 1, retract", "0.49"});
  ToolPath deep = path;
  deep.passes[1].retract = LocalRetract{0.6, 0.2};  // d > h - start z = 0.1
  expectError(deep, options, {"pass 1, retract", "plunge d = 0.2"});
  ToolPath negative = path;
  negative.passes[1].retract = LocalRetract{0.6, -0.01};
  expectError(negative, options, {"pass 1, retract", "-0.01"});
  ToolPath unlinked = path;
  unlinked.passes[1].retractBefore = false;
  expectError(unlinked, options, {"pass 1, retract", "without retractBefore"});
  ToolPath high = path;
  high.passes[2].retract = LocalRetract{options.safeHeight + 0.125 + 0.01, 0.0};
  expectError(high, options, {"safeHeight", "pass 2, retract height"});
  ToolPath notFinite = path;
  notFinite.passes[1].retract = LocalRetract{kNaN, 0.0};
  expectError(notFinite, options, {"pass 1, retract", "nan"});
}

// The cycle time of a path whose every length is worked out by hand (inch, R = 0.25, tips
// = centres - 0.25, safe height 2, feeds 40 and 10, rapid 200 units per minute):
//   pass 0 (first): rapid from the safe height not counted across; plunge at feed from the
//     safe height 2 to its start's tip z = 0: plunge 2; line (0,0,0) -> (3,4,0): feed 5;
//   pass 1, local retract h = 0.75 (tip 0.5), d = 0.1, start tip (3,0,0): rapid up 0.5,
//     across |(3,4) - (3,0)| = 4, down 0.5 - 0.1 = 0.4; plunge 0.1; a counter-clockwise
//     half turn in xy about (3,1,0) of radius 1 to (3,2,0): feed pi;
//   pass 2, fed straight (retractBefore false) from (3,2,0) to (0,2,0): feed 3; a line up
//     to (0,2,0.5): feed 0.5;
//   pass 3, safe-height retract: rapid up 2 - 0.5 = 1.5, across to (1,2): 1; plunge 2;
//     a line to (1,3,0): feed 1;
//   the end: rapid up 2.
// feed 5 + pi + 3 + 0.5 + 1 = 9.5 + pi, plunge 2 + 0.1 + 2 = 4.1,
// rapid 0.5 + 4 + 0.4 + 1.5 + 1 + 2 = 9.4.
ToolPath handWorkedPath() {
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.25;
  const double r = 0.25;
  ToolPass p0;
  p0.start = {0, 0, r};
  p0.moves = {lineTo({3, 4, r})};
  ToolPass p1;
  p1.start = {3, 0, r};
  p1.retract = LocalRetract{0.75, 0.1};
  p1.moves = {arcFrom({3, 0, r}, {3, 1, r}, ArcPlane::xy, false, kPi)};
  ToolPass p2;
  p2.retractBefore = false;
  p2.start = {0, 2, r};
  p2.moves = {lineTo({0, 2, 0.5 + r})};
  ToolPass p3;
  p3.start = {1, 2, r};
  p3.moves = {lineTo({1, 3, r})};
  path.passes = {p0, p1, p2, p3};
  return path;
}

GcodeOptions handWorkedOptions() {
  GcodeOptions options;
  options.safeHeight = 2.0;
  options.feedRate = 40.0;
  options.plungeFeedRate = 10.0;
  options.spindleRpm = 0.0;
  return options;
}

TEST(GcodeMotion, HandWorkedLengthsAndMinutes) {
  const GcodeMotion m = gcodeMotion(handWorkedPath(), handWorkedOptions(), 200.0);
  EXPECT_NEAR(m.feedLength, 9.5 + kPi, 1e-12);
  EXPECT_NEAR(m.plungeLength, 4.1, 1e-12);
  EXPECT_NEAR(m.rapidLength, 9.4, 1e-12);
  EXPECT_NEAR(m.feedMinutes, (9.5 + kPi) / 40.0, 1e-12);
  EXPECT_NEAR(m.plungeMinutes, 0.41, 1e-12);
  EXPECT_NEAR(m.rapidMinutes, 0.047, 1e-12);
  EXPECT_NEAR(m.minutes, (9.5 + kPi) / 40.0 + 0.41 + 0.047, 1e-12);
}

TEST(GcodeMotion, FirstPassLocalPlungeAndHelicalArc) {
  // One pass with a plunge of d = 0.3 only: rapid down 2 - 0.3 (tip start z = 0), plunge 0.3;
  // then a quarter turn in zx of radius 1 that also moves 0.5 along y (a helix within
  // G18, allowed only within 10 quanta: here checked on gcodeMotion's arithmetic alone, so
  // the mismatch check is not reached by using a y change of 5e-5 = 5 q):
  // feed sqrt((pi / 2)^2 + (5e-5)^2); then the final rise from the arc's end to 2.
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.25;
  ToolPass pass;
  pass.start = {0, 0, 0.25};
  pass.retract = LocalRetract{0.55, 0.3};
  ToolMove arc = arcFrom({0, 0, 0.25}, {1, 0, 0.25}, ArcPlane::zx, true, 0.5 * kPi);
  arc.end.y += 5e-5;
  pass.moves = {arc};
  path.passes = {pass};
  const GcodeMotion m = gcodeMotion(path, handWorkedOptions(), 100.0);
  // Which way the arc turns (up or down) decides the final rise: compute its end tip z.
  const double endTip = arc.end.z - 0.25;
  EXPECT_NEAR(m.rapidLength, 1.7 + (2.0 - endTip), 1e-12);
  EXPECT_NEAR(m.plungeLength, 0.3, 1e-12);
  EXPECT_NEAR(m.feedLength, std::hypot(0.5 * kPi, 5e-5), 1e-12);
  EXPECT_NEAR(m.minutes, m.feedLength / 40.0 + 0.03 + m.rapidLength / 100.0, 1e-12);
}

TEST(GcodeMotion, ValidatesTheRapidRate) {
  try {
    (void)gcodeMotion(handWorkedPath(), handWorkedOptions(), 0.0);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("rapidRate"), std::string::npos) << e.what();
  }
}

TEST(GcodeValidation, SafeHeightMustClearTheTopOfVerticalArcs) {
  // A half turn in G18 (G19) from x (y) = 0 to 2 about x (y) = 1, z = 0: the ends are at
  // z = 0, the middle at z = +1 or -1 depending on the direction (tips: 0.1 lower). Which
  // one is computed here by Rodrigues' formula, not assumed.
  for (const ArcPlane plane : {ArcPlane::zx, ArcPlane::yz}) {
    ToolPath path;
    path.toolRadius = 0.1;
    ToolPass pass;
    pass.start = {0, 0, 0};
    const Vec3 centre = plane == ArcPlane::zx ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    int overTheTop = 0;
    for (const bool clockwise : {true, false}) {
      pass.moves = {arcFrom(pass.start, centre, plane, clockwise, kPi)};
      path.passes = {pass};
      const Vec3 middle =
          centre + rotate(pass.start - centre,
                          (clockwise ? -1.0 : 1.0) * planeNormal(plane), 0.5 * kPi);
      GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
      options.safeHeight = 0.5;  // above both ends' tips (-0.1), below the top's if it is up
      if (middle.z > 0.5) {
        ++overTheTop;
        expectError(path, options, {"safeHeight", "0.5", "pass 0, move 0 (top of the arc)"});
      } else {
        EXPECT_NO_THROW((void)gcodeProgram(path, options));
      }
    }
    EXPECT_EQ(overTheTop, 1);
  }
}

TEST(GcodeValidation, BadPathsNameThePassAndMove) {
  const ToolPath good = arcsPath();
  const GcodeOptions options = optionsFor(good, GcodeDialect::linuxcnc);
  {
    ToolPath path = good;
    path.passes[1].moves[2].end.y = kNaN;
    expectError(path, options, {"pass 1, move 2", "end.y", "nan"});
  }
  {
    ToolPath path = good;
    path.passes[2].moves[0].center.z = kInf;
    expectError(path, options, {"pass 2, move 0", "center.z", "inf"});
  }
  {
    ToolPath path = good;
    path.passes[3].start.x = -kInf;
    expectError(path, options, {"pass 3, start", "start.x", "-inf"});
  }
  {
    ToolPath path = good;
    path.passes[0].moves[1].end.x = 2e5;
    expectError(path, options, {"pass 0, move 1", "end.x", "too large"});
  }
  {
    ToolPath path = good;  // pass 0 move 0 is a G17 arc: its end moved off the circle
    path.passes[0].moves[0].end.x += 0.01;
    expectError(path, options, {"pass 0, move 0", "radius"});
  }
  {
    ToolPath path = good;  // a G17 arc whose end leaves the plane z = const
    path.passes[0].moves[0].end.z += 0.01;
    expectError(path, options, {"pass 0, move 0", "G17"});
  }
  {
    ToolPath path = good;  // a full circle
    path.passes[0].moves[0].end = path.passes[0].start;
    expectError(path, options, {"pass 0, move 0", "full circle"});
  }
  {
    ToolPath path = good;
    path.toolRadius = -1.0;
    expectError(path, options, {"toolRadius", "-1"});
  }
  {
    ToolPath path = good;
    path.passes[0].moves[0].plane = static_cast<ArcPlane>(9);
    expectError(path, options, {"pass 0, move 0", "plane"});
  }
}

// ---------------------------------------------------------------------------------------
// arcPolyline
// ---------------------------------------------------------------------------------------

// A random unit vector.
Vec3 randomDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Vec3 v;
  do {
    v = {gauss(rng), gauss(rng), gauss(rng)};
  } while (norm(v) < 1e-3);
  return normalized(v);
}

// Distance from c to the segment [a, b].
double distanceToSegment(Vec3 c, Vec3 a, Vec3 b) {
  const Vec3 d = b - a;
  const double length2 = dot(d, d);
  const double t = length2 > 0.0 ? std::clamp(dot(c - a, d) / length2, 0.0, 1.0) : 0.0;
  return norm(a + t * d - c);
}

TEST(GcodeArcPolyline, CircumscribesRandomArcsWithinTolerance) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t totalSegments = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const double radius = std::pow(10.0, -3.0 + 6.0 * unit(rng));
    const double tolerance = radius * std::pow(10.0, -6.0 + 6.5 * unit(rng));
    const double sweep =
        trial % 50 == 0 ? 2.0 * kPi : 2.0 * kPi * (1e-4 + (1.0 - 1e-4) * unit(rng));
    const Vec3 axis = randomDirection(rng);
    Vec3 u = cross(axis, randomDirection(rng));
    u = normalized(u);
    // (One draw per statement: the order of operands is unspecified, the test's is fixed.)
    const Vec3 direction = {unit(rng), unit(rng), unit(rng)};
    const Vec3 centre = direction * (100.0 * unit(rng) - 50.0);
    const Vec3 start = centre + radius * u;
    const Vec3 end = sweep == 2.0 * kPi ? start : centre + rotate(radius * u, axis, sweep);
    const std::vector<Vec3> poly = arcPolyline(start, end, centre, axis, tolerance);
    ASSERT_GE(poly.size(), 3u);
    const std::string where = "trial " + std::to_string(trial);
    EXPECT_EQ(poly.front(), start) << where;
    EXPECT_EQ(poly.back(), end) << where;
    totalSegments += poly.size() - 1;
    // Rounding slack: coordinates of size |centre| + r, 1e-12 relative.
    const double slack = 1e-12 * (norm(centre) + radius) + 1e-12 * radius;
    double previousAngle = 0.0;
    for (std::size_t i = 0; i + 1 < poly.size(); ++i) {
      // Never inside the circle: every edge keeps its distance from the centre >= r. In
      // the plane (all points are), the distance to the segment is the planar one.
      EXPECT_GE(distanceToSegment(centre, poly[i], poly[i + 1]), radius - slack)
          << where << ", edge " << i;
      // Never farther than the tolerance: the vertices are the farthest points of edges.
      EXPECT_LE(norm(poly[i + 1] - centre), radius + tolerance + slack) << where;
      EXPECT_NEAR(dot(poly[i + 1] - centre, axis), 0.0, slack) << where;
      if (i + 2 < poly.size()) {
        // Interior vertices progress counter-clockwise about the axis within the sweep.
        const double angle = sweepAbout(u, poly[i + 1] - centre, axis);
        EXPECT_GT(angle, previousAngle) << where << ", vertex " << i + 1;
        EXPECT_LT(angle, sweep) << where << ", vertex " << i + 1 << " of " << poly.size()
                                << ", radius " << radius << ", tolerance " << tolerance;
        previousAngle = angle;
      }
    }
    // The fewest segments: one step fewer would exceed the tolerance.
    const auto steps = static_cast<double>(poly.size() - 2);
    if (steps >= 2.0) {
      const double coarser = sweep / (steps - 1.0);
      // (A step of pi or more leaves the tangents parallel or meeting behind the centre.)
      EXPECT_TRUE(coarser >= kPi ||
                  radius / std::cos(0.5 * coarser) - radius > tolerance * (1.0 - 1e-9))
          << where;
    }
  }
  EXPECT_GT(totalSegments, 5000u);
}

TEST(GcodeArcPolyline, RejectsBadInput) {
  const Vec3 c = {0, 0, 0};
  const Vec3 z = {0, 0, 1};
  const auto expectThrows = [](auto call, const std::string& fragment) {
    try {
      call();
      ADD_FAILURE() << "no error; expected '" << fragment << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expectThrows([&] { (void)arcPolyline({1, 0, 0}, {0, 1, 0}, c, z, 0.0); }, "tolerance");
  expectThrows([&] { (void)arcPolyline({1, 0, 0}, {0, 1, 0}, c, z, kNaN); }, "tolerance");
  expectThrows([&] { (void)arcPolyline({1, 0, 0}, {0, 1, 0}, c, {0, 0, 2}, 0.01); }, "unit");
  expectThrows([&] { (void)arcPolyline(c, {0, 1, 0}, c, z, 0.01); }, "radius 0");
  expectThrows([&] { (void)arcPolyline({1, 0, 0}, {0, 1.1, 0}, c, z, 0.01); }, "circle");
  expectThrows([&] { (void)arcPolyline({1, 0, 0}, {0, 1, 0.1}, c, z, 0.01); }, "circle");
  expectThrows([&] { (void)arcPolyline({1, 0, 0}, {0, 1, 0}, c, z, 1e-15); }, "segments");
  expectThrows([&] { (void)arcPolyline({1, 0, kNaN}, {0, 1, 0}, c, z, 0.01); }, "finite");
}

// ---------------------------------------------------------------------------------------
// Through LinuxCNC's interpreter
// ---------------------------------------------------------------------------------------

TEST(GcodeLinuxcnc, InterpreterIsInstalled) {
  EXPECT_FALSE(findRs274().empty())
      << "LinuxCNC's rs274 interpreter was not found: install it with `apt-get install "
         "--no-install-recommends linuxcnc-uspace` (tools/setup.sh test does)";
}

struct Variant {
  Units units;
  GcodeDialect dialect;
};

class GcodeLinuxcncVariants : public ::testing::TestWithParam<Variant> {
 protected:
  ToolPath inUnits(const ToolPath& inchPath) const {
    return GetParam().units == Units::inch ? inchPath
                                           : scaled(inchPath, 25.4, Units::millimetre);
  }
  void check(const ToolPath& path, double blendTolerance = 0.0) const {
    GcodeOptions options = optionsFor(path, GetParam().dialect);
    options.blendTolerance = blendTolerance;
    const std::string program = gcodeProgram(path, options);
    expectWellFormed(program, path.units, options.dialect);
    expectInterpretedAs(program, path, options);
  }
};

TEST_P(GcodeLinuxcncVariants, LinesOnly) { check(inUnits(linesPath())); }

TEST_P(GcodeLinuxcncVariants, ArcsInEveryPlaneBothDirectionsBothLinks) {
  check(inUnits(arcsPath()));
}

TEST_P(GcodeLinuxcncVariants, BlendTolerance) {
  check(inUnits(arcsPath()), GetParam().units == Units::inch ? 0.0005 : 0.0127);
}

TEST_P(GcodeLinuxcncVariants, PolygonisedObliqueArc) {
  // An arc in the plane through the y axis tilted 30 degrees from xy (a raster along an
  // oblique direction), written as its circumscribed polygon.
  ToolPath path;
  path.units = Units::inch;
  path.toolRadius = 0.125;
  const Vec3 axis = normalized(Vec3{std::sin(kPi / 6), 0.0, std::cos(kPi / 6)});
  const Vec3 centre = {1.0, 1.0, 0.5};
  const Vec3 start = centre + 0.75 * normalized(cross(axis, Vec3{1, 0, 0}));
  const Vec3 end = centre + rotate(start - centre, axis, 2.0);
  ToolPass pass;
  pass.start = start;
  for (const Vec3& v : arcPolyline(start, end, centre, axis, 0.001)) {
    if (!(v == start)) pass.moves.push_back(lineTo(v));
  }
  EXPECT_GE(pass.moves.size(), 10u);
  path.passes.push_back(pass);
  check(inUnits(path));
}

TEST_P(GcodeLinuxcncVariants, LargeRandomPath) { check(inUnits(randomPath(20240607, 60, 50))); }

TEST_P(GcodeLinuxcncVariants, HandWorkedLinks) {
  ToolPath path = handWorkedPath();
  path.passes[0].retract = LocalRetract{0.25 + 0.3, 0.3};
  check(inUnits(path));
}

// A contour path over paper-1 (horizontal planes: open and closed sections) as the linker
// relinks it: reversed passes, loops started elsewhere, direct feeds and local retracts.
TEST_P(GcodeLinuxcncVariants, LinkedContourPath) {
  const Surface surface = exampleSurface("paper-1");
  ContourOptions contour;
  contour.normal = {0, 0, 1};
  contour.spacing = 0.1;
  contour.toolRadius = 0.25;
  const LinkedPath linked = linkToolPath(surface, contourPaths(surface, contour).path);
  EXPECT_GT(linked.stats.localRetracts, 0u);
  EXPECT_GT(linked.stats.directLinks, 0u);
  check(inUnits(linked.path));
}

TEST_P(GcodeLinuxcncVariants, LocalRetracts) {
  check(inUnits(withLocalRetracts(linesPath(), 11)));
  check(inUnits(withLocalRetracts(arcsPath(), 12)));
  check(inUnits(withLocalRetracts(randomPath(20240608, 40, 20), 13)));
}

INSTANTIATE_TEST_SUITE_P(
    Gcode, GcodeLinuxcncVariants,
    ::testing::Values(Variant{Units::inch, GcodeDialect::linuxcnc},
                      Variant{Units::millimetre, GcodeDialect::linuxcnc},
                      Variant{Units::inch, GcodeDialect::grbl},
                      Variant{Units::millimetre, GcodeDialect::grbl}),
    [](const ::testing::TestParamInfo<Variant>& variant) {
      return std::string(variant.param.units == Units::inch ? "Inch" : "Mm") +
             (variant.param.dialect == GcodeDialect::linuxcnc ? "Linuxcnc" : "Grbl");
    });

// Arcs that rounding could turn into something else: the program must still be accepted
// and stay on the true arc. `sweepRead` is the total sweep of the canonical arcs (0 when
// written as lines); every canonical point must lie on the true circle within the
// read-back tolerance plus the polygon tolerance, never inside it by more than that.
struct Rebuilt {
  std::vector<Motion> cuts;
  double arcSweep = 0.0;
};

Rebuilt interpretOneArc(const ToolPath& path) {
  GcodeOptions options = optionsFor(path, GcodeDialect::linuxcnc);
  const std::string program = gcodeProgram(path, options);
  expectWellFormed(program, path.units, options.dialect);
  const Canon canon = rebuild(interpret(program));
  Rebuilt out;
  for (const Motion& m : canon.motions) {
    if (m.kind == Motion::Kind::traverse) continue;
    out.cuts.push_back(m);
    if (m.kind == Motion::Kind::arc) out.arcSweep += m.sweep;
  }
  return out;
}

ToolPath oneArcPath(Units units, Vec3 centre, double radius, bool clockwise, double sweep) {
  ToolPath path;
  path.units = units;
  path.toolRadius = 0.0;
  ToolPass pass;
  pass.start = centre + Vec3{radius, 0.0, 0.0};
  pass.moves = {arcFrom(pass.start, centre, ArcPlane::xy, clockwise, sweep),
                lineTo(centre + Vec3{0.0, 0.0, -0.5})};
  path.passes.push_back(pass);
  return path;
}

void expectOnCircle(const Rebuilt& rebuilt, Vec3 centre, double radius, double slack) {
  ASSERT_GE(rebuilt.cuts.size(), 2u);
  // Every point of the arc's part (all cuts but the plunge and the closing line).
  for (std::size_t i = 1; i + 1 < rebuilt.cuts.size(); ++i) {
    const Motion& m = rebuilt.cuts[i];
    EXPECT_NEAR(norm(m.end - centre), radius, slack) << m.text;
    if (m.kind == Motion::Kind::arc) {
      EXPECT_LE(distance(m.centre, centre), slack) << m.text;
    }
  }
}

TEST(GcodeLinuxcncDegenerate, NearlyFullCircleWhoseRoundedEndsCoincide) {
  // Sweep 2 pi - 2e-6 on radius 1: the ends are 2e-6 apart, less than a quantum in inch:
  // written as two half arcs, not as a full circle, nor as nothing.
  for (const bool clockwise : {true, false}) {
    const Vec3 centre = {0.3, 0.2, 0.0};
    const double sweep = 2.0 * kPi - 2e-6;
    const ToolPath path = oneArcPath(Units::inch, centre, 1.0, clockwise, sweep);
    const Rebuilt rebuilt = interpretOneArc(path);
    EXPECT_NEAR(rebuilt.arcSweep, sweep, 1e-3);
    expectOnCircle(rebuilt, centre, 1.0, 2.0 * readBackTolerance(Units::inch));
  }
}

TEST(GcodeLinuxcncDegenerate, ArcsWhoseRoundedEndFallsPastTheStart) {
  // Sweeps a fraction of a quantum either side of 0 and 2 pi, with the start placed so that
  // rounding can move the end to the other side of the start.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Units units = trial % 2 == 0 ? Units::inch : Units::millimetre;
    const double q = quantum(units);
    const double radius = (units == Units::inch ? 0.5 : 12.0) * (0.5 + unit(rng));
    const Vec3 centre = {0.123456789 * (trial + 1), -0.0000037 * trial, 0.0};
    const bool clockwise = trial % 4 < 2;
    const double gap = (0.2 + 1.5 * unit(rng)) * q / radius;
    const double sweep = trial % 3 == 0 ? gap : 2.0 * kPi - gap;
    const ToolPath path = oneArcPath(units, centre, radius, clockwise, sweep);
    const Rebuilt rebuilt = interpretOneArc(path);
    SCOPED_TRACE("trial " + std::to_string(trial));
    // A tiny arc is a line of at most a few quanta, or nothing; a nearly full one keeps its
    // sweep.
    if (sweep < kPi) {
      EXPECT_LT(rebuilt.arcSweep, 0.5);
    } else {
      EXPECT_NEAR(rebuilt.arcSweep, sweep, 0.5);
    }
    expectOnCircle(rebuilt, centre, radius, 2.0 * readBackTolerance(units));
  }
}

TEST(GcodeLinuxcncDegenerate, TinyRadiusArcsBecomePolylines) {
  // Radii below the zero-radius limit LinuxCNC applies (0.00005 in / 0.00127 mm) and up to
  // the writer's minimum arc radius: written as circumscribed polygons, accepted.
  for (const Units units : {Units::inch, Units::millimetre}) {
    const double q = quantum(units);
    // inch: below 10 q; mm: below 25.4 q.
    for (const double radiusInQuanta : {3.0, 8.0, units == Units::inch ? 9.0 : 20.0}) {
      const double radius = radiusInQuanta * q;
      const Vec3 centre = {1.0, 2.0, 0.0};
      const ToolPath path = oneArcPath(units, centre, radius, true, 1.5 * kPi);
      const Rebuilt rebuilt = interpretOneArc(path);
      for (const Motion& m : rebuilt.cuts) {
        EXPECT_EQ(m.kind, Motion::Kind::feed) << m.text;
      }
      // Vertices lie at most q (the polygon's tolerance) outside the circle, up to rounding.
      expectOnCircle(rebuilt, centre, radius + 0.5 * q,
                     0.5 * q + std::sqrt(2.0) * readBackTolerance(units));
    }
  }
}

}  // namespace
}  // namespace scallop
