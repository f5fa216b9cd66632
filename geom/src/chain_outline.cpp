// The outline of a run of consecutive vertical moves on one level (chain_outline.hpp).
#include "chain_outline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <numbers>

namespace lbr::geom::detail {

namespace {

using P2 = SectionScratch::P2;

// Grid index j lies on the counter-clockwise interval [s, e] of an n-grid.
bool on_arc(int j, int s, int e, int n) noexcept { return (j - s + n) % n <= (e - s + n) % n; }

struct Walker {
  const std::vector<P2>& uc;
  int n;
  std::vector<P2>& buf;
  void vertex(P2 c, double rho, int k) { buf.push_back({c.x + rho * uc[static_cast<std::size_t>(k)].x, c.y + rho * uc[static_cast<std::size_t>(k)].y}); }
  // Disk vertices s, s+1, ..., e (counter-clockwise).
  void arc(P2 c, double rho, int s, int e) {
    for (int k = s;; k = (k + 1) % n) {
      vertex(c, rho, k);
      if (k == e) break;
    }
  }
  // At the disk shared by moves p (ending there) and q (starting there), from vertex a to
  // vertex b: along the disk when a lies on the cap interval [lo, hi] of the other move (the
  // outer side of the turn), else on the inner side by a shallow notch a-m-b
  // (notch_is_exact()), or through the centre c where the notch is not proven.
  void join(const MoveCaps& p, const MoveCaps& q, bool right) {
    const P2 c = p.c1;
    const double rho = p.rho1;
    const int a = right ? p.front_r : q.back_l, b = right ? q.back_r : p.front_l;
    if (along_disk(p, q, right)) {
      arc(c, rho, a, b);
      return;
    }
    vertex(c, rho, a);
    if (!notch_is_exact(p, q)) {
      buf.push_back(c);
    } else if (a != b) {
      notch(c, rho, a, b);
    }
    vertex(c, rho, b);
  }
  // The notch point m of the inner join a-b: from the chord's midpoint towards the centre c
  // by half the chord's length, so that a-m and m-b meet the chord at 45 degrees. (The chord
  // itself is exact too, but it runs almost along both sides it joins, backwards, and
  // Clipper's rounded crossings of such near-collinear edges leave zero-area spikes in the
  // result.) The chord spans at most a quarter turn, so m lies between it and c.
  void notch(P2 c, double rho, int a, int b) {
    const P2 ua = uc[static_cast<std::size_t>(a)], ub = uc[static_cast<std::size_t>(b)];
    const P2 mid{0.5 * (ua.x + ub.x), 0.5 * (ua.y + ub.y)};  // on the unit disk
    const double half = 0.5 * std::hypot(ua.x - ub.x, ua.y - ub.y), dist = std::hypot(mid.x, mid.y);
    const double f = (dist - half) / dist;  // in [0, 1) for a chord of at most a quarter turn
    buf.push_back({c.x + rho * f * mid.x, c.y + rho * f * mid.y});
  }
  // The join on this side goes along the disk (see join()).
  bool along_disk(const MoveCaps& p, const MoveCaps& q, bool right) const {
    return right ? on_arc(p.front_r, q.back_l, q.back_r, n) : on_arc(q.back_l, p.front_r, p.front_l, n);
  }
  // Counter-clockwise grid steps from i to j.
  int steps(int i, int j) const { return (j - i + n) % n; }
  // The inner joins at this disk may be notches (docs/lbr-conventions.md, "Joined sections").
  // The outline is the sum of the sections' boundaries minus, at each shared disk D, the
  // closed path G = p's front cap, the left join backwards, q's back cap, the right join
  // backwards (a join along the disk retraces part of a cap, so only the rest of that cap
  // counts). With chords for the inner joins, G's vertices lie on D; where they run once
  // around D counter-clockwise (the grid steps between them sum to n) and no chord spans
  // more than a quarter turn, G is a convex polygon inscribed in D around its centre, and
  // with each chord replaced by its notch (inside the chord's sector) a simple polygon in D:
  // it winds at most once, only inside D, which both sections contain. The sum then winds
  // >= 1 exactly on the union of the sections and 0 elsewhere.
  bool notch_is_exact(const MoveCaps& p, const MoveCaps& q) const {
    const bool right_arc = along_disk(p, q, true), left_arc = along_disk(p, q, false);
    const int q4 = n / 4;
    if (right_arc && left_arc) return false;  // no inner join here
    if (right_arc) {  // G: p's cap fr -> fl, chord to q.back_l, rest of q's cap to p.front_r
      const int chord = steps(p.front_l, q.back_l);
      return chord <= q4 && steps(p.front_r, p.front_l) + chord + steps(q.back_l, p.front_r) == n;
    }
    if (left_arc) {  // G: rest of p's cap fr -> q.back_l, q's cap bl -> br, chord to p.front_r
      const int chord = steps(q.back_r, p.front_r);
      return chord <= q4 && steps(p.front_r, q.back_l) + steps(q.back_l, q.back_r) + chord == n;
    }
    // Both inner: both caps and both chords.
    const int left = steps(p.front_l, q.back_l), right = steps(q.back_r, p.front_r);
    return left <= q4 && right <= q4 &&
           steps(p.front_r, p.front_l) + left + steps(q.back_l, q.back_r) + right == n;
  }
  void side(const std::vector<P2>& pts) { buf.insert(buf.end(), pts.begin(), pts.end()); }
};

// Rounds to kernel units, dropping repeated vertices and vertices collinear with their
// neighbours (exact integer test: the region is unchanged).
bool emit_path(const std::vector<P2>& pts, Paths& out, std::vector<Path>& spare) {
  Path p = SectionScratch::take_spare(spare);
  p.reserve(pts.size());
  auto collinear = [](const Point& a, const Point& b, const Point& c) {
    // |coordinates| < 2^30 (the safe range): the products stay below 2^63.
    return (b.X - a.X) * (c.Y - a.Y) == (b.Y - a.Y) * (c.X - a.X);
  };
  for (const P2& q : pts) {
    const Point ip{to_units(q.x), to_units(q.y)};
    if (!p.empty() && ip == p.back()) continue;
    while (p.size() >= 2 && collinear(p[p.size() - 2], p.back(), ip)) p.pop_back();
    p.push_back(ip);
  }
  // The seam: the last and first vertices against their neighbours.
  while (p.size() >= 3) {
    if (p.back() == p.front()) {
      p.pop_back();
    } else if (collinear(p[p.size() - 2], p.back(), p.front())) {
      p.pop_back();
    } else if (collinear(p.back(), p.front(), p[1])) {
      p.erase(p.begin());
    } else {
      break;
    }
  }
  if (p.size() < 3) {
    spare.push_back(std::move(p));
    return false;
  }
  out.push_back(std::move(p));
  return true;
}

// ---- Tight loops: the outline without its inner chain (docs/lbr-conventions.md, "Joined
// sections", star outline) ----

constexpr double kStarMarginMm = 4.0 * kMmPerUnit;  // beyond the rounding of vertices to units
constexpr std::size_t kStarIntervals = 32;

// The mean of the run's disk centres, when every disk polygon (inscribed radius
// rho·cos(pi/n)) holds it with a margin: then every section contains it.
bool loop_centre(std::span<const MoveCaps> moves, int n, P2& o) {
  double sx = 0.0, sy = 0.0;
  for (const MoveCaps& mc : moves) {
    sx += mc.c0.x;
    sy += mc.c0.y;
  }
  sx += moves.back().c1.x;
  sy += moves.back().c1.y;
  const double count = static_cast<double>(moves.size() + 1);
  o = {sx / count, sy / count};
  const double inscribed = std::cos(std::numbers::pi / n);
  auto holds = [&](P2 c, double rho) { return std::hypot(c.x - o.x, c.y - o.y) < rho * inscribed - kStarMarginMm; };
  for (const MoveCaps& mc : moves)
    if (!holds(mc.c0, mc.rho0) || !holds(mc.c1, mc.rho1)) return false;
  return true;
}

double dist_to_segment(P2 o, P2 a, P2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0.0 ? std::clamp(((o.x - a.x) * dx + (o.y - a.y) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(a.x + t * dx - o.x, a.y + t * dy - o.y);
}

// The chain C = buf[first], buf[first + 1], ... (count vertices, cyclic indices) winds
// counter-clockwise about o edge by edge, and its edges farther than r from o cover every
// direction from o.
bool chain_covers_turn(const std::vector<P2>& buf, std::size_t first, std::size_t count, P2 o, double r) {
  const std::size_t nb = buf.size();
  std::array<std::pair<double, double>, kStarIntervals> iv;
  std::size_t ni = 0;
  double theta = 0.0, run_from = -1.0;
  constexpr double kTurn = 2.0 * std::numbers::pi;
  auto close_run = [&](double to) {  // [run_from, to] split at whole turns
    for (double a = run_from; a < to;) {
      const double base = std::floor(a / kTurn) * kTurn, b = std::min(to, base + kTurn);
      if (ni == kStarIntervals) return false;
      iv[ni++] = {a - base, b - base};
      a = b;
    }
    run_from = -1.0;
    return true;
  };
  for (std::size_t t = 0; t + 1 < count; ++t) {
    const P2 a = buf[(first + t) % nb], b = buf[(first + t + 1) % nb];
    const double ax = a.x - o.x, ay = a.y - o.y, bx = b.x - o.x, by = b.y - o.y;
    const double cross = ax * by - ay * bx, dot = ax * bx + ay * by;
    if (cross < 0.0 || (cross == 0.0 && dot <= 0.0)) return false;  // not counter-clockwise about o
    const bool good = dist_to_segment(o, a, b) > r;
    if (good && run_from < 0.0) run_from = theta;
    if (!good && run_from >= 0.0 && !close_run(theta)) return false;
    theta += std::atan2(cross, dot);
  }
  if (run_from >= 0.0 && !close_run(theta)) return false;
  std::sort(iv.begin(), iv.begin() + static_cast<std::ptrdiff_t>(ni));
  double reach = 0.0;
  for (std::size_t i = 0; i < ni; ++i) {
    if (iv[i].first > reach) return false;
    reach = std::max(reach, iv[i].second);
  }
  return reach >= kTurn;
}

// When the chain of `count` vertices from buf[first] (cyclic) qualifies, the outline may be
// that chain closed through the loop centre o: the rest of the outline lies within r_in of
// o, and the chain covers every direction beyond r_in. Replaces buf by that outline.
bool keep_star_chain(std::vector<P2>& buf, std::size_t first, std::size_t count, P2 o) {
  const std::size_t nb = buf.size();
  double r_in = 0.0;  // the rest, from the chain's last vertex round to its first
  for (std::size_t t = count - 1; t <= nb; ++t) {
    const P2 v = buf[(first + t) % nb];
    r_in = std::max(r_in, std::hypot(v.x - o.x, v.y - o.y));
  }
  if (!chain_covers_turn(buf, first, count, o, r_in + kStarMarginMm)) return false;
  std::rotate(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(first), buf.end());
  buf.resize(count);
  buf.push_back(o);
  return true;
}

}  // namespace

bool append_outline(std::span<const MoveCaps> moves, int n, const std::vector<P2>& uc, std::vector<P2>& buf,
                    Paths& out, std::vector<Path>& spare, bool& star) {
  buf.clear();
  Walker w{uc, n, buf};
  const std::size_t m = moves.size();
  // Back cap of the first move, then the right sides forward.
  w.arc(moves[0].c0, moves[0].rho0, moves[0].back_l, moves[0].back_r);
  const std::size_t back_cap_end = buf.size();
  for (std::size_t k = 0; k < m; ++k) {
    const MoveCaps& a = moves[k];
    w.side(a.right);
    if (k + 1 < m) {
      w.join(a, moves[k + 1], true);
    }
  }
  // Front cap of the last move, then the left sides back.
  const std::size_t front_cap_begin = buf.size();
  w.arc(moves[m - 1].c1, moves[m - 1].rho1, moves[m - 1].front_r, moves[m - 1].front_l);
  const std::size_t front_cap_end = buf.size();
  for (std::size_t k = m; k-- > 0;) {
    const MoveCaps& b = moves[k];
    w.side(b.left);
    if (k > 0) {
      w.join(moves[k - 1], b, false);
    }
  }
  // A tight loop: its outer chain alone, closed through the loop's centre. Counter-clockwise
  // loops keep the back cap, the right sides and the front cap; clockwise ones the front
  // cap, the left sides and the back cap.
  P2 o{};
  star = m >= 2 && loop_centre(moves, n, o) &&
         (keep_star_chain(buf, 0, front_cap_end, o) ||
          keep_star_chain(buf, front_cap_begin, buf.size() - front_cap_begin + back_cap_end, o));
  return emit_path(buf, out, spare);
}

}  // namespace lbr::geom::detail
