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
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "nc/rs274.hpp"
#include "nc_test_util.hpp"

namespace {

using namespace lbr::nc;

using lbr::test::error_of;
using lbr::test::run;

// Rapid/feed end points (dwells and tool changes left out).
std::vector<AxisVector> ends(const Toolpath& tp) {
  std::vector<AxisVector> v;
  for (const Segment& s : tp.segments)
    if (s.kind == SegmentKind::Rapid || s.kind == SegmentKind::Feed) v.push_back(s.end);
  return v;
}

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

}  // namespace
