// The built-in G-code interpreter. Coverage, frames and error messages: docs/nc-frontend.md.
//
// Each line is parsed into a block of words, then executed in the RS274/NGC order of
// execution (feed mode, F, S, T, M6, spindle, dwell, planes, units, tool length, work
// offsets, distance modes, G10/G28/G30/G53, motion, stops). Motion goes through the shared
// PathBuilder, which also serves the rs274 canonical stream, so both front ends convert
// coordinates identically.
#include "nc/gcode.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "cutter_comp.hpp"
#include "fanuc.hpp"
#include "lathe_profile.hpp"
#include "ngc_control.hpp"
#include "ngc_expr.hpp"
#include "path_builder.hpp"

namespace lbr::nc {

std::string read_text_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ParseError(path, 0, "cannot open file");
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

namespace {

using detail::PathBuilder;
using detail::Plane;

constexpr double kInch = 25.4;
constexpr double kMaxAbsValue = 1e9;  // larger numbers are rejected (keeps arithmetic finite)
constexpr long kMaxPecks = 100000;
constexpr long kMaxRepeats = 10000;
// LinuxCNC's peck clearances (interp_cycles.cc): 0.010 inch, in mm.
constexpr double kG83RapidDelta = 0.010 * kInch;
constexpr double kG73Retract = 0.010 * kInch;

constexpr const char* kUseRs274 = "; use --interpreter rs274";

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

struct Word {
  char letter = 0;
  double value = 0.0;
  std::string text;  // as written, e.g. "G1", "X-2.5"
};

struct Block {
  std::vector<Word> g, m;
  std::array<bool, 26> has{};
  std::array<double, 26> val{};
  std::array<std::string, 26> text;
  std::array<bool, 26> used{};
  // Polar coordinates: @ distance, ^ angle [deg] from the XY origin (LinuxCNC).
  bool has_at = false, has_caret = false, used_polar = false;
  double at = 0.0, caret = 0.0;
  std::string polar_text;  // "@..." and/or "^..." as written
  bool empty() const {
    if (!g.empty() || !m.empty() || has_at || has_caret) return false;
    for (bool h : has)
      if (h) return false;
    return true;
  }
};

int idx(char c) { return c - 'A'; }

// One named system parameter's value (any arithmetic state converted to double).
struct SysParam {
  const char* name;
  double value;
  template <typename T>
  SysParam(const char* n, T v) : name(n), value(static_cast<double>(v)) {}
};

class Interpreter {
 public:
  Interpreter(const std::string& name, const GcodeOptions& o)
      : name_(name), opt_(o), b_(name, o), expr_(params_),
        flow_(params_, o, [this](const detail::NormalisedLine& l) { return execute_line(l); }),
        offsets_(o.work_offsets), g28_(o.g28_home), g30_(o.g30_home) {
    selected_tool_ = o.start_tool;
    params_.numbered_hook = [this](int n, double& v) { return system_numbered(n, v); };
    if (fanuc_) {  // Fanuc variables; its system variables read the same state (fanuc.hpp)
      params_.use_fanuc_variables();
      params_.numbered_hook = [this](int n, double& v) {
        const int m = detail::fanuc_system_variable(n);
        return m != 0 && system_numbered(m, v);
      };
    }
    params_.named_hook = [this](const std::string& n, double& v) { return system_named(n, v); };
    flow_.on_leave([this](int level) { leave_level(level); });
  }

  Toolpath run(const std::string& text) {
    flow_.run(text, name_);
    if (comp_.active()) (void)comp_.off();
    return b_.take();
  }

 private:
  // The rs274 hint does not apply to the fanuc dialect, which rs274 cannot read.
  [[noreturn]] void fail(const std::string& msg) const {
    const std::size_t hint = fanuc_ ? msg.find(kUseRs274) : std::string::npos;
    flow_.fail(hint == std::string::npos ? msg : msg.substr(0, hint) + msg.substr(hint + std::string(kUseRs274).size()));
  }

  // One line that is not an O-word line: parameter settings take effect after the whole line
  // has been read (RS274/NGC), then the block executes. Returns true at the program's end.
  bool execute_line(const detail::NormalisedLine& l) {
    line_ = flow_.main_line();
    pending_.clear();
    Block blk = parse(l.code);
    for (const detail::ParamAssign& a : pending_) {
      if (a.number > 0) params_.set_numbered(a.number, a.value);
      else params_.set_named(a.name, a.value);
    }
    if (blk.empty()) return false;
    execute(blk);
    return ended_;
  }

  // Program position of the controlled point (with cutter compensation, the programmed one).
  AxisVector pos() const { return comp_.active() ? comp_.programmed() : b_.position(); }

  // ---- system parameters (read-only, computed when read; LinuxCNC's numbering and names) ----
  double units(double mm) const { return mm / scale_; }
  bool system_numbered(int n, double& v) const {
    const AxisVector p = pos();
    auto axis = [&](const AxisVector& a, int k) { return k < kAxes ? (k <= Z ? units(a[k]) : a[k]) : 0.0; };
    if (n >= 5161 && n <= 5169) v = axis(g28_, n - 5161);
    else if (n >= 5181 && n <= 5189) v = axis(g30_, n - 5181);
    else if (n >= 5211 && n <= 5219) v = axis(g92_, n - 5211);
    else if (n == 5210) v = g92_on_ ? 1.0 : 0.0;
    else if (n == 5220) v = wcs_ + 1;
    else if (n >= 5221 && n <= 5400 - 1 && (n - 5221) % 20 < 9) v = axis(offsets_[static_cast<std::size_t>((n - 5221) / 20)], (n - 5221) % 20);
    else if (n == 5400) v = b_.tool();
    else if (n == 5403) v = units(b_.tool_length_offset());
    else if (n >= 5401 && n <= 5409) v = 0.0;
    else if (n == 5410) v = units(tool_diameter(b_.tool()));
    else if (n >= 5420 && n <= 5428) v = axis(p, n - 5420);
    else return false;
    return true;
  }
  double tool_diameter(int t) const {
    const auto it = opt_.tool_diameters.find(t);
    return it == opt_.tool_diameters.end() ? 0.0 : it->second;
  }
  bool system_named(const std::string& n, double& v) const {
    if (n.empty() || n[0] != '_') return false;
    const AxisVector p = pos();
    static const char* const kAxisNames[] = {"_X", "_Y", "_Z", "_A", "_B", "_C"};
    for (int a = 0; a < kAxes; ++a)
      if (n == kAxisNames[a]) return v = a <= Z ? units(p[a]) : p[a], true;
    if (n == "_U" || n == "_V" || n == "_W") return v = 0.0, true;
    const SysParam table[] = {
        {"_VMAJOR", 2.0}, {"_VMINOR", 9.0}, {"_LINE", flow_.line()}, {"_MOTION_MODE", motion_ < 0 ? 800 : motion_},
        {"_PLANE", plane_ == Plane::XY ? 170 : plane_ == Plane::ZX ? 180 : 190}, {"_CCOMP", comp_.active() ? comp_code_ : 400},
        {"_METRIC", scale_ == 1.0}, {"_IMPERIAL", scale_ != 1.0}, {"_ABSOLUTE", absolute_}, {"_INCREMENTAL", !absolute_},
        {"_INVERSE_TIME", inverse_time_}, {"_UNITS_PER_MINUTE", !inverse_time_}, {"_UNITS_PER_REV", 0.0},
        {"_COORD_SYSTEM", wcs_ < 6 ? 540 + 10 * wcs_ : 591 + (wcs_ - 6)}, {"_TOOL_OFFSET", b_.tool_length_offset() != 0.0},
        {"_RETRACT_R_PLANE", !retract_to_initial_}, {"_RETRACT_OLD_Z", retract_to_initial_},
        {"_SPINDLE_RPM_MODE", 1.0}, {"_SPINDLE_CSS_MODE", 0.0}, {"_IJK_ABSOLUTE_MODE", arc_absolute_},
        {"_LATHE_DIAMETER_MODE", diameter_mode_}, {"_LATHE_RADIUS_MODE", !diameter_mode_},
        {"_SPINDLE_ON", spindle_ != 5}, {"_SPINDLE_CW", spindle_ == 3}, {"_MIST", coolant_ == 7}, {"_FLOOD", coolant_ == 8},
        {"_SPEED_OVERRIDE", 1.0}, {"_FEED_OVERRIDE", 1.0}, {"_ADAPTIVE_FEED", 0.0}, {"_FEED_HOLD", 0.0},
        {"_FEED", feed_}, {"_RPM", spindle_rpm_}, {"_CURRENT_TOOL", b_.tool()}, {"_CURRENT_POCKET", b_.tool()},
        {"_SELECTED_TOOL", selected_tool_}, {"_SELECTED_POCKET", selected_tool_}, {"_CALL_LEVEL", flow_.call_level()},
        {"_REMAP_LEVEL", 0.0}, {"_TASK", 0.0},
    };
    for (const auto& e : table)
      if (n == e.name) return v = e.value, true;
    return false;
  }

