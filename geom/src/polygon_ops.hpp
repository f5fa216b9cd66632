// Private helpers over Clipper's types used by the solid and by serialisation.
#pragma once

#include <span>
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

// Splits every edge of the closed path where it crosses one of the lines x = xs[i] or
// y = ys[j] (each sorted ascending), with a vertex at the crossing rounded to the unit grid
// (half away from zero), computed from the edge's endpoints in a fixed order so that an
// edge and its reverse give the same point. Region borders: a section crosses a border at
// a vertex that every region's clip sees, instead of at a point each clip rounds on its own
// (a crossing half a unit between grid points went either way, region by region; docs/mesh.md).
// Unchanged when its box spans no line. `tmp` is a scratch buffer; allocates only when the
// buffers grow.
void split_at_lines(Path& path, std::span<const Coord> xs, std::span<const Coord> ys, Path& tmp);

// Removes the slivers that rounding crossings to the unit grid leaves in a clip's result
// (docs/mesh.md §6): repeatedly, a vertex within `dist` [units] of a neighbour, or one whose
// removal moves the contour by less than `dist` (a vertex almost on the line through its
// neighbours, or the tip of a spike one unit wide). On a side of `keep` (the region's
// rectangle: its border vertices are what the neighbour's contours meet) only the tip of
// such a spike goes.
// A contour left with fewer than 3 vertices is emptied. Returns true when it changed.
// `tmp` is a scratch buffer.
bool remove_slivers(Path& contour, const Rect& keep, double dist, Path& tmp);

// A box that holds every point of the polygons `touched` of `cell` lying in r: the parts
// of their edges inside r (crossings with r's sides rounded outwards) and the corners of r
// that lie in the polygons or on them. The box of S ∩ r is that of its boundary, which
// consists of pieces of S's edges inside r and pieces of r's sides inside S, and the ends
// of the latter are corners of r or crossings. Empty when the polygons do not meet r.
[[nodiscard]] Rect material_box(const Cell& cell, std::span<const std::uint32_t> touched, const Rect& r) noexcept;

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
