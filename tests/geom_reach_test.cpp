// Clips out of reach (geom/src/clip_reach.cpp): a cell whose material keeps clear of every
// section's capsules, less the tolerance band, is not clipped. The turns of a helical bore
// above the cutting depth and a second pass over a finished bore skip their clips and
// remove exactly what the clips removed before; material just beyond the band is still cut.
#include <cmath>

#include <gtest/gtest.h>

#include "geom/serialize.hpp"
#include "test_util.hpp"

using namespace lbr;
using geom::ToolKind;

using test::helix;

namespace {

constexpr double kTol = 0.001;

// Cuts the path in batches of `batch` moves (one turn, as geom::tight_loop_end() cuts a
// tight helix) and returns the statistics summed over the batches.
geom::SubtractStats cut(geom::LbrSolid& s, const geom::CutterShape& c, const std::vector<geom::Vec3>& pts, int batch) {
  geom::SubtractStats st;
  std::vector<geom::SweepRef> b;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    b.push_back({&c, {pts[i - 1], {0, 0, 1}}, {pts[i], {0, 0, 1}}, static_cast<geom::MoveId>(i)});
    if (static_cast<int>(b.size()) == batch || i + 1 == pts.size()) {
      st += s.subtract(b);
      b.clear();
    }
  }
  return st;
}

}  // namespace

TEST(Reach, HelicalBoreSkipsTheClipsAboveTheCuttingDepth) {
  // Flat Ø8 on a helix of radius 6, 5 turns of 1 mm and a flat turn at -5, one turn per
  // batch: each turn sweeps every level above it again, where the turn before already cut
  // the same annulus.
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const int per_turn = 180;
  const geom::SubtractStats st = cut(s, c, helix(30, 20, 6, 0, 1, 5, per_turn), per_turn);
  const double exact = test::kPi * (100.0 - 4.0) * 5.0;
  const double perimeter = 2.0 * test::kPi * (10.0 + 2.0);
  EXPECT_NEAR(test::removed(s), exact, 2.0 * perimeter * kTol * 5.0);
  EXPECT_GT(st.cells_out_of_reach, 100u);
  EXPECT_EQ(s.check_invariants(), "");

  // The same helix again over the finished bore: most cells are out of reach (measured: 378
  // of 464 tested; the 86 clips left change nothing), the solid keeps every vertex.
  const double before = s.volume_mm3();
  const std::size_t vertices = s.vertex_count();
  const geom::SubtractStats again = cut(s, c, helix(30, 20, 6, 0, 1, 5, per_turn), per_turn);
  EXPECT_GT(again.cells_out_of_reach, 3 * again.cells_clipped);
  EXPECT_EQ(again.cells_changed, 0u);
  EXPECT_EQ(s.volume_mm3(), before);
  EXPECT_EQ(s.vertex_count(), vertices);
}

TEST(Reach, MaterialBeyondTheBandIsStillCut) {
  // A second helix 10 µm wider (the band is 1.5 µm + 0.2 µm): the wall ring 10 µm thick
  // must go on every level of the bore.
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const int per_turn = 180;
  cut(s, c, helix(30, 20, 6, 0, 1, 5, per_turn), per_turn);
  const double first = test::removed(s);
  const geom::SubtractStats st = cut(s, c, helix(30, 20, 6.01, 0, 1, 5, per_turn), per_turn);
  // Ring between r = 10 and 10.01 over the 5 mm depth, and the core between 1.99 and 2.
  const double ring = test::kPi * ((10.01 * 10.01 - 100.0) + (4.0 - 1.99 * 1.99)) * 5.0;
  const double perimeter = 2.0 * test::kPi * (10.0 + 2.0);
  EXPECT_NEAR(test::removed(s) - first, ring, 2.0 * perimeter * kTol * 5.0);
  EXPECT_GT(st.cells_changed, 0u);
  EXPECT_EQ(s.check_invariants(), "");
}

// Chains (horizontal moves at one height, cut as the path offset by r) carry capsules of
// radius r plus two units and no band: the same loop again with a smaller tool, whose
// offset stays inside what the first one cleared, builds no offset and clips nothing, and
// leaves the solid byte for byte; with a larger tool it cuts the ring between them.
TEST(Reach, AChainInsideClearedMaterialBuildsNoOffset) {
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto d10 = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const auto d8 = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const auto d11 = geom::CutterShape::build(test::tool(ToolKind::Flat, 11), kTol);
  std::vector<geom::Vec3> loop;  // a 20 x 20 square about (30, 20) at z -3, 2.5 mm moves
  for (int k = 0; k < 8; ++k) loop.push_back({20 + 2.5 * k, 10, -3});
  for (int k = 0; k < 8; ++k) loop.push_back({40, 10 + 2.5 * k, -3});
  for (int k = 0; k < 8; ++k) loop.push_back({40 - 2.5 * k, 30, -3});
  for (int k = 0; k <= 8; ++k) loop.push_back({20, 30 - 2.5 * k, -3});
  const geom::SubtractStats first = cut(s, d10, loop, 1000);
  EXPECT_GT(first.chain_offsets, 0u);
  EXPECT_GT(first.cells_changed, 0u);
  const auto before = geom::to_bytes(s);
  const double removed = test::removed(s);
  const geom::SubtractStats inside = cut(s, d8, loop, 1000);
  EXPECT_EQ(inside.chain_offsets, 0u);
  EXPECT_EQ(inside.cells_clipped, 0u);
  EXPECT_GT(inside.cells_out_of_reach, 0u);
  EXPECT_EQ(geom::to_bytes(s), before);
  const geom::SubtractStats wider = cut(s, d11, loop, 1000);
  EXPECT_GT(wider.chain_offsets, 0u);
  // The ring between the offsets by 5 and 5.5, 3 mm deep: outside, the square's sides
  // (4 · 20 · 0.5) and the corners' quarter rings; inside, the hole shrinks from 10 x 10 to
  // 9 x 9 (sharp corners).
  const double ring = 4 * 20.0 * 0.5 + test::kPi * (5.5 * 5.5 - 5.0 * 5.0) + (100.0 - 81.0);
  EXPECT_NEAR(test::removed(s) - removed, ring * 3.0, 0.01 * ring * 3.0);
  EXPECT_EQ(s.check_invariants(), "");
}
