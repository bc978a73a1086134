// End-to-end tests of `scallop paths` and `scallop plan`: the main job writes its folder,
// the JSON agrees with itself and with the G-code, and bad input fails cleanly (one error
// line naming the problem, exit status 1, nothing written).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "support/rs274.hpp"
#include "support/distance_reference.hpp"
#include "support/rational_patches.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

namespace fs = std::filesystem;
using scallop::test::CliFixture;
using scallop::test::readFile;
using scallop::test::RunResult;

class PathsCli : public CliFixture {};

// A wall folding back over itself along x: not a graph z = f(x, y) over the raster direction.
constexpr const char* kFoldedSurface = R"({"units": "mm", "patches": [{"degree": [3, 1],
  "control_points": [[[0, 0, 0], [0, 10, 0]], [[20, 0, 5], [20, 10, 5]],
                     [[-10, 0, 10], [-10, 10, 10]], [[10, 0, 15], [10, 10, 15]]]}]})";

// No exponent, no nan or inf anywhere in a G-code program: outside comments only words of
// the letters scallop writes, digits, '.', '-', blanks and '%'.
void expectPlainNumbers(const std::string& gcode) {
  const std::string allowed = "GMSFXYZIJKPT0123456789.- \n%";
  for (std::size_t i = 0; i < gcode.size(); ++i) {
    if (gcode[i] == '(') {  // comments may say anything
      i = gcode.find(')', i);
      ASSERT_NE(i, std::string::npos);
      continue;
    }
    ASSERT_NE(allowed.find(gcode[i]), std::string::npos)
        << "unexpected '" << gcode[i] << "': " << gcode.substr(i > 20 ? i - 20 : 0, 40);
  }
}

TEST_F(PathsCli, PlanWithNoArgumentsWritesTheWholeFolder) {
  const RunResult result = run("plan");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(result.out.empty());
  EXPECT_NE(result.err.find("alpha* = 78.04"), std::string::npos) << result.err;
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(workDir_ / "scallop-out"))
    files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"gauss-map.svg", "paths-plan.svg", "paths.svg",
                                             "report.json", "stereographic.svg", "toolpath.ngc",
                                             "verify.svg"}));
  const auto report = nlohmann::json::parse(readFile(workDir_ / "scallop-out" / "report.json"));
  // The simulated cut of the program as written: no gouge beyond the G-code's rounding
  // (1e-5 in quanta), no rapid into the finishing stock, a heat map with its colour bar.
  const auto& verification = report["verification"];
  EXPECT_LT(verification["max_gouge"].get<double>(), 1e-4);
  EXPECT_EQ(verification["rapids_cutting"].get<int>(), 0);
  EXPECT_GT(verification["max_scallop"].get<double>(), 0.0);
  EXPECT_NE(readFile(workDir_ / "scallop-out" / "verify.svg").find("scallop (in)"), std::string::npos);
  EXPECT_EQ(report["strategy"], "contour");
  EXPECT_EQ(report["units"], "in");
  EXPECT_EQ(report["tool_radius"], 0.25);
  EXPECT_TRUE(report["orientation"]["certified"].get<bool>());
  // The planes' normal is N* up to sign, and the spacing follows from H = 0.001 and alpha.
  const auto& n = report["plane_normal"];
  const auto& m = report["orientation"]["normal"];
  const double dotNm = n[0].get<double>() * m[0].get<double>() + n[1].get<double>() * m[1].get<double>() +
                       n[2].get<double>() * m[2].get<double>();
  EXPECT_NEAR(std::abs(dotNm), 1.0, 1e-12);
  const double alpha = report["alpha_deg"].get<double>() * M_PI / 180.0;
  EXPECT_NEAR(report["spacing"].get<double>(), 2 * std::sqrt(2 * 0.25 * 0.001 - 1e-6) * std::sin(alpha), 1e-12);
  const auto& stats = report["stats"];
  EXPECT_GT(stats["planes"].get<int>(), 50);
  EXPECT_EQ(stats["passes"].get<std::size_t>(), report["passes"].size());
  EXPECT_FALSE(stats.contains("link_length"));  // raster only
  // The centre length is the sum of the passes' line lengths, the linker's feeds over the
  // envelope ("link_moves" leading moves) left out.
  double length = 0.0;
  std::size_t envelopeLinks = 0;
  for (const auto& pass : report["passes"]) {
    std::vector<double> at = pass["start"].get<std::vector<double>>();
    const std::size_t skip = pass.value("link_moves", std::size_t{0});
    envelopeLinks += skip > 0 ? 1 : 0;
    std::size_t k = 0;
    for (const auto& move : pass["moves"]) {
      const std::vector<double> end = move["line"].get<std::vector<double>>();
      if (k++ >= skip) length += std::hypot(end[0] - at[0], end[1] - at[1], end[2] - at[2]);
      at = end;
    }
  }
  EXPECT_EQ(envelopeLinks, report["linking"]["envelope_links"].get<std::size_t>());
  EXPECT_NEAR(length, stats["centre_length"].get<double>(), 1e-9 * length);
  const std::string gcode = readFile(workDir_ / "scallop-out" / "toolpath.ngc");
  EXPECT_NE(gcode.find("G20"), std::string::npos);
  EXPECT_NE(gcode.find("M2"), std::string::npos);
  expectPlainNumbers(gcode);
}

