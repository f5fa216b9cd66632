// verify/: collision checks against the stock of each move's moment (issue 16). Volumes are
// checked against hand-computed values on the built-in default profile (box 100 x 80 x 30,
// top at Z0; T1 flat D10, flutes 30, gauge length 60, holder D40).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "app/batch.hpp"
#include "geom/sweep.hpp"
#include "nc/emulator.hpp"
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

app::BatchResult run(const app::Profile& profile, const std::string& program) {
  app::Profile p = profile;
  p.threads = 1;
  const nc::Toolpath path = nc::interpret_gcode(program, "t.ngc", app::gcode_options(p));
  return app::run_batch(p, path);
}

// `batch --sampled`: the emulator's sampled stream of the program (app::emulator_limits:
// 4 ms samples, 1000 mm/s2), run with the sampled stream's checks.
app::BatchResult run_sampled(const app::Profile& profile, const std::string& program) {
  app::Profile p = profile;
  p.threads = 1;
  const nc::Toolpath path = nc::interpret_gcode(program, "t.ngc", app::gcode_options(p));
  return app::run_batch(p, nc::sampled_toolpath(path, app::emulator_limits(p)), {}, true);
}

const verify::Event* first_of(const std::vector<verify::Event>& ev, verify::EventKind k) {
  for (const verify::Event& e : ev)
    if (e.kind == k) return &e;
  return nullptr;
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
  // r = 5, 5 mm into the box: the tool's polygon, n vertices on r·g (Sweep::circle_grow_width),
  // which keeps the circle's mean width, not its area (2·tol/r below it at most).
  const int n = geom::Sweep::circle_segments(5.0, p.solid.chord_tol_mm);
  const double rho = 5.0 * geom::Sweep::circle_grow_width(n);
  const double expected = 0.5 * n * rho * rho * std::sin(2.0 * std::numbers::pi / n) * 5.0;
  EXPECT_NEAR(in.volume_mm3, expected, 1e-5 * expected);
  const double circle = std::numbers::pi * 25.0 * 5.0;
  EXPECT_NEAR(in.volume_mm3, circle, 2.0 * p.solid.chord_tol_mm / 5.0 * circle);
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
      "G21 G90\nT1 M6 G43 H1 S1000 M3\nG0 X-10 Y40 Z10\nG0 Z-5\nG0 X110\nG0 Z10\nM2\n");
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
      "G21 G90\nT1 M6 G43 H1 S1000 M3\nG0 X-10 Y40 Z10\nG0 Z-5\nG1 X110 F600\nG0 X-10\nG0 Z10\nM2\n");
  EXPECT_TRUE(r.events.empty()) << verify::describe(r.events.at(0));
  EXPECT_NEAR(r.removed_volume_mm3, 5000.0, 0.01 * 5000.0);
}

TEST(CollisionChecks, AForgottenG43PutsShankAndHolderIntoTheStockAtTheRightLine) {
  const std::string body = "G0 X20 Y20 Z5\nG1 Z-3 F300\nG1 X80 F600\nG1 Y60\nG0 Z20\nM2\n";
  const app::BatchResult bad = run("G21 G90 G17\nT1 M6 S1000 M3\n" + body);
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

  const app::BatchResult good = run("G21 G90 G17\nT1 M6 G43 H1 S1000 M3\n" + body);
  EXPECT_TRUE(good.events.empty());
}

