// The clearance certificate (see clearance_certificate.hpp and optimal_slicing.hpp).

#include "slicing/clearance_certificate.hpp"

#include <array>
#include <cmath>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/optimal_slicing.hpp"

namespace scallop {
namespace detail {
namespace {

// Proves P = cos^2(bound) |N|^2 - (N . m)^2 > 0 on the cell (P given in Bernstein form on
// it): then |n . m| < cos(bound), no normal within `bound` of +-m.
bool provePositive(const Bernstein2& p, int depth, int maxDepth, std::size_t& cells) {
  if (cells % 64 == 0) checkCancelled();
  ++cells;
  const Bounds b = bounds(p);
  if (b.lo > 0.0) return true;
  if (b.hi < 0.0 || evaluate(p, 0.5, 0.5) < 0.0 || depth >= maxDepth) return false;
  auto [left, right] = subdivideU(p, 0.5);
  for (const Bernstein2* half : {&left, &right}) {
    auto [a, c] = subdivideV(*half, 0.5);
    if (!provePositive(a, depth + 1, maxDepth, cells)) return false;
    if (!provePositive(c, depth + 1, maxDepth, cells)) return false;
  }
  return true;
}

}  // namespace

// certifyClearance on a surface whose corners are resolved already (cornerPieces): the
// optimal slicing's bisection calls it up to kCertificateBisections times on the same pieces.
bool certifyPieces(const Surface& pieces, const Vec3& n, double lowerBoundRad, std::size_t& cells,
                   int maxDepth) {
  if (!(lowerBoundRad > 0.0)) return true;
  const Vec3 m = normalized(n);
  const double c = std::cos(lowerBoundRad);
  for (const BezierPatch& patch : pieces.patches) {
    // q, N's direction field (collapsed edges factored out), for N: the same directions, and
    // on an apex row their limits, which the certificate must cover too.
    const std::array<Bernstein2, 3> normal = normalDirectionPolynomials(patch).polynomials;
    Bernstein2 dotM = scale(normal[0], m.x);
    dotM = add(dotM, scale(normal[1], m.y));
    dotM = add(dotM, scale(normal[2], m.z));
    const Bernstein2 lengthSquared =
        add(add(multiply(normal[0], normal[0]), multiply(normal[1], normal[1])),
            multiply(normal[2], normal[2]));
    const Bernstein2 p = subtract(scale(lengthSquared, c * c), multiply(dotM, dotM));
    if (!provePositive(p, 0, maxDepth, cells)) return false;
  }
  return true;
}

}  // namespace detail

bool certifyClearance(const Surface& surface, const Vec3& n, double lowerBoundRad,
                      std::size_t& cells, int maxDepth) {
  return detail::certifyPieces(cornerResolved(surface), n, lowerBoundRad, cells, maxDepth);
}

}  // namespace scallop
