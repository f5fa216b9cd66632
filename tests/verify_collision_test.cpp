// verify/: collision checks against the stock of each move's moment (issue 16). Volumes are
// checked against hand-computed values on the built-in default profile (box 100 x 80 x 30,
// top at Z0; T1 flat D10, flutes 30, gauge length 60, holder D40).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/gcode.hpp"
#include "verify/events.hpp"
#include "verify/intrusion.hpp"

using namespace lbr;

namespace {

app::BatchResult run(const std::string& program, int batch_moves = 512) {
  app::Profile p = app::default_profile();
  p.batch_moves = batch_moves;
  p.threads = 1;
  const nc::Toolpath path = nc::interpret_gcode(program, "t.ngc", app::gcode_options(p));
  return app::run_batch(p, path);
}

std::size_t count_kind(const std::vector<verify::Event>& ev, verify::EventKind k) {
  std::size_t n = 0;
  for (const verify::Event& e : ev) n += e.kind == k ? 1 : 0;
  return n;
}

}  // namespace

TEST(IntrusionProbe, APlungeMeetsTheCylinderItWouldCut) {
  app::Profile p = app::default_profile();
  geom::LbrSolid solid(p.solid);
  geom::Tool t;
  t.diameter_mm = 10.0;
  const geom::CutterShape shape = geom::CutterShape::build(t, p.solid.chord_tol_mm);
  const geom::Pose from{{50, 40, 10}, {0, 0, 1}}, to{{50, 40, -5}, {0, 0, 1}};
  verify::IntrusionProbe probe;
  const verify::Intrusion in = probe.measure(solid, geom::Sweep(shape, from, to), 0.01);
  const double expected = std::numbers::pi * 25.0 * 5.0;  // r = 5, 5 mm into the box
  EXPECT_NEAR(in.volume_mm3, expected, 0.001 * expected);
  EXPECT_GT(in.deep_mm3, 0.0);
  EXPECT_NEAR(in.depth_mm, 5.0, 1e-9);
  // The probe leaves the solid as it was.
  EXPECT_DOUBLE_EQ(solid.volume_mm3(), solid.initial_volume_mm3());
}

TEST(IntrusionProbe, AGrazeWithinTheMarginIsNotDeep) {
  app::Profile p = app::default_profile();
  geom::LbrSolid solid(p.solid);
  geom::Tool t;
  t.diameter_mm = 10.0;
  const geom::CutterShape shape = geom::CutterShape::build(t, p.solid.chord_tol_mm);
  // The tool's side 0.005 mm inside the box's X0 face, along it.
  const geom::Pose from{{-4.995, 10, -5}, {0, 0, 1}}, to{{-4.995, 70, -5}, {0, 0, 1}};
  verify::IntrusionProbe probe;
  const verify::Intrusion in = probe.measure(solid, geom::Sweep(shape, from, to), 0.01);
  EXPECT_GT(in.volume_mm3, 0.0);
  EXPECT_EQ(in.deep_mm3, 0.0);
}

TEST(CollisionChecks, ARapidThroughTheStockIsReportedWithItsVolume) {
  const app::BatchResult r = run(
      "G21 G90\nT1 M6 G43 H1\nG0 X-10 Y40 Z10\nG0 Z-5\nG0 X110\nG0 Z10\nM2\n");
  ASSERT_EQ(r.events.size(), 1u);
  const verify::Event& e = r.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::RapidIntoMaterial);
  EXPECT_EQ(e.severity(), verify::Severity::Error);
  EXPECT_EQ(e.line, 5);
  EXPECT_EQ(e.source, "t.ngc");
  EXPECT_EQ(e.tool, 1);
  EXPECT_NEAR(e.volume_mm3, 100.0 * 10.0 * 5.0, 0.01 * 5000.0);  // a 100 x 10 x 5 slot
  EXPECT_NEAR(e.depth_mm, 5.0, 1e-9);
  EXPECT_NEAR(r.removed_volume_mm3, e.volume_mm3, 1e-6 * 5000.0);  // it is all the rapid cut
}

TEST(CollisionChecks, ARapidThroughASlotCutEarlierInTheSameBatchIsClean) {
  // The feed cuts the slot; the rapid returns through it. Both are in one kernel batch, so
  // the checker must judge the rapid against the stock after the feed, not before the batch.
  const app::BatchResult r = run(
      "G21 G90\nT1 M6 G43 H1\nG0 X-10 Y40 Z10\nG0 Z-5\nG1 X110 F600\nG0 X-10\nG0 Z10\nM2\n");
  EXPECT_TRUE(r.events.empty()) << verify::describe(r.events.at(0));
  EXPECT_NEAR(r.removed_volume_mm3, 5000.0, 0.01 * 5000.0);
}

