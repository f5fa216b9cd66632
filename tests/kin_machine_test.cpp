// Machine kinds (issue 7): C-axis live tools (lathe-c), 5-axis poses (mill5), several
// channels cutting one stock. Closed-form volumes and sizes.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "kin/kinematics.hpp"
#include "nc/emulator.hpp"
#include "nc/gcode.hpp"
#include "test_util.hpp"

using namespace lbr;

namespace {

constexpr double kTol = 0.001;

geom::SolidSpec bar(double z0, double delta = 0.1) {
  geom::SolidSpec s;
  s.shape = geom::SolidSpec::Shape::Cylinder;
  s.cylinder = {0.0, 0.0, 40.0, z0, 0.0};
  s.level_spacing_mm = delta;
  s.regions_x = 2;
  s.regions_y = 2;
  return s;
}

nc::AxisVector q_of(double x, double y, double z, double a = 0, double b = 0, double c = 0) { return {x, y, z, a, b, c}; }

// One move through the kinematics, sub-stepped as the batch runner does.
void move(geom::LbrSolid& s, const geom::CutterShape& sh, const kin::Kinematics& k, kin::Mount m, const nc::AxisVector& q0,
          const nc::AxisVector& q1, double length = 0.0) {
  const int n = kin::substeps(k, q0, q1, m, length, std::hypot(sh.height(), sh.radius()), kTol);
  std::vector<geom::SweepRef> refs;
  geom::Pose from = kin::tool_pose(k, q0, m, length);
  for (int i = 1; i <= n; ++i) {
    nc::AxisVector q;
    for (int a = 0; a < nc::kAxes; ++a) q[a] = q0[a] + (q1[a] - q0[a]) * i / n;
    const geom::Pose to = kin::tool_pose(k, q, m, length);
    refs.push_back({&sh, from, to, static_cast<geom::MoveId>(i)});
    from = to;
  }
  s.subtract(refs);
}

// Bounds of one level's material [mm].
geom::Rect level_rect(const geom::LbrSolid& s, int l) {
  geom::Rect r;
  for (int g = 0; g < s.regions(); ++g)
    if (!s.cell(g, l).bbox.empty()) r.add(s.cell(g, l).bbox);
  return r;
}

// ∫_{-w}^{w} 2·sqrt(R² − y²) dy: the area of the strip |y| <= w inside a circle of radius R.
double strip_in_circle(double w, double R) {
  auto F = [&](double y) { return y * std::sqrt(R * R - y * y) + R * R * std::asin(y / R); };
  return F(w) - F(-w);
}

}  // namespace

// ---------------------------------------------------------------- lathe-c (C axis)

TEST(LatheC, FlatAtRadius15OnD40BarRemovesTheCircularSegment) {
  geom::LbrSolid s(bar(-30.0));
  kin::Kinematics k;
  k.kind = nc::MachineKind::LatheC;
  // Radial Ø30 end mill facing the axis, spindle positioned at C90; feed along the bar.
  const auto sh = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 30, 0, 20), kTol);
  move(s, sh, k, kin::Mount::Radial, q_of(15, 0, 20, 0, 0, 90), q_of(15, 0, -50, 0, 0, 90));
  const double R = 20, h = 15;
  const double segment = R * R * std::acos(h / R) - h * std::sqrt(R * R - h * h);
  EXPECT_NEAR(test::removed(s), segment * 30.0, 2 * (2 * test::kPi * R) * kTol * 30.0);
  // C90 turned the workpiece: the flat faces -Y at y = -15.
  const geom::Rect r = level_rect(s, s.level_at(-10));
  EXPECT_NEAR(geom::to_mm(r.y0), -15.0, 0.002);
  EXPECT_NEAR(geom::to_mm(r.y1), 20.0, 0.002);
  EXPECT_NEAR(geom::to_mm(r.x0), -20.0, 0.002);
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(LatheC, RadialCrossHoleThroughTheBar) {
  geom::LbrSolid s(bar(-30.0));
  kin::Kinematics k;
  k.kind = nc::MachineKind::LatheC;
  const auto sh = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 8, 0, 60), kTol);
  move(s, sh, k, kin::Mount::Radial, q_of(25, 0, -15, 0, 0, 30), q_of(-25, 0, -15, 0, 0, 30));
  // Mid-plane sampling: per level the strip |y'| <= w(z) of the hole through the disc.
  double ideal = 0, bound = 0;
  for (int l = 0; l < s.levels(); ++l) {
    const double dz = s.level_z_mm(l) + 15.0;
    if (std::abs(dz) >= 4.0) continue;
    const double w = std::sqrt(16.0 - dz * dz);
    ideal += strip_in_circle(w, 20.0) * s.level_thickness_mm(l);
    bound += 2 * (4 * 20.0 + 4 * w) * kTol * s.level_thickness_mm(l);
  }
  EXPECT_NEAR(test::removed(s), ideal, bound);
  // Closed form of the continuous intersection (two perpendicular cylinders, radii 4 and 20):
  // the level discretisation stays below 0.5 %.
  double exact = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double y = -4.0 + 8.0 * (i + 0.5) / n;
    exact += 2 * std::sqrt(16 - y * y) * 2 * std::sqrt(400 - y * y) * 8.0 / n;
  }
  EXPECT_NEAR(test::removed(s), exact, 0.005 * exact);
  // The hole runs along C30: the level at the hole's middle is split into two pieces.
  EXPECT_EQ(s.check_invariants(), "");
}

