#include "sched/latency_stats.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace lbr::sched {

namespace {
void bump(std::atomic<std::uint64_t>& a) noexcept { a.store(a.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }
}  // namespace

int LatencyHistogram::bucket_of(std::uint64_t v) noexcept {
  if (v < kSub) return static_cast<int>(v);
  const int msb = 63 - std::countl_zero(v);             // >= kSubBits
  const int shift = msb - kSubBits;                      // >= 0
  const int sub = static_cast<int>((v >> shift) & (kSub - 1));
  return (shift + 1) * kSub + sub;
}

std::uint64_t LatencyHistogram::bucket_low(int b) noexcept {
  if (b < kSub) return static_cast<std::uint64_t>(b);
  const int shift = b / kSub - 1;
  const std::uint64_t sub = static_cast<std::uint64_t>(b % kSub);
  return (std::uint64_t{kSub} + sub) << shift;
}

std::uint64_t LatencyHistogram::bucket_high(int b) noexcept {
  if (b < kSub) return static_cast<std::uint64_t>(b) + 1;
  const int shift = b / kSub - 1;
  return bucket_low(b) + (std::uint64_t{1} << shift);
}

void LatencyHistogram::reset() noexcept {
  for (auto& b : buckets_) b.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_relaxed);
  max_.store(0, std::memory_order_relaxed);
  min_.store(std::numeric_limits<std::int64_t>::max(), std::memory_order_relaxed);
  sum_.store(0, std::memory_order_relaxed);
}

void LatencyHistogram::record(std::int64_t value_ns) noexcept {
  const std::int64_t v = std::max<std::int64_t>(value_ns, 0);
  bump(buckets_[static_cast<std::size_t>(bucket_of(static_cast<std::uint64_t>(v)))]);
  bump(count_);
  if (v > max_.load(std::memory_order_relaxed)) max_.store(v, std::memory_order_relaxed);
  if (v < min_.load(std::memory_order_relaxed)) min_.store(v, std::memory_order_relaxed);
  sum_.store(sum_.load(std::memory_order_relaxed) + v, std::memory_order_relaxed);
}

std::int64_t LatencyHistogram::min_ns() const noexcept { return count() == 0 ? 0 : min_.load(std::memory_order_relaxed); }

double LatencyHistogram::mean_ns() const noexcept {
  const std::uint64_t n = count();
  return n == 0 ? 0.0 : static_cast<double>(sum_.load(std::memory_order_relaxed)) / static_cast<double>(n);
}

std::int64_t LatencyHistogram::percentile_ns(double q) const noexcept {
  std::uint64_t total = 0;
  for (const auto& b : buckets_) total += b.load(std::memory_order_relaxed);
  if (total == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  // Rank of the wanted element (1-based), "nearest rank" definition.
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total))));
  std::uint64_t seen = 0;
  for (int i = 0; i < kBuckets; ++i) {
    seen += buckets_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);
    if (seen >= rank) {
      const std::uint64_t lo = bucket_low(i), hi = bucket_high(i);
      const auto mid = static_cast<std::int64_t>(lo + (hi - 1 - lo) / 2);
      return std::clamp(mid, min_ns(), max_ns());
    }
  }
  return max_ns();
}

void LatencyHistogram::copy_counts(Counts& out) const noexcept {
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = buckets_[i].load(std::memory_order_relaxed);
}

std::int64_t LatencyHistogram::percentile_between_ns(const Counts& before, const Counts& after, double q) noexcept {
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < after.size(); ++i) total += after[i] - std::min(before[i], after[i]);
  if (total == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total))));
  std::uint64_t seen = 0;
  for (int i = 0; i < kBuckets; ++i) {
    const auto k = static_cast<std::size_t>(i);
    seen += after[k] - std::min(before[k], after[k]);
    if (seen >= rank) return static_cast<std::int64_t>(bucket_low(i) + (bucket_high(i) - 1 - bucket_low(i)) / 2);
  }
  return 0;
}

}  // namespace lbr::sched