// A raster that forgets G43: every move drags the shank through the stock. The moves that
// continue a run of the same findings stay in their batch, so the run costs about as many
// cell clips as the program without checks (one batch per move cost 20 to 30 times as many),
// and it is still one shank event from its first line.
TEST(CollisionChecks, ARunOfOffendingMovesCostsAFewBatchesNotOneEach) {
  std::string raster = "G0 X10 Y10 Z5\nG1 Z-2 F300\n";
  for (int k = 0; k < 30; ++k) raster += "G1 X" + std::to_string(k % 2 == 0 ? 90 : 10) + " F600\nG1 Y" + std::to_string(12 + 2 * k) + "\n";
  raster += "G0 Z20\nM2\n";
  const std::string bad = "G21 G90 G17\nT1 M6 S1000 M3\n" + raster;
  const app::BatchResult checked = run(bad);
  app::Profile off = app::default_profile();
  off.checks.enabled = false;
  const app::BatchResult unchecked = run(off, bad);
  ASSERT_EQ(count_kind(checked.events, verify::EventKind::ShankInMaterial), 1u);
  const verify::Event* shank = first_of(checked.events, verify::EventKind::ShankInMaterial);
  EXPECT_EQ(shank->line, 3);  // G0 Z5 puts the tip at Z-55: the shank (from Z-25) is in the box
  EXPECT_GE(shank->moves, 60u);
  EXPECT_LE(checked.batches, unchecked.batches + 4) << "unchecked: " << unchecked.batches;
  EXPECT_NEAR(checked.removed_volume_mm3, unchecked.removed_volume_mm3, 1e-6 * unchecked.removed_volume_mm3);
}

TEST(CollisionChecks, TheBundledDemoIsClean) {
  app::Profile p = app::default_profile();
  p.threads = 1;
  const app::BatchResult r = app::run_batch(p, app::demo_toolpath());
  EXPECT_TRUE(r.events.empty());
}

TEST(CollisionChecks, DisabledChecksReportNothingAndCutTheSame) {
  const std::string prog = "G21 G90\nT1 M6 G43 H1 S1000 M3\nG0 X-10 Y40 Z10\nG0 Z-5\nG0 X110\nG0 Z10\nM2\n";
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

// ---- process checks: spindle, plunge, feed, travel ----------------------------------------

// A D10 slot 2 deep from X30 to X60 after the spindle stopped at line 7: the new material is
// 30 x 10 x 2 = 600 mm3 (the half circles at both ends cancel).
TEST(ProcessChecks, ACutAfterM5RaisesSpindleOffAtItsLine) {
  const std::string head = "G21 G90 G17\nT1 M6 G43 H1\nS1000 M3\nG0 X-10 Y40 Z5\nG1 Z-2 F300\nG1 X30 F600\n";
  const app::BatchResult bad = run(head + "M5\nG1 X60\nG0 Z10\nM2\n");
  ASSERT_EQ(bad.events.size(), 1u) << verify::describe(bad.events.at(0));
  const verify::Event& e = bad.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::SpindleOff);
  EXPECT_EQ(e.severity(), verify::Severity::Error);
  EXPECT_EQ(e.line, 8);
  EXPECT_EQ(e.tool, 1);
  EXPECT_NEAR(e.volume_mm3, 600.0, 0.01 * 600.0);
  EXPECT_NEAR(e.depth_mm, 2.0, 1e-9);
  EXPECT_NEAR(e.position.x, 60.0, 1e-9);
  EXPECT_DOUBLE_EQ(e.value, 1000.0);  // S stays set; M5 stopped it

  // The same program with the spindle running throughout raises nothing.
  const app::BatchResult good = run(head + "G1 X60\nG0 Z10\nM2\n");
  EXPECT_TRUE(good.events.empty()) << verify::describe(good.events.at(0));
  EXPECT_NEAR(good.removed_volume_mm3, bad.removed_volume_mm3, 1e-6);  // the check does not change the cut

  // M3 without an S word: S0 from power-up, the spindle does not turn; the plunge (line 5)
  // is reported with its cylinder, the moves above the stock are not.
  const app::BatchResult no_s = run("G21 G90 G17\nT1 M6 G43 H1\nM3\nG0 X20 Y40 Z5\nG1 Z-2 F300\nG0 Z10\nM2\n");
  ASSERT_EQ(no_s.events.size(), 1u);
  EXPECT_EQ(no_s.events[0].kind, verify::EventKind::SpindleOff);
  EXPECT_EQ(no_s.events[0].line, 5);
  EXPECT_NEAR(no_s.events[0].volume_mm3, std::numbers::pi * 25.0 * 2.0, 0.01 * 157.1);
  EXPECT_DOUBLE_EQ(no_s.events[0].value, 0.0);
}

