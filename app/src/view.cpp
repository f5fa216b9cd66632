#include "app/view.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <spdlog/spdlog.h>

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
  const auto it = profile.tools.find(tool);
  if (it == profile.tools.end()) return {};
  return {gfx::tool_state(it->second, tool, pose)};
}

PathStreamer::PathStreamer(const Profile& profile, const nc::Toolpath& path, geom::LbrSolid& solid,
                           gfx::SolidExchange& ex, StreamOptions opt)
    : solid_(solid), ex_(ex), opt_(opt) {
  // Sample the path at the controller period under the batch runner's motion model.
  double t = 0;
  geom::Pose pose = pose_at(path.start, path.start_axis);
  nc::AxisVector pos = path.start;
  samples_.push_back({0.0, pose, path.start_tool, 0});
  for (std::size_t i = 0; i < path.segments.size(); ++i) {
    const nc::Segment& s = path.segments[i];
    if (s.kind == nc::SegmentKind::Dwell) t += s.dwell_s;
    if (s.kind == nc::SegmentKind::ToolChange) t += profile.tool_change_s;
    if (!is_motion(s)) continue;
    if (!shapes_.count(s.tool)) {
      const auto it = profile.tools.find(s.tool);
      if (it == profile.tools.end())
        throw std::runtime_error(path.source + ":" + std::to_string(s.line) + ": tool " + std::to_string(s.tool) +
                                 " is not in the tool table of " + profile.source);
      shapes_.emplace(s.tool, geom::CutterShape::build(it->second, profile.solid.chord_tol_mm));
      tools_.emplace(s.tool, it->second);
    }
    geom::Pose next = pose_at(s.end, s.tool_axis);
    if (!s.has_tool_axis) next.axis = pose.axis;
    const double len = std::hypot(s.end[nc::X] - pos[nc::X], s.end[nc::Y] - pos[nc::Y], s.end[nc::Z] - pos[nc::Z]);
    const double rate = s.kind == nc::SegmentKind::Rapid ? profile.rapid_mm_per_min : s.feed_mm_per_min;
    const double d = rate > 0 ? len / rate * 60.0 : 0.0;
    const int n = std::max(1, static_cast<int>(std::ceil(d / opt_.sample_period_s)));
    for (int k = 1; k <= n; ++k) {
      const double f = static_cast<double>(k) / n;
      samples_.push_back({t + f * d, {geom::lerp(pose.tip, next.tip, f), geom::lerp(pose.axis, next.axis, f)}, s.tool,
                          static_cast<geom::MoveId>(i + 1)});
    }
    t += d;
    pose = next;
    pos = s.end;
  }
}

PathStreamer::~PathStreamer() { stop(); }

double PathStreamer::duration_s() const noexcept { return samples_.empty() ? 0.0 : samples_.back().t; }

void PathStreamer::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { loop(); });
}

