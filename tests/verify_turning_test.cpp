// verify/: turning moves through the collision and process checks (issue 16,
// docs/verification.md#turning). A D40 bar, Z-80..0, levels 0.1 mm, sharp inserts so that
// the revolved regions have closed-form volumes:
// T1 diamond80 at 95°, edge 12, nose 0: the insert spans r, z in [0, 13] from its reference
//    point; holder 25 wide along Z from z' = 13 (above the insert), 3 mm out from it;
// T4 grooving blade 3 wide, 10 deep, nose 0; holder 13 wide from z' = -5 (4 mm on the
//    chuck side of the blade, 5 mm on the other), from r' = 10 (the blade's depth) out.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/gcode.hpp"
#include "verify/events.hpp"
#include "verify/stl.hpp"

#include <filesystem>
#include <fstream>

using namespace lbr;

namespace {

constexpr double kPi = std::numbers::pi;

std::string lathe_toml(const std::string& machine_extra = "", const std::string& checks = "",
                       const std::string& spacing_mm = "0.1") {
  return "[machine]\nkind = \"lathe\"\ndiameter_programming = true\ng54_origin_mm = [-100.0, 0.0, -200.0]\n" +
         machine_extra +
         "\n[stock]\nshape = \"cylinder\"\ncenter_mm = [0.0, 0.0]\ndiameter_mm = 40.0\nz_min_mm = -80.0\nz_max_mm = 0.0\n"
         "\n[lbr]\nlevel_spacing_mm = " + spacing_mm + "\nregions = \"2x2\"\nchord_tolerance_mm = 0.001\n"
         "\n[[tool]]\nnumber = 1\nkind = \"turning\"\ninsert = \"diamond80\"\nnose_radius_mm = 0.0\nedge_length_mm = 12.0\n"
         "approach_angle_deg = 95.0\nholder_width_mm = 25.0\nholder_z_mm = 13.0\nholder_r_mm = 3.0\n"
         "\n[[tool]]\nnumber = 4\nkind = \"grooving\"\nwidth_mm = 3.0\nnose_radius_mm = 0.0\ndepth_mm = 10.0\n"
         "holder_width_mm = 13.0\nholder_z_mm = -5.0\nholder_r_mm = 10.0\n" +
         (checks.empty() ? "" : "\n[checks]\n" + checks + "\n");
}

app::Profile lathe(const std::string& machine_extra = "", const std::string& checks = "",
                   const std::string& spacing_mm = "0.1") {
  app::Profile p = app::parse_profile(lathe_toml(machine_extra, checks, spacing_mm), "lathe-test.toml");
  p.threads = 1;
  return p;
}

app::BatchResult run(const app::Profile& p, const std::string& program) {
  const nc::Toolpath path = nc::interpret_gcode(program, "t.ngc", app::gcode_options(p));
  return app::run_batch(p, path);
}

std::size_t count_kind(const std::vector<verify::Event>& ev, verify::EventKind k) {
  std::size_t n = 0;
  for (const verify::Event& e : ev) n += e.kind == k ? 1 : 0;
  return n;
}

std::string all(const std::vector<verify::Event>& ev) {
  std::string s;
  for (const verify::Event& e : ev) s += verify::describe(e) + "\n";
  return s;
}

// The groove of T4 at Z-10 (z in [-10, -7]) from D40 down to D30: the blade removes the
// ring 15 <= r <= 20 over its 3 mm width.
const double kGrooveMm3 = kPi * (20.0 * 20.0 - 15.0 * 15.0) * 3.0;
const std::string kHead = "G18 G7 G90 G21 G94\n";  // line 1

}  // namespace

TEST(TurningChecks, ARapidGrooveIntoTheBarIsReportedWithTheBladesVolume) {
  const app::Profile p = lathe();
  const std::string tail = "G0 X60\nG0 Z5\nM2\n";
  const app::BatchResult bad = run(p, kHead + "S1000 M3\nT4 M6\nG0 X50 Z-10\nG0 X30\n" + tail);
  ASSERT_EQ(bad.events.size(), 1u) << all(bad.events);
  const verify::Event& e = bad.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::RapidIntoMaterial);
  EXPECT_EQ(e.line, 5);
  EXPECT_EQ(e.tool, 4);
  EXPECT_NEAR(e.volume_mm3, kGrooveMm3, 0.01 * kGrooveMm3);
  EXPECT_NEAR(e.depth_mm, 3.0, 1e-9);
  EXPECT_NEAR(e.position.x, 15.0, 1e-9);  // the radius (X30 in diameter mode)
  EXPECT_NEAR(bad.removed_volume_mm3, e.volume_mm3, 1e-6 * kGrooveMm3);

  // The same groove at a feed: nothing, and the same cut.
  const app::BatchResult good = run(p, kHead + "S1000 M3\nT4 M6\nG0 X50 Z-10\nG1 X30 F60\n" + tail);
  EXPECT_TRUE(good.events.empty()) << all(good.events);
  EXPECT_NEAR(good.removed_volume_mm3, bad.removed_volume_mm3, 1e-6 * kGrooveMm3);
}

