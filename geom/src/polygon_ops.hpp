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

// The closed path `in` cut to the rectangle r (Sutherland-Hodgman), written to `out`
// (`tmp` is a scratch buffer). The winding number of every point inside r is kept: each
// excursion outside r is replaced by a run along r's boundary, and the loop they form lies
// outside r. So a self-overlapping outline keeps its non-zero region inside r; along r's
// boundary the result may double back on itself. Allocates only when the buffers grow.
void cut_to_rect(const Path& in, const Rect& r, Path& out, Path& tmp);

// Bounding box and cached area of a cell recomputed from its polygons.
void refresh_cell(Cell& cell) noexcept;

}  // namespace lbr::geom::detail
