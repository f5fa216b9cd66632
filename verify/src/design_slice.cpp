// The design model's checks and its sections on the level mid-planes (verify/design.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "verify/design.hpp"

namespace lbr::verify {

namespace {

struct Segment {
  geom::Point a, b;  // directed: material on the left
};

struct PointHash {
  std::size_t operator()(const geom::Point& p) const noexcept {
    return std::hash<long long>()(static_cast<long long>(p.X) * 1000003LL ^ static_cast<long long>(p.Y));
  }
};

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// Where the edge a–b crosses z [units]; the same for both triangles sharing the edge
// (the end points are put in one order first).
geom::Point crossing(geom::Vec3 a, geom::Vec3 b, double z) noexcept {
  if (std::tie(b.x, b.y, b.z) < std::tie(a.x, a.y, a.z)) std::swap(a, b);
  const double t = (z - a.z) / (b.z - a.z);
  return {geom::to_units(a.x + t * (b.x - a.x)), geom::to_units(a.y + t * (b.y - a.y))};
}

// The segment of triangle `t` on plane z, directed so the solid lies on its left (outer
// contours counter-clockwise). A vertex on the plane counts as above it.
bool cut(const Triangle& t, double z, Segment& out) noexcept {
  const bool up[3] = {t.v[0].z >= z, t.v[1].z >= z, t.v[2].z >= z};
  if (up[0] == up[1] && up[1] == up[2]) return false;
  const int lone = up[0] == up[1] ? 2 : (up[0] == up[2] ? 1 : 0);
  const geom::Vec3& l = t.v[lone];
  const geom::Point p = crossing(l, t.v[(lone + 1) % 3], z), q = crossing(l, t.v[(lone + 2) % 3], z);
  out = up[lone] ? Segment{p, q} : Segment{q, p};
  return !(out.a == out.b);
}

// Chains directed segments into closed loops; chains that do not close are dropped.
geom::Paths loops_of(const std::vector<Segment>& segs) {
  std::unordered_multimap<geom::Point, std::size_t, PointHash> from;
  from.reserve(segs.size());
  for (std::size_t i = 0; i < segs.size(); ++i) from.emplace(segs[i].a, i);
  std::vector<char> used(segs.size(), 0);
  geom::Paths out;
  for (std::size_t s = 0; s < segs.size(); ++s) {
    if (used[s] != 0) continue;
    geom::Path loop{segs[s].a};
    used[s] = 1;
    geom::Point at = segs[s].b;
    while (!(at == loop.front())) {
      auto [lo, hi] = from.equal_range(at);
      auto it = std::find_if(lo, hi, [&](const auto& e) { return used[e.second] == 0; });
      if (it == hi) break;
      used[it->second] = 1;
      loop.push_back(at);
      at = segs[it->second].b;
    }
    if (at == loop.front() && loop.size() >= 3) out.push_back(std::move(loop));
  }
  return out;
}

}  // namespace

void check_design(const StlMesh& mesh, const geom::LbrSolid& solid, const std::string& name) {
  if (mesh.triangles.empty()) throw DesignError(name + ": expected a closed triangle mesh, found no triangles");
  const EdgeCheck e = check_edges(mesh);
  if (!e.closed_manifold())
    throw DesignError(name + ": expected a closed, manifold mesh; found " + std::to_string(e.boundary_edges) +
                      " boundary edges (holes) and " + std::to_string(e.non_manifold_edges) +
                      " non-manifold edges (shared by more than two triangles); repair it (e.g. admesh) first");
  if (mesh.volume_mm3() <= 0.0)
    throw DesignError(name + ": expected outward-facing triangles (counter-clockwise seen from outside); the mesh is inside out");
  const geom::Box3 d = mesh.bounds();
  const geom::Rect r = solid.stock_rect();
  const geom::Box3 s{{geom::to_mm(r.x0), geom::to_mm(r.y0), solid.z_bottom_mm()},
                     {geom::to_mm(r.x1), geom::to_mm(r.y1), solid.z_top_mm()}};
  const double d_ext = std::max({d.hi.x - d.lo.x, d.hi.y - d.lo.y, d.hi.z - d.lo.z});
  const double s_ext = std::max({s.hi.x - s.lo.x, s.hi.y - s.lo.y, s.hi.z - s.lo.z});
  if (d_ext * 25.4 > 0.7 * s_ext && d_ext * 25.4 < 1.05 * s_ext)
    throw DesignError(name + ": the design's largest extent (" + mm(d_ext) + ") is 25.4 times smaller than the stock's (" +
                      mm(s_ext) + "): it looks like inches; expected millimetres (scale it by 25.4)");
  constexpr double kSlackMm = 0.01;
  if (d.lo.x < s.lo.x - kSlackMm || d.lo.y < s.lo.y - kSlackMm || d.lo.z < s.lo.z - kSlackMm ||
      d.hi.x > s.hi.x + kSlackMm || d.hi.y > s.hi.y + kSlackMm || d.hi.z > s.hi.z + kSlackMm)
    throw DesignError(name + ": expected the design inside the stock; design X" + mm(d.lo.x) + ".." + mm(d.hi.x) + " Y" +
                      mm(d.lo.y) + ".." + mm(d.hi.y) + " Z" + mm(d.lo.z) + ".." + mm(d.hi.z) + ", stock X" +
                      mm(s.lo.x) + ".." + mm(s.hi.x) + " Y" + mm(s.lo.y) + ".." + mm(s.hi.y) + " Z" + mm(s.lo.z) +
                      ".." + mm(s.hi.z) + " (same work coordinates as the program, millimetres)");
}

std::vector<geom::Paths> slice_design(const StlMesh& mesh, const geom::LbrSolid& solid) {
  const int n = solid.levels();
  std::vector<std::vector<Segment>> segs(static_cast<std::size_t>(n));
  for (const Triangle& t : mesh.triangles) {
    const double z0 = std::min({t.v[0].z, t.v[1].z, t.v[2].z}), z1 = std::max({t.v[0].z, t.v[1].z, t.v[2].z});
    for (int l = std::max(0, solid.level_at(z0) - 1); l <= std::min(n - 1, solid.level_at(z1) + 1); ++l) {
      const double z = solid.level_z_mm(l);
      Segment s;
      if (z >= z0 && z <= z1 && cut(t, z, s)) segs[static_cast<std::size_t>(l)].push_back(s);
    }
  }
  std::vector<geom::Paths> out(static_cast<std::size_t>(n));
  ClipperLib::Clipper c;
  for (int l = 0; l < n; ++l) {
    const auto k = static_cast<std::size_t>(l);
    if (segs[k].empty()) continue;
    c.Clear();
    c.AddPaths(loops_of(segs[k]), ClipperLib::ptSubject, true);
    c.Execute(ClipperLib::ctUnion, out[k], ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  }
  return out;
}

}  // namespace lbr::verify
