#include "nc/machine_kind.hpp"

#include <cstring>
#include <initializer_list>

namespace lbr::nc {

const char* to_string(MachineKind k) noexcept {
  switch (k) {
    case MachineKind::Mill3: return "mill3";
    case MachineKind::Mill5: return "mill5";
    case MachineKind::Lathe: return "lathe";
    case MachineKind::LatheC: return "lathe-c";
  }
  return "?";
}

bool parse_machine_kind(const char* s, MachineKind& out) noexcept {
  for (MachineKind k : {MachineKind::Mill3, MachineKind::Mill5, MachineKind::Lathe, MachineKind::LatheC}) {
    if (std::strcmp(s, to_string(k)) == 0) {
      out = k;
      return true;
    }
  }
  return false;
}

}  // namespace lbr::nc
