#include "scallop/io/gcode_reader.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "support/input_file.hpp"
#include "support/text_input.hpp"

namespace scallop {
namespace {

constexpr double kMaxValue = 1e9;

struct Word {
  char letter = 0;
  double value = 0.0;
  std::string text;  // as written, blanks removed, for messages ("G91", "X1.5")
};

class Reader {
 public:
  explicit Reader(const std::string& sourceName) { program_.sourceName = sourceName; }

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(fmt::format("{}:{}: {}", detail::displayName(program_.sourceName), lineNumber_, message));
  }

  // Returns false once M2/M30 has been read.
  bool readLine(std::string_view line, std::size_t lineNumber) {
    lineNumber_ = lineNumber;
    if (line.size() > kGcodeMaxLineLength)
      fail(fmt::format("line longer than {} characters: '{}'", kGcodeMaxLineLength, detail::clipped(line)));
    const std::string compact = stripped(line);
    if (compact.empty() || compact == "%") return true;
    return executeBlock(splitWords(compact));
  }

  GcodeProgram finish(std::size_t lines) {
    program_.lines = lines;
    return std::move(program_);
  }

 private:
  // The block without comments and blanks, upper case; '/' at the start dropped.
  std::string stripped(std::string_view line) const {
    std::string out;
    bool inComment = false;
    for (const char c : line) {
      if (inComment) {
        if (c == '(') fail("nested comment: '(' inside a comment");
        if (c == ')') inComment = false;
        continue;
      }
      if (c == '(') {
        inComment = true;
        continue;
      }
      if (c == ')') fail("')' without a matching '('");
      if (c == ';') break;
      if (detail::isBlank(c)) continue;
      const auto byte = static_cast<unsigned char>(c);
      if (byte < 0x20 || byte >= 0x7f) fail(fmt::format("unexpected character (byte {:#04x})", byte));
      out += (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
    }
    if (inComment) fail("comment not closed: '(' without ')' on the same line");
    if (!out.empty() && out.front() == '/') out.erase(0, 1);
    return out;
  }

  std::vector<Word> splitWords(const std::string& block) const {
    std::vector<Word> words;
    std::size_t i = 0;
    while (i < block.size()) {
      const char letter = block[i];
      if (letter < 'A' || letter > 'Z')
        fail(fmt::format("expected a word (a letter and a number), got '{}'", detail::clipped(block.substr(i))));
      std::size_t j = i + 1;
      while (j < block.size() && (block[j] == '+' || block[j] == '-' || block[j] == '.' ||
                                  (block[j] >= '0' && block[j] <= '9')))
        ++j;
      std::string_view number(block.data() + i + 1, j - i - 1);
      const std::string text = block.substr(i, j - i);
      if (number.empty()) fail(fmt::format("word '{}' has no number", text));
      std::string_view digits = number;
      bool negative = false;
      if (digits.front() == '+' || digits.front() == '-') {
        negative = digits.front() == '-';
        digits.remove_prefix(1);
      }
      double value = 0.0;
      const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value,
                                             std::chars_format::fixed);
      if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || digits.front() == '+' ||
          digits.front() == '-')
        fail(fmt::format("word '{}': '{}' is not a number", text, std::string(number)));
      if (!std::isfinite(value) || std::abs(value) > kMaxValue)
        fail(fmt::format("word '{}': the number must be finite and at most {:g} in magnitude", text, kMaxValue));
      words.push_back({letter, negative ? -value : value, text});
      i = j;
    }
    return words;
  }

  // G and M codes are compared in tenths: G91.1 is 911.
  static int code(const Word& word) { return static_cast<int>(std::lround(word.value * 10.0)); }
  static bool isCode(const Word& word) {
    return word.value >= 0.0 && std::abs(word.value * 10.0 - std::round(word.value * 10.0)) < 1e-6;
  }

