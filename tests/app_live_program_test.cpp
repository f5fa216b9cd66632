// The status bar's program position in `lbrsim run` (docs/ui.md): an emulator source knows
// its line and total time from its plan; a replay of the same run with --program finds the
// line from the sampled positions (nc::LineTracker) and shows the same lines the emulator
// gives, with the program's emulated time as the total. Read from the snapshots the
// geometry thread publishes, as the render thread reads them.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "gfx/exchange.hpp"
#include "nc/emulator.hpp"
#include "nc/movelist.hpp"

namespace lbr {
namespace {

// Plunge, three cuts, retract over the last point, a move to the next start, a second plunge.
const char* kProgram = R"(lbr-moves 1
start 10 10 5
tool 1
feed 6000
rapid 10 10 -2
line 60 10 -2
line 60 30 -3
line 20 30 -1
rapid 20 30 5
rapid 80 60 5
line 80 60 -2
)";

struct Seen {
  double machining_s = 0, total_s = 0;
  std::int64_t line = 0;
};

// Runs `o` with an exchange drained like a render thread; the published positions.
std::vector<Seen> run_and_watch(const app::Profile& p, app::LiveOptions o) {
  gfx::SolidExchange ex(1 << 14);
  o.exchange = &ex;
  std::atomic<bool> stop{false}, done{false};
  std::vector<Seen> seen;
  std::thread reader([&] {
    gfx::Snapshot s;
    for (;;) {
      const bool last = done.load();
      while (ex.take(s))
        if (s.stats.machining_s >= 0) seen.push_back({s.stats.machining_s, s.stats.total_s, s.stats.program_line});
      if (last) break;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  (void)app::run_live(p, o, stop);
  done.store(true);
  reader.join();
  return seen;
}

TEST(LiveProgram, AReplayWithTheProgramShowsTheLinesTheEmulatorGives) {
  const app::Profile p = app::default_profile();
  const std::string dir = testing::TempDir() + "/lbr_live_program";
  std::filesystem::create_directories(dir);
  const std::string program = dir + "/part.moves", log = dir + "/run.log";
  std::ofstream(program) << kProgram;
  const nc::Toolpath path = nc::parse_movelist(kProgram, "part.moves");
  const nc::Emulator em(path, app::live_emulator_limits(p));

  // Paced to about 1.5 s (as fast as possible, a run publishes only a couple of snapshots);
  // the log's timestamps keep that pace for the replay at speed 1.
  app::LiveOptions o;
  o.source = "emulator:" + program;
  o.speed = em.total_time_s() / 1.5;
  o.record = log;
  const std::vector<Seen> emulated = run_and_watch(p, o);
  ASSERT_GT(emulated.size(), 3U);
  for (const Seen& s : emulated) {
    EXPECT_DOUBLE_EQ(s.total_s, em.total_time_s());
    EXPECT_EQ(s.line, em.line_at(s.machining_s)) << "t " << s.machining_s;
  }
  EXPECT_NEAR(emulated.back().machining_s, em.total_time_s(), em.period_s());
  EXPECT_EQ(emulated.back().line, 11);  // the last move (the text's 11th line)

  app::LiveOptions r;
  r.source = "replay:" + log;
  r.speed = 1.0;
  r.program = program;
  const std::vector<Seen> replayed = run_and_watch(p, r);
  ASSERT_GT(replayed.size(), 3U);
  std::size_t same = 0;
  for (const Seen& s : replayed) {
    EXPECT_NEAR(s.total_s, nc::emulated_time_s(path, app::live_emulator_limits(p)), 1e-9);
    same += s.line == em.line_at(s.machining_s) ? 1 : 0;
  }
  std::printf("replay with --program: %zu of %zu snapshots show the emulator's line\n", same, replayed.size());
  EXPECT_GE(static_cast<double>(same), 0.95 * static_cast<double>(replayed.size()));
  EXPECT_NEAR(replayed.back().machining_s, em.total_time_s(), em.period_s());
  EXPECT_EQ(replayed.back().line, 11);

  r.program.clear();  // without the program: elapsed machining time only
  const std::vector<Seen> bare = run_and_watch(p, r);
  ASSERT_FALSE(bare.empty());
  EXPECT_LT(bare.back().total_s, 0);
  EXPECT_EQ(bare.back().line, -1);
  EXPECT_NEAR(bare.back().machining_s, em.total_time_s(), em.period_s());
}

}  // namespace
}  // namespace lbr
