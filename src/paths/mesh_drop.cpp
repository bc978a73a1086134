// Exact ball drop-cutter and clearance on triangle meshes: see mesh_drop.hpp's contract.

#include "scallop/paths/mesh_drop.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/geometry/tolerances.hpp"
#include "scallop/job_control.hpp"

namespace scallop {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double maxAbs(Vec3 p) { return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}); }
bool finite(Vec3 p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// The distance from p to the closed triangle: to its plane when the foot falls inside (the
// three edge orientations agree with the normal), else to the nearest edge (the closest
// point of a convex polygon to an outside point lies on its boundary).
double pointTriangleDistance(Vec3 p, const std::array<Vec3, 3>& t, Vec3 n) {
  if (n.x != 0.0 || n.y != 0.0 || n.z != 0.0) {
    const double h = dot(n, p - t[0]);
    const Vec3 foot = p - h * n;
    if (dot(cross(t[1] - t[0], foot - t[0]), n) >= 0.0 &&
        dot(cross(t[2] - t[1], foot - t[1]), n) >= 0.0 &&
        dot(cross(t[0] - t[2], foot - t[2]), n) >= 0.0)
      return std::fabs(h);
  }
  return std::min({distanceToSegment(p, t[0], t[1]), distanceToSegment(p, t[1], t[2]),
                   distanceToSegment(p, t[2], t[0])});
}

// The distance between segments [p1, q1] and [p2, q2] (Ericson, Real-Time Collision
// Detection, 5.1.9): minimise |p1 + s d1 - p2 - t d2|^2 over the square; the unconstrained s
// of the normal equations clamped, t optimal for it, then s again for a clamped t. Always the
// distance of two points of the segments (never below the true one but by rounding); where
// they are nearly parallel the distance varies little along them, so an inaccurate s costs
// second order.
double segmentSegmentDistance(Vec3 p1, Vec3 q1, Vec3 p2, Vec3 q2) {
  const Vec3 d1 = q1 - p1;
  const Vec3 d2 = q2 - p2;
  const Vec3 r = p1 - p2;
  const double a = dot(d1, d1);
  const double e = dot(d2, d2);
  const double f = dot(d2, r);
  double s = 0.0;
  double t = 0.0;
  if (a == 0.0 && e == 0.0) return norm(r);
  if (a == 0.0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(d1, r);
    if (e == 0.0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(d1, d2);
      const double denom = a * e - b * b;
      s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return norm((p1 + s * d1) - (p2 + t * d2));
}

// The distance from [a, b] to the triangle: 0 when the segment crosses its interior (end
// points strictly on both sides of the plane, the crossing inside), else the smallest of the
// end points' distances and the distances to the three edges (the closest pair of two
// disjoint convex sets, one a segment: either a segment end is involved, or the triangle's
// point is on its boundary, or the segment is parallel to the plane and sliding it reaches
// one of those).
double segmentTriangleDistance(Vec3 a, Vec3 b, const std::array<Vec3, 3>& t, Vec3 n) {
  if (n.x != 0.0 || n.y != 0.0 || n.z != 0.0) {
    const double da = dot(n, a - t[0]);
    const double db = dot(n, b - t[0]);
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
      const Vec3 x = a + (da / (da - db)) * (b - a);
      if (dot(cross(t[1] - t[0], x - t[0]), n) >= 0.0 &&
          dot(cross(t[2] - t[1], x - t[1]), n) >= 0.0 &&
          dot(cross(t[0] - t[2], x - t[2]), n) >= 0.0)
        return 0.0;
    }
  }
  double d = std::min(pointTriangleDistance(a, t, n), pointTriangleDistance(b, t, n));
  for (int i = 0; i < 3; ++i) d = std::min(d, segmentSegmentDistance(a, b, t[i], t[(i + 1) % 3]));
  return d;
}

// Lower bound of the distance between two boxes (0 when they overlap).
double boxDistance(Vec3 lo1, Vec3 hi1, Vec3 lo2, Vec3 hi2) {
  const double dx = std::max({0.0, lo1.x - hi2.x, lo2.x - hi1.x});
  const double dy = std::max({0.0, lo1.y - hi2.y, lo2.y - hi1.y});
  const double dz = std::max({0.0, lo1.z - hi2.z, lo2.z - hi1.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

std::string pointText(double x, double y) { return fmt::format("({}, {})", x, y); }

}  // namespace

MeshDropCutter::MeshDropCutter(const Mesh& mesh, double radius, const MeshDropOptions& options)
    : radius_(radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw Error(fmt::format("mesh drop-cutter: the ball radius must be positive and finite, not {}",
                            radius));
  if (mesh.triangles.empty()) throw Error("mesh drop-cutter: the mesh has no triangle");
  if (!(options.cellSize >= 0.0) || !std::isfinite(options.cellSize))
    throw Error(fmt::format("mesh drop-cutter: the cell size must be positive (0: automatic), not {}",
                            options.cellSize));
  if (mesh.vertices.size() > std::numeric_limits<std::uint32_t>::max() ||
      mesh.triangles.size() > std::numeric_limits<std::uint32_t>::max() / 3)
    throw Error("mesh drop-cutter: more than 2^32 vertices or 2^32 / 3 triangles");
  const std::size_t nv = mesh.vertices.size();
  std::vector<char> used(nv, 0);
  std::vector<std::uint32_t> vertexTriangle(nv, 0);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = mesh.triangles[t][k];
      if (i >= nv)
        throw Error(fmt::format("mesh drop-cutter: triangle {} names vertex {}, but the mesh has {}",
                                t, i, nv));
      const Vec3 p = mesh.vertices[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error(fmt::format("mesh drop-cutter: vertex {} of triangle {} is not finite: ({}, {}, {})",
                                i, t, p.x, p.y, p.z));
      if (!used[i]) vertexTriangle[i] = static_cast<std::uint32_t>(t);
      used[i] = 1;
    }

  Vec3 lo{kInf, kInf, kInf};
  Vec3 hi{-kInf, -kInf, -kInf};
  for (std::size_t i = 0; i < nv; ++i) {
    if (!used[i]) continue;
    const Vec3 p = mesh.vertices[i];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    maxAbs_ = std::max(maxAbs_, maxAbs(p));
    vertices_.push_back({p, static_cast<std::uint32_t>(i), vertexTriangle[i]});
  }
  size_ = norm(hi - lo);
  minZ_ = lo.z;
  maxZ_ = hi.z;

  // Facets. A facet's normal is turned up (n_z >= 0) and its projection made
  // counter-clockwise; both follow from one swap, since n_z is the projection's signed area
  // over the triangle's.
  double extentSum = 0.0;
  facets_.reserve(mesh.triangles.size());
  for (const auto& tri : mesh.triangles) {
    Facet f;
    f.p = {mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]};
    Vec3 n = cross(f.p[1] - f.p[0], f.p[2] - f.p[0]);
    const double length = norm(n);
    if (length > 0.0 && std::isfinite(length)) {
      n = n / length;
      if (n.z < 0.0) {
        std::swap(f.p[1], f.p[2]);
        n = -n;
      }
      f.normal = n;
      f.offset = {radius * n.x, radius * n.y};
      f.rnz = radius * n.z;
    }
    for (int k = 0; k < 3; ++k) {
      f.xy[k] = {f.p[k].x, f.p[k].y};
      f.z[k] = f.p[k].z;
    }
    f.lo = {std::min({f.p[0].x, f.p[1].x, f.p[2].x}), std::min({f.p[0].y, f.p[1].y, f.p[2].y}),
            std::min({f.p[0].z, f.p[1].z, f.p[2].z})};
    f.hi = {std::max({f.p[0].x, f.p[1].x, f.p[2].x}), std::max({f.p[0].y, f.p[1].y, f.p[2].y}),
            std::max({f.p[0].z, f.p[1].z, f.p[2].z})};
    extentSum += std::max(f.hi.x - f.lo.x, f.hi.y - f.lo.y);
    facets_.push_back(f);
  }

  // Distinct edges, each kept with the first triangle that has it (sorted: deterministic).
  std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>> keys;
  keys.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = mesh.triangles[t][k];
      const std::uint32_t j = mesh.triangles[t][(k + 1) % 3];
      if (i != j) keys.emplace_back(std::min(i, j), std::max(i, j), static_cast<std::uint32_t>(t));
    }
  std::sort(keys.begin(), keys.end());
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const auto [i, j, t] = keys[k];
    if (k > 0 && std::get<0>(keys[k - 1]) == i && std::get<1>(keys[k - 1]) == j) continue;
    const Vec3 p = mesh.vertices[i];
    const Vec3 q = mesh.vertices[j];
    const Vec2 d{q.x - p.x, q.y - p.y};
    const double l = norm(d);
    if (!(l > 0.0)) continue;  // vertical: it touches through its end points only
    const double rise = q.z - p.z;
    const double length3 = std::hypot(l, rise);
    Edge e;
    e.p0 = p;
    e.dir = d * (1.0 / l);
    e.length = l;
    e.tanTheta = rise / l;
    e.secTheta = length3 / l;
    e.sinTheta = rise / length3;
    e.top = std::max(p.z, q.z);
    e.lox = std::min(p.x, q.x);
    e.hix = std::max(p.x, q.x);
    e.loy = std::min(p.y, q.y);
    e.hiy = std::max(p.y, q.y);
    e.a = i;
    e.b = j;
    e.triangle = t;
    edges_.push_back(e);
  }

  // The grid: cells of side h from the mesh's lowest x and y. Automatic h: a triangle then
  // spans about four cells and a drop visits at most (2R / h + 2)^2 <= 36 of them.
  x0_ = lo.x;
  y0_ = lo.y;
  double h = options.cellSize;
  if (h == 0.0) {
    h = std::max(extentSum / static_cast<double>(facets_.size()), radius / 2.0);
    const double budget = 4.0 * static_cast<double>(facets_.size()) + 16.0;
    while (((hi.x - lo.x) / h + 1.0) * ((hi.y - lo.y) / h + 1.0) > budget) h *= 1.5;
  }
  cell_ = h;
  const double cellsX = std::floor((hi.x - lo.x) / h) + 1.0;
  const double cellsY = std::floor((hi.y - lo.y) / h) + 1.0;
  if (cellsX * cellsY > 1e8)
    throw Error(fmt::format("mesh drop-cutter: a cell size of {} makes {} x {} cells (at most 1e8)",
                            h, cellsX, cellsY));
  nx_ = static_cast<std::int32_t>(cellsX);
  ny_ = static_cast<std::int32_t>(cellsY);
  const std::size_t cellCount = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);

  for (Facet& f : facets_) {
    f.cx = cellX(f.lo.x);
    f.cy = cellY(f.lo.y);
  }
  for (Edge& e : edges_) {
    e.cx = cellX(e.lox);
    e.cy = cellY(e.loy);
  }
  // Counting sort of the features into the cells (compressed rows).
  std::vector<std::uint32_t> facetCount(cellCount + 1, 0), edgeCount(cellCount + 1, 0),
      vertexCount(cellCount + 1, 0);
  const auto forCells = [&](double xa, double ya, double xb, double yb, auto&& visit) {
    for (std::int32_t cy = cellY(ya); cy <= cellY(yb); ++cy)
      for (std::int32_t cx = cellX(xa); cx <= cellX(xb); ++cx)
        visit(static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(cx));
  };
  for (const Facet& f : facets_) forCells(f.lo.x, f.lo.y, f.hi.x, f.hi.y, [&](std::size_t c) { ++facetCount[c]; });
  for (const Edge& e : edges_) forCells(e.lox, e.loy, e.hix, e.hiy, [&](std::size_t c) { ++edgeCount[c]; });
  for (const Vertex& v : vertices_) forCells(v.p.x, v.p.y, v.p.x, v.p.y, [&](std::size_t c) { ++vertexCount[c]; });
  cells_.resize(cellCount + 1);
  std::uint32_t fs = 0, es = 0, vs = 0;
  for (std::size_t c = 0; c <= cellCount; ++c) {
    cells_[c] = {fs, es, vs};
    fs += facetCount[c];
    es += edgeCount[c];
    vs += vertexCount[c];
  }
  cellFacets_.resize(fs);
  cellEdges_.resize(es);
  cellVertices_.resize(vs);
  std::vector<Cell> fill(cells_.begin(), cells_.end());
  for (std::size_t i = 0; i < facets_.size(); ++i) {
    const Facet& f = facets_[i];
    forCells(f.lo.x, f.lo.y, f.hi.x, f.hi.y,
             [&](std::size_t c) { cellFacets_[fill[c].facetBegin++] = static_cast<std::uint32_t>(i); });
  }
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    const Edge& e = edges_[i];
    forCells(e.lox, e.loy, e.hix, e.hiy,
             [&](std::size_t c) { cellEdges_[fill[c].edgeBegin++] = static_cast<std::uint32_t>(i); });
  }
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vertex& v = vertices_[i];
    forCells(v.p.x, v.p.y, v.p.x, v.p.y,
             [&](std::size_t c) { cellVertices_[fill[c].vertexBegin++] = static_cast<std::uint32_t>(i); });
  }
  cellTop_.assign(cellCount, -kInf);
  for (std::size_t c = 0; c < cellCount; ++c) {
    double top = -kInf;
    for (std::uint32_t k = cells_[c].facetBegin; k < cells_[c + 1].facetBegin; ++k)
      top = std::max(top, facets_[cellFacets_[k]].hi.z);
    for (std::uint32_t k = cells_[c].edgeBegin; k < cells_[c + 1].edgeBegin; ++k)
      top = std::max(top, edges_[cellEdges_[k]].top);
    for (std::uint32_t k = cells_[c].vertexBegin; k < cells_[c + 1].vertexBegin; ++k)
      top = std::max(top, vertices_[cellVertices_[k]].p.z);
    cellTop_[c] = top;
  }
}

