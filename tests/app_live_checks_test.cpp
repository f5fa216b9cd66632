// Live collision checks (issue 16, docs/verification.md#live): the motion stream's speed
// classes, rapids into material with their volume and sample numbers, and the real-time
// contract of the checks on the geometry thread. Default profile: box 100 x 80 x 30 (top at
// Z0), T1 flat D10, live period 1 ms, no [machine] max_feed_mm_per_min, so a stream faster
// than half the rapid rate (7500 mm/min = 0.125 mm a sample) is a rapid.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "alloc_counter.hpp"
#include "app/profile.hpp"
#include "live/checks.hpp"
#include "live/geometry.hpp"
#include "motion/sample_stream.hpp"

namespace {

using namespace lbr;

hal::AxisSample sample(std::uint64_t seq, double x, double y, double z, int tool = 1) {
  hal::AxisSample s;
  s.seq = seq;
  s.t_rx_ns = static_cast<std::int64_t>(seq) * 1'000'000;
  s.mask = 0x3F;
  s.tool = static_cast<decltype(s.tool)>(tool);
  s.q = {x, y, z, 0, 0, 0};
  return s;
}

struct Rig {
  app::Profile profile;
  geom::LbrSolid solid{profile.solid};
  motion::ToolTable tools{profile.tooling, profile.solid.chord_tol_mm, profile.source};
  sched::SpscRing<hal::AxisSample> ring{4096};
  std::unique_ptr<app::live::Geometry> geo;
  std::unique_ptr<app::live::LiveChecks> checks;
  std::uint64_t seq = 1;
  explicit Rig(app::Profile p = app::default_profile()) : profile(std::move(p)) {
    tools.build_all();
    geo = std::make_unique<app::live::Geometry>(solid, profile, tools, 1, ring, 0.001);
    checks = std::make_unique<app::live::LiveChecks>(profile, tools, app::live::Geometry::batch_capacity(4096),
                                                     app::live::ProgramLines{});
    geo->set_checks(checks.get());
  }
  // A straight pass along X at (y, z) from x0, `n` samples `step_mm` apart, then one tick.
  std::size_t pass(double x0, double y, double z, int n, double step_mm) {
    for (int i = 0; i < n; ++i) (void)ring.try_push(sample(seq++, x0 + step_mm * i, y, z));
    return geo->tick(4096);
  }
};

TEST(LiveChecks, TheThresholdIsHalfTheRapidRateWithoutAFeedCap) {
  Rig rig;
  EXPECT_DOUBLE_EQ(rig.checks->rapid_threshold_mm_per_min(), 7500.0);
  EXPECT_NEAR(rig.checks->fast_step_mm(), 1.05 * 7500.0 / 60.0 * 1e-3, 1e-12);
  app::Profile capped = app::default_profile();
  capped.machine.max_feed_mm_per_min = 5000.0;
  const app::live::LiveChecks c(capped, rig.tools, 16, {});
  EXPECT_DOUBLE_EQ(c.rapid_threshold_mm_per_min(), 5000.0);
}

TEST(LiveChecks, AFastPassThroughTheStockIsARapidWithItsVolumeAndSamples) {
  Rig rig;
  // Samples 2 mm apart at 1 ms (120 m/min) along X at Z-1: the first one is the start pose.
  (void)rig.pass(10.0, 40.0, -1.0, 41, 2.0);
  const std::vector<verify::Event> ev = rig.checks->events();
  ASSERT_EQ(ev.size(), 1u);
  const verify::Event& e = ev[0];
  EXPECT_EQ(e.kind, verify::EventKind::RapidIntoMaterial);
  EXPECT_EQ(e.move, 2u);       // the first sample after the start pose
  EXPECT_EQ(e.last_move, 41u);  // the last sample of the sweep
  EXPECT_EQ(e.line, 0);        // no program
  const double expected = (80.0 * 10.0 + std::numbers::pi * 25.0) * 1.0;  // slot with round ends, 1 mm deep
  EXPECT_NEAR(e.volume_mm3, expected, 0.01 * expected);
  EXPECT_NEAR(rig.solid.initial_volume_mm3() - rig.solid.volume_mm3(), e.volume_mm3, 1e-6 * expected);
  EXPECT_EQ(rig.checks->latency().count(), 1u);
  gfx::LiveStats st;
  rig.checks->fill_alarms(st);
  ASSERT_EQ(st.alarm_count, 1);
  EXPECT_EQ(st.alarms[0].severity, gfx::AlarmSeverity::Error);
  EXPECT_STREQ(st.alarms[0].text.data(), "rapid-into-material T1 line 0 sample 2: 878.6 mm3 at X90.0 Y40.0 Z-1.0");
}

TEST(LiveChecks, ACutAtFeedSpeedIsClean) {
  Rig rig;
  // 0.1 mm a sample = 6000 mm/min, under the 7500 mm/min threshold.
  (void)rig.pass(10.0, 40.0, -1.0, 400, 0.1);
  EXPECT_TRUE(rig.checks->events().empty());
  EXPECT_GT(rig.solid.initial_volume_mm3() - rig.solid.volume_mm3(), 300.0);
  gfx::LiveStats st;
  rig.checks->fill_alarms(st);
  EXPECT_EQ(st.alarm_count, 0);
}

TEST(LiveChecks, TheStreamSplitsRunsWhereTheSpeedClassChanges) {
  Rig rig;
  // Slow, then fast, then slow again along one straight line: three sweeps, not one.
  for (int i = 0; i < 10; ++i) (void)rig.ring.try_push(sample(rig.seq++, 10.0 + 0.1 * i, 40.0, 5.0));
  for (int i = 1; i <= 10; ++i) (void)rig.ring.try_push(sample(rig.seq++, 10.9 + 1.0 * i, 40.0, 5.0));
  for (int i = 1; i <= 10; ++i) (void)rig.ring.try_push(sample(rig.seq++, 20.9 + 0.1 * i, 40.0, 5.0));
  (void)rig.geo->tick(4096);
  EXPECT_EQ(rig.geo->sweeps(), 3u);
  EXPECT_TRUE(rig.checks->events().empty());  // in the air
}

TEST(LiveChecks, ARapidAfterAFeedThroughTheSameSlotIsClean) {
  // The feed cuts the slot; the fast return runs through it in the same tick: judged against
  // the stock after the feed (the sub-batch ends at the rapid), so no event.
  Rig rig;
  for (int i = 0; i < 801; ++i) (void)rig.ring.try_push(sample(rig.seq++, 10.0 + 0.1 * i, 40.0, -1.0));
  for (int i = 1; i <= 40; ++i) (void)rig.ring.try_push(sample(rig.seq++, 90.0 - 2.0 * i, 40.0, -1.0));
  (void)rig.geo->tick(4096);
  EXPECT_TRUE(rig.checks->events().empty()) << verify::describe(rig.checks->events().at(0));
}

TEST(LiveChecks, ChecksInTheAirDoNotAllocate) {
  Rig rig;
  (void)rig.pass(10.0, 20.0, 5.0, 200, 0.1);
  (void)rig.pass(10.0, 21.0, 5.0, 200, 2.0);
  const long before = test::allocations();
  (void)rig.pass(10.0, 22.0, 5.0, 200, 0.1);
  (void)rig.pass(10.0, 23.0, 5.0, 40, 2.0);
  EXPECT_EQ(test::allocations() - before, 0) << "checking sweeps that miss the stock allocated";
}

// A lathe (docs/verification.md#turning): D40 bar, Z-80..0; T4 a sharp grooving blade 3 wide
// and 10 deep with a holder 13 wide from 5 mm on the chuck side, from the blade's depth out.
app::Profile live_lathe() {
  return app::parse_profile(
      "[machine]\nkind = \"lathe\"\n[stock]\nshape = \"cylinder\"\ncenter_mm = [0.0, 0.0]\ndiameter_mm = 40.0\n"
      "z_min_mm = -80.0\nz_max_mm = 0.0\n[lbr]\nlevel_spacing_mm = 0.1\nregions = \"2x2\"\nlive_regions = \"2x2\"\n"
      "[[tool]]\nnumber = 4\nkind = \"grooving\"\nwidth_mm = 3.0\nnose_radius_mm = 0.0\ndepth_mm = 10.0\n"
      "holder_width_mm = 13.0\nholder_z_mm = -5.0\nholder_r_mm = 10.0\n",
      "lathe-live.toml");
}

TEST(LiveChecks, AFastGrooveIntoTheBarIsARapidWithTheBladesVolume) {
  Rig rig(live_lathe());
  // The blade at Z-10 from r 25 to r 15, 0.5 mm a sample (30 m/min): the ring 15..20 x 3.
  for (int i = 0; i <= 20; ++i) (void)rig.ring.try_push(sample(rig.seq++, 25.0 - 0.5 * i, 0.0, -10.0, 4));
  (void)rig.geo->tick(4096);
  const std::vector<verify::Event> ev = rig.checks->events();
  ASSERT_EQ(ev.size(), 1u) << verify::describe(ev.at(1));
  EXPECT_EQ(ev[0].kind, verify::EventKind::RapidIntoMaterial);
  EXPECT_EQ(ev[0].tool, 4);
  const double expected = std::numbers::pi * (400.0 - 225.0) * 3.0;
  EXPECT_NEAR(ev[0].volume_mm3, expected, 0.01 * expected);
  EXPECT_NEAR(rig.solid.initial_volume_mm3() - rig.solid.volume_mm3(), expected, 0.01 * expected);
}

TEST(LiveChecks, AGrooveDeeperThanTheBladeDrivesTheHolderIn) {
  Rig rig(live_lathe());
  // At feed speed (0.05 mm a sample = 3 m/min) to r 5 at Z-30: the holder reaches r 15 on
  // the 10 mm of its width beside the blade.
  for (int i = 0; i <= 400; ++i) (void)rig.ring.try_push(sample(rig.seq++, 25.0 - 0.05 * i, 0.0, -30.0, 4));
  (void)rig.geo->tick(4096);
  const std::vector<verify::Event> ev = rig.checks->events();
  ASSERT_FALSE(ev.empty());
  for (const verify::Event& e : ev) EXPECT_EQ(e.kind, verify::EventKind::HolderInMaterial) << verify::describe(e);
  EXPECT_EQ(ev[0].tool, 4);
  EXPECT_GT(ev[0].volume_mm3, 0.0);
  // Stopping at r 11 (the holder at r 21) is clean.
  Rig clean(live_lathe());
  for (int i = 0; i <= 280; ++i) (void)clean.ring.try_push(sample(clean.seq++, 25.0 - 0.05 * i, 0.0, -30.0, 4));
  (void)clean.geo->tick(4096);
  EXPECT_TRUE(clean.checks->events().empty()) << verify::describe(clean.checks->events().at(0));
}

}  // namespace

