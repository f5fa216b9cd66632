// Joined sections (geom/src/chain_outline.cpp): consecutive vertical moves on a level are
// written as one outline. These cases check the region it removes three ways: against the
// exact solid (helical bore, helical entry into a pocket), against the same moves cut one
// by one (each move then gives its own convex section, nothing is joined), and against an
// independent height-field reference for a sloped ball-end raster. Tilted moves (joined into
// unions of their sections) against the same moves one by one, and a tilted swing beside
// the material that builds no section at all.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "geom/serialize.hpp"
#include "test_util.hpp"

using namespace lbr;
using geom::ToolKind;

using test::helix;

namespace {

constexpr double kTol = 0.001;

// Largest difference of level areas between two solids [mm²].
double max_level_area_gap(const geom::LbrSolid& a, const geom::LbrSolid& b) {
  double worst = 0.0;
  for (int l = 0; l < a.levels(); ++l) worst = std::max(worst, std::abs(a.level_area_mm2(l) - b.level_area_mm2(l)));
  return worst;
}

}  // namespace

TEST(Joined, HelicalBoreIsTheAnnulusTimesTheDepth) {
  // Flat Ø8 on a helix of radius 6, 5 turns of 1 mm, then a flat turn at -5: every level
  // above -5 loses the annulus 2 <= r <= 10.
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const int per_turn = 720;  // chord sag 6·(1 - cos(0.25°)) = 57 nm
  test::cut_path(s, c, helix(30, 20, 6, 0, 1, 5, per_turn), 512);
  const double exact = test::kPi * (100.0 - 4.0) * 5.0;
  const double perimeter = 2.0 * test::kPi * (10.0 + 2.0);
  EXPECT_NEAR(test::removed(s), exact, 2.0 * perimeter * kTol * 5.0);
  EXPECT_EQ(s.check_invariants(), "");
}

TEST(Joined, HelixCutInOneBatchEqualsTheMovesCutOneByOne) {
  geom::LbrSolid joined(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  geom::LbrSolid single(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  const auto path = helix(30, 20, 5, 1, 1.5, 3, 90);
  test::cut_path(joined, c, path, 1000);
  test::cut_path(single, c, path, 1);
  // Each level: the union of the same convex sections, polygonised on one grid or per
  // section; they differ by the chord band along the perimeter at most.
  const double perimeter = 2.0 * test::kPi * (8.0 + 2.0);
  EXPECT_LT(max_level_area_gap(joined, single), 2.0 * perimeter * kTol);
  EXPECT_NEAR(test::removed(joined), test::removed(single), 2.0 * perimeter * kTol * 6.0);
  EXPECT_EQ(joined.check_invariants(), "");
}

TEST(Joined, ZigZagWithSharpTurnsEqualsTheMovesCutOneByOne) {
  // A ramping zig-zag with reversals and 90° corners: both sides of every join kind.
  geom::LbrSolid joined(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  geom::LbrSolid single(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Bull, 10, 2), kTol);
  std::vector<geom::Vec3> p{{10, 10, 1}};
  for (int i = 0; i < 12; ++i) {
    const double z = -0.3 * i;
    p.push_back({i % 2 == 0 ? 50.0 : 10.0, 10.0 + 1.5 * i, z});
    p.push_back({i % 2 == 0 ? 50.0 : 10.0, 11.5 + 1.5 * i, z - 0.1});
    p.push_back({i % 2 == 0 ? 10.0 : 50.0, 11.5 + 1.5 * i, z - 0.15});  // reversal
  }
  test::cut_path(joined, c, p, 1000);
  test::cut_path(single, c, p, 1);
  const double perimeter = 2.0 * (60.0 + 40.0);
  EXPECT_LT(max_level_area_gap(joined, single), 2.0 * perimeter * kTol);
  EXPECT_EQ(joined.check_invariants(), "");
}

TEST(Joined, HelicalEntryIntoAPocketLeavesThePocket) {
  // Helical ramp (radius 2, 4 turns to -4) at the centre of a 30 x 20 pocket, then the
  // zig-zag and finishing loop of Volume.RectangularPocketWithRoundedCorners.
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 6), kTol);
  std::vector<geom::Vec3> p = helix(30, 20, 2, 1, 1.25, 4, 180);
  p.push_back({18, 13, -4});
  test::append_pocket_path(p);
  test::cut_path(s, c, p, 512);
  EXPECT_NEAR(test::removed(s), test::kPocketVolume, 2 * 100.0 * kTol * 4.0);
  EXPECT_EQ(s.check_invariants(), "");
}