TEST(TurningChecks, ARapidAlongTheBarMeetsTheRingTheInsertSweeps) {
  // T1 at D30 from Z2 to Z-20: the sharp insert removes 15 <= r <= 20 over 20 mm.
  const app::BatchResult r = run(lathe(), kHead + "S1000 M3\nT1 M6\nG0 X50 Z2\nG0 X30\nG0 Z-20\nG0 X60\nM2\n");
  ASSERT_EQ(r.events.size(), 1u) << all(r.events);
  EXPECT_EQ(r.events[0].kind, verify::EventKind::RapidIntoMaterial);
  EXPECT_EQ(r.events[0].line, 6);
  const double expected = kPi * (400.0 - 225.0) * 20.0;
  EXPECT_NEAR(r.events[0].volume_mm3, expected, 0.01 * expected);
}

TEST(TurningChecks, TurningWithTheSpindleOffIsReportedAtItsLine) {
  const app::Profile p = lathe();
  const std::string cut = "T4 M6\nG0 X50 Z-10\nG1 X30 F60\nG0 X60\nM2\n";
  const app::BatchResult stopped = run(p, kHead + "S800 M3\nM5\n" + cut);
  ASSERT_EQ(stopped.events.size(), 1u) << all(stopped.events);
  const verify::Event& e = stopped.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::SpindleOff);
  EXPECT_EQ(e.line, 6);
  EXPECT_DOUBLE_EQ(e.value, 800.0);
  EXPECT_NEAR(e.volume_mm3, kGrooveMm3, 0.01 * kGrooveMm3);

  // Never started: the same finding (S0 from power-up).
  const app::BatchResult never = run(p, kHead + cut);
  ASSERT_EQ(count_kind(never.events, verify::EventKind::SpindleOff), 1u) << all(never.events);
  EXPECT_EQ(never.events[0].line, 4);

  const app::BatchResult running = run(p, kHead + "S800 M3\n" + cut);
  EXPECT_TRUE(running.events.empty()) << all(running.events);
}

TEST(TurningChecks, AFeedAboveTheLimitIsAWarningWithTheFeed) {
  const app::Profile p = lathe("", "max_cutting_feed_mm_per_min = 500.0");
  const app::BatchResult fast = run(p, kHead + "S1000 M3\nT4 M6\nG0 X50 Z-10\nG1 X30 F800\nG0 X60\nM2\n");
  ASSERT_EQ(fast.events.size(), 1u) << all(fast.events);
  const verify::Event& e = fast.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::FeedLimit);
  EXPECT_EQ(e.severity(), verify::Severity::Warning);
  EXPECT_EQ(e.line, 5);
  EXPECT_DOUBLE_EQ(e.value, 800.0);
  EXPECT_NEAR(e.volume_mm3, kGrooveMm3, 0.01 * kGrooveMm3);
  // F800 in the air (the approach) is not judged.
  const app::BatchResult air = run(p, kHead + "S1000 M3\nT4 M6\nG1 X50 Z-10 F800\nG1 X30 F400\nG0 X60\nM2\n");
  EXPECT_TRUE(air.events.empty()) << all(air.events);
}

TEST(TurningChecks, OverTravelOnXIsARadiusInDiameterAndRadiusMode) {
  // Machine X = radius + g54 origin (-100): X150 in diameter mode (G7) is radius 75, machine
  // -25, 5 mm beyond a -30 limit; G8 X75 is the same place.
  const app::Profile p =
      lathe("travel_min_mm = [-200.0, -1000.0, -1000.0]\ntravel_max_mm = [-30.0, 1000.0, 1000.0]\n");
  const std::string tail = "G0 Z5\nG0 X50\nM2\n";
  for (const std::string& move : {std::string("G7\nG0 X150\n"), std::string("G8\nG0 X75\n")}) {
    const app::BatchResult r = run(p, kHead + "S1000 M3\nT1 M6\n" + move + tail);
    ASSERT_EQ(r.events.size(), 1u) << move << all(r.events);
    const verify::Event& e = r.events[0];
    EXPECT_EQ(e.kind, verify::EventKind::OverTravel);
    EXPECT_EQ(e.axis, 0);
    EXPECT_EQ(e.line, 5);
    EXPECT_EQ(e.moves, 2u);  // the move out and the one along Z there
    EXPECT_NEAR(e.value, 5.0, 1e-9);
  }
}

