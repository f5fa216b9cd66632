// geom/sweep.hpp — cross-sections of a tool moving between two poses.
//
// The tool pose is interpolated linearly between the two poses (tip linearly, axis by
// normalised linear interpolation). The swept solid is cut by horizontal planes z = const
// (the level planes); the result is a set of convex polygons whose union is the section.
//
// Accuracy: with the tool's cutting profile replaced by its piecewise-linear CutterShape, a
// straight move with a fixed axis sweeps a convex solid and the section is computed
// exactly up to the polygonisation of circles, which keeps every boundary point within the
// chord tolerance of the exact section. For a flat end mill the linear profile is exact, so
// the only error is polygonisation. Moves whose axis changes are subdivided, per plane, so
// that the hull of each sub-step's two poses stays within the chord tolerance of the tool
// swept between them (its chords' sagitta and its twist: docs/lbr-conventions.md, "Tilted
// sub-steps"). A tilted ball end mill (CutterShape::capsule_radius_mm) is taken as its exact
// capsule instead of the profile polyline; its section points have a closed form. A tilted
// bull-nose mill (CutterShape::core_radius_mm) is taken as its exact torus and cylinder the
// same way (a disk swept along the axis, grown by the corner radius).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "geom/tool.hpp"
#include "geom/types.hpp"

namespace lbr::geom {

// The convex hull of two disks (a tapered capsule) [mm]: a region known to lie inside a
// section polygon, recorded by Sweep::section() for the vertical fast path.
struct Capsule {
  double x1 = 0, y1 = 0, r1 = -1, x2 = 0, y2 = 0, r2 = -1;
  [[nodiscard]] bool valid() const noexcept { return r1 >= 0.0 && r2 >= 0.0; }
};

struct TiltedPiece;

// A point of a section [mm].
struct SectionPoint {
  double x, y;
};

// A convex polygon shrunk by a margin, which tells in O(log n) whether a point lies inside
// the polygon by at least that margin: what the last tilted piece built on a plane covers
// for the next one (Sweep::build_piece()). Empty: covers nothing.
class ConvexCover {
 public:
  // From a convex counter-clockwise polygon (mm, as convex_hull() writes it) and the
  // margin [mm]. Drops vertices closer than a few margins to the last one kept (the rest
  // spans a subset), then moves every edge inwards by the margin; when an edge would vanish
  // or turn (an edge too short for the margin), or fewer than 3 are left, the cover is empty.
  // Allocates only while its buffer grows.
  void build(const std::vector<SectionPoint>& hull, double margin_mm);
  void clear() noexcept { v_.clear(); }
  [[nodiscard]] bool empty() const noexcept { return v_.empty(); }
  // True when q lies inside the shrunk polygon (so inside the polygon by the margin).
  [[nodiscard]] bool contains(const SectionPoint& q) const noexcept;

 private:
  std::vector<SectionPoint> v_;  // the shrunk polygon, counter-clockwise
  std::vector<SectionPoint> kept_;
  SectionPoint c_{};  // the mean of v_ (inside it)
  double x0_ = 0.0, y0_ = 0.0, x1_ = 0.0, y1_ = 0.0;  // v_'s box
  std::vector<double> ang_;  // pseudo-angles of v_ about c_, increasing
};

// What a tilted sweep's section may remove on one plane (Sweep::tilted_pieces()): the box of
// the material there [kernel units] and a finer test of a convex polygon against it.
class PlaneMaterial {
 public:
  Rect box;
  // False only when no material lies inside convex polygon `poly` [mm, counter-clockwise]:
  // a section inside it would remove nothing. May build the caller's caches (allocates).
  [[nodiscard]] virtual bool may_meet(std::span<const SectionPoint> poly) const = 0;

