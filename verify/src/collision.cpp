#include "verify/collision.hpp"

#include <algorithm>

namespace lbr::verify {

namespace {


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
    : config_(config), tools_(tools), index_(index) {
  for (const auto& [number, tool] : tools.config().tools) {
    Parts p;
    p.shank_from_mm = tool.flute_length_mm + config.tolerance_mm;
    p.holder_from_mm = tool.length_mm + config.tolerance_mm;
    const double shank_d = tool.shank_diameter_mm > 0.0 ? tool.shank_diameter_mm : tool.diameter_mm;
    p.has_shank = tool.length_mm - p.shank_from_mm > 0.0;
    if (p.has_shank) p.shank = cylinder(shank_d, tool.length_mm - p.shank_from_mm, tools.chord_tol_mm());
    p.holder = cylinder(tool.holder_diameter_mm, tool.holder_length_mm, tools.chord_tol_mm());
    parts_.emplace(number, std::move(p));
  }
}

int CollisionChecker::findings_of(const geom::LbrSolid& solid, const motion::TimedSweep& m, int rapid,
                                  Finding (&out)[3]) {
  int n = 0;
  if (m.ref.shape == nullptr) return 0;  // turning inserts and tool 0: not checked
  if (rapid < 0) {
    const nc::Segment* seg = index_.find(m.ref.id, nullptr);
    rapid = seg != nullptr && seg->kind == nc::SegmentKind::Rapid ? 1 : 0;
  }
  if (rapid > 0) {
    const Intrusion in = probe_.measure(solid, geom::Sweep(*m.ref.shape, m.ref.from, m.ref.to), config_.tolerance_mm);
    if (in.deep_mm3 > 0.0) out[n++] = {EventKind::RapidIntoMaterial, in};
  }
  const auto parts = parts_.find(m.tool);
  if (parts == parts_.end()) return n;
  const Parts& p = parts->second;
  if (p.has_shank) {
    const Intrusion in =
        probe_.measure(solid, geom::Sweep(p.shank, raised(m.ref.from, p.shank_from_mm), raised(m.ref.to, p.shank_from_mm)),
                       config_.tolerance_mm);
    if (in.deep_mm3 > 0.0) out[n++] = {EventKind::ShankInMaterial, in};
  }
  const Intrusion in =
      probe_.measure(solid, geom::Sweep(p.holder, raised(m.ref.from, p.holder_from_mm), raised(m.ref.to, p.holder_from_mm)),
                     config_.tolerance_mm);
  if (in.deep_mm3 > 0.0) out[n++] = {EventKind::HolderInMaterial, in};
  return n;
}

Event CollisionChecker::event_of(const motion::TimedSweep& m, const Finding& f) const {
  Event e;
  e.kind = f.kind;
  e.t_s = m.t_s;
  const std::string* source = nullptr;
  if (const nc::Segment* seg = index_.find(m.ref.id, &source)) {
    e.line = seg->line;
    e.source = *source;
  }
  e.move = m.ref.id;
  e.tool = m.tool;
  e.channel = m.channel;
  e.position = m.ref.to.tip;
  e.volume_mm3 = f.what.volume_mm3;
  e.depth_mm = f.what.depth_mm;
  e.region = f.what.region;
  return e;
}

std::size_t CollisionChecker::check(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                                    std::size_t from, std::size_t to, std::vector<Event>& events) {
  return check(solid, moves, {}, from, to, events);
}

std::size_t CollisionChecker::check(const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                                    std::span<const std::uint8_t> rapid, std::size_t from, std::size_t to,
                                    std::vector<Event>& events) {
  if (!config_.enabled) return to;
  Finding found[3];
  for (std::size_t i = from; i < to; ++i) {
    const int n = findings_of(solid, moves[i], rapid.empty() ? -1 : (rapid[i] != 0 ? 1 : 0), found);
    if (n > 0 && i > from) return i;
    for (int k = 0; k < n; ++k) add_event(events, event_of(moves[i], found[k]));
  }
  return to;
}

}  // namespace lbr::verify
