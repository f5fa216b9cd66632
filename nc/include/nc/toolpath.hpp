// nc/toolpath.hpp — the tool path every front end produces and the simulator consumes.
//
// A tool path is a sequence of segments in the workpiece frame. Positions are the tool tip
// (tool length already applied) in mm, rotary axes in degrees. Front ends: the move list
// (nc/movelist.hpp), the G-code interpreter (nc/gcode.hpp) and LinuxCNC's rs274 (nc/rs274.hpp);
// frames in docs/nc-frontend.md#frames. The machine emulator (nc/emulator.hpp) consumes it.
#pragma once

#include <array>
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
};

struct Toolpath {
  std::string source;                    // file name for messages
  AxisVector start{};                    // tip position before the first segment
  std::array<double, 3> start_axis{0, 0, 1};
  int start_tool = 0;
  std::vector<Segment> segments;
};

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
