// The walls of one level: triangle strips between the noded contours of its bottom and top
// planes, edge by edge of the level's contours (docs/mesh.md). On a border shared with a
// neighbour only where the neighbour has no material, so that the two regions' surfaces join.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "reconstruct_detail.hpp"

namespace lbr::mesh::detail {

namespace {

// The noded points of contour edge j (original vertex j to original vertex j+1, both
// included).
void chain(const Noded& nd, std::uint32_t j, std::vector<Point>& out) {
  out.clear();
  const std::size_t n = nd.orig.size();
  const std::uint32_t e = j + 1 < n ? nd.orig[j + 1] : static_cast<std::uint32_t>(nd.pts.size());
  for (std::uint32_t i = nd.orig[j]; i < e; ++i) out.push_back(nd.pts[i]);
  out.push_back(j + 1 < n ? nd.pts[nd.orig[j + 1]] : nd.pts[0]);
}

class WallBuilder {
 public:
  WallBuilder(const geom::LbrSolid& s, int r, int l, const std::vector<PlaneData>& planes, WallData& wd)
      : s_(s), r_(r), l_(l), planes_(planes), wd_(wd), rr_(s.region_rect(r)), thick_mm_(s.level_thickness_mm(l)) {}

  void run();

 private:
  void collect_cover();
  void add_rounding_bound(const Point& u, const Point& v);
  void border_walls(int sd, const Point& u, const Point& v);
  bool covered(int sd, Coord a, Coord b) const noexcept;
  void sub_chain(const std::vector<Point>& ch, int sd, const Point& u, std::size_t i, std::size_t e,
                 std::vector<Point>& out);
  void strip(const std::vector<Point>& B, const std::vector<Point>& T, const Point& u, const Point& v);
  Tri resolve(Tri t) const;

