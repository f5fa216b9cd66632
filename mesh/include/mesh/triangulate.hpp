// mesh/triangulate.hpp — triangulation of integer polygons with holes (ear clipping).
//
// Input: one outer ring and any number of hole rings in kernel units (geom::Point). The
// rings are reoriented as needed (outer CCW, holes CW); holes are bridged into the outer
// ring, then ears are clipped.
//
// Contract that the mesh relies on (watertightness): every edge of every input ring (after
// dropping consecutive duplicate points) is used by exactly one output triangle, in the
// direction of the reoriented ring, and every other edge is used exactly twice in opposite
// directions. This holds combinatorially whatever the geometry: collinear vertices give
// zero-area triangles instead of being dropped, and when no valid ear exists (input not
// simple after rounding) an ear is forced and counted in `forced`. Orientation tests are
// exact (128-bit integer arithmetic).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "geom/types.hpp"

namespace lbr::mesh {

using Triangle2 = std::array<geom::Point, 3>;  // counter-clockwise when non-degenerate

struct TriangulateStats {
  std::size_t forced = 0;      // ears clipped without the empty-triangle test
  std::size_t degenerate = 0;  // zero-area triangles emitted (collinear vertices)
};

// Reusable buffers; one per thread. Grows to the largest polygon seen.
struct TriangulateScratch {
  struct Node {
    geom::Point p;
    int prev = -1, next = -1;
  };
  std::vector<Node> nodes;
  std::vector<int> hole_start;
};

// Appends the triangles of the polygon `rings[0]` minus holes `rings[1..]` to `out`.
// Allocates (grows `out` and the scratch); does not throw except std::bad_alloc.
TriangulateStats triangulate(const std::vector<const geom::Path*>& rings, std::vector<Triangle2>& out,
                             TriangulateScratch& scratch);

// Convenience overload for tests.
std::vector<Triangle2> triangulate(const geom::Paths& rings, TriangulateStats* stats = nullptr);

// Twice the signed area [units²] of triangle abc, exact.
[[nodiscard]] double triangle_area2(const geom::Point& a, const geom::Point& b, const geom::Point& c) noexcept;

}  // namespace lbr::mesh
