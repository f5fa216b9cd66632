#include "motion/path_sweeps.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace lbr::motion {

namespace {

geom::Pose pose_of(const nc::AxisVector& p, const std::array<double, 3>& axis) {
  return geom::Pose{{p[nc::X], p[nc::Y], p[nc::Z]}, {axis[0], axis[1], axis[2]}};
}

bool is_motion(const nc::Segment& s) { return s.kind == nc::SegmentKind::Rapid || s.kind == nc::SegmentKind::Feed; }

// One channel's emulated sample stream, one motion per sample that moved.
void sampled_sweeps(const ToolTable& tools, const ChannelPath& c, nc::Emulator& em, int channel, geom::MoveId id_base,
                    PlannedSweeps& out) {
  const SweepMapper mapper(tools, c.kin);
  nc::AxisVector prev = c.path.start;
  double t_prev = 0.0;
  nc::Sample s;
  while (em.next(s)) {
    if (s.axes != prev) {
      ++out.moves;
      const std::size_t first = out.sweeps.size();
      mapper.map(prev, s.axes, s.tool, static_cast<geom::MoveId>(id_base + s.seq + 1), t_prev, s.t_s, channel,
                 out.sweeps);
      const int line = em.line_at(s.t_s);  // the planned piece the sample ends in
      for (std::size_t k = first; k < out.sweeps.size(); ++k) out.sweeps[k].line = line;
    }
    prev = s.axes;
    t_prev = s.t_s;
  }
}

}  // namespace

void SweepMapper::map(const nc::AxisVector& q0, const nc::AxisVector& q1, int tool, geom::MoveId id, double t0,
                      double t1, int channel, std::vector<TimedSweep>& out) const {
  if (tool == 0) return;  // no tool in the spindle (e.g. G28 before the first M6): nothing cuts
  const ToolRef t = tools_.find(tool);
  geom::SweepRef r;
  r.id = id;
  r.shape = t.shape;
  r.turning = t.turning;
  const int n = kin::substeps(kin_, q0, q1, t.mount, t.length_mm, t.reach_mm, tools_.chord_tol_mm());
  r.from = kin::tool_pose(kin_, q0, t.mount, t.length_mm);
  for (int k = 1; k <= n; ++k) {
    const double f = static_cast<double>(k) / n;
    nc::AxisVector q = q1;
    if (k < n)
      for (int a = 0; a < nc::kAxes; ++a) q[a] = q0[a] + f * (q1[a] - q0[a]);
    r.to = kin::tool_pose(kin_, q, t.mount, t.length_mm);
    out.push_back({t0 + f * (t1 - t0), channel, tool, r});
    r.from = r.to;
  }
}

void path_sweeps(const ToolTable& tools, const kin::Kinematics& k, const nc::Toolpath& path,
                 const std::vector<double>* end_time, int channel, geom::MoveId id_base, std::vector<TimedSweep>& out,
                 std::uint64_t& moves) {
  if (end_time != nullptr && end_time->size() != path.segments.size())
    throw std::logic_error(path.source + ": " + std::to_string(end_time->size()) + " end times for " +
                           std::to_string(path.segments.size()) + " segments");
  const SweepMapper mapper(tools, k);
  const bool direct = k.kind == nc::MachineKind::Mill3;
  geom::Pose pose = pose_of(path.start, path.start_axis);
  nc::AxisVector q = path.start;
  double t = 0.0;
  for (std::size_t i = 0; i < path.segments.size(); ++i) {
    const nc::Segment& s = path.segments[i];
    const double t_end = end_time != nullptr ? (*end_time)[i] : t;
    if (!is_motion(s)) {
      // A tool change moves the tip without a motion (the gauge line stays where it is, the
      // new tool's length differs: docs/nc-frontend.md): the next motion starts from the new
      // tip, as the machine's (and the sampled stream's) does.
      if (direct || s.has_tool_axis) pose.tip = {s.end[nc::X], s.end[nc::Y], s.end[nc::Z]};
      else pose = kin::tool_pose(k, s.end, tools.mount_of(s.tool));
      q = s.end;
      t = t_end;
      continue;
    }
    const auto id = static_cast<geom::MoveId>(id_base + i + 1);
    if (direct || s.has_tool_axis) {
      geom::Pose next = pose_of(s.end, s.tool_axis);
      if (!s.has_tool_axis) next.axis = pose.axis;
      if (s.tool != 0) {
        const ToolRef tr = tools.find(s.tool);
        geom::SweepRef r;
        r.id = id;
        r.shape = tr.shape;
        r.turning = tr.turning;
        r.from = pose;
        r.to = next;
        out.push_back({t_end, channel, s.tool, r, s.line});
        ++moves;
      }
      pose = next;
    } else {
      if (s.tool != 0) ++moves;
      const std::size_t first = out.size();
      mapper.map(q, s.end, s.tool, id, t, t_end, channel, out);
      for (std::size_t j = first; j < out.size(); ++j) out[j].line = s.line;
      pose = kin::tool_pose(k, s.end, tools.mount_of(s.tool));
    }
    q = s.end;
    t = t_end;
  }
}

