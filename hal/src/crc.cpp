#include "hal/crc.hpp"

#include <array>

namespace lbr::hal {

namespace {
constexpr std::array<std::uint16_t, 256> make_table() {
  std::array<std::uint16_t, 256> t{};
  for (int i = 0; i < 256; ++i) {
    auto c = static_cast<std::uint16_t>(i << 8);
    for (int b = 0; b < 8; ++b) c = static_cast<std::uint16_t>((c & 0x8000) ? (c << 1) ^ 0x1021 : c << 1);
    t[static_cast<std::size_t>(i)] = c;
  }
  return t;
}
constexpr auto kTable = make_table();
}  // namespace

std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> bytes, std::uint16_t crc) noexcept {
  for (const std::uint8_t b : bytes) crc = static_cast<std::uint16_t>((crc << 8) ^ kTable[((crc >> 8) ^ b) & 0xFF]);
  return crc;
}

}  // namespace lbr::hal