// Ø40 cylinder on a C-axis lathe with a 6 mm axial live tool: both hexagon tests.
constexpr const char* kLatheCHexProfile = R"(
[machine]
kind = "lathe-c"
[stock]
shape = "cylinder"
center_mm = [0, 0]
diameter_mm = 40
z_min_mm = -12
z_max_mm = 0
[lbr]
level_spacing_mm = 0.25
regions = "2x2"
[[tool]]
number = 1
kind = "flat"
diameter_mm = 6
flute_length_mm = 18
live = "axial"
)";

TEST(LatheC, HexagonByPolarMillingHasItsAcrossFlats) {
  // Through the whole batch path: profile, X/C tool path, kinematics, sub-steps.
  const app::Profile p = app::parse_profile(kLatheCHexProfile, "hex.toml");
  nc::Toolpath path;
  path.start = q_of(30, 0, 5);
  path.start_tool = 1;
  auto seg = [&](nc::SegmentKind kind, double x, double z, double c) {
    nc::Segment g;
    g.kind = kind;
    g.end = q_of(x, 0, z, 0, 0, c);
    g.feed_mm_per_min = 500;
    g.tool = 1;
    path.segments.push_back(g);
  };
  // Tool centre on the hexagon of apothem 15 + 3 (flats 30 across, tool radius 3); the
  // workpiece angle φ of the tool is -C. 0.5° steps of (X, C) per side.
  const double apothem = 18.0;
  seg(nc::SegmentKind::Rapid, apothem / std::cos(test::kPi / 6), 5, 30);
  seg(nc::SegmentKind::Feed, apothem / std::cos(test::kPi / 6), -5, 30);
  for (int side = 0; side < 6; ++side) {
    for (int i = 1; i <= 120; ++i) {
      const double phi = -30.0 + 60.0 * side + 0.5 * i;  // [deg]
      const double rel = phi - 60.0 * side;
      seg(nc::SegmentKind::Feed, apothem / std::cos(rel * test::kPi / 180), -5, -phi);
    }
  }
  seg(nc::SegmentKind::Feed, 30, -5, -330);
  const app::BatchResult r = app::run_batch(p, path);
  const double hex_area = 2.0 * std::sqrt(3.0) * 15.0 * 15.0;
  for (int l = 0; l < r.solid.levels(); ++l) {
    const double z = r.solid.level_z_mm(l);
    const geom::Rect b = level_rect(r.solid, l);
    if (z > -5.0) {
      EXPECT_NEAR(geom::to_mm(b.x1) - geom::to_mm(b.x0), 30.0, 0.01) << "across flats, z " << z;
      EXPECT_NEAR(geom::to_mm(b.y1) - geom::to_mm(b.y0), 30.0 / std::cos(test::kPi / 6), 0.01) << "across corners";
      EXPECT_NEAR(r.solid.level_area_mm2(l), hex_area, 0.01 * 6 * 17.32);
    } else {
      EXPECT_NEAR(r.solid.level_area_mm2(l), test::kPi * 400, 2 * 2 * test::kPi * 20 * kTol);
    }
  }
  EXPECT_EQ(r.solid.check_invariants(), "");
}

