// The built-in G-code interpreter: per-feature move lists, exact error messages, and a
// seeded random mutator over a corpus of valid programs (bounded in time).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <tuple>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;
using lbr::test::program_file;

constexpr double kEps = 1e-9;

using lbr::test::error_of;
using lbr::test::run;

void expect_at(const AxisVector& p, double x, double y, double z) {
  EXPECT_NEAR(p[X], x, kEps);
  EXPECT_NEAR(p[Y], y, kEps);
  EXPECT_NEAR(p[Z], z, kEps);
}
void expect_at(const Segment& s, double x, double y, double z) { expect_at(s.end, x, y, z); }

// Feed segments of line `line`, as points (the linearised arc).
std::vector<AxisVector> points_of_line(const Toolpath& tp, int line) {
  std::vector<AxisVector> v;
  for (const Segment& s : tp.segments)
    if (s.line == line) v.push_back(s.end);
  return v;
}

double poly_length(const AxisVector& from, const std::vector<AxisVector>& pts) {
  double l = 0;
  AxisVector p = from;
  for (const AxisVector& q : pts) {
    l += std::hypot(q[X] - p[X], q[Y] - p[Y], q[Z] - p[Z]);
    p = q;
  }
  return l;
}

TEST(GcodeLinear, RapidFeedModalAndLines) {
  const Toolpath tp = run("G0 X1 Y2\nG1 Z-1 F100\nX5\n\nG0 Y0\n");
  ASSERT_EQ(tp.segments.size(), 4u);
  EXPECT_EQ(tp.segments[0].kind, SegmentKind::Rapid);
  expect_at(tp.segments[0], 1, 2, 0);
  EXPECT_EQ(tp.segments[0].line, 1);
  EXPECT_EQ(tp.segments[1].kind, SegmentKind::Feed);
  EXPECT_DOUBLE_EQ(tp.segments[1].feed_mm_per_min, 100.0);
  expect_at(tp.segments[1], 1, 2, -1);
  EXPECT_EQ(tp.segments[2].kind, SegmentKind::Feed);  // modal G1
  expect_at(tp.segments[2], 5, 2, -1);
  EXPECT_EQ(tp.segments[2].line, 3);
  EXPECT_EQ(tp.segments[3].line, 5);
  expect_at(tp.segments[3], 5, 0, -1);
}

TEST(GcodeLinear, IncrementalAndBack) {
  const Toolpath tp = run("G91\nG0 X1\nX1 Y1\nG90 X0\n");
  ASSERT_EQ(tp.segments.size(), 3u);
  expect_at(tp.segments[0], 1, 0, 0);
  expect_at(tp.segments[1], 2, 1, 0);
  expect_at(tp.segments[2], 0, 1, 0);
}

TEST(GcodeLinear, InchUnitsScaleCoordinatesAndFeed) {
  const Toolpath tp = run("G20 G0 X1\nG1 Y1 F10\nG21 G1 Z-1\n");
  ASSERT_EQ(tp.segments.size(), 3u);
  expect_at(tp.segments[0], 25.4, 0, 0);
  expect_at(tp.segments[1], 25.4, 25.4, 0);
  EXPECT_NEAR(tp.segments[1].feed_mm_per_min, 254.0, kEps);
  expect_at(tp.segments[2], 25.4, 25.4, -1);
  // F was given in inch/min; after G21 the same F value means mm/min (as in LinuxCNC).
  EXPECT_NEAR(tp.segments[2].feed_mm_per_min, 10.0, kEps);
}

TEST(GcodeLinear, InverseTimeFeed) {
  const Toolpath tp = run("G93 G1 X10 F2\n");
  ASSERT_EQ(tp.segments.size(), 1u);
  EXPECT_NEAR(tp.segments[0].feed_mm_per_min, 20.0, kEps);  // 10 mm in 1/2 min
  EXPECT_EQ(error_of("G93 G1 X10 F2\nX20\n"), "t.ngc:2: 'G1' in inverse time mode (G93) needs an F word in the block");
}

struct ArcCase {
  const char* program;
  int arc_line;
  double cu, cv, r;  // centre and radius in the plane
  int u, v, w;       // plane axes
  double sweep;      // signed sweep [rad], + counter-clockwise in (u, v)
};

