// Sections of swept tools on level planes.
//
// Both paths rest on one fact: with a piecewise-linear concave profile the cutting part of
// the tool is the convex hull of its station circles, and translating a convex solid along
// a segment sweeps the convex hull of its start and end copies. So the swept solid of a
// straight move is conv(station circles at both poses), and its section by a plane is convex.
//  - Vertical axis (3-axis): the section is the union over the move of horizontal disks;
//    with a linear profile it is the convex hull of the disks at the parameter values where
//    the plane meets a station or an end of the cutting part. Built as a 2D hull.
//  - Any other axis: boundary points of the section are found through the support function
//    of the 3D hull (bisection on the tilt of the direction), refined adaptively in angle
//    until the chord error is within tolerance.
#include "geom/sweep.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace lbr::geom {

namespace {

using P2 = SectionScratch::P2;


Vec3 normalized(Vec3 v) noexcept {
  const double n = norm(v);
  return n > 0.0 ? (1.0 / n) * v : Vec3{0, 0, 1};
}

double cross2(const P2& o, const P2& a, const P2& b) noexcept {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// True when `pts` is already a strictly convex counter-clockwise polygon: every turn is a
// left turn and x changes direction twice (once round: a polygon of left turns that winds
// more than once changes it more often). The support points of a tilted section, in the
// order of their directions, nearly always are.
bool convex_in_order(const std::vector<P2>& pts) noexcept {
  const std::size_t n = pts.size();
  if (n < 3) return false;
  int turns = 0;
  double last_dx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const P2& a = pts[i];
    const P2& b = pts[i + 1 < n ? i + 1 : i + 1 - n];
    const P2& c = pts[i + 2 < n ? i + 2 : i + 2 - n];
    if (!(cross2(a, b, c) > 0.0)) return false;
    const double dx = b.x - a.x;
    if (dx != 0.0) {
      if (last_dx != 0.0 && (dx > 0.0) != (last_dx > 0.0)) ++turns;
      last_dx = dx;
    }
  }
  // The wrap from the last edge with dx != 0 to the first.
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = pts[i + 1 < n ? i + 1 : 0].x - pts[i].x;
    if (dx != 0.0) {
      if ((dx > 0.0) != (last_dx > 0.0)) ++turns;
      break;
    }
  }
  return turns == 2;
}

