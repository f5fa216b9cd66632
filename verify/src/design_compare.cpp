// The final stock against the design's sections (verify/design.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "geom/sweep.hpp"
#include "verify/design.hpp"

namespace lbr::verify {

namespace {

struct Nearest {
  double dist_units = std::numeric_limits<double>::infinity();
  double qx = 0, qy = 0;  // the nearest boundary point [units]
};

// p's distance to the edge a–b and the nearest point, kept in `n` when nearer [units].
void nearer(const geom::Point& a, const geom::Point& b, double px, double py, Nearest& n) {
  const double ax = static_cast<double>(a.X), ay = static_cast<double>(a.Y);
  const double dx = static_cast<double>(b.X) - ax, dy = static_cast<double>(b.Y) - ay;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0.0 ? std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0) : 0.0;
  const double qx = ax + t * dx, qy = ay + t * dy;
  const double d2 = (px - qx) * (px - qx) + (py - qy) * (py - qy);
  if (d2 < n.dist_units * n.dist_units) n = {std::sqrt(d2), qx, qy};
}

// A uniform grid over the edges of one level's design section, for nearest-boundary queries
// (docs/performance.md "Design comparison"): each cell lists the edges whose bounding box
// meets it; a query visits rings of cells around the point until the nearest edge found is
// closer than any unvisited cell: the same point as a scan of every edge (up to ties).
class EdgeGrid {
 public:
  explicit EdgeGrid(const geom::Paths& paths) {
    for (const geom::Path& path : paths)
      for (std::size_t i = 0; i < path.size(); ++i) edges_.push_back({path[i], path[(i + 1) % path.size()]});
    if (edges_.empty()) return;
    for (const auto& [a, b] : edges_) box_.add(a), box_.add(b);
    const double w = static_cast<double>(box_.x1 - box_.x0) + 1.0, h = static_cast<double>(box_.y1 - box_.y0) + 1.0;
    // About two edges a cell, at most 512 x 512 cells.
    const double cells = std::clamp(static_cast<double>(edges_.size()) / 2.0, 1.0, 512.0 * 512.0);
    cell_ = std::max(1.0, std::sqrt(w * h / cells));
    nx_ = std::clamp(static_cast<int>(std::ceil(w / cell_)), 1, 4096);
    ny_ = std::clamp(static_cast<int>(std::ceil(h / cell_)), 1, 4096);
    fill();
  }

  [[nodiscard]] Nearest nearest(const geom::Point& p) const {
    Nearest n;
    if (edges_.empty()) return n;
    const double px = static_cast<double>(p.X), py = static_cast<double>(p.Y);
    const int cx = cell_x(px), cy = cell_y(py);
    // A point outside the grid is at least `outside` from every cell.
    const double outside = std::max({static_cast<double>(box_.x0) - px, px - static_cast<double>(box_.x1),
                                     static_cast<double>(box_.y0) - py, py - static_cast<double>(box_.y1), 0.0});
    for (int r = 0; r <= std::max(nx_, ny_); ++r) {
      for (int y = cy - r; y <= cy + r; ++y)
        for (int x = cx - r; x <= cx + r; ++x) {
          if (std::max(std::abs(x - cx), std::abs(y - cy)) != r || x < 0 || y < 0 || x >= nx_ || y >= ny_) continue;
          const auto c = static_cast<std::size_t>(y * nx_ + x);
          for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) nearer(edges_[list_[k]].first, edges_[list_[k]].second, px, py, n);
        }
      // Every unvisited cell is at least r cells (and `outside`) away.
      if (n.dist_units <= std::max(static_cast<double>(r) * cell_, outside)) break;
    }
    return n;
  }

 private:
  [[nodiscard]] int cell_x(double x) const { return std::clamp(static_cast<int>((x - static_cast<double>(box_.x0)) / cell_), 0, nx_ - 1); }
  [[nodiscard]] int cell_y(double y) const { return std::clamp(static_cast<int>((y - static_cast<double>(box_.y0)) / cell_), 0, ny_ - 1); }