class GcodeArc : public ::testing::TestWithParam<ArcCase> {};

// Two-sided chords (nc/src/path_builder.cpp): the inner vertices on radius r·θ/sin θ (θ half
// a chord's angle), the end point on the arc; every chord within the tolerance on both sides.
TEST_P(GcodeArc, PointsWithinChordToleranceOnBothSidesAndSweep) {
  const ArcCase& c = GetParam();
  GcodeOptions o;
  o.chord_tol_mm = 0.001;
  const Toolpath tp = run(c.program, o);
  const std::vector<AxisVector> pts = points_of_line(tp, c.arc_line);
  ASSERT_FALSE(pts.empty());
  // Chord count: the smallest with the end chords' deviation (5/12 r θ²) within tol.
  const double step = 2.0 * std::sqrt(2.35 * 0.001 / c.r);
  EXPECT_EQ(static_cast<double>(pts.size()), std::ceil(std::abs(c.sweep) / step));
  const double half = 0.5 * std::abs(c.sweep) / static_cast<double>(pts.size());
  const double rho = pts.size() > 1 ? c.r * half / std::sin(half) : c.r;
  // Start of the arc: the end of the segment before it.
  std::size_t first = 0;
  while (tp.segments[first].line != c.arc_line) ++first;
  AxisVector prev = first == 0 ? tp.start : tp.segments[first - 1].end;
  double swept = 0.0, worst_in = 0.0, worst_out = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const AxisVector& p = pts[i];
    const double radius = std::hypot(p[c.u] - c.cu, p[c.v] - c.cv);
    EXPECT_NEAR(radius, i + 1 == pts.size() ? c.r : rho, 1e-9);
    worst_out = std::max(worst_out, radius - c.r);
    // Closest point of the chord to the centre: its distance inside the circle.
    const double au = prev[c.u] - c.cu, av = prev[c.v] - c.cv, du = p[c.u] - prev[c.u], dv = p[c.v] - prev[c.v];
    const double t = std::clamp(-(au * du + av * dv) / (du * du + dv * dv), 0.0, 1.0);
    worst_in = std::max(worst_in, c.r - std::hypot(au + t * du, av + t * dv));
    double d = std::atan2(p[c.v] - c.cv, p[c.u] - c.cu) - std::atan2(prev[c.v] - c.cv, prev[c.u] - c.cu);
    while (d > std::numbers::pi) d -= 2 * std::numbers::pi;
    while (d < -std::numbers::pi) d += 2 * std::numbers::pi;
    swept += d;
    prev = p;
  }
  EXPECT_LE(worst_in, 0.001 + 1e-12);
  EXPECT_GT(worst_in, 0.0005);  // not needlessly fine
  EXPECT_LE(worst_out, 0.001);
  EXPECT_NEAR(swept, c.sweep, 1e-9);
}

constexpr double kPi = std::numbers::pi;
INSTANTIATE_TEST_SUITE_P(
    AllPlanes, GcodeArc,
    ::testing::Values(
        // G17 XY, IJK, quarter circle counter-clockwise.
        ArcCase{"G0 X10 Y0\nG3 X0 Y10 I-10 J0 F100\n", 2, 0, 0, 10, X, Y, Z, kPi / 2},
        // G17 clockwise.
        ArcCase{"G0 X10 Y0\nG2 X0 Y-10 I-10 J0 F100\n", 2, 0, 0, 10, X, Y, Z, -kPi / 2},
        // Absolute centres (G90.1).
        ArcCase{"G90.1\nG0 X10 Y0\nG3 X0 Y10 I0 J0 F100\n", 3, 0, 0, 10, X, Y, Z, kPi / 2},
        // R form, short arc: centre right of the chord for G2.
        ArcCase{"G1 X0 Y0 F100\nG2 X10 Y0 R10\n", 2, 5, -std::sqrt(75.0), 10, X, Y, Z, -kPi / 3},
        // R form, negative R: the long way round.
        ArcCase{"G1 X0 Y0 F100\nG2 X10 Y0 R-10\n", 2, 5, std::sqrt(75.0), 10, X, Y, Z, -5 * kPi / 3},
        // Full circle (IJK, end = start).
        ArcCase{"G0 X10 Y0\nG2 X10 Y0 I-10 J0 F100\n", 2, 0, 0, 10, X, Y, Z, -2 * kPi},
        // G18: plane Z X; G2 from X0 to X10 around X5 passes Z-5.
        ArcCase{"G18\nG0 X0 Z0\nG2 X10 Z0 I5 K0 F100\n", 3, 0, 5, 5, Z, X, Y, -kPi},
        // G19: plane Y Z; G3 from Y0 to Y10 around Y5.
        ArcCase{"G19\nG0 Y0 Z0\nG3 Y10 Z0 J5 K0 F100\n", 3, 5, 0, 5, Y, Z, X, kPi},
        // G18 in R form.
        ArcCase{"G18 G0 X0 Z0\nG3 X10 Z0 R5 F100\n", 2, 0, 5, 5, Z, X, Y, kPi}));

