// [machine] keys for the emulator and the G-code frames (docs/profiles.md).
#include <gtest/gtest.h>

#include <string>

#include "app/profile.hpp"

namespace {

using namespace lbr;

const std::string kStock = "[stock]\nshape = \"box\"\nmin_mm = [0, 0, -10]\nmax_mm = [50, 50, 0]\n";

std::string error_of(const std::string& text) {
  try {
    (void)app::parse_profile(text, "p.toml");
  } catch (const app::ProfileError& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(MachineProfile, EmulatorKeysReachTheLimits) {
  const app::Profile p = app::parse_profile(
      "[machine]\nrapid_mm_per_min = 20000\ntool_change_s = 4\nmax_velocity_mm_per_min = [18000, 17000, 9000]\n"
      "max_accel_mm_per_s2 = [3000, 2500, 1200]\nmax_feed_mm_per_min = 8000\nsample_period_ms = 2\n"
      "g54_origin_mm = [-300, -200, -400]\n" + kStock +
      "[[tool]]\nnumber = 7\nkind = \"flat\"\ndiameter_mm = 6\nlength_mm = 42\n",
      "p.toml");
  const nc::EmulatorLimits l = app::emulator_limits(p);
  EXPECT_DOUBLE_EQ(l.rapid_mm_per_min, 20000);
  EXPECT_DOUBLE_EQ(l.tool_change_s, 4);
  EXPECT_DOUBLE_EQ(l.max_velocity[nc::Y], 17000);
  EXPECT_DOUBLE_EQ(l.max_accel[nc::Z], 1200);
  EXPECT_DOUBLE_EQ(l.max_feed_mm_per_min, 8000);
  EXPECT_DOUBLE_EQ(l.sample_period_ms, 2);
  const nc::GcodeOptions o = app::gcode_options(p);
  EXPECT_DOUBLE_EQ(o.tool_lengths.at(7), 42);
  EXPECT_DOUBLE_EQ(o.tool_diameters.at(7), 6);
  EXPECT_DOUBLE_EQ(o.work_offsets[0][nc::X], -300);
  EXPECT_DOUBLE_EQ(o.work_offsets[0][nc::Z], -400);
  EXPECT_DOUBLE_EQ(o.chord_tol_mm, p.solid.chord_tol_mm);
}

TEST(MachineProfile, DefaultsWithoutTheKeys) {
  const app::Profile p = app::parse_profile("[machine]\nrapid_mm_per_min = 9000\n" + kStock, "p.toml");
  const nc::EmulatorLimits l = app::emulator_limits(p);
  EXPECT_DOUBLE_EQ(l.max_velocity[nc::X], 9000);  // the rapid rate
  EXPECT_DOUBLE_EQ(l.max_accel[nc::X], 1000);
  EXPECT_DOUBLE_EQ(l.sample_period_ms, 4);
  EXPECT_DOUBLE_EQ(app::gcode_options(p).work_offsets[0][nc::Z], 0);
  // The built-in default profile sets them all.
  const app::Profile d = app::default_profile();
  EXPECT_DOUBLE_EQ(d.machine.max_accel_mm_per_s2[2], 1500);
  EXPECT_DOUBLE_EQ(d.machine.g54_origin_mm[2], -250);
}

TEST(MachineProfile, BadValuesNameFileLineAndKey) {
  EXPECT_EQ(error_of("[machine]\nmax_velocity_mm_per_min = [1, 2]\n" + kStock),
            "p.toml:2: machine.max_velocity_mm_per_min: expected an array of 3 numbers [mm/min]");
  EXPECT_EQ(error_of("[machine]\n\nmax_accel_mm_per_s2 = [100, 0, 100]\n" + kStock),
            "p.toml:3: machine.max_accel_mm_per_s2: expected numbers in [1, 1e+06] mm/s2, got 0");
  EXPECT_EQ(error_of("[machine]\nsample_period_ms = 0\n" + kStock),
            "p.toml:2: machine.sample_period_ms: expected a number in [0.1, 1000] ms, got 0");
  EXPECT_EQ(error_of("[machine]\nsample_period = 4\n" + kStock), "p.toml:2: machine.sample_period: unknown key");
}

}  // namespace
