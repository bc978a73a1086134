#include "scallop/paths/mesh_raster.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/job_control.hpp"

namespace scallop {

Mesh meshWithSkirt(const Mesh& mesh, double offset) {
  if (!(offset >= 0.0) || !std::isfinite(offset))
    throw Error(fmt::format("mesh skirt: the offset must be >= 0 and finite, got {}", offset));
  Mesh out = mesh;
  if (mesh.vertices.empty()) return out;
  double bottom = std::numeric_limits<double>::infinity();
  for (const Vec3& v : mesh.vertices) bottom = std::min(bottom, v.z);
  // Each edge's uses, and the far vertex of its (last) triangle: the side of the material.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<int, std::uint32_t>> uses;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (f % 4096 == 0) checkCancelled();
    const auto& t = mesh.triangles[f];
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t u = t[k], v = t[(k + 1) % 3];
      auto& use = uses[{std::min(u, v), std::max(u, v)}];
      ++use.first;
      use.second = t[(k + 2) % 3];
    }
  }
  const auto add = [&](Vec3 p) {
    out.vertices.push_back(p);
    return static_cast<std::uint32_t>(out.vertices.size() - 1);
  };
  for (const auto& [edge, use] : uses) {
    if (use.first != 1) continue;
    const Vec3 a = mesh.vertices[edge.first], b = mesh.vertices[edge.second], far = mesh.vertices[use.second];
    if (a.z <= bottom && b.z <= bottom) continue;  // on the bottom: no wall
    // Outwards in xy: perpendicular to the edge, away from its triangle.
    Vec3 away{a.y - b.y, b.x - a.x, 0.0};
    const double length = norm(away);
    away = length > 0.0 ? (1.0 / length) * away : Vec3{};
    if ((far.x - a.x) * away.x + (far.y - a.y) * away.y > 0.0) away = -away;
    const Vec3 shift = offset * away;
    const std::uint32_t ta = add(a + shift), tb = add(b + shift);
    const std::uint32_t fa = add({a.x + shift.x, a.y + shift.y, bottom}), fb = add({b.x + shift.x, b.y + shift.y, bottom});
    out.triangles.push_back({ta, tb, fb});
    out.triangles.push_back({ta, fb, fa});
  }
  return out;
}

double meshRasterSpacing(double toolRadius, double scallopHeight) {
  if (!(toolRadius > 0.0) || !std::isfinite(toolRadius) || !(scallopHeight > 0.0) || !(scallopHeight < toolRadius))
    throw Error(fmt::format("raster spacing: need 0 < H < R, got H = {} and R = {}", scallopHeight, toolRadius));
  return 2.0 * std::sqrt(2.0 * toolRadius * scallopHeight - scallopHeight * scallopHeight);
}

