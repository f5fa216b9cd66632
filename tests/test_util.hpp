// Helpers shared by the kernel tests: stock, tools and single cuts in a line.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::test {

inline constexpr double kPi = std::numbers::pi;

inline geom::SolidSpec box_spec(geom::Vec3 lo, geom::Vec3 hi, double delta, int nx = 4, int ny = 4) {
  geom::SolidSpec s;
  s.shape = geom::SolidSpec::Shape::Box;
  s.box = {lo, hi};
  s.level_spacing_mm = delta;
  s.regions_x = nx;
  s.regions_y = ny;
  return s;
}

inline geom::Tool tool(geom::ToolKind k, double d, double param = 0.0, double flute = 30.0) {
  geom::Tool t;
  t.kind = k;
  t.diameter_mm = d;
  t.flute_length_mm = flute;
  t.length_mm = flute + 10.0;
  if (k == geom::ToolKind::Bull) t.corner_radius_mm = param;
  if (k == geom::ToolKind::Drill || k == geom::ToolKind::VBit) t.angle_deg = param;
  return t;
}

inline geom::Pose at(double x, double y, double z, geom::Vec3 axis = {0, 0, 1}) { return {{x, y, z}, axis}; }

// Cuts one straight move.
inline geom::SubtractStats cut(geom::LbrSolid& s, const geom::CutterShape& c, geom::Pose a, geom::Pose b, geom::MoveId id = 1) {
  const geom::SweepRef r{&c, a, b, id};
  return s.subtract(std::span<const geom::SweepRef>(&r, 1));
}

// Cuts a polyline of tip positions as consecutive moves, in batches of `batch`.
inline void cut_path(geom::LbrSolid& s, const geom::CutterShape& c, const std::vector<geom::Vec3>& pts, int batch = 16,
                     geom::MoveId first_id = 1) {
  std::vector<geom::SweepRef> b;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    b.push_back({&c, {pts[i - 1], {0, 0, 1}}, {pts[i], {0, 0, 1}}, static_cast<geom::MoveId>(first_id + i - 1)});
    if (static_cast<int>(b.size()) == batch) {
      s.subtract(b);
      b.clear();
    }
  }
  if (!b.empty()) s.subtract(b);
}

inline double removed(const geom::LbrSolid& s) { return s.initial_volume_mm3() - s.volume_mm3(); }

// Pocket 30 x 20 (x 15..45, y 10..30), depth 4, for a Ø6 flat: tool centre inside
// [18, 42] x [13, 27], zig-zag at 2.5 mm stepover from (18, 13, -4), then the finishing
// loop; appended to `p`. Removed volume: kPocketVolume.
inline void append_pocket_path(std::vector<geom::Vec3>& p) {
  bool right = true;
  for (double y = 13; y <= 27 + 1e-9; y += 2.5) {
    const double yy = std::min(y, 27.0);
    p.push_back({right ? 18.0 : 42.0, yy, -4});
    p.push_back({right ? 42.0 : 18.0, yy, -4});
    right = !right;
  }
  for (const geom::Vec3& q : {geom::Vec3{42, 27, -4}, {42, 13, -4}, {18, 13, -4}, {18, 27, -4}, {42, 27, -4}}) p.push_back(q);
}
inline constexpr double kPocketVolume = (30.0 * 20.0 - (4.0 - kPi) * 9.0) * 4.0;

// Helix around (cx, cy) with radius rho from z0, `turns` turns of `pitch` downwards, then one
// flat turn at the bottom; `per_turn` chords per turn.
inline std::vector<geom::Vec3> helix(double cx, double cy, double rho, double z0, double pitch, int turns, int per_turn) {
  std::vector<geom::Vec3> p;
  const int n = (turns + 1) * per_turn;
  for (int i = 0; i <= n; ++i) {
    const double a = 2.0 * kPi * i / per_turn;
    const double z = z0 - pitch * std::min(static_cast<double>(i) / per_turn, static_cast<double>(turns));
    p.push_back({cx + rho * std::cos(a), cy + rho * std::sin(a), z});
  }
  return p;
}

}  // namespace lbr::test
