// Private: the part as one indexed mesh for export, with the sheets that touch along an
// edge pulled apart (docs/mesh.md §1, "Where this is not a 2-manifold").
//
// Where two pieces of the LBR solid touch along a line, the reconstruction uses that edge
// twice in each direction: closed and oriented, but four triangles meet there, and a
// checker that pairs edges by position (admesh) cannot tell the two sheets apart. Export
// pairs each edge's uses by the side the material lies on, splits every vertex whose
// triangles then fall into separate sheets, and moves the copies of all sheets but the
// largest by `gap_mm` towards their own triangles: each edge is then used once each way.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/reconstruct.hpp"

namespace lbr::mesh::detail {

struct ExportMesh {
  std::vector<float> positions;        // x, y, z per vertex [mm]
  std::vector<std::uint32_t> source;   // per vertex: its index in the regions' concatenation
  std::vector<std::uint32_t> indices;  // 3 per triangle
  [[nodiscard]] std::size_t vertex_count() const noexcept { return source.size(); }
  [[nodiscard]] std::size_t triangle_count() const noexcept { return indices.size() / 3; }
};

// The regions' buffers concatenated (vertex ids offset per region).
[[nodiscard]] ExportMesh concatenate(std::span<const MeshBuffers> regions);

// Pulls apart the sheets that meet at a vertex only through edges used twice each way;
// returns the vertices added. Edges used otherwise (not 1 + 1 or 2 + 2 times) are left.
std::size_t separate_touching_sheets(ExportMesh& m, float gap_mm);

}  // namespace lbr::mesh::detail
