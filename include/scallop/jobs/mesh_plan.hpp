#pragma once
// The plan of a triangle mesh as one library call: an STL mesh, or the tessellation of a STEP
// or IGES part (paths/tessellated_part.hpp, made by cad/tessellate_part.hpp), to its raster
// tool path, G-code program and simulated cut, as `scallop plan PART.stl` makes them (the CLI
// is a shell over these calls; plan.hpp is the same for a surface).
//
// Contract
// --------
// meshToolpaths(mesh, options, control): the raster alone, as `scallop paths PART.stl` writes it:
//   1. the mesh walled down to the top of a solid (mesh_raster.hpp's meshWithSkirt, 4 eps
//      outside its open edges) and its exact drop cutter (mesh_drop.hpp) for a ball of
//      R + c, c the tessellated part's clearance (0 for a mesh);
//   2. raster lines along x (mesh_raster.hpp), every line an exact drop line, every move
//      proven within eps (1e-6 of the mesh's size): at most the spacing given apart, or with
//      H the flat-surface spacing of H' = max(H - c - deviation, H / 4) with steps adapted to
//      the facets' slopes and chords' sag H' / 4; off the part the ball runs R above the
//      lowest point seen from above (the simulation's design grid);
//   3. the deepest the ball comes, exactly: every move's distance to the mesh, in the
//      report's gouge figures (against the ball R + c).
//   The path is the tool's centres for a ball of R.
// planMesh(mesh, options, control): meshToolpaths, then
//   4. the G-code program (gcode.hpp) with the units' feeds and a safe height above the
//      mesh's highest vertex and the path;
//   5. the program read back and its cut simulated (cut_simulation.hpp): on the mesh, or
//      on a tessellated part's exact faces (TessellatedPart::exactHeights) when the
//      simulation's grid is within its budget; the finishing stock is the mesh raised by
//      max(0.01 in / 0.25 mm, 2 H) (H: the one asked, or the flat cusp of the spacing);
//   6. with H (not a spacing) and restFinishing: up to two rounds of rest passes
//      (rest_finishing.hpp's meshRestPasses, every move an exact drop line, proven) where
//      the simulated cut leaves more than H on points the ball can reach, the program
//      written and simulated again after each; a second round only when the first took a
//      tenth of the area above H. A tessellated part whose c + deviation reach H / 2 gets
//      none: the balls stand that far off its faces wherever they go.
// Units: the mesh's (Mesh::units), for every length; rates per minute. Defaults suit them:
//   a 0.25 in (6 mm) ball, H = 0.001 in (0.025 mm), rapids at 200 in/min (5000 mm/min).
// Errors: scallop::Error before any work for bad input, the messages naming options.source
//   where they concern the mesh: no triangle, a triangle index out of range, a vertex not
//   finite, R not positive and finite or more than 1000 times the mesh's largest
//   |coordinate|, both a spacing and H, a spacing not positive or 2 R or more, H not
//   positive or not below R, a rapid rate not positive, a tessellated part's deviation or
//   clearance negative or not finite; then the raster's (mesh_raster.hpp: its budgets),
//   prefixed with the source. scallop::Cancelled once control.cancel is set.
// Progress (job_control.hpp): (fraction, stage) on the calling thread only, the fraction
//   never decreasing and ending at 1 ("done"). The stages, as `scallop plan` prints them:
//   "<description>; raster along x, lines at most <Delta> <unit> apart, each the exact drop
//   line of a <R> <unit> ball[ kept <c> <unit> farther from the mesh]" (advancing per line),
//   then planMesh's "writing the G-code", for a tessellated part "the part's exact heights
//   on <columns> x <rows> vertical lines" (once), "simulating the cut of the program on the
//   mesh (scallop verify)" (or "... on the part's exact faces", or past the judge's budget
//   "the simulation's <columns> x <rows> grid exceeds the budget of <n> lines through the
//   exact faces: simulating the cut on the mesh"), and per rest round "rest finishing: <n>
//   grid points left above H" and the simulation again. Cancellation: polled in every loop
//   whose steps are short (drop-line stations, lines, the facets' passes, the exact
//   distances' moves, the G-code written and read back, the design's triangles or vertical
//   lines, the simulation's moves, the rest passes' targets), on every thread.
// Threads: parallel.hpp's threadCount(); the result is the same, byte for byte, for every
//   thread count and run (report.seconds aside: the call's wall time).
// Cost: the paper-1 mesh of 4,608 triangles at R 0.25 in, H 0.001 in takes about 2 s before
//   rest finishing; the README gives the figures of OpenCAMLib's and OCCT's parts.
//
// meshPlanFiles(result): the three files `scallop plan` writes for a mesh (the G-code,
// report.json, verify.svg), in that order, as (name, contents); nothing is written to disk.

