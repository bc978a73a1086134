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
