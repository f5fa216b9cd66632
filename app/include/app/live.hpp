// app/live.hpp — `lbrsim run`: the live pipeline (implementation in app/src/live/).
//
//   HAL thread (RT, highest)  source.poll → validate → SpscRing<AxisSample>.try_push
//                             (emulator:PROGRAM = nc::Emulator at live.period_ms, with tool numbers)
//   geometry thread (RT)      drain the ring as soon as it holds samples, turn them into
//                             sweeps (motion::SampleStream: kinematics, merged straight runs
//                             per channel), LbrSolid::subtract(batch), record lag = done −
//                             receive time of every applied sample
//   recorder thread (non-RT)  --record: raw input → candump -l lines
//   caller's thread           status line once a second; metrics.json at the end
// The run ends when the source ends (replay, emulator, serial hang-up) or a stop is asked for.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/profile.hpp"
#include "app/snapshot.hpp"
#include "geom/lbr_solid.hpp"
#include "gfx/exchange.hpp"
#include "nc/emulator.hpp"
#include "nc/toolpath.hpp"
#include "verify/design.hpp"
#include "verify/events.hpp"

namespace lbr::app {

// Heartbeats of the pipeline's threads for the service watchdog (app/watchdog.hpp): each
// thread bumps its counter once per loop pass, idle passes included, so a counter that stops
// moving means a stalled thread. `*_running` is false before the thread starts and after it
// ends. Written by the pipeline threads, read by any thread (relaxed).
struct LiveProgress {
  std::atomic<std::uint64_t> hal_loops{0}, geometry_loops{0};
  std::atomic<bool> hal_running{false}, geometry_running{false};
};

// One kernel call of the live geometry thread (`lbrsim run --kernel-log`, docs/performance.md
// "Live lag"): when it started [ns since the run's start], how long subtract() took [µs],
// what it was given and what it did.
struct KernelCallRecord {
  std::int64_t t_ns = 0;
  std::uint32_t dur_us = 0;
  std::uint32_t sweeps = 0;
  std::uint32_t samples = 0;       // ring entries whose samples this call completed
  float units = 0;                 // work estimate (Geometry::work_units, cells once per call)
  float predicted_us = 0;          // the call sizer's prediction for it
  std::uint32_t cells_clipped = 0;  // geom::SubtractStats
  std::uint32_t sections = 0;
  std::uint32_t cell_vertices = 0;  // vertices of the material cells it reaches (once per call)
  std::uint32_t backlog_us = 0;    // age of the oldest sample not yet applied, at the call's start
};

struct LiveOptions {
  std::string source;     // can:IF | serial:DEV | replay:FILE | emulator:PROGRAM
  // The program the machine runs (can, serial, replay): its line is found from the sampled
  // positions (nc::LineTracker) and its emulated time is the run's total, for the status bar.
  // Not used with an emulator source, which knows its line.
  std::string program;
  double speed = 1.0;     // replay/emulator: 1 = real time, 0 = as fast as possible
  std::string record;     // write the raw input to this file (candump -l format; the emulator's
                          // samples as the serial frames of the profile's mapping)
  double status_period_s = 1.0;
  // Warnings about the input the operator must see even with --quiet, e.g. serial frames
  // with fewer positions than the profile maps (called once per kind, within 0.1 s of
  // the first such frame, on the control thread).
  std::function<void(const std::string&)> on_warning;
  // Rendering (docs/rendering.md §7). When set, the geometry thread publishes to the
  // exchange after every batch (never waiting) and records tip positions for the path;
  // `on_start` receives the solid before any thread starts (the render side's initial copy).
  gfx::SolidExchange* exchange = nullptr;
  std::function<void(const geom::LbrSolid&)> on_start;
  // --design (profile.design set): receives the design model's sections on the solid's
  // levels (app::load_design) before on_start, for the renderer's deviation colours.
  std::function<void(const std::vector<geom::Paths>&)> on_design;
  // --design: the comparison of the stock with the model, at every periodic snapshot (on the
  // snapshot writer's thread, `final` false; none without snapshots) and when the run ends
  // (`final` true, the control thread; also in LiveResult::design). For the HUD.
  std::function<void(const verify::DesignReport&, bool final)> on_design_report;
  // Overload (docs/architecture.md "Live overload"): samples the HAL side may hold while the
  // ring is full (0: 16 × live.ring_capacity); testing: sleep this long after every kernel
  // call (a deliberately slowed kernel).
  std::size_t overflow_capacity = 0;
  std::int64_t test_kernel_delay_ns = 0;
  double test_work_budget = 0;  // testing: work budget of one kernel call (0: the default)
  // Diagnostics: keep a record of up to this many kernel calls (LiveResult::kernel_log;
  // allocated at setup, the geometry thread only fills it).
  std::size_t kernel_log_capacity = 0;
  // Power-loss snapshots (app/snapshot.hpp, docs/snapshot.md): written to `snapshot_dir`
  // every profile.live.snapshot_s and when the run ends (none when empty or 0). `resume`:
  // start from this snapshot (stock, channel poses; replay and emulator sources skip the
  // samples it holds). Must outlive the pipeline.
  std::string snapshot_dir;
  const SnapshotState* resume = nullptr;
  LiveProgress* progress = nullptr;  // heartbeats for the watchdog (may be null)
};

struct LiveResult {
  geom::LbrSolid solid;
  std::string source;
  std::uint64_t samples_received = 0;  // decoded samples handed over by the source
  std::uint64_t samples_applied = 0;   // samples the geometry thread applied (coalesced ones included)
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
  double batch_p50_ms = 0, batch_p99_ms = 0, batch_max_ms = 0;  // subtract() per kernel call (sub-batch)
  // Overload (docs/protocols.md#counters): samples folded by the HAL side into a held one
  // (exact, part of samples_applied), samples lost with ring and overflow full (part of
  // samples_lost), the overflow's high water and capacity, kernel calls and sweeps cut into
  // pieces by the work budget, samples a stop left unapplied, and how long the stop took
  // (from the request being seen to the geometry thread's end) [ms].
  std::uint64_t samples_coalesced = 0, overflow_overruns = 0, overflow_high_water = 0, overflow_capacity = 0;
  std::uint64_t kernel_calls = 0, sweeps_split = 0, samples_unapplied = 0;
  std::uint64_t kernel_calls_shared = 0;  // kernel calls that ran on the live kernel pool
  int kernel_threads = 1;                 // threads of the live kernel pool (1: none)
  double stop_latency_ms = 0;
  std::vector<std::string> warnings{};  // as given to LiveOptions::on_warning
  // Snapshots written (periodic and final) and failed; resumed: the snapshot's generation
  // and the source position it skipped to (0: not resumed).
  std::uint64_t snapshots_written = 0, snapshots_failed = 0, resumed_generation = 0, resumed_position = 0;
  double snapshot_copy_max_ms = 0;  // longest copy of the solid into the writer's slot (geometry thread)
  // Collision checks (docs/verification.md#live): whether they ran, the speed above which a
  // sample stream is a rapid [mm/min], the events (sample numbers in move / last_move; lines
  // and source for emulated programs), events not stored (list full), and the latency from
  // the offending sample's receive time to the event [ms]; the time the checks took per
  // kernel call [ms].
  bool checks = false;
  double rapid_threshold_mm_per_min = 0;
  std::vector<verify::Event> events{};
  std::uint64_t events_dropped = 0, event_latency_count = 0;
  double event_latency_p50_ms = 0, event_latency_p99_ms = 0, event_latency_max_ms = 0;
  double check_p50_ms = 0, check_p99_ms = 0, check_max_ms = 0;
  // Power-loss catch-up (docs/snapshot.md): samples applied at start from the --record file
  // after the snapshot's position, and recorded ones skipped there because the solid held them.
  std::uint64_t samples_caught_up = 0, catch_up_skipped = 0;
  // --design (docs/verification.md#live-design): the final stock against the design model,
  // compared when the run ends (control thread), the same comparison as batch; its deepest
  // gouge is not attributed to a sample (the pipeline keeps no move list). A gouge deeper
  // than the tolerance adds a design-gouge event to `events`.
  std::optional<verify::DesignReport> design{};
  std::vector<KernelCallRecord> kernel_log{};  // LiveOptions::kernel_log_capacity > 0
};

using StatusFn = std::function<void(const std::string& line)>;

// The pipeline's lifecycle (as ros2_control's hardware components):
//   configure()  setup: tool shapes, stock, design model (profile.design: read, checked
//                and sliced, errors first), source opened, rings, record file; calls
//                opt.on_design and opt.on_start. Throws std::runtime_error.
//   start()      starts the geometry, HAL and (with --record) recorder threads.
//   running()    true until the geometry thread has applied the last sample.
//   stop()       asks the source loop to end (a no-op once the source has ended), joins the
//                threads, closes the source. Idempotent.
//   result()     after stop() (called if needed): the final solid and counters, and with
//                profile.design the comparison with the design model (seconds on a big
//                part); once.
// Every call is made from one control thread. `stop` (e.g. set by a signal handler) ends the
// source loop like stop() does.
class LivePipeline {
 public:
  LivePipeline(const Profile& profile, LiveOptions opt, const std::atomic<bool>& stop);
  ~LivePipeline();
  LivePipeline(const LivePipeline&) = delete;
  LivePipeline& operator=(const LivePipeline&) = delete;

  void configure();
  void start();
  [[nodiscard]] bool running() const noexcept;
  // One status line with the counters so far (the caller's thread, once a second).
  [[nodiscard]] std::string status_line();
  // The collision events raised since the last call, one line each for the log, with
  // whether it is an error (control thread; docs/verification.md#live).
  [[nodiscard]] std::vector<std::pair<bool, std::string>> new_events();
  // A warning about input that does not match the profile, or "" (control thread).
  [[nodiscard]] std::string input_warning() const;
  // Asks the source loop to end without waiting (any thread).
  void request_stop() noexcept;
  void stop();
  [[nodiscard]] LiveResult result();

  struct Impl;  // app/src/live/pipeline.cpp

 private:
  std::unique_ptr<Impl> impl_;
};

// configure(), start(), a status line every opt.status_period_s until the run ends, stop(),
// result(). Setup errors (bad source spec, device cannot be opened, unknown tool) throw
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
