// Ear clipping with hole bridging over exact integer predicates. See triangulate.hpp for the
// combinatorial contract; the comments here say why each step keeps it.
#include "mesh/triangulate.hpp"

#include <algorithm>
#include <cstdint>

namespace lbr::mesh {

namespace {

using geom::Point;
__extension__ typedef __int128 i128;  // exact cross products of 31-bit differences

int orient(const Point& a, const Point& b, const Point& c) noexcept {
  const i128 v = static_cast<i128>(b.X - a.X) * (c.Y - a.Y) - static_cast<i128>(b.Y - a.Y) * (c.X - a.X);
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

bool same(const Point& a, const Point& b) noexcept { return a.X == b.X && a.Y == b.Y; }

// Open segments pq and rs cross at a point interior to both, or one passes through an
// interior point of the other (touching counts: the bridge must not graze a vertex).
bool blocks(const Point& p, const Point& q, const Point& r, const Point& s) noexcept {
  if (same(p, r) || same(p, s) || same(q, r) || same(q, s)) return false;
  const int d1 = orient(p, q, r), d2 = orient(p, q, s), d3 = orient(r, s, p), d4 = orient(r, s, q);
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  auto on = [](const Point& a, const Point& b, const Point& x) {
    return std::min(a.X, b.X) <= x.X && x.X <= std::max(a.X, b.X) && std::min(a.Y, b.Y) <= x.Y &&
           x.Y <= std::max(a.Y, b.Y);
  };
  return (d1 == 0 && on(p, q, r)) || (d2 == 0 && on(p, q, s));
}

struct Ring {
  std::vector<TriangulateScratch::Node>& n;
  int unlink(int i) noexcept {
    const int a = n[i].prev, c = n[i].next;
    n[a].next = c;
    n[c].prev = a;
    return c;
  }
};

// Appends a ring as a circular list; drops consecutive duplicates; returns the start node
// (-1 when fewer than 3 distinct points remain) and its leftmost node in `leftmost`.
int add_ring(std::vector<TriangulateScratch::Node>& nodes, const geom::Path& path, bool want_ccw, int& leftmost) {
  const std::size_t first = nodes.size();
  const bool ccw = ClipperLib::Area(path) >= 0.0;
  const std::size_t n = path.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Point& p = (ccw == want_ccw) ? path[k] : path[n - 1 - k];
    if (nodes.size() > first && same(nodes.back().p, p)) continue;
    nodes.push_back({p, -1, -1});
  }
  while (nodes.size() > first + 1 && same(nodes.back().p, nodes[first].p)) nodes.pop_back();
  const std::size_t m = nodes.size() - first;
  if (m < 3) {
    nodes.resize(first);
    return -1;
  }
  leftmost = static_cast<int>(first);
  for (std::size_t k = 0; k < m; ++k) {
    const int i = static_cast<int>(first + k);
    nodes[i].prev = static_cast<int>(first + (k + m - 1) % m);
    nodes[i].next = static_cast<int>(first + (k + 1) % m);
    const Point& p = nodes[i].p;
    const Point& l = nodes[leftmost].p;
    if (p.X < l.X || (p.X == l.X && p.Y < l.Y)) leftmost = i;
  }
  return static_cast<int>(first);
}

// h lies strictly inside the interior angle at node m of a CCW ring.
bool in_cone(const std::vector<TriangulateScratch::Node>& n, int m, const Point& h) noexcept {
  const Point& a = n[n[m].prev].p;
  const Point& b = n[m].p;
  const Point& c = n[n[m].next].p;
  if (orient(a, b, c) >= 0) return orient(a, b, h) > 0 && orient(b, c, h) > 0;
  return orient(a, b, h) > 0 || orient(b, c, h) > 0;
}

using Nodes = std::vector<TriangulateScratch::Node>;

// The merged node nearest to hole vertex hp (to its left) that a bridge from hp reaches
// without crossing or grazing any edge, or -1. `cand` is scratch.
int bridge_target(const Nodes& nodes, const std::vector<std::uint8_t>& merged, const Point& hp,
                  std::vector<std::pair<i128, int>>& cand) {
  cand.clear();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (!merged[i] || nodes[i].p.X > hp.X) continue;
    const i128 dx = nodes[i].p.X - hp.X, dy = nodes[i].p.Y - hp.Y;
    cand.push_back({dx * dx + dy * dy, static_cast<int>(i)});
  }
  std::sort(cand.begin(), cand.end());
  for (const auto& [d2, i] : cand) {
    if (!in_cone(nodes, i, hp)) continue;
    bool ok = true;
    for (std::size_t e = 0; e < nodes.size() && ok; ++e) ok = !blocks(hp, nodes[i].p, nodes[e].p, nodes[nodes[e].next].p);
    if (ok) return i;
  }
  return -1;
}

// Splice hole node h into the ring at node m: m -> h -> (hole) -> h' -> m' -> old m.next.
void splice(Nodes& nodes, std::vector<std::uint8_t>& merged, int m, int h) {
  const int mn = nodes[m].next, hp_prev = nodes[h].prev;
  const int m2 = static_cast<int>(nodes.size());
  nodes.push_back({nodes[m].p, -1, -1});
  const int h2 = static_cast<int>(nodes.size());
  nodes.push_back({nodes[h].p, -1, -1});
  merged.push_back(1);
  merged.push_back(1);
  nodes[m].next = h;
  nodes[h].prev = m;
  nodes[m2].next = mn;
  nodes[mn].prev = m2;
  nodes[h2].next = m2;
  nodes[m2].prev = h2;
  nodes[hp_prev].next = h2;
  nodes[h2].prev = hp_prev;
  for (int k = h;;) {
    merged[k] = 1;
    k = nodes[k].next;
    if (k == h) break;
    if (k == h2) break;
  }
}

// Holes, left to right by their leftmost vertex (`holes`: those nodes): a hole's leftward
// bridge can then only meet the outer ring (nodes before outer_end) or holes already merged
// into it.
void bridge_holes(Nodes& nodes, std::vector<int>& holes, std::size_t outer_end, int start, TriangulateStats& stats) {
  std::sort(holes.begin(), holes.end(), [&](int a, int b) {
    const Point& p = nodes[a].p;
    const Point& q = nodes[b].p;
    return p.X != q.X ? p.X < q.X : p.Y < q.Y;
  });
  std::vector<std::uint8_t> merged(nodes.size(), 0);
  for (std::size_t i = 0; i < outer_end; ++i) merged[i] = 1;
  std::vector<std::pair<i128, int>> cand;
  for (int h : holes) {
    int m = bridge_target(nodes, merged, nodes[h].p, cand);
    if (m < 0) {
      ++stats.forced;  // no clean bridge (input not simple after rounding): take the nearest
      if (cand.empty()) m = start;
      else m = cand.front().second;
    }
    splice(nodes, merged, m, h);
  }
}

// No other ring vertex inside the ear a-b-c (reflex vertices only: a convex one can't be).
bool empty_ear(const Nodes& nodes, int a, int b, int c) noexcept {
  const Point &pa = nodes[a].p, &pb = nodes[b].p, &pc = nodes[c].p;
  for (int k = nodes[c].next; k != a; k = nodes[k].next) {
    const Point& p = nodes[k].p;
    if (same(p, pa) || same(p, pb) || same(p, pc)) continue;
    if (orient(nodes[nodes[k].prev].p, p, nodes[nodes[k].next].p) > 0) continue;  // convex can't be inside
    if (orient(pa, pb, p) >= 0 && orient(pb, pc, p) >= 0 && orient(pc, pa, p) >= 0) return false;
  }
  return true;
}

// Clips the ears of the ring through `start` (count nodes), appending them to `out`.
void clip_ears(Nodes& nodes, int start, int count, std::vector<Triangle2>& out, TriangulateStats& stats) {
  Ring ring{nodes};
  auto emit = [&](int a, int b, int c) {
    out.push_back({nodes[a].p, nodes[b].p, nodes[c].p});
    if (orient(nodes[a].p, nodes[b].p, nodes[c].p) == 0) ++stats.degenerate;
  };
  int ear = start, stop = start, pass = 0;
  while (count > 3) {
    const int a = nodes[ear].prev, c = nodes[ear].next;
    if (same(nodes[ear].p, nodes[c].p)) {  // zero-length edge: not a mesh edge, drop a copy
      ring.unlink(c);
      --count;
      stop = ear;
      continue;
    }
    if (same(nodes[a].p, nodes[c].p)) {  // spike a->ear->a: the two edges cancel
      ring.unlink(ear);
      ring.unlink(c);
      count -= 2;
      ear = stop = a;
      continue;
    }
    const int o = orient(nodes[a].p, nodes[ear].p, nodes[c].p);
    bool clip = false;
    if (pass == 0) clip = o > 0 && empty_ear(nodes, a, ear, c);
    else if (pass == 1) clip = o == 0 || (o > 0 && empty_ear(nodes, a, ear, c));
    else clip = o > 0 || pass >= 3;
    if (clip) {
      if (pass >= 2) ++stats.forced;
      emit(a, ear, c);
      ear = stop = ring.unlink(ear);
      --count;
      pass = std::min(pass, 1);  // forcing was a last resort for one ear only
      continue;
    }
    ear = c;
    if (ear == stop) ++pass;
  }
  if (count == 3) {
    const int a = nodes[ear].prev, c = nodes[ear].next;
    if (!same(nodes[a].p, nodes[c].p) && !same(nodes[a].p, nodes[ear].p) && !same(nodes[ear].p, nodes[c].p))
      emit(a, ear, c);
  }
}

}  // namespace

