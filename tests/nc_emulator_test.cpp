// The machine emulator: closed-form times, limits checked from the samples, samples on the
// programmed path, sample count x period = machining time, determinism, no allocation in next().
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include "nc/emulator.hpp"
#include "nc/gcode.hpp"
#include "alloc_counter.hpp"
#include "nc_test_util.hpp"


namespace {

using namespace lbr::nc;

Toolpath line_path(double length, double feed) {
  Toolpath tp;
  tp.source = "line";
  Segment s;
  s.kind = SegmentKind::Feed;
  s.end = {length, 0, 0, 0, 0, 0};
  s.feed_mm_per_min = feed;
  s.tool = 1;
  s.line = 1;
  tp.segments.push_back(s);
  return tp;
}

EmulatorLimits limits(double accel = 1000.0, double period_ms = 1.0) {
  EmulatorLimits l;
  l.rapid_mm_per_min = 12000;
  l.max_velocity = {12000, 12000, 6000, 3600, 3600, 3600};
  l.max_accel = {accel, accel, accel / 2, 720, 720, 720};
  l.sample_period_ms = period_ms;
  return l;
}

std::vector<Sample> all_samples(Emulator& em) {
  std::vector<Sample> v;
  Sample s;
  while (em.next(s)) v.push_back(s);
  return v;
}

TEST(Emulator, TrapezoidTimeMatchesClosedForm) {
  // 100 mm at 6000 mm/min = 100 mm/s with 1000 mm/s²: t = L/v + v/a = 1.1 s.
  Emulator em(line_path(100, 6000), limits());
  EXPECT_NEAR(em.total_time_s(), 1.1, 1e-12);
  const auto& p = em.plans().front();
  EXPECT_NEAR(p.v, 100.0, 1e-12);
  EXPECT_NEAR(p.t_acc_s, 0.1, 1e-12);
  // Short move never reaches the feed: triangular profile, t = 2 sqrt(L/a).
  EXPECT_NEAR(Emulator(line_path(5, 6000), limits()).total_time_s(), 2.0 * std::sqrt(5.0 / 1000.0), 1e-12);
  // Mid-point of the cruise phase: x(t) = v t - v²/(2a).
  AxisVector x;
  int tool = 0;
  em.state_at(0.6, x, tool);
  EXPECT_NEAR(x[X], 100 * 0.6 - 100.0 * 100.0 / 2000.0, 1e-9);
  EXPECT_EQ(tool, 1);
}

TEST(Emulator, AxisLimitsScaleThePathSpeed) {
  // Diagonal XZ move: Z is limited to 6000 mm/min and 500 mm/s².
  Toolpath tp = line_path(0, 1e5);
  tp.segments[0].end = {100, 0, 100, 0, 0, 0};
  Emulator em(tp, limits());
  const auto& p = em.plans().front();
  EXPECT_NEAR(p.v, 100.0 * std::sqrt(2.0), 1e-9);  // Z at 100 mm/s
  EXPECT_NEAR(p.a, 500.0 * std::sqrt(2.0), 1e-9);
  const double L = 100 * std::sqrt(2.0);
  EXPECT_NEAR(em.total_time_s(), L / p.v + p.v / p.a, 1e-12);
}

TEST(Emulator, RotaryOnlyMoveUsesDegreesPerMinute) {
  Toolpath tp = line_path(0, 3600);  // F3600 read as deg/min
  tp.segments[0].end = {0, 0, 0, 90, 0, 0};
  // A limits: 3600 deg/min = 60 deg/s, 720 deg/s²: t = 90/60 + 60/720.
  EXPECT_NEAR(emulated_time_s(tp, limits()), 1.5 + 60.0 / 720.0, 1e-12);
}

TEST(Emulator, DwellToolChangeAndRapidTimes) {
  Toolpath tp;
  Segment tc;
  tc.kind = SegmentKind::ToolChange;
  tc.tool = 2;
  tp.segments.push_back(tc);
  Segment d;
  d.kind = SegmentKind::Dwell;
  d.dwell_s = 1.5;
  d.tool = 2;
  tp.segments.push_back(d);
  Segment r;
  r.kind = SegmentKind::Rapid;
  r.end = {200, 0, 0, 0, 0, 0};
  r.tool = 2;
  tp.segments.push_back(r);
  EmulatorLimits l = limits();
  l.tool_change_s = 3.0;
  // Rapid: 200 mm at 200 mm/s, a = 1000: 1 + 0.2 s.
  EXPECT_NEAR(emulated_time_s(tp, l), 3.0 + 1.5 + 1.2, 1e-12);
}

TEST(Emulator, InvalidLimitsAndFeedsAreReported) {
  EmulatorLimits l = limits();
  l.sample_period_ms = 0;
  EXPECT_EQ(validate(l), "sample period must be > 0 ms");
  EXPECT_THROW(Emulator(line_path(1, 100), l), std::invalid_argument);
  try {
    Emulator bad(line_path(1, 0), limits());
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "line:1: feed segment without a positive feed rate");
  }
}

