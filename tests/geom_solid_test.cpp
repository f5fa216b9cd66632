// LbrSolid construction, level convention, queries, dirty set and move ids.
#include <gtest/gtest.h>

#include "test_util.hpp"

using namespace lbr;
using geom::ToolKind;

TEST(Solid, BoxLevelsAndVolume) {
  const geom::LbrSolid s(test::box_spec({0, 0, -30}, {100, 80, 0}, 0.1));
  EXPECT_EQ(s.levels(), 300);
  EXPECT_EQ(s.regions(), 16);
  EXPECT_NEAR(s.volume_mm3(), 240000.0, 1e-6);
  EXPECT_NEAR(s.level_z_mm(0), -29.95, 1e-12);
  EXPECT_NEAR(s.level_z_mm(299), -0.05, 1e-9);
  EXPECT_EQ(s.polygon_count(), 16u * 300u);
  EXPECT_EQ(s.vertex_count(), 4u * 16u * 300u);
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Solid, PartialTopSlab) {
  // 1.05 mm at Δ = 0.1: ten full slabs and a top slab of 0.05 mm sampled at its own middle.
  const geom::LbrSolid s(test::box_spec({0, 0, 0}, {10, 10, 1.05}, 0.1, 1, 1));
  EXPECT_EQ(s.levels(), 11);
  EXPECT_NEAR(s.level_thickness_mm(10), 0.05, 1e-12);
  EXPECT_NEAR(s.level_z_mm(10), 1.025, 1e-12);
  EXPECT_NEAR(s.volume_mm3(), 105.0, 1e-9);
}

TEST(Solid, CylinderStock) {
  geom::SolidSpec spec;
  spec.shape = geom::SolidSpec::Shape::Cylinder;
  spec.cylinder = {5, -3, 40, -50, 0};
  spec.level_spacing_mm = 0.5;
  spec.regions_x = 3;
  spec.regions_y = 3;
  const geom::LbrSolid s(spec);
  EXPECT_EQ(s.levels(), 100);
  const double exact = test::kPi * 400.0 * 50.0;
  EXPECT_NEAR(s.volume_mm3(), exact, 2 * test::kPi * 40.0 * spec.chord_tol_mm * 50.0);
  EXPECT_EQ(s.check_invariants(), "");
  const geom::Box3 b = s.bounds();
  EXPECT_NEAR(b.lo.x, -15.0, 0.001);
  EXPECT_NEAR(b.hi.y, 17.0, 0.001);
}

TEST(Solid, BadSpecsAreRejectedWithAReason) {
  auto msg = [](const geom::SolidSpec& sp) {
    try {
      geom::LbrSolid s(sp);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(msg(test::box_spec({0, 0, 0}, {10, 10, 10}, 0.0)), "level spacing must be in [0.001, 1000] mm");
  EXPECT_EQ(msg(test::box_spec({0, 0, 0}, {10, -10, 10}, 0.1)), "box stock needs min < max on every axis");
  EXPECT_EQ(msg(test::box_spec({0, 0, 0}, {10, 10, 10}, 0.1, 0, 4)), "region grid must be between 1x1 and 256x256");
  EXPECT_NE(msg(test::box_spec({0, 0, 0}, {2e6, 10, 10}, 0.1)).find("within ±107374"), std::string::npos);
  EXPECT_NE(msg(test::box_spec({0, 0, 0}, {10, 10, 1000}, 0.001)).find("1000000 levels"), std::string::npos);
}

TEST(Solid, DirtySetAndMoveIds) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {40, 40, 0}, 0.5, 4, 4));  // regions 10 x 10 mm
  s.clear_dirty();
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 4), 0.001);
  // Slot along y = 5 from x = 2 to x = 14 at depth 2: regions 0 and 1, the top 4 levels.
  const geom::SubtractStats st = test::cut(s, c, test::at(2, 5, -2), test::at(14, 5, -2), 7);
  EXPECT_EQ(st.cells_changed, 8u);
  EXPECT_EQ(s.dirty_count(), 8u);
  for (int r = 0; r < s.regions(); ++r) {
    for (int l = 0; l < s.levels(); ++l) {
      const bool expect = (r == 0 || r == 1) && l >= 16;
      EXPECT_EQ(s.is_dirty(r, l), expect) << "region " << r << " level " << l;
      for (const geom::Polygon& p : s.cell(r, l).polys) {
        EXPECT_EQ(p.outer.cut_by, expect ? 7u : 0u);
      }
    }
  }
  // Region 5 is untouched by a second cut elsewhere; region 0 keeps id 7 where id 9 misses it.
  s.clear_dirty();
  test::cut(s, c, test::at(35, 35, -1), test::at(35, 35, -1), 9);
  EXPECT_EQ(s.cell(0, 19).polys.front().outer.cut_by, 7u);
  // The plunge leaves a hole cut by move 9 inside region 15's untouched outline.
  ASSERT_EQ(s.cell(15, 19).polys.front().holes.size(), 1u);
  EXPECT_EQ(s.cell(15, 19).polys.front().holes[0].cut_by, 9u);
  EXPECT_EQ(s.cell(15, 19).polys.front().outer.cut_by, 0u);
  EXPECT_TRUE(s.cell(15, 17).polys.front().holes.empty());
  EXPECT_EQ(s.dirty_count(), 2u);
  const auto d = s.dirty_cells();
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0], 15u * 20u + 18u);
  EXPECT_EQ(d[1], 15u * 20u + 19u);
}

