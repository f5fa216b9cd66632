// lathe_profile.hpp (private) — the moves of LinuxCNC's G70/G71/G72 lathe cycles.
//
// A profile is the polyline the cycle's subroutine traces (arcs as chords), in two
// coordinates: `level` (the axis the passes step along: X for G71, Z for G72) and `pass`
// (the axis each roughing pass feeds along). Roughing (G71, G72; type 1: one stretch of
// material per level) feeds straight passes I apart, the first at the start point's level,
// each starting on the line from the start point to the profile's start and ending on the
// profile, retracting R at 45 degrees; then one pass along the profile. What remains is the
// profile. Finishing (G70) goes to the start point, then along the profile. Both end at the
// profile's end. The pattern is LinuxCNC's (checked against rs274). docs/nc-frontend.md#lathe-cycles-g76-g7x.
// Not real-time code: allocates and throws std::invalid_argument (the caller adds FILE:LINE).
#pragma once

#include <vector>

namespace lbr::nc::detail {

struct ProfilePoint {
  double level = 0.0, pass = 0.0;
  bool rapid = false;  // reached by G0 in the subroutine
};

// Roughing: from start (level, pass), increment > 0 between passes, retract >= 0.
[[nodiscard]] std::vector<ProfilePoint> lathe_roughing(const std::vector<ProfilePoint>& profile,
                                                       const ProfilePoint& start, double increment, double retract);
// Finishing (levels along X): rapid to the start point, to the profile's start, along it.
[[nodiscard]] std::vector<ProfilePoint> lathe_finishing(const std::vector<ProfilePoint>& profile, const ProfilePoint& start);

}  // namespace lbr::nc::detail
