// LbrSolid: construction of the stock, the grid and its queries, cell edits, the public
// subtraction calls (the subtraction itself: subtract_engine.hpp), invariants.
#include "geom/lbr_solid.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "polygon_ops.hpp"

#include "subtract_engine.hpp"

namespace lbr::geom {

namespace {

constexpr int kMaxRegionsPerAxis = 256;
constexpr long kMaxLevels = 200000;
constexpr long kMaxCells = 8000000;
constexpr double kMinCylinderDiameterMm = 0.001;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

bool in_range(double mm) { return std::isfinite(mm) && std::abs(mm) <= kSafeRangeMm; }

}  // namespace

LbrSolid::LbrSolid(const SolidSpec& spec) : LbrSolid(spec, true) {}

LbrSolid::LbrSolid(const SolidSpec& spec, CellsSetLater) : LbrSolid(spec, false) {}

LbrSolid::LbrSolid(const SolidSpec& spec, bool fill) : spec_(spec), ws_(std::make_unique<detail::SubtractWorkspace>()) {
  require(std::isfinite(spec.level_spacing_mm) && spec.level_spacing_mm >= 0.001 && spec.level_spacing_mm <= 1000.0,
          "level spacing must be in [0.001, 1000] mm");
  require(spec.regions_x >= 1 && spec.regions_x <= kMaxRegionsPerAxis && spec.regions_y >= 1 &&
              spec.regions_y <= kMaxRegionsPerAxis,
          "region grid must be between 1x1 and 256x256");
  require(std::isfinite(spec.chord_tol_mm) && spec.chord_tol_mm >= 1e-4 && spec.chord_tol_mm <= 1.0,
          "chord tolerance must be in [0.0001, 1] mm");
  if (spec.shape == SolidSpec::Shape::Box) {
    const BoxStock& b = spec.box;
    for (double v : {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z})
      require(in_range(v), "box stock coordinates must be finite and within ±" + std::to_string(kSafeRangeMm) + " mm");
    require(b.min.x < b.max.x && b.min.y < b.max.y && b.min.z < b.max.z, "box stock needs min < max on every axis");
    z0_ = b.min.z;
    z1_ = b.max.z;
    xy_ = Rect{to_units(b.min.x), to_units(b.min.y), to_units(b.max.x), to_units(b.max.y)};
  } else {
    const CylinderStock& c = spec.cylinder;
    // Below a micrometre the polygonised circle degenerates (radius 0 in kernel units: the
    // vertex radius became NaN, found by fuzz_lbrs).
    require(std::isfinite(c.diameter_mm) && c.diameter_mm >= kMinCylinderDiameterMm,
            "cylinder stock needs a diameter >= 0.001 mm");
    for (double v : {c.center_x_mm - c.diameter_mm, c.center_x_mm + c.diameter_mm, c.center_y_mm - c.diameter_mm,
                     c.center_y_mm + c.diameter_mm, c.z_min_mm, c.z_max_mm})
      require(in_range(v), "cylinder stock must lie within ±" + std::to_string(kSafeRangeMm) + " mm");
    require(c.z_min_mm < c.z_max_mm, "cylinder stock needs z_min < z_max");
    z0_ = c.z_min_mm;
    z1_ = c.z_max_mm;
    const double r = 0.5 * c.diameter_mm;
    xy_ = Rect{to_units(c.center_x_mm - r), to_units(c.center_y_mm - r), to_units(c.center_x_mm + r),
               to_units(c.center_y_mm + r)};
  }
  const double n = level_count(spec);
  require(n >= 1 && n <= kMaxLevels, "stock height / level spacing gives " + std::to_string(static_cast<long>(n)) +
                                         " levels; at most " + std::to_string(kMaxLevels) + " are supported");
  levels_ = static_cast<int>(n);
  require(static_cast<long>(levels_) * regions() <= kMaxCells,
          "levels x regions = " + std::to_string(static_cast<long>(levels_) * regions()) + " cells; at most " +
              std::to_string(kMaxCells) + " are supported");
  init_cells(fill);
}

double LbrSolid::level_count(const SolidSpec& spec) noexcept {
  const bool box = spec.shape == SolidSpec::Shape::Box;
  const double z0 = box ? spec.box.min.z : spec.cylinder.z_min_mm, z1 = box ? spec.box.max.z : spec.cylinder.z_max_mm;
  return std::ceil((z1 - z0) / spec.level_spacing_mm - 1e-9);
}

LbrSolid::~LbrSolid() = default;
std::uint64_t LbrSolid::next_epoch() noexcept {
  static std::atomic<std::uint64_t> counter{0};
  return counter.fetch_add(1, std::memory_order_relaxed) + 1;
}

LbrSolid::LbrSolid(LbrSolid&&) noexcept = default;
LbrSolid& LbrSolid::operator=(LbrSolid&&) noexcept = default;
LbrSolid::LbrSolid(const LbrSolid& o)
    : spec_(o.spec_), levels_(o.levels_), z0_(o.z0_), z1_(o.z1_), xy_(o.xy_), xs_(o.xs_), ys_(o.ys_),
      cells_(o.cells_), dirty_flag_(o.dirty_flag_), versions_(o.versions_), initial_volume_mm3_(o.initial_volume_mm3_),
      ws_(std::make_unique<detail::SubtractWorkspace>()) {}
LbrSolid& LbrSolid::operator=(const LbrSolid& o) {
  if (this != &o) *this = LbrSolid(o);
  return *this;
}

void LbrSolid::update_copy_of(const LbrSolid& o) {
  if (this == &o) return;
  if (!same_grid(o)) {
    *this = o;
    return;
  }
  (void)update_copy_slice(o, 0, cells_.size());
}

bool LbrSolid::same_grid(const LbrSolid& o) const noexcept {
  return levels_ == o.levels_ && xs_ == o.xs_ && ys_ == o.ys_ && cells_.size() == o.cells_.size();
}

std::size_t LbrSolid::update_copy_slice(const LbrSolid& o, std::size_t from, std::size_t max_cells) {
  std::size_t i = from, copied = 0;
  for (; i < cells_.size() && copied < max_cells; ++i) {
    if (versions_[i] == o.versions_[i]) continue;
    cells_[i] = o.cells_[i];
    versions_[i] = o.versions_[i];
    ++copied;
  }
  if (copied > 0) epoch_ = next_epoch();
  if (i < cells_.size()) return i;
  spec_ = o.spec_;
  z0_ = o.z0_;
  z1_ = o.z1_;
  xy_ = o.xy_;
  initial_volume_mm3_ = o.initial_volume_mm3_;
  dirty_flag_ = o.dirty_flag_;
  return i;
}

void LbrSolid::init_cells(bool fill) {
  const int nx = spec_.regions_x, ny = spec_.regions_y;
  xs_.resize(nx + 1);
  ys_.resize(ny + 1);
  for (int i = 0; i <= nx; ++i) xs_[i] = xy_.x0 + (xy_.x1 - xy_.x0) * i / nx;
  for (int j = 0; j <= ny; ++j) ys_[j] = xy_.y0 + (xy_.y1 - xy_.y0) * j / ny;
  cells_.assign(static_cast<std::size_t>(regions()) * levels_, Cell{});
  dirty_flag_.assign(cells_.size(), 0);
  versions_.assign(cells_.size(), 0);
  std::vector<double> region_area(static_cast<std::size_t>(regions()));
  const Path circle = stock_circle();
  Path cut, tmp, wedge;  // stock_polygons' scratch, reused over the regions
  for (int reg = 0; reg < regions(); ++reg) {
    Cell stock;
    stock.polys = stock_polygons(reg, circle, cut, tmp, wedge);
    detail::refresh_cell(stock);
    region_area[static_cast<std::size_t>(reg)] = stock.area_units2;
    for (int l = 0; fill && l < levels_; ++l) cells_[static_cast<std::size_t>(reg) * levels_ + l] = stock;
  }
  // The stock's volume, summed as volume_mm3() sums the filled cells (the same value to the
  // bit): per level the regions' areas in order, times the level's thickness.
  initial_volume_mm3_ = 0.0;
  for (int l = 0; l < levels_; ++l) {
    double a = 0.0;
    for (double r : region_area) a += r;
    initial_volume_mm3_ += area_to_mm2(a) * level_thickness_mm(l);
  }
}

Path LbrSolid::stock_circle() const {
  Path circle;
  if (spec_.shape != SolidSpec::Shape::Cylinder) return circle;
  const CylinderStock& c = spec_.cylinder;
  const double r = 0.5 * c.diameter_mm;
  const int segs = Sweep::circle_segments(r, spec_.chord_tol_mm);
  const double rho = r * Sweep::circle_grow_area(segs);
  for (int k = 0; k < segs; ++k) {
    const double a = 2.0 * std::numbers::pi * k / segs;
    circle.push_back({to_units(c.center_x_mm + rho * std::cos(a)), to_units(c.center_y_mm + rho * std::sin(a))});
  }
  return circle;
}

std::vector<Polygon> LbrSolid::stock_polygons(int reg, const Path& circle, Path& cut, Path& tmp, Path& wedge) const {
  const Rect rr = region_rect(reg);
  std::vector<Polygon> polys;
  if (spec_.shape == SolidSpec::Shape::Box) {
    Polygon p;
    p.outer.pts = detail::rect_path(rr);
    p.bbox = rr;
    polys.push_back(std::move(p));
  } else {
    switch (circle_vs_rect(rr, circle.size())) {
      case CircleCover::Outside:
        break;
      case CircleCover::Inside: {
        Polygon p;
        p.outer.pts = detail::rect_path(rr);
        p.bbox = rr;
        polys.push_back(std::move(p));
        break;
      }
      case CircleCover::Crossed: {
        // Only the part of the outline near the region enters Clipper (cut_to_rect keeps it
        // vertex for vertex inside the region): a 4096-gon per region made a many-region
        // cylinder take seconds to build, and the levels file reader with it (fuzz_lbrs).
        detail::cut_to_rect(circle_near(rr, circle, wedge), rr, cut, tmp);
        ClipperLib::Clipper c;
        c.AddPath(cut, ClipperLib::ptSubject, true);
        c.AddPath(detail::rect_path(rr), ClipperLib::ptClip, true);
        ClipperLib::PolyTree tree;
        c.Execute(ClipperLib::ctIntersection, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
        detail::append_polygons(tree, polys);
        break;
      }
    }
  }
  return polys;
}

LbrSolid::CircleCover LbrSolid::circle_vs_rect(const Rect& rr, std::size_t segs) const noexcept {
  if (rr.x0 >= rr.x1 || rr.y0 >= rr.y1 || segs < 3) return CircleCover::Crossed;  // as Clipper decides
  // stock_circle()'s polygon before rounding has circumradius rho and inradius rho cos(pi/segs);
  // rounding moves each vertex by < 1 unit, so a point 2 units inside the inradius (outside
  // the circumradius) keeps its winding number 1 (0): the region is wholly in (out of) the stock.
  const CylinderStock& c = spec_.cylinder;
  const double r = 0.5 * c.diameter_mm * kUnitsPerMm;
  const double pi_n = std::numbers::pi / static_cast<double>(segs);
  const double rho = r * Sweep::circle_grow_area(static_cast<int>(segs));
  const double cx = c.center_x_mm * kUnitsPerMm, cy = c.center_y_mm * kUnitsPerMm;
  const double x0 = static_cast<double>(rr.x0) - cx, x1 = static_cast<double>(rr.x1) - cx;
  const double y0 = static_cast<double>(rr.y0) - cy, y1 = static_cast<double>(rr.y1) - cy;
  const double fx = std::max(std::abs(x0), std::abs(x1)), fy = std::max(std::abs(y0), std::abs(y1));  // farthest corner
  if (std::hypot(fx, fy) <= rho * std::cos(pi_n) - 2.0) return CircleCover::Inside;
  const double nx = std::max({x0, -x1, 0.0}), ny = std::max({y0, -y1, 0.0});  // nearest point
  if (std::hypot(nx, ny) >= rho + 2.0) return CircleCover::Outside;
  return CircleCover::Crossed;
}

// The part of the polygonised circle that can meet region rr: its vertices from one step
// before the smallest angle of rr's corners to one step after the largest, closed through the
// centre. The circle is star-shaped about its centre, so inside that sector the wedge and the
// circle are the same set, and rr (at least 4 units off the wedge's radial sides) meets both
// alike; cut_to_rect() then walks tens of vertices, not the whole outline per region (a
// many-region cylinder made the levels file reader, fuzz_lbrs, spend 69 % of its time there).
// The whole circle when rr is near the centre or the sector spans a quarter turn or more.
const Path& LbrSolid::circle_near(const Rect& rr, const Path& circle, Path& wedge) const {
  const std::size_t segs = circle.size();
  if (segs < 8) return circle;
  const CylinderStock& c = spec_.cylinder;
  const double cx = c.center_x_mm * kUnitsPerMm, cy = c.center_y_mm * kUnitsPerMm;
  const double x0 = static_cast<double>(rr.x0) - cx, x1 = static_cast<double>(rr.x1) - cx;
  const double y0 = static_cast<double>(rr.y0) - cy, y1 = static_cast<double>(rr.y1) - cy;
  const double step = 2.0 * std::numbers::pi / static_cast<double>(segs);
  const double near = std::hypot(std::max({x0, -x1, 0.0}), std::max({y0, -y1, 0.0}));
  if (near * std::sin(step) < 8.0) return circle;
  const double mid = std::atan2(0.5 * (y0 + y1), 0.5 * (x0 + x1));
  double lo = 0.0, hi = 0.0;
  for (const double x : {x0, x1})
    for (const double y : {y0, y1}) {
      const double d = std::remainder(std::atan2(y, x) - mid, 2.0 * std::numbers::pi);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  const auto k0 = static_cast<long>(std::floor((mid + lo) / step)) - 1;
  const auto k1 = static_cast<long>(std::ceil((mid + hi) / step)) + 1;
  if (static_cast<double>(k1 - k0) * step >= 0.5 * std::numbers::pi) return circle;
  wedge.clear();
  wedge.push_back({to_units(c.center_x_mm), to_units(c.center_y_mm)});
  const auto n = static_cast<long>(segs);
  for (long k = k0; k <= k1; ++k) wedge.push_back(circle[static_cast<std::size_t>(((k % n) + n) % n)]);
  return wedge;
}

double LbrSolid::level_bottom_mm(int level) const noexcept { return z0_ + level * spec_.level_spacing_mm; }

double LbrSolid::level_thickness_mm(int level) const noexcept {
  return std::min(z1_, level_bottom_mm(level + 1)) - level_bottom_mm(level);
}

double LbrSolid::level_z_mm(int level) const noexcept {
  return level_bottom_mm(level) + 0.5 * level_thickness_mm(level);
}

int LbrSolid::level_at(double z_mm) const noexcept {
  const double f = std::floor((z_mm - z0_) / spec_.level_spacing_mm);
  return static_cast<int>(std::clamp(f, 0.0, static_cast<double>(levels_ - 1)));
}

Rect LbrSolid::region_rect(int region) const noexcept {
  const int ix = region % spec_.regions_x, iy = region / spec_.regions_x;
  return Rect{xs_[ix], ys_[iy], xs_[ix + 1], ys_[iy + 1]};
}

double LbrSolid::volume_mm3() const noexcept {
  double v = 0.0;
  for (int l = 0; l < levels_; ++l) v += level_area_mm2(l) * level_thickness_mm(l);
  return v;
}

double LbrSolid::level_area_mm2(int level) const noexcept {
  double a = 0.0;
  for (int r = 0; r < regions(); ++r) a += cell(r, level).area_units2;
  return area_to_mm2(a);
}

Box3 LbrSolid::bounds() const noexcept {
  Box3 b;
  for (int l = 0; l < levels_; ++l) {
    for (int r = 0; r < regions(); ++r) {
      const Cell& c = cell(r, l);
      if (c.bbox.empty()) continue;
      b.add({to_mm(c.bbox.x0), to_mm(c.bbox.y0), level_bottom_mm(l)});
      b.add({to_mm(c.bbox.x1), to_mm(c.bbox.y1), level_bottom_mm(l) + level_thickness_mm(l)});
    }
  }
  return b;
}

std::size_t LbrSolid::polygon_count() const noexcept {
  std::size_t n = 0;
  for (const Cell& c : cells_) n += c.polys.size();
  return n;
}

std::size_t LbrSolid::contour_count() const noexcept {
  std::size_t n = 0;
  for (const Cell& c : cells_)
    for (const Polygon& p : c.polys) n += 1 + p.holes.size();
  return n;
}

std::size_t LbrSolid::vertex_count() const noexcept {
  std::size_t n = 0;
  for (const Cell& c : cells_)
    for (const Polygon& p : c.polys) {
      n += p.outer.pts.size();
      for (const Contour& h : p.holes) n += h.pts.size();
    }
  return n;
}

std::vector<std::uint32_t> LbrSolid::dirty_cells() const {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < dirty_flag_.size(); ++i)
    if (dirty_flag_[i]) out.push_back(static_cast<std::uint32_t>(i));
  return out;
}

std::size_t LbrSolid::dirty_count() const noexcept {
  return static_cast<std::size_t>(std::count(dirty_flag_.begin(), dirty_flag_.end(), std::uint8_t{1}));
}

void LbrSolid::clear_dirty() noexcept { std::fill(dirty_flag_.begin(), dirty_flag_.end(), std::uint8_t{0}); }

void LbrSolid::set_cell(int region, int level, std::vector<Polygon> polys, MoveId last_cut) {
  const std::size_t i = static_cast<std::size_t>(region) * levels_ + level;
  Cell& c = cells_[i];
  c.polys = std::move(polys);
  c.last_cut = last_cut;
  for (Polygon& p : c.polys) p.bbox = bounds_of(p.outer.pts);
  detail::refresh_cell(c);
  changed(i);
  epoch_ = next_epoch();
}

SubtractStats LbrSolid::subtract(std::span<const SweepRef> batch) { return detail::SubtractEngine(*this).subtract(batch, *ws_); }

SubtractStats LbrSolid::subtract_solid(const LbrSolid& other, MoveId id) {
  SubtractStats stats;
  detail::SubtractWorkspace& ws = *ws_;
  Paths clip;
  for (int l = 0; l < levels_; ++l) {
    const double z = level_z_mm(l);
    if (z < other.z0_ || z > other.z1_) continue;
    const int ol = other.level_at(z);
    clip.clear();
    Rect cb;
    for (int r = 0; r < other.regions(); ++r) {
      const Cell& oc = other.cell(r, ol);
      flatten(oc, clip);
      cb.add(oc.bbox);
    }
    if (clip.empty()) continue;
    stats.sections += clip.size();
    for (int reg = 0; reg < regions(); ++reg) {
      const std::size_t ci = static_cast<std::size_t>(reg) * levels_ + l;
      Cell& cell = cells_[ci];
      if (!cell.bbox.intersects(cb)) continue;
      ++stats.cells_tested;
      ClipperLib::Clipper& c = ws.clipper;
      c.Clear();
      c.StrictlySimple(spec_.strictly_simple);
      Paths subject;
      flatten(cell, subject);
      c.AddPaths(subject, ClipperLib::ptSubject, true);
      c.AddPaths(clip, ClipperLib::ptClip, true);
      ws.tree.Clear();
      c.Execute(ClipperLib::ctDifference, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      ++stats.cells_clipped;
      ws.fresh.clear();
      detail::append_polygons(ws.tree, ws.fresh);
      for (Polygon& p : ws.fresh) {
        p.outer.cut_by = id;
        for (Contour& h : p.holes) h.cut_by = id;
      }
      cell.polys.swap(ws.fresh);
      detail::refresh_cell(cell);
      cell.last_cut = id;
      changed(ci);
      ++stats.cells_changed;
    }
  }
  return stats;
}

std::string LbrSolid::check_invariants() const {
  std::ostringstream e;
  for (int reg = 0; reg < regions(); ++reg) {
    const Rect rr = region_rect(reg);
    for (int l = 0; l < levels_; ++l) {
      const Cell& c = cell(reg, l);
      double sum = 0.0;
      Paths all;
      for (std::size_t pi = 0; pi < c.polys.size(); ++pi) {
        const Polygon& p = c.polys[pi];
        auto where = [&] { return "region " + std::to_string(reg) + " level " + std::to_string(l) + " polygon " + std::to_string(pi); };
        if (p.outer.pts.size() < 3) return where() + ": outer contour has fewer than 3 vertices";
        if (ClipperLib::Area(p.outer.pts) <= 0.0) return where() + ": outer contour is not counter-clockwise";
        if (!(p.bbox == bounds_of(p.outer.pts))) return where() + ": stale bounding box";
        for (const Contour& h : p.holes)
          if (ClipperLib::Area(h.pts) >= 0.0) return where() + ": hole is not clockwise";
        for (const Point& q : p.outer.pts)
          if (q.X < rr.x0 || q.X > rr.x1 || q.Y < rr.y0 || q.Y > rr.y1) return where() + ": vertex outside its region";
        // A simple contour is its own simplification, with the same area.
        auto simple = [](const Path& path) {
          Paths out;
          ClipperLib::SimplifyPolygon(path, out, ClipperLib::pftNonZero);
          double a = 0.0;
          for (const Path& q : out) a += std::abs(ClipperLib::Area(q));
          return std::abs(a - std::abs(ClipperLib::Area(path))) <= 1.0;
        };
        if (!simple(p.outer.pts)) return where() + ": outer contour self-intersects";
        for (const Contour& h : p.holes)
          if (!simple(h.pts)) return where() + ": hole self-intersects";
        all.push_back(p.outer.pts);
        sum += ClipperLib::Area(p.outer.pts);
        for (const Contour& h : p.holes) {
          all.push_back(h.pts);
          sum += ClipperLib::Area(h.pts);
        }
      }
      if (all.empty()) continue;
      // Non-overlap: the union's area equals the sum of the polygons' areas. Holes outside
      // their outer contour would make the two differ as well.
      ClipperLib::Clipper u;
      u.AddPaths(all, ClipperLib::ptSubject, true);
      Paths un;
      u.Execute(ClipperLib::ctUnion, un, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      double ua = 0.0;
      for (const Path& q : un) ua += ClipperLib::Area(q);
      if (std::abs(ua - sum) > 1.0 + 1e-9 * std::abs(sum))
        return "region " + std::to_string(reg) + " level " + std::to_string(l) + ": polygons overlap (union area " +
               std::to_string(ua) + " != sum " + std::to_string(sum) + ")";
      if (std::abs(sum - c.area_units2) > 1.0 + 1e-9 * std::abs(sum))
        return "region " + std::to_string(reg) + " level " + std::to_string(l) + ": stale cached area";
    }
  }
  return {};
}

}  // namespace lbr::geom
