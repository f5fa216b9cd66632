#include "verify/config_toml.hpp"

namespace lbr::verify {

void read_checks(cfg::Table& checks, CheckConfig& out) {
  out.enabled = checks.boolean("enabled", out.enabled);
  out.tolerance_mm = checks.number("tolerance_mm", out.tolerance_mm, 0.0, 10.0, "mm");
  out.max_cutting_feed_mm_per_min =
      checks.number("max_cutting_feed_mm_per_min", out.max_cutting_feed_mm_per_min, 0.0, 1e6, "mm/min");
  out.max_ramp_angle_deg = checks.number("max_ramp_angle_deg", out.max_ramp_angle_deg, 0.0, 90.0, "deg");
  out.spindle_nose_diameter_mm =
      checks.number("spindle_nose_diameter_mm", out.spindle_nose_diameter_mm, 0.0, 2000.0, "mm");
  out.spindle_nose_length_mm = checks.number("spindle_nose_length_mm", out.spindle_nose_length_mm, 0.0, 5000.0, "mm");
}

}  // namespace lbr::verify
