// The RS274/NGC language in the built-in interpreter: parameters, expressions, O-word control
// flow, subroutine files, and the defects found on the LinuxCNC corpus (issue 14). Positions
// are hand-computed; where rs274 (linuxcnc-uspace) is installed the same text also runs
// through it and the end points must agree.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <fstream>
#include <string>

#include "nc/gcode.hpp"
#include "nc/rs274.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;

using lbr::test::ends;
using lbr::test::error_of;
using lbr::test::run;

// Temporary directory for program and subroutine files.
class NgcFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("lbr-ngc-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_ / "lib");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& rel, const std::string& text) {
    const auto p = dir_ / rel;
    std::ofstream(p) << text;
    return p.string();
  }
  // Runs through rs274 too when installed; end points must agree within 1 µm.
  void cross_check(const std::string& path, const GcodeOptions& o) {
    if (find_rs274().empty()) return;
    const auto a = ends(load_gcode(path, o)), b = ends(run_rs274(path, o));
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      for (int k = 0; k < kAxes; ++k) EXPECT_NEAR(a[i][k], b[i][k], 1e-3) << "segment " << i << " axis " << k;
  }
  std::filesystem::path dir_;
};

TEST(NgcExpressions, PrecedenceFunctionsAndComparison) {
  // 2 + 3 * 2 ** 2 = 14; MOD keeps the divisor's sign; EQ within 1e-4; trig in degrees.
  const auto e = ends(run("G0 X[2 + 3 * 2 ** 2] Y[-7 MOD 3] Z[1.00001 EQ 1]\n"
                          "G0 X[SIN[30] * 10] Y[ATAN[1]/[1]] Z[ROUND[-2.5] + FIX[1.7] + FUP[1.2]]\n"
                          "G0 X[SQRT[16] + ABS[-1] + EXP[0] + LN[1]] Y[1 LT 2 AND 3 GT 4] Z[1 OR 0 XOR 1]\n"));
  ASSERT_EQ(e.size(), 3u);
  EXPECT_DOUBLE_EQ(e[0][X], 14.0);
  EXPECT_DOUBLE_EQ(e[0][Y], 2.0);
  EXPECT_DOUBLE_EQ(e[0][Z], 1.0);
  EXPECT_NEAR(e[1][X], 5.0, 1e-12);
  EXPECT_NEAR(e[1][Y], 45.0, 1e-12);
  EXPECT_DOUBLE_EQ(e[1][Z], -3.0 + 1.0 + 2.0);
  EXPECT_DOUBLE_EQ(e[2][X], 6.0);
  EXPECT_DOUBLE_EQ(e[2][Y], 0.0);
  EXPECT_DOUBLE_EQ(e[2][Z], 0.0);  // (1 OR 0) XOR 1, left to right
}

TEST(NgcParameters, SettingsTakeEffectAfterTheLineAndNamedScopes) {
  // #1 = 2 and X#1 on one line: X reads the old value (0), as RS274/NGC says.
  const auto e = ends(run("#1 = 5\n#1 = 2 G0 X#1\nG0 X#1\n#<_g> = 3\n#<loc> = 4\nG0 Y[#<_g> + #<loc>]\n"
                          "#2 = 1\nG0 Z##2\n"  // ##2 = #[#2] = #1 = 2
                          "G0 X[#5420 + 1] Y#<_y>\n"));
  ASSERT_EQ(e.size(), 5u);
  EXPECT_DOUBLE_EQ(e[0][X], 5.0);
  EXPECT_DOUBLE_EQ(e[1][X], 2.0);
  EXPECT_DOUBLE_EQ(e[2][Y], 7.0);
  EXPECT_DOUBLE_EQ(e[3][Z], 2.0);
  EXPECT_DOUBLE_EQ(e[4][X], 3.0);  // #5420: current X
  EXPECT_DOUBLE_EQ(e[4][Y], 7.0);  // #<_y>: current Y
}

