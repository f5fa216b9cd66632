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
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    // Kernel units (|coordinate| < 2^31 on any stock the kernel accepts): no overflow, so
    // not the slower hypot.
    const double dx = static_cast<double>(p[i].X - p[j].X), dy = static_cast<double>(p[i].Y - p[j].Y);
    l += std::sqrt(dx * dx + dy * dy);
  }
  return l;
}

namespace {

// Adds to `box` the part of the edge p -> q inside r (Liang-Barsky), rounded outwards.
void add_edge_in(const Point& p, const Point& q, const Rect& r, Rect& box) noexcept {
  if (std::max(p.X, q.X) < r.x0 || std::min(p.X, q.X) > r.x1 || std::max(p.Y, q.Y) < r.y0 || std::min(p.Y, q.Y) > r.y1)
    return;
  const bool p_in = p.X >= r.x0 && p.X <= r.x1 && p.Y >= r.y0 && p.Y <= r.y1;
  const bool q_in = q.X >= r.x0 && q.X <= r.x1 && q.Y >= r.y0 && q.Y <= r.y1;
  if (p_in && q_in) {
    box.add(p);
    box.add(q);
    return;
  }
  const double dx = static_cast<double>(q.X - p.X), dy = static_cast<double>(q.Y - p.Y);
  double t0 = 0.0, t1 = 1.0;
  auto side = [&](double den, double num) {  // keeps den * t <= num
    if (den == 0.0) return num >= 0.0;
    const double t = num / den;
    if (den > 0.0) t1 = std::min(t1, t);
    else t0 = std::max(t0, t);
    return t0 <= t1;
  };
  const double px = static_cast<double>(p.X), py = static_cast<double>(p.Y);
  if (!side(-dx, px - static_cast<double>(r.x0)) || !side(dx, static_cast<double>(r.x1) - px) ||
      !side(-dy, py - static_cast<double>(r.y0)) || !side(dy, static_cast<double>(r.y1) - py))
    return;
  for (const double t : {t0, t1}) {
    const double x = px + t * dx, y = py + t * dy;
    box.add(Point{std::max(r.x0, static_cast<Coord>(std::floor(x))), std::max(r.y0, static_cast<Coord>(std::floor(y)))});
    box.add(Point{std::min(r.x1, static_cast<Coord>(std::ceil(x))), std::min(r.y1, static_cast<Coord>(std::ceil(y)))});
  }
}

void add_contour_in(const Path& c, const Rect& r, Rect& box) noexcept {
  for (std::size_t i = 0, j = c.size() - 1; i < c.size(); j = i++) add_edge_in(c[j], c[i], r, box);
}

}  // namespace

Rect material_box(const Cell& cell, std::span<const std::uint32_t> touched, const Rect& r) noexcept {
  Rect box;
  if (r.empty()) return box;
  const Point corners[4] = {{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}};
  bool in[4] = {false, false, false, false};
  for (std::uint32_t t : touched) {
    const Polygon& poly = cell.polys[t];
    if (!poly.bbox.intersects(r)) continue;
    add_contour_in(poly.outer.pts, r, box);
    for (const Contour& h : poly.holes) add_contour_in(h.pts, r, box);
    for (int k = 0; k < 4; ++k) {
      const Point& c = corners[k];
      if (in[k] || c.X < poly.bbox.x0 || c.X > poly.bbox.x1 || c.Y < poly.bbox.y0 || c.Y > poly.bbox.y1) continue;
      if (ClipperLib::PointInPolygon(c, poly.outer.pts) == 0) continue;
      in[k] = std::none_of(poly.holes.begin(), poly.holes.end(),
                           [&](const Contour& h) { return ClipperLib::PointInPolygon(c, h.pts) == 1; });
    }
  }
  for (int k = 0; k < 4; ++k)
    if (in[k]) box.add(corners[k]);
  return box;
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
  // The k-th vertex from `start` (k < n), without a division per vertex.
  auto at = [&](std::size_t k) -> const Point& { return in[start + k < n ? start + k : start + k - n]; };
  for (std::size_t k = 0; k < n;) {
    const Point& p = at(k);
    if (inside(p)) {
      out.push_back(p);
      ++k;
      continue;
    }
    std::size_t e = k;
    while (e + 1 < n && !inside(at(e + 1))) ++e;
    const Point& first = p;
    const Point& last = at(e);
    out.push_back(first);
    if (e - k >= 2) {
      out.push_back(project(first));
      out.push_back(project(last));
    } else if (e > k) {
      out.push_back(at(k + 1));
    }
    if (e - k >= 2) out.push_back(last);
    k = e + 1;
  }
}

}  // namespace