TEST(ProcessChecks, TheSpindleStateIsCarriedOnEverySegment) {
  const nc::Toolpath path = nc::interpret_gcode("G21 G90\nG0 X1\nS2000 M4\nG1 X2 F100\nM5\nG1 X3\n", "s.ngc",
                                                app::gcode_options(app::default_profile()));
  ASSERT_EQ(path.segments.size(), 3u);
  EXPECT_EQ(path.segments[0].spindle, nc::Spindle::Off);  // power-up M5 S0
  EXPECT_FALSE(path.segments[0].spindle_turning());
  EXPECT_EQ(path.segments[1].spindle, nc::Spindle::Ccw);
  EXPECT_DOUBLE_EQ(path.segments[1].spindle_s, 2000.0);
  EXPECT_TRUE(path.segments[1].spindle_turning());
  EXPECT_EQ(path.segments[2].spindle, nc::Spindle::Off);
  EXPECT_FALSE(path.segments[2].spindle_turning());
}

// T1 (flat D10) made non-centre-cutting: its non-cutting core is D2.5 (a quarter).
TEST(ProcessChecks, ANonCentreCuttingToolPlungingIsReportedRampingGentlyIsNot) {
  app::Profile p = app::default_profile();
  p.tooling.tools[1].centre_cutting = false;
  const std::string head = "G21 G90 G17\nT1 M6 G43 H1 S1000 M3\n";
  const app::BatchResult plunge = run(p, head + "G0 X50 Y40 Z5\nG1 Z-3 F100\nG0 Z10\nM2\n");
  ASSERT_EQ(plunge.events.size(), 1u) << verify::describe(plunge.events.at(0));
  const verify::Event& e = plunge.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::Plunge);
  EXPECT_EQ(e.severity(), verify::Severity::Error);
  EXPECT_EQ(e.line, 4);
  EXPECT_NEAR(e.value, 90.0, 1e-9);
  const double core_mm3 = std::numbers::pi * 1.25 * 1.25 * 3.0;  // the core's cylinder 3 mm into the stock
  EXPECT_NEAR(e.volume_mm3, core_mm3, 0.01 * core_mm3);
  EXPECT_NEAR(e.depth_mm, 3.0, 1e-9);

  // A 1.9 deg ramp (2 mm down over 60 mm) and the flat pass back: within the 3 deg limit.
  const app::BatchResult ramp = run(p, head + "G0 X10 Y40 Z1\nG1 X70 Z-1 F300\nG1 X10\nG0 Z10\nM2\n");
  EXPECT_TRUE(ramp.events.empty()) << verify::describe(ramp.events.at(0));
  EXPECT_GT(ramp.removed_volume_mm3, 500.0);
  // A 10 deg ramp is a plunge, reported with its angle.
  const double steep_deg = std::atan2(3.5, 20.0) * 180.0 / std::numbers::pi;
  const app::BatchResult steep = run(p, head + "G0 X20 Y40 Z0.5\nG1 X40 Z-3 F300\nG0 Z10\nM2\n");
  ASSERT_EQ(steep.events.size(), 1u);
  EXPECT_EQ(steep.events[0].kind, verify::EventKind::Plunge);
  EXPECT_NEAR(steep.events[0].value, steep_deg, 1e-6);
  // The same plunge with a centre-cutting T1 is fine.
  EXPECT_TRUE(run(head + "G0 X50 Y40 Z5\nG1 Z-3 F100\nG0 Z10\nM2\n").events.empty());
}

TEST(ProcessChecks, APlungeIntoAPilotHoleWiderThanTheCoreIsClean) {
  app::Profile p = app::default_profile();
  p.tooling.tools[1].centre_cutting = false;
  // T3 drills D8 to Z-5 (its 118 deg point: Z-4.25 at the core's radius 1.25); T1 then plunges to Z-4.
  const app::BatchResult r = run(p,
                                 "G21 G90 G17\nT3 M6 G43 H3 S1000 M3\nG0 X50 Y40 Z5\nG1 Z-5 F100\nG0 Z10\n"
                                 "T1 M6 G43 H1\nG0 X50 Y40 Z5\nG1 Z-4 F100\nG0 Z10\nM2\n");
  EXPECT_TRUE(r.events.empty()) << verify::describe(r.events.at(0));
}