  // ---- parsing -------------------------------------------------------------------------
  // A word's value: a number as written (the common case, kept as text for messages), or a
  // parameter, expression or function (ngc_expr.hpp).
  double word_value(const std::string& s, std::size_t& i, char L) {
    const std::size_t n = s.size();
    const bool sign = i < n && (s[i] == '+' || s[i] == '-');
    if (detail::ExprReader::number_starts(s, i + (sign ? 1 : 0))) {
      if (sign) ++i;
      std::size_t digits = 0;
      while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
      if (i < n && s[i] == '.') {
        ++i;
        while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
      }
      return 0.0;  // the caller converts the text
    }
    const bool expr = i < n && (s[i] == '[' || s[i] == '#' || s[i] == '+' || s[i] == '-' || is_function_at(s, i));
    if (!expr) fail(std::string("word '") + L + "' has no number");
    return expr_.value(s, i);
  }
  static bool is_function_at(const std::string& s, std::size_t i) {
    static const char* const kFunctions[] = {"ABS[", "ACOS[", "ASIN[", "ATAN[", "COS[", "EXP[", "FIX[", "FUP[",
                                             "ROUND[", "LN[", "SIN[", "SQRT[", "TAN[", "EXISTS["};
    for (const char* f : kFunctions)
      if (s.compare(i, std::string(f).size(), f) == 0) return true;
    return false;
  }
  static std::string printable(char c) {
    if (std::isprint(static_cast<unsigned char>(c))) return std::string(1, c);
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
    return buf;
  }

  Block parse(const std::string& s) {
    Block blk;
    std::size_t i = 0;
    const std::size_t n = s.size();
    if (i < n && s[i] == '/') ++i;  // block delete switch is off: the block runs
    while (i < n) {
      const char c = s[i];
      if (c == '#') {
        pending_.push_back(expr_.assignment(s, i));
        continue;
      }
      if (!std::isalpha(static_cast<unsigned char>(c)) && c != '@' && c != '^')
        fail("unexpected character '" + printable(c) + "'");
      const char L = c;
      ++i;
      if (L == 'O') fail("O-word '" + s.substr(i - 1) + "' must begin the line");
      const std::size_t num_start = i;
      double v = word_value(s, i, L);
      const std::string written = s.substr(num_start, i - num_start);
      if (detail::is_vacant(v)) continue;  // fanuc: a word whose value is <vacant> is not given
      if (detail::ExprReader::number_starts(written, written[0] == '+' || written[0] == '-' ? 1 : 0) &&
          written.find_first_of("[#") == std::string::npos && !is_function_at(written, 0))
        v = std::strtod(written.c_str(), nullptr);
      Word w{L, v, std::string(1, L) + written};
      if (!std::isfinite(v) || std::abs(v) > kMaxAbsValue) fail("number out of range in '" + w.text + "'");
      add_word(blk, w);
    }
    return blk;
  }

  void add_word(Block& blk, const Word& w) {
    const char L = w.letter;
    switch (L) {
      case 'G': blk.g.push_back(w); break;
      case 'M': blk.m.push_back(w); break;
      case 'N': break;  // line number: no meaning to the motion
      case 'X': case 'Y': case 'Z': case 'A': case 'B': case 'C': case 'I': case 'J': case 'K':
      case 'R': case 'P': case 'Q': case 'L': case 'H': case 'F': case 'S': case 'T': case 'D': case 'E': {
        const int k = idx(L);
        if (blk.has[k]) fail("word '" + std::string(1, L) + "' given twice ('" + blk.text[k] + "', '" + w.text + "')");
        blk.has[k] = true;
        blk.val[k] = w.value;
        blk.text[k] = w.text;
        break;
      }
      case '@': case '^': {
        bool& h = L == '@' ? blk.has_at : blk.has_caret;
        if (h) fail("word '" + std::string(1, L) + "' given twice");
        h = true;
        (L == '@' ? blk.at : blk.caret) = w.value;
        blk.polar_text += (blk.polar_text.empty() ? "" : " ") + w.text;
        break;
      }
      case 'U': case 'V': case 'W': fail("unsupported word '" + w.text + "' (axes U, V, W are not supported)");
      default: fail("unsupported word '" + w.text + "'");
    }
  }

