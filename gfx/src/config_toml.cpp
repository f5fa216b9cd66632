#include "gfx/config_toml.hpp"

namespace lbr::gfx {

void read_render(cfg::Table& s, RenderThreadConfig& c) {
  c.rate_hz = s.number("rate_hz", 30.0, 1.0, 240.0, "Hz");
  c.ui.scale = static_cast<float>(s.number("ui_scale", 1.5, 0.5, 4.0, "factor"));  // operator UI size (docs/ui.md)
}

}  // namespace lbr::gfx
