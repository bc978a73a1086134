#pragma once
// Exact ball drop-cutter and clearance on triangle meshes (issue 14, items 4 and 5): the
// lowest centre of a ball of radius R above a point (x, y) that penetrates no triangle of an
// STL mesh, the exact distance from a straight centre move to the mesh, and the drop
// envelope along a horizontal line as a polyline whose moves are proven clear.
//
// Contract of MeshDropCutter
// --------------------------
// Input:  a Mesh (mesh.hpp: vertices, triangles as vertex indices; coordinates finite, units
//         the mesh's), the ball radius R > 0 in the same units. Triangles are two-sided (the
//         ball comes from above, whatever the vertex order); a triangle of zero area counts
//         through its edges and vertices only.
// drop(x, y): Z(x, y) = max over points q of the mesh with |q_xy - (x, y)| <= R of
//         q_z + sqrt(R^2 - |q_xy - (x, y)|^2), the lowest centre height at which the ball
//         touches nothing, and the feature that touches. It is the maximum over the
//         triangles' features within R of their closed-form contact heights:
//         - facet (normal n with n_z > 0): the ball rests on the plane with its contact
//           c = C - R n, so c_xy = (x, y) - R n_xy is known before z; valid when c_xy lies in
//           the projected triangle; height = (plane height at c_xy, a convex combination of
//           the vertex heights) + R n_z. Vertical facets (n_z = 0) touch nothing through
//           their interior (p_z + sqrt(...) grows upwards along them);
//         - edge (horizontal length l, rise dz, slope angle theta): in the vertical plane
//           parallel to the edge at horizontal distance d from it the ball's section is a
//           circle of radius r = sqrt(R^2 - d^2); resting on the edge's line from above,
//           (h - z0 - t tan theta) cos theta = r, so h = z0 + t tan theta + r / cos theta
//           (t: the centre's coordinate along the edge); the foot of the perpendicular lies at
//           t + r sin theta, valid in [0, l]. Vertical edges: through their end points only;
//         - vertex v within R: v_z + sqrt(R^2 - d^2).
//         Each valid candidate is a real touching height, hence <= Z, and the maximiser of
//         the definition lies in the relative interior of one feature, whose candidate is
//         Z: so the maximum is exact. -infinity (feature none) when nothing lies within R.
// Rounding: every candidate is a few operations on differences of input coordinates; with
//         S = the largest |coordinate| of the mesh and the point, u = 2^-53, a candidate is
//         the exact one of a point moved by at most ~8 u S horizontally, to within
//         ~8 u (S + R) vertically, so |error| <= ~8 u (S + R)(1 + |grad Z|). Where Z is
//         steep that is what limits it: near-vertical facets and edges, and a contact at the
//         ball's equator (horizontal distance d = R, where sqrt(R^2 - d^2) is vertical),
//         there at most sqrt(16 u S R) (one rounding of d moves the root by that: ~1e-8 R
//         for S ~ R). The tests find at most ~1e-15 of the part size on random points of
//         random meshes and OpenCAMLib's parts, and the equator bound on drop-line stations
//         that fall exactly at d = R. A feature misclassified at a boundary by rounding
//         changes nothing: the neighbouring feature's candidate is the same height there.
// segmentDistance(a, b, cutoff): the exact Euclidean distance from the segment [a, b] to the
//         mesh when it is below cutoff, else cutoff: min over triangles whose box is nearer
//         than the best so far of {0 if the segment crosses the triangle; the end points'
//         distance to the triangle; the segment's distance to each edge} (the closest pair of
//         a segment and a triangle it does not cross has a point on the segment's end or on
//         the triangle's boundary), with the same rounding as above.
// dropLine(origin, direction, t0, t1): centres over the line origin + t direction (xy, a
//         unit horizontal direction), t in [t0, t1]: vertices at exact heights max(Z, floor)
//         (floor default: the mesh's lowest z + R, a ball standing on the part's base level
//         off the part), t increasing, both ends included; stations every `step` (default
//         R / 4), then each move refined by halving where it is not proven, or where the
//         drop at its midpoint or quarter points lies more than `sagTolerance` below the
//         chord (material that the straight move would leave: a check at three points, not
//         a proof). What is proven: every output move keeps every centre on it at least
//         R - eps from the mesh (segmentDistance, less a rounding allowance of
//         64 u (S + R)), so the ball cuts no
//         deeper than eps; a move still unproven after kMeshMaxHalvings halvings is kept and
//         counted (DropLine::unprovenMoves). Depth is proven along the normal, as a cut
//         is: measured vertically, a chord can lie further below Z where the touching
//         surface is steep (up to 0.0135 at the silhouette of OpenCAMLib's sphere.stl, R =
//         3.46, eps = 1.7e-4; 9.3e-4 on mount_rush.stl's moves of slope <= 1, eps = 1e-4),
//         and where Z jumps (a wall's top edge leaving the ball at its equator) every
//         polyline has a near-vertical move. Material left is only checked: the ball's gap
//         to the part along the moves, sampled 32 times a move on four of OpenCAMLib's parts
//         (20 lines each, R = 2% of the size, eps = sag tolerance = 1e-6 of the size), was
//         at most eps on three and 1.9 eps on mount_rush.stl.
// Index:  a uniform grid over the xy plane, the facets, the distinct edges and the vertices
//         listed per cell their xy box covers; a query visits the cells its box (the point
//         grown by R, the segment by the cutoff) covers and handles each feature once (only
//         in the cell holding the lower-left corner of its box intersected with the query's:
//         no mark array, so queries are const and thread-safe). Chosen over Boost's rtree
//         because tessellated parts have triangles of similar size: a cell is addressed
//         directly, with no tree descent, and the distinct edges and vertices (each edge and
//         vertex once, not once per triangle: about 3 and 6 times fewer evaluations) sit
//         next to the facets. A drop visits its cells highest first (each cell's highest
//         feature z + R bounds what its features can give) and stops at the first cell whose
//         bound is not above the best height found: on a terrain most of the disk is skipped.
// Complexity: building O(n) for n triangles (the edges sorted: O(n log n)); drop O(k) for k
//         features within about R + one cell; segmentDistance O(k) likewise around the
//         segment; dropLine O(m) drops and proofs for m output vertices, m about
//         (t1 - t0) / step + the curved stretches' length / sqrt(8 R s) (s: the smaller of
//         eps and the sag tolerance; a chord over an arc of radius R sags L^2 / (8 R)).
// Errors: scallop::Error for R not positive and finite, an empty mesh, a triangle index out
//         of range, a non-finite vertex, a non-finite query point, cutoff negative or NaN, a
//         direction not unit and horizontal, t0 > t1 or not finite, step, eps or sag
//         tolerance not positive, more than maxVertices output vertices.
// Threads: every query is const; one cutter may be shared by threads. dropLine polls the
//         thread's job control (job_control.hpp) per station: scallop::Cancelled.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Halvings of one drop-line move before its pieces are kept unproven.
constexpr int kMeshMaxHalvings = 40;

