// The Fanuc dialect's scanner (fanuc.hpp). Each line is classified once: an O number starts a
// program, a macro statement becomes an OWord, an NC block stays a block (M98 / M99 words
// split off it). DO / END are matched here into the link / end indices ControlFlow's while
// loops use, so running a Fanuc program is the same walk as running an NGC one.
#include "fanuc.hpp"

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace lbr::nc::detail {

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);
constexpr int kMaxLoopNesting = 3;  // Fanuc: DO loops nest three deep

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_letter(char c) { return c >= 'A' && c <= 'Z'; }
bool starts(const std::string& s, std::size_t i, const char* t) { return s.compare(i, std::strlen(t), t) == 0; }

// Position after the ']' that closes the '[' at i; kNone when it is not closed.
std::size_t bracket_end(const std::string& s, std::size_t i) {
  int depth = 0;
  for (; i < s.size(); ++i) {
    if (s[i] == '[') ++depth;
    else if (s[i] == ']' && --depth == 0) return i + 1;
  }
  return kNone;
}

// A word of an NC block: the letter at `at`, the value up to `end`.
struct Word {
  char letter = 0;
  std::size_t at = 0, end = 0;
};

// Fanuc word syntax: a letter, then [sign] a number, #n, #[...] or [...]. nullopt when the text
// is not such a sequence (the G-code executor then says what is wrong with it).
std::optional<std::vector<Word>> split_words(const std::string& s) {
  std::vector<Word> out;
  std::size_t i = 0;
  while (i < s.size()) {
    if (!is_letter(s[i])) return std::nullopt;
    Word w{s[i], i, 0};
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (i < s.size() && s[i] == '#') ++i;
    if (i < s.size() && s[i] == '[') {
      i = bracket_end(s, i);
      if (i == kNone) return std::nullopt;
    } else {
      const std::size_t d = i;
      while (i < s.size() && (is_digit(s[i]) || s[i] == '.')) ++i;
      if (i == d) return std::nullopt;
    }
    w.end = i;
    out.push_back(w);
  }
  return out;
}

