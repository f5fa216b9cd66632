#include "geom/config_toml.hpp"

namespace lbr::geom {

namespace {

bool parse_grid(const std::string& spec, int& nx, int& ny) {
  const auto x = spec.find('x');
  if (x == std::string::npos) return false;
  try {
    std::size_t a = 0, b = 0;
    nx = std::stoi(spec.substr(0, x), &a);
    ny = std::stoi(spec.substr(x + 1), &b);
    return a == x && b == spec.size() - x - 1 && nx >= 1 && ny >= 1 && nx <= 256 && ny <= 256;
  } catch (const std::exception&) {
    return false;
  }
}

void read_box(cfg::Table& s, SolidSpec& solid) {
  solid.shape = SolidSpec::Shape::Box;
  const auto lo = s.numbers("min_mm", 3, "mm");
  const auto hi = s.numbers("max_mm", 3, "mm");
  solid.box = BoxStock{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
  if (!(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2])) s.fail(s.peek("max_mm"), "max_mm", "must be greater than min_mm on every axis");
}

void read_cylinder(cfg::Table& s, SolidSpec& solid) {
  solid.shape = SolidSpec::Shape::Cylinder;
  const auto c = s.numbers("center_mm", 2, "mm");
  CylinderStock& cy = solid.cylinder;
  cy.center_x_mm = c[0];
  cy.center_y_mm = c[1];
  cy.diameter_mm = s.required_number("diameter_mm", 0.001, 1e5, "mm");
  cy.z_min_mm = s.required_number("z_min_mm", -1e5, 1e5, "mm");
  cy.z_max_mm = s.required_number("z_max_mm", -1e5, 1e5, "mm");
  if (!(cy.z_min_mm < cy.z_max_mm)) s.fail(s.peek("z_max_mm"), "z_max_mm", "must be greater than z_min_mm");
}

}  // namespace

void read_stock(cfg::Table& s, SolidSpec& solid) {
  const std::string shape = s.string("shape", "");
  if (shape == "box") read_box(s, solid);
  else if (shape == "cylinder") read_cylinder(s, solid);
  else s.fail(s.peek("shape"), "shape", "expected \"box\" or \"cylinder\", got '" + shape + "'");
}

void read_lbr(cfg::Table& s, SolidSpec& solid, bool& regions_auto) {
  solid.level_spacing_mm = s.number("level_spacing_mm", 0.1, 0.001, 1000.0, "mm");
  solid.chord_tol_mm = s.number("chord_tolerance_mm", 0.001, 0.0001, 1.0, "mm");
  solid.strictly_simple = s.boolean("strictly_simple", solid.strictly_simple);
  solid.vertical_coherence = s.boolean("vertical_coherence", solid.vertical_coherence);
  if (const toml::node* r = s.get("regions")) {
    const auto v = r->value_exact<std::string>();
    if (!v) s.fail(r, "regions", "expected a string \"NXxNY\" or \"auto\"");
    if (const std::string e = apply_regions(*v, solid, regions_auto); !e.empty()) s.fail(r, "regions", e);
  }
}

std::string apply_regions(const std::string& spec, SolidSpec& solid, bool& regions_auto) {
  if (spec == "auto") {
    regions_auto = true;
    return "";
  }
  int nx = 0, ny = 0;
  if (!parse_grid(spec, nx, ny)) return "expected \"NXxNY\" with 1 <= NX, NY <= 256 (e.g. \"4x4\") or \"auto\", got '" + spec + "'";
  regions_auto = false;
  solid.regions_x = nx;
  solid.regions_y = ny;
  return "";
}

}  // namespace lbr::geom
