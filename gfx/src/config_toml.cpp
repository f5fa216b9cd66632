#include "gfx/config_toml.hpp"

namespace lbr::gfx {

void read_render(cfg::Table& s, RenderThreadConfig& c) { c.rate_hz = s.number("rate_hz", 30.0, 1.0, 240.0, "Hz"); }

}  // namespace lbr::gfx