namespace {

// One end time per segment [s]. The planner's pieces are not one per segment (blend arcs,
// merged naive-CAM runs), so the times come from an exact-stop plan of the same path, scaled
// to the blended run's total time `total_s`: segments keep their order and the channel ends
// when its blended run ends. In an exact-stop plan every piece is a Line ending at its
// segment's end or a Hold; a motion too short to plan has no piece and ends when the
// segment before it ends.
std::vector<double> segment_end_times(const nc::Toolpath& path, const nc::EmulatorLimits& limits, double total_s) {
  nc::Toolpath exact = path;
  for (nc::Segment& s : exact.segments) s.path_control = nc::PathControl::ExactStop;
  const nc::Emulator em(exact, limits);
  const std::vector<nc::Emulator::Plan>& plans = em.plans();
  const double scale = em.total_time_s() > 0.0 ? total_s / em.total_time_s() : 1.0;
  std::vector<double> out;
  out.reserve(path.segments.size());
  std::size_t p = 0;
  double t = 0.0;
  for (const nc::Segment& s : path.segments) {
    const bool hold = s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed;
    if (p < plans.size() && (plans[p].kind == nc::Emulator::PieceKind::Hold) == hold && plans[p].to == s.end) {
      t = plans[p].t0_s + plans[p].duration_s;
      ++p;
    }
    out.push_back(t * scale);
  }
  return out;
}

}  // namespace

PlannedSweeps plan_channels(const ToolTable& tools, std::span<const ChannelPath> channels,
                            const nc::EmulatorLimits& limits, bool sampled) {
  PlannedSweeps out;
  geom::MoveId id_base = 0;
  for (std::size_t ci = 0; ci < channels.size(); ++ci) {
    const ChannelPath& c = channels[ci];
    const int channel = static_cast<int>(ci);
    nc::Emulator em(c.path, limits);
    out.machining_time_s = std::max(out.machining_time_s, em.total_time_s());
    if (sampled) {
      sampled_sweeps(tools, c, em, channel, id_base, out);
      id_base += static_cast<geom::MoveId>(em.sample_count());
    } else {
      const std::vector<double> end_time = segment_end_times(c.path, limits, em.total_time_s());
      path_sweeps(tools, c.kin, c.path, &end_time, channel, id_base, out.sweeps, out.moves);
      id_base += static_cast<geom::MoveId>(c.path.segments.size());
    }
  }
  // Time order across channels; within a channel the order is kept (stable), ties go to the
  // lower channel.
  std::stable_sort(out.sweeps.begin(), out.sweeps.end(), [](const TimedSweep& a, const TimedSweep& b) {
    return a.t_s < b.t_s || (a.t_s == b.t_s && a.channel < b.channel);
  });
  return out;
}

}  // namespace lbr::motion