/// What touches the ball at a drop.
enum class MeshFeature {
  none,    ///< nothing within R: the height is -infinity
  facet,   ///< a triangle's interior
  edge,    ///< an edge's interior
  vertex,  ///< a vertex
};

struct MeshContact {
  double z = -std::numeric_limits<double>::infinity();  ///< centre height
  MeshFeature feature = MeshFeature::none;
  std::size_t triangle = 0;  ///< a triangle holding the feature (facet: that triangle)
  /// The feature's vertices (indices into Mesh::vertices): edge: its two; vertex: [0] only.
  std::array<std::uint32_t, 2> vertices{};
};

struct MeshDropOptions {
  /// Side of the index's cells (mesh units, > 0); 0: automatic (the larger of the mean
  /// triangle's xy extent and R / 2, grown until there are at most 4 cells per triangle).
  double cellSize = 0.0;
};

struct DropLineOptions {
  double step = 0.0;          ///< spacing of the initial stations (> 0); 0: R / 4
  double eps = 0.0;           ///< depth proven (> 0); 0: 1e-6 of the mesh's size
  /// Midpoint check against material left (> 0; infinity: none); 0: eps.
  double sagTolerance = 0.0;
  /// Lowest centre height (a ball off the part); NaN: the mesh's lowest z + R.
  double floor = std::numeric_limits<double>::quiet_NaN();
  std::size_t maxVertices = 10'000'000;  ///< budget
};

