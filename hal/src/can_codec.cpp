#include "hal/can_codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "hal/serial_codec.hpp"

namespace lbr::hal {

namespace {

int hexval(char ch) noexcept {
  if (ch >= '0' && ch <= '9') return ch - '0';
  if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
  if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
  return -1;
}

constexpr std::uint32_t kErrFlag = 0x20000000U;

// A Linux interface name as candump writes it: 1..15 printable characters, no space.
bool valid_iface(std::string_view s) noexcept {
  if (s.empty() || s.size() > 15) return false;
  for (const char ch : s)
    if (ch < 0x21 || ch > 0x7E) return false;
  return true;
}

}  // namespace

bool parse_candump_line(std::string_view s, CanFrame& f, std::string_view* iface) noexcept {
  // (SEC.USEC)
  if (s.size() < 4 || s[0] != '(') return false;
  std::size_t i = 1;
  std::int64_t sec = 0, usec = 0;
  int nd = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (++nd > 12) return false;
    sec = sec * 10 + (s[i++] - '0');
  }
  if (sec > kMaxCandumpSec) return false;  // t_ns below must fit in int64
  if (nd == 0 || i >= s.size() || s[i++] != '.') return false;
  nd = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (++nd > 9) return false;
    usec = usec * 10 + (s[i++] - '0');
  }
  if (nd != 6 || i >= s.size() || s[i++] != ')') return false;
  if (i >= s.size() || s[i++] != ' ') return false;
  const std::size_t if0 = i;
  while (i < s.size() && s[i] != ' ') ++i;
  if (i >= s.size() || !valid_iface(s.substr(if0, i - if0))) return false;
  if (iface != nullptr) *iface = s.substr(if0, i - if0);
  ++i;
  const std::size_t id0 = i;
  std::uint32_t id = 0;
  while (i < s.size() && s[i] != '#') {
    const int h = hexval(s[i++]);
    if (h < 0) return false;
    id = id << 4 | static_cast<std::uint32_t>(h);
  }
  const std::size_t idlen = i - id0;
  if (i >= s.size() || (idlen != 3 && idlen != 8)) return false;
  ++i;  // '#'
  f = CanFrame{};
  f.t_ns = sec * 1'000'000'000 + usec * 1000;
  f.ext = idlen == 8;
  if (f.ext && (id & kErrFlag) != 0) {
    f.err = true;
    id &= 0x1FFFFFFFU;
  }
  if (!f.ext && id > 0x7FF) return false;
  f.id = f.ext ? (id & 0x1FFFFFFFU) : id;
  if (i < s.size() && s[i] == '#') return false;  // CAN FD: not supported
  if (i < s.size() && s[i] == 'R') {  // RTR, optionally with its DLC (candump: "123#R4")
    f.rtr = true;
    if (++i < s.size() && s[i] >= '0' && s[i] <= '8') f.len = static_cast<std::uint8_t>(s[i++] - '0');
    return i >= s.size() || s[i] == '\r' || s[i] == '\n' || s[i] == ' ';
  }
  std::size_t n = 0;
  while (i < s.size() && s[i] != '\r' && s[i] != '\n' && s[i] != ' ') {
    if (i + 1 >= s.size() || n >= 8) return false;
    const int a = hexval(s[i]), b = hexval(s[i + 1]);
    if (a < 0 || b < 0) return false;
    f.data[n++] = static_cast<std::uint8_t>(a << 4 | b);
    i += 2;
  }
  f.len = static_cast<std::uint8_t>(n);
  return true;
}

