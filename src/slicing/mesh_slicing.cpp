#include "scallop/slicing/mesh_slicing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

extern "C" {
#include <libqhull_r/libqhull_r.h>
}

#include "scallop/error.hpp"

namespace scallop {
namespace {

// The angle between unit vectors a and +-b, in [0, pi/2]: atan2 keeps it accurate near 0 and
// near pi/2 alike.
double angleToLine(const Vec3& a, const Vec3& b) { return std::atan2(norm(cross(a, b)), std::abs(dot(a, b))); }

// One representative of +-n: z > 0, or z = 0 and y > 0, or z = y = 0 and x > 0.
Vec3 canonical(Vec3 n) {
  if (n.z < 0.0 || (n.z == 0.0 && (n.y < 0.0 || (n.y == 0.0 && n.x < 0.0)))) n = -n;
  return {n.x + 0.0, n.y + 0.0, n.z + 0.0};
}

double alphaOver(const std::vector<Vec3>& normals, const Vec3& direction) {
  double alpha = std::numbers::pi / 2.0;
  for (const Vec3& n : normals) alpha = std::min(alpha, angleToLine(direction, n));
  return alpha;
}

// The eigenvector of the smallest eigenvalue of the symmetric 3 x 3 matrix m (Jacobi
// rotations), and that eigenvalue.
std::pair<Vec3, double> smallestEigen(std::array<std::array<double, 3>, 3> m) {
  std::array<std::array<double, 3>, 3> v{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    if (!(off > 1e-300)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (m[p][q] == 0.0) continue;
        const double theta = 0.5 * (m[q][q] - m[p][p]) / m[p][q];
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {
          const double mkp = m[k][p], mkq = m[k][q];
          m[k][p] = c * mkp - s * mkq;
          m[k][q] = s * mkp + c * mkq;
        }
        for (int k = 0; k < 3; ++k) {
          const double mpk = m[p][k], mqk = m[q][k];
          m[p][k] = c * mpk - s * mqk;
          m[q][k] = s * mpk + c * mqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (m[i][i] < m[best][best]) best = i;
  return {normalized(Vec3{v[0][best], v[1][best], v[2][best]}), m[best][best]};
}

// Qhull's state, freed however we leave.
struct Qhull {
  qhT state;
  std::FILE* messages = nullptr;
  bool started = false;
  Qhull() { qh_zero(&state, stderr); messages = std::tmpfile(); }
  ~Qhull() {
    if (started) {
      qh_freeqhull(&state, !qh_ALL);
      int curlong = 0, totlong = 0;
      qh_memfreeshort(&state, &curlong, &totlong);
    }
    if (messages) std::fclose(messages);
  }
  Qhull(const Qhull&) = delete;
  Qhull& operator=(const Qhull&) = delete;
  std::string message() const {
    if (!messages) return "(no message)";
    std::rewind(messages);
    std::string out;
    char buffer[512];
    while (out.size() < 2000 && std::fgets(buffer, sizeof buffer, messages)) out += buffer;
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
  }
};

}  // namespace

double meshSlicingAngle(const Mesh& mesh, const Vec3& unitNormal) {
  double alpha = std::numbers::pi / 2.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 n = triangleNormal(mesh, t);
    if (n == Vec3{0.0, 0.0, 0.0}) continue;
    alpha = std::min(alpha, angleToLine(unitNormal, n));
  }
  return alpha;
}

MeshSlicing optimalMeshSlicing(const Mesh& mesh) {
  std::vector<Vec3> normals;
  normals.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 n = triangleNormal(mesh, t);
    if (n == Vec3{0.0, 0.0, 0.0}) continue;
    normals.push_back(n);
  }
  if (normals.empty()) throw Error("optimal slicing of a mesh: no triangle of positive area");
  MeshSlicing out = optimalNormalSlicing(std::move(normals));
  out.triangles = out.normalsGiven;
  return out;
}

MeshSlicing optimalNormalSlicing(std::vector<Vec3> normals) {
  MeshSlicing out;
  if (normals.empty()) throw Error("optimal slicing of a set of normals: the set is empty");
  for (Vec3& n : normals) {
    if (!(std::abs(norm(n) - 1.0) <= 1e-9))
      throw Error(fmt::format("optimal slicing of a set of normals: ({}, {}, {}) is not a unit vector", n.x, n.y, n.z));
    n = canonical(n);
  }
  out.normalsGiven = normals.size();
  std::sort(normals.begin(), normals.end(), [](const Vec3& a, const Vec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  });
  normals.erase(std::unique(normals.begin(), normals.end()), normals.end());
  out.distinctNormals = normals.size();

  const auto finish = [&](Vec3 n) {
    out.normal = canonical(normalized(n));  // z >= 0
    out.alphaRad = alphaOver(normals, out.normal);
    return out;
  };
  // On one great circle (a flat hull): its pole. The second moment's smallest eigenvalue is
  // then zero; below 1e-12 of the trace the hull would be flat to rounding.
  std::array<std::array<double, 3>, 3> moment{};
  for (const Vec3& n : normals) {
    const double c[3] = {n.x, n.y, n.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) moment[i][j] += c[i] * c[j];
  }
  const auto [pole, smallest] = smallestEigen(moment);
  const double trace = static_cast<double>(normals.size());
  if (!(smallest > 1e-12 * trace)) {
    out.greatCircle = true;
    return finish(pole);
  }

  std::vector<double> points;
  points.reserve(6 * normals.size());
  for (const Vec3& n : normals)
    for (const double sign : {1.0, -1.0}) points.insert(points.end(), {sign * n.x, sign * n.y, sign * n.z});
  Qhull qhull;
  qhT* qh = &qhull.state;
  char options[] = "qhull Qt";
  qhull.started = true;
  const int code = qh_new_qhull(qh, 3, static_cast<int>(points.size() / 3), points.data(), False, options, nullptr,
                                qhull.messages ? qhull.messages : stderr);
  if (code != 0) {
    const std::string message = qhull.message();
    if (message.find("QH6154") != std::string::npos) {  // initial simplex is flat: one great circle
      out.greatCircle = true;
      return finish(pole);
    }
    throw Error(fmt::format("optimal slicing of a mesh: Qhull refused the {} normals: {}", normals.size(), message));
  }
  // The facets nearest the origin: largest empty caps.
  std::vector<std::pair<double, Vec3>> facets;
  for (facetT* facet = qh->facet_list; facet && facet->next; facet = facet->next)
    facets.push_back({-facet->offset, Vec3{facet->normal[0], facet->normal[1], facet->normal[2]}});
  out.hullFacets = facets.size();
  const std::size_t candidates = std::min(kCandidateFacets, facets.size());
  std::partial_sort(facets.begin(), facets.begin() + static_cast<std::ptrdiff_t>(candidates), facets.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  Vec3 best = facets.front().second;
  double bestAlpha = -1.0;
  for (std::size_t i = 0; i < candidates; ++i) {
    const Vec3 n = normalized(facets[i].second);
    const double alpha = alphaOver(normals, n);
    if (alpha > bestAlpha) bestAlpha = alpha, best = n;
  }
  return finish(best);
}

}  // namespace scallop
