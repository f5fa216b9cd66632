#include "app/outputs.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "app/install_paths.hpp"
#include "demo_program.inc"  // kDemoProgram
#include "geom/serialize.hpp"
#include "mesh/export.hpp"
#include "mesh/reconstruct.hpp"
#include "nc/gcode.hpp"
#include "nc/movelist.hpp"
#include "nc/rs274.hpp"

namespace lbr::app {

namespace {

std::string extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

template <class Bytes>
void write_bytes(const std::string& path, const Bytes& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw std::runtime_error(path + ": cannot open for writing: " + std::strerror(errno));
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  f.close();
  if (!f) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
}

}  // namespace

bool is_gcode_path(const std::string& path) {
  const std::string ext = extension(path);
  return ext == ".ngc" || ext == ".nc" || ext == ".gcode" || ext == ".tap";
}

nc::Toolpath load_toolpath(const std::string& path_as_given, const Profile& profile, Interpreter interpreter) {
  const std::string path = find_program(path_as_given);
  const std::string ext = extension(path);
  if (ext == ".moves") {
    if (interpreter == Interpreter::Rs274)
      throw std::runtime_error(path + ": --interpreter rs274 applies to G-code programs, not move lists");
    nc::Toolpath moves = nc::load_movelist(path);
    nc::set_machine_frame(moves, gcode_options(profile));
    return moves;
  }
  if (is_gcode_path(path)) {
    const nc::GcodeOptions o = gcode_options(profile);
    if (interpreter == Interpreter::Rs274 && o.dialect == nc::Dialect::Fanuc)
      throw std::runtime_error(path + ": the fanuc dialect is read by the built-in interpreter only (LinuxCNC's rs274 "
                               "reads RS274/NGC); drop --interpreter rs274");
    return interpreter == Interpreter::Rs274 ? nc::run_rs274(path, o) : nc::load_gcode(path, o);
  }
  throw std::runtime_error(path + ": unknown program type '" + ext + "' (expected .moves, .ngc, .nc, .gcode or .tap)");
}

std::vector<ChannelPath> load_channel_paths(const Profile& profile, Interpreter interpreter) {
  const std::filesystem::path dir = std::filesystem::path(profile.source).parent_path();
  std::vector<ChannelPath> channels;
  for (const Channel& c : profile.channels) {
    if (c.program.empty()) throw std::runtime_error(profile.source + ": channel '" + c.name + "' has no program");
    std::filesystem::path prog =
        std::filesystem::path(c.program).is_absolute() ? std::filesystem::path(c.program) : dir / c.program;
    std::error_code ec;
    if (!std::filesystem::exists(prog, ec)) prog = find_program(c.program);  // installed: programs apart from /etc
    Profile per = profile;
    per.machine.g54_origin_mm = c.g54_origin_mm;
    channels.push_back({c.name, load_toolpath(prog.string(), per, interpreter), c.kin});
  }
  return channels;
}

nc::Toolpath demo_toolpath() { return nc::parse_movelist(kDemoProgram, "<built-in demo-pocket.moves>"); }

void fill_event_alarms(std::span<const verify::Event> events, std::uint64_t not_stored, int shown, bool by_sample,
                       gfx::LiveStats& stats) noexcept {
  stats.alarm_count = 0;
  const std::size_t n = events.size();
  const std::size_t limit = std::min<std::size_t>(static_cast<std::size_t>(std::max(0, shown)), gfx::kMaxAlarms - 1);
  const std::size_t count = std::min(n, limit);
  char text[gfx::kAlarmTextChars];
  char at[32] = "";
  for (std::size_t i = 0; i < count; ++i) {  // newest first
    const verify::Event& e = events[n - 1 - i];
    if (by_sample) std::snprintf(at, sizeof at, " sample %u", e.move);
    std::snprintf(text, sizeof text, "%s T%d line %d%s: %.1f mm3 at X%.1f Y%.1f Z%.1f", verify::to_string(e.kind),
                  e.tool, e.line, at, e.volume_mm3, e.position.x, e.position.y, e.position.z);
    const auto severity = e.severity() == verify::Severity::Error ? gfx::AlarmSeverity::Error : gfx::AlarmSeverity::Warning;
    gfx::set_alarm(stats.alarms[static_cast<std::size_t>(stats.alarm_count++)], severity, text);
  }
  if (n > count || not_stored > 0) {
    std::snprintf(text, sizeof text, "%llu collision events in all (events.csv when the run ends)",
                  static_cast<unsigned long long>(n + not_stored));
    gfx::set_alarm(stats.alarms[static_cast<std::size_t>(stats.alarm_count++)], gfx::AlarmSeverity::Error, text);
  }
}

std::string design_summary(const verify::DesignReport& d, double tolerance_mm) {
  char buf[512];
  int n = std::snprintf(buf, sizeof buf, "gouge %.3f mm3, max %.3f mm", d.gouge_mm3, d.max_gouge_mm);
  if (d.max_gouge_level >= 0 && n > 0 && n < static_cast<int>(sizeof buf)) {
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), " at X%.3f Y%.3f Z%.3f", d.max_gouge_at.x,
                       d.max_gouge_at.y, d.max_gouge_at.z);
    if (d.gouge_line > 0 && n > 0 && n < static_cast<int>(sizeof buf))
      n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), " (%s:%d)", d.gouge_source.c_str(), d.gouge_line);
  }
  if (n > 0 && n < static_cast<int>(sizeof buf))
    std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), " | excess %.3f mm3, max %.3f mm beyond %.3f mm",
                  d.excess_mm3, d.max_excess_mm, tolerance_mm);
  return buf;
}

