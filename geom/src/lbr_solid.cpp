// LbrSolid: construction of the stock, subtraction of sweeps, queries.
#include "geom/lbr_solid.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "chain_outline.hpp"
#include "polygon_ops.hpp"

namespace lbr::geom {

namespace {

constexpr int kMaxRegionsPerAxis = 256;
constexpr long kMaxLevels = 200000;
constexpr long kMaxCells = 8000000;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

bool in_range(double mm) { return std::isfinite(mm) && std::abs(mm) <= kSafeRangeMm; }

// One step of a thread's wait for another's (a few microseconds at most).
inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

constexpr std::uint32_t kNoChain = 0xFFFFFFFFu;
// Sections with at least this many vertices are cut to the region before a clip.
constexpr std::size_t kCutSectionVertices = 64;

bool same_contour(const Contour& a, const Contour& b) noexcept { return a.cut_by == b.cut_by && a.pts == b.pts; }

// True when some edge of the closed contour has a box that meets b (conservative: the edge
// may still miss b).
bool edge_near(const Path& c, const Rect& b) noexcept {
  for (std::size_t i = 0, j = c.size() - 1; i < c.size(); j = i++) {
    const Point& p = c[i];
    const Point& q = c[j];
    if (std::max(p.X, q.X) < b.x0 || std::min(p.X, q.X) > b.x1 || std::max(p.Y, q.Y) < b.y0 || std::min(p.Y, q.Y) > b.y1)
      continue;
    return true;
  }
  return false;
}

// Vertex for vertex the same polygons, move ids included (cheap tests first).
bool same_polygons(const Cell& a, const Cell& b) noexcept {
  if (a.polys.size() != b.polys.size() || !(a.bbox == b.bbox) || a.area_units2 != b.area_units2) return false;
  for (std::size_t i = 0; i < a.polys.size(); ++i) {
    const Polygon& p = a.polys[i];
    const Polygon& q = b.polys[i];
    if (p.holes.size() != q.holes.size() || !same_contour(p.outer, q.outer)) return false;
    for (std::size_t h = 0; h < p.holes.size(); ++h)
      if (!same_contour(p.holes[h], q.holes[h])) return false;
  }
  return true;
}

// b lies wholly inside a.
bool contains(const Rect& a, const Rect& b) noexcept {
  return b.x0 >= a.x0 && b.x1 <= a.x1 && b.y0 >= a.y0 && b.y1 <= a.y1;
}

Path rect_path(const Rect& r) {
  return Path{{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}};
}

// Index of the interval [b[i], b[i+1]] holding v, clamped to [0, b.size()-2].
int interval_of(const std::vector<Coord>& b, Coord v) noexcept {
  const auto it = std::upper_bound(b.begin(), b.end(), v);
  const long i = static_cast<long>(it - b.begin()) - 1;
  return static_cast<int>(std::clamp<long>(i, 0, static_cast<long>(b.size()) - 2));
}

}  // namespace

LbrSolid::LbrSolid(const SolidSpec& spec) : spec_(spec), ws_(std::make_unique<SubtractWorkspace>()) {
  require(std::isfinite(spec.level_spacing_mm) && spec.level_spacing_mm >= 0.001 && spec.level_spacing_mm <= 1000.0,
          "level spacing must be in [0.001, 1000] mm");
  require(spec.regions_x >= 1 && spec.regions_x <= kMaxRegionsPerAxis && spec.regions_y >= 1 &&
              spec.regions_y <= kMaxRegionsPerAxis,
          "region grid must be between 1x1 and 256x256");
  require(std::isfinite(spec.chord_tol_mm) && spec.chord_tol_mm >= 1e-4 && spec.chord_tol_mm <= 1.0,
          "chord tolerance must be in [0.0001, 1] mm");
  if (spec.shape == SolidSpec::Shape::Box) {
    const BoxStock& b = spec.box;
    for (double v : {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z})
      require(in_range(v), "box stock coordinates must be finite and within ±" + std::to_string(kSafeRangeMm) + " mm");
    require(b.min.x < b.max.x && b.min.y < b.max.y && b.min.z < b.max.z, "box stock needs min < max on every axis");
    z0_ = b.min.z;
    z1_ = b.max.z;
    xy_ = Rect{to_units(b.min.x), to_units(b.min.y), to_units(b.max.x), to_units(b.max.y)};
  } else {
    const CylinderStock& c = spec.cylinder;
    require(std::isfinite(c.diameter_mm) && c.diameter_mm > 0.0, "cylinder stock needs a diameter > 0");
    for (double v : {c.center_x_mm - c.diameter_mm, c.center_x_mm + c.diameter_mm, c.center_y_mm - c.diameter_mm,
                     c.center_y_mm + c.diameter_mm, c.z_min_mm, c.z_max_mm})
      require(in_range(v), "cylinder stock must lie within ±" + std::to_string(kSafeRangeMm) + " mm");
    require(c.z_min_mm < c.z_max_mm, "cylinder stock needs z_min < z_max");
    z0_ = c.z_min_mm;
    z1_ = c.z_max_mm;
    const double r = 0.5 * c.diameter_mm;
    xy_ = Rect{to_units(c.center_x_mm - r), to_units(c.center_y_mm - r), to_units(c.center_x_mm + r),
               to_units(c.center_y_mm + r)};
  }
  const double n = std::ceil((z1_ - z0_) / spec.level_spacing_mm - 1e-9);
  require(n >= 1 && n <= kMaxLevels, "stock height / level spacing gives " + std::to_string(static_cast<long>(n)) +
                                         " levels; at most " + std::to_string(kMaxLevels) + " are supported");
  levels_ = static_cast<int>(n);
  require(static_cast<long>(levels_) * regions() <= kMaxCells,
          "levels x regions = " + std::to_string(static_cast<long>(levels_) * regions()) + " cells; at most " +
              std::to_string(kMaxCells) + " are supported");
  init_cells();
}

LbrSolid::~LbrSolid() = default;
LbrSolid::LbrSolid(LbrSolid&&) noexcept = default;
LbrSolid& LbrSolid::operator=(LbrSolid&&) noexcept = default;
LbrSolid::LbrSolid(const LbrSolid& o)
    : spec_(o.spec_), levels_(o.levels_), z0_(o.z0_), z1_(o.z1_), xy_(o.xy_), xs_(o.xs_), ys_(o.ys_),
      cells_(o.cells_), dirty_flag_(o.dirty_flag_), initial_volume_mm3_(o.initial_volume_mm3_),
      ws_(std::make_unique<SubtractWorkspace>()) {}
LbrSolid& LbrSolid::operator=(const LbrSolid& o) {
  if (this != &o) *this = LbrSolid(o);
  return *this;
}

void LbrSolid::init_cells() {
  const int nx = spec_.regions_x, ny = spec_.regions_y;
  xs_.resize(nx + 1);
  ys_.resize(ny + 1);
  for (int i = 0; i <= nx; ++i) xs_[i] = xy_.x0 + (xy_.x1 - xy_.x0) * i / nx;
  for (int j = 0; j <= ny; ++j) ys_[j] = xy_.y0 + (xy_.y1 - xy_.y0) * j / ny;

  Path circle;
  if (spec_.shape == SolidSpec::Shape::Cylinder) {
    const CylinderStock& c = spec_.cylinder;
    const double r = 0.5 * c.diameter_mm;
    const int segs = Sweep::circle_segments(r, spec_.chord_tol_mm);
    const double rho = r * 2.0 / (1.0 + std::cos(std::numbers::pi / segs));
    for (int k = 0; k < segs; ++k) {
      const double a = 2.0 * std::numbers::pi * k / segs;
      circle.push_back({to_units(c.center_x_mm + rho * std::cos(a)), to_units(c.center_y_mm + rho * std::sin(a))});
    }
  }
  cells_.assign(static_cast<std::size_t>(regions()) * levels_, Cell{});
  dirty_flag_.assign(cells_.size(), 0);
  for (int reg = 0; reg < regions(); ++reg) {
    const Rect rr = region_rect(reg);
    std::vector<Polygon> polys;
    if (spec_.shape == SolidSpec::Shape::Box) {
      Polygon p;
      p.outer.pts = rect_path(rr);
      p.bbox = rr;
      polys.push_back(std::move(p));
    } else {
      ClipperLib::Clipper c;
      c.AddPath(circle, ClipperLib::ptSubject, true);
      c.AddPath(rect_path(rr), ClipperLib::ptClip, true);
      ClipperLib::PolyTree tree;
      c.Execute(ClipperLib::ctIntersection, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      detail::append_polygons(tree, polys);
    }
    for (int l = 0; l < levels_; ++l) {
      Cell& cell = cells_[static_cast<std::size_t>(reg) * levels_ + l];
      cell.polys = polys;
      detail::refresh_cell(cell);
    }
  }
  initial_volume_mm3_ = volume_mm3();
}

double LbrSolid::level_bottom_mm(int level) const noexcept { return z0_ + level * spec_.level_spacing_mm; }

double LbrSolid::level_thickness_mm(int level) const noexcept {
  return std::min(z1_, level_bottom_mm(level + 1)) - level_bottom_mm(level);
}

double LbrSolid::level_z_mm(int level) const noexcept {
  return level_bottom_mm(level) + 0.5 * level_thickness_mm(level);
}

int LbrSolid::level_at(double z_mm) const noexcept {
  const double f = std::floor((z_mm - z0_) / spec_.level_spacing_mm);
  return static_cast<int>(std::clamp(f, 0.0, static_cast<double>(levels_ - 1)));
}

Rect LbrSolid::grown_region_rect(int region) const noexcept {
  const Rect rr = region_rect(region);
  const Coord g = static_cast<Coord>(kUnitsPerMm);
  return Rect{rr.x0 - g, rr.y0 - g, rr.x1 + g, rr.y1 + g};
}

Rect LbrSolid::region_rect(int region) const noexcept {
  const int ix = region % spec_.regions_x, iy = region / spec_.regions_x;
  return Rect{xs_[ix], ys_[iy], xs_[ix + 1], ys_[iy + 1]};
}

double LbrSolid::volume_mm3() const noexcept {
  double v = 0.0;
  for (int l = 0; l < levels_; ++l) v += level_area_mm2(l) * level_thickness_mm(l);
  return v;
}

double LbrSolid::level_area_mm2(int level) const noexcept {
  double a = 0.0;
  for (int r = 0; r < regions(); ++r) a += cell(r, level).area_units2;
  return area_to_mm2(a);
}

Box3 LbrSolid::bounds() const noexcept {
  Box3 b;
  for (int l = 0; l < levels_; ++l) {
    for (int r = 0; r < regions(); ++r) {
      const Cell& c = cell(r, l);
      if (c.bbox.empty()) continue;
      b.add({to_mm(c.bbox.x0), to_mm(c.bbox.y0), level_bottom_mm(l)});
      b.add({to_mm(c.bbox.x1), to_mm(c.bbox.y1), level_bottom_mm(l) + level_thickness_mm(l)});
    }
  }
  return b;
}

std::size_t LbrSolid::polygon_count() const noexcept {
  std::size_t n = 0;
  for (const Cell& c : cells_) n += c.polys.size();
  return n;
}

std::size_t LbrSolid::contour_count() const noexcept {
  std::size_t n = 0;
  for (const Cell& c : cells_)
    for (const Polygon& p : c.polys) n += 1 + p.holes.size();
  return n;
}

std::size_t LbrSolid::vertex_count() const noexcept {
  std::size_t n = 0;
  for (const Cell& c : cells_)
    for (const Polygon& p : c.polys) {
      n += p.outer.pts.size();
      for (const Contour& h : p.holes) n += h.pts.size();
    }
  return n;
}

std::vector<std::uint32_t> LbrSolid::dirty_cells() const {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < dirty_flag_.size(); ++i)
    if (dirty_flag_[i]) out.push_back(static_cast<std::uint32_t>(i));
  return out;
}

std::size_t LbrSolid::dirty_count() const noexcept {
  return static_cast<std::size_t>(std::count(dirty_flag_.begin(), dirty_flag_.end(), std::uint8_t{1}));
}

void LbrSolid::clear_dirty() noexcept { std::fill(dirty_flag_.begin(), dirty_flag_.end(), std::uint8_t{0}); }

void LbrSolid::set_cell(int region, int level, std::vector<Polygon> polys, MoveId last_cut) {
  const std::size_t i = static_cast<std::size_t>(region) * levels_ + level;
  Cell& c = cells_[i];
  c.polys = std::move(polys);
  c.last_cut = last_cut;
  for (Polygon& p : c.polys) p.bbox = bounds_of(p.outer.pts);
  detail::refresh_cell(c);
  ++c.version;
  dirty_flag_[i] = 1;
}

SubtractStats LbrSolid::subtract(std::span<const SweepRef> batch) { return subtract(batch, *ws_); }

SubtractStats LbrSolid::subtract(std::span<const SweepRef> batch, SubtractWorkspace& ws) {
  static const std::function<void()> kNoSync = [] {};
  prepare_shared(batch, ws.own);
  return subtract_shared(ws.own, ws, 0, 1, kNoSync);
}

namespace {

bool same_axis(const Vec3& a, const Vec3& b) noexcept { return a.x == b.x && a.y == b.y && a.z == b.z; }

// Distance from p to the segment a-b [mm].
double dist_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) noexcept {
  const Vec3 ab = b - a;
  const double l2 = dot(ab, ab);
  const double t = l2 > 0.0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  return norm(p - (a + t * ab));
}

}  // namespace