TEST(Solid, BoxCullingSkipsFarCells) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {80, 80, 0}, 0.1, 8, 8));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 4), 0.001);
  const geom::SubtractStats st = test::cut(s, c, test::at(5, 5, -1), test::at(5, 5, -1));
  // A 4 mm tool at (5, 5) touches region 0 only, in the top 10 levels: the lowest is
  // clipped, the 9 above start from the same square with the same disk and reuse it.
  EXPECT_EQ(st.sections, 10u);
  EXPECT_EQ(st.cells_tested, 1u);
  EXPECT_EQ(st.cells_clipped, 1u);
  EXPECT_EQ(st.cells_reused, 9u);
  EXPECT_EQ(st.cells_changed, 10u);
  auto spec = test::box_spec({0, 0, -10}, {80, 80, 0}, 0.1, 8, 8);
  spec.vertical_coherence = false;
  geom::LbrSolid off(spec);
  const geom::SubtractStats so = test::cut(off, c, test::at(5, 5, -1), test::at(5, 5, -1));
  EXPECT_EQ(so.cells_tested, 10u);
  EXPECT_EQ(so.cells_clipped, 10u);
  EXPECT_EQ(so.cells_reused, 0u);
  EXPECT_EQ(so.cells_changed, 10u);
}

TEST(Solid, BooleanDifferenceOfTwoSolids) {
  // Box 40 x 40 x 10 minus a cylinder Ø20 standing on z = -4 inside it: π·100·4 removed.
  geom::LbrSolid a(test::box_spec({0, 0, -10}, {40, 40, 0}, 0.1, 2, 2));
  geom::SolidSpec cs;
  cs.shape = geom::SolidSpec::Shape::Cylinder;
  cs.cylinder = {20, 20, 20, -4, 6};
  cs.level_spacing_mm = 0.1;
  cs.regions_x = cs.regions_y = 3;
  const geom::LbrSolid b(cs);
  const geom::SubtractStats st = a.subtract_solid(b, 3);
  EXPECT_EQ(st.cells_changed, 4u * 40u);
  EXPECT_NEAR(test::removed(a), test::kPi * 100.0 * 4.0, 2 * test::kPi * 20.0 * 0.001 * 4.0);
  EXPECT_EQ(a.check_invariants(), "");
}

