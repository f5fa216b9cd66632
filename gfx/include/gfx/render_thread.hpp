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
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gfx/camera.hpp"
#include "gfx/exchange.hpp"
#include "gfx/renderer.hpp"
#include "gfx/ui.hpp"
#include "gfx/window.hpp"

namespace lbr::gfx {

namespace detail {
class Ui;
struct UiActions;
}  // namespace detail

struct RenderThreadConfig {
  double rate_hz = 30.0;
  bool vsync = true;                 // swap interval 1 on visible windows
  RenderOptions render;
  StandardView view = StandardView::Iso;
  bool ortho = false;
  int width = 1280, height = 800;    // drawing size: the window's framebuffer size initially
  int screenshot_every = 0;          // 0: none; N: a PNG every N frames, and one of the final state at stop()
  std::string screenshot_prefix = "frame-";  // files PREFIX000123.png
  std::size_t max_frames = 0;        // 0: until stop(); otherwise stop by itself after N frames
  UiConfig ui;                       // the operator UI (visible windows only; replaces the HUD)
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
  // --- operator UI (main thread; no-ops without it) ---
  // Queues a pointer event for the UI (applied at the next frame).
  void ui_event(const UiEvent& e);
  // True when (x, y) [window px] lies on the UI as drawn last frame, or a modal dialog is
  // open: a press there belongs to the UI, not to the 3D view.
  [[nodiscard]] bool ui_hit(double x, double y);
  [[nodiscard]] bool ui_enabled() const noexcept { return ui_on_; }
  void ask_quit();  // kiosk: show the quit confirmation
  [[nodiscard]] bool quit_confirmed() const noexcept { return quit_.load(std::memory_order_acquire); }
  // One-finger drag pans instead of orbiting (the UI's Orbit / Pan switch).
  [[nodiscard]] bool touch_pan() const noexcept { return touch_pan_.load(std::memory_order_relaxed); }
  // Measure mode (the UI's Measure switch): a tap on the 3D view picks a point.
  [[nodiscard]] bool measuring() const noexcept { return measuring_.load(std::memory_order_relaxed); }
  // Picks the part's point under window point (x, y) at the next frame (at most 8 waiting).
  void pick(double x, double y);
  // The Measure panel's points as of the last frame (0 to 2) and taps that met no material.
  [[nodiscard]] std::vector<MeasurePoint> measured();
  [[nodiscard]] std::uint64_t measure_misses();
  // The next shown frame as drawn, UI included (visible windows); waits up to timeout_s and
  // returns an empty image when no frame came.
  [[nodiscard]] Image capture(double timeout_s);
  // Where the UI drew the control `label` ("Top", "Pause", "##section", ...) last frame;
  // false when it was not drawn.
  [[nodiscard]] bool ui_item(const std::string& label, UiRect& out);

  // Available after stop().
  [[nodiscard]] const PacingReport& report() const noexcept { return report_; }

 private:
  void loop();
  // Steps of one frame of loop().
  void sync(Renderer& ren, Camera& cam, int& w, int& h);
  void receive_and_sync(Renderer& ren, Snapshot& snap, Camera& cam, int& w, int& h);
  void apply_ui(const detail::UiActions& act);
  FrameInfo draw(Renderer& ren, const Camera& cam, int w, int h, double dt_s, bool force_shot = false);
  void final_shot(Renderer& ren, Snapshot& snap);
  void serve_capture(int w, int h);
  void serve_picks(Renderer& ren, const Camera& cam, int w, int h);

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
  // Operator UI state shared with the main thread (under mu_ unless atomic).
  bool ui_on_ = false;
  detail::Ui* ui_ = nullptr;         // render thread only, alive inside loop()
  std::deque<UiEvent> events_;
  std::vector<UiRect> ui_rects_;
  std::vector<std::pair<std::string, UiRect>> ui_items_;
  bool ui_modal_ = false, ask_quit_ = false, capture_req_ = false, capture_done_ = false;
  Image capture_;
  std::vector<std::pair<double, double>> picks_;  // taps waiting for the Measure tool [px]
  std::vector<MeasurePoint> measured_;
  std::uint64_t measure_misses_ = 0;
  std::condition_variable capture_cv_;
  std::atomic<bool> quit_{false}, touch_pan_{false}, measuring_{false};
};

}  // namespace lbr::gfx
