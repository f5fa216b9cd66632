#include "nc/emulator.hpp"

#include "planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace lbr::nc {

std::string validate(const EmulatorLimits& l) {
  auto bad = [](double v) { return !std::isfinite(v) || v <= 0.0; };
  if (bad(l.sample_period_ms)) return "sample period must be > 0 ms";
  if (bad(l.rapid_mm_per_min)) return "rapid rate must be > 0 mm/min";
  if (!std::isfinite(l.max_feed_mm_per_min) || l.max_feed_mm_per_min < 0.0) return "feed cap must be >= 0 mm/min";
  if (!std::isfinite(l.tool_change_s) || l.tool_change_s < 0.0) return "tool change time must be >= 0 s";
  for (int a = 0; a < kAxes; ++a) {
    if (bad(l.max_velocity[a])) return "axis velocity limits must be > 0";
    if (bad(l.max_accel[a])) return "axis acceleration limits must be > 0";
  }
  return "";
}

Emulator::Emulator(const Toolpath& path, const EmulatorLimits& l) {
  if (const std::string e = validate(l); !e.empty()) throw std::invalid_argument("emulator limits: " + e);
  period_s_ = l.sample_period_ms * 1e-3;
  start_ = path.start;
  start_tool_ = path.start_tool;
  detail::PlannedPath planned = detail::plan_path(path, l);
  plans_ = std::move(planned.plans);
  arcs_ = std::move(planned.arcs);
  total_s_ = planned.total_s;
  const double n = std::ceil(total_s_ / period_s_);
  if (n > 1e15) throw std::invalid_argument(path.source + ": program too long for the sample period");
  count_ = static_cast<std::uint64_t>(n);
}

void Emulator::eval(std::size_t i, double t_s, AxisVector& axes) const noexcept {
  const Plan& p = plans_[i];
  detail::piece_position(p, arcs_, detail::piece_distance(p, t_s - p.t0_s), axes);
}

bool Emulator::next(Sample& out) noexcept {
  if (seq_ >= count_) return false;
  const double t = static_cast<double>(seq_ + 1) * period_s_;
  while (seg_ < plans_.size() && t > plans_[seg_].t0_s + plans_[seg_].duration_s) ++seg_;
  out.seq = seq_;
  out.t_s = t;
  if (seg_ < plans_.size()) {
    eval(seg_, t, out.axes);
    out.tool = plans_[seg_].tool;
  } else if (!plans_.empty()) {
    out.axes = plans_.back().to;
    out.tool = plans_.back().tool;
  } else {
    out.axes = start_;
    out.tool = start_tool_;
  }
  ++seq_;
  return true;
}

void Emulator::state_at(double t_s, AxisVector& axes, int& tool) const noexcept {
  if (plans_.empty() || t_s <= 0.0) {
    axes = start_;
    tool = start_tool_;
    if (!plans_.empty() && t_s > 0.0) tool = plans_.front().tool;
    return;
  }
  // First plan whose end is at or after t.
  auto it = std::lower_bound(plans_.begin(), plans_.end(), t_s,
                             [](const Plan& p, double t) { return p.t0_s + p.duration_s < t; });
  if (it == plans_.end()) {
    axes = plans_.back().to;
    tool = plans_.back().tool;
    return;
  }
  const auto i = static_cast<std::size_t>(it - plans_.begin());
  eval(i, t_s, axes);
  tool = it->tool;
}

int Emulator::line_at(double t_s) const noexcept {
  if (plans_.empty() || t_s <= 0.0) return 0;
  auto it = std::lower_bound(plans_.begin(), plans_.end(), t_s,
                             [](const Plan& p, double t) { return p.t0_s + p.duration_s < t; });
  return it == plans_.end() ? plans_.back().line : it->line;
}

double emulated_time_s(const Toolpath& path, const EmulatorLimits& limits) {
  return Emulator(path, limits).total_time_s();
}

Toolpath sampled_toolpath(const Toolpath& path, const EmulatorLimits& limits) {
  Emulator em(path, limits);
  Toolpath out;
  out.source = path.source;
  out.start = path.start;
  out.start_axis = path.start_axis;
  out.start_tool = path.start_tool;
  out.segments.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(em.sample_count(), 1u << 24)));
  AxisVector prev = path.start;
  int tool = path.start_tool;
  Sample s;
  std::size_t plan = 0;
  const auto& plans = em.plans();
  while (em.next(s)) {
    while (plan + 1 < plans.size() && s.t_s > plans[plan].t0_s + plans[plan].duration_s) ++plan;
    Segment seg;
    seg.end = s.axes;
    seg.tool = s.tool;
    seg.line = plans.empty() ? 0 : plans[plan].line;
    if (!plans.empty()) {
      seg.spindle = plans[plan].spindle;
      seg.spindle_s = plans[plan].spindle_s;
    }
    if (s.tool != tool) {
      seg.kind = SegmentKind::ToolChange;
      tool = s.tool;
    } else {
      if (s.axes == prev) continue;  // standing still (dwell, tool change, end): nothing to sweep
      seg.kind = SegmentKind::Feed;
      const double d = std::hypot(s.axes[X] - prev[X], s.axes[Y] - prev[Y], s.axes[Z] - prev[Z]);
      seg.feed_mm_per_min = std::max(d / em.period_s() * 60.0, 1e-9);
    }
    out.segments.push_back(seg);
    prev = s.axes;
  }
  return out;
}

}  // namespace lbr::nc