TEST(Solid, SectionsInTheAirLeaveTheDifference) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {80, 60, 0}, 0.1, 4, 3));
  const auto flat = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), 0.001);
  // A slot 16 mm wide (two passes, y = 30 and 36), 5 mm deep, from x = 10 to 70.
  test::cut(s, flat, test::at(10, 30, -5), test::at(70, 30, -5), 1);
  test::cut(s, flat, test::at(10, 36, -5), test::at(70, 36, -5), 1);
  const double v0 = s.volume_mm3();
  // The same tool 2 mm above the floor, along the middle of the slot, clear of its walls:
  // every section is in the air.
  const geom::SubtractStats air = test::cut(s, flat, test::at(20, 33, -3), test::at(60, 33, -3), 2);
  EXPECT_EQ(air.cells_clipped, 0u);
  EXPECT_EQ(air.cells_changed, 0u);
  EXPECT_GT(air.sections_in_air, 0u);
  EXPECT_DOUBLE_EQ(s.volume_mm3(), v0);
  // A move that leaves the slot sideways cuts the wall, 3 mm deep (the tip at -3 lies on a
  // slab boundary): new area per level = the band y in [41, 50] x 10 mm plus the end
  // half-disk; the rest of its stadium lies in the slot.
  const geom::SubtractStats wall = test::cut(s, flat, test::at(40, 33, -3), test::at(40, 50, -3), 3);
  EXPECT_GT(wall.cells_clipped, 0u);
  const double area = 9.0 * 10.0 + test::kPi * 25.0 / 2.0;
  EXPECT_NEAR(v0 - s.volume_mm3(), area * 3.0, 2 * (40.0 + 10.0 * test::kPi) * 0.001 * 3.0);
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Solid, ChainOffsetBoxOnARegionBoundary) {
  // A chain's offset box is its polyline's box grown by r + tol/4 (rounded up, +2 units).
  // Here it starts exactly on the boundary x = 15 mm between regions 0 and 1 (and a few
  // units either side), and a plunge in region 0 brings that region's cells into the batch:
  // they touch the box on their edge, and their clip must not look for a piece of the
  // offset there (it covers none of their area). The chained cut must remove what the same
  // moves remove one by one (stadiums, no chain).
  const auto flat = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), 0.005);
  const double d = (std::ceil((4.0 + 0.25 * 0.005) * geom::kUnitsPerMm) + 2.0) / geom::kUnitsPerMm;  // 4.0015 mm
  for (int k = -3; k <= 3; ++k) {
    const double x0 = 15.0 + d + k / geom::kUnitsPerMm;
    std::vector<geom::SweepRef> moves{{&flat, test::at(7, 20, 12), test::at(7, 20, 5), 10, nullptr}};
    const std::vector<geom::Pose> pts{test::at(x0, 5, 5), test::at(x0 + 8, 12, 5), test::at(x0, 19, 5),
                                      test::at(x0 + 8, 26, 5), test::at(x0, 33, 5)};
    for (std::size_t i = 1; i < pts.size(); ++i)
      moves.push_back({&flat, pts[i - 1], pts[i], static_cast<geom::MoveId>(i), nullptr});
    geom::LbrSolid chained(test::box_spec({0, 0, 0}, {60, 40, 10}, 0.5, 4, 2));
    const geom::SubtractStats s = chained.subtract(moves);
    geom::LbrSolid single(test::box_spec({0, 0, 0}, {60, 40, 10}, 0.5, 4, 2));
    for (const geom::SweepRef& m : moves) (void)single.subtract(std::span<const geom::SweepRef>(&m, 1));
    EXPECT_GT(s.chain_offsets, 0u) << k;
    EXPECT_EQ(chained.check_invariants(), "") << k;
    // Both boundaries lie within ±tol/2 of the exact one; the cut is 5 mm deep, its outline
    // shorter than 2 x (4 x 10.6 + 8 pi) mm.
    const double outline = 2.0 * (4.0 * 10.6 + 8.0 * test::kPi);
    EXPECT_NEAR(chained.volume_mm3(), single.volume_mm3(), outline * 0.005 * 5.0) << k;
    EXPECT_GT(chained.initial_volume_mm3() - chained.volume_mm3(), 5.0 * (10.6 * 8.0 + 32.0 * test::kPi)) << k;  // > a stadium and the hole
  }
}