TEST(GcodeArcShape, G18ClockwiseGoesThroughNegativeZ) {
  const Toolpath tp = run("G18\nG0 X0 Z0\nG2 X10 Z0 I5 K0 F100\n");
  double zmin = 0;
  for (const Segment& s : tp.segments) zmin = std::min(zmin, s.end[Z]);
  EXPECT_NEAR(zmin, -5.0, 1e-3);
}

TEST(GcodeArcShape, HelixWithTurnsInterpolatesTheAxis) {
  const Toolpath tp = run("G0 X10 Y0 Z0\nG3 X10 Y0 Z-2 I-10 J0 P2 F100\n");
  const std::vector<AxisVector> pts = points_of_line(tp, 2);
  ASSERT_GT(pts.size(), 10u);
  // Z falls linearly with the angle: two turns, 2 mm.
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double k = static_cast<double>(i + 1) / static_cast<double>(pts.size());
    EXPECT_NEAR(pts[i][Z], -2.0 * k, 1e-9);
  }
  EXPECT_NEAR(poly_length({10, 0, 0, 0, 0, 0}, pts), std::hypot(4 * kPi * 10, 2.0), 0.01);
  expect_at(tp.segments.back(), 10, 0, -2);
}

TEST(GcodeArcShape, ModalArcAndFeed) {
  const Toolpath tp = run("G0 X10 Y0\nG3 X0 Y10 I-10 F100\nX-10 Y0 I0 J-10\n");
  expect_at(tp.segments.back(), -10, 0, 0);
  EXPECT_EQ(tp.segments.back().line, 3);
  EXPECT_DOUBLE_EQ(tp.segments.back().feed_mm_per_min, 100.0);
}

TEST(GcodeOffsets, G10L2AndWorkOffsetSelection) {
  const Toolpath tp = run("G10 L2 P2 X100 Y50\nG55 G0 X1 Y1\nG54 X1 Y1\nG10 L2 P1 Z-5\nG0 Z0\n");
  ASSERT_EQ(tp.segments.size(), 3u);
  expect_at(tp.segments[0], 101, 51, 0);
  expect_at(tp.segments[1], 1, 1, 0);
  // The Toolpath frame stays the G54 frame of program start: a changed G54 shows as an offset.
  expect_at(tp.segments[2], 1, 1, -5);
}

TEST(GcodeOffsets, G53MachineCoordinatesAndStart) {
  GcodeOptions o;
  o.work_offsets[0] = {-10, -20, -250, 0, 0, 0};  // G54 origin in machine coordinates
  const Toolpath tp = run("G0 X5 Y5 Z5\nG53 G0 X0 Y0\nG53 G1 Z-100 F500\n", o);
  expect_at(tp.start, 10, 20, 250);  // homed: gauge line at machine zero
  ASSERT_EQ(tp.segments.size(), 3u);
  expect_at(tp.segments[0], 5, 5, 5);
  expect_at(tp.segments[1], 10, 20, 5);
  expect_at(tp.segments[2], 10, 20, 150);
  EXPECT_EQ(error_of("G91 G53 G0 X0\n", o), "t.ngc:1: 'G53' needs absolute distance mode (G90)");
}