// Andrew's monotone chain; counter-clockwise, collinear points dropped. Sorts `pts` unless
// they already are a strictly convex counter-clockwise polygon (then copied as they are).
void convex_hull(std::vector<P2>& pts, std::vector<P2>& hull) {
  hull.clear();
  if (convex_in_order(pts)) {
    hull.assign(pts.begin(), pts.end());
    return;
  }
  std::sort(pts.begin(), pts.end(), [](const P2& a, const P2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  const std::size_t n = pts.size();
  if (n < 3) {
    hull.assign(pts.begin(), pts.end());
    return;
  }
  hull.resize(2 * n);
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0.0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = n - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0.0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
}

// Rounds a hull to kernel units and appends it when it still encloses area. The path's
// buffer comes from `spare` when it has one (no allocation once the pool has grown).
std::size_t emit(const std::vector<P2>& hull, Paths& out, std::vector<Path>& spare) {
  if (hull.size() < 3) return 0;
  Path p = SectionScratch::take_spare(spare);
  p.reserve(hull.size());
  for (const P2& q : hull) {
    const Point ip{to_units(q.x), to_units(q.y)};
    if (p.empty() || ip.X != p.back().X || ip.Y != p.back().Y) p.push_back(ip);
  }
  while (p.size() > 1 && p.front().X == p.back().X && p.front().Y == p.back().Y) p.pop_back();
  if (p.size() < 3) {
    spare.push_back(std::move(p));
    return 0;
  }
  out.push_back(std::move(p));
  return 1;
}

// A point of plain doubles without initialisers, so that a caller's fixed array of them
// (Circle, Hull3's capsule) costs nothing to declare: with Vec3's zero initialisers the
// 1 024 circles of tilted_pieces() were written on every call (57 KB, 2/3 of its time on
// finish5x's ball pass).
struct P3 {
  double x, y, z;
};
P3 p3(const Vec3& v) noexcept { return {v.x, v.y, v.z}; }

// Station circles of one pose a tilted sub-step takes at most (a profile with more is not
// sectioned: Sweep::tilted_pieces()).
constexpr std::size_t kMaxStations = 512;

// A sub-step hull's box in XY and a point inside it [mm].
struct HullBox {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY, cx = 0.0, cy = 0.0;
};

// A station circle of the tool at one pose.
struct Circle {
  P3 c, n;
  double r;
};

// Station circles of the tool's part up to axial height `top` at pose p: the stations
// below it and one at `top` itself, written to `out` (fixed capacity caller-side).
template <class F>
void for_each_station_circle(const CutterShape& s, const Pose& p, double top, F&& f) noexcept {
  for (const auto& st : s.stations) {
    if (st.h >= top) break;
    f(Circle{p3(p.tip + st.h * p.axis), p3(p.axis), st.r});
  }
  f(Circle{p3(p.tip + top * p.axis), p3(p.axis), s.radius_at(top)});
}
int station_circles(const CutterShape& s, const Pose& p, double top, Circle* out) noexcept {
  int n = 0;
  for_each_station_circle(s, p, top, [&](const Circle& c) { out[n++] = c; });
  return n;
}

// The convex hull of the tool's station circles at two poses (one sub-step of a move).
// Its support in direction d is the larger of the two poses' supports, and at one pose the
// support of station i is tip·d + h_i·(a·d) + r_i·|d⊥| (d⊥: d without its axis part). The
// profile (h_i, r_i) is a concave chain, so the sign of its differences goes from + to
// not +: the best station is the first whose step to the next does not increase the value.
// Consecutive queries come from close directions, so it is found by walking from the last
// query's station (one or two steps) rather than by a binary search; the result is the same.
//
// A ball end mill whose shank is no thinner than its head (CutterShape::capsule_radius_mm)
// is taken as a capsule instead: the points within its radius r of the axis segment from the
// ball's centre to the top of the flutes. That is the ball and the flutes' cylinder exactly;
// only the cylinder's flat top becomes a hemisphere, which lies inside the shank above it.
// The sub-step is then K ⊕ B(r), K four of the edges of the tetrahedron of the two poses'
// segment ends (each pose's segment and the paths of its ends: the tetrahedron's diagonals
// stand out of the swept segment to first order in the turn), and its section has a
// closed-form support point in every direction (capsule_point()).
// A bull-nose mill (CutterShape::core_radius_mm) is taken the same way with a disk of radius
// ρ (its flat end's) in place of each segment end: the points within its corner radius of
// that disk swept along the axis from the corner's centre to the top of the flutes. The
// sub-step's hull is then conv(four disks) ⊕ B(r), whose support is the best of the four
// disks' plus r along the direction (core_support()): the profile's exact torus instead of
// its polyline, and the tilt search's height z(t) is smooth but for the switches between the
// four disks, not a staircase of station bands.
//
// Only the tool's part up to axial height `top` (Sweep's top_: what lies above cuts
// nothing) is modelled: the capsule's and the core's segments end there, and the station
// model ends at a station of its own there (stations above it dropped).
struct Hull3 {
  Hull3(const CutterShape* s, const Pose& a, const Pose& b, double top_mm) noexcept
      : shape(s), pose{a, b}, top(top_mm) {
    cap_r = s->capsule_radius_mm;
    core = s->core_radius_mm;
    if (cap_r > 0.0) {
      q[0] = p3(a.tip + cap_r * a.axis);
      q[1] = p3(a.tip + top * a.axis);
      q[2] = p3(b.tip + cap_r * b.axis);
      q[3] = p3(b.tip + top * b.axis);
      return;
    }
    while (low_stations < s->stations.size() && s->stations[low_stations].h < top) ++low_stations;
    top_r = s->radius_at(top);
  }
  const CutterShape* shape;
  Pose pose[2];
  double top;          // the modelled part's top [mm above the tip]
  double cap_r = 0.0;  // > 0: the capsule model (q: the segment ends at both poses)
  double core = 0.0;   // > 0 with cap_r: the rounded core model (q: the core disks' centres)
  std::size_t low_stations = 0;  // station model: the stations below `top` (then one at top)
  double top_r = 0.0;            // station model: the profile's radius at `top`
  P3 q[4];  // a.centre, a.top, b.centre, b.top (set only for the capsule: no initialisers)
  mutable std::size_t last_station[2] = {0, 0};  // each pose's best station of the last query
  mutable std::uint32_t queries = 0;              // support() calls (TiltedPiece, SectionScratch)
  Vec3 support(const Vec3& d) const noexcept {
    ++queries;
    if (core > 0.0) return core_support(d);
    if (cap_r > 0.0) {
      auto along = [&](const P3& v) { return v.x * d.x + v.y * d.y + v.z * d.z; };
      int best = 0;
      for (int i = 1; i < 4; ++i)
        if (along(q[i]) > along(q[best])) best = i;
      const double l = norm(d);
      const Vec3 c{q[best].x, q[best].y, q[best].z};
      return l > 0.0 ? c + (cap_r / l) * d : c;
    }
    return station_support(d);
  }
  // The station model's support point: the stations below `top` and one at `top`.
  Vec3 station_support(const Vec3& d) const noexcept {
    const auto& stations = shape->stations;
    const std::size_t ns = low_stations + 1;
    auto st = [&](std::size_t i) { return i < low_stations ? stations[i] : CutterShape::Station{top, top_r}; };
    double best = -INFINITY;
    Vec3 bp{};
    const double dd = dot(d, d);
    for (int k = 0; k < 2; ++k) {
      const Pose& p = pose[k];
      const double along = dot(p.axis, d);
      const Vec3 perp = d - along * p.axis;
      const double pl2 = dot(perp, perp);
      const bool flat = pl2 <= 1e-30 * dd;  // |d⊥| <= 1e-15 |d|
      const double pl = flat ? 0.0 : std::sqrt(pl2);
      auto rises = [&](std::size_t i) {
        const CutterShape::Station a = st(i), b = st(i + 1);
        return (b.h - a.h) * along + (flat ? 0.0 : (b.r - a.r) * pl) > 0.0;
      };
      std::size_t lo = std::min(last_station[k], ns - 1);
      while (lo + 1 < ns && rises(lo)) ++lo;
      while (lo > 0 && !rises(lo - 1)) --lo;
      last_station[k] = lo;
      const CutterShape::Station best_st = st(lo);
      const double v = dot(p.tip, d) + best_st.h * along + (flat ? 0.0 : best_st.r * pl);
      if (v > best) {
        best = v;
        const Vec3 c = p.tip + best_st.h * p.axis;
        bp = flat || best_st.r == 0.0 ? c : c + (best_st.r / pl) * perp;
      }
    }
    return bp;
  }
  // Boundary point of the section of the hull by z = zc in in-plane direction (cos φ, sin φ),
  // to about `eps` [mm]: the support point of the section in that direction. The point is
  // interpolated on the chord between the support points below and above the plane (inside
  // the hull, so never outside the section); the bisection on the tilt t of the 3D
  // direction (cos φ, sin φ, t) halves its distance to the boundary each step, so it stops
  // once a step moves the point by less than eps/2 (the steps left would move it by about
  // as much in all). The search starts from [t_lo, t_hi] (a neighbouring direction's
  // bracket: the tilt changes little between close directions), widened until it brackets
  // the plane; `t_lo`/`t_hi` return the final bracket. At least `min_steps` + 1 steps: a
  // wide start bracket can give a first step that happens to move little. Unless the point
  // is proven within eps of the boundary first: see `proven` below.
  // `upper`, when given, receives a proven bound on the section's support value h_S(u).
  P2 section_point(double phi, double zc, double eps, double& t_lo, double& t_hi, int min_steps) const noexcept {
    return section_point(std::cos(phi), std::sin(phi), zc, eps, t_lo, t_hi, min_steps);
  }
  // The same with the in-plane direction given as (ux, uy) = (cos φ, sin φ).
  P2 section_point(double ux, double uy, double zc, double eps, double& t_lo, double& t_hi, int min_steps,
                   double* upper_out = nullptr) const noexcept {
    if (cap_r > 0.0 && core == 0.0) {
      const P2 c = capsule_point(ux, uy, zc);  // exact: its support value is h_S(u)
      if (upper_out != nullptr) *upper_out = ux * c.x + uy * c.y + kExactSlack;
      return c;
    }
    // Every query also bounds the section's support value h_S(u) from above: any point x of
    // the section (x.z = zc) has u·x + t·zc <= h_H(u, t), so h_S(u) <= g(t) = u·s + t·(s.z −
    // zc) with s the support point of (u, t).
    double upper = INFINITY;
    auto sup = [&](double t) {
      const Vec3 s = support(Vec3{ux, uy, t});
      upper = std::min(upper, ux * s.x + uy * s.y + t * (s.z - zc));
      return s;
    };
    // The interpolated point P lies in the section, so u·P <= h_S(u): once the upper bound
    // is within eps of u·P, P is within eps of the boundary's support line in direction u,
    // which is all that the refinement needs of it (refine_section()); then no further
    // step is taken whatever min_steps says.
    auto proven = [&](const P2& pt) { return upper - (ux * pt.x + uy * pt.y) <= eps; };
    // A start bracket is a neighbour's result; one that is not finite (a search whose plane
    // missed the hull widened it without end) starts afresh, or the queries would be NaN.
    constexpr double kMaxTilt = 1e6;
    double tlo = t_lo, thi = t_hi;
    if (!(std::abs(tlo) <= kMaxTilt && std::abs(thi) <= kMaxTilt && tlo < thi)) tlo = -1.0, thi = 1.0;
    // The middle first, then the end on the other side of the plane: the start bracket is
    // halved for the same two queries.
    Vec3 plo, phi_;
    {
      const double tm = 0.5 * (tlo + thi);
      const Vec3 pm = sup(tm);
      if (pm.z <= zc) {
        tlo = tm;
        plo = pm;
        phi_ = sup(thi);
      } else {
        thi = tm;
        phi_ = pm;
        plo = sup(tlo);
      }
    }
    for (int i = 0; i < 80 && plo.z > zc; ++i) {
      const double w = thi - tlo;
      thi = tlo;
      phi_ = plo;
      tlo -= 2.0 * w + 1e-9;
      plo = sup(tlo);
    }
    for (int i = 0; i < 80 && phi_.z < zc; ++i) {
      const double w = thi - tlo;
      tlo = thi;
      plo = phi_;
      thi += 2.0 * w + 1e-9;
      phi_ = sup(thi);
    }
    auto interpolate = [&] {
      const double dz = phi_.z - plo.z;
      if (!(dz > 1e-12)) return P2{plo.x, plo.y};
      const double w = std::clamp((zc - plo.z) / dz, 0.0, 1.0);
      return P2{plo.x + w * (phi_.x - plo.x), plo.y + w * (phi_.y - plo.y)};
    };
    const double stop2 = 0.25 * eps * eps;
    P2 last = interpolate();
    for (int i = 0; i < 64 && thi - tlo > 1e-13 * (1.0 + std::abs(tlo)) && !proven(last); ++i) {
      const double tm = 0.5 * (tlo + thi);
      const Vec3 pm = sup(tm);
      if (pm.z <= zc) {
        tlo = tm;
        plo = pm;
      } else {
        thi = tm;
        phi_ = pm;
      }
      const P2 now = interpolate();
      const double dx = now.x - last.x, dy = now.y - last.y;
      last = now;
      if (i >= min_steps && dx * dx + dy * dy <= stop2) break;
    }
    t_lo = tlo;
    t_hi = thi;
    if (upper_out != nullptr) *upper_out = upper;
    return last;
  }
  // The rounding of a closed-form support value [mm].
  static constexpr double kExactSlack = 1e-9;
  P2 capsule_point(double ux, double uy, double zc) const noexcept;
  // Narrows [lo, hi] to the height range of the capsule's or rounded core's hull (exact);
  // the station model's hull is what its circles span, so it leaves them. The stations'
  // polyline lies up to the chord tolerance outside the exact profile, so their circles can
  // reach below the exact model, and a plane between the two misses the hull: its search
  // would find no point on it.
  void clamp_z_extent(double& lo, double& hi) const noexcept {
    if (cap_r <= 0.0) return;
    double zl = INFINITY, zh = -INFINITY;
    for (int i = 0; i < 4; ++i) {
      const Vec3& a = pose[i / 2].axis;
      const double e = core * std::sqrt(std::max(0.0, 1.0 - a.z * a.z));  // a core disk's half-height
      zl = std::min(zl, q[i].z - e);
      zh = std::max(zh, q[i].z + e);
    }
    lo = std::max(lo, zl - cap_r);
    hi = std::min(hi, zh + cap_r);
  }
  // The capsule's or rounded core's hull's box in XY [mm] (exact for its disks and balls)
  // and the mean of its segment ends.
  HullBox xy_extent() const noexcept {
    HullBox b;
    for (int i = 0; i < 4; ++i) {
      const Vec3& a = pose[i / 2].axis;
      const double ex = core * std::sqrt(std::max(0.0, 1.0 - a.x * a.x)) + cap_r;
      const double ey = core * std::sqrt(std::max(0.0, 1.0 - a.y * a.y)) + cap_r;
      b.x0 = std::min(b.x0, q[i].x - ex);
      b.x1 = std::max(b.x1, q[i].x + ex);
      b.y0 = std::min(b.y0, q[i].y - ey);
      b.y1 = std::max(b.y1, q[i].y + ey);
      b.cx += 0.25 * q[i].x;
      b.cy += 0.25 * q[i].y;
    }
    return b;
  }
  // The rounded core model's support point in direction d: the best of the four core disks'
  // (a disk of radius ρ about c normal to a: c + ρ·d⊥/|d⊥|), moved out by cap_r along d.
  Vec3 core_support(const Vec3& d) const noexcept {
    double best = -INFINITY;
    Vec3 bp{};
    for (int k = 0; k < 2; ++k) {
      const Vec3& a = pose[k].axis;
      const double along = dot(a, d);
      const P3& c = q[2 * k + (along > 0.0 ? 1 : 0)];
      const Vec3 perp = d - along * a;
      const double pl = norm(perp);
      const double v = c.x * d.x + c.y * d.y + c.z * d.z + core * pl;
      if (v > best) {
        best = v;
        const double f = pl > 1e-15 ? core / pl : 0.0;
        bp = Vec3{c.x + f * perp.x, c.y + f * perp.y, c.z + f * perp.z};
      }
    }
    const double l = norm(d);
    return l > 0.0 ? bp + (cap_r / l) * d : bp;
  }

 private:
  // K's edges near the plane of the last capsule query: p0 + s·(dx, dy, dz), s in [s0, s1]
  // within r of it; `level`: dz = 0 (the support is at s0 or s1).
  struct CapEdge {
    P3 p0;
    double dx, dy, dz, s0, s1, sgn, dz2;
    bool level;
  };
  void prepare_capsule(double zc) const noexcept;
  mutable double cap_zc = NAN;
  mutable int cap_edges = 0;
  mutable CapEdge cap_edge[4];
};

// The capsule model's support point of the section on z = zc in direction u = (ux, uy):
// the hull of the sections of the balls swept along K's four edges (Hull3), and along an
// edge p0 + s·d the
// support value u·p(s) + sqrt(r² − (p(s).z − zc)²) is concave in s, greatest where its
// derivative vanishes: p(s).z − zc = r·(u·d)·sgn(d.z) / sqrt(d.z² + (u·d)²), clamped to the
// part of the edge within r of the plane. Exact up to rounding; one query.
P2 Hull3::capsule_point(double ux, double uy, double zc) const noexcept {
  ++queries;
  if (!(zc == cap_zc)) prepare_capsule(zc);
  const double r = cap_r;
  double best = -INFINITY;
  P2 bp{q[0].x, q[0].y};
  for (int i = 0; i < cap_edges; ++i) {
    const CapEdge& e = cap_edge[i];
    const double b = ux * e.dx + uy * e.dy;
    const double s = e.level ? (b > 0.0 ? e.s1 : e.s0)
                             : std::clamp((zc + r * b * e.sgn / std::sqrt(e.dz2 + b * b) - e.p0.z) / e.dz, e.s0, e.s1);
    const double h = e.p0.z + s * e.dz - zc;
    const double rho = std::sqrt(std::max(0.0, r * r - h * h));
    const double v = ux * e.p0.x + uy * e.p0.y + s * b + rho;
    if (v > best) {
      best = v;
      bp = {e.p0.x + s * e.dx + rho * ux, e.p0.y + s * e.dy + rho * uy};
    }
  }
  return bp;
}

// The edges of K that come within r of plane z = zc, each with the part of it that does.
void Hull3::prepare_capsule(double zc) const noexcept {
  cap_zc = zc;
  cap_edges = 0;
  const double r = cap_r;
  auto edge = [&](const P3& p0, const P3& p1) {
    CapEdge e{p0, p1.x - p0.x, p1.y - p0.y, p1.z - p0.z, 0.0, 1.0, 1.0, 0.0, false};
    e.dz2 = e.dz * e.dz;
    e.sgn = e.dz > 0.0 ? 1.0 : -1.0;
    if (std::abs(e.dz) <= 1e-12) {
      if (std::abs(p0.z - zc) > r) return;
      e.level = true;
    } else {
      double s0 = (zc - r - p0.z) / e.dz, s1 = (zc + r - p0.z) / e.dz;
      if (s0 > s1) std::swap(s0, s1);
      e.s0 = std::max(s0, 0.0);
      e.s1 = std::min(s1, 1.0);
      if (e.s0 > e.s1) return;
    }
    cap_edge[cap_edges++] = e;
  };
  edge(q[0], q[1]);
  edge(q[2], q[3]);
  edge(q[0], q[2]);
  edge(q[1], q[3]);
}

double dist_to_line(const P2& p, const P2& a, const P2& b) noexcept {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double l = std::sqrt(dx * dx + dy * dy);  // lengths in mm: no overflow, so not the slower hypot
  if (l < 1e-15) return std::sqrt((p.x - a.x) * (p.x - a.x) + (p.y - a.y) * (p.y - a.y));
  return std::abs((p.x - a.x) * dy - (p.y - a.y) * dx) / l;
}

}  // namespace

double Sweep::circle_grow_width(int n) noexcept {
  const double th = std::numbers::pi / n;
  return th / std::sin(th);
}

double Sweep::circle_grow_area(int n) noexcept {
  const double th = std::numbers::pi / n;
  return std::sqrt(th / (std::sin(th) * std::cos(th)));
}

int Sweep::circle_segments(double r_mm, double chord_tol_mm) noexcept {
  if (!(r_mm > 0.0)) return 1;
  // Either polygon deviates from the circle by about r·θ²/3 at most (θ = π/n): the width-
  // keeping one by r·(g − 1) ≈ r·θ²/6 outside at its vertices and r·(1 − g·cos θ) ≈ r·θ²/3
  // inside at its edges' midpoints, the area-keeping one by r·θ²/3 outside and r·θ²/6
  // inside. Start from θ = sqrt(3·tol/r) and add vertices while either exceeds tol.
  const double t = std::min(1.0, chord_tol_mm / r_mm);
  int n = std::max(8, static_cast<int>(std::ceil(std::numbers::pi / std::sqrt(3.0 * t))));
  auto within = [&](double g) { return g - 1.0 <= t && 1.0 - g * std::cos(std::numbers::pi / n) <= t; };
  while (n < 4096 && !(within(circle_grow_width(n)) && within(circle_grow_area(n)))) ++n;
  return std::min(n, 4096);
}

double cut_height_below(const CutterShape& shape, const Pose& p, double z_mm) noexcept {
  const double R = shape.radius(), H = shape.height();
  const double az = p.axis.z / norm(p.axis);
  if (!std::isfinite(z_mm) || !(az > 0.0)) return H;
  return std::clamp((z_mm - p.tip.z + R * std::sqrt(std::max(0.0, 1.0 - az * az))) / az, 0.0, H);
}

// A sub-step is the convex hull of the modelled part K at its two poses; the tool swept
// between them differs from it in two ways, each bounded by the chord tolerance:
//  - the sagitta: a point at distance ρ from the tip describes an arc while the axis turns
//    by φ; the hull holds its chord, ρ·(1 − cos(φ/2)) inside it (under-cut);
//  - the twist (over-cut, first order in φ). A point of the hull's boundary that lies
//    outside both poses' tools lies on a bridge Q = (1 − λ)·x₀ + λ·y₁ between the support
//    points x, y ∈ K of one direction at the two poses, which lies
//    λ(1 − λ)·|(R₁ − R₀)(y − x)| ≤ λ(1 − λ)·φ·|y − x| from the point (1 − λ)x + λy of
//    the tool at the interpolated pose. Support points of directions φ apart lie on one
//    flat feature of K (or O(φ) apart on a curved part): a straight piece of the profile
//    (|y − x| = |Δh| times its slope, λ(1 − λ)|Δh| ≤ L/4, L the modelled part's axial
//    span) or a flat end (|y − x| ≤ 2ρ: ρφ/2, along the axis; none where the end moves
//    along the axis by 3ρφ or more, which holds such offsets).
// The axial term's offset of Q, ε·W with W = L·(a₁ − a₀) and |ε| ≤ 1/4, counts only across
// the swept surface: the patch of a generator moving by V(s) = ΔA + s·W (A the part's
// lowest axis point, s along it) holds, to first order, every offset along V and along the
// axis, so Q lies about |ε|·|W·n̂| from it, n̂ ∝ a × V(s) (`across`, the largest
// |W·n̂|/|W| over s; 1 where the axis turns about a point of the part, V = 0). A tool that
// leans along its motion barely twists.
// Heights sharpen both: Q.z lies between x₀.z and y₁.z, so λ(1 − λ)|y₁.z − x₀.z| ≤
// min(Q.z − z_lo, z_hi − Q.z) over the part's height range [z_lo, z_hi], and |Δh|·a.z
// differs from |y₁.z − x₀.z| by at most |Δtip.z| + L·|Δa.z| + 2ρφ; a flat end's bridges
// lie within its own height range. Near the part's lowest points, where a finishing tool
// cuts its surface, the axial term vanishes.
// The capsule and the core are hulls of such a part (their segment; the core's disk)
// grown by a ball of radius `ball`, which turns into itself: a plane's points come from
// the part's heights within `ball` of the plane.
int Sweep::TwistBound::count(double z_mm) const noexcept {
  if (!(angle > 1e-12)) return 1;
  const bool all = std::isnan(z_mm);
  const double lo = all ? -INFINITY : z_mm - ball, hi = all ? INFINITY : z_mm + ball;
  double m = 0.5 * (z_hi - z_lo);  // the largest min(q − z_lo, z_hi − q), at the middle
  const double mid = 0.5 * (z_lo + z_hi);
  if (std::max(lo, z_lo) > std::min(hi, z_hi)) m = 0.0;
  else if (hi < mid) m = hi - z_lo;
  else if (lo > mid) m = z_hi - lo;
  double excess = across * slope * (inv_az > 0.0 ? std::min(quarter_len, (m + slack) * inv_az) : quarter_len);
  for (const Face& f : faces)
    if (f.half_rho > 0.0 && lo <= f.z_hi && hi >= f.z_lo) excess = std::max(excess, f.half_rho);
  double n = std::max(static_cast<double>(sagitta), std::ceil(angle * excess / tol));
  if (cross > 0.0) n = std::max(n, std::ceil(std::sqrt(angle * cross / tol)));
  return static_cast<int>(std::clamp(n, 1.0, static_cast<double>(kMaxTiltSubsteps)));
}

namespace {

// TwistBound::across for a part whose lowest axis point moves from a0 to a1 and whose axis
// span of length `len` turns by W (about the mean axis `a`, by `angle`): V(s) = (a1 − a0) +
// s·W across the axis, split along ŵ = W/|W| (c + s·|W|) and across it (n, fixed);
// |W·n̂|/|W| = |n|/|V(s)|, largest at the s in [0, 1] nearest to c + s·|W| = 0. The offset
// along V that brings Q onto the patch is at most |W|/|V| of the move, so it stays on the
// patch only where |W| <= |V|; elsewhere (a turn about a point of the part) 1. What the
// first order leaves out is of the order of the turn itself, added.
double across_share(const Vec3& a0, const Vec3& a1, const Vec3& w, const Vec3& a, double angle) noexcept {
  const double wl = norm(w);
  if (!(wl > 1e-12)) return 0.0;
  const Vec3 w_hat = (1.0 / wl) * w;
  Vec3 d = a1 - a0;
  d = d - dot(d, a) * a;
  const double c = dot(d, w_hat);
  const double n = norm(d - c * w_hat);
  const double s = std::clamp(-c / wl, 0.0, 1.0);
  const double v = std::hypot(n, c + s * wl);  // the least |V(s)| over [0, 1]
  return v >= wl ? std::min(1.0, n / v + angle) : 1.0;
}

}  // namespace

void Sweep::prepare_twist_bound(double turn_rad, double twist_tol_mm) noexcept {
  const CutterShape& s = *shape_;
  TwistBound& b = twist_;
  b.tol = std::max(s.chord_tol_mm, twist_tol_mm);
  b.angle = turn_rad;
  if (!(b.angle > 1e-12)) return;
  // The sagitta (an under-cut) keeps the chord tolerance whatever twist_tol_mm says.
  const double c = 1.0 - std::min(1.0, s.chord_tol_mm / std::hypot(top_, s.radius()));
  b.sagitta = static_cast<int>(std::clamp(std::ceil(b.angle / (2.0 * std::acos(c))), 1.0, static_cast<double>(kMaxTiltSubsteps)));
  // The part: axial heights [h0, top_], its flat ends' radii, its widest radius.
  double h0 = 0.0, rho = 0.0, end0 = 0.0, end1 = 0.0;
  if (s.capsule_radius_mm > 0.0) {
    h0 = std::min(s.capsule_radius_mm, top_);
    rho = end0 = end1 = s.core_radius_mm;
    b.ball = s.capsule_radius_mm;
  } else {
    h0 = s.stations.front().h;
    end0 = s.stations.front().r;
    end1 = s.radius_at(top_);
    for (std::size_t i = 0; i < s.stations.size(); ++i) {
      rho = std::max(rho, s.stations[i].r);
      if (i > 0 && s.stations[i - 1].h < top_) {
        const double g = (s.stations[i].r - s.stations[i - 1].r) / (s.stations[i].h - s.stations[i - 1].h);
        b.slope = std::max(b.slope, std::sqrt(1.0 + g * g));
      }
    }
  }
  const double len = top_ - h0;
  b.quarter_len = 0.25 * len;
  // Heights over both poses, widened by what the axis's arc between them may add.
  const double arc = (top_ + rho) * (1.0 - std::cos(0.5 * b.angle)) + 1e-9;
  auto widen = [](double& lo, double& hi, double z0, double z1) {
    lo = std::min(lo, std::min(z0, z1));
    hi = std::max(hi, std::max(z0, z1));
  };
  double az_min = INFINITY;
  b.z_lo = b.faces[0].z_lo = b.faces[1].z_lo = INFINITY;
  b.z_hi = b.faces[0].z_hi = b.faces[1].z_hi = -INFINITY;
  for (const Pose* p : {&from_, &to_}) {
    const double az = p->axis.z, sn = std::sqrt(std::max(0.0, 1.0 - az * az));
    az_min = std::min(az_min, az);
    const double z0 = p->tip.z + h0 * az, z1 = p->tip.z + top_ * az;
    widen(b.z_lo, b.z_hi, std::min(z0, z1) - rho * sn - arc, std::max(z0, z1) + rho * sn + arc);
    widen(b.faces[0].z_lo, b.faces[0].z_hi, z0 - end0 * sn - arc, z0 + end0 * sn + arc);
    widen(b.faces[1].z_lo, b.faces[1].z_hi, z1 - end1 * sn - arc, z1 + end1 * sn + arc);
  }
  // A flat end's offsets are along the axis; a face that moves along the axis by at least
  // 3ρφ (its centre's motion, less what the turn moves its rim) holds them in the region it
  // sweeps, |ε| <= t(1 − t) of the move from either end.
  const Vec3 mean_axis = normalized(from_.axis + to_.axis);
  auto face_term = [&](double h, double r) {
    const double along = std::abs(dot((to_.tip + h * to_.axis) - (from_.tip + h * from_.axis), mean_axis));
    return along >= 3.0 * r * b.angle ? 0.0 : 0.5 * r;
  };
  b.faces[0].half_rho = face_term(h0, end0);
  b.faces[1].half_rho = face_term(top_, end1);
  b.slack = 0.25 * (std::abs(to_.tip.z - from_.tip.z) + len * std::abs(to_.axis.z - from_.axis.z) + 2.0 * rho * b.angle);
  b.inv_az = az_min > 1e-3 ? 1.0 / az_min : 0.0;
  b.across = across_share(from_.tip + h0 * from_.axis, to_.tip + h0 * to_.axis, len * (to_.axis - from_.axis), mean_axis,
                          b.angle);
  if (s.capsule_radius_mm > 0.0 && s.core_radius_mm == 0.0) {
    // The capsule: the segment's ends' heights change by at most |Δtip.z| + L·|Δa.z|; over
    // a.z, which an axis at or below level (inv_az = 0) takes as 1/1000.
    b.quarter_len = 0.0;
    const double dz = std::abs(to_.tip.z - from_.tip.z) + top_ * std::abs(to_.axis.z - from_.axis.z);
    b.cross = 0.25 * dz * (b.inv_az > 0.0 ? b.inv_az : 1e3);
  }
}

int Sweep::substeps_at(double z_mm) const noexcept { return std::min(substeps_, twist_.count(z_mm)); }

Sweep::Sweep(const CutterShape& shape, const Pose& from, const Pose& to, double z_top_mm, double twist_tol_mm) noexcept
    : shape_(&shape), from_(from), to_(to) {
  from_.axis = normalized(from_.axis);
  to_.axis = normalized(to_.axis);
  vertical_ = vertical_poses(from, to);
  const double R = shape.radius(), H = shape.height();
  if (vertical_) {
    box_.add({from.tip.x - R, from.tip.y - R, from.tip.z});
    box_.add({from.tip.x + R, from.tip.y + R, from.tip.z + H});
    box_.add({to.tip.x - R, to.tip.y - R, to.tip.z});
    box_.add({to.tip.x + R, to.tip.y + R, to.tip.z + H});
    return;
  }
  // The part that may cut: up to the higher of the two poses' cut heights, and never below
  // the capsule's or core's centre. Between the poses the tool's points move on arcs, whose
  // lowest point lies at most their sagitta, reach·(1 − cos(φ/2)), below the chord between
  // the ends' (the tip moves linearly), so the cut height is taken that much lower.
  const double turn = std::acos(std::clamp(dot(from_.axis, to_.axis), -1.0, 1.0));
  const double dip = std::hypot(H, R) * (1.0 - std::cos(0.5 * turn)) + 1e-6;
  top_ = std::max(cut_height_below(shape, from_, z_top_mm + dip), cut_height_below(shape, to_, z_top_mm + dip));
  top_ = std::clamp(top_, std::min(H, shape.capsule_radius_mm), H);
  prepare_twist_bound(turn, twist_tol_mm);
  substeps_ = twist_.count(NAN);
  for (int k = 0; k <= substeps_; ++k) {
    const double t = static_cast<double>(k) / substeps_;
    const Pose p{lerp(from_.tip, to_.tip, t), normalized(lerp(from_.axis, to_.axis, t))};
    for_each_station_circle(shape, p, top_, [&](const Circle& ci) {
      const Vec3 c{ci.c.x, ci.c.y, ci.c.z};
      const Vec3 e{ci.r * std::sqrt(std::max(0.0, 1 - ci.n.x * ci.n.x)), ci.r * std::sqrt(std::max(0.0, 1 - ci.n.y * ci.n.y)),
                   ci.r * std::sqrt(std::max(0.0, 1 - ci.n.z * ci.n.z))};
      box_.add(c - e);
      box_.add(c + e);
    });
  }
}

std::size_t Sweep::section(double z_mm, Paths& out, SectionScratch& scratch, const PlaneMaterial* material) const {
  scratch.core = Capsule{};
  if (z_mm < box_.lo.z || z_mm > box_.hi.z) return 0;
  return vertical_ ? section_vertical(z_mm, out, scratch) : section_general(z_mm, out, scratch, material);
}

bool Sweep::section_disks(double zc, SectionScratch& sc) const {
  const CutterShape& s = *shape_;
  const double H = s.height();
  const double z0 = from_.tip.z, z1 = to_.tip.z, dz = z1 - z0;
  sc.disks.clear();
  // The end poses are taken as given (not as from + 1·(to - from)), so that a move's end
  // disk and the next move's start disk are the same disk to the last bit.
  auto disk_at = [&](double t) {
    const int role = t == 0.0 ? 1 : t == 1.0 ? 2 : 0;
    const double x = role == 1 ? from_.tip.x : role == 2 ? to_.tip.x : from_.tip.x + t * (to_.tip.x - from_.tip.x);
    const double y = role == 1 ? from_.tip.y : role == 2 ? to_.tip.y : from_.tip.y + t * (to_.tip.y - from_.tip.y);
    const double z = role == 1 ? z0 : role == 2 ? z1 : z0 + t * dz;
    sc.disks.push_back({x, y, s.radius_at(std::clamp(zc - z, 0.0, H)), 0.0, role});
  };
  if (dz == 0.0) {
    const double h = zc - z0;
    if (h < 0.0 || h > H) return false;
    disk_at(0.0);
    disk_at(1.0);
    return true;
  }
  // Parameter interval where the plane meets the cutting part: 0 <= zc - z(t) <= H.
  double ta = (zc - z0) / dz, tb = (zc - H - z0) / dz;
  if (ta > tb) std::swap(ta, tb);
  ta = std::max(ta, 0.0);
  tb = std::min(tb, 1.0);
  if (ta > tb) return false;
  disk_at(ta);
  for (const auto& st : s.stations) {
    const double t = (zc - st.h - z0) / dz;
    if (t > ta && t < tb) disk_at(t);
  }
  disk_at(tb);
  return true;
}

std::size_t Sweep::section_vertical(double zc, Paths& out, SectionScratch& sc) const {
  const CutterShape& s = *shape_;
  if (!section_disks(zc, sc)) return 0;
  double rmax = 0.0;
  for (const auto& d : sc.disks) rmax = std::max(rmax, d.r);
  if (rmax <= 0.0) return 0;
  const int n = circle_segments(rmax, s.chord_tol_mm);
  // Vertices at ρ = r·circle_grow_width(n): each disk's polygon has the disk's mean width
  // and deviates from its circle by at most tol on either side.
  const double grow = circle_grow_width(n);
  const std::vector<P2>& uc = sc.unit_circle(n);
  sc.hull.clear();
  if (sc.disks.size() == 2 && sc.disks[0].r == sc.disks[1].r) {
    // Horizontal move (the common case): the hull of two equal n-gons on one angle grid is
    // the far half of each, walked counter-clockwise: vertices of the end disk facing the
    // direction of motion, then those of the start disk facing away from it.
    const auto& a = sc.disks[0];
    const auto& b = sc.disks[1];
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double rho = a.r * grow;
    // The n-gons contain their inscribed circles, radius ρ·cos(π/n).
    const double r_in = rho * std::cos(std::numbers::pi / n);
    sc.core = Capsule{a.x, a.y, r_in, b.x, b.y, r_in};
    if (dx == 0.0 && dy == 0.0) {
      for (int k = 0; k < n; ++k) sc.hull.push_back({a.x + rho * uc[k].x, a.y + rho * uc[k].y});
    } else {
      // The side edges join the two polygons' extreme vertices in the directions normal to
      // the motion: grid indices k_right (θ - 90°) and k_left (θ + 90°).
      const double step = 2.0 * std::numbers::pi / n;
      const double th = std::atan2(dy, dx);
      auto nearest = [&](double ang) {
        const long k = std::lround(ang / step);
        return static_cast<int>(((k % n) + n) % n);
      };
      const int k_right = nearest(th - 0.5 * std::numbers::pi);
      const int k_left = nearest(th + 0.5 * std::numbers::pi);
      for (int k = k_right;; k = (k + 1) % n) {  // front half: end disk
        sc.hull.push_back({b.x + rho * uc[k].x, b.y + rho * uc[k].y});
        if (k == k_left) break;
      }
      for (int k = k_left;; k = (k + 1) % n) {  // back half: start disk
        sc.hull.push_back({a.x + rho * uc[k].x, a.y + rho * uc[k].y});
        if (k == k_right) break;
      }
    }
    return emit(sc.hull, out, sc.spare);
  }
  ramp_hull(sc, n, grow, uc, false);
  // Capsule: the disk farthest along the motion and the largest one (or the first).
  {
    const auto& ds = sc.disks;  // sorted by s, radii are circumradii now
    std::size_t big = 0;
    for (std::size_t i = 1; i < ds.size(); ++i)
      if (ds[i].r > ds[big].r) big = i;
    const std::size_t last = ds.size() - 1;
    const std::size_t other = big != last ? big : 0;
    const double c = std::cos(std::numbers::pi / n);
    sc.core = Capsule{ds[other].x, ds[other].y, ds[other].r * c, ds[last].x, ds[last].y, ds[last].r * c};
  }
  return emit(sc.hull, out, sc.spare);
}

namespace {

// Upper envelope (max) of the lines L_d(h) = s_d·h + ρ_d of sc.disks (sorted by slope) over
// all h, in sc.env; sc.breaks[i] is where env[i] overtakes env[i-1] (ramp_hull()).
void upper_envelope(SectionScratch& sc) {
  auto& disks = sc.disks;
  auto& env = sc.env;
  auto& br = sc.breaks;
  env.clear();
  br.clear();
  auto cross_at = [&](int a, int b) { return (disks[a].r - disks[b].r) / (disks[b].s - disks[a].s); };
  for (int i = 0; i < static_cast<int>(disks.size()); ++i) {
    if (!env.empty() && disks[env.back()].s == disks[i].s) {  // same slope: the larger ρ (later) wins
      env.pop_back();
      br.pop_back();
    }
    while (!env.empty()) {
      const double x = cross_at(env.back(), i);
      if (env.size() >= 2 && x <= br.back()) {
        env.pop_back();
        br.pop_back();
        continue;
      }
      env.push_back(i);
      br.push_back(x);
      break;
    }
    if (env.empty()) {
      env.push_back(i);
      br.push_back(-INFINITY);
    }
  }
}

}  // namespace

// The last direction of the run of directions from k (which lies in a cap) that the same cap
// wins whole: `want` is cap(k), 0 for the start cap (h < b at both of its wedge's edges),
// else the end cap (h >= b), with b the envelope's break beside the cap. The cap is an arc of the
// circle: with a = π/n, h = cos(φ ∓ a)/cos a at the wedge's edges (φ = θ_k − θ_e), so the
// start cap is φ in (α + a, 2π − α − a) and the end cap φ in [−α' + a, α' − a], α = acos(b
// cos a). The arc's end on the grid is estimated from that and settled by cap() itself, in
// which the run's directions lie up to where it stops (the grid's last direction at most).
template <class Cap>
int cap_run_end(int k, int want, double b, int n, double ex, double ey, const Cap& cap) {
  const bool start = want == 0;
  const double step = 2.0 * std::numbers::pi / n, a = std::numbers::pi / n;
  const double alpha = std::acos(std::clamp(b * std::cos(a), -1.0, 1.0));
  const double th_e = std::atan2(ey, ex);
  double end = (start ? th_e + 2.0 * std::numbers::pi - alpha - a : th_e + alpha - a) / step;  // [grid steps]
  if (!std::isfinite(end)) end = k;
  end -= n * std::floor((end - k) / n);  // the arc's end at or after k, within one turn
  int e = static_cast<int>(std::min<double>(n - 1, std::floor(end)));
  while (e > k && cap(e) != want) --e;
  while (e + 1 < n && cap(e + 1) == want) ++e;
  return e;
}

// Hull of several n-gons on one angle grid whose centres lie on the line of motion (a ramp),
// without sorting points. Disk d has centre c0 + s_d·e (e: unit horizontal direction of the
// motion) and circumradius ρ_d. For a direction θ = θ_k + δ with |δ| <= π/n the support
// point of n-gon d is its vertex k, with value c_d·u(θ) + ρ_d·cos δ. Dividing by cos δ > 0,
// the disk that wins is the one maximising the line L_d(h) = s_d·h + ρ_d at
//   h = e·u(θ) / cos δ = cos φ - sin φ·tan δ,   φ = θ_k - θ_e,
// which is monotone in δ. So: build the upper envelope of the lines once (slopes sorted),
// then for each grid direction k walk the envelope from h(-π/n) to h(+π/n) and emit vertex k
// of each winner. As θ grows the support point runs over the hull's vertices
// counter-clockwise, so the output is the hull in order, in O(n + disks).
void Sweep::ramp_hull(SectionScratch& sc, int n, double grow, const std::vector<P2>& uc, bool ends_only) const {
  double ex = to_.tip.x - from_.tip.x, ey = to_.tip.y - from_.tip.y;
  const double len = std::hypot(ex, ey);
  if (len > 0.0) {
    ex /= len;
    ey /= len;
  } else {
    ex = 1.0;
    ey = 0.0;
  }
  auto& disks = sc.disks;
  for (auto& d : disks) {
    d.s = len > 0.0 ? (d.x - from_.tip.x) * ex + (d.y - from_.tip.y) * ey : 0.0;
    d.r *= grow;  // from here on, r is the circumradius ρ
  }
  // Few disks (the tool's stations): insertion sort by slope, then by intercept.
  for (std::size_t i = 1; i < disks.size(); ++i) {
    const auto d = disks[i];
    std::size_t j = i;
    while (j > 0 && (disks[j - 1].s > d.s || (disks[j - 1].s == d.s && disks[j - 1].r > d.r))) {
      disks[j] = disks[j - 1];
      --j;
    }
    disks[j] = d;
  }
  upper_envelope(sc);
  const auto& env = sc.env;
  const auto& br = sc.breaks;
  const int m = static_cast<int>(env.size());
  // Index of the envelope piece that wins at h.
  auto piece = [&](double h) {
    int lo = 0, hi = m - 1;  // br[0] = -inf <= h
    while (lo < hi) {
      const int mid = (lo + hi + 1) / 2;
      if (br[mid] <= h) lo = mid;
      else hi = mid - 1;
    }
    return lo;
  };
  const double T = sc.half_step_tan(n);
  // Inside a cap one disk wins the whole wedge of direction k: piece(h) is m-1 exactly when
  // br[m-1] <= h and 0 exactly when h < br[1], so the two searches are needed only between.
  // wedge(k): h at the two edges of direction k's wedge; cap_of(): 0 or m-1 for a wedge one
  // cap wins whole, -1 for one that needs the searches.
  struct Wedge {
    double hp, hm;
  };
  auto wedge = [&](int k) {
    const double ck = uc[k].x, sk = uc[k].y;
    const double cphi = ck * ex + sk * ey, sphi = sk * ex - ck * ey;
    return Wedge{cphi + sphi * T, cphi - sphi * T};
  };
  auto cap_of = [&](const Wedge& w) {
    if (m == 1 || (w.hp < br[1] && w.hm < br[1])) return 0;
    if (w.hp >= br[m - 1] && w.hm >= br[m - 1]) return m - 1;
    return -1;
  };
  auto cap = [&](int k) { return cap_of(wedge(k)); };
  sc.hull.clear();
  sc.hull_role.clear();
  sc.hull_grid.clear();
  int run_piece = -1, run_len = 0;
  for (int k = 0; k < n; ++k) {
    const double ck = uc[k].x, sk = uc[k].y;
    const Wedge w = wedge(k);
    const int whole_cap = cap_of(w);
    int i0 = whole_cap, i1 = whole_cap;
    if (whole_cap < 0) {
      i0 = piece(w.hp);
      i1 = piece(w.hm);
    }
    // ends_only: a run of directions that one end disk wins whole keeps its first and last
    // vertex (the caps' grid interval is all section_caps() needs of it).
    const bool whole = i0 == i1 && disks[env[i0]].role != 0;
    if (ends_only && whole && i0 == run_piece && run_len >= 2) {
      // With one envelope piece (m == 1) that piece wins every direction: the run goes to the
      // grid's end (and br[1] does not exist).
      const int last = whole_cap < 0 ? k
                       : m == 1      ? n - 1
                                     : cap_run_end(k, whole_cap, whole_cap == 0 ? br[1] : br[m - 1], n, ex, ey, cap);
      const auto& d = disks[env[i0]];
      sc.hull.back() = {d.x + d.r * uc[last].x, d.y + d.r * uc[last].y};
      sc.hull_grid.back() = last;
      k = last;
      continue;
    }
    run_len = !whole ? 0 : i0 == run_piece ? run_len + 1 : 1;
    run_piece = whole ? i0 : -1;
    const int step = i1 >= i0 ? 1 : -1;
    for (int i = i0;; i += step) {
      const auto& d = disks[env[i]];
      sc.hull.push_back({d.x + d.r * ck, d.y + d.r * sk});
      sc.hull_role.push_back(static_cast<std::uint8_t>(d.role));
      sc.hull_grid.push_back(k);
      if (i == i1) break;
    }
  }
}

double Sweep::widest_disk_mm(double zc, SectionScratch& sc) const {
  if (!vertical_ || zc < box_.lo.z || zc > box_.hi.z || !section_disks(zc, sc)) return 0.0;
  double r = 0.0;
  for (const auto& d : sc.disks) r = std::max(r, d.r);
  return r;
}

bool Sweep::section_caps(double zc, int n, SectionScratch& sc, MoveCaps& out) const {
  if (!vertical_ || zc < box_.lo.z || zc > box_.hi.z) return false;
  const double dx = to_.tip.x - from_.tip.x, dy = to_.tip.y - from_.tip.y;
  if (dx == 0.0 && dy == 0.0) return false;
  if (!section_disks(zc, sc)) return false;
  const auto& ds = sc.disks;
  if (ds.front().role != 1 || ds.back().role != 2 || !(ds.front().r > 0.0) || !(ds.back().r > 0.0)) return false;
  const double grow = circle_grow_width(n);
  out.c0 = {ds.front().x, ds.front().y};
  out.c1 = {ds.back().x, ds.back().y};
  out.rho0 = ds.front().r * grow;
  out.rho1 = ds.back().r * grow;
  out.right.clear();
  out.left.clear();
  const bool uniform = std::all_of(ds.begin(), ds.end(), [&](const auto& d) { return d.r == ds.front().r; });
  if (uniform) {
    // Equal disks on one grid: the hull is the far half of each (section_vertical()), the
    // sides are single edges between the grid vertices normal to the motion.
    const double step = 2.0 * std::numbers::pi / n;
    const double th = std::atan2(dy, dx);
    auto nearest = [&](double ang) {
      const long k = std::lround(ang / step);
      return static_cast<int>(((k % n) + n) % n);
    };
    out.front_r = out.back_r = nearest(th - 0.5 * std::numbers::pi);
    out.front_l = out.back_l = nearest(th + 0.5 * std::numbers::pi);
    return true;
  }
  ramp_hull(sc, n, grow, sc.unit_circle(n), true);
  // The caps are the hull's runs of start-disk and end-disk vertices; each must be one run.
  const std::size_t m = sc.hull.size();
  // One pass: where each role's run starts and ends (a role with two runs, or none, fails).
  const std::uint8_t* role = sc.hull_role.data();
  std::size_t first[3] = {0, 0, 0}, last[3] = {0, 0, 0};
  int starts[3] = {0, 0, 0}, ends[3] = {0, 0, 0};
  for (std::size_t i = 0, prev = m - 1; i < m; prev = i++) {
    if (role[i] != role[prev]) {
      ++starts[role[i]];
      first[role[i]] = i;
      ++ends[role[prev]];
      last[role[prev]] = prev;
    }
  }
  auto run_of = [&](std::uint8_t r, std::size_t& f, std::size_t& l) {
    if (starts[r] != 1 || ends[r] != 1) return false;
    f = first[r];
    l = last[r];
    return true;
  };
  std::size_t s0 = 0, s1 = 0, e0 = 0, e1 = 0;
  if (m < 3 || !run_of(1, s0, s1) || !run_of(2, e0, e1)) return false;
  out.back_l = sc.hull_grid[s0];
  out.back_r = sc.hull_grid[s1];
  out.front_r = sc.hull_grid[e0];
  out.front_l = sc.hull_grid[e1];
  auto copy_between = [&](std::size_t after, std::size_t before, std::vector<P2>& to) {
    for (std::size_t i = after + 1 == m ? 0 : after + 1; i != before; i = i + 1 == m ? 0 : i + 1) to.push_back(sc.hull[i]);
  };
  copy_between(s1, e0, out.right);
  copy_between(e1, s0, out.left);
  return true;
}

namespace {

// Drops the vertices of convex polygon b for which inside() holds, keeping the first and
// last vertex of each such run (what b loses is the hull of a run, which lies inside the
// covering region when that is convex). False when every vertex is inside.
template <class Inside>
bool trim_inside(Path& b, std::vector<std::uint8_t>& flags, Inside inside) {
  const std::size_t n = b.size();
  flags.resize(n);
  std::size_t in_count = 0, start = n;
  for (std::size_t i = 0; i < n; ++i) {
    const bool in = inside(b[i]);
    flags[i] = in ? 1 : 0;
    in_count += in ? 1 : 0;
    if (!in && start == n) start = i;
  }
  if (start == n) return false;
  if (in_count <= 2) return true;
  // From an outside vertex on, keep the outside vertices and both ends of each inside run;
  // written in place (the write index never passes the read index).
  std::rotate(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(start), b.end());
  std::rotate(flags.begin(), flags.begin() + static_cast<std::ptrdiff_t>(start), flags.end());
  std::size_t w = 0, i = 0;
  while (i < n) {
    if (flags[i] == 0) {
      b[w++] = b[i++];
      continue;
    }
    std::size_t j = i;
    while (j < n && flags[j] != 0) ++j;
    b[w++] = b[i];
    if (j - i >= 2) b[w++] = b[j - 1];
    i = j;
  }
  b.resize(w);
  return true;
}

}  // namespace

bool trim_covered(Path& b, const Capsule& a, std::vector<std::uint8_t>& flags, double margin) {
  const std::size_t n = b.size();
  if (!a.valid() || n < 4) return true;
  // The capsule in kernel units, shrunk by the margin; IQ's uneven-capsule test in the frame
  // where c1 is the origin and the axis runs along +y.
  const double k = kUnitsPerMm;
  const double x1 = a.x1 * k, y1 = a.y1 * k, x2 = a.x2 * k, y2 = a.y2 * k;
  const double r1 = a.r1 * k - margin, r2 = a.r2 * k - margin;
  if (r1 <= 0.0 && r2 <= 0.0) return true;
  const double dx = x2 - x1, dy = y2 - y1, h = std::hypot(dx, dy);
  const double bx0 = std::min(x1 - r1, x2 - r2), bx1 = std::max(x1 + r1, x2 + r2);
  const double by0 = std::min(y1 - r1, y2 - r2), by1 = std::max(y1 + r1, y2 + r2);
  auto inside = [&](const Point& q) {
    const double qx = static_cast<double>(q.X), qy = static_cast<double>(q.Y);
    if (qx <= bx0 || qx >= bx1 || qy <= by0 || qy >= by1) return false;
    if (h <= std::abs(r1 - r2)) {  // one disk holds the other
      const bool first = r1 >= r2;
      const double ex = qx - (first ? x1 : x2), ey = qy - (first ? y1 : y2), r = first ? r1 : r2;
      return r > 0.0 && ex * ex + ey * ey <= r * r;
    }
    const double ux = dx / h, uy = dy / h;
    const double along = (qx - x1) * ux + (qy - y1) * uy;
    const double perp = std::abs((qx - x1) * uy - (qy - y1) * ux);
    const double bb = (r1 - r2) / h, aa = std::sqrt(1.0 - bb * bb);
    const double kk = -bb * perp + aa * along;
    if (kk < 0.0) return r1 > 0.0 && perp * perp + along * along <= r1 * r1;
    if (kk > aa * h) return r2 > 0.0 && perp * perp + (along - h) * (along - h) <= r2 * r2;
    return aa * perp + bb * along <= r1;
  };
  return trim_inside(b, flags, inside);
}

const std::vector<SectionScratch::P2>& SectionScratch::unit_circle(int n) {
  if (static_cast<std::size_t>(n) >= circles_.size()) {
    circles_.resize(static_cast<std::size_t>(n) + 1);
    half_step_tans_.resize(static_cast<std::size_t>(n) + 1);
  }
  auto& c = circles_[static_cast<std::size_t>(n)];
  if (c.empty()) {
    c.resize(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * k / n;
      c[static_cast<std::size_t>(k)] = {std::cos(a), std::sin(a)};
    }
    half_step_tans_[static_cast<std::size_t>(n)] = std::tan(std::numbers::pi / n);
  }
  return c;
}

double SectionScratch::half_step_tan(int n) {
  (void)unit_circle(n);
  return half_step_tans_[static_cast<std::size_t>(n)];
}

namespace {

constexpr double kPointEps = 0.05;  // boundary points to tol/20 (of the chord tolerance)

// How far inside a cover a refinement triangle must lie: the points' accuracy and a kernel
// unit for the rounding of the cover's polygon.
double cover_margin(double tol) noexcept { return kPointEps * tol + 1.0 / kUnitsPerMm; }

// The kDirs directions of the coarse points as unit vectors (cos, sin of 2πi/kDirs).
const std::array<SectionScratch::P2, TiltedPiece::kDirs>& coarse_directions() noexcept {
  static const std::array<SectionScratch::P2, TiltedPiece::kDirs> dirs = [] {
    std::array<SectionScratch::P2, TiltedPiece::kDirs> d{};
    for (int i = 0; i < TiltedPiece::kDirs; ++i) {
      const double a = 2.0 * std::numbers::pi * i / TiltedPiece::kDirs;
      d[static_cast<std::size_t>(i)] = {std::cos(a), std::sin(a)};
    }
    return d;
  }();
  return dirs;
}

// The boundary of the section of piece p's hull on its plane, as support points in angular
// order (counter-clockwise) appended to sc.pts, starting from the piece's coarse points.
// Between the support points a and b of directions φa < φb the boundary lies in the
// triangle of the chord ab and the two support lines (convexity), whose height over the
// chord is at most |ab|/2 · tan((φb − φa)/2) (base angles summing to φb − φa). An interval
// is split at its middle direction until that bound is within tol less the point accuracy
// (the tolerance's one-sided bound for tilted sections), so every vertex is
// evaluated once and kept; a middle point on the chord (within the point accuracy) proves
// the boundary straight there (the support line through it holds a and b) and ends the
// split as well. So does a triangle (support lines moved out by the point accuracy) that
// lies inside a cover's coarse polygon: what the chord leaves out there is removed by the
// cover's own polygon.
// The cap of the section beyond chord ab of coarse directions a and b (the section there)
// lies in the triangle that the chord's line cuts from their support lines at the proven
// bounds (a and b lie in the section, so on their inner sides): true when the plane's
// material meets none of it, so that the chord leaves out nothing the difference would
// remove. Tested on the coarse intervals only: on finish5x, testing their halves and
// quarters too cost 9.68 G instructions against 9.18 G.
bool cap_in_air(const PlaneMaterial& material, const SectionScratch::Dir& a, const SectionScratch::Dir& b) {
  if (!(a.h < INFINITY && b.h < INFINITY)) return false;
  const double ex = b.p.x - a.p.x, ey = b.p.y - a.p.y;
  const double da = a.u.x * ex + a.u.y * ey, db = b.u.x * ex + b.u.y * ey;
  const double det = a.u.x * b.u.y - a.u.y * b.u.x;
  if (!(da < 0.0 && db > 0.0 && det > 1e-12)) return false;
  const double sa = (a.h - (a.u.x * a.p.x + a.u.y * a.p.y)) / da;  // <= 0: before a
  const double sb = (b.h - (b.u.x * a.p.x + b.u.y * a.p.y)) / db;  // >= 1: after b
  const P2 apex{(a.h * b.u.y - b.h * a.u.y) / det, (a.u.x * b.h - b.u.x * a.h) / det};
  if (!(ey * (apex.x - a.p.x) - ex * (apex.y - a.p.y) >= 0.0)) return false;  // apex beyond the chord
  const P2 tri[3] = {{a.p.x + sb * ex, a.p.y + sb * ey}, {a.p.x + sa * ex, a.p.y + sa * ey}, apex};
  return !material.may_meet(std::span<const P2>(tri, 3));
}

void refine_section(const Hull3& hull, const TiltedPiece& p, double tol, const Sweep::PieceCovers& rc,
                    SectionScratch& sc) {
  const TiltedPiece* cover0 = rc.before;
  const TiltedPiece* cover1 = rc.after;
  const ConvexCover* last = rc.last;
  constexpr int kStart = TiltedPiece::kDirs;
  constexpr int kMaxPoints = 8192;
  constexpr int kWarmSteps = 1;  // a middle direction starts from its neighbours' brackets
  const double eps = kPointEps * tol;
  // The chord may leave out up to tol of the section, less the points' own accuracy.
  const double max_gap2 = (tol - eps) * (tol - eps);
  const double zc = p.zc;
  struct Iv {
    P2 ua, ub;  // the directions of a and b
    P2 a, b;
    double ta_lo, ta_hi, tb_lo, tb_hi;
    int depth;
    int ma, mb;  // which covers hold a and b (bit 0: cover0, bit 1: cover1; −1: not known yet)
  };
  // tan(Δφ/2) of an interval at each depth (Δφ = 2π/kStart/2^depth); beyond the table, the
  // last entry bounds it.
  constexpr int kDepths = 41;
  static const std::array<double, kDepths> tan_half = [] {
    std::array<double, kDepths> t{};
    for (int d = 0; d < kDepths; ++d) t[static_cast<std::size_t>(d)] = std::tan(std::numbers::pi / kStart / std::ldexp(1.0, d));
    return t;
  }();
  // The triangle of interval iv lies inside a cover (its three corners do; margin: the
  // point accuracy and a kernel unit for the rounding of the cover's polygon). Which covers
  // hold a point is found once per point: each end is shared by two intervals.
  const double margin = cover_margin(tol);
  const bool any_cover = cover0 != nullptr || cover1 != nullptr || last != nullptr;
  auto mask_of = [&](const P2& q) {
    return (cover0 != nullptr && cover0->covers(q, margin) ? 1 : 0) | (cover1 != nullptr && cover1->covers(q, margin) ? 2 : 0) |
           (last != nullptr && last->contains(q) ? 4 : 0);
  };
  auto covered = [&](Iv& iv) {
    if (!any_cover) return false;
    if (iv.ma < 0) iv.ma = mask_of(iv.a);
    if (iv.mb < 0) iv.mb = mask_of(iv.b);
    const int both = iv.ma & iv.mb;
    if (both == 0) return false;
    const double ax = iv.ua.x, ay = iv.ua.y, bx = iv.ub.x, by = iv.ub.y;
    const double ha = ax * iv.a.x + ay * iv.a.y + eps, hb = bx * iv.b.x + by * iv.b.y + eps;
    const double det = ax * by - ay * bx;  // sin(φb − φa) > 0
    if (!(det > 1e-12)) return false;
    const P2 apex{(ha * by - hb * ay) / det, (ax * hb - bx * ha) / det};
    return ((both & 1) != 0 && cover0->covers(apex, margin)) || ((both & 2) != 0 && cover1->covers(apex, margin)) ||
           ((both & 4) != 0 && last->contains(apex));
  };
  int coarse_mask[kStart];
  std::fill(std::begin(coarse_mask), std::end(coarse_mask), -1);
  sc.pts.clear();
  for (int i = 0; i < kStart; ++i) {
    const int j = (i + 1) % kStart;
    const auto& di = p.dirs[i];
    const auto& dj = p.dirs[j];
    Iv stack[64];
    int sp = 0;
    stack[sp++] = {di.u, dj.u, di.p, dj.p, di.t_lo, di.t_hi, dj.t_lo, dj.t_hi, 0, coarse_mask[i], coarse_mask[j]};
    while (sp > 0) {
      Iv iv = stack[--sp];
      const double dx = iv.b.x - iv.a.x, dy = iv.b.y - iv.a.y;
      const double bound = 0.5 * tan_half[static_cast<std::size_t>(std::min(iv.depth, kDepths - 1))];  // |ab|/2 · tan(Δφ/2) / |ab|
      const bool fine = iv.depth >= 40 || static_cast<int>(sc.pts.size()) >= kMaxPoints || sp + 2 > 64 ||
                        bound * bound * (dx * dx + dy * dy) <= max_gap2;
      const bool done = fine || covered(iv) ||
                        (iv.depth == 0 && rc.material != nullptr && cap_in_air(*rc.material, di, dj));
      if (iv.depth == 0) {  // the coarse ends' covers, for the intervals beside
        coarse_mask[i] = iv.ma;
        coarse_mask[j] = iv.mb;
      }
      if (done) {
        sc.pts.push_back(iv.a);
        continue;
      }
      const double ca = 0.5 * (iv.ta_lo + iv.ta_hi), cb = 0.5 * (iv.tb_lo + iv.tb_hi);
      const double hw = std::max(0.125 * std::abs(ca - cb), 0.5 * std::max(iv.ta_hi - iv.ta_lo, iv.tb_hi - iv.tb_lo));
      double mlo = 0.5 * (ca + cb) - hw, mhi = 0.5 * (ca + cb) + hw;
      // (cos pm, sin pm) without the trigonometry: the bisector of the ends' unit vectors
      // (their angle is at most 2π/kStart, far below π).
      const double bx = iv.ua.x + iv.ub.x, by = iv.ua.y + iv.ub.y, bl = std::sqrt(bx * bx + by * by);
      const P2 um{bx / bl, by / bl};
      const P2 m = hull.section_point(um.x, um.y, zc, eps, mlo, mhi, kWarmSteps);
      if (dist_to_line(m, iv.a, iv.b) <= eps) {
        sc.pts.push_back(iv.a);
        sc.pts.push_back(m);
        continue;
      }
      stack[sp++] = {um, iv.ub, m, iv.b, mlo, mhi, iv.tb_lo, iv.tb_hi, iv.depth + 1, -1, iv.mb};  // right half last
      stack[sp++] = {iv.ua, um, iv.a, m, iv.ta_lo, iv.ta_hi, mlo, mhi, iv.depth + 1, iv.ma, -1};
    }
  }
}

// The box of station circles c[0..n) and their centres' mean.
HullBox circles_box(const Circle* c, int n) noexcept {
  HullBox b;
  for (int i = 0; i < n; ++i) {
    const double ex = c[i].r * std::sqrt(std::max(0.0, 1.0 - c[i].n.x * c[i].n.x));
    const double ey = c[i].r * std::sqrt(std::max(0.0, 1.0 - c[i].n.y * c[i].n.y));
    b.x0 = std::min(b.x0, c[i].c.x - ex);
    b.x1 = std::max(b.x1, c[i].c.x + ex);
    b.y0 = std::min(b.y0, c[i].c.y - ey);
    b.y1 = std::max(b.y1, c[i].c.y + ey);
    b.cx += c[i].c.x / n;
    b.cy += c[i].c.y / n;
  }
  return b;
}

// True when the sub-step's hull (box b) certainly misses the material box `m` [units] in
// XY: the boxes are apart, or the horizontal direction u from the box's centre to b's
// centre point separates them (the hull's least u·p, one support query, beyond the box's
// greatest). The section on any plane lies in the hull, so it would remove nothing.
bool beside_material(const Hull3& hull, const HullBox& b, const Rect& m) noexcept {
  if (m.empty()) return true;
  const double mx0 = to_mm(m.x0), mx1 = to_mm(m.x1), my0 = to_mm(m.y0), my1 = to_mm(m.y1);
  if (b.x1 < mx0 || b.x0 > mx1 || b.y1 < my0 || b.y0 > my1) return true;
  const double ux = b.cx - 0.5 * (mx0 + mx1), uy = b.cy - 0.5 * (my0 + my1), ul = std::sqrt(ux * ux + uy * uy);
  if (!(ul > 0.0)) return false;
  const Vec3 u{ux / ul, uy / ul, 0.0};
  const double hull_min = dot(hull.support(Vec3{-u.x, -u.y, 0.0}), u);
  const double box_max = std::max(u.x * mx0, u.x * mx1) + std::max(u.y * my0, u.y * my1);
  return hull_min > box_max;
}

// The z-range of sub-step a→b's hull [mm] and, when `box`, its XY box: the capsule's and the
// rounded core's from their exact hull (no station circles), the station model's from its
// circles at both poses.
void substep_extent(const CutterShape& s, const Hull3& hull, const Pose& a, const Pose& b, double top, double& zlo,
                    double& zhi, HullBox* box) noexcept {
  zlo = -INFINITY;
  zhi = INFINITY;
  if (s.capsule_radius_mm > 0.0) {
    hull.clamp_z_extent(zlo, zhi);
    if (box != nullptr) *box = hull.xy_extent();
    return;
  }
  Circle circles[2 * kMaxStations];
  int nc = station_circles(s, a, top, circles);
  nc += station_circles(s, b, top, circles + nc);
  zlo = INFINITY;
  zhi = -INFINITY;
  for (int i = 0; i < nc; ++i) {
    const double e = circles[i].r * std::sqrt(std::max(0.0, 1.0 - circles[i].n.z * circles[i].n.z));
    zlo = std::min(zlo, circles[i].c.z - e);
    zhi = std::max(zhi, circles[i].c.z + e);
  }
  if (box != nullptr) *box = circles_box(circles, nc);
}

// A pseudo-angle of (dx, dy) in [0, 4): increasing with the angle from +x counter-clockwise.
double pseudo_angle(double dx, double dy) noexcept {
  const double s = std::abs(dx) + std::abs(dy);
  if (!(s > 0.0)) return 0.0;
  return dy >= 0.0 ? 1.0 - dx / s : 3.0 + dx / s;
}

// Coarse direction i of piece p, its search started from the previous piece's final
// bracket in the same direction when there is one (`prev`: the sub-step before on the same
// plane, whose tilt there differs little), else from [tlo, thi] (the last direction's; the
// first from [−1, 1], with at least 5 steps). With the piece before that too (`prev2`), the
// bracket is moved by the shift of its centre from prev2 to prev and widened by a quarter
// of it on either side: the tilt drifts steadily along a move, and a bracket left where
// prev's was missed the root by ~10 of its widths, which cost 4 widening queries per coarse
// point (finish5x's ball raster: 1.70 M of 4.21 M coarse queries; 0.30 M of 2.93 M with the
// shift).
void coarse_direction(const Hull3& hull, double eps, const TiltedPiece* prev, const TiltedPiece* prev2, int i,
                      double& tlo, double& thi, TiltedPiece& p) {
  int min_steps = 4;
  if (prev != nullptr) {
    tlo = prev->dirs[i].t_lo;
    thi = prev->dirs[i].t_hi;
    min_steps = 1;
    if (prev2 != nullptr) {
      const double shift = 0.5 * (tlo + thi - prev2->dirs[i].t_lo - prev2->dirs[i].t_hi);
      const double h = 0.25 * std::abs(shift);
      tlo += shift - h;
      thi += shift + h;
    }
  }
  const P2 u = coarse_directions()[static_cast<std::size_t>(i)];
  double h = INFINITY;
  const P2 q = hull.section_point(u.x, u.y, p.zc, eps, tlo, thi, min_steps, &h);
  p.dirs[i] = {u, q, tlo, thi, h};
}

// Q's half-planes, box, and inner and outer disks from p's coarse points.
void coarse_polygon(TiltedPiece& p) {
  constexpr int n = TiltedPiece::kDirs;
  p.edge_count = 0;
  p.x0 = p.x1 = p.dirs[0].p.x;
  p.y0 = p.y1 = p.dirs[0].p.y;
  for (int i = 0; i < n; ++i) {
    const P2 a = p.dirs[i].p, b = p.dirs[(i + 1) % n].p;
    p.x0 = std::min(p.x0, a.x);
    p.x1 = std::max(p.x1, a.x);
    p.y0 = std::min(p.y0, a.y);
    p.y1 = std::max(p.y1, a.y);
    const double ex = b.x - a.x, ey = b.y - a.y, l = std::sqrt(ex * ex + ey * ey);  // mm: not the slower hypot
    if (!(l > 1e-9)) continue;  // coinciding points: no edge
    const double nx = ey / l, ny = -ex / l;  // outward for a counter-clockwise polygon
    p.edges[p.edge_count++] = {nx, ny, nx * a.x + ny * a.y};
  }
  if (p.edge_count < 3) {
    p.edge_count = 0;  // no area: covers nothing
    return;
  }
  p.cx = p.cy = 0.0;
  for (int i = 0; i < n; ++i) {
    p.cx += p.dirs[i].p.x / n;
    p.cy += p.dirs[i].p.y / n;
  }
  p.r_in = INFINITY;
  p.r_out2 = 0.0;
  for (int i = 0; i < p.edge_count; ++i) p.r_in = std::min(p.r_in, p.edges[i].c - (p.edges[i].nx * p.cx + p.edges[i].ny * p.cy));
  for (int i = 0; i < n; ++i) {
    const double dx = p.dirs[i].p.x - p.cx, dy = p.dirs[i].p.y - p.cy;
    p.r_out2 = std::max(p.r_out2, dx * dx + dy * dy);
  }
}

// A piece whose axis directions' box already clears the material: the other directions take
// the brackets their searches would have started from (the next piece's warm start), and Q
// covers nothing.
void mark_in_air(const TiltedPiece* prev, TiltedPiece& p) noexcept {
  constexpr int n = TiltedPiece::kDirs, axis = n / 4;
  for (int i = 0; i < n; ++i) {
    if (i % axis == 0) continue;
    const SectionScratch::Dir& from = prev != nullptr ? prev->dirs[i] : p.dirs[i - i % axis];
    p.dirs[i] = {coarse_directions()[static_cast<std::size_t>(i)], from.p, from.t_lo, from.t_hi, INFINITY};
  }
  p.edge_count = 0;
  p.in_air = true;
}

// The coarse points of piece p (its kDirs directions, coarse_direction()) and Q's
// half-planes (coarse_polygon()). With `material`, the axis directions go first, and a piece
// whose box of their bounds meets no material stops there (mark_in_air()). (The polygon of
// all 16 bounds as a second test found 3 600 more such pieces of finish5x's 246 000 and cost
// more than they did: 4.5 % of the run.)
void coarse_section(const Hull3& hull, double tol, const TiltedPiece* prev, const TiltedPiece* prev2,
                    const PlaneMaterial* material, TiltedPiece& p) {
  constexpr int n = TiltedPiece::kDirs, axis = n / 4;
  const double eps = kPointEps * tol;
  double tlo = -1.0, thi = 1.0;
  P2 box[4];
  p.in_air = false;
  if (material == nullptr) {
    for (int i = 0; i < n; ++i) coarse_direction(hull, eps, prev, prev2, i, tlo, thi, p);
  } else {
    for (int i = 0; i < n; i += axis) coarse_direction(hull, eps, prev, prev2, i, tlo, thi, p);
    if (p.axis_box(box) && !material->may_meet(std::span<const P2>(box, 4))) {
      mark_in_air(prev, p);
      return;
    }
    for (int i = 1; i < n; ++i) {
      if (i % axis == 0) continue;
      tlo = p.dirs[i - 1].t_lo;
      thi = p.dirs[i - 1].t_hi;
      coarse_direction(hull, eps, prev, prev2, i, tlo, thi, p);
    }
  }
  coarse_polygon(p);
}

}  // namespace

void ConvexCover::build(const std::vector<SectionPoint>& hull, double margin_mm) {
  v_.clear();
  kept_.clear();
  const double min_len2 = 16.0 * margin_mm * margin_mm;  // edges of at least 4 margins
  auto far = [&](const P2& a, const P2& b) { return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) >= min_len2; };
  for (const P2& q : hull)
    if (kept_.empty() || far(q, kept_.back())) kept_.push_back(q);
  while (kept_.size() >= 3 && !far(kept_.front(), kept_.back())) kept_.pop_back();
  const std::size_t n = kept_.size();
  if (n < 3) return;
  // Edge j runs from kept_[j] to kept_[j + 1]; its outward normal is (dy, −dx)/l. Vertex j
  // moves to where its two edges' lines meet once moved in by the margin.
  auto normal = [&](std::size_t j) {
    const P2& a = kept_[j];
    const P2& b = kept_[(j + 1) % n];
    const double dx = b.x - a.x, dy = b.y - a.y, l = std::sqrt(dx * dx + dy * dy);
    return P2{dy / l, -dx / l};
  };
  v_.resize(n);
  P2 prev = normal(n - 1);
  for (std::size_t j = 0; j < n; ++j) {
    const P2 nj = normal(j);
    const double d = 1.0 + prev.x * nj.x + prev.y * nj.y;
    if (!(d > 1e-3)) {  // a turn of nearly 180°: no such hull
      v_.clear();
      return;
    }
    v_[j] = {kept_[j].x - margin_mm * (prev.x + nj.x) / d, kept_[j].y - margin_mm * (prev.y + nj.y) / d};
    prev = nj;
  }
  // Every moved edge must keep its direction: then the moved polygon is convex, with its
  // edges on the moved lines, and so the intersection of their half-planes.
  c_ = {0.0, 0.0};
  x0_ = y0_ = INFINITY;
  x1_ = y1_ = -INFINITY;
  for (std::size_t j = 0; j < n; ++j) {
    const P2 &a = v_[j], &b = v_[(j + 1) % n], &oa = kept_[j], &ob = kept_[(j + 1) % n];
    if (!((b.x - a.x) * (ob.x - oa.x) + (b.y - a.y) * (ob.y - oa.y) > 0.0)) {
      v_.clear();
      return;
    }
    c_.x += a.x / static_cast<double>(n);
    c_.y += a.y / static_cast<double>(n);
    x0_ = std::min(x0_, a.x);
    x1_ = std::max(x1_, a.x);
    y0_ = std::min(y0_, a.y);
    y1_ = std::max(y1_, a.y);
  }
  // Starting from the vertex of the least pseudo-angle about the mean, the angles increase.
  std::size_t first = 0;
  ang_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    ang_[j] = pseudo_angle(v_[j].x - c_.x, v_[j].y - c_.y);
    if (ang_[j] < ang_[first]) first = j;
  }
  std::rotate(v_.begin(), v_.begin() + static_cast<std::ptrdiff_t>(first), v_.end());
  std::rotate(ang_.begin(), ang_.begin() + static_cast<std::ptrdiff_t>(first), ang_.end());
  // A convex polygon is in angle order about any point inside it; rounding near c_ could
  // still break the order, and then the bisection would be wrong: no cover.
  if (!std::is_sorted(ang_.begin(), ang_.end())) v_.clear();
}

