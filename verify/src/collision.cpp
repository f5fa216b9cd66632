#include "verify/collision.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lbr::verify {

namespace {

// The kinds a run may continue with (CollisionChecker::check_moves()): the parts that do not
// cut (shank, holder, spindle nose), whose later moves are tested for contact only, and the
// kinds of the cutting sweep itself (rapid, spindle off, feed limit), whose run ends its batch
// and takes the volume the kernel removed for it (settle()). A plunge's core is measured
// move by move against the stock of its exact moment.
constexpr unsigned kPartKinds = (1u << static_cast<unsigned>(EventKind::ShankInMaterial)) |
                                (1u << static_cast<unsigned>(EventKind::HolderInMaterial)) |
                                (1u << static_cast<unsigned>(EventKind::SpindleNoseInMaterial));
constexpr unsigned kSweepKinds = (1u << static_cast<unsigned>(EventKind::RapidIntoMaterial)) |
                                 (1u << static_cast<unsigned>(EventKind::SpindleOff)) |
                                 (1u << static_cast<unsigned>(EventKind::FeedLimit));
constexpr unsigned kRunKinds = kPartKinds | kSweepKinds;


geom::Pose raised(const geom::Pose& p, double h_mm) {
  return {p.tip + h_mm * p.axis, p.axis};
}

// A cylinder of `diameter_mm` and `length_mm` as a flat cutter shape (its sweep sections are
// exact up to the chord tolerance).
geom::CutterShape cylinder(double diameter_mm, double length_mm, double chord_tol_mm) {
  geom::Tool t;
  t.kind = geom::ToolKind::Flat;
  t.diameter_mm = diameter_mm;
  t.flute_length_mm = length_mm;
  t.length_mm = length_mm;
  t.shank_diameter_mm = diameter_mm;
  return geom::CutterShape::build(t, chord_tol_mm);
}

// The cutting part of `t` moved inwards by `m` normal to its surface, as a tool whose tip lies
// `raise` up the axis: every radius less m, a corner radius less m (none left: a sharp
// corner), a cone's tip up by m / sin(half angle), the flutes' top down by m. False when
// nothing of it is left.
bool inner_tool(const geom::Tool& t, double m, geom::Tool& out, double& raise) {
  out = t;
  out.diameter_mm = t.diameter_mm - 2.0 * m;
  raise = m;
  switch (t.kind) {
    case geom::ToolKind::Flat:
    case geom::ToolKind::Ball: break;
    case geom::ToolKind::Bull:
      if (t.corner_radius_mm > m) out.corner_radius_mm = t.corner_radius_mm - m;
      else out.kind = geom::ToolKind::Flat;
      break;
    case geom::ToolKind::Drill:
    case geom::ToolKind::VBit: raise = m / std::sin(0.5 * t.angle_deg * std::numbers::pi / 180.0); break;
  }
  out.flute_length_mm = t.flute_length_mm - m - raise;
  out.length_mm = std::max(out.length_mm, out.flute_length_mm);
  out.shank_diameter_mm = 0.0;
  return out.diameter_mm > 0.0 && out.flute_length_mm > 0.0 && out.validate().empty();
}

// Material within this of a probe's boundary is not a finding: the configured tolerance
// beyond what polygonisation alone can put there. The probe's section and the wall a
// cut left are both polygons within ±chord tolerance of their circles, possibly on
// different angle grids (a joined outline's, a single move's), so they may cross by up to
// twice the chord tolerance where the exact surfaces touch (docs/verification.md).
double probe_margin(const CheckConfig& c, double chord_tol_mm) noexcept { return c.tolerance_mm + 2.0 * chord_tol_mm; }

// The angle of the tip's descent along the tool axis from the plane normal to the axis [deg]
// (90: a straight plunge); 0 when the move does not descend.
double descent_deg(const geom::Pose& from, const geom::Pose& to) {
  const geom::Vec3 d = to.tip - from.tip;
  const double along = geom::dot(d, from.axis);
  if (!(-along > 1e-9)) return 0.0;
  const double across = geom::norm(d - along * from.axis);
  return std::atan2(-along, across) * 180.0 / std::numbers::pi;
}

// A turning move as the kernel sweeps it (geom/src/batch_plan.cpp): the reference point from
// (from.tip.x, from.tip.z) to (to.tip.x, to.tip.z) in the (r, z) plane, moved by `offset`.
geom::LatheSweep lathe_sweep(const geom::TurningShape& shape, const geom::SweepRef& r, geom::TurningShape::P2 offset) {
  return {shape, r.from.tip.x + offset.r, r.from.tip.z + offset.z, r.to.tip.x + offset.r, r.to.tip.z + offset.z};
}

}  // namespace

