// STL and PLY bytes: layout, counts, and the enclosed volume read back from the STL.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "mesh/export.hpp"
#include "mesh_test_util.hpp"

namespace {

using namespace lbr;
using namespace lbr::mesh::testing;

std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
         static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
}
float f32(const std::vector<std::uint8_t>& b, std::size_t at) {
  const std::uint32_t v = u32(b, at);
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}

TEST(MeshExport, StlAndPly) {
  geom::LbrSolid s(box_spec(20, 16, 5, 0.25, 2, 2));
  const auto ball = cutter(geom::ToolKind::Ball, 6);
  cut(s, ball, {-4, 8, 3}, {24, 9, 3.5}, 1);
  const std::vector<mesh::MeshBuffers> regions = mesh::reconstruct(s);
  std::size_t tris = 0, verts = 0;
  double vol = 0;
  for (const auto& m : regions) {
    tris += m.triangle_count();
    verts += m.vertex_count();
  }
  const std::vector<std::uint8_t> stl = mesh::to_binary_stl(regions, "test");
  ASSERT_EQ(stl.size(), 84 + 50 * tris);
  EXPECT_EQ(std::string(stl.begin(), stl.begin() + 4), "test");
  EXPECT_EQ(u32(stl, 80), tris);
  for (std::size_t t = 0; t < tris; ++t) {  // divergence theorem on the float vertices
    double p[3][3];
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a) p[v][a] = f32(stl, 84 + 50 * t + 12 + 12 * v + 4 * a);
    vol += (p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) - p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
            p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0])) / 6.0;
  }
  double expect = 0;
  for (const auto& m : regions) expect += m.volume_mm3;
  EXPECT_NEAR(vol, expect, 1e-4 * expect);  // float32 coordinates

  const std::vector<std::uint8_t> ply = mesh::to_binary_ply(regions);
  const std::string text(ply.begin(), ply.end());
  const std::size_t end = text.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(text.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(text.find("element vertex " + std::to_string(verts) + "\n"), std::string::npos);
  EXPECT_NE(text.find("element face " + std::to_string(tris) + "\n"), std::string::npos);
  EXPECT_EQ(ply.size(), end + 11 + 28 * verts + 13 * tris);
}

}  // namespace

namespace {

// GL buffers: sizes agree, normals are unit, flat floors shade flat, walls point outwards,
// and the attribute carries the id of the move that cut there (0 on untouched stock; the
// kernel records ids per contour, so a whole changed contour carries the id).
TEST(MeshBuffers, NormalsAndMoveIds) {
  geom::LbrSolid s(box_spec(20, 16, 5, 0.25, 2, 2));
  const auto flat = cutter(geom::ToolKind::Flat, 6);
  cut(s, flat, {-4, 4, 3}, {24, 4, 3}, 7);  // a slot in the lower regions: vertical walls, flat floor
  const std::vector<mesh::MeshBuffers> regions = mesh::reconstruct(s);
  std::size_t floor_vertices = 0;
  for (const auto& m : regions) {
    ASSERT_EQ(m.positions.size(), 3 * m.vertex_count());
    ASSERT_EQ(m.normals.size(), 3 * m.vertex_count());
    ASSERT_EQ(m.attributes.size(), m.vertex_count());
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      const float nx = m.normals[3 * v], ny = m.normals[3 * v + 1], nz = m.normals[3 * v + 2];
      EXPECT_NEAR(nx * nx + ny * ny + nz * nz, 1.0f, 1e-5f);
      const float z = m.positions[3 * v + 2], y = m.positions[3 * v + 1];
      if (nz == 1.0f && std::abs(z - 3.0f) < 1e-4f && y > 0.9f && y < 7.1f) {
        ++floor_vertices;  // the slot floor: flat, cut by move 7
        EXPECT_EQ(m.attributes[v], 7.0f);
      }
      if (y > 8.0f) {
        EXPECT_EQ(m.attributes[v], 0.0f);  // regions the slot does not reach
      }
    }
  }
  EXPECT_GT(floor_vertices, 0u);
}

}  // namespace
