#include "app/view.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "app/outputs.hpp"
#include "gfx/viewer.hpp"
#include "gfx/window.hpp"

namespace lbr::app {

namespace {

bool is_motion(const nc::Segment& s) { return s.kind == nc::SegmentKind::Rapid || s.kind == nc::SegmentKind::Feed; }

geom::Pose pose_at(const nc::AxisVector& p, const std::array<double, 3>& a) {
  return geom::Pose{{p[nc::X], p[nc::Y], p[nc::Z]}, {a[0], a[1], a[2]}};
}

}  // namespace

std::vector<gfx::ToolState> final_tools(const Profile& profile, const nc::Toolpath& path) {
  int tool = path.start_tool;
  geom::Pose pose = pose_at(path.start, path.start_axis);
  for (const nc::Segment& s : path.segments) {
    if (s.kind == nc::SegmentKind::ToolChange || is_motion(s)) tool = s.tool;
    if (is_motion(s)) {
      const geom::Vec3 axis = pose.axis;
      pose = pose_at(s.end, s.tool_axis);
      if (!s.has_tool_axis) pose.axis = axis;
    }
  }
  const auto it = profile.tooling.tools.find(tool);
  if (it == profile.tooling.tools.end()) return {};
  return {gfx::tool_state(it->second, tool, pose)};
}

namespace {

std::vector<ChannelPath> one_channel(const Profile& profile, const nc::Toolpath& path) {
  return {ChannelPath{"", path, profile.kin}};
}

bool has_tool_axes(const std::vector<ChannelPath>& channels) {
  for (const ChannelPath& c : channels)
    for (const nc::Segment& s : c.path.segments)
      if (s.has_tool_axis) return true;
  return false;
}

}  // namespace

geom::SolidSpec stream_solid_spec(const Profile& profile, const std::vector<ChannelPath>& channels) {
  motion::ToolTable tools(profile.tooling, profile.solid.chord_tol_mm, profile.source);
  for (const ChannelPath& c : channels) tools.require_path(c.path);
  return batch_solid_spec(profile, tools);
}

PathStreamer::PathStreamer(const Profile& profile, const nc::Toolpath& path, geom::LbrSolid& solid,
                           gfx::SolidExchange& ex, StreamOptions opt)
    : PathStreamer(profile, one_channel(profile, path), solid, ex, opt) {}

PathStreamer::PathStreamer(const Profile& profile, const std::vector<ChannelPath>& channels, geom::LbrSolid& solid,
                           gfx::SolidExchange& ex, StreamOptions opt)
    : tools_(profile.tooling, profile.solid.chord_tol_mm, profile.source), solid_(solid), ex_(ex), opt_(opt) {
  for (const ChannelPath& c : channels) tools_.require_path(c.path);
  nc::EmulatorLimits limits = emulator_limits(profile);
  limits.sample_period_ms = opt_.sample_period_s * 1e3;
  const bool sampled = !has_tool_axes(channels);
  motion::PlannedSweeps plan = motion::plan_channels(tools_, channels, limits, sampled);
  sweeps_ = std::move(plan.sweeps);
  duration_s_ = plan.machining_time_s;
  if (opt_.control != nullptr) initial_ = std::make_unique<geom::LbrSolid>(solid_);
  if (profile.checks.enabled) setup_checks(profile, channels, sampled);
}

void PathStreamer::setup_checks(const Profile& profile, const std::vector<ChannelPath>& channels, bool sampled) {
  for (const ChannelPath& c : channels) sources_.push_back(c.path.source);
  if (sampled) {
    // As live mode: faster than the max cutting feed by more than the margin is a rapid.
    const double fast_mm_per_s = verify::kFastMargin *
                                 verify::rapid_threshold_mm_per_min(profile.machine.max_feed_mm_per_min,
                                                                    profile.machine.rapid_mm_per_min) / 60.0;
    rapid_.assign(sweeps_.size(), 0);
    std::vector<double> t_prev(channels.size(), 0.0);
    for (std::size_t i = 0; i < sweeps_.size(); ++i) {
      const motion::TimedSweep& s = sweeps_[i];
      double& t0 = t_prev[static_cast<std::size_t>(s.channel)];
      const geom::Vec3 d = s.ref.to.tip - s.ref.from.tip;
      const double dt = s.t_s - t0;
      rapid_[i] = dt > 0.0 && std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) > fast_mm_per_s * dt ? 1 : 0;
      t0 = s.t_s;
    }
  } else {
    geom::MoveId base = 0;  // segment ids of each channel, as motion::plan_channels() gives them
    for (const ChannelPath& c : channels) {
      index_.add(c.path, base);
      base += static_cast<geom::MoveId>(c.path.segments.size());
    }
  }
  checker_ = std::make_unique<verify::CollisionChecker>(profile.checks, tools_, index_);
}

