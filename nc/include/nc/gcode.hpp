// nc/gcode.hpp — G-code (RS274/ISO, the dialect CAM post-processors write) to a Toolpath.
//
// Two front ends produce the same Toolpath from a part program:
//  - interpret_gcode(): the built-in interpreter (coverage in docs/nc-frontend.md);
//  - the LinuxCNC `rs274` canonical-command stream (nc/rs274.hpp), for what the built-in
//    interpreter refuses (G70-G72 lathe cycles, G84-G89, probing, remaps) and as its reference.
//
// Frames (docs/nc-frontend.md#frames): the Toolpath is in the G54 frame as it stands at
// program start (GcodeOptions::work_offsets[0]); the profile's stock is given in that frame.
// Machine coordinates (G53, G28/G30 home, work offsets) refer to the spindle gauge line;
// tool tip = gauge line - loaded tool length along Z. Programmed coordinates are those of the
// controlled point as in LinuxCNC: with G43 H<loaded tool> active the programmed Z is the tip.
//
// Not real-time code: the interpreter allocates and throws ParseError.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "nc/machine_kind.hpp"
#include "nc/toolpath.hpp"

namespace lbr::nc {

// The program syntax the built-in interpreter reads (profile [nc] dialect).
enum class Dialect : unsigned char {
  Rs274ngc,  // LinuxCNC's RS274/NGC: O-word subroutines and control flow, #<named> parameters
  Fanuc,     // ISO/Fanuc: O numbers, M98/M99, G65/G66 macros, IF/GOTO/WHILE (docs/nc-frontend.md#fanuc-dialect)
};

// "rs274ngc" / "fanuc" (profile [nc] dialect, --dialect): false for any other name.
[[nodiscard]] bool parse_dialect(const std::string& name, Dialect& out);

struct GcodeOptions {
  MachineKind machine = MachineKind::Mill3;
  Dialect dialect = Dialect::Rs274ngc;
  std::map<int, double> tool_lengths;    // tool number -> gauge line to tip [mm]; missing = 0
  std::map<int, double> tool_diameters;  // tool number -> diameter [mm]; cutter radius
                                         // compensation (G41/G42 D) in both front ends
  double chord_tol_mm = 0.001;         // max distance of an arc chord from the arc [mm]
  // Machine coordinates of the G54, G55, ... G59, G59.1, G59.2, G59.3 origins [mm, deg]
  // at program start (G10 L2 changes them while the program runs). work_offsets[0] defines
  // the Toolpath frame.
  std::array<AxisVector, 9> work_offsets{};
  AxisVector g28_home{};       // machine coordinates of the G28 position [mm, deg]
  AxisVector g30_home{};       // machine coordinates of the G30 position [mm, deg]
  AxisVector start_machine{};  // gauge line at program start, machine coordinates (homed: 0)
  int start_tool = 0;          // tool in the spindle at program start (0 = none)
  bool diameter_mode = false;  // lathe kinds: G7 (X words are diameters) at program start
  // Directories searched for NAME.ngc when a program calls o<name> that it does not define,
  // after the program's own directory (profile [nc] subroutine_path; LinuxCNC's SUBROUTINE_PATH).
  // The fanuc dialect looks there for O1234 / O1234.nc when M98 P1234 or G65 P1234 calls a
  // program that the file does not hold.
  std::vector<std::string> subroutine_path;
  // Mill5: which of A, B, C the machine has (a word for a missing one is an error).
  std::array<bool, 3> rotary{true, true, true};
  // At most this many blocks are executed (loops included); more is an error, not a hang. 0: no limit.
  long max_blocks = 20000000;
  // At most this many toolpath segments (moves, arc chords, dwells, tool changes) are made;
  // more is an error naming the line, not an exhausted memory (a short loop of large arcs
  // or many turns makes millions of chords per pass: 152 bytes each). 0: no limit.
  long max_segments = 20000000;
};

// Interprets G-code text. `name` is used in messages and as Toolpath::source. Arcs become
// Feed segments whose chords deviate at most chord_tol_mm from the arc. Every segment
// carries its 1-based source line. Throws ParseError ("NAME:LINE: message naming the word")
// for malformed or unsupported input; never skips a word silently.
[[nodiscard]] Toolpath interpret_gcode(const std::string& text, const std::string& name, const GcodeOptions& options);
// Reads and interprets a file. Throws ParseError (line 0 when the file cannot be read).
[[nodiscard]] Toolpath load_gcode(const std::string& path, const GcodeOptions& options);

// Records the machine frame of `options` (work_offsets[0], tool_lengths) in `path`
// (Toolpath::machine_origin, tool_lengths_mm): what both G-code front ends do, and what a
// move list, whose tips are in the same frame, gets from its caller.
void set_machine_frame(Toolpath& path, const GcodeOptions& options);

// Reads a whole file into a string. Throws ParseError(path, 0, "cannot open file").
[[nodiscard]] std::string read_text_file(const std::string& path);

}  // namespace lbr::nc