// Cell coordinates, clamped to the grid: monotone in x, so a feature's box and a query's box
// that overlap share the cell of the lower-left corner of their intersection, which is
// (max(feature's lowest cell, query's lowest cell)) in each axis: the one cell in which a
// query handles the feature.
std::int32_t MeshDropCutter::cellX(double x) const {
  const double c = std::floor((x - x0_) / cell_);
  return c <= 0.0 ? 0 : c >= static_cast<double>(nx_ - 1) ? nx_ - 1 : static_cast<std::int32_t>(c);
}
std::int32_t MeshDropCutter::cellY(double y) const {
  const double c = std::floor((y - y0_) / cell_);
  return c <= 0.0 ? 0 : c >= static_cast<double>(ny_ - 1) ? ny_ - 1 : static_cast<std::int32_t>(c);
}

// The rounding allowance of a distance computed from coordinates up to S: a few tens of
// operations each within u of the running magnitude (S + R).
double MeshDropCutter::allowance(Vec3 a, Vec3 b) const {
  return 64.0 * kUnitRoundoff * (std::max({maxAbs_, maxAbs(a), maxAbs(b)}) + radius_);
}

MeshContact MeshDropCutter::drop(double x, double y) const {
  if (!std::isfinite(x) || !std::isfinite(y))
    throw Error("mesh drop-cutter: the drop point " + pointText(x, y) + " is not finite");
  const double r = radius_;
  const double r2 = r * r;
  const Vec2 p{x, y};
  const double qx0 = x - r, qx1 = x + r, qy0 = y - r, qy1 = y + r;
  const std::int32_t cx0 = cellX(qx0), cx1 = cellX(qx1), cy0 = cellY(qy0), cy1 = cellY(qy1);
  // The cells highest first (ties by index: deterministic), so that the best height found
  // early stops the visit: a feature can hold the ball at most R above its highest point, and
  // a feature is listed in the cell where it is handled, whose top is at least its own.
  struct Visit {
    double top;
    std::int32_t cx, cy;
    std::size_t c;
  };
  constexpr std::size_t kMaxSorted = 64;
  std::array<Visit, kMaxSorted> sorted;
  std::vector<Visit> many;
  const std::size_t count = static_cast<std::size_t>(cx1 - cx0 + 1) * static_cast<std::size_t>(cy1 - cy0 + 1);
  Visit* visits = sorted.data();
  if (count > kMaxSorted) {
    many.resize(count);
    visits = many.data();
  }
  std::size_t n = 0;
  for (std::int32_t cy = cy0; cy <= cy1; ++cy)
    for (std::int32_t cx = cx0; cx <= cx1; ++cx) {
      const std::size_t c = static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(cx);
      if (cellTop_[c] > -kInf) visits[n++] = {cellTop_[c], cx, cy, c};
    }
  std::sort(visits, visits + n, [](const Visit& a, const Visit& b) {
    return a.top > b.top || (a.top == b.top && a.c < b.c);
  });
  MeshContact best;
  for (std::size_t j = 0; j < n; ++j) {
    if (visits[j].top + r <= best.z) break;
    const std::int32_t cx = visits[j].cx, cy = visits[j].cy;
    const std::size_t c = visits[j].c;
    {
      for (std::uint32_t k = cells_[c].facetBegin; k < cells_[c + 1].facetBegin; ++k) {
        const std::uint32_t i = cellFacets_[k];
        const Facet& f = facets_[i];
        if (f.rnz <= 0.0 || f.lo.x > qx1 || f.hi.x < qx0 || f.lo.y > qy1 || f.hi.y < qy0) continue;
        if (f.hi.z + r <= best.z) continue;
        if (cx != std::max(f.cx, cx0) || cy != std::max(f.cy, cy0)) continue;
        // The contact c = C - R n is known in xy before the height: c_xy = p - R n_xy. Its
        // barycentric weights (edge functions over their sum) interpolate the vertex heights.
        const Vec2 contact = p - f.offset;
        const double e0 = cross(f.xy[1] - f.xy[0], contact - f.xy[0]);
        const double e1 = cross(f.xy[2] - f.xy[1], contact - f.xy[1]);
        const double e2 = cross(f.xy[0] - f.xy[2], contact - f.xy[2]);
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) continue;
        const double sum = e0 + e1 + e2;
        if (!(sum > 0.0)) continue;
        const double z = (e1 * f.z[0] + e2 * f.z[1] + e0 * f.z[2]) / sum + f.rnz;
        if (z > best.z) best = {z, MeshFeature::facet, i, {}};
      }
      for (std::uint32_t k = cells_[c].edgeBegin; k < cells_[c + 1].edgeBegin; ++k) {
        const Edge& e = edges_[cellEdges_[k]];
        if (e.lox > qx1 || e.hix < qx0 || e.loy > qy1 || e.hiy < qy0) continue;
        if (e.top + r <= best.z) continue;
        if (cx != std::max(e.cx, cx0) || cy != std::max(e.cy, cy0)) continue;
        const Vec2 w{x - e.p0.x, y - e.p0.y};
        const double t = dot(w, e.dir);
        const double d = std::fabs(cross(e.dir, w));
        if (d > r) continue;
        // The section circle's radius sqrt(R^2 - d^2), as (R - d)(R + d) against
        // cancellation; the foot of the perpendicular from the centre at t + r sin(theta).
        const double rs = std::sqrt((r - d) * (r + d));
        const double foot = t + rs * e.sinTheta;
        if (foot < 0.0 || foot > e.length) continue;
        const double z = e.p0.z + t * e.tanTheta + rs * e.secTheta;
        if (z > best.z) best = {z, MeshFeature::edge, e.triangle, {e.a, e.b}};
      }
      for (std::uint32_t k = cells_[c].vertexBegin; k < cells_[c + 1].vertexBegin; ++k) {
        const Vertex& v = vertices_[cellVertices_[k]];
        const double dx = v.p.x - x;
        const double dy = v.p.y - y;
        const double d2 = dx * dx + dy * dy;
        if (d2 > r2) continue;
        const double z = v.p.z + std::sqrt(r2 - d2);
        if (z > best.z) best = {z, MeshFeature::vertex, v.triangle, {v.index, v.index}};
      }
    }
  }
  return best;
}

