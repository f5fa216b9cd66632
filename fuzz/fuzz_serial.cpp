// libFuzzer target: serial stream decoder + frame mapping. Property checked beyond "no
// crash": every delivered frame re-encodes to a frame that decodes to the same values.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "hal/serial_codec.hpp"
#include "hal/validate.hpp"

using namespace lbr::hal;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const LiveConfig cfg = [] {
    LiveConfig c;
    c.axes = default_axes();
    return c;
  }();
  SerialStreamDecoder d;
  Counters c;
  const std::size_t half = size / 2;  // two chunks: exercises the carried-over tail
  auto check = [&](const SerialFrame& f) {
    std::uint8_t buf[kSerialMaxFrame];
    const std::size_t n = encode_serial_frame(f, buf);
    SerialFrame g;
    if (n == 0 || decode_serial_frame({buf, n}, g).status != SerialStatus::Ok || g.seq != f.seq || g.n != f.n ||
        std::memcmp(g.pos.data(), f.pos.data(), sizeof(std::int32_t) * static_cast<std::size_t>(f.n)) != 0)
      std::abort();
    std::array<AxisSample, kMaxChannels> out{};
    (void)frame_to_samples(f, cfg, 0, out, c);
  };
  d.feed({data, half}, c, check);
  d.feed({data + half, size - half}, c, check);
  return 0;
}
