// geom/probe.hpp on the gfx tests' pocketed box (40 x 30 x 10 mm, top at z = 0, a pocket
// 3 mm deep whose straight walls lie at x = 9 / 31 and y = 6 / 24): rays and columns give
// the part's known faces, walls and thicknesses.
#include <gtest/gtest.h>

#include "geom/probe.hpp"
#include "gfx_test_util.hpp"

namespace lbr {
namespace {

using namespace test;
using namespace test::gfx_scene;

geom::LbrSolid pocketed() {
  geom::LbrSolid s = stock();
  const geom::CutterShape t6 = flat6();
  const auto path = pocket_path();
  for (std::size_t i = 1; i < path.size(); ++i)
    cut(s, t6, {path[i - 1], {0, 0, 1}}, {path[i], {0, 0, 1}}, static_cast<geom::MoveId>(i));
  return s;
}

const geom::LbrSolid& part() {
  static const geom::LbrSolid s = pocketed();
  return s;
}

TEST(Probe, AVerticalRayStopsOnThePocketFloorAndOnTheTopFace) {
  const geom::RayHit floor = geom::cast_ray(part(), {20, 15, 50}, {0, 0, -1});
  ASSERT_TRUE(floor.hit);
  EXPECT_TRUE(floor.top_face);
  EXPECT_DOUBLE_EQ(floor.point.z, kFloorZ);
  EXPECT_DOUBLE_EQ(floor.t, 50 - kFloorZ);
  const geom::RayHit top = geom::cast_ray(part(), {5, 5, 50}, {0, 0, -2});
  ASSERT_TRUE(top.hit);
  EXPECT_TRUE(top.top_face);
  EXPECT_DOUBLE_EQ(top.point.z, 0.0);
  EXPECT_DOUBLE_EQ(top.t, 25.0);  // dir is not unit length
}

TEST(Probe, AHorizontalRayStopsOnThePocketWallAndOnTheStockSide) {
  const geom::RayHit wall = geom::cast_ray(part(), {15, 15, -1.6}, {1, 0, 0});
  ASSERT_TRUE(wall.hit);
  EXPECT_FALSE(wall.top_face);
  EXPECT_NEAR(wall.point.x, kPx1 + kToolR, 0.005);  // the tool circle's polygon: chord 2 µm
  EXPECT_DOUBLE_EQ(wall.point.z, -1.6);
  const geom::RayHit side = geom::cast_ray(part(), {-5, 15, -6}, {1, 0, 0});
  ASSERT_TRUE(side.hit);
  EXPECT_NEAR(side.point.x, 0.0, 1e-9);
  EXPECT_FALSE(geom::cast_ray(part(), {-5, 15, 1}, {1, 0, 0}).hit);   // above the stock
  EXPECT_FALSE(geom::cast_ray(part(), {15, 15, -1.6}, {1, 0, 0}, 0, 15).hit);  // stops short of the wall
}

TEST(Probe, ARangeStartingInsideTheMaterialAtASlabBoundaryIsAVerticalFace) {
  // A section plane at x = 20 cuts the ray at (20, 2, -5): a slab boundary (Δ = 0.25).
  const geom::RayHit h = geom::cast_ray(part(), {30, 2, 5}, {-1, 0, -1}, 10, 100);
  ASSERT_TRUE(h.hit);
  EXPECT_DOUBLE_EQ(h.t, 10);
  EXPECT_NEAR(h.point.z, -5, 1e-12);
  EXPECT_FALSE(h.top_face);
}

TEST(Probe, ASlantedRayPassesOverThePocketRimToTheFloor) {
  // From above the corner (x, y) = (50, -15): it enters the stock's top inside the pocket.
  const geom::RayHit h = geom::cast_ray(part(), {50, -15, 27}, {-1, 1, -1});
  ASSERT_TRUE(h.hit);
  EXPECT_TRUE(h.top_face);
  EXPECT_NEAR(h.point.x, 20, 1e-9);
  EXPECT_NEAR(h.point.y, 15, 1e-9);
  EXPECT_DOUBLE_EQ(h.point.z, kFloorZ);
}

TEST(Probe, AColumnSumsTheMaterialBelowAHeight) {
  const geom::Column in = geom::column_at(part(), 20, 15);
  EXPECT_TRUE(in.material);
  EXPECT_DOUBLE_EQ(in.top_mm, kFloorZ);
  EXPECT_NEAR(in.thickness_mm, 10 + kFloorZ, 1e-9);
  EXPECT_NEAR(geom::column_at(part(), 20, 15, -5).thickness_mm, 5.0, 1e-9);
  const geom::Column out = geom::column_at(part(), 5, 5);
  EXPECT_DOUBLE_EQ(out.top_mm, 0.0);
  EXPECT_NEAR(out.thickness_mm, 10.0, 1e-9);
  EXPECT_FALSE(geom::column_at(part(), 45, 5).material);  // beside the stock
  EXPECT_TRUE(geom::material_at(part(), part().level_at(-1), 5, 5));
  EXPECT_FALSE(geom::material_at(part(), part().level_at(-1), 20, 15));
}

}  // namespace
}  // namespace lbr
