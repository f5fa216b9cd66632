// One plane of the reconstruction: the contours of the two levels that meet there, noded
// against each other and against the region borders, the plane's vertex table and its caps
// (docs/mesh.md). The steps are run in order by PlaneBuilder::run(); the comments at each
// step say which rule of the closed mesh it protects.
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_set>
#include <utility>

#include "reconstruct_detail.hpp"

namespace lbr::mesh::detail {

namespace {

// A vertex of one level within kNodeTol of an edge of the other is inserted into that edge
// (this absorbs Clipper's rounding of intersection points, which leaves shared boundary
// points up to ~0.7 units off each other's edges).
constexpr i128 kNodeTol = 2;  // [units]

// w lies within kNodeTol of the open edge a->b, strictly between its ends.
bool near_inside(const Point& a, const Point& b, const Point& w) noexcept {
  if (same(w, a) || same(w, b)) return false;
  const i128 dx = b.X - a.X, dy = b.Y - a.Y;
  const i128 l2 = dx * dx + dy * dy;
  const i128 t = static_cast<i128>(w.X - a.X) * dx + static_cast<i128>(w.Y - a.Y) * dy;
  if (l2 == 0 || t <= 0 || t >= l2) return false;
  const i128 cr = dx * (w.Y - a.Y) - dy * (w.X - a.X);
  return cr * cr <= kNodeTol * kNodeTol * l2;
}

// The crossing of p1p2 and q1q2 (which cross properly), rounded to the grid.
Point crossing_point(const Point& p1, const Point& p2, const Point& q1, const Point& q2) noexcept {
  const long double rx = static_cast<long double>(p2.X - p1.X), ry = static_cast<long double>(p2.Y - p1.Y);
  const long double sx = static_cast<long double>(q2.X - q1.X), sy = static_cast<long double>(q2.Y - q1.Y);
  const long double den = rx * sy - ry * sx;
  const long double t = (static_cast<long double>(q1.X - p1.X) * sy - static_cast<long double>(q1.Y - p1.Y) * sx) / den;
  return Point{static_cast<Coord>(std::llround(static_cast<double>(p1.X + t * rx))),
               static_cast<Coord>(std::llround(static_cast<double>(p1.Y + t * ry)))};
}

using PointSet = std::unordered_set<Point, PointHash, PointEq>;
using EdgeSet = std::unordered_set<EdgeKey, EdgeHash, EdgeEq>;

// Where the material of the levels around plane k ends along one shared border line
// (coordinates along the line), for the border rule of joined walls.
struct BorderEnds {
  std::vector<Coord> lower, upper;    // levels k-1 and k, sorted, unique
  std::vector<Coord> lower2, upper1;  // levels k-2 and k+1, sorted
  std::vector<Coord> all;             // lower and upper together, sorted, unique
};

class PlaneBuilder {
 public:
  PlaneBuilder(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt, PlaneData& pd, CapScratch& scratch)
      : s_(s), r_(r), k_(k), levels_(s.levels()), opt_(opt), pd_(pd), scratch_(scratch),
        rr_(s.region_rect(r)), zk_(plane_z(s, k)),
        wjoin_(opt.join_width_levels * s.level_spacing_mm() * geom::kUnitsPerMm) {}

  void run();

 private:
  // An edge j of contour c of side `side` (0: level k-1, 1: level k), with its bounding box.
  struct Seg {
    Coord x0, x1, y0, y1;
    std::uint32_t side, c, j;
  };

  void reset_plane();
  void load_levels();
  void collect_border_points();
  bool node_round(int round);
  void collect_segments();
  bool split_at_border_points();
  bool split_at_fed_points();
  bool split_touches_and_crossings();
  bool node_pair(const Seg& A, const Seg& B);
  void apply_splits();
  void record_vertices();
  void build_caps(int dir, const EdgeSet& edges);
  void fix_ring(const Path& in, Path& out, const EdgeSet& edges);
  void emit_cap(int dir, const std::vector<Path>& rings);
  static void canonical_order(std::vector<Path>& rings);
  bool triangulate_lobes(const std::vector<Path>& rings);
  MoveId cap_attr(int dir, const std::vector<Path>& rings);
  void join_narrow_steps();
  void join_border_steps();
  void border_ends(int sd, BorderEnds& e) const;
  void ends(int n, int lev, int sd, std::vector<Coord>& out) const;
  void resolve_caps();

