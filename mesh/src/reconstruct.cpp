// Reconstruction of LBR levels into a closed triangle mesh. docs/mesh.md explains why the
// result is closed; the comments here point at the step each rule protects.
#include "mesh/reconstruct.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "mesh/triangulate.hpp"

namespace lbr::mesh {

BuildStats& BuildStats::operator+=(const BuildStats& o) noexcept {
  planes_built += o.planes_built;
  levels_built += o.levels_built;
  regions_built += o.regions_built;
  triangles += o.triangles;
  defects += o.defects;
  forced_ears += o.forced_ears;
  return *this;
}

namespace {

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
EdgeKey undirected(const Point& a, const Point& b) noexcept {
  const bool lt = a.X != b.X ? a.X < b.X : a.Y < b.Y;
  return lt ? EdgeKey{a, b} : EdgeKey{b, a};
}

int orient(const Point& a, const Point& b, const Point& c) noexcept {
  const i128 v = static_cast<i128>(b.X - a.X) * (c.Y - a.Y) - static_cast<i128>(b.Y - a.Y) * (c.X - a.X);
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}
bool same(const Point& a, const Point& b) noexcept { return a.X == b.X && a.Y == b.Y; }
// x is collinear with ab (caller checked) and lies strictly between a and b.
bool strictly_between(const Point& a, const Point& b, const Point& x) noexcept {
  if (same(x, a) || same(x, b)) return false;
  return std::min(a.X, b.X) <= x.X && x.X <= std::max(a.X, b.X) && std::min(a.Y, b.Y) <= x.Y &&
         x.Y <= std::max(a.Y, b.Y);
}
i128 along(const Point& a, const Point& b, const Point& x) noexcept {
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

void contours_of(const geom::Cell& cell, std::vector<const geom::Contour*>& out) {
  out.clear();
  for (const geom::Polygon& p : cell.polys) {
    out.push_back(&p.outer);
    for (const geom::Contour& h : p.holes) out.push_back(&h);
  }
}

// Sides of a region rectangle: 0 left (x = x0), 1 right (x = x1), 2 bottom (y = y0), 3 top.
int neighbour(const geom::LbrSolid& s, int r, int side) noexcept {
  const int nx = s.regions_x(), ny = s.regions_y();
  const int ix = r % nx, iy = r / nx;
  switch (side) {
    case 0: return ix > 0 ? r - 1 : -1;
    case 1: return ix < nx - 1 ? r + 1 : -1;
    case 2: return iy > 0 ? r - nx : -1;
    default: return iy < ny - 1 ? r + nx : -1;
  }
}
bool on_side(const geom::Rect& rr, int side, const Point& p) noexcept {
  switch (side) {
    case 0: return p.X == rr.x0;
    case 1: return p.X == rr.x1;
    case 2: return p.Y == rr.y0;
    default: return p.Y == rr.y1;
  }
}
Coord line_coord(int side, const Point& p) noexcept { return side < 2 ? p.Y : p.X; }
// Side whose line holds the whole edge ab, or -1.
int edge_side(const geom::Rect& rr, const Point& a, const Point& b) noexcept {
  for (int sd = 0; sd < 4; ++sd)
    if (on_side(rr, sd, a) && on_side(rr, sd, b)) return sd;
  return -1;
}

}  // namespace

struct Reconstructor::Cache {
  int nx = 0, ny = 0, levels = 0;
  std::vector<RegionCache> regions;
  std::vector<std::uint8_t> plane_dirty, wall_dirty, region_dirty;
  TriangulateScratch tscratch;
  std::vector<Triangle2> tris2;

  std::size_t pidx(int r, int k) const noexcept { return static_cast<std::size_t>(r) * (levels + 1) + k; }
  std::size_t widx(int r, int l) const noexcept { return static_cast<std::size_t>(r) * levels + l; }

  double plane_z(const geom::LbrSolid& s, int k) const noexcept {
    return k < levels ? s.level_bottom_mm(k) : s.z_top_mm();
  }

