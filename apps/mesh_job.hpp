#pragma once
// The raster of a triangle mesh, as `scallop plan` and `scallop paths` cut it: an STL mesh, or
// the tessellation of a STEP or IGES part whose faces cannot be machined exactly yet
// (cad_tessellation.hpp). Exact drop lines (mesh_raster.hpp), every move proven; the G-code,
// the simulated cut and the files are the commands' own.

#include <chrono>
#include <memory>
#include <cstddef>
#include <optional>
#include <string>

#include "scallop/cad/cad_import.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/paths/mesh_raster.hpp"
#include "scallop/io/paths_output.hpp"

namespace scallop::cli {

// What a mesh plan cuts: an STL mesh, or the tessellation of a STEP or IGES part whose faces
// the exact importer refuses (trimmed, rational).
struct MeshJob {
  Mesh mesh;
  std::string description;        // the progress line's "4,608 triangles (binary STL)"
  double clearance = 0.0;         // added to R in every proof: the tessellation's margin
  double deviation = 0.0;         // the exact faces' sampled distance from the mesh
  const CadPart* part = nullptr;  // the exact faces: the simulated cut's design
  std::optional<TessellationSummary> tessellation;
};

// The simulated cut's budget of vertical lines through a CAD part's exact faces: past it the
// cut is judged on the mesh instead, and the report says so.
constexpr std::size_t kExactDesignRays = 1'000'000;
// The clearance a tessellated part's proofs add to R: this times the sampled deviation
// (cad_tessellation.hpp: sampled, so a margin).
constexpr double kDeviationMargin = 1.5;

// What the command asked for, as given (strings parsed here, with the commands' defaults).
struct MeshRasterRequest {
  std::string source;         // how messages and the report name the input
  std::string command;        // "plan" or "paths": the progress lines' prefix
  std::string toolRadius;     // empty: 0.25 in or 6 mm
  std::string scallopHeight;  // at most one of these two; neither: 0.001 in or 0.025 mm
  std::string spacing;
  bool quiet = false;
};

struct MeshRasterResult {
  MeshRasterPaths paths;          // the tool's centres for a ball of R (path.toolRadius)
  PathsReport report;             // strategy to gouge (exact) and tessellation; no motion, no verification
  SimulationOptions simulation;   // R, H (or the flat cusp of the spacing), allowance, stock top
  double top = 0.0;               // the mesh's highest vertex
  std::chrono::steady_clock::time_point start;
  // What the raster was proven against, for more passes (rest finishing): the mesh walled
  // down as a solid, its cutter (R plus the clearance) and the drop lines' options.
  std::shared_ptr<const Mesh> solid;
  std::shared_ptr<const MeshDropCutter> cutter;
  DropLineOptions dropLine;
};

// The raster of `job` (refusals name request.source).
MeshRasterResult runMeshRaster(const MeshJob& job, const MeshRasterRequest& request);


// A STEP or IGES part's tessellation as a mesh job; `exact`, when given, the faces that could
// not be imported exactly (said on stderr); the deflection as given (empty: H / 8).
MeshJob tessellatedJob(const CadPart& part, const std::optional<CadImport>& exact, const MeshRasterRequest& options,
                       const std::string& deflectionText);

}  // namespace scallop::cli
