// kin/kinematics.hpp — machine kinematics: axis samples → tool poses in the workpiece frame.
//
// One function per concern, shared by `lbrsim batch` and the live pipeline:
//  - tool_pose(): one channel's axis sample (X Y Z [mm], A B C [deg], as nc::Segment::end
//    and nc::Sample::axes hold them) and the mounted tool → tip + unit axis in the workpiece
//    frame, where the LBR levels are planes z = const;
//  - substeps(): how many pieces a move from one sample to the next must be cut into so that
//    the curved path the rotary axes give (in the workpiece frame) stays within the chord
//    tolerance of the chords between the pieces.
// Conventions (docs/machine-kinds.md): rotations are right-handed about the machine axes
// (A about +X, B about +Y, C about +Z); a rotary table turns the workpiece by +angle, a
// rotary head turns the tool by +angle. On lathes the workpiece Z is the spindle axis and
// the workpiece turns with the spindle by C.
// Everything here is real-time safe: no allocation, no exceptions, no locks.
#pragma once

#include "geom/types.hpp"
#include "nc/machine_kind.hpp"  // nc::MachineKind, the one machine-kind type
#include "nc/toolpath.hpp"

namespace lbr::kin {

// Rotary axis arrangement of a mill5 (the first letter is the tilt axis, C the rotary one).
enum class Rotary : unsigned char {
  TableAC,  // trunnion table: A tilts about X and carries the C table
  TableBC,  // B tilts about Y and carries the C table
  HeadAC,   // fork head: C turns about Z and carries the A (about X) tilt
  HeadBC,   // C carries the B (about Y) tilt
};
[[nodiscard]] const char* to_string(Rotary r) noexcept;  // "table-ac", "table-bc", "head-ac", "head-bc"
[[nodiscard]] bool parse_rotary(const char* s, Rotary& out) noexcept;

// How a tool sits in a lathe channel.
enum class Mount : unsigned char {
  Spindle,  // mill spindle (mill3, mill5)
  Turning,  // turning insert: the part rotates, the sweep is revolved (geom::LatheSweep)
  Axial,    // live tool along the spindle axis, pointing at the face (axis +Z)
  Radial,   // live tool along the channel's X, pointing at the axis (axis +X)
};

struct Kinematics {
  nc::MachineKind kind = nc::MachineKind::Mill3;
  // mill5
  Rotary rotary = Rotary::TableAC;
  // Table: a point on both rotary axes (where they meet), in the program (G54) frame at
  // zero rotation [mm]. The workpiece frame is the program frame carried by the table.
  geom::Vec3 rotary_center_mm{};
  // Head: distance from the spindle gauge line up to the head's pivot (the point on the
  // rotary axes) [mm].
  double pivot_length_mm = 0.0;
  // True: programmed X Y Z are the tool tip in the workpiece frame (TCP / RTCP, G43.4);
  // false: they are the machine axes (tip at zero rotation, tool length along Z).
  bool tcp = false;
  // lathe, lathe-c: direction of the channel's +X about the spindle axis [deg] (0: +X of the
  // workpiece frame; 180: a lower turret facing the upper one).
  double turret_angle_deg = 0.0;
};

// Tool pose in the workpiece frame for axis sample q. `tool_length_mm` is the gauge length
// the front end applied along Z (mill5 heads without TCP need it to find the pivot).
// Turning mounts return tip (X, Y, Z) with axis +Z: the sweep is revolved, C plays no role.
[[nodiscard]] geom::Pose tool_pose(const Kinematics& k, const nc::AxisVector& q, Mount mount,
                                   double tool_length_mm = 0.0) noexcept;

// Pieces a move q0 → q1 needs so that every tool point within `reach_mm` of the tip stays
// within `tol_mm` of the chords between consecutive poses (1 when no rotary axis that moves
// the tip changes). At most kMaxMoveSubsteps.
inline constexpr int kMaxMoveSubsteps = 4096;
[[nodiscard]] int substeps(const Kinematics& k, const nc::AxisVector& q0, const nc::AxisVector& q1, Mount mount,
                           double tool_length_mm, double reach_mm, double tol_mm) noexcept;

}  // namespace lbr::kin
