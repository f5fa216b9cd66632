// Windowed clips (window_clip.hpp).
#include "window_clip.hpp"

#include <algorithm>

namespace lbr::geom::detail {

namespace {

// Side flags of a point against the window: left, right, below, above (none: inside it).
unsigned side_of(const Point& p, const Rect& w) noexcept {
  return (p.X < w.x0 ? 1u : 0u) | (p.X > w.x1 ? 2u : 0u) | (p.Y < w.y0 ? 4u : 0u) | (p.Y > w.y1 ? 8u : 0u);
}

// Coordinates lie within ±2^30 (kSafeRange): a cross product of differences needs 64 bits
// and one bit more.
__extension__ using Wide = __int128;

// Contours with fewer vertices are kept whole.
constexpr std::size_t kMinReducedContour = 8;

// Reduced vertices times chords above which the loop test costs more than it saves.
constexpr std::size_t kMaxLoopTests = std::size_t{1} << 16;

// Appends the reduced form of contour `ci` to ws.reduced and its chords to ws.chords.
// The walk starts after an edge that meets the window (its ends share no side), so no run
// wraps past the start; a contour with none starts anywhere, and runs are capped at a third
// of it so that it keeps at least three vertices.
void reduce_contour(std::uint32_t ci, const Rect& w, WindowScratch& ws) {
  const Path& p = *ws.src[ci];
  const std::size_t n = p.size();
  Path& out = ws.reduced[ci];
  out.clear();
  if (n < kMinReducedContour) {
    out = p;
    return;
  }
  std::size_t s = 0;
  for (std::size_t i = 0; i < n; ++i)
    if ((side_of(p[i == 0 ? n - 1 : i - 1], w) & side_of(p[i], w)) == 0) {
      s = i;
      break;
    }
  const std::size_t cap = std::max<std::size_t>(2, n / 3);
  std::size_t k = 0;
  while (k < n) {
    const std::size_t i = (s + k) % n;
    unsigned common = side_of(p[i], w);
    Rect box;
    box.add(p[i]);
    std::size_t len = 0;  // edges in the run from i
    while (common != 0 && k + len < n && len < cap) {
      const Point& q = p[(s + k + len + 1) % n];
      const unsigned next = common & side_of(q, w);
      if (next == 0) break;
      common = next;
      box.add(q);
      ++len;
    }
    out.push_back(p[i]);
    if (len >= 2) {
      const std::size_t e = (s + k + len) % n;
      ws.chords.push_back(WindowChord{p[i], p[e], ci, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(len + 1), box});
      k += len;
    } else {
      ++k;
    }
  }
}

// The winding number of the loop (chord c's run closed by the chord) about q; `on` is set
// when q lies on the loop.
int loop_winding(const Point& q, const WindowChord& c, const Path& src, bool& on) noexcept {
  int wn = 0;
  on = false;
  auto edge = [&](const Point& u, const Point& v) {
    const Wide is_left = static_cast<Wide>(v.X - u.X) * (q.Y - u.Y) - static_cast<Wide>(q.X - u.X) * (v.Y - u.Y);
    if (is_left == 0 && std::min(u.X, v.X) <= q.X && q.X <= std::max(u.X, v.X) && std::min(u.Y, v.Y) <= q.Y &&
        q.Y <= std::max(u.Y, v.Y))
      on = true;
    if (u.Y <= q.Y) {
      if (v.Y > q.Y && is_left > 0) ++wn;
    } else if (v.Y <= q.Y && is_left < 0) {
      --wn;
    }
  };
  const std::size_t n = src.size();
  for (std::uint32_t k = 0; k + 1 < c.count && !on; ++k) edge(src[(c.from + k) % n], src[(c.from + k + 1) % n]);
  if (!on) edge(c.b, c.a);
  return wn;
}

// No reduced vertex but a chord's own ends lies in or on that chord's loop.
bool loops_are_empty(const WindowScratch& ws) noexcept {
  for (const WindowChord& c : ws.chords)
    for (const Path& r : ws.reduced)
      for (const Point& q : r) {
        if (q.X < c.box.x0 || q.X > c.box.x1 || q.Y < c.box.y0 || q.Y > c.box.y1 || q == c.a || q == c.b) continue;
        bool on = false;
        if (loop_winding(q, c, *ws.src[c.contour], on) != 0 || on) return false;
      }
  return true;
}

bool chord_before(const WindowChord& c, const Point& p) noexcept { return c.a.X < p.X || (c.a.X == p.X && c.a.Y < p.Y); }

}  // namespace

bool reduce_to_window(const Rect& w, WindowScratch& ws) {
  ws.chords.clear();
  if (ws.reduced.size() < ws.src.size()) ws.reduced.resize(ws.src.size());
  std::size_t before = 0, after = 0;
  for (std::uint32_t ci = 0; ci < ws.src.size(); ++ci) {
    reduce_contour(ci, w, ws);
    before += ws.src[ci]->size();
    after += ws.reduced[ci].size();
  }
  ws.reduced.resize(ws.src.size());
  if (2 * after > before || after * ws.chords.size() > kMaxLoopTests) return false;
  std::sort(ws.chords.begin(), ws.chords.end(), [](const WindowChord& x, const WindowChord& y) { return chord_before(x, y.a); });
  for (std::size_t j = 1; j < ws.chords.size(); ++j)
    if (ws.chords[j].a == ws.chords[j - 1].a) return false;  // touching contours: ambiguous
  return loops_are_empty(ws);
}

bool restore_runs(ClipperLib::PolyTree& tree, WindowScratch& ws) {
  ws.found.assign(ws.chords.size(), 0);
  for (ClipperLib::PolyNode* node = tree.GetFirst(); node != nullptr; node = node->GetNext()) {
    Path& c = node->Contour;
    const std::size_t m = c.size();
    ws.expanded.clear();
    for (std::size_t i = 0; i < m; ++i) {
      ws.expanded.push_back(c[i]);
      const auto it = std::lower_bound(ws.chords.begin(), ws.chords.end(), c[i], chord_before);
      if (it == ws.chords.end() || !(it->a == c[i]) || !(it->b == c[(i + 1) % m])) continue;
      ++ws.found[static_cast<std::size_t>(it - ws.chords.begin())];
      const Path& src = *ws.src[it->contour];
      for (std::uint32_t k = 1; k + 1 < it->count; ++k) ws.expanded.push_back(src[(it->from + k) % src.size()]);
    }
    c.swap(ws.expanded);
  }
  return std::all_of(ws.found.begin(), ws.found.end(), [](std::uint32_t f) { return f == 1; });
}

}  // namespace lbr::geom::detail
