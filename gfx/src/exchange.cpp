#include "gfx/exchange.hpp"

#include <algorithm>
#include <utility>

namespace lbr::gfx {

void set_alarm(Alarm& a, AlarmSeverity severity, const char* text) noexcept {
  a.severity = severity;
  std::size_t n = 0;
  for (; text != nullptr && text[n] != '\0' && n + 1 < a.text.size(); ++n) a.text[n] = text[n];
  a.text[n] = '\0';
}

ToolState tool_state(const geom::Tool& t, int tool_number, const geom::Pose& pose, int channel) {
  ToolState s;
  s.channel = channel;
  s.tool = tool_number;
  s.pose = pose;
  s.radius_mm = static_cast<float>(0.5 * t.diameter_mm);
  s.flute_mm = static_cast<float>(t.flute_length_mm);
  s.length_mm = static_cast<float>(std::max(t.length_mm, t.flute_length_mm));
  s.holder_radius_mm = static_cast<float>(0.5 * t.holder_diameter_mm);
  s.holder_length_mm = static_cast<float>(t.holder_length_mm);
  return s;
}

SolidExchange::SolidExchange(std::size_t path_capacity) : path_capacity_(std::max<std::size_t>(path_capacity, 2)) {
  path_.reserve(path_capacity_);
  slot_.path.reserve(path_capacity_);
}

void SolidExchange::add_path_point(const geom::Vec3& tip) noexcept {
  if (path_.size() == path_capacity_) {
    // Keep the newest points: drop the oldest half (no allocation; capacity is fixed).
    const std::size_t half = path_capacity_ / 2;
    std::move(path_.begin() + static_cast<std::ptrdiff_t>(half), path_.end(), path_.begin());
    path_.resize(path_.size() - half);
    path_dropped_ += half;
  }
  path_.push_back(tip);
}

bool SolidExchange::publish(geom::LbrSolid& solid, std::span<const ToolState> tools, geom::MoveId last_move,
                            const LiveStats& stats) {
  if (state_.load(std::memory_order_acquire) != kEmpty) {
    skipped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  // The slot is ours until the release store below.
  Snapshot& s = slot_;
  std::size_t n = 0;
  const int nreg = solid.regions(), nlev = solid.levels();
  for (int r = 0; r < nreg; ++r)
    for (int l = 0; l < nlev; ++l) {
      if (!solid.is_dirty(r, l)) continue;
      if (n == s.cells.size()) s.cells.emplace_back();
      CellUpdate& u = s.cells[n++];
      u.region = r;
      u.level = l;
      u.cell = solid.cell(r, l);  // copy-assign: reuses the slot's capacity
    }
  s.cell_count = n;
  s.path.clear();
  std::swap(s.path, path_);  // both reserved to path_capacity_: the writer keeps a reserved buffer
  if (path_.capacity() < path_capacity_) path_.reserve(path_capacity_);
  s.tool_count = static_cast<int>(std::min<std::size_t>(tools.size(), kMaxTools));
  for (int i = 0; i < s.tool_count; ++i) s.tools[static_cast<std::size_t>(i)] = tools[static_cast<std::size_t>(i)];
  s.last_move = last_move;
  s.stats = stats;
  s.path_dropped = path_dropped_;
  s.version = ++version_;
  solid.clear_dirty();
  state_.store(kFull, std::memory_order_release);
  published_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool SolidExchange::take(Snapshot& out) noexcept {
  if (state_.load(std::memory_order_acquire) != kFull) return false;
  std::swap(out.cells, slot_.cells);
  out.cell_count = slot_.cell_count;
  slot_.cell_count = 0;
  std::swap(out.path, slot_.path);
  out.tools = slot_.tools;
  out.tool_count = slot_.tool_count;
  out.last_move = slot_.last_move;
  out.stats = slot_.stats;
  out.path_dropped = slot_.path_dropped;
  out.version = slot_.version;
  state_.store(kEmpty, std::memory_order_release);
  return true;
}

}  // namespace lbr::gfx
