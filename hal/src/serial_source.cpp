// SerialSource: LibSerial opens and configures the port (8N1, raw, baud from the profile);
// we then take over a duplicate of its descriptor with those settings and close the
// LibSerial object. The HAL loop uses poll()+read(), because LibSerial reports timeouts
// (and a hung-up port on close) with exceptions and the RT path must not throw. With
// live.serial.reconnect_ms > 0 a hang-up closes the descriptor and poll() reopens the path
// with plain open() + the saved termios (no allocation) until it comes back.
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <termios.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <libserial/SerialPort.h>

#include "hal/serial_codec.hpp"
#include "hal/source.hpp"
#include "hal/validate.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::hal {

namespace {

LibSerial::BaudRate baud_of(int b) {
  switch (b) {
    case 9600: return LibSerial::BaudRate::BAUD_9600;
    case 19200: return LibSerial::BaudRate::BAUD_19200;
    case 38400: return LibSerial::BaudRate::BAUD_38400;
    case 57600: return LibSerial::BaudRate::BAUD_57600;
    case 115200: return LibSerial::BaudRate::BAUD_115200;
    case 230400: return LibSerial::BaudRate::BAUD_230400;
    case 460800: return LibSerial::BaudRate::BAUD_460800;
    case 921600: return LibSerial::BaudRate::BAUD_921600;
    case 1000000: return LibSerial::BaudRate::BAUD_1000000;
    case 2000000: return LibSerial::BaudRate::BAUD_2000000;
    case 4000000: return LibSerial::BaudRate::BAUD_4000000;
    default: throw std::invalid_argument("live.serial.baud: unsupported baud rate " + std::to_string(b));
  }
}

class SerialSource final : public Source {
 public:
  SerialSource(std::string dev, const LiveConfig& cfg) : dev_(std::move(dev)), cfg_(cfg) {
    if (cfg_.axes.empty()) cfg_.axes = default_axes();
    baud_ = baud_of(cfg_.serial.baud);
    needed_ = serial_positions_needed(cfg_);
    reconnect_ns_ = static_cast<std::int64_t>(cfg_.serial.reconnect_ms * 1e6);
  }
  ~SerialSource() override { close(); }

  void open() override {
    // LibSerial reports a missing device as "Bad file descriptor": say what is wrong first.
    if (::access(dev_.c_str(), R_OK | W_OK) != 0) {
      const int e = errno;
      std::string hint;  // what to do (issue 19), not just the errno text
      if (e == ENOENT)
        hint = ". Is the adapter plugged in? `ls /dev/ttyUSB* /dev/ttyACM*` lists serial devices (`sudo dmesg | tail` "
               "names a new one). Without a machine, feed a pseudo-terminal: `build/tools/feeders/lbr-feed-serial "
               "--pty-link /tmp/lbr-pty --profile PROFILE`, then --source serial:/tmp/lbr-pty with the same profile";
      else if (e == EACCES)
        hint = ". Join the group that owns it (usually dialout: `sudo usermod -aG dialout $USER`, then log in again)";
      throw std::runtime_error("serial:" + dev_ + ": " + std::strerror(e) + hint);
    }
    termios settings{};
    int fd = -1;
    try {
      LibSerial::SerialPort port;
      port.Open(dev_);
      port.SetBaudRate(baud_);
      port.SetCharacterSize(LibSerial::CharacterSize::CHAR_SIZE_8);
      port.SetParity(LibSerial::Parity::PARITY_NONE);
      port.SetStopBits(LibSerial::StopBits::STOP_BITS_1);
      port.SetFlowControl(LibSerial::FlowControl::FLOW_CONTROL_NONE);
      fd = ::dup(port.GetFileDescriptor());
      if (fd < 0 || ::tcgetattr(fd, &settings) != 0) throw std::runtime_error(std::strerror(errno));
      port.Close();  // restores the settings it found; ours are re-applied below
    } catch (const std::exception& e) {
      if (fd >= 0) ::close(fd);
      throw std::runtime_error("serial:" + dev_ + ": " + e.what());
    }
    if (::tcsetattr(fd, TCSANOW, &settings) != 0) {
      const int e = errno;
      ::close(fd);
      throw std::runtime_error("serial:" + dev_ + ": tcsetattr: " + std::strerror(e));
    }
    settings_ = settings;
    fd_ = fd;
  }

