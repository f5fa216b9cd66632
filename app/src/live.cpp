#include "app/live.hpp"

#include <algorithm>
#include <cinttypes>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/batch.hpp"
#include "app/outputs.hpp"
#include "geom/serialize.hpp"
#include "hal/source.hpp"
#include "hal/validate.hpp"
#include "kin/kinematics.hpp"
#include "sched/rt_thread.hpp"
#include "sched/spsc_ring.hpp"

namespace lbr::app {

namespace {

using hal::AxisSample;

// ---- emulator source: the nc machine emulator at the live sample period ----
class EmulatorGenerator final : public hal::SampleGenerator {
 public:
  EmulatorGenerator(const nc::Toolpath& path, const nc::EmulatorLimits& limits) : emu_(path, limits) {}
  bool next(std::array<double, hal::kMaxAxes>& q, int& tool) noexcept override {
    nc::Sample s;
    if (!emu_.next(s)) return false;
    for (std::size_t a = 0; a < q.size(); ++a) q[a] = s.axes[a];
    tool = s.tool;
    return true;
  }

 private:
  nc::Emulator emu_;
};

std::unique_ptr<hal::Source> make_source(const Profile& profile, const LiveOptions& opt) {
  const auto colon = opt.source.find(':');
  if (colon == std::string::npos || colon + 1 >= opt.source.size())
    throw std::runtime_error("--source '" + opt.source + "': expected can:IF, serial:DEV, replay:FILE or emulator:PROGRAM");
  const std::string kind = opt.source.substr(0, colon), arg = opt.source.substr(colon + 1);
  if (kind == "can") return hal::make_socketcan_source(arg, profile.live);
  if (kind == "serial") return hal::make_serial_source(arg, profile.live);
  if (kind == "replay") return hal::make_replay_source(arg, profile.live, opt.speed);
  if (kind == "emulator") {
    const nc::Toolpath path = arg == "demo" ? demo_toolpath() : load_toolpath(arg, profile);
    for (const nc::Segment& sg : path.segments)
      if (sg.tool != 0 && !profile.tools.count(sg.tool) && !profile.inserts.count(sg.tool))
        throw std::runtime_error(path.source + ":" + std::to_string(sg.line) + ": tool " + std::to_string(sg.tool) +
                                 " is not in the tool table of " + profile.source);
    return hal::make_generator_source(std::make_unique<EmulatorGenerator>(path, live_emulator_limits(profile)), arg,
                                      profile.live, opt.speed);
  }
  throw std::runtime_error("--source '" + opt.source + "': unknown kind '" + kind + "' (can, serial, replay, emulator)");
}

// HAL side: validation, then the ring. Runs on the HAL thread.
class RingSink final : public hal::SampleSink {
 public:
  RingSink(sched::SpscRing<AxisSample>& ring, sched::SpscRing<hal::RawRecord>* rec, const hal::LiveConfig& cfg,
           bool backpressure, const std::atomic<bool>& stop)
      : ring_(ring), rec_(rec), validator_(cfg), backpressure_(backpressure), stop_(stop) {}

