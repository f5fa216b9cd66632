// sched/config_toml.hpp — a real-time thread's profile keys (docs/profiles.md, [threads]):
// PREFIX_priority and PREFIX_cpu into an RtConfig. Setup code: throws cfg::ConfigError.
#pragma once

#include <string>

#include "cfg/table.hpp"
#include "sched/rt_thread.hpp"

namespace lbr::sched {

// Reads `prefix`_priority (0..99) and `prefix`_cpu (-1..1023); absent keys keep c's values.
void read_thread(cfg::Table& threads, const std::string& prefix, RtConfig& c);

}  // namespace lbr::sched
