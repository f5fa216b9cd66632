#include "gfx/render_thread.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace lbr::gfx {

double PacingReport::percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

RenderThread::RenderThread(Window& win, SolidExchange& exchange, const geom::LbrSolid& initial, RenderThreadConfig cfg)
    : win_(win), ex_(exchange), initial_(std::make_unique<geom::LbrSolid>(initial)), cfg_(std::move(cfg)) {
  opt_ = cfg_.render;
  w_ = cfg_.width;
  h_ = cfg_.height;
  cam_.set_view(cfg_.view);
  cam_.ortho = cfg_.ortho;
}

RenderThread::~RenderThread() { stop(); }

void RenderThread::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  running_.store(true, std::memory_order_release);
  win_.release_context();
  thread_ = std::thread([this] { loop(); });
}

void RenderThread::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) {
    thread_.join();
    win_.make_current();
  }
}

void RenderThread::edit(const std::function<void(Camera&, RenderOptions&)>& f) {
  std::lock_guard lock(mu_);
  f(cam_, opt_);
}

void RenderThread::resize(int w, int h) {
  std::lock_guard lock(mu_);
  w_ = w;
  h_ = h;
}

void RenderThread::request_fit() {
  std::lock_guard lock(mu_);
  fit_ = true;
}

void RenderThread::loop() {
  using clock = std::chrono::steady_clock;
  win_.make_current();
  try {
    Renderer ren(*initial_, cfg_.render);
    initial_.reset();
    report_.gl = Window::gl_description();
    glfwSwapInterval(win_.visible() && cfg_.vsync ? 1 : 0);
    const auto period = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / cfg_.rate_hz));
    Snapshot snap;
    snap.path.reserve(8192);
    auto next = clock::now();
    clock::time_point prev{};
    std::vector<double> window_periods;
    PacingInfo pacing;
    pacing.rate_hz = cfg_.rate_hz;
    while (!stop_.load(std::memory_order_acquire)) {
      frames_done_.store(frames_done_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      const auto t0 = clock::now();
      if (prev != clock::time_point{}) {
        const double p = std::chrono::duration<double, std::milli>(t0 - prev).count();
        report_.period_ms.push_back(p);
        pacing.period_ms = p;
        window_periods.push_back(p);
        if (window_periods.size() > 300) window_periods.erase(window_periods.begin(), window_periods.begin() + 100);
        if (report_.frames % 15 == 0) pacing.p99_period_ms = PacingReport::percentile(window_periods, 0.99);
      }
      prev = t0;
      if (ex_.take(snap)) {
        ren.receive(snap);
        ++report_.snapshots;
      }
      Camera cam;
      int w, h;
      {
        std::lock_guard lock(mu_);
        if (fit_) {
          cam_.fit(ren.stock_box(), static_cast<double>(w_) / std::max(h_, 1));
          fit_ = false;
        }
        cam = cam_;
        ren.options().color = opt_.color;
        ren.options().show_tools = opt_.show_tools;
        ren.options().show_path = opt_.show_path;
        ren.options().show_hud = opt_.show_hud;
        if (ren.options().notice != opt_.notice) ren.options().notice = opt_.notice;
        w = w_;
        h = h_;
      }
      ren.set_pacing(pacing);
      FrameInfo fi;
      const bool shot = cfg_.screenshot_every > 0 && report_.frames % static_cast<std::uint64_t>(cfg_.screenshot_every) == 0;
      // Hidden windows draw offscreen (their default framebuffer may not be backed).
      if (shot) {
        const Image img = ren.render_offscreen(cam, w, h, false, &fi);
        char name[32];
        std::snprintf(name, sizeof name, "%06llu.png", static_cast<unsigned long long>(report_.frames));
        write_png(cfg_.screenshot_prefix + name, img);
        ++report_.screenshots;
      } else if (!win_.visible()) {
        fi = ren.frame_offscreen(cam, w, h);
      }
      if (win_.visible()) {
        const FrameInfo f2 = ren.frame(cam, w, h);
        if (!shot) fi = f2;
        glfwSwapBuffers(win_.handle());
      } else {
        glFinish();  // the frame's work is done (and measured) within its own period
      }
      const double work = std::chrono::duration<double, std::milli>(clock::now() - t0).count();
      pacing.frame_ms = work;
      report_.work_ms.push_back(work);
      report_.regions_rebuilt.push_back(fi.step.regions_rebuilt);
      report_.regions_applied.push_back(fi.step.regions_applied);
      report_.mesh_ms.push_back(fi.step.mesh_ms);
      ++report_.frames;
      if (cfg_.max_frames && report_.frames >= cfg_.max_frames) break;
      next += period;
      const auto now = clock::now();
      if (now > next) {
        ++report_.late_frames;
        pacing.late_frames = report_.late_frames;
        next = now;  // do not try to catch up with a burst of frames
      } else {
        std::this_thread::sleep_until(next);
      }
    }
  } catch (const std::exception& e) {
    report_.error = e.what();
  }
  win_.release_context();
  running_.store(false, std::memory_order_release);
}

}  // namespace lbr::gfx
