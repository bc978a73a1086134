// Tests for surface.hpp: the paper's two test surfaces (built in and as files), the JSON
// format (bitwise round trip, every malformed variant with the location named), and the
// regularity check (regular, singular and undecided patches, transformed inputs).

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/corner_patches.hpp"
#include "support/message_checks.hpp"
#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/surface_io.hpp"

namespace scallop {
namespace {

using Json = nlohmann::json;

std::uint64_t bitsOf(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// Bit-for-bit equality of two surfaces, so that -0.0 vs 0.0 or one ulp would show.
void expectSameSurface(const Surface& actual, const Surface& expected) {
  EXPECT_EQ(actual.units, expected.units);
  ASSERT_EQ(actual.patches.size(), expected.patches.size());
  for (std::size_t i = 0; i < expected.patches.size(); ++i) {
    const BezierPatch& a = actual.patches[i];
    const BezierPatch& e = expected.patches[i];
    EXPECT_EQ(a.degreeU, e.degreeU) << "patch " << i;
    EXPECT_EQ(a.degreeV, e.degreeV) << "patch " << i;
    ASSERT_EQ(a.control.size(), e.control.size()) << "patch " << i;
    for (std::size_t c = 0; c < e.control.size(); ++c) {
      EXPECT_EQ(bitsOf(a.control[c].x), bitsOf(e.control[c].x)) << "patch " << i << " point " << c;
      EXPECT_EQ(bitsOf(a.control[c].y), bitsOf(e.control[c].y)) << "patch " << i << " point " << c;
      EXPECT_EQ(bitsOf(a.control[c].z), bitsOf(e.control[c].z)) << "patch " << i << " point " << c;
    }
  }
}

// The message of the scallop::Error that parsing `content` throws ("" if none is thrown).
std::string parseError(const std::string& content, const std::string& source = "s.json") {
  try {
    parseSurface(content, source);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

using test::expectMessageContains;

// p_jk of a patch with the given degrees, from a function of (j, k).
BezierPatch makePatch(int m, int n, const std::function<Vec3(int, int)>& point) {
  BezierPatch patch;
  patch.degreeU = m;
  patch.degreeV = n;
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k <= n; ++k) patch.control.push_back(point(j, k));
  }
  return patch;
}

// A graph-like patch over a perturbed grid: x along k, y along j (as the paper's surfaces),
// offsets up to 0.2 of the spacing so the grid stays monotone in both directions, and
// random heights. Regular: the (x, y) projection has a positive Jacobian everywhere.
BezierPatch randomGraphPatch(std::mt19937_64& rng, int m, int n, double heightScale) {
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::uniform_real_distribution<double> height(-1.0, 1.0);
  return makePatch(m, n, [&](int j, int k) {
    return Vec3{k + jitter(rng), j + jitter(rng), heightScale * height(rng)};
  });
}

// ---------------------------------------------------------------------------------------
// The paper's test surfaces
// ---------------------------------------------------------------------------------------

// Section 4.1 and 4.2, typed again here from the paper independently of src/surface.cpp:
// p_jk = (k, j, z[j][k]).
constexpr double kPaper1Z[4][4] = {{0.48, 1.00, 0.80, 0.40},
                                   {0.90, 1.41, 0.60, 0.60},
                                   {1.00, 0.88, 0.00, 0.72},
                                   {0.80, 0.60, 0.40, 0.80}};
constexpr double kPaper2Z[4][4] = {{1.65, 3.05, 3.05, 2.05},
                                   {3.05, 0.00, 4.10, 3.05},
                                   {3.05, 4.10, 0.00, 3.05},
                                   {2.05, 3.05, 3.05, 1.65}};

void expectPaperSurface(const Surface& surface, const double (&z)[4][4]) {
  EXPECT_EQ(surface.units, Units::inch);
  ASSERT_EQ(surface.patches.size(), 1u);
  const BezierPatch& patch = surface.patches[0];
  ASSERT_EQ(patch.degreeU, 3);
  ASSERT_EQ(patch.degreeV, 3);
  ASSERT_EQ(patch.control.size(), 16u);
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) {
      EXPECT_EQ(patch.at(j, k), (Vec3{static_cast<double>(k), static_cast<double>(j), z[j][k]}))
          << "p_" << j << k;
    }
  }
}

TEST(Surface, ExampleNames) {
  EXPECT_EQ(exampleSurfaceNames(),
            (std::vector<std::string>{"paper-1", "paper-2", "teapot", "teapot-rim", "teapot-body",
                                      "teapot-handle", "teapot-spout", "teapot-lid",
                                      "teapot-bottom"}));
  try {
    exampleSurface("paper-3");
    ADD_FAILURE() << "no error for an unknown example";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'paper-3'"), std::string::npos) << message;
    EXPECT_NE(message.find("paper-1, paper-2"), std::string::npos) << message;
  }
}

TEST(Surface, PaperSurfacesHaveThePrintedControlPoints) {
  expectPaperSurface(exampleSurface("paper-1"), kPaper1Z);
  expectPaperSurface(exampleSurface("paper-2"), kPaper2Z);
  // Surface #2's symmetry (Section 4.2, "evident from its control points"): z_jk = z_kj
  // and z_jk = z_{3-k,3-j}.
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) {
      EXPECT_EQ(kPaper2Z[j][k], kPaper2Z[k][j]);
      EXPECT_EQ(kPaper2Z[j][k], kPaper2Z[3 - k][3 - j]);
    }
  }
}

