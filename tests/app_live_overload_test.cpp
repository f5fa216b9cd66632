// Live overload (issue 13 item 4b): with a deliberately slowed kernel the geometry thread
// falls behind a live (paced) source; nothing may be lost, the HAL side folds collinear
// samples (samples_coalesced > 0) and the final part equals an unslowed run. A stop request
// in the middle of a long batch ends the run within a second with the results written.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "app/live.hpp"
#include "app/profile.hpp"

using namespace lbr;

namespace {

// Straight passes (they fold) and a polygonal circle of 0.3 mm edges (corners every three
// samples: mostly not foldable) — 1 kHz samples at 100 mm/s are 0.1 mm apart.
std::string program() {
  std::ostringstream o;
  o << "lbr-moves 1\nstart 10 10 5\ntool 1\nfeed 6000\nrapid 10 10 -2\n";
  for (int pass = 0; pass < 4; ++pass) {
    const double y = 10.0 + 6.0 * pass;
    o << "line " << (pass % 2 ? 10 : 80) << " " << y << " -2\nline " << (pass % 2 ? 10 : 80) << " " << y + 6.0
      << " -2\n";
  }
  const double cx = 50, cy = 60, r = 15;
  const int n = static_cast<int>(2 * M_PI * r / 0.3);
  o << "line " << cx + r << " " << cy << " -2\n";
  for (int i = 1; i <= n; ++i)
    o << "line " << cx + r * std::cos(2 * M_PI * i / n) << " " << cy + r * std::sin(2 * M_PI * i / n) << " -3\n";
  o << "rapid " << cx + r << " " << cy << " 5\n";
  return o.str();
}

std::string write_program(const std::string& subdir) {
  const std::string dir = testing::TempDir() + "/" + subdir;
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/overload.moves";
  std::ofstream(file) << program();
  return file;
}

TEST(LiveOverload, SlowedKernelLosesNothingAndCutsTheSamePart) {
  app::Profile p = app::default_profile();
  const std::string file = write_program("lbr_live_overload");
  std::atomic<bool> stop{false};
  app::LiveOptions ref;
  ref.source = "emulator:" + file;
  ref.speed = 0.0;  // unslowed reference: as fast as possible, every sample applied
  const app::LiveResult a = app::run_live(p, ref, stop);
  ASSERT_EQ(a.samples_lost, 0u);
  ASSERT_GT(a.removed_volume_mm3, 1000.0);

  p.live.ring_capacity = 64;  // a tiny ring ...
  app::LiveOptions slow = ref;
  slow.speed = 4.0;  // ... a paced (live) source: the HAL thread never waits ...
  slow.test_kernel_delay_ns = 25'000'000;  // ... and a kernel 25 ms slower per call
  const app::LiveResult b = app::run_live(p, slow, stop);
  std::printf("slowed: received %llu applied %llu coalesced %llu lost %llu overflow hw %llu/%llu ring hw %llu/%llu "
              "lag p50 %.1f p99 %.1f max %.1f ms, kernel calls %llu; volume %.3f vs %.3f mm3 (%.2e)\n",
              static_cast<unsigned long long>(b.samples_received), static_cast<unsigned long long>(b.samples_applied),
              static_cast<unsigned long long>(b.samples_coalesced), static_cast<unsigned long long>(b.samples_lost),
              static_cast<unsigned long long>(b.overflow_high_water), static_cast<unsigned long long>(b.overflow_capacity),
              static_cast<unsigned long long>(b.ring_high_water), static_cast<unsigned long long>(b.ring_capacity),
              b.lag_p50_ms, b.lag_p99_ms, b.lag_max_ms, static_cast<unsigned long long>(b.kernel_calls),
              b.removed_volume_mm3, a.removed_volume_mm3,
              (b.removed_volume_mm3 - a.removed_volume_mm3) / a.removed_volume_mm3);
  RecordProperty("samples_coalesced", static_cast<int>(b.samples_coalesced));
  RecordProperty("lag_p99_ms", std::to_string(b.lag_p99_ms));
  EXPECT_EQ(b.samples_lost, 0u);
  EXPECT_EQ(b.ring_overruns, 0u);
  EXPECT_EQ(b.overflow_overruns, 0u);
  EXPECT_EQ(b.samples_unapplied, 0u);
  EXPECT_EQ(b.samples_received, a.samples_received);
  EXPECT_EQ(b.samples_applied, b.samples_received) << "coalesced samples count as applied";
  EXPECT_GT(b.samples_coalesced, 0u) << "the geometry thread never fell behind: slow it more";
  EXPECT_GT(b.overflow_high_water, 0u);
  EXPECT_GT(b.lag_max_ms, 50.0) << "behind means lag";
  // Folding moves no sample by more than merge_tolerance / 2 = 0.5 µm: the volumes agree to
  // what different batch boundaries give (the existing live-vs-batch tests use 5e-4).
  EXPECT_NEAR(b.removed_volume_mm3, a.removed_volume_mm3, 5e-4 * a.removed_volume_mm3);
}

TEST(LiveOverload, StopMidBatchReturnsWithinASecondWithResults) {
  app::Profile p = app::default_profile();
  // [lbr] regions for the live solid: the default live grid's 76 800 cells take seconds to
  // build and write under the sanitizers' Debug builds, which this test would time as the stop.
  p.live_grid.set = false;
  std::atomic<bool> stop{false};
  app::LiveOptions o;
  o.source = "emulator:demo";
  o.speed = 0.0;                          // replay as fast as possible: full batches
  o.test_work_budget = 1.0;               // every sweep its own kernel call, cut into pieces
  o.test_kernel_delay_ns = 40'000'000;    // 40 ms per call: one batch takes minutes
  const std::string out = testing::TempDir() + "/lbr_live_stop";
  std::filesystem::remove_all(out);
  std::chrono::steady_clock::time_point t_stop;
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    t_stop = std::chrono::steady_clock::now();
    stop = true;
  });
  const app::LiveResult r = app::run_live(p, o, stop);
  app::write_live_outputs(out, r, p);
  const auto t_done = std::chrono::steady_clock::now();
  stopper.join();
  const double s = std::chrono::duration<double>(t_done - t_stop).count();
  std::printf("stop: returned with results written %.0f ms after the request (geometry %.0f ms); applied %llu, "
              "unapplied %llu, kernel calls %llu, split %llu, kernel call p50 %.1f max %.1f ms\n",
              s * 1e3, r.stop_latency_ms, static_cast<unsigned long long>(r.samples_applied),
              static_cast<unsigned long long>(r.samples_unapplied), static_cast<unsigned long long>(r.kernel_calls),
              static_cast<unsigned long long>(r.sweeps_split), r.batch_p50_ms, r.batch_max_ms);
  RecordProperty("stop_latency_ms", std::to_string(s * 1e3));
  EXPECT_LT(s, 1.0);
  EXPECT_GT(r.samples_unapplied, 0u) << "the stop did not come mid-batch";
  EXPECT_GT(r.sweeps_split, 0u);
  EXPECT_EQ(r.samples_lost, 0u);
  EXPECT_GT(r.stop_latency_ms, 0.0);
  EXPECT_LT(r.stop_latency_ms, 1000.0);
  EXPECT_TRUE(std::filesystem::exists(out + "/metrics.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/levels.lbrs"));
  EXPECT_GT(std::filesystem::file_size(out + "/levels.lbrs"), 0u);
}

}  // namespace
