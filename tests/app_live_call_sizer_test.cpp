// The live geometry thread's call sizing (app/src/live/call_sizer.hpp), driven by a fake clock
// and a fake kernel whose cost per work unit changes with the workload's phase: samples arrive
// at 1 kHz, each with its work units; every call takes the longest prefix of the queue the
// sizer allows (at least one sample), the fake kernel "takes" cost × units, and the test checks
// the calls' sizes and times, that every sample is applied exactly once, and that the queue
// never grows without bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <vector>

#include "live/call_sizer.hpp"

using lbr::app::live::CallSizer;
using lbr::app::live::CallSizerConfig;
using lbr::app::live::DutyBank;

namespace {

struct Sample {
  std::int64_t rx_ns = 0;
  double units = 0.0;
  std::uint64_t id = 0;
};

struct Call {
  std::int64_t start_ns = 0, dur_ns = 0, target_ns = 0;
  std::size_t samples = 0;
};

struct Sim {
  std::vector<Call> calls;
  std::vector<std::int64_t> lag_ns;   // per applied sample
  std::vector<std::uint64_t> applied;  // ids in order
  std::size_t max_queue = 0;
};

// `ns_per_unit(t)`: the fake kernel's true cost; `overhead_ns`: fixed cost per call;
// `units_per_sample`: work of each sample. Runs `seconds` of 1 kHz samples, then drains.
template <class Cost>
Sim simulate(CallSizer& sizer, Cost ns_per_unit, std::int64_t overhead_ns, double units_per_sample, int seconds) {
  Sim sim;
  std::deque<Sample> queue;
  std::int64_t now = 0;
  std::uint64_t next_id = 0;
  const std::int64_t end_ns = std::int64_t{seconds} * 1'000'000'000;
  auto arrive_until = [&](std::int64_t t) {
    for (; static_cast<std::int64_t>(next_id) * 1'000'000 <= std::min(t, end_ns); ++next_id)
      queue.push_back({static_cast<std::int64_t>(next_id) * 1'000'000, units_per_sample, next_id});
  };
  while (now <= end_ns || !queue.empty()) {
    arrive_until(now);
    sim.max_queue = std::max(sim.max_queue, queue.size());
    if (queue.empty()) {
      now += 100'000;  // idle poll
      continue;
    }
    const std::int64_t target = sizer.target_ns(now - queue.front().rx_ns);
    const double budget = sizer.budget_units(target);
    double units = 0.0;
    std::size_t n = 0;
    while (n < queue.size() && (n == 0 || units + queue[n].units <= budget)) units += queue[n++].units;
    const auto dur = static_cast<std::int64_t>(static_cast<double>(overhead_ns) + ns_per_unit(now) * units);
    sizer.observe(units, dur);
    sim.calls.push_back({now, dur, target, n});
    now += dur;
    for (std::size_t k = 0; k < n; ++k) {
      sim.lag_ns.push_back(now - queue.front().rx_ns);
      sim.applied.push_back(queue.front().id);
      queue.pop_front();
    }
  }
  return sim;
}

std::int64_t percentile(std::vector<std::int64_t> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

void expect_every_sample_once(const Sim& sim, int seconds) {
  ASSERT_EQ(sim.applied.size(), static_cast<std::size_t>(seconds) * 1000 + 1);
  for (std::size_t i = 0; i < sim.applied.size(); ++i) ASSERT_EQ(sim.applied[i], i) << "applied out of order or twice";
}

}  // namespace

TEST(CallSizer, TargetGrowsWithTheBacklogUpToTheMaximum) {
  CallSizerConfig c;
  c.target_ns = 2'000'000;
  c.max_ns = 40'000'000;
  c.catch_up = 0.5;
  const CallSizer s(c);
  EXPECT_EQ(s.target_ns(0), 2'000'000);
  EXPECT_EQ(s.target_ns(-5), 2'000'000);
  EXPECT_EQ(s.target_ns(10'000'000), 7'000'000);
  EXPECT_EQ(s.target_ns(1'000'000'000), 40'000'000);
}

TEST(CallSizer, SlowerCallsRaiseTheRateAtOnceFasterOnesLowerItSlowly) {
  CallSizerConfig c;
  c.initial_ns_per_unit = 1000.0;
  c.rise = 0.5;
  c.fall = 0.05;
  CallSizer s(c);
  s.observe(100.0, 1'000'000);  // 10 000 ns per unit
  EXPECT_DOUBLE_EQ(s.ns_per_unit(), 5500.0);
  s.observe(100.0, 100'000);  // 1 000 ns per unit
  EXPECT_DOUBLE_EQ(s.ns_per_unit(), 5500.0 - 0.05 * 4500.0);
  s.observe(0.0, 1'000'000);  // no units: no information
  EXPECT_DOUBLE_EQ(s.ns_per_unit(), 5500.0 - 0.05 * 4500.0);
  EXPECT_DOUBLE_EQ(s.budget_units(2'000'000), 2'000'000 / s.ns_per_unit());
}

TEST(CallSizer, OnlyASweepWellOverTheTargetIsCut) {
  CallSizerConfig c;
  c.initial_ns_per_unit = 1000.0;
  c.split_factor = 2.0;
  const CallSizer s(c);
  EXPECT_EQ(s.pieces(3'000.0, 2'000'000, 64), 1);   // 3 ms: 1.5 × the target, left whole
  EXPECT_EQ(s.pieces(9'000.0, 2'000'000, 64), 5);   // 9 ms: 5 pieces of 1.8 ms
  EXPECT_EQ(s.pieces(1e9, 2'000'000, 64), 64);      // capped
}

// A phase change: the kernel becomes 10x costlier per unit (a tight helix turn). The model
// follows within a few calls: no call after the first slow one is longer than 2x the
// target plus one sample's work, and the lag p99 stays within a few targets.
TEST(CallSizer, FollowsAPhaseOfCostlierWorkWithinAFewCalls) {
  CallSizerConfig c;
  c.target_ns = 2'000'000;
  CallSizer sizer(c);
  const std::int64_t change_ns = 2'000'000'000;
  auto cost = [&](std::int64_t t) { return t < change_ns ? 200.0 : 2000.0; };  // [ns per unit]
  const Sim sim = simulate(sizer, cost, 50'000, 300.0, 4);  // 0.35 / 0.65 ms of work per sample
  expect_every_sample_once(sim, 4);
  int slow = 0;
  for (const Call& k : sim.calls)
    if (k.start_ns >= change_ns && k.dur_ns > 2 * k.target_ns + 50'000 + 600'000) ++slow;
  EXPECT_LE(slow, 2) << "calls far over their target after the phase change";
  std::vector<std::int64_t> before, after;
  for (std::size_t i = 0; i < sim.lag_ns.size(); ++i)
    (static_cast<std::int64_t>(i) * 1'000'000 < change_ns ? before : after).push_back(sim.lag_ns[i]);
  EXPECT_LE(percentile(before, 0.99), 3'000'000);
  EXPECT_LE(percentile(after, 0.99), 6'000'000);
  EXPECT_LE(sim.max_queue, 20u);
}

// Overload: a fixed cost per call that small calls cannot afford (1.9 ms per call, 0.2 ms
// per sample: calls of one or two samples would need 2.1 or 2.3 ms per 1 or 2 ms of
// samples; three or more keep up). The target grows
// with the backlog, the calls get longer, and the queue stays bounded: throughput above
// real time, nothing dropped.
TEST(CallSizer, LongerCallsWhenBehindKeepThroughputAboveRealTime) {
  CallSizerConfig c;
  c.target_ns = 1'000'000;
  c.initial_ns_per_unit = 200.0;
  CallSizer sizer(c);
  auto cost = [](std::int64_t) { return 200.0; };
  const Sim sim = simulate(sizer, cost, 1'900'000, 1000.0, 5);
  expect_every_sample_once(sim, 5);
  EXPECT_LE(sim.max_queue, 40u) << "the backlog grew: throughput below real time";
  std::size_t most = 0;
  for (const Call& k : sim.calls) most = std::max(most, k.samples);
  EXPECT_GE(most, 3u) << "behind, calls must take several samples";
  EXPECT_LE(percentile(sim.lag_ns, 0.99), 15'000'000);
}

TEST(DutyBank, ShortTicksWithinTheDutyNeverRest) {
  DutyBank bank(0.7, 200'000'000, 0);
  std::int64_t t = 0;
  for (int i = 0; i < 1000; ++i) {  // 1 ms of work every 2 ms: 50 % < 70 %
    EXPECT_EQ(bank.spend(t, t + 1'000'000), 0);
    t += 2'000'000;
  }
  EXPECT_DOUBLE_EQ(bank.credit_ns(), 199'000'000.0);  // full (0.2 s) less the last tick's work
}

TEST(DutyBank, SteadyOverloadRestsToHoldTheDuty) {
  DutyBank bank(0.5, 200'000'000, 0);
  std::int64_t t = 0, t_half = 0;
  int rests = 0;
  for (int i = 0; i < 400; ++i) {  // 10-ms ticks back to back, resting as told
    if (i == 200) t_half = t;
    const std::int64_t end = t + 10'000'000;
    const std::int64_t rest = bank.spend(t, end);
    rests += rest > 0;
    t = end + rest;
  }
  // The banked 0.2 s goes first (the first tick spends 10 ms of a full bank, then a net 5 ms
  // each: 39 ticks without a rest), then work : wall = duty.
  EXPECT_EQ(rests, 400 - 39);
  EXPECT_NEAR(200 * 10e6 / static_cast<double>(t - t_half), 0.5, 1e-6);
}

TEST(DutyBank, ALongTickRestsAtMostTheBurstOverTheDuty) {
  // A 35-s tick (a 5-axis stream far behind, before ticks had a budget) used to be followed
  // by a rest of (35 − 0.2) / 0.7 = 50 s while the ring filled; the debt is capped now.
  DutyBank bank(0.7, 200'000'000, 0);
  const std::int64_t rest = bank.spend(0, 35'000'000'000);
  EXPECT_GT(rest, 0);
  EXPECT_LE(rest, static_cast<std::int64_t>(200'000'000 / 0.7) + 1);
  EXPECT_DOUBLE_EQ(bank.credit_ns(), -200'000'000.0);
}
