// The live pipeline's lifecycle (app/live.hpp: LivePipeline) and its threads, each a named
// function over the pipeline's state:
//   hal_thread()       source.poll → RingSink (validate → ring)          RT, highest
//   geometry_thread()  Geometry::tick → publish to the render side       RT
//   recorder_thread()  raw records → the --record file                   non-RT
#include <unistd.h>

#include <array>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "app/batch.hpp"
#include "app/live.hpp"
#include "app/outputs.hpp"
#include "geom/lbr_solid.hpp"
#include "live/geometry.hpp"
#include "live/ring_sink.hpp"
#include "live/source.hpp"
#include <spdlog/spdlog.h>
#include "motion/tool_table.hpp"
#include "sched/rt_thread.hpp"
#include "sched/spsc_ring.hpp"

namespace lbr::app {

using live::Geometry;
using live::RingSink;

struct LivePipeline::Impl {
  const Profile& profile;
  LiveOptions opt;
  const std::atomic<bool>& external_stop;

  // configure()
  std::unique_ptr<motion::ToolTable> tools;
  std::optional<LiveResult> r;  // from configure()
  std::unique_ptr<hal::Source> src;
  bool backpressure = false;
  std::unique_ptr<sched::SpscRing<hal::AxisSample>> ring;
  std::unique_ptr<sched::SpscRing<hal::RawRecord>> rec_ring;
  std::FILE* rec_file = nullptr;
  std::string rec_iface = "can0";
  std::unique_ptr<RingSink> sink;
  std::unique_ptr<live::SkipSink> skip_sink;  // resumed replay: drops what the solid holds
  hal::SampleSink* input = nullptr;            // what the source delivers to
  // The live kernel pool (Geometry::set_pool): made and destroyed by the geometry thread
  // (start_kernel_pool()), so that its workers take that thread's policy and processors.
  std::unique_ptr<geom::ParallelSubtractor> pool;
  bool pool_allowed = false;                 // the source is paced at real time or slower
  std::atomic<int> kernel_threads{1};
  std::unique_ptr<Geometry> geo;
  std::unique_ptr<live::LiveChecks> checks;  // collision checks on the geometry thread (null: off)
  std::shared_ptr<const nc::Emulator> emulator;        // an emulator source's (its plan)
  std::unique_ptr<live::ProgramPosition> position;     // line, machining time for the status bar
  std::vector<geom::Paths> design;                     // --design: the model's sections (load_design)
  // Power-loss snapshots (app/snapshot.hpp): the writer, its period, and the counters of
  // the resumed parts before this run.
  std::unique_ptr<SnapshotWriter> snap;
  std::int64_t snapshot_period_ns = 0;
  std::uint64_t applied_base = 0;
  double wall_base_s = 0;
  std::atomic<std::uint64_t> rec_bytes{0};  // written to the --record file so far
  // Catch-up offsets (docs/snapshot.md): where the --record file stood at a time (geometry
  // thread, every kRecMarkEveryNs; the newest kRecMarks), the file when this run started,
  // and its absolute path as snapshots name it.
  struct RecMark {
    std::int64_t t_ns = 0;
    std::uint64_t bytes = 0;
  };
  static constexpr std::size_t kRecMarks = 64;
  std::array<RecMark, kRecMarks> rec_marks{};
  std::size_t rec_marks_n = 0;
  RecMark rec_start;
  std::int64_t next_mark_ns = 0;
  std::string rec_path;
  std::atomic<std::int64_t> snapshot_copy_max_ns{0};  // longest copy step on the geometry thread
  // A periodic snapshot's copy in progress (offer_snapshot()): the next cell to compare and
  // the passes so far that spanned batches.
  struct SnapshotCopy {
    bool active = false;
    std::size_t cursor = 0;
    int passes = 0;
  };
  SnapshotCopy snap_copy;

  // start() .. stop()
  std::atomic<bool> stop_requested{false};
  std::atomic<bool> hal_done{false}, geo_running{false};
  std::atomic<int> hal_mode{-1}, geo_mode{-1};
  std::atomic<std::uint64_t> source_lost{0};
  // Stop: when a thread first saw the request (0: not yet), when the geometry thread ended,
  // and the held samples the HAL side still had then.
  std::atomic<std::int64_t> stop_ns{0}, geo_end_ns{0};
  std::atomic<std::uint64_t> hal_abandoned{0};
  std::int64_t t0 = 0;
  sched::LatencyHistogram::Counts lag_at_last_line{};  // status_line(): the lag since the previous line
  std::thread hal, geometry, recorder;
  bool stopped = false;
  LiveProgress own_progress;  // when the caller gives none
  LiveProgress* progress = &own_progress;

  Impl(const Profile& p, LiveOptions o, const std::atomic<bool>& stop) : profile(p), opt(std::move(o)), external_stop(stop) {}
};

namespace {

std::size_t write_record_line(std::FILE* f, const hal::RawRecord& r, const std::string& iface) {
  char line[256];
  if (r.serial) {
    const long long sec = r.t_wall_ns / 1'000'000'000, usec = (r.t_wall_ns % 1'000'000'000) / 1000;
    int n = std::snprintf(line, sizeof line, "(%010lld.%06lld) serial #", sec, usec);
    static constexpr char kHex[] = "0123456789ABCDEF";  // not snprintf per byte: the recorder keeps up at 40 kHz
    for (std::uint16_t i = 0; i < r.len && n + 3 < static_cast<int>(sizeof line); ++i) {
      line[n++] = kHex[r.bytes[i] >> 4];
      line[n++] = kHex[r.bytes[i] & 15];
    }
    line[n] = '\0';
    std::fputs(line, f);
    std::fputc('\n', f);
    return static_cast<std::size_t>(n) + 1;
  }
  hal::CanFrame fr = r.frame;
  fr.t_ns = r.t_wall_ns;
  const std::size_t n = hal::format_candump_line(fr, iface, line);
  std::fwrite(line, 1, n, f);
  return n;
}

// Bytes of `path` up to and including its last newline (0 when it does not exist); a longer
// file is cut there. Setup.
std::uint64_t complete_lines_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return 0;
  const auto size = static_cast<std::uint64_t>(in.tellg());
  std::uint64_t keep = size;
  char ch = '\n';
  while (keep > 0 && in.seekg(static_cast<std::streamoff>(keep - 1)) && in.get(ch) && ch != '\n') --keep;
  if (keep < size) {
    spdlog::warn("{}: cutting an unfinished last line ({} bytes) before appending", path, size - keep);
    std::filesystem::resize_file(path, keep);
  }
  return keep;
}

