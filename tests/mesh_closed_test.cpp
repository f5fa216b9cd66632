// Closedness (every edge used exactly twice, opposite directions, by exact vertex identity)
// and volume (mesh = LBR volume within the stated bound) on analytic cases and seeded
// random programs, for region grids 1x1 and 8x8, in both wall modes. Incremental rebuild
// after each cut of a sequence = full rebuild.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <tuple>

#include "mesh_test_util.hpp"

namespace {

using namespace lbr;
using namespace lbr::mesh::testing;
using geom::ToolKind;
using mesh::WallMode;

struct Case {
  int nx, ny;
  WallMode mode;
};

// `nonmanifold_ok`: random programs can leave two pieces of material touching along a line
// (a non-manifold LBR solid); there the edge is used twice in each direction (docs/mesh.md).
void expect_closed_and_volume(const geom::LbrSolid& s, WallMode mode, const std::string& what,
                              bool nonmanifold_ok = false) {
  mesh::Reconstructor rec(mesh::MeshOptions{mode, 20.0});
  const mesh::BuildStats st = rec.build(s);
  const auto c = census(rec);
  EXPECT_EQ(c.bad_edges, 0u) << what << ": first " << c.first_bad;
  EXPECT_EQ(c.degenerate, 0u) << what;
  if (!nonmanifold_ok) EXPECT_EQ(c.nonmanifold, 0u) << what;
  else EXPECT_LE(c.nonmanifold, c.edges / 1000 + 8) << what;
  EXPECT_EQ(st.defects, 0u) << what;
  // Forced ears keep closedness but may overlap; only slivers of random programs need them.
  if (!nonmanifold_ok) EXPECT_EQ(st.forced_ears, 0u) << what;
  else EXPECT_LE(st.forced_ears, 16u) << what;
  const bool joined = mode == WallMode::Joined;
  // Tolerance (docs/mesh.md): rounded crossing points + vertical moves of joined caps +
  // double round-off of the divergence sum.
  const double tol = total_bound(rec, joined) + 1e-9 * s.initial_volume_mm3();
  EXPECT_NEAR(rec.volume_mm3(), s.volume_mm3(), tol) << what;
}

class MeshClosed : public ::testing::TestWithParam<Case> {};

TEST_P(MeshClosed, UntouchedBox) {
  const Case p = GetParam();
  geom::LbrSolid s(box_spec(20, 16, 3, 0.5, p.nx, p.ny));
  expect_closed_and_volume(s, p.mode, "box");
}

TEST_P(MeshClosed, FlatPocketAndBallGrooveAndDrill) {
  const Case p = GetParam();
  geom::LbrSolid s(box_spec(40, 30, 6, 0.25, p.nx, p.ny));
  const auto flat = cutter(ToolKind::Flat, 6);
  const auto ball = cutter(ToolKind::Ball, 4);
  const auto drill = cutter(ToolKind::Drill, 3, 118);
  for (int k = 0; k < 4; ++k) cut(s, flat, {5, 5 + 3.0 * k, 4}, {25, 5 + 3.0 * k, 4}, static_cast<geom::MoveId>(1 + k));
  cut(s, ball, {-5, 22, 4.2}, {45, 24, 4.2}, 10);
  cut(s, drill, {32, 8, 6.5}, {32, 8, 1}, 11);
  cut(s, drill, {10, 10, 6.5}, {10, 10, 0.5}, 12);  // through the pocket floor
  expect_closed_and_volume(s, p.mode, "pocket");
}

TEST_P(MeshClosed, CylinderStock) {
  const Case p = GetParam();
  geom::SolidSpec spec;
  spec.shape = geom::SolidSpec::Shape::Cylinder;
  spec.cylinder = {0, 0, 20, 0, 4};
  spec.level_spacing_mm = 0.5;
  spec.regions_x = p.nx;
  spec.regions_y = p.ny;
  spec.chord_tol_mm = 0.01;
  geom::LbrSolid s(spec);
  const auto ball = cutter(ToolKind::Ball, 6);
  cut(s, ball, {-12, -3, 2}, {12, 4, 3}, 1);
  expect_closed_and_volume(s, p.mode, "cylinder");
}

TEST_P(MeshClosed, TightHelicalRampsBothWays) {
  // Flat Ø6 ramping on a radius of 1.2 (a tight loop: joined outlines written as their outer
  // chain, docs/lbr-conventions.md), counter-clockwise at one place and clockwise at
  // another, batches of 50 moves (whole and part turns).
  const Case p = GetParam();
  geom::LbrSolid s(box_spec(40, 30, 6, 0.25, p.nx, p.ny));
  const auto flat = cutter(ToolKind::Flat, 6);
  std::vector<geom::SweepRef> moves;
  geom::MoveId id = 1;
  for (const double sign : {1.0, -1.0}) {
    const double cx = sign > 0 ? 12.0 : 28.0, cy = 15.0;
    geom::Vec3 prev{cx + 1.2, cy, 6.5};
    for (int i = 1; i <= 300; ++i) {  // 3 turns of 100 chords, 1 mm a turn
      const double a = 2.0 * std::numbers::pi * i / 100.0;
      const geom::Vec3 next{cx + 1.2 * std::cos(a), cy + sign * 1.2 * std::sin(a), 6.5 - 0.01 * i};
      moves.push_back({&flat, {prev, {0, 0, 1}}, {next, {0, 0, 1}}, id++});
      prev = next;
      if (moves.size() == 50) {
        s.subtract(moves);
        moves.clear();
      }
    }
  }
  // Closed, oriented, no degenerate facets and the volume. In joined wall mode these steep
  // ramps leave 16-18 non-manifold edges (edges used twice each way, docs/mesh.md): the same
  // count with the spokes that joined outlines had before the outer chain, so it comes from
  // the walls, not from the outline; asserted exactly in extruded mode only.
  mesh::Reconstructor rec(mesh::MeshOptions{p.mode, 20.0});
  const mesh::BuildStats st = rec.build(s);
  const auto c = census(rec);
  EXPECT_EQ(c.bad_edges, 0u) << "first " << c.first_bad;
  EXPECT_EQ(c.degenerate, 0u);
  if (p.mode == WallMode::Extruded) EXPECT_EQ(c.nonmanifold, 0u);
  else EXPECT_LE(c.nonmanifold, 18u);
  EXPECT_EQ(st.defects, 0u);
  EXPECT_GT(s.initial_volume_mm3() - s.volume_mm3(), 150.0);
  const double tol = total_bound(rec, p.mode == WallMode::Joined) + 1e-9 * s.initial_volume_mm3();
  EXPECT_NEAR(rec.volume_mm3(), s.volume_mm3(), tol);
}

TEST_P(MeshClosed, SeededRandomPrograms) {
  const Case p = GetParam();
  const char* env = std::getenv("LBR_MESH_SEEDS");
  const int seeds = env ? std::atoi(env) : 6;
  for (int seed = 1; seed <= seeds; ++seed) {
    geom::LbrSolid s(box_spec(24, 20, 5, 0.25, p.nx, p.ny));
    std::vector<geom::CutterShape> tools;
    random_program(s, static_cast<std::uint32_t>(seed), 12, tools);
    expect_closed_and_volume(s, p.mode, "seed " + std::to_string(seed), true);
  }
}

INSTANTIATE_TEST_SUITE_P(Grids, MeshClosed,
                         ::testing::Values(Case{1, 1, WallMode::Extruded}, Case{8, 8, WallMode::Extruded},
                                           Case{1, 1, WallMode::Joined}, Case{8, 8, WallMode::Joined}),
                         [](const ::testing::TestParamInfo<Case>& i) {
                           return std::to_string(i.param.nx) + "x" + std::to_string(i.param.ny) +
                                  (i.param.mode == WallMode::Joined ? "_joined" : "_extruded");
                         });

// Extruded mode is the LBR solid itself: its volume equals the kernel's to rounding only.
TEST(MeshVolume, ExtrudedEqualsLbrVolume) {
  geom::LbrSolid s(box_spec(24, 20, 5, 0.25, 4, 4));
  std::vector<geom::CutterShape> tools;
  random_program(s, 99, 15, tools);
  mesh::Reconstructor rec(mesh::MeshOptions{WallMode::Extruded, 20.0});
  rec.build(s);
  const double tol = total_bound(rec, false) + 1e-9 * s.initial_volume_mm3();
  EXPECT_LT(tol, 1e-4 * s.initial_volume_mm3());  // the bound itself is small
  EXPECT_NEAR(rec.volume_mm3(), s.volume_mm3(), tol);
}

// Sorted list of triangles (exact keys + float positions), rotation-normalised.
using TriKey = std::array<std::tuple<long long, long long, int, float>, 3>;
std::vector<TriKey> canonical(const mesh::Reconstructor& rec) {
  std::vector<TriKey> out;
  for (int r = 0; r < rec.regions(); ++r) {
    const mesh::MeshBuffers& m = rec.region(r);
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      TriKey k;
      for (int v = 0; v < 3; ++v) {
        const std::uint32_t i = m.indices[3 * t + v];
        k[v] = {m.keys[i].x, m.keys[i].y, m.keys[i].height, m.positions[3 * i + 2]};
      }
      std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());
      out.push_back(k);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(MeshIncremental, UpdateAfterEachCutEqualsFullRebuild) {
  for (WallMode mode : {WallMode::Extruded, WallMode::Joined}) {
    geom::LbrSolid s(box_spec(24, 20, 5, 0.25, 4, 3));
    mesh::Reconstructor inc(mesh::MeshOptions{mode, 20.0});
    inc.build(s);
    s.clear_dirty();
    std::vector<geom::CutterShape> tools;
    std::mt19937 rng(7);
    std::vector<geom::CutterShape> all;
    random_program(s, 5, 0, all);  // fills the tool list only
    std::uniform_real_distribution<double> ux(-2, 26), uy(-2, 22), uz(0.5, 5.2);
    std::uint64_t partial = 0, full_planes = 0;
    for (int m = 0; m < 10; ++m) {
      const double z = uz(rng);
      cut(s, all[static_cast<std::size_t>(m % 4)], {ux(rng), uy(rng), z}, {ux(rng), uy(rng), z},
          static_cast<geom::MoveId>(m + 1));
      const mesh::BuildStats st = inc.update(s);
      s.clear_dirty();
      mesh::Reconstructor full(mesh::MeshOptions{mode, 20.0});
      full_planes = full.build(s).planes_built;
      partial += st.planes_built;
      ASSERT_EQ(canonical(inc), canonical(full)) << "after move " << m + 1;
      EXPECT_EQ(census(inc).bad_edges, 0u);
    }
    EXPECT_LT(partial, 10 * full_planes);  // it really was incremental
  }
}

}  // namespace
