#include "live/geometry.hpp"

#include <algorithm>
#include <cmath>

#include "sched/rt_thread.hpp"

namespace lbr::app::live {

static_assert(hal::kMaxChannels <= motion::kMaxChannels, "every HAL channel needs a motion channel");

std::array<kin::Kinematics, motion::kMaxChannels> Geometry::channel_kinematics(const Profile& profile) {
  std::array<kin::Kinematics, motion::kMaxChannels> k{};
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = i < profile.channels.size() ? profile.channels[i].kin : profile.kin;
  return k;
}

std::size_t Geometry::batch_capacity(std::size_t ring_capacity) noexcept {
  return 2 * ring_capacity + hal::kMaxChannels + kin::kMaxMoveSubsteps;
}

Geometry::Geometry(geom::LbrSolid& solid, const Profile& profile, const motion::ToolTable& tools, int default_tool,
                   sched::SpscRing<hal::AxisSample>& ring, double tol_mm)
    : solid_(solid),
      ring_(ring),
      stream_(tools, channel_kinematics(profile), default_tool, tol_mm,
              batch_capacity(ring.capacity()), *this) {
  rx_.resize(ring.capacity());
  seq_.resize(ring.capacity());
  chan_.resize(ring.capacity());
  weight_.resize(ring.capacity());
  prefix_units_.resize(batch_capacity(ring.capacity()));
  const std::size_t cells = static_cast<std::size_t>(solid.levels()) * static_cast<std::size_t>(solid.regions());
  if (cells <= (std::size_t{1} << 22)) stamp_.assign(cells, 0);  // else: cells counted per sweep
}

namespace {

// Work estimate weights [units]: building one section of one sweep on one level, and one
// polygon difference of a (region, level) cell. Measured on this machine (docs/performance.md
// "Live overload"): a unit is roughly a microsecond of kernel time.
constexpr double kSectionUnits = 2.0;
constexpr double kCellUnits = 20.0;
constexpr int kMaxPieces = 64;  // one sweep is cut into at most this many pieces

}  // namespace

bool Geometry::reach(const geom::SweepRef& s, Reach& r) const noexcept {
  const geom::LbrSolid& so = solid_;
  double zlo = 0.0, zhi = 0.0, xlo = 0.0, xhi = 0.0, ylo = 0.0, yhi = 0.0;
  bool whole_grid = false;
  r.tilt = 1.0;
  if (s.shape != nullptr) {
    const double rad = s.shape->radius(), h = s.shape->height();
    const geom::Vec3 p[4] = {s.from.tip, s.to.tip, s.from.tip + h * s.from.axis, s.to.tip + h * s.to.axis};
    zlo = zhi = p[0].z;
    xlo = xhi = p[0].x;
    ylo = yhi = p[0].y;
    for (const geom::Vec3& v : p) {
      zlo = std::min(zlo, v.z), zhi = std::max(zhi, v.z);
      xlo = std::min(xlo, v.x), xhi = std::max(xhi, v.x);
      ylo = std::min(ylo, v.y), yhi = std::max(yhi, v.y);
    }
    zlo -= rad, zhi += rad, xlo -= rad, xhi += rad, ylo -= rad, yhi += rad;
    // A turning tool axis: geom::Sweep cuts it into sub-steps within the chord tolerance;
    // a point h from the tip turning by θ needs about θ·sqrt(h / (8·tol)) of them.
    const double c = std::clamp(geom::dot(s.from.axis, s.to.axis), -1.0, 1.0);
    const double theta = std::acos(c);
    if (theta > 0.0)
      r.tilt = 1.0 + std::min(256.0, theta * std::sqrt(h / (8.0 * std::max(1e-6, s.shape->chord_tol_mm))));
  } else if (s.turning != nullptr) {
    const double e = s.turning->z_extent;
    zlo = std::min(s.from.tip.z, s.to.tip.z) - e;
    zhi = std::max(s.from.tip.z, s.to.tip.z) + e;
    whole_grid = true;  // revolved about the spindle axis
  } else {
    return false;
  }
  if (zhi < so.z_bottom_mm() || zlo > so.z_top_mm()) return false;
  r.l0 = so.level_at(zlo);
  r.l1 = so.level_at(zhi);
  const geom::Rect st = so.stock_rect();
  const double x0 = geom::to_mm(st.x0), y0 = geom::to_mm(st.y0);
  const double wx = (geom::to_mm(st.x1) - x0) / so.regions_x(), wy = (geom::to_mm(st.y1) - y0) / so.regions_y();
  auto cell = [](double v, double lo, double w, int n) {
    return std::clamp(static_cast<int>(std::floor((v - lo) / w)), 0, n - 1);
  };
  if (whole_grid) {
    r.x0 = 0, r.x1 = so.regions_x() - 1, r.y0 = 0, r.y1 = so.regions_y() - 1;
  } else {
    if (xhi < x0 || ylo > geom::to_mm(st.y1) || xlo > geom::to_mm(st.x1) || yhi < y0) return false;
    r.x0 = cell(xlo, x0, wx, so.regions_x()), r.x1 = cell(xhi, x0, wx, so.regions_x());
    r.y0 = cell(ylo, y0, wy, so.regions_y()), r.y1 = cell(yhi, y0, wy, so.regions_y());
  }
  return true;
}

double Geometry::work_units(const geom::SweepRef& s) const noexcept {
  Reach r;
  if (!reach(s, r)) return 1.0;
  const double levels = r.l1 - r.l0 + 1, cells = levels * (r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1);
  return kSectionUnits * levels * r.tilt + kCellUnits * cells;
}

bool Geometry::stop_due() noexcept {
  if (stop_ns_ == nullptr) return false;
  std::int64_t t = stop_ns_->load(std::memory_order_relaxed);
  const std::int64_t now = sched::now_ns();
  if (t == 0) {
    const bool asked = (stop_a_ != nullptr && stop_a_->load(std::memory_order_relaxed)) ||
                       (stop_b_ != nullptr && stop_b_->load(std::memory_order_relaxed));
    if (!asked) return false;
    std::int64_t expected = 0;
    (void)stop_ns_->compare_exchange_strong(expected, now, std::memory_order_relaxed);
    t = stop_ns_->load(std::memory_order_relaxed);
  }
  return now - t >= stop_grace_ns_;
}

void Geometry::kernel(std::span<const geom::SweepRef> part, const Part& info) noexcept {
  const std::int64_t t_start = sched::now_ns();
  const bool shared = pool_ != nullptr && sizer_.predict_ns(info.units) >= pool_min_ns_;
  const geom::SubtractStats st = shared ? pool_->subtract(solid_, part) : solid_.subtract(part);
  const std::int64_t took = sched::now_ns() - t_start;
  if (shared) shared_calls_.store(shared_calls_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  work_.record(took);
  if (timed_) sizer_.observe(info.units, took);
  calls_.store(calls_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  sweeps_.store(sweeps_.load(std::memory_order_relaxed) + part.size(), std::memory_order_relaxed);
  if (log_n_ < log_.size()) {
    KernelCallRecord& r = log_[log_n_];
    r.t_ns = t_start - log_t0_ns_;
    r.dur_us = static_cast<std::uint32_t>(took / 1000);
    r.sweeps = static_cast<std::uint32_t>(part.size());
    r.units = static_cast<float>(info.units);
    r.predicted_us = static_cast<float>(sizer_.predict_ns(info.units) * 1e-3);
    r.cells_clipped = static_cast<std::uint32_t>(st.cells_clipped);
    r.sections = static_cast<std::uint32_t>(st.sections);
    r.cell_vertices = static_cast<std::uint32_t>(info.cell_vertices);
    r.backlog_us = static_cast<std::uint32_t>(std::max<std::int64_t>(0, info.backlog_ns) / 1000);
  }
  if (kernel_delay_ns_ > 0) sched::sleep_until_ns(sched::now_ns() + kernel_delay_ns_);
}

void Geometry::set_kernel_log(std::size_t capacity, std::int64_t t0_ns) {
  log_.assign(capacity, KernelCallRecord{});
  log_n_ = 0;
  log_t0_ns_ = t0_ns;
}

std::int64_t Geometry::backlog_ns(std::int64_t now_ns) const noexcept {
  return lag_done_ < taken_ ? now_ns - rx_[lag_done_] : 0;
}

void Geometry::record_lag(std::span<const motion::SweepInfo> info, std::int64_t now_ns) noexcept {
  for (const motion::SweepInfo& w : info) {
    if (w.channel < 0 || w.channel >= hal::kMaxChannels) continue;
    const auto c = static_cast<std::size_t>(w.channel);
    if (!done_any_[c] || w.last_seq > done_seq_[c]) done_seq_[c] = w.last_seq, done_any_[c] = true;
  }
  // In ring order: an entry of another channel not applied yet holds the later ones back
  // (their lag is recorded later, never earlier than true).
  std::uint32_t n = 0;
  while (lag_done_ < taken_) {
    const std::uint8_t c = chan_[lag_done_];
    if (c >= hal::kMaxChannels || !done_any_[c] || seq_[lag_done_] > done_seq_[c]) break;
    for (std::uint32_t w = 0; w < weight_[lag_done_]; ++w) lag_.record(now_ns - rx_[lag_done_]);
    ++lag_done_;
    ++n;
  }
  call_samples_ = n;
  if (log_n_ < log_.size()) log_[log_n_++].samples = n;
}

void Geometry::set_checks(LiveChecks* checks) noexcept {
  checks_ = checks != nullptr && checks->enabled() ? checks : nullptr;
  stream_.set_fast_step(checks_ != nullptr ? checks_->fast_step_mm() : 0.0);
}

std::size_t Geometry::checked(std::size_t i, std::size_t j) noexcept {
  if (checks_ == nullptr) return j;
  const std::int64_t t0 = sched::now_ns();
  const TickSamples tick{std::span<const std::int64_t>(rx_.data(), taken_), std::span<const std::uint64_t>(seq_.data(), taken_),
                         std::span<const std::uint8_t>(chan_.data(), taken_)};
  const std::size_t end = checks_->check(solid_, i, j, tick);
  check_.record(sched::now_ns() - t0);
  return end;
}

bool Geometry::apply_pieces(const geom::SweepRef& s, int k, const Part& info) noexcept {
  // Pieces at geom::Sweep's own interpolated poses.
  split_.store(split_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  geom::SweepRef piece = s;
  for (int p = 1; p <= k; ++p) {
    if (p > 1 && stop_due()) return false;
    const double t = static_cast<double>(p) / k;
    piece.from = piece.to;
    if (p == 1) piece.from = s.from;
    if (p == k) {
      piece.to = s.to;
    } else {
      piece.to.tip = geom::lerp(s.from.tip, s.to.tip, t);
      const geom::Vec3 a = geom::lerp(s.from.axis, s.to.axis, t);
      const double n = geom::norm(a);
      piece.to.axis = n > 0.0 ? (1.0 / n) * a : s.from.axis;
    }
    Part one = info;
    one.units = info.units / k;
    kernel(std::span<const geom::SweepRef>(&piece, 1), one);
    if (p < k && log_n_ < log_.size()) log_[log_n_++].samples = 0;
  }
  return true;
}

double Geometry::added_units(const geom::SweepRef& s, Part& part) noexcept {
  Reach r;
  part.sections = 0.0;
  if (!reach(s, r)) return 1.0;
  const double levels = r.l1 - r.l0 + 1;
  double cells = 0.0;
  if (stamp_.empty()) {
    cells = levels * (r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1);
  } else {
    const auto regions_x = static_cast<std::size_t>(solid_.regions_x());
    const auto nl = static_cast<std::size_t>(solid_.levels());
    const bool logging = log_n_ < log_.size();
    for (int y = r.y0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x) {
        const std::size_t region = static_cast<std::size_t>(y) * regions_x + static_cast<std::size_t>(x);
        for (int l = r.l0; l <= r.l1; ++l) {
          std::uint32_t& st = stamp_[region * nl + static_cast<std::size_t>(l)];
          if (st == stamp_gen_) continue;
          st = stamp_gen_, cells += 1.0;
          if (!logging) continue;
          for (const geom::Polygon& poly : solid_.cell(static_cast<int>(region), l).polys) {
            part.cell_vertices += static_cast<double>(poly.outer.pts.size());
            for (const geom::Contour& h : poly.holes) part.cell_vertices += static_cast<double>(h.pts.size());
          }
        }
      }
  }
  part.sections = kSectionUnits * levels * r.tilt;
  return part.sections + kCellUnits * cells;
}

std::size_t Geometry::sub_batch(std::span<const geom::SweepRef> batch, std::size_t i, Part& part) noexcept {
  if (++stamp_gen_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0U);
    stamp_gen_ = 1;
  }
  double budget = budget_;
  if (timed_) {
    const std::int64_t now = sched::now_ns();
    part.backlog_ns = backlog_ns(now);
    part.target_ns = sizer_.target_ns(part.backlog_ns);
    budget = sizer_.budget_units(part.target_ns);
  }
  std::size_t j = i;
  for (; j < batch.size(); ++j) {
    Part probe = part;
    const double u = added_units(batch[j], probe);
    if (j > i && part.units + u > budget) break;
    part = probe;
    part.units += u;
    if (j == i) part.first = u, part.first_sections = probe.sections;
    if (j - i < prefix_units_.size()) prefix_units_[j - i] = part.units;
  }
  return j;
}

bool Geometry::apply(std::span<const geom::SweepRef> batch) noexcept {
  const std::span<const motion::SweepInfo> info = stream_.batch_info();
  if (checks_ != nullptr) checks_->begin(batch, info);
  std::size_t i = 0;
  while (i < batch.size()) {
    if (stop_due()) return false;
    Part part;
    std::size_t j = sub_batch(batch, i, part);
    // The checks judge the sub-batch against the stock now; a sweep after the first that
    // meets material ends it (judged again, as the first of the next, once the ones before
    // it are subtracted).
    j = i + geom::batch_end(batch.subspan(i, j - i));  // one turn of a tight loop at a time, tilted runs bounded
    j = checked(i, j);
    if (j - i - 1 < prefix_units_.size()) part.units = prefix_units_[j - i - 1];  // the sweeps it keeps
    // Timed calls cut a sweep only for its sections (a turning tool axis): every piece
    // clips the same cells, so cutting a sweep whose cost is its cells multiplies it.
    const int k = j > i + 1 ? 1
                  : timed_  ? sizer_.pieces(part.first_sections, part.target_ns, kMaxPieces)
                  : part.first > budget_ ? std::min(kMaxPieces, static_cast<int>(std::ceil(part.first / budget_)))
                                         : 1;
    if (k > 1) {  // one sweep over the budget: cut into pieces
      if (!apply_pieces(batch[i], k, part)) return false;
    } else {
      kernel(batch.subspan(i, j - i), part);
    }
    if (info.size() == batch.size()) record_lag(info.subspan(i, j - i), sched::now_ns());
    i = j;
  }
  return true;
}

std::size_t Geometry::tick(std::size_t limit) {
  stream_.clear_batch();
  abandoned_ = false;
  std::size_t n = 0;
  taken_ = 0;
  lag_done_ = 0;
  done_any_ = {};
  limit = std::min(limit, rx_.size());
  tick_units_ = 0.0;
  const double tick_budget = timed_ ? sizer_.budget_units(kTickBudgetNs) : INFINITY;
  while (n < limit && tick_units_ < tick_budget) {
    hal::AxisSample* s = ring_.front();
    if (s == nullptr) break;
    rx_[n] = s->t_rx_ns;  // before take(): a full motion batch is applied (and checked) inside it
    seq_[n] = s->seq;
    chan_[n] = s->channel;
    taken_ = n + 1;
    stream_.take(s->channel, s->seq, s->tool, s->q, s->mask);
    if (s->channel < hal::kMaxChannels) pending_[s->channel] = *s, pending_have_[s->channel] = true;
    if (pos_ != nullptr) pos_->on_sample(*s);
    weight_[n++] = 1 + s->coalesced;
    ring_.pop();
  }
  stream_.flush_all();
  if (!abandoned_ && !stream_.batch().empty()) {
    if (apply(stream_.batch())) batches_.store(batches_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    else abandoned_ = true;
  }
  if (n > 0) {
    std::uint64_t samples = 0;
    for (std::size_t i = 0; i < n; ++i) samples += weight_[i];
    if (abandoned_) {  // a stop cut the batch short: these samples are not (all) in the solid
      unapplied_.store(unapplied_.load(std::memory_order_relaxed) + samples, std::memory_order_relaxed);
      return n;
    }
    last_rx_ns_ = rx_[n - 1];
    last_ = pending_;
    have_ = pending_have_;
    const std::int64_t t = sched::now_ns();
    for (std::size_t i = lag_done_; i < n; ++i)  // what no kernel call completed (poses, rests)
      for (std::uint32_t w = 0; w < weight_[i]; ++w) lag_.record(t - rx_[i]);
    lag_done_ = n;
    applied_.store(applied_.load(std::memory_order_relaxed) + samples, std::memory_order_relaxed);
    coalesced_.store(coalesced_.load(std::memory_order_relaxed) + samples - n, std::memory_order_relaxed);
    if (++ticks_since_volume_ >= 50) publish_volume();
  }
  return n;
}

std::uint64_t Geometry::discard() noexcept {
  std::uint64_t samples = 0;
  while (hal::AxisSample* s = ring_.front()) {
    samples += 1 + s->coalesced;
    ring_.pop();
  }
  unapplied_.store(unapplied_.load(std::memory_order_relaxed) + samples, std::memory_order_relaxed);
  return samples;
}

void Geometry::on_sweep(const geom::SweepRef& s) noexcept {
  if (ex_ != nullptr) ex_->add_path_point(s.to.tip);
  if (timed_) tick_units_ += work_units(s);
}

void Geometry::on_batch_full(std::span<const geom::SweepRef> batch) noexcept {
  if (!abandoned_ && !apply(batch)) abandoned_ = true;
}

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

void Geometry::prime(const std::array<bool, hal::kMaxChannels>& have,
                     const std::array<hal::AxisSample, hal::kMaxChannels>& last) noexcept {
  for (int c = 0; c < hal::kMaxChannels; ++c) {
    if (!have[c]) continue;
    const hal::AxisSample& s = last[c];
    stream_.take(c, s.seq, s.tool, s.q, s.mask);  // a channel's first sample: a pose, no sweep
  }
  stream_.flush_all();
  stream_.clear_batch();
  have_ = pending_have_ = have;
  last_ = pending_ = last;
}

void Geometry::publish_volume() noexcept {
  ticks_since_volume_ = 0;
  removed_.store(solid_.initial_volume_mm3() - solid_.volume_mm3(), std::memory_order_relaxed);
}

}  // namespace lbr::app::live