TEST(LatheC, HexagonByG12_1PolarInterpolation) {
  const app::Profile p = app::parse_profile(kLatheCHexProfile, "hex.toml");
  // G7: X words are diameters of the Cartesian x; C words are the Cartesian y [mm].
  const std::string prog =
      "G18 G7 G90 G21\nT1 M6 S1000 M3\nG0 X80 Z5\nG0 X41.569219 C30\nG12.1\nG1 Z-5 F300\n"
      "G1 X36 C10.392305 F600\nG1 X0 C20.784610\nG1 X-36 C10.392305\nG1 X-36 C-10.392305\n"
      "G1 X0 C-20.784610\nG1 X36 C-10.392305\nG0 Z5\nG13.1\nG0 X80\n";
  const nc::Toolpath path = nc::interpret_gcode(prog, "hex.ngc", app::gcode_options(p));
  EXPECT_GT(path.segments.size(), 300u);  // each side became ~110 polar steps
  const app::BatchResult r = app::run_batch(p, path);
  const double hex_area = 2.0 * std::sqrt(3.0) * 15.0 * 15.0;
  for (int l = 0; l < r.solid.levels(); ++l) {
    const double z = r.solid.level_z_mm(l);
    if (z < -5.0) continue;
    const geom::Rect b = level_rect(r.solid, l);
    EXPECT_NEAR(geom::to_mm(b.x1) - geom::to_mm(b.x0), 30.0, 0.01) << "across flats, z " << z;
    EXPECT_NEAR(r.solid.level_area_mm2(l), hex_area, 0.01 * 6 * 17.32);
  }
  // Polar interpolation belongs to lathe-c; a line through the spindle axis is refused.
  EXPECT_THROW((void)nc::interpret_gcode("G12.1\n", "x.ngc", app::gcode_options(app::default_profile())), nc::ParseError);
  EXPECT_THROW((void)nc::interpret_gcode("G18 G7\nT1 M6\nG0 X40 C0\nG12.1\nG1 X-40 C0 F100\n", "x.ngc",
                                         app::gcode_options(p)),
               nc::ParseError);
}

// ---------------------------------------------------------------- mill5

TEST(Mill5, TiltedFlatEndMillPlungeLeavesTheEllipticalFootprint) {
  geom::LbrSolid s(test::box_spec({-30, -30, -20}, {30, 30, 0}, 0.1));
  kin::Kinematics k;
  k.kind = nc::MachineKind::Mill5;
  k.rotary = kin::Rotary::TableAC;
  // A30 tilts the workpiece; a plunge along machine Z is a plunge along the tool axis.
  const double R = 5.0;
  const auto sh = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 2 * R, 0, 30), kTol);
  move(s, sh, k, kin::Mount::Spindle, q_of(0, 0, 20, 30, 0, 0), q_of(0, 0, -5, 30, 0, 0));
  const geom::Pose end = kin::tool_pose(k, q_of(0, 0, -5, 30, 0, 0), kin::Mount::Spindle);
  EXPECT_NEAR(end.axis.z, std::cos(test::kPi / 6), 1e-12);
  EXPECT_NEAR(std::abs(end.axis.y), 0.5, 1e-12);
  // Above the highest point of the tip disc every level is cut by the cylinder alone: an
  // ellipse with semi-axes R and R / cos 30°.
  const double z_full = end.tip.z + R * std::sin(test::kPi / 6);
  const double ellipse = test::kPi * R * R / std::cos(test::kPi / 6);
  const double perim = test::kPi * (3 * (R + R / 0.866) - std::sqrt((3 * R + R / 0.866) * (R + 3 * R / 0.866)));
  int full = 0;
  double prev = 0;
  for (int l = 0; l < s.levels(); ++l) {
    const double z = s.level_z_mm(l);
    const double cut = 3600.0 - s.level_area_mm2(l);
    if (z > z_full) {
      EXPECT_NEAR(cut, ellipse, 2 * perim * kTol) << "z " << z;
      ++full;
    } else {
      EXPECT_GE(cut, prev - 1e-6) << "the footprint grows with z, z " << z;
    }
    prev = cut;
  }
  EXPECT_GT(full, 15);
}