  PollResult poll(int timeout_ms, SampleSink& sink) noexcept override {
    if (fd_ < 0) return reconnect_ns_ > 0 ? try_reopen(timeout_ms) : PollResult::End;
    const PollResult r = read_and_decode(timeout_ms, sink);
    if (r != PollResult::End || reconnect_ns_ <= 0) return r;
    hang_up();  // live.serial.reconnect_ms: wait for the device to come back
    return PollResult::Idle;
  }

  void close() noexcept override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  [[nodiscard]] std::string describe() const override { return "serial:" + dev_; }
  [[nodiscard]] std::uint64_t lost() const noexcept override { return dec_.gaps() + mapped_lost_; }

 private:
  // The device hung up: close it and drop the partial frame; the sequence number is kept, so
  // the frames missed until the reopen count as gaps.
  void hang_up() noexcept {
    close();
    dec_.drop_partial();
    retry_at_ns_ = sched::now_ns();
  }

  // Reopens the device (same path, the settings open() applied) once retry_at_ns_ is due;
  // sleeps until then, at most timeout_ms. No allocation: plain open() + tcsetattr().
  PollResult try_reopen(int timeout_ms) noexcept {
    const std::int64_t now = sched::now_ns();
    if (now < retry_at_ns_) {
      sched::sleep_until_ns(std::min(retry_at_ns_, now + static_cast<std::int64_t>(timeout_ms) * 1'000'000));
      return PollResult::Idle;
    }
    retry_at_ns_ = now + reconnect_ns_;
    const int fd = ::open(dev_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) return PollResult::Idle;
    if (::tcsetattr(fd, TCSANOW, &settings_) != 0) {
      ::close(fd);
      return PollResult::Idle;
    }
    fd_ = fd;
    counters_.add(Fault::Reconnect);
    return PollResult::Idle;
  }

  PollResult read_and_decode(int timeout_ms, SampleSink& sink) noexcept {
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, timeout_ms);
    if (r == 0) return PollResult::Idle;
    if (r < 0) {
      if (errno == EINTR) return PollResult::Idle;
      counters_.add(Fault::ReadError);
      return PollResult::Error;
    }
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) {
      if (!(p.revents & POLLIN)) return PollResult::End;  // the other end closed
    }
    const ssize_t n = ::read(fd_, buf_.data(), buf_.size());
    if (n == 0) return PollResult::End;
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) return PollResult::Idle;
      if (errno == EIO) return PollResult::End;  // pty master closed
      counters_.add(Fault::ReadError);
      return PollResult::Error;
    }
    const std::int64_t now = sched::now_ns();
    if (record_) {
      RawRecord rec;
      rec.serial = true;
      rec.t_wall_ns = wall_ns();
      for (ssize_t off = 0; off < n; off += static_cast<ssize_t>(rec.bytes.size())) {
        const auto k = std::min<std::size_t>(rec.bytes.size(), static_cast<std::size_t>(n - off));
        std::copy_n(buf_.begin() + off, k, rec.bytes.begin());
        rec.len = static_cast<std::uint16_t>(k);
        sink.on_raw(rec);
      }
    }
    dec_.feed(std::span<const std::uint8_t>(buf_.data(), static_cast<std::size_t>(n)), counters_,
              [&](const SerialFrame& f) {
                const int k = frame_to_samples(f, cfg_, now, out_, counters_);
                if (k > 0) sink.on_samples(std::span<const AxisSample>(out_.data(), static_cast<std::size_t>(k)));
                else ++mapped_lost_;
                if (f.n < needed_) note_short_frame(f.n, needed_);
              });
    return PollResult::Data;
  }

  std::string dev_;
  LiveConfig cfg_;
  LibSerial::BaudRate baud_;
  int fd_ = -1;
  std::array<std::uint8_t, 1024> buf_{};
  SerialStreamDecoder dec_;
  std::array<AxisSample, kMaxChannels> out_{};
  std::uint64_t mapped_lost_ = 0;
  int needed_ = 0;
  termios settings_{};
  std::int64_t reconnect_ns_ = 0, retry_at_ns_ = 0;
};

}  // namespace

std::unique_ptr<Source> make_serial_source(const std::string& device, const LiveConfig& cfg) {
  return std::make_unique<SerialSource>(device, cfg);
}

}  // namespace lbr::hal
