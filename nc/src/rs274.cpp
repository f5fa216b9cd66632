// LinuxCNC rs274 canonical output → Toolpath (docs/nc-frontend.md#rs274).
#include "nc/rs274.hpp"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <vector>

#include "path_builder.hpp"

namespace lbr::nc {

namespace {

using detail::PathBuilder;
using detail::Plane;
using detail::spindle_rpm;

constexpr double kInch = 25.4;

struct CanonLine {
  bool ok = false;
  int line = -1;  // -1: "N....." (no line number)
  std::string cmd, args;
};

// "   22 N7     STRAIGHT_TRAVERSE(0.0000, ...)"
CanonLine split_canon(const std::string& s) {
  CanonLine c;
  std::size_t i = 0;
  const std::size_t n = s.size();
  while (i < n && s[i] == ' ') ++i;
  const std::size_t d0 = i;
  while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
  if (i == d0 || i >= n || s[i] != ' ') return c;
  while (i < n && s[i] == ' ') ++i;
  if (i >= n || s[i] != 'N') return c;
  ++i;
  if (i < n && s[i] == '.') {
    while (i < n && s[i] == '.') ++i;
  } else {
    const std::size_t n0 = i;
    while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
    if (i == n0 || i - n0 > 9) return c;
    c.line = std::atoi(s.substr(n0, i - n0).c_str());
  }
  while (i < n && s[i] == ' ') ++i;
  const auto open = s.find('(', i);
  const auto close = s.rfind(')');
  if (open == std::string::npos || close == std::string::npos || close < open) return c;
  c.cmd = s.substr(i, open - i);
  for (char ch : c.cmd)
    if (!(std::isupper(static_cast<unsigned char>(ch)) || ch == '_' || std::isdigit(static_cast<unsigned char>(ch))))
      return c;
  c.args = s.substr(open + 1, close - open - 1);
  c.ok = !c.cmd.empty();
  return c;
}

std::vector<double> numbers(const std::string& args) {
  std::vector<double> v;
  const char* p = args.c_str();
  while (*p != '\0') {
    if (*p == ',' || *p == ' ') {
      ++p;
      continue;
    }
    char* end = nullptr;
    const double x = std::strtod(p, &end);
    if (end == p) break;
    v.push_back(x);
    p = end;
  }
  return v;
}

bool machine_has_axis(const GcodeOptions& o, int a) {
  switch (o.machine) {
    case MachineKind::Mill3: return a <= Z;
    case MachineKind::Mill5: return a <= Z || o.rotary[static_cast<std::size_t>(a - A)];
    case MachineKind::Lathe: return a == X || a == Z;
    case MachineKind::LatheC: return a != A && a != B;
  }
  return false;
}

std::string machine_axes(const GcodeOptions& o) {
  static const char* const kNames[kAxes] = {"X", "Y", "Z", "A", "B", "C"};
  std::string s;
  for (int a = 0; a < kAxes; ++a)
    if (machine_has_axis(o, a)) s += std::string(s.empty() ? "" : " ") + kNames[a];
  return "it has " + s;
}

// Standalone rs274 resynchronises its position after M6 from the last commanded program
// position, ignoring a G43 in the same block, so the next move without Z would bring the new
// tool's tip where the old one was. The real controller keeps the machine position (it reads
// it back), which is what both front ends model; splitting "T2 M6 G43 H2" into "T2 M6" and
// "G43 H2" (same line number) gives rs274 the same behaviour (docs/nc-frontend.md#frames).
std::string split_m6_g43(const std::string& line, const std::string& n_word) {
  static const std::regex m6(R"((^|[^0-9.])[Mm]\s*0*6(?![0-9.]))");
  static const std::regex g43(R"([Gg]\s*0*43(?![0-9.])(\s*[Hh]\s*[-+]?[0-9.]+)?)");
  std::string code = line;
  const auto semi = code.find_first_of(";(");
  const std::string head = code.substr(0, semi);
  std::smatch mg;
  if (!std::regex_search(head, m6) || !std::regex_search(head, mg, g43)) return line;
  std::string rest = head.substr(0, static_cast<std::size_t>(mg.position(0))) +
                     head.substr(static_cast<std::size_t>(mg.position(0) + mg.length(0)));
  return rest + (semi == std::string::npos ? "" : code.substr(semi)) + "\n" + n_word + " " + mg.str(0);
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The state of one pass over rs274's canonical output: the program frame, units, feed and
// spindle (for feed per revolution and synchronised motion), all converted by PathBuilder.
class CanonReader {
 public:
  CanonReader(const std::string& name, const GcodeOptions& options)
      : name_(name), opt_(options), b_(name, options), g5x_(options.work_offsets[0]), selected_(options.start_tool) {}

  Toolpath read(const std::string& canon) {
    std::istringstream in(canon);
    std::string raw;
    while (std::getline(in, raw)) {
      const CanonLine c = split_canon(raw);
      if (!c.ok) continue;
      if (c.line >= 0) line_ = c.line;
      // Everything not handled (comments, coolant, messages, program end, ...) moves nothing.
      if (!frame(c) && !motion(c) && !feed_and_spindle(c)) tools(c);
    }
    return b_.take();
  }

 private:
  [[noreturn]] void fail(const std::string& m) const { throw ParseError(name_, line_, "rs274: " + m); }
  // The numbers of a command (at least k); magnitudes above `limit` are refused.
  std::vector<double> args(const CanonLine& c, std::size_t k, double limit = 1e9) const {
    const std::vector<double> v = numbers(c.args);
    if (v.size() < k)
      fail("canonical command " + c.cmd + " has " + std::to_string(v.size()) + " numbers, expected " + std::to_string(k));
    for (double x : v)
      if (!std::isfinite(x) || std::abs(x) > limit) fail("canonical command " + c.cmd + " has a number out of range");
    return v;
  }
  AxisVector axes(const std::vector<double>& v, std::size_t first) const {
    AxisVector p{};
    for (int a = 0; a < kAxes; ++a) p[a] = v[first + a] * (a <= Z ? scale_ : 1.0);
    return p;
  }
  // A motion that moves an axis the machine lacks is refused, as the built-in interpreter does.
  const AxisVector& checked(const AxisVector& p) const {
    static const char* const kNames[kAxes] = {"X", "Y", "Z", "A", "B", "C"};
    const AxisVector& cur = b_.position();
    for (int a = 0; a < kAxes; ++a)
      if (!machine_has_axis(opt_, a) && std::abs(p[a] - cur[a]) > 1e-9)
        fail(std::string("the program moves axis ") + kNames[a] + ", which the machine lacks (" + machine_axes(opt_) + ")");
    return p;
  }
  // Offsets change the program frame, not the machine position.
  template <typename F>
  void reframe(F&& change) {
    const AxisVector m = b_.to_machine(b_.position());
    change();
    AxisVector o{};
    for (int a = 0; a < kAxes; ++a) o[a] = g5x_[a] + g92_[a];
    b_.set_origin(o);
    b_.set_position(b_.from_machine(m));
  }

  bool frame(const CanonLine& c) {
    const std::string& cmd = c.cmd;
    if (cmd == "USE_LENGTH_UNITS") {
      scale_ = c.args.find("INCHES") != std::string::npos ? kInch : c.args.find("CM") != std::string::npos ? 10.0 : 1.0;
    } else if (cmd == "SET_G5X_OFFSET") {
      const auto v = args(c, 7);
      reframe([&] { g5x_ = axes(v, 1); });
    } else if (cmd == "SET_G92_OFFSET") {
      const auto v = args(c, 6);
      reframe([&] { g92_ = axes(v, 0); });
    } else if (cmd == "SET_XY_ROTATION") {
      if (std::abs(args(c, 1)[0]) > 1e-12) fail("XY rotation (G10 L2 R) is not supported");
    } else if (cmd == "USE_TOOL_LENGTH_OFFSET") {
      const auto v = args(c, 3);
      if (std::abs(v[0]) > 1e-12 || std::abs(v[1]) > 1e-12) fail("tool offsets in X or Y are not supported");
      const AxisVector m = b_.to_machine(b_.position());
      b_.set_tool_length_offset(v[2] * scale_);
      b_.set_position(b_.from_machine(m));
    } else if (cmd == "SELECT_PLANE") {
      if (c.args.find("XZ") != std::string::npos) plane_ = Plane::ZX;
      else if (c.args.find("YZ") != std::string::npos) plane_ = Plane::YZ;
      else if (c.args.find("XY") != std::string::npos) plane_ = Plane::XY;
      else fail("plane " + c.args + " is not supported");
    } else if (cmd == "SET_MOTION_CONTROL_MODE" || cmd == "SET_NAIVECAM_TOLERANCE") {
      path_control(c);
    } else {
      return false;
    }
    return true;
  }

  // G61 / G61.1 / G64 P (CANON_CONTINUOUS, tolerance) and G64 Q, for the emulator's planner.
  void path_control(const CanonLine& c) {
    const auto v = numbers(c.args);
    if (c.cmd == "SET_NAIVECAM_TOLERANCE") {
      path_q_mm_ = args(c, 1)[0] * scale_;
    } else if (c.args.find("CONTINUOUS") != std::string::npos) {
      path_ = PathControl::Blend;
      path_p_mm_ = v.empty() ? 0.0 : v[0] * scale_;
    } else {
      path_ = c.args.find("EXACT_PATH") != std::string::npos ? PathControl::ExactPath : PathControl::ExactStop;
    }
    b_.set_path_control(path_, path_p_mm_, path_q_mm_);
  }

  // Feed rate [mm/min] of a STRAIGHT_FEED or ARC_FEED starting here: synchronised (K x rpm),
  // per revolution (F x rpm) or per minute.
  double feed_now(const std::string& cmd) const {
    if (sync_k_ > 0.0 || per_rev_) {
      const double rpm = spindle_rpm(spindle_s_, css_, css_max_rpm_, scale_, b_.position()[X]);
      if (!(rpm > 0.0) || rpm > 1e9) fail(cmd + " per revolution or synchronised with the spindle needs a spindle speed S > 0 (at X0 in G96: D)");
      return (sync_k_ > 0.0 ? sync_k_ : feed_ * scale_) * rpm;
    }
    if (feed_ <= 0.0) fail(cmd + " with zero feed rate");
    return feed_ * scale_;
  }

  bool motion(const CanonLine& c) {
    const std::string& cmd = c.cmd;
    if (cmd == "STRAIGHT_TRAVERSE") {
      b_.rapid(line_, checked(axes(args(c, 6), 0)));
    } else if (cmd == "STRAIGHT_FEED") {
      const AxisVector end = checked(axes(args(c, 6), 0));
      b_.feed(line_, end, feed_now(cmd), false);  // SET_FEED_RATE is in units/min even for G93
    } else if (cmd == "RIGID_TAP") {  // G33.1: to the end point and back, synchronised
      const auto v = args(c, 3);
      const AxisVector start = b_.position();
      AxisVector end = start;
      for (int a = X; a <= Z; ++a) end[a] = v[static_cast<std::size_t>(a)] * scale_;
      b_.feed(line_, checked(end), feed_now(cmd), false);
      b_.feed(line_, start, feed_now(cmd), false);
    } else if (cmd == "ARC_FEED") {
      arc_feed(c);
    } else if (cmd == "DWELL") {
      const auto v = args(c, 1);
      if (v[0] < 0.0) fail("DWELL with a negative time");
      b_.dwell(line_, v[0]);
    } else if (cmd.find("PROBE") != std::string::npos || cmd.find("NURBS") != std::string::npos ||
               cmd.find("SPLINE") != std::string::npos || cmd.ends_with("_FEED") || cmd.ends_with("_TRAVERSE")) {
      fail("canonical command " + cmd + " is not supported");
    } else {
      return false;
    }
    return true;
  }

  void arc_feed(const CanonLine& c) {
    const auto v = args(c, 9);
    const detail::PlaneAxes ax = detail::plane_axes(plane_);
    AxisVector end = b_.position();
    end[ax.u] = v[0] * scale_;
    end[ax.v] = v[1] * scale_;
    end[ax.w] = v[5] * scale_;
    end[A] = v[6], end[B] = v[7], end[C] = v[8];
    (void)checked(end);
    if (std::abs(v[4]) > 1000.0) fail("ARC_FEED with more than 1000 turns");
    const int rot = static_cast<int>(std::lround(v[4]));
    if (rot == 0) fail("ARC_FEED with rotation 0");
    b_.arc(line_, plane_, end, v[2] * scale_, v[3] * scale_, rot, feed_now("ARC_FEED"), false);
  }

  bool feed_and_spindle(const CanonLine& c) {
    const std::string& cmd = c.cmd;
    if (cmd == "SET_FEED_RATE") {
      feed_ = args(c, 1)[0];
    } else if (cmd == "SET_FEED_MODE") {
      // rs274 turns inverse time (G93) into units/min rates itself; mode 1 is per revolution.
      per_rev_ = std::lround(args(c, 1).back()) == 1;
    } else if (cmd == "SET_SPINDLE_SPEED") {
      spindle_s_ = args(c, 2)[1];
      b_.set_spindle(spindle_, spindle_s_);
    } else if (cmd == "START_SPINDLE_CLOCKWISE" || cmd == "START_SPINDLE_COUNTERCLOCKWISE" || cmd == "STOP_SPINDLE_TURNING") {
      spindle_ = cmd == "STOP_SPINDLE_TURNING" ? Spindle::Off : cmd == "START_SPINDLE_CLOCKWISE" ? Spindle::Cw : Spindle::Ccw;
      b_.set_spindle(spindle_, spindle_s_);
    } else if (cmd == "SET_SPINDLE_MODE") {  // (spindle max): max > 0 is G96 with that cap (1e30: none)
      const double max = args(c, 2, 1e31)[1];
      css_ = max > 0.0;
      css_max_rpm_ = max >= 1e29 ? 0.0 : max;
    } else if (cmd == "START_SPEED_FEED_SYNC") {  // G33, G33.1, G76: (K [units/rev], velocity mode)
      sync_k_ = args(c, 1)[0] * scale_;
      if (!(sync_k_ > 0.0)) fail("START_SPEED_FEED_SYNC with K <= 0");
    } else if (cmd == "STOP_SPEED_FEED_SYNCH") {
      sync_k_ = 0.0;
    } else {
      return false;
    }
    return true;
  }

  void tools(const CanonLine& c) {
    const std::string& cmd = c.cmd;
    if (cmd == "SELECT_TOOL") {
      selected_ = static_cast<int>(std::lround(args(c, 1)[0]));
    } else if (cmd == "CHANGE_TOOL") {
      b_.tool_change(line_, selected_);
    } else if (cmd == "CHANGE_TOOL_NUMBER") {  // M61 Q: this tool is in the spindle now
      selected_ = static_cast<int>(std::lround(args(c, 1)[0]));
      b_.tool_change(line_, selected_);
    }
  }

  const std::string& name_;
  const GcodeOptions& opt_;
  PathBuilder b_;
  double scale_ = 1.0;
  AxisVector g5x_, g92_{};
  Plane plane_ = Plane::XY;
  double feed_ = 0.0;
  bool per_rev_ = false;
  double spindle_s_ = 0.0, css_max_rpm_ = 0.0, sync_k_ = 0.0;  // S [rpm or surface speed], G96 cap, K [mm/rev]
  bool css_ = false;
  Spindle spindle_ = Spindle::Off;  // M5 at start, as LinuxCNC powers up
  int selected_ = 0;
  PathControl path_ = PathControl::Blend;
  double path_p_mm_ = 0.0, path_q_mm_ = 0.0;
  int line_ = 0;
};

}  // namespace

Toolpath parse_rs274_canon(const std::string& canon, const std::string& name, const GcodeOptions& options) {
  return CanonReader(name, options).read(canon);
}

std::string find_rs274() {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return "";
  std::stringstream in(path);
  std::string dir;
  while (std::getline(in, dir, ':')) {
    if (dir.empty()) continue;
    const std::string f = dir + "/rs274";
    if (::access(f.c_str(), X_OK) == 0) return f;
  }
  return "";
}

namespace {

// The program with every line numbered N<line> so that rs274's canonical lines name source
// lines; lathes start with the profile's G7/G8 (standalone rs274 ignores the INI's
// RS274NGC_STARTUP_CODE), after a leading '%'.
std::string numbered_program(const std::string& text, const GcodeOptions& options) {
  std::ostringstream numbered;
  std::istringstream in(text);
  std::string l;
  int k = 0;
  while (std::getline(in, l)) {
    ++k;
    if (!l.empty() && l.back() == '\r') l.pop_back();
    std::size_t i = l.find_first_not_of(" \t");
    if (i == std::string::npos || l[i] == '%') {
      numbered << l << '\n';
      continue;
    }
    std::string prefix;
    if (l[i] == '/') prefix = "/", ++i;
    std::size_t j = i;
    if (j < l.size() && (l[j] == 'N' || l[j] == 'n')) {  // drop an existing line number
      std::size_t e = j + 1;
      while (e < l.size() && std::isdigit(static_cast<unsigned char>(l[e]))) ++e;
      if (e > j + 1) i = e;
    }
    const std::string n_word = "N" + std::to_string(k);
    numbered << prefix << n_word << ' ' << split_m6_g43(l.substr(i), n_word) << '\n';
  }
  std::string prog = numbered.str();
  if (options.machine == MachineKind::Lathe || options.machine == MachineKind::LatheC) {
    const std::string mode = options.diameter_mode ? "G7\n" : "G8\n";
    const std::size_t first = prog.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && prog[first] == '%') prog.insert(prog.find('\n', first) + 1, mode);
    else prog.insert(0, mode);
  }
  return prog;
}

// Standalone rs274 works in inches internally: tool table and parameters are in inches.
std::string tool_table(const GcodeOptions& options) {
  std::ostringstream tbl;
  tbl.precision(12);
  int pocket = 1;
  std::map<int, std::pair<double, double>> tools;  // number -> (length, diameter) [mm]
  for (const auto& [t, len] : options.tool_lengths) tools[t].first = len;
  for (const auto& [t, d] : options.tool_diameters) tools[t].second = d;
  for (const auto& [t, ld] : tools) {
    if (t <= 0) continue;
    tbl << 'T' << t << " P" << pocket++ << std::fixed << " Z" << ld.first / kInch << " D" << ld.second / kInch << " ;\n";
  }
  return tbl.str();
}

std::string parameter_file(const GcodeOptions& options) {
  std::ostringstream var;
  var.precision(12);
  var << std::fixed;
  auto put_axes = [&](int first, const AxisVector& v) {
    for (int a = 0; a < kAxes; ++a) var << first + a << '\t' << (a <= Z ? v[a] / kInch : v[a]) << '\n';
  };
  put_axes(5161, options.g28_home);
  put_axes(5181, options.g30_home);
  var << 5220 << '\t' << 1.0 << '\n';
  for (int k = 0; k < 9; ++k) put_axes(5221 + 20 * k, options.work_offsets[static_cast<std::size_t>(k)]);
  return var.str();
}

// Subroutines: the program's directory, then [nc] subroutine_path (as the built-in interpreter).
// (A bare file name has an empty parent: the working directory.)
std::string ini_file(const std::string& program_path, const GcodeOptions& options) {
  const std::filesystem::path program_dir = std::filesystem::path(program_path).parent_path();
  std::string sub_path = std::filesystem::absolute(program_dir.empty() ? std::filesystem::path(".") : program_dir).string();
  for (const std::string& d : options.subroutine_path) sub_path += ":" + std::filesystem::absolute(d).string();
  return "[RS274NGC]\nPARAMETER_FILE=rs274.var\nSUBROUTINE_PATH=" + sub_path + "\n";
}

// A temporary directory, removed with everything in it at the end of the scope.
struct TempDir {
  std::filesystem::path d;
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "lbrsim-rs274-XXXXXX").string();
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    if (::mkdtemp(buf.data()) == nullptr) throw std::runtime_error("rs274: cannot create a temporary directory");
    d = buf.data();
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(d, ec);
  }
  void write(const char* name, const std::string& content) const {
    std::ofstream f(d / name, std::ios::binary);
    f << content;
    if (!f) throw std::runtime_error("rs274: cannot write " + (d / name).string());
  }
};