  bool executeBlock(const std::vector<Word>& words) {
    std::optional<int> motion;
    std::array<std::optional<double>, 3> axis;  // X Y Z
    std::array<std::optional<double>, 3> offset;  // I J K
    std::optional<double> p;
    bool dwell = false, pathControl = false, end = false;
    const Word* motionWord = nullptr;
    auto once = [&](std::optional<double>& slot, const Word& word) {
      if (slot) fail(fmt::format("word '{}': {} given twice in one block", word.text, word.letter));
      slot = word.value;
    };
    std::optional<double> q;
    for (const Word& word : words) {
      switch (word.letter) {
        case 'N':
          break;
        case 'G': {
          const int g = isCode(word) ? code(word) : -1;
          switch (g) {
            case 0: case 10: case 20: case 30:
              if (motion) fail(fmt::format("word '{}': two motion codes in one block ('{}')", word.text, motionWord->text));
              motion = g / 10;
              motionWord = &word;
              break;
            case 170: plane_ = ArcPlane::xy; break;
            case 180: plane_ = ArcPlane::zx; break;
            case 190: plane_ = ArcPlane::yz; break;
            case 200: setUnits(Units::inch); break;
            case 210: setUnits(Units::millimetre); break;
            case 900: break;
            case 910: fail(fmt::format("word '{}': G91 (incremental distance mode) is not supported; use G90", word.text));
            case 901: centreAbsolute_ = true; break;
            case 911: centreAbsolute_ = false; break;
            case 940: break;
            case 930: fail(fmt::format("word '{}': G93 (inverse-time feed) is not supported; use G94", word.text));
            case 400: case 490: case 800: break;
            case 610: case 611: case 640: pathControl = true; break;
            case 40: dwell = true; break;
            default:
              fail(fmt::format("unsupported word '{}': scallop verify reads G0-G3, G4, G17-G21, G40, "
                               "G49, G61, G61.1, G64, G80, G90, G90.1, G91.1, G94",
                               word.text));
          }
          break;
        }
        case 'M': {
          const int m = isCode(word) ? code(word) : -1;
          switch (m) {
            case 30: case 40: spindleOn_ = true; break;
            case 50: spindleOn_ = false; break;
            case 20: case 300: end = true; break;
            case 0: case 10: break;
            default:
              fail(fmt::format("unsupported word '{}': scallop verify reads M0, M1, M2, M3, M4, M5, M30", word.text));
          }
          break;
        }
        case 'X': once(axis[0], word); break;
        case 'Y': once(axis[1], word); break;
        case 'Z': once(axis[2], word); break;
        case 'I': once(offset[0], word); break;
        case 'J': once(offset[1], word); break;
        case 'K': once(offset[2], word); break;
        case 'P': once(p, word); break;
        case 'Q': once(q, word); break;
        case 'F':
          if (word.value <= 0.0) fail(fmt::format("word '{}': the feed rate must be positive", word.text));
          feed_ = word.value;
          break;
        case 'S':
          if (word.value < 0.0) fail(fmt::format("word '{}': the spindle speed must not be negative", word.text));
          break;
        case 'R':
          fail(fmt::format("word '{}': radius-format arcs (R) are not supported; give the centre with I J K", word.text));
        default:
          fail(fmt::format("unsupported word '{}': scallop verify reads the words G M X Y Z I J K F S P Q N", word.text));
      }
    }
    if (p && !dwell && !pathControl)
      fail(motion && *motion >= 2 ? "P (full turns) on an arc is not supported"
                                  : "word P is only read with G4 (dwell) or G64 (blend tolerance)");
    if (q && !pathControl) fail("word Q is only read with G64");
    if (dwell && !p) fail("G4 (dwell) needs P<seconds>");
    if (dwell && (motion || axis[0] || axis[1] || axis[2])) fail("G4 (dwell) with a motion in the same block is not supported");
    if (motion) motion_ = *motion;
    const bool anyAxis = axis[0] || axis[1] || axis[2];
    const bool anyOffset = offset[0] || offset[1] || offset[2];
    if (!anyAxis && motion && *motion >= 2)
      fail(fmt::format("word '{}': an arc needs an end point (X Y Z)", motionWord->text));
    if (anyOffset && !(anyAxis && motion_ && *motion_ >= 2))
      fail("words I J K are only read on an arc move (G2/G3 with an end point)");
    if (!anyAxis) return !end;
    if (!motion_) fail("axis words before any motion mode (G0, G1, G2, G3)");
    if (!units_) fail("a move before the units are set (G20 inch or G21 mm)");
    move(*motion_, axis, offset);
    return !end;
  }

  void setUnits(Units units) {
    if (units_ && *units_ != units) fail("the units change within the program (G20 and G21)");
    units_ = units;
    program_.units = units;
  }