void put_design_json(const verify::DesignReport& d, const Profile& profile, nlohmann::json& j) {
  j["design"] = profile.design.stl_path;
  j["design_tolerance_mm"] = profile.design.tolerance_mm;
  j["design_volume_mm3"] = d.design_volume_mm3;
  j["design_gouge_mm3"] = d.gouge_mm3;
  j["design_excess_mm3"] = d.excess_mm3;
  j["max_gouge_mm"] = d.max_gouge_mm;
  j["max_excess_mm"] = d.max_excess_mm;
  if (d.max_gouge_level >= 0) j["max_gouge_at_mm"] = {d.max_gouge_at.x, d.max_gouge_at.y, d.max_gouge_at.z};
  else j["max_gouge_at_mm"] = nullptr;
  j["max_gouge_move"] = d.gouge_move;
  j["max_gouge_source"] = d.gouge_source;
  j["max_gouge_line"] = d.gouge_line;
}

namespace {

// The events as metrics.json's "events" array (fields as the columns of events.csv).
nlohmann::json events_json(const std::vector<verify::Event>& events) {
  nlohmann::json a = nlohmann::json::array();
  for (const verify::Event& e : events) {
    a.push_back({{"kind", verify::to_string(e.kind)},
                 {"severity", verify::to_string(e.severity())},
                 {"time_s", e.t_s},
                 {"source", e.source},
                 {"line", e.line},
                 {"last_line", e.last_line},
                 {"moves", e.moves},
                 {"move", e.move},
                 {"last_move", e.last_move},
                 {"tool", e.tool},
                 {"channel", e.channel},
                 {"position_mm", {e.position.x, e.position.y, e.position.z}},
                 {"volume_mm3", e.volume_mm3},
                 {"depth_mm", e.depth_mm},
                 {"region", e.region},
                 {"axis", verify::axis_name(e.axis)},
                 {"value", e.value}});
  }
  return a;
}

}  // namespace

void put_events_json(const std::vector<verify::Event>& events, bool checks, nlohmann::json& j) {
  j["checks"] = checks;
  const verify::EventCounts counts = verify::count(events);
  j["event_errors"] = counts.errors;
  j["event_warnings"] = counts.warnings;
  j["events"] = events_json(events);
}

