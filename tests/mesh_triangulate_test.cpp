// Triangulator: area of the triangles = polygon area, and the edge contract (every ring
// edge once, every diagonal twice in opposite directions), on analytic and random inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include <clipper.hpp>

#include "mesh/triangulate.hpp"

namespace {

using lbr::geom::Path;
using lbr::geom::Paths;
using lbr::geom::Point;
using lbr::mesh::triangulate;

double area_of(const Paths& rings) {
  double a = 0;
  for (const Path& p : rings) a += std::abs(ClipperLib::Area(p)) * (&p == &rings[0] ? 1.0 : -1.0);
  return a;
}
double tri_area(const std::vector<lbr::mesh::Triangle2>& t) {
  double a = 0;
  for (const auto& x : t) a += 0.5 * lbr::mesh::triangle_area2(x[0], x[1], x[2]);
  return a;
}
// Every directed ring edge (outer CCW, holes CW) once; other edges once each way.
bool edge_contract(const Paths& rings, const std::vector<lbr::mesh::Triangle2>& tris) {
  using E = std::pair<std::pair<long long, long long>, std::pair<long long, long long>>;
  std::map<E, int> n;
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) ++n[{{t[e].X, t[e].Y}, {t[(e + 1) % 3].X, t[(e + 1) % 3].Y}}];
  for (std::size_t r = 0; r < rings.size(); ++r) {
    Path p = rings[r];
    if ((ClipperLib::Area(p) > 0) != (r == 0)) std::reverse(p.begin(), p.end());
    for (std::size_t j = 0; j < p.size(); ++j) {
      const Point a = p[j], b = p[(j + 1) % p.size()];
      auto it = n.find({{a.X, a.Y}, {b.X, b.Y}});
      if (it == n.end() || it->second != 1) return false;
      n.erase(it);
    }
  }
  for (const auto& [e, c] : n) {
    auto it = n.find({e.second, e.first});
    if (c != 1 || it == n.end() || it->second != 1) return false;
  }
  return true;
}

TEST(MeshTriangulate, SquareWithHole) {
  const Paths rings{{{0, 0}, {100, 0}, {100, 100}, {0, 100}}, {{30, 30}, {30, 60}, {60, 60}, {60, 30}}};
  lbr::mesh::TriangulateStats st;
  const auto t = triangulate(rings, &st);
  EXPECT_DOUBLE_EQ(tri_area(t), 100.0 * 100 - 30 * 30);
  EXPECT_EQ(st.forced, 0u);
  EXPECT_TRUE(edge_contract(rings, t));
}

TEST(MeshTriangulate, CollinearAndDuplicateVertices) {
  // Clipper-style output with collinear points along the sides and a repeated vertex.
  const Paths rings{{{0, 0}, {50, 0}, {100, 0}, {100, 0}, {100, 50}, {100, 100}, {50, 100}, {0, 100}, {0, 50}},
                    {{20, 20}, {20, 40}, {20, 60}, {40, 60}, {40, 20}},
                    {{60, 20}, {60, 80}, {80, 80}, {80, 20}, {70, 20}}};
  lbr::mesh::TriangulateStats st;
  const auto t = triangulate(rings, &st);
  EXPECT_DOUBLE_EQ(tri_area(t), 10000.0 - 800 - 1200);
  EXPECT_EQ(st.forced, 0u);
  Paths dedup = rings;
  dedup[0].erase(dedup[0].begin() + 3);  // the contract is over distinct consecutive points
  EXPECT_TRUE(edge_contract(dedup, t));
}

TEST(MeshTriangulate, ClockwiseInputIsReoriented) {
  const Paths rings{{{0, 0}, {0, 10}, {10, 10}, {10, 0}}};
  const auto t = triangulate(rings);
  EXPECT_DOUBLE_EQ(tri_area(t), 100.0);
}

// Seeded random: a circle-ish star polygon minus random disjoint circles, through Clipper
// (so the input has Clipper's rounding), triangulated area = Clipper area.
TEST(MeshTriangulate, RandomPolygonsWithHoles) {
  for (std::uint32_t seed = 1; seed <= 60; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Path star;
    const int n = 5 + static_cast<int>(u(rng) * 60);
    for (int k = 0; k < n; ++k) {
      const double a = 2 * M_PI * k / n, r = 50000 + 45000 * u(rng);
      star.push_back({static_cast<long long>(r * std::cos(a)), static_cast<long long>(r * std::sin(a))});
    }
    ClipperLib::Clipper c;
    c.StrictlySimple(true);
    c.AddPath(star, ClipperLib::ptSubject, true);
    const int holes = static_cast<int>(u(rng) * 12);
    for (int h = 0; h < holes; ++h) {
      Path circ;
      const double cx = (u(rng) - 0.5) * 120000, cy = (u(rng) - 0.5) * 120000, r = 2000 + 20000 * u(rng);
      for (int k = 0; k < 24; ++k)
        circ.push_back({static_cast<long long>(cx + r * std::cos(2 * M_PI * k / 24)),
                        static_cast<long long>(cy + r * std::sin(2 * M_PI * k / 24))});
      c.AddPath(circ, ClipperLib::ptClip, true);
    }
    ClipperLib::PolyTree tree;
    c.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
    std::vector<const ClipperLib::PolyNode*> stack(tree.Childs.begin(), tree.Childs.end());
    while (!stack.empty()) {
      const ClipperLib::PolyNode* o = stack.back();
      stack.pop_back();
      Paths rings{o->Contour};
      for (const ClipperLib::PolyNode* h : o->Childs) {
        rings.push_back(h->Contour);
        for (const ClipperLib::PolyNode* i : h->Childs) stack.push_back(i);
      }
      lbr::mesh::TriangulateStats st;
      const auto t = triangulate(rings, &st);
      EXPECT_NEAR(tri_area(t), area_of(rings), 1e-6 * std::abs(area_of(rings))) << "seed " << seed;
      EXPECT_EQ(st.forced, 0u) << "seed " << seed;
      EXPECT_TRUE(edge_contract(rings, t)) << "seed " << seed;
    }
  }
}

}  // namespace
