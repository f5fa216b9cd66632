// Sections of sweeps: closed forms for 3-axis and tilted tools, and agreement between the
// vertical fast path and the general support-function path.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <utility>
#include <vector>

#include "geom/sweep.hpp"
#include "test_util.hpp"

using namespace lbr;
using geom::ToolKind;

namespace {

constexpr double kTol = 0.001;  // chord tolerance [mm]
// How far rounding a vertex to the unit grid can move it: half a unit diagonal [mm].
const double kHalfUnitMm = 0.5 * std::sqrt(2.0) / geom::kUnitsPerMm;

double section_area_mm2(const geom::Sweep& s, double z, std::size_t* count = nullptr) {
  geom::Paths out;
  geom::SectionScratch sc;
  const std::size_t n = s.section(z, out, sc);
  if (count != nullptr) *count = n;
  // Union (the pieces of a rotating move may overlap) then area.
  ClipperLib::Clipper c;
  c.AddPaths(out, ClipperLib::ptSubject, true);
  geom::Paths u;
  c.Execute(ClipperLib::ctUnion, u, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double a = 0.0;
  for (const auto& p : u) a += ClipperLib::Area(p);
  return geom::area_to_mm2(a);
}

}  // namespace

TEST(Sweep, CircleSegmentsFollowTolerance) {
  const int n = geom::Sweep::circle_segments(5.0, kTol);
  // Both polygons on radius 5 deviate from the circle by at most 1 µm on either side, and
  // n is the least such count (within the rounding of the start).
  auto worst = [](double g, int k) { return 5.0 * std::max(g - 1.0, 1.0 - g * std::cos(test::kPi / k)); };
  EXPECT_LE(worst(geom::Sweep::circle_grow_width(n), n), kTol);
  EXPECT_LE(worst(geom::Sweep::circle_grow_area(n), n), kTol);
  EXPECT_GT(worst(geom::Sweep::circle_grow_width(n - 2), n - 2), kTol);
  // Width-keeping: the mean of the polygon's support function, ρ·sin θ / θ, is the radius;
  // area-keeping: n·ρ²·sin θ·cos θ is π·r².
  const double th = test::kPi / n;
  EXPECT_NEAR(geom::Sweep::circle_grow_width(n) * std::sin(th) / th, 1.0, 1e-12);
  const double ga = geom::Sweep::circle_grow_area(n);
  EXPECT_NEAR(n * ga * ga * std::sin(th) * std::cos(th), test::kPi, 1e-12);
  // The vertices are on both sides: outside the circle by about r·θ²/6 (width-keeping).
  EXPECT_GT(5.0 * (geom::Sweep::circle_grow_width(n) - 1.0), 0.4 * kTol);
  EXPECT_EQ(geom::Sweep::circle_segments(0.0, kTol), 1);
  EXPECT_EQ(geom::Sweep::circle_segments(1e-6, kTol), 8);
}

TEST(Sweep, HorizontalFlatMoveIsAStadium) {
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const geom::Sweep s(shape, test::at(0, 0, 0), test::at(20, 0, 0));
  EXPECT_TRUE(s.vertical());
  EXPECT_DOUBLE_EQ(s.z_min(), 0.0);
  EXPECT_DOUBLE_EQ(s.z_max(), 30.0);
  std::size_t n = 0;
  const double a = section_area_mm2(s, 1.0, &n);
  EXPECT_EQ(n, 1u);
  const double exact = 2 * 5.0 * 20.0 + test::kPi * 25.0;
  const double perimeter = 40.0 + 2 * test::kPi * 5.0;
  EXPECT_NEAR(a, exact, perimeter * kTol);
  EXPECT_EQ(section_area_mm2(s, -0.01), 0.0);  // below the tip
  EXPECT_EQ(section_area_mm2(s, 30.01), 0.0);  // above the flutes
}

TEST(Sweep, BallPlungeSectionIsTheWidestDisk) {
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const geom::Sweep s(shape, test::at(0, 0, 10), test::at(0, 0, 0));
  // At z = 1 the widest disk is at h = 1: r² = 9 - 4 = 5.
  EXPECT_NEAR(section_area_mm2(s, 1.0), test::kPi * 5.0, 2 * test::kPi * std::sqrt(5.0) * 2 * kTol);
}

TEST(Sweep, TiltedFlatToolGivesTheEllipse) {
  const double th = 30.0 * test::kPi / 180.0;
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const geom::Vec3 ax{std::sin(th), 0, std::cos(th)};
  const geom::Sweep s(shape, test::at(0, 0, 0, ax), test::at(0, 0, 0, ax));
  EXPECT_FALSE(s.vertical());
  EXPECT_NEAR(s.z_min(), -5.0 * std::sin(th), 1e-9);
  const double a = section_area_mm2(s, 5.0);
  const double exact = test::kPi * 25.0 / std::cos(th);
  EXPECT_NEAR(a, exact, 2 * test::kPi * 5.8 * kTol);
}

TEST(Sweep, AxisParallelToTheLevelPlane) {
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const geom::Sweep s(shape, test::at(0, 0, 0, {1, 0, 0}), test::at(0, 0, 0, {1, 0, 0}));
  // A cylinder of radius 5 along X from 0 to 30, cut by z = 3: a 30 x 8 rectangle.
  EXPECT_NEAR(section_area_mm2(s, 3.0), 30.0 * 8.0, 80.0 * kTol);
  EXPECT_NEAR(section_area_mm2(s, 0.0), 30.0 * 10.0, 80.0 * kTol);
  EXPECT_EQ(section_area_mm2(s, 5.01), 0.0);
}

TEST(Sweep, GeneralPathAgreesWithVerticalFastPath) {
  // A ramped ball move and a bull-nose ramp: the fast path (axis exactly +Z) and the general
  // path (axis tilted by 1e-9 rad) must give the same sections within the chord tolerance.
  for (const auto& t : {test::tool(ToolKind::Ball, 6), test::tool(ToolKind::Bull, 12, 2), test::tool(ToolKind::Drill, 8, 118)}) {
    const auto shape = geom::CutterShape::build(t, kTol);
    const geom::Vec3 almost{1e-9, 0, 1};
    const geom::Sweep fast(shape, test::at(0, 0, 2), test::at(10, 4, 0));
    const geom::Sweep gen(shape, test::at(0, 0, 2, almost), test::at(10, 4, 0, almost));
    ASSERT_TRUE(fast.vertical());
    ASSERT_FALSE(gen.vertical());
    for (double z : {0.05, 0.5, 1.0, 1.7, 2.5, 4.0}) {
      const double af = section_area_mm2(fast, z), ag = section_area_mm2(gen, z);
      EXPECT_GT(af, 0.0);
      EXPECT_NEAR(af, ag, 2 * (2 * 10.8 + 2 * test::kPi * 6) * kTol) << geom::to_string(t.kind) << " z " << z;
    }
  }
}

TEST(Sweep, RotatingAxisIsSubdividedAndCoversBothEnds) {
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const double th = 20.0 * test::kPi / 180.0;
  const geom::Sweep rot(shape, test::at(0, 0, 0, {0, 0, 1}), test::at(0, 0, 0, {std::sin(th), 0, std::cos(th)}));
  const geom::Sweep start(shape, test::at(0, 0, 0, {1e-12, 0, 1}), test::at(0, 0, 0, {1e-12, 0, 1}));
  const geom::Sweep end(shape, test::at(0, 0, 0, {std::sin(th), 0, std::cos(th)}),
                        test::at(0, 0, 0, {std::sin(th), 0, std::cos(th)}));
  // The rotating sweep contains both end poses' sections, and is larger than either.
  const double z = 8.0;
  const double ar = section_area_mm2(rot, z), as = section_area_mm2(start, z), ae = section_area_mm2(end, z);
  EXPECT_GT(ar, as + 1.0);
  EXPECT_GT(ar, ae + 1.0);
  // Bounded by the hull of the two ellipses' extents: x from -5 to 8 tan(20°) + 5/cos(20°).
  EXPECT_LT(ar, (8.0 * std::tan(th) + 5.0 / std::cos(th) + 5.0) * 10.0);
}

TEST(Sweep, StadiumFastPathAgreesWithGeneralPathInAnyDirection) {
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const geom::Vec3 almost{0, 1e-9, 1};
  for (double deg : {0.0, 17.0, 45.0, 90.0, 133.3, 180.0, 271.0}) {
    const double a = deg * test::kPi / 180.0;
    const geom::Vec3 e{7.0 * std::cos(a), 7.0 * std::sin(a), 0.0};
    const geom::Sweep fast(shape, test::at(0, 0, 0), test::at(e.x, e.y, 0));
    const geom::Sweep gen(shape, test::at(0, 0, 0, almost), test::at(e.x, e.y, 0, almost));
    for (double z : {0.5, 2.0, 4.0}) {
      const double r = shape.radius_at(z);
      const double exact = 2 * r * 7.0 + test::kPi * r * r;
      EXPECT_NEAR(section_area_mm2(fast, z), exact, 2 * (14.0 + 2 * test::kPi * r) * kTol) << deg << " " << z;
      EXPECT_NEAR(section_area_mm2(gen, z), exact, 2 * (14.0 + 2 * test::kPi * r) * kTol) << deg << " " << z;
    }
  }
}

// Ramp sections (several disks of different radii along the move) against the exact
// section of the piecewise-linear tool: the section is convex and counter-clockwise, and its
// support value in every direction equals max over t of c(t)·u + r(z - z(t)) within the
// polygonisation band. Random moves from a fixed seed, every tool kind, steep and shallow.
TEST(Sweep, RampSectionsMatchTheExactSupportFunction) {
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  auto uni = [&](double lo, double hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  const std::vector<geom::Tool> tools{test::tool(ToolKind::Ball, 6), test::tool(ToolKind::Bull, 12, 2),
                                      test::tool(ToolKind::Drill, 8, 118), test::tool(ToolKind::VBit, 10, 90),
                                      test::tool(ToolKind::Flat, 10), test::tool(ToolKind::Ball, 1)};
  int checked = 0;
  for (const auto& t : tools) {
    const auto shape = geom::CutterShape::build(t, kTol);
    for (int m = 0; m < 40; ++m) {
      const double len = m % 4 == 0 ? uni(0.0, 0.05) : uni(0.1, 12.0);
      const double ang = uni(0.0, 2 * test::kPi);
      const double dz = m % 5 == 0 ? uni(-20.0, 20.0) : uni(-2.0, 2.0);
      const geom::Vec3 a{uni(-5, 5), uni(-5, 5), 0.0};
      const geom::Vec3 b{a.x + len * std::cos(ang), a.y + len * std::sin(ang), dz};
      const geom::Sweep s(shape, test::at(a.x, a.y, a.z), test::at(b.x, b.y, b.z));
      const double z = uni(std::min(a.z, b.z) - 0.5, std::max(a.z, b.z) + shape.height() * 0.5);
      geom::Paths out;
      geom::SectionScratch sc;
      s.section(z, out, sc);
      // The support value c(t)·u + r(z - z(t)) is piecewise linear in t (linear profile),
      // so its maximum lies at t = 0, 1, or where the plane meets a profile station or an
      // end of the cutting part.
      std::vector<double> ts{0.0, 1.0};
      if (b.z != a.z) {
        for (const auto& st : shape.stations) ts.push_back((z - st.h - a.z) / (b.z - a.z));
        ts.push_back((z - a.z) / (b.z - a.z));
      }
      std::vector<std::array<double, 3>> disks;  // x, y, r
      for (double tt : ts) {
        if (!(tt >= 0.0 && tt <= 1.0)) continue;
        const double h = z - (a.z + (b.z - a.z) * tt);
        if (h < -1e-12 || h > shape.height() + 1e-12) continue;
        disks.push_back({a.x + (b.x - a.x) * tt, a.y + (b.y - a.y) * tt, shape.radius_at(std::clamp(h, 0.0, shape.height()))});
      }
      double rmax = 0.0;
      for (const auto& d : disks) rmax = std::max(rmax, d[2]);
      if (disks.empty() || rmax < 0.01) continue;
      ASSERT_EQ(out.size(), 1u) << geom::to_string(t.kind) << " move " << m;
      const geom::Path& p = out[0];
      ASSERT_GE(p.size(), 3u);
      for (std::size_t i = 0; i < p.size(); ++i) {  // convex, counter-clockwise (within rounding)
        const auto& o = p[i];
        const auto& q = p[(i + 1) % p.size()];
        const auto& w = p[(i + 2) % p.size()];
        const double ex = static_cast<double>(q.X - o.X), ey = static_cast<double>(q.Y - o.Y);
        const double cr = ex * static_cast<double>(w.Y - o.Y) - ey * static_cast<double>(w.X - o.X);
        const double fx = static_cast<double>(w.X - q.X), fy = static_cast<double>(w.Y - q.Y);
        ASSERT_GE(cr, -1.5 * (std::hypot(ex, ey) + std::hypot(fx, fy))) << geom::to_string(t.kind) << " move " << m << " vertex " << i;
      }
      const int n = geom::Sweep::circle_segments(rmax, kTol);
      // The polygons' support is within ρ·cos(π/n) .. ρ of the disks' (ρ = r·circle_grow_width(n)).
      const double g = geom::Sweep::circle_grow_width(n);
      const double band = rmax * std::max(g - 1.0, 1.0 - g * std::cos(test::kPi / n));
      for (int k = 0; k < 720; ++k) {
        const double ux = std::cos(k * test::kPi / 360), uy = std::sin(k * test::kPi / 360);
        double exact = -INFINITY;
        for (const auto& d : disks) exact = std::max(exact, d[0] * ux + d[1] * uy + d[2]);
        double poly = -INFINITY;
        for (const auto& v : p) poly = std::max(poly, geom::to_mm(v.X) * ux + geom::to_mm(v.Y) * uy);
        ASSERT_NEAR(poly, exact, band + 2e-4) << geom::to_string(t.kind) << " move " << m << " dir " << k;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 150);
}

namespace {

double area_units(const geom::Paths& ps, ClipperLib::ClipType op = ClipperLib::ctUnion, const geom::Paths& clip = {}) {
  ClipperLib::Clipper c;
  c.AddPaths(ps, ClipperLib::ptSubject, true);
  if (!clip.empty()) c.AddPaths(clip, ClipperLib::ptClip, true);
  geom::Paths u;
  c.Execute(op, u, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double a = 0.0;
  for (const auto& p : u) a += ClipperLib::Area(p);
  return a;
}

double perimeter_units(const geom::Path& p) {
  double l = 0.0;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    l += std::hypot(static_cast<double>(p[i].X - p[j].X), static_cast<double>(p[i].Y - p[j].Y));
  return l;
}

}  // namespace

// trim_covered() on the sections of two consecutive moves: b' ⊆ b, a ∪ b' = a ∪ b, and for
// moves that continue each other about half of b's vertices go.
TEST(Sweep, TrimCoveredKeepsTheUnionOfConsecutiveSections) {
  std::uint64_t state = 12345;
  auto uni = [&](double lo, double hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  std::size_t before = 0, after = 0;
  int dropped = 0, checked = 0;
  for (const auto& t : {test::tool(ToolKind::Ball, 6), test::tool(ToolKind::Flat, 10), test::tool(ToolKind::Bull, 12, 2),
                        test::tool(ToolKind::VBit, 10, 90)}) {
    const auto shape = geom::CutterShape::build(t, kTol);
    for (int m = 0; m < 60; ++m) {
      const geom::Vec3 p0{uni(-3, 3), uni(-3, 3), uni(-1, 1)};
      const double ang = uni(0, 2 * test::kPi), turn = m % 3 == 0 ? uni(-3.0, 3.0) : uni(-0.3, 0.3);
      const double l1 = uni(0.5, 8), l2 = m % 7 == 0 ? uni(0.0, 0.2) : uni(0.5, 8);
      const geom::Vec3 p1{p0.x + l1 * std::cos(ang), p0.y + l1 * std::sin(ang), p0.z + uni(-1, 1)};
      const geom::Vec3 p2{p1.x + l2 * std::cos(ang + turn), p1.y + l2 * std::sin(ang + turn), p1.z + (m % 2 ? 0.0 : uni(-1, 1))};
      const geom::Sweep sa(shape, test::at(p0.x, p0.y, p0.z), test::at(p1.x, p1.y, p1.z));
      const geom::Sweep sb(shape, test::at(p1.x, p1.y, p1.z), test::at(p2.x, p2.y, p2.z));
      const double z = uni(std::max(p0.z, std::max(p1.z, p2.z)) - 0.5, std::max(p0.z, std::max(p1.z, p2.z)) + 4.0);
      geom::Paths a, b;
      geom::SectionScratch sc;
      sa.section(z, a, sc);
      const geom::Capsule cap = sc.core;
      sb.section(z, b, sc);
      if (a.size() != 1 || b.size() != 1 || !cap.valid()) continue;
      // The capsule lies inside a's polygon.
      geom::Paths capsule;
      double cap_perimeter = 0.0;
      for (int i = 0; i <= 10; ++i) {  // the capsule is the union of the interpolated disks
        const double w = i / 10.0;
        const double cx = cap.x1 + w * (cap.x2 - cap.x1), cy = cap.y1 + w * (cap.y2 - cap.y1);
        const double r = cap.r1 + w * (cap.r2 - cap.r1);
        geom::Path c;
        for (int k = 0; k < 64; ++k)
          c.push_back({geom::to_units(cx + r * std::cos(k * test::kPi / 32)), geom::to_units(cy + r * std::sin(k * test::kPi / 32))});
        cap_perimeter += perimeter_units(c);
        capsule.push_back(c);
      }
      ASSERT_LE(area_units(capsule, ClipperLib::ctDifference, a), cap_perimeter) << "move " << m;
      geom::Path trimmed = b[0];
      std::vector<std::uint8_t> flags;
      const bool keep = geom::trim_covered(trimmed, cap, flags);
      const double slack = 2.0 * (perimeter_units(b[0]) + 10.0);
      if (!keep) {
        ++dropped;
        EXPECT_LE(area_units(b, ClipperLib::ctDifference, a), slack) << "move " << m;  // b inside a
        continue;
      }
      EXPECT_LE(area_units({trimmed}, ClipperLib::ctDifference, b), 1.0) << "move " << m;  // b' ⊆ b
      geom::Paths ab = a, ab2 = a;
      ab.push_back(b[0]);
      ab2.push_back(trimmed);
      EXPECT_NEAR(area_units(ab2), area_units(ab), slack) << "move " << m;
      before += b[0].size();
      after += trimmed.size();
      ++checked;
    }
  }
  EXPECT_GT(checked, 150);
  EXPECT_LT(static_cast<double>(after), 0.75 * static_cast<double>(before));
  // A section wholly inside the previous one is dropped: a ball raised by 1 mm in the
  // middle of a pass cuts a smaller disk on the plane z = 1.5.
  const auto ball = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const geom::Sweep pass(ball, test::at(0, 0, 0), test::at(8, 0, 0));
  const geom::Sweep raised(ball, test::at(4, 0, 1), test::at(4.1, 0, 1));
  geom::Paths a, b;
  geom::SectionScratch sc;
  pass.section(1.5, a, sc);
  const geom::Capsule cap = sc.core;
  raised.section(1.5, b, sc);
  ASSERT_EQ(b.size(), 1u);
  std::vector<std::uint8_t> flags;
  geom::Path kept = b[0];
  EXPECT_FALSE(geom::trim_covered(kept, cap, flags));
  EXPECT_EQ(kept, b[0]);
  EXPECT_EQ(dropped, 0);  // consecutive moves share a boundary, so none of the random ones
}

TEST(Sweep, TiltedPiecesWithNeighbourCoversKeepTheUnionWithFewerVertices) {
  // A bull Ø10 R2 along X in 0.5 mm moves, its axis leaning by 1° more per move along its
  // motion (a sub-step or two each: the hull's offsets lie along the swept surface, Sweep's
  // TwistBound::across), cut by one plane through the corner and one through the flutes'
  // cylinder, at the milling profiles' 10 µm (at 1 µm the flat end's turn, whose hull dips
  // ρφ/2 below the swept end, asks for 26 sub-steps a move on the corner's plane, too thin
  // for a neighbour's coarse polygon to cover any arc). Each piece refined only
  // where neither neighbour's coarse polygon covers it (the engine's way) must give the same
  // union as every piece refined in full, with far fewer vertices.
  auto bull = test::tool(ToolKind::Bull, 10);
  bull.corner_radius_mm = 2.0;
  const double tol = 0.01;
  const auto shape = geom::CutterShape::build(bull, tol);
  ASSERT_DOUBLE_EQ(shape.core_radius_mm, 3.0);  // the rounded core model (Hull3)
  auto pose = [](int i) {
    const double a = (1.0 * i) * test::kPi / 180.0;
    return test::at(0.5 * i, 0, 0, {std::sin(a), 0, std::cos(a)});
  };
  std::vector<geom::Sweep> sweeps;
  for (int i = 0; i < 12; ++i) sweeps.emplace_back(shape, pose(i), pose(i + 1));
  auto union_area = [](const geom::Paths& ps) {
    ClipperLib::Clipper c;
    c.AddPaths(ps, ClipperLib::ptSubject, true);
    geom::Paths u;
    c.Execute(ClipperLib::ctUnion, u, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
    double a = 0.0;
    for (const auto& p : u) a += ClipperLib::Area(p);
    return geom::area_to_mm2(a);
  };
  for (double z : {1.5, 8.0}) {
    std::vector<geom::TiltedPiece> pieces;
    for (std::uint32_t k = 0; k < sweeps.size(); ++k) {
      const std::size_t before = pieces.size();
      sweeps[k].tilted_pieces(z, pieces);
      for (std::size_t i = before; i < pieces.size(); ++i) pieces[i].sweep = k;
    }
    ASSERT_GE(pieces.size(), sweeps.size()) << "z " << z;  // a sub-step or two per move
    geom::SectionScratch sc;
    geom::Paths covered, full;
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      const auto& sw = sweeps[pieces[i].sweep];
      sw.build_piece(pieces[i], {i > 0 ? &pieces[i - 1] : nullptr, i + 1 < pieces.size() ? &pieces[i + 1] : nullptr},
                     covered, sc);
      sw.build_piece(pieces[i], {}, full, sc);
    }
    ASSERT_EQ(full.size(), pieces.size());
    // The engine's way since: the previous piece's refined polygon covers too
    // (build_piece's last and keep).
    geom::ConvexCover cover[2];
    geom::Paths after_last;
    for (std::size_t i = 0; i < pieces.size(); ++i)
      sweeps[pieces[i].sweep].build_piece(pieces[i],
                                          {i > 0 ? &pieces[i - 1] : nullptr, i + 1 < pieces.size() ? &pieces[i + 1] : nullptr,
                                           i > 0 ? &cover[(i - 1) % 2] : nullptr, &cover[i % 2]},
                                          after_last, sc);
    std::size_t vc = 0, vf = 0, vl = 0;
    for (const auto& p : covered) vc += p.size();
    for (const auto& p : full) vf += p.size();
    for (const auto& p : after_last) vl += p.size();
    EXPECT_LT(vc * 2, vf) << "z " << z << ": " << vc << " vertices with covers, " << vf << " without";
    EXPECT_LT(vl, vc) << "z " << z << ": " << vl << " vertices with the last polygon, " << vc << " with coarse covers";
    // Perimeter of the union about 2 · 6.5 + 2π · 3.3 mm; chord tolerance on it.
    const double af = union_area(full), ac = union_area(covered), al = union_area(after_last);
    EXPECT_GT(af, 30.0);
    EXPECT_NEAR(ac, af, 40.0 * tol) << "z " << z;
    EXPECT_NEAR(al, af, 40.0 * tol) << "z " << z;
    // The same with one piece's neighbours missing: its own arcs are then refined in full.
    geom::Paths alone;
    sweeps[pieces[5].sweep].build_piece(pieces[5], {}, alone, sc);
    EXPECT_NEAR(union_area(alone), union_area(geom::Paths{full[5]}), 1e-9);
  }
}

TEST(ConvexCover, HoldsThePointsInsideThePolygonByTheMargin) {
  // A regular 60-gon of radius 3 about (1, −2) and a margin of 0.05 mm: contains() must
  // agree with the least distance to the edges' lines (brute force) wherever that distance
  // is not within 1e-9 mm of the margin.
  std::vector<geom::SectionPoint> poly;
  constexpr int n = 60;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * test::kPi * i / n;
    poly.push_back({1.0 + 3.0 * std::cos(a), -2.0 + 3.0 * std::sin(a)});
  }
  const double m = 0.05;
  geom::ConvexCover cover;
  cover.build(poly, m);
  ASSERT_FALSE(cover.empty());
  auto depth = [&](const geom::SectionPoint& q) {
    double d = INFINITY;
    for (int i = 0; i < n; ++i) {
      const auto& a = poly[static_cast<std::size_t>(i)];
      const auto& b = poly[static_cast<std::size_t>((i + 1) % n)];
      const double ex = b.x - a.x, ey = b.y - a.y, l = std::hypot(ex, ey);
      d = std::min(d, ((q.x - a.x) * ey - (q.y - a.y) * ex) / -l);  // > 0 inside (counter-clockwise)
    }
    return d;
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.5, 3.5);
  int inside = 0, outside = 0;
  for (int k = 0; k < 20000; ++k) {
    const geom::SectionPoint q{1.0 + u(rng), -2.0 + u(rng)};
    const double d = depth(q);
    if (std::abs(d - m) < 1e-9) continue;
    EXPECT_EQ(cover.contains(q), d > m) << "q (" << q.x << ", " << q.y << "), depth " << d;
    (d > m ? inside : outside)++;
  }
  EXPECT_GT(inside, 5000);
  EXPECT_GT(outside, 5000);
  // An edge shorter than the margin can carry turns away: such a polygon covers nothing.
  cover.build({{0, 0}, {1, 0}, {0.5, 0.01}}, m);
  EXPECT_TRUE(cover.empty());
  cover.build({{0, 0}, {1, 0}}, m);
  EXPECT_TRUE(cover.empty());
}

TEST(Sweep, TiltedSectionVerticesLieOnTheEllipseWithinThePointAccuracy) {
  // A flat Ø10 tilted 30° about Y: the hull of its two station circles is the exact
  // cylinder, whose section by z = 5 is the ellipse with semi-axes 5 / cos 30° (along X) and
  // 5 around the axis' crossing (5 tan 30°, 0). Each vertex is a support point found to
  // within tol/20 of the boundary's support line (Hull3::section_point(): the search stops
  // once its upper and lower bounds of the support value meet), then rounded to the 0.1 µm
  // unit grid (up to √2/2 unit off), so every vertex lies inside the ellipse by at most
  // tol/20 + √2/2 unit and outside by at most √2/2 unit.
  const double th = 30.0 * test::kPi / 180.0;
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const geom::Vec3 ax{std::sin(th), 0, std::cos(th)};
  const geom::Sweep s(shape, test::at(0, 0, 0, ax), test::at(0, 0, 0, ax));
  geom::Paths out;
  geom::SectionScratch sc;
  ASSERT_EQ(s.section(5.0, out, sc), 1u);
  const double a = 5.0 / std::cos(th), b = 5.0, cx = 5.0 * std::tan(th);
  double inside_most = 0.0, outside_most = 0.0;
  for (const geom::Point& p : out[0]) {
    const double x = geom::to_mm(p.X) - cx, y = geom::to_mm(p.Y);
    // Signed distance to the ellipse to first order: f / |∇f|, f = (x/a)² + (y/b)² − 1.
    const double f = x * x / (a * a) + y * y / (b * b) - 1.0;
    const double g = 2.0 * std::hypot(x / (a * a), y / (b * b));
    inside_most = std::min(inside_most, f / g);
    outside_most = std::max(outside_most, f / g);
  }
  EXPECT_GE(inside_most, -(kTol / 20.0 + kHalfUnitMm + 1e-6)) << out[0].size() << " vertices";
  EXPECT_LE(outside_most, kHalfUnitMm + 1e-6);
  EXPECT_LT(inside_most, -0.1 * kHalfUnitMm);  // the check sees the rounding, so it can see an error
}

TEST(Sweep, TiltedRasterNeedsFewSupportQueriesPerPoint) {
  // A bull Ø10 R2 raster along X in 0.5 mm moves whose tilt follows A = 20° sin(πx/27),
  // cut by a plane through the corner (a ball's capsule model takes one query per point;
  // the figures below were measured on the ball Ø6 of finish5x's ball pass before it;
  // this bull with its profile's stations: 5.1 queries per coarse point, 3.5 per output
  // vertex; with its rounded core, whose tilt search meets no station staircase: 2.68 and
  // 2.55). The coarse points of each piece
  // start from the previous piece's bracket moved by its drift, the refined points from
  // their neighbours' brackets, and each search stops once its point is proven within
  // tol/20 of the boundary, each search bracketing from its middle first: measured 4.0
  // queries per coarse point and 3.4 per output vertex in all (4.5 and 3.95 without the
  // middle first; on finish5x's first 300 blocks the coarse points took 10.3 queries each
  // before this work, 4.2 of them widening a bracket left where the previous piece's was).
  auto bull = test::tool(ToolKind::Bull, 10);
  bull.corner_radius_mm = 2.0;
  const double tol = 0.01;
  const auto shape = geom::CutterShape::build(bull, tol);
  ASSERT_DOUBLE_EQ(shape.core_radius_mm, 3.0);  // the rounded core model (Hull3)
  auto pose = [](int i) {
    const double x = -13.5 + 0.5 * i, a = 20.0 * std::sin(test::kPi * x / 27.0) * test::kPi / 180.0;
    return test::at(x, 0, 0, {0, -std::sin(a), std::cos(a)});
  };
  std::vector<geom::Sweep> sweeps;
  for (int i = 0; i < 40; ++i) sweeps.emplace_back(shape, pose(i), pose(i + 1));
  std::vector<geom::TiltedPiece> pieces;
  for (std::uint32_t k = 0; k < sweeps.size(); ++k) {
    const std::size_t before = pieces.size();
    sweeps[k].tilted_pieces(1.0, pieces);
    for (std::size_t i = before; i < pieces.size(); ++i) pieces[i].sweep = k;
  }
  ASSERT_GE(pieces.size(), sweeps.size());
  std::uint64_t coarse = 0;
  for (const auto& p : pieces) coarse += p.coarse_queries;
  geom::SectionScratch sc;
  geom::Paths out;
  for (std::size_t i = 0; i < pieces.size(); ++i)
    sweeps[pieces[i].sweep].build_piece(pieces[i], {i > 0 ? &pieces[i - 1] : nullptr, i + 1 < pieces.size() ? &pieces[i + 1] : nullptr},
                                        out, sc);
  std::size_t vertices = 0;
  for (const auto& p : out) vertices += p.size();
  const double per_coarse = static_cast<double>(coarse) / static_cast<double>(geom::TiltedPiece::kDirs * pieces.size());
  const double per_vertex = static_cast<double>(coarse + sc.support_queries) / static_cast<double>(vertices);
  std::printf("pieces %zu, queries per coarse point %.2f, per vertex %.2f (%zu vertices)\n", pieces.size(), per_coarse,
              per_vertex, vertices);
  EXPECT_LT(per_coarse, 3.2);
  EXPECT_LT(per_vertex, 3.0);
}

namespace {

// Distance [mm] from p to the parallelogram o + s·e + t·f (s, t in [0, 1]).
double dist_to_parallelogram(const geom::Vec3& p, const geom::Vec3& o, const geom::Vec3& e, const geom::Vec3& f) {
  auto seg = [&](const geom::Vec3& a, const geom::Vec3& d) {
    const double t = std::clamp(geom::dot(p - a, d) / geom::dot(d, d), 0.0, 1.0);
    return geom::norm(p - (a + t * d));
  };
  // Inside the face: solve for (s, t) in the face's plane.
  const double ee = geom::dot(e, e), ef = geom::dot(e, f), ff = geom::dot(f, f);
  const geom::Vec3 w = p - o;
  const double we = geom::dot(w, e), wf = geom::dot(w, f), det = ee * ff - ef * ef;
  if (det > 1e-18) {
    const double s = (we * ff - wf * ef) / det, t = (wf * ee - we * ef) / det;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) return geom::norm(w - (s * e + t * f));
  }
  return std::min({seg(o, e), seg(o, f), seg(o + e, f), seg(o + f, e)});
}

// The area [mm²] of {(x, y): dist((x, y, z), parallelogram) <= r}, row by row (the set is
// convex: each row is one interval, found by bisection from the row's nearest point).
double capsule_sweep_slice_area(const geom::Vec3& o, const geom::Vec3& e, const geom::Vec3& f, double r, double z,
                                double y0, double y1, double x0, double x1, double dy) {
  double area = 0.0;
  for (double y = y0 + 0.5 * dy; y < y1; y += dy) {
    auto d = [&](double x) { return dist_to_parallelogram({x, y, z}, o, e, f); };
    double a = x0, b = x1;  // golden-section search for the row's nearest point
    for (int i = 0; i < 200 && b - a > 1e-10; ++i) {
      const double m1 = a + 0.382 * (b - a), m2 = a + 0.618 * (b - a);
      if (d(m1) < d(m2)) b = m2;
      else a = m1;
    }
    const double xm = 0.5 * (a + b);
    if (d(xm) > r) continue;
    auto edge = [&](double in, double out) {
      for (int i = 0; i < 80; ++i) {
        const double m = 0.5 * (in + out);
        (d(m) <= r ? in : out) = m;
      }
      return 0.5 * (in + out);
    };
    area += (edge(xm, x1) - edge(xm, x0)) * dy;
  }
  return area;
}

}  // namespace

TEST(Sweep, TiltedBallSectionsMatchTheExactSliceOfTheCapsuleSweep) {
  // A ball Ø6 tilted 20° about X, moving 2 mm in X and 0.6 mm down with a fixed axis: its
  // cutting part (ball and flutes' cylinder, CutterShape::capsule_radius_mm) sweeps the
  // points within 3 mm of the parallelogram of its axis segment (centre to top of the flutes)
  // and the move. The sections' areas against that set's, row by row (an independent
  // reference); the polygons' vertices lie on the exact boundary, so each area may fall
  // short only by the chord segments: measured 1.8–3.2 · 10⁻³ mm² short (about tol/7 times
  // the perimeter; 0.5–2.8 · 10⁻³ while chords were split until tol/2 rather than tol), where
  // the station model (the ball's profile as a polyline, each point found by bisection) fell
  // 2.5–13.8 · 10⁻³ mm² short, up to tol·perimeter at z = 0.4.
  const double a = 20.0 * test::kPi / 180.0;
  const geom::Vec3 ax{0, -std::sin(a), std::cos(a)};
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  ASSERT_DOUBLE_EQ(shape.capsule_radius_mm, 3.0);
  const geom::Pose p0 = test::at(0, 0, 0, ax), p1 = test::at(2, 0, -0.6, ax);
  const geom::Sweep s(shape, p0, p1);
  const geom::Vec3 o = p0.tip + 3.0 * ax, e = (shape.height() - 3.0) * ax, f = p1.tip - p0.tip;
  for (double z : {-0.5, 0.4, 1.5, 3.2, 5.0}) {
    const double ref = capsule_sweep_slice_area(o, e, f, 3.0, z, -12.0, 6.0, -6.0, 8.0, 0.001);
    const double got = section_area_mm2(s, z);
    const double perimeter = 2.0 * std::sqrt(test::kPi * ref) * 1.2;  // a circle's, with room for the elongation
    std::printf("z %.2f: reference %.6f, section %.6f mm2 (%+.6f)\n", z, ref, got, got - ref);
    EXPECT_LE(got, ref + perimeter * kHalfUnitMm) << z;  // rounding to the unit grid
    EXPECT_GE(got, ref - 0.25 * kTol * perimeter) << z;
  }
}

namespace {

// Signed distance [mm] from p to a bull's rounded core: the points within r of a disk of
// radius rho normal to `axis`, centred on base + h·axis for h in [h0, h1] (an independent
// formula for the exact torus and cylinder; negative inside).
double rounded_core_distance(const geom::Vec3& p, const geom::Vec3& base, const geom::Vec3& axis, double h0, double h1,
                             double rho, double r) {
  const geom::Vec3 d = p - base;
  const double h = geom::dot(d, axis), radial = geom::norm(d - h * axis);
  return std::hypot(h - std::clamp(h, h0, h1), std::max(0.0, radial - rho)) - r;
}

}  // namespace

TEST(Sweep, TiltedBullSectionVerticesLieOnTheExactTorusAndCylinder) {
  // A bull Ø10 R2 tilted 25° about X (CutterShape::core_radius_mm: the points within 2 mm of
  // a disk of radius 3 swept along the axis from the corner's centre to the top of the
  // flutes), cut through its flat end and torus (z 0.3, 1.0), the torus (1.9) and the
  // cylinder (4, 10). Each vertex is a support point found to within tol/20 and rounded to
  // the unit grid, so its distance to the exact surface (an independent formula: the
  // distance to that disk-swept core, less 2 mm) lies in [−(tol/20 + ½ unit), ½ unit]. The
  // station model (the corner arc as a polyline within ±tol) put them up to tol off.
  auto bull = test::tool(ToolKind::Bull, 10);
  bull.corner_radius_mm = 2.0;
  const auto shape = geom::CutterShape::build(bull, kTol);
  ASSERT_DOUBLE_EQ(shape.capsule_radius_mm, 2.0);
  ASSERT_DOUBLE_EQ(shape.core_radius_mm, 3.0);
  const double a = 25.0 * test::kPi / 180.0;
  const geom::Vec3 ax{0, -std::sin(a), std::cos(a)};
  const geom::Pose pose = test::at(0, 0, 0, ax);
  const geom::Sweep s(shape, pose, pose);
  auto surface_distance = [&](double x, double y, double z) {
    return rounded_core_distance({x, y, z}, pose.tip, ax, 2.0, shape.height(), 3.0, 2.0);
  };
  std::size_t torus_vertices = 0;
  for (double z : {0.3, 1.0, 1.9, 4.0, 10.0}) {
    geom::Paths out;
    geom::SectionScratch sc;
    ASSERT_EQ(s.section(z, out, sc), 1u) << z;
    double inside_most = 0.0, outside_most = -1.0;
    for (const geom::Point& p : out[0]) {
      const double x = geom::to_mm(p.X), y = geom::to_mm(p.Y);
      const double dist = surface_distance(x, y, z);
      inside_most = std::min(inside_most, dist);
      outside_most = std::max(outside_most, dist);
      const geom::Vec3 q = geom::Vec3{x, y, z} - pose.tip;
      if (geom::dot(q, ax) < 2.0 && geom::norm(q - geom::dot(q, ax) * ax) > 3.0) ++torus_vertices;
    }
    EXPECT_GE(inside_most, -(kTol / 20.0 + kHalfUnitMm + 1e-6)) << z << ": " << out[0].size() << " vertices";
    EXPECT_LE(outside_most, kHalfUnitMm + 1e-6) << z;
  }
  EXPECT_GT(torus_vertices, 20u);
}

TEST(Sweep, TiltedBullSectionsNearItsLowestPointStayOnTheTool) {
  // A sampled retract of finish5x's bull (Ø10 R2, flutes 30, 20° A tilt) along its own
  // axis, as two live samples bring it (poses from a run). The corner's stations lie up to
  // the chord tolerance outside the exact torus, so their circles reach a little below the
  // rounded core's lowest point; planes in that band used to pass the z test, the tilt
  // search found no point on them and returned garbage (a vertex 23 mm away: 2.6 mm3 cut
  // from the finished part per retract). Every vertex on planes within 5 µm of the lowest
  // point must lie on the tool: within half a unit of the exact rounded core (disk of
  // radius 3 swept along the axis from the lower corner centre to the upper flutes' top).
  auto bull = test::tool(ToolKind::Bull, 10, 2.0);
  const auto shape = geom::CutterShape::build(bull, 0.01);
  ASSERT_DOUBLE_EQ(shape.core_radius_mm, 3.0);
  const geom::Vec3 ax{0, -0.34202014332566871, 0.93969262078590843};
  const geom::Pose lo = test::at(-20, -18.299183087152976, -8.1994956768430285, ax);
  const geom::Pose hi = test::at(-20, -18.367587115818107, -8.011557152685846, ax);
  const geom::Sweep s(shape, lo, hi);
  const double top = geom::dot(hi.tip - lo.tip, ax) + shape.height();  // the upper flutes' top above lo's tip
  auto outside = [&](double x, double y, double z) {
    return rounded_core_distance({x, y, z}, lo.tip, ax, 2.0, top, 3.0, 2.0);
  };
  const double lowest = lo.tip.z + 2.0 * ax.z - 3.0 * std::sqrt(1.0 - ax.z * ax.z) - 2.0;
  int planes_with_polygons = 0;
  double worst = -1.0;
  for (int k = -50; k <= 50; ++k) {
    const double z = lowest + k * 1e-4;
    geom::Paths out;
    geom::SectionScratch sc;
    s.section(z, out, sc);
    if (!out.empty()) ++planes_with_polygons;
    for (const geom::Path& p : out)
      for (const geom::Point& q : p) worst = std::max(worst, outside(geom::to_mm(q.X), geom::to_mm(q.Y), z));
  }
  std::printf("planes with a polygon %d of 101, worst vertex %.3g mm outside\n", planes_with_polygons, worst);
  EXPECT_LE(worst, kHalfUnitMm + 1e-6);
  EXPECT_GE(planes_with_polygons, 45);  // those above the lowest point cut the tool
  EXPECT_LE(planes_with_polygons, 51);
}

TEST(Sweep, ABallLyingInTheLevelPlaneIsAStadium) {
  // A ball Ø6 with flutes of 30 and its axis along +X (the capsule's axis segment level:
  // the closed form's constant-height case): the capsule from the ball's centre (x = 3) to the
  // top of the flutes (x = 30), radius 3, cut by z = h is the stadium of that segment and
  // radius sqrt(9 − h²); its far cap (beyond x = 30) is the hemisphere that stands for the
  // flutes' flat top (inside the shank). The polygon's vertices lie on the boundary, so its
  // area falls short by at most the chord segments.
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  ASSERT_DOUBLE_EQ(shape.capsule_radius_mm, 3.0);
  const geom::Sweep s(shape, test::at(0, 0, 0, {1, 0, 0}), test::at(0, 0, 0, {1, 0, 0}));
  for (double h : {0.0, 1.0, 2.0, 2.9}) {
    const double r = std::sqrt(9.0 - h * h), exact = 27.0 * 2.0 * r + test::kPi * r * r;
    const double perimeter = 2.0 * 27.0 + 2.0 * test::kPi * r;
    const double got = section_area_mm2(s, h);
    std::printf("h %.1f: exact %.6f, section %.6f mm2 (%+.6f)\n", h, exact, got, got - exact);
    EXPECT_LE(got, exact + perimeter * kHalfUnitMm) << h;  // rounding to the unit grid
    EXPECT_GE(got, exact - 0.5 * kTol * perimeter) << h;
  }
  EXPECT_EQ(section_area_mm2(s, 3.01), 0.0);
}

namespace {

// The row x ↦ (x, y, z) meets a convex part of a tool in one interval; empty: lo > hi.
struct Interval {
  double lo = INFINITY, hi = -INFINITY;
};

// Where q(x) = d + x·(1, 0, 0) satisfies c2·x² + c1·x + c0 <= 0.
Interval quadratic_interval(double c2, double c1, double c0) {
  if (c2 <= 1e-15) return c0 <= 0.0 ? Interval{-1e9, 1e9} : Interval{};
  const double disc = c1 * c1 - 4.0 * c2 * c0;
  if (disc < 0.0) return {};
  const double s = std::sqrt(disc);
  return {(-c1 - s) / (2.0 * c2), (-c1 + s) / (2.0 * c2)};
}

Interval meet(Interval a, Interval b) { return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)}; }

// The row through p0 = (0, y, z) against the solid cylinder of radius `rad` about `a` from
// c + h0·a to c + h1·a (closed form, independent of geom::Sweep).
Interval row_cylinder(const geom::Vec3& p0, const geom::Vec3& c, const geom::Vec3& a, double h0, double h1, double rad) {
  const geom::Vec3 d = p0 - c, e{1, 0, 0};
  const double da = geom::dot(d, a), ea = geom::dot(e, a);
  const geom::Vec3 dp = d - da * a, ep = e - ea * a;
  Interval r = quadratic_interval(geom::dot(ep, ep), 2.0 * geom::dot(dp, ep), geom::dot(dp, dp) - rad * rad);
  if (std::abs(ea) < 1e-15) return da >= h0 && da <= h1 ? r : Interval{};
  const double x0 = (h0 - da) / ea, x1 = (h1 - da) / ea;
  return meet(r, {std::min(x0, x1), std::max(x0, x1)});
}

Interval row_ball(const geom::Vec3& p0, const geom::Vec3& c, double rad) {
  const geom::Vec3 d = p0 - c;
  return quadratic_interval(1.0, 2.0 * d.x, geom::dot(d, d) - rad * rad);
}

// Area of plane z's section of the union of a tool over `nt` + 1 poses interpolated as
// geom::Sweep interpolates them (tip linearly, axis by normalised linear interpolation),
// row by row at spacing dy: per row the union of the intervals in which each pose's tool
// meets it. `row` gives those intervals for one pose.
template <class Row>
double swept_slice_area(const geom::Pose& a, const geom::Pose& b, double z, double y0, double y1, double dy, int nt,
                        Row row) {
  std::vector<geom::Pose> poses;
  for (int k = 0; k <= nt; ++k) {
    const double t = static_cast<double>(k) / nt;
    geom::Vec3 ax = a.axis + t * (b.axis - a.axis);
    ax = (1.0 / geom::norm(ax)) * ax;
    poses.push_back({a.tip + t * (b.tip - a.tip), ax});
  }
  double area = 0.0;
  std::vector<Interval> iv;
  for (double y = y0 + 0.5 * dy; y < y1; y += dy) {
    iv.clear();
    for (const geom::Pose& p : poses) row({0.0, y, z}, p, iv);
    std::sort(iv.begin(), iv.end(), [](const Interval& u, const Interval& v) { return u.lo < v.lo; });
    double len = 0.0, lo = -INFINITY, hi = -INFINITY;
    for (const Interval& u : iv) {
      if (u.lo > hi) {
        if (hi > lo) len += hi - lo;
        lo = u.lo;
        hi = u.hi;
      } else {
        hi = std::max(hi, u.hi);
      }
    }
    if (hi > lo) len += hi - lo;
    area += len * dy;
  }
  return area;
}

// The union of a sweep's section polygons on plane z: its area and perimeter [mm², mm].
std::pair<double, double> section_area_perimeter(const geom::Sweep& s, double z) {
  geom::Paths out, u;
  geom::SectionScratch sc;
  s.section(z, out, sc);
  ClipperLib::Clipper c;
  c.AddPaths(out, ClipperLib::ptSubject, true);
  c.Execute(ClipperLib::ctUnion, u, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double a = 0.0, len = 0.0;
  for (const auto& p : u) {
    a += ClipperLib::Area(p);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const auto& q = p[i];
      const auto& r = p[(i + 1) % p.size()];
      len += std::hypot(geom::to_mm(r.X - q.X), geom::to_mm(r.Y - q.Y));
    }
  }
  return {geom::area_to_mm2(a), len};
}

// Every section of sweep s on the planes zs against the union of its tool at 400 poses
// (`row`: one pose's intervals on a row), rows from y0 to y1: within tol times its perimeter.
template <class Row>
void expect_sections_match_union(const geom::Sweep& s, std::initializer_list<double> zs, double y0, double y1, double tol,
                                 Row row) {
  for (double z : zs) {
    const double ref = swept_slice_area(s.from(), s.to(), z, y0, y1, 0.002, 400, row);
    const auto [got, perimeter] = section_area_perimeter(s, z);
    std::printf("z %5.1f: reference %.5f, section %.5f mm2 (%+.5f; tol x perimeter %.5f)\n", z, ref, got, got - ref,
                tol * perimeter);
    EXPECT_NEAR(got, ref, tol * perimeter) << z;
  }
}

}  // namespace

TEST(Sweep, TwistingBallSectionsMatchTheUnionOfItsPoses) {
  // A ball Ø6 (flutes 30: the capsule's segment is 27 mm long) moving 2 mm along X while
  // its axis, tilted 15° about X, turns a further 0.1 rad about X: a twist about the motion,
  // where the convex hull of the tool at its two poses stood out from the swept tool by up
  // to L·φ/4 = 0.68 mm at mid-segment (+0.52 mm² on the plane z = 12; docs/lbr-conventions.md,
  // "Tolerances"). Then a ramp that twists about Y and X at once. Against an independent
  // reference (the union of the tool at 400 poses, row by row, closed form), each section's
  // area must agree within the chord tolerance times its perimeter.
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  ASSERT_DOUBLE_EQ(shape.capsule_radius_mm, 3.0);
  auto axis = [](double th, double ph) { return geom::Vec3{std::sin(ph), -std::sin(th), std::cos(th) * std::cos(ph)}; };
  auto capsule_row = [&](const geom::Vec3& q, const geom::Pose& p, std::vector<Interval>& iv) {
    const geom::Vec3 c0 = p.tip + 3.0 * p.axis, c1 = p.tip + shape.height() * p.axis;
    for (const Interval& u : {row_cylinder(q, p.tip, p.axis, 3.0, shape.height(), 3.0), row_ball(q, c0, 3.0), row_ball(q, c1, 3.0)})
      if (u.lo <= u.hi) iv.push_back(u);
  };
  const double th = 15.0 * test::kPi / 180.0;
  const geom::Sweep twist(shape, test::at(0, 0, 0, axis(th, 0.0)), test::at(2, 0, -0.3, axis(th + 0.1, 0.0)));
  expect_sections_match_union(twist, {-0.1, 1.0, 5.0, 12.0, 20.0}, -14.0, 6.0, kTol, capsule_row);
  const geom::Sweep ramp(shape, test::at(0, 0, 0, axis(th, 0.0)), test::at(0.6, 0.4, -1.2, axis(th + 0.05, 0.06)));
  expect_sections_match_union(ramp, {-1.1, -0.5, 0.5, 3.0, 10.0}, -12.0, 6.0, kTol, capsule_row);
}

TEST(Sweep, TurningFlatToolSectionsMatchTheUnionOfItsPoses) {
  // A flat Ø10 × 30 with its axis 15° above horizontal, turned 0.026 rad about the vertical
  // through the middle of its flutes, at the bundled profiles' tolerance of 10 µm: the hull
  // of its two poses stood 5.4–5.9 mm² per level out of the swept tool (docs/performance.md,
  // "The cause"). Sub-steps bounded by the hull's excess keep every level within the
  // chord tolerance times its perimeter of the union of the tool at 400 poses.
  const double tol = 0.01;
  const auto shape = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), tol);
  const double el = 15.0 * test::kPi / 180.0;
  auto pose = [&](double az) {
    const geom::Vec3 a{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    return geom::Pose{geom::Vec3{0, 0, 0} - 15.0 * a, a};  // the flutes' middle at the origin
  };
  const geom::Pose p0 = pose(0.0), p1 = pose(0.026);
  const geom::Sweep s(shape, p0, p1);
  auto flat_row = [&](const geom::Vec3& q, const geom::Pose& p, std::vector<Interval>& iv) {
    const Interval u = row_cylinder(q, p.tip, p.axis, 0.0, shape.height(), 5.0);
    if (u.lo <= u.hi) iv.push_back(u);
  };
  expect_sections_match_union(s, {-5.0, -3.0, 0.0, 3.0, 6.0}, -12.0, 12.0, tol, flat_row);
  // Leaning along its motion (the axis turns 0.05 rad about Y while the tip moves 3 mm
  // along X): the hull's offsets lie along the swept surface, which holds them, so few
  // sub-steps do (TwistBound::across). Leaning across it as well (about a diagonal).
  auto lean = [](double ax, double ay) {
    const geom::Vec3 a{std::sin(ay), -std::sin(ax), std::cos(ax) * std::cos(ay)};
    return (1.0 / geom::norm(a)) * a;
  };
  const geom::Sweep along(shape, test::at(0, 0, 0, lean(0.0, 0.3)), test::at(3, 0, -0.2, lean(0.0, 0.35)));
  expect_sections_match_union(along, {0.0, 2.0, 8.0, 15.0, 25.0}, -8.0, 8.0, tol, flat_row);
  const geom::Sweep diagonal(shape, test::at(0, 0, 0, lean(0.1, 0.3)), test::at(3, 0, -0.2, lean(0.13, 0.33)));
  expect_sections_match_union(diagonal, {0.0, 2.0, 8.0, 15.0, 25.0}, -12.0, 8.0, tol, flat_row);
  // Ramping down 1 mm while it leans: the face moves along its axis by more than 3ρφ, which
  // holds the offsets of its turn (no face term).
  const geom::Sweep ramp(shape, test::at(0, 0, 0, lean(0.0, 0.3)), test::at(0.5, 0, -1.0, lean(0.05, 0.35)));
  expect_sections_match_union(ramp, {-1.2, -0.8, -0.3, 0.5, 4.0}, -8.0, 8.0, tol, flat_row);
}
