// sched/rt_thread.hpp — fixed-priority threads: SCHED_FIFO + mlockall + CPU affinity where
// the process is permitted, otherwise a single logged warning and SCHED_OTHER with 1 ns
// timer slack ("non-rt"). Plus a periodic loop on CLOCK_MONOTONIC absolute deadlines that
// records wake-up latency and missed deadlines.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>

#include "sched/latency_stats.hpp"

namespace lbr::sched {

struct RtConfig {
  std::string name = "lbr";   // thread name (15 characters at most are kept)
  int priority = 0;           // SCHED_FIFO priority 1..99; 0 = do not ask for real time
  int cpu = -1;               // pin to this CPU; -1 = no affinity
  bool lock_memory = true;    // mlockall(MCL_CURRENT | MCL_FUTURE), once per process
};

enum class RtMode { Fifo, NonRt };
[[nodiscard]] const char* to_string(RtMode m) noexcept;  // "fifo" / "non-rt"

// Applies `cfg` to the calling thread. Never throws. When SCHED_FIFO, mlockall or the
// affinity is refused, logs one warning per process (not per thread) and falls back to
// SCHED_OTHER with PR_SET_TIMERSLACK = 1 ns. Not RT-safe itself (call it at thread start).
RtMode configure_current_thread(const RtConfig& cfg) noexcept;

// Monotonic clock [ns] (CLOCK_MONOTONIC). RT-safe.
[[nodiscard]] std::int64_t now_ns() noexcept;
// Sleeps until the absolute CLOCK_MONOTONIC time `t_ns`. RT-safe.
void sleep_until_ns(std::int64_t t_ns) noexcept;

// A thread that runs tick() every period on absolute deadlines. A tick that overruns its
// period counts a miss and the schedule skips the lost periods (no burst of catch-up
// ticks). tick() returns false to stop the loop.
class PeriodicThread {
 public:
  PeriodicThread() = default;
  ~PeriodicThread() { stop(); }
  PeriodicThread(const PeriodicThread&) = delete;
  PeriodicThread& operator=(const PeriodicThread&) = delete;

  // Setup: starts the thread. `tick` must be noexcept in spirit (the RT rules).
  void start(const RtConfig& cfg, std::int64_t period_ns, std::function<bool()> tick);
  // Asks the loop to end after the current tick and joins it. Idempotent.
  void stop();
  void join();
  [[nodiscard]] bool running() const noexcept { return running_.load(std::memory_order_acquire); }
  [[nodiscard]] RtMode mode() const noexcept { return mode_.load(std::memory_order_acquire); }
  [[nodiscard]] const DeadlineStats& stats() const noexcept { return stats_; }

 private:
  std::thread thread_;
  std::atomic<bool> stop_{false}, running_{false};
  std::atomic<RtMode> mode_{RtMode::NonRt};
  DeadlineStats stats_;
};

}  // namespace lbr::sched
