// nc/machine_kind.hpp — the kind of machine a profile describes ([machine] kind,
// docs/machine-kinds.md). The one machine-kind type of the project: the G-code front ends
// use it for the axis words a program may use, kin/ for the pose formulae, motion/ and app/
// for the tool table and the profile checks. It lives in nc/, the lowest module that needs it.
// Real-time safe: no allocation, no exceptions.
#pragma once

namespace lbr::nc {

enum class MachineKind : unsigned char {
  Mill3,   // X Y Z, tool axis +Z
  Mill5,   // X Y Z and two rotary axes (table-table or head-head); a program may use the rotary
           // axes of GcodeOptions::rotary ([deg], carried into Segment::end[A..C])
  Lathe,   // X Z (+Y), turning tools only, C not used; G7 diameter mode / G8 radius mode apply to X words
  LatheC,  // X Y Z C: a lathe with C spindle positioning [deg] and live (milling/drilling) tools; G7 / G8 as Lathe
};

[[nodiscard]] const char* to_string(MachineKind k) noexcept;  // "mill3", "mill5", "lathe", "lathe-c"
[[nodiscard]] bool parse_machine_kind(const char* s, MachineKind& out) noexcept;
[[nodiscard]] constexpr bool is_lathe(MachineKind k) noexcept { return k == MachineKind::Lathe || k == MachineKind::LatheC; }

}  // namespace lbr::nc