  void build_plane(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt);
  void build_wall(const geom::LbrSolid& s, int r, int l);
  void assemble(const geom::LbrSolid& s, int r);
  BuildStats run(const geom::LbrSolid& s, const MeshOptions& opt);
};

void Reconstructor::Cache::build_plane(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt) {
  PlaneData& pd = regions[r].planes[k];
  pd.caps.clear();
  pd.verts.clear();
  pd.defects = pd.forced = 0;
  const geom::Rect rr = s.region_rect(r);
  const double zk = plane_z(s, k);

  // Vertices on a border shared with a neighbour are decided by the border rule below,
  // which both regions evaluate on the same data; the stock's own faces need no agreement.
  std::array<bool, 4> has_n{};
  for (int sd = 0; sd < 4; ++sd) has_n[sd] = neighbour(s, r, sd) >= 0;
  auto on_shared_border = [&](const Point& x) {
    for (int sd = 0; sd < 4; ++sd)
      if (has_n[sd] && on_side(rr, sd, x)) return true;
    return false;
  };

  std::array<std::vector<const geom::Contour*>, 2> cs;
  if (k > 0) contours_of(s.cell(r, k - 1), cs[0]);
  else cs[0].clear();
  if (k < levels) contours_of(s.cell(r, k), cs[1]);
  else cs[1].clear();
  // Identical levels (most levels of a part are): no crossings, no caps; only the border
  // splits remain to be done.
  bool identical = cs[0].size() == cs[1].size() && !cs[0].empty();
  for (std::size_t c = 0; identical && c < cs[0].size(); ++c) identical = cs[0][c]->pts == cs[1][c]->pts;

  // Working copies of the two levels' contours; is_orig marks each level's own vertices.
  std::array<std::vector<Path>, 2> work;
  std::array<std::vector<std::vector<std::uint8_t>>, 2> is_orig;
  for (int sd = 0; sd < 2; ++sd) {
    work[sd].resize(cs[sd].size());
    is_orig[sd].resize(cs[sd].size());
    for (std::size_t c = 0; c < cs[sd].size(); ++c) {
      work[sd][c] = cs[sd][c]->pts;
      is_orig[sd][c].assign(work[sd][c].size(), 1);
    }
  }

  // Neighbours' vertices on the shared borders (levels k-1 and k): the border edges here
  // are split at them so both regions use the same edges along the border. Exact: the
  // border lines are axis-parallel and every such vertex lies on them exactly.
  std::array<std::vector<Coord>, 4> border;
  for (int sd = 0; sd < 4; ++sd) {
    const int n = neighbour(s, r, sd);
    if (n < 0) continue;
    std::vector<Coord>& pts = border[sd];
    for (int lev = k - 1; lev <= k; ++lev) {
      if (lev < 0 || lev >= levels) continue;
      for (const geom::Polygon& poly : s.cell(n, lev).polys) {
        for (const Point& q : poly.outer.pts)
          if (on_side(rr, sd, q)) pts.push_back(line_coord(sd, q));
        for (const geom::Contour& h : poly.holes)
          for (const Point& q : h.pts)
            if (on_side(rr, sd, q)) pts.push_back(line_coord(sd, q));
      }
    }
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  }

  // Noding of the two levels against each other, repeated until stable: a vertex of one
  // level within kNodeTol of an edge of the other is inserted into that edge (this absorbs
  // Clipper's rounding of intersection points, which leaves shared boundary points up to
  // ~0.7 units off each other's edges); proper crossings get a rounded intersection point
  // inserted into both edges. Afterwards the caps Clipper returns are made of noded edges
  // (see the feedback loop below for the rare exception).
  constexpr i128 kNodeTol = 2;  // [units]
  auto near_inside = [](const Point& a, const Point& b, const Point& w) {
    if (same(w, a) || same(w, b)) return false;
    const i128 dx = b.X - a.X, dy = b.Y - a.Y;
    const i128 l2 = dx * dx + dy * dy;
    const i128 t = static_cast<i128>(w.X - a.X) * dx + static_cast<i128>(w.Y - a.Y) * dy;
    if (l2 == 0 || t <= 0 || t >= l2) return false;
    const i128 cr = dx * (w.Y - a.Y) - dy * (w.X - a.X);
    return cr * cr <= kNodeTol * kNodeTol * l2;
  };
  // Edges on a shared border take only points exactly on the border: the neighbour must
  // see the same split points, and it only knows the ones on the line.
  auto may_insert = [&](const Point& a, const Point& b, const Point& w) {
    if (!near_inside(a, b, w)) return false;
    const int sd = edge_side(rr, a, b);
    return sd < 0 || !has_n[sd] || on_side(rr, sd, w);
  };
  struct Seg {
    Coord x0, x1, y0, y1;
    std::uint32_t side, c, j;
  };
  std::vector<Seg> segs;
  std::array<std::vector<std::vector<std::vector<Point>>>, 2> splits;
  const double wjoin = opt.join_width_levels * s.level_spacing_mm() * geom::kUnitsPerMm;

  // Clipper may still make a vertex of its own where two edges nearly touch (its scanbeam
  // rounding sees them as collinear); such vertices are fed back into the noding and the
  // plane is redone (at most 3 times; what remains is counted in `defects`).
  std::vector<Point> extra, feed;
  for (int attempt = 0;; ++attempt) {
    pd.caps.clear();
    pd.verts.clear();
    pd.defects = pd.forced = 0;
    feed.swap(extra);
    extra.clear();
    for (int round = 0; round < 8; ++round) {
      segs.clear();
      for (int sd = 0; sd < 2; ++sd) {
        splits[sd].resize(work[sd].size());
        for (std::uint32_t c = 0; c < work[sd].size(); ++c) {
          const Path& p = work[sd][c];
          splits[sd][c].assign(p.size(), {});
          for (std::uint32_t j = 0; j < p.size(); ++j) {
            const Point& a = p[j];
            const Point& b = p[(j + 1) % p.size()];
            segs.push_back({std::min(a.X, b.X), std::max(a.X, b.X), std::min(a.Y, b.Y), std::max(a.Y, b.Y),
                            static_cast<std::uint32_t>(sd), c, j});
          }
        }
      }
      auto seg_pts = [&](const Seg& g) -> std::pair<Point, Point> {
        const Path& p = work[g.side][g.c];
        return {p[g.j], p[(g.j + 1) % p.size()]};
      };
      // w is the vertex before the segment's start or after its end: inserting it would make
      // the ring run w -> a -> w (or w -> b -> w), a zero-area spike whose two walls meet the
      // edges beside them four times (a non-manifold edge; issue 13 item 6).
      auto folds = [&](const Seg& g, const Point& w) {
        const Path& p = work[g.side][g.c];
        const std::size_t n = p.size();
        return same(w, p[(g.j + n - 1) % n]) || same(w, p[(g.j + 2) % n]);
      };
      auto insert_ok = [&](const Seg& g, const Point& a, const Point& b, const Point& w) {
        return may_insert(a, b, w) && !folds(g, w);
      };
      // w = ring[i] of the other level lies off the edge a->b (within the tolerance) and its
      // edge to a ring neighbour lying on a->b runs the other way: the two levels' material is
      // on opposite sides of that stretch. Snapping w onto a->b would make that edge one of
      // both levels with opposite material, four faces on one edge (a ball contour grazing
      // the stock face within 2 units in high.ngc). Clipper's cap follows w's own edge instead.
      auto opposed = [&](const Seg& g, std::size_t i, const Point& a, const Point& b) {
        const Path& ring = work[g.side][g.c];
        const std::size_t n = ring.size();
        const Point& w = ring[i % n];
        if (orient(a, b, w) == 0) return false;  // exactly on the edge: always a split point
        const Point& prev = ring[(i + n - 1) % n];
        const Point& next = ring[(i + 1) % n];
        auto on_ab = [&](const Point& x) { return same(x, a) || same(x, b) || near_inside(a, b, x); };
        return (on_ab(prev) && along(a, b, w) < along(a, b, prev)) || (on_ab(next) && along(a, b, next) < along(a, b, w));
      };
      bool any = false;
      if (round == 0)
        for (const Seg& g : segs)
          for (int sd = 0; sd < 4; ++sd) {
            const auto [a, b] = seg_pts(g);
            if (border[sd].empty() || !on_side(rr, sd, a) || !on_side(rr, sd, b)) continue;
            const Coord lo = std::min(line_coord(sd, a), line_coord(sd, b));
            const Coord hi = std::max(line_coord(sd, a), line_coord(sd, b));
            for (auto it = std::upper_bound(border[sd].begin(), border[sd].end(), lo);
                 it != border[sd].end() && *it < hi; ++it) {
              splits[g.side][g.c][g.j].push_back(sd < 2 ? Point{a.X, *it} : Point{*it, a.Y});
              any = true;
            }
          }
      if (round == 0)
        for (const Point& w : feed)
          for (const Seg& g : segs) {
            const auto [a, b] = seg_pts(g);
            if (insert_ok(g, a, b, w)) {
              splits[g.side][g.c][g.j].push_back(w);
              any = true;
            }
          }
      std::sort(segs.begin(), segs.end(), [](const Seg& a, const Seg& b) { return a.x0 < b.x0; });
      const Coord tol = static_cast<Coord>(kNodeTol);
      for (std::size_t i = 0; !identical && i < segs.size(); ++i) {
        const Seg& A = segs[i];
        for (std::size_t m = i + 1; m < segs.size() && segs[m].x0 <= A.x1 + tol; ++m) {
          const Seg& B = segs[m];
          if (A.side == B.side || B.y0 > A.y1 + tol || A.y0 > B.y1 + tol) continue;
          const auto [p1, p2] = seg_pts(A);
          const auto [q1, q2] = seg_pts(B);
          auto& sa = splits[A.side][A.c][A.j];
          auto& sb = splits[B.side][B.c][B.j];
          const bool t1 = may_insert(q1, q2, p1), t2 = may_insert(q1, q2, p2);
          const bool t3 = may_insert(p1, p2, q1), t4 = may_insert(p1, p2, q2);
          const std::size_t before = sa.size() + sb.size();
          if (t1 && !folds(B, p1) && !opposed(A, A.j, q1, q2)) sb.push_back(p1);
          if (t2 && !folds(B, p2) && !opposed(A, A.j + 1, q1, q2)) sb.push_back(p2);
          if (t3 && !folds(A, q1) && !opposed(B, B.j, p1, p2)) sa.push_back(q1);
          if (t4 && !folds(A, q2) && !opposed(B, B.j + 1, p1, p2)) sa.push_back(q2);
          if (t1 || t2 || t3 || t4) {  // touching, not crossing (a skipped point stays a touch)
            any = any || sa.size() + sb.size() != before;
            continue;
          }
          const int d1 = orient(q1, q2, p1), d2 = orient(q1, q2, p2);
          const int d3 = orient(p1, p2, q1), d4 = orient(p1, p2, q2);
          if (d1 * d2 < 0 && d3 * d4 < 0) {
            const long double rx = static_cast<long double>(p2.X - p1.X), ry = static_cast<long double>(p2.Y - p1.Y);
            const long double sx = static_cast<long double>(q2.X - q1.X), sy = static_cast<long double>(q2.Y - q1.Y);
            const long double den = rx * sy - ry * sx;
            const long double t =
                (static_cast<long double>(q1.X - p1.X) * sy - static_cast<long double>(q1.Y - p1.Y) * sx) / den;
            const Point x{static_cast<Coord>(std::llround(static_cast<double>(p1.X + t * rx))),
                          static_cast<Coord>(std::llround(static_cast<double>(p1.Y + t * ry)))};
            if (!same(x, p1) && !same(x, p2)) sa.push_back(x);
            if (!same(x, q1) && !same(x, q2)) sb.push_back(x);
            any = true;
          }
        }
      }
      if (!any) break;
      for (int sd = 0; sd < 2; ++sd)
        for (std::uint32_t c = 0; c < work[sd].size(); ++c) {
          const Path& p = work[sd][c];
          Path np;
          std::vector<std::uint8_t> no;
          for (std::uint32_t j = 0; j < p.size(); ++j) {
            const Point& a = p[j];
            const Point& b = p[(j + 1) % p.size()];
            np.push_back(a);
            no.push_back(is_orig[sd][c][j]);
            auto& sp = splits[sd][c][j];
            std::sort(sp.begin(), sp.end(), [&](const Point& u, const Point& v) { return along(a, b, u) < along(a, b, v); });
            for (const Point& x : sp)
              if (!same(x, a) && !same(x, b) && !same(x, np.back())) {
                np.push_back(x);
                no.push_back(0);
              }
          }
          work[sd][c] = std::move(np);
          is_orig[sd][c] = std::move(no);
        }
    }

    // Noded contours and the plane's vertex table.
    for (int sd = 0; sd < 2; ++sd) {
      pd.side[sd].resize(cs[sd].size());
      for (std::uint32_t c = 0; c < cs[sd].size(); ++c) {
        Noded& nd = pd.side[sd][c];
        nd.pts = work[sd][c];
        nd.orig.clear();
        for (std::uint32_t i = 0; i < nd.pts.size(); ++i)
          if (is_orig[sd][c][i]) nd.orig.push_back(i);
        const MoveId id = cs[sd][c]->cut_by;
        for (std::uint32_t i = 0; i < nd.pts.size(); ++i) {
          const Point& x = nd.pts[i];
          auto it = pd.verts.try_emplace(x, VInfo{zk, 2 * k, 0, 0}).first;
          it->second.flags |= (sd == 0 ? kLower : kUpper);
          if (is_orig[sd][c][i]) it->second.flags |= (sd == 0 ? kLowerOrig : kUpperOrig);
          if (on_shared_border(x)) it->second.flags |= kPinned;
          it->second.attr = std::max(it->second.attr, id);
        }
      }
    }

    // Caps: below minus above faces up, above minus below faces down.
    std::unordered_set<EdgeKey, EdgeHash, EdgeEq> edges;
    for (int sd = 0; sd < 2; ++sd)
      for (const Noded& nd : pd.side[sd])
        for (std::size_t j = 0; j < nd.pts.size(); ++j) edges.insert(undirected(nd.pts[j], nd.pts[(j + 1) % nd.pts.size()]));

    for (int dir = 0; dir < 2 && !identical; ++dir) {
      const auto& subj = pd.side[dir];
      const auto& clip = pd.side[1 - dir];
      if (subj.empty()) continue;
      ClipperLib::Clipper cl;
      cl.PreserveCollinear(true);
      cl.StrictlySimple(false);  // strictly simple output adds vertices where output edges touch
      for (const Noded& nd : subj) cl.AddPath(nd.pts, ClipperLib::ptSubject, true);
      for (const Noded& nd : clip) cl.AddPath(nd.pts, ClipperLib::ptClip, true);
      ClipperLib::PolyTree tree;
      cl.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);

      // Cap edges must be edges of the noded contours; Clipper may drop a collinear vertex,
      // which is put back here (exactly collinear plane vertices strictly inside the edge).
      auto fix_ring = [&](const Path& in, Path& out) {
        out.clear();
        for (std::size_t j = 0; j < in.size(); ++j) {
          const Point& u = in[j];
          const Point& v = in[(j + 1) % in.size()];
          out.push_back(u);
          if (edges.count(undirected(u, v))) continue;
          std::vector<Point> mid;
          for (const auto& [w, info] : pd.verts)
            if (orient(u, v, w) == 0 && strictly_between(u, v, w)) mid.push_back(w);
          std::sort(mid.begin(), mid.end(), [&](const Point& a, const Point& b) { return along(u, v, a) < along(u, v, b); });
          Point prev = u;
          for (const Point& w : mid) {
            if (!edges.count(undirected(prev, w))) ++pd.defects;
            out.push_back(w);
            prev = w;
          }
          if (!edges.count(undirected(prev, v))) {
            ++pd.defects;


          }
        }
        for (const Point& x : out)
          if (!pd.verts.count(x)) {
            extra.push_back(x);  // made by Clipper: fed back into the noding below
            pd.verts.emplace(x, VInfo{zk, 2 * k, 0, kPinned});
          }
      };

      std::vector<const ClipperLib::PolyNode*> stack;
      for (const ClipperLib::PolyNode* c : tree.Childs) stack.push_back(c);
      std::vector<Path> rings;
      std::vector<const Path*> ring_ptrs;
      while (!stack.empty()) {
        const ClipperLib::PolyNode* outer = stack.back();
        stack.pop_back();
        rings.assign(1 + outer->Childs.size(), Path{});
        fix_ring(outer->Contour, rings[0]);
        for (std::size_t h = 0; h < outer->Childs.size(); ++h) {
          fix_ring(outer->Childs[h]->Contour, rings[h + 1]);
          for (const ClipperLib::PolyNode* isl : outer->Childs[h]->Childs) stack.push_back(isl);
        }
        const geom::Rect box = geom::bounds_of(rings[0]);
        const bool narrow = static_cast<double>(std::min(box.x1 - box.x0, box.y1 - box.y0)) <= wjoin;
        for (const Path& ring : rings)
          for (const Point& x : ring) pd.verts[x].flags |= narrow ? kNarrow : kWide;
        // Colour by time: a cap was exposed by the cuts that made its far level's contours;
        // its vertices (also those on untouched edges) take the latest of them.
        MoveId cap_attr = 0;
        const std::uint8_t far_side = dir == 0 ? kUpper : kLower;
        for (const Path& ring : rings)
          for (const Point& x : ring) {
            const VInfo& vi = pd.verts[x];
            if (vi.flags & far_side) cap_attr = std::max(cap_attr, vi.attr);
          }
        // No far-level contour (the level beyond was cut away entirely in this region): the
        // cut that emptied that cell exposed the cap.
        if (cap_attr == 0) {
          const int far_level = dir == 0 ? k : k - 1;
          if (far_level >= 0 && far_level < levels) cap_attr = s.cell(r, far_level).last_cut;
        }
        for (const Path& ring : rings)
          for (const Point& x : ring) pd.verts[x].attr = std::max(pd.verts[x].attr, cap_attr);
        ring_ptrs.clear();
        for (const Path& ring : rings) ring_ptrs.push_back(&ring);
        tris2.clear();
        pd.forced += triangulate(ring_ptrs, tris2, tscratch).forced;
        for (const Triangle2& t : tris2) {
          Tri tri{{t[0], t[1], t[2]}, {k, k, k}};
          if (dir == 1) std::swap(tri.p[1], tri.p[2]);
          pd.caps.push_back(tri);
        }
      }
    }

    if (extra.empty()) break;
    if (attempt == 3) {
      pd.defects += extra.size();
      break;
    }
  }

