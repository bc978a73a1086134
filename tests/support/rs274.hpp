#pragma once
// LinuxCNC's G-code interpreter, rs274 (Debian package linuxcnc-uspace), as the tests run it
// (gcode_test.cpp, paths_cli_test.cpp). Quirks (LinuxCNC 2.9): `rs274 -t tools.tbl -v
// params.var -g prog.ngc` runs headless, prints canonical calls on stdout and errors on stderr
// (exit status 1); it maps $HOME/.tool.mmap, so every run gets its own HOME.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#ifndef SCALLOP_RS274_PATH
#define SCALLOP_RS274_PATH ""
#endif

namespace scallop::test {

// rs274: where CMake found it, else on PATH; empty when it is not installed.
inline std::string findRs274() {
  namespace fs = std::filesystem;
  const std::string configured = SCALLOP_RS274_PATH;
  if (!configured.empty() && ::access(configured.c_str(), X_OK) == 0) return configured;
  const char* pathVariable = std::getenv("PATH");
  std::stringstream directories(pathVariable ? pathVariable : "");
  std::string directory;
  while (std::getline(directories, directory, ':')) {
    if (directory.empty()) continue;
    const fs::path candidate = fs::path(directory) / "rs274";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

struct Rs274Run {
  int exitCode = -1;
  std::string out;
  std::string err;
};

// Runs `rs274 -g` on `program` in a fresh temporary directory, removed afterwards, which
// holds everything the interpreter touches: it is the working directory and HOME (rs274
// creates, truncates and maps $HOME/.tool.mmap, so parallel runs sharing a HOME crash each
// other with SIGBUS), and holds an empty tool table (-t; by default rs274 reads a sample
// one from /usr/share/doc) and the parameter file (-v; by default it tries to write one
// under /etc/emc2).
inline Rs274Run runRs274(const std::string& rs274, const std::string& program) {
  namespace fs = std::filesystem;
  std::string pattern = (fs::temp_directory_path() / "scallop-gcode-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  const fs::path dir = pattern;
  std::ofstream(dir / "program.ngc", std::ios::binary) << program;
  std::ofstream(dir / "tools.tbl", std::ios::binary) << "";
  // Empty, but present: rs274 links the old file to a backup and complains if it is missing.
  std::ofstream(dir / "params.var", std::ios::binary) << "";
  const std::string command = "cd '" + dir.string() + "' && HOME='" + dir.string() + "' '" +
                              rs274 +
                              "' -t tools.tbl -v params.var -g program.ngc > canon.txt "
                              "2> err.txt < /dev/null";
  const int status = std::system(command.c_str());
  Rs274Run run;
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  run.out = slurp(dir / "canon.txt");
  run.err = slurp(dir / "err.txt");
  fs::remove_all(dir);
  return run;
}

// One canonical call of rs274's output, "   12 N..... STRAIGHT_FEED(1.0000, 2.0000, ...)":
// its name and the text between its parentheses; none for any other line. Read by hand, not
// with std::regex: libstdc++'s matcher recurses once per character, and on a long call's
// arguments that overflowed the stack under AddressSanitizer.
struct CanonLine {
  std::string name;
  std::string arguments;
};

inline std::optional<CanonLine> parseCanonLine(const std::string& line) {
  const auto isSpace = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::size_t i = 0;
  while (i < line.size() && isSpace(line[i])) ++i;
  const std::size_t digits = i;
  while (i < line.size() && line[i] >= '0' && line[i] <= '9') ++i;
  const std::string marker = " N..... ";
  if (i == digits || line.compare(i, marker.size(), marker) != 0) return std::nullopt;
  i += marker.size();
  const std::size_t nameStart = i;
  while (i < line.size() && ((line[i] >= 'A' && line[i] <= 'Z') || (line[i] >= '0' && line[i] <= '9') || line[i] == '_'))
    ++i;
  if (i == nameStart || i >= line.size() || line[i] != '(') return std::nullopt;
  std::size_t end = line.size();
  while (end > i && isSpace(line[end - 1])) --end;
  if (end <= i + 1 || line[end - 1] != ')') return std::nullopt;
  return CanonLine{line.substr(nameStart, i - nameStart), line.substr(i + 1, end - 1 - (i + 1))};
}

}  // namespace scallop::test
