// nc/config.hpp — nc's part of a machine profile (docs/profiles.md): the emulator's rates and
// axis limits and the program frame from [machine], the G-code front ends' options from [nc].
// Read by nc/config_toml.hpp; app/ turns them into GcodeOptions and EmulatorLimits.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "nc/emulator.hpp"
#include "nc/gcode.hpp"  // Dialect

namespace lbr::nc {

// [machine]: rates, limits, sample period, G54 origin, diameter programming.
struct MachineConfig {
  static constexpr double kNoLimit = std::numeric_limits<double>::infinity();
  double rapid_mm_per_min = 15000.0;
  double tool_change_s = 0.0;
  std::array<double, 3> max_velocity_mm_per_min{0, 0, 0};  // per axis X Y Z; 0: the rapid rate
  std::array<double, 3> max_accel_mm_per_s2{1000, 1000, 1000};  // per axis X Y Z
  double max_feed_mm_per_min = 0.0;   // cap on programmed feeds; 0: none
  double sample_period_ms = 4.0;      // emulator sample period
  std::array<double, 3> g54_origin_mm{0, 0, 0};  // machine coordinates of the G54 origin
  bool diameter_programming = true;   // lathe kinds: X words are diameters (G7) at program start
  // Axis travel (soft limits) in machine coordinates of the spindle gauge line, X Y Z [mm] and
  // A B C [deg] (nc::machine_axes); unlimited by default. The over-travel check uses them.
  AxisVector travel_min{-kNoLimit, -kNoLimit, -kNoLimit, -kNoLimit, -kNoLimit, -kNoLimit};
  AxisVector travel_max{kNoLimit, kNoLimit, kNoLimit, kNoLimit, kNoLimit, kNoLimit};
};

// [nc]: the G-code front ends (docs/nc-frontend.md). A new [nc] key is a field here, read in
// nc/src/config_toml.cpp (read_nc) and passed on in app::gcode_options().
struct FrontEndConfig {
  std::vector<std::string> subroutine_path;  // searched for NAME.ngc after the program's folder
  int start_tool = 0;                        // tool in the spindle at program start (0: none)
  Dialect dialect = Dialect::Rs274ngc;       // program syntax of the built-in interpreter
};

// The emulator's limits from [machine] (X Y Z velocities of 0 take the rapid rate; the rotary
// axes keep EmulatorLimits' defaults).
[[nodiscard]] EmulatorLimits emulator_limits(const MachineConfig& m);

}  // namespace lbr::nc
