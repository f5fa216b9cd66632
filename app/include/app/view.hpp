// app/view.hpp — rendering entry points of the CLI: `lbrsim batch --png`, `lbrsim view`, and
// a path streamer that feeds a tool path through the kernel in (scaled) real time on its
// own geometry thread, publishing to a gfx::SolidExchange as the live pipeline does.
#pragma once

#include <atomic>
#include <cstdint>
#include <array>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/batch.hpp"
#include "app/profile.hpp"
#include "gfx/capture.hpp"
#include "gfx/exchange.hpp"
#include "gfx/render_thread.hpp"
#include "motion/path_sweeps.hpp"
#include "motion/tool_table.hpp"
#include "nc/toolpath.hpp"
#include "verify/collision.hpp"

namespace lbr::app {

// Tool of the last motion segment at the end pose of `path` (for drawing a batch result).
[[nodiscard]] std::vector<gfx::ToolState> final_tools(const Profile& profile, const nc::Toolpath& path);

struct StreamOptions {
  double speed = 1.0;             // simulated seconds per wall second
  double sample_period_s = 0.004; // controller sample period the path is sampled at [s]
  double tick_s = 0.010;          // geometry batch period (wall) [s]
  // Operator replay control (pause / step / speed / restart), or nullptr: stream at `speed`
  // to the end. With a control the streamer keeps running after the end (a restart may
  // come) until stop().
  gfx::ReplayControl* control = nullptr;
};

// Streams the channels' tool paths through `solid` on a geometry thread: each tick, the
// sweeps due by then are subtracted as one batch and published (gfx::SolidExchange
// contract). The sweeps are those of `lbrsim batch --sampled` (motion::plan_channels: the
// machine emulator's samples every sample_period_s through each channel's kinematics), so
// every machine kind animates, and the final solid is the batch one; programs with explicit
// tool axes (CL data) stream their segments at the emulator's end times instead. The solid
// belongs to that thread between start() and stop()/done(). Setup throws like batch (e.g. a
// tool that is not in the tool table, naming the program line).
//
// With the profile's [checks] on, each tick's sweeps go through verify::CollisionChecker
// before they are subtracted, as in `lbrsim batch` (a run of findings is measured against the
// stock of its moment), and the newest events are the status bar's alarms. A sampled stream
// has no G0: a sweep is a rapid when its tip moves faster than the profile's max cutting feed,
// as in live mode (docs/verification.md#view).
class PathStreamer {
 public:
  PathStreamer(const Profile& profile, const nc::Toolpath& path, geom::LbrSolid& solid, gfx::SolidExchange& ex,
               StreamOptions opt = {});
  PathStreamer(const Profile& profile, const std::vector<ChannelPath>& channels, geom::LbrSolid& solid,
               gfx::SolidExchange& ex, StreamOptions opt = {});
  ~PathStreamer();
  PathStreamer(const PathStreamer&) = delete;
  PathStreamer& operator=(const PathStreamer&) = delete;
  void start();
  void stop();
  [[nodiscard]] bool done() const noexcept { return done_.load(std::memory_order_acquire); }
  [[nodiscard]] double duration_s() const noexcept { return duration_s_; }  // simulated machining time
  [[nodiscard]] std::uint64_t batches() const noexcept { return batches_.load(std::memory_order_relaxed); }
  // Where the stream stands after its latest tick: simulated machining time [s] and the
  // source line of channel 0's newest applied sweep (-1: none yet), as published in LiveStats.
  [[nodiscard]] double position_s() const noexcept { return position_s_.load(std::memory_order_acquire); }
  [[nodiscard]] std::int64_t program_line() const noexcept { return line_pub_.load(std::memory_order_acquire); }
  // The planned sweeps, in time order, each with its source line (tests, tools).
  [[nodiscard]] const std::vector<motion::TimedSweep>& sweeps() const noexcept { return sweeps_; }
  // Wall time of each subtract() batch [ms] (valid after stop()/done()).
  [[nodiscard]] const std::vector<double>& batch_ms() const noexcept { return batch_ms_; }
  // The checks' events since the last restart (valid after stop()/done()).
  [[nodiscard]] const std::vector<verify::Event>& events() const noexcept { return events_; }

 private:
  void loop();
  // Simulated time [s] reached after `dt_s` of wall time (speed, pause, single steps).
  double advance(double sim_s, double dt_s, std::size_t next);
  // Back to the untouched stock; every cell is republished.
  void restart(std::size_t& next, geom::MoveId& last);
  // A jump the operator asked for (ReplayControl::seek_*): the machining time to re-simulate
  // up to [s], or < 0 for none.
  double take_seek();
  // Subtracts the sweeps due by `sim_s` from `next` on as one batch (a jump: everything up to
  // its target); returns false when none was due.
  bool apply_due(double sim_s, std::size_t& next, geom::MoveId& last, std::vector<geom::SweepRef>& batch);
  // Tools to draw: each channel's milling tool at the end of its latest sweep up to `upto`.
  std::size_t tools_at(std::size_t upto, std::array<gfx::ToolState, gfx::kMaxTools>& out) const;
  // Sets up the checks for the planned sweeps (`sampled`: rapids by tip speed).
  void setup_checks(const Profile& profile, const std::vector<ChannelPath>& channels, bool sampled);
  // Subtracts sweeps [from, to) in checked pieces (CollisionChecker::check()).
  void subtract_checked(std::size_t from, std::size_t to, std::vector<geom::SweepRef>& batch);

  motion::ToolTable tools_;
  std::vector<motion::TimedSweep> sweeps_;
  double duration_s_ = 0.0;
  geom::LbrSolid& solid_;
  std::unique_ptr<geom::LbrSolid> initial_;  // the untouched stock (restart), with a control only
  gfx::SolidExchange& ex_;
  StreamOptions opt_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<std::uint64_t> batches_{0};
  std::vector<double> batch_ms_;
  std::int64_t line_ = -1;  // source line of channel 0's newest applied sweep
  std::atomic<double> position_s_{0.0};
  std::atomic<std::int64_t> line_pub_{-1};
  verify::MoveIndex index_;                            // segment ids (streams of segments)
  std::unique_ptr<verify::CollisionChecker> checker_;  // null: [checks] off
  std::vector<std::uint8_t> rapid_;                    // per sweep (sampled streams)
  std::vector<verify::Event> events_;
  std::vector<std::string> sources_;                   // program of each channel
};

// The stock `lbrsim batch` would use for these channels (regions = auto sized like batch).
[[nodiscard]] geom::SolidSpec stream_solid_spec(const Profile& profile, const std::vector<ChannelPath>& channels);

struct ViewOptions {
  gfx::RenderThreadConfig render;
  bool animate = false;        // stream the program in real time instead of showing the result
  StreamOptions stream;
  bool hidden = false;         // no visible window (headless run of the render thread)
  std::size_t frames = 0;      // stop after N frames (0: until the window closes / the stream ends)
  bool quiet = false;
  bool kiosk = false;          // full screen, undecorated, quit needs the UI's confirmation
};

// `lbrsim view`: the render thread on a window, fed by a batch result or a streamed run of
// the channels (one for a single program; a profile's [[channel]] tables). Returns the
// process exit code.
int run_view(const Profile& profile, const std::vector<ChannelPath>& channels, const ViewOptions& opt);

// A program file's lines (line 1 first, CR of CRLF removed) for the UI's program panel;
// empty when the file cannot be read (the built-in demo has none).
[[nodiscard]] std::vector<std::string> program_text(const std::string& file);

}  // namespace lbr::app
