// The fanuc dialect of the built-in interpreter (docs/nc-frontend.md#fanuc-dialect): O numbers,
// M98/M99 subprograms, G65/G66 macros, macro variables and expressions, IF/GOTO/WHILE, and the
// errors it refuses with. Positions are hand-computed.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;

GcodeOptions fanuc() {
  GcodeOptions o;
  o.dialect = Dialect::Fanuc;
  return o;
}

Toolpath run(const std::string& text, GcodeOptions o = fanuc()) { return interpret_gcode(text, "t.nc", o); }

std::string error_of(const std::string& text, GcodeOptions o = fanuc()) {
  try {
    (void)interpret_gcode(text, "t.nc", o);
  } catch (const ParseError& e) {
    return e.what();
  }
  return "<no error>";
}

// Feed/rapid end points only.
std::vector<AxisVector> ends(const Toolpath& tp) {
  std::vector<AxisVector> v;
  for (const Segment& s : tp.segments)
    if (s.kind == SegmentKind::Rapid || s.kind == SegmentKind::Feed) v.push_back(s.end);
  return v;
}

void expect_xyz(const AxisVector& p, double x, double y, double z, const std::string& what) {
  EXPECT_NEAR(p[X], x, 1e-9) << what;
  EXPECT_NEAR(p[Y], y, 1e-9) << what;
  EXPECT_NEAR(p[Z], z, 1e-9) << what;
}

TEST(FanucDialect, WhileLoopDrillsABoltCircle) {
  const Toolpath tp = run(
      "%\n"
      "O1000 (BOLT CIRCLE)\n"
      "G90 G17 G21 G80;\n"
      "#1 = 6 (HOLES)\n"
      "#2 = 20. (RADIUS)\n"
      "#3 = 0\n"
      "G0 Z10.\n"
      "WHILE [#3 LT #1] DO 1\n"
      "  #4 = #3 * 360 / #1\n"
      "  G0 X[#2 * COS[#4]] Y[#2 * SIN[#4]]\n"
      "  G1 Z-5. F100.\n"
      "  G0 Z10.\n"
      "  #3 = #3 + 1\n"
      "END 1\n"
      "M30\n"
      "%\n");
  std::vector<AxisVector> bottoms;
  for (const Segment& s : tp.segments)
    if (s.kind == SegmentKind::Feed) bottoms.push_back(s.end);
  ASSERT_EQ(bottoms.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    const double a = k * std::numbers::pi / 3.0;
    expect_xyz(bottoms[static_cast<std::size_t>(k)], 20.0 * std::cos(a), 20.0 * std::sin(a), -5.0, "hole " + std::to_string(k));
  }
  EXPECT_EQ(tp.segments[1].line, 10);  // the G0 X Y of the first pass: source lines carry through the loop
}

TEST(FanucDialect, M98RepeatsAnIncrementalSubprogram) {
  const std::string sub =
      "O2001 (STEP)\n"
      "G91 G1 X10. F200.\n"
      "G1 Y5.\n"
      "G90\n"
      "M99\n";
  for (const std::string call : {"M98 P2001 L3", "M98 P32001", "M98 P00032001"}) {
    const auto e = ends(run("O2000\nG90 G0 X0 Y0 Z5.\n" + call + "\nG0 Z20.\nM30\n" + sub));
    ASSERT_EQ(e.size(), 8u) << call;
    for (int k = 0; k < 3; ++k) {
      expect_xyz(e[static_cast<std::size_t>(1 + 2 * k)], 10.0 * (k + 1), 5.0 * k, 5.0, call);
      expect_xyz(e[static_cast<std::size_t>(2 + 2 * k)], 10.0 * (k + 1), 5.0 * (k + 1), 5.0, call);
    }
    expect_xyz(e[7], 30.0, 15.0, 20.0, call);
  }
}

