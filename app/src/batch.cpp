#include "app/batch.hpp"

#include "app/level_pool.hpp"

#include <sys/resource.h>

#include <algorithm>
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

// Cutter shapes and insert shapes of the tools a run uses, built once; addresses are stable.
struct Tooling {
  std::map<int, geom::CutterShape> cutters;
  std::map<int, geom::TurningShape> inserts;

  void need(const Profile& profile, const nc::Toolpath& path, int tool, int line) {
    if (tool == 0 || cutters.count(tool) || inserts.count(tool)) return;  // tool 0: empty spindle
    if (const auto it = profile.tools.find(tool); it != profile.tools.end()) {
      cutters.emplace(tool, geom::CutterShape::build(it->second, profile.solid.chord_tol_mm));
      return;
    }
    if (const auto it = profile.inserts.find(tool); it != profile.inserts.end()) {
      inserts.emplace(tool, geom::TurningShape::build(it->second, profile.solid.chord_tol_mm));
      return;
    }
    throw std::runtime_error(path.source + ":" + std::to_string(line) + ": tool " + std::to_string(tool) +
                             " is not in the tool table of " + profile.source);
  }
  std::map<int, std::size_t> motions;  // motion segments per milling tool

  void need_all(const Profile& profile, const nc::Toolpath& path) {
    for (const nc::Segment& s : path.segments) {
      if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed && s.kind != nc::SegmentKind::ToolChange)
        continue;
      need(profile, path, s.tool, s.line);
      if (s.kind != nc::SegmentKind::ToolChange && cutters.count(s.tool)) ++motions[s.tool];
    }
  }
  // Diameter of the milling tool with the most motion segments (for a sampled program: the
  // longest time in the spindle), which the automatic region grid is sized for.
  [[nodiscard]] double dominant_diameter() const {
    double d = 1.0;
    std::size_t most = 0;
    for (const auto& [n, count] : motions) {
      if (count > most) {
        most = count;
        d = std::max(1.0, cutters.at(n).tool.diameter_mm);
      }
    }
    return d;
  }
};

struct TimedMove {
  double t_s = 0.0;
  int channel = 0;
  geom::SweepRef ref;
};

// Maps one motion of a channel (axes q0 → q1 with `tool`) through the kinematics into
// sweeps, appended to `out` with times spread over [t0, t1].
class MoveMapper {
 public:
  MoveMapper(const Profile& profile, const kin::Kinematics& k, const Tooling& tooling)
      : profile_(profile), kin_(k), tooling_(tooling) {}

  void map(const nc::AxisVector& q0, const nc::AxisVector& q1, int tool, geom::MoveId id, double t0, double t1,
           int channel, std::vector<TimedMove>& out) const {
    if (tool == 0) return;  // no tool in the spindle (e.g. G28 before the first M6): nothing cuts
    const kin::Mount mount = profile_.mount_of(tool);
    geom::SweepRef r;
    r.id = id;
    double length = 0.0, reach = 0.0;
    if (mount == kin::Mount::Turning) {
      r.turning = &tooling_.inserts.at(tool);
    } else {
      r.shape = &tooling_.cutters.at(tool);
      length = r.shape->tool.length_mm;
      reach = std::hypot(r.shape->height(), r.shape->radius());
    }
    const int n = kin::substeps(kin_, q0, q1, mount, length, reach, profile_.solid.chord_tol_mm);
    r.from = kin::tool_pose(kin_, q0, mount, length);
    for (int k = 1; k <= n; ++k) {
      const double f = static_cast<double>(k) / n;
      nc::AxisVector q = q1;
      if (k < n)
        for (int a = 0; a < nc::kAxes; ++a) q[a] = q0[a] + f * (q1[a] - q0[a]);
      r.to = kin::tool_pose(kin_, q, mount, length);
      out.push_back({t0 + f * (t1 - t0), channel, r});
      r.from = r.to;
    }
  }

 private:
  const Profile& profile_;
  const kin::Kinematics& kin_;
  const Tooling& tooling_;
};

// Segments of a tool path as sweeps. `end_time` (optional) gives each segment's end time.
void path_moves(const Profile& profile, const kin::Kinematics& k, const Tooling& tooling, const nc::Toolpath& path,
                const std::vector<double>* end_time, int channel, geom::MoveId id_base, std::vector<TimedMove>& out,
                std::uint64_t& moves) {
  const MoveMapper mapper(profile, k, tooling);
  // 3-axis and CL data (explicit tool axes from a move list) keep the path's own poses.
  const bool direct = k.kind == kin::MachineKind::Mill3;
  geom::Pose pose = pose_of(path.start, path.start_axis);
  nc::AxisVector q = path.start;
  double t = 0.0;
  for (std::size_t i = 0; i < path.segments.size(); ++i) {
    const nc::Segment& s = path.segments[i];
    const double t_end = end_time != nullptr ? (*end_time)[i] : t;
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed) {
      t = t_end;
      continue;
    }
    const auto id = static_cast<geom::MoveId>(id_base + i + 1);
    if (direct || s.has_tool_axis) {
      geom::Pose next = pose_of(s.end, s.tool_axis);
      if (!s.has_tool_axis) next.axis = pose.axis;
      if (s.tool != 0) {
        geom::SweepRef r;
        r.id = id;
        if (profile.mount_of(s.tool) == kin::Mount::Turning) r.turning = &tooling.inserts.at(s.tool);
        else r.shape = &tooling.cutters.at(s.tool);
        r.from = pose;
        r.to = next;
        out.push_back({t_end, channel, r});
        ++moves;
      }
      pose = next;
    } else {
      if (s.tool != 0) ++moves;
      mapper.map(q, s.end, s.tool, id, t, t_end, channel, out);
      pose = kin::tool_pose(k, s.end, profile.mount_of(s.tool));
    }
    q = s.end;
    t = t_end;
  }
}

