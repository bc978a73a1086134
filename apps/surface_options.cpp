#include "surface_options.hpp"

namespace scallop::cli {

void addSurfaceSourceOptions(CLI::App& command, SurfaceSource& source, const std::string& fileHelp,
                             const std::string& exampleHelp) {
  CLI::Option* file = command.add_option("SURFACE", source.input, fileHelp)->type_name("");
  CLI::Option* example = command.add_option("--example", source.example, exampleHelp)
                             ->check(CLI::IsMember(exampleSurfaceNames()))
                             ->type_name("NAME");
  file->excludes(example);
}

void requireOneSurfaceSource(const SurfaceSource& source, const std::string& command) {
  if (source.input.empty() == source.example.empty()) {
    throw CLI::ValidationError(command, "give the surface either as SURFACE.json or as --example NAME");
  }
}

Surface loadSurface(const SurfaceSource& source) {
  return source.example.empty() ? readSurface(source.input) : exampleSurface(source.example);
}

std::string sourceName(const SurfaceSource& source) {
  if (!source.example.empty()) return "example " + source.example;
  return source.input == "-" ? std::string("<stdin>") : source.input;
}

void addStrategyOption(CLI::App& command, std::string& strategy) {
  command.add_option("--strategy", strategy, "contour (default) or raster")
      ->check(CLI::IsMember({"contour", "raster"}))
      ->type_name("NAME");
}

void addDialectOption(CLI::App& command, std::string& dialect) {
  command.add_option("--dialect", dialect, "G-code dialect: linuxcnc (default) or grbl")
      ->check(CLI::IsMember({"linuxcnc", "grbl"}))
      ->type_name("NAME");
}

GcodeDialect gcodeDialect(const std::string& name) {
  return name == "grbl" ? GcodeDialect::grbl : GcodeDialect::linuxcnc;
}

}  // namespace scallop::cli
