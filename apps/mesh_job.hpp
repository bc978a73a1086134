#pragma once
// What `scallop plan` and `scallop paths` share on their mesh routes (an STL mesh, or a STEP or
// IGES part whose faces cannot be machined exactly yet, cut through its tessellation): the
// progress lines on stderr and the part's tessellation with its warnings. The work itself is
// the library's: jobs/mesh_plan.hpp (planMesh, meshToolpaths) and cad/tessellate_part.hpp.

#include <optional>
#include <string>

#include "scallop/cad/cad_import.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/job_control.hpp"
#include "scallop/jobs/mesh_plan.hpp"
#include "scallop/paths/tessellated_part.hpp"

namespace scallop::cli {

/// A job control that prints "scallop <command>: <stage>..." on stderr at each new stage
/// (not the final "done"); none when `quiet`.
JobControl stageLines(const std::string& command, bool quiet);

/// The line that says why a STEP or IGES part goes through its tessellation: the faces of
/// `exact` that could not be imported exactly (none without `exact`: --tessellate).
void announceTessellation(const CadPart& part, const std::optional<CadImport>& exact, const std::string& command,
                          bool quiet);

/// The part's tessellation for a mesh job with the plan's R, H or spacing (`plan`), the
/// deflection as given (empty: H / 8); its stage line and its warnings on stderr unless quiet.
TessellatedPart tessellatedJob(const CadPart& part, const MeshPlanOptions& plan, const std::string& deflectionText,
                               const std::string& command, bool quiet);

}  // namespace scallop::cli
