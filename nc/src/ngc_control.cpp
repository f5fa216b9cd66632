// RS274/NGC program flow (ngc_control.hpp).
//
// O-word constructs are matched once per file (scan_program) into two per-line indices:
//   link: if/elseif/else -> the next branch of the same if; endwhile -> its while;
//         do-while -> its do; endrepeat -> its repeat; break/continue -> the loop head.
//   end:  if/elseif/else -> the endif; while/do/repeat -> the line closing the loop;
//         sub -> its endsub.
// so that running a program is a walk over an index with a stack of activations (one per
// subroutine call), as LinuxCNC's interpreter does it with its offset table. The fanuc
// dialect's scanner (fanuc.cpp) fills the same indices for WHILE/DO/END; its other
// statements (M98/M99 calls with passes, GOTO, #i = ..., G66) are run at the end of this file.
#include "ngc_control.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "fanuc.hpp"

namespace lbr::nc::detail {

namespace {

constexpr int kMaxCallDepth = 100;
constexpr std::size_t kNone = static_cast<std::size_t>(-1);

struct Keyword {
  const char* text;
  OKind kind;
};
// Longer keywords before their prefixes (ENDIF before ... , ELSEIF before ELSE).
constexpr Keyword kKeywords[] = {
    {"ENDSUB", OKind::EndSub},       {"ENDIF", OKind::EndIf},   {"ENDWHILE", OKind::EndWhile},
    {"ENDREPEAT", OKind::EndRepeat}, {"ELSEIF", OKind::ElseIf}, {"ELSE", OKind::Else},
    {"SUB", OKind::Sub},             {"CALL", OKind::Call},     {"RETURN", OKind::Return},
    {"IF", OKind::If},               {"WHILE", OKind::While},   {"DO", OKind::Do},
    {"REPEAT", OKind::Repeat},       {"BREAK", OKind::Break},   {"CONTINUE", OKind::Continue},
};

const char* keyword_name(OKind k) {
  for (const Keyword& kw : kKeywords)
    if (kw.kind == k) return kw.text;
  return k == OKind::DoWhile ? "WHILE" : "?";
}

// "N10O100WHILE[...]" -> label "100", kind While, rest at '['. Lines that do not start with an
// O-word give kind None and an empty label; an O-word without a keyword gives None + label.
OWord parse_oword(const std::string& code) {
  OWord o;
  std::size_t i = 0;
  if (i < code.size() && code[i] == '/') ++i;
  if (i < code.size() && code[i] == 'N') {
    std::size_t e = i + 1;
    while (e < code.size() && std::isdigit(static_cast<unsigned char>(code[e]))) ++e;
    if (e > i + 1) i = e;
  }
  if (i + 1 >= code.size() || code[i] != 'O') return o;
  std::size_t e = i + 1;
  if (code[e] == '<') {
    const std::size_t close = code.find('>', e);
    if (close == std::string::npos) return o;
    e = close + 1;
  } else {
    while (e < code.size() && std::isdigit(static_cast<unsigned char>(code[e]))) ++e;
    if (e == i + 1) return o;
  }
  o.label = code.substr(i + 1, e - i - 1);
  for (const Keyword& kw : kKeywords) {
    if (code.compare(e, std::string(kw.text).size(), kw.text) == 0) {
      o.kind = kw.kind;
      o.rest = e + std::string(kw.text).size();
      return o;
    }
  }
  o.rest = e;
  return o;
}

std::string owtext(const OWord& o) {
  std::string l = o.label;
  for (char& c : l) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return "'o" + l + " " + [&] {
    std::string k = keyword_name(o.kind);
    for (char& c : k) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return k;
  }() + "'";
}

// Matches the O-word constructs of one file (see the top of this file).
class Matcher {
 public:
  explicit Matcher(NgcFile& f) : f_(f) {}

  void run() {
    for (std::size_t i = 0; i < f_.ow.size(); ++i) line(i);
    if (!open_.empty()) {
      const Open& o = open_.back();
      fail(o.at, owtext(f_.ow[o.at]) + " is never closed");
    }
  }

 private:
  struct Open {
    std::size_t at;
    std::size_t last_branch;
    std::vector<std::size_t> branches;
  };