TEST(ProcessChecks, AFeedOverTheLimitWhileCuttingIsAWarningWithItsFeed) {
  app::Profile p = app::default_profile();
  p.checks.max_cutting_feed_mm_per_min = 1000.0;
  // F3000 in the air (line 4) is not cutting; F600 cuts within the limit; F1500 cuts over it.
  const app::BatchResult r = run(p,
                                 "G21 G90 G17\nT1 M6 G43 H1 S1000 M3\nG0 X-10 Y40 Z5\nG1 X-8 F3000\n"
                                 "G1 Z-2 F300\nG1 X30 F600\nG1 X60 F1500\nG0 Z10\nM2\n");
  ASSERT_EQ(r.events.size(), 1u) << verify::describe(r.events.at(0));
  const verify::Event& e = r.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::FeedLimit);
  EXPECT_EQ(e.severity(), verify::Severity::Warning);
  EXPECT_EQ(e.line, 7);
  EXPECT_DOUBLE_EQ(e.value, 1500.0);
  EXPECT_NEAR(e.volume_mm3, 600.0, 0.01 * 600.0);
  const verify::EventCounts c = verify::count(r.events);
  EXPECT_EQ(c.errors, 0u);
  EXPECT_EQ(c.warnings, 1u);
}

// Default profile: G54 origin at machine Z-250, T1 60 mm long, so the gauge line is at
// machine X = x, Z = z - 250 + 60 for the tip at (x, z).
TEST(ProcessChecks, AMoveBeyondAnAxisLimitRaisesOverTravelWithAxisAndExcess) {
  app::Profile p = app::default_profile();
  p.machine.travel_min = {-5, -5, -300, -360, -360, -360};
  p.machine.travel_max = {150, 100, -150, 360, 360, 360};
  const app::BatchResult r = run(p,
                                 "G21 G90 G17\nT1 M6 G43 H1 S1000 M3\nG0 X-12 Y40 Z20\nG0 X-12 Y50\nG0 X50\n"
                                 "G0 Z50\nG0 Z10\nM2\n");
  ASSERT_EQ(r.events.size(), 2u);
  const verify::Event* x = first_of(r.events, verify::EventKind::OverTravel);
  ASSERT_NE(x, nullptr);
  EXPECT_EQ(x->severity(), verify::Severity::Error);
  EXPECT_EQ(verify::axis_name(x->axis), "X");
  EXPECT_NEAR(x->value, 7.0, 1e-9);  // X-12 against -5
  EXPECT_EQ(x->line, 3);
  EXPECT_EQ(x->last_line, 4);  // one event for the two moves out there
  EXPECT_EQ(x->moves, 2u);
  const verify::Event& z = r.events[1];
  EXPECT_EQ(z.kind, verify::EventKind::OverTravel);
  EXPECT_EQ(verify::axis_name(z.axis), "Z");
  EXPECT_NEAR(z.value, 10.0, 1e-9);  // 50 - 250 + 60 = -140 against -150
  EXPECT_EQ(z.line, 6);
  EXPECT_NEAR(z.position.z, 50.0, 1e-9);
  const std::string csv = verify::events_csv(r.events);
  EXPECT_NE(csv.find(",X,7.0000\n"), std::string::npos) << csv;
  // Within the limits: nothing.
  EXPECT_TRUE(run(p, "G21 G90 G17\nT1 M6 G43 H1 S1000 M3\nG0 X0 Y40 Z20\nG0 X50\nM2\n").events.empty());
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
  const app::Profile p = app::parse_profile(base + "\n[checks]\nenabled = false\ntolerance_mm = 0.05\n"
                                                   "max_cutting_feed_mm_per_min = 2500\nmax_ramp_angle_deg = 5\n"
                                                   "spindle_nose_diameter_mm = 90\nspindle_nose_length_mm = 120\n",
                                            "c.toml");
  EXPECT_FALSE(p.checks.enabled);
  EXPECT_DOUBLE_EQ(p.checks.tolerance_mm, 0.05);
  EXPECT_DOUBLE_EQ(p.checks.max_cutting_feed_mm_per_min, 2500.0);
  EXPECT_DOUBLE_EQ(p.checks.max_ramp_angle_deg, 5.0);
  EXPECT_DOUBLE_EQ(p.checks.spindle_nose_diameter_mm, 90.0);
  EXPECT_DOUBLE_EQ(p.checks.spindle_nose_length_mm, 120.0);
  EXPECT_DOUBLE_EQ(app::default_profile().checks.spindle_nose_diameter_mm, 0.0);  // not checked unless given
  try {
    (void)app::parse_profile(base + "\n[checks]\ntolerance = 0.05\n", "c.toml");
    FAIL() << "unknown key accepted";
  } catch (const app::ProfileError& e) {
    EXPECT_NE(std::string(e.what()).find("checks.tolerance"), std::string::npos) << e.what();
  }
}

