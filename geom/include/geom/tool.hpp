// geom/tool.hpp — milling tools as solids of revolution about their axis.
//
// A tool is described from its tip upwards: the cutting profile r(h) gives the radius at
// height h above the tip for 0 <= h <= flute_length. Every supported profile is concave
// and non-decreasing in h, so the cutting part is a convex solid; the kernel relies on this
// (the sweep of a convex solid along a straight line is convex). Shank and holder are
// non-cutting parts, kept for collision checks; they never remove material.
#pragma once

#include <string>
#include <vector>

namespace lbr::geom {

enum class ToolKind {
  Flat,   // flat end mill
  Ball,   // ball end mill, corner radius = diameter/2
  Bull,   // bull-nose / torus mill, corner radius given
  Drill,  // twist drill: cone tip with point angle (118° typical)
  VBit,   // chamfer / engraving V-bit: cone with included angle up to the full diameter
};

[[nodiscard]] const char* to_string(ToolKind k) noexcept;
// Parses "flat", "ball", "bull", "drill", "vbit"; returns false on anything else.
[[nodiscard]] bool parse_tool_kind(const std::string& s, ToolKind& out) noexcept;

struct Tool {
  ToolKind kind = ToolKind::Flat;
  double diameter_mm = 10.0;
  double corner_radius_mm = 0.0;  // Bull only (Ball: implied diameter/2)
  double angle_deg = 118.0;       // Drill: point angle; VBit: included angle
  double flute_length_mm = 30.0;  // cutting length from the tip
  double length_mm = 60.0;        // gauge length: tip to holder face (non-cutting above flutes)
  double shank_diameter_mm = 0.0; // 0 = same as diameter
  double holder_diameter_mm = 40.0;
  double holder_length_mm = 40.0;
  bool centre_cutting = true;     // false: the end face does not cut at the centre (no plunging; process checks)

  // Empty string when the tool is valid, otherwise what is wrong (e.g.
  // "corner_radius_mm must be in (0, diameter/2]").
  [[nodiscard]] std::string validate() const;
  // Exact cutting radius [mm] at height h [mm] above the tip; 0 outside [0, flute_length].
  [[nodiscard]] double radius_at(double h_mm) const noexcept;
  // Height [mm] above the tip where the profile reaches the full radius.
  [[nodiscard]] double full_radius_height() const noexcept;
};

// Piecewise-linear cutting profile that never deviates from the exact profile by more than
// the chord tolerance, on either side: the corner arc's polyline keeps the arc's area, so the
// profile is not biased inwards or outwards (docs/lbr-conventions.md, "Tolerances"); its
// radius never exceeds the tool's radius. Built once
// per tool at setup (allocates); read-only afterwards.
struct CutterShape {
  struct Station {
    double h;  // [mm] above the tip
    double r;  // [mm]
  };
  Tool tool;
  std::vector<Station> stations;  // strictly increasing h, from 0 to flute_length
  double chord_tol_mm = 0.001;
  // > 0 for a ball end mill whose flutes reach the ball's equator and whose shank is no
  // thinner than the head: its radius. Tilted sweeps then take the cutting part as the
  // capsule around the axis from the ball's centre to the top of the flutes (exact but for
  // the flutes' flat top, which becomes a hemisphere inside the shank; geom/src/sweep.cpp).
  double capsule_radius_mm = 0.0;
  // > 0 for a bull-nose mill whose flutes reach above its corner and whose shank is no
  // thinner than the head: the radius of its flat end (diameter/2 − corner radius). Tilted
  // sweeps then take the cutting part as the points within the corner radius
  // (capsule_radius_mm) of a disk of this radius normal to the axis, swept along the axis
  // from the corner's centre to the top of the flutes: the flat end, the torus and the
  // flutes' cylinder exactly, the flutes' top rounded inside the shank.
  double core_radius_mm = 0.0;

  static CutterShape build(const Tool& tool, double chord_tol_mm);
  [[nodiscard]] double radius() const noexcept { return 0.5 * tool.diameter_mm; }
  [[nodiscard]] double height() const noexcept { return stations.back().h; }
  // Radius of the linear profile at h [mm]; 0 outside [0, height()].
  [[nodiscard]] double radius_at(double h_mm) const noexcept;
};

}  // namespace lbr::geom