  void move(int motion, const std::array<std::optional<double>, 3>& axis,
            const std::array<std::optional<double>, 3>& offset) {
    const bool knownStart = known_[0] && known_[1] && known_[2];
    std::array<double, 3> end = position_;
    for (int k = 0; k < 3; ++k) {
      if (axis[k]) {
        end[k] = *axis[k];
        known_[k] = true;
      }
    }
    const Vec3 from{position_[0], position_[1], position_[2]};
    const Vec3 to{end[0], end[1], end[2]};
    position_ = end;
    if (!knownStart) {
      if (motion != 0)
        fail(fmt::format("a feed move (G{}) from an unknown position: give X, Y and Z (e.g. with G0) first", motion));
      ++program_.unknownStartMoves;
      return;
    }
    if (motion != 0 && !feed_) fail(fmt::format("a feed move (G{}) with no feed rate: give F first", motion));
    ProgramMove m;
    m.kind = motion == 0 ? ProgramMoveKind::rapid : motion == 1 ? ProgramMoveKind::line : ProgramMoveKind::arc;
    m.start = from;
    m.end = to;
    m.spindleOn = spindleOn_;
    m.line = lineNumber_;
    if (m.kind == ProgramMoveKind::arc) {
      m.plane = plane_;
      m.clockwise = motion == 2;
      // In-plane axes (e1, e2) of the plane's frame, as indices into x, y, z.
      const int e1 = plane_ == ArcPlane::xy ? 0 : plane_ == ArcPlane::zx ? 2 : 1;
      const int e2 = plane_ == ArcPlane::xy ? 1 : plane_ == ArcPlane::zx ? 0 : 2;
      const int normal = 3 - e1 - e2;
      if (offset[normal])
        fail(fmt::format("{} word on an arc in the {} plane: give only the in-plane centre words ({}{})",
                         "IJK"[normal], plane_ == ArcPlane::xy ? "G17 (xy)" : plane_ == ArcPlane::zx ? "G18 (zx)" : "G19 (yz)",
                         "IJK"[std::min(e1, e2)], "IJK"[std::max(e1, e2)]));
      std::array<double, 3> c{from.x, from.y, from.z};
      const std::array<double, 3> s{from.x, from.y, from.z};
      for (const int k : {e1, e2}) {
        const double o = offset[k].value_or(0.0);
        c[k] = centreAbsolute_ ? (offset[k] ? o : s[k]) : s[k] + o;
      }
      m.center = {c[0], c[1], c[2]};
      const double r0 = std::hypot(s[e1] - c[e1], s[e2] - c[e2]);
      const double r1 = std::hypot(end[e1] - c[e1], end[e2] - c[e2]);
      if (!(r0 > 0.0) || !(r1 > 0.0)) fail("an arc of zero radius (its start or end is its centre)");
      const double tolerance = std::max(*units_ == Units::inch ? 0.0028 : 0.028, 0.001 * std::max(r0, r1));
      if (std::abs(r1 - r0) > tolerance)
        fail(fmt::format("arc radii differ: the start is {:.6f} from the centre, the end {:.6f} "
                         "(at most {:.6f} allowed, as LinuxCNC)",
                         r0, r1, tolerance));
      program_.maxArcRadiusMismatch = std::max(program_.maxArcRadiusMismatch, std::abs(r1 - r0));
    }
    program_.moves.push_back(m);
  }

  GcodeProgram program_;
  std::size_t lineNumber_ = 0;
  std::optional<Units> units_;
  std::optional<int> motion_;
  std::optional<double> feed_;
  ArcPlane plane_ = ArcPlane::xy;
  bool centreAbsolute_ = false;
  bool spindleOn_ = false;
  std::array<double, 3> position_{0.0, 0.0, 0.0};
  std::array<bool, 3> known_{false, false, false};
};

}  // namespace

GcodeProgram parseGcodeProgram(std::string_view text, const std::string& sourceName) {
  Reader reader(sourceName);
  std::size_t lineNumber = 0;
  while (!text.empty()) {
    const std::size_t newline = text.find('\n');
    std::string_view line = text.substr(0, newline);
    text.remove_prefix(newline == std::string_view::npos ? text.size() : newline + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++lineNumber;
    if (lineNumber % 1024 == 0) checkCancelled();  // a plan's cancel (job_control.hpp)
    if (lineNumber > kGcodeMaxLines)
      throw Error(fmt::format("{}: more than {} lines", detail::displayName(sourceName), kGcodeMaxLines));
    if (!reader.readLine(line, lineNumber)) break;
  }
  return reader.finish(lineNumber);
}

GcodeProgram readGcodeProgram(const std::string& path) {
  return parseGcodeProgram(detail::readInputFile(path), path);
}

}  // namespace scallop