// The wedge at the mean point between rays to v_k and v_k+1 that holds q (bisection on
// the vertices' pseudo-angles), then q against the edge v_k v_k+1.
bool ConvexCover::contains(const SectionPoint& q) const noexcept {
  const std::size_t n = v_.size();
  if (n < 3 || q.x <= x0_ || q.x >= x1_ || q.y <= y0_ || q.y >= y1_) return false;
  const double a = pseudo_angle(q.x - c_.x, q.y - c_.y);
  const auto it = std::upper_bound(ang_.begin(), ang_.end(), a);
  const std::size_t k = it == ang_.begin() ? n - 1 : static_cast<std::size_t>(it - ang_.begin()) - 1;
  return cross2(v_[k], v_[k + 1 == n ? 0 : k + 1], q) > 0.0;
}

bool TiltedPiece::covers(const SectionScratch::P2& q, double margin_mm) const noexcept {
  if (edge_count == 0 || q.x <= x0 || q.x >= x1 || q.y <= y0 || q.y >= y1) return false;
  const double dx = q.x - cx, dy = q.y - cy, d2 = dx * dx + dy * dy;
  if (d2 >= r_out2) return false;  // outside the disk around Q (margin_mm >= 0)
  const double r = r_in - margin_mm;
  if (r > 0.0 && d2 < r * r) return true;  // inside the disk in Q, by the margin
  for (int i = 0; i < edge_count; ++i)
    if (edges[i].nx * q.x + edges[i].ny * q.y > edges[i].c - margin_mm) return false;
  return true;
}

