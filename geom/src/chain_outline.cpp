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
  // outer side of the turn), else on the inner side through the centre, or by the chord a-b
  // when chord_is_covered().
  void join(const MoveCaps& p, const MoveCaps& q, bool right) {
    const P2 c = p.c1;
    const double rho = p.rho1;
    const int a = right ? p.front_r : q.back_l, b = right ? q.back_r : p.front_l;
    const int lo = right ? q.back_l : p.front_r, hi = right ? q.back_r : p.front_l;
    if (on_arc(a, lo, hi, n)) {
      arc(c, rho, a, b);
      return;
    }
    vertex(c, rho, a);
    if (!chord_is_covered(p, q, right)) buf.push_back(c);
    vertex(c, rho, b);
  }
  // The inner side of a join: the path through the centre c and the chord a-b differ by the
  // triangle T = (c, b, a) inside the shared disk, which both sections contain. The outline
  // is the sum of the sections with their caps replaced by spokes (docs/lbr-conventions.md,
  // "Joined sections"), so T is covered twice, and the chord leaves it covered once, when T
  // meets none of the four caps: the two at this disk lie on other angles (checked on the
  // grid), and a far cap (p's start, q's end) spans at most half a turn, so the line along
  // its spoke nearest T separates it from T (checked on T's vertices, with a margin of two
  // kernel units for the rounding). A spoke to c crosses every neighbouring side within ρ of
  // it; the chord crosses none.
  bool chord_is_covered(const MoveCaps& p, const MoveCaps& q, bool right) const {
    const P2 c = p.c1;
    const int a = right ? p.front_r : q.back_l, b = right ? q.back_r : p.front_l;
    const int steps = (a - b + n) % n;  // T spans [b, a] counter-clockwise
    if (steps == 0 || steps > n / 8) return false;
    auto strictly_inside = [&](int j) { return j != a && j != b && on_arc(j, b, a, n); };
    if (strictly_inside(right ? p.front_l : p.front_r) || strictly_inside(right ? q.back_l : q.back_r)) return false;
    if ((p.back_r - p.back_l + n) % n > n / 2 || (q.front_l - q.front_r + n) % n > n / 2) return false;
    const P2 tri[3] = {c, {c.x + p.rho1 * uc[static_cast<std::size_t>(a)].x, c.y + p.rho1 * uc[static_cast<std::size_t>(a)].y},
                       {c.x + p.rho1 * uc[static_cast<std::size_t>(b)].x, c.y + p.rho1 * uc[static_cast<std::size_t>(b)].y}};
    constexpr double kMargin = 2.0 * kMmPerUnit;
    // Signed side of T's vertices against the line through o along grid direction j; the
    // far cap lies where sign * cross <= 0.
    auto clear_of = [&](P2 o, int j, double sign) {
      const P2 d = uc[static_cast<std::size_t>(j)];
      for (const P2& t : tri)
        if (sign * (d.x * (t.y - o.y) - d.y * (t.x - o.x)) <= kMargin) return false;
      return true;
    };
    // Right side: p's back cap ends at spoke back_r (cap on the clockwise side of it), q's
    // front cap starts at spoke front_r (cap on the counter-clockwise side). Left: mirrored.
    return right ? clear_of(p.c0, p.back_r, 1.0) && clear_of(q.c1, q.front_r, -1.0)
                 : clear_of(p.c0, p.back_l, -1.0) && clear_of(q.c1, q.front_l, 1.0);
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
