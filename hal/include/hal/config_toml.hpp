// hal/config_toml.hpp — the live pipeline's profile tables (docs/profiles.md) into a
// LiveConfig (hal/config.hpp): [live] with [live.serial], [live.can] and [[live.axis]], and
// [threads] (through sched/config_toml.hpp). Setup code: throws
// cfg::ConfigError("file:line: live.key: ..."). The caller opens [live] and [threads] and
// rejects their unknown keys; the sub-tables are checked here.
#pragma once

#include "cfg/table.hpp"
#include "hal/config.hpp"

namespace lbr::hal {

// [live]. New [live] keys (e.g. snapshot_s) are a LiveConfig field read in read_live_keys()
// (hal/src/config_toml.cpp). Leaves `axes` empty when the table maps none.
void read_live(cfg::Table& live, LiveConfig& c);

// [threads]: hal_priority, hal_cpu, geometry_priority, geometry_cpu, lock_memory.
void read_threads(cfg::Table& threads, LiveConfig& c);

}  // namespace lbr::hal