  bool on_shared_border(const Point& x) const noexcept;
  bool may_insert(const Point& a, const Point& b, const Point& w) const noexcept;
  std::pair<Point, Point> seg_pts(const Seg& g) const noexcept;
  bool folds(const Seg& g, const Point& w) const noexcept;
  bool opposed(const Seg& g, std::size_t i, const Point& a, const Point& b) const noexcept;
  void to_mid(VInfo& v, int level) const noexcept;

  const geom::LbrSolid& s_;
  const int r_, k_, levels_;
  const MeshOptions& opt_;
  PlaneData& pd_;
  CapScratch& scratch_;
  const geom::Rect rr_;
  const double zk_;
  const double wjoin_;  // join width [units]
  std::array<bool, 4> has_n_{};
  // Contours of levels k-1 and k; both the same (most levels of a part are): no crossings,
  // no caps; only the border splits remain to be done.
  std::array<std::vector<const geom::Contour*>, 2> cs_;
  bool identical_ = false;
  // Working copies of the two levels' contours; is_orig_ marks each level's own vertices.
  std::array<std::vector<Path>, 2> work_;
  std::array<std::vector<std::vector<std::uint8_t>>, 2> is_orig_;
  std::array<std::vector<Coord>, 4> border_;  // neighbours' vertices on each shared border
  std::vector<Seg> segs_;
  std::array<std::vector<std::vector<std::vector<Point>>>, 2> splits_;  // per side, contour, edge
  std::vector<Point> extra_, feed_;  // vertices Clipper made; those of the previous attempt
  std::vector<const Path*> ring_ptrs_;  // the rings of the cap being triangulated
};

void PlaneBuilder::run() {
  reset_plane();
  // Vertices on a border shared with a neighbour are decided by the border rule below,
  // which both regions evaluate on the same data; the stock's own faces need no agreement.
  for (int sd = 0; sd < 4; ++sd) has_n_[sd] = neighbour(s_, r_, sd) >= 0;
  load_levels();
  collect_border_points();

  // Clipper may still make a vertex of its own where two edges nearly touch (its scanbeam
  // rounding sees them as collinear); such vertices are fed back into the noding and the
  // plane is redone (at most 3 times; what remains is counted in `defects`).
  for (int attempt = 0;; ++attempt) {
    reset_plane();
    feed_.swap(extra_);
    extra_.clear();
    for (int round = 0; round < 8; ++round)
      if (!node_round(round)) break;
    record_vertices();

    EdgeSet edges;
    for (int sd = 0; sd < 2; ++sd)
      for (const Noded& nd : pd_.side[sd])
        for (std::size_t j = 0; j < nd.pts.size(); ++j) edges.insert(undirected(nd.pts[j], nd.pts[(j + 1) % nd.pts.size()]));
    for (int dir = 0; dir < 2 && !identical_; ++dir) build_caps(dir, edges);

    if (extra_.empty()) break;
    if (attempt == 3) {
      pd_.defects += extra_.size();
      break;
    }
  }

  // Joined walls: a vertex on only one of the two levels, on narrow steps only, moves to
  // that level's mid-plane (where the kernel sampled it). Vertices on the region border stay,
  // so that the neighbour, which decides independently, agrees on them.
  if (opt_.walls == WallMode::Joined) {
    join_narrow_steps();
    join_border_steps();
  }
  resolve_caps();
}

void PlaneBuilder::reset_plane() {
  pd_.caps.clear();
  pd_.verts.clear();
  pd_.defects = pd_.forced = 0;
}

bool PlaneBuilder::on_shared_border(const Point& x) const noexcept {
  for (int sd = 0; sd < 4; ++sd)
    if (has_n_[sd] && on_side(rr_, sd, x)) return true;
  return false;
}

void PlaneBuilder::load_levels() {
  if (k_ > 0) contours_of(s_.cell(r_, k_ - 1), cs_[0]);
  else cs_[0].clear();
  if (k_ < levels_) contours_of(s_.cell(r_, k_), cs_[1]);
  else cs_[1].clear();
  identical_ = cs_[0].size() == cs_[1].size() && !cs_[0].empty();
  for (std::size_t c = 0; identical_ && c < cs_[0].size(); ++c) identical_ = cs_[0][c]->pts == cs_[1][c]->pts;

  for (int sd = 0; sd < 2; ++sd) {
    work_[sd].resize(cs_[sd].size());
    is_orig_[sd].resize(cs_[sd].size());
    for (std::size_t c = 0; c < cs_[sd].size(); ++c) {
      work_[sd][c] = cs_[sd][c]->pts;
      is_orig_[sd][c].assign(work_[sd][c].size(), 1);
    }
  }
}

// Neighbours' vertices on the shared borders (levels k-1 and k): the border edges here are
// split at them so both regions use the same edges along the border. Exact: the border
// lines are axis-parallel and every such vertex lies on them exactly.
void PlaneBuilder::collect_border_points() {
  for (int sd = 0; sd < 4; ++sd) {
    const int n = neighbour(s_, r_, sd);
    if (n < 0) continue;
    std::vector<Coord>& pts = border_[sd];
    for (int lev = k_ - 1; lev <= k_; ++lev) {
      if (lev < 0 || lev >= levels_) continue;
      for (const geom::Polygon& poly : s_.cell(n, lev).polys) {
        for (const Point& q : poly.outer.pts)
          if (on_side(rr_, sd, q)) pts.push_back(line_coord(sd, q));
        for (const geom::Contour& h : poly.holes)
          for (const Point& q : h.pts)
            if (on_side(rr_, sd, q)) pts.push_back(line_coord(sd, q));
      }
    }
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  }
}

// One round of noding the two levels against each other (repeated until stable): border
// points and fed-back Clipper vertices (first round only), touches within kNodeTol and
// proper crossings (a rounded intersection point inserted into both edges). Afterwards the
// caps Clipper returns are made of noded edges (see run() for the rare exception). Returns
// whether any point was inserted.
bool PlaneBuilder::node_round(int round) {
  collect_segments();
  bool any = false;
  if (round == 0) any = split_at_border_points();
  if (round == 0) any = split_at_fed_points() || any;
  std::sort(segs_.begin(), segs_.end(), [](const Seg& a, const Seg& b) { return a.x0 < b.x0; });
  any = split_touches_and_crossings() || any;
  if (!any) return false;
  apply_splits();
  return true;
}

void PlaneBuilder::collect_segments() {
  segs_.clear();
  for (int sd = 0; sd < 2; ++sd) {
    splits_[sd].resize(work_[sd].size());
    for (std::uint32_t c = 0; c < work_[sd].size(); ++c) {
      const Path& p = work_[sd][c];
      splits_[sd][c].assign(p.size(), {});
      for (std::uint32_t j = 0; j < p.size(); ++j) {
        const Point& a = p[j];
        const Point& b = p[(j + 1) % p.size()];
        segs_.push_back({std::min(a.X, b.X), std::max(a.X, b.X), std::min(a.Y, b.Y), std::max(a.Y, b.Y),
                         static_cast<std::uint32_t>(sd), c, j});
      }
    }
  }
}

// Edges on a shared border take only points exactly on the border: the neighbour must see
// the same split points, and it only knows the ones on the line.
bool PlaneBuilder::may_insert(const Point& a, const Point& b, const Point& w) const noexcept {
  if (!near_inside(a, b, w)) return false;
  const int sd = edge_side(rr_, a, b);
  return sd < 0 || !has_n_[sd] || on_side(rr_, sd, w);
}

std::pair<Point, Point> PlaneBuilder::seg_pts(const Seg& g) const noexcept {
  const Path& p = work_[g.side][g.c];
  return {p[g.j], p[(g.j + 1) % p.size()]};
}

// w is the vertex before the segment's start or after its end: inserting it would make the
// ring run w -> a -> w (or w -> b -> w), a zero-area spike whose two walls meet the edges
// beside them four times (a non-manifold edge; issue 13 item 6).
bool PlaneBuilder::folds(const Seg& g, const Point& w) const noexcept {
  const Path& p = work_[g.side][g.c];
  const std::size_t n = p.size();
  return same(w, p[(g.j + n - 1) % n]) || same(w, p[(g.j + 2) % n]);
}

// w = ring[i] of the other level lies off the edge a->b (within the tolerance) and its edge
// to a ring neighbour lying on a->b runs the other way: the two levels' material is on
// opposite sides of that stretch. Snapping w onto a->b would make that edge one of both
// levels with opposite material, four faces on one edge (a ball contour grazing the stock
// face within 2 units in high.ngc). Clipper's cap follows w's own edge instead.
bool PlaneBuilder::opposed(const Seg& g, std::size_t i, const Point& a, const Point& b) const noexcept {
  const Path& ring = work_[g.side][g.c];
  const std::size_t n = ring.size();
  const Point& w = ring[i % n];
  if (orient(a, b, w) == 0) return false;  // exactly on the edge: always a split point
  const Point& prev = ring[(i + n - 1) % n];
  const Point& next = ring[(i + 1) % n];
  auto on_ab = [&](const Point& x) { return same(x, a) || same(x, b) || near_inside(a, b, x); };
  return (on_ab(prev) && along(a, b, w) < along(a, b, prev)) || (on_ab(next) && along(a, b, next) < along(a, b, w));
}

bool PlaneBuilder::split_at_border_points() {
  bool any = false;
  for (const Seg& g : segs_)
    for (int sd = 0; sd < 4; ++sd) {
      const auto [a, b] = seg_pts(g);
      if (border_[sd].empty() || !on_side(rr_, sd, a) || !on_side(rr_, sd, b)) continue;
      const Coord lo = std::min(line_coord(sd, a), line_coord(sd, b));
      const Coord hi = std::max(line_coord(sd, a), line_coord(sd, b));
      for (auto it = std::upper_bound(border_[sd].begin(), border_[sd].end(), lo); it != border_[sd].end() && *it < hi;
           ++it) {
        splits_[g.side][g.c][g.j].push_back(sd < 2 ? Point{a.X, *it} : Point{*it, a.Y});
        any = true;
      }
    }
  return any;
}

bool PlaneBuilder::split_at_fed_points() {
  bool any = false;
  for (const Point& w : feed_)
    for (const Seg& g : segs_) {
      const auto [a, b] = seg_pts(g);
      if (may_insert(a, b, w) && !folds(g, w)) {
        splits_[g.side][g.c][g.j].push_back(w);
        any = true;
      }
    }
  return any;
}

// Pairs of edges of different levels whose boxes overlap (within the tolerance), swept in
// x order.
bool PlaneBuilder::split_touches_and_crossings() {
  bool any = false;
  const Coord tol = static_cast<Coord>(kNodeTol);
  for (std::size_t i = 0; !identical_ && i < segs_.size(); ++i) {
    const Seg& A = segs_[i];
    for (std::size_t m = i + 1; m < segs_.size() && segs_[m].x0 <= A.x1 + tol; ++m) {
      const Seg& B = segs_[m];
      if (A.side == B.side || B.y0 > A.y1 + tol || A.y0 > B.y1 + tol) continue;
      if (node_pair(A, B)) any = true;
    }
  }
  return any;
}

// Touching, not crossing: each end within the tolerance of the other edge is inserted there
// (a skipped point stays a touch). Otherwise a proper crossing splits both edges.
bool PlaneBuilder::node_pair(const Seg& A, const Seg& B) {
  const auto [p1, p2] = seg_pts(A);
  const auto [q1, q2] = seg_pts(B);
  auto& sa = splits_[A.side][A.c][A.j];
  auto& sb = splits_[B.side][B.c][B.j];
  const bool t1 = may_insert(q1, q2, p1), t2 = may_insert(q1, q2, p2);
  const bool t3 = may_insert(p1, p2, q1), t4 = may_insert(p1, p2, q2);
  const std::size_t before = sa.size() + sb.size();
  if (t1 && !folds(B, p1) && !opposed(A, A.j, q1, q2)) sb.push_back(p1);
  if (t2 && !folds(B, p2) && !opposed(A, A.j + 1, q1, q2)) sb.push_back(p2);
  if (t3 && !folds(A, q1) && !opposed(B, B.j, p1, p2)) sa.push_back(q1);
  if (t4 && !folds(A, q2) && !opposed(B, B.j + 1, p1, p2)) sa.push_back(q2);
  if (t1 || t2 || t3 || t4) return sa.size() + sb.size() != before;
  const int d1 = orient(q1, q2, p1), d2 = orient(q1, q2, p2);
  const int d3 = orient(p1, p2, q1), d4 = orient(p1, p2, q2);
  if (!(d1 * d2 < 0 && d3 * d4 < 0)) return false;
  const Point x = crossing_point(p1, p2, q1, q2);
  if (!same(x, p1) && !same(x, p2)) sa.push_back(x);
  if (!same(x, q1) && !same(x, q2)) sb.push_back(x);
  return true;
}

// Inserts each edge's split points in order along it (duplicates and ends dropped).
void PlaneBuilder::apply_splits() {
  for (int sd = 0; sd < 2; ++sd)
    for (std::uint32_t c = 0; c < work_[sd].size(); ++c) {
      const Path& p = work_[sd][c];
      Path np;
      std::vector<std::uint8_t> no;
      for (std::uint32_t j = 0; j < p.size(); ++j) {
        const Point& a = p[j];
        const Point& b = p[(j + 1) % p.size()];
        np.push_back(a);
        no.push_back(is_orig_[sd][c][j]);
        auto& sp = splits_[sd][c][j];
        std::sort(sp.begin(), sp.end(), [&](const Point& u, const Point& v) { return along(a, b, u) < along(a, b, v); });
        for (const Point& x : sp)
          if (!same(x, a) && !same(x, b) && !same(x, np.back())) {
            np.push_back(x);
            no.push_back(0);
          }
      }
      work_[sd][c] = std::move(np);
      is_orig_[sd][c] = std::move(no);
    }
}

// Noded contours and the plane's vertex table.
void PlaneBuilder::record_vertices() {
  for (int sd = 0; sd < 2; ++sd) {
    pd_.side[sd].resize(cs_[sd].size());
    for (std::uint32_t c = 0; c < cs_[sd].size(); ++c) {
      Noded& nd = pd_.side[sd][c];
      nd.pts = work_[sd][c];
      nd.orig.clear();
      for (std::uint32_t i = 0; i < nd.pts.size(); ++i)
        if (is_orig_[sd][c][i]) nd.orig.push_back(i);
      const MoveId id = cs_[sd][c]->cut_by;
      for (std::uint32_t i = 0; i < nd.pts.size(); ++i) {
        const Point& x = nd.pts[i];
        auto it = pd_.verts.try_emplace(x, VInfo{zk_, 2 * k_, 0, 0}).first;
        it->second.flags |= (sd == 0 ? kLower : kUpper);
        if (is_orig_[sd][c][i]) it->second.flags |= (sd == 0 ? kLowerOrig : kUpperOrig);
        if (on_shared_border(x)) it->second.flags |= kPinned;
        it->second.attr = std::max(it->second.attr, id);
      }
    }
  }
}

// Caps: below minus above faces up (dir 0), above minus below faces down (dir 1).
void PlaneBuilder::build_caps(int dir, const EdgeSet& edges) {
  const auto& subj = pd_.side[dir];
  const auto& clip = pd_.side[1 - dir];
  if (subj.empty()) return;
  ClipperLib::Clipper cl;
  cl.PreserveCollinear(true);
  cl.StrictlySimple(false);  // strictly simple output adds vertices where output edges touch
  for (const Noded& nd : subj) cl.AddPath(nd.pts, ClipperLib::ptSubject, true);
  for (const Noded& nd : clip) cl.AddPath(nd.pts, ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  cl.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);

  std::vector<const ClipperLib::PolyNode*> stack;
  for (const ClipperLib::PolyNode* c : tree.Childs) stack.push_back(c);
  std::vector<Path> rings;
  while (!stack.empty()) {
    const ClipperLib::PolyNode* outer = stack.back();
    stack.pop_back();
    rings.assign(1 + outer->Childs.size(), Path{});
    fix_ring(outer->Contour, rings[0], edges);
    for (std::size_t h = 0; h < outer->Childs.size(); ++h) {
      fix_ring(outer->Childs[h]->Contour, rings[h + 1], edges);
      for (const ClipperLib::PolyNode* isl : outer->Childs[h]->Childs) stack.push_back(isl);
    }
    canonical_order(rings);
    emit_cap(dir, rings);
  }
}

namespace {
bool point_less(const Point& a, const Point& b) noexcept { return a.X != b.X ? a.X < b.X : a.Y < b.Y; }

// Splits `ring` at the vertices it passes twice into its loops, in ring order (a loop
// starts at the repeated vertex). False when no vertex repeats or a loop has under three.
// `repeated` is scratch: the ring's repeated vertices, sorted, once each.
bool split_at_pinches(const Path& ring, Path& repeated, std::vector<Path>& loops) {
  repeated.assign(ring.begin(), ring.end());
  std::sort(repeated.begin(), repeated.end(), point_less);
  auto kept = repeated.begin();
  for (auto i = repeated.begin(); i != repeated.end();) {
    const auto j = std::find_if(i, repeated.end(), [&](const Point& q) { return !(q == *i); });
    if (j - i > 1) *kept++ = *i;
    i = j;
  }
  repeated.erase(kept, repeated.end());
  if (repeated.empty()) return false;
  loops.clear();
  Path open;
  for (const Point& p : ring) {
    const bool pinch = std::binary_search(repeated.begin(), repeated.end(), p, point_less);
    const auto it = pinch ? std::find(open.begin(), open.end(), p) : open.end();
    if (it == open.end()) {
      open.push_back(p);
      continue;
    }
    loops.emplace_back(it, open.end());
    open.erase(it + 1, open.end());
  }
  loops.push_back(std::move(open));
  return std::all_of(loops.begin(), loops.end(), [](const Path& l) { return l.size() >= 3; });
}

// The loop of `loops` that holds `hole` (a vertex strictly inside it), or loops.size().
std::size_t loop_holding(const std::vector<Path>& loops, const Path& hole) {
  for (const Point& v : hole)
    for (std::size_t i = 0; i < loops.size(); ++i) {
      const int in = ClipperLib::PointInPolygon(v, loops[i]);
      if (in == 1) return i;
      if (in == -1) break;  // on this loop's boundary: try the hole's next vertex
    }
  return loops.size();
}

}  // namespace

// The triangulation depends only on the cap's polygon, not on where Clipper started its
// rings: each ring starts at its least vertex (by x, then y) and the holes follow in the
// order of theirs. Two caps of one polygon (a dent one level deep, whose up-cap below and
// down-cap above both collapse onto the level's mid-plane when the walls join) then get the
// same triangles, which the export drops as a fin of zero thickness (docs/mesh.md §5);
// triangulated differently, they left the dent's chord used four times.
void PlaneBuilder::canonical_order(std::vector<Path>& rings) {
  for (Path& ring : rings)
    if (!ring.empty()) std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end(), point_less), ring.end());
  if (rings.size() > 2)
    std::sort(rings.begin() + 1, rings.end(), [](const Path& a, const Path& b) {
      if (a.empty() || b.empty()) return !a.empty() && b.empty();
      return point_less(a.front(), b.front());
    });
}

