#include "polygon_ops.hpp"

#include <algorithm>
#include <cmath>

namespace lbr::geom {

namespace {

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

}  // namespace

double signed_area(const Path& p) noexcept { return ClipperLib::Area(p); }

void flatten(const Cell& cell, Paths& out) {
  for (const Polygon& poly : cell.polys) {
    out.push_back(poly.outer.pts);
    for (const Contour& h : poly.holes) out.push_back(h.pts);
  }
}

RectCover cover_of(const Cell& cell, const Rect& r) noexcept {
  const Point centre{r.x0 + (r.x1 - r.x0) / 2, r.y0 + (r.y1 - r.y0) / 2};
  bool inside = false;
  for (const Polygon& poly : cell.polys) {
    if (!poly.bbox.intersects(r)) continue;  // holes lie inside their outer contour
    if (edge_near(poly.outer.pts, r)) return RectCover::Partly;
    for (const Contour& h : poly.holes)
      if (edge_near(h.pts, r)) return RectCover::Partly;
    if (inside || ClipperLib::PointInPolygon(centre, poly.outer.pts) == 0) continue;
    inside = std::none_of(poly.holes.begin(), poly.holes.end(),
                          [&](const Contour& h) { return ClipperLib::PointInPolygon(centre, h.pts) != 0; });
  }
  return inside ? RectCover::All : RectCover::None;
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

// One pass against the half-plane where inside(p) holds: every run of three or more
// consecutive vertices outside it becomes its first vertex, the projections of its first and
// last vertex onto the boundary line (project()), and its last vertex. The edges into and
// out of the run are kept as they are, and what replaces the run lies outside the open
// half-plane, as the run's own edges do (a half-plane is convex): inside it, the path and
// every winding number are unchanged, vertex for vertex, with no rounding.
template <class Inside, class Project>
void clip_pass(const Path& in, Path& out, Inside inside, Project project) {
  out.clear();
  const std::size_t n = in.size();
  std::size_t start = n;
  for (std::size_t i = 0; i < n; ++i)
    if (inside(in[i])) {
      start = i;
      break;
    }
  if (start == n) return;  // wholly outside: no winding inside
  for (std::size_t k = 0; k < n;) {
    const Point& p = in[(start + k) % n];
    if (inside(p)) {
      out.push_back(p);
      ++k;
      continue;
    }
    std::size_t e = k;
    while (e + 1 < n && !inside(in[(start + e + 1) % n])) ++e;
    const Point& first = p;
    const Point& last = in[(start + e) % n];
    out.push_back(first);
    if (e - k >= 2) {
      out.push_back(project(first));
      out.push_back(project(last));
    } else if (e > k) {
      out.push_back(in[(start + k + 1) % n]);
    }
    if (e - k >= 2) out.push_back(last);
    k = e + 1;
  }
}

}  // namespace

void cut_to_rect(const Path& in, const Rect& r, Path& out, Path& tmp) {
  clip_pass(in, tmp, [&](const Point& p) { return p.X > r.x0; }, [&](const Point& p) { return Point{r.x0, p.Y}; });
  clip_pass(tmp, out, [&](const Point& p) { return p.X < r.x1; }, [&](const Point& p) { return Point{r.x1, p.Y}; });
  clip_pass(out, tmp, [&](const Point& p) { return p.Y > r.y0; }, [&](const Point& p) { return Point{p.X, r.y0}; });
  clip_pass(tmp, out, [&](const Point& p) { return p.Y < r.y1; }, [&](const Point& p) { return Point{p.X, r.y1}; });
}

}  // namespace detail
}  // namespace lbr::geom