double MeshDropCutter::segmentDistance(Vec3 a, Vec3 b, double cutoff) const {
  if (!finite(a) || !finite(b))
    throw Error(fmt::format("mesh segment distance: the segment ({}, {}, {}) - ({}, {}, {}) is not finite",
                            a.x, a.y, a.z, b.x, b.y, b.z));
  if (!(cutoff >= 0.0))
    throw Error(fmt::format("mesh segment distance: the cutoff must be >= 0, not {}", cutoff));
  const Vec3 slo{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
  const Vec3 shi{std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
  const bool all = !std::isfinite(cutoff);
  const std::int32_t cx0 = all ? 0 : cellX(slo.x - cutoff), cx1 = all ? nx_ - 1 : cellX(shi.x + cutoff);
  const std::int32_t cy0 = all ? 0 : cellY(slo.y - cutoff), cy1 = all ? ny_ - 1 : cellY(shi.y + cutoff);
  double best = cutoff;
  for (std::int32_t cy = cy0; cy <= cy1; ++cy)
    for (std::int32_t cx = cx0; cx <= cx1; ++cx) {
      const std::size_t c = static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(cx);
      for (std::uint32_t k = cells_[c].facetBegin; k < cells_[c + 1].facetBegin; ++k) {
        const Facet& f = facets_[cellFacets_[k]];
        // A box nearer than best (<= cutoff) overlaps the query's box in xy.
        if (boxDistance(slo, shi, f.lo, f.hi) >= best) continue;
        if (cx != std::max(f.cx, cx0) || cy != std::max(f.cy, cy0)) continue;
        best = std::min(best, segmentTriangleDistance(a, b, f.p, f.normal));
      }
    }
  return best;
}

bool MeshDropCutter::segmentClear(Vec3 a, Vec3 b, double clearance) const {
  if (!finite(a) || !finite(b))
    throw Error(fmt::format("mesh segment clearance: the segment ({}, {}, {}) - ({}, {}, {}) is not finite",
                            a.x, a.y, a.z, b.x, b.y, b.z));
  if (!std::isfinite(clearance))
    throw Error(fmt::format("mesh segment clearance: the clearance must be finite, not {}", clearance));
  const double need = clearance + allowance(a, b);
  if (need <= 0.0) return true;
  const Vec3 slo{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
  const Vec3 shi{std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
  const std::int32_t cx0 = cellX(slo.x - need), cx1 = cellX(shi.x + need);
  const std::int32_t cy0 = cellY(slo.y - need), cy1 = cellY(shi.y + need);
  for (std::int32_t cy = cy0; cy <= cy1; ++cy)
    for (std::int32_t cx = cx0; cx <= cx1; ++cx) {
      const std::size_t c = static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(cx);
      for (std::uint32_t k = cells_[c].facetBegin; k < cells_[c + 1].facetBegin; ++k) {
        const Facet& f = facets_[cellFacets_[k]];
        if (boxDistance(slo, shi, f.lo, f.hi) >= need) continue;
        if (cx != std::max(f.cx, cx0) || cy != std::max(f.cy, cy0)) continue;
        if (segmentTriangleDistance(a, b, f.p, f.normal) < need) return false;
      }
    }
  return true;
}

namespace {

struct LineContext {
  const MeshDropCutter* cutter = nullptr;
  Vec2 origin, direction;
  double floor = 0.0, clearance = 0.0, sag = 0.0;
  std::size_t maxVertices = 0;
  DropLine* out = nullptr;

  DropLineVertex at(double t) {
    DropLineVertex v;
    v.t = t;
    const Vec2 xy = origin + t * direction;
    v.contact = cutter->drop(xy.x, xy.y);
    ++out->drops;
    v.centre = {xy.x, xy.y, std::max(v.contact.z, floor)};
    return v;
  }

  void push(const DropLineVertex& v) {
    if (out->vertices.size() >= maxVertices)
      throw Error(fmt::format("mesh drop line: more than {} vertices (a tolerance too fine for the "
                              "line, or a budget too small)", maxVertices));
    out->vertices.push_back(v);
  }

  // Appends the move a -> b (a already out), halved until proven and within the sag check.
  // `mid`, when known, is the drop at b's and a's midpoint 0.5 (a.t + b.t) (the parent's
  // quarter point: each halving then costs two new drops, not three).
  void refine(const DropLineVertex& a, const DropLineVertex& b, int depth,
              const std::optional<DropLineVertex>& mid = std::nullopt) {
    const double tm = 0.5 * (a.t + b.t);
    const bool splittable = tm > a.t && tm < b.t && depth < kMeshMaxHalvings;
    if (!splittable) {
      ++out->proofs;
      if (!cutter->segmentClear(a.centre, b.centre, clearance)) ++out->unprovenMoves;
      push(b);
      return;
    }
    // The sag check first, at the quarter points and the midpoint (the halving reuses all
    // three): drops are cheaper than a proof. Three points, not one: next to a steep stretch
    // the envelope's largest sag above a chord sits off its middle (over an arc
    // z = sqrt(2 R s) from a silhouette, at a quarter of the chord).
    const DropLineVertex m = mid ? *mid : at(tm);
    const auto sagAt = [&](const DropLineVertex& v, double f) {
      return v.centre.z >= a.centre.z + f * (b.centre.z - a.centre.z) - sag;
    };
    std::optional<DropLineVertex> q1, q3;  // at the quarter points, as the halves' midpoints
    const auto quarter1 = [&]() -> const DropLineVertex& {
      if (!q1) q1 = at(0.5 * (a.t + m.t));
      return *q1;
    };
    const auto quarter3 = [&]() -> const DropLineVertex& {
      if (!q3) q3 = at(0.5 * (m.t + b.t));
      return *q3;
    };
    if (sagAt(m, 0.5) && sagAt(quarter1(), 0.25) && sagAt(quarter3(), 0.75)) {
      ++out->proofs;
      if (cutter->segmentClear(a.centre, b.centre, clearance)) {
        push(b);
        return;
      }
    }
    refine(a, m, depth + 1, q1);
    refine(m, b, depth + 1, q3);
  }
};

}  // namespace

DropLine MeshDropCutter::dropLine(Vec2 origin, Vec2 direction, double t0, double t1,
                                  const DropLineOptions& options) const {
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y))
    throw Error("mesh drop line: the origin " + pointText(origin.x, origin.y) + " is not finite");
  if (!(std::fabs(norm(direction) - 1.0) <= 1e-12))
    throw Error("mesh drop line: the direction " + pointText(direction.x, direction.y) +
                " is not a unit vector");
  if (!std::isfinite(t0) || !std::isfinite(t1) || t0 > t1)
    throw Error(fmt::format("mesh drop line: the interval [{}, {}] is not finite and ordered", t0, t1));
  DropLine out;
  const double step = options.step == 0.0 ? radius_ / 4.0 : options.step;
  out.eps = options.eps == 0.0 ? 1e-6 * size_ : options.eps;
  out.sagTolerance = options.sagTolerance == 0.0 ? out.eps : options.sagTolerance;
  if (!(step > 0.0) || !std::isfinite(step))
    throw Error(fmt::format("mesh drop line: the step must be positive and finite, not {}", step));
  if (!(out.eps > 0.0) || !std::isfinite(out.eps))
    throw Error(fmt::format("mesh drop line: eps must be positive and finite, not {}", out.eps));
  if (!(out.sagTolerance > 0.0))
    throw Error(fmt::format("mesh drop line: the sag tolerance must be positive, not {}",
                            out.sagTolerance));
  const double floor = std::isnan(options.floor) ? minZ_ + radius_ : options.floor;
  if (!std::isfinite(floor))
    throw Error(fmt::format("mesh drop line: the floor must be finite, not {}", floor));
  const double stations = std::max(1.0, std::ceil((t1 - t0) / step));
  if (!(stations < static_cast<double>(options.maxVertices)))
    throw Error(fmt::format("mesh drop line: {} stations exceed the budget of {} vertices",
                            stations, options.maxVertices));
  LineContext line{this, origin, direction, floor, radius_ - out.eps, out.sagTolerance,
                   options.maxVertices, &out};
  const std::size_t n = static_cast<std::size_t>(stations);
  DropLineVertex a = line.at(t0);
  line.push(a);
  for (std::size_t i = 1; i <= n; ++i) {
    checkCancelled();  // a station's drops and proofs: a plan's cancel stops it here
    const double t = i == n ? t1 : t0 + (t1 - t0) * (static_cast<double>(i) / static_cast<double>(n));
    const DropLineVertex b = line.at(t);
    line.refine(a, b, 0);
    a = b;
  }
  return out;
}

}  // namespace scallop
