#include "support/input_file.hpp"
#include "support/text_input.hpp"
#include "scallop/io/surface_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {
namespace {

using detail::clipped;
using detail::displayName;
using detail::isBlank;
using detail::trim;

constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";


std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isBlank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !isBlank(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

// A whole token as a non-negative integer (digits only); false for anything else, including
// values beyond 64 bits.
bool parseCount(std::string_view token, std::uint64_t& value) {
  if (token.empty() || !std::all_of(token.begin(), token.end(),
                                    [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    return false;
  }
  const auto [stop, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error == std::errc() && stop == token.data() + token.size();
}

enum class NumberStatus { ok, notNumber, outOfRange, notFinite };

// std::from_chars is locale-independent and correctly rounded, as the JSON reader's numbers
// are, so "1.4" gives the same double in either format. A leading '+' is accepted.
NumberStatus parseCoordinate(std::string_view token, double& value) {
  if (token.size() > 1 && token.front() == '+' && token[1] != '+' && token[1] != '-') {
    token.remove_prefix(1);
  }
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  if (error == std::errc::result_out_of_range && stop == end) return NumberStatus::outOfRange;
  if (error != std::errc() || stop != end) return NumberStatus::notNumber;
  return std::isfinite(value) ? NumberStatus::ok : NumberStatus::notFinite;
}

// The non-blank lines of a text, with their 1-based numbers.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  /// The next non-blank line (trimmed), or false at the end of the text.
  bool next(std::string_view& line) {
    while (position_ < text_.size()) {
      const std::size_t end = std::min(text_.find('\n', position_), text_.size());
      const std::string_view raw = text_.substr(position_, end - position_);
      position_ = end + 1;
      ++number_;
      line = trim(raw);
      if (!line.empty()) return true;
    }
    return false;
  }

  /// The number of the line last returned (after the end: of the text's last line).
  std::size_t number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t position_ = 0;
  std::size_t number_ = 0;
};

struct BptParser {
  std::string source;
  LineReader lines;
  std::uint64_t patchCount = 0;
  std::string countText;

  [[noreturn]] void failAt(std::string_view what) const {
    throw Error(fmt::format("{}:{}: {}", source, lines.number(), what));
  }

  // The end of the text where more was expected.
  [[noreturn]] void failAtEnd(std::string_view what) const {
    throw Error(fmt::format("{}: the text ends (after line {}) {}; the patch count on line 1 is "
                            "'{}'",
                            source, lines.number(), what, countText));
  }

  void readCount() {
    std::string_view line;
    if (!lines.next(line)) {
      throw Error(fmt::format("{}:1: empty; expected the number of patches (an integer >= 1) on "
                              "the first line",
                              source));
    }
    const std::vector<std::string_view> fields = splitFields(line);
    if (fields.size() != 1 || !parseCount(fields[0], patchCount) || patchCount == 0) {
      failAt(fmt::format("expected the number of patches, an integer >= 1, got '{}'",
                         clipped(line)));
    }
    countText = std::string(line);
  }

  int degreeOf(std::string_view token, std::size_t patch, const char* direction,
               std::string_view line) const {
    std::uint64_t degree = 0;
    if (!parseCount(token, degree)) {
      failAt(fmt::format("patches[{}]: expected the degrees 'm n', two integers in [1, {}], got '{}'",
                         patch, kMaxPatchDegree, clipped(line)));
    }
    if (degree < 1) {
      failAt(fmt::format("patches[{}]: degree 0 in {} (got '{}'): each degree must be at least 1, or "
                         "r_{} vanishes identically and the patch has no normal",
                         patch, direction, clipped(line), direction[0]));
    }
    if (degree > static_cast<std::uint64_t>(kMaxPatchDegree)) {
      failAt(fmt::format("patches[{}]: degree {} in {} (got '{}') exceeds the supported maximum {}",
                         patch, clipped(token), direction, clipped(line), kMaxPatchDegree));
    }
    return static_cast<int>(degree);
  }

  BezierPatch readPatch(std::size_t index) {
    std::string_view line;
    if (!lines.next(line)) {
      failAtEnd(fmt::format("where patches[{}] should begin with its degrees 'm n'", index));
    }
    const std::vector<std::string_view> degrees = splitFields(line);
    if (degrees.size() != 2) {
      failAt(fmt::format("patches[{}]: expected the degrees 'm n', two integers in [1, {}], got '{}'",
                         index, kMaxPatchDegree, clipped(line)));
    }
    BezierPatch patch;
    patch.degreeU = degreeOf(degrees[0], index, "u (the first)", line);
    patch.degreeV = degreeOf(degrees[1], index, "v (the second)", line);
    const int columns = patch.degreeV + 1;
    const int count = (patch.degreeU + 1) * columns;
    patch.control.reserve(static_cast<std::size_t>(count));
    for (int c = 0; c < count; ++c) {
      const int j = c / columns;
      const int k = c % columns;
      if (!lines.next(line)) {
        failAtEnd(fmt::format("in patches[{}] (degrees {} {}) after {} of its {} control points",
                              index, patch.degreeU, patch.degreeV, c, count));
      }
      const std::vector<std::string_view> fields = splitFields(line);
      if (fields.size() != 3) {
        failAt(fmt::format("patches[{}]: expected control point p_{},{} 'x y z', three numbers, got "
                           "'{}'",
                           index, j, k, clipped(line)));
      }
      double xyz[3] = {0.0, 0.0, 0.0};
      for (std::size_t i = 0; i < 3; ++i) {
        switch (parseCoordinate(fields[i], xyz[i])) {
          case NumberStatus::ok:
            break;
          case NumberStatus::notNumber:
            failAt(fmt::format("patches[{}]: control point p_{},{}: '{}' is not a number (in '{}')",
                               index, j, k, clipped(fields[i]), clipped(line)));
          case NumberStatus::outOfRange:
            failAt(fmt::format("patches[{}]: control point p_{},{}: '{}' is beyond the range of a "
                               "double",
                               index, j, k, clipped(fields[i])));
          case NumberStatus::notFinite:
            failAt(fmt::format("patches[{}]: control point p_{},{}: coordinates must be finite "
                               "numbers, got '{}'",
                               index, j, k, clipped(fields[i])));
        }
      }
      patch.control.push_back({xyz[0], xyz[1], xyz[2]});
    }
    return patch;
  }

  Surface read() {
    readCount();
    Surface surface{Units::inch, {}};
    // Not reserved from the count: a wrong count must not allocate.
    for (std::uint64_t i = 0; i < patchCount; ++i) {
      surface.patches.push_back(readPatch(static_cast<std::size_t>(i)));
    }
    std::string_view line;
    if (lines.next(line)) {
      failAt(fmt::format("trailing text after the last of the {} patches that line 1 counts, got "
                         "'{}'",
                         countText, clipped(line)));
    }
    return surface;
  }
};

bool endsWith(std::string_view text, std::string_view suffix) {
  if (text.size() < suffix.size()) return false;
  return std::equal(suffix.begin(), suffix.end(), text.end() - static_cast<std::ptrdiff_t>(suffix.size()),
                    [](char a, char b) {
                      return std::tolower(static_cast<unsigned char>(a)) ==
                             std::tolower(static_cast<unsigned char>(b));
                    });
}

// JSON unless the first character that is not a blank (or the byte order mark) is not '{'.
bool looksLikeJson(std::string_view text) {
  if (text.substr(0, kByteOrderMark.size()) == kByteOrderMark) {
    text.remove_prefix(kByteOrderMark.size());
  }
  const std::size_t first = text.find_first_not_of(" \t\r\n\f\v");
  return first != std::string_view::npos && text[first] == '{';
}

[[noreturn]] void badSelection(std::string_view selection, std::string_view what) {
  throw Error(fmt::format("invalid patch selection '{}': {}", clipped(selection), what));
}

}  // namespace

Surface parseBptSurface(std::string_view text, const std::string& sourceName, SurfaceCheck check) {
  const std::string source = displayName(sourceName);
  if (text.substr(0, kByteOrderMark.size()) == kByteOrderMark) {
    text.remove_prefix(kByteOrderMark.size());
  }
  BptParser parser{source, LineReader(text), 0, {}};
  Surface surface = parser.read();
  if (check == SurfaceCheck::full) validateSurface(surface, source);
  return surface;
}

Surface readSurface(const std::string& path, SurfaceCheck check) {
  const std::string text = detail::readInputFile(path);
  const bool json = endsWith(path, ".json") || (!endsWith(path, ".bpt") && looksLikeJson(text));
  return json ? parseSurface(text, path, check) : parseBptSurface(text, path, check);
}

std::vector<std::size_t> parsePatchSelection(std::string_view selection, std::size_t patchCount) {
  const std::string range =
      patchCount == 0 ? std::string("the surface has no patches")
                      : fmt::format("the surface has {} patches, 0-{}", patchCount, patchCount - 1);
  if (trim(selection).empty()) {
    badSelection(selection, "expected patch indices and ranges such as '4' or '4-7,12' (0-based)");
  }
  std::vector<bool> chosen(patchCount, false);
  std::size_t start = 0;
  while (start <= selection.size()) {
    const std::size_t comma = std::min(selection.find(',', start), selection.size());
    const std::string_view item = trim(selection.substr(start, comma - start));
    start = comma + 1;
    const std::size_t dash = item.find('-');
    const std::string_view firstText = trim(item.substr(0, dash));
    const std::string_view lastText =
        dash == std::string_view::npos ? firstText : trim(item.substr(dash + 1));
    std::uint64_t first = 0;
    std::uint64_t last = 0;
    if (!parseCount(firstText, first) || !parseCount(lastText, last)) {
      badSelection(selection,
                   fmt::format("'{}' is not an index or a range i-j; expected indices and ranges "
                               "such as '4' or '4-7,12' (0-based)",
                               clipped(item)));
    }
    if (first > last) {
      badSelection(selection, fmt::format("the range '{}' runs backwards", clipped(item)));
    }
    if (last >= patchCount) {
      badSelection(selection,
                   fmt::format("patch {} (in '{}') is out of range: {}", last, clipped(item), range));
    }
    for (std::uint64_t i = first; i <= last; ++i) {
      if (chosen[i]) {
        badSelection(selection, fmt::format("patch {} is listed twice", i));
      }
      chosen[i] = true;
    }
  }
  std::vector<std::size_t> indices;
  for (std::size_t i = 0; i < patchCount; ++i) {
    if (chosen[i]) indices.push_back(i);
  }
  return indices;
}

Surface selectPatches(const Surface& surface, std::span<const std::size_t> indices) {
  Surface selected{surface.units, {}};
  selected.patches.reserve(indices.size());
  for (const std::size_t i : indices) {
    if (i >= surface.patches.size()) {
      throw Error(fmt::format("selectPatches: patch {} is out of range (the surface has {} patches)",
                              i, surface.patches.size()));
    }
    selected.patches.push_back(surface.patches[i]);
    if (surface.trimmed()) selected.trims.push_back(surface.trims[i]);  // a trimmed patch keeps its trim
    if (!surface.seamTolerances.empty()) selected.seamTolerances.push_back(surface.seamTolerances[i]);
  }
  return selected;
}

}  // namespace scallop
