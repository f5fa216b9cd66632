// Real-time contracts of the live pipeline (issue 15), measured with a counting operator new:
//  - the HAL path (serial stream decoding → samples → validation → ring, and the ring's
//    consumer side) allocates nothing after start-up;
//  - on the geometry thread, the motion stream (kinematics, merging, batch buffer) allocates
//    nothing after start-up; a tick whose sweeps miss the stock allocates nothing either;
//    a warmed-up tick that cuts allocates inside LbrSolid::subtract() (Clipper's polygon
//    buffers and the result polygons of every cell it changes) — the count is measured here
//    and bounded by the cells the batch changes, as docs/architecture.md states;
//  - overload: holding samples in the HAL side's overflow, folding collinear ones and
//    pumping them into the ring, and the geometry thread's sub-batches and split sweeps,
//    allocate nothing.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <memory>
#include <cstdlib>
#include <new>
#include <vector>

#include "alloc_counter.hpp"
#include "app/profile.hpp"
#include "hal/serial_codec.hpp"
#include "hal/validate.hpp"
#include "live/geometry.hpp"
#include "live_geometry_rig.hpp"
#include "live/ring_sink.hpp"
#include "motion/sample_stream.hpp"
#include "motion/tool_table.hpp"


namespace {

using namespace lbr;

using test::allocations;

using test::GeometryRig;
using test::sample;

TEST(LiveRealTime, SerialDecodeValidateAndRingDoNotAllocate) {
  const app::Profile profile = app::default_profile();
  hal::LiveConfig cfg = profile.live;
  sched::SpscRing<hal::AxisSample> ring(1024);
  const std::atomic<bool> stop{false};
  app::live::RingSink sink(ring, nullptr, cfg, false, stop);
  hal::SerialStreamDecoder decoder;
  hal::Counters counters;
  // 200 frames of a slow X feed, encoded once (setup).
  std::vector<std::uint8_t> bytes;
  for (std::uint32_t i = 0; i < 200; ++i) {
    hal::SerialFrame f;
    f.seq = i;
    f.t_us = i * 1000;
    f.n = 3;
    f.pos = {static_cast<std::int32_t>(i * 10), 0, 5000};
    std::array<std::uint8_t, hal::kSerialMaxFrame> buf{};
    const std::size_t n = hal::encode_serial_frame(f, buf);
    bytes.insert(bytes.end(), buf.begin(), buf.begin() + static_cast<long>(n));
  }
  std::array<hal::AxisSample, hal::kMaxChannels> out{};
  auto run = [&](std::size_t from, std::size_t to) {
    std::uint64_t popped = 0;
    for (std::size_t at = from; at < to; at += 37) {  // arbitrary chunks, frames split across them
      const auto chunk = std::span<const std::uint8_t>(bytes).subspan(at, std::min<std::size_t>(37, to - at));
      decoder.feed(chunk, counters, [&](const hal::SerialFrame& f) {
        const int n = hal::frame_to_samples(f, cfg, static_cast<std::int64_t>(f.t_us) * 1000, out, counters);
        sink.on_samples(std::span<const hal::AxisSample>(out.data(), static_cast<std::size_t>(n)));
      });
      while (ring.front() != nullptr) {
        ring.pop();
        ++popped;
      }
    }
    return popped;
  };
  const std::size_t half = bytes.size() / 2;
  (void)run(0, half);  // warm-up (first frames)
  const long before = allocations();
  const std::uint64_t popped = run(half, bytes.size());
  EXPECT_EQ(allocations() - before, 0) << "the HAL path allocated";
  EXPECT_GT(popped, 90u) << "samples must have gone through the ring";
  EXPECT_EQ(counters.total(), 0u);
}

TEST(LiveRealTime, OverloadHoldAndFoldDoNotAllocate) {
  // The geometry thread is behind (nobody pops a tiny ring): samples go to the overflow,
  // collinear ones fold, corners stay; then the ring drains and pump() moves them in.
  const app::Profile profile = app::default_profile();
  hal::LiveConfig cfg = profile.live;
  sched::SpscRing<hal::AxisSample> ring(8);
  const std::atomic<bool> stop{false};
  app::live::RingSink sink(ring, nullptr, cfg, false, stop, 4096);
  auto feed = [&](std::uint64_t from, std::uint64_t to) {
    for (std::uint64_t i = from; i < to; ++i) {
      const double x = 10.0 + 0.01 * static_cast<double>(i % 500), y = static_cast<double>((i / 500) % 2);
      hal::AxisSample s = sample(i, x, y, -1.0);
      sink.on_samples(std::span<const hal::AxisSample>(&s, 1));
    }
  };
  feed(0, 100);
  const long before = allocations();
  feed(100, 3000);
  std::uint64_t popped = 0, weight = 0;
  for (int round = 0; round < 10000 && !(sink.pump() && ring.front() == nullptr); ++round)
    while (hal::AxisSample* s = ring.front()) {
      ++popped;
      weight += 1 + s->coalesced;
      ring.pop();
    }
  EXPECT_EQ(allocations() - before, 0) << "holding, folding or pumping allocated";
  EXPECT_EQ(sink.overflow_overruns(), 0u);
  EXPECT_EQ(ring.overruns(), 0u);
  EXPECT_GT(sink.coalesced(), 2000u);
  EXPECT_EQ(weight, 3000u) << "every sample reaches the ring, alone or folded";
  EXPECT_LT(popped, 100u);
}

class NullSink final : public motion::SweepSink {
 public:
  void on_sweep(const geom::SweepRef&) noexcept override { ++sweeps; }
  void on_batch_full(std::span<const geom::SweepRef>) noexcept override { ++full; }
  int sweeps = 0, full = 0;
};

TEST(LiveRealTime, MotionStreamDoesNotAllocate) {
  const app::Profile profile = app::default_profile();
  motion::ToolTable tools(profile.tooling, profile.solid.chord_tol_mm, profile.source);
  tools.build_all();
  std::array<kin::Kinematics, motion::kMaxChannels> kins{};
  NullSink sink;
  motion::SampleStream stream(tools, kins, 1, 0.001, 64, sink);
  auto feed = [&](std::uint64_t from, std::uint64_t to) {
    for (std::uint64_t i = from; i < to; ++i) {
      // A zig-zag: every corner ends a run, so the batch fills and is emptied by the sink.
      const double x = static_cast<double>(i % 20), y = static_cast<double>((i / 20) % 2) * 3.0;
      const hal::AxisSample s = sample(i, x, y, -1.0);
      stream.take(0, s.seq, s.tool, s.q, s.mask);
      if (i % 7 == 0) {
        stream.flush_all();
        stream.clear_batch();
      }
    }
  };
  feed(0, 400);
  const long before = allocations();
  feed(400, 4000);
  EXPECT_EQ(allocations() - before, 0) << "the motion stream allocated";
  EXPECT_GT(sink.sweeps, 100);
}

TEST(LiveRealTime, GeometryTickInTheAirDoesNotAllocate) {
  GeometryRig rig;
  (void)rig.pass(20.0, 5.0, 200);  // above the stock (top at z = 0)
  (void)rig.pass(21.0, 5.0, 200);
  const long before = allocations();
  const std::size_t applied = rig.pass(22.0, 5.0, 200);
  EXPECT_EQ(allocations() - before, 0) << "a tick whose sweeps miss the stock allocated";
  EXPECT_EQ(applied, 200u);
}

TEST(LiveRealTime, SplitBatchesInTheAirDoNotAllocate) {
  // A tiny work budget: every sweep its own kernel call, each cut into pieces.
  GeometryRig rig;
  rig.geo->set_work_budget(1.0);
  (void)rig.pass(20.0, 5.0, 200);
  const long before = allocations();
  const std::size_t applied = rig.pass(22.0, 5.0, 200);
  EXPECT_EQ(allocations() - before, 0) << "sub-batching or splitting allocated";
  EXPECT_EQ(applied, 200u);
  EXPECT_GT(rig.geo->sweeps_split(), 0u);
}

TEST(LiveRealTime, CuttingTickAllocatesOnlyInsideTheKernel) {
  GeometryRig rig;
  // Warm-up: two passes, so the workspace, batch and lag buffers have grown.
  (void)rig.pass(20.0, -1.0, 200);
  (void)rig.pass(30.0, -1.0, 200);
  const std::size_t dirty_before = rig.solid.dirty_count();
  rig.solid.clear_dirty();
  const long before = allocations();
  const std::size_t applied = rig.pass(40.0, -1.0, 200);
  const long cut_allocs = allocations() - before;
  const std::size_t cells = rig.solid.dirty_count();
  EXPECT_EQ(applied, 200u);
  ASSERT_GT(cells, 0u) << "the pass must cut";
  // What allocates: the kernel's Clipper calls (edge lists, output paths) per changed cell.
  // Measured: a few tens per cell; the bound says it grows with the cells the batch changes,
  // not with the samples (200 here, merged into one sweep).
  RecordProperty("allocations", static_cast<int>(cut_allocs));
  RecordProperty("cells_changed", static_cast<int>(cells));
  std::printf("cutting tick: %ld allocations for %zu changed cells (%zu dirty before)\n", cut_allocs, cells,
              dirty_before);
  EXPECT_GT(cut_allocs, 0) << "Clipper allocates; if this reaches 0 the contract in geometry.hpp can be tightened";
  EXPECT_LE(cut_allocs, static_cast<long>(100 * cells)) << "allocations no longer bounded by the changed cells";
}

TEST(LiveOverload, ATimedTickStopsTakingSamplesAtItsWorkBudget) {
  // Live sources (timed calls): a tick takes samples only while the sweeps they make are
  // predicted to fit Geometry::kTickBudgetNs, the rest stay queued; later ticks apply them
  // all. (A 5-axis stream far behind ran one tick of 35 s, then rested 50 s.)
  GeometryRig rig;
  rig.geo->set_timed_calls(true);
  // A zig-zag cutting the stock: every sample ends a sweep of its own.
  const std::size_t pushed = 3000;
  for (std::size_t i = 0; i < pushed; ++i)
    ASSERT_TRUE(rig.ring.try_push(sample(rig.seq++, 10.0 + 0.05 * static_cast<double>(i), 20.0 + (i % 2 ? 3.0 : 0.0), -1.0)));
  const std::size_t first = rig.geo->tick(4096);
  EXPECT_GT(first, 0u);
  EXPECT_LT(first, pushed) << "one tick took the whole backlog";
  EXPECT_EQ(rig.ring.size(), pushed - first) << "what a tick leaves stays queued";
  std::size_t total = first, ticks = 1;
  while (rig.ring.size() > 0 && ticks < 10000) total += rig.geo->tick(4096), ++ticks;
  EXPECT_EQ(total, pushed);
  EXPECT_EQ(rig.geo->applied(), pushed);
  EXPECT_GT(ticks, 2u);
}

}  // namespace
