// The union of consecutive convex polygons as the region between their envelopes
// (monotone_union.hpp).
//
// Each polygon is split at its leftmost and rightmost vertices into an upper and a lower
// chain, both piecewise linear functions of x. The union so far is kept the same way, as
// its upper envelope U and its lower envelope L (stored negated, so that both are merged as
// maxima). Adding a polygon with chains u and l keeps the union the region between the
// envelopes when, on every vertical line both reach, the polygon's interval [l, u] meets the
// union's [L, U]; both sides of that test are linear between the chains' vertices, so it is
// checked at the vertices alone.
#include "monotone_union.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

namespace lbr::geom::detail {

namespace {

using P = MonotoneUnion::P;
using Fn = std::span<const P>;  // a piecewise linear function: points with strictly increasing x

// A gap or a jump smaller than this [units] is taken as none: the inputs are on the unit
// grid and the envelopes' crossings are kept unrounded until the end.
constexpr double kSlack = 0.5;

// The value of f at x (within f's domain), from the segment ending at index i (f[i].x >= x).
inline double value_at(Fn f, std::size_t i, double x) noexcept {
  const P& b = f[i];
  if (b.x == x || i == 0) return b.y;
  const P& a = f[i - 1];
  return a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x);
}

// Calls visit(x, fv, gv, f_vertex, g_vertex) for each x of the sorted union of f's and g's
// vertices on the overlap [lo, hi] of their domains, lo and hi included; false when the
// domains do not overlap. visit returns false to stop (then so does this).
template <class Visit>
bool walk(Fn f, Fn g, Visit visit) {
  const double lo = std::max(f.front().x, g.front().x), hi = std::min(f.back().x, g.back().x);
  if (lo > hi) return false;
  auto first_at = [lo](Fn h) {
    return static_cast<std::size_t>(std::lower_bound(h.begin(), h.end(), lo, [](const P& p, double x) { return p.x < x; }) - h.begin());
  };
  std::size_t i = first_at(f), j = first_at(g);
  double x = lo;
  for (;;) {
    const bool fv = f[i].x == x, gv = g[j].x == x;
    if (!visit(x, value_at(f, i, x), value_at(g, j, x), fv, gv)) return false;
    if (x >= hi) return true;
    if (fv) ++i;
    if (gv) ++j;
    x = std::min({f[i].x, g[j].x, hi});
  }
}

// f + g >= 0 wherever both are defined (and they overlap).
bool sum_nonneg(Fn f, Fn g) {
  return walk(f, g, [](double, double fv, double gv, bool, bool) { return fv + gv >= -kSlack; });
}

// out = max(a, b) over the union of their domains, which overlap. False when the maximum
// jumps where one of them begins or ends inside the other's domain (it would need a vertical
// edge there).
bool merge_max(Fn a_in, Fn b_in, std::vector<P>& out) {
  const bool a_first = a_in.front().x <= b_in.front().x;
  const Fn a = a_first ? a_in : b_in;  // the one that begins first
  const Fn b = a_first ? b_in : a_in;
  out.clear();
  for (const P& p : a) {
    if (p.x >= b.front().x) break;
    out.push_back(p);
  }
  const double lo = b.front().x, hi = std::min(a.back().x, b.back().x);
  const bool a_before = a.front().x < lo;
  double px = 0.0, pa = 0.0, pd = 0.0;
  bool first = true;
  auto push = [&](P p) {
    if (out.empty() || p.x > out.back().x) out.push_back(p);
    else if (p.x == out.back().x) out.back().y = std::max(out.back().y, p.y);
  };
  const bool ok = walk(a, b, [&](double x, double fa, double fb, bool va, bool vb) {
    const double d = fa - fb;
    if (first) {
      first = false;
      if (a_before && d < -kSlack) return false;  // b begins above a
    } else if ((pd > 0.0 && d < 0.0) || (pd < 0.0 && d > 0.0)) {
      const double cx = px + (x - px) * pd / (pd - d);
      if (cx > px && cx < x) push({cx, pa + (fa - pa) * (cx - px) / (x - px)});
    }
    if (x == hi && a.back().x != b.back().x) {
      // One of them ends here inside the other's domain: it must not lie above it.
      const bool a_ends = a.back().x == hi;
      if ((a_ends ? -d : d) < -kSlack) return false;
    }
    if ((va && fa >= fb) || (vb && fb >= fa)) push({x, std::max(fa, fb)});
    px = x, pa = fa, pd = d;
    return true;
  });
  if (!ok) return false;
  const Fn rest = a.back().x > b.back().x ? a : b;
  for (const P& p : rest)
    if (p.x > hi) out.push_back(p);
  return true;
}

// Where the merge of f with g (which begins no earlier than f) starts: the last vertex of
// f before g's domain, or f's first. f's vertices before it stay as they are.
std::size_t tail_start(Fn f, Fn g) noexcept {
  if (!(g.front().x > f.front().x)) return 0;
  const auto it = std::lower_bound(f.begin(), f.end(), g.front().x, [](const P& p, double x) { return p.x < x; });
  return static_cast<std::size_t>(it - f.begin()) - 1;
}

// The part of chain c from the last x at or before which c lies nowhere above the previous
// polygon's chain p (c itself when it begins before p or above it), written to `buf` when it
// starts between two of c's vertices. The envelope is no lower than p on p's domain, so
// max(envelope, c) is the envelope up to there.
Fn beyond_previous(Fn c, Fn p, std::vector<P>& buf) {
  if (c.front().x < p.front().x || c.front().x > p.back().x) return c;
  double start = c.front().x;
  walk(c, p, [&](double x, double cv, double pv, bool, bool) {
    if (cv > pv) return false;
    start = x;
    return true;
  });
  if (start == c.front().x) return c;
  const auto it = std::lower_bound(c.begin(), c.end(), start, [](const P& q, double x) { return q.x < x; });
  const std::size_t i = static_cast<std::size_t>(it - c.begin());
  if (c[i].x == start) return c.subspan(i);
  buf.assign(1, P{start, value_at(c, i, start)});
  buf.insert(buf.end(), c.begin() + static_cast<std::ptrdiff_t>(i), c.end());
  return buf;
}

}  // namespace