namespace {

// A helix as the kinematics splits it: `per_turn` chords a turn, turning counter-clockwise
// (ccw) or clockwise, from z0 down by `pitch` a turn for `turns` turns, then a flat turn.
std::vector<geom::Vec3> helix_dir(double cx, double cy, double rho, double z0, double pitch, int turns, int per_turn,
                                  bool ccw) {
  auto p = helix(cx, cy, rho, z0, pitch, turns, per_turn);
  if (!ccw)
    for (geom::Vec3& v : p) v.y = 2.0 * cy - v.y;
  return p;
}

}  // namespace

TEST(Joined, TightHelicalBoreIsTheDiskTimesTheDepth) {
  // Flat Ø10 on a helix of radius 3 (below the tool radius: a tight loop), 4 turns of
  // 1.25 mm, then a flat turn at -5: every level above -5 loses the disk r <= 8. Whole
  // turns in one batch (as tight_loop_end() cuts them) and parts of turns (37 moves).
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const double exact = test::kPi * 64.0 * 5.0;
  const double perimeter = 2.0 * test::kPi * 8.0;
  for (const bool ccw : {true, false}) {
    for (const int batch : {180, 37}) {
      geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
      std::vector<geom::SweepRef> moves;
      const auto path = helix_dir(30, 20, 3, 0, 1.25, 4, 180, ccw);  // chord sag 3·(1 - cos 1°) = 0.46 µm
      geom::SubtractStats st;
      for (std::size_t i = 1; i < path.size(); ++i) {
        moves.push_back({&c, {path[i - 1], {0, 0, 1}}, {path[i], {0, 0, 1}}, static_cast<geom::MoveId>(i)});
        if (static_cast<int>(moves.size()) == batch || i + 1 == path.size()) {
          st += s.subtract(moves);
          moves.clear();
        }
      }
      EXPECT_GT(st.outlines_star, 0u) << "ccw " << ccw << " batch " << batch;
      EXPECT_NEAR(test::removed(s), exact, 2.0 * perimeter * kTol * 5.0) << "ccw " << ccw << " batch " << batch;
      EXPECT_EQ(s.check_invariants(), "");
    }
  }
}

