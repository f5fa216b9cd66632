#include "app/profile.hpp"

#include "app/install_paths.hpp"

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "cfg/table.hpp"
#include "geom/config_toml.hpp"
#include "verify/config_toml.hpp"
#include "gfx/config_toml.hpp"
#include "hal/config_toml.hpp"
#include "kin/config_toml.hpp"
#include "motion/config_toml.hpp"
#include "nc/config_toml.hpp"

#include "default_profile.inc"  // kDefaultProfileToml, generated from config/profiles/default-mill3.toml

namespace lbr::app {

namespace {

// Opens [key] when the profile has it, lets `read` take its keys, then rejects the others.
template <class Read>
void read_table(cfg::Table& top, const char* key, Read read) {
  if (const toml::table* t = top.table(key)) {
    cfg::Table s(*t, key, top.file());
    read(s);
    s.reject_unknown();
  }
}

// The same for every table of an array of tables [[key]].
template <class Read>
void read_tables(cfg::Table& top, const char* key, Read read) {
  for (const toml::table* t : top.tables(key)) {
    cfg::Table s(*t, key, top.file());
    read(s);
    s.reject_unknown();
  }
}

// [machine]: app's name; kin's kind and kinematics; nc's rates, limits and frames.
void read_machine(cfg::Table& s, Profile& p) {
  p.name = s.string("name", "");
  kin::read_machine(s, p.kin);
  nc::read_machine(s, p.kin.kind, p.machine);
}

// [lbr] live_regions: the region grid of `lbrsim run`'s solid.
void read_live_grid(cfg::Table& s, Profile& p) {
  const toml::node* r = s.get("live_regions");
  if (r == nullptr) return;
  const auto v = r->value_exact<std::string>();
  if (!v) s.fail(r, "live_regions", "expected a string \"NXxNY\" or \"auto\"");
  geom::SolidSpec grid;
  if (const std::string e = geom::apply_regions(*v, grid, p.live_grid.automatic); !e.empty()) s.fail(r, "live_regions", e);
  p.live_grid.set = true;
  p.live_grid.x = grid.regions_x;
  p.live_grid.y = grid.regions_y;
}

// [lbr]: the kernel's keys (geom) and the batch runner's.
void read_lbr(cfg::Table& s, Profile& p) {
  geom::read_lbr(s, p.solid, p.regions_auto);
  p.batch_moves = static_cast<int>(s.integer("batch_moves", 512, 1, 100000));
  p.threads = static_cast<int>(s.integer("threads", 0, 0, 256));
  p.live_threads = static_cast<int>(s.integer("live_threads", 1, 1, 256));
  read_live_grid(s, p);
}

// [stock] is required.
void read_stock(cfg::Table& top, Profile& p) {
  const toml::table* st = top.table("stock");
  if (st == nullptr) top.fail(nullptr, "stock", "missing table [stock]");
  cfg::Table s(*st, "stock", top.file());
  geom::read_stock(s, p.solid);
  s.reject_unknown();
}

// Lathe kinds: the workpiece frame's Z is the spindle axis, so the stock is a bar on it.
void check_lathe_stock(const cfg::Table& top, const Profile& p) {
  if (!nc::is_lathe(p.kin.kind)) return;
  const geom::CylinderStock& cy = p.solid.cylinder;
  if (p.solid.shape != geom::SolidSpec::Shape::Cylinder || cy.center_x_mm != 0.0 || cy.center_y_mm != 0.0)
    top.fail(top.peek("stock"), "stock", std::string("machine kind ") + nc::to_string(p.kin.kind) +
                                             " needs a cylinder stock on the spindle axis (shape = \"cylinder\", center_mm = [0, 0])");
}

// [[channel]]: a channel starts from the machine's kinematics and G54 origin.
Channel read_channel(cfg::Table& s, const Profile& p) {
  Channel c;
  c.kin = p.kin;
  c.g54_origin_mm = p.machine.g54_origin_mm;
  c.name = s.string("name", "ch" + std::to_string(p.channels.size() + 1));
  c.program = s.string("program", "");
  if (s.peek("g54_origin_mm") != nullptr) {
    const auto v = s.numbers("g54_origin_mm", 3, "mm");
    c.g54_origin_mm = {v[0], v[1], v[2]};
  }
  s.only_for("turret_angle_deg", nc::is_lathe(p.kin.kind), "lathe or lathe-c");
  c.kin.turret_angle_deg = s.number("turret_angle_deg", p.kin.turret_angle_deg, -360.0, 360.0, "deg");
  for (const Channel& o : p.channels)
    if (o.name == c.name) s.fail(s.peek("name"), "name", "channel '" + c.name + "' is defined twice");
  return c;
}

std::vector<double> split_numbers(const std::string& s, const std::string& what) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v)) throw ProfileError(what + ": '" + item + "' is not a number");
    out.push_back(v);
  }
  return out;
}

}  // namespace

