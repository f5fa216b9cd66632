#include "kin/config_toml.hpp"

#include <string>

namespace lbr::kin {

namespace {

void read_mill5(cfg::Table& s, Kinematics& k) {
  const std::string rot = s.string("rotary", "table-ac");
  if (!parse_rotary(rot.c_str(), k.rotary))
    s.fail(s.peek("rotary"), "rotary", "expected \"table-ac\", \"table-bc\", \"head-ac\" or \"head-bc\", got '" + rot + "'");
  if (s.peek("rotary_center_mm") != nullptr) {
    const auto c = s.numbers("rotary_center_mm", 3, "mm");
    k.rotary_center_mm = {c[0], c[1], c[2]};
  }
  k.pivot_length_mm = s.number("pivot_length_mm", 0.0, 0.0, 1e4, "mm");
  k.tcp = s.boolean("tcp", false);
}

}  // namespace

void read_machine(cfg::Table& s, Kinematics& k) {
  const std::string kind = s.string("kind", "mill3");
  if (!nc::parse_machine_kind(kind.c_str(), k.kind))
    s.fail(s.peek("kind"), "kind", "expected \"mill3\", \"mill5\", \"lathe\" or \"lathe-c\", got '" + kind + "'");
  const bool mill5 = k.kind == nc::MachineKind::Mill5;
  const bool lathe = nc::is_lathe(k.kind);
  for (const char* key : {"rotary", "rotary_center_mm", "pivot_length_mm", "tcp"}) s.only_for(key, mill5, "mill5");
  s.only_for("turret_angle_deg", lathe, "lathe or lathe-c");
  if (mill5) read_mill5(s, k);
  if (lathe) k.turret_angle_deg = s.number("turret_angle_deg", 0.0, -360.0, 360.0, "deg");
}

}  // namespace lbr::kin
