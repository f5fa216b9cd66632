// sched/latency_stats.hpp — fixed-bucket latency histogram with p50/p99/max.
//
// Log-linear buckets: values below 32 ns are exact; above, every power of two is split into
// 32 sub-buckets, so a reported percentile is within 1/32 (3.1 %) of the true value, from
// 1 ns to 2^63 ns. Storage is a fixed array: record() never allocates.
// Thread safety: one writer; readers on other threads see a consistent-enough snapshot
// (relaxed atomics, so a concurrent reader is race-free but may miss the latest records).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace lbr::sched {

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 5;
  static constexpr int kSub = 1 << kSubBits;
  static constexpr int kBuckets = (64 - kSubBits + 1) * kSub;

  LatencyHistogram() noexcept { reset(); }
  // Writer. RT-safe, no allocation. Negative values count as 0.
  void record(std::int64_t value_ns) noexcept;
  // Writer only (not concurrently with record()).
  void reset() noexcept;

  [[nodiscard]] std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::int64_t max_ns() const noexcept { return max_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::int64_t min_ns() const noexcept;
  [[nodiscard]] double mean_ns() const noexcept;
  // Value at quantile q in [0, 1] (0.5 = median): the midpoint of the bucket holding it,
  // clamped to [min, max]. 0 when empty.
  [[nodiscard]] std::int64_t percentile_ns(double q) const noexcept;

  // Windows: copy the bucket counts now and then (any thread; relaxed reads); the quantile
  // of the values recorded between two copies is the bucket midpoint, as above.
  using Counts = std::array<std::uint64_t, kBuckets>;
  void copy_counts(Counts& out) const noexcept;
  [[nodiscard]] static std::int64_t percentile_between_ns(const Counts& before, const Counts& after, double q) noexcept;

  [[nodiscard]] static int bucket_of(std::uint64_t v) noexcept;
  [[nodiscard]] static std::uint64_t bucket_low(int b) noexcept;
  [[nodiscard]] static std::uint64_t bucket_high(int b) noexcept;  // exclusive

 private:
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_;
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> max_{0}, min_{0}, sum_{0};
};

}  // namespace lbr::sched