// Cap edges must be edges of the noded contours; Clipper may drop a collinear vertex, which
// is put back here (exactly collinear plane vertices strictly inside the edge).
void PlaneBuilder::fix_ring(const Path& in, Path& out, const EdgeSet& edges) {
  out.clear();
  for (std::size_t j = 0; j < in.size(); ++j) {
    const Point& u = in[j];
    const Point& v = in[(j + 1) % in.size()];
    out.push_back(u);
    if (edges.count(undirected(u, v))) continue;
    std::vector<Point> mid;
    for (const auto& [w, info] : pd_.verts)
      if (orient(u, v, w) == 0 && strictly_between(u, v, w)) mid.push_back(w);
    std::sort(mid.begin(), mid.end(), [&](const Point& a, const Point& b) { return along(u, v, a) < along(u, v, b); });
    Point prev = u;
    for (const Point& w : mid) {
      if (!edges.count(undirected(prev, w))) ++pd_.defects;
      out.push_back(w);
      prev = w;
    }
    if (!edges.count(undirected(prev, v))) ++pd_.defects;
  }
  for (const Point& x : out)
    if (!pd_.verts.count(x)) {
      extra_.push_back(x);  // made by Clipper: fed back into the noding (run())
      pd_.verts.emplace(x, VInfo{zk_, 2 * k_, 0, kPinned});
    }
}

