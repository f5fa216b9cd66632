#include "hal/validate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hal/can_codec.hpp"

namespace lbr::hal {

const char* fault_name(Fault f) noexcept {
  switch (f) {
    case Fault::CrcError: return "crc";
    case Fault::LengthError: return "length";
    case Fault::GarbageBytes: return "garbage_bytes";
    case Fault::SeqGap: return "sequence_gap";
    case Fault::SeqDuplicate: return "sequence_duplicate";
    case Fault::MissingTpdo: return "missing_tpdo";
    case Fault::DuplicateTpdo: return "duplicate_tpdo";
    case Fault::LateTpdo: return "late_tpdo";
    case Fault::UnknownId: return "unknown_id";
    case Fault::ErrorFrame: return "error_frame";
    case Fault::DriveFault: return "drive_fault";
    case Fault::InvalidValue: return "invalid_value";
    case Fault::OutOfRange: return "out_of_range";
    case Fault::Jump: return "jump";
    case Fault::Incomplete: return "incomplete";
    case Fault::BusOff: return "bus_off";
    case Fault::Reconnect: return "reconnect";
    case Fault::ReadError: return "read_error";
    case Fault::kCount: break;
  }
  return "?";
}

std::vector<AxisMap> default_axes() {
  std::vector<AxisMap> a;
  const char* names[] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    AxisMap m;
    m.name = names[i];
    m.axis = i;
    m.node = i + 1;
    m.index = i;
    a.push_back(m);
  }
  return a;
}

Validator::Validator(const LiveConfig& cfg) : cfg_(cfg) {
  if (cfg_.axes.empty()) cfg_.axes = default_axes();
  period_s_ = cfg_.period_ms * 1e-3;
  for (const AxisMap& m : cfg_.axes) {
    if (m.channel < 0 || m.channel >= kMaxChannels || m.axis < 0 || m.axis >= kMaxAxes)
      throw std::invalid_argument("axis " + m.name + ": channel or axis out of range");
    Limit& l = lim_[static_cast<std::size_t>(m.channel)][static_cast<std::size_t>(m.axis)];
    l = Limit{true, m.min, m.max, m.max_speed_per_s, 2.0 * std::abs(m.scale)};
  }
}

bool Validator::accept(const AxisSample& s, Counters& c) noexcept {
  if (s.channel >= kMaxChannels) {
    c.add(Fault::OutOfRange);
    ++rejected_;
    return false;
  }
  const auto& lim = lim_[s.channel];
  Ref& ref = ref_[s.channel];
  // Sequence numbers of serial frames are 32-bit on the wire: the step is taken modulo 2^32,
  // so a wrap is one period and not 2^64 − 2^32 of them.
  const double dt = ref.have ? static_cast<double>(static_cast<std::uint32_t>(s.seq - ref.seq)) * period_s_ : 0.0;
  for (int a = 0; a < kMaxAxes; ++a) {
    const Limit& l = lim[static_cast<std::size_t>(a)];
    if (!l.mapped || !(s.mask & (1U << a))) continue;
    const double v = s.q[static_cast<std::size_t>(a)];
    if (!std::isfinite(v) || v < l.min || v > l.max) {
      c.add(Fault::OutOfRange);
      ++rejected_;
      return false;
    }
    if (ref.have && l.speed > 0) {
      const double allowed = l.speed * dt * cfg_.jump_tolerance + l.slack;
      if (std::abs(v - ref.q[static_cast<std::size_t>(a)]) > allowed) {
        c.add(Fault::Jump);
        ++rejected_;
        return false;
      }
    }
  }
  ref.have = true;
  ref.seq = s.seq;
  ref.q = s.q;
  return true;
}

int serial_positions_needed(const LiveConfig& cfg) noexcept {
  int n = 0;
  for (const AxisMap& m : cfg.axes) n = std::max(n, m.index + 1);
  return n;
}

int frame_to_samples(const SerialFrame& f, const LiveConfig& cfg, std::int64_t now_mono_ns,
                     std::span<AxisSample, kMaxChannels> out, Counters& c) noexcept {
  std::array<bool, kMaxChannels> used{};
  std::array<AxisSample, kMaxChannels> tmp{};
  bool ok = true;
  // cfg.axes is never empty: the profile fills default_axes() (no allocation here).
  const AxisMap* begin = cfg.axes.data();
  const std::size_t count = cfg.axes.size();
  if (f.t_us > kMaxSerialTimeUs) {  // a wire value: t_src_ns below must fit in int64
    c.add(Fault::InvalidValue);
    return 0;
  }
  for (std::size_t k = 0; k < count; ++k) {
    const AxisMap& m = begin[k];
    if (m.index >= f.n) {
      c.add(Fault::Incomplete);
      return 0;
    }
    used[static_cast<std::size_t>(m.channel)] = true;
    ok = map_counts(m, f.pos[static_cast<std::size_t>(m.index)], tmp[static_cast<std::size_t>(m.channel)], c) && ok;
  }
  if (!ok) return 0;
  int n = 0;
  for (int ch = 0; ch < kMaxChannels; ++ch) {
    if (!used[static_cast<std::size_t>(ch)]) continue;
    AxisSample s = tmp[static_cast<std::size_t>(ch)];
    s.channel = static_cast<std::uint8_t>(ch);
    s.seq = f.seq;
    s.t_src_ns = static_cast<std::int64_t>(f.t_us) * 1000;
    s.t_rx_ns = now_mono_ns;
    out[static_cast<std::size_t>(n++)] = s;
  }
  return n;
}

}  // namespace lbr::hal
