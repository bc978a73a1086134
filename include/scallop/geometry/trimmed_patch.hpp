#pragma once
// A trimmed face's patch as Bezier pieces for the Gauss map (issue 14, item 3: "the Gauss map
// includes only normals of the trimmed face: a cell outside the face contributes nothing, a
// cell crossing the boundary contributes what lies inside, conservatively").
//
// Contract of splitTrimmedPatch
// -----------------------------
// Input:  a valid patch (surface.hpp; polynomial or rational), and a classifier of parameter
//         cells [u0, u1] x [v0, v1] within [0, 1]^2 against the face's domain D (the part of
//         the patch inside the face's trimming curves) that is conservative:
//           inside   only if the closed cell lies in D,
//           outside  only if the open cell misses D,
//           boundary otherwise (always allowed).
//         Options: a normal spread (radians), a deepest level and a budget of pieces.
// Output: pieces of the patch, each the exact restriction (bezier.hpp's restrictTo: de
//         Casteljau, to rounding) of the patch to a quadtree cell:
//           inside   cells classified inside: together they lie in D;
//           boundary cells classified boundary whose normals provably spread by at most the
//                    given angle about their centre normal (below), or cells at the deepest
//                    level (then the spread they have is what is reported).
//         So the normals of inside pieces are normals of the face, and every normal of the
//         face is a normal of some piece: with n(D) the face's normals,
//           n(inside) <= n(D) <= n(inside + boundary),
//         and every normal of a boundary piece lies within its spread of a normal of the
//         face if the cell really meets D (a classifier's "boundary" for a cell that misses
//         D, near the trimming curve, may add normals of the surface just outside it).
//         For the slicing angle alpha* (optimal_slicing.hpp) this is a certified interval:
//         alpha*(inside + boundary) <= alpha*(D) <= alpha*(inside), and the first one's N*
//         keeps at least its alpha from every normal of the face.
// Spread: q (bezier.hpp's normalDirectionPolynomials, collapsed edges factored out) restricted
//         to the cell is a combination of its Bernstein coefficients c_jk with non-negative
//         weights; when every c_jk makes an acute angle with the centre normal a, the normals
//         of the cell lie within max angle(c_jk, a) of a: that is the spread bound, and pi
//         when some c_jk does not (no bound).
// Work:   a breadth-first quadtree: at most maxPieces pieces and 4 maxPieces cells examined;
//         past either, scallop::Error saying so. Each boundary split costs the restriction
//         of q, O((mn)^2) for a patch of bidegree (m, n).
// Determinism: the same input gives the same pieces, bit for bit, in the same order
//         (breadth-first, children in the order (u low, v low), (u low, v high), (u high, v low),
//         (u high, v high)).

#include <cstddef>
#include <functional>
#include <numbers>
#include <vector>

#include "scallop/geometry/bezier.hpp"

namespace scallop {

/// A cell of a patch's parameter square [0, 1]^2.
struct ParameterCell {
  double u0 = 0.0, u1 = 1.0, v0 = 0.0, v1 = 1.0;
};

/// Where a cell lies with respect to a face's domain (see the contract: conservative).
enum class CellPlace { inside, outside, boundary };

using CellClassifier = std::function<CellPlace(const ParameterCell&)>;

struct TrimSplitOptions {
  /// Boundary cells are split until their normals spread by at most this (radians, > 0).
  /// The pieces grow as 1 / spread along the trimming curves (measured on OCCT's screw.step,
  /// `scallop orient` in all: 938 pieces at 2 degrees, 1.8 s; 4,152 at 0.5, 7.4 s; 8,576 at
  /// 0.25, 15 s; CadImportOptions::maxTrimPieces bounds them).
  double normalSpreadRad = 2.0 * std::numbers::pi / 180.0;
  /// Deepest quadtree level, 1 .. 20 (cells of 2^-depth in u and v).
  int maxDepth = 14;
  /// Budget of pieces (inside and boundary together) for the patch, >= 1.
  std::size_t maxPieces = 20000;
};

enum class PieceRole { inside, boundary };

struct TrimmedPiece {
  BezierPatch patch;        ///< the patch restricted to `cell`, reparametrised to [0, 1]^2
  ParameterCell cell;
  PieceRole role = PieceRole::inside;
  double spreadRad = 0.0;   ///< boundary pieces: the proven spread bound of their normals
};

struct TrimSplit {
  std::vector<TrimmedPiece> pieces;
  std::size_t cellsExamined = 0;
  std::size_t insidePieces = 0;
  std::size_t boundaryPieces = 0;
  double largestSpreadRad = 0.0;  ///< over boundary pieces (0 when there is none)
};

/// The pieces of `patch` inside and on the boundary of a trimmed face (see the contract).
/// Throws scallop::Error on invalid options and past the budget.
TrimSplit splitTrimmedPatch(const BezierPatch& patch, const CellClassifier& classify,
                            const TrimSplitOptions& options = {});

/// The proven bound on the spread of the unit normals of `patch` over `cell` about the
/// normal at the cell's centre (see the contract's Spread), radians in [0, pi].
double normalSpreadBound(const NormalDirection& direction, const ParameterCell& cell);

}  // namespace scallop
