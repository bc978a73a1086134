// The Python module `scallop`: a thin pybind11 layer over the library's front doors (plan.hpp,
// toolpath_job.hpp, mesh_plan.hpp, optimal_slicing.hpp, scallop_hull.hpp, cut_simulation.hpp,
// mesh.hpp's STL reader and, when scallop::cad is built (SCALLOP_PYTHON_CAD), the STEP and
// IGES parts of cad_tessellation.hpp and tessellate_part.hpp). Point sets cross as numpy
// float64 arrays (N x 2 or N x 3), a mesh's triangles as an (M, 3) uint32 array, everything
// else as plain numbers, strings and the library's JSON text; no core type is subclassed.
//
// Contract of the binding
// -----------------------
// Errors: scallop::Error is raised as scallop.Error (a RuntimeError), scallop::Cancelled as
//   scallop.Cancelled (a scallop.Error); arrays of the wrong shape or choices outside their
//   enumeration as ValueError; wrong types as TypeError. Nothing the caller passes crashes
//   the interpreter: every input reaches the library's own validation first.
// Threads: the long calls (plan, paths, plan_mesh, mesh_paths, tessellate_part, orient,
//   verify, hull, and the readers load_surface, load_stl, CadPart) release the GIL,
//   so another Python thread may run meanwhile, e.g. to call CancelToken.cancel(). The
//   progress callback runs on the calling thread with the GIL held (job_control.hpp: never
//   on a worker); an exception it raises unwinds the job and comes out of the call as that
//   same exception. Ctrl-C (KeyboardInterrupt) is checked at every progress report (plan,
//   paths, plan_mesh, mesh_paths, tessellate_part); orient and verify take a CancelToken (no
//   progress); hull and the readers run to their end (linear in their input).
// Units: every length is in the surface's units ("in" or "mm"); angles are named *_deg or
//   *_rad.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#ifdef SCALLOP_PYTHON_CAD
#include "scallop/cad/cad_import.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/cad/tessellate_part.hpp"
#endif
#include "scallop/geometry/mesh.hpp"
#include "scallop/jobs/mesh_plan.hpp"
#include "scallop/paths/chain.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/io/file_output.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/io/hull_json.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/io/orient_output.hpp"
#include "scallop/parallel.hpp"
#include "scallop/paths/path_sampling.hpp"
#include "scallop/io/paths_output.hpp"
#include "scallop/jobs/plan.hpp"
#include "scallop/paths/scallop_hull.hpp"
#include "scallop/paths/tessellated_part.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/surface_io.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/jobs/toolpath_job.hpp"
#include "scallop/io/verify_output.hpp"

namespace py = pybind11;

namespace {

using scallop::Vec3;

// C-contiguous float64, converted from any array-like (lists, integer arrays).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Files a job would write, name -> contents, for Python (nothing is written to disk).
py::dict filesDict(const std::vector<scallop::OutputFile>& files) {
  py::dict out;
  for (const scallop::OutputFile& file : files) out[py::str(file.path)] = py::str(file.content);
  return out;
}

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// ---- numpy in and out -------------------------------------------------------------------

std::string shapeText(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) {
    if (i > 0) text += ", ";
    text += std::to_string(array.shape(i));
  }
  return text + (array.ndim() == 1 ? ",)" : ")");
}

// `object` as a float64 array; TypeError naming `what` when numpy cannot make one.
DoubleArray toDoubleArray(const py::handle& object, const std::string& what) {
  DoubleArray array = DoubleArray::ensure(object);
  if (!array) {
    const std::string got = py::isinstance<py::array>(object)
                                ? "an array of dtype " + std::string(py::str(object.attr("dtype")))
                                : std::string(py::str(object.get_type()));
    throw py::type_error(what + ": expected an array of numbers, got " + got);
  }
  return array;
}

Vec3 toVec3(const py::handle& object, const std::string& what) {
  const DoubleArray array = toDoubleArray(object, what);
  if (array.ndim() != 1 || array.shape(0) != 3)
    throw py::value_error(what + ": expected 3 numbers (x, y, z), got shape " + shapeText(array));
  return {array.at(0), array.at(1), array.at(2)};
}

py::array_t<double> vec3Array(const Vec3& v) {
  py::array_t<double> out(3);
  auto o = out.mutable_unchecked<1>();
  o(0) = v.x;
  o(1) = v.y;
  o(2) = v.z;
  return out;
}

py::object optionalVec3(const std::optional<Vec3>& v) { return v ? py::object(vec3Array(*v)) : py::none(); }

py::array_t<double> matrix(std::size_t rows, std::size_t columns) {
  return py::array_t<double>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(columns)});
}

// Elements with a start, an end and perhaps a centre in the xz-plane (hull elements, tool-path
// elements) as an (k, 6) array: start (x, z), end (x, z), centre (x, z) or NaN where
// hasCentre(element) is false.
template <typename Element, typename HasCentre>
py::array_t<double> xzRows(const std::vector<Element>& elements, HasCentre hasCentre) {
  py::array_t<double> out = matrix(elements.size(), 6);
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const Element& e = elements[i];
    const auto r = static_cast<py::ssize_t>(i);
    const bool centre = hasCentre(e);
    o(r, 0) = e.start.x;
    o(r, 1) = e.start.z;
    o(r, 2) = e.end.x;
    o(r, 3) = e.end.z;
    o(r, 4) = centre ? e.center.x : kNan;
    o(r, 5) = centre ? e.center.z : kNan;
  }
  return out;
}

// flag(element) for each element, as a boolean array.
template <typename Element, typename Flag>
py::array_t<bool> flags(const std::vector<Element>& elements, Flag flag) {
  py::array_t<bool> out(static_cast<py::ssize_t>(elements.size()));
  auto o = out.mutable_unchecked<1>();
  for (std::size_t i = 0; i < elements.size(); ++i) o(static_cast<py::ssize_t>(i)) = flag(elements[i]);
  return out;
}

// ---- choices --------------------------------------------------------------------------

scallop::Units parseUnits(const std::string& text) {
  if (text == "in" || text == "inch") return scallop::Units::inch;
  if (text == "mm") return scallop::Units::millimetre;
  throw py::value_error("units: expected \"in\" (or \"inch\") or \"mm\", got \"" + text + "\"");
}

scallop::GcodeDialect parseDialect(const std::string& text) {
  if (text == "linuxcnc") return scallop::GcodeDialect::linuxcnc;
  if (text == "grbl") return scallop::GcodeDialect::grbl;
  throw py::value_error("dialect: expected \"linuxcnc\" or \"grbl\", got \"" + text + "\"");
}

const char* arcPlaneName(scallop::ArcPlane plane) {
  switch (plane) {
    case scallop::ArcPlane::xy:
      return "xy";
    case scallop::ArcPlane::zx:
      return "zx";
    case scallop::ArcPlane::yz:
      return "yz";
  }
  return "xy";
}

// ---- surfaces -------------------------------------------------------------------------

// One patch from a (m + 1, n + 1, 3) array of control points and an optional (m + 1, n + 1)
// array of weights.
scallop::BezierPatch makePatch(const py::handle& controlObject, const py::handle& weightsObject, std::size_t index) {
  const std::string name = "patches[" + std::to_string(index) + "]";
  const DoubleArray control = toDoubleArray(controlObject, name + " control points");
  if (control.ndim() != 3 || control.shape(2) != 3 || control.shape(0) < 2 || control.shape(1) < 2)
    throw py::value_error(name + ": control points: expected shape (m + 1, n + 1, 3) with m, n >= 1, got shape " +
                          shapeText(control));
  scallop::BezierPatch patch;
  patch.degreeU = static_cast<int>(control.shape(0) - 1);
  patch.degreeV = static_cast<int>(control.shape(1) - 1);
  if (patch.degreeU > scallop::kMaxPatchDegree || patch.degreeV > scallop::kMaxPatchDegree)
    throw py::value_error(name + ": degrees (" + std::to_string(patch.degreeU) + ", " +
                          std::to_string(patch.degreeV) + ") exceed " + std::to_string(scallop::kMaxPatchDegree));
  const auto c = control.unchecked<3>();
  for (py::ssize_t j = 0; j < control.shape(0); ++j)
    for (py::ssize_t k = 0; k < control.shape(1); ++k) patch.control.push_back({c(j, k, 0), c(j, k, 1), c(j, k, 2)});
  if (!weightsObject.is_none()) {
    const DoubleArray weights = toDoubleArray(weightsObject, name + " weights");
    if (weights.ndim() != 2 || weights.shape(0) != control.shape(0) || weights.shape(1) != control.shape(1))
      throw py::value_error(name + ": weights: expected shape (" + std::to_string(control.shape(0)) + ", " +
                            std::to_string(control.shape(1)) + "), as the control points, got shape " +
                            shapeText(weights));
    const auto w = weights.unchecked<2>();
    for (py::ssize_t j = 0; j < weights.shape(0); ++j)
      for (py::ssize_t k = 0; k < weights.shape(1); ++k) patch.weights.push_back(w(j, k));
  }
  return patch;
}

