// Surface quality against the exact machined surface at Δ = 0.1 mm: a ball-end groove and a
// ball-end 3D raster, both along x through the whole stock, so the exact surface is a
// height function f(y) of the cross-section. Distance of a mesh vertex = distance in the
// (y, z) plane to the graph of f. Vertices on the faces y = const of the stock and on the
// bottom are exact in both modes and left out.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "mesh_test_util.hpp"

namespace {

using namespace lbr;
using namespace lbr::mesh::testing;

struct Pass {
  double y, z;  // tip [mm]
};
constexpr double kR = 3.0;  // ball radius [mm]

double f_exact(const std::vector<Pass>& passes, double ztop, double y) {
  double f = ztop;
  for (const Pass& p : passes) {
    const double dy = y - p.y;
    if (std::abs(dy) < kR) f = std::min(f, p.z + kR - std::sqrt(kR * kR - dy * dy));
  }
  return f;
}

// The closest point of the graph lies within |z - f(y)| horizontally: sample that window.
double distance(const std::vector<Pass>& passes, double ztop, double y, double z) {
  const double d0 = std::abs(z - f_exact(passes, ztop, y));
  double d = d0;
  const int n = 400;
  for (int i = -n; i <= n; ++i) {
    const double yy = y + d0 * i / n;
    d = std::min(d, std::hypot(yy - y, f_exact(passes, ztop, yy) - z));
  }
  return d;
}

struct Quality {
  double max_mm = 0, mean_mm = 0;
};

Quality measure(const geom::LbrSolid& s, const std::vector<Pass>& passes, mesh::WallMode mode) {
  mesh::Reconstructor rec(mesh::MeshOptions{mode, 20.0});
  rec.build(s);
  EXPECT_EQ(census(rec).bad_edges, 0u);
  std::vector<geom::Coord> border_y;  // vertical grid lines carry vertices inside the material
  for (int r = 0; r < s.regions(); ++r) {
    border_y.push_back(s.region_rect(r).y0);
    border_y.push_back(s.region_rect(r).y1);
  }
  Quality q;
  std::size_t n = 0;
  for (int r = 0; r < rec.regions(); ++r) {
    const mesh::MeshBuffers& m = rec.region(r);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      const mesh::VertexKey& k = m.keys[v];
      if (k.height == 0 || std::find(border_y.begin(), border_y.end(), k.y) != border_y.end()) continue;
      const double d = distance(passes, s.z_top_mm(), geom::to_mm(k.y), static_cast<double>(m.positions[3 * v + 2]));
      if (d > q.max_mm && std::getenv("LBR_MESH_DEBUG"))
        std::printf("max at x %.4f y %.4f z %.4f height %d: %.4f\n", geom::to_mm(k.x), geom::to_mm(k.y), m.positions[3 * v + 2], k.height, d);
      q.max_mm = std::max(q.max_mm, d);
      q.mean_mm += d;
      ++n;
    }
  }
  if (n) q.mean_mm /= static_cast<double>(n);
  return q;
}

geom::LbrSolid machine(const std::vector<Pass>& passes, int grid) {
  geom::LbrSolid s(box_spec(20, 16, 6, 0.1, grid, grid));
  const geom::CutterShape ball = cutter(geom::ToolKind::Ball, 2 * kR);
  geom::MoveId id = 1;
  for (const Pass& p : passes) cut(s, ball, {-4, p.y, p.z}, {24, p.y, p.z}, id++);
  return s;
}

void report(const char* what, int grid, const Quality& j, const Quality& e) {
  std::printf("[ quality  ] %s %dx%d: joined max %.4f mean %.4f mm | extruded max %.4f mean %.4f mm\n", what, grid, grid,
              j.max_mm, j.mean_mm, e.max_mm, e.mean_mm);
}

TEST(MeshSurface, BallGroove) {
  const std::vector<Pass> passes{{8.0, 4.0}};
  const geom::LbrSolid s = machine(passes, 1);
  const Quality j = measure(s, passes, mesh::WallMode::Joined);
  const Quality e = measure(s, passes, mesh::WallMode::Extruded);
  report("ball groove", 1, j, e);
  // Extruded: contour vertices sit Δ/2 above or below their mid-plane sample.
  EXPECT_GT(e.max_mm, 0.04);
  EXPECT_LT(e.max_mm, 0.052);
  // Joined: vertices sit on their level's mid-plane sample, so the error is the kernel's
  // chord tolerance (0.002 mm here) plus rounding -- except the groove's edges on the top
  // face: the top face is wide, so its corner stays on the top plane, Δ/2 above the last
  // sample, where the exact edge lies 0.016 mm away (Δ/2 / tan of the wall slope there).
  EXPECT_LT(j.max_mm, 0.02);
  EXPECT_LT(j.max_mm, 0.4 * e.max_mm);
  EXPECT_LT(j.mean_mm, 0.1 * e.mean_mm);
}

TEST(MeshSurface, BallRaster3D) {
  std::vector<Pass> passes;
  for (int i = 0; i <= 12; ++i) {
    const double y = 2.0 + 1.0 * i;
    passes.push_back({y, 3.5 + 0.8 * std::sin(y / 3.0)});
  }
  const geom::LbrSolid s = machine(passes, 1);
  const Quality j = measure(s, passes, mesh::WallMode::Joined);
  const Quality e = measure(s, passes, mesh::WallMode::Extruded);
  report("ball raster", 1, j, e);
  EXPECT_GT(e.max_mm, 0.04);
  EXPECT_LT(e.max_mm, 0.052);
  EXPECT_LT(j.max_mm, 0.005);
  EXPECT_LT(j.max_mm, 0.2 * e.max_mm);
  EXPECT_LT(j.mean_mm, 0.1 * e.mean_mm);
}

// With a region grid the vertices on shared borders follow the border rule (docs/mesh.md);
// the result must be as good as in one region.
TEST(MeshSurface, BallRasterOnRegionGrid) {
  std::vector<Pass> passes;
  for (int i = 0; i <= 12; ++i) {
    const double y = 2.0 + 1.0 * i;
    passes.push_back({y, 3.5 + 0.8 * std::sin(y / 3.0)});
  }
  const geom::LbrSolid s = machine(passes, 4);
  const Quality j = measure(s, passes, mesh::WallMode::Joined);
  const Quality e = measure(s, passes, mesh::WallMode::Extruded);
  report("ball raster", 4, j, e);
  EXPECT_LT(j.max_mm, 0.005);
  EXPECT_LT(j.mean_mm, 0.1 * e.mean_mm);
}

}  // namespace
