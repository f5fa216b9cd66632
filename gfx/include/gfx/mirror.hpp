// gfx/mirror.hpp — the render side's copy of the solid and its meshes (docs/rendering.md §2).
// No OpenGL here. Lives on the render thread (or any single thread); allocates.
//
// Cells received from the exchange are held per region as *pending* until the region is
// chosen for a rebuild: then all of that region's pending cells are applied to the mirror
// solid at once and mesh::Reconstructor::update() rebuilds what they affect. A region is
// chosen only when it is visible (the caller's predicate, normally the view frustum against
// the region's bounding box) and only up to a per-step limit, oldest pending first, so the
// work per frame is bounded and off-screen changes cost nothing until they come into view.
//
// Consistency: the mirror solid is always a valid LBR (every cell is a cell the geometry
// thread produced; regions are brought forward whole), and the meshes are always exactly
// Reconstructor::build() of the mirror solid, so the displayed surface is closed across
// region borders even while some regions lag behind others.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "gfx/exchange.hpp"
#include "mesh/reconstruct.hpp"

namespace lbr::gfx {

struct StepStats {
  int regions_applied = 0;   // regions whose pending cells were applied this step
  int regions_rebuilt = 0;   // region meshes reassembled (applied regions and neighbours)
  int regions_pending = 0;   // regions still holding pending cells after the step
  int cells_applied = 0;
  double mesh_ms = 0;        // time in apply + Reconstructor::update [ms]
};

class MeshMirror {
 public:
  // Takes a copy of the solid as the geometry thread had it when the exchange started
  // (before its first publish), and builds every region's mesh (setup; allocates).
  MeshMirror(const geom::LbrSolid& initial, const mesh::MeshOptions& opt = {});

  // Copies the snapshot's cells into the pending sets (the newest version of a cell wins)
  // and marks the snapshot's cells consumed (cell_count = 0; storage kept for reuse).
  void receive(Snapshot& s);
  // Brings at most `max_regions` visible pending regions up to date (all when <= 0).
  StepStats step(const std::function<bool(int region)>& visible, int max_regions);

  [[nodiscard]] const geom::LbrSolid& solid() const noexcept { return solid_; }
  [[nodiscard]] const mesh::Reconstructor& meshes() const noexcept { return rec_; }
  [[nodiscard]] int regions() const noexcept { return solid_.regions(); }
  [[nodiscard]] bool pending(int region) const noexcept { return !pending_[static_cast<std::size_t>(region)].empty(); }
  [[nodiscard]] int pending_regions() const noexcept;
  // Bounding box of region r [mm]: its rectangle × the stock's height range. Conservative
  // for both the displayed and the pending state (material is only ever removed).
  [[nodiscard]] geom::Box3 region_box(int r) const noexcept;

 private:
  geom::LbrSolid solid_;
  mesh::Reconstructor rec_;
  std::vector<std::map<int, geom::Cell>> pending_;  // per region: level → newest cell
  std::vector<std::uint64_t> pending_since_;        // receive() count when it became pending
  std::uint64_t receives_ = 0;
};

}  // namespace lbr::gfx
