// G70/G71/G72 lathe cycles in the built-in interpreter (docs/nc-frontend.md#lathe-cycles-g76-g7x):
// `lbrsim batch` on the bundled lathe profile (insert nose radius made 0.01 mm so the part is
// the programmed profile) removes the analytic volume of a step and of a straight taper within
// 0.1 %, and the same volume as LinuxCNC's rs274 within 0.1 % when linuxcnc-uspace is
// installed. The cycles' own moves are checked pass by pass on a hand-computed case.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
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
  return app::run_batch(profile, app::load_toolpath(path, profile, interp)).removed_volume_mm3;
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
  const std::string path = ::testing::TempDir() + "g7x_path.ngc";
  std::ofstream(path) << program;
  const std::vector<std::array<double, 3>> theirs = path_of(nc::run_rs274(path, o));
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
  EXPECT_EQ(error_of(sub + "G71 Q1 X15 Z3 D0.5\n"),
            "t.ngc:8: 'G71' with D (finishing allowance) is not in the built-in interpreter; use --interpreter rs274");
  EXPECT_EQ(error_of(sub + "G70 Q1 X15 Z3 D1 P2\n"),
            "t.ngc:8: 'G70' with passes away from the profile (E, or D with P > 1) is not in the built-in interpreter; use --interpreter rs274");
  EXPECT_EQ(error_of(sub + "G70 Q1 X15 Z3 E0.1\n"),
            "t.ngc:8: 'G70' with passes away from the profile (E, or D with P > 1) is not in the built-in interpreter; use --interpreter rs274");
  EXPECT_EQ(error_of(sub + "G71 Q1 X8 Z3\n"),
            "t.ngc:8: 'G71': the start point lies within the profile's range across the passes");
  EXPECT_EQ(error_of(sub + "G17 G71 Q1 X15 Z3\n"), "t.ngc:8: 'G71' needs the XZ plane (G18)");
  EXPECT_EQ(error_of(sub + "G71.1 Q1 X15 Z3\n").substr(0, 40), "t.ngc:8: unsupported word 'G71.1' (lathe");
}

}  // namespace