class EmulatorProgram : public ::testing::Test {
 protected:
  void SetUp() override {
    GcodeOptions o;
    o.tool_lengths = {{1, 60}, {2, 50}, {3, 70}};
    o.work_offsets[0] = {0, 0, -250, 0, 0, 0};
    o.chord_tol_mm = 0.01;
    path_ = load_gcode(lbr::test::program_file("cam-pocket.ngc"), o);
    lim_ = limits(2000.0, 2.0);
    lim_.tool_change_s = 2.0;
  }
  Toolpath path_;
  EmulatorLimits lim_;
};

TEST_F(EmulatorProgram, LimitsHoldInTheSamples) {
  Emulator em(path_, lim_);
  const std::vector<Sample> s = all_samples(em);
  ASSERT_GT(s.size(), 1000u);
  const double T = em.period_s();
  double vmax_seen = 0, amax_seen_z = 0;
  for (std::size_t k = 1; k < s.size(); ++k) {
    if (s[k].tool != s[k - 1].tool) continue;  // the tip jumps with the tool length
    for (int a = 0; a < kAxes; ++a) {
      const double v = std::abs(s[k].axes[a] - s[k - 1].axes[a]) / T * 60.0;  // [unit/min]
      ASSERT_LE(v, lim_.max_velocity[a] * (1 + 1e-9) + 1e-9) << "axis " << a << " sample " << k;
      if (a == X) vmax_seen = std::max(vmax_seen, v);
    }
    if (k + 1 < s.size() && s[k + 1].tool == s[k].tool) {
      for (int a = 0; a < kAxes; ++a) {
        const double acc = std::abs(s[k + 1].axes[a] - 2 * s[k].axes[a] + s[k - 1].axes[a]) / (T * T);
        ASSERT_LE(acc, lim_.max_accel[a] * (1 + 1e-6) + 1e-6) << "axis " << a << " sample " << k;
        if (a == Z) amax_seen_z = std::max(amax_seen_z, acc);
      }
    }
  }
  // The limits are reached, not just respected (the rapids and long passes are limited).
  EXPECT_GT(vmax_seen, 0.95 * lim_.max_velocity[X]);
  EXPECT_GT(amax_seen_z, 0.5 * lim_.max_accel[Z]);
}

// Every segment of `tp` under one path control.
Toolpath with_control(Toolpath tp, PathControl c, double p_mm = 0.0, double q_mm = 0.0) {
  for (Segment& s : tp.segments) s.path_control = c, s.blend_tol_mm = p_mm, s.naive_tol_mm = q_mm;
  return tp;
}

TEST_F(EmulatorProgram, ExactStopSamplesLieOnTheProgrammedPath) {
  path_ = with_control(path_, PathControl::ExactStop);
  Emulator em(path_, lim_);
  std::size_t seg = 0;
  AxisVector from = path_.start;
  Sample s;
  std::uint64_t n = 0;
  while (em.next(s)) {
    // Segments are visited in order: advance until the sample lies on the current one.
    while (seg < path_.segments.size() && lbr::test::axis_dist_to_segment(s.axes, from, path_.segments[seg].end) > 1e-9) {
      from = path_.segments[seg].end;
      ++seg;
    }
    ASSERT_LT(seg, path_.segments.size()) << "sample " << s.seq << " is off the path";
    ++n;
  }
  EXPECT_EQ(n, em.sample_count());
  EXPECT_EQ(s.axes, path_.segments.back().end);  // the last sample is the end of the program
}

