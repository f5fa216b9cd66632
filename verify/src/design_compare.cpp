// The final stock against the design's sections (verify/design.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "geom/sweep.hpp"
#include "verify/design.hpp"

namespace lbr::verify {

namespace {

struct Nearest {
  double dist_units = std::numeric_limits<double>::infinity();
  double qx = 0, qy = 0;  // the nearest boundary point [units]
};

// The point of the contours `paths` nearest to p [units].
Nearest nearest_boundary(const geom::Paths& paths, const geom::Point& p) {
  Nearest n;
  const double px = static_cast<double>(p.X), py = static_cast<double>(p.Y);
  for (const geom::Path& path : paths)
    for (std::size_t i = 0; i < path.size(); ++i) {
      const geom::Point& a = path[i];
      const geom::Point& b = path[(i + 1) % path.size()];
      const double ax = static_cast<double>(a.X), ay = static_cast<double>(a.Y);
      const double dx = static_cast<double>(b.X) - ax, dy = static_cast<double>(b.Y) - ay;
      const double len2 = dx * dx + dy * dy;
      const double t = len2 > 0.0 ? std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0) : 0.0;
      const double qx = ax + t * dx, qy = ay + t * dy;
      const double d = std::hypot(px - qx, py - qy);
      if (d < n.dist_units) n = {d, qx, qy};
    }
  return n;
}

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
  void depths(const geom::Paths& design, int level, DesignLevel& lv, DesignReport& rep) const {
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
        const double d_mm = design.empty() ? 0.0 : nearest_boundary(design, v).dist_units * geom::kMmPerUnit;
        lv.max_excess_mm = std::max(lv.max_excess_mm, d_mm);
      }
  }

  // One sample point `v` of a gouge contour: its depth into the design.
  void gouge_point(const geom::Paths& design, const geom::Point& v, int level, DesignLevel& lv, DesignReport& rep) const {
    const double z = solid_.level_z_mm(level);
    const Nearest n = nearest_boundary(design, v);
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
  for (const motion::TimedSweep& m : moves) {
    if (m.ref.shape == nullptr || m.ref.turning != nullptr) continue;
    section.clear();
    geom::Sweep(*m.ref.shape, m.ref.from, m.ref.to).section(z, section, scratch);
    const bool inside = std::any_of(section.begin(), section.end(),
                                    [&](const geom::Path& s) { return ClipperLib::PointInPolygon(p, s) != 0; });
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
