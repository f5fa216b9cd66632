// fanuc.hpp (private) — the Fanuc (ISO) macro dialect as a front end of the built-in interpreter.
//
// scan_fanuc reads a Fanuc program file into the NgcFile that ControlFlow walks
// (ngc_control.hpp): O numbers become subroutine labels, WHILE/DO/END the same loop entries
// as NGC's while/endwhile, M98/M99/G65/G66/G67, IF ... GOTO / THEN and #i = ... statements
// the few OWord kinds NGC lacks. Ordinary blocks go unchanged to the G-code executor, and
// values go through the same ExprReader with Fanuc variables (Params::use_fanuc_variables).
// What is supported and refused: docs/nc-frontend.md#fanuc-dialect.
// Not real-time code: allocates and throws.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "ngc_control.hpp"
#include "ngc_expr.hpp"

namespace lbr::nc::detail {

// Reads `text` as a Fanuc program file. main_file: the program given to run (its first O
// number, or the lines before any, is the main program); otherwise a file found on the
// subroutine path, whose every O number is a subprogram. Throws ParseError ("FILE:LINE: ...")
// for malformed statements and unmatched DO / END.
[[nodiscard]] std::unique_ptr<NgcFile> scan_fanuc(const std::string& text, const std::string& path, bool main_file);

// A call's words ("P1000L3", "P9010L2A1.B#2"), read when the call executes.
struct FanucCall {
  std::string label;         // program number without leading zeros ("1000")
  long count = 1;            // passes (L; M98 also P<count><4-digit program>)
  std::vector<double> args;  // macro (G65/G66): #1..#33 by argument specification I, <vacant> if not given
};
// macro: G65/G66 (argument words allowed), else M98. Throws ExprError.
[[nodiscard]] FanucCall read_fanuc_call(const std::string& words, bool macro, ExprReader& expr);
// M99's words "P n": the sequence number to return to. Throws ExprError.
[[nodiscard]] long read_return_target(const std::string& words, ExprReader& expr);
// File names tried on the subroutine path for program `label` ("O1234", "O1234.nc", ...).
[[nodiscard]] std::vector<std::string> fanuc_file_names(const std::string& label);
// The built-in interpreter's (LinuxCNC-numbered) system parameter that a Fanuc system
// variable reads, or 0 when the dialect has none: #5001-#5006 and #5041-#5046 (position,
// work frame) -> #5420-#5425; #5221-#5326 (G54-G59 offsets) -> the same numbers.
[[nodiscard]] int fanuc_system_variable(int n);

}  // namespace lbr::nc::detail
