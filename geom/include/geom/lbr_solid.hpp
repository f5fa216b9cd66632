// geom/lbr_solid.hpp — the level-based representation (LBR) of the stock.
//
// Conventions (docs/lbr-conventions.md):
//  - Kernel units are 0.1 µm (geom/units.hpp); levels are horizontal (normal +Z) in the
//    workpiece frame.
//  - Level i stands for the slab [z0 + iΔ, min(z0 + (i+1)Δ, z_top)] and is sampled at the
//    slab's mid-plane. Volume = Σ area(i) · thickness(i); every slab but possibly the top one
//    has thickness Δ.
//  - The stock's XY bounds are split into nx × ny equal regions (row-major, region =
//    iy·nx + ix). A cell = (region, level) holds non-overlapping polygons with holes, all
//    inside the region's rectangle: outer contours counter-clockwise, holes clockwise.
//  - Every contour records the id of the move that last changed it (0 = untouched stock).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "geom/sweep.hpp"
#include "geom/turning.hpp"
#include "geom/types.hpp"

namespace lbr::geom {

struct Contour {
  Path pts;
  MoveId cut_by = 0;
};

struct Polygon {
  Contour outer;
  std::vector<Contour> holes;
  Rect bbox;  // of the outer contour
};

struct Cell {
  std::vector<Polygon> polys;
  Rect bbox;                 // of all polygons; empty when the cell holds no material
  double area_units2 = 0.0;  // cached signed sum over contours [units²]
  std::uint32_t version = 0; // incremented on every change
  MoveId last_cut = 0;       // latest move of the last change; kept when the cell becomes empty
                             // (colour by time of a floor whose level above was cut away)
};

// How a rectangle meets the material of a cell (cover_of()).
enum class RectCover : std::uint8_t {
  None,    // no material in the rectangle
  All,     // the rectangle lies inside the material
  Partly,  // some contour edge comes near the rectangle: only a clip tells
};

// Where rectangle r lies against the cell's material: when no contour edge's box meets r,
// r lies wholly inside or wholly outside the material and its centre decides which.
// Conservative (Partly where an edge's box meets r but the edge misses it). O(vertices of
// the polygons whose box meets r), no allocation.
[[nodiscard]] RectCover cover_of(const Cell& cell, const Rect& r) noexcept;

struct BoxStock {
  Vec3 min, max;  // [mm]
};
struct CylinderStock {
  double center_x_mm = 0, center_y_mm = 0, diameter_mm = 0, z_min_mm = 0, z_max_mm = 0;
};

struct SolidSpec {
  enum class Shape { Box, Cylinder } shape = Shape::Box;
  BoxStock box;
  CylinderStock cylinder;
  double level_spacing_mm = 0.1;  // Δ
  int regions_x = 4, regions_y = 4;
  double chord_tol_mm = 0.001;    // polygonisation of the cylinder's circle
  bool strictly_simple = false;   // ask Clipper for strictly simple output (no touching vertices)
  // Reuse the result of the level below when a cell starts from the same polygons and the
  // level's sections are the same (2.5D work: most levels of a step repeat the one below).
  // The result is identical either way; off only to measure or test it.
  bool vertical_coherence = true;
};

// One tool movement to remove: the shape must outlive the call. Either a milling tool
// (`shape`, swept between two poses at any orientation) or a turning insert (`turning`, set
// instead of `shape`): a rotating-part sweep whose insert reference point goes from
// (from.tip.x, from.tip.z) to (to.tip.x, to.tip.z) in the (r, z) plane; the removed region
// is the insert profile revolved about the workpiece Z axis (geom/turning.hpp).
struct SweepRef {
  const CutterShape* shape = nullptr;
  Pose from, to;
  MoveId id = 0;
  const TurningShape* turning = nullptr;
};

// Where a batch of `moves` should end so that the path in it does not come round on itself
// in a tight loop: the number of leading moves (at least one, at most moves.size()) before
// the XY path of consecutive milling moves of one tool has turned a full circle while
// staying within a square of side kTightLoopDiameters tool diameters. A tight helix (a bore,
// a ramp entry, thread milling) turns on one spot, and one difference fed with several of
// its turns carries every turn's outline over the same annulus: the Vatti sweep's cost grows
// with the square of those crossing edges, while batches of one turn each stay linear.
// Loops wider than that (a pocket's passes) are not cut. Real-time safe.
inline constexpr double kTightLoopDiameters = 2.0;
[[nodiscard]] std::size_t tight_loop_end(std::span<const SweepRef> moves) noexcept;

// Where a batch of `moves` should end so that the tilted milling moves in it (a tool axis
// other than +Z at either pose: the general sections, geom/sweep.hpp) do not run along more
// than kTiltedBatchDiameters tool diameters of XY path: the number of leading moves (at
// least one, at most moves.size()). A raster's neighbouring passes overlap, and a batch that
// holds many of them feeds each cell's difference all their sections at once (the Vatti
// sweep's cost grows with the square of the crossing edges), while material that an earlier
// batch removed lets a later one skip the sub-steps beside it. On LinuxCNC's boat-xyzac
// (1 853 segments) batches of 512 moves ran 1.42x the time of batches of 32; against 16
// diameters, 8 ran 0.96x (boat-xyzac) and 0.92x (boat-xyzbc) and 4 ran 1.08x on finish5x.
// A sampled stream's 512 samples run about 3 diameters, and smaller batches than that cost
// more than they save (64 samples: 1.27x). docs/performance.md. Real-time safe.
inline constexpr double kTiltedBatchDiameters = 8.0;
[[nodiscard]] std::size_t tilted_path_end(std::span<const SweepRef> moves) noexcept;

// Where a batch of `moves` should end: the first of tight_loop_end() and tilted_path_end().
// Real-time safe.
[[nodiscard]] std::size_t batch_end(std::span<const SweepRef> moves) noexcept;

struct SubtractStats {
  std::uint64_t sections = 0;       // section polygons computed
  std::uint64_t cells_tested = 0;   // (region, level) pairs that passed the box tests
  std::uint64_t cells_clipped = 0;  // polygon differences executed
  std::uint64_t cells_changed = 0;  // cells whose content changed
  std::uint64_t sections_trimmed = 0;  // sections trimmed or dropped inside the previous one
  std::uint64_t cells_reused = 0;      // cells that took the result of the level below
  std::uint64_t sections_in_air = 0;   // (cell, section) pairs left out: no material there
  std::uint64_t chain_offsets = 0;     // chain offsets built (ParallelSubtractor::run(): some for the next batch)
  std::uint64_t sections_joined = 0;   // move sections written as part of a joined outline
  std::uint64_t outlines_star = 0;     // joined outlines of tight loops written as their outer chain only
  std::uint64_t cells_out_of_reach = 0;  // clips left out: no material within the sections' reach
  std::uint64_t cells_in_anchor = 0;     // clips left out: the sections lie inside a piece already removed from the cell
  std::uint64_t clips_windowed = 0;      // clips fed the cell's contours reduced to the clip's window
  std::uint64_t window_fallbacks = 0;    // windowed clips done again with the whole contours
  std::uint64_t tilted_in_air = 0;       // tilted pieces not built: their section meets no material
  std::uint64_t tilted_beside = 0;       // tilted pieces not made: their hull lies beside the level's material box
  SubtractStats& operator+=(const SubtractStats& o) noexcept {
    sections += o.sections; cells_tested += o.cells_tested;
    cells_clipped += o.cells_clipped; cells_changed += o.cells_changed;
    sections_trimmed += o.sections_trimmed; cells_reused += o.cells_reused;
    sections_in_air += o.sections_in_air; chain_offsets += o.chain_offsets;
    sections_joined += o.sections_joined; outlines_star += o.outlines_star;
    cells_out_of_reach += o.cells_out_of_reach; cells_in_anchor += o.cells_in_anchor;
    clips_windowed += o.clips_windowed; window_fallbacks += o.window_fallbacks;
    tilted_in_air += o.tilted_in_air; tilted_beside += o.tilted_beside;
    return *this;
  }
};

namespace detail {
class SubtractEngine;      // the subtraction's steps (geom/src/subtract_engine.hpp)
struct SubtractWorkspace;  // its reusable buffers (geom/src/subtract_state.hpp)
}  // namespace detail

// Threads: an LbrSolid is not synchronised. One thread at a time calls its non-const members
// (the offline runner, or the live geometry thread); const queries may run together but not
// beside a change. To spread one subtraction over threads, hand the solid to a
// geom::ParallelSubtractor (geom/parallel_subtractor.hpp), which owns the kernel's threads.
class LbrSolid {
 public:
  // Setup: allocates all cells. Throws std::invalid_argument with a precise message when the
  // spec is unusable (non-positive sizes, out of the safe range, too many levels/regions).
  explicit LbrSolid(const SolidSpec& spec);
  // The same grid and initial_volume_mm3(), but every cell is left empty for the caller to
  // set (set_cell) — the levels file reader, which replaces every cell: building the stock's
  // levels first cost up to levels x regions copies of a 4096-gon it then threw away.
  struct CellsSetLater {};
  LbrSolid(const SolidSpec& spec, CellsSetLater);
  // Levels the spec's stock height and spacing give (NaN or out of range for a bad spec; the
  // constructor checks). Lets the levels file reader refuse a header whose level count
  // disagrees before the grid is allocated.
  [[nodiscard]] static double level_count(const SolidSpec& spec) noexcept;
  ~LbrSolid();
  LbrSolid(LbrSolid&&) noexcept;
  LbrSolid& operator=(LbrSolid&&) noexcept;
  LbrSolid(const LbrSolid&);
  LbrSolid& operator=(const LbrSolid&);
  // Makes this solid equal to `o`, copying only the cells whose version differs from this
  // one's, into the storage this one has (a live snapshot's slot: the cells the run changed
  // since the slot's last copy, no allocation once the slot has grown). For a solid last
  // made equal to `o` by this or a copy and not changed since; where the grids differ, a
  // full copy.
  void update_copy_of(const LbrSolid& o);
  // update_copy_of() a slice at a time, for a caller that must not stall for the whole
  // copy (the live geometry thread): compares the cells from `from` on (in storage order)
  // and copies those whose version differs, until it has copied `max_cells` of them or
  // compared all; returns the first cell it did not compare, cell_count() once done (and
  // then the solid-wide state is copied too). Requires same_grid(o). The slices of one pass
  // make this solid equal to `o` only when `o` did not change between them.
  [[nodiscard]] std::size_t update_copy_slice(const LbrSolid& o, std::size_t from, std::size_t max_cells);
  // The same levels and region borders: update_copy_slice() may be used.
  [[nodiscard]] bool same_grid(const LbrSolid& o) const noexcept;
  [[nodiscard]] std::size_t cell_count() const noexcept { return cells_.size(); }
  // Changes whenever material may have been put back (construction, copy, update_copy_*,
  // set_cell), never by a subtraction: what a subtraction removed under one epoch stays
  // removed while it lasts (the kernel keeps such regions as covers, level_sections.cpp).
  [[nodiscard]] std::uint64_t removal_epoch() const noexcept { return epoch_; }