void MoveIndex::add(const nc::Toolpath& path, geom::MoveId base) {
  ranges_.push_back({base, &path});
  std::sort(ranges_.begin(), ranges_.end(), [](const Range& a, const Range& b) { return a.base < b.base; });
}

const nc::Segment* MoveIndex::find(geom::MoveId id, const std::string** source) const noexcept {
  auto it = std::upper_bound(ranges_.begin(), ranges_.end(), id,
                             [](geom::MoveId v, const Range& r) { return v <= r.base; });
  if (it == ranges_.begin()) return nullptr;
  --it;
  const std::size_t k = id - it->base - 1;
  if (k >= it->path->segments.size()) return nullptr;
  if (source != nullptr) *source = &it->path->source;
  return &it->path->segments[k];
}

CollisionChecker::CollisionChecker(const CheckConfig& config, const motion::ToolTable& tools, const MoveIndex& index)
    : config_(config), index_(index) {
  last_tool_.fill(-1);
  for (const auto& [number, tool] : tools.config().tools) {
    Parts p;
    p.shank_from_mm = tool.flute_length_mm + config.tolerance_mm;
    p.holder_from_mm = tool.length_mm + config.tolerance_mm;
    const double shank_d = tool.shank_diameter_mm > 0.0 ? tool.shank_diameter_mm : tool.diameter_mm;
    p.has_shank = tool.length_mm - p.shank_from_mm > 0.0;
    if (p.has_shank) p.shank = cylinder(shank_d, tool.length_mm - p.shank_from_mm, tools.chord_tol_mm());
    p.holder = cylinder(tool.holder_diameter_mm, tool.holder_length_mm, tools.chord_tol_mm());
    p.has_nose = config.spindle_nose_diameter_mm > 0.0 && config.spindle_nose_length_mm > 0.0;
    if (p.has_nose) {
      p.nose_from_mm = tool.length_mm + tool.holder_length_mm + config.tolerance_mm;
      p.nose = cylinder(config.spindle_nose_diameter_mm, config.spindle_nose_length_mm, tools.chord_tol_mm());
    }
    p.centre_cutting = tool.centre_cutting;
    geom::Tool inner;
    p.inner_margin_mm = probe_margin(config, tools.chord_tol_mm());
    p.has_inner = inner_tool(tool, p.inner_margin_mm, inner, p.inner_raise_mm);
    if (p.has_inner) p.inner = geom::CutterShape::build(inner, tools.chord_tol_mm());
    if (!p.centre_cutting)
      p.core = cylinder(kNonCuttingCoreFraction * tool.diameter_mm, tool.flute_length_mm, tools.chord_tol_mm());
    parts_.emplace(number, std::move(p));
  }
  // A holder's faces along Z stand back by the tolerance, as a milling holder's face does.
  for (const auto& [number, insert] : tools.config().inserts) {
    if (!(insert.holder_width_mm > 2.0 * config.tolerance_mm)) continue;
    geom::TurningTool t = insert;
    t.holder_width_mm -= 2.0 * config.tolerance_mm;
    t.holder_z_mm += config.tolerance_mm;
    holders_.emplace(number, InsertHolder{geom::TurningShape::holder(t, tools.chord_tol_mm()),
                                          geom::TurningShape::holder_offset(t)});
  }
}