TEST(TurningChecks, FacingDeeperThanTheInsertDrivesTheHolderIntoTheBar) {
  const app::Profile p = lathe();
  // Facing 15 deep at Z-15: the insert cuts z in [-15, -2]; the holder, from 13 above the
  // reference point, sweeps z in [-2, 0] from r = 25 down to r = 2 (X-2 + 3 mm): the ring
  // 2 <= r <= 20 over 2 mm that the insert leaves.
  const std::string approach = kHead + "S1000 M3\nT1 M6\nG0 X50 Z5\n";
  const app::BatchResult bad = run(p, approach + "G0 Z-15\nG1 X-2 F150\nM2\n");
  ASSERT_EQ(bad.events.size(), 1u) << all(bad.events);
  const verify::Event& e = bad.events[0];
  EXPECT_EQ(e.kind, verify::EventKind::HolderInMaterial);
  EXPECT_EQ(e.severity(), verify::Severity::Error);
  EXPECT_EQ(e.line, 6);
  EXPECT_EQ(e.tool, 1);
  const double expected = kPi * (400.0 - 4.0) * 2.0;
  EXPECT_NEAR(e.volume_mm3, expected, 0.01 * expected);
  EXPECT_NEAR(e.depth_mm, 2.0, 1e-9);

  // The same facing 1 deep: the holder stays above the face.
  const app::BatchResult good = run(p, approach + "G0 Z-1\nG1 X-2 F150\nG0 X50\nG0 Z5\nM2\n");
  EXPECT_TRUE(good.events.empty()) << all(good.events);
  EXPECT_NEAR(good.removed_volume_mm3, kPi * 400.0 * 1.0, 0.01 * kPi * 400.0);
}

TEST(TurningChecks, GroovingDeeperThanTheBladeDrivesItsHolderIntoTheBar) {
  const app::Profile p = lathe();
  // T4 at Z-20 down to D10 (r 5): the blade (z in [-20, -17]) is 10 deep, so its holder
  // reaches r = 15 on z in [-25, -20] and [-17, -12]: 15 <= r <= 20 over 10 mm.
  // The feed back out drags the holder through the same material: one event of two moves,
  // measured once (docs/verification.md, "Runs of findings").
  const app::BatchResult bad = run(p, kHead + "S1000 M3\nT4 M6\nG0 X50 Z-20\nG1 X10 F60\nG1 X50\nM2\n");
  ASSERT_EQ(count_kind(bad.events, verify::EventKind::HolderInMaterial), 1u) << all(bad.events);
  ASSERT_EQ(bad.events.size(), 1u) << all(bad.events);
  const verify::Event& e = bad.events[0];
  EXPECT_EQ(e.line, 5);
  EXPECT_EQ(e.last_line, 6);
  EXPECT_EQ(e.moves, 2u);
  EXPECT_EQ(e.tool, 4);
  const double expected = kPi * (400.0 - 225.0) * 10.0;
  EXPECT_NEAR(e.volume_mm3, expected, 0.01 * expected);
  EXPECT_NEAR(e.depth_mm, 13.0, 1e-9);  // Z extent of the levels met: -25 .. -12

  // Down to D22 (r 11, the holder at r 21): clean.
  const app::BatchResult good = run(p, kHead + "S1000 M3\nT4 M6\nG0 X50 Z-20\nG1 X22 F60\nG0 X50\nM2\n");
  EXPECT_TRUE(good.events.empty()) << all(good.events);
}

TEST(TurningChecks, ToolKeysForTheHolderAreRead) {
  const app::Profile p = lathe();
  const geom::TurningTool& t = p.tooling.inserts.at(4);
  EXPECT_DOUBLE_EQ(t.holder_width_mm, 13.0);
  EXPECT_DOUBLE_EQ(t.holder_z_mm, -5.0);
  EXPECT_DOUBLE_EQ(t.holder_r_mm, 10.0);
  EXPECT_DOUBLE_EQ(p.tooling.inserts.at(1).holder_r_mm, 3.0);
  std::string bad = lathe_toml();
  bad.replace(bad.find("holder_r_mm = 10.0"), 18, "holder_r_mm = -1.0");
  try {
    (void)app::parse_profile(bad, "bad.toml");
    FAIL() << "a negative holder_r_mm was accepted";
  } catch (const std::exception& ex) {
    EXPECT_NE(std::string(ex.what()).find("holder_r_mm"), std::string::npos) << ex.what();
  }
}