 protected:
  PlaneMaterial() = default;
  PlaneMaterial(const PlaneMaterial&) = default;
  PlaneMaterial& operator=(const PlaneMaterial&) = default;
  ~PlaneMaterial() = default;
};

// Reusable buffers for Sweep::section(); grows to the largest section seen, then stops
// allocating. One per thread.
struct SectionScratch {
  using P2 = SectionPoint;
  std::vector<P2> pts;
  std::vector<P2> hull;
  struct Disk {
    double x, y, r;
    double s = 0.0;  // position of the centre along the horizontal motion [mm]
    int role = 0;    // 1: the start pose's disk (t = 0), 2: the end pose's disk (t = 1), 0: other
  };
  // Set by ramp_hull(): per hull vertex, the role of its disk and its index on the angle grid.
  std::vector<std::uint8_t> hull_role;
  std::vector<int> hull_grid;
  std::vector<Disk> disks;
  std::vector<int> env;        // upper envelope of the disks' support lines (indices)
  std::vector<double> breaks;  // where env[i] takes over from env[i-1]
  struct Dir {
    P2 u;  // the in-plane direction (cos φ, sin φ)
    P2 p;  // the section's boundary point in direction u
    double t_lo, t_hi;  // the bracket of the 3D direction's tilt that found p
    double h;  // a proven bound on the section's support value: it lies in u·x <= h [mm]
  };
  std::vector<TiltedPiece> pieces;  // a tilted sweep's sub-steps on the plane (section())
  // Support queries of the tilted sections' refinement (Sweep::build_piece()) so far; the
  // coarse points' are in TiltedPiece::coarse_queries. A count for tests and profiles.
  std::uint64_t support_queries = 0;
  // Set by each vertical section: a capsule inside the polygon just emitted (invalid when
  // the last section was empty or came from the general path).
  Capsule core;
  // Emptied paths whose buffers section() reuses (callers may give theirs back).
  std::vector<Path> spare;
  // An empty path, with the buffer of a spare one when there is one (no allocation once
  // the pool has grown).
  [[nodiscard]] static Path take_spare(std::vector<Path>& spare) noexcept {
    Path p;
    if (!spare.empty()) {
      p = std::move(spare.back());
      spare.pop_back();
      p.clear();
    }
    return p;
  }
  // Unit circle with n vertices, (cos, sin) pairs, built on first use of each n.
  [[nodiscard]] const std::vector<P2>& unit_circle(int n);
  // tan(π/n), the half grid step's tangent, kept with the unit circle of n.
  [[nodiscard]] double half_step_tan(int n);

