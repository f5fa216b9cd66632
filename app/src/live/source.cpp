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
  EmulatorGenerator(std::shared_ptr<nc::Emulator> emu, std::uint64_t skip) : emu_(std::move(emu)) {
    nc::Sample s;
    for (std::uint64_t i = 0; i < skip && emu_->next(s); ++i) {
    }
  }
  bool next(std::array<double, hal::kMaxAxes>& q, int& tool) noexcept override {
    nc::Sample s;
    if (!emu_->next(s)) return false;
    for (std::size_t a = 0; a < q.size(); ++a) q[a] = s.axes[a];
    tool = s.tool;
    return true;
  }

 private:
  std::shared_ptr<nc::Emulator> emu_;
};

std::unique_ptr<hal::Source> make_emulator_source(const Profile& profile, const std::string& arg, double speed,
                                                  std::uint64_t skip, std::shared_ptr<const nc::Emulator>* shared) {
  const nc::Toolpath path = arg == "demo" ? demo_toolpath() : load_toolpath(arg, profile);
  for (const nc::Segment& sg : path.segments)
    if (sg.tool != 0 && !profile.tooling.tools.count(sg.tool) && !profile.tooling.inserts.count(sg.tool))
      throw std::runtime_error(path.source + ":" + std::to_string(sg.line) + ": tool " + std::to_string(sg.tool) +
                               " is not in the tool table of " + profile.source);
  auto emu = std::make_shared<nc::Emulator>(path, live_emulator_limits(profile));
  if (shared != nullptr) *shared = emu;
  return hal::make_generator_source(std::make_unique<EmulatorGenerator>(std::move(emu), skip), arg, profile.live, speed);
}

}  // namespace

int ProgramLines::line_of(std::uint64_t seq) const noexcept {
  if (!emu_ || seq == 0) return 0;
  const double t = static_cast<double>(skip_ + seq) * emu_->period_s();
  if (t > emu_->total_time_s() + emu_->period_s()) return 0;
  return emu_->line_at(t);
}

std::unique_ptr<hal::Source> make_source(const Profile& profile, const std::string& spec, double speed,
                                         std::uint64_t skip, std::shared_ptr<const nc::Emulator>* emulator) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos || colon + 1 >= spec.size())
    throw std::runtime_error("--source '" + spec + "': expected can:IF, serial:DEV, replay:FILE or emulator:PROGRAM");
  const std::string kind = spec.substr(0, colon), arg = spec.substr(colon + 1);
  if (kind == "can") return hal::make_socketcan_source(arg, profile.live);
  if (kind == "serial") return hal::make_serial_source(arg, profile.live);
  if (kind == "replay") return hal::make_replay_source(arg, profile.live, speed);
  if (kind == "emulator") return make_emulator_source(profile, arg, speed, skip, emulator);
  throw std::runtime_error("--source '" + spec + "': unknown kind '" + kind + "' (can, serial, replay, emulator)");
}

}  // namespace lbr::app::live
