// geom/config_toml.hpp — the kernel's profile tables (docs/profiles.md): [stock] and the
// kernel keys of [lbr] (level spacing Δ, chord tolerance, region grid, Clipper options) into a
// SolidSpec. Setup code: throws cfg::ConfigError("file:line: table.key: ..."). The caller
// (app/) opens the tables and calls reject_unknown() after every reader of a table has run.
#pragma once

#include <string>

#include "cfg/table.hpp"
#include "geom/lbr_solid.hpp"

namespace lbr::geom {

// [stock]: shape = "box" (min_mm, max_mm) or "cylinder" (center_mm, diameter_mm, z_min_mm, z_max_mm).
void read_stock(cfg::Table& stock, SolidSpec& solid);

// [lbr]: level_spacing_mm, chord_tolerance_mm, strictly_simple, vertical_coherence, regions.
// `regions_auto` becomes true for regions = "auto" (the caller picks the grid from its tools).
// New kernel keys of [lbr] go here.
void read_lbr(cfg::Table& lbr, SolidSpec& solid, bool& regions_auto);

// A region grid "NXxNY" (1 <= NX, NY <= 256) or "auto", as [lbr] regions and `--regions` take
// it. Returns "" and sets the grid (or regions_auto), else what was expected.
[[nodiscard]] std::string apply_regions(const std::string& spec, SolidSpec& solid, bool& regions_auto);

}  // namespace lbr::geom
