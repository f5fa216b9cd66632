// Profile keys of the machine kinds (issue 7): values reach the kinematics, tools and
// channels; misuse names file, line and key.
#include <gtest/gtest.h>

#include <string>

#include "app/profile.hpp"

namespace {

using namespace lbr;

const std::string kBar = "[stock]\nshape = \"cylinder\"\ncenter_mm = [0, 0]\ndiameter_mm = 40\nz_min_mm = -50\nz_max_mm = 0\n";
const std::string kBox = "[stock]\nshape = \"box\"\nmin_mm = [0, 0, -10]\nmax_mm = [50, 50, 0]\n";

std::string error_of(const std::string& text) {
  try {
    (void)app::parse_profile(text, "k.toml");
  } catch (const app::ProfileError& e) {
    return e.what();
  }
  return "<no error>";
}

}  // namespace

TEST(KindsProfile, Mill5KeysReachTheKinematics) {
  const app::Profile p = app::parse_profile("[machine]\nkind = \"mill5\"\nrotary = \"head-bc\"\npivot_length_mm = 120\n"
                                            "tcp = true\nrotary_center_mm = [1, 2, 3]\n" + kBox,
                                            "k.toml");
  EXPECT_EQ(p.kin.kind, nc::MachineKind::Mill5);
  EXPECT_EQ(p.kin.rotary, kin::Rotary::HeadBC);
  EXPECT_DOUBLE_EQ(p.kin.pivot_length_mm, 120);
  EXPECT_TRUE(p.kin.tcp);
  EXPECT_DOUBLE_EQ(p.kin.rotary_center_mm.z, 3);
  EXPECT_EQ(app::gcode_options(p).machine, nc::MachineKind::Mill5);
}

TEST(KindsProfile, LatheToolsAndMounts) {
  const app::Profile p = app::parse_profile(
      "[machine]\nkind = \"lathe-c\"\ndiameter_programming = false\nturret_angle_deg = 90\n" + kBar +
          "[[tool]]\nnumber = 1\nkind = \"turning\"\ninsert = \"v35\"\nnose_radius_mm = 0.2\n"
          "[[tool]]\nnumber = 2\nkind = \"grooving\"\nwidth_mm = 2.5\n"
          "[[tool]]\nnumber = 3\nkind = \"boring\"\n"
          "[[tool]]\nnumber = 4\nkind = \"drill\"\ndiameter_mm = 5\nlive = \"radial\"\n"
          "[[tool]]\nnumber = 5\nkind = \"flat\"\ndiameter_mm = 6\n",
      "k.toml");
  EXPECT_EQ(p.tooling.mount_of(1), kin::Mount::Turning);
  EXPECT_EQ(p.tooling.inserts.at(1).insert, geom::InsertKind::V35);
  EXPECT_DOUBLE_EQ(p.tooling.inserts.at(1).approach_deg, 93.0);
  EXPECT_EQ(p.tooling.inserts.at(2).insert, geom::InsertKind::Groove);
  EXPECT_DOUBLE_EQ(p.tooling.inserts.at(2).width_mm, 2.5);
  EXPECT_TRUE(p.tooling.inserts.at(3).internal);
  EXPECT_EQ(p.tooling.mount_of(4), kin::Mount::Radial);
  EXPECT_EQ(p.tooling.mount_of(5), kin::Mount::Axial);  // lathe-c milling tools default to axial
  EXPECT_DOUBLE_EQ(p.kin.turret_angle_deg, 90);
  const nc::GcodeOptions o = app::gcode_options(p);
  EXPECT_EQ(o.machine, nc::MachineKind::LatheC);
  EXPECT_FALSE(o.diameter_mode);
  EXPECT_DOUBLE_EQ(o.tool_lengths.at(4), 0.0);  // lathes: programmed point = tool reference
}