TEST(CollisionChecks, AForgottenG43PutsShankAndHolderIntoTheStockAtTheRightLine) {
  const std::string body = "G0 X20 Y20 Z5\nG1 Z-3 F300\nG1 X80 F600\nG1 Y60\nG0 Z20\nM2\n";
  const app::BatchResult bad = run("G21 G90 G17\nT1 M6\n" + body);
  ASSERT_FALSE(bad.events.empty());
  // Without G43 the tip is 60 mm below the programmed Z: the flutes (30 mm) reach from the
  // tip to Z-25 at line 3, the shank from there to Z5 through the 30 mm box.
  EXPECT_EQ(count_kind(bad.events, verify::EventKind::ShankInMaterial), 1u);
  for (const verify::Event& e : bad.events) {
    if (e.kind != verify::EventKind::ShankInMaterial) continue;
    EXPECT_EQ(e.line, 3);
    EXPECT_EQ(e.last_line, 7);  // one event for the run of offending moves
    EXPECT_EQ(e.moves, 5u);
    EXPECT_NEAR(e.position.z, -55.0, 1e-9);
  }
  EXPECT_GE(verify::count(bad.events).errors, 2u);

  const app::BatchResult good = run("G21 G90 G17\nT1 M6 G43 H1\n" + body);
  EXPECT_TRUE(good.events.empty());
}

TEST(CollisionChecks, TheBundledDemoIsClean) {
  app::Profile p = app::default_profile();
  p.threads = 1;
  const app::BatchResult r = app::run_batch(p, app::demo_toolpath());
  EXPECT_TRUE(r.events.empty());
}

TEST(CollisionChecks, DisabledChecksReportNothingAndCutTheSame) {
  const std::string prog = "G21 G90\nT1 M6 G43 H1\nG0 X-10 Y40 Z10\nG0 Z-5\nG0 X110\nG0 Z10\nM2\n";
  app::Profile p = app::default_profile();
  p.threads = 1;
  const nc::Toolpath path = nc::interpret_gcode(prog, "t.ngc", app::gcode_options(p));
  const app::BatchResult on = app::run_batch(p, path);
  p.checks.enabled = false;
  const app::BatchResult off = app::run_batch(p, path);
  EXPECT_EQ(on.events.size(), 1u);
  EXPECT_TRUE(off.events.empty());
  EXPECT_DOUBLE_EQ(on.removed_volume_mm3, off.removed_volume_mm3);
}

TEST(Events, ConsecutiveMovesOfOneKindAreOneEvent) {
  std::vector<verify::Event> ev;
  verify::Event e;
  e.kind = verify::EventKind::ShankInMaterial;
  e.tool = 1;
  for (geom::MoveId id : {4u, 5u, 5u, 6u}) {  // 5 twice: two sub-steps of one move
    e.move = id;
    e.line = static_cast<int>(id) + 10;
    e.volume_mm3 = 1.0;
    verify::add_event(ev, e);
  }
  e.kind = verify::EventKind::HolderInMaterial;  // interleaved with another kind
  e.move = 7;
  e.line = 17;
  verify::add_event(ev, e);
  e.kind = verify::EventKind::ShankInMaterial;
  verify::add_event(ev, e);
  e.move = 9;  // a gap: a new event
  verify::add_event(ev, e);
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].moves, 4u);
  EXPECT_EQ(ev[0].move, 4u);
  EXPECT_EQ(ev[0].last_move, 7u);
  EXPECT_EQ(ev[0].last_line, 17);
  EXPECT_DOUBLE_EQ(ev[0].volume_mm3, 5.0);
  EXPECT_EQ(ev[1].kind, verify::EventKind::HolderInMaterial);
  EXPECT_EQ(ev[2].move, 9u);
}

TEST(Events, CsvHasOneLinePerEventAndQuotesSources) {
  verify::Event e;
  e.source = "a,b.ngc";
  e.line = 3;
  const std::string csv = verify::events_csv({e, e});
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_NE(csv.find("\"a,b.ngc\",3,"), std::string::npos) << csv;
  EXPECT_EQ(csv.rfind("kind,severity,time_s,source,line,", 0), 0u);
}

TEST(CheckProfile, KeysAreReadAndTyposRejected) {
  const std::string base = app::default_profile_text();
  const app::Profile p = app::parse_profile(base + "\n[checks]\nenabled = false\ntolerance_mm = 0.05\n", "c.toml");
  EXPECT_FALSE(p.checks.enabled);
  EXPECT_DOUBLE_EQ(p.checks.tolerance_mm, 0.05);
  try {
    (void)app::parse_profile(base + "\n[checks]\ntolerance = 0.05\n", "c.toml");
    FAIL() << "unknown key accepted";
  } catch (const app::ProfileError& e) {
    EXPECT_NE(std::string(e.what()).find("checks.tolerance"), std::string::npos) << e.what();
  }
}