  void on_samples(std::span<const AxisSample> samples) noexcept override {
    for (const AxisSample& s : samples) {
      received_.store(received_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      if (!validator_.accept(s, counters_)) {
        rejected_.store(rejected_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        continue;
      }
      if (backpressure_) {
        // Not a live source: wait for room rather than drop (never counts an overrun).
        while (ring_.size() >= ring_.capacity()) {
          if (stop_.load(std::memory_order_relaxed)) return;
          sched::sleep_until_ns(sched::now_ns() + 100'000);
        }
      }
      (void)ring_.try_push(s);  // a refused push is counted by the ring (ring_overruns)
    }
  }
  void on_raw(const hal::RawRecord& r) noexcept override {
    if (rec_ != nullptr && !rec_->try_push(r))
      rec_overruns_.store(rec_overruns_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t received() const noexcept { return received_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t rejected() const noexcept { return rejected_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t rec_overruns() const noexcept { return rec_overruns_.load(std::memory_order_relaxed); }
  [[nodiscard]] const hal::Counters& counters() const noexcept { return counters_; }

 private:
  sched::SpscRing<AxisSample>& ring_;
  sched::SpscRing<hal::RawRecord>* rec_;
  hal::Validator validator_;
  bool backpressure_;
  const std::atomic<bool>& stop_;
  hal::Counters counters_;
  std::atomic<std::uint64_t> received_{0}, rejected_{0}, rec_overruns_{0};
};

// Geometry side: drains the ring, maps samples through the channel's kinematics
// (docs/machine-kinds.md), merges straight runs per channel, subtracts.
class Geometry {
 public:
  static constexpr std::size_t kMaxRun = 256;

  // A tool as the geometry thread sees it: a milling cutter or a turning insert, its mount.
  struct ToolRef {
    const geom::CutterShape* shape = nullptr;
    const geom::TurningShape* turning = nullptr;
    kin::Mount mount = kin::Mount::Spindle;
    double length_mm = 0.0, reach_mm = 0.0;
    [[nodiscard]] bool cuts() const noexcept { return shape != nullptr || turning != nullptr; }
    [[nodiscard]] bool same(const ToolRef& o) const noexcept { return shape == o.shape && turning == o.turning; }
  };

  // `shapes`/`inserts`: every tool of the profile; `default_tool` cuts for samples without a
  // tool number. Tool numbers without a shape (0 = empty spindle) cut nothing.
  Geometry(geom::LbrSolid& solid, const Profile& profile, const std::map<int, geom::CutterShape>& shapes,
           const std::map<int, geom::TurningShape>& inserts, int default_tool, sched::SpscRing<AxisSample>& ring,
           double tol_mm)
      : solid_(solid), ring_(ring), tol_(tol_mm) {
    for (const auto& [n, sh] : shapes)
      tools_[n] = ToolRef{&sh, nullptr, profile.mount_of(n), sh.tool.length_mm, std::hypot(sh.height(), sh.radius())};
    for (const auto& [n, sh] : inserts) tools_[n] = ToolRef{nullptr, &sh, kin::Mount::Turning, 0.0, 0.0};
    default_tool_ = lookup(default_tool);
    for (std::size_t i = 0; i < kins_.size(); ++i)
      kins_[i] = i < profile.channels.size() ? profile.channels[i].kin : profile.kin;
    const std::size_t cap = ring.capacity();
    batch_.reserve(2 * cap + hal::kMaxChannels + kin::kMaxSubsteps);
    rx_.resize(cap);
    for (Channel& c : ch_) c.run.reserve(kMaxRun + 1);
  }

  // Applies what is in the ring, at most `limit` samples; returns the samples applied.
  std::size_t tick(std::size_t limit) noexcept {
    batch_.clear();
    std::size_t n = 0;
    limit = std::min(limit, rx_.size());
    while (n < limit) {
      AxisSample* s = ring_.front();
      if (s == nullptr) break;
      take(*s);
      rx_[n++] = s->t_rx_ns;
      ring_.pop();
    }
    for (Channel& c : ch_) flush(c);
    if (!batch_.empty()) {
      const std::int64_t t_start = sched::now_ns();
      solid_.subtract(batch_, ws_);
      work_.record(sched::now_ns() - t_start);
      sweeps_.store(sweeps_.load(std::memory_order_relaxed) + batch_.size(), std::memory_order_relaxed);
      batches_.store(batches_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    }
    if (n > 0) {
      last_rx_ns_ = rx_[n - 1];
      const std::int64_t t = sched::now_ns();
      for (std::size_t i = 0; i < n; ++i) lag_.record(t - rx_[i]);
      applied_.store(applied_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
      if (++ticks_since_volume_ >= 50) publish_volume();
    }
    return n;
  }

  // Rendering: tip points go to the exchange's path buffer (no allocation).
  void set_exchange(gfx::SolidExchange* ex) noexcept { ex_ = ex; }
  // Publishes the solid to the render side between batches (never waits; see
  // gfx/exchange.hpp). Tools: one per channel holding a milling cutter, at its latest pose.
  bool publish(const gfx::LiveStats& stats) noexcept {
    if (ex_ == nullptr) return false;
    std::array<gfx::ToolState, gfx::kMaxTools> tools{};
    std::size_t n = 0;
    for (std::size_t i = 0; i < ch_.size() && n < tools.size(); ++i) {
      const Channel& c = ch_[i];
      if (!c.have || c.tool.shape == nullptr || c.run.empty()) continue;
      tools[n++] = gfx::tool_state(c.tool.shape->tool, 1, c.run.back(), static_cast<int>(i));
    }
    return ex_->publish(solid_, std::span<const gfx::ToolState>(tools.data(), n), last_id_, stats);
  }
  [[nodiscard]] std::int64_t last_rx_ns() const noexcept { return last_rx_ns_; }

  void publish_volume() noexcept {
    ticks_since_volume_ = 0;
    removed_.store(solid_.initial_volume_mm3() - solid_.volume_mm3(), std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t applied() const noexcept { return applied_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t sweeps() const noexcept { return sweeps_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t batches() const noexcept { return batches_.load(std::memory_order_relaxed); }
  [[nodiscard]] double removed_mm3() const noexcept { return removed_.load(std::memory_order_relaxed); }
  [[nodiscard]] const sched::LatencyHistogram& lag() const noexcept { return lag_; }
  // Duration of each tick's subtract() (the geometry thread's work per batch).
  [[nodiscard]] const sched::LatencyHistogram& work() const noexcept { return work_; }

 private:
  struct Channel {
    bool have = false;
    nc::AxisVector q{};              // latest axis values (end of the pending run)
    ToolRef tool;                    // tool of the pending run
    std::vector<geom::Pose> run;     // run[0] = start of the pending sweep, then its samples
    std::uint64_t seq = 0;
  };

  [[nodiscard]] ToolRef lookup(int tool) const noexcept {
    const auto it = tools_.find(tool);  // no allocation
    return it == tools_.end() ? ToolRef{} : it->second;
  }

  // Distance of p from the segment a–b [mm].
  static double dist_to_segment(geom::Vec3 p, geom::Vec3 a, geom::Vec3 b) noexcept {
    const geom::Vec3 d = b - a;
    const double dd = geom::dot(d, d);
    const double t = dd > 0 ? std::clamp(geom::dot(p - a, d) / dd, 0.0, 1.0) : 0.0;
    return geom::norm(p - geom::lerp(a, b, t));
  }

  void push(const Channel& c, const geom::Pose& from, const geom::Pose& to) noexcept {
    if (!c.tool.cuts()) return;
    geom::SweepRef r;
    r.shape = c.tool.shape;
    r.turning = c.tool.turning;
    r.from = from;
    r.to = to;
    r.id = static_cast<geom::MoveId>(c.seq & 0xFFFFFFFFU);
    last_id_ = r.id;
    if (ex_ != nullptr) ex_->add_path_point(to.tip);
    if (batch_.size() == batch_.capacity()) {  // capacity reserved at start-up: subtract early
      solid_.subtract(batch_, ws_);
      batch_.clear();
    }
    batch_.push_back(r);
  }

  void take(const AxisSample& s) noexcept {
    if (s.channel >= hal::kMaxChannels) return;
    Channel& c = ch_[s.channel];
    const kin::Kinematics& k = kins_[s.channel];
    nc::AxisVector q = c.q;
    for (int a = 0; a < nc::kAxes && a < static_cast<int>(hal::kMaxAxes); ++a)
      if (s.mask & (1U << a)) q[a] = s.q[static_cast<std::size_t>(a)];
    c.seq = s.seq;
    const ToolRef tool = s.tool >= 0 ? lookup(s.tool) : default_tool_;
    if (c.have && !tool.same(c.tool)) {  // tool change: the pending run belongs to the old tool
      flush(c);
      c.tool = tool;
      c.run.clear();
      c.run.push_back(kin::tool_pose(k, c.q, tool.mount, tool.length_mm));
    }
    if (!c.have) {  // first sample: where the tool is; nothing to cut yet
      c.have = true;
      c.tool = tool;
      c.q = q;
      c.run.clear();
      c.run.push_back(kin::tool_pose(k, q, tool.mount, tool.length_mm));
      return;
    }
    if (q == c.q) return;  // standing still
    const ToolRef& t = c.tool;
    const int n = t.cuts() ? kin::substeps(k, c.q, q, t.mount, t.length_mm, t.reach_mm, tol_) : 1;
    if (n > 1) {
      // Rotary axes moved the tool along a curve: chords within the tolerance.
      flush(c);
      geom::Pose from = c.run.back();
      for (int i = 1; i <= n; ++i) {
        nc::AxisVector qi = q;
        if (i < n)
          for (int a = 0; a < nc::kAxes; ++a) qi[a] = c.q[a] + (q[a] - c.q[a]) * i / n;
        const geom::Pose to = kin::tool_pose(k, qi, t.mount, t.length_mm);
        push(c, from, to);
        from = to;
      }
      c.run.clear();
      c.run.push_back(from);
      c.q = q;
      return;
    }
    const geom::Pose p = kin::tool_pose(k, q, t.mount, t.length_mm);
    if (c.run.size() >= 2) {
      // Replace the run's straight sweep run[0]→last by run[0]→p only if the tool axis stays
      // put and every sample of the run stays within the tolerance of the longer sweep:
      // geometry stays exact.
      bool straight = c.run.size() < kMaxRun && p.axis == c.run[0].axis && c.run.back().axis == c.run[0].axis;
      for (std::size_t i = 1; straight && i < c.run.size(); ++i)
        straight = dist_to_segment(c.run[i].tip, c.run[0].tip, p.tip) <= tol_;
      if (!straight) flush(c);
    }
    c.run.push_back(p);
    c.q = q;
  }

  void flush(Channel& c) noexcept {
    if (c.run.size() < 2) return;
    push(c, c.run.front(), c.run.back());
    const geom::Pose end = c.run.back();
    c.run.clear();
    c.run.push_back(end);
  }

  geom::LbrSolid& solid_;
  std::map<int, ToolRef> tools_;
  ToolRef default_tool_;
  std::array<kin::Kinematics, hal::kMaxChannels> kins_{};
  sched::SpscRing<AxisSample>& ring_;
  double tol_;
  geom::SubtractWorkspace ws_;
  std::vector<geom::SweepRef> batch_;
  std::vector<std::int64_t> rx_;
  std::array<Channel, hal::kMaxChannels> ch_;
  sched::LatencyHistogram lag_, work_;
  std::atomic<std::uint64_t> applied_{0}, sweeps_{0}, batches_{0};
  std::atomic<double> removed_{0.0};
  int ticks_since_volume_ = 0;
  gfx::SolidExchange* ex_ = nullptr;
  geom::MoveId last_id_ = 0;
  std::int64_t last_rx_ns_ = 0;
};

void write_record_line(std::FILE* f, const hal::RawRecord& r, const std::string& iface) {
  char line[256];
  if (r.serial) {
    const long long sec = r.t_wall_ns / 1'000'000'000, usec = (r.t_wall_ns % 1'000'000'000) / 1000;
    int n = std::snprintf(line, sizeof line, "(%lld.%06lld) serial #", sec, usec);
    for (std::uint16_t i = 0; i < r.len && n + 3 < static_cast<int>(sizeof line); ++i)
      n += std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), "%02X", r.bytes[i]);
    std::fputs(line, f);
    std::fputc('\n', f);
  } else {
    hal::CanFrame fr = r.frame;
    fr.t_ns = r.t_wall_ns;
    const std::size_t n = hal::format_candump_line(fr, iface, line);
    std::fwrite(line, 1, n, f);
  }
}

}  // namespace

LiveResult run_live(const Profile& profile, const LiveOptions& opt, const std::atomic<bool>& stop, const StatusFn& status) {
  const hal::LiveConfig& cfg = profile.live;
  if (!profile.tools.count(cfg.tool) && !profile.inserts.count(cfg.tool))
    throw std::runtime_error(profile.source + ": live.tool " + std::to_string(cfg.tool) + " is not in the tool table");
  std::map<int, geom::CutterShape> shapes;
  std::map<int, geom::TurningShape> inserts;
  double dmax = 1.0;
  for (const auto& [n, t] : profile.tools) {
    shapes.emplace(n, geom::CutterShape::build(t, profile.solid.chord_tol_mm));
    dmax = std::max(dmax, t.diameter_mm);
  }
  for (const auto& [n, t] : profile.inserts) inserts.emplace(n, geom::TurningShape::build(t, profile.solid.chord_tol_mm));
  geom::SolidSpec spec = profile.solid;
  if (profile.regions_auto) std::tie(spec.regions_x, spec.regions_y) = auto_region_grid(spec, dmax);
  LiveResult r{geom::LbrSolid(spec), opt.source, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, {}, 0, 0, 0, 0, 0, 0, ""};
  r.stock_volume_mm3 = r.solid.initial_volume_mm3();

  std::unique_ptr<hal::Source> src = make_source(profile, opt);
  src->open();
  const bool backpressure = !src->live();

  sched::SpscRing<AxisSample> ring(cfg.ring_capacity);
  std::unique_ptr<sched::SpscRing<hal::RawRecord>> rec_ring;
  std::FILE* rec_file = nullptr;
  if (!opt.record.empty()) {
    rec_file = std::fopen(opt.record.c_str(), "w");
    if (rec_file == nullptr) throw std::runtime_error(opt.record + ": cannot open for writing");
    rec_ring = std::make_unique<sched::SpscRing<hal::RawRecord>>(1 << 15);
    src->set_recording(true);
  }
  std::string rec_iface = "can0";
  if (opt.source.rfind("can:", 0) == 0) rec_iface = opt.source.substr(4);

  RingSink sink(ring, rec_ring.get(), cfg, backpressure, stop);
  Geometry geo(r.solid, profile, shapes, inserts, cfg.tool, ring, cfg.merge_tolerance_mm);
  geo.set_exchange(opt.exchange);
  if (opt.on_start) opt.on_start(r.solid);
  r.solid.clear_dirty();  // the render side starts from this state

  std::atomic<bool> hal_done{false}, rec_done{false};
  std::atomic<int> hal_mode{-1};
  std::atomic<std::uint64_t> source_lost{0};
  const std::int64_t t0 = sched::now_ns();

  // Geometry thread: apply whatever is in the ring at once; when it was empty, look again
  // after geometry_idle_us (so a sample waits at most that long before work starts).
  // Sources that are not live (replay/emulator as fast as possible) are applied in chunks
  // of exactly lbr.batch_moves samples, so such a run is reproducible bit for bit.
  const std::size_t chunk = backpressure ? static_cast<std::size_t>(profile.batch_moves) : ring.capacity();
  std::atomic<bool> geo_running{true};
  std::atomic<int> geo_mode{-1};
  const std::int64_t idle_ns = static_cast<std::int64_t>(cfg.geometry_idle_us) * 1000;
  // Counters for the HUD, filled by the geometry thread when it publishes (reads of
  // counters other threads own are relaxed atomics, as in the status line).
  auto live_stats = [&] {
    gfx::LiveStats st;
    st.live = true;
    const std::int64_t now = sched::now_ns();
    st.lag_ms = geo.last_rx_ns() > 0 ? static_cast<double>(now - geo.last_rx_ns()) * 1e-6 : 0.0;
    st.samples = geo.applied();
    st.sample_rate_hz = now > t0 ? static_cast<double>(sink.received()) / (static_cast<double>(now - t0) * 1e-9) : 0.0;
    st.ring_high_water = ring.high_water();
    st.ring_capacity = ring.capacity();
    st.ring_overruns = ring.overruns();
    st.decode_errors = src->counters().total() + sink.counters().total();
    st.realtime = hal_mode.load(std::memory_order_relaxed) == 1 && geo_mode.load(std::memory_order_relaxed) == 1;
    return st;
  };
  // Duty limit: after a tick that worked w, a live source's geometry thread rests
  // w·(1/duty − 1) before the next (samples queue meanwhile and merge into longer sweeps).
  // A SCHED_FIFO thread that keeps a core busy trips the kernel's real-time throttling
  // (sched_rt_runtime_us, by default 950 ms per second), which then stops it for the rest of
  // the second: measured 50–56 ms stalls and a lag p99 of 31 ms on the "high" workload at
  // 1 kHz without this limit.
  const double rest_per_work = backpressure ? 0.0 : 1.0 / cfg.geometry_duty - 1.0;
  std::thread geometry([&] {
    geo_mode = sched::configure_current_thread(cfg.geometry_thread) == sched::RtMode::Fifo ? 1 : 0;
    for (;;) {
      const bool finished = hal_done.load(std::memory_order_acquire);
      const std::int64_t t_tick = sched::now_ns();
      if ((finished || !backpressure || ring.size() >= chunk) && geo.tick(chunk) > 0) {
        if (opt.exchange != nullptr) (void)geo.publish(live_stats());
        if (rest_per_work > 0.0 && !finished) {
          const std::int64_t now = sched::now_ns();
          sched::sleep_until_ns(now + static_cast<std::int64_t>(static_cast<double>(now - t_tick) * rest_per_work));
        }
        continue;
      }
      if (finished && ring.front() == nullptr) break;
      sched::sleep_until_ns(sched::now_ns() + idle_ns);
    }
    // The final state must reach the render side: retry while it is busy (bounded: 2 s).
    for (int i = 0; opt.exchange != nullptr && i < 1000 && !geo.publish(live_stats()); ++i)
      sched::sleep_until_ns(sched::now_ns() + 2'000'000);
    geo.publish_volume();
    geo_running.store(false, std::memory_order_release);
  });
  std::thread hal_thread([&] {
    hal_mode = sched::configure_current_thread(cfg.hal_thread) == sched::RtMode::Fifo ? 1 : 0;
    while (!stop.load(std::memory_order_relaxed)) {
      const hal::PollResult pr = src->poll(50, sink);
      source_lost.store(src->lost(), std::memory_order_relaxed);  // the source is this thread's
      if (pr == hal::PollResult::End) break;
      if (pr == hal::PollResult::Error) sched::sleep_until_ns(sched::now_ns() + 1'000'000);  // no busy loop
    }
    hal_done.store(true, std::memory_order_release);
  });
  std::thread recorder;
  if (rec_ring) {
    recorder = std::thread([&] {
      for (;;) {
        const bool finished = hal_done.load(std::memory_order_acquire);
        bool any = false;
        while (hal::RawRecord* rec = rec_ring->front()) {
          write_record_line(rec_file, *rec, rec_iface);
          rec_ring->pop();
          any = true;
        }
        if (finished && !any) break;
        if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    });
  }

  auto snapshot = [&] {
    r.samples_received = sink.received();
    r.samples_applied = geo.applied();
    r.samples_rejected = sink.rejected();
    r.ring_overruns = ring.overruns();
    r.ring_high_water = ring.high_water();
    r.samples_lost = source_lost.load(std::memory_order_relaxed) + r.samples_rejected + r.ring_overruns;
    const auto& lag = geo.lag();
    r.lag_p50_ms = static_cast<double>(lag.percentile_ns(0.5)) * 1e-6;
    r.lag_p99_ms = static_cast<double>(lag.percentile_ns(0.99)) * 1e-6;
    r.lag_max_ms = static_cast<double>(lag.max_ns()) * 1e-6;
    r.batch_p50_ms = static_cast<double>(geo.work().percentile_ns(0.5)) * 1e-6;
    r.batch_p99_ms = static_cast<double>(geo.work().percentile_ns(0.99)) * 1e-6;
    r.batch_max_ms = static_cast<double>(geo.work().max_ns()) * 1e-6;
    r.removed_volume_mm3 = geo.removed_mm3();
  };
  std::int64_t next_status = t0 + static_cast<std::int64_t>(opt.status_period_s * 1e9);
  while (geo_running.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (status && sched::now_ns() >= next_status) {
      next_status += static_cast<std::int64_t>(opt.status_period_s * 1e9);
      snapshot();
      char line[320];
      std::snprintf(line, sizeof line,
                    "t %.1f s | rx %" PRIu64 " applied %" PRIu64 " lost %" PRIu64 " | ring hw %" PRIu64 "/%zu overruns %" PRIu64
                    " | lag p50 %.2f p99 %.2f max %.2f ms | removed %.1f mm3 | errors %" PRIu64,
                    static_cast<double>(sched::now_ns() - t0) * 1e-9, r.samples_received, r.samples_applied, r.samples_lost,
                    r.ring_high_water, ring.capacity(), r.ring_overruns, r.lag_p50_ms, r.lag_p99_ms, r.lag_max_ms,
                    r.removed_volume_mm3, src->counters().total() + sink.counters().total());
      status(line);
    }
  }
  hal_thread.join();
  geometry.join();
  if (recorder.joinable()) recorder.join();
  if (rec_file != nullptr) std::fclose(rec_file);
  src->close();

  r.wall_time_s = static_cast<double>(sched::now_ns() - t0) * 1e-9;
  geo.publish_volume();
  snapshot();
  r.removed_volume_mm3 = r.stock_volume_mm3 - r.solid.volume_mm3();
  r.ring_capacity = ring.capacity();
  r.sweeps = geo.sweeps();
  r.batches = geo.batches();
  r.record_overruns = sink.rec_overruns();
  for (int k = 0; k < hal::kFaultKinds; ++k) {
    const auto f = static_cast<hal::Fault>(k);
    r.decode_errors[hal::fault_name(f)] = src->counters().get(f) + sink.counters().get(f);
  }
  const bool fifo = hal_mode.load() == 1 && geo_mode.load() == 1;
  r.rt_mode = fifo ? "fifo" : "non-rt";
  return r;
}

std::string live_metrics_json(const LiveResult& r, const Profile& profile) {
  nlohmann::json j;
  j["source"] = r.source;
  j["profile"] = profile.source;
  j["samples_received"] = r.samples_received;
  j["samples_applied"] = r.samples_applied;
  j["samples_lost"] = r.samples_lost;
  j["samples_rejected"] = r.samples_rejected;
  j["ring_overruns"] = r.ring_overruns;
  j["ring_high_water"] = r.ring_high_water;
  j["ring_capacity"] = r.ring_capacity;
  j["decode_errors"] = r.decode_errors;
  j["lag_p50_ms"] = r.lag_p50_ms;
  j["lag_p99_ms"] = r.lag_p99_ms;
  j["lag_max_ms"] = r.lag_max_ms;
  j["batch_p50_ms"] = r.batch_p50_ms;
  j["batch_p99_ms"] = r.batch_p99_ms;
  j["batch_max_ms"] = r.batch_max_ms;
  j["stock_volume_mm3"] = r.stock_volume_mm3;
  j["removed_volume_mm3"] = r.removed_volume_mm3;
  j["sweeps"] = r.sweeps;
  j["batches"] = r.batches;
  j["record_overruns"] = r.record_overruns;
  j["wall_time_s"] = r.wall_time_s;
  j["rt_mode"] = r.rt_mode;
  j["peak_rss_mb"] = peak_rss_mb();
  return j.dump(2) + "\n";
}

void write_live_outputs(const std::string& dir, const LiveResult& r, const Profile& profile) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create output directory: " + ec.message());
  write_file(dir + "/metrics.json", live_metrics_json(r, profile));
  write_file(dir + "/levels.lbrs", geom::to_bytes(r.solid));
}

nc::EmulatorLimits live_emulator_limits(const Profile& profile) {
  nc::EmulatorLimits l = emulator_limits(profile);
  l.sample_period_ms = profile.live.period_ms;
  return l;
}

}  // namespace lbr::app