geom::SolidSpec solid_spec(const Profile& profile, const Tooling& tooling) {
  geom::SolidSpec spec = profile.solid;
  if (profile.regions_auto) std::tie(spec.regions_x, spec.regions_y) = auto_region_grid(spec, tooling.dominant_diameter());
  return spec;
}

// Subtracts the moves in order, profile.batch_moves at a time.
void run_moves(const Profile& profile, const std::vector<TimedMove>& moves, BatchResult& r, const Progress& progress) {
  LevelPool pool(profile.threads);
  r.threads = pool.threads();
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  // Within one subtract() call the order of the sweeps does not matter (their union is
  // removed), so a batch is grouped by channel: each channel's consecutive sampled moves
  // then merge into long sweeps (merge_collinear) instead of alternating with the others'.
  std::vector<const TimedMove*> group;
  auto fill = [&](std::size_t from, std::size_t to, std::vector<geom::SweepRef>& out) {
    out.clear();
    const auto by_channel = [](const TimedMove& a, const TimedMove& b) { return a.channel < b.channel; };
    if (std::is_sorted(moves.begin() + static_cast<long>(from), moves.begin() + static_cast<long>(to), by_channel)) {
      for (std::size_t k = from; k < to; ++k) out.push_back(moves[k].ref);  // one channel: as they come
      return;
    }
    group.clear();
    for (std::size_t k = from; k < to; ++k) group.push_back(&moves[k]);
    std::stable_sort(group.begin(), group.end(),
                     [](const TimedMove* a, const TimedMove* b) { return a->channel < b->channel; });
    for (const TimedMove* m : group) out.push_back(m->ref);
  };
  // Batches of profile.batch_moves moves, pulled by the pool (a worker pulls the next one
  // while the current one is clipped).
  const std::size_t per = static_cast<std::size_t>(std::max(1, profile.batch_moves));
  std::size_t begin = 0;
  const LevelPool::BatchSource source = [&](std::vector<geom::SweepRef>& out) {
    if (begin >= moves.size()) return false;
    const std::size_t end = std::min(begin + per, moves.size());
    fill(begin, end, out);
    begin = end;
    return true;
  };
  std::size_t done_moves = 0;
  const LevelPool::BatchDone done = [&](const geom::SubtractStats&) {
    done_moves = std::min(done_moves + per, moves.size());
    if (!progress) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report > std::chrono::seconds(1)) {
      last_report = now;
      progress(static_cast<double>(done_moves) / static_cast<double>(moves.size()));
    }
  };
  r.stats += pool.run(r.solid, source, done);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.removed_volume_mm3 = r.stock_volume_mm3 - r.solid.volume_mm3();
  if (progress) progress(1.0);
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
  Tooling tooling;
  tooling.need_all(profile, path);
  BatchResult r{geom::LbrSolid(solid_spec(profile, tooling)), 0, 0, 0, 0, 0, {}, 1};
  r.stock_volume_mm3 = r.solid.initial_volume_mm3();
  r.machining_time_s = machining_time_s(profile, path);
  std::vector<TimedMove> moves;
  path_moves(profile, profile.kin, tooling, path, nullptr, 0, 0, moves, r.moves);
  run_moves(profile, moves, r, progress);
  return r;
}

BatchResult run_batch_channels(const Profile& profile, const std::vector<ChannelPath>& channels, bool sampled,
                               const Progress& progress) {
  Tooling tooling;
  for (const ChannelPath& c : channels) tooling.need_all(profile, c.path);
  BatchResult r{geom::LbrSolid(solid_spec(profile, tooling)), 0, 0, 0, 0, 0, {}, 1};
  r.stock_volume_mm3 = r.solid.initial_volume_mm3();
  const nc::EmulatorLimits limits = emulator_limits(profile);
  std::vector<TimedMove> moves;
  geom::MoveId id_base = 0;
  for (std::size_t ci = 0; ci < channels.size(); ++ci) {
    const ChannelPath& c = channels[ci];
    const int channel = static_cast<int>(ci);
    nc::Emulator em(c.path, limits);
    r.machining_time_s = std::max(r.machining_time_s, em.total_time_s());
    if (sampled) {
      // The channel's sample stream, as live mode receives it: one sweep per sample.
      const MoveMapper mapper(profile, c.kin, tooling);
      nc::AxisVector prev = c.path.start;
      double t_prev = 0.0;
      nc::Sample s;
      while (em.next(s)) {
        if (s.axes != prev) {
          ++r.moves;
          mapper.map(prev, s.axes, s.tool, static_cast<geom::MoveId>(id_base + s.seq + 1), t_prev, s.t_s, channel, moves);
        }
        prev = s.axes;
        t_prev = s.t_s;
      }
      id_base += static_cast<geom::MoveId>(em.sample_count());
    } else {
      std::vector<double> end_time;
      end_time.reserve(em.plans().size());
      for (const auto& pl : em.plans()) end_time.push_back(pl.t0_s + pl.duration_s);
      path_moves(profile, c.kin, tooling, c.path, &end_time, channel, id_base, moves, r.moves);
      id_base += static_cast<geom::MoveId>(c.path.segments.size());
    }
  }
  // Time order across channels; within a channel the order is kept (stable), ties go to the
  // lower channel.
  std::stable_sort(moves.begin(), moves.end(), [](const TimedMove& a, const TimedMove& b) {
    return a.t_s < b.t_s || (a.t_s == b.t_s && a.channel < b.channel);
  });
  run_moves(profile, moves, r, progress);
  return r;
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace lbr::app