  // Joined walls: a vertex on only one of the two levels, on narrow steps only, moves to
  // that level's mid-plane (where the kernel sampled it). Vertices on the region border stay,
  // so that the neighbour, which decides independently, agrees on them.
  if (opt.walls == WallMode::Joined) {
    // A corner of only one of the two levels (it may lie on an edge of the other: moving it
    // keeps that edge's wall in its vertical plane) moves to its level's mid-plane when its
    // step is narrow and the wall continuing it beyond that level is not vertical (the
    // level two away has no vertex there): sharp flat-end steps and flat floors stay.
    auto to_mid = [&](VInfo& v, int level) {
      v.z = s.level_z_mm(level);
      v.height = 2 * level + 1;
    };
    std::unordered_set<Point, PointHash, PointEq> below2, above1;
    auto fill = [&](int lev, std::unordered_set<Point, PointHash, PointEq>& out) {
      if (lev < 0 || lev >= levels) return;
      for (const geom::Polygon& poly : s.cell(r, lev).polys) {
        out.insert(poly.outer.pts.begin(), poly.outer.pts.end());
        for (const geom::Contour& h : poly.holes) out.insert(h.pts.begin(), h.pts.end());
      }
    };
    fill(k - 2, below2);
    fill(k + 1, above1);
    for (auto& [x, v] : pd.verts) {
      if ((v.flags & kPinned) || !(v.flags & kNarrow) || (v.flags & kWide)) continue;
      const std::uint8_t o = v.flags & (kLowerOrig | kUpperOrig);
      if (o == kLowerOrig && !below2.count(x)) to_mid(v, k - 1);
      else if (o == kUpperOrig && !above1.count(x)) to_mid(v, k);
    }
    // Border rule: on a shared border line, the union of both regions' levels k-1 and k is
    // seen as intervals; a vertex where only the level-(k-1) material ends moves to that
    // level's mid-plane when the level-k material ends within the join width along the
    // line (a narrow step), and conversely. Corners (shared with a diagonal neighbour) stay.
    std::vector<Coord> lo_end, up_end, lo2_end, up1_end, all_end;
    auto ends = [&](int n, int lev, int sd, std::vector<Coord>& out) {
      if (lev < 0 || lev >= levels) return;
      for (const geom::Polygon& poly : s.cell(n, lev).polys) {
        auto scan = [&](const Path& q) {
          for (std::size_t j = 0; j < q.size(); ++j) {
            const Point& a = q[j];
            const Point& b = q[(j + 1) % q.size()];
            if (on_side(rr, sd, a) && on_side(rr, sd, b)) {
              out.push_back(line_coord(sd, a));
              out.push_back(line_coord(sd, b));
            }
          }
        };
        scan(poly.outer.pts);
        for (const geom::Contour& h : poly.holes) scan(h.pts);
      }
    };
    auto has = [](const std::vector<Coord>& v, Coord c) { return std::binary_search(v.begin(), v.end(), c); };
    for (int sd = 0; sd < 4; ++sd) {
      if (!has_n[sd]) continue;
      const int n = neighbour(s, r, sd);
      lo_end.clear();
      up_end.clear();
      lo2_end.clear();
      up1_end.clear();
      for (int reg : {r, n}) {
        ends(reg, k - 1, sd, lo_end);
        ends(reg, k, sd, up_end);
        ends(reg, k - 2, sd, lo2_end);
        ends(reg, k + 1, sd, up1_end);
      }
      std::sort(lo2_end.begin(), lo2_end.end());
      std::sort(up1_end.begin(), up1_end.end());
      std::sort(lo_end.begin(), lo_end.end());
      lo_end.erase(std::unique(lo_end.begin(), lo_end.end()), lo_end.end());
      std::sort(up_end.begin(), up_end.end());
      up_end.erase(std::unique(up_end.begin(), up_end.end()), up_end.end());
      all_end = lo_end;
      all_end.insert(all_end.end(), up_end.begin(), up_end.end());
      std::sort(all_end.begin(), all_end.end());
      all_end.erase(std::unique(all_end.begin(), all_end.end()), all_end.end());
      // Narrow: another end of either level within the join width along the line.
      auto near_other = [&](Coord c) {
        auto it = std::lower_bound(all_end.begin(), all_end.end(), c);
        double d = 1e300;
        if (it != all_end.end() && std::next(it) != all_end.end()) d = std::min(d, static_cast<double>(*std::next(it) - c));
        if (it != all_end.begin()) d = std::min(d, static_cast<double>(c - *std::prev(it)));
        return d <= wjoin;
      };
      for (auto& [x, v] : pd.verts) {
        if (!on_side(rr, sd, x)) continue;
        bool corner = false;
        for (int sd2 = 0; sd2 < 4; ++sd2)
          if (sd2 != sd && on_side(rr, sd2, x)) corner = true;
        if (corner) continue;
        const Coord c = line_coord(sd, x);
        const bool lo = has(lo_end, c), up = has(up_end, c);
        if (lo && !up && !has(lo2_end, c) && near_other(c)) to_mid(v, k - 1);
        else if (up && !lo && !has(up1_end, c) && near_other(c)) to_mid(v, k);
      }
    }
  }
  for (Tri& t : pd.caps)
    for (int v = 0; v < 3; ++v) {
      const auto it = pd.verts.find(t.p[v]);
      t.z[v] = it != pd.verts.end() ? it->second.z : zk;
      t.height[v] = it != pd.verts.end() ? it->second.height : 2 * k;
      t.attr[v] = it != pd.verts.end() ? it->second.attr : 0;
    }
}

void Reconstructor::Cache::build_wall(const geom::LbrSolid& s, int r, int l) {
  WallData& wd = regions[r].walls[l];
  wd.tris.clear();
  wd.rounding_bound_mm3 = 0;
  wd.defects = 0;
  const geom::Rect rr = s.region_rect(r);
  const auto& bot = regions[r].planes[l].side[1];
  const auto& top = regions[r].planes[l + 1].side[0];
  std::vector<const geom::Contour*> cs;
  contours_of(s.cell(r, l), cs);
  const double thick = s.level_thickness_mm(l);

  std::array<std::vector<std::pair<Coord, Coord>>, 4> cover;  // neighbour's material on each border
  std::array<bool, 4> has_n{};
  for (int sd = 0; sd < 4; ++sd) {
    const int n = neighbour(s, r, sd);
    has_n[sd] = n >= 0;
    if (n < 0) continue;
    for (const geom::Polygon& poly : s.cell(n, l).polys) {
      auto scan = [&](const Path& p) {
        for (std::size_t j = 0; j < p.size(); ++j) {
          const Point& a = p[j];
          const Point& b = p[(j + 1) % p.size()];
          if (on_side(rr, sd, a) && on_side(rr, sd, b))
            cover[sd].push_back({std::min(line_coord(sd, a), line_coord(sd, b)), std::max(line_coord(sd, a), line_coord(sd, b))});
        }
      };
      scan(poly.outer.pts);
      for (const geom::Contour& h : poly.holes) scan(h.pts);
    }
  }

  std::vector<Point> cb, ct, rb, rt;
  std::vector<Coord> merged;
  auto chain = [](const Noded& nd, std::uint32_t j, std::vector<Point>& out) {
    out.clear();
    const std::size_t n = nd.orig.size();
    const std::uint32_t e = j + 1 < n ? nd.orig[j + 1] : static_cast<std::uint32_t>(nd.pts.size());
    for (std::uint32_t i = nd.orig[j]; i < e; ++i) out.push_back(nd.pts[i]);
    out.push_back(j + 1 < n ? nd.pts[nd.orig[j + 1]] : nd.pts[0]);
  };
  auto resolve = [&](Tri t) {
    for (int v = 0; v < 3; ++v) {
      const PlaneData& pd = regions[r].planes[t.plane[v]];
      const auto it = pd.verts.find(t.p[v]);
      t.z[v] = it != pd.verts.end() ? it->second.z : plane_z(s, t.plane[v]);
      t.height[v] = it != pd.verts.end() ? it->second.height : 2 * t.plane[v];
      t.attr[v] = it != pd.verts.end() ? it->second.attr : 0;
    }
    return t;
  };
  auto strip = [&](const std::vector<Point>& B, const std::vector<Point>& T, const Point& u, const Point& v) {
    std::size_t i = 0, j = 0;
    while (i + 1 < B.size() || j + 1 < T.size()) {
      const bool adv_b = i + 1 < B.size() && (j + 1 >= T.size() || along(u, v, B[i + 1]) <= along(u, v, T[j + 1]));
      if (adv_b) {
        wd.tris.push_back(resolve({{B[i], B[i + 1], T[j]}, {l, l, l + 1}}));
        ++i;
      } else {
        wd.tris.push_back(resolve({{B[i], T[j + 1], T[j]}, {l, l + 1, l + 1}}));
        ++j;
      }
    }
  };

  for (std::uint32_t c = 0; c < cs.size(); ++c) {
    const Path& p = cs[c]->pts;
    for (std::uint32_t j = 0; j < p.size(); ++j) {
      const Point& u = p[j];
      const Point& v = p[(j + 1) % p.size()];
      chain(bot[c], j, cb);
      chain(top[c], j, ct);
      // Rounded crossing points lie off the edge line: bound their effect on the volume.
      const double len_mm = std::hypot(geom::to_mm(v.X - u.X), geom::to_mm(v.Y - u.Y));
      for (const auto* ch : {&cb, &ct})
        for (std::size_t i = 1; i + 1 < ch->size(); ++i) {
          const double a2 = std::abs(triangle_area2(u, v, (*ch)[i]));  // [units²]
          if (a2 == 0.0 || len_mm == 0.0) continue;
          const double d_mm = geom::area_to_mm2(a2) / len_mm;  // distance from the edge line
          wd.rounding_bound_mm3 += 0.5 * len_mm * d_mm * thick;
        }
      const int sd = edge_side(rr, u, v);
      if (sd < 0 || !has_n[sd]) {
        strip(cb, ct, u, v);
        continue;
      }
      // On a border with a neighbour: walls only where the neighbour has no material.
      merged.clear();
      for (const Point& x : cb) merged.push_back(line_coord(sd, x));
      for (const Point& x : ct) merged.push_back(line_coord(sd, x));
      const bool asc = line_coord(sd, v) > line_coord(sd, u);
      std::sort(merged.begin(), merged.end());
      merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
      if (!asc) std::reverse(merged.begin(), merged.end());
      auto covered = [&](Coord a, Coord b) {
        const Coord lo = std::min(a, b), hi = std::max(a, b);
        for (const auto& [clo, chi] : cover[sd])
          if (clo <= lo && hi <= chi) return true;
        return false;
      };
      std::size_t i = 0;
      while (i + 1 < merged.size()) {
        if (covered(merged[i], merged[i + 1])) {
          ++i;
          continue;
        }
        std::size_t e = i + 1;
        while (e + 1 < merged.size() && !covered(merged[e], merged[e + 1])) ++e;
        const Coord lo = std::min(merged[i], merged[e]), hi = std::max(merged[i], merged[e]);
        auto sub = [&](const std::vector<Point>& ch, std::vector<Point>& out) {
          out.clear();
          for (const Point& x : ch)
            if (line_coord(sd, x) >= lo && line_coord(sd, x) <= hi) out.push_back(x);
          const Point pa = sd < 2 ? Point{u.X, merged[i]} : Point{merged[i], u.Y};
          const Point pb = sd < 2 ? Point{u.X, merged[e]} : Point{merged[e], u.Y};
          if (out.empty() || !same(out.front(), pa)) {
            out.insert(out.begin(), pa);
            ++wd.defects;
          }
          if (!same(out.back(), pb)) {
            out.push_back(pb);
            ++wd.defects;
          }
        };
        sub(cb, rb);
        sub(ct, rt);
        strip(rb, rt, u, v);
        i = e;
      }
    }
  }
}

void Reconstructor::Cache::assemble(const geom::LbrSolid& s, int r) {
  RegionCache& rc = regions[r];
  MeshBuffers& out = rc.out;
  const std::uint64_t generation = out.generation;
  out = MeshBuffers{};
  out.generation = generation + 1;
  struct AKey {
    VertexKey k;
    int cls;
  };
  struct AHash {
    std::size_t operator()(const AKey& a) const noexcept {
      return PointHash{}(Point{a.k.x, a.k.y}) ^ (static_cast<std::size_t>(a.k.height) * 0x51ED27u) ^
             static_cast<std::size_t>(a.cls);
    }
  };
  struct AEq {
    bool operator()(const AKey& a, const AKey& b) const noexcept { return a.k == b.k && a.cls == b.cls; }
  };
  std::unordered_map<AKey, std::uint32_t, AHash, AEq> index;
  std::vector<double> pos, nrm;
  const double ox = geom::to_mm(s.stock_rect().x0), oy = geom::to_mm(s.stock_rect().y0), oz = s.z_bottom_mm();

  auto add_tri = [&](const Tri& t) {
    // Vertices are identified by position (x, y, height), not by the plane they came from:
    // a joined wall whose two ends moved to the same mid-plane has collapsed, its two vertex
    // columns are one vertex and its triangles have no area. Dropping them keeps every edge
    // paired (each directed edge of a dropped triangle is a loop or cancels against its
    // reverse in the same triangle), so the surface stays closed without zero-area facets.
    const std::array<VertexKey, 3> key{VertexKey{t.p[0].X, t.p[0].Y, t.height[0]},
                                       VertexKey{t.p[1].X, t.p[1].Y, t.height[1]},
                                       VertexKey{t.p[2].X, t.p[2].Y, t.height[2]}};
    if (key[0] == key[1] || key[1] == key[2] || key[0] == key[2]) return;
    std::array<std::array<double, 3>, 3> q{};
    std::array<MoveId, 3> attr{};
    for (int v = 0; v < 3; ++v) {
      attr[v] = t.attr[v];
      q[v] = {geom::to_mm(t.p[v].X) - ox, geom::to_mm(t.p[v].Y) - oy, t.z[v] - oz};
    }
    const std::array<double, 3> e1{q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
    const std::array<double, 3> e2{q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
    const std::array<double, 3> n{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                  e1[0] * e2[1] - e1[1] * e2[0]};
    out.volume_mm3 += (q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) -
                       q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
                       q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0])) / 6.0;
    if (t.plane[0] == t.plane[1] && t.plane[1] == t.plane[2]) {
      double dz = 0;
      for (int v = 0; v < 3; ++v) dz = std::max(dz, std::abs(q[v][2] + oz - plane_z(s, t.plane[v])));
      out.join_bound_mm3 += 0.5 * std::abs(n[2]) * dz;
    }
    const bool flat = q[0][2] == q[1][2] && q[1][2] == q[2][2] && n[2] != 0.0;
    const int cls = flat ? (n[2] > 0 ? 1 : 2) : 0;
    for (int v = 0; v < 3; ++v) {
      const AKey ak{key[v], cls};
      auto [it, fresh] = index.try_emplace(ak, static_cast<std::uint32_t>(out.keys.size()));
      if (fresh) {
        out.keys.push_back(ak.k);
        for (int a = 0; a < 3; ++a) pos.push_back(q[v][a]);
        nrm.insert(nrm.end(), {0.0, 0.0, cls == 1 ? 1.0 : (cls == 2 ? -1.0 : 0.0)});
        out.attributes.push_back(static_cast<float>(attr[v]));
      }
      if (cls == 0)
        for (int a = 0; a < 3; ++a) nrm[3 * it->second + a] += n[a];
      out.indices.push_back(it->second);
    }
  };
  for (const PlaneData& pd : rc.planes)
    for (const Tri& t : pd.caps) add_tri(t);
  for (const WallData& wd : rc.walls) {
    for (const Tri& t : wd.tris) add_tri(t);
    out.rounding_bound_mm3 += wd.rounding_bound_mm3;
  }
  out.positions.resize(pos.size());
  out.normals.resize(nrm.size());
  for (std::size_t v = 0; v < out.keys.size(); ++v) {
    const double wx = nrm[3 * v], wy = nrm[3 * v + 1], wz = nrm[3 * v + 2];
    const double len = std::sqrt(wx * wx + wy * wy + wz * wz);
    for (int a = 0; a < 3; ++a) {
      const double o = a == 0 ? ox : (a == 1 ? oy : oz);
      out.positions[3 * v + a] = static_cast<float>(pos[3 * v + a] + o);
      out.normals[3 * v + a] = len > 0 ? static_cast<float>(nrm[3 * v + a] / len) : (a == 2 ? 1.0f : 0.0f);
    }
  }
}