TEST(FanucDialect, M98ShareLocalsAndRunsTheBlockFirst) {
  // M98 keeps the caller's locals (#1 counts across passes); "G0 X5. M98 P3" moves first.
  const auto e = ends(run("#1 = 0\nG0 X5. M98 P3 L2\nG0 X#1\nM30\nO3\n#1 = #1 + 1\nM99\n"));
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NEAR(e[0][X], 5.0, 1e-12);
  EXPECT_NEAR(e[1][X], 2.0, 1e-12);
}

TEST(FanucDialect, G65PassesArgumentsAsLocalsAndRestoresThem) {
  const auto e = ends(run(
      "O1\n"
      "#24 = 99.\n"
      "G65 P9100 X10. Y20. R5. Z-3.\n"
      "G0 X#24 (THE CALLER'S #24 AGAIN)\n"
      "M30\n"
      "O9100 (CORNER: X=#24 Y=#25 R=#18 Z=#26)\n"
      "G0 X#24 Y#25\n"
      "G1 Z#26 F100.\n"
      "G1 X[#24 + #18]\n"
      "IF [#9 NE #0] GOTO 10 (F NOT GIVEN: #9 IS VACANT)\n"
      "G1 Y[#25 + #18]\n"
      "N10 M99\n"));
  ASSERT_EQ(e.size(), 5u);
  expect_xyz(e[0], 10, 20, 0, "G0 X#24 Y#25");
  expect_xyz(e[1], 10, 20, -3, "G1 Z#26");
  expect_xyz(e[2], 15, 20, -3, "X+R");
  expect_xyz(e[3], 15, 25, -3, "Y+R (not skipped)");
  expect_xyz(e[4], 99, 25, -3, "caller's #24");
}

TEST(FanucDialect, G65RepeatCountGivesEachPassTheArguments) {
  // Each of the L3 passes starts with #1 = A = 2; #100 (common) accumulates.
  const auto e = ends(run("#100 = 0\nG65 P50 L3 A2.\nG0 X#100\nM30\nO50\n#1 = #1 + 1\n#100 = #100 + #1\nM99\n"));
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0][X], 9.0, 1e-12);
}

TEST(FanucDialect, IfGotoSkipsAndIfThenAssigns) {
  const auto e = ends(run(
      "#1 = 5\n"
      "IF [#1 GT 3] GOTO 20\n"
      "G0 X99.\n"
      "N20 G0 X1.\n"
      "IF [#1 EQ 5] THEN #2 = #1 * 2\n"
      "IF [#1 EQ 6] THEN #3 = 1\n"
      "G0 Y#2\n"
      "G0 X#3 Z4. (#3 IS VACANT: NO X WORD)\n"
      "GOTO 40\n"
      "G0 Z99.\n"
      "N40 M30\n"));
  ASSERT_EQ(e.size(), 3u);
  expect_xyz(e[0], 1, 0, 0, "N20");
  expect_xyz(e[1], 1, 10, 0, "Y#2");
  expect_xyz(e[2], 1, 10, 4, "vacant X");
}

TEST(FanucDialect, NestedWhileLoops) {
  const auto e = ends(run(
      "#1 = 0\n"
      "WHILE [#1 LT 2] DO 1\n"
      "#2 = 0\n"
      "WHILE [#2 LT 3] DO 2\n"
      "G0 X[#1 * 10] Y[#2 * 10]\n"
      "#2 = #2 + 1\n"
      "END 2\n"
      "#1 = #1 + 1\n"
      "END 1\n"
      "M30\n"));
  ASSERT_EQ(e.size(), 6u);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) expect_xyz(e[static_cast<std::size_t>(3 * i + j)], 10.0 * i, 10.0 * j, 0, "pass");
}

