// The moves of LinuxCNC's G70/G71/G72 lathe cycles (lathe_profile.hpp).
#include "lathe_profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace lbr::nc::detail {
namespace {

constexpr double kTol = 1e-6;       // LinuxCNC's tolerance for "on the level", "same point" [mm]
constexpr double kMonotonic = 1e-3;  // how far a segment may run back along the pass axis [mm]
constexpr double kChord = 0.001;     // chord error of the round corners of an offset profile [mm]
constexpr long kMaxSteps = 1000000;
constexpr std::size_t kMaxPoints = 20000;  // profile points (chords): the offset is quadratic in them
constexpr double kMaxLevels = 100000;      // roughing levels (range across the passes / I)

// A point in the normalised frame: p along the passes (the profile runs towards −p), l across
// them (the level; passes step towards −l from the start point).
struct V {
  double p = 0.0, l = 0.0;
};
V operator+(V a, V b) { return {a.p + b.p, a.l + b.l}; }
V operator-(V a, V b) { return {a.p - b.p, a.l - b.l}; }
V operator*(double s, V a) { return {s * a.p, s * a.l}; }
double cross(V a, V b) { return a.p * b.l - a.l * b.p; }
double norm(V a) { return std::hypot(a.p, a.l); }

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

struct Move {
  V to;
  bool rapid = false;
};

// Caller (x, z) <-> normalised (p, l): G71 passes along Z, G72 (and G70 on a profile that is
// not monotonic in Z) along X; each axis mirrored as the profile's direction needs.
struct Frame {
  bool along_x = false;
  double sp = 1.0, sl = 1.0;
  V to(const LathePoint& q) const { return along_x ? V{sp * q.x, sl * q.z} : V{sp * q.z, sl * q.x}; }
  LathePoint from(const Move& m) const {
    LathePoint q;
    const double a = sp * m.to.p, b = sl * m.to.l;
    q.x = along_x ? a : b, q.z = along_x ? b : a, q.rapid = m.rapid;
    return q;
  }
};

// The start point, then the profile, in the frame (moves of zero length dropped, as LinuxCNC).
std::vector<V> to_frame(const Frame& f, const LathePoint& start, const std::vector<LathePoint>& profile) {
  std::vector<V> pts{f.to(start)};
  for (const LathePoint& q : profile) {
    const V v = f.to(q);
    if (norm(v - pts.back()) > 1e-12) pts.push_back(v);
  }
  if (pts.size() < 3) throw std::invalid_argument("the profile subroutine makes fewer than two moves");
  if (pts.size() > kMaxPoints)
    throw std::invalid_argument("the profile has more than " + std::to_string(kMaxPoints) + " points (arcs count as chords)");
  return pts;
}

// Mirror so that the profile runs towards −p and ends no lower (in l) than the point `first`.
void normalise(Frame& f, std::vector<V>& pts, std::size_t first) {
  const V a = pts[first], b = pts.back();
  if (a.l - b.l > 0.0) {
    f.sl = -f.sl;
    for (V& v : pts) v.l = -v.l;
  }
  if (a.p - b.p < 0.0) {
    f.sp = -f.sp;
    for (V& v : pts) v.p = -v.p;
  }
}

bool runs_back(const std::vector<V>& pts, std::size_t from = 0) {
  for (std::size_t k = from; k + 1 < pts.size(); ++k)
    if (pts[k + 1].p - pts[k].p > kMonotonic) return true;
  return false;
}

// An approach that runs back along p starts level with the profile's start instead; then
// every segment must run towards −p.
void make_monotonic(std::vector<V>& pts, const char* axis) {
  if (pts[1].p - pts[0].p > 0.0) pts[0].p = pts[1].p;
  if (runs_back(pts))
    throw std::invalid_argument(std::string("the profile is not monotonic along ") + axis +
                                " (it runs back along the passes)");
}

// Where segments a-b and c-d cross (end points included).
bool crossing(V a, V b, V c, V d, V& at) {
  const V r = b - a, s = d - c;
  const double den = cross(r, s);
  if (std::abs(den) < 1e-18) return false;
  const double t = cross(c - a, s) / den, u = cross(c - a, r) / den;
  if (t < -1e-12 || t > 1.0 + 1e-12 || u < -1e-12 || u > 1.0 + 1e-12) return false;
  at = a + t * r;
  return true;
}

// Cut out the loops an offset makes at inner corners and across narrow features.
void remove_loops(std::vector<V>& q) {
  for (std::size_t i = 0; i + 3 < q.size(); ++i) {
    const double lo = std::min(q[i].p, q[i + 1].p), hi = std::max(q[i].p, q[i + 1].p);
    for (std::size_t j = q.size() - 2; j >= i + 2; --j) {
      if (std::max(q[j].p, q[j + 1].p) < lo || std::min(q[j].p, q[j + 1].p) > hi) continue;
      V at;
      if (!crossing(q[i], q[i + 1], q[j], q[j + 1], at)) continue;
      q.erase(q.begin() + static_cast<long>(i) + 1, q.begin() + static_cast<long>(j) + 1);
      q.insert(q.begin() + static_cast<long>(i) + 1, at);
      break;
    }
  }
}

// Chords of the round corner about c from a to b (radius |d|), end points excluded.
void round_corner(std::vector<V>& out, V c, V a, V b, double d) {
  const V u = a - c, w = b - c;
  const double sweep = std::atan2(cross(u, w), u.p * w.p + u.l * w.l);
  const double step = 2.0 * std::acos(std::max(0.0, 1.0 - kChord / std::abs(d)));
  const long n = std::max(1L, static_cast<long>(std::ceil(std::abs(sweep) / std::max(step, 1e-6))));
  const double a0 = std::atan2(u.l, u.p);
  for (long i = 1; i < n; ++i) {
    const double t = a0 + sweep * static_cast<double>(i) / static_cast<double>(n);
    out.push_back({c.p + std::abs(d) * std::cos(t), c.l + std::abs(d) * std::sin(t)});
  }
}

// The path with its profile (pts[1..]) offset by d towards the start point (LinuxCNC's sign
// rule), outer corners rounded. The free ends move square to their segments, unless the
// other offset segments cross a segment's extension there (a short end segment swallowed by
// the offset): then the profile starts or ends at that crossing. The approach line then ends
// at the offset profile's start.
std::vector<V> offset_path(const std::vector<V>& pts, double d) {
  if (d == 0.0) return pts;
  const std::size_t n = pts.size();
  if (cross(pts[n - 2] - pts[0], pts[1] - pts[0]) < 0.0) d = -d;
  auto normal = [&](std::size_t k) {  // right of segment k -> k+1, times d
    const V dir = pts[k + 1] - pts[k];
    return (d / norm(dir)) * V{dir.l, -dir.p};
  };
  std::vector<V> q{pts[1] + normal(1), pts[2] + normal(1)};
  for (std::size_t k = 2; k + 1 < n; ++k) {
    const V a = q.back(), b = pts[k] + normal(k);
    if (cross(pts[k] - pts[k - 1], pts[k + 1] - pts[k]) * d > 0.0) round_corner(q, pts[k], a, b, d);
    q.push_back(b);
    q.push_back(pts[k + 1] + normal(k));
  }
  constexpr double kFar = 1e4;  // [mm]
  const V d0 = pts[2] - pts[1], d1 = pts[n - 1] - pts[n - 2];
  q.insert(q.begin(), q.front() - (kFar / norm(d0)) * d0);
  q.push_back(q.back() + (kFar / norm(d1)) * d1);
  remove_loops(q);
  q.erase(q.begin());
  q.pop_back();
  if (q.size() < 2) throw std::invalid_argument("D is too large for the profile: nothing of it is left");
  q.insert(q.begin(), pts[0]);
  return q;
}

// G71/G72 roughing in the normalised frame: LinuxCNC's pass pattern on the segments of pts
// (the approach line first, the closing line to the start level last).
class Roughing {
 public:
  Roughing(std::vector<V> pts, double increment, double retract, std::vector<Move>& out)
      : pts_(std::move(pts)), delta_(increment), r_(retract), out_(out) {}