void PathStreamer::subtract_checked(std::size_t from, std::size_t to, std::vector<geom::SweepRef>& batch) {
  while (from < to) {
    std::size_t end = to;
    const std::size_t before = events_.size();
    if (checker_ && rapid_.empty()) end = checker_->check(solid_, sweeps_, from, to, events_);
    else if (checker_) end = checker_->check(solid_, sweeps_, rapid_, from, to, events_, true);
    for (std::size_t k = before; k < events_.size(); ++k) {  // a sampled sweep names its line, not its program
      verify::Event& e = events_[k];
      if (e.source.empty() && static_cast<std::size_t>(e.channel) < sources_.size()) e.source = sources_[e.channel];
    }
    batch.clear();
    for (std::size_t k = from; k < end; ++k) batch.push_back(sweeps_[k].ref);
    const double before_mm3 = checker_ ? solid_.volume_mm3() : 0.0;
    solid_.subtract(batch);
    if (checker_) checker_->settle(before_mm3 - solid_.volume_mm3(), true, events_);
    from = end;
  }
}

PathStreamer::~PathStreamer() { stop(); }

void PathStreamer::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { loop(); });
}

void PathStreamer::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

std::size_t PathStreamer::tools_at(std::size_t upto, std::array<gfx::ToolState, gfx::kMaxTools>& out) const {
  std::array<bool, gfx::kMaxTools> seen{};
  std::size_t n = 0;
  for (std::size_t i = upto; i-- > 0 && n < out.size();) {
    const motion::TimedSweep& s = sweeps_[i];
    const auto ch = static_cast<std::size_t>(s.channel);
    if (ch >= seen.size() || seen[ch]) continue;
    seen[ch] = true;
    if (s.ref.shape != nullptr) out[n++] = gfx::tool_state(s.ref.shape->tool, s.tool, s.ref.to, s.channel);
    if (std::all_of(seen.begin(), seen.end(), [](bool b) { return b; })) break;
  }
  return n;
}

double PathStreamer::advance(double sim_s, double dt_s, std::size_t next) {
  gfx::ReplayControl* c = opt_.control;
  if (c == nullptr) return sim_s + dt_s * opt_.speed;
  if (!c->paused.load(std::memory_order_relaxed)) return sim_s + dt_s * c->speed.load(std::memory_order_relaxed);
  // Paused: one step runs the next sweep (one controller sample) and nothing else.
  int steps = c->steps.load(std::memory_order_relaxed);
  while (steps > 0 && !c->steps.compare_exchange_weak(steps, steps - 1, std::memory_order_relaxed)) {
  }
  if (steps > 0 && next < sweeps_.size()) return std::max(sim_s, sweeps_[next].t_s);
  return sim_s;
}

void PathStreamer::restart(std::size_t& next, geom::MoveId& last) {
  for (int r = 0; r < solid_.regions(); ++r)
    for (int l = 0; l < solid_.levels(); ++l) solid_.set_cell(r, l, initial_->cell(r, l).polys, 0);
  next = 0;
  last = 0;
  line_ = -1;
  events_.clear();
}

