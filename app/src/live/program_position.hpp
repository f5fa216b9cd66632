// app/src/live/program_position.hpp — where a live run stands in its program, for the
// status bar (gfx::LiveStats machining_s, total_s, program_line; docs/ui.md "Program line
// and machining time of a run"):
//   emulator source   line and total time from the emulator's own plan (exact);
//   --program given   line by position (nc::LineTracker on channel 0's samples), total time
//                     the emulator's time of the program;
//   neither           machining time only.
// Machining time counts channel 0's samples from the first one the run saw, one sample
// period each (the emulator: from the program's start, resumed runs included).
//
// Setup allocates (the tracker's move list); on_sample() and fill() run on the geometry
// thread and are real-time safe (no allocation, no exceptions, no locks).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "gfx/exchange.hpp"
#include "hal/sample.hpp"
#include "nc/emulator.hpp"
#include "nc/line_tracker.hpp"

namespace lbr::app::live {

class ProgramPosition {
 public:
  // `emulator`: the emulator source's (shared with the HAL thread, which only advances its
  // sample counter; this side reads its plan). `program`: --program's tool path. `period_s`:
  // the live sample period; `seq_base`: samples a resumed emulator skipped.
  ProgramPosition(std::shared_ptr<const nc::Emulator> emulator, const nc::Toolpath* program,
                  const nc::EmulatorLimits& limits, double period_s, std::uint64_t seq_base);

  // Every applied sample (channel 0 counts; others are ignored).
  void on_sample(const hal::AxisSample& s) noexcept;
  void fill(gfx::LiveStats& st) const noexcept;

 private:
  std::shared_ptr<const nc::Emulator> emu_;
  std::optional<nc::LineTracker> tracker_;
  double period_s_ = 0, total_s_ = -1;
  std::uint64_t seq_base_ = 0, first_seq_ = 0, seq_ = 0;
  int line_ = -1;
};

}  // namespace lbr::app::live