  [[noreturn]] void fail(std::size_t i, const std::string& m) const {
    throw ParseError(f_.path, static_cast<int>(i) + 1, m);
  }
  OWord& ow(std::size_t i) { return f_.ow[i]; }
  Open& top(std::size_t i, OKind want) {
    if (open_.empty() || ow(open_.back().at).kind != want || ow(open_.back().at).label != ow(i).label)
      fail(i, owtext(ow(i)) + " does not close an open 'o" + ow(i).label + " " +
                  std::string(keyword_name(want)) + "'");
    return open_.back();
  }
  std::size_t loop_of(std::size_t i) {
    for (auto it = open_.rbegin(); it != open_.rend(); ++it) {
      const OKind k = ow(it->at).kind;
      if ((k == OKind::While || k == OKind::Do || k == OKind::Repeat) && ow(it->at).label == ow(i).label) return it->at;
    }
    fail(i, owtext(ow(i)) + " is not inside a loop labelled o" + ow(i).label);
  }

  void line(std::size_t i) {
    switch (ow(i).kind) {
      case OKind::Sub:
        if (f_.subs.count(ow(i).label)) fail(i, "subroutine o" + ow(i).label + " is defined twice");
        open_.push_back({i, i, {}});
        break;
      case OKind::EndSub: {
        Open& o = top(i, OKind::Sub);
        f_.end[o.at] = i;
        f_.subs[ow(i).label] = o.at;
        open_.pop_back();
        break;
      }
      case OKind::If: open_.push_back({i, i, {i}}); break;
      case OKind::ElseIf:
      case OKind::Else: {
        Open& o = top(i, OKind::If);
        if (ow(o.last_branch).kind == OKind::Else) fail(i, owtext(ow(i)) + " after 'else'");
        f_.link[o.last_branch] = i;
        o.last_branch = i;
        o.branches.push_back(i);
        break;
      }
      case OKind::EndIf: {
        Open& o = top(i, OKind::If);
        f_.link[o.last_branch] = i;
        for (std::size_t b : o.branches) f_.end[b] = i;
        open_.pop_back();
        break;
      }
      case OKind::While:
        if (!open_.empty() && ow(open_.back().at).kind == OKind::Do && ow(open_.back().at).label == ow(i).label) {
          ow(i).kind = OKind::DoWhile;
          f_.link[i] = open_.back().at;
          f_.end[open_.back().at] = i;
          open_.pop_back();
        } else {
          open_.push_back({i, i, {}});
        }
        break;
      case OKind::EndWhile: close_loop(i, OKind::While); break;
      case OKind::EndRepeat: close_loop(i, OKind::Repeat); break;
      case OKind::Do:
      case OKind::Repeat: open_.push_back({i, i, {}}); break;
      case OKind::Break:
      case OKind::Continue: f_.link[i] = loop_of(i); break;
      default: break;
    }
  }
  void close_loop(std::size_t i, OKind head) {
    Open& o = top(i, head);
    f_.end[o.at] = i;
    f_.link[i] = o.at;
    open_.pop_back();
  }

