// lbrsim — command-line entry point. Subcommands: batch, view, run, emulate, profile.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <future>
#include <mutex>
#include <optional>
#include <thread>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "app/batch.hpp"
#include "app/install_paths.hpp"
#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "app/snapshot.hpp"
#include "app/watchdog.hpp"
#include "app/tune.hpp"
#include "app/view.hpp"
#include "gfx/viewer.hpp"
#include "gfx/window.hpp"
#include "nc/emulator.hpp"
#include "nc/gcode.hpp"

namespace {

using namespace lbr;

struct BatchOptions {
  std::string program, profile, stock, regions, out = "lbrsim-out", interpreter = "builtin";
  std::string dialect;  // --dialect: overrides the profile's [nc] dialect
  std::string stl, ply;  // mesh exports (empty: none)
  std::vector<std::string> tools;
  double level_spacing = 0.0;
  int threads = -1;
  int start_tool = -1;  // --start-tool (-1: the profile's [nc] start_tool)
  bool quiet = false;
  bool sampled = false;
  // rendering (gfx/)
  std::string png, view = "iso", color = "plain", size = "1024x768";
  bool view_window = false;
  bool show_tool = false;  // batch --png: a finished-part picture has no tool unless asked for
  bool no_tool = false;    // view: hide the tool
  std::string fail_on = "never";  // exit 3 when the checks raise events of this severity or worse
  bool no_checks = false;
  std::string design;              // --design: STL of the part to compare the final stock with
  double design_tolerance = 0.02;  // --tolerance [mm]
};

struct ViewCliOptions {
  bool animate = false, hidden = false, ortho = false, no_vsync = false, no_ui = false, kiosk = false;
  double speed = 1.0, rate_hz = 30.0;
  int screenshot_every = 0;
  std::string screenshot_prefix = "lbrsim-frame-";  // view has no --out; .gitignore lists these
  std::size_t frames = 0;
};


struct EmulateOptions {
  std::string program, profile, period, out = "samples.csv", interpreter = "builtin";
  std::string dialect;
  int start_tool = -1;  // --start-tool (-1: the profile's [nc] start_tool)
};

// --start-tool N: the tool in the spindle at program start (overrides [nc] start_tool).
void add_start_tool_option(CLI::App* c, int& start_tool) {
  c->add_option("--start-tool", start_tool,
                "Tool in the spindle at program start (0 = empty; default: the profile's [nc] start_tool)")
      ->check(CLI::Range(0, 99999));
}

// --dialect NAME (rs274ngc, fanuc): the built-in interpreter's program syntax for this run.
void add_dialect_option(CLI::App* c, std::string& dialect) {
  c->add_option("--dialect", dialect, "G-code dialect of the built-in interpreter: rs274ngc or fanuc "
                "(default: the profile's [nc] dialect)")
      ->check(CLI::IsMember({"rs274ngc", "fanuc"}));
}
void apply_dialect(app::Profile& p, const std::string& dialect) {
  if (!dialect.empty()) (void)nc::parse_dialect(dialect, p.nc.dialect);
}

// DIR/NAME as the user would type it ("out/" + metrics.json -> out/metrics.json, not out//).
std::string out_file(const std::string& dir, const std::string& name) {
  return (std::filesystem::path(dir) / name).string();
}

app::Interpreter interpreter_of(const std::string& s) {
  return s == "rs274" ? app::Interpreter::Rs274 : app::Interpreter::Builtin;
}

// "4ms", "4", "500us", "0.004s" -> milliseconds.
double parse_period_ms(const std::string& s) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = used > 0 ? s.substr(used) : "";
  double ms = v;
  if (unit == "us") ms = v * 1e-3;
  else if (unit == "s") ms = v * 1e3;
  else if (!(unit.empty() || unit == "ms")) used = 0;
  if (used == 0 || !std::isfinite(ms) || ms < 0.1 || ms > 1000.0)
    throw std::runtime_error("--period " + s + ": expected a period between 0.1 ms and 1000 ms, e.g. 4ms, 500us");
  return ms;
}

int run_emulate_command(const EmulateOptions& o) {
  app::Profile profile = o.profile.empty() ? app::default_profile() : app::load_profile(o.profile);
  if (!o.period.empty()) profile.machine.sample_period_ms = parse_period_ms(o.period);
  apply_dialect(profile, o.dialect);
  if (o.start_tool >= 0) profile.nc.start_tool = o.start_tool;
  const nc::Toolpath path = app::load_toolpath(o.program, profile, interpreter_of(o.interpreter));
  nc::Emulator em(path, app::emulator_limits(profile));
  const std::uint64_t n = app::write_samples_csv(o.out, em);
  std::printf("%llu samples every %.4g ms | machining %.3f s | %zu segments | wrote %s\n",
              static_cast<unsigned long long>(n), profile.machine.sample_period_ms, em.total_time_s(), path.segments.size(),
              o.out.c_str());
  return 0;
}

// `--png`: checks the rendering options and the display before the (possibly long) run.
gfx::CaptureOptions capture_options(const BatchOptions& o) {
  gfx::CaptureOptions cap;
  if (o.png.empty()) return cap;
  cap.view = gfx::parse_view(o.view);
  cap.ortho = cap.view == gfx::StandardView::Top;
  cap.color = gfx::parse_color_mode(o.color);
  gfx::parse_size(o.size, cap.width, cap.height);
  if (!gfx::display_available())
    throw gfx::DisplayError("--png needs an X or Wayland display for its hidden OpenGL window, and neither "
                            "DISPLAY nor WAYLAND_DISPLAY is set. Run it under a virtual X server: "
                            "`xvfb-run -a lbrsim batch ... --png " + o.png + "`");
  return cap;
}

// --color deviation shows the deviation from --design: without one it is an error.
void require_design_for_deviation(const std::string& color, const std::string& design) {
  if (color == "deviation" && design.empty())
    throw std::runtime_error("--color deviation needs --design FILE.stl: the design model whose deviation it shows");
}

// --color deviation: colours from the design the run compared with (docs/verification.md#deviation-colour).
bool deviation_colours(const BatchOptions& o) { return o.color == "deviation"; }

