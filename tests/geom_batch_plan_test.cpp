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

// The fraction along sweep s at which pose p lies on it (tip and axis as geom::Sweep moves
// them), or a negative value when it does not lie on s.
double fraction_on(const geom::SweepRef& s, const geom::Pose& p) {
  const geom::Vec3 d = s.to.tip - s.from.tip;
  const double f = geom::dot(p.tip - s.from.tip, d) / geom::dot(d, d);
  if (f < -1e-12 || f > 1.0 + 1e-12) return -1.0;
  const geom::Vec3 ax = geom::lerp(s.from.axis, s.to.axis, f);
  const bool on = geom::norm(p.tip - geom::lerp(s.from.tip, s.to.tip, f)) < 1e-9 &&
                  geom::norm(p.axis - (1.0 / geom::norm(ax)) * ax) < 1e-9;
  return on ? f : -1.0;
}

TEST(BatchPlan, TiltedRunsMergeByThePartOfTheToolBelowTheTop) {
  // With the whole tool's reach (30 mm) the axis may turn only by about tol/2 / 30 mm
  // between a merged sweep and its poses; with the solid's top 2–3 mm above the tip, by
  // ten times that. Every pose of a merged run stays within tol/2 of the merged sweep by
  // the reach sampled on the tool's surface below the top. A run ends where the tolerance
  // ends it, inside a move: its end lies on that move, and the next run starts there.
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const auto run = tilting_run(c, 80);
  std::vector<geom::SweepRef> whole, below;
  geom::detail::merge_collinear(run, whole);
  const double z_top = 0.0;
  geom::detail::merge_collinear(run, below, z_top);
  std::printf("%zu moves: %zu merged sweeps with the whole tool, %zu with its part below the top\n", run.size(),
              whole.size(), below.size());
  EXPECT_LT(below.size(), whole.size());
  EXPECT_LE(4 * below.size(), run.size());
  ASSERT_FALSE(below.empty());
  EXPECT_TRUE(below.front().from.tip == run.front().from.tip);
  EXPECT_TRUE(below.back().to.tip == run.back().to.tip);
  std::size_t k = 0;  // the move that holds the merged sweep's start
  std::size_t splits = 0;
  for (std::size_t m = 0; m < below.size(); ++m) {
    const geom::SweepRef& s = below[m];
    if (m > 0) {
      EXPECT_TRUE(s.from.tip == below[m - 1].to.tip && s.from.axis == below[m - 1].to.axis) << m;
    }
    // The poses inside: the ends of the moves from k on before the one that holds s's end.
    while (k < run.size() && !(fraction_on(run[k], s.to) > 0.0)) {
      const double reach = sampled_reach_below(c, run[k].to, z_top);
      EXPECT_LE(geom::pose_deviation_mm(s.from, s.to, run[k].to, reach), 0.5 * kTol) << "pose " << k;
      ++k;
    }
    ASSERT_LT(k, run.size()) << "merged sweep " << m << " ends on no move";
    const double f = fraction_on(run[k], s.to);
    if (f < 1.0 - 1e-12) ++splits;  // ends inside move k, which the next sweep goes on with
    else ++k;
  }
  EXPECT_EQ(k, run.size());
  EXPECT_GT(splits, 0u);
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
