// gfx/render_thread.hpp — the render thread (docs/rendering.md §3): owns the OpenGL context
// of a Window, runs at a fixed rate (default 30 Hz; vsync when the window is visible), and
// each frame takes the geometry thread's latest snapshot from a SolidExchange without
// blocking it, rebuilds visible dirty regions within a per-frame budget, uploads, draws,
// and optionally writes a PNG every N frames.
//
// Threads: construct, start(), stop() and the input functions run on the main thread,
// which also polls GLFW events (GLFW requires it); the render thread only issues GL calls
// and glfwSwapBuffers. Camera and options cross between them under a mutex that only these
// two non-real-time threads take. The geometry thread only ever touches the exchange.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gfx/camera.hpp"
#include "gfx/exchange.hpp"
#include "gfx/renderer.hpp"
#include "gfx/window.hpp"

namespace lbr::gfx {

struct RenderThreadConfig {
  double rate_hz = 30.0;
  bool vsync = true;                 // swap interval 1 on visible windows
  RenderOptions render;
  StandardView view = StandardView::Iso;
  bool ortho = false;
  int width = 1280, height = 800;    // drawing size: the window's framebuffer size initially
  int screenshot_every = 0;          // 0: none; N: a PNG every N frames
  std::string screenshot_prefix = "frame-";  // files PREFIX000123.png
  std::size_t max_frames = 0;        // 0: until stop(); otherwise stop by itself after N frames
};

// Frame-pacing record of a run (benchmark output, docs/performance.md).
struct PacingReport {
  std::vector<double> period_ms;      // start-to-start, one per frame after the first
  std::vector<double> work_ms;        // rebuild + upload + draw (+ screenshot) per frame
  std::vector<int> regions_rebuilt;   // per frame
  std::vector<int> regions_applied;   // per frame
  std::vector<double> mesh_ms;        // per frame
  std::uint64_t frames = 0, late_frames = 0, snapshots = 0, screenshots = 0;
  std::string gl;                     // renderer description
  std::string error;                  // non-empty when the thread stopped on an exception
  // Percentile q in [0, 1] of a sample set (nearest rank); 0 for an empty set.
  [[nodiscard]] static double percentile(std::vector<double> v, double q);
};

class RenderThread {
 public:
  // `initial`: the solid as it was before the geometry thread's first publish (copied).
  // The window's context must be current on the calling (main) thread; start() hands it over.
  RenderThread(Window& win, SolidExchange& exchange, const geom::LbrSolid& initial, RenderThreadConfig cfg);
  ~RenderThread();  // stops and joins
  RenderThread(const RenderThread&) = delete;
  RenderThread& operator=(const RenderThread&) = delete;

  void start();
  // Stops the loop and joins; the context is current on the calling thread again.
  void stop();
  [[nodiscard]] bool running() const noexcept { return running_.load(std::memory_order_acquire); }

  // Main thread: change the camera / options (applied at the next frame).
  void edit(const std::function<void(Camera&, RenderOptions&)>& f);
  void resize(int w, int h);
  // Request fit-to-part at the next frame (uses the stock box).
  void request_fit();

  // Frame loop passes so far (any thread): the service watchdog's heartbeat (app/watchdog.hpp).
  [[nodiscard]] std::uint64_t frames_done() const noexcept { return frames_done_.load(std::memory_order_relaxed); }

  // Available after stop().
  [[nodiscard]] const PacingReport& report() const noexcept { return report_; }

 private:
  void loop();

  Window& win_;
  SolidExchange& ex_;
  std::unique_ptr<geom::LbrSolid> initial_;
  RenderThreadConfig cfg_;
  std::thread thread_;
  std::atomic<bool> running_{false}, stop_{false};
  std::atomic<std::uint64_t> frames_done_{0};
  std::mutex mu_;  // guards the fields below (main ↔ render thread, never the geometry thread)
  Camera cam_;
  RenderOptions opt_;
  int w_ = 0, h_ = 0;
  bool fit_ = true;
  PacingReport report_;
};

}  // namespace lbr::gfx
