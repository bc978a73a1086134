#include "scallop/mesh_raster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {

double meshRasterSpacing(double toolRadius, double scallopHeight) {
  if (!(toolRadius > 0.0) || !std::isfinite(toolRadius) || !(scallopHeight > 0.0) || !(scallopHeight < toolRadius))
    throw Error(fmt::format("raster spacing: need 0 < H < R, got H = {} and R = {}", scallopHeight, toolRadius));
  return 2.0 * std::sqrt(2.0 * toolRadius * scallopHeight - scallopHeight * scallopHeight);
}

MeshRasterPaths meshRasterPaths(const MeshDropCutter& cutter, const Mesh& mesh, const MeshRasterOptions& options) {
  if (!(options.spacing > 0.0) || !std::isfinite(options.spacing))
    throw Error(fmt::format("mesh raster: the spacing must be positive and finite, got {}", options.spacing));
  if (!std::isfinite(options.angleRad))
    throw Error(fmt::format("mesh raster: the feed angle must be finite, got {}", options.angleRad));
  if (mesh.vertices.empty()) throw Error("mesh raster: the mesh has no vertices");
  const double radius = cutter.radius();
  const Vec2 along{std::cos(options.angleRad), std::sin(options.angleRad)};
  const Vec2 across{-along.y, along.x};
  double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
  for (const Vec3& v : mesh.vertices) {
    const double a = along.x * v.x + along.y * v.y, b = across.x * v.x + across.y * v.y;
    a0 = std::min(a0, a);
    a1 = std::max(a1, a);
    b0 = std::min(b0, b);
    b1 = std::max(b1, b);
  }
  const double t0 = a0 - radius, t1 = a1 + radius;
  const double steps = std::ceil((b1 - b0) / options.spacing);
  if (!(steps + 1.0 <= static_cast<double>(options.maxLines)))
    throw Error(fmt::format("mesh raster: a spacing of {} needs {:.0f} lines across {}, more than the budget of {}",
                            options.spacing, steps + 1.0, b1 - b0, options.maxLines));
  const auto lines = static_cast<std::size_t>(steps) + 1;
  const auto offset = [&](std::size_t k) {
    return k + 1 == lines ? b1 : b0 + static_cast<double>(k) * options.spacing;
  };

  DropLineOptions drop;
  drop.eps = options.eps;
  drop.sagTolerance = options.sagTolerance;
  MeshRasterPaths out;
  out.lines = lines;
  out.path.units = mesh.units;
  out.path.toolRadius = radius;
  ToolPass pass;
  pass.retractBefore = true;
  bool started = false;
  const auto append = [&](const DropLine& line, bool backwards, bool skipFirst) {
    out.drops += line.drops;
    out.proofs += line.proofs;
    out.unprovenMoves += line.unprovenMoves;
    out.eps = line.eps;
    const std::size_t n = line.vertices.size();
    for (std::size_t i = skipFirst ? 1 : 0; i < n; ++i) {
      const Vec3 c = line.vertices[backwards ? n - 1 - i : i].centre;
      if (!started) {
        pass.start = c;
        started = true;
      } else {
        pass.moves.push_back(ToolMove{MoveKind::line, c, {}, ArcPlane::xy, true});
      }
    }
  };
  for (std::size_t k = 0; k < lines; ++k) {
    const double b = offset(k);
    const bool backwards = k % 2 == 1;
    if (k > 0) {
      // The link across, at the end both lines share: from b_k-1 to b_k along e. Its first
      // vertex is the previous line's last (the same drop point), its last this line's first.
      const double t = backwards ? t1 : t0;
      const DropLine link =
          cutter.dropLine(Vec2{t * along.x, t * along.y}, across, offset(k - 1), b, drop);
      DropLine inner = link;
      if (!inner.vertices.empty()) inner.vertices.pop_back();
      append(inner, false, true);
    }
    const DropLine line = cutter.dropLine(Vec2{b * across.x, b * across.y}, along, t0, t1, drop);
    append(line, backwards, false);
  }
  Vec3 at = pass.start;
  for (const ToolMove& move : pass.moves) {
    out.centreLength += norm(move.end - at);
    at = move.end;
  }
  out.path.passes.push_back(std::move(pass));
  return out;
}

}  // namespace scallop
