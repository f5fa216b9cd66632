// GeneratorSource: samples from an in-process generator (the machine emulator, wired in by
// app/), paced at the live period (speed × real time) or as fast as possible (speed 0).
#include "hal/source.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::hal {

namespace {

class GeneratorSource final : public Source {
 public:
  GeneratorSource(std::unique_ptr<SampleGenerator> gen, std::string name, const LiveConfig& cfg, double speed)
      : gen_(std::move(gen)), name_(std::move(name)), speed_(speed),
        period_ns_(static_cast<std::int64_t>(cfg.period_ms * 1e6)) {}
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
    s.t_src_ns = s.t_rx_ns;
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
  bool done_ = false;
};

}  // namespace

std::unique_ptr<Source> make_generator_source(std::unique_ptr<SampleGenerator> gen, const std::string& name,
                                              const LiveConfig& cfg, double speed) {
  return std::make_unique<GeneratorSource>(std::move(gen), name, cfg, speed);
}

}  // namespace lbr::hal
