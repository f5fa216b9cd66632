// Tool profiles: exact radii and the piecewise-linear shape within the chord tolerance.
#include <gtest/gtest.h>

#include "test_util.hpp"

using namespace lbr;
using geom::ToolKind;

TEST(Tool, ExactProfiles) {
  EXPECT_DOUBLE_EQ(test::tool(ToolKind::Flat, 10).radius_at(0.0), 5.0);
  EXPECT_DOUBLE_EQ(test::tool(ToolKind::Flat, 10).radius_at(31.0), 0.0);  // above the flutes
  const geom::Tool ball = test::tool(ToolKind::Ball, 6);
  EXPECT_DOUBLE_EQ(ball.radius_at(0.0), 0.0);
  EXPECT_NEAR(ball.radius_at(1.0), std::sqrt(9.0 - 4.0), 1e-12);
  EXPECT_DOUBLE_EQ(ball.radius_at(3.0), 3.0);
  const geom::Tool bull = test::tool(ToolKind::Bull, 12, 2);
  EXPECT_DOUBLE_EQ(bull.radius_at(0.0), 4.0);
  EXPECT_NEAR(bull.radius_at(1.0), 4.0 + std::sqrt(3.0), 1e-12);
  const geom::Tool drill = test::tool(ToolKind::Drill, 8, 118);
  EXPECT_NEAR(drill.full_radius_height(), 4.0 / std::tan(59.0 * test::kPi / 180.0), 1e-12);
  EXPECT_NEAR(drill.radius_at(1.0), std::tan(59.0 * test::kPi / 180.0), 1e-12);
  const geom::Tool v = test::tool(ToolKind::VBit, 12, 90);
  EXPECT_NEAR(v.radius_at(2.0), 2.0, 1e-12);
  EXPECT_NEAR(v.radius_at(7.0), 6.0, 1e-12);
}

TEST(Tool, ValidationNamesTheProblem) {
  EXPECT_EQ(test::tool(ToolKind::Flat, 10).validate(), "");
  EXPECT_NE(test::tool(ToolKind::Flat, -1).validate().find("diameter_mm must be > 0"), std::string::npos);
  EXPECT_NE(test::tool(ToolKind::Bull, 10, 6).validate().find("corner_radius_mm must be in (0, diameter/2 = 5]"),
            std::string::npos);
  EXPECT_NE(test::tool(ToolKind::VBit, 10, 180).validate().find("included angle must be in (0, 180)"), std::string::npos);
}

class ShapeTolerance : public ::testing::TestWithParam<std::tuple<ToolKind, double, double>> {};

TEST_P(ShapeTolerance, LinearProfileWithinChordToleranceOnBothSides) {
  const auto [kind, d, param] = GetParam();
  for (double tol : {0.001, 0.01}) {
    const geom::Tool t = test::tool(kind, d, param, 20.0);
    const geom::CutterShape s = geom::CutterShape::build(t, tol);
    ASSERT_GE(s.stations.size(), 2u);
    EXPECT_DOUBLE_EQ(s.stations.front().h, 0.0);
    EXPECT_DOUBLE_EQ(s.height(), 20.0);
    // Signed distance of the linear profile from the exact one, measured normal to the exact
    // profile (positive inside): on the corner arc it is the gap to the arc's circle,
    // elsewhere the profile is straight and must match exactly.
    const double R = 0.5 * d;
    const double rc = kind == ToolKind::Ball ? R : (kind == ToolKind::Bull ? param : 0.0);
    double inside = 0.0, outside = 0.0;
    for (int i = 0; i <= 20000; ++i) {
      const double h = 20.0 * i / 20000.0;
      const double exact = t.radius_at(h), lin = s.radius_at(h);
      EXPECT_LE(lin, R + 1e-12) << "h " << h;  // never wider than the tool
      const double gap = (rc > 0.0 && h < rc) ? rc - std::hypot(lin - (R - rc), h - rc) : exact - lin;
      inside = std::max(inside, gap);
      outside = std::max(outside, -gap);
    }
    EXPECT_LE(inside, tol * 1.0001 + 1e-12) << geom::to_string(kind) << " tol " << tol;
    EXPECT_LE(outside, tol * 1.0001 + 1e-12) << geom::to_string(kind) << " tol " << tol;
    if (rc > 0.0) {  // the corner arc's polyline lies on both sides of the arc
      EXPECT_GT(inside, 0.1 * tol) << geom::to_string(kind) << " tol " << tol;
      EXPECT_GT(outside, 0.1 * tol) << geom::to_string(kind) << " tol " << tol;
    }
  }
}

// The corner arc's polyline keeps the arc's mean support (Sweep::circle_grow_width()): the
// mean over the arc's directions of the polyline's support minus the arc's is zero to within
// a small fraction of the tolerance, so a ball end removes neither more nor less on average.
TEST(Tool, CornerPolylineHasNoSupportBias) {
  for (double tol : {0.001, 0.01}) {
    const geom::Tool t = test::tool(ToolKind::Ball, 6.0, 0.0, 20.0);
    const geom::CutterShape s = geom::CutterShape::build(t, tol);
    const double rc = 3.0;
    double sum = 0.0;
    const int m = 100000;
    for (int i = 0; i < m; ++i) {
      const double a = 0.5 * test::kPi * (i + 0.5) / m;  // direction (sin a, -cos a) in (r, h)
      double best = -INFINITY;  // support of the stations about the corner centre (0, rc)
      for (const auto& st : s.stations) best = std::max(best, st.r * std::sin(a) - (st.h - rc) * std::cos(a));
      sum += best - rc;
    }
    EXPECT_NEAR(sum / m, 0.0, 0.05 * tol) << "tol " << tol;
  }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, ShapeTolerance,
                         ::testing::Values(std::make_tuple(ToolKind::Flat, 10.0, 0.0), std::make_tuple(ToolKind::Ball, 6.0, 0.0),
                                           std::make_tuple(ToolKind::Bull, 12.0, 2.0),
                                           std::make_tuple(ToolKind::Drill, 8.0, 118.0),
                                           std::make_tuple(ToolKind::VBit, 12.0, 90.0)));