// One cap polygon (outer ring, then its holes): width and colour of its vertices, and its
// triangles.
void PlaneBuilder::emit_cap(int dir, const std::vector<Path>& rings) {
  const geom::Rect box = geom::bounds_of(rings[0]);
  const bool narrow = static_cast<double>(std::min(box.x1 - box.x0, box.y1 - box.y0)) <= wjoin_;
  for (const Path& ring : rings)
    for (const Point& x : ring) pd_.verts[x].flags |= narrow ? kNarrow : kWide;
  const MoveId attr = cap_attr(dir, rings);
  for (const Path& ring : rings)
    for (const Point& x : ring) pd_.verts[x].attr = std::max(pd_.verts[x].attr, attr);
  scratch_.tris.clear();
  if (!triangulate_lobes(rings)) {
    ring_ptrs_.clear();
    for (const Path& ring : rings) ring_ptrs_.push_back(&ring);
    pd_.forced += triangulate(ring_ptrs_, scratch_.tris, scratch_.triangulate).forced;
  }
  for (const Triangle2& t : scratch_.tris) {
    Tri tri{{t[0], t[1], t[2]}, {k_, k_, k_}};
    if (dir == 1) std::swap(tri.p[1], tri.p[2]);
    pd_.caps.push_back(tri);
  }
}

