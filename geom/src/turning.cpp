// Lathe inserts and the revolved sweep of a turning move.
//
// The swept region of a convex insert P translated along d is the Minkowski sum P ⊕ [0, d];
// its boundary is made of edges of P, edges of P + d and the two segments v → v + d from
// the extreme vertices. Intersecting the level line with all edges of P, of P + d and all
// segments v → v + d therefore yields exactly the radial interval of the sum (every one of
// those segments lies inside it, and its boundary is among them), in O(3N) and without
// building a hull.
#include "geom/turning.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "geom/sweep.hpp"

namespace lbr::geom {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

double nose_angle_deg(InsertKind k) noexcept {
  switch (k) {
    case InsertKind::Diamond80: return 80.0;
    case InsertKind::Diamond55: return 55.0;
    case InsertKind::V35: return 35.0;
    case InsertKind::Groove: return 90.0;
  }
  return 80.0;
}

// Points of an arc centred at c, radius r, from angle a0 to a1 (a1 > a0, radians),
// vertices on the arc, chord error <= tol.
void arc(std::vector<TurningShape::P2>& out, TurningShape::P2 c, double r, double a0, double a1, double tol) {
  if (r <= 0.0) {
    out.push_back(c);
    return;
  }
  const double step = 2.0 * std::acos(std::max(-1.0, 1.0 - std::min(1.0, tol / r)));
  const int n = std::clamp(static_cast<int>(std::ceil((a1 - a0) / std::max(step, 1e-6))), 1, 4096);
  for (int k = 0; k <= n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    out.push_back({c.r + r * std::cos(a), c.z + r * std::sin(a)});
  }
}
}  // namespace

const char* to_string(InsertKind k) noexcept {
  switch (k) {
    case InsertKind::Diamond80: return "diamond80";
    case InsertKind::Diamond55: return "diamond55";
    case InsertKind::V35: return "v35";
    case InsertKind::Groove: return "groove";
  }
  return "?";
}

bool parse_insert_kind(const std::string& s, InsertKind& out) noexcept {
  for (InsertKind k : {InsertKind::Diamond80, InsertKind::Diamond55, InsertKind::V35, InsertKind::Groove}) {
    if (s == to_string(k)) {
      out = k;
      return true;
    }
  }
  return false;
}

std::string TurningTool::validate() const {
  if (!(nose_radius_mm >= 0.0 && nose_radius_mm <= 10.0)) return "nose_radius_mm must be in [0, 10]";
  if (!(edge_length_mm > 0.0 && edge_length_mm <= 1000.0)) return "edge_length_mm must be in (0, 1000]";
  if (!(holder_width_mm >= 0.0 && holder_width_mm <= 1000.0)) return "holder_width_mm must be in [0, 1000]";
  if (!(holder_r_mm >= 0.0 && holder_r_mm <= 1000.0)) return "holder_r_mm must be in [0, 1000]";
  if (!(std::abs(holder_z_mm) <= 1000.0)) return "holder_z_mm must be in [-1000, 1000]";
  if (insert == InsertKind::Groove) {
    if (!(width_mm > 0.0 && width_mm <= 100.0)) return "width_mm must be in (0, 100]";
    if (2.0 * nose_radius_mm > width_mm) return "nose_radius_mm must be at most width_mm / 2";
    if (nose_radius_mm > edge_length_mm) return "nose_radius_mm must be at most edge_length_mm";
    return "";
  }
  const double eps = nose_angle_deg(insert);
  if (!(approach_deg >= 90.0 && approach_deg - 90.0 + eps <= 90.0))
    return "approach_angle_deg must be in [90, " + std::to_string(static_cast<int>(180.0 - eps)) + "] for a " +
           to_string(insert) + " insert";
  const double tangent = nose_radius_mm / std::tan(0.5 * eps * kDeg);
  if (tangent >= edge_length_mm) return "nose_radius_mm is too large for edge_length_mm";
  return "";
}

TurningShape TurningShape::build(const TurningTool& tool, double chord_tol_mm) {
  TurningShape s;
  s.tool = tool;
  s.chord_tol_mm = chord_tol_mm;
  std::vector<P2>& p = s.pts;
  const double re = tool.nose_radius_mm, L = tool.edge_length_mm;
  if (tool.insert == InsertKind::Groove) {
    const double w = tool.width_mm;
    const double pi = std::numbers::pi;
    arc(p, {re, re}, re, pi, 1.5 * pi, chord_tol_mm);
    p.push_back({L, 0.0});
    p.push_back({L, w});
    arc(p, {re, w - re}, re, 0.5 * pi, pi, chord_tol_mm);
  } else {
    // Sharp corner at the origin, main edge e1 at (approach - 90°) from +r towards +z,
    // trailing edge e2 at the nose angle further; the nose arc is tangent to both.
    const double eps = nose_angle_deg(tool.insert) * kDeg;
    const double a1 = (tool.approach_deg - 90.0) * kDeg, a2 = a1 + eps;
    const P2 e1{std::cos(a1), std::sin(a1)}, e2{std::cos(a2), std::sin(a2)};
    const double d = re / std::sin(0.5 * eps);
    const double bis = 0.5 * (a1 + a2);
    const P2 c{d * std::cos(bis), d * std::sin(bis)};
    p.push_back({L * e1.r, L * e1.z});
    p.push_back({L * (e1.r + e2.r), L * (e1.z + e2.z)});
    p.push_back({L * e2.r, L * e2.z});
    const double pi = std::numbers::pi;
    arc(p, c, re, a2 + 0.5 * pi, a1 + 1.5 * pi, chord_tol_mm);
  }
  if (tool.internal) {
    for (P2& q : p) q.r = -q.r;
    std::reverse(p.begin(), p.end());
  }
  double rmin = INFINITY, rmax = -INFINITY, zmin = INFINITY, zmax = -INFINITY;
  for (const P2& q : p) {
    rmin = std::min(rmin, q.r);
    rmax = std::max(rmax, q.r);
    zmin = std::min(zmin, q.z);
    zmax = std::max(zmax, q.z);
  }
  const double dr = tool.internal ? rmax : rmin;
  for (P2& q : p) {
    q.r -= dr;
    q.z -= zmin;
  }
  s.z_extent = zmax - zmin;
  return s;
}