TEST_F(EmulatorProgram, CountTimesPeriodIsMachiningTimeAndRunsAreIdentical) {
  Emulator em(path_, lim_);
  const std::vector<Sample> a = all_samples(em);
  const double T = em.period_s();
  const double span = static_cast<double>(a.size()) * T;
  EXPECT_GE(span, em.total_time_s() - 1e-9);
  EXPECT_LT(span, em.total_time_s() + T);
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].seq, k);
    ASSERT_DOUBLE_EQ(a[k].t_s, static_cast<double>(k + 1) * T);
  }
  // Deterministic: a second emulator and a reset give bit-identical samples.
  Emulator em2(path_, lim_);
  const std::vector<Sample> b = all_samples(em2);
  em.reset();
  const std::vector<Sample> c = all_samples(em);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].axes, b[k].axes);
    ASSERT_EQ(a[k].axes, c[k].axes);
    ASSERT_EQ(a[k].tool, b[k].tool);
  }
}

TEST_F(EmulatorProgram, BlendedSamplesStayWithinTheTolerance) {
  // G64 P0.01 on the whole program: no sample is further than 0.01 mm from the programmed
  // polyline (blend arcs deviate at most P at the corner, lines lie on the path).
  path_ = with_control(path_, PathControl::Blend, 0.01);
  Emulator em(path_, lim_);
  ASSERT_GT(em.arcs().size(), 500u);
  std::size_t seg = 0;
  AxisVector from = path_.start;
  Sample s;
  double worst = 0.0;
  while (em.next(s)) {
    // The nearest of the current segment and the next few (a blend spans two segments).
    double best = 1e300;
    std::size_t at = seg;
    AxisVector f = from;
    for (std::size_t k = seg; k < std::min(seg + 4, path_.segments.size()); ++k) {
      const double d = lbr::test::axis_dist_to_segment(s.axes, f, path_.segments[k].end);
      if (d < best - 1e-12) best = d, at = k;
      f = path_.segments[k].end;
    }
    for (; seg < at; ++seg) from = path_.segments[seg].end;
    worst = std::max(worst, best);
  }
  EXPECT_LE(worst, 0.01 + 1e-9);
  EXPECT_GT(worst, 0.005);  // the tolerance is used, not just respected
}

TEST_F(EmulatorProgram, NextAndStateAtDoNotAllocate) {
  // The bundled program runs blended (G64 at start): lines and blend arcs.
  Emulator em(path_, lim_);
  ASSERT_GT(em.arcs().size(), 100u);
  Sample s;
  std::uint64_t n = 0;
  AxisVector x{};
  int tool = 0;
  const long before = lbr::test::allocations();
  while (em.next(s)) ++n;
  em.reset();
  while (em.next(s)) em.state_at(s.t_s * 0.5, x, tool);
  const long after = lbr::test::allocations();
  EXPECT_EQ(after, before);
  EXPECT_EQ(n, em.sample_count());
}

TEST_F(EmulatorProgram, SampledToolpathFollowsTheSamples) {
  const Toolpath sp = sampled_toolpath(path_, lim_);
  Emulator em(path_, lim_);
  int changes = 0;
  for (const Segment& seg : sp.segments) {
    EXPECT_FALSE(seg.has_tool_axis);
    if (seg.kind == SegmentKind::ToolChange) ++changes;
    else ASSERT_EQ(seg.kind, SegmentKind::Feed);
  }
  EXPECT_EQ(changes, 3);
  EXPECT_EQ(sp.segments.back().end, path_.segments.back().end);
  EXPECT_LE(sp.segments.size(), em.sample_count());
  EXPECT_GT(sp.segments.size(), em.sample_count() / 2);  // few standing samples in this program
}

// --- planner: analytic cases (docs/nc-frontend.md#planner) ---