int CollisionChecker::findings_of(const geom::LbrSolid& solid, const motion::TimedSweep& m, int rapid, Findings& out) {
  if (m.ref.turning != nullptr) {
    const int n = segment_findings(solid, m, index_.find(m.ref.id, nullptr), rapid, out, 0);
    const auto h = holders_.find(m.tool);
    return h != holders_.end() ? holder_finding(solid, m, h->second, out, n) : n;
  }
  if (m.ref.shape == nullptr) return 0;  // tool 0: nothing cuts
  const auto parts = parts_.find(m.tool);
  const Parts* p = parts == parts_.end() ? nullptr : &parts->second;
  int n = tool_change_finding(solid, m, out, 0);
  n = segment_findings(solid, m, index_.find(m.ref.id, nullptr), rapid, out, n);
  return p != nullptr ? part_findings(solid, m, *p, out, n) : n;
}

int CollisionChecker::segment_findings(const geom::LbrSolid& solid, const motion::TimedSweep& m, const nc::Segment* seg,
                                       int rapid_flag, Findings& out, int n) {
  const bool rapid = rapid_flag >= 0 ? rapid_flag > 0 : seg != nullptr && seg->kind == nc::SegmentKind::Rapid;
  const bool spindle_off = seg != nullptr && !seg->spindle_turning();
  const double feed_limit = config_.max_cutting_feed_mm_per_min;
  // A rapid is judged as one (a sampled rapid is a Feed segment at the rapid's speed).
  const bool too_fast = !rapid && seg != nullptr && seg->kind == nc::SegmentKind::Feed && feed_limit > 0.0 &&
                        seg->feed_mm_per_min > feed_limit;
  if (rapid || spindle_off || too_fast) {
    const Intrusion in = cutting_intrusion(solid, m);
    if (in.deep_mm3 > 0.0) {
      if (rapid) out[n++] = {EventKind::RapidIntoMaterial, in};
      if (spindle_off) out[n++] = {EventKind::SpindleOff, in, seg->spindle_s};
      if (too_fast) out[n++] = {EventKind::FeedLimit, in, seg->feed_mm_per_min};
    }
  }
  return n;
}

namespace {
double probe_margin(const CheckConfig& c, const geom::LbrSolid& solid) noexcept {
  return probe_margin(c, solid.spec().chord_tol_mm);
}

// How far a checked part's tilted sub-step (the tool where it must not cut, its shank,
// holder, the spindle nose) may stand out of its sweep (geom::Sweep's twist_tol_mm): half
// the checks' tolerance, inside the probe's margin, so that it raises no finding the exact
// sweep would not (docs/verification.md).
double part_twist_tol(const CheckConfig& c) noexcept { return 0.5 * c.tolerance_mm; }
}  // namespace

int CollisionChecker::tool_change_finding(const geom::LbrSolid& solid, const motion::TimedSweep& m, Findings& out,
                                          int n) {
  if (m.channel < 0 || m.channel >= kChannels) return n;
  const int before = last_tool_[static_cast<std::size_t>(m.channel)];
  if (before < 0 || before == m.tool || m.ref.shape == nullptr) return n;
  const Intrusion in = tool_intrusion(solid, m, m.ref.from, m.ref.from);
  if (in.deep_mm3 > 0.0) out[n++] = {EventKind::ToolChangeInMaterial, in};
  return n;
}

Intrusion CollisionChecker::cutting_intrusion(const geom::LbrSolid& solid, const motion::TimedSweep& m) {
  const double margin = probe_margin(config_, solid);
  if (m.ref.turning != nullptr)
    return probe_.measure(solid, lathe_sweep(*m.ref.turning, m.ref, {0.0, 0.0}), margin, contact_only_);
  return tool_intrusion(solid, m, m.ref.from, m.ref.to);
}