void PathStreamer::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void PathStreamer::loop() {
  using clock = std::chrono::steady_clock;
  std::vector<geom::SweepRef> batch;
  batch.reserve(4096);
  batch_ms_.reserve(1 << 16);
  geom::SubtractWorkspace ws;
  const auto start = clock::now();
  const auto tick = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(opt_.tick_s));
  auto next = start;
  std::size_t i = 1;
  gfx::LiveStats stats;
  std::vector<gfx::ToolState> tools(1);
  geom::MoveId last = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    const double sim = std::chrono::duration<double>(clock::now() - start).count() * opt_.speed;
    batch.clear();
    while (i < samples_.size() && samples_[i].t <= sim) {
      const Sample& a = samples_[i - 1];
      const Sample& b = samples_[i];
      batch.push_back({&shapes_.at(b.tool), a.pose, b.pose, b.id});
      ex_.add_path_point(b.pose.tip);
      last = b.id;
      ++i;
    }
    if (!batch.empty()) {
      const auto t0 = clock::now();
      solid_.subtract(batch, ws);
      batch_ms_.push_back(std::chrono::duration<double, std::milli>(clock::now() - t0).count());
      batches_.fetch_add(1, std::memory_order_relaxed);
      const Sample& cur = samples_[i - 1];
      tools[0] = gfx::tool_state(tools_.at(cur.tool), cur.tool, cur.pose);
      stats.lag_ms = std::max(0.0, (std::chrono::duration<double>(clock::now() - start).count() * opt_.speed - cur.t) /
                                       opt_.speed * 1000.0);
      stats.sample_rate_hz = opt_.speed / opt_.sample_period_s;
      stats.samples = i;
    }
    // Publish every tick: a refused publish (render side busy) loses nothing.
    (void)ex_.publish(solid_, tools, last, stats);
    if (i >= samples_.size()) {
      // Make sure the final state gets out.
      while (solid_.dirty_count() > 0 && !stop_.load(std::memory_order_relaxed)) {
        if (ex_.publish(solid_, tools, last, stats)) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      break;
    }
    next += tick;
    std::this_thread::sleep_until(next);
  }
  done_.store(true, std::memory_order_release);
}

int run_view(const Profile& profile, const nc::Toolpath& path, const ViewOptions& opt) {
  gfx::RenderThreadConfig rc = opt.render;
  if (opt.frames) rc.max_frames = opt.frames;
  gfx::Window win(rc.width, rc.height, !opt.hidden, "lbrsim — " + path.source);
  if (!opt.quiet) spdlog::info("OpenGL: {}", gfx::Window::gl_description());

  std::unique_ptr<geom::LbrSolid> solid;
  gfx::SolidExchange ex(std::max<std::size_t>(8192, path.segments.size() + 2));
  std::unique_ptr<PathStreamer> streamer;
  if (opt.animate) {
    geom::SolidSpec spec = profile.solid;
    if (profile.regions_auto) {
      double dmax = 1.0;
      for (const nc::Segment& s : path.segments)
        if (is_motion(s) && profile.tools.count(s.tool)) dmax = std::max(dmax, profile.tools.at(s.tool).diameter_mm);
      std::tie(spec.regions_x, spec.regions_y) = auto_region_grid(spec, dmax);
    }
    solid = std::make_unique<geom::LbrSolid>(spec);
    solid->clear_dirty();
    streamer = std::make_unique<PathStreamer>(profile, path, *solid, ex, opt.stream);
    if (!opt.quiet) spdlog::info("streaming {:.1f} s of machining at {}x", streamer->duration_s(), opt.stream.speed);
  } else {
    BatchResult r = run_batch(profile, path);
    solid = std::make_unique<geom::LbrSolid>(std::move(r.solid));
    solid->clear_dirty();
    // One snapshot with the tool at its final pose and the programmed path (segment ends).
    geom::Vec3 p{path.start[nc::X], path.start[nc::Y], path.start[nc::Z]};
    ex.add_path_point(p);
    for (const nc::Segment& s : path.segments)
      if (is_motion(s)) ex.add_path_point({s.end[nc::X], s.end[nc::Y], s.end[nc::Z]});
    const auto tools = final_tools(profile, path);
    (void)ex.publish(*solid, tools, static_cast<geom::MoveId>(path.segments.size()), gfx::LiveStats{});
  }

  gfx::RenderThread rt(win, ex, *solid, rc);
  rt.start();
  if (streamer) streamer->start();
  gfx::run_event_loop(win, rt, [&] {
    // Headless animated runs end a second after the stream does.
    static std::chrono::steady_clock::time_point done_at{};
    if (!opt.hidden || !streamer || opt.frames) return true;
    if (!streamer->done()) return true;
    if (done_at == std::chrono::steady_clock::time_point{}) done_at = std::chrono::steady_clock::now();
    return std::chrono::steady_clock::now() - done_at < std::chrono::seconds(1);
  });
  if (streamer) streamer->stop();
  rt.stop();
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