TEST(GcodeOffsets, G28WithIntermediatePointAndStoredHome) {
  GcodeOptions o;
  o.work_offsets[0] = {0, 0, -100, 0, 0, 0};
  const Toolpath tp = run("G0 X5 Y5 Z10\nG28 G91 Z0\nG90\nG28\nG0 X7 Y8 Z9\nG28.1\nG0 X0\nG28\n", o);
  ASSERT_EQ(tp.segments.size(), 7u);
  expect_at(tp.segments[1], 5, 5, 10);   // intermediate point (G91 Z0: where it is)
  expect_at(tp.segments[2], 5, 5, 100);  // only Z goes home
  expect_at(tp.segments[3], 0, 0, 100);  // G28 without axes: all axes home
  expect_at(tp.segments[6], 7, 8, 9);    // G28.1 stored (7, 8, 9)
}

TEST(GcodeTools, ToolChangeAndLengthCompensation) {
  GcodeOptions o;
  o.tool_lengths = {{1, 50.0}, {2, 80.0}};
  o.work_offsets[0] = {0, 0, -200, 0, 0, 0};
  const Toolpath tp = run("T1 M6\nG43 H1 G0 Z10\nG49 G0 Z10\nT2\nM6\nG43 G0 Z5\n", o);
  expect_at(tp.start, 0, 0, 200);
  EXPECT_EQ(tp.start_tool, 0);
  ASSERT_EQ(tp.segments.size(), 5u);
  EXPECT_EQ(tp.segments[0].kind, SegmentKind::ToolChange);
  EXPECT_EQ(tp.segments[0].tool, 1);
  expect_at(tp.segments[0], 0, 0, 150);  // same gauge line, tip 50 mm lower
  expect_at(tp.segments[1], 0, 0, 10);   // G43 H1: programmed Z is the tip
  expect_at(tp.segments[2], 0, 0, -40);  // G49: programmed Z is the gauge line
  EXPECT_EQ(tp.segments[3].kind, SegmentKind::ToolChange);
  EXPECT_EQ(tp.segments[3].tool, 2);
  EXPECT_EQ(tp.segments[3].line, 5);
  expect_at(tp.segments[3], 0, 0, -70);
  expect_at(tp.segments[4], 0, 0, 5);  // G43 without H: the loaded tool
  EXPECT_EQ(tp.segments[4].tool, 2);
}

TEST(GcodeCycles, G81WithG98RetractsToInitialZ) {
  const Toolpath tp = run("G0 X0 Y0 Z10\nG98 G81 X5 Y6 Z-3 R2 F100\nX8\nG80\n");
  const std::vector<std::tuple<SegmentKind, double, double, double>> want = {
      {SegmentKind::Rapid, 0, 0, 10},  {SegmentKind::Rapid, 5, 6, 10}, {SegmentKind::Rapid, 5, 6, 2},
      {SegmentKind::Feed, 5, 6, -3},   {SegmentKind::Rapid, 5, 6, 10}, {SegmentKind::Rapid, 8, 6, 10},
      {SegmentKind::Rapid, 8, 6, 2},   {SegmentKind::Feed, 8, 6, -3},  {SegmentKind::Rapid, 8, 6, 10}};
  ASSERT_EQ(tp.segments.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(tp.segments[i].kind, std::get<0>(want[i]));
    expect_at(tp.segments[i], std::get<1>(want[i]), std::get<2>(want[i]), std::get<3>(want[i]));
  }
  EXPECT_EQ(tp.segments[5].line, 3);
}

TEST(GcodeCycles, G83PecksAndG99RetractsToR) {
  const Toolpath tp = run("G0 X0 Y0 Z10\nG99 G83 X1 Y1 Z-7 R2 Q4 F100\n");
  const std::vector<std::tuple<SegmentKind, double>> want = {
      {SegmentKind::Rapid, 10}, {SegmentKind::Rapid, 10},  {SegmentKind::Rapid, 2},   {SegmentKind::Feed, -2},
      {SegmentKind::Rapid, 2},  {SegmentKind::Rapid, -1.746}, {SegmentKind::Feed, -6}, {SegmentKind::Rapid, 2},
      {SegmentKind::Rapid, -5.746}, {SegmentKind::Feed, -7}, {SegmentKind::Rapid, 2}};
  ASSERT_EQ(tp.segments.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(tp.segments[i].kind, std::get<0>(want[i]));
    EXPECT_NEAR(tp.segments[i].end[Z], std::get<1>(want[i]), kEps);
  }
}

