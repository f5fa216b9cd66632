// Private: the state of one subtraction — the prepared batch, what its threads share, and
// each thread's reusable buffers. Only geom/ sees these; callers use LbrSolid::subtract()
// or geom::ParallelSubtractor (docs/architecture.md, "Kernel").
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "clip_reach.hpp"
#include "material_mask.hpp"
#include "monotone_union.hpp"
#include "window_clip.hpp"
#include "geom/lbr_solid.hpp"

namespace lbr::geom::detail {

inline constexpr std::uint32_t kNoChain = 0xFFFFFFFFu;
inline constexpr std::uint32_t kNoReach = 0xFFFFFFFFu;  // a section without capsules (LevelSections::reach_begin)

// One step of a thread's wait for another's (a few microseconds at most).
inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// The last tilted sections that batches subtracted on one level (PriorPiece), a ring by
// generation: entry g sits in piece[g % kSize] while gen[g % kSize] == g. A cell's
// SubtractWorkspace::cell_anchor names the latest one its clips have taken.
struct LevelAnchors {
  static constexpr std::size_t kSize = 4;
  std::array<PriorPiece, kSize> piece;
  std::array<std::uint64_t, kSize> gen{};
  std::uint64_t last = 0;  // the latest generation given out on the level
  [[nodiscard]] const PriorPiece* find(std::uint64_t g) const noexcept {
    return g != 0 && gen[g % kSize] == g ? &piece[g % kSize] : nullptr;
  }
};

// What a clip of one cell did (SubtractShared::outcome).
enum CellOutcome : std::uint8_t {
  kCellKept = 0,      // nothing changed
  kCellChanged = 1,   // the cell changed
  kCellInAnchor = 2,  // left out: the sections lie inside a piece the cell has had removed
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
  // Per section: its capsules [reach_begin, reach_end) in `reach` (clip_reach.hpp), or
  // reach_begin = kNoReach (chain offsets, tilted and lathe sections).
  std::vector<ReachCapsule> reach;
  std::vector<std::uint32_t> reach_begin, reach_end;
  const LevelAnchors* anchors = nullptr;  // the solid's removed pieces on this level
  std::uint64_t anchor = 0;  // the generation of this batch's removed piece there, or 0 (none)
  [[nodiscard]] bool empty() const noexcept { return ix1 < ix0 || iy1 < iy0; }
};

// State that the threads of one SubtractEngine::run() share. SubtractEngine::prepare()
// fills the batch part on one thread; in run() each part is written in one phase and read
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
  RegionRange tilted_regions;              // the regions its tilted sweeps' boxes reach (LevelMaterial)
  // The regions' inner borders (the solid's xs_/ys_ without the first and last): sections
  // and offsets get a vertex where they cross one (split_at_lines()).
  std::span<const Coord> border_x, border_y;

  // --- built by the threads ---
  std::vector<LevelSections> levels;    // per level the batch reaches, reused between batches
  std::vector<std::uint8_t> outcome;    // per (level - lb, region): CellOutcome
  // A chain offset by one radius (one per distinct (chain, radius) of the batch), and its
  // pieces cut to the regions its box reaches (rectangles grown by 1 mm), so that a clip
  // carries only the nearby edges. A piece is cut when a clip first needs it.
  struct Offset {
    Paths paths;
    Rect box;
    int ix0 = 0, ix1 = -1, iy0 = 0, iy1 = -1;
    std::vector<Paths> cut;            // (iy - iy0) * (ix1 - ix0 + 1) + (ix - ix0)
    std::vector<std::uint8_t> state;   // per piece: 0 not cut, 1 being cut, 2 cut (atomic_ref)
    std::uint8_t built = 0;            // `paths`: 0 not built, 1 being built, 2 built (atomic_ref)
  };
  std::vector<Offset> offsets;
  std::atomic<std::size_t> next[3] = {};  // work counters: phase A, phase C, next batch's offsets
  std::atomic<std::uint8_t> ahead_ready{0};  // the next batch is prepared (SubtractAhead)
};