TEST(CheckProfile, TravelLimitsAndTheCentreCuttingFlagAreRead) {
  std::string text = app::default_profile_text();
  text.replace(text.find("[machine]\n"), 10,
               "[machine]\ntravel_min_mm = [-5, -10, -400]\ntravel_max_mm = [600, 400, 0]\ntravel_max_deg = [0, 0, 90]\n");
  text += "\n[[tool]]\nnumber = 6\nkind = \"flat\"\ndiameter_mm = 16.0\ncentre_cutting = false\n";
  const app::Profile p = app::parse_profile(text, "t.toml");
  EXPECT_DOUBLE_EQ(p.machine.travel_min[nc::X], -5.0);
  EXPECT_DOUBLE_EQ(p.machine.travel_max[nc::Z], 0.0);
  EXPECT_DOUBLE_EQ(p.machine.travel_max[nc::C], 90.0);
  EXPECT_TRUE(std::isinf(p.machine.travel_min[nc::A]));  // not given: unlimited
  EXPECT_FALSE(p.tooling.tools.at(6).centre_cutting);
  EXPECT_TRUE(p.tooling.tools.at(1).centre_cutting);
  auto error_of = [](const std::string& t) {
    try {
      (void)app::parse_profile(t, "t.toml");
    } catch (const app::ProfileError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string bad = app::default_profile_text();
  bad.replace(bad.find("[machine]\n"), 10, "[machine]\ntravel_min_mm = [0, 0, 0]\ntravel_max_mm = [10, 10, -1]\n");
  EXPECT_NE(error_of(bad).find("machine.travel_max_mm: expected every maximum above its minimum"), std::string::npos)
      << error_of(bad);
  const std::string ball = std::string(app::default_profile_text()) +
                           "\n[[tool]]\nnumber = 6\nkind = \"ball\"\ndiameter_mm = 6.0\ncentre_cutting = false\n";
  EXPECT_NE(error_of(ball).find("tool.centre_cutting: only for tool kinds flat and bull"), std::string::npos)
      << error_of(ball);
}

// batch --sampled (docs/verification.md#sampled): a G0 at 15 m/min through the stock is a
// rapid by its sample speed (above 1.05 x 7500 mm/min, half the rapid rate: the default
// profile has no feed cap), at its line, with the slot's volume (100 x 10 x 1: it starts and
// ends 60 mm outside the stock, so its acceleration ramps are in the air). The same path as
// G1 F1000 raises nothing.
TEST(SampledChecks, ARapidIsToldBySampleSpeedAtItsLineWithItsVolume) {
  const std::string head = "G21 G90 G17\nT1 M6 G43 H1 S1000 M3\nG0 X-60 Y40 Z5\nG1 Z-1 F1000\n";
  const app::BatchResult r = run_sampled(app::default_profile(), head + "G0 X160\nG0 Z10\nM2\n");
  ASSERT_EQ(r.events.size(), 1u) << verify::describe(r.events.at(1));
  const verify::Event& e = r.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::RapidIntoMaterial);
  EXPECT_EQ(e.line, 5);
  EXPECT_EQ(e.last_line, 5);
  EXPECT_EQ(e.source, "t.ngc");
  EXPECT_GT(e.moves, 100u);  // samples, 1 mm apart
  EXPECT_NEAR(e.volume_mm3, 1000.0, 0.01 * 1000.0);
  EXPECT_NEAR(e.depth_mm, 1.0, 1e-6);
  EXPECT_NEAR(r.removed_volume_mm3, e.volume_mm3, 1e-6 * 1000.0);
  const app::BatchResult feed = run_sampled(app::default_profile(), head + "G1 X160\nG0 Z10\nM2\n");
  EXPECT_TRUE(feed.events.empty()) << verify::describe(feed.events.at(0));
  EXPECT_NEAR(feed.removed_volume_mm3, r.removed_volume_mm3, 1e-3);
}

// The sampled stream keeps each program move's spindle state: a cut after M5 raises
// spindle-off at its line with the 30 x 10 x 2 it cuts (as in batch, within 1 %).
TEST(SampledChecks, ACutAfterM5RaisesSpindleOffAtItsLine) {
  const std::string head = "G21 G90 G17\nT1 M6 G43 H1\nS1000 M3\nG0 X-10 Y40 Z5\nG1 Z-2 F300\nG1 X30 F600\n";
  const app::BatchResult bad = run_sampled(app::default_profile(), head + "M5\nG1 X60\nG0 Z10\nM2\n");
  ASSERT_EQ(bad.events.size(), 1u) << verify::describe(bad.events.at(1));
  const verify::Event& e = bad.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::SpindleOff);
  EXPECT_EQ(e.line, 8);
  EXPECT_NEAR(e.volume_mm3, 600.0, 0.01 * 600.0);
  EXPECT_DOUBLE_EQ(e.value, 1000.0);
  const app::BatchResult good = run_sampled(app::default_profile(), head + "G1 X60\nG0 Z10\nM2\n");
  EXPECT_TRUE(good.events.empty()) << verify::describe(good.events.at(0));
}

