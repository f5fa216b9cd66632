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

namespace {

std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> w;
  std::istringstream in(line);
  std::string s;
  while (in >> s) w.push_back(s);
  return w;
}

}  // namespace

Toolpath parse_movelist(const std::string& text, const std::string& name) {
  Toolpath tp;
  tp.source = name;
  std::istringstream in(text);
  std::string raw;
  int lineno = 0;
  bool header = false;
  bool moved = false;
  bool start_given = false;
  double feed = 0.0;
  int tool = 0;
  AxisVector pos{};
  std::array<double, 3> axis{0, 0, 1};
  auto fail = [&](const std::string& m) -> void { throw ParseError(name, lineno, m); };

  while (std::getline(in, raw)) {
    ++lineno;
    const auto hash = raw.find('#');
    const std::vector<std::string> w = split_words(raw.substr(0, hash));
    if (w.empty()) continue;
    const std::string& kw = w[0];
    auto number = [&](std::size_t i, const char* what) {
      if (i >= w.size()) fail(std::string("'") + kw + "' expects " + what);
      double v = 0.0;
      std::size_t used = 0;
      try {
        v = std::stod(w[i], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != w[i].size() || !std::isfinite(v))
        fail(std::string("'") + kw + "': " + what + " must be a finite number, got '" + w[i] + "'");
      return v;
    };
    auto arity = [&](std::size_t lo, std::size_t hi, const char* form) {
      if (w.size() < lo || w.size() > hi) fail(std::string("expected '") + form + "'");
    };
    if (!header) {
      if (kw != "lbr-moves" || w.size() != 2 || w[1] != "1")
        fail("a move list starts with the line 'lbr-moves 1'");
      header = true;
      continue;
    }
    if (kw == "start") {
      arity(4, 4, "start X Y Z");
      if (moved) fail("'start' must come before the first move");
      for (int a = 0; a < 3; ++a) pos[a] = number(1 + a, "a coordinate");
      tp.start = pos;
      start_given = true;
    } else if (kw == "tool") {
      arity(2, 2, "tool N");
      const double n = number(1, "a tool number");
      if (n < 0 || n > 9999 || n != std::floor(n)) fail("tool number must be an integer in [0, 9999]");
      tool = static_cast<int>(n);
      Segment s;
      s.kind = SegmentKind::ToolChange;
      s.end = pos;
      s.tool = tool;
      s.line = lineno;
      tp.segments.push_back(s);
    } else if (kw == "feed") {
      arity(2, 2, "feed F_MM_PER_MIN");
      feed = number(1, "a feed rate");
      if (feed <= 0.0) fail("feed rate must be > 0 mm/min");
    } else if (kw == "rapid" || kw == "line") {
      if (w.size() != 4 && w.size() != 7) fail("expected '" + kw + " X Y Z' or '" + kw + " X Y Z I J K'");
      Segment s;
      s.kind = kw == "rapid" ? SegmentKind::Rapid : SegmentKind::Feed;
      if (s.kind == SegmentKind::Feed && feed <= 0.0) fail("'line' before any 'feed': no feed rate set");
      if (tool == 0) fail("'" + kw + "' before any 'tool': no tool in the spindle");
      for (int a = 0; a < 3; ++a) pos[a] = number(1 + a, "a coordinate");
      s.end = pos;
      if (w.size() == 7) {
        std::array<double, 3> v{number(4, "I"), number(5, "J"), number(6, "K")};
        const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (n < 1e-9) fail("tool axis I J K must not be the zero vector");
        for (double& c : v) c /= n;
        axis = v;
      }
      s.has_tool_axis = true;
      s.tool_axis = axis;
      s.feed_mm_per_min = feed;
      s.tool = tool;
      s.line = lineno;
      tp.segments.push_back(s);
      moved = true;
    } else if (kw == "dwell") {
      arity(2, 2, "dwell SECONDS");
      Segment s;
      s.kind = SegmentKind::Dwell;
      s.dwell_s = number(1, "a time in seconds");
      if (s.dwell_s < 0.0) fail("dwell time must be >= 0");
      s.end = pos;
      s.tool = tool;
      s.line = lineno;
      tp.segments.push_back(s);
    } else {
      fail("unknown keyword '" + kw + "' (expected start, tool, feed, rapid, line or dwell)");
    }
  }
  if (!header) throw ParseError(name, lineno == 0 ? 1 : lineno, "empty file: a move list starts with 'lbr-moves 1'");
  // Without 'start' the tool is taken to begin where the first motion ends.
  if (!start_given) {
    for (const Segment& s : tp.segments) {
      if (s.kind == SegmentKind::Rapid || s.kind == SegmentKind::Feed) {
        tp.start = s.end;
        tp.start_axis = s.tool_axis;
        break;
      }
    }
  }
  return tp;
}

Toolpath load_movelist(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ParseError(path, 0, "cannot open file");
  std::ostringstream ss;
  ss << f.rdbuf();
  return parse_movelist(ss.str(), path);
}

}  // namespace lbr::nc
