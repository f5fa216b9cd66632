// tools/feeders/feed_common.hpp — shared parts of the feeders: the sample stream of a
// program (nc machine emulator at live.period_ms, counts per the profile mapping) and
// seeded fault injection.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

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

// Options both feeders take; each adds its own transport options.
struct FeedOptions {
  std::string program, profile_path;
  double speed = 1.0;
  std::size_t max_samples = 0;
  int priority = 0;
  FaultPlan faults;
};

inline void add_feed_options(CLI::App& cli, FeedOptions& o, double min_speed, const char* speed_help) {
  cli.add_option("--program", o.program, "Move list (.moves) or G-code; default: the bundled demo");
  cli.add_option("--profile", o.profile_path, "Profile (period, [[live.axis]] mapping, [live.can]); default: built-in");
  cli.add_option("--speed", o.speed, speed_help)->check(CLI::Range(min_speed, 1000.0));
  cli.add_option("--corrupt-every", o.faults.corrupt_every, "Damage every Nth frame (serial: one flipped bit; CAN: wrong DLC)");
  cli.add_option("--drop-every", o.faults.drop_every, "Leave out every Nth frame (CAN: TPDO)");
  cli.add_option("--duplicate-every", o.faults.duplicate_every, "Send every Nth frame (CAN: TPDO) twice");
  cli.add_option("--seed", o.faults.seed, "Seed of the fault injection");
  cli.add_option("--max-samples", o.max_samples, "Stop after this many samples (0 = whole program)");
  cli.add_option("--priority", o.priority, "Run the sending loop SCHED_FIFO at this priority (0 = normal)")
      ->check(CLI::Range(0, 99));
}

// The profile and the (possibly shortened) sample stream of the options' program.
inline std::pair<app::Profile, Stream> load_feed(const FeedOptions& o) {
  app::Profile profile = o.profile_path.empty() ? app::default_profile() : app::load_profile(o.profile_path);
  Stream stream = make_stream(profile, o.program);
  if (o.max_samples > 0 && stream.counts.size() > o.max_samples) stream.counts.resize(o.max_samples);
  return {std::move(profile), std::move(stream)};
}

}  // namespace lbr::tools
