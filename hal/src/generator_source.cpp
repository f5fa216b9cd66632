// GeneratorSource: samples from an in-process generator (the machine emulator, wired in by
// app/), paced at the live period (speed × real time) or as fast as possible (speed 0).
// With --record, every sample is also written as the serial frame a machine with the
// profile's [[live.axis]] mapping would send (docs/protocols.md#logs), so that
// `run --source replay:LOG` with the same profile plays the emulated run again.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "hal/serial_codec.hpp"
#include "hal/source.hpp"
#include "hal/validate.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::hal {

namespace {

class GeneratorSource final : public Source {
 public:
  GeneratorSource(std::unique_ptr<SampleGenerator> gen, std::string name, const LiveConfig& cfg, double speed,
                  std::uint64_t first_seq)
      : gen_(std::move(gen)), name_(std::move(name)), speed_(speed),
        period_ns_(static_cast<std::int64_t>(cfg.period_ms * 1e6)), seq_(first_seq - 1), axes_(cfg.axes) {
    if (axes_.empty()) axes_ = default_axes();
    LiveConfig c;
    c.axes = axes_;
    positions_ = serial_positions_needed(c);
    if (positions_ < 1 || positions_ > kSerialMaxPositions)
      throw std::invalid_argument("emulator: the [[live.axis]] mapping needs " + std::to_string(positions_) +
                                  " serial positions (1..16) to record the samples");
  }
  void open() override { next_t_ = sched::now_ns(); }
  PollResult poll(int timeout_ms, SampleSink& sink) noexcept override {
    if (done_) return PollResult::End;
    if (speed_ > 0.0) {
      const std::int64_t now = sched::now_ns();
      const std::int64_t limit = now + static_cast<std::int64_t>(timeout_ms) * 1'000'000;
      if (next_t_ > limit) {
        sched::sleep_until_ns(limit);
        return PollResult::Idle;
      }
      sched::sleep_until_ns(next_t_);
      next_t_ += static_cast<std::int64_t>(static_cast<double>(period_ns_) / speed_);
    }
    AxisSample s;
    int tool = -1;
    if (!gen_->next(s.q, tool)) {
      done_ = true;
      return PollResult::End;
    }
    s.tool = static_cast<std::int16_t>(tool < -1 || tool > 32767 ? -1 : tool);
    s.seq = ++seq_;
    s.mask = 0b111111;
    s.t_rx_ns = sched::now_ns();
    // Whole microseconds, strictly increasing: what a recorded frame's TS holds exactly.
    s.t_src_ns = std::max(s.t_rx_ns / 1000 * 1000, last_src_ns_ + 1000);
    last_src_ns_ = s.t_src_ns;
    if (record_) record(s, sink);
    sink.on_samples(std::span<const AxisSample>(&s, 1));
    return PollResult::Data;
  }
  void close() noexcept override {}
  [[nodiscard]] std::string describe() const override { return "emulator:" + name_; }
  [[nodiscard]] bool live() const noexcept override { return speed_ > 0.0; }
  [[nodiscard]] std::uint64_t lost() const noexcept override { return 0; }

 private:
  std::unique_ptr<SampleGenerator> gen_;
  std::string name_;
  double speed_;
  std::int64_t period_ns_, next_t_ = 0;
  std::uint64_t seq_ = 0;
  std::int64_t last_src_ns_ = 0;
  bool done_ = false;
  std::vector<AxisMap> axes_;
  int positions_ = 0;

  // The sample as a serial frame (counts = (value − offset) / scale, the inverse of the
  // decoder's mapping), cut into raw records. RT-safe: no allocation.
  void record(const AxisSample& s, SampleSink& sink) noexcept {
    SerialFrame f;
    f.seq = static_cast<std::uint32_t>(s.seq);
    f.t_us = static_cast<std::uint64_t>(s.t_src_ns / 1000);
    f.n = positions_;
    f.pos.fill(0);
    for (const AxisMap& m : axes_) {
      if (m.channel != 0 || m.axis < 0 || m.axis >= kMaxAxes) continue;
      const double c = std::round((s.q[static_cast<std::size_t>(m.axis)] - m.offset) / m.scale);
      f.pos[static_cast<std::size_t>(m.index)] = static_cast<std::int32_t>(std::clamp(c, -2147483647.0, 2147483647.0));
    }
    std::array<std::uint8_t, kSerialMaxFrame> bytes{};
    const std::size_t n = encode_serial_frame(f, bytes);
    RawRecord rec;
    rec.serial = true;
    rec.t_wall_ns = wall_ns();
    for (std::size_t off = 0; off < n; off += rec.bytes.size()) {
      const std::size_t k = std::min(rec.bytes.size(), n - off);
      std::copy_n(bytes.begin() + static_cast<std::ptrdiff_t>(off), k, rec.bytes.begin());
      rec.len = static_cast<std::uint16_t>(k);
      sink.on_raw(rec);
    }
  }
};

}  // namespace

std::unique_ptr<Source> make_generator_source(std::unique_ptr<SampleGenerator> gen, const std::string& name,
                                              const LiveConfig& cfg, double speed, std::uint64_t first_seq) {
  return std::make_unique<GeneratorSource>(std::move(gen), name, cfg, speed, first_seq);
}

}  // namespace lbr::hal