  void run(int variant) {
    emit(pts_[0], true);
    if (pts_.back().l < pts_[0].l) pts_.push_back({pts_.back().p, pts_[0].l});
    starts_ = {pts_[0].l};
    pocket(variant, pts_[0], 0);
  }

 private:
  std::size_t segments() const { return pts_.size() - 1; }
  void emit(V v, bool rapid) { out_.push_back({v, rapid}); }
  void step() {
    if (++steps_ > kMaxSteps) throw std::invalid_argument("more than " + std::to_string(kMaxSteps) + " steps");
  }

  // Where segment k crosses level x (both ends of a segment along the level).
  std::vector<double> crossings(std::size_t k, double x) const {
    const V a = pts_[k], b = pts_[k + 1];
    if (std::min(a.l, b.l) > x + kTol || std::max(a.l, b.l) < x - kTol) return {};
    if (std::abs(a.l - b.l) < kTol) return {a.p, b.p};
    return {a.p + (x - a.l) / (b.l - a.l) * (b.p - a.p)};
  }

  // Down segment k to level x (or its end); false when k does not go down.
  bool dive(std::size_t k, V& loc, double x, bool fast) {
    const V a = pts_[k], b = pts_[k + 1];
    if (a.l <= b.l + kTol) return false;
    if (x < b.l) {
      loc = b;
    } else {
      const std::vector<double> c = crossings(k, x);
      if (c.empty()) throw std::invalid_argument("level beyond a descending segment");
      loc = {c.front(), x};
    }
    emit(loc, fast);
    return true;
  }