void write_png_if_asked(const app::BatchResult& r, const BatchOptions& o, const gfx::CaptureOptions& cap,
                        const std::vector<gfx::ToolState>& tools) {
  if (o.png.empty()) return;
  gfx::CaptureOptions c = cap;
  if (deviation_colours(o)) {
    c.deviation = app::deviation_fn(r.design_sections, r.solid, o.design_tolerance);
    c.deviation_scale_mm = gfx::kDeviationScalePerTolerance * o.design_tolerance;
  }
  // A picture of the finished part: the tool would hide part of it (issue 19), so it is
  // drawn only with --show-tool.
  gfx::capture_png(r.solid, o.png, c, o.show_tool && !o.no_tool ? tools : std::vector<gfx::ToolState>{});
  std::printf("wrote %s (%dx%d, view %s, colour %s)\n", o.png.c_str(), cap.width, cap.height, o.view.c_str(),
              o.color.c_str());
}

// Exit status of `batch --fail-on`: events at or above the chosen severity (docs/verification.md).
constexpr int kExitEvents = 3;
// Events printed one per line; the rest are in events.csv.
constexpr std::size_t kEventsShown = 20;

// --design: one line with the comparison's figures.
void print_design(const verify::DesignReport& d, double tolerance_mm, const std::string& out) {
  std::printf("design: %s (%s)\n", app::design_summary(d, tolerance_mm).c_str(), out_file(out, "deviation.csv").c_str());
}

// The checks' summary line and the first events; returns kExitEvents when --fail-on says so.
int report_events(const app::BatchResult& r, const BatchOptions& o) {
  const verify::EventCounts c = verify::count(r.events);
  std::printf("checks: %zu error%s, %zu warning%s (%s)\n", c.errors, c.errors == 1 ? "" : "s", c.warnings,
              c.warnings == 1 ? "" : "s", out_file(o.out, "events.csv").c_str());
  for (std::size_t k = 0; k < std::min(kEventsShown, r.events.size()); ++k) {
    const verify::Event& e = r.events[k];
    if (e.severity() == verify::Severity::Error) spdlog::error("{}", verify::describe(e));
    else spdlog::warn("{}", verify::describe(e));
  }
  if (r.events.size() > kEventsShown) spdlog::warn("{} more events in {}", r.events.size() - kEventsShown, out_file(o.out, "events.csv"));
  if (r.design) print_design(*r.design, o.design_tolerance, o.out);
  const bool fail = (o.fail_on == "error" && c.errors > 0) || (o.fail_on == "warning" && c.errors + c.warnings > 0);
  return fail ? kExitEvents : 0;
}

void print_result(const app::BatchResult& r, const BatchOptions& o) {
  std::printf("removed %.3f mm3 of %.3f mm3 | machining %.2f s | simulated in %.3f s (factor %.5f) | "
              "%d levels x %d regions (%dx%d), %zu vertices\n",
              r.removed_volume_mm3, r.stock_volume_mm3, r.machining_time_s, r.wall_time_s,
              r.machining_time_s > 0 ? r.wall_time_s / r.machining_time_s : 0.0, r.solid.levels(), r.solid.regions(),
              r.solid.regions_x(), r.solid.regions_y(), r.solid.vertex_count());
  std::printf("wrote %s, %s and %s\n", out_file(o.out, "metrics.json").c_str(), out_file(o.out, "levels.lbrs").c_str(),
              out_file(o.out, "events.csv").c_str());
  app::DeviationColours colours;
  if (deviation_colours(o)) colours = {&r.design_sections, o.design_tolerance};
  app::write_mesh_files(r.solid, o.stl, o.ply, colours);
  if (!o.stl.empty()) std::printf("wrote %s\n", o.stl.c_str());
  if (!o.ply.empty()) std::printf("wrote %s\n", o.ply.c_str());
}

// A profile with [[channel]] tables: every channel runs its own program; the sweeps are
// merged by time (docs/machine-kinds.md#several-channels).
int run_channels_command(const BatchOptions& o, const app::Profile& profile, const gfx::CaptureOptions& cap) {
  if (!o.program.empty())
    throw std::runtime_error("--program: profile " + profile.source +
                             " defines [[channel]] tables; their programs come from channel.program");
  const std::vector<app::ChannelPath> channels = app::load_channel_paths(profile, interpreter_of(o.interpreter));
  std::string names;
  for (const app::ChannelPath& c : channels) {
    spdlog::info("channel {}: program {} ({} segments)", c.name, c.path.source, c.path.segments.size());
    names += (names.empty() ? "" : "+") + c.name;
  }
  app::Progress progress;
  if (!o.quiet) progress = [](double f) { spdlog::info("progress {:5.1f} %", 100.0 * f); };
  const app::BatchResult r = app::run_batch_channels(profile, channels, o.sampled, progress);
  app::write_batch_outputs(o.out, r, profile, names);
  std::printf("%zu channels (%s)%s\n", channels.size(), names.c_str(), o.sampled ? ", sampled" : "");
  print_result(r, o);
  const int status = report_events(r, o);
  write_png_if_asked(r, o, cap, {});
  return status;
}

app::Profile batch_profile(const BatchOptions& o) {
  app::Profile profile = o.profile.empty() ? app::default_profile() : app::load_profile(o.profile);
  if (!o.stock.empty()) app::apply_stock_override(profile, o.stock);
  for (const std::string& t : o.tools) app::apply_tool_override(profile, t);
  if (o.level_spacing > 0.0) profile.solid.level_spacing_mm = o.level_spacing;
  if (!o.regions.empty()) app::apply_regions(profile, o.regions, "--regions");
  if (o.threads >= 0) profile.threads = o.threads;
  apply_dialect(profile, o.dialect);
  if (o.start_tool >= 0) profile.nc.start_tool = o.start_tool;
  if (o.no_checks) profile.checks.enabled = false;
  profile.design = {o.design, o.design_tolerance};
  return profile;
}

