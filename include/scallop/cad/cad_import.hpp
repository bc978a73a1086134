#pragma once
// STEP and IGES input through OpenCASCADE (issue 14, item 1): every face of the file becomes
// Bezier patches of a scallop::Surface, exactly, or the face is refused with the reason.
// This header is OpenCASCADE-free; the library target scallop::cad (src/cad_import.cpp)
// links OCCT's toolkits, so the core scallop::scallop does not depend on them.
//
// Contract of importCad
// ---------------------
// Input:  a STEP (ISO 10303-21: AP203/AP214/AP242) or IGES 5.x file. Its faces are visited in
//         the order of OCCT's TopExp_Explorer over the transferred shape (every occurrence of a
//         face in an assembly is a face of its own, placed), numbered from 0: "face N".
// Units:  the file's length unit: inches when the file says inches (STEP: every length unit
//         of its shape representations is INCH; IGES: unit flag 1, or 3 with the name IN or
//         INCH), Units::inch and coordinates in inches; otherwise OCCT converts to
//         millimetres, Units::millimetre.
// Faces:  per face, its surface with the face's location applied (BRep_Tool::Surface):
//         - kinds: B-spline and Bezier surfaces as they are; planes, cylinders, cones,
//           spheres, tori, and extrusions and revolutions of lines, conics, B-spline and
//           Bezier curves through GeomConvert::SurfaceToBSplineSurface (exact: OCCT's
//           conversion of these is algebraic); an offset surface only when OCCT knows an
//           equivalent surface of one of those kinds (the offset of a plane is a plane).
//           Every other kind (offsets of free-form surfaces, offset curves swept: OCCT would
//           approximate them) is refused. The conversion is checked against OCCT's own
//           evaluation of the original surface at 5 x 5 points of the face (relative
//           distance <= 1e-9 of the face's size), so no approximation slips through.
//         - trimming: the face must be a parameter rectangle of its surface: one wire, every
//           edge's pcurve an iso-line (a 2D line along u or v, or a B-spline/Bezier whose
//           poles all share that u or v) on one side of the face's UV bounding box
//           [u0, u1] x [v0, v1] (to the edge's tolerance in parameter space), the four sides
//           covered (collapsed sides, as at a pole, by degenerate edges). The surface is then
//           restricted exactly to that rectangle (knot insertion, Geom_BSplineSurface::Segment)
//           when it is smaller than the surface's own.
//         - splitting: the B-spline is made non-periodic and split at every interior knot
//           into Bezier patches (GeomConvert_BSplineSurfaceToBezierSurface, exact up to the
//           rounding of knot insertion), in order u-interval major, v-interval minor. The
//           patch's p_jk is the Bezier piece's pole (j + 1, k + 1): scallop's u and v are
//           OCCT's, so r_u x r_v is OCCT's surface normal.
//         - orientation: a REVERSED face (its material on the other side of the surface
//           normal) has its patches' u reversed (p_jk -> p_{m-j,k}), so r_u x r_v points out
//           of the material as the face says; a FORWARD face keeps the surface's.
//         - rational: a face whose Bezier pieces are not all polynomial (some piece's weights
//           differ by more than 1e-14 relative: every exact cylinder, cone, sphere, torus
//           and revolution) is refused, with the range of its weights, unless
//           CadImportOptions::acceptRational: then each piece is a rational patch, its poles
//           and weights as they are (a REVERSED face's reversed alike). Approximating
//           silently is not allowed. A piece whose weights are all equal is polynomial.
//         - trimmed faces (CadImportOptions::acceptTrimmed; otherwise refused as "trimmed"):
//           a face that is not a parameter rectangle is converted on the rectangle of its
//           pcurves' bounds (BRepTools::UVBounds, snapped to the period on periodic surfaces)
//           and each Bezier patch split by trimmed_patch.hpp's splitTrimmedPatch against the
//           face's trimming curves. Cells are classified in the face's own parameters: a
//           patch's (s, t) maps to the B-spline's (U, V) affinely, and (U, V) to the surface's
//           (u, v) by u = phi(U), v = psi(V): the identity (up to the period) for B-spline
//           and Bezier surfaces, the inverse of OCCT's conversion for the others (computed
//           by ElSLib's closed forms for quadrics and projection for swept surfaces, and
//           checked to be separable: u independent of V and v of U at the quarter points).
//           phi and psi are monotone (a conic's rational parametrisation is), so a cell maps
//           onto the box [phi(U0), phi(U1)] x [psi(V0), psi(V1)], widened by 1e-8 of the
//           rectangle. Every pcurve (lines, conics, B-spline and Bezier curves; offset curves
//           are refused) is converted exactly to rational Bezier arcs; a cell's box that no
//           arc's control polygon box meets (arcs subdivided until their boxes are an eighth
//           of the cell's) lies wholly inside or outside the face, decided at its centre by
//           the parity of the arcs' winding number (face_trim.hpp's classifyBox; each edge's
//           arcs run as its wire does, so the loops close); a box that some arc may meet, or
//           whose centre the winding cannot decide, is "boundary". CadImport::faceTrims keeps
//           the arcs.
//           CadImport::patchRoles tells the pieces apart; at most maxTrimPieces in all.
//         - validity: each patch must satisfy surface.hpp's contract (degree <= 20, regular);
//           a face with a patch that does not is refused with validateSurface's reason.
// Output: the surface (at least one patch), and per patch the face it came from.
// Errors: scallop::Error, one line naming the file and, for a face, "face N" with its entity
//         in the file where OCCT tells it (STEP "#123", IGES "D45"), the reason and the
//         values, e.g.
//           "part.step: face 3 (#812) is rational (weights 0.707107 to 1, a cylinder): rational
//            faces are not supported yet".
//         File errors: cannot open; empty; not STEP (no "ISO-10303-21;" at the start) or not
//         IGES (no start line 'S' in column 73); truncated (a STEP file without its
//         "END-ISO-10303-21;", an IGES file whose terminate line is missing or whose section
//         counts disagree with its lines); OCCT cannot parse it; no face in it. With
//         CadImportOptions::skipUnsupportedFaces, refused faces are listed in `skipped`
//         instead (the file is still refused when no face is left). Nothing is written.
// Determinism: the same file gives the same patches, bit for bit.
// Threads: OCCT's reader parameters and message printers are process-wide: calls are
//         serialised by a mutex. OCCT's console messages are silenced during a call.
// Cost:   OCCT's parse and transfer (about 1 s for a 2 MB STEP file), then per face linear in
//         its poles, plus surface.hpp's regularity check per patch.

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scallop/geometry/face_trim.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/trimmed_patch.hpp"