Reconstructor::Reconstructor(MeshOptions opt) : opt_(opt) {}
Reconstructor::~Reconstructor() = default;
Reconstructor::Reconstructor(Reconstructor&&) noexcept = default;
Reconstructor& Reconstructor::operator=(Reconstructor&&) noexcept = default;

int Reconstructor::regions() const noexcept { return cache_ ? static_cast<int>(cache_->regions.size()) : 0; }
const MeshBuffers& Reconstructor::region(int r) const { return cache_->regions.at(static_cast<std::size_t>(r)).out; }
double Reconstructor::volume_mm3() const noexcept {
  double v = 0;
  if (cache_)
    for (const RegionCache& rc : cache_->regions) v += rc.out.volume_mm3;
  return v;
}
std::size_t Reconstructor::triangle_count() const noexcept {
  std::size_t n = 0;
  if (cache_)
    for (const RegionCache& rc : cache_->regions) n += rc.out.triangle_count();
  return n;
}

BuildStats Reconstructor::build(const geom::LbrSolid& s) {
  cache_ = std::make_unique<Cache>();
  Cache& c = *cache_;
  c.nx = s.regions_x();
  c.ny = s.regions_y();
  c.levels = s.levels();
  c.regions.resize(static_cast<std::size_t>(s.regions()));
  for (RegionCache& rc : c.regions) {
    rc.planes.resize(static_cast<std::size_t>(c.levels) + 1);
    rc.walls.resize(static_cast<std::size_t>(c.levels));
  }
  c.plane_dirty.assign(c.regions.size() * (c.levels + 1), 1);
  c.wall_dirty.assign(c.regions.size() * c.levels, 1);
  c.region_dirty.assign(c.regions.size(), 1);
  return c.run(s, opt_);
}

