// lathe_profile.hpp (private) — the moves of LinuxCNC's G70/G71/G72 lathe cycles.
//
// A profile is the polyline the cycle's subroutine traces (arcs as chords), in two
// coordinates: `level` (the axis the passes step along: X for G71, Z for G72) and `pass`
// (the axis each roughing pass feeds along). Roughing (G71, G72; type 1: one stretch of
// material per level) feeds straight passes from the start point, I apart, each ending on the
// profile, retracts R, and finishes with one pass along the profile; what remains is the
// profile. Finishing (G70) follows the profile. docs/nc-frontend.md#lathe-cycles-g76-g7x.
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
// Finishing: rapid to the profile's start, along it, back to the start point.
[[nodiscard]] std::vector<ProfilePoint> lathe_finishing(const std::vector<ProfilePoint>& profile, const ProfilePoint& start);

}  // namespace lbr::nc::detail
