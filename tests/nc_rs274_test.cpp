// The rs274 front end: parsing recorded canonical output (always), and — where LinuxCNC's
// rs274 is installed — the cross-check against the built-in interpreter on real programs.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "nc/rs274.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;

// A program and what `rs274 -g` printed for it (linuxcnc-uspace 2.9.0~pre1, Debian 12), with
// the program lines numbered N1.. by run_rs274, tool table T1 = 60 mm, G54 Z = -250 mm.
const char* kRecordedProgram = R"NGC(G21 G90 G17 G94
T1 M6
G43 H1 G0 Z10
G0 X10 Y0
G1 Z-1 F300
G3 X0 Y10 I-10 J0 F600
G18 G2 X-10 Z-1 I-5 K0
G17
G10 L2 P2 X100
G55 G0 X0 Y0
G20 G1 X1 F10
G93 G1 Y1 F4
G94 G21
G4 P0.5
G54 G0 Z25
M30
)NGC";
const char* kRecordedCanon = R"CANON(    1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)
    2 N..... SET_G5X_OFFSET(1, 0.0000, 0.0000, -250.0000, 0.0000, 0.0000, 0.0000)
    3 N..... SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    4 N..... SET_XY_ROTATION(0.0000)
    5 N..... SET_FEED_REFERENCE(CANON_XYZ)
    6 N..... ON_RESET()
    8 N1     SET_FEED_MODE(0, 0)
    9 N1     SET_FEED_RATE(0.0000)
   10 N1     SELECT_PLANE(CANON_PLANE_XY)
   11 N1     USE_LENGTH_UNITS(CANON_UNITS_MM)
   12 N2     SELECT_TOOL(1)
   13 N2     START_CHANGE()
   14 N2     STOP_SPINDLE_TURNING(0)
   15 N2     CHANGE_TOOL(1)
   16 N3     USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 60.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)
   17 N3     STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
   18 N4     STRAIGHT_TRAVERSE(10.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
   19 N5     SET_FEED_RATE(300.0000)
   20 N5     STRAIGHT_FEED(10.0000, 0.0000, -1.0000, 0.0000, 0.0000, 0.0000)
   21 N6     SET_FEED_RATE(600.0000)
   22 N6     ARC_FEED(0.0000, 10.0000, 0.0000, 0.0000, 1, -1.0000, 0.0000, 0.0000, 0.0000)
   23 N7     SELECT_PLANE(CANON_PLANE_XZ)
   24 N7     ARC_FEED(-1.0000, -10.0000, -1.0000, -5.0000, -1, 10.0000, 0.0000, 0.0000, 0.0000)
   25 N8     SELECT_PLANE(CANON_PLANE_XY)
   27 N10    SET_G5X_OFFSET(2, 100.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
   28 N10    SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
   29 N10    SET_XY_ROTATION(0.0000)
   30 N10    STRAIGHT_TRAVERSE(0.0000, 0.0000, -251.0000, 0.0000, 0.0000, 0.0000)
   31 N11    SET_FEED_RATE(10.0000)
   32 N11    USE_LENGTH_UNITS(CANON_UNITS_INCHES)
   33 N11    STRAIGHT_FEED(1.0000, 0.0000, -9.8819, 0.0000, 0.0000, 0.0000)
   35 N12    SET_FEED_MODE(0, 0)
   36 N12    SET_FEED_RATE(4.0000)
   37 N12    STRAIGHT_FEED(1.0000, 1.0000, -9.8819, 0.0000, 0.0000, 0.0000)
   39 N13    SET_FEED_MODE(0, 0)
   40 N13    SET_FEED_RATE(0.0000)
   41 N13    USE_LENGTH_UNITS(CANON_UNITS_MM)
   42 N14    DWELL(0.5000)
   43 N15    SET_G5X_OFFSET(1, 0.0000, 0.0000, -250.0000, 0.0000, 0.0000, 0.0000)
   44 N15    SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
   45 N15    SET_XY_ROTATION(0.0000)
   46 N15    STRAIGHT_TRAVERSE(125.4000, 25.4000, 25.0000, 0.0000, 0.0000, 0.0000)
   47 N16    SET_G5X_OFFSET(1, 0.0000, 0.0000, -250.0000, 0.0000, 0.0000, 0.0000)
   48 N16    SET_XY_ROTATION(0.0000)
   49 N16    SET_FEED_MODE(0, 0)
   50 N16    SET_FEED_RATE(0.0000)
   51 N16    STOP_SPINDLE_TURNING(0)
   52 N16    SET_SPINDLE_MODE(0 0.0000)
   53 N16    PALLET_SHUTTLE()
   54 N16    PROGRAM_END()
   55 N..... ON_RESET()
)CANON";

GcodeOptions recorded_options(double chord_tol_mm) {
  GcodeOptions o;
  o.tool_lengths = {{1, 60.0}, {2, 50.0}, {3, 70.0}};
  o.work_offsets[0] = {0, 0, -250, 0, 0, 0};
  o.chord_tol_mm = chord_tol_mm;
  return o;
}

using lbr::test::directed_distance;

struct Event {
  SegmentKind kind;
  int tool;
  int line;
  double value;
};
// Tool changes and dwells in order, with their lines.
std::vector<Event> events(const Toolpath& t) {
  std::vector<Event> e;
  for (const Segment& s : t.segments)
    if (s.kind == SegmentKind::ToolChange || s.kind == SegmentKind::Dwell)
      e.push_back({s.kind, s.tool, s.line, s.kind == SegmentKind::Dwell ? s.dwell_s : s.end[Z]});
  return e;
}

void expect_same_path(const Toolpath& a, const Toolpath& b, double tol) {
  EXPECT_LE(directed_distance(a, b, tol), tol);
  EXPECT_LE(directed_distance(b, a, tol), tol);
  const auto ea = events(a), eb = events(b);
  ASSERT_EQ(ea.size(), eb.size());
  for (std::size_t i = 0; i < ea.size(); ++i) {
    EXPECT_EQ(ea[i].kind, eb[i].kind);
    EXPECT_EQ(ea[i].tool, eb[i].tool);
    EXPECT_EQ(ea[i].line, eb[i].line);
    EXPECT_NEAR(ea[i].value, eb[i].value, tol);
  }
  EXPECT_NEAR(a.start[Z], b.start[Z], tol);
}

std::string error_of_canon(const std::string& canon) {
  try {
    (void)parse_rs274_canon(canon, "p.ngc", recorded_options(0.001));
  } catch (const ParseError& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(Rs274Canon, RecordedOutputMatchesTheBuiltInInterpreter) {
  // Chords at 0.5 um; rs274 prints 4 decimals, in inches for the G20 block (1.27 um).
  const GcodeOptions o = recorded_options(0.0005);
  const Toolpath canon = parse_rs274_canon(kRecordedCanon, "rec.ngc", o);
  const Toolpath mine = interpret_gcode(kRecordedProgram, "rec.ngc", o);
  expect_same_path(canon, mine, 0.0013);
  // Lines come from the N words.
  EXPECT_EQ(canon.segments.front().kind, SegmentKind::ToolChange);
  EXPECT_EQ(canon.segments.front().line, 2);
  EXPECT_EQ(canon.segments.back().line, 15);
  // G55 move in inches and G93: 1 inch in 1/4 min.
  bool saw_inverse = false;
  for (const Segment& s : canon.segments)
    if (s.line == 12) {
      EXPECT_NEAR(s.feed_mm_per_min, 4 * 25.4, 1e-9);
      saw_inverse = true;
    }
  EXPECT_TRUE(saw_inverse);
}

TEST(Rs274Canon, UnrepresentableCommandsAreErrors) {
  EXPECT_EQ(error_of_canon("    1 N3     STRAIGHT_PROBE(0.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000, 0)\n"),
            "p.ngc:3: rs274: canonical command STRAIGHT_PROBE is not supported");
  EXPECT_EQ(error_of_canon("    1 N4     SET_FEED_MODE(0, 1)\n    2 N4     SET_FEED_RATE(0.1000)\n"
                           "    3 N4     STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"),
            "p.ngc:4: rs274: STRAIGHT_FEED per revolution or synchronised with the spindle needs a spindle speed S > 0 "
            "(at X0 in G96: D)");
  EXPECT_EQ(error_of_canon("    1 N5     SET_XY_ROTATION(30.0000)\n"), "p.ngc:5: rs274: XY rotation (G10 L2 R) is not supported");
  EXPECT_EQ(error_of_canon("    1 N6     STRAIGHT_FEED(1.0000, 0.0000)\n"),
            "p.ngc:6: rs274: canonical command STRAIGHT_FEED has 2 numbers, expected 6");
  // Non-canonical lines (banners, messages) are not commands.
  EXPECT_EQ(parse_rs274_canon("executing\nsome text\n", "p.ngc", recorded_options(0.001)).segments.size(), 0u);
}

TEST(Rs274Run, MissingExecutableIsAClearError) {
  const char* old = std::getenv("PATH");
  const std::string saved = old != nullptr ? old : "";
  setenv("PATH", "/nonexistent-lbrsim-path", 1);
  std::string msg;
  try {
    (void)run_rs274(lbr::test::program_file("cam-pocket.ngc"), recorded_options(0.001));
  } catch (const std::runtime_error& e) {
    msg = e.what();
  }
  setenv("PATH", saved.c_str(), 1);
  EXPECT_EQ(msg,
            "--interpreter rs274: the rs274 program (LinuxCNC's G-code interpreter, Debian package linuxcnc-uspace) "
            "is not on PATH; install it, or leave out --interpreter to use the built-in interpreter");
}

// ---- cross-check with the real rs274 (CI installs linuxcnc-uspace) ---------------------------

class Rs274CrossCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    if (find_rs274().empty()) GTEST_SKIP() << "rs274 (linuxcnc-uspace) is not installed";
  }
  std::string write(const std::string& name, const std::string& text) {
    // Unique per process: test runs of several checkouts may share the temporary directory.
    const std::string path = ::testing::TempDir() + "lbrsim-" + std::to_string(::getpid()) + "-" + name;
    std::ofstream(path) << text;
    written_.push_back(path);
    return path;
  }
  void TearDown() override {
    for (const std::string& p : written_) std::remove(p.c_str());
  }
  std::vector<std::string> written_;
};

TEST_F(Rs274CrossCheck, ProgramsBothAcceptCoincideWithin1um) {
  const std::vector<std::pair<std::string, std::string>> programs = {
      {"arcs.ngc",
       "G21 G90 G17 G94 G91.1\nG0 X10 Y0 Z1\nG1 Z0 F100\nG3 X0 Y10 I-10 J0\nG2 X10 Y0 R10\nG2 X10 Y0 I-10 J0\n"
       "G3 X10 Y0 Z-2 I-10 J0 P2\nG2 X0 Y-10 R-10\nG18 G2 X10 Z-2 I5 K0\nG19 G3 Y0 Z-2 J5 K0\nG17 G90.1 G3 X0 Y0 I5 J5\nM2\n"},
      {"modes.ngc",
       "G21 G90 G17\nT2 M6\nG43 H2 G0 Z5\nG91 G0 X5 Y5\nG1 Z-6 F200\nG90 G1 X20\nG10 L2 P3 X50 Y-5\nG56 G0 X0 Y0\n"
       "G54 G53 G0 Z0\nG28 G91 Z0\nG90 G28 X1 Y2\nG93 G1 X30 F3\nG94 G1 Y30 F400\nG4 P0.25\nG49 G0 Z-100\nM30\n"},
      {"cycles.ngc",
       "G21 G90 G17\nT3 M6\nG43 H3 G0 X0 Y0 Z10\nG98 G81 X5 Y5 Z-3 R2 F100\nX10\nG99 G83 X20 Z-11 R1 Q2.5\n"
       "G98 G73 X30 Y10 Z-7 R2 Q2\nG82 X40 Z-4 R2 P0.2\nG91 G81 X5 Y0 Z-4 R-8 L3\nG90 G80\nG0 Z20\nM30\n"},
      {"inch.ngc", "G20 G90 G17\nG0 X1 Y1 Z0.5\nG1 Z-0.1 F20\nG2 X2 Y1 I0.5 J0\nG21 G1 X0 F500\nM2\n"},
  };
  for (const auto& [name, text] : programs) {
    SCOPED_TRACE(name);
    const GcodeOptions o = recorded_options(0.0005);
    const std::string path = write(name, text);
    const Toolpath theirs = run_rs274(path, o);
    const Toolpath mine = load_gcode(path, o);
    ASSERT_FALSE(mine.segments.empty());
    // 4 printed decimals: 0.05 um in mm, 1.27 um in inches.
    expect_same_path(theirs, mine, name == "inch.ngc" ? 0.0013 : 0.001);
  }
}

TEST_F(Rs274CrossCheck, BundledCamProgramCoincides) {
  const GcodeOptions o = recorded_options(0.0005);
  const std::string path = lbr::test::program_file("cam-pocket.ngc");
  expect_same_path(run_rs274(path, o), load_gcode(path, o), 0.001);
}

// The spindle state (docs/nc-frontend.md#spindle) comes from both front ends alike: M5 S0 at
// start, then what M3/M4/M5 and S set, on every segment.
TEST_F(Rs274CrossCheck, SpindleStatesAgree) {
  const GcodeOptions o = recorded_options(0.0005);
  const std::string path = write("spindle.ngc", "G21 G90\nG0 X1\nS2000 M4\nG1 X2 F100\nM5\nG1 X3\nS500 M3\nG1 X4\nS0\nG1 X5\nM2\n");
  const Toolpath theirs = run_rs274(path, o), mine = load_gcode(path, o);
  ASSERT_EQ(mine.segments.size(), 5u);
  ASSERT_EQ(theirs.segments.size(), mine.segments.size());
  const Spindle expected[] = {Spindle::Off, Spindle::Ccw, Spindle::Off, Spindle::Cw, Spindle::Cw};
  const double s_expected[] = {0, 2000, 2000, 500, 0};
  for (std::size_t i = 0; i < mine.segments.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(mine.segments[i].spindle, expected[i]);
    EXPECT_EQ(theirs.segments[i].spindle, expected[i]);
    EXPECT_DOUBLE_EQ(mine.segments[i].spindle_s, s_expected[i]);
    EXPECT_DOUBLE_EQ(theirs.segments[i].spindle_s, s_expected[i]);
    EXPECT_EQ(mine.segments[i].spindle_turning(), i == 1 || i == 3);
  }
}

TEST_F(Rs274CrossCheck, SubroutinesAndParametersAgree) {
  const std::string path = write("sub.ngc",
                                 "G21 G90\n"
                                 "o100 sub\n"
                                 "  G1 X#1 Y[#1 * 2] F100\n"
                                 "o100 endsub\n"
                                 "#<depth> = -2\n"
                                 "G0 Z#<depth>\n"
                                 "o100 call [3]\n"
                                 "o100 call [4]\n"
                                 "M2\n");
  for (const Toolpath& tp : {run_rs274(path, recorded_options(0.001)), load_gcode(path, recorded_options(0.001))}) {
    ASSERT_EQ(tp.segments.size(), 3u);
    EXPECT_NEAR(tp.segments[0].end[Z], -2.0, 1e-9);
    EXPECT_EQ(tp.segments[0].line, 6);
    EXPECT_NEAR(tp.segments[1].end[X], 3.0, 1e-9);
    EXPECT_NEAR(tp.segments[1].end[Y], 6.0, 1e-9);
    EXPECT_EQ(tp.segments[1].line, 3);  // the line inside the subroutine
    EXPECT_NEAR(tp.segments[2].end[Y], 8.0, 1e-9);
  }
}

TEST_F(Rs274CrossCheck, CutterCompensationUsesTheProfileDiameters) {
  const std::string path = write("comp.ngc",
                                 "G21 G90 G17\nT1 M6\nG43 H1 G0 X-10 Y-10 Z5\nG1 Z-1 F300\nG41 G1 X0 Y0 D1\n"
                                 "G1 X20\nG1 Y20\nG1 X0\nG1 Y0\nG40 G1 X-10 Y-10\nM2\n");
  GcodeOptions o = recorded_options(0.001);
  o.tool_diameters = {{1, 10.0}};
  const Toolpath tp = run_rs274(path, o);
  // Left compensation on a counter-clockwise square: the centre runs 5 mm inside it.
  double xmax = -1e9, ymax = -1e9;
  for (const Segment& s : tp.segments)
    if (s.end[Z] < 0 && s.line >= 6 && s.line <= 9) xmax = std::max(xmax, s.end[X]), ymax = std::max(ymax, s.end[Y]);
  EXPECT_NEAR(xmax, 15.0, 1e-4);
  EXPECT_NEAR(ymax, 15.0, 1e-4);
}

TEST_F(Rs274CrossCheck, ErrorsNameTheSourceLine) {
  const std::string path = write("bad.ngc", "G21 G90\nG0 X0 Y0\nG2 X10 Y0 I4 F100\nM2\n");
  try {
    (void)run_rs274(path, recorded_options(0.001));
    FAIL() << "rs274 accepted an arc with mismatched radii";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(std::string(e.what()).rfind(path + ":3: rs274: Radius to end of arc differs from radius to start", 0), 0u)
        << e.what();
  }
}

}  // namespace
