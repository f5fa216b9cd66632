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

#include <atomic>
#include <cstdint>
#include <functional>
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

struct SubtractStats {
  std::uint64_t sections = 0;       // section polygons computed
  std::uint64_t cells_tested = 0;   // (region, level) pairs that passed the box tests
  std::uint64_t cells_clipped = 0;  // polygon differences executed
  std::uint64_t cells_changed = 0;  // cells whose content changed
  std::uint64_t sections_trimmed = 0;  // sections trimmed or dropped inside the previous one
  std::uint64_t cells_reused = 0;      // cells that took the result of the level below
  std::uint64_t sections_in_air = 0;   // (cell, section) pairs left out: no material there
  std::uint64_t chain_offsets = 0;     // chain offsets built (LevelPool: some for the next batch)
  std::uint64_t sections_joined = 0;   // move sections written as part of a joined outline
  SubtractStats& operator+=(const SubtractStats& o) noexcept {
    sections += o.sections; cells_tested += o.cells_tested;
    cells_clipped += o.cells_clipped; cells_changed += o.cells_changed;
    sections_trimmed += o.sections_trimmed; cells_reused += o.cells_reused;
    sections_in_air += o.sections_in_air; chain_offsets += o.chain_offsets;
    sections_joined += o.sections_joined;
    return *this;
  }
};

// The sections of one level for one batch, built by one thread and read by all.
struct LevelSections {
  Paths paths;                        // convex sections, lathe regions; empty for a chain
  std::vector<Rect> box;              // bounding boxes
  std::vector<MoveId> id;             // move ids
  std::vector<std::uint32_t> chain;   // offset index (SubtractShared) of a chain's entry, else ~0
  std::vector<std::uint32_t> chain_offset;  // per chain: its offset on this level, or ~0
  Rect all;                           // union of the boxes
  int ix0 = 0, ix1 = -1, iy0 = 0, iy1 = -1;  // regions that the boxes reach
  std::vector<std::uint8_t> same_cell_below;  // per region: same start as the level below
  std::vector<std::uint32_t> cost;            // per region: the cell's vertices before the batch
  [[nodiscard]] bool empty() const noexcept { return ix1 < ix0 || iy1 < iy0; }
};

// State that the threads of one subtract_shared() call share. prepare_shared() fills the
// batch part on one thread; in subtract_shared() each part is written in one phase and read
// in the next (the caller's barrier orders them), except the offsets' region pieces, which
// the first clip that needs one cuts (a per-piece state orders it).
struct SubtractShared {
  // --- the batch, prepared once (read only while the threads run) ---
  std::vector<SweepRef> merged;   // the batch after merging collinear runs
  std::vector<Sweep> sweeps;      // one per merged milling move
  std::vector<MoveId> sweep_id;   // their move ids
  // Runs of consecutive sweeps [first, last) of one tool with a vertical axis along a
  // continuous path: on each level their sections are joined into outlines where they can.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;
  std::vector<LatheSweep> lathe;  // one per merged turning move
  std::vector<MoveId> lathe_id;
  // Runs of at least three consecutive horizontal moves of one tool with a vertical axis at
  // one height: their section on a level is the polyline offset by the tool radius there,
  // computed once per distinct radius instead of one stadium per move.
  struct Chain {
    const CutterShape* shape = nullptr;
    double z = 0.0;            // tip height [mm]
    Path pts;                  // tip positions [units]
    MoveId id = 0;             // largest move id of the run
  };
  std::vector<Chain> chains;
  std::size_t chain_count = 0;  // chains in use (the vector keeps its buffers)
  struct OffsetKey {
    std::uint32_t chain;
    double r;
  };
  std::vector<OffsetKey> offset_keys;      // the batch's distinct (chain, radius), in order
  std::vector<std::uint32_t> offset_of;    // per (level - lb, chain): index into offset_keys, or ~0
  int lb = 0, le = 0;                      // the levels the batch reaches: [lb, le)
  bool offsets_ready = false;              // the offsets' paths are built (during the batch before)

  // --- built by the threads ---
  std::vector<LevelSections> levels;    // per level the batch reaches, reused between batches
  std::vector<std::uint8_t> outcome;    // per (level - lb, region): the clip changed the cell
  // A chain offset by one radius (one per distinct (chain, radius) of the batch), and its
  // pieces cut to the regions its box reaches (rectangles grown by 1 mm), so that a clip
  // carries only the nearby edges. A piece is cut when a clip first needs it.
  struct Offset {
    Paths paths;
    Rect box;
    int ix0 = 0, ix1 = -1, iy0 = 0, iy1 = -1;
    std::vector<Paths> cut;            // (iy - iy0) * (ix1 - ix0 + 1) + (ix - ix0)
    std::vector<std::uint8_t> state;   // per piece: 0 not cut, 1 being cut, 2 cut (atomic_ref)
  };
  std::vector<Offset> offsets;
  std::atomic<std::size_t> next[3] = {};  // work counters: phase A, phase C, next batch's offsets
  std::atomic<std::uint8_t> ahead_ready{0};  // the next batch is prepared (SubtractAhead)
};

// The batch after the current one, prepared during the current one's clips by one thread
// (`prepare`: prepare_shared() into `shared`, and whatever the caller keeps with it); its
// chain offsets, which depend on the batch only, are then built by the threads between
// their clips. The caller sets shared->offsets_ready once the call has returned.
struct SubtractAhead {
  SubtractShared* shared = nullptr;
  std::function<void()> prepare;
};