void MonotoneUnion::begin(double dx, double dy) noexcept {
  // The quarter turn that brings (dx, dy) nearest to +x: (x, y) → (y, −x) per quarter.
  quarter_ = std::abs(dx) >= std::abs(dy) ? (dx >= 0.0 ? 0 : 2) : (dy >= 0.0 ? 1 : 3);
  count_ = 0;
  up_.clear();
  lo_.clear();
}

MonotoneUnion::P MonotoneUnion::to_frame(const Point& q) const noexcept {
  const double x = static_cast<double>(q.X), y = static_cast<double>(q.Y);
  switch (quarter_) {
    case 1: return {y, -x};
    case 2: return {-x, -y};
    case 3: return {-y, x};
    default: return {x, y};
  }
}

Point MonotoneUnion::from_frame(double x, double y) const noexcept {
  const Coord cx = static_cast<Coord>(std::llround(x)), cy = static_cast<Coord>(std::llround(y));
  switch (quarter_) {
    case 1: return {-cy, cx};
    case 2: return {-cx, -cy};
    case 3: return {cy, -cx};
    default: return {cx, cy};
  }
}

// The polygon's chains in the frame: cu_ its upper chain from the leftmost-highest to the
// rightmost-highest vertex, cl_ its lower chain from the leftmost-lowest to the
// rightmost-lowest vertex, negated. False unless the polygon is counter-clockwise with area
// and monotone along x (one run of increasing x, then one of decreasing x, vertical edges
// only at the two ends). A convex polygon is; its upper chain then lies nowhere below its
// lower one.
bool MonotoneUnion::chains_of(const Path& poly) {
  const std::size_t n = poly.size();
  if (n < 3 || ClipperLib::Area(poly) <= 0.0) return false;
  pts_.resize(n);
  std::size_t start = 0;
  for (std::size_t i = 0; i < n; ++i) {
    pts_[i] = to_frame(poly[i]);
    if (pts_[i].x < pts_[start].x || (pts_[i].x == pts_[start].x && pts_[i].y < pts_[start].y)) start = i;
  }
  std::size_t k = start, steps = 0;
  // Advances over the next vertex while `keep` holds for it (duplicates are skipped).
  auto run = [&](auto keep, std::vector<P>* into, double sign) {
    while (steps < n) {
      const std::size_t next = k + 1 == n ? 0 : k + 1;
      const P cur = pts_[k], nxt = pts_[next];
      if (nxt.x == cur.x && nxt.y == cur.y) {
        k = next, ++steps;
        continue;
      }
      if (!keep(cur, nxt)) return;
      if (into != nullptr) into->push_back({nxt.x, sign * nxt.y});
      k = next, ++steps;
    }
  };
  cl_.clear();
  cu_.clear();
  cl_.push_back({pts_[start].x, -pts_[start].y});
  run([](const P& a, const P& b) { return b.x > a.x; }, &cl_, -1.0);
  run([](const P& a, const P& b) { return b.x == a.x; }, nullptr, 1.0);  // the right vertical edge
  cu_.push_back(pts_[k]);
  run([](const P& a, const P& b) { return b.x < a.x; }, &cu_, 1.0);
  run([](const P& a, const P& b) { return b.x == a.x; }, nullptr, 1.0);  // the left vertical edge
  if (steps != n || cl_.size() < 2 || cu_.size() < 2) return false;
  std::reverse(cu_.begin(), cu_.end());
  return true;
}