// A program that never starts the spindle cuts a D10 slot 2 deep from X-10 to X60 across
// the stock's X0 face: 60 x 10 plus the half disc at X60, 639.27 mm2 x 2 = 1278.5 mm3, in
// ~175 samples. Every cutting sample is a spindle-off finding; the run is one event, tested
// for contact after its first sample, and it ends its batch there: the event takes the
// volume the kernel removed for the run (exact, not the first sample's lower bound), and the
// run costs two kernel calls more than the unchecked cut, not one per sample.
TEST(SampledChecks, ARunOfSpindleOffSamplesIsOneEventWithTheVolumeTheKernelRemoved) {
  const std::string prog = "G21 G90 G17\nT1 M6 G43 H1\nG0 X-10 Y40 Z5\nG1 Z-2 F300\nG1 X60 F600\nG0 Z10\nM2\n";
  app::Profile p = app::default_profile();
  const app::BatchResult checked = run_sampled(p, prog);
  p.checks.enabled = false;
  const app::BatchResult unchecked = run_sampled(p, prog);
  ASSERT_EQ(checked.events.size(), 1u) << verify::describe(checked.events.at(1));
  const verify::Event& e = checked.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::SpindleOff);
  EXPECT_EQ(e.line, 5);
  EXPECT_GE(e.moves, 100u);
  const double slot_mm3 = (600.0 + 12.5 * std::numbers::pi) * 2.0;
  EXPECT_NEAR(e.volume_mm3, slot_mm3, 0.01 * slot_mm3);
  EXPECT_NEAR(e.volume_mm3, checked.removed_volume_mm3, 1e-6 * slot_mm3);  // the run is all the cutting
  EXPECT_LE(checked.batches, unchecked.batches + 2) << "unchecked: " << unchecked.batches;
  // Other batches, the same sweeps: within the kernel's batching dependence (docs/verification.md).
  EXPECT_NEAR(checked.removed_volume_mm3, unchecked.removed_volume_mm3, 2e-4 * slot_mm3);
}