int live_kernel_threads(const Profile& p) noexcept {
  if (p.live_threads <= 1) return 1;
  cpu_set_t set;
  CPU_ZERO(&set);
  const int usable = sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set)
                                                                   : static_cast<int>(std::thread::hardware_concurrency());
  return std::max(1, std::min(p.live_threads, usable));
}

void apply_regions(Profile& p, const std::string& spec, const std::string& where) {
  if (const std::string e = geom::apply_regions(spec, p.solid, p.regions_auto); !e.empty()) throw ProfileError(where + ": " + e);
}

// Each module reads its own tables; the order matters only where one depends on another
// ([machine]'s kind before [[tool]] and [[channel]]).
Profile parse_profile(const std::string& text, const std::string& name) {
  const toml::table root = cfg::parse(text, name);
  Profile p;
  p.source = name;
  cfg::Table top(root, "", name);
  read_table(top, "machine", [&](cfg::Table& s) { read_machine(s, p); });
  read_stock(top, p);
  read_table(top, "lbr", [&](cfg::Table& s) { read_lbr(s, p); });
  read_tables(top, "tool", [&](cfg::Table& s) { motion::read_tool(s, p.kin.kind, p.tooling); });
  check_lathe_stock(top, p);
  read_tables(top, "channel", [&](cfg::Table& s) { p.channels.push_back(read_channel(s, p)); });
  read_table(top, "nc", [&](cfg::Table& s) { nc::read_nc(s, p.nc); });
  read_table(top, "live", [&](cfg::Table& s) { hal::read_live(s, p.live); });
  if (p.live.axes.empty()) p.live.axes = hal::default_axes();
  read_table(top, "threads", [&](cfg::Table& s) { hal::read_threads(s, p.live); });
  read_table(top, "render", [&](cfg::Table& s) { gfx::read_render(s, p.render); });
  read_table(top, "checks", [&](cfg::Table& s) { verify::read_checks(s, p.checks); });
  top.reject_unknown();
  return p;
}

Profile load_profile(const std::string& path_as_given) {
  const std::string path = find_profile(path_as_given);  // then /etc/lbrsim (app/install_paths.hpp)
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ProfileError(path + ":0: cannot open profile");
  std::ostringstream ss;
  ss << f.rdbuf();
  return parse_profile(ss.str(), path);
}

const char* default_profile_text() noexcept { return kDefaultProfileToml; }

Profile default_profile() { return parse_profile(kDefaultProfileToml, "<built-in default-mill3>"); }

nc::GcodeOptions gcode_options(const Profile& p, const Channel& c) {
  nc::GcodeOptions o = gcode_options(p);
  for (int a = 0; a < 3; ++a) o.work_offsets[0][a] = c.g54_origin_mm[static_cast<std::size_t>(a)];
  return o;
}

nc::GcodeOptions gcode_options(const Profile& p) {
  nc::GcodeOptions o;
  o.machine = p.kin.kind;
  const bool lathe = nc::is_lathe(p.kin.kind);
  o.diameter_mode = lathe && p.machine.diameter_programming;
  // On lathes the programmed point is the tool's reference point (the controller applies the
  // X/Z offsets it measured), so no tool length is applied (docs/machine-kinds.md).
  for (const auto& [n, t] : p.tooling.tools) {
    o.tool_lengths[n] = lathe ? 0.0 : t.length_mm;
    o.tool_diameters[n] = t.diameter_mm;
  }
  for (const auto& [n, insert] : p.tooling.inserts) o.tool_lengths.emplace(n, 0.0);  // rs274's tool table lists them too
  if (p.kin.kind == nc::MachineKind::Mill5) {
    const bool ac = p.kin.rotary == kin::Rotary::TableAC || p.kin.rotary == kin::Rotary::HeadAC;
    o.rotary = {ac, !ac, true};
  }
  // [nc] keys (nc::FrontEndConfig) reach the front ends here.
  o.subroutine_path = p.nc.subroutine_path;
  o.dialect = p.nc.dialect;
  o.start_tool = p.nc.start_tool;
  o.chord_tol_mm = p.solid.chord_tol_mm;
  for (int a = 0; a < 3; ++a) o.work_offsets[0][a] = p.machine.g54_origin_mm[static_cast<std::size_t>(a)];
  return o;
}

