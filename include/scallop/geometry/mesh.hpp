#pragma once
// Triangle meshes and STL input (issue 14, item 4: real parts come as STL from scanners and
// mesh modellers; OpenCAMLib and MeshLib start there).
//
// Contract of parseStl
// --------------------
// Input:  the bytes of an STL file, binary or ASCII, and the name to quote in messages. STL
//         carries no units: the caller says what they are.
// Format: binary when the size is exactly 84 + 50 n for the little-endian triangle count n
//         at byte 80 (whatever the 80-byte header says: many binary files begin with
//         "solid"); otherwise ASCII: `solid [name]`, then per triangle `facet normal a b c`,
//         `outer loop`, three `vertex x y z`, `endloop`, `endfacet`, and `endsolid [name]`;
//         keywords in any case, any whitespace between tokens, numbers as strtod reads them
//         (no hex, no inf or nan). Several solids in one file are read one after another.
//         The stored facet normals are ignored (many writers leave them zero or wrong); the
//         vertex order is kept, so the normal is (b - a) x (c - a).
// Output: an indexed mesh in the given units: vertices whose coordinates are equal are merged
//         (STL repeats every shared vertex per triangle), triangles as vertex indices in file
//         order.
// Errors: scallop::Error naming the file and what is wrong: empty, too short, a binary size
//         that does not match its count and is not ASCII either (truncated), no triangle, an
//         unexpected or missing keyword (ASCII line), a bad number, a coordinate that is not
//         finite (triangle index from 0, vertex 1 to 3, ASCII line, values), a triangle of
//         zero area (two equal vertices, or three exactly on a line: the cross product of its
//         edges, in double, is zero; index and coordinates) unless StlOptions::dropZeroArea
//         (then skipped and counted; a file with none left is refused), more than
//         kMaxStlTriangles.
// Cost:   linear in the size of the file: one pass, hash-merged vertices.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Budget: triangles in one STL file (a 50-million-triangle mesh is 2.5 GB as binary STL).
inline constexpr std::size_t kMaxStlTriangles = 50'000'000;

struct Mesh {
  Units units = Units::millimetre;
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< indices into `vertices`
};

/// Which STL form parseStl read.
enum class StlFormat { binary, ascii };

struct StlOptions {
  Units units = Units::millimetre;  ///< STL has none: what the coordinates are in
  /// Skip triangles of zero area (counted in StlMesh) instead of refusing the file. They add
  /// no surface, but a file full of them is suspect, so the default refuses; real exports do
  /// carry a few (OpenCAMLib's own test part beet_mm.stl has one of 4,630: three points on a
  /// line).
  bool dropZeroArea = false;
};

struct StlMesh {
  Mesh mesh;
  StlFormat format = StlFormat::binary;
  std::size_t trianglesRead = 0;        ///< triangles in the file
  std::size_t zeroAreaDropped = 0;      ///< with dropZeroArea
  std::size_t firstZeroArea = 0;        ///< the first one's index (when any were dropped)
};

/// See the contract.
StlMesh parseStl(std::string_view bytes, const std::string& sourceName, const StlOptions& options);

/// Whether bytes are STL by their content, as parseStl tells the forms apart: the size of a
/// binary STL (exactly 84 + 50 n for the count n at byte 80; `size` is the whole file's, `head`
/// its first bytes, at least 84 of them when there are), or text that begins, past blanks and a
/// UTF-8 byte order mark, with "solid" (any case) and a blank or its end. A surface's JSON
/// begins with '{' and .bpt with a number; text's bytes 80-83 would count more than 500 million
/// triangles, which no text file of that size holds.
bool looksLikeStl(std::string_view head, std::uint64_t size);

/// parseStl on the whole file at `path` ("-": standard input).
StlMesh readStl(const std::string& path, const StlOptions& options);

/// The unit normal of triangle `t` ((b - a) x (c - a), normalised); zero for a degenerate one.
Vec3 triangleNormal(const Mesh& mesh, std::size_t t);

}  // namespace scallop
