// Exact answers from the level polygons: a level's material is its slab × its polygons, so
// a ray meets the material either where it enters a slab over a polygon (a horizontal face)
// or where its XY trace, inside one slab, first crosses a contour (a wall). Kernel units
// as doubles for the crossings; the query point rounded to a unit (0.1 µm) for the
// point-in-polygon tests.
#include "geom/probe.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace lbr::geom {

namespace {

struct P2 {
  double x = 0, y = 0;  // [units]
};

bool contains(const Rect& r, Point p) noexcept { return p.X >= r.x0 && p.X <= r.x1 && p.Y >= r.y0 && p.Y <= r.y1; }

bool in_polygon(const Polygon& poly, Point p) noexcept {
  if (!contains(poly.bbox, p) || ClipperLib::PointInPolygon(p, poly.outer.pts) == 0) return false;
  for (const Contour& h : poly.holes)
    if (ClipperLib::PointInPolygon(p, h.pts) == 1) return false;  // on a hole's edge: material
  return true;
}

Point to_point(double x_mm, double y_mm) noexcept { return {to_units(x_mm), to_units(y_mm)}; }

// Regions whose rectangle holds p (up to 4 at a corner); returns how many.
int regions_at(const LbrSolid& s, Point p, std::array<int, 4>& out) noexcept {
  int n = 0;
  for (int r = 0; r < s.regions() && n < 4; ++r)
    if (contains(s.region_rect(r), p)) out[static_cast<std::size_t>(n++)] = r;
  return n;
}

bool material_in(const LbrSolid& s, int level, Point p, const std::array<int, 4>& regions, int n) noexcept {
  for (int i = 0; i < n; ++i) {
    const Cell& c = s.cell(regions[static_cast<std::size_t>(i)], level);
    if (c.bbox.empty() || !contains(c.bbox, p)) continue;
    for (const Polygon& poly : c.polys)
      if (in_polygon(poly, p)) return true;
  }
  return false;
}

// Smallest u in [0, 1] where segment a→b crosses the closed path `pts` (units); keeps the
// smaller of it and `best`.
void first_crossing(const Path& pts, P2 a, P2 b, double& best) noexcept {
  const double dx = b.x - a.x, dy = b.y - a.y;
  for (std::size_t i = 0, j = pts.size() - 1; i < pts.size(); j = i++) {
    const double ex = static_cast<double>(pts[i].X - pts[j].X), ey = static_cast<double>(pts[i].Y - pts[j].Y);
    const double den = dx * ey - dy * ex;
    if (den == 0.0) continue;  // parallel (or a zero-length trace)
    const double wx = static_cast<double>(pts[j].X) - a.x, wy = static_cast<double>(pts[j].Y) - a.y;
    const double u = (wx * ey - wy * ex) / den, v = (wx * dy - wy * dx) / den;
    if (u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) best = std::min(best, u);
  }
}

// Where the XY trace a→b [mm] of the ray inside level l's slab first meets its material:
// u in [0, 1] along the trace; false when it does not.
bool first_inside(const LbrSolid& s, int l, P2 a_mm, P2 b_mm, double& u) noexcept {
  const P2 a{a_mm.x * kUnitsPerMm, a_mm.y * kUnitsPerMm}, b{b_mm.x * kUnitsPerMm, b_mm.y * kUnitsPerMm};
  const Point pa = to_point(a_mm.x, a_mm.y);
  Rect trace;
  trace.add(Point{static_cast<Coord>(std::floor(std::min(a.x, b.x))) - 1, static_cast<Coord>(std::floor(std::min(a.y, b.y))) - 1});
  trace.add(Point{static_cast<Coord>(std::ceil(std::max(a.x, b.x))) + 1, static_cast<Coord>(std::ceil(std::max(a.y, b.y))) + 1});
  double best = 2.0;
  for (int r = 0; r < s.regions(); ++r) {
    if (!s.region_rect(r).intersects(trace)) continue;
    const Cell& c = s.cell(r, l);
    if (!c.bbox.intersects(trace)) continue;
    for (const Polygon& poly : c.polys) {
      if (!poly.bbox.intersects(trace)) continue;
      if (in_polygon(poly, pa)) {
        u = 0.0;
        return true;
      }
      first_crossing(poly.outer.pts, a, b, best);
      for (const Contour& h : poly.holes) first_crossing(h.pts, a, b, best);
    }
  }
  u = best;
  return best <= 1.0;
}

// Clips [t0, t1] to lo <= o + t·d <= hi on one axis; false when nothing is left.
bool clip_axis(double o, double d, double lo, double hi, double& t0, double& t1) noexcept {
  if (std::abs(d) < 1e-300) return o >= lo && o <= hi;
  double a = (lo - o) / d, b = (hi - o) / d;
  if (a > b) std::swap(a, b);
  t0 = std::max(t0, a);
  t1 = std::min(t1, b);
  return t0 <= t1;
}

}  // namespace

