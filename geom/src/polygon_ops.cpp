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

}  // namespace detail
}  // namespace lbr::geom
