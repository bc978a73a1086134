// End-to-end tests of the `scallop` program: each run happens in a fresh temporary
// directory; failures must exit non-zero, say what and where (file, line, value), and leave
// no output file and no temporary behind; the happy path writes JSON and SVG that agree
// with the library.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "support/cli_fixture.hpp"
#include "scallop/paths/chain.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

using test::readFile;
using test::RunResult;

class Cli : public test::CliFixture {};

// ---------------------------------------------------------------------------------------
// Bad input: non-zero exit, a message naming the place and value, nothing written.
// ---------------------------------------------------------------------------------------

struct BadRun {
  const char* what;
  const char* inputName;  // nullptr: no input file is created
  const char* content;
  const char* arguments;  // after "hull"; output options are appended
  std::vector<std::string> messageParts;
};

const std::vector<BadRun>& badRuns() {
  static const std::vector<BadRun> runs = {
      {"x decreasing",
       "in.txt",
       "0 0\n1 1\n# comment\n0.5 2\n",
       "in.txt -r 1",
       {"in.txt:4:", "'0.5'"}},
      {"NaN coordinate", "in.txt", "0 0\n1 nan\n", "in.txt -r 1", {"in.txt:2:", "'nan'"}},
      {"infinite coordinate", "in.txt", "0 0\ninf 1\n", "in.txt -r 1", {"in.txt:2:", "'inf'"}},
      {"one point", "in.txt", "0 0\n", "in.txt -r 1", {"in.txt:1:", "at least 2"}},
      {"empty file", "in.txt", "", "in.txt -r 1", {"in.txt", "no points"}},
      {"malformed line", "in.txt", "0 0\n1 2 3\n", "in.txt -r 1", {"in.txt:2:", "'3'"}},
      {"trailing garbage", "in.txt", "0 0\n1 2x\n", "in.txt -r 1", {"in.txt:2:", "'2x'"}},
      {"malformed JSON",
       "in.json",
       "{\"points\": [[0, 0], [1, 2]\n",
       "in.json -r 1",
       {"in.json", "line 2"}},
      {"bad JSON point",
       "in.json",
       "{\"points\": [[0, 0], [1, \"2\"]]}",
       "in.json -r 1",
       {"in.json", "points[1]"}},
      {"r below the coordinates' tolerance", "in.txt", "0 1e15\n1 1e15\n", "in.txt -r 1",
       {"in.txt", "radius 1 is below"}},
      {"r zero", "in.txt", "0 0\n1 1\n", "in.txt -r 0", {"radius", "'0'"}},
      {"r negative", "in.txt", "0 0\n1 1\n", "in.txt --radius=-2.5", {"radius", "'-2.5'"}},
      {"r NaN", "in.txt", "0 0\n1 1\n", "in.txt -r nan", {"radius", "'nan'"}},
      {"r not a number", "in.txt", "0 0\n1 1\n", "in.txt -r abc", {"radius", "'abc'"}},
      {"r trailing garbage", "in.txt", "0 0\n1 1\n", "in.txt -r 1mm", {"radius", "'1mm'"}},
      {"tolerance zero", "in.txt", "0 0\n1 1\n", "in.txt -r 1 --tolerance 0", {"tolerance", "'0'"}},
      {"missing file", nullptr, "", "missing.txt -r 1", {"missing.txt", "No such file"}},
  };
  return runs;
}

TEST_F(Cli, BadInputFailsWithMessageAndWritesNothing) {
  for (const BadRun& bad : badRuns()) {
    SCOPED_TRACE(bad.what);
    fs::remove_all(workDir_);
    fs::create_directory(workDir_);
    if (bad.inputName != nullptr) write(bad.inputName, bad.content);
    const RunResult result =
        run(std::string("hull ") + bad.arguments + " --json out.json --svg out.svg");
    expectCleanFailure(result, bad.messageParts, bad.inputName);
  }
}