TEST(Surface, PaperSurfacesAreRegular) {
  for (const std::string name : {"paper-1", "paper-2"}) {
    const Surface surface = exampleSurface(name);
    EXPECT_NO_THROW(validateSurface(surface)) << name;
    const PatchRegularity regularity = checkPatchRegularity(surface.patches[0]);
    EXPECT_EQ(regularity.verdict, RegularityVerdict::regular) << name;
    // Graphs over the (x, y) grid: |r_u x r_v| >= |z component| = 9 everywhere, far above
    // the threshold; the quadtree needs only a few cells.
    EXPECT_LE(regularity.cells, 21u) << name;
  }
  EXPECT_EQ(surfaceScale(exampleSurface("paper-1")), 3.0);
  EXPECT_EQ(surfaceScale(exampleSurface("paper-2")), 4.10);
}

TEST(Surface, ExampleFilesEqualBuiltIns) {
  // The teapot's files: surface_io_test.cpp.
  for (const std::string name : {"paper-1", "paper-2"}) {
    const std::string path = std::string(SCALLOP_EXAMPLES_DIR) + "/surfaces/" + name + ".json";
    expectSameSurface(readSurface(path), exampleSurface(name));
  }
}

// ---------------------------------------------------------------------------------------
// JSON: accepted forms and the round trip
// ---------------------------------------------------------------------------------------

TEST(Surface, ParsesUnitsAndSeveralPatches) {
  const std::string content = R"({"units": "mm", "patches": [
      {"degree": [1, 1], "control_points": [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 1]]]},
      {"degree": [1, 2], "control_points": [[[0, 0, 0], [1, 0, 0], [2, 0, 0]],
                                            [[0, 1, 0], [1, 1, 0.5], [2, 1.5, -0.0]]]}]})";
  const Surface surface = parseSurface(content, "s.json");
  EXPECT_EQ(surface.units, Units::millimetre);
  ASSERT_EQ(surface.patches.size(), 2u);
  EXPECT_EQ(surface.patches[1].degreeU, 1);
  EXPECT_EQ(surface.patches[1].degreeV, 2);
  // control_points[j][k] is p_jk at index j (n + 1) + k.
  EXPECT_EQ(surface.patches[1].at(1, 2), (Vec3{2.0, 1.5, -0.0}));
  EXPECT_TRUE(std::signbit(surface.patches[1].at(1, 2).z));
  EXPECT_EQ(surface.patches[0].at(1, 1), (Vec3{1.0, 1.0, 1.0}));
  // A byte order mark is skipped; "-" is named <stdin> in messages.
  EXPECT_NO_THROW(parseSurface("\xEF\xBB\xBF" + content, "s.json"));
  EXPECT_NE(parseError("[]", "-").find("<stdin>"), std::string::npos);
}

// Random regular surfaces, then scaled by factors from 1e-310 (coordinates subnormal) to
// 1e300, with -0.0 planted: surfaceToJson writes shortest-round-trip numbers, so parsing
// reproduces every bit; writing again gives the same text (deterministic).
TEST(Surface, JsonRoundTripIsBitwise) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> degree(1, 5);
  std::uniform_int_distribution<int> patchCount(1, 4);
  // Scales across the accepted range (kMinPatchScale .. kMaxPatchScale; a patch spans up to
  // ~6 units before scaling), and in every patch one subnormal coordinate and one of 1e-300,
  // so that the shortest round-trip printing is exercised at the extremes.
  const std::array<double, 9> factors = {1e-19, 1e-15, 3e-7, 0.1, 1.0, 7.0, 1e5, 1e15, 1e19};
  for (int trial = 0; trial < 200; ++trial) {
    Surface surface;
    surface.units = trial % 2 == 0 ? Units::inch : Units::millimetre;
    const double factor = factors[static_cast<std::size_t>(trial) % factors.size()];
    const int count = patchCount(rng);
    for (int i = 0; i < count; ++i) {
      BezierPatch patch = randomGraphPatch(rng, degree(rng), degree(rng), 2.0);
      for (Vec3& p : patch.control) p = factor * p;
      patch.control[0].z = -0.0;
      patch.control[1].z = 4.9406564584124654e-324 * (1 + trial % 7);  // subnormal
      patch.control.back().z = 1e-300;
      surface.patches.push_back(std::move(patch));
    }
    const std::string text = surfaceToJson(surface);
    const Surface back = parseSurface(text, "round-trip.json");
    expectSameSurface(back, surface);
    EXPECT_EQ(surfaceToJson(back), text);
  }
}

TEST(Surface, RationalPatchesRoundTripBitwiseWithTheirWeights) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> weight(0.3, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    Surface surface;
    surface.units = Units::millimetre;
    BezierPatch patch = randomGraphPatch(rng, 1 + trial % 4, 1 + trial % 3, 2.0);
    for (std::size_t k = 0; k < patch.control.size(); ++k) patch.weights.push_back(weight(rng));
    surface.patches.push_back(patch);
    surface.patches.push_back(randomGraphPatch(rng, 2, 3, 1.0));  // a polynomial one beside it
    const std::string text = surfaceToJson(surface);
    EXPECT_NE(text.find("\"weights\""), std::string::npos);
    const Surface back = parseSurface(text, "rational.json");
    expectSameSurface(back, surface);
    ASSERT_EQ(back.patches[0].weights, surface.patches[0].weights);
    EXPECT_TRUE(back.patches[1].weights.empty());
    EXPECT_EQ(surfaceToJson(back), text);
  }
}

