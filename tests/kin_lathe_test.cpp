// Lathe cutting (issue 7): turning inserts revolved about the spindle axis (geom::LatheSweep)
// remove annuli and discs level by level. Closed-form volumes and per-level radii.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "test_util.hpp"

using namespace lbr;

namespace {

constexpr double kTol = 0.001;

// Ø40 bar on the spindle axis, z in [z0, 0].
geom::SolidSpec bar(double z0 = -60.0, double delta = 0.1) {
  geom::SolidSpec s;
  s.shape = geom::SolidSpec::Shape::Cylinder;
  s.cylinder = {0.0, 0.0, 40.0, z0, 0.0};
  s.level_spacing_mm = delta;
  s.regions_x = 2;
  s.regions_y = 2;
  s.chord_tol_mm = kTol;
  return s;
}

geom::TurningTool insert(geom::InsertKind k, double nose, double approach = 95.0, bool internal = false) {
  geom::TurningTool t;
  t.insert = k;
  t.nose_radius_mm = nose;
  t.approach_deg = approach;
  t.internal = internal;
  return t;
}

// Reference point path in the (r, z) plane.
void turn(geom::LbrSolid& s, const geom::TurningShape& sh, const std::vector<std::pair<double, double>>& rz) {
  std::vector<geom::SweepRef> refs;
  for (std::size_t i = 1; i < rz.size(); ++i) {
    geom::SweepRef r;
    r.turning = &sh;
    r.from.tip = {rz[i - 1].first, 0, rz[i - 1].second};
    r.to.tip = {rz[i].first, 0, rz[i].second};
    r.id = static_cast<geom::MoveId>(i);
    refs.push_back(r);
  }
  s.subtract(refs);
}

// Radius of the disc left on a level, from its area.
double level_radius(const geom::LbrSolid& s, int l) { return std::sqrt(s.level_area_mm2(l) / test::kPi); }

}  // namespace

TEST(TurningShape, ReferencePointIsTheImaginaryTip) {
  for (auto k : {geom::InsertKind::Diamond80, geom::InsertKind::Diamond55, geom::InsertKind::V35}) {
    const auto sh = geom::TurningShape::build(insert(k, 0.8, 93.0), kTol);
    double rmin = 1e9, zmin = 1e9;
    for (const auto& p : sh.pts) rmin = std::min(rmin, p.r), zmin = std::min(zmin, p.z);
    EXPECT_NEAR(rmin, 0.0, 1e-12);
    EXPECT_NEAR(zmin, 0.0, 1e-12);
    // Convex and counter-clockwise.
    const std::size_t n = sh.pts.size();
    for (std::size_t i = 0; i < n; ++i) {
      const auto& a = sh.pts[i];
      const auto& b = sh.pts[(i + 1) % n];
      const auto& c = sh.pts[(i + 2) % n];
      EXPECT_GE((b.r - a.r) * (c.z - b.z) - (b.z - a.z) * (c.r - b.r), -1e-12) << to_string(k) << " vertex " << i;
    }
  }
  geom::TurningTool bad = insert(geom::InsertKind::Diamond55, 0.4, 130.0);
  EXPECT_NE(bad.validate(), "");
}

TEST(Lathe, TurningDiameter40To30Over50mm) {
  geom::LbrSolid s(bar());
  const auto sh = geom::TurningShape::build(insert(geom::InsertKind::Diamond80, 0.4), kTol);
  turn(s, sh, {{25, 2}, {15, 2}, {15, -50}, {25, -50}});
  const double closed = test::kPi * (20.0 * 20.0 - 15.0 * 15.0) * 50.0;
  // The nose radius leaves a fillet ring: the spandrel (1 - π/4)·rε², centroid
  // (10 - 3π)/(12 - 3π)·rε off the corner, revolved (Pappus).
  const double re = 0.4;
  const double fillet = 2.0 * test::kPi * (15.0 + (10.0 - 3.0 * test::kPi) / (12.0 - 3.0 * test::kPi) * re) *
                        (1.0 - test::kPi / 4.0) * re * re;
  const double removed = test::removed(s);
  EXPECT_NEAR(removed, closed - fillet, 2 * 2 * test::kPi * 35 * kTol * 50 + 0.5);
  EXPECT_NEAR(removed, closed, 0.0005 * closed);  // the figure, within 0.05 %
  for (int l = 0; l < s.levels(); ++l) {
    const double z = s.level_z_mm(l);
    if (z > -49.5) {
      EXPECT_NEAR(level_radius(s, l), 15.0, 0.002) << "z " << z;
    } else if (z < -50.0) {
      EXPECT_NEAR(level_radius(s, l), 20.0, 0.002) << "z " << z;
    }
  }
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Lathe, FacingRemovesWholeDiscs) {
  geom::LbrSolid s(bar(-30.0));
  const auto sh = geom::TurningShape::build(insert(geom::InsertKind::Diamond80, 0.8), kTol);
  // Face 0.5 mm off the end, past the centre by more than the nose radius (X-2 in
  // diameter): stopping at X0 would leave a pip of the nose radius on the axis.
  turn(s, sh, {{22, 3}, {22, -0.5}, {-1.0, -0.5}, {-1.0, 3}});
  EXPECT_NEAR(test::removed(s), test::kPi * 400.0 * 0.5, 2 * 2 * test::kPi * 20 * kTol * 0.5 + 1e-6);
  EXPECT_NEAR(s.bounds().hi.z, -0.5, 1e-9);
  EXPECT_NEAR(level_radius(s, s.level_at(-0.55)), 20.0, 0.002);
}