TEST(GcodeCycles, G73ChipBreakAndG82Dwell) {
  const Toolpath tp = run("G0 X0 Y0 Z2\nG73 Z-5 R2 Q2 F100\nG80\nG82 X3 Z-1 R2 P0.5 F50\n");
  using K = SegmentKind;
  const std::vector<std::tuple<SegmentKind, double, double>> want = {
      {K::Rapid, 0, 2},     {K::Rapid, 0, 2}, {K::Feed, 0, 0},  {K::Rapid, 0, 0.254}, {K::Feed, 0, -2},
      {K::Rapid, 0, -1.746}, {K::Feed, 0, -4}, {K::Rapid, 0, -3.746}, {K::Feed, 0, -5}, {K::Rapid, 0, 2},
      {K::Rapid, 3, 2},     {K::Feed, 3, -1}, {K::Dwell, 3, -1}, {K::Rapid, 3, 2}};
  ASSERT_EQ(tp.segments.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(tp.segments[i].kind, std::get<0>(want[i]));
    EXPECT_NEAR(tp.segments[i].end[X], std::get<1>(want[i]), kEps);
    EXPECT_NEAR(tp.segments[i].end[Z], std::get<2>(want[i]), kEps);
  }
  EXPECT_DOUBLE_EQ(tp.segments[12].dwell_s, 0.5);
  EXPECT_EQ(tp.segments[12].line, 4);
}

TEST(GcodeCycles, IncrementalRepeatsWithL) {
  const Toolpath tp = run("G0 X0 Y0 Z5\nG91 G98 G81 X10 R-3 Z-5 L3 F100\n");
  // R = 5 - 3 = 2, bottom = 2 - 5 = -3; holes at X10, X20, X30.
  std::vector<double> bottoms;
  for (const Segment& s : tp.segments)
    if (s.kind == SegmentKind::Feed) {
      EXPECT_NEAR(s.end[Z], -3.0, kEps);
      bottoms.push_back(s.end[X]);
    }
  EXPECT_EQ(bottoms, (std::vector<double>{10, 20, 30}));
  expect_at(tp.segments.back(), 30, 0, 5);
}

TEST(GcodeMisc, DwellCommentsDelimitersLineNumbersAndProgramEnd) {
  const Toolpath tp = run("%\nN10 G0 X1 (comment) ; tail\n/G0 X2\nG4 P1.5\n( a whole-line comment )\nM30\nthis is not read\n%\n");
  ASSERT_EQ(tp.segments.size(), 3u);
  EXPECT_EQ(tp.segments[0].line, 2);
  EXPECT_EQ(tp.segments[1].line, 3);
  EXPECT_EQ(tp.segments[2].kind, SegmentKind::Dwell);
  EXPECT_DOUBLE_EQ(tp.segments[2].dwell_s, 1.5);
  const Toolpath tp2 = run("%\nG0 X1\n%\nG0 X2\n");
  EXPECT_EQ(tp2.segments.size(), 1u);  // the closing % ends the program
}

TEST(GcodeMisc, SpindleCoolantFeedModesAreAccepted) {
  const Toolpath tp = run("G17 G21 G40 G49 G80 G90 G94 G91.1 G64\nG61\nG61.1\nS12000 M3 M8\nM7\nM4\nM5 M9\nM0\nM1\n");
  EXPECT_TRUE(tp.segments.empty());
}

TEST(GcodeMachines, RotaryAxesCarried) {
  GcodeOptions o;
  o.machine = MachineKind::Mill5;
  const Toolpath tp = run("G0 A90 B10 C-5\nG91 G1 A10 F100\n", o);
  ASSERT_EQ(tp.segments.size(), 2u);
  EXPECT_DOUBLE_EQ(tp.segments[0].end[A], 90);
  EXPECT_DOUBLE_EQ(tp.segments[0].end[B], 10);
  EXPECT_DOUBLE_EQ(tp.segments[0].end[C], -5);
  EXPECT_DOUBLE_EQ(tp.segments[1].end[A], 100);
  EXPECT_EQ(error_of("G0 A1\n"), "t.ngc:1: word 'A1' needs an axis the machine lacks (machine kind mill3 has X Y Z)");
}

