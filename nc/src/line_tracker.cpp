// Nearest move by point-to-segment distance, with a penalty for moves the tool travels
// against: a plunge and the retract over it are the same segment, and only the direction of
// travel tells them apart.
#include "nc/line_tracker.hpp"

#include <algorithm>
#include <cmath>

namespace lbr::nc {

namespace {

constexpr double kAgainstPenaltyMm = 1.0;  // added to the distance of a move travelled backwards
constexpr double kTieMm = 1e-6;            // distances this close count as equal
constexpr std::size_t kMaxWindowMoves = 4096;

double dot3(const std::array<double, 3>& a, const std::array<double, 3>& b) noexcept {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

}  // namespace

LineTracker::LineTracker(const Toolpath& path, double window_mm, std::size_t window_moves, double relock_mm)
    : window_mm_(window_mm), relock_mm_(relock_mm), window_moves_(std::max<std::size_t>(window_moves, 1)) {
  std::array<double, 3> at{path.start[X], path.start[Y], path.start[Z]};
  double s = 0;
  for (const Segment& sg : path.segments) {
    const std::array<double, 3> to{sg.end[X], sg.end[Y], sg.end[Z]};
    if (sg.kind != SegmentKind::Rapid && sg.kind != SegmentKind::Feed) {
      at = to;  // a tool change may move the tip (another tool length)
      continue;
    }
    Move m;
    m.a = at;
    m.d = {to[0] - at[0], to[1] - at[1], to[2] - at[2]};
    m.len2 = dot3(m.d, m.d);
    m.s0 = s;
    m.line = sg.line;
    at = to;
    if (m.len2 <= 0.0) continue;
    s += std::sqrt(m.len2);
    moves_.push_back(m);
  }
}

void LineTracker::reset() noexcept {
  cur_ = 0;
  have_prev_ = false;
  motion_ = {};
}

double LineTracker::score(const Move& m, const std::array<double, 3>& p) const noexcept {
  const std::array<double, 3> w{p[0] - m.a[0], p[1] - m.a[1], p[2] - m.a[2]};
  const double u = std::clamp(dot3(w, m.d) / m.len2, 0.0, 1.0);
  const std::array<double, 3> e{w[0] - u * m.d[0], w[1] - u * m.d[1], w[2] - u * m.d[2]};
  double dist = std::sqrt(dot3(e, e));
  const double mv = dot3(motion_, motion_);
  if (mv > 1e-12 && dot3(motion_, m.d) < -0.5 * std::sqrt(mv * m.len2)) dist += kAgainstPenaltyMm;
  return dist;
}

int LineTracker::update(const AxisVector& q) noexcept {
  if (moves_.empty()) return 0;
  const std::array<double, 3> p{q[X], q[Y], q[Z]};
  if (have_prev_) {
    const std::array<double, 3> m{p[0] - prev_[0], p[1] - prev_[1], p[2] - prev_[2]};
    if (dot3(m, m) > 1e-12) motion_ = m;  // standing still keeps the last direction
  }
  prev_ = p;
  have_prev_ = true;
  double best = score(moves_[cur_], p);
  std::size_t best_i = cur_;
  const double s_end = moves_[cur_].s0 + window_mm_;
  const std::size_t last = std::min(moves_.size(), cur_ + kMaxWindowMoves);
  for (std::size_t i = cur_ + 1; i < last && (i < cur_ + window_moves_ || moves_[i].s0 <= s_end); ++i) {
    const double d = score(moves_[i], p);
    if (d < best - kTieMm) best = d, best_i = i;
  }
  if (best > relock_mm_) {  // lost: the nearest move of the whole program
    ++relocks_;
    for (std::size_t i = 0; i < moves_.size(); ++i) {
      const double d = score(moves_[i], p);
      if (d < best - kTieMm) best = d, best_i = i;
    }
  }
  cur_ = best_i;
  return moves_[cur_].line;
}

}  // namespace lbr::nc