// An outer ring that touches itself at a vertex (Clipper joins two pieces that meet at a
// point into one ring) is several polygons: each loop is triangulated on its own, with the
// holes inside it. The ear clipper, given the pinched ring whole, may take a diagonal to the
// repeated vertex and cover one loop by a fan from the other, which uses that diagonal
// three times and leaves a four-use edge where two such caps collapse onto one mid-plane
// (docs/mesh.md §6). Only when every loop turns the ring's way and every hole lies inside
// one; false (nothing done) otherwise.
bool PlaneBuilder::triangulate_lobes(const std::vector<Path>& rings) {
  std::vector<Path>& loops = scratch_.loops;
  if (!split_at_pinches(rings[0], scratch_.repeated, loops)) return false;
  const bool ccw = ClipperLib::Orientation(rings[0]);
  for (const Path& l : loops)
    if (ClipperLib::Area(l) == 0.0 || ClipperLib::Orientation(l) != ccw) return false;
  std::vector<std::size_t> owner(rings.size(), 0);
  for (std::size_t h = 1; h < rings.size(); ++h)
    if ((owner[h] = loop_holding(loops, rings[h])) == loops.size()) return false;
  for (std::size_t i = 0; i < loops.size(); ++i) {
    ring_ptrs_.assign(1, &loops[i]);
    for (std::size_t h = 1; h < rings.size(); ++h)
      if (owner[h] == i) ring_ptrs_.push_back(&rings[h]);
    pd_.forced += triangulate(ring_ptrs_, scratch_.tris, scratch_.triangulate).forced;
  }
  return true;
}

