// Tests of gcode_reader.hpp: every accepted word, the positions and arc centres read back,
// scallop's own programs, and malformed programs refused with the file, line and word named.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "support/message_checks.hpp"
#include "support/rs274.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

std::string errorOf(const std::string& text) {
  try {
    parseGcodeProgram(text, "p.ngc");
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

constexpr const char* kHeader = "G20\nG90 G94 G17 G40 G80\nG91.1\nG61\nS10000 M3\nG0 Z1\nG0 X0 Y0\nF40\n";

TEST(GcodeReader, ReadsEveryAcceptedWord) {
  const std::string text = std::string("(a title)\n%\n") + kHeader +
                           "N10 G1 Z0.5 ; a comment\n"
                           "/g1 x 1 . 5 y+0.25\n"             // block delete, lower case, blanks
                           "G64 P0.001 Q0.001\n"
                           "G4 P0.5\n"
                           "G18 G2 X2.5 Z0.5 I0.5 K0\n"     // a half turn about (2, 0.25, 0.5)
                           "G19 G3 Y1.25 Z0.5 J0.5 K0\n"
                           "G17 G2 X2.5 Y1.25 I0 J-0.5 Z0.4\n"  // a full circle, helical
                           "G90.1 G3 X3.5 Y1.25 I3 J1.25\n"  // absolute centre
                           "M5\nG0 Z1\nM2\n"
                           "this line is not read\n";
  const GcodeProgram program = parseGcodeProgram(text, "p.ngc");
  EXPECT_EQ(program.units, Units::inch);
  EXPECT_EQ(program.lines, 21u);  // up to M2
  EXPECT_EQ(program.unknownStartMoves, 2u);  // G0 Z1 and G0 X0 Y0 before all axes were known
  ASSERT_EQ(program.moves.size(), 7u);
  const ProgramMove& down = program.moves[0];
  EXPECT_EQ(down.kind, ProgramMoveKind::line);
  EXPECT_EQ(down.line, 11u);
  EXPECT_EQ(down.start.z, 1.0);
  EXPECT_EQ(down.end.z, 0.5);
  EXPECT_TRUE(down.spindleOn);
  EXPECT_EQ(program.moves[1].end.x, 1.5);
  EXPECT_EQ(program.moves[1].end.y, 0.25);
  const ProgramMove& zx = program.moves[2];
  EXPECT_EQ(zx.kind, ProgramMoveKind::arc);
  EXPECT_EQ(zx.plane, ArcPlane::zx);
  EXPECT_TRUE(zx.clockwise);
  EXPECT_EQ(zx.center.x, 2.0);
  EXPECT_EQ(zx.center.y, 0.25);
  EXPECT_EQ(zx.center.z, 0.5);
  const ProgramMove& yz = program.moves[3];
  EXPECT_EQ(yz.plane, ArcPlane::yz);
  EXPECT_FALSE(yz.clockwise);
  EXPECT_EQ(yz.center.y, 0.75);
  EXPECT_EQ(yz.center.x, 2.5);
  const ProgramMove& circle = program.moves[4];
  EXPECT_EQ(circle.plane, ArcPlane::xy);
  EXPECT_EQ(circle.center.y, 0.75);
  EXPECT_EQ(circle.center.z, 0.5);  // the start's normal coordinate
  EXPECT_EQ(circle.end.z, 0.4);
  EXPECT_EQ(program.moves[5].center.x, 3.0);
  EXPECT_EQ(program.moves[5].center.y, 1.25);
  EXPECT_FALSE(program.moves[6].spindleOn);
  EXPECT_EQ(program.moves[6].kind, ProgramMoveKind::rapid);
}

TEST(GcodeReader, ReadsScallopsOwnProgramsBackToTheirTips) {
  // A raster along y writes G19 arcs; every position read back is the path's centre - R z
  // within the printed rounding (q / 2 = 5e-6 in).
  const Surface surface = exampleSurface("paper-2");
  RasterOptions raster;
  raster.angleRad = 0.5 * 3.141592653589793;
  raster.toolRadius = 0.25;
  raster.scallopHeight = 0.005;
  raster.dropEnvelope = false;  // the hull's exact G19 arcs (lifting replaces them)
  const RasterPaths paths = rasterPaths(surface, raster);
  GcodeOptions options;
  options.safeHeight = 4.0;
  options.feedRate = 40.0;
  options.plungeFeedRate = 15.0;
  options.spindleRpm = 0.0;
  const GcodeProgram program = parseGcodeProgram(gcodeProgram(paths.path, options), "r.ngc");
  std::vector<Vec3> ends;
  for (const ToolPass& pass : paths.path.passes)
    for (const ToolMove& move : pass.moves) ends.push_back(move.end - Vec3{0.0, 0.0, raster.toolRadius});
  std::size_t matched = 0, arcs = 0;
  std::size_t next = 0;
  for (const ProgramMove& move : program.moves) {
    if (move.kind == ProgramMoveKind::arc) ++arcs;
    // Walk the path's ends in order; moves the writer left out (no printed change) are skipped.
    for (std::size_t k = next; k < ends.size() && k < next + 4; ++k) {
      if (std::abs(ends[k].x - move.end.x) <= 5.1e-6 && std::abs(ends[k].y - move.end.y) <= 5.1e-6 &&
          std::abs(ends[k].z - move.end.z) <= 5.1e-6) {
        ++matched;
        next = k + 1;
        break;
      }
    }
  }
  EXPECT_GT(arcs, 100u);
  EXPECT_GE(matched, ends.size() * 99 / 100);
}

// LinuxCNC's interpreter as the reference: a random program (lines, rapids, arcs in the three
// planes both ways, full circles, helices, centres relative and absolute) is read by rs274,
// whose canonical calls (STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED(first_end, second_end,
// first_axis, second_axis, rotation, axis_end, ...), (first, second) = (x, y), (z, x),
// (y, z) in XY, XZ, YZ, rotation > 0 counter-clockwise) must match the reader's moves one
// for one, within the canonical printing (4 decimals).
TEST(GcodeReader, AgreesWithLinuxCncOnRandomPrograms) {
  const std::string rs274 = test::findRs274();
  ASSERT_FALSE(rs274.empty()) << "rs274 (Debian package linuxcnc-uspace) is needed";
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 8; ++trial) {
    std::string text = "G20 G90 G94 G40 G80 G91.1\nF30\nG0 X1 Y1 Z1\n";
    std::array<double, 3> at = {1.0, 1.0, 1.0};
    bool absoluteCentre = false;
    auto fixed = [](double v) { return fmt::format("{:.4f}", v); };
    for (int k = 0; k < 60; ++k) {
      const int kind = static_cast<int>(rng() % 6);
      if (kind <= 1) {
        for (double& c : at) c = std::round((c + unit(rng) - 0.5) * 1e4) / 1e4;
        text += fmt::format("{} X{} Y{} Z{}\n", kind == 0 ? "G0" : "G1", fixed(at[0]), fixed(at[1]), fixed(at[2]));
        continue;
      }
      if (rng() % 4 == 0) {
        absoluteCentre = !absoluteCentre;
        text += absoluteCentre ? "G90.1\n" : "G91.1\n";
      }
      const int plane = static_cast<int>(rng() % 3);  // 0 G17, 1 G18, 2 G19
      const std::array<int, 3> axes = plane == 0 ? std::array<int, 3>{0, 1, 2}
                                      : plane == 1 ? std::array<int, 3>{2, 0, 1}
                                                   : std::array<int, 3>{1, 2, 0};
      const double radius = 0.2 + unit(rng);
      const double a0 = 2.0 * 3.141592653589793 * unit(rng);
      std::array<double, 3> centre = at;
      centre[axes[0]] = std::round((at[axes[0]] - radius * std::cos(a0)) * 1e4) / 1e4;
      centre[axes[1]] = std::round((at[axes[1]] - radius * std::sin(a0)) * 1e4) / 1e4;
      const double r = std::hypot(at[axes[0]] - centre[axes[0]], at[axes[1]] - centre[axes[1]]);
      const double a1 = kind == 5 ? std::atan2(at[axes[1]] - centre[axes[1]], at[axes[0]] - centre[axes[0]])
                                  : 2.0 * 3.141592653589793 * unit(rng);
      std::array<double, 3> end = at;
      if (kind != 5) {  // 5: a full circle, the end at the start
        end[axes[0]] = std::round((centre[axes[0]] + r * std::cos(a1)) * 1e4) / 1e4;
        end[axes[1]] = std::round((centre[axes[1]] + r * std::sin(a1)) * 1e4) / 1e4;
      }
      if (kind == 4) end[axes[2]] = std::round((at[axes[2]] + unit(rng) - 0.5) * 1e4) / 1e4;  // helix
      const char* letters = "IJK";
      const char* names = "XYZ";
      std::string block = fmt::format("G{} G{}", 17 + plane, rng() % 2 == 0 ? 2 : 3);
      for (int a = 0; a < 3; ++a) block += fmt::format(" {}{}", names[a], fixed(end[a]));
      for (const int a : {axes[0], axes[1]})
        block += fmt::format(" {}{}", letters[a], fixed(absoluteCentre ? centre[a] : centre[a] - at[a]));
      text += block + "\n";
      at = end;
    }
    text += "M2\n";
    const GcodeProgram program = parseGcodeProgram(text, "random.ngc");
    const test::Rs274Run run = test::runRs274(rs274, text);
    ASSERT_EQ(run.exitCode, 0) << run.err << "\n" << text;
    std::vector<std::pair<std::string, std::vector<double>>> calls;
    std::string plane = "CANON_PLANE_XY";
    std::stringstream lines(run.out);
    std::string line;
    while (std::getline(lines, line)) {
      const std::optional<test::CanonLine> call = test::parseCanonLine(line);
      if (!call) continue;
      const std::string& name = call->name;
      if (name == "SELECT_PLANE") plane = call->arguments;
      if (name != "STRAIGHT_TRAVERSE" && name != "STRAIGHT_FEED" && name != "ARC_FEED") continue;
      std::vector<double> args;
      std::stringstream list(call->arguments);
      std::string arg;
      while (std::getline(list, arg, ',')) args.push_back(std::stod(arg));
      calls.push_back({name == "ARC_FEED" ? plane : name, args});
    }
    // rs274 starts at the origin: its first traverse is the reader's unknown start.
    ASSERT_EQ(program.unknownStartMoves, 1u);
    ASSERT_EQ(calls.size(), program.moves.size() + 1);
    const double tolerance = 6e-5;
    for (std::size_t k = 0; k < program.moves.size(); ++k) {
      const ProgramMove& m = program.moves[k];
      const auto& [name, args] = calls[k + 1];
      SCOPED_TRACE(testing::Message() << "trial " << trial << " line " << m.line << ": " << name);
      if (m.kind != ProgramMoveKind::arc) {
        EXPECT_EQ(name, m.kind == ProgramMoveKind::rapid ? "STRAIGHT_TRAVERSE" : "STRAIGHT_FEED");
        EXPECT_NEAR(args[0], m.end.x, tolerance);
        EXPECT_NEAR(args[1], m.end.y, tolerance);
        EXPECT_NEAR(args[2], m.end.z, tolerance);
        continue;
      }
      const std::array<double, 3> end = {m.end.x, m.end.y, m.end.z};
      const std::array<double, 3> centre = {m.center.x, m.center.y, m.center.z};
      const std::array<int, 3> axes = m.plane == ArcPlane::xy ? std::array<int, 3>{0, 1, 2}
                                      : m.plane == ArcPlane::zx ? std::array<int, 3>{2, 0, 1}
                                                                : std::array<int, 3>{1, 2, 0};
      EXPECT_EQ(name, m.plane == ArcPlane::xy ? "CANON_PLANE_XY" : m.plane == ArcPlane::zx ? "CANON_PLANE_XZ" : "CANON_PLANE_YZ");
      EXPECT_NEAR(args[0], end[axes[0]], tolerance);
      EXPECT_NEAR(args[1], end[axes[1]], tolerance);
      EXPECT_NEAR(args[2], centre[axes[0]], tolerance);
      EXPECT_NEAR(args[3], centre[axes[1]], tolerance);
      EXPECT_EQ(args[4] > 0.0, !m.clockwise);
      EXPECT_EQ(std::abs(args[4]), 1.0);
      EXPECT_NEAR(args[5], end[axes[2]], tolerance);
    }
  }
}

TEST(GcodeReader, MalformedProgramsNameTheFileLineAndWord) {
  const std::string h = kHeader;  // 8 lines
  struct Case {
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {h + "T1 M6\n", {"p.ngc:9:", "'T1'", "unsupported"}},
      {h + "G1 X\n", {"p.ngc:9:", "'X'", "no number"}},
      {h + "G1 X1.2.3\n", {"p.ngc:9:", "'X1.2.3'", "not a number"}},
      {h + "G1 X--1\n", {"p.ngc:9:", "not a number"}},
      {h + "G1 X1e5\n", {"p.ngc:9:", "'E5'", "unsupported"}},
      {h + "G91\nG1 X1\n", {"p.ngc:9:", "G91", "incremental"}},
      {h + "G93\n", {"p.ngc:9:", "G93", "inverse-time"}},
      {h + "G2 X1 Y0 R0.5\n", {"p.ngc:9:", "'R0.5'", "radius-format"}},
      {h + "G2 X1 Y0 I0.3 J0\n", {"p.ngc:9:", "arc radii differ", "0.300000", "0.700000"}},
      {h + "G2 X0 Y0 I0 J0\n", {"p.ngc:9:", "zero radius"}},
      {h + "G2 X1 Y0 I0.5 K0.1\n", {"p.ngc:9:", "K word", "G17"}},
      {h + "G2 X1 Y0 I0.5 P2\n", {"p.ngc:9:", "P (full turns)"}},
      {h + "G2 I0.5\n", {"p.ngc:9:", "needs an end point"}},
      {h + "G1 X1 I0.5\n", {"p.ngc:9:", "I J K"}},
      {h + "G0 G1 X1\n", {"p.ngc:9:", "two motion codes"}},
      {h + "G1 X1 X2\n", {"p.ngc:9:", "'X2'", "twice"}},
      {h + "G21\n", {"p.ngc:9:", "units change"}},
      {h + "G1 X1 (open\n", {"p.ngc:9:", "not closed"}},
      {h + "G1 X1 (a (b))\n", {"p.ngc:9:", "nested"}},
      {h + "G1 X1 )\n", {"p.ngc:9:", "without a matching"}},
      {h + "G4\n", {"p.ngc:9:", "G4", "P"}},
      {h + "G1 X1 Q1\n", {"p.ngc:9:", "Q"}},
      {h + "F0\n", {"p.ngc:9:", "'F0'", "positive"}},
      {h + "M7\n", {"p.ngc:9:", "'M7'"}},
      {h + "G43 H1\n", {"p.ngc:9:", "'G43'"}},
      {h + "G1 X\x01\n", {"p.ngc:9:", "byte 0x01"}},
      {h + "G1 X" + std::string(300, '1') + "\n", {"p.ngc:9:", "longer than 256"}},
      {"G20\nG0 X0 Y0 Z0\nG1 X1\n", {"p.ngc:3:", "no feed"}},
      {"G20\nF10\nG1 X1\n", {"p.ngc:3:", "unknown position"}},
      {"G0 X1 Y1 Z1\n", {"p.ngc:1:", "units are set"}},
      {"G20\nX1 Y1\n", {"p.ngc:2:", "motion mode"}},
      {"G20\nG0 X1e308\n", {"p.ngc:2:", "'E308'"}},
      {"G20\nG0 X1000000000000\n", {"p.ngc:2:", "at most"}},
  };
  for (const Case& c : cases) test::expectMessageContains(errorOf(c.text), c.parts, c.text);
}

TEST(GcodeReader, RandomBytesNeverCrashOrHang) {
  // Fixed seed; every outcome is a program or a scallop::Error.
  std::mt19937_64 rng(3);
  const std::string alphabet = "GMXYZIJKFSPQNRT0123456789.+- ()\n;%/\r";
  int refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = kHeader;
    const int length = static_cast<int>(rng() % 120);
    for (int i = 0; i < length; ++i) text += alphabet[rng() % alphabet.size()];
    try {
      const GcodeProgram program = parseGcodeProgram(text, "fuzz.ngc");
      for (const ProgramMove& move : program.moves) {
        ASSERT_TRUE(std::isfinite(move.end.x) && std::isfinite(move.end.y) && std::isfinite(move.end.z));
      }
    } catch (const Error& error) {
      ++refused;
      EXPECT_EQ(std::string(error.what()).rfind("fuzz.ngc:", 0), 0u) << error.what();
    }
  }
  EXPECT_GT(refused, 1000);
}

TEST(GcodeReader, CrLfAndTheStandardInputName) {
  const GcodeProgram program = parseGcodeProgram("G21\r\nG0 X1 Y2 Z3\r\nF100\r\nG1 X2\r\n", "-");
  EXPECT_EQ(program.units, Units::millimetre);
  ASSERT_EQ(program.moves.size(), 1u);
  EXPECT_EQ(program.moves[0].end.x, 2.0);
  try {
    parseGcodeProgram("G21\nT2\n", "-");
    ADD_FAILURE() << "accepted T2";
  } catch (const Error& error) {
    test::expectMessageContains(error.what(), {"<stdin>:2:", "'T2'"}, "stdin");
  }
}

}  // namespace
}  // namespace scallop
