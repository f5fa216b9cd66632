// app/watchdog.hpp — lbrsim as a systemd service (packaging/systemd/lbrsim@.service): READY=1
// once the live threads run, STATUS= lines, and WATCHDOG=1 only while every live thread
// makes progress, so a stalled geometry, HAL or render thread gets the service restarted.
//
// Threads: ProgressWatchdog::check() runs on the watchdog thread (WatchdogThread); the
// probes read counters other threads bump (relaxed atomics). Nothing here is real-time code.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace lbr::app {

// Where the notifications go (sd_notify(3) in the service; a recording fake in tests).
class Notifier {
 public:
  virtual ~Notifier() = default;
  // One "KEY=VALUE" line: READY=1, WATCHDOG=1, STATUS=..., STOPPING=1.
  virtual void notify(const std::string& state) = 0;
};

// sd_notify(3) to $NOTIFY_SOCKET; does nothing when lbrsim was not started by systemd.
class SystemdNotifier final : public Notifier {
 public:
  SystemdNotifier();
  void notify(const std::string& state) override;
  [[nodiscard]] bool active() const noexcept { return active_; }
  // WatchdogSec= of the unit [µs]; 0 when the watchdog is off.
  [[nodiscard]] std::uint64_t watchdog_us() const noexcept { return watchdog_us_; }

 private:
  bool active_ = false;
  std::uint64_t watchdog_us_ = 0;
};

// A thread's heartbeat: its loop counter, or nullopt while the thread is not running (not
// started yet, or finished) — such a thread cannot stall.
struct ProgressProbe {
  std::string name;
  std::function<std::optional<std::uint64_t>()> count;
  bool needed_for_ready = true;  // READY=1 waits for this thread (false: optional, e.g. rendering)
};

class ProgressWatchdog {
 public:
  ProgressWatchdog(Notifier& n, std::vector<ProgressProbe> probes);

  // One look at the probes (every WatchdogSec/3 on the watchdog thread):
  //  * READY=1 once, when every probe needed_for_ready has reported a running thread;
  //  * then WATCHDOG=1 when every running thread's counter moved since the previous check;
  //  * otherwise no pet, and STATUS=stalled: NAMES (once per stall) — systemd restarts the
  //    service when WatchdogSec passes without a pet.
  // Returns true when it petted.
  bool check();
  [[nodiscard]] bool ready() const noexcept { return ready_; }
  [[nodiscard]] std::uint64_t pets() const noexcept { return pets_; }
  [[nodiscard]] const std::string& stalled() const noexcept { return stalled_; }

 private:
  Notifier& n_;
  std::vector<ProgressProbe> probes_;
  std::vector<std::optional<std::uint64_t>> last_;
  bool ready_ = false;
  std::uint64_t pets_ = 0;
  std::string stalled_;  // names of the stalled threads ("" when none)
};

struct LiveProgress;  // app/live.hpp
// Probes on the live pipeline's HAL and geometry threads (both needed for READY=1).
[[nodiscard]] std::vector<ProgressProbe> live_progress_probes(const LiveProgress& progress);

// Runs watchdog.check() every `period_ms` until stop() (or destruction).
class WatchdogThread {
 public:
  WatchdogThread(ProgressWatchdog& w, std::int64_t period_ms);
  ~WatchdogThread();
  WatchdogThread(const WatchdogThread&) = delete;
  WatchdogThread& operator=(const WatchdogThread&) = delete;
  void stop();

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace lbr::app