  NgcFile& f_;
  std::vector<Open> open_;
};

}  // namespace

std::unique_ptr<NgcFile> read_program_lines(const std::string& text, const std::string& path) {
  auto f = std::make_unique<NgcFile>();
  f->path = path;
  std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // UTF-8 byte order mark
  int percent = 0;
  while (start <= text.size()) {
    std::size_t nl = text.find('\n', start);
    if (nl == std::string::npos) nl = text.size();
    const std::string_view raw(text.data() + start, nl - start);
    start = nl + 1;
    if (nl == text.size() && raw.empty()) break;
    const auto first = raw.find_first_not_of(" \t\r");
    NormalisedLine line;
    std::string err;
    if (first != std::string_view::npos && raw[first] == '%') {
      if (++percent == 2) break;  // closing delimiter: the program ends here
    } else {
      try {
        line = normalise_line(raw);
      } catch (const ExprError& e) {
        err = e.what();
      }
    }
    f->lines.push_back(std::move(line));
    f->errors.push_back(std::move(err));
  }
  f->ow.assign(f->lines.size(), OWord{});
  f->link.assign(f->lines.size(), kNone);
  f->end.assign(f->lines.size(), kNone);
  return f;
}

std::unique_ptr<NgcFile> scan_program(const std::string& text, const std::string& path) {
  auto f = read_program_lines(text, path);
  for (std::size_t i = 0; i < f->lines.size(); ++i) f->ow[i] = parse_oword(f->lines[i].code);
  Matcher(*f).run();
  return f;
}

ControlFlow::ControlFlow(Params& params, const GcodeOptions& options, Executor exec)
    : params_(params), opt_(options), exec_(std::move(exec)), expr_(params) {}

const std::string& ControlFlow::file() const { return stack_.back().file->path; }
int ControlFlow::line() const {
  // Past the end (the program ran off its last line without M2): what fails then, e.g. the
  // move that cutter compensation still holds, is named at the last line, not one after it.
  const Activation& a = stack_.back();
  const std::size_t n = a.file->lines.size();
  return static_cast<int>(n > 0 ? std::min(a.pc, n - 1) : 0) + 1;
}
int ControlFlow::main_line() const {
  for (auto it = stack_.rbegin(); it != stack_.rend(); ++it)
    if (it->file == files_.front().get()) return static_cast<int>(it->pc) + 1;
  return 0;
}

void ControlFlow::fail(const std::string& msg) const {
  if (stack_.empty()) throw ParseError(files_.empty() ? std::string() : files_.front()->path, 0, msg);
  throw ParseError(file(), line(), msg);
}

void ControlFlow::run(const std::string& text, const std::string& name) {
  files_.clear();
  files_.push_back(opt_.dialect == Dialect::Fanuc ? scan_fanuc(text, name, true) : scan_program(text, name));
  modal_ = {};
  search_dirs_.clear();
  const std::filesystem::path dir = std::filesystem::path(name).parent_path();
  search_dirs_.push_back(dir.empty() ? std::string(".") : dir.string());
  for (const std::string& d : opt_.subroutine_path) search_dirs_.push_back(d);
  stack_.assign(1, activation(files_.front().get(), 0, ""));
  try {
    while (step()) {
    }
  } catch (const ExprError& e) {
    fail(e.what());
  }
}

bool ControlFlow::step() {
  Activation& a = stack_.back();
  const NgcFile& f = *a.file;
  if (a.pc >= f.lines.size()) {
    if (stack_.size() > 1) a.pc = f.lines.size() - 1;  // reported at the file's last line
    if (stack_.size() > 1) fail(f.fanuc ? "program O" + a.label + " ends without M99" : "end of file inside subroutine o" + a.label);
    return false;
  }
  if (opt_.max_blocks > 0 && ++executed_ > opt_.max_blocks)
    fail("more than " + std::to_string(opt_.max_blocks) + " blocks executed (endless loop?)");
  const std::size_t i = a.pc;
  if (!f.errors[i].empty()) fail(f.errors[i]);
  const OWord& o = f.ow[i];
  if (o.kind == OKind::None && o.label.empty()) {
    const bool ended = exec_(f.lines[i]);
    stack_.back().pc = i + 1;
    if (!ended && o.axis_words && modal_.on) after_block(i);
    return !ended;
  }
  if (o.block_first && exec_(f.lines[i])) return false;
  return oword(o);
}

double ControlFlow::condition(const OWord& o) {
  if (stack_.back().file->fanuc) {  // "[...]" at rest; what follows (GOTO, DO, THEN) is the scanner's
    std::size_t p = o.rest;
    const double v = expr_.bracketed(o.words, p);
    return is_vacant(v) ? 0.0 : v;
  }
  const std::string& code = stack_.back().file->lines[stack_.back().pc].code;
  std::size_t p = o.rest;
  if (p >= code.size()) fail(owtext(o) + " needs an expression in [ ]");
  const double v = expr_.bracketed(code, p);
  if (p != code.size()) fail("unexpected '" + code.substr(p) + "' after " + owtext(o));
  return v;
}

void ControlFlow::branch_false(std::size_t i) {
  Activation& a = stack_.back();
  std::size_t j = a.file->link[i];
  while (a.file->ow[j].kind == OKind::ElseIf) {
    a.pc = j;  // messages name the elseif being evaluated
    if (condition(a.file->ow[j]) != 0.0) {
      a.pc = j + 1;
      return;
    }
    j = a.file->link[j];
  }
  a.pc = j + 1;  // else: its body; endif: after it
}

bool ControlFlow::oword(const OWord& o) {
  Activation& a = stack_.back();
  const NgcFile& f = *a.file;
  const std::size_t i = a.pc;
  switch (o.kind) {
    case OKind::None:
      fail("O-word 'O" + o.label + "' without a keyword (sub, call, if, while, do, repeat, ...)" +
           (o.label.find_first_not_of("0123456789") == std::string::npos
                ? "; a Fanuc program number needs [nc] dialect = \"fanuc\" or --dialect fanuc"
                : ""));
    case OKind::Sub:
      if (f.fanuc && stack_.size() > 1) fail("program O" + a.label + " runs into program O" + o.label + " (no M99)");
      a.pc = f.end[i] + 1;
      break;
    case OKind::EndSub:
    case OKind::Return:
      if (f.fanuc) return fanuc_return(o);
      leave(o);
      break;
    case OKind::Call:
      if (f.fanuc) fanuc_call(o);
      else call(o);
      break;
    case OKind::Goto: go_to(o); break;
    case OKind::Assign: assign(o); break;
    case OKind::ModalCall: modal_call(o); break;
    case OKind::EndModalCall:
      modal_.on = false;
      a.pc = i + 1;
      break;
    case OKind::If:
      if (condition(o) != 0.0) a.pc = i + 1;
      else branch_false(i);
      break;
    case OKind::ElseIf:
    case OKind::Else: a.pc = f.end[i] + 1; break;  // the branch before was taken
    case OKind::EndIf:
    case OKind::Do: a.pc = i + 1; break;
    case OKind::While: a.pc = condition(o) != 0.0 ? i + 1 : f.end[i] + 1; break;
    case OKind::EndWhile: a.pc = f.link[i]; break;
    case OKind::DoWhile: a.pc = condition(o) != 0.0 ? f.link[i] + 1 : i + 1; break;
    case OKind::Repeat: {
      const double n = std::nearbyint(condition(o));
      if (n >= 1.0) a.repeats[i] = static_cast<long>(std::min(n, 1e12)), a.pc = i + 1;
      else a.pc = f.end[i] + 1;
      break;
    }
    case OKind::EndRepeat: {
      const std::size_t r = f.link[i];
      if (--a.repeats[r] > 0) {
        a.pc = r + 1;
      } else {
        a.repeats.erase(r);
        a.pc = i + 1;
      }
      break;
    }
    case OKind::Break: {
      const std::size_t loop = f.link[i];
      a.repeats.erase(loop);
      a.pc = f.end[loop] + 1;
      break;
    }
    case OKind::Continue: {
      const std::size_t loop = f.link[i];
      a.pc = f.ow[loop].kind == OKind::While ? loop : f.end[loop];
      break;
    }
  }
  return true;
}

void ControlFlow::call(const OWord& o) {
  const std::string& code = stack_.back().file->lines[stack_.back().pc].code;
  std::vector<double> args;
  std::size_t p = o.rest;
  while (p < code.size()) {
    if (code[p] != '[') fail("unexpected '" + code.substr(p) + "' in " + owtext(o) + " (arguments are [expressions])");
    args.push_back(expr_.bracketed(code, p));
  }
  if (args.size() > static_cast<std::size_t>(kLocalParams)) fail(owtext(o) + " with more than 30 arguments");
  if (call_level() >= kMaxCallDepth) fail(owtext(o) + ": subroutine calls nested deeper than " + std::to_string(kMaxCallDepth));
  std::size_t at = 0;
  const NgcFile* file = find_sub(o.label, at);
  params_.push_frame(args);
  params_.set_named("_VALUE_RETURNED", 0.0);
  stack_.push_back(activation(file, at + 1, o.label));
}

void ControlFlow::call_now(const std::string& label) {
  if (call_level() >= kMaxCallDepth) fail("o" + label + ": subroutine calls nested deeper than " + std::to_string(kMaxCallDepth));
  std::size_t at = 0;
  const NgcFile* file = find_sub(label, at);
  const std::size_t depth = stack_.size();
  const std::size_t pc = stack_.back().pc;
  params_.push_frame({});
  params_.set_named("_VALUE_RETURNED", 0.0);
  stack_.push_back(activation(file, at + 1, label));
  while (stack_.size() > depth) {
    if (!step()) fail("the program ends inside subroutine o" + label);
  }
  stack_.back().pc = pc;  // leave() moved the caller on; the calling block is not done
}

void ControlFlow::leave(const OWord& o) {
  if (stack_.size() <= 1) fail(owtext(o) + " outside a subroutine");
  // LinuxCNC lets 'return' carry any label (retval.ngc: o1010 return inside o1000); endsub
  // labels are matched when the file is read.
  const std::string& code = stack_.back().file->lines[stack_.back().pc].code;
  std::size_t p = o.rest;
  double value = 0.0;
  const bool has_value = p < code.size();
  if (has_value) {
    value = expr_.bracketed(code, p);
    if (p != code.size()) fail("unexpected '" + code.substr(p) + "' after " + owtext(o));
  }
  if (on_leave_) on_leave_(call_level());
  params_.pop_frame();
  stack_.pop_back();
  stack_.back().pc += 1;
  if (has_value) params_.set_named("_VALUE", value);
  params_.set_named("_VALUE_RETURNED", has_value ? 1.0 : 0.0);
}

const NgcFile* ControlFlow::find_sub(const std::string& label, std::size_t& at) {
  const NgcFile* current = stack_.back().file;
  if (const auto it = current->subs.find(label); it != current->subs.end()) {
    at = it->second;
    return current;
  }
  for (const auto& f : files_) {
    if (const auto it = f->subs.find(label); it != f->subs.end()) {
      at = it->second;
      return f.get();
    }
  }
  const NgcFile* f = load_sub_file(label);
  at = f->subs.at(label);
  return f;
}

// LinuxCNC looks for "name.ngc" (lower case) on its SUBROUTINE_PATH for o<name> call.
const NgcFile* ControlFlow::load_sub_file(const std::string& label) {
  if (files_.front()->fanuc) return load_fanuc_file(label);
  std::string name = label;
  if (name.size() < 3 || name.front() != '<') fail("subroutine o" + label + " is not defined");
  name = name.substr(1, name.size() - 2);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::ostringstream dirs;
  for (const std::string& d : search_dirs_) {
    const std::filesystem::path p = std::filesystem::path(d) / (name + ".ngc");
    dirs << (dirs.tellp() > 0 ? ", " : "") << d;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec)) continue;
    files_.push_back(scan_program(read_text_file(p.string()), p.string()));
    if (files_.back()->subs.count(label) == 0)
      fail("subroutine file " + p.string() + " does not define o<" + name + "> sub");
    return files_.back().get();
  }
  fail("subroutine o<" + name + "> is not defined in the program and " + name + ".ngc is not in " + dirs.str() +
       " (program directory, [nc] subroutine_path)");
}

}  // namespace lbr::nc::detail

