// A STEP or IGES part made ready for a mesh plan (see tessellate_part.hpp).

#include "scallop/cad/tessellate_part.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/paths/cusp.hpp"

namespace scallop {
namespace {

void requirePositive(const std::optional<double>& value, const char* what) {
  if (value && !(*value > 0.0 && std::isfinite(*value)))
    throw Error(fmt::format("the {} must be positive and finite, got {}", what, *value));
}

}  // namespace

TessellatedPart tessellatePart(const CadPart& part, const PartMeshOptions& options, const JobControl& control) {
  const JobControlScope scope(&control);
  const bool inch = part.units() == Units::inch;
  requirePositive(options.deflection, "tessellation's deflection");
  requirePositive(options.toolRadius, "tool radius");
  requirePositive(options.scallopHeight, "scallop height");
  requirePositive(options.spacing, "spacing");
  if (options.spacing && options.scallopHeight) throw Error("give at most one of a spacing and a scallop height");
  // The scallop height the plan aims at: the one given, or its default.
  const double height = options.scallopHeight.value_or(inch ? 0.001 : 0.025);
  // The deflection asked of the mesher is H / 8 unless given: what the mesh's error adds to
  // the scallops is then small beside H (measured, the deviation is often 1.5-3 times the
  // deflection). With a spacing, H is its flat cusp.
  double deflection = height / 8.0;
  if (options.deflection)
    deflection = *options.deflection;
  else if (options.spacing)
    deflection = flatCusp(options.toolRadius.value_or(inch ? 0.25 : 6.0), *options.spacing) / 8.0;
  TessellationOptions tessellation;
  tessellation.deflection = deflection;
  CadTessellation mesh;
  {
    const ProgressStage stage(0.0, 1.0,
                              fmt::format("tessellating its {} faces with deflection {:.3g} {}", part.faces(),
                                          deflection, unitsName(part.units())));
    mesh = part.tessellate(tessellation);
  }
  TessellatedPart out;
  out.faces = part.faces();
  out.deflection = deflection;
  out.deviation = mesh.deviation;
  out.deviationFace = mesh.deviationFace;
  out.deviationAt = mesh.deviationAt;
  out.clearance = kDeviationMargin * mesh.deviation;
  out.description = fmt::format("{} triangles from {} faces ({}), the exact faces at most {:.3g} {} from them (sampled "
                                "at {} points)",
                                mesh.mesh.triangles.size(), part.faces(), cadFormatName(part.format()), mesh.deviation,
                                unitsName(part.units()), mesh.deviationSamples);
  // The clearance is material left on the part: beside H it shows in the scallops. Often it is
  // not the mesh but the model: faces whose edges stand off their surfaces by the model's
  // tolerance (OCCT's bearing.iges: 0.0012 mm).
  if (!options.spacing && out.clearance + out.deviation > 0.75 * height)
    out.warnings.push_back(fmt::format(
        "the exact faces stand up to {:.3g} {} from the mesh (face {}, near ({:.6g}, {:.6g}, {:.6g})), and the passes "
        "keep 1.5 times that farther: that leaves more than 3/4 of H = {}, so the scallops may exceed H (a smaller "
        "{} helps unless the model's own tolerance is the cause)",
        mesh.deviation, unitsName(part.units()), mesh.deviationFace, mesh.deviationAt.x, mesh.deviationAt.y,
        mesh.deviationAt.z, height, options.deflectionOption));
  // The judge: the exact faces' heights, its budget the plan's (which only asks within it).
  out.exactHeights = [&part](HeightGrid& grid, std::vector<double>& normalZ) {
    ExactHeightOptions heights;
    heights.maxRays = std::max<std::size_t>(grid.z.size(), 1);
    part.designHeights(grid, &normalZ, heights);
  };
  out.maxExactRays = kExactDesignRays;
  out.mesh = std::move(mesh.mesh);
  const ProgressStage done(1.0, 1.0, "done");
  return out;
}

}  // namespace scallop