TEST(FanucDialect, FunctionsAndVacantArithmetic) {
  const auto e = ends(run(
      "G0 X[FIX[-1.2]] Y[FUP[-1.2]] Z[ATAN[-1,-1]]\n"
      "G0 X[POW[2,3]] Y[BCD[25]] Z[BIN[37]]\n"
      "G0 X[#0 + 1] Y[ATAN[1]/[-1]] Z[ROUND[2.5] + [7 MOD 4]]\n"
      "#5 = #0\n"
      "IF [#5 EQ #0] THEN #6 = 1\n"
      "IF [#5 EQ 0] THEN #6 = 2\n"
      "G0 X#6\n"));
  ASSERT_EQ(e.size(), 4u);
  expect_xyz(e[0], -1, -2, 225, "FIX FUP ATAN[y,x]");
  expect_xyz(e[1], 8, 37, 25, "POW BCD BIN");
  expect_xyz(e[2], 1, 135, 6, "vacant + 1, ATAN[y]/[x], ROUND, MOD");
  EXPECT_NEAR(e[3][X], 1.0, 1e-12);  // vacant EQ vacant, not EQ 0
}

TEST(FanucDialect, G66CallsTheMacroAfterEachMove) {
  const auto e = ends(run(
      "G0 Z5.\n"
      "G66 P9200 Z-2. F50.\n"
      "G0 X10.\n"
      "G0 X20.\n"
      "G67\n"
      "G0 X30.\n"
      "M30\n"
      "O9200\n"
      "G1 Z#26 F#9\n"
      "G0 Z5.\n"
      "M99\n"));
  ASSERT_EQ(e.size(), 8u);
  expect_xyz(e[1], 10, 0, 5, "first move");
  expect_xyz(e[2], 10, 0, -2, "macro after it");
  expect_xyz(e[5], 20, 0, -2, "macro after the second");
  expect_xyz(e[7], 30, 0, 5, "after G67: no call");
}

TEST(FanucDialect, M99WithPReturnsToASequenceNumber) {
  const auto e = ends(run("M98 P7\nG0 X99.\nN30 G0 X3.\nM30\nO7\nG0 Y1.\nM99 P30\n"));
  ASSERT_EQ(e.size(), 2u);
  expect_xyz(e[1], 3, 1, 0, "returned to N30");
}

TEST(FanucDialect, DwellIsInMillisecondsAndCyclesRepeatWithK) {
  const Toolpath tp = run("G4 P500\nG4 X1.5\nG0 Z10.\nG91 G99 G81 X10. R-8. Z-5. K3 F100.\nG80\n");
  std::vector<double> dwells;
  int feeds = 0;
  double last_x = 0;
  for (const Segment& s : tp.segments) {
    if (s.kind == SegmentKind::Dwell) dwells.push_back(s.dwell_s);
    if (s.kind == SegmentKind::Feed) ++feeds, last_x = s.end[X];
  }
  ASSERT_EQ(dwells.size(), 2u);
  EXPECT_DOUBLE_EQ(dwells[0], 0.5);
  EXPECT_DOUBLE_EQ(dwells[1], 1.5);
  EXPECT_EQ(feeds, 3);
  EXPECT_NEAR(last_x, 30.0, 1e-12);
}

TEST(FanucDialect, SafetyBlockCancelsAreAccepted) {
  const auto e = ends(run("G15 G17 G40 G49 G50 G50.1 G69 G80 G90\nG0 X1.\n"));
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(error_of("G68 X0 Y0 R30.\n"), "t.nc:1: unsupported word 'G68' (not supported by the built-in interpreter)");
}

TEST(FanucDialect, SubprogramFileOnTheSearchPath) {
  const auto dir = std::filesystem::temp_directory_path() / "lbr-fanuc-subpath";
  std::filesystem::create_directories(dir / "lib");
  std::ofstream(dir / "lib" / "O0042.nc") << "%\nO0042\nG0 X[#24 * 2]\nM99\n%\n";
  GcodeOptions o = fanuc();
  o.subroutine_path = {(dir / "lib").string()};
  const auto e = ends(interpret_gcode("G65 P42 X4.\nM30\n", (dir / "main.nc").string(), o));
  std::filesystem::remove_all(dir);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0][X], 8.0, 1e-12);
}

