// motion/path_sweeps.hpp — tool paths (nc::Toolpath) of one or several channels → timed
// sweeps through each channel's kinematics (docs/machine-kinds.md).
//
// Offline (setup-time) code: everything here allocates; errors throw std::runtime_error
// naming the program's source:line. The live path uses motion/sample_stream.hpp instead.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "geom/lbr_solid.hpp"  // SweepRef
#include "kin/kinematics.hpp"
#include "motion/tool_table.hpp"
#include "nc/emulator.hpp"
#include "nc/toolpath.hpp"

namespace lbr::motion {

// One sweep with the time its motion ends [s] and the channel and tool that make it.
struct TimedSweep {
  double t_s = 0.0;
  int channel = 0;
  int tool = 0;
  geom::SweepRef ref;
  int line = 0;  // 1-based source line of the motion it belongs to (0: unknown)
};

// Maps one motion of a channel (axes q0 → q1 with `tool`) through the kinematics into
// sweeps: as many pieces as kin::substeps() asks for (rotary axes), timed over [t0, t1].
// Tool 0 (empty spindle) cuts nothing. The tools must be built (ToolTable::require).
class SweepMapper {
 public:
  SweepMapper(const ToolTable& tools, const kin::Kinematics& k) : tools_(tools), kin_(k) {}
  void map(const nc::AxisVector& q0, const nc::AxisVector& q1, int tool, geom::MoveId id, double t0, double t1,
           int channel, std::vector<TimedSweep>& out) const;

 private:
  const ToolTable& tools_;
  const kin::Kinematics& kin_;
};

// The motion segments of `path` as sweeps, appended to `out`; `end_time` (optional) gives
// each segment's end time (else 0). Move ids: id_base + segment index + 1. 3-axis machines
// and CL data (explicit tool axes in a move list) keep the path's own poses; other kinds go
// through SweepMapper. `moves` counts the motion segments that have a tool.
void path_sweeps(const ToolTable& tools, const kin::Kinematics& k, const nc::Toolpath& path,
                 const std::vector<double>* end_time, int channel, geom::MoveId id_base, std::vector<TimedSweep>& out,
                 std::uint64_t& moves);

// One channel of a machine: its tool path and kinematics.
struct ChannelPath {
  std::string name;
  nc::Toolpath path;
  kin::Kinematics kin;
};

struct PlannedSweeps {
  std::vector<TimedSweep> sweeps;  // in time order (ties: lower channel first)
  double machining_time_s = 0.0;   // the longest channel's emulated time [s]
  std::uint64_t moves = 0;         // motion segments (sampled: samples that moved)
};

// Several channels cutting the same stock (docs/machine-kinds.md#several-channels). Every
// channel is timed by the machine emulator (`limits`); each segment's sweeps enter at the
// time its motion ends (sub-steps at their share of it), ties in channel order. With
// `sampled`, the channels' emulated sample streams are mapped instead (one motion per
// sample that moved), as live mode receives them. Move ids: segment index + 1 plus the
// segment counts of the channels before (sampled: running sample count).
[[nodiscard]] PlannedSweeps plan_channels(const ToolTable& tools, std::span<const ChannelPath> channels,
                                          const nc::EmulatorLimits& limits, bool sampled);

}  // namespace lbr::motion