TEST(GcodeMachines, LatheDiameterMode) {
  GcodeOptions o;
  o.machine = MachineKind::Lathe;
  const Toolpath tp = run("G7 G0 X20 Z1\nG8 X20\nG7 G91 X-4\n", o);
  ASSERT_EQ(tp.segments.size(), 3u);
  expect_at(tp.segments[0], 10, 0, 1);
  expect_at(tp.segments[1], 20, 0, 1);
  expect_at(tp.segments[2], 18, 0, 1);
  EXPECT_EQ(error_of("G0 Y1\n", o), "t.ngc:1: word 'Y1' needs an axis the machine lacks (machine kind lathe has X Z)");
  EXPECT_EQ(error_of("G7\n"), "t.ngc:1: 'G7' (lathe diameter mode) needs machine kind lathe");
}

struct ErrorCase {
  const char* program;
  const char* message;
};
class GcodeErrors : public ::testing::TestWithParam<ErrorCase> {};
TEST_P(GcodeErrors, ExactMessage) { EXPECT_EQ(error_of(GetParam().program), GetParam().message); }

INSTANTIATE_TEST_SUITE_P(
    Messages, GcodeErrors,
    ::testing::Values(
        ErrorCase{"G41.1 D2\nG42.1 D2\n", "t.ngc:2: 'G42.1': cutter radius compensation is already on (G40 first)"},
        ErrorCase{"G0 X1\n\no100 sub\n", "t.ngc:3: 'o100 sub' is never closed"},
        ErrorCase{"#1 = [1 / 0]\n", "t.ngc:1: division by zero"},
        ErrorCase{"G0 X#<nope>\n", "t.ngc:1: named parameter '#<NOPE>' is not defined"},
        ErrorCase{"G0 X[1+2\n", "t.ngc:1: expected ']' to close the expression"},
        ErrorCase{"G92\n", "t.ngc:1: 'G92' needs at least one axis word"},
        ErrorCase{"G33 Z-1 K1\n", "t.ngc:1: 'G33' needs a spindle speed S > 0 (spindle-synchronised motion)"},
        ErrorCase{"M100\n", "t.ngc:1: unsupported word 'M100' (user-defined M-code: runs a program on the controller)"},
        ErrorCase{"G95 G1 X1 F0.1\n", "t.ngc:1: 'G1' in feed per revolution (G95) needs a spindle speed S > 0"},
        ErrorCase{"G0 X\x01\n", "t.ngc:1: word 'X' has no number"},
        ErrorCase{"G0 \x01X1\n", "t.ngc:1: unexpected character '\\x01'"},
        ErrorCase{"M98 P100\n", "t.ngc:1: unsupported word 'M98' (not supported by the built-in interpreter; use --interpreter rs274)"},
        ErrorCase{"G1 X1 F100 E5\n", "t.ngc:1: unused word 'E5' (no G-code in the block uses it)"},
        ErrorCase{"G1 X1 F100 D3\n", "t.ngc:1: unused word 'D3' (D is a tool number for G41/G42, a diameter for G41.1/G42.1, or the maximum speed for G96)"},
        ErrorCase{"G1 F100\nG42 D3 X1\n", "t.ngc:2: 'D3': tool 3 has no diameter in the tool table"},
        ErrorCase{"G1 X1 F100 U5\n", "t.ngc:1: unsupported word 'U5' (axes U, V, W are not supported)"},
        ErrorCase{"(comment\nG1 X1\n", "t.ngc:1: unclosed comment '('"},
        ErrorCase{"G0 X1..2\n", "t.ngc:1: unexpected character '.'"},
        ErrorCase{"G0 X\n", "t.ngc:1: word 'X' has no number"},
        ErrorCase{"G1 X1\n", "t.ngc:1: 'G1' needs a feed rate: no F word > 0 given yet"},
        ErrorCase{"X1\n", "t.ngc:1: axis word 'X1' given but no motion mode is in effect"},
        ErrorCase{"G0 G1 X1\n", "t.ngc:1: 'G0' and 'G1' are in the same modal group"},
        ErrorCase{"G0 X1 X2\n", "t.ngc:1: word 'X' given twice ('X1', 'X2')"},
        ErrorCase{"G0 X1 Q2\n", "t.ngc:1: unused word 'Q2' (no G-code in the block uses it)"},
        ErrorCase{"G1 F100\nG2 X1 Y1\n", "t.ngc:2: 'G2' needs R or a centre word I/J (plane XY)"},
        ErrorCase{"G1 F100\nG2 X1 Y1 R1 I1\n", "t.ngc:2: 'G2' with both R and a centre word (I/J)"},
        ErrorCase{"G0 X0 Y0\nG2 X10 Y0 I4 F100\n", "t.ngc:2: 'G2' end point is off the circle: start radius 4 mm, end radius 6 mm"},
        ErrorCase{"G1 F100\nG3 X10 R2\n", "t.ngc:2: 'G3' radius 'R2' is too small for an end point 10 mm away"},
        ErrorCase{"G1 F100\nG3 X0 Y0 R2\n", "t.ngc:2: 'G3' in R form cannot make a full circle (end point = start point)"},
        ErrorCase{"G81 X1 Z-1 F100\n", "t.ngc:1: canned cycle 'G81' needs R and Z"},
        ErrorCase{"G83 X1 Z-1 R1 F100\n", "t.ngc:1: 'G83' needs Q > 0 (peck depth)"},
        ErrorCase{"G0 Z0\nG81 X1 Z1 R-1 F100\n", "t.ngc:2: canned cycle 'G81': R (-1) is below Z (1)"},
        ErrorCase{"G18 G81 X1 Z-1 R1 F100\n", "t.ngc:1: canned cycle 'G81' needs R and Y"},
        ErrorCase{"G4\n", "t.ngc:1: 'G4' needs P (dwell time [s])"},
        ErrorCase{"G10 L1 P1 Z0\n", "t.ngc:1: 'G10' needs L2 or L20 (work offsets); 'L1' is not supported"},
        ErrorCase{"T1.5 M6\n", "t.ngc:1: 'T1.5': expected an integer in [0, 99999]"},
        ErrorCase{"G0 X1 $\n", "t.ngc:1: unexpected character '$'"},
        ErrorCase{"G28 G0 X1\n", "t.ngc:1: 'G0' and 'G28' both use the axis words"}));

