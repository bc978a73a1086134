// A trimmed face's patch as Bezier pieces for the Gauss map (see trimmed_patch.hpp).

#include "scallop/geometry/trimmed_patch.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

// The restricted coefficients carry rounding of a few ulps relative to their size (bernstein.hpp's
// bounds for restrictTo); an angle bound this much larger covers it.
constexpr double kSpreadRoundingRad = 1e-12;

struct Pending {
  ParameterCell cell;
  int depth = 0;
};

}  // namespace

double normalSpreadBound(const NormalDirection& direction, const ParameterCell& cell) {
  std::array<Bernstein2, 3> q;
  for (std::size_t c = 0; c < 3; ++c) q[c] = restrictTo(direction.polynomials[c], cell.u0, cell.u1, cell.v0, cell.v1);
  Vec3 axis{evaluate(q[0], 0.5, 0.5), evaluate(q[1], 0.5, 0.5), evaluate(q[2], 0.5, 0.5)};
  const std::size_t count = q[0].coefficients.size();
  if (!(norm(axis) > 0.0)) {
    // q vanishes at the centre only on a patch that is not regular; the coefficients' sum
    // still gives a direction to measure from.
    axis = {};
    for (std::size_t i = 0; i < count; ++i) axis = axis + Vec3{q[0].coefficients[i], q[1].coefficients[i], q[2].coefficients[i]};
    if (!(norm(axis) > 0.0)) return std::numbers::pi;
  }
  axis = axis / norm(axis);
  double widest = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 c{q[0].coefficients[i], q[1].coefficients[i], q[2].coefficients[i]};
    const double length = norm(c);
    if (length == 0.0) continue;  // adds nothing to any combination's direction
    const double cosine = dot(c, axis) / length;
    if (!(cosine > 0.0)) return std::numbers::pi;
    widest = std::max(widest, std::acos(std::min(1.0, cosine)));
  }
  return std::min(std::numbers::pi, widest + kSpreadRoundingRad);
}

TrimSplit splitTrimmedPatch(const BezierPatch& patch, const CellClassifier& classify, const TrimSplitOptions& options) {
  if (!(options.normalSpreadRad > 0.0) || !std::isfinite(options.normalSpreadRad))
    throw Error(fmt::format("trimmed patch: the normal spread must be a positive number of radians, got {}",
                            options.normalSpreadRad));
  if (options.maxDepth < 1 || options.maxDepth > 20)
    throw Error(fmt::format("trimmed patch: the deepest level must be in 1 .. 20, got {}", options.maxDepth));
  if (options.maxPieces < 1) throw Error("trimmed patch: the budget of pieces must be at least 1");

  TrimSplit split;
  const std::size_t maxCells = 4 * options.maxPieces;
  NormalDirection direction;
  bool haveDirection = false;
  const auto emit = [&](const ParameterCell& cell, PieceRole role, double spread) {
    if (split.pieces.size() >= options.maxPieces)
      throw Error(fmt::format("trimmed patch: more than {} pieces are needed to follow the trimming curves to a normal "
                              "spread of {:.4g} deg (at cell [{:.6g}, {:.6g}] x [{:.6g}, {:.6g}])",
                              options.maxPieces, options.normalSpreadRad * 180.0 / std::numbers::pi, cell.u0, cell.u1,
                              cell.v0, cell.v1));
    TrimmedPiece piece;
    const bool whole = cell.u0 == 0.0 && cell.u1 == 1.0 && cell.v0 == 0.0 && cell.v1 == 1.0;
    piece.patch = whole ? patch : restrictTo(patch, cell.u0, cell.u1, cell.v0, cell.v1);
    piece.cell = cell;
    piece.role = role;
    piece.spreadRad = spread;
    if (role == PieceRole::inside) {
      ++split.insidePieces;
    } else {
      ++split.boundaryPieces;
      split.largestSpreadRad = std::max(split.largestSpreadRad, spread);
    }
    split.pieces.push_back(std::move(piece));
  };

  std::deque<Pending> queue{{ParameterCell{}, 0}};
  while (!queue.empty()) {
    const Pending current = queue.front();
    queue.pop_front();
    if (++split.cellsExamined > maxCells)
      throw Error(fmt::format("trimmed patch: more than {} cells examined following the trimming curves", maxCells));
    const ParameterCell& cell = current.cell;
    const CellPlace place = classify(cell);
    if (place == CellPlace::outside) continue;
    if (place == CellPlace::inside) {
      emit(cell, PieceRole::inside, 0.0);
      continue;
    }
    if (!haveDirection) {
      direction = normalDirectionPolynomials(patch);
      haveDirection = true;
    }
    const double spread = normalSpreadBound(direction, cell);
    if (spread <= options.normalSpreadRad || current.depth >= options.maxDepth) {
      emit(cell, PieceRole::boundary, spread);
      continue;
    }
    const double um = 0.5 * (cell.u0 + cell.u1), vm = 0.5 * (cell.v0 + cell.v1);
    for (const ParameterCell child : {ParameterCell{cell.u0, um, cell.v0, vm}, ParameterCell{cell.u0, um, vm, cell.v1},
                                      ParameterCell{um, cell.u1, cell.v0, vm}, ParameterCell{um, cell.u1, vm, cell.v1}})
      queue.push_back({child, current.depth + 1});
  }
  return split;
}

Surface trimmedPieces(const Surface& surface, const TrimSplitOptions& options) {
  Surface pieces;
  pieces.units = surface.units;
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    const PatchTrim* trim = patchTrim(surface, i);
    if (trim == nullptr) {
      pieces.patches.push_back(surface.patches[i]);
      continue;
    }
    TrimSplit split = splitTrimmedPatch(
        surface.patches[i], [&](const ParameterCell& cell) { return classifyCell(*trim, cell); }, options);
    for (TrimmedPiece& piece : split.pieces) pieces.patches.push_back(std::move(piece.patch));
  }
  return pieces;
}

}  // namespace scallop
