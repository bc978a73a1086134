#pragma once
// A STEP or IGES part made ready for a mesh plan: its tessellation, how far its exact faces
// stand from it, and its exact heights as the plan's judge (paths/tessellated_part.hpp). This
// is how `scallop plan` and `scallop paths` take a part whose faces cannot be machined exactly
// yet; jobs/mesh_plan.hpp's planMesh(TessellatedPart) then plans it.
//
// Contract
// --------
// tessellatePart(part, options, control):
// Input:   a CadPart (cad_tessellation.hpp), which must outlive the result: its exactHeights
//          calls the part. options: the mesher's linear deflection D, and the plan's R, H and
//          spacing as MeshPlanOptions takes them (jobs/mesh_plan.hpp; none: its defaults,
//          0.25 in / 6 mm and 0.001 in / 0.025 mm by the part's units). They set the default
//          D = H / 8, H the scallop height the plan aims at (the flat cusp of the spacing
//          when a spacing is given): measured, the deviation is often 1.5-3 D, so what the
//          mesh adds to the scallops stays small beside H.
// Output:  TessellatedPart: CadPart::tessellate's mesh (deflection D, the default angular
//          deflection), its deviation and where it occurs, the clearance kDeviationMargin
//          times the deviation, the exact heights (CadPart::designHeights, every core, the
//          result the same for any thread count; budget kExactDesignRays), a description
//          for the plan's first stage, and warnings: one when the plan aims at H (no
//          spacing) and clearance + deviation exceed 3/4 of H, naming the face and the point
//          (the scallops may then exceed H; a smaller D helps unless the model's own
//          tolerance is the cause, as on OCCT's bearing.iges). The warning names the option
//          that sets D as options.deflectionOption says: the library's field by default,
//          the CLI's flag for `scallop plan`, a keyword for the Python module.
// Units:   the part's (CadPart::units), for every length.
// Errors:  scallop::Error: D, R, H or the spacing given but not positive and finite, H and a
//          spacing both, a spacing of 2 R or more when D is derived from it (cusp.hpp's
//          flatCusp); then CadPart::tessellate's (a D below 1e-6 of the part's size, a face
//          left without triangles, the triangle budget). The plan's own checks (H < R, R
//          against the part's size) are planMesh's.
// Progress (job_control.hpp): one stage, "tessellating its N faces with deflection D <unit>",
//          then 1 ("done"), on the calling thread. Cancellation: polled per face while the
//          deviation is sampled (OCCT's mesher itself runs to its end); the exact heights
//          poll per vertical line and report per grid row under the plan's stage.
// Threads: the tessellation holds cad_import.hpp's process-wide mutex.

#include <optional>
#include <string>

#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/job_control.hpp"
#include "scallop/paths/tessellated_part.hpp"

namespace scallop {

struct PartMeshOptions {
  std::optional<double> deflection;     ///< D > 0 (the part's units); none: H / 8
  std::optional<double> toolRadius;     ///< the plan's R; none: 0.25 in or 6 mm
  std::optional<double> scallopHeight;  ///< the plan's H; at most one of it and the spacing
  std::optional<double> spacing;        ///< the plan's spacing instead of H
  /// How the warnings name the option that sets D ("a smaller <it> helps"): the caller's
  /// own, e.g. "--deflection" for the CLI.
  std::string deflectionOption = "deflection (PartMeshOptions::deflection)";
};

/// See the contract.
TessellatedPart tessellatePart(const CadPart& part, const PartMeshOptions& options = {},
                               const JobControl& control = {});

}  // namespace scallop
