// nc/emulator.hpp — machine emulator: a Toolpath as a controller would execute and report it.
//
// Motion model (docs/nc-frontend.md#planner): a look-ahead trajectory planner in X Y Z A B C.
// Moves under G64 are joined by tangent circular blend arcs (corner deviation <= the G64 P
// tolerance, collinear runs within Q merged), G61 stops at corners, G61.1 and move lists stop
// after every move. A backward and a forward velocity pass over the whole program give every
// piece (line, blend arc) a trapezoidal speed profile that keeps each axis within its velocity
// and acceleration limits and can stop within the remaining path. The path parameter is the
// X Y Z A B C length [mm, deg counted as mm]; the programmed feed is the XYZ speed (the rotary
// speed for rotary-only moves, deg/min). Dwell and ToolChange hold the position for dwell_s /
// tool_change_s.
//
// Samples are taken every period at t = (seq + 1) * period, seq = 0, 1, ...; the last one is
// the first at or after the end of the program, so count * period - total time is in
// [0, period). Deterministic: the same path and limits give bit-identical samples.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "nc/toolpath.hpp"

namespace lbr::nc {

struct EmulatorLimits {
  double rapid_mm_per_min = 15000.0;   // rapid rate along the path [mm/min]
  double max_feed_mm_per_min = 0.0;    // cap on programmed feeds [mm/min]; 0: none
  AxisVector max_velocity{15000, 15000, 15000, 3600, 3600, 3600};  // per axis [mm/min | deg/min]
  AxisVector max_accel{1000, 1000, 1000, 720, 720, 720};           // per axis [mm/s² | deg/s²]
  double sample_period_ms = 4.0;       // [ms]
  double tool_change_s = 0.0;          // [s]
};

// Checks the limits; returns "" when usable, else what is wrong (e.g. "sample period must be > 0 ms").
[[nodiscard]] std::string validate(const EmulatorLimits& limits);

struct Sample {
  std::uint64_t seq = 0;  // 0, 1, 2, ...
  double t_s = 0.0;       // (seq + 1) * period [s]
  int tool = 0;           // tool in the spindle
  AxisVector axes{};      // tool tip in the Toolpath frame [mm, deg]
};

// Incremental sample generator. The constructor plans the whole path (allocates, may throw
// std::invalid_argument for invalid limits or segments, naming the source line); next()
// and the queries are real-time safe: no allocation, no exceptions, no locks.
class Emulator {
 public:
  Emulator(const Toolpath& path, const EmulatorLimits& limits);

  // Writes the next sample and returns true; false (and `out` untouched) after the last one.
  bool next(Sample& out) noexcept;
  // Back to the first sample.
  void reset() noexcept { seq_ = 0, seg_ = 0; }

  [[nodiscard]] double total_time_s() const noexcept { return total_s_; }
  [[nodiscard]] std::uint64_t sample_count() const noexcept { return count_; }
  [[nodiscard]] double period_s() const noexcept { return period_s_; }

  // Position and tool at time t [s] (clamped to [0, total]). Real-time safe; O(log n).
  void state_at(double t_s, AxisVector& axes, int& tool) const noexcept;
  // Source line of the planned piece that holds time t [s] (a blend arc: the line of the
  // move it leaves; t at a boundary: the piece that ends there); 0 before the first piece
  // or without pieces. Real-time safe; O(log n). Reads only the plan, so another thread may
  // call it while next() runs.
  [[nodiscard]] int line_at(double t_s) const noexcept;

  // One planned piece of motion (exposed for tests and tools): a Hold (dwell, tool change), a
  // Line from `from` to `to`, or an Arc (blend) whose geometry is arcs()[arc].
  enum class PieceKind : unsigned char { Hold, Line, Arc };
  struct Plan {
    PieceKind kind = PieceKind::Hold;
    AxisVector from{}, to{};
    double t0_s = 0.0;        // start time [s]
    double duration_s = 0.0;  // [s]
    double length = 0.0;      // path parameter length [mm, deg]
    double v_in = 0.0;        // speed at the start [unit/s]
    double v = 0.0;           // peak (cruise) speed [unit/s]
    double v_out = 0.0;       // speed at the end [unit/s]
    double a = 0.0;           // tangential acceleration [unit/s²]
    double t_acc_s = 0.0;     // v_in -> v [s]
    double t_dec_s = 0.0;     // v -> v_out [s]
    int arc = -1;             // Arc: index into arcs()
    int tool = 0;             // tool during the piece
    int line = 0;             // source line (a blend arc: the line of the move it leaves)
    Spindle spindle = Spindle::Unknown;  // the segment's spindle state and S word (sampled_toolpath
    double spindle_s = 0.0;              // carries them, so batch --sampled judges spindle-off)
  };
  // Blend arc: position at path length s is centre + radius (cos(s/r) e1 + sin(s/r) e2).
  struct ArcGeom {
    AxisVector centre{}, e1{}, e2{};
    double radius = 0.0;
    double normal_accel = 0.0;  // centripetal acceleration allowed on it [unit/s²]
  };
  [[nodiscard]] const std::vector<ArcGeom>& arcs() const noexcept { return arcs_; }
  [[nodiscard]] const std::vector<Plan>& plans() const noexcept { return plans_; }

 private:
  void eval(std::size_t i, double t_s, AxisVector& axes) const noexcept;

  std::vector<Plan> plans_;
  std::vector<ArcGeom> arcs_;
  AxisVector start_{};
  int start_tool_ = 0;
  double period_s_ = 0.004;
  double total_s_ = 0.0;
  std::uint64_t count_ = 0;
  std::uint64_t seq_ = 0;
  std::size_t seg_ = 0;
};

// Total time [s] the emulated machine needs for `path`.
[[nodiscard]] double emulated_time_s(const Toolpath& path, const EmulatorLimits& limits);

// The sampled stream as a tool path, as live mode sees it: one Feed segment from sample to
// sample (has_tool_axis false; feed = distance / period), a ToolChange where the tool changes.
// Each segment keeps the line and spindle state of the program move it samples (G0 becomes
// Feed: a rapid is told by its speed, as in live mode; docs/verification.md).
[[nodiscard]] Toolpath sampled_toolpath(const Toolpath& path, const EmulatorLimits& limits);

}  // namespace lbr::nc
