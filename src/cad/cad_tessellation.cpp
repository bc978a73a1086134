// A STEP or IGES part whole: its tessellation and its exact heights (see cad_tessellation.hpp).

#include "scallop/cad/cad_tessellation.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <numbers>
#include <thread>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IntCurvesFace_ShapeIntersector.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Lin.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>

#include "cad/cad_file.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/parallel.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinRelativeDeflection = 1e-6;  // of the bounding box's diagonal
constexpr int kLatticeSteps = 4;                  // deviation samples: barycentric step 1/4

Vec3 toVec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

// The distance from p to triangle abc (closest point by the triangle's Voronoi regions:
// vertex, edge or face; Ericson, Real-Time Collision Detection, 5.1.5).
double pointTriangleDistance(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return norm(ap);
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return norm(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return norm(p - (a + (d1 / (d1 - d3)) * ab));
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return norm(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return norm(p - (a + (d2 / (d2 - d6)) * ac));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return norm(p - (b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b)));
  const double denominator = 1.0 / (va + vb + vc);
  return norm(p - (a + (vb * denominator) * ab + (vc * denominator) * ac));
}

// Vertices merged by their exact coordinates (+0 and -0 as one).
struct VertexKey {
  std::array<std::uint64_t, 3> bits;
  bool operator==(const VertexKey&) const = default;
};
struct VertexKeyHash {
  std::size_t operator()(const VertexKey& key) const {
    std::size_t h = 0;
    for (const std::uint64_t b : key.bits) h = (h ^ std::hash<std::uint64_t>{}(b)) * 0x9E3779B97F4A7C15ULL;
    return h;
  }
};
VertexKey keyOf(Vec3 v) {
  const auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x == 0.0 ? 0.0 : x); };
  return {{bits(v.x), bits(v.y), bits(v.z)}};
}

}  // namespace

struct CadPart::Impl {
  std::string path;
  CadFormat format = CadFormat::step;
  detail::CadFile file;
  std::size_t faces = 0;
  std::vector<TopoDS_Face> faceList;
  Vec3 low, high;
};

CadPart::CadPart(const std::string& path) : CadPart(path, [&] {
  const std::optional<CadFormat> format = cadFormatOf(path);
  if (!format) throw Error(fmt::format("{}: not a STEP or IGES file (by its name or its first line)", path));
  return *format;
}()) {}

CadPart::CadPart(const std::string& path, CadFormat format) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->format = format;
  const std::lock_guard<std::mutex> lock(detail::cadMutex());
  const detail::QuietMessages quiet;
  impl_->file = detail::readCadFile(path, format);
  for (TopExp_Explorer it(impl_->file.shape, TopAbs_FACE); it.More(); it.Next())
    impl_->faceList.push_back(TopoDS::Face(it.Current()));
  impl_->faces = impl_->faceList.size();
  if (impl_->faces == 0)
    throw Error(fmt::format("{}: no faces in the file ({} root entities transferred): nothing to machine", path,
                            impl_->file.roots));
  Bnd_Box box;
  try {
    // The tight box (AddOptimal): Add bounds a trimmed face by its whole surface's poles.
    BRepBndLib::AddOptimal(impl_->file.shape, box, Standard_False, Standard_False);
  } catch (const Standard_Failure& failure) {
    throw Error(fmt::format("{}: OpenCASCADE failed to bound the part ({})", path, detail::occtMessage(failure)));
  }
  if (box.IsVoid()) throw Error(fmt::format("{}: the part's faces bound no space", path));
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  impl_->low = {x0, y0, z0};
  impl_->high = {x1, y1, z1};
  if (!std::isfinite(x0 + y0 + z0 + x1 + y1 + z1))
    throw Error(fmt::format("{}: the part is unbounded (an infinite face?)", path));
}

CadPart::~CadPart() = default;
CadPart::CadPart(CadPart&&) noexcept = default;
CadPart& CadPart::operator=(CadPart&&) noexcept = default;

const std::string& CadPart::path() const { return impl_->path; }
CadFormat CadPart::format() const { return impl_->format; }
Units CadPart::units() const { return impl_->file.units; }
const std::string& CadPart::fileUnit() const { return impl_->file.fileUnit; }
std::size_t CadPart::faces() const { return impl_->faces; }
Vec3 CadPart::boxLow() const { return impl_->low; }
Vec3 CadPart::boxHigh() const { return impl_->high; }

