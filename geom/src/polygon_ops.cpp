#include "polygon_ops.hpp"

#include <cmath>

namespace lbr::geom {

double signed_area(const Path& p) noexcept { return ClipperLib::Area(p); }

void flatten(const Cell& cell, Paths& out) {
  for (const Polygon& poly : cell.polys) {
    out.push_back(poly.outer.pts);
    for (const Contour& h : poly.holes) out.push_back(h.pts);
  }
}

namespace detail {

bool same_cycle(const Path& a, const Path& b) noexcept {
  const std::size_t n = a.size();
  if (n != b.size() || n == 0) return false;
  std::size_t off = 0;
  while (off < n && !(b[off] == a[0])) ++off;
  if (off == n) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(a[i] == b[(i + off) % n])) return false;
  }
  return true;
}

void append_polygons(const ClipperLib::PolyTree& tree, std::vector<Polygon>& out) {
  // Outer contours are the even-depth nodes; their children are holes, whose children are
  // again outer contours (islands inside holes).
  std::vector<const ClipperLib::PolyNode*> stack;
  for (const ClipperLib::PolyNode* n : tree.Childs) stack.push_back(n);
  while (!stack.empty()) {
    const ClipperLib::PolyNode* node = stack.back();
    stack.pop_back();
    Polygon poly;
    poly.outer.pts = node->Contour;
    poly.bbox = bounds_of(poly.outer.pts);
    for (const ClipperLib::PolyNode* hole : node->Childs) {
      poly.holes.push_back(Contour{hole->Contour, 0});
      for (const ClipperLib::PolyNode* island : hole->Childs) stack.push_back(island);
    }
    out.push_back(std::move(poly));
  }
}

double perimeter(const Path& p) noexcept {
  double l = 0.0;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    l += std::hypot(static_cast<double>(p[i].X - p[j].X), static_cast<double>(p[i].Y - p[j].Y));
  return l;
}

void refresh_cell(Cell& cell) noexcept {
  cell.bbox = Rect{};
  cell.area_units2 = 0.0;
  for (const Polygon& p : cell.polys) {
    cell.bbox.add(p.bbox);
    cell.area_units2 += ClipperLib::Area(p.outer.pts);
    for (const Contour& h : p.holes) cell.area_units2 += ClipperLib::Area(h.pts);
  }
}

namespace {

// One Sutherland-Hodgman pass: keeps the part of closed path `in` where inside(p) holds,
// with the crossing points computed by cross(a, b) (on the boundary line).
template <class Inside, class Cross>
void clip_pass(const Path& in, Path& out, Inside inside, Cross cross) {
  out.clear();
  const std::size_t n = in.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point& a = in[(i + n - 1) % n];
    const Point& b = in[i];
    const bool ia = inside(a), ib = inside(b);
    if (ib) {
      if (!ia) out.push_back(cross(a, b));
      out.push_back(b);
    } else if (ia) {
      out.push_back(cross(a, b));
    }
  }
}

// The point of segment a-b at coordinate v of the axis given by member m (the other axis
// interpolated and rounded to the unit grid).
Coord lerp_at(Coord a_m, Coord a_o, Coord b_m, Coord b_o, Coord v) noexcept {
  const double t = static_cast<double>(v - a_m) / static_cast<double>(b_m - a_m);
  return static_cast<Coord>(std::llround(static_cast<double>(a_o) + t * static_cast<double>(b_o - a_o)));
}

}  // namespace

void cut_to_rect(const Path& in, const Rect& r, Path& out, Path& tmp) {
  auto at_x = [](Coord x) {
    return [x](const Point& a, const Point& b) { return Point{x, lerp_at(a.X, a.Y, b.X, b.Y, x)}; };
  };
  auto at_y = [](Coord y) {
    return [y](const Point& a, const Point& b) { return Point{lerp_at(a.Y, a.X, b.Y, b.X, y), y}; };
  };
  clip_pass(in, tmp, [&](const Point& p) { return p.X >= r.x0; }, at_x(r.x0));
  clip_pass(tmp, out, [&](const Point& p) { return p.X <= r.x1; }, at_x(r.x1));
  clip_pass(out, tmp, [&](const Point& p) { return p.Y >= r.y0; }, at_y(r.y0));
  clip_pass(tmp, out, [&](const Point& p) { return p.Y <= r.y1; }, at_y(r.y1));
}

}  // namespace detail
}  // namespace lbr::geom
