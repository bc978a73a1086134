// Tests for surface_io.hpp and the teapot examples: the .bpt reader (general degrees, every
// malformed variant with file, line and value named, bitwise agreement with JSON), the choice
// of format in readSurface, patch selection, the teapot's files against the built-in examples
// bit for bit (and against a reading of the JSON independent of the library), and the CLI's
// .bpt input and --patches.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "support/message_checks.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/surface_io.hpp"

namespace scallop {
namespace {

using Json = nlohmann::json;

const std::string kSurfacesDir = std::string(SCALLOP_EXAMPLES_DIR) + "/surfaces/";

std::uint64_t bitsOf(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// Bit-for-bit equality of two surfaces (-0.0 against 0.0 or one ulp would show).
void expectSameSurface(const Surface& actual, const Surface& expected, const std::string& what) {
  EXPECT_EQ(actual.units, expected.units) << what;
  ASSERT_EQ(actual.patches.size(), expected.patches.size()) << what;
  for (std::size_t i = 0; i < expected.patches.size(); ++i) {
    const BezierPatch& a = actual.patches[i];
    const BezierPatch& e = expected.patches[i];
    EXPECT_EQ(a.degreeU, e.degreeU) << what << " patch " << i;
    EXPECT_EQ(a.degreeV, e.degreeV) << what << " patch " << i;
    ASSERT_EQ(a.control.size(), e.control.size()) << what << " patch " << i;
    for (std::size_t c = 0; c < e.control.size(); ++c) {
      const bool same = bitsOf(a.control[c].x) == bitsOf(e.control[c].x) &&
                        bitsOf(a.control[c].y) == bitsOf(e.control[c].y) &&
                        bitsOf(a.control[c].z) == bitsOf(e.control[c].z);
      EXPECT_TRUE(same) << what << " patch " << i << " point " << c;
    }
  }
}

// .bpt text of a surface, every coordinate in 17 significant digits (exact round trip).
std::string toBpt(const Surface& surface) {
  std::string text = fmt::format("{}\n", surface.patches.size());
  for (const BezierPatch& patch : surface.patches) {
    text += fmt::format("{} {}\n", patch.degreeU, patch.degreeV);
    for (const Vec3& p : patch.control) text += fmt::format("{:.17g} {:.17g} {:.17g}\n", p.x, p.y, p.z);
  }
  return text;
}

std::string bptError(const std::string& text, SurfaceCheck check = SurfaceCheck::full) {
  try {
    parseBptSurface(text, "s.bpt", check);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

using test::expectMessageContains;

// A graph patch of degrees (m, n) over a jittered grid, random heights: regular.
BezierPatch randomPatch(std::mt19937_64& rng, int m, int n) {
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::uniform_real_distribution<double> height(-1.0, 1.0);
  BezierPatch patch;
  patch.degreeU = m;
  patch.degreeV = n;
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k <= n; ++k) patch.control.push_back({k + jitter(rng), j + jitter(rng), height(rng)});
  }
  return patch;
}

// ---------------------------------------------------------------------------------------
// The .bpt reader
// ---------------------------------------------------------------------------------------

TEST(Bpt, ParsesGeneralDegreesRowByRow) {
  const std::string text =
      "2\n"
      "1 2\n"
      "0 0 0\n1 0 0.5\n2 0 0\n"  // row j = 0: p_00 p_01 p_02
      "0 1 0\n1 1 -0.5\n2 1 0\n"
      "3 3\n";
  std::string full = text;
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) full += fmt::format("{} {} {}\n", k, j, (j * k) % 3);
  }
  const Surface surface = parseBptSurface(full, "s.bpt");
  EXPECT_EQ(surface.units, Units::inch);
  ASSERT_EQ(surface.patches.size(), 2u);
  EXPECT_EQ(surface.patches[0].degreeU, 1);
  EXPECT_EQ(surface.patches[0].degreeV, 2);
  EXPECT_EQ(surface.patches[0].at(0, 1), (Vec3{1.0, 0.0, 0.5}));
  EXPECT_EQ(surface.patches[0].at(1, 1), (Vec3{1.0, 1.0, -0.5}));
  EXPECT_EQ(surface.patches[1].degreeU, 3);
  EXPECT_EQ(surface.patches[1].at(2, 1), (Vec3{1.0, 2.0, 2.0}));
  EXPECT_EQ(surface.patches[1].at(3, 0), (Vec3{0.0, 3.0, 0.0}));
}

TEST(Bpt, AcceptsBlankLinesTabsCrlfByteOrderMarkAndPlusSigns) {
  const std::string plain = "1\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n";
  const std::string decorated =
      "\xEF\xBB\xBF\r\n  1  \r\n\r\n1\t1\r\n0 0 0\r\n\n +1\t0   0 \r\n0 +1 0\r\n1 1 1e0\r\n\r\n";
  expectSameSurface(parseBptSurface(decorated, "d.bpt"), parseBptSurface(plain, "p.bpt"),
                    "decorated");
}

TEST(Bpt, RoundTripsRandomSurfacesBitForBitAsJsonDoes) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> degree(1, 5);
  for (int trial = 0; trial < 20; ++trial) {
    Surface surface{Units::inch, {}};
    const int patches = 1 + trial % 3;
    for (int i = 0; i < patches; ++i) surface.patches.push_back(randomPatch(rng, degree(rng), degree(rng)));
    const Surface fromBpt = parseBptSurface(toBpt(surface), "r.bpt");
    expectSameSurface(fromBpt, surface, fmt::format("trial {}", trial));
    expectSameSurface(fromBpt, parseSurface(surfaceToJson(surface), "r.json"),
                      fmt::format("trial {} against JSON", trial));
  }
}

