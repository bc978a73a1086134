// End-to-end tests of `scallop orient`: each run happens in a fresh temporary directory;
// failures must exit non-zero, name the problem, and leave no output file, no temporary and
// no --svg-dir directory behind; the happy path writes the JSON and both figures, and finds
// the paper's optimum for test surface #2 (eq 19), an independent reference.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/slicing/mesh_slicing.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::readFile;
using test::RunResult;

class OrientCli : public test::CliFixture {
 protected:
  std::vector<std::string> listing(const fs::path& subdirectory) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(workDir_ / subdirectory)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
  using test::CliFixture::listing;
};

// The angle in degrees between the line of `normal` (a JSON [x, y, z]) and that of the
// paper's N* = (0.975, -0.221, -0.002) for test surface #2, eq (19); +-N* slice alike.
// Angle between `normal` and the paper's N* for surface 2 (eq 19), up to sign and the
// surface's symmetry: its control net is unchanged by swapping x and y (p_jk <-> p_kj), so
// (y, x, z) is as optimal as (x, y, z).
double degreesFromPaperOptimum(const Json& normal) {
  const double n[3] = {normal.at(0).get<double>(), normal.at(1).get<double>(), normal.at(2).get<double>()};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  double best = 180.0;
  for (const auto& reference : {std::array<double, 3>{0.975, -0.221, -0.002},
                                std::array<double, 3>{-0.221, 0.975, -0.002}}) {
    const double referenceLength = std::sqrt(reference[0] * reference[0] +
                                             reference[1] * reference[1] + reference[2] * reference[2]);
    const double cosine =
        std::abs(n[0] * reference[0] + n[1] * reference[1] + n[2] * reference[2]) / (length * referenceLength);
    best = std::min(best, std::acos(std::min(1.0, cosine)) * 180.0 / std::numbers::pi);
  }
  return best;
}

// ---------------------------------------------------------------------------------------
// Bad input: exit status 1, a message naming the problem, nothing written.
// ---------------------------------------------------------------------------------------

constexpr const char* kDegenerateSurface =
    R"({"units": "in", "patches": [{"degree": [1, 1], "control_points": )"
    R"([[[1, 2, 3], [1, 2, 3]], [[1, 2, 3], [1, 2, 3]]]}]})";

struct BadRun {
  const char* what;
  const char* inputName;  // nullptr: no input file is created
  const char* content;
  const char* arguments;  // after "orient"; output options are appended
  std::vector<std::string> messageParts;
};

const std::vector<BadRun>& badRuns() {
  static const std::vector<BadRun> runs = {
      {"tolerance zero", nullptr, "", "--example paper-2 --tolerance 0",
       {"tolerance", "'0'", "positive"}},
      {"tolerance negative", nullptr, "", "--example paper-2 --tolerance -1",
       {"tolerance", "'-1'", "positive"}},
      {"tolerance not a number", nullptr, "", "--example paper-2 --tolerance abc",
       {"tolerance", "'abc'"}},
      {"tolerance too large", nullptr, "", "--example paper-2 --tolerance 10",
       {"tolerance", "'10'", "below 5"}},
      {"tolerance finer than the grid", nullptr, "", "--example paper-2 --tolerance 1e-12",
       {"tolerance", "'1e-12'", "at least 5.7e-08 degrees"}},
      {"missing file", nullptr, "", "missing.json --tolerance 1", {"missing.json", "No such file"}},
      {"malformed JSON", "in.json", R"({"units": "in", "patches": [)", "in.json --tolerance 1",
       {"in.json", "malformed JSON"}},
      {"not a surface", "in.json", R"({"units": "in", "patch": []})", "in.json --tolerance 1",
       {"in.json", "patch"}},
      {"degenerate patch", "in.json", kDegenerateSurface, "in.json --tolerance 1",
       {"in.json", "patches[0]", "degenerate"}},
  };
  return runs;
}

TEST_F(OrientCli, BadInputFailsWithMessageAndWritesNothing) {
  for (const BadRun& bad : badRuns()) {
    SCOPED_TRACE(bad.what);
    fs::remove_all(workDir_);
    fs::create_directory(workDir_);
    if (bad.inputName != nullptr) write(bad.inputName, bad.content);
    const RunResult result =
        run(std::string("orient ") + bad.arguments + " --json out.json --svg-dir figs");
    expectCleanFailure(result, bad.messageParts, bad.inputName);
  }
}

