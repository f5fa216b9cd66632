#include "motion/config_toml.hpp"

#include <algorithm>
#include <string>

namespace lbr::motion {

namespace {

bool is_turning_kind(const std::string& k) { return k == "turning" || k == "boring" || k == "grooving"; }

// The message of a geom validate() starts with the key it is about; report it with its line.
[[noreturn]] void fail_validation(cfg::Table& s, const std::string& e, bool groove) {
  std::string key = e.substr(0, e.find(' '));
  if (key == "edge_length_mm" && groove) key = "depth_mm";
  s.fail(s.peek(key), key, e.substr(e.find(' ') + 1));
}

// Kind turning, boring or grooving: a lathe insert.
geom::TurningTool read_insert(cfg::Table& s, const std::string& kind) {
  geom::TurningTool t;
  t.internal = kind == "boring";
  if (kind == "grooving") {
    t.insert = geom::InsertKind::Groove;
    t.width_mm = s.required_number("width_mm", 0.01, 100.0, "mm");
    t.nose_radius_mm = s.number("nose_radius_mm", 0.0, 0.0, 10.0, "mm");
    t.edge_length_mm = s.number("depth_mm", 10.0, 0.01, 1000.0, "mm");
  } else {
    const std::string ins = s.string("insert", "diamond80");
    if (!geom::parse_insert_kind(ins, t.insert) || t.insert == geom::InsertKind::Groove)
      s.fail(s.peek("insert"), "insert", "expected one of diamond80, diamond55, v35; got '" + ins + "'");
    t.nose_radius_mm = s.number("nose_radius_mm", 0.4, 0.0, 10.0, "mm");
    t.edge_length_mm = s.number("edge_length_mm", 12.0, 0.01, 1000.0, "mm");
    t.approach_deg = s.number("approach_angle_deg", t.insert == geom::InsertKind::Diamond80 ? 95.0 : 93.0, 0.0, 180.0, "deg");
  }
  t.holder_width_mm = s.number("holder_width_mm", 0.0, 0.0, 1000.0, "mm");
  t.holder_z_mm = s.number("holder_z_mm", 0.0, -1000.0, 1000.0, "mm");
  t.holder_r_mm = s.number("holder_r_mm", 0.0, 0.0, 1000.0, "mm");
  if (const std::string e = t.validate(); !e.empty()) fail_validation(s, e, t.insert == geom::InsertKind::Groove);
  return t;
}

kin::Mount read_live_mount(cfg::Table& s) {
  const toml::node* ln = s.get("live");
  if (ln == nullptr) return kin::Mount::Spindle;
  const auto v = ln->value_exact<std::string>();
  if (!v || (*v != "axial" && *v != "radial")) s.fail(ln, "live", "expected \"axial\" or \"radial\"");
  return *v == "axial" ? kin::Mount::Axial : kin::Mount::Radial;
}

// The other kinds: a milling cutter (spindle tool, or live tool on lathe-c).
geom::Tool read_cutter(cfg::Table& s, kin::Mount& mount) {
  geom::Tool t;
  const std::string kind = s.string("kind", "");
  if (!geom::parse_tool_kind(kind, t.kind))
    s.fail(s.peek("kind"), "kind", "expected one of flat, ball, bull, drill, vbit, turning, boring, grooving; got '" + kind + "'");
  mount = read_live_mount(s);
  t.diameter_mm = s.required_number("diameter_mm", 0.001, 1000.0, "mm");
  t.flute_length_mm = s.number("flute_length_mm", 3.0 * t.diameter_mm, 0.001, 5000.0, "mm");
  t.length_mm = s.number("length_mm", std::max(t.flute_length_mm, 6.0 * t.diameter_mm), 0.001, 5000.0, "mm");
  t.shank_diameter_mm = s.number("shank_diameter_mm", t.diameter_mm, 0.0, 1000.0, "mm");
  t.holder_diameter_mm = s.number("holder_diameter_mm", 40.0, 0.0, 1000.0, "mm");
  t.holder_length_mm = s.number("holder_length_mm", 40.0, 0.0, 5000.0, "mm");
  const bool end_mill = t.kind == geom::ToolKind::Flat || t.kind == geom::ToolKind::Bull;
  if (!end_mill && s.peek("centre_cutting") != nullptr)
    s.fail(s.peek("centre_cutting"), "centre_cutting", "only for tool kinds flat and bull (ball, drill and vbit tools cut at the centre)");
  t.centre_cutting = s.boolean("centre_cutting", true);
  if (t.kind == geom::ToolKind::Bull) t.corner_radius_mm = s.required_number("corner_radius_mm", 0.0, 500.0, "mm");
  if (t.kind == geom::ToolKind::Drill) t.angle_deg = s.number("point_angle_deg", 118.0, 1.0, 179.0, "deg");
  if (t.kind == geom::ToolKind::VBit) t.angle_deg = s.required_number("included_angle_deg", 1.0, 179.0, "deg");
  if (const std::string e = t.validate(); !e.empty()) s.fail(nullptr, "", e);
  return t;
}

// A live tool's mount on this machine kind: lathe-c holds milling tools axially unless told.
kin::Mount check_mount(cfg::Table& s, nc::MachineKind machine, kin::Mount mount, const std::string& kind) {
  if (machine == nc::MachineKind::Lathe)
    s.fail(s.peek("kind"), "kind", "a lathe has no live tools (use machine kind lathe-c), got a '" + kind + "' tool");
  if (machine == nc::MachineKind::LatheC && mount == kin::Mount::Spindle) return kin::Mount::Axial;
  if (machine != nc::MachineKind::LatheC && mount != kin::Mount::Spindle) s.fail(s.peek("live"), "live", "only for machine kind lathe-c");
  return mount;
}

}  // namespace

void read_tool(cfg::Table& s, nc::MachineKind machine, ToolsConfig& tools) {
  const int number = static_cast<int>(s.integer("number", -1, 1, 9999));
  if (number < 0) s.fail(nullptr, "number", "missing (every [[tool]] needs a number in [1, 9999])");
  const toml::node* kn = s.peek("kind");
  const std::string kind = kn != nullptr && kn->is_string() ? *kn->value<std::string>() : "";
  auto check_unique = [&] {
    if (tools.tools.count(number) || tools.inserts.count(number))
      s.fail(s.peek("number"), "number", "tool " + std::to_string(number) + " is defined twice");
  };
  if (is_turning_kind(kind)) {
    s.string("kind", "");
    if (!nc::is_lathe(machine))
      s.fail(kn, "kind", "'" + kind + "' tools need machine kind lathe or lathe-c, this is " + nc::to_string(machine));
    const geom::TurningTool t = read_insert(s, kind);
    check_unique();
    tools.inserts[number] = t;
    return;
  }
  kin::Mount mount = kin::Mount::Spindle;
  const geom::Tool t = read_cutter(s, mount);
  check_unique();
  tools.live_mounts[number] = check_mount(s, machine, mount, kind);
  tools.tools[number] = t;
}

}  // namespace lbr::motion
