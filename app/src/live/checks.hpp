// app/src/live/checks.hpp — the collision checks of `lbrsim run` (docs/verification.md#live):
// verify::CollisionChecker, the one used by `lbrsim batch`, on the sweeps the geometry
// thread applies, each judged against the stock as it is at that moment.
//
// The geometry thread calls begin() with a batch of the motion stream, then, before each
// kernel call, check() on the sub-batch it is about to subtract: check() returns where the
// kernel must stop (a sweep after the first that meets material is judged again once the
// sweeps before it are in the stock), exactly as the batch runner does.
//
// Rapids: a live stream has no program, so a sweep is a rapid when every sample step of it
// is faster than the profile's max cutting feed (motion::SweepInfo::fast; the threshold is
// rapid_threshold_mm_per_min()).
//
// Real-time contract: the move list, the rapid flags, the event list and the log ring are
// allocated at setup; begin() and the queries never allocate. check() allocates inside
// Clipper (verify::IntrusionProbe), bounded by the sweeps of the sub-batch, like the kernel
// itself. Once the event list is full (kMaxEvents) new events are counted, not stored.
// Latency: receive time of the offending sweep's first sample → the event raised.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "app/outputs.hpp"
#include "app/profile.hpp"
#include "geom/lbr_solid.hpp"
#include "gfx/exchange.hpp"
#include "live/source.hpp"
#include "motion/sample_stream.hpp"
#include "motion/tool_table.hpp"
#include "sched/latency_stats.hpp"
#include "sched/spsc_ring.hpp"
#include "verify/collision.hpp"

namespace lbr::app::live {

// A raised event for the log (the control thread writes it): plain values.
struct EventNote {
  verify::EventKind kind = verify::EventKind::RapidIntoMaterial;
  std::uint64_t sample = 0;  // first offending sample
  int line = 0;              // program line (emulated programs), else 0
  int tool = 0, channel = 0;
  geom::Vec3 position;
  double volume_mm3 = 0.0, depth_mm = 0.0;
  double latency_ms = 0.0;   // sample received → event raised
};

// Where the samples of the current tick came from: ring entry i had sequence seq[i] on
// channel channel[i] and was received at rx_ns[i] (the geometry thread's tick buffers).
struct TickSamples {
  std::span<const std::int64_t> rx_ns;
  std::span<const std::uint64_t> seq;
  std::span<const std::uint8_t> channel;
};

class LiveChecks {
 public:
  static constexpr std::size_t kMaxEvents = 4096;
  static constexpr int kShownAlarms = kShownEventAlarms;  // newest events shown in the status bar
  // Kinds one sweep can raise at once: rapid, plunge, shank, holder, spindle nose.
  static constexpr std::size_t kKindsPerSweep = 5;

  // `batch_capacity`: the motion stream's batch size. `lines` (may be empty): program lines
  // of an emulated program's samples. Setup: allocates.
  LiveChecks(const Profile& profile, const motion::ToolTable& tools, std::size_t batch_capacity, ProgramLines lines);

  [[nodiscard]] bool enabled() const noexcept { return enabled_; }
  // Tip travel per sample above which a step is fast (SampleStream::set_fast_step) [mm].
  [[nodiscard]] double fast_step_mm() const noexcept { return fast_step_mm_; }
  [[nodiscard]] double rapid_threshold_mm_per_min() const noexcept { return rapid_mm_per_min_; }

  // A new batch of the motion stream (sweeps and what the stream knows of them).
  void begin(std::span<const geom::SweepRef> batch, std::span<const motion::SweepInfo> info) noexcept;
  // Checks sweeps [from, to) of the batch against `solid`, the stock just before sweep
  // `from`; returns the end of the prefix the kernel may subtract now (CollisionChecker::check).
  std::size_t check(const geom::LbrSolid& solid, std::size_t from, std::size_t to, const TickSamples& tick);

  // The newest events as status-bar alarms (geometry thread, no allocation).
  void fill_alarms(gfx::LiveStats& stats) const noexcept;
  // Raised events for the log, oldest first (one consumer thread).
  bool pop_note(EventNote& out) noexcept;

  // Read after the geometry thread has ended: the events (with the program name of an
  // emulated program), events not stored for lack of room, the latency histogram.
  [[nodiscard]] std::vector<verify::Event> events() const;
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }
  // The emulated program's name ("" for other sources).
  [[nodiscard]] const std::string& program() const noexcept { return lines_.source(); }
  [[nodiscard]] const sched::LatencyHistogram& latency() const noexcept { return latency_; }

 private:
  // After a check that found something in sweep k: sample numbers, lines, times, the note.
  void record(std::size_t k, std::size_t events_before, const std::array<double, kKindsPerSweep>& volume_before,
              std::vector<verify::Event>& list, const TickSamples& tick);
  [[nodiscard]] std::int64_t rx_of(const motion::SweepInfo& info, const TickSamples& tick) const noexcept;

  bool enabled_ = false;
  double rapid_mm_per_min_ = 0.0, fast_step_mm_ = 0.0, period_s_ = 0.0;
  verify::MoveIndex index_;  // empty: a live stream has no program
  verify::CollisionChecker checker_;
  ProgramLines lines_;
  std::vector<motion::TimedSweep> moves_;
  std::vector<motion::SweepInfo> info_;
  std::vector<std::uint8_t> rapid_;
  std::vector<verify::Event> events_, overflow_;
  std::uint64_t dropped_ = 0;
  sched::LatencyHistogram latency_;
  sched::SpscRing<EventNote> notes_{256};
};

}  // namespace lbr::app::live
