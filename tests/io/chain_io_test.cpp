// Tests for chain_io.hpp: every accepted text and JSON syntax, every rejected one (with the
// line, point index and offending value named in the message), reading files, and the
// built-in examples. Expected values come from the test's own literals or its own
// formatting (std::to_chars), never from the parser's output.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scallop/paths/chain.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/error.hpp"

namespace scallop {
namespace {

std::uint64_t bitsOf(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// Bit-for-bit equality, so that -0.0 vs 0.0 or one ulp of rounding would show.
void expectSameChain(const Chain& actual, const Chain& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(bitsOf(actual[i].x), bitsOf(expected[i].x)) << "x of vertex " << i;
    EXPECT_EQ(bitsOf(actual[i].z), bitsOf(expected[i].z)) << "z of vertex " << i;
  }
}

// The message of the scallop::Error that parsing `content` throws ("" if none is thrown).
std::string parseError(const std::string& content, const std::string& source = "in.txt") {
  try {
    parseChain(content, source);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

std::string shortest(double value) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

// ---------------------------------------------------------------------------------------
// Accepted text syntax
// ---------------------------------------------------------------------------------------

TEST(ChainIo, ReadsWhitespaceSeparatedPairs) {
  expectSameChain(parseChain("0 0\n1 2\n", "a.txt"), {{0.0, 0.0}, {1.0, 2.0}});
  expectSameChain(parseChain("0\t0\n  1    2  \n\t3 \t 4", "a.txt"),
                  {{0.0, 0.0}, {1.0, 2.0}, {3.0, 4.0}});
}

TEST(ChainIo, ReadsOneCommaWithOrWithoutBlanks) {
  expectSameChain(parseChain("0,0\n1, 2\n2 ,3\n3 , 4\n4\t,\t5\n", "a.csv"),
                  {{0.0, 0.0}, {1.0, 2.0}, {2.0, 3.0}, {3.0, 4.0}, {4.0, 5.0}});
}

TEST(ChainIo, SkipsCommentsAndBlankLines) {
  const std::string content =
      "# leading comment\n"
      "\n"
      "0 0   # trailing comment\n"
      "   \t  \n"
      "#1 1 commented-out vertex\n"
      "2 3#comment without a blank\n"
      "# last line, no newline";
  expectSameChain(parseChain(content, "a.txt"), {{0.0, 0.0}, {2.0, 3.0}});
}

TEST(ChainIo, SkipsOneHeaderLine) {
  expectSameChain(parseChain("x,z\n0,0\n1,1\n", "a.csv"), {{0.0, 0.0}, {1.0, 1.0}});
  expectSameChain(parseChain("# comment first\n\nx_mm z_mm\n0 0\n1 1\n", "a.txt"),
                  {{0.0, 0.0}, {1.0, 1.0}});
}

TEST(ChainIo, AcceptsWindowsLineEndingsAndByteOrderMark) {
  expectSameChain(parseChain("\xEF\xBB\xBFx,z\r\n0,0\r\n1,1\r\n", "a.csv"),
                  {{0.0, 0.0}, {1.0, 1.0}});
}

TEST(ChainIo, ReadsEveryNumberForm) {
  const Chain chain = parseChain("-1.5e3 +2\n1E-3 -0\n.5 5.\n0.5 -7.25E+2\n", "a.txt");
  expectSameChain(chain, {{-1500.0, 2.0}, {0.001, -0.0}, {0.5, 5.0}, {0.5, -725.0}});
}

TEST(ChainIo, KeepsVerticalEdgesAndRepeatedPoints) {
  expectSameChain(parseChain("0 0\n0 1\n0 1\n1 1\n1 0\n", "a.txt"),
                  {{0.0, 0.0}, {0.0, 1.0}, {0.0, 1.0}, {1.0, 1.0}, {1.0, 0.0}});
}

// Random doubles, written shortest-round-trip by std::to_chars in every separator style,
// must come back bit for bit (from_chars rounds correctly).
TEST(ChainIo, RandomValuesRoundTripExactly) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-30, 30);
  const std::array<const char*, 5> separators = {" ", "\t", ",", ", ", " ,  "};
  Chain expected;
  std::string content = "# random chain\n";
  double x = -1e6;
  for (int i = 0; i < 2000; ++i) {
    x += std::ldexp(std::abs(mantissa(rng)), exponent(rng) / 3);
    const double z = std::ldexp(mantissa(rng), exponent(rng));
    expected.push_back({x, z});
    content += shortest(x) + separators[static_cast<std::size_t>(i) % separators.size()] +
               shortest(z) + "\n";
  }
  expectSameChain(parseChain(content, "random.txt"), expected);
}

// ---------------------------------------------------------------------------------------
// Rejected text syntax: each message names the source, the line and the offending text.
// ---------------------------------------------------------------------------------------

struct RejectedText {
  const char* content;
  std::vector<std::string> mustContain;
};

TEST(ChainIo, RejectsMalformedTextNamingLineAndValue) {
  const std::vector<RejectedText> cases = {
      {"0 0\nabc 1\n", {"in.txt:2:", "'abc'"}},
      {"0 0\n1 abc\n", {"in.txt:2:", "'abc'"}},
      {"0 0\n1.5x 2\n", {"in.txt:2:", "'1.5x'"}},
      {"0 0\n1 2mm\n", {"in.txt:2:", "'2mm'"}},
      {"0 0\n1;2\n", {"in.txt:2:", "'1;2'"}},
      {"0 0\n1 2 3\n", {"in.txt:2:", "third", "'3'"}},
      {"0 0\n1,2,3\n", {"in.txt:2:", "'3'"}},
      {"0 0\n\n# c\n7\n", {"in.txt:4:", "missing", "'7'"}},
      {"0,,0\n1 1\n", {"in.txt:1:", "'0,,0'"}},
      {"0 0,\n1 1\n", {"in.txt:1:", "'0 0,'"}},
      {",0 0\n1 1\n", {"in.txt:1:", "',0 0'"}},
      {"0 0\n1 nan\n", {"in.txt:2:", "'nan'"}},
      {"0 0\nNaN 1\n", {"in.txt:2:", "'NaN'"}},
      {"0 0\n1 inf\n", {"in.txt:2:", "'inf'"}},
      {"0 0\n1 -inf\n", {"in.txt:2:", "'-inf'"}},
      {"0 0\n1 Infinity\n", {"in.txt:2:", "'Infinity'"}},
      {"0 0\n1 1e999\n", {"in.txt:2:", "'1e999'"}},
      {"0 0\n1 --1\n", {"in.txt:2:", "'--1'"}},
      {"0 0\n1 0x10\n", {"in.txt:2:", "'0x10'"}},
      // A header is only the first data line.
      {"0 0\nx z\n1 1\n", {"in.txt:2:", "'x'"}},
      {"x z\nx z\n1 1\n", {"in.txt:2:", "'x'"}},
  };
  for (const RejectedText& rejected : cases) {
    const std::string message = parseError(rejected.content);
    ASSERT_FALSE(message.empty()) << "accepted: " << rejected.content;
    for (const std::string& part : rejected.mustContain) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message '" << message << "' lacks '" << part << "' for input: " << rejected.content;
    }
  }
}

TEST(ChainIo, RejectsDecreasingXNamingBothLines) {
  const std::string message = parseError("# c\n0 0\n2 1\n\n# gap\n1.5 1\n3 3\n");
  EXPECT_NE(message.find("in.txt:6:"), std::string::npos) << message;
  EXPECT_NE(message.find("'1.5'"), std::string::npos) << message;
  EXPECT_NE(message.find("line 3"), std::string::npos) << message;
}

TEST(ChainIo, RejectsTooFewPoints) {
  for (const char* empty : {"", "\n\n", "# only a comment\n", "x z\n", "   \n\t\n"}) {
    const std::string message = parseError(empty);
    EXPECT_NE(message.find("in.txt"), std::string::npos) << message;
    EXPECT_NE(message.find("no points"), std::string::npos) << message;
  }
  const std::string message = parseError("# c\n\n5 5\n");
  EXPECT_NE(message.find("in.txt:3:"), std::string::npos) << message;
  EXPECT_NE(message.find("at least 2"), std::string::npos) << message;
}

TEST(ChainIo, NamesStandardInput) {
  EXPECT_NE(parseError("0 0\nbad 1\n", "-").find("<stdin>:2:"), std::string::npos);
}

// ---------------------------------------------------------------------------------------
// JSON
// ---------------------------------------------------------------------------------------

TEST(ChainIoJson, ReadsPoints) {
  expectSameChain(parseChain(R"({"points": [[0, 0], [1.5, -2], [1.5, 3e2]]})", "a.json"),
                  {{0.0, 0.0}, {1.5, -2.0}, {1.5, 300.0}});
  // Leading blanks, other keys, and newlines anywhere.
  expectSameChain(
      parseChain("\n  {\"units\": \"mm\",\n \"points\":[[0,0],\n[1,1]], \"x\": {}}\n", "a.json"),
      {{0.0, 0.0}, {1.0, 1.0}});
}

TEST(ChainIoJson, RandomValuesRoundTripExactly) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Chain expected;
  nlohmann::json points = nlohmann::json::array();
  double x = 0.0;
  for (int i = 0; i < 500; ++i) {
    x += std::abs(unit(rng)) * 1e-3;
    const double z = unit(rng) * 1e5;
    expected.push_back({x, z});
    points.push_back({x, z});
  }
  expectSameChain(parseChain(nlohmann::json{{"points", points}}.dump(), "r.json"), expected);
}

