// app/src/live/geometry.hpp — the live geometry thread's work per tick: drain the sample
// ring, turn the samples into sweeps (motion::SampleStream: kinematics, sub-steps, merging
// of straight runs per channel), subtract them, record lag and batch work, publish to the
// render side.
//
// Real-time contract (tests/app_live_alloc_test.cpp measures it): draining the ring and the
// motion stream never allocate; LbrSolid::subtract() allocates inside Clipper (bounded by
// the batch: the cells its sweeps touch), and publish() copies cells into the exchange's
// slot storage, which allocates while that storage grows. Neither throws in practice; an
// allocation failure terminates (std::bad_alloc is not caught on this thread).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "app/profile.hpp"
#include "geom/lbr_solid.hpp"
#include "gfx/exchange.hpp"
#include "hal/sample.hpp"
#include "motion/sample_stream.hpp"
#include "motion/tool_table.hpp"
#include "sched/latency_stats.hpp"
#include "sched/spsc_ring.hpp"

namespace lbr::app::live {

class Geometry final : public motion::SweepSink {
 public:
  // `tools` must be built (ToolTable::build_all); `default_tool` cuts for samples without a
  // tool number. Setup: allocates the batch and lag buffers.
  Geometry(geom::LbrSolid& solid, const Profile& profile, const motion::ToolTable& tools, int default_tool,
           sched::SpscRing<hal::AxisSample>& ring, double tol_mm);

  // Applies what is in the ring, at most `limit` samples; returns the samples applied.
  std::size_t tick(std::size_t limit);

  // Rendering: tip points go to the exchange's path buffer (no allocation).
  void set_exchange(gfx::SolidExchange* ex) noexcept { ex_ = ex; }
  // Publishes the solid to the render side between batches (never waits; see
  // gfx/exchange.hpp). Tools: one per channel holding a milling cutter, at its latest pose.
  bool publish(const gfx::LiveStats& stats);
  [[nodiscard]] std::int64_t last_rx_ns() const noexcept { return last_rx_ns_; }

  void publish_volume() noexcept;
  [[nodiscard]] std::uint64_t applied() const noexcept { return applied_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t sweeps() const noexcept { return sweeps_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t batches() const noexcept { return batches_.load(std::memory_order_relaxed); }
  [[nodiscard]] double removed_mm3() const noexcept { return removed_.load(std::memory_order_relaxed); }
  [[nodiscard]] const sched::LatencyHistogram& lag() const noexcept { return lag_; }
  // Duration of each tick's subtract() (the geometry thread's work per batch).
  [[nodiscard]] const sched::LatencyHistogram& work() const noexcept { return work_; }

  // motion::SweepSink
  void on_sweep(const geom::SweepRef& s) noexcept override;
  void on_batch_full(std::span<const geom::SweepRef> batch) noexcept override;

 private:
  static std::array<kin::Kinematics, motion::kMaxChannels> channel_kinematics(const Profile& profile);

  geom::LbrSolid& solid_;
  sched::SpscRing<hal::AxisSample>& ring_;
  motion::SampleStream stream_;
  geom::SubtractWorkspace ws_;
  std::vector<std::int64_t> rx_;
  sched::LatencyHistogram lag_, work_;
  std::atomic<std::uint64_t> applied_{0}, sweeps_{0}, batches_{0};
  std::atomic<double> removed_{0.0};
  int ticks_since_volume_ = 0;
  gfx::SolidExchange* ex_ = nullptr;
  std::int64_t last_rx_ns_ = 0;
};

}  // namespace lbr::app::live
