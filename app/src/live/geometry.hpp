// app/src/live/geometry.hpp — the live geometry thread's work per tick: drain the sample
// ring, turn the samples into sweeps (motion::SampleStream: kinematics, sub-steps, merging
// of straight runs per channel), subtract them, record lag and batch work, publish to the
// render side.
//
// Bounded work (issue 13 item 4): the batch is subtracted in sub-batches whose estimated
// work (work_units(): the (level, region) cells the sweeps reach and the sections they
// need, a tool-axis turn counting as many sections) stays within a budget, and a single
// sweep over the budget is cut into pieces at poses interpolated as geom::Sweep does (tip
// linear, axis normalised-linear). Live sources size the sub-batches by time instead
// (live/call_sizer.hpp: a target call time from the backlog, units converted to time by a
// rate fitted online); replay and emulator runs as fast as possible keep the fixed budget,
// so their split depends only on the sweeps and such a run stays reproducible. Between
// kernel calls the geometry thread looks at the stop request: once stop_grace_ns has passed
// since it was made, the rest is abandoned.
//
// Lag: a sample's lag is recorded when the kernel call that applies its sweep returns (the
// sweep whose last sample it is or follows, per channel), not at the end of the tick.
//
// Real-time contract (tests/app_live_alloc_test.cpp measures it): draining the ring and the
// motion stream never allocate; LbrSolid::subtract() allocates inside Clipper (bounded by
// the batch: the cells its sweeps touch), and publish() copies cells into the exchange's
// slot storage, which allocates while that storage grows. Neither throws in practice; an
// allocation failure terminates (std::bad_alloc is not caught on this thread).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "app/live.hpp"
#include "app/profile.hpp"
#include "live/call_sizer.hpp"
#include "geom/lbr_solid.hpp"
#include "geom/parallel_subtractor.hpp"
#include "live/checks.hpp"
#include "gfx/exchange.hpp"
#include "hal/sample.hpp"
#include "live/program_position.hpp"
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

  // Sweeps the motion stream buffers before a kernel call is forced (on_batch_full).
  [[nodiscard]] static std::size_t batch_capacity(std::size_t ring_capacity) noexcept;

  // Applies what is in the ring, at most `limit` ring entries; returns the entries taken.
  // With timed calls (live sources) a tick also stops taking entries once the sweeps they
  // made are predicted to take kTickBudgetNs: what is left stays queued (and merges further)
  // for the next tick, so the thread returns to the pipeline (display, snapshot, stop, duty
  // rest) every few calls however far behind it is.
  std::size_t tick(std::size_t limit);
  static constexpr std::int64_t kTickBudgetNs = 100'000'000;

  // Stop handling: `a` or `b` set asks for a stop; the first kernel-call boundary that sees
  // it stores the time in `*stop_ns` (unless another thread did), and from stop_ns + grace
  // on, tick() abandons what it has not applied (abandoned() says so). Setup.
  void set_stop(const std::atomic<bool>* a, const std::atomic<bool>* b, std::atomic<std::int64_t>* stop_ns,
                std::int64_t grace_ns) noexcept {
    stop_a_ = a;
    stop_b_ = b;
    stop_ns_ = stop_ns;
    stop_grace_ns_ = grace_ns;
  }
  // True once the stop's grace time has passed (checked at kernel-call boundaries).
  [[nodiscard]] bool stop_due() noexcept;
  [[nodiscard]] bool abandoned() const noexcept { return abandoned_; }
  // Empties the ring without applying (after a stop); counts them in unapplied().
  std::uint64_t discard() noexcept;
  // Work budget of one kernel call [units of work_units()].
  void set_work_budget(double units) noexcept { budget_ = units; }
  // Live sources: sub-batches sized by time (live/call_sizer.hpp) instead of the fixed
  // budget. Setup.
  void set_timed_calls(bool on, const CallSizerConfig& c = {}) noexcept {
    timed_ = on;
    sizer_ = CallSizer(c);
  }
  [[nodiscard]] const CallSizer& sizer() const noexcept { return sizer_; }
  // Diagnostics: record up to `capacity` kernel calls (allocates now; setup).
  void set_kernel_log(std::size_t capacity, std::int64_t t0_ns);
  [[nodiscard]] std::span<const KernelCallRecord> kernel_log() const noexcept {
    return {log_.data(), std::min(log_n_, log_.size())};
  }
  [[nodiscard]] double work_budget() const noexcept { return budget_; }
  // Kernel calls predicted (CallSizer) to take at least `min_call_ns` run on `pool` (its
  // threads and this one; byte for byte the same result) instead of on this thread alone:
  // a shorter call would pay more for the hand-over than it gains. Null: every call here.
  // The pool is used only by the thread that ticks, which sets it. Setup.
  static constexpr std::int64_t kSharedCallNs = 500'000;
  void set_pool(geom::ParallelSubtractor* pool, std::int64_t min_call_ns = kSharedCallNs) noexcept {
    pool_ = pool;
    pool_min_ns_ = static_cast<double>(min_call_ns);
  }
  // Kernel calls that ran on the pool (part of kernel_calls()).
  [[nodiscard]] std::uint64_t kernel_calls_shared() const noexcept { return shared_calls_.load(std::memory_order_relaxed); }
  // Testing: sleep this long after every kernel call (a deliberately slowed kernel).
  void set_kernel_delay_ns(std::int64_t ns) noexcept { kernel_delay_ns_ = ns; }
  // Estimated work of one sweep alone (cells it reaches + its sections).
  [[nodiscard]] double work_units(const geom::SweepRef& s) const noexcept;

  // Collision checks (live/checks.hpp) before every kernel call; null: none. Setup: also
  // sets the motion stream's fast-step threshold (rapids).
  void set_checks(LiveChecks* checks) noexcept;
  // Duration of the checks before each kernel call.
  [[nodiscard]] const sched::LatencyHistogram& check_time() const noexcept { return check_; }

  // Every sample taken from the ring also goes to `pos` (the status bar's program position).
  void set_program_position(ProgramPosition* pos) noexcept { pos_ = pos; }
  // Rendering: tip points go to the exchange's path buffer (no allocation).
  void set_exchange(gfx::SolidExchange* ex) noexcept { ex_ = ex; }
  // Publishes the solid to the render side between batches (never waits; see
  // gfx/exchange.hpp). Tools: one per channel holding a milling cutter, at its latest pose.
  bool publish(const gfx::LiveStats& stats);
  [[nodiscard]] std::int64_t last_rx_ns() const noexcept { return last_rx_ns_; }

  // Power-loss resume (app/snapshot.hpp): each channel's newest applied sample, and priming
  // the motion stream with them so the next sample sweeps from where the tool was. prime()
  // is setup (before the thread starts); last_applied() is read on the geometry thread.
  void prime(const std::array<bool, hal::kMaxChannels>& have, const std::array<hal::AxisSample, hal::kMaxChannels>& last) noexcept;
  // A break in the stream (a live source after the outage, once the catch-up from the
  // recording is applied): the next sample of each channel sweeps from nowhere. The newest
  // applied samples stay (the snapshot's). Setup, between tick()s on the thread that ticks.
  void forget_poses() noexcept {
    stream_.forget_poses();
    stream_.clear_batch();
  }
  [[nodiscard]] const std::array<bool, hal::kMaxChannels>& have_applied() const noexcept { return have_; }
  [[nodiscard]] const std::array<hal::AxisSample, hal::kMaxChannels>& last_applied() const noexcept { return last_; }

  void publish_volume() noexcept;
  [[nodiscard]] std::uint64_t applied() const noexcept { return applied_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t sweeps() const noexcept { return sweeps_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t batches() const noexcept { return batches_.load(std::memory_order_relaxed); }
  // Samples applied that the HAL side had folded into others (part of applied()).
  [[nodiscard]] std::uint64_t coalesced() const noexcept { return coalesced_.load(std::memory_order_relaxed); }
  // Kernel calls (sub-batches) and sweeps cut into pieces by the work budget.
  [[nodiscard]] std::uint64_t kernel_calls() const noexcept { return calls_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t sweeps_split() const noexcept { return split_.load(std::memory_order_relaxed); }
  // Samples taken from the ring but abandoned by a stop (not counted as applied).
  [[nodiscard]] std::uint64_t unapplied() const noexcept { return unapplied_.load(std::memory_order_relaxed); }
  [[nodiscard]] double removed_mm3() const noexcept { return removed_.load(std::memory_order_relaxed); }
  [[nodiscard]] const sched::LatencyHistogram& lag() const noexcept { return lag_; }
  // Duration of each kernel call (subtract() of one sub-batch).
  [[nodiscard]] const sched::LatencyHistogram& work() const noexcept { return work_; }

  // motion::SweepSink
  void on_sweep(const geom::SweepRef& s) noexcept override;
  void on_batch_full(std::span<const geom::SweepRef> batch) noexcept override;

 private:
  static std::array<kin::Kinematics, motion::kMaxChannels> channel_kinematics(const Profile& profile);
  // Subtracts `batch` in sub-batches within the work budget; false when a stop cut it short.
  bool apply(std::span<const geom::SweepRef> batch) noexcept;
  // What apply() knows of one sub-batch before its kernel call.
  struct Part {
    double units = 0.0;          // work estimate, cells once
    double first = 0.0;          // of its first sweep alone
    double first_sections = 0.0; // of its first sweep's sections (what pieces share out)
    double sections = 0.0;       // added_units(): of the last sweep's sections
    double cell_vertices = 0.0;  // only with a kernel log
    std::int64_t target_ns = 0;  // the call time it was sized for (timed calls)
    std::int64_t backlog_ns = 0;
  };
  // The end of the longest prefix of batch[i..] within the budget (at least i + 1).
  std::size_t sub_batch(std::span<const geom::SweepRef> batch, std::size_t i, Part& part) noexcept;
  // Work units sweep s adds to the current sub-batch (its sections, its cells not yet
  // counted); its vertices go to part.cell_vertices when logging.
  double added_units(const geom::SweepRef& s, Part& part) noexcept;
  void kernel(std::span<const geom::SweepRef> part, const Part& info) noexcept;
  // After batch[i, j) was applied: records the lag of the ring entries it completed.
  void record_lag(std::span<const motion::SweepInfo> info, std::int64_t now_ns) noexcept;
  // Age of the oldest ring entry of this tick not applied yet [ns] (0: none).
  [[nodiscard]] std::int64_t backlog_ns(std::int64_t now_ns) const noexcept;
  // The end of the prefix of [i, j) the kernel may subtract now (the checks' verdict).
  std::size_t checked(std::size_t i, std::size_t j) noexcept;
  // Subtracts the single sweep s in k pieces; false when a stop cut it short.
  bool apply_pieces(const geom::SweepRef& s, int k, const Part& info) noexcept;
  // Cells of one sweep [levels l0..l1] x [regions x0..x1, y0..y1]; false when it reaches none.
  struct Reach {
    int l0 = 0, l1 = -1, x0 = 0, x1 = -1, y0 = 0, y1 = -1;
    double tilt = 1.0;  // sections per level (a turning tool axis needs several)
  };
  [[nodiscard]] bool reach(const geom::SweepRef& s, Reach& r) const noexcept;

  geom::LbrSolid& solid_;
  sched::SpscRing<hal::AxisSample>& ring_;
  motion::SampleStream stream_;
  std::vector<std::int64_t> rx_;
  std::vector<std::uint64_t> seq_;         // sequence number of ring entry i of this tick
  std::vector<std::uint8_t> chan_;         // its channel
  std::size_t taken_ = 0;                  // ring entries taken in this tick so far
  LiveChecks* checks_ = nullptr;
  std::vector<std::uint32_t> weight_;      // 1 + samples folded into ring entry i
  std::vector<std::uint32_t> stamp_;       // per (region, level): sub-batch that counted it
  std::uint32_t stamp_gen_ = 0;
  double budget_ = 60'000.0;
  bool timed_ = false;
  CallSizer sizer_;
  std::vector<double> prefix_units_;  // sub_batch(): units of its first k + 1 sweeps
  double tick_units_ = 0.0;           // work units of the sweeps made in this tick so far
  std::size_t lag_done_ = 0;  // ring entries of this tick whose lag is recorded
  std::array<std::uint64_t, hal::kMaxChannels> done_seq_{};  // per channel: applied up to this sample
  std::array<bool, hal::kMaxChannels> done_any_{};
  std::uint32_t call_samples_ = 0;  // ring entries the current kernel call completed
  std::vector<KernelCallRecord> log_;
  std::size_t log_n_ = 0;
  std::int64_t log_t0_ns_ = 0;
  std::int64_t kernel_delay_ns_ = 0;
  const std::atomic<bool>* stop_a_ = nullptr;
  const std::atomic<bool>* stop_b_ = nullptr;
  std::atomic<std::int64_t>* stop_ns_ = nullptr;
  std::int64_t stop_grace_ns_ = 0;
  bool abandoned_ = false;
  sched::LatencyHistogram lag_, work_, check_;
  std::atomic<std::uint64_t> applied_{0}, sweeps_{0}, batches_{0}, coalesced_{0}, calls_{0}, split_{0}, unapplied_{0};
  std::atomic<std::uint64_t> shared_calls_{0};
  geom::ParallelSubtractor* pool_ = nullptr;
  double pool_min_ns_ = 0.0;
  std::atomic<double> removed_{0.0};
  int ticks_since_volume_ = 0;
  gfx::SolidExchange* ex_ = nullptr;
  ProgramPosition* pos_ = nullptr;
  std::int64_t last_rx_ns_ = 0;
  std::array<bool, hal::kMaxChannels> have_{}, pending_have_{};
  std::array<hal::AxisSample, hal::kMaxChannels> last_{}, pending_{};
};

}  // namespace lbr::app::live
