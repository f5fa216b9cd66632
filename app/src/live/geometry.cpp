#include "live/geometry.hpp"

#include <algorithm>

#include "sched/rt_thread.hpp"

namespace lbr::app::live {

static_assert(hal::kMaxChannels <= motion::kMaxChannels, "every HAL channel needs a motion channel");

std::array<kin::Kinematics, motion::kMaxChannels> Geometry::channel_kinematics(const Profile& profile) {
  std::array<kin::Kinematics, motion::kMaxChannels> k{};
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = i < profile.channels.size() ? profile.channels[i].kin : profile.kin;
  return k;
}

Geometry::Geometry(geom::LbrSolid& solid, const Profile& profile, const motion::ToolTable& tools, int default_tool,
                   sched::SpscRing<hal::AxisSample>& ring, double tol_mm)
    : solid_(solid),
      ring_(ring),
      stream_(tools, channel_kinematics(profile), default_tool, tol_mm,
              2 * ring.capacity() + hal::kMaxChannels + kin::kMaxMoveSubsteps, *this) {
  rx_.resize(ring.capacity());
}

std::size_t Geometry::tick(std::size_t limit) {
  stream_.clear_batch();
  std::size_t n = 0;
  limit = std::min(limit, rx_.size());
  while (n < limit) {
    hal::AxisSample* s = ring_.front();
    if (s == nullptr) break;
    stream_.take(s->channel, s->seq, s->tool, s->q, s->mask);
    rx_[n++] = s->t_rx_ns;
    ring_.pop();
  }
  stream_.flush_all();
  if (!stream_.batch().empty()) {
    const std::int64_t t_start = sched::now_ns();
    solid_.subtract(stream_.batch(), ws_);
    work_.record(sched::now_ns() - t_start);
    sweeps_.store(sweeps_.load(std::memory_order_relaxed) + stream_.batch().size(), std::memory_order_relaxed);
    batches_.store(batches_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  if (n > 0) {
    last_rx_ns_ = rx_[n - 1];
    const std::int64_t t = sched::now_ns();
    for (std::size_t i = 0; i < n; ++i) lag_.record(t - rx_[i]);
    applied_.store(applied_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
    if (++ticks_since_volume_ >= 50) publish_volume();
  }
  return n;
}

void Geometry::on_sweep(const geom::SweepRef& s) noexcept {
  if (ex_ != nullptr) ex_->add_path_point(s.to.tip);
}

void Geometry::on_batch_full(std::span<const geom::SweepRef> batch) noexcept { solid_.subtract(batch, ws_); }

bool Geometry::publish(const gfx::LiveStats& stats) {
  if (ex_ == nullptr) return false;
  std::array<gfx::ToolState, gfx::kMaxTools> tools{};
  std::size_t n = 0;
  for (int i = 0; i < motion::kMaxChannels && n < tools.size(); ++i) {
    const motion::SampleStream::ChannelState c = stream_.channel(i);
    if (!c.have || c.tool.shape == nullptr) continue;
    tools[n++] = gfx::tool_state(c.tool.shape->tool, 1, c.pose, i);
  }
  return ex_->publish(solid_, std::span<const gfx::ToolState>(tools.data(), n), stream_.last_id(), stats);
}

void Geometry::publish_volume() noexcept {
  ticks_since_volume_ = 0;
  removed_.store(solid_.initial_volume_mm3() - solid_.volume_mm3(), std::memory_order_relaxed);
}

}  // namespace lbr::app::live
