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
//         h and [b0, b1] along e; with m = R / 64 the lines are e . (x, y) = b_k, b_0 = b0 - R
//         + m, b_k+1 = b_k + Delta_k, the last at b1 + R - m exactly (a point near the mesh's
//         extreme whose surface slopes towards it is finished by a ball beyond it, at
//         q + R n), each run over h . (x, y) in [a0 - R - m, a1 + R + m] (its ends and the
//         links between lines touch nothing; m keeps them off the tangent at R, where a z-map
//         would read the ball's equator beside the part's edge as a cut); a line whose ball
//         touches nothing along it is left out. At most maxLines lines.
//         Delta_k = Delta, or with a scallop height H > 0 the cusp-adaptive step: balls
//         resting on a facet (unit normal n, n_z > 0; slopes s_h = -n_h / n_z along the feed
//         and s_e = -n_e / n_z across it) from neighbouring lines Delta apart have centres on
//         the facet's offset plane whose lines lie w = Delta sqrt(1 + s_e^2 + s_h^2) /
//         sqrt(1 + s_h^2) apart (the cross product of the across step (1, s_e) and the
//         feed (1, s_h) directions lifted onto the plane), and leave the cusp
//         R - sqrt(R^2 - w^2 / 4) <= H while w <= w_H = 2 sqrt(2 R H - H^2). So Delta_k is
//         the least of Delta and w_H sqrt(1 + s_h^2) / sqrt(1 + s_e^2 + s_h^2) over the
//         facets whose touching centres (the facet offset by R n) reach across the band
//         [b_k, b_k + Delta]; at least Delta / 32 (the floor: counted in floorSteps).
//         Vertical facets touch only through their edges and are left out. Flat facets make
//         the cusp exact on them; the edges between facets (the mesh's curvature) are not
//         modelled: the plan's simulated cut measures what is left there.
// Passes: one continuous pass, zigzag: line k forwards when k is even, backwards when odd;
//         each line is dropLine's envelope (exact drop heights at its vertices, every move
//         proven to keep the centre at least R - eps from the mesh; off the part the ball runs
//         at the floor (MeshRasterOptions::floor)); consecutive lines are joined at their common
//         end by the drop line across (along e from b_k to b_k+1 at that end), proven the
//         same way: no move of the path cuts deeper than eps.
// Spacing: with a constant Delta the cusp on a horizontal facet is R - sqrt(R^2 - Delta^2 / 4)
//         (the paper's formula with sin(alpha) = 1, planes vertical); on a slope rising across
//         the feed it is larger (w > Delta above), which the adaptive steps take in.
// Output: MeshRasterPaths: the tool path (ball centres, the mesh's units), the lines' count,
//         drops, proofs and unproven moves summed, the centre length.
// Errors: scallop::Error for Delta or the angle not finite or Delta <= 0, more than maxLines
//         lines (the message gives the count), and dropLine's errors (budget included).
// Cost:   sum over lines of dropLine's cost: O(vertices) drops and proofs, each O(features
//         within about R).
// Progress: the caller's stage (job_control.hpp) advances per line and per link; the cancel
//         is polled there, per drop-line station and every 4096 facets of the adaptive
//         steps' and meshWithSkirt's passes over the mesh (scallop::Cancelled).
// Deterministic.

#include <cstddef>
#include <limits>
#include <vector>

#include "scallop/geometry/mesh.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/paths/toolpath.hpp"

namespace scallop {

struct MeshRasterOptions {
  double spacing = 0.0;   ///< Delta > 0, mesh units
  double angleRad = 0.0;  ///< feed direction from +x (radians)
  double eps = 0.0;       ///< depth proven; 0: 1e-6 of the mesh's size (dropLine's default)
  double sagTolerance = 0.0;  ///< dropLine's midpoint check; 0: its default (eps)
  /// The centre's height where nothing lies within R (dropLine's floor); NaN: the mesh's
  /// lowest z + R. A plan passes the lowest point visible from above + R: a part whose
  /// hidden underside reaches lower (a sphere through a plate) would otherwise have its balls
  /// run beside its walls below their tops, grazing them within eps, which a z-map reads as
  /// its columns cut down to the ball's equator.
  double floor = std::numeric_limits<double>::quiet_NaN();
  /// H > 0: cusp-adaptive steps, at most `spacing` (see the contract); 0: constant spacing.
  double scallopHeight = 0.0;
  std::size_t maxLines = 100'000;  ///< budget
};

struct MeshRasterPaths {
  ToolPath path;
  std::size_t lines = 0;
  std::vector<double> lineOffsets;  ///< b_k, increasing (the last b1)
  /// The least step between lines but the last (which only reaches b1); 0 with one line.
  double minSpacing = 0.0;
  std::size_t floorSteps = 0;  ///< adaptive steps held at the floor Delta / 32
  std::size_t drops = 0;
  std::size_t proofs = 0;
  std::size_t unprovenMoves = 0;
  double centreLength = 0.0;  ///< the ball centre's path length
  double eps = 0.0;           ///< used
};

/// The raster of `mesh` (the cutter's mesh, in `units`) (see the contract).
MeshRasterPaths meshRasterPaths(const MeshDropCutter& cutter, const Mesh& mesh, const MeshRasterOptions& options);

/// The mesh as the top of a solid, for the cutter's proofs: below every open boundary edge
/// (an edge of one triangle only) a vertical wall of two triangles down to the mesh's lowest
/// z, `offset` (>= 0) outwards in xy from the edge (away from its triangle). Why: the drop
/// heights are the same (a vertical facet touches the ball only through its top edge, which
/// lies beside the mesh's), but a move proven against the open sheet may pass beside its edge
/// below it (a ramp onto the part), cutting the side of the solid the sheet is the top of;
/// against the walls it is not proven, and is halved until it rises beside them. The offset
/// (a plan gives 4 eps) keeps a ball that grazes a wall within eps off the edge's own vertical
/// line, which a z-map would read as cut down to the ball's equator.
Mesh meshWithSkirt(const Mesh& mesh, double offset = 0.0);

/// The flat-surface raster spacing for a scallop height H < R: 2 sqrt(2 R H - H^2).
double meshRasterSpacing(double toolRadius, double scallopHeight);

}  // namespace scallop