TEST(NgcParameters, UndefinedGlobalIsAnError) {
  EXPECT_EQ(error_of("G0 X1\nG0 Y#<_nope>\n"), "t.ngc:2: named parameter '#<_NOPE>' is not defined");
  EXPECT_EQ(error_of("#6000 = 1\n"), "t.ngc:1: parameter number 6000 is not an integer in [1, 5602]");
}

TEST(NgcControl, IfElseifElse) {
  const std::string prog =
      "#1 = 2\n"
      "o1 if [#1 EQ 1]\n G0 X1\n"
      "o1 elseif [#1 EQ 2]\n G0 X2\n"
      "o1 else\n G0 X3\n"
      "o1 endif\n"
      "o2 if [0]\n G0 Y9\no2 else\n G0 Y4\no2 endif\n";
  const auto e = ends(run(prog));
  ASSERT_EQ(e.size(), 2u);
  EXPECT_DOUBLE_EQ(e[0][X], 2.0);
  EXPECT_DOUBLE_EQ(e[1][Y], 4.0);
}

TEST(NgcControl, WhileDoRepeatBreakContinue) {
  const std::string prog =
      "#1 = 0\n"
      "o1 while [#1 LT 5]\n #1 = [#1 + 1]\n o2 if [#1 EQ 2]\n  o1 continue\n o2 endif\n"
      " o3 if [#1 EQ 4]\n  o1 break\n o3 endif\n G0 X#1\no1 endwhile\n"  // X1, X3
      "o4 do\n G0 Y#1\n #1 = [#1 - 1]\no4 while [#1 GT 2]\n"               // Y4, Y3
      "o5 repeat [3]\n G91 G0 Z1\n G90\no5 endrepeat\n";                      // Z1, Z2, Z3
  const auto e = ends(run(prog));
  ASSERT_EQ(e.size(), 7u);
  EXPECT_DOUBLE_EQ(e[0][X], 1.0);
  EXPECT_DOUBLE_EQ(e[1][X], 3.0);
  EXPECT_DOUBLE_EQ(e[2][Y], 4.0);
  EXPECT_DOUBLE_EQ(e[3][Y], 3.0);
  EXPECT_DOUBLE_EQ(e[6][Z], 3.0);
}

TEST(NgcControl, SubroutineArgumentsLocalsAndReturnValue) {
  const std::string prog =
      "o<sq> sub\n #<t> = [#1 * #1]\n o<sq> return [#<t> + #2]\no<sq> endsub\n"
      "#1 = 7\n"
      "o<sq> call [3] [1]\n"
      "G0 X#<_value> Y#1 Z#<_value_returned>\n";  // 10, #1 restored to 7, 1
  const auto e = ends(run(prog));
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0][X], 10.0);
  EXPECT_DOUBLE_EQ(e[0][Y], 7.0);
  EXPECT_DOUBLE_EQ(e[0][Z], 1.0);
  EXPECT_EQ(error_of("#<t> = 1\no<s> sub\nG0 X#<t>\no<s> endsub\no<s> call\n"),
            "t.ngc:3: named parameter '#<T>' is not defined");  // locals do not leak into calls
}

TEST(NgcControl, EndlessLoopIsBoundedAndMismatchesAreNamed) {
  GcodeOptions o;
  o.max_blocks = 1000;
  EXPECT_EQ(error_of("o1 while [1]\no1 endwhile\n", o), "t.ngc:1: more than 1000 blocks executed (endless loop?)");
  EXPECT_EQ(error_of("o1 if [1]\no2 endif\n"), "t.ngc:2: 'o2 endif' does not close an open 'o2 IF'");
  EXPECT_EQ(error_of("o1 break\n"), "t.ngc:1: 'o1 break' is not inside a loop labelled o1");
  EXPECT_EQ(error_of("G0 X1\no<nosuch> call\n").find("t.ngc:2: subroutine o<nosuch> is not defined"), 0u);
}

