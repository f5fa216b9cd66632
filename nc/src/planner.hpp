// planner.hpp (private) — the emulator's look-ahead trajectory planner (docs/nc-frontend.md#planner).
//
// Turns a Toolpath into timed pieces: Holds (dwell, tool change), Lines and tangent blend Arcs,
// each with a trapezoidal speed profile (v_in -> v -> v_out). Steps, in order:
//   1. moves: every Rapid/Feed as a straight move with its speed and acceleration bounds;
//   2. naive-CAM merge: under G64 Q, runs of feeds whose vertices lie within Q of one chord
//      become that chord (LinuxCNC's naive CAM detector);
//   3. corners: under G64 a circular arc tangent to both moves replaces each corner, as large
//      as the tolerance P and half of each move allow; G61 stops at corners, G61.1 after every
//      move; collinear junctions keep the speed;
//   4. velocity passes: backward (every piece can stop within the remaining path) then forward
//      (every piece can reach its speed from the previous one);
//   5. profiles and times.
// Setup code: allocates, throws std::invalid_argument naming the source line.
#pragma once

#include <vector>

#include "nc/emulator.hpp"

namespace lbr::nc::detail {

struct PlannedPath {
  std::vector<Emulator::Plan> plans;
  std::vector<Emulator::ArcGeom> arcs;
  double total_s = 0.0;
};

[[nodiscard]] PlannedPath plan_path(const Toolpath& path, const EmulatorLimits& limits);

// Position at path length s [0, length] of a Line or Arc piece; a Hold gives `to`.
// Real-time safe.
void piece_position(const Emulator::Plan& p, const std::vector<Emulator::ArcGeom>& arcs, double s,
                    AxisVector& out) noexcept;

// Path length covered after tau [s] from the start of the piece (clamped to its duration).
// Real-time safe.
[[nodiscard]] double piece_distance(const Emulator::Plan& p, double tau_s) noexcept;

}  // namespace lbr::nc::detail