// Regression: a clip whose result loses a whole polygon is a change, however thin that
// polygon. A strip one unit wide along a stock face (left where a section's side is tangent
// to the face) has less area than half a unit times its perimeter, the bound under which a
// difference counts as rounding noise, and used to stay for good: every later pass over it
// was taken for noise and its cells kept.
TEST(LbrSolid, RegressionAStripOneUnitWideIsRemovedByAPassOverIt) {
  geom::SolidSpec spec;
  spec.box = {{0, 0, 0}, {20, 16, 6}};
  spec.level_spacing_mm = 0.1;
  spec.regions_x = spec.regions_y = 1;
  geom::LbrSolid s(spec);
  const int level = 57;
  geom::Polygon strip;
  strip.outer.pts = {{geom::to_units(20.0), geom::to_units(16.0)}, {0, geom::to_units(16.0)},
                     {0, geom::to_units(16.0) - 1}, {geom::to_units(20.0), geom::to_units(16.0) - 1}};
  strip.bbox = geom::bounds_of(strip.outer.pts);
  for (int l = 0; l < s.levels(); ++l)
    s.set_cell(0, l, l == level ? std::vector<geom::Polygon>{strip} : std::vector<geom::Polygon>{});
  ASSERT_FALSE(s.cell(0, level).bbox.empty());
  geom::Tool t;
  t.diameter_mm = 6.0;
  const geom::CutterShape flat = geom::CutterShape::build(t, 0.001);
  // Covers y 11..17 on every level above z 2.
  const geom::SweepRef ref{&flat, geom::Pose{{-4, 14, 2}}, geom::Pose{{24, 14, 2}}, 1};
  const geom::SubtractStats st = s.subtract(std::span<const geom::SweepRef>(&ref, 1));
  EXPECT_EQ(st.cells_changed, 1u);
  EXPECT_TRUE(s.cell(0, level).polys.empty());
}

// The snapshot slot tests' stock: 40 x 30 x 10 mm in 4 x 3 regions, levels 0.5 mm apart.
// A 40 x 30 mm box stock from z_min to 0 on a 4x3 grid.
geom::SolidSpec box_40x30(double z_min, double spacing) {
  geom::SolidSpec spec;
  spec.box = {{0, 0, z_min}, {40, 30, 0}};
  spec.level_spacing_mm = spacing;
  spec.regions_x = 4;
  spec.regions_y = 3;
  return spec;
}

geom::SolidSpec snapshot_test_spec() { return box_40x30(-10.0, 0.5); }

// A snapshot slot follows the live solid by copying only the cells that changed since its
// last copy (LbrSolid::update_copy_of): the result equals a full copy, and a cell that did
// not change keeps its storage.
TEST(LbrSolid, UpdateCopyOfCopiesTheChangedCellsOnly) {
  const geom::SolidSpec spec = snapshot_test_spec();
  geom::LbrSolid live(spec);
  geom::Tool t;
  t.diameter_mm = 6.0;
  const geom::CutterShape flat = geom::CutterShape::build(t, 0.01);
  const geom::SweepRef first{&flat, geom::Pose{{-5, 5, -3}}, geom::Pose{{45, 5, -3}}, 1};
  live.subtract(std::span<const geom::SweepRef>(&first, 1));
  geom::SolidSpec other = spec;  // another grid: the first update is a full copy
  other.regions_x = 1;
  geom::LbrSolid slot(other);
  slot.update_copy_of(live);
  EXPECT_DOUBLE_EQ(slot.volume_mm3(), live.volume_mm3());
  const int far_region = 11, level = 15;  // x 30..40, y 20..30: the second cut misses it
  const auto* kept = slot.cell(far_region, level).polys.data();
  const geom::SweepRef second{&flat, geom::Pose{{5, -5, -6}}, geom::Pose{{5, 25, -6}}, 2};
  live.subtract(std::span<const geom::SweepRef>(&second, 1));
  ASSERT_NE(slot.volume_mm3(), live.volume_mm3());
  slot.update_copy_of(live);
  EXPECT_DOUBLE_EQ(slot.volume_mm3(), live.volume_mm3());
  EXPECT_EQ(slot.cell(far_region, level).polys.data(), kept);
  for (int r = 0; r < live.regions(); ++r)
    for (int l = 0; l < live.levels(); ++l) {
      const geom::Cell& a = slot.cell(r, l);
      const geom::Cell& b = live.cell(r, l);
      ASSERT_EQ(a.version, b.version);
      ASSERT_EQ(a.polys.size(), b.polys.size());
      for (std::size_t p = 0; p < a.polys.size(); ++p) ASSERT_EQ(a.polys[p].outer.pts, b.polys[p].outer.pts);
    }
}

