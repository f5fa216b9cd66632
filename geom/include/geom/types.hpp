// geom/types.hpp — small value types shared by the kernel: 3D vectors, poses, boxes, paths.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <clipper.hpp>

#include "geom/units.hpp"

namespace lbr::geom {

// Integer polygon types are Clipper's own, so no copy is made at the clipping boundary.
using Point = ClipperLib::IntPoint;  // [units]
using Path = ClipperLib::Path;
using Paths = ClipperLib::Paths;

// Identifier of the move (tool path segment) that produced a sweep. 0 = stock / never cut.
using MoveId = std::uint32_t;

struct Vec3 {
  double x = 0, y = 0, z = 0;
  friend Vec3 operator+(Vec3 a, Vec3 b) noexcept { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec3 operator-(Vec3 a, Vec3 b) noexcept { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec3 operator*(double s, Vec3 a) noexcept { return {s * a.x, s * a.y, s * a.z}; }
  friend bool operator==(const Vec3&, const Vec3&) = default;
};
[[nodiscard]] inline double dot(Vec3 a, Vec3 b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
[[nodiscard]] inline Vec3 cross(Vec3 a, Vec3 b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
[[nodiscard]] inline double norm(Vec3 a) noexcept { return std::sqrt(dot(a, a)); }
[[nodiscard]] inline Vec3 lerp(Vec3 a, Vec3 b, double t) noexcept { return a + t * (b - a); }

// A tool pose in the workpiece frame: tip point [mm] and unit axis pointing from the tip
// into the holder (+Z for a 3-axis mill).
struct Pose {
  Vec3 tip;
  Vec3 axis{0, 0, 1};
};

// True when both poses' axes are exactly +Z: geom::Sweep's 3-axis (vertical) sweep.
[[nodiscard]] inline bool vertical_poses(const Pose& a, const Pose& b) noexcept {
  return a.axis.x == 0.0 && a.axis.y == 0.0 && a.axis.z > 0.0 && b.axis.x == 0.0 && b.axis.y == 0.0 && b.axis.z > 0.0;
}

// How far the tool at pose p lies from the sweep a→b (tip along the segment, axis
// normalized(lerp(a.axis, b.axis, t)), as geom::Sweep moves it) [mm]: at the parameter t where
// p's tip projects onto the segment, the tips' distance plus reach_mm times the angle between
// the axes. A rigid motion taking that sweep pose to p moves no tool point within reach_mm of
// the tip farther (a turn by the angle, then the tips' offset), so it bounds the distance of
// every cutting point of a rotationally symmetric tool. With a fixed axis it is the tip's
// distance from the segment. The test of the live stream's merged runs (motion::SampleStream).
[[nodiscard]] inline double pose_deviation_mm(const Pose& a, const Pose& b, const Pose& p, double reach_mm) noexcept {
  const Vec3 d = b.tip - a.tip;
  const double dd = dot(d, d);
  const double t = dd > 0 ? std::clamp(dot(p.tip - a.tip, d) / dd, 0.0, 1.0) : 0.0;
  const double off = norm(p.tip - lerp(a.tip, b.tip, t));
  if (a.axis == b.axis && p.axis == a.axis) return off;
  const Vec3 m = lerp(a.axis, b.axis, t);
  const double len = norm(m);
  if (!(len > 0.0)) return std::numeric_limits<double>::infinity();
  const double chord = norm(p.axis - (1.0 / len) * m);  // between unit vectors: 2 sin(angle / 2)
  return off + reach_mm * 2.0 * std::asin(std::min(1.0, 0.5 * chord));
}

// Axis-aligned box in mm.
struct Box3 {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity()};
  [[nodiscard]] bool empty() const noexcept { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  void add(Vec3 p) noexcept {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
};

// Axis-aligned rectangle in kernel units; empty when lo > hi.
struct Rect {
  Coord x0 = std::numeric_limits<Coord>::max(), y0 = std::numeric_limits<Coord>::max();
  Coord x1 = std::numeric_limits<Coord>::min(), y1 = std::numeric_limits<Coord>::min();
  [[nodiscard]] bool empty() const noexcept { return x0 > x1 || y0 > y1; }
  void add(Point p) noexcept {
    x0 = std::min(x0, p.X); y0 = std::min(y0, p.Y);
    x1 = std::max(x1, p.X); y1 = std::max(y1, p.Y);
  }
  void add(const Rect& r) noexcept {
    x0 = std::min(x0, r.x0); y0 = std::min(y0, r.y0);
    x1 = std::max(x1, r.x1); y1 = std::max(y1, r.y1);
  }
  [[nodiscard]] bool intersects(const Rect& r) const noexcept {
    return !empty() && !r.empty() && x0 <= r.x1 && r.x0 <= x1 && y0 <= r.y1 && r.y0 <= y1;
  }
  friend bool operator==(const Rect&, const Rect&) = default;
};

[[nodiscard]] inline Rect bounds_of(const Path& p) noexcept {
  Rect r;
  for (const Point& q : p) r.add(q);
  return r;
}

}  // namespace lbr::geom