double PathStreamer::take_seek() {
  gfx::ReplayControl* c = opt_.control;
  if (c == nullptr) return -1.0;
  const double t = c->seek_s.exchange(-1.0);
  const long long line = c->seek_line.exchange(0);
  if (line <= 0) return t;
  // The end of the line's first run of motion (channel 0); a line without motion: just
  // before the next line that moves.
  std::size_t k = 0;
  while (k < sweeps_.size() && (sweeps_[k].channel != 0 || sweeps_[k].line < line)) ++k;
  double target = 0.0;
  for (std::size_t j = 0; j < k; ++j) target = std::max(target, sweeps_[j].t_s);
  for (; k < sweeps_.size(); ++k) {
    if (sweeps_[k].channel != 0) continue;
    if (sweeps_[k].line != line) break;
    target = sweeps_[k].t_s;
  }
  return target;
}

bool PathStreamer::apply_due(double sim_s, std::size_t& next, geom::MoveId& last, std::vector<geom::SweepRef>& batch) {
  using clock = std::chrono::steady_clock;
  const std::size_t from = next;
  for (; next < sweeps_.size() && sweeps_[next].t_s <= sim_s; ++next) {
    const motion::TimedSweep& s = sweeps_[next];
    ex_.add_path_point(s.ref.to.tip);
    last = s.ref.id;
    if (s.channel == 0 && s.line > 0) line_ = s.line;
  }
  if (next == from) return false;
  const auto t0 = clock::now();
  subtract_checked(from, next, batch);
  batch_ms_.push_back(std::chrono::duration<double, std::milli>(clock::now() - t0).count());
  batches_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

void PathStreamer::loop() {
  using clock = std::chrono::steady_clock;
  std::vector<geom::SweepRef> batch;
  batch.reserve(4096);
  batch_ms_.reserve(1 << 16);
  const auto tick = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(opt_.tick_s));
  auto next = clock::now(), prev = next;
  double sim = 0.0;  // simulated machining time reached [s]
  std::size_t i = 0;
  gfx::LiveStats stats;
  stats.total_s = duration_s_;
  std::array<gfx::ToolState, gfx::kMaxTools> tools{};
  std::size_t tool_count = 0;
  geom::MoveId last = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    const auto now = clock::now();
    const double seek = take_seek();
    if (seek >= 0.0 || (opt_.control != nullptr && opt_.control->restart.exchange(false))) {
      restart(i, last);
      // A seek goes to its time; a restart to just before the start, so that the samples at
      // t = 0 wait for the first tick that advances (a restart while paused leaves the stock
      // untouched).
      sim = seek >= 0.0 ? seek : -1e-9;
      tool_count = 0;
      done_.store(false, std::memory_order_release);
    }
    if (seek < 0.0) sim = advance(sim, std::chrono::duration<double>(now - prev).count(), i);
    prev = now;
    const double speed = opt_.control != nullptr ? opt_.control->speed.load(std::memory_order_relaxed) : opt_.speed;
    if (apply_due(sim, i, last, batch)) {
      tool_count = tools_at(i, tools);
      stats.lag_ms = std::max(0.0, (sim - sweeps_[i - 1].t_s) / speed * 1000.0);
      stats.sample_rate_hz = speed / opt_.sample_period_s;
      stats.samples = i;
    }
    stats.program_line = line_;
    stats.machining_s = std::clamp(sim, 0.0, duration_s_);
    stats.paused = opt_.control != nullptr && opt_.control->paused.load(std::memory_order_relaxed);
    fill_event_alarms(events_, 0, kShownEventAlarms, false, stats);
    const std::span<const gfx::ToolState> shown(tools.data(), tool_count);
    // Publish every tick: a refused publish (render side busy) loses nothing.
    (void)ex_.publish(solid_, shown, last, stats);
    line_pub_.store(line_, std::memory_order_relaxed);
    position_s_.store(stats.machining_s, std::memory_order_release);
    if (i >= sweeps_.size()) {
      // Make sure the final state gets out.
      while (solid_.dirty_count() > 0 && !stop_.load(std::memory_order_relaxed)) {
        if (ex_.publish(solid_, shown, last, stats)) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      done_.store(true, std::memory_order_release);
      if (opt_.control == nullptr) break;  // with a control a restart may follow
    }
    next += tick;
    std::this_thread::sleep_until(next);
  }
  done_.store(true, std::memory_order_release);
}

