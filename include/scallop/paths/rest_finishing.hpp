#pragma once
// Rest finishing: short extra passes where the simulated cut of a plan still leaves more than
// the scallop height H on points the ball can reach.
//
// Why: the strategies space their planes from a model of the cusp between neighbouring
// passes and run their passes on past the surface's edges, but some points are finished only
// by a ball standing where no pass goes: a corner of the surface whose ball stands outside
// the footprint diagonally (paper-2's corner (0, 0) with a 1 in ball: 0.82 in out), the rim
// of a pocket tighter than the ball, where the balls of neighbouring planes are wedged at
// different heights. The simulated cut (cut_simulation.hpp) finds them; a commercial CAM
// system calls the passes that clean them up "rest machining".
//
// Contract
// --------
// Input:  a valid Surface, the SimulationReport of the plan's program on it (its design and
//         stock grids, |n_z| per point and the reach classification), RestOptions (H > 0,
//         0 < threshold <= 1, R > 0 the simulation's radius).
// Targets: the grid points q with surface, not classified beyond the ball's reach, whose
//         simulated scallop (stock - design) |n_z| exceeds H, and those that exceed
//         threshold x H within `neighbourhood` grid steps (in x and y) of a point that
//         reads above H or lies beyond the ball's reach. By default the threshold is
//         1 - b / H (at least 1/2), b the simulation's heightErrorBound: between grid points
//         a scallop ridge stands at most b above the grid's reading where the flanks of
//         neighbouring balls meet (cut_simulation.hpp). A ridge is long and the grid reads it
//         along its length; what is left beside the rim of a pocket tighter than the ball or
//         around a point the passes missed is a small peak that the grid may straddle
//         (paper-2's corner (3, 3) with a 1 in ball: the plan's grid reads 0.98 H there, grids
//         0.0071 and 0.0093 in apart 1.18 H and 1.27 H), so there the points whose
//         neighbourhood may hold more than H are taken too; the rest of the surface, whose
//         reading is the plan's own, is left alone (an edge band was tried: on the paper's
//         plans that read <= H it added 3-7 % of path and changed no finer grid's reading).
// Witness: for each target, the ball that touches it: c = q + R n (n the upward unit normal
//         at q's foot point, gouge.hpp's closest point), dropped onto the drop envelope over
//         c (envelope.hpp's DropCutter: the lowest centre on that vertical proven clear of the
//         whole surface, within eps / 4). Lifted by L >= 0 the ball stays
//         g = sqrt(R^2 + 2 R L n_z + L^2) - R from q (as the simulator's reach test); a target
//         with g > H cannot be finished by this ball from anywhere near there and is only
//         counted (`unreached`).
// Passes: the witnesses are chained nearest-next (3D distance, ties by grid order), a chain
//         broken where the nearest unvisited witness is farther than chainGap; each chain is a
//         pass through its witnesses in that order (a lone witness: a pass of one zero-length
//         move), and the passes are lifted by liftToDropEnvelope (eps, the sag tolerance, the
//         same proofs as the strategies' passes): every move is proven to keep the ball's
//         centre at least R - eps from the surface. The witnesses are on the envelope, so the
//         lifting keeps them (within eps / 4): after the rest passes, the ball has stood
//         within g + eps / 4 of every target. What that leaves between grid points is the
//         simulator's to judge (the plan simulates its program again).
// Output: RestPasses: the lifted passes (retract before each; the linker links them), and
//         RestReport: targets, witnesses, unreached, chains, the passes' length, the
//         lifting's report.
// Budget: more than maxTargets targets: no passes at all and `overBudget` set (a plan that
//         leaves that much has a wrong spacing, not a few corners: the report says so).
//         Chaining is O(k) expected (buckets of chainGap), O(k^2) at worst for k targets.
// Cost:   per target one closest point and one drop-cutter height (tens of microseconds);
//         the lifting as the strategies'.
// Errors: scallop::Error for invalid options (naming the option and its value) and a
//         simulation without grids.
// Deterministic: the same report gives the same passes, for any number of threads.

#include <cstddef>
#include <vector>

#include "scallop/paths/cut_simulation.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"

namespace scallop {

struct RestOptions {
  double toolRadius = 0.0;      ///< R > 0 of the program simulated (the surface's units)
  double scallopHeight = 0.0;   ///< H > 0, the scallop height promised
  /// Targets are the points above threshold x H, in (0, 1]; 0: 1 - heightErrorBound / H,
  /// at least 1/2 (see the contract).
  double threshold = 0.0;
  /// The targets below H are taken within this many grid steps of a point above H or beyond
  /// reach (>= 0).
  std::size_t neighbourhood = 8;
  /// Witnesses farther apart than this start a new pass (> 0); 0: eight grid spacings,
  /// at most R.
  double chainGap = 0.0;
  /// eps for the lifting (envelope.hpp; 0: 1e-6 of the part's size).
  double depthTolerance = 0.0;
  /// The lifting's sag tolerance (envelope.hpp; 0: none); the plan uses H / 4.
  double sagTolerance = 0.0;
  std::size_t maxTargets = 50'000;  ///< budget (see the contract)
  std::size_t threads = 0;          ///< the lifting's threads; 0: every core
};

struct RestReport {
  std::size_t targets = 0;     ///< grid points above threshold x H, within reach
  std::size_t witnesses = 0;   ///< targets whose ball comes within H (in the passes)
  std::size_t unreached = 0;   ///< targets whose ball stays more than H away (left)
  std::size_t passes = 0;      ///< chains
  double length = 0.0;         ///< the lifted passes' length (ball centre)
  double maxScallopBefore = 0.0;  ///< the largest target's simulated scallop
  bool overBudget = false;     ///< more than maxTargets targets: no passes made
  EnvelopeReport envelope;     ///< the lifting of the rest passes
};

struct RestPasses {
  ToolPath path;  ///< the rest passes, lifted; units and radius of the simulation's surface
  RestReport report;
};

/// The grid points the rest passes would serve (see the contract's Targets), in grid order;
/// `threshold` 0 as in RestOptions. What restPasses starts from; empty: nothing to do.
std::vector<std::size_t> restTargets(const SimulationReport& simulated, double scallopHeight,
                                     double threshold = 0.0, std::size_t neighbourhood = 8);

/// The rest passes of a simulated program (see the contract).
RestPasses restPasses(const Surface& surface, const SimulationReport& simulated, const RestOptions& options);

/// The same over a triangle mesh (an STL file, or a STEP/IGES part's tessellation), simulated
/// on the grid of `simulated`: the same targets; each witness is c = q + R' n, n the upward
/// unit normal of the triangle that holds q over its grid point (designTriangles), raised
/// onto the exact drop envelope of `cutter` (radius R': R, or R plus a tessellation's
/// clearance), with the gap test as above; the chains as above, each step from one witness to
/// the next an exact drop line (MeshDropCutter::dropLine from the first's xy toward the
/// next's, with `dropLine`'s eps, sag tolerance and floor), so every move is proven as the
/// mesh raster's. options.depthTolerance and sagTolerance are unused (dropLine's instead);
/// report.envelope counts the drop lines' moves, proofs and unproven moves.
RestPasses meshRestPasses(const Mesh& mesh, const MeshDropCutter& cutter, const SimulationReport& simulated,
                          const RestOptions& options, const DropLineOptions& dropLine);

}  // namespace scallop
