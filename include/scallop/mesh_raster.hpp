#pragma once
// Raster (direction-parallel) finishing of a triangle mesh with a ball-end mill: the passes of
// `scallop plan PART.stl` and `scallop paths PART.stl`.
//
// Contract
// --------
// Input:  a MeshDropCutter (mesh_drop.hpp) of the mesh and its radius R, MeshRasterOptions: a
//         spacing Delta > 0 between the vertical planes (horizontal, across the feed), the
//         feed direction h = (cos a, sin a, 0), eps and the sag tolerance of the drop lines.
// Lines:  with e = (-sin a, cos a, 0) across the feed, the mesh's vertices span [a0, a1] along
//         h and [b0, b1] along e; the lines are e . (x, y) = b0 + k Delta, k = 0, 1, ..., the
//         last at b1 exactly (the extreme line touches the mesh's extreme from above; the
//         step before it is at most Delta), each run over h . (x, y) in [a0 - R, a1 + R]
//         (beyond, nothing lies within R). At most maxLines lines.
// Passes: one continuous pass, zigzag: line k forwards when k is even, backwards when odd;
//         each line is dropLine's envelope (exact drop heights at its vertices, every move
//         proven to keep the centre at least R - eps from the mesh; off the part the ball runs
//         at the floor, the mesh's lowest z + R); consecutive lines are joined at their common
//         end by the drop line across (along e from b_k to b_k+1 at that end), proven the
//         same way: no move of the path cuts deeper than eps.
// Spacing: a raster's cusp on a flat surface is H = R - sqrt(R^2 - Delta^2 / 4) (the paper's
//         formula with sin(alpha) = 1, planes vertical); on a slope rising across the feed at
//         angle phi the contacts are Delta / cos phi apart and the cusp is larger: the plan
//         measures it by simulating the cut (cut_simulation.hpp), it does not promise it.
// Output: MeshRasterPaths: the tool path (ball centres, the mesh's units), the lines' count,
//         drops, proofs and unproven moves summed, the centre length.
// Errors: scallop::Error for Delta or the angle not finite or Delta <= 0, more than maxLines
//         lines (the message gives the count), and dropLine's errors (budget included).
// Cost:   sum over lines of dropLine's cost: O(vertices) drops and proofs, each O(features
//         within about R).
// Deterministic.

#include <cstddef>

#include "scallop/mesh.hpp"
#include "scallop/mesh_drop.hpp"
#include "scallop/toolpath.hpp"

namespace scallop {

struct MeshRasterOptions {
  double spacing = 0.0;   ///< Delta > 0, mesh units
  double angleRad = 0.0;  ///< feed direction from +x (radians)
  double eps = 0.0;       ///< depth proven; 0: 1e-6 of the mesh's size (dropLine's default)
  double sagTolerance = 0.0;  ///< dropLine's midpoint check; 0: its default (eps)
  std::size_t maxLines = 100'000;  ///< budget
};

struct MeshRasterPaths {
  ToolPath path;
  std::size_t lines = 0;
  std::size_t drops = 0;
  std::size_t proofs = 0;
  std::size_t unprovenMoves = 0;
  double centreLength = 0.0;  ///< the ball centre's path length
  double eps = 0.0;           ///< used
};

/// The raster of `mesh` (the cutter's mesh, in `units`) (see the contract).
MeshRasterPaths meshRasterPaths(const MeshDropCutter& cutter, const Mesh& mesh, const MeshRasterOptions& options);

/// The flat-surface raster spacing for a scallop height H < R: 2 sqrt(2 R H - H^2).
double meshRasterSpacing(double toolRadius, double scallopHeight);

}  // namespace scallop
