// G70/G71/G72 lathe cycles in the built-in interpreter (docs/nc-frontend.md#lathe-cycles-g76-g7x):
// `lbrsim batch` on the bundled lathe profile (insert nose radius made 0.01 mm so the part is
// the programmed profile) removes the analytic volume of a step and of a straight taper within
// 0.1 %, and the same volume as LinuxCNC's rs274 within 0.1 % when linuxcnc-uspace is
// installed. The cycles' own moves are checked pass by pass on a hand-computed case.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <array>
#include <vector>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "nc/gcode.hpp"
#include "nc/rs274.hpp"

namespace {

using namespace lbr;
constexpr double kPi = 3.14159265358979323846;

app::Profile sharp_lathe() {
  std::ifstream f(std::string(LBR_SOURCE_DIR) + "/config/profiles/lathe.toml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string text = ss.str();
  for (std::size_t p = text.find("nose_radius_mm = "); p != std::string::npos; p = text.find("nose_radius_mm = ", p + 1))
    text.replace(p, text.find('\n', p) - p, "nose_radius_mm = 0.01");
  return app::parse_profile(text, "lathe.toml");
}

double removed_mm3(const std::string& program, app::Interpreter interp) {
  // One file per test and process: ctest runs the cases in parallel processes.
  const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string path = ::testing::TempDir() + "g7x_" + t->name() + "_" + std::to_string(::getpid()) + ".ngc";
  std::ofstream(path) << program;
  const app::Profile profile = sharp_lathe();
  const double removed = app::run_batch(profile, app::load_toolpath(path, profile, interp)).removed_volume_mm3;
  std::remove(path.c_str());
  return removed;
}

// Both interpreters (rs274 when installed) against the analytic volume.
void expect_volume(const std::string& program, double expected_mm3) {
  const double builtin = removed_mm3(program, app::Interpreter::Builtin);
  EXPECT_NEAR(builtin, expected_mm3, 1e-3 * expected_mm3);
  if (nc::find_rs274().empty()) return;
  const double rs274 = removed_mm3(program, app::Interpreter::Rs274);
  EXPECT_NEAR(builtin, rs274, 1e-3 * rs274);
}

const char* kHead = "G18 G7 G21 G90 G94\nT1 M6\nM3 S1000\nF200\n";

// Stock: diameter 40, Z -80..0. Step: diameter 20 for Z -20..0, 30 for Z -40..-20.
const char* kStep = "O100 SUB\n G0 X20 Z2\n G1 Z-20\n X30\n Z-40\n X42\nO100 ENDSUB\n";
const double kStepMm3 = kPi * ((400.0 - 100.0) * 20.0 + (400.0 - 225.0) * 20.0);

// Taper: diameter 20 at Z-10 to 42 at Z-30 (radius 20 at Z = -10 - 200/11), diameter 20 for Z -10..0.
const char* kTaper = "O200 SUB\n G0 X42 Z-30\n G1 X20 Z-10\n Z2\nO200 ENDSUB\n";
double taper_mm3() {
  const double len = 200.0 / 11.0;  // frustum from radius 10 to 20
  const double frustum = kPi * (400.0 * len - len * (100.0 + 200.0 + 400.0) / 3.0);
  return kPi * (400.0 - 100.0) * 10.0 + frustum;
}

TEST(LatheG7x, G71StepRemovesTheAnalyticVolume) {
  expect_volume(std::string(kHead) + kStep + "G0 X44 Z2\nG71 Q100 X44 Z2 I1 R0.5\nG0 X60 Z20\nM2\n", kStepMm3);
}

TEST(LatheG7x, G72StepRemovesTheAnalyticVolume) {
  expect_volume(std::string(kHead) + kStep + "G0 X44 Z2\nG72 Q100 X44 Z2 I1 R0.5\nG0 X60 Z20\nM2\n", kStepMm3);
}

TEST(LatheG7x, G71TaperThenG70RemovesTheAnalyticVolume) {
  expect_volume(std::string(kHead) + kTaper + "G0 X44 Z2\nG71 Q200 X44 Z2 I1.5 R0.3\nG70 Q200 X44 Z2\nG0 X60 Z20\nM2\n",
                taper_mm3());
}

TEST(LatheG7x, G72TaperRemovesTheAnalyticVolume) {
  expect_volume(std::string(kHead) + kTaper + "G0 X44 Z2\nG72 Q200 X44 Z2 I0.7 R0.2\nG0 X60 Z20\nM2\n", taper_mm3());
}

// The segments' end points and kinds, consecutive repeats dropped (rs274 repeats positions).
std::vector<std::array<double, 3>> path_of(const nc::Toolpath& tp) {
  std::vector<std::array<double, 3>> out;
  for (const nc::Segment& s : tp.segments) {
    const std::array<double, 3> p{s.end[nc::X], s.end[nc::Z], s.kind == nc::SegmentKind::Feed ? 1.0 : 0.0};
    if (!out.empty() && std::abs(out.back()[0] - p[0]) < 1e-9 && std::abs(out.back()[1] - p[1]) < 1e-9) continue;
    out.push_back(p);
  }
  return out;
}

// The built-in path against hand-computed feeds, then against rs274's path (when installed):
// the same moves within 1e-4 mm (rs274 prints 4 decimals).
void expect_path(const std::string& program, const std::vector<std::array<double, 2>>& want_feeds) {
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  const std::vector<std::array<double, 3>> ours = path_of(nc::interpret_gcode(program, "t.ngc", o));
  std::vector<std::array<double, 2>> feeds;
  for (const auto& p : ours)
    if (p[2] > 0.5) feeds.push_back({p[0], p[1]});
  ASSERT_EQ(feeds.size(), want_feeds.size());
  for (std::size_t i = 0; i < feeds.size(); ++i) {
    EXPECT_NEAR(feeds[i][0], want_feeds[i][0], 1e-9) << i;
    EXPECT_NEAR(feeds[i][1], want_feeds[i][1], 1e-9) << i;
  }
  if (nc::find_rs274().empty()) return;
  // One file per test: ctest runs the cases as parallel processes (a shared name raced).
  const std::string path =
      ::testing::TempDir() + "g7x_" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".ngc";
  std::ofstream(path) << program;
  const std::vector<std::array<double, 3>> theirs = path_of(nc::run_rs274(path, o));
  std::remove(path.c_str());
  ASSERT_EQ(ours.size(), theirs.size());
  for (std::size_t i = 0; i < ours.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(ours[i][k], theirs[i][k], 1e-4) << i;
}

const char* kSmall = "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10\n X12\n Z-20\n X15\nO1 ENDSUB\nG0 X20 Z3\n";

TEST(LatheG7x, G70FollowsTheProfileFromTheStartPoint) {
  expect_path(std::string(kSmall) + "G70 Q1 X15 Z3 P2\nG0 X30\nM2\n",
              {{5, -10}, {12, -10}, {12, -20}, {15, -20}, {5, -10}, {12, -10}, {12, -20}, {15, -20}});
  // One pass (P1) runs at E = 0 from the profile whatever D is.
  expect_path(std::string(kSmall) + "G70 Q1 X15 Z3 D1 P1\nG0 X30\nM2\n", {{5, -10}, {12, -10}, {12, -20}, {15, -20}});
}

TEST(LatheG7x, G70ApproachesAProfileRunningBackAlongZFirst) {
  const std::string face = "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X15 Z-6\n G1 X8 Z-5\n Z0\n X3 Z1.2\nO1 ENDSUB\nG0 X20 Z3\n";
  expect_path(face + "G70 Q1 X25 Z5\nG0 X30\nM2\n", {{8, -5}, {8, 0}, {3, 1.2}});
  expect_path(face + "G70 Q1 X15 Z3\nG0 X30\nM2\n", {{8, -5}, {8, 0}, {3, 1.2}});
  expect_path("G18 G8 G21 G90\nF200\nO2 SUB\n G0 X21 Z-30\n G1 X10 Z-10\n Z2\nO2 ENDSUB\nG0 X22 Z2\nG70 Q2 X22 Z2\nG0 X60\nM2\n",
              {{10, -10}, {10, 2}});
}

TEST(LatheG7x, G71PassesEndOnTheProfile) {
  // Start X15 Z3 (radius mode), I2: passes at X15, 13, 11, 9, 7, each from the line between the
  // start point and the profile's start (X5 Z1) to the profile (Z-20 at X15 and 13, the
  // shoulder Z-10 below), retracting R0.5 at 45 degrees; then along the profile.
  expect_path(std::string(kSmall) + "G71 Q1 X15 Z3 I2 R0.5\nG0 X30\nM2\n",
              {{15, -20}, {13, -20}, {11, -10}, {9, -10}, {7, -10}, {5, -10}, {12, -10}, {12, -20}, {15, -20}});
}

TEST(LatheG7x, G71InDiameterModeStepsIAsARadius) {
  // G7: X words are diameters; I and R are not halved (as rs274).
  expect_path("G18 G7 G21 G90\nF100\nO1 SUB\n G0 X10 Z1\n G1 Z-10\n X24\n Z-20\n X30\nO1 ENDSUB\nG0 X40 Z3\n"
              "G71 Q1 X30 Z3 I2 R0.5\nG0 X60\nM2\n",
              {{15, -20}, {13, -20}, {11, -10}, {9, -10}, {7, -10}, {5, -10}, {12, -10}, {12, -20}, {15, -20}});
}

TEST(LatheG7x, G72PassesEndOnTheProfile) {
  // The profile does not run towards the start level (Z3): LinuxCNC makes no roughing passes,
  // only the approach at the start level, a feed to the profile's start and the profile.
  expect_path(std::string(kSmall) + "G72 Q1 X15 Z3 I1.5 R0.5\nG0 X30\nM2\n",
              {{5, 1}, {5, -10}, {12, -10}, {12, -20}, {15, -20}});
}

TEST(LatheG7x, G72PassesAlongXEndOnTheProfile) {
  // Facing: the profile runs from the outside (X15 Z-6) up to the start level's side (X3 Z1.2);
  // passes along X at Z levels 3 (start), 1.5 (both above the profile: none), 0, -1.5, -3,
  // -4.5, from X15 to the profile (X3 above it: the profile is closed by a line from its end
  // to the start level) retracting R0.5 at 45 degrees; then along the profile and that line.
  expect_path("G18 G8 G21 G90\nF100\nO1 SUB\n G0 X15 Z-6\n G1 X8 Z-5\n Z0\n X3 Z1.2\nO1 ENDSUB\nG0 X20 Z3\n"
              "G72 Q1 X15 Z3 I1.5 R0.5\nG0 X30\nM2\n",
              {{3, 3}, {3, 1.5}, {8, 0}, {8, -1.5}, {8, -3}, {8, -4.5}, {8, -5}, {8, 0}, {3, 1.2}, {3, 3}});
}

TEST(LatheG7x, RefusesWhatItDoesNotDo) {
  nc::GcodeOptions o;
  auto error_of = [&](const std::string& prog) {
    try {
      (void)nc::interpret_gcode(prog, "t.ngc", o);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string sub = "G18 G8 G21\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10\n X12\nO1 ENDSUB\n";
  EXPECT_EQ(error_of(sub + "G71 Q1 X15 Z3 D-0.5\n"), "t.ngc:8: 'G71': D (distance left to the profile) must be >= 0");
  EXPECT_EQ(error_of(sub + "G72.1 Q1 X15 Z3 I0\n"), "t.ngc:8: 'G72.1': I (cut increment) must be > 0");
  EXPECT_EQ(error_of(sub + "G70 Q1 X15 Z3 P0\n"), "t.ngc:8: 'P0': expected an integer in [1, 1000]");
  EXPECT_EQ(error_of(sub + "G71 Q1 X15 Z3 I0.00001\n"), "t.ngc:8: 'G71': more than 100000 levels (I too small)");
  const std::string corner = "G18 G8 G21\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10 ";
  EXPECT_EQ(error_of(corner + "A1 C1\n X12\nO1 ENDSUB\nG71 Q1 X15 Z3\n"),
            "t.ngc:5: 'A1' and 'C1': a corner takes a fillet or a chamfer");
  EXPECT_EQ(error_of(corner + "A3\n X7\nO1 ENDSUB\nG71 Q1 X15 Z3\n"),
            "t.ngc:8: 'G71': the corner finish 3 mm does not fit the straight moves at X5 Z-10 (arcs take none)");
  EXPECT_EQ(error_of(corner + "A1\n X12\nO1 ENDSUB\nG1 X5 A1\n"),
            "t.ngc:8: word 'A1' needs an axis the machine lacks (machine kind mill3 has X Y Z)");
  EXPECT_EQ(error_of(sub + "G17 G71 Q1 X15 Z3\n"), "t.ngc:8: 'G71' needs the XZ plane (G18)");
  const std::string back = "G18 G8 G21\nF100\nO1 SUB\n G0 X5 Z1\n G1 X12 Z-5\n X8 Z-10\nO1 ENDSUB\n";
  EXPECT_EQ(error_of(back + "G72 Q1 X15 Z3\n"),
            "t.ngc:8: 'G72': the profile is not monotonic along X (it runs back along the passes)");
  EXPECT_EQ(error_of(back + "G71 Q1 X15 Z3\nM2\n"), "accepted");
  EXPECT_EQ(error_of("G18 G8 G21\nF100\nO1 SUB\n G0 X5 Z1\nO1 ENDSUB\nG71 Q1 X15 Z3\n"),
            "t.ngc:6: 'G71': the profile subroutine makes fewer than two moves");
  EXPECT_EQ(error_of(sub + "G71.2 Q1 X15 Z3\nM2\n"), "accepted");
  EXPECT_EQ(error_of(sub + "G71 Q1 X8 Z3\nM2\n"), "accepted");  // start within the profile's X range: as LinuxCNC
}

// The feeds that end a roughing pass (a rapid retract follows), consecutive repeats dropped.
std::vector<std::array<double, 2>> pass_ends(const nc::Toolpath& tp) {
  std::vector<std::array<double, 2>> out;
  for (std::size_t i = 0; i + 1 < tp.segments.size(); ++i) {
    const nc::Segment &s = tp.segments[i], &n = tp.segments[i + 1];
    if (s.kind == nc::SegmentKind::Feed && n.kind != nc::SegmentKind::Feed) out.push_back({s.end[nc::X], s.end[nc::Z]});
  }
  return out;
}

// Rapids of the built-in path against rs274's (when installed): arcs are chords in both, cut
// differently (a pass ending where an arc runs nearly along it ends some um apart).
void expect_rapids_as_rs274(const std::string& program, double tol_mm = 2e-3) {
  if (nc::find_rs274().empty()) return;
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  auto rapids = [](const nc::Toolpath& tp) {
    std::vector<std::array<double, 3>> out;
    for (const auto& p : path_of(tp))
      if (p[2] < 0.5) out.push_back(p);
    return out;
  };
  const std::string path = ::testing::TempDir() + "g7x_rapids_" + std::to_string(::getpid()) + ".ngc";
  std::ofstream(path) << program;
  const auto ours = rapids(nc::interpret_gcode(program, "t.ngc", o)), theirs = rapids(nc::run_rs274(path, o));
  std::remove(path.c_str());
  ASSERT_EQ(ours.size(), theirs.size());
  for (std::size_t i = 0; i < ours.size(); ++i)
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(ours[i][k], theirs[i][k], tol_mm) << i;
}

TEST(LatheG7x, G71WithDLeavesTheAllowanceAndStepsI) {
  // kSmall (radius mode), start X15 Z3, I2, D0.5: the profile offset 0.5 towards the start
  // point (X5.5 up to Z-9.5, Z-9.5 up to X12, round corner, X12.5 to Z-19.5). Passes at X15,
  // 13, 11, 9, 7 (2 apart, five of them: the next level, 5, is below the offset profile's
  // start X5.5), each from the approach line to the offset profile, then the offset profile
  // from X5.5 Z1 to its end X15 Z-19.5 (the start level: no closing line).
  const std::string prog = std::string(kSmall) + "G71 Q1 X15 Z3 I2 R0.5 D0.5\nG0 X30\nM2\n";
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  const nc::Toolpath tp = nc::interpret_gcode(prog, "t.ngc", o);
  const std::vector<std::array<double, 2>> want{{15, -19.5}, {13, -19.5}, {11, -9.5}, {9, -9.5}, {7, -9.5}};
  const std::vector<std::array<double, 2>> got = pass_ends(tp);
  ASSERT_EQ(got.size(), want.size() + 1);  // and the end of the profile pass before G0 X30
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_NEAR(got[i][0], want[i][0], 1e-9) << i;
    EXPECT_NEAR(got[i][1], want[i][1], 1e-9) << i;
  }
  EXPECT_NEAR(got.back()[0], 15.0, 1e-9);
  EXPECT_NEAR(got.back()[1], -19.5, 1e-9);
  expect_rapids_as_rs274(prog);
}

// Step (kStep, diameters) offset by D = 0.5 (radius) towards the start point: radius 10.5 to
// Z-19.5, the outer corner at (15, -20) rounded with radius 0.5, radius 15.5 to Z-39.5, closed
// to the start level at Z-39.5.
double step_with_allowance_mm3() {
  const double corner = 225.0 * 0.5 + 30.0 * (kPi * 0.25 / 4.0) + 0.25 * 0.5 - 0.125 / 3.0;  // integral of r^2 dz
  return kPi * ((400.0 - 110.25) * 19.5 + (400.0 * 0.5 - corner) + (400.0 - 240.25) * 19.5);
}

TEST(LatheG7x, G71WithDRemovesTheAnalyticVolumeThenG70TheRest) {
  const std::string rough = std::string(kHead) + kStep + "G0 X44 Z2\nG71 Q100 X44 Z2 I1 R0.5 D0.5\n";
  expect_volume(rough + "G0 X60 Z20\nM2\n", step_with_allowance_mm3());
  expect_volume(rough + "G70 Q100 X44 Z2 D1 P2\nG0 X60 Z20\nM2\n", kStepMm3);
}

TEST(LatheG7x, G72WithDRemovesTheAnalyticVolume) {
  // The step traced from the outside in (facing): the same offset profile.
  const char* rev = "O101 SUB\n G0 X42 Z-40\n G1 X30\n Z-20\n X20\n Z2\nO101 ENDSUB\n";
  expect_volume(std::string(kHead) + rev + "G0 X44 Z2\nG72 Q101 X44 Z2 I1 R0.5 D0.5\nG0 X60 Z20\nM2\n",
                step_with_allowance_mm3());
}

// Type 2 (diameters): radius 10 for Z 0..-10, 15 for -10..-20, a pocket of radius 12 for
// -20..-30 between 45-degree walls (15 to 12 over Z -20..-23, 12 to 18 over -30..-36), 18 to -40.
const char* kPocket = "O300 SUB\n G0 X20 Z2\n G1 Z-10\n X30\n Z-20\n X24 Z-23\n Z-30\n X36 Z-36\n Z-40\n X42\nO300 ENDSUB\n";
double cone_mm3(double r0, double r1, double len) { return kPi * len * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0; }
double pocket_mm3() {
  const double outside = kPi * 400.0 * 40.0;
  const double part = kPi * (100.0 * 10.0 + 225.0 * 10.0 + 144.0 * 7.0 + 324.0 * 4.0) + cone_mm3(15, 12, 3) + cone_mm3(12, 18, 6);
  return outside - part;
}
// What G71.1 leaves: the pocket below its rim (radius 15) from Z-20 to the far wall's Z-33.
double pocket_bridged_mm3() {
  const double left = (kPi * 225.0 * 3.0 - cone_mm3(15, 12, 3)) + kPi * (225.0 - 144.0) * 7.0 +
                      (kPi * 225.0 * 3.0 - cone_mm3(12, 15, 3));
  return pocket_mm3() - left;
}

TEST(LatheG7x, Type2PocketIsRoughedToTheProfile) {
  // Tool 3 (35-degree insert, 93-degree holder): its trailing edge clears the 45-degree wall
  // down into the pocket (tool 1's 5 degrees would gouge it).
  const std::string head = "G18 G7 G21 G90 G94\nT3 M6\nM3 S1000\nF200\n" + std::string(kPocket) + "G0 X44 Z2\n";
  expect_volume(head + "G71 Q300 X44 Z2 I1 R0.5\nG0 X60 Z20\nM2\n", pocket_mm3());
  expect_volume(head + "G71.1 Q300 X44 Z2 I1 R0.5\nG0 X60 Z20\nM2\n", pocket_bridged_mm3());
  expect_volume(head + "G71.1 Q300 X44 Z2 I1 R0.5\nG71.2 Q300 X44 Z2 I1 R0.5\nG0 X60 Z20\nM2\n", pocket_mm3());
}

TEST(LatheG7x, G70PassesStepFromDToE) {
  // P3 from D1.5 to E0: passes at 1.0, 0.5, 0 from the profile ((pass-1)(D-E)/P + E), each
  // from the start point; the first profile segment (X5) is offset along +X.
  const std::string prog = std::string(kSmall) + "G70 Q1 X15 Z3 D1.5 P3\nG0 X30\nM2\n";
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  const nc::Toolpath tp = nc::interpret_gcode(prog, "t.ngc", o);
  std::vector<double> entry_x, end_z;
  for (std::size_t i = 1; i < tp.segments.size(); ++i) {
    const nc::Segment &s = tp.segments[i], &p = tp.segments[i - 1];
    if (s.kind != nc::SegmentKind::Feed && p.kind == nc::SegmentKind::Feed) end_z.push_back(p.end[nc::Z]);
    if (s.kind == nc::SegmentKind::Feed && p.kind != nc::SegmentKind::Feed) entry_x.push_back(p.end[nc::X]);
  }
  ASSERT_EQ(entry_x.size(), 3u);
  EXPECT_NEAR(entry_x[0], 6.0, 1e-9);
  EXPECT_NEAR(entry_x[1], 5.5, 1e-9);
  EXPECT_NEAR(entry_x[2], 5.0, 1e-9);
  ASSERT_EQ(end_z.size(), 3u);  // each pass ends on the offset last segment (X12..15 at Z-20 + distance)
  EXPECT_NEAR(end_z[0], -19.0, 1e-9);
  EXPECT_NEAR(end_z[1], -19.5, 1e-9);
  EXPECT_NEAR(end_z[2], -20.0, 1e-9);
  expect_rapids_as_rs274(prog);
  expect_rapids_as_rs274(std::string(kSmall) + "G70 Q1 X15 Z3 D1 E0.25 P2\nG0 X30\nM2\n");
}

TEST(LatheG7x, VariantsFollowRs274) {
  // A type 2 profile with an arc, in both directions, every variant, with and without D.
  const std::string turn = "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X10 Z1\n G1 Z-5\n X16 Z-10\n Z-14\n X11 Z-18\n Z-24\n"
                           " G2 X15 Z-28 R4\n G1 X20 Z-32\n Z-36\n X22\nO1 ENDSUB\nG0 X30 Z5\n";
  const std::string face = "G18 G8 G21 G90\nF100\nO2 SUB\n G0 X30 Z-12\n G1 X24 Z-12\n X20 Z-6\n X14 Z-6\n X10 Z-9\n"
                           " X6\n X2 Z0\n X0\nO2 ENDSUB\nG0 X40 Z5\n";
  for (const char* c : {"G71 Q1 X24 Z3 I1.5 R0.5", "G71.1 Q1 X24 Z3 I1 R0.3 D1", "G71.2 Q1 X24 Z3 I0.7 R0.3 D0.5",
                        "G71 Q1 X24 Z3 I1.5 R0.5 D0.7", "G70 Q1 X24 Z3 D1 E0.2 P3"})
    expect_rapids_as_rs274(turn + c + "\nM2\n", 0.01);
  for (const char* c : {"G72 Q2 X32 Z2 I0.8 R0.5 D0.3", "G72.1 Q2 X32 Z2 I1 R0.5 D0.5", "G72.2 Q2 X32 Z2 I0.8 R0.5 D0.3",
                        "G70 Q2 X32 Z2 D0.5 E0.1 P2"})
    expect_rapids_as_rs274(face + c + "\nM2\n");
}

TEST(LatheG7x, OffsetProfileStartsWhereItMeetsAShortFirstSegmentsExtension) {
  // Profile (radius mode): X5 Z1, X4.8 (0.2 along -X), X10 Z-5, Z-10; G70 at E0.5 (one pass,
  // 0.5 from the profile towards the start point X15 Z3). The short first segment offset lies
  // at Z0.5 (X4.8..5); the offset diagonal does not reach it but crosses its extension at
  // X = 5.895: the pass starts there (LinuxCNC's stepwise offset ends up elsewhere).
  const double len = std::hypot(6.0, 5.2), nz = 5.2 / len * 0.5, nx = 6.0 / len * 0.5;  // normal (Z, X) * 0.5
  const double t = (1.0 + nz - 0.5) / 6.0;  // along the diagonal from its offset start to Z0.5
  const double want_x = 4.8 + nx + t * 5.2;
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  const nc::Toolpath tp = nc::interpret_gcode(
      "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X5 Z1\n G1 X4.8\n X10 Z-5\n Z-10\nO1 ENDSUB\nG70 Q1 X15 Z3 E0.5\nM2\n", "t.ngc", o);
  const std::vector<std::array<double, 3>> p = path_of(tp);
  ASSERT_GE(p.size(), 4u);
  EXPECT_NEAR(p[1][0], want_x, 1e-9);  // after the rapid to the start point
  EXPECT_NEAR(p[1][1], 0.5, 1e-9);
  EXPECT_EQ(p[1][2], 0.0);
  EXPECT_NEAR(p.back()[0], 10.5, 1e-9);  // the last segment offset 0.5 along +X
  EXPECT_NEAR(p.back()[1], -10.0, 1e-9);
}

TEST(LatheG7x, CornerFinishesRoundAndCutTheCorners) {
  // A1 at X5 Z-10 (90-degree corner): tangent points 1 from the corner, (5, -9) and (6, -10),
  // arc about (6, -9); C1 at X12 Z-20: a straight cut from (12, -19) to (13, -20).
  const std::string prog = "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10 A1\n X12\n Z-20 C1\n X15\nO1 ENDSUB\n"
                           "G0 X20 Z3\nG70 Q1 X15 Z3\nM2\n";
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  const std::vector<std::array<double, 3>> p = path_of(nc::interpret_gcode(prog, "t.ngc", o));
  auto index_of = [&](double x, double z) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (std::abs(p[i][0] - x) < 1e-9 && std::abs(p[i][1] - z) < 1e-9) return static_cast<long>(i);
    return -1L;
  };
  const long t1 = index_of(5, -9), t2 = index_of(6, -10), c1 = index_of(12, -19), c2 = index_of(13, -20);
  ASSERT_GE(t1, 0);
  ASSERT_GT(t2, t1 + 1);  // chords of the fillet between
  for (long i = t1; i <= t2; ++i) EXPECT_NEAR(std::hypot(p[i][0] - 6.0, p[i][1] + 9.0), 1.0, 1e-9) << i;
  ASSERT_GE(c1, 0);
  EXPECT_EQ(c2, c1 + 1);
  EXPECT_EQ(index_of(5, -10), -1L);  // the corners themselves are gone
  EXPECT_EQ(index_of(12, -20), -1L);
  expect_rapids_as_rs274(prog);
  expect_rapids_as_rs274("G18 G8 G21 G90\nF100\nO1 SUB\n G0 X10 Z1\n G1 Z-5 C1\n X16 Z-10 A2\n Z-14 A0.5\n X11 Z-18 C0.7\n"
                         " Z-24\n G1 X20 Z-32 A1\n Z-36\n X22\nO1 ENDSUB\nG0 X30 Z5\nG71 Q1 X24 Z3 I1 R0.5 D0.7\nM2\n");
}

TEST(LatheG7x, FeedInTheProfileSubroutineIsIgnored) {
  // Regression: the subroutine's F50 used to become the cycle's feed; LinuxCNC ignores it.
  nc::GcodeOptions o;
  o.machine = nc::MachineKind::Lathe;
  const nc::Toolpath tp = nc::interpret_gcode(
      "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10 F50\n X12\nO1 ENDSUB\nG0 X20 Z3\nG71 Q1 X15 Z3\nG1 X20\nM2\n",
      "t.ngc", o);
  int feeds = 0;
  for (const nc::Segment& s : tp.segments) {
    if (s.kind != nc::SegmentKind::Feed) continue;
    EXPECT_DOUBLE_EQ(s.feed_mm_per_min, 100.0);
    ++feeds;
  }
  EXPECT_GT(feeds, 5);
}

// LinuxCNC's two G7x sample programs (tests/data/nc_corpus_exclusions.txt no longer lists
// them), radius mode, with tool 1 loaded: the built-in tool path removes what rs274's removes.
TEST(LatheG7x, LinuxCncSamplesRemoveWhatRs274Removes) {
  if (nc::find_rs274().empty()) GTEST_SKIP() << "linuxcnc-uspace is not installed";
  FILE* p = ::popen("dpkg -L linuxcnc-uspace 2>/dev/null | grep 'lathe_g7x_.*\\.ngc$' | sort", "r");
  ASSERT_NE(p, nullptr);
  std::vector<std::string> files;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p) != nullptr) files.emplace_back(buf, std::strcspn(buf, "\n"));
  ::pclose(p);
  EXPECT_EQ(files.size(), 2u);
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    std::ifstream in(f);
    std::stringstream ss;
    ss << "G8 T1 M6\n" << in.rdbuf();
    const double builtin = removed_mm3(ss.str(), app::Interpreter::Builtin);
    const double rs274 = removed_mm3(ss.str(), app::Interpreter::Rs274);
    EXPECT_GT(builtin, 1000.0);
    EXPECT_NEAR(builtin, rs274, 1e-3 * rs274);
  }
}

}  // namespace
