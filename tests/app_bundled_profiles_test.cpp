// Every bundled profile (config/profiles/*.toml) loads, and each module's tables give the
// values written in the file (or the module's default where the file is silent): the
// per-module readers (geom, kin, nc, motion, hal, sched, gfx) composed by app::parse_profile.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "app/profile.hpp"

using namespace lbr;

namespace {

app::Profile bundled(const std::string& file) { return app::load_profile(std::string(LBR_SOURCE_DIR) + "/config/profiles/" + file); }

}  // namespace

TEST(BundledProfiles, EveryProfileLoadsAndIsCoveredHere) {
  const std::set<std::string> covered = {"default-mill3.toml", "lathe-c.toml", "lathe.toml",
                                         "live-6axis.toml", "mill5-ac.toml", "twin-turret-lathe.toml"};
  std::set<std::string> found;
  for (const auto& e : std::filesystem::directory_iterator(std::string(LBR_SOURCE_DIR) + "/config/profiles")) {
    if (e.path().extension() != ".toml") continue;
    found.insert(e.path().filename().string());
    EXPECT_NO_THROW((void)app::load_profile(e.path().string())) << e.path();
  }
  EXPECT_EQ(found, covered) << "a new bundled profile needs its checks in this file";
}

TEST(BundledProfiles, DefaultMill3) {
  const app::Profile p = bundled("default-mill3.toml");
  EXPECT_EQ(p.name, "Generic 3-axis VMC");
  EXPECT_EQ(p.kin.kind, nc::MachineKind::Mill3);                         // kin
  EXPECT_EQ(p.machine.rapid_mm_per_min, 15000.0);                        // nc [machine]
  EXPECT_EQ(p.machine.max_velocity_mm_per_min[2], 10000.0);
  EXPECT_EQ(p.machine.max_accel_mm_per_s2[0], 2000.0);
  EXPECT_EQ(p.machine.g54_origin_mm[2], -250.0);
  EXPECT_EQ(p.machine.sample_period_ms, 4.0);
  EXPECT_EQ(p.machine.max_feed_mm_per_min, 0.0);
  EXPECT_EQ(p.solid.shape, geom::SolidSpec::Shape::Box);                 // geom
  EXPECT_EQ(p.solid.box.min.z, -30.0);
  EXPECT_EQ(p.solid.box.max.y, 80.0);
  EXPECT_EQ(p.solid.level_spacing_mm, 0.1);
  EXPECT_EQ(p.solid.regions_x, 4);
  EXPECT_EQ(p.solid.regions_y, 4);
  EXPECT_EQ(p.solid.chord_tol_mm, 0.01);
  EXPECT_FALSE(p.regions_auto);
  EXPECT_EQ(p.batch_moves, 512);                                         // app [lbr]
  EXPECT_EQ(p.threads, 0);
  ASSERT_EQ(p.tooling.tools.size(), 5u);                                 // motion
  EXPECT_EQ(p.tooling.tools.at(1).length_mm, 60.0);
  EXPECT_EQ(p.tooling.tools.at(3).kind, geom::ToolKind::Drill);
  EXPECT_EQ(p.tooling.tools.at(4).angle_deg, 90.0);
  EXPECT_EQ(p.tooling.tools.at(5).corner_radius_mm, 2.0);
  EXPECT_EQ(p.tooling.tools.at(2).holder_diameter_mm, 40.0);
  EXPECT_EQ(p.tooling.mount_of(1), kin::Mount::Spindle);
  EXPECT_TRUE(p.tooling.inserts.empty());
  EXPECT_TRUE(p.live_grid.set);                                          // app [lbr] live_regions
  EXPECT_FALSE(p.live_grid.automatic);
  EXPECT_EQ(p.live_grid.x, 16);
  EXPECT_EQ(p.live_grid.y, 16);
  EXPECT_EQ(p.live.period_ms, 1.0);                                      // hal defaults
  EXPECT_EQ(p.live.axes.size(), 3u);
  EXPECT_EQ(p.live.hal_thread.priority, 80);                             // sched defaults
  EXPECT_EQ(p.render.rate_hz, 30.0);                                     // gfx default
  EXPECT_TRUE(p.nc.subroutine_path.empty());                             // nc [nc] defaults
  EXPECT_EQ(p.nc.start_tool, 0);
  EXPECT_TRUE(p.channels.empty());
  // The compiled-in default is the same file.
  const app::Profile d = app::default_profile();
  EXPECT_EQ(d.name, p.name);
  EXPECT_EQ(d.tooling.tools.size(), p.tooling.tools.size());
  EXPECT_EQ(d.machine.g54_origin_mm, p.machine.g54_origin_mm);
  EXPECT_EQ(d.live_grid.x, p.live_grid.x);
}

