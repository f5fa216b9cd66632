// The material masks that let tilted pieces in air go unbuilt (geom/src/material_mask.hpp):
// a clear pixel holds no material (checked against the exact intersection of random convex
// polygons with a cell's polygons), the mask is tight (a polygon whose neighbourhood of 1.5
// pixels holds no material is cleared), and a tilted pass cut over a pocket leaves the same
// solid as the pass cut first and the pocket after.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "material_mask.hpp"
#include "test_util.hpp"

using namespace lbr;
using geom::SectionPoint;

namespace {

// Area [mm²] of the intersection of convex polygon `poly` [mm], grown by `grow_mm` (0: as it
// is), with the level's material.
double overlap_mm2(const geom::LbrSolid& s, int level, const std::vector<SectionPoint>& poly, double grow_mm) {
  ClipperLib::Path p;
  for (const SectionPoint& q : poly)
    p.push_back({static_cast<ClipperLib::cInt>(std::llround(q.x * geom::kUnitsPerMm)),
                 static_cast<ClipperLib::cInt>(std::llround(q.y * geom::kUnitsPerMm))});
  ClipperLib::Paths clip{p};
  if (grow_mm > 0.0) {
    ClipperLib::ClipperOffset co;
    co.AddPath(p, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
    co.Execute(clip, grow_mm * geom::kUnitsPerMm);
  }
  ClipperLib::Clipper c;
  for (int r = 0; r < s.regions(); ++r) {
    geom::Paths flat;
    geom::flatten(s.cell(r, level), flat);
    c.AddPaths(flat, ClipperLib::ptSubject, true);
  }
  c.AddPaths(clip, ClipperLib::ptClip, true);
  ClipperLib::Paths out;
  c.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftEvenOdd, ClipperLib::pftNonZero);
  double a = 0.0;
  for (const auto& q : out) a += ClipperLib::Area(q);
  return a / (geom::kUnitsPerMm * geom::kUnitsPerMm);
}

// The region borders of solid `s` along one axis, from its region rectangles.
std::vector<geom::Coord> borders(const geom::LbrSolid& s, bool x) {
  std::vector<geom::Coord> b;
  const int n = x ? s.regions_x() : s.regions_y();
  for (int i = 0; i < n; ++i) {
    const geom::Rect r = s.region_rect(x ? i : i * s.regions_x());
    b.push_back(x ? r.x0 : r.y0);
    if (i == n - 1) b.push_back(x ? r.x1 : r.y1);
  }
  return b;
}

// A random convex polygon: a regular k-gon of radius r about (cx, cy), turned by a random angle.
std::vector<SectionPoint> random_polygon(std::mt19937& rng, double x0, double x1, double y0, double y1) {
  std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1), ur(0.02, 3.0), ua(0.0, 2.0 * test::kPi);
  std::uniform_int_distribution<int> uk(3, 8);
  const double cx = ux(rng), cy = uy(rng), r = ur(rng), a0 = ua(rng);
  const int k = uk(rng);
  std::vector<SectionPoint> p;
  for (int i = 0; i < k; ++i) {
    const double a = a0 + 2.0 * test::kPi * i / k;
    p.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
  }
  return p;
}

TEST(CellMask, ClearPixelsHoldNoMaterialAndPolygonsAwayFromItAreCleared) {
  // A 40 x 30 stock on a 2 x 2 grid, with a pocket and a slot cut into it: cells with holes,
  // cells cut in two, and an empty one.
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {40, 30, 0}, 0.5, 2, 2));
  const auto flat = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 6), 0.01);
  std::vector<geom::Vec3> path;
  test::append_pocket_path(path);  // x 15..45 clipped by the stock, y 10..30
  test::cut_path(s, flat, path);
  test::cut(s, flat, test::at(2, 5, -8), test::at(25, 5, -8));
  const int level = s.level_at(-3.0);
  std::vector<geom::detail::CellMask> masks(s.cell_count());
  std::vector<std::pair<int, double>> crossings;
  const auto xs = borders(s, true), ys = borders(s, false);
  const geom::detail::LevelMaterial m(s, level, xs, ys, masks, crossings);
  // A region is 20 x 15 mm: 64 x 60 pixels (at most kMaxSide a row), 0.3125 x 0.25 mm.
  const double pixel = 20.0 / geom::detail::CellMask::kMaxSide;
  std::mt19937 rng(7);
  int meeting = 0, cleared = 0, away = 0;
  for (int i = 0; i < 4000; ++i) {
    const auto p = random_polygon(rng, -2.0, 42.0, -2.0, 32.0);
    const bool meets = m.may_meet(p);
    if (overlap_mm2(s, level, p, 0.0) > 1e-8) {
      ++meeting;
      EXPECT_TRUE(meets) << "polygon " << i << " meets material but was cleared";
    }
    if (overlap_mm2(s, level, p, 1.5 * pixel) == 0.0) {
      ++away;
      EXPECT_FALSE(meets) << "polygon " << i << " lies 1.5 pixels from any material but was not cleared";
    }
    if (!meets) ++cleared;
  }
  std::printf("%d polygons meet material, %d lie 1.5 pixels away from it, %d cleared\n", meeting, away, cleared);
  EXPECT_GT(meeting, 1000);
  EXPECT_GT(away, 300);
  // A changed cell's mask is rebuilt: after the level is cut away everywhere, nothing meets.
  test::cut_path(s, geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 20), 0.01),
                 {{-10, -5, -6}, {50, -5, -6}, {50, 8, -6}, {-10, 8, -6}, {-10, 21, -6}, {50, 21, -6}, {50, 34, -6}, {-10, 34, -6}});
  EXPECT_DOUBLE_EQ(s.level_area_mm2(level), 0.0);
  const geom::detail::LevelMaterial after(s, level, xs, ys, masks, crossings);
  for (int i = 0; i < 200; ++i) EXPECT_FALSE(after.may_meet(random_polygon(rng, -2.0, 42.0, -2.0, 32.0)));
}

