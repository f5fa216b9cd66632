// lbr-feed-can — streams a program's samples on a SocketCAN interface in the CANopen-style
// format (docs/protocols.md#can): SYNC with counter, then one TPDO per mapped node, paced
// in real time, with seeded fault injection. Prints what it sent and injected as JSON.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "feed_common.hpp"
#include "sched/rt_thread.hpp"

using namespace lbr;

int main(int argc, char** argv) {
  CLI::App cli{"lbr-feed-can — send a program's axis samples as CANopen-style SYNC + TPDOs"};
  std::string iface = "vcan0";
  bool status_word = false;
  tools::FeedOptions o;
  tools::add_feed_options(cli, o, 0.001, "1 = real time");
  cli.add_option("--iface", iface, "CAN interface")->capture_default_str();
  cli.add_flag("--statusword", status_word, "Send 6-byte TPDOs with a statusword");
  CLI11_PARSE(cli, argc, argv);
  const tools::FaultPlan& f = o.faults;
  try {
    const auto [profile, stream] = tools::load_feed(o);
    const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (s < 0) throw std::runtime_error(std::string("socket(PF_CAN): ") + std::strerror(errno));
    ifreq ifr{};
    std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", iface.c_str());
    if (::ioctl(s, SIOCGIFINDEX, &ifr) < 0) throw std::runtime_error(iface + ": " + std::strerror(errno));
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) < 0) throw std::runtime_error(std::string("bind: ") + std::strerror(errno));
    std::uint64_t send_errors = 0;  // e.g. ENETDOWN while the interface is down: counted, go on
    auto send = [&](const can_frame& fr) {
      for (int tries = 0; tries < 50; ++tries) {
        if (::write(s, &fr, sizeof(fr)) == static_cast<ssize_t>(sizeof(fr))) return true;
        if (errno != ENOBUFS && errno != EAGAIN && errno != EINTR) break;
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
      ++send_errors;
      return true;
    };
    std::uint64_t syncs = 0, tpdos = 0, corrupted = 0, dropped = 0, duplicated = 0, k_tpdo = 0;
    if (o.priority > 0) (void)sched::configure_current_thread(sched::RtConfig{"lbr-feed", o.priority, -1, true});
    const std::int64_t t0 = sched::now_ns();
    const auto period_ns = static_cast<std::int64_t>(stream.period_s * 1e9);
    int counter = 0;
    for (std::size_t k = 0; k < stream.counts.size(); ++k) {
      sched::sleep_until_ns(t0 + static_cast<std::int64_t>(static_cast<double>(k) * static_cast<double>(period_ns) / o.speed));
      can_frame sy{};
      sy.can_id = profile.live.can.sync_id;
      counter = counter % profile.live.can.sync_counter_max + 1;
      sy.len = 1;
      sy.data[0] = static_cast<std::uint8_t>(counter);
      if (!send(sy)) throw std::runtime_error(std::string("write: ") + std::strerror(errno));
      ++syncs;
      for (std::size_t a = 0; a < profile.live.axes.size(); ++a, ++k_tpdo) {
        const hal::AxisMap& m = profile.live.axes[a];
        can_frame t{};
        t.can_id = profile.live.can.tpdo_base + static_cast<canid_t>(m.node);
        const auto u = static_cast<std::uint32_t>(stream.counts[k][a]);
        for (int i = 0; i < 4; ++i) t.data[i] = static_cast<std::uint8_t>(u >> (8 * i));
        t.len = status_word ? 6 : 4;
        if (status_word) t.data[4] = 0x37;  // DS402 "operation enabled"
        if (tools::FaultPlan::hit(f.drop_every, k_tpdo)) {
          ++dropped;
          continue;
        }
        if (tools::FaultPlan::hit(f.corrupt_every, k_tpdo)) {
          t.len = 3;
          ++corrupted;
        }
        if (!send(t)) throw std::runtime_error(std::string("write: ") + std::strerror(errno));
        ++tpdos;
        if (tools::FaultPlan::hit(f.duplicate_every, k_tpdo)) {
          send(t);
          ++duplicated;
        }
      }
    }
    ::close(s);
    nlohmann::json j{{"samples", stream.counts.size()}, {"syncs", syncs},   {"tpdos", tpdos},
                     {"corrupted", corrupted},          {"dropped", dropped}, {"duplicated", duplicated},
                     {"send_errors", send_errors}};
    std::printf("%s\n", j.dump().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lbr-feed-can: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