double triangle_area2(const Point& a, const Point& b, const Point& c) noexcept {
  return static_cast<double>(static_cast<i128>(b.X - a.X) * (c.Y - a.Y) - static_cast<i128>(b.Y - a.Y) * (c.X - a.X));
}

TriangulateStats triangulate(const std::vector<const geom::Path*>& rings, std::vector<Triangle2>& out,
                             TriangulateScratch& scratch) {
  TriangulateStats stats;
  auto& nodes = scratch.nodes;
  nodes.clear();
  if (rings.empty() || rings[0] == nullptr) return stats;
  int left = -1;
  int start = add_ring(nodes, *rings[0], true, left);
  if (start < 0) return stats;
  const std::size_t outer_end = nodes.size();

  std::vector<int>& holes = scratch.hole_start;
  holes.clear();
  for (std::size_t r = 1; r < rings.size(); ++r) {
    if (rings[r] == nullptr) continue;
    int hl = -1;
    if (add_ring(nodes, *rings[r], false, hl) >= 0) holes.push_back(hl);
  }
  bridge_holes(nodes, holes, outer_end, start, stats);

  int count = 0;
  for (int k = start;;) {
    ++count;
    k = nodes[k].next;
    if (k == start) break;
  }
  clip_ears(nodes, start, count, out, stats);
  return stats;
}

std::vector<Triangle2> triangulate(const geom::Paths& rings, TriangulateStats* stats) {
  std::vector<const geom::Path*> r;
  for (const geom::Path& p : rings) r.push_back(&p);
  std::vector<Triangle2> out;
  TriangulateScratch s;
  const TriangulateStats st = triangulate(r, out, s);
  if (stats) *stats = st;
  return out;
}

}  // namespace lbr::mesh