TEST(CellMask, APolygonBeyondTheCoordinateRangeOrNotFiniteMayMeetMaterial) {
  // A cap triangle of almost parallel support lines has its apex far away (1e15 mm is past
  // the kernel's 64-bit units); a degenerate one may hold a NaN. Neither is cleared, and
  // neither overflows the conversion to units (the sanitizer build checks that).
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {40, 30, 0}, 0.5, 2, 2));
  const int level = s.level_at(-3.0);
  std::vector<geom::detail::CellMask> masks(s.cell_count());
  std::vector<std::pair<int, double>> crossings;
  const auto xs = borders(s, true), ys = borders(s, false);
  const geom::detail::LevelMaterial m(s, level, xs, ys, masks, crossings);
  EXPECT_TRUE(m.may_meet(std::vector<SectionPoint>{{10, 10}, {12, 10}, {11, -1e15}}));
  EXPECT_TRUE(m.may_meet(std::vector<SectionPoint>{{10, 10}, {12, 10}, {1e300, 11}}));
  EXPECT_TRUE(m.may_meet(std::vector<SectionPoint>{{10, 10}, {12, 10}, {11, std::nan("")}}));
  // The same triangle with a near apex is decided by the masks: inside the stock it meets
  // material, beside it it does not.
  EXPECT_TRUE(m.may_meet(std::vector<SectionPoint>{{10, 10}, {12, 10}, {11, 12}}));
  EXPECT_FALSE(m.may_meet(std::vector<SectionPoint>{{50, 10}, {52, 10}, {51, 12}}));
}

TEST(CellMask, TiltedPassOverAPocketLeavesTheSolidOfThePassCutFirst) {
  // A tilted ball pass (the axis turning by 20° about X) half over a pocket: cut after the
  // pocket, its pieces over the pocket are in air and not built, and its arcs there are not
  // refined; cut before the pocket, every piece meets material. The two solids are the same
  // set up to the points' accuracy (tol/20: the pieces' searches start from other brackets
  // after a piece in air). A piece that met material but went unbuilt would leave at least
  // its advance across the tool on one level, 0.5 × 6 × 0.1 = 0.3 mm³, where its
  // neighbours do not cover it.
  const auto ball = geom::CutterShape::build(test::tool(geom::ToolKind::Ball, 6), 0.01);
  const auto flat = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 6), 0.01);
  std::vector<geom::SweepRef> pass;
  auto pose = [](int i) {
    const double x = 5.0 + 0.5 * i, a = 20.0 * std::sin(x / 8.0) * test::kPi / 180.0;
    return test::at(x, 20.0, -3.0 - 0.01 * x, {0, -std::sin(a), std::cos(a)});
  };
  for (int i = 0; i < 70; ++i) pass.push_back({&ball, pose(i), pose(i + 1), static_cast<geom::MoveId>(100 + i)});
  std::vector<geom::Vec3> pocket;
  test::append_pocket_path(pocket);
  geom::LbrSolid after(test::box_spec({0, 0, -10}, {50, 40, 0}, 0.1));
  test::cut_path(after, flat, pocket);
  geom::SubtractStats st;
  for (std::size_t i = 0; i < pass.size(); i += 10)
    st += after.subtract(std::span<const geom::SweepRef>(pass).subspan(i, std::min<std::size_t>(10, pass.size() - i)));
  geom::LbrSolid before(test::box_spec({0, 0, -10}, {50, 40, 0}, 0.1));
  geom::SubtractStats sb;
  for (std::size_t i = 0; i < pass.size(); i += 10)
    sb += before.subtract(std::span<const geom::SweepRef>(pass).subspan(i, std::min<std::size_t>(10, pass.size() - i)));
  test::cut_path(before, flat, pocket);
  auto skipped = [](const geom::SubtractStats& x) { return x.tilted_in_air + x.tilted_beside; };
  std::printf("pass after the pocket: %llu pieces in air, %llu beside the material; before it: %llu and %llu; "
              "removed %.6f and %.6f mm3\n",
              static_cast<unsigned long long>(st.tilted_in_air), static_cast<unsigned long long>(st.tilted_beside),
              static_cast<unsigned long long>(sb.tilted_in_air), static_cast<unsigned long long>(sb.tilted_beside),
              test::removed(after), test::removed(before));
  // Over the pocket a piece is either not made (its hull lies beside the material box of the
  // regions the pass reaches: Sweep::tilted_pieces()) or made and found in air.
  EXPECT_GT(skipped(st), 500u);
  EXPECT_LT(skipped(sb), skipped(st) / 10);
  EXPECT_GT(test::removed(after), test::kPocketVolume);
  EXPECT_NEAR(test::removed(after), test::removed(before), 0.05);
  EXPECT_EQ(after.check_invariants(), "");
}

