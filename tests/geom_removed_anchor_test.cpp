// Clips left out inside a piece the cell has already had removed (geom/src/clip_reach.hpp,
// PriorPiece; docs/lbr-conventions.md "Clips inside a removed piece"): the grown polygon
// holds every point within band · cos 30° of the polygon and none farther than the band;
// a live-like pass of one short tilted move per batch, each step shorter than the band,
// removes what the same pass in one batch removes, up to the band along its walls (a test
// against the last batch's piece instead of the last piece each cell had removed would drift
// with the tool and leave the groove standing).
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "clip_reach.hpp"
#include "test_util.hpp"

using namespace lbr;
using geom::detail::PriorPiece;

namespace {

geom::Path polygon(const std::vector<std::pair<double, double>>& mm) {
  geom::Path p;
  for (const auto& [x, y] : mm)
    p.push_back({static_cast<ClipperLib::cInt>(std::llround(x * geom::kUnitsPerMm)),
                 static_cast<ClipperLib::cInt>(std::llround(y * geom::kUnitsPerMm))});
  return p;
}

// Distance [units] from q to the convex polygon p (0 inside).
double distance_to(const geom::Path& p, double x, double y) {
  bool inside = true;
  double d = INFINITY;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double ax = static_cast<double>(p[i].X), ay = static_cast<double>(p[i].Y);
    const double bx = static_cast<double>(p[(i + 1) % p.size()].X), by = static_cast<double>(p[(i + 1) % p.size()].Y);
    const double ex = bx - ax, ey = by - ay;
    if (ex * (y - ay) - ey * (x - ax) < 0.0) inside = false;
    const double t = std::clamp(((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
    d = std::min(d, std::hypot(x - ax - t * ex, y - ay - t * ey));
  }
  return inside ? 0.0 : d;
}

}  // namespace

TEST(PriorPiece, HoldsTheBandTimesCos30AndNoMoreThanTheBand) {
  // A sliver triangle with a 4-degree apex: without bevels its grown region would reach
  // band / sin 2° = 28.7 bands beyond the apex.
  const double inner = 202.0 * std::cos(test::kPi / 6.0);
  const std::vector<geom::Path> polys{polygon({{0, 0}, {2, 0}, {2, 1.5}, {0, 1.5}}),
                                      polygon({{0, 0}, {10, 0.35}, {0, 0.7}}),
                                      polygon({{1, 0}, {0.5, 0.866}, {-0.5, 0.866}, {-1, 0}, {-0.5, -0.866}, {0.5, -0.866}})};
  const double band = 202.0;  // 20.2 µm: reach_band_units(0.01)
  std::mt19937 rng(7);
  for (const geom::Path& poly : polys) {
    PriorPiece piece;
    ASSERT_TRUE(piece.set(poly, band));
    const geom::Rect b = geom::bounds_of(poly);
    const double x0 = static_cast<double>(b.x0), x1 = static_cast<double>(b.x1);
    const double y0 = static_cast<double>(b.y0), y1 = static_cast<double>(b.y1);
    std::uniform_real_distribution<double> ux(x0 - 3 * band, x1 + 3 * band), uy(y0 - 3 * band, y1 + 3 * band);
    int near = 0, far = 0;
    for (int i = 0; i < 200000; ++i) {
      const geom::Point q{static_cast<ClipperLib::cInt>(ux(rng)), static_cast<ClipperLib::cInt>(uy(rng))};
      const double d = distance_to(poly, static_cast<double>(q.X), static_cast<double>(q.Y));
      const bool held = piece.holds(q);
      if (d <= inner - 0.5) {
        EXPECT_TRUE(held) << "d " << d;
      }
      if (held) {
        EXPECT_LE(d, band + 0.5);
        EXPECT_TRUE(piece.box_holds(geom::Rect{q.X, q.Y, q.X, q.Y}));
        if (d > 0.0) ++near;
      } else {
        ++far;
      }
    }
    EXPECT_GT(near, 100);
    EXPECT_GT(far, 100);
  }
  // The apex of the sliver: 0.8 bands out along its axis is held, 1.1 bands out is not.
  PriorPiece sliver;
  ASSERT_TRUE(sliver.set(polys[1], band));
  EXPECT_TRUE(sliver.holds({100000 + static_cast<ClipperLib::cInt>(0.8 * band), 3500}));
  EXPECT_FALSE(sliver.holds({100000 + static_cast<ClipperLib::cInt>(1.1 * band), 3500}));
}

TEST(PriorPiece, RefusesClockwiseConcaveAndDegeneratePolygons) {
  PriorPiece p;
  EXPECT_FALSE(p.set(polygon({{0, 0}, {0, 1}, {1, 1}, {1, 0}}), 202.0));  // clockwise
  EXPECT_TRUE(p.empty());
  EXPECT_FALSE(p.set(polygon({{0, 0}, {2, 0}, {1, 0.5}, {2, 1}, {0, 1}}), 202.0));  // a notch
  EXPECT_FALSE(p.set(polygon({{0, 0}, {1, 0}, {2, 0}}), 202.0));                    // no area
  // A pentagram turns left at every vertex but goes round twice.
  std::vector<std::pair<double, double>> star;
  for (int k = 0; k < 5; ++k) star.emplace_back(std::cos(0.8 * test::kPi * k), std::sin(0.8 * test::kPi * k));
  EXPECT_FALSE(p.set(polygon(star), 202.0));
  EXPECT_FALSE(p.set(polygon({{0, 0}, {1, 0}}), 202.0));
  EXPECT_FALSE(p.box_holds(geom::Rect{0, 0, 1, 1}));
  // Repeated vertices are edges without length: left out.
  EXPECT_TRUE(p.set(polygon({{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}}), 202.0));
  EXPECT_TRUE(p.holds({5000, 5000}));
  EXPECT_TRUE(p.holds({5000, 10000 + 170}));
  EXPECT_FALSE(p.holds({5000, 10000 + 210}));
}

TEST(RemovedAnchor, OneShortTiltedMovePerBatchRemovesThePassUpToTheBand) {
  // A ball Ø6 tilted 20° about X, 2 mm deep, 3 mm along X in steps of 10 µm (the band is
  // 20.2 µm), with the tilt turning slowly so that every move is a tilted sweep: one move per
  // batch as a live call at 1 kHz and 600 mm/min has, against the whole pass in one batch.
  const auto ball = geom::CutterShape::build(test::tool(geom::ToolKind::Ball, 6), 0.01);
  auto pose = [](int i) {
    const double a = (20.0 + 0.002 * i) * test::kPi / 180.0;
    return test::at(10.0 + 0.01 * i, 10.0, -2.0, {0, -std::sin(a), std::cos(a)});
  };
  constexpr int kSteps = 300;
  std::vector<geom::SweepRef> pass;
  for (int i = 0; i < kSteps; ++i) pass.push_back({&ball, pose(i), pose(i + 1), static_cast<geom::MoveId>(1 + i)});
  geom::LbrSolid live(test::box_spec({0, 0, -6}, {20, 20, 0}, 0.1));
  geom::SubtractStats st;
  for (std::size_t i = 0; i < pass.size(); ++i) st += live.subtract(std::span<const geom::SweepRef>(pass).subspan(i, 1));
  geom::LbrSolid whole(test::box_spec({0, 0, -6}, {20, 20, 0}, 0.1));
  whole.subtract(pass);
  std::printf("one move per batch: %.6f mm3, %llu clips left out inside a removed piece of %llu; one batch: %.6f mm3\n",
              test::removed(live), static_cast<unsigned long long>(st.cells_in_anchor),
              static_cast<unsigned long long>(st.cells_tested), test::removed(whole));
  EXPECT_GT(st.cells_in_anchor, 1000u);
  // The groove: 3 mm long, its two walls and the front 2 mm deep and about 6 mm wide. A
  // section left out may leave the band standing on its walls:
  // (2 × 3 + 6) mm × 2 mm × 20.2 µm = 0.48 mm³ at most (measured: 0.023).
  // A test against the last batch's piece drifts with the tool: it left 8.2 mm³ standing.
  const double groove = test::removed(whole);
  EXPECT_GT(groove, 30.0);
  EXPECT_NEAR(test::removed(live), groove, 0.48);
  EXPECT_LE(test::removed(live), groove + 0.01);
  EXPECT_EQ(live.check_invariants(), "");
}
