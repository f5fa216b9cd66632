// Windowed clips (geom/src/window_clip.hpp): a difference fed the subject reduced to the clip's
// window, with the runs put back afterwards, is the difference of the whole subject, point
// for point (the XOR of the two results has zero area); where the reduction would change the
// result it refuses, and the caller clips the whole subject.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "window_clip.hpp"

using namespace lbr::geom;
using detail::WindowScratch;

namespace {

ClipperLib::Paths tree_paths(const ClipperLib::PolyTree& tree) {
  ClipperLib::Paths out;
  ClipperLib::PolyTreeToPaths(tree, out);
  return out;
}

ClipperLib::Paths full_difference(const Paths& subject, const Paths& clip) {
  ClipperLib::Clipper c;
  c.AddPaths(subject, ClipperLib::ptSubject, true);
  c.AddPaths(clip, ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  c.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return tree_paths(tree);
}

struct Windowed {
  bool reduced = false;   // reduce_to_window() took it
  bool restored = false;  // restore_runs() found every chord
  std::size_t reduced_vertices = 0;
  ClipperLib::Paths result;
};

// As cell_clip.cpp does it: window = the clip's box grown by 4 units.
Windowed windowed_difference(const Paths& subject, const Paths& clip) {
  Rect box;
  for (const Path& p : clip) box.add(bounds_of(p));
  const Rect w{box.x0 - 4, box.y0 - 4, box.x1 + 4, box.y1 + 4};
  WindowScratch ws;
  for (const Path& p : subject) ws.src.push_back(&p);
  Windowed out;
  out.reduced = detail::reduce_to_window(w, ws);
  if (!out.reduced) return out;
  for (const Path& r : ws.reduced) out.reduced_vertices += r.size();
  ClipperLib::Clipper c;
  c.PreserveCollinear(true);
  c.AddPaths(ws.reduced, ClipperLib::ptSubject, true);
  c.AddPaths(clip, ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  c.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  out.restored = detail::restore_runs(tree, ws);
  out.result = tree_paths(tree);
  return out;
}

double xor_area(const ClipperLib::Paths& a, const ClipperLib::Paths& b) {
  ClipperLib::Clipper c;
  c.AddPaths(a, ClipperLib::ptSubject, true);
  c.AddPaths(b, ClipperLib::ptClip, true);
  ClipperLib::Paths x;
  c.Execute(ClipperLib::ctXor, x, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double area = 0.0;
  for (const Path& p : x) area += std::abs(ClipperLib::Area(p));
  return area;
}

double area_of(const ClipperLib::Paths& paths) {
  double area = 0.0;
  for (const Path& p : paths) area += ClipperLib::Area(p);
  return area;
}

Path regular(double cx, double cy, double r, int n, double phase = 0.0) {
  Path p;
  for (int i = 0; i < n; ++i) {
    const double t = phase + 2.0 * std::numbers::pi * i / n;
    p.push_back({static_cast<Coord>(std::lround(cx + r * std::cos(t))), static_cast<Coord>(std::lround(cy + r * std::sin(t)))});
  }
  return p;
}

// A wall as a finishing pass leaves it: x = 930 000 ± 197 in 2 000-unit steps from y = 200 000
// to 356 000, closed by the stock's faces (a finish3d cell's contour).
Path scalloped_wall() {
  Path p;
  for (Coord y = 356000; y > 200000; y -= 2000) p.push_back({(y / 2000) % 2 == 0 ? 930048 : 929851, y});
  p.push_back({930048, 200000});
  p.push_back({1000000, 200000});
  p.push_back({1000000, 400000});
  p.push_back({760000, 400000});
  p.push_back({760000, 385000});
  p.push_back({911499, 383761});
  return p;  // counter-clockwise: the wall is walked downwards, the material on its left

}

}  // namespace

TEST(WindowClip, ASmallCutInALongScallopedWallClipsAQuarterOfItsVertices) {
  const Paths subject{scalloped_wall()};
  ASSERT_GT(ClipperLib::Area(subject[0]), 0.0);
  const Paths clip{regular(929900, 280000, 3000, 24)};  // a ball's section biting the wall
  const Windowed w = windowed_difference(subject, clip);
  ASSERT_TRUE(w.reduced);
  EXPECT_TRUE(w.restored);
  EXPECT_LT(w.reduced_vertices, subject[0].size() / 4);
  const ClipperLib::Paths full = full_difference(subject, clip);
  EXPECT_LT(area_of(full), area_of(ClipperLib::Paths{subject}));  // the cut removes something
  EXPECT_EQ(xor_area(w.result, full), 0.0);
  EXPECT_EQ(w.result.size(), full.size());
}

TEST(WindowClip, ACutAtTheWallsLastVertexKeepsTheRunsInLine) {
  // The wall's straight stock faces reduce to chords in line with their neighbours: the
  // difference must not merge them (PreserveCollinear), or the runs could not go back.
  Path box;
  for (Coord x = 0; x <= 100000; x += 1000) box.push_back({x, 0});
  for (Coord y = 1000; y <= 100000; y += 1000) box.push_back({100000, y});
  for (Coord x = 99000; x >= 0; x -= 1000) box.push_back({x, 100000});
  for (Coord y = 99000; y > 0; y -= 1000) box.push_back({0, y});
  const Paths subject{box};
  const Paths clip{regular(100000, 50000, 2500, 32)};
  const Windowed w = windowed_difference(subject, clip);
  ASSERT_TRUE(w.reduced);
  EXPECT_TRUE(w.restored);
  EXPECT_EQ(xor_area(w.result, full_difference(subject, clip)), 0.0);
}

TEST(WindowClip, AnIslandInsideAChordsLoopRefusesTheReduction) {
  // A U-shaped polygon whose notch opens away from the cut: the run around the notch is
  // closed by a chord across its mouth, and an island standing in the notch would then lie
  // inside the reduced polygon (winding number 2).
  Path u;
  for (Coord y = 0; y <= 100000; y += 1000) u.push_back({0, y});                 // left side, up
  for (Coord x = 1000; x <= 40000; x += 1000) u.push_back({x, 100000});          // top, right
  for (Coord y = 99000; y >= 20000; y -= 1000) u.push_back({40000, y});          // notch's left wall, down
  for (Coord x = 41000; x <= 60000; x += 1000) u.push_back({x, 20000});          // notch bottom
  for (Coord y = 21000; y <= 100000; y += 1000) u.push_back({60000, y});         // notch's right wall, up
  for (Coord x = 61000; x <= 200000; x += 1000) u.push_back({x, 100000});        // top, on to the right
  for (Coord y = 99000; y >= 0; y -= 1000) u.push_back({200000, y});             // right side, down
  for (Coord x = 199000; x > 0; x -= 1000) u.push_back({x, 0});                  // bottom, back
  std::reverse(u.begin(), u.end());                                               // counter-clockwise
  ASSERT_GT(ClipperLib::Area(u), 0.0);
  Path island = regular(50000, 60000, 5000, 16);
  ASSERT_GT(ClipperLib::Area(island), 0.0);
  const Paths subject{u, island};
  const Paths clip{regular(200000, 10000, 3000, 24)};  // a cut at the far lower right corner
  const Windowed w = windowed_difference(subject, clip);
  EXPECT_FALSE(w.reduced);
  // Without the island the same reduction is taken, and exact.
  const Paths alone{u};
  const Windowed a = windowed_difference(alone, clip);
  ASSERT_TRUE(a.reduced);
  EXPECT_TRUE(a.restored);
  EXPECT_EQ(xor_area(a.result, full_difference(alone, clip)), 0.0);
}

TEST(WindowClip, RandomWallsHolesAndIslandsGiveTheWholeDifference) {
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int reduced = 0, restored = 0;
  const int kCases = 400;
  for (int k = 0; k < kCases; ++k) {
    // A wavy star of 300-600 vertices about the origin (radius 100 000 ± 30 %), holes inside
    // it, an island in the first hole, and a small polygon cut near its boundary.
    Paths subject;
    const int n = 300 + static_cast<int>(300 * u01(rng));
    const double lobes = 3 + std::floor(12 * u01(rng)), amp = 0.3 * u01(rng);
    Path outer;
    for (int i = 0; i < n; ++i) {
      const double t = 2.0 * std::numbers::pi * i / n;
      const double r = 100000.0 * (1.0 + amp * std::sin(lobes * t) + 0.01 * (u01(rng) - 0.5));
      outer.push_back({static_cast<Coord>(std::lround(r * std::cos(t))), static_cast<Coord>(std::lround(r * std::sin(t)))});
    }
    subject.push_back(outer);
    const int holes = static_cast<int>(4 * u01(rng));
    for (int h = 0; h < holes; ++h) {
      const double t = 2.0 * std::numbers::pi * (h + 0.5 * u01(rng)) / 4;
      Path hole = regular(40000 * std::cos(t), 40000 * std::sin(t), 12000, 40 + h, u01(rng));
      std::reverse(hole.begin(), hole.end());  // clockwise
      subject.push_back(hole);
      if (h == 0) subject.push_back(regular(40000 * std::cos(t), 40000 * std::sin(t), 5000, 24, u01(rng)));
    }
    const double ct = 2.0 * std::numbers::pi * u01(rng), cr = 100000.0 * (0.5 + 0.8 * u01(rng));
    const Paths clip{regular(cr * std::cos(ct), cr * std::sin(ct), 1000 + 20000 * u01(rng), 12 + static_cast<int>(40 * u01(rng)))};
    const Windowed w = windowed_difference(subject, clip);
    if (!w.reduced) continue;
    ++reduced;
    if (!w.restored) continue;
    ++restored;
    ASSERT_EQ(xor_area(w.result, full_difference(subject, clip)), 0.0) << "case " << k;
  }
  // Most cuts are small against the wall: the reduction pays and is exact.
  EXPECT_GT(reduced, kCases / 2);
  EXPECT_EQ(restored, reduced);
}
