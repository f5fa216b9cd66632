#include "nc/config_toml.hpp"

#include <filesystem>

namespace lbr::nc {

namespace {

// travel_min_mm / travel_max_mm [x, y, z], travel_min_deg / travel_max_deg [a, b, c]: each
// optional, min < max on every axis where both are given.
void read_travel(cfg::Table& s, MachineConfig& m) {
  constexpr double kRange = 1e6;
  const struct {
    const char *min_key, *max_key, *unit;
    int first;
  } groups[] = {{"travel_min_mm", "travel_max_mm", "mm", X}, {"travel_min_deg", "travel_max_deg", "deg", A}};
  for (const auto& g : groups) {
    std::array<double, 3> lo{-MachineConfig::kNoLimit, -MachineConfig::kNoLimit, -MachineConfig::kNoLimit};
    std::array<double, 3> hi{MachineConfig::kNoLimit, MachineConfig::kNoLimit, MachineConfig::kNoLimit};
    s.triple(g.min_key, lo, -kRange, kRange, g.unit);
    s.triple(g.max_key, hi, -kRange, kRange, g.unit);
    for (int k = 0; k < 3; ++k) {
      if (!(lo[k] < hi[k]))
        s.fail(s.peek(g.max_key), g.max_key, "expected every maximum above its minimum (" + std::string(g.min_key) + ")");
      m.travel_min[g.first + k] = lo[k];
      m.travel_max[g.first + k] = hi[k];
    }
  }
}

}  // namespace

void read_machine(cfg::Table& s, MachineKind kind, MachineConfig& m) {
  s.only_for("diameter_programming", is_lathe(kind), "lathe or lathe-c");
  if (is_lathe(kind)) m.diameter_programming = s.boolean("diameter_programming", true);
  m.rapid_mm_per_min = s.number("rapid_mm_per_min", 15000.0, 1.0, 1e6, "mm/min");
  m.tool_change_s = s.number("tool_change_s", 0.0, 0.0, 3600.0, "s");
  s.triple("max_velocity_mm_per_min", m.max_velocity_mm_per_min, 1.0, 1e6, "mm/min");
  s.triple("max_accel_mm_per_s2", m.max_accel_mm_per_s2, 1.0, 1e6, "mm/s2");
  s.triple("g54_origin_mm", m.g54_origin_mm, -1e5, 1e5, "mm");
  m.max_feed_mm_per_min = s.number("max_feed_mm_per_min", 0.0, 0.0, 1e6, "mm/min");
  m.sample_period_ms = s.number("sample_period_ms", 4.0, 0.1, 1000.0, "ms");
  read_travel(s, m);
}

void read_nc(cfg::Table& s, FrontEndConfig& f) {
  f.start_tool = static_cast<int>(s.integer("start_tool", 0, 0, 99999));
  const std::string dialect = s.string("dialect", "rs274ngc");
  if (!parse_dialect(dialect, f.dialect))
    s.fail(s.raw().get("dialect"), "dialect", "expected rs274ngc or fanuc; got '" + dialect + "'");
  if (const toml::node* n = s.get("subroutine_path")) {
    const toml::array* a = n->as_array();
    if (a == nullptr) s.fail(n, "subroutine_path", "expected an array of folder names");
    const std::filesystem::path base = std::filesystem::path(s.file()).parent_path();
    for (const toml::node& e : *a) {
      const auto v = e.value_exact<std::string>();
      if (!v) s.fail(&e, "subroutine_path", "expected folder names (strings)");
      const std::filesystem::path d(*v);
      f.subroutine_path.push_back(d.is_relative() && !base.empty() ? (base / d).string() : d.string());
    }
  }
  // New [nc] keys (dialect, lathe_diameter_mode, ...) are read here, into FrontEndConfig.
}

}  // namespace lbr::nc