TEST(BundledProfiles, Mill5AC) {
  const app::Profile p = bundled("mill5-ac.toml");
  EXPECT_EQ(p.kin.kind, nc::MachineKind::Mill5);
  EXPECT_EQ(p.kin.rotary, kin::Rotary::TableAC);
  EXPECT_EQ(p.kin.rotary_center_mm.z, 0.0);
  EXPECT_FALSE(p.kin.tcp);
  EXPECT_EQ(p.kin.pivot_length_mm, 0.0);
  EXPECT_EQ(p.solid.box.min.x, -30.0);
  EXPECT_TRUE(p.live_grid.set);  // live runs on 3.75-mm cells (docs/performance.md)
  EXPECT_EQ(p.live_grid.x, 16);
  EXPECT_EQ(p.live_grid.y, 16);
  EXPECT_EQ(p.tooling.tools.at(2).diameter_mm, 16.0);
  const nc::GcodeOptions o = app::gcode_options(p);
  EXPECT_EQ(o.machine, nc::MachineKind::Mill5);
  EXPECT_EQ(o.rotary, (std::array<bool, 3>{true, false, true}));
  EXPECT_EQ(o.tool_lengths.at(1), 60.0);
  EXPECT_EQ(o.work_offsets[0][nc::Z], -250.0);
  EXPECT_EQ(p.checks.spindle_nose_diameter_mm, 100.0);  // verify
  EXPECT_EQ(p.checks.spindle_nose_length_mm, 150.0);
}

TEST(BundledProfiles, Lathe) {
  const app::Profile p = bundled("lathe.toml");
  EXPECT_EQ(p.kin.kind, nc::MachineKind::Lathe);
  EXPECT_EQ(p.kin.turret_angle_deg, 0.0);
  EXPECT_TRUE(p.machine.diameter_programming);
  EXPECT_EQ(p.machine.rapid_mm_per_min, 10000.0);
  EXPECT_EQ(p.machine.max_velocity_mm_per_min[0], 8000.0);
  EXPECT_EQ(p.solid.shape, geom::SolidSpec::Shape::Cylinder);
  EXPECT_EQ(p.solid.cylinder.diameter_mm, 40.0);
  EXPECT_EQ(p.solid.cylinder.z_min_mm, -80.0);
  EXPECT_EQ(p.solid.regions_x, 2);
  EXPECT_TRUE(p.tooling.tools.empty());
  ASSERT_EQ(p.tooling.inserts.size(), 5u);
  EXPECT_EQ(p.tooling.inserts.at(2).insert, geom::InsertKind::Diamond55);
  EXPECT_EQ(p.tooling.inserts.at(2).edge_length_mm, 15.0);
  EXPECT_EQ(p.tooling.inserts.at(3).approach_deg, 93.0);  // v35 default
  EXPECT_EQ(p.tooling.inserts.at(4).insert, geom::InsertKind::Groove);
  EXPECT_EQ(p.tooling.inserts.at(4).width_mm, 3.0);
  EXPECT_EQ(p.tooling.inserts.at(4).edge_length_mm, 20.0);  // depth_mm
  EXPECT_TRUE(p.tooling.inserts.at(5).internal);
  EXPECT_EQ(p.tooling.mount_of(1), kin::Mount::Turning);
  const nc::GcodeOptions o = app::gcode_options(p);
  EXPECT_EQ(o.machine, nc::MachineKind::Lathe);
  EXPECT_TRUE(o.diameter_mode);
  EXPECT_EQ(o.tool_lengths.at(1), 0.0);
  EXPECT_EQ(o.work_offsets[0][nc::X], -100.0);
}

