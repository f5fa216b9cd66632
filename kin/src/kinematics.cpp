// Machine kinematics per kind (conventions in docs/machine-kinds.md).
//
// Zero rotations must reproduce the 3-axis result bit for bit (the test
// `Kinematics.Mill5WithZeroTiltEqualsMill3` relies on it), so positions are corrected by
// differences, p + (R·v − v), which vanish exactly when R is the identity, instead of being
// recomputed as c + R·(p − c).
#include "kin/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace lbr::kin {

namespace {

using geom::Vec3;
using nc::MachineKind;
constexpr double kDeg = std::numbers::pi / 180.0;

Vec3 rot_x(Vec3 v, double deg) noexcept {
  if (deg == 0.0) return v;
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  return {v.x, c * v.y - s * v.z, s * v.y + c * v.z};
}
Vec3 rot_y(Vec3 v, double deg) noexcept {
  if (deg == 0.0) return v;
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  return {c * v.x + s * v.z, v.y, -s * v.x + c * v.z};
}
Vec3 rot_z(Vec3 v, double deg) noexcept {
  if (deg == 0.0) return v;
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

bool tilt_is_a(Rotary r) noexcept { return r == Rotary::TableAC || r == Rotary::HeadAC; }
bool is_table(Rotary r) noexcept { return r == Rotary::TableAC || r == Rotary::TableBC; }

double tilt_of(Rotary r, const nc::AxisVector& q) noexcept { return tilt_is_a(r) ? q[nc::A] : q[nc::B]; }

Vec3 rot_tilt(Rotary r, Vec3 v, double deg) noexcept { return tilt_is_a(r) ? rot_x(v, deg) : rot_y(v, deg); }

// Workpiece-frame vector of a machine-frame vector for a table-table machine: the table
// turned the workpiece by R = R_tilt · R_C, so the inverse applies.
Vec3 table_inverse(Rotary r, const nc::AxisVector& q, Vec3 v) noexcept {
  return rot_z(rot_tilt(r, v, -tilt_of(r, q)), -q[nc::C]);
}

Vec3 head_axis(Rotary r, const nc::AxisVector& q) noexcept {
  return rot_z(rot_tilt(r, Vec3{0, 0, 1}, tilt_of(r, q)), q[nc::C]);
}

}  // namespace

const char* to_string(Rotary r) noexcept {
  switch (r) {
    case Rotary::TableAC: return "table-ac";
    case Rotary::TableBC: return "table-bc";
    case Rotary::HeadAC: return "head-ac";
    case Rotary::HeadBC: return "head-bc";
  }
  return "?";
}

bool parse_rotary(const char* s, Rotary& out) noexcept {
  for (Rotary r : {Rotary::TableAC, Rotary::TableBC, Rotary::HeadAC, Rotary::HeadBC}) {
    if (std::strcmp(s, to_string(r)) == 0) {
      out = r;
      return true;
    }
  }
  return false;
}

geom::Pose tool_pose(const Kinematics& k, const nc::AxisVector& q, Mount mount, double tool_length_mm) noexcept {
  const Vec3 p{q[nc::X], q[nc::Y], q[nc::Z]};
  switch (k.kind) {
    case MachineKind::Mill3: return {p, {0, 0, 1}};
    case MachineKind::Mill5: {
      if (is_table(k.rotary)) {
        const Vec3 axis = table_inverse(k.rotary, q, Vec3{0, 0, 1});
        if (k.tcp) return {p, axis};
        const Vec3 v = p - k.rotary_center_mm;
        return {p + (table_inverse(k.rotary, q, v) - v), axis};
      }
      const Vec3 axis = head_axis(k.rotary, q);
      if (k.tcp) return {p, axis};
      // Programmed point = tip at zero rotation; the head turns about the pivot, which sits
      // (tool length + pivot length) above it.
      const double arm = tool_length_mm + k.pivot_length_mm;
      return {p + arm * (Vec3{0, 0, 1} - axis), axis};
    }
    case MachineKind::Lathe:
    case MachineKind::LatheC: {
      if (mount == Mount::Turning || mount == Mount::Spindle) return {p, {0, 0, 1}};
      const Vec3 axis_m = rot_z(mount == Mount::Axial ? Vec3{0, 0, 1} : Vec3{1, 0, 0}, k.turret_angle_deg);
      const Vec3 tip_m = rot_z(p, k.turret_angle_deg);
      const double c = k.kind == MachineKind::LatheC ? q[nc::C] : 0.0;
      return {rot_z(tip_m, -c), rot_z(axis_m, -c)};
    }
  }
  return {p, {0, 0, 1}};
}

int substeps(const Kinematics& k, const nc::AxisVector& q0, const nc::AxisVector& q1, Mount mount,
             double tool_length_mm, double reach_mm, double tol_mm) noexcept {
  double angle_deg = 0.0, radius = 0.0;
  auto dist = [](const nc::AxisVector& q, Vec3 c) {
    return norm(Vec3{q[nc::X], q[nc::Y], q[nc::Z]} - c);
  };
  switch (k.kind) {
    case MachineKind::Mill3: return 1;
    case MachineKind::Mill5:
      angle_deg = std::abs(tilt_of(k.rotary, q1) - tilt_of(k.rotary, q0)) + std::abs(q1[nc::C] - q0[nc::C]);
      if (k.tcp) radius = 0.0;
      else if (is_table(k.rotary)) radius = std::max(dist(q0, k.rotary_center_mm), dist(q1, k.rotary_center_mm));
      else radius = tool_length_mm + k.pivot_length_mm;
      break;
    case MachineKind::Lathe: return 1;
    case MachineKind::LatheC:
      if (mount == Mount::Turning || mount == Mount::Spindle) return 1;
      angle_deg = std::abs(q1[nc::C] - q0[nc::C]);
      radius = std::max(std::hypot(q0[nc::X], q0[nc::Y]), std::hypot(q1[nc::X], q1[nc::Y]));
      break;
  }
  if (angle_deg == 0.0) return 1;
  radius += reach_mm;
  if (radius <= 0.0) return 1;
  // A point at distance ρ from the rotation axis turned by θ lies within ρ(1 − cos(θ/2)) of
  // the chord.
  const double step = 2.0 * std::acos(std::max(-1.0, 1.0 - std::min(1.0, tol_mm / radius)));
  if (!(step > 0.0)) return kMaxMoveSubsteps;
  const double n = std::ceil(angle_deg * kDeg / step);
  return static_cast<int>(std::clamp(n, 1.0, static_cast<double>(kMaxMoveSubsteps)));
}

}  // namespace lbr::kin
