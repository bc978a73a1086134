#pragma once
// Contour machining on parallel planes (Smith, Farouki, al-Kandari, Pottmann, "Optimal
// slicing of free-form surfaces", Section 4 and Table 1): the surface is cut by the planes
// N . r = k Delta (eq. (3), k an integer), each section is a contact locus of the ball-end
// cutter, and the ball's centre follows its offset r + R n.
//
// Contract
// --------
// Input:  a valid surface (surface.hpp) to be cut from above (z up); a plane normal N
//         (finite, non-zero; normalised); a spacing Delta > 0 between planes; a ball radius
//         R > 0; a chordal tolerance (surface units) for the traced sections.
//         Or an explicit increasing list of plane offsets (ContourOptions::planeOffsets,
//         e.g. cusp.hpp's adaptive spacing), used instead of k Delta.
// Output: every plane N . r = k Delta that cuts the surface (k from the control points'
//         extent, so no plane is missed), its section (section.hpp), and one tool pass per
//         section curve through the centres r + R n at the curve's vertices (n the unit
//         normal at the vertex's (u, v), turned up at each point: n_z >= 0, the side a ball
//         from above reaches); passes follow the planes in increasing k, each entered from
//         the safe height. With dropEnvelope an open pass (a curve ending on the surface's
//         edge) runs on R/4 past each end along its end direction: where the planes cross an
//         edge obliquely the edge between two pass ends is otherwise cut from one side only.
//         By default (dropEnvelope) each pass is then lifted to the drop
//         envelope (envelope.hpp): a centre that would cut in (a concave radius below R, a
//         crease, another part of the surface within R, a chord sagging below the offset)
//         rises straight up to the lowest position proven clear, and every move is proven to
//         cut no deeper than depthTolerance; the lifted stretches are reported.
//         Statistics: planes that cut, connected components (summed over planes), the
//         contact-locus length and the tool-centre path length (polyline lengths, after
//         lifting).
// Scallop height: planes Delta apart meet the surface in curves whose local distance on the
//         surface is l = Delta / sqrt(1 - (N . n)^2) = Delta / sin(angle(N, n)); the ball
//         leaves a cusp of height h = R - sqrt(R^2 - l^2 / 4) between neighbouring passes
//         (on a locally flat surface). The worst case is at the smallest angle alpha between
//         N and +-n over the surface, so h <= H on flat parts when
//         Delta = 2 sqrt(2 R H - H^2) sin(alpha)   (spacingForScallopHeight).
//         This is why the optimal N* (largest alpha*) allows the widest planes for a given
//         scallop height: the path is shortest. On curved parts the cusp differs (higher on
//         convex ones): cusp.hpp estimates it from the curvature and chooses planeOffsets
//         that keep it <= H.
// Complexity: one planeSection per plane: O(planes * (cells + vertices)).

#include <cstddef>
#include <vector>

#include "scallop/paths/envelope.hpp"
#include "scallop/paths/section.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

struct ContourOptions {
  Vec3 normal{0.0, 0.0, 1.0};   ///< N, any length (normalised)
  double spacing = 0.0;         ///< Delta > 0, surface units
  double toolRadius = 0.0;      ///< R > 0, surface units
  double chordalTolerance = 0.0;  ///< > 0; 0 means 1e-4 times the surface's largest coordinate
  /// Lift the passes to the drop envelope (envelope.hpp): gouge-free in 3D to
  /// depthTolerance. Off: the centres r + R n as they are (they cut in where a concave
  /// radius is below R, at creases, where another part of the surface comes within R, and
  /// where a straight move sags below the true offset curve).
  bool dropEnvelope = true;
  /// eps of the drop envelope (>= 0); 0 means 1e-6 times surfaceScale.
  double depthTolerance = 0.0;  /// Lifts above this are reported as stretches the ball cannot follow (>= 0); 0 means
  /// the envelope's default (10 eps). The CLI passes the scallop height.
  double stretchThreshold = 0.0;
  /// The drop envelope's sag tolerance (envelope.hpp; >= 0, 0: off). The CLI passes H / 4.
  double sagTolerance = 0.0;
  /// Explicit plane offsets (strictly increasing, finite, at most kMaxPlanes), used instead
  /// of k Delta when non-empty: the planes N . r = planeOffsets[k] (cusp.hpp's
  /// adaptivePlaneOffsets). `spacing` is then only reported (it may be 0).
  std::vector<double> planeOffsets;
};

struct PathStats {
  std::size_t planes = 0;        ///< planes that cut the surface
  std::size_t components = 0;    ///< connected pieces of the sections, summed over planes
  double contactLength = 0.0;    ///< total length of the contact loci (sections)
  double centreLength = 0.0;     ///< total length of the tool-centre paths
  std::size_t touchPoints = 0;   ///< isolated tangent points (no path)
};

struct ContourSection {
  double offset = 0.0;  ///< k Delta (or planeOffsets[k]): the plane N . r = offset (N unit)
  long long k = 0;      ///< k, or the index into planeOffsets
  PlaneSection section;
};

struct ContourPaths {
  Vec3 normal;     ///< N, unit
  double spacing = 0.0;
  std::vector<ContourSection> sections;  ///< the planes that cut, in increasing k
  ToolPath path;   ///< one pass per section curve, same order
  PathStats stats;
  /// The drop envelope's lifting (ContourOptions::dropEnvelope; empty when off): its
  /// lifted stretches are where the ball as given cannot follow the surface (areas left for
  /// a smaller tool).
  EnvelopeReport envelope;
};

/// The contour paths of `surface` (see the contract); throws scallop::Error on bad options.
ContourPaths contourPaths(const Surface& surface, const ContourOptions& options);

/// The planes n . r = k Delta that can cut a surface: the surface lies in the convex hull of
/// its control points, so n . r spans at most [lo, hi], their range, and only k in
/// [first, last] = [ceil(lo / Delta), floor(hi / Delta)] can cut it (first > last: none).
/// Shared by the contour and raster strategies. Throws scallop::Error when that is more
/// than kMaxPlanes planes (`what` names the spacing in the message).
constexpr double kMaxPlanes = 100000.0;
struct PlaneRange {
  double lo = 0.0;
  double hi = 0.0;
  double first = 0.0;  ///< an integer
  double last = 0.0;   ///< an integer
};
PlaneRange planeRange(const Surface& surface, const Vec3& unitNormal, double spacing,
                      const char* what);

/// Throws scallop::Error unless `offsets` is empty or strictly increasing, finite and at most
/// kMaxPlanes long (`what` names the option).
void validatePlaneOffsets(const std::vector<double>& offsets, const char* what);

/// Delta = 2 sqrt(2 R H - H^2) sin(alpha): the plane spacing that keeps the scallop height
/// below H where the planes meet the surface at angle >= alpha (radians) to its normal.
/// Throws scallop::Error unless 0 < H < R and 0 < alpha <= pi / 2.
double spacingForScallopHeight(double toolRadius, double scallopHeight, double alphaRad);

/// The unit normal at (u, v) of patch `patch`, turned up (n_z >= 0; a horizontal normal keeps
/// the patch's r_u x r_v orientation).
Vec3 upwardNormal(const Surface& surface, std::size_t patch, double u, double v);

/// The smallest angle (radians) between `direction` and +-(surface normals), with a proof:
/// the value is first estimated by sampling and local refinement, then lowered until the
/// Bernstein-form certificate (optimal_slicing.hpp's certifyClearance) proves that no normal
/// comes closer. The result is a proven lower bound within about 0.01 degree of the truth.
double minimumAngleBound(const Surface& surface, const Vec3& direction);

}  // namespace scallop
