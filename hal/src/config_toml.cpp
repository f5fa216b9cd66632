#include "hal/config_toml.hpp"

#include "hal/sample.hpp"  // kMaxChannels
#include "sched/config_toml.hpp"

namespace lbr::hal {

namespace {

void read_live_keys(cfg::Table& s, LiveConfig& c) {
  c.period_ms = s.number("period_ms", 1.0, 0.05, 1000.0, "ms");
  c.tool = static_cast<int>(s.integer("tool", 1, 0, 9999));
  c.ring_capacity = static_cast<std::size_t>(s.integer("ring_capacity", 4096, 16, 1 << 22));
  c.geometry_idle_us = static_cast<int>(s.integer("geometry_idle_us", 1000, 10, 100000));
  c.geometry_duty = s.number("geometry_duty", 0.7, 0.1, 1.0, "fraction");
  c.jump_tolerance = s.number("jump_tolerance", 1.5, 1.0, 100.0, "factor");
  c.merge_tolerance_mm = s.number("merge_tolerance_mm", 0.001, 0.0, 1.0, "mm");
  c.snapshot_s = s.number("snapshot_s", 5.0, 0.0, 86400.0, "s");  // app/snapshot.hpp
}

void read_serial(cfg::Table& s, SerialConfig& c) {
  c.baud = static_cast<int>(s.integer("baud", 115200, 1200, 4000000));
  c.reconnect_ms = s.number("reconnect_ms", 0.0, 0.0, 60000.0, "ms");
}

void read_can(cfg::Table& s, CanConfig& c) {
  c.sync_id = static_cast<std::uint32_t>(s.integer("sync_id", 0x080, 0, 0x7FF));
  c.tpdo_base = static_cast<std::uint32_t>(s.integer("tpdo_base", 0x180, 0, 0x7FF - 127));
  c.sync_counter_max = static_cast<int>(s.integer("sync_counter_max", 240, 2, 255));
  c.late_ms = s.number("late_ms", 0.0, 0.0, 1000.0, "ms");
  c.reconnect_ms = s.number("reconnect_ms", 500.0, 1.0, 60000.0, "ms");
  c.bitrate = static_cast<int>(s.integer("bitrate", 500000, 10000, 1000000));  // lbrsim-can@.service
}

// Reads the sub-table [parent.key] with `read` and rejects its unknown keys.
template <class Config, class Read>
void read_sub_table(cfg::Table& parent, const char* key, Config& c, Read read) {
  if (const toml::table* t = parent.table(key)) {
    cfg::Table s(*t, parent.qualified(key), parent.file());
    read(s, c);
    s.reject_unknown();
  }
}

int axis_index(cfg::Table& s) {
  const std::string a = s.string("axis", "");
  static const char* kNames[] = {"X", "Y", "Z", "A", "B", "C"};
  for (int i = 0; i < 6; ++i)
    if (a == kNames[i]) return i;
  s.fail(s.peek("axis"), "axis", "expected one of X, Y, Z, A, B, C; got '" + a + "'");
}

AxisMap read_axis(cfg::Table& as) {
  AxisMap m;
  m.axis = axis_index(as);
  m.name = as.string("name", std::string(1, "XYZABC"[m.axis]));
  m.channel = static_cast<int>(as.integer("channel", 0, 0, kMaxChannels - 1));
  m.node = static_cast<int>(as.integer("node", m.axis + 1, 1, 127));
  m.index = static_cast<int>(as.integer("index", m.axis, 0, 15));
  m.scale = as.number("scale", 0.001, -1e6, 1e6, "mm or deg per count");
  if (m.scale == 0.0) as.fail(as.peek("scale"), "scale", "must not be 0");
  m.offset = as.number("offset", 0.0, -1e9, 1e9, "mm or deg");
  m.min = as.number("min", -1e6, -1e9, 1e9, "mm or deg");
  m.max = as.number("max", 1e6, -1e9, 1e9, "mm or deg");
  if (!(m.min < m.max)) as.fail(as.peek("max"), "max", "must be greater than min");
  m.max_speed_per_s = as.number("max_speed_per_min", 0.0, 0.0, 1e7, "mm/min or deg/min") / 60.0;
  as.reject_unknown();
  return m;
}

void check_unique(const cfg::Table& as, const AxisMap& m, const std::vector<AxisMap>& axes) {
  for (const AxisMap& o : axes) {
    if (o.channel == m.channel && o.axis == m.axis)
      as.fail(as.peek("axis"), "axis", "channel " + std::to_string(m.channel) + " axis " + m.name + " is mapped twice");
    if (o.node == m.node) as.fail(as.peek("node"), "node", "CAN node " + std::to_string(m.node) + " is mapped twice");
    if (o.index == m.index && o.channel == m.channel)
      as.fail(as.peek("index"), "index", "serial index " + std::to_string(m.index) + " is mapped twice");
  }
}

}  // namespace

void read_live(cfg::Table& s, LiveConfig& c) {
  read_live_keys(s, c);
  read_sub_table(s, "serial", c.serial, read_serial);
  read_sub_table(s, "can", c.can, read_can);
  for (const toml::table* t : s.tables("axis")) {
    cfg::Table as(*t, s.qualified("axis"), s.file());
    const AxisMap m = read_axis(as);
    check_unique(as, m, c.axes);
    c.axes.push_back(m);
  }
}

void read_threads(cfg::Table& s, LiveConfig& c) {
  sched::read_thread(s, "hal", c.hal_thread);
  sched::read_thread(s, "geometry", c.geometry_thread);
  const bool lock = s.boolean("lock_memory", true);
  c.hal_thread.lock_memory = c.geometry_thread.lock_memory = lock;
}

}  // namespace lbr::hal