// The plan's report carries the G-code's motion (lengths, minutes at the stated rates) and
// the linking; --no-linking gives the strategy's path with its safe-height retracts, whose
// time off the cut the linked plan cuts by more than 80 % (the issue's target).
TEST_F(PathsCli, PlanReportsCycleTimeAndLinking) {
  const RunResult linked = run("plan --quiet --out a");
  ASSERT_EQ(linked.exitCode, 0) << linked.err;
  EXPECT_NE(linked.err.find("cycle "), std::string::npos) << linked.err;
  EXPECT_NE(linked.err.find("local retracts"), std::string::npos) << linked.err;
  const RunResult unlinked = run("plan --quiet --no-linking --rapid-rate 100 --out b");
  ASSERT_EQ(unlinked.exitCode, 0) << unlinked.err;
  const auto a = nlohmann::json::parse(readFile(workDir_ / "a" / "report.json"));
  const auto b = nlohmann::json::parse(readFile(workDir_ / "b" / "report.json"));
  for (const auto* report : {&a, &b}) {
    const auto& m = (*report)["motion"];
    ASSERT_TRUE(m.is_object());
    EXPECT_EQ(m["feed_rate"], 40.0);
    EXPECT_EQ(m["plunge_feed_rate"], 15.0);
    const double feed = m["feed_length"].get<double>() / 40.0;
    const double plunge = m["plunge_length"].get<double>() / 15.0;
    const double rapid = m["rapid_length"].get<double>() / m["rapid_rate"].get<double>();
    EXPECT_NEAR(m["feed_minutes"].get<double>(), feed, 1e-12 * feed);
    EXPECT_NEAR(m["plunge_minutes"].get<double>(), plunge, 1e-12 * plunge);
    EXPECT_NEAR(m["rapid_minutes"].get<double>(), rapid, 1e-12 * rapid);
    EXPECT_NEAR(m["cycle_minutes"].get<double>(), feed + plunge + rapid, 1e-12 * (feed + plunge + rapid));
  }
  EXPECT_EQ(a["motion"]["rapid_rate"], 200.0);
  EXPECT_EQ(b["motion"]["rapid_rate"], 100.0);
  ASSERT_TRUE(a["linking"].is_object());
  EXPECT_TRUE(b["linking"].is_null());
  const auto& l = a["linking"];
  EXPECT_EQ(l["direct_links"].get<std::size_t>() + l["local_retracts"].get<std::size_t>() +
                l["unproven_links"].get<std::size_t>() + l["strategy_links"].get<std::size_t>() + 1,
            a["passes"].size());
  // Air time at the same rapid rate: b's rapids were timed at 100, so rescale them to 200.
  const double airA = a["motion"]["non_cutting_minutes"].get<double>();
  const double airB = b["motion"]["plunge_minutes"].get<double>() +
                      b["motion"]["rapid_length"].get<double>() / 200.0;
  EXPECT_LE(airA, 0.2 * airB) << airA << " vs " << airB;
  const RunResult bad = run("paths --example paper-1 --tool-radius 0.25 --spacing 0.1 --rapid-rate 0");
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("rapid rate"), std::string::npos) << bad.err;
}

TEST_F(PathsCli, PlanRasterReportsTheGougeCheck) {
  const RunResult result = run("plan --strategy raster --out r --quiet --dialect grbl");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto report = nlohmann::json::parse(readFile(workDir_ / "r" / "report.json"));
  EXPECT_EQ(report["strategy"], "raster");
  ASSERT_TRUE(report["gouge"].is_object());
  EXPECT_GE(report["gouge"]["max_depth"].get<double>(), 0.0);
  EXPECT_GE(report["gouge"]["depth_bound"].get<double>(), report["gouge"]["max_depth"].get<double>());
  // Every pass end of the main job has a proven way off (raster.hpp's Ends).
  EXPECT_EQ(report["stats"]["uncleared_ends"].get<std::size_t>(), 0u);
  EXPECT_GT(report["stats"]["link_length"].get<double>(), 0.0);
  EXPECT_TRUE(fs::exists(workDir_ / "r" / "toolpath.gcode"));
  expectPlainNumbers(readFile(workDir_ / "r" / "toolpath.gcode"));
}