// A document nested 80,000 deep (issue 15's audit: the message quoting the value recursed
// once a level and overflowed the stack) is refused while it is parsed, by every command that
// reads JSON: one line, exit 1, nothing written.
TEST_F(Cli, DeeplyNestedJsonIsRefusedByEveryCommand) {
  const std::size_t depth = 80000;
  const std::string nested = std::string(depth, '[') + std::string(depth, ']');
  write("chain.json", "{\"points\": [[0, 0], " + nested + "]}");
  expectCleanFailure(run("hull chain.json -r 1"), {"chain.json", "malformed JSON", "nested more than 64"}, "chain.json");
  std::filesystem::remove(workDir_ / "chain.json");
  write("surface.json", "{\"units\": \"in\", \"patches\": [" + nested + "]}");
  for (const std::string command :
       {"orient surface.json", "paths surface.json --tool-radius 0.25 --scallop-height 0.01 --json out.json", "plan surface.json --out out"})
    expectCleanFailure(run(command), {"surface.json", "malformed JSON", "nested more than 64"}, "surface.json");
  write("p.ngc", "G20\nG0 X0 Y0 Z1\nM2\n");
  const scallop::test::RunResult verify = run("verify surface.json p.ngc --radius 0.25");
  EXPECT_EQ(verify.exitCode, 1);
  EXPECT_EQ(verify.err.rfind("scallop: error: surface.json: malformed JSON: arrays or objects nested more than 64", 0), 0u)
      << verify.err;
  EXPECT_EQ(std::count(verify.err.begin(), verify.err.end(), '\n'), 1) << verify.err;
}

// Every usage error, the option parser's (a missing or unknown option, a bad choice, too
// many files: CLI11's exit codes 105-109 and a second line before) and scallop's own, is one
// line "scallop: error: ..." and exit status 1, as the README says.
TEST_F(Cli, UsageErrorsFailWithoutOutput) {
  write("in.txt", "0 0\n1 1\n");
  for (const char* arguments :
       {"", "hull --json out.json -r 1", "hull in.txt --example figure2 -r 1 --json out.json",
        "hull --example nope -r 1 --json out.json", "hull in.txt --json out.json",
        "hull in.txt -r 1 --bogus", "hull in.txt -r 1 --json - --svg -", "bogus", "hull in.txt -r",
        "verify in.txt p.ngc --tool-radius 2", "orient in.txt --method nope", "plan --out"}) {
    SCOPED_TRACE(arguments);
    const RunResult result = run(arguments);
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_EQ(result.err.rfind("scallop: error: ", 0), 0u) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(listing(), std::vector<std::string>{"in.txt"});
  }
  // An unknown option is named as such, with its command, whatever else is wrong or missing
  // (CLI11 alone said "--radius is required" or "FILES: At Most 2 required but received 3").
  for (const auto& [arguments, said] : std::vector<std::pair<std::string, std::string>>{
           {"verify --example paper-1 p.ngc --tool-radius 2", "unknown option '--tool-radius' for scallop verify"},
           {"hull --example figure2 -r 1 --bogus 3", "unknown option '--bogus' for scallop hull"},
           {"plan --example paper-1 --tool-radius=1 -x", "unknown option '-x' for scallop plan"},
           {"--threads 1 --bogus hull in.txt -r 1", "unknown option '--bogus' for scallop (see scallop --help)"}}) {
    SCOPED_TRACE(arguments);
    const RunResult result = run(arguments);
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_NE(result.err.find(said), std::string::npos) << result.err;
    EXPECT_EQ(listing(), std::vector<std::string>{"in.txt"});
  }
  // Negative numbers are values, not options: the radius is what is wrong.
  EXPECT_NE(run("hull in.txt -r -2.5").err.find("invalid radius '-2.5'"), std::string::npos);
  // Help and the version are not errors.
  for (const char* arguments : {"--help", "hull --help", "--version"}) {
    SCOPED_TRACE(arguments);
    const RunResult result = run(arguments);
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_FALSE(result.out.empty());
  }
}

TEST_F(Cli, UnwritableSecondOutputRemovesTheFirst) {
  write("in.txt", "0 0\n1 1\n2 0\n");
  for (const char* outputs :
       {"--json out.json --svg nodir/out.svg", "--json nodir/out.json --svg out.svg"}) {
    SCOPED_TRACE(outputs);
    const RunResult result = run(std::string("hull in.txt -r 0.5 ") + outputs);
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_NE(result.err.find("nodir/out."), std::string::npos) << result.err;
    EXPECT_EQ(listing(), std::vector<std::string>{"in.txt"});
  }
}

