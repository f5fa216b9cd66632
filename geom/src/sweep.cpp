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
#include <cmath>
#include <numbers>

namespace lbr::geom {

namespace {

using P2 = SectionScratch::P2;

bool is_plus_z(const Vec3& a) noexcept { return a.x == 0.0 && a.y == 0.0 && a.z > 0.0; }

Vec3 normalized(Vec3 v) noexcept {
  const double n = norm(v);
  return n > 0.0 ? (1.0 / n) * v : Vec3{0, 0, 1};
}

double cross2(const P2& o, const P2& a, const P2& b) noexcept {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Andrew's monotone chain; counter-clockwise, collinear points dropped. Sorts `pts`.
void convex_hull(std::vector<P2>& pts, std::vector<P2>& hull) {
  hull.clear();
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

// Rounds a hull to kernel units and appends it when it still encloses area.
std::size_t emit(const std::vector<P2>& hull, Paths& out) {
  if (hull.size() < 3) return 0;
  Path p;
  p.reserve(hull.size());
  for (const P2& q : hull) {
    const Point ip{to_units(q.x), to_units(q.y)};
    if (p.empty() || ip.X != p.back().X || ip.Y != p.back().Y) p.push_back(ip);
  }
  while (p.size() > 1 && p.front().X == p.back().X && p.front().Y == p.back().Y) p.pop_back();
  if (p.size() < 3) return 0;
  out.push_back(std::move(p));
  return 1;
}

// A station circle of the tool at one pose.
struct Circle {
  Vec3 c, n;
  double r;
};

// Support point of a circle in direction d.
Vec3 circle_support(const Circle& k, const Vec3& d, double& value) noexcept {
  const Vec3 perp = d - dot(d, k.n) * k.n;
  const double pl = norm(perp);
  if (pl <= 1e-15 * norm(d) || k.r == 0.0) {
    value = dot(k.c, d);
    return k.c;
  }
  value = dot(k.c, d) + k.r * pl;
  return k.c + (k.r / pl) * perp;
}

// Station circles of the tool at pose p, written to `out` (fixed capacity caller-side).
int station_circles(const CutterShape& s, const Pose& p, Circle* out) noexcept {
  int n = 0;
  for (const auto& st : s.stations) out[n++] = Circle{p.tip + st.h * p.axis, p.axis, st.r};
  return n;
}

struct Hull3 {
  const Circle* circles;
  int count;
  Vec3 support(const Vec3& d) const noexcept {
    double best = -INFINITY;
    Vec3 bp{};
    for (int i = 0; i < count; ++i) {
      double v;
      const Vec3 p = circle_support(circles[i], d, v);
      if (v > best) {
        best = v;
        bp = p;
      }
    }
    return bp;
  }
  // Boundary point of the section of the hull by z = zc in in-plane direction (cos φ, sin φ).
  P2 section_point(double phi, double zc) const noexcept {
    const double ux = std::cos(phi), uy = std::sin(phi);
    auto sup = [&](double t) { return support(Vec3{ux, uy, t}); };
    double tlo = -1.0, thi = 1.0;
    Vec3 plo = sup(tlo), phi_ = sup(thi);
    for (int i = 0; i < 80 && plo.z > zc; ++i) {
      thi = tlo;
      phi_ = plo;
      tlo *= 2.0;
      plo = sup(tlo);
    }
    for (int i = 0; i < 80 && phi_.z < zc; ++i) {
      tlo = thi;
      plo = phi_;
      thi *= 2.0;
      phi_ = sup(thi);
    }
    for (int i = 0; i < 64 && thi - tlo > 1e-13 * (1.0 + std::abs(tlo)); ++i) {
      const double tm = 0.5 * (tlo + thi);
      const Vec3 pm = sup(tm);
      if (pm.z <= zc) {
        tlo = tm;
        plo = pm;
      } else {
        thi = tm;
        phi_ = pm;
      }
    }
    const double dz = phi_.z - plo.z;
    if (dz > 1e-12) {
      const double w = std::clamp((zc - plo.z) / dz, 0.0, 1.0);
      return {plo.x + w * (phi_.x - plo.x), plo.y + w * (phi_.y - plo.y)};
    }
    return {plo.x, plo.y};
  }
};

double dist_to_line(const P2& p, const P2& a, const P2& b) noexcept {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double l = std::hypot(dx, dy);
  if (l < 1e-15) return std::hypot(p.x - a.x, p.y - a.y);
  return std::abs((p.x - a.x) * dy - (p.y - a.y) * dx) / l;
}

}  // namespace

int Sweep::circle_segments(double r_mm, double chord_tol_mm) noexcept {
  if (!(r_mm > 0.0)) return 1;
  const double c = 1.0 - std::min(1.0, chord_tol_mm / r_mm);
  const double step = 2.0 * std::acos(c);
  if (!(step > 0.0)) return 4096;
  return std::clamp(static_cast<int>(std::ceil(2.0 * std::numbers::pi / step)), 8, 4096);
}

Sweep::Sweep(const CutterShape& shape, const Pose& from, const Pose& to) noexcept
    : shape_(&shape), from_(from), to_(to) {
  from_.axis = normalized(from_.axis);
  to_.axis = normalized(to_.axis);
  vertical_ = is_plus_z(from.axis) && is_plus_z(to.axis);
  const double R = shape.radius(), H = shape.height();
  if (vertical_) {
    box_.add({from.tip.x - R, from.tip.y - R, from.tip.z});
    box_.add({from.tip.x + R, from.tip.y + R, from.tip.z + H});
    box_.add({to.tip.x - R, to.tip.y - R, to.tip.z});
    box_.add({to.tip.x + R, to.tip.y + R, to.tip.z + H});
    return;
  }
  // Sub-steps: the chord between two interpolated poses stays within tolerance of the arc
  // a tool point describes while the axis turns.
  const double cosang = std::clamp(dot(from_.axis, to_.axis), -1.0, 1.0);
  const double ang = std::acos(cosang);
  if (ang > 1e-12) {
    const double reach = std::hypot(H, R);
    const double c = 1.0 - std::min(1.0, shape.chord_tol_mm / reach);
    const double step = 2.0 * std::acos(c);
    substeps_ = std::clamp(static_cast<int>(std::ceil(ang / step)), 1, kMaxSubsteps);
  }
  for (int k = 0; k <= substeps_; ++k) {
    const double t = static_cast<double>(k) / substeps_;
    const Vec3 tip = lerp(from_.tip, to_.tip, t);
    const Vec3 ax = normalized(lerp(from_.axis, to_.axis, t));
    for (const auto& st : shape.stations) {
      const Vec3 c = tip + st.h * ax;
      const Vec3 e{st.r * std::sqrt(std::max(0.0, 1 - ax.x * ax.x)), st.r * std::sqrt(std::max(0.0, 1 - ax.y * ax.y)),
                   st.r * std::sqrt(std::max(0.0, 1 - ax.z * ax.z))};
      box_.add(c - e);
      box_.add(c + e);
    }
  }
}

std::size_t Sweep::section(double z_mm, Paths& out, SectionScratch& scratch) const {
  if (z_mm < box_.lo.z || z_mm > box_.hi.z) return 0;
  return vertical_ ? section_vertical(z_mm, out, scratch) : section_general(z_mm, out, scratch);
}

std::size_t Sweep::section_vertical(double zc, Paths& out, SectionScratch& sc) const {
  const CutterShape& s = *shape_;
  const double H = s.height();
  const double z0 = from_.tip.z, z1 = to_.tip.z, dz = z1 - z0;
  sc.disks.clear();
  auto disk_at = [&](double t) {
    const double h = zc - (z0 + t * dz);
    sc.disks.push_back({from_.tip.x + t * (to_.tip.x - from_.tip.x), from_.tip.y + t * (to_.tip.y - from_.tip.y),
                        s.radius_at(std::clamp(h, 0.0, H))});
  };
  if (dz == 0.0) {
    const double h = zc - z0;
    if (h < 0.0 || h > H) return 0;
    disk_at(0.0);
    disk_at(1.0);
  } else {
    // Parameter interval where the plane meets the cutting part: 0 <= zc - z(t) <= H.
    double ta = (zc - z0) / dz, tb = (zc - H - z0) / dz;
    if (ta > tb) std::swap(ta, tb);
    ta = std::max(ta, 0.0);
    tb = std::min(tb, 1.0);
    if (ta > tb) return 0;
    disk_at(ta);
    for (const auto& st : s.stations) {
      const double t = (zc - st.h - z0) / dz;
      if (t > ta && t < tb) disk_at(t);
    }
    disk_at(tb);
  }
  double rmax = 0.0;
  for (const auto& d : sc.disks) rmax = std::max(rmax, d.r);
  if (rmax <= 0.0) return 0;
  const int n = circle_segments(rmax, s.chord_tol_mm);
  // Vertices at ρ = 2r / (1 + cos(π/n)): the polygon then deviates from the circle by at
  // most ±(ρ - r), i.e. half the chord band, on either side.
  const double grow = 2.0 / (1.0 + std::cos(std::numbers::pi / n));
  if (sc.table_n != n) {
    sc.cos_t.resize(n);
    sc.sin_t.resize(n);
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * k / n;
      sc.cos_t[k] = std::cos(a);
      sc.sin_t[k] = std::sin(a);
    }
    sc.table_n = n;
  }
  sc.hull.clear();
  if (sc.disks.size() == 2 && sc.disks[0].r == sc.disks[1].r) {
    // Horizontal move (the common case): the hull of two equal n-gons on one angle grid is
    // the far half of each, walked counter-clockwise: vertices of the end disk facing the
    // direction of motion, then those of the start disk facing away from it.
    const auto& a = sc.disks[0];
    const auto& b = sc.disks[1];
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double rho = a.r * grow;
    if (dx == 0.0 && dy == 0.0) {
      for (int k = 0; k < n; ++k) sc.hull.push_back({a.x + rho * sc.cos_t[k], a.y + rho * sc.sin_t[k]});
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
        sc.hull.push_back({b.x + rho * sc.cos_t[k], b.y + rho * sc.sin_t[k]});
        if (k == k_left) break;
      }
      for (int k = k_left;; k = (k + 1) % n) {  // back half: start disk
        sc.hull.push_back({a.x + rho * sc.cos_t[k], a.y + rho * sc.sin_t[k]});
        if (k == k_right) break;
      }
    }
    return emit(sc.hull, out);
  }
  // Several disks (ramps): only vertices whose value in their own grid direction comes
  // close to the union's support value in that direction can be hull vertices. The support
  // function of the union is D-Lipschitz in the direction (D bounds |p - centre|), and a
  // vertex is extreme for some direction within ±π/n of its own, so a vertex below
  // S_k - 2·D·π/n is strictly inside; dropping those leaves the hull unchanged and the sort
  // small.
  double cx = 0.0, cy = 0.0;
  for (const auto& d : sc.disks) cx += d.x, cy += d.y;
  cx /= static_cast<double>(sc.disks.size());
  cy /= static_cast<double>(sc.disks.size());
  double dmax = 0.0;
  for (const auto& d : sc.disks) dmax = std::max(dmax, std::hypot(d.x - cx, d.y - cy) + d.r * grow);
  const double slack = 2.0 * dmax * std::numbers::pi / n + 1e-12;
  sc.pts.clear();
  for (int k = 0; k < n; ++k) {
    const double ux = sc.cos_t[k], uy = sc.sin_t[k];
    double best = -INFINITY;
    for (const auto& d : sc.disks) best = std::max(best, (d.x - cx) * ux + (d.y - cy) * uy + d.r * grow);
    for (const auto& d : sc.disks) {
      const double v = (d.x - cx) * ux + (d.y - cy) * uy + d.r * grow;
      if (v < best - slack) continue;
      const double rho = d.r * grow;
      sc.pts.push_back({d.x + rho * ux, d.y + rho * uy});
    }
  }
  convex_hull(sc.pts, sc.hull);
  return emit(sc.hull, out);
}

std::size_t Sweep::section_general(double zc, Paths& out, SectionScratch& sc) const {
  const CutterShape& s = *shape_;
  const double tol = s.chord_tol_mm;
  const int ns = static_cast<int>(s.stations.size());
  constexpr int kMaxStations = 512;
  Circle circles[2 * kMaxStations];
  if (ns > kMaxStations) return 0;
  std::size_t emitted = 0;
  Pose a{from_.tip, from_.axis};
  for (int k = 1; k <= substeps_; ++k) {
    const double t = static_cast<double>(k) / substeps_;
    const Pose b{lerp(from_.tip, to_.tip, t), normalized(lerp(from_.axis, to_.axis, t))};
    int nc = station_circles(s, a, circles);
    nc += station_circles(s, b, circles + nc);
    a = b;
    // Quick z test for this sub-step.
    double zlo = INFINITY, zhi = -INFINITY;
    for (int i = 0; i < nc; ++i) {
      const double e = circles[i].r * std::sqrt(std::max(0.0, 1.0 - circles[i].n.z * circles[i].n.z));
      zlo = std::min(zlo, circles[i].c.z - e);
      zhi = std::max(zhi, circles[i].c.z + e);
    }
    if (zc < zlo || zc > zhi) continue;
    const Hull3 hull{circles, nc};
    // Adaptive refinement in angle: start with 16 directions, split an interval while the
    // boundary point at its middle lies farther than tol/2 from the chord.
    sc.dirs.clear();
    constexpr int kStart = 16;
    constexpr int kMaxPoints = 8192;
    for (int i = 0; i <= kStart; ++i) {
      const double phi = 2.0 * std::numbers::pi * i / kStart;
      sc.dirs.push_back({phi, i == kStart ? sc.dirs.front().p : hull.section_point(phi, zc)});
    }
    sc.pts.clear();
    // Depth-first refinement using `hull` storage as a stack of intervals (reused buffer).
    for (int i = 0; i < kStart; ++i) {
      struct Iv {
        double pa, pb;
        P2 a, b;
        int depth;
      };
      Iv stack[64];
      int sp = 0;
      stack[sp++] = {sc.dirs[i].phi, sc.dirs[i + 1].phi, sc.dirs[i].p, sc.dirs[i + 1].p, 0};
      while (sp > 0) {
        const Iv iv = stack[--sp];
        const double pm = 0.5 * (iv.pa + iv.pb);
        const P2 m = hull.section_point(pm, zc);
        if (iv.depth < 40 && static_cast<int>(sc.pts.size()) < kMaxPoints && sp + 2 <= 64 &&
            dist_to_line(m, iv.a, iv.b) > 0.5 * tol) {
          stack[sp++] = {pm, iv.pb, m, iv.b, iv.depth + 1};  // right half processed last
          stack[sp++] = {iv.pa, pm, iv.a, m, iv.depth + 1};
        } else {
          sc.pts.push_back(iv.a);
          sc.pts.push_back(m);
        }
      }
    }
    convex_hull(sc.pts, sc.hull);
    emitted += emit(sc.hull, out);
  }
  return emitted;
}

}  // namespace lbr::geom
