#include "surface_options.hpp"

#include <cctype>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "arguments.hpp"
#include "scallop/cad/cad_import.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/io/surface_io.hpp"

namespace scallop::cli {
namespace {

// Validates the patches kept from a file one by one, so that a message names a patch by its
// index in the file ("patches[20]"), not in the selection.
void validateSelection(const Surface& selected, const std::vector<std::size_t>& indices,
                       const std::string& source) {
  for (std::size_t s = 0; s < indices.size(); ++s) {
    try {
      validateSurface(Surface{selected.units, {selected.patches[s]}});
    } catch (const Error& error) {
      // validateSurface names the only patch "patches[0]".
      constexpr std::string_view kOnlyPatch = "patches[0]";
      const std::string_view message = error.what();
      const std::string located =
          message.starts_with(kOnlyPatch)
              ? fmt::format("patches[{}]{}", indices[s], message.substr(kOnlyPatch.size()))
              : fmt::format("patches[{}]: {}", indices[s], message);
      throw Error(fmt::format("{}: {}", source, located));
    }
  }
}

// The file name ("<stdin>" for "-") or "example NAME", without the patch selection.
std::string sourceBaseName(const SurfaceSource& source) {
  if (!source.example.empty()) return "example " + source.example;
  return source.input == "-" ? std::string("<stdin>") : source.input;
}

// A STEP or IGES file through scallop::cad, and the line that says what came of it: the
// units especially, which the file chose and every length on the command line is in.
Surface importCadSurface(const SurfaceSource& source, CadFormat format, bool announce, const CadImport* given) {
  CadImportOptions options;
  options.skipUnsupportedFaces = source.skipFaces;
  options.acceptRational = source.acceptRational;
  CadImport imported = given ? *given : importCad(source.input, format, options);
  if (announce) {
    std::string skipped;
    if (!imported.skipped.empty()) {
      std::map<std::string_view, std::size_t> issues;
      for (const SkippedFace& face : imported.skipped) ++issues[cadFaceIssueName(face.issue)];
      std::string counts;
      for (const auto& [issue, count] : issues) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", count, issue);
      skipped = fmt::format("; {} faces skipped ({}), the first: {}", imported.skipped.size(), counts,
                            imported.skipped.front().reason);
    }
    fmt::print(stderr, "scallop: {}: {}, {} faces -> {} Bezier patches, units {} (the file's: {}){}; {:.2f} s\n",
               source.input, cadFormatName(imported.format), imported.faces, imported.surface.patches.size(),
               unitsName(imported.surface.units), imported.fileUnit, skipped, imported.seconds);
  }
  return std::move(imported.surface);
}

}  // namespace

void addSkipFacesOption(CLI::App& command, SurfaceSource& source) {
  command.add_flag("--skip-faces", source.skipFaces,
                   "STEP/IGES: leave out the faces that cannot be imported exactly (trimmed, "
                   "other kinds) instead of failing; they are counted on stderr");
}

void addSurfaceSourceOptions(CLI::App& command, SurfaceSource& source, const std::string& fileHelp,
                             const std::string& exampleHelp) {
  CLI::Option* file = command.add_option("SURFACE", source.input, fileHelp)->type_name("");
  CLI::Option* example = command.add_option("--example", source.example, exampleHelp)
                             ->check(CLI::IsMember(exampleSurfaceNames()))
                             ->type_name("NAME");
  file->excludes(example);
  command
      .add_option("--patches", source.patches,
                  "keep only these patches of the surface: 0-based indices and ranges, e.g. 4 or "
                  "4-7,12")
      ->type_name("LIST");
  addSkipFacesOption(command, source);
}

void requireOneSurfaceSource(const SurfaceSource& source, const std::string& command) {
  if (source.input.empty() == source.example.empty()) {
    throw CLI::ValidationError(command,
                               "give the surface either as SURFACE (.json, .bpt, .step or .iges) or as --example NAME");
  }
}

Surface loadSurface(const SurfaceSource& source, bool announce, const CadImport* imported) {
  const std::optional<CadFormat> cad =
      source.example.empty() ? cadFormatOf(source.input) : std::optional<CadFormat>();
  if (source.skipFaces && !cad)
    throw Error(fmt::format("{}: --skip-faces is for STEP and IGES files", sourceBaseName(source)));
  // Standard input is read once (a command may have looked at it): JSON when its first
  // non-blank character is '{', .bpt otherwise, as readSurface tells them apart.
  const auto read = [&](SurfaceCheck check) {
    if (source.input != "-") return readSurface(source.input, check);
    std::string_view text = standardInput();
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    const std::size_t first = text.find_first_not_of(" \t\r\n\f\v");
    return first != std::string_view::npos && text[first] == '{' ? parseSurface(standardInput(), "-", check)
                                                                  : parseBptSurface(standardInput(), "-", check);
  };
  if (source.patches.empty()) {
    if (cad) return importCadSurface(source, *cad, announce, imported);
    return source.example.empty() ? read(SurfaceCheck::full) : exampleSurface(source.example);
  }
  const std::string name = sourceBaseName(source);
  // Examples are built, not read: they are not validated (as without --patches). A CAD
  // import validates every patch it returns.
  const Surface whole = cad ? importCadSurface(source, *cad, announce, imported)
                        : source.example.empty() ? read(SurfaceCheck::formOnly)
                                                 : exampleSurface(source.example);
  std::vector<std::size_t> indices;
  try {
    indices = parsePatchSelection(source.patches, whole.patches.size());
  } catch (const Error& error) {
    throw Error(fmt::format("{}: --patches: {}", name, error.what()));
  }
  Surface selected = selectPatches(whole, indices);
  if (source.example.empty() && !cad) validateSelection(selected, indices, name);
  return selected;
}

CadRoute cadRoute(const SurfaceSource& source, bool tessellate, const std::string& deflection,
                  const CadImportOptions& exactOptions) {
  const bool cad = !source.input.empty() && source.input != "-" && cadFormatOf(source.input).has_value();
  if (!cad && (tessellate || !deflection.empty()))
    throw Error("--tessellate and --deflection are for STEP and IGES parts (.step, .stp, .iges, .igs)");
  if (!cad && source.exactTrims)
    throw Error(fmt::format("{}: --exact-trims is for STEP and IGES parts (.step, .stp, .iges, .igs)",
                            sourceBaseName(source)));
  if (source.exactTrims && (tessellate || source.skipFaces))
    throw Error(fmt::format("{}: --exact-trims takes trimmed faces exactly; not with {}", source.input,
                            tessellate ? "--tessellate" : "--skip-faces"));
  if (cad && source.skipFaces && tessellate)
    throw Error(fmt::format("{}: --skip-faces takes only the faces imported exactly, --tessellate all of them "
                            "through the mesh: give one",
                            source.input));
  if (!deflection.empty()) (void)parsePositive(deflection, "deflection", "a positive length");
  CadRoute route;
  if (cad && !source.skipFaces) {
    route.part.emplace(source.input);
    if (!tessellate) route.exact = route.part->exactFaces(exactOptions);
    route.tessellate = tessellate || !route.exact->skipped.empty();
  }
  if (!route.tessellate && !deflection.empty())
    throw Error(fmt::format("{}: --deflection is for a tessellated part (--tessellate, or faces that cannot be "
                            "imported exactly); this one is taken on its exact faces",
                            sourceName(source)));
  return route;
}

void addExactTrimsOption(CLI::App& command, SurfaceSource& source) {
  command.add_flag("--exact-trims", source.exactTrims,
                   "STEP/IGES: take trimmed faces exactly, with their trimming curves (B-spline and Bezier surfaces, "
                   "planes, and the cylinders, cones, spheres, tori and revolutions OCCT converts with rational "
                   "quadratic circles), instead of cutting the part through its tessellation (a part with another "
                   "trimmed face is still tessellated)");
}

CadImportOptions exactRationalFaces(const SurfaceSource& source) {
  CadImportOptions options;
  options.acceptRational = true;
  // Trimmed faces exactly, with their trims, where each patch parameter maps onto the face's
  // affinely or by half-angles (cad_import.hpp's keepTrims); others leave the part to the
  // tessellation.
  options.acceptTrimmed = source.exactTrims;
  options.keepTrims = source.exactTrims;
  return options;
}

std::string sourceName(const SurfaceSource& source) {
  std::string name = sourceBaseName(source);
  if (!source.patches.empty()) name += fmt::format(" (patches {})", source.patches);
  return name;
}

void addStrategyOption(CLI::App& command, std::string& strategy) {
  command.add_option("--strategy", strategy, "contour (default for a surface) or raster (always for an STL mesh)")
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

bool isStlPath(const std::string& path) {
  if (path.size() < 4) return false;
  std::string tail = path.substr(path.size() - 4);
  for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return tail == ".stl";
}

const std::string& standardInput() {
  static const std::string bytes = [] {
    std::string content;
    char buffer[1 << 16];
    std::size_t count = 0;
    while ((count = std::fread(buffer, 1, sizeof buffer, stdin)) > 0) content.append(buffer, count);
    if (std::ferror(stdin) != 0) throw Error("cannot read standard input");
    return content;
  }();
  return bytes;
}

bool isStlSource(const std::string& path) {
  if (path.empty()) return false;
  if (path == "-") return looksLikeStl(standardInput(), standardInput().size());
  if (isStlPath(path)) return true;
  std::string lower = path;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const std::string_view known : {".json", ".bpt", ".step", ".stp", ".iges", ".igs"})
    if (lower.ends_with(known)) return false;
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) return false;  // the reader that follows names the problem
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return false;
  char head[256];
  const std::size_t count = std::fread(head, 1, sizeof head, file);
  std::fclose(file);
  return looksLikeStl(std::string_view(head, count), size);
}

StlMesh loadStlMesh(const std::string& path, const std::string& units, bool dropZeroArea) {
  StlOptions stl;
  stl.units = units == "in" ? Units::inch : Units::millimetre;
  stl.dropZeroArea = dropZeroArea;
  try {
    if (path == "-") return parseStl(standardInput(), "<stdin>", stl);
    return readStl(path, stl);
  } catch (const Error& e) {
    if (!dropZeroArea && std::string(e.what()).find("zero area") != std::string::npos)
      throw Error(fmt::format("{}; --drop-zero-area skips such triangles", e.what()));
    throw;
  }
}

void addStlOptions(CLI::App& command, std::string& units, bool& dropZeroArea) {
  command.add_option("--units", units, "an STL mesh's units, in or mm (default mm: STL has none)")
      ->check(CLI::IsMember({"in", "mm"}))
      ->type_name("UNITS");
  command.add_flag("--drop-zero-area", dropZeroArea,
                   "an STL mesh's triangles of zero area are dropped (counted) instead of refused");
}

}  // namespace scallop::cli