void merge_collinear(std::span<const SweepRef> batch, std::vector<SweepRef>& out) {
  out.clear();
  constexpr std::size_t kMaxRun = 512;
  std::size_t i = 0;
  while (i < batch.size()) {
    const SweepRef& first = batch[i];
    if (first.shape == nullptr && first.turning == nullptr) {
      ++i;
      continue;
    }
    SweepRef merged = first;
    const double tol = 0.5 * (first.shape != nullptr ? first.shape->chord_tol_mm : first.turning->chord_tol_mm);
    std::size_t j = i + 1;
    // Extend the run while the next move continues this one with the same tool and a fixed
    // axis, and every intermediate point stays within tol/2 of the merged chord.
    //
    // `dev` bounds the intermediate points' distance to the current chord A-E. When the end
    // moves to E' with |E' - A| >= |E - A|, each point's nearest point A + s·u on A-E has the
    // partner A + s·u' on A-E', |s·(u - u')| away, so dev + |E - A|·|u - u'| bounds the
    // distance to the new chord and only E itself needs measuring: O(1) per sample on a
    // straight stream. Where the bound exceeds tol, every point is measured again.
    const Vec3 A = first.from.tip;
    Vec3 u{0, 0, 0};
    double len = 0.0, dev = 0.0;
    {
      const Vec3 e = first.to.tip - A;
      len = norm(e);
      if (len > 0.0) u = (1.0 / len) * e;
    }
    while (j < batch.size() && j - i < kMaxRun) {
      const SweepRef& n = batch[j];
      if (n.shape != first.shape || n.turning != first.turning || !(n.from.tip == merged.to.tip) || !same_axis(n.from.axis, first.from.axis) ||
          !same_axis(n.to.axis, first.from.axis) || !same_axis(first.to.axis, first.from.axis))
        break;
      const Vec3 v = n.to.tip - A;
      const double nlen = norm(v);
      const Vec3 nu = nlen > 0.0 ? (1.0 / nlen) * v : Vec3{0, 0, 0};
      double bound = INFINITY;
      if (len > 0.0 && nlen >= len) bound = std::max(dev + len * norm(u - nu), dist_to_segment(merged.to.tip, A, n.to.tip));
      if (bound <= tol) {
        dev = bound;
      } else {
        double exact = 0.0;
        for (std::size_t k = i; k < j && exact <= tol; ++k) exact = std::max(exact, dist_to_segment(batch[k].to.tip, A, n.to.tip));
        if (exact > tol) break;
        dev = exact;
      }
      len = nlen;
      u = nu;
      merged.to = n.to;
      merged.id = std::max(merged.id, n.id);
      ++j;
    }
    out.push_back(merged);
    i = j;
  }
}