TEST(NgcControl, ToolpathSizeIsBoundedAndTheLineNamed) {
  GcodeOptions o;
  o.max_segments = 3;
  EXPECT_EQ(run("G0 X1\nG0 X2\nG0 X3\n", o).segments.size(), 3u);  // at the limit: accepted
  EXPECT_EQ(error_of("G0 X1\nG0 X2\nG0 X3\nG0 X4\n", o),
            "t.ngc:4: the program makes more than 3 moves (an endless loop, or arcs of many turns at a fine chord "
            "tolerance?)");
  // Ten turns of r = 50 mm at 1 um: 4 583 chords, refused in the arc's own line.
  o.max_segments = 1000;
  EXPECT_EQ(error_of("F100\nG2 X0 Y0 I-50 J0 P10\n", o),
            "t.ngc:2: the program makes more than 1000 moves (an endless loop, or arcs of many turns at a fine chord "
            "tolerance?)");
  o.max_segments = 5000;
  EXPECT_EQ(run("F100\nG2 X0 Y0 I-50 J0 P10\n", o).segments.size(), 4583u);
}

TEST_F(NgcFiles, SubroutineFileFromTheProgramDirectoryAndTheSearchPath) {
  write("lib/side.ngc", "o<side> sub\nG1 X[#1] F100\no<side> endsub\nM2\n");
  write("square.ngc", "o<square> sub\no<side> call [#1]\nG1 Y[#1]\no<square> endsub\n");
  const std::string main = write("main.ngc", "G21 G90\nG0 X0 Y0\no<square> call [5]\nM2\n");
  GcodeOptions o;
  EXPECT_NE(error_of(read_text_file(main), o), "<no error>");  // side.ngc is only on the path
  o.subroutine_path = {(dir_ / "lib").string()};
  const Toolpath tp = load_gcode(main, o);
  const auto e = ends(tp);
  ASSERT_EQ(e.size(), 3u);
  EXPECT_DOUBLE_EQ(e[1][X], 5.0);
  EXPECT_DOUBLE_EQ(e[2][Y], 5.0);
  for (const Segment& s : tp.segments) EXPECT_EQ(s.line, s.kind == SegmentKind::Rapid ? 2 : 3);  // the call line
  cross_check(main, o);
}

TEST_F(NgcFiles, LoopsAndParametersAgreeWithRs274) {
  const std::string p = write("loops.ngc",
                              "G21 G90 F500\n#<r> = 10\n#1 = 0\n"
                              "o10 while [#1 LT 360]\n G1 X[#<r> * COS[#1]] Y[#<r> * SIN[#1]]\n #1 = [#1 + 45]\no10 endwhile\n"
                              "o20 repeat [2]\n G91 G1 Z-1\n G90\no20 endrepeat\n"
                              "G92 X0 Y0\nG1 X1\nG92.1\nG10 L20 P1 X0\nG1 Y2\nM2\n");
  const auto e = ends(load_gcode(p, {}));
  ASSERT_EQ(e.size(), 12u);
  EXPECT_NEAR(e[1][X], 10.0 * std::cos(std::numbers::pi / 4), 1e-12);
  EXPECT_DOUBLE_EQ(e[9][Z], -2.0);
  EXPECT_NEAR(e[10][X], e[9][X] + 1.0, 1e-12);  // G92: the current point became X0
  cross_check(p, {});
}

// ---- defects found on the LinuxCNC corpus (issue 14) ------------------------------------------

TEST(NgcDefects, G64WithTolerancesIsAccepted) {
  const auto e = ends(run("G64 P0.25 Q0.1\nG61\nG64\nG1 X1 F100\n"));
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0][X], 1.0);
}

TEST(NgcDefects, ByteOrderMarkIsSkippedAndNulIsShown) {
  const auto e = ends(run("\xEF\xBB\xBFG0 X3\n"));
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0][X], 3.0);
  EXPECT_EQ(error_of(std::string("G0 X1 ") + '\0' + "\n"), "t.ngc:1: unexpected character '\\x00'");
}

