// scallop: command-line front end of the library. main() builds the CLI, dispatches to the
// subcommand, and is the one place errors are caught: each is printed once, as
// "scallop: error: <message>", and the exit status is 1, usage errors included.

#include <cctype>
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

// The first option on the command line that neither the command nor scallop itself knows.
// CLI11 checks the required options and the positionals' count before it looks for unknown
// ones, so a misspelt `--tool-radius` for verify's `--radius` read as "--radius is required"
// or "FILES: At Most 2 required but received 3" (its value taken for a file). Negative
// numbers (-2.5) are values; after "--" everything is.
struct UnknownOption {
  std::string name;     // empty: none
  std::string command;  // "scallop" or "scallop <command>"
};

UnknownOption unknownOption(const CLI::App& app, int argc, char** argv) {
  const CLI::App* command = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string token = argv[i];
    if (token == "--") break;
    if (command == nullptr) {
      for (const CLI::App* sub : app.get_subcommands({})) {
        if (sub->check_name(token)) command = sub;
      }
      if (command != nullptr) continue;
    }
    if (token.size() < 2 || token[0] != '-' || std::isdigit(static_cast<unsigned char>(token[1])) != 0 ||
        token[1] == '.')
      continue;
    // --name=value and -xVALUE name --name and -x.
    const std::string name = token[1] == '-' ? token.substr(0, token.find('=')) : token.substr(0, 2);
    const bool known = app.get_option_no_throw(name) != nullptr ||
                       (command != nullptr && command->get_option_no_throw(name) != nullptr);
    if (!known) return {name, command != nullptr ? "scallop " + command->get_name() : std::string("scallop")};
  }
  return {};
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
    if (const UnknownOption unknown = unknownOption(app, argc, argv); !unknown.name.empty())
      return reportError(fmt::format("unknown option '{}' for {} (see {} --help)", unknown.name, unknown.command,
                                     unknown.command)
                             .c_str());
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
