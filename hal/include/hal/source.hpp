// hal/source.hpp — one interface for every live source (docs/protocols.md).
//
// Lifecycle: construct → open() (setup: may throw, allocates, opens devices) → poll()
// repeatedly on the HAL thread (RT-safe: never throws, never allocates, blocks only on its
// own device or pacing clock) → close(). Faults are counters, never exceptions.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "hal/can_codec.hpp"
#include "hal/config.hpp"
#include "hal/sample.hpp"

namespace lbr::hal {

// Raw input as received, for --record (candump -l lines, docs/protocols.md#logs).
struct RawRecord {
  std::int64_t t_wall_ns = 0;  // CLOCK_REALTIME receive time
  bool serial = false;
  CanFrame frame;              // CAN
  std::uint16_t len = 0;       // serial: bytes used
  std::array<std::uint8_t, 64> bytes{};
};

class SampleSink {
 public:
  // Called on the HAL thread with decoded (not yet validated) samples. RT-safe.
  virtual void on_samples(std::span<const AxisSample> samples) noexcept = 0;
  // Called with raw input when recording is enabled. RT-safe.
  virtual void on_raw(const RawRecord& /*r*/) noexcept {}

 protected:
  ~SampleSink() = default;
};

// Input whose shape does not match the profile's [[live.axis]] mapping: serial frames with
// fewer positions than the highest mapped index needs. Every such frame is only counted as
// `incomplete`; this says why, for a warning the operator sees (issue 19).
struct InputMismatch {
  int positions_carried = 0;  // by the latest frame that was too short; 0: none seen
  int positions_needed = 0;   // highest mapped index + 1
};

enum class PollResult {
  Data,   // input was processed (samples may or may not have been produced)
  Idle,   // timeout without input
  End,    // the source has ended (replay/emulator finished); poll no further
  Error,  // transient failure (counted); the source retries on later polls
};

class Source {
 public:
  virtual ~Source() = default;
  virtual void open() = 0;
  // Waits at most timeout_ms for input, decodes what arrived, hands samples to `sink`.
  virtual PollResult poll(int timeout_ms, SampleSink& sink) noexcept = 0;
  virtual void close() noexcept = 0;
  [[nodiscard]] virtual std::string describe() const = 0;
  // False for sources that may wait when the ring is full (replay as fast as possible,
  // emulator without pacing): the pipeline then applies back-pressure instead of dropping.
  [[nodiscard]] virtual bool live() const noexcept { return true; }
  // Samples known to be lost before the ring (sequence gaps, incomplete cycles).
  [[nodiscard]] virtual std::uint64_t lost() const noexcept = 0;
  [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
  void set_recording(bool on) noexcept { record_ = on; }
  // The latest mismatch between input and mapping (any thread; relaxed atomics).
  [[nodiscard]] InputMismatch input_mismatch() const noexcept {
    return {short_frame_positions_.load(std::memory_order_relaxed), positions_needed_.load(std::memory_order_relaxed)};
  }

 protected:
  // Decoders call this (HAL thread, RT-safe) for a frame with too few positions.
  void note_short_frame(int carried, int needed) noexcept {
    positions_needed_.store(needed, std::memory_order_relaxed);
    short_frame_positions_.store(carried, std::memory_order_relaxed);
  }
  Counters counters_;
  bool record_ = false;

 private:
  std::atomic<int> short_frame_positions_{0}, positions_needed_{0};
};

// Generates positions for GeneratorSource (the machine emulator, app/). Called on the
// HAL thread: must be RT-safe. Returns false at the end of the program.
class SampleGenerator {
 public:
  virtual ~SampleGenerator() = default;
  // Next position and the tool in the spindle (-1 if unknown).
  virtual bool next(std::array<double, kMaxAxes>& q, int& tool) noexcept = 0;
};

// Factories. `speed` applies to replay (1 = real time, 0 = as fast as possible) and to the
// generator (same meaning). Throw std::runtime_error / std::invalid_argument on bad specs.
// Replay: `from_byte` starts reading the log there (a line boundary; power-loss catch-up
// replays the --record file from a snapshot's offset); errors then name lines counted from it.
// Generator: its samples are numbered first_seq, first_seq + 1, … (a resumed emulator goes on
// with the numbers of the samples it skipped), and its sender times (t_src_ns) are whole
// microseconds, strictly increasing, so that a --record file holds them exactly.
[[nodiscard]] std::unique_ptr<Source> make_serial_source(const std::string& device, const LiveConfig& cfg);
[[nodiscard]] std::unique_ptr<Source> make_socketcan_source(const std::string& iface, const LiveConfig& cfg);
[[nodiscard]] std::unique_ptr<Source> make_replay_source(const std::string& file, const LiveConfig& cfg, double speed,
                                                         std::uint64_t from_byte = 0);
[[nodiscard]] std::unique_ptr<Source> make_generator_source(std::unique_ptr<SampleGenerator> gen, const std::string& name,
                                                            const LiveConfig& cfg, double speed, std::uint64_t first_seq = 1);

// CLOCK_REALTIME [ns].
[[nodiscard]] std::int64_t wall_ns() noexcept;

}  // namespace lbr::hal
