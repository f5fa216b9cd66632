// Latency histogram (bucket bounds, percentiles within the documented 1/32 error) and the
// real-time thread setup (FIFO where permitted, otherwise non-rt with 1 ns timer slack).
#include <gtest/gtest.h>

#include <sys/prctl.h>

#include <atomic>
#include <random>

#include "sched/latency_stats.hpp"
#include "sched/rt_thread.hpp"

using namespace lbr::sched;

TEST(LatencyHistogram, BucketsCoverEveryValueOnce) {
  for (std::uint64_t v : {0ULL, 1ULL, 31ULL, 32ULL, 33ULL, 63ULL, 64ULL, 1000ULL, 123456789ULL, (1ULL << 62) + 5}) {
    const int b = LatencyHistogram::bucket_of(v);
    EXPECT_LE(LatencyHistogram::bucket_low(b), v) << v;
    EXPECT_GT(LatencyHistogram::bucket_high(b), v) << v;
    EXPECT_LT(b, LatencyHistogram::kBuckets);
  }
  EXPECT_EQ(LatencyHistogram::bucket_of(~0ULL), LatencyHistogram::kBuckets - 1);
}

TEST(LatencyHistogram, PercentilesOfUniformValues) {
  LatencyHistogram h;
  for (int i = 1; i <= 10000; ++i) h.record(i * 1000);  // 1 µs .. 10 ms
  EXPECT_EQ(h.count(), 10000u);
  EXPECT_EQ(h.max_ns(), 10'000'000);
  EXPECT_EQ(h.min_ns(), 1000);
  EXPECT_NEAR(static_cast<double>(h.percentile_ns(0.5)), 5'000'000.0, 5'000'000.0 / 32);
  EXPECT_NEAR(static_cast<double>(h.percentile_ns(0.99)), 9'900'000.0, 9'900'000.0 / 32);
  EXPECT_EQ(h.percentile_ns(1.0), 10'000'000);
  EXPECT_NEAR(h.mean_ns(), 5'000'500.0, 1.0);
  h.reset();
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.percentile_ns(0.5), 0);
}

TEST(LatencyHistogram, NegativeCountsAsZero) {
  LatencyHistogram h;
  h.record(-5);
  EXPECT_EQ(h.max_ns(), 0);
  EXPECT_EQ(h.percentile_ns(0.5), 0);
}

// Windows (the status line's "p99 since last line", tools/soak.sh): the percentile of what
// was recorded between two copies of the counts, not of the whole run.
TEST(LatencyHistogram, PercentileBetweenTwoCopies) {
  LatencyHistogram h;
  for (int i = 0; i < 1000; ++i) h.record(1'000'000);  // 1 ms
  LatencyHistogram::Counts before{}, after{};
  h.copy_counts(before);
  for (int i = 0; i < 100; ++i) h.record(50'000'000);  // then 100 values of 50 ms
  h.copy_counts(after);
  const double p99 = static_cast<double>(LatencyHistogram::percentile_between_ns(before, after, 0.99));
  EXPECT_NEAR(p99, 50e6, 50e6 / 32);
  EXPECT_NEAR(static_cast<double>(h.percentile_ns(0.5)), 1e6, 1e6 / 32);  // the whole run: still 1 ms
  EXPECT_EQ(LatencyHistogram::percentile_between_ns(after, after, 0.99), 0);  // empty window
}

TEST(RtThread, FifoOrNonRtWithMinimalSlack) {
  std::atomic<int> mode{-1};
  std::atomic<long> slack{-1};
  std::thread t([&] {
    RtConfig c;
    c.name = "lbr-test";
    c.priority = 10;
    c.lock_memory = false;
    const RtMode m = configure_current_thread(c);
    mode = m == RtMode::Fifo ? 1 : 0;
    slack = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
  });
  t.join();
  ASSERT_NE(mode.load(), -1);
  if (mode.load() == 0) {
    EXPECT_EQ(slack.load(), 1) << "non-rt fallback must set 1 ns timer slack";
  }
}

