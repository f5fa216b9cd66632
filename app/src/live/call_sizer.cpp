#include "live/call_sizer.hpp"

#include <algorithm>
#include <cmath>

namespace lbr::app::live {

std::int64_t CallSizer::target_ns(std::int64_t backlog_ns) const noexcept {
  const double grown = static_cast<double>(c_.target_ns) + c_.catch_up * static_cast<double>(std::max<std::int64_t>(0, backlog_ns));
  return static_cast<std::int64_t>(std::clamp(grown, static_cast<double>(c_.target_ns), static_cast<double>(c_.max_ns)));
}

int CallSizer::pieces(double units, std::int64_t target_ns, int max_pieces) const noexcept {
  const double t = static_cast<double>(std::max<std::int64_t>(1, target_ns));
  const double predicted = predict_ns(units);
  if (!(predicted > c_.split_factor * t)) return 1;
  return static_cast<int>(std::clamp(std::ceil(predicted / t), 1.0, static_cast<double>(std::max(1, max_pieces))));
}

void CallSizer::observe(double units, std::int64_t ns) noexcept {
  if (!(units > 0.0) || ns <= 0) return;
  const double rate = static_cast<double>(ns) / units;
  const double w = rate > ns_per_unit_ ? c_.rise : c_.fall;
  ns_per_unit_ = std::clamp(ns_per_unit_ + w * (rate - ns_per_unit_), c_.min_ns_per_unit, c_.max_ns_per_unit);
}

}  // namespace lbr::app::live