  // ---- word access -----------------------------------------------------------------------
  bool has(const Block& b, char L) const { return b.has[idx(L)]; }
  double raw(Block& b, char L) {
    b.used[idx(L)] = true;
    return b.val[idx(L)];
  }
  double len(Block& b, char L) { return raw(b, L) * scale_; }
  const std::string& text(const Block& b, char L) const { return b.text[idx(L)]; }
  int integer(Block& b, char L, int lo, int hi) {
    const double v = raw(b, L);
    if (v != std::floor(v) || v < lo || v > hi)
      fail("'" + text(b, L) + "': expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }

  static constexpr char kAxisLetters[kAxes] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
  bool axis_allowed(int a) const {
    switch (opt_.machine) {
      case MachineKind::Mill3: return a <= Z;
      case MachineKind::Mill5: return a <= Z || opt_.rotary[static_cast<std::size_t>(a - A)];
      case MachineKind::Lathe: return a == X || a == Z;
      case MachineKind::LatheC: return a == X || a == Y || a == Z || a == C;
    }
    return false;
  }
  const char* machine_name() const {
    switch (opt_.machine) {
      case MachineKind::Mill3: return "mill3 has X Y Z";
      case MachineKind::Mill5: return rotary_name();
      case MachineKind::Lathe: return "lathe has X Z";
      case MachineKind::LatheC: return "lathe-c has X Y Z C";
    }
    return "?";
  }
  const char* rotary_name() const {
    static const char* const kNames[8] = {"mill-rotary has X Y Z",       "mill-rotary has X Y Z A",
                                          "mill-rotary has X Y Z B",     "mill-rotary has X Y Z A B",
                                          "mill-rotary has X Y Z C",     "mill-rotary has X Y Z A C",
                                          "mill-rotary has X Y Z B C",   "mill-rotary has X Y Z A B C"};
    return kNames[(opt_.rotary[0] ? 1 : 0) + (opt_.rotary[1] ? 2 : 0) + (opt_.rotary[2] ? 4 : 0)];
  }
  bool any_axis(const Block& b) const {
    if (b.has_at || b.has_caret) return true;
    for (char L : kAxisLetters)
      if (has(b, L)) return true;
    return false;
  }
  // An axis word in the block's units (and lathe diameter mode for X) [mm, deg].
  double axis_value(Block& b, int a) {
    const char L = kAxisLetters[a];
    if (a >= A) return raw(b, L);
    double v = len(b, L);
    if (a == X && diameter_mode_) v *= 0.5;
    return v;
  }
  // End point of a move: program coordinates.
  AxisVector target(Block& b, bool machine_coords) {
    if ((b.has_at || b.has_caret) && machine_coords) fail("polar coordinates '" + b.polar_text + "' cannot be used with G53");
    if (machine_coords) {
      AxisVector m = b_.to_machine(b_.position());
      for (int a = 0; a < kAxes; ++a)
        if (has(b, kAxisLetters[a])) m[a] = axis_value(b, a);
      return b_.from_machine(m);
    }
    AxisVector t = pos();
    for (int a = 0; a < kAxes; ++a) {
      if (!has(b, kAxisLetters[a])) continue;
      const double v = axis_value(b, a);
      t[a] = absolute_ ? v : t[a] + v;
    }
    if (b.has_at || b.has_caret) {
      const auto xy = polar_xy(b, t[X], t[Y]);
      t[X] = xy[0], t[Y] = xy[1];
    }
    return t;
  }

  // X Y of polar words from the point (x, y), as LinuxCNC: in G90 @ is the distance from the
  // XY origin and ^ the angle from +X, counter-clockwise [deg] (a missing one keeps the
  // point's); in G91 both are added to the point's distance and angle.
  std::array<double, 2> polar_xy(Block& b, double x, double y) {
    if (has(b, 'X') || has(b, 'Y')) fail("polar coordinates '" + b.polar_text + "' cannot be combined with X or Y words");
    if (!axis_allowed(Y)) fail("polar coordinates '" + b.polar_text + "' need axes X and Y (machine kind " + machine_name() + ")");
    b.used_polar = true;
    double r = std::hypot(x, y), a = std::atan2(y, x);
    constexpr double kRad = std::numbers::pi / 180.0;
    if (absolute_) {
      if (b.has_at) r = b.at * scale_;
      if (b.has_caret) a = b.caret * kRad;
    } else {
      if (x == 0.0 && y == 0.0) fail("incremental polar coordinates '" + b.polar_text + "' are indeterminate at the origin");
      r += b.has_at ? b.at * scale_ : 0.0;
      a += b.has_caret ? b.caret * kRad : 0.0;
    }
    return {r * std::cos(a), r * std::sin(a)};
  }

  // ---- execution -------------------------------------------------------------------------
  static int code10(const Word& w) { return static_cast<int>(std::lround(w.value * 10.0)); }

  enum Group { kMotion, kPlane, kDistance, kArcDistance, kFeedMode, kUnits, kCutter, kLength, kRetract, kCoord,
               kPath, kLathe, kPolar, kSpindleMode, kNonModal, kGroups };
  int group_of(const Word& w) const {
    const int c = code10(w);
    if (std::abs(w.value * 10.0 - c) > 1e-6) return -1;
    switch (c) {
      case 0: case 10: case 20: case 30: case 330: case 331: case 760: case 800: case 810: case 820: case 830: case 730:
      case 700: case 710: case 711: case 712: case 720: case 721: case 722:
        return kMotion;
      case 170: case 180: case 190: return kPlane;
      case 900: case 910: return kDistance;
      case 901: case 911: return kArcDistance;
      case 930: case 940: case 950: return kFeedMode;
      case 960: case 970: return kSpindleMode;
      case 200: case 210: return kUnits;
      case 400: case 410: case 411: case 420: case 421: return kCutter;
      case 430: case 490: return kLength;
      case 980: case 990: return kRetract;
      case 540: case 550: case 560: case 570: case 580: case 590: case 591: case 592: case 593: return kCoord;
      case 610: case 611: case 640: return kPath;
      case 70: case 80: return kLathe;
      case 121: case 131: return kPolar;
      case 40: case 100: case 280: case 281: case 300: case 301: case 530: case 920: case 921: case 922: case 923:
        return kNonModal;
      default: return -1;
    }
  }
  std::string unsupported_g(const Word& w) const {
    const int c = code10(w);
    const char* why = "not supported by the built-in interpreter";
    if (c == 381 || c == 382 || c == 383 || c == 384) why = "probing";
    else if (c == 431) why = "dynamic tool length offset";
    else if (c == 840 || c == 850 || c == 860 || c == 870 || c == 880 || c == 890) why = "this cycle";
    return "unsupported word '" + w.text + "' (" + why + kUseRs274 + ")";
  }

  // The G- and M-codes of one block, sorted into their modal groups.
  struct Codes {
    std::array<const Word*, kGroups> g{};
    int dwell = 0, g10 = 0, home = 0, g53 = 0, g92 = 0;  // non-modal codes x 10 (home: 280, 281, 300, 301)
    const Word* nonmodal = nullptr;                      // G10, G28, G30, G53 or G92 (one per block)
    const Word* mstop = nullptr;
    const Word* mspindle = nullptr;
    const Word* m6 = nullptr;
    const Word* mcool = nullptr;
    const Word* m61 = nullptr;
    const Word* mio = nullptr;  // overrides, digital outputs: nothing to simulate
    const Word* mstate = nullptr;  // M70-M73: modal state save/restore
    bool f_in_block = false;
  };

  void execute(Block& b) {
    Codes k = group_codes(b);
    check_comp_allows(k);
    set_feed_and_speed(b, k);
    change_tools(b, k);
    if (k.mspindle != nullptr) spindle_ = static_cast<int>(k.mspindle->value);
    if (k.mcool != nullptr) coolant_ = static_cast<int>(k.mcool->value);
    if (k.dwell != 0) {
      if (!has(b, 'P') && !fanuc_) fail("'G4' needs P (dwell time [s])");
      const double p = fanuc_ ? fanuc_dwell_s(b) : raw(b, 'P');
      if (p < 0) fail("'" + text(b, 'P') + "': dwell time must be >= 0");
      if (comp_.active()) comp_.dwell(line_, p);
      else b_.dwell(line_, p);
    }
    set_modes(b, k);
    if (k.mstate != nullptr) modal_state(*k.mstate);
    // Axis words must exist on the machine (a G10 offset for a missing axis moves nothing; in a
    // G7x profile A and C are corner finishes).
    for (int a = 0; a < kAxes; ++a)
      if (has(b, kAxisLetters[a]) && !axis_allowed(a) && k.g10 == 0 && !(capture_ != nullptr && (a == 3 || a == 5)))
        fail("word '" + text(b, kAxisLetters[a]) + "' needs an axis the machine lacks (machine kind " + machine_name() + ")");
    move(b, k);
    check_all_words_used(b);
    if (k.mstop != nullptr) {
      const int c = static_cast<int>(k.mstop->value);
      if (c == 2 || c == 30) {
        if (comp_.active()) (void)comp_.off();
        ended_ = true;
      } else {
        ++pauses_;
      }  // M0/M1: program pause; no motion
    }
  }

  Codes group_codes(const Block& b) const {
    Codes k;
    std::vector<const Word*> nonmodal;
    for (const Word& w : b.g) {
      if (fanuc_ && fanuc_cancel(w)) continue;
      const int gr = group_of(w);
      if (gr < 0) fail(unsupported_g(w));
      if (gr == kNonModal) {
        nonmodal.push_back(&w);
        continue;
      }
      if (k.g[gr] != nullptr) fail("'" + k.g[gr]->text + "' and '" + w.text + "' are in the same modal group");
      k.g[gr] = &w;
    }
    for (const Word* w : nonmodal) {
      const int c = code10(*w);
      int* slot = c == 40 ? &k.dwell : c == 100 ? &k.g10 : c == 530 ? &k.g53 : c >= 920 ? &k.g92 : &k.home;
      if (*slot != 0 || (slot == &k.g10 && (k.home != 0 || k.g92 != 0)) ||
          (slot == &k.home && (k.g10 != 0 || k.g92 != 0)) || (slot == &k.g92 && (k.g10 != 0 || k.home != 0)))
        fail("'" + w->text + "' cannot be combined with another non-modal G-code in the block");
      *slot = c;
      if (c != 40) k.nonmodal = w;
    }
    for (const Word& w : b.m) {
      const int c = static_cast<int>(std::lround(w.value));
      if (w.value != std::floor(w.value)) fail("unsupported word '" + w.text + "'");
      const Word** slot = m_slot(k, w, c);
      if (*slot != nullptr && !(c == 7 || c == 8))
        fail("'" + (*slot)->text + "' and '" + w.text + "' are in the same modal group");
      *slot = &w;
    }
    return k;
  }

  const Word** m_slot(Codes& k, const Word& w, int c) const {
    switch (c) {
      case 0: case 1: case 2: case 30: return &k.mstop;
      case 3: case 4: case 5: return &k.mspindle;
      case 6: return &k.m6;
      case 7: case 8: case 9: return &k.mcool;
      case 61: return &k.m61;
      case 70: case 71: case 72: case 73: return &k.mstate;
      case 48: case 49: case 50: case 51: case 52: case 53: case 62: case 63: case 64: case 65: return &k.mio;
      default: break;
    }
    if (c >= 100 && c <= 199) fail("unsupported word '" + w.text + "' (user-defined M-code: runs a program on the controller)");
    if (c >= 200) fail("unsupported word '" + w.text + "' (machine-specific M-code or remap)");
    fail("unsupported word '" + w.text + "' (not supported by the built-in interpreter" + std::string(kUseRs274) + ")");
  }

  // 1. feed mode, F; 2. S with the spindle speed mode: G97 S [rpm], G96 S [m/min | ft/min] D [max rpm]
  void set_feed_and_speed(Block& b, Codes& k) {
    if (k.g[kFeedMode]) {
      inverse_time_ = code10(*k.g[kFeedMode]) == 930;
      per_rev_ = code10(*k.g[kFeedMode]) == 950;
    }
    if (has(b, 'F')) {
      feed_ = raw(b, 'F');
      if (feed_ < 0) fail("'" + text(b, 'F') + "': feed rate must be >= 0");
      k.f_in_block = true;
    }
    if (has(b, 'S')) {
      spindle_rpm_ = raw(b, 'S');
      if (spindle_rpm_ < 0) fail("'" + text(b, 'S') + "': spindle speed must be >= 0");
    }
    if (k.g[kSpindleMode]) {
      css_ = code10(*k.g[kSpindleMode]) == 960;
      if (css_ && has(b, 'D')) css_max_rpm_ = raw(b, 'D');
    }
  }

  // 3. T (select), 4. M6 (change), M61 Q (the tool now in the spindle); outputs
  void change_tools(Block& b, const Codes& k) {
    if (has(b, 'T')) selected_tool_ = integer(b, 'T', 0, 99999);
    if (k.m6 != nullptr) b_.tool_change(line_, selected_tool_);
    if (k.m61 != nullptr) {
      if (!has(b, 'Q')) fail("'M61' needs Q (the tool in the spindle)");
      selected_tool_ = integer(b, 'Q', 0, 99999);
      b_.tool_change(line_, selected_tool_);
    }
    if (k.mio != nullptr) {
      const int c = static_cast<int>(k.mio->value);
      if (c >= 62 && !has(b, 'P')) fail("'" + k.mio->text + "' needs P (output number)");
      if (has(b, 'P')) (void)raw(b, 'P');
    }
  }

  // 7. modal settings: plane, units, cutter compensation, polar, lathe mode, tool length,
  // work offset, path control, distance modes, retract mode.
  void set_modes(Block& b, const Codes& k) {
    if (k.g[kPlane]) {
      const int c = code10(*k.g[kPlane]);
      plane_ = c == 170 ? Plane::XY : c == 180 ? Plane::ZX : Plane::YZ;
    }
    if (k.g[kUnits]) scale_ = code10(*k.g[kUnits]) == 200 ? kInch : 1.0;
    if (k.g[kCutter]) set_cutter_comp(b, *k.g[kCutter]);
    if (k.g[kPolar]) {
      if (opt_.machine != MachineKind::LatheC)
        fail("'" + k.g[kPolar]->text + "' (polar interpolation) needs machine kind lathe-c");
      polar_ = code10(*k.g[kPolar]) == 121;
    }
    if (k.g[kLathe]) {
      // G8 (radius mode) is every mill's state; LinuxCNC accepts it anywhere.
      const bool lathe = opt_.machine == MachineKind::Lathe || opt_.machine == MachineKind::LatheC;
      if (!lathe && code10(*k.g[kLathe]) == 70)
        fail("'" + k.g[kLathe]->text + "' (lathe diameter mode) needs machine kind lathe");
      diameter_mode_ = code10(*k.g[kLathe]) == 70;
    }
    if (k.g[kLength]) set_tool_length(b, code10(*k.g[kLength]) == 430);
    if (k.g[kCoord]) {
      const int c = code10(*k.g[kCoord]);
      select_wcs(c <= 590 ? (c - 540) / 10 : 6 + (c - 591));
    }
    // kPath: G61/G61.1/G64 [P tolerance] [Q naive-cam tolerance] go on the segments; the
    // emulator's planner reads them (docs/nc-frontend.md#planner). As in LinuxCNC, G64 without
    // P blends without a tolerance and Q defaults to P.
    if (k.g[kPath]) {
      path_mode_ = code10(*k.g[kPath]);
      if (path_mode_ == 640) {
        path_tol_mm_ = has(b, 'P') ? len(b, 'P') : 0.0;
        path_q_tol_mm_ = has(b, 'Q') ? len(b, 'Q') : path_tol_mm_;
        if (path_tol_mm_ < 0.0 || path_q_tol_mm_ < 0.0) fail("'G64' tolerances P and Q must be >= 0");
      }
      const PathControl c = path_mode_ == 640 ? PathControl::Blend
                            : path_mode_ == 610 ? PathControl::ExactPath
                                                : PathControl::ExactStop;
      b_.set_path_control(c, path_tol_mm_, path_q_tol_mm_);
    }
    if (k.g[kDistance]) absolute_ = code10(*k.g[kDistance]) == 900;
    if (k.g[kArcDistance]) arc_absolute_ = code10(*k.g[kArcDistance]) == 901;
    if (k.g[kRetract]) retract_to_initial_ = code10(*k.g[kRetract]) == 980;
  }

  // ---- M70-M73: modal state save/restore, per call level, as LinuxCNC ----------------------
  // Saved: units, plane, distance modes, feed mode, F, S and its mode, spindle, coolant, lathe
  // diameter mode, path control, retract mode, the active work offset.
  struct ModalState {
    double scale = 1.0, feed = 0.0, rpm = 0.0, css_max = 0.0, path_tol = 0.0, path_q_tol = 0.0;
    bool absolute = true, arc_absolute = false, inverse = false, per_rev = false, css = false, diameter = false,
         retract_initial = false, auto_restore = false;
    int path_mode = 640, spindle = 5, coolant = 9, wcs = 0;
    Plane plane = Plane::XY;
  };

  void modal_state(const Word& w) {
    const int c = static_cast<int>(w.value);
    const int level = flow_.call_level();
    if (c == 70 || c == 73) {
      ModalState m{scale_, feed_, spindle_rpm_, css_max_rpm_, path_tol_mm_, path_q_tol_mm_, absolute_, arc_absolute_,
                   inverse_time_, per_rev_, css_, diameter_mode_, retract_to_initial_, c == 73, path_mode_, spindle_,
                   coolant_, wcs_, plane_};
      saved_states_[level] = m;
      return;
    }
    const auto it = saved_states_.find(level);
    if (it == saved_states_.end()) fail("'" + w.text + "': no modal state saved at this call level (M70 or M73 first)");
    if (c == 71) {
      saved_states_.erase(it);
      return;
    }
    restore(it->second);
  }

  void restore(const ModalState& m) {
    if (comp_.active() && (m.plane != plane_ || m.scale != scale_ || m.wcs != wcs_))
      fail("cannot restore the modal state (plane, units, work offset) with cutter radius compensation on (G40 first)");
    scale_ = m.scale, feed_ = m.feed, spindle_rpm_ = m.rpm, css_max_rpm_ = m.css_max;
    path_tol_mm_ = m.path_tol, path_q_tol_mm_ = m.path_q_tol, absolute_ = m.absolute, arc_absolute_ = m.arc_absolute;
    inverse_time_ = m.inverse, per_rev_ = m.per_rev, css_ = m.css, diameter_mode_ = m.diameter;
    retract_to_initial_ = m.retract_initial, path_mode_ = m.path_mode, spindle_ = m.spindle, coolant_ = m.coolant;
    plane_ = m.plane;
    if (m.wcs != wcs_) select_wcs(m.wcs);
  }

  // A subroutine returns: M73 state saved in it is restored; its saved states end with it.
  void leave_level(int level) {
    const auto it = saved_states_.find(level);
    if (it == saved_states_.end()) return;
    if (it->second.auto_restore) restore(it->second);
    saved_states_.erase(it);
  }

  // G40 (off), G41/G42 [D tool number] (left/right by the radius of tool D, default: the
  // loaded tool), G41.1/G42.1 D diameter (program units; negative swaps the side), as LinuxCNC.
  void set_cutter_comp(Block& b, const Word& w) {
    const int c = code10(w);
    if (c == 400) {
      if (comp_.active()) arc_after_g40_ = comp_.off();
      return;
    }
    comp_code_ = c;
    if (comp_.active()) fail("'" + w.text + "': cutter radius compensation is already on (G40 first)");
    int side = c == 410 || c == 411 ? 1 : -1;
    double radius = 0.0;
    if (c == 411 || c == 421) {
      if (!has(b, 'D')) fail("'" + w.text + "' needs D (tool diameter)");
      radius = 0.5 * len(b, 'D');
      if (radius < 0.0) side = -side, radius = -radius;
    } else if (has(b, 'D')) {
      const int t = integer(b, 'D', 0, 99999);
      if (t != 0 && opt_.tool_diameters.count(t) == 0)
        fail("'" + text(b, 'D') + "': tool " + std::to_string(t) + " has no diameter in the tool table");
      radius = 0.5 * tool_diameter(t);
    } else {
      radius = 0.5 * tool_diameter(b_.tool());
    }
    comp_.on(side, radius, plane_);
  }

  // While cutter compensation is on, LinuxCNC refuses what would move the frame or the tool
  // under the open move; so does the built-in interpreter.
  void check_comp_allows(const Codes& k) const {
    if (!comp_.active()) return;
    auto refuse = [&](const std::string& what) { fail(what + " with cutter radius compensation on (G40 first)"); };
    if (k.m6 != nullptr || k.m61 != nullptr) refuse("cannot change tools");
    if (k.g[kLength] != nullptr) refuse("cannot change the tool length offset");
    if (k.g[kPlane] != nullptr && k.g[kCutter] == nullptr) refuse("cannot change the plane");
    if (k.g[kUnits] != nullptr && k.g[kCutter] == nullptr) refuse("cannot change units");
  }
  void check_comp_allows_motion(const Codes& k) const {
    if (!comp_.active()) return;
    const Word* w = k.g10 != 0 || k.g92 != 0 || k.home != 0 || k.g53 != 0 || k.g[kCoord] != nullptr || k.g[kPolar] != nullptr
                        ? nonmodal_word(k)
                        : nullptr;
    if (w != nullptr) fail("'" + w->text + "' cannot be used with cutter radius compensation on (G40 first)");
  }
  const Word* nonmodal_word(const Codes& k) const {
    if (k.g[kCoord] != nullptr) return k.g[kCoord];
    if (k.g[kPolar] != nullptr) return k.g[kPolar];
    return k.nonmodal;
  }

  void set_tool_length(Block& b, bool on) {
    const AxisVector m = b_.to_machine(b_.position());
    if (on) {
      const int h = has(b, 'H') ? integer(b, 'H', 0, 99999) : b_.tool();
      b_.set_tool_length_offset(b_.tool_length(h));
    } else {
      b_.set_tool_length_offset(0.0);
    }
    b_.set_position(b_.from_machine(m));
  }

  // 8. G10, G28/G30, G53; 9. motion. While a G7x profile is recorded, A (fillet) and C
  // (chamfer) are corner finishes at the move's end, as LinuxCNC reads them there.
  void move(Block& b, const Codes& k) {
    if (capture_ == nullptr) return move_block(b, k);
    double radius = 0.0;
    bool chamfer = false;
    if (has(b, 'A') && has(b, 'C')) fail("'" + text(b, 'A') + "' and '" + text(b, 'C') + "': a corner takes a fillet or a chamfer");
    for (char L : {'A', 'C'}) {
      if (!has(b, L)) continue;
      radius = len(b, L), chamfer = L == 'C';
      if (!(radius > 0.0)) fail("'" + text(b, L) + "': a corner finish needs a size > 0");
      b.has[idx(L)] = false;
    }
    const std::size_t before = capture_->size();
    move_block(b, k);
    if (radius > 0.0 && capture_->size() > before) capture_->back().corner = radius, capture_->back().chamfer = chamfer;
  }

  void move_block(Block& b, const Codes& k) {
    if (k.g[kMotion] && is_lathe_profile_cycle(code10(*k.g[kMotion]))) {
      lathe_profile_cycle(b, code10(*k.g[kMotion]), k.f_in_block);
      return;
    }
    if (k.g[kMotion]) {
      const int c = code10(*k.g[kMotion]);
      if (c != motion_ && is_cycle(c)) cycle_sticky_ = {};
      if (!is_cycle(c)) cycle_series_ = false;
      motion_ = c;
      if (c == 800) motion_ = -1;
    }
    check_comp_allows_motion(k);
    const Word* gm = k.g[kMotion];
    if (k.g10 != 0) {
      do_g10(b);
    } else if (k.g92 != 0) {
      if (gm != nullptr && any_axis(b)) fail("'" + gm->text + "' and 'G92' both use the axis words");
      do_g92(b, k.g92);
    } else if (k.home != 0) {
      if (gm != nullptr && any_axis(b))
        fail("'" + gm->text + "' and 'G" + (k.home < 300 ? std::string("28") : std::string("30")) +
             (k.home % 10 ? ".1" : "") + "' both use the axis words");
      do_home(b, k.home);
    } else if (k.g53 != 0) {
      const int c = gm ? code10(*gm) : motion_;
      if (c != 0 && c != 10) fail("'G53' needs G0 or G1 in the block or in effect");
      if (!absolute_) fail("'G53' needs absolute distance mode (G90)");
      move_line(c, target(b, true), k.f_in_block);
    } else if (any_axis(b) || (gm != nullptr && (is_cycle(motion_) || motion_ == 20 || motion_ == 30))) {
      modal_motion(b, k.f_in_block);
    }
  }

  void modal_motion(Block& b, bool f_in_block) {
    if (comp_.active() && motion_ > 30)
      fail("'" + motion_name() + "' cannot be used with cutter radius compensation on (G40 first)");
    if (motion_ < 0) {
      for (char L : kAxisLetters)
        if (has(b, L)) fail("axis word '" + text(b, L) + "' given but no motion mode is in effect");
    }
    if (polar_) {
      if (motion_ != 0 && motion_ != 10) fail("only G0 and G1 are supported in polar interpolation (G12.1)");
      move_polar(b, f_in_block);
    } else if (motion_ == 0 || motion_ == 10) {
      move_line(motion_, target(b, false), f_in_block);
    } else if (motion_ == 20 || motion_ == 30) {
      move_arc(b, f_in_block);
    } else if (motion_ == 330 || motion_ == 331) {
      move_synchronised(b);
    } else if (motion_ == 760) {
      if (fanuc_) fail("'G76' (in the fanuc dialect the fine boring cycle) is not supported");
      threading_cycle(b);
    } else if (motion_ >= 0) {
      canned_cycle(b);
    }
  }

  std::string motion_name() const {
    const int c = motion_;
    return "G" + std::to_string(c / 10) + (c % 10 != 0 ? "." + std::to_string(c % 10) : std::string());
  }

  // Every word must have been used by something in the block.
  void check_all_words_used(Block& b) const {
    for (char L : {'X', 'Y', 'Z', 'A', 'B', 'C', 'F', 'S', 'T'}) b.used[idx(L)] = b.used[idx(L)] || has(b, L);
    if (has(b, 'D') && !b.used[idx('D')])
      fail("unused word '" + text(b, 'D') + "' (D is a tool number for G41/G42, a diameter for G41.1/G42.1, or the maximum speed for G96)");
    for (int k = 0; k < 26; ++k)
      if (b.has[k] && !b.used[k]) fail("unused word '" + b.text[k] + "' (no G-code in the block uses it)");
    if ((b.has_at || b.has_caret) && !b.used_polar)
      fail("unused polar coordinates '" + b.polar_text + "' (no motion in the block uses them)");
  }
  // ---- spindle-synchronised motion (G33, G33.1, G76) --------------------------------------
  // The tool path carries no spindle angle: a synchronised move is a feed move at
  // K [length/rev] x the spindle speed at its start (docs/nc-frontend.md#lathe).
  double sync_feed(const std::string& g, double k_mm_per_rev) const {
    const double rpm = spindle_rpm_now();
    if (!(rpm > 0.0)) fail("'" + g + "' needs a spindle speed S > 0 (spindle-synchronised motion)");
    return k_mm_per_rev * rpm;
  }

  // G33 K: a straight move synchronised with the spindle. G33.1 K: rigid tapping, to the end
  // point and back to the start at the same rate (the spindle reverses at the bottom).
  void move_synchronised(Block& b) {
    const std::string g = motion_ == 330 ? "G33" : "G33.1";
    if (!has(b, 'K')) fail("'" + g + "' needs K (distance per revolution)");
    const double k = len(b, 'K');
    if (!(k > 0.0)) fail("'" + g + "' needs K > 0 (distance per revolution)");
    const AxisVector start = b_.position();
    const AxisVector end = target(b, false);
    b_.feed(line_, end, sync_feed(g, k), false);
    if (motion_ == 331) b_.feed(line_, start, sync_feed(g, k), false);
  }

  // G76 threading cycle, as LinuxCNC: the start point is on the drive line; I is the thread
  // peak's offset from it (I < 0: external thread), J the first pass depth, K the full depth
  // (K > J), R the depth degression (pass n at depth J·n^(1/R)), Q the compound slide angle
  // [deg], H spring passes, E the taper length along Z and L which ends are tapered (1 entry,
  // 2 exit, 3 both). X words are radii in G8 and diameters in G7; I, J, K are halved in G7 too.
  struct Thread {
    double pitch = 0, peak = 0, first = 0, full = 0, degression = 1, tan_q = 0, taper = 0;
    int springs = 0, taper_ends = 0;
    double sx = 0, sz = 0, ez = 0, s = 1, dir = -1;  // drive line start, end Z, Z direction, depth direction
  };

  void threading_cycle(Block& b) {
    const Thread t = thread_words(b);
    const AxisVector start = b_.position();
    double depth = t.first;
    for (long n = 1; depth < t.full - 1e-9; depth = t.first * std::pow(static_cast<double>(++n), 1.0 / t.degression)) {
      if (n > kMaxPecks) fail("'G76': more than " + std::to_string(kMaxPecks) + " passes");
      threading_pass(t, depth);
    }
    for (int i = 0; i <= t.springs; ++i) threading_pass(t, t.full);
    AxisVector end = b_.position();
    end[X] = has(b, 'X') ? (absolute_ ? axis_value(b, X) : start[X] + axis_value(b, X)) : t.sx;
    end[Z] = t.ez;
    b_.rapid(line_, end);
  }

  Thread thread_words(Block& b) {
    for (char L : {'P', 'Z', 'I', 'J', 'K'})
      if (!has(b, L)) fail(std::string("'G76' needs ") + L + " (P pitch, Z end, I peak offset, J first depth, K full depth)");
    for (char L : {'Y', 'A', 'B', 'C'})
      if (has(b, L)) fail("word '" + text(b, L) + "' cannot be used with 'G76'");
    Thread t;
    const double radius = diameter_mode_ ? 0.5 : 1.0;
    t.pitch = len(b, 'P');
    t.peak = len(b, 'I') * radius;
    t.first = len(b, 'J') * radius;
    t.full = len(b, 'K') * radius;
    if (has(b, 'R')) t.degression = raw(b, 'R');
    if (has(b, 'Q')) t.tan_q = std::tan(raw(b, 'Q') * std::numbers::pi / 180.0);
    if (has(b, 'H')) t.springs = integer(b, 'H', 0, 1000);
    if (has(b, 'E')) t.taper = len(b, 'E');
    if (has(b, 'L')) t.taper_ends = integer(b, 'L', 0, 3);
    if (!(t.pitch > 0.0)) fail("'G76' needs P > 0 (thread pitch)");
    if (!(t.first > 0.0)) fail("'G76' needs J > 0 (first cut depth)");
    if (!(t.full > t.first)) fail("'G76': K (full thread depth) must be greater than J (first cut depth)");
    if (!(t.degression > 0.0)) fail("'G76' needs R > 0 (depth degression)");
    if (t.taper < 0.0) fail("'G76' needs E >= 0 (taper length)");
    const AxisVector p = b_.position();
    t.sx = p[X], t.sz = p[Z];
    const double z = has(b, 'Z') ? len(b, 'Z') : 0.0;
    t.ez = absolute_ ? z : p[Z] + z;
    if (std::abs(t.ez - t.sz) < 1e-9) fail("'G76' needs a Z end point different from the start");
    t.s = t.ez < t.sz ? -1.0 : 1.0;
    t.dir = t.peak > 0.0 ? 1.0 : -1.0;  // I > 0: internal thread, cuts towards +X
    return t;
  }

  // One pass at `depth`: rapid to the retract X beside the start, in to the cut (with the
  // entry taper as a synchronised move), along the thread (exit taper), rapid back out.
  void threading_pass(const Thread& t, double depth) {
    const double zoff = depth * t.tan_q;
    const double zs = t.sz + t.s * zoff, ze = t.ez - t.s * (t.full * t.tan_q - zoff);
    const double cut = t.sx + t.peak + t.dir * depth, crest = cut - t.dir * t.full;
    const double safe = t.sx - t.dir * (t.full - depth);
    const double taper_k = t.taper > 0.0 ? t.pitch * std::hypot(t.full, t.taper) / t.taper : t.pitch;
    auto at = [&](double x, double z) {
      AxisVector v = b_.position();
      v[X] = x, v[Z] = z;
      return v;
    };
    b_.rapid(line_, at(safe, zs));
    if ((t.taper_ends & 1) != 0 && t.taper > 0.0) {
      b_.feed(line_, at(crest, zs), sync_feed("G76", taper_k), false);
      b_.feed(line_, at(cut, zs + t.s * t.taper), sync_feed("G76", taper_k), false);
    } else {
      b_.rapid(line_, at(cut, zs));
    }
    if ((t.taper_ends & 2) != 0 && t.taper > 0.0) {
      b_.feed(line_, at(cut, ze - t.s * t.taper), sync_feed("G76", t.pitch), false);
      b_.feed(line_, at(crest, ze), sync_feed("G76", taper_k), false);
    } else {
      b_.feed(line_, at(cut, ze), sync_feed("G76", t.pitch), false);
    }
    b_.rapid(line_, at(safe, b_.position()[Z]));
  }

  static bool is_cycle(int c) { return c == 810 || c == 820 || c == 830 || c == 730; }

  // Fanuc safety blocks cancel modes the interpreter never enters: G15 (polar coordinates),
  // G50.1 (mirror image), G69 (rotation) and, on mills, G50 (scaling). Nothing to do.
  bool fanuc_cancel(const Word& w) const {
    const int c = code10(w);
    const bool mill = opt_.machine == MachineKind::Mill3 || opt_.machine == MachineKind::Mill5;
    return c == 150 || c == 501 || c == 690 || (c == 500 && mill);
  }

  // Fanuc G4: P [ms] or X [s]; the X word is the dwell's, not a move.
  double fanuc_dwell_s(Block& b) {
    if (has(b, 'P') == has(b, 'X')) fail("'G4' needs P (dwell time [ms]) or X (dwell time [s])");
    if (has(b, 'P')) return raw(b, 'P') * 0.001;
    const double s = raw(b, 'X');
    if (s < 0) fail("'" + text(b, 'X') + "': dwell time must be >= 0");
    b.has[idx('X')] = false;
    return s;
  }

  // The program frame: the selected work offset plus the G92 offset while it is applied.
  void select_wcs(int k) {
    const AxisVector m = b_.to_machine(b_.position());
    wcs_ = k;
    AxisVector o = offsets_[static_cast<std::size_t>(k)];
    if (g92_on_)
      for (int a = 0; a < kAxes; ++a) o[a] += g92_[a];
    b_.set_origin(o);
    b_.set_position(b_.from_machine(m));
  }

  // G92 (the current point gets the given coordinates), G92.1 (cancel, zero), G92.2 (cancel,
  // keep), G92.3 (apply the kept offset), as LinuxCNC.
  void do_g92(Block& b, int code) {
    if (code == 920) {
      if (!any_axis(b)) fail("'G92' needs at least one axis word");
      const AxisVector p = b_.position();
      const AxisVector old = g92_on_ ? g92_ : AxisVector{};
      for (int a = 0; a < kAxes; ++a)
        if (has(b, kAxisLetters[a])) g92_[a] = p[a] + old[a] - axis_value(b, a);
        else if (!g92_on_) g92_[a] = 0.0;
      g92_on_ = true;
    } else if (code == 921) {
      g92_ = {};
      g92_on_ = false;
    } else if (code == 922) {
      g92_on_ = false;
    } else {
      g92_on_ = true;
    }
    select_wcs(wcs_);
  }

  // G10 L2 (work offset = the values) and G10 L20 (work offset such that the current point
  // has the values).
  void do_g10(Block& b) {
    const double l = has(b, 'L') ? raw(b, 'L') : -1.0;
    if (l != 2.0 && l != 20.0)
      fail("'G10' needs L2 or L20 (work offsets); " + (has(b, 'L') ? "'" + text(b, 'L') + "'" : std::string("no L word")) +
           " is not supported");
    const std::string g = l == 2.0 ? "'G10 L2'" : "'G10 L20'";
    if (has(b, 'R')) fail("unsupported word '" + text(b, 'R') + "' (" + g + " rotation)");
    if (!has(b, 'P')) fail(g + " needs P0..P9 (coordinate system)");
    int p = integer(b, 'P', 0, 9);
    const int k = p == 0 ? wcs_ : p - 1;
    AxisVector& o = offsets_[static_cast<std::size_t>(k)];
    const AxisVector m = b_.to_machine(b_.position());
    for (int a = 0; a < kAxes; ++a) {
      if (!has(b, kAxisLetters[a])) continue;
      const double v = axis_value(b, a);
      if (l == 2.0) o[a] = v;
      else o[a] = m[a] - (a == Z ? b_.tool_length_offset() : 0.0) - (g92_on_ ? g92_[a] : 0.0) - v;
    }
    if (k == wcs_) select_wcs(k);
  }

  void do_home(Block& b, int code) {
    AxisVector& stored = code < 300 ? g28_ : g30_;
    if (code % 10 == 1) {  // G28.1 / G30.1: store the current machine position
      stored = b_.to_machine(b_.position());
      return;
    }
    const bool axes = any_axis(b);
    if (axes) b_.rapid(line_, target(b, false));
    AxisVector m = b_.to_machine(b_.position());
    for (int a = 0; a < kAxes; ++a)
      if (!axes || has(b, kAxisLetters[a])) m[a] = stored[a];
    b_.rapid(line_, b_.from_machine(m));
  }

  double feed_for_move(const std::string& g, bool f_in_block) const {
    if (inverse_time_) {
      if (!f_in_block) fail("'" + g + "' in inverse time mode (G93) needs an F word in the block");
      if (feed_ <= 0.0) fail("'" + g + "' in inverse time mode (G93) needs F > 0");
      return feed_;
    }
    if (feed_ <= 0.0) fail("'" + g + "' needs a feed rate: no F word > 0 given yet");
    if (per_rev_) {
      const double rpm = spindle_rpm_now();
      if (!(rpm > 0.0)) fail("'" + g + "' in feed per revolution (G95) needs a spindle speed S > 0");
      return feed_ * scale_ * rpm;
    }
    return feed_ * scale_;
  }

  // Spindle speed at the current point [rpm]: S in G97; in G96 the speed that gives the
  // surface speed S at the current radius |X| (capped by G96 D), as LinuxCNC computes it.
  double spindle_rpm_now() const {
    const double rpm = detail::spindle_rpm(spindle_rpm_, css_, css_max_rpm_, scale_, b_.position()[X]);
    if (rpm > 1e9) fail("'G96' at the spindle axis needs a maximum speed (G96 D)");
    return rpm;
  }

  void move_line(int c, const AxisVector& t, bool f_in_block) {
    arc_after_g40_ = false;
    if (capture_ != nullptr) {
      capture_point(t, c == 0);
      return;
    }
    if (comp_.active()) {
      comp_.line(line_, c == 0, t, c == 0 ? 0.0 : feed_for_move("G1", f_in_block), inverse_time_);
    } else if (c == 0) {
      b_.rapid(line_, t);
    } else {
      const double f = feed_for_move("G1", f_in_block);
      b_.feed(line_, t, f, inverse_time_);
    }
  }

  // G12.1 polar interpolation (lathe-c): X (a diameter in G7) and C are Cartesian coordinates
  // x, y [program units] of the tool centre in the face plane of the part, which turns with
  // C; the tool sits at polar angle φ = -C in the workpiece frame (docs/machine-kinds.md).
  // The straight Cartesian line becomes (X radius, C) steps whose linear interpolation stays
  // within tol/2 of it: angular steps of at most 2·sqrt(tol / r_max).
  void move_polar(Block& b, bool f_in_block) {
    if (has(b, 'Y')) fail("word '" + text(b, 'Y') + "' cannot be used in polar interpolation (G12.1)");
    const AxisVector p0 = b_.position();
    constexpr double kRad = 3.14159265358979323846 / 180.0;
    const double x0 = p0[X] * std::cos(-p0[C] * kRad), y0 = p0[X] * std::sin(-p0[C] * kRad);
    double xt = x0, yt = y0, zt = p0[Z];
    if (has(b, 'X')) xt = absolute_ ? axis_value(b, X) : x0 + axis_value(b, X);
    if (has(b, 'C')) yt = absolute_ ? len(b, 'C') : y0 + len(b, 'C');
    if (has(b, 'Z')) zt = absolute_ ? len(b, 'Z') : p0[Z] + len(b, 'Z');
    if (inverse_time_) fail("inverse time feed (G93) is not supported in polar interpolation (G12.1)");
    const double dx = xt - x0, dy = yt - y0, L = std::hypot(dx, dy);
    // Linear interpolation of (r, φ) between two points of the line at distance d from the
    // axis deviates from it by at most ds² / (8 d): steps of ds = 2·sqrt(tol / 2 · d) keep
    // that within tol / 4.
    double d_min = std::min(std::hypot(x0, y0), std::hypot(xt, yt));
    if (L > 0.0) {
      const double tc = -(x0 * dx + y0 * dy) / (L * L);
      if (tc > 0.0 && tc < 1.0) d_min = std::abs(x0 * dy - y0 * dx) / L;
      if (tc > 0.0 && tc < 1.0 && d_min < 1e-3) fail("polar interpolation (G12.1): the line passes through the spindle axis");
    }
    const double ds = 2.0 * std::sqrt(0.5 * opt_.chord_tol_mm * std::max(d_min, 1e-3));
    const double steps_d = L > 0.0 ? std::ceil(L / ds) : 1.0;
    if (steps_d > 1e6) fail("polar interpolation (G12.1): too many steps for this line");
    const int n = std::max(1, static_cast<int>(steps_d));
    const double f = motion_ == 10 ? feed_for_move("G1", f_in_block) : 0.0;
    double c_prev = p0[C];
    AxisVector prev = p0;
    for (int i = 1; i <= n; ++i) {
      const double t = static_cast<double>(i) / n;
      const double x = x0 + t * dx, y = y0 + t * dy;
      AxisVector q = p0;
      q[X] = std::hypot(x, y);
      q[Z] = p0[Z] + t * (zt - p0[Z]);
      // C = -φ, unwrapped to the nearest turn of the previous step.
      double c = q[X] > 1e-12 ? -std::atan2(y, x) / kRad : c_prev;
      c += 360.0 * std::round((c_prev - c) / 360.0);
      q[C] = c;
      c_prev = c;
      if (motion_ == 0) {
        b_.rapid(line_, q);
      } else {
        // Cartesian feed along the line: the step's duration is its Cartesian length / F.
        const double seg = L / n;
        const double joint = std::hypot(q[X] - prev[X], q[Z] - prev[Z]);
        double fj = f;
        if (!inverse_time_ && seg > 0.0) {
          fj = joint > 1e-9 ? f * joint / seg : f * std::abs(q[C] - prev[C]) / seg;
          fj = std::max(fj, 1e-6);
        }
        b_.feed(line_, q, fj, inverse_time_);
      }
      prev = q;
    }
  }

  void move_arc(Block& b, bool f_in_block) {
    const std::string g = motion_ == 20 ? "G2" : "G3";
    if (arc_after_g40_) fail("'" + g + "': the move just after G40 must be a straight line, not an arc (as LinuxCNC)");
    const detail::PlaneAxes ax = detail::plane_axes(plane_);
    static constexpr char kCentre[3] = {'I', 'J', 'K'};  // centre word of X, Y, Z
    const char cu_l = kCentre[ax.u], cv_l = kCentre[ax.v];
    const char* plane_name = plane_ == Plane::XY ? "XY" : plane_ == Plane::ZX ? "XZ" : "YZ";
    const bool ijk = has(b, cu_l) || has(b, cv_l);
    const bool r_form = has(b, 'R');
    if (ijk && r_form) fail("'" + g + "' with both R and a centre word (" + cu_l + "/" + cv_l + ")");
    if (!ijk && !r_form) fail("'" + g + "' needs R or a centre word " + cu_l + "/" + cv_l + " (plane " + plane_name + ")");
    int turns = 1;
    if (has(b, 'P')) turns = integer(b, 'P', 1, 1000);
    const double f = feed_for_move(g, f_in_block);
    const AxisVector start = pos();
    const AxisVector end = target(b, false);
    const double du = end[ax.u] - start[ax.u], dv = end[ax.v] - start[ax.v];
    double cu = 0.0, cv = 0.0;
    if (r_form) {
      const double r = len(b, 'R');
      const double d = std::hypot(du, dv);
      if (d < 1e-9) fail("'" + g + "' in R form cannot make a full circle (end point = start point)");
      double h2 = r * r - 0.25 * d * d;
      if (h2 < 0.0) {
        if (std::abs(r) < 0.5 * d - 0.001)
          fail("'" + g + "' radius '" + text(b, 'R') + "' is too small for an end point " + fmt(d) + " mm away");
        h2 = 0.0;
      }
      const double h = std::sqrt(h2);
      // Centre left of the chord for counter-clockwise short arcs; R < 0 asks for the long arc.
      double side = motion_ == 30 ? 1.0 : -1.0;
      if (r < 0) side = -side;
      cu = start[ax.u] + 0.5 * du - side * h * dv / d;
      cv = start[ax.v] + 0.5 * dv + side * h * du / d;
    } else {
      if (arc_absolute_) {
        if (!has(b, cu_l) || !has(b, cv_l))
          fail("'" + g + "' with absolute arc centres (G90.1) needs both " + cu_l + " and " + cv_l);
        cu = len(b, cu_l);
        cv = len(b, cv_l);
      } else {
        cu = start[ax.u] + (has(b, cu_l) ? len(b, cu_l) : 0.0);
        cv = start[ax.v] + (has(b, cv_l) ? len(b, cv_l) : 0.0);
      }
      const double r0 = std::hypot(start[ax.u] - cu, start[ax.v] - cv);
      const double r1 = std::hypot(end[ax.u] - cu, end[ax.v] - cv);
      if (r0 < 1e-9) fail("'" + g + "' has zero radius (centre = start point)");
      const double err = std::abs(r1 - r0);
      if (err > 0.002 && err > 0.001 * r0)
        fail("'" + g + "' end point is off the circle: start radius " + fmt(r0) + " mm, end radius " + fmt(r1) + " mm");
    }
    if (capture_ != nullptr) capture_arc(ax, start, end, cu, cv, motion_ == 30 ? turns : -turns);
    else if (comp_.active()) comp_.arc(line_, end, cu, cv, motion_ == 30 ? turns : -turns, f, inverse_time_);
    else b_.arc(line_, plane_, end, cu, cv, motion_ == 30 ? turns : -turns, f, inverse_time_);
  }

  // ---- G70/G71/G72 lathe cycles (lathe_profile.hpp) ----------------------------------------
  static bool is_lathe_profile_cycle(int c) {
    return c == 700 || c == 710 || c == 711 || c == 712 || c == 720 || c == 721 || c == 722;
  }

  // The profile: the subroutine Q runs with its moves recorded (not cut), starting from the
  // cycle's start point; then the cycle's own moves are cut.
  void lathe_profile_cycle(Block& b, int c, bool f_in_block) {
    const std::string g = "G" + std::to_string(c / 10) + (c % 10 != 0 ? "." + std::to_string(c % 10) : "");
    if (plane_ != Plane::ZX) fail("'" + g + "' needs the XZ plane (G18)");
    if (comp_.active()) fail("'" + g + "' cannot be used with cutter radius compensation on (G40 first)");
    if (!has(b, 'Q')) fail("'" + g + "' needs Q (the number of the profile's subroutine)");
    const int q = integer(b, 'Q', 0, 99999999);
    const AxisVector before = b_.position();
    const AxisVector start = (has(b, 'X') || has(b, 'Z')) ? target(b, false) : before;
    const detail::LatheCycle cycle = lathe_cycle_words(b, c);
    const std::vector<detail::LathePoint> profile = capture_profile(q, start);
    std::vector<detail::LathePoint> moves;
    try {
      moves = detail::lathe_cycle(profile, lathe_point(start), cycle);
    } catch (const std::invalid_argument& e) {
      fail("'" + g + "': " + e.what());
    }
    b_.set_position(before);
    b_.rapid(line_, start);
    const double f = feed_for_move(g, f_in_block);
    for (const detail::LathePoint& p : moves) {
      AxisVector v = b_.position();
      v[X] = p.x, v[Z] = p.z;
      if (p.rapid) b_.rapid(line_, v);
      else b_.feed(line_, v, f, inverse_time_);
    }
  }

  // D, E, P (G70) and D, I, R (G71/G72) in program units, as LinuxCNC reads them (radii in G7 too).
  detail::LatheCycle lathe_cycle_words(Block& b, int c) {
    detail::LatheCycle k;
    k.code = c / 10;
    k.variant = c % 10;
    auto word = [&](char L, double dflt) { return has(b, L) ? len(b, L) : dflt; };
    k.allowance = word('D', 0.0);
    if (k.code == 70) {
      k.end_allowance = word('E', 0.0);
      k.passes = has(b, 'P') ? integer(b, 'P', 1, 1000) : 1;
    } else {
      k.increment = word('I', 1.0);
      k.retract = word('R', 0.5);
    }
    return k;
  }

  detail::LathePoint lathe_point(const AxisVector& v) const {
    detail::LathePoint p;
    p.x = v[X], p.z = v[Z];
    return p;
  }

  // The subroutine's F words do not change the cycle's feed (LinuxCNC ignores them there).
  std::vector<detail::LathePoint> capture_profile(int q, const AxisVector& start) {
    std::vector<detail::LathePoint> profile;
    const int motion = motion_, line = line_;
    const double feed = feed_;
    b_.set_position(start);
    capture_ = &profile;
    try {
      flow_.call_now(std::to_string(q));
    } catch (...) {
      capture_ = nullptr;
      throw;
    }
    capture_ = nullptr;
    motion_ = motion, line_ = line, feed_ = feed;
    return profile;
  }

  void capture_point(const AxisVector& t, bool rapid) {
    detail::LathePoint p = lathe_point(t);
    p.rapid = rapid;
    capture_->push_back(p);
    b_.set_position(t);
  }

  // An arc of the profile as chords at most 0.001 mm from it (rotation > 0: counter-clockwise).
  void capture_arc(const detail::PlaneAxes& ax, const AxisVector& start, const AxisVector& end, double cu, double cv,
                   int rotation) {
    const double r = std::hypot(start[ax.u] - cu, start[ax.v] - cv);
    const double a0 = std::atan2(start[ax.v] - cv, start[ax.u] - cu);
    double a1 = std::atan2(end[ax.v] - cv, end[ax.u] - cu);
    const double two_pi = 2.0 * std::acos(-1.0);
    if (rotation > 0) {
      while (a1 <= a0 + 1e-12) a1 += two_pi;
      a1 += two_pi * (rotation - 1);
    } else {
      while (a1 >= a0 - 1e-12) a1 -= two_pi;
      a1 -= two_pi * (-rotation - 1);
    }
    const double step = 2.0 * std::acos(std::max(0.0, 1.0 - 0.001 / std::max(r, 1e-9)));
    const long n = std::max(1L, static_cast<long>(std::ceil(std::abs(a1 - a0) / std::max(step, 1e-6))));
    for (long i = 1; i <= n; ++i) {
      AxisVector p = i == n ? end : start;
      if (i < n) {
        const double a = a0 + (a1 - a0) * static_cast<double>(i) / static_cast<double>(n);
        p[ax.u] = cu + r * std::cos(a);
        p[ax.v] = cv + r * std::sin(a);
      }
      capture_point(p, false);
    }
  }

  // Drilling cycles in the selected plane, as LinuxCNC: the hole axis w is Z in G17, Y in G18,
  // X in G19; the positions are the plane's other two axis words; R and the depth word (the
  // w axis letter) are along w.
  void canned_cycle(Block& b) {
    const std::string g = motion_ == 810 ? "G81" : motion_ == 820 ? "G82" : motion_ == 830 ? "G83" : "G73";
    const detail::PlaneAxes ax = detail::plane_axes(plane_);
    const char wl = kAxisLetters[ax.w];
    cycle_words(b, g, wl);
    const CycleSticky& cs = cycle_sticky_;
    const double f = feed_for_move(g, has(b, 'F'));
    int repeats = 1;
    if (has(b, 'L')) repeats = integer(b, 'L', 0, static_cast<int>(kMaxRepeats));
    if (fanuc_ && has(b, 'K')) repeats = integer(b, 'K', 0, static_cast<int>(kMaxRepeats));  // fanuc: K repeats
    AxisVector p = pos();
    // The initial level: the hole-axis position where this series of contiguous canned cycle
    // blocks began. In G91 R is relative to it; G98 retracts to it (or R, the higher), and a
    // G98 block starts from it (or the current position, the higher). A block that starts
    // below R first rises to R where it stands. All as LinuxCNC (checked against rs274).
    if (!cycle_series_) cycle_initial_z_ = p[ax.w];
    cycle_series_ = true;
    const double r = absolute_ ? cs.r : cycle_initial_z_ + cs.r;
    const double bottom = absolute_ ? cs.z : r + cs.z;
    if (bottom > r) fail("canned cycle '" + g + "': R (" + fmt(r) + ") is below " + wl + " (" + fmt(bottom) + ")");
    if ((motion_ == 830 || motion_ == 730) && (r - bottom) / cs.q > static_cast<double>(kMaxPecks))
      fail("'" + g + "': more than " + std::to_string(kMaxPecks) + " pecks");
    double old_w = retract_to_initial_ ? std::max(cycle_initial_z_, p[ax.w]) : p[ax.w];
    if (old_w < r) {
      p[ax.w] = r;
      b_.rapid(line_, p);
      old_w = r;
    }
    const double clear = retract_to_initial_ ? std::max(cycle_initial_z_, r) : r;
    double hu = p[ax.u], hv = p[ax.v];
    const char ul = kAxisLetters[ax.u], vl = kAxisLetters[ax.v];
    const double du = has(b, ul) ? axis_value(b, ax.u) : 0.0, dv = has(b, vl) ? axis_value(b, ax.v) : 0.0;
    for (int rep = 0; rep < repeats; ++rep) {
      if (b.has_at || b.has_caret) {
        if (plane_ != Plane::XY) fail("polar coordinates '" + b.polar_text + "' in a canned cycle need plane G17");
        const auto xy = polar_xy(b, hu, hv);
        hu = xy[0], hv = xy[1];
      } else if (absolute_) {
        if (has(b, ul)) hu = du;
        if (has(b, vl)) hv = dv;
      } else {
        hu += du, hv += dv;
      }
      drill_hole(ax, hu, hv, old_w, r, bottom, f);
      old_w = clear;
      b_.rapid(line_, cycle_point(ax, hu, hv, clear));
    }
  }

  void cycle_words(Block& b, const std::string& g, char wl) {
    for (char L : {'A', 'B', 'C'})
      if (has(b, L)) fail("canned cycle '" + g + "' with rotary axis word '" + text(b, L) + "'");
    CycleSticky& cs = cycle_sticky_;
    if (has(b, 'R')) cs.r = len(b, 'R'), cs.has_r = true;
    if (has(b, wl)) cs.z = len(b, wl), cs.has_z = true;
    b.used[idx(wl)] = true;
    if (has(b, 'Q')) {
      cs.q = len(b, 'Q');
      cs.has_q = true;
      if (motion_ != 830 && motion_ != 730) fail("unused word '" + text(b, 'Q') + "' (" + g + " takes no Q)");
    }
    if (has(b, 'P')) {
      cs.p = raw(b, 'P') * (fanuc_ ? 0.001 : 1.0);  // fanuc: P [ms]
      cs.has_p = true;
      if (motion_ != 820) fail("unused word '" + text(b, 'P') + "' (" + g + " takes no P)");
    }
    if (!cs.has_r || !cs.has_z) fail("canned cycle '" + g + "' needs R and " + wl);
    if ((motion_ == 830 || motion_ == 730) && (!cs.has_q || cs.q <= 0.0)) fail("'" + g + "' needs Q > 0 (peck depth)");
    if (motion_ == 820 && (!cs.has_p || cs.p < 0.0)) fail("'G82' needs P >= 0 (dwell time [s])");
  }

  AxisVector cycle_point(const detail::PlaneAxes& ax, double hu, double hv, double w) const {
    AxisVector v = b_.position();
    v[ax.u] = hu, v[ax.v] = hv, v[ax.w] = w;
    return v;
  }

  // One hole at (hu, hv): rapid over it at old_w, down to R, then the cycle's feed moves.
  void drill_hole(const detail::PlaneAxes& ax, double hu, double hv, double old_w, double r, double bottom, double f) {
    auto at = [&](double w) { return cycle_point(ax, hu, hv, w); };
    const double q = cycle_sticky_.q;
    b_.rapid(line_, at(old_w));
    if (old_w != r) b_.rapid(line_, at(r));
    switch (motion_) {
      case 810: b_.feed(line_, at(bottom), f, inverse_time_); break;
      case 820:
        b_.feed(line_, at(bottom), f, inverse_time_);
        b_.dwell(line_, cycle_sticky_.p);
        break;
      case 830:
        for (double d = r - q; d > bottom; d -= q) {
          b_.feed(line_, at(d), f, inverse_time_);
          b_.rapid(line_, at(r));
          b_.rapid(line_, at(d + kG83RapidDelta));
        }
        b_.feed(line_, at(bottom), f, inverse_time_);
        break;
      case 730:
        for (double d = r - q; d > bottom; d -= q) {
          b_.feed(line_, at(d), f, inverse_time_);
          b_.rapid(line_, at(d + kG73Retract));
        }
        b_.feed(line_, at(bottom), f, inverse_time_);
        break;
      default: break;
    }
  }

  struct CycleSticky {
    double r = 0, z = 0, q = 0, p = 0;
    bool has_r = false, has_z = false, has_q = false, has_p = false;
  };

  std::string name_;
  const GcodeOptions& opt_;
  bool fanuc_ = opt_.dialect == Dialect::Fanuc;
  PathBuilder b_;
  detail::Params params_;
  detail::ExprReader expr_;
  detail::ControlFlow flow_;
  detail::CutterComp comp_{b_, [this](const std::string& m) { fail(m); }};
  bool arc_after_g40_ = false;  // the move after G40 must be straight (LinuxCNC)
  std::vector<detail::LathePoint>* capture_ = nullptr;  // G70-G72: the profile subroutine's moves go here
  std::map<int, ModalState> saved_states_;  // M70/M73, per call level
  int comp_code_ = 400;                      // G41/G42/G41.1/G42.1 x 10 while compensation is on
  std::vector<detail::ParamAssign> pending_;
  std::array<AxisVector, 9> offsets_;
  AxisVector g28_, g30_;
  AxisVector g92_{};      // G92 offset [mm, deg]
  bool g92_on_ = false;
  int line_ = 0;
  bool ended_ = false;
  int wcs_ = 0;
  double scale_ = 1.0;  // mm per program length unit
  bool absolute_ = true, arc_absolute_ = false, inverse_time_ = false, retract_to_initial_ = false;  // G99 at start, as LinuxCNC's interpreter
  bool per_rev_ = false;        // G95: F is [length unit / revolution]
  bool css_ = false;            // G96 constant surface speed (else G97 rpm)
  double css_max_rpm_ = 0.0;    // G96 D [rpm]; 0: none
  bool diameter_mode_ = opt_.diameter_mode;
  bool polar_ = false;  // G12.1 in effect (lathe-c)
  int path_mode_ = 640;                                 // G61 (610), G61.1 (611), G64 (640)
  double path_tol_mm_ = 0.0, path_q_tol_mm_ = 0.0;    // G64 P, Q [mm]
  Plane plane_ = Plane::XY;
  int motion_ = -1;  // code x 10; -1: none (G80 or program start)
  double feed_ = 0.0;
  double spindle_rpm_ = 0.0;
  int spindle_ = 5;  // M3, M4 or M5 (recorded, not in the Toolpath)
  int coolant_ = 9;  // M7, M8 or M9 (recorded, not in the Toolpath)
  int selected_tool_ = 0;
  int pauses_ = 0;
  CycleSticky cycle_sticky_;
  bool cycle_series_ = false;     // inside a series of contiguous canned cycle blocks
  double cycle_initial_z_ = 0.0;  // hole-axis position when the series began
};

}  // namespace

bool parse_dialect(const std::string& name, Dialect& out) {
  if (name == "rs274ngc") out = Dialect::Rs274ngc;
  else if (name == "fanuc") out = Dialect::Fanuc;
  else return false;
  return true;
}

Toolpath interpret_gcode(const std::string& text, const std::string& name, const GcodeOptions& options) {
  if (!(options.chord_tol_mm > 0.0)) throw ParseError(name, 0, "chord tolerance must be > 0 mm");
  Interpreter in(name, options);
  return in.run(text);
}

Toolpath load_gcode(const std::string& path, const GcodeOptions& options) {
  return interpret_gcode(read_text_file(path), path, options);
}

}  // namespace lbr::nc
