#pragma once
// The fixture of the end-to-end tests of the `scallop` program (cli_test.cpp,
// orient_cli_test.cpp): each test runs the built binary (SCALLOP_CLI_PATH) in a fresh
// temporary directory, with stdout and stderr captured in a second one, so that the run's
// directory holds only what the program itself created.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace scallop::test {

struct RunResult {
  int exitCode = -1;
  std::string out;
  std::string err;
};

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class CliFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    workDir_ = makeTempDir("scallop-cli-");
    captureDir_ = makeTempDir("scallop-cli-capture-");
  }
  void TearDown() override {
    std::filesystem::remove_all(workDir_);
    std::filesystem::remove_all(captureDir_);
  }

  static std::filesystem::path makeTempDir(const std::string& prefix) {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    return pattern;
  }

  void write(const std::string& name, const std::string& content) const {
    std::ofstream(workDir_ / name, std::ios::binary) << content;
  }

  // Runs `scallop <arguments>` in the work directory. Arguments are passed through the
  // shell: tests quote them as needed.
  RunResult run(const std::string& arguments, const std::string& stdinFile = "") const {
    const std::filesystem::path out = captureDir_ / "stdout";
    const std::filesystem::path err = captureDir_ / "stderr";
    std::string command = "cd '" + workDir_.string() + "' && '" SCALLOP_CLI_PATH "' " + arguments +
                          " > '" + out.string() + "' 2> '" + err.string() + "'";
    if (!stdinFile.empty()) command += " < '" + stdinFile + "'";
    const int status = std::system(command.c_str());
    RunResult result;
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = readFile(out);
    result.err = readFile(err);
    return result;
  }

  // A run on bad input failed cleanly: exit status 1, one line "scallop: error: ..." on
  // stderr containing every one of `messageParts`, nothing on stdout, and no file left in the
  // work directory but the input the test wrote (`inputName`, or none).
  void expectCleanFailure(const RunResult& result, const std::vector<std::string>& messageParts,
                          const char* inputName) const {
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_EQ(result.err.rfind("scallop: error: ", 0), 0u) << result.err;
    for (const std::string& part : messageParts) {
      EXPECT_NE(result.err.find(part), std::string::npos)
          << "stderr '" << result.err << "' lacks '" << part << "'";
    }
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_TRUE(result.out.empty()) << result.out;
    const std::vector<std::string> expected =
        inputName == nullptr ? std::vector<std::string>{} : std::vector<std::string>{inputName};
    EXPECT_EQ(listing(), expected);
  }

  // The names in the work directory, sorted (not recursive).
  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(workDir_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  std::filesystem::path workDir_;
  std::filesystem::path captureDir_;
};

}  // namespace scallop::test
