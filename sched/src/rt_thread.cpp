#include "sched/rt_thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>

#include <cerrno>
#include <cstring>
#include <mutex>

#include <spdlog/spdlog.h>

namespace lbr::sched {

namespace {
std::once_flag g_warn_once;
std::once_flag g_mlock_once;
bool g_mlock_ok = false;
}  // namespace

const char* to_string(RtMode m) noexcept { return m == RtMode::Fifo ? "fifo" : "non-rt"; }

std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t t_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(t_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

RtMode configure_current_thread(const RtConfig& cfg) noexcept {
  const std::string name = cfg.name.substr(0, 15);
  pthread_setname_np(pthread_self(), name.c_str());
  if (cfg.priority <= 0) {
    prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    return RtMode::NonRt;
  }
  std::string failure;
  if (cfg.lock_memory) {
    std::call_once(g_mlock_once, [] { g_mlock_ok = mlockall(MCL_CURRENT | MCL_FUTURE) == 0; });
    if (!g_mlock_ok) failure = "mlockall refused";
  }
  if (failure.empty() && cfg.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cfg.cpu, &set);
    if (const int e = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); e != 0)
      failure = "affinity to CPU " + std::to_string(cfg.cpu) + ": " + std::strerror(e);
  }
  if (failure.empty()) {
    sched_param sp{};
    sp.sched_priority = cfg.priority;
    if (const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp); e != 0)
      failure = "SCHED_FIFO " + std::to_string(cfg.priority) + ": " + std::strerror(e);
  }
  if (failure.empty()) return RtMode::Fifo;
  std::call_once(g_warn_once, [&] {
    try {
      spdlog::warn("real-time scheduling not permitted ({}); threads run SCHED_OTHER with 1 ns timer slack (rt_mode "
                   "non-rt)", failure);
    } catch (...) {
    }
  });
  sched_param sp{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  return RtMode::NonRt;
}

}  // namespace lbr::sched
