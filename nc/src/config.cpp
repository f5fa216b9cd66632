#include "nc/config.hpp"

namespace lbr::nc {

EmulatorLimits emulator_limits(const MachineConfig& m) {
  EmulatorLimits l;
  l.rapid_mm_per_min = m.rapid_mm_per_min;
  l.max_feed_mm_per_min = m.max_feed_mm_per_min;
  for (std::size_t a = 0; a < 3; ++a) {
    l.max_velocity[a] = m.max_velocity_mm_per_min[a] > 0 ? m.max_velocity_mm_per_min[a] : m.rapid_mm_per_min;
    l.max_accel[a] = m.max_accel_mm_per_s2[a];
  }
  l.sample_period_ms = m.sample_period_ms;
  l.tool_change_s = m.tool_change_s;
  return l;
}

}  // namespace lbr::nc
