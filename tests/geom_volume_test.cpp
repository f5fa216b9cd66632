// Analytic volumes. Each case compares the LBR volume with two references:
//  - the ideal LBR volume Σ A(z_mid)·thickness from the exact section area A(z): the
//    kernel must match it within the chord tolerance (|ΔA| <= 2·perimeter·tol per level,
//    one tol for the polygonised circles and one for the linearised tool profile);
//  - the exact solid volume: the gap is the level discretisation, bounded per case.
#include <functional>

#include <gtest/gtest.h>

#include "test_util.hpp"

using namespace lbr;
using geom::ToolKind;

namespace {

constexpr double kTol = 0.001;

struct Ideal {
  double volume = 0;  // Σ A(z_mid) · thickness
  double bound = 0;   // Σ 2 · P(z_mid) · tol · thickness
};

// area_perimeter(z) returns {A, P} of the exact section at height z.
Ideal ideal(const geom::LbrSolid& s, const std::function<std::pair<double, double>(double)>& area_perimeter) {
  Ideal r;
  for (int l = 0; l < s.levels(); ++l) {
    const auto [a, p] = area_perimeter(s.level_z_mm(l));
    r.volume += a * s.level_thickness_mm(l);
    r.bound += 2.0 * p * kTol * s.level_thickness_mm(l);
  }
  r.bound += 1e-6;
  return r;
}

}  // namespace

TEST(Volume, FlatSlotIsStadiumTimesDepth) {
  geom::LbrSolid s(test::box_spec({0, 0, -20}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  test::cut(s, c, test::at(10, 20, -5), test::at(50, 20, -5));
  const double area = 2 * 5.0 * 40.0 + test::kPi * 25.0, perim = 80.0 + 10.0 * test::kPi;
  // Tip at -5 lies on a slab boundary: exactly 50 levels are cut.
  EXPECT_NEAR(test::removed(s), area * 5.0, 2 * perim * kTol * 5.0);
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Volume, RectangularPocketWithRoundedCorners) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 6), kTol);
  // Pocket 30 x 20 (x 15..45, y 10..30), depth 4: tool centre inside [18, 42] x [13, 27],
  // zig-zag at 2.5 mm stepover, then the finishing loop.
  std::vector<geom::Vec3> p{{18, 13, 5}, {18, 13, -4}};
  test::append_pocket_path(p);
  test::cut_path(s, c, p, 8);
  EXPECT_NEAR(test::removed(s), test::kPocketVolume, 2 * 100.0 * kTol * 4.0);
  EXPECT_EQ(s.check_invariants(), "");
}

namespace {
double ball_groove(double delta, Ideal* id = nullptr) {
  // Ball Ø6 along X for 40 mm with its centre on the top face (groove depth = R = 3).
  geom::LbrSolid s(test::box_spec({0, 0, -6}, {60, 40, 0}, delta, 4, 2));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  test::cut(s, c, test::at(10, 20, -3), test::at(50, 20, -3));
  if (id != nullptr) {
    *id = ideal(s, [](double z) -> std::pair<double, double> {
      if (z <= -3.0 || z >= 0.0) return {0.0, 0.0};
      const double rho = std::sqrt(9.0 - z * z);
      return {2 * rho * 40.0 + test::kPi * rho * rho, 80.0 + 2 * test::kPi * rho};
    });
  }
  return test::removed(s);
}
const double kBallGrooveExact = test::kPi * 9.0 / 2.0 * 40.0 + 2.0 / 3.0 * test::kPi * 27.0;
}  // namespace

TEST(Volume, BallGrooveMatchesIdealLevelsAndExactVolume) {
  Ideal id;
  const double v = ball_groove(0.1, &id);
  EXPECT_NEAR(v, id.volume, id.bound);
  // Mid-plane sampling of a sqrt-shaped profile: within 0.5 % at Δ = 0.1 mm.
  EXPECT_NEAR(v, kBallGrooveExact, 0.005 * kBallGrooveExact);
}

TEST(Volume, BallGrooveErrorShrinksWithLevelSpacing) {
  double previous = INFINITY;
  for (double delta : {0.6, 0.3, 0.15, 0.075}) {
    const double err = std::abs(ball_groove(delta) - kBallGrooveExact);
    EXPECT_LT(err, previous) << "Δ = " << delta;
    previous = err;
  }
}

