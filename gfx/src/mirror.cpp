#include "gfx/mirror.hpp"

#include <algorithm>
#include <chrono>

namespace lbr::gfx {

MeshMirror::MeshMirror(const geom::LbrSolid& initial, const mesh::MeshOptions& opt)
    : solid_(initial), rec_(opt), pending_(static_cast<std::size_t>(initial.regions())),
      pending_since_(static_cast<std::size_t>(initial.regions()), 0) {
  rec_.build(solid_);
  solid_.clear_dirty();
}

void MeshMirror::receive(Snapshot& s) {
  ++receives_;
  // Copy (not move) the cells: the snapshot's storage goes back to the writer with its
  // capacity, and the memory freed later here was allocated on this thread.
  const std::size_t n = std::min(s.cell_count, s.cells.size());
  for (std::size_t i = 0; i < n; ++i) {
    const CellUpdate& u = s.cells[i];
    if (u.region < 0 || u.region >= solid_.regions() || u.level < 0 || u.level >= solid_.levels()) continue;
    auto& p = pending_[static_cast<std::size_t>(u.region)];
    if (p.empty()) pending_since_[static_cast<std::size_t>(u.region)] = receives_;
    p[u.level] = u.cell;
  }
  s.cell_count = 0;
}

int MeshMirror::pending_regions() const noexcept {
  int n = 0;
  for (const auto& p : pending_) n += p.empty() ? 0 : 1;
  return n;
}

geom::Box3 MeshMirror::region_box(int r) const noexcept {
  const geom::Rect rr = solid_.region_rect(r);
  geom::Box3 b;
  b.add({geom::to_mm(rr.x0), geom::to_mm(rr.y0), solid_.z_bottom_mm()});
  b.add({geom::to_mm(rr.x1), geom::to_mm(rr.y1), solid_.z_top_mm()});
  return b;
}

StepStats MeshMirror::step(const std::function<bool(int)>& visible, int max_regions) {
  const auto t0 = std::chrono::steady_clock::now();
  StepStats st;
  std::vector<int> chosen;
  for (int r = 0; r < solid_.regions(); ++r)
    if (pending(r) && (!visible || visible(r))) chosen.push_back(r);
  std::stable_sort(chosen.begin(), chosen.end(), [&](int a, int b) {
    return pending_since_[static_cast<std::size_t>(a)] < pending_since_[static_cast<std::size_t>(b)];
  });
  if (max_regions > 0 && static_cast<int>(chosen.size()) > max_regions) chosen.resize(static_cast<std::size_t>(max_regions));
  for (int r : chosen) {
    auto& p = pending_[static_cast<std::size_t>(r)];
    for (auto& [level, cell] : p) {
      solid_.set_cell(r, level, std::move(cell.polys), cell.last_cut);
      ++st.cells_applied;
    }
    p.clear();
  }
  st.regions_applied = static_cast<int>(chosen.size());
  if (!chosen.empty()) {
    const mesh::BuildStats b = rec_.update(solid_);
    solid_.clear_dirty();
    st.regions_rebuilt = static_cast<int>(b.regions_built);
  }
  st.regions_pending = pending_regions();
  st.mesh_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return st;
}

}  // namespace lbr::gfx
