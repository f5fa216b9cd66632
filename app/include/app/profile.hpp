// app/profile.hpp — machine profiles (TOML): the composition of every module's configuration.
// Each module reads its own tables (docs/architecture.md, "Configuration"): geom [stock] and
// [lbr]'s kernel keys, kin and nc [machine], nc [nc], motion [[tool]], hal and sched [live] and
// [threads], gfx [render]; app/ reads [machine] name, [lbr] batch_moves / threads / live_threads and
// [[channel]], checks what spans modules, and rejects unknown keys. Every key is documented in
// docs/profiles.md. Loading errors name file, line and key.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "cfg/error.hpp"
#include "geom/lbr_solid.hpp"
#include "gfx/render_thread.hpp"
#include "hal/config.hpp"
#include "kin/kinematics.hpp"
#include "motion/tool_table.hpp"
#include "nc/config.hpp"
#include "nc/emulator.hpp"
#include "nc/gcode.hpp"
#include "verify/collision.hpp"
#include "verify/design.hpp"

namespace lbr::app {

// Every profile error, from whichever module read the key: "file:line: table.key: ...".
using ProfileError = cfg::ConfigError;

// One channel of a multi-channel machine ([[channel]] tables, docs/profiles.md): its own
// program, G54 origin and turret direction; tools come from the shared tool table.
struct Channel {
  std::string name;
  std::string program;       // path as written, resolved against the profile's folder
  std::array<double, 3> g54_origin_mm{0, 0, 0};
  kin::Kinematics kin;       // the machine's kinematics with this channel's turret angle
};

struct Profile {
  std::string source;          // file name, or "<built-in default>"
  std::string name;            // [machine] name
  kin::Kinematics kin;         // [machine] kind and kinematics keys (kin/config_toml.hpp)
  nc::MachineConfig machine;   // [machine] rates, axis limits, G54 origin, diameter programming (nc/config_toml.hpp)
  nc::FrontEndConfig nc;       // [nc]: G-code front ends (nc/config_toml.hpp)
  geom::SolidSpec solid;       // [stock], [lbr] kernel keys: stock, Δ, region grid, chord tolerance (geom/config_toml.hpp)
  bool regions_auto = false;   // [lbr] regions = "auto" (auto_region_grid)
  int batch_moves = 512;       // [lbr] moves per subtract() call in batch mode
  int threads = 0;             // [lbr] batch-mode kernel threads (0 = one per hardware thread)
  int live_threads = 1;        // [lbr] kernel threads of `lbrsim run`'s long calls (live_kernel_threads())
  motion::ToolsConfig tooling; // [[tool]]: milling tools, lathe inserts, live-tool mounts (motion/config_toml.hpp)
  hal::LiveConfig live;        // [live], [[live.axis]], [threads]: `lbrsim run` (hal/config_toml.hpp)
  // [lbr] live_regions: the region grid of `lbrsim run`'s solid when it differs from
  // [lbr] regions (set = false: the same). A live kernel call clips every cell a sweep reaches, whole,
  // so smaller cells make the short calls of a live run cheaper (docs/performance.md "Live lag").
  struct LiveGrid {
    bool set = false, automatic = false;
    int x = 0, y = 0;
  } live_grid;
  gfx::RenderThreadConfig render;  // [render]: the render thread's rate (gfx/config_toml.hpp)
  verify::CheckConfig checks;      // [checks]: collision and process checks (verify/config_toml.hpp)
  verify::DesignConfig design;     // batch --design / --tolerance only (no profile key): design-model comparison
  std::vector<Channel> channels;   // [[channel]]; empty: one channel, the program given
};

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
// Emulator limits from a profile (nc::emulator_limits of its [machine] keys).
[[nodiscard]] nc::EmulatorLimits emulator_limits(const Profile& p);

// Region grid for regions = "auto": an interim rule from stock size and tool diameter
// (docs/profiles.md). Returns {nx, ny}.
[[nodiscard]] std::pair<int, int> auto_region_grid(const geom::SolidSpec& solid, double max_tool_diameter_mm);

// Threads of `lbrsim run`'s kernel pool, called on the geometry thread: [lbr] live_threads,
// at most the processors that thread may run on (pinned by geometry_cpu: 1, no pool).
[[nodiscard]] int live_kernel_threads(const Profile& p) noexcept;

// Command-line overrides, with the syntax of `lbrsim batch --help`. Throw ProfileError.
void apply_stock_override(Profile& p, const std::string& spec);
void apply_tool_override(Profile& p, const std::string& spec);
void apply_regions(Profile& p, const std::string& spec, const std::string& where);

}  // namespace lbr::app