TEST_F(OrientCli, UsageErrorsFailWithoutOutput) {
  write("in.json", kDegenerateSurface);  // never read: every command line here is rejected
  for (const char* arguments :
       {"orient --json out.json", "orient in.json --example paper-2 --json out.json",
        "orient --example nope --json out.json", "orient --example paper-2 --svg-dir -",
        "orient --example paper-2 --bogus", "orient --example paper-2 --tolerance"}) {
    SCOPED_TRACE(arguments);
    const RunResult result = run(arguments);
    EXPECT_NE(result.exitCode, 0);
    EXPECT_FALSE(result.err.empty());
    EXPECT_EQ(listing(), std::vector<std::string>{"in.json"});
  }
}

// The JSON cannot be written: the figures are not left behind, nor the directory this run
// created for them.
TEST_F(OrientCli, FailedWriteRemovesFiguresAndTheirDirectory) {
  const RunResult result = run(
      "orient --example paper-2 --tolerance 1 --no-certify --json nodir/out.json --svg-dir "
      "figs/nested");
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE(result.err.find("nodir/out.json"), std::string::npos) << result.err;
  EXPECT_TRUE(listing().empty());
}

// ---------------------------------------------------------------------------------------
// Happy paths
// ---------------------------------------------------------------------------------------

TEST_F(OrientCli, WritesJsonAndFiguresAndFindsThePapersOptimum) {
  const RunResult result = run("orient --example paper-2 --json out.json --svg-dir figs");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(result.out.empty()) << result.out;
  EXPECT_EQ(listing(), (std::vector<std::string>{"figs", "out.json"}));
  EXPECT_EQ(listing("figs"), (std::vector<std::string>{"gauss-map.svg", "stereographic.svg"}));

  // One summary line: N*, alpha*, the certificate, the segments, the time, the outputs.
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  for (const char* part : {"example paper-2", "N* = (", "alpha* = ", "certified",
                           "boundary segments", " s -> out.json, figs/gauss-map.svg"}) {
    EXPECT_NE(result.err.find(part), std::string::npos) << part << " in " << result.err;
  }

  const Json doc = Json::parse(readFile(workDir_ / "out.json"));
  EXPECT_LT(degreesFromPaperOptimum(doc.at("normal")), 1.0) << doc.at("normal").dump();
  EXPECT_EQ(doc.at("method"), "medial-axis");
  EXPECT_TRUE(doc.at("certified").get<bool>());
  // The library's default tolerance, in degrees.
  EXPECT_NEAR(doc.at("tolerance_deg").get<double>(),
              OptimalSlicingOptions{}.toleranceRad * 180.0 / std::numbers::pi, 1e-9);
  EXPECT_GT(doc.at("gauss_map").at("boundary_segments").get<std::size_t>(), 0u);

  for (const char* figure : {"figs/gauss-map.svg", "figs/stereographic.svg"}) {
    const std::string svg = readFile(workDir_ / figure);
    EXPECT_EQ(svg.rfind("<svg", 0), 0u) << figure;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << figure;
    EXPECT_NE(svg.find("class=\"circle\""), std::string::npos) << figure;
  }
}

// A rational patch in the surface JSON (weights): a torus's outer quarter, whose normals
// fill an octant of the sphere: alpha* = 45 deg, certified. paths and plan take it too
// (rational sections, distances and the simulated cut).
TEST_F(OrientCli, TakesARationalPatchAsEveryCommandDoes) {
  const double s = std::sqrt(0.5);
  Json patch;
  patch["degree"] = {2, 2};
  Json points = Json::array(), weights = Json::array();
  const double arc[3][2] = {{1, 0}, {1, 1}, {0, 1}}, profile[3][2] = {{4, 0}, {4, 1}, {3, 1}};
  const double w[3] = {1, s, 1};
  for (int j = 0; j < 3; ++j) {
    Json row = Json::array(), weightRow = Json::array();
    for (int k = 0; k < 3; ++k) {
      row.push_back({profile[k][0] * arc[j][0], profile[k][0] * arc[j][1], profile[k][1]});
      weightRow.push_back(w[j] * w[k]);
    }
    points.push_back(row);
    weights.push_back(weightRow);
  }
  patch["control_points"] = points;
  patch["weights"] = weights;
  write("torus.json", Json{{"units", "mm"}, {"patches", {patch}}}.dump());
  const RunResult orient = run("orient torus.json");
  ASSERT_EQ(orient.exitCode, 0) << orient.err;
  const Json json = Json::parse(orient.out);
  EXPECT_NEAR(json["alpha_deg"].get<double>(), 45.0, 1e-9);
  EXPECT_TRUE(json["certified"].get<bool>());
  EXPECT_GE(json["certified_alpha_deg"].get<double>(), 45.0 - 1e-3);
  const RunResult paths = run("paths torus.json --tool-radius 1 --scallop-height 0.01 --json p.json");
  EXPECT_EQ(paths.exitCode, 0) << paths.err;
  const RunResult plan = run("plan torus.json --tool-radius 1 --scallop-height 0.01 --out out --quiet");
  ASSERT_EQ(plan.exitCode, 0) << plan.err;
  const Json report = Json::parse(readFile(workDir_ / "out" / "report.json"));
  EXPECT_LE(report["verification"]["max_gouge"].get<double>(), report["verification"]["gouge_tolerance"].get<double>());
}

