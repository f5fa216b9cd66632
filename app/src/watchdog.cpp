// The service side of `lbrsim run` (app/watchdog.hpp): sd_notify through libsystemd, and the
// rule that the watchdog is petted only while the live threads make progress.
#include "app/watchdog.hpp"

#include "app/live.hpp"

#include <systemd/sd-daemon.h>

#include <chrono>
#include <cstdlib>

namespace lbr::app {

SystemdNotifier::SystemdNotifier() {
  const char* sock = std::getenv("NOTIFY_SOCKET");
  active_ = sock != nullptr && *sock != '\0';
  std::uint64_t us = 0;
  if (sd_watchdog_enabled(0, &us) > 0) watchdog_us_ = us;
}

void SystemdNotifier::notify(const std::string& state) {
  if (active_) (void)sd_notify(0, state.c_str());
}

ProgressWatchdog::ProgressWatchdog(Notifier& n, std::vector<ProgressProbe> probes)
    : n_(n), probes_(std::move(probes)), last_(probes_.size()) {}

bool ProgressWatchdog::check() {
  std::string stalled;
  bool all_running = true;
  for (std::size_t i = 0; i < probes_.size(); ++i) {
    const std::optional<std::uint64_t> now = probes_[i].count();
    if (!now) {
      if (probes_[i].needed_for_ready) all_running = false;
    } else if (last_[i] && *now == *last_[i]) {
      stalled += (stalled.empty() ? "" : ", ") + probes_[i].name;
    }
    last_[i] = now;
  }
  if (!ready_) {
    if (!all_running) return false;  // start-up: the threads are not all running yet
    ready_ = true;
    n_.notify("READY=1");
    stalled.clear();  // the first counts only set the baseline
  }
  if (!stalled.empty()) {
    if (stalled != stalled_) n_.notify("STATUS=stalled: " + stalled + " (watchdog not petted)");
    stalled_ = stalled;
    return false;
  }
  stalled_.clear();
  n_.notify("WATCHDOG=1");
  ++pets_;
  return true;
}

std::vector<ProgressProbe> live_progress_probes(const LiveProgress& pr) {
  using C = std::optional<std::uint64_t>;
  return {
      {"hal thread", [&pr]() -> C { return pr.hal_running.load() ? C(pr.hal_loops.load()) : std::nullopt; }, true},
      {"geometry thread", [&pr]() -> C { return pr.geometry_running.load() ? C(pr.geometry_loops.load()) : std::nullopt; },
       true},
  };
}

WatchdogThread::WatchdogThread(ProgressWatchdog& w, std::int64_t period_ms) {
  thread_ = std::thread([this, &w, period_ms] {
    while (!stop_.load(std::memory_order_acquire)) {
      (void)w.check();
      for (std::int64_t t = 0; t < period_ms && !stop_.load(std::memory_order_acquire); t += 10)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
}

WatchdogThread::~WatchdogThread() { stop(); }

void WatchdogThread::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

}  // namespace lbr::app
