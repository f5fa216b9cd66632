// geom/probe.hpp — questions about the stock at a point, answered exactly from the level
// polygons (the operator UI's Measure tool, docs/ui.md): the material on the vertical through
// an XY point, and the first point where a ray meets the material.
//
// Const queries on a solid (geom/lbr_solid.hpp threading rules: not beside a change). No
// allocation, no exceptions, no locks; the cost is the levels the ray crosses times the
// contours of the cells it passes over (a tap, not a per-frame call).
#pragma once

#include <limits>

#include "geom/lbr_solid.hpp"

namespace lbr::geom {

// The material on the vertical through (x, y) [mm].
struct Column {
  bool material = false;    // some level holds material at (x, y)
  double top_mm = 0;        // top of the highest slab holding material there (surface Z)
  double thickness_mm = 0;  // material along the vertical, at or below z_max [mm]
};
// A level holds material at a point on its polygons' boundary too (closed sets).
[[nodiscard]] Column column_at(const LbrSolid& s, double x_mm, double y_mm,
                               double z_max_mm = std::numeric_limits<double>::infinity()) noexcept;

// Whether level `level` holds material at (x, y) [mm] (boundary included).
[[nodiscard]] bool material_at(const LbrSolid& s, int level, double x_mm, double y_mm) noexcept;

struct RayHit {
  bool hit = false;
  double t = 0;      // ray parameter of the hit
  Vec3 point;        // origin + t · dir [mm]
  int level = -1;    // the level whose slab holds the hit
  bool top_face = false;  // the ray entered the slab through its top (a horizontal face)
};
// First point of the ray origin + t · dir, t in [t_min, t_max], that lies in the material
// (the slabs × their level polygons). dir need not be unit length.
[[nodiscard]] RayHit cast_ray(const LbrSolid& s, const Vec3& origin, const Vec3& dir, double t_min = 0,
                              double t_max = std::numeric_limits<double>::infinity()) noexcept;

}  // namespace lbr::geom