TEST(ChainIoJson, RejectsBadPointsNamingIndexAndValue) {
  const std::vector<RejectedText> cases = {
      {R"({"points": [[0, 0], [1, 1], [2, 2], [3, "a"]]})", {"in.json: points[3]", "[3,\"a\"]"}},
      {R"({"points": [[0, 0], [1, 1, 1]]})", {"points[1]", "[1,1,1]"}},
      {R"({"points": [[0, 0], [1]]})", {"points[1]", "[1]"}},
      {R"({"points": [[0, 0], {"x": 1, "z": 2}]})", {"points[1]", "{\"x\":1,\"z\":2}"}},
      {R"({"points": [[0, 0], [1, null]]})", {"points[1]", "[1,null]"}},
      {R"({"points": [[0, 0], 5]})", {"points[1]", "5"}},
      {R"({"points": [[0, 0], [2, 0], [1, 0]]})", {"points[2]", "[1,0]", "points[1]"}},
      {R"({"points": [[0, 0]]})", {"in.json", "at least 2"}},
      {R"({"points": []})", {"in.json", "no points"}},
      {R"({"points": {"a": 1}})", {"in.json", "points"}},
      {R"({"vertices": [[0, 0], [1, 1]]})", {"in.json", "points"}},
  };
  for (const RejectedText& rejected : cases) {
    const std::string message = parseError(rejected.content, "in.json");
    ASSERT_FALSE(message.empty()) << "accepted: " << rejected.content;
    for (const std::string& part : rejected.mustContain) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message '" << message << "' lacks '" << part << "' for input: " << rejected.content;
    }
  }
}

