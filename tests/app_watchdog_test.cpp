// The service watchdog (app/watchdog.hpp) with a fake notifier: READY=1 once the threads
// run, WATCHDOG=1 while their heartbeats move, no pet once one stalls, and petting again
// when it recovers; then end to end over a notify socket during a live run.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>
#include <chrono>
#include <vector>

#include "app/live.hpp"
#include "app/profile.hpp"
#include "app/watchdog.hpp"

using namespace lbr;

namespace {

class FakeNotifier final : public app::Notifier {
 public:
  void notify(const std::string& state) override { lines.push_back(state); }
  [[nodiscard]] int count(const std::string& s) const {
    int n = 0;
    for (const std::string& l : lines) n += l == s ? 1 : 0;
    return n;
  }
  std::vector<std::string> lines;
};

struct FakeThread {
  std::optional<std::uint64_t> loops;  // nullopt: not running
  app::ProgressProbe probe(const std::string& name, bool needed = true) {
    return {name, [this] { return loops; }, needed};
  }
};

}  // namespace

TEST(Watchdog, ReadyOnlyOnceTheThreadsRun) {
  FakeNotifier n;
  FakeThread geo, hal;
  app::ProgressWatchdog w(n, {geo.probe("geometry thread"), hal.probe("hal thread")});
  EXPECT_FALSE(w.check());
  geo.loops = 1;
  EXPECT_FALSE(w.check());  // the HAL thread has not started
  EXPECT_EQ(n.count("READY=1"), 0);
  hal.loops = 1;
  EXPECT_TRUE(w.check());
  EXPECT_TRUE(w.ready());
  EXPECT_EQ(n.lines, (std::vector<std::string>{"READY=1", "WATCHDOG=1"}));
}

TEST(Watchdog, PetsWhileCountersMoveAndStopsWhenAThreadStalls) {
  FakeNotifier n;
  FakeThread geo, hal;
  app::ProgressWatchdog w(n, {geo.probe("geometry thread"), hal.probe("hal thread")});
  geo.loops = 10, hal.loops = 5;
  ASSERT_TRUE(w.check());
  for (int i = 0; i < 5; ++i) {
    *geo.loops += 3, *hal.loops += 1;
    EXPECT_TRUE(w.check()) << i;
  }
  EXPECT_EQ(w.pets(), 6u);
  // The geometry thread stalls (e.g. stuck in a kernel call): no pet, one STATUS line.
  *hal.loops += 1;
  EXPECT_FALSE(w.check());
  *hal.loops += 1;
  EXPECT_FALSE(w.check());
  EXPECT_EQ(w.stalled(), "geometry thread");
  EXPECT_EQ(n.count("WATCHDOG=1"), 6);
  EXPECT_EQ(n.count("STATUS=stalled: geometry thread (watchdog not petted)"), 1);
  // Both stall: the status names both.
  EXPECT_FALSE(w.check());
  EXPECT_EQ(w.stalled(), "geometry thread, hal thread");
  // It recovers: petting resumes.
  *geo.loops += 1, *hal.loops += 1;
  EXPECT_TRUE(w.check());
  EXPECT_EQ(n.count("WATCHDOG=1"), 7);
  EXPECT_EQ(w.stalled(), "");
}

TEST(Watchdog, AnOptionalThreadCountsOnlyWhileItRuns) {
  FakeNotifier n;
  FakeThread geo, render;
  app::ProgressWatchdog w(n, {geo.probe("geometry thread"), render.probe("render thread", false)});
  geo.loops = 1;
  EXPECT_TRUE(w.check());  // ready without a render thread
  render.loops = 100;      // the window opens
  *geo.loops += 1;
  EXPECT_TRUE(w.check());
  *geo.loops += 1;         // the render thread hangs
  EXPECT_FALSE(w.check());
  EXPECT_EQ(w.stalled(), "render thread");
  render.loops.reset();    // the window closed: no longer watched
  *geo.loops += 1;
  EXPECT_TRUE(w.check());
}

// End to end over a real notify socket: libsystemd's sd_notify, the pipeline's heartbeats and
// the watchdog thread, as systemd would see them for lbrsim@.service.
TEST(Watchdog, NotifiesSystemdOverItsSocketDuringALiveRun) {
  const std::string path = testing::TempDir() + "/lbrsim-notify.sock";
  ::unlink(path.c_str());
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(path.size(), sizeof addr.sun_path);
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ::setenv("NOTIFY_SOCKET", path.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "30000", 1);  // 30 ms: a look every 10 ms
  ::unsetenv("WATCHDOG_PID");
  app::SystemdNotifier notifier;
  ASSERT_TRUE(notifier.active());
  EXPECT_EQ(notifier.watchdog_us(), 30000u);

  // systemd reads as they come; a full datagram queue would block sd_notify.
  std::vector<std::string> got;
  std::atomic<bool> done{false};
  std::thread reader([&] {
    char buf[512];
    while (!done.load()) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
      if (n > 0) got.emplace_back(buf, static_cast<std::size_t>(n));
      else std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT)) > 0;) got.emplace_back(buf, static_cast<std::size_t>(n));
  });
  app::LiveProgress progress;
  app::ProgressWatchdog w(notifier, app::live_progress_probes(progress));
  app::LiveOptions o;
  o.source = "emulator:demo";
  o.speed = 200.0;  // the demo in ~2 s, paced: the threads idle between samples
  o.progress = &progress;
  std::atomic<bool> stop{false};
  std::optional<app::LiveResult> r;
  {
    app::WatchdogThread t(w, 10);
    r.emplace(app::run_live(app::default_profile(), o, stop));
  }
  EXPECT_GT(r->removed_volume_mm3, 100.0);
  done.store(true);
  reader.join();
  ::close(fd);
  ::unlink(path.c_str());
  ::unsetenv("NOTIFY_SOCKET");  // sd_notify reads it at every call
  ::unsetenv("WATCHDOG_USEC");
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.front(), "READY=1");
  const auto pets = std::count(got.begin(), got.end(), std::string("WATCHDOG=1"));
  EXPECT_GE(pets, 20) << "a pet about every 10 ms of a ~2 s run";
  EXPECT_EQ(static_cast<std::uint64_t>(pets), w.pets());
}
