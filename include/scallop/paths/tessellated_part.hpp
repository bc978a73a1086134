#pragma once
// A triangle mesh that stands in for a part's exact faces: the tessellation of a STEP or IGES
// part whose faces cannot be machined exactly yet, as a mesh plan (jobs/mesh_plan.hpp) takes
// it. cad/tessellate_part.hpp makes one from a CadPart; any other source of a mesh with a
// measured deviation and an exact judge may fill it the same way.
//
// Contract
// --------
// mesh:        the tessellation, in the part's units (Mesh: finite vertices, triangles of
//              three indices into them).
// deviation:   the largest distance found from the exact faces to their triangles, >= 0.
//              Sampled (cad_tessellation.hpp): a measure, not a bound.
// clearance:   c >= 0, added to the ball's radius R in every proof against the mesh: a
//              centre R + c from the mesh is at least R from every exact face within c of
//              it. tessellatePart sets kDeviationMargin times the deviation (the sampled
//              deviation's margin). The passes then stand up to c + deviation off the exact
//              faces: the plan's cusps aim at H less that (at least H / 4).
// exactHeights: the exact faces' heights on a grid (cut_simulation.hpp's
//              DesignHeightsFunction): the design the plan's simulated cut is judged
//              against, independent of the mesh the plan was cut on. Empty: the mesh's own
//              heights. It may call the part it was made from, which must then outlive every
//              plan made with it.
// maxExactRays: the judge's budget of vertical lines; a simulation grid with more points is
//              judged on the mesh instead, and the plan says so in its progress stage.
// Units: the mesh's (Mesh::units), for every length here.

#include <cstddef>
#include <string>
#include <vector>

#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/vector.hpp"
#include "scallop/paths/cut_simulation.hpp"

namespace scallop {

/// The clearance a tessellated part's proofs add to R: this times the sampled deviation.
inline constexpr double kDeviationMargin = 1.5;

/// The exact judge's default budget: vertical lines through the exact faces (at roughly
/// 100-300 us each, a few minutes).
inline constexpr std::size_t kExactDesignRays = 1'000'000;

struct TessellatedPart {
  Mesh mesh;                            ///< the tessellation (the part's units)
  /// How the plan's first stage names the mesh ("8302 triangles from 10 faces (STEP), ...").
  std::string description;
  std::size_t faces = 0;                ///< the part's faces, all of them tessellated
  double deflection = 0.0;              ///< the mesher's linear deflection D, as asked
  double deviation = 0.0;               ///< sampled max distance, exact faces to the mesh (>= 0)
  std::size_t deviationFace = 0;        ///< where it occurs: the face (numbered as cad_import.hpp)
  Vec3 deviationAt;                     ///< and the exact face's point
  double clearance = 0.0;               ///< c >= 0 added to R in every proof
  DesignHeightsFunction exactHeights;   ///< the judge; empty: the mesh
  std::size_t maxExactRays = kExactDesignRays;
  /// What the caller should be told before the plan (one line each, no prefix): e.g. that
  /// the clearance leaves more than 3/4 of H and the scallops may exceed it.
  std::vector<std::string> warnings;
};

}  // namespace scallop