TEST(GcodeErrors, OWordNamesTheWord) {
  EXPECT_EQ(error_of("O100 sub\n"), "t.ngc:1: 'o100 sub' is never closed");
  EXPECT_EQ(error_of("G0 X1\nO100\n"), "t.ngc:2: O-word 'O100' without a keyword (sub, call, if, while, do, repeat, ...); "
                                        "a Fanuc program number needs [nc] dialect = \"fanuc\" or --dialect fanuc");
}

TEST(GcodeErrors, ArcChordLimitIsAnErrorNotAHang) {
  GcodeOptions o;
  o.chord_tol_mm = 1e-6;
  EXPECT_EQ(error_of("G0 X100000\nG2 X100000 Y0 I-100000 P1000 F1\n", o),
            "t.ngc:2: arc of radius 100000 mm needs more than 1000000 chords at the chord tolerance 1e-06 mm");
}

// Metamorphic: the same program run in G55 shifted by (dx, dy, dz), or written incrementally,
// gives the same path shifted / the same path.
TEST(GcodeMetamorphic, WorkOffsetShiftsAndIncrementalFormAgree) {
  const std::string body =
      "G0 X10 Y0 Z5\nG1 Z-1 F300\nG3 X0 Y10 I-10 J0\nG2 X-10 Y0 R10\nG18 G2 X0 Z-1 I5 K0\nG17\n"
      "G98 G81 X20 Y20 Z-4 R2\nG80\nG0 Z10\n";
  const Toolpath base = run(body);
  const Toolpath shifted = run("G10 L2 P2 X7 Y-3 Z2\nG55\n" + body);
  ASSERT_EQ(base.segments.size(), shifted.segments.size());
  for (std::size_t i = 0; i < base.segments.size(); ++i) {
    SCOPED_TRACE(i);
    expect_at(shifted.segments[i], base.segments[i].end[X] + 7, base.segments[i].end[Y] - 3, base.segments[i].end[Z] + 2);
  }
  const Toolpath incremental =
      run("G91 G0 X10 Y0 Z5\nG1 Z-6 F300\nG3 X-10 Y10 I-10 J0\nG2 X-10 Y-10 R10\nG18 G2 X10 Z0 I5 K0\nG90 G17\n"
          "G98 G81 X20 Y20 Z-4 R2\nG80\nG0 Z10\n");
  ASSERT_EQ(base.segments.size(), incremental.segments.size());
  for (std::size_t i = 0; i < base.segments.size(); ++i) {
    SCOPED_TRACE(i);
    expect_at(incremental.segments[i], base.segments[i].end[X], base.segments[i].end[Y], base.segments[i].end[Z]);
  }
}

