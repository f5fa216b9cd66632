// Private: a test, before a cell's clip, that the level's sections cannot change the cell
// (docs/lbr-conventions.md, "Clips out of reach").
//
// Every vertical section (one move's, or a joined outline's) lies inside capsules around
// its moves' XY segments: the move's disks have their centres on that segment, so every
// vertex of its polygon lies within the vertex radius ρ of it. A tight loop's later turns,
// and a finishing pass over cleared levels, reach the material only in the band that the
// polygonisation itself leaves open (ρ − tol … ρ): the difference removes rounding slivers
// at most, yet costs a whole Clipper run over the cell's contours and the section's
// outline. When no material lies within ρ − band of any move's segment, the clip is left
// out: what it could have removed lies within the band of the section's boundary.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/sweep.hpp"

namespace lbr::geom::detail {

struct LevelSections;

// A segment and the radius around it that a section's material test uses [units].
struct ReachCapsule {
  double ax = 0, ay = 0, bx = 0, by = 0;
  double r = 0;  // the bounding radius less the band; <= 0: the capsule tests nothing
  friend bool operator==(const ReachCapsule&, const ReachCapsule&) = default;
};

// Per thread: buffers of material_out_of_reach().
struct ReachScratch {
  struct Box {
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  };
  struct Item {
    Box box;              // the capsule's box [units]
    double lo = 0;        // start of its angular interval about the test centre [rad, 0..2π)
    std::uint32_t k = 0;  // index into caps
    bool wide = false;    // spans a wide angle or passes the centre: tested against every edge
  };
  struct Chunk {
    Box box;                        // of consecutive items [begin, end)
    std::uint32_t begin = 0, end = 0;
  };
  std::vector<ReachCapsule> caps;
  std::vector<Item> items;
  std::vector<std::uint32_t> sorted, wide;  // items: narrow ones by lo; wide ones
  std::vector<Chunk> chunks;
  // Derived from the capsules: the centre o of the angular test (the middle of their
  // segments' box), the largest distance of a segment end from o and the least of a segment,
  // the largest radius, the capsules' box.
  struct Frame {
    double ox = 0, oy = 0, rho_max = 0, rho_min = 0, r_max = 0;
    Box all;
    bool angular = false;  // items carry lo/wide and `sorted`, `wide` are built
  };
  Frame frame;
  std::vector<ReachCapsule> framed;  // the capsules that items, chunks and frame describe
  bool framed_valid = false, framed_items = false;
};

// The width of the band [units] a skipped clip may leave unremoved, below the section's
// vertex radius: a two-sided polygon's chords come up to 1.5·tol inside its vertex radius
// (vertices tol/2 outside the exact circle, chords up to tol inside; docs/lbr-conventions.md,
// "Two-sided polygons"), tol/2 for a merged sampled chord, and two units for rounding.
[[nodiscard]] double reach_band_units(double chord_tol_mm) noexcept;

// Appends one capsule per move of a joined outline: the segment c0–c1 and the largest
// distance of the move's section vertices from it (caps on rho0 / rho1, the sides'
// vertices), plus one unit for rounding, less `band_units`.
void add_outline_reach(std::span<const MoveCaps> moves, double band_units, std::vector<ReachCapsule>& out);

// Appends one capsule per segment of a chain's path `pts` [units] offset by r_mm: Clipper's
// offset lies within r of the path but for the rounding of its vertices to units, so the
// capsules have radius r plus two units and no band (an offset's straight walls are exact:
// a band would leave slivers along them).
void add_chain_reach(const Path& pts, double r_mm, std::vector<ReachCapsule>& out);

// Appends the capsule of a single vertical section `p` of the move from (ax, ay) to
// (bx, by) [mm]: the largest distance of its vertices from that segment, less `band_units`.
void add_section_reach(const Path& p, double ax_mm, double ay_mm, double bx_mm, double by_mm, double band_units,
                       std::vector<ReachCapsule>& out);

// A tilted section that a batch subtracted from a cell (SubtractWorkspace::level_anchors):
// its convex counter-clockwise polygon [units] as half-planes, each moved out by
// band · cos 30°, with bevels where a corner turns by more than 60 degrees, so that the grown
// region holds every point within band · cos 30° of the polygon and none farther than the
// band. The cell holds no material inside the polygon (its clip removed it, or it was
// noise), and material only goes, so a later section whose part near the cell's material
// lies in the grown region can remove material within the band of its own boundary at most,
// as a clip left out by material_out_of_reach() can. A live call's
// short tilted sweep starts where the last one ended: in a quarter of its (cell, level) clips
// the new section only grazes the previous one's walls (docs/performance.md, "Live clips
// inside the removed piece").
class PriorPiece {
 public:
  // From `poly` and the band [units]; false (and empty) unless `poly` is convex,
  // counter-clockwise and has at least 3 vertices. Allocates while its buffer grows.
  bool set(const Path& poly, double band_units);
  void clear() noexcept { planes_.clear(); }
  [[nodiscard]] bool empty() const noexcept { return planes_.empty(); }
  // True when rectangle `r` lies within the box of the grown polygon.
  [[nodiscard]] bool box_holds(const Rect& r) const noexcept {
    return !empty() && r.x0 >= box_.x0 && r.y0 >= box_.y0 && r.x1 <= box_.x1 && r.y1 <= box_.y1;
  }
  // True when q lies inside the grown polygon.
  [[nodiscard]] bool holds(const Point& q) const noexcept;

 private:
  struct Plane {
    double nx, ny, c;  // inside, grown: nx·x + ny·y <= c (unit normal)
  };
  void add_plane(double nx, double ny, const Point& on, double band_units);
  std::vector<Plane> planes_;
  Rect box_;  // of the polygon, grown by the band (rounded outwards)
};

// True when no material of `cell` (its polygons `touched`) lies within any capsule of the
// sections `selected` of `ls`: their clip can remove at most the band. False when a selected
// section has no capsules (tilted and lathe sections). Exact up to the
// rounding of doubles: every material edge against the capsules that an angular bound about
// the capsules' mean point cannot exclude, and one point of each connected chain of
// capsules against the material. No allocation once `rs` has grown.
[[nodiscard]] bool material_out_of_reach(const Cell& cell, std::span<const std::uint32_t> touched,
                                         const LevelSections& ls, std::span<const std::uint32_t> selected,
                                         ReachScratch& rs);

}  // namespace lbr::geom::detail
