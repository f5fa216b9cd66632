#include "app/batch.hpp"

#include "app/level_pool.hpp"

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

namespace lbr::app {

namespace {

geom::Pose pose_of(const nc::AxisVector& p, const std::array<double, 3>& axis) {
  return geom::Pose{{p[nc::X], p[nc::Y], p[nc::Z]}, {axis[0], axis[1], axis[2]}};
}

double distance(const nc::AxisVector& a, const nc::AxisVector& b) {
  return std::hypot(b[nc::X] - a[nc::X], b[nc::Y] - a[nc::Y], b[nc::Z] - a[nc::Z]);
}

}  // namespace

double machining_time_s(const Profile& profile, const nc::Toolpath& path) {
  double t = 0.0;
  nc::AxisVector pos = path.start;
  for (const nc::Segment& s : path.segments) {
    switch (s.kind) {
      case nc::SegmentKind::Rapid: t += distance(pos, s.end) / profile.rapid_mm_per_min * 60.0; break;
      case nc::SegmentKind::Feed: t += distance(pos, s.end) / s.feed_mm_per_min * 60.0; break;
      case nc::SegmentKind::Dwell: t += s.dwell_s; break;
      case nc::SegmentKind::ToolChange: t += profile.tool_change_s; break;
    }
    pos = s.end;
  }
  return t;
}

BatchResult run_batch(const Profile& profile, const nc::Toolpath& path, const Progress& progress) {
  // Cutter shapes for every tool the path uses, built once.
  std::map<int, geom::CutterShape> shapes;
  for (const nc::Segment& s : path.segments) {
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed && s.kind != nc::SegmentKind::ToolChange) continue;
    if (s.tool == 0 || shapes.count(s.tool)) continue;  // tool 0: empty spindle
    const auto it = profile.tools.find(s.tool);
    if (it == profile.tools.end())
      throw std::runtime_error(path.source + ":" + std::to_string(s.line) + ": tool " + std::to_string(s.tool) +
                               " is not in the tool table of " + profile.source);
    shapes.emplace(s.tool, geom::CutterShape::build(it->second, profile.solid.chord_tol_mm));
  }

  geom::SolidSpec spec = profile.solid;
  if (profile.regions_auto) {
    double dmax = 1.0;
    for (const auto& [n, sh] : shapes) dmax = std::max(dmax, sh.tool.diameter_mm);
    std::tie(spec.regions_x, spec.regions_y) = auto_region_grid(spec, dmax);
  }
  BatchResult r{geom::LbrSolid(spec), 0, 0, 0, 0, 0, {}, 1};
  r.stock_volume_mm3 = r.solid.initial_volume_mm3();
  r.machining_time_s = machining_time_s(profile, path);

  LevelPool pool(profile.threads);
  r.threads = pool.threads();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<geom::SweepRef> batch;
  batch.reserve(profile.batch_moves);
  geom::Pose pose = pose_of(path.start, path.start_axis);
  const std::size_t n = path.segments.size();
  auto last_report = t0;
  for (std::size_t i = 0; i < n; ++i) {
    const nc::Segment& s = path.segments[i];
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed) continue;
    geom::Pose next = pose_of(s.end, s.tool_axis);
    if (!s.has_tool_axis) next.axis = pose.axis;
    if (s.tool == 0) {  // no tool in the spindle (e.g. G28 before the first M6): nothing cuts
      pose = next;
      continue;
    }
    batch.push_back({&shapes.at(s.tool), pose, next, static_cast<geom::MoveId>(i + 1)});
    pose = next;
    ++r.moves;
    if (static_cast<int>(batch.size()) >= profile.batch_moves) {
      r.stats += pool.subtract(r.solid, batch);
      batch.clear();
      if (progress) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_report > std::chrono::seconds(1)) {
          last_report = now;
          progress(static_cast<double>(i + 1) / static_cast<double>(n));
        }
      }
    }
  }
  if (!batch.empty()) r.stats += pool.subtract(r.solid, batch);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.removed_volume_mm3 = r.stock_volume_mm3 - r.solid.volume_mm3();
  if (progress) progress(1.0);
  return r;
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace lbr::app