  const geom::LbrSolid& s_;
  const int r_, l_;
  const std::vector<PlaneData>& planes_;
  WallData& wd_;
  const geom::Rect rr_;
  const double thick_mm_;
  std::array<std::vector<std::pair<Coord, Coord>>, 4> cover_;  // neighbour's material on each border
  std::array<bool, 4> has_n_{};
  std::vector<Point> cb_, ct_, rb_, rt_;  // bottom / top chains of an edge, and of a piece of it
  std::vector<Coord> merged_;             // their points along a border line
};

void WallBuilder::run() {
  wd_.tris.clear();
  wd_.rounding_bound_mm3 = 0;
  wd_.defects = 0;
  const auto& bot = planes_[l_].side[1];
  const auto& top = planes_[l_ + 1].side[0];
  std::vector<const geom::Contour*> cs;
  contours_of(s_.cell(r_, l_), cs);
  collect_cover();

  for (std::uint32_t c = 0; c < cs.size(); ++c) {
    const Path& p = cs[c]->pts;
    for (std::uint32_t j = 0; j < p.size(); ++j) {
      const Point& u = p[j];
      const Point& v = p[(j + 1) % p.size()];
      chain(bot[c], j, cb_);
      chain(top[c], j, ct_);
      add_rounding_bound(u, v);
      const int sd = edge_side(rr_, u, v);
      if (sd < 0 || !has_n_[sd]) strip(cb_, ct_, u, v);
      else border_walls(sd, u, v);
    }
  }
}

void WallBuilder::collect_cover() {
  for (int sd = 0; sd < 4; ++sd) {
    const int n = neighbour(s_, r_, sd);
    has_n_[sd] = n >= 0;
    if (n < 0) continue;
    auto scan = [&](const Path& p) {
      for (std::size_t j = 0; j < p.size(); ++j) {
        const Point& a = p[j];
        const Point& b = p[(j + 1) % p.size()];
        if (on_side(rr_, sd, a) && on_side(rr_, sd, b))
          cover_[sd].push_back({std::min(line_coord(sd, a), line_coord(sd, b)), std::max(line_coord(sd, a), line_coord(sd, b))});
      }
    };
    for (const geom::Polygon& poly : s_.cell(n, l_).polys) {
      scan(poly.outer.pts);
      for (const geom::Contour& h : poly.holes) scan(h.pts);
    }
  }
}

// Rounded crossing points lie off the edge line: bound their effect on the volume.
void WallBuilder::add_rounding_bound(const Point& u, const Point& v) {
  const double len_mm = std::hypot(geom::to_mm(v.X - u.X), geom::to_mm(v.Y - u.Y));
  for (const auto* ch : {&cb_, &ct_})
    for (std::size_t i = 1; i + 1 < ch->size(); ++i) {
      const double a2 = std::abs(triangle_area2(u, v, (*ch)[i]));  // [units²]
      if (a2 == 0.0 || len_mm == 0.0) continue;
      const double d_mm = geom::area_to_mm2(a2) / len_mm;  // distance from the edge line
      wd_.rounding_bound_mm3 += 0.5 * len_mm * d_mm * thick_mm_;
    }
}

// Edge u->v lies on side sd's border, which has a neighbour: walls only along the pieces
// where the neighbour has no material.
void WallBuilder::border_walls(int sd, const Point& u, const Point& v) {
  merged_.clear();
  for (const Point& x : cb_) merged_.push_back(line_coord(sd, x));
  for (const Point& x : ct_) merged_.push_back(line_coord(sd, x));
  const bool asc = line_coord(sd, v) > line_coord(sd, u);
  std::sort(merged_.begin(), merged_.end());
  merged_.erase(std::unique(merged_.begin(), merged_.end()), merged_.end());
  if (!asc) std::reverse(merged_.begin(), merged_.end());
  std::size_t i = 0;
  while (i + 1 < merged_.size()) {
    if (covered(sd, merged_[i], merged_[i + 1])) {
      ++i;
      continue;
    }
    std::size_t e = i + 1;
    while (e + 1 < merged_.size() && !covered(sd, merged_[e], merged_[e + 1])) ++e;
    sub_chain(cb_, sd, u, i, e, rb_);
    sub_chain(ct_, sd, u, i, e, rt_);
    strip(rb_, rt_, u, v);
    i = e;
  }
}

bool WallBuilder::covered(int sd, Coord a, Coord b) const noexcept {
  const Coord lo = std::min(a, b), hi = std::max(a, b);
  for (const auto& [clo, chi] : cover_[sd])
    if (clo <= lo && hi <= chi) return true;
  return false;
}

// The part of chain ch between merged_[i] and merged_[e], with those two ends added when
// the chain has no point there (counted as defects).
void WallBuilder::sub_chain(const std::vector<Point>& ch, int sd, const Point& u, std::size_t i, std::size_t e,
                            std::vector<Point>& out) {
  const Coord lo = std::min(merged_[i], merged_[e]), hi = std::max(merged_[i], merged_[e]);
  out.clear();
  for (const Point& x : ch)
    if (line_coord(sd, x) >= lo && line_coord(sd, x) <= hi) out.push_back(x);
  const Point pa = sd < 2 ? Point{u.X, merged_[i]} : Point{merged_[i], u.Y};
  const Point pb = sd < 2 ? Point{u.X, merged_[e]} : Point{merged_[e], u.Y};
  if (out.empty() || !same(out.front(), pa)) {
    out.insert(out.begin(), pa);
    ++wd_.defects;
  }
  if (!same(out.back(), pb)) {
    out.push_back(pb);
    ++wd_.defects;
  }
}

// Triangles between bottom chain B and top chain T, both running along u->v.
void WallBuilder::strip(const std::vector<Point>& B, const std::vector<Point>& T, const Point& u, const Point& v) {
  std::size_t i = 0, j = 0;
  const int l = l_;
  while (i + 1 < B.size() || j + 1 < T.size()) {
    const bool adv_b = i + 1 < B.size() && (j + 1 >= T.size() || along(u, v, B[i + 1]) <= along(u, v, T[j + 1]));
    if (adv_b) {
      wd_.tris.push_back(resolve({{B[i], B[i + 1], T[j]}, {l, l, l + 1}}));
      ++i;
    } else {
      wd_.tris.push_back(resolve({{B[i], T[j + 1], T[j]}, {l, l + 1, l + 1}}));
      ++j;
    }
  }
}

// Each vertex's height and colour from its plane's vertex table.
Tri WallBuilder::resolve(Tri t) const {
  for (int v = 0; v < 3; ++v) {
    const PlaneData& pd = planes_[t.plane[v]];
    const auto it = pd.verts.find(t.p[v]);
    t.z[v] = it != pd.verts.end() ? it->second.z : plane_z(s_, t.plane[v]);
    t.height[v] = it != pd.verts.end() ? it->second.height : 2 * t.plane[v];
    t.attr[v] = it != pd.verts.end() ? it->second.attr : 0;
  }
  return t;
}

}  // namespace

void build_wall(const geom::LbrSolid& s, int r, int l, const std::vector<PlaneData>& planes, WallData& wd) {
  WallBuilder(s, r, l, planes, wd).run();
}

}  // namespace lbr::mesh::detail
