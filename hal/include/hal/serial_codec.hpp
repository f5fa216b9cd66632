// hal/serial_codec.hpp — the serial frame format (docs/protocols.md#serial):
//
//   offset  size  field
//   0       2     sync 0xA5 0x5A
//   2       1     LEN = 12 + 4·N, N = 1..16 positions
//   3       4     SEQ  u32 little endian, +1 per frame (wraps)
//   7       8     TS   u64 little endian, sender timestamp [µs]
//   15      4·N   positions, INT32 little endian [counts]; 0x80000000 = no value
//   3+LEN   2     CRC-16/CCITT-FALSE over bytes 2 .. 2+LEN (LEN byte .. last position),
//                 big endian (high byte first)
//
// Decoding is a pure function over bytes; SerialStreamDecoder adds the resynchronising
// buffer and the sequence checks. Everything here is RT-safe and allocation free.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "hal/sample.hpp"

namespace lbr::hal {

inline constexpr std::uint8_t kSerialSync0 = 0xA5, kSerialSync1 = 0x5A;
inline constexpr int kSerialMaxPositions = 16;
inline constexpr std::size_t kSerialHeader = 3;   // sync + LEN
inline constexpr std::size_t kSerialFixed = 12;   // SEQ + TS
inline constexpr std::size_t kSerialMaxFrame = kSerialHeader + kSerialFixed + 4 * kSerialMaxPositions + 2;
inline constexpr std::int32_t kNoValue = INT32_MIN;

struct SerialFrame {
  std::uint32_t seq = 0;
  std::uint64_t t_us = 0;
  int n = 0;
  std::array<std::int32_t, kSerialMaxPositions> pos{};
};

// Bytes of a frame with n positions.
[[nodiscard]] constexpr std::size_t serial_frame_size(int n) noexcept { return kSerialHeader + kSerialFixed + 4 * static_cast<std::size_t>(n) + 2; }

// Writes one frame; returns its size, or 0 when `out` is too small or n is out of range.
std::size_t encode_serial_frame(const SerialFrame& f, std::span<std::uint8_t> out) noexcept;

enum class SerialStatus {
  Ok,         // frame decoded; `consumed` bytes used
  NeedMore,   // the buffer holds the start of a frame only
  NoSync,     // buffer does not start with the sync pattern; skip `consumed` bytes (garbage)
  BadLength,  // LEN impossible; skip `consumed` (= 1) byte and resynchronise
  BadCrc,     // CRC mismatch; skip `consumed` (= 1) byte and resynchronise
};
struct SerialDecode {
  SerialStatus status = SerialStatus::NeedMore;
  std::size_t consumed = 0;
};

// Looks at the start of `in`. Pure.
[[nodiscard]] SerialDecode decode_serial_frame(std::span<const std::uint8_t> in, SerialFrame& out) noexcept;

// Stream decoder: accepts arbitrary chunks, finds frames, counts faults (CrcError,
// LengthError, GarbageBytes, SeqGap, SeqDuplicate). After a corrupt frame it restarts the
// search one byte after the false sync, so a good frame that follows garbage — even one
// that starts inside the damaged frame — is found.
class SerialStreamDecoder {
 public:
  // Calls on_frame(const SerialFrame&) for every good, new frame. Returns frames delivered.
  template <class F>
  int feed(std::span<const std::uint8_t> bytes, Counters& c, F&& on_frame) noexcept {
    int delivered = 0;
    while (!bytes.empty()) {
      const std::size_t room = buf_.size() - len_;
      const std::size_t take = bytes.size() < room ? bytes.size() : room;
      for (std::size_t i = 0; i < take; ++i) buf_[len_ + i] = bytes[i];
      len_ += take;
      bytes = bytes.subspan(take);
      delivered += drain(c, on_frame);
    }
    return delivered;
  }
  [[nodiscard]] std::uint64_t frames() const noexcept { return frames_; }
  // Samples missing by sequence number so far (also counted as Fault::SeqGap).
  [[nodiscard]] std::uint64_t gaps() const noexcept { return gaps_; }
  void reset() noexcept { len_ = 0; have_seq_ = false; }
  // Forgets buffered bytes (a partial frame of a stream that hung up); keeps the sequence
  // number, so frames missed until the stream resumes count as gaps.
  void drop_partial() noexcept { len_ = 0; }

 private:
  template <class F>
  int drain(Counters& c, F& on_frame) noexcept {
    int delivered = 0;
    std::size_t pos = 0;
    SerialFrame f;
    while (pos < len_) {
      const SerialDecode d = decode_serial_frame(std::span<const std::uint8_t>(buf_.data() + pos, len_ - pos), f);
      if (d.status == SerialStatus::NeedMore) break;
      pos += d.consumed;
      switch (d.status) {
        case SerialStatus::NoSync: c.add(Fault::GarbageBytes, d.consumed); break;
        case SerialStatus::BadLength: c.add(Fault::LengthError); break;
        case SerialStatus::BadCrc: c.add(Fault::CrcError); break;
        case SerialStatus::Ok:
          if (accept_seq(f.seq, c)) {
            ++frames_;
            ++delivered;
            on_frame(static_cast<const SerialFrame&>(f));
          }
          break;
        case SerialStatus::NeedMore: break;
      }
    }
    // Keep the unconsumed tail at the front.
    for (std::size_t i = pos; i < len_; ++i) buf_[i - pos] = buf_[i];
    len_ -= pos;
    return delivered;
  }
  bool accept_seq(std::uint32_t seq, Counters& c) noexcept {
    if (have_seq_) {
      const std::uint32_t d = seq - last_seq_;
      if (d == 0 || d >= 0x80000000U) {
        c.add(Fault::SeqDuplicate);
        return false;
      }
      if (d > 1) {
        c.add(Fault::SeqGap, d - 1);
        gaps_ += d - 1;
      }
    }
    have_seq_ = true;
    last_seq_ = seq;
    return true;
  }

  std::array<std::uint8_t, 2 * kSerialMaxFrame> buf_{};
  std::size_t len_ = 0;
  bool have_seq_ = false;
  std::uint32_t last_seq_ = 0;
  std::uint64_t frames_ = 0, gaps_ = 0;
};

}  // namespace lbr::hal