TEST(Surface, JsonLayoutIsOneRowPerLine) {
  Surface surface;
  surface.patches.push_back(makePatch(1, 1, [](int j, int k) {
    return Vec3{0.5 * k, 0.25 * j, -0.0};
  }));
  EXPECT_EQ(surfaceToJson(surface),
            "{\n"
            "  \"units\": \"in\",\n"
            "  \"patches\": [\n"
            "    {\n"
            "      \"degree\": [1, 1],\n"
            "      \"control_points\": [\n"
            "        [[0, 0, -0.0], [0.5, 0, -0.0]],\n"
            "        [[0, 0.25, -0.0], [0.5, 0.25, -0.0]]\n"
            "      ]\n"
            "    }\n"
            "  ]\n"
            "}\n");
}

// ---------------------------------------------------------------------------------------
// JSON: rejected forms, each naming the source, the location and the offending value
// ---------------------------------------------------------------------------------------

// A valid two-patch document to break one piece at a time.
Json validDocument() {
  Json document = Json::parse(surfaceToJson(exampleSurface("paper-1")));
  document["patches"].push_back(document["patches"][0]);
  return document;
}

struct Rejected {
  std::string name;
  std::function<void(Json&)> breakIt;
  std::vector<std::string> mustContain;
};

TEST(Surface, RejectsMalformedDocumentsNamingTheLocation) {
  const std::vector<Rejected> cases = {
      {"not an object",
       [](Json& d) {
         d = Json::array({1, 2});
       },
       {"s.json", "expected a JSON object", "[1,2]"}},
      {"missing units", [](Json& d) { d.erase("units"); }, {"s.json", "missing \"units\""}},
      {"unknown units", [](Json& d) { d["units"] = "cm"; }, {"s.json", "units", "\"cm\""}},
      {"units not a string", [](Json& d) { d["units"] = 25.4; }, {"s.json", "units", "25.4"}},
      {"unknown top-level key",
       [](Json& d) { d["colour"] = "red"; },
       {"s.json", "unknown key \"colour\""}},
      {"missing patches", [](Json& d) { d.erase("patches"); }, {"s.json", "missing \"patches\""}},
      {"patches not an array",
       [](Json& d) { d["patches"] = Json::object(); },
       {"s.json", "patches", "{}"}},
      {"no patches",
       [](Json& d) { d["patches"] = Json::array(); },
       {"s.json", "patches", "no patches"}},
      {"patch not an object", [](Json& d) { d["patches"][1] = 5; }, {"s.json: patches[1]", "5"}},
      {"unknown patch key",
       [](Json& d) { d["patches"][1]["degrees"] = 3; },
       {"s.json: patches[1]", "unknown key \"degrees\""}},
      {"missing degree",
       [](Json& d) { d["patches"][1].erase("degree"); },
       {"s.json: patches[1]", "missing \"degree\""}},
      {"missing control points",
       [](Json& d) { d["patches"][0].erase("control_points"); },
       {"s.json: patches[0]", "missing \"control_points\""}},
      {"degree one number",
       [](Json& d) { d["patches"][1]["degree"] = 3; },
       {"s.json: patches[1].degree", "3"}},
      {"degree three numbers",
       [](Json& d) {
         d["patches"][1]["degree"] = {3, 3, 3};
       },
       {"s.json: patches[1].degree", "[3,3,3]"}},
      {"degree not integer",
       [](Json& d) {
         d["patches"][1]["degree"] = {3.5, 3};
       },
       {"s.json: patches[1].degree", "not an integer", "[3.5,3]"}},
      {"degree a string",
       [](Json& d) {
         d["patches"][0]["degree"] = {3, "3"};
       },
       {"s.json: patches[0].degree", "v (the second)", "[3,\"3\"]"}},
      {"degree negative",
       [](Json& d) {
         d["patches"][1]["degree"] = {-1, 3};
       },
       {"s.json: patches[1].degree", "degree -1 in u", "at least 1"}},
      {"degree zero in u",
       [](Json& d) {
         d["patches"][1]["degree"] = {0, 3};
       },
       {"s.json: patches[1].degree", "degree 0 in u", "at least 1", "no normal"}},
      {"degree zero in v",
       [](Json& d) {
         d["patches"][1]["degree"] = {3, 0};
       },
       {"s.json: patches[1].degree", "degree 0 in v", "at least 1"}},
      {"degree too high",
       [](Json& d) {
         d["patches"][1]["degree"] = {3, 99};
       },
       {"s.json: patches[1].degree", "99", "maximum 20"}},
      {"huge degree",
       [](Json& d) {
         d["patches"][1]["degree"] = {18446744073709551615ull, 3};
       },
       {"s.json: patches[1].degree", "maximum"}},
      {"control points not an array",
       [](Json& d) { d["patches"][1]["control_points"] = "grid"; },
       {"s.json: patches[1].control_points", "\"grid\""}},
      {"too few rows",
       [](Json& d) { d["patches"][1]["control_points"].erase(3); },
       {"s.json: patches[1].control_points", "4 rows", "got 3"}},
      {"too many rows",
       [](Json& d) {
         Json& rows = d["patches"][1]["control_points"];
         rows.push_back(rows[0]);
       },
       {"s.json: patches[1].control_points", "4 rows", "got 5"}},
      {"row not an array",
       [](Json& d) { d["patches"][1]["control_points"][2] = 7; },
       {"s.json: patches[1].control_points[2]", "7"}},
      {"row too long",
       [](Json& d) {
         Json& row = d["patches"][1]["control_points"][1];
         row.push_back(row[0]);
       },
       {"s.json: patches[1].control_points[1]", "4 points per row", "got 5"}},
      {"row too short",
       [](Json& d) { d["patches"][0]["control_points"][3].erase(0); },
       {"s.json: patches[0].control_points[3]", "got 3"}},
      {"point with two numbers",
       [](Json& d) {
         d["patches"][1]["control_points"][2][3] = {1, 2};
       },
       {"s.json: patches[1].control_points[2][3]", "[1,2]"}},
      {"point with four numbers",
       [](Json& d) {
         d["patches"][1]["control_points"][0][1] = {1, 2, 3, 4};
       },
       {"s.json: patches[1].control_points[0][1]", "[1,2,3,4]"}},
      {"point with a string",
       [](Json& d) {
         d["patches"][0]["control_points"][1][2] = {1, "a", 3};
       },
       {"s.json: patches[0].control_points[1][2]", "[1,\"a\",3]"}},
      {"point with null",
       [](Json& d) {
         d["patches"][0]["control_points"][3][3] = {1, 2, nullptr};
       },
       {"s.json: patches[0].control_points[3][3]", "[1,2,null]"}},
      {"point a number",
       [](Json& d) { d["patches"][0]["control_points"][0][0] = 0.5; },
       {"s.json: patches[0].control_points[0][0]", "0.5"}},
      // A rational patch's weights: rows of positive numbers shaped as the control points.
      {"weights not rows",
       [](Json& d) { d["patches"][1]["weights"] = 1.0; },
       {"s.json: patches[1].weights", "4 rows of 4 weights"}},
      {"a row of weights too short",
       [](Json& d) { d["patches"][1]["weights"] = Json::array({{1, 1, 1, 1}, {1, 1, 1}, {1, 1, 1, 1}, {1, 1, 1, 1}}); },
       {"s.json: patches[1].weights[1]", "a row of 4 weights"}},
      {"a zero weight",
       [](Json& d) { d["patches"][1]["weights"] = Json::array({{1, 1, 1, 1}, {1, 1, 0, 1}, {1, 1, 1, 1}, {1, 1, 1, 1}}); },
       {"s.json: patches[1].weights[1][2]", "positive", "0"}},
      {"a weight that is a string",
       [](Json& d) { d["patches"][0]["weights"] = Json::array({{1, 1, 1, 1}, {1, 1, 1, 1}, {1, 1, 1, "2"}, {1, 1, 1, 1}}); },
       {"s.json: patches[0].weights[2][3]", "a number"}},
      {"weights too far apart",
       [](Json& d) { d["patches"][0]["weights"] = Json::array({{1, 1, 1, 1}, {1, 1e7, 1, 1}, {1, 1, 1, 1}, {1, 1, 1, 1}}); },
       {"s.json: patches[0].weights", "ratio"}},
  };
  for (const Rejected& rejected : cases) {
    Json document = validDocument();
    rejected.breakIt(document);
    expectMessageContains(parseError(document.dump()), rejected.mustContain, rejected.name);
  }
}

