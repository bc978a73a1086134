#pragma once
// Tolerances: the unit roundoff every rounding-error bound is written in, and where each
// module's tolerance lives.
//
// The scheme
// ----------
// scallop never compares with a bare absolute epsilon. A tolerance is one of:
// - a rounding-error bound, k u (scale + |query|), with u the unit roundoff below and k
//   derived from the operation count (the derivation sits beside the bound, e.g.
//   gouge.cpp's cellAllowance, bezier.cpp's normal bounds, bernstein.cpp's enclosures,
//   mesh_drop.cpp's segment distance); such a bound is proven, not tuned;
// - a relative tolerance, a fixed fraction of the input's scale (surfaceScale, the chain's
//   largest |coordinate| and r), stated in the contract of the header that uses it, as a
//   named constant next to that contract (listed below);
// - a user's tolerance in the user's length unit (scallop height H, gouge eps, the Gauss
//   map's angle), checked where it enters (job and command options).
// Inputs whose scale makes a relative tolerance meaningless are refused where it is applied
// (the hull past 1e9 r, surfaces outside kMinPatchScale .. kMaxPatchScale).
//
// The named relative tolerances, each beside the contract it belongs to:
//   geometry/surface.hpp        kRelativeNormalTolerance (regularity: |q| <= tau is a zero),
//                               kMinPatchScale, kMaxPatchScale, kMaxWeightRatio
//   geometry/face_trim.hpp      kWindingSlackRad (winding sums off a multiple of 2 pi)
//   slicing/gauss_map.hpp       kMinGaussMapToleranceRad (the finest angle accepted)
//   paths/scallop_hull.hpp      tau = 1e-12 max(r, |coordinate|) (its Tolerance paragraph)
//   paths/section.hpp           kJoinTolerance, kSeamJoinFactor (piece ends that are one point)
//   paths/raster.hpp            kRasterTurnTolerance (a section's s stepping back on a wall)
//   paths/gouge.hpp             kTrimCellReach (distance bounds beside a trimming curve)
//   paths/cut_simulation.hpp    kHelixTolerance (G18/G19 helices' branch and bound)
//   io/gcode.hpp                kGcodeMaxCoordinate, kGcodeMinArcRadiusInch/Mm
//
// Robust predicates: orientation and side tests are written once, where their error bound
// is derived: the hull's capsule side test (scallop_hull.cpp's sideOfCapsule, with its
// undecided band), the medial axis's exact integer grid (Boost.Polygon's Voronoi on 2^29
// integer coordinates, medial_axis.cpp), and the cell bounds of gouge.cpp. vector.hpp's
// cross() is the plain product, for callers that carry their own bound.

#include <limits>

namespace scallop {

/// The unit roundoff u = 2^-53 of IEEE double: |fl(a op b) - (a op b)| <= u |a op b|.
inline constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2.0;

}  // namespace scallop
