// app/src/live/source.hpp — the live source named by `--source` (can:, serial:, replay:,
// emulator:). Setup: throws std::runtime_error on a bad spec, an unknown tool in an emulated
// program, or a device that cannot be found.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "app/profile.hpp"
#include "hal/source.hpp"
#include "nc/emulator.hpp"

namespace lbr::app::live {

// The program line of each sample of an emulated program (emulator:PROGRAM), for the live
// collision events: sample `seq` (1-based, as the emulator source numbers them after
// `skip` skipped samples) is the emulator's position at (skip + seq) × period
// (nc::Emulator::line_at on the source's shared emulator, as live::ProgramPosition does for
// the status bar). line_of() is real-time safe and may be called from any thread.
class ProgramLines {
 public:
  ProgramLines() = default;
  // `emulator` null: no program (other sources); `source`: the program's name for events.
  ProgramLines(std::shared_ptr<const nc::Emulator> emulator, std::string source, std::uint64_t skip)
      : emu_(std::move(emulator)), skip_(skip), source_(emu_ ? std::move(source) : std::string()) {}
  [[nodiscard]] bool empty() const noexcept { return !emu_; }
  // 0 when unknown (no program, or past its end).
  [[nodiscard]] int line_of(std::uint64_t seq) const noexcept;
  [[nodiscard]] const std::string& source() const noexcept { return source_; }

 private:
  std::shared_ptr<const nc::Emulator> emu_;
  std::uint64_t skip_ = 0;
  std::string source_;
};

// `skip`: resuming (app/snapshot.hpp), the emulator starts after its first `skip` samples
// (they are computed, not paced); other sources ignore it (replay skips with SkipSink).
// `emulator` (may be null): receives an emulator source's emulator, whose plan (line_at,
// total_time_s) other threads may read while the HAL thread samples it.
[[nodiscard]] std::unique_ptr<hal::Source> make_source(const Profile& profile, const std::string& spec, double speed,
                                                      std::uint64_t skip = 0,
                                                      std::shared_ptr<const nc::Emulator>* emulator = nullptr);

// Resuming a replay: drops the samples whose sequence number is at most `through` (they
// are in the resumed solid) and forwards the rest. HAL thread; real-time safe.
class SkipSink final : public hal::SampleSink {
 public:
  SkipSink(hal::SampleSink& next, std::uint64_t through) : next_(next), through_(through) {}
  void on_samples(std::span<const hal::AxisSample> samples) noexcept override {
    std::size_t i = 0;
    while (i < samples.size() && samples[i].seq <= through_) ++i;
    if (i < samples.size()) next_.on_samples(samples.subspan(i));
  }
  void on_raw(const hal::RawRecord& r) noexcept override { next_.on_raw(r); }

 private:
  hal::SampleSink& next_;
  std::uint64_t through_;
};

}  // namespace lbr::app::live
