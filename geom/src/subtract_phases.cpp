// The phases of one subtraction over the threads that share it (SubtractEngine::run()),
// and the clip of one cell by the sections of its level.
#include <algorithm>
#include <atomic>

#include "polygon_ops.hpp"
#include "subtract_engine.hpp"

namespace lbr::geom::detail {

namespace {

// Sections with at least this many vertices are cut to the region before a clip.
constexpr std::size_t kCutSectionVertices = 64;

bool same_contour(const Contour& a, const Contour& b) noexcept { return a.cut_by == b.cut_by && a.pts == b.pts; }

// True when some edge of the closed contour has a box that meets b (conservative: the edge
// may still miss b).
bool edge_near(const Path& c, const Rect& b) noexcept {
  for (std::size_t i = 0, j = c.size() - 1; i < c.size(); j = i++) {
    const Point& p = c[i];
    const Point& q = c[j];
    if (std::max(p.X, q.X) < b.x0 || std::min(p.X, q.X) > b.x1 || std::max(p.Y, q.Y) < b.y0 || std::min(p.Y, q.Y) > b.y1)
      continue;
    return true;
  }
  return false;
}

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

// The sections whose box meets the cell's content (ws.selected) and the cell's polygons
// whose box meets those sections (ws.touched); false when either is empty.
bool select_for_cell(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws) {
  ws.selected.clear();
  Rect clipbox;
  for (std::uint32_t k = 0; k < ls.paths.size(); ++k) {
    if (ls.box[k].intersects(cell.bbox)) {
      ws.selected.push_back(k);
      clipbox.add(ls.box[k]);
    }
  }
  if (ws.selected.empty()) return false;
  ws.touched.clear();
  for (std::uint32_t p = 0; p < cell.polys.size(); ++p)
    if (cell.polys[p].bbox.intersects(clipbox)) ws.touched.push_back(p);
  return !ws.touched.empty();
}

// Sections in the air: when no edge of the material comes near a section's box, the box
// lies wholly inside or wholly outside the material, and one point decides which. A
// section outside removes nothing and leaves the clip (the shank of a finishing tool over
// already cleared levels). False when none is left: nothing changes.
bool drop_sections_in_air(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws, SubtractStats& stats) {
  std::size_t kept = 0;
  for (std::uint32_t k : ws.selected) {
    const Rect& b = ls.box[k];
    bool near = false, inside = false;
    const Point centre{b.x0 + (b.x1 - b.x0) / 2, b.y0 + (b.y1 - b.y0) / 2};
    for (std::uint32_t p : ws.touched) {
      const Polygon& poly = cell.polys[p];
      if (!poly.bbox.intersects(b)) continue;
      near = edge_near(poly.outer.pts, b);
      for (std::size_t h = 0; !near && h < poly.holes.size(); ++h) near = edge_near(poly.holes[h].pts, b);
      if (near) break;
      if (ClipperLib::PointInPolygon(centre, poly.outer.pts) != 0) {
        inside = true;
        for (const Contour& h : poly.holes)
          if (ClipperLib::PointInPolygon(centre, h.pts) != 0) inside = false;
        if (inside) break;
      }
    }
    if (near || inside) ws.selected[kept++] = k;
    else ++stats.sections_in_air;
  }
  ws.selected.resize(kept);
  return kept > 0;
}

// A difference that removes no more than the rounding of intersection points to the unit
// grid can account for (half a unit along the touched perimeter) is noise, e.g. a second
// pass along the same path: the caller keeps the old polygons, vertex for vertex.
bool removes_only_noise(const Cell& cell, const SubtractWorkspace& ws) {
  double before = 0.0, after = 0.0, perimeter = 0.0;
  for (std::uint32_t p : ws.touched) {
    const Polygon& old = cell.polys[p];
    before += ClipperLib::Area(old.outer.pts);
    perimeter += detail::perimeter(old.outer.pts);
    for (const Contour& h : old.holes) {
      before += ClipperLib::Area(h.pts);
      perimeter += detail::perimeter(h.pts);
    }
  }
  for (const Polygon& poly : ws.fresh) {
    after += ClipperLib::Area(poly.outer.pts);
    for (const Contour& h : poly.holes) after += ClipperLib::Area(h.pts);
  }
  return before - after <= 0.5 * perimeter;
}

// Carries the move id over to the contours of ws.fresh that came out unchanged; a new or
// changed contour takes the latest move among the sections that overlap it. True when
// some contour changed.
bool inherit_move_ids(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws) {
  bool changed = ws.fresh.size() != ws.touched.size();
  auto inherit = [&](Contour& out, const Rect& box) {
    for (std::uint32_t p : ws.touched) {
      const Polygon& old = cell.polys[p];
      if (old.bbox == box && same_cycle(old.outer.pts, out.pts)) {
        out.cut_by = old.outer.cut_by;
        return;
      }
      for (const Contour& h : old.holes) {
        if (h.pts.size() == out.pts.size() && same_cycle(h.pts, out.pts)) {
          out.cut_by = h.cut_by;
          return;
        }
      }
    }
    changed = true;
    MoveId id = 0;
    for (std::uint32_t k : ws.selected)
      if (ls.box[k].intersects(box)) id = std::max(id, ls.id[k]);
    if (id == 0)
      for (std::uint32_t k : ws.selected) id = std::max(id, ls.id[k]);
    out.cut_by = id;
  };
  for (Polygon& poly : ws.fresh) {
    inherit(poly.outer, poly.bbox);
    for (Contour& h : poly.holes) inherit(h, bounds_of(h.pts));
  }
  return changed;
}

// The cell's polygons with the touched ones replaced by ws.fresh (untouched first).
void replace_touched(Cell& cell, SubtractWorkspace& ws) {
  ws.kept.clear();
  std::size_t t = 0;
  for (std::uint32_t p = 0; p < cell.polys.size(); ++p) {
    if (t < ws.touched.size() && ws.touched[t] == p) {
      ++t;
      continue;
    }
    ws.kept.push_back(std::move(cell.polys[p]));
  }
  for (Polygon& poly : ws.fresh) ws.kept.push_back(std::move(poly));
  cell.polys.swap(ws.kept);
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

Rect SubtractEngine::grown_region_rect(int region) const noexcept {
  const Rect rr = s_.region_rect(region);
  const Coord g = static_cast<Coord>(kUnitsPerMm);
  return Rect{rr.x0 - g, rr.y0 - g, rr.x1 + g, rr.y1 + g};
}

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
  build_offsets_and_levels(sh, ws, stats);
  sync();  // (1) offsets and sections built
  plan_clips(sh, ws);
  if (count > 1) order_clips(sh, ws);
  clip_phase(sh, ws, ahead, stats);
  sync();  // (2) every run's first cell is final
  copy_runs(sh, ws, index, count, stats);
  return stats;
}

// Phase A: the chain offsets unless built ahead (items [0, noff)) and the levels' sections
// (the rest); for the cells a level reaches, whether the cell starts equal to the one below
// (read only: nothing changes before phase C).
void SubtractEngine::build_offsets_and_levels(SubtractShared& sh, SubtractWorkspace& ws, SubtractStats& stats) const {
  const std::size_t noff = sh.offsets_ready ? 0 : sh.offset_keys.size();
  const auto n = static_cast<std::size_t>(sh.le - sh.lb);
  for (std::size_t item = take(sh, 0); item < noff + n; item = take(sh, 0)) {
    if (item < noff) {
      build_offset(sh, item, stats);
      continue;
    }
    const int l = sh.lb + static_cast<int>(item - noff);
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
      sh.outcome[k] = clip_cell(region, l, sh.levels[k / nreg], sh, ws, stats) ? 1 : 0;
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
        if (sh.outcome[static_cast<std::size_t>(src - lb) * nreg + static_cast<std::size_t>(region)] == 0) continue;
        const std::size_t ci = static_cast<std::size_t>(region) * levels + static_cast<std::size_t>(l);
        const Cell& from = s_.cells_[static_cast<std::size_t>(region) * levels + static_cast<std::size_t>(src)];
        Cell& to = s_.cells_[ci];
        to.polys = from.polys;
        to.bbox = from.bbox;
        to.area_units2 = from.area_units2;
        to.last_cut = from.last_cut;
        ++to.version;
        s_.dirty_flag_[ci] = 1;
        ++stats.cells_changed;
      }
  }
}

// The selected sections as clip paths. A chain enters as its offset's piece for the
// region; a long section that reaches well beyond the region (a joined outline runs along
// a whole pass) is cut down to the region grown by 1 mm first, so that the clip carries
// only the nearby edges (the cut keeps the path inside the grown region, where the cell lies).
void SubtractEngine::add_clip_paths(int region, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws) const {
  ClipperLib::Clipper& c = ws.clipper;
  const Rect grown = grown_region_rect(region);
  for (std::uint32_t k : ws.selected) {
    if (ls.chain[k] != kNoChain) {
      c.AddPaths(offset_piece(sh, ls.chain[k], region, ws), ClipperLib::ptClip, true);
    } else if (contains(grown, ls.box[k]) || ls.paths[k].size() < kCutSectionVertices) {
      c.AddPath(ls.paths[k], ClipperLib::ptClip, true);
    } else {
      cut_to_rect(ls.paths[k], grown, ws.cut, ws.cut_tmp);
      if (ws.cut.size() >= 3) c.AddPath(ws.cut, ClipperLib::ptClip, true);
    }
  }
}

// Clips one cell with the level's sections; true when the cell changed.
bool SubtractEngine::clip_cell(int region, int level, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                         SubtractStats& stats) {
  const std::size_t ci = static_cast<std::size_t>(region) * s_.levels_ + level;
  Cell& cell = s_.cells_[ci];
  if (!cell.bbox.intersects(ls.all)) return false;
  ++stats.cells_tested;
  if (!select_for_cell(cell, ls, ws) || !drop_sections_in_air(cell, ls, ws, stats)) return false;

  ClipperLib::Clipper& c = ws.clipper;
  c.Clear();
  c.StrictlySimple(s_.spec_.strictly_simple);
  for (std::uint32_t p : ws.touched) {
    c.AddPath(cell.polys[p].outer.pts, ClipperLib::ptSubject, true);
    for (const Contour& h : cell.polys[p].holes) c.AddPath(h.pts, ClipperLib::ptSubject, true);
  }
  add_clip_paths(region, ls, sh, ws);
  ws.tree.Clear();
  c.Execute(ClipperLib::ctDifference, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  ++stats.cells_clipped;
  ws.fresh.clear();
  append_polygons(ws.tree, ws.fresh);
  if (removes_only_noise(cell, ws) || !inherit_move_ids(cell, ls, ws)) return false;

  replace_touched(cell, ws);
  refresh_cell(cell);
  cell.last_cut = 0;
  for (std::uint32_t k : ws.selected) cell.last_cut = std::max(cell.last_cut, ls.id[k]);
  ++cell.version;
  s_.dirty_flag_[ci] = 1;
  ++stats.cells_changed;
  return true;
}

}  // namespace lbr::geom::detail
