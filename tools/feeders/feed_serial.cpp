// lbr-feed-serial — streams a program's samples as serial frames (docs/protocols.md#serial)
// to a device, or to a pseudo-terminal it creates (--pty-link), paced in real time, with
// seeded fault injection. Prints what it sent and injected as JSON on stdout.
//
// Soak mode (tools/soak.sh): --duration-s plays the program forwards then backwards (so the
// positions stay continuous) until that much stream time has passed; --disconnect-every-s
// closes the pseudo-terminal for --disconnect-ms and opens a new one behind the same link;
// --burst-every holds --burst-len frames back and writes them at once.
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "feed_common.hpp"
#include "hal/serial_codec.hpp"
#include "sched/rt_thread.hpp"

using namespace lbr;

namespace {

bool write_all(int fd, const std::uint8_t* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR || errno == EAGAIN) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

struct SoakPlan {
  double duration_s = 0.0;         // > 0: loop the program (forwards, backwards) this long
  double disconnect_every_s = 0.0; // > 0 (with --pty-link): hang up this often
  int disconnect_ms = 1000;        // ... for this long
  int burst_every = 0;             // hold back every Nth frame and the burst_len − 1 after it
  int burst_len = 50;
};

struct Tally {
  std::uint64_t generated = 0, sent = 0, corrupted = 0, garbage = 0, truncated = 0, dropped = 0, duplicated = 0;
  std::uint64_t disconnects = 0, not_sent_disconnected = 0, bursts = 0;
};

// Creates a pseudo-terminal with `link` pointing at its slave side and waits (at most
// wait_ms) until a reader has opened it. Returns the master descriptor.
int open_pty(const std::string& link, int wait_ms) {
  int master = -1, slave = -1;
  if (openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) throw std::runtime_error(std::string("openpty: ") + std::strerror(errno));
  termios t{};
  tcgetattr(slave, &t);
  cfmakeraw(&t);
  tcsetattr(slave, TCSANOW, &t);
  const std::string name = ttyname(slave);
  std::filesystem::remove(link);
  std::filesystem::create_symlink(name, link);
  ::close(slave);
  // While no slave fd is open the master reports POLLHUP: wait for the reader.
  const std::int64_t deadline = sched::now_ns() + static_cast<std::int64_t>(wait_ms) * 1'000'000;
  for (;;) {
    pollfd p{master, POLLOUT, 0};
    ::poll(&p, 1, 0);
    if (!(p.revents & POLLHUP)) break;
    if (sched::now_ns() > deadline) throw std::runtime_error("no reader opened " + link);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // let the reader finish its setup
  return master;
}

class SerialFeeder {
 public:
  SerialFeeder(const tools::FeedOptions& o, const SoakPlan& soak, app::Profile profile, tools::Stream stream)
      : o_(o), soak_(soak), profile_(std::move(profile)), stream_(std::move(stream)), rng_(o.faults.seed) {
    for (const hal::AxisMap& m : profile_.live.axes) n_pos_ = std::max(n_pos_, m.index + 1);
    period_ns_ = static_cast<std::int64_t>(stream_.period_s * 1e9);
    total_ = stream_.counts.size();
    if (soak_.duration_s > 0) total_ = static_cast<std::uint64_t>(soak_.duration_s / stream_.period_s);
  }

  // Sends every sample; returns the tally. fd: an open device, or -1 with a pty link.
  Tally run(int fd, const std::string& pty_link, int wait_ms) {
    fd_ = fd >= 0 ? fd : open_pty(pty_link, wait_ms);
    if (o_.priority > 0) (void)sched::configure_current_thread(sched::RtConfig{"lbr-feed", o_.priority, -1, true});
    t0_ = sched::now_ns();
    next_disconnect_ns_ = soak_.disconnect_every_s > 0 && !pty_link.empty() ? t0_ + seconds_ns(soak_.disconnect_every_s) : -1;
    for (std::uint64_t k = 0; k < total_; ++k) {
      if (o_.speed > 0) sched::sleep_until_ns(t0_ + static_cast<std::int64_t>(static_cast<double>(k) * static_cast<double>(period_ns_) / o_.speed));
      ++t_.generated;
      if (next_disconnect_ns_ >= 0 && sched::now_ns() >= next_disconnect_ns_ && k + 2000 < total_) {
        k = reconnect(k, pty_link, wait_ms);
        continue;
      }
      if (!send_frame(k)) break;
    }
    if (!flush_burst()) return t_;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // let the reader drain
    ::close(fd_);
    if (!pty_link.empty()) std::filesystem::remove(pty_link);
    return t_;
  }

 private:
  static std::int64_t seconds_ns(double s) { return static_cast<std::int64_t>(s * 1e9); }

  // Stream index of sample k: the program forwards, then backwards, and so on.
  [[nodiscard]] std::size_t index_of(std::uint64_t k) const {
    const std::uint64_t n = stream_.counts.size();
    if (n < 2) return 0;
    const std::uint64_t i = k % (2 * n - 2);
    return static_cast<std::size_t>(i < n ? i : 2 * n - 2 - i);
  }

  // Hangs up (link removed first, so the reader cannot reopen the old slave), waits
  // disconnect_ms, opens a new pty behind the link. The samples due meanwhile are not sent.
  // Returns the last sample index skipped.
  std::uint64_t reconnect(std::uint64_t k, const std::string& pty_link, int wait_ms) {
    (void)flush_burst();
    std::filesystem::remove(pty_link);
    ::close(fd_);
    ++t_.disconnects;
    std::this_thread::sleep_for(std::chrono::milliseconds(soak_.disconnect_ms));
    fd_ = open_pty(pty_link, wait_ms);
    // Skip what fell due while the line was down (k itself included).
    const auto due = static_cast<std::uint64_t>((sched::now_ns() - t0_) / period_ns_);
    const std::uint64_t last = std::min(std::max(due, k), total_ - 1);
    t_.not_sent_disconnected += last - k + 1;
    t_.generated += last - k;
    next_disconnect_ns_ = sched::now_ns() + seconds_ns(soak_.disconnect_every_s);
    return last;
  }

  bool send_frame(std::uint64_t k) {
    const tools::FaultPlan& f = o_.faults;
    hal::SerialFrame fr;
    fr.seq = static_cast<std::uint32_t>(k);
    fr.t_us = static_cast<std::uint64_t>((sched::now_ns() - t0_) / 1000);
    fr.n = n_pos_;
    const std::vector<std::int32_t>& row = stream_.counts[index_of(k)];
    for (std::size_t a = 0; a < profile_.live.axes.size(); ++a) fr.pos[static_cast<std::size_t>(profile_.live.axes[a].index)] = row[a];
    std::array<std::uint8_t, hal::kSerialMaxFrame> b{};
    std::size_t len = hal::encode_serial_frame(fr, b);
    const bool tail = soak_.duration_s > 0 && k + 1000 >= total_;  // the end arrives intact: no gap is left uncounted
    if (!tail && tools::FaultPlan::hit(f.drop_every, k)) {
      ++t_.dropped;
      return true;
    }
    if (!tail && tools::FaultPlan::hit(f.garbage_every, k)) {
      std::array<std::uint8_t, 24> g{};
      const std::size_t gl = 1 + rng_() % g.size();
      for (std::size_t i = 0; i < gl; ++i) g[i] = static_cast<std::uint8_t>(rng_());
      g[0] = hal::kSerialSync0;  // a false sync start makes the resync work harder
      if (!out(g.data(), gl)) return false;
      ++t_.garbage;
    }
    if (!tail && tools::FaultPlan::hit(f.corrupt_every, k)) {
      b[3 + rng_() % (len - 3)] ^= static_cast<std::uint8_t>(1U << (rng_() % 8));
      ++t_.corrupted;
    } else if (!tail && tools::FaultPlan::hit(f.truncate_every, k)) {
      len = 3 + rng_() % (len - 4);
      ++t_.truncated;
    }
    if (!tail && tools::FaultPlan::hit(soak_.burst_every, k)) {
      burst_left_ = soak_.burst_len;
      ++t_.bursts;
    }
    if (!out(b.data(), len)) return false;
    if (!tail && tools::FaultPlan::hit(f.duplicate_every, k)) {
      if (!out(b.data(), len)) return false;
      ++t_.duplicated;
    }
    ++t_.sent;
    return burst_left_ == 0 || --burst_left_ > 0 || flush_burst();  // a burst ends: write it at once
  }

  // Writes, or holds the bytes back while a burst is being collected.
  bool out(const std::uint8_t* p, std::size_t n) {
    if (burst_left_ == 0) return write_all(fd_, p, n);
    if (held_.size() + n > 1 << 20) return flush_burst() && write_all(fd_, p, n);
    held_.insert(held_.end(), p, p + n);
    return true;
  }
  bool flush_burst() {
    burst_left_ = 0;
    const bool ok = held_.empty() || write_all(fd_, held_.data(), held_.size());
    held_.clear();
    return ok;
  }

  const tools::FeedOptions& o_;
  SoakPlan soak_;
  app::Profile profile_;
  tools::Stream stream_;
  std::mt19937_64 rng_;
  int n_pos_ = 0;
  std::int64_t period_ns_ = 1'000'000, t0_ = 0, next_disconnect_ns_ = -1;
  std::uint64_t total_ = 0;
  int fd_ = -1;
  int burst_left_ = 0;
  std::vector<std::uint8_t> held_;
  Tally t_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"lbr-feed-serial — send a program's axis samples as serial frames"};
  std::string device, pty_link;
  int wait_ms = 10000;
  tools::FeedOptions o;
  SoakPlan soak;
  tools::add_feed_options(cli, o, 0.0, "1 = real time, 0 = as fast as the reader takes it");
  auto* dev = cli.add_option("--device", device, "Serial device to write to");
  cli.add_option("--pty-link", pty_link, "Create a pseudo-terminal and make PATH a symlink to its slave side")->excludes(dev);
  cli.add_option("--wait-reader-ms", wait_ms, "With --pty-link: wait this long for the reader to open the slave");
  cli.add_option("--garbage-every", o.faults.garbage_every, "Insert random garbage before every Nth frame");
  cli.add_option("--truncate-every", o.faults.truncate_every, "Cut every Nth frame short");
  cli.add_option("--duration-s", soak.duration_s, "Loop the program (forwards, then backwards) for this many seconds of samples")
      ->check(CLI::Range(0.0, 1e6));
  cli.add_option("--disconnect-every-s", soak.disconnect_every_s, "With --pty-link: hang up this often [s]")->check(CLI::Range(0.0, 1e6));
  cli.add_option("--disconnect-ms", soak.disconnect_ms, "... for this long; the samples due meanwhile are not sent")
      ->check(CLI::Range(0, 60000))
      ->capture_default_str();
  cli.add_option("--burst-every", soak.burst_every, "Hold back every Nth frame and the ones after it, then write them at once");
  cli.add_option("--burst-len", soak.burst_len, "Frames per burst")->check(CLI::Range(1, 100000))->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  if (device.empty() == pty_link.empty()) {
    std::fprintf(stderr, "lbr-feed-serial: give --device or --pty-link\n");
    return 2;
  }
  try {
    auto [profile, stream] = tools::load_feed(o);
    const std::size_t program_samples = stream.counts.size();
    int fd = -1;
    if (!device.empty()) {
      fd = ::open(device.c_str(), O_WRONLY | O_NOCTTY);
      if (fd < 0) throw std::runtime_error(device + ": " + std::strerror(errno));
    }
    SerialFeeder feeder(o, soak, std::move(profile), std::move(stream));
    const Tally t = feeder.run(fd, pty_link, wait_ms);
    nlohmann::json j{{"samples", t.generated},
                     {"program_samples", program_samples},
                     {"frames_sent", t.sent},
                     {"corrupted", t.corrupted},
                     {"garbage", t.garbage},
                     {"truncated", t.truncated},
                     {"dropped", t.dropped},
                     {"duplicated", t.duplicated},
                     {"disconnects", t.disconnects},
                     {"not_sent_disconnected", t.not_sent_disconnected},
                     {"bursts", t.bursts}};
    std::printf("%s\n", j.dump().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lbr-feed-serial: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