Intrusion CollisionChecker::tool_intrusion(const geom::LbrSolid& solid, const motion::TimedSweep& m,
                                           const geom::Pose& from, const geom::Pose& to) {
  const double margin = probe_margin(config_, solid);
  const geom::Sweep sweep(*m.ref.shape, from, to, solid.z_top_mm(), part_twist_tol(config_));
  const auto parts = parts_.find(m.tool);
  // The inner tool stands for this margin only (the tool table's chord tolerance is the
  // solid's whenever both come from one profile).
  if (parts == parts_.end() || !parts->second.has_inner || parts->second.inner_margin_mm != margin)
    return probe_.measure(solid, sweep, margin, contact_only_);
  const Parts& p = parts->second;
  const geom::Sweep inner(p.inner, raised(from, p.inner_raise_mm), raised(to, p.inner_raise_mm), solid.z_top_mm(),
                          part_twist_tol(config_));
  return probe_.measure(solid, sweep, margin, contact_only_, &inner);
}

int CollisionChecker::holder_finding(const geom::LbrSolid& solid, const motion::TimedSweep& m, const InsertHolder& h,
                                     Findings& out, int n) {
  const geom::LatheSweep insert = lathe_sweep(*m.ref.turning, m.ref, {0.0, 0.0});
  const Intrusion in =
      probe_.measure(solid, lathe_sweep(h.shape, m.ref, h.offset), probe_margin(config_, solid), contact_only_, &insert);
  if (in.deep_mm3 > 0.0) out[n++] = {EventKind::HolderInMaterial, in};
  return n;
}

int CollisionChecker::part_findings(const geom::LbrSolid& solid, const motion::TimedSweep& m, const Parts& p,
                                    Findings& out, int n) {
  if (!p.centre_cutting) {
    const double angle = descent_deg(m.ref.from, m.ref.to);
    if (angle > config_.max_ramp_angle_deg) {
      const Intrusion in =
          probe_.measure(solid, geom::Sweep(p.core, m.ref.from, m.ref.to, solid.z_top_mm(), part_twist_tol(config_)),
                         probe_margin(config_, solid), contact_only_);
      if (in.deep_mm3 > 0.0) out[n++] = {EventKind::Plunge, in, angle};
    }
  }
  if (p.has_shank && raised_finding(solid, m, p.shank, p.shank_from_mm, EventKind::ShankInMaterial, out[n])) ++n;
  if (raised_finding(solid, m, p.holder, p.holder_from_mm, EventKind::HolderInMaterial, out[n])) ++n;
  if (p.has_nose && raised_finding(solid, m, p.nose, p.nose_from_mm, EventKind::SpindleNoseInMaterial, out[n])) ++n;
  return n;
}

bool CollisionChecker::raised_finding(const geom::LbrSolid& solid, const motion::TimedSweep& m,
                                      const geom::CutterShape& part, double from_mm, EventKind kind, Finding& out) {
  const geom::Sweep sweep(part, raised(m.ref.from, from_mm), raised(m.ref.to, from_mm), solid.z_top_mm(),
                          part_twist_tol(config_));
  const Intrusion in = probe_.measure(solid, sweep, probe_margin(config_, solid), contact_only_);
  if (!(in.deep_mm3 > 0.0)) return false;
  out = {kind, in};
  return true;
}

Event CollisionChecker::event_of(const motion::TimedSweep& m, const Finding& f) const {
  Event e;
  e.kind = f.kind;
  e.t_s = m.t_s;
  const std::string* source = nullptr;
  if (const nc::Segment* seg = index_.find(m.ref.id, &source)) {
    e.line = seg->line;
    e.source = *source;
  } else {
    e.line = m.line;  // a sampled stream's sweep knows its line (0: none, e.g. live)
  }
  e.move = m.ref.id;
  e.tool = m.tool;
  e.channel = m.channel;
  e.position = f.kind == EventKind::ToolChangeInMaterial ? m.ref.from.tip : m.ref.to.tip;  // where it stands
  e.volume_mm3 = f.what.volume_mm3;
  e.depth_mm = f.what.depth_mm;
  e.region = f.what.region;
  e.value = f.value;
  return e;
}

std::size_t CollisionChecker::check(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                                    std::size_t from, std::size_t to, std::vector<Event>& events) {
  return check_moves(solid, moves, {}, from, to, events, true);
}

