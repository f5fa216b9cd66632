// app/view.hpp — rendering entry points of the CLI: `lbrsim batch --png`, `lbrsim view`, and
// a path streamer that feeds a tool path through the kernel in (scaled) real time on its
// own geometry thread, publishing to a gfx::SolidExchange as the live pipeline does.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/batch.hpp"
#include "app/profile.hpp"
#include "gfx/capture.hpp"
#include "gfx/exchange.hpp"
#include "gfx/render_thread.hpp"
#include "nc/toolpath.hpp"

namespace lbr::app {

// Tool of the last motion segment at the end pose of `path` (for drawing a batch result).
[[nodiscard]] std::vector<gfx::ToolState> final_tools(const Profile& profile, const nc::Toolpath& path);

struct StreamOptions {
  double speed = 1.0;             // simulated seconds per wall second
  double sample_period_s = 0.004; // controller sample period the path is sampled at [s]
  double tick_s = 0.010;          // geometry batch period (wall) [s]
};

// Streams a tool path through `solid` on a geometry thread: each tick, the samples due by
// then are subtracted as one batch and published (gfx::SolidExchange contract). The solid
// belongs to that thread between start() and stop()/done().
class PathStreamer {
 public:
  PathStreamer(const Profile& profile, const nc::Toolpath& path, geom::LbrSolid& solid, gfx::SolidExchange& ex,
               StreamOptions opt = {});
  ~PathStreamer();
  PathStreamer(const PathStreamer&) = delete;
  PathStreamer& operator=(const PathStreamer&) = delete;
  void start();
  void stop();
  [[nodiscard]] bool done() const noexcept { return done_.load(std::memory_order_acquire); }
  [[nodiscard]] double duration_s() const noexcept;  // simulated machining time
  [[nodiscard]] std::uint64_t batches() const noexcept { return batches_.load(std::memory_order_relaxed); }
  // Wall time of each subtract() batch [ms] (valid after stop()/done()).
  [[nodiscard]] const std::vector<double>& batch_ms() const noexcept { return batch_ms_; }

 private:
  struct Sample {
    double t;
    geom::Pose pose;
    int tool;
    geom::MoveId id;
  };
  void loop();
  std::map<int, geom::CutterShape> shapes_;
  std::map<int, geom::Tool> tools_;
  std::vector<Sample> samples_;
  geom::LbrSolid& solid_;
  gfx::SolidExchange& ex_;
  StreamOptions opt_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<std::uint64_t> batches_{0};
  std::vector<double> batch_ms_;
};

struct ViewOptions {
  gfx::RenderThreadConfig render;
  bool animate = false;        // stream the program in real time instead of showing the result
  StreamOptions stream;
  bool hidden = false;         // no visible window (headless run of the render thread)
  std::size_t frames = 0;      // stop after N frames (0: until the window closes / the stream ends)
  bool quiet = false;
};

// `lbrsim view`: the render thread on a window, fed by a batch result or a streamed run.
// Returns the process exit code.
int run_view(const Profile& profile, const nc::Toolpath& path, const ViewOptions& opt);

}  // namespace lbr::app
