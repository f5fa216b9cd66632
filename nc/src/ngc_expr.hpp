// ngc_expr.hpp (private) — the RS274/NGC value language: parameters and expressions.
//
// Works on a *normalised* line (normalise_line): comments removed, spaces and tabs removed,
// letters upper case, as LinuxCNC reads a block. Values are numbers, parameters (#5, #[1+2],
// ##1, #<name>, #<_global>), bracketed expressions with the binary operators ** * / MOD + -
// EQ NE GT GE LT LE AND OR XOR (that precedence, left to right) and the functions ABS ACOS
// ASIN ATAN[y]/[x] COS EXP FIX FUP ROUND LN SIN SQRT TAN EXISTS[#<name>]; angles in degrees.
// Semantics follow LinuxCNC's documentation (docs/nc-frontend.md#parameters-and-expressions).
// Not real-time code: allocates and throws ExprError.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace lbr::nc::detail {

// An error in a line; the caller adds file and line.
class ExprError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A source line as the interpreter reads it. `code` is what remains for the parser.
struct NormalisedLine {
  std::string code;                   // no comments, no blanks, upper case
  std::vector<std::string> comments;  // text inside ( ), as written
};
// Throws ExprError("unclosed comment '('") for a '(' without ')'.
[[nodiscard]] NormalisedLine normalise_line(std::string_view raw);

inline constexpr int kMaxNumberedParam = 5602;  // #1 .. #5602 as in LinuxCNC
inline constexpr int kLocalParams = 30;         // #1 .. #30 are local to a subroutine call
inline constexpr int kFanucLocalParams = 33;    // Fanuc dialect: #1 .. #33

// Parameter storage: numbered parameters, named locals per call frame, named globals
// (names starting with '_'). Read-only system values come from the hooks.
class Params {
 public:
  Params();
  // Fanuc macro variables (docs/nc-frontend.md#fanuc-dialect): #0 and every variable not set
  // yet are <vacant>, held as NaN (is_vacant); locals are #1..#33; only #1..#33, #100..#199
  // and #500..#999 can be set; the Fanuc functions (POW, BIN, BCD, ATAN[y,x]) are known.
  void use_fanuc_variables();
  [[nodiscard]] bool fanuc() const { return fanuc_; }
  // Hooks for computed read-only parameters (#5420.., #<_x>, ...): return true and set v.
  std::function<bool(int, double&)> numbered_hook;
  std::function<bool(const std::string&, double&)> named_hook;

  [[nodiscard]] double numbered(int n) const;  // throws ExprError outside 1..kMaxNumberedParam
  void set_numbered(int n, double v);
  // Named parameter (name upper case, without #< >). Throws ExprError when not defined.
  [[nodiscard]] double named(const std::string& name) const;
  [[nodiscard]] bool named_exists(const std::string& name) const;
  void set_named(const std::string& name, double v);

  // Subroutine frames: push saves the locals (#1..#30; Fanuc #1..#33) and sets them to `args`
  // (the rest 0; Fanuc: vacant); pop restores.
  void push_frame(const std::vector<double>& args);
  void pop_frame();
  [[nodiscard]] int depth() const { return static_cast<int>(frames_.size()) - 1; }

 private:
  struct Frame {
    std::array<double, kFanucLocalParams> saved{};
    std::map<std::string, double> locals;
  };
  // The value of a parameter never set: 0 (RS274/NGC) or <vacant> (Fanuc).
  [[nodiscard]] double unset() const;
  // Parameter n's storage, growing the table to n (new entries unset()). The table holds only
  // up to the highest parameter set so far: a program that sets none allocates none (reading
  // one beyond the table gives unset()), instead of #0..#5602 per interpreter.
  double& slot(int n);

  std::vector<double> numbered_;
  std::map<std::string, double> globals_;
  std::vector<Frame> frames_;
  bool fanuc_ = false;
  int locals_ = kLocalParams;
};

// Fanuc's <vacant> value (Params::use_fanuc_variables).
[[nodiscard]] double vacant();
[[nodiscard]] bool is_vacant(double v);

// A pending parameter assignment of a line: applied after the whole line has been read.
struct ParamAssign {
  int number = 0;    // > 0: numbered
  std::string name;  // otherwise named
  double value = 0.0;
};

// Reads values from a normalised line at `pos`, advancing it.
class ExprReader {
 public:
  explicit ExprReader(Params& p) : params_(p) {}
  // A real value: number, parameter, [expression], function, or a sign before one of them.
  [[nodiscard]] double value(std::string_view s, std::size_t& pos);
  // "#ref=value" at pos (pos at '#'): the assignment target and value. With Fanuc variables
  // the value is a whole expression ("#1=#2+#3*2"), read to the end of `s`.
  [[nodiscard]] ParamAssign assignment(std::string_view s, std::size_t& pos);
  // A bracketed expression "[...]" at pos.
  [[nodiscard]] double bracketed(std::string_view s, std::size_t& pos);
  // True when a number literal starts at pos (digits or '.').
  [[nodiscard]] static bool number_starts(std::string_view s, std::size_t pos);

 private:
  double binary(std::string_view s, std::size_t& pos, int level);
  double operate(std::string_view op, double a, double b) const;
  double fanuc_function(std::string_view f, std::string_view s, std::size_t& pos);
  double parameter(std::string_view s, std::size_t& pos);
  double function(std::string_view s, std::size_t& pos);
  static double number(std::string_view s, std::size_t& pos);
  static std::string param_name(std::string_view s, std::size_t& pos);
  int param_number(std::string_view s, std::size_t& pos);

  Params& params_;
  int depth_ = 0;
};

}  // namespace lbr::nc::detail