TEST(Joined, TightBallRampEqualsTheMovesCutOneByOne) {
  // Ball Ø8 ramping on a radius of 1.5 (sections of every radius from 0 to 4 on the levels
  // it crosses, tight on most of them), both directions, in batches of whole and part turns,
  // against the same moves one by one (no outline at all).
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 8), kTol);
  for (const bool ccw : {true, false}) {
    const auto path = helix_dir(30, 20, 1.5, 0.5, 0.8, 4, 120, ccw);
    geom::LbrSolid single(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
    test::cut_path(single, c, path, 1);
    for (const int batch : {121, 50}) {
      geom::LbrSolid joined(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
      test::cut_path(joined, c, path, batch);
      const double perimeter = 2.0 * test::kPi * 5.5;
      EXPECT_LT(max_level_area_gap(joined, single), 2.0 * perimeter * kTol) << "ccw " << ccw << " batch " << batch;
      EXPECT_NEAR(test::removed(joined), test::removed(single), 2.0 * perimeter * kTol * 4.0);
      EXPECT_GT(test::removed(joined), 150.0);
      EXPECT_EQ(joined.check_invariants(), "");
    }
  }
}

TEST(Joined, CoarseTightLoopInShortBatchesEqualsTheMovesCutOneByOne) {
  // 8 chords a turn of radius 3 under a flat Ø10 (45° turns, 2.3 mm chords), both
  // directions, in batches of 2 to 9 moves: a run that turns less than a full circle about
  // its centre keeps its inner chain where that chain bounds the union; each batch against
  // the same moves one by one.
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  for (const bool ccw : {true, false}) {
    const auto path = helix_dir(30, 20, 3, 0, 0.35, 2, 8, ccw);
    geom::LbrSolid single(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
    test::cut_path(single, c, path, 1);
    for (const int batch : {2, 3, 5, 9}) {
      geom::LbrSolid joined(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
      test::cut_path(joined, c, path, batch);
      const double perimeter = 2.0 * test::kPi * 8.0;
      EXPECT_LT(max_level_area_gap(joined, single), 2.0 * perimeter * kTol) << "ccw " << ccw << " batch " << batch;
      EXPECT_EQ(joined.check_invariants(), "");
    }
  }
}

namespace {

// Lowest point of a ball (radius r) whose centre runs from a to b, above (x, y); +inf where
// the ball does not pass over it. z(t) - sqrt(r² - d(t)²) is convex in t: ternary search.
double ball_floor(double x, double y, const geom::Vec3& a, const geom::Vec3& b, double r) {
  auto f = [&](double t) {
    const double cx = a.x + t * (b.x - a.x), cy = a.y + t * (b.y - a.y), cz = a.z + t * (b.z - a.z);
    const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
    return d2 >= r * r ? INFINITY : cz - std::sqrt(r * r - d2);
  };
  // Closest approach in XY first: the floor is finite near it when it is finite at all.
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t0 = l2 > 0.0 ? std::clamp(((x - a.x) * dx + (y - a.y) * dy) / l2, 0.0, 1.0) : 0.0;
  if (!std::isfinite(f(t0))) return INFINITY;
  double lo = 0.0, hi = 1.0;
  // The finite interval around t0 (d(t) < r) is where the search runs.
  for (double* e : {&lo, &hi}) {
    double in = t0, out = *e;
    if (std::isfinite(f(out))) continue;
    for (int i = 0; i < 60; ++i) {
      const double m = 0.5 * (in + out);
      (std::isfinite(f(m)) ? in : out) = m;
    }
    *e = in;
  }
  for (int i = 0; i < 60 && hi - lo > 1e-10; ++i) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    if (f(m1) < f(m2)) hi = m2;
    else lo = m1;
  }
  return f(0.5 * (lo + hi));
}

}  // namespace

TEST(Joined, SlopedBallRasterMatchesAHeightFieldReference) {
  // Ball Ø6 raster over z = -2.5 + 1.5·sin(x/4)·cos(y/3) (slopes up to ~25°), 0.25 mm
  // points, 0.5 mm stepover, 12 lines; the reference integrates the lower envelope of the
  // balls on a 0.04 mm grid.
  const double R = 3.0;
  geom::LbrSolid s(test::box_spec({0, 0, -8}, {30, 20, 0}, 0.1, 4, 2));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 2 * R, 0.0, 18.0), kTol);
  auto surf = [](double x, double y) { return -2.5 + 1.5 * std::sin(x / 4.0) * std::cos(y / 3.0); };
  std::vector<std::vector<geom::Vec3>> lines;
  for (int j = 0; j < 12; ++j) {
    const double y = 7.0 + 0.5 * j;
    std::vector<geom::Vec3> line;
    for (int i = 0; i <= 64; ++i) {
      const double x = j % 2 == 0 ? 7.0 + 0.25 * i : 23.0 - 0.25 * i;
      line.push_back({x, y, surf(x, y)});  // tip on the surface
    }
    lines.push_back(line);
  }
  std::vector<geom::Vec3> path;
  for (const auto& l : lines) path.insert(path.end(), l.begin(), l.end());
  test::cut_path(s, c, path, 512);
  // The moves from one line to the next cut too: two-point lines for the reference.
  for (std::size_t j = 0; j + 1 < 12; ++j) lines.push_back({lines[j].back(), lines[j + 1].front()});
  // Reference: tip z + R is the ball centre. Per grid point only the lines within R in y
  // and their moves within R in x can reach it (lines are straight in XY, 0.25 mm steps).
  const double h = 0.04;  // the cut lies within x 4..26, y 4..15.5; grid points at cell centres
  double ref = 0.0;
  for (double y = 4.0 + 0.5 * h; y < 15.6; y += h)
    for (double x = 4.0 + 0.5 * h; x < 26.0; x += h) {
      double floor = INFINITY;
      for (const auto& line : lines) {
        if (std::min(line.front().y, line.back().y) - y >= R || y - std::max(line.front().y, line.back().y) >= R) continue;
        for (std::size_t k = 1; k < line.size(); ++k) {
          const geom::Vec3& a0 = line[k - 1];
          const geom::Vec3& b0 = line[k];
          if (std::max(a0.x, b0.x) <= x - R || std::min(a0.x, b0.x) >= x + R) continue;
          floor = std::min(floor, ball_floor(x, y, {a0.x, a0.y, a0.z + R}, {b0.x, b0.y, b0.z + R}, R));
        }
      }
      // The retract between lines (up to z = 1) cuts nothing: its ball stays above the top.
      if (floor < 0.0) ref += (0.0 - std::max(floor, -8.0)) * h * h;
    }
  const double v = test::removed(s);
  ASSERT_GT(ref, 300.0);
  EXPECT_NEAR(v, ref, 0.0005 * ref) << "lbr " << v << " reference " << ref;
  RecordProperty("relative_error", std::to_string((v - ref) / ref));
  EXPECT_EQ(s.check_invariants(), "");
}

