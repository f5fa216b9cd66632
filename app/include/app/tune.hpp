// app/tune.hpp — `lbrsim tune`: measure the kernel on a program for several region grids and
// write the fastest into a profile.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "app/profile.hpp"
#include "nc/toolpath.hpp"

namespace lbr::app {

struct GridTiming {
  int nx = 1, ny = 1;
  double wall_s = 0;     // best of the repetitions [s]
  double removed_mm3 = 0;
};

// Candidate grids: NxM with N, M in {1, 2, 4, 8, 16}, |log2(N/M)| <= 1, keeping regions no
// smaller than the largest tool diameter used.
[[nodiscard]] std::vector<std::pair<int, int>> tune_candidates(const Profile& p, double max_tool_diameter_mm);

// Runs `path` once per candidate (best of `repeats`, one thread) and returns the timings,
// fastest first. Calls `report` after each candidate.
[[nodiscard]] std::vector<GridTiming> tune_regions(const Profile& p, const nc::Toolpath& path,
                                                   const std::vector<std::pair<int, int>>& grids, int repeats,
                                                   const std::function<void(const GridTiming&)>& report = {});

// Returns `profile_text` with `regions = "NXxNY"` set in its [lbr] table (replacing an
// existing regions line, else adding it to [lbr], else appending an [lbr] table). Comments
// and everything else are kept.
[[nodiscard]] std::string set_regions_in_profile_text(const std::string& profile_text, int nx, int ny);

}  // namespace lbr::app
