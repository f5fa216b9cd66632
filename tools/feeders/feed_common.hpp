// tools/feeders/feed_common.hpp — shared parts of the feeders: the sample stream of a
// program (nc machine emulator at live.period_ms, counts per the profile mapping) and
// seeded fault injection.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "hal/config.hpp"

namespace lbr::tools {

struct FaultPlan {
  int corrupt_every = 0;    // flip one bit in every Nth frame (serial: CRC error; CAN: DLC error)
  int garbage_every = 0;    // serial: random garbage bytes before every Nth frame
  int truncate_every = 0;   // serial: cut every Nth frame short
  int drop_every = 0;       // leave out every Nth frame (CAN: one TPDO)
  int duplicate_every = 0;  // send every Nth frame twice
  std::uint64_t seed = 1;
  [[nodiscard]] static bool hit(int every, std::uint64_t k) { return every > 0 && k % static_cast<std::uint64_t>(every) == static_cast<std::uint64_t>(every) - 1; }
};

// All samples of a program as counts per axis mapping entry.
struct Stream {
  std::vector<std::vector<std::int32_t>> counts;  // [sample][mapping entry]
  double period_s = 0.001;
};

inline std::int32_t to_counts(const hal::AxisMap& m, double v) {
  return static_cast<std::int32_t>(std::llround((v - m.offset) / m.scale));
}

inline Stream make_stream(const app::Profile& profile, const std::string& program) {
  nc::Toolpath path = program.empty() || program == "demo" ? app::demo_toolpath() : app::load_toolpath(program, profile);
  nc::Emulator emu(path, app::live_emulator_limits(profile));
  Stream s;
  s.period_s = profile.live.period_ms * 1e-3;
  // The first sample: the machine at its start position, before it moves.
  nc::Sample smp;
  smp.axes = path.start;
  do {
    std::vector<std::int32_t> row;
    for (const hal::AxisMap& m : profile.live.axes) row.push_back(to_counts(m, smp.axes[static_cast<std::size_t>(m.axis)]));
    s.counts.push_back(std::move(row));
  } while (emu.next(smp));
  return s;
}

}  // namespace lbr::tools
