// Private helpers over Clipper's types used by the solid and by serialisation.
#pragma once

#include <vector>

#include "geom/lbr_solid.hpp"

namespace lbr::geom::detail {

// True when b is the same closed contour as a, possibly starting at another vertex.
[[nodiscard]] bool same_cycle(const Path& a, const Path& b) noexcept;

// Appends the polygons (outer + holes) of a Clipper PolyTree to `out`; cut_by is 0.
void append_polygons(const ClipperLib::PolyTree& tree, std::vector<Polygon>& out);

// Length of a closed contour [units].
[[nodiscard]] double perimeter(const Path& p) noexcept;

// Bounding box and cached area of a cell recomputed from its polygons.
void refresh_cell(Cell& cell) noexcept;

}  // namespace lbr::geom::detail