// The code of a G or M word written as plain digits ("G65", "M098"); -1 otherwise.
int plain_code(const std::string& s, const Word& w) {
  const std::string v = s.substr(w.at + 1, w.end - w.at - 1);
  if (v.empty() || v.size() > 6 || v.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::atoi(v.c_str());
}

std::string text_of(const std::string& s, const Word& w) { return s.substr(w.at, w.end - w.at); }

class Scanner {
 public:
  Scanner(NgcFile& f, bool main_file) : f_(f), main_file_(main_file) {}

  void run() {
    f_.fanuc = true;
    f_.owner.assign(f_.lines.size(), kNone);
    for (std::size_t i = 0; i < f_.lines.size(); ++i)
      if (f_.errors[i].empty()) line(i);  // a line that failed to normalise is reported when run
    close_program(f_.lines.size());
  }

 private:
  struct Loop {
    std::size_t at;
    char id;
  };

  [[noreturn]] void fail(std::size_t i, const std::string& m) const {
    throw ParseError(f_.path, static_cast<int>(i) + 1, m);
  }

  // "/N10 rest": block delete (the switch is off: the block runs) and the sequence number.
  std::size_t sequence_number(std::size_t i, const std::string& code) {
    std::size_t p = code.size() > 0 && code[0] == '/' ? 1 : 0;
    if (p + 1 < code.size() && code[p] == 'N' && is_digit(code[p + 1])) {
      std::size_t e = p + 1;
      while (e < code.size() && is_digit(code[e])) ++e;
      if (e - p - 1 > 5) fail(i, "sequence number '" + code.substr(p, e - p) + "' has more than 5 digits");
      f_.numbers.emplace(std::atol(code.substr(p + 1, e - p - 1).c_str()), i);
      p = e;
    }
    return p;
  }

  void line(std::size_t i) {
    std::string& code = f_.lines[i].code;
    f_.owner[i] = program_;
    const std::string w = code.substr(sequence_number(i, code));
    if (w.empty()) return;
    if ((w[0] == 'O' || w[0] == ':') && w.size() > 1 && is_digit(w[1])) return header(i, w);
    if (program_ == kNone) main_has_code_ = true;
    if (starts(w, 0, "WHILE[")) {
      const std::size_t e = bracket_end(w, 5);
      if (e == kNone) fail(i, "'WHILE [' without its closing ']'");
      if (!starts(w, e, "DO")) fail(i, "'WHILE [...]' needs 'DO m' after the condition");
      statement(i, OKind::While, "WHILE", w, 5, 0);
      open_loop(i, loop_id(i, w, e + 2, "DO"));
    } else if (starts(w, 0, "IF[")) {
      conditional(i, w);
    } else if (starts(w, 0, "GOTO")) {
      if (w.size() == 4) fail(i, "'GOTO' needs a sequence number");
      statement(i, OKind::Goto, "GOTO", w, kNone, 4);
    } else if (starts(w, 0, "DO") && w.size() > 2 && is_digit(w[2])) {
      statement(i, OKind::Do, "DO", w, kNone, 0);
      open_loop(i, loop_id(i, w, 2, "DO"));
    } else if (starts(w, 0, "END") && w.size() > 3 && is_digit(w[3])) {
      statement(i, OKind::EndWhile, "END", w, kNone, 0);
      close_loop(i, loop_id(i, w, 3, "END"));
    } else if (w[0] == '#') {
      statement(i, OKind::Assign, "#", w, kNone, 0);
    } else {
      block(i, w);
    }
  }

  void statement(std::size_t i, OKind kind, const char* keyword, const std::string& w, std::size_t cond, std::size_t target) {
    OWord& o = f_.ow[i];
    o.kind = kind;
    o.label = keyword;
    o.words = w;
    o.rest = cond;
    o.target = target;
    f_.lines[i].code.clear();
  }

  // IF [condition] GOTO n | IF [condition] THEN #i = expression
  void conditional(std::size_t i, const std::string& w) {
    const std::size_t e = bracket_end(w, 2);
    if (e == kNone) fail(i, "'IF [' without its closing ']'");
    if (starts(w, e, "GOTO") && e + 4 < w.size()) return statement(i, OKind::Goto, "IF", w, 2, e + 4);
    if (starts(w, e, "THEN") && e + 4 < w.size() && w[e + 4] == '#') return statement(i, OKind::Assign, "IF", w, 2, e + 4);
    fail(i, "'IF [...]' needs 'GOTO n' or 'THEN #i = ...' after the condition");
  }

  char loop_id(std::size_t i, const std::string& w, std::size_t at, const char* keyword) const {
    if (w.size() != at + 1 || w[at] < '1' || w[at] > '3')
      fail(i, std::string("'") + keyword + "' needs an identification number 1, 2 or 3, not '" + w.substr(at) + "'");
    return w[at];
  }
  void open_loop(std::size_t i, char id) {
    if (loops_.size() >= static_cast<std::size_t>(kMaxLoopNesting)) fail(i, "DO loops nested deeper than 3");
    loops_.push_back({i, id});
  }
  void close_loop(std::size_t i, char id) {
    if (loops_.empty() || loops_.back().id != id)
      fail(i, std::string("'END ") + id + "' does not close an open 'DO " + id + "'" +
                  (loops_.empty() ? std::string() : std::string(" (the innermost open loop is 'DO ") + loops_.back().id + "')"));
    f_.link[i] = loops_.back().at;
    f_.end[loops_.back().at] = i;
    loops_.pop_back();
  }

  // O1234 / :1234 starts a program: the main program (the given file's first, unless code
  // came before it) or a subprogram, which runs only when called and ends at the next O.
  void header(std::size_t i, const std::string& w) {
    std::size_t e = 1;
    while (e < w.size() && is_digit(w[e])) ++e;
    if (e != w.size()) fail(i, "unexpected '" + w.substr(e) + "' after the program number '" + w.substr(0, e) + "'");
    if (e - 1 > 8) fail(i, "program number '" + w + "' has more than 8 digits");
    const std::string label = std::to_string(std::atol(w.substr(1).c_str()));
    close_program(i);
    f_.lines[i].code.clear();
    const bool is_main = main_file_ && !header_seen_ && !main_has_code_;
    header_seen_ = true;
    program_ = is_main ? kNone : i;
    f_.owner[i] = program_;
    if (is_main) return;  // an empty block
    if (f_.subs.count(label) != 0) fail(i, "program O" + label + " is defined twice");
    f_.subs[label] = i;
    f_.ow[i].kind = OKind::Sub;
    f_.ow[i].label = label;
  }
  void close_program(std::size_t next) {
    if (!loops_.empty())
      fail(loops_.back().at, std::string("'DO ") + loops_.back().id + "' is never closed by 'END " + loops_.back().id + "'");
    if (program_ != kNone) f_.end[program_] = next - 1;
  }

  // An NC block; M98 / M99 and their words are split off (the rest runs first), G65 / G66 /
  // G67 take the whole block.
  void block(std::size_t i, const std::string& w) {
    if (w.find('=') != std::string::npos) fail(i, "a macro assignment '#i = ...' must be a block of its own");
    const auto words = split_words(w);
    if (!words) return;
    const Word* macro = nullptr;
    const Word* sub = nullptr;
    for (const Word& x : *words) {
      const int c = plain_code(w, x);
      const bool is_macro = x.letter == 'G' && (c == 65 || c == 66 || c == 67);
      const bool is_sub = x.letter == 'M' && (c == 98 || c == 99);
      if (!is_macro && !is_sub) continue;
      if (macro != nullptr || sub != nullptr)
        fail(i, "'" + text_of(w, x) + "' cannot share a block with '" + text_of(w, macro ? *macro : *sub) + "'");
      (is_macro ? macro : sub) = &x;
    }
    OWord& o = f_.ow[i];
    if (macro != nullptr) return macro_block(i, w, *words, *macro);
    if (sub == nullptr) {
      for (const Word& x : *words) o.axis_words = o.axis_words || std::strchr("XYZABC", x.letter) != nullptr;
      return;
    }
    std::string rest;
    for (const Word& x : *words)
      if (&x != sub) (x.letter == 'P' || x.letter == 'L' ? o.words : rest) += text_of(w, x);
    const bool call = plain_code(w, *sub) == 98;
    if (!call && o.words.find('L') != std::string::npos) fail(i, "'M99' takes no L word");
    o.kind = call ? OKind::Call : OKind::Return;
    o.label = call ? "M98" : "M99";
    o.block_first = !rest.empty();
    f_.lines[i].code = rest;
  }
  void macro_block(std::size_t i, const std::string& w, const std::vector<Word>& words, const Word& g) {
    OWord& o = f_.ow[i];
    const int c = plain_code(w, g);
    for (const Word& x : words) {
      if (&x == &g) continue;
      if (c == 67 || x.letter == 'G' || x.letter == 'M' || x.letter == 'N' || x.letter == 'O')
        fail(i, "'" + text_of(w, g) + "' cannot share a block with '" + text_of(w, x) + "'" +
                    (c == 67 ? "" : " (the block holds P, L and argument words)"));
      o.words += text_of(w, x);
    }
    o.kind = c == 65 ? OKind::Call : c == 66 ? OKind::ModalCall : OKind::EndModalCall;
    o.label = "G" + std::to_string(c);
    f_.lines[i].code.clear();
  }

  NgcFile& f_;
  bool main_file_;
  std::size_t program_ = kNone;  // O line of the program being read; kNone: the main program
  bool header_seen_ = false;
  bool main_has_code_ = false;
  std::vector<Loop> loops_;
};

// Argument specification I: the local each argument letter sets (0: not an argument).
int argument_local(char letter) {
  static constexpr std::array<int, 26> kLocal = {
      1, 2, 3, 7, 8, 9, 0, 11, 4, 5, 6, 0, 13,  // A B C D E F G H I J K L M
      0, 0, 0, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26};  // N O P Q R S T U V W X Y Z
  return kLocal[static_cast<std::size_t>(letter - 'A')];
}

long whole(double v, double hi, const std::string& what) {
  if (is_vacant(v) || v != std::floor(v) || v < 0.0 || v > hi)
    throw ExprError(what + " must be a whole number in [0, " + std::to_string(static_cast<long>(hi)) + "]");
  return static_cast<long>(v);
}

}  // namespace