TurningShape TurningShape::holder(const TurningTool& tool, double chord_tol_mm) {
  constexpr double kReach = 1000.0;  // out of any stock [mm]; only the side towards the cut matters
  TurningShape s;
  s.tool = tool;
  s.chord_tol_mm = chord_tol_mm;
  const double w = tool.holder_width_mm;
  if (tool.internal)
    s.pts = {{0.0, 0.0}, {0.0, w}, {-kReach, w}, {-kReach, 0.0}};
  else
    s.pts = {{0.0, 0.0}, {kReach, 0.0}, {kReach, w}, {0.0, w}};
  s.z_extent = w;
  return s;
}

TurningShape::P2 TurningShape::holder_offset(const TurningTool& tool) noexcept {
  return {tool.internal ? -tool.holder_r_mm : tool.holder_r_mm, tool.holder_z_mm};
}

LatheSweep::LatheSweep(const TurningShape& shape, double r0_mm, double z0_mm, double r1_mm, double z1_mm) noexcept
    : shape_(&shape), r0_(r0_mm), z0_(z0_mm), dr_(r1_mm - r0_mm), dz_(z1_mm - z0_mm) {
  zlo_ = std::min(z0_mm, z1_mm);
  zhi_ = std::max(z0_mm, z1_mm) + shape.z_extent;
}

bool LatheSweep::interval(double z, double& r_lo, double& r_hi) const noexcept {
  if (z < zlo_ || z > zhi_) return false;
  double lo = INFINITY, hi = -INFINITY;
  auto seg = [&](double ar, double az, double br, double bz) {
    if (az > bz) {
      std::swap(ar, br);
      std::swap(az, bz);
    }
    if (z < az || z > bz) return;
    if (bz - az <= 1e-12) {
      lo = std::min({lo, ar, br});
      hi = std::max({hi, ar, br});
      return;
    }
    const double r = ar + (br - ar) * (z - az) / (bz - az);
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  };
  const auto& p = shape_->pts;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = p[i];
    const auto& b = p[(i + 1) % n];
    const double ar = r0_ + a.r, az = z0_ + a.z, br = r0_ + b.r, bz = z0_ + b.z;
    seg(ar, az, br, bz);
    seg(ar + dr_, az + dz_, br + dr_, bz + dz_);
    seg(ar, az, ar + dr_, az + dz_);
  }
  if (!(lo <= hi)) return false;
  r_lo = lo;
  r_hi = hi;
  return true;
}

std::size_t LatheSweep::section(double z, const Rect& extent, Paths& out) const {
  double lo = 0, hi = 0;
  if (extent.empty() || !interval(z, lo, hi)) return 0;
  const bool inside = shape_->tool.internal;
  return removed_region(inside ? hi : lo, inside, shape_->chord_tol_mm, extent, out);
}

std::size_t LatheSweep::removed_region(double r, bool inside, double tol, const Rect& extent, Paths& out) {
  return inside ? ring(0.0, r, tol, extent, out) : ring(r, INFINITY, tol, extent, out);
}

namespace {
// A circle polygonised like a tool section (vertices at rho = r * Sweep::circle_grow_area(n)).
void append_circle(double rad, bool ccw, double tol, Paths& out) {
  const int n = Sweep::circle_segments(rad, tol);
  const double rho = rad * Sweep::circle_grow_area(n);
  Path c;
  c.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * std::numbers::pi * (ccw ? k : n - k) / n;
    c.push_back({to_units(rho * std::cos(a)), to_units(rho * std::sin(a))});
  }
  out.push_back(std::move(c));
}
}  // namespace

std::size_t LatheSweep::ring(double r_in, double r_out, double tol, const Rect& extent, Paths& out) {
  if (extent.empty() || !(r_out > std::max(r_in, 0.0))) return 0;
  std::size_t n = 0;
  if (std::isfinite(r_out)) {
    append_circle(r_out, true, tol, out);
    ++n;
  } else {
    // Nothing to remove when the circle holds the whole extent.
    const double fx = std::max(std::abs(to_mm(extent.x0)), std::abs(to_mm(extent.x1)));
    const double fy = std::max(std::abs(to_mm(extent.y0)), std::abs(to_mm(extent.y1)));
    if (r_in > 0.0 && r_in * r_in >= fx * fx + fy * fy) return 0;
    const Coord m = 16;  // margin [units] so the square strictly covers the extent
    out.push_back(Path{{extent.x0 - m, extent.y0 - m}, {extent.x1 + m, extent.y0 - m}, {extent.x1 + m, extent.y1 + m},
                       {extent.x0 - m, extent.y1 + m}});
    ++n;
  }
  if (r_in <= 0.0) return n;
  append_circle(r_in, false, tol, out);
  return n + 1;
}

}  // namespace lbr::geom
