// Helpers shared by the nc tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "nc/gcode.hpp"
#include "nc/toolpath.hpp"

#ifndef LBR_SOURCE_DIR
#error "LBR_SOURCE_DIR must be defined by the build (tests/CMakeLists.txt)"
#endif

namespace lbr::test {

// A bundled part program (config/programs/NAME).
inline std::string program_file(const std::string& name) { return std::string(LBR_SOURCE_DIR) + "/config/programs/" + name; }

// Distance of p from the segment a–b in axis space (all nc::kAxes axes).
inline double axis_dist_to_segment(const nc::AxisVector& p, const nc::AxisVector& a, const nc::AxisVector& b) {
  double ab2 = 0, t = 0;
  for (int i = 0; i < nc::kAxes; ++i) {
    ab2 += (b[i] - a[i]) * (b[i] - a[i]);
    t += (p[i] - a[i]) * (b[i] - a[i]);
  }
  t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
  double d2 = 0;
  for (int i = 0; i < nc::kAxes; ++i) {
    const double q = a[i] + t * (b[i] - a[i]) - p[i];
    d2 += q * q;
  }
  return std::sqrt(d2);
}

// The built-in interpreter on a program text (named t.ngc in messages).
inline nc::Toolpath run(const std::string& text, nc::GcodeOptions o = {}) { return nc::interpret_gcode(text, "t.ngc", o); }

// The interpreter's error message for a program text, or "<no error>".
inline std::string error_of(const std::string& text, nc::GcodeOptions o = {}) {
  try {
    (void)nc::interpret_gcode(text, "t.ngc", o);
  } catch (const nc::ParseError& e) {
    return e.what();
  }
  return "<no error>";
}

}  // namespace lbr::test