std::unique_ptr<NgcFile> scan_fanuc(const std::string& text, const std::string& path, bool main_file) {
  auto f = read_program_lines(text, path);
  Scanner(*f, main_file).run();
  return f;
}

FanucCall read_fanuc_call(const std::string& words, bool macro, ExprReader& expr) {
  FanucCall c;
  if (macro) c.args.assign(kFanucLocalParams, vacant());
  const char* what = macro ? "G65" : "M98";
  std::array<bool, 26> seen{};
  std::string p_text;
  double p = vacant();
  bool has_l = false;
  for (std::size_t pos = 0; pos < words.size();) {
    const char L = words[pos];
    if (!is_letter(L)) throw ExprError("unexpected '" + words.substr(pos) + "'");
    if (seen[static_cast<std::size_t>(L - 'A')]) throw ExprError(std::string("word '") + L + "' given twice");
    seen[static_cast<std::size_t>(L - 'A')] = true;
    const std::size_t start = ++pos;
    const double v = expr.value(words, pos);
    const std::string text = words.substr(start, pos - start);
    if (L == 'P') {
      p = v, p_text = text;
    } else if (L == 'L') {
      c.count = whole(v, 9999, std::string(what) + " L (the number of passes)");
      has_l = true;
    } else if (macro && argument_local(L) != 0) {
      c.args[static_cast<std::size_t>(argument_local(L) - 1)] = v;
    } else {
      throw ExprError(std::string("'") + L + text + "' is not a " + what +
                      (macro ? " argument (argument specification I: A B C D E F H I J K M Q R S T U V W X Y Z)"
                             : " word (M98 takes P and L)"));
    }
  }
  if (p_text.empty()) throw ExprError(std::string(what) + " needs P (the program number)");
  long program = whole(p, 99999999, std::string(what) + " P (the program number)");
  // M98 P<passes><4-digit program>: P51002 runs O1002 five times.
  if (!macro && !has_l && p_text.size() > 4 && p_text.find_first_not_of("0123456789") == std::string::npos) {
    c.count = std::atol(p_text.substr(0, p_text.size() - 4).c_str());
    program = std::atol(p_text.substr(p_text.size() - 4).c_str());
  }
  c.label = std::to_string(program);
  return c;
}

long read_return_target(const std::string& words, ExprReader& expr) {
  std::size_t pos = 0;
  if (words[0] != 'P') throw ExprError("'M99' takes P (the sequence number to return to), not '" + words + "'");
  ++pos;
  const long n = whole(expr.value(words, pos), 99999, "M99 P (a sequence number)");
  if (pos != words.size()) throw ExprError("unexpected '" + words.substr(pos) + "' after M99 P");
  return n;
}

std::vector<std::string> fanuc_file_names(const std::string& label) {
  std::string padded = label;
  while (padded.size() < 4) padded.insert(padded.begin(), '0');
  std::vector<std::string> names = {"O" + padded, "O" + padded + ".nc", "o" + padded, "o" + padded + ".nc"};
  if (padded != label)
    for (const char* prefix : {"O", "o"}) names.push_back(prefix + label), names.push_back(prefix + label + ".nc");
  return names;
}

int fanuc_system_variable(int n) {
  if (n >= 5001 && n <= 5006) return 5420 + (n - 5001);
  if (n >= 5041 && n <= 5046) return 5420 + (n - 5041);
  if (n >= 5221 && n <= 5340 && (n - 5221) % 20 < 6) return n;
  return 0;
}

}  // namespace lbr::nc::detail