namespace {

// Tool axis tilted by `a` [rad] about X (a table A axis seen from the workpiece).
geom::Vec3 tilted(double a) { return {0.0, -std::sin(a), std::cos(a)}; }

}  // namespace

TEST(Joined, TiltedRasterCutInOneBatchEqualsTheMovesCutOneByOne) {
  // Two passes of a ball Ø6 along X and back, the tilt going 0 -> 20° -> 0 and the tip
  // following a bump: one batch (consecutive tilted sections joined into unions) against
  // the same sweeps one by one (each sub-step its own convex section).
  geom::LbrSolid joined(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  geom::LbrSolid single(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6, 0, 18), kTol);
  std::vector<geom::SweepRef> moves;
  auto pose = [](double x, double y) {
    const double a = 20.0 * test::kPi / 180.0 * std::sin(test::kPi * (x - 10.0) / 20.0);
    return geom::Pose{{x, y, -3.0 + std::cos(x / 8.0)}, tilted(a)};
  };
  geom::MoveId id = 1;
  for (int pass = 0; pass < 2; ++pass) {
    const double y = 18.0 + 0.5 * pass;
    for (int i = 0; i < 40; ++i) {
      const double x0 = pass == 0 ? 10.0 + 0.5 * i : 30.0 - 0.5 * i;
      const double x1 = pass == 0 ? x0 + 0.5 : x0 - 0.5;
      moves.push_back({&c, pose(x0, y), pose(x1, y), id++});
    }
    if (pass == 0) moves.push_back({&c, pose(30.0, y), pose(30.0, y + 0.5), id++});
  }
  const geom::SubtractStats st = joined.subtract(moves);
  for (const auto& m : moves) single.subtract(std::span<const geom::SweepRef>(&m, 1));
  EXPECT_GT(st.sections_joined, 5u * st.sections);  // the clips saw unions of up to 8 sections
  const double perimeter = 2.0 * (20.0 + 7.0);
  EXPECT_LT(max_level_area_gap(joined, single), 2.0 * perimeter * kTol);
  EXPECT_GT(test::removed(joined), 250.0);
  EXPECT_NEAR(test::removed(joined), test::removed(single), 2.0 * perimeter * kTol * 10.0);
  EXPECT_EQ(joined.check_invariants(), "");
}

TEST(Joined, TiltedSweepBesideTheMaterialBuildsNoSection) {
  // A radial Ø10 face mill swung a quarter turn about the axis of a Ø40 bar with its face
  // on radius 30 (a lathe-c rotary rapid): never in the material, though its box meets the
  // bar's box near 45°. No section is built and nothing is removed; the same swing with
  // the face on radius 12 cuts. At the milling profiles' 10 µm: a face turning about an
  // axis in its plane needs a sub-step per 4·tol/ρ of turn (its hull's excess, ρφ/2).
  const double tol = 0.01;
  geom::SolidSpec spec;
  spec.shape = geom::SolidSpec::Shape::Cylinder;
  spec.cylinder = {0.0, 0.0, 40.0, -60.0, 0.0};
  spec.level_spacing_mm = 0.1;
  spec.regions_x = spec.regions_y = 2;
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 10, 0, 10), tol);
  auto swing = [&](geom::LbrSolid& s, double radius) {
    std::vector<geom::SweepRef> m;  // 16 chords of the arc, as the kinematics splits a C move
    for (int k = 0; k < 16; ++k) {
      const double a0 = 0.5 * test::kPi * k / 16, a1 = 0.5 * test::kPi * (k + 1) / 16;
      const geom::Vec3 u0{std::cos(a0), std::sin(a0), 0}, u1{std::cos(a1), std::sin(a1), 0};
      m.push_back({&c, {radius * u0 + geom::Vec3{0, 0, -38}, u0}, {radius * u1 + geom::Vec3{0, 0, -38}, u1},
                   static_cast<geom::MoveId>(k + 1)});
    }
    return s.subtract(m);
  };
  geom::LbrSolid outside(spec), inside(spec);
  const geom::SubtractStats so = swing(outside, 30.0);
  EXPECT_EQ(so.sections, 0u);
  EXPECT_EQ(test::removed(outside), 0.0);
  const geom::SubtractStats si = swing(inside, 12.0);
  EXPECT_GT(si.sections, 0u);
  EXPECT_GT(test::removed(inside), 100.0);
  EXPECT_EQ(inside.check_invariants(), "");
}

