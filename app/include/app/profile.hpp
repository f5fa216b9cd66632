// app/profile.hpp — machine profiles (TOML): machine, stock, LBR settings and tool table.
// Every key is documented in docs/profiles.md. Loading errors name file, line and key.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "geom/lbr_solid.hpp"
#include "geom/tool.hpp"
#include "geom/turning.hpp"
#include "kin/kinematics.hpp"
#include "motion/tool_table.hpp"
#include "hal/config.hpp"
#include "nc/emulator.hpp"
#include "nc/gcode.hpp"

namespace lbr::app {

class ProfileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One channel of a multi-channel machine ([[channel]] tables, docs/profiles.md): its own
// program, G54 origin and turret direction; tools come from the shared tool table.
struct Channel {
  std::string name;
  std::string program;       // path as written, resolved against the profile's folder
  std::array<double, 3> g54_origin_mm{0, 0, 0};
  kin::Kinematics kin;       // the machine's kinematics with this channel's turret angle
};

struct Profile {
  std::string source;  // file name, or "<built-in default>"
  std::string name;
  std::string machine_kind = "mill3";
  double rapid_mm_per_min = 15000.0;
  double tool_change_s = 0.0;
  // Machine emulator and G-code frames ([machine] keys in docs/profiles.md).
  std::array<double, 3> max_velocity_mm_per_min{0, 0, 0};  // per axis X Y Z; 0: the rapid rate
  std::array<double, 3> max_accel_mm_per_s2{1000, 1000, 1000};  // per axis X Y Z
  double max_feed_mm_per_min = 0.0;   // cap on programmed feeds; 0: none
  double sample_period_ms = 4.0;      // emulator sample period
  std::array<double, 3> g54_origin_mm{0, 0, 0};  // machine coordinates of the G54 origin
  geom::SolidSpec solid;    // stock, Δ, region grid, chord tolerance
  bool regions_auto = false;
  int batch_moves = 512;    // moves per subtract() call in batch mode
  int threads = 0;          // batch-mode kernel threads (0 = one per hardware thread)
  std::map<int, geom::Tool> tools;             // milling tools (spindle or live tools)
  double render_rate_hz = 30.0;  // [render] rate_hz: the render thread's fixed frame rate
  double render_ui_scale = 1.5;  // [render] ui_scale: operator UI size factor (fonts, buttons)
  hal::LiveConfig live;     // [live], [[live.axis]], [threads]: `lbrsim run` (docs/profiles.md)
  // Machine kinematics ([machine] kind, rotary, ... in docs/profiles.md).
  kin::Kinematics kin;
  bool diameter_programming = true;            // lathe kinds: X words are diameters (G7)
  std::map<int, geom::TurningTool> inserts;    // turning tools (lathe kinds), same numbering
  std::map<int, kin::Mount> live_mounts;       // lathe-c: how each milling tool is mounted
  std::vector<Channel> channels;               // empty: one channel, the program given
  // [nc]: G-code front ends (docs/profiles.md, docs/nc-frontend.md).
  std::vector<std::string> subroutine_path;    // searched for NAME.ngc after the program's folder
  int start_tool = 0;                          // tool in the spindle at program start (0: none)
  // Mount of tool n on this machine (Spindle on mills).
  [[nodiscard]] kin::Mount mount_of(int tool) const;
};

// The tool table's definitions (motion::ToolTable) from a profile.
[[nodiscard]] motion::ToolsConfig tool_config(const Profile& p);

// Parses profile text; `name` is used in messages. Throws ProfileError("name:line: ...").
[[nodiscard]] Profile parse_profile(const std::string& text, const std::string& name);
[[nodiscard]] Profile load_profile(const std::string& path);
// The built-in default 3-axis mill profile (config/profiles/default-mill3.toml, compiled in).
[[nodiscard]] Profile default_profile();
[[nodiscard]] const char* default_profile_text() noexcept;

// Interpreter options from a profile: tool lengths, machine kind, chord tolerance, G54 origin.
[[nodiscard]] nc::GcodeOptions gcode_options(const Profile& p);
// The same for one channel of a multi-channel profile (its G54 origin).
[[nodiscard]] nc::GcodeOptions gcode_options(const Profile& p, const Channel& c);
// Emulator limits from a profile (axis limits, rapid rate, sample period, tool change time).
[[nodiscard]] nc::EmulatorLimits emulator_limits(const Profile& p);

// Region grid for regions = "auto": an interim rule from stock size and tool diameter
// (docs/profiles.md). Returns {nx, ny}.
[[nodiscard]] std::pair<int, int> auto_region_grid(const geom::SolidSpec& solid, double max_tool_diameter_mm);

// Command-line overrides, with the syntax of `lbrsim batch --help`. Throw ProfileError.
void apply_stock_override(Profile& p, const std::string& spec);
void apply_tool_override(Profile& p, const std::string& spec);
void apply_regions(Profile& p, const std::string& spec, const std::string& where);

}  // namespace lbr::app