TEST(GcodeFile, BundledCamProgramInterprets) {
  GcodeOptions o;
  o.tool_lengths = {{1, 60}, {2, 50}, {3, 70}};
  o.work_offsets[0] = {0, 0, -250, 0, 0, 0};
  const Toolpath tp = load_gcode(program_file("cam-pocket.ngc"), o);
  int changes = 0;
  double zmin = 1e9;
  for (const Segment& s : tp.segments) {
    if (s.kind == SegmentKind::ToolChange) ++changes;
    if (s.tool != 0) zmin = std::min(zmin, s.end[Z]);
    EXPECT_GT(s.line, 0);
  }
  EXPECT_EQ(changes, 3);
  EXPECT_NEAR(zmin, -20.0, kEps);  // the G83 hole
  EXPECT_EQ(tp.segments.back().tool, 3);
  EXPECT_THROW((void)load_gcode("/nonexistent/x.ngc", o), ParseError);
}

// Seeded random mutations of valid programs: every run ends in a Toolpath or a ParseError
// naming a line of the input, never in another exception, a crash or a hang.
// LBR_FUZZ_SEED=<n> reproduces a run; the budget is a few seconds.
TEST(GcodeFuzz, SeededMutatorNeverCrashesOrHangs) {
  const std::vector<std::string> corpus = {
      "G0 X10 Y0\nG3 X0 Y10 I-10 J0 F100\nG2 X10 Y0 R10\n",
      "G0 X0 Y0 Z10\nG98 G81 X5 Y6 Z-3 R2 F100\nX8\nG83 X1 Y1 Z-7 R2 Q4\nG80\n",
      "G20 G91 G0 X1\nG1 Y1 F10\nG90 G18 G2 X0 Z0 I1 K0\nG19 G3 Y1 Z0 J1 K0\n",
      "G10 L2 P2 X100\nG55 G0 X1\nG28 G91 Z0\nG90 G53 G0 Z0\nT1 M6\nG43 H1 Z5\nG4 P0.1\nM30\n",
      "%\nN10 G0 X1 (c) ; t\nG93 G1 X2 F3\nG94 G1 X3 F100\nG3 X3 Y0 I1 J0 P3 Z-1\n%\n",
      read_text_file(program_file("cam-pocket.ngc")),
  };
  const char* env = std::getenv("LBR_FUZZ_SEED");
  const unsigned seed = env != nullptr ? static_cast<unsigned>(std::strtoul(env, nullptr, 10)) : 20261122u;
  std::mt19937 rng(seed);
  const std::string alphabet = "GMXYZABCIJKRPQLFSTNOHDE0123456789.-+ ()%;#[]/\n\t";
  GcodeOptions o;
  o.tool_lengths = {{1, 60}};
  o.chord_tol_mm = 0.01;  // keeps arcs cheap; the limit logic is the same
  const auto t0 = std::chrono::steady_clock::now();
  int runs = 0, parsed = 0;
  for (; runs < 20000; ++runs) {
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(3)) break;
    std::string s = corpus[rng() % corpus.size()];
    lbr::test::mutate(s, rng, alphabet);
    const long lines = 1 + std::count(s.begin(), s.end(), '\n');
    try {
      const Toolpath tp = interpret_gcode(s, "fuzz.ngc", o);
      ++parsed;
      for (const Segment& seg : tp.segments) {
        for (double v : seg.end) ASSERT_TRUE(std::isfinite(v)) << "seed " << seed << " run " << runs << ":\n" << s;
        ASSERT_GE(seg.line, 1);
        ASSERT_LE(seg.line, lines);
      }
    } catch (const ParseError& e) {
      ASSERT_GE(e.line(), 1) << e.what();
      ASSERT_LE(e.line(), lines) << e.what();
    }
  }
  std::printf("fuzz: seed %u, %d runs, %d interpreted, %d rejected\n", seed, runs, parsed, runs - parsed);
  EXPECT_GT(runs, 200);
  EXPECT_GT(parsed, 0);
  EXPECT_LT(parsed, runs);
}

}  // namespace
