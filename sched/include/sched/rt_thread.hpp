// sched/rt_thread.hpp — fixed-priority threads: SCHED_FIFO + mlockall + CPU affinity where
// the process is permitted, otherwise a single logged warning and SCHED_OTHER with 1 ns
// timer slack ("non-rt"). The live threads are event driven (docs/architecture.md), so there
// is no periodic loop here; sleep_until_ns() gives absolute CLOCK_MONOTONIC wake-ups.
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

}  // namespace lbr::sched