TEST(Mill5, TiltedSlotVolumeMatchesTheClosedForm) {
  // Head B/C with TCP: B30 tilts the tool in XZ; the slot runs along Y through the block.
  geom::LbrSolid s(test::box_spec({-20, 0, -20}, {20, 40, 0}, 0.1));
  kin::Kinematics k;
  k.kind = nc::MachineKind::Mill5;
  k.rotary = kin::Rotary::HeadBC;
  k.tcp = true;
  const double R = 5.0, H = 30.0, th = test::kPi / 6;
  const auto sh = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 2 * R, 0, H), kTol);
  move(s, sh, k, kin::Mount::Spindle, q_of(0, -10, -3, 0, 30, 0), q_of(0, 50, -3, 0, 30, 0));
  // Cross-section perpendicular to Y: the tool's projection, a rectangle 2R x H tilted by
  // 30°, clipped by the top face z = 0; the block is 40 mm long.
  const double ax = std::sin(th), az = std::cos(th), ux = std::cos(th), uz = -std::sin(th);
  std::vector<std::pair<double, double>> poly{{-R * ux, -3 - R * uz},
                                             {R * ux, -3 + R * uz},
                                             {R * ux + H * ax, -3 + R * uz + H * az},
                                             {-R * ux + H * ax, -3 - R * uz + H * az}};
  std::vector<std::pair<double, double>> clipped;  // Sutherland–Hodgman against z <= 0
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const auto a = poly[i], b = poly[(i + 1) % poly.size()];
    const bool ia = a.second <= 0, ib = b.second <= 0;
    if (ia) clipped.push_back(a);
    if (ia != ib) {
      const double t = a.second / (a.second - b.second);
      clipped.push_back({a.first + t * (b.first - a.first), 0.0});
    }
  }
  double area = 0;
  for (std::size_t i = 0; i < clipped.size(); ++i) {
    const auto a = clipped[i], b = clipped[(i + 1) % clipped.size()];
    area += 0.5 * (a.first * b.second - b.first * a.second);
  }
  area = std::abs(area);
  // Mid-plane sampling is exact here: the width is piecewise linear with kinks at z = -5.5
  // and z = -0.5, both slab boundaries.
  EXPECT_NEAR(test::removed(s), area * 40.0, 2 * 2 * 40.0 * kTol * 5.5 + 0.05);
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Mill5, ZeroTiltGivesTheSameResultAsMill3) {
  const std::string prog =
      "G21 G90 G17\nT1 M6\nG43 H1\nG0 X-8 Y20 Z5\nG1 Z-3 F800\nG1 X40 Y25\nG2 X60 Y45 I0 J20\nG1 Y70\n"
      "G1 X20 Z-6\nG0 Z5\n";
  app::Profile p3 = app::default_profile();
  app::Profile p5 = p3;
  p5.kin.kind = nc::MachineKind::Mill5;
  p5.kin.rotary = kin::Rotary::TableAC;
  p5.kin.rotary_center_mm = {37.5, 41.25, -12.3};
  const auto path3 = nc::interpret_gcode(prog, "p.ngc", app::gcode_options(p3));
  const auto path5 = nc::interpret_gcode(prog + "G0 A0 C0\n", "p.ngc", app::gcode_options(p5));
  const app::BatchResult r3 = app::run_batch(p3, path3);
  const app::BatchResult r5 = app::run_batch(p5, path5);
  EXPECT_GT(r3.removed_volume_mm3, 1000.0);
  EXPECT_EQ(r3.removed_volume_mm3, r5.removed_volume_mm3);
  ASSERT_EQ(r3.solid.levels(), r5.solid.levels());
  for (int g = 0; g < r3.solid.regions(); ++g) {
    for (int l = 0; l < r3.solid.levels(); ++l) {
      const auto& a = r3.solid.cell(g, l).polys;
      const auto& b = r5.solid.cell(g, l).polys;
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i].outer.pts, b[i].outer.pts);
    }
  }
}

// A tool change keeps the gauge line where it is, so a longer tool's tip comes down by the
// difference of the lengths (docs/nc-frontend.md): the next move starts from that tip, on
// G-code segments as on the machine's sampled stream. Default profile: T2 (ball, 50 mm) at
// Z2, then T1 (flat Ø10, 60 mm) without a new G43 stands 8 mm deep; G1 X40 cuts a slot from
// there, an exact prism of a stadium (20 x 10 mm plus the two half disks) 8 mm deep. Before
// the fix the segments ran the slot from the old tip, a ramp down from Z2 (1 267 mm³).
TEST(ToolChange, TheNextMoveStartsFromTheNewToolsTip) {
  const std::string prog = "G21 G90 G17\nT2 M6\nG43 H2\nS8000 M3\nG0 X20 Y20 Z2\nT1 M6\nG1 X40 F500\nG0 Z60\n";
  for (const bool mill5 : {false, true}) {
    app::Profile p = app::default_profile();
    if (mill5) {  // the axes through the kinematics (SweepMapper), not the direct path
      p.kin.kind = nc::MachineKind::Mill5;
      p.kin.rotary = kin::Rotary::TableAC;
    }
    const nc::Toolpath path = nc::interpret_gcode(prog, "p.ngc", app::gcode_options(p));
    const double expect = (20.0 * 10.0 + test::kPi * 25.0) * 8.0;
    const double segments = app::run_batch(p, path).removed_volume_mm3;
    const double sampled = app::run_batch(p, nc::sampled_toolpath(path, app::emulator_limits(p))).removed_volume_mm3;
    EXPECT_NEAR(segments, expect, 1e-3 * expect) << (mill5 ? "mill5" : "mill3");
    EXPECT_NEAR(sampled, expect, 1e-3 * expect) << (mill5 ? "mill5" : "mill3");
  }
}

