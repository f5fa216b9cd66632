#include "nc/movelist.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

namespace lbr::nc {

const char* to_string(SegmentKind k) noexcept {
  switch (k) {
    case SegmentKind::Rapid: return "rapid";
    case SegmentKind::Feed: return "feed";
    case SegmentKind::Dwell: return "dwell";
    case SegmentKind::ToolChange: return "tool";
  }
  return "?";
}

AxisVector machine_axes(const Toolpath& path, const AxisVector& tip, int tool) noexcept {
  AxisVector m{};
  for (int a = 0; a < kAxes; ++a) m[a] = tip[a] + path.machine_origin[a];
  const auto it = path.tool_lengths_mm.find(tool);
  if (it != path.tool_lengths_mm.end()) m[Z] += it->second;
  return m;
}

namespace {

std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> w;
  std::istringstream in(line);
  std::string s;
  while (in >> s) w.push_back(s);
  return w;
}

// Reads a move list line by line (format in docs/formats.md#move-list); one method per keyword.
class MoveListReader {
 public:
  explicit MoveListReader(const std::string& name) { tp_.source = name; }

  Toolpath read(const std::string& text) {
    std::istringstream in(text);
    std::string raw;
    while (std::getline(in, raw)) {
      ++lineno_;
      w_ = split_words(raw.substr(0, raw.find('#')));
      if (!w_.empty()) line();
    }
    if (!header_)
      throw ParseError(tp_.source, lineno_ == 0 ? 1 : lineno_, "empty file: a move list starts with 'lbr-moves 1'");
    if (!start_given_) start_at_first_motion();
    return std::move(tp_);
  }

 private:
  [[noreturn]] void fail(const std::string& m) const { throw ParseError(tp_.source, lineno_, m); }

  double number(std::size_t i, const char* what) const {
    const std::string& kw = w_[0];
    if (i >= w_.size()) fail(std::string("'") + kw + "' expects " + what);
    double v = 0.0;
    std::size_t used = 0;
    try {
      v = std::stod(w_[i], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != w_[i].size() || !std::isfinite(v))
      fail(std::string("'") + kw + "': " + what + " must be a finite number, got '" + w_[i] + "'");
    return v;
  }

  void arity(std::size_t lo, std::size_t hi, const char* form) const {
    if (w_.size() < lo || w_.size() > hi) fail(std::string("expected '") + form + "'");
  }

  Segment segment(SegmentKind kind) const {
    Segment s;
    s.kind = kind;
    s.end = pos_;
    s.tool = tool_;
    s.line = lineno_;
    return s;
  }

  void line() {
    const std::string& kw = w_[0];
    if (!header_) {
      if (kw != "lbr-moves" || w_.size() != 2 || w_[1] != "1") fail("a move list starts with the line 'lbr-moves 1'");
      header_ = true;
    } else if (kw == "start") {
      start();
    } else if (kw == "tool") {
      tool();
    } else if (kw == "feed") {
      arity(2, 2, "feed F_MM_PER_MIN");
      feed_ = number(1, "a feed rate");
      if (feed_ <= 0.0) fail("feed rate must be > 0 mm/min");
    } else if (kw == "rapid" || kw == "line") {
      motion(kw == "rapid" ? SegmentKind::Rapid : SegmentKind::Feed);
    } else if (kw == "dwell") {
      dwell();
    } else {
      fail("unknown keyword '" + kw + "' (expected start, tool, feed, rapid, line or dwell)");
    }
  }

  void start() {
    arity(4, 4, "start X Y Z");
    if (moved_) fail("'start' must come before the first move");
    for (int a = 0; a < 3; ++a) pos_[a] = number(1 + a, "a coordinate");
    tp_.start = pos_;
    start_given_ = true;
  }

  void tool() {
    arity(2, 2, "tool N");
    const double n = number(1, "a tool number");
    if (n < 0 || n > 9999 || n != std::floor(n)) fail("tool number must be an integer in [0, 9999]");
    tool_ = static_cast<int>(n);
    tp_.segments.push_back(segment(SegmentKind::ToolChange));
  }

  void motion(SegmentKind kind) {
    const std::string& kw = w_[0];
    if (w_.size() != 4 && w_.size() != 7) fail("expected '" + kw + " X Y Z' or '" + kw + " X Y Z I J K'");
    if (kind == SegmentKind::Feed && feed_ <= 0.0) fail("'line' before any 'feed': no feed rate set");
    if (tool_ == 0) fail("'" + kw + "' before any 'tool': no tool in the spindle");
    for (int a = 0; a < 3; ++a) pos_[a] = number(1 + a, "a coordinate");
    if (w_.size() == 7) {
      std::array<double, 3> v{number(4, "I"), number(5, "J"), number(6, "K")};
      const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (n < 1e-9) fail("tool axis I J K must not be the zero vector");
      for (double& c : v) c /= n;
      axis_ = v;
    }
    Segment s = segment(kind);
    s.has_tool_axis = true;
    s.tool_axis = axis_;
    s.feed_mm_per_min = feed_;
    tp_.segments.push_back(s);
    moved_ = true;
  }

  void dwell() {
    arity(2, 2, "dwell SECONDS");
    Segment s = segment(SegmentKind::Dwell);
    s.dwell_s = number(1, "a time in seconds");
    if (s.dwell_s < 0.0) fail("dwell time must be >= 0");
    tp_.segments.push_back(s);
  }

  // Without 'start' the tool is taken to begin where the first motion ends.
  void start_at_first_motion() {
    for (const Segment& s : tp_.segments) {
      if (s.kind == SegmentKind::Rapid || s.kind == SegmentKind::Feed) {
        tp_.start = s.end;
        tp_.start_axis = s.tool_axis;
        return;
      }
    }
  }

  Toolpath tp_;
  std::vector<std::string> w_;  // the words of the current line
  int lineno_ = 0;
  bool header_ = false, moved_ = false, start_given_ = false;
  double feed_ = 0.0;
  int tool_ = 0;
  AxisVector pos_{};
  std::array<double, 3> axis_{0, 0, 1};
};

}  // namespace

Toolpath parse_movelist(const std::string& text, const std::string& name) { return MoveListReader(name).read(text); }

Toolpath load_movelist(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ParseError(path, 0, "cannot open file");
  std::ostringstream ss;
  ss << f.rdbuf();
  return parse_movelist(ss.str(), path);
}

}  // namespace lbr::nc
