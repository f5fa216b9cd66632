// app/src/live/source.hpp — the live source named by `--source` (can:, serial:, replay:,
// emulator:). Setup: throws std::runtime_error on a bad spec, an unknown tool in an emulated
// program, or a device that cannot be found.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "app/profile.hpp"
#include "hal/source.hpp"
#include "nc/emulator.hpp"

namespace lbr::app::live {

// The program line of each sample of an emulated program (emulator:PROGRAM), for the live
// collision events: sample `seq` (1-based; a resumed emulator numbers on from the samples it
// skipped) is the emulator's position at seq × period
// (nc::Emulator::line_at on the source's shared emulator, as live::ProgramPosition does for
// the status bar). line_of() is real-time safe and may be called from any thread.
class ProgramLines {
 public:
  ProgramLines() = default;
  // `emulator` null: no program (other sources); `source`: the program's name for events.
  ProgramLines(std::shared_ptr<const nc::Emulator> emulator, std::string source)
      : emu_(std::move(emulator)), source_(emu_ ? std::move(source) : std::string()) {}
  [[nodiscard]] bool empty() const noexcept { return !emu_; }
  // 0 when unknown (no program, or past its end).
  [[nodiscard]] int line_of(std::uint64_t seq) const noexcept;
  [[nodiscard]] const std::string& source() const noexcept { return source_; }

 private:
  std::shared_ptr<const nc::Emulator> emu_;
  std::string source_;
};

// `skip`: resuming (app/snapshot.hpp), the emulator starts after its first `skip` samples
// (they are computed, not paced) and numbers its samples on from skip + 1; other sources
// ignore it (replay skips with SkipSink). `emulator` (may be null): receives an emulator
// source's emulator, whose plan (line_at, total_time_s) other threads may read while the
// HAL thread samples it.
[[nodiscard]] std::unique_ptr<hal::Source> make_source(const Profile& profile, const std::string& spec, double speed,
                                                      std::uint64_t skip = 0,
                                                      std::shared_ptr<const nc::Emulator>* emulator = nullptr);

// Resuming: drops the samples the resumed solid already holds and forwards the rest. A
// sample is held when its sequence number is at most `through` (a replay numbers its log
// from the start, as the snapshot did), or when its channel's newest applied sample has the
// same or a later sender time (t_src_ns: the SYNC time on CAN, the frame's TS on serial —
// what a --record file stores exactly, so the power-loss catch-up can start anywhere before
// the snapshot's position). HAL thread; real-time safe.
class SkipSink final : public hal::SampleSink {
 public:
  SkipSink(hal::SampleSink& next, std::uint64_t through) : next_(next), through_(through) { src_through_.fill(kNone); }
  // Channel c's newest applied sample (have[c] false: none, nothing of it is skipped by time).
  void skip_by_time(const std::array<bool, hal::kMaxChannels>& have, const std::array<hal::AxisSample, hal::kMaxChannels>& last) noexcept {
    for (int c = 0; c < hal::kMaxChannels; ++c) src_through_[c] = have[c] ? last[c].t_src_ns : kNone;
  }
  void on_samples(std::span<const hal::AxisSample> samples) noexcept override {
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const hal::AxisSample& s = samples[i];
      if (s.seq <= through_ || (s.channel < hal::kMaxChannels && s.t_src_ns <= src_through_[s.channel])) {
        ++skipped_;
        continue;
      }
      next_.on_samples(samples.subspan(i, 1));
    }
  }
  void on_raw(const hal::RawRecord& r) noexcept override { next_.on_raw(r); }
  [[nodiscard]] std::uint64_t skipped() const noexcept { return skipped_; }

 private:
  static constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::min();
  hal::SampleSink& next_;
  std::uint64_t through_;
  std::array<std::int64_t, hal::kMaxChannels> src_through_{};
  std::uint64_t skipped_ = 0;
};

}  // namespace lbr::app::live
