// motion/config_toml.hpp — a profile's [[tool]] tables (docs/profiles.md) into the tool
// definitions (ToolsConfig): milling cutters and lathe inserts in one numbering, with their
// mount on the machine. Setup code: throws cfg::ConfigError("file:line: tool.key: ...").
#pragma once

#include "cfg/table.hpp"
#include "motion/tool_table.hpp"
#include "nc/machine_kind.hpp"

namespace lbr::motion {

// Adds one [[tool]] table to `tools`: kind turning, boring or grooving is an insert (lathe
// kinds only), the other kinds a milling tool (a live tool on lathe-c, axial unless
// live = "radial"). A number defined twice fails. New [[tool]] keys are read in
// motion/src/config_toml.cpp. The caller rejects unknown keys afterwards.
void read_tool(cfg::Table& tool, nc::MachineKind kind, ToolsConfig& tools);

}  // namespace lbr::motion
