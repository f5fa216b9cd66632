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

}  // namespace

Toolpath parse_rs274_canon(const std::string& canon, const std::string& name, const GcodeOptions& options) {
  PathBuilder b(name, options);
  double scale = 1.0;
  AxisVector g5x = options.work_offsets[0], g92{};
  Plane plane = Plane::XY;
  double feed = 0.0;
  const bool inverse = false;  // SET_FEED_RATE is always in length units per minute
  int selected = options.start_tool;
  PathControl path = PathControl::Blend;
  double path_p_mm = 0.0, path_q_mm = 0.0;
  int line = 0;
  std::istringstream in(canon);
  std::string raw;
  auto fail = [&](const std::string& m) { throw ParseError(name, line, "rs274: " + m); };
  auto need = [&](const std::vector<double>& v, std::size_t k, const std::string& cmd) {
    if (v.size() < k) fail("canonical command " + cmd + " has " + std::to_string(v.size()) + " numbers, expected " + std::to_string(k));
    for (double x : v)
      if (!std::isfinite(x) || std::abs(x) > 1e9) fail("canonical command " + cmd + " has a number out of range");
  };
  // Offsets change the program frame, not the machine position.
  auto reframe = [&](auto&& change) {
    const AxisVector m = b.to_machine(b.position());
    change();
    AxisVector o{};
    for (int a = 0; a < kAxes; ++a) o[a] = g5x[a] + g92[a];
    b.set_origin(o);
    b.set_position(b.from_machine(m));
  };
  auto axes = [&](const std::vector<double>& v, std::size_t first) {
    AxisVector p{};
    for (int a = 0; a < kAxes; ++a) p[a] = v[first + a] * (a <= Z ? scale : 1.0);
    return p;
  };
  // A motion that moves an axis the machine lacks is refused, as the built-in interpreter does.
  auto check_axes = [&](const AxisVector& p) {
    static const char* const kNames[kAxes] = {"X", "Y", "Z", "A", "B", "C"};
    const AxisVector& cur = b.position();
    for (int a = 0; a < kAxes; ++a)
      if (!machine_has_axis(options, a) && std::abs(p[a] - cur[a]) > 1e-9)
        fail(std::string("the program moves axis ") + kNames[a] + ", which the machine lacks (" +
             machine_axes(options) + ")");
    return p;
  };
  while (std::getline(in, raw)) {
    const CanonLine c = split_canon(raw);
    if (!c.ok) continue;
    if (c.line >= 0) line = c.line;
    const std::string& cmd = c.cmd;
    if (cmd == "USE_LENGTH_UNITS") {
      if (c.args.find("INCHES") != std::string::npos) scale = kInch;
      else if (c.args.find("CM") != std::string::npos) scale = 10.0;
      else scale = 1.0;
    } else if (cmd == "SET_G5X_OFFSET") {
      const auto v = numbers(c.args);
      need(v, 7, cmd);
      reframe([&] { g5x = axes(v, 1); });
    } else if (cmd == "SET_G92_OFFSET") {
      const auto v = numbers(c.args);
      need(v, 6, cmd);
      reframe([&] { g92 = axes(v, 0); });
    } else if (cmd == "SET_XY_ROTATION") {
      const auto v = numbers(c.args);
      need(v, 1, cmd);
      if (std::abs(v[0]) > 1e-12) fail("XY rotation (G10 L2 R) is not supported");
    } else if (cmd == "USE_TOOL_LENGTH_OFFSET") {
      const auto v = numbers(c.args);
      need(v, 3, cmd);
      if (std::abs(v[0]) > 1e-12 || std::abs(v[1]) > 1e-12) fail("tool offsets in X or Y are not supported");
      const AxisVector m = b.to_machine(b.position());
      b.set_tool_length_offset(v[2] * scale);
      b.set_position(b.from_machine(m));
    } else if (cmd == "STRAIGHT_TRAVERSE") {
      const auto v = numbers(c.args);
      need(v, 6, cmd);
      b.rapid(line, check_axes(axes(v, 0)));
    } else if (cmd == "STRAIGHT_FEED") {
      const auto v = numbers(c.args);
      need(v, 6, cmd);
      if (feed <= 0.0) fail("STRAIGHT_FEED with zero feed rate");
      b.feed(line, check_axes(axes(v, 0)), inverse ? feed : feed * scale, inverse);
    } else if (cmd == "ARC_FEED") {
      const auto v = numbers(c.args);
      need(v, 9, cmd);
      const detail::PlaneAxes ax = detail::plane_axes(plane);
      AxisVector end = b.position();
      end[ax.u] = v[0] * scale;
      end[ax.v] = v[1] * scale;
      end[ax.w] = v[5] * scale;
      end[A] = v[6], end[B] = v[7], end[C] = v[8];
      (void)check_axes(end);
      if (std::abs(v[4]) > 1000.0) fail("ARC_FEED with more than 1000 turns");
      const int rot = static_cast<int>(std::lround(v[4]));
      if (rot == 0) fail("ARC_FEED with rotation 0");
      if (feed <= 0.0) fail("ARC_FEED with zero feed rate");
      b.arc(line, plane, end, v[2] * scale, v[3] * scale, rot, inverse ? feed : feed * scale, inverse);
    } else if (cmd == "SET_FEED_RATE") {
      const auto v = numbers(c.args);
      need(v, 1, cmd);
      feed = v[0];
    } else if (cmd == "SET_FEED_MODE") {
      const auto v = numbers(c.args);
      need(v, 1, cmd);
      // rs274 turns inverse time (G93) into units/min rates itself; mode 1 is feed per revolution.
      if (std::lround(v.back()) != 0) fail("feed per revolution (G95) is not supported");
    } else if (cmd == "DWELL") {
      const auto v = numbers(c.args);
      need(v, 1, cmd);
      if (v[0] < 0.0) fail("DWELL with a negative time");
      b.dwell(line, v[0]);
    } else if (cmd == "SELECT_TOOL") {
      const auto v = numbers(c.args);
      need(v, 1, cmd);
      selected = static_cast<int>(std::lround(v[0]));
    } else if (cmd == "CHANGE_TOOL") {
      b.tool_change(line, selected);
    } else if (cmd == "CHANGE_TOOL_NUMBER") {  // M61 Q: this tool is in the spindle now
      const auto v = numbers(c.args);
      need(v, 1, cmd);
      selected = static_cast<int>(std::lround(v[0]));
      b.tool_change(line, selected);
    } else if (cmd == "SET_MOTION_CONTROL_MODE" || cmd == "SET_NAIVECAM_TOLERANCE") {
      // G61 / G61.1 / G64 P (CANON_CONTINUOUS, tolerance) and G64 Q, for the emulator's planner.
      const auto v = numbers(c.args);
      if (cmd == "SET_NAIVECAM_TOLERANCE") need(v, 1, cmd), path_q_mm = v[0] * scale;
      else if (c.args.find("CONTINUOUS") != std::string::npos) path = PathControl::Blend, path_p_mm = v.empty() ? 0.0 : v[0] * scale;
      else path = c.args.find("EXACT_PATH") != std::string::npos ? PathControl::ExactPath : PathControl::ExactStop;
      b.set_path_control(path, path_p_mm, path_q_mm);
    } else if (cmd == "SELECT_PLANE") {
      if (c.args.find("XZ") != std::string::npos) plane = Plane::ZX;
      else if (c.args.find("YZ") != std::string::npos) plane = Plane::YZ;
      else if (c.args.find("XY") != std::string::npos) plane = Plane::XY;
      else fail("plane " + c.args + " is not supported");
    } else if (cmd.starts_with("START_SPEED_FEED_SYNC")) {
      fail("spindle-synchronised motion (G33, G33.1, G76) is not supported: the tool path carries no spindle angle");
    } else if (cmd.find("PROBE") != std::string::npos || cmd == "RIGID_TAP" || cmd.find("NURBS") != std::string::npos ||
               cmd.find("SPLINE") != std::string::npos ||
               cmd.ends_with("_FEED") || cmd.ends_with("_TRAVERSE")) {
      fail("canonical command " + cmd + " is not supported");
    }
    // Everything else (comments, spindle, coolant, messages, program end, ...) moves nothing.
  }
  return b.take();
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

Toolpath run_rs274(const std::string& program_path, const GcodeOptions& options) {
  const std::string exe = find_rs274();
  if (exe.empty())
    throw std::runtime_error(
        "--interpreter rs274: the rs274 program (LinuxCNC's G-code interpreter, Debian package linuxcnc-uspace) "
        "is not on PATH; install it, or leave out --interpreter to use the built-in interpreter");
  const std::string text = read_text_file(program_path);

  // Number every program line (N<line>) so that rs274's canonical lines name source lines.
  std::ostringstream numbered;
  {
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
  }

  std::string tmpl = (std::filesystem::temp_directory_path() / "lbrsim-rs274-XXXXXX").string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (::mkdtemp(buf.data()) == nullptr) throw std::runtime_error("rs274: cannot create a temporary directory");
  const std::filesystem::path dir(buf.data());
  struct Cleanup {
    std::filesystem::path d;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove_all(d, ec);
    }
  } cleanup{dir};

  auto write = [&](const char* name, const std::string& content) {
    std::ofstream f(dir / name, std::ios::binary);
    f << content;
    if (!f) throw std::runtime_error("rs274: cannot write " + (dir / name).string());
  };
  // Lathes start in the profile's diameter/radius mode: standalone rs274 ignores the INI's
  // RS274NGC_STARTUP_CODE, so a G7/G8 block without a line number goes first (after a
  // leading '%').
  std::string prog = numbered.str();
  if (options.machine == MachineKind::Lathe || options.machine == MachineKind::LatheC) {
    const std::string mode = options.diameter_mode ? "G7\n" : "G8\n";
    const std::size_t first = prog.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && prog[first] == '%') prog.insert(prog.find('\n', first) + 1, mode);
    else prog.insert(0, mode);
  }
  write("program.ngc", prog);
  // Subroutines: the program's directory, then [nc] subroutine_path (as the built-in interpreter).
  // (A bare file name has an empty parent: the working directory.)
  const std::filesystem::path program_dir = std::filesystem::path(program_path).parent_path();
  std::string sub_path = std::filesystem::absolute(program_dir.empty() ? std::filesystem::path(".") : program_dir).string();
  for (const std::string& d : options.subroutine_path) sub_path += ":" + std::filesystem::absolute(d).string();
  std::string ini = "[RS274NGC]\nPARAMETER_FILE=rs274.var\nSUBROUTINE_PATH=" + sub_path + "\n";
  write("rs274.ini", ini);
  // Standalone rs274 works in inches internally: tool table and parameters are in inches.
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
  write("tool.tbl", tbl.str());
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
  write("rs274.var", var.str());

  // LinuxCNC's rs274 shares state between concurrent processes (seen here: "Bus error" when
  // two run at once), so runs are serialised machine-wide with flock(1) on one lock file.
  const std::string lock = (std::filesystem::temp_directory_path() / "lbrsim-rs274.lock").string();
  const std::string cmd = "cd " + shell_quote(dir.string()) + " && flock " + shell_quote(lock) + " timeout 120 " +
                          shell_quote(exe) + " -g -i rs274.ini -t tool.tbl -v rs274.var program.ngc < /dev/null 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("rs274: cannot start " + exe);
  std::string out;
  char chunk[4096];
  std::size_t got = 0;
  while ((got = std::fread(chunk, 1, sizeof chunk, p)) > 0) out.append(chunk, got);
  const int status = ::pclose(p);
  const int rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (rc != 0) {
    // rs274 prints the error, then the offending block (with our N<line>).
    // (print, ...) output comes before; the message is the line before the echoed block.
    // A block in a subroutine file carries no N<line>: the last canonical line's N is used.
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
    throw ParseError(program_path, line, "rs274: " + msg);
  }
  return parse_rs274_canon(out, program_path, options);
}

}  // namespace lbr::nc
