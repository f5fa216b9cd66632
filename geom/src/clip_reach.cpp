// The test that a level's sections cannot change a cell (clip_reach.hpp).
#include "clip_reach.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "subtract_state.hpp"

namespace lbr::geom::detail {

namespace {

constexpr double kPeriod = 4.0;  // a full turn of pseudo_angle()

struct V2 {
  double x, y;
};

// Squared distance from p to the segment a–b.
double dist2_point_segment(V2 p, V2 a, V2 b) noexcept {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  double t = len2 > 0.0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = a.x + t * dx - p.x, ey = a.y + t * dy - p.y;
  return ex * ex + ey * ey;
}

double cross(V2 o, V2 a, V2 b) noexcept { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

// Squared distance between the segments p–q and a–b (0 when they cross).
double dist2_segments(V2 p, V2 q, V2 a, V2 b) noexcept {
  const double d1 = cross(a, b, p), d2 = cross(a, b, q), d3 = cross(p, q, a), d4 = cross(p, q, b);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return 0.0;
  return std::min(std::min(dist2_point_segment(p, a, b), dist2_point_segment(q, a, b)),
                  std::min(dist2_point_segment(a, p, q), dist2_point_segment(b, p, q)));
}

// The direction of p from o as a pseudo-angle in [0, 4) (the "diamond angle", monotone in
// the angle, 4 for a full turn): cheaper than atan2 and 1-Lipschitz in the angle (its
// derivative is 1/(|cos| + |sin|)² ∈ [1/2, 1]), so a gap of g between pseudo-angles is a
// gap of at least g radians between the directions.
double pseudo_angle(V2 p, V2 o) noexcept {
  const double dx = p.x - o.x, dy = p.y - o.y;
  if (dx == 0.0 && dy == 0.0) return 0.0;
  if (dy >= 0.0) return dx >= 0.0 ? dy / (dx + dy) : 1.0 - dx / (dy - dx);
  return dx < 0.0 ? 2.0 - dy / (-dx - dy) : 3.0 + dx / (dx - dy);
}

// The pseudo-angular interval [lo, lo + span] of the segment a–b seen from o (o not on it),
// counter-clockwise from whichever end starts the turn.
void interval_of_segment(V2 a, V2 b, V2 o, double& lo, double& span) noexcept {
  const double pa = pseudo_angle(a, o), pb = pseudo_angle(b, o);
  const bool ccw = cross(o, a, b) >= 0.0;
  lo = ccw ? pa : pb;
  span = ccw ? pb - pa : pa - pb;
  if (span < 0.0) span += kPeriod;
}

// Capsules that span more than this pseudo-angle about the test centre are tested against every
// edge (few: lead-ins, long passes); the others are found through their sorted angles.
constexpr double kNarrowRad = 0.25;
// Consecutive capsules boxed together for edges that the angular bound does not help.
constexpr std::uint32_t kChunk = 8;

using ReachFrame = ReachScratch::Frame;

bool box_misses(const ReachScratch::Box& b, V2 u, V2 v) noexcept {
  return std::max(u.x, v.x) < b.x0 || std::min(u.x, v.x) > b.x1 || std::max(u.y, v.y) < b.y0 || std::min(u.y, v.y) > b.y1;
}

void grow(ReachScratch::Box& b, const ReachScratch::Box& c) noexcept {
  b.x0 = std::min(b.x0, c.x0);
  b.y0 = std::min(b.y0, c.y0);
  b.x1 = std::max(b.x1, c.x1);
  b.y1 = std::max(b.y1, c.y1);
}

// Fills rs.items (capsules with r > 0, in path order), their chunks, the angular index and
// the frame; false when no capsule has r > 0.
// The test centre o: the centre of the circle fitted to the segments' ends (Kåsa's linear
// least squares; a helix turn, whole or part, gives its axis), or the middle of their box
// where the ends lie on no circle near them. Any o keeps the test exact; a good one keeps it
// short.
void fit_centre(const ReachScratch& rs, const ReachScratch::Box& seg, ReachFrame& f) noexcept {
  const double cx = 0.5 * (seg.x0 + seg.x1), cy = 0.5 * (seg.y0 + seg.y1);
  f.ox = cx;
  f.oy = cy;
  double sxx = 0, sxy = 0, syy = 0, sx = 0, sy = 0, n = 0, sxz = 0, syz = 0, sz = 0;
  auto add = [&](double x, double y) {
    x -= cx;
    y -= cy;
    const double z = x * x + y * y;
    sxx += x * x; sxy += x * y; syy += y * y; sx += x; sy += y; n += 1.0;
    sxz += x * z; syz += y * z; sz += z;
  };
  for (const ReachScratch::Item& it : rs.items) {
    add(rs.caps[it.k].ax, rs.caps[it.k].ay);
    add(rs.caps[it.k].bx, rs.caps[it.k].by);
  }
  // [sxx sxy sx; sxy syy sy; sx sy n] (a, b, c) = −(sxz, syz, sz); o = −(a, b) / 2 (Cramer).
  auto det3 = [](double a11, double a12, double a13, double a21, double a22, double a23, double a31, double a32,
                 double a33) {
    return a11 * (a22 * a33 - a23 * a32) - a12 * (a21 * a33 - a23 * a31) + a13 * (a21 * a32 - a22 * a31);
  };
  const double det = det3(sxx, sxy, sx, sxy, syy, sy, sx, sy, n);
  const double size = std::max(seg.x1 - seg.x0, seg.y1 - seg.y0);
  if (!(std::abs(det) > 0.0) || size <= 0.0) return;
  const double a = det3(-sxz, sxy, sx, -syz, syy, sy, -sz, sy, n) / det;
  const double b = det3(sxx, -sxz, sx, sxy, -syz, sy, sx, -sz, n) / det;
  const double ox = -0.5 * a, oy = -0.5 * b;
  if (std::isfinite(ox) && std::isfinite(oy) && std::abs(ox) <= size && std::abs(oy) <= size) {
    f.ox = cx + ox;
    f.oy = cy + oy;
  }
}

bool build_frame(ReachScratch& rs, ReachFrame& f) {
  f = ReachFrame{};
  ReachScratch::Box seg;  // of the segments alone
  rs.items.clear();
  for (std::uint32_t k = 0; k < rs.caps.size(); ++k) {
    const ReachCapsule& c = rs.caps[k];
    if (c.r <= 0.0) continue;
    ReachScratch::Item it;
    it.k = k;
    it.box = {std::min(c.ax, c.bx) - c.r, std::min(c.ay, c.by) - c.r, std::max(c.ax, c.bx) + c.r,
              std::max(c.ay, c.by) + c.r};
    grow(seg, ReachScratch::Box{std::min(c.ax, c.bx), std::min(c.ay, c.by), std::max(c.ax, c.bx), std::max(c.ay, c.by)});
    grow(f.all, it.box);
    f.r_max = std::max(f.r_max, c.r);
    rs.items.push_back(it);
  }
  if (rs.items.empty()) return false;
  fit_centre(rs, seg, f);
  f.rho_min = INFINITY;
  rs.sorted.clear();
  rs.wide.clear();
  rs.chunks.clear();
  const V2 o{f.ox, f.oy};
  for (std::uint32_t i = 0; i < rs.items.size(); ++i) {
    ReachScratch::Item& it = rs.items[i];
    const ReachCapsule& c = rs.caps[it.k];
    const V2 a{c.ax, c.ay}, b{c.bx, c.by};
    f.rho_max = std::max(f.rho_max, std::sqrt(std::max(dist2_point_segment(a, o, o), dist2_point_segment(b, o, o))));
    f.rho_min = std::min(f.rho_min, std::sqrt(dist2_point_segment(o, a, b)));
    if (i % kChunk == 0) rs.chunks.push_back(ReachScratch::Chunk{it.box, i, i + 1});
    grow(rs.chunks.back().box, it.box);
    rs.chunks.back().end = i + 1;
  }
  // The angular index pays where the segments wind about o in a ring thinner than the
  // tool (a helix turn); a raster pass's edges go through the chunks only.
  f.angular = rs.items.size() >= kChunk && f.rho_max - f.rho_min < f.r_max;
  if (!f.angular) return true;
  for (std::uint32_t i = 0; i < rs.items.size(); ++i) {
    ReachScratch::Item& it = rs.items[i];
    const ReachCapsule& c = rs.caps[it.k];
    const V2 a{c.ax, c.ay}, b{c.bx, c.by};
    double span = kPeriod;  // (a segment through the centre's unit disk is wide)
    if (dist2_point_segment(o, a, b) >= 1.0) interval_of_segment(a, b, o, it.lo, span);
    it.wide = span > kNarrowRad;
    (it.wide ? rs.wide : rs.sorted).push_back(i);
  }
  std::sort(rs.sorted.begin(), rs.sorted.end(), [&](std::uint32_t x, std::uint32_t y) {
    return rs.items[x].lo < rs.items[y].lo || (rs.items[x].lo == rs.items[y].lo && x < y);
  });
  return true;
}

bool capsule_meets(const ReachCapsule& c, const ReachScratch::Box& b) noexcept {
  return c.r > 0.0 && std::min(c.ax, c.bx) - c.r <= b.x1 && std::max(c.ax, c.bx) + c.r >= b.x0 &&
         std::min(c.ay, c.by) - c.r <= b.y1 && std::max(c.ay, c.by) + c.r >= b.y0;
}

bool edge_hits(const ReachScratch& rs, std::uint32_t i, V2 u, V2 v) noexcept {
  const ReachScratch::Item& it = rs.items[i];
  if (box_misses(it.box, u, v)) return false;
  const ReachCapsule& c = rs.caps[it.k];
  return dist2_segments(u, v, V2{c.ax, c.ay}, V2{c.bx, c.by}) < c.r * c.r;
}

// The narrow capsules whose pseudo-angle lo lies in [from, to] (within [0, 4)).
bool scan_sorted(const ReachScratch& rs, double from, double to, V2 u, V2 v) noexcept {
  auto it = std::lower_bound(rs.sorted.begin(), rs.sorted.end(), from,
                             [&](std::uint32_t i, double x) { return rs.items[i].lo < x; });
  for (; it != rs.sorted.end() && rs.items[*it].lo <= to; ++it)
    if (edge_hits(rs, *it, u, v)) return true;
  return false;
}

// Every narrow capsule, chunk by chunk.
bool scan_chunks(const ReachScratch& rs, V2 u, V2 v) noexcept {
  for (const ReachScratch::Chunk& ch : rs.chunks) {
    if (box_misses(ch.box, u, v)) continue;
    for (std::uint32_t i = ch.begin; i < ch.end; ++i)
      if (!rs.items[i].wide && edge_hits(rs, i, u, v)) return true;  // (wide ones: none without the index)
  }
  return false;
}

// The half-width [rad] of the angular window about o outside which no capsule comes within
// r_max of the edge, or a negative value where the bound does not help. With every segment
// end within ρ_max of o and every segment at least ρ_min from it: a point p at distance
// >= d from o (the edge outside the segments) and a point q at distance <= ρ_max whose
// directions from o differ by Δ are at least sqrt(d² + ρ_max² − 2dρ_max cos Δ) apart
// (d sin Δ where d cos Δ <= ρ_max), which exceeds r_max for Δ > W when d² > ρ_max² + r_max²;
// the same with p within d_max of o (the edge inside) and q beyond ρ_min, when
// ρ_min² > d_max² + r_max².
double window_rad(const ReachFrame& f, double d, double d_max) noexcept {
  const double r2 = f.r_max * f.r_max;
  if (d >= 1.0 && d * d > f.rho_max * f.rho_max + r2)
    return std::acos(std::clamp((d * d + f.rho_max * f.rho_max - r2) / (2.0 * d * f.rho_max), -1.0, 1.0));
  if (d >= 1.0 && f.rho_min * f.rho_min > d_max * d_max + r2)
    return std::acos(std::clamp((d_max * d_max + f.rho_min * f.rho_min - r2) / (2.0 * d_max * f.rho_min), -1.0, 1.0));
  return -1.0;
}

// True when the material edge u–v comes within some capsule's radius of its segment. Edges
// beyond ρ_max + r_max from o, or within ρ_min − r_max of it, meet no capsule (triangle
// inequality); of the others, the wide capsules are tested, and the narrow ones in the
// angular window (window_rad()), or chunk by chunk under their boxes where it does not help.
bool edge_in_reach(const ReachScratch& rs, const ReachFrame& f, V2 u, V2 v) noexcept {
  const V2 o{f.ox, f.oy};
  const double d = std::sqrt(dist2_point_segment(o, u, v));
  if (d >= f.rho_max + f.r_max) return false;
  const double d_max = std::sqrt(std::max(dist2_point_segment(u, o, o), dist2_point_segment(v, o, o)));
  if (d_max <= f.rho_min - f.r_max) return false;
  if (!f.angular) return scan_chunks(rs, u, v);
  for (std::uint32_t i : rs.wide)
    if (edge_hits(rs, i, u, v)) return true;
  const double w = window_rad(f, d, d_max);
  if (w < 0.0) return scan_chunks(rs, u, v);
  double elo = 0, espan = 0;
  interval_of_segment(u, v, o, elo, espan);
  // A narrow capsule meets the window [elo - w, elo + espan + w] only if its lo lies in
  // [elo - w - kNarrowRad, elo + espan + w]; pseudo-angle gaps bound angle gaps from below.
  const double qlen = espan + 2.0 * w + kNarrowRad;
  if (qlen >= kPeriod) return scan_chunks(rs, u, v);
  const double qlo = std::fmod(elo - w - kNarrowRad + 2.0 * kPeriod, kPeriod);
  if (qlo + qlen <= kPeriod) return scan_sorted(rs, qlo, qlo + qlen, u, v);
  return scan_sorted(rs, qlo, kPeriod, u, v) || scan_sorted(rs, 0.0, qlo + qlen - kPeriod, u, v);
}

// Even-odd: p lies inside the material of the touched polygons.
bool inside_material(const Cell& cell, std::span<const std::uint32_t> touched, V2 p) noexcept {
  bool in = false;
  auto walk = [&](const Path& pts) {
    for (std::size_t i = 0, j = pts.size() - 1; i < pts.size(); j = i++) {
      const double yi = static_cast<double>(pts[i].Y), yj = static_cast<double>(pts[j].Y);
      if ((yi > p.y) == (yj > p.y)) continue;
      const double xi = static_cast<double>(pts[i].X), xj = static_cast<double>(pts[j].X);
      if (p.x < xi + (p.y - yi) * (xj - xi) / (yj - yi)) in = !in;
    }
  };
  for (std::uint32_t t : touched) {
    const Polygon& poly = cell.polys[t];
    walk(poly.outer.pts);
    for (const Contour& h : poly.holes) walk(h.pts);
  }
  return in;
}

bool contour_in_reach(const Path& pts, const ReachScratch& rs, const ReachFrame& f) noexcept {
  for (std::size_t i = 0, j = pts.size() - 1; i < pts.size(); j = i++) {
    const V2 u{static_cast<double>(pts[j].X), static_cast<double>(pts[j].Y)};
    const V2 v{static_cast<double>(pts[i].X), static_cast<double>(pts[i].Y)};
    if (box_misses(f.all, u, v)) continue;
    if (edge_in_reach(rs, f, u, v)) return true;
  }
  return false;
}

double max_dist_to_segment(V2 a, V2 b, double d2, V2 p) noexcept { return std::max(d2, dist2_point_segment(p, a, b)); }

}  // namespace

void PriorPiece::add_plane(double nx, double ny, const Point& on, double band_units) {
  planes_.push_back({nx, ny, nx * static_cast<double>(on.X) + ny * static_cast<double>(on.Y) + band_units});
}

bool PriorPiece::set(const Path& poly, double band_units) {
  planes_.clear();
  const std::size_t n = poly.size();
  if (n < 3) return false;
  auto normal = [&](std::size_t i, double& nx, double& ny) {  // edge i's outward unit normal, false if it has no length
    const Point& a = poly[i];
    const Point& b = poly[i + 1 == n ? 0 : i + 1];
    const double ex = static_cast<double>(b.X - a.X), ey = static_cast<double>(b.Y - a.Y);
    const double len = std::sqrt(ex * ex + ey * ey);
    if (!(len > 0.0)) return false;
    nx = ey / len, ny = -ex / len;  // counter-clockwise: the inside is on the left
    return true;
  };
  double px = 0.0, py = 0.0;  // the previous edge's normal, first the last edge's
  bool have = false;
  for (std::size_t i = n; i-- > 0 && !have;) have = normal(i, px, py);
  if (!have) return false;
  constexpr double kStep = std::numbers::pi / 3.0;  // bevels: at most 60 degrees between planes
  const double out = band_units * std::cos(kStep / 2.0);  // each plane's move: a corner reaches the band
  Rect box;
  int windings = 0;  // the normals' turns through angle 0: once around for a convex polygon
  for (std::size_t i = 0; i < n; ++i) {
    double nx = 0.0, ny = 0.0;
    if (!normal(i, nx, ny)) continue;
    const Point& a = poly[i];
    const double cross = px * ny - py * nx, dot = px * nx + py * ny;  // the turn at a
    if (cross < 0.0 || (cross == 0.0 && dot < 0.0)) {  // concave, or a spike
      planes_.clear();
      return false;
    }
    if (py < 0.0 && ny >= 0.0) ++windings;  // a left turn below π from the lower half passes angle 0
    if (dot < std::cos(kStep)) {  // more than 60 degrees: bevels between the two planes
      const double turn = std::atan2(cross, dot), from = std::atan2(py, px);
      const int bevels = static_cast<int>(std::ceil(turn / kStep)) - 1;
      for (int k = 1; k <= bevels; ++k) {
        const double t = from + turn * k / (bevels + 1);
        add_plane(std::cos(t), std::sin(t), a, out);
      }
    }
    add_plane(nx, ny, a, out);
    box.add(a);
    px = nx, py = ny;
  }
  if (planes_.size() < 3 || windings != 1) {  // once around: simple and convex
    planes_.clear();
    return false;
  }
  const auto grow = static_cast<Coord>(std::ceil(band_units)) + 1;
  box_ = Rect{box.x0 - grow, box.y0 - grow, box.x1 + grow, box.y1 + grow};
  return true;
}

bool PriorPiece::holds(const Point& q) const noexcept {
  const double x = static_cast<double>(q.X), y = static_cast<double>(q.Y);
  for (const Plane& p : planes_)
    if (p.nx * x + p.ny * y > p.c) return false;
  return true;
}

double reach_band_units(double chord_tol_mm) noexcept { return 2.0 * chord_tol_mm * kUnitsPerMm + 2.0; }

void add_outline_reach(std::span<const MoveCaps> moves, double band_units, std::vector<ReachCapsule>& out) {
  const double k = kUnitsPerMm;
  for (const MoveCaps& m : moves) {
    const V2 a{m.c0.x, m.c0.y}, b{m.c1.x, m.c1.y};
    double r2 = std::max(m.rho0, m.rho1);
    r2 *= r2;
    for (const auto& p : m.right) r2 = max_dist_to_segment(a, b, r2, V2{p.x, p.y});
    for (const auto& p : m.left) r2 = max_dist_to_segment(a, b, r2, V2{p.x, p.y});
    out.push_back(ReachCapsule{a.x * k, a.y * k, b.x * k, b.y * k, std::sqrt(r2) * k + 1.0 - band_units});
  }
}

void add_chain_reach(const Path& pts, double r_mm, std::vector<ReachCapsule>& out) {
  const double r = r_mm * kUnitsPerMm + 2.0;
  auto at = [&](std::size_t i) { return V2{static_cast<double>(pts[i].X), static_cast<double>(pts[i].Y)}; };
  if (pts.size() == 1) out.push_back(ReachCapsule{at(0).x, at(0).y, at(0).x, at(0).y, r});
  for (std::size_t i = 1; i < pts.size(); ++i) out.push_back(ReachCapsule{at(i - 1).x, at(i - 1).y, at(i).x, at(i).y, r});
}

void add_section_reach(const Path& p, double ax_mm, double ay_mm, double bx_mm, double by_mm, double band_units,
                       std::vector<ReachCapsule>& out) {
  const double k = kUnitsPerMm;
  const V2 a{ax_mm * k, ay_mm * k}, b{bx_mm * k, by_mm * k};
  double r2 = 0.0;
  for (const Point& q : p) r2 = max_dist_to_segment(a, b, r2, V2{static_cast<double>(q.X), static_cast<double>(q.Y)});
  out.push_back(ReachCapsule{a.x, a.y, b.x, b.y, std::sqrt(r2) - band_units});
}

bool material_out_of_reach(const Cell& cell, std::span<const std::uint32_t> touched, const LevelSections& ls,
                           std::span<const std::uint32_t> selected, ReachScratch& rs) {
  // Only capsules whose box meets the touched polygons' box can hold their material; a long
  // pass's outline brings the capsules of all its moves.
  ReachScratch::Box material;
  for (std::uint32_t t : touched) {
    const Rect& b = cell.polys[t].bbox;
    grow(material, ReachScratch::Box{static_cast<double>(b.x0), static_cast<double>(b.y0), static_cast<double>(b.x1),
                                     static_cast<double>(b.y1)});
  }
  rs.caps.clear();
  for (std::uint32_t s : selected) {
    if (s >= ls.reach_begin.size() || ls.reach_begin[s] == kNoReach) return false;
    for (std::uint32_t k = ls.reach_begin[s]; k < ls.reach_end[s]; ++k)
      if (capsule_meets(ls.reach[k], material)) rs.caps.push_back(ls.reach[k]);
  }
  // A segment's end inside the material is in reach (cheap, and where a clip does cut it
  // usually answers first). Once no material edge meets a capsule either, each connected
  // chain of capsules lies wholly in the material or wholly outside it, and its first
  // point told which.
  for (std::size_t k = 0; k < rs.caps.size(); ++k) {
    const ReachCapsule& c = rs.caps[k];
    if (c.r <= 0.0) continue;
    const bool joined = k > 0 && rs.caps[k - 1].r > 0.0 && rs.caps[k - 1].bx == c.ax && rs.caps[k - 1].by == c.ay;
    if (!joined && inside_material(cell, touched, V2{c.ax, c.ay})) return false;
  }
  // Cells of one level, and levels whose sections are the same, meet the same capsules:
  // the frame is built once for them.
  if (!rs.framed_valid || rs.framed != rs.caps) {
    rs.framed = rs.caps;
    rs.framed_valid = true;
    rs.framed_items = build_frame(rs, rs.frame);
  }
  if (!rs.framed_items) return true;  // every section lies within the band of its capsules
  const ReachFrame& f = rs.frame;
  for (std::uint32_t t : touched) {
    const Polygon& poly = cell.polys[t];
    const V2 lo{static_cast<double>(poly.bbox.x0), static_cast<double>(poly.bbox.y0)};
    const V2 hi{static_cast<double>(poly.bbox.x1), static_cast<double>(poly.bbox.y1)};
    if (box_misses(f.all, lo, hi)) continue;
    if (contour_in_reach(poly.outer.pts, rs, f)) return false;
    for (const Contour& h : poly.holes)
      if (contour_in_reach(h.pts, rs, f)) return false;
  }
  return true;
}

}  // namespace lbr::geom::detail