TEST(Mill5, HeadWithoutTcpTurnsAboutThePivot) {
  kin::Kinematics k;
  k.kind = nc::MachineKind::Mill5;
  k.rotary = kin::Rotary::HeadBC;
  k.pivot_length_mm = 100.0;
  // Tool 50 long: the pivot is 150 above the programmed tip; B90 swings the tip to +X.
  const geom::Pose p = kin::tool_pose(k, q_of(10, 20, 30, 0, 90, 0), kin::Mount::Spindle, 50.0);
  EXPECT_NEAR(p.tip.x, 10 - 150.0, 1e-9);  // axis +X (tip → holder): the tip lies at -X
  EXPECT_NEAR(p.tip.z, 30 + 150.0, 1e-9);
  EXPECT_NEAR(p.axis.x, 1.0, 1e-12);
  // Table A/C: C90 turns the workpiece, a point at +X of the centre appears at -Y.
  kin::Kinematics t;
  t.kind = nc::MachineKind::Mill5;
  t.rotary_center_mm = {5, 5, 0};
  const geom::Pose q = kin::tool_pose(t, q_of(15, 5, 0, 0, 0, 90), kin::Mount::Spindle);
  EXPECT_NEAR(q.tip.x, 5.0, 1e-9);
  EXPECT_NEAR(q.tip.y, -5.0, 1e-9);
  // A move turning C by 90° at 10 mm from the centre is cut into chords within tolerance.
  const int n = kin::substeps(t, q_of(15, 5, 0), q_of(15, 5, 0, 0, 0, 90), kin::Mount::Spindle, 0, 0, kTol);
  const double chord_err = 10.0 * (1 - std::cos(0.5 * (test::kPi / 2) / n));
  EXPECT_LE(chord_err, kTol);
  EXPECT_GT(10.0 * (1 - std::cos(0.5 * (test::kPi / 2) / (n - 1))), kTol);
}

// ---------------------------------------------------------------- several channels

namespace {

const char* kTwin = R"(
[machine]
kind = "lathe"
g54_origin_mm = [-100, 0, -200]
[stock]
shape = "cylinder"
center_mm = [0, 0]
diameter_mm = 40
z_min_mm = -60
z_max_mm = 0
[lbr]
level_spacing_mm = 0.2
regions = "2x2"
[[tool]]
number = 1
kind = "turning"
insert = "diamond80"
nose_radius_mm = 0.0
approach_angle_deg = 90
[[tool]]
number = 2
kind = "grooving"
width_mm = 3
[[channel]]
name = "upper"
[[channel]]
name = "lower"
turret_angle_deg = 180
)";

// Upper turret: Ø30 over [-20, 0]. Lower turret: groove Ø30 x 3 at Z-40.
const char* kUpper = "G18 G7 G90\nT1 M6\nG0 X50 Z2\nG1 X30 F200\nG1 Z-20\nG1 X50\nG0 Z2\n";
const char* kLower = "G18 G7 G90\nT2 M6\nG0 X50 Z-40\nG1 X42 F400\nG1 X30 F100\nG1 X50\n";

std::vector<app::ChannelPath> channels(const app::Profile& p, const std::string& up, const std::string& low) {
  std::vector<app::ChannelPath> c;
  c.push_back({"upper", nc::interpret_gcode(up, "upper.ngc", app::gcode_options(p)), p.channels[0].kin});
  c.push_back({"lower", nc::interpret_gcode(low, "lower.ngc", app::gcode_options(p)), p.channels[1].kin});
  return c;
}

}  // namespace

