// `lbrsim run`: the pipeline's control loop (run_live) and its outputs. The pipeline itself
// (threads, geometry, sources) is in app/src/live/.
#include "app/live.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "app/batch.hpp"
#include "app/install_paths.hpp"
#include "app/outputs.hpp"
#include "geom/serialize.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::app {

LiveResult run_live(const Profile& profile, const LiveOptions& opt, const std::atomic<bool>& stop, const StatusFn& status) {
  LivePipeline pipeline(profile, opt, stop);
  pipeline.configure();
  pipeline.start();
  const auto period = static_cast<std::int64_t>(opt.status_period_s * 1e9);
  std::int64_t next_status = sched::now_ns() + period;
  std::vector<std::string> warnings;
  const auto check_input = [&] {
    if (!warnings.empty()) return;  // one warning per run: the mismatch does not change
    std::string w = pipeline.input_warning();
    if (w.empty()) return;
    if (opt.on_warning) opt.on_warning(w);
    warnings.push_back(std::move(w));
  };
  // Collision events go to the log as they are raised (docs/verification.md#live).
  const auto log_events = [&pipeline] {
    for (const auto& [error, line] : pipeline.new_events()) {
      if (error) spdlog::error("{}", line);
      else spdlog::warn("{}", line);
    }
  };
  while (pipeline.running()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    check_input();
    log_events();
    if (status && sched::now_ns() >= next_status) {
      next_status += period;
      status(pipeline.status_line());
    }
  }
  pipeline.stop();
  check_input();
  log_events();
  LiveResult r = pipeline.result();
  r.warnings = std::move(warnings);
  return r;
}

std::string live_metrics_json(const LiveResult& r, const Profile& profile) {
  nlohmann::json j;
  j["lbrsim_version"] = version();
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
  j["warnings"] = r.warnings;
  j["samples_coalesced"] = r.samples_coalesced;
  j["overflow_overruns"] = r.overflow_overruns;
  j["overflow_high_water"] = r.overflow_high_water;
  j["overflow_capacity"] = r.overflow_capacity;
  j["kernel_calls"] = r.kernel_calls;
  j["sweeps_split"] = r.sweeps_split;
  j["kernel_threads"] = r.kernel_threads;
  j["kernel_calls_shared"] = r.kernel_calls_shared;
  j["samples_unapplied"] = r.samples_unapplied;
  j["stop_latency_ms"] = r.stop_latency_ms;
  j["wall_time_s"] = r.wall_time_s;
  j["rt_mode"] = r.rt_mode;
  j["snapshots_written"] = r.snapshots_written;
  j["snapshots_failed"] = r.snapshots_failed;
  j["snapshot_copy_max_ms"] = r.snapshot_copy_max_ms;
  j["resumed_generation"] = r.resumed_generation;
  j["resumed_position"] = r.resumed_position;
  j["samples_caught_up"] = r.samples_caught_up;
  j["catch_up_skipped"] = r.catch_up_skipped;
  j["peak_rss_mb"] = peak_rss_mb();
  put_events_json(r.events, r.checks, j);
  j["events_dropped"] = r.events_dropped;
  j["rapid_threshold_mm_per_min"] = r.rapid_threshold_mm_per_min;
  j["event_latency_count"] = r.event_latency_count;
  j["event_latency_p50_ms"] = r.event_latency_p50_ms;
  j["event_latency_p99_ms"] = r.event_latency_p99_ms;
  j["event_latency_max_ms"] = r.event_latency_max_ms;
  j["check_p50_ms"] = r.check_p50_ms;
  j["check_p99_ms"] = r.check_p99_ms;
  j["check_max_ms"] = r.check_max_ms;
  if (r.design) put_design_json(*r.design, profile, j);
  return j.dump(2) + "\n";
}

void write_live_outputs(const std::string& dir, const LiveResult& r, const Profile& profile) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create output directory: " + ec.message());
  write_file((std::filesystem::path(dir) / "metrics.json").string(), live_metrics_json(r, profile));
  write_file((std::filesystem::path(dir) / "levels.lbrs").string(), geom::to_bytes(r.solid));
  write_file((std::filesystem::path(dir) / "events.csv").string(), verify::events_csv(r.events));
  if (r.design) write_file((std::filesystem::path(dir) / "deviation.csv").string(), verify::deviation_csv(*r.design));
  if (!r.kernel_log.empty()) {
    std::string csv = "t_ms,dur_us,sweeps,samples,units,predicted_us,cells_clipped,sections,cell_vertices,backlog_us\n";
    char line[192];
    for (const KernelCallRecord& k : r.kernel_log) {
      std::snprintf(line, sizeof line, "%.3f,%u,%u,%u,%.0f,%.0f,%u,%u,%u,%u\n", static_cast<double>(k.t_ns) * 1e-6, k.dur_us,
                    k.sweeps, k.samples, static_cast<double>(k.units), static_cast<double>(k.predicted_us), k.cells_clipped,
                    k.sections, k.cell_vertices, k.backlog_us);
      csv += line;
    }
    write_file((std::filesystem::path(dir) / "kernel_calls.csv").string(), csv);
  }
}

nc::EmulatorLimits live_emulator_limits(const Profile& profile) {
  nc::EmulatorLimits l = emulator_limits(profile);
  l.sample_period_ms = profile.live.period_ms;
  return l;
}

}  // namespace lbr::app
