// The batch plan's merge of tilted runs (geom/src/batch_plan.cpp, merge_collinear): a run's
// poses may stray from the merged sweep by the chord tolerance measured on the part of the
// tool that comes below the solid's top, which nothing above can cut.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "subtract_engine.hpp"
#include "test_util.hpp"

namespace {

using namespace lbr;
using geom::ToolKind;

constexpr double kTol = 0.01;  // chord tolerance [mm], the bundled milling profiles'

// A ball Ø6 (flutes 30) along X in 0.5 mm moves, its tip on a gentle arc and its axis
// tilting about X by up to 15°, as finish5x's ball pass does.
std::vector<geom::SweepRef> tilting_run(const geom::CutterShape& c, int moves) {
  auto pose = [](int i) {
    const double x = 0.5 * i, a = 15.0 * std::sin(x / 12.0) * test::kPi / 180.0;
    return test::at(x, 0, -2.0 - 0.002 * (x - 10.0) * (x - 10.0), {0, -std::sin(a), std::cos(a)});
  };
  std::vector<geom::SweepRef> run;
  for (int i = 0; i < moves; ++i) run.push_back({&c, pose(i), pose(i + 1), static_cast<geom::MoveId>(i + 1)});
  return run;
}

// The farthest point from the tip of the tool's cutting part that lies at or below z_top at
// pose p, by sampling the part's surface (independent of the code's closed bound).
double sampled_reach_below(const geom::CutterShape& c, const geom::Pose& p, double z_top) {
  const geom::Vec3 a = (1.0 / geom::norm(p.axis)) * p.axis;
  const geom::Vec3 e1 = geom::norm(geom::Vec3{a.y, -a.x, 0}) > 1e-9 ? geom::Vec3{a.y, -a.x, 0} : geom::Vec3{1, 0, 0};
  const geom::Vec3 u = (1.0 / geom::norm(e1)) * e1;
  const geom::Vec3 v{a.y * u.z - a.z * u.y, a.z * u.x - a.x * u.z, a.x * u.y - a.y * u.x};
  double best = 0.0;
  for (int i = 0; i <= 600; ++i) {
    const double h = c.height() * i / 600.0, r = c.radius_at(h);
    for (int k = 0; k < 72; ++k) {
      const double t = 2.0 * test::kPi * k / 72.0;
      const geom::Vec3 q = p.tip + h * a + (r * std::cos(t)) * u + (r * std::sin(t)) * v;
      if (q.z <= z_top) best = std::max(best, geom::norm(q - p.tip));
    }
  }
  return best;
}

TEST(BatchPlan, TiltedRunsMergeByThePartOfTheToolBelowTheTop) {
  // With the whole tool's reach (30 mm) the axis may turn only by about tol/2 / 30 mm
  // between a merged sweep and its poses; with the solid's top 2–3 mm above the tip, by
  // ten times that. Every pose of a merged run stays within tol/2 of the merged sweep by
  // the reach sampled on the tool's surface below the top.
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const auto run = tilting_run(c, 80);
  std::vector<geom::SweepRef> whole, below;
  geom::detail::merge_collinear(run, whole);
  const double z_top = 0.0;
  geom::detail::merge_collinear(run, below, z_top);
  std::printf("%zu moves: %zu merged sweeps with the whole tool, %zu with its part below the top\n", run.size(),
              whole.size(), below.size());
  EXPECT_LT(2 * below.size(), whole.size());
  std::size_t k = 0;
  for (const geom::SweepRef& m : below) {
    ASSERT_LT(k, run.size());
    ASSERT_TRUE(m.from.tip == run[k].from.tip);
    for (; k < run.size() && !(run[k].to.tip == m.to.tip); ++k) {
      const double reach = sampled_reach_below(c, run[k].to, z_top);
      EXPECT_LE(geom::pose_deviation_mm(m.from, m.to, run[k].to, reach), 0.5 * kTol) << "pose " << k;
    }
    ++k;
  }
  EXPECT_EQ(k, run.size());
}

TEST(BatchPlan, MergedTiltedRunRemovesWhatItsMovesRemove) {
  // The same run cut in one batch (merged) and move by move (nothing to merge): the removed
  // volumes differ by no more than the tolerance over the cut's surface (about 40 × 7 mm²).
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const auto run = tilting_run(c, 80);
  geom::LbrSolid merged(test::box_spec({-5, -10, -8}, {45, 10, 0}, 0.1));
  merged.subtract(run);
  geom::LbrSolid single(test::box_spec({-5, -10, -8}, {45, 10, 0}, 0.1));
  for (const geom::SweepRef& s : run) single.subtract(std::vector<geom::SweepRef>{s});
  std::printf("removed %.4f mm3 merged, %.4f move by move\n", test::removed(merged), test::removed(single));
  EXPECT_GT(test::removed(single), 300.0);
  EXPECT_NEAR(test::removed(merged), test::removed(single), 40.0 * 7.0 * kTol);
  EXPECT_EQ(merged.check_invariants(), "");
}

}  // namespace
