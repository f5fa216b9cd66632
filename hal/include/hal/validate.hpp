// hal/validate.hpp — plausibility checks between decoding and the ring, and the mapping of
// serial frames to channel samples. RT-safe and allocation free after construction.
#pragma once

#include <array>
#include <span>

#include "hal/config.hpp"
#include "hal/sample.hpp"
#include "hal/serial_codec.hpp"

namespace lbr::hal {

// Rejects samples with a position outside the travel limits (OutOfRange) or a change
// faster than the axis maximum speed allows (Jump): allowed step = max_speed × Δt ×
// jump_tolerance + 2 counts, Δt = (seq − seq of the last accepted sample) × period, so
// bursts of buffered frames do not look like jumps. A rejected sample leaves the reference
// unchanged.
class Validator {
 public:
  explicit Validator(const LiveConfig& cfg);
  [[nodiscard]] bool accept(const AxisSample& s, Counters& c) noexcept;
  [[nodiscard]] std::uint64_t rejected() const noexcept { return rejected_; }

 private:
  struct Ref {
    bool have = false;
    std::uint64_t seq = 0;
    std::array<double, kMaxAxes> q{};
  };
  struct Limit {
    bool mapped = false;
    double min = 0, max = 0, speed = 0, slack = 0;
  };
  LiveConfig cfg_;
  std::array<std::array<Limit, kMaxAxes>, kMaxChannels> lim_{};
  std::array<Ref, kMaxChannels> ref_{};
  double period_s_ = 0.001;
  std::uint64_t rejected_ = 0;
};

// Largest serial timestamp accepted [µs] (about 292 000 years): t_us × 1000 fits in int64.
inline constexpr std::uint64_t kMaxSerialTimeUs = 9'223'372'036'854'775ULL;

// Serial frame → one sample per mapped channel (mapping by AxisMap::index). Returns the
// number written; 0 with Incomplete counted when the frame has too few positions, or with
// InvalidValue counted when a mapped position holds 0x80000000 or t_us exceeds
// kMaxSerialTimeUs. cfg.axes must not be empty.
int frame_to_samples(const SerialFrame& f, const LiveConfig& cfg, std::int64_t now_mono_ns,
                     std::span<AxisSample, kMaxChannels> out, Counters& c) noexcept;

// Positions a serial frame must carry for cfg.axes: the highest mapped index + 1. RT-safe.
[[nodiscard]] int serial_positions_needed(const LiveConfig& cfg) noexcept;

}  // namespace lbr::hal
