// app/live.hpp — `lbrsim run`: the live pipeline.
//
//   HAL thread (RT, highest)  source.poll → validate → SpscRing<AxisSample>.try_push
//                             (emulator:PROGRAM = nc::Emulator at live.period_ms, with tool numbers)
//   geometry thread (RT)      drain the ring as soon as it holds samples, merge straight runs
//                             of samples per channel into sweeps, LbrSolid::subtract(batch),
//                             record lag = done − receive time of every applied sample
//   recorder thread (non-RT)  --record: raw input → candump -l lines
//   caller's thread           status line once a second; metrics.json at the end
// The run ends when the source ends (replay, emulator, serial hang-up) or `stop` is set.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "app/profile.hpp"
#include "geom/lbr_solid.hpp"
#include "gfx/exchange.hpp"
#include "nc/emulator.hpp"
#include "nc/toolpath.hpp"

namespace lbr::app {

struct LiveOptions {
  std::string source;     // can:IF | serial:DEV | replay:FILE | emulator:PROGRAM
  double speed = 1.0;     // replay/emulator: 1 = real time, 0 = as fast as possible
  std::string record;     // write the raw input to this file (candump -l format)
  double status_period_s = 1.0;
  // Rendering (docs/rendering.md §7). When set, the geometry thread publishes to the
  // exchange after every batch (never waiting) and records tip positions for the path;
  // `on_start` receives the solid before any thread starts (the render side's initial copy).
  gfx::SolidExchange* exchange = nullptr;
  std::function<void(const geom::LbrSolid&)> on_start;
};

struct LiveResult {
  geom::LbrSolid solid;
  std::string source;
  std::uint64_t samples_received = 0;  // decoded samples handed over by the source
  std::uint64_t samples_applied = 0;   // samples the geometry thread consumed
  std::uint64_t samples_lost = 0;      // sequence gaps + incomplete cycles + rejected + overruns
  std::uint64_t samples_rejected = 0;  // failed validation (out_of_range, jump)
  std::uint64_t ring_overruns = 0;
  std::uint64_t ring_high_water = 0;
  std::uint64_t ring_capacity = 0;
  std::uint64_t sweeps = 0;            // sweeps subtracted after merging
  std::uint64_t batches = 0;
  std::uint64_t record_overruns = 0;
  std::map<std::string, std::uint64_t> decode_errors;
  double lag_p50_ms = 0, lag_p99_ms = 0, lag_max_ms = 0;
  double stock_volume_mm3 = 0, removed_volume_mm3 = 0;
  double wall_time_s = 0;
  std::string rt_mode;  // "fifo" when both RT threads got SCHED_FIFO, else "non-rt"
  double batch_p50_ms = 0, batch_p99_ms = 0, batch_max_ms = 0;  // subtract() per geometry tick
};

using StatusFn = std::function<void(const std::string& line)>;

// Setup errors (bad source spec, device cannot be opened, unknown tool) throw
// std::runtime_error; everything after start-up is counted instead.
[[nodiscard]] LiveResult run_live(const Profile& profile, const LiveOptions& opt, const std::atomic<bool>& stop,
                                  const StatusFn& status = {});

[[nodiscard]] std::string live_metrics_json(const LiveResult& r, const Profile& profile);
void write_live_outputs(const std::string& dir, const LiveResult& r, const Profile& profile);

// The machine emulator (nc/emulator.hpp) for live mode: the profile's motion limits with
// the live sample period (live.period_ms), so emulator and feeders stream what a machine
// reporting at that period would. Setup; throws like nc::Emulator.
[[nodiscard]] nc::EmulatorLimits live_emulator_limits(const Profile& profile);

}  // namespace lbr::app