// A tool change in the stream: the new tool starts where its first sample puts it (no sweep
// from the old tool's last position), and standing in the stock there raises
// tool-change-in-material with the material its body holds: T1 (flat Ø10) 8 mm deep,
// π·25·8 mm³ less the two-sided polygon's share.
TEST(LiveChecks, AToolLoadedIntoTheStockIsReportedWhereItStands) {
  Rig rig;
  for (int i = 0; i < 5; ++i) (void)rig.ring.try_push(sample(rig.seq++, 20.0, 20.0, 2.0 + 0.01 * i, 2));
  for (int i = 0; i <= 180; ++i) (void)rig.ring.try_push(sample(rig.seq++, 20.0, 20.0, -8.0 + 0.1 * i, 1));  // 6 m/min up
  (void)rig.geo->tick(4096);
  const std::vector<verify::Event> ev = rig.checks->events();
  ASSERT_EQ(ev.size(), 1u);
  const verify::Event& e = ev[0];
  EXPECT_EQ(e.kind, verify::EventKind::ToolChangeInMaterial);
  EXPECT_EQ(e.tool, 1);
  EXPECT_NEAR(e.position.z, -8.0, 1e-9);
  const double cylinder = std::numbers::pi * 25.0 * 8.0;
  EXPECT_NEAR(e.volume_mm3, cylinder, 0.005 * cylinder);
  EXPECT_NEAR(rig.solid.initial_volume_mm3() - rig.solid.volume_mm3(), e.volume_mm3, 0.005 * cylinder);
}
