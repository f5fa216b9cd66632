// hal/config.hpp — live-source settings, filled from the profile ([live], [[live.axis]],
// [threads]; docs/profiles.md). Plain values, validated by the profile parser.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sched/rt_thread.hpp"

namespace lbr::hal {

struct AxisMap {
  std::string name;             // for messages, e.g. "X"
  int channel = 0;              // 0 .. kMaxChannels-1
  int axis = 0;                 // 0..5 = X Y Z A B C
  int node = 0;                 // CAN node id 1..127 (TPDO COB-ID = tpdo_base + node)
  int index = 0;                // serial: position index in the frame, 0..15
  double scale = 0.001;         // [mm or deg per count]
  double offset = 0.0;          // [mm or deg], added after scaling
  double min = -1e6, max = 1e6; // travel limits [mm or deg]
  double max_speed_per_s = 0.0; // [mm/s or deg/s]; 0 = no jump check
};

struct CanConfig {
  std::uint32_t sync_id = 0x080;
  std::uint32_t tpdo_base = 0x180;
  int sync_counter_max = 240;      // SYNC counter runs 1..max, then 1 again
  double late_ms = 0.0;            // TPDO later than this after SYNC is late; 0 = 0.8 × period
  double reconnect_ms = 500.0;     // retry period after bus-off / interface down
  int bitrate = 500000;            // [bit/s] for setting up the interface (lbrsim-can@.service, docs/deployment.md)
};

struct SerialConfig {
  int baud = 115200;
  double reconnect_ms = 0.0;       // > 0: reopen the device this often after a hang-up; 0 = the run ends
};

struct LiveConfig {
  double period_ms = 1.0;          // nominal sample period of the sender
  std::vector<AxisMap> axes;       // empty = X,Y,Z on channel 0, nodes 1..3, indices 0..2
  double jump_tolerance = 1.5;     // allowed step = max_speed × Δt × tolerance + 2 counts
  int tool = 1;                    // tool in the spindle (samples carry no tool number)
  double merge_tolerance_mm = 0.001;  // samples within this of a straight sweep extend it
  double snapshot_s = 5.0;         // power-loss snapshot period [s]; 0: none (docs/snapshot.md)
  std::size_t ring_capacity = 4096;
  int geometry_idle_us = 1000;     // geometry thread looks at an empty ring again after this [µs]
  double geometry_duty = 0.7;      // most of the time the geometry thread may work (see live.cpp)
  CanConfig can;
  SerialConfig serial;
  sched::RtConfig hal_thread{"lbr-hal", 80, -1, true};
  sched::RtConfig geometry_thread{"lbr-geom", 70, -1, true};
};

// The mapping used when the profile has none: X, Y, Z on channel 0, 1 µm counts.
[[nodiscard]] std::vector<AxisMap> default_axes();

}  // namespace lbr::hal