bool TiltedPiece::axis_box(SectionScratch::P2 (&out)[4]) const noexcept {
  constexpr int axis = kDirs / 4;
  constexpr double kOut = 1.0 / kUnitsPerMm;  // a kernel unit beyond each bound
  // The axis directions' unit vectors are the axes to 1e-16.
  const double bx1 = dirs[0].h + kOut, by1 = dirs[axis].h + kOut;
  const double bx0 = -dirs[2 * axis].h - kOut, by0 = -dirs[3 * axis].h - kOut;
  if (!(bx0 < bx1 && by0 < by1) || !(bx1 - bx0 < INFINITY && by1 - by0 < INFINITY)) return false;  // (NaN too)
  out[0] = {bx0, by0};
  out[1] = {bx1, by0};
  out[2] = {bx1, by1};
  out[3] = {bx0, by1};
  return true;
}

std::size_t Sweep::tilted_pieces(double zc, std::vector<TiltedPiece>& out, const PlaneMaterial* material,
                                 std::uint64_t* beside) const {
  if (vertical_ || zc < box_.lo.z || zc > box_.hi.z) return 0;
  const CutterShape& s = *shape_;
  if (s.stations.size() > kMaxStations) return 0;
  std::size_t added = 0;
  Pose a{from_.tip, from_.axis};
  const int n = substeps_at(zc);
  for (int k = 1; k <= n; ++k) {
    const double t = static_cast<double>(k) / n;
    const Pose b{lerp(from_.tip, to_.tip, t), normalized(lerp(from_.axis, to_.axis, t))};
    const Pose pa = a;
    a = b;
    const Hull3 hull(&s, pa, b, top_);
    double zlo = 0.0, zhi = 0.0;
    HullBox hb;
    substep_extent(s, hull, pa, b, top_, zlo, zhi, material != nullptr ? &hb : nullptr);
    if (zc < zlo || zc > zhi) continue;
    if (material != nullptr && beside_material(hull, hb, material->box)) {
      if (beside != nullptr) ++*beside;
      continue;
    }
    const bool warm = !out.empty() && out.back().zc == zc;
    out.emplace_back();
    TiltedPiece& p = out.back();
    p.a = pa;
    p.b = b;
    p.zc = zc;
    const bool warm2 = warm && out.size() >= 3 && out[out.size() - 3].zc == zc;
    coarse_section(hull, s.chord_tol_mm, warm ? &out[out.size() - 2] : nullptr, warm2 ? &out[out.size() - 3] : nullptr,
                   material, p);
    p.coarse_queries = hull.queries;
    ++added;
  }
  return added;
}