  // Removes the union of the sweeps from the stock: per (region, level) touched, one
  // polygon difference. Cells are skipped by bounding boxes first. Changed cells are marked
  // dirty. The calling thread does all the work. Allocates (Clipper; the solid's reusable
  // buffers while they grow to the largest batch seen), bounded by the cells the batch
  // touches; does not throw. Not real-time safe in the strict sense (it allocates); the live
  // geometry thread bounds its batches instead (app/src/live/geometry.hpp).
  SubtractStats subtract(std::span<const SweepRef> batch);

  // 3D boolean difference with another LBR solid (the paper's OpBool): every level of this
  // solid loses the polygons of the other solid's level that contains the same mid-plane
  // height. Changed cells become dirty; cut contours get `id`. Allocates.
  SubtractStats subtract_solid(const LbrSolid& other, MoveId id = 0);

  // --- geometry of the grid; contents (real-time safe: no allocation, no locks) ---
  [[nodiscard]] const SolidSpec& spec() const noexcept { return spec_; }
  [[nodiscard]] int levels() const noexcept { return levels_; }
  [[nodiscard]] int regions_x() const noexcept { return spec_.regions_x; }
  [[nodiscard]] int regions_y() const noexcept { return spec_.regions_y; }
  [[nodiscard]] int regions() const noexcept { return spec_.regions_x * spec_.regions_y; }
  [[nodiscard]] double level_spacing_mm() const noexcept { return spec_.level_spacing_mm; }
  [[nodiscard]] double z_bottom_mm() const noexcept { return z0_; }
  [[nodiscard]] double z_top_mm() const noexcept { return z1_; }
  [[nodiscard]] double level_z_mm(int level) const noexcept;          // mid-plane
  [[nodiscard]] double level_thickness_mm(int level) const noexcept;
  [[nodiscard]] double level_bottom_mm(int level) const noexcept;
  // Level whose slab contains z (clamped to [0, levels()-1]).
  [[nodiscard]] int level_at(double z_mm) const noexcept;
  [[nodiscard]] Rect region_rect(int region) const noexcept;
  [[nodiscard]] Rect stock_rect() const noexcept { return xy_; }

