// lathe_profile.hpp (private) — the moves of LinuxCNC's G70/G71/G72 lathe cycles.
//
// A profile is the polyline the cycle's subroutine traces (arcs as chords) in the XZ plane.
// The cycles follow LinuxCNC 2.9's interpreter (checked move by move against its rs274): the
// profile, preceded by the line from the start point to its first point, is mirrored (and for
// G72 turned by 90 degrees) so that it runs towards −pass and its end is no lower than its
// start; then
//  * roughing (G71 along Z, G72 along X; .1: no pockets; .2: only what .1 left) offsets the
//    profile by D towards the start point (round outer corners), feeds passes at the start
//    level and every I below it from the approach line (or a pocket's side) to the profile,
//    retracting R at 45 degrees, follows the profile up and cuts each pocket (a stretch where
//    the profile goes down again: type 2) the same way;
//  * finishing (G70) runs P passes along the profile offset by (pass−1)(D−E)/P + E.
// Corner finishes (A, C on a profile move) are applied first, between straight neighbours.
// docs/nc-frontend.md#lathe-cycles-g76-g7x. Not real-time code: allocates and throws
// std::invalid_argument (the caller adds FILE:LINE).
#pragma once

#include <vector>

namespace lbr::nc::detail {

struct LathePoint {
  double x = 0.0, z = 0.0;  // radius [mm], Z [mm]
  bool rapid = false;       // reached by a rapid move
  double corner = 0.0;      // profile: fillet radius (A) or chamfer size (C) at this corner [mm]
  bool chamfer = false;
};

struct LatheCycle {
  int code = 71;             // 70, 71 or 72
  int variant = 0;           // 0: G7x, 1: G7x.1 (no pockets), 2: G7x.2 (only after the first pocket)
  double allowance = 0.0;    // D: distance left to the profile (G70: of the first pass) [mm]
  double end_allowance = 0.0;  // E (G70): distance of the last pass [mm]
  double increment = 1.0;    // I (G71/G72): depth of cut between passes [mm], > 0
  double retract = 0.5;      // R (G71/G72): retract at 45 degrees after a pass [mm]
  int passes = 1;            // P (G70)
};

// The cycle's moves after the rapid to its start point. `profile` starts at the point the
// subroutine's first move reaches (the start point itself is not in it).
[[nodiscard]] std::vector<LathePoint> lathe_cycle(const std::vector<LathePoint>& profile, const LathePoint& start,
                                                  const LatheCycle& cycle);

}  // namespace lbr::nc::detail
