// nc/config_toml.hpp — reading nc's profile keys (nc/config.hpp; docs/profiles.md). Setup
// code: throws cfg::ConfigError("file:line: table.key: ..."). The caller (app/) opens the
// tables and rejects unknown keys after every reader of a table has run ([machine] is shared
// with kin/, which reads the machine kind).
#pragma once

#include "cfg/table.hpp"
#include "nc/config.hpp"
#include "nc/machine_kind.hpp"

namespace lbr::nc {

// [machine]: rapid_mm_per_min, tool_change_s, max_velocity_mm_per_min, max_accel_mm_per_s2,
// g54_origin_mm, max_feed_mm_per_min, sample_period_ms, travel_min_mm / travel_max_mm /
// travel_min_deg / travel_max_deg, and diameter_programming (lathe kinds).
void read_machine(cfg::Table& machine, MachineKind kind, MachineConfig& m);

// [nc]: start_tool, subroutine_path (folders relative to the profile's folder, `file`'s parent).
void read_nc(cfg::Table& nc, FrontEndConfig& f);

}  // namespace lbr::nc