namespace {

struct ViewDesign {
  std::optional<verify::DesignReport> report;  // a static view's comparison
  std::vector<geom::Paths> sections;            // the model sliced on the stock's levels
  std::vector<verify::Event> events;            // a static view's checks (the batch run's)
};

// The checks' summary on stdout ("checks: N errors, M warnings") and the first events, as
// `lbrsim batch` prints them (no events.csv: batch writes that).
void print_view_events(const std::vector<verify::Event>& events) {
  constexpr std::size_t kShown = 5;
  const verify::EventCounts c = verify::count(events);
  std::printf("checks: %zu error%s, %zu warning%s\n", c.errors, c.errors == 1 ? "" : "s", c.warnings,
              c.warnings == 1 ? "" : "s");
  for (std::size_t k = 0; k < std::min(kShown, events.size()); ++k) {
    if (events[k].severity() == verify::Severity::Error) spdlog::error("{}", verify::describe(events[k]));
    else spdlog::warn("{}", verify::describe(events[k]));
  }
}

// The batch result with the tool at its final pose and the programmed path (segment ends);
// with --design, the comparison and the design sections go to `design`.
std::unique_ptr<geom::LbrSolid> publish_batch_result(const Profile& profile, const std::vector<ChannelPath>& channels,
                                                     gfx::SolidExchange& ex, ViewDesign& design) {
  BatchResult r = channels.size() == 1 ? run_batch(profile, channels.front().path) : run_batch_channels(profile, channels);
  design.report = std::move(r.design);
  design.sections = std::move(r.design_sections);
  design.events = r.events;
  auto solid = std::make_unique<geom::LbrSolid>(std::move(r.solid));
  solid->clear_dirty();
  std::size_t segments = 0;
  for (const ChannelPath& c : channels) {
    const nc::Toolpath& path = c.path;
    segments += path.segments.size();
    ex.add_path_point({path.start[nc::X], path.start[nc::Y], path.start[nc::Z]});
    for (const nc::Segment& s : path.segments)
      if (is_motion(s)) ex.add_path_point({s.end[nc::X], s.end[nc::Y], s.end[nc::Z]});
  }
  const auto tools = channels.size() == 1 ? final_tools(profile, channels.front().path) : std::vector<gfx::ToolState>{};
  gfx::LiveStats stats;
  fill_event_alarms(r.events, 0, kShownEventAlarms, false, stats);
  (void)ex.publish(*solid, tools, static_cast<geom::MoveId>(segments), stats);
  return solid;
}

// --design: deviation colours (--color deviation) from the sections on the levels of `solid`,
// and the comparison's line on the HUD and stdout (a static view; --animate colours only).
void apply_design(const Profile& profile, const ViewDesign& design, const geom::LbrSolid& solid,
                  gfx::RenderThreadConfig& rc) {
  const double tol = profile.design.tolerance_mm;
  if (rc.render.color == gfx::ColorMode::Deviation && !design.sections.empty()) {
    rc.render.deviation = deviation_fn(design.sections, solid, tol);
    rc.render.deviation_scale_mm = gfx::kDeviationScalePerTolerance * tol;
  }
  if (!design.report) return;
  rc.render.design = design_summary(*design.report, tol);
  std::printf("design: %s\n", rc.render.design.c_str());
}

}  // namespace

std::vector<std::string> program_text(const std::string& file) {
  std::vector<std::string> lines;
  std::ifstream in(file);
  for (std::string l; std::getline(in, l);) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    lines.push_back(std::move(l));
  }
  return lines;
}