TEST(KindsProfile, ChannelsInheritAndOverride) {
  const app::Profile p = app::parse_profile("[machine]\nkind = \"lathe\"\ng54_origin_mm = [-100, 0, -200]\n" + kBar +
                                                "[[channel]]\nname = \"up\"\nprogram = \"a.ngc\"\n"
                                                "[[channel]]\nname = \"low\"\nprogram = \"b.ngc\"\nturret_angle_deg = 180\n"
                                                "g54_origin_mm = [-90, 0, -210]\n",
                                            "k.toml");
  ASSERT_EQ(p.channels.size(), 2u);
  EXPECT_EQ(p.channels[0].name, "up");
  EXPECT_DOUBLE_EQ(p.channels[0].kin.turret_angle_deg, 0);
  EXPECT_DOUBLE_EQ(p.channels[0].g54_origin_mm[2], -200);
  EXPECT_DOUBLE_EQ(p.channels[1].kin.turret_angle_deg, 180);
  EXPECT_DOUBLE_EQ(app::gcode_options(p, p.channels[1]).work_offsets[0][nc::Z], -210);
}

TEST(KindsProfile, MisuseNamesFileLineAndKey) {
  EXPECT_EQ(error_of("[machine]\nkind = \"mill3\"\nrotary = \"table-ac\"\n" + kBox),
            "k.toml:3: machine.rotary: only for machine kind mill5");
  EXPECT_EQ(error_of("[machine]\nkind = \"mill5\"\nrotary = \"table-xy\"\n" + kBox),
            "k.toml:3: machine.rotary: expected \"table-ac\", \"table-bc\", \"head-ac\" or \"head-bc\", got 'table-xy'");
  EXPECT_EQ(error_of("[machine]\nkind = \"mill3\"\nturret_angle_deg = 180\n" + kBox),
            "k.toml:3: machine.turret_angle_deg: only for machine kind lathe or lathe-c");
  EXPECT_EQ(error_of("[machine]\nkind = \"lathe\"\n" + kBox),
            "k.toml:3: stock: machine kind lathe needs a cylinder stock on the spindle axis (shape = \"cylinder\", "
            "center_mm = [0, 0])");
  EXPECT_EQ(error_of(kBox + "[[tool]]\nnumber = 1\nkind = \"turning\"\n"),
            "k.toml:7: tool.kind: 'turning' tools need machine kind lathe or lathe-c, this is mill3");
  EXPECT_EQ(error_of("[machine]\nkind = \"lathe\"\n" + kBar + "[[tool]]\nnumber = 1\nkind = \"flat\"\ndiameter_mm = 6\n"),
            "k.toml:11: tool.kind: a lathe has no live tools (use machine kind lathe-c), got a 'flat' tool");
  EXPECT_EQ(error_of(kBox + "[[tool]]\nnumber = 1\nkind = \"flat\"\ndiameter_mm = 6\nlive = \"axial\"\n"),
            "k.toml:9: tool.live: only for machine kind lathe-c");
  EXPECT_EQ(error_of("[machine]\nkind = \"lathe\"\n" + kBar + "[[tool]]\nnumber = 1\nkind = \"turning\"\ninsert = \"diamond55\"\n"
                     "approach_angle_deg = 140\n"),
            "k.toml:13: tool.approach_angle_deg: must be in [90, 125] for a diamond55 insert");
  EXPECT_EQ(error_of("[machine]\nkind = \"lathe\"\n" + kBar + "[[tool]]\nnumber = 1\nkind = \"grooving\"\nwidth_mm = 3\n"
                     "insert = \"v35\"\n"),
            "k.toml:13: tool.insert: unknown key");
  EXPECT_EQ(error_of("[machine]\nkind = \"lathe\"\n" + kBar + "[[channel]]\nname = \"a\"\nspeed = 3\n"),
            "k.toml:11: channel.speed: unknown key");
  EXPECT_EQ(error_of("[machine]\nkind = \"lathe\"\n" + kBar + "[[channel]]\nname = \"a\"\n[[channel]]\nname = \"a\"\n"),
            "k.toml:12: channel.name: channel 'a' is defined twice");
}
