#include "mesh/export.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "sheets.hpp"

namespace lbr::mesh {

namespace {

void put_u32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_f32(std::vector<std::uint8_t>& b, float f) { put_u32(b, std::bit_cast<std::uint32_t>(f)); }

}  // namespace

namespace {

// Pulled apart at touching sheets (sheets.hpp): 0.5 µm, well above float32's resolution at
// the size of a stock and far below the chord tolerance.
constexpr float kSheetGapMm = 0.0005f;

detail::ExportMesh export_mesh(std::span<const MeshBuffers> regions) {
  detail::ExportMesh m = detail::concatenate(regions);
  detail::separate_touching_sheets(m, kSheetGapMm);
  return m;
}

}  // namespace

std::vector<std::uint8_t> to_binary_stl(std::span<const MeshBuffers> regions, const std::string& header) {
  const detail::ExportMesh m = export_mesh(regions);
  const std::size_t n = m.triangle_count();
  std::vector<std::uint8_t> b;
  b.reserve(84 + 50 * n);
  for (std::size_t i = 0; i < 80; ++i) b.push_back(i < header.size() ? static_cast<std::uint8_t>(header[i]) : 0);
  put_u32(b, static_cast<std::uint32_t>(n));
  for (std::size_t t = 0; t < n; ++t) {
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
  return b;
}

std::vector<std::uint8_t> to_binary_ply(std::span<const MeshBuffers> regions, std::span<const std::uint8_t> rgb) {
  const detail::ExportMesh m = export_mesh(regions);
  std::vector<float> normals, attributes;  // of the regions' vertices, concatenated
  for (const MeshBuffers& r : regions) {
    normals.insert(normals.end(), r.normals.begin(), r.normals.end());
    attributes.insert(attributes.end(), r.attributes.begin(), r.attributes.end());
  }
  const std::size_t nv = m.vertex_count(), nf = m.triangle_count();
  const bool colours = !rgb.empty() && rgb.size() == 3 * attributes.size();
  const std::string head = "ply\nformat binary_little_endian 1.0\ncomment lbrsim reconstruction\nelement vertex " +
                           std::to_string(nv) +
                           "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
                           "property float ny\nproperty float nz\nproperty float move_id\n" +
                           std::string(colours ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "") +
                           "element face " +
                           std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<std::uint8_t> b(head.begin(), head.end());
  b.reserve(head.size() + 28 * nv + 13 * nf);
  for (std::size_t v = 0; v < nv; ++v) {
    const std::size_t k = m.source[v];
    for (int a = 0; a < 3; ++a) put_f32(b, m.positions[3 * v + a]);
    for (int a = 0; a < 3; ++a) put_f32(b, normals[3 * k + a]);
    put_f32(b, attributes[k]);
    if (colours) b.insert(b.end(), rgb.begin() + static_cast<std::ptrdiff_t>(3 * k), rgb.begin() + static_cast<std::ptrdiff_t>(3 * k + 3));
  }
  for (std::size_t t = 0; t < nf; ++t) {
    b.push_back(3);
    for (int v = 0; v < 3; ++v) put_u32(b, m.indices[3 * t + v]);
  }
  return b;
}

}  // namespace lbr::mesh
