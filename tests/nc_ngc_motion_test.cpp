// Motion added to the built-in interpreter for issue 14: spindle-synchronised moves (G33,
// G33.1), the G76 threading cycle, cutter radius compensation (G41/G42, G41.1/G42.1) and
// canned cycles in the G18/G19 planes. Positions are hand-computed; where rs274
// (linuxcnc-uspace) is installed the same text also runs through it and every end point must
// agree within 1 µm (rs274 prints 4 decimals).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "nc/rs274.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;

using lbr::test::ends;
using lbr::test::error_of;
using lbr::test::run;

GcodeOptions lathe() {
  GcodeOptions o;
  o.machine = MachineKind::Lathe;
  return o;
}

// Runs `text` through rs274 too (when installed): the same end points within 1 µm. Arcs are
// compared at their end points only (both front ends chord them with the same code).
void cross_check(const std::string& text, const GcodeOptions& o, double tol = 1e-3) {
  if (find_rs274().empty()) return;
  const auto dir = std::filesystem::temp_directory_path() / ("lbr-motion-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  const Toolpath theirs = run_rs274(path, o);
  std::filesystem::remove_all(dir);
  const auto a = ends(run(text, o)), b = ends(theirs);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < kAxes; ++k) EXPECT_NEAR(a[i][k], b[i][k], tol) << "end point " << i << " axis " << k;
  ASSERT_EQ(run(text, o).segments.size(), theirs.segments.size());
  for (std::size_t i = 0; i < theirs.segments.size(); ++i)
    EXPECT_NEAR(run(text, o).segments[i].feed_mm_per_min, theirs.segments[i].feed_mm_per_min, 1e-3 * 200)
        << "segment " << i;
}