// Colour by time: a cap was exposed by the cuts that made its far level's contours; its
// vertices (also those on untouched edges) take the latest of them.
MoveId PlaneBuilder::cap_attr(int dir, const std::vector<Path>& rings) {
  MoveId attr = 0;
  const std::uint8_t far_side = dir == 0 ? kUpper : kLower;
  for (const Path& ring : rings)
    for (const Point& x : ring) {
      const VInfo& vi = pd_.verts[x];
      if (vi.flags & far_side) attr = std::max(attr, vi.attr);
    }
  // No far-level contour (the level beyond was cut away entirely in this region): the cut
  // that emptied that cell exposed the cap.
  if (attr == 0) {
    const int far_level = dir == 0 ? k_ : k_ - 1;
    if (far_level >= 0 && far_level < levels_) attr = s_.cell(r_, far_level).last_cut;
  }
  return attr;
}

void PlaneBuilder::to_mid(VInfo& v, int level) const noexcept {
  v.z = s_.level_z_mm(level);
  v.height = 2 * level + 1;
}

// A corner of only one of the two levels (it may lie on an edge of the other: moving it
// keeps that edge's wall in its vertical plane) moves to its level's mid-plane when its step
// is narrow and the wall continuing it beyond that level is not vertical (the level two away
// has no vertex there): sharp flat-end steps and flat floors stay.
void PlaneBuilder::join_narrow_steps() {
  PointSet below2, above1;
  auto fill = [&](int lev, PointSet& out) {
    if (lev < 0 || lev >= levels_) return;
    for (const geom::Polygon& poly : s_.cell(r_, lev).polys) {
      out.insert(poly.outer.pts.begin(), poly.outer.pts.end());
      for (const geom::Contour& h : poly.holes) out.insert(h.pts.begin(), h.pts.end());
    }
  };
  fill(k_ - 2, below2);
  fill(k_ + 1, above1);
  for (auto& [x, v] : pd_.verts) {
    if ((v.flags & kPinned) || !(v.flags & kNarrow) || (v.flags & kWide)) continue;
    const std::uint8_t o = v.flags & (kLowerOrig | kUpperOrig);
    if (o == kLowerOrig && !below2.count(x)) to_mid(v, k_ - 1);
    else if (o == kUpperOrig && !above1.count(x)) to_mid(v, k_);
  }
}