// The live snapshot's copy a slice at a time (LbrSolid::update_copy_slice): each slice
// copies at most its budget of changed cells and says where it stopped; the passes over
// the cells end equal to the live solid, and a pass that the solid changes in the middle of
// leaves the cells it had passed behind, which the next pass catches up.
TEST(LbrSolid, UpdateCopySliceCopiesAtMostItsBudgetAndCatchesUp) {
  const geom::SolidSpec spec = snapshot_test_spec();
  geom::LbrSolid live(spec);
  geom::LbrSolid slot(spec);
  ASSERT_TRUE(slot.same_grid(live));
  EXPECT_EQ(slot.cell_count(), static_cast<std::size_t>(live.regions() * live.levels()));
  geom::Tool t;
  t.diameter_mm = 6.0;
  const geom::CutterShape flat = geom::CutterShape::build(t, 0.01);
  const geom::SweepRef first{&flat, geom::Pose{{-5, 5, -3}}, geom::Pose{{45, 5, -3}}, 1};
  live.subtract(std::span<const geom::SweepRef>(&first, 1));
  auto changed = [&] {
    std::size_t n = 0;
    for (int r = 0; r < live.regions(); ++r)
      for (int l = 0; l < live.levels(); ++l) n += slot.cell(r, l).version != live.cell(r, l).version ? 1 : 0;
    return n;
  };
  const std::size_t to_copy = changed();
  ASSERT_GT(to_copy, 4u);
  // Slices of 3 cells: each stops right after its third copy (or at the end).
  std::size_t at = 0, slices = 0;
  while (at < slot.cell_count()) {
    const std::size_t before = changed();
    at = slot.update_copy_slice(live, at, 3);
    ++slices;
    EXPECT_EQ(before - changed(), std::min<std::size_t>(3, before)) << "slice " << slices;
  }
  EXPECT_EQ(slices, (to_copy + 2) / 3 + (to_copy % 3 == 0 ? 1 : 0));
  EXPECT_EQ(changed(), 0u);
  EXPECT_DOUBLE_EQ(slot.volume_mm3(), live.volume_mm3());
  // The live solid changes in the middle of a pass: cells before the cursor stay behind.
  const geom::SweepRef second{&flat, geom::Pose{{5, -5, -6}}, geom::Pose{{5, 25, -6}}, 2};
  const geom::SweepRef third{&flat, geom::Pose{{5, -5, -8}}, geom::Pose{{5, 25, -8}}, 3};
  live.subtract(std::span<const geom::SweepRef>(&second, 1));
  at = 0;
  while (at < static_cast<std::size_t>(live.levels())) at = slot.update_copy_slice(live, at, 1);  // region 0 passed
  live.subtract(std::span<const geom::SweepRef>(&third, 1));  // deeper in region 0 (and 4, 8)
  while (at < slot.cell_count()) at = slot.update_copy_slice(live, at, 1000);
  EXPECT_GT(changed(), 0u);  // region 0's cells missed the third cut
  EXPECT_NE(slot.volume_mm3(), live.volume_mm3());
  EXPECT_EQ(slot.update_copy_slice(live, 0, slot.cell_count()), slot.cell_count());
  EXPECT_EQ(changed(), 0u);
  EXPECT_DOUBLE_EQ(slot.volume_mm3(), live.volume_mm3());
}