// A list or tuple: one array per patch (degrees may differ); anything else: one array of
// shape (patches, m + 1, n + 1, 3).
scallop::Surface makeSurface(const py::object& control, const std::string& units, const py::object& weights) {
  scallop::Surface surface;
  surface.units = parseUnits(units);
  if (py::isinstance<py::list>(control) || py::isinstance<py::tuple>(control)) {
    const py::sequence patches = control;
    const bool weighted = !weights.is_none();
    if (weighted && (!py::isinstance<py::sequence>(weights) || py::len(weights) != py::len(patches)))
      throw py::value_error("weights: with a list of patches, expected a list of as many weight arrays");
    for (std::size_t i = 0; i < py::len(patches); ++i)
      surface.patches.push_back(makePatch(patches[i], weighted ? py::object(weights[py::int_(i)]) : py::none(), i));
  } else {
    const DoubleArray array = toDoubleArray(control, "control points");
    if (array.ndim() != 4 || array.shape(3) != 3)
      throw py::value_error("control points: expected an array of shape (patches, m + 1, n + 1, 3), got shape " +
                            shapeText(array));
    std::optional<DoubleArray> weightArray;
    if (!weights.is_none()) {
      weightArray = toDoubleArray(weights, "weights");
      if (weightArray->ndim() != 3 || weightArray->shape(0) != array.shape(0))
        throw py::value_error("weights: expected an array of shape (patches, m + 1, n + 1), got shape " +
                              shapeText(*weightArray));
    }
    for (py::ssize_t i = 0; i < array.shape(0); ++i) {
      const py::object patchWeights = weightArray ? py::object((*weightArray)[py::int_(i)]) : py::none();
      surface.patches.push_back(makePatch(array[py::int_(i)], patchWeights, static_cast<std::size_t>(i)));
    }
  }
  scallop::validateSurface(surface);
  return surface;
}

const scallop::BezierPatch& patchAt(const scallop::Surface& surface, std::size_t index) {
  if (index >= surface.patches.size())
    throw py::index_error("patch " + std::to_string(index) + " out of range: the surface has " +
                          std::to_string(surface.patches.size()) + " patches");
  return surface.patches[index];
}

// ---- job control ----------------------------------------------------------------------

// The JobControl of one call from Python: progress(fraction, stage) called with the GIL held,
// Ctrl-C checked at every report, and the caller's CancelToken (or a fresh one). It lives on
// the binding's stack for the whole call; the library's copies of the callback hold only a
// pointer to it, so no Python reference is copied without the GIL.
class PythonJobControl {
 public:
  PythonJobControl(py::object progress, const std::optional<scallop::CancelToken>& cancel)
      : progress_(std::move(progress)) {
    if (!progress_.is_none() && !PyCallable_Check(progress_.ptr()))
      throw py::type_error("progress: expected a callable (fraction, stage) or None, got " +
                           std::string(py::str(progress_.get_type())));
    if (cancel) control_.cancel = *cancel;
    control_.progress = [this](double fraction, const std::string& stage) { report(fraction, stage); };
  }
  PythonJobControl(const PythonJobControl&) = delete;
  PythonJobControl& operator=(const PythonJobControl&) = delete;

  const scallop::JobControl& control() const { return control_; }

 private:
  void report(double fraction, const std::string& stage) const {
    const py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!progress_.is_none()) progress_(fraction, stage);  // its exception: error_already_set
  }

  py::object progress_;
  scallop::JobControl control_;
};

// ---- results ----------------------------------------------------------------------------

struct Hull {
  scallop::ScallopHull hull;
  std::size_t vertices = 0;  // of the chain, for the JSON form
};

struct Paths {
  scallop::Surface surface;  // for the G-code's safe height
  scallop::ToolpathResult result;
};

struct Plan {
  scallop::Surface surface;  // for planFiles' figures
  scallop::PlanResult result;
};

struct Verification {
  scallop::SimulationReport simulated;
  scallop::VerifySources sources;
};

// An STL file as read: the mesh, and how the CLI names it (its path; "<n> triangles (binary
// STL)" in the plan's first stage).
struct StlFile {
  scallop::StlMesh stl;
  std::string path;
};

#ifdef SCALLOP_PYTHON_CAD
// A STEP or IGES part's tessellation. Its judge (exactHeights) calls the CadPart it was made
// from: tessellate_part keeps that Python object alive as long as this one (keep_alive).
struct Tessellated {
  scallop::TessellatedPart part;
  std::string path;  // the part's file, the plans' default source
};
#endif

struct MeshPaths {
  scallop::MeshToolpathResult result;
};

struct MeshPlan {
  scallop::MeshPlanResult result;
};

// What the tool-path figures read of a mesh's result: its path and its report.
struct PathView {
  const scallop::ToolPath& path;
  const scallop::PathsReport& report;
};

// The passes as (k + 1, 3) arrays: the start and every move's end.
py::list passPoints(const scallop::ToolPath& path) {
  py::list passes;
  for (const scallop::ToolPass& pass : path.passes) {
    py::array_t<double> points = matrix(pass.moves.size() + 1, 3);
    auto p = points.mutable_unchecked<2>();
    p(0, 0) = pass.start.x;
    p(0, 1) = pass.start.y;
    p(0, 2) = pass.start.z;
    for (std::size_t i = 0; i < pass.moves.size(); ++i) {
      const auto row = static_cast<py::ssize_t>(i + 1);
      p(row, 0) = pass.moves[i].end.x;
      p(row, 1) = pass.moves[i].end.y;
      p(row, 2) = pass.moves[i].end.z;
    }
    passes.append(std::move(points));
  }
  return passes;
}

// Per pass, a (k + 1,) bool array aligned with passPoints' rows: true where the row ends an arc.
py::list arcFlags(const scallop::ToolPath& path) {
  py::list flags;
  for (const scallop::ToolPass& pass : path.passes) {
    py::array_t<bool> arc(static_cast<py::ssize_t>(pass.moves.size() + 1));
    auto a = arc.mutable_unchecked<1>();
    a(0) = false;
    for (std::size_t i = 0; i < pass.moves.size(); ++i)
      a(static_cast<py::ssize_t>(i + 1)) = pass.moves[i].kind == scallop::MoveKind::arc;
    flags.append(std::move(arc));
  }
  return flags;
}

// One pass's moves in full: ends, arc flags, centres (NaN for lines), planes, directions.
py::dict passMoves(const scallop::ToolPath& path, std::size_t index) {
  if (index >= path.passes.size())
    throw py::index_error("pass " + std::to_string(index) + " out of range: the path has " +
                          std::to_string(path.passes.size()) + " passes");
  const scallop::ToolPass& pass = path.passes[index];
  const std::size_t n = pass.moves.size();
  py::array_t<double> ends = matrix(n, 3), centres = matrix(n, 3);
  py::array_t<bool> arc(static_cast<py::ssize_t>(n)), clockwise(static_cast<py::ssize_t>(n));
  py::list planes;
  auto e = ends.mutable_unchecked<2>();
  auto c = centres.mutable_unchecked<2>();
  auto a = arc.mutable_unchecked<1>();
  auto w = clockwise.mutable_unchecked<1>();
  for (std::size_t i = 0; i < n; ++i) {
    const scallop::ToolMove& move = pass.moves[i];
    const auto row = static_cast<py::ssize_t>(i);
    const bool isArc = move.kind == scallop::MoveKind::arc;
    e(row, 0) = move.end.x;
    e(row, 1) = move.end.y;
    e(row, 2) = move.end.z;
    c(row, 0) = isArc ? move.center.x : kNan;
    c(row, 1) = isArc ? move.center.y : kNan;
    c(row, 2) = isArc ? move.center.z : kNan;
    a(row) = isArc;
    w(row) = isArc && move.clockwise;
    planes.append(isArc ? py::object(py::str(arcPlaneName(move.plane))) : py::none());
  }
  py::dict out;
  out["start"] = vec3Array(pass.start);
  out["end"] = std::move(ends);
  out["arc"] = std::move(arc);
  out["center"] = std::move(centres);
  out["plane"] = std::move(planes);
  out["clockwise"] = std::move(clockwise);
  out["retract_before"] = pass.retractBefore;
  return out;
}

