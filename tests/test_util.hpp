// Helpers shared by the kernel tests: stock, tools and single cuts in a line.
#pragma once

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

}  // namespace lbr::test
