#include "verify/intrusion.hpp"

#include <algorithm>
#include <cmath>

#include "geom/units.hpp"

namespace lbr::verify {

namespace {

geom::Rect rect_of(const geom::Box3& b) {
  geom::Rect r;
  r.add(geom::Point{geom::to_units(b.lo.x), geom::to_units(b.lo.y)});
  r.add(geom::Point{geom::to_units(b.hi.x), geom::to_units(b.hi.y)});
  return r;
}

geom::Rect rect_of(const geom::Paths& paths) {
  geom::Rect r;
  for (const geom::Path& p : paths) r.add(geom::bounds_of(p));
  return r;
}

// One Sutherland–Hodgman pass: the part of `in` on the inner side of the line x = c
// (axis 0) or y = c (axis 1); `keep_greater` picks the side.
void clip_half(const geom::Path& in, int axis, geom::Coord c, bool keep_greater, geom::Path& out) {
  out.clear();
  if (in.empty()) return;
  const auto coord = [axis](const geom::Point& p) { return axis == 0 ? p.X : p.Y; };
  const auto inside = [&](const geom::Point& p) { return keep_greater ? coord(p) >= c : coord(p) <= c; };
  geom::Point prev = in.back();
  for (const geom::Point& cur : in) {
    if (inside(cur) != inside(prev)) {  // the edge crosses the line: add the crossing
      const double t = static_cast<double>(c - coord(prev)) / static_cast<double>(coord(cur) - coord(prev));
      const double ox = static_cast<double>(prev.X) + t * static_cast<double>(cur.X - prev.X);
      const double oy = static_cast<double>(prev.Y) + t * static_cast<double>(cur.Y - prev.Y);
      out.push_back(axis == 0 ? geom::Point{c, std::llround(oy)} : geom::Point{std::llround(ox), c});
    }
    if (inside(cur)) out.push_back(cur);
    prev = cur;
  }
}

// Empties `paths`, keeping their buffers in `spare` (geom::Sweep::section() takes them from
// there), up to a bound: the lathe's rings and the offsets in the plane come with buffers of
// their own, which would otherwise pile up there.
void recycle(geom::Paths& paths, std::vector<geom::Path>& spare) {
  constexpr std::size_t kMaxSpare = 256;
  for (geom::Path& p : paths)
    if (spare.size() < kMaxSpare) spare.push_back(std::move(p));
  paths.clear();
}

// Area of non-overlapping paths [mm²].
double area_mm2(const geom::Paths& paths) {
  double units2 = 0.0;
  for (const geom::Path& p : paths) units2 += ClipperLib::Area(p);
  return geom::area_to_mm2(std::abs(units2));
}

}  // namespace

// A milling sweep, or a turning sweep (and its shadow) over the stock's rectangle.
struct IntrusionProbe::Source {
  const geom::Sweep* mill = nullptr;
  const geom::Sweep* deep = nullptr;  // mill's tool moved inwards by the margin (or none)
  const geom::LatheSweep* lathe = nullptr;
  const geom::LatheSweep* shadow = nullptr;
  geom::Box3 bounds;
  geom::Rect extent;  // turning: the stock's rectangle (kernel units)
};

// The part of contour `p` inside `r` (Sutherland–Hodgman). For a non-convex contour the
// result may hold zero-width bridges along r's sides, but its winding number at every point
// inside r is p's, so the area it shares with a clip polygon inside r is exact. A dense
// finishing cell holds contours of thousands of vertices; the clip then sees a few dozen.
void IntrusionProbe::clip_to_rect(const geom::Path& p, const geom::Rect& r) {
  clip_half(p, 0, r.x0, true, tmp_a_);
  clip_half(tmp_a_, 0, r.x1, false, tmp_b_);
  clip_half(tmp_b_, 1, r.y0, true, tmp_a_);
  clip_half(tmp_a_, 1, r.y1, false, tmp_b_);
  if (tmp_b_.size() >= 3) subject_.push_back(tmp_b_);
}

void IntrusionProbe::regions_under(const geom::LbrSolid& solid, const geom::Rect& r) {
  regions_.clear();
  for (int region = 0; region < solid.regions(); ++region)
    if (solid.region_rect(region).intersects(r)) regions_.push_back(region);
  region_volume_.assign(regions_.size(), 0.0);
}

void IntrusionProbe::cell_subject(const geom::Cell& cell, const geom::Rect& r) {
  subject_.clear();
  for (const geom::Polygon& p : cell.polys) {
    if (!p.bbox.intersects(r)) continue;  // holes lie inside their outer contour
    clip_to_rect(p.outer.pts, r);
    for (const geom::Contour& h : p.holes) clip_to_rect(h.pts, r);
  }
}

double IntrusionProbe::subject_overlap_mm2(const geom::Paths& clip) {
  if (subject_.empty()) return 0.0;
  clipper_.Clear();
  clipper_.AddPaths(subject_, ClipperLib::ptSubject, true);
  clipper_.AddPaths(clip, ClipperLib::ptClip, true);
  result_.clear();
  clipper_.Execute(ClipperLib::ctIntersection, result_, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double units2 = 0.0;
  for (const geom::Path& p : result_) units2 += ClipperLib::Area(p);
  return geom::area_to_mm2(std::abs(units2));
}

// Each convex section polygon moved inwards by the margin (pieces thinner than twice the
// margin vanish).
void IntrusionProbe::shrink_section(double margin_mm) {
  recycle(shrunk_, scratch_.spare);
  geom::Paths piece;
  for (const geom::Path& p : section_) {
    offset_.Clear();
    offset_.AddPath(p, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
    piece.clear();
    offset_.Execute(piece, -margin_mm * geom::kUnitsPerMm);
    for (geom::Path& q : piece) shrunk_.push_back(std::move(q));
  }
}

int IntrusionProbe::top_material_level(const geom::LbrSolid& solid, int from) const {
  for (int level = from; level >= 0; --level)
    for (int region : regions_)
      if (!solid.cell(region, level).bbox.empty()) return level;
  return -1;
}

Intrusion IntrusionProbe::measure(const geom::LbrSolid& solid, const geom::Sweep& sweep, double margin_mm,
                                  bool contact_only, const geom::Sweep* deep) {
  Source src;
  src.mill = &sweep;
  src.deep = deep;
  src.bounds = sweep.bounds();
  return measure_source(solid, src, margin_mm, contact_only);
}

Intrusion IntrusionProbe::measure(const geom::LbrSolid& solid, const geom::LatheSweep& sweep, double margin_mm,
                                  bool contact_only, const geom::LatheSweep* shadow) {
  Source src;
  src.lathe = &sweep;
  src.shadow = shadow;
  src.extent = solid.stock_rect();
  src.bounds.lo = {geom::to_mm(src.extent.x0), geom::to_mm(src.extent.y0), sweep.z_min()};
  src.bounds.hi = {geom::to_mm(src.extent.x1), geom::to_mm(src.extent.y1), sweep.z_max()};
  return measure_source(solid, src, margin_mm, contact_only);
}

// A turning sweep's ring on plane z: {r >= r_min} (external) or {r <= r_max} (internal),
// less its shadow's region on that plane. The ring's polygons are built only where a cell
// may meet it: a holder spans many levels and mostly stays clear of the stock.
bool IntrusionProbe::source_section(const geom::LbrSolid& solid, const Source& src, int level, double z) {
  if (src.mill != nullptr) return src.mill->section(z, section_, scratch_) > 0;
  double lo = 0.0, hi = 0.0;
  if (!src.lathe->interval(z, lo, hi)) return false;
  const bool internal = src.lathe->internal();
  const double tol = src.lathe->chord_tol_mm();
  ring_in_ = internal ? 0.0 : lo;
  ring_out_ = internal ? hi : INFINITY;
  if (!ring_meets_cells(solid, level, tol)) return false;
  double slo = 0.0, shi = 0.0;
  if (src.shadow != nullptr && src.shadow->interval(z, slo, shi)) {
    if (internal) ring_in_ = std::max(ring_in_, shi);  // the insert cuts r <= shi
    else ring_out_ = std::min(ring_out_, slo);         // the insert cuts r >= slo
    if (!ring_meets_cells(solid, level, tol)) return false;
  }
  return geom::LatheSweep::ring(ring_in_, ring_out_, tol, src.extent, section_) > 0;
}

void IntrusionProbe::source_shrunk(const Source& src, double z_mm, double margin_mm) {
  if (src.deep != nullptr) {
    recycle(shrunk_, scratch_.spare);
    (void)src.deep->section(z_mm, shrunk_, scratch_);
    return;
  }
  if (src.mill != nullptr) return shrink_section(margin_mm);
  shrunk_.clear();
  const double in = ring_in_ > 0.0 ? ring_in_ + margin_mm : ring_in_;  // no hole: nothing to move
  (void)geom::LatheSweep::ring(in, ring_out_ - margin_mm, src.lathe->chord_tol_mm(), src.extent, shrunk_);
}

namespace {

// Distance² from the origin to segment a-b [units²].
double origin_segment_d2(const geom::Point& a, const geom::Point& b) {
  const double ax = static_cast<double>(a.X), ay = static_cast<double>(a.Y);
  const double dx = static_cast<double>(b.X) - ax, dy = static_cast<double>(b.Y) - ay;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0.0 ? std::clamp(-(ax * dx + ay * dy) / len2, 0.0, 1.0) : 0.0;
  const double x = ax + t * dx, y = ay + t * dy;
  return x * x + y * y;
}

// Nearest distance² of a contour's edges to the origin; the farthest of its vertices.
void contour_reach(const geom::Path& c, double& near2, double& far2) {
  for (std::size_t i = 0; i < c.size(); ++i) {
    const geom::Point& q = c[i];
    const double x = static_cast<double>(q.X), y = static_cast<double>(q.Y);
    far2 = std::max(far2, x * x + y * y);
    near2 = std::min(near2, origin_segment_d2(q, c[(i + 1) % c.size()]));
  }
}

}  // namespace

const IntrusionProbe::CellReach& IntrusionProbe::cell_reach(const geom::LbrSolid& solid, int region, int level) {
  if (reach_solid_ != &solid || reach_.size() != static_cast<std::size_t>(solid.regions()) * solid.levels()) {
    reach_solid_ = &solid;
    reach_.assign(static_cast<std::size_t>(solid.regions()) * solid.levels(), CellReach{});
  }
  const geom::Cell& cell = solid.cell(region, level);
  CellReach& c = reach_[static_cast<std::size_t>(region) * solid.levels() + level];
  if (c.area_units2 >= 0.0 && c.version == cell.version && c.area_units2 == cell.area_units2) return c;
  // The farthest point of a polygon from the axis is an outer vertex; the nearest is 0 when
  // the axis lies in the material, else on an edge.
  double near2 = INFINITY, far2 = 0.0;
  bool axis_inside = false;
  const geom::Point origin{0, 0};
  for (const geom::Polygon& p : cell.polys) {
    contour_reach(p.outer.pts, near2, far2);
    double unused = 0.0;
    for (const geom::Contour& h : p.holes) contour_reach(h.pts, near2, unused);
    if (ClipperLib::PointInPolygon(origin, p.outer.pts) == 0) continue;
    axis_inside = axis_inside || std::none_of(p.holes.begin(), p.holes.end(), [&](const geom::Contour& h) {
                    return ClipperLib::PointInPolygon(origin, h.pts) == 1;
                  });
  }
  c.version = cell.version;
  c.area_units2 = cell.area_units2;
  c.near_mm = axis_inside ? 0.0 : std::sqrt(near2) / geom::kUnitsPerMm;
  c.far_mm = std::sqrt(far2) / geom::kUnitsPerMm;
  return c;
}

bool IntrusionProbe::ring_meets_cells(const geom::LbrSolid& solid, int level, double tol) {
  meets_.assign(regions_.size(), 0);
  bool any = false;
  for (std::size_t k = 0; k < regions_.size(); ++k) {
    if (solid.cell(regions_[k], level).bbox.empty()) continue;
    const CellReach& c = cell_reach(solid, regions_[k], level);
    if (std::isfinite(ring_out_) && c.near_mm >= ring_out_ + tol) continue;
    if (ring_in_ > 0.0 && c.far_mm <= ring_in_ - tol) continue;
    meets_[k] = 1;
    any = true;
  }
  return any;
}

Intrusion IntrusionProbe::measure_source(const geom::LbrSolid& solid, const Source& src, double margin_mm,
                                         bool contact_only) {
  Intrusion out;
  const geom::Box3& b = src.bounds;
  const double z_lo = std::max(b.lo.z, solid.z_bottom_mm());
  const double z_hi = std::min(b.hi.z, solid.z_top_mm());
  if (b.empty() || z_lo > z_hi) return out;
  const geom::Rect xy = rect_of(b);
  regions_under(solid, xy);
  if (regions_.empty()) return out;
  // Nothing to meet above the highest material of the regions under the sweep: the shank
  // and holder of a finishing tool mostly stay there, and are then judged without a clip.
  const int highest = top_material_level(solid, solid.level_at(z_hi));
  if (highest < 0) return out;
  double hit_lo = 0.0, hit_hi = 0.0;
  for (int level = solid.level_at(z_lo); level <= highest; ++level) {
    const double z = solid.level_z_mm(level);
    if (z < b.lo.z || z > b.hi.z) continue;
    const bool material = std::any_of(regions_.begin(), regions_.end(),
                                      [&](int region) { return solid.cell(region, level).bbox.intersects(xy); });
    if (!material) continue;
    recycle(section_, scratch_.spare);
    if (!source_section(solid, src, level, z)) continue;
    const geom::Rect sb = rect_of(section_);
    double level_mm3 = 0.0;
    bool shrunk = false;
    for (std::size_t k = 0; k < regions_.size(); ++k) {
      const geom::Cell& cell = solid.cell(regions_[k], level);
      if (!cell.bbox.intersects(sb)) continue;
      if (src.lathe != nullptr && meets_[k] == 0) continue;
      // No clip where the section's box lies in the air (a rapid over cleared levels) or,
      // for one convex section, wholly in the material (the overlap is the section).
      const geom::RectCover cover = geom::cover_of(cell, sb);
      if (cover == geom::RectCover::None) continue;
      const bool whole = cover == geom::RectCover::All && section_.size() == 1;
      if (!whole) cell_subject(cell, sb);
      const double v = (whole ? area_mm2(section_) : subject_overlap_mm2(section_)) * solid.level_thickness_mm(level);
      if (v <= 0.0) continue;
      region_volume_[k] += v;
      level_mm3 += v;
      if (out.deep_mm3 > 0.0) continue;  // a finding already: only the volume is still needed
      if (!shrunk) source_shrunk(src, z, margin_mm), shrunk = true;
      out.deep_mm3 += (whole ? area_mm2(shrunk_) : subject_overlap_mm2(shrunk_)) * solid.level_thickness_mm(level);
    }
    if (level_mm3 <= 0.0) continue;
    const double bottom = solid.level_bottom_mm(level), top = bottom + solid.level_thickness_mm(level);
    if (out.volume_mm3 == 0.0) hit_lo = bottom, hit_hi = top;
    hit_lo = std::min(hit_lo, bottom);
    hit_hi = std::max(hit_hi, top);
    out.volume_mm3 += level_mm3;
    if (contact_only && out.deep_mm3 > 0.0) break;
  }
  if (out.volume_mm3 <= 0.0) return out;
  out.depth_mm = hit_hi - hit_lo;
  const auto most = std::max_element(region_volume_.begin(), region_volume_.end());
  out.region = regions_[static_cast<std::size_t>(most - region_volume_.begin())];
  return out;
}

}  // namespace lbr::verify
