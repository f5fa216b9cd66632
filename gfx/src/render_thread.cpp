#include "gfx/render_thread.hpp"

#include "measure.hpp"
#include "ui.hpp"

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
  ui_on_ = cfg_.ui.enabled && win_.visible();
  if (ui_on_) opt_.show_hud = opt_.show_legend = false;  // the status bar and view panel show them
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

void RenderThread::ui_event(const UiEvent& e) {
  if (!ui_on_) return;
  std::lock_guard lock(mu_);
  if (events_.size() < 1024) events_.push_back(e);  // a stalled render thread cannot grow it without bound
}

bool RenderThread::ui_hit(double x, double y) {
  if (!ui_on_) return false;
  std::lock_guard lock(mu_);
  if (ui_modal_ || ask_quit_) return true;
  return std::any_of(ui_rects_.begin(), ui_rects_.end(), [&](const UiRect& r) { return r.contains(x, y); });
}

bool RenderThread::ui_item(const std::string& label, UiRect& out) {
  std::lock_guard lock(mu_);
  for (const auto& [l, r] : ui_items_)
    if (l == label) {
      out = r;
      return true;
    }
  return false;
}

void RenderThread::pick(double x, double y) {
  if (!ui_on_) return;
  std::lock_guard lock(mu_);
  if (picks_.size() < 8) picks_.emplace_back(x, y);
}

std::vector<MeasurePoint> RenderThread::measured() {
  std::lock_guard lock(mu_);
  return measured_;
}

std::uint64_t RenderThread::measure_misses() {
  std::lock_guard lock(mu_);
  return measure_misses_;
}

void RenderThread::ask_quit() {
  std::lock_guard lock(mu_);
  ask_quit_ = true;
}

Image RenderThread::capture(double timeout_s) {
  std::unique_lock lock(mu_);
  capture_req_ = true;
  capture_done_ = false;
  const bool got = capture_cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return capture_done_; });
  capture_req_ = false;
  return got ? std::move(capture_) : Image{};
}

// The geometry thread's latest snapshot, if a new one was published, then sync().
void RenderThread::receive_and_sync(Renderer& ren, Snapshot& snap, Camera& cam, int& w, int& h) {
  if (ex_.take(snap)) {
    ren.receive(snap);
    ++report_.snapshots;
  }
  sync(ren, cam, w, h);
}

// Takes the main thread's camera, options, size and UI events for this frame.
void RenderThread::sync(Renderer& ren, Camera& cam, int& w, int& h) {
  std::lock_guard lock(mu_);
  if (fit_) {
    cam_.fit(ren.stock_box(), static_cast<double>(w_) / std::max(h_, 1));
    fit_ = false;
  }
  cam = cam_;
  RenderOptions& o = ren.options();
  o.color = opt_.color;
  o.show_tools = opt_.show_tools;
  o.show_path = opt_.show_path;
  o.show_hud = opt_.show_hud;
  o.show_outline = opt_.show_outline;
  o.section_axis = opt_.section_axis;
  o.section_mm = opt_.section_mm;
  o.section_flip = opt_.section_flip;
  if (o.notice != opt_.notice) o.notice = opt_.notice;
  if (o.design != opt_.design) o.design = opt_.design;
  w = w_;
  h = h_;
  if (ui_ != nullptr) ui_->feed(events_);
}

// What the operator asked for in the UI, into the shared camera and options.
void RenderThread::apply_ui(const detail::UiActions& act) {
  if (act.quit) quit_.store(true, std::memory_order_release);
  if (act.touch_pan >= 0) touch_pan_.store(act.touch_pan == 1, std::memory_order_relaxed);
  if (act.measure >= 0) measuring_.store(act.measure == 1, std::memory_order_relaxed);
  std::lock_guard lock(mu_);
  measured_ = ui_->measured();
  ask_quit_ = false;
  ui_rects_ = ui_->rects();
  ui_items_.clear();
  for (const auto& [label, r] : ui_->items()) ui_items_.emplace_back(label, r);
  ui_modal_ = ui_->modal();
  if (act.view >= 0) {
    cam_.set_view(static_cast<StandardView>(act.view));
    cam_.ortho = act.view == static_cast<int>(StandardView::Top);
    fit_ = true;
  }
  if (act.fit) fit_ = true;
  if (act.zoom_steps != 0) cam_.zoom(act.zoom_steps);
  if (act.toggle_ortho) cam_.ortho = !cam_.ortho;
  if (act.options_changed) {
    opt_.color = act.opt.color;
    opt_.show_tools = act.opt.show_tools;
    opt_.show_path = act.opt.show_path;
    opt_.show_outline = act.opt.show_outline;
    opt_.section_axis = act.opt.section_axis;
    opt_.section_mm = act.opt.section_mm;
    opt_.section_flip = act.opt.section_flip;
  }
}