TEST(BundledProfiles, LatheC) {
  const app::Profile p = bundled("lathe-c.toml");
  EXPECT_EQ(p.kin.kind, nc::MachineKind::LatheC);
  EXPECT_EQ(p.solid.level_spacing_mm, 0.2);
  EXPECT_EQ(p.solid.cylinder.z_min_mm, -60.0);
  EXPECT_EQ(p.tooling.inserts.at(1).nose_radius_mm, 0.8);
  EXPECT_EQ(p.tooling.inserts.at(1).approach_deg, 95.0);  // diamond80 default
  EXPECT_EQ(p.tooling.mount_of(11), kin::Mount::Axial);
  EXPECT_EQ(p.tooling.mount_of(12), kin::Mount::Radial);
  EXPECT_EQ(p.tooling.mount_of(13), kin::Mount::Radial);
  EXPECT_EQ(p.tooling.tools.at(13).diameter_mm, 30.0);
  EXPECT_EQ(app::gcode_options(p).machine, nc::MachineKind::LatheC);
  EXPECT_EQ(app::gcode_options(p).tool_lengths.at(11), 0.0);
}

TEST(BundledProfiles, TwinTurretLathe) {
  const app::Profile p = bundled("twin-turret-lathe.toml");
  EXPECT_EQ(p.kin.kind, nc::MachineKind::Lathe);
  ASSERT_EQ(p.channels.size(), 2u);
  EXPECT_EQ(p.channels[0].name, "upper");
  EXPECT_EQ(p.channels[0].program, "../programs/twin-upper.ngc");
  EXPECT_EQ(p.channels[0].kin.turret_angle_deg, 0.0);
  EXPECT_EQ(p.channels[1].kin.turret_angle_deg, 180.0);
  EXPECT_EQ(p.channels[1].kin.kind, nc::MachineKind::Lathe);
  EXPECT_EQ(p.channels[1].g54_origin_mm[2], -200.0);  // the machine's G54 origin
  EXPECT_EQ(p.tooling.inserts.at(4).nose_radius_mm, 0.0);
  EXPECT_EQ(p.solid.regions_y, 2);
}

TEST(BundledProfiles, Live6Axis) {
  const app::Profile p = bundled("live-6axis.toml");
  EXPECT_EQ(p.live.period_ms, 1.0);                  // hal [live]
  EXPECT_EQ(p.live.tool, 1);
  EXPECT_EQ(p.live.ring_capacity, 4096u);
  EXPECT_EQ(p.live.geometry_duty, 0.7);
  EXPECT_EQ(p.live.serial.baud, 4000000);            // [live.serial]
  EXPECT_EQ(p.live.can.sync_counter_max, 240);       // [live.can]
  EXPECT_EQ(p.live.can.tpdo_base, 0x180u);
  ASSERT_EQ(p.live.axes.size(), 6u);                 // [[live.axis]]
  EXPECT_EQ(p.live.axes[0].max, 120.0);
  EXPECT_DOUBLE_EQ(p.live.axes[0].max_speed_per_s, 20000.0 / 60.0);
  EXPECT_EQ(p.live.axes[5].axis, 5);
  EXPECT_EQ(p.live.axes[5].node, 6);
  EXPECT_EQ(p.live.axes[5].name, "C");
  EXPECT_EQ(p.live.axes[5].scale, 0.0001);
  EXPECT_EQ(p.live.hal_thread.priority, 80);         // sched, through [threads]
  EXPECT_EQ(p.live.geometry_thread.priority, 70);
  EXPECT_EQ(p.live.geometry_thread.cpu, -1);
  EXPECT_TRUE(p.live.hal_thread.lock_memory);
  EXPECT_EQ(p.solid.chord_tol_mm, 0.001);            // geom default
  EXPECT_EQ(p.machine.g54_origin_mm[2], 0.0);         // nc default
}