TEST(NgcDefects, ToolChangeWithG43KeepsTheGaugeLine) {
  // LinuxCNC's controller reads the machine position back after M6: the gauge line stays,
  // so the new tool's tip is 10 mm higher than the old one's (tool 1 60 mm, tool 2 50 mm).
  GcodeOptions o;
  o.tool_lengths = {{1, 60}, {2, 50}};
  const std::string prog = "G21 G90\nT1 M6 G43 H1\nG0 X5 Y5 Z100\nT2 M6 G43 H2\nG0 X10 Y10\nG1 X60 F500\nM2\n";
  const auto e = ends(run(prog, o));
  ASSERT_EQ(e.size(), 3u);
  EXPECT_DOUBLE_EQ(e[0][Z], 100.0);
  EXPECT_DOUBLE_EQ(e[1][Z], 110.0);
  EXPECT_DOUBLE_EQ(e[2][Z], 110.0);
  if (!find_rs274().empty()) {
    const auto dir = std::filesystem::temp_directory_path() / "lbr-ngc-toolchange";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "tc.ngc") << prog;
    const auto r = ends(run_rs274((dir / "tc.ngc").string(), o));
    std::filesystem::remove_all(dir);
    ASSERT_EQ(r.size(), 3u);
    EXPECT_NEAR(r[1][Z], 110.0, 1e-3);
    EXPECT_NEAR(r[2][Z], 110.0, 1e-3);
  }
}

TEST(NgcDefects, LatheDiameterModeIsTheProfilesInBothFrontEnds) {
  GcodeOptions o;
  o.machine = MachineKind::Lathe;
  o.diameter_mode = true;
  const std::string prog = "G21 G90\nG0 X20 Z1\nG1 Z-10 F100\nM2\n";
  EXPECT_DOUBLE_EQ(ends(run(prog, o)).back()[X], 10.0);
  if (!find_rs274().empty()) {
    const auto dir = std::filesystem::temp_directory_path() / "lbr-ngc-lathe";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "l.ngc") << prog;
    EXPECT_NEAR(ends(run_rs274((dir / "l.ngc").string(), o)).back()[X], 10.0, 1e-3);
    o.diameter_mode = false;
    EXPECT_NEAR(ends(run_rs274((dir / "l.ngc").string(), o)).back()[X], 20.0, 1e-3);
    std::filesystem::remove_all(dir);
  }
}

TEST(NgcDefects, RotaryWordsForMissingAxesAreRefused) {
  GcodeOptions o;
  o.machine = MachineKind::Mill5;
  o.rotary = {true, false, true};  // A/C table
  EXPECT_EQ(error_of("G0 B10\n", o),
            "t.ngc:1: word 'B10' needs an axis the machine lacks (machine kind mill-rotary has X Y Z A C)");
  EXPECT_DOUBLE_EQ(ends(run("G0 A10 C5\n", o)).back()[C], 5.0);
}

TEST(NgcDefects, SpindleSynchronisedMotionNeedsASpindleSpeed) {
  // G33/G33.1/G76 run in both front ends now (tests/nc_ngc_motion_test.cpp); without S they
  // are refused with the reason, not with a suggestion to use rs274.
  EXPECT_EQ(error_of("G18\nG76 P1 Z-10 I-1 J0.5 K1\n"),
            "t.ngc:2: 'G76' needs a spindle speed S > 0 (spindle-synchronised motion)");
}

TEST(NgcDefects, FeedPerRevolution) {
  // G95 F0.1 mm/rev at S1000 rpm (G97) = 100 mm/min; G96 S100 m/min at X radius 10 mm.
  const Toolpath tp = run("G0 X10\nG97 S1000 M3\nG95 G1 Z-1 F0.1\nG96 S100 D5000\nG1 Z-2\n");
  ASSERT_EQ(tp.segments.size(), 3u);
  EXPECT_DOUBLE_EQ(tp.segments[1].feed_mm_per_min, 100.0);
  EXPECT_NEAR(tp.segments[2].feed_mm_per_min, 0.1 * 100000.0 / (2.0 * std::numbers::pi * 10.0), 1e-9);
}

}  // namespace