// Counters for the HUD, read on the geometry thread when it publishes (reads of counters
// other threads own are relaxed atomics, as in the status line).
gfx::LiveStats live_stats(const LivePipeline::Impl& p) {
  gfx::LiveStats st;
  st.live = true;
  const std::int64_t now = sched::now_ns();
  st.lag_ms = p.geo->last_rx_ns() > 0 ? static_cast<double>(now - p.geo->last_rx_ns()) * 1e-6 : 0.0;
  st.samples = p.geo->applied();
  st.sample_rate_hz =
      now > p.t0 ? static_cast<double>(p.sink->received()) / (static_cast<double>(now - p.t0) * 1e-9) : 0.0;
  st.ring_high_water = p.ring->high_water();
  st.ring_capacity = p.ring->capacity();
  st.ring_overruns = p.ring->overruns();
  st.decode_errors = p.src->counters().total() + p.sink->counters().total();
  st.samples_coalesced = p.sink->coalesced();
  st.samples_held = p.sink->held();
  st.realtime = p.hal_mode.load(std::memory_order_relaxed) == 1 && p.geo_mode.load(std::memory_order_relaxed) == 1;
  if (p.checks) p.checks->fill_alarms(st);
  if (p.position) p.position->fill(st);
  return st;
}

// Geometry thread: apply whatever is in the ring at once; when it was empty, look again
// after geometry_idle_us (so a sample waits at most that long before work starts). Sources
// that are not live (replay/emulator as fast as possible) are applied in chunks of exactly
// lbr.batch_moves samples, so such a run is reproducible bit for bit.
//
// Duty limit (live::DutyBank, call_sizer.hpp): a live source's geometry thread earns `duty`
// seconds of work per second of wall time, banked up to kDutyBurstNs, and spends its work
// on it; when the bank is
// overdrawn it rests until it is even (samples queue meanwhile and merge into longer
// sweeps). A SCHED_FIFO thread that keeps a core busy trips the kernel's real-time
// throttling (sched_rt_runtime_us, by default 950 ms per second), which then stops it for
// the rest of the second: measured 50–56 ms stalls and a lag p99 of 31 ms on the "high"
// workload at 1 kHz without a limit. The bank bounds the work of any second by
// kDutyBurstNs + duty·1 s (0.9 s at the default 0.7), and a single long tick no longer
// forces a rest (before: w·(1/duty − 1) after every tick, which added up to 43 % of each
// long call to the lag of the samples queued behind it). The debt is also bounded by
// kDutyBurstNs, so no rest is longer than kDutyBurstNs / duty (0.29 s): a tick of 35 s (a
// 5-axis stream far behind, before ticks had a budget: Geometry::kTickBudgetNs) was followed
// by a 50-s rest while the ring filled. A rest ends early when a stop is asked for.
//
// Stop (docs/architecture.md "Live overload"): after a stop request the thread goes on
// applying what is queued for kStopGraceNs, then abandons the rest (counted as
// samples_unapplied) — checked between kernel calls, whose work the budget bounds.
constexpr std::int64_t kStopGraceNs = 250'000'000;
constexpr std::int64_t kDutyBurstNs = 200'000'000;
constexpr std::int64_t kRestSliceNs = 20'000'000;

// Gathering (live sources): a kernel call pays a fixed cost for every cell it clips, so a
// thread that applies each sample as soon as it arrives spends most of its time re-clipping
// the same cells (measured: busy 63–69 % of the time at 1 kHz on finish3d, calls of one
// sweep, and held at the duty limit, where the rests build a backlog). It waits instead
// until the oldest queued sample is kGatherFactor × the recent tick time old (the EWMA of
// the work per tick), at most kGatherMaxNs: work per tick c, gathered for 4c, keeps the
// thread at most a quarter busy where it can, and a sample's lag stays within the gather
// time plus one tick. Measured on helix (16x16 cells, 1 kHz): gathering 2c (≈ 1 ms) made
// 97 k kernel calls busy for 70 s and lag p99 19.7 ms; gathering 2.5 ms, 59 k calls, 53 s,
// p99 13.0 ms (docs/performance.md "Live lag").
constexpr double kGatherFactor = 4.0;
constexpr std::int64_t kGatherMaxNs = 2'500'000;
constexpr double kTickEwmaWeight = 0.1;

void bump(std::atomic<std::uint64_t>& c) noexcept { c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }

constexpr std::int64_t kRecMarkEveryNs = 250'000'000;

// Geometry thread: notes where the --record file stands now (every kRecMarkEveryNs).
void mark_recording(LivePipeline::Impl& p, std::int64_t now_ns) noexcept {
  if (p.rec_path.empty() || now_ns < p.next_mark_ns) return;
  p.rec_marks[p.rec_marks_n++ % p.rec_marks.size()] = {now_ns, p.rec_bytes.load(std::memory_order_relaxed)};
  p.next_mark_ns = now_ns + kRecMarkEveryNs;
}