// Both front ends on `text` (rs274 when installed): every vertex of each path within tol of
// the other path, in order (arcs are chorded by the same code, so chord counts may differ
// by the 4 decimals rs274 prints).
void cross_check_path(const std::string& text, const GcodeOptions& o, double tol = 1e-3) {
  if (find_rs274().empty()) return;
  const auto dir = std::filesystem::temp_directory_path() / ("lbr-motion-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  const Toolpath theirs = run_rs274(path, o);
  std::filesystem::remove_all(dir);
  const Toolpath mine = run(text, o);
  EXPECT_LE(lbr::test::directed_distance(mine, theirs, tol), tol);
  EXPECT_LE(lbr::test::directed_distance(theirs, mine, tol), tol);
}

GcodeOptions mill_with_tools() {
  GcodeOptions o;
  o.tool_diameters = {{1, 10.0}, {2, 4.0}};
  o.chord_tol_mm = 0.0005;
  return o;
}

// ---- G33, G33.1 ----------------------------------------------------------------------------

TEST(NgcSpindleSync, G33FeedsAtKTimesTheSpindleSpeed) {
  const std::string prog = "G21 G90 G18\nM3 S100\nG0 X10 Z5\nG33 Z-20 K1.5\nG0 X12\nG0 Z5\nG33.1 Z-10 K1.25\nM2\n";
  const Toolpath tp = run(prog, lathe());
  ASSERT_EQ(tp.segments.size(), 6u);
  EXPECT_EQ(tp.segments[1].kind, SegmentKind::Feed);
  EXPECT_DOUBLE_EQ(tp.segments[1].end[Z], -20.0);
  EXPECT_DOUBLE_EQ(tp.segments[1].feed_mm_per_min, 150.0);  // 1.5 mm/rev x 100 rpm
  // G33.1: down to Z-10 and back up to Z5, both at 1.25 x 100 mm/min.
  EXPECT_DOUBLE_EQ(tp.segments[4].end[Z], -10.0);
  EXPECT_DOUBLE_EQ(tp.segments[5].end[Z], 5.0);
  EXPECT_DOUBLE_EQ(tp.segments[4].feed_mm_per_min, 125.0);
  EXPECT_DOUBLE_EQ(tp.segments[5].feed_mm_per_min, 125.0);
  cross_check(prog, lathe());
}

TEST(NgcSpindleSync, ErrorsNameTheWord) {
  EXPECT_EQ(error_of("S100\nG33 Z-1\n", lathe()), "t.ngc:2: 'G33' needs K (distance per revolution)");
  EXPECT_EQ(error_of("G33.1 Z-1 K1\n", lathe()), "t.ngc:1: 'G33.1' needs a spindle speed S > 0 (spindle-synchronised motion)");
}

// ---- G76 -------------------------------------------------------------------------------------

TEST(NgcThreading, PassesFollowTheDepthSeries) {
  // Drive line X10 (radius mode), peak I-1.5 -> X8.5; J0.3 then 0.6, full K0.9: cuts at
  // X8.2, 7.9, 7.6; the retract X is 10 + (K - depth); pitch 2 mm at 100 rpm = 200 mm/min.
  const std::string prog = "G21 G90 G18 G8\nM3 S100\nG0 X10 Z5\nG76 P2 Z-20 I-1.5 J0.3 K0.9\nM2\n";
  const Toolpath tp = run(prog, lathe());
  const auto e = ends(tp);
  ASSERT_EQ(e.size(), 1u + 3u * 4u + 1u);
  const double cut[3] = {8.2, 7.9, 7.6}, safe[3] = {10.6, 10.3, 10.0};
  for (int p = 0; p < 3; ++p) {
    const std::size_t i = 1 + 4 * static_cast<std::size_t>(p);
    EXPECT_NEAR(e[i][X], safe[p], 1e-12);
    EXPECT_NEAR(e[i][Z], 5.0, 1e-12);
    EXPECT_NEAR(e[i + 1][X], cut[p], 1e-12);
    EXPECT_NEAR(e[i + 2][X], cut[p], 1e-12);
    EXPECT_NEAR(e[i + 2][Z], -20.0, 1e-12);
    EXPECT_NEAR(e[i + 3][X], safe[p], 1e-12);
    EXPECT_DOUBLE_EQ(tp.segments[i + 2].feed_mm_per_min, 200.0);
  }
  EXPECT_NEAR(e.back()[X], 10.0, 1e-12);
  EXPECT_NEAR(e.back()[Z], -20.0, 1e-12);
  cross_check(prog, lathe());
}

TEST(NgcThreading, CompoundAngleTapersSpringPassesAndInternalThreads) {
  // Q30, L1 E3 (entry taper): pass 1 at depth 0.5 starts at Z5 - 0.5 tan30 and ends at
  // Z-20 + (1 - 0.5) tan30; the taper runs from the crest (cut + K) over E along Z at
  // 2 sqrt(1 + 9) / 3 mm/rev.
  const std::string prog = "G21 G90 G18 G8\nM3 S100\nG0 X10 Z5\nG76 P2 Z-20 I-1.5 J0.5 K1 E3 L1 Q30\nM2\n";
  const Toolpath tp = run(prog, lathe());
  const auto e = ends(tp);
  const double t30 = std::tan(std::numbers::pi / 6);
  ASSERT_GE(e.size(), 6u);
  EXPECT_NEAR(e[1][X], 10.5, 1e-12);
  EXPECT_NEAR(e[1][Z], 5.0 - 0.5 * t30, 1e-12);
  EXPECT_NEAR(e[2][X], 9.0, 1e-12);
  EXPECT_NEAR(e[3][X], 8.0, 1e-12);
  EXPECT_NEAR(e[3][Z], 5.0 - 0.5 * t30 - 3.0, 1e-12);
  EXPECT_NEAR(e[4][Z], -20.0 + 0.5 * t30, 1e-12);
  EXPECT_NEAR(tp.segments[3].feed_mm_per_min, 2.0 * std::sqrt(10.0) / 3.0 * 100.0, 1e-9);
  cross_check(prog, lathe());
  // Internal thread (I > 0), exit taper, degression R2, two spring passes.
  cross_check("G21 G90 G18 G8\nM3 S100\nG0 X10 Z5\nG76 P2 Z-20 I2 J0.3 K0.9 R2 H2 E1 L2\nM2\n", lathe());
  cross_check("G21 G90 G18 G8\nM3 S100\nG0 X10 Z-20\nG76 P1.5 Z5 X12 I-1 J0.2 K0.8 Q29.5 E2 L3\nM2\n", lathe());
}

TEST(NgcThreading, ErrorsNameTheWord) {
  EXPECT_EQ(error_of("S100\nG76 P2 Z-20 I-1.5 J0.5 K0.4\n", lathe()),
            "t.ngc:2: 'G76': K (full thread depth) must be greater than J (first cut depth)");
  EXPECT_EQ(error_of("S100\nG76 P2 Z-20 I-1.5 K1\n", lathe()),
            "t.ngc:2: 'G76' needs J (P pitch, Z end, I peak offset, J first depth, K full depth)");
}

// ---- canned cycles in G18 and G19 ------------------------------------------------------------

TEST(NgcCannedCycles, DrillAlongTheThirdAxisOfEveryPlane) {
  // G18: holes along Y at X Z positions; G19: along X at Y Z positions. G98 returns to the
  // level the series began at (Y10, X10), G99 to R.
  const std::string prog = "G21 G90 F100\nG0 X5 Y10 Z5\nG18 G98 G81 X7 Z3 Y-4 R2\nX9\nG80\nG0 X10 Y0 Z0\n"
                           "G19 G99 G83 Y6 Z8 X-5 R1 Q2.5\nG80\nG17\nM2\n";
  const auto e = ends(run(prog));
  ASSERT_GE(e.size(), 8u);
  // First hole: over X7 Z3 at Y10, down to R (Y2), feed to Y-4, back to Y10.
  EXPECT_DOUBLE_EQ(e[1][X], 7.0);
  EXPECT_DOUBLE_EQ(e[1][Z], 3.0);
  EXPECT_DOUBLE_EQ(e[1][Y], 10.0);
  EXPECT_DOUBLE_EQ(e[2][Y], 2.0);
  EXPECT_DOUBLE_EQ(e[3][Y], -4.0);
  EXPECT_DOUBLE_EQ(e[4][Y], 10.0);
  EXPECT_DOUBLE_EQ(e[5][X], 9.0);
  cross_check(prog, {});
  // Regression: without G98/G99 the retract mode is G99 (R plane), as LinuxCNC's interpreter
  // starts (the built-in interpreter started in G98).
  const std::string dflt = "G21 G90 F100\nG0 X5 Y10 Z10\nG81 X1 Y1 Z-1 R2\nX2\nM2\n";
  EXPECT_DOUBLE_EQ(ends(run(dflt))[4][Z], 2.0);
  cross_check(dflt, {});
  // Regression: a G99 block raised above the initial level, then G98 (retracts to the
  // initial level, starts from the current height); a G98 block after G99 starts from the
  // initial level (a diagonal traverse), as rs274.
  cross_check_path("G21 G90 G17\nG0 X0 Y0 Z10\nG98 G81 X5 Y5 Z-3 R2 F100\nX10\nG99 G83 X20 Z-11 R1 Q2.5\n"
                   "G98 G73 X30 Y10 Z-7 R2 Q2\nG82 X40 Z-4 R2 P0.2\nG99 G81 X50 R12 Z-1\nG98 X60 R2\nM2\n",
                   {});
  cross_check("G21 G90 F100\nG0 X5 Y10 Z5\nG18 G91 G73 X2 Z1 Y-6 R-2 Q1.5 L3\nG90 G80\nG19 G82 Y1 Z2 X1 R4 P0.5\nM2\n", {});
}

// ---- polar coordinates (@ distance, ^ angle) -------------------------------------------------

TEST(NgcPolar, AbsoluteIncrementalAndInCannedCycles) {
  // G90: @ and ^ from the XY origin; G91: added to the current distance and angle.
  const std::string prog = "G21 G90 F100\nG0 @10 ^30\nG91 G1 @5 ^60\nG90 G1 ^180\nM2\n";
  const auto e = ends(run(prog));
  ASSERT_EQ(e.size(), 3u);
  EXPECT_NEAR(e[0][X], 10.0 * std::cos(std::numbers::pi / 6), 1e-12);
  EXPECT_NEAR(e[0][Y], 5.0, 1e-12);
  EXPECT_NEAR(e[1][X], 0.0, 1e-12);  // distance 15 at 90 deg
  EXPECT_NEAR(e[1][Y], 15.0, 1e-12);
  EXPECT_NEAR(e[2][X], -15.0, 1e-12);
  cross_check(prog, {});
  // A bolt circle: six holes 60 deg apart from X15 Y0 (LinuxCNC's hole-circle.ngc), and the
  // regression for G91 R in a continued series (relative to where the series began).
  const std::string holes = "G21 G90 F100\nG0 X15 Y0 Z0\nG91 G81 R2 Z-5 ^60 L6\nG90 G0 Z10\nG81 @5 ^33 R2 Z-3\n"
                            "G91 @5 R1 Z-3 L2\nG90 G80\nM2\n";
  const auto h = ends(run(holes));
  ASSERT_GE(h.size(), 5u);
  EXPECT_NEAR(h[2][X], 15.0 * std::cos(std::numbers::pi / 3), 1e-12);  // first hole at 60 deg
  EXPECT_NEAR(h[2][Y], 15.0 * std::sin(std::numbers::pi / 3), 1e-12);
  EXPECT_NEAR(h[3][Z], -3.0, 1e-12);  // R = 0 + 2, bottom R - 5
  cross_check_path(holes, {});
  EXPECT_EQ(error_of("G0 @1 X2\n"), "t.ngc:1: polar coordinates '@1' cannot be combined with X or Y words");
  EXPECT_EQ(error_of("G91 G0 ^10\n"), "t.ngc:1: incremental polar coordinates '^10' are indeterminate at the origin");
}

// ---- M70-M73 modal state ---------------------------------------------------------------------

TEST(NgcModalState, SaveRestoreAndAutoRestoreOnReturn) {
  // M70/M72 at one level; M73 in a subroutine restores the caller's G21 G90 F100 at endsub.
  const std::string prog = "G21 G90 F200\nM70\nG20 G91 F5\nG1 X1\nM72\nG1 X10\n"
                           "o<s> sub\nM73\nG20 G91 F5\nG1 X1\no<s> endsub\nG21 G90 F100\no<s> call\nG1 X50\nM71\nM2\n";
  const Toolpath tp = run(prog);
  ASSERT_EQ(tp.segments.size(), 4u);
  EXPECT_DOUBLE_EQ(tp.segments[0].end[X], 25.4);
  EXPECT_DOUBLE_EQ(tp.segments[0].feed_mm_per_min, 127.0);
  EXPECT_DOUBLE_EQ(tp.segments[1].end[X], 10.0);  // G21 G90 again
  EXPECT_DOUBLE_EQ(tp.segments[1].feed_mm_per_min, 200.0);
  EXPECT_DOUBLE_EQ(tp.segments[2].end[X], 10.0 + 25.4);
  EXPECT_DOUBLE_EQ(tp.segments[3].end[X], 50.0);
  EXPECT_DOUBLE_EQ(tp.segments[3].feed_mm_per_min, 100.0);
  cross_check(prog, {});
  EXPECT_EQ(error_of("M70\nM71\nM72\n"), "t.ngc:3: 'M72': no modal state saved at this call level (M70 or M73 first)");
}

// ---- cutter radius compensation -------------------------------------------------------------

// The last end point of the segments of `line`.
AxisVector end_of_line(const Toolpath& tp, int line) {
  AxisVector e{};
  for (const Segment& s : tp.segments)
    if (s.line == line) e = s.end;
  return e;
}

TEST(NgcCutterComp, SquareLeftAndRightWithEntryAndExit) {
  // Counter-clockwise 20 mm square from (0, 0), G41 with a 10 mm tool (radius 5): the entry
  // from (-10, -10) ends beside (0, 0), square to its direction: (0, 0) + 5 (-sin 45, cos 45).
  // Its corner with the first side is convex (a right turn): an arc around (0, 0) to (0, 5).
  // The other corners turn left, towards the tool: concave, the sides meet at X15 Y5, X15
  // Y15, X5 Y15; the last side ends beside (0, 0) at (5, 0) when G40 closes it.
  const std::string prog = "G21 G90 G17\nG0 X-10 Y-10 Z5\nG1 Z-1 F300\nG41 D1 G1 X0 Y0\nG1 X20\nG1 Y20\nG1 X0\nG1 Y0\n"
                           "G40 G1 X-10 Y-10\nM2\n";
  const Toolpath tp = run(prog, mill_with_tools());
  const double s45 = std::sqrt(0.5) * 5.0;
  const double want[][3] = {{4, -s45, s45}, {5, 15, 5}, {6, 15, 15}, {7, 5, 15}, {8, 5, 0}, {9, -10, -10}};
  for (const auto& w : want) {
    EXPECT_NEAR(end_of_line(tp, static_cast<int>(w[0]))[X], w[1], 1e-9) << "line " << w[0];
    EXPECT_NEAR(end_of_line(tp, static_cast<int>(w[0]))[Y], w[2], 1e-9) << "line " << w[0];
  }
  for (const Segment& s : tp.segments) {  // the corner arc of line 5 stays 5 mm from (0, 0)
    if (s.line == 5 && s.end[X] < 1.0) {  // within the chord tolerance (two-sided chords)
      EXPECT_NEAR(std::hypot(s.end[X], s.end[Y]), 5.0, 0.001);
    }
  }
  cross_check_path(prog, mill_with_tools());
  // G42 on the same square: outside, every corner convex: a quarter arc around each corner.
  std::string right = prog;
  right.replace(right.find("G41"), 3, "G42");
  const Toolpath rp = run(right, mill_with_tools());
  double xmax = -1e9, ymin = 1e9;
  for (const Segment& s : rp.segments) xmax = std::max(xmax, s.end[X]), ymin = std::min(ymin, s.end[Y]);
  EXPECT_NEAR(xmax, 25.0, 1e-9);
  EXPECT_NEAR(ymin, -10.0, 1e-9);  // the exit point; the path itself stays at Y >= -5
  cross_check_path(right, mill_with_tools());
}

TEST(NgcCutterComp, ArcsInXYAndXZAndTheDiameterForm) {
  // Lines and arcs both ways, convex and concave, R and IJK arcs (LinuxCNC's comp.ngc shape).
  const std::string xy = "G21 G90 G17 F300\nG0 X-5 Y-5 Z0\nG42 D2\nG1 X0 Y0\nG1 Y25\nG3 R6.25 X-6.25 Y31.25\nG1 X-12.5\n"
                         "G2 R6.25 X-18.75 Y37.5\nG1 Y43.75\nG40\nG0 X5 Y-5\nG41 D2\nG1 X0 Y0\nG1 Y25\n"
                         "G3 X-6.25 Y31.25 I-6.25 J0\nG1 X-12.5\nG2 X-18.75 Y37.5 I0 J6.25\nG1 Y43.75\nG40\nM2\n";
  cross_check_path(xy, mill_with_tools());
  const std::string xz = "G21 G90 G18 F300\nG0 X-5 Z-5 Y0\nG42 D2\nG1 X0 Z0\nG1 Z25\nG2 R6.25 X-6.25 Z31.25\n"
                         "G1 X-12.5\nG3 R6.25 X-18.75 Z37.5\nG1 Z43.75\nG40\nM2\n";
  cross_check_path(xz, mill_with_tools());
  std::string xz_left = xz;
  xz_left.replace(xz_left.find("G42"), 3, "G41");
  xz_left.replace(xz_left.find("G0 X-5 Z-5"), 10, "G0 X5 Z-5");
  cross_check_path(xz_left, mill_with_tools());
  // G41.1 D4 (diameter in the block) gives the path of G41 D2 (tool 2: 4 mm).
  std::string d = xy;
  for (std::size_t at; (at = d.find("D2")) != std::string::npos;) d.replace(at, 2, "D4");
  for (std::size_t at; (at = d.find("G41 ")) != std::string::npos;) d.replace(at, 4, "G41.1 ");
  for (std::size_t at; (at = d.find("G42 ")) != std::string::npos;) d.replace(at, 4, "G42.1 ");
  const auto a = ends(run(xy, mill_with_tools())), b = ends(run(d, mill_with_tools()));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i][X], b[i][X], 1e-12);
}

