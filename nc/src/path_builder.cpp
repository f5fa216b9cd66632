#include "path_builder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

namespace lbr::nc::detail {

PlaneAxes plane_axes(Plane p) noexcept {
  switch (p) {
    case Plane::XY: return {X, Y, Z};
    case Plane::ZX: return {Z, X, Y};
    case Plane::YZ: return {Y, Z, X};
  }
  return {X, Y, Z};
}

double spindle_rpm(double s, bool css, double max_rpm, double mm_per_unit, double radius_mm) noexcept {
  if (!css) return s;
  const double surface_mm_per_min = s * (mm_per_unit == 1.0 ? 1000.0 : 304.8);
  const double r = std::abs(radius_mm);
  double rpm = r > 1e-6 ? surface_mm_per_min / (2.0 * std::numbers::pi * r) : HUGE_VAL;
  if (max_rpm > 0.0) rpm = std::min(rpm, max_rpm);
  return rpm;
}

PathBuilder::PathBuilder(const std::string& source, const GcodeOptions& options) : opt_(options) {
  tp_.source = source;
  tool_ = options.start_tool;
  length_ = tool_length(tool_);
  origin_ = options.work_offsets[0];
  pos_ = from_machine(options.start_machine);
  tp_.start = tip(pos_);
  tp_.start_tool = tool_;
  set_machine_frame(tp_, options);
}

double PathBuilder::tool_length(int tool) const {
  const auto it = opt_.tool_lengths.find(tool);
  return it == opt_.tool_lengths.end() ? 0.0 : it->second;
}

AxisVector PathBuilder::to_machine(const AxisVector& p) const {
  AxisVector m{};
  for (int a = 0; a < kAxes; ++a) m[a] = p[a] + origin_[a];
  m[Z] += tlo_;
  return m;
}

AxisVector PathBuilder::from_machine(const AxisVector& m) const {
  AxisVector p{};
  for (int a = 0; a < kAxes; ++a) p[a] = m[a] - origin_[a];
  p[Z] -= tlo_;
  return p;
}

AxisVector PathBuilder::tip(const AxisVector& p) const {
  AxisVector t = to_machine(p);
  for (int a = 0; a < kAxes; ++a) t[a] -= opt_.work_offsets[0][a];
  t[Z] -= length_;
  return t;
}

void PathBuilder::push(SegmentKind k, int line, const AxisVector& end_program, double feed_mm_per_min, double dwell_s) {
  if (opt_.max_segments > 0 && tp_.segments.size() >= static_cast<std::size_t>(opt_.max_segments))
    throw ParseError(tp_.source, line,
                     "the program makes more than " + std::to_string(opt_.max_segments) +
                         " moves (an endless loop, or arcs of many turns at a fine chord tolerance?)");
  Segment s;
  s.kind = k;
  s.end = tip(end_program);
  s.feed_mm_per_min = feed_mm_per_min;
  s.dwell_s = dwell_s;
  s.tool = tool_;
  s.line = line;
  s.path_control = control_;
  s.blend_tol_mm = blend_tol_mm_;
  s.naive_tol_mm = naive_tol_mm_;
  s.spindle = spindle_;
  s.spindle_s = spindle_s_;
  tp_.segments.push_back(s);
}

namespace {
double move_length(const AxisVector& a, const AxisVector& b) {
  const double l = std::hypot(b[X] - a[X], b[Y] - a[Y], b[Z] - a[Z]);
  if (l > 0.0) return l;
  return std::hypot(b[A] - a[A], b[B] - a[B], b[C] - a[C]);  // rotary-only move [deg]
}
}  // namespace

void PathBuilder::rapid(int line, const AxisVector& end) {
  push(SegmentKind::Rapid, line, end, 0.0, 0.0);
  pos_ = end;
}

void PathBuilder::feed(int line, const AxisVector& end, double feed, bool inverse_time) {
  const double f = inverse_time ? feed * move_length(pos_, end) : feed;
  push(SegmentKind::Feed, line, end, f, 0.0);
  pos_ = end;
}

void PathBuilder::arc(int line, Plane p, const AxisVector& end, double cu, double cv, int rotation, double feed,
                      bool inverse_time) {
  const PlaneAxes ax = plane_axes(p);
  const AxisVector start = pos_;
  const double su = start[ax.u] - cu, sv = start[ax.v] - cv;
  const double eu = end[ax.u] - cu, ev = end[ax.v] - cv;
  const double r0 = std::hypot(su, sv), r1 = std::hypot(eu, ev);
  const double a0 = std::atan2(sv, su);
  double sweep = std::atan2(ev, eu) - a0;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const bool closed = std::hypot(end[ax.u] - start[ax.u], end[ax.v] - start[ax.v]) < 1e-9;
  if (rotation > 0) {
    while (sweep <= 0.0) sweep += kTwoPi;
    if (closed) sweep = kTwoPi;
    sweep += kTwoPi * (rotation - 1);
  } else {
    while (sweep >= 0.0) sweep -= kTwoPi;
    if (closed) sweep = -kTwoPi;
    sweep -= kTwoPi * (-rotation - 1);
  }
  const double rmax = std::max(r0, r1);
  const double tol = opt_.chord_tol_mm;
  // Chords on both sides of the arc, like the kernel's two-sided polygons
  // (docs/lbr-conventions.md): the inner vertices lie on radius r·θ/sin θ (θ half a chord's
  // angle), which keeps the arc's mean position, so the swept volume has no bias from the
  // chord tolerance; the end points stay exact. The end chords (from radius r to r·θ/sin θ)
  // deviate most, about 5/12·r·θ² inside the arc: θ = sqrt(2.35·tol/r) keeps that below tol.
  double n_real = 1.0;
  if (rmax > tol) n_real = std::ceil(std::abs(sweep) / (2.0 * std::sqrt(2.35 * tol / rmax)));
  if (!(n_real <= static_cast<double>(kMaxArcChords))) {
    std::ostringstream m;
    m << "arc of radius " << rmax << " mm needs more than " << kMaxArcChords << " chords at the chord tolerance "
      << tol << " mm";
    throw ParseError(tp_.source, line, m.str());
  }
  const long n = std::max(1L, static_cast<long>(n_real));
  const double half = 0.5 * std::abs(sweep) / static_cast<double>(n);
  const double grow = half > 1e-9 ? half / std::sin(half) : 1.0;
  double f = feed;
  if (inverse_time) {
    // Length of the linearised move, so that it takes 1/F minutes.
    const double r = 0.5 * (r0 + r1);
    const double planar = std::abs(sweep) * r;
    const double along = end[ax.w] - start[ax.w];
    f = feed * std::hypot(planar, along);
  }
  for (long i = 1; i <= n; ++i) {
    AxisVector q{};
    if (i == n) {
      q = end;
    } else {
      const double k = static_cast<double>(i) / static_cast<double>(n);
      for (int a = 0; a < kAxes; ++a) q[a] = start[a] + k * (end[a] - start[a]);
      const double ang = a0 + k * sweep;
      const double r = (r0 + k * (r1 - r0)) * grow;
      q[ax.u] = cu + r * std::cos(ang);
      q[ax.v] = cv + r * std::sin(ang);
    }
    push(SegmentKind::Feed, line, q, f, 0.0);
  }
  pos_ = end;
}

void PathBuilder::dwell(int line, double seconds) { push(SegmentKind::Dwell, line, pos_, 0.0, seconds); }

void PathBuilder::tool_change(int line, int tool) {
  tool_ = tool;
  length_ = tool_length(tool);
  push(SegmentKind::ToolChange, line, pos_, 0.0, 0.0);
}

}  // namespace lbr::nc::detail

namespace lbr::nc {

void set_machine_frame(Toolpath& path, const GcodeOptions& options) {
  path.machine_origin = options.work_offsets[0];
  path.tool_lengths_mm = options.tool_lengths;
}

}  // namespace lbr::nc
