#pragma once
// Outputs of an optimal slicing orientation (the `scallop orient` command): its JSON form and
// two self-contained SVG figures in the spirit of Smith, Farouki, al-Kandari, Pottmann,
// "Optimal slicing of free-form surfaces" (2002), Figs 3, 4, 5, 10, 11 and 12.
//
// JSON (keys in this order; numbers are the shortest text that round-trips to the same
// double, so every value is the in-memory one bit for bit; angles in degrees by toDegrees):
//   {"normal": [x, y, z]                     N*, unit (+-N* slice alike),
//    "alpha_deg": a                          alpha*, the least angle between N* and +-n,
//    "certified": bool, "certified_alpha_deg": a, "certificate_cells": k
//                                            what the Bernstein-form certificate proved
//                                            (false, 0, 0 when it was not run),
//    "method": "medial-axis" | "plane" | "curve",
//    "circle": {"center": [x, y], "radius": R} | null
//                                            the maximal circle in the pole frame's
//                                            stereographic plane (null unless medial-axis),
//    "sphere_circle": {"center": [x, y, z], "alpha_deg": a}
//                                            the optimal circle on the sphere (original frame),
//    "pole": [x, y, z]                       the surface normal used as the pole,
//    "tolerance_deg": t                      the Gauss-map tolerance the caller used,
//    "gauss_map": {"kind": "region" | "curve" | "point", "loops",
//                  "boundary_segments", "parabolic_curves" (connected parabolic lines),
//                  "traced_cells", "fold_cells", "untraced_cells", "candidate_pieces",
//                  "image_vertices", "coarse_band" (bool)}   counts (see GaussMap),
//    "medial_axis": {"edges", "rebuilds", "segments" (of the final domain searched),
//                    "refinements" (coarse-to-fine rounds)},
//    }
// No wall time (the CLI prints it on stderr): the same input gives the same bytes.
//
// Figures (fixed-point numbers only: no exponent, nan or inf; deterministic):
//   gaussMapSphereSvg: the symmetrized Gauss map Omega on the unit sphere, in two
//     orthographic views, both with N* in front: one tilted 45 degrees from N* towards the
//     pole p (a surface normal, so the part of Omega around p is in front) and one tilted
//     towards -p (the part around -p in front), so that together they show where the circle
//     touches Omega on both sides, as the paper's Fig. 5 does. Each view: the sphere's
//     outline, equator and meridians (original frame, z up) faint, Omega's visible part
//     shaded, its boundary solid where visible and dashed where hidden, the optimal circle
//     (centre N*, angular radius alpha*) likewise, N* marked, the axes' directions, a legend
//     and a title giving N* and alpha*.
//   stereographicSvg: the stereographic plane of the pole frame (Figs 4 and 11): Omega
//     shaded (even-odd rule over the boundary loops), its boundary loops, the medial axis of
//     the complement (thin), the optimal circle and its centre, the unit circle dashed (the
//     image of the equator), the origin (the image of -p) and the axes. The image of the part
//     of Omega around p is large and the part around -p small (the paper's "barely
//     distinguishable" south cap), so there are two panels with linear scales: the whole
//     domain, and a zoom centred on the origin fitted to the innermost loop around it (its
//     region is outlined in the first panel). Each panel has its own scale bar.
// Both throw scallop::Error if a coordinate they would draw is not finite.

#include <numbers>
#include <string>

#include "scallop/geometry/mesh.hpp"
#include "scallop/slicing/mesh_slicing.hpp"
#include "scallop/slicing/optimal_slicing.hpp"

namespace scallop {

/// Radians to degrees, as every "*_deg" key of orientationToJson is computed.
constexpr double toDegrees(double radians) { return radians * (180.0 / std::numbers::pi); }

/// The JSON form of `result` (see above); `toleranceDeg` is recorded as "tolerance_deg".
std::string orientationToJson(const OptimalSlicing& result, double toleranceDeg);

/// What a part with trimmed faces adds to its orientation (cad_import.hpp's acceptTrimmed).
struct TrimmedFacts {
  std::size_t faces = 0;            ///< trimmed faces
  std::size_t insidePieces = 0;     ///< pieces inside their faces (untrimmed faces' patches too)
  std::size_t boundaryPieces = 0;   ///< pieces crossing (or touching) a trimming curve
  double spreadRad = 0.0;           ///< the normal spread asked of boundary pieces
  double largestSpreadRad = 0.0;    ///< the largest a boundary piece has
  const OptimalSlicing* inside = nullptr;  ///< the slicing of the inside pieces alone, if any
};

/// orientationToJson of a part with trimmed faces: `result` is the slicing of all its pieces
/// (inside and boundary: a superset of the faces' normals, so its N* keeps at least its
/// certified alpha from every normal of the part), with, at the end, "trimmed":
/// {"faces", "inside_pieces", "boundary_pieces", "spread_deg", "largest_spread_deg",
///  "alpha_lower_deg" (the certified alpha, or alpha_deg when not certified),
///  "alpha_upper_deg" (alpha* of the inside pieces alone, a subset of the normals: no
///  direction does better on the part, within the Gauss map's tolerance; null without inside
///  pieces, or when it bounds nothing), "upper_method" (that slicing's method: "covered" when
///  the inside pieces' normals provably cover the sphere, alpha* = 0; "open" when their Gauss
///  map leaves no direction free without such a proof: alpha_upper_deg is then null),
///  "upper_normal" (that slicing's N*, or null)}.
std::string trimmedOrientationToJson(const OptimalSlicing& result, double toleranceDeg, const TrimmedFacts& facts);

/// The JSON form of a mesh's optimal slicing (mesh_slicing.hpp): {"input": "mesh", "source",
/// "format": "binary"|"ascii", "units", "triangles_read", "zero_area_dropped", "triangles" (of
/// positive area), "distinct_normals", "hull_facets", "great_circle", "normal": [x, y, z],
/// "alpha_deg"}; numbers round-trip exactly.
std::string meshOrientationToJson(const MeshSlicing& result, const StlMesh& mesh, const std::string& source);

/// What `scallop orient` says of a STEP or IGES part oriented by its tessellation
/// (cad_tessellation.hpp): the facts of the mesh beside the facets' optimum.
struct TessellationFacts {
  Units units = Units::millimetre;
  std::size_t faces = 0;
  double deflection = 0.0;        ///< asked of OCCT's mesher
  double deviation = 0.0;         ///< sampled distance, exact faces to their triangles
  double normalAngleRad = 0.0;    ///< sampled angle, exact normals to their facets'
  std::size_t normalsSampled = 0;
};

/// meshOrientationToJson for a tessellated part: input "tessellation", the facts, and the
/// optimum over the part's sampled exact normals (optimalNormalSlicing): alpha_deg is then an
/// upper bound of the part's alpha* ("alpha_is": "upper bound"), not certified.
std::string tessellationOrientationToJson(const MeshSlicing& result, const TessellationFacts& facts,
                                          const std::string& source);

/// The symmetrized Gauss map and the optimal circle on the unit sphere (see above).
std::string gaussMapSphereSvg(const OptimalSlicing& result);

/// The pole frame's stereographic plane: loops, medial axis, optimal circle (see above).
std::string stereographicSvg(const OptimalSlicing& result);

}  // namespace scallop