#include <optional>
#include <string>
#include <vector>

#include "scallop/geometry/mesh.hpp"
#include "scallop/io/file_output.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/job_control.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/paths/mesh_raster.hpp"
#include "scallop/paths/tessellated_part.hpp"

namespace scallop {

struct MeshPlanOptions {
  std::string source = "mesh";          ///< the mesh's name in errors, the report and the G-code title
  /// How the first stage names the mesh ("4608 triangles (binary STL)"); empty: "<n>
  /// triangles", or a tessellated part's own description.
  std::string description;
  std::optional<double> toolRadius;     ///< R; none: 0.25 in or 6 mm
  std::optional<double> scallopHeight;  ///< H < R; none (and no spacing): 0.001 in or 0.025 mm
  std::optional<double> spacing;        ///< the lines' spacing instead of H (then no rest finishing)
  bool restFinishing = true;            ///< planMesh: rest passes where the cut leaves more than H
  GcodeDialect dialect = GcodeDialect::linuxcnc;  ///< planMesh's program
  std::optional<double> rapidRate;      ///< planMesh's cycle time; none: 200 in/min or 5000 mm/min
};

struct MeshToolpathResult {
  /// The tool's centres for a ball of R (raster.path) and the raster's figures: lines,
  /// spacings, drops, proofs, unproven moves, centre length, eps. planMesh appends its rest
  /// passes to raster.path (the raster is its first pass); the other figures stay the
  /// raster's.
  MeshRasterPaths raster;
  /// Strategy "raster", source, units, R, spacing, H, the lines, the exact deepest
  /// interference (gouge), the tessellation; planMesh adds the motion, the rates, the rest
  /// rounds and the verification. seconds: the call's wall time.
  PathsReport report;
  double partTop = 0.0;  ///< the mesh's highest vertex (the G-code's safe height stands above it)
};

struct MeshPlanResult {
  MeshToolpathResult toolpaths;  ///< the path with its rest passes, and the report with every figure
  GcodeOptions gcode;            ///< feeds, spindle, safe height of the program
  std::string programName;       ///< toolpath.ngc (LinuxCNC) or toolpath.gcode (grbl)
  std::string program;           ///< the G-code program
  SimulationReport simulated;    ///< the program's simulated cut (the last one, after rest passes)
};

/// The raster of a mesh (see the contract).
MeshToolpathResult meshToolpaths(const Mesh& mesh, const MeshPlanOptions& options = {},
                                 const JobControl& control = {});
/// The same for a tessellated part: the proofs kept its clearance farther from the mesh.
MeshToolpathResult meshToolpaths(const TessellatedPart& part, const MeshPlanOptions& options = {},
                                 const JobControl& control = {});

/// The whole plan of a mesh (see the contract).
MeshPlanResult planMesh(const Mesh& mesh, const MeshPlanOptions& options = {}, const JobControl& control = {});
/// The same for a tessellated part, its cut judged on its exact faces.
MeshPlanResult planMesh(const TessellatedPart& part, const MeshPlanOptions& options = {},
                        const JobControl& control = {});

/// The files `scallop plan` writes for a mesh, as (name, contents), from planMesh's result.
std::vector<OutputFile> meshPlanFiles(const MeshPlanResult& result);

}  // namespace scallop