TEST(NgcCutterComp, ReversalsAndFarMeetingPointsAsRs274) {
  // Regressions from random programs against rs274: a near reversal before an arc with the
  // tool outside it is a concave corner (the entry line is cut back to the arc); an arc-arc
  // corner whose offset circles meet far from the programmed corner.
  cross_check_path("G21 G90 G17 F300\nG0 X-20 Y-20\nG42 D2\nG1 X0 Y0\nG3 X3.729 Y-18.626 R11.344\n"
                   "G3 X-6.777 Y23.7 R22.663\nG2 X6.878 Y-9.854 R36.558\nG2 X15.207 Y-5.232 R22.247\n"
                   "G3 X14.683 Y-26.068 R30.179\nG1 X1.205 Y18.254\nG40 G1 X40 Y40\nM2\n",
                   mill_with_tools());
  cross_check_path("G21 G90 G17 F300\nG0 X-20 Y-20\nG41 D2\nG1 X0 Y0\nG2 X-4.297 Y-12.663 R20.705\n"
                   "G1 X25.831 Y-20.893\nG3 X0.934 Y23.007 R37.956\nG2 X18.107 Y-15.502 R28.595\n"
                   "G3 X10.907 Y6.377 R29.956\nG1 X-5.851 Y-6.427\nG40 G1 X40 Y40\nM2\n",
                   mill_with_tools());
}

