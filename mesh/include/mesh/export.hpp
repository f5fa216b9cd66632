// mesh/export.hpp — whole-part export of reconstructed regions as binary STL or PLY bytes.
// Pure functions: no file I/O here (the app writes the bytes). Allocate; not real-time safe.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mesh/reconstruct.hpp"

namespace lbr::mesh {

// Binary STL (little-endian): 80-byte header (`header`, truncated/padded with zeros),
// uint32 triangle count, then per triangle the unit face normal, three vertices [mm] as
// float32 and a zero uint16 attribute.
[[nodiscard]] std::vector<std::uint8_t> to_binary_stl(std::span<const MeshBuffers> regions,
                                                      const std::string& header = "lbrsim");

// Binary PLY 1.0 (little-endian): vertices with x y z nx ny nz (float32) and move_id (float32:
// the id of the move that last cut there, for colouring by time); faces as uchar-counted
// lists of int32 indices. Regions are concatenated (vertex ids offset per region).
// With `rgb` (3 bytes a vertex, the regions' vertices in order; empty: none), the vertices
// also carry uchar red, green, blue (e.g. deviation colours, docs/formats.md#ply).
[[nodiscard]] std::vector<std::uint8_t> to_binary_ply(std::span<const MeshBuffers> regions,
                                                      std::span<const std::uint8_t> rgb = {});

}  // namespace lbr::mesh