// Reusable buffers for subtract(); one per thread that calls it. Grows to the largest batch
// seen and is then reused without further allocation of its own.
struct SubtractWorkspace {
  ClipperLib::Clipper clipper;
  ClipperLib::Clipper rect_clipper;  // cuts chain offsets to regions
  ClipperLib::PolyTree tree;
  SectionScratch scratch;
  std::vector<MoveCaps> caps;                 // one per move of a joined run
  std::vector<SectionScratch::P2> outline;    // a joined run's vertices before rounding
  Path cut, cut_tmp;                          // a long section cut to a region
  Path prev_tilted, tilted_next;              // the last tilted section of a level, untrimmed
  bool prev_tilted_valid = false;
  std::uint32_t prev_tilted_sweep = 0;
  std::vector<std::uint8_t> trim_flags;
  std::vector<int> source;          // per (level - lb, region): the level whose result it takes
  std::vector<std::uint32_t> jobs;         // (level - lb) * regions + region of the cells to clip
  std::vector<std::pair<std::size_t, std::uint32_t>> job_cost;  // (estimate, job) for ordering
  SubtractShared own;               // for subtract() on one thread
  std::vector<std::uint32_t> selected, touched;
  std::vector<Polygon> fresh, kept;
};

class LbrSolid {
 public:
  // Setup: allocates all cells. Throws std::invalid_argument with a precise message when the
  // spec is unusable (non-positive sizes, out of the safe range, too many levels/regions).
  explicit LbrSolid(const SolidSpec& spec);
  ~LbrSolid();
  LbrSolid(LbrSolid&&) noexcept;
  LbrSolid& operator=(LbrSolid&&) noexcept;
  LbrSolid(const LbrSolid&);
  LbrSolid& operator=(const LbrSolid&);

  // Removes the union of the sweeps from the stock: per (region, level) touched, one
  // polygon difference. Cells are skipped by bounding boxes first. Changed cells are marked
  // dirty. Does not throw; allocates (Clipper does).
  SubtractStats subtract(std::span<const SweepRef> batch);
  SubtractStats subtract(std::span<const SweepRef> batch, SubtractWorkspace& ws);
  // The same subtraction run by `count` threads together. One thread first calls
  // prepare_shared() (merging, sweeps, chains, shared storage); then each of the `count`
  // threads calls subtract_shared() with its own workspace, its index in [0, count) and the
  // same `shared`; `sync` is a barrier over the `count` callers (called twice, or never when
  // the batch reaches no level). Each returns its share of the statistics. Phases: the chain
  // offsets and the levels' sections are built, and each cell compared with the one below;
  // then the cells that start a run of equal levels are clipped (longest first; offsets are
  // cut to a region when a clip first needs it), and the rest of each run copies its result
  // (vertical coherence). Work inside a phase is taken from shared counters. The result
  // does not depend on `count`.
  //
  // `ahead`, when given, is the next batch (SubtractAhead): it is prepared and its chain
  // offsets built among this batch's clips, where a thread would otherwise wait for the
  // longest offset at the start of the next batch, and the caller for the preparation.
  void prepare_shared(std::span<const SweepRef> batch, SubtractShared& shared) const;
  SubtractStats subtract_shared(SubtractShared& shared, SubtractWorkspace& ws, int index, int count,
                                const std::function<void()>& sync, const SubtractAhead* ahead = nullptr);

  // 3D boolean difference with another LBR solid (the paper's OpBool): every level of this
  // solid loses the polygons of the other solid's level that contains the same mid-plane
  // height. Changed cells become dirty; cut contours get `id`. Allocates.
  SubtractStats subtract_solid(const LbrSolid& other, MoveId id = 0);

  // --- geometry of the grid ---
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

  // --- contents ---
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
  // tests). Marks it dirty.
  void set_cell(int region, int level, std::vector<Polygon> polys, MoveId last_cut = 0);

 private:
  void init_cells();
  // Phases of subtract_shared().
  void build_level(int level, const SubtractShared& sh, SubtractWorkspace& ws, LevelSections& out,
                   SubtractStats& stats) const;
  void trim_tilted(std::uint32_t si, std::size_t before, const SubtractShared& sh, SubtractWorkspace& ws,
                   LevelSections& ls, SubtractStats& stats) const;
  void build_run_sections(double zc, std::pair<std::uint32_t, std::uint32_t> run, const SubtractShared& sh,
                          SubtractWorkspace& ws, LevelSections& ls, SubtractStats& stats) const;
  const Paths& offset_piece(SubtractShared& sh, std::uint32_t o, int region, SubtractWorkspace& ws) const;
  // The region's rectangle grown by 1 mm: what a clip of its cells needs of a long section.
  [[nodiscard]] Rect grown_region_rect(int region) const noexcept;
  void add_clip_paths(int region, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws) const;
  bool clip_cell(int region, int level, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                 SubtractStats& stats);

  SolidSpec spec_;
  int levels_ = 0;
  double z0_ = 0, z1_ = 0;
  Rect xy_;
  std::vector<Coord> xs_, ys_;  // region boundaries, nx+1 and ny+1 values
  std::vector<Cell> cells_;
  std::vector<std::uint8_t> dirty_flag_;
  double initial_volume_mm3_ = 0;
  std::unique_ptr<SubtractWorkspace> ws_;
};

// Merges runs of consecutive moves of one tool with a fixed axis into single moves when no
// intermediate point lies farther than half the chord tolerance from the merged chord (so the
// swept region moves by at most that much). The merged move keeps the largest move id.
// Sampled straight lines collapse to one move each. Allocates only when `out` grows.
void merge_collinear(std::span<const SweepRef> batch, std::vector<SweepRef>& out);

// Fills `out` with the polygons of `cell` as a flat list of contours (outer then holes).
void flatten(const Cell& cell, Paths& out);
// Signed area [units²] of a path (positive for counter-clockwise).
[[nodiscard]] double signed_area(const Path& p) noexcept;

}  // namespace lbr::geom
