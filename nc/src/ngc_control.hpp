// ngc_control.hpp (private) — RS274/NGC program flow: O-word subroutines and control flow.
//
// A program is read whole and each line normalised (ngc_expr.hpp); O-word lines are matched
// once (sub/endsub, if/elseif/else/endif, while/endwhile, do/while, repeat/endrepeat,
// break/continue), so a jump is an index. ControlFlow then walks the lines: O-word lines
// are executed here, every other line is handed to the block executor (the G-code
// interpreter). Subroutines called by name that the program does not define are read from
// NAME.ngc in the program's directory, then in GcodeOptions::subroutine_path (as LinuxCNC's
// SUBROUTINE_PATH). Errors are ParseError naming the file and line where they happen.
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
  Break, Continue
};

struct OWord {
  OKind kind = OKind::None;
  std::string label;     // "100" or "<NAME>" (normalised: upper case, no blanks)
  std::size_t rest = 0;  // position in the line's code after the keyword
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
};

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

  // Called when a subroutine returns (endsub, return), with the call level being left
  // (M73 restores the modal state saved at that level).
  void on_leave(std::function<void(int level)> hook) { on_leave_ = std::move(hook); }

 private:
  struct Activation {
    const NgcFile* file = nullptr;
    std::size_t pc = 0;
    std::string label;                         // subroutine label ("" for the main program)
    std::map<std::size_t, long> repeats;       // repeat line -> remaining passes
  };

  bool step();  // executes the line at pc; false when the program has ended
  void oword(const OWord& o);
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
  std::function<void(int level)> on_leave_;
};

}  // namespace lbr::nc::detail