TEST(Surface, RejectsMalformedJsonText) {
  expectMessageContains(parseError(""), {"s.json", "malformed JSON"}, "empty");
  expectMessageContains(parseError("{\"units\": \"in\",\n \"patches\": [}"),
                        {"s.json", "malformed JSON", "line 2"}, "syntax");
  // A literal beyond the range of a double.
  std::string huge = surfaceToJson(exampleSurface("paper-1"));
  huge.replace(huge.find("0.48"), 4, "1e999");
  expectMessageContains(parseError(huge), {"s.json"}, "1e999");
}

TEST(Surface, ReadsFilesAndNamesMissingOnes) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "scallop_surface_test_read.json";
  {
    std::ofstream file(path);
    file << surfaceToJson(exampleSurface("paper-2"));
  }
  expectSameSurface(readSurface(path.string()), exampleSurface("paper-2"));
  std::filesystem::remove(path);
  try {
    readSurface(path.string());
    ADD_FAILURE() << "no error for a missing file";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("cannot open"), std::string::npos) << message;
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  }
}

// ---------------------------------------------------------------------------------------
// Validation of surfaces built in memory
// ---------------------------------------------------------------------------------------

std::string validationError(const Surface& surface) {
  try {
    validateSurface(surface);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

TEST(Surface, ValidatesSurfacesBuiltInMemory) {
  Surface surface = exampleSurface("paper-1");
  surface.patches.push_back(surface.patches[0]);
  EXPECT_EQ(validationError(surface), "");

  Surface wrongCount = surface;
  wrongCount.patches[1].control.pop_back();
  expectMessageContains(validationError(wrongCount), {"patches[1]", "16", "got 15"}, "count");

  Surface notFinite = surface;
  notFinite.patches[1].control[6].y = std::nan("");
  expectMessageContains(validationError(notFinite), {"patches[1].control_points[1][2]", "nan"},
                        "nan");

  // Too large or too small for the curvature polynomials (overflow, underflow: once a hang).
  for (double factor : {1e21, 1e-22}) {
    Surface scaled = surface;
    for (Vec3& p : scaled.patches[1].control) p = factor * p;
    expectMessageContains(validationError(scaled), {"patches[1]", "largest |coordinate|", "check the units"},
                          "scale");
  }
  Surface large = surface;  // within the limits: accepted
  for (Vec3& p : large.patches[0].control) p = 1e19 * p;
  EXPECT_EQ(validationError(large), "");

  Surface zeroDegree = surface;
  zeroDegree.patches[0].degreeV = 0;
  expectMessageContains(validationError(zeroDegree), {"patches[0].degree", "degree 0 in v"},
                        "degree");

  expectMessageContains(validationError(Surface{}), {"no patches"}, "empty");
  EXPECT_THROW(checkPatchRegularity(wrongCount.patches[1]), Error);
  EXPECT_THROW(surfaceToJson(wrongCount), Error);
  EXPECT_THROW(surfaceToJson(notFinite), Error);
  EXPECT_THROW(checkPatchRegularity(notFinite.patches[1]), Error);
  EXPECT_EQ(surfaceScale(Surface{}), 0.0);
}

// ---------------------------------------------------------------------------------------
// Regularity
// ---------------------------------------------------------------------------------------

// Patches whose r_u x r_v vanishes somewhere, each rejected with the location.
TEST(Surface, RejectsCollinearControlPoints) {
  // All control points on one line: r_u and r_v parallel everywhere.
  const BezierPatch patch = makePatch(3, 3, [](int j, int k) {
    const double t = j + 0.5 * k;
    return Vec3{t, 2.0 * t, -3.0 * t};
  });
  const PatchRegularity regularity = checkPatchRegularity(patch);
  EXPECT_EQ(regularity.verdict, RegularityVerdict::singular);
  EXPECT_LE(regularity.relativeNormalLength, regularity.threshold);
  Surface surface;
  surface.patches = {exampleSurface("paper-1").patches[0], patch};
  const std::string message = parseError(surfaceToJson(surface));
  expectMessageContains(message, {"s.json: patches[1]", "degenerate", "(u, v) = ("}, "collinear");
}

// A collapsed boundary row: p_0k all equal, so r(0, v) is one point (an apex) and r_v = 0
// along u = 0; likewise a collapsed column k = 3 makes r_u vanish along v = 1. The normal has
// a limit there (bezier.hpp's normalDirectionPolynomials), so the patch is regular. A net
// collapsed to one point, or with a second collapsed edge that leaves no limit, is not.
TEST(Surface, AcceptsCollapsedBoundaryRowOrColumn) {
  const BezierPatch row = makePatch(3, 3, [](int j, int k) {
    return j == 0 ? Vec3{1.5, 0.0, 0.7}
                  : Vec3{static_cast<double>(k), static_cast<double>(j), 0.1 * j * k};
  });
  EXPECT_EQ(checkPatchRegularity(row).verdict, RegularityVerdict::regular);
  Surface surface;
  surface.patches = {row};
  EXPECT_NO_THROW(validateSurface(surface));

  const BezierPatch column = makePatch(3, 3, [](int j, int k) {
    return k == 3 ? Vec3{3.0, 1.5, 0.0}
                  : Vec3{static_cast<double>(k), static_cast<double>(j), 0.05 * j * j - 0.1 * k};
  });
  EXPECT_EQ(checkPatchRegularity(column).verdict, RegularityVerdict::regular);

  const BezierPatch point = makePatch(3, 3, [](int, int) { return Vec3{1.0, 2.0, 3.0}; });
  EXPECT_NE(checkPatchRegularity(point).verdict, RegularityVerdict::regular);
  surface.patches = {point};
  expectMessageContains(parseError(surfaceToJson(surface)), {"s.json: patches[0]", "degenerate"},
                        "one point");
  // Rows 0 and 3 both collapsed to the same point: a closed, pinched net whose normal along
  // both rows needs more than one factor; the u = 0 and u = 1 limits exist, but the v-edges
  // then run through the apex twice. Whatever the verdict, it must not throw.
  const BezierPatch pinched = makePatch(3, 3, [](int j, int k) {
    return j == 0 || j == 3 ? Vec3{0.0, 0.0, 0.0}
                            : Vec3{static_cast<double>(k), static_cast<double>(j) - 1.5, 0.3 * k};
  });
  EXPECT_NO_THROW(checkPatchRegularity(pinched));
}

// Each row a cubic with p_0 = p_3 and p_1 = p_2: r_v = 0 along the interior line v = 1/2
// (a cusp line), found by evaluating at the cell's centre.
TEST(Surface, RejectsCuspLine) {
  const BezierPatch patch = makePatch(3, 3, [](int j, int k) {
    const bool inner = k == 1 || k == 2;
    return Vec3{inner ? 1.0 : 0.0, static_cast<double>(j), inner ? 1.0 : 0.0};
  });
  const PatchRegularity regularity = checkPatchRegularity(patch);
  EXPECT_EQ(regularity.verdict, RegularityVerdict::singular);
  EXPECT_EQ(regularity.v, 0.5);
}

// Bernstein coefficients of a bivariate quadratic from its power coefficients c[a][b]
// (of u^a v^b): per variable, b_i = sum_{a <= i} C(i, a) / C(2, a) c_a.
BezierPatch quadraticFromPower(const double (&x)[3][3], const double (&y)[3][3]) {
  const double weight[3][3] = {{1.0, 0.0, 0.0}, {1.0, 0.5, 0.0}, {1.0, 1.0, 1.0}};
  auto convert = [&](const double(&c)[3][3], int j, int k) {
    double sum = 0.0;
    for (int a = 0; a <= 2; ++a) {
      for (int b = 0; b <= 2; ++b) sum += weight[j][a] * weight[k][b] * c[a][b];
    }
    return sum;
  };
  return makePatch(2, 2, [&](int j, int k) {
    return Vec3{convert(x, j, k), convert(y, j, k), 0.0};
  });
}

// The planar patch (u, v) -> (z - z0)^2 in complex notation, z = u + i v: its Jacobian
// 4 |z - z0|^2 vanishes only at z0. At z0 = (1/2, 1/2) (a dyadic point) the quadtree's
// first probe finds the zero exactly; at z0 = (1/3, 1/3) no probe lands on it, no cell
// around it can be proven positive, and the verdict is "undecided" near (1/3, 1/3).
BezierPatch squaringPatch(double a, double b) {
  // x = (u - a)^2 - (v - b)^2 = u^2 - 2a u + a^2 - v^2 + 2b v - b^2
  // y = 2 (u - a)(v - b)      = 2 u v - 2b u - 2a v + 2ab
  const double x[3][3] = {{a * a - b * b, 2.0 * b, -1.0}, {-2.0 * a, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  const double y[3][3] = {{2.0 * a * b, -2.0 * a, 0.0}, {-2.0 * b, 2.0, 0.0}, {0.0, 0.0, 0.0}};
  return quadraticFromPower(x, y);
}

TEST(Surface, IsolatedSingularPoint) {
  const PatchRegularity dyadic = checkPatchRegularity(squaringPatch(0.5, 0.5));
  EXPECT_EQ(dyadic.verdict, RegularityVerdict::singular);
  EXPECT_EQ(dyadic.u, 0.5);
  EXPECT_EQ(dyadic.v, 0.5);

  const BezierPatch third = squaringPatch(1.0 / 3.0, 1.0 / 3.0);
  const PatchRegularity undecided = checkPatchRegularity(third);
  EXPECT_EQ(undecided.verdict, RegularityVerdict::undecided);
  EXPECT_NEAR(undecided.u, 1.0 / 3.0, 1e-3);
  EXPECT_NEAR(undecided.v, 1.0 / 3.0, 1e-3);
  EXPECT_LE(undecided.cells, kRegularityMaxCells);
  Surface surface;
  surface.patches = {third};
  expectMessageContains(parseError(surfaceToJson(surface)),
                        {"s.json: patches[0]", "degenerate", "could not prove", "(u, v) = (0.33"},
                        "isolated zero");
  // Moved off the patch (z0 = (-1/3, 1/3)), the same map is regular on [0, 1]^2.
  EXPECT_EQ(checkPatchRegularity(squaringPatch(-1.0 / 3.0, 1.0 / 3.0)).verdict,
            RegularityVerdict::regular);
}

// r_u = 0 along the whole non-dyadic line u = 1/3: x(u) = (u - 1/3)^3 is stationary there.
// No probe lands on the line and the cells along it cannot be proven regular, so their
// number doubles with each level until the cell budget stops the search: "undecided",
// located on the line, in bounded time.
TEST(Surface, SingularLineOffTheGridIsUndecidedWithinBudget) {
  const double a = 1.0 / 3.0;
  const Bernstein1 x = fromPowerBasis({-a * a * a, 3.0 * a * a, -3.0 * a, 1.0});
  const BezierPatch patch = makePatch(3, 1, [&](int j, int k) {
    return Vec3{x.coefficients[static_cast<std::size_t>(j)], static_cast<double>(k), 0.0};
  });
  const PatchRegularity regularity = checkPatchRegularity(patch);
  EXPECT_EQ(regularity.verdict, RegularityVerdict::undecided);
  EXPECT_NEAR(regularity.u, a, 1e-3);
  EXPECT_LE(regularity.cells, kRegularityMaxCells);
}

// A cylinder-like patch: a cubic arc close to a half circle in (x, z), extruded along y.
// Its normal turns through about 180 degrees, so no single direction certifies the root
// cell, yet |r_u x r_v| stays well away from 0: regular.
TEST(Surface, HalfCylinderIsRegular) {
  const double arc[4][2] = {{-1.0, 0.0}, {-1.0, 4.0 / 3.0}, {1.0, 4.0 / 3.0}, {1.0, 0.0}};
  const BezierPatch patch = makePatch(2, 3, [&](int j, int k) {
    return Vec3{arc[k][0], static_cast<double>(j), arc[k][1]};
  });
  const PatchRegularity regularity = checkPatchRegularity(patch);
  EXPECT_EQ(regularity.verdict, RegularityVerdict::regular);
  EXPECT_GE(regularity.cells, 1u);
}

// A flat patch is regular (the plane's normal is defined): coplanarity alone is fine.
TEST(Surface, FlatPatchIsRegular) {
  const BezierPatch patch = makePatch(3, 2, [](int j, int k) {
    return Vec3{static_cast<double>(k), static_cast<double>(j), 0.0};
  });
  EXPECT_EQ(checkPatchRegularity(patch).verdict, RegularityVerdict::regular);
}

// Random graph patches of degrees 1..5 and heights up to 10x the footprint are regular,
// and stay so under transformed inputs: scaling by powers of two and ten, translation,
// rotation, and swapping the roles of u and v (transposing the net flips the normal).
TEST(Surface, RandomGraphPatchesAreRegular) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> degree(1, 5);
  std::uniform_real_distribution<double> heightScale(0.0, 10.0);
  for (int trial = 0; trial < 300; ++trial) {
    const BezierPatch patch = randomGraphPatch(rng, degree(rng), degree(rng), heightScale(rng));
    const PatchRegularity regularity = checkPatchRegularity(patch);
    ASSERT_EQ(regularity.verdict, RegularityVerdict::regular) << trial;

    BezierPatch scaled = patch;
    for (Vec3& p : scaled.control) p = std::ldexp(1.0, 40) * p + Vec3{3.0, -7.0, 1e3};
    EXPECT_EQ(checkPatchRegularity(scaled).verdict, RegularityVerdict::regular) << trial;

    BezierPatch rotated = patch;
    const double c = std::cos(0.7);
    const double s = std::sin(0.7);
    for (Vec3& p : rotated.control) p = Vec3{c * p.x - s * p.z, p.y, s * p.x + c * p.z} * 1e-3;
    EXPECT_EQ(checkPatchRegularity(rotated).verdict, RegularityVerdict::regular) << trial;

    const BezierPatch transposed =
        makePatch(patch.degreeV, patch.degreeU, [&](int j, int k) { return patch.at(k, j); });
    EXPECT_EQ(checkPatchRegularity(transposed).verdict, RegularityVerdict::regular) << trial;
  }
}

// The full path for random bicubic graph patches: written, parsed and validated.
TEST(Surface, RandomBicubicGraphPatchIsAccepted) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 50; ++trial) {
    Surface surface;
    surface.units = Units::millimetre;
    surface.patches.push_back(randomGraphPatch(rng, 3, 3, 25.0));
    expectSameSurface(parseSurface(surfaceToJson(surface), "bicubic.json"), surface);
  }
}

// A bicubic patch pinched until nearly singular: the quadtree either proves it regular
// or rejects it; it never reports a singular point where |r_u x r_v| is above the threshold.
TEST(Surface, SingularVerdictsAreBackedByTheThreshold) {
  for (const double pinch : {1.0, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-11, 1e-12, 1e-13, 0.0}) {
    // Row 0 shrinks toward one point as pinch -> 0: r_v along u = 0 is pinch times a row.
    const BezierPatch patch = makePatch(3, 3, [&](int j, int k) {
      const double width = j == 0 ? pinch : 1.0;  // pinch 0: an apex row
      return Vec3{1.5 + width * (k - 1.5), static_cast<double>(j), 0.2 * j};
    });
    const PatchRegularity regularity = checkPatchRegularity(patch);
    if (regularity.verdict == RegularityVerdict::singular) {
      EXPECT_LE(regularity.relativeNormalLength, regularity.threshold) << pinch;
      const Vec3 n = cross(derivativeU(patch, regularity.u, regularity.v),
                           derivativeV(patch, regularity.u, regularity.v));
      EXPECT_LE(norm(n), 1e-12 * 3.0 * 3.0) << pinch;
    }
    if (pinch >= 1e-11) {
      EXPECT_EQ(regularity.verdict, RegularityVerdict::regular) << pinch;
    }
    if (pinch == 0.0) {
      // Collapsed to one point exactly: an apex, with the normal's limit there.
      EXPECT_EQ(regularity.verdict, RegularityVerdict::regular) << pinch;
    } else if (pinch <= 1e-13) {
      // Nearly collapsed, above rounding: r_u x r_v is small but no factor, and within the
      // threshold on that edge.
      EXPECT_EQ(regularity.verdict, RegularityVerdict::singular) << pinch;
    }
  }
}

}  // namespace
}  // namespace scallop

