// The mesh routes' shared lines for `scallop plan` and `scallop paths` (see mesh_job.hpp).

#include "mesh_job.hpp"

#include <cstddef>
#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "arguments.hpp"
#include "scallop/cad/tessellate_part.hpp"

namespace scallop::cli {

JobControl stageLines(const std::string& command, bool quiet) {
  JobControl control;
  if (!quiet)
    control.progress = [command, last = std::string()](double, const std::string& stage) mutable {
      if (stage == last || stage == "done") return;  // a stage's advances; the end
      last = stage;
      fmt::print(stderr, "scallop {}: {}...\n", command, stage);
    };
  return control;
}

void announceTessellation(const CadPart& part, const std::optional<CadImport>& exact, const std::string& command,
                          bool quiet) {
  if (!exact || quiet) return;
  std::size_t trimmed = 0, rational = 0;
  for (const SkippedFace& face : exact->skipped) {
    trimmed += face.issue == CadFaceIssue::trimmed ? 1 : 0;
    rational += face.issue == CadFaceIssue::rational ? 1 : 0;
  }
  fmt::print(stderr,
             "scallop {}: {} of {} faces cannot be machined exactly yet ({} trimmed, {} rational, {} other; the first: "
             "{}): cutting the part through its tessellation...\n",
             command, exact->skipped.size(), part.faces(), trimmed, rational,
             exact->skipped.size() - trimmed - rational, exact->skipped.front().reason);
}

TessellatedPart tessellatedJob(const CadPart& part, const MeshPlanOptions& plan, const std::string& deflectionText,
                               const std::string& command, bool quiet) {
  PartMeshOptions options;
  if (!deflectionText.empty()) options.deflection = parsePositive(deflectionText, "deflection", "a positive length");
  options.toolRadius = plan.toolRadius;
  options.scallopHeight = plan.scallopHeight;
  options.spacing = plan.spacing;
  options.deflectionOption = "--deflection";  // the warning names the flag
  TessellatedPart tessellated = tessellatePart(part, options, stageLines(command, quiet));
  if (!quiet)
    for (const std::string& warning : tessellated.warnings)
      fmt::print(stderr, "scallop {}: warning: {}\n", command, warning);
  return tessellated;
}

}  // namespace scallop::cli