BuildStats Reconstructor::update(const geom::LbrSolid& s) {
  if (!cache_ || cache_->nx != s.regions_x() || cache_->ny != s.regions_y() || cache_->levels != s.levels())
    return build(s);
  Cache& c = *cache_;
  for (std::uint32_t ci : s.dirty_cells()) {
    const int r = static_cast<int>(ci / static_cast<std::uint32_t>(c.levels));
    const int l = static_cast<int>(ci % static_cast<std::uint32_t>(c.levels));
    // Plane p reads levels p-2 .. p+1 of its region and of its neighbours (joined-wall
    // decisions); walls read their two planes and the neighbours' same level.
    const int p0 = std::max(0, l - 1), p1 = std::min(c.levels, l + 2);
    c.wall_dirty[c.widx(r, l)] = 1;
    for (int p = p0; p <= p1; ++p) c.plane_dirty[c.pidx(r, p)] = 1;
    for (int sd = 0; sd < 4; ++sd) {
      const int n = neighbour(s, r, sd);
      if (n < 0) continue;
      for (int p = p0; p <= p1; ++p) c.plane_dirty[c.pidx(n, p)] = 1;
      c.wall_dirty[c.widx(n, l)] = 1;
    }
  }
  return c.run(s, opt_);
}

BuildStats Reconstructor::Cache::run(const geom::LbrSolid& s, const MeshOptions& opt) {
  Cache& c = *this;
  BuildStats st;
  const int nreg = static_cast<int>(c.regions.size());
  for (int r = 0; r < nreg; ++r)
    for (int k = 0; k <= c.levels; ++k) {
      if (!c.plane_dirty[c.pidx(r, k)]) continue;
      c.build_plane(s, r, k, opt);
      c.plane_dirty[c.pidx(r, k)] = 0;
      ++st.planes_built;
      if (k > 0) c.wall_dirty[c.widx(r, k - 1)] = 1;
      if (k < c.levels) c.wall_dirty[c.widx(r, k)] = 1;
      c.region_dirty[r] = 1;
    }
  for (int r = 0; r < nreg; ++r)
    for (int l = 0; l < c.levels; ++l) {
      if (!c.wall_dirty[c.widx(r, l)]) continue;
      c.build_wall(s, r, l);
      c.wall_dirty[c.widx(r, l)] = 0;
      ++st.levels_built;
      c.region_dirty[r] = 1;
    }
  for (int r = 0; r < nreg; ++r) {
    if (!c.region_dirty[r]) continue;
    c.assemble(s, r);
    c.region_dirty[r] = 0;
    ++st.regions_built;
    st.triangles += c.regions[r].out.triangle_count();
  }
  for (const auto& rc : c.regions) {
    for (const auto& pd : rc.planes) {
      st.defects += pd.defects;
      st.forced_ears += pd.forced;
    }
    for (const auto& wd : rc.walls) st.defects += wd.defects;
  }
  return st;
}

std::vector<MeshBuffers> reconstruct(const geom::LbrSolid& solid, const MeshOptions& opt, BuildStats* stats) {
  Reconstructor rec(opt);
  const BuildStats st = rec.build(solid);
  if (stats) *stats = st;
  std::vector<MeshBuffers> out;
  for (int r = 0; r < rec.regions(); ++r) out.push_back(rec.region(r));
  return out;
}

}  // namespace lbr::mesh