bool MonotoneUnion::add(const Path& poly) {
  if (!chains_of(poly)) return false;
  if (count_ == 0) {
    up_.assign(cu_.begin(), cu_.end());
    lo_.assign(cl_.begin(), cl_.end());
  } else {
    // The envelopes' vertices from ku and kl on are those the polygon can change.
    const std::size_t ku = tail_start(up_, cu_), kl = tail_start(lo_, cl_);
    if (!meets_union(ku, kl)) return false;
    // Where a chain lies under the previous polygon's, it lies under the envelope (which is
    // no lower), so the merge starts where it first may not.
    const Fn cu = beyond_previous(cu_, pu_, cut_u_), cl = beyond_previous(cl_, pl_, cut_l_);
    const std::size_t mu = tail_start(up_, cu), ml = tail_start(lo_, cl);
    if (!merge_max(Fn(up_).subspan(mu), cu, tmp_) || !merge_max(Fn(lo_).subspan(ml), cl, tmp2_)) return false;
    up_.resize(mu);
    up_.insert(up_.end(), tmp_.begin(), tmp_.end());
    lo_.resize(ml);
    lo_.insert(lo_.end(), tmp2_.begin(), tmp2_.end());
  }
  ++count_;
  pu_.swap(cu_);
  pl_.swap(cl_);
  return true;
}

// The polygon's interval meets the union's on every line x = const both reach: l <= U and
// L <= u (the envelopes from ku and kl on). Where the union's domain within the polygon's
// lies in the previous polygon's, meeting the previous polygon there is enough (its interval
// lies in the union's), and its chains are shorter than the envelopes.
bool MonotoneUnion::meets_union(std::size_t ku, std::size_t kl) const {
  const double lo = std::max(cu_.front().x, up_.front().x), hi = std::min(cu_.back().x, up_.back().x);
  if (pu_.front().x <= lo && hi <= pu_.back().x) return sum_nonneg(pu_, cl_) && sum_nonneg(cu_, pl_);
  return sum_nonneg(Fn(up_).subspan(ku), cl_) && sum_nonneg(cu_, Fn(lo_).subspan(kl));
}

void MonotoneUnion::write(Path& out) const {
  out.clear();
  auto emit = [&](double x, double y) {
    const Point p = from_frame(x, y);
    if (out.empty() || !(out.back() == p)) out.push_back(p);
  };
  for (const P& p : lo_) emit(p.x, -p.y);
  for (std::size_t i = up_.size(); i-- > 0;) emit(up_[i].x, up_[i].y);
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
}

}  // namespace lbr::geom::detail
