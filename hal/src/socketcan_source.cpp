// SocketCanSource: raw CAN socket with kernel filters (SYNC + mapped TPDOs + error
// frames), SO_TIMESTAMP receive times, bus-off / interface-down detection and periodic
// reconnection. Exercised in the HIL VM (this development kernel has no AF_CAN).
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "hal/source.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::hal {

namespace {

class SocketCanSource final : public Source {
 public:
  SocketCanSource(std::string iface, const LiveConfig& cfg) : iface_(std::move(iface)), cfg_(fill(cfg)), asm_(cfg_) {
    if (iface_.empty() || iface_.size() >= IFNAMSIZ) throw std::invalid_argument("can: bad interface name '" + iface_ + "'");
    filters_.push_back({cfg_.can.sync_id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
    for (const AxisMap& m : cfg_.axes)
      filters_.push_back({cfg_.can.tpdo_base + static_cast<canid_t>(m.node), CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
    reconnect_ns_ = static_cast<std::int64_t>(cfg_.can.reconnect_ms * 1e6);
  }
  ~SocketCanSource() override { close(); }

  void open() override {
    std::string err;
    if (!connect(err)) throw std::runtime_error("can:" + iface_ + ": " + err);
  }

  PollResult poll(int timeout_ms, SampleSink& sink) noexcept override {
    if (fd_ < 0) {
      const std::int64_t now = sched::now_ns();
      if (now < retry_at_) {
        const std::int64_t limit = now + static_cast<std::int64_t>(timeout_ms) * 1'000'000;
        sched::sleep_until_ns(std::min(limit, retry_at_));
        return PollResult::Idle;
      }
      if (!connect_noexcept()) {
        retry_at_ = now + reconnect_ns_;
        return PollResult::Error;
      }
      counters_.add(Fault::Reconnect);
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, timeout_ms);
    if (r == 0) return PollResult::Idle;
    if (r < 0) return errno == EINTR ? PollResult::Idle : PollResult::Error;
    can_frame cf{};
    iovec iov{&cf, sizeof(cf)};
    alignas(cmsghdr) char ctrl[CMSG_SPACE(sizeof(timeval))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = ctrl;
    msg.msg_controllen = sizeof(ctrl);
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) return PollResult::Idle;
      // ENETDOWN: interface down; anything else: treat the same and reconnect later.
      counters_.add(errno == ENETDOWN ? Fault::BusOff : Fault::ReadError);
      drop();
      return PollResult::Error;
    }
    if (static_cast<std::size_t>(n) < sizeof(can_frame)) {
      counters_.add(Fault::ReadError);
      return PollResult::Error;
    }
    CanFrame f;
    f.t_ns = wall_ns();
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMP) {
        timeval tv{};
        std::memcpy(&tv, CMSG_DATA(c), sizeof(tv));
        f.t_ns = static_cast<std::int64_t>(tv.tv_sec) * 1'000'000'000 + static_cast<std::int64_t>(tv.tv_usec) * 1000;
      }
    }
    f.err = (cf.can_id & CAN_ERR_FLAG) != 0;
    f.ext = (cf.can_id & CAN_EFF_FLAG) != 0;
    f.rtr = (cf.can_id & CAN_RTR_FLAG) != 0;
    f.id = cf.can_id & (f.ext || f.err ? CAN_EFF_MASK : CAN_SFF_MASK);
    f.len = std::min<std::uint8_t>(cf.len, 8);
    std::memcpy(f.data.data(), cf.data, f.len);
    if (record_) {
      RawRecord rec;
      rec.frame = f;
      rec.t_wall_ns = f.t_ns;
      sink.on_raw(rec);
    }
    if (f.err && (f.id & CAN_ERR_BUSOFF)) {
      counters_.add(Fault::BusOff);
      counters_.add(Fault::ErrorFrame);
      drop();
      return PollResult::Error;
    }
    const int k = asm_.on_frame(f, sched::now_ns(), out_, counters_);
    if (k > 0) sink.on_samples(std::span<const AxisSample>(out_.data(), static_cast<std::size_t>(k)));
    return PollResult::Data;
  }

  void close() noexcept override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  [[nodiscard]] std::string describe() const override { return "can:" + iface_; }
  [[nodiscard]] std::uint64_t lost() const noexcept override { return asm_.lost(); }

 private:
  static LiveConfig fill(LiveConfig c) {
    if (c.axes.empty()) c.axes = default_axes();
    return c;
  }
  void drop() noexcept {
    close();
    retry_at_ = sched::now_ns() + reconnect_ns_;
  }
  bool connect_noexcept() noexcept {
    const char* what = nullptr;
    return connect_impl(what);
  }
  bool connect(std::string& err) {
    const char* what = nullptr;
    if (connect_impl(what)) return true;
    const int e = errno;
    err = std::string(what) + ": " + std::strerror(e) + hint(e, what);
    return false;
  }
  // What to do about the usual set-up faults (issue 19): the message alone names a socket
  // call, not the missing kernel module or interface.
  [[nodiscard]] std::string hint(int e, const char* what) const {
    const std::string up = "`sudo ip link set " + iface_ + " up type can bitrate 1000000` (a real adapter; its bitrate) "
                           "or a virtual bus: `sudo ip link add dev " + iface_ + " type vcan && sudo ip link set " + iface_ + " up`";
    if (e == EAFNOSUPPORT || e == EPROTONOSUPPORT)
      return ". This kernel has no SocketCAN (AF_CAN): load the modules with `sudo modprobe can can_raw` and, for a "
             "virtual bus, `sudo modprobe vcan` (or the adapter's driver, e.g. gs_usb, peak_usb); then bring the "
             "interface up: " + up + ". Containers and WSL kernels often lack CAN entirely: run on the host, or "
             "try tools/hil/hil-bench.sh (vcan in a VM)";
    if (std::string(what) == "no such interface")
      return ". Create it: " + up + " (`ip -details link show type can` lists CAN interfaces)";
    if (e == ENETDOWN) return ". Bring it up: " + up;
    return "";
  }
  bool connect_impl(const char*& what) noexcept {
    const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (s < 0) {
      what = "socket(PF_CAN)";
      return false;
    }
    auto fail = [&](const char* w) {
      const int e = errno;
      ::close(s);
      errno = e;
      what = w;
      return false;
    };
    ifreq ifr{};
    std::memcpy(ifr.ifr_name, iface_.c_str(), iface_.size() + 1);
    if (::ioctl(s, SIOCGIFINDEX, &ifr) < 0) return fail("no such interface");
    if (::ioctl(s, SIOCGIFFLAGS, &ifr) < 0) return fail("SIOCGIFFLAGS");
    if (!(ifr.ifr_flags & IFF_UP)) {
      errno = ENETDOWN;
      return fail("interface is down");
    }
    if (::ioctl(s, SIOCGIFINDEX, &ifr) < 0) return fail("SIOCGIFINDEX");
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, filters_.data(),
                     static_cast<socklen_t>(filters_.size() * sizeof(can_filter))) < 0)
      return fail("CAN_RAW_FILTER");
    const can_err_mask_t errmask = CAN_ERR_MASK;
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errmask, sizeof(errmask)) < 0) return fail("CAN_RAW_ERR_FILTER");
    const int on = 1;
    if (::setsockopt(s, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof(on)) < 0) return fail("SO_TIMESTAMP");
    const int rcvbuf = 1 << 20;
    ::setsockopt(s, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));  // best effort
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) < 0) return fail("bind");
    fd_ = s;
    return true;
  }

  std::string iface_;
  LiveConfig cfg_;
  CanopenAssembler asm_;
  std::vector<can_filter> filters_;
  int fd_ = -1;
  std::int64_t retry_at_ = 0, reconnect_ns_ = 500'000'000;
  std::array<AxisSample, kMaxChannels> out_{};
};

}  // namespace

std::unique_ptr<Source> make_socketcan_source(const std::string& iface, const LiveConfig& cfg) {
  return std::make_unique<SocketCanSource>(iface, cfg);
}

}  // namespace lbr::hal
