// kin/config_toml.hpp — kin's keys of a profile's [machine] table (docs/profiles.md,
// docs/machine-kinds.md): kind, and per kind rotary, rotary_center_mm, pivot_length_mm, tcp
// (mill5) and turret_angle_deg (lathe kinds). nc/ reads the same table's rates and limits
// (nc/config_toml.hpp); the caller (app/) rejects unknown keys after both. Setup code: throws
// cfg::ConfigError("file:line: machine.key: ...").
#pragma once

#include "cfg/table.hpp"
#include "kin/kinematics.hpp"

namespace lbr::kin {

// Reads kind first: keys of another machine kind fail ("only for machine kind ...").
// New kinematics keys of [machine] go here.
void read_machine(cfg::Table& machine, Kinematics& k);

}  // namespace lbr::kin
