#include "app/profile.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include <toml++/toml.h>

#include "hal/sample.hpp"

#include "default_profile.inc"  // kDefaultProfileToml, generated from config/profiles/default-mill3.toml

namespace lbr::app {

namespace {

// Reads one TOML table, remembering which keys were used so that unknown keys (typos) can
// be reported with their line.
class Section {
 public:
  Section(const toml::table& t, std::string path, const std::string& file) : t_(t), path_(std::move(path)), file_(file) {}

  [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& msg) const {
    const auto line = n != nullptr ? n->source().begin.line : t_.source().begin.line;
    throw ProfileError(file_ + ":" + std::to_string(line) + ": " + qualified(key) + ": " + msg);
  }
  [[nodiscard]] std::string qualified(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  const toml::node* get(const std::string& key) {
    used_.insert(key);
    return t_.get(key);
  }
  double number(const std::string& key, double def, double lo, double hi, const char* unit) {
    const toml::node* n = get(key);
    if (n == nullptr) return def;
    double v;
    if (auto f = n->value<double>()) v = *f;
    else fail(n, key, std::string("expected a number [") + unit + "]");
    if (!std::isfinite(v) || v < lo || v > hi) {
      std::ostringstream m;
      m << "expected a number in [" << lo << ", " << hi << "] " << unit << ", got " << v;
      fail(n, key, m.str());
    }
    return v;
  }
  double required_number(const std::string& key, double lo, double hi, const char* unit) {
    if (t_.get(key) == nullptr) fail(nullptr, key, std::string("missing (a number [") + unit + "] is required)");
    return number(key, 0.0, lo, hi, unit);
  }
  long integer(const std::string& key, long def, long lo, long hi) {
    const toml::node* n = get(key);
    if (n == nullptr) return def;
    const auto v = n->value_exact<std::int64_t>();
    if (!v || *v < lo || *v > hi)
      fail(n, key, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<long>(*v);
  }
  std::string string(const std::string& key, const std::string& def) {
    const toml::node* n = get(key);
    if (n == nullptr) return def;
    const auto v = n->value_exact<std::string>();
    if (!v) fail(n, key, "expected a string");
    return *v;
  }
  bool boolean(const std::string& key, bool def) {
    const toml::node* n = get(key);
    if (n == nullptr) return def;
    const auto v = n->value_exact<bool>();
    if (!v) fail(n, key, "expected true or false");
    return *v;
  }
  std::vector<double> numbers(const std::string& key, std::size_t count, const char* unit) {
    const toml::node* n = get(key);
    if (n == nullptr) fail(nullptr, key, "missing (an array of " + std::to_string(count) + " numbers [" + unit + "] is required)");
    const toml::array* a = n->as_array();
    if (a == nullptr || a->size() != count) fail(n, key, "expected an array of " + std::to_string(count) + " numbers [" + unit + "]");
    std::vector<double> out;
    for (const toml::node& e : *a) {
      const auto v = e.value<double>();
      if (!v || !std::isfinite(*v)) fail(&e, key, std::string("expected numbers [") + unit + "]");
      out.push_back(*v);
    }
    return out;
  }
  const toml::table* table(const std::string& key) {
    const toml::node* n = get(key);
    if (n == nullptr) return nullptr;
    if (!n->is_table()) fail(n, key, "expected a table [" + qualified(key) + "]");
    return n->as_table();
  }
  void reject_unknown() const {
    for (const auto& [k, v] : t_) {
      const std::string key(k.str());
      if (!used_.count(key)) fail(&v, key, "unknown key");
    }
  }
  [[nodiscard]] const toml::table& raw() const { return t_; }

 private:
  const toml::table& t_;
  std::string path_;
  const std::string& file_;
  std::set<std::string> used_;
};

bool is_turning_kind(const std::string& k) { return k == "turning" || k == "boring" || k == "grooving"; }

// [[tool]] with kind turning, boring or grooving: a lathe insert (docs/profiles.md).
geom::TurningTool read_turning_tool(Section& s, const std::string& kind) {
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
      s.fail(s.raw().get("insert"), "insert", "expected one of diamond80, diamond55, v35; got '" + ins + "'");
    t.nose_radius_mm = s.number("nose_radius_mm", 0.4, 0.0, 10.0, "mm");
    t.edge_length_mm = s.number("edge_length_mm", 12.0, 0.01, 1000.0, "mm");
    t.approach_deg = s.number("approach_angle_deg", t.insert == geom::InsertKind::Diamond80 ? 95.0 : 93.0, 0.0, 180.0, "deg");
  }
  // validate() messages start with the key they are about; report it with its line.
  if (const std::string e = t.validate(); !e.empty()) {
    std::string key = e.substr(0, e.find(' '));
    if (key == "edge_length_mm" && t.insert == geom::InsertKind::Groove) key = "depth_mm";
    s.fail(s.raw().get(key), key, e.substr(e.find(' ') + 1));
  }
  s.reject_unknown();
  return t;
}

geom::Tool read_tool(Section& s, int& number, kin::Mount& mount) {
  number = static_cast<int>(s.integer("number", -1, 1, 9999));
  if (number < 0) s.fail(nullptr, "number", "missing (every [[tool]] needs a number in [1, 9999])");
  geom::Tool t;
  const std::string kind = s.string("kind", "");
  const toml::node* kn = s.raw().get("kind");
  if (!geom::parse_tool_kind(kind, t.kind))
    s.fail(kn, "kind", "expected one of flat, ball, bull, drill, vbit, turning, boring, grooving; got '" + kind + "'");
  mount = kin::Mount::Spindle;
  if (const toml::node* ln = s.get("live")) {
    const auto v = ln->value_exact<std::string>();
    if (!v || (*v != "axial" && *v != "radial")) s.fail(ln, "live", "expected \"axial\" or \"radial\"");
    mount = *v == "axial" ? kin::Mount::Axial : kin::Mount::Radial;
  }
  t.diameter_mm = s.required_number("diameter_mm", 0.001, 1000.0, "mm");
  t.flute_length_mm = s.number("flute_length_mm", 3.0 * t.diameter_mm, 0.001, 5000.0, "mm");
  t.length_mm = s.number("length_mm", std::max(t.flute_length_mm, 6.0 * t.diameter_mm), 0.001, 5000.0, "mm");
  t.shank_diameter_mm = s.number("shank_diameter_mm", t.diameter_mm, 0.0, 1000.0, "mm");
  t.holder_diameter_mm = s.number("holder_diameter_mm", 40.0, 0.0, 1000.0, "mm");
  t.holder_length_mm = s.number("holder_length_mm", 40.0, 0.0, 5000.0, "mm");
  if (t.kind == geom::ToolKind::Bull) t.corner_radius_mm = s.required_number("corner_radius_mm", 0.0, 500.0, "mm");
  if (t.kind == geom::ToolKind::Drill) t.angle_deg = s.number("point_angle_deg", 118.0, 1.0, 179.0, "deg");
  if (t.kind == geom::ToolKind::VBit) t.angle_deg = s.required_number("included_angle_deg", 1.0, 179.0, "deg");
  if (const std::string e = t.validate(); !e.empty()) s.fail(nullptr, "", e);
  s.reject_unknown();
  return t;
}

bool parse_grid(const std::string& spec, int& nx, int& ny) {
  const auto x = spec.find('x');
  if (x == std::string::npos) return false;
  try {
    std::size_t a = 0, b = 0;
    nx = std::stoi(spec.substr(0, x), &a);
    ny = std::stoi(spec.substr(x + 1), &b);
    return a == x && b == spec.size() - x - 1 && nx >= 1 && ny >= 1 && nx <= 256 && ny <= 256;
  } catch (const std::exception&) {
    return false;
  }
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

int axis_index(Section& s, const toml::table& t) {
  const std::string a = s.string("axis", "");
  static const char* kNames[] = {"X", "Y", "Z", "A", "B", "C"};
  for (int i = 0; i < 6; ++i)
    if (a == kNames[i]) return i;
  s.fail(t.get("axis"), "axis", "expected one of X, Y, Z, A, B, C; got '" + a + "'");
}

sched::RtConfig thread_config(Section& s, const std::string& prefix, sched::RtConfig c) {
  c.priority = static_cast<int>(s.integer(prefix + "_priority", c.priority, 0, 99));
  c.cpu = static_cast<int>(s.integer(prefix + "_cpu", c.cpu, -1, 1023));
  return c;
}

void read_live(Section& top, Profile& p, const std::string& name) {
  hal::LiveConfig& L = p.live;
  if (const toml::table* lt = top.table("live")) {
    Section s(*lt, "live", name);
    L.period_ms = s.number("period_ms", 1.0, 0.05, 1000.0, "ms");
    L.tool = static_cast<int>(s.integer("tool", 1, 0, 9999));
    L.ring_capacity = static_cast<std::size_t>(s.integer("ring_capacity", 4096, 16, 1 << 22));
    L.geometry_idle_us = static_cast<int>(s.integer("geometry_idle_us", 1000, 10, 100000));
    L.geometry_duty = s.number("geometry_duty", 0.7, 0.1, 1.0, "fraction");
    L.jump_tolerance = s.number("jump_tolerance", 1.5, 1.0, 100.0, "factor");
    L.merge_tolerance_mm = s.number("merge_tolerance_mm", 0.001, 0.0, 1.0, "mm");
    if (const toml::table* st = s.table("serial")) {
      Section ss(*st, "live.serial", name);
      L.serial.baud = static_cast<int>(ss.integer("baud", 115200, 1200, 4000000));
      ss.reject_unknown();
    }
    if (const toml::table* ct = s.table("can")) {
      Section cs(*ct, "live.can", name);
      L.can.sync_id = static_cast<std::uint32_t>(cs.integer("sync_id", 0x080, 0, 0x7FF));
      L.can.tpdo_base = static_cast<std::uint32_t>(cs.integer("tpdo_base", 0x180, 0, 0x7FF - 127));
      L.can.sync_counter_max = static_cast<int>(cs.integer("sync_counter_max", 240, 2, 255));
      L.can.late_ms = cs.number("late_ms", 0.0, 0.0, 1000.0, "ms");
      L.can.reconnect_ms = cs.number("reconnect_ms", 500.0, 1.0, 60000.0, "ms");
      cs.reject_unknown();
    }
    if (const toml::node* an = s.get("axis")) {
      const toml::array* arr = an->as_array();
      if (arr == nullptr) s.fail(an, "axis", "expected an array of tables [[live.axis]]");
      for (const toml::node& e : *arr) {
        if (!e.is_table()) s.fail(&e, "axis", "expected [[live.axis]] tables");
        const toml::table& t = *e.as_table();
        Section as(t, "live.axis", name);
        hal::AxisMap m;
        m.axis = axis_index(as, t);
        m.name = as.string("name", std::string(1, "XYZABC"[m.axis]));
        m.channel = static_cast<int>(as.integer("channel", 0, 0, hal::kMaxChannels - 1));
        m.node = static_cast<int>(as.integer("node", m.axis + 1, 1, 127));
        m.index = static_cast<int>(as.integer("index", m.axis, 0, 15));
        m.scale = as.number("scale", 0.001, -1e6, 1e6, "mm or deg per count");
        if (m.scale == 0.0) as.fail(t.get("scale"), "scale", "must not be 0");
        m.offset = as.number("offset", 0.0, -1e9, 1e9, "mm or deg");
        m.min = as.number("min", -1e6, -1e9, 1e9, "mm or deg");
        m.max = as.number("max", 1e6, -1e9, 1e9, "mm or deg");
        if (!(m.min < m.max)) as.fail(t.get("max"), "max", "must be greater than min");
        m.max_speed_per_s = as.number("max_speed_per_min", 0.0, 0.0, 1e7, "mm/min or deg/min") / 60.0;
        as.reject_unknown();
        for (const hal::AxisMap& o : L.axes) {
          if (o.channel == m.channel && o.axis == m.axis)
            as.fail(t.get("axis"), "axis", "channel " + std::to_string(m.channel) + " axis " + m.name + " is mapped twice");
          if (o.node == m.node) as.fail(t.get("node"), "node", "CAN node " + std::to_string(m.node) + " is mapped twice");
          if (o.index == m.index && o.channel == m.channel)
            as.fail(t.get("index"), "index", "serial index " + std::to_string(m.index) + " is mapped twice");
        }
        L.axes.push_back(m);
      }
    }
    s.reject_unknown();
  }
  if (L.axes.empty()) L.axes = hal::default_axes();
  if (const toml::table* tt = top.table("threads")) {
    Section s(*tt, "threads", name);
    L.hal_thread = thread_config(s, "hal", L.hal_thread);
    L.geometry_thread = thread_config(s, "geometry", L.geometry_thread);
    const bool lock = s.boolean("lock_memory", true);
    L.hal_thread.lock_memory = L.geometry_thread.lock_memory = lock;
    s.reject_unknown();
  }
}

}  // namespace

void apply_regions(Profile& p, const std::string& spec, const std::string& where) {
  if (spec == "auto") {
    p.regions_auto = true;
    return;
  }
  int nx = 0, ny = 0;
  if (!parse_grid(spec, nx, ny))
    throw ProfileError(where + ": expected \"NXxNY\" with 1 <= NX, NY <= 256 (e.g. \"4x4\") or \"auto\", got '" + spec + "'");
  p.regions_auto = false;
  p.solid.regions_x = nx;
  p.solid.regions_y = ny;
}

Profile parse_profile(const std::string& text, const std::string& name) {
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    throw ProfileError(name + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  Profile p;
  p.source = name;
  Section top(root, "", name);

  if (const toml::table* m = top.table("machine")) {
    Section s(*m, "machine", name);
    p.name = s.string("name", "");
    p.machine_kind = s.string("kind", "mill3");
    if (!kin::parse_machine_kind(p.machine_kind.c_str(), p.kin.kind))
      s.fail(m->get("kind"), "kind", "expected \"mill3\", \"mill5\", \"lathe\" or \"lathe-c\", got '" + p.machine_kind + "'");
    const bool mill5 = p.kin.kind == kin::MachineKind::Mill5;
    const bool lathe = p.kin.kind == kin::MachineKind::Lathe || p.kin.kind == kin::MachineKind::LatheC;
    auto only = [&](const char* key, bool allowed, const char* kinds) {
      if (m->get(key) != nullptr && !allowed) s.fail(m->get(key), key, std::string("only for machine kind ") + kinds);
    };
    only("rotary", mill5, "mill5");
    only("rotary_center_mm", mill5, "mill5");
    only("pivot_length_mm", mill5, "mill5");
    only("tcp", mill5, "mill5");
    only("diameter_programming", lathe, "lathe or lathe-c");
    only("turret_angle_deg", lathe, "lathe or lathe-c");
    if (mill5) {
      const std::string rot = s.string("rotary", "table-ac");
      if (!kin::parse_rotary(rot.c_str(), p.kin.rotary))
        s.fail(m->get("rotary"), "rotary", "expected \"table-ac\", \"table-bc\", \"head-ac\" or \"head-bc\", got '" + rot + "'");
      if (m->get("rotary_center_mm") != nullptr) {
        const auto c = s.numbers("rotary_center_mm", 3, "mm");
        p.kin.rotary_center_mm = {c[0], c[1], c[2]};
      }
      p.kin.pivot_length_mm = s.number("pivot_length_mm", 0.0, 0.0, 1e4, "mm");
      p.kin.tcp = s.boolean("tcp", false);
    }
    if (lathe) {
      p.diameter_programming = s.boolean("diameter_programming", true);
      p.kin.turret_angle_deg = s.number("turret_angle_deg", 0.0, -360.0, 360.0, "deg");
    }
    p.rapid_mm_per_min = s.number("rapid_mm_per_min", 15000.0, 1.0, 1e6, "mm/min");
    p.tool_change_s = s.number("tool_change_s", 0.0, 0.0, 3600.0, "s");
    auto triple = [&](const char* key, std::array<double, 3>& out, double lo, double hi, const char* unit) {
      if (m->get(key) == nullptr) {
        s.get(key);
        return;
      }
      const auto v = s.numbers(key, 3, unit);
      for (std::size_t i = 0; i < 3; ++i) {
        if (v[i] < lo || v[i] > hi) {
          std::ostringstream msg;
          msg << "expected numbers in [" << lo << ", " << hi << "] " << unit << ", got " << v[i];
          s.fail(m->get(key), key, msg.str());
        }
        out[i] = v[i];
      }
    };
    triple("max_velocity_mm_per_min", p.max_velocity_mm_per_min, 1.0, 1e6, "mm/min");
    triple("max_accel_mm_per_s2", p.max_accel_mm_per_s2, 1.0, 1e6, "mm/s2");
    triple("g54_origin_mm", p.g54_origin_mm, -1e5, 1e5, "mm");
    p.max_feed_mm_per_min = s.number("max_feed_mm_per_min", 0.0, 0.0, 1e6, "mm/min");
    p.sample_period_ms = s.number("sample_period_ms", 4.0, 0.1, 1000.0, "ms");
    s.reject_unknown();
  }

  const toml::table* st = top.table("stock");
  if (st == nullptr) top.fail(nullptr, "stock", "missing table [stock]");
  {
    Section s(*st, "stock", name);
    const std::string shape = s.string("shape", "");
    if (shape == "box") {
      p.solid.shape = geom::SolidSpec::Shape::Box;
      const auto lo = s.numbers("min_mm", 3, "mm");
      const auto hi = s.numbers("max_mm", 3, "mm");
      p.solid.box = geom::BoxStock{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
      if (!(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2]))
        s.fail(st->get("max_mm"), "max_mm", "must be greater than min_mm on every axis");
    } else if (shape == "cylinder") {
      p.solid.shape = geom::SolidSpec::Shape::Cylinder;
      const auto c = s.numbers("center_mm", 2, "mm");
      geom::CylinderStock& cy = p.solid.cylinder;
      cy.center_x_mm = c[0];
      cy.center_y_mm = c[1];
      cy.diameter_mm = s.required_number("diameter_mm", 0.001, 1e5, "mm");
      cy.z_min_mm = s.required_number("z_min_mm", -1e5, 1e5, "mm");
      cy.z_max_mm = s.required_number("z_max_mm", -1e5, 1e5, "mm");
      if (!(cy.z_min_mm < cy.z_max_mm)) s.fail(st->get("z_max_mm"), "z_max_mm", "must be greater than z_min_mm");
    } else {
      s.fail(st->get("shape"), "shape", "expected \"box\" or \"cylinder\", got '" + shape + "'");
    }
    s.reject_unknown();
  }

  if (const toml::table* l = top.table("lbr")) {
    Section s(*l, "lbr", name);
    p.solid.level_spacing_mm = s.number("level_spacing_mm", 0.1, 0.001, 1000.0, "mm");
    p.solid.chord_tol_mm = s.number("chord_tolerance_mm", 0.001, 0.0001, 1.0, "mm");
    p.batch_moves = static_cast<int>(s.integer("batch_moves", 512, 1, 100000));
    p.threads = static_cast<int>(s.integer("threads", 0, 0, 256));
    if (const toml::node* ss = s.get("strictly_simple")) {
      const auto v = ss->value_exact<bool>();
      if (!v) s.fail(ss, "strictly_simple", "expected true or false");
      p.solid.strictly_simple = *v;
    }
    if (const toml::node* vc = s.get("vertical_coherence")) {
      const auto v = vc->value_exact<bool>();
      if (!v) s.fail(vc, "vertical_coherence", "expected true or false");
      p.solid.vertical_coherence = *v;
    }
    if (const toml::node* r = s.get("regions")) {
      const auto v = r->value_exact<std::string>();
      if (!v) s.fail(r, "regions", "expected a string \"NXxNY\" or \"auto\"");
      apply_regions(p, *v, name + ":" + std::to_string(r->source().begin.line) + ": lbr.regions");
    }
    s.reject_unknown();
  }

  if (const toml::node* tn = top.get("tool")) {
    const toml::array* arr = tn->as_array();
    if (arr == nullptr) top.fail(tn, "tool", "expected an array of tables [[tool]]");
    for (const toml::node& e : *arr) {
      if (!e.is_table()) top.fail(&e, "tool", "expected [[tool]] tables");
      Section s(*e.as_table(), "tool", name);
      const toml::node* kn = e.as_table()->get("kind");
      const std::string kind = kn != nullptr && kn->is_string() ? *kn->value<std::string>() : "";
      const bool lathe = p.kin.kind == kin::MachineKind::Lathe || p.kin.kind == kin::MachineKind::LatheC;
      int number = 0;
      if (is_turning_kind(kind)) {
        number = static_cast<int>(s.integer("number", -1, 1, 9999));
        if (number < 0) s.fail(nullptr, "number", "missing (every [[tool]] needs a number in [1, 9999])");
        s.string("kind", "");
        if (!lathe) s.fail(kn, "kind", "'" + kind + "' tools need machine kind lathe or lathe-c, this is " + p.machine_kind);
        geom::TurningTool t = read_turning_tool(s, kind);
        if (p.tools.count(number) || p.inserts.count(number))
          s.fail(e.as_table()->get("number"), "number", "tool " + std::to_string(number) + " is defined twice");
        p.inserts[number] = t;
        continue;
      }
      kin::Mount mount = kin::Mount::Spindle;
      geom::Tool t = read_tool(s, number, mount);
      if (p.tools.count(number) || p.inserts.count(number))
        s.fail(e.as_table()->get("number"), "number", "tool " + std::to_string(number) + " is defined twice");
      if (p.kin.kind == kin::MachineKind::Lathe)
        s.fail(kn, "kind", "a lathe has no live tools (use machine kind lathe-c), got a '" + kind + "' tool");
      if (p.kin.kind == kin::MachineKind::LatheC && mount == kin::Mount::Spindle) mount = kin::Mount::Axial;
      if (p.kin.kind != kin::MachineKind::LatheC && mount != kin::Mount::Spindle)
        s.fail(e.as_table()->get("live"), "live", "only for machine kind lathe-c");
      p.tools[number] = t;
      p.live_mounts[number] = mount;
    }
  }

  // Lathe kinds: the workpiece frame's Z is the spindle axis, so the stock is a bar on it.
  if (p.kin.kind == kin::MachineKind::Lathe || p.kin.kind == kin::MachineKind::LatheC) {
    const geom::CylinderStock& cy = p.solid.cylinder;
    if (p.solid.shape != geom::SolidSpec::Shape::Cylinder || cy.center_x_mm != 0.0 || cy.center_y_mm != 0.0)
      top.fail(st, "stock", "machine kind " + p.machine_kind +
                                " needs a cylinder stock on the spindle axis (shape = \"cylinder\", center_mm = [0, 0])");
  }

  if (const toml::node* cn = top.get("channel")) {
    const toml::array* arr = cn->as_array();
    if (arr == nullptr) top.fail(cn, "channel", "expected an array of tables [[channel]]");
    for (const toml::node& e : *arr) {
      if (!e.is_table()) top.fail(&e, "channel", "expected [[channel]] tables");
      Section s(*e.as_table(), "channel", name);
      Channel c;
      c.kin = p.kin;
      c.g54_origin_mm = p.g54_origin_mm;
      c.name = s.string("name", "ch" + std::to_string(p.channels.size() + 1));
      c.program = s.string("program", "");
      if (e.as_table()->get("g54_origin_mm") != nullptr) {
        const auto v = s.numbers("g54_origin_mm", 3, "mm");
        c.g54_origin_mm = {v[0], v[1], v[2]};
      }
      const bool lathe = p.kin.kind == kin::MachineKind::Lathe || p.kin.kind == kin::MachineKind::LatheC;
      if (e.as_table()->get("turret_angle_deg") != nullptr && !lathe)
        s.fail(e.as_table()->get("turret_angle_deg"), "turret_angle_deg", "only for machine kind lathe or lathe-c");
      c.kin.turret_angle_deg = s.number("turret_angle_deg", p.kin.turret_angle_deg, -360.0, 360.0, "deg");
      for (const Channel& o : p.channels)
        if (o.name == c.name) s.fail(e.as_table()->get("name"), "name", "channel '" + c.name + "' is defined twice");
      s.reject_unknown();
      p.channels.push_back(std::move(c));
    }
  }
  if (const toml::table* nt = top.table("nc")) {  // G-code front ends
    Section s(*nt, "nc", name);
    p.start_tool = static_cast<int>(s.integer("start_tool", 0, 0, 99999));
    if (const toml::node* n = s.get("subroutine_path")) {
      const toml::array* a = n->as_array();
      if (a == nullptr) s.fail(n, "subroutine_path", "expected an array of folder names");
      const std::filesystem::path base = std::filesystem::path(name).parent_path();
      for (const toml::node& e : *a) {
        const auto v = e.value_exact<std::string>();
        if (!v) s.fail(&e, "subroutine_path", "expected folder names (strings)");
        const std::filesystem::path d(*v);
        p.subroutine_path.push_back(d.is_relative() && !base.empty() ? (base / d).string() : d.string());
      }
    }
    s.reject_unknown();
  }
  read_live(top, p, name);
  if (const toml::table* rt = top.table("render")) {
    Section s(*rt, "render", name);
    p.render_rate_hz = s.number("rate_hz", 30.0, 1.0, 240.0, "Hz");
    p.render_ui_scale = s.number("ui_scale", 1.5, 0.5, 4.0, "factor");
    s.reject_unknown();
  }
  top.reject_unknown();
  return p;
}

Profile load_profile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ProfileError(path + ":0: cannot open profile");
  std::ostringstream ss;
  ss << f.rdbuf();
  return parse_profile(ss.str(), path);
}

const char* default_profile_text() noexcept { return kDefaultProfileToml; }

Profile default_profile() { return parse_profile(kDefaultProfileToml, "<built-in default-mill3>"); }

motion::ToolsConfig tool_config(const Profile& p) { return {p.tools, p.inserts, p.live_mounts}; }

kin::Mount Profile::mount_of(int tool) const {
  if (inserts.count(tool)) return kin::Mount::Turning;
  const auto it = live_mounts.find(tool);
  return it != live_mounts.end() ? it->second : kin::Mount::Spindle;
}

nc::GcodeOptions gcode_options(const Profile& p, const Channel& c) {
  nc::GcodeOptions o = gcode_options(p);
  for (int a = 0; a < 3; ++a) o.work_offsets[0][a] = c.g54_origin_mm[static_cast<std::size_t>(a)];
  return o;
}

nc::GcodeOptions gcode_options(const Profile& p) {
  nc::GcodeOptions o;
  switch (p.kin.kind) {
    case kin::MachineKind::Mill3: o.machine = nc::MachineKind::Mill3; break;
    case kin::MachineKind::Mill5: o.machine = nc::MachineKind::MillRotary; break;
    case kin::MachineKind::Lathe: o.machine = nc::MachineKind::Lathe; break;
    case kin::MachineKind::LatheC: o.machine = nc::MachineKind::LatheC; break;
  }
  const bool lathe = p.kin.kind == kin::MachineKind::Lathe || p.kin.kind == kin::MachineKind::LatheC;
  o.diameter_mode = lathe && p.diameter_programming;
  // On lathes the programmed point is the tool's reference point (the controller applies the
  // X/Z offsets it measured), so no tool length is applied (docs/machine-kinds.md).
  for (const auto& [n, t] : p.tools) {
    o.tool_lengths[n] = lathe ? 0.0 : t.length_mm;
    o.tool_diameters[n] = t.diameter_mm;
  }
  for (const auto& [n, insert] : p.inserts) o.tool_lengths.emplace(n, 0.0);  // rs274's tool table lists them too
  if (p.kin.kind == kin::MachineKind::Mill5) {
    const bool ac = p.kin.rotary == kin::Rotary::TableAC || p.kin.rotary == kin::Rotary::HeadAC;
    o.rotary = {ac, !ac, true};
  }
  o.subroutine_path = p.subroutine_path;
  o.start_tool = p.start_tool;
  o.chord_tol_mm = p.solid.chord_tol_mm;
  for (int a = 0; a < 3; ++a) o.work_offsets[0][a] = p.g54_origin_mm[static_cast<std::size_t>(a)];
  return o;
}

nc::EmulatorLimits emulator_limits(const Profile& p) {
  nc::EmulatorLimits l;
  l.rapid_mm_per_min = p.rapid_mm_per_min;
  l.max_feed_mm_per_min = p.max_feed_mm_per_min;
  for (std::size_t a = 0; a < 3; ++a) {
    l.max_velocity[a] = p.max_velocity_mm_per_min[a] > 0 ? p.max_velocity_mm_per_min[a] : p.rapid_mm_per_min;
    l.max_accel[a] = p.max_accel_mm_per_s2[a];
  }
  l.sample_period_ms = p.sample_period_ms;
  l.tool_change_s = p.tool_change_s;
  return l;
}

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
  p.tools[static_cast<int>(num[0])] = t;
}

}  // namespace lbr::app