namespace scallop {

enum class CadFormat {
  step,  ///< ISO 10303-21 (.step, .stp)
  iges,  ///< IGES (.iges, .igs)
};

/// "STEP" or "IGES".
std::string_view cadFormatName(CadFormat format);

/// The CAD format of `path`: by its extension (.step, .stp, .iges, .igs, in any case), else
/// by its first bytes ("ISO-10303-21;" for STEP; an 80-column start line with 'S' in column
/// 73 for IGES); nullopt for anything else, for a file that cannot be read, and for "-".
std::optional<CadFormat> cadFormatOf(const std::string& path);

struct CadImportOptions {
  /// Skip faces that cannot be imported exactly (rational, trimmed, of an unsupported kind,
  /// not regular) instead of refusing the file; they are listed in CadImport::skipped.
  bool skipUnsupportedFaces = false;
  /// Rational faces become rational Bezier patches (bezier.hpp: poles and weights, exactly)
  /// instead of being refused (every command takes them: the CLI sets this).
  bool acceptRational = false;
  /// Trimmed faces (not a parameter rectangle of their surface) become pieces of their Bezier
  /// patches that follow the trimming curves (trimmed_patch.hpp) instead of being refused: for
  /// `scallop orient`, whose Gauss map then sees only the face's normals (see the contract's
  /// "trimmed faces"). The other computations take untrimmed faces only.
  bool acceptTrimmed = false;
  /// With acceptTrimmed: a trimmed face's patches that meet it are kept whole, each with its
  /// trim (surface.hpp's trims: the face's arcs and the map of its parameters), instead of as
  /// pieces; for `plan`, `paths` and `verify`, whose sections, distances and simulated cut
  /// then take exactly the face's part. Each patch parameter maps onto the face's either
  /// affinely (B-spline and Bezier faces, planes, the heights of cylinders and cones) or by
  /// half-angles (face_trim.hpp's AxisMap: the angles of cylinders, cones, spheres, tori and
  /// revolutions, whose OCCT conversions are rational quadratic circles), fitted through
  /// three points and checked against OCCT's parameters at the seven inner eighths; a face
  /// where neither fits is refused as "trimmed". The pieces are still made, for the budget
  /// and to check the patches are regular where the face is.
  bool keepTrims = false;
  /// How finely boundary pieces follow the trimming curves (per patch).
  TrimSplitOptions trimSplit{};
  /// Budget of pieces over all trimmed faces of the file, a rational piece counting
  /// kRationalPieceWeight: past it, scallop::Error naming the face (with skipUnsupportedFaces,
  /// the face is skipped). Measured in `scallop orient`: OCCT's bearing.iges, 11,336
  /// polynomial pieces, 7 s; linkrods.step's 4,331 mostly rational pieces at 8 degrees,
  /// 500 s (their Gauss map's polynomials are of bidegree 10m - 4, not 6m - 4).
  std::size_t maxTrimPieces = 20000;
};

/// What a rational piece counts against CadImportOptions::maxTrimPieces.
inline constexpr std::size_t kRationalPieceWeight = 10;

/// Why a face was refused.
enum class CadFaceIssue {
  rational,            ///< some Bezier piece has unequal weights
  trimmed,             ///< the face is not a parameter rectangle of its surface
  unsupportedSurface,  ///< a kind OCCT can only approximate, or a conversion that failed
  invalidPatch,        ///< a patch breaks surface.hpp's contract (degree > 20, not regular)
};

/// "rational", "trimmed", "unsupported surface", "invalid patch".
std::string_view cadFaceIssueName(CadFaceIssue issue);

/// A face left out with CadImportOptions::skipUnsupportedFaces.
struct SkippedFace {
  std::size_t face = 0;  ///< its index, as in messages
  CadFaceIssue issue = CadFaceIssue::trimmed;
  std::string reason;    ///< the message the face would have raised, without the file name
};

struct CadImport {
  Surface surface;                       ///< the accepted faces' patches, validated
  CadFormat format = CadFormat::step;
  std::string fileUnit;                  ///< the file's length unit as it names it ("INCH", "MM")
  std::size_t faces = 0;                 ///< faces in the file
  std::vector<std::size_t> patchFaces;   ///< per patch of `surface`, its face
  std::vector<SkippedFace> skipped;      ///< faces left out (skipUnsupportedFaces)
  /// Per patch: inside its face, or a boundary piece of a trimmed face (acceptTrimmed; a
  /// boundary piece may reach beyond the trimming curve by less than its cell).
  std::vector<PieceRole> patchRoles;
  std::size_t trimmedFaces = 0;          ///< faces taken as pieces (acceptTrimmed)
  /// Per trimmed face (acceptTrimmed), by its index: its trimming arcs in its own parameters,
  /// as the pieces were classified against them (face_trim.hpp).
  std::map<std::size_t, FaceTrim> faceTrims;
  double largestSpreadRad = 0.0;         ///< over boundary pieces (trimmed_patch.hpp's spread)
  double seconds = 0.0;                  ///< wall time of the import
};

/// Reads `path` as `format` (see the contract).
CadImport importCad(const std::string& path, CadFormat format, const CadImportOptions& options = {});

/// importCad with the format from cadFormatOf; scallop::Error when it names none.
CadImport importCad(const std::string& path, const CadImportOptions& options = {});

}  // namespace scallop
