// The live geometry thread's kernel pool (Geometry::set_pool, [lbr] live_threads): calls
// that go to the pool leave the same solid, byte for byte, as calls on the geometry thread
// alone; the threshold decides which calls go; the profile key and its default.
#include <gtest/gtest.h>

#include <sched.h>

#include <algorithm>
#include <memory>

#include "app/profile.hpp"
#include "geom/parallel_subtractor.hpp"
#include "geom/serialize.hpp"
#include "live/geometry.hpp"
#include "live_geometry_rig.hpp"

namespace {

using namespace lbr;

using test::GeometryRig;
using test::sample;

// Ramps and zig-zags through the stock (T1, a 10 mm flat end mill): sweeps that reach many
// levels and regions, in ticks of 150 samples.
void cut(GeometryRig& rig) {
  for (int pass = 0; pass < 6; ++pass) {
    const double y = 15.0 + 9.0 * pass;
    for (int i = 0; i < 600; ++i) {
      const double x = pass % 2 == 0 ? 5.0 + 0.15 * i : 95.0 - 0.15 * i;
      const double z = -1.0 - 4.0 * (i / 600.0) - 0.5 * pass;
      ASSERT_TRUE(rig.ring.try_push(sample(rig.seq++, x, y, z)));
      if (i % 150 == 149) (void)rig.geo->tick(4096);
    }
  }
  (void)rig.geo->tick(4096);
}

TEST(LivePool, SharedCallsLeaveTheSameSolidAsOneThread) {
  GeometryRig alone;
  cut(alone);
  geom::ParallelSubtractor pool(2);
  GeometryRig shared;
  shared.geo->set_pool(&pool, 0);  // every call to the pool
  cut(shared);
  ASSERT_GT(alone.geo->kernel_calls(), 10u);
  EXPECT_EQ(alone.geo->kernel_calls_shared(), 0u);
  EXPECT_EQ(shared.geo->kernel_calls(), alone.geo->kernel_calls());
  EXPECT_EQ(shared.geo->kernel_calls_shared(), shared.geo->kernel_calls());
  EXPECT_EQ(shared.geo->applied(), alone.geo->applied());
  EXPECT_GT(alone.solid.initial_volume_mm3() - alone.solid.volume_mm3(), 1000.0) << "the passes must cut";
  EXPECT_EQ(geom::to_bytes(shared.solid), geom::to_bytes(alone.solid));
}

TEST(LivePool, OnlyCallsAboveTheThresholdGoToThePool) {
  geom::ParallelSubtractor pool(2);
  GeometryRig rig;
  rig.geo->set_pool(&pool, 3'600'000'000'000);  // an hour: no call is predicted that long
  cut(rig);
  EXPECT_GT(rig.geo->kernel_calls(), 10u);
  EXPECT_EQ(rig.geo->kernel_calls_shared(), 0u);
  rig.geo->set_pool(nullptr);
  EXPECT_GT(rig.solid.initial_volume_mm3() - rig.solid.volume_mm3(), 1000.0);
}

TEST(LivePool, ProfileKeyAndDefault) {
  const std::string stock = "[stock]\nshape = \"box\"\nmin_mm = [0, 0, -10]\nmax_mm = [50, 40, 0]\n";
  app::Profile p = app::parse_profile(stock, "p.toml");
  EXPECT_EQ(p.live_threads, 1);
  EXPECT_EQ(app::live_kernel_threads(p), 1);
  p = app::parse_profile(stock + "[lbr]\nlive_threads = 2\n", "p.toml");
  EXPECT_EQ(p.live_threads, 2);
  cpu_set_t set;
  CPU_ZERO(&set);
  ASSERT_EQ(sched_getaffinity(0, sizeof(set), &set), 0);
  EXPECT_EQ(app::live_kernel_threads(p), std::min(2, CPU_COUNT(&set)));
  p.live_threads = 300;  // more than this thread may run on: as many as it may
  EXPECT_EQ(app::live_kernel_threads(p), CPU_COUNT(&set));
  try {
    (void)app::parse_profile(stock + "[lbr]\nlive_threads = 0\n", "p.toml");
    FAIL() << "live_threads = 0 was accepted";
  } catch (const app::ProfileError& e) {
    EXPECT_NE(std::string(e.what()).find("p.toml:6: lbr.live_threads"), std::string::npos) << e.what();
  }
}

}  // namespace
