// ngc_control.hpp (private) — RS274/NGC program flow: O-word subroutines and control flow.
//
// A program is read whole and each line normalised (ngc_expr.hpp); O-word lines are matched
// once (sub/endsub, if/elseif/else/endif, while/endwhile, do/while, repeat/endrepeat,
// break/continue), so a jump is an index. ControlFlow then walks the lines: O-word lines
// are executed here, every other line is handed to the block executor (the G-code
// interpreter). Subroutines called by name that the program does not define are read from
// NAME.ngc in the program's directory, then in GcodeOptions::subroutine_path (as LinuxCNC's
// SUBROUTINE_PATH). Errors are ParseError naming the file and line where they happen.
// The fanuc dialect (fanuc.hpp) is a second scanner over the same walk: its statements
// (M98/M99, G65/G66/G67, IF/GOTO, WHILE/DO/END, #i=...) become OWord entries of the same
// NgcFile, with the few kinds NGC lacks (Goto, Assign, ModalCall, EndModalCall).
// Not real-time code: allocates and throws.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "nc/gcode.hpp"
#include "ngc_expr.hpp"

namespace lbr::nc::detail {

enum class OKind : unsigned char {
  None, Sub, EndSub, Call, Return, If, ElseIf, Else, EndIf, While, EndWhile, Do, DoWhile, Repeat, EndRepeat,
  Break, Continue,
  Goto, Assign, ModalCall, EndModalCall  // fanuc dialect only
};

struct OWord {
  OKind kind = OKind::None;
  std::string label;     // "100" or "<NAME>" (normalised: upper case, no blanks)
  std::size_t rest = 0;  // position in the line's code after the keyword
  // Fanuc statements (fanuc.hpp): `label` is the keyword as written (M98, G65, WHILE, ...),
  // `words` the statement's text, which `rest` (its [condition]; npos: none) and `target`
  // (GOTO's N number, the '#' of an assignment) index. block_first: the line's other words
  // (its code) run as a block before the statement ("X10. M98 P100"). axis_words: an
  // ordinary block with axis words (a G66 modal call follows it).
  std::string words;
  std::size_t target = 0;
  bool block_first = false;
  bool axis_words = false;
};

// One program or subroutine file, read and matched.
struct NgcFile {
  std::string path;                     // as used in messages
  std::vector<NormalisedLine> lines;    // up to the closing '%' (or the end)
  std::vector<std::string> errors;      // per line: a normalisation error to report when executed
  std::vector<OWord> ow;                // per line
  std::vector<std::size_t> link;        // per O-line: partner (see ngc_control.cpp)
  std::vector<std::size_t> end;         // per O-line: end of its construct
  std::map<std::string, std::size_t> subs;  // label -> line index of its 'sub'
  bool fanuc = false;                       // scanned by scan_fanuc (fanuc.hpp)
  std::multimap<long, std::size_t> numbers;  // fanuc: N number -> line (GOTO targets)
  std::vector<std::size_t> owner;           // fanuc: per line, its program's O line (npos: main)
};

// Reads the lines of a program file up to the closing '%', normalised; ow, link and end are
// sized and empty (the scanners fill them).
[[nodiscard]] std::unique_ptr<NgcFile> read_program_lines(const std::string& text, const std::string& path);
// Reads `text` as a program file. Throws ParseError for unmatched O-words.
[[nodiscard]] std::unique_ptr<NgcFile> scan_program(const std::string& text, const std::string& path);

class ControlFlow {
 public:
  // Executes one normalised, non-O-word line; returns true when the program ends (M2, M30).
  using Executor = std::function<bool(const NormalisedLine& line)>;

  ControlFlow(Params& params, const GcodeOptions& options, Executor exec);

  // Runs the main program. Throws ParseError ("FILE:LINE: message").
  void run(const std::string& text, const std::string& name);

  // Where execution is: the file and 1-based line being executed.
  [[nodiscard]] const std::string& file() const;
  [[nodiscard]] int line() const;
  // The line of the main program that is executing or, inside another file, the main
  // program's line that called into it (Toolpath segments carry this line).
  [[nodiscard]] int main_line() const;
  [[nodiscard]] int call_level() const { return static_cast<int>(stack_.size()) - 1; }

  [[noreturn]] void fail(const std::string& msg) const;

  // Runs subroutine `label` (no arguments) to its return from inside the block being
  // executed (the G70-G72 profile), then goes on with that block.
  void call_now(const std::string& label);

  // Called when a subroutine returns (endsub, return), with the call level being left
  // (M73 restores the modal state saved at that level).
  void on_leave(std::function<void(int level)> hook) { on_leave_ = std::move(hook); }

 private:
  struct Activation {
    const NgcFile* file = nullptr;
    std::size_t pc = 0;
    std::string label;                         // subroutine label ("" for the main program)
    std::map<std::size_t, long> repeats;       // repeat line -> remaining passes
    // Fanuc calls (M98 P L, G65 P L): passes left, where a pass starts, the arguments each
    // pass gets, and whether the call has its own locals (G65) or shares the caller's (M98).
    long passes = 1;
    std::size_t entry = 0;
    std::vector<double> args;
    bool frame = true;
  };
  struct ModalCall {  // G66: the macro called after each block with axis words
    bool on = false;
    std::string label;
    std::vector<double> args;
    long count = 1;
    std::size_t level = 0;  // stack depth where G66 was given (moves inside the macro do not call)
  };

  static Activation activation(const NgcFile* file, std::size_t pc, const std::string& label) {
    Activation a;
    a.file = file, a.pc = pc, a.label = label;
    return a;
  }
  bool step();  // executes the line at pc; false when the program has ended
  bool oword(const OWord& o);  // false when the program has ended
  // Fanuc statements (fanuc.hpp).
  void fanuc_call(const OWord& o);
  bool fanuc_return(const OWord& o);
  void enter(const std::string& label, const std::vector<double>& args, bool frame, long count);
  void go_to(const OWord& o);
  void jump_to_number(long n, const std::string& what);
  void assign(const OWord& o);
  void modal_call(const OWord& o);
  void after_block(std::size_t i);
  const NgcFile* load_fanuc_file(const std::string& label);
  void branch_false(std::size_t i);
  void call(const OWord& o);
  void leave(const OWord& o);
  double condition(const OWord& o);
  const NgcFile* find_sub(const std::string& label, std::size_t& at);
  const NgcFile* load_sub_file(const std::string& label);

  Params& params_;
  const GcodeOptions& opt_;
  Executor exec_;
  ExprReader expr_;
  std::vector<std::unique_ptr<NgcFile>> files_;  // [0] = main program
  std::vector<Activation> stack_;
  std::vector<std::string> search_dirs_;
  long executed_ = 0;
  ModalCall modal_;
  std::function<void(int level)> on_leave_;
};

}  // namespace lbr::nc::detail