TEST(FanucDialect, ErrorsNameFileAndLine) {
  EXPECT_EQ(error_of("#1 = 1\nWHILE [#1 LT 2] DO 1\nEND 2\n"),
            "t.nc:3: 'END 2' does not close an open 'DO 2' (the innermost open loop is 'DO 1')");
  EXPECT_EQ(error_of("G0 X1.\nEND 1\n"), "t.nc:2: 'END 1' does not close an open 'DO 1'");
  EXPECT_EQ(error_of("WHILE [1 EQ 1] DO 3\nG0 X1.\n"), "t.nc:1: 'DO 3' is never closed by 'END 3'");
  EXPECT_EQ(error_of("G0 X1.\nGOTO 50\nN5 M30\nO9\nN50 M99\n"), "t.nc:2: GOTO 50: no block N50 in the main program");
  const std::string e = error_of("G0 X1.\nM98 P7777\n");
  EXPECT_EQ(e.rfind("t.nc:2: program O7777 is not in this file, and no file O7777 or O7777.nc is in", 0), 0u) << e;
  EXPECT_EQ(error_of("G0 X1.\n#3000 = 12 (TOOL BROKEN)\n"), "t.nc:2: macro alarm 3012 (#3000): TOOL BROKEN");
  EXPECT_EQ(error_of("G0 X1. #1 = 2\n"), "t.nc:1: a macro assignment '#i = ...' must be a block of its own");
  EXPECT_EQ(error_of("#2000 = 1\n"),
            "t.nc:1: variable #2000 cannot be set (locals #1-#33, common #100-#199 and #500-#999; "
            "docs/nc-frontend.md#fanuc-dialect)");
  EXPECT_EQ(error_of("G65 P9 G1 X1.\nO9\nM99\n"),
            "t.nc:1: 'G65' cannot share a block with 'G1' (the block holds P, L and argument words)");
  EXPECT_EQ(error_of("G65 P9 N4\nO9\nM99\n"),
            "t.nc:1: 'G65' cannot share a block with 'N4' (the block holds P, L and argument words)");
  EXPECT_EQ(error_of("IF [#1 GT 0] X1.\n"), "t.nc:1: 'IF [...]' needs 'GOTO n' or 'THEN #i = ...' after the condition");
  EXPECT_EQ(error_of("O1\nM30\nO5\nM99\nO5\nM99\n"), "t.nc:5: program O5 is defined twice");
  // Inside a subprogram the line is the subprogram's.
  EXPECT_EQ(error_of("M98 P9\nM30\nO9\nG0 X[1 / 0]\nM99\n"), "t.nc:4: division by zero");
  // The NGC dialect still refuses the Fanuc words.
  GcodeOptions ngc;
  EXPECT_EQ(error_of("M98 P9\n", ngc), "t.nc:1: unsupported word 'M98' (not supported by the built-in interpreter; use --interpreter rs274)");
}

TEST(FanucDialect, RefusalsOfTheBuiltinSayNothingOfRs274) {
  EXPECT_EQ(error_of("G0 X1.\nG84 Z-5. R2. F100.\n"), "t.nc:2: unsupported word 'G84' (this cycle)");
  EXPECT_EQ(error_of("M98 P9\nM30\nO9\nG0 X1.\nO10\nM99\n"), "t.nc:5: program O9 runs into program O10 (no M99)");
  EXPECT_EQ(error_of("M98 P9\nM30\nO9\nG0 X1."), "t.nc:4: program O9 ends without M99");
}

TEST(FanucDialect, M99InTheMainProgramEndsIt) {
  const auto e = ends(run("G0 X1.\nM99\nG0 X2.\n"));
  ASSERT_EQ(e.size(), 1u);
}

