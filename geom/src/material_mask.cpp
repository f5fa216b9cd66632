// A cell's material as a conservative raster, and a level's material for the tilted pieces
// (material_mask.hpp).
#include "material_mask.hpp"

#include <algorithm>
#include <cmath>

#include "geom/units.hpp"
#include "subtract_engine.hpp"  // interval_of()

namespace lbr::geom::detail {

namespace {

// The x-range of segment a-b within the band y in [lo, hi] (false when it misses the band).
bool band_range(double ax, double ay, double bx, double by, double lo, double hi, double& xmin, double& xmax) noexcept {
  if ((ay < lo && by < lo) || (ay > hi && by > hi)) return false;
  double t0 = 0.0, t1 = 1.0;
  const double dy = by - ay;
  if (dy != 0.0) {
    double ta = (lo - ay) / dy, tb = (hi - ay) / dy;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  const double xa = ax + t0 * (bx - ax), xb = ax + t1 * (bx - ax);
  xmin = std::min(xa, xb);
  xmax = std::max(xa, xb);
  return true;
}

}  // namespace

double CellMask::px(double x_mm) const noexcept { return (x_mm * kUnitsPerMm - x0_) * sx_; }
double CellMask::py(double y_mm) const noexcept { return (y_mm * kUnitsPerMm - y0_) * sy_; }

int CellMask::column(double v) const noexcept {
  if (!(v >= 0.0)) return 0;  // NaN too
  return v >= nx_ - 1 ? nx_ - 1 : static_cast<int>(v);
}

int CellMask::row(double v) const noexcept {
  if (!(v >= 0.0)) return 0;
  return v >= ny_ - 1 ? ny_ - 1 : static_cast<int>(v);
}

std::uint64_t CellMask::span(int c0, int c1) const noexcept {
  const std::uint64_t upto = c1 >= 63 ? ~std::uint64_t{0} : (std::uint64_t{1} << (c1 + 1)) - 1;
  return upto & ~((std::uint64_t{1} << c0) - 1);
}

// The pixels the edge passes through, row by row (pixel coordinates), widened by kEdgePad.
void CellMask::mark_edge(double ax, double ay, double bx, double by) noexcept {
  const int r0 = row(std::min(ay, by) - kEdgePad), r1 = row(std::max(ay, by) + kEdgePad);
  for (int r = r0; r <= r1; ++r) {
    double xmin = 0.0, xmax = 0.0;
    if (!band_range(ax, ay, bx, by, r - kEdgePad, r + 1 + kEdgePad, xmin, xmax)) continue;
    rows_[static_cast<std::size_t>(r)] |= span(column(xmin - kEdgePad), column(xmax + kEdgePad));
  }
}

// Sets the pixels whose centres lie between pairs of a row's crossings (sorted by row, x).
// Closed contours cross a row an even number of times; a row with an odd count (which
// rounding cannot make, but a caller's broken cell might) is set whole.
void CellMask::fill_rows(std::vector<std::pair<int, double>>& crossings) noexcept {
  std::sort(crossings.begin(), crossings.end());
  std::size_t i = 0;
  while (i < crossings.size()) {
    const int r = crossings[i].first;
    std::size_t j = i;
    while (j < crossings.size() && crossings[j].first == r) ++j;
    if ((j - i) % 2 != 0) rows_[static_cast<std::size_t>(r)] = span(0, nx_ - 1);
    for (std::size_t k = i; k + 1 < j && (j - i) % 2 == 0; k += 2) {
      // Centres c + 0.5 in [x_k, x_k+1].
      const double c0 = std::ceil(crossings[k].second - 0.5), c1 = std::floor(crossings[k + 1].second - 0.5);
      if (c1 < 0.0 || c0 > nx_ - 1 || c0 > c1) continue;
      rows_[static_cast<std::size_t>(r)] |= span(column(c0), column(c1));
    }
    i = j;
  }
}

void CellMask::build(const Cell& cell, const Rect& region, std::vector<std::pair<int, double>>& crossings) {
  misses = !built || cleared ? 0 : static_cast<std::uint8_t>(std::min<int>(misses + 1, kMaxMisses));
  cleared = false;
  version = cell.version;
  built = true;
  x0_ = static_cast<double>(region.x0);
  y0_ = static_cast<double>(region.y0);
  const double wu = std::max(1.0, static_cast<double>(region.x1 - region.x0));
  const double hu = std::max(1.0, static_cast<double>(region.y1 - region.y0));
  auto side = [](double extent) {
    return static_cast<int>(std::clamp(std::ceil(extent / (kPixelMm * kUnitsPerMm)), 1.0, static_cast<double>(kMaxSide)));
  };
  nx_ = side(wu);
  ny_ = side(hu);
  sx_ = nx_ / wu;
  sy_ = ny_ / hu;
  rows_.assign(static_cast<std::size_t>(ny_), std::uint64_t{0});
  crossings.clear();
  auto contour = [&](const Path& pts) {
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Point& a = pts[i];
      const Point& b = pts[i + 1 == n ? 0 : i + 1];
      const double ax = (static_cast<double>(a.X) - x0_) * sx_, ay = (static_cast<double>(a.Y) - y0_) * sy_;
      const double bx = (static_cast<double>(b.X) - x0_) * sx_, by = (static_cast<double>(b.Y) - y0_) * sy_;
      mark_edge(ax, ay, bx, by);
      // Crossings of the row centres y = r + 0.5 with ay <= y < by (or by <= y < ay).
      const double lo = std::min(ay, by), hi = std::max(ay, by);
      const int r0 = std::max(0, static_cast<int>(std::ceil(lo - 0.5)));
      const int r1 = std::min(ny_ - 1, static_cast<int>(std::ceil(hi - 0.5)) - 1);
      for (int r = r0; r <= r1; ++r) {
        const double yc = r + 0.5;
        crossings.emplace_back(r, ax + (yc - ay) * (bx - ax) / (by - ay));
      }
    }
  };
  for (const Polygon& p : cell.polys) {
    contour(p.outer.pts);
    for (const Contour& h : p.holes) contour(h.pts);
  }
  fill_rows(crossings);
}

bool CellMask::may_meet(std::span<const SectionPoint> poly) const noexcept {
  if (poly.size() < 3) return true;
  double ylo = INFINITY, yhi = -INFINITY, xlo = INFINITY, xhi = -INFINITY;
  for (const SectionPoint& q : poly) {
    xlo = std::min(xlo, px(q.x));
    xhi = std::max(xhi, px(q.x));
    ylo = std::min(ylo, py(q.y));
    yhi = std::max(yhi, py(q.y));
  }
  if (xhi < 0.0 || yhi < 0.0 || xlo > nx_ || ylo > ny_) return false;
  const std::uint64_t box = span(column(xlo), column(xhi));
  const int r0 = row(ylo), r1 = row(yhi);
  for (int r = r0; r <= r1; ++r) {
    const std::uint64_t bits = rows_[static_cast<std::size_t>(r)];
    if ((bits & box) == 0) continue;
    // The polygon's own x-range in this row (convex: its clipped edges' ends).
    double xmin = INFINITY, xmax = -INFINITY;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const SectionPoint& a = poly[i];
      const SectionPoint& b = poly[i + 1 == poly.size() ? 0 : i + 1];
      double e0 = 0.0, e1 = 0.0;
      if (!band_range(px(a.x), py(a.y), px(b.x), py(b.y), r, r + 1, e0, e1)) continue;
      xmin = std::min(xmin, e0);
      xmax = std::max(xmax, e1);
    }
    if (xmin > xmax || xmax < 0.0 || xmin > nx_) continue;
    if ((bits & span(column(xmin), column(xmax))) != 0) return true;
  }
  return false;
}

