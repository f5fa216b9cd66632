// libFuzzer target: candump -l line parser + CANopen assembler. Property: a parsed line
// formats back (candump's own layout) to a line that parses to the same frame and interface;
// the formatted line is a fixed point (formatting it again gives the same bytes).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "hal/can_codec.hpp"

using namespace lbr::hal;

namespace {

bool same(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.len != b.len || a.ext != b.ext || a.err != b.err || a.rtr != b.rtr) return false;
  // candump -l keeps microseconds
  if (a.t_ns / 1000 != b.t_ns / 1000) return false;
  return a.rtr || std::equal(a.data.begin(), a.data.begin() + a.len, b.data.begin());
}

}  // namespace

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
  char buf[128], buf2[128];
  const std::size_t n = format_candump_line(f, iface, buf);
  if (n == 0) std::abort();  // everything the parser accepts can be written back
  CanFrame g;
  std::string_view iface2;
  if (!parse_candump_line({buf, n}, g, &iface2) || !same(f, g) || iface2 != iface) std::abort();
  const std::size_t n2 = format_candump_line(g, iface2, buf2);
  if (n2 != n || std::string_view(buf, n) != std::string_view(buf2, n2)) std::abort();
  std::array<AxisSample, kMaxChannels> out{};
  (void)a.on_frame(f, 0, out, c);
  return 0;
}