  // Counting sort of (cell, edge) pairs into start_ / list_.
  void fill() {
    start_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1) {
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        list_.resize(start_.back());
        next_.assign(start_.begin(), start_.end() - 1);
      }
      for (std::size_t e = 0; e < edges_.size(); ++e) {
        const auto& [a, b] = edges_[e];
        const int x0 = cell_x(static_cast<double>(std::min(a.X, b.X))), x1 = cell_x(static_cast<double>(std::max(a.X, b.X)));
        const int y0 = cell_y(static_cast<double>(std::min(a.Y, b.Y))), y1 = cell_y(static_cast<double>(std::max(a.Y, b.Y)));
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const auto c = static_cast<std::size_t>(y * nx_ + x);
            if (pass == 0) ++start_[c + 1];
            else list_[next_[c]++] = static_cast<std::uint32_t>(e);
          }
      }
    }
  }

  std::vector<std::pair<geom::Point, geom::Point>> edges_;
  geom::Rect box_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> start_, list_, next_;
};

double area_mm2(const geom::Paths& paths) {
  double a = 0.0;
  for (const geom::Path& p : paths) a += geom::signed_area(p);
  return geom::area_to_mm2(a);
}

// The level's comparison, accumulated into `lv` and the report's maxima.
class LevelCompare {
 public:
  LevelCompare(const geom::LbrSolid& solid, double tolerance_mm) : solid_(solid), tol_mm_(tolerance_mm) {}