// The frame into the window (with the UI over it) or offscreen, and the optional PNG.
FrameInfo RenderThread::draw(Renderer& ren, const Camera& cam, int w, int h, double dt_s, bool force_shot) {
  FrameInfo fi;
  const bool shot = cfg_.screenshot_every > 0 &&
                    (force_shot || report_.frames % static_cast<std::uint64_t>(cfg_.screenshot_every) == 0);
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
    if (ui_ != nullptr) {
      bool ask = false;
      {
        std::lock_guard lock(mu_);
        ask = ask_quit_;
      }
      serve_picks(ren, cam, w, h);
      const detail::UiFrameInput in{cam, ren.options(), touch_pan(), measuring(), ask, w, h, dt_s};
      apply_ui(ui_->frame(ren, in));
    }
    serve_capture(w, h);
    glfwSwapBuffers(win_.handle());
  } else {
    glFinish();  // the frame's work is done (and measured) within its own period
  }
  return fi;
}

// With screenshots on, the state at stop() as one more PNG (numbered after the last frame),
// so that the last file shows the end of the run however many frames a slow machine drew.
void RenderThread::final_shot(Renderer& ren, Snapshot& snap) {
  if (cfg_.screenshot_every <= 0) return;
  Camera cam;
  int w = 0, h = 0;
  receive_and_sync(ren, snap, cam, w, h);
  (void)draw(ren, cam, w, h, 1.0 / cfg_.rate_hz, true);
  ++report_.frames;
}

// Taps of the Measure tool, against the mirror solid as this frame shows it (the levels of
// the regions drawn; never the geometry thread's solid).
void RenderThread::serve_picks(Renderer& ren, const Camera& cam, int w, int h) {
  std::vector<std::pair<double, double>> picks;
  {
    std::lock_guard lock(mu_);
    picks.swap(picks_);
  }
  for (const auto& [x, y] : picks) {
    MeasurePoint p;
    if (detail::measure_at(ren.mirror().solid(), cam, ren.options(), x, y, w, h, p)) {
      ui_->add_measure(p);
    } else {
      ui_->measure_missed();
      std::lock_guard lock(mu_);
      ++measure_misses_;
    }
  }
}

// A capture() waiting on the main thread gets this frame's back buffer.
void RenderThread::serve_capture(int w, int h) {
  {
    std::lock_guard lock(mu_);
    if (!capture_req_ || capture_done_) return;
  }
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  std::vector<std::uint8_t> rows(img.rgba.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  const std::size_t stride = static_cast<std::size_t>(w) * 4;
  for (int y = 0; y < h; ++y)  // GL rows are bottom first
    std::copy_n(rows.data() + static_cast<std::size_t>(h - 1 - y) * stride, stride,
                img.rgba.data() + static_cast<std::size_t>(y) * stride);
  std::lock_guard lock(mu_);
  capture_ = std::move(img);
  capture_done_ = true;
  capture_cv_.notify_all();
}

void RenderThread::loop() {
  using clock = std::chrono::steady_clock;
  win_.make_current();
  try {
    Renderer ren(*initial_, cfg_.render);
    initial_.reset();
    std::unique_ptr<detail::Ui> ui;
    if (ui_on_) {
      ui = std::make_unique<detail::Ui>(cfg_.ui);
      ui_ = ui.get();
    }
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
      double dt_s = 1.0 / cfg_.rate_hz;
      if (prev != clock::time_point{}) {
        const double p = std::chrono::duration<double, std::milli>(t0 - prev).count();
        dt_s = p * 1e-3;
        report_.period_ms.push_back(p);
        pacing.period_ms = p;
        window_periods.push_back(p);
        if (window_periods.size() > 300) window_periods.erase(window_periods.begin(), window_periods.begin() + 100);
        if (report_.frames % 15 == 0) pacing.p99_period_ms = PacingReport::percentile(window_periods, 0.99);
      }
      prev = t0;
      Camera cam;
      int w = 0, h = 0;
      receive_and_sync(ren, snap, cam, w, h);
      ren.set_pacing(pacing);
      const FrameInfo fi = draw(ren, cam, w, h, dt_s);
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
    if (stop_.load(std::memory_order_acquire)) final_shot(ren, snap);
    ui_ = nullptr;
  } catch (const std::exception& e) {
    ui_ = nullptr;
    report_.error = e.what();
  }
  win_.release_context();
  running_.store(false, std::memory_order_release);
}

}  // namespace lbr::gfx
