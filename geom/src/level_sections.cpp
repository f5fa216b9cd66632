// The sections of one level for one batch: joined outlines of vertical runs, single
// sections trimmed where the previous one covers them, tilted sections, chain offsets and
// lathe regions; and the chain offsets themselves with their pieces cut to regions.
#include <algorithm>
#include <atomic>
#include <cmath>

#include "chain_outline.hpp"
#include "polygon_ops.hpp"
#include "subtract_engine.hpp"

namespace lbr::geom::detail {

namespace {
// Consecutive tilted sections joined at a time (join_tilted()): a union's cost is linear in
// its sections' vertices, and longer unions put fewer overlapping ends into a clip (finish5x:
// groups of 8, 32 and 128 cost 1.33, 0.83 and 0.76 G instructions of clipping; 1 024 the same
// as 128). Bounded so that the move a contour is attributed to (its cut_by, the latest
// among the sections it meets) stays that of a stretch of the path.
constexpr std::size_t kTiltedGroup = 128;
}  // namespace

// Builds offset `o` of the prepared batch: the chain's path offset by exactly r, so that its
// straight walls stand where the tool's circle puts them in every direction (a pocket's or
// a slot's walls: no bias, where vertices on r·θ/sin θ put them up to tol/2 outside).
// Clipper puts the round joins' and ends' vertices on r (inscribed); its arc tolerance tol/2
// keeps them within tol/2 inside the exact arcs (docs/lbr-conventions.md, "Straight walls").
// Once: the first caller builds it, a caller meanwhile waits for it.
void build_offset(SubtractShared& sh, std::size_t o, SubtractStats& stats) {
  SubtractShared::Offset& off = sh.offsets[o];
  build_once(off.built, [&] {
    ++stats.chain_offsets;
    const SubtractShared::Chain& c = sh.chains[sh.offset_keys[o].chain];
    ClipperLib::ClipperOffset co(2.0, 0.5 * c.shape->chord_tol_mm * kUnitsPerMm);
    co.AddPath(c.pts, ClipperLib::jtRound, ClipperLib::etOpenRound);
    off.paths.clear();
    co.Execute(off.paths, sh.offset_keys[o].r * kUnitsPerMm);
  });
}

namespace {
// Section k's capsules start at the end of ls.reach; the sections before it that have none
// (tilted) are marked so.
void begin_reach(LevelSections& ls, std::size_t k) {
  ls.reach_begin.resize(k, kNoReach);
  ls.reach_end.resize(k, kNoReach);
  ls.reach_begin.push_back(static_cast<std::uint32_t>(ls.reach.size()));
  ls.reach_end.push_back(kNoReach);
}
}  // namespace

void SubtractEngine::build_level(int level, const SubtractShared& sh, SubtractWorkspace& ws, LevelSections& ls,
                                 SubtractStats& stats) const {
  const double zc = s_.level_z_mm(level);
  for (Path& p : ls.paths) ws.scratch.spare.push_back(std::move(p));  // keep the buffers
  ls.paths.clear();
  ls.box.clear();
  ls.id.clear();
  ls.chain.clear();
  ls.chain_offset.assign(sh.chain_count, kNoChain);
  ls.reach.clear();
  ls.reach_begin.clear();
  ls.reach_end.clear();
  ls.all = Rect{};
  ls.ix0 = ls.iy0 = 0;
  ls.ix1 = ls.iy1 = -1;
  ls.anchors = &s_.ws_->level_anchors[static_cast<std::size_t>(level)];
  ls.anchor = 0;
  // The material of this level before the batch (the cells' boxes and masks): tilted
  // sub-steps beside it are not built, and pieces whose sections miss it are marked in_air
  // (Sweep::tilted_pieces()).
  const LevelMaterial material(s_, level, s_.xs_, s_.ys_, s_.ws_->masks, ws.mask_crossings, sh.tilted_regions);
  for (const auto& run : sh.runs) build_run_sections(zc, run, material, sh, ws, ls, stats);
  ls.chain.assign(ls.paths.size(), kNoChain);
  ls.reach_begin.resize(ls.paths.size(), kNoReach);  // tilted sections: none
  ls.reach_end.resize(ls.paths.size(), kNoReach);
  add_chain_sections(level, sh, ls);
  add_lathe_sections(zc, sh, ls);
  for (std::size_t k = 0; k < ls.paths.size(); ++k)
    if (ls.chain[k] == kNoChain) split_at_lines(ls.paths[k], sh.border_x, sh.border_y, ws.cut_tmp);
  stats.sections += ls.paths.size();
  if (ls.paths.empty() || !ls.all.intersects(s_.xy_)) return;
  ls.ix0 = interval_of(s_.xs_, ls.all.x0);
  ls.ix1 = interval_of(s_.xs_, ls.all.x1);
  ls.iy0 = interval_of(s_.ys_, ls.all.y0);
  ls.iy1 = interval_of(s_.ys_, ls.all.y1);
}

// Chains: one entry for the whole offset (outer contours and holes); a clip adds its piece
// cut to the region (SubtractShared::Offset), and builds the offset first if no clip has.
// The offset lies within the capsules of radius r about the chain's segments, so a cell
// whose material is out of their reach builds nothing (docs/lbr-conventions.md, "Clips out
// of reach").
void SubtractEngine::add_chain_sections(int level, const SubtractShared& sh, LevelSections& ls) {
  for (std::size_t ci = 0; ci < sh.chain_count; ++ci) {
    const std::uint32_t o = sh.offset_of[static_cast<std::size_t>(level - sh.lb) * sh.chain_count + ci];
    if (o == kNoChain) continue;
    ls.chain_offset[ci] = o;
    begin_reach(ls, ls.paths.size());
    add_chain_reach(sh.chains[ci].pts, sh.offset_keys[o].r, ls.reach);
    ls.reach_end.back() = static_cast<std::uint32_t>(ls.reach.size());
    ls.paths.emplace_back();
    ls.box.push_back(sh.offsets[o].box);
    ls.id.push_back(sh.chains[ci].id);
    ls.chain.push_back(o);
    ls.all.add(sh.offsets[o].box);
  }
}

// Turning moves: the union of their revolved regions on this level is one region, the
// smallest r_min (external) and the largest r_max (internal); it takes the latest move id
// among them.
void SubtractEngine::add_lathe_sections(double zc, const SubtractShared& sh, LevelSections& ls) const {
  if (sh.lathe.empty()) return;
  double r_out = INFINITY, r_in = -INFINITY, tol = s_.spec_.chord_tol_mm;
  MoveId id_out = 0, id_in = 0;
  for (std::size_t si = 0; si < sh.lathe.size(); ++si) {
    const LatheSweep& lw = sh.lathe[si];
    double lo = 0, hi = 0;
    if (zc < lw.z_min() || zc > lw.z_max() || !lw.interval(zc, lo, hi)) continue;
    tol = lw.chord_tol_mm();
    if (lw.internal()) {
      if (hi > r_in) r_in = hi;
      id_in = std::max(id_in, sh.lathe_id[si]);
    } else {
      if (lo < r_out) r_out = lo;
      id_out = std::max(id_out, sh.lathe_id[si]);
    }
  }
  for (int internal = 0; internal < 2; ++internal) {
    const double r = internal ? r_in : r_out;
    if (!std::isfinite(r)) continue;
    const std::size_t before = ls.paths.size();
    LatheSweep::removed_region(r, internal != 0, tol, s_.xy_, ls.paths);
    for (std::size_t k = before; k < ls.paths.size(); ++k) {
      ls.box.push_back(bounds_of(ls.paths[k]));
      ls.id.push_back(internal ? id_in : id_out);
      ls.chain.push_back(kNoChain);
      ls.all.add(ls.box.back());
    }
  }
}

namespace {

// The run's angle grid for joined outlines: the tool's full radius sets it. Even, so that a
// stadium's caps are exact half turns (chain_outline.cpp, notch_is_exact()).
int outline_grid(const Sweep& sw) noexcept {
  return (Sweep::circle_segments(sw.shape().radius(), sw.shape().chord_tol_mm) + 1) / 2 * 2;
}

// Moves si, si + 1, ... (before `end`) whose sections on zc share their joint disks, with
// their caps in ws.caps; how many (an outline needs two or more).
std::size_t joinable_moves(double zc, std::uint32_t si, std::uint32_t end, int grid, const SubtractShared& sh,
                           SubtractWorkspace& ws) {
  if (ws.caps.size() < end - si) ws.caps.resize(end - si);
  std::size_t count = 0;
  while (si + count < end && sh.sweeps[si + count].section_caps(zc, grid, ws.scratch, ws.caps[count]) &&
         (count == 0 || (ws.caps[count - 1].c1.x == ws.caps[count].c0.x && ws.caps[count - 1].c1.y == ws.caps[count].c0.y &&
                         ws.caps[count - 1].rho1 == ws.caps[count].rho0)))
    ++count;
  return count;
}

// A still move (a plunge or a retract: the tip moves along the vertical axis only) beside a
// joined outline on the outline's grid: a plunge's lowest point is where the outline's first
// move starts, a retract's where its last move ended. A tool is no narrower above than below,
// so the still move's section on zc is the disk of its lowest point, no wider than the
// outline's cap there (radius `rho` on the grid, centre c); discretised on the outline's grid
// it is a concentric copy of that cap's polygon, no larger, which the outline contains
// (docs/lbr-conventions.md, "Joined sections"). True when that holds: the section adds
// nothing to the outline and is left out.
bool still_inside_cap(double zc, const Sweep& sw, SectionScratch::P2 c, double rho, int grid, SectionScratch& sc) {
  const Vec3& low = sw.from().tip.z <= sw.to().tip.z ? sw.from().tip : sw.to().tip;
  if (c.x != low.x || c.y != low.y) return false;
  const double r = sw.widest_disk_mm(zc, sc);
  return r > 0.0 && r * Sweep::circle_grow_width(grid) <= rho;
}

bool still_move(const Sweep& sw) noexcept {
  return sw.vertical() && sw.from().tip.x == sw.to().tip.x && sw.from().tip.y == sw.to().tip.y;
}

// A still move at si whose section on zc lies inside the outline that ends just before it
// (after_outline: that outline's end cap, radius and grid) or the one that starts just after it.
bool still_beside_outline(double zc, std::uint32_t si, std::uint32_t end, bool after_outline, SectionScratch::P2 cap,
                          double rho, int grid, const SubtractShared& sh, SubtractWorkspace& ws) {
  const Sweep& sw = sh.sweeps[si];
  if (sw.to().tip.z > sw.from().tip.z) return after_outline && still_inside_cap(zc, sw, cap, rho, grid, ws.scratch);
  if (si + 2 >= end) return false;  // no two moves after it
  const int g = outline_grid(sh.sweeps[si + 1]);
  if (joinable_moves(zc, si + 1, std::min(end, si + 3), g, sh, ws) < 2) return false;
  return still_inside_cap(zc, sw, ws.caps[0].c0, ws.caps[0].rho0, g, ws.scratch);
}

}  // namespace

// The sections of one run of sweeps on plane zc: consecutive moves whose sections share
// their joint disk become one outline (chain_outline.hpp); the others are emitted one by
// one, trimmed where the previous vertical section covers them (trim_covered()).
void SubtractEngine::build_run_sections(double zc, std::pair<std::uint32_t, std::uint32_t> run, const PlaneMaterial& material,
                                        const SubtractShared& sh, SubtractWorkspace& ws, LevelSections& ls,
                                        SubtractStats& stats) const {
  Capsule prev_core;  // inside the last single vertical section of this run (trim_covered())
  // The last joined outline on this level: one past its last move, and that move's end cap.
  std::uint32_t outline_end = run.second;
  SectionScratch::P2 end_cap{};
  double end_rho = 0.0;
  int end_grid = 0;
  const double band = reach_band_units(s_.spec_.chord_tol_mm);
  auto push_boxes = [&](std::size_t before, MoveId id) {
    for (std::size_t k = before; k < ls.paths.size(); ++k) {
      ls.box.push_back(bounds_of(ls.paths[k]));
      ls.id.push_back(id);
      ls.all.add(ls.box.back());
    }
  };
  // Tilted sweeps' pieces (sub-steps) wait in ws.pieces until the run's next vertical sweep
  // or its end (build_tilted()).
  ws.pieces.clear();
  auto flush_tilted = [&] { build_tilted(sh, material, ws, ls, stats); };
  std::uint32_t si = run.first;
  while (si < run.second) {
    const Sweep& sw = sh.sweeps[si];
    if (zc < sw.z_min() || zc > sw.z_max()) {
      ++si;
      continue;
    }
    if (!sw.vertical()) {
      const std::size_t before = ws.pieces.size();
      sw.tilted_pieces(zc, ws.pieces, &material, &stats.tilted_beside);
      for (std::size_t k = before; k < ws.pieces.size(); ++k) ws.pieces[k].sweep = si;
      ++si;
      continue;
    }
    flush_tilted();
    // Joined outline from si, when si and at least the next move share their joint disk.
    if (run.second - si >= 2) {
      const int grid = outline_grid(sw);
      const std::size_t count = joinable_moves(zc, si, run.second, grid, sh, ws);
      if (count >= 2) {
        const std::size_t before = ls.paths.size();
        bool star = false;
        detail::append_outline(std::span<const MoveCaps>(ws.caps.data(), count), grid, ws.scratch.unit_circle(grid),
                               ws.outline, ls.paths, ws.scratch.spare, star);
        if (star) ++stats.outlines_star;
        MoveId id = 0;
        for (std::size_t k = 0; k < count; ++k) id = std::max(id, sh.sweep_id[si + k]);
        push_boxes(before, id);
        if (ls.paths.size() == before + 1) {
          begin_reach(ls, before);
          add_outline_reach(std::span<const MoveCaps>(ws.caps.data(), count), band, ls.reach);
          ls.reach_end[before] = static_cast<std::uint32_t>(ls.reach.size());
          outline_end = si + static_cast<std::uint32_t>(count);
          end_cap = ws.caps[count - 1].c1;
          end_rho = ws.caps[count - 1].rho1;
          end_grid = grid;
        }
        stats.sections_joined += count;
        prev_core = Capsule{};
        si += static_cast<std::uint32_t>(count);
        continue;
      }
    }
    if (still_move(sw) && still_beside_outline(zc, si, run.second, outline_end == si, end_cap, end_rho, end_grid, sh, ws)) {
      ++stats.sections_trimmed;
      ++si;
      continue;
    }
    const std::size_t before = ls.paths.size();
    sw.section(zc, ls.paths, ws.scratch);
    // Consecutive moves overlap: the vertices of this section inside the previous vertical
    // section's capsule add edges to the clip but remove nothing more (trim_covered()).
    if (ls.paths.size() == before + 1) {
      if (prev_core.valid()) {
        const std::size_t vertices = ls.paths.back().size();
        if (!trim_covered(ls.paths.back(), prev_core, ws.trim_flags)) {
          ls.paths.pop_back();
          ++stats.sections_trimmed;
        } else if (ls.paths.back().size() != vertices) {
          ++stats.sections_trimmed;
        }
      }
      if (ws.scratch.core.valid()) prev_core = ws.scratch.core;
    }
    push_boxes(before, sh.sweep_id[si]);
    for (std::size_t k = before; k < ls.paths.size(); ++k) {
      begin_reach(ls, k);
      add_section_reach(ls.paths[k], sw.from().tip.x, sw.from().tip.y, sw.to().tip.x, sw.to().tip.y, band, ls.reach);
      ls.reach_end[k] = static_cast<std::uint32_t>(ls.reach.size());
    }
    ++si;
  }
  flush_tilted();
}

// The sections of the pending tilted pieces (ws.pieces, consecutive sub-steps of a run's
// tilted sweeps on this level), each refined only where neither neighbour's coarse polygon
// covers its arcs (Sweep::build_piece(): all of them go into this level's one difference),
// then joined in groups (join_tilted()).
void SubtractEngine::build_tilted(const SubtractShared& sh, const PlaneMaterial& material, SubtractWorkspace& ws, LevelSections& ls,
                                  SubtractStats& stats) const {
  const std::size_t n = ws.pieces.size();
  if (n == 0) return;
  const std::size_t level = static_cast<std::size_t>(s_.level_at(ws.pieces.front().zc));
  const TiltedPiece* prior = level_prior(level);
  MoveId id = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const TiltedPiece& p = ws.pieces[i];
    if (p.in_air) {  // its section would remove nothing; what it covers for its neighbours is air too
      ++stats.tilted_in_air;
      ws.piece_cover[i % 2].clear();  // no polygon built: the next piece has no such cover
      continue;
    }
    const std::size_t before = ls.paths.size();
    const Sweep::PieceCovers covers{i > 0 ? &ws.pieces[i - 1] : prior, i + 1 < n ? &ws.pieces[i + 1] : nullptr,
                                    i > 0 ? &ws.piece_cover[(i - 1) % 2] : nullptr,
                                    i + 1 < n ? &ws.piece_cover[i % 2] : nullptr, &material};
    sh.sweeps[p.sweep].build_piece(p, covers, ls.paths, ws.scratch);
    if (i + 1 == n && ls.paths.size() == before + 1)  // before joins and border splits
      keep_anchor(level, ls.paths.back(), sh.sweeps[p.sweep].shape().chord_tol_mm, ls);
    if (ls.paths.size() > before) id = std::max(id, sh.sweep_id[p.sweep]);
    if (ls.paths.size() - ls.box.size() >= kTiltedGroup) {
      join_tilted(ls.box.size(), id, ws, ls, stats);
      id = 0;
    }
  }
  if (ls.paths.size() > ls.box.size()) join_tilted(ls.box.size(), id, ws, ls, stats);
  SubtractWorkspace& kept = *s_.ws_;  // the solid's: the same whichever thread builds the level
  kept.level_last[level] = ws.pieces.back();
  kept.level_last_set[level] = 1;
  ws.pieces.clear();
}

