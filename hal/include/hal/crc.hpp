// hal/crc.hpp — CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, xorout 0;
// check value for "123456789" = 0x29B1). RT-safe, table driven, no allocation.
#pragma once

#include <cstdint>
#include <span>

namespace lbr::hal {

[[nodiscard]] std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> bytes,
                                              std::uint16_t crc = 0xFFFF) noexcept;

}  // namespace lbr::hal