  [[nodiscard]] const Cell& cell(int region, int level) const noexcept {
    return cells_[static_cast<std::size_t>(region) * levels_ + level];
  }
  [[nodiscard]] double volume_mm3() const noexcept;
  [[nodiscard]] double initial_volume_mm3() const noexcept { return initial_volume_mm3_; }
  [[nodiscard]] double level_area_mm2(int level) const noexcept;
  // Bounds of the remaining material [mm] (z from the slabs that hold material).
  [[nodiscard]] Box3 bounds() const noexcept;
  [[nodiscard]] std::size_t polygon_count() const noexcept;
  [[nodiscard]] std::size_t contour_count() const noexcept;
  [[nodiscard]] std::size_t vertex_count() const noexcept;

  // --- dirty set: cells changed since the last clear_dirty() ---
  [[nodiscard]] bool is_dirty(int region, int level) const noexcept {
    return dirty_flag_[static_cast<std::size_t>(region) * levels_ + level] != 0;
  }
  // Cell indices (region * levels() + level), ascending. Allocates; not for the RT path.
  [[nodiscard]] std::vector<std::uint32_t> dirty_cells() const;
  [[nodiscard]] std::size_t dirty_count() const noexcept;
  void clear_dirty() noexcept;

  // Empty string when every cell satisfies the representation invariants (contours inside
  // their region, outers CCW and holes CW, contours simple, polygons non-overlapping);
  // otherwise a description of the first violation. Slow; for tests and diagnostics.
  [[nodiscard]] std::string check_invariants() const;