TEST(Bpt, RejectsMalformedTextNamingFileLineAndValue) {
  const std::string point = "0 0 0\n";
  const std::string unitSquare = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
  struct Case {
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"", {"s.bpt:1:", "empty", "number of patches"}},
      {"  \n\t\n", {"s.bpt:1:", "empty"}},
      {"0\n", {"s.bpt:1:", "number of patches", "'0'"}},
      {"-1\n1 1\n" + unitSquare, {"s.bpt:1:", "'-1'"}},
      {"two\n", {"s.bpt:1:", "'two'"}},
      {"1.0\n", {"s.bpt:1:", "'1.0'"}},
      {"1 1\n", {"s.bpt:1:", "'1 1'"}},
      {"99999999999999999999999\n", {"s.bpt:1:", "'99999999999999999999999'"}},
      {"1\n3\n", {"s.bpt:2:", "patches[0]", "degrees 'm n'", "'3'"}},
      {"1\n3 3 3\n", {"s.bpt:2:", "patches[0]", "'3 3 3'"}},
      {"1\nx 3\n", {"s.bpt:2:", "'x 3'"}},
      {"1\n-1 1\n", {"s.bpt:2:", "'-1 1'"}},
      {"1\n0 1\n0 0 0\n0 1 0\n", {"s.bpt:2:", "degree 0", "u (the first)", "'0 1'"}},
      {"1\n1 0\n", {"s.bpt:2:", "degree 0", "v (the second)"}},
      {"1\n21 1\n", {"s.bpt:2:", "degree 21", "maximum 20", "'21 1'"}},
      {"1\n1 999999999999\n", {"s.bpt:2:", "maximum 20"}},
      {"1\n1 1\n0 0 0\n1 0\n0 1 0\n1 1 0\n", {"s.bpt:4:", "patches[0]", "p_0,1", "'1 0'"}},
      {"1\n1 1\n0 0 0\n1 0 0 0\n", {"s.bpt:4:", "three numbers", "'1 0 0 0'"}},
      {"1\n1 1\n0 0 0\n1 0 nan\n", {"s.bpt:4:", "p_0,1", "finite", "'nan'"}},
      {"1\n1 1\n0 0 0\n1 0 0\n-inf 1 0\n", {"s.bpt:5:", "p_1,0", "finite", "'-inf'"}},
      {"1\n1 1\n0 0 0\n1 0 0\n0 1e999 0\n", {"s.bpt:5:", "beyond the range", "'1e999'"}},
      {"1\n1 1\n0 0 0\n1mm 0 0\n", {"s.bpt:4:", "'1mm' is not a number"}},
      {"1\n1 1\n0 0 0\n1,0,0\n", {"s.bpt:4:", "'1,0,0'"}},
      {"1\n1 1\n0 0 0\n1 0 0\n", {"s.bpt", "ends", "after line 4", "after 2 of its 4 control points", "'1'"}},
      {"2\n1 1\n" + unitSquare, {"s.bpt", "ends", "after line 6", "patches[1]", "'2'"}},
      {"1\n1 1\n" + unitSquare + "1 1\n", {"s.bpt:7:", "trailing", "'1 1'"}},
      {"1\n1 1\n" + unitSquare + "\nend\n", {"s.bpt:8:", "trailing", "'end'"}},
      {"1\n1 1\n" + unitSquare + point, {"s.bpt:7:", "trailing", "'0 0 0'"}},
  };
  for (const Case& c : cases) {
    expectMessageContains(bptError(c.text), c.parts, c.text);
    // The form is checked whatever the validation.
    expectMessageContains(bptError(c.text, SurfaceCheck::formOnly), c.parts, c.text);
  }
}