// Border rule: on a shared border line, the union of both regions' levels k-1 and k is seen
// as intervals; a vertex where only the level-(k-1) material ends moves to that level's
// mid-plane when the level-k material ends within the join width along the line (a narrow
// step), and conversely. Corners (shared with a diagonal neighbour) stay.
void PlaneBuilder::join_border_steps() {
  auto has = [](const std::vector<Coord>& v, Coord c) { return std::binary_search(v.begin(), v.end(), c); };
  BorderEnds e;
  for (int sd = 0; sd < 4; ++sd) {
    if (!has_n_[sd]) continue;
    border_ends(sd, e);
    // Narrow: another end of either level within the join width along the line.
    auto near_other = [&](Coord c) {
      auto it = std::lower_bound(e.all.begin(), e.all.end(), c);
      double d = 1e300;
      if (it != e.all.end() && std::next(it) != e.all.end()) d = std::min(d, static_cast<double>(*std::next(it) - c));
      if (it != e.all.begin()) d = std::min(d, static_cast<double>(c - *std::prev(it)));
      return d <= wjoin_;
    };
    for (auto& [x, v] : pd_.verts) {
      if (!on_side(rr_, sd, x)) continue;
      bool corner = false;
      for (int sd2 = 0; sd2 < 4; ++sd2)
        if (sd2 != sd && on_side(rr_, sd2, x)) corner = true;
      if (corner) continue;
      const Coord c = line_coord(sd, x);
      const bool lo = has(e.lower, c), up = has(e.upper, c);
      if (lo && !up && !has(e.lower2, c) && near_other(c)) to_mid(v, k_ - 1);
      else if (up && !lo && !has(e.upper1, c) && near_other(c)) to_mid(v, k_);
    }
  }
}

