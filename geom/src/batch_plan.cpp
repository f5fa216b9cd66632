// The batch plan: what one subtraction works from, prepared on one thread before the
// threads start — the moves merged, their sweeps, the chains of horizontal moves and the
// turning sweeps, the levels they reach, and per level the chain offsets it needs.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "subtract_engine.hpp"

namespace lbr::geom::detail {

namespace {

// An axis-aligned box in the XY plane [mm].
struct Rect2 {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  void add(double x, double y) noexcept {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  [[nodiscard]] double span() const noexcept { return std::max(x1 - x0, y1 - y0); }
};

bool same_axis(const Vec3& a, const Vec3& b) noexcept { return a.x == b.x && a.y == b.y && a.z == b.z; }

// Distance from p to the segment a-b [mm].
double dist_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) noexcept {
  const Vec3 ab = b - a;
  const double l2 = dot(ab, ab);
  const double t = l2 > 0.0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  return norm(p - (a + t * ab));
}

// The farthest point from the tip [mm] of the part of `shape`'s cutting part that lies at
// or below z_top at pose p (with 1 mm to spare; geom::cut_height_below()).
double reach_below(const CutterShape& shape, const Pose& p, double z_top) noexcept {
  return std::hypot(cut_height_below(shape, p, z_top + 1.0), shape.radius());
}

// The pose a fraction f along sweep s, as geom::Sweep moves the tool there (tip linearly,
// axis by normalised linear interpolation).
Pose pose_along(const SweepRef& s, double f) noexcept {
  const Vec3 ax = lerp(s.from.axis, s.to.axis, f);
  return {lerp(s.from.tip, s.to.tip, f), (1.0 / norm(ax)) * ax};
}

// A run of milling sweeps whose tool axis turns (a 5-axis programme or sampled stream), from
// `head`: batch[i], or the part of it that the run before left. Extended while the next
// sweep continues the run with the same tool and every pose inside the run (the ends of its
// sweeps) stays within tol of the merged sweep by geom::pose_deviation_mm with the reach of
// the tool's part below z_top at that pose (reach_below(): the rest of the tool cuts
// nothing, wherever it moves). The live stream's rule (motion::SampleStream) is the same
// with the whole tool's reach. O(run) per sweep, so runs stop at kMaxTiltedRun. Returns the
// end of the run; `merged` is its sweep.
//
// When the tolerance (not the tool, a break in the path or the run's length) ends the run at
// batch[j], the run takes the longest start of batch[j] that keeps its poses within tol (by
// bisection, to 1/64 of batch[j]), and `rest` the part after it (`split`); the caller
// starts the next run from `rest`. So a run ends where the tolerance ends it, not at the
// programme point before, as a sampled stream's runs do: finish5x's ball pass merged its
// 2 700 tilted segments into 2 279 sweeps and its 12 544 samples into 1 638.
std::size_t merge_tilted_run(std::span<const SweepRef> batch, std::size_t i, const SweepRef& head, double tol,
                             double z_top, SweepRef& merged, SweepRef& rest, bool& split) noexcept {
  constexpr std::size_t kMaxTiltedRun = 64;
  constexpr int kSplitSteps = 6;
  double reach[kMaxTiltedRun];  // of each pose inside the run, found once
  merged = head;
  split = false;
  auto within = [&](std::size_t j, const Pose& end) {
    for (std::size_t k = i; k < j; ++k)
      if (pose_deviation_mm(head.from, end, batch[k].to, reach[k - i]) > tol) return false;
    return true;
  };
  std::size_t j = i + 1;
  for (; j < batch.size() && j - i < kMaxTiltedRun; ++j) {
    const SweepRef& n = batch[j];
    if (n.shape != head.shape || n.turning != nullptr || !(n.from.tip == merged.to.tip) ||
        !same_axis(n.from.axis, merged.to.axis))
      break;
    reach[j - 1 - i] = reach_below(*head.shape, batch[j - 1].to, z_top);  // the pose now inside
    if (!within(j, n.to)) {
      double lo = 0.0, hi = 1.0;  // lo: within (batch[j]'s start is the run's end now)
      for (int s = 0; s < kSplitSteps; ++s) {
        const double f = 0.5 * (lo + hi);
        (within(j, pose_along(n, f)) ? lo : hi) = f;
      }
      if (lo > 0.0) {
        merged.to = pose_along(n, lo);
        merged.id = std::max(merged.id, n.id);
        rest = n;
        rest.from = merged.to;
        split = true;
      }
      break;
    }
    merged.to = n.to;
    merged.id = std::max(merged.id, n.id);
  }
  return j;
}

}  // namespace

void merge_collinear(std::span<const SweepRef> batch, std::vector<SweepRef>& out, double z_top_mm) {
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
    if (first.shape != nullptr && !same_axis(first.from.axis, first.to.axis)) {
      SweepRef head = first, rest;
      for (bool split = true; split; head = rest) {
        i = merge_tilted_run(batch, i, head, tol, z_top_mm, merged, rest, split);
        out.push_back(merged);
      }
      continue;
    }
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

namespace {

bool horizontal(const SweepRef& r) noexcept {
  return r.turning == nullptr && r.shape != nullptr && r.from.tip.z == r.to.tip.z && vertical_poses(r.from, r.to);
}

// When sh.merged[i] starts a chain (at least three consecutive horizontal moves of one tool
// at one height along a continuous path), records it, sets i to its last move and returns
// true.
bool plan_chain(SubtractShared& sh, std::size_t& i, double& zlo, double& zhi) {
  const std::vector<SweepRef>& merged = sh.merged;
  const SweepRef& s = merged[i];
  if (!horizontal(s)) return false;
  std::size_t j = i + 1;
  while (j < merged.size() && horizontal(merged[j]) && merged[j].shape == s.shape &&
         merged[j].from.tip.z == s.from.tip.z && merged[j].from.tip == merged[j - 1].to.tip)
    ++j;
  if (j - i < 3) return false;
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
  return true;
}

// The sweeps, runs, chains and turning sweeps of sh.merged; widens [zlo, zhi] to the
// heights they reach. `z_top` is the solid's top (geom::Sweep's z_top_mm).
void plan_moves(SubtractShared& sh, double z_top, double& zlo, double& zhi) {
  sh.sweeps.clear();
  sh.sweep_id.clear();
  sh.runs.clear();
  sh.lathe.clear();
  sh.lathe_id.clear();
  sh.chain_count = 0;
  bool run_open = false;  // the last item pushed is a sweep that the next one may continue
  const std::vector<SweepRef>& merged = sh.merged;
  for (std::size_t i = 0; i < merged.size(); ++i) {
    const SweepRef& s = merged[i];
    if (plan_chain(sh, i, zlo, zhi)) {
      run_open = false;
      continue;
    }
    if (s.turning != nullptr) {
      sh.lathe.emplace_back(*s.turning, s.from.tip.x, s.from.tip.z, s.to.tip.x, s.to.tip.z);
      sh.lathe_id.push_back(s.id);
      zlo = std::min(zlo, sh.lathe.back().z_min());
      zhi = std::max(zhi, sh.lathe.back().z_max());
      run_open = false;
      continue;
    }
    sh.sweeps.emplace_back(*s.shape, s.from, s.to, z_top);
    sh.sweep_id.push_back(s.id);
    const auto si = static_cast<std::uint32_t>(sh.sweeps.size() - 1);
    // A run: consecutive sweeps of one tool, each starting where the last ended (vertical
    // ones are joined into outlines, tilted ones into unions: level_sections.cpp).
    if (run_open && merged[i - 1].shape == s.shape && merged[i - 1].to.tip == s.from.tip)
      sh.runs.back().second = si + 1;
    else
      sh.runs.emplace_back(si, si + 1);
    run_open = true;
    zlo = std::min(zlo, sh.sweeps.back().z_min());
    zhi = std::max(zhi, sh.sweeps.back().z_max());
  }
}

}  // namespace

// The regions the boxes of the batch's tilted sweeps reach, each box grown by a millimetre
// and a region taken where the box reaches its border (the material a tilted piece may meet
// lies in them: LevelMaterial); empty without tilted sweeps.
RegionRange SubtractEngine::tilted_regions(const SubtractShared& sh) const noexcept {
  Box3 b;
  for (const Sweep& w : sh.sweeps)
    if (!w.vertical()) b.add(w.bounds().lo), b.add(w.bounds().hi);
  if (b.empty()) return RegionRange{};
  if (!(std::isfinite(b.lo.x) && std::isfinite(b.lo.y) && std::isfinite(b.hi.x) && std::isfinite(b.hi.y)))
    return RegionRange::all(s_);  // a box that is not finite reaches everything
  constexpr double kGrowMm = 1.0;
  return regions_reached(s_.xs_, s_.ys_,
                         units_box_outward(b.lo.x - kGrowMm, b.lo.y - kGrowMm, b.hi.x + kGrowMm, b.hi.y + kGrowMm));
}

int interval_of(const std::vector<Coord>& b, Coord v) noexcept {
  const auto it = std::upper_bound(b.begin(), b.end(), v);
  const long i = static_cast<long>(it - b.begin()) - 1;
  return static_cast<int>(std::clamp<long>(i, 0, static_cast<long>(b.size()) - 2));
}

void SubtractEngine::prepare(std::span<const SweepRef> batch, SubtractShared& sh) const {
  merge_collinear(batch, sh.merged, s_.z_top_mm());
  reset_level_last();
  double zlo = INFINITY, zhi = -INFINITY;
  plan_moves(sh, s_.z_top_mm(), zlo, zhi);
  sh.tilted_regions = tilted_regions(sh);
  reset_cell_masks(!sh.tilted_regions.empty());
  const bool nothing =
      (sh.sweeps.empty() && sh.lathe.empty() && sh.chain_count == 0) || zhi < s_.z0_ || zlo > s_.z1_;
  sh.lb = nothing ? 0 : s_.level_at(zlo);
  sh.le = nothing ? 0 : s_.level_at(zhi) + 1;
  plan_offsets(sh);
  size_storage(sh);
  sh.border_x = std::span<const Coord>(s_.xs_).subspan(1, s_.xs_.size() - 2);
  sh.border_y = std::span<const Coord>(s_.ys_).subspan(1, s_.ys_.size() - 2);
  for (auto& next : sh.next) next.store(0, std::memory_order_relaxed);
  sh.ahead_ready.store(0, std::memory_order_relaxed);
}

// The distinct (chain, radius) pairs of the batch, in level order: a flat tool's chain has
// one radius on all its levels.
void SubtractEngine::plan_offsets(SubtractShared& sh) const {
  const std::size_t cc = sh.chain_count;
  sh.offset_keys.clear();
  sh.offset_of.assign(static_cast<std::size_t>(sh.le - sh.lb) * cc, kNoChain);
  for (int l = sh.lb; l < sh.le; ++l) {
    const double zc = s_.level_z_mm(l);
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
}

void SubtractEngine::size_storage(SubtractShared& sh) const {
  const auto n = static_cast<std::size_t>(sh.le - sh.lb);
  const std::size_t noff = sh.offset_keys.size();
  if (sh.levels.size() < n) sh.levels.resize(n);
  sh.outcome.assign(n * static_cast<std::size_t>(s_.regions()), 0);
  if (sh.offsets.size() < noff) sh.offsets.resize(noff);
  for (std::size_t o = 0; o < noff; ++o) {
    // The box from the polyline's box (conservative: the offset lies within r + tol of
    // it), so that levels can be built while the offsets are being computed.
    SubtractShared::Offset& off = sh.offsets[o];
    const SubtractShared::Chain& c = sh.chains[sh.offset_keys[o].chain];
    const Coord d = static_cast<Coord>(std::ceil((sh.offset_keys[o].r + c.shape->chord_tol_mm) * kUnitsPerMm)) + 2;
    const Rect b = bounds_of(c.pts);
    off.box = Rect{b.x0 - d, b.y0 - d, b.x1 + d, b.y1 + d};
    off.ix0 = interval_of(s_.xs_, off.box.x0);
    off.ix1 = interval_of(s_.xs_, off.box.x1);
    off.iy0 = interval_of(s_.ys_, off.box.y0);
    off.iy1 = interval_of(s_.ys_, off.box.y1);
    const std::size_t pieces = static_cast<std::size_t>((off.ix1 - off.ix0 + 1) * (off.iy1 - off.iy0 + 1));
    off.cut.resize(pieces);
    off.state.assign(pieces, 0);
    off.built = 0;
  }
}

}  // namespace lbr::geom::detail

namespace lbr::geom {

using detail::Rect2;

std::size_t tight_loop_end(std::span<const SweepRef> moves) noexcept {
  const CutterShape* tool = nullptr;
  double turned = 0.0, dx = 0.0, dy = 0.0;
  Rect2 box;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const SweepRef& m = moves[i];
    const double mx = m.to.tip.x - m.from.tip.x, my = m.to.tip.y - m.from.tip.y;
    if (m.shape == nullptr || m.shape != tool) {  // a turning move or another tool: start again
      tool = m.shape;
      turned = dx = dy = 0.0;
      box = Rect2{};
    }
    if (tool == nullptr || (mx == 0.0 && my == 0.0)) continue;
    box.add(m.from.tip.x, m.from.tip.y);
    box.add(m.to.tip.x, m.to.tip.y);
    if (box.span() > kTightLoopDiameters * 2.0 * tool->radius()) {  // a wide loop: count from here
      turned = 0.0;
      box = Rect2{};
      box.add(m.from.tip.x, m.from.tip.y);
      box.add(m.to.tip.x, m.to.tip.y);
    } else if (dx != 0.0 || dy != 0.0) {
      turned += std::atan2(dx * my - dy * mx, dx * mx + dy * my);  // signed: a zig-zag turns back
      if (std::abs(turned) >= 2.0 * std::numbers::pi) return i + 1;
    }
    dx = mx;
    dy = my;
  }
  return moves.size();
}

std::size_t tilted_path_end(std::span<const SweepRef> moves) noexcept {
  double diameters = 0.0;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const SweepRef& m = moves[i];
    if (m.shape == nullptr || vertical_poses(m.from, m.to) || !(m.shape->radius() > 0.0)) continue;
    diameters += std::hypot(m.to.tip.x - m.from.tip.x, m.to.tip.y - m.from.tip.y) / (2.0 * m.shape->radius());
    if (diameters > kTiltedBatchDiameters) return std::max<std::size_t>(i, 1);
  }
  return moves.size();
}

std::size_t batch_end(std::span<const SweepRef> moves) noexcept {
  return std::min(tight_loop_end(moves), tilted_path_end(moves));
}

}  // namespace lbr::geom