// The bundled lathe programs run clean on their profiles, holders included (batch and the
// twin-turret's two channels, also as sampled streams).
TEST(TurningChecks, TheBundledLatheProgramsAreClean) {
  const std::string dir = std::string(LBR_SOURCE_DIR) + "/config/";
  for (const auto& [profile, program] : {std::pair<std::string, std::string>{"lathe.toml", "lathe-shaft.ngc"},
                                        {"lathe-c.toml", "lathe-c-parts.ngc"}}) {
    app::Profile p = app::load_profile(dir + "profiles/" + profile);
    p.threads = 1;
    const app::BatchResult r = app::run_batch(p, app::load_toolpath(dir + "programs/" + program, p));
    EXPECT_TRUE(r.events.empty()) << program << "\n" << all(r.events);
  }
  app::Profile twin = app::load_profile(dir + "profiles/twin-turret-lathe.toml");
  twin.threads = 1;
  for (bool sampled : {false, true}) {
    const app::BatchResult r = app::run_batch_channels(twin, app::load_channel_paths(twin), sampled);
    EXPECT_TRUE(r.events.empty()) << "twin-turret, sampled " << sampled << "\n" << all(r.events);
  }
}

namespace {

// A closed cylinder r x [z0, z1] on the Z axis as an n-gon prism, outward-facing.
verify::StlMesh cylinder_mesh(double r, double z0, double z1, int n) {
  verify::StlMesh m;
  auto at = [&](int k, double z) {
    const double a = 2.0 * kPi * (k % n) / n;
    return geom::Vec3{r * std::cos(a), r * std::sin(a), z};
  };
  for (int k = 0; k < n; ++k) {
    m.triangles.push_back({{at(k, z0), at(k + 1, z0), at(k + 1, z1)}});
    m.triangles.push_back({{at(k, z0), at(k + 1, z1), at(k, z1)}});
  }
  for (int k = 1; k + 1 < n; ++k) {
    m.triangles.push_back({{at(0, z1), at(k, z1), at(k + 1, z1)}});
    m.triangles.push_back({{at(0, z0), at(k + 1, z0), at(k, z0)}});
  }
  return m;
}

}  // namespace

// --design on a lathe: the deepest gouge is attributed to the turning move that cut it
// (docs/verification.md, "The move that gouged").
TEST(TurningChecks, AnOverCutTurningPassIsAttributedToItsLine) {
  const std::string stl = (std::filesystem::temp_directory_path() / "lbr_turned_d30.stl").string();
  std::ofstream(stl, std::ios::binary) << verify::stl_binary(cylinder_mesh(15.0, -40.0, 0.0, 512));
  app::Profile p = lathe("", "", "0.5");  // 160 levels: the comparison's cost is per level
  p.design = {stl, 0.02};
  // Line 6 turns D30 to Z-40; line 10 goes again to Z-10 at D29.4, 0.3 mm (radius) too deep.
  const std::string program = kHead +
                              "S1000 M3\nT1 M6\nG0 X50 Z2\nG0 X30\nG1 Z-40 F200\nG1 X50\nG0 Z2\nG0 X29.4\n"
                              "G1 Z-10 F200\nG1 X50\nG0 Z2\nM2\n";
  const app::BatchResult r = run(p, program);
  ASSERT_TRUE(r.design.has_value());
  const verify::DesignReport& d = *r.design;
  const double expected = kPi * (15.0 * 15.0 - 14.7 * 14.7) * 10.0;
  EXPECT_NEAR(d.gouge_mm3, expected, 0.02 * expected);
  EXPECT_NEAR(d.max_gouge_mm, 0.3, 0.02 * 0.3);
  EXPECT_GT(d.max_gouge_at.z, -10.0);
  EXPECT_EQ(d.gouge_line, 10);
  EXPECT_EQ(d.gouge_tool, 1);
  ASSERT_EQ(count_kind(r.events, verify::EventKind::DesignGouge), 1u) << all(r.events);
  EXPECT_EQ(r.events.size(), 1u) << all(r.events);
}
