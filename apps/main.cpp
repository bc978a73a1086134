// scallop: command-line front end of the library. main() builds the CLI, dispatches to the
// subcommand, and is the one place errors are caught: each is printed once, as
// "scallop: error: <message>", and the exit status is 1 (CLI11's own, non-zero codes for
// usage errors).

#include <cstdio>
#include <exception>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "commands.hpp"

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
  scallop::cli::addHullCommand(app);
  scallop::cli::addOrientCommand(app);
  scallop::cli::addPathsCommand(app);
  scallop::cli::addPlanCommand(app);
  int status = 0;  // a command's own non-zero status that is not an error (verify --fail-on-gouge)
  scallop::cli::addVerifyCommand(app, status);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  } catch (const std::exception& error) {
    // scallop::Error (bad input, unwritable output) and anything else, e.g. std::bad_alloc.
    return reportError(error.what());
  }
  return status;
}