TEST(Lathe, GrooveOfKnownWidthAndDepth) {
  geom::LbrSolid s(bar());
  geom::TurningTool g;
  g.insert = geom::InsertKind::Groove;
  g.width_mm = 3.0;
  g.nose_radius_mm = 0.0;
  g.edge_length_mm = 12.0;
  const auto sh = geom::TurningShape::build(g, kTol);
  turn(s, sh, {{21, -20}, {15, -20}, {21, -20}});  // plunge to Ø30 at Z-20, width 3
  const double v = test::kPi * (400.0 - 225.0) * 3.0;
  EXPECT_NEAR(test::removed(s), v, 2 * 2 * test::kPi * 35 * kTol * 3.0);
  int grooved = 0;
  for (int l = 0; l < s.levels(); ++l) {
    const double z = s.level_z_mm(l), r = level_radius(s, l);
    if (z > -20.0 && z < -17.0) {
      EXPECT_NEAR(r, 15.0, 0.002) << z;
      ++grooved;
    } else {
      EXPECT_NEAR(r, 20.0, 0.002) << z;
    }
  }
  EXPECT_EQ(grooved, 30);  // 3 mm / Δ
}

TEST(Lathe, BoringAHole) {
  geom::LbrSolid s(bar(-40.0));
  // 90° approach, sharp nose: flat bottom.
  const auto sh = geom::TurningShape::build(insert(geom::InsertKind::Diamond80, 0.0, 90.0, true), kTol);
  turn(s, sh, {{5, 2}, {10, 2}, {10, -30}, {5, -30}, {5, 2}});
  EXPECT_NEAR(test::removed(s), test::kPi * 100.0 * 30.0, 2 * 2 * test::kPi * 10 * kTol * 30.0);
  for (int l = 0; l < s.levels(); ++l) {
    const double z = s.level_z_mm(l);
    const double expect = z > -30.0 ? test::kPi * (400.0 - 100.0) : test::kPi * 400.0;
    EXPECT_NEAR(s.level_area_mm2(l), expect, 4 * test::kPi * 30 * kTol) << z;
  }
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Lathe, MultiStepShaftMatchesItsDrawingAtEveryLevel) {
  geom::LbrSolid s(bar(-60.0));
  const double re = 0.4;
  const auto sh = geom::TurningShape::build(insert(geom::InsertKind::Diamond55, re, 93.0), kTol);
  // Drawing: Ø24 on [-15, 0], Ø30 on [-30, -15], Ø36 on [-45, -30], Ø40 stock below.
  turn(s, sh, {{14, 2}, {12, 2}, {12, -15}, {15, -15}, {15, -30}, {18, -30}, {18, -45}, {21, -45}, {25, -45}, {25, 3}});
  struct Step {
    double z_lo, z_hi, r;
  };
  const Step steps[] = {{-15, 0, 12}, {-30, -15, 15}, {-45, -30, 18}};
  auto drawing = [&](double z) {
    for (const Step& st : steps) {
      if (z >= st.z_lo && z <= st.z_hi) {
        // Nose radius fillet in the inner corner at z_lo.
        const double dz = st.z_lo + re - z;
        if (dz > 0.0) return st.r + re - std::sqrt(re * re - dz * dz);
        return st.r;
      }
    }
    return 20.0;
  };
  for (int l = 0; l < s.levels(); ++l) {
    const double z = s.level_z_mm(l);
    EXPECT_NEAR(level_radius(s, l), drawing(z), 0.003) << "z " << z;
  }
  EXPECT_EQ(s.check_invariants(), "");
}
