#pragma once
// Reading a G-code program back into moves: the dialect scallop's own writer produces
// (gcode.hpp), for the cut simulator (cut_simulation.hpp).
//
// Contract of parseGcodeProgram
// -----------------------------
// Input:  program text, one block per line ('\n', a trailing '\r' is dropped). Accepted:
//         comments in parentheses (not nested, closed on the same line) and after ';';
//         blank lines; a leading '/' (block delete: the block is read, as with the switch
//         off) and N<number> (ignored); a line "%" (ignored); words, a letter and a number
//         (upper or lower case, blanks allowed between and inside them as RS-274 allows,
//         e.g. "G 1 X 1 . 5"), at most one of each axis letter per block:
//           G0 G1 G2 G3       motion (rapid, feed line, clockwise / counter-clockwise arc)
//           G17 G18 G19       the arc plane (xy, zx, yz)
//           G20 G21           inch, mm (must be set before the first move)
//           G90               absolute positions (G91, incremental, is refused)
//           G90.1 G91.1       arc centres I J K absolute / relative to the start (default)
//           G94               feed per minute (G93 inverse time is refused)
//           G40 G49 G80       no cutter compensation, no length offset, no canned cycle
//           G61 G61.1 G64 [P<tol> [Q<tol>]]   path control (recorded, not simulated)
//           G4 P<seconds>     dwell (no motion)
//           X Y Z             the ball's TIP position (scallop's convention; the simulator
//                             adds R to get the centre); I J K arc centre
//           F S               feed (> 0) and spindle speed (>= 0); M3 M4 M5 spindle; M2 M30
//                             end (the rest of the text is not read); M0 M1 (pause: ignored)
//         Arcs: G2/G3 with the two in-plane centre words (G17 I J, G18 I K, G19 J K; a
//         missing one is 0, a word of the third axis is refused), no R (radius form) and no P
//         (turns): the ends' distances from the centre in the plane must agree within
//         max(0.0028 in | 0.028 mm, 0.1 % of the radius), LinuxCNC's rule
//         (interp_internal.hh CENTER_ARC_RADIUS_TOLERANCE_*); start == end in the plane is a
//         full circle. The normal coordinate may change (a helix). Zero-radius arcs are
//         refused.
// Output: the moves in program order, each with its 1-based line number. Positions are
//         known once an axis has been given; a move before all three axes are known is
//         not a move (the controller's start position is unknown): a rapid then only counts
//         in `unknownStartMoves`, a feed move (G1-G3) is an error. Numbers must be finite
//         and at most 1e9 in magnitude.
// Errors: scallop::Error "NAME:LINE: ..." naming the word and what was expected, for any
//         word, modal group or value not listed above, e.g.
//           "p.ngc:12: unsupported word 'T1': scallop verify reads only ..."
//           "p.ngc:7: G91 (incremental distance mode) is not supported; use G90".
//         Never crashes or loops: time and memory O(length of the text); at most
//         kGcodeMaxLines lines and kGcodeMaxLineLength characters per line. Polls the
//         thread's job control (job_control.hpp) every 1024 lines: scallop::Cancelled.

#include <cstddef>
#include <string>
#include <string_view>

#include "scallop/paths/machine_program.hpp"

namespace scallop {

inline constexpr std::size_t kGcodeMaxLines = 20'000'000;
inline constexpr std::size_t kGcodeMaxLineLength = 256;

/// Parses `text` (see the contract); `sourceName` names it in messages.
GcodeProgram parseGcodeProgram(std::string_view text, const std::string& sourceName);

/// Reads and parses a file ("-" reads standard input).
GcodeProgram readGcodeProgram(const std::string& path);

}  // namespace scallop
