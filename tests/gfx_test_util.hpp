// Shared scene of the gfx tests: a 40 x 30 x 10 mm box (top at z = 0), Δ = 0.25 mm,
// 4 x 3 regions of 10 mm, and a rectangular pocket cut with a flat Ø6 mill.
#pragma once

#include <cmath>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "test_util.hpp"

namespace lbr::test::gfx_scene {

inline constexpr double kToolR = 3.0;
// Centre-line rectangle of the pocket raster; the pocket is this rectangle grown by kToolR
// with rounded corners.
inline constexpr double kPx0 = 12, kPy0 = 9, kPx1 = 28, kPy1 = 21;
inline constexpr double kFloorZ = -3.0;

inline geom::LbrSolid stock() { return geom::LbrSolid(box_spec({0, 0, -10}, {40, 30, 0}, 0.25, 4, 3)); }
inline geom::CutterShape flat6() { return geom::CutterShape::build(tool(geom::ToolKind::Flat, 6.0), 0.002); }
inline geom::CutterShape flat4() { return geom::CutterShape::build(tool(geom::ToolKind::Flat, 4.0), 0.002); }

// Zig-zag raster over the centre-line rectangle at the floor depth, stepover 2 mm.
inline std::vector<geom::Vec3> pocket_path() {
  std::vector<geom::Vec3> p{{kPx0, kPy0, 5}, {kPx0, kPy0, kFloorZ}};
  bool right = true;
  for (double y = kPy0; y <= kPy1 + 1e-9; y += 2.0) {
    p.push_back({right ? kPx0 : kPx1, y, kFloorZ});
    p.push_back({right ? kPx1 : kPx0, y, kFloorZ});
    right = !right;
  }
  p.push_back({p.back().x, p.back().y, 5});
  return p;
}

// Signed distance-like test: inside the pocket's outline (rounded rectangle)?
inline bool in_pocket(double x, double y, double grow = 0.0) {
  const double dx = std::max({kPx0 - x, 0.0, x - kPx1}), dy = std::max({kPy0 - y, 0.0, y - kPy1});
  return std::hypot(dx, dy) <= kToolR + grow;
}

}  // namespace lbr::test::gfx_scene