TEST_F(OrientCli, JsonGoesToStandardOutputByDefault) {
  const RunResult result = run("orient --example paper-1 --tolerance 1 --no-certify");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;  // no summary when stdout carries the JSON
  EXPECT_TRUE(listing().empty());
  const Json doc = Json::parse(result.out);
  EXPECT_EQ(doc.at("tolerance_deg").get<double>(), 1.0);
  EXPECT_FALSE(doc.at("certified").get<bool>());
  EXPECT_EQ(doc.at("certificate_cells").get<std::size_t>(), 0u);
}

TEST_F(OrientCli, ReadsStandardInputAndCreatesNestedFigureDirectories) {
  const std::string input =
      (fs::path(SCALLOP_EXAMPLES_DIR) / "surfaces" / "paper-2.json").string();
  const RunResult result =
      run("orient - --tolerance 1 --no-certify --json - --svg-dir out/figs", input);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_LT(degreesFromPaperOptimum(Json::parse(result.out).at("normal")), 1.0);
  EXPECT_EQ(listing("out/figs"),
            (std::vector<std::string>{"gauss-map.svg", "stereographic.svg"}));
}

// A corner where r_u x r_v vanishes to first order (paper-1 with p01 = p00) is a surface like
// any other; one where it vanishes to second order (p10 = p00 too) is refused, the message
// naming the corner.
TEST_F(OrientCli, CornersWhereTheNormalVanishes) {
  Surface surface = exampleSurface("paper-1");
  surface.patches[0].control[1] = surface.patches[0].control[0];
  write("corner.json", surfaceToJson(surface));
  const RunResult accepted = run("orient corner.json --json out.json");
  ASSERT_EQ(accepted.exitCode, 0) << accepted.err;
  const Json json = Json::parse(readFile(workDir_ / "out.json"));
  EXPECT_TRUE(json.at("certified").get<bool>());
  EXPECT_EQ(json.at("method").get<std::string>(), "medial-axis");
  surface.patches[0].control[4] = surface.patches[0].control[0];
  write("second.json", surfaceToJson(surface));
  const RunResult refused = run("orient second.json --json out2.json");
  EXPECT_EQ(refused.exitCode, 1);
  for (const char* part : {"scallop: error: second.json", "patches[0]", "(u, v) = (0, 0)", "at a corner"}) {
    EXPECT_NE(refused.err.find(part), std::string::npos) << refused.err;
  }
  EXPECT_FALSE(fs::exists(workDir_ / "out2.json"));
}

TEST_F(OrientCli, Help) {
  const RunResult help = run("orient --help");
  EXPECT_EQ(help.exitCode, 0);
  for (const char* part : {"SURFACE", "--example", "--tolerance", "--json", "--svg-dir",
                           "--no-certify", "scallop orient"}) {
    EXPECT_NE(help.out.find(part), std::string::npos) << part;
  }
  EXPECT_TRUE(listing().empty());
}

// ---- STL meshes: `orient part.stl` ----

