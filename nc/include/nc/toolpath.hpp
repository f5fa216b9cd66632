// nc/toolpath.hpp — the tool path every front end produces and the simulator consumes.
//
// A tool path is a sequence of segments in the workpiece frame. Positions are the tool tip
// (tool length already applied) in mm, rotary axes in degrees. Front ends: the move list
// (nc/movelist.hpp), the G-code interpreter (nc/gcode.hpp) and LinuxCNC's rs274 (nc/rs274.hpp);
// frames in docs/nc-frontend.md#frames. The machine emulator (nc/emulator.hpp) consumes it.
#pragma once

#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace lbr::nc {

enum Axis : int { X = 0, Y, Z, A, B, C };
inline constexpr int kAxes = 6;
using AxisVector = std::array<double, kAxes>;  // X Y Z [mm], A B C [deg]

enum class SegmentKind : unsigned char {
  Rapid,       // positioning at the machine's rapid rate (still removes material it meets)
  Feed,        // cutting move at feed_mm_per_min
  Dwell,       // stay in place for dwell_s
  ToolChange,  // load `tool`; position unchanged
};

[[nodiscard]] const char* to_string(SegmentKind k) noexcept;

// Path control in effect for a move (docs/nc-frontend.md#planner): how the machine emulator
// passes the corner at the move's end.
enum class PathControl : unsigned char {
  ExactStop,  // G61.1: stop at the end of every move (also move lists, which have no such word)
  ExactPath,  // G61: stop at corners, keep speed through exactly collinear moves
  Blend,      // G64 [P] [Q]: blend corners within blend_tol_mm, keep speed through tangent runs
};

// Spindle state in effect for a segment (docs/nc-frontend.md#spindle): M3 (Cw), M4 (Ccw), M5
// (Off; also at program start, as LinuxCNC powers up). Unknown: the front end has no spindle
// words (move lists), so the process checks cannot judge it.
enum class Spindle : unsigned char { Unknown, Off, Cw, Ccw };

struct Segment {
  SegmentKind kind = SegmentKind::Feed;
  AxisVector end{};                       // axis positions at the end of the segment
  bool has_tool_axis = false;             // CL data: explicit tool axis (overrides kinematics)
  std::array<double, 3> tool_axis{0, 0, 1};  // unit vector, tip → holder, workpiece frame
  double feed_mm_per_min = 0.0;           // Feed only
  double dwell_s = 0.0;                   // Dwell only
  int tool = 0;                           // tool in the spindle during (after) the segment
  int line = 0;                           // 1-based source line
  PathControl path_control = PathControl::ExactStop;
  double blend_tol_mm = 0.0;              // G64 P: corner deviation bound [mm]; 0: none
  double naive_tol_mm = 0.0;              // G64 Q: collinear feeds within this merge [mm]; 0: off
  Spindle spindle = Spindle::Unknown;     // spindle during the segment
  double spindle_s = 0.0;                 // S word in effect: rpm (G97) or surface speed (G96); 0: not turning
  // True when the spindle turns: M3 or M4 with S > 0 (Unknown counts as turning: not judged).
  [[nodiscard]] bool spindle_turning() const noexcept {
    return spindle == Spindle::Unknown || ((spindle == Spindle::Cw || spindle == Spindle::Ccw) && spindle_s > 0.0);
  }
};

struct Toolpath {
  std::string source;                    // file name for messages
  AxisVector start{};                    // tip position before the first segment
  std::array<double, 3> start_axis{0, 0, 1};
  int start_tool = 0;
  std::vector<Segment> segments;
  // The machine frame (docs/nc-frontend.md#frames): machine coordinates of this frame's origin
  // (the G54 origin at program start) and the gauge length the front end took off each
  // tool's tip along Z (missing: 0). machine_axes() adds them back.
  AxisVector machine_origin{};
  std::map<int, double> tool_lengths_mm;
};

// Machine axis positions (the spindle gauge line in machine coordinates, rotary axes as
// programmed) of the tool-tip position `tip` of `path` with `tool` in the spindle.
[[nodiscard]] AxisVector machine_axes(const Toolpath& path, const AxisVector& tip, int tool) noexcept;

// Parse errors in any front end: what() is "FILE:LINE: message".
class ParseError : public std::runtime_error {
 public:
  ParseError(const std::string& file, int line, const std::string& msg)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + msg), file_(file), line_(line) {}
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] int line() const noexcept { return line_; }

 private:
  std::string file_;
  int line_;
};

}  // namespace lbr::nc