TEST(Channels, SimultaneousEqualsOneAfterTheOther) {
  const app::Profile p = app::parse_profile(kTwin, "twin.toml");
  ASSERT_EQ(p.channels.size(), 2u);
  const double expect = test::kPi * (400 - 225) * (20 + 3);
  const auto both = app::run_batch_channels(p, channels(p, kUpper, kLower));
  // The lower turret waits until the upper one is done (G4 dwell longer than its program).
  const auto sequential = app::run_batch_channels(p, channels(p, kUpper, std::string("G4 P120\n") + kLower));
  EXPECT_NEAR(both.removed_volume_mm3, expect, 2 * 2 * test::kPi * 35 * kTol * 23);
  EXPECT_NEAR(sequential.removed_volume_mm3, both.removed_volume_mm3, 1e-6 * expect);
  EXPECT_GT(sequential.machining_time_s, 120.0);
  EXPECT_LT(both.machining_time_s, 60.0);
}

TEST(Channels, InterleavingOrderDoesNotChangeTheResult) {
  const app::Profile p = app::parse_profile(kTwin, "twin.toml");
  const auto a = app::run_batch_channels(p, channels(p, kUpper, kLower));
  auto swapped = channels(p, kUpper, kLower);
  std::swap(swapped[0], swapped[1]);
  const auto b = app::run_batch_channels(p, swapped);
  const auto c = app::run_batch_channels(p, channels(p, kUpper, kLower), /*sampled=*/true);
  EXPECT_NEAR(a.removed_volume_mm3, b.removed_volume_mm3, 1e-6 * a.removed_volume_mm3);
  EXPECT_NEAR(a.removed_volume_mm3, c.removed_volume_mm3, 1e-4 * a.removed_volume_mm3);
  EXPECT_GT(c.moves, 10 * a.moves);  // the sampled streams really interleaved many sweeps
  for (int l = 0; l < a.solid.levels(); ++l)
    EXPECT_NEAR(a.solid.level_area_mm2(l), c.solid.level_area_mm2(l), 2 * 2 * test::kPi * 20 * kTol)
        << a.solid.level_z_mm(l);
}

// ---------------------------------------------------------------- bundled lathe example

TEST(LatheExample, ShaftProgramMatchesItsDrawingAtEveryLevel) {
  // config/programs/lathe-shaft.ngc on config/profiles/lathe.toml, through the G-code front
  // end and the batch runner. Drawing: face at Z-0.5; Ø24 to Z-15, Ø30 to Z-30, Ø36 to Z-45
  // with the finishing insert's 0.4 nose fillets in the inner corners; groove Ø26 over
  // [-27, -24] with 0.2 corners; bore Ø12 to Z-20 with a 0.4 fillet at its bottom.
  const std::string dir = std::string(LBR_SOURCE_DIR) + "/config/";
  const app::Profile p = app::load_profile(dir + "profiles/lathe.toml");
  const app::BatchResult r = app::run_batch(p, app::load_toolpath(dir + "programs/lathe-shaft.ngc", p));
  auto fillet = [](double r0, double re, double z_corner, double z) {  // inner corner at z_corner
    const double dz = z_corner + re - z;
    return dz > 0.0 ? r0 + re - std::sqrt(re * re - dz * dz) : r0;
  };
  auto outer = [&](double z) {
    if (z <= -45.0) return 20.0;
    if (z <= -30.0) return fillet(18.0, 0.4, -45.0, z);
    if (z <= -27.0) return fillet(15.0, 0.4, -30.0, z);
    if (z <= -24.0) {  // groove bottom, 0.2 corners at both walls
      const double lo = fillet(13.0, 0.2, -27.0, z);
      const double dz = z - (-24.0 - 0.2);
      return dz > 0.0 ? std::max(lo, 13.2 - std::sqrt(0.04 - dz * dz)) : lo;
    }
    if (z <= -15.0) return 15.0;
    return fillet(12.0, 0.4, -15.0, z);
  };
  auto inner = [](double z) {
    if (z <= -20.0) return 0.0;
    const double dz = z - (-20.0 + 0.4);
    return dz < 0.0 ? 5.6 + std::sqrt(0.16 - dz * dz) : 6.0;
  };
  int checked = 0;
  for (int l = 0; l < r.solid.levels(); ++l) {
    const double z = r.solid.level_z_mm(l);
    const double area = r.solid.level_area_mm2(l);
    if (z > -0.5) {
      EXPECT_NEAR(area, 0.0, 1e-9) << "faced off, z " << z;
      continue;
    }
    const double ro = outer(z), ri = inner(z);
    EXPECT_NEAR(area, test::kPi * (ro * ro - ri * ri), 2 * test::kPi * (ro + ri) * 0.003) << "z " << z;
    ++checked;
  }
  EXPECT_EQ(checked, 795);
}
