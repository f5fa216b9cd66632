// Live pipeline in process: profile keys of [live]/[[live.axis]]/[threads], the tool path
// sampler, and `run_live` on a generated candump log (the CAN path without AF_CAN) with
// injected faults, compared with the batch result.
#include <gtest/gtest.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "app/batch.hpp"
#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "hal/can_codec.hpp"
#include "hal/sample.hpp"
#include "nc/movelist.hpp"

using namespace lbr;

namespace {

// Live against batch: the stream's sweeps start and end at samples, batch's at the program's
// corners, so their sections' polygons put their vertices elsewhere, each within ±chord
// tolerance (0.01 mm in the built-in profile) of the exact wall. Measured at that tolerance:
// up to 5.4e-4 of the removed volume on these small parts (2.0e-4 on the straight line);
// 5e-4 and 2e-4 were the bounds at 1 µm.
constexpr double kLiveVsBatch = 1e-3;

std::string with_live(const std::string& extra) { return std::string(app::default_profile_text()) + "\n" + extra; }

const char* kShortProgram = R"(lbr-moves 1
start 10 10 5
tool 1
feed 6000
rapid 10 10 -2
line 60 10 -2
line 60 30 -3
line 20 30 -1
)";

// Runs `program` (a move list, written to TEMP/subdir/name) through the emulator source as
// fast as possible.
app::LiveResult run_emulated(const app::Profile& p, const std::string& program, const std::string& subdir,
                             const std::string& name) {
  const std::string dir = testing::TempDir() + "/" + subdir;
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/" + name;
  std::ofstream(file) << program;
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "emulator:" + file;
  o.speed = 0.0;
  return app::run_live(p, o, stop);
}

}  // namespace

