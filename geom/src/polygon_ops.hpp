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

// The closed path `in` cut down to the rectangle r, written to `out` (`tmp` is a scratch
// buffer): per side of r, each run of three or more vertices beyond it is replaced by its
// first and last vertex and their projections onto the side. Inside r the path is unchanged
// vertex for vertex (no new intersection points, so no rounding), and so is the winding
// number of every point: the replaced parts lie outside. A self-overlapping outline keeps
// its non-zero region inside r. Allocates only when the buffers grow.
void cut_to_rect(const Path& in, const Rect& r, Path& out, Path& tmp);

// b lies wholly inside a.
[[nodiscard]] inline bool contains(const Rect& a, const Rect& b) noexcept {
  return b.x0 >= a.x0 && b.x1 <= a.x1 && b.y0 >= a.y0 && b.y1 <= a.y1;
}

// The rectangle as a counter-clockwise path.
[[nodiscard]] inline Path rect_path(const Rect& r) {
  return Path{{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}};
}

// Bounding box and cached area of a cell recomputed from its polygons.
void refresh_cell(Cell& cell) noexcept;

}  // namespace lbr::geom::detail