// The last tilted piece built on `level` for this solid (by whichever thread built the level:
// kept in the solid's own workspace, so that the result is the same for every thread count),
// when the solid has not had material put back since (LbrSolid::removal_epoch()): its
// coarse polygon lies in material already removed, or removed in this difference, so the
// level's next piece need not refine its boundary where a refinement triangle lies in it
// (Sweep::build_piece()). A live call holds one or two pieces per level, which had no cover
// before their first. Until 2026-12-01 each thread kept its own, and a level's first piece
// of a batch saw the cover of whichever thread had built that level last: finish5x with
// two threads gave one of two results.
void SubtractEngine::reset_level_last() const {
  SubtractWorkspace& kept = *s_.ws_;
  const std::size_t levels = static_cast<std::size_t>(s_.levels());
  if (kept.level_last_epoch != s_.removal_epoch() || kept.level_last.size() != levels) {
    kept.level_last.resize(levels);
    kept.level_last_set.assign(levels, 0);
    kept.level_anchors.assign(levels, LevelAnchors{});
    kept.cell_anchor.assign(s_.cells_.size(), 0);
    kept.level_last_epoch = s_.removal_epoch();
  }
}

// The last piece of a level's tilted run, `poly` (convex, before joins and border splits),
// becomes the level's newest anchor (LevelAnchors), a generation given to the cells that
// this batch clips there (clip_cell()); a later run of the batch on the level replaces it.
// Its band: reach_band_units() of the tool's chord tolerance.
void SubtractEngine::keep_anchor(std::size_t level, const Path& poly, double chord_tol_mm, LevelSections& ls) const {
  LevelAnchors& a = s_.ws_->level_anchors[level];
  const std::uint64_t g = ls.anchor != 0 ? ls.anchor : a.last + 1;
  const std::size_t slot = g % LevelAnchors::kSize;
  if (a.piece[slot].set(poly, reach_band_units(chord_tol_mm))) {
    a.gen[slot] = g;
    a.last = g;
    ls.anchor = g;
  } else {
    a.gen[slot] = 0;
    ls.anchor = 0;
  }
}

