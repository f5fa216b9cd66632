// The union of consecutive convex polygons that follow a path, without a sweep-line clip:
// the region between their upper and lower envelopes along the path's main axis
// (docs/lbr-conventions.md, "Joined sections", tilted moves).
#pragma once

#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/sweep.hpp"

namespace lbr::geom::detail {

// A union of polygons grown one polygon at a time while it stays monotone along the frame's
// x axis (each line x = const meets it in one interval). The frame is the plane turned by a
// multiple of 90° so that the path runs along +x as nearly as it can: then a new polygon
// overlaps only the end of the envelopes, and adding it costs time linear in its vertices
// and that overlap. Reuses its buffers; allocates only when they grow. One per thread.
class MonotoneUnion {
 public:
  using P = SectionScratch::P2;

  // Starts an empty union whose path runs in direction (dx, dy) [any units].
  void begin(double dx, double dy) noexcept;

  // Adds a polygon and returns true when it is counter-clockwise with area, monotone along
  // the frame's x, and meets the union so far on every line x = const both reach (so that
  // the union stays the region between the envelopes) without making an envelope jump where
  // it begins or ends. Otherwise returns false and leaves the union unchanged.
  [[nodiscard]] bool add(const Path& poly);

  // Polygons added since begin().
  [[nodiscard]] std::size_t count() const noexcept { return count_; }

  // The union as one counter-clockwise polygon, its vertices rounded to the unit grid (the
  // envelopes' crossings are kept exact until then: half a unit, as a clip's union).
  void write(Path& out) const;

 private:
  [[nodiscard]] P to_frame(const Point& q) const noexcept;
  [[nodiscard]] Point from_frame(double x, double y) const noexcept;
  [[nodiscard]] bool chains_of(const Path& poly);
  [[nodiscard]] bool meets_union(std::size_t ku, std::size_t kl) const;

  int quarter_ = 0;  // the frame is the plane turned by −90°·quarter_
  std::size_t count_ = 0;
  std::vector<P> up_, lo_;  // the union's upper envelope, and its lower envelope negated
  std::vector<P> cu_, cl_;  // the polygon being added: its upper chain, its lower chain negated
  std::vector<P> pu_, pl_;  // the same of the polygon added last
  std::vector<P> pts_;      // the polygon being added, in the frame
  std::vector<P> tmp_, tmp2_;  // the merges' output (upper, lower)
  std::vector<P> cut_u_, cut_l_;  // a chain's part that can rise above the envelope, when cut between vertices
};

}  // namespace lbr::geom::detail