TEST(Volume, DrilledHoleWithConeTip) {
  geom::LbrSolid s(test::box_spec({0, 0, -20}, {40, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Drill, 8, 118), kTol);
  test::cut(s, c, test::at(20, 20, 5), test::at(20, 20, -10));
  const double t = std::tan(59.0 * test::kPi / 180.0), hc = 4.0 / t;
  const Ideal id = ideal(s, [&](double z) -> std::pair<double, double> {
    const double h = z + 10.0;
    if (h <= 0.0 || z >= 0.0) return {0.0, 0.0};
    const double r = std::min(4.0, h * t);
    return {test::kPi * r * r, 2 * test::kPi * r};
  });
  const double v = test::removed(s);
  EXPECT_NEAR(v, id.volume, id.bound);
  const double exact = test::kPi * 16.0 * (10.0 - hc) + test::kPi * 16.0 * hc / 3.0;
  EXPECT_NEAR(v, exact, 0.002 * exact);
}

TEST(Volume, VGroove) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::VBit, 12, 90, 10), kTol);
  test::cut(s, c, test::at(10, 20, -2), test::at(50, 20, -2));
  const Ideal id = ideal(s, [](double z) -> std::pair<double, double> {
    const double h = z + 2.0;
    if (h <= 0.0 || z >= 0.0) return {0.0, 0.0};
    return {2 * h * 40.0 + test::kPi * h * h, 80.0 + 2 * test::kPi * h};
  });
  const double v = test::removed(s);
  EXPECT_NEAR(v, id.volume, id.bound);
  // Triangle d² along 40 mm plus two half cones of radius and height d = 2.
  const double exact = 4.0 * 40.0 + test::kPi * 8.0 / 3.0;
  EXPECT_NEAR(v, exact, 0.003 * exact);
}

TEST(Volume, BullNoseSlot) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Bull, 12, 2), kTol);
  test::cut(s, c, test::at(15, 20, -4), test::at(45, 20, -4));
  const Ideal id = ideal(s, [](double z) -> std::pair<double, double> {
    const double h = z + 4.0;
    if (h <= 0.0 || z >= 0.0) return {0.0, 0.0};
    const double r = h >= 2.0 ? 6.0 : 4.0 + std::sqrt(4.0 - (2.0 - h) * (2.0 - h));
    return {2 * r * 30.0 + test::kPi * r * r, 60.0 + 2 * test::kPi * r};
  });
  EXPECT_NEAR(test::removed(s), id.volume, id.bound);
}

TEST(Volume, TiltedFlatPlungeLeavesTheEllipticalFootprint) {
  const double th = 30.0 * test::kPi / 180.0;
  const geom::Vec3 ax{std::sin(th), 0, std::cos(th)};
  geom::LbrSolid s(test::box_spec({0, 0, -20}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  test::cut(s, c, test::at(30, 20, -6, ax), test::at(30, 20, -6, ax));
  // Above the tilted bottom face (z > -6 + 5 sin 30° = -3.5) every level holds the full
  // ellipse of area πR²/cos θ.
  const double ellipse = test::kPi * 25.0 / std::cos(th);
  const double full = 60.0 * 40.0;
  int checked = 0;
  for (int l = 0; l < s.levels(); ++l) {
    const double z = s.level_z_mm(l);
    if (z <= -3.45) continue;
    EXPECT_NEAR(full - s.level_area_mm2(l), ellipse, 2 * 2 * test::kPi * 5.8 * kTol) << "z " << z;
    ++checked;
  }
  EXPECT_EQ(checked, 35);
  // A cylinder between two planes that each cut it in a full ellipse holds πR² times the
  // axial distance between the planes' crossings with the axis: D / cos θ.
  const double exact = test::kPi * 25.0 * 6.0 / std::cos(th);
  EXPECT_NEAR(test::removed(s), exact, 0.002 * exact);
}

TEST(Volume, SampledTiltingPassMergesIntoTheSweepItSamples) {
  // A ball pass whose tool axis tilts from +Z to 20 degrees about X, sampled as 400 short
  // sweeps on the pose path of the single sweep from start to end: the batch merges them
  // (merge_collinear's tilted runs, at most 64 sweeps each) and removes what the single
  // sweep removes. Before, each sampled sweep was sectioned on its own (400x the sections).
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const double th = 20.0 * test::kPi / 180.0;
  const geom::Pose a = test::at(10, 20, -3), b = test::at(50, 20, -3, {0, -std::sin(th), std::cos(th)});
  geom::LbrSolid one(test::box_spec({0, 0, -20}, {60, 40, 0}, 0.1));
  const geom::SubtractStats single = test::cut(one, c, a, b);
  std::vector<geom::SweepRef> fine;
  geom::Pose from = a;
  for (int k = 1; k <= 400; ++k) {
    const double t = k / 400.0;
    const geom::Vec3 m = geom::lerp(a.axis, b.axis, t);
    const geom::Pose to = k == 400 ? b : geom::Pose{geom::lerp(a.tip, b.tip, t), (1.0 / geom::norm(m)) * m};
    fine.push_back({&c, from, to, static_cast<geom::MoveId>(k)});
    from = to;
  }
  geom::LbrSolid sampled(test::box_spec({0, 0, -20}, {60, 40, 0}, 0.1));
  const geom::SubtractStats st = sampled.subtract(fine);
  EXPECT_LE(st.sections, 8 * single.sections) << st.sections << " sections against " << single.sections;
  EXPECT_NEAR(test::removed(sampled), test::removed(one), 1e-4 * test::removed(one));
  EXPECT_GT(test::removed(one), 500.0);
  EXPECT_EQ(sampled.check_invariants(), "");
}