// Where a catch-up must start to find every sample not in the solid: the newest mark at least
// kCatchUpMarginNs before the newest applied sample was received (records written by then
// belong to samples received before it, which the geometry thread applied in order), else
// where this run started recording. Recorded samples before the solid's are skipped by time.
std::uint64_t catch_up_offset(const LivePipeline::Impl& p) noexcept {
  const std::int64_t limit = p.geo->last_rx_ns() - kCatchUpMarginNs;
  LivePipeline::Impl::RecMark best = p.rec_start;
  for (std::size_t i = 0; i < std::min(p.rec_marks_n, p.rec_marks.size()); ++i) {
    const LivePipeline::Impl::RecMark& m = p.rec_marks[i];
    if (m.t_ns <= limit && m.t_ns > best.t_ns) best = m;
  }
  return best.bytes;
}

// What a snapshot records besides the solid (the geometry thread's state at a batch boundary).
void fill_snapshot(const LivePipeline::Impl& p, SnapshotState& s) {
  s.source = p.opt.source;
  s.have = p.geo->have_applied();
  s.last = p.geo->last_applied();
  s.source_position = 0;
  for (int c = 0; c < hal::kMaxChannels; ++c)
    if (s.have[c]) s.source_position = std::max(s.source_position, s.last[c].seq);
  s.samples_applied = p.applied_base + p.geo->applied();
  s.record_file = p.rec_path;
  s.record_offset = p.rec_path.empty() ? 0 : catch_up_offset(p);
  s.wall_time_s = p.wall_base_s + static_cast<double>(sched::now_ns() - p.t0) * 1e-9;
}

// A periodic snapshot's copy at one batch boundary lasts at most this long...
constexpr std::int64_t kSnapshotSliceNs = 1'000'000;
// ...checked after this many copied cells.
constexpr std::size_t kSnapshotSliceCells = 64;
// After this many passes that spanned batches, the next pass runs to its end in one step:
// the snapshots go on, with one longer step, where a pass never fits in one slice.
constexpr int kSnapshotSlicedPasses = 6;

// Periodic snapshot (docs/snapshot.md, "Threads and cost"): once due, the cells changed
// since the writer's slot last held the solid are copied into it, a slice of at most
// kSnapshotSliceNs per batch boundary (no waiting, no I/O, no stall of a whole copy). A
// pass over the cells that spans several batches is no single state of the solid, so the
// passes repeat (each copies only what changed since the last) until one starts and ends at
// the same boundary; that boundary is the snapshot's moment. A busy writer means trying
// again after the next batch.
void offer_snapshot(LivePipeline::Impl& p, std::int64_t& due_ns) {
  if (!p.snap) return;
  LivePipeline::Impl::SnapshotCopy& c = p.snap_copy;
  if (!c.active) {
    if (sched::now_ns() < due_ns || p.snap->slot() == nullptr) return;
    c = {true, 0, 0};
  }
  SnapshotState* s = p.snap->slot();  // still free: only this thread commits it
  const geom::LbrSolid& solid = p.r->solid;
  const std::int64_t t0 = sched::now_ns();
  const bool whole = c.cursor == 0;  // the pass starts at this boundary
  const bool forced = whole && c.passes >= kSnapshotSlicedPasses;
  if (whole && !s->solid.same_grid(solid)) s->solid = solid;  // (start_snapshots() gave it the grid)
  while (c.cursor < solid.cell_count()) {
    c.cursor = s->solid.update_copy_slice(solid, c.cursor, kSnapshotSliceCells);
    if (!forced && sched::now_ns() - t0 > kSnapshotSliceNs) break;
  }
  const std::int64_t took = sched::now_ns() - t0;
  if (took > p.snapshot_copy_max_ns.load(std::memory_order_relaxed)) p.snapshot_copy_max_ns.store(took, std::memory_order_relaxed);
  if (c.cursor < solid.cell_count()) return;  // on at the next boundary
  if (!whole) {  // the solid changed during the pass: another one
    c.cursor = 0;
    ++c.passes;
    return;
  }
  fill_snapshot(p, *s);
  p.snap->commit();
  c.active = false;
  due_ns = sched::now_ns() + p.snapshot_period_ns;
}

// Waits (see kGatherFactor) while the oldest queued sample is young; returns at once when
// the ring is empty (the caller's idle wait) or a stop is asked for.
bool stop_asked(const LivePipeline::Impl& p) noexcept;

void gather(LivePipeline::Impl& p, double tick_ewma_ns) noexcept {
  const hal::AxisSample* s = p.ring->front();
  if (s == nullptr) return;
  const auto wait_ns = static_cast<std::int64_t>(std::min(static_cast<double>(kGatherMaxNs), kGatherFactor * tick_ewma_ns));
  const std::int64_t due = s->t_rx_ns + wait_ns;
  if (due > sched::now_ns() && !stop_asked(p)) sched::sleep_until_ns(due);
}

// The duty rest: sleeps until `due` in slices of kRestSliceNs, and returns early when a stop
// is asked for (a stop takes effect within a slice, not after the rest).
void rest_until(const LivePipeline::Impl& p, std::int64_t due) noexcept {
  for (std::int64_t now = sched::now_ns(); now < due && !stop_asked(p); now = sched::now_ns())
    sched::sleep_until_ns(std::min(due, now + kRestSliceNs));
}