// ---- fanuc dialect statements (fanuc.hpp) ---------------------------------------------------

namespace lbr::nc::detail {

// M98 P L (shares the caller's locals) and G65 P L (locals #1..#33 from the arguments).
void ControlFlow::fanuc_call(const OWord& o) {
  const FanucCall c = read_fanuc_call(o.words, o.label != "M98", expr_);
  if (c.count <= 0) {
    stack_.back().pc += 1;
    return;
  }
  enter(c.label, c.args, o.label != "M98", c.count);
}

void ControlFlow::enter(const std::string& label, const std::vector<double>& args, bool frame, long count) {
  if (call_level() >= kMaxCallDepth)
    fail("program O" + label + ": calls nested deeper than " + std::to_string(kMaxCallDepth));
  std::size_t at = 0;
  const NgcFile* file = find_sub(label, at);
  if (frame) params_.push_frame(args);
  Activation act = activation(file, at + 1, label);
  act.passes = count;
  act.entry = at + 1;
  act.args = args;
  act.frame = frame;
  stack_.push_back(std::move(act));
}

// M99 [P n]: the next pass of the call, or back to the caller (to its block N n with P).
// In the main program M99 ends it (docs/nc-frontend.md#fanuc-dialect).
bool ControlFlow::fanuc_return(const OWord& o) {
  const long target = o.words.empty() ? -1 : read_return_target(o.words, expr_);
  if (stack_.size() <= 1) return false;
  Activation& a = stack_.back();
  if (--a.passes > 0) {
    if (a.frame) {
      params_.pop_frame();
      params_.push_frame(a.args);
    }
    a.pc = a.entry;
    return true;
  }
  if (on_leave_) on_leave_(call_level());
  if (a.frame) params_.pop_frame();
  stack_.pop_back();
  if (target >= 0) jump_to_number(target, "M99 P" + std::to_string(target));
  else stack_.back().pc += 1;
  return true;
}

void ControlFlow::go_to(const OWord& o) {
  if (o.rest != kNone && condition(o) == 0.0) {
    stack_.back().pc += 1;
    return;
  }
  std::size_t p = o.target;
  const double v = expr_.value(o.words, p);
  if (p != o.words.size()) fail("unexpected '" + o.words.substr(p) + "' after GOTO");
  if (is_vacant(v) || v != std::floor(v) || v < 0 || v > 99999) fail("GOTO needs a sequence number 0..99999");
  jump_to_number(static_cast<long>(v), "GOTO " + std::to_string(static_cast<long>(v)));
}

// Fanuc searches the executing program (not the others in the file) for block N n.
void ControlFlow::jump_to_number(long n, const std::string& what) {
  Activation& a = stack_.back();
  const NgcFile& f = *a.file;
  const std::size_t owner = f.owner[a.pc];
  const auto [lo, hi] = f.numbers.equal_range(n);
  for (auto it = lo; it != hi; ++it) {
    if (f.owner[it->second] == owner) {
      a.pc = it->second;
      return;
    }
  }
  fail(what + ": no block N" + std::to_string(n) + " in " +
       (owner == kNone ? std::string("the main program") : "program O" + f.ow[owner].label));
}

// #i = expression, or IF [condition] THEN #i = expression. #3000 = n raises alarm 3000 + n
// with the block's comment as its message: the program is refused there.
void ControlFlow::assign(const OWord& o) {
  if (o.rest == kNone || condition(o) != 0.0) {
    std::size_t p = o.target;
    const ParamAssign pa = expr_.assignment(o.words, p);
    if (p != o.words.size()) fail("unexpected '" + o.words.substr(p) + "' after the assignment");
    if (pa.number == 3000) {
      const NormalisedLine& l = stack_.back().file->lines[stack_.back().pc];
      const double n = is_vacant(pa.value) ? 0.0 : std::clamp(std::floor(pa.value), -1e6, 1e6);
      fail("macro alarm " + std::to_string(3000 + static_cast<long>(n)) + " (#3000): " +
           (l.comments.empty() ? std::string("no message") : l.comments.front()));
    }
    params_.set_numbered(pa.number, pa.value);
  }
  stack_.back().pc += 1;
}

void ControlFlow::modal_call(const OWord& o) {
  const FanucCall c = read_fanuc_call(o.words, true, expr_);
  modal_ = {true, c.label, c.args, c.count, stack_.size()};
  stack_.back().pc += 1;
}

// After a block with axis words under G66: call the macro; the return goes to the next line.
void ControlFlow::after_block(std::size_t i) {
  if (stack_.size() != modal_.level || modal_.count <= 0) return;
  stack_.back().pc = i;
  enter(modal_.label, modal_.args, true, modal_.count);
}

const NgcFile* ControlFlow::load_fanuc_file(const std::string& label) {
  std::ostringstream dirs;
  const std::vector<std::string> names = fanuc_file_names(label);
  for (const std::string& d : search_dirs_) {
    dirs << (dirs.tellp() > 0 ? ", " : "") << d;
    for (const std::string& name : names) {
      const std::filesystem::path p = std::filesystem::path(d) / name;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(p, ec)) continue;
      files_.push_back(scan_fanuc(read_text_file(p.string()), p.string(), false));
      if (files_.back()->subs.count(label) == 0) fail("program file " + p.string() + " does not hold program O" + label);
      return files_.back().get();
    }
  }
  fail("program O" + label + " is not in this file, and no file " + names.front() + " or " + names[1] + " is in " +
       dirs.str() + " (program directory, [nc] subroutine_path)");
}

}  // namespace lbr::nc::detail
