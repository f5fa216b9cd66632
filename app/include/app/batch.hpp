// app/batch.hpp — offline run of a tool path through the LBR kernel, as fast as possible.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "app/profile.hpp"
#include "geom/lbr_solid.hpp"
#include "motion/path_sweeps.hpp"
#include "motion/tool_table.hpp"
#include "nc/toolpath.hpp"
#include "verify/design.hpp"
#include "verify/events.hpp"

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
  std::vector<verify::Event> events;  // collision and process checks (verify/), in move order
  std::optional<verify::DesignReport> design;  // profile.design.stl_path set: the final stock against it
  std::vector<geom::Paths> design_sections{};   // the sliced design (--design), for deviation colours
  std::uint64_t batches = 0;    // kernel calls (batches of moves subtracted at once)
};

// Progress callback: fraction done in [0, 1].
using Progress = std::function<void(double)>;

// What a user should hear about a toolpath before it runs: an empty program, and feed
// moves that run with no tool loaded (tool 0 removes nothing; a program that never calls
// M6 cuts nothing unless the profile's [nc] start_tool says which tool the spindle holds).
// One message each, empty when there is nothing to say.
std::vector<std::string> toolpath_warnings(const nc::Toolpath& path);

// Runs `path` on the stock of `profile`. Throws std::runtime_error naming the source line
// when the path uses a tool the profile does not define, or (profile.design set) when the
// design model cannot be read or compared (verify::StlError, verify::DesignError), before
// the run. Segments with tool 0 (empty
// spindle) remove nothing. `sampled`: `path` is the emulator's sampled stream
// (nc::sampled_toolpath, `batch --sampled`), whose rapids the checks tell by speed as live
// mode does (docs/verification.md "batch --sampled").
[[nodiscard]] BatchResult run_batch(const Profile& profile, const nc::Toolpath& path, const Progress& progress = {},
                                    bool sampled = false);

// One channel of a multi-channel run: its name, tool path and kinematics.
using ChannelPath = motion::ChannelPath;

// Runs several channels cutting the same stock (docs/machine-kinds.md#several-channels).
// Every channel is timed by the machine emulator (emulator_limits(profile)); each segment's
// sweep enters the kernel at the time its motion ends (sub-steps of a segment at their share
// of it), ties in channel order. With `sampled`, the channels' emulated sample streams are
// merged instead, by sample time, as live mode receives them. Move ids: segment index + 1
// plus the segment counts of the channels before (sampled: running sample count).
// machining_time_s is the longest channel's emulated time.
[[nodiscard]] BatchResult run_batch_channels(const Profile& profile, const std::vector<ChannelPath>& channels,
                                             bool sampled = false, const Progress& progress = {});

// --design (docs/verification.md#design-model-comparison), one mechanism for batch, view and
// run: the model of profile.design read, checked against the stock of `solid` and sliced on
// its levels; empty when profile.design names no model. Setup; throws verify::StlError or
// verify::DesignError naming the file.
[[nodiscard]] std::vector<geom::Paths> load_design(const Profile& profile, const geom::LbrSolid& solid);

// The final stock `solid` against `design` (load_design()): the report, its deepest gouge
// attributed to the earliest of `moves` that cut there (empty `moves`: not attributed, as in
// live mode, which keeps no move list), and a design-gouge event appended to `events` when
// that gouge is deeper than the tolerance. Not real-time: allocates, takes seconds on big parts.
[[nodiscard]] verify::DesignReport compare_with_design(const Profile& profile, const std::vector<geom::Paths>& design,
                                                       const geom::LbrSolid& solid,
                                                       std::span<const motion::TimedSweep> moves,
                                                       const verify::MoveIndex& index,
                                                       std::vector<verify::Event>& events);

// The stock of `profile` with regions = auto sized for the tool with the most motions.
[[nodiscard]] geom::SolidSpec batch_solid_spec(const Profile& profile, const motion::ToolTable& tools);

// Machining time [s] of a tool path under the simple motion model of the batch runner
// (feed and rapid rates, no acceleration).
[[nodiscard]] double machining_time_s(const Profile& profile, const nc::Toolpath& path);

// Peak resident set size of this process [MB].
[[nodiscard]] double peak_rss_mb();

}  // namespace lbr::app