 private:
  std::vector<std::vector<P2>> circles_;
  std::vector<double> half_step_tans_;
};

// The section of one vertical move on one plane, split for joining consecutive moves into
// one outline (geom/src/chain_outline.cpp). All vertices lie on one angle grid of n
// directions: the start disk J0 (centre c0, circumradius rho0) and the end disk J1 carry
// the caps; the back cap runs counter-clockwise over J0's grid vertices [back_l, back_r],
// the front cap over J1's [front_r, front_l]; `right` holds the hull vertices strictly
// between the back cap's last and the front cap's first vertex, `left` those between the
// front cap's last and the back cap's first (both counter-clockwise) [mm].
struct MoveCaps {
  SectionScratch::P2 c0{}, c1{};
  double rho0 = 0.0, rho1 = 0.0;
  int back_l = 0, back_r = 0, front_r = 0, front_l = 0;
  std::vector<SectionScratch::P2> right, left;
};

// One sub-step of a tilted sweep (Sweep::tilted_pieces()) cut by one plane, with its coarse
// section: the boundary points in kDirs equally spaced directions, whose polygon Q lies
// inside the section (each point is interpolated inside the hull). Q, as half-planes, is
// what a neighbouring piece's refinement tests its unrefined arcs against
// (Sweep::build_piece()).
struct TiltedPiece {
  static constexpr int kDirs = 16;
  // Leaves dirs and edges unset (Sweep::tilted_pieces() writes them): a value-initialised
  // piece would zero their 1 KB for every piece.
  TiltedPiece() noexcept {}  // NOLINT(modernize-use-equals-default): = default would zero them in emplace_back()
  Pose a, b;  // the sub-step's poses
  double zc = 0.0;
  std::uint32_t sweep = 0;  // caller's index of the sweep it belongs to
  std::uint32_t coarse_queries = 0;  // support queries of its material test and coarse points
  SectionScratch::Dir dirs[kDirs];
  // Q's edges of non-zero length: inside Q by at least `margin` <=> nx·x + ny·y <= c - margin.
  struct Edge {
    double nx, ny, c;
  };
  Edge edges[kDirs];
  int edge_count = 0;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // Q's box [mm]
  // A disk inside Q and one around it, both about the mean of Q's points [mm]: most points
  // are decided by one of them without Q's edges.
  double cx = 0, cy = 0, r_in = 0, r_out2 = 0;
  // Its section meets no material (Sweep::tilted_pieces()'s PlaneMaterial): it is not built,
  // and its coarse points may be only those of the axis directions (then edge_count is 0).
  bool in_air = false;
  [[nodiscard]] bool covers(const SectionScratch::P2& p, double margin_mm) const noexcept;
  // The box of its axis directions' proven bounds (Dir::h), each moved out by a kernel
  // unit, into `out` (counter-clockwise): the section lies inside it. False when the bounds
  // leave no box (not finite, or crossed).
  bool axis_box(SectionScratch::P2 (&out)[4]) const noexcept;
};

// Removes from convex polygon `b` (counter-clockwise, kernel units) the vertices that lie
// inside capsule `a` by at least `margin` units, keeping the first and last vertex of each
// such run. What b loses is the convex hull of a run, which lies inside a, so b' ⊆ b and
// a ∪ b' = a ∪ b: when a's polygon is removed from the stock in the same operation, b' does
// the same work with fewer edges. Returns false when every vertex of b lies inside a (b is
// then unchanged and can be dropped). `flags` is a reusable buffer.
bool trim_covered(Path& b, const Capsule& a, std::vector<std::uint8_t>& flags, double margin = 2.0);

// The axial height above the tip [mm] from which the cutting part of `shape` at pose p
// lies wholly above z_mm (a point at height h on the axis and within the tool's radius R of
// it lies no lower than tip.z + h·a.z − R·sqrt(1 − a.z²)), clamped to [0, height()];
// height() when z_mm is infinite or the axis does not point up.
[[nodiscard]] double cut_height_below(const CutterShape& shape, const Pose& p, double z_mm) noexcept;

class Sweep {
 public:
  // Does not allocate beyond the sub-step list (fixed capacity). Real-time safe.
  // `z_top_mm` is the top of the material the sweep may cut (the solid's top): a tilted
  // sweep then models only the part of the tool from the tip up to the larger of its two
  // poses' cut_height_below() (what lies above cuts nothing there, at any pose between
  // them), which shortens its hull's excess and so its sub-steps. Infinite: the whole
  // cutting part. `twist_tol_mm` bounds that excess (0: the shape's chord tolerance; the
  // collision checks' non-cutting parts take half the checks' tolerance).
  Sweep(const CutterShape& shape, const Pose& from, const Pose& to, double z_top_mm = INFINITY,
        double twist_tol_mm = 0.0) noexcept;

  // Height range [mm] touched by the cutting part of the sweep.
  [[nodiscard]] double z_min() const noexcept { return box_.lo.z; }
  [[nodiscard]] double z_max() const noexcept { return box_.hi.z; }
  // 3D bounding box of the cutting part [mm].
  [[nodiscard]] const Box3& bounds() const noexcept { return box_; }
  // True when both poses have the axis exactly +Z (the 3-axis fast path).
  [[nodiscard]] bool vertical() const noexcept { return vertical_; }
  [[nodiscard]] const CutterShape& shape() const noexcept { return *shape_; }
  [[nodiscard]] const Pose& from() const noexcept { return from_; }
  [[nodiscard]] const Pose& to() const noexcept { return to_; }