// A polyline through `pts` at `feed`, every segment under `c`.
Toolpath polyline(const std::vector<AxisVector>& pts, double feed, PathControl c, double p_mm = 0.0, double q_mm = 0.0) {
  Toolpath tp;
  tp.source = "poly";
  tp.start = pts.front();
  for (std::size_t k = 1; k < pts.size(); ++k) {
    Segment s;
    s.kind = SegmentKind::Feed;
    s.end = pts[k];
    s.feed_mm_per_min = feed;
    s.line = static_cast<int>(k);
    tp.segments.push_back(s);
  }
  return with_control(tp, c, p_mm, q_mm);
}

std::vector<AxisVector> split_line(double length, double step) {
  std::vector<AxisVector> pts;
  const int n = static_cast<int>(std::lround(length / step));
  for (int k = 0; k <= n; ++k) pts.push_back({length * k / n, 0, 0, 0, 0, 0});
  return pts;
}

TEST(Planner, CollinearBlocksRunAtTheProgrammedFeed) {
  // 100 mm in 400 blocks of 0.25 mm at F1500 (25 mm/s), a = 1000 mm/s²: one trapezoid,
  // t = L/F + F/a = 4.025 s, under G64 and G61 (collinear junctions keep the speed).
  const double want = 100.0 / 25.0 + 25.0 / 1000.0;
  for (PathControl c : {PathControl::Blend, PathControl::ExactPath}) {
    const double t = emulated_time_s(polyline(split_line(100, 0.25), 1500, c), limits());
    EXPECT_NEAR(t, want, 0.01 * want);
    EXPECT_NEAR(t, want, 1e-9);
  }
  // G61.1 stops after every block: 0.25 mm < v²/a = 0.625 mm, so each block is a triangle
  // 2 sqrt(L/a) that never reaches the feed (3.2x slower).
  const double tri = 2.0 * std::sqrt(0.25 / 1000.0);
  EXPECT_NEAR(emulated_time_s(polyline(split_line(100, 0.25), 1500, PathControl::ExactStop), limits()), 400 * tri, 1e-9);
}

TEST(Planner, PolygonalCircleRunsAtTheCentripetalSpeed) {
  // r = 10 mm in 720 chords at F12000: the blend arcs (radius r cos(pi/720)) allow
  // v = sqrt(a_n r) with a_n = sqrt(0.75) a (the rest of a is left to the tangential ramp).
  const double r = 10.0;
  const int n = 720;
  std::vector<AxisVector> pts;
  for (int k = 0; k <= 2 * n; ++k) {  // two turns: the second one runs at the steady speed
    const double th = 2.0 * M_PI * k / n;
    pts.push_back({r * std::cos(th), r * std::sin(th), 0, 0, 0, 0});
  }
  Emulator em(polyline(pts, 12000, PathControl::Blend), limits());
  const double want = std::sqrt(std::sqrt(0.75) * 1000.0 * r);  // 93.06 mm/s
  AxisVector p0{}, p1{};
  int tool = 0;
  const double T = em.total_time_s();
  for (double t = 0.4 * T; t < 0.6 * T; t += 0.01) {
    em.state_at(t, p0, tool);
    em.state_at(t + 1e-4, p1, tool);
    const double v = std::hypot(p1[X] - p0[X], p1[Y] - p0[Y]) / 1e-4;
    ASSERT_NEAR(v, want, 0.01 * want) << "t = " << t;
    ASSERT_NEAR(std::hypot(p0[X], p0[Y]), r, 0.001);  // on the circle within its chord sag
  }
}

TEST(Planner, ExactStopAtEveryCornerUnderG61) {
  // Square 50 mm at F1500: four trapezoids, each 50/25 + 25/1000 s; zero speed at the corners.
  const std::vector<AxisVector> sq = {{0, 0, 0, 0, 0, 0}, {50, 0, 0, 0, 0, 0}, {50, 50, 0, 0, 0, 0}, {0, 50, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}};
  for (PathControl c : {PathControl::ExactPath, PathControl::ExactStop}) {
    Emulator em(polyline(sq, 1500, c), limits());
    EXPECT_NEAR(em.total_time_s(), 4 * (2.0 + 0.025), 1e-9);
    for (const auto& p : em.plans()) {
      EXPECT_EQ(p.kind, Emulator::PieceKind::Line);
      EXPECT_EQ(p.v_in, 0.0);
      EXPECT_EQ(p.v_out, 0.0);
    }
    EXPECT_TRUE(em.arcs().empty());
  }
}