CadImport CadPart::exactFaces(CadImportOptions options) const {
  const auto start = std::chrono::steady_clock::now();
  const std::lock_guard<std::mutex> lock(detail::cadMutex());
  const detail::QuietMessages quiet;
  options.skipUnsupportedFaces = true;
  CadImport result = detail::convertFaces(impl_->file, impl_->path, options, false);
  result.format = impl_->format;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

CadTessellation CadPart::tessellate(const TessellationOptions& options) const {
  const auto start = std::chrono::steady_clock::now();
  const std::string& path = impl_->path;
  const double diagonal = norm(impl_->high - impl_->low);
  if (!(std::isfinite(options.deflection) && options.deflection >= kMinRelativeDeflection * diagonal))
    throw Error(fmt::format("{}: the tessellation's deflection {} must be at least {:g} of the part's size ({:.6g} {}), "
                            "a mesh any finer outgrows every budget",
                            path, options.deflection, kMinRelativeDeflection, diagonal, unitsName(units())));
  if (!(options.angularDeflection > 0.0 && options.angularDeflection <= std::numbers::pi / 2.0))
    throw Error(fmt::format("the tessellation's angular deflection {} must be in (0, pi/2] radians",
                            options.angularDeflection));

  CadTessellation result;
  result.mesh.units = units();
  result.deflection = options.deflection;
  const std::lock_guard<std::mutex> lock(detail::cadMutex());
  const detail::QuietMessages quiet;
  TopoDS_Shape& shape = impl_->file.shape;
  try {
    BRepTools::Clean(shape);
    const BRepMesh_IncrementalMesh mesher(shape, options.deflection, Standard_False, options.angularDeflection,
                                          Standard_False);
    if (!mesher.IsDone()) throw Error(fmt::format("{}: OpenCASCADE's mesher failed on the part", path));
  } catch (const Standard_Failure& failure) {
    throw Error(fmt::format("{}: OpenCASCADE's mesher failed on the part ({})", path, detail::occtMessage(failure)));
  }

  std::unordered_map<VertexKey, std::uint32_t, VertexKeyHash> merged;
  std::size_t total = 0;
  for (std::size_t f = 0; f < impl_->faceList.size(); ++f) {
    checkCancelled();  // a plan's (tessellate_part.hpp): per face of the sampling below
    const TopoDS_Face& face = impl_->faceList[f];
    TopLoc_Location location;
    const Handle(Poly_Triangulation) triangulation = BRep_Tool::Triangulation(face, location);
    if (triangulation.IsNull() || triangulation->NbTriangles() == 0)
      throw Error(fmt::format("{}: {} could not be tessellated (OpenCASCADE's mesher left it without triangles)",
                              path, detail::cadFaceName(impl_->file, face, f)));
    total += static_cast<std::size_t>(triangulation->NbTriangles());
    if (total > options.maxTriangles)
      throw Error(fmt::format("{}: the tessellation with deflection {} has more than {} triangles (the budget); give a "
                              "larger deflection",
                              path, options.deflection, options.maxTriangles));
    const gp_Trsf placement = location.Transformation();
    std::vector<std::uint32_t> index(static_cast<std::size_t>(triangulation->NbNodes()) + 1);
    std::vector<Vec3> node(index.size());
    for (int n = 1; n <= triangulation->NbNodes(); ++n) {
      const Vec3 v = toVec(triangulation->Node(n).Transformed(placement));
      if (!std::isfinite(v.x + v.y + v.z))
        throw Error(fmt::format("{}: {} was tessellated to a point that is not finite", path,
                                detail::cadFaceName(impl_->file, face, f)));
      node[static_cast<std::size_t>(n)] = v;
      const auto [it, inserted] =
          merged.try_emplace(keyOf(v), static_cast<std::uint32_t>(result.mesh.vertices.size()));
      if (inserted) result.mesh.vertices.push_back(v);
      index[static_cast<std::size_t>(n)] = it->second;
    }
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    const bool hasUV = triangulation->HasUVNodes();
    std::optional<BRepAdaptor_Surface> exact;
    if (hasUV) exact.emplace(face);  // the face's location applied: points in the mesh's frame
    if (exact) {
      for (int n = 1; n <= triangulation->NbNodes(); ++n) {
        gp_Pnt onFace;
        gp_Vec du, dv;
        exact->D1(triangulation->UVNode(n).X(), triangulation->UVNode(n).Y(), onFace, du, dv);
        const gp_Vec cross = du.Crossed(dv);
        const Vec3 normal{cross.X(), cross.Y(), cross.Z()};
        const double length = norm(normal);
        if (length > 0.0 && std::isfinite(length)) result.sampledNormals.push_back(normal / length);
      }
    }
    for (int t = 1; t <= triangulation->NbTriangles(); ++t) {
      int n1 = 0, n2 = 0, n3 = 0;
      triangulation->Triangle(t).Get(n1, n2, n3);
      if (reversed) std::swap(n2, n3);
      const std::array<std::size_t, 3> n{static_cast<std::size_t>(n1), static_cast<std::size_t>(n2),
                                         static_cast<std::size_t>(n3)};
      const std::array<std::uint32_t, 3> tri{index[n[0]], index[n[1]], index[n[2]]};
      const Vec3 a = result.mesh.vertices[tri[0]], b = result.mesh.vertices[tri[1]], c = result.mesh.vertices[tri[2]];
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || norm(cross(b - a, c - a)) == 0.0) {
        ++result.degenerateTriangles;
        continue;
      }
      result.mesh.triangles.push_back(tri);
      result.triangleFaces.push_back(static_cast<std::uint32_t>(f));
      if (!exact) continue;
      const std::array<gp_Pnt2d, 3> uv{triangulation->UVNode(n1), triangulation->UVNode(n2),
                                       triangulation->UVNode(n3)};
      const Vec3 facetNormal = cross(b - a, c - a) / norm(cross(b - a, c - a));
      for (int i = 0; i <= kLatticeSteps; ++i) {
        for (int j = 0; i + j <= kLatticeSteps; ++j) {
          const int k = kLatticeSteps - i - j;
          if (i == kLatticeSteps || j == kLatticeSteps || k == kLatticeSteps) continue;  // corners
          const double wa = i / double(kLatticeSteps), wb = j / double(kLatticeSteps), wc = k / double(kLatticeSteps);
          const double u = wa * uv[0].X() + wb * uv[1].X() + wc * uv[2].X();
          const double v = wa * uv[0].Y() + wb * uv[1].Y() + wc * uv[2].Y();
          gp_Pnt onFace;
          gp_Vec du, dv;
          exact->D1(u, v, onFace, du, dv);
          const Vec3 p = toVec(onFace);
          ++result.deviationSamples;
          const gp_Vec cross = du.Crossed(dv);
          const Vec3 exactNormal{cross.X(), cross.Y(), cross.Z()};
          const double exactLength = norm(exactNormal);
          if (exactLength > 0.0 && std::isfinite(exactLength)) {
            const double cosine = std::min(1.0, std::abs(dot(exactNormal, facetNormal)) / exactLength);
            result.normalDeviationRad = std::max(result.normalDeviationRad, std::acos(cosine));
            if (i > 0 && j > 0 && k > 0) result.sampledNormals.push_back(exactNormal / exactLength);
          }
          const double d = pointTriangleDistance(p, a, b, c);
          if (d > result.deviation) {
            result.deviation = d;
            result.deviationAt = p;
            result.deviationFace = f;
          }
        }
      }
    }
  }
  if (result.mesh.triangles.empty())
    throw Error(fmt::format("{}: the tessellation has no triangle of positive area", path));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void CadPart::designHeights(HeightGrid& grid, std::vector<double>* normalZ, const ExactHeightOptions& options) const {
  std::fill(grid.z.begin(), grid.z.end(), -kInf);
  if (normalZ) normalZ->assign(grid.z.size(), 0.0);
  const Vec3 low = impl_->low, high = impl_->high;
  // The grid points inside the part's xy box: the only lines that can meet it.
  const auto range = [&](double lo, double hi, double origin, std::size_t count) {
    const double first = std::ceil((lo - origin) / grid.spacing), last = std::floor((hi - origin) / grid.spacing);
    const double a = std::max(first, 0.0), b = std::min(last, static_cast<double>(count) - 1.0);
    return b < a ? std::pair<std::size_t, std::size_t>{1, 0}
                 : std::pair<std::size_t, std::size_t>{static_cast<std::size_t>(a), static_cast<std::size_t>(b)};
  };
  const auto [i0, i1] = range(low.x, high.x, grid.x0, grid.columns);
  const auto [j0, j1] = range(low.y, high.y, grid.y0, grid.rows);
  if (i1 < i0 || j1 < j0) return;
  const std::size_t columns = i1 - i0 + 1, rows = j1 - j0 + 1;
  if (static_cast<double>(columns) * static_cast<double>(rows) > static_cast<double>(options.maxRays))
    throw Error(fmt::format("{}: the exact heights on a grid of {} x {} points (spacing {}) over the part take {} "
                            "vertical lines, more than the budget of {}: give a coarser resolution",
                            impl_->path, grid.columns, grid.rows, grid.spacing, columns * rows, options.maxRays));
  const double clearance = 1.0 + (high.z - low.z);
  const double top = high.z + clearance, length = (high.z - low.z) + 2.0 * clearance;
  const std::size_t threads = std::clamp<std::size_t>(threadCount(options.threads), 1, std::min<std::size_t>(rows, 64));
  // Rows are dealt out one at a time; each thread owns its intersector and writes only its
  // rows' points, so the result is the same for any number of threads.
  std::atomic<std::size_t> nextRow{j0};
  std::exception_ptr failure;
  std::mutex failureMutex;
  // The caller's job control (job_control.hpp), on every thread: each line polls its cancel,
  // each row reports progress (on the calling thread only).
  const JobControl* const control = currentJobControl();
  const auto work = [&] {
    try {
      IntCurvesFace_ShapeIntersector intersector;
      intersector.Load(impl_->file.shape, Precision::Confusion());
      std::unordered_map<const TopoDS_TShape*, BRepAdaptor_Surface> surfaces;
      for (std::size_t j = nextRow++; j <= j1; j = nextRow++) {
        advanceStage(j - j0, rows);
        for (std::size_t i = i0; i <= i1; ++i) {
          checkCancelled();
          const Vec2 p = grid.point(i, j);
          intersector.Perform(gp_Lin(gp_Pnt(p.x, p.y, top), gp_Dir(0.0, 0.0, -1.0)), 0.0, length);
          if (!intersector.IsDone() || intersector.NbPnt() == 0) continue;
          int best = 0;
          double z = -kInf;
          for (int k = 1; k <= intersector.NbPnt(); ++k) {
            const double zk = intersector.Pnt(k).Z();
            if (std::isfinite(zk) && zk > z) {
              z = zk;
              best = k;
            }
          }
          if (best == 0) continue;
          const std::size_t at = j * grid.columns + i;
          grid.z[at] = z;
          if (!normalZ) continue;
          const TopoDS_Face& face = intersector.Face(best);
          auto found = surfaces.find(face.TShape().get());
          if (found == surfaces.end()) found = surfaces.try_emplace(face.TShape().get(), face).first;
          gp_Pnt point;
          gp_Vec du, dv;
          found->second.D1(intersector.UParameter(best), intersector.VParameter(best), point, du, dv);
          const gp_Vec n = du.Crossed(dv);
          const double length2 = n.SquareMagnitude();
          (*normalZ)[at] = length2 > 0.0 && std::isfinite(length2) ? std::abs(n.Z()) / std::sqrt(length2) : 1.0;
        }
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failureMutex);
      if (!failure) failure = std::current_exception();
      nextRow = j1 + 1;
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t)
    pool.emplace_back([&work, control] {
      const JobControlScope scope(control, false);
      work();
    });
  work();
  for (std::thread& thread : pool) thread.join();
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const Standard_Failure& occt) {
      throw Error(fmt::format("{}: OpenCASCADE failed intersecting the part with a vertical line ({})", impl_->path,
                              detail::occtMessage(occt)));
    }
  }
}

}  // namespace scallop
