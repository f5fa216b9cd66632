#include "app/batch.hpp"

#include "geom/parallel_subtractor.hpp"
#include "motion/path_sweeps.hpp"
#include "motion/tool_table.hpp"
#include "verify/collision.hpp"
#include "verify/design.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <stdexcept>

namespace lbr::app {

namespace {

double distance(const nc::AxisVector& a, const nc::AxisVector& b) {
  return std::hypot(b[nc::X] - a[nc::X], b[nc::Y] - a[nc::Y], b[nc::Z] - a[nc::Z]);
}

// Subtracts the moves in order, profile.batch_moves at a time. With a `checker`, each batch
// is checked against the stock before it is subtracted and ends early where a move meets
// material (verify/collision.hpp), so every event sees the stock of its moment.
void run_moves(const Profile& profile, const std::vector<motion::TimedSweep>& moves, BatchResult& r, const Progress& progress,
               verify::CollisionChecker* checker = nullptr, std::span<const std::uint8_t> rapid = {}) {
  geom::ParallelSubtractor pool(profile.threads);
  r.threads = pool.threads();
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  // Within one subtract() call the order of the sweeps does not matter (their union is
  // removed), so a batch is grouped by channel: each channel's consecutive sampled moves
  // then merge into long sweeps (merge_collinear) instead of alternating with the others'.
  std::vector<const motion::TimedSweep*> group;
  auto fill = [&](std::size_t from, std::size_t to, std::vector<geom::SweepRef>& out) {
    out.clear();
    const auto by_channel = [](const motion::TimedSweep& a, const motion::TimedSweep& b) { return a.channel < b.channel; };
    if (std::is_sorted(moves.begin() + static_cast<long>(from), moves.begin() + static_cast<long>(to), by_channel)) {
      for (std::size_t k = from; k < to; ++k) out.push_back(moves[k].ref);  // one channel: as they come
      return;
    }
    group.clear();
    for (std::size_t k = from; k < to; ++k) group.push_back(&moves[k]);
    std::stable_sort(group.begin(), group.end(),
                     [](const motion::TimedSweep* a, const motion::TimedSweep* b) { return a->channel < b->channel; });
    for (const motion::TimedSweep* m : group) out.push_back(m->ref);
  };
  // Batches of profile.batch_moves moves, pulled by the pool (a worker pulls the next one
  // while the current one is clipped).
  const std::size_t per = static_cast<std::size_t>(std::max(1, profile.batch_moves));
  std::size_t begin = 0;
  std::deque<std::size_t> ends;  // where the batches pulled so far end
  // A batch also ends where its path closes a tight loop or its tilted moves have run long
  // enough (geom::batch_end()).
  auto cut_loops = [&](std::vector<geom::SweepRef>& out, std::size_t from) {
    if (!std::is_sorted(moves.begin() + static_cast<long>(from), moves.begin() + static_cast<long>(from + out.size()),
                        [](const motion::TimedSweep& a, const motion::TimedSweep& b) { return a.channel < b.channel; }))
      return out.size();  // channels regrouped: several paths, no single loop to cut
    out.resize(geom::batch_end(out));
    return out.size();
  };
  const geom::ParallelSubtractor::BatchSource source = [&](std::vector<geom::SweepRef>& out) {
    if (begin >= moves.size()) return false;
    fill(begin, std::min(begin + per, moves.size()), out);
    begin += cut_loops(out, begin);
    ends.push_back(begin);
    return true;
  };
  std::size_t done_moves = 0;
  const geom::ParallelSubtractor::BatchDone done = [&](const geom::SubtractStats&) {
    ++r.batches;
    if (checker != nullptr || ends.empty()) {
      done_moves = begin;
    } else {  // the pool may already have pulled the next batch
      done_moves = ends.front();
      ends.pop_front();
    }
    if (!progress) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report > std::chrono::seconds(1)) {
      last_report = now;
      progress(static_cast<double>(done_moves) / static_cast<double>(moves.size()));
    }
  };
  if (checker == nullptr) {
    r.stats += pool.run(r.solid, source, done);
  } else {
    // One batch at a time: the checks read the stock between batches.
    std::vector<geom::SweepRef> batch;
    while (begin < moves.size()) {
      const std::size_t end =
          checker->check(r.solid, moves, rapid, begin, std::min(begin + per, moves.size()), r.events, true);
      fill(begin, end, batch);
      begin += cut_loops(batch, begin);
      const double before_mm3 = r.solid.volume_mm3();
      const geom::SubtractStats s = pool.subtract(r.solid, batch);
      checker->settle(before_mm3 - r.solid.volume_mm3(), begin == end, r.events);
      r.stats += s;
      done(s);
    }
  }
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.removed_volume_mm3 = r.stock_volume_mm3 - r.solid.volume_mm3();
  if (progress) progress(1.0);
}

// --design: the final stock against the design, and the move that made the deepest gouge.
void compare_design(const Profile& profile, const std::vector<geom::Paths>& design,
                    const std::vector<motion::TimedSweep>& moves, const verify::MoveIndex& index, BatchResult& r) {
  if (profile.design.stl_path.empty()) return;
  r.design = compare_with_design(profile, design, r.solid, moves, index, r.events);
  r.design_sections = design;
}

// --sampled: which moves are rapids. A sampled stream has no G0, so, as in live mode, a move
// is a rapid when its sample speed (the segment's feed) is above the profile's max cutting
// feed by more than verify::kFastMargin (docs/verification.md "batch --sampled").
std::vector<std::uint8_t> sampled_rapids(const Profile& profile, const std::vector<motion::TimedSweep>& moves,
                                         const verify::MoveIndex& index) {
  const double fast = verify::kFastMargin * verify::rapid_threshold_mm_per_min(profile.machine.max_feed_mm_per_min,
                                                                               profile.machine.rapid_mm_per_min);
  std::vector<std::uint8_t> rapid(moves.size(), 0);
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const nc::Segment* seg = index.find(moves[i].ref.id, nullptr);
    rapid[i] = seg != nullptr && seg->kind == nc::SegmentKind::Feed && seg->feed_mm_per_min > fast ? 1 : 0;
  }
  return rapid;
}