// A binary STL of triangles with the given normals (each on its own, placed apart), written
// here: 80-byte header, count, 50 bytes per triangle, little-endian floats.
std::string binaryStlOf(const std::vector<std::array<float, 3>>& normals, bool zeroAreaToo = false) {
  std::string out(80, ' ');
  const auto u32 = [&](std::uint32_t x) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((x >> (8 * i)) & 0xff));
  };
  const auto f32 = [&](float f) {
    std::uint32_t x = 0;
    std::memcpy(&x, &f, 4);
    u32(x);
  };
  u32(static_cast<std::uint32_t>(normals.size() + (zeroAreaToo ? 1 : 0)));
  const auto triangle = [&](const std::array<std::array<float, 3>, 3>& v) {
    for (int k = 0; k < 3; ++k) f32(0.0f);
    for (const auto& p : v)
      for (const float c : p) f32(c);
    out += std::string(2, '\0');
  };
  float x = 0.0f;
  for (const auto& n : normals) {
    // Two edges orthogonal to n: (b - a) x (c - a) points along n.
    const std::array<float, 3> helper = std::abs(n[0]) < 0.9f ? std::array<float, 3>{1, 0, 0} : std::array<float, 3>{0, 1, 0};
    const std::array<float, 3> u = {n[1] * helper[2] - n[2] * helper[1], n[2] * helper[0] - n[0] * helper[2],
                                    n[0] * helper[1] - n[1] * helper[0]};
    const std::array<float, 3> v = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
    triangle({{{x, 0, 0}, {x + u[0], u[1], u[2]}, {x + v[0], v[1], v[2]}}});
    x += 10.0f;
  }
  if (zeroAreaToo) triangle({{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}});
  return out;
}

const std::vector<std::array<float, 3>> kSomeNormals = {
    {0.1f, 0.2f, 1.0f}, {-0.3f, 0.1f, 0.9f}, {0.2f, -0.4f, 0.8f}, {0.5f, 0.5f, 0.6f}, {-0.2f, -0.3f, 1.0f}};

TEST_F(OrientCli, AnStlMeshGivesTheLibrarysDirectionAsJson) {
  const std::string bytes = binaryStlOf(kSomeNormals);
  write("part.stl", bytes);
  const RunResult result = run("orient part.stl --json out.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("5 triangles (binary STL)"), std::string::npos) << result.err;
  const Json doc = Json::parse(readFile(workDir_ / "out.json"));
  const scallop::StlMesh mesh = scallop::parseStl(bytes, "part.stl", {});
  const scallop::MeshSlicing expected = scallop::optimalMeshSlicing(mesh.mesh);
  EXPECT_EQ(doc["input"], "mesh");
  EXPECT_EQ(doc["format"], "binary");
  EXPECT_EQ(doc["units"], "mm");
  EXPECT_EQ(doc["triangles"].get<std::size_t>(), 5u);
  // Full precision: the same doubles as the library's.
  EXPECT_EQ(doc["normal"][0].get<double>(), expected.normal.x);
  EXPECT_EQ(doc["normal"][1].get<double>(), expected.normal.y);
  EXPECT_EQ(doc["normal"][2].get<double>(), expected.normal.z);
  EXPECT_EQ(doc["alpha_deg"].get<double>(), expected.alphaRad * 180.0 / std::numbers::pi);
  // JSON on standard output when no output is named; --units in recorded.
  const RunResult piped = run("orient part.stl --units in");
  ASSERT_EQ(piped.exitCode, 0) << piped.err;
  EXPECT_EQ(Json::parse(piped.out)["units"], "in");
}

TEST_F(OrientCli, BadStlMeshesFailCleanly) {
  write("empty.stl", "");
  expectCleanFailure(run("orient empty.stl --json out.json"), {"empty.stl", "empty"}, "empty.stl");
  std::filesystem::remove(workDir_ / "empty.stl");
  write("z.stl", binaryStlOf(kSomeNormals, true));
  expectCleanFailure(run("orient z.stl --json out.json"), {"z.stl", "triangle 5 has zero area", "--drop-zero-area"},
                     "z.stl");
  expectCleanFailure(run("orient z.stl --svg-dir figs"), {"z.stl", "--svg-dir", "not for a mesh"}, "z.stl");
  expectCleanFailure(run("orient z.stl --patches 0"), {"--patches", "not for a mesh"}, "z.stl");
  const RunResult dropped = run("orient z.stl --drop-zero-area --json out.json");
  ASSERT_EQ(dropped.exitCode, 0) << dropped.err;
  const Json doc = Json::parse(readFile(workDir_ / "out.json"));
  EXPECT_EQ(doc["zero_area_dropped"].get<std::size_t>(), 1u);
  EXPECT_EQ(doc["triangles"].get<std::size_t>(), 5u);
  std::filesystem::remove(workDir_ / "out.json");
  std::filesystem::remove(workDir_ / "z.stl");
  expectCleanFailure(run("orient --example paper-1 --units in"), {"--units", "STL"}, nullptr);
}

}  // namespace
}  // namespace scallop
