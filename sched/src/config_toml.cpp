#include "sched/config_toml.hpp"

namespace lbr::sched {

void read_thread(cfg::Table& s, const std::string& prefix, RtConfig& c) {
  c.priority = static_cast<int>(s.integer(prefix + "_priority", c.priority, 0, 99));
  c.cpu = static_cast<int>(s.integer(prefix + "_cpu", c.cpu, -1, 1023));
}

}  // namespace lbr::sched