TEST(CellMask, RebuildsThatClearNothingBackOff) {
  // A polygon in the middle of the material meets it whatever the mask's age, so rebuilding
  // the mask for it after each small cut elsewhere in the cell clears nothing: the rebuilds
  // come after 1, 2, 4, 8 and then every 16 changes of the cell. A rebuilt mask that clears
  // a polygon ends the back-off.
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {20, 15, 0}, 0.5, 1, 1));
  const auto flat = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 1), 0.01);
  const int level = s.level_at(-3.0);
  std::vector<geom::detail::CellMask> masks(s.cell_count());
  std::vector<std::pair<int, double>> crossings;
  const auto xs = borders(s, true), ys = borders(s, false);
  const std::vector<SectionPoint> inside{{10, 10}, {12, 10}, {12, 12}, {10, 12}};
  const geom::detail::CellMask& mask = masks[static_cast<std::size_t>(level)];
  std::vector<std::uint32_t> built_at;  // the cell's versions the mask was built from
  for (int i = 0; i < 40; ++i) {
    const geom::detail::LevelMaterial m(s, level, xs, ys, masks, crossings);
    EXPECT_TRUE(m.may_meet(inside));
    if (built_at.empty() || built_at.back() != mask.version) built_at.push_back(mask.version);
    const double x = 1.0 + 0.45 * i;
    test::cut(s, flat, test::at(x, 3, -8), test::at(x + 0.1, 3, -8));
  }
  const std::uint32_t v0 = built_at.front();
  std::vector<std::uint32_t> gaps;
  for (std::size_t k = 1; k < built_at.size(); ++k) gaps.push_back(built_at[k] - built_at[k - 1]);
  EXPECT_EQ(gaps, (std::vector<std::uint32_t>{1, 2, 4, 8, 16})) << "first build at version " << v0;
  EXPECT_EQ(mask.misses, geom::detail::CellMask::kMaxMisses);
  // In the slot the holes left, at its last one (x = 18.55, 0.45 mm from the slot's walls:
  // more than a pixel of 0.3125 mm), cut after the mask's last build: only a rebuilt mask
  // clears it, and the next rebuild starts the back-off again.
  const std::vector<SectionPoint> hole{{18.55, 2.95}, {18.65, 2.95}, {18.65, 3.05}, {18.55, 3.05}};
  for (int i = 0; i < 16; ++i) test::cut(s, flat, test::at(1.0 + 0.45 * i, 13, -8), test::at(1.1 + 0.45 * i, 13, -8));
  const geom::detail::LevelMaterial m(s, level, xs, ys, masks, crossings);
  EXPECT_FALSE(m.may_meet(hole));
  EXPECT_TRUE(mask.cleared);
  EXPECT_EQ(mask.misses, geom::detail::CellMask::kMaxMisses);  // rebuilt, after a run that cleared nothing
  test::cut(s, flat, test::at(10, 7, -8), test::at(10.1, 7, -8));
  const geom::detail::LevelMaterial m2(s, level, xs, ys, masks, crossings);
  EXPECT_TRUE(m2.may_meet(inside));  // a rebuild after one change: the mask had cleared the hole
  EXPECT_EQ(mask.misses, 0);
}

}  // namespace