TEST(ChainIoJson, RejectsMalformedJsonWithPosition) {
  const std::string message = parseError("{\"points\": [[0, 0],\n [1, 1]\n", "in.json");
  EXPECT_NE(message.find("in.json"), std::string::npos) << message;
  EXPECT_NE(message.find("line 3"), std::string::npos) << message;
  const std::string badToken = parseError("{\"points\": [[0, 0], [1, x]]}", "in.json");
  EXPECT_NE(badToken.find("column"), std::string::npos) << badToken;
  const std::string overflow = parseError("{\"points\": [[0, 0], [1, 1e999]]}", "in.json");
  EXPECT_NE(overflow.find("1e999"), std::string::npos) << overflow;
}

// ---------------------------------------------------------------------------------------
// Files and examples
// ---------------------------------------------------------------------------------------

class ChainIoFile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "scallop-io-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    directory_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string write(const std::string& name, const std::string& content) const {
    const std::string path = (directory_ / name).string();
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

  std::filesystem::path directory_;
};

TEST_F(ChainIoFile, ReadsTextAndJsonFiles) {
  expectSameChain(readChain(write("a.txt", "0 0\n1 2\n")), {{0.0, 0.0}, {1.0, 2.0}});
  expectSameChain(readChain(write("a.dat", "{\"points\": [[0, 0], [1, 2]]}")),
                  {{0.0, 0.0}, {1.0, 2.0}});
}

