// splitTrimmedPatch (trimmed_patch.hpp): pieces of a patch that follow a trimming curve, checked
// against the curve written here (disks in the parameter square, classified in closed form), the
// parent patch's own points, dense samples of the normals (the spread bound), and, for the
// slicing angle, a brute force over normals sampled densely inside the trimmed domain.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "support/gauss_references.hpp"
#include "support/rational_patches.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/slicing/mesh_slicing.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/trimmed_patch.hpp"

namespace {

using scallop::BezierPatch;
using scallop::CellPlace;
using scallop::ParameterCell;
using scallop::PieceRole;
using scallop::Surface;
using scallop::TrimSplit;
using scallop::TrimSplitOptions;
using scallop::Vec3;

constexpr double kDegree = std::numbers::pi / 180.0;

// The disk |(u, v) - centre| <= radius of the parameter square, classified in closed form: a
// cell is inside when its four corners are (the disk is convex), outside when its nearest
// point to the centre is farther than the radius.
struct Disk {
  double cu, cv, radius;
  bool contains(double u, double v) const { return std::hypot(u - cu, v - cv) <= radius; }
  CellPlace classify(const ParameterCell& c) const {
    if (contains(c.u0, c.v0) && contains(c.u0, c.v1) && contains(c.u1, c.v0) && contains(c.u1, c.v1))
      return CellPlace::inside;
    const double nu = std::clamp(cu, c.u0, c.u1), nv = std::clamp(cv, c.v0, c.v1);
    return contains(nu, nv) ? CellPlace::boundary : CellPlace::outside;
  }
};

bool inCell(const ParameterCell& c, double u, double v) { return u >= c.u0 && u <= c.u1 && v >= c.v0 && v <= c.v1; }
bool inCellInterior(const ParameterCell& c, double u, double v) { return u > c.u0 && u < c.u1 && v > c.v0 && v < c.v1; }

std::vector<BezierPatch> testPatches() {
  std::vector<BezierPatch> patches{scallop::exampleSurface("paper-1").patches[0],
                                   scallop::exampleSurface("paper-2").patches[0],
                                   scallop::test::torusPatch(3.0, 1.0, true), scallop::test::torusPatch(3.0, 1.0, false)};
  // A teapot patch with a collapsed edge (its lid's apex) when there is one.
  for (const BezierPatch& p : scallop::exampleSurface("teapot").patches) {
    bool collapsed = true;
    for (int k = 1; k <= p.degreeV; ++k) collapsed = collapsed && p.at(0, k) == p.at(0, 0);
    if (collapsed) {
      patches.push_back(p);
      break;
    }
  }
  std::mt19937_64 rng(20261128);
  patches.push_back(scallop::test::randomRationalPatch(rng, 3, 2));
  return patches;
}

TEST(TrimmedPatch, DiskTrimsTileTheDomainAndPiecesAreThePatchRestricted) {
  const std::vector<BezierPatch> patches = testPatches();
  ASSERT_GE(patches.size(), 6u);  // the teapot's apex patch was found
  // Disks: through the middle, tangent to an edge, around a corner, smaller than any cell the
  // spread asks for, covering the square, missing it.
  const std::vector<Disk> disks{{0.5, 0.5, 0.3}, {0.5, 0.3, 0.3}, {0.0, 1.0, 0.45}, {0.37, 0.61, 0.004},
                                {0.5, 0.5, 0.8}, {1.6, 0.5, 0.5}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t p = 0; p < patches.size(); ++p)
    for (const Disk& disk : disks) {
      SCOPED_TRACE(testing::Message() << "patch " << p << ", disk (" << disk.cu << ", " << disk.cv << ") r "
                                      << disk.radius);
      TrimSplitOptions options;
      options.normalSpreadRad = 3.0 * kDegree;
      const TrimSplit split =
          scallop::splitTrimmedPatch(patches[p], [&](const ParameterCell& c) { return disk.classify(c); }, options);
      EXPECT_EQ(split.pieces.size(), split.insidePieces + split.boundaryPieces);
      if (disk.radius == 0.8) {
        ASSERT_EQ(split.pieces.size(), 1u);  // the whole patch, as it is
        EXPECT_EQ(split.pieces[0].role, PieceRole::inside);
        EXPECT_TRUE(split.pieces[0].patch.control == patches[p].control);
      }
      if (disk.cu == 1.6) {
        EXPECT_TRUE(split.pieces.empty());
      }
      // Every point of the disk is in some piece's cell; inside cells lie in the disk; a point in
      // no cell is outside it; no two cells overlap.
      for (int trial = 0; trial < 4000; ++trial) {
        const double u = unit(rng), v = unit(rng);
        int covering = 0;
        for (const scallop::TrimmedPiece& piece : split.pieces) {
          if (inCellInterior(piece.cell, u, v)) ++covering;
          if (piece.role == PieceRole::inside && inCell(piece.cell, u, v)) {
            ASSERT_TRUE(disk.contains(u, v));
          }
        }
        ASSERT_LE(covering, 1);
        bool inSome = false;
        for (const scallop::TrimmedPiece& piece : split.pieces) inSome = inSome || inCell(piece.cell, u, v);
        if (disk.contains(u, v)) {
          ASSERT_TRUE(inSome) << u << ", " << v;
        }
      }
      // Pieces are the patch restricted to their cells: the same points.
      const double scale = [&] {
        double m = 0.0;
        for (const Vec3& c : patches[p].control) m = std::max({m, std::abs(c.x), std::abs(c.y), std::abs(c.z)});
        return m;
      }();
      for (std::size_t i = 0; i < split.pieces.size(); i += 1 + split.pieces.size() / 40) {
        const scallop::TrimmedPiece& piece = split.pieces[i];
        for (int trial = 0; trial < 5; ++trial) {
          const double s = unit(rng), t = unit(rng);
          const Vec3 expected = scallop::point(patches[p], piece.cell.u0 + s * (piece.cell.u1 - piece.cell.u0),
                                               piece.cell.v0 + t * (piece.cell.v1 - piece.cell.v0));
          ASSERT_LE(norm(scallop::point(piece.patch, s, t) - expected), 1e-12 * scale);
        }
      }
    }
}

// The spread bound holds: every normal sampled on a boundary piece lies within it of the
// piece's centre normal; and the pieces reach the asked spread (or the deepest level).
TEST(TrimmedPatch, BoundaryPiecesSpreadNoMoreThanTheirBound) {
  const Disk disk{0.45, 0.55, 0.35};
  std::size_t checked = 0;
  for (const BezierPatch& patch : testPatches()) {
    for (const double spreadDeg : {4.0, 1.0}) {
      TrimSplitOptions options;
      options.normalSpreadRad = spreadDeg * kDegree;
      const TrimSplit split =
          scallop::splitTrimmedPatch(patch, [&](const ParameterCell& c) { return disk.classify(c); }, options);
      for (const scallop::TrimmedPiece& piece : split.pieces) {
        if (piece.role != PieceRole::boundary) continue;
        EXPECT_LE(piece.spreadRad, options.normalSpreadRad);
        EXPECT_LE(piece.spreadRad, split.largestSpreadRad);
        const Vec3 centre = scallop::unitNormal(piece.patch, 0.5, 0.5);
        for (int i = 0; i <= 8; ++i)
          for (int k = 0; k <= 8; ++k) {
            const Vec3 n = scallop::unitNormal(piece.patch, i / 8.0, k / 8.0);
            const double angle = std::atan2(norm(cross(n, centre)), dot(n, centre));
            ASSERT_LE(angle, piece.spreadRad + 1e-9);
          }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500u);
}

// alpha* of a disk-trimmed face lies between the slicing of all pieces (certified: its N* keeps
// that angle from every normal of the face) and the slicing of the inside pieces; both against
// a brute force over normals sampled densely inside the disk (a polar grid, scallop's
// derivatives: the samples are normals of the face, so their largest empty cap, computed
// exactly, bounds alpha* from above, as the inside pieces' optimum does). The gap shrinks
// with the spread.
TEST(TrimmedPatch, SlicingBoundsBracketABruteForceOverTheTrimmedNormals) {
  struct Case {
    BezierPatch patch;
    Disk disk;
  };
  const std::vector<Case> cases{{scallop::exampleSurface("paper-1").patches[0], {0.5, 0.5, 0.3}},
                                {scallop::exampleSurface("paper-2").patches[0], {0.4, 0.6, 0.35}},
                                {scallop::test::torusPatch(3.0, 1.0, true), {0.3, 0.7, 0.25}}};
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const Case& tc = cases[c];
    std::vector<Vec3> samples;
    for (int i = 0; i <= 80; ++i)
      for (int k = 0; k < 160; ++k) {
        const double r = tc.disk.radius * std::sqrt(i / 80.0) * (1.0 - 1e-12), t = 2.0 * std::numbers::pi * k / 160.0;
        const double u = tc.disk.cu + r * std::cos(t), v = tc.disk.cv + r * std::sin(t);
        if (u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) samples.push_back(scallop::unitNormal(tc.patch, u, v));
      }
    const double sampledAlpha = scallop::optimalNormalSlicing(samples).alphaRad;
    double previousGap = 10.0;
    for (const double spreadDeg : {2.0, 0.5}) {
      SCOPED_TRACE(testing::Message() << "case " << c << ", spread " << spreadDeg << " deg");
      TrimSplitOptions options;
      options.normalSpreadRad = spreadDeg * kDegree;
      const TrimSplit split =
          scallop::splitTrimmedPatch(tc.patch, [&](const ParameterCell& cell) { return tc.disk.classify(cell); }, options);
      Surface all, inside;
      for (const scallop::TrimmedPiece& piece : split.pieces) {
        all.patches.push_back(piece.patch);
        if (piece.role == PieceRole::inside) inside.patches.push_back(piece.patch);
      }
      ASSERT_FALSE(inside.patches.empty());
      const scallop::OptimalSlicing lower = scallop::optimalSlicing(all);
      scallop::OptimalSlicingOptions upperOptions;
      upperOptions.certify = false;
      const scallop::OptimalSlicing upper = scallop::optimalSlicing(inside, upperOptions);
      ASSERT_TRUE(lower.certified);
      const double lowerBound = lower.certifiedAlphaRad, upperBound = upper.alphaRad;
      std::printf("[          ] case %zu, spread %.1f deg: %zu pieces (%zu boundary): alpha* in [%.4f, %.4f] deg, "
                  "sampled normals' cap %.4f deg\n",
                  c, spreadDeg, split.pieces.size(), split.boundaryPieces, lowerBound / kDegree, upperBound / kDegree,
                  sampledAlpha / kDegree);
      // The certified N* keeps its angle from every sampled normal of the face.
      EXPECT_GE(scallop::reference::sampledAlpha(samples, lower.normal), lowerBound - 1e-12);
      // Both are bounds of alpha*, which the samples' cap bounds from above.
      EXPECT_LE(lowerBound, upperBound + 1e-9);
      EXPECT_LE(lowerBound, sampledAlpha + 1e-12);
      // How tight: a boundary piece holds a point of the face, and its normals lie within its
      // spread of that point's, so every normal added lies within twice the spread of a normal
      // of the face: alpha* - lower <= 2 spread; the samples' cap is within a few thousandths
      // of a degree above alpha* (80 x 160 over the disk). The inside pieces miss the band of
      // boundary pieces, whose normals lie within twice the spread of theirs.
      EXPECT_LE(sampledAlpha - lowerBound, 2.0 * options.normalSpreadRad);
      EXPECT_LE(upperBound - sampledAlpha, 2.0 * options.normalSpreadRad);
      const double gap = upperBound - lowerBound;
      EXPECT_LE(gap, previousGap + 1e-9);
      previousGap = gap;
    }
  }
}

TEST(TrimmedPatch, BadOptionsAndBudgetsAreErrors) {
  const BezierPatch patch = scallop::exampleSurface("paper-1").patches[0];
  const Disk disk{0.5, 0.5, 0.3};
  const auto classify = [&](const ParameterCell& c) { return disk.classify(c); };
  TrimSplitOptions options;
  options.normalSpreadRad = 0.0;
  EXPECT_THROW((void)scallop::splitTrimmedPatch(patch, classify, options), scallop::Error);
  options.normalSpreadRad = std::nan("");
  EXPECT_THROW((void)scallop::splitTrimmedPatch(patch, classify, options), scallop::Error);
  options = {};
  options.maxDepth = 21;
  EXPECT_THROW((void)scallop::splitTrimmedPatch(patch, classify, options), scallop::Error);
  options = {};
  options.maxPieces = 0;
  EXPECT_THROW((void)scallop::splitTrimmedPatch(patch, classify, options), scallop::Error);
  // A classifier that never decides: the deepest level ends it, or the budget does, with a message.
  options = {};
  options.maxPieces = 50;
  options.maxDepth = 4;  // 256 pieces at that level: the budget ends it
  options.normalSpreadRad = 1e-6;
  try {
    (void)scallop::splitTrimmedPatch(patch, [](const ParameterCell&) { return CellPlace::boundary; }, options);
    FAIL() << "no error past the budget";
  } catch (const scallop::Error& error) {
    EXPECT_NE(std::string(error.what()).find("more than 50 pieces"), std::string::npos) << error.what();
  }
  // The same input, the same pieces, bit for bit.
  const TrimSplit a = scallop::splitTrimmedPatch(patch, classify), b = scallop::splitTrimmedPatch(patch, classify);
  ASSERT_EQ(a.pieces.size(), b.pieces.size());
  for (std::size_t i = 0; i < a.pieces.size(); ++i) EXPECT_TRUE(a.pieces[i].patch.control == b.pieces[i].patch.control);
}

}  // namespace