TEST(Bpt, ValidatesUnlessAskedForTheFormOnly) {
  // Collinear control points: well formed, but r_u x r_v = 0 everywhere.
  const std::string flat = "1\n1 1\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n";
  expectMessageContains(bptError(flat), {"s.bpt:", "patches[0]", "degenerate"}, flat);
  EXPECT_EQ(bptError(flat, SurfaceCheck::formOnly), "");
  const std::string huge = "1\n1 1\n0 0 0\n1e30 0 0\n0 1 0\n1 1 0\n";
  expectMessageContains(bptError(huge), {"s.bpt:", "patches[0]", "largest |coordinate|"}, huge);
}

TEST(Bpt, ReadSurfaceChoosesTheFormatByExtensionThenContent) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const Surface paper = exampleSurface("paper-2");
  struct File {
    std::string name;
    std::string content;
  };
  const std::vector<File> files = {{"scallop_io_test.bpt", toBpt(paper)},
                                   {"scallop_io_test.BPT", toBpt(paper)},
                                   {"scallop_io_test_bpt.txt", toBpt(paper)},
                                   {"scallop_io_test_json.txt", "\n  " + surfaceToJson(paper)},
                                   {"scallop_io_test.json", surfaceToJson(paper)}};
  for (const File& file : files) {
    const std::filesystem::path path = dir / file.name;
    std::ofstream(path, std::ios::binary) << file.content;
    expectSameSurface(readSurface(path.string()), paper, file.name);
    std::filesystem::remove(path);
  }
  // The extension decides over the content: .bpt text named .json is malformed JSON.
  const std::filesystem::path misnamed = dir / "scallop_io_test_misnamed.json";
  std::ofstream(misnamed, std::ios::binary) << toBpt(paper);
  try {
    readSurface(misnamed.string());
    ADD_FAILURE() << "no error for .bpt text in a .json file";
  } catch (const Error& error) {
    expectMessageContains(error.what(), {misnamed.string(), "malformed JSON"}, "misnamed");
  }
  std::filesystem::remove(misnamed);
}

// ---------------------------------------------------------------------------------------
// Patch selection
// ---------------------------------------------------------------------------------------

TEST(PatchSelection, ParsesIndicesAndRanges) {
  using Indices = std::vector<std::size_t>;
  EXPECT_EQ(parsePatchSelection("4", 32), (Indices{4}));
  EXPECT_EQ(parsePatchSelection("4-7,12", 32), (Indices{4, 5, 6, 7, 12}));
  EXPECT_EQ(parsePatchSelection(" 12 , 4 - 5 ,0", 32), (Indices{0, 4, 5, 12}));
  EXPECT_EQ(parsePatchSelection("31-31", 32), (Indices{31}));
  EXPECT_EQ(parsePatchSelection("0-31", 32).size(), 32u);
}

TEST(PatchSelection, RejectsBadListsNamingTheItem) {
  struct Case {
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"", {"''", "such as"}},
      {" ", {"such as"}},
      {"32", {"'32'", "patch 32", "out of range", "32 patches, 0-31"}},
      {"4-40", {"patch 40", "'4-40'", "0-31"}},
      {"99999999999999999999999", {"'99999999999999999999999'"}},
      {"7-4", {"'7-4'", "backwards"}},
      {"4-7,5", {"patch 5", "twice"}},
      {"4,,5", {"'' is not an index"}},
      {"4,", {"'' is not an index"}},
      {"-4", {"'-4'"}},
      {"a", {"'a'"}},
      {"1.5", {"'1.5'"}},
      {"4-", {"'4-'"}},
      {"1-2-3", {"'1-2-3'"}},
  };
  for (const Case& c : cases) {
    std::string message;
    try {
      parsePatchSelection(c.text, 32);
    } catch (const Error& error) {
      message = error.what();
    }
    expectMessageContains(message, c.parts, c.text);
    expectMessageContains(message, {"invalid patch selection"}, c.text);
  }
}

TEST(PatchSelection, SelectsInOrderAndChecksIndices) {
  const Surface teapot = exampleSurface("teapot");
  const std::vector<std::size_t> indices = {12, 4};
  const Surface selected = selectPatches(teapot, indices);
  ASSERT_EQ(selected.patches.size(), 2u);
  EXPECT_EQ(selected.units, Units::inch);
  EXPECT_EQ(selected.patches[0].control, teapot.patches[12].control);
  EXPECT_EQ(selected.patches[1].control, teapot.patches[4].control);
  const std::vector<std::size_t> outside = {32};
  EXPECT_THROW(selectPatches(teapot, outside), Error);
}

