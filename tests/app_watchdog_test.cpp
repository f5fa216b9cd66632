// The service watchdog (app/watchdog.hpp) with a fake notifier: READY=1 once the threads
// run, WATCHDOG=1 while their heartbeats move, no pet once one stalls, and petting again
// when it recovers.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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
