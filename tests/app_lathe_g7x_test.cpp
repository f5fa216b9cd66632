// G70/G71/G72 lathe cycles in the built-in interpreter (docs/nc-frontend.md#lathe-cycles-g76-g7x):
// `lbrsim batch` on the bundled lathe profile (insert nose radius made 0.01 mm so the part is
// the programmed profile) removes the analytic volume of a step and of a straight taper within
// 0.1 %, and the same volume as LinuxCNC's rs274 within 0.1 % when linuxcnc-uspace is
// installed. The cycles' own moves are checked pass by pass on a hand-computed case.
#include <gtest/gtest.h>

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
  const std::string path = ::testing::TempDir() + "g7x_test.ngc";
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
  expect_volume(std::string(kHead) + kTaper + "G0 X44 Z2\nG71 Q200 X44 Z2 I1.5 R0.3\nG70 Q200\nG0 X60 Z20\nM2\n",
                taper_mm3());
}

TEST(LatheG7x, G72TaperRemovesTheAnalyticVolume) {
  expect_volume(std::string(kHead) + kTaper + "G0 X44 Z2\nG72 Q200 X44 Z2 I0.7 R0.2\nG0 X60 Z20\nM2\n", taper_mm3());
}

TEST(LatheG7x, G70AloneFollowsTheProfile) {
  // Finishing alone from the start point: rapid to the profile's start, along it, back.
  nc::GcodeOptions o;
  const nc::Toolpath tp =
      nc::interpret_gcode("G18 G8 G21 G90\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10\n X12\nO1 ENDSUB\nG70 Q1 X15 Z3\nM2\n", "t.ngc", o);
  ASSERT_EQ(tp.segments.size(), 6u);
  const double want[6][2] = {{15, 3}, {5, 1}, {5, -10}, {12, -10}, {15, -10}, {15, 3}};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(tp.segments[i].end[nc::X], want[i][0], 1e-12) << i;
    EXPECT_NEAR(tp.segments[i].end[nc::Z], want[i][1], 1e-12) << i;
  }
}

TEST(LatheG7x, G71PassesEndOnTheProfile) {
  // Radius mode, start X15 Z3, I2: passes at X13, 11, 9, 7 from Z3 to the profile (X13 meets
  // it at Z-20, the others at the shoulder Z-10), each retracting R0.5; then one pass along
  // the profile. The feeds' end points, by hand:
  nc::GcodeOptions o;
  const nc::Toolpath tp = nc::interpret_gcode(
      "G18 G8 G21 G90\nF100\nO1 SUB\n G0 X5 Z1\n G1 Z-10\n X12\n Z-20\n X15\nO1 ENDSUB\nG71 Q1 X15 Z3 I2 R0.5\nM2\n",
      "t.ngc", o);
  std::vector<std::array<double, 2>> feeds;
  for (const nc::Segment& s : tp.segments)
    if (s.kind == nc::SegmentKind::Feed) feeds.push_back({s.end[nc::X], s.end[nc::Z]});
  const std::vector<std::array<double, 2>> want = {{13, -20}, {11, -10}, {9, -10}, {7, -10},
                                                   {5, -10},  {12, -10}, {12, -20}, {15, -20}};
  ASSERT_EQ(feeds.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_NEAR(feeds[i][0], want[i][0], 1e-12) << i;
    EXPECT_NEAR(feeds[i][1], want[i][1], 1e-12) << i;
  }
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
            "t.ngc:8: 'G70' with D or E (passes away from the profile) is not in the built-in interpreter; use --interpreter rs274");
  EXPECT_EQ(error_of(sub + "G71 Q1 X8 Z3\n"),
            "t.ngc:8: 'G71': the start point lies within the profile's range across the passes");
  EXPECT_EQ(error_of(sub + "G17 G71 Q1 X15 Z3\n"), "t.ngc:8: 'G71' needs the XZ plane (G18)");
  EXPECT_EQ(error_of(sub + "G71.1 Q1 X15 Z3\n").substr(0, 40), "t.ngc:8: unsupported word 'G71.1' (lathe");
}

}  // namespace