void PlaneBuilder::border_ends(int sd, BorderEnds& e) const {
  const int n = neighbour(s_, r_, sd);
  e.lower.clear();
  e.upper.clear();
  e.lower2.clear();
  e.upper1.clear();
  for (int reg : {r_, n}) {
    ends(reg, k_ - 1, sd, e.lower);
    ends(reg, k_, sd, e.upper);
    ends(reg, k_ - 2, sd, e.lower2);
    ends(reg, k_ + 1, sd, e.upper1);
  }
  std::sort(e.lower2.begin(), e.lower2.end());
  std::sort(e.upper1.begin(), e.upper1.end());
  std::sort(e.lower.begin(), e.lower.end());
  e.lower.erase(std::unique(e.lower.begin(), e.lower.end()), e.lower.end());
  std::sort(e.upper.begin(), e.upper.end());
  e.upper.erase(std::unique(e.upper.begin(), e.upper.end()), e.upper.end());
  e.all = e.lower;
  e.all.insert(e.all.end(), e.upper.begin(), e.upper.end());
  std::sort(e.all.begin(), e.all.end());
  e.all.erase(std::unique(e.all.begin(), e.all.end()), e.all.end());
}

// Ends (along the line) of the edges of region n's level lev that lie on side sd's line.
void PlaneBuilder::ends(int n, int lev, int sd, std::vector<Coord>& out) const {
  if (lev < 0 || lev >= levels_) return;
  auto scan = [&](const Path& q) {
    for (std::size_t j = 0; j < q.size(); ++j) {
      const Point& a = q[j];
      const Point& b = q[(j + 1) % q.size()];
      if (on_side(rr_, sd, a) && on_side(rr_, sd, b)) {
        out.push_back(line_coord(sd, a));
        out.push_back(line_coord(sd, b));
      }
    }
  };
  for (const geom::Polygon& poly : s_.cell(n, lev).polys) {
    scan(poly.outer.pts);
    for (const geom::Contour& h : poly.holes) scan(h.pts);
  }
}

// Each cap vertex's height and colour as decided above (Tri carries them to assembly).
void PlaneBuilder::resolve_caps() {
  for (Tri& t : pd_.caps)
    for (int v = 0; v < 3; ++v) {
      const auto it = pd_.verts.find(t.p[v]);
      t.z[v] = it != pd_.verts.end() ? it->second.z : zk_;
      t.height[v] = it != pd_.verts.end() ? it->second.height : 2 * k_;
      t.attr[v] = it != pd_.verts.end() ? it->second.attr : 0;
    }
}

}  // namespace

void build_plane(const geom::LbrSolid& s, int r, int k, const MeshOptions& opt, PlaneData& pd, CapScratch& scratch) {
  PlaneBuilder(s, r, k, opt, pd, scratch).run();
}

}  // namespace lbr::mesh::detail
