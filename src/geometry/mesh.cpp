#include "scallop/geometry/mesh.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <unordered_map>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "support/input_file.hpp"

namespace scallop {
namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kTriangleBytes = 50;

std::uint32_t littleEndian32(const char* p) {
  const auto b = [&](int i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(p[i])); };
  return b(0) | (b(1) << 8) | (b(2) << 16) | (b(3) << 24);
}

float littleEndianFloat(const char* p) { return std::bit_cast<float>(littleEndian32(p)); }

// Vertices merged by their exact coordinates (-0 taken as +0).
class VertexMerger {
 public:
  explicit VertexMerger(Mesh& mesh) : mesh_(mesh) {}

  std::uint32_t index(Vec3 p) {
    const Key key{std::bit_cast<std::uint64_t>(p.x + 0.0), std::bit_cast<std::uint64_t>(p.y + 0.0),
                  std::bit_cast<std::uint64_t>(p.z + 0.0)};
    const auto [it, inserted] = indices_.try_emplace(key, static_cast<std::uint32_t>(mesh_.vertices.size()));
    if (inserted) mesh_.vertices.push_back({p.x + 0.0, p.y + 0.0, p.z + 0.0});
    return it->second;
  }

 private:
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 1469598103934665603ull;
      for (const std::uint64_t word : k) h = (h ^ word) * 1099511628211ull, h ^= h >> 29;
      return static_cast<std::size_t>(h);
    }
  };
  Mesh& mesh_;
  std::unordered_map<Key, std::uint32_t, KeyHash> indices_;
};

// One triangle checked (finite, not of zero area) and added. `lines`: the ASCII lines of its
// vertices (none for binary), for the messages.
void addTriangle(const std::string& source, std::size_t triangle, const std::array<Vec3, 3>& corners,
                 VertexMerger& merger, StlMesh& out, const StlOptions& options,
                 const std::array<std::size_t, 3>* lines) {
  Mesh& mesh = out.mesh;
  const auto where = [&](std::size_t k) {
    return lines ? fmt::format("{}:{}: triangle {}, vertex {}", source, (*lines)[k], triangle, k + 1)
                 : fmt::format("{}: triangle {}, vertex {}", source, triangle, k + 1);
  };
  for (std::size_t k = 0; k < 3; ++k) {
    const Vec3& p = corners[k];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(fmt::format("{} ({}, {}, {}) is not finite", where(k), p.x, p.y, p.z));
  }
  const Vec3 n = cross(corners[1] - corners[0], corners[2] - corners[0]);
  if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0 && options.dropZeroArea) {
    if (out.zeroAreaDropped++ == 0) out.firstZeroArea = triangle;
    return;
  }
  if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0)
    throw Error(fmt::format("{}: triangle {} has zero area: its vertices ({}, {}, {}), ({}, {}, {}), ({}, {}, {}) {}",
                            lines ? fmt::format("{}:{}", source, (*lines)[0]) : source, triangle, corners[0].x,
                            corners[0].y, corners[0].z, corners[1].x, corners[1].y, corners[1].z, corners[2].x,
                            corners[2].y, corners[2].z,
                            corners[0] == corners[1] || corners[1] == corners[2] || corners[0] == corners[2]
                                ? "repeat a point"
                                : "lie on a line"));
  if (mesh.triangles.size() >= kMaxStlTriangles)
    throw Error(fmt::format("{}: more than {} triangles; not read", source, kMaxStlTriangles));
  mesh.triangles.push_back({merger.index(corners[0]), merger.index(corners[1]), merger.index(corners[2])});
}

StlMesh parseBinary(std::string_view bytes, const std::string& source, const StlOptions& options) {
  StlMesh out;
  out.format = StlFormat::binary;
  out.mesh.units = options.units;
  const std::size_t count = littleEndian32(bytes.data() + kHeaderBytes);
  if (count > kMaxStlTriangles)
    throw Error(fmt::format("{}: {} triangles; more than {} not read", source, count, kMaxStlTriangles));
  out.mesh.triangles.reserve(count);
  VertexMerger merger(out.mesh);
  for (std::size_t t = 0; t < count; ++t) {
    const char* record = bytes.data() + kHeaderBytes + 4 + t * kTriangleBytes + 12;  // past the normal
    std::array<Vec3, 3> corners;
    for (std::size_t k = 0; k < 3; ++k) {
      const char* p = record + 12 * k;
      corners[k] = {littleEndianFloat(p), littleEndianFloat(p + 4), littleEndianFloat(p + 8)};
    }
    addTriangle(source, t, corners, merger, out, options, nullptr);
  }
  out.trianglesRead = count;
  return out;
}

// ASCII STL: tokens with their line numbers.
class AsciiReader {
 public:
  AsciiReader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  bool atEnd() {
    skipSpace();
    return position_ >= text_.size();
  }

  std::string_view token() {
    skipSpace();
    const std::size_t start = position_;
    while (position_ < text_.size() && !isSpace(text_[position_])) ++position_;
    return text_.substr(start, position_ - start);
  }

  // The rest of the current line (a solid's name), without the line break.
  void skipRestOfLine() {
    while (position_ < text_.size() && text_[position_] != '\n') ++position_;
  }

  void expect(std::string_view keyword) {
    const std::string_view got = token();
    if (!same(got, keyword))
      throw Error(fmt::format("{}:{}: expected '{}', found {}", source_, line_, keyword,
                              got.empty() ? std::string("the end of the file") : fmt::format("'{}'", clip(got))));
  }