// The geometry thread's kernel pool (Geometry::set_pool, [lbr] live_threads > 1), made on
// that thread once it is configured: its workers take its scheduling policy and priority
// (SCHED_FIFO below the HAL thread; a SCHED_OTHER worker behind other processes' work held
// the saturated geometry thread at the pool's barriers: finish5x lag p99 40 ms against 5.4
// ms, docs/performance.md "Two kernel threads live") and its processors (pinned by
// geometry_cpu: no pool). They work only inside the calls the pool takes, so each core keeps
// the geometry thread's duty limit. Opt-in, and only for sources at real time or slower.
void start_kernel_pool(LivePipeline::Impl& p) {
  const int n = live_kernel_threads(p.profile);
  if (n < 2 || !p.pool_allowed) return;
  try {
    p.pool = std::make_unique<geom::ParallelSubtractor>(n);
  } catch (const std::system_error& e) {
    spdlog::warn("live kernel: {} threads could not start ({}); one thread", n, e.what());
    return;
  }
  p.geo->set_pool(p.pool.get());
  p.kernel_threads.store(n, std::memory_order_relaxed);
}

// Before the threads start: the pool only for a source at the machine's pace. One faster
// than real time (a replay or the emulator at --speed > 1, or as fast as possible) keeps
// the HAL thread busy on the worker's core, the geometry thread then waits at the pool's
// barriers for a worker that cannot run, and the HAL thread waits for the ring: the demo at
// --speed 200 made 127 kernel calls instead of 8 537, lag p99 6.6 s, and a SCHED_OTHER
// thread waited 0.9 s.
void allow_kernel_pool(LivePipeline::Impl& p) {
  p.pool_allowed = p.opt.speed > 0.0 && p.opt.speed <= 1.0;
  if (p.profile.live_threads > 1 && !p.pool_allowed)
    spdlog::warn("live kernel: live_threads = {} needs a source at real time or slower (--speed {}); one thread",
                 p.profile.live_threads, p.opt.speed);
}

void stop_kernel_pool(LivePipeline::Impl& p) noexcept {
  p.geo->set_pool(nullptr);
  p.pool.reset();
}

void geometry_thread(LivePipeline::Impl& p) {
  const hal::LiveConfig& cfg = p.profile.live;
  p.geo_mode = sched::configure_current_thread(cfg.geometry_thread) == sched::RtMode::Fifo ? 1 : 0;
  start_kernel_pool(p);
  const std::size_t chunk = p.backpressure ? static_cast<std::size_t>(p.profile.batch_moves) : p.ring->capacity();
  const std::int64_t idle_ns = static_cast<std::int64_t>(cfg.geometry_idle_us) * 1000;
  const bool duty_limited = !p.backpressure && cfg.geometry_duty < 1.0;
  live::DutyBank duty(cfg.geometry_duty, kDutyBurstNs, sched::now_ns());
  double tick_ewma_ns = 0.0;
  std::int64_t snapshot_due_ns = sched::now_ns() + p.snapshot_period_ns;
  p.progress->geometry_running.store(true, std::memory_order_relaxed);
  for (;;) {
    bump(p.progress->geometry_loops);
    mark_recording(p, sched::now_ns());
    const bool finished = p.hal_done.load(std::memory_order_acquire);
    if (!p.backpressure && !finished) gather(p, tick_ewma_ns);
    const std::int64_t t_tick = sched::now_ns();  // the tick's work starts here (not its gathering)
    if (p.geo->stop_due()) break;
    if ((finished || !p.backpressure || p.ring->size() >= chunk) && p.geo->tick(chunk) > 0) {
      tick_ewma_ns += kTickEwmaWeight * (static_cast<double>(sched::now_ns() - t_tick) - tick_ewma_ns);
      if (p.geo->abandoned()) break;
      if (p.opt.exchange != nullptr) (void)p.geo->publish(live_stats(p));
      offer_snapshot(p, snapshot_due_ns);
      if (duty_limited && !finished) {
        const std::int64_t now = sched::now_ns();
        if (const std::int64_t rest = duty.spend(t_tick, now); rest > 0) rest_until(p, now + rest);
      }
      continue;
    }
    if (finished && p.ring->front() == nullptr) break;
    sched::sleep_until_ns(sched::now_ns() + idle_ns);
  }
  stop_kernel_pool(p);
  const bool stopping = p.stop_ns.load(std::memory_order_relaxed) != 0;
  if (stopping) (void)p.geo->discard();
  // The final state must reach the render side: retry while it is busy (bounded: 2 s, or
  // 0.2 s after a stop).
  for (int i = 0; p.opt.exchange != nullptr && i < (stopping ? 100 : 1000) && !p.geo->publish(live_stats(p)); ++i)
    sched::sleep_until_ns(sched::now_ns() + 2'000'000);
  p.geo_end_ns.store(sched::now_ns(), std::memory_order_relaxed);
  p.geo->publish_volume();
  p.progress->geometry_running.store(false, std::memory_order_relaxed);
  p.geo_running.store(false, std::memory_order_release);
}

bool stop_asked(const LivePipeline::Impl& p) noexcept {
  return p.external_stop.load(std::memory_order_relaxed) || p.stop_requested.load(std::memory_order_relaxed);
}

// HAL thread: polls the source until it ends or a stop is asked for; between polls, held
// samples (the geometry thread behind) move into the ring as it empties. When the source
// ends, it waits for the held ones to go in, unless a stop is asked for.
void hal_thread(LivePipeline::Impl& p) {
  p.hal_mode = sched::configure_current_thread(p.profile.live.hal_thread) == sched::RtMode::Fifo ? 1 : 0;
  p.progress->hal_running.store(true, std::memory_order_relaxed);
  while (!stop_asked(p)) {
    bump(p.progress->hal_loops);
    const hal::PollResult pr = p.src->poll(50, *p.input);
    p.source_lost.store(p.src->lost(), std::memory_order_relaxed);  // the source is this thread's
    (void)p.sink->pump();
    if (pr == hal::PollResult::End) break;
    if (pr == hal::PollResult::Error) sched::sleep_until_ns(sched::now_ns() + 1'000'000);  // no busy loop
  }
  while (!p.sink->pump() && !stop_asked(p)) {
    bump(p.progress->hal_loops);
    sched::sleep_until_ns(sched::now_ns() + 1'000'000);
  }
  if (stop_asked(p)) {
    std::int64_t expected = 0;
    (void)p.stop_ns.compare_exchange_strong(expected, sched::now_ns(), std::memory_order_relaxed);
  }
  p.hal_abandoned.store(p.sink->abandon(), std::memory_order_relaxed);
  p.progress->hal_running.store(false, std::memory_order_relaxed);
  p.hal_done.store(true, std::memory_order_release);
}

