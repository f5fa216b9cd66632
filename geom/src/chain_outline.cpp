// The outline of a run of consecutive vertical moves on one level (chain_outline.hpp).
#include "chain_outline.hpp"

#include <algorithm>
#include <cmath>
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
  Path p;
  if (!spare.empty()) {
    p = std::move(spare.back());
    spare.pop_back();
    p.clear();
  }
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

}  // namespace

bool append_outline(std::span<const MoveCaps> moves, int n, const std::vector<P2>& uc, std::vector<P2>& buf,
                    Paths& out, std::vector<Path>& spare) {
  buf.clear();
  Walker w{uc, n, buf};
  const std::size_t m = moves.size();
  // Back cap of the first move, then the right sides forward.
  w.arc(moves[0].c0, moves[0].rho0, moves[0].back_l, moves[0].back_r);
  for (std::size_t k = 0; k < m; ++k) {
    const MoveCaps& a = moves[k];
    w.side(a.right);
    if (k + 1 < m) {
      w.join(a, moves[k + 1], true);
    }
  }
  // Front cap of the last move, then the left sides back.
  w.arc(moves[m - 1].c1, moves[m - 1].rho1, moves[m - 1].front_r, moves[m - 1].front_l);
  for (std::size_t k = m; k-- > 0;) {
    const MoveCaps& b = moves[k];
    w.side(b.left);
    if (k > 0) {
      w.join(moves[k - 1], b, false);
    }
  }
  return emit_path(buf, out, spare);
}

}  // namespace lbr::geom::detail