// Runs a shell command; returns its exit status and stdout.
int run_command(const std::string& cmd, const std::string& exe, std::string& out) {
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("rs274: cannot start " + exe);
  char chunk[4096];
  std::size_t got = 0;
  while ((got = std::fread(chunk, 1, sizeof chunk, p)) > 0) out.append(chunk, got);
  const int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// rs274 prints the error, then the offending block (with our N<line>). (print, ...) output
// comes before; the message is the line before the echoed block. A block in a subroutine file
// carries no N<line>: the last canonical line's N is used.
ParseError rs274_error(const std::string& out, int rc, const std::string& program_path) {
  std::istringstream in(out);
  std::string l, msg;
  std::vector<std::string> shown;
  int line = 0, last_canon = 0;
  while (std::getline(in, l)) {
    if (const CanonLine c = split_canon(l); c.ok) {
      if (c.line > 0) last_canon = c.line;
      continue;
    }
    if (l.starts_with("executing")) continue;
    if (l.size() > 1 && l[0] == 'N' && std::isdigit(static_cast<unsigned char>(l[1])) && !shown.empty()) {
      line = static_cast<int>(std::min(std::strtol(l.c_str() + 1, nullptr, 10), 1000000000L));
      break;
    }
    shown.push_back(l);
  }
  for (auto it = shown.rbegin(); it != shown.rend() && msg.empty(); ++it)
    if (it->find_first_not_of(" \t") != std::string::npos) msg = *it;
  if (line == 0) line = last_canon;
  for (std::size_t at = msg.find("program.ngc"); at != std::string::npos; at = msg.find("program.ngc", at + 1))
    msg.replace(at, std::string("program.ngc").size(), program_path);
  if (rc == 124) msg = "did not finish within 120 s";
  if (msg.empty()) msg = "failed with exit status " + std::to_string(rc);
  return ParseError(program_path, line, "rs274: " + msg);
}

}  // namespace

