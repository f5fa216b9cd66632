#include "hal/serial_codec.hpp"

#include "hal/crc.hpp"

namespace lbr::hal {

namespace {
void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}
bool valid_len(std::uint8_t len) noexcept {
  return len >= kSerialFixed + 4 && len <= kSerialFixed + 4 * kSerialMaxPositions && (len - kSerialFixed) % 4 == 0;
}
}  // namespace

std::size_t encode_serial_frame(const SerialFrame& f, std::span<std::uint8_t> out) noexcept {
  if (f.n < 1 || f.n > kSerialMaxPositions) return 0;
  const std::size_t size = serial_frame_size(f.n);
  if (out.size() < size) return 0;
  std::uint8_t* p = out.data();
  p[0] = kSerialSync0;
  p[1] = kSerialSync1;
  p[2] = static_cast<std::uint8_t>(kSerialFixed + 4 * static_cast<std::size_t>(f.n));
  put_u32(p + 3, f.seq);
  put_u32(p + 7, static_cast<std::uint32_t>(f.t_us));
  put_u32(p + 11, static_cast<std::uint32_t>(f.t_us >> 32));
  for (int i = 0; i < f.n; ++i) put_u32(p + 15 + 4 * i, static_cast<std::uint32_t>(f.pos[static_cast<std::size_t>(i)]));
  const std::uint16_t crc = crc16_ccitt_false(std::span<const std::uint8_t>(p + 2, size - 4));
  p[size - 2] = static_cast<std::uint8_t>(crc >> 8);
  p[size - 1] = static_cast<std::uint8_t>(crc & 0xFF);
  return size;
}

SerialDecode decode_serial_frame(std::span<const std::uint8_t> in, SerialFrame& out) noexcept {
  if (in.empty()) return {SerialStatus::NeedMore, 0};
  if (in[0] != kSerialSync0 || (in.size() >= 2 && in[1] != kSerialSync1)) {
    // Skip to the next byte that could start a frame.
    std::size_t k = 1;
    while (k < in.size() && in[k] != kSerialSync0) ++k;
    return {SerialStatus::NoSync, k};
  }
  if (in.size() < kSerialHeader) return {SerialStatus::NeedMore, 0};
  const std::uint8_t len = in[2];
  if (!valid_len(len)) return {SerialStatus::BadLength, 1};
  const std::size_t size = kSerialHeader + len + 2;
  if (in.size() < size) return {SerialStatus::NeedMore, 0};
  const std::uint16_t want = crc16_ccitt_false(in.subspan(2, 1 + len));
  const std::uint16_t got = static_cast<std::uint16_t>(in[size - 2] << 8 | in[size - 1]);
  if (want != got) return {SerialStatus::BadCrc, 1};
  const std::uint8_t* p = in.data();
  out.seq = get_u32(p + 3);
  out.t_us = static_cast<std::uint64_t>(get_u32(p + 7)) | static_cast<std::uint64_t>(get_u32(p + 11)) << 32;
  out.n = static_cast<int>((len - kSerialFixed) / 4);
  for (int i = 0; i < out.n; ++i) out.pos[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(get_u32(p + 15 + 4 * i));
  return {SerialStatus::Ok, size};
}

}  // namespace lbr::hal