// Recorder thread (--record): writes the raw records as candump -l lines until the HAL
// thread is done and the ring is empty.
// Each drained batch is flushed to the kernel (a crashed process loses at most the lines not
// yet drained), and fdatasync'd every second (a power cut loses about a second of it): the
// catch-up after a restart replays what the file holds.
void recorder_thread(LivePipeline::Impl& p) {
  std::int64_t next_sync_ns = sched::now_ns() + 1'000'000'000;
  for (;;) {
    const bool finished = p.hal_done.load(std::memory_order_acquire);
    bool any = false;
    std::uint64_t bytes = 0;
    while (hal::RawRecord* rec = p.rec_ring->front()) {
      bytes += write_record_line(p.rec_file, *rec, p.rec_iface);
      p.rec_ring->pop();
      any = true;
    }
    if (any) {
      std::fflush(p.rec_file);  // before the bytes count as written
      p.rec_bytes.store(p.rec_bytes.load(std::memory_order_relaxed) + bytes, std::memory_order_relaxed);
    }
    if (any && sched::now_ns() >= next_sync_ns) {
      (void)::fdatasync(fileno(p.rec_file));
      next_sync_ns = sched::now_ns() + 1'000'000'000;
    }
    if (finished && !any) break;
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// Counters so far into p.r (any thread; relaxed reads).
void snapshot(LivePipeline::Impl& p) {
  LiveResult& r = *p.r;
  r.samples_received = p.sink->received();
  r.samples_applied = p.geo->applied();
  r.samples_rejected = p.sink->rejected();
  r.ring_overruns = p.ring->overruns();
  r.ring_high_water = p.ring->high_water();
  r.samples_coalesced = p.sink->coalesced();
  r.overflow_overruns = p.sink->overflow_overruns();
  r.overflow_high_water = p.sink->overflow_high_water();
  r.overflow_capacity = p.sink->overflow_capacity();
  r.kernel_calls = p.geo->kernel_calls();
  r.sweeps_split = p.geo->sweeps_split();
  r.kernel_calls_shared = p.geo->kernel_calls_shared();
  r.kernel_threads = p.kernel_threads.load(std::memory_order_relaxed);
  r.samples_unapplied = p.geo->unapplied() + p.hal_abandoned.load(std::memory_order_relaxed);
  r.samples_lost = p.source_lost.load(std::memory_order_relaxed) + r.samples_rejected + r.ring_overruns + r.overflow_overruns;
  const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-6; };
  const sched::LatencyHistogram& lag = p.geo->lag();
  r.lag_p50_ms = ms(lag.percentile_ns(0.5));
  r.lag_p99_ms = ms(lag.percentile_ns(0.99));
  r.lag_max_ms = ms(lag.max_ns());
  r.batch_p50_ms = ms(p.geo->work().percentile_ns(0.5));
  r.batch_p99_ms = ms(p.geo->work().percentile_ns(0.99));
  r.batch_max_ms = ms(p.geo->work().max_ns());
  r.removed_volume_mm3 = p.geo->removed_mm3();
}

// Resuming: the snapshot's solid, counters and channel poses; the emulator and replay
// sources skip the samples it holds (live sources go on with what the machine sends now).
void resume_from(LivePipeline::Impl& p, const SnapshotState& snap) {
  geom::LbrSolid& solid = p.r->solid;
  if (snap.solid.levels() != solid.levels() || snap.solid.regions() != solid.regions())
    throw std::runtime_error(p.profile.source + ": the snapshot's stock (" + std::to_string(snap.solid.levels()) +
                             " levels x " + std::to_string(snap.solid.regions()) + " regions) is not the profile's (" +
                             std::to_string(solid.levels()) + " x " + std::to_string(solid.regions()) +
                             "); start without --resume for a new part");
  solid = snap.solid;
  p.applied_base = snap.samples_applied;
  p.wall_base_s = snap.wall_time_s;
  p.r->resumed_generation = snap.generation;
  p.r->resumed_position = snap.source_position;
}

void start_snapshots(LivePipeline::Impl& p) {
  const std::string& dir = p.opt.snapshot_dir;
  if (dir.empty() || p.profile.live.snapshot_s <= 0.0) return;
  std::uint64_t generation = 1;
  if (p.opt.resume != nullptr) {
    generation = p.opt.resume->generation + 1;
  } else {  // a new part: a later --resume must not find the previous part's snapshots
    std::error_code ec;
    for (const char* f : {"snapshot-a.lbrsnap", "snapshot-b.lbrsnap"}) std::filesystem::remove(std::filesystem::path(dir) / f, ec);
  }
  SnapshotWriter::AfterWrite compare;  // --design: the snapshot's stock against the model
  if (!p.design.empty() && p.opt.on_design_report)
    compare = [&p](const SnapshotState& s) {
      p.opt.on_design_report(verify::compare_design(p.design, s.solid, p.profile.design.tolerance_mm), false);
    };
  p.snap = std::make_unique<SnapshotWriter>(dir, generation, std::move(compare));
  p.snapshot_period_ns = static_cast<std::int64_t>(p.profile.live.snapshot_s * 1e9);
  // The slot's first copy, of the whole solid, here before the real-time threads start: the
  // geometry thread's periodic copies then take only the cells changed since (110 ms on
  // finish3d's 16x16 live grid when the first periodic copy was a whole one).
  if (SnapshotState* s = p.snap->slot()) s->solid = p.r->solid;
}

// The collision checks' results into r (after the geometry thread has ended).
void fill_check_results(const LivePipeline::Impl& p, LiveResult& r) {
  r.checks = p.checks != nullptr;
  if (!p.checks) return;
  const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-6; };
  r.rapid_threshold_mm_per_min = p.checks->rapid_threshold_mm_per_min();
  r.events = p.checks->events();
  r.events_dropped = p.checks->dropped();
  const sched::LatencyHistogram& lat = p.checks->latency();
  r.event_latency_count = lat.count();
  r.event_latency_p50_ms = ms(lat.percentile_ns(0.5));
  r.event_latency_p99_ms = ms(lat.percentile_ns(0.99));
  r.event_latency_max_ms = ms(lat.max_ns());
  const sched::LatencyHistogram& ct = p.geo->check_time();
  r.check_p50_ms = ms(ct.percentile_ns(0.5));
  r.check_p99_ms = ms(ct.percentile_ns(0.99));
  r.check_max_ms = ms(ct.max_ns());
}