gfx::RenderThreadConfig render_config(const BatchOptions& o, const ViewCliOptions& v) {
  gfx::RenderThreadConfig rc;
  rc.rate_hz = v.rate_hz;
  rc.vsync = !v.no_vsync;
  rc.view = gfx::parse_view(o.view);
  rc.ortho = v.ortho || rc.view == gfx::StandardView::Top;
  rc.render.color = gfx::parse_color_mode(o.color);
  gfx::parse_size(o.size, rc.width, rc.height);
  rc.screenshot_every = v.screenshot_every;
  rc.screenshot_prefix = v.screenshot_prefix;
  rc.render.show_tools = !o.no_tool;
  rc.ui.enabled = !v.no_ui && !v.hidden;
  rc.ui.kiosk = v.kiosk;
  return rc;
}

int run_view_command(const BatchOptions& o, const ViewCliOptions& v) {
  require_design_for_deviation(o.color, o.design);
  if (!gfx::display_available())
    throw gfx::DisplayError("lbrsim view needs a display (DISPLAY / WAYLAND_DISPLAY are not set); "
                            "headless: `xvfb-run -a lbrsim view --hidden ...`");
  const app::Profile profile = batch_profile(o);
  std::vector<app::ChannelPath> channels;
  if (!profile.channels.empty()) {
    if (!o.program.empty())
      throw std::runtime_error("--program: profile " + profile.source +
                               " defines [[channel]] tables; their programs come from channel.program");
    channels = app::load_channel_paths(profile, interpreter_of(o.interpreter));
  } else {
    channels.push_back({"", o.program.empty() ? app::demo_toolpath()
                                              : app::load_toolpath(o.program, profile, interpreter_of(o.interpreter)),
                        profile.kin});
  }
  app::ViewOptions vo;
  vo.render = render_config(o, v);
  vo.animate = v.animate;
  vo.stream.speed = v.speed;
  vo.hidden = v.hidden;
  vo.frames = v.frames;
  vo.quiet = o.quiet;
  vo.kiosk = v.kiosk;
  vo.render.ui.scale = profile.render.ui.scale;
  return app::run_view(profile, channels, vo);
}

int run_batch_command(const BatchOptions& o) {
  if (o.quiet) spdlog::set_level(spdlog::level::warn);  // --quiet: the result lines and warnings only
  require_design_for_deviation(o.color, o.design);
  const app::Profile profile = batch_profile(o);
  const gfx::CaptureOptions cap = capture_options(o);
  if (!profile.channels.empty()) return run_channels_command(o, profile, cap);
  nc::Toolpath path =
      o.program.empty() ? app::demo_toolpath() : app::load_toolpath(o.program, profile, interpreter_of(o.interpreter));
  const std::string program = o.program.empty() ? path.source : o.program;
  spdlog::info("program {} ({} segments), profile {}", program, path.segments.size(), profile.source);
  for (const std::string& w : app::toolpath_warnings(path)) spdlog::warn("{}", w);
  // G-code programs and sampled runs take the emulator's time (acceleration, axis limits).
  const bool emulated = o.sampled || (!o.program.empty() && app::is_gcode_path(o.program));
  double emulated_time_s = 0.0;
  if (emulated) {
    const nc::EmulatorLimits limits = app::emulator_limits(profile);
    emulated_time_s = nc::emulated_time_s(path, limits);
    if (o.sampled) {
      path = nc::sampled_toolpath(path, limits);
      spdlog::info("sampled every {} ms: {} segments", profile.machine.sample_period_ms, path.segments.size());
    }
  }

  app::Progress progress;
  if (!o.quiet) {
    progress = [](double f) { spdlog::info("progress {:5.1f} %", 100.0 * f); };
  }
  app::BatchResult r = app::run_batch(profile, path, progress, o.sampled);
  if (emulated) r.machining_time_s = emulated_time_s;
  app::write_batch_outputs(o.out, r, profile, program);
  print_result(r, o);
  const int status = report_events(r, o);
  write_png_if_asked(r, o, cap, app::final_tools(profile, path));
  if (o.view_window) return run_view_command(o, ViewCliOptions{});
  return status;
}

struct RunOptions {
  std::string profile, out = "lbrsim-out", stl, ply;
  app::LiveOptions live;
  bool quiet = false;
  // rendering (gfx/): a viewer window when a display exists, screenshots on request
  bool no_window = false, hidden = false, no_tool = false, no_ui = false, kiosk = false;
  int screenshot_every = 0;
  std::string screenshot_prefix;  // empty: OUT/frame-
  std::string view = "iso", color = "heat", size = "1280x800";
  double rate_hz = 0.0;  // 0: the profile's [render] rate_hz
  // power-loss resume (docs/snapshot.md)
  bool resume = false;
  std::string snapshot_dir;  // empty: the --out folder
  std::string design;              // --design: STL of the part to compare the final stock with
  double design_tolerance = 0.02;  // --tolerance [mm]
};

// The render thread of a rendered run, for the watchdog's probe (null when none runs).
std::mutex g_render_mu;
const gfx::RenderThread* g_render_thread = nullptr;
void set_render_thread(const gfx::RenderThread* rt) {
  const std::lock_guard<std::mutex> lock(g_render_mu);
  g_render_thread = rt;
}


std::atomic<bool> g_stop{false};
std::atomic<bool> g_signalled{false}, g_window_closed{false};
extern "C" void on_signal(int) {
  g_signalled.store(true);
  g_stop.store(true);
}

// Results of `lbrsim run` must survive the display (issue 19): the live thread writes them
// as soon as the run ends, before the window and GL context are torn down, and a lost X
// connection (xvfb-run ending on Ctrl-C, the session closing) stops the run and waits for
// them before the process leaves.
enum class Results : int { NotStarted, Running, Written, Failed };
std::atomic<Results> g_results{Results::NotStarted};
std::atomic<const char*> g_results_dir{""};