Rect units_box_outward(double xlo, double ylo, double xhi, double yhi) noexcept {
  static constexpr double kFarUnits = 4e18;  // well inside Coord's range
  auto units = [](double mm, bool up) {
    const double u = std::clamp(mm * kUnitsPerMm, -kFarUnits, kFarUnits);
    return static_cast<Coord>(up ? std::ceil(u) : std::floor(u));
  };
  Rect r;
  r.add(Point{units(xlo, false), units(ylo, false)});
  r.add(Point{units(xhi, true), units(yhi, true)});
  return r;
}

RegionRange regions_reached(const std::vector<Coord>& xs, const std::vector<Coord>& ys, const Rect& b) noexcept {
  return RegionRange{interval_of(xs, b.x0 - 1), interval_of(xs, b.x1), interval_of(ys, b.y0 - 1), interval_of(ys, b.y1)};
}

LevelMaterial::LevelMaterial(const LbrSolid& solid, int level, const std::vector<Coord>& xs, const std::vector<Coord>& ys,
                             std::vector<CellMask>& masks, std::vector<std::pair<int, double>>& crossings,
                             const RegionRange& regions) noexcept
    : s_(solid), level_(level), xs_(xs), ys_(ys), masks_(masks), crossings_(crossings) {
  for (int iy = regions.iy0; iy <= regions.iy1; ++iy)
    for (int ix = regions.ix0; ix <= regions.ix1; ++ix) box.add(solid.cell(iy * solid.regions_x() + ix, level).bbox);
}

bool LevelMaterial::may_meet(std::span<const SectionPoint> poly) const {
  if (masks_.size() != s_.cell_count() || poly.empty()) return true;
  // A polygon beyond the kernel's coordinate range (a cap triangle of almost parallel support
  // lines has a far apex), or with a point that is not finite, may meet anything.
  constexpr double kFarMm = 1e9;
  double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
  for (const SectionPoint& q : poly) {
    xlo = std::min(xlo, q.x);
    xhi = std::max(xhi, q.x);
    ylo = std::min(ylo, q.y);
    yhi = std::max(yhi, q.y);
  }
  if (!(xlo >= -kFarMm && xhi <= kFarMm && ylo >= -kFarMm && yhi <= kFarMm)) return true;
  const Rect pb = units_box_outward(xlo, ylo, xhi, yhi);
  if (!pb.intersects(box)) return false;
  const RegionRange rr = regions_reached(xs_, ys_, pb);
  const auto levels = static_cast<std::size_t>(s_.levels());
  for (int iy = rr.iy0; iy <= rr.iy1; ++iy)
    for (int ix = rr.ix0; ix <= rr.ix1; ++ix) {
      const int region = iy * s_.regions_x() + ix;
      const Cell& c = s_.cell(region, level_);
      if (!c.bbox.intersects(pb)) continue;
      CellMask& m = masks_[static_cast<std::size_t>(region) * levels + static_cast<std::size_t>(level_)];
      if (!m.built) m.build(c, s_.region_rect(region), crossings_);
      if (!m.may_meet(poly)) {  // a mask built before later cuts holds more material: still clear
        m.cleared = true;
        continue;
      }
      if (!m.rebuild_due(c.version)) return true;
      m.build(c, s_.region_rect(region), crossings_);
      if (m.may_meet(poly)) return true;
      m.cleared = true;
    }
  return false;
}

}  // namespace lbr::geom::detail
