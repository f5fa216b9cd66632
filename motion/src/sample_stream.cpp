#include "motion/sample_stream.hpp"

#include <algorithm>

namespace lbr::motion {

SampleStream::SampleStream(const ToolTable& tools, const std::array<kin::Kinematics, kMaxChannels>& kins,
                           int default_tool, double tol_mm, std::size_t batch_capacity, SweepSink& sink)
    : tools_(tools), kins_(kins), default_tool_(tools.find(default_tool)), tol_(tol_mm), sink_(sink) {
  batch_.reserve(batch_capacity);
  info_.reserve(batch_capacity);
  for (Channel& c : ch_) c.run.reserve(kMaxRun + 1);
}

SampleStream::ChannelState SampleStream::channel(int i) const noexcept {
  if (i < 0 || i >= kMaxChannels) return {};
  const Channel& c = ch_[static_cast<std::size_t>(i)];
  return {c.have && !c.run.empty(), c.tool, c.run.empty() ? geom::Pose{} : c.run.back()};
}

void SampleStream::push(const Channel& c, const geom::Pose& from, const geom::Pose& to) noexcept {
  if (!c.tool.cuts()) return;
  geom::SweepRef r;
  r.shape = c.tool.shape;
  r.turning = c.tool.turning;
  r.from = from;
  r.to = to;
  r.id = static_cast<geom::MoveId>(c.seq & 0xFFFFFFFFU);
  last_id_ = r.id;
  sink_.on_sweep(r);
  if (batch_.size() == batch_.capacity()) {  // capacity reserved at start-up: empty it now
    sink_.on_batch_full(batch_);
    clear_batch();
  }
  batch_.push_back(r);
  const auto channel = static_cast<int>(&c - ch_.data());
  info_.push_back({c.run_first, c.run_last, channel, c.tool.number, c.run_fast});
}

bool SampleStream::fast(const geom::Vec3& a, const geom::Vec3& b, std::uint64_t dseq) const noexcept {
  return fast_step_mm_ > 0.0 && geom::norm(b - a) > fast_step_mm_ * static_cast<double>(std::max<std::uint64_t>(dseq, 1));
}

void SampleStream::flush(Channel& c) noexcept {
  if (c.run.size() < 2) return;
  push(c, c.run.front(), c.run.back());
  const geom::Pose end = c.run.back();
  c.run.clear();
  c.run.push_back(end);
}

void SampleStream::flush_all() noexcept {
  for (Channel& c : ch_) flush(c);
}

void SampleStream::forget_poses() noexcept {
  for (Channel& c : ch_) {
    flush(c);
    c.have = false;
  }
}

// The pending run starts afresh at axis values q with the channel's current tool.
void SampleStream::restart(Channel& c, const kin::Kinematics& k, const nc::AxisVector& q) noexcept {
  c.run.clear();
  c.run.push_back(kin::tool_pose(k, q, c.tool.mount, c.tool.length_mm));
}

// Rotary axes moved the tool along a curve: n chords within the tolerance.
void SampleStream::substeps(Channel& c, const kin::Kinematics& k, const nc::AxisVector& q, int n,
                            std::uint64_t dseq) noexcept {
  flush(c);
  const ToolRef& t = c.tool;
  geom::Pose from = c.run.back();
  c.run_first = c.run_last = c.seq;  // every chord covers this one sample
  c.run_fast = fast(from.tip, kin::tool_pose(k, q, t.mount, t.length_mm).tip, dseq);
  for (int i = 1; i <= n; ++i) {
    nc::AxisVector qi = q;
    if (i < n)
      for (int a = 0; a < nc::kAxes; ++a) qi[a] = c.q[a] + (q[a] - c.q[a]) * i / n;
    const geom::Pose to = kin::tool_pose(k, qi, t.mount, t.length_mm);
    push(c, from, to);
    from = to;
  }
  c.run.clear();
  c.run.push_back(from);
  c.q = q;
}

// A straight move: extend the pending run when it stays straight, else cut it first.
void SampleStream::extend(Channel& c, const kin::Kinematics& k, const nc::AxisVector& q, std::uint64_t dseq) noexcept {
  const geom::Pose p = kin::tool_pose(k, q, c.tool.mount, c.tool.length_mm);
  const bool step_fast = fast(c.run.back().tip, p.tip, dseq);
  if (c.run.size() >= 2) {
    // Replace the run's sweep run[0]→last by run[0]→p only if every sample of the run stays
    // within the tolerance of the longer sweep (geom::pose_deviation_mm: with a fixed tool
    // axis the tip's distance from the segment; while a rotary axis turns, also the turn of
    // the axis times the tool's reach, so a 5-axis stream merges where its motion is close
    // to linear) and the step is of the run's kind (fast or not).
    bool straight = c.run.size() < kMaxRun && step_fast == c.run_fast;
    for (std::size_t i = 1; straight && i < c.run.size(); ++i)
      straight = geom::pose_deviation_mm(c.run[0], p, c.run[i], c.tool.reach_mm) <= tol_;
    if (!straight) flush(c);
  }
  if (c.run.size() == 1) c.run_first = c.seq, c.run_fast = step_fast;
  c.run_last = c.seq;
  c.run.push_back(p);
  c.q = q;
}

void SampleStream::take(int channel, std::uint64_t seq, int tool, std::span<const double> sample,
                        std::uint32_t mask) noexcept {
  if (channel < 0 || channel >= kMaxChannels) return;
  Channel& c = ch_[static_cast<std::size_t>(channel)];
  const kin::Kinematics& k = kins_[static_cast<std::size_t>(channel)];
  nc::AxisVector q = c.q;
  for (int a = 0; a < nc::kAxes && a < static_cast<int>(sample.size()); ++a)
    if (mask & (1U << a)) q[a] = sample[static_cast<std::size_t>(a)];
  const std::uint64_t dseq = seq - c.seq;
  c.seq = seq;
  const ToolRef t = tool >= 0 ? tools_.find(tool) : default_tool_;
  if (c.have && !t.same(c.tool)) {  // tool change: the pending run belongs to the old tool,
    flush(c);                       // and the new one starts where this sample puts it (as
    c.tool = t;                     // nc::sampled_toolpath's ToolChange does), not with a
    c.q = q;                        // sweep from where the old one was
    restart(c, k, q);
    return;
  }
  if (!c.have) {  // first sample: where the tool is; nothing to cut yet
    c.have = true;
    c.tool = t;
    c.q = q;
    restart(c, k, q);
    return;
  }
  if (q == c.q) return;  // standing still
  const int n = c.tool.cuts()
                    ? kin::substeps(k, c.q, q, c.tool.mount, c.tool.length_mm, c.tool.reach_mm, tol_)
                    : 1;
  if (n > 1) substeps(c, k, q, n, dseq);
  else extend(c, k, q, dseq);
}

}  // namespace lbr::motion
