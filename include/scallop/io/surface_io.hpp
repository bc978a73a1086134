#pragma once
// Surfaces in the .bpt text form (Bezier patch text, the form the Utah teapot circulates in),
// and the selection of some patches of a surface by index ("4-7,12").
//
// .bpt format
// -----------
//   line 1:      P, the number of patches (an integer >= 1)
//   per patch:   a line "m n", its degrees (integers, 1 <= m, n <= kMaxPatchDegree), then
//                (m + 1)(n + 1) lines "x y z", the control points row by row: the point on
//                line j (n + 1) + k of the patch is p_jk, the coefficient of b_j^m(u) b_k^n(v)
//                (row j runs along v), as in the JSON format of surface.hpp.
// Fields are separated by blanks or tabs; blank lines are skipped anywhere, CRLF line ends and a
// UTF-8 byte order mark are accepted; there are no comments. Coordinates are decimal numbers
// (std::from_chars, correctly rounded: "1.4" here and in JSON give the same double) and must
// be finite. Nothing may follow the last patch. The format has no units: a .bpt surface is in
// inches (Units::inch), as Newell's teapot is.
//
// Contract
// --------
// parseBptSurface returns the surface the text describes, validated as parseSurface's is
// (SurfaceCheck::full) or checked for form only (SurfaceCheck::formOnly, see surface.hpp).
// Every malformed text is a scallop::Error naming the source ("<stdin>" for "-"), the line
// (1-based) and the offending text, e.g.
//   "t.bpt:18: patches[0]: expected control point p_3,3 'x y z', three numbers, got '1.5 0'";
//   "t.bpt:1: expected the number of patches, an integer >= 1, got '0'".
// Validation errors are "<source>: patches[i]...: ..." as for JSON. Time and memory O(size).
//
// parsePatchSelection reads a list of patch indices: comma-separated items, each an index i
// or an inclusive range i-j (i <= j), 0-based, blanks around items allowed, e.g. "4", "4-7,12".
// It returns the indices in increasing order; an index listed twice, an index >= the number
// of patches, an empty item or anything else is a scallop::Error quoting the item and the
// valid range. selectPatches keeps the patches at the given indices, in that order (units
// kept), and performs no validation.

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scallop/geometry/surface.hpp"

namespace scallop {

/// Parses a surface from .bpt text (see the format above); `sourceName` (a file name, or "-"
/// for standard input) is used in error messages. The units are inches.
Surface parseBptSurface(std::string_view text, const std::string& sourceName,
                        SurfaceCheck check = SurfaceCheck::full);

/// The indices that `selection` ("4-7,12") names among `patchCount` patches, increasing.
std::vector<std::size_t> parsePatchSelection(std::string_view selection, std::size_t patchCount);

/// The surface made of `surface.patches[i]` for i in `indices`, in that order; throws
/// scallop::Error for an index out of range. No validation.
Surface selectPatches(const Surface& surface, std::span<const std::size_t> indices);

/// Reads, parses and validates a surface file ("-" reads standard input): .bpt text
/// (above, in inches) when the name ends in ".bpt", JSON when it ends in ".json",
/// otherwise JSON if the text's first non-blank character is '{' and .bpt if not.
Surface readSurface(const std::string& path, SurfaceCheck check = SurfaceCheck::full);

}  // namespace scallop