// ---------------------------------------------------------------------------------------
// The teapot: files, built-in examples, the data itself
// ---------------------------------------------------------------------------------------

TEST(Teapot, FilesAndBuiltInExampleAreTheSameBitForBit) {
  // Until collapsed edges are accepted the knob and bottom patches fail validation: the
  // files are compared for their form and numbers.
  const Surface teapot = exampleSurface("teapot");
  ASSERT_EQ(teapot.patches.size(), 32u);
  const Surface bpt = readSurface(kSurfacesDir + "teapot.bpt", SurfaceCheck::formOnly);
  const Surface json = readSurface(kSurfacesDir + "teapot.json", SurfaceCheck::formOnly);
  expectSameSurface(bpt, teapot, "teapot.bpt");
  expectSameSurface(json, teapot, "teapot.json");
  // The JSON file read by nlohmann directly, independently of the library's reader.
  std::ifstream in(kSurfacesDir + "teapot.json");
  const Json document = Json::parse(in);
  EXPECT_EQ(document["units"], "in");
  ASSERT_EQ(document["patches"].size(), 32u);
  for (std::size_t i = 0; i < 32; ++i) {
    const Json& patch = document["patches"][i];
    EXPECT_EQ(patch["degree"], Json::parse("[3, 3]"));
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) {
        const Json& p = patch["control_points"][j][k];
        const Vec3 expected = teapot.patches[i].at(j, k);
        EXPECT_EQ(bitsOf(p[0].get<double>()), bitsOf(expected.x)) << i << " " << j << k;
        EXPECT_EQ(bitsOf(p[1].get<double>()), bitsOf(expected.y)) << i << " " << j << k;
        EXPECT_EQ(bitsOf(p[2].get<double>()), bitsOf(expected.z)) << i << " " << j << k;
      }
    }
  }
  // And the .bpt file is what toBpt writes, up to the spelling of the numbers.
  expectSameSurface(parseBptSurface(toBpt(teapot), "t.bpt", SurfaceCheck::formOnly), bpt, "toBpt");
}

TEST(Teapot, PartsAreRangesOfTheWhole) {
  const Surface teapot = exampleSurface("teapot");
  const std::vector<std::pair<std::string, std::pair<std::size_t, std::size_t>>> parts = {
      {"teapot-rim", {0, 4}},     {"teapot-body", {4, 12}},  {"teapot-handle", {12, 16}},
      {"teapot-spout", {16, 20}}, {"teapot-lid", {20, 28}},  {"teapot-bottom", {28, 32}}};
  for (const auto& [name, range] : parts) {
    const Surface part = exampleSurface(name);
    Surface expected{Units::inch, {}};
    for (std::size_t i = range.first; i < range.second; ++i) expected.patches.push_back(teapot.patches[i]);
    expectSameSurface(part, expected, name);
  }
}

TEST(Teapot, ApexesAreWhereTheyShouldBeAndEveryPatchIsRegular) {
  const Surface teapot = exampleSurface("teapot");
  for (std::size_t i = 0; i < teapot.patches.size(); ++i) {
    const BezierPatch& patch = teapot.patches[i];
    ASSERT_EQ(patch.degreeU, 3);
    ASSERT_EQ(patch.degreeV, 3);
    // Boundary rows (j = 0, 3) and columns (k = 0, 3) collapsed to one point.
    std::vector<std::string> collapsed;
    for (int j : {0, 3}) {
      if (patch.at(j, 0) == patch.at(j, 1) && patch.at(j, 1) == patch.at(j, 2) &&
          patch.at(j, 2) == patch.at(j, 3)) {
        collapsed.push_back(fmt::format("row {}", j));
      }
    }
    for (int k : {0, 3}) {
      if (patch.at(0, k) == patch.at(1, k) && patch.at(1, k) == patch.at(2, k) &&
          patch.at(2, k) == patch.at(3, k)) {
        collapsed.push_back(fmt::format("column {}", k));
      }
    }
    const bool apex = (i >= 20 && i < 24) || i >= 28;
    if (apex) {
      // Row 0 is the apex on the axis: the knob's top (z = 3.15), the bottom's centre (0).
      ASSERT_EQ(collapsed, (std::vector<std::string>{"row 0"})) << "patch " << i;
      EXPECT_EQ(patch.at(0, 0), (Vec3{0.0, 0.0, i < 24 ? 3.15 : 0.0})) << "patch " << i;
    } else {
      EXPECT_TRUE(collapsed.empty()) << "patch " << i;
    }
    // Every patch is regular, the apexes with their normals' limits (bezier.hpp).
    EXPECT_NO_THROW(validateSurface(Surface{Units::inch, {patch}})) << "patch " << i;
  }
  // The teapot stands on z = 0 and is 3.15 in tall.
  EXPECT_EQ(surfaceScale(teapot), 3.525);  // the spout's tip, x = 3.525
}