nc::EmulatorLimits emulator_limits(const Profile& p) { return nc::emulator_limits(p.machine); }

std::pair<int, int> auto_region_grid(const geom::SolidSpec& solid, double max_tool_diameter_mm) {
  double wx, wy;
  if (solid.shape == geom::SolidSpec::Shape::Box) {
    wx = solid.box.max.x - solid.box.min.x;
    wy = solid.box.max.y - solid.box.min.y;
  } else {
    wx = wy = solid.cylinder.diameter_mm;
  }
  // Regions of at most 2.5 tool diameters keep a single sweep within few regions while the
  // polygons per region stay small; capped at 16 per axis (see docs/profiles.md).
  const double side = std::max(2.5 * max_tool_diameter_mm, 1.0);
  auto n = [&](double w) { return std::clamp(static_cast<int>(std::ceil(w / side - 1e-9)), 1, 16); };
  return {n(wx), n(wy)};
}

void apply_stock_override(Profile& p, const std::string& spec) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string what = "--stock " + spec;
  if (colon == std::string::npos) throw ProfileError(what + ": expected box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX or cylinder:DIAMETER,ZMIN,ZMAX");
  const auto v = split_numbers(spec.substr(colon + 1), what);
  if (kind == "box") {
    if (v.size() != 6) throw ProfileError(what + ": box needs 6 numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX [mm]");
    if (!(v[0] < v[3] && v[1] < v[4] && v[2] < v[5])) throw ProfileError(what + ": box needs min < max on every axis");
    p.solid.shape = geom::SolidSpec::Shape::Box;
    p.solid.box = geom::BoxStock{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  } else if (kind == "cylinder") {
    if (v.size() != 3) throw ProfileError(what + ": cylinder needs 3 numbers DIAMETER,ZMIN,ZMAX [mm]");
    if (!(v[0] > 0 && v[1] < v[2])) throw ProfileError(what + ": cylinder needs DIAMETER > 0 and ZMIN < ZMAX");
    p.solid.shape = geom::SolidSpec::Shape::Cylinder;
    p.solid.cylinder = geom::CylinderStock{0.0, 0.0, v[0], v[1], v[2]};
  } else {
    throw ProfileError(what + ": stock kind must be 'box' or 'cylinder', got '" + kind + "'");
  }
}

void apply_tool_override(Profile& p, const std::string& spec) {
  const std::string what = "--tool " + spec;
  std::vector<std::string> f;
  std::stringstream in(spec);
  std::string item;
  while (std::getline(in, item, ':')) f.push_back(item);
  if (f.size() < 3 || f.size() > 4) throw ProfileError(what + ": expected N:KIND:DIAMETER[:PARAM]");
  const auto num = split_numbers(f[0], what);
  if (num.size() != 1 || num[0] < 1 || num[0] > 9999 || num[0] != std::floor(num[0]))
    throw ProfileError(what + ": tool number must be an integer in [1, 9999]");
  geom::Tool t;
  if (!geom::parse_tool_kind(f[1], t.kind)) throw ProfileError(what + ": KIND must be flat, ball, bull, drill or vbit");
  const auto d = split_numbers(f[2], what);
  if (d.size() != 1) throw ProfileError(what + ": DIAMETER must be one number [mm]");
  t.diameter_mm = d[0];
  t.flute_length_mm = 3.0 * t.diameter_mm;
  t.length_mm = std::max(t.flute_length_mm, 6.0 * t.diameter_mm);
  t.shank_diameter_mm = t.diameter_mm;
  const bool needs_param = t.kind == geom::ToolKind::Bull || t.kind == geom::ToolKind::VBit;
  if (f.size() == 4) {
    if (t.kind == geom::ToolKind::Flat || t.kind == geom::ToolKind::Ball)
      throw ProfileError(what + ": " + f[1] + " tools take no PARAM");
    const auto q = split_numbers(f[3], what);
    if (q.size() != 1) throw ProfileError(what + ": PARAM must be one number");
    if (t.kind == geom::ToolKind::Bull) t.corner_radius_mm = q[0];
    else t.angle_deg = q[0];
  } else if (needs_param) {
    throw ProfileError(what + ": " + f[1] + " needs PARAM (" +
                       (t.kind == geom::ToolKind::Bull ? "corner radius [mm]" : "included angle [deg]") + ")");
  }
  if (const std::string e = t.validate(); !e.empty()) throw ProfileError(what + ": " + e);
  p.tooling.tools[static_cast<int>(num[0])] = t;
}

}  // namespace lbr::app