TEST(FanucDialect, RegressionLoopOfLargeArcsIsRefusedNotOutOfMemory) {
  // fuzz_gcode (campaign 2026-11-28): an endless GOTO loop whose full circle `G3 I-4 8000`
  // reads I-48000 (blanks are removed before parsing) made 4 494 segments per pass; within
  // 20 000 blocks the toolpath vector grew to a 2.5 GB allocation, over libFuzzer's memory
  // limit (fuzz/corpus/gcode/regression-arc-loop-oom). The toolpath is bounded instead.
  const std::string prog =
      "N1M8 G94 G40 G49 G80\nT0 G40\nF800\nG3 X24 Y28 Z0.0357 I-4 2000 M3\nG0 X32 Y+8 Z0 G40\nF800\n"
      "G3 I-4 8000\nG3 X24 Y28 Z0.0357 I-4 2000 M3\nG0 X32 Y+81M64P0 \nGOTO1\n";
  GcodeOptions o = fanuc();
  o.chord_tol_mm = 0.01;
  o.max_blocks = 20000;
  o.max_segments = 100000;
  EXPECT_EQ(error_of(prog, o),
            "t.nc:7: the program makes more than 100000 moves (an endless loop, or arcs of many turns at a fine chord "
            "tolerance?)");
}

// Seeded random mutations of Fanuc programs: every run ends in a Toolpath or a ParseError naming
// a line of the input, never in another exception, a crash or a hang. LBR_FUZZ_SEED=<n>
// reproduces a run; the budget is a few seconds.
TEST(FanucDialect, SeededMutatorNeverCrashesOrHangs) {
  const std::vector<std::string> corpus = {
      read_text_file(lbr::test::program_file("fanuc-flange.nc")),
      "#1=0\nWHILE[#1LT3]DO1\n#2=0\nWHILE[#2LT2]DO2\nG0X#1Y#2\n#2=#2+1\nEND2\n#1=#1+1\nEND1\nM30\n",
      "G66P9Z-2.\nG0X10.\nG67\nM98P9L2\nIF[#0EQ#0]GOTO5\nN5M99\nO9\nG1Z#26F100.\n#100=ATAN[1,2]+POW[2,3]\nM99P5\n",
  };
  const char* env = std::getenv("LBR_FUZZ_SEED");
  const unsigned seed = env != nullptr ? static_cast<unsigned>(std::strtoul(env, nullptr, 10)) : 20261124u;
  std::mt19937 rng(seed);
  const std::string alphabet = "GMXYZPLKOND#[]=0123456789.-+ ()%;/\nIFWHILEDOENDGOTOTHEN";
  GcodeOptions o = fanuc();
  o.chord_tol_mm = 0.01;
  o.max_blocks = 20000;      // mutated loops may never end
  o.max_segments = 100000;  // nor may loops of large arcs (see the regression below)
  const auto t0 = std::chrono::steady_clock::now();
  int runs = 0, parsed = 0;
  for (; runs < 20000; ++runs) {
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(3)) break;
    std::string s = corpus[rng() % corpus.size()];
    lbr::test::mutate(s, rng, alphabet);
    const long lines = 1 + std::count(s.begin(), s.end(), '\n');
    try {
      const Toolpath tp = interpret_gcode(s, "fuzz.nc", o);
      ++parsed;
      for (const Segment& seg : tp.segments) {
        for (double v : seg.end) ASSERT_TRUE(std::isfinite(v)) << "seed " << seed << " run " << runs << ":\n" << s;
        ASSERT_GE(seg.line, 1);
        ASSERT_LE(seg.line, lines);
      }
    } catch (const ParseError& e) {
      ASSERT_GE(e.line(), 1) << e.what() << "\n" << s;
      ASSERT_LE(e.line(), lines) << e.what() << "\n" << s;
    }
  }
  std::printf("fuzz: seed %u, %d runs, %d interpreted, %d rejected\n", seed, runs, parsed, runs - parsed);
  EXPECT_GT(runs, 200);
  EXPECT_GT(parsed, 0);
  EXPECT_LT(parsed, runs);
}

}  // namespace