  // Replaces the content of one cell (used by deserialisation, the render-side mirror and
  // tests). Marks it dirty. Allocates.
  void set_cell(int region, int level, std::vector<Polygon> polys, MoveId last_cut = 0);

 private:
  friend class detail::SubtractEngine;  // reads the grid, writes cells (and marks them changed())
  LbrSolid(const SolidSpec& spec, bool fill);
  // After a change of cell `i`: its version goes up (in the cell and in versions_) and it is dirty.
  void changed(std::size_t i) noexcept {
    versions_[i] = ++cells_[i].version;
    dirty_flag_[i] = 1;
  }
  void init_cells(bool fill);  // grid, initial volume; fill: every cell holds the stock
  [[nodiscard]] Path stock_circle() const;  // the cylinder polygonised (empty for a box)
  [[nodiscard]] std::vector<Polygon> stock_polygons(int region, const Path& circle, Path& cut, Path& tmp,
                                                   Path& wedge) const;
  enum class CircleCover { Inside, Outside, Crossed };  // a region against the cylinder's outline
  [[nodiscard]] CircleCover circle_vs_rect(const Rect& region, std::size_t segs) const noexcept;
  [[nodiscard]] const Path& circle_near(const Rect& region, const Path& circle, Path& wedge) const;

  SolidSpec spec_;
  int levels_ = 0;
  double z0_ = 0, z1_ = 0;
  Rect xy_;
  std::vector<Coord> xs_, ys_;  // region boundaries, nx+1 and ny+1 values
  std::vector<Cell> cells_;
  std::vector<std::uint8_t> dirty_flag_;
  // Each cell's version, side by side: update_copy_slice() finds the changed cells by
  // reading 4 bytes per cell, not a cache line of each Cell.
  std::vector<std::uint32_t> versions_;
  double initial_volume_mm3_ = 0;
  std::uint64_t epoch_ = next_epoch();  // removal_epoch()
  [[nodiscard]] static std::uint64_t next_epoch() noexcept;
  std::unique_ptr<detail::SubtractWorkspace> ws_;  // for subtract() and subtract_solid()
};

// Fills `out` with the polygons of `cell` as a flat list of contours (outer then holes).
void flatten(const Cell& cell, Paths& out);
// Signed area [units²] of a path (positive for counter-clockwise).
[[nodiscard]] double signed_area(const Path& p) noexcept;

}  // namespace lbr::geom
