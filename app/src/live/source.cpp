#include "live/source.hpp"

#include <algorithm>
#include <stdexcept>

#include "app/live.hpp"
#include "app/outputs.hpp"
#include "nc/emulator.hpp"

namespace lbr::app::live {

namespace {

// The nc machine emulator at the live sample period, with the tool of every sample.
class EmulatorGenerator final : public hal::SampleGenerator {
 public:
  EmulatorGenerator(const nc::Toolpath& path, const nc::EmulatorLimits& limits, std::uint64_t skip) : emu_(path, limits) {
    nc::Sample s;
    for (std::uint64_t i = 0; i < skip && emu_.next(s); ++i) {
    }
  }
  bool next(std::array<double, hal::kMaxAxes>& q, int& tool) noexcept override {
    nc::Sample s;
    if (!emu_.next(s)) return false;
    for (std::size_t a = 0; a < q.size(); ++a) q[a] = s.axes[a];
    tool = s.tool;
    return true;
  }
  [[nodiscard]] const nc::Emulator& emulator() const noexcept { return emu_; }

 private:
  nc::Emulator emu_;
};

std::unique_ptr<hal::Source> make_emulator_source(const Profile& profile, const std::string& arg, double speed,
                                                  std::uint64_t skip, ProgramLines* lines) {
  const nc::Toolpath path = arg == "demo" ? demo_toolpath() : load_toolpath(arg, profile);
  for (const nc::Segment& sg : path.segments)
    if (sg.tool != 0 && !profile.tooling.tools.count(sg.tool) && !profile.tooling.inserts.count(sg.tool))
      throw std::runtime_error(path.source + ":" + std::to_string(sg.line) + ": tool " + std::to_string(sg.tool) +
                               " is not in the tool table of " + profile.source);
  auto gen = std::make_unique<EmulatorGenerator>(path, live_emulator_limits(profile), skip);
  if (lines != nullptr) *lines = ProgramLines(gen->emulator(), path.source, skip);
  return hal::make_generator_source(std::move(gen), arg, profile.live, speed);
}

}  // namespace

ProgramLines::ProgramLines(const nc::Emulator& emulator, std::string source, std::uint64_t skip)
    : period_s_(emulator.period_s()), total_s_(emulator.total_time_s()), skip_(skip), source_(std::move(source)) {
  for (const nc::Emulator::Plan& p : emulator.plans()) {
    t0_s_.push_back(p.t0_s);
    line_.push_back(p.line);
  }
}

int ProgramLines::line_of(std::uint64_t seq) const noexcept {
  if (t0_s_.empty() || seq == 0) return 0;
  const double t = static_cast<double>(skip_ + seq) * period_s_;
  if (t > total_s_ + period_s_) return 0;
  // The piece that brought the tool there: the last one starting before t.
  const auto it = std::lower_bound(t0_s_.begin(), t0_s_.end(), t);
  const std::size_t i = it == t0_s_.begin() ? 0 : static_cast<std::size_t>(it - t0_s_.begin()) - 1;
  return line_[i];
}

std::unique_ptr<hal::Source> make_source(const Profile& profile, const std::string& spec, double speed,
                                         std::uint64_t skip, ProgramLines* lines) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos || colon + 1 >= spec.size())
    throw std::runtime_error("--source '" + spec + "': expected can:IF, serial:DEV, replay:FILE or emulator:PROGRAM");
  const std::string kind = spec.substr(0, colon), arg = spec.substr(colon + 1);
  if (kind == "can") return hal::make_socketcan_source(arg, profile.live);
  if (kind == "serial") return hal::make_serial_source(arg, profile.live);
  if (kind == "replay") return hal::make_replay_source(arg, profile.live, speed);
  if (kind == "emulator") return make_emulator_source(profile, arg, speed, skip, lines);
  throw std::runtime_error("--source '" + spec + "': unknown kind '" + kind + "' (can, serial, replay, emulator)");
}

}  // namespace lbr::app::live
