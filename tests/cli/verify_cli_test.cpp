// End-to-end tests of `scallop verify`: the main job's programs verified, the exit status of
// --fail-on-gouge, and bad input refused with one line and nothing written.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <vector>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"

namespace scallop::test {
namespace {

namespace fs = std::filesystem;

class VerifyCli : public CliFixture {};

TEST_F(VerifyCli, VerifiesTheMainJobsContourProgram) {
  ASSERT_EQ(run("plan --out p --quiet").exitCode, 0);
  // A finishing plan: the stock is what roughing left, 0.01 in over the surface (the links
  // clear 0.02 in), not a block its local retracts would plunge into.
  const RunResult result = run("verify --example paper-1 p/toolpath.ngc --radius 0.25 --stock-allowance 0.01 "
                               "--json v.json --svg v.svg");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("deepest gouge"), std::string::npos) << result.err;
  const auto report = nlohmann::json::parse(readFile(workDir_ / "v.json"));
  EXPECT_EQ(report["surface"], "example paper-1");
  EXPECT_EQ(report["units"], "in");
  EXPECT_EQ(report["moves"]["rapids_cutting"].get<int>(), 0);  // rapids run above the stock
  EXPECT_GT(report["grid"]["surface_points"].get<int>(), 250000);
  // Lifted to the drop envelope, the plan cuts in by no more than the G-code's rounding.
  EXPECT_LT(report["gouge"]["max"].get<double>(), 1e-4);
  EXPECT_LT(report["scallop"]["p99"].get<double>(), 0.002);
  const std::string svg = readFile(workDir_ / "v.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("scallop (in)"), std::string::npos);
}

TEST_F(VerifyCli, FailOnGougeGivesStatusTwoAndStillWritesTheReport) {
  // The in-plane raster (no drop envelope) gouges: what --fail-on-gouge is for.
  ASSERT_EQ(run("plan --strategy raster --no-drop-envelope --out r --quiet").exitCode, 0);
  const RunResult plain = run("verify --example paper-1 r/toolpath.ngc --radius 0.25 --resolution 0.02");
  EXPECT_EQ(plain.exitCode, 0) << plain.err;
  const RunResult strict =
      run("verify --example paper-1 r/toolpath.ngc --radius 0.25 --resolution 0.02 --fail-on-gouge --json v.json");
  EXPECT_EQ(strict.exitCode, 2) << strict.err;
  const auto report = nlohmann::json::parse(readFile(workDir_ / "v.json"));
  EXPECT_TRUE(report["gouge"]["over_tolerance"].get<bool>());
  EXPECT_GT(report["gouge"]["max"].get<double>(), 0.15);
  // A file surface and the program given as two positionals; JSON on standard output.
  const RunResult piped = run("verify '" SCALLOP_EXAMPLES_DIR "/surfaces/paper-1.json' r/toolpath.ngc --radius 0.25 "
                              "--resolution 0.05 --json -");
  ASSERT_EQ(piped.exitCode, 0) << piped.err;
  EXPECT_GT(nlohmann::json::parse(piped.out)["gouge"]["max"].get<double>(), 0.1);
}

TEST_F(VerifyCli, BadInputFailsWithOneLineAndNothingWritten) {
  write("bad.ngc", "G20\nG90\nG0 X0 Y0 Z1\nG91\nG1 X1\n");
  expectCleanFailure(run("verify --example paper-1 bad.ngc --radius 0.25 --json v.json --svg v.svg"),
                     {"bad.ngc:4:", "G91"}, "bad.ngc");
  fs::remove(workDir_ / "bad.ngc");
  write("mm.ngc", "G21\nG0 X0 Y0 Z1\n");
  expectCleanFailure(run("verify --example paper-1 mm.ngc --radius 0.25 --json v.json"), {"mm.ngc", "G21", "inches"},
                     "mm.ngc");
  fs::remove(workDir_ / "bad.ngc");
  fs::remove(workDir_ / "mm.ngc");
  write("ok.ngc", "G20\nG0 X0 Y0 Z1\n");
  expectCleanFailure(run("verify --example paper-1 ok.ngc --radius 0 --json v.json"), {"tool radius", "'0'"}, "ok.ngc");
  expectCleanFailure(run("verify --example paper-1 ok.ngc --radius 0.25 --resolution 0.00001 --json v.json"),
                     {"budget"}, "ok.ngc");
  expectCleanFailure(run("verify --example paper-1 ok.ngc --radius 0.25 --scallop-height 0.3"),
                     {"scallop height", "0.3"}, "ok.ngc");
  expectCleanFailure(run("verify --example paper-1 missing.ngc --radius 0.25"), {"missing.ngc"}, "ok.ngc");
  // A surface file and --example together is a usage error (CLI11's status), nothing written.
  const RunResult usage = run("verify --example paper-1 ok.ngc ok.ngc --radius 0.25 --json v.json");
  EXPECT_NE(usage.exitCode, 0);
  EXPECT_FALSE(fs::exists(workDir_ / "v.json"));
}

// A plane as a bilinear patch (JSON) and as two triangles (ASCII STL, written here): the same
// program verified against either gives the same figures (the mesh's design is the same plane).
TEST_F(VerifyCli, AnStlMeshIsVerifiedAsTheSurfaceItTriangulates) {
  write("plane.json", R"({"units": "mm", "patches": [{"degree": [1, 1], "control_points": )"
                      R"([[[0, 0, 0], [0, 20, 10]], [[20, 0, 0], [20, 20, 10]]]}]})");
  write("plane.stl", "solid plane\n"
                     "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 20 0 0\nvertex 20 20 10\nendloop\nendfacet\n"
                     "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 20 20 10\nvertex 0 20 10\nendloop\nendfacet\n"
                     "endsolid plane\n");
  ASSERT_EQ(run("plan plane.json --tool-radius 3 --scallop-height 0.05 --out p --quiet").exitCode, 0);
  const std::string common = " p/toolpath.ngc --radius 3 --scallop-height 0.05 --stock-allowance 0.5 --resolution 0.1";
  const RunResult patch = run("verify plane.json" + common + " --json patch.json");
  ASSERT_EQ(patch.exitCode, 0) << patch.err;
  const RunResult mesh = run("verify plane.stl" + common + " --units mm --json mesh.json --svg mesh.svg");
  ASSERT_EQ(mesh.exitCode, 0) << mesh.err;
  const auto a = nlohmann::json::parse(readFile(workDir_ / "patch.json"));
  const auto b = nlohmann::json::parse(readFile(workDir_ / "mesh.json"));
  EXPECT_EQ(b["surface"], "plane.stl");
  EXPECT_EQ(b["units"], "mm");
  EXPECT_NEAR(b["scallop"]["max"].get<double>(), a["scallop"]["max"].get<double>(), 1e-9);
  // The deepest vertical gouge is a ball beside the edge touching it at its equator (sqrt(2 R
  // eps), the envelope's eps): it sits on the footprint's edge points, which the patch's Newton
  // solve and the triangles' barycentric test each take within their own rounding. Both are
  // under the tolerance.
  EXPECT_LE(b["gouge"]["max"].get<double>(), 0.0025);
  EXPECT_LE(a["gouge"]["max"].get<double>(), 0.0025);
  EXPECT_GT(a["scallop"]["max"].get<double>(), 0.0);
  EXPECT_LE(a["scallop"]["max"].get<double>(), 0.05);
  EXPECT_NEAR(b["grid"]["surface_points"].get<double>(), a["grid"]["surface_points"].get<double>(), 500.0);
  EXPECT_EQ(readFile(workDir_ / "mesh.svg").rfind("<svg", 0), 0u);
  // Options that select a surface's patches are refused for a mesh, and mesh options for a
  // surface; a broken mesh names the file; nothing written.
  const auto refused = [&](const std::string& command, const std::vector<std::string>& parts) {
    const RunResult result = run(command);
    EXPECT_EQ(result.exitCode, 1) << command;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    for (const std::string& part : parts) EXPECT_NE(result.err.find(part), std::string::npos) << result.err;
    EXPECT_FALSE(fs::exists(workDir_ / "x.json")) << command;
  };
  refused("verify plane.stl" + common + " --patches 0 --json x.json", {"--patches", "mesh"});
  refused("verify plane.json" + common + " --units mm --json x.json", {"--units", "STL"});
  write("broken.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n");
  refused("verify broken.stl" + common + " --json x.json", {"broken.stl"});
}

}  // namespace
}  // namespace scallop::test
