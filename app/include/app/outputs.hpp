// app/outputs.hpp — files a run leaves behind (docs/formats.md): metrics.json, levels.lbrs.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "app/batch.hpp"
#include "app/profile.hpp"
#include "gfx/exchange.hpp"
#include "gfx/renderer.hpp"
#include "nc/toolpath.hpp"

namespace lbr::app {

// G-code front ends: the built-in interpreter or LinuxCNC's rs274 (nc/rs274.hpp).
enum class Interpreter { Builtin, Rs274 };

// True for the G-code file extensions (.ngc, .nc, .gcode, .tap; any case).
[[nodiscard]] bool is_gcode_path(const std::string& path);

// Loads a tool path, choosing the front end by file extension (.moves; G-code: .ngc, .nc,
// .gcode, .tap, through `interpreter`). `profile` supplies the tool table, chord tolerance
// and G54 origin. Throws nc::ParseError or std::runtime_error with file and line.
[[nodiscard]] nc::Toolpath load_toolpath(const std::string& path, const Profile& profile,
                                         Interpreter interpreter = Interpreter::Builtin);

// The channels of a profile with [[channel]] tables, each with its program (channel.program,
// relative to the profile's folder) loaded with that channel's G54 origin. Throws
// std::runtime_error for a channel without a program, or like load_toolpath().
[[nodiscard]] std::vector<ChannelPath> load_channel_paths(const Profile& profile,
                                                          Interpreter interpreter = Interpreter::Builtin);

// Writes emulator samples as CSV (columns in docs/nc-frontend.md#samples-csv). Returns the
// number of samples. Throws std::runtime_error naming the path on I/O failure.
std::uint64_t write_samples_csv(const std::string& path, nc::Emulator& emulator);
// The bundled demo part program (config/programs/demo-pocket.moves, compiled in).
[[nodiscard]] nc::Toolpath demo_toolpath();

// The checks' keys of metrics.json (docs/formats.md#events): checks, event_errors,
// event_warnings and the "events" array (fields as the columns of events.csv).
void put_events_json(const std::vector<verify::Event>& events, bool checks, nlohmann::json& j);
// Events shown as status-bar alarms by view and run (the newest ones).
inline constexpr int kShownEventAlarms = 3;
// The newest `shown` of `events` as status-bar alarms, newest first ("shank-in-material T1
// line 12: 341.2 mm3 at X.. Y.. Z..", with "sample N" after the line for a live stream,
// `by_sample`), then, when not all are shown, one line counting them all plus `not_stored`
// (events a live run counted but had no room to keep). The HUD / operator UI of view and run.
// No allocation.
void fill_event_alarms(std::span<const verify::Event> events, std::uint64_t not_stored, int shown, bool by_sample,
                       gfx::LiveStats& stats) noexcept;
// --design: the comparison's keys of metrics.json (design_*, max_gouge_*; docs/formats.md#metrics-design),
// for batch, view and run alike.
void put_design_json(const verify::DesignReport& d, const Profile& profile, nlohmann::json& j);
// --design: the comparison in one line, "gouge V mm3, max D mm at X.. Y.. Z.. (FILE:LINE) |
// excess V mm3, max D mm beyond T mm" (stdout of batch, view and run; the viewer's HUD).
[[nodiscard]] std::string design_summary(const verify::DesignReport& d, double tolerance_mm);
// Metrics of a batch run as a JSON document (keys in docs/formats.md#metrics).
[[nodiscard]] std::string batch_metrics_json(const BatchResult& r, const Profile& profile, const std::string& program);

// Creates `dir` if needed and writes metrics.json and levels.lbrs into it. Throws
// std::runtime_error naming the path on I/O failure.
void write_batch_outputs(const std::string& dir, const BatchResult& r, const Profile& profile,
                         const std::string& program);

// Reconstructs the whole part (mesh/, joined walls) and writes it as binary STL and/or PLY;
// an empty path skips that format. For `lbrsim batch --stl/--ply` and live mode's export on
// request. Throws std::runtime_error naming the path on I/O failure.
// With `colours.design`, the PLY's vertices carry deviation colours (gfx::deviation_rgb of
// verify::vertex_deviation; --color deviation --design, docs/verification.md#deviation-colour).
struct DeviationColours {
  const std::vector<geom::Paths>* design = nullptr;  // verify::slice_design() of the model; null: none
  double tolerance_mm = 0.02;
};
void write_mesh_files(const geom::LbrSolid& solid, const std::string& stl_path, const std::string& ply_path,
                      const DeviationColours& colours = {});
// The renderer's per-vertex deviation values (gfx::RenderOptions::deviation) for `design`,
// sliced on the levels of `solid` (both must outlive the renderer).
[[nodiscard]] gfx::DeviationFn deviation_fn(const std::vector<geom::Paths>& design, const geom::LbrSolid& solid,
                                            double tolerance_mm);

void write_file(const std::string& path, const std::string& bytes);
void write_file(const std::string& path, const std::vector<std::uint8_t>& bytes);

}  // namespace lbr::app
