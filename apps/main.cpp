// scallop: command-line front end of the library. main() builds the CLI, dispatches to the
// subcommand, and is the one place errors are caught: each is printed once, as
// "scallop: error: <message>", and the exit status is 1, usage errors included.

#include <cstdio>
#include <exception>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "scallop/parallel.hpp"

#ifndef SCALLOP_VERSION
#error "SCALLOP_VERSION is set by apps/CMakeLists.txt from project(VERSION ...)"
#endif

namespace {

int reportError(const char* message) {
  fmt::print(stderr, "scallop: error: {}\n", message);
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Exact tool paths for ball-end milling: the scallop hull of a monotone chain "
      "(a section of a surface) and its offset, the tool-centre path; and the optimal slicing "
      "orientation of a free-form surface; contour and raster tool paths and G-code from them;"
      " and the simulation of a program's cut, to verify it.",
      "scallop"};
  app.set_version_flag("--version", std::string("scallop ") + SCALLOP_VERSION);
  app.require_subcommand(1);
  // Before or after the command's name (fallthrough): every command's parallel parts use it,
  // and every output is the same for every count (parallel.hpp).
  app.add_option_function<std::size_t>(
         "--threads", [](std::size_t threads) { scallop::setThreadCount(threads); },
         "Threads for the parallel parts (0: every core, the default); the output is the same for any count")
      ->check(CLI::Range(std::size_t{0}, std::size_t{1024}));
  app.fallthrough();
  scallop::cli::addHullCommand(app);
  scallop::cli::addOrientCommand(app);
  scallop::cli::addPathsCommand(app);
  scallop::cli::addPlanCommand(app);
  int status = 0;  // a command's own non-zero status that is not an error (verify --fail-on-gouge)
  scallop::cli::addVerifyCommand(app, status);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    // --help and --version are "errors" with exit code 0: CLI11 prints them. Every other one
    // is a usage error: one line and exit status 1, as any other error (CLI11's own would be
    // 105-109 and a second line).
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    std::string help = "scallop --help";
    for (const CLI::App* command : app.get_subcommands()) help = fmt::format("scallop {} --help", command->get_name());
    return reportError(fmt::format("{} (see {})", error.what(), help).c_str());
  } catch (const std::exception& error) {
    // scallop::Error (bad input, unwritable output) and anything else, e.g. std::bad_alloc.
    return reportError(error.what());
  }
  return status;
}
