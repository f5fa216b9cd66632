// The live motion stream's merged runs (motion::SampleStream) and the pose test they rest on
// (geom::pose_deviation_mm): merged sweeps keep every sample's tool within the tolerance,
// also while a rotary axis turns, and a 5-axis stream merges where its motion is near linear.
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "app/profile.hpp"
#include "geom/types.hpp"
#include "kin/kinematics.hpp"
#include "motion/sample_stream.hpp"
#include "motion/tool_table.hpp"

namespace {

using namespace lbr;

geom::Vec3 tilted(double rad) { return {0.0, -std::sin(rad), std::cos(rad)}; }  // +Z turned about X

TEST(PoseDeviation, TipOffsetAloneIsTheDistanceFromTheSegment) {
  const geom::Pose a{{0, 0, 0}}, b{{10, 0, 0}};
  EXPECT_DOUBLE_EQ(geom::pose_deviation_mm(a, b, {{5, 0.3, 0}}, 20.0), 0.3);
  EXPECT_DOUBLE_EQ(geom::pose_deviation_mm(a, b, {{12, 0, 0.4}}, 20.0), std::hypot(2.0, 0.4));  // past the end
}

TEST(PoseDeviation, AxisTurnCountsWithTheReach) {
  const geom::Pose a{{0, 0, 0}, tilted(0.0)}, b{{10, 0, 0}, tilted(0.2)};
  // On the sweep: the middle pose with the interpolated axis.
  EXPECT_NEAR(geom::pose_deviation_mm(a, b, {{5, 0, 0}, tilted(0.1)}, 20.0), 0.0, 1e-12);
  // Same tip, axis 0.01 rad off the interpolated one: reach × angle.
  EXPECT_NEAR(geom::pose_deviation_mm(a, b, {{5, 0, 0}, tilted(0.11)}, 20.0), 20.0 * 0.01, 1e-9);
  // Both: the sum.
  EXPECT_NEAR(geom::pose_deviation_mm(a, b, {{5, 0.05, 0}, tilted(0.09)}, 20.0), 0.05 + 0.2, 1e-9);
  // A pure turn about a fixed tip is measured against the start pose.
  const geom::Pose c{{1, 1, 1}, tilted(0.0)};
  EXPECT_NEAR(geom::pose_deviation_mm(c, {{1, 1, 1}, tilted(0.3)}, {{1, 1, 1}, tilted(0.02)}, 10.0), 0.2, 1e-9);
}

class Capture final : public motion::SweepSink {
 public:
  void on_sweep(const geom::SweepRef& s) noexcept override { sweeps.push_back(s); }
  void on_batch_full(std::span<const geom::SweepRef>) noexcept override {}
  std::vector<geom::SweepRef> sweeps;
};

struct Mill5Stream {
  app::Profile profile = app::default_profile();
  motion::ToolTable tools{profile.tooling, profile.solid.chord_tol_mm, profile.source};
  std::array<kin::Kinematics, motion::kMaxChannels> kins{};
  Capture sink;
  std::vector<geom::Pose> poses;  // every sample's tool pose
  Mill5Stream() {
    tools.build_all();
    kins[0].kind = nc::MachineKind::Mill5;
    kins[0].rotary = kin::Rotary::TableAC;
    kins[0].tcp = true;
  }
  // Feeds n samples q(i) through a stream of tolerance tol; returns the sweeps it made.
  template <class Q>
  std::size_t run(double tol, int n, Q q) {
    motion::SampleStream s(tools, kins, 1, tol, 4096, sink);
    const motion::ToolRef t = tools.find(1);
    for (int i = 0; i < n; ++i) {
      const nc::AxisVector v = q(i);
      poses.push_back(kin::tool_pose(kins[0], v, t.mount, t.length_mm));
      s.take(0, static_cast<std::uint64_t>(i + 1), 1, std::span<const double>(v.data(), v.size()), 0x3F);
    }
    s.flush_all();
    return sink.sweeps.size();
  }
  // The largest distance of a sample's tool from the sweeps (each sample from the nearest).
  double worst(double reach) const {
    double w = 0.0;
    for (const geom::Pose& p : poses) {
      double best = INFINITY;
      for (const geom::SweepRef& s : sink.sweeps) best = std::min(best, geom::pose_deviation_mm(s.from, s.to, p, reach));
      w = std::max(w, best);
    }
    return w;
  }
};

TEST(SampleStream, FiveAxisSamplesMergeWhileEveryToolStaysWithinTheTolerance) {
  // A tilting pass sampled finely: 0.01 mm of X and 0.002 degrees of A per sample, tip
  // programmed (TCP): the tip runs straight and the tool axis turns at a constant rate.
  Mill5Stream m;
  const double reach = m.tools.find(1).reach_mm;
  ASSERT_GT(reach, 10.0);
  const std::size_t sweeps = m.run(0.001, 2000, [](int i) {
    return nc::AxisVector{0.01 * i, 0.0, -2.0, 0.002 * i, 0.0, 0.0};
  });
  // One sweep per sample before (the axis changed at every sample).
  EXPECT_LT(sweeps, 2000u / 5) << sweeps << " sweeps for 2000 samples";
  EXPECT_GE(sweeps, 2000u / motion::SampleStream::kMaxRun);
  EXPECT_LE(m.worst(reach), 0.001 + 1e-12);
}

TEST(SampleStream, AnAxisThatTurnsAlongACurveBreaksTheRunsWhereItLeavesTheTolerance) {
  // The tilt follows a parabola in the sample index: far from linear over a long run.
  Mill5Stream m;
  const double reach = m.tools.find(1).reach_mm;
  const std::size_t sweeps = m.run(0.001, 2000, [](int i) {
    const double u = 0.001 * i;
    return nc::AxisVector{0.01 * i, 0.0, -2.0, 30.0 * u * u, 0.0, 0.0};
  });
  EXPECT_LE(m.worst(reach), 0.001 + 1e-12);
  EXPECT_GT(sweeps, 2000u / motion::SampleStream::kMaxRun);  // the curvature cuts the runs short
  EXPECT_LT(sweeps, 2000u);
}

TEST(SampleStream, AFixedAxisStraightRunIsOneSweep) {
  Mill5Stream m;
  const std::size_t sweeps = m.run(0.001, 200, [](int i) { return nc::AxisVector{0.01 * i, 0.02 * i, -2.0, 5.0, 0.0, 0.0}; });
  EXPECT_EQ(sweeps, 1u);
}

}  // namespace
