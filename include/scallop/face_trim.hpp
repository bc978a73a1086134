#pragma once
// A trimmed face's domain in its parameter plane: the trimming curves (the pcurves of its
// edges) as exact rational Bezier arcs, and where boxes and points of the plane lie with
// respect to them (issue 14, item 3: "the trimming curves are honoured everywhere").
// OpenCASCADE-free: cad_import.cpp converts a face's pcurves into arcs; everything here is
// plain geometry, so that the Gauss map, sections, distances and the simulated cut can all
// classify against the same curves.
//
// Contract of mayMeet
// -------------------
// Input:  an arc of n >= 1 homogeneous poles (w u, w v, w), every w > 0 and finite, and a box.
// Output: false only when the arc provably misses the box: a rational arc with positive
//         weights lies in the convex hull of its poles, so in their box, and each half
//         (de Casteljau on the homogeneous poles at 1/2) lies in its poles' box. true once a
//         half whose poles' box meets the box is smaller than an eighth of the box in both
//         directions, or at depth 40: conservatively "may meet". Rounding of the halving is
//         a few ulps of the poles; callers widen their boxes by more (cad_import.cpp: 1e-8
//         of the face's rectangle).
// Work:   at most 2^k halves examined for the depth k reached, k <= 40; in practice a few
//         dozen (an arc's halves away from the box drop out at once).

#include <array>
#include <vector>

namespace scallop {

/// A box [u0, u1] x [v0, v1] of a face's parameter plane (closed).
struct ParameterBox {
  double u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0;
  bool meets(const ParameterBox& other) const {
    return u0 <= other.u1 && other.u0 <= u1 && v0 <= other.v1 && other.v0 <= v1;
  }
};

/// One rational Bezier arc of a trimming curve in a face's parameter plane: its poles in
/// homogeneous coordinates (w u, w v, w), w > 0, from the arc's start to its end.
using TrimArc = std::vector<std::array<double, 3>>;

/// The box of the arc's poles (u = wu / w, v = wv / w).
ParameterBox poleBox(const TrimArc& arc);

/// Whether the arc may meet the box (see the contract: false is proven).
bool mayMeet(const TrimArc& arc, const ParameterBox& box);

}  // namespace scallop