bool material_at(const LbrSolid& s, int level, double x_mm, double y_mm) noexcept {
  if (level < 0 || level >= s.levels()) return false;
  const Point p = to_point(x_mm, y_mm);
  std::array<int, 4> regions{};
  const int n = regions_at(s, p, regions);
  return material_in(s, level, p, regions, n);
}

Column column_at(const LbrSolid& s, double x_mm, double y_mm, double z_max_mm) noexcept {
  Column c;
  const Point p = to_point(x_mm, y_mm);
  std::array<int, 4> regions{};
  const int n = regions_at(s, p, regions);
  if (n == 0) return c;
  for (int l = 0; l < s.levels(); ++l) {
    if (!material_in(s, l, p, regions, n)) continue;
    const double bottom = s.level_bottom_mm(l), top = bottom + s.level_thickness_mm(l);
    c.top_mm = c.material ? std::max(c.top_mm, top) : top;
    c.material = true;
    c.thickness_mm += std::max(0.0, std::min(top, z_max_mm) - bottom);
  }
  return c;
}

RayHit cast_ray(const LbrSolid& s, const Vec3& o, const Vec3& d, double t_min, double t_max) noexcept {
  RayHit h;
  const Rect xy = s.stock_rect();
  if (!clip_axis(o.x, d.x, to_mm(xy.x0), to_mm(xy.x1), t_min, t_max) ||
      !clip_axis(o.y, d.y, to_mm(xy.y0), to_mm(xy.y1), t_min, t_max) ||
      !clip_axis(o.z, d.z, s.z_bottom_mm(), s.z_top_mm(), t_min, t_max) || !std::isfinite(t_max))
    return h;
  const bool flat = std::abs(d.z) < 1e-12;
  auto at = [&](double t) { return o + t * d; };
  // A hit at the start of the range is on a horizontal face only when the range starts on
  // the stock's top; otherwise it starts on a side of the stock or on the caller's limit
  // (a section plane): a vertical face, even at a slab boundary.
  const double t_start = t_min;
  const bool start_on_top = std::abs(at(t_start).z - s.z_top_mm()) < 1e-9;
  const int first = s.level_at(at(t_min).z), last = flat ? first : s.level_at(at(t_max).z);
  const int step = last >= first ? 1 : -1;
  for (int l = first;; l += step) {
    double ta = t_min, tb = t_max;
    const double zb = s.level_bottom_mm(l), zt = zb + s.level_thickness_mm(l);
    if (flat || clip_axis(o.z, d.z, zb, zt, ta, tb)) {
      const Vec3 a = at(ta), b = at(tb);
      double u = 0;
      if (first_inside(s, l, {a.x, a.y}, {b.x, b.y}, u)) {
        h.hit = true;
        h.t = ta + u * (tb - ta);
        h.point = at(h.t);
        h.level = l;
        h.top_face = u == 0.0 && d.z < 0.0 && std::abs(h.point.z - zt) < 1e-6 && (ta > t_start || start_on_top);
        if (h.top_face) h.point.z = zt;  // the face's height, not its rounding along the ray
        return h;
      }
    }
    if (l == last) break;
  }
  return h;
}

}  // namespace lbr::geom