// ---- geom::tight_loop_end(): where a batch ends so that one turn of a tight loop is cut at a time ----

namespace {

std::vector<geom::SweepRef> refs(const geom::CutterShape& c, const std::vector<geom::Vec3>& pts) {
  std::vector<geom::SweepRef> out;
  for (std::size_t i = 1; i < pts.size(); ++i)
    out.push_back({&c, geom::Pose{pts[i - 1], {0, 0, 1}}, geom::Pose{pts[i], {0, 0, 1}}, static_cast<geom::MoveId>(i), nullptr});
  return out;
}

}  // namespace

// A plunge into the start of a joined pass and a retract from its end: on every level their
// section is the disk of the pass's first (last) point, which the pass's outline contains,
// so they add no section and the solid is the one the pass alone leaves, byte for byte. A
// plunge beside a single move keeps its section.
TEST(Joined, PlungeAndRetractBesideAPassAddNothingToIt) {
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  std::vector<geom::SweepRef> pass;
  // A dip to z -4 with level ends, so that on every level above -3 the first and last moves
  // are in the outline.
  geom::Vec3 prev{10, 20, -3};
  for (int i = 1; i <= 160; ++i) {
    const double x = 10.0 + 0.25 * i;
    const geom::Vec3 p{x, 20.0, -3.0 - 0.5 * (1.0 - std::cos(2.0 * test::kPi * (x - 10.0) / 40.0))};
    pass.push_back({&c, {prev, {0, 0, 1}}, {p, {0, 0, 1}}, static_cast<geom::MoveId>(10 + i)});
    prev = p;
  }
  std::vector<geom::SweepRef> with = pass;
  with.insert(with.begin(), geom::SweepRef{&c, test::at(10, 20, 5), test::at(10, 20, -3), 10});
  with.push_back({&c, {prev, {0, 0, 1}}, {{prev.x, prev.y, 5}, {0, 0, 1}}, 500});

  geom::LbrSolid alone(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  geom::LbrSolid both(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const geom::SubtractStats sa = alone.subtract(pass);
  const geom::SubtractStats sb = both.subtract(with);
  EXPECT_EQ(sb.sections, sa.sections);
  EXPECT_EQ(sb.sections_trimmed, sa.sections_trimmed + 2 * 30);  // both still moves, on the 30 levels above -3
  EXPECT_EQ(geom::to_bytes(both), geom::to_bytes(alone));
  EXPECT_GT(test::removed(alone), 100.0);

  // A plunge beside one move: no outline, so its section stays.
  geom::LbrSolid single(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const std::vector<geom::SweepRef> two{with[0], with[1]};
  const geom::SubtractStats ss = single.subtract(two);
  geom::LbrSolid one(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const geom::SubtractStats so = one.subtract(std::span<const geom::SweepRef>(&with[1], 1));
  EXPECT_GT(ss.sections, so.sections);
  EXPECT_EQ(both.check_invariants(), "");
}

TEST(TightLoop, HelixBatchEndsAfterOneTurn) {
  // Flat Ø8 on a helix of radius 2 (4 mm across: within 2 diameters), 720 chords a turn: the
  // turning between chords is 0.5°, a full circle after 720 of them, i.e. at move 721.
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const auto moves = refs(c, helix(30, 20, 2, 0, 1, 3, 720));
  const std::size_t n = geom::tight_loop_end(moves);
  EXPECT_NEAR(static_cast<double>(n), 721.0, 1.0);
  // From there the next batch again holds one turn.
  const std::size_t m = geom::tight_loop_end(std::span<const geom::SweepRef>(moves).subspan(n));
  EXPECT_NEAR(static_cast<double>(m), 721.0, 1.0);
}

TEST(TightLoop, WideLoopsZigZagsAndToolChangesAreNotCut) {
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const auto d = geom::CutterShape::build(test::tool(ToolKind::Ball, 6), kTol);
  // A circle of radius 20 (40 mm across: wider than 2 diameters of Ø8), three turns.
  const auto wide = refs(c, helix(30, 20, 20, 0, 0.5, 2, 360));
  EXPECT_EQ(geom::tight_loop_end(wide), wide.size());
  // A zig-zag in a 1 mm square turns back and forth: no net turn.
  std::vector<geom::Vec3> zz;
  for (int i = 0; i < 400; ++i) zz.push_back({10.0 + (i % 2), 10.0 + 0.002 * i, -1.0});
  const auto zig = refs(c, zz);
  EXPECT_EQ(geom::tight_loop_end(zig), zig.size());
  // Half a tight turn with one tool, then the other half with another: no loop of one tool.
  auto mixed = refs(c, helix(30, 20, 2, 0, 0, 0, 720));
  for (std::size_t i = 360; i < mixed.size(); ++i) mixed[i].shape = &d;
  EXPECT_EQ(geom::tight_loop_end(mixed), mixed.size());
}

TEST(TightLoop, BatchesCutAtLoopsRemoveTheExactHelicalBore) {
  // The bore of HelicalBoreIsTheAnnulusTimesTheDepth, in batches of at most 4096 moves each
  // ended by tight_loop_end() (as lbrsim batch and the live geometry thread cut them).
  geom::LbrSolid s(test::box_spec({0, 0, -10}, {60, 40, 0}, 0.1));
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 8), kTol);
  const auto moves = refs(c, helix(30, 20, 6, 0, 1, 5, 720));
  std::size_t batches = 0;
  for (std::size_t i = 0; i < moves.size(); ++batches) {
    const auto part = std::span<const geom::SweepRef>(moves).subspan(i, std::min<std::size_t>(4096, moves.size() - i));
    const std::size_t n = geom::tight_loop_end(part);
    s.subtract(part.first(n));
    i += n;
  }
  EXPECT_EQ(batches, 6u) << "one batch per turn";
  const double exact = test::kPi * (100.0 - 4.0) * 5.0;
  const double perimeter = 2.0 * test::kPi * (10.0 + 2.0);
  EXPECT_NEAR(test::removed(s), exact, 2.0 * perimeter * kTol * 5.0);
  EXPECT_EQ(s.check_invariants(), "");
}

// ---- geom::tilted_path_end(), geom::batch_end(): a batch's tilted moves run at most
// kTiltedBatchDiameters tool diameters ----

TEST(TiltedBatch, EndsAfterEightDiametersOfTiltedPath) {
  // Flat Ø10, moves of 1 mm in X: 8 diameters are 80 mm, so the 81st tilted move would
  // exceed them and the batch ends before it (after 100 vertical and 80 tilted moves).
  // Vertical moves do not count.
  const auto c = geom::CutterShape::build(test::tool(ToolKind::Flat, 10), kTol);
  const geom::Vec3 tilted{0.0, std::sin(0.2), std::cos(0.2)};
  std::vector<geom::SweepRef> moves;
  for (int i = 0; i < 400; ++i) {
    const bool vertical = i < 100;  // 100 vertical moves first
    const geom::Vec3 axis = vertical ? geom::Vec3{0, 0, 1} : tilted;
    moves.push_back({&c, geom::Pose{{1.0 * i, 0, 0}, axis}, geom::Pose{{1.0 * (i + 1), 0, 0}, axis},
                     static_cast<geom::MoveId>(i + 1), nullptr});
  }
  ASSERT_DOUBLE_EQ(geom::kTiltedBatchDiameters, 8.0);
  EXPECT_EQ(geom::tilted_path_end(moves), 180u);
  EXPECT_EQ(geom::batch_end(moves), 180u);  // no tight loop in a straight line
  EXPECT_EQ(geom::tilted_path_end(std::span<const geom::SweepRef>(moves).first(100)), 100u);  // all vertical
  // One move longer than the bound on its own still makes a batch of one.
  const std::vector<geom::SweepRef> long_move{{&c, geom::Pose{{0, 0, 0}, tilted}, geom::Pose{{500, 0, 0}, tilted}, 1, nullptr},
                                              {&c, geom::Pose{{500, 0, 0}, tilted}, geom::Pose{{501, 0, 0}, tilted}, 2, nullptr}};
  EXPECT_EQ(geom::tilted_path_end(long_move), 1u);
  // A tight helix ends the batch first where it closes its turn (tight_loop_end()).
  const auto helix_moves = refs(c, helix(30, 20, 2, 0, 1, 3, 720));
  EXPECT_EQ(geom::batch_end(helix_moves), geom::tight_loop_end(helix_moves));
}