namespace {

// The v coordinate at u of the segment (pu, pv)-(qu, pv), pu != qu, rounded half away from
// zero; the endpoints are ordered first, so both directions give the same value.
Coord v_at(Coord pu, Coord pv, Coord qu, Coord qv, Coord u) noexcept {
  if (qu < pu || (qu == pu && qv < pv)) {
    std::swap(pu, qu);
    std::swap(pv, qv);
  }
  const Coord num = (qv - pv) * (u - pu), den = qu - pu;  // |num| < 2^62 for coordinates < 2^31
  const Coord q = num >= 0 ? (2 * num + den) / (2 * den) : -((-2 * num + den) / (2 * den));
  return pv + q;
}

// The lines strictly between a and b in the order the edge a -> b meets them: [first, last)
// walked with `step` (+1 or -1) from index `first`.
struct LineWalk {
  std::ptrdiff_t i = 0, end = 0, step = 1;
  [[nodiscard]] bool more() const noexcept { return i != end; }
};

LineWalk walk(std::span<const Coord> lines, Coord a, Coord b) noexcept {
  const auto lo = std::upper_bound(lines.begin(), lines.end(), std::min(a, b)) - lines.begin();
  const auto hi = std::lower_bound(lines.begin(), lines.end(), std::max(a, b)) - lines.begin();
  if (lo >= hi) return LineWalk{0, 0, 1};
  return a < b ? LineWalk{lo, hi, 1} : LineWalk{hi - 1, lo - 1, -1};
}

// Appends the crossings of the edge a -> b with the lines, in order along the edge (the
// x lines' and the y lines' merged by their parameter), without repeating a point.
void append_crossings(const Point& a, const Point& b, std::span<const Coord> xs, std::span<const Coord> ys, Path& out) {
  LineWalk wx = walk(xs, a.X, b.X), wy = walk(ys, a.Y, b.Y);
  const double dx = static_cast<double>(b.X - a.X), dy = static_cast<double>(b.Y - a.Y);
  auto push = [&](const Point& p) {
    if (out.empty() || !(out.back() == p)) out.push_back(p);
  };
  while (wx.more() || wy.more()) {
    const double tx = wx.more() ? static_cast<double>(xs[static_cast<std::size_t>(wx.i)] - a.X) / dx : 2.0;
    const double ty = wy.more() ? static_cast<double>(ys[static_cast<std::size_t>(wy.i)] - a.Y) / dy : 2.0;
    if (tx <= ty) {
      const Coord x = xs[static_cast<std::size_t>(wx.i)];
      push(Point{x, v_at(a.X, a.Y, b.X, b.Y, x)});
      wx.i += wx.step;
    } else {
      const Coord y = ys[static_cast<std::size_t>(wy.i)];
      push(Point{v_at(a.Y, a.X, b.Y, b.X, y), y});
      wy.i += wy.step;
    }
  }
}

// The lines strictly between lo and hi.
std::span<const Coord> lines_between(std::span<const Coord> lines, Coord lo, Coord hi) noexcept {
  const auto first = std::upper_bound(lines.begin(), lines.end(), lo);
  const auto last = std::lower_bound(first, lines.end(), hi);
  return {first, last};
}

// Some line of a path's few (lines_between()) lies strictly between a and b.
bool edge_spans(std::span<const Coord> lines, Coord a, Coord b) noexcept {
  const Coord lo = std::min(a, b), hi = std::max(a, b);
  for (const Coord l : lines)
    if (lo < l && l < hi) return true;
  return false;
}

}  // namespace

void split_at_lines(Path& path, std::span<const Coord> xs, std::span<const Coord> ys, Path& tmp) {
  if (path.size() < 2) return;
  const Rect box = bounds_of(path);
  // Only the lines inside the path's box can lie strictly between an edge's ends: each edge
  // looks at those (mostly one) instead of searching all the borders.
  const std::span<const Coord> in_x = lines_between(xs, box.x0, box.x1), in_y = lines_between(ys, box.y0, box.y1);
  if (in_x.empty() && in_y.empty()) return;
  tmp.clear();
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Point& a = path[i];
    const Point& b = path[i + 1 < path.size() ? i + 1 : 0];
    tmp.push_back(a);
    if (edge_spans(in_x, a.X, b.X) || edge_spans(in_y, a.Y, b.Y)) append_crossings(a, b, in_x, in_y, tmp);
  }
  path.assign(tmp.begin(), tmp.end());  // (not a swap: the scratch buffer keeps its capacity)
}