// over-travel: from the tool path alone, before the cut (its events come first).
void check_travel(const Profile& profile, const nc::Toolpath& path, int channel, geom::MoveId base, BatchResult& r) {
  if (profile.checks.enabled)
    verify::check_travel(path, profile.machine.travel_min, profile.machine.travel_max, channel, base, r.events);
}

}  // namespace

std::vector<geom::Paths> load_design(const Profile& profile, const geom::LbrSolid& solid) {
  if (profile.design.stl_path.empty()) return {};
  const verify::StlMesh mesh = verify::read_stl(profile.design.stl_path);
  verify::check_design(mesh, solid, profile.design.stl_path);
  return verify::slice_design(mesh, solid);
}

verify::DesignReport compare_with_design(const Profile& profile, const std::vector<geom::Paths>& design,
                                         const geom::LbrSolid& solid, std::span<const motion::TimedSweep> moves,
                                         const verify::MoveIndex& index, std::vector<verify::Event>& events) {
  verify::DesignReport d = verify::compare_design(design, solid, profile.design.tolerance_mm);
  if (!moves.empty()) verify::attribute_gouge(d, solid, moves, index);
  if (auto e = verify::gouge_event(d, profile.design.tolerance_mm)) events.push_back(std::move(*e));
  return d;
}

std::vector<std::string> toolpath_warnings(const nc::Toolpath& path) {
  std::vector<std::string> out;
  const std::string& name = path.source;
  if (path.segments.empty()) {
    out.push_back(name + ": the program holds no moves; nothing is cut");
    return out;
  }
  std::size_t untooled = 0;
  int first_line = 0;
  for (const nc::Segment& s : path.segments)
    if (s.kind == nc::SegmentKind::Feed && s.tool == 0) {
      if (untooled++ == 0) first_line = s.line;
    }
  if (untooled > 0)
    out.push_back(name + ":" + std::to_string(first_line) + ": " + std::to_string(untooled) +
                  " feed moves run with no tool loaded (tool 0) and cut nothing; load one with T.. M6, "
                  "or give --start-tool N (profile: [nc] start_tool) when the spindle already holds a tool");
  return out;
}

