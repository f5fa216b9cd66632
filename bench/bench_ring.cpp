// Cost of the live hand-over: SpscRing<AxisSample> push + pop per sample, single thread
// (pure instruction cost) and across two threads (cache-line transfer included).
#include <benchmark/benchmark.h>

#include <atomic>
#include <thread>

#include "hal/sample.hpp"
#include "sched/spsc_ring.hpp"

namespace {

using lbr::hal::AxisSample;

void BM_RingPushPopSameThread(benchmark::State& state) {
  lbr::sched::SpscRing<AxisSample> ring(4096);
  AxisSample s;
  for (auto _ : state) {
    s.seq++;
    benchmark::DoNotOptimize(ring.try_push(s));
    AxisSample* p = ring.front();
    benchmark::DoNotOptimize(p);
    ring.pop();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RingPushPopSameThread);

void BM_RingTwoThreads(benchmark::State& state) {
  const std::int64_t n = 1 << 20;
  for (auto _ : state) {
    lbr::sched::SpscRing<AxisSample> ring(4096);
    std::thread consumer([&] {
      std::int64_t got = 0;
      while (got < n) {
        if (AxisSample* p = ring.front()) {
          benchmark::DoNotOptimize(p->q[0]);
          ring.pop();
          ++got;
        }
      }
    });
    AxisSample s;
    for (std::int64_t i = 0; i < n; ++i) {
      s.seq = static_cast<std::uint64_t>(i);
      while (!ring.try_push(s)) {
      }
    }
    consumer.join();
  }
  state.SetItemsProcessed(state.iterations() * n);
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(state.iterations() * n), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RingTwoThreads)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