// The tool-path figures shared by Paths, Plan, MeshPaths and MeshPlan; `get` gives what has
// the path and its report (a ToolpathResult, a PathView).
template <class Holder, class Get>
void defPathFigures(py::class_<Holder>& cls, Get get) {
  cls.def_property_readonly(
         "passes", [get](const Holder& h) { return passPoints(get(h).path); },
         "Tool-centre passes in machining order: a list of (k + 1, 3) arrays, the pass's start and the end "
         "of each of its k moves. An arc move appears as its end point only (see arc_flags, pass_moves).")
      .def_property_readonly(
          "arc_flags", [get](const Holder& h) { return arcFlags(get(h).path); },
          "Per pass, a bool array aligned with the rows of passes: True where the row ends an arc move.")
      .def(
          "pass_moves", [get](const Holder& h, std::size_t i) { return passMoves(get(h).path, i); }, py::arg("index"),
          "Pass `index` in full: dict of start (3,), end (k, 3), arc (k,) bool, center (k, 3) (NaN for lines), "
          "plane (k,) 'xy' | 'zx' | 'yz' | None, clockwise (k,) bool (G2), retract_before.")
      .def_property_readonly(
          "retract_before",
          [get](const Holder& h) {
            const auto& passes = get(h).path.passes;
            py::array_t<bool> out(static_cast<py::ssize_t>(passes.size()));
            auto o = out.mutable_unchecked<1>();
            for (std::size_t i = 0; i < passes.size(); ++i) o(static_cast<py::ssize_t>(i)) = passes[i].retractBefore;
            return out;
          },
          "Per pass: the tool retracts before it (else it feeds straight from the previous pass's end).")
      .def_property_readonly(
          "strategy", [get](const Holder& h) { return get(h).report.strategy; }, "\"contour\" or \"raster\".")
      .def_property_readonly(
          "units", [get](const Holder& h) { return std::string(scallop::unitsName(get(h).report.units)); },
          "\"in\" or \"mm\".")
      .def_property_readonly(
          "tool_radius", [get](const Holder& h) { return get(h).report.toolRadius; }, "R of the ball.")
      .def_property_readonly(
          "spacing", [get](const Holder& h) { return get(h).report.spacing; }, "Delta between the planes.")
      .def_property_readonly(
          "scallop_height", [get](const Holder& h) { return get(h).report.scallopHeight; },
          "H when the spacing came from it, else None.")
      .def_property_readonly(
          "plane_normal", [get](const Holder& h) { return vec3Array(get(h).report.planeNormal); },
          "N of the cutting planes (unit).")
      .def_property_readonly(
          "alpha_deg", [get](const Holder& h) { return scallop::toDegrees(get(h).report.alphaRad); },
          "The proven least angle between N and +-n, degrees.")
      .def_property_readonly(
          "planes", [get](const Holder& h) { return get(h).report.stats.planes; }, "Planes that cut the surface.")
      .def_property_readonly(
          "components", [get](const Holder& h) { return get(h).report.stats.components; },
          "Connected pieces of the sections, summed over the planes.")
      .def_property_readonly(
          "centre_length", [get](const Holder& h) { return get(h).report.stats.centreLength; },
          "Total length of the tool-centre paths (the strategy's).")
      .def_property_readonly(
          "contact_length", [get](const Holder& h) { return get(h).report.stats.contactLength; },
          "Total length of the contact curves (the sections).")
      .def_property_readonly(
          "gouge_depth",
          [get](const Holder& h) -> std::optional<double> {
            const auto& gouge = get(h).report.gouge;
            return gouge ? std::optional<double>(gouge->maxDepth) : std::nullopt;
          },
          "Deepest sampled interference of the ball with the whole surface (gouge.hpp), or None unchecked.")
      .def_property_readonly(
          "gouge_bound",
          [get](const Holder& h) -> std::optional<double> {
            const auto& gouge = get(h).report.gouge;
            return gouge ? std::optional<double>(gouge->depthBound) : std::nullopt;
          },
          "Proven: no centre of the path cuts deeper than this (or None unchecked).")
      .def_property_readonly(
          "cycle_minutes",
          [get](const Holder& h) -> std::optional<double> {
            const auto& motion = get(h).report.motion;
            return motion ? std::optional<double>(motion->minutes) : std::nullopt;
          },
          "Estimated cycle time of the program at the default feeds and rapid rate, minutes.")
      .def_property_readonly(
          "report_json", [get](const Holder& h) { return scallop::pathsToJson(get(h).report, get(h).path); },
          "The report and the passes as JSON (paths_output.hpp), as `scallop paths --json` writes it.");
}

// The simulated-cut figures shared by Verification and Plan; `get` gives the SimulationReport.
template <class Holder, class Get>
void defSimulationFigures(py::class_<Holder>& cls, Get get) {
  const auto grid = [get](const Holder& h, bool stock) {
    const scallop::HeightGrid& g = stock ? get(h).stock : get(h).design;
    py::array_t<double> out = matrix(g.rows, g.columns);
    auto o = out.mutable_unchecked<2>();
    for (std::size_t j = 0; j < g.rows; ++j)
      for (std::size_t i = 0; i < g.columns; ++i)
        o(static_cast<py::ssize_t>(j), static_cast<py::ssize_t>(i)) = g.z[j * g.columns + i];
    return out;
  };
  cls.def_property_readonly(
         "max_gouge", [get](const Holder& h) { return get(h).maxGouge; },
         "Deepest gouge of the simulated cut, vertical (design - stock), at grid points.")
      .def_property_readonly(
          "max_gouge_at", [get](const Holder& h) { return optionalVec3(get(h).maxGougeAt); },
          "(x, y, design z) of the deepest gouge, or None.")
      .def_property_readonly(
          "gouge_points", [get](const Holder& h) { return get(h).gougePoints; },
          "Grid points gouged deeper than gouge_tolerance.")
      .def_property_readonly(
          "gouge_area", [get](const Holder& h) { return get(h).gougeArea; }, "gouge_points x spacing^2.")
      .def_property_readonly(
          "gouge_tolerance", [get](const Holder& h) { return get(h).gougeTolerance; },
          "A gouge deeper than this counts.")
      .def_property_readonly(
          "max_scallop", [get](const Holder& h) { return get(h).maxScallop; },
          "Highest scallop left (along the normal) where the ball reaches.")
      .def_property_readonly(
          "max_scallop_at", [get](const Holder& h) { return optionalVec3(get(h).maxScallopAt); },
          "(x, y, design z) of the highest scallop, or None.")
      .def_property_readonly(
          "scallop_p99", [get](const Holder& h) { return get(h).scallopP99; },
          "99th percentile of the scallop over the surface's grid points.")
      .def_property_readonly(
          "mean_scallop", [get](const Holder& h) { return get(h).meanScallop; }, "Mean scallop.")
      .def_property_readonly(
          "uncut_area", [get](const Holder& h) { return get(h).uncutArea; },
          "Area left above H where the ball reaches.")
      .def_property_readonly(
          "unreachable_area", [get](const Holder& h) { return get(h).unreachableArea; },
          "Area left above H beyond the ball's reach (a smaller tool's work).")
      .def_property_readonly(
          "rapids_cutting", [get](const Holder& h) { return get(h).rapidsCutting; },
          "Rapid moves that removed material.")
      .def_property_readonly(
          "simulated_moves", [get](const Holder& h) { return get(h).moves; }, "Moves simulated.")
      .def_property_readonly(
          "grid_spacing", [get](const Holder& h) { return get(h).design.spacing; }, "The z-map's spacing d.")
      .def_property_readonly(
          "grid_origin",
          [get](const Holder& h) { return py::make_tuple(get(h).design.x0, get(h).design.y0); },
          "(x0, y0): column i, row j of the grids is at (x0 + i d, y0 + j d).")
      .def_property_readonly(
          "stock_heights", [grid](const Holder& h) { return grid(h, true); },
          "The stock after the cut: (rows, columns) array of z.")
      .def_property_readonly(
          "design_heights", [grid](const Holder& h) { return grid(h, false); },
          "The visible design surface: (rows, columns) array of z, -inf where there is none.");
}

// ---- front doors --------------------------------------------------------------------------

Paths runPaths(const scallop::Surface& surface, double toolRadius, std::optional<double> scallopHeight,
               std::optional<double> spacing, const std::string& strategy, const py::object& normal,
               std::optional<double> angleDeg, bool constantSpacing, bool gougeCheck, bool link, bool oneWay,
               bool dropEnvelope, std::optional<double> rapidRate, const std::string& source,
               const py::object& progress, const std::optional<scallop::CancelToken>& cancel) {
  // As `scallop paths` refuses them (apps/paths_command.cpp).
  if (scallopHeight.has_value() == spacing.has_value())
    throw py::value_error("give exactly one of scallop_height and spacing");
  if (strategy == "raster" && !normal.is_none()) throw py::value_error("normal is for strategy \"contour\"");
  if (strategy == "contour" && angleDeg) throw py::value_error("angle_deg is for strategy \"raster\"");
  scallop::ToolpathOptions options;
  options.source = source;
  options.strategy = scallop::parseStrategy(strategy);
  options.toolRadius = toolRadius;
  options.scallopHeight = scallopHeight;
  options.spacing = spacing;
  options.constantSpacing = constantSpacing;
  if (!normal.is_none()) options.normal = toVec3(normal, "normal");
  options.angleDeg = angleDeg;
  options.gougeCheck = gougeCheck;
  options.link = link;
  options.dropEnvelope = dropEnvelope;
  options.linking.direction = oneWay ? scallop::PassDirection::keep : scallop::PassDirection::zigzag;
  const double rate = rapidRate.value_or(scallop::defaultRapidRate(surface.units));
  if (!(rate > 0.0) || !std::isfinite(rate)) throw scallop::Error("the rapid rate must be positive");
  const PythonJobControl job(progress, cancel);
  Paths out{surface, {}};
  {
    const py::gil_scoped_release release;
    out.result = scallop::toolpaths(surface, options, std::nullopt, job.control());
    // As `scallop paths`: the program's motion at the default feeds, in the report.
    const scallop::GcodeOptions gcode = scallop::defaultGcodeOptions(
        surface, out.result.path, scallop::GcodeDialect::linuxcnc, "scallop paths " + strategy + " " + source);
    scallop::PathsReport& report = out.result.report;
    report.motion = scallop::gcodeMotion(out.result.path, gcode, rate);
    report.feedRate = gcode.feedRate;
    report.plungeFeedRate = gcode.plungeFeedRate;
    report.rapidRate = rate;
  }
  return out;
}

Plan runPlan(const scallop::Surface& surface, std::optional<double> toolRadius, std::optional<double> scallopHeight,
             std::optional<double> spacing, const std::string& strategy, const std::string& dialect,
             bool constantSpacing, bool link, bool oneWay, bool dropEnvelope, bool restFinishing,
             std::optional<double> rapidRate, const std::string& source, const py::object& progress,
             const std::optional<scallop::CancelToken>& cancel) {
  scallop::PlanOptions options;
  options.source = source;
  options.strategy = scallop::parseStrategy(strategy);
  options.toolRadius = toolRadius;
  options.scallopHeight = scallopHeight;
  options.spacing = spacing;
  options.constantSpacing = constantSpacing;
  options.link = link;
  options.oneWay = oneWay;
  options.dropEnvelope = dropEnvelope;
  options.restFinishing = restFinishing;
  options.dialect = parseDialect(dialect);
  options.rapidRate = rapidRate;
  const PythonJobControl job(progress, cancel);
  Plan out{surface, {}};
  {
    const py::gil_scoped_release release;
    out.result = scallop::plan(surface, options, job.control());
  }
  return out;
}

