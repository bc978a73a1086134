#pragma once
// A STEP or IGES part whole, as OpenCASCADE models it: every face, trimmed or not, rational
// or not, of any surface kind (issue 14). cad_import.hpp turns faces into scallop's exact
// Bezier patches, but only faces that are untrimmed, polynomial parameter rectangles; most
// faces of real parts are trimmed, and every cylinder, cone, sphere and torus is rational.
// Until the core handles both exactly, such a part is machined through two things this
// header gives:
//   - its tessellation: a triangle mesh of every face (OCCT's BRepMesh), with the distance
//     from the exact faces to their triangles measured. `scallop plan` cuts the mesh by
//     raster (mesh_raster.hpp) with the ball's clearance raised by that deviation;
//   - its exact heights: the highest point of the exact, trimmed faces on the vertical line
//     through each point of a grid (OCCT's line-face intersection, which honours the
//     trimming curves). This is the design `scallop verify` judges a program against on
//     such a part: a judge independent of the mesh the plan was cut on.
// This header is OpenCASCADE-free; the implementation is in the scallop::cad target.
//
// Contract of CadPart
// -------------------
// Input:  a STEP or IGES file (cad_import.hpp's contract for the file: formats, units, the
//         errors of an empty, truncated or unparsable file, of one with no face; the same
//         messages). The faces are numbered as cad_import.hpp numbers them.
// Tessellation (tessellate): OCCT's BRepMesh_IncrementalMesh on the whole shape, run
//         sequentially (the same file gives the same mesh, bit for bit) with linear
//         deflection D (TessellationOptions::deflection, in the file's units) and angular
//         deflection A. Any earlier triangulation of the shape is cleared first. Every
//         face's triangles are placed (the face's location), oriented (a REVERSED face's
//         triangles are reversed, so (b - a) x (c - a) points out of the material), and their
//         vertices merged where their coordinates are equal (BRepMesh discretises a shared
//         edge once, so neighbouring faces meet at the same points). A triangle whose
//         corners coincide after merging or whose cross product is zero adds no surface and
//         is dropped (counted).
//         Refused: D not finite or below 1e-6 of the part's bounding-box diagonal (the mesh
//         would outgrow any budget), A outside (0, pi/2], a face BRepMesh leaves without
//         triangles (named as cad_import.hpp names faces), more than maxTriangles.
// Deviation: per triangle, the exact face is evaluated at the 12 points of the barycentric
//         lattice of step 1/4 in the triangle's parameter-space corners that are not corners
//         (the parameter triangles tile the trimmed face, so every part of every face is
//         sampled), and their distances to the triangle are measured; the largest is
//         `deviation`, with where it occurs. Sampled, not proven: between samples the
//         distance may be larger (for a smooth face, whose distance to a small triangle is
//         close to a quadratic that vanishes at its corners, by a few per cent). Callers
//         that need a bound add a margin; `scallop plan` uses 1.5 times it and the judge
//         below checks the result. At the same points the angle between the exact face's
//         normal (BRepAdaptor_Surface::D1; a point where it vanishes is skipped) and the
//         triangle's, as lines, gives normalDeviationRad: how far `scallop orient`'s facet
//         normals may stand from the part's.
// Heights (designHeights): for each point (x, y) of the grid inside the part's xy bounding
//         box, the vertical line through it is intersected with every face
//         (IntCurvesFace_ShapeIntersector: exact surfaces, points classified against the
//         face's trimming curves to OCCT's confusion tolerance 1e-7) and the highest point
//         found is the height; no point: -infinity. |n_z| of the face's unit normal there
//         (BRepAdaptor_Surface::D1) goes to `normalZ` (1 where the face is singular).
//         Exact up to OCCT's intersection tolerance; a line through an edge between faces
//         may miss both and report the surface below (a deeper design: never a false
//         gouge), as may a line along a vertical face. The grid's points are split among
//         `threads` threads (0: the hardware's), each with its own intersector; the result
//         does not depend on the number of threads. The caller's job control
//         (job_control.hpp) is polled per line on every thread (scallop::Cancelled) and
//         advanced per row on the calling thread; tessellate polls it per face.
//         Budget: more than maxRays lines is an error naming the grid and the budget (at
//         roughly 100-300 us per line, 1,000,000 lines is a few minutes).
// Errors: scallop::Error, one line naming the file and, for a face, "face N" with its entity.
// Threads: reading and tessellating hold cad_import.hpp's process-wide mutex.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scallop/parallel.hpp"
#include "scallop/cad/cad_import.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

struct TessellationOptions {
  double deflection = 0.0;                ///< D > 0, BRepMesh's linear deflection (file units)
  double angularDeflection = 0.35;        ///< A in (0, pi/2], radians (about 20 degrees)
  std::size_t maxTriangles = 20'000'000;  ///< budget
};

struct CadTessellation {
  Mesh mesh;                                  ///< in the file's units
  std::vector<std::uint32_t> triangleFaces;   ///< per triangle, its face
  double deflection = 0.0;                    ///< D as asked
  double deviation = 0.0;                     ///< sampled max distance, exact face to its triangles
  Vec3 deviationAt;                           ///< the exact face's point where it occurs
  std::size_t deviationFace = 0;              ///< and its face
  std::size_t deviationSamples = 0;           ///< points evaluated
  /// The largest angle between the exact face's unit normal and its triangle's, over the same
  /// samples (as lines: the sense ignored; radians).
  double normalDeviationRad = 0.0;
  /// The exact faces' unit normals (as D1 gives them, the face's orientation ignored) at
  /// every node of every face's triangulation and at the 3 interior points of each
  /// triangle's lattice: `scallop orient`'s sample of the part's Gauss map.
  std::vector<Vec3> sampledNormals;
  std::size_t degenerateTriangles = 0;        ///< dropped (no area)
  double seconds = 0.0;
};

struct ExactHeightOptions {
  unsigned threads = 0;               ///< 0: threadCount() (parallel.hpp)
  std::size_t maxRays = 1'000'000;    ///< budget: vertical lines intersected
};

class CadPart {
 public:
  /// Reads `path`, its format by cadFormatOf (scallop::Error when it names none).
  explicit CadPart(const std::string& path);
  CadPart(const std::string& path, CadFormat format);
  ~CadPart();
  CadPart(CadPart&&) noexcept;
  CadPart& operator=(CadPart&&) noexcept;

  const std::string& path() const;
  CadFormat format() const;
  Units units() const;
  const std::string& fileUnit() const;  ///< as the file names it ("INCH", "MM")
  std::size_t faces() const;
  Vec3 boxLow() const;   ///< the part's bounding box (OCCT's BRepBndLib::AddOptimal, without tolerances)
  Vec3 boxHigh() const;

  /// The faces cad_import.hpp converts to exact Bezier patches, and those it cannot (as
  /// importCad with skipUnsupportedFaces, but a part with none left is not refused: its
  /// surface is then empty). No faces skipped: the part can be planned exactly. `options`
  /// as importCad's (acceptRational, acceptTrimmed: orient's); skipUnsupportedFaces is set.
  CadImport exactFaces(CadImportOptions options = {}) const;

  /// See the contract's Tessellation and Deviation.
  CadTessellation tessellate(const TessellationOptions& options) const;

  /// See the contract's Heights: fills grid.z (and normalZ, when given, sized as grid.z).
  void designHeights(HeightGrid& grid, std::vector<double>* normalZ = nullptr,
                     const ExactHeightOptions& options = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scallop
