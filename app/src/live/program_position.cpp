#include "live/program_position.hpp"

namespace lbr::app::live {

ProgramPosition::ProgramPosition(std::shared_ptr<const nc::Emulator> emulator, const nc::Toolpath* program,
                                 const nc::EmulatorLimits& limits, double period_s, std::uint64_t seq_base)
    : emu_(std::move(emulator)), period_s_(period_s), seq_base_(seq_base) {
  if (emu_) {
    period_s_ = emu_->period_s();
    total_s_ = emu_->total_time_s();
  } else if (program != nullptr) {
    tracker_.emplace(*program);
    total_s_ = nc::emulated_time_s(*program, limits);
  }
}

void ProgramPosition::on_sample(const hal::AxisSample& s) noexcept {
  if (s.channel != 0) return;
  if (first_seq_ == 0) first_seq_ = s.seq;
  seq_ = s.seq;
  if (emu_) {
    // The generator numbers its samples from 1; sample k of the program ends at k periods.
    line_ = emu_->line_at(static_cast<double>(seq_ + seq_base_) * period_s_);
  } else if (tracker_) {
    nc::AxisVector q{};
    for (std::size_t a = 0; a < q.size() && a < s.q.size(); ++a) q[a] = s.q[a];
    line_ = tracker_->update(q);
  }
}

void ProgramPosition::fill(gfx::LiveStats& st) const noexcept {
  st.total_s = total_s_;
  if (seq_ == 0) return;
  st.machining_s = emu_ ? static_cast<double>(seq_ + seq_base_) * period_s_
                        : static_cast<double>(seq_ - first_seq_ + 1) * period_s_;
  if (line_ > 0) st.program_line = line_;
}

}  // namespace lbr::app::live
