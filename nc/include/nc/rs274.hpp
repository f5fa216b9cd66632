// nc/rs274.hpp — LinuxCNC's `rs274` interpreter as an alternative G-code front end.
//
// `rs274` (Debian package linuxcnc-uspace) run standalone prints the canonical machining
// commands of a program (STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED, tool changes, units,
// offsets). parse_rs274_canon() turns that text into a Toolpath through the same coordinate
// conversion as the built-in interpreter (nc/gcode.hpp), so both front ends agree within
// the chord tolerance. run_rs274() runs the program through the binary: it accepts some of
// what the built-in interpreter rejects (G70-G72 lathe cycles) and is its reference.
// Not real-time code: allocates, starts a process, throws.
#pragma once

#include <string>

#include "nc/gcode.hpp"
#include "nc/toolpath.hpp"

namespace lbr::nc {

// Parses rs274's canonical output. Segment lines come from the N words of the canonical
// lines (run_rs274 numbers every program line, so they are the source lines); `name` is the
// program name for messages. Spindle-synchronised moves (START_SPEED_FEED_SYNC, RIGID_TAP)
// and feed per revolution become feeds at K (or F) x the spindle speed. Throws ParseError on
// commands that cannot be represented (probing, XY rotation, NURBS, unknown motion commands).
[[nodiscard]] Toolpath parse_rs274_canon(const std::string& canon, const std::string& name, const GcodeOptions& options);

// Full path of the rs274 executable found on PATH, or "" when it is not installed.
[[nodiscard]] std::string find_rs274();

// Runs `rs274 -g -i INI -t TOOLTABLE -v VARFILE PROGRAM < /dev/null` in a temporary
// directory (tool table, work offsets and G28/G30 positions written from `options`) and
// parses its output. Throws std::runtime_error when rs274 is not on PATH, ParseError
// (program:line: rs274: message) when rs274 rejects the program.
[[nodiscard]] Toolpath run_rs274(const std::string& program_path, const GcodeOptions& options);

}  // namespace lbr::nc
