// hal/sample.hpp — what the HAL hands to the geometry thread, and the error counters.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace lbr::hal {

inline constexpr int kMaxAxes = 6;      // X Y Z [mm], A B C [deg] (nc::Axis order)
inline constexpr int kMaxChannels = 4;  // independent tool carriers

// One decoded, validated set of axis positions of one channel. Trivially copyable.
struct AxisSample {
  std::uint64_t seq = 0;         // source sequence: SYNC count (CAN) or frame sequence (serial)
  std::int64_t t_rx_ns = 0;      // receive time, CLOCK_MONOTONIC [ns]; lag = now − t_rx_ns
  std::int64_t t_src_ns = 0;     // sender timestamp [ns] (serial) or SYNC time (CAN)
  std::uint8_t channel = 0;
  std::uint8_t mask = 0;         // bit a set: q[a] holds a value
  std::int16_t tool = -1;        // tool in the spindle when the source knows it (emulator); -1: not reported
  // Samples folded into this one by the HAL side when the geometry thread was behind
  // (app/src/live/ring_sink.hpp: exact coalescing of collinear samples); 0 normally.
  // t_rx_ns is then the receive time of the oldest of them.
  std::uint32_t coalesced = 0;
  std::array<double, kMaxAxes> q{};  // X Y Z [mm], A B C [deg]
};

// Every fault the HAL detects has a counter; the names are the keys of
// metrics.json "decode_errors" (docs/protocols.md#counters).
enum class Fault : int {
  CrcError,          // serial: CRC-16/CCITT-FALSE mismatch
  LengthError,       // serial: LEN not 12 + 4N; CAN: DLC not 4 or 6 (TPDO) / not 0 or 1 (SYNC)
  GarbageBytes,      // serial: bytes skipped while hunting for a sync pattern
  SeqGap,            // samples missing according to the sequence number / SYNC counter
  SeqDuplicate,      // serial: repeated or older sequence number
  MissingTpdo,       // CAN: mapped node did not answer before the next SYNC
  DuplicateTpdo,     // CAN: second TPDO of a node within one SYNC cycle
  LateTpdo,          // CAN: TPDO after the late window, or with no SYNC open
  UnknownId,         // CAN: frame id that is neither SYNC nor a mapped TPDO
  ErrorFrame,        // CAN: error frame reported by the controller
  DriveFault,        // CAN: statusword fault bit (bit 3) set (position still used)
  InvalidValue,      // INT32_MIN (0x80000000), the "no value" pattern
  OutOfRange,        // position outside the axis travel limits
  Jump,              // position change faster than the axis maximum speed
  Incomplete,        // serial: frame carries fewer positions than the mapping needs
  BusOff,            // CAN: bus-off / interface down events
  Reconnect,         // source reopened after a failure
  ReadError,         // read()/recv() failures
  kCount
};
inline constexpr int kFaultKinds = static_cast<int>(Fault::kCount);
[[nodiscard]] const char* fault_name(Fault f) noexcept;

// Single-writer counters (the HAL thread); readable from any thread.
class Counters {
 public:
  void add(Fault f, std::uint64_t n = 1) noexcept {
    auto& c = v_[static_cast<std::size_t>(f)];
    c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t get(Fault f) const noexcept { return v_[static_cast<std::size_t>(f)].load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t total() const noexcept {
    std::uint64_t s = 0;
    for (const auto& c : v_) s += c.load(std::memory_order_relaxed);
    return s;
  }

 private:
  std::array<std::atomic<std::uint64_t>, kFaultKinds> v_{};
};

}  // namespace lbr::hal