int run_view(const Profile& profile, const std::vector<ChannelPath>& channels, const ViewOptions& opt) {
  gfx::RenderThreadConfig rc = opt.render;
  if (opt.frames) rc.max_frames = opt.frames;
  const std::string title = channels.size() == 1 ? channels.front().path.source : profile.source;
  gfx::Window win(rc.width, rc.height, !opt.hidden, "lbrsim — " + title, opt.kiosk);
  if (!opt.quiet) spdlog::info("OpenGL: {}", gfx::Window::gl_description());

  std::size_t segments = 0;
  for (const ChannelPath& c : channels) segments += c.path.segments.size();
  std::unique_ptr<geom::LbrSolid> solid;
  ViewDesign design;  // --design; outlives the render thread (its deviation callback reads it)
  gfx::SolidExchange ex(std::max<std::size_t>(8192, segments + 2 * channels.size()));
  std::unique_ptr<PathStreamer> streamer;
  gfx::ReplayControl replay;
  replay.speed.store(opt.stream.speed);
  rc.ui.source = title;
  if (channels.size() == 1) rc.ui.program = program_text(channels.front().path.source);
  if (opt.animate) {
    solid = std::make_unique<geom::LbrSolid>(stream_solid_spec(profile, channels));
    solid->clear_dirty();
    StreamOptions so = opt.stream;
    if (rc.ui.enabled && !opt.hidden) {
      so.control = &replay;
      rc.ui.replay = &replay;
    }
    streamer = std::make_unique<PathStreamer>(profile, channels, *solid, ex, so);
    design.sections = load_design(profile, *solid);
    if (!opt.quiet) spdlog::info("streaming {:.1f} s of machining at {}x", streamer->duration_s(), opt.stream.speed);
  } else {
    solid = publish_batch_result(profile, channels, ex, design);
  }
  apply_design(profile, design, *solid, rc);

  gfx::RenderThread rt(win, ex, *solid, rc);
  rt.start();
  if (streamer) streamer->start();
  gfx::run_event_loop(win, rt, [&] {
    // Headless animated runs end a second after the stream does.
    static std::chrono::steady_clock::time_point done_at{};
    if (!opt.hidden || !streamer || opt.frames) return true;  // (hidden: no UI, no replay control)
    if (!streamer->done()) return true;
    if (done_at == std::chrono::steady_clock::time_point{}) done_at = std::chrono::steady_clock::now();
    return std::chrono::steady_clock::now() - done_at < std::chrono::seconds(1);
  }, opt.kiosk);
  if (streamer) streamer->stop();
  rt.stop();
  if (profile.checks.enabled) print_view_events(streamer ? streamer->events() : design.events);
  const gfx::PacingReport& rep = rt.report();
  if (!rep.error.empty()) throw std::runtime_error("render thread: " + rep.error);
  double rebuilt = 0;
  int rebuilt_max = 0;
  for (int v : rep.regions_rebuilt) {
    rebuilt += v;
    rebuilt_max = std::max(rebuilt_max, v);
  }
  std::printf("frames %llu (late %llu) | period p50 %.2f ms p99 %.2f ms max %.2f ms | work p50 %.2f ms p99 %.2f ms | "
              "regions rebuilt per frame mean %.2f max %d | snapshots %llu | screenshots %llu\n",
              static_cast<unsigned long long>(rep.frames), static_cast<unsigned long long>(rep.late_frames),
              gfx::PacingReport::percentile(rep.period_ms, 0.5), gfx::PacingReport::percentile(rep.period_ms, 0.99),
              gfx::PacingReport::percentile(rep.period_ms, 1.0), gfx::PacingReport::percentile(rep.work_ms, 0.5),
              gfx::PacingReport::percentile(rep.work_ms, 0.99),
              rep.frames ? rebuilt / static_cast<double>(rep.frames) : 0.0, rebuilt_max,
              static_cast<unsigned long long>(rep.snapshots), static_cast<unsigned long long>(rep.screenshots));
  return 0;
}

}  // namespace lbr::app