namespace {

// A tilted ball raster (Ø6, axis turning from 10° to 30° about x along 40 moves of 0.5 mm),
// as a 5-axis finishing pass sends it.
std::vector<geom::SweepRef> tilted_pass(const geom::CutterShape& ball, std::size_t first, std::size_t count) {
  std::vector<geom::SweepRef> moves;
  auto pose = [](std::size_t i) {
    const double a = (10.0 + 0.5 * static_cast<double>(i)) * test::kPi / 180.0;
    return geom::Pose{{5.0 + 0.5 * static_cast<double>(i), 15.0, -2.0 - 0.02 * static_cast<double>(i)}, {0.0, -std::sin(a), std::cos(a)}};
  };
  for (std::size_t i = first; i < first + count; ++i) moves.push_back({&ball, pose(i), pose(i + 1), static_cast<geom::MoveId>(i + 1)});
  return moves;
}

geom::SolidSpec tilted_test_spec() { return box_40x30(-6.0, 0.1); }

void expect_same_cells(const geom::LbrSolid& a, const geom::LbrSolid& b) {
  for (int r = 0; r < a.regions(); ++r)
    for (int l = 0; l < a.levels(); ++l) {
      const geom::Cell& x = a.cell(r, l);
      const geom::Cell& y = b.cell(r, l);
      ASSERT_EQ(x.polys.size(), y.polys.size()) << r << " " << l;
      for (std::size_t p = 0; p < x.polys.size(); ++p) ASSERT_EQ(x.polys[p].outer.pts, y.polys[p].outer.pts) << r << " " << l;
    }
}

}  // namespace

// A live stream subtracts a tilted pass a move or two at a time: each level's first piece of
// a call takes the level's last piece of the call before as its cover (level_sections.cpp,
// level_prior()). The part is the one the whole pass in one call gives, within the tolerance
// the covers keep (each piece's section within the chord tolerance of its own).
TEST(LbrSolid, ATiltedPassMoveByMoveRemovesWhatItRemovesInOneCall) {
  const geom::CutterShape ball = geom::CutterShape::build(test::tool(ToolKind::Ball, 6.0, 18.0), 0.01);
  const std::vector<geom::SweepRef> pass = tilted_pass(ball, 0, 40);
  geom::LbrSolid whole(tilted_test_spec()), by_move(tilted_test_spec());
  whole.subtract(pass);
  for (const geom::SweepRef& m : pass) by_move.subtract(std::span<const geom::SweepRef>(&m, 1));
  const double removed = test::removed(whole);
  ASSERT_GT(removed, 250.0);
  // The boundaries differ by at most the chord tolerance: 0.01 mm over the pass's wetted
  // outline (2 x 26 mm long, 6 mm high on each level's sides, both ends): < 4 mm³.
  EXPECT_NEAR(test::removed(by_move), removed, 0.01 * (2.0 * 26.0 + 2.0 * 6.0) * 6.0);
  EXPECT_EQ(by_move.check_invariants(), "");
}

// Covers last only while nothing is put back: after update_copy_of() restores the stock, the
// next tilted move (starting where the last one ended, so its pieces lie mostly inside the
// last ones) builds every section whole, as on a fresh solid: the same cells, vertex for vertex.
TEST(LbrSolid, MaterialPutBackEndsTheTiltedCovers) {
  const geom::CutterShape ball = geom::CutterShape::build(test::tool(ToolKind::Ball, 6.0, 18.0), 0.01);
  const std::vector<geom::SweepRef> first = tilted_pass(ball, 0, 10), second = tilted_pass(ball, 10, 1);
  const geom::LbrSolid stock(tilted_test_spec());
  geom::LbrSolid reused(tilted_test_spec()), fresh(tilted_test_spec());
  const std::uint64_t epoch = reused.removal_epoch();
  reused.subtract(first);
  EXPECT_EQ(reused.removal_epoch(), epoch);  // subtracting keeps it
  reused.update_copy_of(stock);
  EXPECT_NE(reused.removal_epoch(), epoch);
  ASSERT_DOUBLE_EQ(reused.volume_mm3(), stock.volume_mm3());
  reused.subtract(second);
  fresh.subtract(second);
  expect_same_cells(reused, fresh);
}