// The feed limit judges the sample speed: F1500 over a 1000 mm/min limit while cutting is a
// warning at its line with the feed reached (the emulator runs at the programmed feed) and
// about its 600 mm3 (the deceleration's last 0.14 mm below the limit are not counted).
TEST(SampledChecks, AFeedOverTheLimitIsJudgedBySampleSpeed) {
  app::Profile p = app::default_profile();
  p.checks.max_cutting_feed_mm_per_min = 1000.0;
  const app::BatchResult r = run_sampled(p,
                                         "G21 G90 G17\nT1 M6 G43 H1 S1000 M3\nG0 X-10 Y40 Z5\nG1 X-8 F3000\n"
                                         "G1 Z-2 F300\nG1 X30 F600\nG1 X60 F1500\nG0 Z10\nM2\n");
  ASSERT_EQ(r.events.size(), 1u) << verify::describe(r.events.at(1));
  const verify::Event& e = r.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::FeedLimit);
  EXPECT_EQ(e.line, 7);
  EXPECT_NEAR(e.value, 1500.0, 1.0);
  EXPECT_NEAR(e.volume_mm3, 600.0, 0.01 * 600.0);
}

// [checks] spindle_nose_diameter_mm / spindle_nose_length_mm (docs/verification.md): the nose
// (D80 x 100 here) starts at the holder's top face, tip + 60 (T1) + 40 (holder) = 100 mm up.
// T1 goes down beside the stock (X-35, the stock starts at X0) to Z-105: tool (r 5) and
// holder (r 20) stay clear, the nose (r 40) dips 5 mm into the stock over a circular segment
// 5 mm wide: 1600 acos(35/40) - 35 sqrt(40^2 - 35^2) = 130.8 mm2 x 5 mm = 654 mm3, from the
// line of that move (and as much again on the retract). At X-45 the nose clears the stock's X0 face: nothing. Without the keys
// the nose is not checked.
TEST(CollisionChecks, TheSpindleNoseBesideTheStockIsReportedAtItsLine) {
  app::Profile p = app::default_profile();
  p.checks.spindle_nose_diameter_mm = 80.0;
  p.checks.spindle_nose_length_mm = 100.0;
  const auto program = [](const char* x) {
    return std::string("G21 G90 G17\nT1 M6 G43 H1 S1000 M3\nG0 X") + x + " Y40 Z5\nG1 Z-105 F1000\nG0 Z10\nM2\n";
  };
  const app::BatchResult r = run(p, program("-35"));
  const verify::Event* e = first_of(r.events, verify::EventKind::SpindleNoseInMaterial);
  ASSERT_NE(e, nullptr) << (r.events.empty() ? "no events" : verify::describe(r.events[0]));
  EXPECT_EQ(e->line, 4);
  EXPECT_EQ(e->severity(), verify::Severity::Error);
  EXPECT_EQ(std::string(verify::to_string(e->kind)), "spindle-nose-in-material");
  // The retract (line 5) goes back up through the same material (nothing was cut): the two
  // consecutive moves are one event. The retract continues the run, so it is tested for
  // contact only: the volume is the plunge's (docs/verification.md, "Runs of findings").
  EXPECT_EQ(e->moves, 2u);
  EXPECT_EQ(e->last_line, 5);
  const double segment_mm2 = 1600.0 * std::acos(35.0 / 40.0) - 35.0 * std::sqrt(1600.0 - 1225.0);
  EXPECT_NEAR(e->volume_mm3, segment_mm2 * 5.0, 0.01 * segment_mm2 * 5.0);
  EXPECT_NEAR(e->depth_mm, 5.0, 0.1);
  EXPECT_EQ(count_kind(r.events, verify::EventKind::HolderInMaterial), 0u);
  EXPECT_EQ(count_kind(r.events, verify::EventKind::ShankInMaterial), 0u);
  EXPECT_NEAR(r.removed_volume_mm3, 0.0, 1e-9);  // the tool cuts nothing

  const app::BatchResult clear = run(p, program("-45"));
  EXPECT_EQ(count_kind(clear.events, verify::EventKind::SpindleNoseInMaterial), 0u);
  const app::BatchResult off = run(program("-35"));
  EXPECT_EQ(count_kind(off.events, verify::EventKind::SpindleNoseInMaterial), 0u);
}

