// The kernel's rounding at region borders (docs/mesh.md §6): sections get a vertex where they
// cross a region border (split_at_lines), and a clip's result loses the slivers that
// rounding its crossings leaves (remove_slivers), keeping what a neighbour region meets.
#include <cmath>

#include <gtest/gtest.h>

#include "polygon_ops.hpp"

using namespace lbr::geom;
using detail::remove_slivers;
using detail::split_at_lines;

namespace {

const std::vector<Coord> kNone;

}  // namespace

TEST(SplitAtLines, AHalfUnitCrossingRoundsTheSameWayInBothDirections) {
  // (0, 0) -> (2, 1) crosses x = 1 at y = 0.5, a tie; (2, 5) -> (0, 0) at y = 2.5.
  const std::vector<Coord> xs{1};
  Path a{{0, 0}, {2, 1}, {2, 5}}, b{{2, 1}, {0, 0}, {0, 5}}, tmp;
  split_at_lines(a, xs, kNone, tmp);
  split_at_lines(b, xs, kNone, tmp);
  EXPECT_EQ(a, (Path{{0, 0}, {1, 1}, {2, 1}, {2, 5}, {1, 3}}));  // half away from zero
  EXPECT_EQ(b, (Path{{2, 1}, {1, 1}, {0, 0}, {0, 5}, {1, 3}}));  // the same points from the other ends
}

TEST(SplitAtLines, CrossingsInOrderAlongTheEdgeAndNoneWithoutALine) {
  const std::vector<Coord> xs{10, 20, 30}, ys{15};
  Path p{{0, 0}, {40, 40}, {0, 40}}, tmp;
  split_at_lines(p, xs, ys, tmp);
  // (0,0) (10,10) (15,15) (20,20) (30,30) (40,40) (30,40) (20,40) (10,40) (0,40) (0,15)
  const Path want{{0, 0}, {10, 10}, {15, 15}, {20, 20}, {30, 30}, {40, 40}, {30, 40}, {20, 40}, {10, 40}, {0, 40}, {0, 15}};
  EXPECT_EQ(p, want);
  Path q{{11, 11}, {19, 11}, {19, 14}}, q0 = q;
  split_at_lines(q, xs, ys, tmp);
  EXPECT_EQ(q, q0);
}

TEST(SplitAtLines, EveryCrossingOfABorderIsAVertexOnIt) {
  // A 64-gon of radius 20 000 units around (3, 7) against the border x = 10 000: two
  // crossings, each a vertex exactly on the line, and no edge crosses the line any more.
  Path p, tmp;
  for (int k = 0; k < 64; ++k) {
    const double a = 2 * 3.14159265358979 * k / 64;
    p.push_back({static_cast<Coord>(std::llround(3 + 20000 * std::cos(a))), static_cast<Coord>(std::llround(7 + 20000 * std::sin(a)))});
  }
  const std::vector<Coord> xs{10000};
  split_at_lines(p, xs, kNone, tmp);
  EXPECT_EQ(p.size(), 66u);
  int on = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Point& a = p[i];
    const Point& b = p[(i + 1) % p.size()];
    on += a.X == 10000 ? 1 : 0;
    EXPECT_FALSE((a.X < 10000 && b.X > 10000) || (a.X > 10000 && b.X < 10000)) << i;
  }
  EXPECT_EQ(on, 2);
}

TEST(RemoveSlivers, ASpikeOneUnitWideGoesAndTheCornersStay) {
  const Rect region{0, 0, 1000, 1000};
  // A rectangle with a spike one unit wide up to (500, 900): its tip goes, then (500, 100),
  // a unit from (499, 100), then (499, 100), on the line through its neighbours.
  Path p{{100, 100}, {499, 100}, {500, 900}, {500, 100}, {900, 100}, {900, 800}, {100, 800}}, tmp;
  EXPECT_TRUE(remove_slivers(p, region, 1.415, tmp));
  const Path want{{100, 100}, {900, 100}, {900, 800}, {100, 800}};
  EXPECT_EQ(p, want);
  Path square{{100, 100}, {900, 100}, {900, 800}, {100, 800}};
  EXPECT_FALSE(remove_slivers(square, region, 1.415, tmp));
}