std::size_t format_candump_line(const CanFrame& f, std::string_view iface, std::span<char> out) noexcept {
  if (!valid_iface(iface) || f.t_ns < 0 || f.len > 8) return 0;
  char data[17] = {};
  if (f.rtr) {  // candump: "R", then the DLC when it is not 0
    data[0] = 'R';
    if (f.len > 0) data[1] = static_cast<char>('0' + f.len);
  } else {
    for (int k = 0; k < f.len; ++k) std::snprintf(data + 2 * k, 3, "%02X", f.data[static_cast<std::size_t>(k)]);
  }
  const long long sec = f.t_ns / 1'000'000'000, usec = (f.t_ns % 1'000'000'000) / 1000;
  int n;
  const int ilen = static_cast<int>(iface.size());
  // candump -l: seconds zero-padded to 10 digits, ids upper-case hex.
  if (f.ext || f.err)
    n = std::snprintf(out.data(), out.size(), "(%010lld.%06lld) %.*s %08X#%s\n", sec, usec, ilen, iface.data(),
                      f.id | (f.err ? kErrFlag : 0U), data);
  else
    n = std::snprintf(out.data(), out.size(), "(%010lld.%06lld) %.*s %03X#%s\n", sec, usec, ilen, iface.data(), f.id,
                      data);
  return n > 0 && static_cast<std::size_t>(n) < out.size() ? static_cast<std::size_t>(n) : 0;
}

bool map_counts(const AxisMap& m, std::int32_t raw, AxisSample& s, Counters& c) noexcept {
  if (raw == kNoValue) {
    c.add(Fault::InvalidValue);
    return false;
  }
  s.q[static_cast<std::size_t>(m.axis)] = static_cast<double>(raw) * m.scale + m.offset;
  s.mask = static_cast<std::uint8_t>(s.mask | (1U << m.axis));
  return true;
}

CanopenAssembler::CanopenAssembler(const LiveConfig& cfg) : cfg_(cfg) {
  if (cfg_.axes.empty()) cfg_.axes = default_axes();
  node_map_.fill(-1);
  for (std::size_t k = 0; k < cfg_.axes.size(); ++k) {
    const AxisMap& m = cfg_.axes[k];
    if (m.node < 1 || m.node > 127) throw std::invalid_argument("axis " + m.name + ": CAN node must be in 1..127");
    if (node_map_[static_cast<std::size_t>(m.node)] >= 0)
      throw std::invalid_argument("axis " + m.name + ": CAN node " + std::to_string(m.node) + " is mapped twice");
    node_map_[static_cast<std::size_t>(m.node)] = static_cast<std::int16_t>(k);
    ++mapped_;
  }
  late_ns_ = static_cast<std::int64_t>((cfg_.can.late_ms > 0 ? cfg_.can.late_ms : 0.8 * cfg_.period_ms) * 1e6);
  period_ns_ = cfg_.period_ms * 1e6;
}

std::uint64_t CanopenAssembler::hidden_turns(std::int64_t t_ns, std::uint64_t gap) const noexcept {
  if (period_ns_ <= 0 || t_ns <= last_sync_t_) return 0;
  // Both times lie in [0, 9e18] ns (parse_candump_line, kernel timestamps): no overflow.
  const double missing = static_cast<double>(t_ns - last_sync_t_) / period_ns_ - 1.0;
  const auto max = static_cast<double>(cfg_.can.sync_counter_max);
  const double turns = std::floor((missing - static_cast<double>(gap)) / max + 0.1);
  return turns >= 1.0 ? static_cast<std::uint64_t>(std::min(turns, 1e6)) * static_cast<std::uint64_t>(max) : 0;
}

void CanopenAssembler::close_cycle(Counters& c) noexcept {
  if (open_ && !completed_) {
    c.add(Fault::MissingTpdo, static_cast<std::uint64_t>(mapped_ - answered_count_));
    ++lost_;
  }
}

// A SYNC frame: closes the open cycle (counting its missing TPDOs) and opens the next; a
// jump of the SYNC counter counts the cycles it skipped as lost.
void CanopenAssembler::on_sync(const CanFrame& f, Counters& c) noexcept {
  close_cycle(c);
  ++syncs_;
  std::uint64_t step = 1;
  if (f.len == 1) {
    const int counter = f.data[0];
    const int max = cfg_.can.sync_counter_max;
    if (last_counter_ >= 0) {
      const int expected = last_counter_ % max + 1;
      auto gap = static_cast<std::uint64_t>(((counter - expected) % max + max) % max);
      gap += hidden_turns(f.t_ns, gap);
      if (gap > 0) {
        c.add(Fault::SeqGap, gap);
        lost_ += gap;
        step += gap;
      }
    }
    last_counter_ = counter;
    last_sync_t_ = f.t_ns;
  }
  seq_ += step;
  open_ = true;
  completed_ = false;
  sync_t_ = f.t_ns;
  answered_.fill(false);
  answered_count_ = 0;
}