void SubtractEngine::reset_cell_masks(bool tilted) const {
  SubtractWorkspace& kept = *s_.ws_;
  if (kept.masks_epoch != s_.removal_epoch()) {
    for (CellMask& m : kept.masks) m.built = false;
    kept.masks_epoch = s_.removal_epoch();
  }
  if (tilted && kept.masks.size() != s_.cells_.size()) kept.masks.assign(s_.cells_.size(), CellMask{});
}

const TiltedPiece* SubtractEngine::level_prior(std::size_t level) const {
  const SubtractWorkspace& kept = *s_.ws_;
  return kept.level_last_set[level] != 0 ? &kept.level_last[level] : nullptr;
}

// The tilted sections ls.paths[begin..] (consecutive sub-steps and moves of one run, each
// convex) become the unions of their longest stretches that stay monotone along the path
// (MonotoneUnion), with id `id` (the latest move among them). Fed to a clip as separate
// polygons, neighbours that overlap put all their edges into every scan beam; a stretch along
// a path has the outline of about two sections. A union is exact up to the rounding of its
// new vertices (the crossings of section edges) to the unit grid, ±0.05 µm. The direction of
// a stretch is taken from its first section to the one kJoinAhead later.
void SubtractEngine::join_tilted(std::size_t begin, MoveId id, SubtractWorkspace& ws, LevelSections& ls,
                                 SubtractStats& stats) {
  constexpr std::size_t kJoinAhead = 8;
  Paths& in = ws.join_in;
  in.clear();
  for (std::size_t k = begin; k < ls.paths.size(); ++k) in.push_back(std::move(ls.paths[k]));
  ls.paths.resize(begin);
  auto centre = [&](std::size_t k) {
    const Rect b = bounds_of(in[k]);
    return SectionScratch::P2{0.5 * (static_cast<double>(b.x0) + static_cast<double>(b.x1)), 0.5 * (static_cast<double>(b.y0) + static_cast<double>(b.y1))};
  };
  MonotoneUnion& u = ws.joined;
  std::size_t i = 0;
  while (i < in.size()) {
    const SectionScratch::P2 a = centre(i), b = centre(std::min(i + kJoinAhead, in.size() - 1));
    u.begin(b.x - a.x, b.y - a.y);
    std::size_t j = i;
    while (j < in.size() && u.add(in[j])) ++j;
    if (j <= i + 1) {  // a section on its own (or one the union cannot take): as it is
      ls.paths.push_back(std::move(in[i]));
      i = std::max(j, i + 1);
      continue;
    }
    ls.paths.push_back(SectionScratch::take_spare(ws.scratch.spare));
    u.write(ls.paths.back());
    stats.sections_joined += j - i;
    i = j;
  }
  for (Path& p : in)
    if (p.capacity() > 0) ws.scratch.spare.push_back(std::move(p));
  for (std::size_t k = begin; k < ls.paths.size(); ++k) {
    ls.box.push_back(bounds_of(ls.paths[k]));
    ls.id.push_back(id);
    ls.all.add(ls.box.back());
  }
}