  // Appends the section on plane z = z_mm as convex polygons (counter-clockwise, kernel
  // units) to out; returns how many were appended. `scratch` is reused between calls to
  // avoid allocation once it has grown. Real-time safe once the buffers have grown.
  // `material`, when given, is what the section may remove on this plane: a tilted sub-step
  // whose swept hull lies wholly beside its box (the boxes, or one horizontal direction that
  // separates the two), or whose section's axis box (TiltedPiece::axis_box()) it does not
  // meet, is not built, as its section would remove nothing.
  std::size_t section(double z_mm, Paths& out, SectionScratch& scratch, const PlaneMaterial* material = nullptr) const;

  // Circles become regular n-gons that deviate from them on both sides, so that they carry no
  // bias (docs/lbr-conventions.md, "Tolerances"): vertices on radius r·g, outside the circle
  // near the vertices and inside near the edges' midpoints. A tool's disks and profile, which
  // remove material by their support (a sweep's side lies at the tool's support in the
  // direction normal to it), keep the circle's mean width: g = circle_grow_width(n) =
  // θ / sin θ (θ = π/n). Regions bounded by a circle (a cylinder stock, a lathe's turned
  // radius) keep its area: g = circle_grow_area(n) = sqrt(θ / (sin θ·cos θ)).
  // circle_segments() is the least n (at least 8, at most 4096) for which both polygons
  // stay within the chord tolerance of the circle.
  [[nodiscard]] static int circle_segments(double r_mm, double chord_tol_mm) noexcept;
  [[nodiscard]] static double circle_grow_width(int n) noexcept;
  [[nodiscard]] static double circle_grow_area(int n) noexcept;

  // Vertical sweeps only: the section on z = z_mm on the grid of n directions, split into
  // caps and sides (MoveCaps). False when the section has no start or no end disk on its
  // boundary (the plane misses the cutting part at either pose, the disk there has no
  // radius, or the move does not move in XY); `out` is then unspecified. Real-time safe once
  // the buffers have grown.
  bool section_caps(double z_mm, int n, SectionScratch& scratch, MoveCaps& out) const;

  // Vertical sweeps only: the radius of the widest disk of the section on z = z_mm, 0 when the
  // plane misses the cutting part [mm]. Real-time safe once the buffers have grown.
  [[nodiscard]] double widest_disk_mm(double z_mm, SectionScratch& scratch) const;

  // Tilted sweeps only: appends to `out` one TiltedPiece per sub-step whose hull meets plane
  // z = z_mm and, when `material` is given, does not lie beside its box (as section());
  // returns how many, and adds to `*beside` (when given) how many it left out beside the box.
  // With `material`, a piece's axis directions are searched first, and a piece whose axis box
  // (TiltedPiece::axis_box()) does not meet `material` is marked in_air and has only those
  // coarse points. Real-time safe once `out` has grown and when `material` is (or is null).
  std::size_t tilted_pieces(double z_mm, std::vector<TiltedPiece>& out, const PlaneMaterial* material = nullptr,
                            std::uint64_t* beside = nullptr) const;
  // What a piece's refinement may leave out (build_piece()); every member may be null.
  struct PieceCovers {
    const TiltedPiece* before = nullptr;  // the piece before on the same plane
    const TiltedPiece* after = nullptr;   // the piece after
    const ConvexCover* last = nullptr;    // the polygon that `before` built
    ConvexCover* keep = nullptr;          // takes this piece's polygon
    const PlaneMaterial* material = nullptr;  // the plane's material before the difference
  };
  // The section of piece `p` as one convex polygon appended to `out` (counter-clockwise,
  // kernel units); returns 1, or 0 when it has no area. Its boundary is refined to the chord
  // tolerance except on arcs whose refinement triangle (docs/lbr-conventions.md, "Sweeps and
  // sections") lies inside the coarse polygon of `before` or `after` (pieces of the same
  // plane): there the polygon keeps only the coarse points, and is exact only together with
  // those pieces' own polygons, which contain their coarse polygons. So the polygons of a
  // sequence of pieces, each built with its neighbours as covers, have the union of their
  // sections within the chord tolerance when removed in one difference. `last` is the
  // polygon that `before`'s piece built (kept by its call in `keep`; removed in the same
  // difference: the caller's promise). It covers refined as it was, so it stands in for
  // `before`'s coarse polygon, which it contains. `keep` takes this piece's polygon for the
  // next piece (emptied when there is none). Models whose boundary points are closed forms
  // (the capsule) ignore both: a test costs as much as the point. Nor is an arc refined
  // whose cap (the section beyond its chord, inside the triangle of the chord and the two
  // proven support lines) meets no `material`: what the chord leaves out there removes
  // nothing.
  std::size_t build_piece(const TiltedPiece& p, const PieceCovers& covers, Paths& out, SectionScratch& scratch) const;

