// app/src/live/ring_sink.hpp — the HAL side of the live pipeline: validation, then the
// sample ring (and the raw-record ring for --record). Runs on the HAL thread.
//
// Lossless overload (issue 13 item 4b, docs/architecture.md "Live overload"): a live source
// never waits, and a sample is never dropped because the geometry thread is behind. While
// the ring is full, samples go to a preallocated overflow FIFO that only this thread sees,
// and pump() moves them into the ring as it empties (oldest first). Inside the overflow a
// channel's newest held sample absorbs the next one of that channel when that is exact:
// same tool, rotary axes (A B C) unchanged over both moves, and every folded sample within
// merge_tolerance_mm / 2 of the straight move from the sample before them to the new one.
// With the rotary axes fixed, every kinematics (kin::tool_pose) maps X Y Z to the tool tip
// by a rigid motion, so the distance in axis space is the distance of the tool tips and the
// swept region changes by at most that much — the same rule as motion::SampleStream's and
// geom::merge_collinear's merging of straight runs. Only when the overflow is full too is a
// sample lost (counted: overflow_overruns, part of samples_lost).
//
// Real-time safe: on_samples(), on_raw() and pump() never allocate, throw or lock (tested
// by tests/app_live_alloc_test.cpp). The constructor allocates the overflow.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "hal/source.hpp"
#include "hal/validate.hpp"
#include "sched/rt_thread.hpp"
#include "sched/spsc_ring.hpp"

namespace lbr::app::live {

class RingSink final : public hal::SampleSink {
 public:
  static constexpr std::uint32_t kMaxFold = 256;  // samples folded into one at most

  // `backpressure`: the source is not live (replay/emulator as fast as possible): wait for
  // room in the ring instead of dropping, until `stop`. `overflow_capacity`: samples held
  // while the ring is full (0: 16 × the ring's capacity).
  RingSink(sched::SpscRing<hal::AxisSample>& ring, sched::SpscRing<hal::RawRecord>* rec, const hal::LiveConfig& cfg,
           bool backpressure, const std::atomic<bool>& stop, std::size_t overflow_capacity = 0);

  void on_samples(std::span<const hal::AxisSample> samples) noexcept override;
  void on_raw(const hal::RawRecord& r) noexcept override {
    if (rec_ != nullptr && !rec_->try_push(r)) bump(rec_overruns_);
  }
  // Moves held samples into the ring while it has room; true when none are held. The HAL
  // thread calls it after every poll (also when the source was quiet).
  bool pump() noexcept;
  // Samples (with those folded into them) still held when the run ended; HAL thread, once.
  std::uint64_t abandon() noexcept;

  [[nodiscard]] std::uint64_t received() const noexcept { return received_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t rejected() const noexcept { return rejected_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t rec_overruns() const noexcept { return rec_overruns_.load(std::memory_order_relaxed); }
  // Samples folded into a held one (they reach the geometry thread as part of it).
  [[nodiscard]] std::uint64_t coalesced() const noexcept { return coalesced_.load(std::memory_order_relaxed); }
  // Samples lost because ring and overflow were both full.
  [[nodiscard]] std::uint64_t overflow_overruns() const noexcept { return overflow_overruns_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t held() const noexcept { return held_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t overflow_high_water() const noexcept { return overflow_hw_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::size_t overflow_capacity() const noexcept { return buf_.size(); }
  [[nodiscard]] const hal::Counters& counters() const noexcept { return counters_; }

 private:
  using Axes = std::array<double, hal::kMaxAxes>;
  struct Channel {
    bool have = false;    // a sample of this channel went through
    Axes q{};             // axis values after its newest sample (masks applied)
    std::int16_t tool = -1;
    bool open = false;    // its newest sample is still held (may absorb the next one)
    std::uint64_t open_at = 0;  // absolute overflow index of that sample
    Axes start{};         // axis values before it: the start of its straight move
    std::uint32_t folded = 0;   // tips folded into it so far
    std::array<std::array<double, 3>, kMaxFold> tips{};
  };

  // Single writer (the HAL thread): a relaxed load + store, readable from other threads.
  static void bump(std::atomic<std::uint64_t>& c, std::uint64_t n = 1) noexcept {
    c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  void take(const hal::AxisSample& s) noexcept;
  bool try_fold(Channel& c, const hal::AxisSample& s, const Axes& q) noexcept;
  void hold(Channel* c, const hal::AxisSample& s) noexcept;

  sched::SpscRing<hal::AxisSample>& ring_;
  sched::SpscRing<hal::RawRecord>* rec_;
  hal::Validator validator_;
  bool backpressure_;
  const std::atomic<bool>& stop_;
  double fold_tol_mm_;
  hal::Counters counters_;
  std::vector<hal::AxisSample> buf_;      // overflow FIFO storage (setup)
  std::uint64_t head_ = 0, tail_ = 0;     // absolute indices: oldest held, next free
  std::array<Channel, hal::kMaxChannels> ch_{};
  std::atomic<std::uint64_t> received_{0}, rejected_{0}, rec_overruns_{0};
  std::atomic<std::uint64_t> coalesced_{0}, overflow_overruns_{0}, held_{0}, overflow_hw_{0};
};

}  // namespace lbr::app::live
