#pragma once
// The optimal slicing direction of a triangle mesh (issue 14, item 4): the paper's problem
// (Smith, Farouki, al-Kandari, Pottmann 2002) for a surface whose Gauss map is a finite set.
//
// Contract
// --------
// Input:  a mesh (mesh.hpp) with at least one triangle of positive area.
// Output: N*, a unit vector with N*_z >= 0 (N and -N slice alike), maximising
//         alpha(N) = min over the triangles of the angle between N and +-n_t (n_t the unit
//         normal, (b - a) x (c - a) normalised; zero-area triangles are skipped), and alpha*,
//         the least angle between N* and the facets' normals, as OptimalSlicing's alpha.
// Method: the symmetrized Gauss map of a mesh is the point set P = {+-n_t} on the unit sphere,
//         and N* is the centre of the largest spherical cap containing no point of P (the
//         largest empty circle on the sphere, the paper's problem for a finite set). Every
//         maximal empty cap is cut off by the supporting plane of a facet of the convex hull
//         of P (its points lie on the cap's rim), at distance d from the origin, with angular
//         radius acos(d) and centre the facet's outward normal: N* is the normal of the hull
//         facet nearest the origin. The hull is Qhull's (Debian's libqhull-dev, the field's
//         standard, robust to coplanar and repeated points); the distinct points of P only.
//         The hull is computed in floating point, so the candidates are its kCandidateFacets
//         facets nearest the origin, and alpha is evaluated exactly (in double) at each over
//         every normal: alpha* is alpha(N*) for the N* returned, not Qhull's figure.
// Degenerate: when P lies on one great circle (a prism's or an extrusion's facets, a plane:
//         the hull is flat), N* is the circle's pole and alpha* = 90 degrees.
// Tolerance: alpha* is the true alpha of the N* returned; optimality is that of the hull (the
//         tests compare with a brute force over 20,000 directions refined by pattern search).
// Cost:   O(T log T) for T triangles (Qhull's expected time on points on a sphere); a mesh of
//         a million triangles in a few seconds.
// Errors: scallop::Error for a mesh with no triangle of positive area, or a hull Qhull
//         refuses (its message quoted).

#include <cstddef>

#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Hull facets nearest the origin evaluated exactly (see the contract).
inline constexpr std::size_t kCandidateFacets = 16;

struct MeshSlicing {
  Vec3 normal;              ///< N*, unit, N*_z >= 0
  double alphaRad = 0.0;    ///< alpha(N*), radians in [0, pi/2]
  std::size_t triangles = 0;        ///< of positive area
  std::size_t distinctNormals = 0;  ///< distinct unit normals up to sign
  std::size_t hullFacets = 0;       ///< 0 when degenerate
  bool greatCircle = false;         ///< every +-normal on one great circle (see the contract)
  std::size_t normalsGiven = 0;     ///< the normals the optimum was taken over
};

/// See the contract.
MeshSlicing optimalMeshSlicing(const Mesh& mesh);

/// The same over a set of unit normals instead of a mesh's facets (a part's exact normals
/// sampled: cad_tessellation.hpp): the largest empty cap of their +-set. `triangles` is 0.
/// scallop::Error for an empty set or a normal that is not a unit vector (to 1e-9).
MeshSlicing optimalNormalSlicing(std::vector<Vec3> unitNormals);

/// alpha(N) of the contract for a unit N: the least angle between N and +-n_t, radians.
double meshSlicingAngle(const Mesh& mesh, const Vec3& unitNormal);

}  // namespace scallop