// Runs `build` once for a flag shared by threads (0 not built, 1 being built, 2 built): the
// first caller runs it, a caller meanwhile waits until it is done (a build takes
// microseconds).
template <class Build>
void build_once(std::uint8_t& flag, Build&& build) {
  std::atomic_ref<std::uint8_t> state(flag);
  std::uint8_t s = state.load(std::memory_order_acquire);
  if (s == 0 && state.compare_exchange_strong(s, 1, std::memory_order_acq_rel)) {
    build();
    state.store(2, std::memory_order_release);
    return;
  }
  while (state.load(std::memory_order_acquire) != 2) cpu_relax();
}

// The batch after the current one, prepared during the current one's clips by one thread
// (`prepare`: SubtractEngine::prepare() into `shared`, and whatever the caller keeps with
// it); its chain offsets, which depend on the batch only, are then built by the threads
// between their clips (an offset no clip of the current batch needed waits for its first use
// in the next one, or is never built).
struct SubtractAhead {
  SubtractShared* shared = nullptr;
  std::function<void()> prepare;
};

// Reusable buffers for the subtraction; one per thread that runs it. Grows to the largest
// batch seen and is then reused without further allocation of its own.
struct SubtractWorkspace {
  ClipperLib::Clipper clipper;
  ClipperLib::Clipper rect_clipper;  // cuts chain offsets to regions
  ClipperLib::PolyTree tree;
  SectionScratch scratch;
  std::vector<MoveCaps> caps;                 // one per move of a joined run
  std::vector<SectionScratch::P2> outline;    // a joined run's vertices before rounding
  Path cut, cut_tmp;                          // a long section cut to a region
  std::vector<TiltedPiece> pieces;            // a run's tilted sub-steps on one level, pending
  ConvexCover piece_cover[2];                 // pieces[i]'s polygon in [i % 2], for pieces[i + 1]
  // Per level, the last tilted piece built there for the solid, while its removal_epoch() is
  // level_last_epoch: its coarse polygon lies in material already removed (or removed in the
  // same difference), so it covers the next piece there (build_tilted()). Only the solid's
  // own workspace (LbrSolid::ws_) holds them, whichever thread builds the level.
  std::vector<TiltedPiece> level_last;
  std::vector<std::uint8_t> level_last_set;
  // Per level, the last tilted sections that batches removed (LevelAnchors); per cell
  // (region * levels + level), the generation of the latest one that the cell's clips took
  // (removed, or left out where it could remove the band at most), or 0. Forgotten with the
  // removal epoch as level_last is; a cell's entry is written by the thread that clips it.
  std::vector<LevelAnchors> level_anchors;
  std::vector<std::uint64_t> cell_anchor;
  std::uint64_t level_last_epoch = 0;
  // Per cell (region * levels + level), its material as a raster, built when a tilted piece
  // first reaches the cell and rebuilt when it no longer clears one (LevelMaterial); sized on
  // the first batch with a tilted sweep and forgotten with the removal epoch. Only the solid's own workspace
  // holds them; a cell is read and built by the one thread that builds its level.
  std::vector<CellMask> masks;
  std::uint64_t masks_epoch = 0;
  std::vector<std::pair<int, double>> mask_crossings;  // CellMask::build()'s buffer
  MonotoneUnion joined;                       // joins consecutive tilted sections (join_tilted())
  Paths join_in;                              // the sections being joined
  std::vector<std::uint8_t> trim_flags;
  std::vector<int> source;          // per (level - lb, region): the level whose result it takes
  std::vector<std::uint32_t> jobs;         // (level - lb) * regions + region of the cells to clip
  std::vector<std::pair<std::size_t, std::uint32_t>> job_cost;  // (estimate, job) for ordering
  SubtractShared own;               // for a subtraction on one thread
  std::vector<std::uint32_t> selected, touched;
  std::vector<Polygon> fresh, kept;
  ReachScratch reach;               // material_out_of_reach()
  WindowScratch window;             // windowed clips (window_clip.hpp)
  Rect keep;                        // a clip's paths are cut to this box (the material they may meet)
};

}  // namespace lbr::geom::detail
