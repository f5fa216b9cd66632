// The union of consecutive convex sections along a path as the region between their
// envelopes (geom/src/monotone_union.hpp): the same region as a clip's union, one simple
// counter-clockwise polygon, and a refusal wherever that region would not be the union.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "monotone_union.hpp"

using namespace lbr::geom;
using detail::MonotoneUnion;

namespace {

// A regular n-gon (counter-clockwise) of radius r [units] about (cx, cy), turned by `phase`.
Path ngon(double cx, double cy, double r, int n, double phase = 0.0) {
  Path p;
  for (int i = 0; i < n; ++i) {
    const double a = phase + 2.0 * std::numbers::pi * i / n;
    p.push_back({std::llround(cx + r * std::cos(a)), std::llround(cy + r * std::sin(a))});
  }
  return p;
}

// The area of the clip's union of `polys` (non-zero) and how many polygons it has.
double clip_union_area(const Paths& polys, std::size_t& count) {
  ClipperLib::Clipper c;
  c.AddPaths(polys, ClipperLib::ptSubject, true);
  Paths out;
  c.Execute(ClipperLib::ctUnion, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  count = out.size();
  double a = 0.0;
  for (const Path& p : out) a += ClipperLib::Area(p);
  return a;
}

// Sections of a Ø6 mm tool every 0.5 mm along a gently curving path in direction (ux, uy),
// each with its own phase, as a tilted tool's sub-steps give.
Paths path_of_sections(double ux, double uy, int count) {
  Paths polys;
  for (int i = 0; i < count; ++i) {
    const double s = 5000.0 * i, bend = 2000.0 * std::sin(0.05 * i);
    polys.push_back(ngon(s * ux - bend * uy, s * uy + bend * ux, 30000.0 + 500.0 * std::sin(0.3 * i), 40, 0.1 * i));
  }
  return polys;
}

}  // namespace

TEST(MonotoneUnion, SectionsAlongAPathInEachDirectionGiveTheClipsUnion) {
  const double dirs[][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {0.6, -0.8}, {-0.8, -0.6}};
  for (const auto& d : dirs) {
    SCOPED_TRACE(testing::Message() << "direction " << d[0] << ", " << d[1]);
    const Paths polys = path_of_sections(d[0], d[1], 60);
    MonotoneUnion u;
    u.begin(d[0], d[1]);
    for (const Path& p : polys) ASSERT_TRUE(u.add(p));
    EXPECT_EQ(u.count(), polys.size());
    Path out;
    u.write(out);
    std::size_t clip_count = 0;
    const double want = clip_union_area(polys, clip_count);
    ASSERT_EQ(clip_count, 1u);
    // One counter-clockwise polygon without self-intersections (simplifying keeps it whole),
    // with the clip's area up to the rounding of the crossings (half a unit along the outline).
    Paths simple;
    ClipperLib::SimplifyPolygon(out, simple, ClipperLib::pftNonZero);
    ASSERT_EQ(simple.size(), 1u);
    EXPECT_GT(ClipperLib::Area(out), 0.0);
    // Both round the crossings of section edges to the unit grid, each moving the outline by
    // half a unit at most: 2 per section along edges about 5 000 units long (seen: 1 630).
    EXPECT_NEAR(ClipperLib::Area(out), want, 2.0 * 0.5 * 5000.0 * 60.0);
    EXPECT_NEAR(ClipperLib::Area(simple[0]), ClipperLib::Area(out), 1.0);
    // Every section's vertices lie in the union (or on it).
    for (const Path& p : polys)
      for (const Point& q : p) EXPECT_NE(ClipperLib::PointInPolygon(q, out), 0) << q.X << ", " << q.Y;
  }
}

TEST(MonotoneUnion, RefusesAGapAJumpAndAClockwiseSection) {
  MonotoneUnion u;
  u.begin(1, 0);
  ASSERT_TRUE(u.add(ngon(0, 0, 30000, 40)));
  // Beside the first on the same lines x = const but not meeting it: a gap across the axis.
  EXPECT_FALSE(u.add(ngon(10000, 70000, 30000, 40)));
  // Beyond the first's end: no line x = const meets both.
  EXPECT_FALSE(u.add(ngon(70000, 0, 30000, 40)));
  // A tall rectangle that begins inside the first's domain and rises above it: the upper
  // envelope would jump there.
  EXPECT_FALSE(u.add(Path{{20000, -10000}, {90000, -10000}, {90000, 90000}, {20000, 90000}}));
  // Clockwise.
  Path cw = ngon(5000, 0, 30000, 40);
  std::reverse(cw.begin(), cw.end());
  EXPECT_FALSE(u.add(cw));
  EXPECT_EQ(u.count(), 1u);  // the refusals left the union as it was
  ASSERT_TRUE(u.add(ngon(5000, 0, 30000, 40)));
  Path out;
  u.write(out);
  std::size_t n = 0;
  EXPECT_NEAR(ClipperLib::Area(out), clip_union_area(Paths{ngon(0, 0, 30000, 40), ngon(5000, 0, 30000, 40)}, n), 2000.0);
}

TEST(MonotoneUnion, AStraightUnionIsExactAndAStepIsRefused) {
  // A rectangle and a section that begins inside it and ends level with it: the union is the
  // long rectangle, vertex for vertex (the shared corners stay on its sides).
  MonotoneUnion u;
  u.begin(1, 0);
  ASSERT_TRUE(u.add(Path{{0, 0}, {100, 0}, {100, 50}, {0, 50}}));
  ASSERT_TRUE(u.add(Path{{60, 25}, {100, 0}, {200, 0}, {200, 50}, {100, 50}}));
  Path out;
  u.write(out);
  EXPECT_EQ(out, (Path{{0, 0}, {100, 0}, {200, 0}, {200, 50}, {100, 50}, {0, 50}}));
  // A lower rectangle beyond the first's end: the upper envelope would step down at x = 100,
  // which needs a vertical edge the envelopes do not have.
  MonotoneUnion v;
  v.begin(1, 0);
  ASSERT_TRUE(v.add(Path{{0, 0}, {100, 0}, {100, 50}, {0, 50}}));
  EXPECT_FALSE(v.add(Path{{60, 10}, {200, 10}, {200, 40}, {60, 40}}));
}