// A TPDO of a mapped node: the fault it is, or none when it belongs to the open cycle.
bool CanopenAssembler::accept_tpdo(const CanFrame& f, std::uint32_t node, Counters& c) const noexcept {
  if (f.id < cfg_.can.tpdo_base || node > 127 || node_map_[node] < 0) {
    c.add(Fault::UnknownId);
    return false;
  }
  if (f.len != 4 && f.len != 6) {
    c.add(Fault::LengthError);
    return false;
  }
  if (!open_) {
    c.add(Fault::LateTpdo);
    return false;
  }
  if (answered_[node]) {
    c.add(Fault::DuplicateTpdo);
    return false;
  }
  if (completed_ || f.t_ns - sync_t_ > late_ns_) {
    c.add(Fault::LateTpdo);
    return false;
  }
  return true;
}

// Every mapped node answered: one sample per channel into `out`; returns how many.
int CanopenAssembler::complete_cycle(std::int64_t now_mono_ns, std::span<AxisSample, kMaxChannels> out,
                                     Counters& c) noexcept {
  completed_ = true;
  std::array<bool, kMaxChannels> used{};
  for (auto& s : out) s = AxisSample{};
  bool ok = true;
  for (const AxisMap& m : cfg_.axes) {
    AxisSample& s = out[static_cast<std::size_t>(m.channel)];
    used[static_cast<std::size_t>(m.channel)] = true;
    ok = map_counts(m, raw_[static_cast<std::size_t>(m.node)], s, c) && ok;
  }
  if (!ok) {
    ++lost_;
    return 0;
  }
  int n = 0;
  for (int ch = 0; ch < kMaxChannels; ++ch) {
    if (!used[static_cast<std::size_t>(ch)]) continue;
    AxisSample s = out[static_cast<std::size_t>(ch)];
    s.channel = static_cast<std::uint8_t>(ch);
    s.seq = seq_;
    s.t_src_ns = sync_t_;
    s.t_rx_ns = now_mono_ns;
    out[static_cast<std::size_t>(n++)] = s;
  }
  ++samples_;
  return n;
}

int CanopenAssembler::on_frame(const CanFrame& f, std::int64_t now_mono_ns, std::span<AxisSample, kMaxChannels> out,
                               Counters& c) noexcept {
  if (f.err) {
    c.add(Fault::ErrorFrame);
    return 0;
  }
  if (f.ext || f.rtr) {
    c.add(Fault::UnknownId);
    return 0;
  }
  if (f.id == cfg_.can.sync_id) {
    if (f.len > 1) c.add(Fault::LengthError);
    else on_sync(f, c);
    return 0;
  }
  const std::uint32_t node = f.id - cfg_.can.tpdo_base;
  if (!accept_tpdo(f, node, c)) return 0;
  const auto raw = static_cast<std::int32_t>(static_cast<std::uint32_t>(f.data[0]) | static_cast<std::uint32_t>(f.data[1]) << 8 |
                                             static_cast<std::uint32_t>(f.data[2]) << 16 |
                                             static_cast<std::uint32_t>(f.data[3]) << 24);
  if (f.len == 6) {
    const auto status = static_cast<std::uint16_t>(f.data[4] | f.data[5] << 8);
    if (status & 0x0008U) c.add(Fault::DriveFault);
  }
  answered_[node] = true;
  raw_[node] = raw;
  if (++answered_count_ < mapped_) return 0;
  return complete_cycle(now_mono_ns, out, c);
}

}  // namespace lbr::hal
