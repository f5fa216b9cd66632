// Private to mesh/: the types and exact predicates that plane building (plane.cpp), wall
// building (wall.cpp) and assembly (reconstruct.cpp) share. docs/mesh.md explains the reconstruction.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "mesh/reconstruct.hpp"
#include "mesh/triangulate.hpp"

namespace lbr::mesh::detail {

using geom::Coord;
using geom::MoveId;
using geom::Path;
using geom::Point;
__extension__ typedef __int128 i128;

struct PointHash {
  std::size_t operator()(const Point& p) const noexcept {
    std::uint64_t h = static_cast<std::uint64_t>(p.X) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(p.Y) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h);
  }
};
struct PointEq {
  bool operator()(const Point& a, const Point& b) const noexcept { return a.X == b.X && a.Y == b.Y; }
};
using EdgeKey = std::pair<Point, Point>;
struct EdgeHash {
  std::size_t operator()(const EdgeKey& e) const noexcept {
    return PointHash{}(e.first) * 31u + PointHash{}(e.second);
  }
};
struct EdgeEq {
  bool operator()(const EdgeKey& a, const EdgeKey& b) const noexcept {
    return PointEq{}(a.first, b.first) && PointEq{}(a.second, b.second);
  }
};
inline EdgeKey undirected(const Point& a, const Point& b) noexcept {
  const bool lt = a.X != b.X ? a.X < b.X : a.Y < b.Y;
  return lt ? EdgeKey{a, b} : EdgeKey{b, a};
}

inline int orient(const Point& a, const Point& b, const Point& c) noexcept {
  const i128 v = static_cast<i128>(b.X - a.X) * (c.Y - a.Y) - static_cast<i128>(b.Y - a.Y) * (c.X - a.X);
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}
inline bool same(const Point& a, const Point& b) noexcept { return a.X == b.X && a.Y == b.Y; }
// x is collinear with ab (caller checked) and lies strictly between a and b.
inline bool strictly_between(const Point& a, const Point& b, const Point& x) noexcept {
  if (same(x, a) || same(x, b)) return false;
  return std::min(a.X, b.X) <= x.X && x.X <= std::max(a.X, b.X) && std::min(a.Y, b.Y) <= x.Y &&
         x.Y <= std::max(a.Y, b.Y);
}
inline i128 along(const Point& a, const Point& b, const Point& x) noexcept {
  return static_cast<i128>(x.X - a.X) * (b.X - a.X) + static_cast<i128>(x.Y - a.Y) * (b.Y - a.Y);
}

// Vertex flags at a plane: on the boundary of the level below / above (as a vertex of its
// noded contour), an original vertex of that level (not an inserted split point), on a
// border shared with a neighbour, on a narrow / wide cap polygon.
enum : std::uint8_t {
  kLower = 1, kUpper = 2, kPinned = 4, kNarrow = 8, kWide = 16, kLowerOrig = 32, kUpperOrig = 64
};

struct VInfo {
  double z = 0;
  std::int32_t height = 0;  // VertexKey::height: 2k at plane k, 2l+1 when moved to level l's mid-plane
  MoveId attr = 0;
  std::uint8_t flags = 0;
};

// A contour of one level with the plane's split points inserted; orig[j] = index of the
// contour's vertex j in pts.
struct Noded {
  Path pts;
  std::vector<std::uint32_t> orig;
};

// A triangle by exact vertex identities, with each vertex's height and attribute resolved
// when the triangle is built (walls are rebuilt whenever one of their planes is, so these
// stay current) so that assembly needs no vertex-table lookups.
struct Tri {
  std::array<Point, 3> p;
  std::array<std::int32_t, 3> plane;
  std::array<double, 3> z{};
  std::array<std::int32_t, 3> height{};
  std::array<MoveId, 3> attr{};
};

struct PlaneData {
  std::array<std::vector<Noded>, 2> side;  // 0: level k-1 (below), 1: level k (above)
  std::vector<Tri> caps;
  std::unordered_map<Point, VInfo, PointHash, PointEq> verts;
  std::uint64_t defects = 0, forced = 0;
};

struct WallData {
  std::vector<Tri> tris;
  double rounding_bound_mm3 = 0;
  std::uint64_t defects = 0;
};

struct RegionCache {
  std::vector<PlaneData> planes;  // levels + 1
  std::vector<WallData> walls;    // levels
  MeshBuffers out;
};

inline void contours_of(const geom::Cell& cell, std::vector<const geom::Contour*>& out) {
  out.clear();
  for (const geom::Polygon& p : cell.polys) {
    out.push_back(&p.outer);
    for (const geom::Contour& h : p.holes) out.push_back(&h);
  }
}

// Sides of a region rectangle: 0 left (x = x0), 1 right (x = x1), 2 bottom (y = y0), 3 top.
inline int neighbour(const geom::LbrSolid& s, int r, int side) noexcept {
  const int nx = s.regions_x(), ny = s.regions_y();
  const int ix = r % nx, iy = r / nx;
  switch (side) {
    case 0: return ix > 0 ? r - 1 : -1;
    case 1: return ix < nx - 1 ? r + 1 : -1;
    case 2: return iy > 0 ? r - nx : -1;
    default: return iy < ny - 1 ? r + nx : -1;
  }
}
inline bool on_side(const geom::Rect& rr, int side, const Point& p) noexcept {
  switch (side) {
    case 0: return p.X == rr.x0;
    case 1: return p.X == rr.x1;
    case 2: return p.Y == rr.y0;
    default: return p.Y == rr.y1;
  }
}
inline Coord line_coord(int side, const Point& p) noexcept { return side < 2 ? p.Y : p.X; }
// Side whose line holds the whole edge ab, or -1.
inline int edge_side(const geom::Rect& rr, const Point& a, const Point& b) noexcept {
  for (int sd = 0; sd < 4; ++sd)
    if (on_side(rr, sd, a) && on_side(rr, sd, b)) return sd;
  return -1;
}


// z [mm] of plane k: the bottom of level k, or the stock top for k = levels.
inline double plane_z(const geom::LbrSolid& s, int k) noexcept {
  return k < s.levels() ? s.level_bottom_mm(k) : s.z_top_mm();
}

// Buffers the cap triangulation reuses from plane to plane.
struct CapScratch {
  TriangulateScratch triangulate;
  std::vector<Triangle2> tris;
  std::vector<geom::Path> loops;  // a pinched cap ring's loops (PlaneBuilder::triangulate_lobes())
  geom::Path repeated;            // the vertices a cap ring passes twice
};

// Rebuilds plane k of region r (between levels k-1 and k): the two levels' contours noded
// against each other and the region borders, the vertex table, and the cap triangles.
// Allocates; throws only std::bad_alloc.
void build_plane(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt, PlaneData& pd, CapScratch& scratch);

// Rebuilds the walls of level l of region r from its two planes (planes[l], planes[l+1],
// already built). Allocates; throws only std::bad_alloc.
void build_wall(const geom::LbrSolid& s, int r, int l, const std::vector<PlaneData>& planes, WallData& wd);

}  // namespace lbr::mesh::detail