std::size_t CollisionChecker::check(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                                    std::span<const std::uint8_t> rapid, std::size_t from, std::size_t to,
                                    std::vector<Event>& events, bool runs) {
  return check_moves(solid, moves, rapid, from, to, events, runs);
}

std::size_t CollisionChecker::check_moves(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                                          std::span<const std::uint8_t> rapid, std::size_t from, std::size_t to,
                                          std::vector<Event>& events, bool runs) {
  settle_.clear();
  run_moves_ = 0;
  if (!config_.enabled) return to;
  Findings found;
  unsigned before = 0;  // the kinds the move before raised (bit per EventKind), 0: clean
  for (std::size_t i = from; i < to; ++i) {
    // After a move with findings, the next is first tested for contact only: if it continues
    // the run (the same kinds), it extends the run's events without adding volume or depth.
    contact_only_ = runs && i > from && before != 0 && (before & ~kRunKinds) == 0;
    const int n = findings_of(solid, moves[i], rapid.empty() ? -1 : (rapid[i] != 0 ? 1 : 0), found);
    unsigned kinds = 0;
    for (int k = 0; k < n; ++k) kinds |= 1u << static_cast<unsigned>(found[k].kind);
    // A move that starts a run of findings is checked again against the stock of its moment;
    // a run of the cutting sweep's kinds ends its batch with its last move (settle()).
    const bool continues = kinds == before;
    if (i > from && ((n > 0 && (!runs || !continues || (kinds & ~kRunKinds) != 0)) || (run_moves_ > 1 && !continues))) {
      contact_only_ = false;
      if (run_moves_ < 2) settle_.clear();
      return i;
    }
    if (i == from) run_moves_ = (kinds & kSweepKinds) != 0 ? 1 : 0;
    else if (run_moves_ > 0) run_moves_ = continues ? run_moves_ + 1 : 0;  // 0: a one-move run, measured whole
    if (run_moves_ == 0) settle_.clear();
    before = kinds;
    for (int k = 0; k < n; ++k) {
      if (contact_only_) found[k].what.volume_mm3 = found[k].what.depth_mm = 0.0;
      const std::size_t at = add_event(events, event_of(moves[i], found[k]));
      if (i == from && (kSweepKinds >> static_cast<unsigned>(found[k].kind) & 1u) != 0)
        settle_.push_back({at, found[k].what.volume_mm3});
    }
    if (moves[i].channel >= 0 && moves[i].channel < kChannels)
      last_tool_[static_cast<std::size_t>(moves[i].channel)] = moves[i].tool;  // judged: not asked again
  }
  contact_only_ = false;
  if (run_moves_ < 2) settle_.clear();
  return to;
}

void CollisionChecker::settle(double removed_mm3, bool whole, std::vector<Event>& events) {
  if (whole)
    for (const auto& [at, first_mm3] : settle_)
      if (at < events.size()) events[at].volume_mm3 += std::max(0.0, removed_mm3 - first_mm3);
  settle_.clear();
  run_moves_ = 0;
}

void check_travel(const nc::Toolpath& path, const nc::AxisVector& min, const nc::AxisVector& max, int channel,
                  geom::MoveId base, std::vector<Event>& events) {
  for (std::size_t i = 0; i < path.segments.size(); ++i) {
    const nc::Segment& s = path.segments[i];
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed) continue;
    const nc::AxisVector q = nc::machine_axes(path, s.end, s.tool);
    for (int a = 0; a < nc::kAxes; ++a) {
      const double beyond = std::max(min[a] - q[a], q[a] - max[a]);
      if (!(beyond > 0.0)) continue;
      Event e;
      e.kind = EventKind::OverTravel;
      e.source = path.source;
      e.line = s.line;
      e.move = static_cast<geom::MoveId>(base + i + 1);
      e.tool = s.tool;
      e.channel = channel;
      e.position = {s.end[nc::X], s.end[nc::Y], s.end[nc::Z]};
      e.axis = a;
      e.value = beyond;
      add_event(events, e);
    }
  }
}

}  // namespace lbr::verify
