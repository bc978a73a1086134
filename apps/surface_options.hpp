#pragma once
// Command-line pieces that `orient`, `paths` and `plan` share: where the surface comes from
// (a JSON, .bpt, STEP or IGES file, standard input or a built-in example, and which of its
// patches) and,
// for the tool-path commands, the strategy and the G-code dialect.

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "scallop/cad/cad_import.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop::cli {

/// SURFACE (a path, "-" for standard input) or --example NAME; at most one is set. `patches`,
/// when not empty, keeps only those patches of the surface (--patches "4-7,12"). `skipFaces`:
/// a STEP or IGES file's faces that cannot be imported exactly are left out (--skip-faces)
/// instead of failing.
struct SurfaceSource {
  std::string input;
  std::string example;
  std::string patches;
  bool skipFaces = false;
  bool acceptRational = true;  // STEP/IGES rational faces as rational patches (every command takes them)
  bool exactTrims = false;     // --exact-trims: trimmed B-spline faces kept whole with their trims
};

/// Adds --exact-trims (plan, paths, verify): STEP/IGES trimmed faces of B-spline and Bezier
/// surfaces (and planes) taken exactly, with their trims (cad_import.hpp's keepTrims).
void addExactTrimsOption(CLI::App& command, SurfaceSource& source);

/// Adds the SURFACE positional and --example NAME (checked against the built-in names,
/// mutually exclusive), --patches LIST and --skip-faces to `command`.
void addSurfaceSourceOptions(CLI::App& command, SurfaceSource& source, const std::string& fileHelp,
                             const std::string& exampleHelp);

/// Throws CLI::ValidationError for `command` unless exactly one of the file and the example
/// is given.
void requireOneSurfaceSource(const SurfaceSource& source, const std::string& command);

/// Adds --skip-faces alone (for commands that declare their own SURFACE).
void addSkipFacesOption(CLI::App& command, SurfaceSource& source);

/// The surface: the example if named, else the file (scallop::Error naming the file on bad
/// input), reduced to the selected patches if any. A STEP or IGES file (cad_import.hpp's
/// cadFormatOf: by extension, or by its first line) goes through scallop::cad, which
/// validates every patch and names the face at fault; when `announce`, a line on stderr then
/// says what was read: format, faces, patches, units, faces skipped. Any other file is JSON or
/// .bpt; with a selection it is validated after the selection, so the patches not kept need
/// not be regular; errors name the patches by their indices in the file. `imported`: a STEP or
/// IGES file's faces already converted (CadRoute::exact), used instead of reading it again.
Surface loadSurface(const SurfaceSource& source, bool announce = true, const CadImport* imported = nullptr);

/// How a command takes a STEP or IGES part: on its exact faces (the surface route), or through
/// its tessellation (cad_tessellation.hpp) when some face cannot be imported exactly or
/// --tessellate is given. The part is read once.
struct CadRoute {
  std::optional<CadPart> part;     ///< read when the input is STEP or IGES and --skip-faces is not given
  std::optional<CadImport> exact;  ///< its faces converted exactly (without --tessellate)
  bool tessellate = false;         ///< take the part through its tessellation
};

/// The route for `source`. Refused in one line, before the file is read: --tessellate or
/// --deflection for anything but STEP or IGES, --tessellate with --skip-faces, a deflection
/// that is not a positive length; after it, --deflection on the exact route.
/// `exactOptions`: what the exact route takes (orient's Gauss map takes rational faces and
/// trimmed faces' pieces; the others neither).
CadRoute cadRoute(const SurfaceSource& source, bool tessellate, const std::string& deflection,
                  const CadImportOptions& exactOptions = {});

/// The exact route's options for plan, paths and verify: rational faces as rational patches
/// (sections, distances and the simulated cut take them); trimmed faces refused (their tool
/// paths would not stop at the trimming curves: the part goes through its tessellation).
CadImportOptions exactRationalFaces(const SurfaceSource& source);

/// How messages and reports name the surface: "example NAME", "<stdin>" or the path, followed
/// by " (patches LIST)" when some are selected.
std::string sourceName(const SurfaceSource& source);

/// A mesh by its name: .stl in any case.
bool isStlPath(const std::string& path);

/// Standard input's bytes, read once on first use: a command looks at them (is it STL?)
/// before it parses them. scallop::Error when it cannot be read.
const std::string& standardInput();

/// Whether the surface argument is an STL mesh: by its name (.stl); a name that is none of
/// scallop's other forms (.json, .bpt, .step, .stp, .iges, .igs), and standard input ("-"),
/// by content (mesh.hpp's looksLikeStl).
bool isStlSource(const std::string& path);

/// The STL mesh at `path` ("-": standard input) in `units` ("in" or "mm"; empty: mm, STL has
/// none); zero-area triangles refused (the message then names --drop-zero-area) unless
/// `dropZeroArea`.
StlMesh loadStlMesh(const std::string& path, const std::string& units, bool dropZeroArea);

/// --units in|mm and --drop-zero-area, for commands that take an STL mesh.
void addStlOptions(CLI::App& command, std::string& units, bool& dropZeroArea);

/// --strategy contour|raster and --dialect linuxcnc|grbl, into `strategy` and `dialect`.
void addStrategyOption(CLI::App& command, std::string& strategy);
void addDialectOption(CLI::App& command, std::string& dialect);

/// The dialect named by --dialect (already checked by the option).
GcodeDialect gcodeDialect(const std::string& name);

}  // namespace scallop::cli
