// libFuzzer target: CANopen sample assembler fed a sequence of binary CAN frames, then the
// validator. Each 16-byte record: id (2 bytes LE; bit 15 = extended, bit 14 = RTR, bit 13 =
// error), DLC (0..15, values above 8 are invalid and skipped), 8 data bytes, time step
// (5 bytes LE, ns). Properties: samples come out with strictly increasing sequence numbers,
// at most one per mapped channel per frame, with finite positions; the assembler's losses
// never exceed the SYNCs seen.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "hal/can_codec.hpp"
#include "hal/validate.hpp"

using namespace lbr::hal;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const LiveConfig cfg = [] {
    LiveConfig c;
    for (int i = 0; i < 6; ++i) {  // the 6-axis bench mapping: nodes 1..6, channel 0
      AxisMap m;
      m.name = std::string(1, "XYZABC"[i]);
      m.axis = i;
      m.node = i + 1;
      m.index = i;
      m.min = -1000;
      m.max = 1000;
      m.max_speed_per_s = 500;
      c.axes.push_back(m);
    }
    return c;
  }();
  CanopenAssembler a(cfg);
  Validator v(cfg);
  Counters c;
  std::array<AxisSample, kMaxChannels> out{};
  std::int64_t t_ns = 0;
  std::uint64_t last_seq = 0, syncs = 0;
  bool have = false;
  constexpr std::size_t kRec = 16;
  for (std::size_t off = 0; off + kRec <= size; off += kRec) {
    const std::uint8_t* p = data + off;
    const auto raw_id = static_cast<std::uint16_t>(p[0] | p[1] << 8);
    CanFrame f;
    f.ext = (raw_id & 0x8000U) != 0;
    f.rtr = (raw_id & 0x4000U) != 0;
    f.err = (raw_id & 0x2000U) != 0;
    f.id = raw_id & 0x7FFU;
    if ((p[2] & 0x0F) > 8) continue;
    f.len = static_cast<std::uint8_t>(p[2] & 0x0F);
    for (int i = 0; i < 8; ++i) f.data[static_cast<std::size_t>(i)] = p[3 + i];
    std::uint64_t step = 0;
    for (int i = 0; i < 5; ++i) step |= static_cast<std::uint64_t>(p[11 + i]) << (8 * i);
    t_ns += static_cast<std::int64_t>(step);
    if (f.id == cfg.can.sync_id && !f.ext && !f.rtr && !f.err) ++syncs;
    const int n = a.on_frame(f, t_ns, out, c);
    if (n < 0 || n > 1) std::abort();  // one channel mapped
    for (int k = 0; k < n; ++k) {
      const AxisSample& s = out[static_cast<std::size_t>(k)];
      if (have && s.seq <= last_seq) std::abort();
      for (double q : s.q)
        if (!std::isfinite(q)) std::abort();
      have = true;
      last_seq = s.seq;
      (void)v.accept(s, c);
    }
  }
  if (a.lost() > syncs + c.get(Fault::SeqGap)) std::abort();
  return 0;
}
