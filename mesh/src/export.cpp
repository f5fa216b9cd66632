#include "mesh/export.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

namespace lbr::mesh {

namespace {

void put_u32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_f32(std::vector<std::uint8_t>& b, float f) { put_u32(b, std::bit_cast<std::uint32_t>(f)); }

}  // namespace

std::vector<std::uint8_t> to_binary_stl(std::span<const MeshBuffers> regions, const std::string& header) {
  std::size_t n = 0;
  for (const MeshBuffers& m : regions) n += m.triangle_count();
  std::vector<std::uint8_t> b;
  b.reserve(84 + 50 * n);
  for (std::size_t i = 0; i < 80; ++i) b.push_back(i < header.size() ? static_cast<std::uint8_t>(header[i]) : 0);
  put_u32(b, static_cast<std::uint32_t>(n));
  for (const MeshBuffers& m : regions) {
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const float* p[3];
      for (int v = 0; v < 3; ++v) p[v] = &m.positions[3 * static_cast<std::size_t>(m.indices[3 * t + v])];
      const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      double nv[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
      for (double& c : nv) c = len > 0 ? c / len : 0.0;
      for (double c : nv) put_f32(b, static_cast<float>(c));
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a) put_f32(b, p[v][a]);
      b.push_back(0);
      b.push_back(0);
    }
  }
  return b;
}

std::vector<std::uint8_t> to_binary_ply(std::span<const MeshBuffers> regions, std::span<const std::uint8_t> rgb) {
  std::size_t nv = 0, nf = 0;
  for (const MeshBuffers& m : regions) {
    nv += m.vertex_count();
    nf += m.triangle_count();
  }
  const bool colours = !rgb.empty() && rgb.size() == 3 * nv;
  const std::string head = "ply\nformat binary_little_endian 1.0\ncomment lbrsim reconstruction\nelement vertex " +
                           std::to_string(nv) +
                           "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
                           "property float ny\nproperty float nz\nproperty float move_id\n" +
                           std::string(colours ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "") +
                           "element face " +
                           std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<std::uint8_t> b(head.begin(), head.end());
  b.reserve(head.size() + 28 * nv + 13 * nf);
  std::size_t k = 0;  // vertex index over all regions
  for (const MeshBuffers& m : regions)
    for (std::size_t v = 0; v < m.vertex_count(); ++v, ++k) {
      for (int a = 0; a < 3; ++a) put_f32(b, m.positions[3 * v + a]);
      for (int a = 0; a < 3; ++a) put_f32(b, m.normals[3 * v + a]);
      put_f32(b, m.attributes[v]);
      if (colours) b.insert(b.end(), rgb.begin() + static_cast<std::ptrdiff_t>(3 * k), rgb.begin() + static_cast<std::ptrdiff_t>(3 * k + 3));
    }
  std::uint32_t base = 0;
  for (const MeshBuffers& m : regions) {
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      b.push_back(3);
      for (int v = 0; v < 3; ++v) put_u32(b, base + m.indices[3 * t + v]);
    }
    base += static_cast<std::uint32_t>(m.vertex_count());
  }
  return b;
}

}  // namespace lbr::mesh
