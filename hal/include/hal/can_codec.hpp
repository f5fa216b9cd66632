// hal/can_codec.hpp — classic CAN frames, candump -l log lines, and the CANopen-style
// sample assembler (docs/protocols.md#can):
//   SYNC  COB-ID 0x080, DLC 0 or 1 (1-byte counter 1..sync_counter_max, then 1 again)
//   TPDO  COB-ID 0x180 + node, DLC 4: INT32 LE position [counts]
//                              DLC 6: INT32 LE position + UINT16 LE statusword (bit 3 = fault)
// A sample is complete when every mapped node has answered after a SYNC. Everything here
// is pure (time comes in as arguments), RT-safe and allocation free after construction.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "hal/config.hpp"
#include "hal/sample.hpp"

namespace lbr::hal {

struct CanFrame {
  std::uint32_t id = 0;  // 11-bit (or 29-bit when ext)
  std::uint8_t len = 0;
  bool ext = false, rtr = false, err = false;
  std::array<std::uint8_t, 8> data{};
  std::int64_t t_ns = 0;  // receive time (kernel timestamp or log time) [ns]
};

// Parses one candump -l line "(SEC.USEC) IFACE ID#HEXDATA" (also ID#R or ID#R<DLC> for RTR,
// 8-digit ids are extended, error frames carry the 0x20000000 flag). IFACE: 1..15 printable
// characters; SEC at most kMaxCandumpSec (so the time fits in int64 ns). Pure; false on
// malformed lines.
inline constexpr std::int64_t kMaxCandumpSec = 9'000'000'000;  // year 2255
[[nodiscard]] bool parse_candump_line(std::string_view line, CanFrame& f, std::string_view* iface = nullptr) noexcept;
// Formats a frame the way candump -l does ("(%010lu.%06lu) IFACE ID#DATA"); returns the
// length written, 0 if `out` is too small, the interface name is not one parse_candump_line
// accepts, t_ns is negative or len > 8.
std::size_t format_candump_line(const CanFrame& f, std::string_view iface, std::span<char> out) noexcept;

class CanopenAssembler {
 public:
  // Setup: builds the node table from the mapping. Throws std::invalid_argument on a
  // node outside 1..127, or twice mapped.
  explicit CanopenAssembler(const LiveConfig& cfg);

  // Feeds one frame. Writes completed samples (one per mapped channel) to `out` and
  // returns how many; `now_mono_ns` stamps their t_rx_ns. Faults go to `c`.
  int on_frame(const CanFrame& f, std::int64_t now_mono_ns, std::span<AxisSample, kMaxChannels> out,
               Counters& c) noexcept;

  [[nodiscard]] std::uint64_t syncs() const noexcept { return syncs_; }
  [[nodiscard]] std::uint64_t samples() const noexcept { return samples_; }
  // Cycles that never completed plus cycles skipped by the SYNC counter. The counter repeats
  // every sync_counter_max SYNCs; a silence of more than that (outage, bus-off, reconnect)
  // hides whole turns of it, which the SYNC times reveal: whole turns are added when the
  // time since the last SYNC exceeds the counter's gap by at least 0.9 of a turn.
  [[nodiscard]] std::uint64_t lost() const noexcept { return lost_; }

 private:
  void close_cycle(Counters& c) noexcept;
  void on_sync(const CanFrame& f, Counters& c) noexcept;
  [[nodiscard]] bool accept_tpdo(const CanFrame& f, std::uint32_t node, Counters& c) const noexcept;
  int complete_cycle(std::int64_t now_mono_ns, std::span<AxisSample, kMaxChannels> out, Counters& c) noexcept;
  [[nodiscard]] std::uint64_t hidden_turns(std::int64_t t_ns, std::uint64_t gap) const noexcept;

  LiveConfig cfg_;
  std::array<std::int16_t, 128> node_map_{};  // node → index in cfg_.axes, -1 unmapped
  int mapped_ = 0;
  std::int64_t late_ns_ = 0;
  // Current cycle.
  bool open_ = false;
  std::int64_t sync_t_ = 0;
  std::uint64_t seq_ = 0;
  std::array<std::int32_t, 128> raw_{};
  std::array<bool, 128> answered_{};
  int answered_count_ = 0;
  bool completed_ = false;
  int last_counter_ = -1;
  std::int64_t last_sync_t_ = 0;
  double period_ns_ = 1e6;
  std::uint64_t syncs_ = 0, samples_ = 0, lost_ = 0;
};

// Converts raw counts to a channel sample; shared by the CAN and serial paths.
// Returns false (and counts InvalidValue) when a raw value is the 0x80000000 pattern.
bool map_counts(const AxisMap& m, std::int32_t raw, AxisSample& s, Counters& c) noexcept;

}  // namespace lbr::hal
