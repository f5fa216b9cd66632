// SpscRing: element lifetime balance, FIFO order across two threads, overrun counting,
// exact high-water mark. Also built with -fsanitize=thread (ctest label tsan).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "sched/spsc_ring.hpp"

using lbr::sched::SpscRing;

namespace {

struct Counted {
  static inline std::atomic<int> live{0}, constructed{0}, destroyed{0};
  int v = 0;
  explicit Counted(int x) noexcept : v(x) { ++live; ++constructed; }
  Counted(const Counted& o) noexcept : v(o.v) { ++live; ++constructed; }
  Counted(Counted&& o) noexcept : v(o.v) { ++live; ++constructed; }
  Counted& operator=(const Counted&) = default;
  Counted& operator=(Counted&&) = default;
  ~Counted() { --live; ++destroyed; }
  static void reset() { live = 0; constructed = 0; destroyed = 0; }
};

}  // namespace

TEST(SpscRing, ConstructionDestructionBalance) {
  Counted::reset();
  {
    SpscRing<Counted> ring(8);
    EXPECT_EQ(Counted::live.load(), 0) << "no element may exist before a push";
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(ring.try_emplace(i));
    EXPECT_EQ(Counted::live.load(), 5);
    ASSERT_NE(ring.front(), nullptr);
    EXPECT_EQ(ring.front()->v, 0);
    ring.pop();
    ring.pop();
    EXPECT_EQ(Counted::live.load(), 3);
    EXPECT_EQ(ring.size(), 3u);
    // Wrap around several times.
    for (int round = 0; round < 20; ++round) {
      ASSERT_TRUE(ring.try_push(Counted(100 + round)));
      ASSERT_NE(ring.front(), nullptr);
      ring.pop();
    }
    EXPECT_EQ(Counted::live.load(), 3);
  }  // destructor destroys the 3 left
  EXPECT_EQ(Counted::live.load(), 0);
  EXPECT_EQ(Counted::constructed.load(), Counted::destroyed.load());
}

TEST(SpscRing, OverrunCountingAndHighWater) {
  SpscRing<int> ring(4);
  EXPECT_EQ(ring.capacity(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(99));
  EXPECT_FALSE(ring.try_push(98));
  EXPECT_EQ(ring.overruns(), 2u);
  EXPECT_EQ(ring.high_water(), 4u);
  int out = -1;
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 0);
  EXPECT_TRUE(ring.try_push(4));  // room again: not an overrun
  EXPECT_EQ(ring.overruns(), 2u);
  for (int want = 1; want <= 4; ++want) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, want) << "overrun values must not have entered the ring";
  }
  EXPECT_FALSE(ring.try_pop(out));
  EXPECT_EQ(ring.front(), nullptr);
}

TEST(SpscRing, HighWaterIsExactWhenConsumerKeepsUp) {
  SpscRing<int> ring(1024);
  for (int i = 0; i < 5000; ++i) {
    ASSERT_TRUE(ring.try_push(i));
    if (i % 3 == 2) {  // let up to 3 accumulate
      for (int k = 0; k < 3; ++k) ring.pop();
    }
  }
  EXPECT_EQ(ring.high_water(), 3u);
  EXPECT_EQ(ring.overruns(), 0u);
}

TEST(SpscRing, RejectsZeroCapacity) { EXPECT_THROW(SpscRing<int>(0), std::invalid_argument); }

TEST(SpscRing, TwoThreadOrderedSum) {
  constexpr std::uint64_t kN = 200000;
  SpscRing<std::uint64_t> ring(64);
  std::uint64_t failed_pushes = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 1; i <= kN; ++i) {
      while (!ring.try_push(i)) {
        ++failed_pushes;
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t sum = 0, expected_next = 1, out_of_order = 0;
  for (std::uint64_t got = 0; got < kN;) {
    std::uint64_t* v = ring.front();
    if (v == nullptr) {
      std::this_thread::yield();
      continue;
    }
    if (*v != expected_next) ++out_of_order;
    expected_next = *v + 1;
    sum += *v;
    ring.pop();
    ++got;
  }
  producer.join();
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(sum, kN * (kN + 1) / 2);
  EXPECT_EQ(ring.overruns(), failed_pushes);  // every refused push was counted
  EXPECT_LE(ring.high_water(), 64u);
  EXPECT_GE(ring.high_water(), 1u);
}