  // Along segment k when it does not go down; true (a pocket starts) when it does.
  bool climb(std::size_t k, V& loc) {
    if (pts_[k + 1].l + kTol < pts_[k].l) return true;
    emit(pts_[k + 1], false);
    loc = pts_[k + 1];
    return false;
  }

  // G7x.1 after the passes: up the profile, straight across its pockets at the current level.
  void climb_only(std::size_t k, V& loc) {
    if (pts_[k + 1].l < pts_[k].l) return;
    const std::vector<double> c = crossings(k, loc.l);
    if (c.empty()) return;
    loc.p = c.front();
    emit(loc, false);
    emit(pts_[k + 1], false);
    loc = pts_[k + 1];
  }

  void follow_profile(int cycle, std::size_t k, V& loc);
  bool pass_at_level(std::size_t& k, const V& loc, double& x);
  void pocket(int cycle, V loc, std::size_t k);

  std::vector<V> pts_;
  double delta_, r_;
  std::vector<Move>& out_;
  std::vector<double> starts_;  // levels the passes count from (G7x.2: each pocket's top)
  long steps_ = 0;
};

// Past the bottom of the descent: along the profile, cutting each pocket met (cycle 0, 3), or
// bridging them (cycle 1).
void Roughing::follow_profile(int cycle, std::size_t k, V& loc) {
  if (cycle == 1) {
    for (; k < segments(); ++k) climb_only(k, loc);
    return;
  }
  for (; k < segments(); ++k) {
    if (!climb(k, loc)) continue;
    if (cycle == 3) {
      if (loc.l > starts_.back() && starts_.size() > 1) starts_.pop_back();
      if (starts_.size() == 1) starts_.push_back(loc.l);
    }
    pocket(cycle, loc, k);
    return;
  }
}

// One pass at loc's level from descending segment k to the next crossing ahead: feed, retract
// R at 45 degrees (less on a short pass), back beside the entry, to the entry. Moves k on when
// the level meets the next segment at loc. False when nothing lies ahead at that level.
bool Roughing::pass_at_level(std::size_t& k, const V& loc, double& x) {
  for (std::size_t ip = k; ip < segments(); ++ip) {
    const std::vector<double> c = crossings(ip, loc.l);
    if (c.empty()) continue;
    const double dz = ip != k ? c.front() : c.back();
    const double distance = std::abs(dz - loc.p);
    if (dz - kTol > loc.p) continue;
    if (distance < kTol) {
      if (ip == k) continue;
      if (norm(loc - pts_[ip]) < kTol) k = ip;
      else x -= delta_;
      return true;
    }
    emit({dz, loc.l}, false);
    const double s = r_ > 0.0 ? std::min(1.0, distance / 2.0 / r_) : 0.0;
    emit({dz + s * r_, loc.l + s * r_}, true);
    emit({loc.p - s * r_, loc.l + s * r_}, true);
    emit(loc, k == 0);
    x -= delta_;
    return true;
  }
  return false;
}

void Roughing::pocket(int cycle, V loc, std::size_t k) {
  double x = starts_.back();
  if (cycle == 2) {  // G7x.2: down the profile without passes, then its pockets
    for (; k < segments(); ++k)
      if (!dive(k, loc, -1e9, k == 0)) break;
    cycle = 3;
  }
  while (k < segments()) {
    step();
    while (x - kTol > loc.l) x -= delta_;
    if (!dive(k, loc, x, k == 0)) {
      follow_profile(cycle, k, loc);
      return;
    }
    if (std::abs(loc.l - x) > kTol) {
      ++k;
      continue;
    }
    if (!pass_at_level(k, loc, x)) throw std::invalid_argument("a pass meets no profile: the profile is not closed towards the start point");
  }
}

std::vector<LathePoint> from_frame(const Frame& f, const std::vector<Move>& moves) {
  std::vector<LathePoint> out;
  out.reserve(moves.size());
  for (const Move& m : moves) out.push_back(f.from(m));
  return out;
}

std::vector<LathePoint> roughing(const std::vector<LathePoint>& profile, const LathePoint& start,
                                 const LatheCycle& c) {
  if (!(c.increment > 0.0)) throw std::invalid_argument("I (cut increment) must be > 0");
  if (c.retract < 0.0) throw std::invalid_argument("R (retract) must be >= 0");
  if (c.allowance < 0.0) throw std::invalid_argument("D (distance left to the profile) must be >= 0");
  Frame f;
  f.along_x = c.code == 72;
  std::vector<V> pts = to_frame(f, start, profile);
  normalise(f, pts, 1);
  make_monotonic(pts, f.along_x ? "X" : "Z");
  double lo = pts[0].l, hi = lo;
  for (const V& v : pts) lo = std::min(lo, v.l), hi = std::max(hi, v.l);
  if ((hi - lo) / c.increment > kMaxLevels)
    throw std::invalid_argument("more than " + std::to_string(static_cast<long>(kMaxLevels)) + " levels (I too small)");
  std::vector<V> path = offset_path(pts, c.allowance);
  if (runs_back(path, 1))  // the approach may (LinuxCNC does not check it after the offset)
    throw std::invalid_argument("D is too large for the profile: offset, it runs back along the passes");
  std::vector<Move> moves;
  Roughing(std::move(path), c.increment, c.retract, moves).run(c.variant);
  return from_frame(f, moves);
}

// G70: the passes run along X when the profile (normalised on its own) is not monotonic in Z.
std::vector<LathePoint> finishing(const std::vector<LathePoint>& profile, const LathePoint& start,
                                  const LatheCycle& c) {
  if (c.passes < 1) throw std::invalid_argument("P (number of passes) must be >= 1");
  Frame f;
  std::vector<V> own = to_frame(f, start, profile);
  own.erase(own.begin());
  Frame g;
  normalise(g, own, 1);
  f.along_x = runs_back(own);
  std::vector<V> pts = to_frame(f, start, profile);
  normalise(f, pts, 1);
  make_monotonic(pts, f.along_x ? "X" : "Z");
  std::vector<Move> moves;
  for (int pass = c.passes; pass > 0; --pass) {
    const double d = (pass - 1) * (c.allowance - c.end_allowance) / c.passes + c.end_allowance;
    const std::vector<V> path = offset_path(pts, d);
    moves.push_back({path[0], true});
    moves.push_back({path[1], true});
    for (std::size_t i = 2; i < path.size(); ++i) moves.push_back({path[i], false});
  }
  return from_frame(f, moves);
}

// LinuxCNC's corner finishes: a fillet (A) of radius r or a chamfer (C, the same end points)
// at a corner, tangent to the two straight moves meeting there, r·tan(turn/2) from the corner.
// A finish on the last move has no corner (ignored, as LinuxCNC).
std::vector<LathePoint> with_corner_finishes(const LathePoint& start, const std::vector<LathePoint>& profile) {
  std::vector<LathePoint> out;
  auto v = [](const LathePoint& q) { return V{q.z, q.x}; };
  for (std::size_t k = 0; k < profile.size(); ++k) {
    const LathePoint& q = profile[k];
    if (q.corner <= 0.0 || k + 1 == profile.size()) {
      out.push_back(q);
      continue;
    }
    const V a = v(out.empty() ? start : out.back()), c = v(q), b = v(profile[k + 1]);
    const double la = norm(c - a), lb = norm(b - c);
    if (la < 1e-12 || lb < 1e-12) throw std::invalid_argument("a corner finish at a move of zero length");
    const V u = (1.0 / la) * (c - a), w = (1.0 / lb) * (b - c);
    const double turn = std::atan2(std::abs(cross(u, w)), u.p * w.p + u.l * w.l);
    if (turn < 1e-9) {
      out.push_back(q);
      continue;
    }
    const double t = q.corner * std::tan(turn / 2.0);
    if (t > la + 1e-9 || t > lb + 1e-9)
      throw std::invalid_argument("the corner finish " + num(q.corner) + " mm does not fit the straight moves at X" +
                                  num(q.x) + " Z" + num(q.z) + " (arcs take none)");
    std::vector<V> pts{c - t * u};
    if (!q.chamfer) {
      const double side = cross(u, w) > 0.0 ? 1.0 : -1.0;
      const V centre = pts[0] + (side * q.corner) * V{-u.l, u.p};
      round_corner(pts, centre, pts[0], c + t * w, q.corner);
    }
    pts.push_back(c + t * w);
    for (const V& p : pts) {
      LathePoint r;
      r.x = p.l, r.z = p.p;
      out.push_back(r);
    }
  }
  return out;
}

}  // namespace

std::vector<LathePoint> lathe_cycle(const std::vector<LathePoint>& profile, const LathePoint& start,
                                    const LatheCycle& cycle) {
  const std::vector<LathePoint> finished = with_corner_finishes(start, profile);
  if (cycle.code == 70) return finishing(finished, start, cycle);
  return roughing(finished, start, cycle);
}

}  // namespace lbr::nc::detail