// ---------------------------------------------------------------------------------------
// Corners where r_u x r_v vanishes (cornerPieces)
// ---------------------------------------------------------------------------------------

namespace scallop {
namespace {

// The unit normal at (u, v) straight from r_u x r_v (no limits, no fallbacks).
Vec3 crossNormal(const BezierPatch& patch, double u, double v) {
  return normalized(cross(derivativeU(patch, u, v), derivativeV(patch, u, v)));
}

// The limit of the normal at `corner` along the ray at angle theta into the patch, taken at
// 1e-7 of the parameter range (the error of that is O(1e-7)).
Vec3 rayNormal(const BezierPatch& patch, int corner, double theta) {
  const double u0 = (corner & 1) ? 1.0 : 0.0, v0 = (corner & 2) ? 1.0 : 0.0;
  return crossNormal(patch, u0 + (1.0 - 2.0 * u0) * 1e-7 * std::cos(theta),
                     v0 + (1.0 - 2.0 * v0) * 1e-7 * std::sin(theta));
}

// 2,000 random patches with one to four singular corners of each kind (fixed seed): those
// the regularity check accepts are split into pieces that reproduce the patch (points and
// normals at their source parameters), cover its parameter square once (the pieces' signed
// parameter areas sum to 1, each positive: the orientation is kept), and whose apex rows
// carry the normal's limits along the rays into the corner.
TEST(CornerPieces, ReproduceThePatchAndItsNormals) {
  std::mt19937_64 rng(20261125);
  int accepted = 0, fanned = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const test::CorneredPatch cornered = test::randomCorneredPatch(rng);
    const BezierPatch& patch = cornered.patch;
    if (checkPatchRegularity(patch).verdict != RegularityVerdict::regular) continue;
    ++accepted;
    SCOPED_TRACE("trial " + std::to_string(trial));
    const std::vector<PatchPiece> pieces = cornerPieces(patch, 7);
    double area = 0.0;
    for (const PatchPiece& piece : pieces) {
      EXPECT_EQ(piece.source, 7u);
      fanned += piece.corner >= 0;
      EXPECT_EQ(checkPatchRegularity(piece.patch).verdict, RegularityVerdict::regular);
      // Signed area by the midpoint rule on 16 x 16 cells: exact for the maps used (their
      // Jacobians are linear in each parameter).
      const int cells = 16;
      const double h = 1.0 / cells, dh = 1e-6;
      for (int a = 0; a < cells; ++a) {
        for (int b = 0; b < cells; ++b) {
          const double s = (a + 0.5) * h, t = (b + 0.5) * h;
          const Vec2 ds = (piece.sourceParameters(s + dh, t) - piece.sourceParameters(s - dh, t)) * (0.5 / dh);
          const Vec2 dt = (piece.sourceParameters(s, t + dh) - piece.sourceParameters(s, t - dh)) * (0.5 / dh);
          const double jacobian = ds.x * dt.y - ds.y * dt.x;
          EXPECT_GT(jacobian, 0.0);
          area += jacobian * h * h;
        }
      }
      for (int a = 0; a <= 8; ++a) {
        for (int b = 0; b <= 8; ++b) {
          const double s = a / 8.0, t = b / 8.0;
          const Vec2 uv = piece.sourceParameters(s, t);
          EXPECT_LE(norm(point(piece.patch, s, t) - point(patch, uv.x, uv.y)), 1e-13 * 8.0);
          const bool nearCorner = piece.corner >= 0 && std::min({uv.x, 1.0 - uv.x}) < 1e-3 &&
                                  std::min({uv.y, 1.0 - uv.y}) < 1e-3;
          if (!nearCorner) {
            EXPECT_LE(norm(unitNormal(piece.patch, s, t) - crossNormal(patch, uv.x, uv.y)), 1e-9);
          }
        }
      }
      if (piece.corner < 0) continue;
      // The apex row: its normals are the ray limits, from the corner of the source patch
      // (the quarter's corner is the patch's own). Parameter a along the row runs over the
      // ray's direction as sourceParameters says.
      for (int i = 0; i <= 10; ++i) {
        const double t = i / 10.0;
        // A point just off the apex row, and the ray from the corner through it.
        const double cu = (piece.corner & 1) ? 1.0 : 0.0, cv = (piece.corner & 2) ? 1.0 : 0.0;
        const double s0 = piece.besideUEdge ? cu : t, t0 = piece.besideUEdge ? t : cv;
        const double s1 = piece.besideUEdge ? cu + (1.0 - 2.0 * cu) * 1e-3 : t;
        const double t1 = piece.besideUEdge ? t : cv + (1.0 - 2.0 * cv) * 1e-3;
        const Vec2 apex = piece.sourceParameters(s0, t0);
        const Vec2 off = piece.sourceParameters(s1, t1);
        const int c = (apex.x == 1.0 ? 1 : 0) | (apex.y == 1.0 ? 2 : 0);
        ASSERT_TRUE((apex.x == 0.0 || apex.x == 1.0) && (apex.y == 0.0 || apex.y == 1.0));
        const double theta = std::atan2(std::abs(off.y - apex.y), std::abs(off.x - apex.x));
        EXPECT_LE(norm(unitNormal(piece.patch, s0, t0) - rayNormal(patch, c, theta)), 1e-5);
      }
    }
    EXPECT_NEAR(area, 1.0, 1e-9);
  }
  std::printf("[          ] %d of 2000 accepted, %d fans\n", accepted, fanned);
  EXPECT_GE(accepted, 1000);
  EXPECT_GE(fanned, 1000);
}

// A corner where r_u x r_v vanishes to first order is regular: validateSurface accepts it,
// and unitNormal there is the limit along the diagonal ray (near it, along its own ray).
TEST(CornerPieces, FirstOrderCornerZerosAreAccepted) {
  for (int corner = 0; corner < 4; ++corner) {
    SCOPED_TRACE("corner " + std::to_string(corner));
    BezierPatch patch = makePatch(3, 3, [](int j, int k) { return Vec3{double(k), double(j), 0.1 * j * k - 0.05 * k * k}; });
    const int j0 = (corner & 1) ? 3 : 0, k0 = (corner & 2) ? 3 : 0, k1 = (corner & 2) ? 2 : 1;
    patch.control[j0 * 4 + k1] = patch.control[j0 * 4 + k0];  // p_{j0,k1} = p_{j0,k0}: r_v = 0
    const double u0 = (corner & 1) ? 1.0 : 0.0, v0 = (corner & 2) ? 1.0 : 0.0;
    EXPECT_LE(norm(normalVector(patch, u0, v0)), 1e-15);
    EXPECT_EQ(checkPatchRegularity(patch).verdict, RegularityVerdict::regular);
    EXPECT_NO_THROW(validateSurface(Surface{Units::inch, {patch}}));
    EXPECT_EQ(cornerPieces(patch).size(), 2u);
    EXPECT_LE(norm(unitNormal(patch, u0, v0) - rayNormal(patch, corner, std::numbers::pi / 4.0)), 1e-6);
    const double theta = 0.3;
    const double u = u0 + (1.0 - 2.0 * u0) * 1e-9 * std::cos(theta), v = v0 + (1.0 - 2.0 * v0) * 1e-9 * std::sin(theta);
    EXPECT_LE(norm(unitNormal(patch, u, v) - rayNormal(patch, corner, theta)), 1e-6);
  }
}

// Where r_u x r_v vanishes to second order at a corner (both r_u and r_v zero; the planar
// map (u + i v)^2, whose Jacobian is 4 |u + i v|^2), the normal has no limit along some ray
// or none at all: rejected, the message naming the corner.
TEST(CornerPieces, HigherOrderCornerZerosAreRejected) {
  BezierPatch both = makePatch(3, 3, [](int j, int k) { return Vec3{double(k), double(j), 0.2 * j * k}; });
  both.control[1] = both.control[0];  // p01 = p00
  both.control[4] = both.control[0];  // p10 = p00
  const PatchRegularity regularity = checkPatchRegularity(both);
  EXPECT_NE(regularity.verdict, RegularityVerdict::regular);
  EXPECT_EQ(checkPatchRegularity(squaringPatch(0.0, 0.0)).verdict, RegularityVerdict::singular);
  Surface surface{Units::inch, {both}};
  expectMessageContains(parseError(surfaceToJson(surface)),
                        {"s.json: patches[0]", "degenerate", "(u, v) = (0, 0)", "at a corner"}, "second order");
}

// Fans of a degree sum above kMaxPatchDegree are refused with the reason, not built.
TEST(CornerPieces, DegreeSumBeyondTheLimitIsAClearError) {
  BezierPatch patch = makePatch(12, 12, [](int j, int k) { return Vec3{double(k), double(j), 0.01 * j * k}; });
  patch.control[1] = patch.control[0];
  expectMessageContains(parseError(surfaceToJson(Surface{Units::inch, {patch}})),
                        {"s.json: patches[0]", "corner", "m + n <= 20"}, "degree sum");
}

}  // namespace
}  // namespace scallop