// ---------------------------------------------------------------------------------------
// Happy paths
// ---------------------------------------------------------------------------------------

Point2 pointOf(const Json& json) { return {json.at(0).get<double>(), json.at(1).get<double>()}; }

// Each element starts exactly where the previous one ends; the path runs from
// (x_0 - r, z_0) to (x_{n-1} + r, z_{n-1}).
void expectContiguousToolPath(const Json& doc, const Chain& chain, double r) {
  const Json& path = doc.at("toolpath");
  ASSERT_FALSE(path.empty());
  for (std::size_t i = 1; i < path.size(); ++i) {
    EXPECT_EQ(pointOf(path[i].at("start")), pointOf(path[i - 1].at("end"))) << "element " << i;
  }
  const Point2 first = pointOf(path.front().at("start"));
  const Point2 last = pointOf(path.back().at("end"));
  EXPECT_NEAR(first.x, chain.front().x - r, 1e-12);
  EXPECT_NEAR(first.z, chain.front().z, 1e-12);
  EXPECT_NEAR(last.x, chain.back().x + r, 1e-12);
  EXPECT_NEAR(last.z, chain.back().z, 1e-12);
}

TEST_F(Cli, WritesJsonAndSvg) {
  const RunResult result =
      run("hull --example figure2 --radius 1 --json out.json --svg out.svg --tolerance 0.01");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(listing(), (std::vector<std::string>{"out.json", "out.svg"}));
  EXPECT_TRUE(result.out.empty());
  EXPECT_NE(result.err.find("n = 27"), std::string::npos) << result.err;

  const Json doc = Json::parse(readFile(workDir_ / "out.json"));
  const Chain chain = exampleChain("figure2");
  EXPECT_EQ(doc.at("radius").get<double>(), 1.0);
  EXPECT_EQ(doc.at("stats").at("vertices").get<std::size_t>(), chain.size());
  expectContiguousToolPath(doc, chain, 1.0);
  const Json& polyline = doc.at("polyline");
  ASSERT_GE(polyline.size(), 2u);
  EXPECT_EQ(pointOf(polyline.front()), pointOf(doc["toolpath"].front().at("start")));
  EXPECT_EQ(pointOf(polyline.back()), pointOf(doc["toolpath"].back().at("end")));

  const std::string svg = readFile(workDir_ / "out.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

TEST_F(Cli, ReplacesExistingOutputs) {
  write("out.json", "stale");
  const RunResult result = run("hull --example steps -r 0.5 --json out.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NO_THROW(Json::parse(readFile(workDir_ / "out.json")));
  EXPECT_EQ(listing(), std::vector<std::string>{"out.json"});
}

TEST_F(Cli, JsonGoesToStandardOutputByDefault) {
  const std::string input = (fs::path(SCALLOP_EXAMPLES_DIR) / "chains" / "figure2.txt").string();
  const RunResult result = run("hull '" + input + "' -r 1");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;  // no summary when stdout carries the JSON
  expectContiguousToolPath(Json::parse(result.out), readChain(input), 1.0);
  EXPECT_TRUE(listing().empty());
}

TEST_F(Cli, ReadsStandardInput) {
  const std::string input = (fs::path(SCALLOP_EXAMPLES_DIR) / "chains" / "pits.json").string();
  const RunResult result = run("hull - -r 0.5 --json -", input);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  expectContiguousToolPath(Json::parse(result.out), readChain(input), 0.5);
}

TEST_F(Cli, InfiniteRadius) {
  for (const char* spelling : {"inf", "infinity", "Inf"}) {
    SCOPED_TRACE(spelling);
    const RunResult result = run(std::string("hull --example sawtooth -r ") + spelling);
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Json doc = Json::parse(result.out);
    EXPECT_TRUE(doc.at("radius").is_null());
    EXPECT_TRUE(doc.at("toolpath").empty());
    EXPECT_FALSE(doc.at("hull").empty());
  }
}

// ---------------------------------------------------------------------------------------
// Reproducible files: every command's outputs are the same bytes run after run and for
// every thread count (parallel.hpp; 2 is every core on the CI machine); no wall time is
// written into them.
// ---------------------------------------------------------------------------------------

// Every regular file under `dir`, by its path relative to it, with its content.
std::vector<std::pair<std::string, std::string>> filesUnder(const fs::path& dir) {
  std::vector<std::pair<std::string, std::string>> files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) files.emplace_back(fs::relative(entry.path(), dir).string(), readFile(entry.path()));
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST_F(Cli, EveryCommandWritesTheSameBytesOnEveryRunAndThreadCount) {
  // A 24 x 24 grid of paper-1's points as an ASCII STL (the mesh route).
  const Surface paper1 = exampleSurface("paper-1");
  std::string stl = "solid paper1\n";
  const int n = 24;
  const auto at = [&](int i, int j) { return point(paper1.patches[0], i / double(n), j / double(n)); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      for (const std::array<Vec3, 3>& t : {std::array<Vec3, 3>{at(i, j), at(i + 1, j), at(i + 1, j + 1)},
                                           std::array<Vec3, 3>{at(i, j), at(i + 1, j + 1), at(i, j + 1)}}) {
        stl += "facet normal 0 0 0\nouter loop\n";
        for (const Vec3& v : t) stl += fmt::format("vertex {} {} {}\n", v.x, v.y, v.z);
        stl += "endloop\nendfacet\n";
      }
  stl += "endsolid paper1\n";
  const fs::path inputs = makeTempDir("scallop-cli-inputs-");
  std::ofstream(inputs / "paper1.stl", std::ios::binary) << stl;
  const std::string mesh = "'" + (inputs / "paper1.stl").string() + "'";
  // Each command with every output it has (figures included), into the folder `o`.
  const std::vector<std::string> commands = {
      "hull --example figure2 --radius 1 --tolerance 0.01 --json o/h.json --svg o/h.svg",
      "orient --example paper-1 --json o/o.json --svg-dir o/figures",
      "paths --example paper-2 --strategy raster --tool-radius 0.25 --scallop-height 0.01 --json o/p.json "
      "--gcode o/p.ngc --svg o/p.svg",
      "plan --example paper-1 --tool-radius 0.25 --scallop-height 0.01 --out o/plan",
      "plan " + mesh + " --units in --tool-radius 0.25 --scallop-height 0.01 --out o/mesh",
      "verify --example paper-2 o/p.ngc --radius 0.25 --scallop-height 0.01 --json o/v.json --svg o/v.svg",
  };
  std::vector<std::pair<std::string, std::string>> first;
  for (const char* threads : {"1", "2", "2"}) {
    SCOPED_TRACE(std::string("--threads ") + threads);
    fs::remove_all(workDir_ / "o");
    fs::create_directories(workDir_ / "o");
    for (const std::string& command : commands) {
      // The option goes before the command or after it: both are read.
      const RunResult result = run(command.substr(0, command.find(' ')) + " --threads " + threads +
                                   command.substr(command.find(' ')));
      ASSERT_EQ(result.exitCode, 0) << command << ": " << result.err;
    }
    const std::vector<std::pair<std::string, std::string>> files = filesUnder(workDir_ / "o");
    if (first.empty()) {
      first = files;
      EXPECT_EQ(first.size(), 20u);  // reports, programs, JSON and every figure
      for (const auto& [name, content] : first) EXPECT_EQ(content.find("seconds"), std::string::npos) << name;
      continue;
    }
    ASSERT_EQ(files.size(), first.size());
    for (std::size_t i = 0; i < files.size(); ++i) {
      EXPECT_EQ(files[i].first, first[i].first);
      EXPECT_TRUE(files[i].second == first[i].second) << files[i].first << " differs";
    }
  }
  const RunResult before = run("--threads 1 hull --example figure2 --radius 1 --json -");
  EXPECT_EQ(before.exitCode, 0) << before.err;
  for (const char* bad : {"--threads -1", "--threads 2000", "--threads two"}) {
    const RunResult refused = run(std::string("hull --example figure2 --radius 1 ") + bad);
    EXPECT_EQ(refused.exitCode, 1) << bad;
    EXPECT_NE(refused.err.find("--threads"), std::string::npos) << refused.err;
  }
  fs::remove_all(inputs);
}

// `plan --out` over an earlier result, killed (SIGKILL) at moments spread over its run: the
// directory holds the old result or the new one, whole, never a mix and never a temporary
// (a kill leaves at most a hidden sibling). A directory holding a file plan does not write is
// refused before any work and left as it was.
TEST_F(Cli, PlanOutIsTheOldResultOrTheNewOneUnderAKillAtAnyMoment) {
  const std::string common = "plan --example paper-1 --tool-radius 0.25 --quiet --threads 1 --scallop-height ";
  const auto started = std::chrono::steady_clock::now();
  ASSERT_EQ(run(common + "0.02 --out reference").exitCode, 0);
  const double runSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_EQ(run(common + "0.04 --out old").exitCode, 0);
  const auto newFiles = filesUnder(workDir_ / "reference");
  const auto oldFiles = filesUnder(workDir_ / "old");
  ASSERT_EQ(newFiles.size(), 7u);
  ASSERT_FALSE(newFiles == oldFiles);
  int sawOld = 0, sawNew = 0;
  for (int k = 0; k <= 12; ++k) {
    const double delay = runSeconds * 0.1 * k;  // from the start to past the end of the run
    SCOPED_TRACE(delay);
    const std::string command =
        fmt::format("cd '{}' && ('{}' {}0.02 --out old & pid=$!; sleep {}; kill -9 $pid; wait $pid) >/dev/null 2>&1",
                    workDir_.string(), SCALLOP_CLI_PATH, common, delay);
    (void)std::system(command.c_str());  // killed or finished: the directory is what is judged
    const auto files = filesUnder(workDir_ / "old");
    if (files == oldFiles) {
      ++sawOld;
    } else if (files == newFiles) {
      ++sawNew;
      ASSERT_EQ(run(common + "0.04 --out old").exitCode, 0);  // the old result back
    } else {
      ADD_FAILURE() << "a mix of the two results, or a temporary, in old/ (" << files.size() << " files)";
    }
    for (const fs::directory_entry& entry : fs::directory_iterator(workDir_)) {
      const std::string name = entry.path().filename().string();
      EXPECT_TRUE(name == "old" || name == "reference" || name.rfind(".old.tmp-", 0) == 0) << name;
    }
  }
  EXPECT_GT(sawOld, 0);  // a kill at 0 s comes before any output
  std::printf("[          ] %d kills left the old result, %d the new one\n", sawOld, sawNew);
  // Not killed: the new result, whole.
  ASSERT_EQ(run(common + "0.02 --out old").exitCode, 0);
  EXPECT_TRUE(filesUnder(workDir_ / "old") == newFiles);
  // A file of the user's in the directory: refused at once, nothing touched.
  write("old/notes.txt", "mine");
  const RunResult refused = run(common + "0.04 --out old");
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.err.find("'old' holds 'notes.txt'"), std::string::npos) << refused.err;
  EXPECT_EQ(refused.err.find("scallop plan: "), std::string::npos) << refused.err;  // no work began
  EXPECT_EQ(filesUnder(workDir_ / "old").size(), 8u);
  EXPECT_EQ(readFile(workDir_ / "old" / "notes.txt"), "mine");
  for (const char* out : {".", "..", "old/notes.txt"}) {
    const RunResult bad = run(common + "0.04 --out " + out);
    EXPECT_EQ(bad.exitCode, 1) << out;
    EXPECT_NE(bad.err.find(std::string("'") + out + "'"), std::string::npos) << bad.err;
  }
}

TEST_F(Cli, VersionAndHelp) {
  const RunResult version = run("--version");
  EXPECT_EQ(version.exitCode, 0);
  EXPECT_NE(version.out.find("scallop "), std::string::npos) << version.out;

  const RunResult help = run("hull --help");
  EXPECT_EQ(help.exitCode, 0);
  for (const char* part :
       {"--radius", "--json", "--svg", "--tolerance", "--example", "scallop hull"}) {
    EXPECT_NE(help.out.find(part), std::string::npos) << part;
  }
  EXPECT_TRUE(listing().empty());
}

}  // namespace
}  // namespace scallop
