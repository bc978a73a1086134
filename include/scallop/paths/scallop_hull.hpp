#pragma once
// The scallop hull of a monotone chain and its offset (Chou, Woo, Chen, Tang, Shin,
// "Scallop hull and its offset", Computer-Aided Design 26(7), 1994).
//
// Contract
// --------
// Input:  a monotone chain v_0 .. v_{n-1} (see chain.hpp: n >= 2, finite, x non-decreasing;
//         vertical edges and repeated points allowed), material below it and below the two
//         downward vertical rays at v_0 and v_{n-1}; a ball (circle) radius r > 0, or
//         r = +infinity.
// Output: for finite r,
//         - the scallop hull: links (an edge, or the part of an edge, in contact with the
//           circle) and lids (the arc of the circle bridging a deficiency, with its centre),
//           ordered left to right; convex hull vertices are where two elements meet;
//         - its offset, the tool-centre path: lines (offset links, and vertical lines where
//           the ball slides along a vertical edge), clockwise arcs of radius r around convex
//           vertices, and corners at lid centres. It runs from (x_0 - r, z_0) to
//           (x_{n-1} + r, z_{n-1}), end quarter-arcs included, the offsets of the two
//           vertical rays left out. x never decreases along it and every element starts
//           exactly (bit for bit) where the previous one ends.
//         For r = +infinity the hull is the upper convex hull (links and straight lids with
//         no centre) and the tool path is empty (the centre is at infinity).
// Time:   O(n), one left-to-right pass with a stack: each edge is pushed at most once and
//         popped at most once (HullStats counts both); O(n) memory. No sampling, no sorting.
// Tolerance: with S = max(r, largest |coordinate|) and tau = 1e-12 * S, every path point
//         is at distance within tau of the exact envelope (its distance to the chain lies in
//         [r - tau, r + tau]); contact points lie within tau of the chain. Pieces shorter
//         than tau are merged into their neighbours (so lids that coincide within tau are
//         one lid, as the paper's COINCIDE step). A chain so far from the origin that tau
//         exceeds r / 1000 (largest |coordinate| > 1e9 r) is refused with an error: the hull
//         would mean nothing at that resolution.
//
// Method (why it is linear)
// -------------------------
// The lowest non-gouging centre height over x is c(x) = max_i C_i(x), where C_i is the top
// of the "capsule" of edge e_i = (v_i, v_{i+1}): the set of centres within r of the edge.
// C_i is an arc around v_i, the edge's offset line, then an arc around v_{i+1} (the paper's
// Figure 3 initial offset of one edge and its two vertices). Two equal circles whose centres
// are x-ordered touch a monotone chain in x-ordered points, so along c(x) the active
// capsules appear in edge order. Adding edges left to right, each new capsule either takes
// over the envelope from one crossing onward (popping the capsules it covers from the stack
// of the current hull: the paper's Backward_Exclusion) or is covered entirely. The crossing
// of two capsules is one of the paper's support pairs: arc-arc = peak-peak, arc-line =
// peak-slope, line-line = slope-slope (Figure 6), solved in closed form.
//
// Two passes build that stack. The filtered pass (HullMethod::automatic, the default) adds
// "units" instead of capsules, an edge's offset line with the arc around its end vertex, and
// solves only the one support pair that side tests at the units' junctions point to. An edge
// it cannot decide (a vertical edge, a tie its filters cannot tell) goes to the exact pass,
// which decides every case, and the units start again above what it built. The two give the
// same result bit for bit but where they break a tie within rounding differently (2 of 23,335
// test chains, with near-duplicate points); both are within the tolerance below
// (HullMethod::exact runs the exact pass alone; tests/paths/scallop_hull_test.cpp compares).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "scallop/paths/chain.hpp"

namespace scallop {

enum class HullElementKind {
  link,  ///< an edge, or part of one, in contact with the circle
  lid,   ///< the arc of the circle over a deficiency (the lower arc from start to end)
};

struct HullElement {
  HullElementKind kind = HullElementKind::link;
  Point2 start;          ///< contact point where the element begins (left)
  Point2 end;            ///< contact point where it ends (right)
  Point2 center;         ///< lid: centre of the circle (a corner of the tool path); link: unused
  std::size_t edge = 0;  ///< link: index i of the edge e_i = (v_i, v_{i+1}) it lies on; lid: unused
  bool straight = false; ///< lid only: true for r = infinity (a convex-hull bridge, no centre)
};

enum class PathElementKind {
  line,  ///< straight move: the offset of a link, or a vertical slide along a vertical edge
  arc,   ///< circular move of radius r around a convex chain vertex
};

struct PathElement {
  PathElementKind kind = PathElementKind::line;
  Point2 start;
  Point2 end;
  Point2 center;          ///< arc only: the chain vertex it rolls around
  double radius = 0.0;    ///< arc only: the ball radius r
  bool clockwise = true;  ///< arc only: always true (x right, z up, moving left to right)
  std::size_t feature = 0;  ///< line: the edge it offsets; arc: the vertex it rolls around
};

/// Counters for the linear-time claim: pushes and pops of edges on the hull stack, and
/// capsule comparisons (each costs O(1)), of the pass that built the hull.
struct HullStats {
  std::uint64_t pushes = 0;
  std::uint64_t pops = 0;
  std::uint64_t comparisons = 0;
  std::uint64_t exactSteps = 0;  ///< edges the exact pass added (all of them with HullMethod::exact)
};

/// Which pass builds the stack for a finite radius (see Method above; r = infinity has one).
enum class HullMethod {
  automatic,  ///< the filtered pass, the exact pass for the edges it leaves (the default)
  exact,      ///< the exact pass alone: for comparisons and tests
};

struct ScallopHull {
  double radius = 0.0;                ///< r (may be +infinity)
  std::vector<HullElement> hull;      ///< links and lids, left to right
  std::vector<PathElement> toolpath;  ///< tool-centre path, left to right (empty if r = inf)
  HullStats stats;
};

constexpr double kInfiniteRadius = std::numeric_limits<double>::infinity();

/// The scallop hull of `chain` for a circle of radius `radius` (> 0, may be +infinity) and
/// its offset. Throws scallop::Error on an invalid chain (see validateChain) or radius.
ScallopHull scallopHull(std::span<const Point2> chain, double radius,
                        HullMethod method = HullMethod::automatic);

/// Indices of the vertices of the upper convex hull of a chain with non-decreasing x
/// (Andrew's monotone chain, one pass, O(n)); collinear vertices on hull edges are kept,
/// the first and last vertex always included. This is the r = infinity limit.
std::vector<std::size_t> upperHullIndices(std::span<const Point2> chain);

/// Height of the tool path at abscissa x: the highest z of any path element over x
/// (a vertical element counts with its upper end). -infinity outside the path's x range.
/// O(log m) for a path of m elements.
double pathHeightAt(std::span<const PathElement> toolpath, double x);

/// Total length of the tool-centre path (lines plus arcs).
double pathLength(std::span<const PathElement> toolpath);

}  // namespace scallop