// paper-1 sampled on a 48 x 48 grid of its parameters and written as an ASCII STL in inches:
// `plan` cuts it by raster (the default for a mesh), every move proven clear (the exact
// deepest interference at most eps), the program accepted by LinuxCNC's rs274, and the
// simulated cut on the mesh finds no gouge beyond its tolerance and scallops within H where the
// mesh is not steep across the feed. Options meant for surfaces are refused by name.
TEST_F(PathsCli, PlanCutsAnStlMeshByRaster) {
  const scallop::Surface surface = scallop::exampleSurface("paper-1");
  std::string stl = "solid paper1\n";
  const int n = 48;
  const auto at = [&](int i, int j) { return scallop::point(surface.patches[0], i / double(n), j / double(n)); };
  const auto facet = [&](scallop::Vec3 a, scallop::Vec3 b, scallop::Vec3 c) {
    stl += fmt::format("facet normal 0 0 0\nouter loop\nvertex {} {} {}\nvertex {} {} {}\nvertex {} {} {}\nendloop\nendfacet\n",
                       a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z);
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      facet(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      facet(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  stl += "endsolid paper1\n";
  write("paper1.stl", stl);
  const RunResult result = run("plan paper1.stl --units in --tool-radius 0.25 --scallop-height 0.001 --out m");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("raster on paper1.stl: 4608 triangles"), std::string::npos) << result.err;
  const auto report = nlohmann::json::parse(readFile(workDir_ / "m" / "report.json"));
  EXPECT_EQ(report["strategy"], "raster");
  EXPECT_EQ(report["units"], "in");
  // eps: 1e-6 of the mesh's bounding-box diagonal (sqrt(3^2 + 3^2 + 1.5^2) = 4.5 in at most).
  const double eps = 4.5e-6;
  EXPECT_LE(report["gouge"]["max_depth"].get<double>(), eps);
  const auto& v = report["verification"];
  // The skirt's walls stand 4 eps outside the edges, so no ball grazes an edge's own vertical
  // line, which the simulator's z-map would read as cut to the ball's equator (up to
  // sqrt(2 R eps) = 0.0015 in here, 0.0008 in measured before the offset).
  std::printf("[          ] STL plan: simulated gouge %.3g in at (%.4f, %.4f)\n", v["max_gouge"].get<double>(),
              v["max_gouge_at"][0].get<double>(), v["max_gouge_at"][1].get<double>());
  EXPECT_LE(v["max_gouge"].get<double>(), v["gouge_tolerance"].get<double>());
  EXPECT_EQ(v["rapids_cutting"].get<int>(), 0);
  std::printf("[          ] STL plan: scallop max %.6f / 99%% %.6f in, above H %.5f in^2\n", v["max_scallop"].get<double>(),
              v["scallop_p99"].get<double>(), v["uncut_area"].get<double>());
  EXPECT_LT(v["scallop_p99"].get<double>(), 0.001);
  EXPECT_TRUE(fs::exists(workDir_ / "m" / "verify.svg"));
  const std::string rs274 = scallop::test::findRs274();
  ASSERT_FALSE(rs274.empty()) << "LinuxCNC's rs274 was not found: install linuxcnc-uspace";
  const scallop::test::Rs274Run interpreted = scallop::test::runRs274(rs274, readFile(workDir_ / "m" / "toolpath.ngc"));
  EXPECT_EQ(interpreted.exitCode, 0) << interpreted.err;
  // Surface options refused for a mesh, by name; nothing written.
  for (const char* option : {"--strategy contour", "--patches 0", "--no-drop-envelope", "--constant-spacing"}) {
    const RunResult refused = run(std::string("plan paper1.stl --units in --out x ") + option);
    EXPECT_EQ(refused.exitCode, 1) << option;
    EXPECT_NE(refused.err.find("not for a mesh"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(workDir_ / "x"));
  }
  // A spacing the balls cannot bridge, and a ball in the wrong units: one line, nothing written
  // (the same spacing for a surface too).
  for (const char* arguments : {"plan paper1.stl --units in --tool-radius 0.25 --spacing 0.6 --out x",
                                "plan paper1.stl --units in --tool-radius 6000 --out x",
                                "plan --example paper-1 --tool-radius 0.25 --spacing 0.6 --out x"}) {
    const RunResult refused = run(arguments);
    EXPECT_EQ(refused.exitCode, 1) << arguments;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_TRUE(refused.err.find("diameter") != std::string::npos || refused.err.find("1000 times") != std::string::npos)
        << refused.err;
    EXPECT_FALSE(fs::exists(workDir_ / "x"));
  }
  // The same mesh by its content: on standard input and under a name without .stl. The same
  // program but for its title line, which names the source.
  const auto body = [](const std::string& program) { return program.substr(program.find('\n')); };
  const std::string program = readFile(workDir_ / "m" / "toolpath.ngc");
  const RunResult piped = run("plan - --units in --tool-radius 0.25 --scallop-height 0.001 --out p --quiet",
                              (workDir_ / "paper1.stl").string());
  ASSERT_EQ(piped.exitCode, 0) << piped.err;
  EXPECT_TRUE(body(readFile(workDir_ / "p" / "toolpath.ngc")) == body(program));
  EXPECT_NE(readFile(workDir_ / "p" / "report.json").find("\"source\": \"<stdin>\""), std::string::npos);
  fs::copy_file(workDir_ / "paper1.stl", workDir_ / "paper1.mesh");
  const RunResult named = run("plan paper1.mesh --units in --tool-radius 0.25 --scallop-height 0.001 --out n --quiet");
  ASSERT_EQ(named.exitCode, 0) << named.err;
  EXPECT_TRUE(body(readFile(workDir_ / "n" / "toolpath.ngc")) == body(program));
  const RunResult verified = run("verify paper1.mesh m/toolpath.ngc --units in --radius 0.25 --fail-on-gouge");
  EXPECT_EQ(verified.exitCode, 0) << verified.err;
  // `paths` on the mesh: the same raster as JSON and G-code (the program as plan's without
  // its rest passes; compared whole, not by gtest's line diff, which is quadratic).
  const RunResult paths =
      run("paths paper1.stl --units in --tool-radius 0.25 --scallop-height 0.001 --json p.json --gcode p.ngc");
  ASSERT_EQ(paths.exitCode, 0) << paths.err;
  const RunResult plain =
      run("plan paper1.stl --units in --tool-radius 0.25 --scallop-height 0.001 --no-rest-finishing --out nr --quiet");
  ASSERT_EQ(plain.exitCode, 0) << plain.err;
  EXPECT_TRUE(body(readFile(workDir_ / "p.ngc")) == body(readFile(workDir_ / "nr" / "toolpath.ngc")));
  const auto json = nlohmann::json::parse(readFile(workDir_ / "p.json"));
  const auto plainReport = nlohmann::json::parse(readFile(workDir_ / "nr" / "report.json"));
  EXPECT_EQ(json["strategy"], "raster");
  EXPECT_EQ(json["stats"]["planes"], report["stats"]["planes"]);
  EXPECT_EQ(json["passes"].size(), plainReport["passes"].size());
  // Rest finishing (rest_finishing.hpp on a mesh): this mesh's simulated cut leaves 0.010 in^2
  // above H without it (its edges between facets); the rest passes take most of it, all
  // proven, and add no gouge.
  const auto& rest = report["rest_finishing"];
  ASSERT_TRUE(rest.is_array());
  ASSERT_FALSE(rest.empty());
  EXPECT_GT(rest[0]["passes"].get<int>(), 0);
  EXPECT_EQ(rest[0]["unproven_moves"].get<int>(), 0);
  EXPECT_LT(v["uncut_area"].get<double>(), 0.5 * plainReport["verification"]["uncut_area"].get<double>());
  EXPECT_LE(v["max_gouge"].get<double>(), v["gouge_tolerance"].get<double>());
  for (const char* option : {"--svg x.svg", "--strategy contour", "--angle 30", "--no-gouge-check"}) {
    const RunResult refused =
        run(std::string("paths paper1.stl --units in --tool-radius 0.25 --scallop-height 0.001 --json x.json ") + option);
    EXPECT_EQ(refused.exitCode, 1) << option;
    EXPECT_NE(refused.err.find("not for a mesh"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(workDir_ / "x.json"));
  }
}

// A plate at z = 0 over a hidden pyramid reaching down to z = -20 (mm), as OpenCAMLib's
// sphere.stl is a sphere through a plate: off the part the balls run R above the lowest point
// seen from above (the plate), not beside the plate below it, where grazing its corner within
// eps read as a 20 mm gouge in the simulated cut.
TEST_F(PathsCli, PlanOfAPlateOverAHiddenUndersideRunsAboveThePlate) {
  const auto facet = [](const char* a, const char* b, const char* c) {
    return fmt::format("facet normal 0 0 0\nouter loop\nvertex {}\nvertex {}\nvertex {}\nendloop\nendfacet\n", a, b, c);
  };
  const std::string stl = "solid plate\n" + facet("0 0 0", "10 0 0", "10 10 0") + facet("0 0 0", "10 10 0", "0 10 0") +
                          facet("0 0 0", "10 0 0", "5 5 -20") + facet("10 0 0", "10 10 0", "5 5 -20") +
                          facet("10 10 0", "0 10 0", "5 5 -20") + facet("0 10 0", "0 0 0", "5 5 -20") +
                          "endsolid plate\n";
  write("plate.stl", stl);
  const RunResult result = run("plan plate.stl --tool-radius 1 --scallop-height 0.01 --quiet --out p");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto report = nlohmann::json::parse(readFile(workDir_ / "p" / "report.json"));
  const auto& v = report["verification"];
  EXPECT_LE(v["max_gouge"].get<double>(), v["gouge_tolerance"].get<double>());
  EXPECT_LE(v["max_scallop"].get<double>(), 0.01);
  // The ball never goes below the plate's top + R (a tip at or above 0).
  const std::string gcode = readFile(workDir_ / "p" / "toolpath.ngc");
  std::stringstream lines(gcode);
  double lowest = 1e300;
  for (std::string line; std::getline(lines, line);) {
    const auto z = line.find(" Z");
    if (line.rfind("G1", 0) == 0 && z != std::string::npos) lowest = std::min(lowest, std::stod(line.substr(z + 2)));
  }
  EXPECT_GE(lowest, -1e-4);
}

// The main job's G-code, for both strategies and both dialects, goes through LinuxCNC's own
// interpreter without a single complaint, and its cutting moves end where the report's passes
// say (tips = centres - R).
TEST_F(PathsCli, PlanGcodeIsAcceptedByLinuxCnc) {
  const std::string rs274 = scallop::test::findRs274();
  ASSERT_FALSE(rs274.empty()) << "LinuxCNC's rs274 was not found: install linuxcnc-uspace "
                                 "(tools/setup.sh test does)";
  for (const char* arguments : {"plan --quiet --out c", "plan --quiet --strategy raster --out r",
                                "plan --quiet --example paper-2 --dialect grbl --out g"}) {
    SCOPED_TRACE(arguments);
    const RunResult result = run(arguments);
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const std::string dir = std::string(arguments).substr(std::string(arguments).rfind(' ') + 1);
    const bool grbl = dir == "g";
    const std::string gcode = readFile(workDir_ / dir / (grbl ? "toolpath.gcode" : "toolpath.ngc"));
    const scallop::test::Rs274Run interpreted = scallop::test::runRs274(rs274, gcode);
    EXPECT_EQ(interpreted.exitCode, 0) << interpreted.err;
    std::stringstream err(interpreted.err);
    for (std::string line; std::getline(err, line);)
      EXPECT_TRUE(line.empty() || line == "executing") << "rs274 reported: " << line;
    // Count the feed moves (STRAIGHT_FEED and ARC_FEED) against the report's moves plus one
    // plunge per retracted pass and one straight feed per pass fed from elsewhere than
    // where the previous one ended (a direct link).
    std::size_t feeds = 0;
    std::stringstream canon(interpreted.out);
    for (std::string line; std::getline(canon, line);)
      if (line.find("STRAIGHT_FEED(") != std::string::npos || line.find("ARC_FEED(") != std::string::npos)
        ++feeds;
    const auto report = nlohmann::json::parse(readFile(workDir_ / dir / "report.json"));
    std::size_t moves = 0;
    nlohmann::json previousEnd;
    for (const auto& pass : report["passes"]) {
      const bool linked = !pass["retract_before"].get<bool>() && pass["start"] != previousEnd;
      moves += pass["moves"].size() + (pass["retract_before"].get<bool>() || linked ? 1 : 0);
      previousEnd = pass["moves"].empty() ? pass["start"] : pass["moves"].back().begin().value();
      if (previousEnd.is_object()) previousEnd = previousEnd["end"];
    }
    // The writer may drop moves shorter than its printed precision; never adds any.
    EXPECT_LE(feeds, moves);
    EXPECT_GE(feeds, moves * 99 / 100);
  }
}

TEST_F(PathsCli, PathsWritesJsonToStandardOutputByDefault) {
  // The paper's paths: the centres r + R n, not lifted (nor run on past the edges).
  const RunResult result = run("paths --example paper-2 --tool-radius 0.25 --spacing 0.0267 "
                               "--normal 0.975,-0.221,-0.002 --no-drop-envelope");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto report = nlohmann::json::parse(result.out);
  // Table 1 of the paper, last row: 359.23 in and 134 components.
  EXPECT_NEAR(report["stats"]["centre_length"].get<double>(), 359.23, 0.01 * 359.23);
  EXPECT_EQ(report["stats"]["components"].get<int>(), 134);
  EXPECT_TRUE(listing().empty());
}

TEST_F(PathsCli, PathsRasterAlongXWritesArcsInTheZxPlane) {
  const RunResult result = run("paths --example paper-1 --tool-radius 0.25 --spacing 0.1 "
                               "--strategy raster --angle 0 --gcode p.ngc --svg p.svg --json p.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const std::string gcode = readFile(workDir_ / "p.ngc");
  EXPECT_NE(gcode.find("G18"), std::string::npos);
  expectPlainNumbers(gcode);
  EXPECT_EQ(readFile(workDir_ / "p.svg").rfind("<svg", 0), 0u);
}

TEST_F(PathsCli, BadInputFailsWithMessageAndWritesNothing) {
  struct Bad {
    const char* arguments;
    std::vector<std::string> parts;
  };
  const Bad bads[] = {
      {"--example paper-1 --tool-radius 0 --spacing 0.1", {"tool radius", "'0'", "positive"}},
      {"--example paper-1 --tool-radius -1 --spacing 0.1", {"tool radius", "'-1'"}},
      {"--example paper-1 --tool-radius nan --spacing 0.1", {"tool radius", "'nan'"}},
      {"--example paper-1 --tool-radius 0.25 --spacing 0", {"spacing", "'0'"}},
      {"--example paper-1 --tool-radius 0.25 --spacing -0.5", {"spacing", "'-0.5'"}},
      {"--example paper-1 --tool-radius 0.25 --spacing 0.1 --normal 0,0,0", {"normal", "zero"}},
      {"--example paper-1 --tool-radius 0.25 --spacing 0.1 --normal nan,0,1", {"normal", "'nan'"}},
      {"--example paper-1 --tool-radius 0.25 --spacing 0.1 --normal 1,2", {"normal", "X,Y,Z"}},
      {"--example paper-1 --tool-radius 0.25 --scallop-height 0.25", {"scallop height", "smaller"}},
      {"--example paper-1 --tool-radius 0.25 --scallop-height 0.3", {"scallop height", "0.3"}},
      {"--example paper-1 --tool-radius 0.25 --spacing 100 --normal 0,0,1", {"cuts the surface"}},
      {"--example paper-1 --tool-radius 6350 --spacing 0.1", {"tool radius", "1000 times", "units"}},
      {"--example paper-1 --tool-radius 0.25 --spacing 1e-5", {"spacing", "100,000", "units"}},
      {"--example paper-1 --tool-radius 0.25 --scallop-height 0.001 --normal 0,0,1",
       {"tangency", "spacing"}},
  };
  for (const Bad& bad : bads) {
    SCOPED_TRACE(bad.arguments);
    fs::remove_all(workDir_);
    fs::create_directory(workDir_);
    write("folded.json", kFoldedSurface);
    const RunResult result =
        run(std::string("paths ") + bad.arguments + " --json out.json --gcode out.ngc --svg out.svg");
    expectCleanFailure(result, bad.parts, "folded.json");
  }
}

// A wall folding back over itself is cut from above: the raster follows what the ball sees
// and the report's gouge check finds nothing deeper than the drop envelope's eps.
TEST_F(PathsCli, FoldedSurfaceIsCutFromAbove) {
  write("folded.json", kFoldedSurface);
  const RunResult result = run("plan folded.json --quiet --strategy raster --tool-radius 1 --out out");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const nlohmann::json report = nlohmann::json::parse(readFile(workDir_ / "out" / "report.json"));
  const double eps = report.at("envelope").at("depth_tolerance").get<double>();
  EXPECT_GT(eps, 0.0);
  EXPECT_LE(report.at("gouge").at("signed_max_depth").get<double>(), eps);
  EXPECT_EQ(report.at("envelope").at("unproven_moves").get<std::size_t>(), 0u);
}

TEST_F(PathsCli, PlanFailsCleanlyAndLeavesNoFolder) {
  write("folded.json", kFoldedSurface);
  expectCleanFailure(run("plan --quiet --tool-radius 0"), {"tool radius"}, "folded.json");
  expectCleanFailure(run("plan --quiet --scallop-height 1"), {"scallop height"}, "folded.json");
  // The folder cannot be made (a file is in the way): nothing is left.
  write("blocked", "x");
  const RunResult result = run("plan --quiet --out blocked/out");
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_EQ(listing(), (std::vector<std::string>{"blocked", "folded.json"}));
}

}  // namespace

// With --scallop-height the planes are adaptive by default (cusp.hpp) and the report gives the
// estimated cusp distribution beside the paper's flat-surface spacing; --constant-spacing
// keeps the paper's Delta, whose estimated cusp exceeds H on paper-2's convex parts.
TEST_F(PathsCli, ScallopReportAdaptiveAndConstant) {
  const std::string common = "paths --example paper-2 --tool-radius 0.25 --scallop-height 0.001 "
                             "--no-gouge-check --no-linking";
  ASSERT_EQ(run(common + " --json adaptive.json").exitCode, 0);
  ASSERT_EQ(run(common + " --constant-spacing --json constant.json").exitCode, 0);
  const auto adaptive = nlohmann::json::parse(readFile(workDir_ / "adaptive.json"));
  const auto constant = nlohmann::json::parse(readFile(workDir_ / "constant.json"));
  const auto& a = adaptive["scallop"];
  const auto& c = constant["scallop"];
  EXPECT_EQ(a["spacing_mode"], "adaptive");
  EXPECT_EQ(c["spacing_mode"], "constant");
  // The paper's spacing is the same both ways, and it is the report's "spacing".
  const double alpha = adaptive["alpha_deg"].get<double>() * M_PI / 180.0;
  const double flat = 2 * std::sqrt(2 * 0.25 * 0.001 - 1e-6) * std::sin(alpha);
  EXPECT_NEAR(a["flat_spacing"].get<double>(), flat, 1e-12);
  EXPECT_EQ(a["flat_spacing"], c["flat_spacing"]);
  EXPECT_EQ(adaptive["spacing"], a["flat_spacing"]);
  // Constant: every gap is Delta; adaptive: they vary, and fewer planes cover paper-2.
  EXPECT_NEAR(c["min_spacing"].get<double>(), flat, 1e-12);
  EXPECT_NEAR(c["max_spacing"].get<double>(), flat, 1e-12);
  EXPECT_LT(a["min_spacing"].get<double>(), a["max_spacing"].get<double>());
  EXPECT_EQ(a["planes"], adaptive["stats"]["planes"]);
  EXPECT_EQ(c["planes"], constant["stats"]["planes"]);
  EXPECT_LT(a["planes"].get<int>(), c["planes"].get<int>());
  // The estimate: <= H adaptive, above H for the flat-surface formula.
  const auto& ac = a["cusp_estimate"];
  const auto& cc = c["cusp_estimate"];
  EXPECT_LE(ac["max"].get<double>(), 0.001);
  EXPECT_GT(cc["max"].get<double>(), 0.001);
  EXPECT_LE(ac["mean"].get<double>(), ac["p99"].get<double>());
  EXPECT_LE(ac["p99"].get<double>(), ac["max"].get<double>());
  EXPECT_GT(ac["samples"].get<int>(), 1000);
  EXPECT_EQ(ac["pairs"].get<int>() + 1, a["planes"].get<int>());
  // A shorter path for the same (estimated) finish.
  EXPECT_LT(adaptive["stats"]["centre_length"].get<double>(),
            constant["stats"]["centre_length"].get<double>());
}

// ---------------------------------------------------------------------------------------
// The issue's acceptance: `scallop plan` on both paper surfaces, both strategies, balls from
// 0.05 to 1 in, H = 0.001 in, judged by the simulated cut of the program it wrote (the
// simulator is independent of how the paths were made): no gouge beyond the G-code's
// rounding (the gouge tolerance, 1e-4 in), no scallop above H where the ball can reach, and
// what the ball cannot reach reported, not hidden.
// ---------------------------------------------------------------------------------------

struct PlanVerdict {
  double maxGouge = 0.0, gougeTolerance = 0.0, maxScallop = 0.0, uncutArea = 0.0, unreachableArea = 0.0;
};

class PlanAcceptance : public PathsCli {
 protected:
  PlanVerdict plan(const std::string& example, const std::string& strategy, double radius) {
    const RunResult result = run("plan --quiet --example " + example + " --strategy " + strategy +
                                 " --tool-radius " + std::to_string(radius) + " --out out");
    EXPECT_EQ(result.exitCode, 0) << result.err;
    const auto report = nlohmann::json::parse(readFile(workDir_ / "out" / "report.json"));
    const auto& v = report["verification"];
    PlanVerdict out;
    out.maxGouge = v["max_gouge"].get<double>();
    out.gougeTolerance = v["gouge_tolerance"].get<double>();
    out.maxScallop = v["max_scallop"].get<double>();
    out.uncutArea = v["uncut_area"].get<double>();
    out.unreachableArea = v["unreachable_area"].get<double>();
    std::printf("[          ] %s %s R %.2f: gouge %.3g, scallop max %.6f (H 0.001), above H %.5f in^2, "
                "beyond reach %.4f in^2\n",
                example.c_str(), strategy.c_str(), radius, out.maxGouge, out.maxScallop, out.uncutArea,
                out.unreachableArea);
    return out;
  }
  void expectFinished(const std::string& example, const std::string& strategy, double radius) {
    const PlanVerdict v = plan(example, strategy, radius);
    EXPECT_LE(v.maxGouge, v.gougeTolerance);
    EXPECT_LE(v.maxScallop, 0.001);
    EXPECT_EQ(v.uncutArea, 0.0);
    EXPECT_EQ(v.unreachableArea, 0.0);  // no concave radius below these balls
  }
};

TEST_F(PlanAcceptance, Paper1ContourSmallBall) { expectFinished("paper-1", "contour", 0.05); }
TEST_F(PlanAcceptance, Paper1ContourQuarterInchBall) { expectFinished("paper-1", "contour", 0.25); }
TEST_F(PlanAcceptance, Paper1ContourInchBall) { expectFinished("paper-1", "contour", 1.0); }
TEST_F(PlanAcceptance, Paper1RasterSmallBall) { expectFinished("paper-1", "raster", 0.05); }
TEST_F(PlanAcceptance, Paper1RasterQuarterInchBall) { expectFinished("paper-1", "raster", 0.25); }
TEST_F(PlanAcceptance, Paper1RasterInchBall) { expectFinished("paper-1", "raster", 1.0); }
TEST_F(PlanAcceptance, Paper2ContourSmallBall) { expectFinished("paper-2", "contour", 0.05); }
TEST_F(PlanAcceptance, Paper2ContourQuarterInchBall) { expectFinished("paper-2", "contour", 0.25); }
TEST_F(PlanAcceptance, Paper2RasterQuarterInchBall) { expectFinished("paper-2", "raster", 0.25); }

// paper-2's two concave pockets are tighter than a 1 in ball: about 1.8 in^2 of it is beyond
// its reach, reported as such (a smaller tool's work). Next to the pockets' rims and at the
// surface's corners the strategies' passes leave up to 1.40 H (contour) and 2.05 H (raster)
// where a ball could reach (`--no-rest-finishing`); the rest passes finish them. The judge
// is the plan's own simulated cut and an independent one on a grid 0.0093 in apart (the
// plan's is 0.0112 in), which a peak straddled by the plan's grid would show: within H
// (and a hair of rounding) everywhere the ball reaches.
class PlanAcceptanceInchBall : public PlanAcceptance {
 protected:
  void expectFinishedWhereItReaches(const char* strategy) {
    const PlanVerdict v = plan("paper-2", strategy, 1.0);
    EXPECT_LE(v.maxGouge, v.gougeTolerance) << strategy;
    EXPECT_GT(v.unreachableArea, 1.5) << strategy;
    EXPECT_LT(v.unreachableArea, 2.2) << strategy;
    EXPECT_LE(v.maxScallop, 0.001) << strategy;
    EXPECT_EQ(v.uncutArea, 0.0) << strategy;
    const auto report = nlohmann::json::parse(readFile(workDir_ / "out" / "report.json"));
    const auto& rounds = report["rest_finishing"];
    ASSERT_TRUE(rounds.is_array()) << strategy;
    ASSERT_FALSE(rounds.empty()) << strategy;
    EXPECT_GT(rounds[0]["max_scallop_before"].get<double>(), 0.0013) << strategy;  // what it finished
    EXPECT_EQ(rounds[0]["unproven_moves"].get<std::size_t>(), 0u) << strategy;
    const RunResult judge = run("verify --example paper-2 out/toolpath.ngc --radius 1 --scallop-height 0.001 "
                                "--stock-allowance 0.01 --resolution 0.0093 --json judge.json");
    ASSERT_EQ(judge.exitCode, 0) << judge.err;
    const auto figures = nlohmann::json::parse(readFile(workDir_ / "judge.json"));
    std::printf("[          ] judge on a 0.0093 in grid: scallop max %.6f, above H %.6f in^2, gouge %.3g\n",
                figures["scallop"]["max"].get<double>(), figures["scallop"]["uncut_area"].get<double>(),
                figures["gouge"]["max"].get<double>());
    EXPECT_LE(figures["scallop"]["max"].get<double>(), 0.001 + 1e-6) << strategy;
    EXPECT_EQ(figures["scallop"]["uncut_area"].get<double>(), 0.0) << strategy;
  }
};

TEST_F(PlanAcceptanceInchBall, Paper2ContourFinishedToHWhereItReachesAndThePocketsReported) {
  expectFinishedWhereItReaches("contour");
}
TEST_F(PlanAcceptanceInchBall, Paper2RasterFinishedToHWhereItReachesAndThePocketsReported) {
  expectFinishedWhereItReaches("raster");
}

// Without rest finishing the pockets' rims and corners keep what the strategies leave there.
TEST_F(PlanAcceptance, Paper2InchBallWithoutRestFinishingLeavesMoreThanH) {
  const RunResult result = run("plan --quiet --example paper-2 --tool-radius 1 --no-rest-finishing --out out");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto report = nlohmann::json::parse(readFile(workDir_ / "out" / "report.json"));
  EXPECT_TRUE(report["rest_finishing"].is_null());
  EXPECT_GT(report["verification"]["max_scallop"].get<double>(), 0.0013);
  EXPECT_GT(report["verification"]["uncut_area"].get<double>(), 0.0);
}

// The simulator measures the scallop as the vertical gap times |n_z|, exact on planes: with a
// 0.05 in ball on paper-2's 43-degree flanks the strategy's own passes read 1.02 H at two grid
// points beside the edges (the program's nearest ball stands 0.80 H from them); the rest
// passes put a ball on each, and the reading is within H.
TEST_F(PlanAcceptance, Paper2RasterSmallBall) { expectFinished("paper-2", "raster", 0.05); }

// Rational patches through the exact route (issue 14, item 2): `scallop plan` on a surface JSON
// of two random rational bumpy graphs (weights 0.3 .. 3), both strategies, judged by the
// simulated cut (rational design heights, tested against closed forms in
// cut_simulation_test.cpp), by `scallop verify --fail-on-gouge`, and by the dense-sampling
// distance reference (distance_reference.hpp, scallop's rational points, no search of the
// code under test) from 400 of the program's ball centres.
TEST_F(PathsCli, PlanOnRationalPatchesIsGougeFreeAndFinishedToH) {
  std::mt19937_64 rng(20261128);
  scallop::Surface surface{scallop::Units::inch, {}};
  for (int i = 0; i < 2; ++i) {
    scallop::BezierPatch patch = scallop::test::randomRationalPatch(rng, 3, 3);
    for (scallop::Vec3& c : patch.control) c = 2.0 * c + scallop::Vec3{2.0 * i, 0.0, 0.0};
    surface.patches.push_back(patch);
  }
  scallop::validateSurface(surface);
  write("rational.json", scallop::surfaceToJson(surface));
  const double radius = 0.25, height = 0.002;
  for (const std::string strategy : {"raster", "contour"}) {
    SCOPED_TRACE(strategy);
    const RunResult result = run(fmt::format("plan rational.json --quiet --strategy {} --tool-radius {} "
                                             "--scallop-height {} --out out",
                                             strategy, radius, height));
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const auto report = nlohmann::json::parse(readFile(workDir_ / "out" / "report.json"));
    const auto& v = report["verification"];
    std::printf("[          ] rational %s: gouge %.3g, scallop max %.6f (H %.3f), above H %.5f in^2\n",
                strategy.c_str(), v["max_gouge"].get<double>(), v["max_scallop"].get<double>(), height,
                v["uncut_area"].get<double>());
    EXPECT_LE(v["max_gouge"].get<double>(), v["gouge_tolerance"].get<double>());
    EXPECT_LE(v["max_scallop"].get<double>(), height);
    const RunResult verify = run(fmt::format("verify rational.json out/toolpath.ngc --radius {} --scallop-height {} "
                                             "--fail-on-gouge",
                                             radius, height));
    EXPECT_EQ(verify.exitCode, 0) << verify.err;
    const scallop::GcodeProgram program = scallop::readGcodeProgram((workDir_ / "out" / "toolpath.ngc").string());
    const std::vector<scallop::SweptMove> moves = scallop::sweptMoves(program, radius);
    std::size_t checked = 0;
    double least = 1e9;
    for (std::size_t i = 0; i < moves.size(); i += std::max<std::size_t>(1, moves.size() / 400)) {
      if (moves[i].rapid) continue;
      least = std::min(least, scallop::reference::referenceDistance(surface, moves[i].end).refined);
      ++checked;
    }
    EXPECT_GT(checked, 300u);
    // No deeper than the gouge tolerance (1e-4 in, the G-code's rounding) below R.
    EXPECT_GE(least, radius - 1e-4) << strategy;
    fs::remove_all(workDir_ / "out");
  }
}