void LbrSolid::prepare_shared(std::span<const SweepRef> batch, SubtractShared& sh) const {
  // The batch merged, then its sweeps, chains and turning sweeps, and the range they reach.
  merge_collinear(batch, sh.merged);
  sh.sweeps.clear();
  sh.sweep_id.clear();
  sh.runs.clear();
  bool run_open = false;  // the last item pushed is a sweep that the next one may continue
  sh.lathe.clear();
  sh.lathe_id.clear();
  sh.chain_count = 0;
  double zlo = INFINITY, zhi = -INFINITY;
  auto horizontal = [](const SweepRef& r) {
    return r.turning == nullptr && r.shape != nullptr && r.from.tip.z == r.to.tip.z && r.from.axis.x == 0.0 &&
           r.from.axis.y == 0.0 && r.from.axis.z > 0.0 && r.to.axis.x == 0.0 && r.to.axis.y == 0.0 && r.to.axis.z > 0.0;
  };
  const std::vector<SweepRef>& merged = sh.merged;
  for (std::size_t i = 0; i < merged.size(); ++i) {
    const SweepRef& s = merged[i];
    if (horizontal(s)) {
      std::size_t j = i + 1;
      while (j < merged.size() && horizontal(merged[j]) && merged[j].shape == s.shape &&
             merged[j].from.tip.z == s.from.tip.z && merged[j].from.tip == merged[j - 1].to.tip)
        ++j;
      if (j - i >= 3) {
        if (sh.chains.size() <= sh.chain_count) sh.chains.emplace_back();
        SubtractShared::Chain& c = sh.chains[sh.chain_count++];
        c.shape = s.shape;
        c.z = s.from.tip.z;
        c.pts.clear();
        c.pts.push_back({to_units(s.from.tip.x), to_units(s.from.tip.y)});
        c.id = 0;
        for (std::size_t k = i; k < j; ++k) {
          c.pts.push_back({to_units(merged[k].to.tip.x), to_units(merged[k].to.tip.y)});
          c.id = std::max(c.id, merged[k].id);
        }
        zlo = std::min(zlo, c.z);
        zhi = std::max(zhi, c.z + s.shape->height());
        i = j - 1;
        run_open = false;
        continue;
      }
    }
    if (s.turning != nullptr) {
      sh.lathe.emplace_back(*s.turning, s.from.tip.x, s.from.tip.z, s.to.tip.x, s.to.tip.z);
      sh.lathe_id.push_back(s.id);
      zlo = std::min(zlo, sh.lathe.back().z_min());
      zhi = std::max(zhi, sh.lathe.back().z_max());
      run_open = false;
      continue;
    }
    sh.sweeps.emplace_back(*s.shape, s.from, s.to);
    sh.sweep_id.push_back(s.id);
    const auto si = static_cast<std::uint32_t>(sh.sweeps.size() - 1);
    const bool vertical = sh.sweeps.back().vertical();
    if (vertical && run_open && merged[i - 1].shape == s.shape && merged[i - 1].to.tip == s.from.tip)
      sh.runs.back().second = si + 1;
    else
      sh.runs.emplace_back(si, si + 1);  // (a tilted move is a run of one: its section as it is)
    run_open = vertical;
    zlo = std::min(zlo, sh.sweeps.back().z_min());
    zhi = std::max(zhi, sh.sweeps.back().z_max());
  }
  const bool nothing = (sh.sweeps.empty() && sh.lathe.empty() && sh.chain_count == 0) || zhi < z0_ || zlo > z1_;
  sh.lb = nothing ? 0 : level_at(zlo);
  sh.le = nothing ? 0 : level_at(zhi) + 1;
  const int n = sh.le - sh.lb;
  const std::size_t nreg = static_cast<std::size_t>(regions());
  // The distinct (chain, radius) pairs of the batch, in level order: a flat tool's chain
  // has one radius on all its levels.
  const std::size_t cc = sh.chain_count;
  sh.offset_keys.clear();
  sh.offset_of.assign(static_cast<std::size_t>(n) * cc, kNoChain);
  for (int l = sh.lb; l < sh.le; ++l) {
    const double zc = level_z_mm(l);
    for (std::size_t ci = 0; ci < cc; ++ci) {
      const SubtractShared::Chain& c = sh.chains[ci];
      const double h = zc - c.z;
      if (h < 0.0 || h > c.shape->height()) continue;
      const double r = c.shape->radius_at(h);
      if (r <= 0.0) continue;
      std::uint32_t o = kNoChain;
      for (std::size_t k = sh.offset_keys.size(); k-- > 0;)
        if (sh.offset_keys[k].chain == ci && sh.offset_keys[k].r == r) {
          o = static_cast<std::uint32_t>(k);
          break;
        }
      if (o == kNoChain) {
        o = static_cast<std::uint32_t>(sh.offset_keys.size());
        sh.offset_keys.push_back({static_cast<std::uint32_t>(ci), r});
      }
      sh.offset_of[static_cast<std::size_t>(l - sh.lb) * cc + ci] = o;
    }
  }
  const std::size_t noff = sh.offset_keys.size();
  if (sh.levels.size() < static_cast<std::size_t>(n)) sh.levels.resize(static_cast<std::size_t>(n));
  sh.outcome.assign(static_cast<std::size_t>(n) * nreg, 0);
  if (sh.offsets.size() < noff) sh.offsets.resize(noff);
  for (std::size_t o = 0; o < noff; ++o) {
    // The box from the polyline's box (conservative: the offset lies within r + tol/4 of
    // it), so that levels can be built while the offsets are being computed.
    SubtractShared::Offset& off = sh.offsets[o];
    const SubtractShared::Chain& c = sh.chains[sh.offset_keys[o].chain];
    const Coord d = static_cast<Coord>(std::ceil((sh.offset_keys[o].r + 0.25 * c.shape->chord_tol_mm) * kUnitsPerMm)) + 2;
    const Rect b = bounds_of(c.pts);
    off.box = Rect{b.x0 - d, b.y0 - d, b.x1 + d, b.y1 + d};
    off.ix0 = interval_of(xs_, off.box.x0);
    off.ix1 = interval_of(xs_, off.box.x1);
    off.iy0 = interval_of(ys_, off.box.y0);
    off.iy1 = interval_of(ys_, off.box.y1);
    const std::size_t pieces = static_cast<std::size_t>((off.ix1 - off.ix0 + 1) * (off.iy1 - off.iy0 + 1));
    off.cut.resize(pieces);
    off.state.assign(pieces, 0);
  }
  for (auto& next : sh.next) next.store(0, std::memory_order_relaxed);
  sh.ahead_ready.store(0, std::memory_order_relaxed);
  sh.offsets_ready = false;
}