// --design: the final stock against the model, by the batch runner's comparison (no move
// list to attribute the gouge to); its design-gouge event joins the checks' events.
void fill_design_result(const LivePipeline::Impl& p, LiveResult& r) {
  if (p.profile.design.stl_path.empty()) return;
  r.design = compare_with_design(p.profile, p.design, r.solid, {}, verify::MoveIndex{}, r.events);
  if (p.opt.on_design_report) p.opt.on_design_report(*r.design, true);
}

// The status bar's program position: the emulator source's plan, or --program's moves.
void configure_program(LivePipeline::Impl& p) {
  std::optional<nc::Toolpath> program;
  if (!p.opt.program.empty() && !p.emulator) program = load_toolpath(p.opt.program, p.profile);
  p.position = std::make_unique<live::ProgramPosition>(p.emulator, program ? &*program : nullptr,
                                                       live_emulator_limits(p.profile), p.profile.live.period_ms * 1e-3);
  p.geo->set_program_position(p.position.get());
}

geom::SolidSpec live_solid_spec(const Profile& profile, const motion::ToolTable& tools) {
  geom::SolidSpec spec = profile.solid;
  bool automatic = profile.regions_auto;
  if (profile.live_grid.set) {  // [lbr] live_regions
    automatic = profile.live_grid.automatic;
    if (!automatic) spec.regions_x = profile.live_grid.x, spec.regions_y = profile.live_grid.y;
  }
  if (automatic) std::tie(spec.regions_x, spec.regions_y) = auto_region_grid(spec, tools.max_diameter());
  return spec;
}

// The --record file: a new part truncates it; a resumed one appends (snapshot offsets stay
// file offsets), after cutting a last line that a crash left unfinished.
void open_recording(LivePipeline::Impl& p, bool resumed) {
  if (p.opt.record.empty()) return;
  p.rec_path = std::filesystem::absolute(p.opt.record).lexically_normal().string();
  std::uint64_t size = 0;
  if (resumed) size = complete_lines_size(p.opt.record);
  p.rec_file = std::fopen(p.opt.record.c_str(), resumed ? "a" : "w");
  if (p.rec_file == nullptr) throw std::runtime_error(p.opt.record + ": cannot open for writing");
  p.rec_bytes.store(size, std::memory_order_relaxed);
  p.rec_start = {std::numeric_limits<std::int64_t>::min(), size};
}

// Power-loss catch-up (docs/snapshot.md): the samples that the --record file holds after the
// snapshot's offset and the solid does not (SkipSink by sender time) are replayed through the
// validation, the ring and Geometry::tick like any other samples — on the calling thread,
// before the threads start, in chunks of batch_moves as a replay as fast as possible.
void catch_up(LivePipeline::Impl& p, const SnapshotState& snap) {
  const std::uint64_t size = p.rec_bytes.load(std::memory_order_relaxed);
  if (p.rec_path.empty() || snap.record_file != p.rec_path || snap.record_offset >= size) return;
  // The emulator computes the samples after the snapshot again, with their tools; its
  // recording (serial frames) has no tool numbers, so it is not replayed.
  if (p.opt.source.rfind("emulator:", 0) == 0) return;
  std::unique_ptr<hal::Source> src;
  try {
    src = hal::make_replay_source(p.opt.record, p.profile.live, 0.0, snap.record_offset);
    src->open();
  } catch (const std::exception& e) {
    p.r->warnings.push_back(std::string("no catch-up from the recording: ") + e.what());
    return;
  }
  const std::atomic<bool> never{false};
  RingSink sink(*p.ring, nullptr, p.profile.live, true, never, p.opt.overflow_capacity);
  live::SkipSink skip(sink, 0);
  skip.skip_by_time(snap.have, snap.last);
  const std::uint64_t before = p.geo->applied();
  constexpr std::size_t kRoom = 64;  // samples one poll of a replay can deliver at most (4 serial frames x 4 channels + margin)
  bool more = true;
  while (more || p.ring->size() > 0) {
    while (more && p.ring->capacity() - p.ring->size() >= std::min(kRoom, p.ring->capacity()))
      more = src->poll(0, skip) != hal::PollResult::End;
    (void)p.geo->tick(static_cast<std::size_t>(p.profile.batch_moves));
  }
  p.r->samples_caught_up = p.geo->applied() - before;
  p.r->catch_up_skipped = skip.skipped();
  spdlog::info("resume: caught up {} samples from {} after byte {} ({} recorded ones already in the part)",
               p.r->samples_caught_up, p.opt.record, snap.record_offset, p.r->catch_up_skipped);
}

}  // namespace

