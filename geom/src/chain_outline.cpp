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
  // From vertex a to vertex b of the shared disk: along the disk when a lies on the cap
  // interval [lo, hi] of the other move (the outer side of the turn), else through the
  // centre (the inner side). `direct`: the inner side may take the chord a-b instead.
  void join(P2 c, double rho, int a, int b, int lo, int hi, bool direct) {
    if (on_arc(a, lo, hi, n)) {
      arc(c, rho, a, b);
      return;
    }
    vertex(c, rho, a);
    if (!direct || !chord_is_covered(rho, (a - b + n) % n)) buf.push_back(c);
    vertex(c, rho, b);
  }
  // The inner side of a join between two stadiums (moves k and k+1 at the shared disk,
  // centre c, turning by `steps` grid steps, α): the path through c and the chord a-b
  // differ by the triangle (c, b, a) inside the shared disk. The triangle lies in both
  // stadiums and outside the four caps that the outline replaces by spokes when
  // ρ·sin α < L·cos(2π/n) for both move lengths L: the spoke of a move's far cap has the
  // direction of the near spoke, and the line through the far centre along it separates
  // the far cap from the triangle (docs/lbr-conventions.md, "Joined sections"). The
  // triangle is then covered twice and the chord leaves it covered once. A spoke to c
  // crosses every neighbouring side within ρ of it; the chord crosses none.
  double shorter = 0.0;  // the shorter of the two moves at this join [mm]
  bool chord_is_covered(double rho, int steps) const {
    const double step = 2.0 * std::numbers::pi / n;
    const double alpha = steps * step;
    if (alpha >= 0.25 * std::numbers::pi) return false;
    return rho * std::sin(alpha) < 0.9 * std::cos(step) * shorter;
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
      const MoveCaps& b = moves[k + 1];
      w.shorter = std::min(a.length, b.length);
      w.join(a.c1, a.rho1, a.front_r, b.back_r, b.back_l, b.back_r, a.uniform && b.uniform);
    }
  }
  // Front cap of the last move, then the left sides back.
  w.arc(moves[m - 1].c1, moves[m - 1].rho1, moves[m - 1].front_r, moves[m - 1].front_l);
  for (std::size_t k = m; k-- > 0;) {
    const MoveCaps& b = moves[k];
    w.side(b.left);
    if (k > 0) {
      const MoveCaps& a = moves[k - 1];
      w.shorter = std::min(a.length, b.length);
      w.join(b.c0, b.rho0, b.back_l, a.front_l, a.front_r, a.front_l, a.uniform && b.uniform);
    }
  }
  return emit_path(buf, out, spare);
}

}  // namespace lbr::geom::detail