TEST(NgcCutterComp, ArcEntryHelixAndZMovesInside) {
  // comp311_2-like: the first move after G41 is an arc; Z-only moves between corners.
  GcodeOptions o = mill_with_tools();
  const std::string prog = "G21 G90 G17 F300\nG0 X30 Y100 Z5\nG1 Z0\nG41 D2\nG3 X50 Y80 I20\nG2 X70 Y60 J-20\nG1 Y0\n"
                           "G1 Z-1\nG1 X0\nG2 X0 Y0 Z-2 I0 J10\nG1 X-10 Y20\nG40\nG1 X-20 Y30\nM2\n";
  cross_check_path(prog, o);
}

TEST(NgcCutterComp, GougingCornersAreRefusedWithTheLine) {
  // A 4 mm wide slot, cut inside with a 10 mm tool: the concave corners cannot be reached.
  EXPECT_EQ(error_of("G21 G90 F100\nG0 X-10 Y-10\nG41 D1 G1 X0 Y0\nG1 X20\nG1 Y4\nG1 X0\nG1 Y0\nG40 G1 X-10\nM2\n",
                     mill_with_tools()),
            "t.ngc:6: straight feed in a concave corner cannot be reached by the tool (radius 5 mm) without gouging");
  EXPECT_EQ(error_of("G21 G90 F100\nG0 X0 Y0\nG41 D1 G1 X3 Y0\n", mill_with_tools()),
            "t.ngc:3: the cutter compensation entry move (3 mm in the plane) is not longer than the tool radius (5 mm)");
  EXPECT_EQ(error_of("G21 G90 F100\nG0 X-20 Y0\nG41 D1 G1 X0 Y0\nG3 X8 Y0 I4\n", mill_with_tools()),
            "t.ngc:4: the tool radius (5 mm) is not less than the arc radius (4 mm) with cutter compensation");
  EXPECT_EQ(error_of("G21 F100\nG41 D1\nT2 M6\n", mill_with_tools()),
            "t.ngc:3: cannot change tools with cutter radius compensation on (G40 first)");
  EXPECT_EQ(error_of("G21 F100\nG41 D1\nG1 X20 Y0\nG81 X1 R1 Z-1\n", mill_with_tools()),
            "t.ngc:4: 'G81' cannot be used with cutter radius compensation on (G40 first)");
  EXPECT_EQ(error_of("G21 F100\nG41 D1\nG1 X20 Y0\nG40\nG2 X30 Y0 R5\n", mill_with_tools()),
            "t.ngc:5: 'G2': the move just after G40 must be a straight line, not an arc (as LinuxCNC)");
  EXPECT_EQ(error_of("G41 D7\n", mill_with_tools()), "t.ngc:1: 'D7': tool 7 has no diameter in the tool table");
  // #<_ccomp> follows the state (410 with G41, 400 after G40), as LinuxCNC.
  const auto cc = ends(run("G21 F100\nG41 D1\nG1 X20 Y0\nG1 X[#<_ccomp>]\nG40\nG1 Y[#<_ccomp>]\n", mill_with_tools()));
  EXPECT_NEAR(cc[2][X], 410.0, 1e-9);
  EXPECT_NEAR(cc.back()[Y], 400.0, 1e-9);
  EXPECT_EQ(error_of("G19 G41 D1\n", mill_with_tools()), "t.ngc:1: cutter radius compensation needs plane G17 (XY) or G18 (XZ)");
}

TEST(NgcCutterComp, RegressionAMoveStillHeldAtTheEndIsNamedAtTheLastLine) {
  // fuzz_gcode (seventh round): a program that ends with compensation on and no M2. The move
  // compensation still held went out when the program ran off its end, and its gouge error
  // named line 4 of a 3-line program.
  // Its input, as found (fuzz/corpus/gcode/regression-comp-at-end):
  EXPECT_EQ(error_of("%SIA\xa8" "6\nD1G0X1G41.1\nG0 ^40 81T32104", mill_with_tools()),
            "t.ngc:3: straight traverse in a concave corner cannot be reached by the tool (radius 0.5 mm) without gouging");
}

}  // namespace
