// path_builder.hpp (private) — canonical machining operations to Toolpath segments.
//
// Both G-code front ends (the built-in interpreter and the rs274 canonical stream) describe
// motion in program coordinates of the controlled point, as LinuxCNC's canonical interface
// does. The builder converts them to tool-tip positions in the Toolpath frame
// (docs/nc-frontend.md#frames) and linearises arcs. Allocates; throws ParseError.
#pragma once

#include <string>

#include "nc/gcode.hpp"
#include "nc/toolpath.hpp"

namespace lbr::nc::detail {

// Arc planes with their axes: u, v span the plane (counter-clockwise = from +u towards +v),
// w is the helix axis. G17: X Y (Z); G18: Z X (Y); G19: Y Z (X) — LinuxCNC's convention.
enum class Plane : unsigned char { XY, ZX, YZ };
struct PlaneAxes {
  int u, v, w;
};
[[nodiscard]] PlaneAxes plane_axes(Plane p) noexcept;

// G64 P in effect before the program sets one [mm] (0.001 inch).
inline constexpr double kPowerUpBlendTolMm = 0.0254;

// Spindle speed [rpm] for feed per revolution and spindle-synchronised moves (G95, G33, G33.1,
// G76): in G97 (css = false) the S word; in G96 the speed that gives the surface speed S
// [m/min, ft/min when mm_per_unit is 25.4] at radius |radius_mm|, capped by max_rpm (0: none).
// Returns +inf at the spindle axis without a cap.
[[nodiscard]] double spindle_rpm(double s, bool css, double max_rpm, double mm_per_unit, double radius_mm) noexcept;

// At most this many chords per arc; more is reported as an error (keeps runaway input bounded).
inline constexpr long kMaxArcChords = 1000000;

class PathBuilder {
 public:
  PathBuilder(const std::string& source, const GcodeOptions& options);

  // Frame of the program coordinates: machine gauge line = P + origin + (0, 0, tlo).
  void set_origin(const AxisVector& origin_machine) { origin_ = origin_machine; }
  void set_tool_length_offset(double tlo_mm) { tlo_ = tlo_mm; }
  [[nodiscard]] const AxisVector& origin() const { return origin_; }
  [[nodiscard]] double tool_length_offset() const { return tlo_; }
  // Program position of the controlled point (set by the front end when offsets change).
  void set_position(const AxisVector& p) { pos_ = p; }
  [[nodiscard]] const AxisVector& position() const { return pos_; }
  [[nodiscard]] int tool() const { return tool_; }
  [[nodiscard]] double tool_length(int tool) const;

  // Machine (gauge line) coordinates of a program position, and back.
  [[nodiscard]] AxisVector to_machine(const AxisVector& p) const;
  [[nodiscard]] AxisVector from_machine(const AxisVector& m) const;

  void rapid(int line, const AxisVector& end);
  // feed: [mm/min], or with inverse_time the F word [1/min] (the whole move takes 1/F min).
  void feed(int line, const AxisVector& end, double feed, bool inverse_time);
  // Arc from position() to end around centre (cu, cv) in plane p; rotation > 0 counter-clockwise,
  // < 0 clockwise, |rotation| - 1 extra full turns. The radius may change linearly (spiral).
  void arc(int line, Plane p, const AxisVector& end, double cu, double cv, int rotation, double feed,
           bool inverse_time);
  // Path control stamped on the segments that follow (G61 / G61.1 / G64 P Q).
  void set_path_control(PathControl c, double blend_tol_mm, double naive_tol_mm) {
    control_ = c, blend_tol_mm_ = blend_tol_mm, naive_tol_mm_ = naive_tol_mm;
  }
  // Spindle state stamped on the segments that follow (M3/M4/M5, S; docs/nc-frontend.md#spindle).
  void set_spindle(Spindle state, double s) { spindle_ = state, spindle_s_ = s; }
  void dwell(int line, double seconds);
  void tool_change(int line, int tool);

  [[nodiscard]] Toolpath take() { return std::move(tp_); }
  [[nodiscard]] const std::string& source() const { return tp_.source; }

 private:
  [[nodiscard]] AxisVector tip(const AxisVector& p) const;
  void push(SegmentKind k, int line, const AxisVector& end_program, double feed_mm_per_min, double dwell_s);

  const GcodeOptions& opt_;
  Toolpath tp_;
  AxisVector origin_{};
  double tlo_ = 0.0;
  AxisVector pos_{};
  int tool_ = 0;
  double length_ = 0.0;
  // Before any G61/G64 the program blends within 0.001 inch, as LinuxCNC's planner was
  // measured to do (docs/nc-frontend.md#planner); an explicit G64 without P has no P bound.
  PathControl control_ = PathControl::Blend;
  double blend_tol_mm_ = kPowerUpBlendTolMm, naive_tol_mm_ = 0.0;
  Spindle spindle_ = Spindle::Off;  // LinuxCNC powers up with M5 S0
  double spindle_s_ = 0.0;
};

}  // namespace lbr::nc::detail
