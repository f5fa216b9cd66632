// LevelPool: the threaded subtraction, with and without the next batch given ahead, gives
// the single-threaded solid byte for byte, and builds each chain offset once.
#include <gtest/gtest.h>

#include <vector>

#include "app/level_pool.hpp"
#include "geom/serialize.hpp"
#include "geom/tool.hpp"
#include "test_util.hpp"

namespace lbr {
namespace {

using geom::Pose;
using geom::SweepRef;

// A zig-zag pocket at two depths plus a plunge between them: every batch holds chains
// (horizontal runs) and a vertical sweep, so batches have offsets to build.
std::vector<std::vector<SweepRef>> pocket_batches(const geom::CutterShape& tool, std::size_t per) {
  std::vector<SweepRef> moves;
  geom::MoveId id = 0;
  Pose at{{5.0, 5.0, 25.0}, {0, 0, 1}};
  auto go = [&](double x, double y, double z) {
    const Pose to{{x, y, z}, {0, 0, 1}};
    moves.push_back({&tool, at, to, ++id, nullptr});
    at = to;
  };
  for (double z : {22.0, 18.5}) {
    go(at.tip.x, at.tip.y, z);
    for (int row = 0; row < 9; ++row) {
      const double y = 5.0 + 4.0 * row;
      const double x0 = row % 2 == 0 ? 5.0 : 55.0, x1 = row % 2 == 0 ? 55.0 : 5.0;
      go(x0, y, z);
      for (int k = 1; k <= 10; ++k) go(x0 + (x1 - x0) * k / 10.0, y, z);  // sampled: short steps
    }
  }
  std::vector<std::vector<SweepRef>> out;
  for (std::size_t i = 0; i < moves.size(); i += per)
    out.emplace_back(moves.begin() + static_cast<long>(i), moves.begin() + static_cast<long>(std::min(i + per, moves.size())));
  return out;
}

geom::SolidSpec spec() {
  geom::SolidSpec s;
  s.box = {{0, 0, 0}, {60, 40, 25}};
  s.level_spacing_mm = 0.5;
  s.regions_x = 4;
  s.regions_y = 3;
  return s;
}

TEST(LevelPool, NextBatchAheadGivesTheSameSolidAndBuildsEachOffsetOnce) {
  const geom::CutterShape tool = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 8.0), 0.005);
  const auto batches = pocket_batches(tool, 24);
  ASSERT_GT(batches.size(), 4u);

  geom::LbrSolid one(spec());
  geom::SubtractStats s1;
  for (const auto& b : batches) s1 += one.subtract(b);
  ASSERT_GT(s1.chain_offsets, 2u);

  for (int threads : {2, 3}) {
    // With the right next batch: the same bytes, the same offsets (built a batch early).
    geom::LbrSolid many(spec());
    app::LevelPool pool(threads);
    geom::SubtractStats s;
    for (std::size_t i = 0; i < batches.size(); ++i)
      s += pool.subtract(many, batches[i], i + 1 < batches.size() ? std::span<const SweepRef>(batches[i + 1])
                                                                   : std::span<const SweepRef>());
    EXPECT_EQ(geom::to_bytes(one), geom::to_bytes(many)) << threads;
    EXPECT_EQ(s.chain_offsets, s1.chain_offsets) << threads;
    EXPECT_EQ(s.cells_clipped, s1.cells_clipped) << threads;
    EXPECT_EQ(s.cells_reused, s1.cells_reused) << threads;

    // With a wrong next batch (the one after it): still the same bytes; the offsets built
    // ahead for batches that did not come are wasted, so more are built in all.
    geom::LbrSolid wrong(spec());
    app::LevelPool pool2(threads);
    geom::SubtractStats w;
    for (std::size_t i = 0; i < batches.size(); ++i)
      w += pool2.subtract(wrong, batches[i], i + 2 < batches.size() ? std::span<const SweepRef>(batches[i + 2])
                                                                     : std::span<const SweepRef>());
    EXPECT_EQ(geom::to_bytes(one), geom::to_bytes(wrong)) << threads;
    EXPECT_GT(w.chain_offsets, s1.chain_offsets) << threads;
    EXPECT_EQ(w.cells_clipped, s1.cells_clipped) << threads;
  }
}

}  // namespace
}  // namespace lbr