namespace {

double dist2(const Point& a, const Point& b) noexcept {
  const double dx = static_cast<double>(a.X - b.X), dy = static_cast<double>(a.Y - b.Y);
  return dx * dx + dy * dy;
}

// Squared distance of p from the line through a and b (a != b).
double line_dist2(const Point& p, const Point& a, const Point& b) noexcept {
  const double ux = static_cast<double>(b.X - a.X), uy = static_cast<double>(b.Y - a.Y);
  const double c = ux * static_cast<double>(p.Y - a.Y) - uy * static_cast<double>(p.X - a.X);
  return c * c / (ux * ux + uy * uy);
}

// prev, cur and next are almost on one line: the one of the three that lies between the
// other two (along the dominant axis) is within sqrt(d2) of the line through them. When
// cur is the tip of a thin spike, prev or next is the one between.
bool near_collinear(const Point& prev, const Point& cur, const Point& next, double d2) noexcept {
  const bool by_x = std::abs(prev.X - cur.X) > std::abs(prev.Y - cur.Y);
  auto key = [by_x](const Point& p) { return by_x ? p.X : p.Y; };
  const Coord a = key(prev), b = key(cur), c = key(next);
  if ((a > b) == (a < c) && !(cur == next)) return line_dist2(prev, cur, next) < d2;
  if ((b > a) == (b < c) && !(prev == next)) return line_dist2(cur, prev, next) < d2;
  if (prev == cur) return true;
  return line_dist2(next, prev, cur) < d2;
}

// The contour turns back at cur (the tip of a spike).
bool backtracks(const Point& prev, const Point& cur, const Point& next) noexcept {
  return static_cast<double>(cur.X - prev.X) * static_cast<double>(next.X - cur.X) +
             static_cast<double>(cur.Y - prev.Y) * static_cast<double>(next.Y - cur.Y) <
         0.0;
}

bool on_side(const Point& p, const Rect& r) noexcept { return p.X == r.x0 || p.X == r.x1 || p.Y == r.y0 || p.Y == r.y1; }

// a and b lie on one side of r: the edge a-b runs along the region's border.
bool along_side(const Point& a, const Point& b, const Rect& r) noexcept {
  return (a.X == b.X && (a.X == r.x0 || a.X == r.x1)) || (a.Y == b.Y && (a.Y == r.y0 || a.Y == r.y1));
}

// cur, on a side of r, is the tip of a spike that can go: the contour turns back there
// within sqrt(d2) of a line, and no edge along the border longer than that goes with it
// (that edge is what the neighbour region's contour meets).
bool spike_on_side(const Point& prev, const Point& cur, const Point& next, const Rect& r, double d2) noexcept {
  if (along_side(prev, cur, r) && dist2(prev, cur) >= d2) return false;
  if (along_side(cur, next, r) && dist2(cur, next) >= d2) return false;
  return backtracks(prev, cur, next) && near_collinear(prev, cur, next, d2);
}

}  // namespace

bool remove_slivers(Path& contour, const Rect& keep, double dist, Path& tmp) {
  const double d2 = dist * dist;
  bool changed = false, pass = true;
  while (pass && contour.size() >= 3) {
    pass = false;
    tmp.clear();
    const std::size_t n = contour.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Point& cur = contour[i];
      const Point& prev = tmp.empty() ? contour[n - 1] : tmp.back();
      const Point& next = contour[i + 1 < n ? i + 1 : 0];
      if (on_side(cur, keep) ? spike_on_side(prev, cur, next, keep, d2)
                             : dist2(cur, prev) < d2 || dist2(cur, next) < d2 || near_collinear(prev, cur, next, d2)) {
        pass = changed = true;
        continue;
      }
      tmp.push_back(cur);
    }
    if (pass) contour.assign(tmp.begin(), tmp.end());  // (a swap would hand the cell the scratch buffer's capacity)
  }
  if (contour.size() < 3 && !contour.empty()) {
    contour.clear();
    changed = true;
  }
  return changed;
}

void cut_to_rect(const Path& in, const Rect& r, Path& out, Path& tmp) {
  // Only the sides the path reaches (a pass against a side wholly beyond the path copies it;
  // projections keep the other coordinate, so a later side's test still holds).
  const Rect b = bounds_of(in);
  const bool left = b.x0 <= r.x0, right = b.x1 >= r.x1, below = b.y0 <= r.y0, above = b.y1 >= r.y1;
  const int passes = int{left} + int{right} + int{below} + int{above};
  if (passes == 0) {
    out = in;
    return;
  }
  // Alternate the buffers so that the last pass writes `out`.
  const Path* src = &in;
  Path* dst = passes % 2 == 1 ? &out : &tmp;
  auto pass = [&](auto inside, auto project) {
    clip_pass(*src, *dst, inside, project);
    src = dst;
    dst = dst == &out ? &tmp : &out;
  };
  if (left) pass([&](const Point& p) { return p.X > r.x0; }, [&](const Point& p) { return Point{r.x0, p.Y}; });
  if (right) pass([&](const Point& p) { return p.X < r.x1; }, [&](const Point& p) { return Point{r.x1, p.Y}; });
  if (below) pass([&](const Point& p) { return p.Y > r.y0; }, [&](const Point& p) { return Point{p.X, r.y0}; });
  if (above) pass([&](const Point& p) { return p.Y < r.y1; }, [&](const Point& p) { return Point{p.X, r.y1}; });
}

}  // namespace detail
}  // namespace lbr::geom
