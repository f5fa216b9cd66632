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

TEST_F(EmulatorProgram, SamplesLieOnTheProgrammedPath) {
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

TEST_F(EmulatorProgram, NextDoesNotAllocate) {
  Emulator em(path_, lim_);
  Sample s;
  std::uint64_t n = 0;
  const long before = lbr::test::allocations();
  while (em.next(s)) ++n;
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

}  // namespace