  static constexpr int kMaxTiltSubsteps = 256;  // sub-steps of one sweep whose tool axis turns (kin::kMaxMoveSubsteps: pieces of a move)

 private:
  std::size_t section_vertical(double z_mm, Paths& out, SectionScratch& scratch) const;
  std::size_t section_general(double z_mm, Paths& out, SectionScratch& scratch, const PlaneMaterial* material) const;
  // The hull of sc.disks on the n-grid in sc.hull (with hull_role, hull_grid); ends_only keeps
  // only the first and last vertex of each run of directions one end disk wins.
  void ramp_hull(SectionScratch& sc, int n, double grow, const std::vector<SectionScratch::P2>& uc, bool ends_only) const;
  // The disks whose hull is the section on z = zc (vertical sweeps); false when none.
  bool section_disks(double zc, SectionScratch& sc) const;

  // What bounds a tilted sweep's sub-steps (docs/lbr-conventions.md, "Tolerances"): the
  // chords' sagitta, and the hull's twist excess, which depends on the plane.
  struct TwistBound {
    double angle = 0.0;         // the axis's turn over the sweep [rad]
    int sagitta = 1;            // sub-steps for the sagitta
    double quarter_len = 0.0;   // L/4, L the modelled part's axial span [mm]
    double slope = 1.0;         // the profile's steepest |dρ/dh|, as sqrt(1 + (dρ/dh)²)
    double across = 1.0;        // the share of the axial term across the swept surface (<= 1)
    double z_lo = 0.0, z_hi = 0.0;  // that part's height range over the sweep [mm]
    double ball = 0.0;          // the model's rounding radius (capsule, core; 0: stations) [mm]
    double slack = 0.0;         // (|Δtip.z| + L·|Δa.z| + 2ρ·φ)/4 [mm]
    double inv_az = 0.0;        // 1 / the least a.z (0: an axis not pointing up)
    struct Face {
      double half_rho = 0.0;    // ρ/2, ρ the flat face's radius [mm]
      double z_lo = 0.0, z_hi = 0.0;  // its height range over the sweep [mm]
    };
    Face faces[2];              // the modelled part's flat ends: at the tip's end, at its top
    // The capsule's section needs no twist term (its section is that of the hull of four of
    // the tetrahedron's edges: docs/lbr-conventions.md): only the crossing term, `cross`·φ/n²
    // for n sub-steps [mm/rad].
    double cross = 0.0;
    double tol = 0.0;           // the excess allowed [mm]
    // Sub-steps on the planes whose points of the hull come from heights within `ball` of
    // z_mm (all planes: z_mm = NaN).
    [[nodiscard]] int count(double z_mm) const noexcept;
  };
  void prepare_twist_bound(double turn_rad, double twist_tol_mm) noexcept;
  // Sub-steps of this tilted sweep on plane z = z_mm (at most substeps_).
  [[nodiscard]] int substeps_at(double z_mm) const noexcept;

  const CutterShape* shape_;
  Pose from_, to_;
  bool vertical_ = true;
  int substeps_ = 1;
  double top_ = 0.0;  // tilted sweeps: the modelled part's top, axial height above the tip [mm]
  TwistBound twist_;
  Box3 box_;
};

}  // namespace lbr::geom