TEST(LiveProfile, DefaultsAndMapping) {
  const app::Profile d = app::default_profile();
  ASSERT_EQ(d.live.axes.size(), 3u);
  EXPECT_EQ(d.live.axes[2].node, 3);
  EXPECT_DOUBLE_EQ(d.live.period_ms, 1.0);
  const app::Profile p = app::parse_profile(with_live(R"(
[live]
period_ms = 2.0
tool = 2
ring_capacity = 1024
[live.can]
sync_id = 0x081
late_ms = 1.5
[[live.axis]]
axis = "X"
node = 5
index = 1
scale = 0.0005
min = -1.0
max = 101.0
max_speed_per_min = 12000
[[live.axis]]
axis = "Z"
node = 6
index = 0
[threads]
hal_priority = 60
geometry_cpu = 1
lock_memory = false
)"), "t.toml");
  EXPECT_DOUBLE_EQ(p.live.period_ms, 2.0);
  EXPECT_EQ(p.live.tool, 2);
  EXPECT_EQ(p.live.ring_capacity, 1024u);
  EXPECT_EQ(p.live.can.sync_id, 0x081u);
  ASSERT_EQ(p.live.axes.size(), 2u);
  EXPECT_EQ(p.live.axes[0].node, 5);
  EXPECT_EQ(p.live.axes[0].index, 1);
  EXPECT_DOUBLE_EQ(p.live.axes[0].max_speed_per_s, 200.0);
  EXPECT_EQ(p.live.axes[1].axis, 2);
  EXPECT_EQ(p.live.hal_thread.priority, 60);
  EXPECT_EQ(p.live.geometry_thread.cpu, 1);
  EXPECT_FALSE(p.live.hal_thread.lock_memory);
}

TEST(LiveProfile, ErrorsNameLineAndKey) {
  auto msg = [](const std::string& extra) {
    try {
      (void)app::parse_profile(with_live(extra), "t.toml");
    } catch (const app::ProfileError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg("[live]\nperiod_mss = 1\n").find("live.period_mss: unknown key"), std::string::npos);
  EXPECT_NE(msg("[live.can]\nbogus = 1\n").find("live.can.bogus: unknown key"), std::string::npos);
  EXPECT_NE(msg("[[live.axis]]\naxis = \"Q\"\n").find("live.axis.axis"), std::string::npos);
  EXPECT_NE(msg("[[live.axis]]\naxis = \"X\"\n[[live.axis]]\naxis = \"X\"\nnode = 9\nindex = 4\n").find("mapped twice"),
            std::string::npos);
  EXPECT_NE(msg("[threads]\nhal_priority = 120\n").find("threads.hal_priority"), std::string::npos);
}

TEST(LiveRun, EmulatorWithToolChangesMatchesBatch) {
  // Two tools: the emulator source reports the tool number, so each part cuts with its tool.
  const app::Profile p = app::default_profile();
  const std::string program = std::string(kShortProgram) + "rapid 20 30 5\ntool 2\nrapid 30 60 5\nline 30 60 -2\nline 80 60 -2\nrapid 80 60 5\n";
  const app::LiveResult r = run_emulated(p, program, "lbr_live_emu", "two-tools.moves");
  const nc::Toolpath path = nc::parse_movelist(program, "two-tools");
  const app::BatchResult b = app::run_batch(p, path);
  EXPECT_EQ(r.samples_lost, 0u);
  EXPECT_EQ(r.samples_applied, r.samples_received);
  const nc::Emulator emu(path, app::live_emulator_limits(p));
  EXPECT_EQ(r.samples_received, emu.sample_count());
  EXPECT_NEAR(r.removed_volume_mm3, b.removed_volume_mm3, kLiveVsBatch * b.removed_volume_mm3);
  // With tool 1 only (live.tool, no tool numbers) the ball-nose groove would be a flat one.
  EXPECT_GT(b.removed_volume_mm3, 100.0);
}

TEST(LiveRun, AKernelPoolOnTheGeometryThreadMatchesBatch) {
  // [lbr] live_threads = 2 with a source at real time: the geometry thread makes the pool
  // when it starts and ends it when it ends; the part is the batch's
  // (tests/app_live_pool_test.cpp: byte for byte). As fast as possible: no pool.
  app::Profile p = app::default_profile();
  p.live_threads = 2;
  const std::string program = std::string(kShortProgram) + "rapid 20 30 5\ntool 2\nrapid 30 60 5\nline 30 60 -2\nline 80 60 -2\nrapid 80 60 5\n";
  const app::LiveResult fast = run_emulated(p, program, "lbr_live_pool", "pool.moves");
  EXPECT_EQ(fast.kernel_threads, 1);
  EXPECT_EQ(fast.kernel_calls_shared, 0u);
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "emulator:" + testing::TempDir() + "/lbr_live_pool/pool.moves";
  o.speed = 1.0;
  const app::LiveResult r = app::run_live(p, o, stop);
  const app::BatchResult b = app::run_batch(p, nc::parse_movelist(program, "pool"));
  cpu_set_t set;
  CPU_ZERO(&set);
  ASSERT_EQ(sched_getaffinity(0, sizeof(set), &set), 0);
  EXPECT_EQ(r.kernel_threads, std::min(2, CPU_COUNT(&set)));
  EXPECT_LE(r.kernel_calls_shared, r.kernel_calls);
  EXPECT_NEAR(fast.removed_volume_mm3, b.removed_volume_mm3, kLiveVsBatch * b.removed_volume_mm3);
  EXPECT_EQ(r.samples_lost, 0u);
  EXPECT_EQ(r.samples_applied, r.samples_received);
  EXPECT_GT(b.removed_volume_mm3, 100.0);
  EXPECT_NEAR(r.removed_volume_mm3, b.removed_volume_mm3, kLiveVsBatch * b.removed_volume_mm3);
}

TEST(LiveRun, TheLiveSolidHasTheLiveRegionGrid) {
  // [lbr] live_regions (the default profile: 16x16) for `lbrsim run`; without it, [lbr] regions.
  app::Profile p = app::default_profile();
  ASSERT_TRUE(p.live_grid.set);
  const app::LiveResult a = run_emulated(p, kShortProgram, "lbr_live_grid", "short.moves");
  EXPECT_EQ(a.solid.regions_x(), 16);
  EXPECT_EQ(a.solid.regions_y(), 16);
  p.live_grid.set = false;
  const app::LiveResult b = run_emulated(p, kShortProgram, "lbr_live_grid", "short.moves");
  EXPECT_EQ(b.solid.regions_x(), p.solid.regions_x);
  EXPECT_NEAR(a.removed_volume_mm3, b.removed_volume_mm3, 5e-4 * b.removed_volume_mm3);
}

TEST(LiveRun, APacedRunRecordsEachKernelCallAndTheSamplesItCompleted) {
  // A live (paced) source: calls sized by time; the kernel log holds every call, and the
  // samples whose lag was taken at the end of their own call add up to nearly all of them
  // (the rest: a channel's first sample, a pose, recorded at the end of the tick).
  const app::Profile p = app::default_profile();
  const std::string dir = testing::TempDir() + "/lbr_live_log";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/short.moves") << kShortProgram;
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "emulator:" + dir + "/short.moves";
  o.speed = 4.0;
  o.kernel_log_capacity = 100000;
  const app::LiveResult r = app::run_live(p, o, stop);
  EXPECT_EQ(r.samples_lost, 0u);
  EXPECT_EQ(r.samples_applied, r.samples_received);
  ASSERT_EQ(r.kernel_log.size(), r.kernel_calls);
  std::uint64_t completed = 0, sweeps = 0;
  std::int64_t t_prev = -1;
  for (const app::KernelCallRecord& k : r.kernel_log) {
    completed += k.samples;
    sweeps += k.sweeps;
    EXPECT_GT(k.sweeps, 0u);
    EXPECT_GT(k.t_ns, t_prev) << "calls in order";
    t_prev = k.t_ns;
  }
  EXPECT_EQ(sweeps, r.sweeps);
  EXPECT_LE(completed, r.samples_applied);
  EXPECT_GE(completed + 10, r.samples_applied);
}

TEST(LiveRun, StraightRunsMergeIntoOneSweepPerBatch) {
  // One straight cut: every chunk of samples (lbr.batch_moves in a non-live run) is
  // collinear, so each batch subtracts a single sweep, and the volume is the batch volume.
  // Chunks of 64 samples, as the test was written for (the default is larger).
  app::Profile p = app::default_profile();
  p.batch_moves = 64;
  const std::string program = "lbr-moves 1\nstart 5 20 5\ntool 1\nfeed 3000\nrapid 5 20 -2\nline 95 20 -2\n";
  const app::LiveResult r = run_emulated(p, program, "lbr_live_line", "line.moves");
  EXPECT_GT(r.samples_applied, 1500u);  // 90 mm at 50 mm/s plus the plunge
  EXPECT_LE(r.sweeps, r.batches + 2);    // + the corner at the plunge's end, within one batch
  EXPECT_LT(r.sweeps * 20, r.samples_applied);
  const app::BatchResult b = app::run_batch(p, nc::parse_movelist(program, "line"));
  EXPECT_NEAR(r.removed_volume_mm3, b.removed_volume_mm3, 0.5 * kLiveVsBatch * b.removed_volume_mm3);
}

TEST(LiveRun, CandumpReplayWithFaultsMatchesBatch) {
  const app::Profile p = app::default_profile();
  const nc::Toolpath path = nc::parse_movelist(kShortProgram, "short");
  const std::string dir = testing::TempDir() + "/lbr_live_can";
  std::filesystem::create_directories(dir);
  const std::string log = dir + "/bus.log";
  // Write the program as a CAN log: SYNC with counter, three TPDOs, 1 ms apart.
  std::uint64_t cycles = 0;
  {
    std::ofstream out(log);
    nc::Emulator emu(path, app::live_emulator_limits(p));
    nc::Sample smp;
    smp.axes = path.start;
    std::int64_t t = 1'700'000'000'000'000'000LL;
    int counter = 0;
    char line[128];
    auto put = [&](const hal::CanFrame& f) { out.write(line, static_cast<std::streamsize>(hal::format_candump_line(f, "vcan0", line))); };
    bool more = true;
    for (; more; more = emu.next(smp)) {
      const nc::AxisVector& q = smp.axes;
      ++cycles;
      hal::CanFrame sy;
      sy.id = 0x080;
      sy.len = 1;
      counter = counter % 240 + 1;
      sy.data[0] = static_cast<std::uint8_t>(counter);
      sy.t_ns = t;
      if (cycles == 500) continue;  // a lost SYNC: its TPDOs are not sent either → counter gap
      put(sy);
      for (int a = 0; a < 3; ++a) {
        hal::CanFrame f;
        f.id = 0x181 + static_cast<std::uint32_t>(a);
        f.len = 4;
        f.t_ns = t + 100'000 + a * 10'000;
        const auto u = static_cast<std::uint32_t>(std::llround(q[static_cast<std::size_t>(a)] * 1000.0));
        for (int i = 0; i < 4; ++i) f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(u >> (8 * i));
        if (cycles == 300 && a == 1) continue;  // missing TPDO
        put(f);
        if (cycles == 700 && a == 2) put(f);  // duplicate TPDO
      }
      t += 1'000'000;
    }
  }
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "replay:" + log;
  o.speed = 0.0;
  const app::LiveResult r = app::run_live(p, o, stop);
  EXPECT_EQ(r.decode_errors.at("missing_tpdo"), 1u);
  EXPECT_EQ(r.decode_errors.at("sequence_gap"), 1u);
  EXPECT_EQ(r.decode_errors.at("duplicate_tpdo"), 1u);
  EXPECT_EQ(r.samples_lost, 2u);  // the incomplete cycle and the skipped SYNC
  EXPECT_EQ(r.samples_received, cycles - 2);
  EXPECT_EQ(r.samples_applied, cycles - 2);
  EXPECT_EQ(r.ring_overruns, 0u);
  const app::BatchResult b = app::run_batch(p, path);
  EXPECT_GT(b.removed_volume_mm3, 1000.0);
  EXPECT_NEAR(r.removed_volume_mm3, b.removed_volume_mm3, kLiveVsBatch * b.removed_volume_mm3);
  const std::string json = app::live_metrics_json(r, p);
  for (const char* key : {"samples_received", "samples_applied", "samples_lost", "ring_overruns", "ring_high_water",
                          "decode_errors", "lag_p50_ms", "lag_p99_ms", "lag_max_ms", "removed_volume_mm3", "rt_mode"})
    EXPECT_NE(json.find(std::string("\"") + key + "\""), std::string::npos) << key;
}

TEST(LiveRun, StopFlagEndsAPacedRun) {
  app::Profile p = app::default_profile();
  // [lbr] regions for the live solid: the default live grid's 76 800 cells take seconds to
  // build under the sanitizers' Debug builds, which this test would time as the stop.
  p.live_grid.set = false;
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "emulator:demo";  // 5+ minutes in real time
  o.speed = 1.0;
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    stop = true;
  });
  const auto t0 = std::chrono::steady_clock::now();
  const app::LiveResult r = app::run_live(p, o, stop);
  stopper.join();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 2.0);
  EXPECT_GT(r.samples_applied, 100u);
  EXPECT_EQ(r.samples_applied, r.samples_received);
  EXPECT_EQ(r.ring_overruns, 0u);
}
