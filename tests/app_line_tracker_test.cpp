// nc::LineTracker (the program line of a live source, `run --program`): fed the emulator's
// own samples of bundled programs, it names the line the emulator's plan gives
// (nc::Emulator::line_at, what `run --source emulator:` and `view --animate` show) except
// where the two definitions differ by construction: on blend arcs (the plan gives the line
// the arc leaves, the nearest move may be the one it enters) and at stops (dwell, tool
// change: the plan's line, the tracker the move the tool stands at the end of), and at a
// corner itself, which both moves touch.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "app/live.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/emulator.hpp"
#include "nc/line_tracker.hpp"

namespace lbr {
namespace {

const std::string kConfig = std::string(LBR_SOURCE_DIR) + "/config/";

struct Agreement {
  std::size_t samples = 0, same = 0, explained = 0;
};

Agreement compare(const std::string& program) {
  const app::Profile profile = app::load_profile(kConfig + "profiles/default-mill3.toml");
  const nc::Toolpath path = app::load_toolpath(kConfig + "programs/" + program, profile);
  nc::Emulator em(path, app::live_emulator_limits(profile));
  nc::LineTracker tracker(path);
  Agreement a;
  nc::Sample s;
  const auto& plans = em.plans();
  while (em.next(s)) {
    const int want = em.line_at(s.t_s), got = tracker.update(s.axes);
    ++a.samples;
    if (want == got) {
      ++a.same;
      continue;
    }
    // Which piece the sample lies in: a blend arc or a hold explains the difference, and so
    // does a sample still at a corner (within 1 µm of the piece's start: both moves touch it).
    auto it = std::lower_bound(plans.begin(), plans.end(), s.t_s,
                               [](const nc::Emulator::Plan& p, double t) { return p.t0_s + p.duration_s < t; });
    const bool at_corner = it != plans.end() && std::hypot(s.axes[0] - it->from[0], s.axes[1] - it->from[1],
                                                           s.axes[2] - it->from[2]) < 1e-3;
    if (it != plans.end() && (it->kind != nc::Emulator::PieceKind::Line || at_corner)) ++a.explained;
    else ADD_FAILURE() << program << ": t " << s.t_s << " s: emulator line " << want << ", tracker line " << got;
  }
  std::cout << program << ": " << a.samples << " samples, same line " << a.same << ", differing on blend arcs / holds "
            << a.explained << "\n";
  return a;
}

TEST(LineTracker, NamesTheEmulatorsLineOnEveryStraightPieceOfCamPocket) {
  const Agreement a = compare("cam-pocket.ngc");
  ASSERT_GT(a.samples, 1000U);
  EXPECT_GE(static_cast<double>(a.same), 0.97 * static_cast<double>(a.samples));
}

TEST(LineTracker, TellsARetractFromThePlungeUnderIt) {
  nc::Toolpath p;
  p.start = {0, 0, 5, 0, 0, 0};
  auto move = [&](nc::SegmentKind k, double x, double y, double z, int line) {
    nc::Segment s;
    s.kind = k;
    s.end = {x, y, z, 0, 0, 0};
    s.line = line;
    s.feed_mm_per_min = 600;
    p.segments.push_back(s);
  };
  move(nc::SegmentKind::Feed, 0, 0, -2, 10);   // plunge
  move(nc::SegmentKind::Rapid, 0, 0, 5, 11);   // retract over it
  move(nc::SegmentKind::Rapid, 20, 0, 5, 12);  // traverse
  nc::LineTracker t(p);
  EXPECT_EQ(t.update({0, 0, 4, 0, 0, 0}), 10);
  EXPECT_EQ(t.update({0, 0, -2, 0, 0, 0}), 10);
  EXPECT_EQ(t.update({0, 0, 1, 0, 0, 0}), 11);   // same segment, travelled upwards
  EXPECT_EQ(t.update({10, 0, 5, 0, 0, 0}), 12);
  EXPECT_EQ(t.update({10, 0, 5, 0, 0, 0}), 12);  // standing still keeps the match
  EXPECT_EQ(t.relocks(), 0U);
  EXPECT_EQ(t.update({0, 0, 0, 0, 0, 0}), 10);   // far behind the window: re-locked on the whole program
  EXPECT_EQ(t.relocks(), 1U);
}

}  // namespace
}  // namespace lbr