namespace {

// The cusp-adaptive line offsets of the contract: facets as intervals of the touching centres'
// across-coordinate with the step each allows, in buckets of the constant spacing's width.
std::vector<double> adaptiveOffsets(const Mesh& mesh, double radius, Vec2 along, Vec2 across, double b0, double b1,
                                    const MeshRasterOptions& options, std::size_t& floorSteps) {
  const double height = options.scallopHeight;
  if (!(height < radius))
    throw Error(fmt::format("mesh raster: the scallop height {} must be smaller than the tool radius {}", height, radius));
  const double widest = 2.0 * std::sqrt(2.0 * radius * height - height * height);  // w_H
  const double most = options.spacing, least = options.spacing / 32.0;
  struct Band {
    double lo, hi, step;
  };
  // Unit upward normals and centroids, and each edge's facets, for the concave bend.
  const std::size_t facets = mesh.triangles.size();
  std::vector<Vec3> normals(facets), centroids(facets);
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::size_t>> edgeFacets;
  for (std::size_t f = 0; f < facets; ++f) {
    if (f % 4096 == 0) checkCancelled();
    const auto& t = mesh.triangles[f];
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    Vec3 n = cross(b - a, c - a);
    const double length = norm(n);
    normals[f] = length > 0.0 ? (n.z < 0.0 ? -1.0 : 1.0) / length * n : Vec3{};
    centroids[f] = (1.0 / 3.0) * (a + b + c);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = t[static_cast<std::size_t>(k)], v = t[static_cast<std::size_t>((k + 1) % 3)];
      edgeFacets[{std::min(u, v), std::max(u, v)}].push_back(f);
    }
  }
  // The largest concave bend at each facet: across an edge to a neighbour whose far vertex
  // stands above the facet's plane, the angle between their normals over their centroids'
  // distance (a curvature estimate, in any direction: conservative across the feed).
  std::vector<double> concave(facets, 0.0);
  std::size_t edges = 0;
  for (const auto& [edge, list] : edgeFacets) {
    if (++edges % 4096 == 0) checkCancelled();
    for (const std::size_t f : list) {
      for (const std::size_t g : list) {
        if (f == g || normals[f].z <= 0.0 || normals[g].z <= 0.0) continue;
        const auto& t = mesh.triangles[g];
        Vec3 far = mesh.vertices[t[0]];
        for (const std::uint32_t w : t)
          if (w != edge.first && w != edge.second) far = mesh.vertices[w];
        if (dot(far - mesh.vertices[edge.first], normals[f]) <= 0.0) continue;  // convex or flat
        const double distance = norm(centroids[g] - centroids[f]);
        const double angle = std::acos(std::clamp(dot(normals[f], normals[g]), -1.0, 1.0));
        if (distance > 0.0) concave[f] = std::max(concave[f], angle / distance);
      }
    }
  }
  std::vector<Band> bands;
  for (std::size_t f = 0; f < facets; ++f) {
    if (f % 4096 == 0) checkCancelled();
    const Vec3 n = normals[f];
    if (!(n.z > 0.0)) continue;  // vertical or degenerate: touches through its edges only
    const auto& t = mesh.triangles[f];
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const double nh = n.x * along.x + n.y * along.y, ne = n.x * across.x + n.y * across.y;
    const double sh = -nh / n.z, se = -ne / n.z;
    // On a surface bending concavely with curvature k (radius 1 / k > R) balls whose
    // centres are w apart leave w^2 / (8 R (1 - R k)): the step shrinks by sqrt(1 - R k),
    // held at 1/4 where the bend is tighter (a crease the ball cannot enter).
    const double bend = std::max(0.25, std::sqrt(std::max(0.0, 1.0 - radius * concave[f])));
    const double step = bend * widest * std::sqrt(1.0 + sh * sh) / std::sqrt(1.0 + se * se + sh * sh);
    if (step >= most) continue;  // allows the constant spacing: no constraint
    const auto e = [&](Vec3 p) { return p.x * across.x + p.y * across.y + radius * ne; };
    bands.push_back({std::min({e(a), e(b), e(c)}), std::max({e(a), e(b), e(c)}), step});
  }
  // Buckets of width `most` over [b0 - R, b1 + R]: a window [b, b + most] meets at most two.
  const double origin = b0 - radius;
  const auto bucketOf = [&](double x) {
    return static_cast<std::size_t>(std::max(0.0, std::floor((x - origin) / most)));
  };
  const std::size_t count = bucketOf(b1 + radius) + 2;
  if (!(static_cast<double>(count) <= 4.0 * static_cast<double>(options.maxLines)))
    throw Error(fmt::format("mesh raster: a spacing of {} across {} exceeds the budget of {} lines", most, b1 - b0,
                            options.maxLines));
  std::vector<std::vector<std::size_t>> buckets(count);
  for (std::size_t k = 0; k < bands.size(); ++k)
    for (std::size_t i = bucketOf(bands[k].lo); i <= std::min(count - 1, bucketOf(bands[k].hi)); ++i) buckets[i].push_back(k);
  std::vector<double> offsets{b0};
  floorSteps = 0;
  for (double at = b0; at < b1;) {
    checkCancelled();
    double step = most;
    for (std::size_t i = bucketOf(at); i <= std::min(count - 1, bucketOf(at + most)); ++i)
      for (const std::size_t k : buckets[i])
        if (bands[k].hi >= at && bands[k].lo <= at + most) step = std::min(step, bands[k].step);
    if (step < least) {
      step = least;
      ++floorSteps;
    }
    at = at + step >= b1 ? b1 : at + step;
    offsets.push_back(at);
    if (offsets.size() > options.maxLines)
      throw Error(fmt::format("mesh raster: the scallop height {} needs more than {} lines across {}", height,
                              options.maxLines, b1 - b0));
  }
  if (offsets.size() > 1 && offsets[offsets.size() - 2] == b1) offsets.pop_back();
  return offsets;
}

}  // namespace

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
  // The lines run from R + R/64 before the mesh to as far beyond: their ends and the links
  // between them touch nothing (a ball exactly R beside the mesh's extreme vertex would graze
  // the vertical line through it at its equator, below the part's edge: no cut, but a z-map
  // reads one there).
  const double margin = radius / 64.0;
  const double t0 = a0 - radius - margin, t1 = a1 + radius + margin;
  if (!(options.scallopHeight >= 0.0) || !std::isfinite(options.scallopHeight))
    throw Error(fmt::format("mesh raster: the scallop height must be >= 0 and finite, got {}", options.scallopHeight));
  MeshRasterPaths out;
  const std::vector<double> offsets = [&] {
    // Beyond the extreme lines by R: a point near the mesh's extreme whose surface slopes
    // towards it is finished by a ball beyond it (at q + R n).
    const double lo = b0 - radius + margin, hi = b1 + radius - margin;
    if (options.scallopHeight > 0.0) return adaptiveOffsets(mesh, radius, along, across, lo, hi, options, out.floorSteps);
    const double steps = std::ceil((hi - lo) / options.spacing);
    if (!(steps + 1.0 <= static_cast<double>(options.maxLines)))
      throw Error(fmt::format("mesh raster: a spacing of {} needs {:.0f} lines across {}, more than the budget of {}",
                              options.spacing, steps + 1.0, hi - lo, options.maxLines));
    std::vector<double> b;
    for (std::size_t k = 0; k < static_cast<std::size_t>(steps); ++k) b.push_back(lo + static_cast<double>(k) * options.spacing);
    b.push_back(hi);
    return b;
  }();
  DropLineOptions drop;
  drop.eps = options.eps;
  drop.sagTolerance = options.sagTolerance;
  drop.floor = options.floor;
  out.path.units = mesh.units;
  out.path.toolRadius = radius;
  // Every drop line's counts, the lines left out and the links included.
  const auto tally = [&](const DropLine& line) {
    out.drops += line.drops;
    out.proofs += line.proofs;
    out.unprovenMoves += line.unprovenMoves;
    out.eps = line.eps;
  };
  ToolPass pass;
  pass.retractBefore = true;
  bool started = false;
  const auto append = [&](const DropLine& line, bool backwards, bool skipFirst) {
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
  // Every line's drop line; those that touch nothing (beyond the mesh by R) are left out.
  std::vector<DropLine> dropLines;
  std::vector<double> kept;
  // Progress (job_control.hpp): the lines take about three quarters of the work, the links
  // the rest.
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    advanceStage(3 * k, 4 * offsets.size());
    const double b = offsets[k];
    DropLine line = cutter.dropLine(Vec2{b * across.x, b * across.y}, along, t0, t1, drop);
    tally(line);
    const bool touches = std::any_of(line.vertices.begin(), line.vertices.end(), [](const DropLineVertex& v) {
      return v.contact.feature != MeshFeature::none;
    });
    if (!touches) continue;
    dropLines.push_back(std::move(line));
    kept.push_back(b);
  }
  const std::size_t lines = kept.size();
  // Every line crosses the mesh's extent: one that touches it exists unless the cutter was
  // built from another mesh.
  if (lines == 0) throw Error("mesh raster: no line touches the mesh (is the cutter built from it?)");
  out.lines = lines;
  out.lineOffsets = kept;
  out.minSpacing = lines > 2 ? std::numeric_limits<double>::infinity() : (lines == 2 ? kept[1] - kept[0] : 0.0);
  for (std::size_t k = 0; k + 2 < lines; ++k) out.minSpacing = std::min(out.minSpacing, kept[k + 1] - kept[k]);
  for (std::size_t k = 0; k < lines; ++k) {
    advanceStage(3 * lines + k, 4 * lines);
    const bool backwards = k % 2 == 1;
    if (k > 0) {
      // The link across, at the end both lines share: from b_k-1 to b_k along e. Its first
      // vertex is the previous line's last (the same drop point), its last this line's first.
      const double t = backwards ? t1 : t0;
      DropLine link = cutter.dropLine(Vec2{t * along.x, t * along.y}, across, kept[k - 1], kept[k], drop);
      tally(link);
      if (!link.vertices.empty()) link.vertices.pop_back();
      append(link, false, true);
    }
    append(dropLines[k], backwards, false);
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
