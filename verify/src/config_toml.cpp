#include "verify/config_toml.hpp"

namespace lbr::verify {

void read_checks(cfg::Table& checks, CheckConfig& out) {
  out.enabled = checks.boolean("enabled", out.enabled);
  out.tolerance_mm = checks.number("tolerance_mm", out.tolerance_mm, 0.0, 10.0, "mm");
}

}  // namespace lbr::verify
