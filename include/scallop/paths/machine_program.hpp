#pragma once
// A machine program as moves: what the G-code reader (io/gcode_reader.hpp) makes of a
// program's text and what the cut simulator (cut_simulation.hpp) sweeps. A type of its own in
// the paths layer, so that the simulator depends on no reader.

#include <cstddef>
#include <string>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"
#include "scallop/paths/toolpath.hpp"

namespace scallop {

enum class ProgramMoveKind {
  rapid,  ///< G0: a straight line at rapid rate (LinuxCNC moves G0 in a straight line)
  line,   ///< G1
  arc,    ///< G2 / G3
};

/// One move of a program. Positions are as written: the ball's TIP (centre - R z).
struct ProgramMove {
  ProgramMoveKind kind = ProgramMoveKind::line;
  Vec3 start;
  Vec3 end;
  Vec3 center;                    ///< arc: the centre, its normal coordinate that of `start`
  ArcPlane plane = ArcPlane::xy;  ///< arc
  bool clockwise = true;          ///< arc: G2
  bool spindleOn = false;         ///< M3/M4 in effect
  std::size_t line = 0;           ///< 1-based line of the block
};

struct GcodeProgram {
  std::string sourceName;
  Units units = Units::inch;
  std::vector<ProgramMove> moves;
  std::size_t lines = 0;              ///< lines read (up to M2/M30 or the end)
  std::size_t unknownStartMoves = 0;  ///< rapids before all three axes were known
  /// Largest |r_end - r_start| of an arc (the two ends' distances from its centre): the
  /// simulator sweeps the circle of the mean radius, so each position of the controller's
  /// spiral is within half of this of a swept one.
  double maxArcRadiusMismatch = 0.0;
};

}  // namespace scallop
