// ReplaySource: candump -l logs (CAN) and recorded serial captures, paced by their
// timestamps (speed × real time) or as fast as possible (speed 0). The whole log is parsed
// in open(), so the HAL loop does no file I/O.
#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "hal/serial_codec.hpp"
#include "hal/source.hpp"
#include "hal/validate.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::hal {

namespace {

int hexv(char ch) {
  if (ch >= '0' && ch <= '9') return ch - '0';
  if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
  if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
  return -1;
}

class ReplaySource final : public Source {
 public:
  ReplaySource(std::string file, const LiveConfig& cfg, double speed, std::uint64_t from_byte)
      : file_(std::move(file)), cfg_(cfg), speed_(speed), from_byte_(from_byte), asm_(fill(cfg)) {
    if (cfg_.axes.empty()) cfg_.axes = default_axes();
    if (!(speed >= 0.0)) throw std::invalid_argument("--speed must be >= 0");
  }

  void open() override {
    std::ifstream in(file_);
    if (!in) throw std::runtime_error(file_ + ": cannot open replay log");
    if (from_byte_ > 0 && !in.seekg(static_cast<std::streamoff>(from_byte_)))
      throw std::runtime_error(file_ + ": cannot seek to byte " + std::to_string(from_byte_));
    std::string line;
    int lineno = 0;
    while (std::getline(in, line)) {
      ++lineno;
      if (line.empty() || line[0] == '#') continue;
      Rec r;
      const auto sp = line.find(' ');
      if (line.find(" serial #") != std::string::npos && sp != std::string::npos) {
        CanFrame tmp;  // reuse the timestamp parser on a fake CAN line
        if (!parse_candump_line(line.substr(0, sp) + " x 000#", tmp))
          throw std::runtime_error(file_ + ":" + std::to_string(lineno) + ": malformed timestamp");
        r.serial = true;
        r.t_ns = tmp.t_ns;
        r.off = bytes_.size();
        const std::string hex = line.substr(line.find('#') + 1);
        if (hex.size() % 2 != 0) throw std::runtime_error(file_ + ":" + std::to_string(lineno) + ": odd hex length");
        for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
          const int a = hexv(hex[i]), b = hexv(hex[i + 1]);
          if (a < 0 || b < 0) throw std::runtime_error(file_ + ":" + std::to_string(lineno) + ": bad hex byte");
          bytes_.push_back(static_cast<std::uint8_t>(a << 4 | b));
        }
        r.len = bytes_.size() - r.off;
      } else {
        if (!parse_candump_line(line, r.frame))
          throw std::runtime_error(file_ + ":" + std::to_string(lineno) + ": not a candump -l line: " + line);
        r.t_ns = r.frame.t_ns;
      }
      recs_.push_back(r);
    }
    if (recs_.empty() && from_byte_ == 0) throw std::runtime_error(file_ + ": replay log holds no frames");
    if (recs_.empty()) return;  // a catch-up with nothing after its offset
    t0_log_ = recs_.front().t_ns;
    t0_mono_ = sched::now_ns();
  }

  PollResult poll(int timeout_ms, SampleSink& sink) noexcept override {
    if (next_ >= recs_.size()) return PollResult::End;
    const Rec& r = recs_[next_];
    if (speed_ > 0.0) {
      // Log times are in [0, kMaxCandumpSec] s, so the difference fits; the quotient is
      // clamped (a tiny --speed would overflow int64).
      const double wait_ns = std::clamp(static_cast<double>(r.t_ns - t0_log_) / speed_, 0.0, 1e17);
      const auto due = t0_mono_ + static_cast<std::int64_t>(wait_ns);
      const std::int64_t now = sched::now_ns();
      if (due > now) {
        const std::int64_t limit = now + static_cast<std::int64_t>(timeout_ms) * 1'000'000;
        if (due > limit) {
          sched::sleep_until_ns(limit);
          return PollResult::Idle;
        }
        sched::sleep_until_ns(due);
      }
    }
    ++next_;
    const std::int64_t now = sched::now_ns();
    if (r.serial) {
      const std::span<const std::uint8_t> b(bytes_.data() + r.off, r.len);
      if (record_) {
        RawRecord rec;
        rec.serial = true;
        rec.t_wall_ns = r.t_ns;
        for (std::size_t off = 0; off < b.size(); off += rec.bytes.size()) {
          const std::size_t k = std::min(rec.bytes.size(), b.size() - off);
          std::copy_n(b.begin() + static_cast<std::ptrdiff_t>(off), k, rec.bytes.begin());
          rec.len = static_cast<std::uint16_t>(k);
          sink.on_raw(rec);
        }
      }
      dec_.feed(b, counters_, [&](const SerialFrame& f) {
        const int k = frame_to_samples(f, cfg_, now, out_, counters_);
        if (k > 0) sink.on_samples(std::span<const AxisSample>(out_.data(), static_cast<std::size_t>(k)));
        else ++mapped_lost_;
        if (f.n < serial_positions_needed(cfg_)) note_short_frame(f.n, serial_positions_needed(cfg_));
      });
    } else {
      if (record_) {
        RawRecord rec;
        rec.frame = r.frame;
        rec.t_wall_ns = r.t_ns;
        sink.on_raw(rec);
      }
      const int k = asm_.on_frame(r.frame, now, out_, counters_);
      if (k > 0) sink.on_samples(std::span<const AxisSample>(out_.data(), static_cast<std::size_t>(k)));
    }
    return PollResult::Data;
  }

  void close() noexcept override {}
  [[nodiscard]] std::string describe() const override { return "replay:" + file_; }
  [[nodiscard]] bool live() const noexcept override { return speed_ > 0.0; }
  [[nodiscard]] std::uint64_t lost() const noexcept override { return dec_.gaps() + asm_.lost() + mapped_lost_; }

 private:
  static LiveConfig fill(LiveConfig c) {
    if (c.axes.empty()) c.axes = default_axes();
    return c;
  }
  struct Rec {
    std::int64_t t_ns = 0;
    bool serial = false;
    CanFrame frame;
    std::size_t off = 0, len = 0;
  };
  std::string file_;
  LiveConfig cfg_;
  double speed_;
  std::uint64_t from_byte_ = 0;
  CanopenAssembler asm_;
  SerialStreamDecoder dec_;
  std::vector<Rec> recs_;
  std::vector<std::uint8_t> bytes_;
  std::size_t next_ = 0;
  std::int64_t t0_log_ = 0, t0_mono_ = 0;
  std::array<AxisSample, kMaxChannels> out_{};
  std::uint64_t mapped_lost_ = 0;
};

}  // namespace

std::int64_t wall_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::unique_ptr<Source> make_replay_source(const std::string& file, const LiveConfig& cfg, double speed,
                                           std::uint64_t from_byte) {
  return std::make_unique<ReplaySource>(file, cfg, speed, from_byte);
}

}  // namespace lbr::hal