namespace {

// Builds offset `o` of the prepared batch. Offset vertices lie on radius r + tol/4 and
// chords sag at most tol/2 inside it, so the boundary stays within ±tol/4 of the exact one.
void build_offset(SubtractShared& sh, std::size_t o, SubtractStats& stats) {
  ++stats.chain_offsets;
  const SubtractShared::Chain& c = sh.chains[sh.offset_keys[o].chain];
  SubtractShared::Offset& off = sh.offsets[o];
  const double tol = c.shape->chord_tol_mm;
  ClipperLib::ClipperOffset co(2.0, 0.5 * tol * kUnitsPerMm);
  co.AddPath(c.pts, ClipperLib::jtRound, ClipperLib::etOpenRound);
  off.paths.clear();
  co.Execute(off.paths, (sh.offset_keys[o].r + 0.25 * tol) * kUnitsPerMm);
}

}  // namespace

SubtractStats LbrSolid::subtract_shared(SubtractShared& sh, SubtractWorkspace& ws, int index, int count,
                                        const std::function<void()>& sync, const SubtractAhead* ahead) {
  SubtractStats stats;
  const int lb = sh.lb, le = sh.le, n = le - lb;
  // Work is taken from shared counters, so a thread that gets a long item takes fewer of
  // the rest; which thread does an item never changes the result.
  auto take = [&](int phase) { return sh.next[static_cast<std::size_t>(phase)].fetch_add(1, std::memory_order_relaxed); };
  const std::size_t nreg = static_cast<std::size_t>(regions());
  // Phase C's items: the next batch's preparation (item 0, when there is one), then the
  // cells to clip; once it is prepared, its offsets go before the clips.
  const std::size_t pre = ahead != nullptr ? 1 : 0;
  auto ahead_offset = [&] {
    if (ahead == nullptr || sh.ahead_ready.load(std::memory_order_acquire) == 0) return false;
    const std::size_t o = take(2);
    if (o >= ahead->shared->offset_keys.size()) return false;
    build_offset(*ahead->shared, o, stats);
    return true;
  };
  auto run_phase_c = [&] {
    const std::vector<std::uint32_t>& jobs = ws.jobs;
    for (;;) {
      if (ahead_offset()) continue;
      const std::size_t item = take(1);
      if (item < pre) {
        ahead->prepare();
        sh.ahead_ready.store(1, std::memory_order_release);
        continue;
      }
      if (item - pre < jobs.size()) {
        const std::size_t k = jobs[item - pre];
        const int l = lb + static_cast<int>(k / nreg), region = static_cast<int>(k % nreg);
        sh.outcome[k] = clip_cell(region, l, sh.levels[k / nreg], sh, ws, stats) ? 1 : 0;
        continue;
      }
      // No clips left: the next batch's offsets, once it is prepared.
      if (ahead != nullptr) {
        while (sh.ahead_ready.load(std::memory_order_acquire) == 0) cpu_relax();
        while (ahead_offset()) {
        }
      }
      return;
    }
  };
  if (n <= 0) {  // the same in every thread: nobody waits
    ws.jobs.clear();
    run_phase_c();
    return stats;
  }
  const std::size_t noff = sh.offsets_ready ? 0 : sh.offset_keys.size();
  // Phase A: the chain offsets unless built ahead (items [0, noff)) and the levels'
  // sections (the rest); for the cells a level reaches, whether the cell starts equal to
  // the one below (read only: nothing changes before phase C).
  for (std::size_t item = take(0); item < noff + static_cast<std::size_t>(n); item = take(0)) {
    if (item < noff) {
      build_offset(sh, item, stats);
      continue;
    }
    const int l = lb + static_cast<int>(item - noff);
    LevelSections& ls = sh.levels[static_cast<std::size_t>(l - lb)];
    build_level(l, sh, ws, ls, stats);
    ls.same_cell_below.assign(nreg, 0);
    ls.cost.assign(nreg, 0);
    for (int iy = ls.iy0; iy <= ls.iy1; ++iy)
      for (int ix = ls.ix0; ix <= ls.ix1; ++ix) {
        const int region = iy * spec_.regions_x + ix;
        const Cell& c = cell(region, l);
        std::size_t v = 0;
        for (const Polygon& p : c.polys) {
          v += p.outer.pts.size();
          for (const Contour& h : p.holes) v += h.pts.size();
        }
        ls.cost[static_cast<std::size_t>(region)] = static_cast<std::uint32_t>(std::min<std::size_t>(v, 0xFFFFFFFFu));
        if (spec_.vertical_coherence && l > lb)
          ls.same_cell_below[static_cast<std::size_t>(region)] = same_polygons(c, cell(region, l - 1)) ? 1 : 0;
      }
  }
  sync();  // (1) offsets and sections built
  // Phase B, within this thread: which levels have the sections of the level below, the
  // level each cell takes its result from, and the list of cells that start a run. Every
  // thread derives the same table.
  ws.source.assign(static_cast<std::size_t>(n) * nreg, -1);
  ws.jobs.clear();
  for (int l = lb; l < le; ++l) {
    const LevelSections& ls = sh.levels[static_cast<std::size_t>(l - lb)];
    if (ls.empty()) continue;
    bool same = false;
    if (spec_.vertical_coherence && l > lb) {
      const LevelSections& lo = sh.levels[static_cast<std::size_t>(l - 1 - lb)];
      same = !lo.empty() && ls.chain_offset == lo.chain_offset && ls.paths == lo.paths;
    }
    for (int iy = ls.iy0; iy <= ls.iy1; ++iy)
      for (int ix = ls.ix0; ix <= ls.ix1; ++ix) {
        const std::size_t region = static_cast<std::size_t>(iy * spec_.regions_x + ix);
        const std::size_t k = static_cast<std::size_t>(l - lb) * nreg + region;
        const int below = same && ls.same_cell_below[region] != 0 ? ws.source[k - nreg] : -1;
        ws.source[k] = below >= 0 ? below : l;
        if (below < 0) ws.jobs.push_back(static_cast<std::uint32_t>(k));
      }
  }
  // Phase C: clip the cells that start a run, longest first (estimated by the cell's
  // vertex count before the batch, from phase A: cells change from here on), so that no
  // thread is left with a long clip at the end.
  if (count > 1 && ws.jobs.size() > 1) {
    ws.job_cost.resize(ws.jobs.size());
    for (std::size_t j = 0; j < ws.jobs.size(); ++j) {
      const std::size_t k = ws.jobs[j];
      ws.job_cost[j] = {sh.levels[k / nreg].cost[k % nreg], ws.jobs[j]};
    }
    std::sort(ws.job_cost.begin(), ws.job_cost.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    for (std::size_t j = 0; j < ws.jobs.size(); ++j) ws.jobs[j] = ws.job_cost[j].second;
  }
  run_phase_c();
  sync();  // (2) every run's first cell is final
  // Phase D: the other cells of each run take its result.
  std::size_t copy = 0;
  for (int l = lb; l < le; ++l) {
    const LevelSections& ls = sh.levels[static_cast<std::size_t>(l - lb)];
    if (ls.empty()) continue;
    for (int iy = ls.iy0; iy <= ls.iy1; ++iy)
      for (int ix = ls.ix0; ix <= ls.ix1; ++ix) {
        const int region = iy * spec_.regions_x + ix;
        const std::size_t k = static_cast<std::size_t>(l - lb) * nreg + static_cast<std::size_t>(region);
        const int src = ws.source[k];
        if (src == l) continue;
        if (copy++ % static_cast<std::size_t>(count) != static_cast<std::size_t>(index)) continue;
        ++stats.cells_reused;
        if (sh.outcome[static_cast<std::size_t>(src - lb) * nreg + static_cast<std::size_t>(region)] == 0) continue;
        const std::size_t ci = static_cast<std::size_t>(region) * levels_ + l;
        const Cell& from = cells_[static_cast<std::size_t>(region) * levels_ + src];
        Cell& to = cells_[ci];
        to.polys = from.polys;
        to.bbox = from.bbox;
        to.area_units2 = from.area_units2;
        to.last_cut = from.last_cut;
        ++to.version;
        dirty_flag_[ci] = 1;
        ++stats.cells_changed;
      }
  }
  return stats;
}

void LbrSolid::build_level(int level, const SubtractShared& sh, SubtractWorkspace& ws, LevelSections& ls,
                           SubtractStats& stats) const {
  const double zc = level_z_mm(level);
  ws.prev_tilted_valid = false;
  for (Path& p : ls.paths) ws.scratch.spare.push_back(std::move(p));  // keep the buffers
  ls.paths.clear();
  ls.box.clear();
  ls.id.clear();
  ls.chain.clear();
  ls.chain_offset.assign(sh.chain_count, kNoChain);
  ls.all = Rect{};
  ls.ix0 = ls.iy0 = 0;
  ls.ix1 = ls.iy1 = -1;
  for (const auto& run : sh.runs) build_run_sections(zc, run, sh, ws, ls, stats);
  ls.chain.assign(ls.paths.size(), kNoChain);
  // Chains: one entry for the whole offset (outer contours and holes); a clip adds its
  // piece cut to the region (SubtractShared::Offset).
  for (std::size_t ci = 0; ci < sh.chain_count; ++ci) {
    const std::uint32_t o = sh.offset_of[static_cast<std::size_t>(level - sh.lb) * sh.chain_count + ci];
    if (o == kNoChain) continue;  // (the offset itself may still be in the making)
    ls.chain_offset[ci] = o;
    ls.paths.emplace_back();
    ls.box.push_back(sh.offsets[o].box);
    ls.id.push_back(sh.chains[ci].id);
    ls.chain.push_back(o);
    ls.all.add(sh.offsets[o].box);
  }
  // Turning moves: the union of their revolved regions on this level is one region, the
  // smallest r_min (external) and the largest r_max (internal); it takes the latest move id
  // among them.
  if (!sh.lathe.empty()) {
    double r_out = INFINITY, r_in = -INFINITY, tol = spec_.chord_tol_mm;
    MoveId id_out = 0, id_in = 0;
    for (std::size_t si = 0; si < sh.lathe.size(); ++si) {
      const LatheSweep& lw = sh.lathe[si];
      double lo = 0, hi = 0;
      if (zc < lw.z_min() || zc > lw.z_max() || !lw.interval(zc, lo, hi)) continue;
      tol = lw.chord_tol_mm();
      if (lw.internal()) {
        if (hi > r_in) r_in = hi;
        id_in = std::max(id_in, sh.lathe_id[si]);
      } else {
        if (lo < r_out) r_out = lo;
        id_out = std::max(id_out, sh.lathe_id[si]);
      }
    }
    for (int internal = 0; internal < 2; ++internal) {
      const double r = internal ? r_in : r_out;
      if (!std::isfinite(r)) continue;
      const std::size_t before = ls.paths.size();
      LatheSweep::removed_region(r, internal != 0, tol, xy_, ls.paths);
      for (std::size_t k = before; k < ls.paths.size(); ++k) {
        ls.box.push_back(bounds_of(ls.paths[k]));
        ls.id.push_back(internal ? id_in : id_out);
        ls.chain.push_back(kNoChain);
        ls.all.add(ls.box.back());
      }
    }
  }
  stats.sections += ls.paths.size();
  if (ls.paths.empty() || !ls.all.intersects(xy_)) return;
  ls.ix0 = interval_of(xs_, ls.all.x0);
  ls.ix1 = interval_of(xs_, ls.all.x1);
  ls.iy0 = interval_of(ys_, ls.all.y0);
  ls.iy1 = interval_of(ys_, ls.all.y1);
}

// The sections of one run of sweeps on plane zc: consecutive moves whose sections share
// their joint disk become one outline (chain_outline.hpp); the others are emitted one by
// one, trimmed where the previous vertical section covers them (trim_covered()).
void LbrSolid::build_run_sections(double zc, std::pair<std::uint32_t, std::uint32_t> run, const SubtractShared& sh,
                                  SubtractWorkspace& ws, LevelSections& ls, SubtractStats& stats) const {
  Capsule prev_core;  // inside the last single vertical section of this run (trim_covered())
  auto push_boxes = [&](std::size_t before, MoveId id) {
    for (std::size_t k = before; k < ls.paths.size(); ++k) {
      ls.box.push_back(bounds_of(ls.paths[k]));
      ls.id.push_back(id);
      ls.all.add(ls.box.back());
    }
  };
  std::uint32_t si = run.first;
  while (si < run.second) {
    const Sweep& sw = sh.sweeps[si];
    if (zc < sw.z_min() || zc > sw.z_max()) {
      ++si;
      continue;
    }
    // Joined outline from si, when si and at least the next move share their joint disk.
    if (run.second - si >= 2) {
      // One angle grid along the run: the tool's full radius sets it. Even, so that a
      // stadium's caps are exact half turns (chain_outline.cpp, chord_is_covered()).
      const int grid = (Sweep::circle_segments(sw.shape().radius(), sw.shape().chord_tol_mm) + 1) / 2 * 2;
      if (ws.caps.size() < run.second - si) ws.caps.resize(run.second - si);
      std::size_t count = 0;
      while (si + count < run.second && sh.sweeps[si + count].section_caps(zc, grid, ws.scratch, ws.caps[count]) &&
             (count == 0 || (ws.caps[count - 1].c1.x == ws.caps[count].c0.x && ws.caps[count - 1].c1.y == ws.caps[count].c0.y &&
                             ws.caps[count - 1].rho1 == ws.caps[count].rho0)))
        ++count;
      if (count >= 2) {
        const std::size_t before = ls.paths.size();
        detail::append_outline(std::span<const MoveCaps>(ws.caps.data(), count), grid, ws.scratch.unit_circle(grid),
                               ws.outline, ls.paths, ws.scratch.spare);
        MoveId id = 0;
        for (std::size_t k = 0; k < count; ++k) id = std::max(id, sh.sweep_id[si + k]);
        push_boxes(before, id);
        stats.sections_joined += count;
        prev_core = Capsule{};
        si += static_cast<std::uint32_t>(count);
        continue;
      }
    }
    const std::size_t before = ls.paths.size();
    sw.section(zc, ls.paths, ws.scratch);
    // Consecutive moves overlap: the vertices of this section inside the previous vertical
    // section's capsule add edges to the clip but remove nothing more (trim_covered()).
    if (sw.vertical() && ls.paths.size() == before + 1) {
      if (prev_core.valid()) {
        const std::size_t vertices = ls.paths.back().size();
        if (!trim_covered(ls.paths.back(), prev_core, ws.trim_flags)) {
          ls.paths.pop_back();
          ++stats.sections_trimmed;
        } else if (ls.paths.back().size() != vertices) {
          ++stats.sections_trimmed;
        }
      }
      if (ws.scratch.core.valid()) prev_core = ws.scratch.core;
    } else if (!sw.vertical()) {
      trim_tilted(si, before, sh, ws, ls, stats);
    }
    push_boxes(before, sh.sweep_id[si]);
    ++si;
  }
}

// A tilted move's sections (one per sub-step) on a level overlap the previous sub-step's and
// the previous tilted move's as much as vertical ones do: each is trimmed by the previous
// one as it was before its own trimming (convex; trim_covered() with a polygon). Any
// untrimmed section of this level is a valid cover (what trimming took from it lies in its
// own cover, which is removed in the same difference); the previous move's is the useful one.
void LbrSolid::trim_tilted(std::uint32_t si, std::size_t before, const SubtractShared& sh, SubtractWorkspace& ws,
                           LevelSections& ls, SubtractStats& stats) const {
  const Sweep& sw = sh.sweeps[si];
  bool covered = ws.prev_tilted_valid && ws.prev_tilted_sweep + 1 == si &&
                 &sh.sweeps[si - 1].shape() == &sw.shape() && sh.sweeps[si - 1].to().tip == sw.from().tip;
  std::size_t w = before;
  for (std::size_t k = before; k < ls.paths.size(); ++k) {
    ws.tilted_next = ls.paths[k];
    bool keep = true;
    if (covered) {
      const std::size_t vertices = ls.paths[k].size();
      keep = trim_covered(ls.paths[k], ws.prev_tilted, ws.trim_flags);
      if (!keep || ls.paths[k].size() != vertices) ++stats.sections_trimmed;
    }
    ws.prev_tilted.swap(ws.tilted_next);
    ws.prev_tilted_valid = covered = true;
    ws.prev_tilted_sweep = si;
    if (!keep) {
      ws.scratch.spare.push_back(std::move(ls.paths[k]));
      continue;
    }
    if (w != k) ls.paths[w] = std::move(ls.paths[k]);
    ++w;
  }
  ls.paths.resize(w);
}

// The chain offset `o` cut to `region` (grown by 1 mm); the first thread that needs a piece
// cuts it, one that needs it meanwhile waits (a cut takes microseconds).
const Paths& LbrSolid::offset_piece(SubtractShared& sh, std::uint32_t o, int region, SubtractWorkspace& ws) const {
  static const Paths kNone;
  SubtractShared::Offset& off = sh.offsets[o];
  const int ix = region % spec_.regions_x, iy = region / spec_.regions_x;
  // A cell can touch the box on its edge from the region beside the box's first one: the
  // offset covers none of its area there.
  if (ix < off.ix0 || ix > off.ix1 || iy < off.iy0 || iy > off.iy1) return kNone;
  const Rect rr = grown_region_rect(region);
  if (contains(rr, off.box)) return off.paths;  // wholly inside: nothing to cut
  const std::size_t i = static_cast<std::size_t>((iy - off.iy0) * (off.ix1 - off.ix0 + 1) + (ix - off.ix0));
  std::atomic_ref<std::uint8_t> state(off.state[i]);
  std::uint8_t s = state.load(std::memory_order_acquire);
  if (s == 0 && state.compare_exchange_strong(s, 1, std::memory_order_acq_rel)) {
    Paths& out = off.cut[i];
    out.clear();
    ClipperLib::Clipper& k = ws.rect_clipper;
    k.Clear();
    k.AddPaths(off.paths, ClipperLib::ptSubject, true);
    k.AddPath(rect_path(rr), ClipperLib::ptClip, true);
    k.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
    state.store(2, std::memory_order_release);
  } else {
    while (state.load(std::memory_order_acquire) != 2) cpu_relax();
  }
  return off.cut[i];
}

namespace {

// The sections whose box meets the cell's content (ws.selected) and the cell's polygons
// whose box meets those sections (ws.touched); false when either is empty.
bool select_for_cell(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws) {
  ws.selected.clear();
  Rect clipbox;
  for (std::uint32_t k = 0; k < ls.paths.size(); ++k) {
    if (ls.box[k].intersects(cell.bbox)) {
      ws.selected.push_back(k);
      clipbox.add(ls.box[k]);
    }
  }
  if (ws.selected.empty()) return false;
  ws.touched.clear();
  for (std::uint32_t p = 0; p < cell.polys.size(); ++p)
    if (cell.polys[p].bbox.intersects(clipbox)) ws.touched.push_back(p);
  return !ws.touched.empty();
}

// Sections in the air: when no edge of the material comes near a section's box, the box
// lies wholly inside or wholly outside the material, and one point decides which. A
// section outside removes nothing and leaves the clip (the shank of a finishing tool over
// already cleared levels). False when none is left: nothing changes.
bool drop_sections_in_air(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws, SubtractStats& stats) {
  std::size_t kept = 0;
  for (std::uint32_t k : ws.selected) {
    const Rect& b = ls.box[k];
    bool near = false, inside = false;
    const Point centre{b.x0 + (b.x1 - b.x0) / 2, b.y0 + (b.y1 - b.y0) / 2};
    for (std::uint32_t p : ws.touched) {
      const Polygon& poly = cell.polys[p];
      if (!poly.bbox.intersects(b)) continue;
      near = edge_near(poly.outer.pts, b);
      for (std::size_t h = 0; !near && h < poly.holes.size(); ++h) near = edge_near(poly.holes[h].pts, b);
      if (near) break;
      if (ClipperLib::PointInPolygon(centre, poly.outer.pts) != 0) {
        inside = true;
        for (const Contour& h : poly.holes)
          if (ClipperLib::PointInPolygon(centre, h.pts) != 0) inside = false;
        if (inside) break;
      }
    }
    if (near || inside) ws.selected[kept++] = k;
    else ++stats.sections_in_air;
  }
  ws.selected.resize(kept);
  return kept > 0;
}

// A difference that removes no more than the rounding of intersection points to the unit
// grid can account for (half a unit along the touched perimeter) is noise, e.g. a second
// pass along the same path: the caller keeps the old polygons, vertex for vertex.
bool removes_only_noise(const Cell& cell, const SubtractWorkspace& ws) {
  double before = 0.0, after = 0.0, perimeter = 0.0;
  for (std::uint32_t p : ws.touched) {
    const Polygon& old = cell.polys[p];
    before += ClipperLib::Area(old.outer.pts);
    perimeter += detail::perimeter(old.outer.pts);
    for (const Contour& h : old.holes) {
      before += ClipperLib::Area(h.pts);
      perimeter += detail::perimeter(h.pts);
    }
  }
  for (const Polygon& poly : ws.fresh) {
    after += ClipperLib::Area(poly.outer.pts);
    for (const Contour& h : poly.holes) after += ClipperLib::Area(h.pts);
  }
  return before - after <= 0.5 * perimeter;
}

// Carries the move id over to the contours of ws.fresh that came out unchanged; a new or
// changed contour takes the latest move among the sections that overlap it. True when
// some contour changed.
bool inherit_move_ids(const Cell& cell, const LevelSections& ls, SubtractWorkspace& ws) {
  bool changed = ws.fresh.size() != ws.touched.size();
  auto inherit = [&](Contour& out, const Rect& box) {
    for (std::uint32_t p : ws.touched) {
      const Polygon& old = cell.polys[p];
      if (old.bbox == box && detail::same_cycle(old.outer.pts, out.pts)) {
        out.cut_by = old.outer.cut_by;
        return;
      }
      for (const Contour& h : old.holes) {
        if (h.pts.size() == out.pts.size() && detail::same_cycle(h.pts, out.pts)) {
          out.cut_by = h.cut_by;
          return;
        }
      }
    }
    changed = true;
    MoveId id = 0;
    for (std::uint32_t k : ws.selected)
      if (ls.box[k].intersects(box)) id = std::max(id, ls.id[k]);
    if (id == 0)
      for (std::uint32_t k : ws.selected) id = std::max(id, ls.id[k]);
    out.cut_by = id;
  };
  for (Polygon& poly : ws.fresh) {
    inherit(poly.outer, poly.bbox);
    for (Contour& h : poly.holes) inherit(h, bounds_of(h.pts));
  }
  return changed;
}

// The cell's polygons with the touched ones replaced by ws.fresh (untouched first).
void replace_touched(Cell& cell, SubtractWorkspace& ws) {
  ws.kept.clear();
  std::size_t t = 0;
  for (std::uint32_t p = 0; p < cell.polys.size(); ++p) {
    if (t < ws.touched.size() && ws.touched[t] == p) {
      ++t;
      continue;
    }
    ws.kept.push_back(std::move(cell.polys[p]));
  }
  for (Polygon& poly : ws.fresh) ws.kept.push_back(std::move(poly));
  cell.polys.swap(ws.kept);
}

}  // namespace

// The selected sections as clip paths. A chain enters as its offset's piece for the
// region; a long section that reaches well beyond the region (a joined outline runs along
// a whole pass) is cut down to the region grown by 1 mm first, so that the clip carries
// only the nearby edges (the cut keeps the path inside the grown region, where the cell lies).
void LbrSolid::add_clip_paths(int region, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws) const {
  ClipperLib::Clipper& c = ws.clipper;
  const Rect grown = grown_region_rect(region);
  for (std::uint32_t k : ws.selected) {
    if (ls.chain[k] != kNoChain) {
      c.AddPaths(offset_piece(sh, ls.chain[k], region, ws), ClipperLib::ptClip, true);
    } else if (contains(grown, ls.box[k]) || ls.paths[k].size() < kCutSectionVertices) {
      c.AddPath(ls.paths[k], ClipperLib::ptClip, true);
    } else {
      detail::cut_to_rect(ls.paths[k], grown, ws.cut, ws.cut_tmp);
      if (ws.cut.size() >= 3) c.AddPath(ws.cut, ClipperLib::ptClip, true);
    }
  }
}

// Clips one cell with the level's sections; true when the cell changed.
bool LbrSolid::clip_cell(int region, int level, const LevelSections& ls, SubtractShared& sh, SubtractWorkspace& ws,
                         SubtractStats& stats) {
  const std::size_t ci = static_cast<std::size_t>(region) * levels_ + level;
  Cell& cell = cells_[ci];
  if (!cell.bbox.intersects(ls.all)) return false;
  ++stats.cells_tested;
  if (!select_for_cell(cell, ls, ws) || !drop_sections_in_air(cell, ls, ws, stats)) return false;

  ClipperLib::Clipper& c = ws.clipper;
  c.Clear();
  c.StrictlySimple(spec_.strictly_simple);
  for (std::uint32_t p : ws.touched) {
    c.AddPath(cell.polys[p].outer.pts, ClipperLib::ptSubject, true);
    for (const Contour& h : cell.polys[p].holes) c.AddPath(h.pts, ClipperLib::ptSubject, true);
  }
  add_clip_paths(region, ls, sh, ws);
  ws.tree.Clear();
  c.Execute(ClipperLib::ctDifference, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  ++stats.cells_clipped;
  ws.fresh.clear();
  detail::append_polygons(ws.tree, ws.fresh);
  if (removes_only_noise(cell, ws) || !inherit_move_ids(cell, ls, ws)) return false;

  replace_touched(cell, ws);
  detail::refresh_cell(cell);
  cell.last_cut = 0;
  for (std::uint32_t k : ws.selected) cell.last_cut = std::max(cell.last_cut, ls.id[k]);
  ++cell.version;
  dirty_flag_[ci] = 1;
  ++stats.cells_changed;
  return true;
}

SubtractStats LbrSolid::subtract_solid(const LbrSolid& other, MoveId id) {
  SubtractStats stats;
  SubtractWorkspace& ws = *ws_;
  Paths clip;
  for (int l = 0; l < levels_; ++l) {
    const double z = level_z_mm(l);
    if (z < other.z0_ || z > other.z1_) continue;
    const int ol = other.level_at(z);
    clip.clear();
    Rect cb;
    for (int r = 0; r < other.regions(); ++r) {
      const Cell& oc = other.cell(r, ol);
      flatten(oc, clip);
      cb.add(oc.bbox);
    }
    if (clip.empty()) continue;
    stats.sections += clip.size();
    for (int reg = 0; reg < regions(); ++reg) {
      const std::size_t ci = static_cast<std::size_t>(reg) * levels_ + l;
      Cell& cell = cells_[ci];
      if (!cell.bbox.intersects(cb)) continue;
      ++stats.cells_tested;
      ClipperLib::Clipper& c = ws.clipper;
      c.Clear();
      c.StrictlySimple(spec_.strictly_simple);
      Paths subject;
      flatten(cell, subject);
      c.AddPaths(subject, ClipperLib::ptSubject, true);
      c.AddPaths(clip, ClipperLib::ptClip, true);
      ws.tree.Clear();
      c.Execute(ClipperLib::ctDifference, ws.tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      ++stats.cells_clipped;
      ws.fresh.clear();
      detail::append_polygons(ws.tree, ws.fresh);
      for (Polygon& p : ws.fresh) {
        p.outer.cut_by = id;
        for (Contour& h : p.holes) h.cut_by = id;
      }
      cell.polys.swap(ws.fresh);
      detail::refresh_cell(cell);
      cell.last_cut = id;
      ++cell.version;
      dirty_flag_[ci] = 1;
      ++stats.cells_changed;
    }
  }
  return stats;
}

std::string LbrSolid::check_invariants() const {
  std::ostringstream e;
  for (int reg = 0; reg < regions(); ++reg) {
    const Rect rr = region_rect(reg);
    for (int l = 0; l < levels_; ++l) {
      const Cell& c = cell(reg, l);
      double sum = 0.0;
      Paths all;
      for (std::size_t pi = 0; pi < c.polys.size(); ++pi) {
        const Polygon& p = c.polys[pi];
        auto where = [&] { return "region " + std::to_string(reg) + " level " + std::to_string(l) + " polygon " + std::to_string(pi); };
        if (p.outer.pts.size() < 3) return where() + ": outer contour has fewer than 3 vertices";
        if (ClipperLib::Area(p.outer.pts) <= 0.0) return where() + ": outer contour is not counter-clockwise";
        if (!(p.bbox == bounds_of(p.outer.pts))) return where() + ": stale bounding box";
        for (const Contour& h : p.holes)
          if (ClipperLib::Area(h.pts) >= 0.0) return where() + ": hole is not clockwise";
        for (const Point& q : p.outer.pts)
          if (q.X < rr.x0 || q.X > rr.x1 || q.Y < rr.y0 || q.Y > rr.y1) return where() + ": vertex outside its region";
        // A simple contour is its own simplification, with the same area.
        auto simple = [](const Path& path) {
          Paths out;
          ClipperLib::SimplifyPolygon(path, out, ClipperLib::pftNonZero);
          double a = 0.0;
          for (const Path& q : out) a += std::abs(ClipperLib::Area(q));
          return std::abs(a - std::abs(ClipperLib::Area(path))) <= 1.0;
        };
        if (!simple(p.outer.pts)) return where() + ": outer contour self-intersects";
        for (const Contour& h : p.holes)
          if (!simple(h.pts)) return where() + ": hole self-intersects";
        all.push_back(p.outer.pts);
        sum += ClipperLib::Area(p.outer.pts);
        for (const Contour& h : p.holes) {
          all.push_back(h.pts);
          sum += ClipperLib::Area(h.pts);
        }
      }
      if (all.empty()) continue;
      // Non-overlap: the union's area equals the sum of the polygons' areas. Holes outside
      // their outer contour would make the two differ as well.
      ClipperLib::Clipper u;
      u.AddPaths(all, ClipperLib::ptSubject, true);
      Paths un;
      u.Execute(ClipperLib::ctUnion, un, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      double ua = 0.0;
      for (const Path& q : un) ua += ClipperLib::Area(q);
      if (std::abs(ua - sum) > 1.0 + 1e-9 * std::abs(sum))
        return "region " + std::to_string(reg) + " level " + std::to_string(l) + ": polygons overlap (union area " +
               std::to_string(ua) + " != sum " + std::to_string(sum) + ")";
      if (std::abs(sum - c.area_units2) > 1.0 + 1e-9 * std::abs(sum))
        return "region " + std::to_string(reg) + " level " + std::to_string(l) + ": stale cached area";
    }
  }
  return {};
}

}  // namespace lbr::geom
