// LevelPool: the threaded subtraction, batch by batch or pulling batches one ahead, gives
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

// The pool's run() over the batches (pulled one ahead by a worker) and its subtract() per
// batch, with 1 to 3 threads.
TEST(LevelPool, RunGivesTheSingleThreadedSolidAndBuildsEachOffsetOnce) {
  const geom::CutterShape tool = geom::CutterShape::build(test::tool(geom::ToolKind::Flat, 8.0), 0.005);
  auto batches = pocket_batches(tool, 24);
  batches.insert(batches.begin() + 3, std::vector<SweepRef>{});  // an empty batch on the way
  ASSERT_GT(batches.size(), 5u);

  geom::LbrSolid one(spec());
  geom::SubtractStats s1;
  for (const auto& b : batches) s1 += one.subtract(b);
  ASSERT_GT(s1.chain_offsets, 2u);
  ASSERT_GT(s1.cells_changed, 0u);

  for (int threads : {1, 2, 3}) {
    geom::LbrSolid many(spec());
    app::LevelPool pool(threads);
    std::size_t next = 0, pulled = 0, done = 0;
    geom::SubtractStats each;
    const geom::SubtractStats s = pool.run(
        many,
        [&](std::vector<SweepRef>& out) {
          if (next == batches.size()) return false;
          out = batches[next++];
          ++pulled;
          return true;
        },
        [&](const geom::SubtractStats& b) {
          ++done;
          each += b;
        });
    EXPECT_EQ(pulled, batches.size()) << threads;
    EXPECT_EQ(done, batches.size()) << threads;
    EXPECT_EQ(geom::to_bytes(one), geom::to_bytes(many)) << threads;
    EXPECT_EQ(s.chain_offsets, s1.chain_offsets) << threads;  // each once, most a batch early
    EXPECT_EQ(s.cells_clipped, s1.cells_clipped) << threads;
    EXPECT_EQ(s.cells_reused, s1.cells_reused) << threads;
    EXPECT_EQ(each.cells_changed, s.cells_changed) << threads;

    // subtract() per batch on the same pool, then run() again on a fresh solid: the pool
    // holds no state between calls that changes the result.
    geom::LbrSolid again(spec());
    for (const auto& b : batches) (void)pool.subtract(again, b);
    EXPECT_EQ(geom::to_bytes(one), geom::to_bytes(again)) << threads;
    geom::LbrSolid third(spec());
    next = 0;
    (void)pool.run(third, [&](std::vector<SweepRef>& out) {
      if (next == batches.size()) return false;
      out = batches[next++];
      return true;
    });
    EXPECT_EQ(geom::to_bytes(one), geom::to_bytes(third)) << threads;
  }
}

}  // namespace
}  // namespace lbr