TEST(RemoveSlivers, OnTheBorderOnlyTheTipOfASpikeGoes) {
  const Rect region{0, 0, 1000, 1000};
  // The contour reaches the border x = 1000 at y = 501, steps back to y = 500 along it and
  // runs up the border (ball raster, level 291: C -> A -> B). The tip (1000, 501) goes; the
  // material then meets the border from y = 500, as the neighbour's contour does.
  Path p{{0, 0}, {1000, 501}, {1000, 500}, {1000, 1000}, {0, 1000}}, tmp;
  EXPECT_TRUE(remove_slivers(p, region, 1.415, tmp));
  const Path want{{0, 0}, {1000, 500}, {1000, 1000}, {0, 1000}};
  EXPECT_EQ(p, want);
  // A long edge along the border with a one-unit turn at its end is a corner, not a spike
  // (Joined.HelixCutInOneBatchEqualsTheMovesCutOneByOne: dropping it let the contour leave
  // the border, clip after clip).
  Path q{{0, 0}, {862, 0}, {861, 1}, {0, 1000}}, q0 = q;
  remove_slivers(q, region, 1.415, tmp);
  EXPECT_EQ(q[0], q0[0]);
  EXPECT_EQ(q[1], q0[1]);
}

TEST(RemoveSlivers, ATinyContourIsEmptied) {
  const Rect region{0, 0, 1000, 1000};
  Path p{{10, 10}, {11, 10}, {11, 11}}, tmp;
  EXPECT_TRUE(remove_slivers(p, region, 1.415, tmp));
  EXPECT_TRUE(p.empty());
}

namespace {

Cell cell_of(std::vector<Polygon> polys) {
  Cell c;
  for (Polygon& p : polys) p.bbox = bounds_of(p.outer.pts);
  c.polys = std::move(polys);
  detail::refresh_cell(c);
  return c;
}

Rect material_box_all(const Cell& c, const Rect& r) {
  std::vector<std::uint32_t> all;
  for (std::uint32_t i = 0; i < c.polys.size(); ++i) all.push_back(i);
  return detail::material_box(c, all, r);
}

}  // namespace

// The box of the material inside a rectangle, which a clip's paths are cut to: from the
// edges inside it and its corners in the material; nothing where the rectangle lies in a
// hole or beyond the material.
TEST(MaterialBox, CornersInMaterialEdgesInsideAndHoles) {
  Polygon sq;
  sq.outer.pts = {{0, 0}, {100, 0}, {100, 100}, {0, 100}};
  sq.holes.push_back(Contour{{{40, 40}, {40, 60}, {60, 60}, {60, 40}}, 0});
  const Cell c = cell_of({sq});
  EXPECT_TRUE(material_box_all(c, Rect{45, 45, 55, 55}).empty());       // in the hole
  EXPECT_TRUE(material_box_all(c, Rect{110, 10, 120, 20}).empty());     // beside the square
  EXPECT_EQ(material_box_all(c, Rect{30, 30, 50, 50}), (Rect{30, 30, 50, 50}));  // a corner in the hole
  EXPECT_EQ(material_box_all(c, Rect{90, 10, 120, 20}), (Rect{90, 10, 100, 20}));
  EXPECT_EQ(material_box_all(c, Rect{45, 20, 55, 50}), (Rect{45, 20, 55, 40}));  // down to the hole's side
  EXPECT_EQ(material_box_all(c, Rect{-10, -10, 200, 200}), (Rect{0, 0, 100, 100}));
}

TEST(MaterialBox, ASlantedEdgeIsCutToTheRectangle) {
  Polygon tri;
  tri.outer.pts = {{0, 0}, {10, 0}, {0, 10}};
  const Cell c = cell_of({tri});
  // x + y <= 10 within [4, 20]²: the triangle (4, 4), (6, 4), (4, 6).
  EXPECT_EQ(material_box_all(c, Rect{4, 4, 20, 20}), (Rect{4, 4, 6, 6}));
  // A crossing between grid points is rounded outwards: x + y <= 10 within y >= 3.5 is not
  // representable, so use y in [3, 20], x in [5, 20]: (5, 3) .. (7, 3), (5, 5).
  EXPECT_EQ(material_box_all(c, Rect{5, 3, 20, 20}), (Rect{5, 3, 7, 5}));
  EXPECT_TRUE(material_box_all(c, Rect{6, 6, 20, 20}).empty());
}
