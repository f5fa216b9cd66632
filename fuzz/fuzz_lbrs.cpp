// libFuzzer target: the levels file reader (LBRS, docs/formats.md). Either it rebuilds a
// solid, which writes back to bytes that read again to the same bytes (a fixed point), or it
// throws std::runtime_error starting "LBRS: ".
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "geom/serialize.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> in(data, data + size);
  try {
    const lbr::geom::LbrSolid s = lbr::geom::from_bytes(in);
    const std::vector<std::uint8_t> once = lbr::geom::to_bytes(s);
    if (lbr::geom::to_bytes(lbr::geom::from_bytes(once)) != once) __builtin_trap();
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).rfind("LBRS: ", 0) != 0) __builtin_trap();
  }
  return 0;
}