std::string batch_metrics_json(const BatchResult& r, const Profile& profile, const std::string& program) {
  nlohmann::json j;
  j["lbrsim_version"] = version();
  j["program"] = program;
  j["profile"] = profile.source;
  j["stock_volume_mm3"] = r.stock_volume_mm3;
  j["removed_volume_mm3"] = r.removed_volume_mm3;
  j["final_volume_mm3"] = r.stock_volume_mm3 - r.removed_volume_mm3;
  j["machining_time_s"] = r.machining_time_s;
  j["wall_time_s"] = r.wall_time_s;
  j["factor"] = r.machining_time_s > 0 ? r.wall_time_s / r.machining_time_s : 0.0;
  j["levels"] = r.solid.levels();
  j["level_spacing_mm"] = r.solid.level_spacing_mm();
  j["regions"] = r.solid.regions();
  j["regions_x"] = r.solid.regions_x();
  j["regions_y"] = r.solid.regions_y();
  j["polygons"] = r.solid.polygon_count();
  j["contours"] = r.solid.contour_count();
  j["vertices"] = r.solid.vertex_count();
  j["moves"] = r.moves;
  j["sections"] = r.stats.sections;
  j["cells_clipped"] = r.stats.cells_clipped;
  j["kernel_batches"] = r.batches;
  j["cells_changed"] = r.stats.cells_changed;
  j["cells_reused"] = r.stats.cells_reused;
  j["sections_trimmed"] = r.stats.sections_trimmed;
  j["sections_in_air"] = r.stats.sections_in_air;
  j["tilted_in_air"] = r.stats.tilted_in_air;
  j["tilted_beside"] = r.stats.tilted_beside;
  j["sections_joined"] = r.stats.sections_joined;
  j["outlines_star"] = r.stats.outlines_star;
  j["cells_out_of_reach"] = r.stats.cells_out_of_reach;
  j["cells_in_anchor"] = r.stats.cells_in_anchor;
  j["clips_windowed"] = r.stats.clips_windowed;
  j["window_fallbacks"] = r.stats.window_fallbacks;
  j["chain_offsets"] = r.stats.chain_offsets;
  j["threads"] = r.threads;
  j["peak_rss_mb"] = peak_rss_mb();
  j["checks"] = profile.checks.enabled;
  const verify::EventCounts counts = verify::count(r.events);
  j["event_errors"] = counts.errors;
  j["event_warnings"] = counts.warnings;
  j["events"] = events_json(r.events);
  if (r.design) put_design_json(*r.design, profile, j);
  return j.dump(2) + "\n";
}

std::uint64_t write_samples_csv(const std::string& path, nc::Emulator& em) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw std::runtime_error(path + ": cannot open for writing: " + std::strerror(errno));
  f << "seq,t_s,tool,x_mm,y_mm,z_mm,a_deg,b_deg,c_deg\n";
  em.reset();
  nc::Sample s;
  std::uint64_t n = 0;
  char line[256];
  while (em.next(s)) {
    const int len = std::snprintf(line, sizeof line, "%llu,%.6f,%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n",
                                  static_cast<unsigned long long>(s.seq), s.t_s, s.tool, s.axes[0], s.axes[1],
                                  s.axes[2], s.axes[3], s.axes[4], s.axes[5]);
    f.write(line, len);
    ++n;
  }
  f.close();
  if (!f) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
  return n;
}

void write_file(const std::string& path, const std::string& bytes) { write_bytes(path, bytes); }
void write_file(const std::string& path, const std::vector<std::uint8_t>& bytes) { write_bytes(path, bytes); }

void write_mesh_files(const geom::LbrSolid& solid, const std::string& stl_path, const std::string& ply_path,
                      const DeviationColours& colours) {
  if (stl_path.empty() && ply_path.empty()) return;
  const std::vector<mesh::MeshBuffers> regions = mesh::reconstruct(solid);
  if (!stl_path.empty()) write_file(stl_path, mesh::to_binary_stl(regions));
  if (ply_path.empty()) return;
  std::vector<std::uint8_t> rgb;
  if (colours.design != nullptr) {
    std::vector<float> dev;
    for (const mesh::MeshBuffers& m : regions) {
      verify::vertex_deviation(*colours.design, solid, m.positions, m.normals, colours.tolerance_mm, dev);
      for (float d : dev) {
        const std::array<std::uint8_t, 3> c =
            gfx::deviation_rgb(d, static_cast<float>(gfx::kDeviationScalePerTolerance * colours.tolerance_mm));
        rgb.insert(rgb.end(), c.begin(), c.end());
      }
    }
  }
  write_file(ply_path, mesh::to_binary_ply(regions, rgb));
}

gfx::DeviationFn deviation_fn(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid, double tolerance_mm) {
  return [&design, &solid, tolerance_mm](const mesh::MeshBuffers& m, std::vector<float>& out) {
    verify::vertex_deviation(design, solid, m.positions, m.normals, tolerance_mm, out);
  };
}

void write_batch_outputs(const std::string& dir, const BatchResult& r, const Profile& profile,
                         const std::string& program) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create output directory: " + ec.message());
  write_file(dir + "/metrics.json", batch_metrics_json(r, profile, program));
  write_file(dir + "/levels.lbrs", geom::to_bytes(r.solid));
  write_file(dir + "/events.csv", verify::events_csv(r.events));
  if (r.design) write_file(dir + "/deviation.csv", verify::deviation_csv(*r.design));
}

}  // namespace lbr::app
