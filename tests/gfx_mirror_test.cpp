// gfx/ without a display: the hand-over (SolidExchange), the render-side mirror (visible
// dirty regions only, bounded work per step, equality with a full rebuild) and the camera.
#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <set>
#include <thread>

#include "gfx/camera.hpp"
#include "gfx/exchange.hpp"
#include "gfx/mirror.hpp"
#include "gfx_test_util.hpp"

namespace lbr {
namespace {

using namespace test;
using namespace test::gfx_scene;

std::set<int> dirty_regions(const geom::LbrSolid& s) {
  std::set<int> r;
  for (std::uint32_t c : s.dirty_cells()) r.insert(static_cast<int>(c / static_cast<std::uint32_t>(s.levels())));
  return r;
}

// Same cells (content versions differ: the mirror counts its own set_cell calls).
void expect_same_solid(const geom::LbrSolid& a, const geom::LbrSolid& b) {
  ASSERT_EQ(a.regions(), b.regions());
  ASSERT_EQ(a.levels(), b.levels());
  for (int r = 0; r < a.regions(); ++r)
    for (int l = 0; l < a.levels(); ++l) {
      const geom::Cell &ca = a.cell(r, l), &cb = b.cell(r, l);
      ASSERT_EQ(ca.polys.size(), cb.polys.size()) << "region " << r << " level " << l;
      EXPECT_EQ(ca.area_units2, cb.area_units2) << "region " << r << " level " << l;
      for (std::size_t i = 0; i < ca.polys.size(); ++i) {
        EXPECT_EQ(ca.polys[i].outer.pts, cb.polys[i].outer.pts);
        EXPECT_EQ(ca.polys[i].outer.cut_by, cb.polys[i].outer.cut_by);
      }
    }
}

TEST(GfxExchange, PublishRefusedUntilTakenAndNothingIsLost) {
  geom::LbrSolid s = stock();
  s.clear_dirty();
  gfx::SolidExchange ex(16);
  gfx::MeshMirror mirror(s);
  const geom::CutterShape t = flat4();
  cut(s, t, at(5, 5, 5), at(5, 5, -2), 1);  // region 0
  const std::set<int> first = dirty_regions(s);
  ASSERT_TRUE(ex.publish(s, {}, 1, {}));
  EXPECT_EQ(s.dirty_count(), 0u);  // the exchange consumed the dirty set
  cut(s, t, at(35, 25, 5), at(35, 25, -2), 2);  // region 11
  const std::set<int> second = dirty_regions(s);
  EXPECT_FALSE(ex.publish(s, {}, 2, {}));  // not taken yet: refused, dirty set kept
  EXPECT_EQ(dirty_regions(s), second);
  EXPECT_EQ(ex.skipped(), 1u);

  gfx::Snapshot snap;
  ASSERT_TRUE(ex.take(snap));
  EXPECT_EQ(snap.version, 1u);
  std::set<int> got;
  for (std::size_t i = 0; i < snap.cell_count; ++i) got.insert(snap.cells[i].region);
  EXPECT_EQ(got, first);
  EXPECT_FALSE(ex.take(snap));  // nothing new
  mirror.receive(snap);
  ASSERT_TRUE(ex.publish(s, {}, 2, {}));
  ASSERT_TRUE(ex.take(snap));
  EXPECT_EQ(snap.version, 2u);
  EXPECT_EQ(snap.last_move, 2u);
  mirror.receive(snap);
  mirror.step({}, 0);
  expect_same_solid(mirror.solid(), s);
}

TEST(GfxExchange, PathBufferKeepsNewestPointsWithoutGrowing) {
  gfx::SolidExchange ex(8);
  for (int i = 0; i < 20; ++i) ex.add_path_point({static_cast<double>(i), 0, 0});
  geom::LbrSolid s = stock();
  s.clear_dirty();
  ASSERT_TRUE(ex.publish(s, {}, 0, {}));
  gfx::Snapshot snap;
  ASSERT_TRUE(ex.take(snap));
  ASSERT_FALSE(snap.path.empty());
  EXPECT_LE(snap.path.size(), 8u);
  EXPECT_EQ(snap.path.back().x, 19.0);
  EXPECT_EQ(snap.path_dropped + snap.path.size(), 20u);
}

TEST(GfxMirror, OnlyVisibleDirtyRegionsAreRebuiltAndTheRestWaits) {
  geom::LbrSolid s = stock();
  s.clear_dirty();
  gfx::MeshMirror mirror(s);
  const geom::CutterShape t = flat4();
  // A groove along y = 15 through all four columns of regions (x from 2 to 38).
  cut(s, t, at(2, 15, 5), at(2, 15, -2), 1);
  cut(s, t, at(2, 15, -2), at(38, 15, -2), 2);
  const std::set<int> dirty = dirty_regions(s);
  ASSERT_GE(dirty.size(), 4u);
  gfx::SolidExchange ex;
  ASSERT_TRUE(ex.publish(s, {}, 2, {}));
  gfx::Snapshot snap;
  ASSERT_TRUE(ex.take(snap));
  mirror.receive(snap);

  // Only the left half (region columns 0 and 1) is "visible".
  auto left = [&](int r) { return r % 4 < 2; };
  std::vector<std::uint64_t> gen0(12);
  for (int r = 0; r < 12; ++r) gen0[static_cast<std::size_t>(r)] = mirror.meshes().region(r).generation;
  const gfx::StepStats st = mirror.step(left, 0);
  int dirty_left = 0;
  for (int r : dirty) dirty_left += left(r) ? 1 : 0;
  EXPECT_EQ(st.regions_applied, dirty_left);
  EXPECT_EQ(st.regions_pending, static_cast<int>(dirty.size()) - dirty_left);
  for (int r = 0; r < 12; ++r) {
    const bool rebuilt = mirror.meshes().region(r).generation != gen0[static_cast<std::size_t>(r)];
    if (r % 4 == 3) {
      EXPECT_FALSE(rebuilt) << "region " << r << " is invisible and not next to an applied one";
    }
    EXPECT_EQ(mirror.pending(r), dirty.count(r) == 1 && !left(r)) << "region " << r;
  }
  // Regions rebuilt = applied regions and the neighbours that share their borders.
  EXPECT_GE(st.regions_rebuilt, st.regions_applied);
  EXPECT_LE(st.regions_rebuilt, 12 - 3);  // column 3 untouched

  // Everything visible, at most one region per step: one region per step, oldest first,
  // until nothing is pending; then identical to a fresh full reconstruction.
  int steps = 0;
  while (mirror.pending_regions() > 0) {
    const gfx::StepStats s2 = mirror.step([](int) { return true; }, 1);
    EXPECT_EQ(s2.regions_applied, 1);
    ASSERT_LT(++steps, 20);
  }
  EXPECT_EQ(steps, static_cast<int>(dirty.size()) - dirty_left);
  expect_same_solid(mirror.solid(), s);
  mesh::Reconstructor fresh;
  fresh.build(s);
  EXPECT_EQ(mirror.meshes().triangle_count(), fresh.triangle_count());
  EXPECT_NEAR(mirror.meshes().volume_mm3(), fresh.volume_mm3(), 1e-6 * fresh.volume_mm3());
}

TEST(GfxMirror, ConcurrentWriterAndReaderEndIdentical) {
  geom::LbrSolid s = stock();
  s.clear_dirty();
  gfx::MeshMirror mirror(s);
  gfx::SolidExchange ex(256);
  const geom::CutterShape t = flat4();
  std::atomic<bool> done{false};
  std::thread writer([&] {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> ux(1, 39), uy(1, 29), uz(-6, -0.5);
    for (int i = 0; i < 120; ++i) {
      const geom::Vec3 a{ux(rng), uy(rng), uz(rng)}, b{ux(rng), uy(rng), uz(rng)};
      cut(s, t, {a, {0, 0, 1}}, {b, {0, 0, 1}}, static_cast<geom::MoveId>(i + 1));
      ex.add_path_point(b);
      (void)ex.publish(s, {}, static_cast<geom::MoveId>(i + 1), {});
    }
    while (s.dirty_count() > 0)
      if (!ex.publish(s, {}, 120, {})) std::this_thread::yield();
    done.store(true);
  });
  gfx::Snapshot snap;
  std::uint64_t last_version = 0, taken = 0;
  while (true) {
    const bool fin = done.load();
    if (ex.take(snap)) {
      EXPECT_GT(snap.version, last_version);
      last_version = snap.version;
      ++taken;
      mirror.receive(snap);
      mirror.step({}, 3);
    } else if (fin) {
      break;
    }
  }
  writer.join();
  while (mirror.pending_regions() > 0) mirror.step({}, 3);
  EXPECT_EQ(last_version, ex.published());
  EXPECT_GT(taken, 0u);
  expect_same_solid(mirror.solid(), s);
  mesh::Reconstructor fresh;
  fresh.build(s);
  EXPECT_EQ(mirror.meshes().triangle_count(), fresh.triangle_count());
}

TEST(GfxCamera, StandardViewsAndFit) {
  geom::Box3 box;
  box.add({0, 0, -10});
  box.add({40, 30, 0});
  gfx::Camera c;
  c.set_view(gfx::StandardView::Top);
  c.ortho = true;
  c.fit(box, 400.0 / 300.0, 0.05);
  // Top view: +X to the right, +Y up (smaller pixel row), centred.
  const glm::dvec2 o = c.project({20, 15, 0}, 400, 300), px = c.project({30, 15, 0}, 400, 300),
                   py = c.project({20, 25, 0}, 400, 300);
  EXPECT_NEAR(o.x, 200, 1e-6);
  EXPECT_NEAR(o.y, 150, 1e-6);
  EXPECT_GT(px.x, o.x);
  EXPECT_NEAR(px.y, o.y, 1e-6);
  EXPECT_LT(py.y, o.y);
  // The 40 mm width fills 90 % of 400 px (limited by width: 40/30 = aspect).
  EXPECT_NEAR(c.project({40, 15, 0}, 400, 300).x - c.project({0, 15, 0}, 400, 300).x, 360.0, 1.0);

  for (gfx::StandardView v : {gfx::StandardView::Front, gfx::StandardView::Side, gfx::StandardView::Iso}) {
    gfx::Camera p;
    p.set_view(v);
    p.fit(box, 4.0 / 3.0, 0.05);
    const gfx::Frustum f(p.projection(4.0 / 3.0) * p.view());
    EXPECT_TRUE(f.intersects(box));
    // Every corner projects inside the image.
    for (int i = 0; i < 8; ++i) {
      const glm::dvec2 q = p.project({(i & 1) ? 40.0 : 0.0, (i & 2) ? 30.0 : 0.0, (i & 4) ? 0.0 : -10.0}, 400, 300);
      EXPECT_GE(q.x, 0);
      EXPECT_LE(q.x, 400);
      EXPECT_GE(q.y, 0);
      EXPECT_LE(q.y, 300);
    }
    // A box far behind the camera is culled.
    const glm::dvec3 back = p.eye() + 10.0 * (p.eye() - p.target);
    geom::Box3 b2;
    b2.add({back.x - 1, back.y - 1, back.z - 1});
    b2.add({back.x + 1, back.y + 1, back.z + 1});
    EXPECT_FALSE(f.intersects(b2));
  }
  // Front view looks along +Y: a point with larger y is farther (hidden behind).
  gfx::Camera fr;
  fr.set_view(gfx::StandardView::Front);
  EXPECT_LT(fr.eye().y, fr.target.y);
  gfx::Camera sd;
  sd.set_view(gfx::StandardView::Side);
  EXPECT_GT(sd.eye().x, sd.target.x);
}

}  // namespace
}  // namespace lbr