// The chain offset `o` cut to `region` (grown by 1 mm); the first thread that needs a piece
// cuts it, one that needs it meanwhile waits (a cut takes microseconds).
const Paths& SubtractEngine::offset_piece(SubtractShared& sh, std::uint32_t o, int region, SubtractWorkspace& ws,
                                          SubtractStats& stats) const {
  static const Paths kNone;
  SubtractShared::Offset& off = sh.offsets[o];
  const int ix = region % s_.spec_.regions_x, iy = region / s_.spec_.regions_x;
  // A cell can touch the box on its edge from the region beside the box's first one: the
  // offset covers none of its area there.
  if (ix < off.ix0 || ix > off.ix1 || iy < off.iy0 || iy > off.iy1) return kNone;
  build_offset(sh, o, stats);
  const Rect rr = grown_region_rect(region);
  if (contains(rr, off.box)) return off.paths;  // wholly inside: nothing to cut
  const std::size_t i = static_cast<std::size_t>((iy - off.iy0) * (off.ix1 - off.ix0 + 1) + (ix - off.ix0));
  build_once(off.state[i], [&] {
    Paths& out = off.cut[i];
    out.clear();
    ClipperLib::Clipper& k = ws.rect_clipper;
    k.Clear();
    k.AddPaths(off.paths, ClipperLib::ptSubject, true);
    k.AddPath(rect_path(rr), ClipperLib::ptClip, true);
    k.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  });
  return off.cut[i];
}

}  // namespace lbr::geom::detail
