// lbr-feed-serial — streams a program's samples as serial frames (docs/protocols.md#serial)
// to a device, or to a pseudo-terminal it creates (--pty-link), paced in real time, with
// seeded fault injection. Prints what it sent and injected as JSON on stdout.
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"lbr-feed-serial — send a program's axis samples as serial frames"};
  std::string device, pty_link;
  int wait_ms = 10000;
  tools::FeedOptions o;
  tools::add_feed_options(cli, o, 0.0, "1 = real time, 0 = as fast as the reader takes it");
  auto* dev = cli.add_option("--device", device, "Serial device to write to");
  cli.add_option("--pty-link", pty_link, "Create a pseudo-terminal and make PATH a symlink to its slave side")->excludes(dev);
  cli.add_option("--wait-reader-ms", wait_ms, "With --pty-link: wait this long for the reader to open the slave");
  cli.add_option("--garbage-every", o.faults.garbage_every, "Insert random garbage before every Nth frame");
  cli.add_option("--truncate-every", o.faults.truncate_every, "Cut every Nth frame short");
  CLI11_PARSE(cli, argc, argv);
  if (device.empty() == pty_link.empty()) {
    std::fprintf(stderr, "lbr-feed-serial: give --device or --pty-link\n");
    return 2;
  }
  try {
    const auto [profile, stream] = tools::load_feed(o);
    const tools::FaultPlan& f = o.faults;
    int fd = -1;
    if (!pty_link.empty()) {
      int master = -1, slave = -1;
      if (openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) throw std::runtime_error(std::string("openpty: ") + std::strerror(errno));
      termios t{};
      tcgetattr(slave, &t);
      cfmakeraw(&t);
      tcsetattr(slave, TCSANOW, &t);
      const std::string name = ttyname(slave);
      std::filesystem::remove(pty_link);
      std::filesystem::create_symlink(name, pty_link);
      ::close(slave);
      // While no slave fd is open the master reports POLLHUP: wait for the reader.
      const std::int64_t deadline = sched::now_ns() + static_cast<std::int64_t>(wait_ms) * 1'000'000;
      for (;;) {
        pollfd p{master, POLLOUT, 0};
        ::poll(&p, 1, 0);
        if (!(p.revents & POLLHUP)) break;
        if (sched::now_ns() > deadline) throw std::runtime_error("no reader opened " + pty_link);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));  // let the reader finish its setup
      fd = master;
    } else {
      fd = ::open(device.c_str(), O_WRONLY | O_NOCTTY);
      if (fd < 0) throw std::runtime_error(device + ": " + std::strerror(errno));
    }

    std::mt19937_64 rng(f.seed);
    std::uint64_t sent = 0, corrupted = 0, garbage = 0, truncated = 0, dropped = 0, duplicated = 0;
    if (o.priority > 0) (void)sched::configure_current_thread(sched::RtConfig{"lbr-feed", o.priority, -1, true});
    const std::int64_t t0 = sched::now_ns();
    const auto period_ns = static_cast<std::int64_t>(stream.period_s * 1e9);
    int n_pos = 0;
    for (const hal::AxisMap& m : profile.live.axes) n_pos = std::max(n_pos, m.index + 1);
    for (std::size_t k = 0; k < stream.counts.size(); ++k) {
      if (o.speed > 0) sched::sleep_until_ns(t0 + static_cast<std::int64_t>(static_cast<double>(k) * static_cast<double>(period_ns) / o.speed));
      hal::SerialFrame fr;
      fr.seq = static_cast<std::uint32_t>(k);
      fr.t_us = static_cast<std::uint64_t>((sched::now_ns() - t0) / 1000);
      fr.n = n_pos;
      for (std::size_t a = 0; a < profile.live.axes.size(); ++a)
        fr.pos[static_cast<std::size_t>(profile.live.axes[a].index)] = stream.counts[k][a];
      std::array<std::uint8_t, hal::kSerialMaxFrame> b{};
      std::size_t len = hal::encode_serial_frame(fr, b);
      if (tools::FaultPlan::hit(f.drop_every, k)) {
        ++dropped;
        continue;
      }
      if (tools::FaultPlan::hit(f.garbage_every, k)) {
        std::array<std::uint8_t, 24> g{};
        const std::size_t gl = 1 + rng() % g.size();
        for (std::size_t i = 0; i < gl; ++i) g[i] = static_cast<std::uint8_t>(rng());
        g[0] = hal::kSerialSync0;  // a false sync start makes the resync work harder
        if (!write_all(fd, g.data(), gl)) break;
        ++garbage;
      }
      if (tools::FaultPlan::hit(f.corrupt_every, k)) {
        b[3 + rng() % (len - 3)] ^= static_cast<std::uint8_t>(1U << (rng() % 8));
        ++corrupted;
      } else if (tools::FaultPlan::hit(f.truncate_every, k)) {
        len = 3 + rng() % (len - 4);
        ++truncated;
      }
      if (!write_all(fd, b.data(), len)) break;
      if (tools::FaultPlan::hit(f.duplicate_every, k)) {
        if (!write_all(fd, b.data(), len)) break;
        ++duplicated;
      }
      ++sent;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // let the reader drain
    ::close(fd);
    if (!pty_link.empty()) std::filesystem::remove(pty_link);
    nlohmann::json j{{"samples", stream.counts.size()}, {"frames_sent", sent},   {"corrupted", corrupted},
                     {"garbage", garbage},              {"truncated", truncated}, {"dropped", dropped},
                     {"duplicated", duplicated}};
    std::printf("%s\n", j.dump().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lbr-feed-serial: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
