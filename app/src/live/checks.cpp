#include "live/checks.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "app/outputs.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::app::live {

namespace {

// The profile's max cutting feed (verify::rapid_threshold_mm_per_min) [mm/min].
double rapid_threshold(const Profile& p) {
  return verify::rapid_threshold_mm_per_min(p.machine.max_feed_mm_per_min, p.machine.rapid_mm_per_min);
}

}  // namespace

LiveChecks::LiveChecks(const Profile& profile, const motion::ToolTable& tools, std::size_t batch_capacity,
                       ProgramLines lines)
    : enabled_(profile.checks.enabled),
      rapid_mm_per_min_(rapid_threshold(profile)),
      period_s_(profile.live.period_ms * 1e-3),
      checker_(profile.checks, tools, index_),
      lines_(std::move(lines)) {
  fast_step_mm_ = verify::kFastMargin * rapid_mm_per_min_ / 60.0 * period_s_;
  moves_.reserve(batch_capacity);
  info_.reserve(batch_capacity);
  rapid_.reserve(batch_capacity);
  events_.reserve(kMaxEvents);
  overflow_.reserve(8);
}

void LiveChecks::begin(std::span<const geom::SweepRef> batch, std::span<const motion::SweepInfo> info) noexcept {
  moves_.clear();
  info_.clear();
  rapid_.clear();
  if (!enabled_) return;
  const std::size_t n = std::min({batch.size(), info.size(), moves_.capacity()});
  for (std::size_t i = 0; i < n; ++i) {
    motion::TimedSweep m;
    m.ref = batch[i];
    // Events name the first offending sample; record() widens them to the last one.
    m.ref.id = static_cast<geom::MoveId>(info[i].first_seq & 0xFFFFFFFFU);
    m.t_s = static_cast<double>(info[i].last_seq) * period_s_;
    m.channel = info[i].channel;
    m.tool = info[i].tool;
    moves_.push_back(m);
    info_.push_back(info[i]);
    rapid_.push_back(info[i].fast ? 1 : 0);
  }
}

std::size_t LiveChecks::check(const geom::LbrSolid& solid, std::size_t from, std::size_t to, const TickSamples& tick) {
  if (!enabled_ || to > moves_.size()) return to;
  // Up to kKindsPerSweep events a sweep; without room for them the findings are counted only.
  const bool room = events_.size() + kKindsPerSweep <= kMaxEvents;
  std::vector<verify::Event>& list = room ? events_ : overflow_;
  if (!room) overflow_.clear();
  const std::size_t before = list.size();
  std::array<double, kKindsPerSweep> volume{};  // of the last events: one that grows was extended
  for (std::size_t b = 0; b < std::min(kKindsPerSweep, before); ++b) volume[b] = list[before - 1 - b].volume_mm3;
  const std::size_t end = checker_.check(solid, moves_, rapid_, from, to, list);
  record(from, before, volume, list, tick);  // only sweep `from` can have findings (CollisionChecker::check)
  if (!room) dropped_ += overflow_.size();
  return end;
}

std::int64_t LiveChecks::rx_of(const motion::SweepInfo& info, const TickSamples& tick) const noexcept {
  for (std::size_t i = 0; i < tick.seq.size() && i < tick.rx_ns.size() && i < tick.channel.size(); ++i)
    if (tick.channel[i] == info.channel && tick.seq[i] >= info.first_seq) return tick.rx_ns[i];
  return tick.rx_ns.empty() ? 0 : tick.rx_ns.front();
}

void LiveChecks::record(std::size_t k, std::size_t events_before, const std::array<double, kKindsPerSweep>& volume_before,
                        std::vector<verify::Event>& list, const TickSamples& tick) {
  const motion::SweepInfo& info = info_[k];
  const geom::MoveId first = moves_[k].ref.id;
  bool found = false;
  // The events the sweep raised or extended: new ones, and older ones whose volume grew
  // (add_event() left the last_move of both at `first`).
  for (std::size_t back = 0; back < std::min(kKindsPerSweep, list.size()); ++back) {
    const std::size_t i = list.size() - 1 - back;
    verify::Event& e = list[i];
    const bool extended = i < events_before && events_before - 1 - i < kKindsPerSweep && e.volume_mm3 > volume_before[events_before - 1 - i];
    if (e.last_move != first || (i < events_before && !extended)) continue;
    found = true;
    e.last_move = static_cast<geom::MoveId>(info.last_seq & 0xFFFFFFFFU);
    e.last_line = lines_.line_of(info.last_seq);
    if (i < events_before) continue;  // an event extended, not raised
    e.line = lines_.line_of(info.first_seq);
    EventNote n{e.kind, info.first_seq, e.line, e.tool, e.channel, e.position, e.volume_mm3, e.depth_mm, 0.0};
    n.latency_ms = static_cast<double>(sched::now_ns() - rx_of(info, tick)) * 1e-6;
    (void)notes_.try_push(n);
  }
  if (found) latency_.record(sched::now_ns() - rx_of(info, tick));
}

void LiveChecks::fill_alarms(gfx::LiveStats& stats) const noexcept {
  fill_event_alarms(events_, dropped_, kShownAlarms, true, stats);
}

bool LiveChecks::pop_note(EventNote& out) noexcept { return notes_.try_pop(out); }

std::vector<verify::Event> LiveChecks::events() const {
  std::vector<verify::Event> out = events_;
  if (!lines_.empty())
    for (verify::Event& e : out) e.source = lines_.source();
  return out;
}

}  // namespace lbr::app::live