Verification runVerify(const scallop::Surface& surface, const std::string& program, double toolRadius,
                       std::optional<double> scallopHeight, std::optional<double> resolution,
                       std::optional<double> gougeTolerance, std::optional<double> stockTop,
                       std::optional<double> stockAllowance, const std::string& source,
                       const std::string& programName, const std::optional<scallop::CancelToken>& cancel) {
  // As `scallop verify` fills the options (apps/verify_command.cpp).
  scallop::SimulationOptions options;
  if (!(toolRadius > 0.0) || !std::isfinite(toolRadius))
    throw scallop::Error("invalid tool radius " + std::to_string(toolRadius) + ": must be a positive length");
  options.toolRadius = toolRadius;
  options.scallopHeight = scallopHeight.value_or(surface.units == scallop::Units::inch ? 0.001 : 0.025);
  if (!(options.scallopHeight > 0.0) || !(options.scallopHeight < toolRadius))
    throw scallop::Error("invalid scallop height " + std::to_string(options.scallopHeight) +
                         ": must be positive and smaller than the tool radius");
  if (resolution) options.resolution = *resolution;
  if (gougeTolerance) options.gougeTolerance = *gougeTolerance;
  options.stockTop = stockTop;
  options.stockAllowance = stockAllowance;
  Verification out;
  const PythonJobControl job(py::none(), cancel);
  {
    const py::gil_scoped_release release;
    const scallop::JobControlScope scope(&job.control());  // the simulation polls the token
    const scallop::GcodeProgram parsed = scallop::parseGcodeProgram(program, programName);
    out.simulated = scallop::verifyProgram(surface, parsed, options);
    out.sources = {source, programName, parsed.unknownStartMoves, parsed.maxArcRadiusMismatch};
  }
  return out;
}


// ---- meshes -------------------------------------------------------------------------------

