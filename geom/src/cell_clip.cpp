// The clip of one cell by the sections of its level (phase C of SubtractEngine::run()):
// which sections and polygons take part, sections in the air left out, long sections and
// chain offsets cut down to the region, one Clipper difference, move ids carried over.
#include <algorithm>

#include "clip_reach.hpp"
#include "polygon_ops.hpp"
#include "subtract_engine.hpp"

namespace lbr::geom::detail {

namespace {

// Sections with at least this many vertices are cut to the region before a clip.
constexpr std::size_t kCutSectionVertices = 16;

// Margin of the box a clip path is cut to around the material it may touch [units].
constexpr Coord kKeepMarginUnits = 16;

// Windowed clips (window_clip.hpp): the window is the clip paths' box grown by this margin
// [units], beyond the unit that rounding moves a crossing, so that no chord comes near a
// vertex the difference makes; touched polygons with fewer vertices are clipped whole
// (finish3d: 32 and a window up to the touched box 0.90x the kernel time, 96 and a quarter
// of it 0.986x; docs/performance.md "Windowed clips").
constexpr Coord kWindowMarginUnits = 4;
constexpr std::size_t kWindowMinVertices = 32;

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

// Sections in the air (cover_of() is None: no material in the section's box) leave the
// clip: the shank of a finishing tool over already cleared levels. False when none is left:
// nothing changes.
bool drop_sections_in_air(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws, SubtractStats& stats) {
  std::size_t kept = 0;
  for (std::uint32_t k : ws.selected) {
    if (cover_of(cell, ls.box[k]) != RectCover::None) ws.selected[kept++] = k;
    else ++stats.sections_in_air;
  }
  ws.selected.resize(kept);
  return kept > 0;
}

// Clipper rounds the crossings of edges to the unit grid, and where a clip edge crosses a
// subject edge at a very shallow angle near the region's border the rounded point can land
// a few units beyond the subject, so beyond the region (seen: 4 units, a tilted ball raster,
// tests/geom_joined_test.cpp, Joined.TiltedRasterCutInOneBatchEqualsTheMovesCutOneByOne).
// Rare: only then is the result intersected with the region's rectangle (whose sides are
// axis-parallel, so its crossings lie on it exactly).
void keep_in_region(const Rect& rr, SubtractWorkspace& ws) {
  const bool out = std::any_of(ws.fresh.begin(), ws.fresh.end(), [&](const Polygon& p) { return !contains(rr, p.bbox); });
  if (!out) return;
  ClipperLib::Clipper& k = ws.rect_clipper;
  k.Clear();
  for (const Polygon& p : ws.fresh) {
    k.AddPath(p.outer.pts, ClipperLib::ptSubject, true);
    for (const Contour& h : p.holes) k.AddPath(h.pts, ClipperLib::ptSubject, true);
  }
  k.AddPath(rect_path(rr), ClipperLib::ptClip, true);
  ws.tree.Clear();
  k.Execute(ClipperLib::ctIntersection, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  ws.fresh.clear();
  append_polygons(ws.tree, ws.fresh);
}

// Clipper's result without the slivers its rounding leaves (remove_slivers(), within
// kSliverUnits): two sections whose edges run within a unit of each other leave a spike a
// unit wide between them, and where it reaches a region border the neighbour's contour
// does not follow it (docs/mesh.md §6). Vertices on the region's sides stay.
void drop_slivers(const Rect& rr, SubtractWorkspace& ws) {
  constexpr double kSliverUnits = 1.415;  // just over a diagonal grid step
  std::size_t kept = 0;
  for (Polygon& poly : ws.fresh) {
    if (remove_slivers(poly.outer.pts, rr, kSliverUnits, ws.cut_tmp)) poly.bbox = bounds_of(poly.outer.pts);
    if (poly.outer.pts.empty()) continue;
    std::size_t holes = 0;
    for (Contour& h : poly.holes) {
      remove_slivers(h.pts, rr, kSliverUnits, ws.cut_tmp);
      if (h.pts.empty()) continue;
      if (&poly.holes[holes] != &h) poly.holes[holes] = std::move(h);
      ++holes;
    }
    poly.holes.resize(holes);
    if (&ws.fresh[kept] != &poly) ws.fresh[kept] = std::move(poly);
    ++kept;
  }
  ws.fresh.resize(kept);
}

// A difference that removes no more than the rounding of intersection points to the unit
// grid can account for (half a unit along the touched perimeter), and keeps as many
// polygons, is noise, e.g. a second pass along the same path: the caller keeps the old
// polygons, vertex for vertex. A polygon that vanishes is not noise, however thin: a strip
// one unit wide (left where a section's side is tangent to a stock face) would otherwise
// stay for good, since its whole area is below that bound.
bool removes_only_noise(const Cell& cell, const SubtractWorkspace& ws) {
  if (ws.fresh.size() != ws.touched.size()) return false;
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

// The touched polygons' contours, whole, as the clip's subject.
void add_subjects(const Cell& cell, SubtractWorkspace& ws) {
  for (std::uint32_t p : ws.touched) {
    ws.clipper.AddPath(cell.polys[p].outer.pts, ClipperLib::ptSubject, true);
    for (const Contour& h : cell.polys[p].holes) ws.clipper.AddPath(h.pts, ClipperLib::ptSubject, true);
  }
}

// The touched contours reduced to the window of the clip paths (window_clip.hpp) as the
// clip's subject; false, with nothing added, where that does not pay or is not safe. Tried
// only where the window is no larger than the touched polygons' box and they have enough vertices.
bool add_windowed_subjects(const Cell& cell, const Rect& clip_box, SubtractWorkspace& ws) {
  if (clip_box.empty()) return false;
  Rect touched;
  std::size_t vertices = 0;
  ws.window.src.clear();
  for (std::uint32_t p : ws.touched) {
    const Polygon& poly = cell.polys[p];
    touched.add(Point{poly.bbox.x0, poly.bbox.y0});
    touched.add(Point{poly.bbox.x1, poly.bbox.y1});
    ws.window.src.push_back(&poly.outer.pts);
    vertices += poly.outer.pts.size();
    for (const Contour& h : poly.holes) {
      ws.window.src.push_back(&h.pts);
      vertices += h.pts.size();
    }
  }
  const Rect w{clip_box.x0 - kWindowMarginUnits, clip_box.y0 - kWindowMarginUnits, clip_box.x1 + kWindowMarginUnits,
               clip_box.y1 + kWindowMarginUnits};
  auto area = [](const Rect& r) { return static_cast<double>(r.x1 - r.x0) * static_cast<double>(r.y1 - r.y0); };
  if (vertices < kWindowMinVertices || area(w) > area(touched) || !reduce_to_window(w, ws.window)) return false;
  // Collinear vertices kept (a flag AddPath() reads): a chord in line with its neighbour
  // stays an edge of its own; drop_slivers() takes out those the whole difference would not
  // have.
  ws.clipper.PreserveCollinear(true);
  ws.clipper.AddPaths(ws.window.reduced, ClipperLib::ptSubject, true);
  return true;
}

// True when every selected section, cut to ws.keep (the box of the material it may meet),
// lies inside `anchor`, a piece already removed from the cell, grown by its band
// (PriorPiece): the clip could remove material within the band of the sections' boundary
// at most. A chain's offset is not tested (false).
bool inside_anchor(const PriorPiece& anchor, const LevelSections& ls, SubtractWorkspace& ws) {
  for (std::uint32_t k : ws.selected) {  // the boxes first: a batch's sections reach far beyond one piece
    if (ls.chain[k] != kNoChain) return false;
    const Rect& b = ls.box[k];
    const Rect part{std::max(b.x0, ws.keep.x0), std::max(b.y0, ws.keep.y0), std::min(b.x1, ws.keep.x1),
                    std::min(b.y1, ws.keep.y1)};
    if (!anchor.box_holds(part)) return false;
  }
  for (std::uint32_t k : ws.selected) {
    const Path& path = ls.paths[k];
    const Path* cut = &path;
    if (!contains(ws.keep, ls.box[k])) {
      cut_to_rect(path, ws.keep, ws.cut, ws.cut_tmp);
      cut = &ws.cut;
    }
    for (const Point& q : *cut)
      if (!anchor.holds(q)) return false;
  }
  return true;
}

}  // namespace

// The difference of the touched polygons and the selected sections into ws.tree: with the
// polygons reduced to the sections' window where that pays, checked, and done again with the
// whole polygons where the check fails (window_clip.hpp).
void SubtractEngine::run_difference(const Cell& cell, int region, const LevelSections& ls, SubtractShared& sh,
                                    SubtractWorkspace& ws, SubtractStats& stats) const {
  ClipperLib::Clipper& c = ws.clipper;
  c.Clear();
  c.StrictlySimple(s_.spec_.strictly_simple);
  const Rect clip_box = add_clip_paths(region, ls, sh, ws, stats);
  const bool windowed = add_windowed_subjects(cell, clip_box, ws);
  if (!windowed) add_subjects(cell, ws);
  ws.tree.Clear();
  c.Execute(ClipperLib::ctDifference, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  c.PreserveCollinear(false);
  if (!windowed) return;
  if (restore_runs(ws.tree, ws.window)) {
    ++stats.clips_windowed;
    return;
  }
  ++stats.window_fallbacks;
  c.Clear();
  (void)add_clip_paths(region, ls, sh, ws, stats);
  add_subjects(cell, ws);
  ws.tree.Clear();
  c.Execute(ClipperLib::ctDifference, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
}

Rect SubtractEngine::grown_region_rect(int region) const noexcept {
  const Rect rr = s_.region_rect(region);
  const Coord g = static_cast<Coord>(kUnitsPerMm);
  return Rect{rr.x0 - g, rr.y0 - g, rr.x1 + g, rr.y1 + g};
}

// The selected sections as clip paths, each cut down (cut_to_rect()) to ws.keep, the box of
// the material they may meet (material_box()) grown by kKeepMarginUnits: the difference
// depends only on the part of a section that meets the material, which lies strictly inside
// that box, and inside it the cut changes no vertex and no winding number. A joined outline
// runs along a whole pass and a finishing pass mostly over material already removed, so most
// of its edges (its caps over cleared levels, the stretch beyond the material) leave the
// clip. A chain enters as its offset's piece for the region, cut the same way. Returns the
// box of the paths added.
Rect SubtractEngine::add_clip_paths(int region, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                                    SubtractStats& stats) const {
  ClipperLib::Clipper& c = ws.clipper;
  const Rect& keep = ws.keep;
  Rect added;
  auto add = [&](const Path& path, const Rect& box) {
    if (path.size() < kCutSectionVertices || contains(keep, box)) {
      if (c.AddPath(path, ClipperLib::ptClip, true)) added.add(box);
      return;
    }
    cut_to_rect(path, keep, ws.cut, ws.cut_tmp);
    if (ws.cut.size() >= 3 && c.AddPath(ws.cut, ClipperLib::ptClip, true)) added.add(bounds_of(ws.cut));
  };
  for (std::uint32_t k : ws.selected) {
    if (ls.chain[k] != kNoChain) {
      for (const Path& piece : offset_piece(sh, ls.chain[k], region, ws, stats)) add(piece, bounds_of(piece));
    } else {
      add(ls.paths[k], ls.box[k]);
    }
  }
  return added;
}

// Clips one cell with the level's sections. Unless the clip was left out inside the cell's
// anchor, the cell has now had the level's newest anchor removed (LevelAnchors).
CellOutcome SubtractEngine::clip_cell(int region, int level, const LevelSections& ls, SubtractShared& sh,
                                      SubtractWorkspace& ws, SubtractStats& stats) {
  const std::size_t ci = static_cast<std::size_t>(region) * s_.levels_ + level;
  const CellOutcome o = difference_cell(ci, region, ls, sh, ws, stats);
  if (o != kCellInAnchor && ls.anchor != 0) s_.ws_->cell_anchor[ci] = ls.anchor;
  return o;
}

CellOutcome SubtractEngine::difference_cell(std::size_t ci, int region, const LevelSections& ls, SubtractShared& sh,
                                            SubtractWorkspace& ws, SubtractStats& stats) {
  Cell& cell = s_.cells_[ci];
  if (!cell.bbox.intersects(ls.all)) return kCellKept;
  ++stats.cells_tested;
  if (!select_for_cell(cell, ls, ws) || !drop_sections_in_air(cell, ls, ws, stats)) return kCellKept;
  if (material_out_of_reach(cell, ws.touched, ls, ws.selected, ws.reach)) {
    ++stats.cells_out_of_reach;
    return kCellKept;
  }

  // What the sections may cut: the touched polygons within the sections' box.
  Rect reach;
  for (std::uint32_t k : ws.selected) reach.add(ls.box[k]);
  const Rect m = material_box(cell, ws.touched, reach);
  if (m.empty()) {
    ++stats.cells_out_of_reach;
    return kCellKept;
  }
  ws.keep = Rect{m.x0 - kKeepMarginUnits, m.y0 - kKeepMarginUnits, m.x1 + kKeepMarginUnits, m.y1 + kKeepMarginUnits};
  if (const PriorPiece* anchor = ls.anchors->find(s_.ws_->cell_anchor[ci]);
      anchor != nullptr && inside_anchor(*anchor, ls, ws)) {
    ++stats.cells_in_anchor;
    return kCellInAnchor;
  }
  run_difference(cell, region, ls, sh, ws, stats);
  ++stats.cells_clipped;
  ws.fresh.clear();
  append_polygons(ws.tree, ws.fresh);
  keep_in_region(s_.region_rect(region), ws);
  drop_slivers(s_.region_rect(region), ws);
  if (removes_only_noise(cell, ws) || !inherit_move_ids(cell, ls, ws)) return kCellKept;

  replace_touched(cell, ws);
  refresh_cell(cell);
  cell.last_cut = 0;
  for (std::uint32_t k : ws.selected) cell.last_cut = std::max(cell.last_cut, ls.id[k]);
  s_.changed(ci);
  ++stats.cells_changed;
  return kCellChanged;
}

}  // namespace lbr::geom::detail