void on_display_lost() {
  g_stop.store(true);
  std::fprintf(stderr, "lbrsim: warning: display lost (the X server connection closed); stopping the run\n");
  for (int i = 0; i < 60000 && g_results.load() == Results::Running; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const Results r = g_results.load();
  if (r == Results::Written)
    std::fprintf(stderr, "lbrsim: results written to %s (metrics.json, levels.lbrs)\n", g_results_dir.load());
  else if (r != Results::NotStarted)
    std::fprintf(stderr, "lbrsim: error: results could not be written after the display was lost\n");
  std::fflush(stdout);
  std::_Exit(r == Results::Written ? 0 : 1);  // Xlib would exit(1) on return; no destructors with threads running
}

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

gfx::RenderThreadConfig live_render_config(const RunOptions& o, const app::Profile& profile) {
  gfx::RenderThreadConfig rc;
  rc.rate_hz = o.rate_hz > 0 ? o.rate_hz : profile.render.rate_hz;
  rc.view = gfx::parse_view(o.view);
  rc.ortho = rc.view == gfx::StandardView::Top;
  rc.render.color = gfx::parse_color_mode(o.color);
  gfx::parse_size(o.size, rc.width, rc.height);
  rc.screenshot_every = o.screenshot_every;
  rc.screenshot_prefix = o.screenshot_prefix.empty() ? out_file(o.out, "frame-") : o.screenshot_prefix;
  rc.render.show_tools = !o.no_tool;
  rc.ui.enabled = !o.no_ui && !o.hidden && !o.no_window;
  rc.ui.scale = profile.render.ui.scale;
  rc.ui.source = o.live.source;
  rc.ui.kiosk = o.kiosk;
  // The program panel: the emulator's program file (the one that runs), else --program.
  const bool emulator = o.live.source.rfind("emulator:", 0) == 0;
  const std::string emu = emulator ? o.live.source.substr(9) : "";
  if (emulator && emu != "demo") rc.ui.program = app::program_text(emu);
  else if (!emulator && !o.live.program.empty()) rc.ui.program = app::program_text(o.live.program);
  return rc;
}

// metrics.json, levels.lbrs and the mesh files of a finished (or stopped) live run; with
// --color deviation the PLY carries the deviation from the design sections.
void write_live_results(const RunOptions& o, const app::Profile& profile, const app::LiveResult& r,
                        const std::vector<geom::Paths>& design) {
  try {
    app::write_live_outputs(o.out, r, profile);
    app::DeviationColours colours;
    if (o.color == "deviation" && !design.empty()) colours = {&design, o.design_tolerance};
    app::write_mesh_files(r.solid, o.stl, o.ply, colours);
  } catch (...) {
    g_results.store(Results::Failed);
    throw;
  }
  g_results.store(Results::Written);
}

void log_render_report(const gfx::PacingReport& rep, double rate_hz) {
  if (!rep.error.empty()) spdlog::warn("render thread stopped: {}", rep.error);
  using P = gfx::PacingReport;
  const std::vector<double> rebuilt(rep.regions_rebuilt.begin(), rep.regions_rebuilt.end());
  double rebuilt_sum = 0;
  for (double v : rebuilt) rebuilt_sum += v;
  spdlog::info("render: {} frames ({} late) at {} Hz | period p50 {:.2f} p99 {:.2f} max {:.2f} ms | work p50 {:.2f} "
               "p99 {:.2f} ms | mesh p99 {:.2f} ms | regions rebuilt per frame mean {:.2f} max {:.0f} | {} "
               "screenshots | {}",
               rep.frames, rep.late_frames, rate_hz, P::percentile(rep.period_ms, 0.5), P::percentile(rep.period_ms, 0.99),
               P::percentile(rep.period_ms, 1.0), P::percentile(rep.work_ms, 0.5), P::percentile(rep.work_ms, 0.99),
               P::percentile(rep.mesh_ms, 0.99), rep.frames ? rebuilt_sum / static_cast<double>(rep.frames) : 0.0,
               P::percentile(rebuilt, 1.0), rep.screenshots, rep.gl);
}

// Warnings from the live run for the HUD: the live thread may warn before the render
// thread exists or after it is gone.
class HudNotice {
 public:
  void attach(gfx::RenderThread* rt) {
    std::lock_guard lock(mu_);
    rt_ = rt;
    push();
  }
  // The design comparison's line (--design), shown when the run has ended.
  void set_design(const std::string& text) {
    std::lock_guard lock(mu_);
    design_ = text;
    push();
  }
  void set(const std::string& text) {
    std::lock_guard lock(mu_);
    text_.clear();
    std::size_t col = 0;  // wrapped at about 100 characters: the HUD has no wrapping of its own
    for (char c : text) {
      if (c == ' ' && col > 100) {
        text_ += "\n  ";
        col = 2;
        continue;
      }
      text_ += c;
      ++col;
    }
    push();
  }

 private:
  void push() {
    if (rt_ == nullptr || (text_.empty() && design_.empty())) return;
    rt_->edit([&](gfx::Camera&, gfx::RenderOptions& ro) {
      ro.notice = text_;
      ro.design = design_;
    });
  }
  std::mutex mu_;
  gfx::RenderThread* rt_ = nullptr;
  std::string text_, design_;
};

// The live run on its own thread while the main thread owns the window's events and the
// render thread draws what the geometry thread publishes.
// `design`: filled by o.live.on_design before the initial solid arrives (--design).
app::LiveResult run_live_rendered(const RunOptions& o, const app::Profile& profile, const app::StatusFn& status,
                                  const std::vector<geom::Paths>& design) {
  gfx::RenderThreadConfig rc = live_render_config(o, profile);
  const bool visible = !o.hidden && !o.no_window;
  gfx::Window win(rc.width, rc.height, visible, "lbrsim run — " + o.live.source, o.kiosk);
  gfx::SolidExchange ex(1 << 14);
  std::promise<std::unique_ptr<geom::LbrSolid>> initial;
  auto initial_ready = initial.get_future();
  app::LiveOptions lo = o.live;
  HudNotice notice;
  lo.on_warning = [&notice, warn = o.live.on_warning](const std::string& w) {
    if (warn) warn(w);
    notice.set(w);
  };
  // --design: the figures on the HUD, at every snapshot and when the run ends.
  lo.on_design_report = [&notice, tol = o.design_tolerance](const verify::DesignReport& d, bool final) {
    notice.set_design(app::design_summary(d, tol) + (final ? " (final)" : " (at the last snapshot)"));
  };
  lo.exchange = &ex;
  lo.on_start = [&initial](const geom::LbrSolid& s) { initial.set_value(std::make_unique<geom::LbrSolid>(s)); };
  std::optional<app::LiveResult> result;
  std::exception_ptr live_error;
  std::atomic<bool> live_done{false};
  std::thread live([&] {
    try {
      result.emplace(app::run_live(profile, lo, g_stop, status));
      write_live_results(o, profile, *result, design);  // before anything that needs the display
    } catch (...) {
      Results running = Results::Running;
      g_results.compare_exchange_strong(running, Results::Failed);
      live_error = std::current_exception();
      try {
        initial.set_value(nullptr);
      } catch (...) {  // already set
      }
    }
    live_done.store(true);
  });
  std::unique_ptr<geom::LbrSolid> start = initial_ready.get();
  if (start) {
    // --color deviation: the colours from the design sections on the stock's levels (kept in `start`).
    if (rc.render.color == gfx::ColorMode::Deviation && !design.empty()) {
      rc.render.deviation = app::deviation_fn(design, *start, o.design_tolerance);
      rc.render.deviation_scale_mm = gfx::kDeviationScalePerTolerance * o.design_tolerance;
    }
    gfx::RenderThread rt(win, ex, *start, rc);
    if (!rc.render.deviation) start.reset();
    rt.start();
    set_render_thread(&rt);
    notice.attach(&rt);
    if (visible) {
      gfx::run_event_loop(win, rt, [&] { return !live_done.load(); }, o.kiosk);
      if (!live_done.load() && rt.running()) {  // the window was closed: end the run, keep its results
        g_window_closed.store(true);
        g_stop.store(true);
      }
    } else {
      while (!live_done.load() && rt.running()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    // Show the final state for one more frame period before closing.
    std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(2000.0 / rc.rate_hz)));
    notice.attach(nullptr);
    set_render_thread(nullptr);
    rt.stop();
    log_render_report(rt.report(), rc.rate_hz);
  }
  live.join();
  if (live_error) std::rethrow_exception(live_error);
  return std::move(*result);
}

void print_live_summary(const RunOptions& o, const app::LiveResult& r) {
  std::uint64_t errors = 0;
  for (const auto& [k, v] : r.decode_errors) errors += v;
  std::printf("%s | received %llu applied %llu lost %llu | ring overruns %llu high water %llu | decode errors %llu | "
              "lag p50 %.3f p99 %.3f max %.3f ms | removed %.3f mm3 | rt %s%s\n",
              r.source.c_str(), static_cast<unsigned long long>(r.samples_received),
              static_cast<unsigned long long>(r.samples_applied), static_cast<unsigned long long>(r.samples_lost),
              static_cast<unsigned long long>(r.ring_overruns), static_cast<unsigned long long>(r.ring_high_water),
              static_cast<unsigned long long>(errors), r.lag_p50_ms, r.lag_p99_ms, r.lag_max_ms, r.removed_volume_mm3,
              r.rt_mode.c_str(), g_signalled.load() ? " | stopped by signal" : (g_window_closed.load() ? " | stopped: window closed" : ""));
  std::printf("wrote %s and %s%s%s%s%s\n", out_file(o.out, "metrics.json").c_str(), out_file(o.out, "levels.lbrs").c_str(),
              o.stl.empty() ? "" : ", ", o.stl.c_str(), o.ply.empty() ? "" : ", ", o.ply.c_str());
  if (r.design) print_design(*r.design, o.design_tolerance, o.out);
}

// --resume: the newest valid snapshot in the snapshot folder (a corrupt one is reported and
// the other used); none: a new part.
std::optional<app::SnapshotState> resume_snapshot(const RunOptions& o) {
  if (!o.resume) return std::nullopt;
  app::LoadedSnapshot l = app::load_newest_snapshot(o.live.snapshot_dir);
  for (const std::string& p : l.problems) spdlog::warn("snapshot passed over: {}", p);
  if (!l.state) {
    spdlog::info("resume: no snapshot in {}; starting a new part", o.live.snapshot_dir);
    return std::nullopt;
  }
  if (l.state->source != o.live.source)
    throw std::runtime_error(l.file + ": snapshot of source '" + l.state->source + "', not '" + o.live.source +
                             "'; start without --resume for a new part");
  spdlog::info("resume: {} (generation {}, source sample {}, {} samples applied, {:.1f} s)", l.file, l.state->generation,
               l.state->source_position, l.state->samples_applied, l.state->wall_time_s);
  return std::move(l.state);
}

// The systemd watchdog (app/watchdog.hpp): probes on the HAL, geometry and render threads.
std::vector<app::ProgressProbe> live_probes(const app::LiveProgress& pr) {
  using C = std::optional<std::uint64_t>;
  std::vector<app::ProgressProbe> probes = app::live_progress_probes(pr);
  probes.push_back({"render thread", []() -> C {
                      const std::lock_guard<std::mutex> lock(g_render_mu);
                      return g_render_thread != nullptr && g_render_thread->running() ? C(g_render_thread->frames_done())
                                                                                      : std::nullopt;
                    }, false});
  return probes;
}

int run_live_command(RunOptions o) {
  o.live.on_warning = [](const std::string& w) { spdlog::warn("{}", w); };
  require_design_for_deviation(o.color, o.design);
  app::Profile profile = o.profile.empty() ? app::default_profile() : app::load_profile(o.profile);
  profile.design = {o.design, o.design_tolerance};
  install_stop_handlers();
  spdlog::info("run: source {}, profile {}, period {} ms", o.live.source, profile.source, profile.live.period_ms);
  o.live.snapshot_dir = o.snapshot_dir.empty() ? o.out : o.snapshot_dir;
  const std::optional<app::SnapshotState> resume = resume_snapshot(o);
  if (resume) o.live.resume = &*resume;
  app::SystemdNotifier notifier;
  app::LiveProgress progress;
  o.live.progress = &progress;
  app::ProgressWatchdog watchdog(notifier, live_probes(progress));
  std::optional<app::WatchdogThread> watchdog_thread;
  if (notifier.active()) {
    const std::int64_t wd_ms = static_cast<std::int64_t>(notifier.watchdog_us() / 3000);
    watchdog_thread.emplace(watchdog, wd_ms > 0 ? std::min<std::int64_t>(wd_ms, 1000) : 1000);
  }
  app::StatusFn status = [quiet = o.quiet, &notifier](const std::string& line) {
    if (!quiet) spdlog::info("{}", line);
    notifier.notify("STATUS=" + line);
  };
  // Rendering: a window (visible, or hidden for screenshots only) when a display exists.
  const bool want_render = o.screenshot_every > 0 || (!o.no_window && gfx::display_available());
  if (o.screenshot_every > 0 && !gfx::display_available())
    throw gfx::DisplayError("--screenshot-every needs an X or Wayland display for its hidden OpenGL window, and "
                            "neither DISPLAY nor WAYLAND_DISPLAY is set. Run it under a virtual X server: "
                            "`xvfb-run -a lbrsim run ...`");
  std::vector<geom::Paths> design;  // --design: the model's sections (deviation colours of the view and the PLY)
  o.live.on_design = [&design](const std::vector<geom::Paths>& d) { design = d; };
  g_results_dir.store(o.out.c_str());
  g_results.store(Results::Running);
  if (want_render) {
    gfx::set_display_lost_handler(on_display_lost);
    if (o.screenshot_prefix.empty()) std::filesystem::create_directories(o.out);  // screenshots go there
    const app::LiveResult r = run_live_rendered(o, profile, status, design);  // writes the results itself
    notifier.notify("STOPPING=1");
    print_live_summary(o, r);
    return 0;
  }
  const app::LiveResult r = app::run_live(profile, o.live, g_stop, status);
  notifier.notify("STOPPING=1");
  write_live_results(o, profile, r, design);
  print_live_summary(o, r);
  return 0;
}

void add_render_options(CLI::App* c, BatchOptions& o) {
  c->add_option("--view", o.view, "Camera: top, front, side or iso")
      ->check(CLI::IsMember({"top", "front", "side", "iso"}))
      ->capture_default_str();
  c->add_option("--color", o.color,
                "Colour mode: plain, heat (move of the last cut), regions (grid) or deviation (from --design: "
                "gouge red, excess blue)")
      ->check(CLI::IsMember({"plain", "heat", "regions", "deviation"}))
      ->capture_default_str();
  c->add_option("--size", o.size, "Image / window size WxH [px]")->capture_default_str();
}

// --design FILE.stl / --tolerance MM (batch, view, run): the design-model comparison.
void add_design_options(CLI::App* c, std::string& design, double& tolerance_mm, const char* what) {
  c->add_option("--design", design, std::string("Compare ") + what +
                                        " with this design model (STL, mm, work coordinates; docs/verification.md)")
      ->check(CLI::ExistingFile);
  c->add_option("--tolerance", tolerance_mm, "--design: stock closer than this outside the design is not excess [mm]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

CLI::App* add_batch_command(CLI::App& cli, BatchOptions& b) {
  CLI::App* batch = cli.add_subcommand("batch", "Run a part program through the simulator as fast as possible");
  batch->add_option("--program", b.program,
                    "Part program: a move list (.moves) or G-code (.ngc, .nc, .gcode, .tap); without it the "
                    "bundled demo program runs");
  batch->add_option("--interpreter", b.interpreter,
                    "G-code front end: builtin, or rs274 (LinuxCNC's interpreter, package linuxcnc-uspace)")
      ->check(CLI::IsMember({"builtin", "rs274"}))
      ->capture_default_str();
  add_dialect_option(batch, b.dialect);
  add_start_tool_option(batch, b.start_tool);
  batch->add_flag("--sampled", b.sampled,
                  "Run the kernel on the machine emulator's sampled stream (as live mode sees it) instead of the "
                  "interpreted segments; the checks tell rapids by sample speed, as live mode does");
  batch->add_option("--profile", b.profile, "Machine profile (TOML); default: the built-in 3-axis mill profile");
  batch->add_option("--stock", b.stock,
                    "Override the stock: box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX or cylinder:DIAMETER,ZMIN,ZMAX [mm]");
  batch->add_option("--tool", b.tools,
                    "Add or override tool N: N:KIND:DIAMETER[:PARAM], KIND = flat|ball|bull|drill|vbit; "
                    "PARAM = corner radius [mm] (bull), point angle [deg] (drill), included angle [deg] (vbit)")
      ->take_all();
  batch->add_option("--level-spacing", b.level_spacing, "Level spacing Δ [mm]")->check(CLI::Range(0.001, 1000.0));
  batch->add_option("--regions", b.regions, "Region grid NXxNY (e.g. 4x4) or auto");
  batch->add_option("--threads", b.threads, "Kernel worker threads (0 = one per hardware thread; default: profile)")
      ->check(CLI::Range(0, 256));
  batch->add_option("--out", b.out, "Output directory (metrics.json, levels.lbrs)")->capture_default_str();
  batch->add_flag("--quiet", b.quiet, "No progress messages");
  batch->add_option("--stl", b.stl, "Also write the reconstructed part as binary STL to this file");
  batch->add_option("--ply", b.ply, "Also write the reconstructed part as binary PLY (with normals, move id) to this file");

  batch->add_option("--png", b.png, "Render the result offscreen to this PNG (needs a display; headless: xvfb-run -a)");
  add_render_options(batch, b);
  batch->add_flag("--show-tool", b.show_tool, "--png: draw the tool at its last position (default: the part alone)");
  batch->add_flag("--no-tool", b.no_tool, "--png: no tool in the picture (the default)")->excludes("--show-tool");
  batch->add_flag("--view-window", b.view_window, "Then open the interactive viewer on the program (runs it again)");
  batch->add_option("--fail-on", b.fail_on,
                    "Exit with status 3 when the collision checks raise an error (error) or any event (warning)")
      ->check(CLI::IsMember({"never", "error", "warning"}))
      ->capture_default_str();
  batch->add_flag("--no-checks", b.no_checks, "Skip the collision and process checks (profile [checks] enabled = false)");
  add_design_options(batch, b.design, b.design_tolerance, "the final stock");
  return batch;
}

CLI::App* add_view_command(CLI::App& cli, BatchOptions& vb, ViewCliOptions& vv) {
  CLI::App* view = cli.add_subcommand("view", "Interactive viewer: a batch result, or the program streamed in real time");
  view->add_option("--program", vb.program, "Part program (.moves or G-code); default: the bundled demo");
  view->add_option("--interpreter", vb.interpreter, "G-code front end: builtin or rs274")
      ->check(CLI::IsMember({"builtin", "rs274"}))
      ->capture_default_str();
  add_dialect_option(view, vb.dialect);
  view->add_option("--profile", vb.profile, "Machine profile (TOML)");
  add_start_tool_option(view, vb.start_tool);
  view->add_option("--stock", vb.stock, "Override the stock (as for batch)");
  view->add_option("--tool", vb.tools, "Add or override a tool (as for batch)")->take_all();
  view->add_option("--level-spacing", vb.level_spacing, "Level spacing Δ [mm]")->check(CLI::Range(0.001, 1000.0));
  view->add_option("--regions", vb.regions, "Region grid NXxNY or auto");
  view->add_flag("--quiet", vb.quiet, "Fewer messages");
  add_render_options(view, vb);
  view->add_flag("--no-tool", vb.no_tool, "Do not draw the tool (key K toggles it)");
  add_design_options(view, vb.design, vb.design_tolerance, "the final stock (with --animate: colours as it goes)");
  view->add_flag("--animate", vv.animate, "Stream the program through the kernel in real time (geometry thread)");
  view->add_option("--speed", vv.speed, "Simulated seconds per second when animating")->check(CLI::Range(0.01, 1000.0));
  view->add_option("--rate", vv.rate_hz, "Render rate [Hz]")->check(CLI::Range(1.0, 240.0))->capture_default_str();
  view->add_flag("--no-vsync", vv.no_vsync, "Do not sync buffer swaps to the display");
  view->add_flag("--ortho", vv.ortho, "Orthographic projection");
  view->add_flag("--hidden", vv.hidden, "No visible window (headless render thread; with --frames or --animate)");
  view->add_flag("--no-ui", vv.no_ui, "Hide the operator UI (status bar, view and replay controls); the text HUD instead");
  view->add_flag("--kiosk", vv.kiosk, "Full screen without decorations; quitting asks for a confirmation");
  view->add_option("--frames", vv.frames, "Stop after N frames");
  view->add_option("--screenshot-every", vv.screenshot_every, "Write a PNG every N frames")->check(CLI::Range(0, 1000000));
  view->add_option("--screenshot-prefix", vv.screenshot_prefix, "Screenshot file prefix (PREFIX000123.png)")
      ->capture_default_str();
  return view;
}

CLI::App* add_run_command(CLI::App& cli, RunOptions& ro) {
  CLI::App* run = cli.add_subcommand("run", "Simulate live from a machine (CAN, serial), a log replay or the emulator");
  ro.live.source = "emulator:demo";
  run->add_option("--source", ro.live.source,
                  "can:IFACE | serial:DEVICE | replay:LOGFILE | emulator:PROGRAM (PROGRAM 'demo' = bundled demo)")
      ->capture_default_str();
  run->add_option("--program", ro.live.program,
                  "The part program the machine runs (can, serial, replay sources): its current line is found from "
                  "the sampled positions and its emulated time gives the progress")
      ->check(CLI::ExistingFile);
  run->add_option("--stl", ro.stl, "Also write the final part as binary STL");
  run->add_option("--ply", ro.ply, "Also write the final part as binary PLY (with move ids)");
  run->add_option("--profile", ro.profile, "Machine profile (TOML); default: the built-in 3-axis mill profile");
  run->add_option("--speed", ro.live.speed, "Replay/emulator pacing: 1 = real time, 0 = as fast as possible")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  run->add_option("--out", ro.out, "Output directory (metrics.json, levels.lbrs)")->capture_default_str();
  run->add_option("--record", ro.live.record, "Record the raw input to this file (candump -l format)");
  run->add_option("--kernel-log", ro.live.kernel_log_capacity,
                  "Diagnostics: write OUT/kernel_calls.csv, one line per kernel call (up to N calls)");
  run->add_flag("--resume", ro.resume,
                "Go on from the newest valid power-loss snapshot in the snapshot folder (a new part when there is none)");
  run->add_option("--snapshot-dir", ro.snapshot_dir,
                  "Folder of the power-loss snapshots (profile [live] snapshot_s); default: the --out folder");
  run->add_flag("--quiet", ro.quiet, "No status lines");
  run->add_option("--status-every", ro.live.status_period_s, "Seconds between status lines (each gives the lag p99 since the last)")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  run->add_flag("--no-window", ro.no_window, "Do not open the viewer even when a display exists");
  run->add_flag("--hidden", ro.hidden, "Render without a visible window (with --screenshot-every)");
  run->add_flag("--no-ui", ro.no_ui, "Hide the operator UI (status bar, view controls); the text HUD instead");
  run->add_flag("--kiosk", ro.kiosk, "Full screen without decorations; quitting asks for a confirmation");
  run->add_option("--screenshot-every", ro.screenshot_every, "Write a PNG every N render frames, and one of the final state "
                  "when the run ends (needs a display; headless: xvfb-run -a)")->check(CLI::Range(0, 1000000));
  run->add_option("--screenshot-prefix", ro.screenshot_prefix,
                  "Screenshot file prefix (PREFIX000123.png); default: OUT/frame- in the --out directory");
  run->add_flag("--no-tool", ro.no_tool, "Do not draw the tool (key K toggles it)");
  run->add_option("--view", ro.view, "Camera: top, front, side or iso")
      ->check(CLI::IsMember({"top", "front", "side", "iso"}))
      ->capture_default_str();
  run->add_option("--color", ro.color, "Colour mode: plain, heat, regions or deviation (from --design: gouge red, "
                  "excess blue)")
      ->check(CLI::IsMember({"plain", "heat", "regions", "deviation"}))
      ->capture_default_str();
  run->add_option("--size", ro.size, "Window / screenshot size WxH [px]")->capture_default_str();
  add_design_options(run, ro.design, ro.design_tolerance, "the final stock (when the run ends)");
  run->add_option("--render-rate", ro.rate_hz, "Render rate [Hz] (default: the profile's [render] rate_hz, 30)")
      ->check(CLI::Range(1.0, 240.0));
  return run;
}

CLI::App* add_emulate_command(CLI::App& cli, EmulateOptions& em) {
  CLI::App* emu = cli.add_subcommand("emulate", "Run a part program through the machine emulator and write its samples");
  emu->add_option("program", em.program, "Part program (G-code or .moves)")->required();
  emu->add_option("--profile", em.profile, "Machine profile (TOML); default: the built-in 3-axis mill profile");
  emu->add_option("--period", em.period, "Sample period, e.g. 4ms, 500us (default: the profile's sample_period_ms)");
  emu->add_option("--out", em.out, "CSV file (columns: docs/nc-frontend.md#samples-csv)")->capture_default_str();
  emu->add_option("--interpreter", em.interpreter, "G-code front end: builtin or rs274")
      ->check(CLI::IsMember({"builtin", "rs274"}))
      ->capture_default_str();
  add_dialect_option(emu, em.dialect);
  add_start_tool_option(emu, em.start_tool);
  return emu;
}

struct TuneOptions {
  std::string program, profile, write;
  int repeats = 1;
};

CLI::App* add_tune_command(CLI::App& cli, TuneOptions& to) {
  CLI::App* tune = cli.add_subcommand(
      "tune", "Measure the kernel on a program's sampled stream for several region grids and pick the fastest");
  tune->add_option("--program", to.program, "Part program (.ngc, .nc, .gcode, .tap or .moves)")->required();
  tune->add_option("--profile", to.profile, "Machine profile (TOML); default: the built-in 3-axis mill profile");
  tune->add_option("--write", to.write, "Write the profile with the fastest grid as lbr.regions to this file");
  tune->add_option("--repeats", to.repeats, "Runs per grid (the best counts)")->check(CLI::Range(1, 20))->capture_default_str();
  return tune;
}

int run_tune_command(const TuneOptions& o) {
  const app::Profile profile = o.profile.empty() ? app::default_profile() : app::load_profile(o.profile);
  const nc::Toolpath path = app::load_toolpath(o.program, profile);
  const nc::Toolpath sampled = nc::sampled_toolpath(path, app::emulator_limits(profile));
  const double machining = nc::emulated_time_s(path, app::emulator_limits(profile));
  double dmax = 1.0;
  for (const auto& [n, t] : profile.tooling.tools) dmax = std::max(dmax, t.diameter_mm);
  const auto grids = app::tune_candidates(profile, dmax);
  std::printf("tune: %s, %zu samples, %zu grids, one kernel thread\n", o.program.c_str(), sampled.segments.size(),
              grids.size());
  const auto t = app::tune_regions(profile, sampled, grids, o.repeats, [&](const app::GridTiming& g) {
    std::printf("  %2dx%-2d  %8.3f s  factor %.5f\n", g.nx, g.ny, g.wall_s, machining > 0 ? g.wall_s / machining : 0.0);
    std::fflush(stdout);
  });
  std::printf("fastest: regions = \"%dx%d\" (%.3f s)\n", t.front().nx, t.front().ny, t.front().wall_s);
  if (!o.write.empty()) {
    const std::string base = o.profile.empty() ? std::string(app::default_profile_text())
                                                : nc::read_text_file(o.profile);
    app::write_file(o.write, app::set_regions_in_profile_text(base, t.front().nx, t.front().ny));
    std::printf("wrote %s\n", o.write.c_str());
  }
  return 0;
}

struct ProfileOptions {
  std::string check_path;
  bool print_default = false;
  bool can_bitrate = false;
};

CLI::App* add_profile_command(CLI::App& cli, ProfileOptions& po) {
  CLI::App* prof = cli.add_subcommand("profile", "Check a profile, or print the built-in default profile");
  prof->add_option("file", po.check_path, "Profile to check");
  prof->add_flag("--print-default", po.print_default, "Print the built-in default profile");
  prof->add_flag("--can-bitrate", po.can_bitrate, "Print the profile's [live.can] bitrate [bit/s] only (lbrsim-can@.service)");
  return prof;
}

int run_profile_command(const ProfileOptions& o) {
  if (o.print_default) {
    std::cout << app::default_profile_text();
    return 0;
  }
  if (o.check_path.empty()) {
    std::cerr << "lbrsim profile: give a file to check, or --print-default\n";
    return 2;
  }
  const app::Profile p = app::load_profile(o.check_path);
  if (o.can_bitrate) {
    std::printf("%d\n", p.live.can.bitrate);
    return 0;
  }
  std::printf("%s: ok (machine %s, %zu tools, level spacing %.4g mm)\n", o.check_path.c_str(), nc::to_string(p.kin.kind),
              p.tooling.tools.size(), p.solid.level_spacing_mm);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{std::string("lbrsim ") + app::version() +
               " — NC machining simulator on a level-based representation (LBR)"};
  cli.set_version_flag("--version", std::string("lbrsim ") + app::version());
  cli.require_subcommand(1);
  std::string log_level = "info";
  cli.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  BatchOptions b, vb;
  ViewCliOptions vv;
  RunOptions ro;
  EmulateOptions em;
  TuneOptions to;
  ProfileOptions po;
  CLI::App* batch = add_batch_command(cli, b);
  CLI::App* view = add_view_command(cli, vb, vv);
  CLI::App* run = add_run_command(cli, ro);
  CLI::App* emu = add_emulate_command(cli, em);
  CLI::App* tune = add_tune_command(cli, to);
  CLI::App* prof = add_profile_command(cli, po);
  CLI11_PARSE(cli, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  try {
    if (batch->parsed()) return run_batch_command(b);
    if (view->parsed()) return run_view_command(vb, vv);
    if (run->parsed()) return run_live_command(ro);
    if (emu->parsed()) return run_emulate_command(em);
    if (tune->parsed()) return run_tune_command(to);
    if (prof->parsed()) return run_profile_command(po);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lbrsim: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