// A Mesh from an (n, 3) array of vertices and an (m, 3) array of vertex indices. The indices'
// range against the vertices, finiteness and the rest are the plans' checks (mesh_plan.hpp);
// here only what uint32 cannot hold.
scallop::Mesh makeMesh(const py::object& verticesObject, const py::object& trianglesObject, const std::string& units) {
  scallop::Mesh mesh;
  mesh.units = parseUnits(units);
  const DoubleArray vertices = toDoubleArray(verticesObject, "vertices");
  if (vertices.ndim() != 2 || vertices.shape(1) != 3)
    throw py::value_error("vertices: expected an array of shape (n, 3), got shape " + shapeText(vertices));
  const auto v = vertices.unchecked<2>();
  for (py::ssize_t i = 0; i < vertices.shape(0); ++i) mesh.vertices.push_back({v(i, 0), v(i, 1), v(i, 2)});
  using IndexArray = py::array_t<long long, py::array::c_style | py::array::forcecast>;
  const py::array asArray = py::array::ensure(trianglesObject);
  if (!asArray || (asArray.size() > 0 && asArray.dtype().kind() != 'i' && asArray.dtype().kind() != 'u'))
    throw py::type_error("triangles: expected an array of integers (vertex indices), got " +
                         (asArray ? "an array of dtype " + std::string(py::str(asArray.dtype()))
                                  : std::string(py::str(trianglesObject.get_type()))));
  const IndexArray triangles = IndexArray::ensure(asArray);
  if (!triangles || triangles.ndim() != 2 || triangles.shape(1) != 3)
    throw py::value_error("triangles: expected an array of shape (m, 3), got shape " + shapeText(asArray));
  const auto t = triangles.unchecked<2>();
  for (py::ssize_t i = 0; i < triangles.shape(0); ++i) {
    std::array<std::uint32_t, 3> triangle{};
    for (py::ssize_t k = 0; k < 3; ++k) {
      const long long index = t(i, k);
      if (index < 0 || index > static_cast<long long>(std::numeric_limits<std::uint32_t>::max()))
        throw py::value_error("triangles[" + std::to_string(i) + "]: vertex index " + std::to_string(index) +
                              " is negative or too large");
      triangle[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(index);
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

// As `scallop plan PART.stl` names the mesh in its first stage.
std::string stlDescription(const scallop::StlMesh& stl) {
  return std::to_string(stl.mesh.triangles.size()) +
         (stl.format == scallop::StlFormat::binary ? " triangles (binary STL)" : " triangles (ASCII STL)");
}

StlFile loadStl(const std::string& path, const std::string& units, bool dropZeroArea) {
  scallop::StlOptions options;
  options.units = parseUnits(units);
  options.dropZeroArea = dropZeroArea;
  StlFile out;
  out.path = path;
  const py::gil_scoped_release release;
  try {
    out.stl = scallop::readStl(path, options);
  } catch (const scallop::Error& e) {
    // As the CLI adds its flag (apps/surface_options.cpp), the keyword that skips them.
    if (!dropZeroArea && std::string(e.what()).find("zero area") != std::string::npos)
      throw scallop::Error(std::string(e.what()) + "; drop_zero_area=True skips such triangles");
    throw;
  }
  return out;
}

// What a mesh plan takes: a Mesh, an StlMesh or a TessellatedPart, with the CLI's names.
struct MeshInput {
  const scallop::Mesh* mesh = nullptr;
  const scallop::TessellatedPart* part = nullptr;  // instead of mesh
  std::string source = "mesh";
  std::string description;
};

MeshInput meshInput(const py::object& object) {
  MeshInput in;
  if (py::isinstance<scallop::Mesh>(object)) {
    in.mesh = &object.cast<const scallop::Mesh&>();
  } else if (py::isinstance<StlFile>(object)) {
    const StlFile& file = object.cast<const StlFile&>();
    in.mesh = &file.stl.mesh;
    in.source = file.path;
    in.description = stlDescription(file.stl);
#ifdef SCALLOP_PYTHON_CAD
  } else if (py::isinstance<Tessellated>(object)) {
    const Tessellated& tessellated = object.cast<const Tessellated&>();
    in.part = &tessellated.part;
    in.source = tessellated.path;
#endif
  } else {
    throw py::type_error("mesh: expected a scallop.Mesh, StlMesh or TessellatedPart, got " +
                         std::string(py::str(object.get_type())));
  }
  return in;
}

scallop::MeshPlanOptions meshPlanOptions(const MeshInput& in, std::optional<double> toolRadius,
                                         std::optional<double> scallopHeight, std::optional<double> spacing,
                                         const std::optional<std::string>& source,
                                         const std::optional<std::string>& description) {
  scallop::MeshPlanOptions options;
  options.source = source.value_or(in.source);
  options.description = description.value_or(in.description);
  options.toolRadius = toolRadius;
  options.scallopHeight = scallopHeight;
  options.spacing = spacing;
  return options;
}

MeshPaths runMeshPaths(const py::object& meshObject, std::optional<double> toolRadius,
                       std::optional<double> scallopHeight, std::optional<double> spacing,
                       std::optional<double> rapidRate, const std::optional<std::string>& source,
                       const std::optional<std::string>& description, const py::object& progress,
                       const std::optional<scallop::CancelToken>& cancel) {
  const MeshInput in = meshInput(meshObject);
  const scallop::MeshPlanOptions options = meshPlanOptions(in, toolRadius, scallopHeight, spacing, source, description);
  const scallop::Units units = in.part != nullptr ? in.part->mesh.units : in.mesh->units;
  const double rate = rapidRate.value_or(scallop::defaultRapidRate(units));
  if (!(rate > 0.0) || !std::isfinite(rate)) throw scallop::Error("the rapid rate must be positive");
  const PythonJobControl job(progress, cancel);
  MeshPaths out;
  {
    const py::gil_scoped_release release;
    out.result = in.part != nullptr ? scallop::meshToolpaths(*in.part, options, job.control())
                                    : scallop::meshToolpaths(*in.mesh, options, job.control());
    // As `scallop paths PART.stl`: the program's motion at the default feeds, in the report.
    scallop::MeshToolpathResult& r = out.result;
    const scallop::GcodeOptions gcode =
        scallop::defaultGcodeOptions(units, r.partTop, r.raster.path, scallop::GcodeDialect::linuxcnc,
                                     "scallop paths raster " + options.source);
    r.report.motion = scallop::gcodeMotion(r.raster.path, gcode, rate);
    r.report.feedRate = gcode.feedRate;
    r.report.plungeFeedRate = gcode.plungeFeedRate;
    r.report.rapidRate = rate;
  }
  return out;
}

MeshPlan runMeshPlan(const py::object& meshObject, std::optional<double> toolRadius,
                     std::optional<double> scallopHeight, std::optional<double> spacing, const std::string& dialect,
                     bool restFinishing, std::optional<double> rapidRate, const std::optional<std::string>& source,
                     const std::optional<std::string>& description, const py::object& progress,
                     const std::optional<scallop::CancelToken>& cancel) {
  const MeshInput in = meshInput(meshObject);
  scallop::MeshPlanOptions options = meshPlanOptions(in, toolRadius, scallopHeight, spacing, source, description);
  options.restFinishing = restFinishing;
  options.dialect = parseDialect(dialect);
  options.rapidRate = rapidRate;
  const PythonJobControl job(progress, cancel);
  MeshPlan out;
  {
    const py::gil_scoped_release release;
    out.result = in.part != nullptr ? scallop::planMesh(*in.part, options, job.control())
                                    : scallop::planMesh(*in.mesh, options, job.control());
  }
  return out;
}

// The figures of a mesh's raster shared by MeshPaths and MeshPlan; `get` gives the
// MeshToolpathResult.
template <class Holder, class Get>
void defMeshRasterFigures(py::class_<Holder>& cls, Get get) {
  cls.def_property_readonly(
         "lines", [get](const Holder& h) { return get(h).raster.lines; }, "Raster lines (along x).")
      .def_property_readonly(
          "min_spacing", [get](const Holder& h) { return get(h).raster.minSpacing; },
          "The least step between lines but the last (0 with one line); spacing is the largest.")
      .def_property_readonly(
          "drops", [get](const Holder& h) { return get(h).raster.drops; }, "Exact drops of the ball computed.")
      .def_property_readonly(
          "unproven_moves", [get](const Holder& h) { return get(h).raster.unprovenMoves; },
          "Moves of the raster not proven clear of the mesh within eps (0 unless a budget ran out).")
      .def_property_readonly(
          "eps", [get](const Holder& h) { return get(h).raster.eps; },
          "The proofs' tolerance eps (1e-6 of the mesh's size).")
      .def_property_readonly(
          "part_top", [get](const Holder& h) { return get(h).partTop; },
          "The mesh's highest vertex (the G-code's safe height stands above it).");
}
}  // namespace

PYBIND11_MODULE(scallop, m) {
  m.doc() =
      "scallop: exact tool paths for 3-axis ball-end milling (scallop hull, optimal slicing), a thin layer "
      "over the C++ library. Lengths are in the surface's units; point sets are numpy float64 arrays.\n\n"
      "Front doors: plan (the whole job: tool path, G-code, simulated cut), paths, orient, hull, verify; "
      "surfaces from Surface(control_points), load_surface, example_surface. Meshes: plan_mesh, mesh_paths on a "
      "Mesh(vertices, triangles), load_stl, or (has_cad) tessellate_part(CadPart(path)) for STEP and IGES.";
  m.attr("__version__") = SCALLOP_VERSION;

  // Cancelled is registered after Error: pybind11 tries the latest translator first, so a
  // Cancelled is never reported as a plain Error.
  auto& error = py::register_local_exception<scallop::Error>(m, "Error", PyExc_RuntimeError);
  error.attr("__doc__") = "Every failure the library detects (bad input, malformed files, violated preconditions).";
  auto& cancelled = py::register_local_exception<scallop::Cancelled>(m, "Cancelled", error.ptr());
  cancelled.attr("__doc__") = "The job was cancelled through its CancelToken.";

  py::class_<scallop::CancelToken>(m, "CancelToken",
                                   "A shared cancellation flag: give it to plan, paths, plan_mesh, mesh_paths or "
                                   "tessellate_part, call cancel() from any thread (or from the progress callback); "
                                   "the job then raises scallop.Cancelled.")
      .def(py::init<>())
      .def("cancel", &scallop::CancelToken::cancel, "Asks the job to stop; thread-safe, idempotent.")
      .def_property_readonly("cancelled", &scallop::CancelToken::cancelled, "True once cancel() was called.");

  // ---- surfaces
  py::class_<scallop::Surface>(
      m, "Surface",
      "Tensor-product Bezier patches sharing one unit of length (surface.hpp). Patch p_jk multiplies "
      "b_j^m(u) b_k^n(v): row j runs along v. Validated on construction: degrees 1..20, finite control points, "
      "regular (r_u x r_v != 0 on the whole patch), positive weights.")
      .def(py::init(&makeSurface), py::arg("control_points"), py::arg("units") = "in", py::arg("weights") = py::none(),
           "Surface(control_points, units='in', weights=None): control_points an array of shape (patches, m + 1, "
           "n + 1, 3), or a list of (m + 1, n + 1, 3) arrays (degrees may differ); units 'in' ('inch') or 'mm'; "
           "weights None (polynomial) or shaped as the control points without the last axis (rational patches).")
      .def_property_readonly(
          "units", [](const scallop::Surface& s) { return std::string(scallop::unitsName(s.units)); },
          "\"in\" or \"mm\".")
      .def_property_readonly(
          "patch_count", [](const scallop::Surface& s) { return s.patches.size(); }, "Number of patches.")
      .def("__len__", [](const scallop::Surface& s) { return s.patches.size(); })
      .def(
          "degrees",
          [](const scallop::Surface& s, std::size_t i) {
            const scallop::BezierPatch& p = patchAt(s, i);
            return py::make_tuple(p.degreeU, p.degreeV);
          },
          py::arg("index"), "(m, n) of patch `index`.")
      .def(
          "control_points",
          [](const scallop::Surface& s, std::size_t i) {
            const scallop::BezierPatch& p = patchAt(s, i);
            const auto rows = static_cast<py::ssize_t>(p.degreeU + 1), columns = static_cast<py::ssize_t>(p.degreeV + 1);
            py::array_t<double> out({rows, columns, static_cast<py::ssize_t>(3)});
            auto o = out.mutable_unchecked<3>();
            for (py::ssize_t j = 0; j < rows; ++j)
              for (py::ssize_t k = 0; k < columns; ++k) {
                const Vec3& c = p.control[static_cast<std::size_t>(j * columns + k)];
                o(j, k, 0) = c.x;
                o(j, k, 1) = c.y;
                o(j, k, 2) = c.z;
              }
            return out;
          },
          py::arg("index"), "Patch `index`'s control points, an (m + 1, n + 1, 3) array (a copy).")
      .def(
          "weights",
          [](const scallop::Surface& s, std::size_t i) -> py::object {
            const scallop::BezierPatch& p = patchAt(s, i);
            if (!p.rational()) return py::none();
            const auto rows = static_cast<py::ssize_t>(p.degreeU + 1), columns = static_cast<py::ssize_t>(p.degreeV + 1);
            py::array_t<double> out({rows, columns});
            auto o = out.mutable_unchecked<2>();
            for (py::ssize_t j = 0; j < rows; ++j)
              for (py::ssize_t k = 0; k < columns; ++k) o(j, k) = p.weights[static_cast<std::size_t>(j * columns + k)];
            return out;
          },
          py::arg("index"), "Patch `index`'s weights, an (m + 1, n + 1) array, or None for a polynomial patch.")
      .def("to_json", &scallop::surfaceToJson, "The surface in the JSON file format (surface.hpp).")
      .def("__repr__", [](const scallop::Surface& s) {
        return "<scallop.Surface: " + std::to_string(s.patches.size()) + " patches, units " +
               std::string(scallop::unitsName(s.units)) + ">";
      });

  m.def(
      "load_surface",
      [](const std::string& path) {
        const py::gil_scoped_release release;
        return scallop::readSurface(path);
      },
      py::arg("path"),
      "Reads and validates a surface file: .bpt text (inches) or JSON (surface.hpp's format). scallop.Error "
      "names the file, the patch and the offending value.");
  m.def("example_surface", &scallop::exampleSurface, py::arg("name"),
        "A built-in surface: 'paper-1', 'paper-2' (the optimal-slicing paper's test surfaces, inches), 'teapot' "
        "and its parts (example_surface_names()).");
  m.def("example_surface_names", &scallop::exampleSurfaceNames, "Names of the built-in surfaces.");
  m.def(
      "example_chain",
      [](const std::string& name) {
        const scallop::Chain chain = scallop::exampleChain(name);
        py::array_t<double> out = matrix(chain.size(), 2);
        auto o = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < chain.size(); ++i) {
          o(static_cast<py::ssize_t>(i), 0) = chain[i].x;
          o(static_cast<py::ssize_t>(i), 1) = chain[i].z;
        }
        return out;
      },
      py::arg("name"), "A built-in monotone chain as an (n, 2) array of (x, z): 'figure2', 'steps', 'sawtooth', 'sine'.");
  m.def("example_chain_names", &scallop::exampleChainNames, "Names of the built-in chains.");

  // ---- the scallop hull
  py::class_<Hull>(m, "Hull",
                   "The scallop hull of a monotone chain and its offset, the tool-centre path (scallop_hull.hpp).")
      .def_property_readonly(
          "radius", [](const Hull& h) { return h.hull.radius; }, "r (may be inf).")
      .def_property_readonly(
          "elements",
          [](const Hull& h) {
            return xzRows(h.hull.hull, [](const scallop::HullElement& e) {
              return e.kind == scallop::HullElementKind::lid && !e.straight;
            });
          },
          "The hull's links and lids left to right, an (k, 6) array: start (x, z), end (x, z), a lid's circle "
          "centre (x, z) (NaN for links and for the straight lids of r = inf).")
      .def_property_readonly(
          "is_lid",
          [](const Hull& h) {
            return flags(h.hull.hull, [](const scallop::HullElement& e) { return e.kind == scallop::HullElementKind::lid; });
          },
          "Per element: True for a lid (the circle over a deficiency), False for a link (on an edge).")
      .def_property_readonly(
          "edges",
          [](const Hull& h) {
            py::array_t<long long> out(static_cast<py::ssize_t>(h.hull.hull.size()));
            auto o = out.mutable_unchecked<1>();
            for (std::size_t i = 0; i < h.hull.hull.size(); ++i) {
              const scallop::HullElement& e = h.hull.hull[i];
              o(static_cast<py::ssize_t>(i)) =
                  e.kind == scallop::HullElementKind::link ? static_cast<long long>(e.edge) : -1;
            }
            return out;
          },
          "Per element: the chain edge i (v_i, v_i+1) a link lies on; -1 for lids.")
      .def_property_readonly(
          "toolpath",
          [](const Hull& h) {
            return xzRows(h.hull.toolpath,
                          [](const scallop::PathElement& e) { return e.kind == scallop::PathElementKind::arc; });
          },
          "The tool-centre path left to right, an (k, 6) array: start (x, z), end (x, z), an arc's centre (the "
          "chain vertex it rolls around; NaN for lines). Arcs are clockwise, of radius r. Empty for r = inf.")
      .def_property_readonly(
          "is_arc",
          [](const Hull& h) {
            return flags(h.hull.toolpath,
                         [](const scallop::PathElement& e) { return e.kind == scallop::PathElementKind::arc; });
          },
          "Per tool-path element: True for an arc, False for a line.")
      .def_property_readonly(
          "length", [](const Hull& h) { return scallop::pathLength(h.hull.toolpath); },
          "Length of the tool-centre path (lines plus arcs).")
      .def(
          "polyline",
          [](const Hull& h, double tolerance) {
            const std::vector<scallop::Point2> points = scallop::samplePath(h.hull.toolpath, tolerance);
            py::array_t<double> out = matrix(points.size(), 2);
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < points.size(); ++i) {
              o(static_cast<py::ssize_t>(i), 0) = points[i].x;
              o(static_cast<py::ssize_t>(i), 1) = points[i].z;
            }
            return out;
          },
          py::arg("tolerance"),
          "The tool path as an (n, 2) polyline: lines kept, arcs replaced by circumscribed polygons within "
          "`tolerance` (never closer to the material than the arc).")
      .def(
          "height_at",
          [](const Hull& h, const py::object& x) -> py::object {
            if (PyFloat_Check(x.ptr()) || PyLong_Check(x.ptr()))
              return py::float_(scallop::pathHeightAt(h.hull.toolpath, x.cast<double>()));
            const DoubleArray at = toDoubleArray(x, "x");
            py::array_t<double> out(std::vector<py::ssize_t>(at.shape(), at.shape() + at.ndim()));
            const double* in = at.data();
            double* result = out.mutable_data();
            for (py::ssize_t i = 0; i < at.size(); ++i) result[i] = scallop::pathHeightAt(h.hull.toolpath, in[i]);
            return out;
          },
          py::arg("x"), "Height of the tool path at x (scalar or array); -inf outside its x range.")
      .def_property_readonly(
          "stats",
          [](const Hull& h) {
            py::dict out;
            out["pushes"] = h.hull.stats.pushes;
            out["pops"] = h.hull.stats.pops;
            out["comparisons"] = h.hull.stats.comparisons;
            out["exact_steps"] = h.hull.stats.exactSteps;
            return out;
          },
          "The linear-time counters: edge pushes and pops on the hull stack, capsule comparisons, and the "
          "edges the exact pass added (vertical edges, ties the filtered pass leaves to it).")
      .def(
          "to_json", [](const Hull& h) { return scallop::hullToJson(h.hull, h.vertices); },
          "The JSON form of `scallop hull --json` (hull_json.hpp).");

  m.def(
      "hull",
      [](const py::object& points, double radius) {
        const DoubleArray array = toDoubleArray(points, "points");
        if (array.ndim() != 2 || array.shape(1) != 2)
          throw py::value_error("points: expected an array of shape (n, 2) of (x, z), got shape " + shapeText(array));
        scallop::Chain chain;
        const auto p = array.unchecked<2>();
        for (py::ssize_t i = 0; i < array.shape(0); ++i) chain.push_back({p(i, 0), p(i, 1)});
        Hull out;
        out.vertices = chain.size();
        {
          const py::gil_scoped_release release;
          out.hull = scallop::scallopHull(chain, radius);
        }
        return out;
      },
      py::arg("points"), py::arg("radius"),
      "The scallop hull of a monotone chain and its offset (Chou et al., CAD 1994), in O(n). points: (n, 2) "
      "array of (x, z), n >= 2, finite, x non-decreasing, material below; radius r > 0 (inf: the upper convex "
      "hull, no tool path). The tool path runs from (x_0 - r, z_0) to (x_n-1 + r, z_n-1), every point within "
      "1e-12 max(r, |coordinates|) of distance r from the chain.");

  // ---- the optimal slicing orientation
  py::class_<scallop::OptimalSlicing>(
      m, "Orientation",
      "The optimal slicing orientation N* of a surface (optimal_slicing.hpp): the normal of parallel planes "
      "farthest from every surface normal, alpha* that least angle, and the certificate.")
      .def_property_readonly(
          "normal", [](const scallop::OptimalSlicing& o) { return vec3Array(o.normal); },
          "N*, unit (its sign is arbitrary).")
      .def_readonly("alpha_rad", &scallop::OptimalSlicing::alphaRad, "alpha*, radians.")
      .def_property_readonly(
          "alpha_deg", [](const scallop::OptimalSlicing& o) { return scallop::toDegrees(o.alphaRad); },
          "alpha*, degrees.")
      .def_readonly("certified", &scallop::OptimalSlicing::certified,
                    "Proven: no surface normal within certified_alpha_deg of +-N*.")
      .def_property_readonly(
          "certified_alpha_deg",
          [](const scallop::OptimalSlicing& o) { return scallop::toDegrees(o.certifiedAlphaRad); },
          "The angle the certificate proves (alpha* - 1e-7 rad), degrees.")
      .def_property_readonly(
          "uncertified_alpha_deg",
          [](const scallop::OptimalSlicing& o) { return scallop::toDegrees(o.uncertifiedAlphaRad); },
          "The polish's alpha when the certificate refuted it (alpha_deg is then what it proves), else 0.")
      .def_readonly("certificate_cells", &scallop::OptimalSlicing::certificateCells,
                    "Quadtree cells the certificate examined.")
      .def_property_readonly(
          "method", [](const scallop::OptimalSlicing& o) { return scallop::slicingMethodName(o.method); },
          "'medial-axis'; 'plane' or 'curve' (degenerate Gauss maps); 'covered', 'lattice', 'open' (no "
                    "complement).")
      .def_property_readonly(
          "pole", [](const scallop::OptimalSlicing& o) { return vec3Array(o.pole); },
          "The surface normal used as the stereographic pole.")
      .def_property_readonly(
          "boundary_segments", [](const scallop::OptimalSlicing& o) { return o.gaussMap.boundarySegments; },
          "Segments of the Gauss map's boundary.")
      .def_readonly("medial_axis_edges", &scallop::OptimalSlicing::medialAxisEdges, "Edges of the medial axis.")
      .def_readonly("seconds", &scallop::OptimalSlicing::seconds, "Wall time of the computation.")
      .def("to_json", &scallop::orientationToJson, py::arg("tolerance_deg") = 0.5,
           "The JSON form of `scallop orient` (orient_output.hpp); tolerance_deg is recorded as the Gauss-map "
           "tolerance used (orient's argument; plan and paths use 0.5).")
      .def("gauss_map_svg", &scallop::gaussMapSphereSvg, "The symmetrized Gauss map and the optimal circle (SVG).")
      .def("stereographic_svg", &scallop::stereographicSvg,
           "The stereographic plane with the medial axis and the optimal circle (SVG).");

  m.def(
      "orient",
      [](const scallop::Surface& surface, double toleranceDeg, bool certify, bool latticeSeeds,
         const std::optional<scallop::CancelToken>& cancel) {
        scallop::OptimalSlicingOptions options;
        options.toleranceRad = toleranceDeg * std::numbers::pi / 180.0;
        options.certify = certify;
        options.latticeSeeds = latticeSeeds;
        const PythonJobControl job(py::none(), cancel);
        const py::gil_scoped_release release;
        const scallop::JobControlScope scope(&job.control());  // the Gauss map and certificate poll it
        return scallop::optimalSlicing(surface, options);
      },
      py::arg("surface"), py::kw_only(), py::arg("tolerance_deg") = 0.5, py::arg("certify") = true,
      py::arg("lattice_seeds") = false, py::arg("cancel") = py::none(),
      "The optimal slicing orientation of a surface (Smith, Farouki, al-Kandari, Pottmann, CAGD 2002): the "
      "Gauss map's stereographic image, the medial axis of its complement, polished on the true surface and "
      "certified in Bernstein form. tolerance_deg: the Gauss map's polygon tolerance, in (0, 5.7) degrees. cancel: a CancelToken; once it is cancelled the call raises scallop.Cancelled.");

  // ---- tool paths
  py::class_<Paths> paths(m, "Paths", "The tool path of a surface, as `scallop paths` makes it (toolpath_job.hpp).");
  defPathFigures(paths, [](const Paths& p) -> const scallop::ToolpathResult& { return p.result; });
  paths
      .def_property_readonly(
          "orientation",
          [](const Paths& p) -> const scallop::OptimalSlicing* {
            return p.result.orientation ? &*p.result.orientation : nullptr;
          },
          py::return_value_policy::reference_internal, "The optimal orientation when N* was computed, else None.")
      .def(
          "gcode",
          [](const Paths& p, const std::string& dialect) {
            const scallop::GcodeOptions options = scallop::defaultGcodeOptions(
                p.surface, p.result.path, parseDialect(dialect),
                "scallop paths " + p.result.report.strategy + " " + p.result.report.source);
            return scallop::gcodeProgram(p.result.path, options);
          },
          py::arg("dialect") = "linuxcnc",
          "The G-code program (gcode.hpp) at the default feeds and safe height for the units: 'linuxcnc' "
          "(RS-274/NGC) or 'grbl'. Positions are the ball's tip.");

  m.def("paths", &runPaths, py::arg("surface"), py::arg("tool_radius"), py::arg("scallop_height") = py::none(),
        py::arg("spacing") = py::none(), py::arg("strategy") = "contour", py::kw_only(),
        py::arg("normal") = py::none(), py::arg("angle_deg") = py::none(), py::arg("constant_spacing") = false,
        py::arg("gouge_check") = true, py::arg("link") = true, py::arg("one_way") = false,
        py::arg("drop_envelope") = true, py::arg("rapid_rate") = py::none(), py::arg("source") = "surface",
        py::arg("progress") = py::none(), py::arg("cancel") = py::none(),
        "Tool paths over a surface (toolpath_job.hpp): contour on the optimal planes N* (or `normal`) or raster "
        "(feed angle `angle_deg`, default the best), planes from the scallop height H (0 < H < R) or a spacing, "
        "lifted to the gouge-free drop envelope, linked, and the ball checked against the whole surface. "
        "progress(fraction, stage) and cancel (a CancelToken) as for plan.");

  // ---- the whole job
  py::class_<Plan> planClass(m, "Plan",
                             "The main job's result (plan.hpp): tool path, G-code program, simulated cut, "
                             "orientation.");
  defPathFigures(planClass, [](const Plan& p) -> const scallop::ToolpathResult& { return p.result.toolpaths; });
  defSimulationFigures(planClass, [](const Plan& p) -> const scallop::SimulationReport& { return p.result.simulated; });
  planClass.def_property_readonly(
               "program", [](const Plan& p) { return p.result.program; }, "The G-code program.")
      .def_property_readonly(
          "program_name", [](const Plan& p) { return p.result.programName; },
          "toolpath.ngc (LinuxCNC) or toolpath.gcode (grbl).")
      .def_property_readonly(
          "orientation", [](const Plan& p) -> const scallop::OptimalSlicing& { return p.result.orientation; },
          py::return_value_policy::reference_internal, "The optimal slicing orientation N* the plan used.")
      .def(
          "files",
          [](const Plan& p) { return filesDict(scallop::planFiles(p.surface, p.result)); },
          "The files `scallop plan` writes, name -> contents: the G-code, report.json, verify.svg, paths.svg, "
          "paths-plan.svg, gauss-map.svg, stereographic.svg. Nothing is written to disk.");

  m.def("plan", &runPlan, py::arg("surface"), py::arg("tool_radius") = py::none(),
        py::arg("scallop_height") = py::none(), py::arg("spacing") = py::none(), py::arg("strategy") = "contour",
        py::arg("dialect") = "linuxcnc", py::kw_only(), py::arg("constant_spacing") = false, py::arg("link") = true,
        py::arg("one_way") = false, py::arg("drop_envelope") = true, py::arg("rest_finishing") = true,
        py::arg("rapid_rate") = py::none(), py::arg("source") = "surface", py::arg("progress") = py::none(),
        py::arg("cancel") = py::none(),
        "The main job, as `scallop plan` (plan.hpp): the optimal orientation N*, the tool path (contour on N* or "
        "raster) lifted to the drop envelope and linked, the G-code program, its cut simulated, and rest "
        "finishing where it leaves more than H. Defaults suit the units: a 0.25 in (6 mm) ball, H = 0.001 in "
        "(0.025 mm). progress: None or a callable (fraction, stage), called on this thread, fraction never "
        "decreasing and ending at 1; an exception it raises comes out of plan. cancel: a CancelToken; once "
        "cancelled (from any thread) plan raises scallop.Cancelled. The GIL is released meanwhile. The result "
        "is the same, byte for byte, for every thread count.");

  // ---- the simulated cut of a program
  py::class_<Verification> verification(
      m, "Verification", "The simulated cut of a G-code program against a surface (cut_simulation.hpp).");
  defSimulationFigures(verification,
                       [](const Verification& v) -> const scallop::SimulationReport& { return v.simulated; });
  verification.def_property_readonly(
      "report_json", [](const Verification& v) { return scallop::verifyToJson(v.simulated, v.sources); },
      "The figures as JSON, as `scallop verify --json` writes them (verify_output.hpp).");

  m.def("verify", &runVerify, py::arg("surface"), py::arg("program"), py::arg("tool_radius"),
        py::arg("scallop_height") = py::none(), py::kw_only(), py::arg("resolution") = py::none(),
        py::arg("gouge_tolerance") = py::none(), py::arg("stock_top") = py::none(),
        py::arg("stock_allowance") = py::none(), py::arg("source") = "surface",
        py::arg("program_name") = "program", py::arg("cancel") = py::none(),
        "Simulates a G-code program's cut (the text, as scallop's writer makes it: positions the ball's tip) "
        "with a ball of radius tool_radius on a z-map of the stock, and compares it with the surface: gouges "
        "(vertical), scallops (along the normal), area left above H (default 0.001 in / 0.025 mm), as "
        "`scallop verify`. scallop.Error names the program's line for what it cannot read. cancel: a CancelToken (scallop.Cancelled).");

  // ---- meshes: STL files, STEP and IGES parts through their tessellation, the mesh plan
  py::class_<scallop::Mesh>(
      m, "Mesh",
      "An indexed triangle mesh (mesh.hpp): vertices, triangles as three vertex indices each, one unit of "
      "length. The triangles' vertex order gives their normal, (b - a) x (c - a).")
      .def(py::init(&makeMesh), py::arg("vertices"), py::arg("triangles"), py::arg("units") = "mm",
           "Mesh(vertices, triangles, units='mm'): vertices an (n, 3) array of coordinates, triangles an (m, 3) "
           "array of vertex indices from 0; units 'mm' or 'in' ('inch'). The plans check the rest (indices in "
           "range, finite coordinates, at least one triangle) and raise scallop.Error.")
      .def_property_readonly(
          "units", [](const scallop::Mesh& mesh) { return std::string(scallop::unitsName(mesh.units)); },
          "\"in\" or \"mm\".")
      .def_property_readonly(
          "vertices",
          [](const scallop::Mesh& mesh) {
            py::array_t<double> out = matrix(mesh.vertices.size(), 3);
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
              const auto r = static_cast<py::ssize_t>(i);
              o(r, 0) = mesh.vertices[i].x;
              o(r, 1) = mesh.vertices[i].y;
              o(r, 2) = mesh.vertices[i].z;
            }
            return out;
          },
          "The vertices, an (n, 3) array (a copy).")
      .def_property_readonly(
          "triangles",
          [](const scallop::Mesh& mesh) {
            py::array_t<std::uint32_t> out({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
              for (std::size_t k = 0; k < 3; ++k)
                o(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(k)) = mesh.triangles[i][k];
            return out;
          },
          "The triangles, an (m, 3) uint32 array of vertex indices (a copy).")
      .def("__repr__", [](const scallop::Mesh& mesh) {
        return "<scallop.Mesh: " + std::to_string(mesh.triangles.size()) + " triangles, " +
               std::to_string(mesh.vertices.size()) + " vertices, units " +
               std::string(scallop::unitsName(mesh.units)) + ">";
      });

  py::class_<StlFile>(m, "StlMesh", "An STL file as read by load_stl: its mesh and what the file held.")
      .def_property_readonly(
          "mesh", [](const StlFile& f) -> const scallop::Mesh& { return f.stl.mesh; },
          py::return_value_policy::reference_internal, "The mesh (equal vertices merged, file order kept).")
      .def_readonly("path", &StlFile::path, "The file, as given: the plans' default source.")
      .def_property_readonly(
          "format",
          [](const StlFile& f) { return f.stl.format == scallop::StlFormat::binary ? "binary" : "ascii"; },
          "\"binary\" or \"ascii\".")
      .def_property_readonly(
          "triangles_read", [](const StlFile& f) { return f.stl.trianglesRead; }, "Triangles in the file.")
      .def_property_readonly(
          "zero_area_dropped", [](const StlFile& f) { return f.stl.zeroAreaDropped; },
          "Triangles of zero area skipped (drop_zero_area=True).")
      .def_property_readonly(
          "description", [](const StlFile& f) { return stlDescription(f.stl); },
          "How the plan's first stage names it, as `scallop plan` does: \"<m> triangles (binary STL)\".")
      .def("__repr__", [](const StlFile& f) {
        return "<scallop.StlMesh: " + f.path + ", " + stlDescription(f.stl) + ">";
      });

  m.def("load_stl", &loadStl, py::arg("path"), py::arg("units") = "mm", py::arg("drop_zero_area") = false,
        "Reads an STL file, binary or ASCII (told apart by its size, 84 + 50 n bytes, whatever its header says), "
        "into an indexed mesh (mesh.hpp's readStl). STL has no units: units 'mm' (default) or 'in'. The file's "
        "facet normals are ignored. scallop.Error names the file and what is wrong: empty, too short, "
        "truncated, a bad keyword or number (ASCII line), a coordinate not finite, a triangle of zero area "
        "(unless drop_zero_area: skipped and counted), no triangle.");

#ifdef SCALLOP_PYTHON_CAD
  m.attr("has_cad") = true;
  py::class_<scallop::CadPart>(
      m, "CadPart",
      "A STEP or IGES part whole, as OpenCASCADE models it (cad_tessellation.hpp): every face, trimmed or not. "
      "tessellate_part makes it ready for plan_mesh; its exact faces then judge the plan's simulated cut.")
      .def(py::init([](const std::string& path) {
             const py::gil_scoped_release release;
             return std::make_unique<scallop::CadPart>(path);
           }),
           py::arg("path"),
           "CadPart(path): reads a STEP (.step, .stp) or IGES (.iges, .igs) file, its format by the extension or "
           "the first line. Units: inches when the file says inches, else millimetres (OCCT converts the rest). "
           "scallop.Error names the file for one that cannot be opened, is empty, truncated, unparsable or "
           "holds no face.")
      .def_property_readonly("path", &scallop::CadPart::path, "The file, as given: the plans' default source.")
      .def_property_readonly(
          "format", [](const scallop::CadPart& part) { return std::string(scallop::cadFormatName(part.format())); },
          "\"STEP\" or \"IGES\".")
      .def_property_readonly(
          "units", [](const scallop::CadPart& part) { return std::string(scallop::unitsName(part.units())); },
          "\"in\" or \"mm\": every length of the part and of its plans.")
      .def_property_readonly("file_unit", &scallop::CadPart::fileUnit,
                             "The unit as the file names it (\"INCH\", \"MM\").")
      .def_property_readonly("faces", &scallop::CadPart::faces, "Its faces, every one tessellated.")
      .def_property_readonly(
          "box_low", [](const scallop::CadPart& part) { return vec3Array(part.boxLow()); },
          "The bounding box's lowest corner (OCCT's, without tolerances).")
      .def_property_readonly(
          "box_high", [](const scallop::CadPart& part) { return vec3Array(part.boxHigh()); },
          "The bounding box's highest corner.")
      .def("__repr__", [](const scallop::CadPart& part) {
        return "<scallop.CadPart: " + part.path() + ", " + std::string(scallop::cadFormatName(part.format())) + ", " +
               std::to_string(part.faces()) + " faces, units " + std::string(scallop::unitsName(part.units())) + ">";
      });

  py::class_<Tessellated>(
      m, "TessellatedPart",
      "A part's tessellation made ready for plan_mesh (tessellated_part.hpp): the mesh, how far the exact faces "
      "stand from it, the clearance the proofs add to R, and the exact faces as the simulated cut's judge. It "
      "keeps its CadPart alive.")
      .def_property_readonly(
          "mesh", [](const Tessellated& t) -> const scallop::Mesh& { return t.part.mesh; },
          py::return_value_policy::reference_internal, "The tessellation (the part's units).")
      .def_readonly("path", &Tessellated::path, "The part's file: the plans' default source.")
      .def_property_readonly(
          "description", [](const Tessellated& t) { return t.part.description; },
          "How the plan's first stage names the mesh (\"8302 triangles from 10 faces (STEP), ...\").")
      .def_property_readonly(
          "faces", [](const Tessellated& t) { return t.part.faces; }, "The part's faces, all tessellated.")
      .def_property_readonly(
          "deflection", [](const Tessellated& t) { return t.part.deflection; },
          "The mesher's linear deflection D, as asked.")
      .def_property_readonly(
          "deviation", [](const Tessellated& t) { return t.part.deviation; },
          "The largest distance found from the exact faces to their triangles (sampled: a measure, not a bound).")
      .def_property_readonly(
          "deviation_face", [](const Tessellated& t) { return t.part.deviationFace; },
          "The face where it occurs (numbered as the importer numbers them).")
      .def_property_readonly(
          "deviation_at", [](const Tessellated& t) { return vec3Array(t.part.deviationAt); },
          "And the exact face's point there.")
      .def_property_readonly(
          "clearance", [](const Tessellated& t) { return t.part.clearance; },
          "c = 1.5 x deviation, added to R in every proof against the mesh.")
      .def_property_readonly(
          "warnings", [](const Tessellated& t) { return t.part.warnings; },
          "What the caller should be told before the plan, one line each: e.g. that the clearance leaves more "
          "than 3/4 of H and the scallops may exceed it.")
      .def("__repr__", [](const Tessellated& t) { return "<scallop.TessellatedPart: " + t.part.description + ">"; });

  m.def(
      "tessellate_part",
      [](const scallop::CadPart& part, std::optional<double> deflection, std::optional<double> toolRadius,
         std::optional<double> scallopHeight, std::optional<double> spacing, const py::object& progress,
         const std::optional<scallop::CancelToken>& cancel) {
        scallop::PartMeshOptions options;
        options.deflection = deflection;
        options.toolRadius = toolRadius;
        options.scallopHeight = scallopHeight;
        options.spacing = spacing;
        options.deflectionOption = "deflection";  // the warnings name this keyword
        const PythonJobControl job(progress, cancel);
        Tessellated out;
        out.path = part.path();
        const py::gil_scoped_release release;
        out.part = scallop::tessellatePart(part, options, job.control());
        return out;
      },
      py::arg("part"), py::kw_only(), py::arg("deflection") = py::none(), py::arg("tool_radius") = py::none(),
      py::arg("scallop_height") = py::none(), py::arg("spacing") = py::none(), py::arg("progress") = py::none(),
      py::arg("cancel") = py::none(), py::keep_alive<0, 1>(),
      "A STEP or IGES part made ready for plan_mesh (tessellate_part.hpp), as `scallop plan` cuts a part whose "
      "faces cannot be machined exactly yet: OCCT's mesh of every face with linear deflection D (default H / "
      "8), the exact faces' deviation from it sampled, the clearance 1.5 x deviation, and the exact faces as "
      "the judge. tool_radius, scallop_height or spacing: the plan's, as plan_mesh will take them (they set "
      "the default D; defaults 0.25 in / 6 mm and 0.001 in / 0.025 mm by the part's units). warnings: one "
      "when clearance + deviation exceed 3/4 of H. progress and cancel as for plan (OCCT's mesher itself runs "
      "to its end). The result keeps the part alive.");
#else
  m.attr("has_cad") = false;
#endif

  py::class_<MeshPaths> meshPaths(m, "MeshPaths",
                                  "The raster of a mesh, as `scallop paths PART.stl` makes it (mesh_plan.hpp's "
                                  "meshToolpaths).");
  defPathFigures(meshPaths,
                 [](const MeshPaths& p) { return PathView{p.result.raster.path, p.result.report}; });
  defMeshRasterFigures(meshPaths, [](const MeshPaths& p) -> const scallop::MeshToolpathResult& { return p.result; });
  meshPaths.def(
      "gcode",
      [](const MeshPaths& p, const std::string& dialect) {
        const scallop::MeshToolpathResult& r = p.result;
        const scallop::GcodeOptions options =
            scallop::defaultGcodeOptions(r.report.units, r.partTop, r.raster.path, parseDialect(dialect),
                                         "scallop paths raster " + r.report.source);
        return scallop::gcodeProgram(r.raster.path, options);
      },
      py::arg("dialect") = "linuxcnc",
      "The G-code program `scallop paths PART.stl --gcode` writes (gcode.hpp): the default feeds, a safe height "
      "above the mesh and the path; 'linuxcnc' or 'grbl'. Positions are the ball's tip.");

  m.def("mesh_paths", &runMeshPaths, py::arg("mesh"), py::arg("tool_radius") = py::none(),
        py::arg("scallop_height") = py::none(), py::arg("spacing") = py::none(), py::kw_only(),
        py::arg("rapid_rate") = py::none(), py::arg("source") = py::none(), py::arg("description") = py::none(),
        py::arg("progress") = py::none(), py::arg("cancel") = py::none(),
        "The raster of a mesh (mesh_plan.hpp's meshToolpaths), as `scallop paths PART.stl`: lines along x, each "
        "the exact drop line of the ball, every move proven clear of the mesh within eps (1e-6 of its size), at "
        "most `spacing` apart or spaced for the scallop height H (0 < H < R) on the facets' slopes. mesh: a "
        "Mesh, an StlMesh (load_stl) or a TessellatedPart (tessellate_part: the proofs keep its clearance). "
        "source: the name in the report and the G-code title (default the file's path, or 'mesh'); "
        "description: the first stage's name for the mesh. Defaults suit the units: a 0.25 in (6 mm) ball, "
        "H = 0.001 in (0.025 mm). progress and cancel as for plan.");

  py::class_<MeshPlan> meshPlan(m, "MeshPlan",
                                "The whole plan of a mesh (mesh_plan.hpp's planMesh): raster, G-code program, "
                                "simulated cut, rest passes.");
  defPathFigures(meshPlan,
                 [](const MeshPlan& p) { return PathView{p.result.toolpaths.raster.path, p.result.toolpaths.report}; });
  defMeshRasterFigures(meshPlan,
                       [](const MeshPlan& p) -> const scallop::MeshToolpathResult& { return p.result.toolpaths; });
  defSimulationFigures(meshPlan,
                       [](const MeshPlan& p) -> const scallop::SimulationReport& { return p.result.simulated; });
  meshPlan
      .def_property_readonly(
          "program", [](const MeshPlan& p) { return p.result.program; }, "The G-code program.")
      .def_property_readonly(
          "program_name", [](const MeshPlan& p) { return p.result.programName; },
          "toolpath.ngc (LinuxCNC) or toolpath.gcode (grbl).")
      .def_property_readonly(
          "rest_rounds", [](const MeshPlan& p) { return p.result.toolpaths.report.restRounds.size(); },
          "Rounds of rest passes added where the simulated cut left more than H.")
      .def(
          "files",
          [](const MeshPlan& p) { return filesDict(scallop::meshPlanFiles(p.result)); },
          "The files `scallop plan PART.stl` writes, name -> contents: the G-code, report.json, verify.svg. "
          "Nothing is written to disk.");

  m.def("plan_mesh", &runMeshPlan, py::arg("mesh"), py::arg("tool_radius") = py::none(),
        py::arg("scallop_height") = py::none(), py::arg("spacing") = py::none(), py::arg("dialect") = "linuxcnc",
        py::kw_only(), py::arg("rest_finishing") = true, py::arg("rapid_rate") = py::none(),
        py::arg("source") = py::none(), py::arg("description") = py::none(), py::arg("progress") = py::none(),
        py::arg("cancel") = py::none(),
        "The main job on a mesh, as `scallop plan PART.stl` (mesh_plan.hpp's planMesh): mesh_paths' raster, the "
        "G-code program, its cut simulated (on the mesh, or on a TessellatedPart's exact faces), and with H "
        "(not a spacing) rest passes where it leaves more than H. mesh: a Mesh, an StlMesh or a "
        "TessellatedPart; source and description as for mesh_paths; the same options give the bytes the CLI "
        "writes (files()). Errors: scallop.Error naming the source (no triangle, an index out of range, a "
        "vertex not finite, R against the mesh's size, H not below R, a spacing and H both). progress: None or "
        "a callable (fraction, stage), on this thread, never decreasing, ending at 1; cancel: a CancelToken "
        "(scallop.Cancelled). The GIL is released meanwhile; the result is the same for every thread count.");

  m.def("set_thread_count", &scallop::setThreadCount, py::arg("threads"),
        "Sets the thread count of every parallel part (0: every core). Results do not depend on it.");
  m.def(
      "thread_count", [] { return scallop::threadCount(); }, "The thread count in use (>= 1).");
}