  double number() {
    const std::string_view got = token();
    double value = 0.0;
    const auto [end, error] = std::from_chars(got.data(), got.data() + got.size(), value);
    if (got.empty() || error != std::errc() || end != got.data() + got.size())
      throw Error(fmt::format("{}:{}: expected a number, found {}", source_, line_,
                              got.empty() ? std::string("the end of the file") : fmt::format("'{}'", clip(got))));
    return value;
  }

  std::size_t line() const { return line_; }

  static bool same(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
    return true;
  }

  // A token quoted in a message: at most 40 characters, unprintable ones as '?'.
  static std::string clip(std::string_view s) {
    std::string out(s.substr(0, 40));
    for (char& c : out)
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    return s.size() > 40 ? out + "..." : out;
  }

 private:
  static bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
  void skipSpace() {
    while (position_ < text_.size() && isSpace(text_[position_])) {
      if (text_[position_] == '\n') ++line_;
      ++position_;
    }
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t position_ = 0;
  std::size_t line_ = 1;
};

StlMesh parseAscii(std::string_view text, const std::string& source, const StlOptions& options) {
  StlMesh out;
  out.format = StlFormat::ascii;
  out.mesh.units = options.units;
  VertexMerger merger(out.mesh);
  AsciiReader reader(text, source);
  std::size_t triangle = 0;
  while (!reader.atEnd()) {
    reader.expect("solid");
    reader.skipRestOfLine();
    for (;;) {
      const std::string_view keyword = reader.token();
      if (AsciiReader::same(keyword, "endsolid")) {
        reader.skipRestOfLine();
        break;
      }
      if (!AsciiReader::same(keyword, "facet"))
        throw Error(fmt::format("{}:{}: expected 'facet' or 'endsolid', found {}", source, reader.line(),
                                keyword.empty() ? std::string("the end of the file") : fmt::format("'{}'", AsciiReader::clip(keyword))));
      reader.expect("normal");
      for (int k = 0; k < 3; ++k) static_cast<void>(reader.number());  // ignored (see the contract)
      reader.expect("outer");
      reader.expect("loop");
      std::array<Vec3, 3> corners;
      std::array<std::size_t, 3> lines{};
      for (std::size_t k = 0; k < 3; ++k) {
        reader.expect("vertex");
        lines[k] = reader.line();
        const double x = reader.number(), y = reader.number(), z = reader.number();
        corners[k] = {x, y, z};
      }
      reader.expect("endloop");
      reader.expect("endfacet");
      addTriangle(source, triangle, corners, merger, out, options, &lines);
      ++triangle;
    }
  }
  out.trianglesRead = triangle;
  return out;
}

}  // namespace

StlMesh parseStl(std::string_view bytes, const std::string& sourceName, const StlOptions& options) {
  if (bytes.empty()) throw Error(fmt::format("{}: the file is empty; an STL mesh was expected", sourceName));
  const bool binarySized = bytes.size() >= kHeaderBytes + 4 &&
                           bytes.size() == kHeaderBytes + 4 + kTriangleBytes * static_cast<std::size_t>(
                                                                   littleEndian32(bytes.data() + kHeaderBytes));
  StlMesh out;
  if (binarySized) {
    out = parseBinary(bytes, sourceName, options);
  } else {
    // Not the size of a binary STL: ASCII, which begins with "solid".
    std::size_t first = 0;
    while (first < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[first]))) ++first;
    if (!AsciiReader::same(bytes.substr(first, std::min<std::size_t>(5, bytes.size() - first)), "solid")) {
      if (bytes.size() < kHeaderBytes + 4)
        throw Error(fmt::format("{}: {} bytes: too short for a binary STL (84 bytes and 50 per triangle) and not ASCII "
                                "STL (which begins with 'solid')",
                                sourceName, bytes.size()));
      const std::size_t count = littleEndian32(bytes.data() + kHeaderBytes);
      throw Error(fmt::format("{}: {} bytes, but its header counts {} triangles ({} bytes): truncated or not an STL "
                              "file (and not ASCII STL, which begins with 'solid')",
                              sourceName, bytes.size(), count,
                              kHeaderBytes + 4 + kTriangleBytes * static_cast<double>(count)));
    }
    out = parseAscii(bytes, sourceName, options);
  }
  if (out.mesh.triangles.empty())
    throw Error(out.zeroAreaDropped > 0
                    ? fmt::format("{}: no triangle of positive area in the file ({} of zero area)", sourceName,
                                  out.zeroAreaDropped)
                    : fmt::format("{}: no triangle in the file", sourceName));
  return out;
}

bool looksLikeStl(std::string_view head, std::uint64_t size) {
  if (head.size() >= kHeaderBytes + 4 &&
      size == kHeaderBytes + 4 + static_cast<std::uint64_t>(kTriangleBytes) * littleEndian32(head.data() + kHeaderBytes))
    return true;
  if (head.substr(0, 3) == "\xEF\xBB\xBF") head.remove_prefix(3);
  std::size_t first = 0;
  while (first < head.size() && std::isspace(static_cast<unsigned char>(head[first]))) ++first;
  head.remove_prefix(first);
  return head.size() >= 5 && AsciiReader::same(head.substr(0, 5), "solid") &&
         (head.size() == 5 || std::isspace(static_cast<unsigned char>(head[5])));
}

StlMesh readStl(const std::string& path, const StlOptions& options) {
  const std::string bytes = detail::readInputFile(path);
  return parseStl(bytes, path == "-" ? "<stdin>" : path, options);
}

Vec3 triangleNormal(const Mesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles.at(t);
  const Vec3 a = mesh.vertices.at(tri[0]), b = mesh.vertices.at(tri[1]), c = mesh.vertices.at(tri[2]);
  const Vec3 n = cross(b - a, c - a);
  const double length = norm(n);
  return length > 0.0 ? n / length : Vec3{0.0, 0.0, 0.0};
}

}  // namespace scallop