// tool-change-in-material: M6 keeps the gauge line where it is, so T1 (60 mm) loaded after
// T2 (50 mm) at Z2 stands 8 mm deep in the stock top (docs/nc-frontend.md). Its first move
// raises the event where the tool stood, with the material its body held there: the flat
// Ø10 cylinder, 8 mm of it below the top (π·25·8 = 628.3 mm³; the tool's polygon is a
// two-sided 10 µm n-gon, a little less). On G-code segments and on the sampled stream alike;
// the same change at a safe height raises nothing.
TEST(CollisionChecks, AToolLoadedIntoTheStockIsReportedWhereItStands) {
  const std::string head = "G21 G90\nT2 M6\nG43 H2\nS8000 M3\nG0 X20 Y20 Z";
  const std::string tail = "\nT1 M6\nG43 H1\nG0 Z10\nG0 X50\nM2\n";
  const app::Profile p = app::default_profile();
  const double cylinder = std::numbers::pi * 25.0 * 8.0;
  for (const bool sampled : {false, true}) {
    const app::BatchResult r = sampled ? run_sampled(p, head + "2" + tail) : run(p, head + "2" + tail);
    ASSERT_EQ(count_kind(r.events, verify::EventKind::ToolChangeInMaterial), 1u) << (sampled ? "sampled" : "segments");
    const verify::Event* e = first_of(r.events, verify::EventKind::ToolChangeInMaterial);
    EXPECT_EQ(e->tool, 1);
    EXPECT_EQ(e->line, 8);  // the new tool's first move
    EXPECT_NEAR(e->position.z, -8.0, 0.01);
    EXPECT_NEAR(e->depth_mm, 8.0, 0.05);
    EXPECT_NEAR(e->volume_mm3, cylinder, 0.005 * cylinder);
    EXPECT_NEAR(r.removed_volume_mm3, e->volume_mm3, 0.005 * cylinder);
    const app::BatchResult safe = sampled ? run_sampled(p, head + "20" + tail) : run(p, head + "20" + tail);
    EXPECT_EQ(count_kind(safe.events, verify::EventKind::ToolChangeInMaterial), 0u);
    EXPECT_EQ(safe.removed_volume_mm3, 0.0);
  }
}

TEST(CollisionChecks, ARetractAlongTheAxisOfATiltedBallCutIsClean) {
  // finish5x's line ends: the tilted ball's last move turns the axis upright, then G0 Z20
  // lifts the tool along its axis out of the cut it stands in. The tilted moves are sectioned
  // as the exact capsule, the upright retract with the ball's profile polyline, which 12 µm
  // above the tip is 38 µm wider than the sphere (its first station, within the chord
  // tolerance normal to the surface, lies almost level). A margin taken in the plane reported
  // that film as a rapid into material; the deep test is the tool moved inwards by the margin
  // normal to its surface (CollisionChecker::Parts::inner). A rapid that does cut is still one.
  app::Profile p = app::load_profile(std::string(LBR_SOURCE_DIR) + "/config/profiles/mill5-ac.toml");
  app::apply_tool_override(p, "3:ball:6");
  const std::string head = "G21 G90 G17 G94\nG0 A0 C0\nT3 M6\nG43 H3\nS15000 M3\nG0 Z20\n";
  const app::BatchResult r = run(p, head + "G0 X26.5 Y4.1149 A1.1629\nG1 Z-8.619 F500\nG1 X27 Y4 Z-8.6621 A0\nG0 Z20\nM2\n");
  EXPECT_EQ(count_kind(r.events, verify::EventKind::RapidIntoMaterial), 0u) << verify::describe(r.events.at(0));
  EXPECT_GT(r.removed_volume_mm3, 200.0);
  const app::BatchResult crash = run(p, head + "G0 X26.5 Y4.1149 A1.1629\nG1 Z-8.619 F500\nG1 X27 Y4 Z-8.6621 A0\nG0 Y8\nM2\n");
  const verify::Event* e = first_of(crash.events, verify::EventKind::RapidIntoMaterial);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->line, 10);
}