LivePipeline::LivePipeline(const Profile& profile, LiveOptions opt, const std::atomic<bool>& stop)
    : impl_(std::make_unique<Impl>(profile, std::move(opt), stop)) {}

LivePipeline::~LivePipeline() {
  if (impl_ && impl_->geo_running.load()) stop();
}

void LivePipeline::configure() {
  Impl& p = *impl_;
  const Profile& profile = p.profile;
  const hal::LiveConfig& cfg = profile.live;
  p.tools = std::make_unique<motion::ToolTable>(profile.tooling, profile.solid.chord_tol_mm, profile.source);
  if (!p.tools->defines(cfg.tool))
    throw std::runtime_error(profile.source + ": live.tool " + std::to_string(cfg.tool) + " is not in the tool table");
  p.tools->build_all();
  p.r.emplace(LiveResult{geom::LbrSolid(live_solid_spec(profile, *p.tools)), p.opt.source, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                         {}, 0, 0, 0, 0, 0, 0, ""});
  p.r->stock_volume_mm3 = p.r->solid.initial_volume_mm3();
  p.design = load_design(profile, p.r->solid);  // before the source opens: its errors come first
  if (p.opt.progress != nullptr) p.progress = p.opt.progress;
  const SnapshotState* resume = p.opt.resume;
  if (resume != nullptr) resume_from(p, *resume);
  const bool emulator = p.opt.source.rfind("emulator:", 0) == 0, replay = p.opt.source.rfind("replay:", 0) == 0;
  start_snapshots(p);

  p.ring = std::make_unique<sched::SpscRing<hal::AxisSample>>(cfg.ring_capacity);
  open_recording(p, resume != nullptr);
  p.geo = std::make_unique<Geometry>(p.r->solid, profile, *p.tools, cfg.tool, *p.ring, cfg.merge_tolerance_mm);
  p.geo->set_stop(&p.external_stop, &p.stop_requested, &p.stop_ns, kStopGraceNs);
  p.geo->set_kernel_delay_ns(p.opt.test_kernel_delay_ns);
  if (p.opt.test_work_budget > 0) p.geo->set_work_budget(p.opt.test_work_budget);
  std::uint64_t position = 0;  // the emulator's samples in the solid (it computes and skips them)
  if (resume != nullptr) {
    p.geo->prime(resume->have, resume->last);  // the recorded stream goes on from these poses
    catch_up(p, *resume);
    position = resume->source_position;
    for (int c = 0; c < hal::kMaxChannels; ++c)
      if (p.geo->have_applied()[c]) position = std::max(position, p.geo->last_applied()[c].seq);
    // A live machine has moved on during the outage: no sweep across it.
    if (!emulator && !replay) p.geo->forget_poses();
  }

  p.src = live::make_source(profile, p.opt.source, p.opt.speed, emulator ? position : 0, &p.emulator);
  p.src->open();
  p.backpressure = !p.src->live();
  // Live sources: sub-batches sized by time (live/call_sizer.hpp); as fast as possible:
  // the fixed budget, reproducible.
  p.geo->set_timed_calls(!p.backpressure && p.opt.test_work_budget <= 0);
  if (p.opt.kernel_log_capacity > 0) p.geo->set_kernel_log(p.opt.kernel_log_capacity, sched::now_ns());
  if (p.rec_file != nullptr) {
    p.rec_ring = std::make_unique<sched::SpscRing<hal::RawRecord>>(1 << 15);
    p.src->set_recording(true);
  }
  if (p.opt.source.rfind("can:", 0) == 0) p.rec_iface = p.opt.source.substr(4);
  p.sink = std::make_unique<RingSink>(*p.ring, p.rec_ring.get(), cfg, p.backpressure, p.stop_requested,
                                      p.opt.overflow_capacity);
  p.input = p.sink.get();
  if (resume != nullptr && replay) {  // the log from its start: what the solid holds is skipped
    p.skip_sink = std::make_unique<live::SkipSink>(*p.sink, resume->source_position);
    p.skip_sink->skip_by_time(p.geo->have_applied(), p.geo->last_applied());
    p.input = p.skip_sink.get();
  }
  if (profile.checks.enabled) {
    p.checks = std::make_unique<live::LiveChecks>(profile, *p.tools, Geometry::batch_capacity(p.ring->capacity()),
                                                  live::ProgramLines(p.emulator, emulator ? p.opt.source.substr(9) : ""));
    p.geo->set_checks(p.checks.get());
  }
  p.geo->set_exchange(p.opt.exchange);
  configure_program(p);
  if (p.opt.on_design && !p.design.empty()) p.opt.on_design(p.design);
  if (p.opt.on_start) p.opt.on_start(p.r->solid);
  p.r->solid.clear_dirty();  // the render side starts from this state
}

void LivePipeline::start() {
  Impl& p = *impl_;
  if (!p.geo) throw std::logic_error("LivePipeline::start() before configure()");
  p.t0 = sched::now_ns();
  allow_kernel_pool(p);
  p.geo_running.store(true, std::memory_order_release);
  p.geometry = std::thread([&p] { geometry_thread(p); });
  p.hal = std::thread([&p] { hal_thread(p); });
  if (p.rec_ring) p.recorder = std::thread([&p] { recorder_thread(p); });
}

bool LivePipeline::running() const noexcept { return impl_->geo_running.load(std::memory_order_acquire); }

