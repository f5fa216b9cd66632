// Private: the steps of one subtraction of a batch of sweeps from an LbrSolid, for one
// thread or for several that share the work (geom::ParallelSubtractor). LbrSolid's public
// calls and the worker pool are its only users; it reads and writes the solid's cells
// directly (a friend of LbrSolid), so it lives as long as one call.
//
// Sources, by concern:
//   batch_plan.cpp      prepare(): merging, sweeps, chains, the levels and offsets a batch reaches
//   level_sections.cpp  a level's sections (joined runs, trimmed tilted sections, chains,
//                       lathe regions) and the chain offsets and their region pieces
//   subtract_phases.cpp run(): the phases A-D over the threads
//   cell_clip.cpp       one cell's clip by its level's sections (phase C)
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "subtract_state.hpp"

namespace lbr::geom::detail {

class SubtractEngine {
 public:
  explicit SubtractEngine(LbrSolid& solid) noexcept : s_(solid) {}

  // One thread, before the threads run: merging, sweeps, chains and the shared storage for
  // the batch. Reads the solid's grid only. Allocates while the buffers grow.
  void prepare(std::span<const SweepRef> batch, SubtractShared& sh) const;

  // Called by `count` threads together, each with its own workspace, its index in
  // [0, count) and the same prepared `sh`; `sync` is a barrier over the `count` callers
  // (called twice, or never when the batch reaches no level). Each returns its share of the
  // statistics. Phases: (A) the levels' sections are built, and each cell compared with the
  // one below; (B) each thread derives which cells start a run of equal levels; (C) those
  // are clipped (longest first; a chain offset is built, and cut to a region, when a clip
  // first needs it); (D) the rest of each run copies its result (vertical coherence).
  // Work inside a phase is taken from shared counters. The result does not depend on
  // `count`. `ahead`, when given, is the next batch (SubtractAhead): it is prepared and its
  // chain offsets built among this batch's clips. Allocates (Clipper); does not throw.
  SubtractStats run(SubtractShared& sh, SubtractWorkspace& ws, int index, int count, const std::function<void()>& sync,
                    const SubtractAhead* ahead);

  // prepare() and run() on the calling thread alone, with ws.own as the shared state.
  SubtractStats subtract(std::span<const SweepRef> batch, SubtractWorkspace& ws);

 private:
  // --- batch_plan.cpp ---
  void plan_offsets(SubtractShared& sh) const;  // per level, the distinct (chain, radius) pairs
  void size_storage(SubtractShared& sh) const;  // per-level storage, each offset's box and pieces

  // --- level_sections.cpp ---
  void build_level(int level, const SubtractShared& sh, SubtractWorkspace& ws, LevelSections& ls,
                   SubtractStats& stats) const;
  void build_run_sections(double zc, std::pair<std::uint32_t, std::uint32_t> run, const PlaneMaterial& material,
                          const SubtractShared& sh, SubtractWorkspace& ws, LevelSections& ls, SubtractStats& stats) const;
  void build_tilted(const SubtractShared& sh, const PlaneMaterial& material, SubtractWorkspace& ws, LevelSections& ls,
                    SubtractStats& stats) const;
  // The solid's last tilted piece per level (the solid's own workspace's level_last):
  // sized and reset on the preparing thread (reset_level_last(), from prepare()), then read
  // and written per level by the one thread that builds that level.
  void reset_level_last() const;
  // The solid's cell masks (SubtractWorkspace::masks), sized when `tilted` (the batch has a
  // tilted sweep) and forgotten when material was put back; on the preparing thread.
  void reset_cell_masks(bool tilted) const;
  [[nodiscard]] RegionRange tilted_regions(const SubtractShared& sh) const noexcept;
  [[nodiscard]] const TiltedPiece* level_prior(std::size_t level) const;
  void keep_anchor(std::size_t level, const Path& poly, double chord_tol_mm, LevelSections& ls) const;
  static void join_tilted(std::size_t begin, MoveId id, SubtractWorkspace& ws, LevelSections& ls, SubtractStats& stats);
  static void add_chain_sections(int level, const SubtractShared& sh, LevelSections& ls);
  void add_lathe_sections(double zc, const SubtractShared& sh, LevelSections& ls) const;
  const Paths& offset_piece(SubtractShared& sh, std::uint32_t o, int region, SubtractWorkspace& ws,
                            SubtractStats& stats) const;

  // --- subtract_phases.cpp ---
  void build_levels(SubtractShared& sh, SubtractWorkspace& ws, SubtractStats& stats) const;  // A
  void compare_cells(int level, bool below, LevelSections& ls) const;                                     // A
  void plan_clips(const SubtractShared& sh, SubtractWorkspace& ws) const;                                 // B
  void order_clips(const SubtractShared& sh, SubtractWorkspace& ws) const;                                // B
  void clip_phase(SubtractShared& sh, SubtractWorkspace& ws, const SubtractAhead* ahead, SubtractStats& stats);  // C
  void copy_runs(const SubtractShared& sh, const SubtractWorkspace& ws, int index, int count,
                 SubtractStats& stats);                                                                    // D

  // --- cell_clip.cpp ---
  Rect add_clip_paths(int region, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                      SubtractStats& stats) const;
  void run_difference(const Cell& cell, int region, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                      SubtractStats& stats) const;
  CellOutcome difference_cell(std::size_t ci, int region, const LevelSections& ls, SubtractShared& sh,
                              SubtractWorkspace& ws, SubtractStats& stats);
  CellOutcome clip_cell(int region, int level, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                        SubtractStats& stats);

  // The region's rectangle grown by 1 mm: what a clip of its cells needs of a long section.
  [[nodiscard]] Rect grown_region_rect(int region) const noexcept;

  LbrSolid& s_;
};

// Merges runs of consecutive moves of one tool with a fixed axis into single moves when no
// intermediate point lies farther than half the chord tolerance from the merged chord (so the
// swept region moves by at most that much). The merged move keeps the largest move id.
// Sampled straight lines collapse to one move each. Runs whose tool axis turns merge while
// every pose inside stays within that of the merged move, rotation times the tool's reach
// included (geom::pose_deviation_mm); the reach counts only the part of the tool that comes
// below `z_top_mm` (the solid's top: nothing above it can be cut). Allocates only when
// `out` grows.
void merge_collinear(std::span<const SweepRef> batch, std::vector<SweepRef>& out, double z_top_mm = INFINITY);

// Builds offset `o` of the prepared batch (sh.offsets[o].paths) unless it is built; waits
// while another thread builds it. Allocates (Clipper).
void build_offset(SubtractShared& sh, std::size_t o, SubtractStats& stats);

// Index of the interval [b[i], b[i+1]] holding v, clamped to [0, b.size()-2].
[[nodiscard]] int interval_of(const std::vector<Coord>& b, Coord v) noexcept;

}  // namespace lbr::geom::detail
