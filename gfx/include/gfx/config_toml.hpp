// gfx/config_toml.hpp — the render thread's profile table [render] (docs/profiles.md) into a
// RenderThreadConfig. Setup code: throws cfg::ConfigError("file:line: render.key: ...").
#pragma once

#include "cfg/table.hpp"
#include "gfx/render_thread.hpp"

namespace lbr::gfx {

// [render]: rate_hz. New [render] keys are read here (gfx/src/config_toml.cpp).
void read_render(cfg::Table& render, RenderThreadConfig& c);

}  // namespace lbr::gfx
