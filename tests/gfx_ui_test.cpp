// The operator UI (docs/ui.md) on a real window under `xvfb-run -a`: pointer events are
// injected at the GLFW level (gfx::EventRouter, what the GLFW callbacks call) at the places
// where the UI drew its controls, and the assertions read the frame the window shows
// (RenderThread::capture) or the state the control drives. A view button changes the camera
// and the image as expected; the section slider removes the part beyond the plane exactly
// where the plane projects; pause stops the removed volume from growing.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <future>
#include <functional>
#include <memory>
#include <thread>

#include <glm/glm.hpp>

#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "app/view.hpp"
#include "stream_test_util.hpp"
#include "gfx/render_thread.hpp"
#include "gfx/renderer.hpp"
#include "gfx/viewer.hpp"
#include "gfx/window.hpp"
#include "gfx_test_util.hpp"

namespace lbr {
namespace {

using namespace test;
using namespace test::gfx_scene;
using Clock = std::chrono::steady_clock;

constexpr int kW = 1024, kH = 768;

bool wait_for(const std::function<bool()>& cond, double timeout_s = 30.0) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (Clock::now() < end) {
    if (cond()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return cond();
}

bool is_background(const std::uint8_t* p) {  // the clear colour (0.13, 0.14, 0.17)
  return std::abs(p[0] - 33) <= 2 && std::abs(p[1] - 36) <= 2 && std::abs(p[2] - 43) <= 2;
}

// A window with the render thread and the UI on, and the router the GLFW callbacks use.
class UiWindow {
 public:
  UiWindow(const geom::LbrSolid& solid, gfx::StandardView view, gfx::ReplayControl* replay = nullptr, int width = kW,
           int height = kH, bool kiosk = false, std::vector<std::string> program = {}, std::string source = "gfx_ui_test",
           gfx::SolidExchange* exchange = nullptr) {
    win_ = std::make_unique<gfx::Window>(width, height, true, "gfx_ui_test");
    gfx::RenderThreadConfig cfg;
    cfg.rate_hz = 20;
    cfg.vsync = false;
    cfg.width = width;
    cfg.height = height;
    cfg.view = view;
    cfg.ortho = view == gfx::StandardView::Top;
    cfg.render.show_tools = cfg.render.show_path = false;
    cfg.ui.enabled = true;
    cfg.ui.scale = 1.5f;
    cfg.ui.source = std::move(source);
    cfg.ui.replay = replay;
    cfg.ui.kiosk = kiosk;
    cfg.ui.program = std::move(program);
    rt_ = std::make_unique<gfx::RenderThread>(*win_, exchange != nullptr ? *exchange : ex_, solid, cfg);
    router_ = std::make_unique<gfx::EventRouter>(*rt_, height);
    rt_->start();
  }
  ~UiWindow() { rt_->stop(); }

  gfx::SolidExchange& exchange() { return ex_; }
  gfx::RenderThread& rt() { return *rt_; }
  // Where `label` is drawn, once it stays in place from one frame to the next (windows that
  // just appeared, like a dialog, are measured in their first frames).
  gfx::UiRect item(const std::string& label) {
    gfx::UiRect r, again;
    EXPECT_TRUE(wait_for([&] {
      if (!rt_->ui_item(label, r)) return false;
      (void)rt_->capture(10.0);
      return rt_->ui_item(label, again) && again.x0 == r.x0 && again.y0 == r.y0 && again.x1 == r.x1 &&
             again.y1 == r.y1;
    })) << "the UI never drew '" << label << "' in one place";
    return r;
  }
  // A one-finger tap at (x, y).
  void tap(double x, double y) {
    router_->cursor(x, y);
    router_->button(0, true, x, y);
    router_->button(0, false, x, y);
  }
  void tap(const std::string& label) {
    const gfx::UiRect r = item(label);
    tap(0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1));
  }
  void drag(double x0, double y0, double x1, double y1) {
    router_->cursor(x0, y0);
    router_->button(0, true, x0, y0);
    for (int i = 1; i <= 10; ++i) router_->cursor(x0 + (x1 - x0) * i / 10.0, y0 + (y1 - y0) * i / 10.0);
    router_->button(0, false, x1, y1);
  }
  std::pair<gfx::Camera, gfx::RenderOptions> state() {
    std::pair<gfx::Camera, gfx::RenderOptions> s;
    rt_->edit([&](gfx::Camera& c, gfx::RenderOptions& o) { s = {c, o}; });
    return s;
  }
  // A frame drawn after everything asked so far (two frames later), as the window shows it.
  gfx::Image frame() {
    (void)rt_->capture(30.0);
    gfx::Image img = rt_->capture(30.0);
    EXPECT_GT(img.width, 0);
    return img;
  }

 private:
  gfx::SolidExchange ex_;
  std::unique_ptr<gfx::Window> win_;
  std::unique_ptr<gfx::RenderThread> rt_;
  std::unique_ptr<gfx::EventRouter> router_;
};

class GfxUi : public ::testing::Test {
 protected:
  // A hidden window for the whole suite keeps GLFW's one X connection open between the
  // tests' windows (no reconnect to a display that other xvfb-run instances may be racing for).
  static void SetUpTestSuite() {
    if (gfx::display_available()) keep_ = std::make_unique<gfx::Window>(16, 16, false, "gfx_ui_test");
  }
  static void TearDownTestSuite() { keep_.reset(); }
  void SetUp() override {
    if (!keep_) GTEST_SKIP() << "no display (run under xvfb-run -a)";
  }
  static std::unique_ptr<gfx::Window> keep_;
};
std::unique_ptr<gfx::Window> GfxUi::keep_;

geom::LbrSolid pocketed() {
  geom::LbrSolid s = stock();
  const geom::CutterShape t6 = flat6();
  const auto path = pocket_path();
  for (std::size_t i = 1; i < path.size(); ++i)
    cut(s, t6, {path[i - 1], {0, 0, 1}}, {path[i], {0, 0, 1}}, static_cast<geom::MoveId>(i));
  s.clear_dirty();
  return s;
}

const std::uint8_t* pixel_at(const gfx::Image& img, const gfx::Camera& cam, glm::dvec3 p) {
  const glm::dvec2 q = cam.project(p, img.width, img.height);
  return img.px(static_cast<int>(q.x), static_cast<int>(q.y));
}

TEST_F(GfxUi, TopButtonShowsTheStockFromAboveFilledToItsEdges) {
  UiWindow w(pocketed(), gfx::StandardView::Iso);
  const double yaw0 = w.state().first.yaw;
  w.tap("Top");
  ASSERT_TRUE(wait_for([&] { return std::abs(w.state().first.pitch - glm::radians(90.0)) < 1e-6; }));
  const gfx::Image img = w.frame();
  const gfx::Camera cam = w.state().first;
  EXPECT_TRUE(cam.ortho);
  // The stock's outline projects to an axis-aligned rectangle: 0.5 mm inside its left and
  // back edges is material, 0.5 mm outside is background (22 px/mm at this size).
  for (const glm::dvec3& inside : {glm::dvec3{0.5, 15, 0}, glm::dvec3{20, 29.5, 0}, glm::dvec3{2, 10, 0}}) {
    EXPECT_FALSE(w.rt().ui_hit(cam.project(inside, kW, kH).x, cam.project(inside, kW, kH).y));
    EXPECT_FALSE(is_background(pixel_at(img, cam, inside))) << inside.x << "," << inside.y;
  }
  for (const glm::dvec3& outside : {glm::dvec3{-0.5, 15, 0}, glm::dvec3{20, 30.5, 0}})
    EXPECT_TRUE(is_background(pixel_at(img, cam, outside))) << outside.x << "," << outside.y;
  // A drag on the 3D view orbits; a drag that starts on the UI panel does not.
  const gfx::UiRect fit = w.item("Fit");
  w.drag(0.5 * (fit.x0 + fit.x1), 0.5 * (fit.y0 + fit.y1), 0.5 * (fit.x0 + fit.x1) - 200, 300);
  EXPECT_DOUBLE_EQ(w.state().first.yaw, cam.yaw);
  w.drag(300, 300, 400, 300);
  EXPECT_NE(w.state().first.yaw, cam.yaw);
  EXPECT_NE(yaw0, glm::radians(90.0));
}

TEST_F(GfxUi, SectionSliderCutsAwayThePartBeyondThePlane) {
  UiWindow w(pocketed(), gfx::StandardView::Top);
  w.tap("X");
  ASSERT_TRUE(wait_for([&] { return w.state().second.section_axis == 0; }));
  EXPECT_DOUBLE_EQ(w.state().second.section_mm, 20.0);  // the stock's middle
  gfx::Image img = w.frame();
  const gfx::Camera cam = w.state().first;
  // Points of the top face along y = 25 mm, clear of the UI's panels.
  auto at = [&](const gfx::Image& im, double x_mm) {
    const glm::dvec2 q = cam.project({x_mm, 25, 0}, kW, kH);
    EXPECT_FALSE(w.rt().ui_hit(q.x, q.y)) << "x = " << x_mm << " mm lies under the UI";
    return im.px(static_cast<int>(q.x), static_cast<int>(q.y));
  };
  EXPECT_FALSE(is_background(at(img, 5)));
  EXPECT_FALSE(is_background(at(img, 19)));
  EXPECT_TRUE(is_background(at(img, 21)));
  EXPECT_TRUE(is_background(at(img, 30)));
  // Touch the slider at 60 % of its track: the plane moves to about x = 24.
  const gfx::UiRect s = w.item("##section");
  w.tap(s.x0 + 0.6 * (s.x1 - s.x0), 0.5 * (s.y0 + s.y1));
  ASSERT_TRUE(wait_for([&] { return w.state().second.section_mm > 21.0; }));
  const double x_mm = w.state().second.section_mm;
  EXPECT_NEAR(x_mm, 24.0, 2.5);
  img = w.frame();
  EXPECT_FALSE(is_background(at(img, x_mm - 1)));
  EXPECT_TRUE(is_background(at(img, x_mm + 1)));
  EXPECT_TRUE(is_background(at(img, 30)));
  // Off: the whole stock again.
  w.tap("Off");
  ASSERT_TRUE(wait_for([&] { return w.state().second.section_axis == -1; }));
  img = w.frame();
  EXPECT_FALSE(is_background(at(img, 30)));
}

TEST_F(GfxUi, PauseStopsTheRemovedVolumeFromGrowing) {
  const app::Profile profile = app::default_profile();
  const std::vector<app::ChannelPath> channels{{"", app::demo_toolpath(), profile.kin}};
  geom::LbrSolid solid(app::stream_solid_spec(profile, channels));
  solid.clear_dirty();
  gfx::ReplayControl ctl;
  UiWindow w(solid, gfx::StandardView::Iso, &ctl);
  app::StreamOptions so;
  so.control = &ctl;
  app::PathStreamer streamer(profile, channels, solid, w.exchange(), so);
  ctl.speed.store(streamer.duration_s() / 30.0);  // the whole program in about 30 s
  streamer.start();
  ASSERT_TRUE(wait_for([&] { return solid.volume_mm3() < solid.initial_volume_mm3() - 1.0; }));
  w.tap("Pause");
  ASSERT_TRUE(wait_for([&] { return ctl.paused.load(); }));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the tick in flight ends
  const std::uint64_t b0 = streamer.batches();
  const double v0 = solid.volume_mm3();  // no subtract() runs while paused
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(streamer.batches(), b0);
  EXPECT_EQ(solid.volume_mm3(), v0);
  gfx::UiRect play;
  EXPECT_TRUE(wait_for([&] { return w.rt().ui_item("Play", play); }));  // the button now says Play
  // One step: exactly one more batch (one controller sample).
  w.tap("Step");
  ASSERT_TRUE(wait_for([&] { return streamer.batches() == b0 + 1; }, 10.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(streamer.batches(), b0 + 1);
  w.tap("Play");
  ASSERT_TRUE(wait_for([&] { return !ctl.paused.load() && streamer.batches() > b0 + 5; }));
  ctl.speed.store(streamer.duration_s());  // the rest in about a second
  ASSERT_TRUE(wait_for([&] { return streamer.done(); }, 60.0));
  EXPECT_LT(solid.volume_mm3(), v0 - 1.0);  // the streamer idles at the end: no subtract() runs
  // Paused, Restart brings back the untouched stock (and nothing is cut again while paused).
  w.tap("Pause");
  ASSERT_TRUE(wait_for([&] { return ctl.paused.load(); }));
  w.tap("Restart");
  ASSERT_TRUE(wait_for([&] { return !streamer.done(); }));  // cleared once the stock is back
  EXPECT_NEAR(solid.volume_mm3(), solid.initial_volume_mm3(), 1e-6 * solid.initial_volume_mm3());
  streamer.stop();
}

// The same sweeps from the untouched stock up to `upto_s`, on a fresh solid [mm3 removed].
// Program panel and time slider (issue 17) on cam-pocket.ngc, paused: touching the time
// slider at 40 % re-simulates to about 40 % of the machining time (the removed volume is that
// of the sweeps up to there), the panel scrolls to the line being cut and highlights it;
// tapping a later line jumps to the end of that line's motion.
TEST_F(GfxUi, TimeSliderAndProgramLinesJumpTheSimulation) {
  const std::string prog = std::string(LBR_SOURCE_DIR) + "/config/programs/cam-pocket.ngc";
  const app::Profile profile = app::load_profile(std::string(LBR_SOURCE_DIR) + "/config/profiles/default-mill3.toml");
  const std::vector<app::ChannelPath> channels{{"", app::load_toolpath(prog, profile), profile.kin}};
  std::vector<std::string> lines;
  std::ifstream in(prog);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const geom::SolidSpec spec = app::stream_solid_spec(profile, channels);
  geom::LbrSolid solid(spec);
  solid.clear_dirty();
  gfx::ReplayControl ctl;
  ctl.paused.store(true);
  UiWindow w(solid, gfx::StandardView::Iso, &ctl, kW, kH, false, lines);
  app::StreamOptions so;
  so.control = &ctl;
  app::PathStreamer streamer(profile, channels, solid, w.exchange(), so);
  streamer.start();
  const gfx::UiRect bar = w.item("##time");
  w.tap(bar.x0 + 0.4 * (bar.x1 - bar.x0), 0.5 * (bar.y0 + bar.y1));
  ASSERT_TRUE(wait_for([&] { return streamer.position_s() > 0; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the tick that published it ends
  const double t = streamer.position_s();
  EXPECT_NEAR(t / streamer.duration_s(), 0.4, 0.05);
  const double removed_t = solid.initial_volume_mm3() - solid.volume_mm3();
  EXPECT_GT(removed_t, 1000.0);
  EXPECT_NEAR(removed_t, test::removed_by_sweeps_mm3(spec, streamer, t), 5e-5 * removed_t);
  // The current line is shown, highlighted: its row differs from the row below.
  const std::int64_t cur = streamer.program_line();
  ASSERT_GT(cur, 0);
  const gfx::UiRect row = w.item("##line " + std::to_string(cur));
  const gfx::UiRect below = w.item("##line " + std::to_string(cur + 1));
  const gfx::Image img = w.frame();
  const int x = static_cast<int>(row.x1) - 6;
  const std::uint8_t* a = img.px(x, static_cast<int>(0.5 * (row.y0 + row.y1)));
  const std::uint8_t* b = img.px(x, static_cast<int>(0.5 * (below.y0 + below.y1)));
  EXPECT_GT(std::abs(a[2] - b[2]), 20) << "the current line's row is not highlighted";
  // Tap a later visible line with motion: the simulation ends that line's motion.
  int target = 0;
  for (const motion::TimedSweep& sw : streamer.sweeps()) {
    gfx::UiRect r;
    if (sw.line > cur + 1 && w.rt().ui_item("##line " + std::to_string(sw.line), r)) {
      target = sw.line;
      break;
    }
  }
  ASSERT_GT(target, 0) << "no later line with motion is visible";
  double end_s = 0;
  for (const motion::TimedSweep& sw : streamer.sweeps())
    if (sw.line == target) end_s = sw.t_s;
  w.tap("##line " + std::to_string(target));
  ASSERT_TRUE(wait_for([&] { return streamer.program_line() == target && streamer.position_s() == end_s; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const double removed_line = solid.initial_volume_mm3() - solid.volume_mm3();
  EXPECT_GT(removed_line, removed_t);
  EXPECT_NEAR(removed_line, test::removed_by_sweeps_mm3(spec, streamer, end_s), 5e-5 * removed_line);
  streamer.stop();
}

// Live counters with alarms, as the geometry side would publish them.
gfx::LiveStats live_stats(bool alarm) {
  gfx::LiveStats L;
  L.live = true;
  L.sample_rate_hz = 250;
  L.lag_ms = 6.5;
  L.samples = 12000;
  L.ring_capacity = 4096;
  L.ring_high_water = 300;
  L.machining_s = 41.2;
  L.total_s = 96.0;
  L.program_line = 118;
  if (alarm) {
    gfx::set_alarm(L.alarms[0], gfx::AlarmSeverity::Error, "holder collides with the stock at X12.0 Y9.0 Z-3.0");
    gfx::set_alarm(L.alarms[1], gfx::AlarmSeverity::Warning, "rapid into material (line 117)");
    L.alarm_count = 2;
  }
  return L;
}

void publish(gfx::SolidExchange& ex, geom::LbrSolid& s, const gfx::LiveStats& L) {
  const gfx::ToolState tool{0, 3, {{20, 15, -3}, {0, 0, 1}}, 3, 20, 40, 10, 20};
  ASSERT_TRUE(wait_for([&] { return ex.publish(s, std::span(&tool, 1), 50, L); }));
}

TEST_F(GfxUi, AnErrorAlarmTurnsTheStatusBarRed) {
  geom::LbrSolid s = pocketed();
  UiWindow w(s, gfx::StandardView::Iso);
  publish(w.exchange(), s, live_stats(false));
  (void)w.item("Top");
  const gfx::Image calm = w.frame();
  const std::uint8_t* c = calm.px(kW - 4, kH - 4);  // the status bar's corner: its background
  EXPECT_LT(c[0], 80);
  publish(w.exchange(), s, live_stats(true));
  gfx::Image red;
  ASSERT_TRUE(wait_for([&] {
    red = w.frame();
    return red.px(kW - 4, kH - 4)[0] > 110;
  }));
  const std::uint8_t* r = red.px(kW - 4, kH - 4);
  EXPECT_GT(r[0], 110);
  EXPECT_LT(r[1], 40);
  EXPECT_LT(r[2], 40);
  EXPECT_EQ(red.px(kW / 3, kH / 3)[0], calm.px(kW / 3, kH / 3)[0]);  // the 3D view is unchanged
}

TEST_F(GfxUi, KioskQuitNeedsTheConfirmation) {
  UiWindow w(pocketed(), gfx::StandardView::Iso, nullptr, kW, kH, true);
  (void)w.item("Quit...");
  w.rt().ask_quit();  // Esc / Q / the window manager's close in kiosk mode
  w.tap("Cancel");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(w.rt().quit_confirmed());
  EXPECT_FALSE(w.rt().ui_hit(300, 300));  // the dialog is gone: the 3D view takes presses again
  w.tap("Quit...");
  w.tap("Quit");
  EXPECT_TRUE(wait_for([&] { return w.rt().quit_confirmed(); }));
}

// Not a check: with LBR_UI_SCREENSHOTS=DIR set, writes the pictures in docs/ui.md at the two
// panel sizes (1024x768, 1280x800).
// Taps at the window points where known points of the part project (top view): the panel
// gets their coordinates (the pocket floor at z = -3, the top face at z = 0), the material
// below them (7 and 10 mm) and their distance; a tap beside the part picks nothing.
TEST_F(GfxUi, MeasureTapsReportThePointTheStockBelowAndTheDistance) {
  UiWindow w(pocketed(), gfx::StandardView::Top);
  w.tap("Measure");
  ASSERT_TRUE(wait_for([&] { return w.rt().measuring(); }));
  (void)w.item("Clear");  // the panel is up
  const gfx::Camera cam = w.state().first;
  auto tap_at = [&](glm::dvec3 p) {
    const glm::dvec2 q = cam.project(p, kW, kH);
    ASSERT_FALSE(w.rt().ui_hit(q.x, q.y)) << p.x << "," << p.y << " lies under the UI";
    w.tap(q.x, q.y);
  };
  constexpr double kDeltaMm = 0.01;  // the tap lands where the point projects; the pick inverts it
  tap_at({20, 15, 0});
  ASSERT_TRUE(wait_for([&] { return w.rt().measured().size() == 1; }));
  gfx::MeasurePoint a = w.rt().measured()[0];
  EXPECT_NEAR(a.x_mm, 20, kDeltaMm);
  EXPECT_NEAR(a.y_mm, 15, kDeltaMm);
  EXPECT_NEAR(a.z_mm, kFloorZ, 1e-9);
  EXPECT_TRUE(a.top_face);
  EXPECT_NEAR(a.thickness_mm, 10 + kFloorZ, 1e-9);
  EXPECT_NEAR(a.surface_z_mm, kFloorZ, 1e-9);
  tap_at({25, 27, 0});
  ASSERT_TRUE(wait_for([&] { return w.rt().measured().size() == 2; }));
  const gfx::MeasurePoint b = w.rt().measured()[1];
  EXPECT_NEAR(b.x_mm, 25, kDeltaMm);
  EXPECT_NEAR(b.y_mm, 27, kDeltaMm);
  EXPECT_NEAR(b.z_mm, 0, 1e-9);
  EXPECT_NEAR(b.thickness_mm, 10, 1e-9);
  const double d = std::sqrt((b.x_mm - a.x_mm) * (b.x_mm - a.x_mm) + (b.y_mm - a.y_mm) * (b.y_mm - a.y_mm) +
                             (b.z_mm - a.z_mm) * (b.z_mm - a.z_mm));
  EXPECT_NEAR(d, std::sqrt(5.0 * 5.0 + 12.0 * 12.0 + 3.0 * 3.0), 2 * kDeltaMm);
  // Beside the part: a miss, the points stay.
  tap_at({-1, 15, 0});
  ASSERT_TRUE(wait_for([&] { return w.rt().measure_misses() == 1; }));
  EXPECT_EQ(w.rt().measured().size(), 2U);
  // A drag in Measure mode still orbits and picks nothing.
  const double yaw = w.state().first.yaw;
  w.drag(500, 300, 600, 300);
  EXPECT_NE(w.state().first.yaw, yaw);
  EXPECT_EQ(w.rt().measured().size(), 2U);
  EXPECT_EQ(w.rt().measure_misses(), 1U);
  // The switch turns the mode off again.
  w.tap("Measure");
  ASSERT_TRUE(wait_for([&] { return !w.rt().measuring(); }));
}

// `lbrsim run --source emulator:cam-pocket.ngc` as main.cpp runs it (the live pipeline on
// its own thread, the window on this one), photographed half way.
void run_screenshot(const std::string& png) {
  const std::string cfg = std::string(LBR_SOURCE_DIR) + "/config/";
  const app::Profile p = app::load_profile(cfg + "profiles/default-mill3.toml");
  const std::string program = cfg + "programs/cam-pocket.ngc";
  gfx::SolidExchange ex(1 << 14);
  std::promise<geom::LbrSolid> initial;
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "emulator:" + program;
  o.speed = 25;  // 165 s of machining: a third to half way when the picture is taken
  o.exchange = &ex;
  o.on_start = [&](const geom::LbrSolid& s) { initial.set_value(s); };
  std::thread live([&] { (void)app::run_live(p, o, stop); });
  {
    UiWindow w(initial.get_future().get(), gfx::StandardView::Iso, nullptr, kW, kH, false, app::program_text(program),
               "emulator:config/programs/cam-pocket.ngc", &ex);
    std::this_thread::sleep_for(std::chrono::milliseconds(2000));
    gfx::write_png(png, w.frame());
    stop.store(true);
  }
  live.join();
}

// With a section on, the line of sight starts on the drawn side of the plane: a tap on the
// cut face (iso view, X section at 20 mm) measures the cut face, not the part beyond it.
TEST_F(GfxUi, MeasureOnASectionPicksTheCutFace) {
  UiWindow w(pocketed(), gfx::StandardView::Iso);
  w.tap("X");
  ASSERT_TRUE(wait_for([&] { return w.state().second.section_axis == 0; }));
  w.tap("Measure");
  ASSERT_TRUE(wait_for([&] { return w.rt().measuring(); }));
  (void)w.item("Clear");
  const gfx::Camera cam = w.state().first;
  const glm::dvec2 q = cam.project({20, 2, -5}, kW, kH);
  ASSERT_FALSE(w.rt().ui_hit(q.x, q.y));
  w.tap(q.x, q.y);
  ASSERT_TRUE(wait_for([&] { return w.rt().measured().size() == 1; }));
  const gfx::MeasurePoint p = w.rt().measured()[0];
  EXPECT_NEAR(p.x_mm, 20, 1e-6);  // on the plane
  EXPECT_NEAR(p.y_mm, 2, 0.01);
  EXPECT_NEAR(p.z_mm, -5, 0.01);
  EXPECT_FALSE(p.top_face);
  EXPECT_NEAR(p.thickness_mm, p.z_mm + 10, 1e-9);
  EXPECT_NEAR(p.surface_z_mm, 0, 1e-9);
}

TEST_F(GfxUi, Screenshots) {
  const char* dir = std::getenv("LBR_UI_SCREENSHOTS");
  if (dir == nullptr) GTEST_SKIP() << "set LBR_UI_SCREENSHOTS=DIR to write the docs' screenshots";
  geom::LbrSolid s = pocketed();
  gfx::ReplayControl ctl;
  for (auto [wpx, hpx] : {std::pair{1024, 768}, std::pair{1280, 800}}) {
    UiWindow w(s, gfx::StandardView::Iso, &ctl, wpx, hpx);
    publish(w.exchange(), s, live_stats(true));
    w.tap("Heat");
    w.tap("X");
    (void)w.item("##section");
    w.tap("Stock");
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    gfx::write_png(std::string(dir) + "/ui-" + std::to_string(wpx) + "x" + std::to_string(hpx) + ".png", w.frame());
  }
  {  // The Measure panel: two points on the iso view (pocket floor, top face).
    UiWindow w(s, gfx::StandardView::Iso);
    w.tap("Measure");
    (void)w.item("Clear");
    const gfx::Camera cam = w.state().first;
    for (glm::dvec3 p : {glm::dvec3{20, 15, kFloorZ}, glm::dvec3{25, 27, 0}}) {
      const glm::dvec2 q = cam.project(p, kW, kH);
      w.tap(q.x, q.y);
    }
    (void)wait_for([&] { return w.rt().measured().size() == 2; });
    gfx::write_png(std::string(dir) + "/ui-measure.png", w.frame());
  }  // one UI at a time: ImGui's current context is process-wide
  run_screenshot(std::string(dir) + "/ui-run.png");
}

}  // namespace
}  // namespace lbr
