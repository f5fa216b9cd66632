// app/batch.hpp — offline run of a tool path through the LBR kernel, as fast as possible.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "app/profile.hpp"
#include "geom/lbr_solid.hpp"
#include "nc/toolpath.hpp"

namespace lbr::app {

struct BatchResult {
  geom::LbrSolid solid;
  double stock_volume_mm3 = 0;
  double removed_volume_mm3 = 0;
  double machining_time_s = 0;  // time the machine needs: the simple model below; lbrsim batch
                                // replaces it by the emulator's time for G-code and --sampled
  double wall_time_s = 0;       // kernel time only (excluding parsing and output)
  std::uint64_t moves = 0;      // motion segments
  geom::SubtractStats stats;
  int threads = 1;              // kernel worker threads used
};

// Progress callback: fraction done in [0, 1].
using Progress = std::function<void(double)>;

// Runs `path` on the stock of `profile`. Throws std::runtime_error naming the source line
// when the path uses a tool the profile does not define. Segments with tool 0 (empty
// spindle) remove nothing.
[[nodiscard]] BatchResult run_batch(const Profile& profile, const nc::Toolpath& path, const Progress& progress = {});

// Machining time [s] of a tool path under the simple motion model of the batch runner
// (feed and rapid rates, no acceleration).
[[nodiscard]] double machining_time_s(const Profile& profile, const nc::Toolpath& path);

// Peak resident set size of this process [MB].
[[nodiscard]] double peak_rss_mb();

}  // namespace lbr::app
