// verify/config_toml.hpp — a profile's [checks] table (docs/profiles.md) into CheckConfig.
// Setup code: throws cfg::ConfigError("file:line: checks.key: ...").
#pragma once

#include "cfg/table.hpp"
#include "verify/collision.hpp"

namespace lbr::verify {

// Reads [checks]: enabled (bool), tolerance_mm, max_cutting_feed_mm_per_min, max_ramp_angle_deg. The caller rejects unknown keys afterwards.
void read_checks(cfg::Table& checks, CheckConfig& out);

}  // namespace lbr::verify