  void run(const geom::Paths& design, int level, DesignLevel& lv, DesignReport& rep) {
    grid_.reset();  // built when this level has a gouge or an excess to measure
    grown_.clear();
    offset_.Clear();
    offset_.ArcTolerance = 10.0;  // 1 µm
    offset_.AddPaths(design, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
    offset_.Execute(grown_, tol_mm_ * geom::kUnitsPerMm);
    const double dz = solid_.level_thickness_mm(level);
    for (int r = 0; r < solid_.regions(); ++r) {
      const geom::Rect rc = solid_.region_rect(r);
      const geom::Path rect{{rc.x0, rc.y0}, {rc.x1, rc.y0}, {rc.x1, rc.y1}, {rc.x0, rc.y1}};
      stock_.clear();  // flatten() appends
      geom::flatten(solid_.cell(r, level), stock_);
      clip(ClipperLib::ctIntersection, design, geom::Paths{rect}, part_);
      clip(ClipperLib::ctDifference, part_, stock_, gouge_);
      clip(ClipperLib::ctDifference, stock_, grown_, excess_);
      open_slivers();
      lv.gouge_mm3 += area_mm2(gouge_) * dz;
      lv.excess_mm3 += area_mm2(excess_) * dz;
      depths(design, level, lv, rep);
    }
  }

 private:
  // Gouge slivers thinner than 2 µm (hairline slits between two sweeps' polygonised
  // outlines, rounding) are left out of the depth: opened_ = gouge shrunk and grown by 1 µm.
  void open_slivers() {
    constexpr double kHalfWidthUnits = 10.0;  // 1 µm
    opened_.clear();
    if (gouge_.empty()) return;
    ClipperLib::Paths shrunk;
    offset_.Clear();
    offset_.AddPaths(gouge_, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
    offset_.Execute(shrunk, -kHalfWidthUnits);
    offset_.Clear();
    offset_.AddPaths(shrunk, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
    offset_.Execute(opened_, kHalfWidthUnits);
  }

  void clip(ClipperLib::ClipType op, const geom::Paths& a, const geom::Paths& b, geom::Paths& out) {
    out.clear();
    if (a.empty()) return;
    c_.Clear();
    c_.AddPaths(a, ClipperLib::ptSubject, true);
    c_.AddPaths(b, ClipperLib::ptClip, true);
    c_.Execute(op, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  }

  // Gouge depth: sampled at kSamplesPerEdge points along each gouge edge (the deepest point
  // of a gouge sliver lies on its cut side, not always at a vertex).
  static constexpr int kSamplesPerEdge = 8;
  const EdgeGrid& grid(const geom::Paths& design) {
    if (!grid_) grid_.emplace(design);
    return *grid_;
  }

  void depths(const geom::Paths& design, int level, DesignLevel& lv, DesignReport& rep) {
    for (const geom::Path& p : opened_)
      for (std::size_t i = 0; i < p.size(); ++i)
        for (int k = 0; k < kSamplesPerEdge; ++k) {
          const geom::Point& a = p[i];
          const geom::Point& b = p[(i + 1) % p.size()];
          const double t = static_cast<double>(k) / kSamplesPerEdge;
          gouge_point(design, {a.X + static_cast<geom::Coord>(t * static_cast<double>(b.X - a.X)),
                               a.Y + static_cast<geom::Coord>(t * static_cast<double>(b.Y - a.Y))},
                      level, lv, rep);
        }
    for (const geom::Path& p : excess_)
      for (const geom::Point& v : p) {
        const double d_mm = design.empty() ? 0.0 : grid(design).nearest(v).dist_units * geom::kMmPerUnit;
        lv.max_excess_mm = std::max(lv.max_excess_mm, d_mm);
      }
  }

  // One sample point `v` of a gouge contour: its depth into the design.
  void gouge_point(const geom::Paths& design, const geom::Point& v, int level, DesignLevel& lv, DesignReport& rep) {
    const double z = solid_.level_z_mm(level);
    const Nearest n = grid(design).nearest(v);
    const double d_mm = n.dist_units * geom::kMmPerUnit;
    lv.max_gouge_mm = std::max(lv.max_gouge_mm, d_mm);
    if (d_mm <= rep.max_gouge_mm) return;
    rep.max_gouge_mm = d_mm;
    rep.max_gouge_level = level;
    rep.max_gouge_at = {geom::to_mm(v.X), geom::to_mm(v.Y), z};
    // 10 µm (at most half the depth) back towards the design boundary: inside the cut.
    const double s = std::min(0.5, 0.01 / d_mm);
    rep.gouge_probe = {geom::to_mm(v.X) + s * (n.qx * geom::kMmPerUnit - geom::to_mm(v.X)),
                       geom::to_mm(v.Y) + s * (n.qy * geom::kMmPerUnit - geom::to_mm(v.Y)), z};
  }

  const geom::LbrSolid& solid_;
  double tol_mm_;
  ClipperLib::ClipperOffset offset_;
  ClipperLib::Clipper c_;
  geom::Paths grown_, stock_, part_, gouge_, excess_, opened_;
  std::optional<EdgeGrid> grid_;  // the level's design edges
};

}  // namespace

DesignReport compare_design(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid, double tolerance_mm) {
  DesignReport rep;
  LevelCompare cmp(solid, tolerance_mm);
  constexpr double kReportMm3 = 1e-9;  // levels below this are left out of `levels`
  for (int l = 0; l < solid.levels(); ++l) {
    const geom::Paths& d = design[static_cast<std::size_t>(l)];
    rep.design_volume_mm3 += area_mm2(d) * solid.level_thickness_mm(l);
    DesignLevel lv{l, solid.level_z_mm(l), 0, 0, 0, 0};
    cmp.run(d, l, lv, rep);
    rep.gouge_mm3 += lv.gouge_mm3;
    rep.excess_mm3 += lv.excess_mm3;
    rep.max_excess_mm = std::max(rep.max_excess_mm, lv.max_excess_mm);
    if (lv.gouge_mm3 > kReportMm3 || lv.excess_mm3 > kReportMm3) rep.levels.push_back(lv);
  }
  return rep;
}

void attribute_gouge(DesignReport& report, const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                     const MoveIndex& index) {
  if (report.max_gouge_level < 0) return;
  const double z = solid.level_z_mm(report.max_gouge_level);
  const geom::Point p{geom::to_units(report.gouge_probe.x), geom::to_units(report.gouge_probe.y)};
  geom::SectionScratch scratch;
  geom::Paths section;
  // A turning move removes its insert's revolved region: the point's radius against the
  // region's radius on the level (exact; the kernel's circles lie within tol/2 of it).
  const double r_probe = std::hypot(report.gouge_probe.x, report.gouge_probe.y);
  for (const motion::TimedSweep& m : moves) {
    bool inside = false;
    if (m.ref.turning != nullptr) {
      const geom::LatheSweep lathe(*m.ref.turning, m.ref.from.tip.x, m.ref.from.tip.z, m.ref.to.tip.x, m.ref.to.tip.z);
      double lo = 0.0, hi = 0.0;
      inside = lathe.interval(z, lo, hi) && (lathe.internal() ? r_probe <= hi : r_probe >= lo);
    } else if (m.ref.shape != nullptr) {
      section.clear();
      geom::Sweep(*m.ref.shape, m.ref.from, m.ref.to).section(z, section, scratch);
      inside = std::any_of(section.begin(), section.end(),
                           [&](const geom::Path& s) { return ClipperLib::PointInPolygon(p, s) != 0; });
    }
    if (!inside) continue;
    report.gouge_move = m.ref.id;
    report.gouge_tool = m.tool;
    report.gouge_channel = m.channel;
    report.gouge_t_s = m.t_s;
    const std::string* source = nullptr;
    if (const nc::Segment* seg = index.find(m.ref.id, &source); seg != nullptr) {
      report.gouge_line = seg->line;
      report.gouge_source = source != nullptr ? *source : std::string();
    }
    return;
  }
}

namespace {

// Where point p lies against the design: 1 inside the section of its level, 0 outside
// (above or below the stock too), -1 on a section's boundary.
int design_side(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid, const geom::Vec3& p) {
  if (p.z < solid.z_bottom_mm() || p.z > solid.z_top_mm()) return 0;
  const geom::Paths& d = design[static_cast<std::size_t>(solid.level_at(p.z))];
  const geom::Point q{geom::to_units(p.x), geom::to_units(p.y)};
  int inside = 0;
  for (const geom::Path& path : d) {
    const int k = ClipperLib::PointInPolygon(q, path);
    if (k < 0) return -1;
    inside += k;
  }
  return inside % 2;  // the NonZero union's outer contours and holes
}

}  // namespace

void vertex_deviation(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid,
                      std::span<const float> positions, std::span<const float> normals, double tolerance_mm,
                      std::vector<float>& out) {
  out.assign(positions.size() / 3, 0.0f);
  if (design.size() != static_cast<std::size_t>(solid.levels())) return;
  const double half = 0.5 * tolerance_mm;
  std::vector<std::unique_ptr<EdgeGrid>> grids(design.size());  // per level, when first needed
  // The in-plane depth of `at` inside (gouge) or outside (excess) the design section [mm].
  const auto depth_mm = [&](const geom::Vec3& at) {
    const auto l = static_cast<std::size_t>(solid.level_at(at.z));
    if (design[l].empty()) return 1e9;
    if (!grids[l]) grids[l] = std::make_unique<EdgeGrid>(design[l]);
    return grids[l]->nearest({geom::to_units(at.x), geom::to_units(at.y)}).dist_units * geom::kMmPerUnit;
  };
  // A point on a level boundary (cap edges, probes moved sideways from them) belongs to both
  // levels: `side` must hold on both (1 µm below and above).
  const auto both = [&](const geom::Vec3& at, int side) {
    const geom::Vec3 dz{0, 0, 1e-3};
    return design_side(design, solid, at - dz) == side && design_side(design, solid, at + dz) == side;
  };
  for (std::size_t v = 0; v < out.size(); ++v) {
    const geom::Vec3 p{positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]};
    const geom::Vec3 n{normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]};
    const geom::Vec3 outside = p + half * n, inside = p - half * n;
    // Gouge: half the tolerance outside the stock is design material, at least half the
    // tolerance deep; excess: half the tolerance inside is as far outside the design. A
    // vertex where a floor meets a wall sits on both within rounding and is neither.
    if (both(outside, 1)) {
      if (const double d = depth_mm(outside); d >= half) out[v] = static_cast<float>(-(d + half));
    } else if (both(inside, 0)) {
      if (const double d = depth_mm(inside); d >= half) out[v] = static_cast<float>(std::min(d, 1e6) + half);
    }
  }
}

std::optional<Event> gouge_event(const DesignReport& report, double tolerance_mm) {
  if (!(report.max_gouge_mm > tolerance_mm)) return std::nullopt;
  Event e;
  e.kind = EventKind::DesignGouge;
  e.t_s = report.gouge_t_s;
  e.source = report.gouge_source;
  e.line = e.last_line = report.gouge_line;
  e.move = e.last_move = report.gouge_move;
  e.tool = report.gouge_tool;
  e.channel = report.gouge_channel;
  e.position = report.max_gouge_at;
  e.volume_mm3 = report.gouge_mm3;
  e.depth_mm = report.max_gouge_mm;
  return e;
}

std::string deviation_csv(const DesignReport& report) {
  std::ostringstream o;
  o << "level,z_mm,gouge_mm3,excess_mm3,max_gouge_mm,max_excess_mm\n";
  char buf[160];
  for (const DesignLevel& l : report.levels) {
    std::snprintf(buf, sizeof buf, "%d,%.4f,%.6f,%.6f,%.4f,%.4f\n", l.level, l.z_mm, l.gouge_mm3, l.excess_mm3,
                  l.max_gouge_mm, l.max_excess_mm);
    o << buf;
  }
  return o.str();
}

}  // namespace lbr::verify