double machining_time_s(const Profile& profile, const nc::Toolpath& path) {
  double t = 0.0;
  nc::AxisVector pos = path.start;
  for (const nc::Segment& s : path.segments) {
    switch (s.kind) {
      case nc::SegmentKind::Rapid: t += distance(pos, s.end) / profile.machine.rapid_mm_per_min * 60.0; break;
      case nc::SegmentKind::Feed: t += distance(pos, s.end) / s.feed_mm_per_min * 60.0; break;
      case nc::SegmentKind::Dwell: t += s.dwell_s; break;
      case nc::SegmentKind::ToolChange: t += profile.machine.tool_change_s; break;
    }
    pos = s.end;
  }
  return t;
}

geom::SolidSpec batch_solid_spec(const Profile& profile, const motion::ToolTable& tools) {
  geom::SolidSpec spec = profile.solid;
  if (profile.regions_auto) std::tie(spec.regions_x, spec.regions_y) = auto_region_grid(spec, tools.dominant_diameter());
  return spec;
}

BatchResult run_batch(const Profile& profile, const nc::Toolpath& path, const Progress& progress, bool sampled) {
  motion::ToolTable tools(profile.tooling, profile.solid.chord_tol_mm, profile.source);
  tools.require_path(path);
  BatchResult r{geom::LbrSolid(batch_solid_spec(profile, tools)), 0, 0, 0, 0, 0, {}, 1, {}, {}};
  r.stock_volume_mm3 = r.solid.initial_volume_mm3();
  r.machining_time_s = machining_time_s(profile, path);
  std::vector<motion::TimedSweep> moves;
  motion::path_sweeps(tools, profile.kin, path, nullptr, 0, 0, moves, r.moves);
  verify::MoveIndex index;
  index.add(path, 0);
  check_travel(profile, path, 0, 0, r);
  const std::vector<geom::Paths> design = load_design(profile, r.solid);
  verify::CollisionChecker checker(profile.checks, tools, index);
  const std::vector<std::uint8_t> rapid = sampled ? sampled_rapids(profile, moves, index) : std::vector<std::uint8_t>{};
  run_moves(profile, moves, r, progress, profile.checks.enabled ? &checker : nullptr, rapid);
  compare_design(profile, design, moves, index, r);
  return r;
}

BatchResult run_batch_channels(const Profile& profile, const std::vector<ChannelPath>& channels, bool sampled,
                               const Progress& progress) {
  motion::ToolTable tools(profile.tooling, profile.solid.chord_tol_mm, profile.source);
  for (const ChannelPath& c : channels) tools.require_path(c.path);
  BatchResult r{geom::LbrSolid(batch_solid_spec(profile, tools)), 0, 0, 0, 0, 0, {}, 1, {}, {}};
  r.stock_volume_mm3 = r.solid.initial_volume_mm3();
  motion::PlannedSweeps plan = motion::plan_channels(tools, channels, emulator_limits(profile), sampled);
  r.machining_time_s = plan.machining_time_s;
  r.moves = plan.moves;
  verify::MoveIndex index;  // segment ids of each channel (sampled: sample ids, no lines)
  geom::MoveId base = 0;
  for (std::size_t k = 0; k < channels.size(); ++k) {
    const nc::Toolpath& path = channels[k].path;
    if (!sampled) index.add(path, base);
    check_travel(profile, path, static_cast<int>(k), base, r);
    base += static_cast<geom::MoveId>(path.segments.size());
  }
  const std::vector<geom::Paths> design = load_design(profile, r.solid);
  verify::CollisionChecker checker(profile.checks, tools, index);
  run_moves(profile, plan.sweeps, r, progress, profile.checks.enabled ? &checker : nullptr);
  compare_design(profile, design, plan.sweeps, index, r);
  return r;
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace lbr::app