// ---------------------------------------------------------------------------------------
// The CLI: .bpt files and --patches
// ---------------------------------------------------------------------------------------

class SurfaceIoCli : public test::CliFixture {};

double alphaOf(const test::RunResult& result) {
  return Json::parse(result.out)["alpha_deg"].get<double>();
}

TEST_F(SurfaceIoCli, OrientReadsBptFilesAndStandardInput) {
  write("p1.bpt", toBpt(exampleSurface("paper-1")));
  write("p1", toBpt(exampleSurface("paper-1")));
  const test::RunResult example = run("orient --example paper-1");
  ASSERT_EQ(example.exitCode, 0) << example.err;
  for (const std::string arguments : {"orient p1.bpt", "orient p1", "orient -"}) {
    const test::RunResult result =
        run(arguments, arguments == "orient -" ? (workDir_ / "p1.bpt").string() : "");
    ASSERT_EQ(result.exitCode, 0) << arguments << ": " << result.err;
    EXPECT_EQ(alphaOf(result), alphaOf(example)) << arguments;
  }
}

TEST_F(SurfaceIoCli, BadBptFailsNamingFileLineAndValueAndWritesNothing) {
  write("bad.bpt", "1\n1 1\n0 0 0\n1 0 zero\n0 1 0\n1 1 0\n");
  expectCleanFailure(run("orient bad.bpt --json out.json"), {"bad.bpt:4:", "'zero'"}, "bad.bpt");
  expectCleanFailure(run("paths bad.bpt --tool-radius 0.25 --spacing 0.1 --json out.json"),
                     {"bad.bpt:4:", "'zero'"}, "bad.bpt");
  expectCleanFailure(run("plan bad.bpt --out out"), {"bad.bpt:4:", "'zero'"}, "bad.bpt");
}

TEST_F(SurfaceIoCli, PatchesKeepsTheSelectionBeforeValidating) {
  // Patch 0 is degenerate (collinear control points), patch 1 is paper-2, patch 2 paper-1.
  Surface surface{Units::inch, {}};
  surface.patches.push_back(
      {1, 1, {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {3.0, 0.0, 0.0}}});
  surface.patches.push_back(exampleSurface("paper-2").patches[0]);
  surface.patches.push_back(exampleSurface("paper-1").patches[0]);
  write("three.bpt", toBpt(surface));
  write("three.json", surfaceToJson(surface));
  const test::RunResult paper2 = run("orient --example paper-2");
  ASSERT_EQ(paper2.exitCode, 0) << paper2.err;
  for (const std::string file : {"three.bpt", "three.json"}) {
    const test::RunResult one = run("orient " + file + " --patches 1");
    ASSERT_EQ(one.exitCode, 0) << one.err;
    EXPECT_EQ(alphaOf(one), alphaOf(paper2));
    // Errors name the patch by its index in the file.
    const test::RunResult bad = run("orient " + file + " --patches 2,0 --json out.json");
    EXPECT_EQ(bad.exitCode, 1);
    expectMessageContains(bad.err, {file + ": patches[0]: degenerate"}, file);
  }
  write("four.json", surfaceToJson(Surface{Units::inch, {surface.patches[1], surface.patches[1],
                                                         surface.patches[1], surface.patches[0]}}));
  expectMessageContains(run("orient four.json --patches 2-3").err, {"four.json: patches[3]:"},
                        "four.json");
}

TEST_F(SurfaceIoCli, PatchesOnExamplesAndBadLists) {
  const test::RunResult paper1 = run("orient --example paper-1");
  const test::RunResult selected = run("orient --example paper-1 --patches 0");
  ASSERT_EQ(selected.exitCode, 0) << selected.err;
  EXPECT_EQ(alphaOf(selected), alphaOf(paper1));
  expectCleanFailure(run("orient --example teapot --patches 4-32 --json out.json"),
                     {"example teapot: --patches:", "'4-32'", "patch 32", "0-31"}, nullptr);
  expectCleanFailure(run("paths --example paper-1 --patches 1 --tool-radius 0.25 --spacing 0.1"),
                     {"example paper-1: --patches:", "0-0"}, nullptr);
  expectCleanFailure(run("plan --patches x --out out"), {"example paper-1: --patches:", "'x'"},
                     nullptr);
}

}  // namespace
}  // namespace scallop
