// The phases of one subtraction over the threads that share it (SubtractEngine::run()):
// A sections, B the table of runs, C the clips (cell_clip.cpp), D the copies.
#include <algorithm>
#include <atomic>

#include "subtract_engine.hpp"

namespace lbr::geom::detail {

namespace {

bool same_contour(const Contour& a, const Contour& b) noexcept { return a.cut_by == b.cut_by && a.pts == b.pts; }

// Vertex for vertex the same polygons, move ids included (cheap tests first).
bool same_polygons(const Cell& a, const Cell& b) noexcept {
  if (a.polys.size() != b.polys.size() || !(a.bbox == b.bbox) || a.area_units2 != b.area_units2) return false;
  for (std::size_t i = 0; i < a.polys.size(); ++i) {
    const Polygon& p = a.polys[i];
    const Polygon& q = b.polys[i];
    if (p.holes.size() != q.holes.size() || !same_contour(p.outer, q.outer)) return false;
    for (std::size_t h = 0; h < p.holes.size(); ++h)
      if (!same_contour(p.holes[h], q.holes[h])) return false;
  }
  return true;
}

// Work is taken from shared counters, so a thread that gets a long item takes fewer of the
// rest; which thread does an item never changes the result.
std::size_t take(SubtractShared& sh, int phase) noexcept {
  return sh.next[static_cast<std::size_t>(phase)].fetch_add(1, std::memory_order_relaxed);
}

// Builds one of the next batch's chain offsets once that batch is prepared; false when it
// is not prepared yet or none is left.
bool build_ahead_offset(SubtractShared& sh, const SubtractAhead* ahead, SubtractStats& stats) {
  if (ahead == nullptr || sh.ahead_ready.load(std::memory_order_acquire) == 0) return false;
  const std::size_t o = take(sh, 2);
  if (o >= ahead->shared->offset_keys.size()) return false;
  build_offset(*ahead->shared, o, stats);
  return true;
}

}  // namespace

SubtractStats SubtractEngine::subtract(std::span<const SweepRef> batch, SubtractWorkspace& ws) {
  static const std::function<void()> kNoSync = [] {};
  prepare(batch, ws.own);
  return run(ws.own, ws, 0, 1, kNoSync, nullptr);
}

SubtractStats SubtractEngine::run(SubtractShared& sh, SubtractWorkspace& ws, int index, int count,
                                  const std::function<void()>& sync, const SubtractAhead* ahead) {
  SubtractStats stats;
  if (sh.le - sh.lb <= 0) {  // the same in every thread: nobody waits
    ws.jobs.clear();
    clip_phase(sh, ws, ahead, stats);
    return stats;
  }
  build_levels(sh, ws, stats);
  sync();  // (1) sections built
  plan_clips(sh, ws);
  if (count > 1) order_clips(sh, ws);
  clip_phase(sh, ws, ahead, stats);
  sync();  // (2) every run's first cell is final
  copy_runs(sh, ws, index, count, stats);
  return stats;
}

// Phase A: the levels' sections; for the cells a level reaches, whether the cell starts
// equal to the one below (read only: nothing changes before phase C). The chain offsets are
// built where a clip first needs one (offset_piece()), or ahead by idle threads.
void SubtractEngine::build_levels(SubtractShared& sh, SubtractWorkspace& ws, SubtractStats& stats) const {
  const auto n = static_cast<std::size_t>(sh.le - sh.lb);
  for (std::size_t item = take(sh, 0); item < n; item = take(sh, 0)) {
    const int l = sh.lb + static_cast<int>(item);
    LevelSections& ls = sh.levels[static_cast<std::size_t>(l - sh.lb)];
    build_level(l, sh, ws, ls, stats);
    compare_cells(l, l > sh.lb, ls);
  }
}

// Per region the level reaches: the cell's vertex count before the batch (the clip's cost
// estimate) and, when `below` (a level of the batch under this one), whether the cell holds
// the same polygons as the one below.
void SubtractEngine::compare_cells(int level, bool below, LevelSections& ls) const {
  const auto nreg = static_cast<std::size_t>(s_.regions());
  ls.same_cell_below.assign(nreg, 0);
  ls.cost.assign(nreg, 0);
  for (int iy = ls.iy0; iy <= ls.iy1; ++iy)
    for (int ix = ls.ix0; ix <= ls.ix1; ++ix) {
      const int region = iy * s_.spec_.regions_x + ix;
      const Cell& c = s_.cell(region, level);
      std::size_t v = 0;
      for (const Polygon& p : c.polys) {
        v += p.outer.pts.size();
        for (const Contour& h : p.holes) v += h.pts.size();
      }
      ls.cost[static_cast<std::size_t>(region)] = static_cast<std::uint32_t>(std::min<std::size_t>(v, 0xFFFFFFFFu));
      if (s_.spec_.vertical_coherence && below)
        ls.same_cell_below[static_cast<std::size_t>(region)] = same_polygons(c, s_.cell(region, level - 1)) ? 1 : 0;
    }
}

// Phase B, within each thread: which levels have the sections of the level below, the
// level each cell takes its result from (ws.source), and the list of cells that start a run
// (ws.jobs). Every thread derives the same table.
void SubtractEngine::plan_clips(const SubtractShared& sh, SubtractWorkspace& ws) const {
  const int lb = sh.lb;
  const auto nreg = static_cast<std::size_t>(s_.regions());
  ws.source.assign(static_cast<std::size_t>(sh.le - lb) * nreg, -1);
  ws.jobs.clear();
  for (int l = lb; l < sh.le; ++l) {
    const LevelSections& ls = sh.levels[static_cast<std::size_t>(l - lb)];
    if (ls.empty()) continue;
    bool same = false;
    if (s_.spec_.vertical_coherence && l > lb) {
      const LevelSections& lo = sh.levels[static_cast<std::size_t>(l - 1 - lb)];
      same = !lo.empty() && ls.chain_offset == lo.chain_offset && ls.paths == lo.paths;
    }
    for (int iy = ls.iy0; iy <= ls.iy1; ++iy)
      for (int ix = ls.ix0; ix <= ls.ix1; ++ix) {
        const std::size_t region = static_cast<std::size_t>(iy * s_.spec_.regions_x + ix);
        const std::size_t k = static_cast<std::size_t>(l - lb) * nreg + region;
        const int below = same && ls.same_cell_below[region] != 0 ? ws.source[k - nreg] : -1;
        ws.source[k] = below >= 0 ? below : l;
        if (below < 0) ws.jobs.push_back(static_cast<std::uint32_t>(k));
      }
  }
}

// Phase B, with more than one thread: the clips longest first (estimated by the cell's
// vertex count before the batch, from phase A: cells change from here on), so that no
// thread is left with a long clip at the end.
void SubtractEngine::order_clips(const SubtractShared& sh, SubtractWorkspace& ws) const {
  if (ws.jobs.size() <= 1) return;
  const auto nreg = static_cast<std::size_t>(s_.regions());
  ws.job_cost.resize(ws.jobs.size());
  for (std::size_t j = 0; j < ws.jobs.size(); ++j) {
    const std::size_t k = ws.jobs[j];
    ws.job_cost[j] = {sh.levels[k / nreg].cost[k % nreg], ws.jobs[j]};
  }
  std::sort(ws.job_cost.begin(), ws.job_cost.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  for (std::size_t j = 0; j < ws.jobs.size(); ++j) ws.jobs[j] = ws.job_cost[j].second;
}

// Phase C: the items are the next batch's preparation (item 0, when there is one), then the
// cells to clip (ws.jobs); once the next batch is prepared, its offsets go before the
// clips. With no clip left, a thread helps build the next batch's offsets.
void SubtractEngine::clip_phase(SubtractShared& sh, SubtractWorkspace& ws, const SubtractAhead* ahead,
                                SubtractStats& stats) {
  const auto nreg = static_cast<std::size_t>(s_.regions());
  const std::size_t pre = ahead != nullptr ? 1 : 0;
  for (;;) {
    if (build_ahead_offset(sh, ahead, stats)) continue;
    const std::size_t item = take(sh, 1);
    if (item < pre) {
      ahead->prepare();
      sh.ahead_ready.store(1, std::memory_order_release);
      continue;
    }
    if (item - pre < ws.jobs.size()) {
      const std::size_t k = ws.jobs[item - pre];
      const int l = sh.lb + static_cast<int>(k / nreg), region = static_cast<int>(k % nreg);
      sh.outcome[k] = clip_cell(region, l, sh.levels[k / nreg], sh, ws, stats);
      continue;
    }
    if (ahead != nullptr) {
      while (sh.ahead_ready.load(std::memory_order_acquire) == 0) cpu_relax();
      while (build_ahead_offset(sh, ahead, stats)) {
      }
    }
    return;
  }
}

// Phase D: the other cells of each run take its result (shared round-robin by position).
void SubtractEngine::copy_runs(const SubtractShared& sh, const SubtractWorkspace& ws, int index, int count,
                               SubtractStats& stats) {
  const int lb = sh.lb;
  const auto nreg = static_cast<std::size_t>(s_.regions());
  const auto levels = static_cast<std::size_t>(s_.levels_);
  std::size_t copy = 0;
  for (int l = lb; l < sh.le; ++l) {
    const LevelSections& ls = sh.levels[static_cast<std::size_t>(l - lb)];
    if (ls.empty()) continue;
    for (int iy = ls.iy0; iy <= ls.iy1; ++iy)
      for (int ix = ls.ix0; ix <= ls.ix1; ++ix) {
        const int region = iy * s_.spec_.regions_x + ix;
        const std::size_t k = static_cast<std::size_t>(l - lb) * nreg + static_cast<std::size_t>(region);
        const int src = ws.source[k];
        if (src == l) continue;
        if (copy++ % static_cast<std::size_t>(count) != static_cast<std::size_t>(index)) continue;
        ++stats.cells_reused;
        // (The cell keeps its anchor: this level's removed piece may differ from the source's.)
        if (sh.outcome[static_cast<std::size_t>(src - lb) * nreg + static_cast<std::size_t>(region)] != kCellChanged) continue;
        const std::size_t ci = static_cast<std::size_t>(region) * levels + static_cast<std::size_t>(l);
        const Cell& from = s_.cells_[static_cast<std::size_t>(region) * levels + static_cast<std::size_t>(src)];
        Cell& to = s_.cells_[ci];
        to.polys = from.polys;
        to.bbox = from.bbox;
        to.area_units2 = from.area_units2;
        to.last_cut = from.last_cut;
        s_.changed(ci);
        ++stats.cells_changed;
      }
  }
}

}  // namespace lbr::geom::detail