TEST(Planner, CornerUnderG64StaysWithinP) {
  // 90° corner at (50, 0) under G64 P0.05: the closest sample comes within the tolerance of
  // the corner but never further than 0.05 mm from the programmed path.
  const std::vector<AxisVector> pts = {{0, 0, 0, 0, 0, 0}, {50, 0, 0, 0, 0, 0}, {50, 50, 0, 0, 0, 0}};
  Emulator em(polyline(pts, 6000, PathControl::Blend, 0.05), limits());
  ASSERT_EQ(em.arcs().size(), 1u);
  // Blend radius: P / (1/cos(45°) - 1); trim R tan(45°) = R.
  const double radius = 0.05 / (std::sqrt(2.0) - 1.0);
  EXPECT_NEAR(em.arcs()[0].radius, radius, 1e-12);
  Sample s;
  double closest = 1e9, worst = 0.0;
  while (em.next(s)) {
    closest = std::min(closest, std::hypot(s.axes[X] - 50, s.axes[Y]));
    worst = std::max(worst, std::min(lbr::test::axis_dist_to_segment(s.axes, pts[0], pts[1]),
                                     lbr::test::axis_dist_to_segment(s.axes, pts[1], pts[2])));
  }
  // P bounds the distance from the programmed corner (as LinuxCNC's G64 P); from the lines
  // the arc's middle is R (1 - cos 45°) = 0.035 mm away.
  EXPECT_GE(closest, 0.05 - 1e-12);
  EXPECT_LT(closest, 0.0505);  // a 1 ms sample lands near the arc's middle
  EXPECT_LE(worst, 0.05);
  EXPECT_NEAR(worst, radius * (1.0 - std::sqrt(0.5)), 0.005);  // less off the middle
  // Faster than exact stop: the corner is passed at sqrt(a_n R), not at rest.
  const double v_corner = std::sqrt(std::sqrt(0.75) * 1000.0 * radius);
  EXPECT_NEAR(em.plans()[1].v, v_corner, 1e-9);
  EXPECT_LT(em.total_time_s(), emulated_time_s(polyline(pts, 6000, PathControl::ExactPath), limits()));
}

TEST(Planner, NaiveCamToleranceMergesNearlyCollinearBlocks) {
  // A zig-zag of ±0.004 mm around the X axis in 0.25 mm blocks: under G64 Q0.01 one straight
  // move (trapezoid time), without Q a chain of tiny blends (slower).
  std::vector<AxisVector> pts = split_line(50, 0.25);
  for (std::size_t k = 1; k + 1 < pts.size(); ++k) pts[k][Y] = (k % 2 ? 0.004 : -0.004);
  const double straight = 50.0 / 25.0 + 25.0 / 1000.0;
  Emulator merged(polyline(pts, 1500, PathControl::Blend, 0.01, 0.01), limits());
  EXPECT_NEAR(merged.total_time_s(), straight, 1e-9);
  EXPECT_EQ(merged.plans().size(), 1u);
  EXPECT_GT(emulated_time_s(polyline(pts, 1500, PathControl::Blend, 0.01, 0.0), limits()), straight);
}

TEST(Planner, BlendsStopForToolChangesAndDwells) {
  Toolpath tp = polyline({{0, 0, 0, 0, 0, 0}, {10, 0, 0, 0, 0, 0}, {10, 10, 0, 0, 0, 0}}, 6000, PathControl::Blend);
  Segment d;
  d.kind = SegmentKind::Dwell;
  d.end = tp.segments[0].end;
  d.dwell_s = 0.5;
  tp.segments.insert(tp.segments.begin() + 1, d);
  Emulator em(tp, limits());
  EXPECT_TRUE(em.arcs().empty());
  // Two 10 mm trapezoids at 100 mm/s and 1000 mm/s² (10 mm = v²/a: just reaches the feed).
  EXPECT_NEAR(em.total_time_s(), 2 * (0.1 + 0.1) + 0.5, 1e-9);
}

}  // namespace