std::string LivePipeline::input_warning() const {
  const Impl& p = *impl_;
  if (!p.src) return "";
  const hal::InputMismatch m = p.src->input_mismatch();
  if (m.positions_carried == 0) return "";
  return p.src->describe() + ": frames carry " + std::to_string(m.positions_carried) + " position" +
         (m.positions_carried == 1 ? "" : "s") + ", the profile maps " + std::to_string(m.positions_needed) + " (" +
         p.profile.source + ", [[live.axis]] index up to " + std::to_string(m.positions_needed - 1) +
         "); no sample can be used. Give the sender and lbrsim the same profile (lbr-feed-serial --profile FILE)";
}

std::string LivePipeline::status_line() {
  Impl& p = *impl_;
  snapshot(p);
  const LiveResult& r = *p.r;
  sched::LatencyHistogram::Counts now{};
  p.geo->lag().copy_counts(now);
  const double window_p99_ms =
      static_cast<double>(sched::LatencyHistogram::percentile_between_ns(p.lag_at_last_line, now, 0.99)) * 1e-6;
  p.lag_at_last_line = now;
  char line[440];
  std::snprintf(line, sizeof line,
                "t %.1f s | rx %" PRIu64 " applied %" PRIu64 " lost %" PRIu64 " | ring hw %" PRIu64 "/%zu overruns %" PRIu64
                " | coalesced %" PRIu64 " held %" PRIu64 " | lag p50 %.2f p99 %.2f max %.2f ms, p99 since last line %.2f ms"
                " | removed %.1f mm3 | errors %" PRIu64,
                static_cast<double>(sched::now_ns() - p.t0) * 1e-9, r.samples_received, r.samples_applied, r.samples_lost,
                r.ring_high_water, p.ring->capacity(), r.ring_overruns, r.samples_coalesced, p.sink->held(), r.lag_p50_ms,
                r.lag_p99_ms, r.lag_max_ms, window_p99_ms,
                r.removed_volume_mm3, p.src->counters().total() + p.sink->counters().total());
  return line;
}

std::vector<std::pair<bool, std::string>> LivePipeline::new_events() {
  Impl& p = *impl_;
  std::vector<std::pair<bool, std::string>> out;
  if (!p.checks) return out;
  live::EventNote n;
  while (p.checks->pop_note(n)) {
    verify::Event e;
    e.kind = n.kind;
    e.source = n.line > 0 ? p.checks->program() : "";
    e.line = n.line;
    e.move = static_cast<geom::MoveId>(n.sample & 0xFFFFFFFFU);
    e.tool = n.tool;
    e.channel = n.channel;
    e.position = n.position;
    e.volume_mm3 = n.volume_mm3;
    e.depth_mm = n.depth_mm;
    char tail[96];
    std::snprintf(tail, sizeof tail, " (sample %" PRIu64 ", raised %.2f ms after it was received)", n.sample, n.latency_ms);
    out.emplace_back(e.severity() == verify::Severity::Error, verify::describe(e) + tail);
  }
  return out;
}

void LivePipeline::request_stop() noexcept { impl_->stop_requested.store(true, std::memory_order_relaxed); }

void LivePipeline::stop() {
  Impl& p = *impl_;
  if (p.stopped) return;
  p.stopped = true;
  request_stop();
  if (p.hal.joinable()) p.hal.join();
  if (p.geometry.joinable()) p.geometry.join();
  if (p.recorder.joinable()) p.recorder.join();
  if (p.rec_file != nullptr) std::fclose(p.rec_file);
  p.rec_file = nullptr;
  if (p.src) p.src->close();
}

LiveResult LivePipeline::result() {
  Impl& p = *impl_;
  if (!p.stopped) stop();
  LiveResult& r = *p.r;
  r.wall_time_s = static_cast<double>(sched::now_ns() - p.t0) * 1e-9;
  p.geo->publish_volume();
  (void)p.geo->discard();  // what the HAL thread pushed after the geometry thread ended (a stop)
  snapshot(p);
  r.removed_volume_mm3 = r.stock_volume_mm3 - r.solid.volume_mm3();
  r.ring_capacity = p.ring->capacity();
  r.sweeps = p.geo->sweeps();
  r.batches = p.geo->batches();
  r.record_overruns = p.sink->rec_overruns();
  const std::int64_t t_stop = p.stop_ns.load(), t_end = p.geo_end_ns.load();
  r.stop_latency_ms = t_stop > 0 && t_end > t_stop ? static_cast<double>(t_end - t_stop) * 1e-6 : 0.0;
  for (int k = 0; k < hal::kFaultKinds; ++k) {
    const auto f = static_cast<hal::Fault>(k);
    r.decode_errors[hal::fault_name(f)] = p.src->counters().get(f) + p.sink->counters().get(f);
  }
  fill_check_results(p, r);
  r.kernel_log.assign(p.geo->kernel_log().begin(), p.geo->kernel_log().end());
  const bool fifo = p.hal_mode.load() == 1 && p.geo_mode.load() == 1;
  r.rt_mode = fifo ? "fifo" : "non-rt";
  if (p.snap) {  // clean shutdown: the final state, after any periodic one still being written
    SnapshotState s;
    s.solid = r.solid;
    fill_snapshot(p, s);
    try {
      p.snap->write_now(s);
    } catch (const std::exception& e) {
      r.warnings.push_back(std::string("final snapshot not written: ") + e.what());
    }
    r.snapshots_written = p.snap->written();
    r.snapshot_copy_max_ms = static_cast<double>(p.snapshot_copy_max_ns.load()) * 1e-6;
    r.snapshots_failed = p.snap->failed();
  }
  fill_design_result(p, r);  // after the writer thread's last periodic comparison
  return std::move(r);
}

}  // namespace lbr::app
