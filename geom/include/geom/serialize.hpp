// geom/serialize.hpp — the LBR level file (format "LBRS", docs/formats.md#levels-file).
// Pure functions over bytes: no I/O here; the application writes the bytes to disk.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::geom {

// Serialises spec, grid and every cell. Allocates.
[[nodiscard]] std::vector<std::uint8_t> to_bytes(const LbrSolid& solid);
// Rebuilds a solid from to_bytes() output. Throws std::runtime_error naming the byte offset
// and what was expected on malformed input.
[[nodiscard]] LbrSolid from_bytes(const std::vector<std::uint8_t>& bytes);

}  // namespace lbr::geom
