// Export pulls apart the sheets that touch along an edge and drops zero-thickness fins
// (mesh/src/sheets.cpp): after it, every edge of the exported part is used once in each
// direction, by position, as an independent checker (admesh) pairs them.
#include <array>
#include <map>

#include <gtest/gtest.h>

#include "sheets.hpp"

using namespace lbr;
using mesh::detail::ExportMesh;

namespace {

using P3 = std::array<float, 3>;

// A box [x0, x1] x [y0, y1] x [0, 1] as 12 outward-facing triangles into `m`.
void add_box(mesh::MeshBuffers& m, float x0, float y0, float x1, float y1) {
  const auto base = static_cast<std::uint32_t>(m.keys.size());
  for (int k = 0; k < 8; ++k) {
    m.positions.insert(m.positions.end(), {(k & 1) ? x1 : x0, (k & 2) ? y1 : y0, (k & 4) ? 1.0f : 0.0f});
    m.normals.insert(m.normals.end(), {0, 0, 1});
    m.attributes.push_back(0);
    m.keys.push_back({});
  }
  const std::uint32_t f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                  {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& t : f)
    for (std::uint32_t v : t) m.indices.push_back(base + v);
}

// Uses of each directed edge, by exact position.
std::map<std::pair<P3, P3>, int> directed_edges(const ExportMesh& m) {
  std::map<std::pair<P3, P3>, int> uses;
  auto at = [&](std::uint32_t v) { return P3{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]}; };
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int i = 0; i < 3; ++i) ++uses[{at(m.indices[3 * t + i]), at(m.indices[3 * t + (i + 1) % 3])}];
  return uses;
}

// Edges not used exactly once each way.
int unpaired(const ExportMesh& m) {
  const auto uses = directed_edges(m);
  int bad = 0;
  for (const auto& [e, n] : uses) {
    const auto r = uses.find({e.second, e.first});
    if (n != 1 || r == uses.end() || r->second != 1) ++bad;
  }
  return bad;
}

}  // namespace

TEST(Sheets, TwoBoxesTouchingAlongAnEdgeBecomeTwoClosedSheets) {
  mesh::MeshBuffers a, b;
  add_box(a, 0, 0, 1, 1);
  add_box(b, 1, 1, 2, 2);  // shares the edge x = 1, y = 1, z in [0, 1] with the first
  const std::array<mesh::MeshBuffers, 2> regions{a, b};
  ExportMesh m = mesh::detail::concatenate(regions);
  EXPECT_EQ(unpaired(m), 2);  // the shared edge, both directions, used twice each
  const std::size_t added = mesh::detail::separate_touching_sheets(m, 0.0005f);
  EXPECT_EQ(added, 2u);  // the smaller sheet's copies of the edge's two vertices
  EXPECT_EQ(m.triangle_count(), 24u);
  EXPECT_EQ(unpaired(m), 0);
}

TEST(Sheets, AZeroThicknessFinIsDropped) {
  mesh::MeshBuffers a;
  add_box(a, 0, 0, 1, 1);
  // A fin on the top face's diagonal plane: the same triangle both ways.
  const auto base = static_cast<std::uint32_t>(a.keys.size());
  for (const P3& p : {P3{0, 0, 1}, P3{1, 1, 1}, P3{0.5f, 0.5f, 2}}) {
    a.positions.insert(a.positions.end(), p.begin(), p.end());
    a.normals.insert(a.normals.end(), {0, 0, 1});
    a.attributes.push_back(0);
    a.keys.push_back({});
  }
  a.indices.insert(a.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 1});
  const std::array<mesh::MeshBuffers, 1> regions{a};
  ExportMesh m = mesh::detail::concatenate(regions);
  EXPECT_EQ(m.triangle_count(), 14u);
  EXPECT_EQ(mesh::detail::separate_touching_sheets(m, 0.0005f), 0u);
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_EQ(unpaired(m), 0);
}
