// geom/turning.hpp — lathe tools (insert profiles) and the sweep of a turning move.
//
// On a lathe the workpiece rotates about the workpiece-frame Z axis (the spindle axis), so
// the levels are discs perpendicular to it. A turning tool is a flat insert in the (r, z)
// half-plane; the region it sweeps in the rotating part is its profile revolved about Z.
// On level z a turning move therefore removes {r >= r_min(z)} (external tools: turning,
// facing, grooving, parting) or {r <= r_max(z)} (internal tools: boring), where r_min/r_max
// is the smallest/largest radius the insert reaches at height z during the move. The insert
// and its holder are assumed to reach out of the stock radially (external) or along the axis
// (internal), as real holders do; docs/machine-kinds.md.
//
// Reference point (the "imaginary tool tip", ISO tip orientation): the programmed X/Z is
// the corner of the insert's bounding box nearest the axis and the chuck, i.e. the insert
// lies in r >= 0, z >= 0 of its own frame and touches r = 0 and z = 0 (external), or in
// r <= 0, z >= 0 touching both axes (internal). So X30 with any external insert turns a
// diameter of exactly 30, and a grooving insert's reference is its corner towards -Z.
#pragma once

#include <string>
#include <vector>

#include "geom/types.hpp"

namespace lbr::geom {

enum class InsertKind {
  Diamond80,  // C-type rhombus, 80° nose (roughing, facing)
  Diamond55,  // D-type rhombus, 55° nose (profiling)
  V35,        // V-type rhombus, 35° nose (fine profiling)
  Groove,     // grooving / parting blade: rectangle of width_mm, cutting at its -r end
};

[[nodiscard]] const char* to_string(InsertKind k) noexcept;
// Parses "diamond80", "diamond55", "v35", "groove"; false on anything else.
[[nodiscard]] bool parse_insert_kind(const std::string& s, InsertKind& out) noexcept;

struct TurningTool {
  InsertKind insert = InsertKind::Diamond80;
  bool internal = false;          // boring bar: mirrored insert, removes the inside
  double nose_radius_mm = 0.4;    // corner radius of the cutting corner(s) [mm]
  double edge_length_mm = 12.0;   // rhombus edge length / grooving blade length (depth) [mm]
  double width_mm = 3.0;          // grooving blade width [mm] (Groove only)
  // Angle between the main cutting edge and the feed direction -Z [deg]. 90 puts the main
  // edge square to the spindle axis; a 95° holder lets the tool square a shoulder with 5°
  // clearance. The nose angle plus approach - 90 must not exceed 90 (the trailing edge
  // must not face -r). Rhombus inserts only.
  double approach_deg = 95.0;
  // The holder (shank, blade holder or boring bar; collision checks only, never cuts): in
  // the (r, z) plane a bar from `holder_z_mm` to `holder_z_mm + holder_width_mm` along +Z
  // from the reference point, and from `holder_r_mm` outwards from it (internal tools: from
  // `holder_r_mm` inwards, towards the axis), reaching out of the stock as the insert's own
  // region does. holder_width_mm 0: no holder (docs/verification.md).
  double holder_width_mm = 0.0;
  double holder_z_mm = 0.0;
  double holder_r_mm = 0.0;

  // "" when valid, else what is wrong.
  [[nodiscard]] std::string validate() const;
};

// The insert as a convex polygon in its (r, z) frame [mm], counter-clockwise, reference
// point at the origin. Nose radii are polygonised with every vertex within the chord
// tolerance of the arc. Built once per tool at setup (allocates).
struct TurningShape {
  struct P2 {
    double r, z;
  };
  TurningTool tool;
  std::vector<P2> pts;
  double chord_tol_mm = 0.001;
  double z_extent = 0.0;  // height of the insert along Z [mm]

  static TurningShape build(const TurningTool& tool, double chord_tol_mm);
  // The holder of `tool` (tool.holder_width_mm > 0) as a shape of its own: a rectangle
  // holder_width_mm along Z that reaches 1 m out (in, internal tools) from its reference
  // point, the holder's corner nearest the insert's reference point. Sweep it with
  // LatheSweep from the insert's reference point moved by holder_offset(). Allocates.
  static TurningShape holder(const TurningTool& tool, double chord_tol_mm);
  // (dr, dz) from the insert's reference point to the holder's [mm].
  [[nodiscard]] static P2 holder_offset(const TurningTool& tool) noexcept;
};

// A turning move: the insert reference point goes from (r0, z0) to (r1, z1) in the (r, z)
// plane; r may be negative (past the spindle axis). Does not allocate; real-time safe.
class LatheSweep {
 public:
  LatheSweep(const TurningShape& shape, double r0_mm, double z0_mm, double r1_mm, double z1_mm) noexcept;

  [[nodiscard]] double z_min() const noexcept { return zlo_; }
  [[nodiscard]] double z_max() const noexcept { return zhi_; }
  [[nodiscard]] bool internal() const noexcept { return shape_->tool.internal; }

  // Radial extent [r_lo, r_hi] of the swept profile on plane z; false when the plane misses
  // the sweep. Exact for the polygonal insert (Minkowski sum of a convex polygon and a segment).
  bool interval(double z_mm, double& r_lo, double& r_hi) const noexcept;

  // Appends the removed region on plane z (kernel units) to `out`: for an external tool a
  // counter-clockwise square covering `extent` with a clockwise circle of radius r_min as a
  // hole (non-zero fill), or the square alone when r_min <= 0; for an internal tool a
  // counter-clockwise circle of radius r_max. Circles are polygonised like tool sections
  // (boundary within ±tol/2). Returns the number of paths appended.
  std::size_t section(double z_mm, const Rect& extent, Paths& out) const;
  // The same region for a given radius: external (r_min, `internal` false) or internal
  // (r_max). Used to emit one region for many turning moves on a level: the union of
  // {r >= r_i} is {r >= min r_i}, of {r <= r_i} it is {r <= max r_i}.
  static std::size_t removed_region(double r_mm, bool internal, double chord_tol_mm, const Rect& extent, Paths& out);
  // The ring {r_in <= r <= r_out} on a level: a counter-clockwise circle of radius r_out (a
  // square covering `extent` when r_out is infinite) with a clockwise circle of radius r_in
  // as a hole (none when r_in <= 0); nothing when the ring is empty or, r_out infinite, the
  // hole holds the whole extent. removed_region() is ring(r, inf) (external) or ring(0, r)
  // (internal). Circles as in section(). Returns the number of paths appended.
  static std::size_t ring(double r_in_mm, double r_out_mm, double chord_tol_mm, const Rect& extent, Paths& out);
  [[nodiscard]] double chord_tol_mm() const noexcept { return shape_->chord_tol_mm; }

 private:
  const TurningShape* shape_;
  double r0_, z0_, dr_, dz_;
  double zlo_, zhi_;
};

}  // namespace lbr::geom
