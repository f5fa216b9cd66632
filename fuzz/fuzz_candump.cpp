// libFuzzer target: candump -l line parser + CANopen assembler. Property: a parsed line
// formats back to a line that parses to the same frame.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "hal/can_codec.hpp"

using namespace lbr::hal;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static LiveConfig cfg = [] {
    LiveConfig c;
    c.axes = default_axes();
    return c;
  }();
  static CanopenAssembler a(cfg);
  static Counters c;
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  CanFrame f;
  std::string_view iface;
  if (!parse_candump_line(line, f, &iface)) return 0;
  char buf[128];
  const std::size_t n = format_candump_line(f, iface, buf);
  CanFrame g;
  if (n > 0 && (!parse_candump_line({buf, n}, g) || g.id != f.id || g.len != f.len || g.err != f.err || g.rtr != f.rtr ||
                g.t_ns != f.t_ns))
    std::abort();
  std::array<AxisSample, kMaxChannels> out{};
  (void)a.on_frame(f, 0, out, c);
  return 0;
}