TEST_F(ChainIoFile, ErrorsNameThePath) {
  const std::string path = write("bad.txt", "0 0\n1 x\n");
  try {
    readChain(path);
    FAIL() << "accepted a malformed file";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":2:"), std::string::npos) << error.what();
  }
}

TEST_F(ChainIoFile, MissingFileNamesPathAndReason) {
  const std::string path = (directory_ / "missing.txt").string();
  try {
    readChain(path);
    FAIL() << "read a missing file";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("cannot open '" + path + "'"), std::string::npos) << message;
    EXPECT_NE(message.find(std::strerror(ENOENT)), std::string::npos) << message;
  }
}

TEST_F(ChainIoFile, DirectoryIsAnError) { EXPECT_THROW(readChain(directory_.string()), Error); }

TEST(ChainIoExamples, ShippedFilesParse) {
  const std::filesystem::path directory = std::filesystem::path(SCALLOP_EXAMPLES_DIR) / "chains";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    const std::string extension = entry.path().extension().string();
    if (extension != ".txt" && extension != ".json" && extension != ".csv") continue;
    SCOPED_TRACE(entry.path().string());
    const Chain chain = readChain(entry.path().string());
    EXPECT_GE(chain.size(), 2u);
    EXPECT_NO_THROW(validateChain(chain));
    ++count;
  }
  EXPECT_GE(count, 2);
}

TEST(ChainIoExamples, Figure2FileMatchesBuiltIn) {
  const std::filesystem::path file =
      std::filesystem::path(SCALLOP_EXAMPLES_DIR) / "chains" / "figure2.txt";
  expectSameChain(readChain(file.string()), exampleChain("figure2"));
}

TEST(ChainIoExamples, BuiltInsAreValidAndAsDescribed) {
  const std::vector<std::string> names = exampleChainNames();
  for (const char* required : {"figure2", "steps", "sawtooth", "sine"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    EXPECT_NO_THROW(validateChain(exampleChain(name)));
  }

  const Chain figure2 = exampleChain("figure2");
  EXPECT_GE(figure2.size(), 20u);
  EXPECT_LE(figure2.size(), 30u);

  // "steps" has vertical edges going up and going down.
  const Chain steps = exampleChain("steps");
  bool up = false;
  bool down = false;
  for (std::size_t i = 1; i < steps.size(); ++i) {
    if (steps[i].x == steps[i - 1].x) {
      up = up || steps[i].z > steps[i - 1].z;
      down = down || steps[i].z < steps[i - 1].z;
    }
  }
  EXPECT_TRUE(up);
  EXPECT_TRUE(down);

  const Chain sine = exampleChain("sine");
  EXPECT_GE(sine.size(), 150u);
  for (const Point2& p : sine) EXPECT_NEAR(p.z, std::sin(p.x), 1e-15);
}

TEST(ChainIoExamples, UnknownNameIsAnErrorNamingIt) {
  try {
    exampleChain("no-such-example");
    FAIL();
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("'no-such-example'"), std::string::npos);
  }
}

}  // namespace
}  // namespace scallop
