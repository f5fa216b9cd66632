#include "live/ring_sink.hpp"

#include <algorithm>
#include <cmath>

namespace lbr::app::live {

namespace {

// Distance of p from the segment a–b in X Y Z [mm] (motion::SampleStream's rule).
double dist_to_segment(const std::array<double, 3>& p, const std::array<double, 3>& a,
                       const std::array<double, 3>& b) noexcept {
  double d[3], w[3], dd = 0.0, wd = 0.0;
  for (int i = 0; i < 3; ++i) {
    d[i] = b[static_cast<std::size_t>(i)] - a[static_cast<std::size_t>(i)];
    w[i] = p[static_cast<std::size_t>(i)] - a[static_cast<std::size_t>(i)];
    dd += d[i] * d[i];
    wd += w[i] * d[i];
  }
  const double t = dd > 0.0 ? std::clamp(wd / dd, 0.0, 1.0) : 0.0;
  double s = 0.0;
  for (int i = 0; i < 3; ++i) s += (w[i] - t * d[i]) * (w[i] - t * d[i]);
  return std::sqrt(s);
}

std::array<double, 3> xyz(const std::array<double, hal::kMaxAxes>& q) noexcept { return {q[0], q[1], q[2]}; }

bool same_rotary(const std::array<double, hal::kMaxAxes>& a, const std::array<double, hal::kMaxAxes>& b) noexcept {
  for (std::size_t i = 3; i < a.size(); ++i)
    if (a[i] != b[i]) return false;
  return true;
}

}  // namespace

RingSink::RingSink(sched::SpscRing<hal::AxisSample>& ring, sched::SpscRing<hal::RawRecord>* rec,
                   const hal::LiveConfig& cfg, bool backpressure, const std::atomic<bool>& stop,
                   std::size_t overflow_capacity)
    : ring_(ring),
      rec_(rec),
      validator_(cfg),
      backpressure_(backpressure),
      stop_(stop),
      fold_tol_mm_(0.5 * cfg.merge_tolerance_mm) {
  buf_.resize(overflow_capacity > 0 ? overflow_capacity : 16 * ring.capacity());
}

void RingSink::on_samples(std::span<const hal::AxisSample> samples) noexcept {
  for (const hal::AxisSample& s : samples) {
    bump(received_);
    if (!validator_.accept(s, counters_)) {
      bump(rejected_);
      continue;
    }
    take(s);
  }
}

void RingSink::take(const hal::AxisSample& s) noexcept {
  Channel* c = s.channel < ch_.size() ? &ch_[s.channel] : nullptr;
  Axes q{};
  if (c != nullptr) {
    q = c->q;
    for (std::size_t a = 0; a < q.size(); ++a)
      if (s.mask & (1U << a)) q[a] = s.q[a];
  }
  if (backpressure_) {
    // Not a live source: wait for room rather than hold or drop (never counts an overrun).
    while (ring_.size() >= ring_.capacity()) {
      if (stop_.load(std::memory_order_relaxed)) return;
      sched::sleep_until_ns(sched::now_ns() + 100'000);
    }
  } else if (!pump() || ring_.size() >= ring_.capacity()) {
    // Behind: hold it (folded into the channel's newest held sample when that is exact).
    if (c == nullptr || !try_fold(*c, s, q)) hold(c, s);
    if (c != nullptr) {
      c->have = true;
      c->q = q;
      c->tool = s.tool;
    }
    return;
  }
  // Room, and nothing held before it: straight into the ring (cannot fail: one producer).
  (void)ring_.try_push(s);
  if (c != nullptr) {
    c->have = true;
    c->q = q;
    c->tool = s.tool;
    c->open = false;
  }
}

bool RingSink::try_fold(Channel& c, const hal::AxisSample& s, const Axes& q) noexcept {
  if (!c.have || !c.open || c.open_at < head_ || c.folded >= kMaxFold || s.tool != c.tool) return false;
  if (!same_rotary(c.start, c.q) || !same_rotary(c.q, q)) return false;
  // The held sample's end point c.q becomes an intermediate point of the move start → q.
  const std::array<double, 3> a = xyz(c.start), b = xyz(q);
  if (dist_to_segment(xyz(c.q), a, b) > fold_tol_mm_) return false;
  for (std::uint32_t i = 0; i < c.folded; ++i)
    if (dist_to_segment(c.tips[i], a, b) > fold_tol_mm_) return false;
  c.tips[c.folded++] = xyz(c.q);
  hal::AxisSample& e = buf_[static_cast<std::size_t>(c.open_at % buf_.size())];
  for (std::size_t i = 0; i < e.q.size(); ++i)
    if (s.mask & (1U << i)) e.q[i] = s.q[i];
  e.mask = static_cast<std::uint8_t>(e.mask | s.mask);
  e.seq = s.seq;
  e.t_src_ns = s.t_src_ns;  // t_rx_ns stays the oldest one's: lag is counted from it
  e.coalesced += 1 + s.coalesced;
  bump(coalesced_, 1 + s.coalesced);
  return true;
}

void RingSink::hold(Channel* c, const hal::AxisSample& s) noexcept {
  if (tail_ - head_ >= buf_.size()) {  // overflow full as well: the only loss left
    bump(overflow_overruns_, 1 + s.coalesced);
    if (c != nullptr) c->open = false;  // the next sample must not fold across the gap
    return;
  }
  if (c != nullptr) {
    c->open = c->have;  // the first sample of a channel has no start to fold along
    c->open_at = tail_;
    c->start = c->q;
    c->folded = 0;
  }
  buf_[static_cast<std::size_t>(tail_ % buf_.size())] = s;
  ++tail_;
  held_.store(tail_ - head_, std::memory_order_relaxed);
  if (tail_ - head_ > overflow_hw_.load(std::memory_order_relaxed))
    overflow_hw_.store(tail_ - head_, std::memory_order_relaxed);
}

bool RingSink::pump() noexcept {
  if (head_ == tail_) return true;
  std::size_t room = ring_.capacity() - std::min(ring_.capacity(), ring_.size());
  for (; room > 0 && head_ < tail_; --room, ++head_) {
    const hal::AxisSample& e = buf_[static_cast<std::size_t>(head_ % buf_.size())];
    if (e.channel < ch_.size() && ch_[e.channel].open && ch_[e.channel].open_at == head_) ch_[e.channel].open = false;
    (void)ring_.try_push(e);  // room was counted: cannot fail
  }
  held_.store(tail_ - head_, std::memory_order_relaxed);
  return head_ == tail_;
}

std::uint64_t RingSink::abandon() noexcept {
  std::uint64_t n = 0;
  for (; head_ < tail_; ++head_) n += 1 + buf_[static_cast<std::size_t>(head_ % buf_.size())].coalesced;
  held_.store(0, std::memory_order_relaxed);
  for (Channel& c : ch_) c.open = false;
  return n;
}

}  // namespace lbr::app::live