Toolpath run_rs274(const std::string& program_path, const GcodeOptions& options) {
  const std::string exe = find_rs274();
  if (exe.empty())
    throw std::runtime_error(
        "--interpreter rs274: the rs274 program (LinuxCNC's G-code interpreter, Debian package linuxcnc-uspace) "
        "is not on PATH; install it, or leave out --interpreter to use the built-in interpreter");
  const TempDir dir;
  dir.write("program.ngc", numbered_program(read_text_file(program_path), options));
  dir.write("rs274.ini", ini_file(program_path, options));
  dir.write("tool.tbl", tool_table(options));
  dir.write("rs274.var", parameter_file(options));
  // LinuxCNC's rs274 shares state between concurrent processes (seen here: "Bus error" when
  // two run at once), so runs are serialised machine-wide with flock(1) on one lock file.
  const std::string lock = (std::filesystem::temp_directory_path() / "lbrsim-rs274.lock").string();
  const std::string cmd = "cd " + shell_quote(dir.d.string()) + " && flock " + shell_quote(lock) + " timeout 120 " +
                          shell_quote(exe) + " -g -i rs274.ini -t tool.tbl -v rs274.var program.ngc < /dev/null 2>&1";
  std::string out;
  const int rc = run_command(cmd, exe, out);
  if (rc != 0) throw rs274_error(out, rc, program_path);
  return parse_rs274_canon(out, program_path, options);
}

}  // namespace lbr::nc