namespace {

std::string error_of(const std::string& text) {
  try {
    (void)app::parse_profile(text, "m.toml");
  } catch (const app::ProfileError& e) {
    return e.what();
  }
  return "no error";
}
const std::string kStock = "[stock]\nshape = \"box\"\nmin_mm = [0, 0, -10]\nmax_mm = [50, 40, 0]\n";  // lines 1-4

}  // namespace

// Each module's reader reports "file:line: table.key: what was expected", as parse_profile did
// when it read every table itself.
TEST(BundledProfiles, EveryModulesReaderNamesFileLineAndKey) {
  EXPECT_EQ(error_of(kStock + "[machine]\ndiameter_programming = false\n"),  // nc
            "m.toml:6: machine.diameter_programming: only for machine kind lathe or lathe-c");
  EXPECT_EQ(error_of(kStock + "[machine]\ntool_change_s = -1\n"), "m.toml:6: machine.tool_change_s: expected a number in [0, 3600] s, got -1");
  EXPECT_EQ(error_of(kStock + "[machine]\nkind = \"mill5\"\ntcp = 1\n"), "m.toml:7: machine.tcp: expected true or false");  // kin
  EXPECT_EQ(error_of(kStock + "[machine]\nspeed = 1\n"), "m.toml:6: machine.speed: unknown key");  // after kin and nc
  EXPECT_EQ(error_of(kStock + "[nc]\nsubroutine_path = \"subs\"\n"), "m.toml:6: nc.subroutine_path: expected an array of folder names");
  EXPECT_EQ(error_of(kStock + "[nc]\ndialekt = \"x\"\n"), "m.toml:6: nc.dialekt: unknown key");
  EXPECT_EQ(error_of(kStock + "[render]\nrate_hz = 500\n"), "m.toml:6: render.rate_hz: expected a number in [1, 240] Hz, got 500");  // gfx
  EXPECT_EQ(error_of(kStock + "[threads]\n\ngeometry_cpu = -2\n"), "m.toml:7: threads.geometry_cpu: expected an integer in [-1, 1023]");  // sched
  EXPECT_EQ(error_of(kStock + "[live]\n[live.serial]\nbaud = 10\n"), "m.toml:7: live.serial.baud: expected an integer in [1200, 4000000]");  // hal
  EXPECT_EQ(error_of(kStock + "[[live.axis]]\naxis = \"X\"\nscale = 0\n"), "m.toml:7: live.axis.scale: must not be 0");
  EXPECT_EQ(error_of(kStock + "[[tool]]\nnumber = 1\nkind = \"bull\"\ndiameter_mm = 6\n"),  // motion
            "m.toml:5: tool.corner_radius_mm: missing (a number [mm] is required)");
  EXPECT_EQ(error_of(kStock + "[lbr]\nstrictly_simple = 1\n"), "m.toml:6: lbr.strictly_simple: expected true or false");  // geom
  EXPECT_EQ(error_of(kStock + "[lbr]\nthreads = 999\n"), "m.toml:6: lbr.threads: expected an integer in [0, 256]");  // app
  EXPECT_EQ(error_of("[stock]\nshape = \"cylinder\"\ncenter_mm = [0, 0]\ndiameter_mm = 10\nz_min_mm = 0\nz_max_mm = 0\n"),
            "m.toml:6: stock.z_max_mm: must be greater than z_min_mm");
  EXPECT_EQ(error_of("tool = 3\n" + kStock), "m.toml:1: tool: expected an array of tables [[tool]]");
}