struct DropLineVertex {
  double t = 0.0;  ///< line parameter
  Vec3 centre;     ///< ball centre: (origin + t direction, max(Z, floor))
  MeshContact contact;  ///< the drop there (feature none: the floor or nothing within R)
};

struct DropLine {
  std::vector<DropLineVertex> vertices;
  double eps = 0.0;               ///< depth tolerance used
  double sagTolerance = 0.0;      ///< used
  std::size_t drops = 0;          ///< drop queries made
  std::size_t proofs = 0;         ///< clearance proofs run
  std::size_t unprovenMoves = 0;  ///< moves kept without a proof
};

class MeshDropCutter {
 public:
  /// Builds the index (see the contract).
  MeshDropCutter(const Mesh& mesh, double radius, const MeshDropOptions& options = {});

  double radius() const { return radius_; }
  /// The diagonal of the mesh's bounding box: the scale of default tolerances.
  double meshSize() const { return size_; }
  double cellSize() const { return cell_; }
  /// Lowest and highest vertex heights.
  double minZ() const { return minZ_; }
  double maxZ() const { return maxZ_; }

  /// The exact drop height at (x, y) and what touches (see the contract).
  MeshContact drop(double x, double y) const;

  /// The exact distance from the segment [a, b] to the mesh when below cutoff, else cutoff.
  double segmentDistance(Vec3 a, Vec3 b,
                         double cutoff = std::numeric_limits<double>::infinity()) const;

  /// Whether every point of [a, b] lies at least `clearance` from the mesh, proven with the
  /// rounding allowance (stops at the first triangle nearer).
  bool segmentClear(Vec3 a, Vec3 b, double clearance) const;

  /// The drop envelope along a horizontal line (see the contract).
  DropLine dropLine(Vec2 origin, Vec2 direction, double t0, double t1,
                    const DropLineOptions& options = {}) const;

 private:
  struct Facet {
    std::array<Vec2, 3> xy;     // counter-clockwise in xy when not vertical
    std::array<double, 3> z;
    Vec2 offset;                // R n_xy (n the unit normal with n_z >= 0)
    double rnz = 0.0;           // R n_z; 0: vertical or degenerate (no interior contact)
    std::array<Vec3, 3> p;      // the triangle in space, for distances
    Vec3 normal;                // unit normal (zero when degenerate)
    Vec3 lo, hi;                // 3D box
    std::int32_t cx = 0, cy = 0;  // the box's lowest cell
  };
  struct Edge {
    Vec3 p0;
    Vec2 dir;                   // unit, horizontal
    double length = 0.0;        // horizontal length l
    double tanTheta = 0.0, secTheta = 0.0, sinTheta = 0.0;
    double lox = 0, loy = 0, hix = 0, hiy = 0;
    double top = 0.0;           // the higher end's z
    std::uint32_t a = 0, b = 0;
    std::uint32_t triangle = 0;
    std::int32_t cx = 0, cy = 0;
  };
  struct Vertex {
    Vec3 p;
    std::uint32_t index = 0;
    std::uint32_t triangle = 0;
  };
  struct Cell {
    std::uint32_t facetBegin = 0, edgeBegin = 0, vertexBegin = 0;
  };

  std::int32_t cellX(double x) const;
  std::int32_t cellY(double y) const;
  double allowance(Vec3 a, Vec3 b) const;

  double radius_ = 0.0;
  double size_ = 0.0;
  double cell_ = 0.0;
  double minZ_ = 0.0, maxZ_ = 0.0;
  double maxAbs_ = 0.0;
  double x0_ = 0.0, y0_ = 0.0;
  std::int32_t nx_ = 0, ny_ = 0;
  std::vector<Facet> facets_;
  std::vector<Edge> edges_;
  std::vector<Vertex> vertices_;
  // Per cell (row-major, plus one sentinel), the start of its lists in the arrays below.
  std::vector<Cell> cells_;
  // Per cell, the highest z of the features listed in it (-infinity: none): no feature of it
  // can hold the ball higher than that + R.
  std::vector<double> cellTop_;
  std::vector<std::uint32_t> cellFacets_, cellEdges_, cellVertices_;
};

}  // namespace scallop