std::size_t Sweep::build_piece(const TiltedPiece& p, const PieceCovers& covers, Paths& out, SectionScratch& sc) const {
  const Hull3 hull(shape_, p.a, p.b, top_);
  const double tol = shape_->chord_tol_mm;
  const bool bisected = !(shape_->capsule_radius_mm > 0.0 && shape_->core_radius_mm == 0.0);
  const ConvexCover* last = bisected && covers.last != nullptr && !covers.last->empty() ? covers.last : nullptr;
  refine_section(hull, p, tol, {last != nullptr ? nullptr : covers.before, covers.after, last, nullptr, covers.material},
                 sc);
  sc.support_queries += hull.queries;
  convex_hull(sc.pts, sc.hull);
  const std::size_t emitted = emit(sc.hull, out, sc.spare);
  if (covers.keep != nullptr) {
    if (bisected && emitted > 0) covers.keep->build(sc.hull, cover_margin(tol));
    else covers.keep->clear();
  }
  return emitted;
}

// Each sub-step on its own (no covers): every polygon is its sub-step's whole section.
std::size_t Sweep::section_general(double zc, Paths& out, SectionScratch& sc, const PlaneMaterial* material) const {
  sc.pieces.clear();
  tilted_pieces(zc, sc.pieces, material);
  std::size_t emitted = 0;
  for (const TiltedPiece& p : sc.pieces)
    if (!p.in_air) emitted += build_piece(p, {}, out, sc);
  return emitted;
}

}  // namespace lbr::geom
