// app/src/live/ring_sink.hpp — the HAL side of the live pipeline: validation, then the
// sample ring (and the raw-record ring for --record). Runs on the HAL thread.
// Real-time safe: on_samples() and on_raw() never allocate, throw or lock (tested by
// tests/app_live_alloc_test.cpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <span>

#include "hal/source.hpp"
#include "hal/validate.hpp"
#include "sched/rt_thread.hpp"
#include "sched/spsc_ring.hpp"

namespace lbr::app::live {

class RingSink final : public hal::SampleSink {
 public:
  // `backpressure`: the source is not live (replay/emulator as fast as possible): wait for
  // room in the ring instead of dropping, until `stop`.
  RingSink(sched::SpscRing<hal::AxisSample>& ring, sched::SpscRing<hal::RawRecord>* rec, const hal::LiveConfig& cfg,
           bool backpressure, const std::atomic<bool>& stop)
      : ring_(ring), rec_(rec), validator_(cfg), backpressure_(backpressure), stop_(stop) {}

  void on_samples(std::span<const hal::AxisSample> samples) noexcept override {
    for (const hal::AxisSample& s : samples) {
      bump(received_);
      if (!validator_.accept(s, counters_)) {
        bump(rejected_);
        continue;
      }
      if (backpressure_) {
        // Not a live source: wait for room rather than drop (never counts an overrun).
        while (ring_.size() >= ring_.capacity()) {
          if (stop_.load(std::memory_order_relaxed)) return;
          sched::sleep_until_ns(sched::now_ns() + 100'000);
        }
      }
      (void)ring_.try_push(s);  // a refused push is counted by the ring (ring_overruns)
    }
  }
  void on_raw(const hal::RawRecord& r) noexcept override {
    if (rec_ != nullptr && !rec_->try_push(r)) bump(rec_overruns_);
  }
  [[nodiscard]] std::uint64_t received() const noexcept { return received_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t rejected() const noexcept { return rejected_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t rec_overruns() const noexcept { return rec_overruns_.load(std::memory_order_relaxed); }
  [[nodiscard]] const hal::Counters& counters() const noexcept { return counters_; }

 private:
  // Single writer (the HAL thread): a relaxed load + store, readable from other threads.
  static void bump(std::atomic<std::uint64_t>& c) noexcept {
    c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

  sched::SpscRing<hal::AxisSample>& ring_;
  sched::SpscRing<hal::RawRecord>* rec_;
  hal::Validator validator_;
  bool backpressure_;
  const std::atomic<bool>& stop_;
  hal::Counters counters_;
  std::atomic<std::uint64_t> received_{0}, rejected_{0}, rec_overruns_{0};
};

}  // namespace lbr::app::live
